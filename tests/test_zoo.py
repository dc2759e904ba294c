"""The machine zoo (validation/examples, ``gatetherm validate zoo``): every machine loads and runs,
and invariants that hold on any machine: the steady heat balance, a free body refused by name,
results independent of the node numbering, P2 against P1 within the element-order check's claim.
The heavy matrix cells are slow tests that pin each cell's value."""
from __future__ import annotations

import dataclasses
import re
import shutil

import numpy as np
import pytest

import gatetherm as gt
from gatetherm import InputError
from gatetherm.validation.zoo import CAPABILITIES, MACHINES, guarded, markdown

NEW = ("lathe_headstock", "gantry", "grinding_wheelhead", "ballscrew_axis", "vertical_column", "rotary_table",
       "spindle_unit")
TWO_D = tuple(n for n in MACHINES if n != "gantry")
SLOW_3D = [pytest.param("gantry", marks=pytest.mark.slow)]


@pytest.fixture(scope="module")
def cases():
    return {}


def case_of(cases, name):
    if name not in cases:
        cases[name] = gt.load_case(MACHINES[name].case_path)
    return cases[name]


def test_the_zoo_has_nine_machines_of_seven_new_kinds_and_twelve_capabilities():
    assert set(NEW) < set(MACHINES) and len(MACHINES) == 9
    assert len(CAPABILITIES) == 12
    for name in NEW:
        folder = MACHINES[name].case_path.parent
        assert gt.load_case(folder / "case.toml").schedule.label.startswith("schedule ") and list(folder.glob("*.geo"))


# --- loads and runs ---------------------------------------------------------------------------

# δ swing over the 6-h duty cycle (µm), pinned; band: a machine-tool's thermal error, 1 .. 200 µm
SWING_UM = {"c_frame": 54.89, "lathe_headstock": 11.18, "gantry": 81.71, "grinding_wheelhead": 33.95,
            "ballscrew_axis": 89.45, "vertical_column": 7.7, "rotary_table": 15.73, "spindle_unit": 75.83}


@pytest.mark.parametrize("name", [n for n in TWO_D if n != "joint"] + SLOW_3D)
def test_every_zoo_machine_runs_its_duty_cycle(cases, name):
    case = case_of(cases, name)
    run = gt.run(case, keep=())
    d = run["delta_um"]
    swing = float(d.max() - d.min())
    assert np.isfinite(d).all()
    assert swing == pytest.approx(SWING_UM[name], rel=0.02)  # band: 1 .. 200 µm
    temps = [c for c in run.columns if c.endswith("_degC") and c != "ambient_degC"]
    assert 20.0 < max(float(run[c].max()) for c in temps) < 60.0  # a few hundred W warm a machine by a few K


# --- steady heat balance ------------------------------------------------------------------------

def steady_balance(case, t: float = 0.0):
    """(sources, losses, heat in through fixed temperatures) in W of the steady state at the
    inputs of time ``t``, from the FE operators: sources Σ fᵢ of the source loads; losses
    1ᵀ K₀ U − Σ fᵢ of the film and face loads (the films' h ∫ (T − T_amb)); the fixed
    temperatures' reactions Σ (K₀ U − f) over their unknowns. A film that follows the temperature adds
    its law's part beyond K₀ (``correction``)."""
    from gatetherm.solvers.heat import HeatSolver, environment
    from gatetherm.solvers.model import build

    sys = build(case.problem, case.mesh).heat
    env = environment(case.schedule.drive, t)
    U = HeatSolver(sys).steady(env)
    solid = np.zeros(sys.n)
    solid[:sys.n_solid] = 1.0

    def total(kinds):
        return sum(float(solid @ ld.vector) * ld.value(env) for ld in sys.loads if ld.kind in kinds)

    KU = sys.K0 @ U + sys.correction(U, env)  # with a film that follows the temperature: its law's h
    residual = KU - sys.f(env, sys.mode(env))
    return total(("source",)), float(solid @ KU) - total(("film", "faces")), float(residual[sys.fixed_dofs].sum())


def nominal_power(case, t: float = 0.0) -> float:
    """The sum of the schedule's power columns (``*_W``) and of the machine elements' losses at ``t``
    (a bearing's at the schedule's speed): what the case file asks for, W."""
    from gatetherm.studies.run.simulate import loss_columns

    env = case.schedule.drive(t)
    losses = loss_columns(case.problem, {"time_s": np.array([t]), **{k: np.array([v]) for k, v in env.items()}})
    return sum(v for k, v in env.items() if k.endswith("_W")) + sum(float(v[0]) for v in losses.values())


@pytest.mark.parametrize("name", [n for n in TWO_D if n != "joint"] + SLOW_3D)
def test_steady_heat_balance_sources_equal_losses(cases, name):
    case = case_of(cases, name)
    source, lost, fixed = steady_balance(case)
    assert fixed == 0.0  # no fixed temperature on these machines
    assert source == pytest.approx(nominal_power(case), rel=1e-9)  # power spread over the region: all of it
    assert abs(source - lost) <= 1e-9 * source


def test_steady_heat_balance_of_the_joint_through_its_fixed_temperatures(cases):
    source, lost, fixed = steady_balance(case_of(cases, "joint"))
    assert source == 0.0 and abs(lost) < 1e-9  # W: no film, no source
    # heat in at 100 °C = heat out at 0 °C: the reactions cancel; q A = 10 909 W/m² × 0.05 m × 0.02 m
    from gatetherm.solvers.heat import HeatSolver, environment
    from gatetherm.solvers.model import build

    case = case_of(cases, "joint")
    sys = build(case.problem, case.mesh).heat
    env = environment(case.schedule.drive, 0.0)
    U = HeatSolver(sys).steady(env)
    r = (sys.K0 @ U - sys.f(env, sys.mode(env)))
    hot = next(d for d, v in sys.fixed if v(env) == 100.0)
    assert float(r[hot].sum()) == pytest.approx(100.0 / (0.1 / 50 + 1 / 2000 + 0.1 / 15) * 0.05 * 0.02, rel=1e-9)
    assert abs(fixed) <= 1e-9 * float(r[hot].sum())


# --- a free body is refused by name ---------------------------------------------------------------

def unsupported_copy(tmp_path, name):
    """The machine's folder copied with every support made to hold x only (2-D: y and the
    rotation free; 3-D: y, z and the rotations; axisymmetric: the axial translation)."""
    src = MACHINES[name].case_path.parent
    dst = tmp_path / name
    shutil.copytree(src, dst)
    text = (dst / "case.toml").read_text()
    text = re.sub(r'(\[supports\.[^\]]+\]\s*\n)type = "[a-z]+"[^\n]*', r'\1type = "fixed"\ncomponents = ["x"]', text)
    (dst / "case.toml").write_text(text)
    return dst / "case.toml"


@pytest.mark.parametrize("name", list(TWO_D) + SLOW_3D)
def test_a_free_body_is_refused_naming_the_part(tmp_path, name):
    path = unsupported_copy(tmp_path, name)
    regions = set(gt.load_case(MACHINES[name].case_path).mesh.regions)
    with pytest.raises(InputError) as err:
        gt.run(gt.load_case(path), keep=())
    text = str(err.value)
    assert "\n" not in text and "free to move" in text and "translation y" in text
    named = set(re.search(r"the part made of regions? (.+?) is free", text).group(1).split(", "))
    joined = {r for c in gt.load_case(MACHINES[name].case_path).problem.contacts for r in c.between}
    # a bonded machine is one part (every region named); with a joint, the part on one side of it, or the
    # whole machine where the joint's stiffness holds its sides together (the ball screw's floating support)
    assert named == regions if not joined else named <= regions


# --- node numbering -----------------------------------------------------------------------------

def permuted(case, seed: int = 51):
    """The case on its mesh with the nodes renumbered at random."""
    m = case.mesh
    perm = np.random.default_rng(seed).permutation(len(m.points))  # new index i holds old node perm[i]
    inv = np.empty_like(perm)
    inv[perm] = np.arange(len(perm))
    mesh = dataclasses.replace(m, points=m.points[perm], cells=inv[m.cells],
                               boundaries={k: inv[v] for k, v in m.boundaries.items()},
                               sensors={k: int(inv[v]) for k, v in m.sensors.items()},
                               lines={k: inv[v] for k, v in m.lines.items()})
    return dataclasses.replace(case, mesh=mesh)


@pytest.mark.slow
@pytest.mark.parametrize("name", list(MACHINES))
def test_results_do_not_depend_on_the_node_numbering(cases, name):
    case = case_of(cases, name)
    a, b = gt.run(case, keep=()), gt.run(permuted(case), keep=())
    for col in a.columns:  # relative to the largest column of its unit (a held point's is round-off of 0)
        unit = col.rsplit("_", 1)[-1]
        scale = max(float(np.abs(a[c]).max()) for c in a.columns if c.rsplit("_", 1)[-1] == unit)
        assert np.abs(a[col] - b[col]).max() <= 1e-8 * max(scale, 1e-12), col


def test_node_numbering_steady_heat_of_the_lathe(cases):
    """The fast version: the steady temperatures at the probes of the headstock, renumbered."""
    case = case_of(cases, "lathe_headstock")
    from gatetherm.solvers.heat import HeatSolver, environment
    from gatetherm.solvers.model import build

    out = []
    for c in (case, permuted(case)):
        model = build(c.problem, c.mesh)
        env = environment(c.schedule.drive, 0.0)
        U = HeatSolver(model.heat).steady(env)
        out.append(np.array([U[c.mesh.sensors[s]] for s in sorted(c.mesh.sensors)]))
    assert np.abs(out[0] - out[1]).max() <= 1e-9 * np.abs(out[0]).max()
    assert out[0].max() == pytest.approx(30.12, abs=0.05)  # 170 W at steady state: 10 K above the room


# --- P2 against P1 ------------------------------------------------------------------------------

def full_p2_relative(case):
    """The element-order check of a P1 run and the change of its outputs to a full P2 run, relative to
    the largest output of its unit as the check measures it."""
    from gatetherm.studies.run.order_check import TOLERANCE, UNITS

    run1 = gt.run(case, keep=(), check_order=True)
    run2 = gt.run(case.with_order(2), keep=())
    check = run1.order_check
    p1 = {k: float(run1[k][-1]) for k in check.p1}
    p2 = {k: float(run2[k][-1]) for k in check.p1}
    base = {u: case.problem.T_ref if u == "_degC" else 0.0 for u in UNITS}
    size = {u: max((abs(p2[k] - base[u]) for k in p1 if k.endswith(u)), default=0.0) for u in UNITS}
    rel = {k: (p2[k] - p1[k]) / max(next(s for u, s in size.items() if k.endswith(u)), 1e-300) for k in p1}
    return check, rel, TOLERANCE


# |full P2 − P1| / scale of the worst output, pinned; the check's verdict (warned: > 2 %)
P2_WORST = {"lathe_headstock": (0.0059, False), "grinding_wheelhead": (0.0040, False),
            "ballscrew_axis": (0.0196, False), "vertical_column": (0.0143, False), "rotary_table": (0.0011, False),
            "c_frame": (0.0136, False), "gantry": (0.041, True)}


@pytest.mark.slow
@pytest.mark.parametrize("name", list(P2_WORST))
def test_p2_against_p1_within_the_order_checks_claim(cases, name):
    check, rel, tol = full_p2_relative(case_of(cases, name))
    worst = max(abs(v) for v in rel.values())
    warned = abs(check.relative[check.worst]) > tol
    expected, expect_warn = P2_WORST[name]
    assert warned == expect_warn
    if not warned:  # the check's claim: no output moves by more than its tolerance
        assert worst <= tol
    assert worst == pytest.approx(expected, abs=max(0.3 * expected, 1e-3))


# --- the matrix --------------------------------------------------------------------------------

def test_a_cell_that_raises_or_hangs_is_one_failed_line():
    def raises(_):
        raise ValueError("a\nb")

    def refuses(_):
        raise InputError("where", "what", "fix")

    def hangs(_):
        import time
        time.sleep(60)

    assert guarded(raises, None, timeout_s=30)["text"] == "FAILED: ValueError: a b"
    assert guarded(refuses, None, timeout_s=30)["text"] == "refused: where: what; fix"
    hung = guarded(hangs, None, timeout_s=1.0)
    assert hung["status"] == "failed" and "1-s limit" in hung["text"]
    assert guarded(lambda _: (2.5, "ok"), None, timeout_s=30)["value"] == 2.5
    table = markdown({"m": {"run": {"status": "ok", "value": 2.5, "text": "x", "seconds": 1.0},
                            "rom": {"status": "refused", "value": None, "text": "refused: y", "seconds": 0.0}}})
    assert "| m | 2.5 | refused |" in table and "1 numbers, 1 refusals, 0 failed" in table


def test_an_unknown_machine_is_refused():
    with pytest.raises(InputError, match="unknown machine 'lathe'"):
        gt.validate_zoo("/nonexistent-zoo", ["lathe"])


# --- every cell of the matrix, pinned (slow: the whole zoo) -------------------------------------

# (status, value or words of the refusal) of every cell, as `gatetherm validate zoo --out Z` gave them
# (Z/zoo.json; docs/validation.md, "The machine zoo"); a root cause fixed elsewhere changes its cells: update them.
NO_SIGNALS = "case.toml: signals: a compensated case needs [time] and [signals] with theta_A, theta_B, theta_C"
PINNED = {
    ("c_frame", "run"): ("ok", 54.89),
    ("c_frame", "reduce"): ("ok", 0.001542),
    ("c_frame", "paper"): ("ok", 2.351),
    ("c_frame", "mlr"): ("ok", 3.046),
    ("c_frame", "rom"): ("ok", 1.096),
    ("c_frame", "errormodel comp"): ("ok", 6.144),
    ("c_frame", "sweep"): ("ok", -4.921),
    ("c_frame", "sensors"): ("ok", 0.2758),
    ("c_frame", "diagnose"): ("ok", 1.299),
    ("c_frame", "errormodel"): ("ok", 0.4606),
    ("c_frame", "report"): ("ok", 54.89),
    ("c_frame", "export ccx"): ("ok", 1.179e-05),
    ("joint", "run"): ("ok", 47.38),
    ("joint", "reduce"): ("refused", "case: two blocks and a joint has no transient heat solve (steady or pr"),
    ("joint", "paper"): ("refused", NO_SIGNALS),
    ("joint", "mlr"): ("refused", NO_SIGNALS),
    ("joint", "rom"): ("refused", NO_SIGNALS),
    ("joint", "errormodel comp"): ("refused", "target ux_a_um: only 1 valid samples in the fitting span; give at leas"),
    ("joint", "sweep"): ("ok", -0.8701),
    ("joint", "sensors"): ("refused", "validation/examples/joint/case.toml: has no relative displacement to p"),
    ("joint", "diagnose"): ("refused", "--data: 1 samples are too few to train and hold out; give a longer run"),
    ("joint", "errormodel"): ("refused", "target ux_a_um: only 1 valid samples in the fitting span; give at leas"),
    ("joint", "report"): ("refused", "joint run: 1 data row: a drift needs two samples or more; give the who"),
    ("joint", "export ccx"): ("refused", "contacts.joint.stiffness: an elastic joint layer has no CalculiX count"),
    ("lathe_headstock", "run"): ("ok", 11.18),
    ("lathe_headstock", "reduce"): ("ok", 0.07311),
    ("lathe_headstock", "paper"): ("ok", 2.86),
    ("lathe_headstock", "mlr"): ("ok", 3.194),
    ("lathe_headstock", "rom"): ("ok", 0.4643),
    ("lathe_headstock", "errormodel comp"): ("ok", 4.003),
    ("lathe_headstock", "sweep"): ("ok", -0.1053),
    ("lathe_headstock", "sensors"): ("ok", 0.2218),
    ("lathe_headstock", "diagnose"): ("ok", 1.601),
    ("lathe_headstock", "errormodel"): ("ok", 0.8076),
    ("lathe_headstock", "report"): ("ok", 11.18),
    ("lathe_headstock", "export ccx"): ("ok", 0.0001232),
    ("gantry", "run"): ("ok", 81.71),
    ("gantry", "reduce"): ("ok", 0.006666),
    ("gantry", "paper"): ("ok", 4.95),
    ("gantry", "mlr"): ("ok", 7.296),
    ("gantry", "rom"): ("ok", 1.195),
    ("gantry", "errormodel comp"): ("ok", 4.614),
    ("gantry", "sweep"): ("ok", -16.02),
    ("gantry", "sensors"): ("ok", 0.3867),
    ("gantry", "diagnose"): ("ok", 1.3),
    ("gantry", "errormodel"): ("ok", 3.031),
    ("gantry", "report"): ("ok", 81.71),
    ("gantry", "export ccx"): ("ok", 2.376e-06),
    ("grinding_wheelhead", "run"): ("ok", 33.95),
    ("grinding_wheelhead", "reduce"): ("ok", 0.1473),
    ("grinding_wheelhead", "paper"): ("refused", "--method paper: paper would leave δ 44.38 um > 14.39 um uncompensated "),
    ("grinding_wheelhead", "mlr"): ("ok", 3.629),
    ("grinding_wheelhead", "rom"): ("ok", 1.178),
    ("grinding_wheelhead", "errormodel comp"): ("ok", 7.62),
    ("grinding_wheelhead", "sweep"): ("ok", 0.07095),
    ("grinding_wheelhead", "sensors"): ("ok", 0.5995),
    ("grinding_wheelhead", "diagnose"): ("ok", 1.301),
    ("grinding_wheelhead", "errormodel"): ("ok", 3.599),
    ("grinding_wheelhead", "report"): ("ok", 19.56),
    ("grinding_wheelhead", "export ccx"): ("ok", 2.768e-05),
    ("ballscrew_axis", "run"): ("ok", 89.45),
    ("ballscrew_axis", "reduce"): ("ok", 0.3885),
    ("ballscrew_axis", "paper"): ("ok", 0.4641),
    ("ballscrew_axis", "mlr"): ("ok", 6.513),
    ("ballscrew_axis", "rom"): ("ok", 2.103),
    ("ballscrew_axis", "errormodel comp"): ("ok", 24.67),
    ("ballscrew_axis", "sweep"): ("ok", -16.27),
    ("ballscrew_axis", "sensors"): ("ok", 1.646),
    ("ballscrew_axis", "diagnose"): ("ok", 1.398),
    ("ballscrew_axis", "errormodel"): ("ok", 2.61),
    ("ballscrew_axis", "report"): ("ok", 89.45),
    ("ballscrew_axis", "export ccx"): ("refused", "contacts.floating.stiffness: an elastic joint layer has no CalculiX co"),
    ("vertical_column", "run"): ("ok", 7.7),
    ("vertical_column", "reduce"): ("ok", 0.004755),
    ("vertical_column", "paper"): ("ok", 4.167),
    ("vertical_column", "mlr"): ("ok", 1.032),
    ("vertical_column", "rom"): ("ok", 0.1998),
    ("vertical_column", "errormodel comp"): ("ok", 1.845),
    ("vertical_column", "sweep"): ("ok", -0.251),
    ("vertical_column", "sensors"): ("ok", 0.1836),
    ("vertical_column", "diagnose"): ("ok", 1.302),
    ("vertical_column", "errormodel"): ("ok", 0.1463),
    ("vertical_column", "report"): ("ok", 7.7),
    ("vertical_column", "export ccx"): ("refused", "contacts.bolted.stiffness: an elastic joint layer has no CalculiX coun"),
    ("rotary_table", "run"): ("ok", 15.73),
    ("rotary_table", "reduce"): ("ok", 0.003928),
    ("rotary_table", "paper"): ("ok", 0.2128),
    ("rotary_table", "mlr"): ("ok", 0.4547),
    ("rotary_table", "rom"): ("ok", 0.2015),
    ("rotary_table", "errormodel comp"): ("ok", 0.1633),
    ("rotary_table", "sweep"): ("ok", -0.6922),
    ("rotary_table", "sensors"): ("ok", 0.07958),
    ("rotary_table", "diagnose"): ("ok", 1.305),
    ("rotary_table", "errormodel"): ("ok", 0.1087),
    ("rotary_table", "report"): ("ok", 15.73),
    ("rotary_table", "export ccx"): ("ok", 0.0002534),
    ("spindle_unit", "run"): ("ok", 75.83),
    ("spindle_unit", "reduce"): ("ok", 8.12),  # the nose's correlation film held at its run's mean
    ("spindle_unit", "paper"): ("refused", NO_SIGNALS),
    ("spindle_unit", "mlr"): ("refused", NO_SIGNALS),
    ("spindle_unit", "rom"): ("refused", NO_SIGNALS),
    ("spindle_unit", "errormodel comp"): ("ok", 26.33),
    ("spindle_unit", "sweep"): ("ok", -15.0),
    ("spindle_unit", "sensors"): ("ok", 0.274),
    ("spindle_unit", "diagnose"): ("ok", 1.299),
    ("spindle_unit", "errormodel"): ("ok", 7.608),
    ("spindle_unit", "report"): ("ok", 75.83),
    ("spindle_unit", "export ccx"): ("ok", 0.01088),
}
TOLERANCE = {"sensors": 0.15, "diagnose": 0.05, "errormodel": 0.15, "errormodel comp": 0.15, "rom": 0.15}
"""Relative tolerance of a pinned number (default 2 %): the sensor placement's and the error models'
selections are greedy on small differences, the rom's observer on the run's noise-free signals.
A fresh install (SciPy 1.17.1, NumPy 2.4.6, gmsh 4.15.2) moved three "errormodel comp" cells of
the same code (not traced to one library; the likeliest is SciPy's L-BFGS-B tuning the time constants)
(grinding_wheelhead 6.46 → 7.62 µm, rotary_table 0.3375 → 0.1633 µm, ballscrew_axis 24.59 → 24.67 µm,
each still better than uncompensated); they are pinned as that install gives them."""


@pytest.fixture(scope="module")
def contexts(tmp_path_factory):
    from gatetherm.studies.run.scenario import run_scenario
    from gatetherm.validation.zoo import Context

    made = {}

    def get(name):  # as the zoo's runner makes them
        if name not in made:
            case = gt.load_case(MACHINES[name].case_path)
            made[name] = Context(MACHINES[name], case, run_scenario(case), tmp_path_factory.mktemp(name))
        return made[name]
    return get


@pytest.mark.slow
@pytest.mark.parametrize("name,capability", [(m, c) for m in MACHINES for c in CAPABILITIES if (m, c) in PINNED])
def test_every_cell_of_the_zoo_is_its_pinned_value(contexts, name, capability):
    from gatetherm.validation.zoo import TIMEOUT_S
    from gatetherm.validation.zoo.cells import CELLS

    status, expected = PINNED[name, capability]
    if capability == "export ccx" and status == "ok" and shutil.which("ccx") is None:
        pytest.skip("CalculiX (Debian calculix-ccx) is not installed: the cell runs the deck it exports")
    cell = guarded(CELLS[capability], contexts(name), timeout_s=TIMEOUT_S)
    assert "\n" not in cell["text"]
    assert cell["status"] == status, cell["text"]
    if status == "ok":
        assert cell["value"] == pytest.approx(expected, rel=TOLERANCE.get(capability, 0.02), abs=1e-3), cell["text"]
    else:
        assert expected in cell["text"], cell["text"]
