"""``spinviz info``: a body's derived quantities beside the figures the paper prints.

Every printed figure that differs from what spinviz computes from the paper's own
inputs by more than ``FLAG_THRESHOLD`` (5 %) is flagged, so a user sees both numbers
and knows which to trust (docs/design.md, "Verified against the paper").
"""

from __future__ import annotations

import math

import numpy as np

from .. import units as U
from ..physics.bodies import Body

FLAG_THRESHOLD = 0.05

_LABELS = {
    "I1": "I1", "I2": "I2", "I3": "I3", "epsilon": "eps = I3/I1", "delta": "delta = 1 - I3/I1 (3.6)",
    "chi_deg": "chi (d from e3)", "d_debye": "|d|", "tau0": "tau0 (3.8)", "density": "density", "mass": "mass",
    "T": "T = 1/(tau0 W^2)", "Theta": "Theta = 1/(tau0 W^2 eps^2)",
}


def rows(body: Body, omega_body=None) -> list[dict]:
    """One dict per quantity: key, label, value, unit, human, printed, where, rel_diff, flagged.

    omega_body : optional shape (3,) initial body-frame Omega (rad/s or 1/tau0) of a scene; T and
    Theta are then also given for it.  For presets the paper's reference spin
    Omega0 = Omega3 = pi 1e10 rad/s is used for the printed comparison.
    """
    printed = {p.key: p for p in body.printed}
    out = []
    for key, (value, unit) in body.figures().items():
        r = {"key": key, "label": _LABELS.get(key, key), "value": value, "unit": unit, "human": _human(value, unit)}
        if key in ("T", "Theta"):
            r["label"] += " *"
        p = printed.get(key)
        if p is not None:
            diff = value / p.value - 1.0 if p.value != 0 else math.inf
            r.update(printed=p.value, printed_human=_human(p.value, unit, short=True), where=p.where, approx=p.approx,
                     rel_diff=diff, flagged=abs(diff) > FLAG_THRESHOLD)
        out.append(r)
    if omega_body is not None:
        w = np.asarray(omega_body, dtype=float)
        w0, w_perp, w3 = float(np.linalg.norm(w)), math.hypot(w[0], w[1]), abs(float(w[2]))
        tu = "s" if body.units == "cgs" else "tau0"
        if w_perp > 0:   # the unit of a scene's t_end_T
            T = body.braking_time_T(w_perp)
            out.append({"key": "T_scene", "label": "T for this scene's Omega_perp", "value": T, "unit": tu,
                        "human": _human(T, tu)})
        if w0 > 0:
            out.append({"key": "eps_rad", "label": "tau0 |Omega0| (spin/braking ratio)", "value": body.tau0 * w0, "unit": "",
                        "human": f"{body.tau0 * w0:.3g}"})
        if w3 > 0:
            Th = body.residual_time_Theta(w3)
            out.append({"key": "Theta_scene", "label": "Theta for this scene's Omega3", "value": Th, "unit": tu,
                        "human": _human(Th, tu)})
    return out


def _human(value: float, unit: str, short: bool = False) -> str:
    if unit == "s":
        if short or abs(value) < 60:
            return U.human_time(value)
        return f"{value:.4g} s ({U.human_time(value)})"
    if unit in ("", "(relative)"):
        return f"{value:.4g}" + (f" {unit}" if unit else "")
    return f"{value:.4g} {unit}"


def format_info(body: Body, title: str, omega_body=None) -> str:
    """The human-readable report."""
    lines = [title, f"  source: {body.source}" if body.source else "", f"  units: {body.units}", ""]
    lines.append(f"  {'quantity':<34} {'spinviz':<30} {'paper prints':<16} diff")
    flagged = 0
    for r in rows(body, omega_body):
        line = f"  {r['label']:<34} {r['human']:<30}"
        if "printed" in r:
            p = ("~" if r["approx"] else "") + r["printed_human"]
            line += f" {p:<16} {r['rel_diff'] * 100:+5.1f} %"
            if r["flagged"]:
                flagged += 1
                line += "  ** differs by more than 5 %" + (" (the paper gives an order of magnitude)" if r["approx"] else "")
                line += f"  [{r['where']}]"
        lines.append(line)
    if body.reference_omega:
        lines += ["", f"  * W = {body.reference_omega:.4g} rad/s (pi 1e10), the spin section 6 assumes for Omega0 and Omega3"]
    if flagged:
        lines += ["", f"  {flagged} printed figure(s) differ by more than 5 % from what the paper's own inputs give."]
    return "\n".join(x for x in lines if x is not None)
