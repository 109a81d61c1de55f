"""Which asymptotic regime a run ends in: a label, how sure it is, and the evidence.

    v = classify(tau, omega, delta, chi, model="reduced")
    v.label, v.confidence, v.candidate, v.reason, v.evidence["slope_perp"], ...

Input: one run of the dimensionless Euler equation, tau shape (N,) log-spaced, omega shape
(N, 3) body frame (4.1); J = (1, 1, 1 - delta), d = (sin chi, 0, cos chi).  The last
``window`` decades are analysed (default 2).

With log-spaced samples the precession phase is aliased, so nothing is fitted to a phase.
The phase behaviour is judged from statistics that aliasing cannot fake:

* the largest empty arc ("gap") of phi = atan2(omega2, omega1) on the circle, the occupied
  arc and its centre;
* the fraction of consecutive samples at which omega3 changes sign (0 for a spiral, whose
  omega3 keeps its sign; about 1/2 for an oscillation sampled at random phases);
* the number of turns implied by phi_dot = -delta omega3: |delta| int |omega3| dtau / 2 pi.

Envelopes: omega_perp and |omega| are regressed (log-log) on every sample; omega3 on every
sample when it keeps its sign, else on half-decade RMS values.  The slopes of the two halves
of the window tell a settled power law from a drifting one.

Phenomenological classes come first (they do not depend on the paper being right), then
the model's name for them::

    class              evidence                                             reduced  truncated
    axial-stopped      omega3 ~ tau^-1/2 dominant, omega_perp ~ 1/tau, phi stopped   "1"
    axial-spiral       omega3 ~ tau^-1/2 dominant, omega_perp ~ tau^p, p < -1/2     "2"      "T2"
    balanced-spiral    omega_perp, omega3 ~ tau^-1/2, phi turning                   "3"      "Tcone"
    transverse-spiral  omega_perp ~ tau^-1/2 dominant, omega3 ~ tau^q, q < -1/2     "4"      "T4"
    libration          omega_perp ~ tau^-1/2, phi swings about -sign(delta) pi/2,   "5"
                       omega3 changes sign, pendulum energy h constant
    transverse-frozen  omega3 -> 0 faster than 1/tau, phi stopped                   "3.9" only if exact, "TF"
    residual           |omega| -> const, omega along d (no braking)                 "R"      "R"

Confidence = best score x settledness x min(1, 0.5 + margin to the runner-up) x fit factor
(the RMS scatter about the power laws, log10 units: 1 below 0.05, 0 above 0.15).  Below
``MIN_CONFIDENCE`` the label is "other" and ``candidate`` names the best class or a
mixture ("1|2": omega3 ~ tau^-1/2 with the phase neither stopped nor turning freely, the
hand-over between types 1 and 2; "4|5": transverse, omega3 too small to tell a rotating
phase from a swinging one).  The paper's formulas are then evaluated for the label and
their relative deviations reported: they never change the label, so where the paper is
wrong the label is still right.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ...physics import asymptotics as FM
from ...physics import models as M

VERSION = 4                # bump when a rule changes: stores made by another version are not resumed
#                            (what each version changed: CHANGELOG.md)

MIN_CONFIDENCE = 0.5
TOL_HALF = 0.03            # |slope + 1/2| accepted as "-1/2" (full score within TOL/2, none beyond 1.5 TOL)
TOL_SEP = 0.03             # a slope counts as "below -1/2" below -1/2 - TOL_SEP (ramping from -1/2 - TOL_SEP/2)
TOL_ONE = 0.12             # |slope + 1| accepted as "-1" (type 1's omega_perp)
TOL_34 = 0.12              # |slope + 3/4| accepted as "-3/4" (type 5's omega3)
DRIFT = 0.05               # slope change between the window's halves still "settled" (none beyond 3 DRIFT)
SC_SPIRAL = 0.03           # omega3 sign-change fraction below which omega3 "keeps its sign"
SC_LIBR = 0.15             # ... above which omega3 "oscillates"
ARC_STOP = 0.05            # occupied arc of phi (rad) below which phi "has stopped"
RES_SLOPE = -0.05          # slope of |omega| above which the run "does not brake"
EXACT_39 = 1e-6            # hypot(omega1, omega3)/|omega| below which a run *is* (3.9)
MIN_SAMPLES = 12           # samples needed in the window



def class_labels(model: str):
    """The model's class -> type label (``physics.models``' ``type_labels``: "axial-stopped" is
    "1" under the reduced model, "T1" under the truncated one); ValueError for a model the
    atlas cannot map."""
    labels = M.get(model).type_labels
    if labels is None:
        raise ValueError(f"the model {model!r} has no atlas types; valid: {', '.join(M.for_atlas())}")
    return labels


# Every label the atlas can store, with its int8 code (CF flag_values / flag_meanings).  The
# paper's types keep their number; 0 is Zarr's fill value, so a run not computed yet reads "missing".
CODE = {"missing": 0, "1": 1, "2": 2, "3": 3, "4": 4, "5": 5, "3.9": 6, "R": 7, "T2": 8, "Tcone": 9, "T4": 10,
        "TF": 11, "T1": 12, "T5": 13, "other": 14, "1|2": 15, "4|5": 16, "approaching": 17, "failed": -1}
LABELS = tuple(CODE)

# The evidence of every run, in this order (the store's ``quantity`` dimension).
EVIDENCE = (
    "slope_perp",          # p: d log omega_perp / d log tau over the window
    "slope_3",             # q: the same for |omega3| (half-decade RMS when omega3 changes sign)
    "slope_norm",          # s: the same for |omega|
    "slope_drift",         # largest change of p or q between the window's halves
    "settled",             # 1 - ramp(slope_drift): 1 = the power laws hold over the whole window
    "fit_rms",             # RMS scatter about the power-law fits, log10 units
    "fit_quality",         # exp(-fit_rms / 0.02): 1 = perfect power laws
    "X2",                  # omega_perp^2 tau, RMS over the last half decade (A^2 of (4.16), (4.18))
    "Y2",                  # omega3^2 tau, same (B^2 of (4.14), (4.16); C^2 of (4.9))
    "w2_tau",              # mean of omega2 tau, last half decade (B of (4.9))
    "w1_tau32",            # mean of omega1 tau^(3/2), last half decade (A of (4.9))
    "libration_A2",        # max (omega_angle^2 tau), omega_angle of (4.23): A^2 of (4.42) read as the peak
    "libration_B",         # mean omega2 sqrt(tau) (B of (4.42), a mean)
    "libration_M2",        # max omega3^2 tau^(3/2): M^2 of (4.42) read as the peak
    "h_mean",              # pendulum energy of the phase (-1 at (3.9), +1 on the separatrix), mean
    "h_std",               # its spread over the window (a libration keeps it constant)
    "phi_arc",             # occupied arc of phi (rad): 2 pi = turning, small = stopped
    "phi_centre",          # centre of the occupied arc (rad); a libration swings about -sign(delta) pi/2
    "w3_sign_changes",     # fraction of consecutive samples where omega3 changes sign
    "turns",               # turns of phi implied by phi_dot = -delta omega3 over the window
    "angle_omega_d_deg",   # angle between omega(end) and d, deg (residual rotation: 0)
    "frozen_norm",         # |omega| sqrt(2 tau) |d x omega/|omega||, last half decade (-> 1 for "TF" and (3.9))
    "lock_to_5_at_tau",    # a transverse spiral with q < -3/4: estimated tau of its capture into type 5
    "score",               # score of the best class (0..1)
    "margin",              # its lead over the runner-up
    "deviation",           # largest |relative deviation| of the label's measured quantities from its formulas
)


@dataclass(frozen=True)
class Verdict:
    """The classifier's answer for one run.

    label : a key of ``LABELS`` ("other" when no class is met with ``MIN_CONFIDENCE``).
    confidence : 0..1.
    candidate : the best class's label even when ``label`` is "other" (or a mixture, "1|2",
        "4|5", or "none").
    reason : one short line: why "other", or how the label was met.
    evidence : ``EVIDENCE`` -> float (NaN where not measured).
    deviations : the label's formula quantities -> relative deviation (measured - formula)/|formula|.
    """

    label: str
    confidence: float
    candidate: str
    reason: str
    evidence: dict = field(default_factory=dict)
    deviations: dict = field(default_factory=dict)

    def vector(self) -> np.ndarray:
        """The evidence in ``EVIDENCE`` order, shape (len(EVIDENCE),)."""
        return np.array([self.evidence.get(k, np.nan) for k in EVIDENCE], dtype=float)


# --- small helpers ------------------------------------------------------------------------
def _ramp(x: float, lo: float, hi: float) -> float:
    """0 at x <= lo, 1 at x >= hi, linear between."""
    if not math.isfinite(x):
        return 0.0
    if hi == lo:
        return float(x >= hi)
    return float(min(1.0, max(0.0, (x - lo) / (hi - lo))))


def _near(x: float, target: float, tol: float) -> float:
    """1 when |x - target| <= tol/2, 0 beyond 1.5 tol, linear between."""
    return _ramp(-abs(x - target), -1.5 * tol, -0.5 * tol)


def _below_half(x: float) -> float:
    """A slope clearly below -1/2."""
    return _ramp(-x, 0.5 + 0.5 * TOL_SEP, 0.5 + TOL_SEP)


def _fit(x: np.ndarray, y: np.ndarray) -> tuple[float, float]:
    """(slope, RMS residual) of the least-squares line y = a x + b (closed form: np.polyfit's
    SVD costs 25 us a call, and the atlas makes ~14 fits a run)."""
    if len(x) < 2:
        return math.nan, math.nan
    dx = x - x.mean()
    dy = y - y.mean()
    sxx = float(dx @ dx)
    if sxx == 0.0:
        return math.nan, math.nan
    a = float(dx @ dy) / sxx
    r = dy - a * dx
    return a, math.sqrt(float(r @ r) / len(x))


def gap(phi: np.ndarray) -> tuple[float, float]:
    """(largest empty arc of the angles ``phi`` on the circle, centre of the occupied arc), rad."""
    s = np.sort(np.mod(phi, 2.0 * math.pi))
    if len(s) == 1:
        return 2.0 * math.pi, float(s[0])
    d = np.diff(np.concatenate([s, [s[0] + 2.0 * math.pi]]))
    k = int(np.argmax(d))
    start = s[(k + 1) % len(s)]                        # the occupied arc runs from s[k+1] round to s[k]
    return float(d[k]), float(math.remainder(start + 0.5 * (2.0 * math.pi - d[k]), 2.0 * math.pi))


def _rel(meas: float, pred: float) -> float:
    if not (math.isfinite(meas) and math.isfinite(pred)) or pred == 0.0:
        return math.nan
    return (meas - pred) / abs(pred)


def _slopes(lt: np.ndarray, w: np.ndarray, nsub: int) -> dict:
    """Envelope slopes over one window (log10 tau = lt)."""
    tiny = 1e-300
    wp = np.hypot(w[:, 0], w[:, 1])
    w3 = w[:, 2]
    lp, ln = np.log10(wp + tiny), np.log10(np.sqrt(wp * wp + w3 * w3) + tiny)
    half = 0.5 * (lt[0] + lt[-1])
    e, l = lt <= half, lt >= half
    p, res_p = _fit(lt, lp)
    s, _ = _fit(lt, ln)
    p_e, p_l = _fit(lt[e], lp[e])[0], _fit(lt[l], lp[l])[0]
    smooth3 = bool(np.all(w3 > 0) or np.all(w3 < 0))
    if smooth3:
        l3 = np.log10(np.abs(w3))
        q, res_q = _fit(lt, l3)
        q_e, q_l = _fit(lt[e], l3[e])[0], _fit(lt[l], l3[l])[0]
    else:
        # omega3 changes sign: its envelope is the RMS over sub-windows (half decades)
        edges = np.linspace(lt[0], lt[-1] + 1e-12, nsub + 1)
        mids, r3 = [], []
        for i in range(nsub):
            m = (lt >= edges[i]) & (lt < edges[i + 1])
            if m.sum() >= 2:
                mids.append(lt[m].mean())
                r3.append(math.log10(math.sqrt(float(np.mean(w3[m] ** 2))) + tiny))
        mids_a, r3_a = np.array(mids), np.array(r3)
        q, res_q = _fit(mids_a, r3_a)
        h = len(mids_a) // 2
        q_e = _fit(mids_a[:h + 1], r3_a[:h + 1])[0] if h >= 1 else q
        q_l = _fit(mids_a[h:], r3_a[h:])[0] if len(mids_a) - h >= 2 else q
    return {"p": p, "q": q, "s": s, "p_e": p_e, "p_l": p_l, "q_e": q_e, "q_l": q_l,
            "res_p": res_p, "res_q": res_q, "smooth3": smooth3}


# --- the classifier -------------------------------------------------------------------------
def classify(tau, omega, delta: float, chi: float, model: str = "reduced", window: float = 2.0) -> Verdict:
    """Label the late-time regime of one run (see the module docstring).

    tau : shape (N,), increasing, log-spaced (0 allowed first, ignored), dimensionless.
    omega : shape (N, 3), body-frame dimensionless angular velocity.
    delta, chi : the top, (3.6) and (3.2), chi in rad.
    model : "reduced" or "truncated" (only the names of the classes and the formulas differ).
    window : decades analysed at the end of the run.
    """
    tau = np.asarray(tau, dtype=float)
    omega = np.asarray(omega, dtype=float)
    if omega.ndim != 2 or omega.shape[1] != 3 or tau.shape != omega.shape[:1]:
        raise ValueError(f"omega must have shape (N, 3) with N = len(tau) = {tau.shape[0]}, got {omega.shape}")
    class_labels(model)
    if not np.all(np.isfinite(omega)):
        return Verdict("failed", 0.0, "none", "non-finite samples")
    keep = tau > 0.0
    tau, omega = tau[keep], omega[keep]
    if len(tau) == 0:
        return Verdict("other", 0.0, "none", "no samples after tau = 0")
    m = tau >= float(tau[-1]) / 10.0**window
    if m.sum() < MIN_SAMPLES:
        return Verdict("other", 0.0, "none", f"{int(m.sum())} samples in the last {window:g} decades (need {MIN_SAMPLES})")
    x = _measure(tau[m], omega[m], delta, chi, window)
    scores = _scores(x, delta, model, relax=1.0)
    return _verdict(x, scores, delta, chi, model)


def _measure(tw, w, delta: float, chi: float, window: float) -> dict:
    """Everything the scores are made of, over the window: envelope slopes, amplitudes, the
    phase's statistics, settledness and the pendulum energy of the phase (``ev``: the evidence)."""
    n = len(tw)
    lt = np.log10(tw)
    nsub = max(2, int(round(2 * window)))
    S = _slopes(lt, w, nsub)
    ev: dict = {"slope_perp": S["p"], "slope_3": S["q"], "slope_norm": S["s"]}
    wp = np.hypot(w[:, 0], w[:, 1])
    w3 = w[:, 2]
    wn = np.sqrt(wp * wp + w3 * w3)
    sq = np.sqrt(tw)
    last = lt >= lt[-1] - window / nsub                   # the last sub-window (half a decade)
    X = float(np.sqrt(np.mean((wp[last] * sq[last]) ** 2)))
    Y = float(np.sqrt(np.mean((w3[last] * sq[last]) ** 2)))
    ev.update(X2=X * X, Y2=Y * Y, w2_tau=float(np.mean(w[last, 1] * tw[last])),
              w1_tau32=float(np.mean(w[last, 0] * tw[last] ** 1.5)))
    x = {"S": S, "ev": ev, "n": n, "X": X, "Y": Y, "tw": tw, "w": w, "wp": wp, "w3": w3, "wn": wn, "sq": sq,
         "last": last, "half": lt >= lt[0] + 0.5 * (lt[-1] - lt[0])}
    _phase(x, delta)
    drift = max(abs(S["p_l"] - S["p_e"]), abs(S["q_l"] - S["q_e"]) if Y > 1e-3 * X else 0.0)
    dvec = np.array([math.sin(chi), 0.0, math.cos(chi)])
    ang = math.degrees(math.acos(min(1.0, abs(float(w[-1] @ dvec)) / max(float(wn[-1]), 1e-300))))
    dxw = np.linalg.norm(np.cross(dvec, w[last]), axis=1)  # |d x omega| = |omega| |d x omega_hat|
    ev.update(slope_drift=drift, angle_omega_d_deg=ang, frozen_norm=float(np.mean(dxw * np.sqrt(2.0 * tw[last]))))
    x.update(drift=drift, settle=1.0 - _ramp(drift, DRIFT, 3.0 * DRIFT), ang=ang)
    _pendulum(x, delta, chi)
    # type 5's quantities of (4.42), measured: omega_angle (4.23), omega2, omega3 envelopes.  (4.33)
    # writes omega_angle = f cos(phi), omega3 = v sin(phi) + w cos(phi), so A and M are the swing's
    # amplitudes: read as peaks, the maximum over the window (log-spaced samples meet the swings
    # at scattered phases; at (0.8, 1.2) the median of 32 starts is within 0.2 % of the dense
    # samples' peak, single starts up to 3 % below it).  The r.m.s. reading (A^2 = 2 <omega_angle^2
    # tau>, the same for a harmonic swing) needs samples dense within swings, which log-spaced
    # samples alias: validation.atlas.validate.libration_readings.
    n1, n3 = math.sin(chi), math.cos(chi)
    w_ang = w[:, 0] + (n3 / n1) * (1.0 - delta) * w[:, 2] if n1 > 0.0 else w[:, 0]
    ev.update(libration_A2=float(np.max((w_ang * sq) ** 2)), libration_B=float(np.mean(w[:, 1] * sq)),
              libration_M2=float(np.max(w[:, 2] ** 2 * tw**1.5)))
    return x


def _phase(x: dict, delta: float) -> None:
    """The phase phi = atan2(omega2, omega1): turning, stopped or swinging, judged from
    statistics aliasing cannot fake (module docstring)."""
    w, w3, tw, half, n = x["w"], x["w3"], x["tw"], x["half"], x["n"]
    phi = np.arctan2(w[:, 1], w[:, 0])
    g, centre = gap(phi)
    zero3 = bool(x["Y"] < 1e-10 * x["X"])                # omega3 at round-off (an invariant plane)
    sgn = np.zeros_like(w3) if zero3 else np.sign(w3)
    sc = float(np.mean(sgn[1:] != sgn[:-1]))
    a3 = np.abs(w3) * tw
    turns = abs(delta) * float(np.sum(0.5 * (a3[1:] + a3[:-1]) * np.diff(np.log(tw)))) / (2.0 * math.pi)
    x["ev"].update(phi_arc=2.0 * math.pi - g, phi_centre=centre, w3_sign_changes=sc, turns=turns)
    x.update(phi=phi, gap=g, centre=centre, arc_late=2.0 * math.pi - gap(phi[half])[0], zero3=zero3, sc=sc,
             turns=turns, gap_random=2.0 * math.pi * (math.log(n) + 0.58) / n)   # largest gap of n random angles


def _pendulum(x: dict, delta: float, chi: float) -> None:
    """The pendulum of the phase (formulas.xi_spinviz_beta_minus_three_quarters): with
    rho = omega_perp sqrt(tau), u = omega3 tau^(3/4), k = n1 n3/(1 - delta),
    H = 2 delta u^2 + 4 k rho^3 sin(phi) is conserved over a swing; h = sign(delta) H/(4 k rho^3)
    is -1 at the bottom ((3.9), phi = -sign(delta) pi/2) and +1 on the separatrix."""
    ev = x["ev"]
    n1, n3 = math.sin(chi), math.cos(chi)
    k = n1 * n3 / (1.0 - delta)
    h_mean = h_std = h_drift = math.nan
    if k > 0.0 and delta != 0.0:
        tw, w3, phi, half = x["tw"], x["w3"], x["phi"], x["half"]
        rho3 = (x["wp"] * x["sq"]) ** 3
        hh = math.copysign(1.0, delta) * (2.0 * delta * (w3 * tw**0.75) ** 2 + 4.0 * k * rho3 * np.sin(phi)) \
            / np.maximum(4.0 * k * rho3, 1e-300)
        h_mean, h_std = float(np.mean(hh)), float(np.std(hh))
        h_drift = float(abs(np.mean(hh[half]) - np.mean(hh[~half])))
        h_end = float(np.mean(hh[x["last"]]))
        q = x["S"]["q"]
        # a rotating transverse phase has h > 1 with a kinetic part ~ tau^(2q + 3/2): for
        # q < -3/4 it reaches the separatrix and locks into the swing at about this tau
        if q < -0.76 and h_end > 1.0:
            ev["lock_to_5_at_tau"] = float(tw[-1] * h_end ** (1.0 / (-2.0 * q - 1.5)))
    ev.update(h_mean=h_mean, h_std=h_std)
    x.update(h_mean=h_mean, h_std=h_std, h_drift=h_drift)


def _scores(x: dict, delta: float, model: str, relax: float = 1.0, slopes=None) -> dict:
    """Each class's score (0..1) from the measurements; ``relax`` widens every slope tolerance
    by that factor (the test of a run still approaching a class), ``slopes`` replaces (p, q)
    (the early half's, to see which way a run moves)."""
    p, q = slopes if slopes is not None else (x["S"]["p"], x["S"]["q"])
    X, Y, sc, g, gr = x["X"], x["Y"], x["sc"], x["gap"], x["gap_random"]
    th, tone, t34 = TOL_HALF * relax, TOL_ONE * relax, TOL_34 * relax
    scores: dict[str, float] = {}
    scores["residual"] = _ramp(x["S"]["s"], -0.15, RES_SLOPE) * (1.0 if x["ang"] < 5.0 else 0.3)
    wn = x["wn"]
    rel13 = float(np.max(np.hypot(x["w"][:, 0], x["w"][:, 2]) / np.maximum(wn, 1e-300)))
    exact39 = rel13 < EXACT_39 and abs(X * math.sqrt(2.0) - 1.0) < 0.01
    x["exact39"] = exact39
    stopped = _ramp(-x["arc_late"], -4.0 * ARC_STOP, -ARC_STOP) * (1.0 if sc == 0.0 else 0.0)
    turning = (1.0 - _ramp(sc, SC_SPIRAL, 2.0 * SC_SPIRAL)) \
        * _ramp(-g, -max(1.2, 2.5 * gr), -max(0.8, 1.5 * gr)) * _ramp(x["turns"], 1.0, 3.0)
    if delta == 0.0:
        # a spherical top does not precess (phi_dot = -delta omega3 = 0): its "spiral" is the
        # straight line of (5.4) at delta = 0 ((6.9)), a fixed direction
        turning = stopped if model == "truncated" else 0.0
    swinging = _ramp(sc, 0.5 * SC_LIBR, SC_LIBR) * _ramp(g, max(0.2, gr), max(0.35, 1.5 * gr))
    y_dom = _ramp(Y / max(X, 1e-300), 1.0, 2.0)
    x_dom = _ramp(X / max(Y, 1e-300), 1.0, 2.0)
    below = _ramp(-p, 0.5 + 0.5 * TOL_SEP, 0.5 + TOL_SEP)            # p clearly below -1/2
    below_q = _ramp(-q, 0.5 + 0.5 * TOL_SEP, 0.5 + TOL_SEP)
    scores["axial-stopped"] = min(stopped, y_dom, _near(q, -0.5, th), _near(p, -1.0, tone))
    scores["axial-spiral"] = min(turning, y_dom, _near(q, -0.5, th), below)
    scores["balanced-spiral"] = min(turning, _near(p, -0.5, th), _near(q, -0.5, th))
    scores["transverse-spiral"] = min(turning, x_dom, _near(p, -0.5, th), below_q)
    centre_ok = 1.0 - _ramp(abs(math.remainder(x["centre"] + math.copysign(0.5 * math.pi, delta or 1.0), 2.0 * math.pi)),
                            0.3, 0.6)
    h_ok = 0.0
    if math.isfinite(x["h_std"]):
        h_ok = (1.0 - _ramp(x["h_std"], 0.05, 0.15)) * (1.0 - _ramp(x["h_drift"], 0.03, 0.1)) \
            * _ramp(-x["h_mean"], -1.0, -0.97)
    scores["libration"] = min(swinging, x_dom, _near(p, -0.5, 1.5 * th), centre_ok, max(h_ok, 0.6 * _near(q, -0.75, t34)))
    frozen3 = _ramp(-q, 1.0, 1.1) if (Y > 0.0 and not exact39 and not x["zero3"]) else 1.0
    scores["transverse-frozen"] = 1.0 if exact39 else min(stopped, x_dom, _near(p, -0.5, th), frozen3)
    return scores


RELAX = 4.0                # slope tolerances x this: "approaching" a class (a slow hand-over), not yet in it


def _verdict(x: dict, scores: dict, delta: float, chi: float, model: str) -> Verdict:
    """The label from the scores: the best class if it is met clearly; else "approaching X"
    when the run is within ``RELAX`` x the tolerances of class X and moving towards it (a slow
    hand-over, e.g. type 3 below delta = -1/2 converging as tau^-0.1); else "other"."""
    ev, S = x["ev"], x["S"]
    best = max(scores, key=scores.get)
    ordered = sorted(scores.values(), reverse=True)
    margin = ordered[0] - ordered[1]
    settle = x["settle"]
    if best == "libration" and math.isfinite(x["h_drift"]):
        settle = 1.0 - _ramp(x["h_drift"], 0.03, 0.1)       # omega3's RMS slope is noisy at random phases
    fit_rms = max(S["res_p"], S["res_q"]) if (S["smooth3"] and math.isfinite(S["res_q"])) else S["res_p"]
    fit_ok = 1.0 - _ramp(fit_rms, 0.05, 0.15) if math.isfinite(fit_rms) else 0.0
    exact39 = x["exact39"]
    exempt = exact39 or best == "residual"                # no power law to fit, nothing to settle
    conf = scores[best] * (1.0 if exempt else settle * fit_ok) * min(1.0, 0.5 + margin)
    ev.update(settled=settle, fit_rms=fit_rms, fit_quality=math.exp(-fit_rms / 0.02) if math.isfinite(fit_rms) else 0.0,
              score=scores[best], margin=margin)
    names = class_labels(model)
    candidate = _candidate(x, scores, best, names)
    label = names[best] if scores[best] > 0.0 else "other"
    if exact39:
        label = candidate = "3.9"
    devs = deviations(label, ev, delta, chi, model)
    finite = [abs(v) for v in devs.values() if math.isfinite(v)]
    ev["deviation"] = max(finite) if finite else math.nan
    if conf < MIN_CONFIDENCE:
        return _unsettled(x, scores, best, settle, fit_ok, delta, model, candidate, conf, devs)
    if label == "3.9" and not exact39:
        return Verdict("other", float(min(conf, 0.45)), candidate,
                       "transverse rotation with a stopped phase, but not (3.9) itself", ev, devs)
    if label in ("T1", "T5"):
        return Verdict("other", float(min(conf, 0.45)), candidate, f"{best} has no counterpart in the truncated model",
                       ev, devs)
    if best == "residual" and x["ang"] >= 5.0:
        return Verdict("other", float(min(conf, 0.45)), candidate, "residual rotation not about d", ev, devs)
    return Verdict(label, float(conf), candidate, f"{best}: score {scores[best]:.2f}, margin {margin:.2f}", ev, devs)


def _candidate(x: dict, scores: dict, best: str, names: dict) -> str:
    """The best class's label even where the run is not labelled, or a mixture."""
    S, X, Y = x["S"], x["X"], x["Y"]
    p, q = S["p"], S["q"]
    if scores[best] >= 0.05:
        return names[best]
    if Y > X and _near(q, -0.5, TOL_HALF) > 0.5 and -1.0 - TOL_ONE < p < -0.5 and x["sc"] == 0.0:
        return "1|2"
    if X > Y and _near(p, -0.5, TOL_HALF) > 0.5 and q < -0.5:
        return "4|5"
    return "none"


def _between_1_and_2(x: dict, model: str):
    """The hand-over between types 2 and 1: omega3 ~ tau^-1/2 dominant and keeping its sign,
    omega_perp falling faster, the phase neither turning freely nor stopped.  omega_perp is
    then the sum of type 1's forced part (B/tau, a fixed phase) and type 2's spiral (tau^alpha,
    turning), beating against each other, so its slope p wanders; whichever falls slower wins:
    p < -1 - TOL_ONE/2 means the spiral dies first (-> type 1), p > -1 + TOL_ONE/2 that it
    outlives the forced part (-> type 2).  Near alpha = -1 the two decay almost together and
    the hand-over takes tens of decades ((0.5, 14 deg): alpha = -1.22).  Returns (class label,
    reason) or None."""
    S = x["S"]
    p, q = S["p"], S["q"]
    if not (x["Y"] > 2.0 * x["X"] and _near(q, -0.5, TOL_HALF) > 0.5 and x["sc"] == 0.0 and p < -0.5 - TOL_SEP):
        return None
    names = class_labels(model)
    if p < -1.0 - 0.5 * TOL_ONE:
        target = "axial-stopped"
    elif p > -1.0 + 0.5 * TOL_ONE:
        target = "axial-spiral"
    else:
        return None
    if names[target] in ("T1", "T5"):
        return None
    return names[target], (f"hand-over between types 2 and 1: omega_perp ~ tau^{p:.2f} beats its forced and spiral "
                           f"parts; approaching {names[target]}")


def _unsettled(x, scores, best, settle, fit_ok, delta, model, candidate, conf, devs) -> Verdict:
    """A run no class meets clearly: "approaching" the class it is within ``RELAX`` x the slope
    tolerances of and moving towards (its late half's slopes closer to the class than its early
    half's), or "other"."""
    ev, S = x["ev"], x["S"]
    names = class_labels(model)
    wide = _scores(x, delta, model, relax=RELAX)
    early = _scores(x, delta, model, relax=RELAX, slopes=(S["p_e"], S["q_e"]))
    late = _scores(x, delta, model, relax=RELAX, slopes=(S["p_l"], S["q_l"]))
    cls = max(wide, key=wide.get)
    towards = late[cls] >= early[cls] and wide[cls] >= 0.5 and cls not in ("residual", "transverse-frozen")
    if towards and names[cls] not in ("T1", "T5", "3.9"):
        c = float(min(0.49, wide[cls] * fit_ok))
        return Verdict("approaching", c, names[cls], f"approaching {cls} ({names[cls]}): within {RELAX:g}x the slope "
                                                     f"tolerances, slopes moving towards it (settled {settle:.2f})", ev, devs)
    handover = _between_1_and_2(x, model)
    if handover is not None:
        return Verdict("approaching", float(min(0.49, fit_ok or 0.3)), handover[0], handover[1], ev, devs)
    why = (f"no class met clearly (best {best} {scores[best]:.2f}, settled {settle:.2f}, fit {fit_ok:.2f})"
           if scores[best] > 0.0 else "no class fits the slopes or the phase")
    return Verdict("other", float(conf), candidate, why, ev, devs)


def deviations(label: str, ev: dict, delta: float, chi: float, model: str = "reduced") -> dict:
    """Relative deviations (measured - formula)/|formula| of the quantities the label's
    formulas fix, keyed by "<quantity> <equation>"."""
    if model == "reduced":
        if label == "1":
            f = FM.type1_eq4_9(delta, chi)
            return {"C^2 (4.9)": _rel(ev["Y2"], f["C2"]), "B (4.9)": _rel(ev["w2_tau"], f["B"])}
        if label == "2":
            f = FM.type2_eq4_14(delta, chi)
            return {"alpha (4.14)": _rel(ev["slope_perp"], f["alpha"]), "B^2 (4.14)": _rel(ev["Y2"], f["B2"])}
        if label == "3":
            f = FM.type3_eq4_16(delta, chi)
            return {"A^2 (4.16)": _rel(ev["X2"], f["A2"]), "B^2 (4.16)": _rel(ev["Y2"], f["B2"])}
        if label == "4":
            f = FM.type4_eq4_18(delta, chi)
            return {"beta (4.18)": _rel(ev["slope_3"], f["beta"]), "A^2 (4.18) corrected": _rel(ev["X2"], f["A2"])}
        if label == "5":
            f = FM.type5_eq4_42(delta, chi)
            if not f["real"]:
                return {}                  # (4.42) has no real solution here (A^2 outside (0, 1])
            return {"A^2 (4.42) peak": _rel(ev["libration_A2"], f["A2"]), "B (4.42)": _rel(ev["libration_B"], f["B"]),
                    "M^2 (4.42) peak": _rel(ev["libration_M2"], f["M2"])}
    else:
        f = FM.truncated_averaged(delta, chi)
        if label == "T4":
            return {"A^2 (averaged)": _rel(ev["X2"], f["T4_A2"]), "beta (averaged)": _rel(ev["slope_3"], f["T4_beta"])}
        if label == "T2":
            return {"B^2 (averaged)": _rel(ev["Y2"], f["T2_B2"]), "alpha (averaged)": _rel(ev["slope_perp"], f["T2_alpha"])}
        if label == "TF":
            return {"omega sqrt(2 tau) sin(d, omega) = 1": _rel(ev["frozen_norm"], 1.0)}
    if label == "3.9":
        return {"omega2^2 2 tau (3.9)": _rel(2.0 * ev["X2"], 1.0)}
    return {}
