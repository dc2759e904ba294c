"""A conservative text scan of a gmsh ``.geo`` script and every file it reads.

The scan tokenises the script (comments and strings apart, as gmsh's lexer does) and
follows every ``Include``, ``Merge``, ``ShapeFromFile`` and ``ListFromFile``: each must name
its file as a string (``"part.geo"`` or ``StrCat(CurrentDir, "part.geo")``, relative to the
file it is in) inside the case's folder or among the files the case names
(``mesh.include``); a computed path is refused, so no file escapes the scan. With
``commands``, it also refuses every command that runs a program, writes, renames or deletes
a file or folder, or ends gmsh (:data:`COMMANDS`, ``Printf … >``, ``Print``, ``Delete File``,
``Solver.*`` and ``General.*File*`` options), wherever it appears: inside a ``Macro`` as
much as outside, whatever string it is given. It is the fallback where the sandbox of
:mod:`gatetherm.geometry.sandbox` cannot report what a script tries.
"""
from __future__ import annotations

import re
from pathlib import Path

from gatetherm import InputError

READERS = ("Include", "Merge", "MergeWithBoundingBox", "ShapeFromFile", "ListFromFile")
"""Commands and functions that read a file."""
COMMANDS = {"System": "runs a program", "SystemCall": "runs a program", "NonBlockingSystemCall": "runs a program",
            "OnelabRun": "runs a program", "OnelabAction": "runs a solver", "CreateDir": "creates a folder",
            "Save": "writes a file", "Plugin": "runs a plugin (some write files)", "Exit": "ends gmsh",
            "Abort": "ends gmsh", "SendToServer": "talks to a server", "RenameFile": "renames a file",
            "DeleteFile": "deletes a file"}
"""Identifiers refused wherever they appear (with ``commands``)."""
ENDS = ("Abort",)
"""Commands that end the reading of a script and leave gmsh meshing what was read so far: refused
always, with or without ``commands`` (``Exit`` ends gmsh, which the sandbox reports)."""
DATA = {".step", ".stp", ".brep", ".iges", ".igs", ".stl", ".msh", ".vtk", ".vtu", ".med", ".unv", ".mesh",
        ".inp", ".bdf", ".nas", ".obj", ".ply", ".off", ".x3d", ".xao", ".cgns", ".p3d", ".pos.bin"}
"""Formats gmsh reads with another reader than its script parser (not scanned)."""
_TOKEN = re.compile(r"//[^\n]*|/\*.*?\*/|\"[^\"]*\"|'[^']*'|>>|[A-Za-z_][A-Za-z0-9_]*|\S", re.S)
_FILE_OPTION = re.compile(r"(File|Executable|Options|Session|Dir|Save)")


def tokens(text: str) -> list[tuple[str, int]]:
    """(token, line) pairs, comments dropped; a string keeps its quotes."""
    out, line, at = [], 1, 0
    for m in _TOKEN.finditer(text):
        line += text.count("\n", at, m.start())
        at = m.start()
        if not m.group().startswith(("//", "/*")):
            out.append((m.group(), line))
    return out


def _path(toks, i: int) -> str | None:
    """The literal path read by the reader at ``toks[i]``, or None (computed)."""
    j = i + 1 + (toks[i + 1][0] == "(" if i + 1 < len(toks) else 0)
    rest = [t for t, _ in toks[j:j + 6]]
    if rest[:1] and rest[0][:1] in "\"'":
        return rest[0][1:-1]
    if rest[:3] == ["StrCat", "(", "CurrentDir"] or rest[:3] == ["StrCat", "(", "CurrentDirectory"]:
        if len(rest) > 5 and rest[3] == "," and rest[4][:1] in "\"'" and rest[5] == ")":
            return rest[4][1:-1]
    return None


def scan(path: Path, root: Path, allowed=(), commands: bool = False) -> list[Path]:
    """Check ``path`` and, recursively, the files it reads; return them all. ``root`` is the
    case's folder, ``allowed`` the files outside it that the case names. Raises InputError
    naming the file and the line."""
    allowed = {Path(p).resolve() for p in allowed}
    root, todo, seen = Path(root).resolve(), [Path(path).resolve()], []
    while todo:
        f = todo.pop()
        if f in seen:
            continue
        seen.append(f)
        try:
            text = f.read_text(encoding="utf-8", errors="replace")
        except OSError as err:
            raise InputError(str(f), f"cannot be read ({err.strerror})", "check the path") from None
        toks = tokens(text)
        for i, (tok, line) in enumerate(toks):
            if i and toks[i - 1][0] == ".":  # an option (General.FileName …)
                group = toks[i - 2][0]
                if commands and (group == "Solver" or group == "General" and _FILE_OPTION.search(tok)):
                    _refuse(f, line, f"{toks[i - 2][0]}.{tok}", "names a program or a file to write")
                continue
            if tok in READERS:
                name = _path(toks, i)
                if name is None:
                    raise InputError(str(f), f"line {line}: {tok} of a computed path",
                                     "give the file name as a string, relative to the file")
                target = (f.parent / name).resolve()
                if not (target.is_relative_to(root) or target in allowed):
                    raise InputError(str(f), f"line {line}: {tok} \"{name}\" reads a file outside the case's folder",
                                     f"copy it beside the case or name it in the case: [mesh] include = [\"{name}\"]")
                if target.suffix.lower() not in DATA:
                    todo.append(target)
            elif tok in ENDS:  # even in the sandbox: what follows it would be dropped without a word
                raise InputError(str(f), f"line {line}: {tok} ends gmsh's reading of the script there (the "
                                 "groups after it would be missing)", "remove it")
            elif not commands:
                continue
            elif tok in COMMANDS:
                _refuse(f, line, tok, COMMANDS[tok])
            elif tok == "Print" and (i + 1 == len(toks) or toks[i + 1][0] != "."):
                _refuse(f, line, tok, "writes a file")
            elif tok == "Delete" and i + 1 < len(toks) and toks[i + 1][0] == "File":
                _refuse(f, line, "Delete File", "deletes a file")
            elif tok == "Printf" and _redirected(toks, i):
                _refuse(f, line, "Printf … >", "writes a file")
    return seen


def _redirected(toks, i: int) -> bool:
    """Whether the ``Printf`` at ``toks[i]`` sends its output to a file (``>`` or ``>>``)."""
    depth = 0
    for tok, _ in toks[i + 1:]:
        depth += tok == "("
        depth -= tok == ")"
        if tok == ";" and depth <= 0:
            return False
        if tok in (">", ">>") and depth == 0:
            return True
    return False


def _refuse(f: Path, line: int, what: str, does: str) -> None:
    raise InputError(str(f), f"line {line}: {what} {does}; gatetherm does not allow it in a geometry script",
                     "remove it")
