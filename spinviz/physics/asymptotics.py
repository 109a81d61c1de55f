"""The paper's asymptotic solutions of section 4 and their domains, as functions of (delta, chi).

Everything is dimensionless (4.1): omega = tau0 Omega, tau = t / tau0; n1 = sin chi,
n3 = cos chi, xi = tan^2 chi.  Each function cites its equation; where spinviz has derived a
line the paper does not print, the name says so (``spinviz_*``) and the docstring gives the
derivation, so a diagram can tell the paper's lines from spinviz's.

Types (section 4):

* "1" monotonous, (4.6) with (4.9): omega3 ~ C tau^-1/2, omega2 ~ B/tau, omega1 ~ A tau^-3/2;
* "2" axial spiral, (4.14): omega_perp ~ tau^alpha, omega3 ~ B tau^-1/2, in (4.15);
* "3" balanced spiral, (4.16): omega_perp ~ A tau^-1/2, omega3 ~ B tau^-1/2, in (4.17);
* "4" transverse spiral, (4.18): omega_perp ~ A tau^-1/2, omega3 ~ tau^beta, in (4.19);
* "5" oscillation about (3.9), (4.41)-(4.45), in (4.43);
* (3.9) itself: omega1 = omega3 = 0, omega2 = omega20 / sqrt(1 + 2 omega20^2 tau).

Misprints handled here (each reported beside the printed value, never silently):

* (4.18) prints A^2 = 1/(2 - xi), negative for xi > 2.  Averaging (4.12) with omega3 -> 0
  gives d omega_perp/d tau = -(n3^2 + n1^2/2) omega_perp^3, hence A^2 = 1/(2 n3^2 + n1^2) =
  (1 + xi)/(2 + xi); ``type4_eq4_18`` returns both.
* (4.43) prints xi > 2(1 - delta)/(7 delta - 6), delta > 4/7.  (4.42)'s B = -sqrt((1 - A^2)/2)
  is real only where A^2 <= 1, i.e. xi (7 delta - 4) >= 2 (1 - delta): the printed "delta > 4/7"
  belongs to 7 delta - 4, and for 4/7 < delta < 6/7 the printed bound (negative) would admit
  A^2 > 1.  ``type5_eq4_42`` reports both conditions.
"""

from __future__ import annotations

import math

import numpy as np

from . import closed_forms as CF

NAN = float("nan")


def _n(chi: float) -> tuple[float, float, float]:
    n1, n3 = math.sin(chi), math.cos(chi)
    return n1, n3, (n1 / n3) ** 2 if n3 != 0.0 else math.inf


def type1_eq4_9(delta: float, chi: float) -> dict:
    """(4.9): C^2 = (1 - delta)/(2 n1^2), B = -n3 (1 - delta)/(2 n1 delta),
    A = B/(delta C) {1 - [(1 - delta)^2 + 3 n1^2 delta] C^2}.  A is returned for C > 0 (A
    changes sign with C).  Undefined (NaN) at delta = 0 or chi = 0 (no type 1 there)."""
    n1, n3, _ = _n(chi)
    if n1 == 0.0 or delta == 0.0:
        return {"C2": NAN, "B": NAN, "A_for_C_positive": NAN}
    C2 = (1.0 - delta) / (2.0 * n1 * n1)
    B = -n3 * (1.0 - delta) / (2.0 * n1 * delta)
    A = B / (delta * math.sqrt(C2)) * (1.0 - ((1.0 - delta) ** 2 + 3.0 * n1 * n1 * delta) * C2)
    return {"C2": C2, "B": B, "A_for_C_positive": A}


def type2_eq4_14(delta: float, chi: float) -> dict:
    """(4.14): alpha = -(1 - delta^3)/4 - (1 - delta)^3/(2 xi), B^2 = (1 - delta)/(2 n1^2);
    ``in_domain`` is (4.15): 0 < xi < 2 (1 - delta)^3/(1 + delta^3)."""
    n1, _, xi = _n(chi)
    if xi == 0.0:
        return {"alpha": -math.inf, "B2": math.inf, "in_domain": False}
    alpha = -(1.0 - delta**3) / 4.0 - (1.0 - delta) ** 3 / (2.0 * xi)
    return {"alpha": alpha, "B2": (1.0 - delta) / (2.0 * n1 * n1),
            "in_domain": bool(0.0 < xi < xi_eq4_15(delta))}


def type3_eq4_16(delta: float, chi: float) -> dict:
    """(4.16): A^2, B^2 of the balanced spiral; ``in_domain`` is (4.17) as printed
    (including its delta > -1/2), ``positive`` is A^2 > 0 and B^2 > 0 (where (4.16) is a
    solution of the averaged system (4.12) at all)."""
    n1, _, xi = _n(chi)
    den = delta * n1 * n1 * (2.0 * (3.0 - delta * delta) - (3.0 + 3.0 * delta + delta * delta) * xi)
    if den == 0.0 or not math.isfinite(xi):
        return {"A2": NAN, "B2": NAN, "in_domain": False, "positive": False}
    A2 = ((1.0 + delta**3) * xi - 2.0 * (1.0 - delta) ** 3) / den
    B2 = (2.0 * (1.0 - delta) - (1.0 + 2.0 * delta) * xi) / den
    in_dom = xi >= xi_eq4_15(delta) and delta > -0.5 and xi <= xi_eq4_17(delta)
    return {"A2": A2, "B2": B2, "in_domain": bool(in_dom), "positive": bool(A2 > 0.0 and B2 > 0.0)}


def type4_eq4_18(delta: float, chi: float) -> dict:
    """(4.18): beta = -(2 + delta) xi / (2 (1 - delta)(xi + 2)); A^2 corrected to
    (1 + xi)/(2 + xi) (module docstring), the printed 1/(2 - xi) beside it; ``in_domain``
    is (4.19)."""
    _, _, xi = _n(chi)
    if not math.isfinite(xi):
        return {"beta": -(2.0 + delta) / (2.0 * (1.0 - delta)), "A2": 1.0, "A2_printed": 0.0, "in_domain": False}
    beta = -(2.0 + delta) * xi / (2.0 * (1.0 - delta) * (xi + 2.0))
    in_dom = delta > -0.5 and xi > xi_eq4_17(delta) and (delta <= 0.0 or xi < xi_eq4_20(delta))
    return {"beta": beta, "A2": CF.spiral4_amplitude_sq_eq4_18(chi), "A2_printed": 1.0 / (2.0 - xi) if xi != 2.0 else math.inf,
            "in_domain": bool(in_dom)}


def type5_eq4_42(delta: float, chi: float) -> dict:
    """(4.42): A^2 = 3 (1 + xi)(1 - delta)/(1 - delta - (1 - 4 delta) xi), B = -sqrt((1 - A^2)/2),
    M^2 = n1 n3 A^2 (3 A^2 + 4 B^2)/(4 delta (1 - delta)|B|), and (4.45)'s K = A^2/(4B) as
    printed.  ``in_domain`` is (4.43) as printed; ``real`` is 0 < A^2 <= 1 (B real)."""
    n1, n3, xi = _n(chi)
    den = 1.0 - delta - (1.0 - 4.0 * delta) * xi
    A2 = 3.0 * (1.0 + xi) * (1.0 - delta) / den if den != 0.0 and math.isfinite(xi) else NAN
    real = bool(0.0 < A2 <= 1.0)
    B = -math.sqrt((1.0 - A2) / 2.0) if real else NAN
    M2 = n1 * n3 * A2 * (3.0 * A2 + 4.0 * B * B) / (4.0 * delta * (1.0 - delta) * abs(B)) \
        if real and delta != 0.0 and B != 0.0 else NAN
    printed = delta > 4.0 / 7.0 and (7.0 * delta - 6.0 == 0.0 or xi > 2.0 * (1.0 - delta) / (7.0 * delta - 6.0)
                                     or 7.0 * delta - 6.0 < 0.0)
    return {"A2": A2, "B": B, "M2": M2, "K_printed": A2 / (4.0 * B) if real and B != 0.0 else NAN,
            "in_domain": bool(printed), "real": real}


# --- the boundary lines, xi as a function of delta ------------------------------------------
def xi_eq4_15(delta):
    """(4.15) and the first bound of (4.17): xi = 2 (1 - delta)^3 / (1 + delta^3) (2 | 3)."""
    return 2.0 * (1.0 - delta) ** 3 / (1.0 + delta**3)


def xi_eq4_17(delta):
    """Second bound of (4.17), first of (4.19): xi = 2 (1 - delta)/(1 + 2 delta), delta > -1/2 (3 | 4)."""
    return 2.0 * (1.0 - delta) / (1.0 + 2.0 * delta)


def xi_eq4_20(delta):
    """(4.20), the upper bound of (4.19): xi = 4 (1 - delta)/(3 delta), delta > 0 (4 | "?")."""
    return 4.0 * (1.0 - delta) / (3.0 * delta)


def xi_eq4_43(delta):
    """(4.43) as printed: xi = 2 (1 - delta)/(7 delta - 6), a bound only for delta > 6/7."""
    return 2.0 * (1.0 - delta) / (7.0 * delta - 6.0)


def xi_spinviz_type5_real(delta):
    """Where (4.42) has a real B (A^2 = 1): xi = 2 (1 - delta)/(7 delta - 4), delta > 4/7."""
    return 2.0 * (1.0 - delta) / (7.0 * delta - 4.0)


def xi_spinviz_alpha_minus_one(delta):
    """alpha of (4.14) = -1: xi = 2 (1 - delta)^3/(3 + delta^3).

    Type 1's omega_perp = |B|/tau of (4.9) is the response forced by omega3; the free spiral
    part decays as tau^alpha.  Below this line (alpha < -1) the spiral dies first and the
    late state is type 1; between it and (4.15) it is type 2."""
    return 2.0 * (1.0 - delta) ** 3 / (3.0 + delta**3)


def xi_spinviz_beta_minus_three_quarters(delta):
    """beta of (4.18) = -3/4: xi = 6 (1 - delta)/(1 + 5 delta), delta > -1/5.

    With rho = omega_perp sqrt(tau), u = omega3 tau^(3/4), s = tau^(1/4), the phase obeys a
    pendulum equation d phi/ds = -4 delta u, du/ds = 4 k rho^3 cos phi (k = n1 n3/(1 - delta))
    with energy H = 2 delta u^2 + 4 k rho^3 sin phi.  A rotating phase (type 4) has
    u ~ tau^(beta + 3/4): for beta < -3/4 its kinetic part dies, the phase falls onto the
    separatrix and is captured into a libration about phi = -sign(delta) pi/2, type 5.  Above
    this line (larger xi) type 4 is therefore not asymptotic."""
    return 6.0 * (1.0 - delta) / (1.0 + 5.0 * delta)


def chi_of_xi(xi):
    """chi = arctan sqrt(xi) (rad); NaN where xi <= 0 or not finite."""
    xi = np.asarray(xi, dtype=float)
    out = np.full(xi.shape, np.nan)
    ok = np.isfinite(xi) & (xi > 0.0)
    out[ok] = np.arctan(np.sqrt(xi[ok]))
    return out


def boundaries(model: str = "reduced", n: int = 801) -> list[dict]:
    """The lines of the delta-chi diagram: each a dict with ``name``, ``label`` (what the
    diagram writes beside it), ``source`` ("paper" or "spinviz"), ``kind`` -- what the line is
    for the types as tau -> oo: "sharp" (the averaged flow's one stable state changes there, so
    every start on each side ends in that side's type: (4.15) is where the axial state loses
    its stability, alpha = -1/2; (4.17) for delta > -1/2 the transverse one, beta = -1/2;
    alpha = -1 where the free spiral and the forced response trade places; truncated delta = 0
    and beta_T = -1), "band" (beta = -3/4: beyond it type 4 is captured into 5, before it the
    two coexist among the starts over a band) or "none" (the paper's (4.20) and (4.43), with
    type 5 on both sides) -- ``delta`` and ``chi`` (rad, NaN where the line does not exist).

    Reduced: (4.15), (4.17) (= the lower bound of (4.19)), (4.20) (= its upper bound), (4.43)
    as printed and corrected (7 delta - 4, where (4.42)'s B is real), and spinviz's alpha = -1
    of (4.14) and beta = -3/4 of (4.18).  Truncated: spinviz's lines of the averaged truncated
    flow (``truncated_averaged``): delta = 0 and the frozen-phase line."""
    d = np.linspace(-1.0, 1.0, n)[1:-1]
    lines = []
    with np.errstate(divide="ignore", invalid="ignore"):
        if model == "reduced":
            dm = np.where(d > -0.5, d, np.nan)
            dp = np.where(d > 0.0, d, np.nan)
            d43 = np.where(d > 6.0 / 7.0, d, np.nan)
            d47 = np.where(d > 4.0 / 7.0, d, np.nan)
            db = np.where(d > -0.2, d, np.nan)
            lines += [
                {"name": "(4.15): 2 | 3", "label": "(4.15)", "source": "paper", "kind": "sharp", "delta": d,
                 "chi": chi_of_xi(xi_eq4_15(d))},
                {"name": "(4.17), (4.19): 3 | 4", "label": "(4.17), (4.19)", "source": "paper", "kind": "sharp", "delta": dm,
                 "chi": chi_of_xi(xi_eq4_17(dm))},
                {"name": "(4.20), (4.19): 4 | ?", "label": "(4.20), (4.19)", "source": "paper", "kind": "none", "delta": dp,
                 "chi": chi_of_xi(xi_eq4_20(dp))},
                {"name": "(4.43) as printed: 5", "label": "(4.43) printed", "source": "paper", "kind": "none", "delta": d43,
                 "chi": chi_of_xi(xi_eq4_43(d43))},
                {"name": "(4.43) corrected: 7 delta - 4", "label": "(4.43) corrected", "source": "spinviz", "kind": "none",
                 "delta": d47, "chi": chi_of_xi(xi_spinviz_type5_real(d47))},
                {"name": "alpha = -1 of (4.14): 1 | 2", "label": "(4.14) \u03b1 = \u22121", "source": "spinviz", "kind": "sharp",
                 "delta": d, "chi": chi_of_xi(xi_spinviz_alpha_minus_one(d))},
                {"name": "beta = -3/4 of (4.18): 4 | 5", "label": "(4.18) \u03b2 = \u2212\u00be", "source": "spinviz",
                 "kind": "band", "delta": db, "chi": chi_of_xi(xi_spinviz_beta_minus_three_quarters(db))},
            ]
        else:
            dt = np.where(d > 0.5, d, np.nan)
            lines += [
                {"name": "delta = 0: T2 | T4", "label": "\u03b4 = 0", "source": "spinviz", "kind": "sharp",
                 "delta": np.array([0.0, 0.0]),
                 "chi": np.array([0.0, 0.5 * math.pi])},
                {"name": "beta_T = -1: T4 | TF", "label": "\u03b2_T = \u22121", "source": "spinviz", "kind": "sharp", "delta": dt,
                 "chi": chi_of_xi(2.0 * (1.0 - dt) / (2.0 * dt - 1.0))},
            ]
    return lines


def truncated_averaged(delta: float, chi: float) -> dict:
    """The truncated equation (2.5) averaged over the precession (spinviz's derivation, by
    exact trigonometric quadrature of the cubic torque; the analogue of (4.12)):

        <omega_perp>' = -[(n3^2 + n1^2/2) wp^2 + n1^2 (2 + delta)/2 w3^2] wp,
        <omega3>'     = -[(n3^2 + n1^2/(2(1 - delta))) wp^2 + n1^2/(1 - delta) w3^2] w3.

    Its late states: "T4" (delta > 0) omega_perp^2 tau -> A2 = 1/(2 a), omega3 ~ tau^beta_T;
    "T2" (delta < 0) omega3^2 tau -> B2 = 1/(2 e), omega_perp ~ tau^alpha_T; "TF" where
    beta_T < -1 (the phase stops; delta > 1/2, xi > 2 (1 - delta)/(2 delta - 1))."""
    n1, n3, _ = _n(chi)
    a = n3 * n3 + n1 * n1 / 2.0
    b = n1 * n1 * (2.0 + delta) / 2.0
    c = n3 * n3 + n1 * n1 / (2.0 * (1.0 - delta))
    e = n1 * n1 / (1.0 - delta)
    beta_t = -c / (2.0 * a)
    return {"T4_A2": 1.0 / (2.0 * a), "T4_beta": beta_t, "T2_B2": 1.0 / (2.0 * e) if e > 0 else math.inf,
            "T2_alpha": -b / (2.0 * e) if e > 0 else NAN, "frozen": bool(beta_t < -1.0)}


# --- the DAST boxes of figure 5 ---------------------------------------------------------
def box_delta(sym: float, other: float) -> float:
    """delta = 1 - I_sym/I_perp of a box whose two equal edges are ``other`` and whose third
    edge ``sym`` lies along the symmetry axis: I_sym = m 2 other^2/12, I_perp = m (sym^2 +
    other^2)/12 (family 1: sym = c, other = a; family 2: sym = a, other = b)."""
    return (sym * sym - other * other) / (sym * sym + other * other)
