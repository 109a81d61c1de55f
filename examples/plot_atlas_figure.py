"""
The regime atlas of the paper's figures 2, 3.D and 5
====================================================

Which asymptotic type of the paper's section 4 does a symmetric top end in, for every
elongation δ = 1 − I3/I1 and dipole tilt χ, under each equation of motion?  The figure
atlas (``scenes/atlas_figure.toml``) answers as τ → ∞ at 32 × 32 cells × 32 random starts,
both models: each run integrated in full until the flow averaged over the precession holds,
then carried by it to τ = 1e16, its type as τ → ∞ the attractor it is in; every cell along a
change of type cut in four, twice (128 × 128 there): 206 464 runs, 13 min 43 s on
2026-11-26 on this project's two cores -- too long for a documentation build::

    spinviz atlas run scenes/atlas_figure.toml --out atlas_figure.zarr --plot atlas_figure.png

So this example reads a small extract of that store, committed beside it
(``examples/data/atlas_figure_labels.npz``, made by ``examples/data/extract_atlas.py``, which
checks that this very script draws from it the same diagram, pixel for pixel, as
``--plot`` draws from the store): each run's type and, for the hodographs, the confidence of
each run and the series of the runs they show.  The pictures are drawn here, by the same
functions ``spinviz atlas run --plot`` calls.  What the diagram says, and where it disagrees
with the paper: the :doc:`regime atlas page <../atlas>`.
"""

# %%
# The extract: per refinement level, the grid and each run's type code at τ_end (``regime``)
# and as τ → ∞ (``label_inf``), and its best class (``candidate``, which type an
# "approaching" run approaches), as (model, delta, chi, member) arrays; the spec of the
# atlas as JSON.
import json

import numpy as np
import xarray as xr

from spinviz import regimes

saved = np.load("data/atlas_figure_labels.npz")
spec = json.loads(str(saved["spec"]))
print(str(saved["title"]))
print(f"{len(spec['delta'])} x {len(spec['chi'])} cells, {spec['members']['count']} starts each "
      f"(|omega0| = {spec['members']['omega']}), models {spec['models']}, tau_end = {spec['run']['tau_end']:g}, "
      f"refined {spec.get('refine', {}).get('levels', 0)} time(s) where the types change")

# %%
# Each level as the Dataset ``spinviz.atlas`` returns (``label`` and ``limit_label``: the
# types' names, as ``store.open_atlas`` decodes them), the coarse grid first.
NAMES = {code: name for name, code in regimes.TYPE_CODES.items()}
DIMS = ("model", "delta", "chi", "member")
levels = []
for k in range(int(saved["levels"])):
    regime = saved[f"regime_{k}"]
    levels.append(xr.Dataset(
        {"label": (DIMS, np.vectorize(NAMES.get, otypes=[str])(regime)),
         "limit_label": (DIMS, np.vectorize(NAMES.get, otypes=[str])(saved[f"label_inf_{k}"])),
         "candidate": (DIMS, saved[f"candidate_{k}"])},
        coords={"model": saved["models"], "delta": saved[f"delta_{k}"], "chi": saved[f"chi_{k}"],
                "member": np.arange(regime.shape[-1])},
        attrs={"title": str(saved["title"]), "spec": str(saved["spec"])}))
    print(f"level {k}: {regime.shape[1]} x {regime.shape[2]} cells, {int((regime != 0).sum())} runs")
coarse = levels[0].assign(
    confidence=(DIMS, saved["confidence"]),
    tau_handover=(DIMS, saved["tau_handover"].astype(float)),
    omega0=(("member", "axis"), saved["omega0"]),
    series=(("model", "delta", "chi", "start", "sample", "axis"), saved["series"]))
levels[0] = coarse.assign_coords(tau=("sample", saved["tau"]), start=np.arange(saved["series"].shape[3]))

# %%
# The share of each type as τ → ∞ over the coarse grid, per model, counted as the diagram
# counts it (a run still approaching a type counts for that type; "failed": truncated starts too close
# to that equation's singular surface, near δ = 1, refused rather than integrated through it).
for model in levels[0]["model"].values:
    by_type = {name: 100 * float(s.mean()) for name, s in regimes.shares(levels[0], str(model)).items()}
    print(f"{model:>9}: " + ", ".join(f"{name} {p:.1f} %" for name, p in sorted(by_type.items(), key=lambda kv: -kv[1])))

# %%
# The δ–χ diagram, both models side by side: each cell split into bars as wide as the
# shares of its starts' types as τ → ∞ (hatched: a run integrated in full still approaching
# its type at τ_end; a dot: two types coexist among the starts); thick lines are sharp
# boundaries, a band under a line a coexistence band; black, the paper's boundaries as
# printed; blue and red, the lines spinviz derived; grey, the DAST families of figure 5.
regimes.diagram(levels, "atlas_figure.png")

# %%
# The hodographs of the most confident run of each type: ω·√(τ + 1/ω₀²) in the body frame
# (ω₀ the starting spin rate), as the paper's figure 3 draws them; a ring marks where a run
# went over to the averaged flow (after it, the amplitudes are the run's, the phase the
# averaged one).
regimes.hodographs(levels[0], "atlas_figure_hodographs.png")
