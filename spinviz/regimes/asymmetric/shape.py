"""Where any body's spin ends as tau -> oo: the averaged flow's shape, a flow on one line.

The torque of either model is cubic in Omega (the truncated one to O(tau0 |Omega|), which
vanishes as the spin brakes), so the rates of ln|L|^2 and ln p averaged over the polhode
(``integrators.polhode_flow``) are both |L|^2 times functions of the polhode's shape alone.
In the braking clock sigma = int eps |L|^2 dt the shape therefore follows an autonomous flow on
one line, D = |L|^2 / 2E from the smallest moment J_s (rotation about that axis) through the
middle one J_m (the separatrix) to the largest J_l -- and where it goes is where the spin ends:

* an axis, J_s or J_l, where the flow runs into it: the spin settles about that axis, its
  polhode shrinking as tau^alpha relative to |Omega| ~ tau^-1/2 (``Attractor.alpha``; for the
  reduced model, whose torque pushes the axis off by a forced tilt ~ 1/tau, the tilt outlives
  the polhode where alpha < -1: the paper's type "1", else "2", as on a symmetric top's axis);
* a zero of the flow between, stable: the spin ends on that polhode, a fixed shape (the
  asymmetric counterpart of the paper's balanced type "3");
* the separatrix, where the flow runs into it from both sides: the spin is carried onto the
  middle axis's separatrix, where no averaging holds (on a symmetric top: the equator -- the
  transverse state "4", or "5" / "?" where its phase stops).

A run crossing the separatrix enters one of the two lobes about the other extreme axis with
the probabilities of ``polhode_flow.separatrix_odds``; so a start's fate is a distribution over
the attractors and, for an axis, over the sign of L along it (which puts d at the acute or the
obtuse angle from L).  On a symmetric top the line is (4.12)'s Lotka-Volterra system read along
its ratio: its stable state, exponent and balanced amplitudes are reproduced
(``tests/test_asymmetric_atlas.py``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import brentq

from ...integrators.polhode_flow import Flow, separatrix_odds
from ...physics import polhode as PH
from ...physics.models import System

EPS = 1e-12            # the coupling's scale: the flow's zeros, signs and ratios do not depend on it
Q_AXIS = -40.0         # ln(p / |L|^2) taken as the axis
GRID = 48              # points along each side between the axis and the separatrix
SEP_GAP = 1e-7         # the separatrix is approached to this share of ln(p_sep / |L|^2)


@dataclass
class Attractor:
    """One end state: ``kind`` "axis", "polhode" or "separatrix"; ``axis`` the body index (axis),
    ``D`` its |L|^2 / 2E; ``alpha`` the polhode's exponent about an axis (omega_perp ~ tau^alpha);
    ``label`` "1"/"2" (reduced model: the forced tilt outlives the polhode, or not), "axis"
    (truncated), "3" (a fixed polhode), "sep"; ``angles_deg`` the angle between d and L at the end
    ((acute, obtuse) for an axis, (lowest, highest) over the polhode otherwise)."""

    kind: str
    D: float
    axis: int | None = None
    alpha: float = math.nan
    label: str = ""
    angles_deg: tuple = ()


@dataclass
class ShapeFlow:
    """The shape flow of one body and model: the attractors and, along D, the flow's sign."""

    J: tuple
    d: tuple
    model: str
    attractors: list = field(default_factory=list)
    D: np.ndarray = None                 # the sampled line, increasing, J_s .. J_l
    rate: np.ndarray = None              # d D / d sigma there (sigma in eps |L|^2 t)
    sep_D: float = math.nan
    odds: dict = field(default_factory=dict)    # (from axis, sign) -> [(to axis, sign, probability)]


def _side(J, c: int, model: str, g):
    """(q, D, dq/dsigma, flow, rates) along the side about axis c: q = ln(p / |L|^2) from the axis
    to the separatrix, D there, and the flow in q (d ln p/dt - d ln |L|^2/dt, in eps |L|^2)."""
    flow = Flow(System(model, tuple(J), tuple(g)), c, 1.0)
    s, m, l = PH.extreme_axes(J)
    q_sep = math.log(abs(J[c] - J[m]) / J[m])
    q = np.concatenate([np.linspace(Q_AXIS, q_sep - 3.0, GRID // 2),
                        q_sep - np.geomspace(3.0, max(SEP_GAP * max(1.0, abs(q_sep)), 1e-12), GRID // 2)])
    sig = 1.0 if c == l else -1.0
    r = np.array([flow.rates(np.array([0.0, qq])) for qq in q]) / EPS
    D = J[c] / (1.0 + sig * np.exp(q))
    return q, D, r[:, 1] - r[:, 0], flow, r


def _d_rate(c: int, l: int, qrate):
    """The flow's sign along increasing D from its sign along q (D grows with q about the
    smallest axis, falls with it about the largest)."""
    return qrate if c != l else -qrate


def shape_flow(J, d, model: str) -> ShapeFlow:
    """The shape flow of the body (moments J, dipole direction d) under ``model`` and its attractors."""
    J = np.asarray(J, dtype=float) / float(np.max(J))
    d = np.asarray(d, dtype=float) / np.linalg.norm(d)
    g = math.sqrt(EPS) * d
    s, m, l = PH.extreme_axes(J)
    sides = {}
    for c in (s, l):
        if J[c] != J[m]:
            sides[c] = _side(J, c, model, g)
    out = ShapeFlow(tuple(J), tuple(d), model, sep_D=float(J[m]))
    parts_D, parts_r = [], []
    if s in sides:
        q, D, qr, _, _ = sides[s]
        parts_D.append(D)
        parts_r.append(_d_rate(s, l, qr))
    if l in sides:
        q, D, qr, _, _ = sides[l]
        parts_D.append(D[::-1])
        parts_r.append(_d_rate(l, l, qr)[::-1])
    out.D, out.rate = np.concatenate(parts_D), np.concatenate(parts_r)
    for c, (q, _, qr, flow, r) in sides.items():
        # the axis: the polhode shrinks onto it where q falls there
        if qr[0] < 0.0:
            alpha = -0.5 * r[0, 1] / r[0, 0] if r[0, 0] != 0.0 else -math.inf
            label = ("1" if alpha < -1.0 else "2") if model == "reduced" and _forced(flow) else "axis"
            ang = math.degrees(math.acos(min(1.0, abs(float(d[c])))))
            out.attractors.append(Attractor("axis", float(J[c]), int(c), float(alpha), label, (ang, 180.0 - ang)))
        # fixed polhodes between: zeros of the flow in q where it falls through zero
        for k in np.flatnonzero(np.sign(qr[1:]) != np.sign(qr[:-1])):
            if not qr[k] > 0.0:
                continue

            def f(qq, flow=flow):
                r_ = flow.rates(np.array([0.0, qq]))
                return r_[1] - r_[0]

            qz = brentq(f, q[k], q[k + 1], xtol=1e-12)
            sig = 1.0 if c == l else -1.0
            pol = PH.Polhode(tuple(J), int(c), 1.0, 1.0, math.exp(qz))
            lo, hi = PH.angle_range(pol, d)
            out.attractors.append(Attractor("polhode", float(J[c] / (1.0 + sig * math.exp(qz))), int(c), label="3",
                                            angles_deg=(math.degrees(lo), math.degrees(hi))))
    # the separatrix, where both sides run into it (q rises there on each side that exists)
    if all(side[2][-1] > 0.0 for side in sides.values()):
        out.attractors.append(Attractor("separatrix", float(J[m]), int(m), label="sep"))
    out.odds = _odds(J, g, model, s, m, l, sides)
    return out


def _forced(flow: Flow) -> bool:
    """Whether the model pushes the axis off (a transverse torque on a rotation about it)."""
    return bool(np.any(flow.forced_offset(1.0) != 0.0))


def _odds(J, g, model, s, m, l, sides) -> dict:
    """(axis, sign) of the lobe left -> [(axis, sign, probability)] of the lobes entered, at the
    separatrix (only where the flow crosses it)."""
    system = System(model, tuple(J), tuple(g))
    out = {}
    for c, o in ((s, l), (l, s)):
        if c not in sides or o not in sides:
            continue
        if not sides[c][2][-1] > 0.0:          # q does not rise into the separatrix: nothing leaves
            continue
        for s_c in (1.0, -1.0):
            # a state on the separatrix's |L| = 1 in the lobe about (c, s_c)
            q_sep = math.log(abs(J[c] - J[m]) / J[m])
            w = PH.Polhode(tuple(J), int(c), s_c, 1.0, math.exp(q_sep - 1e-3)).omega(0.0)
            res = separatrix_odds(system, w, (int(c), s_c))
            out[(int(c), s_c)] = [(int(a), float(sg), float(p)) for a, sg, p in res["to"]]
    return out


def fate(shape: ShapeFlow, D0: float, c0: int, s0: float) -> dict:
    """{(attractor index, sign): probability} of a start at D0 in the lobe (c0, s0): the flow
    followed along D to the attractor it runs into, through the separatrix with its odds."""
    if not shape.attractors:
        return {}
    direction = np.sign(np.interp(D0, shape.D, shape.rate))
    out: dict = {}
    _walk(shape, D0, c0, s0, direction, 1.0, out, depth=0)
    return out


def _walk(shape: ShapeFlow, D0, c0, s0, direction, weight, out, depth):
    if direction == 0.0:
        direction = 1.0
    ahead = [(k, a) for k, a in enumerate(shape.attractors) if a.kind != "separatrix"
             and (a.D - D0) * direction >= 0.0 and (a.kind == "axis" or _same_side(shape, a.D, D0))]
    sep = shape.sep_D
    crosses = (sep - D0) * direction > 0.0
    # the nearest attractor before the separatrix
    if ahead:
        k, a = min(ahead, key=lambda ka: abs(ka[1].D - D0))
        if not crosses or abs(a.D - D0) < abs(sep - D0):
            sign = s0 if a.axis == c0 else 1.0
            out[(k, sign)] = out.get((k, sign), 0.0) + weight
            return
    if crosses:
        ks = [k for k, a in enumerate(shape.attractors) if a.kind == "separatrix"]
        if ks or depth > 2 or (c0, s0) not in shape.odds:
            key = (ks[0], 1.0) if ks else (-1, 1.0)
            out[key] = out.get(key, 0.0) + weight
            return
        for axis, sign, p in shape.odds[(c0, s0)]:
            if p > 0.0:
                _walk(shape, sep + 1e-9 * direction, axis, sign, direction, weight * p, out, depth + 1)
        return
    out[(-1, 1.0)] = out.get((-1, 1.0), 0.0) + weight


def _same_side(shape: ShapeFlow, a: float, b: float) -> bool:
    return (a - shape.sep_D) * (b - shape.sep_D) > 0.0


def isotropic_starts(n: int) -> np.ndarray:
    """n unit spin directions spread evenly over the sphere (a Fibonacci lattice), (n, 3)."""
    k = np.arange(n) + 0.5
    z = 1.0 - 2.0 * k / n
    phi = math.pi * (3.0 - math.sqrt(5.0)) * k
    r = np.sqrt(1.0 - z * z)
    return np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=-1)


def shares(shape: ShapeFlow, starts: np.ndarray) -> dict:
    """{(attractor index, sign): share} over spin directions ``starts`` (n, 3) (the sign of L
    along an end axis; +1 for other attractors); (-1, 1) collects starts with no attractor."""
    J = np.asarray(shape.J)
    out: dict = {}
    for w in starts:
        try:
            c0, s0 = PH.encircled_axis(J, w)
        except PH.NoPolhode:
            continue
        D0 = float(np.sum((J * w) ** 2) / np.sum(J * w * w))
        for key, p in fate(shape, D0, c0, s0).items():
            out[key] = out.get(key, 0.0) + p / len(starts)
    return out
