"""The atlas's dimensionless system against the full physical-unit equation.

    spinviz atlas evidence physical [--members 4] [--tau-end 1e10] [--json]

The atlas integrates (4.2)-(4.4) -- and, for the truncated model, spinviz's analogue of them
(``physics.equations.symmetric_truncated_rate``) -- in the dimensionless variables (4.1),
in heyoka's batch mode.  Here the same starts are integrated the other way round: a CGS
body (g cm^2, statC cm) with the same delta and chi, the initial Omega = omega0 / tau0 in
rad/s and the output times t = tau tau0 in seconds, through ``spinviz.simulate`` -- the
general equation (2.2)+(2.3) (or (2.5)) for any inertia and dipole, the driver's own unit
conversion, one scalar Taylor integrator per run.  Nothing is shared but the classifier,
and each run's end state (omega at tau_end) and label are compared.

The CGS body: I1 = 2e-26 g cm^2 (a 100 nm DAST cube's order), d such that tau0 = 1e-20 s, so
Omega0 = omega0 / tau0 ~ 1e18 rad/s -- far from the dimensionless numbers, as a real
particle's are.
"""

from __future__ import annotations

import math
import time

import numpy as np

from ... import units as U
from ...inputs.atlas_spec import Settings, directions
from ...regimes.engine import classify as C
from ...regimes.engine.runs import integrate_many

I1_CGS = 2e-26
TAU0_S = 1e-20

# The four points where docs/atlas.md disagrees with the paper, and one point per truncated type.
POINTS = [
    ("type 1 where alpha < -1", "reduced", -0.6, math.degrees(0.3)),
    ("type 3 below delta = -1/2", "reduced", -0.6, 77.0),
    ("type 4 only up to beta = -3/4: captured into 5", "reduced", 0.5, 45.0),
    ("type 5 far outside (4.43)", "reduced", 0.2, 70.0),
    ("type 5 inside (4.43): (4.42) off", "reduced", 0.8, math.degrees(1.2)),
    ("T4", "truncated", 0.5, 22.0),
    ("T2", "truncated", -0.6, 60.0),
    ("TF", "truncated", 0.8, math.degrees(1.2)),
]


def cgs_body(delta: float, chi: float):
    """A symmetric CGS body with this (delta, chi) and tau0 = ``TAU0_S``: d = sqrt(3 I1 c^3 tau0 / 2) (3.8)."""
    from ...physics.bodies import Body

    d = math.sqrt(1.5 * I1_CGS * U.C_LIGHT**3 * TAU0_S)
    return Body("cross-check body", "cgs", (I1_CGS, I1_CGS, (1.0 - delta) * I1_CGS),
                (d * math.sin(chi), 0.0, d * math.cos(chi)))


def physical_run(model: str, delta: float, chi: float, omega0, tau, rtol: float):
    """omega(tau) (N, 3), dimensionless, from ``simulate`` on the CGS body (4.1 undone, then redone)."""
    from ...driver import simulate

    body = cgs_body(delta, chi)
    assert abs(body.tau0 / TAU0_S - 1.0) < 1e-12
    tr = simulate(body, model, np.asarray(omega0) / body.tau0, t_eval=np.asarray(tau) * body.tau0, method="taylor",
                  kinematics="none", rtol=rtol, atol=rtol)
    return tr.omega * body.tau0


def compare(points=POINTS, members: int = 4, omega: float = 0.1, tau_end: float = 1e10, rtol: float = 1e-10,
            seed: int = 1, progress=None) -> list[dict]:
    """Per point and member: the relative difference of the end states, both labels.
    ``members`` and ``tau_end`` are checked first (``inputs.options.EvidenceRequest``; the work against the cap by
    ``evidence.run``)."""
    from ...inputs.options import EvidenceRequest

    EvidenceRequest(members=members, tau_end=tau_end, tau_max=1e16)
    say = progress or (lambda m: None)
    st = Settings(tau_end=tau_end, rtol=rtol)
    tau = st.times()
    rows = []
    for name, model, d, cdeg in points:
        chi = math.radians(cdeg)
        w0 = directions(members, seed) * (omega if model == "reduced" else min(omega, 0.04))
        t0 = time.perf_counter()
        atlas_runs = integrate_many(model, [(d, chi)] * members, list(w0), st)
        t1 = time.perf_counter()
        for k in range(members):
            say(f"{name}: member {k}")
            a = atlas_runs[k].omega
            b = physical_run(model, d, chi, w0[k], tau, rtol)
            la = C.classify(tau, a, d, chi, model, st.window).label
            lb = C.classify(tau, b, d, chi, model, st.window).label
            end = float(np.linalg.norm(a[-1] - b[-1]) / np.linalg.norm(b[-1]))
            amp_a, amp_b = np.linalg.norm(a[-1]) * math.sqrt(tau[-1]), np.linalg.norm(b[-1]) * math.sqrt(tau[-1])
            rows.append({"point": name, "model": model, "delta": d, "chi_deg": cdeg, "member": k, "label_atlas": la,
                         "label_physical": lb, "end_rel_diff": end, "amp_atlas": amp_a, "amp_physical": amp_b,
                         "atlas_s": (t1 - t0) / members})
    return rows


def format_table(rows: list[dict]) -> str:
    """The comparison's rows as a table for people."""
    lines = ["| point | model | delta | chi | member | label (atlas) | label (simulate, CGS) | |omega| sqrt(tau) at the end | "
             "end state, relative difference |", "|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['point']} | {r['model']} | {r['delta']:g} | {r['chi_deg']:.1f} | {r['member']} | "
                     f"{r['label_atlas']} | {r['label_physical']} | {r['amp_atlas']:.6g} / {r['amp_physical']:.6g} | "
                     f"{r['end_rel_diff']:.1e} |")
    same = sum(r["label_atlas"] == r["label_physical"] for r in rows)
    worst = max(r["end_rel_diff"] for r in rows)
    lines += ["", f"same label in {same} of {len(rows)} runs; largest relative difference of the end states {worst:.1e}"]
    return "\n".join(lines)

