"""``taylor`` in a trap: Taylor's method with a static field in the equations and the gas's
collisions as impulses at their Poisson times.

The scheme, and why it is this one:

* the field's torque d x E is deterministic and depends on the orientation: it is part of
  the heyoka system (``field_equations``: E turned into the body frame by the integrated
  quaternion), so the run is as exact as any field-free one;
* the gas acts only through collisions.  Each is an angular impulse J applied to Omega at its
  instant (``integrators.collisions``: the exact kinetic-theory draw at the state of that
  instant), and between collisions Taylor's method integrates the rest.  The gas's drag is
  the mean of these impulses, so it is *not* also put into the equations: adding it there
  would count it twice, and adding it there while taking the mean out of each impulse would
  lose the variance of the collisions' number -- which for a crystal whose surface outruns the
  molecules (the DAST cube: each collision takes ~m |Omega| a^2 of angular momentum, against
  a random part ~m v_bar a) is most of the line's random walk;
* the collisions' times: a Poisson stream whose rate depends on the state, drawn by thinning:
  candidates at a bound Lambda (``Collider.bound``: for any |Omega| up to |L| / I_min) and
  each kept with the ratio of the true rate to the bound at the candidate's state.  Candidates
  come in batches: heyoka's dense output gives the states at a batch's candidate times in one
  call, and the first kept one ends the batch (the rest is redrawn from there: a Poisson
  stream has no memory).

Spin units inside (``scaling``): the impulse J (g cm^2/s, body frame) changes the spin-unit
omega by J / (I |Omega0|); the field enters as e = |d| E / (I1 |Omega0|^2) (dimensionless).
"""

from __future__ import annotations

import copy
import math
from dataclasses import dataclass, field

import numpy as np

from ..interrupt import call_stoppable
from . import cache
from . import status as ST
from . import taylor as TY
from .base import Problem, Solution

N_PARS_FIELD = TY.N_PARS + 6          # then e (3, world frame) and the unit dipole (3, body frame)
E_PAR, D_PAR = TY.N_PARS, TY.N_PARS + 3
BATCH_MIN, BATCH_MAX = 4, 256
BOUND_MARGIN = 1.0 + 1e-6             # the thinning's |Omega| bound over |L| / I_min


@dataclass
class EnvRun:
    """The environment of one run, as the integrators need it (CGS, body frame for the body):

    gas, surface : ``physics.gas.Gas`` and ``physics.surface.Surface`` (None: no gas);
    inertia : (I1, I2, I3) g cm^2; dipole : body-frame d, statC cm; field : world-frame E,
    statV/cm; omega_scale : |Omega0| (rad/s), the spin unit; rng : NumPy ``Generator``.
    Counters are filled in as the run goes (``stats``)."""

    gas: object
    surface: object
    inertia: tuple
    dipole: tuple
    field: np.ndarray
    omega_scale: float
    rng: np.random.Generator
    collisions: int = 0
    candidates: int = 0
    impulse: np.ndarray = field(default_factory=lambda: np.zeros(3))

    @property
    def has_field(self) -> bool:
        """A non-zero static field."""
        return bool(np.any(np.asarray(self.field) != 0.0))

    def field_pars(self) -> np.ndarray:
        """e (3) and the unit dipole (3): the par[] of the field's torque in spin units."""
        d = np.asarray(self.dipole, dtype=float)
        dn = float(np.linalg.norm(d))
        e = dn * np.asarray(self.field, dtype=float) / (float(self.inertia[0]) * self.omega_scale**2)
        return np.concatenate([e, d / dn])

    def rescaled(self, factor: float) -> EnvRun:
        """The same environment (and random stream, and counters) for a problem whose spin
        unit is ``factor`` times this one's (a stage of a hand-over)."""
        out = copy.copy(self)
        out.omega_scale = self.omega_scale * factor
        return out

    def stats(self) -> dict:
        """What the environment did over the run."""
        return {"collisions": int(self.collisions), "collision_candidates": int(self.candidates),
                "gas_angular_impulse_body": [float(x) for x in self.impulse]}


def field_equations(model: str):
    """The Taylor system of ``model`` with quaternion kinematics (``taylor.equations``) and the
    torque d x E of a static world-frame field: E_body = R(q)^T e, omega_dot += (d_hat x E_body)
    / J (spin units; par[E_PAR:E_PAR+3] = e, par[D_PAR:D_PAR+3] = d_hat)."""
    import heyoka as hy

    base = TY.equations(model, "quaternion")
    par = hy.par
    q0, q1, q2, q3 = (v for v, _ in base[3:7])
    e = [par[E_PAR + i] for i in range(3)]
    d = [par[D_PAR + i] for i in range(3)]
    J = [par[TY.J1], par[TY.J2], par[TY.J3]]
    # R(q) (w, x, y, z), body -> world; E_body = R^T e
    R = [[1.0 - 2.0 * (q2 * q2 + q3 * q3), 2.0 * (q1 * q2 - q0 * q3), 2.0 * (q1 * q3 + q0 * q2)],
         [2.0 * (q1 * q2 + q0 * q3), 1.0 - 2.0 * (q1 * q1 + q3 * q3), 2.0 * (q2 * q3 - q0 * q1)],
         [2.0 * (q1 * q3 - q0 * q2), 2.0 * (q2 * q3 + q0 * q1), 1.0 - 2.0 * (q1 * q1 + q2 * q2)]]
    Eb = [R[0][i] * e[0] + R[1][i] * e[1] + R[2][i] * e[2] for i in range(3)]
    torque = [d[1] * Eb[2] - d[2] * Eb[1], d[2] * Eb[0] - d[0] * Eb[2], d[0] * Eb[1] - d[1] * Eb[0]]
    c = par[TY.C]
    sigma = (1.0 + c * hy.time) ** 0.5                  # u = omega sigma: du/dt gains sigma x the torque's rate
    out = [(var, ex + sigma * torque[i] / J[i]) for i, (var, ex) in enumerate(base[:3])]
    return out + base[3:]


_templates: dict = {}


def template(model: str, tol: float, precision: str = "double"):
    """A compiled integrator of ``field_equations`` (runaway event only), made once per process
    and kept in the on-disk cache like ``taylor.template``'s; callers take a copy."""
    key = (model, float(tol), precision)
    ta = _templates.get(key)
    if ta is None:
        import heyoka as hy

        sys_ = field_equations(model)
        fp = TY.PRECISIONS[precision]
        evs = TY.events(model, False, fp, residual=False, runaway=True)
        digest = cache.digest(hy.__version__, "field", repr(float(tol)), precision, str(sys_), *(str(x) for x in evs))
        ta = cache.load(digest)
        if ta is None:
            kw = {"tol": fp(tol), "t_events": evs}
            if precision != "double":
                kw.update(fp_type=fp, compact_mode=True)
            ta = hy.taylor_adaptive(sys_, np.zeros(7, dtype=fp), pars=np.zeros(N_PARS_FIELD, dtype=fp), **kw)
            cache.store(digest, ta)
        _templates[key] = ta
    return ta


def _integrator(problem: Problem, env: EnvRun, tol: float, precision: str):
    """(heyoka integrator ready at the start, par[] used, the braking scale c)."""
    pars = TY.parameters(problem)
    c = float(pars[TY.C])
    if env.gas is not None:
        # collisions can spin a slow body up to the gas's rotational temperature: the runaway bound
        # must sit well above that, not at 10 |omega0|
        from ..units import K_BOLTZMANN

        t_max = max(env.gas.temperature_k, env.gas.surface_temperature_k)
        thermal = math.sqrt(3.0 * K_BOLTZMANN * t_max / min(env.inertia)) / env.omega_scale
        w_max = max(math.sqrt(pars[TY.W2MAX]), 100.0 * thermal)
        pars[TY.W2MAX] = w_max * w_max
    if env.has_field:
        ta = copy.copy(template(problem.system.model, tol, precision))
        full = np.concatenate([pars, env.field_pars()])
    else:
        ta = copy.copy(TY.template(problem.system.model, "quaternion", tol, precision, residual=False, runaway=True))
        full = pars
    ta.time = ta.state.dtype.type(problem.t_eval[0])
    ta.state[:] = TY.initial_state(problem)
    ta.pars[:] = full[:len(ta.pars)]
    return ta, c


def solve_taylor_env(problem: Problem, env: EnvRun, rtol: float = 1e-10, atol: float = 1e-12,
                     step: float | None = None, max_steps: int = TY.MAX_STEPS, precision: str = "double",
                     stop_on_stiffness: bool = False) -> Solution:
    """Taylor's method on ``problem`` (spin units, quaternion kinematics) in the environment
    ``env`` (module docstring); output at ``problem.t_eval``.  A run that stops early keeps
    its samples so far and says why; ``env``'s counters say what the gas did."""
    if problem.kinematics != "quaternion":
        raise ValueError("an environment needs the orientation (quaternion kinematics): the field acts in the world "
                         "frame")
    tol, honoured = TY.tolerance(rtol, atol, precision)
    t = np.asarray(problem.t_eval, dtype=float)
    ta, c = _integrator(problem, env, tol, precision)
    watch = TY._Watch(max_steps, stiff_check=stop_on_stiffness, c=c)
    y = np.full((t.size, 7), np.nan)
    y[0] = TY.initial_state(problem)

    def kernel(stop):
        watch.stop = stop
        if env.gas is None:
            res = ta.propagate_grid(t.astype(ta.state.dtype), callback=watch,
                                    **({} if step is None else {"max_delta_t": float(step)}))
            rows = np.asarray(res[-1], dtype=float)
            y[:rows.shape[0]] = rows
            return res[0]
        return _with_collisions(ta, env, t, y, c, watch, step, stop)

    outcome = call_stoppable(kernel)
    status = TY._status(outcome, watch)
    ok_rows = np.all(np.isfinite(y), axis=1)
    reached = int(np.argmin(ok_rows)) if not ok_rows.all() else len(t)
    y = TY.unscale(t, y, c)
    stats = {"nsteps": int(watch.steps), "order": int(ta.order), "tol": tol, "precision": precision, **env.stats()}
    if not honoured:
        stats["tolerance_note"] = (f"asked min(rtol, atol) = {min(rtol, atol):.2g}, below what {precision} can hold; "
                                   f"integrated at {tol:.2g}")
    if watch.stiff_at is not None:
        stats["stiff_at"] = watch.stiff_at
    if status == ST.RUNAWAY:
        stats.update(runaway_at=float(ta.time), runaway_omega=(np.asarray(ta.state[:3], dtype=float)
                                                                / math.sqrt(1.0 + c * float(ta.time))).tolist())
    return TY._solution(problem, t, y, status, stats, reached)


def _with_collisions(ta, env: EnvRun, t, y, c: float, watch, step, stop):
    """The run with its collisions (module docstring), filling ``y`` at the grid ``t``; returns
    heyoka's last outcome."""
    from .collisions import Collider

    hy_ok = None
    col = Collider(env.gas, env.surface, env.rng)
    inertia = np.asarray(env.inertia, dtype=float)
    imin = float(inertia.min())
    scale = env.omega_scale
    kw = {"callback": watch} if step is None else {"callback": watch, "max_delta_t": float(step)}
    j = 1                                         # next output index
    kept_per_candidate = 0.25
    grow = 1.0                                    # raised when a state outran the thinning's bound
    while j < t.size:
        if stop[0] != 0:
            watch.why = ST.INTERRUPTED
            return _cb_stop()
        now = float(ta.time)
        sig = math.sqrt(1.0 + c * now)
        w = np.asarray(ta.state[:3], dtype=float) / sig
        L = float(np.linalg.norm(inertia * w))
        s_bound, lam = col.bound(BOUND_MARGIN * grow * L / imin * scale)
        lam_spin = lam / scale                     # candidates per unit of spin-unit time
        n = int(min(BATCH_MAX, max(BATCH_MIN, math.ceil(1.5 / max(kept_per_candidate, 1e-3)))))
        times = now + np.cumsum(env.rng.exponential(1.0 / lam_spin, n)) if lam_spin > 0 else np.full(n, np.inf)
        end = float(t[-1])
        cand = times[times < end]
        outs = t[j:][t[j:] <= (cand[-1] if cand.size else end)]
        grid = np.unique(np.concatenate([[now], outs, cand]))
        if grid.size < 2:
            grid = np.array([now, end])
        res = ta.propagate_grid(grid.astype(ta.state.dtype), **kw)
        hy_ok = res[0]
        states = np.asarray(res[-1], dtype=float)
        if states.shape[0] < grid.size:                       # stopped early: keep what was reached
            _store(t, y, grid[:states.shape[0]], states, j)
            return hy_ok
        if cand.size == 0:
            j = _store(t, y, grid, states, j)
            continue
        rows = np.searchsorted(grid, cand)
        sig_c = np.sqrt(1.0 + c * cand)
        omegas = states[rows, :3] / sig_c[:, None] * scale     # rad/s, body frame
        k, J, tried, exceeded = _first_kept(col, omegas, s_bound)
        env.candidates += tried
        if exceeded:                                 # the bound was too low for a state reached: redo with a larger one
            ta.time, ta.state[:] = ta.state.dtype.type(now), states[0]
            grow *= 1.5
            continue
        kept_per_candidate = 0.9 * kept_per_candidate + 0.1 * ((1.0 if k >= 0 else 0.0) / max(tried, 1))
        if k < 0:
            j = _store(t, y, grid, states, j)
            continue
        t_hit = cand[k]
        upto = grid <= t_hit
        j = _store(t, y, grid[upto], states[upto], j)
        new = states[rows[k]].copy()
        new[:3] += J / (inertia * scale) * sig_c[k]
        ta.time, ta.state[:] = ta.state.dtype.type(t_hit), new
        env.collisions += 1
        env.impulse += J
    return hy_ok


def _cb_stop():
    import heyoka as hy

    return hy.taylor_outcome.cb_stop


def _store(t, y, grid, states, j: int) -> int:
    """Copy the states at output times of ``grid`` into ``y`` from index ``j``; the next index."""
    while j < t.size:
        i = int(np.searchsorted(grid, t[j]))
        if i >= grid.size or grid[i] != t[j]:
            break
        y[j] = states[i]
        j += 1
    return j


def _first_kept(col, omegas, s_bound):
    """The first candidate kept among states ``omegas`` (B, 3) (rad/s): (its index or -1, J,
    candidates looked at, whether a state's rate exceeded the bound)."""
    from .collisions import first_kept

    k, J, tried, exceeded = first_kept(col.rng, np.ascontiguousarray(omegas), *col.args, s_bound)
    return int(k), J, int(tried), bool(exceeded)
