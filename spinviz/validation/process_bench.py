"""``spinviz bench --process``: error against *whole-process* time, every method and the peers.

Each point is one command a user would type, timed from start to exit (the minimum of
``repeats`` runs, warm caches): ``spinviz simulate SCENE --out X.npz`` with the method and
tolerance written into a scene file, or a standalone script of the peers in ``benchmarks/``
(heyoka written from the paper without spinviz; scipy's DOP853 on a plain NumPy right-hand
side).  The error is the largest misorientation over the 41 output instants against the exact
orientation ((6.10), (3.9)) or against ``taylor-long`` at rtol 1e-18 (the others).

Problems, each at ~``turns`` turns (default 400): (6.10) truncated DAST cube, (3.9) askew top
about e2, (5.2) with orientation, the askew symmetric top of family 1 (delta = -0.6, chi = 55
deg) and an askew asymmetric body (I = (1, 0.85, 0.55), d along (0.3, 0.2, 0.93)), all at
tau0 |Omega0| = 1e-2 unless the closed form fixes it.

The figure the engine issue asks for is printed last: on the asymmetric body at rtol 1e-13,
spinviz's error and whole-process time against the standalone heyoka script at tol 1e-13.
"""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, field

import numpy as np

from .. import rotations as R
from .bench import make_problem

PEERS = os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))), "benchmarks")
PROBLEMS = ("6.10", "3.9", "5.2+q", "askew", "asym")
EPS = 1e-2


@dataclass
class Point:
    """One command's measurement: the largest misorientation over the output instants (rad)
    and the minimum whole-process time of ``repeats`` runs (s)."""

    problem: str
    method: str
    setting: str
    error: float
    seconds: float
    note: str = ""

    def record(self) -> dict:
        """The point as a JSON-ready dict (``spinviz bench --process --json``)."""
        return dict(self.__dict__)


@dataclass
class Spec:
    """One problem as the scene file and the peers see it (dimensionless, tau0 = 1)."""

    name: str
    model: str
    inertia: tuple
    dipole: tuple
    omega0: np.ndarray
    q0: np.ndarray
    t_end: float
    samples: int
    q_exact: np.ndarray | None
    symmetric: bool
    notes: list = field(default_factory=list)

    @property
    def t(self) -> np.ndarray:
        """The output instants, shape (samples,), tau0, evenly spaced over [0, t_end]."""
        return np.linspace(0.0, self.t_end, self.samples)


def problem(name: str, turns: float) -> Spec:
    """The benchmark problem ``name`` at ~``turns`` turns."""
    if name == "asym":
        w = np.array([0.3, 0.5, 0.8])
        w0 = w / np.linalg.norm(w) * EPS
        return Spec("asym", "reduced", (1.0, 0.85, 0.55), (0.3, 0.2, 0.93), w0, R.quat_from_euler_zxz((0.2, 0.9, -0.3)),
                    2.0 * math.pi * turns / EPS, 41, None, False)
    p = make_problem(name, turns)
    s = p.system
    d = np.asarray(s.coupling) / np.linalg.norm(s.coupling)
    return Spec(name, s.model, tuple(s.inertia), tuple(d), np.asarray(p.omega0), np.asarray(p.q0), float(p.t[-1]),
                len(p.t), p.q_exact, s.is_symmetric)


def scene_text(sp: Spec, method: str, kw: dict) -> str:
    """A scene file running ``sp`` with ``method`` and its settings."""
    lines = ["[body]", f"inertia = {list(map(float, sp.inertia))}", f"dipole = {list(map(float, sp.dipole))}",
             "[initial]", f"omega = {[float(x) for x in sp.omega0]}", f"quaternion = {[float(x) for x in sp.q0]}",
             "[simulation]", f'model = "{sp.model}"', f"t_end = {sp.t_end!r}", f"samples = {sp.samples}",
             f'method = "{method}"']
    lines += [f"{k} = {v!r}" for k, v in kw.items()]
    return "\n".join(lines) + "\n"


def configs(sp: Spec, quick: bool) -> list:
    """(method, settings) of every point: each registered method where it applies."""
    period = 2.0 * math.pi / float(np.linalg.norm(sp.omega0))
    tols = (1e-6, 1e-8, 1e-10, 1e-12, 1e-13) if not quick else (1e-8, 1e-10, 1e-13)
    out = [("taylor", {"rtol": r, "atol": r * 1e-2}) for r in tols]
    out.append(("taylor-long", {"rtol": 1e-15, "atol": 1e-17}))
    out += [("dop853", {"rtol": r, "atol": r * 1e-2}) for r in ((1e-8, 1e-10, 1e-12) if not quick else (1e-10,))]
    if not quick:
        out += [("rk45", {"rtol": r, "atol": r * 1e-2}) for r in (1e-6, 1e-8)]
        out += [(m, {"rtol": 1e-6, "atol": 1e-8}) for m in ("radau", "bdf", "lsoda")]
        if sp.symmetric:
            out += [(m, {"step": period / 4}) for m in ("split2", "split4", "split6", "split8")]
            out.append(("split8", {"step": period / 16}))
    return out


def _env() -> dict:
    """The commands' environment: Python's default bytecode cache, whatever this shell says.
    With PYTHONDONTWRITEBYTECODE set (as on some CI machines) spinviz's ~60 modules are
    compiled from source at every start (~40 ms) while the peers' imports come precompiled
    from site-packages: warm caches on both sides means .pyc files on both sides."""
    env = dict(os.environ)
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    return env


def _timed(cmd: list, repeats: int) -> float:
    best = math.inf
    for _ in range(repeats):
        t0 = time.perf_counter()
        subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, env=_env())
        best = min(best, time.perf_counter() - t0)
    return best


def _error(sp: Spec, path: str, q_ref) -> float:
    with np.load(path) as z:
        q = np.asarray(z["q"])
    return float(R.misorientation(q, q_ref).max())


def reference(sp: Spec):
    """The exact orientation, or taylor-long at rtol 1e-18 (in this process)."""
    if sp.q_exact is not None:
        return np.asarray(sp.q_exact)
    from ..driver import simulate
    from ..physics.bodies import Body

    body = Body("bench", "dimensionless", sp.inertia, sp.dipole)
    return simulate(body, sp.model, sp.omega0, t_eval=sp.t, q0=sp.q0, method="taylor-long", rtol=1e-18, atol=1e-18).q


def run(problems=PROBLEMS, turns: float = 400.0, repeats: int = 3, quick: bool = False, progress=None) -> list[Point]:
    """Every point of every problem (see the module docstring).  ``problems``, ``turns`` and
    ``repeats`` are checked first (``inputs.options.BenchRequest``: the work they mean within
    the cap)."""
    from ..inputs.options import BenchRequest

    BenchRequest(repeats=repeats, quick=quick, process=True, problems=problems, known=PROBLEMS, turns=turns)
    say = progress or (lambda m: None)
    py = sys.executable
    points: list[Point] = []
    with tempfile.TemporaryDirectory(prefix="spinviz-bench-") as tmp:
        for name in problems:
            sp = problem(name, turns)
            q_ref = reference(sp)
            pj = os.path.join(tmp, f"{name}.json")
            with open(pj, "w") as f:
                json.dump({"model": sp.model, "inertia": list(sp.inertia), "dipole": list(sp.dipole),
                           "omega0": sp.omega0.tolist(), "q0": list(map(float, sp.q0)), "t": sp.t.tolist()}, f)
            period = 2.0 * math.pi / float(np.linalg.norm(sp.omega0))
            for k, (method, kw) in enumerate(configs(sp, quick)):
                setting = ", ".join(f"{a}={v:.0e}" if a != "step" else f"step=turn/{period / v:.0f}"
                                    for a, v in kw.items() if a != "atol")
                say(f"{name}: {method} {setting}")
                scene = os.path.join(tmp, f"{name}_{k}.toml")
                out = os.path.join(tmp, f"{name}_{k}.npz")
                with open(scene, "w") as f:
                    f.write(scene_text(sp, method, kw))
                cmd = [py, "-m", "spinviz", "simulate", scene, "--out", out]
                try:
                    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, env=_env())   # warm
                    secs = _timed(cmd, repeats)
                    points.append(Point(name, method, setting, _error(sp, out, q_ref), secs))
                except subprocess.CalledProcessError as e:
                    msg = (e.stderr or b"").decode(errors="replace").strip().splitlines()
                    points.append(Point(name, method, setting, math.nan, math.nan, note=(msg[-1] if msg else "failed")[:120]))
            points += _peers(sp, pj, q_ref, tmp, repeats, quick, say)
    return points


def _peers(sp, pj, q_ref, tmp, repeats, quick, say) -> list[Point]:
    out = []
    script = os.path.join(PEERS, "peer_heyoka_simulate.py")
    base = os.path.join(PEERS, "peer_scipy_simulate.py")
    if not os.path.exists(script):
        return [Point(sp.name, "peer: heyoka script", "", math.nan, math.nan, note="benchmarks/ not found: run from a "
                                                                              "source checkout")]
    for tol in ((1e-6, 1e-8, 1e-10, 1e-12, 1e-13) if not quick else (1e-8, 1e-10, 1e-13)):
        say(f"{sp.name}: heyoka script tol={tol:.0e}")
        npz = os.path.join(tmp, "peer.npz")
        cmd = [sys.executable, script, pj, "--tol", repr(tol), "--out", npz]
        subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, env=_env())
        out.append(Point(sp.name, "peer: heyoka script", f"tol={tol:.0e}", _error(sp, npz, q_ref), _timed(cmd, repeats)))
    for rtol in ((1e-8, 1e-10, 1e-12) if not quick else (1e-10,)):
        say(f"{sp.name}: scipy script rtol={rtol:.0e}")
        npz = os.path.join(tmp, "base.npz")
        cmd = [sys.executable, base, pj, "--rtol", repr(rtol), "--out", npz]
        subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, env=_env())
        out.append(Point(sp.name, "peer: scipy DOP853 script", f"rtol={rtol:.0e}", _error(sp, npz, q_ref),
                         _timed(cmd, repeats)))
    return out


def headline(points: list[Point]) -> dict | None:
    """The engine issue's figure: on the asymmetric body at 1e-13, spinviz taylor against the
    heyoka script (error and whole-process time, and their ratio)."""
    a = [p for p in points if p.problem == "asym" and p.method == "taylor" and p.setting.startswith("rtol=1e-13")]
    b = [p for p in points if p.problem == "asym" and p.method == "peer: heyoka script" and p.setting == "tol=1e-13"]
    if not (a and b):
        return None
    return {"spinviz_error": a[0].error, "spinviz_seconds": a[0].seconds, "peer_error": b[0].error,
            "peer_seconds": b[0].seconds, "time_ratio": a[0].seconds / b[0].seconds}


def format_table(points: list[Point]) -> str:
    """The points as ``spinviz bench --process`` prints them, and the headline (spinviz against the
    standalone heyoka script on the asymmetric body)."""
    lines = [f"{'problem':<7} {'method':<26} {'setting':<16} {'orient. err':>11} {'whole s':>8}  note", "-" * 90]
    for p in points:
        lines.append(f"{p.problem:<7} {p.method:<26} {p.setting:<16} {p.error:>11.2e} {p.seconds:>8.3f}  {p.note}")
    h = headline(points)
    if h:
        lines += ["", f"askew asymmetric body, 400 turns, rtol 1e-13: spinviz simulate {h['spinviz_error']:.1e} rad in "
                      f"{h['spinviz_seconds']:.2f} s whole process; heyoka script {h['peer_error']:.1e} rad in "
                      f"{h['peer_seconds']:.2f} s: {h['time_ratio']:.2f}x"]
    return "\n".join(lines)


STYLE = {"taylor": ("tab:blue", "D"), "taylor-long": ("navy", "d"), "dop853": ("tab:gray", "s"), "rk45": ("silver", "s"),
         "radau": ("tab:brown", "v"), "bdf": ("peru", "v"), "lsoda": ("goldenrod", "v"), "split2": ("mistyrose", "*"),
         "split4": ("salmon", "*"), "split6": ("tab:orange", "X"), "split8": ("tab:red", "*"),
         "peer: heyoka script": ("k", "o"), "peer: scipy DOP853 script": ("dimgray", "^")}


def plot(points: list[Point], path: str) -> None:
    """Error against whole-process time, log-log, one panel per problem, one line per method."""
    from matplotlib.ticker import LogLocator, NullFormatter

    from ..plotting import pyplot, save

    plt = pyplot()
    probs = [p for p in PROBLEMS if any(q.problem == p for q in points)]
    fig, axes = plt.subplots(1, len(probs), figsize=(4.2 * len(probs), 4.6), squeeze=False)
    titles = {"6.10": "(6.10) truncated cube", "3.9": "(3.9) askew top about e2", "5.2+q": "(5.2) with orientation",
              "askew": "askew symmetric top", "asym": "askew asymmetric body"}
    for ax, name in zip(axes.flat, probs):
        sel = [p for p in points if p.problem == name and math.isfinite(p.error)]
        for m, (c, mk) in STYLE.items():
            pts = sorted((p.seconds, max(p.error, 1e-16)) for p in sel if p.method == m)
            if pts:
                ls = "--" if m.startswith("peer") else "-"
                ax.loglog([x for x, _ in pts], [y for _, y in pts], ls, color=c, marker=mk, label=m, ms=5)
        ax.set_title(titles.get(name, name), fontsize=10)
        ax.set_xlabel("whole-process time [s]")
        ax.set_ylabel("largest orientation error [rad]")
        ax.grid(True, which="both", alpha=0.25)
        ax.xaxis.set_major_locator(LogLocator(base=10.0, subs=(1.0, 2.0, 5.0)))   # 0.1, 0.2, 0.5, 1 ... s
        ax.xaxis.set_minor_formatter(NullFormatter())
    handles, labels = axes.flat[0].get_legend_handles_labels()
    for ax in axes.flat[1:]:                                    # every method once, whichever panel has it
        for h, lab in zip(*ax.get_legend_handles_labels()):
            if lab not in labels:
                handles.append(h)
                labels.append(lab)
    fig.legend(handles, labels, loc="lower center", ncol=min(len(labels), 7), fontsize=8, frameon=False)
    fig.suptitle("Work-precision, whole process (python -m spinviz simulate, or the standalone scripts), ~400 turns")
    fig.tight_layout(rect=(0.0, 0.1, 1.0, 1.0))
    save(fig, path, dpi=100)
