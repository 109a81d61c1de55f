"""``spinviz stress``: stiff and extreme cases, each with pass/fail, error and time.

Every case runs through the one ``simulate`` driver with ``method = "auto"`` unless it is
about a particular formulation, and reports which method the driver picked and why.
"""

from __future__ import annotations

import math
import time
from dataclasses import asdict, dataclass, field

import numpy as np

from .. import rotations as R
from ..driver import simulate
from ..errors import SimulationError
from ..integrators.auto import stiffness_ratio
from ..physics import bodies as B
from ..physics import cases
from ..physics import closed_forms as CF
from ..physics import presets as P


@dataclass
class StressResult:
    """One case.  ``correct``: the physics criterion; ``time_limit_s``: the issue's speed target,
    if the case has one.  ``passed`` needs both; the tests assert ``correct`` only (speed is
    measured by this command, not by timed tests)."""

    case: str
    description: str
    correct: bool
    error: float
    metric: str
    runtime_s: float
    method: str = ""
    reason: str = ""
    notes: str = ""
    time_limit_s: float | None = None
    details: dict = field(default_factory=dict)       # measured numbers behind ``notes``

    @property
    def in_time(self) -> bool:
        """Whether the run met the case's speed target (True when it has none)."""
        return self.time_limit_s is None or self.runtime_s < self.time_limit_s

    @property
    def passed(self) -> bool:
        """Correct and in time: what ``spinviz stress`` reports as PASS."""
        return bool(self.correct) and self.in_time

    def record(self) -> dict:
        """The case as a JSON-ready dict, with "passed" (``spinviz stress --json``)."""
        rec = {k: (float(v) if isinstance(v, np.floating) else v) for k, v in asdict(self).items()}
        rec["passed"] = self.passed
        return rec


def _timed(fn):
    t0 = time.perf_counter()
    out = fn()
    return out, time.perf_counter() - t0


def _rel(a, b):
    return float(np.max(np.linalg.norm(a - b, axis=-1) / np.maximum(np.linalg.norm(b, axis=-1), 1e-300)))


# --- thin bodies: eps = I3/I1 -> 0 ----------------------------------------------------------
def case_thin_longitudinal(eps=1e-6) -> StressResult:
    """eps = 1e-6 with d along e3: (4.4) is trivial (omega3 constant), so not stiff; (5.2) exact."""
    body = B.custom((1.0, 1.0, eps), (0.0, 0.0, 1.0), units="dimensionless")
    w20, w30 = 0.1, 0.3
    tr, dt = _timed(lambda: simulate(body, "reduced", (0.0, w20, w30), t_end=3.0 / w20**2, samples=101))
    err = _rel(tr.omega, CF.omega_eq5_2(tr.t, 1.0 - eps, w20, w30))
    return StressResult("eps=1e-6, chi=0", "thin rod, longitudinal dipole: (5.2) exact", err < 1e-8, err,
                        "|dOmega|/|Omega| vs (5.2)", dt, tr.stats["method"], tr.stats["method_reason"])


def case_thin_askew(eps=1e-6) -> StressResult:
    """eps = 1e-6 with d at 30 deg: (4.4) divides by 1 - delta = eps -- stiff (decay/spin ~2e4).
    Taylor's method still beats radau here (the measured table of ``auto.STIFF_RATIO``), and
    the driver must pick it and be right; checked against a tighter run of another method."""
    chi = math.radians(30.0)
    body = B.custom((1.0, 1.0, eps), (math.sin(chi), 0.0, math.cos(chi)), units="dimensionless")
    w0 = (0.0, 0.05, 0.05)
    t_end = 100.0
    tr, dt = _timed(lambda: simulate(body, "reduced", w0, t_end=t_end, samples=51, rtol=1e-8, atol=1e-10))
    ref = simulate(body, "reduced", w0, t_end=t_end, samples=51, method="bdf", rtol=1e-12, atol=1e-14)
    err = _rel(tr.omega, ref.omega)
    mis = float(R.misorientation(tr.q, ref.q).max())
    ok = tr.stats["method"] == "taylor" and err < 1e-5 and mis < 1e-5
    return StressResult("eps=1e-6, chi=30deg", "thin rod, askew dipole: stiff (4.4)", ok, max(err, mis),
                        "vs BDF at rtol 1e-12 (Omega rel., orientation rad)", dt, tr.stats["method"],
                        tr.stats["method_reason"], notes=f"stiffness ratio {stiffness_ratio(body, 'reduced', w0):.3g}")


def case_thin_askew_fast(eps=1e-6) -> StressResult:
    """The same rod spun 60 times faster (|omega| = 4.2 tau0^-1): decay/spin 1.6e6, beyond
    ``auto.STIFF_RATIO``, where radau is 2x faster than Taylor's method; the driver must pick
    radau and say why; checked against BDF at rtol 1e-12."""
    chi = math.radians(30.0)
    body = B.custom((1.0, 1.0, eps), (math.sin(chi), 0.0, math.cos(chi)), units="dimensionless")
    w0 = (0.0, 3.0, 3.0)
    tr, dt = _timed(lambda: simulate(body, "reduced", w0, t_end=2.0, samples=21, rtol=1e-8, atol=1e-10))
    ref = simulate(body, "reduced", w0, t_end=2.0, samples=21, method="bdf", rtol=1e-12, atol=1e-14)
    err = _rel(tr.omega, ref.omega)
    mis = float(R.misorientation(tr.q, ref.q).max())
    ok = tr.stats["method"] in ("radau", "bdf", "lsoda") and err < 1e-5 and mis < 1e-5
    return StressResult("eps=1e-6, chi=30deg, |w|=4.2", "thin rod spun fast: very stiff (4.4)", ok, max(err, mis),
                        "vs BDF at rtol 1e-12 (Omega rel., orientation rad)", dt, tr.stats["method"],
                        tr.stats["method_reason"], notes=f"stiffness ratio {stiffness_ratio(body, 'reduced', w0):.3g}")


def case_flat_disk() -> StressResult:
    """delta = -1 (I3 = 2 I1, a flat disk) with an askew dipole: against a tight run."""
    body = B.symmetric_top(-1.0, math.radians(55.0))
    w0 = (0.02, 0.05, 0.1)
    tr, dt = _timed(lambda: simulate(body, "reduced", w0, t_end=400.0, samples=51))
    ref = simulate(body, "reduced", w0, t_end=400.0, samples=51, method="dop853", rtol=1e-13, atol=1e-15)
    err = max(_rel(tr.omega, ref.omega), float(R.misorientation(tr.q, ref.q).max()))
    return StressResult("delta=-1", "flat disk (I3 = I1 + I2), askew dipole", err < 1e-8, err,
                        "vs scipy DOP853 at rtol 1e-13", dt, tr.stats["method"], tr.stats["method_reason"])


# --- dipole along a principal axis ----------------------------------------------------------
def case_chi_zero() -> StressResult:
    """chi = 0 exactly, truncated: (5.4) exact."""
    delta, w20, w30 = 0.3, 0.1, 0.3
    tr, dt = _timed(lambda: simulate(B.symmetric_top(delta, 0.0), "truncated", (0.0, w20, w30), t_end=5.0 / w20**2,
                                     samples=101))
    err = _rel(tr.omega, CF.omega_eq5_4(tr.t, delta, w20, w30))
    return StressResult("chi=0", "longitudinal dipole, truncated: (5.4) exact", err < 1e-8, err,
                        "|dOmega|/|Omega| vs (5.4)", dt, tr.stats["method"], tr.stats["method_reason"])


def case_chi_right_angle() -> StressResult:
    """chi = pi/2 exactly (d along e1), reduced: near the fixed point omega_inf e1 the motion is
    the linearization (5.7).  omega1 moves only at second order (omega1_dot = delta omega2
    omega3), which feeds back into omega2, omega3 at third: halving the perturbation must
    divide their deviation from (5.7) by 8."""
    delta, wi = 0.3, 0.2
    devs, dt_total, tr = [], 0.0, None
    for a in (1e-3, 5e-4):
        w0 = (wi, a, 2 * a)
        tr, dt = _timed(lambda w0=w0: simulate(B.symmetric_top(delta, 0.5 * math.pi), "reduced", w0, t_end=150.0,
                                               samples=61, rtol=1e-12, atol=1e-15))
        dt_total += dt
        lin = CF.omega_eq5_7(tr.t, delta, wi, a, 2 * a)
        devs.append(float(np.max(np.abs(tr.omega[:, 1:] - lin[:, 1:]))))
    ratio = devs[0] / devs[1]
    return StressResult("chi=pi/2", "transverse dipole: deviation from (5.7) is third order", 7.0 < ratio < 9.0,
                        devs[1], f"max |d omega2,3| vs (5.7); halving ratio {ratio:.2f}", dt_total,
                        tr.stats["method"], tr.stats["method_reason"])


# --- spin magnitude ------------------------------------------------------------------------------
def case_spin_magnitude(w: float) -> StressResult:
    """|omega0| = w (dimensionless, = tau0 |Omega0|): (5.2) exact over 2 Theta.  Large w brakes
    faster than it spins (stiff); small w means many turns."""
    delta = 0.3
    eps = 1.0 - delta
    w20 = w30 = w / math.sqrt(2.0)
    t_end = 2.0 / (eps * w30) ** 2
    tr, dt = _timed(lambda: simulate(B.symmetric_top(delta, 0.0), "reduced", (0.0, w20, w30), t_end=t_end, samples=51))
    err = _rel(tr.omega, CF.omega_eq5_2(tr.t, delta, w20, w30))
    return StressResult(f"|omega|={w:g}", f"spin tau0|Omega0| = {w:g}: (5.2) exact over 2 Theta", err < 1e-7, err,
                        "|dOmega|/|Omega| vs (5.2)", dt, tr.stats["method"], tr.stats["method_reason"],
                        notes=f"{tr.stats.get('turns', t_end * w / (2 * math.pi)):.3g} turns")


def case_truncated_singularity() -> StressResult:
    """(2.5) cannot be solved for Omega_dot where 1 + (g x Omega) . J^-1 g = 0 -- only at
    tau0 |Omega| ~ 1, never for a real particle.  Started just inside (denominator 1e-3 > 0,
    Omega_dot ~ 300) the run must move away from the surface and agree with Radau; started
    just beyond it (denominator -1e-3) it must stop with an error that names the singularity,
    not integrate into it or return NaNs."""
    from ..physics.equations import truncated_singularity

    body = B.custom((1.0, 1.0, 0.3), (0.6, 0.0, 0.8), units="dimensionless")
    s = body.system("truncated")
    # (g x Omega) . J^-1 g = 1.12 Omega2 here: Omega2 = -1/1.12 is on the singular surface; the
    # Omega1, Omega3 parts keep the numerator of Omega_dot from vanishing with it
    on_surface = np.array([0.3, -1.0 / 1.12, 0.2])
    inside, beyond = on_surface * (1.0, 0.999, 1.0), on_surface * (1.0, 1.001, 1.0)
    kw = dict(t_end=5.0, samples=101)
    tr, dt = _timed(lambda: simulate(body, "truncated", inside, **kw))
    ref = simulate(body, "truncated", inside, method="radau", rtol=1e-12, atol=1e-14, **kw)
    err = _rel(tr.omega, ref.omega)
    den_min = min(truncated_singularity(*w, s.inertia, s.coupling) for w in tr.omega)
    try:
        simulate(body, "truncated", beyond, **kw)
        beyond_msg, stopped = "beyond the surface: integrated (wrong)", False
    except SimulationError as e:
        beyond_msg, stopped = f"beyond the surface: stopped ({e})", "singular" in str(e)
    ok = err < 1e-8 and den_min >= 1e-3 * (1 - 1e-9) and stopped
    return StressResult("truncated singular", "(2.5) near 1 + (g x Omega).J^-1 g = 0 (tau0 |Omega| ~ 1)", ok, err,
                        "|dOmega|/|Omega| vs Radau (started inside)", dt, tr.stats["method"], tr.stats["method_reason"],
                        notes=f"smallest denominator {den_min:.1e} (at the start); {beyond_msg}")


# --- real CGS parameters ------------------------------------------------------------------
def case_real_cgs_rod() -> StressResult:
    """Cellulose rod with real parameters (tau0 = 1.46e-35 s, Omega = pi 1e10 /s) over 3 T in
    CGS: no overflow or underflow; the truncated spin-down matches (6.2)'s |Omega_perp|, Omega3."""
    rod = P.cellulose_rod()
    W = math.pi * 1e10
    T = rod.braking_time_T(W)                  # the paper's T = 1/(tau0 Omega20^2), 2.2e6 years
    tr, dt = _timed(lambda: simulate(rod, "truncated", (0.0, W, W), t_end=3.0 * T, samples=61))
    # the finite-eps form (5.4) through (4.1): exact for this rod, the eps -> 0 limit (6.2) is not
    tau0 = rod.tau0
    ex = CF.omega_eq5_4(tr.t / tau0, rod.delta, tau0 * W, tau0 * W) / tau0
    err = _rel(np.c_[np.hypot(tr.omega[:, 0], tr.omega[:, 1]), tr.omega[:, 2]],
               np.c_[np.hypot(ex[:, 0], ex[:, 1]), ex[:, 2]])
    finite = bool(np.all(np.isfinite(tr.omega)) and np.all(np.isfinite(tr.q)))
    return StressResult("real CGS rod", "tau0 = 1.46e-35 s, 1e24 turns, truncated over 3 T (6.6e6 years)",
                        finite and err < 1e-6, err, "slow variables vs (5.4)/(6.2)", dt, tr.stats["method"],
                        tr.stats["method_reason"], notes=f"{tr.stats['turns']:.2g} turns; phase ulp "
                        f"{tr.stats['phase_resolution_rad']:.2g} rad")


def case_real_dast_cube() -> StressResult:
    """The DAST cube with real parameters over 10 Theta (~1e16 turns): |Omega_perp|, Omega3 and
    theta (d from the rotation axis) against (6.7) and (6.8), to 1e-6 relative, in < 1 s."""
    cube = P.dast_cube()
    W = math.pi * 1e10
    Th = 1.0 / (cube.tau0 * W**2)
    tr, dt = _timed(lambda: simulate(cube, "reduced", (0.0, W, W), t_end=10.0 * Th, samples=201,
                                     euler_zxz0=(0.0, 0.25 * math.pi, 0.0)))
    ex = CF.omega_eq6_7(tr.t, cube.tau0, W, W)
    wp, wpe = np.hypot(tr.omega[:, 0], tr.omega[:, 1]), np.hypot(ex[:, 0], ex[:, 1])
    L = np.array(tr.stats["L_axis_world"])
    theta = R.angle_between(tr.dipole_world(), L)
    e = max(float(np.max(np.abs(wp / wpe - 1))), float(np.max(np.abs(tr.omega[:, 2] / ex[:, 2] - 1))),
            float(np.max(np.abs(theta / np.arctan2(wpe, ex[:, 2]) - 1))))
    late = tr.t > 3 * Th
    rate = -np.polyfit(tr.t[late], np.log(theta[late]), 1)[0] / (cube.tau0 * W**2) - 1.0
    return StressResult("real DAST cube 10 Theta", "tau0 = 3.7e-27 s, ~1e16 turns: (6.7), (6.8)",
                        e < 1e-6 and abs(rate) < 1e-4, e, "relative error of |Omega_perp|, Omega3, theta",
                        dt, tr.stats["method"], tr.stats["method_reason"],
                        notes=f"{tr.stats['turns']:.2g} turns; theta decay rate / tau0 Omega3^2 - 1 = {rate:.1e}; the spin "
                        f"phase is beyond float64 (1 ulp = {tr.stats['phase_resolution_rad']:.0f} rad): shown slowed on screen",
                        time_limit_s=1.0)


# --- theta -> 0: Euler angles (6.4) vs quaternions -------------------------------------------
def case_pole_passage() -> StressResult:
    """A free sphere turning about the world x axis with e3 starting 1e-9 rad from the z axis:
    e3 passes within 1e-9 rad of the pole each half turn.  (6.4) divides by sin(theta) ~ 1e-9
    there; the quaternion kinematics does not notice."""
    body = B.symmetric_top(0.0, 0.0)
    q0 = R.quat_from_axis_angle((0.0, 1.0, 0.0), 1e-9)
    w_body = R.body_from_world(q0, (1.0, 0.0, 0.0))        # constant for a free sphere
    t = np.linspace(0.0, 4.0 * math.pi, 9)
    exact = R.multiply(R.quat_from_axis_angle((1.0, 0.0, 0.0), t), q0[None, :])
    kw = dict(t_eval=t, q0=q0, rtol=1e-10, atol=1e-12, method="taylor")     # one method, two kinematics
    tq, dq = _timed(lambda: simulate(body, "free", w_body, **kw))
    eq = float(R.misorientation(tq.q, exact).max())
    t0 = time.perf_counter()
    try:
        te = simulate(body, "free", w_body, kinematics="euler_zxz", **kw)
        ee, en = float(R.misorientation(R.quat_from_euler_zxz(te.euler), exact).max()), te.stats["nsteps"]
        euler = f"(6.4): error {ee:.1e} rad, {en} steps"
    except SimulationError as e:
        ee, en = math.inf, None
        euler = f"(6.4) failed: {e}"
    de = time.perf_counter() - t0
    return StressResult("theta -> 0", "e3 passes 1e-9 rad from the pole (2 turns)", eq < 1e-9, eq,
                        "quaternion orientation error, rad", dq, tq.stats["method"], tq.stats["method_reason"],
                        notes=f"Taylor's method on both: quaternion {tq.stats['nsteps']} steps; {euler} in {de:.2f} s",
                        details={"quaternion_error": eq, "quaternion_steps": tq.stats["nsteps"],
                                 "euler_error": ee, "euler_steps": en})


# --- asymmetric free top near the separatrix ----------------------------------------------
def case_separatrix() -> StressResult:
    """I = (1, 0.75, 0.4), spin almost about the intermediate axis: Dzhanibekov flips.  Energy
    and L_world stay constant to the tolerance; |q| = 1."""
    body = B.custom((1.0, 0.75, 0.4), (0.0, 0.0, 1.0), units="dimensionless")
    tr, dt = _timed(lambda: simulate(body, "free", (1e-3, 1.0, 1e-3), t_end=400.0, samples=401, rtol=1e-12, atol=1e-14))
    E = tr.energy()
    L = tr.angular_momentum_world()
    dE = float(np.max(np.abs(E / E[0] - 1)))
    dL = float(np.max(np.linalg.norm(L - L[0], axis=1)) / np.linalg.norm(L[0]))
    dq = float(np.max(np.abs(np.linalg.norm(tr.q, axis=1) - 1)))
    flips = int(np.sum(np.diff(np.sign(tr.omega[:, 1])) != 0))
    return StressResult("separatrix", "asymmetric free top near the intermediate axis", max(dE, dL) < 1e-10 and
                        dq < 1e-14 and flips >= 2, max(dE, dL), "relative drift of E and L_world", dt,
                        tr.stats["method"], tr.stats["method_reason"], notes=f"{flips} flips of omega2; ||q|-1| = {dq:.1e}")


# --- 1e6 turns ----------------------------------------------------------------------------
def case_million_turns_free() -> StressResult:
    """1e6 turns of a free symmetric top (delta = 0.3): the splitting's free flow is exact, so
    |q| stays 1 and the energy is conserved to round-off; checked against the closed form."""
    body = B.symmetric_top(0.3, 0.7)
    w0 = np.array([0.3, 0.4, 0.5])
    w = float(np.linalg.norm(w0))
    t_end = 1e6 * 2.0 * math.pi / w
    tr, dt = _timed(lambda: simulate(body, "free", w0, t_end=t_end, samples=11, method="split8", step=t_end / 10))
    dq = float(np.max(np.abs(np.linalg.norm(tr.q, axis=1) - 1)))
    E = tr.energy()
    dE = float(np.max(np.abs(E / E[0] - 1)))
    # exact: Omega_perp turns by -delta w3 t; O(t) = O0 exp(L_body t) exp(e3 delta w3 t)
    delta = 0.3
    ang = -delta * w0[2] * tr.t
    w_ex = np.stack([w0[0] * np.cos(ang) - w0[1] * np.sin(ang), w0[0] * np.sin(ang) + w0[1] * np.cos(ang),
                     np.full_like(ang, w0[2])], -1)
    err = _rel(tr.omega, w_ex)
    return StressResult("1e6 turns", "free symmetric top, split8: |q| and energy at round-off", dq <= 1e-12 and dE < 1e-14
                        and err < 1e-9, max(dq, dE), "||q|-1| and energy drift", dt, tr.stats["method"],
                        tr.stats["method_reason"], notes=f"Omega error {err:.1e} rel.")


def case_million_turns_braked() -> StressResult:
    """1e6 turns of (6.10) (truncated DAST cube, exact) with the default driver: error and time."""
    case = cases.eq6_10_turns(1e6)
    T = case.t_end / 3.0
    tr, dt = _timed(lambda: simulate(case.body, case.model, method="split8", step=T / 40, **case.run_kwargs(21)))
    exact = case.orientation_exact(tr.t)
    err = float(R.misorientation(tr.q, exact).max())
    dq = float(np.max(np.abs(np.linalg.norm(tr.q, axis=1) - 1)))
    return StressResult("1e6 turns (6.10)", "truncated DAST cube over 3 T, split8 with T/40 steps", err < 1e-8 and dq <= 1e-12,
                        err, "orientation error vs (6.10), rad", dt, tr.stats["method"],
                        tr.stats["method_reason"], notes=f"||q|-1| = {dq:.1e}", time_limit_s=10.0)


CASES = (
    case_thin_longitudinal, case_thin_askew, case_thin_askew_fast, case_flat_disk, case_chi_zero, case_chi_right_angle,
    lambda: case_spin_magnitude(1e-6), lambda: case_spin_magnitude(1e-3), lambda: case_spin_magnitude(1.0),
    lambda: case_spin_magnitude(1e3), case_truncated_singularity, case_real_cgs_rod, case_real_dast_cube,
    case_pole_passage, case_separatrix, case_million_turns_free, case_million_turns_braked,
)


def run_all(progress=None) -> list[StressResult]:
    """Every case, in order; ``progress(result)`` is called after each."""
    out = []
    for fn in CASES:
        out.append(fn())
        if progress:
            progress(out[-1])
    return out


def format_table(results: list[StressResult]) -> str:
    """The cases as ``spinviz stress`` prints them: PASS, SLOW (correct, over its time target) or
    FAIL, the error, time and method, then the description and notes."""
    lines = [f"{'case':<24} {'result':<6} {'error':>9}  {'time':>8}  {'method':<11} metric / why / notes", "-" * 120]
    for r in results:
        verdict = "PASS" if r.passed else ("SLOW" if r.correct else "FAIL")
        limit = f" (target < {r.time_limit_s:g} s)" if r.time_limit_s is not None else ""
        lines.append(f"{r.case:<24} {verdict:<6} {r.error:>9.2e}  {r.runtime_s:>7.3f}s  {r.method:<11} {r.metric}{limit}")
        lines.append(f"{'':<24} {r.description}; method: {r.reason}")
        if r.notes:
            lines.append(f"{'':<24} {r.notes}")
    lines.append("-" * 120)
    lines.append(f"{sum(r.passed for r in results)}/{len(results)} cases passed")
    return "\n".join(lines)
