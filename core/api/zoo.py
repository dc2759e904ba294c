"""The machine zoo: every capability on every shipped machine (:mod:`gatetherm.api`)."""
from __future__ import annotations

import os
from pathlib import Path


def validate_zoo(out: str | os.PathLike, machines=None, *, capabilities=None, timeout_s: float | None = None,
                 on_cell=None) -> dict:
    """Run every capability on every machine of the zoo and write the matrix.

    The machines are the case files under ``validation/examples/`` (``gatetherm.validation.zoo.MACHINES``);
    each cell runs the library functions its command calls, in a child process with a time limit,
    and is a number with one line of context, a one-line refusal or ``FAILED: …`` (never a traceback).
    docs/validation.md, "The machine zoo", says what each cell's number is.

    Parameters
    ----------
    out : path
        Output directory: ``zoo.md``, ``zoo.json`` and each cell's files under ``<machine>/<capability>/``.
    machines : sequence of str, optional
        Names of the machines (default: all).
    capabilities : sequence of str, optional
        Columns of the matrix (default: all of ``gatetherm.validation.zoo.CAPABILITIES``).
    timeout_s : float, optional
        Time limit of one cell, s (default ``gatetherm.validation.zoo.TIMEOUT_S``).
    on_cell : callable, optional
        ``on_cell(machine, capability, cell)`` after each cell.

    Returns
    -------
    dict
        ``{machine: {capability: {"status": "ok" | "refused" | "failed", "value": float or None
        (µm, a factor or %), "text": one line, "seconds": s}}}``.

    Raises
    ------
    InputError
        An unknown machine or capability.
    """
    from gatetherm.validation.zoo import CAPABILITIES, TIMEOUT_S, write_zoo

    return write_zoo(Path(out), machines, CAPABILITIES if capabilities is None else tuple(capabilities),
                     TIMEOUT_S if timeout_s is None else timeout_s, on_cell)
