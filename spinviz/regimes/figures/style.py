"""How an atlas is drawn, shared by the PNG pictures and the web page: the colour, legend words
and order of every type, and the style of every analytic line."""

from __future__ import annotations

# Okabe & Ito's colour-blind-safe palette; a truncated type shares the colour of the reduced
# type it resembles (T2 ~ 2, Tcone ~ 3, T4 ~ 4, TF ~ the frozen 3.9).
COLORS = {"1": "#0072B2", "2": "#56B4E9", "3": "#009E73", "4": "#E69F00", "5": "#D55E00", "3.9": "#CC79A7",
          "R": "#F0E442", "T2": "#56B4E9", "Tcone": "#009E73", "T4": "#E69F00", "TF": "#CC79A7", "T1": "#0072B2",
          "T5": "#D55E00", "other": "#dddddd", "1|2": "#dddddd", "4|5": "#dddddd", "approaching": "#bbbbbb",
          "failed": "#000000", "missing": "#ffffff"}
ORDER = ("1", "2", "3", "4", "5", "3.9", "R", "T2", "Tcone", "T4", "TF", "approaching", "other", "failed", "missing")
# what each type is, in plain words (the diagram's legend; the paper's section 4 for the formulas)
WORDS = {
    "1": "1: spin about the symmetry axis, the cross spin dies as 1/\u03c4",
    "2": "2: spiral onto the symmetry axis",
    "3": "3: balanced spiral, both parts fall as 1/\u221a\u03c4",
    "4": "4: spiral with the cross spin dominant",
    "5": "5: wobble about a cross axis (libration)",
    "3.9": "(3.9): rotation about e\u2082 itself",
    "R": "R: keeps spinning about the dipole",
    "T2": "T2: slows to rest, spin gathering on the axis",
    "Tcone": "Tcone: slows to rest on a fixed cone",
    "T4": "T4: slows to rest, cross spin dominant",
    "TF": "TF: slows to rest, turning about a fixed cross axis",
}
COEXIST = 0.10             # a type "coexists" in a cell when it holds at least this share next to another


LINE_STYLE = {  # name prefix -> (colour, style, where to write its label: delta)
    "(4.15)": ("k", "-", -0.72), "(4.17)": ("k", "--", -0.38), "(4.20)": ("k", ":", 0.62),
    "(4.43) as printed": ("k", "-.", 0.93), "(4.43) corrected": ("#a3001b", "-.", 0.72),
    "alpha": ("#0b3d91", "-", -0.62), "beta = -3/4": ("#a3001b", "-", 0.3),
    "delta = 0": ("#0b3d91", "-", 0.0), "beta_T": ("#a3001b", "-", 0.75),
}

# delta = 1 - I3/I1 > 0 is a prolate top (I3 < I1: a rod), delta < 0 an oblate one (a plate)
DELTA_AXIS = "\u03b4 = 1 \u2212 I\u2083/I\u2081   (oblate \u2190 0 \u2192 prolate)"
