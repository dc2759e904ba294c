"""The layers: geometry → solvers → studies → validation → the public API → CLI, never back.

Every import of every module (top level and inside functions) is read from the source;
a module may import gatetherm modules of its own layer or earlier ones only. Numerics
(geometry, solvers) import no plotting library.
"""
from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
#: Source folder -> package it installs as (pyproject.toml's package-dir).
FOLDERS = {"core": "gatetherm", "geometry": "gatetherm.geometry", "solvers": "gatetherm.solvers",
           "studies": "gatetherm.studies", "validation": "gatetherm.validation"}
LAYERS = ("gatetherm", "gatetherm.geometry", "gatetherm.solvers", "gatetherm.studies", "gatetherm.validation",
          "gatetherm.api", "gatetherm.cli")
PLOTTING = ("matplotlib", "pyvista", "vtk", "vtkmodules")


def layer(module: str) -> int:
    """Index in :data:`LAYERS` of the longest layer prefix of ``module``."""
    best = max((p for p in LAYERS if module == p or module.startswith(p + ".")), key=len)
    return LAYERS.index(best)


def modules() -> dict[str, Path]:
    out = {}
    for folder, package in FOLDERS.items():
        for path in (ROOT / folder).rglob("*.py"):
            parts = path.relative_to(ROOT / folder).with_suffix("").parts
            parts = parts[:-1] if parts[-1] == "__init__" else parts
            out[".".join((package, *parts))] = path
    return out


def imports(path: Path) -> set[str]:
    found = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            found |= {a.name for a in node.names}
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            found.add(node.module)
            found |= {f"{node.module}.{a.name}" for a in node.names}  # "from pkg import module"
    return found


MODULES = modules()


def test_every_package_folder_is_mapped():
    assert {"gatetherm.cli", "gatetherm.studies.run", "gatetherm.solvers.heat"} <= set(MODULES)
    assert "gatetherm.validation.plots" in MODULES and len(MODULES) > 50


@pytest.mark.parametrize("name", sorted(MODULES))
def test_no_back_edges(name):
    own = layer(name)
    later = sorted(m for m in imports(MODULES[name])
                   if (m == "gatetherm" or m.startswith("gatetherm.")) and m in MODULES and layer(m) > own)
    assert not later, f"{name} ({LAYERS[own]}) imports later layers: {later}"


@pytest.mark.parametrize("name", sorted(m for m in MODULES if layer(m) <= LAYERS.index("gatetherm.solvers")))
def test_numerics_do_not_plot(name):
    bad = sorted(m for m in imports(MODULES[name]) if m.split(".")[0] in PLOTTING)
    assert not bad, f"{name} imports {bad}"


def test_the_walk_sees_a_back_edge(tmp_path):
    """The checker itself: a library module importing the CLI is caught."""
    path = tmp_path / "bad.py"
    path.write_text("def f():\n    from gatetherm.cli import main\n    from gatetherm.validation import plots\n")
    assert {"gatetherm.cli.main", "gatetherm.validation.plots"} <= imports(path)
    assert layer("gatetherm.cli.simulate") > layer("gatetherm.validation.paper_table") \
        > layer("gatetherm.studies.run.scenario")


def test_the_facade_offers_the_api_and_the_cli_calls_only_it_and_below():
    """``import gatetherm as gt`` names exactly ``gatetherm.api.__all__`` (imported on first use, from the
    API layer only); the CLI is the one module above the API."""
    import gatetherm
    import gatetherm.api

    assert set(gatetherm.API) == set(gatetherm.api.__all__)
    assert all(getattr(gatetherm, name) is getattr(gatetherm.api, name) for name in gatetherm.API)
    root = imports(MODULES["gatetherm"])
    assert not {m for m in root if m.startswith("gatetherm.")}  # the root imports no layer at import time
    above = [m for m in MODULES if layer(m) > LAYERS.index("gatetherm.api")]
    assert above and all(m.startswith("gatetherm.cli") for m in above)


def backend_choices(path: Path) -> list[str]:
    """Where the module at ``path`` would choose a matplotlib backend: calls of ``matplotlib.use`` or
    ``pyplot.switch_backend`` (through any alias), ``from matplotlib import use``, and assignments
    to ``rcParams["backend"]``."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    alias = {}  # local name -> module
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            alias |= {(a.asname or a.name.split(".")[0]): (a.name if a.asname else a.name.split(".")[0])
                      for a in node.names}
        elif isinstance(node, ast.ImportFrom) and node.module and node.module.split(".")[0] == "matplotlib":
            alias |= {(a.asname or a.name): f"{node.module}.{a.name}" for a in node.names}
    found = []
    for node in ast.walk(tree):
        where = (getattr(node, "lineno", 0), f"{path.name}:{getattr(node, 'lineno', 0)}")
        if isinstance(node, ast.Call):
            f = node.func
            name = (f"{alias.get(f.value.id, f.value.id)}.{f.attr}" if isinstance(f, ast.Attribute)
                    and isinstance(f.value, ast.Name) else alias.get(f.id, f.id) if isinstance(f, ast.Name) else "")
            if name in ("matplotlib.use", "matplotlib.pyplot.switch_backend"):
                found.append((*where, name))
        elif isinstance(node, (ast.Assign, ast.AugAssign)):
            for target in getattr(node, "targets", [getattr(node, "target", None)]):
                if isinstance(target, ast.Subscript) and isinstance(target.slice, ast.Constant) \
                        and target.slice.value == "backend":
                    found.append((*where, "rcParams['backend']"))
    return [f"{w} {what}" for _, w, what in sorted(found)]


@pytest.mark.parametrize("name", sorted(MODULES))
def test_no_module_chooses_a_matplotlib_backend(name):
    assert not backend_choices(MODULES[name])


def test_the_backend_check_sees_every_form(tmp_path):
    path = tmp_path / "bad.py"
    path.write_text("import matplotlib\nimport matplotlib as mpl\nimport matplotlib.pyplot as plt\n"
                    "from matplotlib import use, rcParams\n"
                    "matplotlib.use('Agg')\nmpl.use('Agg')\nplt.switch_backend('Agg')\nuse('Agg')\n"
                    "rcParams['backend'] = 'Agg'\n\ndef f():\n    import matplotlib\n    matplotlib.use('svg')\n")
    assert [f.split(" ", 1)[1] for f in backend_choices(path)] == [
        "matplotlib.use", "matplotlib.use", "matplotlib.pyplot.switch_backend", "matplotlib.use",
        "rcParams['backend']", "matplotlib.use"]
    path.write_text("import matplotlib\nmatplotlib.get_backend()\nx = {}\nx['backend'] = 1\n")
    assert backend_choices(path) == ["bad.py:4 rcParams['backend']"]  # any 'backend' key: on the safe side
