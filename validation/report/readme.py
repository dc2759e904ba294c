"""The README's generated tables: a block between ``<!-- report:NAME -->`` and ``<!-- /report -->``
is replaced by the table of that name from the report's full results, so the README quotes
the same numbers as the page (never edited by hand)."""
from __future__ import annotations

import re

from gatetherm import InputError

BLOCK = re.compile(r"^(<!-- report:([\w-]+) -->\n)(.*?)^(<!-- /report -->)$", re.S | re.M)
START = re.compile(r"^<!-- report:[\w-]+ -->$", re.M)
"""A block's first line (a marker quoted inside a line of text is not one)."""


def blocks(text: str) -> list[str]:
    """Names of the generated blocks of a README text, in order."""
    names = [m.group(2) for m in BLOCK.finditer(text)]
    if len(START.findall(text)) != len(names):
        raise InputError("README", "a <!-- report:NAME --> marker without its <!-- /report --> end",
                         "close every block with <!-- /report -->")
    return names


def full_tables(results: dict) -> tuple[dict, set]:
    """({block name: markdown} of the tables of full results, names whose result is a subset)."""
    tables, partial = {}, set()
    for r in results.values():
        for t in (r.tables if r else ()):
            if t.readme:
                if r.stamp.get("full"):
                    tables[t.readme] = t.markdown()
                else:
                    partial.add(t.readme)
    return tables, partial


def rewrite(text: str, tables: dict[str, str]) -> tuple[str, list[str]]:
    """``text`` with every block whose table is in ``tables`` replaced; returns (new text, the
    names rewritten); a block whose table is not in ``tables`` stays as it is
    (:func:`check_names` refuses a block naming no table of the report)."""
    done = []

    def sub(m):
        name = m.group(2)
        if name not in tables:
            return m.group(0)
        done.append(name)
        return m.group(1) + tables[name].rstrip("\n") + "\n" + m.group(4)

    return BLOCK.sub(sub, text), done


def check_names(names, known, path: str) -> None:
    unknown = [n for n in names if n not in known]
    if unknown:
        raise InputError(f"{path}: <!-- report:{unknown[0]} -->", "no section of the report makes this table",
                         "known tables: " + ", ".join(sorted(known)))
