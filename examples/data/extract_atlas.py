"""The extract of the figure atlas that the gallery's ``plot_atlas_figure.py`` draws.

The figure atlas takes 13 min 43 s on two cores (2026-11-26), too long for a documentation
build, and its store is ~90 MB.  This script keeps what the atlas's pictures read -- per refinement
level the grid and each run's type at tau_end (``regime``), as tau -> oo (``label_inf``) and
best class (``candidate``); on the coarse level each run's confidence and hand-over time,
the starts, and the stored series of the runs the hodographs show -- in one compressed NumPy file of a few hundred kB::

    spinviz atlas run scenes/atlas_figure.toml --out atlas_figure.zarr
    python examples/data/extract_atlas.py atlas_figure.zarr

It then checks the extract: ``plot_atlas_figure.py``, run from ``examples/`` as the gallery
runs it, must draw from it the very pictures -- pixel for pixel -- that ``spinviz atlas run
--plot`` draws from the store.  Nothing is written unless that holds.
"""

from __future__ import annotations

import argparse
import os
import runpy
import shutil
import sys
import tempfile
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
EXAMPLE = HERE.parent / "plot_atlas_figure.py"
OUT = HERE / "atlas_figure_labels.npz"
PICTURES = ("atlas_figure.png", "atlas_figure_hodographs.png")
LIMIT_BYTES = 2_000_000                       # a generated file committed to the repository


def extract(store: str) -> dict[str, np.ndarray]:
    """The arrays of the extract, from the store at ``store`` (every refinement level)."""
    from spinviz.regimes.figures.draw import open_levels
    from spinviz.regimes.figures.hodographs import representatives

    levels = open_levels(store)
    top = levels[0]
    out = {"levels": np.array(len(levels)), "title": np.array(top.attrs["title"]), "spec": np.array(top.attrs["spec"]),
           "models": top["model"].values.astype(str)}
    for k, ds in enumerate(levels):
        # a run not computed (a refined level computes only the cells it cut) reads "missing", code 0
        out[f"regime_{k}"] = ds["regime"].where(ds["done"] == 1, 0).values.astype(np.int8)
        out[f"label_inf_{k}"] = ds["label_inf"].where(ds["done"] == 1, 0).values.astype(np.int8)
        out[f"candidate_{k}"] = ds["candidate"].values.astype(np.int8)
        out[f"delta_{k}"], out[f"chi_{k}"] = ds["delta"].values, ds["chi"].values
    out["confidence"] = top["confidence"].values.astype(np.float32)
    out["tau_handover"] = top["tau_handover"].values.astype(np.float32)
    out["omega0"], out["tau"] = top["omega0"].values, top["tau"].values
    # the series of the runs the hodographs show; the rest of the array is NaN (compresses to nothing)
    series = np.full(top["series"].shape, np.nan, dtype=np.float32)
    models, deltas, chis = list(top["model"].values), list(top["delta"].values), list(top["chi"].values)
    for model, _, d, c, k, *_ in representatives(top):
        if k < top.sizes["start"]:
            m, i, j = models.index(model), deltas.index(d), chis.index(c)
            series[m, i, j, k] = top["series"].values[m, i, j, k]
    out["series"] = series
    return out


def pictures(directory: Path) -> list[np.ndarray]:
    from PIL import Image

    return [np.asarray(Image.open(directory / name).convert("RGB")) for name in PICTURES]


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("store", help="the figure atlas's store (spinviz atlas run scenes/atlas_figure.toml --out STORE)")
    args = p.parse_args(argv)
    from spinviz.regimes.figures.draw import draw

    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        candidate = tmp / OUT.name
        np.savez_compressed(candidate, **extract(args.store))
        size = candidate.stat().st_size
        if size > LIMIT_BYTES:
            sys.exit(f"{candidate.name}: {size / 1e6:.2f} MB, over the {LIMIT_BYTES / 1e6:g} MB a committed file may take")
        # the store's own pictures, as spinviz atlas run --plot draws them
        (tmp / "store").mkdir()
        draw(args.store, [str(tmp / "store" / name) for name in PICTURES])
        # the example's, from the extract: run from a copy of examples/ as the gallery runs it
        (tmp / "examples" / "data").mkdir(parents=True)
        (tmp / "examples" / EXAMPLE.name).write_text(EXAMPLE.read_text())
        os.replace(candidate, tmp / "examples" / "data" / OUT.name)
        cwd = os.getcwd()
        try:
            os.chdir(tmp / "examples")
            runpy.run_path(EXAMPLE.name, run_name="__main__")
        finally:
            os.chdir(cwd)
        for name, a, b in zip(PICTURES, pictures(tmp / "store"), pictures(tmp / "examples")):
            if a.shape != b.shape or not np.array_equal(a, b):
                diff = "sizes differ" if a.shape != b.shape else f"{int((a != b).any(axis=2).sum())} pixels differ"
                sys.exit(f"{name}: the example's picture from the extract is not the store's ({diff}); nothing written")
        partial = OUT.with_name(f".{OUT.stem}.partial.npz")      # beside OUT: the replace is atomic
        shutil.copyfile(tmp / "examples" / "data" / OUT.name, partial)
        os.replace(partial, OUT)
    print(f"{OUT}: {size / 1e3:.0f} kB; the example draws the store's {' and '.join(PICTURES)} from it, pixel for pixel")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
