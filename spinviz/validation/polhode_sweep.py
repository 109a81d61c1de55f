"""`polhode` against full integration on random asymmetric bodies: are its stated errors bounds?

Each case draws a box of edges in [0.5, 1.5] (moments J = (b^2 + c^2, a^2 + c^2, a^2 + b^2),
scaled to J1 = 1), a random dipole direction, a random spin direction (every 4th close to the
separatrix, so that the run passes it in full), a model, eps = tau0 |Omega0| in ``EPS``, a
horizon of 0.3, 1 or 3 braking times (1/eps in spin units) and a random start orientation;
runs `polhode` and `taylor` at rtol = atol = 1e-13 on the same spin-unit problem, and compares

* |L| and the energy (largest relative error over the samples) with ``slow_error_estimate``;
* the direction of L in space (largest angle) with ``L_direction_uncertainty_rad``;
* the orientation (largest misorientation) with ``phase_error_rad``.

``run`` returns one row per case; the statements hold where every ratio measured/stated <= 1.
"""

from __future__ import annotations

import math
import time

import numpy as np

EPS = (1e-3, 1e-4, 1e-5)
HORIZONS_T = (0.3, 1.0, 3.0)
REF_TOL = 1e-13


def random_body(rng: np.random.Generator) -> tuple[tuple, np.ndarray]:
    """(J, unit dipole): a random box's moments (J1 = 1) and a random dipole direction."""
    a, b, c = rng.uniform(0.5, 1.5, size=3)
    J = np.array([b * b + c * c, a * a + c * c, a * a + b * b])
    d = rng.normal(size=3)
    return tuple(J / J[0]), d / np.linalg.norm(d)


def near_separatrix(J, rng: np.random.Generator, share: float) -> np.ndarray:
    """A unit spin direction whose polhode lies ``share`` of the way from the separatrix to an
    extreme axis (share small: close to the separatrix)."""
    J = np.asarray(J)
    s, m, l = np.argsort(J)
    c = l if rng.random() < 0.5 else s
    # omega in the (c, m) plane: D = (J_c^2 x + J_m^2 y) / (J_c x + J_m y) between J_m and J_c
    D = J[m] + share * (J[c] - J[m])
    r = (J[c] ** 2 - D * J[c]) / (D * J[m] - J[m] ** 2)
    w = np.zeros(3)
    w[c], w[m] = 1.0, math.sqrt(r)
    o = 3 - c - m
    w[o] = 0.05 * rng.normal()
    return w / np.linalg.norm(w)


def draw(rng: np.random.Generator, k: int) -> dict:
    """The k-th random case of a seed's stream."""
    J, d = random_body(rng)
    if k % 4 == 3:
        w = near_separatrix(J, rng, float(rng.uniform(0.005, 0.03)))
    else:
        w = rng.normal(size=3)
        w /= np.linalg.norm(w)
    q0 = rng.normal(size=4)
    return {"J": J, "d": d, "w": w, "model": str(rng.choice(["reduced", "truncated"])),
            "eps": float(rng.choice(EPS)), "n_T": float(rng.choice(HORIZONS_T)), "q0": q0 / np.linalg.norm(q0)}


def run_case(case: dict, samples: int = 21) -> dict:
    """One comparison (spin units)."""
    from .. import rotations as R
    from ..integrators.base import Problem
    from ..integrators.polhode import solve_polhode
    from ..integrators.taylor import solve_taylor
    from ..physics.models import System

    eps = case["eps"]
    s = System(case["model"], case["J"], tuple(math.sqrt(eps) * np.asarray(case["d"])))
    t = np.linspace(0.0, case["n_T"] / eps, samples)
    pr = Problem(s, np.asarray(case["w"]), t, q0=case["q0"])
    t0 = time.perf_counter()
    a = solve_polhode(pr, 1e-10, 1e-12)
    t1 = time.perf_counter()
    b = solve_taylor(pr, REF_TOL, REF_TOL)
    t2 = time.perf_counter()
    row = {k: case[k] for k in ("model", "eps", "n_T")}
    row.update(J=[float(x) for x in case["J"]], success=bool(a.success), message=a.message,
               seconds_polhode=t1 - t0, seconds_taylor=t2 - t1)
    if not a.success:
        return row
    J = np.asarray(case["J"])

    def inv(w):
        return np.sqrt(np.sum((J * w) ** 2, axis=-1)), np.sum(J * w * w, axis=-1)

    La, Ea = inv(a.omega)
    Lb, Eb = inv(b.omega)
    slow = float(max(np.max(np.abs(La / Lb - 1.0)), np.max(np.abs(Ea / Eb - 1.0))))
    Lw_a, Lw_b = R.world_from_body(a.q, J * a.omega), R.world_from_body(b.q, J * b.omega)
    L_err = float(np.max(R.angle_between(Lw_a, Lw_b)))
    q_err = float(np.max(R.misorientation(a.q, b.q)))
    st = a.stats
    row.update(slow_err=slow, slow_stated=st["slow_error_estimate"], slow_ratio=slow / (st["slow_error_estimate"] + 1e-11),
               L_err=L_err, L_stated=st["L_direction_uncertainty_rad"],
               L_ratio=L_err / (st["L_direction_uncertainty_rad"] + 1e-11),
               q_err=q_err, q_stated=st["phase_error_rad"], q_ratio=q_err / (st["phase_error_rad"] + 1e-10),
               crossings=len(st["separatrix_crossings"]), resonances=len(st["resonances"]),
               full_turns=st["full_turns"], resolved=bool(st["phases_resolved"]),
               turns=float(t[-1] / (2.0 * math.pi)), terms=dict(st["error_terms"]))
    return row


def run(seeds, runs: int = 24, progress=None) -> list[dict]:
    """``runs`` cases for each seed; ``progress(row)`` after each."""
    rows = []
    for seed in seeds:
        rng = np.random.default_rng(seed)
        for k in range(runs):
            r = run_case(draw(rng, k))
            r["seed"], r["k"] = seed, k
            rows.append(r)
            if progress:
                progress(r)
    return rows


def row_line(r: dict) -> str:
    """One case in one line: its body and run, each measured error against the stated one."""
    head = (f"seed {r['seed']}/{r['k']} {r['model'][:3]} J=({', '.join(f'{x:.2f}' for x in r['J'])}) "
            f"eps={r['eps']:.0e} {r['n_T']}T")
    if not r["success"]:
        return f"{head}: refused: {r['message']}"
    return (f"{head} x{r['crossings']} res{r['resonances']}: slow {r['slow_err']:.1e}/{r['slow_stated']:.1e} "
            f"(x{r['slow_ratio']:.2f})  L {r['L_err']:.1e}/{r['L_stated']:.1e} (x{r['L_ratio']:.2f})  "
            f"q {r['q_err']:.1e}/{r['q_stated']:.1e} (x{r['q_ratio']:.2f})  {r['seconds_polhode']:.1f}s/"
            f"{r['seconds_taylor']:.1f}s")
