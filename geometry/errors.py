"""The one user-facing error type: bad input, reported as a single line."""


class InputError(ValueError):
    """Bad user input. ``str(err)`` is one line naming the field and the fix."""

    def __init__(self, field: str, problem: str, fix: str = ""):
        self.field = field
        msg = f"{field}: {problem}"
        if fix:
            msg += f"; {fix}"
        super().__init__(msg)
