"""Reduced-order model: the seam, Gramians, balanced reduction, exact stepping, observer, controller."""
import numpy as np
import pytest
import scipy.linalg as sla
import scipy.sparse as sp

from gatetherm import InputError
from gatetherm.frame.conditions import CONDITIONS
from gatetherm.solvers.gramians import ShiftedSolves, gramian_factor
from gatetherm.frame.problem import build_model
from gatetherm.solvers.rom import Input, ReducedModel, linear_heat_model, reduce
from gatetherm.studies.run.reduce import load_rom, series_inputs, write_rom
from gatetherm.solvers.rom_time import discretise, march_rom, simulate_rom
from gatetherm.studies.control.observer import ObserverParams, kalman, uniform_state
from gatetherm.studies.control.predictive import PredictiveParams, event_updates, minimax, plan_threshold
from gatetherm.studies.run.conditions import SupplyParams, condition_drive
from gatetherm.studies.run.simulate import column, run_model, sample_times

from conftest import FIXED_MODEL


@pytest.fixture(scope="module")
def coarse(frame_2d):
    """The fixture frame's model, its linear heat model and a 20-state reduction."""
    model = build_model(FIXED_MODEL, 2, frame_2d)
    lhm = linear_heat_model(model, column)
    return model, lhm, reduce(lhm, 20)


def test_seam_uniform_rise_is_steady_and_read_as_one_kelvin(coarse):
    """Frame, oil and hose 1 K above T0 with oil and room 1 K above T0 is a steady state of both
    pump modes (K_p 1 = B_p [1, 1] to round-off), and every temperature output reads 1 K."""
    _, lhm, _ = coarse
    one = np.ones(lhm.M.shape[0])
    for mode in ("on", "off"):
        assert np.max(np.abs(lhm.K[mode] @ one - lhm.B[mode] @ [1.0, 1.0])) < 1e-10 * np.abs(lhm.B[mode]).max()
    temps = [i for i, n in enumerate(lhm.outputs) if n.endswith("_degC")]
    assert np.allclose(lhm.C[temps] @ one, 1.0, atol=1e-12) and np.allclose(lhm.y0[temps], lhm.T0, atol=1e-12)
    assert lhm.inputs == (Input("oil_degC", 20.0), Input("ambient_degC", 20.0)) and lhm.modes == ("on", "off")
    assert lhm.key_outputs == ("delta_um", "delta_E_um", "theta_A_degC", "theta_B_degC", "theta_C_degC",
                               "T_tank_wall_degC", "T_tank_oil_degC")


def test_gramian_factor_solves_the_lyapunov_equation():
    """ADI factors of a small nonsymmetric heat-like system against scipy's dense solution."""
    rng = np.random.default_rng(1)
    n = 40
    L = sp.diags([-np.ones(n - 1), 2.0 * np.ones(n), -np.ones(n - 1)], [-1, 0, 1]) * 50.0
    K = (L + sp.diags(rng.uniform(0.1, 1.0, n)) + sp.coo_matrix(([0.3], ([0], [5])), shape=(n, n))).tocsr()
    M = sp.diags(rng.uniform(1.0, 2.0, n)).tocsr()
    B, C = rng.standard_normal((n, 2)), rng.standard_normal((3, n))
    solves = ShiftedSolves(K, M)
    Minv = np.diag(1 / M.diagonal())
    A = -Minv @ K.toarray()
    P = sla.solve_continuous_lyapunov(A, -Minv @ B @ B.T @ Minv)
    Z = gramian_factor(solves, B)
    assert np.linalg.norm(Z @ Z.T - P) < 1e-8 * np.linalg.norm(P)
    Q = sla.solve_continuous_lyapunov(A.T, -C.T @ C)  # for E = M: Mᵀ Q_E M = Q of the explicit form
    Y = gramian_factor(solves, C.T, observability=True)
    assert np.linalg.norm(M.T @ (Y @ Y.T) @ M - Q) < 1e-8 * np.linalg.norm(Q)


def test_reduction_static_gain_stability_and_fe_agreement(coarse):
    """Exact static δ gain in both modes, a common Lyapunov function (A_p + A_pᵀ < 0), and the
    condition-1 run within 0.5 µm of the FE march on the same mesh."""
    model, lhm, red = coarse
    rom = red.rom
    assert rom.states == 20 and max(red.static_gain_error.values()) < 1e-8
    for mode in rom.modes:
        assert np.linalg.eigvalsh(rom.A[mode] + rom.A[mode].T).max() < 0
    times = sample_times(5 * 3600.0)
    drive = condition_drive(CONDITIONS[1], SupplyParams())
    fe = run_model(model, drive, times).columns
    u, modes = series_inputs(rom, fe)
    y = simulate_rom(rom, 60.0, u, modes)
    assert np.max(np.abs(y[:, rom.output("delta_um")] - fe["delta_um"])) == pytest.approx(0.1048, abs=0.01)  # ≤ 0.5
    assert np.max(np.abs(y[:, rom.output("theta_A_degC")] - fe["theta_A_degC"])) < 0.1
    assert max(red.error_bound.values()) < 1.0


def test_exact_step_for_linear_inputs():
    """One state, ẋ = −a x + b u with u a ramp: the closed form to round-off, both modes."""
    a, b, dt = 1e-3, 2e-3, 60.0
    rom = ReducedModel({"on": np.array([[-a]]), "off": np.array([[-2 * a]])},
                       {"on": np.array([[b, 0.0]]), "off": np.array([[0.0, b]])}, np.eye(1), np.zeros((1, 2)),
                       np.zeros(1), (Input("a", 0.0), Input("b", 0.0)), ("T_degC",), ("pump",))
    t = np.arange(11) * dt
    u = np.column_stack([0.01 * t, 0.02 * t])
    X = march_rom(discretise(rom, dt), u, np.zeros(10, int))
    exact = b * 0.01 * (t / a - (1 - np.exp(-a * t)) / a ** 2)
    assert np.max(np.abs(X[:, 0] - exact)) < 1e-12 * np.abs(exact).max()
    X = march_rom(discretise(rom, dt), u, np.ones(10, int))
    exact = b * 0.02 * (t / (2 * a) - (1 - np.exp(-2 * a * t)) / (2 * a) ** 2)
    assert np.max(np.abs(X[:, 0] - exact)) < 1e-12 * np.abs(exact).max()


def test_a_long_stretch_is_marched_in_eigenvectors_to_round_off(coarse, monkeypatch):
    """Hour-long pump stretches of 120 steps (≥ MODAL_MIN: marched in Φ's eigenvectors) from a warm
    state give the states of the step-by-step march to round-off, in both pump modes."""
    import gatetherm.solvers.rom_time as rom_time

    rom = coarse[2].rom
    disc = discretise(rom, 30.0)
    assert set(disc.modal) == {0, 1} and rom_time.MODAL_MIN <= 120  # both modes' Φ well-conditioned
    t = np.arange(0.0, 5 * 3600.0 + 1, 30.0)
    u = np.column_stack([np.where((t // 3600) % 2 == 0, 20.0, 0.0), np.sin(t / 5000.0)])
    modes = np.where((t[:-1] // 3600) % 2 == 0, 0, 1)
    x0 = 1.5 * uniform_state(rom, disc)
    modal = march_rom(disc, u, modes, x0)
    monkeypatch.setattr(rom_time, "MODAL_MIN", len(t))
    stepped = march_rom(disc, u, modes, x0)
    rel = np.max(np.abs(modal - stepped)) / np.max(np.abs(stepped))
    assert rel < 1e-11  # achieved 6.1e-14 (band: round-off times the eigenvectors' condition)


def test_rom_file_round_trip_and_bad_file(coarse, tmp_path):
    rom = coarse[2].rom
    write_rom(rom, tmp_path / "rom.npz")
    back = load_rom(tmp_path / "rom.npz")
    assert back.inputs == rom.inputs and back.outputs == rom.outputs and back.T0 == rom.T0
    assert all(np.array_equal(back.A[m], rom.A[m]) and np.array_equal(back.B[m], rom.B[m]) for m in rom.modes)
    assert all(np.array_equal(getattr(back, k), getattr(rom, k)) for k in ("C", "D", "y0"))
    with np.load(tmp_path / "rom.npz") as d:
        assert d["inputs"].dtype.kind == "U" and {"A_on", "B_on", "A_off", "B_off", "C", "D", "y0", "offsets",
                                                  "modes", "pumps", "T0"} <= set(d.files)
    np.savez(tmp_path / "bad.npz", A_on=np.eye(2))
    with pytest.raises(InputError, match="not a reduced model"):
        load_rom(tmp_path / "bad.npz")


def test_observer_recovers_state_and_learns_a_wrong_delta_map(coarse):
    """Truth: the reduced model from 1.5 K warm, and δ with 0.8 µm/K × θ_C the model lacks. From
    noisy θ_A, θ_B, θ_C and δ the filter's δ (with the learned correction) and its state converge."""
    rom = coarse[2].rom
    disc = discretise(rom, 60.0)
    t = sample_times(5 * 3600.0)
    oil = np.where((t // 3600) % 2 == 0, 20.0, 0.0)
    u, modes = np.column_stack([oil, np.zeros_like(t)]), np.where((t[:-1] // 3600) % 2 == 0, 0, 1)
    X = march_rom(disc, u, modes, 1.5 * uniform_state(rom, disc))
    Y = X @ rom.C.T
    ch = [rom.output(k) for k in ("theta_A_degC", "theta_B_degC", "theta_C_degC")]
    delta = Y[:, rom.output("delta_um")] + 0.8 * Y[:, rom.output("theta_C_degC")]
    rng = np.random.default_rng(0)
    est = kalman(rom, disc, u, modes, Y[:, ch] + rng.normal(0, 0.05, (len(t), 3)), ch,
                 delta + rng.normal(0, 0.1, len(t)), ObserverParams())
    late = t >= 3600
    fitted = np.array([est.delta_of(rom, k, X[k]) for k in range(len(t))])
    assert np.max(np.abs(fitted - delta)[late]) < 0.5
    assert np.max(np.abs((est.z[:, :rom.states] - X) @ rom.C[ch[2]])[late]) < 0.1


def test_minimax_and_event_plan():
    cmd, L = minimax(np.array([0.0, 1.0, 2.0, 3.0, 4.0]), 1.0)
    assert (cmd, L) == (-1.0, 3)  # 0..2 fits a band of ±1 around 1
    assert minimax(np.array([5.0]), 0.1) == (-5.0, 1)
    ramp = np.arange(101.0)  # 1 µm per sample: a hold of L samples spans L − 1 µm
    assert event_updates(ramp, 2.0, 60) == 21  # holds of 5 samples (4 µm)
    p = PredictiveParams(max_updates=28, plan_fraction=0.75)  # at most 21 updates planned
    h = plan_threshold(np.r_[0.0, ramp], p, 60)
    assert event_updates(ramp, h, 60) <= 21 < event_updates(ramp, h - p.threshold_step_um, 60)
    with pytest.raises(InputError):
        PredictiveParams(mode="sometimes")
