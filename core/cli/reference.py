"""The command-line reference, ``docs/cli.md``, made from the argument parsers themselves:
``python -m gatetherm.cli.reference > docs/cli.md`` writes it, and ``tests/test_docs.py``
checks that the committed file is what this makes, so it is never stale."""
from __future__ import annotations

import argparse
import sys

WIDTH = 100
"""Line width of the usage blocks (fixed, so that the page does not depend on the terminal)."""


def _usage(p: argparse.ArgumentParser) -> str:
    fmt = argparse.HelpFormatter(prog=p.prog, width=WIDTH)
    fmt.add_usage(p.usage, p._actions, p._mutually_exclusive_groups, prefix="")
    return fmt.format_help().strip()


def _cell(text: str) -> str:
    return " ".join(str(text).split()).replace("|", "\\|")


def _name(a: argparse.Action) -> str:
    return ", ".join(f"`{o}`" for o in a.option_strings) or f"`{a.metavar or a.dest}`" + (" …" if a.nargs in ("+", "*") else "")


def _argument(a: argparse.Action) -> str:
    if a.nargs == 0 or not a.option_strings:
        return ""
    if a.choices is not None and a.metavar is None:
        return " \\| ".join(f"`{c}`" for c in a.choices)
    meta = a.metavar or a.dest.upper()
    return f"`{' '.join(meta) if isinstance(meta, tuple) else meta}`" + (" …" if a.nargs in ("+", "*") else "")


def _subcommands(p: argparse.ArgumentParser):
    """(name, one-line help, parser) of each sub-command of ``p``, in ``--help`` order."""
    for a in p._actions:
        if isinstance(a, argparse._SubParsersAction):
            helps = {c.dest: c.help for c in a._choices_actions}
            yield from ((name, helps.get(name, ""), sub) for name, sub in a.choices.items())


def _section(p: argparse.ArgumentParser, level: int, summary: str = "") -> list[str]:
    L = [f"{'#' * level} `{p.prog}`", ""]
    if summary:
        L += [_cell(summary[0].upper() + summary[1:]) + ("" if summary.endswith(".") else "."), ""]
    L += ["```", _usage(p), "```", ""]
    if p.description and p.description != summary:
        L += [_cell(p.description), ""]
    rows = [a for a in p._actions if not isinstance(a, (argparse._HelpAction, argparse._SubParsersAction))]
    if rows:
        L += ["| argument | value | meaning |", "| --- | --- | --- |"]
        L += [f"| {_name(a)} | {_argument(a)} | "
              f"{_cell(a.help or '')} |" for a in rows if a.help is not argparse.SUPPRESS]
        L.append("")
    for name, help_, sub in _subcommands(p):
        L += _section(sub, min(level + 1, 4), help_ or "")
    return L


def markdown(parser: argparse.ArgumentParser | None = None) -> str:
    """``docs/cli.md``: every command and option of ``parser`` (default: ``gatetherm``'s)."""
    if parser is None:
        from gatetherm.cli import build_parser

        parser = build_parser()
    head = ["# Command-line reference", "",
            "Generated from the argument parsers by `python -m gatetherm.cli.reference > docs/cli.md` "
            "(`tests/test_docs.py` checks that this file is what they make). Every command also prints "
            "its own `--help`. Exit codes: 0 done; 1 an I/O failure or failed sweep points; 2 bad input "
            "(one line on stderr naming the file, the field and the fix); 130 Ctrl-C; 143 SIGTERM.", "",
            "Commands: " + ", ".join(f"[`{n}`](#gatetherm-{n})" for n, _, _ in _subcommands(parser)) + ".", ""]
    return "\n".join(head + _section(parser, 1)[2:]).rstrip("\n") + "\n"


if __name__ == "__main__":
    sys.stdout.write(markdown())
