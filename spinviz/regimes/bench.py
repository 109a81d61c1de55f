"""The atlas benchmark (a command, not a test): ``spinviz atlas SPEC --bench [--json]``, and
``spinviz atlas SPEC --bench --write-path`` for the store's write path alone.

Measured on the spec as given, each time into a fresh temporary store, one after the other:

* the whole atlas on an embedded LocalCluster with 1 worker, then with 2 (or ``workers``):
  runs per second (of the execution phase, and of the whole command with the cluster's
  start and stop), the speed-up, peak resident memory per worker process, and the
  scheduling overhead as a share of worker time, 1 - (time inside tasks)/(wall x threads);
* the client's writing of the store: chunk writes, ms each, and the share of it spent on
  the checksums (hashing the chunk files just written, recording them);
* the bare cost of a Dask task: 200 empty tasks on the 2-worker cluster, ms each, beside the
  mean task's compute time;
* (``--store``, on its own: no run is integrated) the store's write path at the spec's full
  size, fed synthetic results: ms per chunk write with and without the checksums, and the
  time to verify the finished store (``store_cost``);
* projections of a figure-quality atlas, 64 x 64 cells x 32 members per model, on 1, 2 and
  64 cores: runs x (one worker's seconds per run) / cores, on 64 with the empty-task cost as
  a share and the longest task as the tail.
"""

from __future__ import annotations

import math
import os
import shutil
import tempfile
import time

import numpy as np

from ..inputs.atlas_spec import AtlasSpec, load_spec
from .api import atlas

FIGURE_RUNS = 64 * 64 * 32


def _noop(x):
    return x


def task_cost(n: int = 200, workers: int = 2) -> float:
    """Milliseconds per empty task (submit, schedule, run, gather) on a local cluster."""
    from .cluster import atlas_cluster

    with atlas_cluster(None, workers) as cl:
        cl.client.gather(cl.client.map(_noop, range(10), pure=False))         # warm
        t0 = time.perf_counter()
        cl.client.gather(cl.client.map(_noop, range(n), pure=False))
        return 1e3 * (time.perf_counter() - t0) / n


def run(spec, workers: int | None = None, progress: bool = True) -> dict:
    """All measurements (see the module docstring) as a dict of plain numbers.  ``workers`` (the
    larger of the two measurements) is checked first, by the atlas's own schema, and the spec's
    atlas must be feasible on it -- before the first measurement."""
    from ..inputs.atlas import AtlasArguments
    from .engine.cost import check_feasible

    args = AtlasArguments(workers=workers, progress=progress)
    spec = spec if isinstance(spec, AtlasSpec) else load_spec(spec)
    many = workers or min(2, os.cpu_count() or 1)
    check_feasible(spec, AtlasArguments(workers=many, progress=args.progress))
    rows = {"spec": spec.path, "runs": spec.runs, "models": list(spec.models), "cores": os.cpu_count()}
    tmp = tempfile.mkdtemp(prefix="spinviz-atlas-bench-")
    try:
        per = {}
        for n in sorted({1, many}):
            out = os.path.join(tmp, f"w{n}.zarr")
            t0 = time.perf_counter()
            res = atlas(spec, out, workers=n, progress=progress)
            total = time.perf_counter() - t0
            st = res.stats
            from .store.dataset import open_atlas

            ds = open_atlas(out)
            secs = ds["run_seconds"].values
            per[n] = {
                "workers": n, "wall_s": st.wall_s, "command_s": total, "runs_per_s": st.runs / st.wall_s,
                "runs_per_s_per_worker": st.runs / st.wall_s / n, "command_runs_per_s": st.runs / total,
                "tasks": st.tasks, "overhead_share": st.overhead_share, "cpu_share": st.cpu_share,
                "mean_task_s": float(np.mean(st.task_compute_s)), "max_task_s": float(np.max(st.task_compute_s)),
                "max_rss_mb": max(st.max_rss_mb.values()),
                "mean_run_s": float(np.nanmean(secs)), "median_run_s": float(np.nanmedian(secs)),
                "p99_run_s": float(np.nanpercentile(secs, 99)), "max_run_s": float(np.nanmax(secs)),
                "median_steps": float(np.nanmedian(ds["nsteps"].values)),
                "chunk_writes": st.chunk_writes, "write_ms_per_chunk": 1e3 * st.write_s / max(1, st.chunk_writes),
                "checksum_share_of_writes": st.checksum_s / st.write_s if st.write_s > 0 else float("nan"),
                "write_share_of_wall": st.write_s / st.wall_s if st.wall_s > 0 else float("nan"),
            }
            shutil.rmtree(out, ignore_errors=True)
        rows["by_workers"] = per
        rows["speedup"] = per[many]["runs_per_s"] / per[1]["runs_per_s"] if many != 1 else 1.0
        rows["task_ms"] = task_cost(workers=many)
        rows["task_overhead_share"] = rows["task_ms"] / 1e3 / per[1]["mean_task_s"]
        # projections: one worker's measured seconds per run (everything included), divided
        # over n cores; on 64 the scheduler's cost per task is added as a share, and the
        # longest task as the tail while the last tasks finish
        s_run = 1.0 / per[1]["runs_per_s"]
        runs_fig = FIGURE_RUNS * len(spec.models)
        tail = max(per[n]["max_task_s"] for n in per)
        rows["projection"] = {
            "runs": runs_fig,
            "1_core_h": runs_fig * s_run / 3600.0,
            "2_cores_h": runs_fig / per[many]["runs_per_s"] / 3600.0 if many == 2 else runs_fig * s_run / 2 / 3600.0,
            "64_cores_min": (runs_fig * s_run / 64.0 / (1.0 - rows["task_overhead_share"]) + tail) / 60.0,
        }
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    return rows


def _synthetic(batch, evidence: int) -> dict:
    """A batch result of the right shapes and types, random numbers (incompressible, as real ones)."""
    from .engine import runs as RN

    rng = np.random.default_rng([abs(int(x)) for x in np.ravel(batch.region[1:])] + [batch.region[0]])
    sh = (len(batch.deltas), len(batch.chis), len(batch.omega0))
    ints = {k: rng.integers(1, 14, sh).astype(np.int8) for k in ("regime", "regime_early", "candidate")}
    return {"region": batch.region, "data": {
        **ints, "status": np.zeros(sh, np.int8), "method": np.zeros(sh, np.int8), "confidence": rng.random(sh),
        "tau_reached": rng.random(sh), "run_seconds": rng.random(sh), "nsteps": rng.integers(10**3, 10**6, sh),
        "nfev": np.zeros(sh, np.int64), "evidence": rng.random(sh + (evidence,)), "omega_final": rng.random(sh + (3,)),
        "reason": np.full(sh, "type 3: slopes -0.50, -0.50; the phase turning", dtype=f"<U{RN.REASON_CHARS}")}}


def store_cost(spec, repeats: int = 3) -> dict:
    """The store's write path at the spec's size without integrating anything: the Writer fed
    synthetic results, with the checksums and with ``integrity.record`` replaced by a no-op;
    medians over ``repeats``.  Returns ms per chunk write (with, without, of which the
    checksums), the store's size and the time to verify it."""
    from .engine import classify as C
    from .engine.runs import RUNS_PER_TASK, plan
    from .store import dataset as DS
    from .store import integrity as IN
    from .store import levels as LV

    if isinstance(repeats, bool) or not isinstance(repeats, int) or not 1 <= repeats <= 100:
        from ..errors import SpecError

        raise SpecError("repeats", f"must be a whole number in [1, 100] (the median of the write timings), got {repeats!r}")
    spec = spec if isinstance(spec, AtlasSpec) else load_spec(spec)
    rows = {True: [], False: []}
    tmp = tempfile.mkdtemp(prefix="spinviz-atlas-store-")
    real = IN.record
    try:
        for _ in range(repeats):
            for sums in (False, True):
                out = os.path.join(tmp, f"s{int(sums)}.zarr")
                chunks = LV.chunk_shape(spec)
                DS.create(spec, out, chunks, LV.identity(spec))
                done = np.zeros((len(spec.models), len(spec.deltas), len(spec.chis), spec.members), dtype=bool)
                batches, keys, expected = plan(spec, chunks, done, RUNS_PER_TASK)
                results = [_synthetic(b, len(C.EVIDENCE)) for b in batches]
                IN.record = real if sums else (lambda *a, **k: None)
                try:
                    w = DS.Writer(out, expected, flush_s=float("inf"))
                    for k, res in zip(keys, results):
                        w.add(k, res)
                    w.close()
                finally:
                    IN.record = real
                t0 = time.perf_counter()
                if sums:
                    assert DS.verify(out).clean
                size = sum(os.path.getsize(os.path.join(r, f)) for r, _, fs in os.walk(out) for f in fs)
                rows[sums].append((1e3 * w.write_s / w.chunk_writes, 1e3 * w.checksum_s / w.chunk_writes,
                                   time.perf_counter() - t0, size, w.chunk_writes))
                shutil.rmtree(out)
    finally:
        IN.record = real
        shutil.rmtree(tmp, ignore_errors=True)
    med = {k: np.median(np.array(v), axis=0) for k, v in rows.items()}
    return {"runs": spec.runs, "chunk_writes": int(med[True][4]), "ms_per_chunk_with": float(med[True][0]),
            "ms_per_chunk_without": float(med[False][0]), "ms_checksums_per_chunk": float(med[True][1]),
            "verify_s": float(med[True][2]), "store_mb": float(med[True][3]) / 1e6}


def format_store_cost(r: dict) -> str:
    """The ``--write-path`` measurements as a table for people."""
    return (f"store write path, {r['runs']} runs in {r['chunk_writes']} chunk writes ({r['store_mb']:.1f} MB): "
            f"{r['ms_per_chunk_with']:.1f} ms per chunk with checksums, {r['ms_per_chunk_without']:.1f} ms without; "
            f"hashing and recording {r['ms_checksums_per_chunk']:.2f} ms per chunk "
            f"({100 * r['ms_checksums_per_chunk'] / r['ms_per_chunk_with']:.0f} % of a write); verifying the store "
            f"{1e3 * r['verify_s']:.0f} ms")


def format_table(r: dict) -> str:
    """The benchmark's rows as a table for people."""
    lines = [f"atlas benchmark: {r['spec']}, {r['runs']} runs ({', '.join(r['models'])}), {r['cores']} cores", "",
             "| workers | runs/s | runs/s per worker | whole command runs/s | tasks | mean task | overhead share | "
             "CPU / wall in tasks | peak RSS per worker |",
             "|---|---|---|---|---|---|---|---|---|"]
    for n, p in r["by_workers"].items():
        lines.append(f"| {n} | {p['runs_per_s']:.1f} | {p['runs_per_s_per_worker']:.1f} | {p['command_runs_per_s']:.1f} | "
                     f"{p['tasks']} | {p['mean_task_s']:.2f} s | {100 * p['overhead_share']:.1f} % | "
                     f"{100 * p['cpu_share']:.0f} % | {p['max_rss_mb']:.0f} MiB |")
    p1 = r["by_workers"][min(r["by_workers"])]
    pj = r["projection"]
    busy = [n for n, p in r["by_workers"].items() if p["cpu_share"] < 0.9]
    shares = ", ".join("%.0f %%" % (100 * r["by_workers"][n]["cpu_share"]) for n in busy)
    note = (f" (NOT the atlas's: with {', '.join(map(str, busy))} worker(s) the tasks got only {shares} of a core: "
            f"other work was running on this machine)") if busy else ""
    lines += [
        "",
        f"speed-up 1 -> {max(r['by_workers'])} workers: {r['speedup']:.2f}{note}",
        f"cost of one run (1 worker): mean {p1['mean_run_s'] * 1e3:.1f} ms, median {p1['median_run_s'] * 1e3:.1f} ms, "
        f"99th percentile {p1['p99_run_s'] * 1e3:.0f} ms, max {p1['max_run_s']:.2f} s; median {p1['median_steps']:.0f} steps",
        f"an empty Dask task: {r['task_ms']:.2f} ms = {100 * r['task_overhead_share']:.2f} % of a mean task",
        f"writing the store (1 worker): {p1['chunk_writes']} chunk writes, {p1['write_ms_per_chunk']:.1f} ms each, "
        f"{100 * p1['checksum_share_of_writes']:.0f} % of it the checksums; {100 * p1['write_share_of_wall']:.2f} % "
        f"of the wall time",
        f"projected 64 x 64 x 32 x {len(r['models'])} model(s) = {pj['runs']} runs: {pj['1_core_h']:.2f} h on 1 core, "
        f"{pj['2_cores_h']:.2f} h on 2, {pj['64_cores_min']:.1f} min on 64 (with the longest task, "
        f"{max(p['max_task_s'] for p in r['by_workers'].values()):.0f} s, as the tail)",
    ]
    return "\n".join(lines)


# --- against the standalone peer ----------------------------------------------------------------
PEER_CASES = ((256, 1e10), (256, 1e12), (256, 1e14), (None, 1e10))   # (starts, tau_end); None: the spec's


def against_peer(spec, script: str, cases=PEER_CASES, progress=None) -> list[dict]:
    """The spec's one cell, ``spinviz atlas`` as a whole command, against the standalone heyoka
    script ``script`` (``benchmarks/peer_heyoka_atlas.py``: the same cell, starts, tolerance and
    output grid, every run integrated to tau_end on both cores) as a whole process, one after
    the other in this one run, for each (starts, tau_end) of ``cases``: wall and CPU seconds
    (the child processes' user + system), the machine's load before each, the ratio; and the
    same end state (``_end_state``)."""
    import json
    import sys

    from ..errors import UsageError

    spec = spec if isinstance(spec, AtlasSpec) else load_spec(spec)
    if len(spec.models) != 1 or len(spec.deltas) != 1 or len(spec.chis) != 1 or spec.seed is None:
        raise UsageError(f"--peer: {spec.path}: needs a one-cell spec of one model with [members] count, seed and omega")
    say = progress or (lambda m: None)
    model, d, chi = spec.models[0], float(spec.deltas[0]), float(spec.chis[0])
    run = json.loads(spec.canonical_json())["run"]
    rows = []
    tmp = tempfile.mkdtemp(prefix="spinviz-atlas-peer-")
    try:
        for n, te in cases:
            n = n or spec.members
            toml = os.path.join(tmp, f"cell_{n}_{te:.0e}.toml")
            with open(toml, "w") as f:
                f.write(f'title = "peer cell"\nmodel = "{model}"\n[grid]\ndelta = [{d!r}]\nchi = [{chi!r}]\n'
                        f'[members]\ncount = {n}\nseed = {spec.seed}\nomega = {spec.omega_magnitude!r}\n[run]\n'
                        + "".join(f"{k} = {json.dumps(v)}\n" for k, v in dict(run, tau_end=te).items())
                        + "[output]\nseries = 0\n")
            out, npz = os.path.join(tmp, f"s{n}_{te:.0e}.zarr"), os.path.join(tmp, f"p{n}_{te:.0e}.npz")
            say(f"spinviz atlas: {n} starts to tau {te:g}")
            mine = _timed([sys.executable, "-m", "spinviz", "atlas", toml, "--out", out, "--quiet"])
            say(f"peer: {n} starts to tau {te:g}")
            peer = _timed([sys.executable, script, "--runs", str(n), "--tau-end", repr(te), "--tol",
                           repr(spec.settings.rtol), "--delta", repr(d), "--chi-deg", repr(math.degrees(chi)),
                           "--omega", repr(spec.omega_magnitude), "--seed", str(spec.seed), "--out", npz])
            rows.append({"starts": n, "tau_end": te, "spinviz": mine, "peer": peer,
                         "ratio_wall": mine["wall_s"] / peer["wall_s"], "ratio_cpu": mine["cpu_s"] / peer["cpu_s"],
                         **_end_state(model, d, chi, te, spec.settings.window, out, npz)})
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    return rows


def _timed(argv: list) -> dict:
    """Run ``argv`` as a whole process: its wall and CPU seconds (children's user + system) and
    the machine's load average before it."""
    import resource
    import subprocess

    load = os.getloadavg()[0]
    c0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    p = subprocess.run(argv, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    c1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    if p.returncode != 0:
        raise RuntimeError(f"{' '.join(argv[:4])}... failed ({p.returncode}): {p.stderr.strip()[-400:]}")
    return {"wall_s": wall, "cpu_s": (c1.ru_utime - c0.ru_utime) + (c1.ru_stime - c0.ru_stime), "load": load}


def _end_state(model: str, d: float, chi: float, tau_end: float, window: float, out: str, npz: str) -> dict:
    """The store's runs against the peer's: every handed-over run's averaged end amplitudes
    (``abar_end``, ``bbar_end``) against the peer's last sample read through the same transform
    (``physics.averaged.scaled_amplitudes``), against the stated bound; and the labels (the
    peer's samples through spinviz's classifier, not timed)."""
    from collections import Counter

    from ..physics import averaged as AV
    from .engine import classify as C
    from .store.dataset import open_atlas

    ds = open_atlas(out).isel(model=0, delta=0, chi=0)
    peer = np.load(npz)
    w = peer["omega"][:, -1]
    a, b = AV.scaled_amplitudes(AV.Flow(model, d, chi), w[:, 0] + 1j * w[:, 1], w[:, 2], tau_end)
    handed = np.isfinite(ds["tau_handover"].values)
    da = np.abs(ds["abar_end"].values - a)[handed]
    db = np.abs(np.abs(ds["bbar_end"].values) - b)[handed]
    bound = ds["bound"].values[handed]
    labels = []
    for x in peer["omega"]:
        v = C.classify(peer["tau"], x, d, chi, model, window)
        labels.append(f"->{v.candidate}" if v.label == "approaching" else v.label)

    def stat(x, f):
        return float(f(x)) if x.size else math.nan

    return {"handed_over": int(handed.sum()), "beyond_bound": int(np.sum((da > bound) | (db > bound))),
            "d_abar_median": stat(da, np.median), "d_abar_max": stat(da, np.max),
            "d_bbar_median": stat(db, np.median), "d_bbar_max": stat(db, np.max),
            "bound_median": stat(bound, np.median),
            "labels_spinviz": dict(Counter(str(x) for x in ds["label"].values)), "labels_peer": dict(Counter(labels))}


def format_peer(rows: list[dict]) -> str:
    """The comparison with the peer as a Markdown table."""
    lab = lambda c: ", ".join(f"{k} {v}" for k, v in sorted(c.items(), key=lambda kv: -kv[1]))  # noqa: E731
    out = ["| starts | tau_end | spinviz atlas, whole command | peer, whole process | ratio (wall, CPU) | load | "
           "same end state: |d abar|, |d bbar| median (max), beyond bound | labels spinviz / peer |",
           "|---|---|---|---|---|---|---|---|"]
    for r in rows:
        s, p = r["spinviz"], r["peer"]
        out.append(f"| {r['starts']} | {r['tau_end']:.0e} | {s['wall_s']:.2f} s ({s['cpu_s']:.2f} s CPU) | "
                   f"{p['wall_s']:.2f} s ({p['cpu_s']:.2f} s CPU) | {r['ratio_wall']:.3g}, {r['ratio_cpu']:.3g} | "
                   f"{s['load']:.1f}, {p['load']:.1f} | {r['d_abar_median']:.1e} ({r['d_abar_max']:.1e}), "
                   f"{r['d_bbar_median']:.1e} ({r['d_bbar_max']:.1e}); {r['beyond_bound']} of {r['handed_over']} "
                   f"(bound median {r['bound_median']:.1e}) | {lab(r['labels_spinviz'])} / {lab(r['labels_peer'])} |")
    return "\n".join(out)
