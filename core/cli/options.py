"""Options shared by several commands, and the terminal progress bar. Only the standard
library is imported here (the parsers are built before a command imports :mod:`gatetherm.api`)."""
from __future__ import annotations

import argparse
import os
import sys


class _Default(int):
    """An option's default value, told apart from the same value given on the command line."""


def add_model_options(p: argparse.ArgumentParser, dims=(2, 3), dim_help: str = "2-D section or 3-D solid (default 2)") -> None:
    """``--dim`` and ``--config``, shared by the commands that build a model."""
    p.add_argument("--dim", type=int, choices=dims, default=_Default(2), help=dim_help)
    p.add_argument("--config", metavar="FILE.toml", help="model file (default: the shipped paper model)")


def refuse_model_options(args, case: str = "--case") -> None:
    """InputError if ``--dim`` or ``--config`` was given with a case file (which gives its own model and mesh)."""
    given = [o for o, v in (("--dim", args.dim), ("--config", args.config))
             if v is not None and type(v) is not _Default]
    if given:
        from gatetherm.api import InputError

        raise InputError(f"{case}/{given[0]}", "a case file gives its own model and mesh", f"drop {given[0]}")


def add_parallel_options(p: argparse.ArgumentParser) -> None:
    """``--workers`` and ``--scheduler``, shared by the commands that run many points."""
    p.add_argument("--workers", type=number(WORKERS), default=os.cpu_count() or 1, metavar="N",
                   help="local worker processes (default: the CPU count; 1 = in this process)")
    p.add_argument("--scheduler", metavar="ADDRESS",
                   help="run the points on an existing Dask cluster, e.g. tcp://10.0.0.5:8786")


class Progress:
    """A one-line bar on a terminal; silent otherwise (logs stay clean)."""

    def __init__(self, label: str, stream=None):
        self.label, self.stream = label, stream or sys.stderr
        self.on = self.stream.isatty()

    def __call__(self, i: int, n: int) -> None:
        if not self.on:
            return
        k = int(30 * i / n)
        self.stream.write(f"\r{self.label} [{'#' * k}{'.' * (30 - k)}] {i}/{n}")
        if i == n:
            self.stream.write("\n")
        self.stream.flush()


class UsageError(Exception):
    """A command-line error found by argparse; ``str(err)`` is the one line to print."""


class Parser(argparse.ArgumentParser):
    """argparse with one-line errors (exit code 2); the usage is printed by ``--help`` only.
    Sub-command parsers are of the same class."""

    def error(self, message):
        raise UsageError(f"{self.prog}: error: {message} (see '{self.prog} --help')")


def number(rng):
    """An argparse ``type``: a number (a whole one if ``rng.whole``) admissible in ``rng``, a
    :class:`gatetherm.api.Range` or the name of one there (``"POSITIVE"``, ``"WORKERS"``: looked
    up when a value is parsed, so that building the parser imports no library)."""
    def parse(text: str):
        nonlocal rng
        if isinstance(rng, str):
            import gatetherm.api

            rng = getattr(gatetherm.api, rng)
        try:
            value = int(text) if rng.whole else float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected {'a whole number' if rng.whole else 'a number'}, "
                                             f"got {text!r}") from None
        if not rng.admits(value):
            raise argparse.ArgumentTypeError(f"got {text}, must be {rng}")
        return value
    return parse


SEED = "SEED"
"""A random seed: a whole number from 0 to 2^32 - 1 (numpy's range), as ``gatetherm.api.SEED``."""
WORKERS = "WORKERS"
"""Worker processes: :data:`gatetherm.api.WORKERS`, for :func:`number`."""
