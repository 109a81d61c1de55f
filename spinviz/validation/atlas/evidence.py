"""The evidence the atlas rests on, one command each: ``spinviz atlas --evidence KIND``.

========================  ======================================================================
``validate``              single-cell atlases inside every domain against the paper's formulas
                          (``validate``: the README's validation table)
``crosscheck``            the disputed points with the paper's (4.2)-(4.4) typed in and SciPy
                          (``crosscheck``)
``physical``              the dimensionless runs against physical-unit ``simulate`` runs of
                          (2.2)+(2.3) and (2.5) (``physical_check``); exit status 1 if a label differs
``convergence``           labels against horizon (x 100, x 1e4) and 4x members (``convergence``);
                          ``--out STORE`` keeps the rows in that atlas store
``tolerance``             labels and end states against rtol on the quick atlas's grid
``handover``              the hand-over engine against brute-force runs of the same starts at
                          1e12 and 1e14, tighter references where they differ (``handover``);
                          ``--out STORE`` keeps the rows in that atlas store
``basins``                the 4|5 band at delta = 0.5: the shares of the starts ending in 4 and
                          in 5 against beta of (4.18) (``handover.basins``)
``flows``                 the averaged flows against full integration at tol 1e-15: the error
                          of the averaged amplitudes against the stated bound and its order
                          in mu (``handover.flows``)
========================  ======================================================================

Each prints a table (``--json``: the rows as JSON instead) and its progress on stderr.
"""

from __future__ import annotations

import contextlib
import json
import sys

from ...errors import UsageError, printable

KINDS = ("validate", "crosscheck", "physical", "convergence", "tolerance", "handover", "basins", "flows")


def _say(line: str) -> None:
    print(f"  {printable(line, 300)}", file=sys.stderr, flush=True)


def run(kind: str, members: int | None = None, *, workers: int | None = None, tau_end: float | None = None,
        horizons=None, out: str | None = None, as_json: bool = False) -> int:
    """Compute one kind of evidence and print it; returns the exit status.

    Every argument goes through the schema (``inputs.options.EvidenceRequest``: members,
    tau_end and horizons finite and in range, the estimated work within the cap) and an option
    the kind does not use is refused (``SpecError`` naming it) -- all before any work.
    horizons : a sequence of increasing horizons (the command line's ``--horizons 1e10,1e12``)."""
    from ...inputs.options import EvidenceRequest, check_accepts

    if kind not in KINDS:
        raise UsageError(f"--evidence: {printable(kind, 40)} is not one of {', '.join(KINDS)}")
    check_accepts(kind, {"workers": workers, "tau_end": tau_end, "horizons": horizons, "out": out})
    req = EvidenceRequest(kind=kind, members=members, workers=workers, tau_end=tau_end, horizons=horizons, out=out)
    with contextlib.ExitStack() as held:
        if req.out is not None:
            from ...regimes.store.lock import StoreLock

            _check_store(req.out)
            # the store's lock before the study, not after it: refused at once when another
            # command writes the store, and no one writes it while the rows are computed
            held.enter_context(StoreLock(req.out, exclusive=True, what=f"--evidence {req.kind} --out"))
        rows, table, status = _compute(req)
    print(json.dumps(rows, indent=2, default=float) if as_json else table)
    return status


def _check_store(out: str) -> None:
    import os

    from ...regimes.store.integrity import verify_skeleton

    if not os.path.exists(os.path.join(out, ".zgroup")) or verify_skeleton(out) is None:
        raise UsageError(f"--out {printable(out, 200)}: not an atlas store to keep the rows in")


def _compute(req) -> tuple:
    """(rows, table, exit status) of one kind."""
    kind, n = req.kind, req.n_members
    if kind == "validate":
        from . import validate as V

        rows = V.run(n, req.workers, progress=False)
        return rows, V.format_table(rows), 0
    if kind == "crosscheck":
        from . import crosscheck as X

        rows = X.run(n, progress=lambda r: _say(f"{r['point']} member {r['member']}: {r['label']} "
                                                f"({r['seconds']:.1f} s)"))
        return rows, X.format_rows(rows), 0
    if kind == "physical":
        from . import physical as PC

        rows = PC.compare(members=n, tau_end=req.tau_end or 1e10, progress=_say)
        return rows, PC.format_table(rows), 0 if all(r["label_atlas"] == r["label_physical"] for r in rows) else 1
    if kind == "basins":
        from . import against_brute_force as HV

        rows = HV.basins(members=n, tau_end=req.tau_end or 1e16, progress=_say)
        return rows, HV.format_basins(rows), 0
    if kind == "flows":
        from . import against_brute_force as HV

        rows = HV.flows(progress=_say)
        return rows, HV.format_flows(rows), 0 if all(r["within_bound"] for r in rows) else 1
    from . import convergence as CV

    if kind == "handover":
        from . import against_brute_force as HV

        rows = HV.run(n, req.horizons or HV.HORIZONS, progress=_say)
        _keep(req, rows, "handover_validation")
        return rows, HV.format_table(rows), 0
    if kind == "tolerance":
        rows = CV.tolerance(n, progress=_say)
        return rows, CV.format_tolerance(rows), 0
    rows = CV.study(n, req.horizons or CV.HORIZONS, progress=_say)
    _keep(req, rows, "convergence")
    return rows, CV.format_table(rows), 0


def _keep(req, rows: list, key: str) -> None:
    """The rows kept in the atlas store ``--out`` names (if any), under ``key``; ``run`` holds
    the store's lock from before the study."""
    if not req.out:
        return
    from . import convergence as CV

    CV.record(req.out, rows, key=key)
