"""``polhode``: real horizons for any body -- the torque averaged over the Euler-Poinsot polhode.

An asymmetric top's free motion is periodic in the body frame along a polhode; under a torque
weak against the spin (eps = tau0 |Omega0| << 1) the polhode drifts slowly.  This method
follows the drift (``polhode_flow``: |L|^2 and the polhode's size p about its encircled axis,
averaged over one period, with a near-identity transform), carries the two fast phases --
the polhode phase u and the turn Sigma about L -- at their averaged rates, and rebuilds the
orientation as O = R(q_L) Rz(phi) Rx(theta) Rz(psi) about the fixed L_world (the torque
across L turns with the body and averages out; ``physics.polhode``).  For a symmetric top the
polhode is a circle and the method is ``secular``'s averaged stage ((4.12)); a sphere has no
polhode and is handed to ``secular``.

Where averaging fails it integrates in full, with Taylor's method (``taylor``) on the true
state, and hands back when it holds again:

* near the separatrix (the polhode through the middle axis), whose period diverges: the
  state's distance from it changes by more than ``MU_IN`` of itself within one period --
  ``mu_sep``; a crossing is passed in full and recorded with the two lobes it may lead to and
  their probabilities (the flux of the torque through each branch of the separatrix; which
  lobe a run enters depends on its phase at the crossing, so where the phase is not resolved
  the outcome is that draw, not a prediction);
* where the polhode's frequency changes by more than ``MU_IN`` of itself within one period,
  or the slow variables swing by more than that (``mu_ad``, ``mu_osc``: a nearly symmetric
  body whose two close moments make the polhode about them slow).

The direction of L in space is fixed to O(eps) except at the resonances nu_phi + n omega_p =
0 between the precession about L and the polhode (``resonance_kicks``), where the torque
across L stops averaging out and L turns by ~|c_n| / |L| sqrt(2 pi / |dF/dt|) ~ sqrt(eps), in a
direction the averaged run cannot tell: each crossing and its kick are reported.

What it reports (``stats``): the segments, the crossings, the resonances, ``slow_error_estimate``
(relative, |L| and the energy), ``L_direction_uncertainty_rad``, ``phase_error_rad`` and
``phases_resolved``, as ``secular`` does; measured against full Taylor integration in
docs/asymmetric.md.
"""

from __future__ import annotations

import math

import numpy as np

from .. import rotations as R
from ..interrupt import check
from ..physics import polhode as PH
from .base import Integrator, Problem, Solution, register
from .polhode_flow import Flow
from .scaling import spin_problem

EPS_MAX = 1e-3          # tau0 |Omega0| above which there is no fast motion to average over
MU_IN = 2e-2            # averaging is left above this mu (mu_sep / SEP_WEIGHT, mu_ad, mu_osc) ...
MU_OUT = 0.5 * MU_IN    # ... and taken up again below this
SEP_WEIGHT = 10.0       # mu_sep counts 1/SEP_WEIGHT: the separatrix distance may change by 20 % a period
MAX_FULL_TURNS = 5e7    # turns resolved in full (crossings, slow polhodes) before the run is refused
FULL_CHUNK_PERIODS = 20.0
PHASE_TOL = 1e-3        # rad: phases called resolved below this estimated error
L_TOL = 1e-2            # rad: a resonance uncertainty of L's direction above this is refused


class NotApplicable(ValueError):
    """The averaged flow does not apply to this problem; the message says why."""


def mu_of(av) -> float:
    """The one small parameter the hand-over watches (module docstring)."""
    return max(av.mu_sep / SEP_WEIGHT, av.mu_ad, av.mu_osc)


def check_applicable(problem: Problem) -> float:
    """eps = tau0 |Omega0| (spin units), or ``NotApplicable`` with the reason."""
    s = problem.system
    g = np.asarray(s.coupling, dtype=float)
    eps = float(g @ g)
    if eps > EPS_MAX * (1.0 + 1e-12) and s.model != "free":      # (sqrt(1e-3))^2 is 1e-3 and a hair
        raise NotApplicable(f"tau0 |Omega0| = {eps:.3g} > {EPS_MAX:g}: the radiation changes the spin within a few "
                            f"turns, so there is no fast motion to average over; use a resolving method")
    try:
        PH.extreme_axes(s.inertia)
    except PH.NoPolhode as e:
        raise NotApplicable(str(e)) from None
    return eps


class _Run:
    """One run: the output grid, what is filled so far, and the bookkeeping."""

    def __init__(self, problem: Problem, rtol: float, atol: float):
        self.problem, self.rtol, self.atol = problem, rtol, atol
        self.t = np.asarray(problem.t_eval, dtype=float)
        n = self.t.size
        self.omega = np.full((n, 3), np.nan)
        self.q = np.full((n, 4), np.nan) if problem.kinematics == "quaternion" else None
        self.omega[0] = problem.omega0
        q0 = R.normalize(problem.q0 if problem.q0 is not None else (1.0, 0.0, 0.0, 0.0))
        if self.q is not None:
            self.q[0] = q0
        self.j = 1                        # next output index
        self.s = float(self.t[0])         # time reached
        self.w = np.asarray(problem.omega0, dtype=float)
        self.qs = q0
        self.segments: list = []
        self.crossings: list = []
        self.resonances: list = []
        self.full_turns = 0.0
        self.full_steps = 0
        self.avg_steps = 0
        self.nfev = 0
        self.L_kicks: list = []
        self.max_mu = 0.0
        self.axis_end = None
        self.terms = dict.fromkeys(ERROR_TERMS, 0.0)


def solve_polhode(problem: Problem, rtol: float = 1e-10, atol: float = 1e-12, step: float | None = None) -> Solution:
    """The ``polhode`` method (module docstring).  ``problem`` in spin units (|omega(0)| = 1),
    omega0 body frame, q0 (w, x, y, z); ``step`` ignored (adaptive).  Not successful, with
    the reason, where averaging does not apply or a stretch in full cannot finish."""
    t = np.asarray(problem.t_eval, dtype=float)
    try:
        eps = check_applicable(problem)
    except NotApplicable as e:
        if "sphere" in str(e):
            return _sphere(problem, rtol, atol)
        return Solution(t=t, omega=np.full((t.size, 3), np.nan), success=False, message=str(e))
    run = _Run(problem, rtol, atol)
    run.eps = eps
    # beyond float64 (1 ulp of the phase > PHASE_TOL) no phase is resolved whatever its rate: the
    # torque's O(eps) corrections to the phase rates (two thirds of the work) are then left out
    run.phase_corrections = bool(float(np.spacing(float(t[-1]) * 2.0)) <= PHASE_TOL)
    # the second-order slow rates matter where first order's drift exceeds the tolerance: eps^2 per unit
    # time, while tau0 |Omega| falls as the spin brakes -- about eps per e-fold of the horizon in braking times
    run.order2 = bool(eps * max(1.0, math.log1p(eps * float(t[-1] - t[0]))) > 0.1 * rtol)
    while run.s < t[-1]:
        failure = _averaged_stage(run)
        if failure is None and run.s < t[-1]:
            failure = _full_stage(run)
        if failure is not None:
            return Solution(t=t, omega=run.omega, q=run.q, success=False, message=failure, stats=_stats(run),
                            reached=run.j, status=1)
    stats = _stats(run)
    return Solution(t=t, omega=run.omega, q=run.q, stats=stats)


def _sphere(problem: Problem, rtol: float, atol: float) -> Solution:
    """A sphere has no polhode: ``secular`` (e3 along d, where the torque needs no average)."""
    from .secular import solve_secular

    sol = solve_secular(problem, rtol, atol)
    sol.stats["polhode_note"] = "a sphere has no polhode: run by secular (e3 along d)"
    return sol


# --- the averaged stage ------------------------------------------------------------------------
def _averaged_stage(run: _Run):
    """From (run.s, run.w, run.qs): averaged while mu <= MU_IN, to the end or to the instant it
    is exceeded (then run.w, run.qs hold the true state there).  None, or why it cannot go on."""
    from scipy.integrate import solve_ivp  # here: importing the integrators stays light

    system = run.problem.system
    try:
        c, s_c = PH.encircled_axis(system.inertia, run.w)
    except PH.NoPolhode:
        return None                                  # on the separatrix itself: the full stage takes it
    flow = Flow(system, c, s_c)
    if mu_of(flow.averages(flow.x_of(run.w), phases=False)) > MU_IN:
        return None
    o2 = run.order2
    y0, q_L, av0 = _averaged_start(run, flow)
    t_all, t0 = run.t, run.s
    out_t = t_all[run.j:]
    count = {"n": 0}
    # the clock: s = ln(1 + (t - t0) / tb), tb the braking time at the start -- a spin braking as a power
    # of t is then nearly linear in s, and each decade of a long horizon costs a few steps, not tens
    r0 = av0.rates
    clock = _Clock(t0, 1.0 / max(abs(float(r0[0])) + abs(float(r0[1])), 1.0 / max(float(t_all[-1]) - t0, 1e-300)))
    # beyond float64 the phases are not resolved whatever their error: their tolerance is then left out
    atol = np.array([run.atol] * 4) if run.phase_corrections else np.array([run.atol, run.atol, 1e300, 1e300])

    def rhs(s_, y):
        count["n"] += 1
        if count["n"] % 64 == 0:
            check()
        av = flow.averages(y[:2], phases=run.phase_corrections, order2=o2)
        return np.array([av.rates[0], av.rates[1], av.u_rate, av.sigma_rate]) * clock.dtds(s_)

    def leave(_s, y):
        return mu_of(flow.averages(y[:2], phases=False)) - MU_IN

    leave.terminal = True
    leave.direction = 1.0
    s_end = float(clock.s(float(t_all[-1])))
    s_out = np.minimum(clock.s(out_t), s_end)
    sol = solve_ivp(rhs, (0.0, s_end), y0, method="DOP853", rtol=run.rtol, atol=atol,
                    t_eval=s_out if s_out.size else None, events=leave, dense_output=True)
    run.nfev += int(sol.nfev)
    run.avg_steps += int(sol.sol.ts.size - 1)
    if sol.status < 0:
        return f"the averaged flow: {sol.message}"
    t_end = float(clock.t(float(sol.t_events[0][0]))) if sol.status == 1 else float(t_all[-1])
    run.segments.append([t0, "averaged", c, s_c])
    _averaged_end(run, flow, _Path(sol, clock), q_L, t0, t_end, left=sol.status == 1)
    run.axis_end = (c, s_c)
    return None


def _averaged_start(run: _Run, flow: Flow):
    """(y0 = (x_bar, u_bar, Sigma_bar), q_L, the averages at x_bar) of the true state (run.w, run.qs)."""
    system = run.problem.system
    o2 = run.order2
    xbar, u0, _, _ = flow.to_averaged(run.w, order2=o2)
    q_L = R.quat_between((0.0, 0.0, 1.0), R.world_from_body(run.qs, np.asarray(system.inertia) * run.w))
    av0 = flow.averages(xbar, phases=False, order2=o2)
    pol_true = flow.polhode(flow.x_of(run.w))
    u_true = float(flow._phase(run.w - (flow.forced_offset(float(run.w[flow.c])) if av0.shifted else 0.0)))
    sig0 = PH.sigma_of(pol_true, q_L, run.qs) - float(flow.w0(av0, u_true))
    return np.array([xbar[0], xbar[1], u0, sig0]), q_L, av0


def _averaged_end(run: _Run, flow: Flow, path, q_L, t0: float, t_end: float, left: bool):
    """The outputs an averaged stretch reached, its error terms and resonances, and (``left`` for
    the full stage) the true state where it ends."""
    out_t = run.t[run.j:]
    k = int(np.searchsorted(out_t, t_end, side="right"))
    if k:
        _fill(run, flow, q_L, path.state(out_t[:k]).T, run.q is not None)
        run.j += k
    _charge(run, flow, path, t0, t_end)
    if left:                                 # left for the full stage: what the averaged flow did not see there
        mu_exit = flow.averages(path.state(t_end)[:2], phases=False, order2=run.order2).mu_osc
        run.terms["slow_entry"] += mu_exit * mu_exit
        run.terms["phase_entry"] += mu_exit
    _resonances(run, flow, path, t0, t_end)
    run.s = t_end
    if t_end < run.t[-1]:
        run.w, run.qs = _true_state(flow, q_L, path.state(t_end), run.order2)


class _Clock:
    """t = t0 + tb (e^s - 1): the averaged stage's independent variable s and back."""

    def __init__(self, t0: float, tb: float):
        self.t0, self.tb = float(t0), float(tb)

    def t(self, s):
        return self.t0 + self.tb * np.expm1(s)

    def s(self, t):
        return np.log1p((np.asarray(t, dtype=float) - self.t0) / self.tb)

    def dtds(self, s) -> float:
        return self.tb * math.exp(s)


class _Path:
    """An averaged stage's solution in the run's time t: its step instants and its state."""

    def __init__(self, sol, clock: _Clock):
        self.sol, self.clock = sol, clock

    @property
    def steps(self) -> np.ndarray:
        return self.clock.t(self.sol.sol.ts)

    def state(self, t) -> np.ndarray:
        return self.sol.sol(np.clip(self.clock.s(t), self.sol.sol.ts[0], self.sol.sol.ts[-1]))


TRANSFORM_INVISIBLE = 1e-15      # tau0 |Omega| below which the transform (O(eps) of the state) is below float64


def _true_state(flow: Flow, q_L, y, order2: bool):
    """(omega, q) of the averaged state y = (x_bar, u_bar, Sigma_bar).  Where the transform and the
    forced tilt are O(eps) below float64's resolution of the state (real crystals) they are left
    out: the free motion at (x_bar, u_bar) is the state to the last digit."""
    if flow.eps * math.exp(0.5 * float(y[0])) < TRANSFORM_INVISIBLE:
        pol = flow.polhode(y[:2])
        om_p, _, c = PH.angle_variables(pol)
        w, q = pol.pose(q_L, y[3] + float(PH.sigma_periodic(c, om_p, y[2])), y[2])
        return w, R.normalize(q)
    w, x, u = flow.to_true(y[:2], y[2], order2=order2)
    av = flow.averages(y[:2], phases=False, order2=order2)
    sig = y[3] + float(flow.w0(av, u))
    _, q = flow.polhode(x).pose(q_L, sig, u)
    return w, R.normalize(q)


def _fill(run: _Run, flow: Flow, q_L, ys, with_q: bool):
    for i, y in enumerate(ys):
        w, q = _true_state(flow, q_L, y, run.order2)
        run.omega[run.j + i] = w
        if with_q:
            run.q[run.j + i] = q


# The error statements: each a sum of measured coefficients times terms the run records (``ERROR_TERMS``),
# fitted as upper envelopes to the sweep against full Taylor integration (validation.polhode_sweep; the
# measurement in docs/asymmetric.md).  mu is mu_osc, the largest swing of the slow variables over a period.
SLOW_COEF = {"transform": 3.0, "drift": 3.0, "entry": 3.0}
# measured/stated reached 3.25 with 3.0 (a nearly symmetric prolate body, J = (1, 1.33, 1.33)): 15 for a margin
PHASE_COEF = {"transform": 15.0, "drift": 15.0, "entry": 15.0, "fed": 15.0}
L_MARGIN = 1.5


def _charge(run: _Run, flow: Flow, path, t0: float, t1: float):
    """The error terms of an averaged stretch [t0, t1]: the transform's O(mu^2) at its ends and
    O(mu) in the phases; the next order's drift, sum mu^3 omega_p dt in the slow variables and
    mu^2 omega_p dt in the phases; the slow error fed into the phase rates."""
    steps = path.steps
    ts = np.unique(np.concatenate([steps[(steps >= t0) & (steps <= t1)], [t0, t1]]))
    avs = [flow.averages(path.state(tt)[:2], phases=False, order2=run.order2) for tt in ts]
    mus = np.array([a.mu_osc for a in avs])
    wps = np.array([a.omega_p for a in avs])
    dts = np.diff(ts)
    run.max_mu = max(run.max_mu, max(mu_of(a) for a in avs))
    T = run.terms
    mu = float(np.max(mus))
    T["slow_transform"] += mu * mu
    T["slope"] = max(T["slope"], max(a.mu_slope for a in avs))
    T["phase_transform"] += mu
    mid = 0.5 * (mus[1:] + mus[:-1])
    wmid = 0.5 * (wps[1:] + wps[:-1])
    third = mid**3 * wmid * dts if run.order2 else mid * mid * wmid * dts
    T["slow_drift"] += float(np.sum(third))
    T["phase_drift"] += float(np.sum(mid * mid * wmid * dts))
    # a slow error dx shifts omega_p by |d omega_p/dx| dx: over the stretch, the phase drifts by its integral
    grad = np.array([np.linalg.norm(flow._grad_ln_frequency(path.state(tt)[:2])) for tt in ts])
    slow_now = _slow_statement(run, with_phase=False)
    T["phase_fed"] += float(np.sum(0.5 * (grad[1:] + grad[:-1]) * wmid * dts)) * slow_now
    T["slow_rtol"] += run.rtol * math.sqrt(ts.size)
    T["phase_rtol"] += run.rtol * float(np.sum(wmid * dts))


def _slow_statement(run: _Run, with_phase: bool = True) -> float:
    T = run.terms
    # the slow variables are read at the (averaged) phase: an error there moves them along their oscillation
    return (SLOW_COEF["transform"] * T["slow_transform"] + SLOW_COEF["drift"] * T["slow_drift"]
            + SLOW_COEF["entry"] * T["slow_entry"] + T["slow_rtol"]
            + (T["slope"] * _phase_statement(run) if with_phase else 0.0))


def _phase_statement(run: _Run) -> float:
    T = run.terms
    return (PHASE_COEF["transform"] * T["phase_transform"] + PHASE_COEF["drift"] * T["phase_drift"]
            + PHASE_COEF["entry"] * T["phase_entry"] + PHASE_COEF["fed"] * T["phase_fed"] + T["phase_rtol"]
            + T["phase_full"])


ERROR_TERMS = ("slow_transform", "slow_drift", "slow_entry", "slow_rtol", "phase_transform", "phase_drift",
               "phase_entry", "phase_fed", "phase_rtol", "phase_full", "L_wobble", "slope")


def _resonances(run: _Run, flow: Flow, path, t0: float, t1: float):
    """The resonances nu_phi + n omega_p = 0 crossed over [t0, t1] (between the solver's
    steps), each with the turn of L it can cause, |c_n| / |L| sqrt(2 pi / |dF/dt|) (rad); and the
    O(eps) wobble of L about its mean, sum_n |c_n| / (|L| |nu_phi + n omega_p|) (each term at most
    its kick), whose largest value joins ``L_wobble``."""
    from .polhode_flow import precession_harmonics

    if flow.free:
        return
    steps = path.steps
    ts = np.unique(np.concatenate([steps[(steps >= t0) & (steps <= t1)], [t0, t1]]))
    vals = [precession_harmonics(flow, path.state(tt)[:2]) for tt in ts]
    r = np.array([nu / wp for nu, wp, _, _ in vals])
    wps = np.array([wp for _, wp, _, _ in vals])
    for i in range(len(ts)):
        nu, wp, c, L = vals[i]
        j = min(i + 1, len(ts) - 1)
        k = max(j - 1, 0)
        rdot = (r[j] - r[k]) / (ts[j] - ts[k]) if ts[j] > ts[k] else 0.0
        Fdot = max(abs(wp * rdot), 1e-300)
        nn = c.size
        n = np.fft.fftfreq(nn, 1.0 / nn)
        F = np.abs(nu + n * wp)
        cap = math.sqrt(2.0 * math.pi / Fdot)
        wob = float(np.sum(np.abs(c) * np.minimum(1.0 / np.maximum(F, 1e-300), cap))) / L
        run.terms["L_wobble"] = max(run.terms["L_wobble"], 2.0 * wob)
        if i == 0:
            continue
        lo, hi = sorted((r[i - 1], r[i]))
        for kk in range(math.ceil(lo), math.floor(hi) + 1):
            if not lo < kk <= hi:
                continue
            n_res = -kk
            f = (kk - r[i - 1]) / (r[i] - r[i - 1])
            t_k = ts[i - 1] + f * (ts[i] - ts[i - 1])
            Fd = abs(0.5 * (wps[i] + wps[i - 1]) * (r[i] - r[i - 1]) / (ts[i] - ts[i - 1]))
            cn = abs(c[n_res % nn]) if abs(n_res) < nn // 2 else 0.0
            kick = cn / L * math.sqrt(2.0 * math.pi / Fd) if Fd > 0.0 else math.inf
            run.resonances.append([int(n_res), float(t_k), float(kick)])
            run.L_kicks.append(kick)


# --- the full stage -----------------------------------------------------------------------------
def _full_stage(run: _Run):
    """Taylor's method from (run.s, run.w, run.qs) until mu < MU_OUT again (or t_end), chunk by
    chunk; a separatrix crossing is recorded.  None, or why it cannot go on."""
    from .taylor import solve_taylor

    system = run.problem.system
    t_all = run.t
    t_end = float(t_all[-1])
    start_axis = _axis_or_none(system, run.w)
    entry = _crossing_odds(system, run.w, start_axis)
    t_enter = run.s
    run.segments.append([run.s, "full", None, None])
    while run.s < t_end:
        rate = float(np.linalg.norm(run.w))
        try:
            c, s_c = PH.encircled_axis(system.inertia, run.w)
            flow = Flow(system, c, s_c)
            av = flow.averages(flow.x_of(run.w), phases=False)
            if run.s > t_enter and mu_of(av) < MU_OUT:
                break
            span = FULL_CHUNK_PERIODS * 2.0 * math.pi / av.omega_p
        except PH.NoPolhode:
            span = FULL_CHUNK_PERIODS * 2.0 * math.pi / max(rate, 1e-300)
        end = min(t_end, run.s + span)
        if run.full_turns + rate * (end - run.s) / (2.0 * math.pi) > MAX_FULL_TURNS:
            return (f"averaging fails from here on ({_why(system, run.w)}) and resolving it in full would take more "
                    f"than {MAX_FULL_TURNS:g} turns")
        k = int(np.searchsorted(t_all, end, side="right"))
        times = t_all[run.j:k] if k > run.j and t_all[k - 1] == end else np.concatenate([t_all[run.j:k], [end]])
        sub, e = spin_problem(system, run.w, np.concatenate([[run.s], times]) - run.s, q0=run.qs,
                              kinematics="quaternion")
        sol = solve_taylor(sub, run.rtol, min(run.atol, run.rtol), None)
        run.full_steps += int(sol.stats.get("nsteps", 0))
        if not sol.success:
            return f"the full stage (taylor): {sol.message}"
        n = k - run.j
        run.omega[run.j:k] = sol.omega[1:1 + n] * e
        if run.q is not None:
            run.q[run.j:k] = sol.q[1:1 + n]
        run.full_turns += rate * (end - run.s) / (2.0 * math.pi)
        run.terms["phase_full"] += 3.0 * run.rtol * rate * (end - run.s)
        run.j, run.s = k, end
        run.w, run.qs = sol.omega[-1] * e, R.normalize(sol.q[-1])
        check()
    end_axis = _axis_or_none(system, run.w)
    if entry is not None and end_axis is not None and start_axis is not None and end_axis[0] != start_axis[0]:
        run.crossings.append({"t": t_enter, "t_out": run.s, "from": list(start_axis), "to": list(end_axis),
                              "odds": entry, "phase_error_rad": _phase_statement(run),
                              "outcome_resolved": bool(_phase_statement(run) < 0.1)})
    return None


def _axis_or_none(system, w):
    try:
        return PH.encircled_axis(system.inertia, w)
    except PH.NoPolhode:
        return None


def _why(system, w) -> str:
    try:
        c, s_c = PH.encircled_axis(system.inertia, w)
        av = Flow(system, c, s_c).averages(Flow(system, c, s_c).x_of(w), phases=False)
    except PH.NoPolhode:
        return "no polhode: on the separatrix or about a degenerate pair"
    if av.mu_sep / SEP_WEIGHT >= max(av.mu_ad, av.mu_osc):
        return f"near the separatrix, mu_sep = {av.mu_sep:.2g}"
    return f"the polhode is slow against the braking, mu = {max(av.mu_ad, av.mu_osc):.2g}"


def _crossing_odds(system, w, axis):
    """{lobe: probability} of the lobes a run leaving its polhode's lobe through the
    separatrix may enter, or None where it is not near one (``polhode_flow.separatrix_odds``)."""
    if axis is None:
        return None
    from .polhode_flow import separatrix_odds

    return separatrix_odds(system, w, axis)


# --- what the run says --------------------------------------------------------------------------
def _stats(run: _Run) -> dict:
    biggest = float(np.nanmax(np.abs(run.t))) if run.t.size else 0.0
    resolution = float(np.spacing(max(biggest, 1.0)))
    # the kicks and the wobble as computed, times a margin (measured/stated up to 1.03 without it)
    L_unc = L_MARGIN * float(math.sqrt(sum(k * k for k in run.L_kicks) + run.terms["L_wobble"] ** 2))
    # the orientation is built about L: it is no better than L's direction
    phase_err = max(_phase_statement(run) + L_unc, resolution)
    return {
        "nsteps": run.avg_steps + run.full_steps, "nsteps_averaged": run.avg_steps, "nsteps_full": run.full_steps,
        "nfev": run.nfev, "full_turns": run.full_turns, "max_mu": run.max_mu, "mu_in": MU_IN,
        "second_order": run.order2,
        "segments": [[a, b] for a, b, _, _ in run.segments[:50]],
        "segment_axes": [[c, s] for _, _, c, s in run.segments[:50]],
        "separatrix_crossings": run.crossings, "resonances": run.resonances,
        "slow_error_estimate": _slow_statement(run), "L_direction_uncertainty_rad": L_unc,
        "phase_error_rad": phase_err, "phase_resolution_rad": resolution,
        "phases_resolved": bool(phase_err <= PHASE_TOL),
        "phase_rates": "with the torque's corrections" if run.phase_corrections else
                       "free (the phase is beyond float64: the torque's O(eps) corrections left out)",
        "end_axis": None if run.axis_end is None else [int(run.axis_end[0]), float(run.axis_end[1])],
        "error_terms": dict(run.terms),
    }


register(Integrator(
    name="polhode", order=None, fixed_step=False, solve=solve_polhode,
    description="any body over real horizons: the torque averaged over the Euler-Poinsot polhode (Jacobi elliptic "
                "functions), L_world fixed, separatrix crossings integrated in full",
))
