"""Standalone peer of one ``spinviz simulate`` run: heyoka, no spinviz.

    python benchmarks/peer_heyoka_simulate.py PROBLEM.json --tol 1e-13 --out peer.npz

PROBLEM.json (written by ``spinviz bench --process``): model ("reduced" or "truncated"),
inertia (J1, J2, J3), dipole (a direction), omega0 (body frame, dimensionless (4.1)), q0
(w, x, y, z), t (dimensionless output times).  The equations are written here from the paper,
independently of spinviz's code: (2.2) with (2.3a), (2.3b) in vector form, or (2.5) with
Omega_dot solved by Cramer's rule; tau0 = 1 and a unit coupling, scaled to |omega(0)| = 1 (as
any careful user would, to keep heyoka's tolerance meaningful), and
q_dot = 1/2 q (x) (0, Omega).  Prints the steps and the integration time; writes t, omega
(dimensionless) and q.
"""

import argparse
import json
import math
import time

import heyoka as hy
import numpy as np


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def reduced(w, J, g):
    Jw = tuple(J[i] * w[i] for i in range(3))
    wd = tuple(-c / J[i] for i, c in enumerate(cross(w, Jw)))                    # (2.3a)
    Jwd = tuple(J[i] * wd[i] for i in range(3))
    a1, a2 = cross(wd, Jw), cross(w, Jwd)
    wdd = tuple(-(a1[i] + a2[i]) / J[i] for i in range(3))                        # (2.3b)
    ww = dot(w, w)
    gi = cross(g, tuple(ww * w[i] - wdd[i] for i in range(3)))
    h = tuple(gi[i] + dot(g, wd) * w[i] + 2.0 * dot(g, w) * wd[i] for i in range(3))
    torque = cross(g, h)                                                          # (2.2)
    return tuple(wd[i] + torque[i] / J[i] for i in range(3))


def truncated(w, J, g):
    """(2.5): J wdot + w x J w = -|g x w|^2 w - (g . (w x wdot)) g, i.e. M wdot = r with
    M = J + g (g x w)^T; solved by Cramer's rule."""
    v = cross(g, w)
    r = tuple(-c - dot(v, v) * w[i] for i, c in enumerate(cross(w, tuple(J[i] * w[i] for i in range(3)))))
    M = [[(J[i] if i == j else 0.0) + g[i] * v[j] for j in range(3)] for i in range(3)]

    def det(m):
        return (m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
                + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]))

    D = det(M)
    out = []
    for k in range(3):
        Mk = [[r[i] if j == k else M[i][j] for j in range(3)] for i in range(3)]
        out.append(det(Mk) / D)
    return tuple(out)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("problem")
    ap.add_argument("--tol", type=float, default=1e-13)
    ap.add_argument("--out", default=None)
    a = ap.parse_args()
    t0 = time.perf_counter()
    with open(a.problem) as f:
        p = json.load(f)
    J = tuple(float(x) / p["inertia"][0] for x in p["inertia"])
    w0 = np.array(p["omega0"], dtype=float)
    eps = float(np.linalg.norm(w0))                                   # tau0 |Omega0|
    d = np.array(p["dipole"], dtype=float)
    g = tuple(float(x) for x in d / np.linalg.norm(d) * math.sqrt(eps))   # coupling where |omega(0)| = 1
    w = hy.make_vars("w1", "w2", "w3")
    q = hy.make_vars("q0", "q1", "q2", "q3")
    wdot = (reduced if p["model"] == "reduced" else truncated)(w, J, g)
    rhs = [(w[i], wdot[i]) for i in range(3)]
    rhs += [(q[0], -0.5 * (q[1] * w[0] + q[2] * w[1] + q[3] * w[2])),
            (q[1], 0.5 * (q[0] * w[0] + q[2] * w[2] - q[3] * w[1])),
            (q[2], 0.5 * (q[0] * w[1] + q[3] * w[0] - q[1] * w[2])),
            (q[3], 0.5 * (q[0] * w[2] + q[1] * w[1] - q[2] * w[0]))]
    ta = hy.taylor_adaptive(rhs, np.concatenate([w0 / eps, p["q0"]]), tol=a.tol)
    t_build = time.perf_counter()
    t = np.array(p["t"], dtype=float)
    res = ta.propagate_grid(t * eps)
    t_done = time.perf_counter()
    y = np.asarray(res[-1])
    if a.out:
        np.savez(a.out, t=t, omega=y[:, :3] * eps, q=y[:, 3:] / np.linalg.norm(y[:, 3:], axis=1)[:, None])
    print(f"tol {a.tol:g}: {res[3]} steps, integration {1e3 * (t_done - t_build):.2f} ms, build {t_build - t0:.3f} s")


if __name__ == "__main__":
    main()
