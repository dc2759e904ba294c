"""The Python API reference, ``docs/api.md``, made from the docstrings of the public names
(``gatetherm.API`` and ``gt.plot``): ``python -m gatetherm.cli.api_reference > docs/api.md``
writes it, and ``tests/test_docs.py`` checks that the committed file is what this makes and that
every public name is documented (a numpydoc ``Parameters`` section wherever it takes any)."""
from __future__ import annotations

import ast
import inspect
import re
import sys
import textwrap

SECTION = re.compile(r"^(Parameters|Returns|Yields|Raises|Notes|Examples)\n-+$", re.M)


def _rst(text: str) -> str:
    """reStructuredText inline markup as Markdown: roles and double backticks as code, ``::``
    blocks as fenced Python."""
    text = re.sub(r":(?:func|class|meth|mod|data|attr):`~?([^`]+)`", r"`\1`", text).replace("``", "`")
    return re.sub(r"::\n\n((?:    .*\n?|\n)+)", lambda m: ":\n\n```python\n" + textwrap.dedent(m.group(1)).strip("\n")
                  + "\n```\n\n", text)


def _numpydoc(doc: str) -> str:
    """A numpydoc docstring as Markdown: sections as bold labels, entries as list items."""
    doc = _rst(doc)
    parts = SECTION.split(doc)
    out = [parts[0].strip()]
    for title, body in zip(parts[1::2], parts[2::2]):
        items: list[str] = []
        for line in body.strip("\n").splitlines():
            if not line.strip():
                continue
            if line.startswith(" ") and items:
                items[-1] += " " + line.strip()
            else:
                name, _, kind = line.partition(" : ")
                items.append(f"- `{name.strip()}`" + (f" ({kind.strip()})" if kind else "") + ":")
        out.append(f"**{title}**\n\n" + "\n".join(i.rstrip(":") if i.endswith(":") else i for i in items))
    return "\n\n".join(p for p in out if p)


def _attributes(cls) -> list[tuple[str, str]]:
    """(name, docstring) of a dataclass's fields with an attribute docstring."""
    try:
        tree = ast.parse(textwrap.dedent(inspect.getsource(cls)))
    except (OSError, TypeError):
        return []
    body, out = tree.body[0].body, []
    for a, b in zip(body, body[1:]):
        if isinstance(a, ast.AnnAssign) and isinstance(b, ast.Expr) and isinstance(b.value, ast.Constant) \
                and isinstance(b.value.value, str) and not a.target.id.startswith("_"):
            out.append((a.target.id, _rst(" ".join(inspect.cleandoc(b.value.value).split()))))
    return out


def _signature(obj) -> str:
    """``(a: int, b: str = 'x', *, c=None) -> T`` with the annotations as written in the source."""
    try:
        sig = inspect.signature(obj)
    except (TypeError, ValueError):
        return "(...)"
    P, out, star = inspect.Parameter, [], False
    for p in sig.parameters.values():
        if p.kind is P.KEYWORD_ONLY and not star:
            out.append("*")
        star = star or p.kind in (P.KEYWORD_ONLY, P.VAR_POSITIONAL)
        text = {P.VAR_POSITIONAL: "*", P.VAR_KEYWORD: "**"}.get(p.kind, "") + p.name
        if p.annotation is not P.empty:
            hint = p.annotation if isinstance(p.annotation, str) else inspect.formatannotation(p.annotation)
            text += ": " + re.sub(r"Annotated\[(\w+), \w+\]", r"\1", hint)  # the boundary's marks are not types
        if p.default is not P.empty:
            text += f" = {p.default!r}" if p.annotation is not P.empty else f"={p.default!r}"
        out.append(text)
    ret = sig.return_annotation
    ret = "" if ret in (P.empty, None, "None") else f" -> {ret if isinstance(ret, str) else inspect.formatannotation(ret)}"
    return f"({', '.join(out)}){ret}"


def _entry(prefix: str, name: str, obj) -> list[str]:
    L = [f"### `{prefix}{name}{'' if inspect.isclass(obj) else _signature(obj)}`", "",
         _numpydoc(inspect.getdoc(obj) or ""), ""]
    if inspect.isclass(obj):
        attrs = _attributes(obj)
        if attrs:
            L += ["| attribute | meaning |", "| --- | --- |"]
            L += [f"| `{a}` | {d.replace('|', chr(92) + '|')} |" for a, d in attrs] + [""]
        for m, member in inspect.getmembers(obj):
            own = m in vars(obj)
            doc = inspect.getdoc(member) if own else None
            if m.startswith("_") or not doc or not (inspect.isfunction(member) or isinstance(member, property)):
                continue
            sig = "" if isinstance(member, property) else _signature(member).replace("(self, ", "(").replace("(self)", "()")
            L += [f"#### `{name}.{m}{sig}`", "", _numpydoc(doc), ""]
    return L


def public() -> list[tuple[str, str, object]]:
    """(prefix, name, object) of every documented public name: ``gt.NAME`` and ``gt.plot.NAME``."""
    import gatetherm.api as gt

    return [("gt.", n, getattr(gt, n)) for n in gt.__all__] + [("gt.plot.", n, getattr(gt.plot, n))
                                                             for n in gt.plot.__all__]


def markdown() -> str:
    """``docs/api.md``."""
    import gatetherm.api

    plots = gatetherm.api.plot
    names = public()
    L = ["# Python API reference", "",
         "Generated from the docstrings by `python -m gatetherm.cli.api_reference > docs/api.md` "
         "(`tests/test_docs.py` checks that this file is what they make). Everything here is reached "
         "through `import gatetherm as gt`; units are SI unless a name says otherwise (`_um`: µm, "
         "`_degC`: °C, `_MPa`: MPa).", "",
         "Contents: " + ", ".join(f"`{p}{n}`" for p, n, _ in names) + ".", "",
         "## `gatetherm`", "", _numpydoc(inspect.getdoc(gatetherm.api) or ""), ""]
    for prefix, name, obj in names:
        if prefix == "gt.plot." and name == plots.__all__[0]:
            L += ["## `gatetherm.plot`", "", _numpydoc(inspect.getdoc(plots) or ""), ""]
        L += _entry(prefix, name, obj)
    return "\n".join(L).rstrip("\n") + "\n"


if __name__ == "__main__":
    sys.stdout.write(markdown())
