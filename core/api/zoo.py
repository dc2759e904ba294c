"""The machine zoo: every capability on every shipped machine (:mod:`gatetherm.api`)."""
from __future__ import annotations

import os
from pathlib import Path
from typing import Sequence

from gatetherm import InputError
from gatetherm.checks import POSITIVE, argument, number_argument

PUBLIC = ("validate_zoo",)  # offered as gt.NAME (gatetherm.api finds them here)


def validate_zoo(out: str | os.PathLike, machines: Sequence[str] | None = None, *,
                 capabilities: Sequence[str] | None = None, timeout_s: float | None = None,
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

    for name, names in (("machines", machines), ("capabilities", capabilities)):
        argument(name, names, (list, tuple, type(None)), "a list of names or None", f"e.g. {name}=[...]")
        if names is not None and not names:
            raise InputError(name, "is empty: nothing to run", "give at least one, or None for all")
    if timeout_s is not None:
        timeout_s = number_argument("timeout_s", timeout_s, POSITIVE, "e.g. 600")
    if on_cell is not None and not callable(on_cell):
        raise TypeError(f"on_cell: got {type(on_cell).__name__}, expected a function on_cell(machine, capability, "
                        "cell) or None")
    return write_zoo(Path(out), machines, CAPABILITIES if capabilities is None else tuple(capabilities),
                     TIMEOUT_S if timeout_s is None else timeout_s, on_cell)
