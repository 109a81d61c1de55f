"""``taylor``: Taylor's method (heyoka), for single runs and batches of runs.

heyoka builds the right-hand side as an expression, differentiates it automatically to the
order its tolerance needs (order ~ -ln(tol)/2: 20 at 1e-16) and compiles it with LLVM, so
steps are long and the error follows the tolerance down to the last digits, where explicit
Runge-Kutta methods stall (see ``spinviz bench``).

One source.  The right-hand sides are the very functions of ``physics.equations``
(``reduced_terms``, ``truncated_terms``, ``free_rate``, ``quat_rate``, ``euler_zxz_rate``),
evaluated once on heyoka's symbolic variables: they are written with + - * / only, so the
same code gives numbers, NumPy arrays and heyoka expressions.

Runtime parameters.  The body enters as ``heyoka.par``: J = (J1, J2, J3), g = (g1, g2, g3),
so one compiled integrator serves every body of a model (``PARS`` below); compiled code is
cached in memory and on disk by heyoka (~/.cache/heyoka), so only the first run on a machine
compiles (see ``spinviz bench --startup``).

Scaled variables.  heyoka's error control is absolute where the state is below 1 and
relative above, on the state's largest component.  Radiation brakes |omega| like
1/sqrt(1 + c t) (section 3, (3.7); c = |g|^2 = eps_rad in spin units), so late in a long run
an absolute tolerance on omega would no longer mean anything.  The integrated variable is
therefore u = omega sqrt(1 + c t), O(1) for the whole run, with::

    du/dt = sigma f(u / sigma) + u c / (2 sigma^2),   sigma = sqrt(1 + c t),

and the kinematics driven by omega = u / sigma.  (For real particles c ~ 1e-16 and sigma = 1
to round-off; for the atlas it keeps the tolerance meaningful to tau = 1e16.)

Events.  Terminal events stop a run where it must stop: a runaway (|omega| past
``status.runaway_bound``: the reduction (2.3) has broken down) and, when asked, the residual
rotation about d (|d x omega| < eta |d| |omega|), where the paper proves it is the end state
and a resolving method would otherwise follow it turn by turn for ever.
"""

from __future__ import annotations

import copy
import math
import threading
from dataclasses import dataclass

import numpy as np

from ..interrupt import call_stoppable
from ..physics import equations as E
from ..physics import models as M
from . import cache
from . import status as ST
from .base import Integrator, Problem, Solution, register

# par[] layouts.  General bodies: J = (J1, J2, J3), g = (g1, g2, g3); symmetric tops of the atlas
# ((4.2)-(4.4)): delta and g = (n1, 0, n3).  Then the braking scale c and the event thresholds.
J1, J2, J3, G1, G2, G3, C, W2MAX, ETA2 = range(9)
N_PARS = 9
S_DELTA, S_N1, S_N3, S_C, S_W2MAX, S_ETA2 = range(6)
N_PARS_SYMMETRIC = 6
MAX_STEPS = 200_000_000
PRECISIONS = {"double": np.float64, "long double": np.longdouble}
# The smallest tolerance each precision can honour: below it heyoka is asked for digits the
# number format does not have (machine epsilon 2.2e-16 and 1.1e-19).
TOL_FLOOR = {"double": 2.2e-16, "long double": 1.1e-19}


def _hy():
    import heyoka as hy

    return hy


@dataclass(frozen=True)
class _Layout:
    """Where the body sits in par[]: g (three expressions), c, the event thresholds, and the
    rate omega -> omega_dot as a function of the three omega expressions."""

    g: tuple
    c: object
    w2max: object
    eta2: object
    n_pars: int
    rate: object


def _layout(model: str, symmetric: bool) -> _Layout:
    hy = _hy()
    par = hy.par
    if symmetric:
        f = M.get(model).symmetric_rate
        return _Layout((par[S_N1], 0.0, par[S_N3]), par[S_C], par[S_W2MAX], par[S_ETA2], N_PARS_SYMMETRIC,
                       lambda w: f(w[0], w[1], w[2], par[S_DELTA], par[S_N1], par[S_N3]))
    J = (par[J1], par[J2], par[J3])
    g = (par[G1], par[G2], par[G3])
    f = M.rate_function(model)
    return _Layout(g, par[C], par[W2MAX], par[ETA2], N_PARS, lambda w: f(w[0], w[1], w[2], J, g))


def equations(model: str, kinematics: str = "quaternion", symmetric: bool = False):
    """The Taylor system of ``model`` with ``kinematics``, in the scaled variables u (module
    docstring): a list of (variable, expression) pairs for heyoka, body in ``par``.

    State order: (u1, u2, u3) then (q0, q1, q2, q3) for "quaternion" (w, x, y, z), (phi,
    theta, psi) for "euler_zxz" (the Poisson equations (6.4)), nothing for "none".
    symmetric : the symmetric top's own form ((4.2)-(4.4) and its truncated analogue, par
    layout ``S_*``), for the atlas's Euler-only runs.
    """
    hy = _hy()
    if symmetric and (M.get(model).symmetric_rate is None or kinematics != "none"):
        raise ValueError("the symmetric form serves the atlas: Euler-only runs of a model with a symmetric rate")
    lay = _layout(model, symmetric)
    u = hy.make_vars("u1", "u2", "u3")
    s1 = (1.0 + lay.c * hy.time) ** -0.5                 # 1 / sigma
    w = [x * s1 for x in u]
    a = lay.rate(w)
    out = [(u[i], a[i] / s1 + 0.5 * lay.c * s1 * s1 * u[i]) for i in range(3)]
    if kinematics == "quaternion":
        q = hy.make_vars("q0", "q1", "q2", "q3")
        out += list(zip(q, E.quat_rate(*q, *w)))
    elif kinematics == "euler_zxz":
        ang = hy.make_vars("phi", "theta", "psi")
        out += list(zip(ang, E.euler_zxz_rate(*ang, *w, sin=hy.sin, cos=hy.cos)))
    elif kinematics != "none":
        raise ValueError(f"unknown kinematics {kinematics!r}")
    return out


def events(model: str, batch: bool, fp_type=np.float64, symmetric: bool = False, residual: bool = True,
           runaway: bool = True):
    """The terminal events, in this order: the runaway (with ``runaway``) and the residual
    rotation (with ``residual``); see ``event_kind``."""
    hy = _hy()
    lay = _layout(model, symmetric)
    u1, u2, u3 = hy.make_vars("u1", "u2", "u3")
    g = lay.g
    uu = u1 * u1 + u2 * u2 + u3 * u3
    c1, c2, c3 = g[1] * u3 - g[2] * u2, g[2] * u1 - g[0] * u3, g[0] * u2 - g[1] * u1
    gg = g[0] * g[0] + g[1] * g[1] + g[2] * g[2]
    d = hy.event_direction
    if batch:
        def make(ex, direction):
            return hy.t_event_batch(ex, direction=direction)
    else:
        def make(ex, direction):
            return hy.t_event(ex, direction=direction, fp_type=fp_type)
    # Both stay within [-1, 1] and are polynomials of the state where they can be: heyoka sizes
    # its steps on the largest Taylor coefficients of the state *and* of the event functions
    # (measured: an event function of 1e6 took the steps up 3x and the error from 1e-12 to
    # 1e-2; the residual event as a rational function of u cost 60 % more steps, as a
    # polynomial 16 %, so it is compiled in only where a run needs it).
    out = []
    if runaway:
        out.append(make(uu / (lay.w2max * (1.0 + lay.c * hy.time)) - 1.0, d.positive))
    if residual:
        out.append(make(c1 * c1 + c2 * c2 + c3 * c3 - lay.eta2 * gg * uu, d.negative))
    return out


def event_kind(index: int, runaway: bool) -> int:
    """The status of terminal event ``index`` of an integrator built with (runaway, ...)."""
    return ST.RUNAWAY if (runaway and index == 0) else ST.STOPPED_RESIDUAL


def n_pars(symmetric: bool, residual: bool, runaway: bool) -> int:
    """How many par[] the system uses (heyoka counts up to the highest index used)."""
    c, w2, e2 = (S_C, S_W2MAX, S_ETA2) if symmetric else (C, W2MAX, ETA2)
    return 1 + (e2 if residual else (w2 if runaway else c))



_lock = threading.Lock()
_templates: dict = {}


def template(model: str, kinematics: str, tol: float, precision: str = "double", batch: int = 0,
             symmetric: bool = False, residual: bool = True, runaway: bool = True):
    """A compiled integrator for (model, kinematics, tol, precision, form, events), batch width
    ``batch`` (0: scalar), made once per process.  Callers take a copy (``copy.copy``) or reset
    every field they use.

    Start-up: heyoka caches machine code on disk itself, but still rebuilds the expression
    decomposition at every construction (~45 ms for the 7-variable reduced system); the built
    integrator is therefore also kept pickled (``cache``: loads in ~6 ms), keyed by the
    system's own expressions, the tolerance, heyoka's version and the CPU's features (the
    pickle holds code compiled for this CPU)."""
    key = (model, kinematics, float(tol), precision, int(batch), symmetric, residual, runaway)
    with _lock:
        ta = _templates.get(key)
        if ta is None:
            hy = _hy()
            sys_ = equations(model, kinematics, symmetric)
            fp = PRECISIONS[precision]
            evs = events(model, bool(batch), fp, symmetric, residual, runaway)
            digest = cache.digest(hy.__version__, repr(float(tol)), precision, str(batch), str(sys_),
                                  *(str(e) for e in evs))
            ta = cache.load(digest)
            if ta is None:
                n = len(sys_)
                npar = n_pars(symmetric, residual, runaway)
                kw = {"tol": fp(tol), "t_events": evs}
                if precision != "double":
                    kw.update(fp_type=fp, compact_mode=True)
                if batch:
                    ta = hy.taylor_adaptive_batch(sys_, np.zeros((n, batch)), pars=np.zeros((npar, batch)), **kw)
                else:
                    ta = hy.taylor_adaptive(sys_, np.zeros(n, dtype=fp), pars=np.zeros(npar, dtype=fp), **kw)
                cache.store(digest, ta)
            _templates[key] = ta
    return ta


def tolerance(rtol: float, atol: float, precision: str = "double") -> tuple[float, bool]:
    """heyoka's one tolerance for the requested (rtol, atol) in spin units (|omega(0)| = 1,
    |q| = 1, so the state is O(1) and the two coincide), and whether the number format can
    honour it: min(rtol, atol) rounded down to a power of ten (compiled code depends on the
    tolerance: this keeps a machine's cache to a few integrators, at most 10x tighter than
    asked -- which costs ~10 % more steps, the order rising with the digits)."""
    tol = min(float(rtol), float(atol))
    floor = TOL_FLOOR[precision]
    if not tol >= floor:
        return floor, False
    return max(floor, 10.0 ** math.floor(math.log10(tol) + 1e-9)), True


def parameters(problem: Problem, eta: float = 0.0, symmetric: bool = False) -> np.ndarray:
    """par[] of ``problem``: the body (J and g, or for ``symmetric`` delta, n1, n3), the
    braking scale c = |g|^2 (0 for the free top), the runaway bound squared and the
    residual-rotation threshold squared (0: off)."""
    s = problem.system
    g = np.asarray(s.coupling, dtype=float)
    c = 0.0 if s.model == "free" else float(g @ g)
    w_max = ST.runaway_bound(c)
    tail = [c, w_max * w_max if math.isfinite(w_max) else 1e300, eta * eta]
    if symmetric:
        J = s.inertia
        if not (J[0] == 1.0 and J[1] == 1.0 and g[1] == 0.0):
            raise ValueError("the symmetric form needs J = (1, 1, 1 - delta) and g = (n1, 0, n3)")
        return np.array([1.0 - float(J[2]), g[0], g[2], *tail])
    return np.array([*map(float, s.inertia), *g, *tail])


def initial_state(problem: Problem) -> np.ndarray:
    """(u(0) = omega0, then q0 or the ZXZ angles) of ``problem``."""
    w0 = np.asarray(problem.omega0, dtype=float)
    if problem.kinematics == "quaternion":
        q0 = problem.q0 if problem.q0 is not None else (1.0, 0.0, 0.0, 0.0)
        return np.concatenate([w0, np.asarray(q0, dtype=float)])
    if problem.kinematics == "euler_zxz":
        return np.concatenate([w0, np.asarray(problem.euler0, dtype=float)])
    return w0.copy()


def unscale(t, y, c: float) -> np.ndarray:
    """The state with omega = u / sqrt(1 + c t) restored; t shape (N,), y shape (N, n)."""
    out = np.array(y, dtype=float, copy=True)
    out[:, :3] /= np.sqrt(1.0 + c * np.asarray(t, dtype=float))[:, None]
    return out


class _Watch:
    """heyoka's step callback: counts steps, stops at ``max_steps`` or when ``stop[0]`` is set,
    and (``stiff_check``) when the problem turns stiff.  (~0.2 us a step, against ~1.5 us for
    the step itself.)

    Stiffness, for an explicit Taylor method: its step is held to ~order/|lambda| by the
    fastest decaying mode, so where that mode is much faster than the spin, steps shrink to a
    small fraction of a radian of spin.  Every ``WINDOW`` steps the mean step is compared with
    the spin period; ``STIFF_WINDOWS`` windows in a row below ``STIFF_RAD`` radians a step stop
    the run with status STIFF.  The threshold is where radau starts to win (measured on thin
    askew tops, ``spinviz stress``: taylor 7-400x faster up to a decay/spin ratio of 1.6e5, even
    at 5e5 -- steps of ~4e-5 rad --, radau 1.3-2x faster at 1.6e6 .. 1.6e7).
    """

    WINDOW = 512
    STIFF_RAD = 1e-5
    STIFF_WINDOWS = 4

    def __init__(self, max_steps: int, stop=None, stiff_check: bool = False, c: float = 0.0):
        self.max_steps, self.stop = int(max_steps), stop
        self.steps = 0
        self.why = None
        self.stiff_check, self.c = stiff_check, c
        self.win_t = None
        self.n_stiff = 0
        self.stiff_at = None

    def __call__(self, ta) -> bool:
        self.steps += 1
        if self.stop is not None and self.stop[0] != 0:
            self.why = ST.INTERRUPTED
            return False
        if self.steps >= self.max_steps:
            self.why = ST.TOO_MANY_STEPS
            return False
        if self.stiff_check and self.steps % self.WINDOW == 0:
            return self._window(ta)
        return True

    def _window(self, ta) -> bool:
        t = float(ta.time)
        if self.win_t is not None:
            u = np.asarray(ta.state[:3], dtype=float)
            spin = float(np.sqrt(u @ u / (1.0 + self.c * t)))
            slow = (t - self.win_t) / self.WINDOW * spin < self.STIFF_RAD
            self.n_stiff = self.n_stiff + 1 if slow else 0
            if self.n_stiff >= self.STIFF_WINDOWS:
                self.why, self.stiff_at = ST.STIFF, t
                return False
        self.win_t = t
        return True


def _status(outcome, watch, runaway: bool = True) -> int:
    """A ``status`` code from heyoka's outcome of one run."""
    hy = _hy()
    o = hy.taylor_outcome
    if outcome in (o.time_limit, o.success):
        return ST.OK
    if outcome == o.cb_stop:
        return watch.why if (watch is not None and watch.why is not None) else ST.INTERRUPTED
    if outcome == o.err_nf_state:
        return ST.NOT_FINITE
    if outcome == o.step_limit:
        return ST.TOO_MANY_STEPS
    v = int(outcome)
    if v < 0:                                    # terminal event i is reported as -(i + 1)
        return event_kind(-v - 1, runaway)
    return ST.NOT_FINITE


def _grid_run(ta, t, watch, h_max):
    kw = {"callback": watch}
    if h_max is not None and math.isfinite(h_max):
        kw["max_delta_t"] = float(h_max)
    res = ta.propagate_grid(np.asarray(t, dtype=ta.state.dtype), **kw)
    return res[0], res[-1]


def solve_taylor(problem: Problem, rtol: float = 1e-10, atol: float = 1e-12, step: float | None = None,
                 max_steps: int = MAX_STEPS, precision: str = "double", stop_on_stiffness: bool = False) -> Solution:
    """Taylor's method on ``problem`` (spin units), output at ``problem.t_eval`` by heyoka's
    dense output; ``step`` caps the step size; ``stop_on_stiffness`` gives up (status STIFF)
    when the steps shrink to a sliver of the spin period (see ``_Watch``).  A run that stops
    early keeps its samples up to where it got (``Solution.reached``) and says why."""
    tol, honoured = tolerance(rtol, atol, precision)
    t = np.asarray(problem.t_eval, dtype=float)
    pars = parameters(problem)
    ta = copy.copy(template(problem.system.model, problem.kinematics, tol, precision, residual=False, runaway=True))
    ta.time = ta.state.dtype.type(t[0])
    ta.state[:] = initial_state(problem)
    ta.pars[:] = pars[:len(ta.pars)]
    watch = _Watch(max_steps, stiff_check=stop_on_stiffness, c=float(pars[C]))

    def kernel(stop):
        watch.stop = stop
        return _grid_run(ta, t, watch, step)

    outcome, y = call_stoppable(kernel)
    status = _status(outcome, watch)
    y = np.asarray(y, dtype=float)
    if y.shape[0] < len(t):                      # stopped early: heyoka returns the rows it reached
        y = np.concatenate([y, np.full((len(t) - y.shape[0], y.shape[1]), np.nan)])
    ok_rows = np.all(np.isfinite(y), axis=1)
    reached = int(np.argmin(ok_rows)) if not ok_rows.all() else len(t)
    y = unscale(t, np.where(ok_rows[:, None], y, np.nan), float(pars[C]))
    stats = {"nsteps": int(watch.steps), "order": int(ta.order), "tol": tol, "precision": precision}
    if not honoured:
        stats["tolerance_note"] = (f"asked min(rtol, atol) = {min(rtol, atol):.2g}, below what {precision} can hold; "
                                   f"integrated at {tol:.2g}")
    if watch.stiff_at is not None:
        stats["stiff_at"] = watch.stiff_at
    if status == ST.RUNAWAY:
        stats.update(runaway_at=float(ta.time), runaway_omega=(np.asarray(ta.state[:3], dtype=float)
                                                                / math.sqrt(1.0 + pars[C] * float(ta.time))).tolist())
    return _solution(problem, t, y, status, stats, reached)


def _solution(problem: Problem, t, y, status: int, stats: dict, reached: int) -> Solution:
    ok = status == ST.OK
    kin = problem.kinematics
    return Solution(t=t, omega=y[:, :3], q=y[:, 3:7] if kin == "quaternion" else None,
                    euler=y[:, 3:6] if kin == "euler_zxz" else None, success=ok,
                    message="" if ok else ST.MESSAGES.get(status, f"status {status}"), stats=stats,
                    status=status, reached=reached)


# --- batches: many runs of one model at once (the atlas) ----------------------------------------
@dataclass
class BatchRun:
    """One lane's result: samples up to ``reached`` (NaN after), how it ended, its steps."""

    omega: np.ndarray            # (N, 3) at the grid times, NaN after ``reached``
    status: int
    reached: int                 # samples obtained (the first is the start)
    t_stop: float                # where it stopped (the grid's end, or the event / failure time)
    nsteps: int


def width() -> int:
    """heyoka's SIMD width for double precision on this machine (8 with AVX-512, 4 with AVX)."""
    return int(_hy().recommended_simd_size())


def solve_batch(problems: list[Problem], rtol: float, max_steps: int = MAX_STEPS, residual_eta=None,
                stop=None) -> list[BatchRun]:
    """Euler-only runs (kinematics "none") of symmetric tops (J = (1, 1, 1 - delta), g in the
    e1-e3 plane) of one model, ``width()`` at a time in heyoka's batch integrator on the
    symmetric form (4.2)-(4.4) (or its truncated analogue); each run has its own output grid
    ``t_eval`` (spin units: the same tau grid is a different t grid for each |omega0|), all of
    one length.

    residual_eta : per problem, eta > 0 to stop at the residual rotation |d x omega| < eta
        |d||omega| (the atlas passes it where that rotation is the exact end state), else 0.
    A lane that stops (an event, a non-finite state, its step budget) keeps its samples so far
    and is parked at omega = 0 -- a fixed point of the scaled system, costing nothing -- while
    the others go on.

    No per-step callback (a Python call a step costs ~0.3 us, a third of a step here): the
    batch advances ``CHUNK`` samples at a time, and the stop flag and the step budgets are
    looked at between chunks.  Events cost too (~15 %), so each is compiled in only where a
    run can need it: the residual rotation where ``residual_eta`` asks for it, the runaway
    where |omega0| > ``RUNAWAY_RISK`` (no symmetric top started below that ran away: 0 of 512
    random (delta, chi, omega0) at |omega0| = 0.1 .. 3, to tau = 1e6).
    """
    if not problems:
        return []
    model = problems[0].system.model
    N = len(problems[0].t_eval)
    for p in problems:
        if p.system.model != model or p.kinematics != "none" or len(p.t_eval) != N:
            raise ValueError("a batch holds Euler-only runs of one model on output grids of one length")
    eta = np.zeros(len(problems)) if residual_eta is None else np.asarray(residual_eta, dtype=float)
    tol, _ = tolerance(rtol, rtol)
    n = width()
    out: list = [None] * len(problems)
    groups: dict = {}
    for i, p in enumerate(problems):
        c = float(np.dot(p.system.coupling, p.system.coupling))       # = tau0 |Omega0| in spin units
        groups.setdefault((bool(eta[i] > 0.0), c > RUNAWAY_RISK), []).append(i)
    for (residual, runaway), idx in groups.items():
        for a in range(0, len(idx), n):
            part = idx[a:a + n]
            res = _one_batch([problems[i] for i in part], eta[part], model, tol, n, max_steps, stop,
                             residual, runaway)
            for i, r in zip(part, res):
                out[i] = r
    return out


RUNAWAY_RISK = 1.0         # tau0 |Omega0| above which a batch compiles in the runaway event
CHUNK = 24                 # samples a batch advances between looks at the stop flag and the budgets


def _one_batch(probs, eta, model, tol, n, max_steps, stop, residual, runaway) -> list[BatchRun]:
    k = len(probs)
    t = np.array([np.asarray(probs[min(j, k - 1)].t_eval, dtype=float) for j in range(n)])   # (lane, sample)
    ta = copy.copy(template(model, "none", tol, "double", n, symmetric=True, residual=residual, runaway=runaway))
    npar = ta.pars.shape[0]
    pars = np.zeros((N_PARS_SYMMETRIC, n))
    state = np.zeros((3, n))
    for i, p in enumerate(probs):
        pars[:, i] = parameters(p, eta[i], symmetric=True)
        state[:, i] = p.omega0
    pars[:, k:] = pars[:, :1]
    pars[S_ETA2, k:] = 0.0                       # idle lanes: the first body, at rest (a fixed point)
    ta.set_time(t[:, 0].copy())
    ta.state[:] = state
    ta.pars[:] = pars[:npar]
    N = t.shape[1]
    y = np.full((N, 3, n), np.nan)
    y[0] = state
    nxt = np.ones(n, dtype=int)                  # next grid index per lane
    status = np.full(n, ST.OK)
    t_stop = t[:, -1].copy()
    live = np.arange(n) < k
    steps = np.zeros(n, dtype=np.int64)
    while live.any():
        grid, rows = _restart_grid(t, nxt, np.asarray(ta.time, dtype=float), live, CHUNK)
        _, res = ta.propagate_grid(grid)
        res = np.asarray(res)
        pr = ta.propagate_res
        steps[live] += np.array([int(r[3]) for r in pr], dtype=np.int64)[live]
        for lane in np.flatnonzero(live):
            r = rows[lane]
            got = np.all(np.isfinite(res[1:len(r) + 1, :, lane]), axis=1)
            good = r[got]
            y[good, :, lane] = res[1:len(r) + 1][got, :, lane]
            if good.size:
                nxt[lane] = int(good.max()) + 1
            st = _status(pr[lane][0], None, runaway)
            if st != ST.OK:
                status[lane], t_stop[lane], live[lane] = st, float(ta.time[lane]), False
            elif nxt[lane] >= N:
                live[lane] = False
            elif steps[lane] >= max_steps:
                status[lane], t_stop[lane], live[lane] = ST.TOO_MANY_STEPS, float(ta.time[lane]), False
        if stop is not None and stop[0] != 0:
            raise InterruptedError("stop flag set")
        # stopped lanes are parked at omega = 0 (a fixed point, events off) while the others go on
        s = np.array(ta.state)
        s[:, ~live] = 0.0
        ta.state[:] = s
        if residual:
            p = np.array(ta.pars)
            p[S_ETA2, ~live] = 0.0
            ta.pars[:] = p
    out = []
    for i in range(k):
        w = y[:, :, i] / np.sqrt(1.0 + float(pars[S_C, i]) * t[i])[:, None]
        out.append(BatchRun(w, int(status[i]), int(nxt[i]), float(t_stop[i]), int(steps[i])))
    return out


def _restart_grid(t, nxt, times, live, chunk):
    """The output grid of the next stretch of a batch: lane j from its own time through up to
    ``chunk`` of its next samples t[j, nxt[j]:], padded by steps of 1e-9 of its last time
    (heyoka wants one strictly increasing column per lane, all of one length).  Returns
    (grid (M, n), rows: lane -> the sample indices of grid rows 1..)."""
    n, N = t.shape
    M = 1 + max((min(chunk, N - int(nxt[j])) for j in range(n) if live[j]), default=1)
    grid = np.empty((M, n))
    rows = {}
    for j in range(n):
        idx = np.arange(nxt[j], min(N, nxt[j] + chunk)) if live[j] else np.arange(0)
        col = np.concatenate([[times[j]], t[j, idx]])
        pad = M - len(col)
        if pad:
            end = max(col[-1], times[j])
            col = np.concatenate([col, end + max(abs(end), 1.0) * 1e-9 * np.arange(1, pad + 1)])
        grid[:, j] = col
        rows[j] = idx
    return grid, rows


register(Integrator(
    name="taylor", order=None, fixed_step=False, solve=solve_taylor, detects_stiffness=True, rtol_floor=1e-13,
    kinematics=("quaternion", "euler_zxz", "none"),
    description="Taylor's method (heyoka, LLVM-compiled, order from the tolerance), adaptive with dense output; "
                "error follows the tolerance to ~1e-13; the default",
))


def _solve_long(problem: Problem, rtol: float = 1e-15, atol: float = 1e-17, step: float | None = None,
                max_steps: int = MAX_STEPS, stop_on_stiffness: bool = False) -> Solution:
    return solve_taylor(problem, rtol, atol, step, max_steps, "long double", stop_on_stiffness)


register(Integrator(
    name="taylor-long", order=None, fixed_step=False, solve=_solve_long, detects_stiffness=True, rtol_floor=1e-17,
    kinematics=("quaternion", "euler_zxz", "none"),
    description="Taylor's method in 80-bit long double (heyoka, compact mode): references, error follows the "
                "tolerance to ~1e-16",
))
