"""The hand-over engine's averaged stage: (LV), the Lotka-Volterra flow of the scaled amplitudes
A = omega_perp^2 tau, B = omega3^2 tau in s = ln tau (``physics.averaged``), carried from each
handed-over run's averaged state to tau_end, one run per lane of heyoka's batch integrator
(``handover_engine``, step 2)."""

from __future__ import annotations

import math

import numpy as np

from ...integrators import cache

LV_TOL = 1e-12              # Taylor tolerance of the averaged stage (on ln A, ln B)
_LV: dict = {}              # (LV)'s built integrators of this process, by batch width


def lv_template(batch: int):
    """heyoka's batch integrator of (LV) in (ln A, ln B) against sigma = s - s_h, (P, Q, R, S)
    in par[0..3] per lane (built once per process, kept in spinviz's integrator cache)."""
    import heyoka as hy

    key = ("lv", batch)
    ta = _LV.get(key)
    if ta is None:
        la, lb = hy.make_vars("lnA", "lnB")
        A, B = hy.exp(la), hy.exp(lb)
        sys_ = [(la, 1.0 - 2.0 * (hy.par[0] * A + hy.par[1] * B)), (lb, 1.0 - 2.0 * (hy.par[2] * A + hy.par[3] * B))]
        digest = cache.digest(hy.__version__, "lotka-volterra", repr(LV_TOL), str(batch), str(sys_))
        ta = cache.load(digest)
        if ta is None:
            ta = hy.taylor_adaptive_batch(sys_, np.zeros((2, batch)), pars=np.zeros((4, batch)), tol=LV_TOL)
            cache.store(digest, ta)
        _LV[key] = ta
    return ta


def averaged_stage(flows: list, tau: np.ndarray, handed: list, omega_h, mu_limit: float) -> list[dict]:
    """(LV) from each handed-over run's averaged state at its hand-over sample ``handed[i]``
    (an index into the output grid ``tau``) to the grid's end, one run per lane of heyoka's
    batch integrator (a run's numbers never depend on the others').  Per run a dict: ``idx``
    (grid indices from the hand-over on), ``lnA``, ``lnB`` there, ``sign_b``, ``phase_h``,
    ``mu_max`` along it, ``mu2_int`` (int mu^2 d ln tau along it, trapezoid rule on the samples)
    and ``tau_back`` (where mu first exceeds ``mu_limit``; inf if never)."""
    from ...integrators.taylor import width

    out = []
    for i, f in enumerate(flows):
        zb, w3b = f.to_averaged(omega_h[i][0] + 1j * omega_h[i][1], omega_h[i][2])
        idx = np.arange(handed[i], len(tau))
        t_h = float(tau[handed[i]])
        out.append({"idx": idx, "sign_b": 1.0 if w3b >= 0.0 else -1.0, "phase_h": float(np.angle(zb)),
                    "y0": (math.log(max(abs(zb) ** 2 * t_h, 1e-300)), math.log(max(w3b * w3b * t_h, 1e-300))),
                    "sigma": np.log(tau[idx] / t_h)})
    n = width()
    ta = cache.working(lv_template(n)) if flows else None
    for a in range(0, len(flows), n):
        part = list(range(a, min(a + n, len(flows))))
        _lv_lanes(ta, [flows[i] for i in part], [out[i] for i in part], n)
    for f, r in zip(flows, out):
        mu = f.small_parameter_scaled(np.exp(r["lnA"]), np.exp(r["lnB"]), np.log(tau[r["idx"]]))
        over = np.flatnonzero(mu > mu_limit)
        r["mu_max"] = float(np.max(mu))
        r["mu2_int"] = float(np.sum(0.5 * (mu[1:] ** 2 + mu[:-1] ** 2) * np.diff(np.log(tau[r["idx"]]))))
        r["tau_back"] = float(tau[r["idx"][over[0]]]) if over.size else math.inf
    return out


def _lv_lanes(ta, flows: list, runs: list, n: int) -> None:
    """One batch of (LV) runs in the integrator ``ta``: each lane on its own grid sigma (padded
    past its end)."""
    M = max(len(r["sigma"]) for r in runs)
    grid = np.zeros((M, n))
    state, pars = np.zeros((2, n)), np.zeros((4, n))
    for j in range(n):
        if j < len(runs):
            sig = runs[j]["sigma"]
            state[:, j] = runs[j]["y0"]
            pars[:, j] = [flows[j].P, flows[j].Q, flows[j].R, flows[j].S]
        else:
            sig = np.zeros(1)
        end = float(sig[-1])
        grid[:, j] = np.concatenate([sig, end + max(abs(end), 1.0) * 1e-9 * np.arange(1, M - len(sig) + 1)])
    ta.set_time(np.zeros(n))
    ta.state[:] = state
    ta.pars[:] = pars
    _, res = ta.propagate_grid(grid)
    res = np.asarray(res)
    for j, r in enumerate(runs):
        k = len(r["sigma"])
        r["lnA"], r["lnB"] = res[:k, 0, j].copy(), res[:k, 1, j].copy()
