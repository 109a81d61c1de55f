"""What a run records about its limit tau -> oo, beside its label: where it left full
integration for the averaged flow, how far the averaged flow is trusted, the amplitudes it
reached, the 1-versus-2 ratio, whether it has settled, and the flags that say when a run stops
being evidence.  The hand-over engine (``handover``) fills them; a run of the brute-force
engine (``runs``) carries them blank (NaN, 0), except what its samples tell (``label_inf``).
The store (``store.dataset``) describes each one.

And how a handed-over run stands against its attractor (``limit_of``), the classifier's
evidence read from the averaged flow (``evidence``), where its free/forced ratio crosses 1
(``crossing``), and its omega series rebuilt from the averaged amplitudes (``reconstruct``).
"""

from __future__ import annotations

import math

import numpy as np

from . import classify as C

SETTLED = 0.05              # ln-distance (or share of a dying component) to the attractor below which a run is settled
R_ONE, R_TWO = 0.1, 10.0    # free/forced ratio below which omega_perp is type 1's forced response, above it type 2's spiral

# name -> (dtype, fill where a run has nothing to say)
RECORDS = {
    "tau_handover": ("float64", math.nan),
    "mu_handover": ("float64", math.nan),
    "bound": ("float64", math.nan),
    "abar_end": ("float64", math.nan),
    "bbar_end": ("float64", math.nan),
    "free_forced_ratio": ("float64", math.nan),
    "tau_1_2": ("float64", math.nan),
    "limit_settled": ("int8", 0),
    "decades_to_settle": ("float64", math.nan),
    "label_inf": ("int8", 0),
    "noise_floor": ("float64", math.nan),
    "spiral_unresolved": ("int8", 0),
    "returned_to_full": ("int8", 0),
}


def blank(shape: tuple) -> dict:
    """The records of ``shape`` runs, every one at its fill value."""
    return {name: np.full(shape, fill, dtype=dtype) for name, (dtype, fill) in RECORDS.items()}


def ln_ratio(flow, lnA, lnB, s):
    """ln of the free/forced ratio |zbar|/|z_f| at (ln A, ln B) of (LV) at s = ln tau
    (``Flow.free_forced_ratio``, in logs: no overflow)."""
    return 0.5 * lnA + math.log(abs(flow.delta) / abs(flow.F)) + 0.5 * s - lnB


# --- labels from the limit -------------------------------------------------------------------
def _distance(state, lnA: float, lnB: float) -> tuple[float, float]:
    """(distance to the attractor, its approach rate per unit s): ln-distance of the surviving
    amplitudes, share sqrt(A/B*) (or sqrt(B/A*)) of a dying one, whichever is farther, with
    the rate that governs it."""
    lam_across, lam_slow = abs(state.eigenvalues[0]), abs(state.slowest)
    if state.name == "axial":
        d_log, d_share = abs(lnB - math.log(state.B)), math.exp(0.5 * (lnA - math.log(state.B)))
        return max((d_log, 1.0), (d_share, 0.5 * lam_across))
    if state.name == "transverse":
        d_log, d_share = abs(lnA - math.log(state.A)), math.exp(0.5 * (lnB - math.log(state.A)))
        return max((d_log, 1.0), (d_share, 0.5 * lam_across))
    return max(abs(lnA - math.log(state.A)), abs(lnB - math.log(state.B))), lam_slow


def _decades(dist: float, rate: float) -> float:
    return 0.0 if dist < SETTLED else math.log(dist / SETTLED) / (rate * math.log(10.0))


def crossing(flow, r: dict, tau: np.ndarray) -> float:
    """tau at which a handed-over run's free/forced ratio crosses 1 -- found along its averaged
    run (``averaged_stage``'s dict ``r``), else extrapolated beyond the end as tau^(alpha + 1);
    NaN if it moves away from 1 (or there is no forced response)."""
    if flow.F == 0.0 or flow.delta == 0.0:
        return math.nan
    s = np.log(tau[r["idx"]])
    lr = ln_ratio(flow, r["lnA"], r["lnB"], s)
    ch = np.flatnonzero(np.sign(lr[1:]) != np.sign(lr[:-1]))
    if ch.size:
        k = int(ch[-1])
        return float(math.exp(s[k] - lr[k] * (s[k + 1] - s[k]) / (lr[k + 1] - lr[k])))
    e = flow.ratio_exponent
    if not math.isfinite(e) or e == 0.0 or lr[-1] * e > 0.0:
        return math.nan
    x = s[-1] - lr[-1] / e
    return math.exp(x) if x < 700.0 else math.inf


def limit_of(flow, state, lnA: float, lnB: float, s: float, unresolved_factor: float = 1.0) -> dict:
    """How a handed-over run stands at s = ln tau: ``label``, ``label_inf``, ``settled``,
    ``decades`` (still needed to settle), ``ratio`` (free/forced, or NaN).  On the reduced
    axial state the limit is "1" iff alpha + 1 < 0, and settling needs the ratio past R_ONE
    (limit 1) or R_TWO (limit 2); ``unresolved_factor`` > 1 scales the ratio up to its noise
    bound (a free spiral below the noise floor)."""
    dist, rate = _distance(state, lnA, lnB)
    decades = _decades(dist, rate)
    label, inf, ratio = state.label, state.label, math.nan
    if state.name == "axial" and flow.model == "reduced" and flow.F != 0.0:
        lr = ln_ratio(flow, lnA, lnB, s) + math.log(unresolved_factor)
        ratio = math.exp(min(lr, 700.0))
        e = flow.ratio_exponent
        label = "1" if lr < math.log(R_ONE) else "2" if lr > math.log(R_TWO) else "1|2"
        target = math.log(R_ONE) if e < 0.0 else math.log(R_TWO)
        if (e < 0.0 and lr > target) or (e >= 0.0 and lr < target):
            decades = max(decades, abs(lr - target) / (abs(e) * math.log(10.0)) if e != 0.0 else math.inf)
    return {"label": label, "label_inf": inf, "settled": decades == 0.0, "decades": decades, "ratio": ratio}


def evidence(flow, label: str, lnA: float, lnB: float, s: float, early: tuple, sign_b: float, turns: float) -> dict:
    """The classifier's evidence (``classify.EVIDENCE``) of a handed-over run, read from (LV)
    at s = ln tau_end (and at the window's start for the drift): the true omega_perp^2 tau
    (free spiral and forced response: X2), omega3^2 tau (Y2), the instantaneous exponents of
    omega_perp, omega3, |omega| (the slopes), the forced response's omega2 tau and omega1
    tau^3/2 ((4.9)'s B and A), the deviations from the label's formulas.  ``early``: (ln A,
    ln B, s) at the window's start."""
    def slopes(lnA, lnB, s):
        A, B = math.exp(lnA), math.exp(lnB)
        w3 = sign_b * math.sqrt(B) * math.exp(-0.5 * s)
        zf = complex(flow.forced_response(w3))
        Af = abs(zf) ** 2 * math.exp(s)
        gA, gB = flow.lv(lnA, lnB)
        gAf = 2.0 * gB - 1.0
        X2 = A + Af
        p = 0.5 * (A * gA + Af * gAf) / X2 - 0.5 if X2 > 0.0 else -math.inf
        q = 0.5 * gB - 0.5
        sn = 0.5 * (A * gA + Af * gAf + B * gB) / (X2 + B) - 0.5
        return p, q, sn, X2, B, zf
    p, q, sn, X2, Y2, zf = slopes(lnA, lnB, s)
    pe, qe, _, _, _, _ = slopes(*early)
    drift = max(abs(p - pe) if math.isfinite(p - pe) else 0.0, abs(q - qe))
    ev = {k: math.nan for k in C.EVIDENCE}
    tau = math.exp(s)
    ev.update(slope_perp=p, slope_3=q, slope_norm=sn, slope_drift=drift,
              settled=1.0 - C._ramp(drift, C.DRIFT, 3.0 * C.DRIFT), fit_rms=0.0, fit_quality=1.0, X2=X2, Y2=Y2,
              w2_tau=zf.imag * tau, w1_tau32=zf.real * tau**1.5, phi_arc=2.0 * math.pi, w3_sign_changes=0.0,
              turns=turns, score=1.0, margin=1.0)
    devs = C.deviations(label, ev, flow.delta, flow.chi, flow.model)
    finite = [abs(v) for v in devs.values() if math.isfinite(v)]
    ev["deviation"] = max(finite) if finite else math.nan
    return ev


def phase_advance(flow, r: dict, tau: np.ndarray) -> np.ndarray:
    """The averaged phase of a handed-over run at its samples: phi_h - delta int omega3_bar
    dtau ((4.12): d phi_bar/dtau = -delta omega3_bar; omega3 dtau = b e^{s/2} ds), by the
    trapezoid rule on the samples -- a reconstruction for the pictures, not a resolved phase."""
    s = np.log(tau[r["idx"]])
    f = np.exp(0.5 * r["lnB"] + 0.5 * s)
    cum = np.concatenate([[0.0], np.cumsum(0.5 * (f[1:] + f[:-1]) * np.diff(s))])
    return r["phase_h"] - flow.delta * r["sign_b"] * cum


def reconstruct(flow, r: dict, tau: np.ndarray, last_only: bool = False) -> np.ndarray:
    """omega (k, 3) of a handed-over run at its samples from the hand-over on (``last_only``:
    at its last): the averaged amplitudes with the averaged phase (``phase_advance``), back
    through the near-identity transform (the forced response included).  Only the amplitudes
    are physical."""
    k = slice(-1, None) if last_only else slice(None)
    t = tau[r["idx"]][k]
    sq = np.sqrt(t)
    zbar = np.exp(0.5 * r["lnA"][k]) / sq * np.exp(1j * phase_advance(flow, r, tau)[k])
    z, w3 = flow.to_true(zbar, r["sign_b"] * np.exp(0.5 * r["lnB"][k]) / sq)
    return np.stack([z.real, z.imag, w3], axis=-1)
