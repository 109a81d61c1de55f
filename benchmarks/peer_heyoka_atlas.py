"""Standalone peer of one atlas cell: heyoka's batch integrator on both cores, no spinviz.

    python benchmarks/peer_heyoka_atlas.py --runs 2048 --tau-end 1e10 --out peer.npz [--threads 2]

The same work as ``spinviz atlas`` does for a one-cell spec (by default delta = 0.3,
chi = 41.25 deg, |omega0| = 0.04, starts uniform on the sphere from seed 12, tol 1e-8, 20
samples a decade from tau = 1e-2 to --tau-end), written from the paper independently of
spinviz's code: the dimensionless symmetric-top system (4.2)-(4.4), integrated in the scaled
variable u = omega sqrt(1 + tau/T) / |omega0| (T = 1/|omega0|^2) with time s = |omega0| tau, so
that heyoka's tolerance stays relative as omega ~ 1/sqrt(tau) falls; output on the same log
grid.  The batches (width heyoka.recommended_simd_size()) are spread over --threads threads by
``ensemble_propagate_grid_batch``.  It writes omega (runs, samples, 3) and tau; labels are
compared afterwards with spinviz's classifier (not timed here).  Every run is integrated to
--tau-end: brute force, whose cost grows as sqrt(tau_end).
"""

import argparse
import math
import time

import heyoka as hy
import numpy as np


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--runs", type=int, default=2048)
    ap.add_argument("--tau-end", type=float, default=1e10)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--tol", type=float, default=1e-8)
    ap.add_argument("--delta", type=float, default=0.3)
    ap.add_argument("--chi-deg", type=float, default=41.25)
    ap.add_argument("--omega", type=float, default=0.04)
    ap.add_argument("--seed", type=int, default=12)
    ap.add_argument("--out", default=None)
    a = ap.parse_args()
    t_start = time.perf_counter()
    delta, chi, w0 = a.delta, math.radians(a.chi_deg), a.omega
    n1, n3 = math.sin(chi), math.cos(chi)
    v = np.random.default_rng(a.seed).normal(size=(a.runs, 3))
    starts = v / np.linalg.norm(v, axis=1, keepdims=True)          # u(0) = omega(0) / |omega0|
    per = 20
    n = int(round(per * math.log10(a.tau_end / 1e-2))) + 1
    tau = np.concatenate([[0.0], np.logspace(-2, math.log10(a.tau_end), n)])
    s = tau * w0                                                     # time in units of 1/|omega0|

    # (4.2)-(4.4) in omega = w0 u / sigma, sigma = sqrt(1 + w0 s): d/ds = (1/w0) d/dtau
    u1, u2, u3 = hy.make_vars("u1", "u2", "u3")
    inv = (1.0 + w0 * hy.time) ** -0.5                               # 1 / sigma
    w1, w2, w3 = u1 * inv, u2 * inv, u3 * inv                        # omega / w0
    W2 = w1 * w1 + w2 * w2 + w3 * w3
    wa = W2 + delta * (delta - 2.0) * w3 * w3
    wb = W2 + delta * (2.0 * w1 * w1 - w2 * w2)
    wc = W2 + delta * (delta + 1.0) * w3 * w3
    k = w0                                                           # the cubic terms carry one more w0
    f1 = delta * w2 * w3 - k * (n3 * n3 * wa * w1 - n1 * n3 * wb * w3)
    f2 = -delta * w1 * w3 - k * (n1 * n1 * wc + n3 * n3 * wa - 3.0 * n1 * n3 * delta * w1 * w3) * w2
    f3 = k * (n1 * n3 * wa * w1 - n1 * n1 * wb * w3) / (1.0 - delta)
    drift = 0.5 * w0 * inv * inv
    sys_ = [(u1, f1 / inv + drift * u1), (u2, f2 / inv + drift * u2), (u3, f3 / inv + drift * u3)]
    B = hy.recommended_simd_size()
    nb = math.ceil(a.runs / B)
    padded = np.concatenate([starts, np.repeat(starts[:1], nb * B - a.runs, axis=0)])
    ta = hy.taylor_adaptive_batch(sys_, np.zeros((3, B)), tol=a.tol)
    grid = s                                                         # splatted to every lane by heyoka

    def gen(tc, i):
        tc.set_time(np.zeros(B))
        tc.state[:] = padded[i * B:(i + 1) * B].T
        return tc

    t_int = time.perf_counter()
    res = hy.ensemble_propagate_grid_batch(ta, grid, nb, gen, algorithm="thread", max_workers=a.threads)
    t_done = time.perf_counter()
    out = np.empty((nb * B, len(tau), 3))
    for i, r in enumerate(res):
        states = np.asarray(r[-1])                                   # (samples, 3, B)
        out[i * B:(i + 1) * B] = np.transpose(states, (2, 0, 1))
    sig = np.sqrt(1.0 + w0 * s)
    omega = out[:a.runs] * (w0 / sig)[None, :, None]
    if a.out:
        np.savez(a.out, tau=tau, omega=omega)
    print(f"{a.runs} runs to tau {a.tau_end:g}, batch {B}, {a.threads} threads: integration {t_done - t_int:.3f} s "
          f"({1e3 * (t_done - t_int) / a.runs:.2f} ms a run), build {t_int - t_start:.3f} s")


if __name__ == "__main__":
    main()
