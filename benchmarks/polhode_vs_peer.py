"""``polhode`` against brute force on the same run: the standalone heyoka peer
(``peer_heyoka_simulate.py``, no spinviz) integrating every turn, side by side in one run.

    python benchmarks/polhode_vs_peer.py [--eps 1e-6] [--horizons 1,10,100] [--model reduced] [--json OUT]

The body is the DAST 100 x 80 x 60 nm box in the units of (4.1) (J = 1 : 1.36 : 1.64, the
crystal's dipole 35 deg from a in the a-c plane), spun at tau0 |Omega0| = eps along (0, 1, 1)
(as the scene dast_box.toml), over each horizon in braking times 1/(tau0 |Omega0|^2).  Both
are timed as whole processes (interpreter, imports, compilation from cache, the run): the
peer at tol 1e-13, spinviz's polhode at its default rtol 1e-10.  Printed per horizon: the
turns, each one's seconds, the ratio peer / polhode, and the largest relative difference of
|L| and of the energy between the two (the peer taken as the reference).
"""

import argparse
import json
import math
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
J = (1.0, 1.36, 1.64)
D = (math.cos(math.radians(35.0)), 0.0, math.sin(math.radians(35.0)))

SPINVIZ = """
import json, sys, numpy as np
from spinviz.physics import bodies as B
from spinviz.driver import simulate
p = json.load(open(sys.argv[1]))
body = B.custom(tuple(p["inertia"]), tuple(p["dipole"]), units="dimensionless")
tr = simulate(body, p["model"], p["omega0"], t_eval=p["t"], q0=p["q0"], method="polhode")
np.savez(sys.argv[2], t=tr.t, omega=tr.omega, q=tr.q)
print(tr.stats["nsteps"], tr.stats["full_turns"])
"""


def timed(cmd):
    t0 = time.perf_counter()
    r = subprocess.run(cmd, capture_output=True, text=True)
    dt = time.perf_counter() - t0
    if r.returncode != 0:
        raise SystemExit(f"{' '.join(cmd[:2])} failed: {r.stderr.strip().splitlines()[-1:]}")
    return dt, r.stdout.strip()


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--eps", type=float, default=1e-6)
    ap.add_argument("--horizons", default="1,10,100")
    ap.add_argument("--model", default="reduced")
    ap.add_argument("--json", default=None)
    a = ap.parse_args()
    w = np.array([0.0, 1.0, 1.0]) / math.sqrt(2.0) * a.eps
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for n_T in (float(x) for x in a.horizons.split(",")):
            t = np.linspace(0.0, n_T / a.eps**2, 21).tolist()
            prob = {"model": a.model, "inertia": J, "dipole": D, "omega0": w.tolist(), "q0": [1.0, 0.0, 0.0, 0.0], "t": t}
            path = os.path.join(tmp, "problem.json")
            with open(path, "w") as f:
                json.dump(prob, f)
            peer_out, ours_out = os.path.join(tmp, "peer.npz"), os.path.join(tmp, "ours.npz")
            t_peer, _ = timed([sys.executable, os.path.join(HERE, "peer_heyoka_simulate.py"), path, "--tol", "1e-13",
                               "--out", peer_out])
            t_ours, _ = timed([sys.executable, "-c", SPINVIZ, path, ours_out])
            P, O = np.load(peer_out), np.load(ours_out)
            Jv = np.asarray(J)
            L = [np.sqrt(np.sum((Jv * x["omega"]) ** 2, axis=-1)) for x in (P, O)]
            E = [np.sum(Jv * x["omega"] ** 2, axis=-1) for x in (P, O)]
            turns = float(np.trapezoid(np.linalg.norm(P["omega"], axis=-1), P["t"]) / (2.0 * math.pi))
            row = {"braking_times": n_T, "turns": turns, "peer_s": t_peer, "polhode_s": t_ours,
                   "ratio": t_peer / t_ours, "dL": float(np.max(np.abs(L[1] / L[0] - 1.0))),
                   "dE": float(np.max(np.abs(E[1] / E[0] - 1.0)))}
            rows.append(row)
            print(f"{n_T:g} T ({turns:.3g} turns): peer {t_peer:.2f} s, polhode {t_ours:.2f} s, ratio {row['ratio']:.3g}; "
                  f"|L| {row['dL']:.1e}, E {row['dE']:.1e}", flush=True)
    if a.json:
        with open(a.json, "w") as f:
            json.dump(rows, f, indent=1)


if __name__ == "__main__":
    main()
