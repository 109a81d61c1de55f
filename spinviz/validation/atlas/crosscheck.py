"""The atlas's disagreements with the paper, re-checked with an independent integrator.

    spinviz atlas evidence crosscheck [--members 3] [--json]

Independent of the atlas in two ways: the equations are (4.2)-(4.4) typed in from the paper
(with omega_a, omega_b, omega_c of section 3), not spinviz's general reduced equation; and
they are integrated by SciPy's ``solve_ivp`` (DOP853, and Radau for one point), not by the
atlas's heyoka Taylor integrator.  Only the classifier is shared, and every claim is also shown by
a number computed here directly (omega_perp sqrt(tau), omega2 tau, a fitted slope).

The points (|omega0| = 0.1, tau_end = 1e10, starts from the atlas's seeded directions):

* (-0.6, 0.3): inside (4.15)'s domain "2", but alpha of (4.14) = -21.7: the late state is
  type 1, omega2 tau -> B and omega3^2 tau -> C^2 of (4.9);
* (-0.6, 77 deg): delta < -1/2, excluded by (4.17), yet type 3 with (4.16)'s amplitudes;
* (0.5, 39 deg): type 4 (beta = -0.617 > -3/4) with A^2 = (1 + xi)/(2 + xi), not (4.18)'s 1/(2 - xi);
* (0.5, 45 deg): in (4.19)'s domain "4", but beta = -0.833 < -3/4: the phase is captured into
  type 5, omega_perp sqrt(tau) -> 0.882 (the paper's 0.81 is the value passed before the capture, at tau ~ 1e3-1e4);
* (0.2, 70 deg): far outside (4.43) (delta < 4/7), type 5 all the same;
* (0.8, 1.2): inside (4.43): type 5, against (4.42)'s A^2, B, M^2, and the sign of (4.45)'s K
  (fitted: omega2 sqrt(tau) = B + K cos 2 psi, cos psi = omega_angle / envelope).
"""

from __future__ import annotations

import math
import time

import numpy as np

from ...inputs.atlas_spec import Settings, directions
from ...physics import asymptotics as FM
from ...regimes.engine import classify as C


def rhs_eq4_2_4(delta: float, chi: float):
    """(4.2)-(4.4) as printed (dimensionless), with omega_a^2, omega_b^2, omega_c^2 of section 3."""
    n1, n3 = math.sin(chi), math.cos(chi)

    def f(t, w):
        w1, w2, w3 = w
        s = w1 * w1 + w2 * w2 + w3 * w3
        wa = s + delta * (delta - 2.0) * w3 * w3
        wb = s + delta * (2.0 * w1 * w1 - w2 * w2)
        wc = s + delta * (delta + 1.0) * w3 * w3
        d1 = delta * w2 * w3 - n3 * n3 * wa * w1 + n1 * n3 * wb * w3
        d2 = -delta * w1 * w3 - (n1 * n1 * wc + n3 * n3 * wa - 3.0 * n1 * n3 * delta * w1 * w3) * w2
        d3 = (-n1 * n1 * wb * w3 + n1 * n3 * wa * w1) / (1.0 - delta)
        return [d1, d2, d3]

    return f


def scipy_run(delta, chi, omega0, settings: Settings, method: str = "DOP853"):
    """(tau, omega (N, 3), seconds, nfev) from solve_ivp on (4.2)-(4.4)."""
    from scipy.integrate import solve_ivp

    t = settings.times()
    t0 = time.perf_counter()
    sol = solve_ivp(rhs_eq4_2_4(delta, chi), (0.0, t[-1]), np.asarray(omega0, float), method=method, t_eval=t,
                    rtol=1e-10, atol=1e-20)
    if not sol.success:
        raise RuntimeError(f"solve_ivp {method} failed at delta={delta}, chi={chi}: {sol.message}")
    return t, sol.y.T, time.perf_counter() - t0, sol.nfev


POINTS = [
    ("type 1 inside (4.15)'s '2'", -0.6, 0.3, "DOP853"),
    ("type 3 at delta < -1/2", -0.6, math.radians(77.0), "DOP853"),
    ("type 4, corrected A^2", 0.5, math.radians(39.0), "DOP853"),
    ("type 5 inside (4.19)'s '4'", 0.5, math.radians(45.0), "DOP853"),
    ("type 5 inside (4.19)'s '4' (Radau)", 0.5, math.radians(45.0), "Radau"),
    ("type 5 outside (4.43)", 0.2, math.radians(70.0), "DOP853"),
    ("type 5 inside (4.43)", 0.8, 1.2, "DOP853"),
]


def measures(delta, chi, tau, w) -> dict:
    """Direct numbers over the last decade: omega_perp sqrt(tau), omega3 sqrt(tau), omega2 tau,
    slopes, and (4.45)'s K fitted."""
    m = tau >= tau[-1] / 10.0
    tw, ww = tau[m], w[m]
    wp = np.hypot(ww[:, 0], ww[:, 1])
    lt = np.log(tw)
    out = {"X": float(np.sqrt(np.mean(wp**2 * tw))), "Y": float(np.sqrt(np.mean(ww[:, 2] ** 2 * tw))),
           "w2_tau": float(np.mean(ww[:, 1] * tw)), "slope_perp": float(np.polyfit(lt, np.log(wp), 1)[0])}
    n1, n3 = math.sin(chi), math.cos(chi)
    wang = (ww[:, 0] + n3 / n1 * (1.0 - delta) * ww[:, 2]) * np.sqrt(tw)
    env = float(np.max(np.abs(wang)))
    if env > 0:
        c2 = 2.0 * (wang / env) ** 2 - 1.0                 # cos 2 psi, omega_angle = f cos psi (4.33)
        K, B = np.polyfit(c2, ww[:, 1] * np.sqrt(tw), 1)
        out.update(K_fit=float(K), B_fit=float(B), A2_env=env * env)
    return out


def run(members: int = 3, settings: Settings | None = None, progress=None) -> list[dict]:
    """Integrate every point's starts with SciPy and classify them; one row per start.
    ``members`` is checked first (``inputs.options.EvidenceRequest``; the work against the cap by
    ``evidence.run``)."""
    from ...inputs.options import EvidenceRequest

    EvidenceRequest(members=members, tau_end=settings.tau_end if settings is not None else None)
    st = settings or Settings()
    starts = directions(members, 1) * 0.1
    rows = []
    for name, d, c, method in POINTS:
        for k in range(members):
            tau, w, secs, nfev = scipy_run(d, c, starts[k], st, method)
            v = C.classify(tau, w, d, c, "reduced", st.window)
            row = {"point": name, "delta": d, "chi_deg": math.degrees(c), "method": method, "member": k,
                   "label": v.label, "confidence": v.confidence, "seconds": secs, "nfev": int(nfev),
                   "deviations": v.deviations, **measures(d, c, tau, w)}
            rows.append(row)
            if progress:
                progress(row)
    return rows


def paper_values(d: float, c: float) -> str:
    """What the paper's formulas give at (d, c), as text for the table."""
    t1, t2, t3, t4, t5 = (FM.type1_eq4_9(d, c), FM.type2_eq4_14(d, c), FM.type3_eq4_16(d, c), FM.type4_eq4_18(d, c),
                          FM.type5_eq4_42(d, c))
    return (f"(4.9) C^2={t1['C2']:.4g} B={t1['B']:.4g} | (4.14) alpha={t2['alpha']:.4g} in (4.15): {t2['in_domain']} | "
            f"(4.16) A^2={t3['A2']:.4g} B^2={t3['B2']:.4g} in (4.17): {t3['in_domain']} | (4.18) beta={t4['beta']:.4g} "
            f"A^2 printed {t4['A2_printed']:.4g} corrected {t4['A2']:.4g} in (4.19): {t4['in_domain']} | "
            f"(4.42) A^2={t5['A2']:.4g} B={t5['B']:.4g} M^2={t5['M2']:.4g} K={t5['K_printed']:.4g} in (4.43): {t5['in_domain']}")


def format_rows(rows: list[dict]) -> str:
    """The cross-check rows as a table for people."""
    out = []
    last = None
    for r in rows:
        if r["point"] != last:
            last = r["point"]
            out.append(f"\n== {r['point']}: delta = {r['delta']:g}, chi = {r['chi_deg']:.2f} deg, xi = "
                       f"{math.tan(math.radians(r['chi_deg'])) ** 2:.4g}")
            out.append("   paper: " + paper_values(r["delta"], math.radians(r["chi_deg"])))
        devs = ", ".join(f"{k} {100 * v:+.2f} %" for k, v in r["deviations"].items())
        extra = ""
        if r["label"] == "5" and "K_fit" in r:
            extra = (f" fit of w2 sqrt(tau) = B + K cos 2psi: B={r['B_fit']:+.4f} K={r['K_fit']:+.4f}"
                     f" (-A^2/(4B) = {-r['A2_env'] / (4 * r['B_fit']):+.4f})")
        out.append(f"   {r['method']:6s} member {r['member']}: {r['label']:5s} ({r['confidence']:.2f})  "
                   f"X=w_perp sqrt(tau)={r['X']:.4f}  Y={r['Y']:.4f}  w2 tau={r['w2_tau']:.4g}  "
                   f"p={r['slope_perp']:.4f}{extra}  [{devs}]  {r['seconds']:.1f} s")
    return "\n".join(out)

