"""What a run records about its limit tau -> oo, beside its label: where it left full
integration for the averaged flow, how far the averaged flow is trusted, the amplitudes it
reached, the 1-versus-2 ratio, whether it has settled, and the flags that say when a run stops
being evidence.  The hand-over engine (``handover``) fills them; a run of the brute-force
engine (``runs``) carries them blank (NaN, 0), except what its samples tell (``label_inf``).
The store (``store.dataset``) describes each one.

And how a handed-over run stands against its attractor (``limit_of``), where its free/forced
ratio crosses 1 (``crossing``), and its omega series rebuilt from the averaged amplitudes
(``reconstruct``), on which the classifier labels its state at tau_end.
"""

from __future__ import annotations

import math

import numpy as np

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


def phase_advance(flow, r: dict, tau: np.ndarray) -> np.ndarray:
    """The averaged phase of a handed-over run at its samples: phi_h - delta int omega3_bar
    dtau ((4.12): d phi_bar/dtau = -delta omega3_bar; omega3 dtau = b e^{s/2} ds), by the
    trapezoid rule on the samples -- a reconstruction for the pictures, not a resolved phase."""
    s = np.log(tau[r["idx"]])
    f = np.exp(0.5 * r["lnB"] + 0.5 * s)
    cum = np.concatenate([[0.0], np.cumsum(0.5 * (f[1:] + f[:-1]) * np.diff(s))])
    return r["phase_h"] - flow.delta * r["sign_b"] * cum


GOLDEN = math.pi * (3.0 - math.sqrt(5.0))   # rad: the golden angle, the most evenly spread steps round a circle


def reconstruct(flow, r: dict, tau: np.ndarray, last_only: bool = False, spread: bool = False) -> np.ndarray:
    """omega (k, 3) of a handed-over run at its samples from the hand-over on (``last_only``:
    at its last): the averaged amplitudes with the averaged phase (``phase_advance``), back
    through the near-identity transform (the forced response included).  Only the amplitudes
    are physical.  ``spread``: the free spiral's phase steps by the golden angle from sample
    to sample instead -- for the classifier, which judges a phase by how it fills the circle:
    between two samples it turns thousands of times, and the averaged phase's exactly
    geometric progression in sqrt(tau) leaves empty arcs no real phase shows (gaps of 1.5-1.8
    rad among 41 samples in ~1 % of runs), so a turning spiral read "other"."""
    k = slice(-1, None) if last_only else slice(None)
    t = tau[r["idx"]][k]
    sq = np.sqrt(t)
    phase = r["phase_h"] + GOLDEN * np.arange(len(r["idx"])) if spread else phase_advance(flow, r, tau)
    zbar = np.exp(0.5 * r["lnA"][k]) / sq * np.exp(1j * phase[k])
    z, w3 = flow.to_true(zbar, r["sign_b"] * np.exp(0.5 * r["lnB"][k]) / sq)
    return np.stack([z.real, z.imag, w3], axis=-1)
