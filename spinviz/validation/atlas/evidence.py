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

import json
import sys
from dataclasses import dataclass

from ...errors import UsageError, printable


@dataclass(frozen=True)
class Kind:
    """One kind of evidence: its default member count, and what it accepts beyond it."""

    members: int
    accepts: frozenset = frozenset()


KINDS = {"validate": Kind(32, frozenset({"workers"})), "crosscheck": Kind(3),
         "physical": Kind(4, frozenset({"tau_end"})), "convergence": Kind(32, frozenset({"horizons", "out"})),
         "tolerance": Kind(8), "handover": Kind(16, frozenset({"horizons", "out"})),
         "basins": Kind(32, frozenset({"tau_end"})), "flows": Kind(1)}
OPTIONS = {"workers": "--workers", "tau_end": "--tau-end", "horizons": "--horizons", "out": "--out"}


def _say(line: str) -> None:
    print(f"  {printable(line, 300)}", file=sys.stderr, flush=True)


def run(kind: str, members: int | None = None, *, workers: int | None = None, tau_end: float | None = None,
        horizons: str | None = None, out: str | None = None, as_json: bool = False) -> int:
    """Compute one kind of evidence and print it; returns the exit status.  An option the kind
    does not use is refused (``UsageError`` naming it) before any work."""
    if kind not in KINDS:
        raise UsageError(f"--evidence: {printable(kind, 40)} is not one of {', '.join(KINDS)}")
    given = {"workers": workers, "tau_end": tau_end, "horizons": horizons, "out": out}
    extra = [OPTIONS[k] for k, v in given.items() if v is not None and k not in KINDS[kind].accepts]
    if extra:
        raise UsageError(f"--evidence {kind}: does not use {', '.join(extra)}")
    n = members or KINDS[kind].members
    rows, table, status = _compute(kind, n, given)
    print(json.dumps(rows, indent=2, default=float) if as_json else table)
    return status


def _compute(kind: str, n: int, given: dict) -> tuple:
    """(rows, table, exit status) of one kind."""
    if kind == "validate":
        from . import validate as V

        rows = V.run(n, given["workers"], progress=False)
        return rows, V.format_table(rows), 0
    if kind == "crosscheck":
        from . import crosscheck as X

        rows = X.run(n, progress=lambda r: _say(f"{r['point']} member {r['member']}: {r['label']} "
                                                f"({r['seconds']:.1f} s)"))
        return rows, X.format_rows(rows), 0
    if kind == "basins":
        from . import handover as HV

        rows = HV.basins(members=n, tau_end=given["tau_end"] or 1e16, progress=_say)
        return rows, HV.format_basins(rows), 0
    if kind == "flows":
        from . import handover as HV

        rows = HV.flows(progress=_say)
        return rows, HV.format_flows(rows), 0 if all(r["within_bound"] for r in rows) else 1
    if kind == "physical":
        from . import physical as P

        rows = P.compare(members=n, tau_end=given["tau_end"] or 1e10, progress=_say)
        return rows, P.format_table(rows), 0 if all(r["label_atlas"] == r["label_physical"] for r in rows) else 1
    from . import convergence as CV

    if kind == "tolerance":
        rows = CV.tolerance(n, progress=_say)
        return rows, CV.format_tolerance(rows), 0
    horizons = CV.HORIZONS
    if kind == "handover":
        from . import handover as HV

        horizons = HV.HORIZONS
    if given["horizons"]:
        try:
            horizons = tuple(float(x) for x in given["horizons"].split(","))
        except ValueError:
            raise UsageError(f"--horizons: expected numbers separated by commas, got "
                             f"{printable(given['horizons'], 80)}") from None
        if len(horizons) < 2 or any(not b > a for a, b in zip(horizons, horizons[1:])) or horizons[0] <= 0:
            raise UsageError("--horizons: give at least two increasing positive horizons (e.g. 1e10,1e12,1e14)")
    if given["out"]:
        import os

        from ...regimes.store.integrity import verify_skeleton

        if not os.path.exists(os.path.join(given["out"], ".zgroup")) or verify_skeleton(given["out"]) is None:
            raise UsageError(f"--out {printable(given['out'], 200)}: not an atlas store to keep the rows in")
    if kind == "handover":
        rows = HV.run(n, horizons, progress=_say)
        if given["out"]:
            CV.record(given["out"], rows, key="handover_validation")
        return rows, HV.format_table(rows), 0
    rows = CV.study(n, horizons, progress=_say)
    if given["out"]:
        CV.record(given["out"], rows)
    return rows, CV.format_table(rows), 0
