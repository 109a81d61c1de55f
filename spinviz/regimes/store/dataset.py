"""The atlas on disk: an xarray Dataset in a Zarr store, written region by region.

Layout (dims ``model``, ``delta``, ``chi``, ``member``; ``axis`` = 1, 2, 3; ``quantity`` =
``classify.EVIDENCE``; ``formula`` = ``FORMULAS``)::

    regime, regime_early, candidate   int8   label codes at tau_end, what the state shows there (flag_values /
                                             flag_meanings; 0 = not computed yet); ``label_inf`` is the limit
    status, method                    int8   how the run ended (``runs.STATUS_TEXT``), the integrator
    confidence, tau_reached, run_seconds  float64
    nsteps, nfev                      int64
    reason                            <U96   why the label (or the failure), one line
    evidence                          float64 (..., quantity): slopes, amplitudes, phase statistics
    omega_final                       float64 (..., axis): omega at tau_reached
    done                              int8   1 once the run's results are on disk
    tau_handover, ..., label_inf      the run's limit (``LIMIT``: hand-over, bound, averaged end amplitudes,
                                      free/forced ratio, settling, limit label, noise flags)
    omega0                            float64 (member, axis): the starts, the same at every cell
    paper                             float64 (delta, chi, formula): the formulas' predictions

Attributes: ``spec`` (canonical JSON), ``spec_sha256`` (identity: the hash of every setting
that changes the numbers, the classifier's version among them), ``grid_axes`` (the grid's
{min, max, cells}, from which the refinement levels' grids follow), ``seed``,
``spinviz_version``, ``classifier_version``, ``title``.  Every refinement level's store carries
its own ``spec_sha256`` (of its level's spec), so a level from another atlas is told apart
(``levels``).  Zarr format 2 with consolidated metadata, so plain
``xarray.open_zarr(path)`` opens it with no warning.

Safety.  The store is created complete but empty in a temporary directory and renamed into
place, so a path either holds a whole atlas skeleton or nothing.  Results are written as they
arrive, one storage chunk (one model, one delta, a row of chi, the members) at a time and
whole (its earlier runs read back first when it was written in part before), each chunk file
atomically (Zarr writes a temporary file and renames it), with stop signals held back for the
few milliseconds of the write, ``done`` last and the chunk's checksums after it
(``integrity``): a run counts as computed only when everything it produced is on disk and
vouched for.  Only results count: a task lost with a worker or the scheduler is never
written.  A later run of the same spec verifies the checksums, recomputes the runs of any
chunk that does not match, and computes what ``done`` lacks; a store of another spec is
refused, never mixed.
"""

from __future__ import annotations

import json
import math
import os
import shutil
import tempfile
import time
from dataclasses import dataclass

import numpy as np

from ...errors import UsageError, printable
from ...interrupt import deferred
from ...physics import asymptotics as FM
from ..engine import classify as C
from ..engine import limit as LM
from ..engine import runs as RN
from ..faults import StoreDamaged
from . import integrity as IN

DIMS = ("model", "delta", "chi", "member")
PER_RUN = {            # name -> (dtype, description)
    "regime": ("int8", "the type the run's state shows at tau_reached (see flag_meanings): the classifier's label on "
                       "its last window_decades of samples -- a handed-over run's rebuilt from the averaged flow; "
                       "label_inf is where it goes; 0 = not computed yet"),
    "regime_early": ("int8", "the same run's label window_decades before its end (agreement = the label held)"),
    "candidate": ("int8", "the best class even where regime is 'other' (or a mixture 1|2, 4|5)"),
    "status": ("int8", "how the run ended (flag_meanings)"),
    "method": ("int8", "integrator (flag_meanings)"),
    "confidence": ("float64", "0..1: how sure the label is (labels below 0.5 are 'other')"),
    "tau_reached": ("float64", "last sample, tau = t/tau0 (tau_end unless stopped early or out of steps)"),
    "run_seconds": ("float64", "wall time of the run (integration and classification), s"),
    "nsteps": ("int64", "accepted steps"),
    "nfev": ("int64", "right-hand-side evaluations"),
    "reason": (f"<U{RN.REASON_CHARS}", "why this label, or why the run failed"),
    "done": ("int8", "1 once the run's results are on disk"),
}
# What a run says about its limit tau -> oo (engine.limit; the hand-over engine fills them, a
# brute-force run leaves them blank, NaN or 0, but for label_inf)
LIMIT = {
    "tau_handover": "tau where the run left full integration for the averaged flow (NaN: in full to tau_end)",
    "mu_handover": "the averaged flow's small parameter mu = |omega|^2/|delta omega3| (x max(1, |omega|/|omega3|), "
                   "reduced) at the hand-over",
    "bound": "stated bound on the error of abar_end, bbar_end: 0.2 mu_handover^2 |(a, b)| + min(a, b) (mu_handover^2 + "
             "int mu^2 d ln tau) / min(1, 1 - delta) + noise_floor (+ type 1's ln tau drift on the reduced axial state)",
    "abar_end": "averaged omega_perp sqrt(tau) at tau_end (through the near-identity transform; NaN where it does not hold)",
    "bbar_end": "averaged omega3 sqrt(tau) at tau_end, signed",
    "free_forced_ratio": "free spiral / forced response of omega_perp at tau_end (reduced axial state: type 2's part "
                         "against type 1's); it goes as tau^(alpha + 1)",
    "tau_1_2": "tau where the free/forced ratio crosses 1 (extrapolated as tau^(alpha + 1) beyond tau_end; inf: never "
               "in float64; NaN: it moves away from 1 or does not apply)",
    "limit_settled": "1: within 5 % (ln A, ln B) of the attractor and, on the reduced axial state, the ratio past 0.1 "
                     "(limit 1) or 10 (limit 2); full runs: the label held over the last two windows",
    "decades_to_settle": "decades beyond tau_end still needed to settle (from the attractor's eigenvalues and alpha + 1)",
    "label_inf": "the type as tau -> oo (flag_meanings): a handed-over run's attractor, settled or not (regime says "
                 "what its state shows at tau_end); for runs in full their label, a type-4 run where beta < -3/4 "
                 "counted as 5 (captured into the libration)",
    "noise_floor": "global error of the full stage at hand-over, scaled amplitudes (the cell's first handed-over "
                   "runs of the task rerun at rtol/100); NaN: not measured",
    "spiral_unresolved": "1: the free spiral at hand-over is below 10 x the noise floor (or the transform's residual): "
                         "not evidence for 1 versus 2",
    "returned_to_full": "1: the averaged flow stopped holding (mu > 3 mu_star) before tau_end; integrated in full again",
}
PER_RUN.update({name: (LM.RECORDS[name][0], desc) for name, desc in LIMIT.items()})
FORMULAS = (
    "C2 (4.9)", "B (4.9)", "A (4.9) for C > 0",
    "alpha (4.14)", "B2 (4.14)", "in (4.15)",
    "A2 (4.16)", "B2 (4.16)", "in (4.17)",
    "beta (4.18)", "A2 (4.18) corrected", "A2 (4.18) printed", "in (4.19)", "in (4.20)",
    "A2 (4.42)", "B (4.42)", "M2 (4.42)", "K (4.45) printed", "in (4.43)",
    "truncated T4 A2", "truncated T4 beta", "truncated T2 B2", "truncated T2 alpha",
)
RUN_VARIABLES = tuple(PER_RUN) + ("evidence", "omega_final")   # what a run writes (``done`` among them)
SERIES = "series"          # omega(tau) of a cell's first members (``[output].series``), when the spec keeps any


def run_variables(path: str) -> tuple:
    """The per-run variables of the store at ``path``: ``RUN_VARIABLES``, and ``series`` where kept."""
    return RUN_VARIABLES + ((SERIES,) if os.path.isdir(os.path.join(path, SERIES)) else ())


def predictions(delta: float, chi: float) -> list[float]:
    """The ``FORMULAS`` at one cell (flags as 1.0 / 0.0)."""
    t1, t2, t3 = FM.type1_eq4_9(delta, chi), FM.type2_eq4_14(delta, chi), FM.type3_eq4_16(delta, chi)
    t4, t5, tr = FM.type4_eq4_18(delta, chi), FM.type5_eq4_42(delta, chi), FM.truncated_averaged(delta, chi)
    q = delta > 0.0 and math.tan(chi) ** 2 > FM.xi_eq4_20(delta)
    return [t1["C2"], t1["B"], t1["A_for_C_positive"], t2["alpha"], t2["B2"], float(t2["in_domain"]),
            t3["A2"], t3["B2"], float(t3["in_domain"]), t4["beta"], t4["A2"], t4["A2_printed"], float(t4["in_domain"]),
            float(q), t5["A2"], t5["B"], t5["M2"], t5["K_printed"], float(t5["in_domain"]),
            tr["T4_A2"], tr["T4_beta"], tr["T2_B2"], tr["T2_alpha"]]


def _flags(names) -> dict:
    return {"flag_values": list(names.keys()), "flag_meanings": " ".join(str(v).replace(" ", "_") for v in names.values())}


def template(spec, chunks: tuple, sha256: str):
    """The empty Dataset of ``spec`` (dask-backed, so writing it writes only metadata), stored
    in ``chunks`` and carrying ``sha256`` (``levels.identity``) as its identity."""
    # Long on purpose: every variable, coordinate and attribute of the store declared in one place
    import dask.array as da
    import xarray as xr

    from ... import __version__

    shape = (len(spec.models), len(spec.deltas), len(spec.chis), spec.members)
    label_flags = _flags({C.CODE[k]: k for k in C.LABELS})
    data = {}
    for name, (dtype, desc) in PER_RUN.items():
        fill = "" if dtype.startswith("<U") else (np.nan if dtype == "float64" else 0)
        arr = da.full(shape, fill, dtype=dtype, chunks=chunks)
        attrs = {"description": desc}
        if name in ("regime", "regime_early", "candidate", "label_inf"):
            attrs.update(label_flags)
        elif name == "status":
            attrs.update(_flags(RN.STATUS_TEXT))
        elif name == "method":
            attrs.update(_flags({v: k for k, v in RN.METHOD_CODE.items()}))
        data[name] = (DIMS, arr, attrs)
    data["evidence"] = (DIMS + ("quantity",), da.full(shape + (len(C.EVIDENCE),), np.nan, chunks=chunks + (-1,)),
                        {"description": "the classifier's measurements (see the quantity coordinate and classify.EVIDENCE)"})
    data["omega_final"] = (DIMS + ("axis",), da.full(shape + (3,), np.nan, chunks=chunks + (-1,)),
                           {"description": "body-frame omega at tau_reached (dimensionless)"})
    if spec.series:
        n = len(spec.settings.times())
        data[SERIES] = (("model", "delta", "chi", "start", "sample", "axis"),
                        da.full(shape[:3] + (spec.series, n, 3), np.nan, dtype=np.float32,
                                chunks=chunks[:3] + (spec.series, n, 3)),
                        {"description": "omega(tau) of the first members of every cell, body frame, dimensionless "
                                        "(float32; samples at the coordinate tau); the hodographs read these"})
    data["omega0"] = (("member", "axis"), np.asarray(spec.omega0, dtype=float),
                      {"description": "body-frame omega(0), the same at every cell and model (dimensionless)"})
    pred = np.array([[predictions(float(d), float(c)) for c in spec.chis] for d in spec.deltas], dtype=float)
    data["paper"] = (("delta", "chi", "formula"), pred,
                     {"description": "the paper's formulas at each cell ((4.18)'s A2 also corrected; truncated: "
                                     "spinviz's averaged flow); flags are 1/0"})
    coords = {
        "model": list(spec.models),
        "delta": ("delta", np.asarray(spec.deltas, dtype=float), {"long_name": "delta = 1 - I3/I1 (3.6)"}),
        "chi": ("chi", np.asarray(spec.chis, dtype=float), {"long_name": "dipole angle from e3 (3.2)", "units": "rad"}),
        "chi_deg": ("chi", np.degrees(spec.chis), {"units": "deg"}),
        "member": np.arange(spec.members),
        "axis": ["1", "2", "3"],
        "quantity": list(C.EVIDENCE),
        "formula": list(FORMULAS),
    }
    if spec.series:
        coords["start"] = np.arange(spec.series)
        coords["tau"] = ("sample", spec.settings.times(), {"long_name": "tau = t/tau0 of the series' samples"})
    s = spec.settings
    attrs = {
        "title": spec.title or os.path.basename(spec.path),
        "spec": spec.canonical_json(),
        "spec_sha256": sha256,
        **({"grid_axes": json.dumps({k: list(v) for k, v in spec.axes.items()})} if spec.axes else {}),
        "seed": -1 if spec.seed is None else int(spec.seed),
        "spinviz_version": __version__,
        "classifier_version": C.VERSION,
        "method": (f"{RN.METHOD} (heyoka batch mode, Euler equation only, on omega sqrt(1 + tau/T)), rtol {s.rtol:g}"
                   + (", handed over to the averaged flow where it holds (engine handover)" if s.engine == "handover"
                      else "")),
        "conventions": "dimensionless (4.1): tau = t/tau0, omega = tau0 Omega; body frame; J = (1, 1, 1 - delta), "
                       "d = (sin chi, 0, cos chi)",
    }
    return xr.Dataset(data, coords=coords, attrs=attrs)


def create(spec, path: str, chunks: tuple, sha256: str) -> None:
    """Write the empty store of ``spec`` at ``path`` atomically (temporary sibling, then
    rename): chunked as ``chunks`` (``levels.chunk_shape``), carrying ``sha256``."""
    parent = os.path.dirname(os.path.abspath(path)) or "."
    os.makedirs(parent, exist_ok=True)
    # .NAME.XXXXXXXX.partial: what a kill before the rename leaves, recognised by that name
    # (integrity.creation_leftover) and removed by the next atlas command on this store
    tmp = tempfile.mkdtemp(prefix=f".{os.path.basename(os.path.abspath(path))}.", suffix=".partial", dir=parent)
    try:
        store = os.path.join(tmp, "atlas.zarr")
        template(spec, chunks, sha256).to_zarr(store, mode="w-", compute=False, zarr_format=2, consolidated=True)
        IN.record_skeleton(store)                      # checksums of the skeleton, inside the store before it lands
        with deferred():
            if os.path.exists(path):
                raise UsageError(f"{path}: appeared while the atlas was being created; not overwritten")
            os.rename(store, path)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def level_path(out: str, k: int) -> str:
    """Where level ``k`` of the atlas at ``out`` is kept (inside it: a Zarr subgroup)."""
    return out if k == 0 else os.path.join(out, f"level{k}")


def stored_levels(out: str) -> list[str]:
    """The stores of an atlas's levels that exist: ``out`` itself, then ``levelK`` for
    K = 1, 2, ... up to the first one missing."""
    paths = [out]
    while os.path.exists(os.path.join(level_path(out, len(paths)), ".zgroup")):
        paths.append(level_path(out, len(paths)))
    return paths


def done_mask(path: str) -> np.ndarray:
    """Which runs are on disk, shape (model, delta, chi, member), bool."""
    import zarr

    return np.asarray(zarr.open_group(path, mode="r", zarr_format=2)["done"][...]) == 1


def regime_codes(path: str) -> np.ndarray:
    """The label codes of every run, shape (model, delta, chi, member), int8 (0 = not computed)."""
    import zarr

    return np.asarray(zarr.open_group(path, mode="r", zarr_format=2)["regime"][...])


def chunks_of(path: str) -> tuple:
    """The storage chunk shape of the store's per-run variables (model, delta, chi, member)."""
    import zarr

    return tuple(zarr.open_group(path, mode="r", zarr_format=2)["regime"].chunks)


@dataclass
class _Pending:
    """Results of one storage chunk waiting to be written."""

    parts: list
    since: float
    expected: int


class Writer:
    """Writes batch results into the store: a storage chunk as soon as all its batches are
    in, and whatever has waited ``flush_s`` seconds; ``close()`` writes everything still
    waiting (also on an interrupt: those are finished results).

    ``expected`` : chunk index (model, delta, chi block, member block) -> batches in it.
    A chunk is written whole, one file per variable: its earlier runs are read back first
    if this write does not cover all of it; then ``done``; then its checksums."""

    def __init__(self, path: str, expected: dict, flush_s: float = 30.0):
        import zarr

        self.path = path
        self.group = zarr.open_group(path, mode="r+", zarr_format=2)
        self.variables = run_variables(path)
        self.arrays = {k: self.group[k] for k in self.variables}
        self.shape = tuple(self.arrays["done"].shape)
        self.chunks = tuple(self.arrays["done"].chunks)
        self.expected = expected
        self.pending: dict = {}
        self.flush_s = flush_s
        self.written_runs = 0
        self.write_s = 0.0                    # wall time inside _write (data, done, checksums)
        self.checksum_s = 0.0                 # of which: hashing and recording the checksums
        self.chunk_writes = 0

    def add(self, chunk_key, result: dict) -> None:
        """Take one batch's result; write its chunk once every batch of the chunk has arrived."""
        p = self.pending.setdefault(chunk_key, _Pending([], time.monotonic(), self.expected[chunk_key]))
        p.parts.append(result)
        if len(p.parts) >= p.expected:
            self._write(chunk_key)
        else:
            self.flush(older_than=self.flush_s)

    def flush(self, older_than: float = 0.0) -> None:
        """Write the chunks whose results have waited at least ``older_than`` seconds (0: all of them)."""
        now = time.monotonic()
        for key in [k for k, p in self.pending.items() if now - p.since >= older_than]:
            self._write(key)

    def close(self) -> None:
        """Write every pending chunk; the store is then complete for what arrived."""
        self.flush(0.0)

    def _write(self, key) -> None:
        p = self.pending.pop(key)
        t0 = time.perf_counter()
        region = IN.chunk_region(key, self.shape, self.chunks)
        lo = [r.start for r in region]
        shape = tuple(r.stop - r.start for r in region)
        new = np.zeros(shape, dtype=bool)
        for res in p.parts:
            new[_relative(res["region"], lo)] = True
        whole = bool(new.all())
        with deferred():                      # a stop signal waits for these few milliseconds
            IN.forget(self.path, key)         # from here until the record below, the chunk is unverified
            for name, arr in self.arrays.items():
                if name in ("done", SERIES):
                    continue
                buf = np.empty(shape + tuple(arr.shape[4:]), dtype=arr.dtype) if whole else np.asarray(arr[region])
                for res in p.parts:
                    buf[_relative(res["region"], lo)] = res["data"][name][None]
                arr[region] = buf
            if SERIES in self.arrays and key[3] == 0:
                self._write_series(region, lo, p.parts, whole)
            done = new if whole else (np.asarray(self.arrays["done"][region]) == 1) | new
            self.arrays["done"][region] = done.astype(np.int8)
            t1 = time.perf_counter()
            IN.record(self.path, self.variables, key, int(done.sum()))
            self.checksum_s += time.perf_counter() - t1
        self.written_runs += int(new.sum())
        self.chunk_writes += 1
        self.write_s += time.perf_counter() - t0

    def _write_series(self, region, lo, parts, whole: bool) -> None:
        """The series of the chunk's first members (their own array: (model, delta, chi,
        start, sample, axis), one chunk file per run chunk whose member block is the first)."""
        arr = self.arrays[SERIES]
        sreg = region[:3] + (slice(0, arr.shape[3]),)
        shape = tuple(r.stop - r.start for r in sreg) + tuple(arr.shape[4:])
        buf = np.full(shape, np.nan, dtype=arr.dtype) if whole else np.asarray(arr[sreg])
        for res in parts:
            if "series" not in res["data"]:
                continue
            m, ds, cs, ms = res["region"]
            ks = res["data"]["series"].shape[2]
            buf[m - lo[0], ds[0] - lo[1]:ds[1] - lo[1], cs[0] - lo[2]:cs[1] - lo[2], ms[0]:ms[0] + ks] = res["data"]["series"]
        arr[sreg] = buf


def _relative(r, lo) -> tuple:
    """A batch's region (model, (d0, d1), (c0, c1), (m0, m1)) as slices inside its chunk."""
    m, ds, cs, ms = r
    return (slice(m - lo[0], m - lo[0] + 1), slice(ds[0] - lo[1], ds[1] - lo[1]), slice(cs[0] - lo[2], cs[1] - lo[2]),
            slice(ms[0] - lo[3], ms[1] - lo[3]))


def verify(path: str) -> IN.Report:
    """The store's files against their checksums (``integrity.verify``)."""
    return IN.verify(path, run_variables(path))


# The first classifier version whose ``regime`` of a handed-over run is what its state shows at
# tau_end; a hand-over store of an earlier version holds the attractor there (``label_inf``'s value)
STATE_LABELS_SINCE = 4


def resume(path: str, say) -> tuple:
    """An existing store, whose skeleton and identity ``levels.open_level`` judged: every chunk
    verified against its checksums; damaged or unverified chunks are emptied (their runs
    recomputed) and leftover temporary files removed, each said in one line.

    Returns (chunks, done mask, runs to recompute, notices)."""
    rep = verify(path)
    if rep.skeleton is None or rep.skeleton:          # changed since it was judged: another hand in the store
        raise StoreDamaged(f"{path}: its metadata changed while it was being opened; move it away and compute the "
                           f"atlas again")
    notices = []
    shape, chunks = IN.layout(path)
    bad = rep.bad_keys
    repaired = 0
    if bad:
        with deferred():
            IN.discard(path, run_variables(path), bad, rep.leftovers)
        n = sum(int(np.prod([r.stop - r.start for r in IN.chunk_region(k, shape, chunks)])) for k in bad)
        repaired = n
        what = "damaged" if rep.damaged else "unverified"
        if rep.damaged and rep.unrecorded:
            what = "damaged or unverified"
        notices.append(f"{path}: {len(bad)} {what} chunk{'s' if len(bad) != 1 else ''} ({IN.summary(rep.problems())}); "
                       f"{'their' if len(bad) != 1 else 'its'} {n} runs are recomputed")
    elif rep.leftovers:
        with deferred():
            IN.discard(path, run_variables(path), [], rep.leftovers)
    if rep.leftovers and not bad:
        notices.append(f"{path}: removed {len(rep.leftovers)} temporary file{'s' if len(rep.leftovers) != 1 else ''} "
                       f"of an interrupted write ({IN.summary([IN.Damage(x, 'leftover') for x in rep.leftovers], 3)})")
    for line in notices:
        say(line)
    return tuple(chunks), done_mask(path), repaired, notices


def open_atlas(path: str):
    """The store as an xarray Dataset, with ``label`` (strings: what each run's state shows at
    tau_end) and ``limit_label`` (the type as tau -> oo, where the store has it), and the
    evidence unpacked into one variable per quantity (``slope_perp``, ``X2``, ...); runs not
    computed yet are masked.  A hand-over store of a classifier before ``STATE_LABELS_SINCE``,
    whose ``regime`` of a handed-over run is its attractor, is refused (``UsageError``, one line):
    its ``label`` would silently mean another thing."""
    import xarray as xr

    ds = xr.open_zarr(path)
    version = ds.attrs.get("classifier_version")
    if isinstance(version, int) and version < STATE_LABELS_SINCE and "tau_handover" in ds \
            and bool((ds["method"] == RN.METHOD_CODE[RN.HANDED_OVER]).any()):
        raise UsageError(f"{printable(str(path), 200)}: an atlas of classifier version {version}, whose label at "
                         f"tau_end of a handed-over run is its attractor's; this spinviz (version {C.VERSION}) labels "
                         f"the state there: compute the atlas again into a new store")
    names = np.array(["" for _ in range(256)], dtype=object)
    for lab, c in C.CODE.items():
        names[c % 256] = lab
    done = ds["done"] == 1
    width = f"<U{max(len(k) for k in C.CODE)}"          # every block as wide as the longest label
    for name, var in (("label", "regime"), ("limit_label", "label_inf")):
        if var in ds:
            ds[name] = xr.apply_ufunc(lambda a: names[a.astype(np.int64) % 256].astype(width), ds[var].where(done, 0)
                                      .astype(np.int8), dask="parallelized", output_dtypes=[width])
    for q in C.EVIDENCE:
        ds[q] = ds["evidence"].sel(quantity=q, drop=True).where(done)
    return ds
