"""What a run records about its limit tau -> oo, beside its label: where it left full
integration for the averaged flow, how far the averaged flow is trusted, the amplitudes it
reached, the 1-versus-2 ratio, whether it has settled, and the flags that say when a run stops
being evidence.  The hand-over engine (``handover``) fills them; a run of the brute-force
engine (``runs``) carries them blank (NaN, 0), except what its samples tell (``label_inf``).
The store (``store.dataset``) describes each one.
"""

from __future__ import annotations

import math

import numpy as np

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
