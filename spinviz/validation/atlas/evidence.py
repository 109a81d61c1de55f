"""The evidence the atlas rests on, one registry entry per kind: ``spinviz atlas evidence KIND``.

A ``Kind`` owns everything about itself: its one-line summary, its default starts per point,
the options it takes beyond ``--members``, its largest horizon and why, its default horizon(s),
the store key its rows are kept under with ``--out``, the estimate of its work from measured
costs, and the computation.  The command line builds one sub-command per entry with exactly
its options; ``run`` checks a request (the schema, ``inputs.options.EvidenceRequest``, checks
the values; the entry says which options it takes and how far its horizons reach), estimates
its work against the cap (``inputs.options.check_work``) and computes -- all checks before any
work.  A new kind is one entry here plus its computation.

Each prints a table (``--json``: the rows as JSON instead) and its progress on stderr.
"""

from __future__ import annotations

import contextlib
import dataclasses
import json
import math
import sys
from collections.abc import Callable
from dataclasses import dataclass

from ...errors import SpecError, UsageError, printable

OPTIONS = ("workers", "tau_end", "horizons", "out")      # what a kind may take beyond --members

# Measured costs, one core (docs/atlas.md), at tau = 1e10 unless said, growing as sqrt(tau / 1e10)
# (the steps of a spiral integrated in full):
ATLAS_S_PER_RUN = 0.096          # a run of a single-cell atlas, cluster and classification included
PHYSICAL_S_PER_RUN = 0.094       # an atlas run and its physical-unit simulate run (32 in 3 s)
CROSSCHECK_S_PER_RUN = 25.0      # a SciPy DOP853 run of (4.2)-(4.4) at rtol 1e-10
TOLERANCE_S_PER_RUN = 0.009      # a run of the 12 x 12 grid at one rtol (82 s for 9216)
BRUTE_S_PER_START = 0.7          # brute force per start and unit of sqrt(tau/1e10) over the 19 points (1 222 s for 16
#                                  starts at 1e12 and 1e14, the machine shared)
FLOWS_S = 60.0                   # eight starts to 1e10 at tol 1e-15 (measured 25-50 s)
BASIN_S_PER_RUN = 0.075          # a run of the 4|5 band to 1e16, most in full (64 in 4.8 s of CPU, load ~6)
LIBRATION_S = 2.0                # (4.42) read two ways: 8 starts sampled densely over 1e10 ... 2e10 (0.9 s)
ENGINE_S_PER_RUN = 0.03          # a run of the hand-over engine, one cell's batch and its noise floor included
MARGIN_REF_S = 0.12              # a tol-1e-15 reference of a handed-over start to 1e10 (0.05-0.12 s at (0.7, 29 deg))


@dataclass(frozen=True)
class Kind:
    """One kind of evidence (module docstring).

    options : what it takes beyond --members (of ``OPTIONS``); tau_max, tau_why : its largest
    horizon and why; tau_end, horizons : its defaults (None: it takes none); keeps : the store
    key of its rows with --out (None: no --out); cost(req) -> s and compute(req, say) -> (rows,
    table, exit status) take the checked ``EvidenceRequest`` with the defaults filled in.
    """

    name: str
    summary: str
    members: int
    cost: Callable
    compute: Callable
    options: tuple = ()
    tau_max: float = 1e16
    tau_why: str = "float64 time steps of integration in full"
    tau_end: float | None = None
    horizons: tuple | None = None
    keeps: str | None = None

    def request(self, members=None, **given):
        """The checked request: options this kind does not take refused (``SpecError`` naming
        the option), the values by the schema within this kind's horizons, defaults filled in."""
        from ...inputs.options import EvidenceRequest

        for key, value in given.items():
            if value is not None and key not in self.options:
                raise SpecError(key, f"not used by evidence {self.name} (it takes "
                                     f"{', '.join(sorted((*self.options, 'members')))})")
        req = EvidenceRequest(members=members, tau_max=self.tau_max, tau_why=self.tau_why, **given)
        fill = {"members": self.members, "tau_end": self.tau_end, "horizons": self.horizons}
        return dataclasses.replace(req, **{k: v for k, v in fill.items() if getattr(req, k) is None and v is not None})


def _grows(tau: float) -> float:
    return math.sqrt(tau / 1e10)


def _validate(req, say):
    from . import validate as V

    rows = V.run(req.members, req.workers, progress=False)
    say("(4.42) read as peak and as r.m.s.: dense samples")
    lib = V.libration_readings()
    return rows + [{"libration_readings": lib}], V.format_table(rows) + "\n\n" + V.format_libration(lib), 0


def _crosscheck(req, say):
    from . import crosscheck as X

    rows = X.run(req.members, progress=lambda r: say(f"{r['point']} member {r['member']}: {r['label']} "
                                                     f"({r['seconds']:.1f} s)"))
    return rows, X.format_rows(rows), 0


def _physical(req, say):
    from . import physical as PC

    rows = PC.compare(members=req.members, tau_end=req.tau_end, progress=say)
    return rows, PC.format_table(rows), 0 if all(r["label_atlas"] == r["label_physical"] for r in rows) else 1


def _convergence(req, say):
    from . import convergence as CV

    rows = CV.study(req.members, req.horizons, progress=say)
    return rows, CV.format_table(rows), 0


def _tolerance(req, say):
    from . import convergence as CV

    rows = CV.tolerance(req.members, progress=say)
    return rows, CV.format_tolerance(rows), 0


def _handover(req, say):
    from . import against_brute_force as HV

    rows = HV.run(req.members, req.horizons, progress=say)
    return rows, HV.format_table(rows), 0


def _basins(req, say):
    from . import against_brute_force as HV

    rows = HV.basins(members=req.members, tau_end=req.tau_end, progress=say)
    return rows, HV.format_basins(rows), 0


def _bound(req, say):
    from . import against_brute_force as HV

    rows = HV.margins(members=req.members, tau_end=req.tau_end, progress=say)
    return rows, HV.format_margins(rows), 0 if all(r["beyond_bound"] == 0 for r in rows) else 1


def _flows(req, say):
    from . import against_brute_force as HV

    rows = HV.flows(progress=say)
    return rows, HV.format_flows(rows), 0 if all(r["within_bound"] for r in rows) else 1


def _cores(req) -> int:
    from ...executors.processes import usable_cores

    return req.workers or usable_cores()


def _band_points() -> int:
    from .against_brute_force import band_points

    return len(band_points())


def _full(tau: float) -> float:
    from ...regimes.engine.cost import full_run_s

    return full_run_s(tau)                         # an upper bound: every run kept in full


KINDS = {k.name: k for k in (
    Kind("validate", "single-cell atlases inside every domain against the paper's formulas", 32,
         cost=lambda r: 12 * r.members * ATLAS_S_PER_RUN / _cores(r) + LIBRATION_S, compute=_validate,
         options=("workers",)),
    Kind("crosscheck", "the disputed points with the paper's (4.2)-(4.4) typed in and SciPy", 3,
         cost=lambda r: 6 * r.members * CROSSCHECK_S_PER_RUN, compute=_crosscheck),
    Kind("physical", "the dimensionless runs against physical-unit simulate runs of (2.2)+(2.3) and (2.5); exit "
                     "status 1 if a label differs", 4,
         cost=lambda r: 8 * r.members * PHYSICAL_S_PER_RUN * _grows(r.tau_end), compute=_physical,
         options=("tau_end",), tau_end=1e10),
    Kind("convergence", "labels against horizon (x 100, x 1e4) and 4x members; --out STORE keeps the rows in that "
                        "atlas", 32,
         cost=lambda r: 15 * r.members * (sum(_full(h) for h in r.horizons) + 4 * _full(r.horizons[0])),
         compute=_convergence, options=("horizons", "out"), tau_max=1e20,
         tau_why="where the hand-over engine was measured to hold", horizons=(1e10, 1e12, 1e14, 1e16, 1e20),
         keeps="convergence"),
    Kind("tolerance", "labels and end states against rtol on the quick atlas's grid", 8,
         cost=lambda r: 144 * r.members * 2 * 4 * TOLERANCE_S_PER_RUN, compute=_tolerance),
    Kind("handover", "the hand-over engine against brute-force runs of the same starts, tighter references where "
                     "they differ; --out STORE keeps the rows in that atlas", 16,
         cost=lambda r: r.members * BRUTE_S_PER_START * sum(_grows(h) for h in r.horizons), compute=_handover,
         options=("horizons", "out"), tau_why="where brute force integrates in full", horizons=(1e12, 1e14),
         keeps="handover_validation"),
    Kind("basins", "the 4|5 band at delta = 0.5 and 0.4: the shares of the starts ending in 4 and in 5 against "
                   "beta of (4.18), with their Clopper-Pearson intervals at 95 percent", 256,
         cost=lambda r: _band_points() * r.members * BASIN_S_PER_RUN * (_full(r.tau_end) / _full(1e16)) / _cores(r),
         compute=_basins, options=("tau_end",), tau_max=1e20, tau_why="where the hand-over engine was measured to hold",
         tau_end=1e16),
    Kind("bound", "the hand-over engine's end amplitudes against tol-1e-15 references of the same starts: the error "
                  "over the stated bound at every validation point; exit status 1 if one is beyond it", 8,
         cost=lambda r: 18 * r.members * (ENGINE_S_PER_RUN + MARGIN_REF_S * _grows(r.tau_end)), compute=_bound,
         options=("tau_end",), tau_end=1e12, tau_why="where the references integrate in full"),
    Kind("flows", "the averaged flows against full integration at tol 1e-15: the error of the averaged amplitudes "
                  "against the stated bound and its order in mu", 1,
         cost=lambda r: FLOWS_S, compute=_flows),
)}


def _say(line: str) -> None:
    print(f"  {printable(line, 300)}", file=sys.stderr, flush=True)


def kind_of(name: str) -> Kind:
    """The registry's entry ``name``; ``UsageError`` naming the kinds otherwise."""
    try:
        return KINDS[name]
    except (KeyError, TypeError):
        raise UsageError(f"evidence: {printable(str(name), 40)} is not one of {', '.join(KINDS)}") from None


def run(kind: str, members: int | None = None, *, workers: int | None = None, tau_end: float | None = None,
        horizons=None, out: str | None = None, as_json: bool = False) -> int:
    """Compute one kind of evidence and print it; returns the exit status.

    Every argument is checked (``Kind.request``), the work estimated against the cap, and the
    store named by ``out`` checked -- all before any work.
    horizons : a sequence of increasing horizons (the command line's ``--horizons 1e10,1e12``)."""
    from ...inputs.options import check_work

    k = kind_of(kind)
    req = k.request(members, workers=workers, tau_end=tau_end, horizons=horizons, out=out)
    given = {"members": members, "tau_end": tau_end, "horizons": horizons}
    key = next((o for o in ("members", "tau_end", "horizons") if given[o] is not None), "members")
    check_work(key, k.cost(req), f"evidence {k.name} with {req.members} member(s) per point")
    with contextlib.ExitStack() as held:
        if req.out is not None:
            from ...regimes.store.lock import StoreLock

            _check_store(req.out)
            # the store's lock before the study, not after it: refused at once when another
            # command writes the store, and no one writes it while the rows are computed
            held.enter_context(StoreLock(req.out, exclusive=True, what=f"evidence {k.name} --out"))
        rows, table, status = _compute(k, req)
    print(json.dumps(rows, indent=2, default=float) if as_json else table)
    return status


def _check_store(out: str) -> None:
    import os

    from ...regimes.store.integrity import verify_skeleton

    if not os.path.exists(os.path.join(out, ".zgroup")) or verify_skeleton(out) is None:
        raise UsageError(f"--out {printable(out, 200)}: not an atlas store to keep the rows in")


def _compute(k: Kind, req) -> tuple:
    """(rows, table, exit status) of one kind, its rows kept in the store ``req.out`` names
    (``run`` holds the store's lock from before the study)."""
    rows, table, status = k.compute(req, _say)
    if req.out and k.keeps:
        from . import convergence as CV

        CV.record(req.out, rows, key=k.keeps)
    return rows, table, status
