"""``secular`` in a trap: the slow flow over real horizons with the gas's drift and diffusion of
the slow variables and the static field's precession of L.

Splitting in chunks.  ``secular`` carries the radiation from one chunk's start to its end; the
gas and the field then act on the state reached, and the next chunk starts from the result.
Chunks end at every output instant and are short enough that neither the gas nor the radiation
changes |L| by more than ``ETA`` within one (so the order of the two does not matter to that
accuracy), so the error of the splitting is O(ETA) of what each does within a chunk.

The gas over a chunk of length dt, at the state (Omega_body, O = R_world_from_body) reached:

* where the chunk holds few collisions (the thinning's candidates Lambda dt <= ``EXACT_MAX``),
  each is drawn exactly (``integrators.collisions``) at a uniform instant t_end - tau of the
  chunk, on the free motion through the end state: Omega' = R_e3(delta omega3 tau) Omega_body
  (the body's own precession; none for a spherical top), O' = R_L(-omega_L tau) O R_e3(-delta
  omega3 tau).  Its impulse J' changes L_body by R_e3(-delta omega3 tau) J' and L_world by O' J';
* where it holds many, their sum is Gaussian (the collisions' count is Poisson, so the sum's
  mean is dt times the mean torque and its covariance dt times the impulses' second moment
  per unit time, ``physics.gas.GasModel.moments``), averaged over the body's precession when
  that turns many times in the chunk (boxes: over a quarter turn, their symmetry), and turned
  by the spin about L in the world frame when the spin turns many times (then its part across
  L is isotropic about L there, its part along L exactly the body frame's);
* the new orientation takes the old L_body to the new one in the body and the old L_world to
  the new one in the world (the smallest rotations): O_new L_body_new = L_world_new.  The
  phase about L is not resolved (collisions randomise it).

The field over a chunk: averaged over the free motion, the dipole is d_par (e_ax . L_hat) L_hat
(e_ax the symmetry axis, or d for a sphere; d_par = d . e_ax), so L turns about E at
-d_par (e_ax . L_hat) |E| / |L| (rad/s) and keeps its size; the whole motion is turned about E
by that angle (trapezoid over the chunk).  This holds while the precession is slow against the
spin (``FIELD_RATIO_MAX``); a faster one is refused with the reason.
"""

from __future__ import annotations

import math

import numpy as np

from .. import rotations as R
from ..interrupt import check
from . import status as ST
from .base import Problem, Solution
from .scaling import spin_problem

ETA = 0.01                   # the largest relative change of |L| by the gas or the radiation within one chunk
EXACT_MAX = 4096             # candidates of the thinned stream a chunk may hold and still be drawn one by one
MAX_CHUNKS = 200_000         # chunks a run may take (the request refuses runs estimated beyond)
FIELD_RATIO_MAX = 1e-3       # the field's precession rate over the spin rate, the most the averaging carries
MOMENT_TOL = 3e-3            # the gas's moments are recomputed when Omega has changed by this much (relative)
MANY_TURNS = 8.0 * math.pi   # a phase turning at least this much over a chunk is averaged over


def _rot_z(angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


class _Moments:
    """The gas's moments at the state, recomputed only when Omega has moved by ``MOMENT_TOL``
    (the quadrature costs ~10 ms)."""

    def __init__(self, model):
        self.model = model
        self.at = None
        self.value = None

    def __call__(self, omega):
        if self.at is None or np.linalg.norm(omega - self.at) > MOMENT_TOL * np.linalg.norm(omega):
            self.at, self.value = np.array(omega, dtype=float), self.model.moments(omega)
        return self.value


def solve_secular_env(problem: Problem, env, rtol: float = 1e-10, atol: float = 1e-12,
                      step: float | None = None) -> Solution:
    """``secular`` on ``problem`` (spin units) in the environment ``env``
    (``taylor_env.EnvRun``), by chunks (module docstring).  Not successful, with the reason,
    where ``secular`` is not (its own refusals), where the field's precession is not slow
    against the spin, or where the run would take more than ``MAX_CHUNKS`` chunks."""
    from . import secular as SC

    t = np.asarray(problem.t_eval, dtype=float)
    run = _Chunks(problem, env, rtol, atol)
    failure = run.go(t, SC.solve_secular)
    stats = run.stats()
    if failure is not None:
        return Solution(t=t, omega=run.omega, q=run.q_out, success=False, message=failure, stats=stats,
                        status=ST.NOT_FINITE if "finite" in failure else 1, reached=run.j)
    slow = run.slow_series()
    return Solution(t=t, omega=run.omega, q=run.q_out, stats=stats, slow=slow)


class _Chunks:
    """The chunk loop of ``solve_secular_env``: the state (spin units of ``problem``) and the
    outputs filled in as it goes."""

    def __init__(self, problem: Problem, env, rtol: float, atol: float):
        self.problem, self.env, self.rtol, self.atol = problem, env, rtol, atol
        s = problem.system
        self.J = np.asarray(s.inertia, dtype=float)                  # I / I1
        self.inertia = np.asarray(env.inertia, dtype=float)           # g cm^2
        self.scale = env.omega_scale                                  # rad/s per spin unit
        t = np.asarray(problem.t_eval, dtype=float)
        self.omega = np.full((t.size, 3), np.nan)
        self.q_out = np.full((t.size, 4), np.nan)
        self.w = np.asarray(problem.omega0, dtype=float).copy()
        self.q = R.normalize(problem.q0 if problem.q0 is not None else (1.0, 0.0, 0.0, 0.0))
        self.omega[0], self.q_out[0] = self.w, self.q
        self.j = 1
        self.chunks = self.exact_chunks = self.gauss_chunks = 0
        self.nsteps = 0
        self.slow_error = 0.0
        self.expected_collisions = 0.0
        self.q_frame = None
        self.field_turn = 0.0
        self.eps = float(np.dot(s.coupling, s.coupling))
        delta = 1.0 - self.J[2] / self.J[0]
        self.sphere = abs(delta) < 1e-12
        d = np.asarray(env.dipole, dtype=float)
        self.axis = d / np.linalg.norm(d) if self.sphere else np.array([0.0, 0.0, 1.0])
        self.d_par = float(d @ self.axis)
        self.delta = delta
        self.gas = None
        if env.gas is not None:
            from ..physics.gas import GasModel
            from .collisions import Collider

            self.gas = _Moments(GasModel(env.gas, env.surface, tuple(env.inertia)))
            self.collider = Collider(env.gas, env.surface, env.rng)
        self.E = np.asarray(env.field, dtype=float)
        self.E_norm = float(np.linalg.norm(self.E))

    # -- rates, for the chunks' length -------------------------------------------------------
    def _rates(self):
        """(gas rate, radiation rate) of |L|, 1/spin-unit time, at the state."""
        w = self.w
        L = self.J * w
        rad = np.asarray(self.problem.system.radiation()(*w), dtype=float)
        g_rad = float(np.linalg.norm(self.J * rad)) / max(float(np.linalg.norm(L)), 1e-300)
        g_gas = 0.0
        if self.gas is not None:
            _, N, _ = self.gas(w * self.scale)
            Lp = self.inertia * w * self.scale
            # the drift sets the chunks: the diffusion's step is exact in distribution at any size
            # the moments allow (an Euler-Maruyama step of an Ornstein-Uhlenbeck process errs by gamma dt)
            g_gas = float(np.linalg.norm(N)) / float(np.linalg.norm(Lp)) / self.scale
        return g_gas, g_rad

    def go(self, t, secular):
        """Advance to the end of ``t``; None, or the reason the run stops."""
        end = float(t[-1])
        now = float(t[0])
        while self.j < t.size:
            check()
            g_gas, g_rad = self._rates()
            limit = ETA / max(g_gas + g_rad, 1e-300)
            nxt = float(t[self.j])
            dt = min(nxt - now, limit)
            if dt <= 0.0 or not math.isfinite(dt):
                return "the environment's chunk length fell to zero (a state outside the finite numbers)"
            if self.chunks >= MAX_CHUNKS:
                return (f"the gas and the radiation change the state so fast that the run needs more than "
                        f"{MAX_CHUNKS} chunks (by t = {now:.4g} spin units); shorten t_end")
            why = self._chunk(now, dt, secular)
            if why is not None:
                return why
            now = nxt if dt == nxt - now else now + dt
            if now >= nxt:
                self.omega[self.j], self.q_out[self.j] = self.w, self.q
                self.j += 1
        return None if now >= end else "stopped before the end"

    def _chunk(self, now: float, dt: float, secular):
        """Radiation by ``secular`` over [now, now + dt], then the gas and the field."""
        sub, e = spin_problem(self.problem.system, self.w, np.array([0.0, dt]), q0=self.q,
                              kinematics="quaternion")
        sol = secular(sub, self.rtol, self.atol)
        if not sol.success:
            return f"secular, at t = {now:.4g} (spin units): {sol.message}"
        self.nsteps += int(sol.stats.get("nsteps", 0))
        self.slow_error = max(self.slow_error, float(sol.stats.get("slow_error_estimate", 0.0)))
        if self.q_frame is None and sol.slow is not None:
            self.q_frame = np.asarray(sol.slow["q_frame"], dtype=float)
        w_old = self.w
        self.w = np.asarray(sol.omega[-1], dtype=float) * e
        self.q = R.normalize(sol.q[-1])
        self.chunks += 1
        if self.gas is not None:
            self._gas(dt)
        if self.E_norm > 0.0:
            why = self._field(w_old, dt)
            if why is not None:
                return why
        if not (np.all(np.isfinite(self.w)) and np.all(np.isfinite(self.q))):
            return "the state left the finite numbers"
        return None

    # -- the gas -------------------------------------------------------------------------------
    def _gas(self, dt: float) -> None:
        """The chunk's collisions (module docstring), applied to (w, q)."""
        from .collisions import chunk_exact

        col, scale = self.collider, self.scale
        omega = self.w * scale                                      # rad/s, body frame
        O = R.matrix_from_quat(self.q)
        L_body = self.inertia * omega
        L_world = O @ L_body
        Ln = float(np.linalg.norm(L_body))
        w_L = Ln / float(self.inertia[0])                          # the spin about L, rad/s
        prec = 0.0 if self.sphere else self.delta * float(self.w[2]) * scale     # delta omega3, rad/s
        dt_s = dt / scale
        s_bound, lam = col.bound(1.05 * Ln / float(self.inertia.min()))
        mean_candidates = lam * dt_s
        if mean_candidates <= EXACT_MAX:
            count = int(self.env.rng.poisson(mean_candidates))
            dLb, dLw, kept, bumped = chunk_exact(col.rng, omega, self.inertia, O, L_world / max(Ln, 1e-300), w_L, prec,
                                                 dt_s, count, *col.args, s_bound)
            self.exact_chunks += 1
            self.env.collisions += int(kept)
            self.env.candidates += count
        else:
            dLb, dLw = self._gauss(omega, O, L_body, w_L, prec, dt_s)
            self.gauss_chunks += 1
            self.expected_collisions += self.gas(omega)[0] * dt_s
        self.env.impulse += dLb
        self._reorient(L_body, L_world, L_body + dLb, L_world + dLw)

    def _moments(self, omega, precessing: bool):
        """(mean torque, impulses' second moment per unit time) at ``omega`` (rad/s, body frame);
        with ``precessing``, averaged over a quarter turn of a box's precession (its symmetry)."""
        if not precessing:
            _, N, Q = self.gas(omega)
            return N, Q
        Ns, Qs = [], []
        for psi in np.arange(4) * (math.pi / 8.0):
            Rz = _rot_z(psi)
            _, N, Q = self.gas.model.moments(Rz @ omega)
            Ns.append(Rz.T @ N)
            Qs.append(Rz.T @ Q @ Rz)
        return np.mean(Ns, axis=0), np.mean(Qs, axis=0)

    def _gauss(self, omega, O, L_body, w_L, prec, dt_s):
        """The chunk's many collisions as one Gaussian sum: (dL_body, dL_world).  Its mean is the
        drag at the chunk's midpoint (predicted by the drag at its start): second order in the
        chunk, where the drag at the start alone errs by ~ETA/2 of the change a chunk -- 1 % of |L|
        over the ~200 chunks a factor 8 of braking takes (a ramming body's drag falls with it)."""
        rng = self.env.rng
        precessing = abs(prec) * dt_s >= MANY_TURNS and self.env.surface.kind[0] == 0
        N, Q = self._moments(omega, precessing)
        N, _ = self._moments(omega + 0.5 * dt_s * N / self.inertia, precessing)
        dLb = rng.multivariate_normal(N * dt_s, Q * dt_s)
        Lh = L_body / np.linalg.norm(L_body)
        if w_L * dt_s >= MANY_TURNS:
            par = float(dLb @ Lh)
            perp = Q - np.outer(Q @ Lh, Lh) - np.outer(Lh, Lh @ Q) + float(Lh @ Q @ Lh) * np.outer(Lh, Lh)
            var = 0.5 * float(np.trace(perp)) * dt_s
            Lw = O @ Lh
            a = np.cross(Lw, [1.0, 0.0, 0.0] if abs(Lw[0]) < 0.9 else [0.0, 1.0, 0.0])
            a /= np.linalg.norm(a)
            b = np.cross(Lw, a)
            x, y = rng.standard_normal(2) * math.sqrt(var)
            return dLb, par * Lw + x * a + y * b
        return dLb, O @ dLb

    def _reorient(self, Lb_old, Lw_old, Lb_new, Lw_new) -> None:
        """The new state: Omega from L_body, and O_new = Q_w O Q_b^T (the smallest rotations
        taking the old L to the new one in each frame)."""
        Qb = R.quat_between(Lb_old, Lb_new)
        Qw = R.quat_between(Lw_old, Lw_new)
        self.q = R.normalize(R.multiply(R.multiply(Qw, self.q), R.conjugate(Qb)))
        self.w = Lb_new / self.inertia / self.scale

    # -- the field -------------------------------------------------------------------------------
    def _precession(self, w) -> float:
        """L's precession rate about E, rad per spin-unit time (signed, about +E)."""
        Lb = self.inertia * w * self.scale
        Ln = float(np.linalg.norm(Lb))
        return -self.d_par * float(self.axis @ Lb) / Ln * self.E_norm / Ln / self.scale

    def _field(self, w_old, dt: float):
        rate0, rate1 = self._precession(w_old), self._precession(self.w)
        spin = float(np.linalg.norm(self.inertia * self.w)) / float(self.inertia[0])        # spin units
        if abs(rate1) > FIELD_RATIO_MAX * spin:
            return (f"the field turns L at {abs(rate1) * self.scale:.3g} rad/s, not slow against the spin "
                    f"({spin * self.scale:.3g} rad/s: more than {FIELD_RATIO_MAX:g} of it), so its torque does not "
                    f"average over the spin; integrate in full (method taylor)")
        angle = 0.5 * (rate0 + rate1) * dt
        self.field_turn += angle
        self.q = R.normalize(R.multiply(R.quat_from_axis_angle(self.E / self.E_norm, angle), self.q))
        return None

    # -- what the run says -------------------------------------------------------------------------
    def stats(self) -> dict:
        """The run's statements: chunks, collisions, the field's turn of L, secular's slow error."""
        out = {"nsteps": self.nsteps, "chunks": self.chunks, "exact_chunks": self.exact_chunks,
               "gaussian_chunks": self.gauss_chunks, "chunk_change": ETA,
               "slow_error_estimate": self.slow_error + ETA * ETA, "phases_resolved": False,
               "field_turn_rad": self.field_turn, **self.env.stats()}
        if self.gauss_chunks:
            out["collisions_in_gaussian_chunks"] = float(self.expected_collisions)
        return out

    def slow_series(self) -> dict:
        """The slow geometry at each output: q_L (N, 4) (L moves: the gas and the field), and
        theta_L, phi_L, psi_L about it, in the frame of ``secular`` (q_frame)."""
        q_frame = self.q_frame if self.q_frame is not None else np.array([1.0, 0.0, 0.0, 0.0])
        n = self.omega.shape[0]
        q_L = np.full((n, 4), np.nan)
        ang = np.full((n, 3), np.nan)
        for i in range(n):
            if not np.all(np.isfinite(self.q_out[i])):
                continue
            Lw = R.world_from_body(self.q_out[i], self.J * self.omega[i])
            q_L[i] = R.quat_between((0.0, 0.0, 1.0), Lw)
            ang[i] = R.euler_zxz_from_quat(R.multiply(R.multiply(R.conjugate(q_L[i]), self.q_out[i]),
                                                      R.conjugate(q_frame)))
        return {"q_L": q_L, "q_frame": q_frame, "phi_L": np.unwrap(ang[:, 0]), "theta_L": ang[:, 1],
                "psi_L": np.unwrap(ang[:, 2])}
