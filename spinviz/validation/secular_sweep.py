"""`secular` against full integration on random symmetric tops: are its stated errors bounds?

    spinviz check --sweep [--seeds 1-9] [--runs 40] [--json]

Each run draws delta from the paper's range, chi uniform in [0.1, 1.45] rad, a random spin
direction (every 7th near the axis, omega_perp = 1e-3 omega3), eps = tau0 |Omega0| = 1e-4 or
3e-5, a horizon of 0.3, 1 or 3 T and a random start orientation, runs `secular` with the
resonance refusal lifted (so that the statements are tested through resonances too) and
`taylor` at rtol 1e-12, and compares the orientation (largest misorientation) with
``stats["phase_error_rad"]`` and the slow variables (|d omega_perp| + |d omega3|, relative to
|Omega0|) with ``stats["slow_error_estimate"]``.  The command prints one line per run (on
stderr) and a summary table: the largest measured/stated ratios must stay below 1 (``passed``).
"""

from __future__ import annotations

import math

import numpy as np

DELTAS = (0.01, 0.02, 0.05, -0.03, 0.1, -0.1, 0.2, 0.3, -0.3, 0.5, -0.6, 0.8, -0.9)


def draw(rng: np.random.Generator, k: int) -> dict:
    """The k-th random case of a seed's stream."""
    d = float(rng.choice(DELTAS))
    chi = float(rng.uniform(0.1, 1.45))
    v = rng.normal(size=3)
    v /= np.linalg.norm(v)
    if k % 7 == 0:
        v = np.array([1e-3, 0.0, rng.choice([-1.0, 1.0])])
        v /= np.linalg.norm(v)
    eps = float(rng.choice([1e-4, 3e-5]))
    n_T = float(rng.choice([0.3, 1.0, 3.0]))
    q0 = rng.normal(size=4)
    return {"delta": d, "chi": chi, "w_dir": v, "eps": eps, "n_T": n_T, "q0": q0 / np.linalg.norm(q0)}


def run_case(case: dict) -> dict:
    """One comparison; the resonance refusal of secular is lifted for it."""
    import spinviz
    from spinviz.integrators import secular

    from .checks import RTOL, secular_errors

    v, eps = case["w_dir"], case["eps"]
    T = 1.0 / (eps**2 * max(math.hypot(v[0], v[1]), 0.3) ** 2)
    body = spinviz.symmetric_top(case["delta"], case["chi"])
    kw = dict(t_end=case["n_T"] * T, samples=21, q0=case["q0"])
    saved, secular.L_TOL = secular.L_TOL, 1.0
    try:
        a = spinviz.simulate(body, "reduced", v * eps, method="secular", **kw)
    finally:
        secular.L_TOL = saved
    b = spinviz.simulate(body, "reduced", v * eps, method="taylor", rtol=RTOL, atol=1e-14, **kw)
    slow, q_err, ref_err = secular_errors(a, b, eps)
    st = a.stats
    return {"delta": case["delta"], "chi": case["chi"], "eps": eps, "n_T": case["n_T"], "w3": float(v[2]),
            "q_err": q_err, "q_stated": st["phase_error_rad"], "q_ratio": q_err / (st["phase_error_rad"] + ref_err),
            "slow_err": slow, "slow_stated": st["slow_error_estimate"],
            "slow_ratio": slow / (st["slow_error_estimate"] + 1e-9),   # 1e-9: the reference's tolerance
            "resolved": bool(a.phase_resolved), "switches": int(st.get("switches", 0)),
            "resonances": len(st.get("resonances", []))}


def run(seeds, runs: int = 40, progress=None) -> list[dict]:
    """``runs`` cases of each seed (``draw``, ``run_case``), each row with its "seed";
    ``progress(row)`` is called after each.  ``seeds`` (a range or a list of non-negative
    whole numbers) and ``runs`` are checked first (``inputs.options.SweepRequest``: the work
    they mean within the cap)."""
    from ..inputs.options import SweepRequest

    seeds = SweepRequest(seeds=seeds, runs=runs).seeds
    rows = []
    for seed in seeds:
        rng = np.random.default_rng(seed)
        for k in range(runs):
            r = run_case(draw(rng, k))
            r["seed"] = seed
            rows.append(r)
            if progress:
                progress(r)
    return rows


def row_line(r: dict) -> str:
    """One run in one line: its case, and each measured error against the stated one."""
    return (f"seed {r['seed']} delta={r['delta']:+.2f} chi={r['chi']:.2f} eps={r['eps']:.0e} {r['n_T']}T "
            f"w3={r['w3']:+.2f}: q {r['q_err']:.1e} / {r['q_stated']:.1e} (x{r['q_ratio']:.2f})  "
            f"slow {r['slow_err']:.1e} / {r['slow_stated']:.1e} (x{r['slow_ratio']:.2f})")


def passed(rows: list[dict]) -> bool:
    """Whether every measured error stayed within its statement (both ratios at most 1)."""
    return max(r["q_ratio"] for r in rows) <= 1.0 and max(r["slow_ratio"] for r in rows) <= 1.0


def format_table(rows: list[dict], seconds: float) -> str:
    """The sweep's summary as a Markdown table: runs, the largest measured/stated ratios, how many
    runs were called resolved and the worst of those (rad), and the time taken (s)."""
    worst_q = max(r["q_ratio"] for r in rows)
    worst_s = max(r["slow_ratio"] for r in rows)
    res = [r for r in rows if r["resolved"]]
    return (f"| runs | largest q error / stated | largest slow error / stated | resolved | largest q error resolved |"
            f" time |\n|---|---|---|---|---|---|\n| {len(rows)} | {worst_q:.2f} | {worst_s:.2f} | "
            f"{len(res)} | {max((r['q_err'] for r in res), default=0.0):.1e} rad | {seconds:.0f} s |")
