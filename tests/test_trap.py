"""Runs in a trap (inputs.environment, integrators.taylor_env, integrators.secular_env): the
perfect vacuum is the vacuum bit for bit; a run is reproduced by its seed; the field turns L at
|d x E| / |L| in full integration and at the averaged rate in secular's; the gas brakes a
sphere at 10 p / (pi rho a v_bar) through single collisions and a crystal left in it takes its
temperature; the methods that cannot carry the environment refuse it with the reason."""

import math
from pathlib import Path

import numpy as np
import pytest

import spinviz
from spinviz import units as U
from spinviz.errors import SceneError, SpecError
from spinviz.inputs.environment import EnvironmentSpec
from spinviz.inputs.scene_spec import load_scene, parse_scene
from spinviz.physics import gas as G
from spinviz.physics import presets as P
from spinviz.physics.bodies import Body, Shape

ROOT = Path(__file__).resolve().parents[1]
CUBE = ROOT / "scenes" / "dast_cube.toml"
SPIN = [0.0, 3.141592653589793e10, 3.141592653589793e10]


def cube_doc(**env):
    import tomllib

    d = tomllib.loads((CUBE).read_text())
    d["simulation"]["samples"] = 20
    if env:
        d["environment"] = env
    return d


def test_the_perfect_vacuum_is_the_vacuum_bit_for_bit():
    """An environment with nothing in it (the table absent, all defaults, pressure 0, a zero field)
    changes nothing: the same arrays, bit for bit, from Python and from a scene."""
    cube = P.dast_cube()
    a = spinviz.simulate(cube, "reduced", SPIN, t_end=1e3, samples=9)
    for env in (EnvironmentSpec(), {"pressure_mbar": 0.0, "field_v_per_m": [0.0, 0.0, 0.0], "gas": "He"}):
        b = spinviz.simulate(cube, "reduced", SPIN, t_end=1e3, samples=9, environment=env)
        assert np.array_equal(a.omega, b.omega) and np.array_equal(a.q, b.q) and "environment" not in b.stats
    s1 = parse_scene(cube_doc(), "a.toml")
    s2 = parse_scene(cube_doc(pressure_mbar=0.0, seed=5), "b.toml")
    r1, r2 = spinviz.simulate_request(s1.request("truncated")), spinviz.simulate_request(s2.request("truncated"))
    assert np.array_equal(r1.omega, r2.omega) and np.array_equal(r1.q, r2.q)


def test_a_run_is_reproduced_by_its_seed():
    """The collisions' random streams come from the environment's seed: the same seed, the same
    run; another seed, another one."""
    cube = P.dast_cube()
    kw = dict(t_end=2e4, samples=5, method="secular")
    runs = [spinviz.simulate(cube, "reduced", SPIN, **kw, environment={"pressure_mbar": 1e-12, "seed": s})
            for s in (3, 3, 4)]
    assert runs[0].stats["collisions"] > 300
    assert np.array_equal(runs[0].omega, runs[1].omega) and not np.array_equal(runs[0].omega, runs[2].omega)


def test_the_field_turns_L_at_d_cross_E_over_L_in_full_integration():
    """Taylor's method with d x E in its equations: a rod spun about its axis (d along it, so
    along L) in a field across L turns L about E at |d x E| / |L| (a gyroscope: the angle turned
    over 3 ms, 0.09 rad, to 1e-3: the axis lags L by the precession over the nutation rate,
    2e-4), keeping |L|."""
    rod = P.cellulose_rod()
    E = np.array([1.0, 0.0, 0.0])                                   # V/m, world frame, across L (along z)
    tr = spinviz.simulate(rod, "reduced", [0.0, 0.0, 1e7], t_end=3e-3, samples=3, method="taylor",
                          environment={"field_v_per_m": list(E)})
    L = tr.angular_momentum_world()
    rate = np.linalg.norm(np.cross(np.asarray(rod.dipole), U.field_from_v_per_m(E))) / np.linalg.norm(L[0])
    turned = math.acos(float(L[0] @ L[-1]) / (np.linalg.norm(L[0]) * np.linalg.norm(L[-1])))
    assert turned == pytest.approx(rate * tr.t[-1], rel=1e-3)
    assert np.linalg.norm(L[-1]) == pytest.approx(np.linalg.norm(L[0]), rel=1e-8)
    assert tr.stats["environment"]["field_v_per_m"] == list(E)


def test_secular_carries_the_field_as_the_averaged_precession():
    """secular turns the DAST cube's L about E at d cos(theta_L) |E| / |L| (the dipole averaged
    over the spin), keeping the angle between E and L: over a minute (the radiation changes |L|
    and theta_L by 1e-4) L turns about E by that rate times the time, to 1e-3."""
    cube = P.dast_cube()
    E = np.array([0.03, 0.0, 0.01])                 # L(0) is along (0, 1, 1): E at 77 deg from it
    T = 60.0
    tr = spinviz.simulate(cube, "reduced", SPIN, t_end=T, samples=3, method="secular",
                          environment={"field_v_per_m": list(E)})
    L = tr.angular_momentum_world()
    e = E / np.linalg.norm(E)
    perp = L - np.outer(L @ e, e)
    angle = math.atan2(float(np.cross(perp[0], perp[-1]) @ e), float(perp[0] @ perp[-1]))
    Lb = np.asarray(cube.inertia) * tr.omega[0]
    cos_theta = float(np.asarray(cube.dipole) @ Lb) / (np.linalg.norm(cube.dipole) * np.linalg.norm(Lb))
    rate = np.linalg.norm(cube.dipole) * cos_theta * np.linalg.norm(U.field_from_v_per_m(E)) / np.linalg.norm(L[0])
    assert 1.0 < rate * T < math.pi
    assert -angle == pytest.approx(rate * T, rel=1e-3)
    assert tr.stats["field_turn_rad"] == pytest.approx(-rate * T, rel=1e-3)
    assert (L[-1] @ e) / np.linalg.norm(L[-1]) == pytest.approx((L[0] @ e) / np.linalg.norm(L[0]), abs=1e-6)


def test_methods_that_cannot_carry_it_refuse_with_the_reason():
    """A method without restarts or a world frame, Euler-only kinematics, a dimensionless body and a
    body without a surface are refused, each in one line naming the key."""
    cube = P.dast_cube()
    env = {"pressure_mbar": 1e-12}
    with pytest.raises(SpecError, match="cannot carry the environment") as e:
        spinviz.simulate(cube, "reduced", SPIN, t_end=1e-6, samples=3, method="radau", environment=env)
    assert e.value.key == "method"
    with pytest.raises(SpecError) as e:
        spinviz.simulate(cube, "reduced", SPIN, t_end=1e-6, samples=3, kinematics="none", environment=env)
    assert e.value.key == "kinematics"
    with pytest.raises(SpecError) as e:
        spinviz.simulate(spinviz.symmetric_top(0.3, 0.5), "reduced", [0, 0.05, 0.3], t_end=10, samples=3,
                         environment={"field_v_per_m": [1, 0, 0]})
    assert e.value.key == "environment.field_v_per_m" and "physical units" in e.value.reason
    with pytest.raises(SpecError, match="mean free path") as e:
        spinviz.simulate(cube, "reduced", SPIN, t_end=1e-6, samples=3, environment={"pressure_mbar": 1000.0})
    with pytest.raises(SpecError) as e:
        spinviz.simulate(cube, "reduced", SPIN, t_end=1e-6, samples=3, environment={"pressure_mbar": "high"})
    assert e.value.key == "environment.pressure_mbar"
    d = cube_doc(pressure_mbar=1e-9, gas="Kr")
    with pytest.raises(SceneError, match=r"\[environment\]\.gas: unknown value 'Kr'"):
        parse_scene(d, "x.toml")


def test_a_gas_so_dense_that_full_integration_cannot_finish_is_refused():
    """Every collision restarts Taylor's method: a run of more than a million is refused before any
    work, with its horizon to blame."""
    with pytest.raises(SpecError, match="hits the body") as e:
        spinviz.simulate(P.dast_cube(), "reduced", SPIN, t_end=1e-3, samples=3, method="taylor",
                         environment={"pressure_mbar": 1e-2})
    assert e.value.key == "t_end"


@pytest.mark.slow
def test_gas_alone_brakes_a_sphere_through_single_collisions():
    """A 10 nm sphere spun 10 000 times faster than the gas's thermal spin, N2 at 1 mbar (the
    radiation negligible: a 1e-18 statC cm dipole), integrated in full with every collision applied
    (~4e4 of them): |L| falls as exp(-gamma t), gamma = 10 p / (pi rho a v_bar), over five e-folds;
    the rate measured to 1.5 % (the collisions' number is Poisson: 0.5 % of spread)."""
    a, rho = 5e-7, 1.3
    I = 8.0 * math.pi * rho * a**5 / 15.0
    body = Body("sphere", "cgs", (I, I, I), (0.0, 0.0, 1e-18), shape=Shape("sphere", (2 * a,)))
    gas = G.Gas("N2", 1e3, 300.0)
    gamma = 10.0 * gas.pressure / (math.pi * rho * a * gas.mean_speed)
    w = 1e4 * math.sqrt(U.K_BOLTZMANN * 300.0 / I)
    T = 5.0 / gamma
    tr = spinviz.simulate(body, "reduced", [0.0, 0.6 * w, 0.8 * w], t_end=T, samples=3, method="taylor",
                          rtol=1e-8, environment={"pressure_mbar": 1.0, "seed": 2})
    assert tr.stats["collisions"] > 30_000
    L = np.linalg.norm(tr.omega, axis=1)
    assert -math.log(L[-1] / L[0]) / T == pytest.approx(gamma, rel=0.015)


@pytest.mark.slow
def test_a_box_left_in_the_gas_through_simulate_takes_its_temperature():
    """An asymmetric 2 x 3 x 4 nm DAST box in N2 at 100 mbar and 300 K, integrated in full (Taylor's
    method between the collisions, each applied), from a tenth of the thermal spin: over 300 damping
    times <1/2 Omega.I Omega> settles at 3/2 k T (to 8 %: the run's own spread; the recoil-free draw
    heats a body this small by ~2 %)."""
    body = P.dast_box(2.0, 3.0, 4.0)
    gas = G.Gas("N2", float(U.pressure_from_mbar(100.0)), 300.0)
    from spinviz.physics.surface import surface_of

    w_th = math.sqrt(U.K_BOLTZMANN * 300.0 / body.I1)
    gamma = G.GasModel(gas, surface_of(body), body.inertia).damping_rate(np.array([w_th, 0, 0]))
    T = 300.0 / gamma
    tr = spinviz.simulate(body, "reduced", [0.1 * w_th, 0.0, 0.0], t_end=T, samples=3001, method="taylor",
                          rtol=1e-8, environment={"pressure_mbar": 100.0, "seed": 1})
    E = 0.5 * np.sum(np.asarray(body.inertia) * tr.omega**2, axis=1)
    assert np.mean(E[300:]) / (1.5 * U.K_BOLTZMANN * 300.0) == pytest.approx(1.0, abs=0.08)


@pytest.mark.slow
def test_secular_brakes_the_cube_as_the_gas_drags_it():
    """secular's chunks in N2 at 1e-9 mbar (5.6e7 collisions in a day, summed as Gaussians): the
    cube's |Omega| follows the deterministic equation of its mean -- the reduced radiation torque
    (2.2)+(2.3) plus the gas's quadrature torque, integrated by SciPy -- to 1 % over a day in which
    the gas brakes it by a factor ~8 (measured: 6e-4, the Gaussian sums' mean taken at each
    chunk's midpoint)."""
    from scipy.integrate import solve_ivp

    from spinviz.physics import models as M
    from spinviz.physics.surface import surface_of

    cube = P.dast_cube()
    env = {"pressure_mbar": 1e-9, "seed": 6}
    tr = spinviz.simulate(cube, "reduced", SPIN, t_end=U.DAY, samples=5, method="secular", environment=env)
    model = G.GasModel(EnvironmentSpec(**env).gas_model(), surface_of(cube), cube.inertia)
    system = cube.system("reduced")
    tau0, I = cube.tau0, np.asarray(cube.inertia)

    def f(t, w):
        rad = np.asarray(M.radiation_function("reduced")(*(tau0 * w), system.inertia, system.coupling)) / tau0**2
        return rad + model.torque(w) / I

    ref = solve_ivp(f, (0.0, U.DAY), np.asarray(SPIN), rtol=1e-9, atol=1.0, t_eval=tr.t).y.T
    got, want = np.linalg.norm(tr.omega, axis=1), np.linalg.norm(ref, axis=1)
    assert want[-1] / want[0] < 0.15
    assert got == pytest.approx(want, rel=0.01)


@pytest.mark.slow
def test_the_hand_over_carries_the_gas(monkeypatch):
    """auto's hand-over (Taylor's method until the spin is fast enough for secular, then secular)
    carries the gas in both stages: a 10 x 10 x 5 nm box (oblate: no resonance for secular to
    refuse) with a dipole so large that tau0 = 1e-12 s, spun at tau0 |Omega0| = 0.01 in cold N2
    (its thermal spin below the run's), handed over as soon as a run is long (auto's limit lowered
    to 1000 turns), runs to the end with collisions in both stages."""
    from spinviz.integrators import auto
    from spinviz.physics.bodies import box

    monkeypatch.setattr(auto, "MAX_RESOLVED_TURNS", 1e3)
    a, c = 1e-6, 5e-7
    I1 = 1.3 * a * a * c * (a * a + c * c) / 12.0
    d = math.sqrt(1.5 * I1 * U.C_LIGHT**3 * 1e-12)                  # tau0 = 1e-12 s
    body = box(a, a, c, 1.3, (0.3 * d, 0.0, d))
    omega = np.array([0.0, 0.6e10, 0.8e10])
    env = {"pressure_mbar": 1e-6, "gas_temperature_k": 0.1, "seed": 1}
    tr = spinviz.simulate(body, "reduced", omega, t_end=1e-3, samples=5, environment=env)
    assert tr.stats["method"] == "taylor -> secular" and tr.stats.get("handover_at") is not None
    assert tr.stats["collisions"] > 10 and tr.stats["chunks"] > 10
    assert np.all(np.isfinite(tr.omega)) and tr.slow["q_L"].shape == (5, 4)


@pytest.mark.slow
def test_observe_tells_the_trap(tmp_path):
    """observe in a trap (environment options in place of the scene's): the table, the JSON and the
    receiver figure give the collisions per integration, one collision's jump of the line against
    sigma_f, the gas's braking against the radiation's and the field's precession -- the numbers of
    the gas's quadrature and of |d||E|cos(theta_L)/|L|."""
    import json

    from spinviz import experiment
    from spinviz.analysis import observe as OB
    from spinviz.analysis.experiment_plots import plot_receiver
    from spinviz.physics.surface import surface_of

    obs = experiment.observe(CUBE, samples=60, pressure_mbar=1e-12, field_v_per_m=(0.0, 0.01, 0.0))
    rec = json.loads(json.dumps(obs.record(), allow_nan=False))["environment"]
    cube = P.dast_cube()
    sc = load_scene(CUBE)
    model = G.GasModel(EnvironmentSpec(pressure_mbar=1e-12).gas_model(), surface_of(cube), cube.inertia)
    assert rec["collisions_per_s"] == pytest.approx(model.rate(sc.omega0), rel=1e-12)
    assert rec["collisions_per_integration"] == pytest.approx(rec["collisions_per_s"] * 1.0)
    assert rec["jump_rms_over_sigma_f"] > 1e3 and rec["jump_mean_hz"] < 0
    assert 0.005 < rec["gas_over_radiation"] < 0.05
    L = np.asarray(cube.inertia) * sc.omega0
    rate = np.linalg.norm(cube.dipole) * math.cos(math.radians(45.0)) * 0.01 / U.STATV_PER_CM_IN_V_PER_M \
        / np.linalg.norm(L)
    assert rec["field_precession_rad_per_s"] == pytest.approx(rate, rel=1e-9)
    assert "one collision moves the line" in OB.format_table(obs)
    plot_receiver(obs, str(tmp_path / "r.png"))
    assert (tmp_path / "r.png").stat().st_size > 50_000


def test_the_shipped_trap_scene_loads_as_written():
    """scenes/trap/dast_cube_trap.toml: the DAST cube's scene with N2 at 1e-12 mbar and a field of
    10 mV/m across L(0); the runs it asks for pass the request's checks (secular by chunks)."""
    sc = load_scene(ROOT / "scenes" / "trap" / "dast_cube_trap.toml")
    env = sc.environment
    assert (env.pressure_mbar, env.gas, env.field_v_per_m, env.seed) == (1e-12, "N2", (0.0, 0.01, 0.0), 1)
    assert sc.request("reduced").environment == env
    assert spinviz.Environment is EnvironmentSpec
