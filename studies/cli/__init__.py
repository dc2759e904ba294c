"""The ``gatetherm`` console command: argument parsing and error reporting only."""
from __future__ import annotations

import argparse
import importlib
import logging
import sys

from gatetherm import InputError

#: Sub-command modules of this package, in ``--help`` order.
COMMAND_MODULES = ("run", "mesh", "simulate", "beam", "compensate", "sweep", "validate", "diagnose", "export",
                   "report")


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="gatetherm",
        description="Thermal deformation of gate-type machine-tool frames: "
        "FE, beam theory and compensation.",
    )
    parser.add_argument("-v", "--verbose", action="store_true", help="log progress details")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name in COMMAND_MODULES:
        importlib.import_module(f"gatetherm.studies.cli.{name}").register(sub)
    return parser




def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)  # argparse itself exits 2 with a one-line usage error
    logging.basicConfig(
        level=logging.INFO if args.verbose else logging.WARNING,
        format="%(levelname)s %(name)s: %(message)s",
    )
    if not getattr(args, "func", None):
        parser.print_help()
        return 2
    try:
        return int(args.func(args) or 0)
    except InputError as err:
        print(f"gatetherm: error: {err}", file=sys.stderr)
        return 2
    except (FileNotFoundError, IsADirectoryError, PermissionError) as err:
        print(f"gatetherm: error: {err.filename}: {err.strerror}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("gatetherm: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
