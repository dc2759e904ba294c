"""The error a solver raises when the equations cannot be solved."""


class SolverError(RuntimeError):
    """An iterative solve did not converge, or a matrix cannot be factorised."""
