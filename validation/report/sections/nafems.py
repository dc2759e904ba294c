"""NAFEMS section: T1, T3, T4, LE11, LE1 and LE10 run as case files (validation/nafems/), each against
its published target (NAFEMS, The Standard NAFEMS Benchmarks, TNSB Rev. 3, 1990)."""
from __future__ import annotations

import tomllib
from pathlib import Path

from gatetherm.validation.report.result import Result, table

BENCHMARKS = {
    "t1": ("T1 membrane with hot spot, σ_yy at D", "sigma_yy_MPa", "50", "MPa", "quarter"),
    "t3": ("T3 1-D transient, T at x = 0.08 m, t = 32 s", "T_degC", "36.60", "°C", ""),
    "t4": ("T4 2-D convection, T at E", "T_degC", "18.25", "°C", ""),
    "le11": ("LE11 cylinder/taper/sphere, σ_zz at A", "sigma_zz_MPa", "-105", "MPa", "quarter"),
    "le1": ("LE1 elliptic membrane, σ_yy at D", "sigma_yy_MPa", "92.7", "MPa", "quarter"),
    "le10": ("LE10 thick plate under pressure, σ_yy at D", "sigma_yy_MPa", "-5.38", "MPa", "quarter"),
}
"""Case -> (label, probe quantity of the probe ``target``, published target as printed, unit, model note)."""


def signed(text: str) -> str:
    """A number's text with a typographic minus."""
    return text.replace("-", "−")


def case_dir() -> Path:
    import gatetherm.validation

    return Path(gatetherm.validation.__path__[0]) / "nafems"


def run(path: Path) -> tuple[dict, object]:
    """The probes' summary and the case of one benchmark (as ``gatetherm run`` computes them)."""
    from gatetherm.studies.run.case import load_case
    from gatetherm.studies.run.output import probe_summary
    from gatetherm.studies.run.scenario import run_scenario

    case = load_case(path)
    res = run_scenario(case)
    return probe_summary(case.problem, res.columns), case


def _mesh_note(path: Path, case) -> str:
    params = tomllib.loads(path.read_text(encoding="utf-8")).get("mesh", {}).get("parameters", {})
    sizes = ", ".join(f"{k} = {v * 1e3:g} mm" for k, v in params.items())
    return f"{len(case.mesh.points)} nodes ({sizes})" if sizes else f"{len(case.mesh.points)} nodes"


def _element(case, extra: str) -> str:
    p = case.problem
    kind = f"plane {p.plane}" if p.dim == 2 and p.elastic else f"{p.dim}-D"
    transient = f", Δt {case.time.step:g} s CN" if case.time else ""
    return ", ".join(x for x in (f"P{p.order}", kind, extra) if x) + transient


def compute(ctx) -> Result:
    rows = []
    for name in ctx.scope["cases"]:
        label, quantity, target, unit, extra = BENCHMARKS[name]
        path = case_dir() / f"{name}.toml"
        summary, case = run(path)
        got = summary["probes"]["target"][quantity]
        rows.append((label, signed(f"{target} {unit}"), signed(f"{got:.5g} {unit}"),
                     signed(f"{100 * (got / float(target) - 1):+.3f} %"),
                     _mesh_note(path, case), _element(case, extra)))
    t = table("NAFEMS benchmarks: gatetherm against the published targets",
              ("benchmark", "target", "gatetherm", "rel. error", "mesh", "element"), rows,
              note="Each case is `validation/nafems/NAME.toml` run as `gatetherm run` runs it; the value is the "
                   "probe `target` in its summary.json.")
    return Result(tables=(t,))
