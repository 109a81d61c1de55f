"""``spinviz bench``: error against run time (work-precision), method by method.

Problems (dimensionless, tau0 = 1), each run over three braking times at a spin chosen so
the body turns 1e2, 1e4 or 1e6 times:

* ``6.10``   truncated, spherical top, d along e3: Omega (6.9) and orientation (6.10) exact;
* ``3.9``    askew top (delta = -0.6, chi = 55 deg) turning about e2: (3.9) exact, both;
* ``5.2+q``  reduced, longitudinal dipole, delta = 0.3: Omega exact (5.2), the orientation
             against a tight reference (the torque here has a part across L);
* ``askew``  reduced, delta = -0.6, chi = 55 deg, general start: against a tight reference.

Over 1e6 turns the spin phase is ~6e6 rad, so 1e-8 rad is ~11 ulps of it: the references
and the best methods agree to that level (compensated summation in every compiled kernel),
which is as far as float64 lets a 1e6-turn orientation be checked.

Errors are the largest over 41 output instants: the misorientation angle (rad) and
|dOmega|/|Omega|.  Times are the minimum of ``repeats`` runs (compiled kernels warmed up
first).  The baseline is what a user would write: scipy DOP853 on a plain NumPy
right-hand side (np.cross, a 3x3 solve for (2.5)).  A benchmark is a command, not a test.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from .. import rotations as R
from ..integrators import get
from ..integrators.scaling import spin_problem
from ..physics import cases
from ..physics.bodies import symmetric_top
from ..physics.models import System

TARGET_ERROR = 1e-8
N_OUT = 41


# --- the problems --------------------------------------------------------------------------
@dataclass
class BenchProblem:
    """One benchmark problem at one horizon, dimensionless (4.1) in spin units.

    system : the model and body; omega0 : (3,) body frame; q0 : (4,) (w, x, y, z); t : (41,)
    output instants; omega_exact (41, 3) body frame and q_exact (41, 4), where a closed form
    gives them ((6.9), (6.10), (3.9), (5.2)), else None (a tight reference is used).
    """

    name: str
    turns: float
    system: System
    omega0: np.ndarray
    q0: np.ndarray
    t: np.ndarray                      # output instants
    omega_exact: np.ndarray | None = None
    q_exact: np.ndarray | None = None
    commuting: bool = False            # the torque commutes with the free flow (splitting needs no spin resolution)
    averaged: bool = True              # the secular flow applies (there is a precession to average over)
    note: str = ""


def _system(delta, chi, model) -> System:
    return symmetric_top(delta, chi).system(model)


def make_problem(name: str, turns: float) -> BenchProblem:
    """The problem ``name`` at a spin giving ``turns`` turns over its horizon."""
    if name in ("6.10", "3.9", "5.2+q"):
        case = {"6.10": cases.eq6_10_turns, "3.9": cases.eq3_9_turns, "5.2+q": cases.eq5_2_turns}[name](turns)
        t = np.linspace(0.0, case.t_end, N_OUT)
        # (3.9) is not "commuting" for the splitting: it is an unstable solution of the askew top
        # (perturbations grow like exp(c tau^(1/4)), section 4.3); braking-scale steps let the
        # 1e-16 rounding of the splitting's polar form grow into an O(1) error by 1e5 turns.
        # It has no precession about e2 to average over either.
        traits = {"6.10": dict(commuting=True, note="truncated, DAST cube, exact (6.9)/(6.10)"),
                  "3.9": dict(averaged=False, note="askew top about e2, exact (3.9), an unstable solution"),
                  "5.2+q": dict(note="reduced, chi = 0, delta = 0.3: Omega exact (5.2), orientation vs reference")}[name]
        return BenchProblem(name, turns, case.body.system(case.model), case.omega0, case.q0, t,
                            case.omega_exact(t), case.orientation_exact(t), **traits)
    if name == "askew":
        n = np.array([0.3, 0.4, 0.866])
        n /= np.linalg.norm(n)
        w = 0.5 / (2.0 * math.pi * turns) * 3.0          # ~turns over 3 T (the spin slows ~ 1/F)
        t = np.linspace(0.0, 3.0 / w**2, N_OUT)
        q0 = R.quat_from_euler_zxz((0.2, 0.9, -0.3))
        return BenchProblem(name, turns, _system(-0.6, math.radians(55.0), "reduced"), w * n, q0, t, None, None,
                            note="reduced, delta = -0.6, chi = 55 deg, general: vs reference")
    raise ValueError(f"unknown bench problem {name!r}")


PROBLEMS = ("6.10", "3.9", "5.2+q", "askew")


def reference(p: BenchProblem):
    """Tight reference for problems without an exact orientation: Taylor's method in long
    double at rtol 1e-18 (``taylor-long``).  Checked independently against split8 at 1/6-turn
    steps (a different method: the exact free flow composed with the torque), whose own
    accuracy is estimated from its distance d to split8 at 1/4 turn: an 8th-order method's
    error shrinks by r = (4/6)^8 between the two, so the finer one is off by ~ d r / (1 - r)
    (Richardson).  Returns (solution, split8's estimated accuracy, distance between the two)."""
    eps = float(np.linalg.norm(p.omega0))
    period = 2.0 * math.pi / eps
    ref = _run(p, "taylor-long", {"rtol": 1e-18, "atol": 1e-18})[0]
    a = _run(p, "split8", {"step": period / 6})[0]
    b = _run(p, "split8", {"step": period / 4})[0]
    r = (4.0 / 6.0) ** 8
    d = float(R.misorientation(a.q, b.q).max())
    return ref, d * r / (1.0 - r), float(R.misorientation(a.q, ref.q).max())


# --- running ---------------------------------------------------------------------------------
def _spin_units(p: BenchProblem):
    """The problem in spin units (|omega(0)| = 1), exactly as simulate() hands it over."""
    return spin_problem(p.system, p.omega0, p.t, p.q0)


def _run(p: BenchProblem, method: str, kw: dict):
    prob, eps = _spin_units(p)
    kw = dict(kw)
    if "step" in kw:
        kw["step"] = kw["step"] * eps
    if method == "baseline":
        sol = get("dop853").solve(prob, rtol=kw["rtol"], atol=kw["atol"], fun=baseline_rhs(prob.system))
    else:
        sol = get(method).solve(prob, **kw)
    if not sol.success:
        raise RuntimeError(sol.message)
    sol.omega = sol.omega * eps
    return sol, eps


def baseline_rhs(system: System):
    """The right-hand side a user would write with NumPy: np.cross and, for (2.5), a 3x3 solve."""
    J = np.array(system.inertia, dtype=float)
    g = np.array(system.coupling, dtype=float)
    model = system.model

    def f(t, y):
        w, q = y[:3], y[3:]
        Jw = J * w
        free = -np.cross(w, Jw) / J
        if model == "reduced":
            wdd = -(np.cross(free, Jw) + np.cross(w, J * free)) / J
            torque = np.cross(g, np.cross(g, (w @ w) * w - wdd) + (g @ free) * w + 2.0 * (g @ w) * free)
            wdot = free + torque / J
        elif model == "truncated":
            v = np.cross(g, w)
            A = np.diag(J) + np.outer(g, v)
            wdot = np.linalg.solve(A, -np.cross(w, Jw) - (v @ v) * w)
        else:
            wdot = free
        qdot = 0.5 * np.array([-q[1:] @ w, *(q[0] * w + np.cross(q[1:], w))])
        return np.concatenate([wdot, qdot])

    return f


@dataclass
class Row:
    """One configuration's measurement: the largest misorientation (rad) and |dOmega|/|Omega|
    over the output instants, the minimum wall time of ``repeats`` runs (s), and the right-hand
    side evaluations or steps."""

    problem: str
    turns: float
    method: str
    setting: str
    orientation_error: float
    omega_rel_error: float
    seconds: float
    nfev: int | None
    repeats: int
    note: str = ""

    def record(self) -> dict:
        """The row as a JSON-ready dict (``spinviz bench --json``)."""
        return dict(self.__dict__)


def measure(p: BenchProblem, method: str, kw: dict, q_ref, repeats: int, budget: float, setting: str = "") -> Row:
    """Errors and the minimum wall time of ``repeats`` runs (fewer if one run exceeds ``budget``)."""
    times = []
    sol = None
    for _ in range(repeats):
        t0 = time.perf_counter()
        sol, _eps = _run(p, method, kw)
        times.append(time.perf_counter() - t0)
        if times[-1] > budget:
            break
    q_true = p.q_exact if p.q_exact is not None else q_ref
    err_q = float(R.misorientation(sol.q, q_true).max())
    w_true = p.omega_exact
    err_w = (float(np.max(np.linalg.norm(sol.omega - w_true, axis=1) / np.linalg.norm(w_true, axis=1)))
             if w_true is not None else float("nan"))
    return Row(p.name, p.turns, method, setting, err_q, err_w, min(times), sol.stats.get("nfev", sol.stats.get("nsteps")),
               len(times))


@dataclass
class Plan:
    """Which methods and settings each problem gets."""

    rtols: tuple = (1e-8, 1e-10, 1e-12)
    taylor_rtols: tuple = (1e-6, 1e-8, 1e-10, 1e-12, 1e-13)
    split_per_T: tuple = (5, 10, 20, 40)         # steps per braking time (commuting problems)
    split_per_turn: tuple = (2, 4)               # steps per turn (the others)
    repeats: int = 3
    budget: float = 20.0                         # seconds: longer single runs are not repeated
    max_run_seconds: float = 60.0                # runs predicted longer are not run: their time is extrapolated
    horizons: tuple = (1e2, 1e4, 1e6)
    problems: tuple = PROBLEMS
    radau_up_to: float = 1e2
    notes: list = field(default_factory=list)
    quick: bool = False                          # the --quick plan (its repeats are cheaper: the work estimate)


def quick_plan() -> Plan:
    """The plan of ``spinviz bench --quick``: two problems, 1e2 and 1e4 turns, fewer
    tolerances (~2 min)."""
    return Plan(rtols=(1e-8, 1e-11), taylor_rtols=(1e-8, 1e-11, 1e-13), split_per_T=(10, 40), split_per_turn=(8, 32),
                repeats=3, horizons=(1e2, 1e4), problems=("6.10", "5.2+q"), radau_up_to=0, quick=True)


def _configs(p: BenchProblem, plan: Plan, turns: float):
    """(method, keyword arguments, label) per configuration; the label is the same at every
    horizon (steps per turn or per braking time T, tolerances), so costs carry over."""
    eps = float(np.linalg.norm(p.omega0))
    period = 2.0 * math.pi / eps
    T = 1.0 / eps**2
    configs = [("taylor", {"rtol": r, "atol": r * 1e-2}, f"rtol={r:.0e}") for r in plan.taylor_rtols]
    if p.commuting:                             # (all bench problems are symmetric tops)
        configs += [("split8", {"step": T / k}, f"T/{k}") for k in plan.split_per_T]
    else:
        configs += [("split8", {"step": period / k}, f"turn/{k}") for k in plan.split_per_turn]
        configs += [("split6", {"step": period / k}, f"turn/{k}") for k in plan.split_per_turn]
    if p.averaged:
        configs.append(("secular", {"rtol": 1e-12, "atol": 1e-14}, "rtol=1e-12"))
    configs += [("dop853", {"rtol": r, "atol": r * 1e-2}, f"rtol={r:.0e}") for r in plan.rtols]
    if turns <= plan.radau_up_to:
        configs += [("radau", {"rtol": r, "atol": r * 1e-2}, f"rtol={r:.0e}") for r in plan.rtols[:2]]
    configs += [("baseline", {"rtol": r, "atol": r * 1e-2}, f"rtol={r:.0e}") for r in plan.rtols]
    return configs


def run(plan: Plan, progress=None) -> list[Row]:
    """Every problem, horizon and configuration; runs predicted to take longer than
    ``plan.max_run_seconds`` (from the same configuration at the previous horizon, cost per
    turn) are not run and get an extrapolated time.  The plan's repeats and problems are
    checked first (``inputs.options.BenchRequest``: the work they mean within the cap)."""
    from ..inputs.options import BenchRequest

    if not isinstance(plan, Plan):
        from ..errors import SpecTypeError

        raise SpecTypeError("plan", f"must be a bench.Plan, got {type(plan).__name__}")
    BenchRequest(repeats=plan.repeats, quick=plan.quick, problems=plan.problems, known=PROBLEMS)
    rows: list[Row] = []
    say = progress or (lambda msg: None)
    _warm_up()
    for name in plan.problems:
        per_turn: dict = {}                     # (method, label) -> seconds per turn at the last horizon
        for turns in plan.horizons:
            p = make_problem(name, turns)
            q_ref = None
            if p.q_exact is None:
                say(f"{name} {turns:.0e} turns: reference")
                ref, acc, indep = reference(p)
                q_ref = ref.q
                plan.notes.append(f"{name} at {turns:.0e} turns: reference taylor-long at rtol 1e-18; split8 at 1/6 turn "
                                  f"(accurate to ~{acc:.1e} rad by Richardson from 1/4 turn) differs from it by {indep:.1e} rad")
            for method, kw, setting in _configs(p, plan, turns):
                key = (method, setting)
                if key in per_turn and per_turn[key] * turns > plan.max_run_seconds:
                    rows.append(Row(name, turns, method, setting, float("nan"), float("nan"), per_turn[key] * turns,
                                    None, 0, note="not run: time extrapolated from the previous horizon"))
                    continue
                say(f"{name} {turns:.0e} turns: {method} {setting}")
                try:
                    row = measure(p, method, kw, q_ref, plan.repeats, plan.budget, setting)
                    per_turn[key] = row.seconds / turns
                except RuntimeError as e:
                    row = Row(name, turns, method, setting, float("nan"), float("nan"), float("nan"), None, 0,
                              note=f"failed: {e}")
                rows.append(row)
    return rows


def _warm_up():
    """Compile (or load) the numba kernels and the Taylor integrators once, outside the timings."""
    p = make_problem("6.10", 10.0)
    for m, kw in (("taylor", {"rtol": 1e-8, "atol": 1e-10}), ("split8", {"step": 10.0})):
        _run(p, m, kw)


# --- summary ---------------------------------------------------------------------------------
def time_at(rows: list[Row], error: float = TARGET_ERROR) -> float | None:
    """Time to reach ``error`` along a method's sweep (log-log interpolation), or None."""
    pts = sorted((r.orientation_error, r.seconds) for r in rows if r.repeats and np.isfinite(r.orientation_error))
    if not pts:
        return None
    good = [(e, s) for e, s in pts if e <= error]
    if not good:
        return None
    bad = [(e, s) for e, s in pts if e > error]
    if not bad:
        return min(s for _, s in good)
    e1, s1 = min(bad)                       # closest above
    e0, s0 = max(good)                      # closest below
    x = (math.log(error) - math.log(e1)) / (math.log(e0) - math.log(e1))
    return min(min(s for _, s in good), math.exp(math.log(s1) + x * (math.log(s0) - math.log(s1))))


TARGETS = {1e2: ("speedup", 20.0), 1e4: ("speedup", 100.0), 1e6: ("seconds", 10.0)}


def summary(rows: list[Row]) -> list[dict]:
    """Per problem and horizon: the fastest method to reach 1e-8 rad, the baseline's time
    (measured, or extrapolated from the previous horizon: cost x turns^(1 + 1/8), since the
    error per turn must fall in proportion and DOP853's cost grows as tol^(-1/8)), the
    speed-up, and whether the issue's target is met."""
    out = []
    keys = sorted({(r.problem, r.turns) for r in rows}, key=lambda k: (PROBLEMS.index(k[0]), k[1]))
    prev_base: dict = {}
    for prob, turns in keys:
        sel = [r for r in rows if r.problem == prob and r.turns == turns]
        per = {}
        for m in sorted({r.method for r in sel}):
            t = time_at([r for r in sel if r.method == m])
            if t is not None:
                per[m] = t
        base, base_how = per.get("baseline"), "measured"
        if base is None and prob in prev_base:
            t0, n0 = prev_base[prob]
            base, base_how = t0 * (turns / n0) ** (1.0 + 1.0 / 8.0), "extrapolated"
        if per.get("baseline") is not None:
            prev_base[prob] = (per["baseline"], turns)
        best = min(((t, m) for m, t in per.items() if m != "baseline"), default=(None, None))
        speedup = base / best[0] if (base and best[0]) else None
        kind, goal = TARGETS.get(turns, (None, None))
        met = None
        if kind == "speedup" and speedup is not None:
            met = speedup >= goal
        elif kind == "seconds" and best[0] is not None:
            met = best[0] < goal
        out.append({"problem": prob, "turns": turns, "best_method": best[1], "best_seconds": best[0],
                    "baseline_seconds": base, "baseline": base_how if base else None, "speedup": speedup,
                    "target": _target(kind, goal),
                    "target_met": met, "seconds_at_1e-8": per})
    return out


def _target(kind, goal) -> str | None:
    if not kind:
        return None
    return f">= {goal:g}x" if kind == "speedup" else f"< {goal:g} s"


def format_table(rows: list[Row], summ: list[dict], notes) -> str:
    """The benchmark as ``spinviz bench`` prints it: one line per row, then each problem's time to
    reach ``TARGET_ERROR`` against the baseline, then the notes."""
    lines = [f"{'problem':<7} {'turns':>6} {'method':<11} {'setting':<16} {'orient. err':>11} {'rel. Omega err':>14} "
             f"{'time s':>10} {'evals|steps':>11}  note", "-" * 110]
    for r in rows:
        lines.append(f"{r.problem:<7} {r.turns:>6.0e} {r.method:<11} {r.setting:<16} {r.orientation_error:>11.2e} "
                     f"{r.omega_rel_error:>14.2e} {r.seconds:>10.4g} {r.nfev if r.nfev is not None else '':>11}  {r.note}")
    lines += ["", f"time to reach {TARGET_ERROR:g} rad (interpolated along each sweep):"]
    for s in summ:
        best = f"{s['best_method']} {s['best_seconds']:.3g} s" if s["best_method"] else "not reached"
        base = f"{s['baseline_seconds']:.3g} s ({s['baseline']})" if s["baseline_seconds"] else "n/a"
        sp = f"{s['speedup']:.0f}x" if s["speedup"] else "n/a"
        met = {True: "met", False: "MISSED", None: "n/a"}[s["target_met"]]
        tgt = "" if s["target"] is None else f"; target {s['target']}: {met}"
        lines.append(f"  {s['problem']:<6} {s['turns']:>6.0e} turns: best {best}; baseline {base}; speed-up {sp}{tgt}")
    if notes:
        lines += [""] + [f"note: {n}" for n in notes]
    return "\n".join(lines)


def plot(rows: list[Row], path: str) -> None:
    """Error against time, log-log, one line per method; one panel per problem and horizon."""
    from ..plotting import pyplot, save

    plt = pyplot()

    keys = sorted({(r.problem, r.turns) for r in rows}, key=lambda k: (PROBLEMS.index(k[0]), k[1]))
    ncol = 3
    nrow = math.ceil(len(keys) / ncol)
    fig, axes = plt.subplots(nrow, ncol, figsize=(5 * ncol, 3.8 * nrow), squeeze=False)
    styles = {"baseline": ("k", "o"), "dop853": ("tab:gray", "s"), "radau": ("tab:brown", "v"),
              "taylor": ("tab:blue", "D"), "split8": ("tab:red", "*"),
              "split6": ("tab:orange", "X"), "secular": ("tab:green", "P")}
    for ax, (prob, turns) in zip(axes.flat, keys):
        sel = [r for r in rows if r.problem == prob and r.turns == turns and r.repeats and np.isfinite(r.orientation_error)]
        for m in styles:
            pts = sorted((r.seconds, max(r.orientation_error, 1e-16)) for r in sel if r.method == m)
            if pts:
                c, mk = styles[m]
                ax.loglog([p[0] for p in pts], [p[1] for p in pts], color=c, marker=mk, label=m)
        ax.axhline(TARGET_ERROR, color="grey", lw=0.8, ls=":")
        ax.set_title(f"({prob}), {turns:.0e} turns" if prob[0].isdigit() else f"{prob}, {turns:.0e} turns")
        ax.set_xlabel("wall time [s]")
        ax.set_ylabel("max orientation error [rad]")
        ax.legend(fontsize=7)
    for ax in list(axes.flat)[len(keys):]:
        ax.axis("off")
    fig.tight_layout()
    save(fig, path, dpi=100)
