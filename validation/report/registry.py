"""The report's sections: one entry each, in page order.

An entry names its compute function (``module:function`` in
:mod:`gatetherm.validation.report.sections`, imported when it runs), the scope of the default
run (``subset``) and of ``--full``, and what its cache digest covers beyond the code: data
files and external programs. A section whose code is not in this build has no compute
function and says what brings it (``pending``); adding it later is filling in its entry.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Mapping


@dataclass(frozen=True)
class Section:
    key: str
    """Name after ``--section``, folder under ``DIR/sections`` and anchor on the page."""
    title: str
    """Heading on the page."""
    compute: str | Callable = ""
    """``module:function`` under ``gatetherm.validation.report.sections`` (or the function):
    Context -> Result."""
    subset: Mapping = field(default_factory=dict)
    """Scope of the default run, handed to the compute function (JSON values; in the digest)."""
    full: Mapping | None = None
    """Scope of ``--full`` (None: the default run is already the full study)."""
    about: str = ""
    """What the default run leaves out, in words (shown beside the scope)."""
    inputs: tuple[str, ...] = ()
    """Data files it reads, ``package:glob`` or absolute paths (their bytes, or their absence, are in the digest)."""
    tools: tuple[str, ...] = ()
    """External programs it runs (their version line is in the digest)."""
    also: str = ""
    """The command outside the report that makes the same study."""
    pending: str = ""
    """For a section not in this build: what brings it."""

    def scope(self, full: bool) -> dict:
        return dict(self.full if full and self.full is not None else self.subset)

    def command(self, out: str, full: bool) -> str:
        """The one command that regenerates this section alone (into the page at ``out``)."""
        return f"gatetherm report --out {out} --section {self.key}" + (" --full" if full and self.full else "")


@dataclass(frozen=True)
class Context:
    """What a compute function gets."""

    work: Path
    """Its folder: figures and files go here (referred to by name in the Result)."""
    scope: dict
    """The section's subset or full scope (:attr:`Section.subset`, :attr:`Section.full`)."""
    workers: int
    """Worker processes it may use."""


PAPER_MODEL = "gatetherm.studies:data/paper.toml"
BENCHMARKS = Path(__file__).resolve().parents[2] / "benchmarks" / "results"
"""Where the benchmark scripts of a source checkout write their results (absent in an installed wheel)."""
BENCHMARK_FILES = {"peer.json": "python benchmarks/peer.py --rounds 3",
                   "scaling.json": "python benchmarks/scaling.py",
                   "backends.json": "python benchmarks/backends.py --rounds 3",
                   "blas_threads.json": "python benchmarks/blas_threads.py --rounds 3",
                   "huge_pages.json": "python benchmarks/blas_threads.py --huge-pages --rounds 5",
                   "malloc.json": "python benchmarks/blas_threads.py --malloc --rounds 5",
                   "errormodel.json": "/tmp/venv_bench/bin/python benchmarks/errormodel.py --data FILE.csv"}
"""Result files of the benchmark scripts the speed section shows, with the command that measures
each."""

SECTIONS: tuple[Section, ...] = (
    Section("verification", "Verification: convergence orders and exact cases", "verification:compute",
            subset={"elastic_3d": ["3-D P2"]}, full={"elastic_3d": ["3-D P1", "3-D P2"]},
            about="the 3-D P1 elastic order (70 s) is left out",
            also="python -m pytest tests/test_verification_heat.py tests/test_verification_elastic.py -s "
                 "(-m slow adds the 3-D elastic orders)"),
    Section("nafems", "NAFEMS benchmarks through case files", "nafems:compute",
            subset={"cases": ["t1", "t3", "t4", "le11", "le1", "le10"]}, inputs=("gatetherm.validation:nafems/*",),
            also="gatetherm run validation/nafems/t1.toml --out D (and t3, t4, le11, le1, le10)"),
    Section("paper", "Paper vs gatetherm, 2-D and 3-D (Figs. 10-13 analogues)", "paper:compute",
            subset={"dims": [2, 3], "size_3d": 0.015}, full={"dims": [2, 3], "size_3d": None},
            about="3-D on a coarser mesh (element size 15 mm instead of the model's 9 mm)",
            inputs=(PAPER_MODEL,), also="gatetherm validate paper --out runs"),
    Section("beam", "Beam theory against FE (Figs. 7-8 analogues)", "beam:compute",
            subset={"dim": 2, "a_every": 4, "series": False}, full={"dim": 2, "a_every": 1, "series": True},
            about="every fourth l/l4 value and no slenderness, tie-bar height or mesh series",
            inputs=(PAPER_MODEL,), also="gatetherm validate beam --dim 2 --out v"),
    Section("design", "Design study: tie-bar position and a second tie bar", "design:compute",
            subset={"dim": 2, "positions": 6, "refine": 2, "second_above": [0.0, 0.2], "size": 0.012},
            full={"dim": 2, "positions": 14, "refine": 6, "second_above": [0.0, 0.1, 0.2, 0.35], "size": None},
            about="6 + 2 tie-bar heights instead of 14 + 6, two second-bar heights instead of four, "
                  "elements of 12 mm instead of 8 mm",
            inputs=(PAPER_MODEL,), also="gatetherm validate design --out d"),
    Section("compensation", "Compensation (Figs. 14-16 analogues)", "compensation:compute",
            subset={"dim": 2}, inputs=(PAPER_MODEL,), also="gatetherm validate compensation --out comp"),
    Section("hidden-effects", "Discrepancy diagnosis: hidden effects found blind", "hidden:compute",
            subset={"conditions": [1], "effects": ["joint_resistance", "none"], "seed": 6, "per_kind": 1},
            full={"conditions": [1, 2, 3], "effects": "all", "seed": 6, "per_kind": None},
            about="two cases of condition 1: a hidden tie-bar joint resistance and noise only (the full "
                  "study: 8 effects at two strengths, noise, 3 outside effects and 2 wrong parameters on "
                  "conditions 1-3, 78 cases)",
            inputs=(PAPER_MODEL,), also="gatetherm validate hidden-effects --out DIR"),
    Section("c-frame", "A second machine: the C-frame example", "cframe:compute",
            subset={"case": "examples/c_frame/case.toml"}, inputs=("gatetherm.validation:examples/c_frame/*",),
            also="gatetherm run validation/examples/c_frame/case.toml --out cf"),
    Section("case-diagnosis", "Diagnosis on a user's frame: the C-frame with hidden pieces", "casediag:compute",
            subset={"case": "examples/c_frame/case.toml", "seed": 10,
                    "scenarios": ["film+offset", "noise-only, case mesh"]},
            full={"case": "examples/c_frame/case.toml", "seed": 10, "scenarios": None},
            about="two of the nine scenarios (a film and a thermocouple offset hidden; noise only on the case's "
                  "own mesh)",
            inputs=("gatetherm.validation:examples/c_frame/*",), also="gatetherm validate case-diagnosis --out DIR"),
    Section("calculix", "CalculiX cross-check of the 3-D frame", "calculix:compute",
            subset={"condition": 1, "time_min": 15, "size_3d": 0.015},
            full={"condition": 1, "time_min": 15, "size_3d": None},
            about="15-mm elements instead of the model's 9 mm",
            inputs=(PAPER_MODEL,), tools=("ccx",),
            also="gatetherm export ccx --condition 1 --time 15 --dim 3 --out X && (cd X && ccx job)"),
    Section("rom", "Reduced-order model, observer and predictive compensation", "rom:compute",
            subset={"dims": [2], "conditions": [1, 2, 3], "effects": "all"},
            full={"dims": [2, 3], "conditions": [1, 2, 3], "effects": "all"},
            about="2-D only: no 3-D reduced model and no 3-D data on the 2-D model (the 3-D reduction took "
                  "25 min and 13 GB)",
            inputs=(PAPER_MODEL,), also="gatetherm validate rom --out DIR"),
    Section("sensors", "Sensor placement: where to put the thermocouples", "sensors:compute",
            subset={"frame_count": 3, "case_count": 4, "loads": 20, "case": "examples/c_frame/case.toml", "seeds": [0]},
            full={"frame_count": 3, "case_count": 4, "loads": 20, "case": "examples/c_frame/case.toml",
                  "seeds": [0, 1, 2, 3, 4]},
            about="the paper frame for seed 0 only (--full: seeds 0-4 of the generated loads and the noise)",
            inputs=(PAPER_MODEL, "gatetherm.validation:examples/c_frame/*"),
            also="gatetherm sensors --dim 2 --count 3 --check --out s; "
                 "gatetherm sensors --case validation/examples/c_frame/case.toml --count 4 --out cs"),
    Section("compound", "Compound diagnosis: several missing pieces at once", "compound:compute",
            subset={"seed": 14, "pairs": 2, "single": False, "mesh_size": 0.012},
            full={"seed": 14, "pairs": 48, "single": True, "mesh_size": None},
            about="the first 2 of the 48 random pairs on 12-mm elements, no single-piece cases (each "
                  "diagnosis takes 1-2 min)",
            inputs=(PAPER_MODEL,), also="gatetherm validate compound --out DIR"),
    Section("zoo", "The machine zoo: every capability on every machine", "zoo:compute",
            subset={"machines": None, "timeout_s": 300.0},
            about="", inputs=("gatetherm.validation:examples/*/*",), tools=("ccx",),
            also="gatetherm validate zoo --out Z"),
    Section("speed", "Speed and scaling", "speed:compute", inputs=tuple(str(BENCHMARKS / f) for f in BENCHMARK_FILES),
            also="; ".join(BENCHMARK_FILES.values())),
)


def section(key: str, sections=SECTIONS) -> Section:
    return next(s for s in sections if s.key == key)
