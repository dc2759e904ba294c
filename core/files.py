"""Reading the text of an input file, with one clear line for whatever can go wrong.

Model files, study files, case files, schedules and data files are UTF-8 text; a leading
byte-order mark (spreadsheets write one) is dropped. A missing file, a directory, a file
that cannot be read, bytes that are not UTF-8 and binary content each end in an
:class:`~gatetherm.InputError` naming the file (and the line of a bad byte) and the fix.
"""
from __future__ import annotations

import os
from pathlib import Path

from gatetherm import InputError


def read_text(path: str | os.PathLike, option: str = "", fix: str = "give a text file") -> str:
    """The text of the UTF-8 file ``path``; ``option`` (e.g. ``"--config"``) names where the
    path came from in the messages about the path itself."""
    p = Path(path)
    field = option or str(p)
    try:
        if p.is_dir():
            raise InputError(field, f"'{path}' is a directory", fix)
        if not p.exists():
            raise InputError(field, f"no such file '{path}'", fix)
        if not p.is_file():
            raise InputError(field, f"'{path}' is not a regular file", fix)
        data = p.read_bytes()
    except OSError as err:
        raise InputError(field, f"cannot read '{path}' ({err.strerror or err})", "check its permissions") from None
    utf8 = "save it as UTF-8" + (" (a spreadsheet's 'CSV UTF-8')" if p.suffix.lower() == ".csv" else "")
    if data.startswith((b"\xff\xfe", b"\xfe\xff")):
        raise InputError(str(p), "is UTF-16 text", utf8)

    def line(at: int) -> str:
        n = data.count(b"\n", 0, at) + 1
        return f"{p}, line {n}"

    if b"\0" in data:
        raise InputError(line(data.index(b"\0")), "holds a NUL byte: a binary file, not text", fix)
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as err:
        raise InputError(line(err.start), f"byte 0x{data[err.start]:02x} is not UTF-8 text", utf8) from None


MAX_TOML_DEPTH = 32
"""Deepest nesting of tables and arrays a TOML input file may have."""


def parse_toml(text: str, where: str, fix: str = "fix the file's syntax", what: str = "valid TOML") -> dict:
    """The document of the TOML text of the file ``where``: InputError (one line) for text that is
    not TOML and for nesting deeper than :data:`MAX_TOML_DEPTH` (arrays thousands deep would
    otherwise exhaust the parser's recursion)."""
    import tomllib

    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as err:
        raise InputError(where, f"not {what} ({err})", fix) from None
    except RecursionError:
        data = None
    stack = [(data, 1)]
    while stack:
        value, depth = stack.pop()
        if value is None or depth > MAX_TOML_DEPTH:
            raise InputError(where, f"nested deeper than {MAX_TOML_DEPTH} levels", fix)
        if isinstance(value, (dict, list)):
            stack.extend((v, depth + 1) for v in (value.values() if isinstance(value, dict) else value)
                         if isinstance(v, (dict, list)))
    return data
