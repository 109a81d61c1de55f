"""Standalone baseline of one ``spinviz simulate`` run: scipy's DOP853 on a plain NumPy
right-hand side, no spinviz -- what a user would write.

    python benchmarks/peer_scipy_simulate.py PROBLEM.json --rtol 1e-10 --out base.npz

Same PROBLEM.json as ``peer_heyoka_simulate.py``; (2.2)+(2.3) with np.cross, (2.5) with a
3x3 solve; scaled to |omega(0)| = 1, atol = rtol / 100.
"""

import argparse
import json
import math
import time

import numpy as np
from scipy.integrate import solve_ivp


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("problem")
    ap.add_argument("--rtol", type=float, default=1e-10)
    ap.add_argument("--out", default=None)
    a = ap.parse_args()
    with open(a.problem) as f:
        p = json.load(f)
    J = np.array(p["inertia"], dtype=float) / p["inertia"][0]
    w0 = np.array(p["omega0"], dtype=float)
    eps = float(np.linalg.norm(w0))
    d = np.array(p["dipole"], dtype=float)
    g = d / np.linalg.norm(d) * math.sqrt(eps)
    model = p["model"]

    def f(t, y):
        w, q = y[:3], y[3:]
        Jw = J * w
        free = -np.cross(w, Jw) / J
        if model == "reduced":
            wdd = -(np.cross(free, Jw) + np.cross(w, J * free)) / J
            torque = np.cross(g, np.cross(g, (w @ w) * w - wdd) + (g @ free) * w + 2.0 * (g @ w) * free)
            wdot = free + torque / J
        else:
            v = np.cross(g, w)
            wdot = np.linalg.solve(np.diag(J) + np.outer(g, v), -np.cross(w, Jw) - (v @ v) * w)
        qdot = 0.5 * np.array([-q[1:] @ w, *(q[0] * w + np.cross(q[1:], w))])
        return np.concatenate([wdot, qdot])

    t = np.array(p["t"], dtype=float)
    t0 = time.perf_counter()
    res = solve_ivp(f, (0.0, t[-1] * eps), np.concatenate([w0 / eps, p["q0"]]), method="DOP853", t_eval=t * eps,
                    rtol=a.rtol, atol=a.rtol * 1e-2)
    dt = time.perf_counter() - t0
    y = res.y.T
    if a.out:
        np.savez(a.out, t=t, omega=y[:, :3] * eps, q=y[:, 3:] / np.linalg.norm(y[:, 3:], axis=1)[:, None])
    print(f"rtol {a.rtol:g}: {res.nfev} evaluations, integration {dt:.3f} s")


if __name__ == "__main__":
    main()
