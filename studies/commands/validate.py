"""``gatetherm validate TARGET``: regenerate a validation study (work in progress)."""
from __future__ import annotations


def register(sub) -> None:
    p = sub.add_parser("validate", help="regenerate a validation study")
    p.set_defaults(func=lambda args: 0)
