"""``spinviz compare``: how far apart the reduced and truncated predictions drift.

For a two-model scene: the misorientation angle between the two predicted orientations
and the angle between the two predicted dipole directions over time, the first times
they exceed 1 and 10 degrees, and each model's final state (residual rotation about the
dipole, or spin-down to rest).  When the spin phase is beyond float64 resolution (real
particles, ``secular`` runs), orientations cannot be compared turn by turn; then the
slow, physical comparison is reported instead: each model's angle between the dipole and
its rotation axis L, and their difference.

Numbers come from NumPy; matplotlib is imported only to draw the PNGs.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .. import rotations as R
from ..plotting import model_color, pyplot, save, time_unit
from ..trajectory import Trajectory
from ..units import format_time

THRESHOLDS_DEG = (1.0, 10.0)
MAX_SAMPLES = 100_000          # per kind of output time: 2 x 1e5 instants x 7 floats x 2 models ~ 22 MB


@dataclass
class ModelSummary:
    """How one model's run ends (``summarize``): |Omega| at the end (rad/s or 1/tau0) and
    relative to the start, the late spin-down exponent d ln|Omega| / d ln t, the angle between
    Omega and d (degrees, frame-free), angle(d, L) along the run, shape (N,), degrees, and the
    end state in words."""

    model: str
    omega_final: float               # |Omega| at t_end, scene units
    omega_ratio: float               # |Omega(t_end)| / |Omega(0)|
    spin_exponent: float             # d ln|Omega| / d ln t over the last third
    angle_omega_d_deg: float         # angle between Omega and d at t_end
    angle_d_L_deg: np.ndarray        # (N,) angle between d and L
    final_state: str


@dataclass
class Comparison:
    """Reduced against truncated from the same start (``compare``), stored at the same times.

    t : (N,) s or tau0; misorientation_deg, dipole_angle_deg : (N,) degrees between the two
    orientations and the two world-frame dipoles, None where the phases are not resolved;
    cone_difference_deg : (N,) difference of angle(d, L), degrees (needs no phase);
    first_exceed : metric -> {threshold: first time above it, or None}; models : the two
    ``ModelSummary``; omega_body : model -> (N, 3) body-frame Omega, rad/s or 1/tau0.
    """

    t: np.ndarray
    units: str
    phase_resolved: bool
    misorientation_deg: np.ndarray | None
    dipole_angle_deg: np.ndarray | None
    cone_difference_deg: np.ndarray
    first_exceed: dict = field(default_factory=dict)      # metric -> {threshold: time or None}
    models: list = field(default_factory=list)
    omega_body: dict = field(default_factory=dict)
    title: str = ""

    def table(self) -> str:
        """The comparison for people (``format_table``): when the models part, how each ends."""
        return format_table(self, self.title)

    def record(self) -> dict:
        """The end states and first crossings as a JSON-ready dict (``spinviz compare --json``)."""
        return {
            "phase_resolved": self.phase_resolved,
            "units": self.units,
            "first_exceed": self.first_exceed,
            "models": [{"model": m.model, "final_state": m.final_state, "omega_final": m.omega_final,
                        "omega_ratio": m.omega_ratio, "spin_exponent": m.spin_exponent,
                        "angle_omega_d_deg": m.angle_omega_d_deg, "angle_d_L_final_deg": float(m.angle_d_L_deg[-1])}
                       for m in self.models],
        }


def compare_times(t_end: float, n: int) -> np.ndarray:
    """Output times: n evenly spaced and n log-spaced from t_end 1e-6 (early departures)."""
    lin = np.linspace(0.0, t_end, n)
    log = np.geomspace(t_end * 1e-6, t_end, n)
    return np.unique(np.concatenate([lin, log]))


def first_crossing(t, angle_deg, threshold):
    """The first time ``angle_deg`` exceeds ``threshold`` (linear interpolation), or None."""
    above = np.nonzero(angle_deg > threshold)[0]
    if above.size == 0:
        return None
    i = int(above[0])
    if i == 0:
        return float(t[0])
    a0, a1 = angle_deg[i - 1], angle_deg[i]
    return float(t[i - 1] + (threshold - a0) / (a1 - a0) * (t[i] - t[i - 1]))


def _angle(a, b):
    """Angle between row vectors, degrees."""
    return np.degrees(R.angle_between(a, b))


def summarize(tr: Trajectory) -> ModelSummary:
    """The end state of one run (``ModelSummary``): residual rotation about d (5.2), (6.8),
    spin-down to rest (5.4), (6.10), or still evolving, from |Omega| over the last third of the
    run and the angle between Omega and d at its end."""
    w = tr.omega_body
    mag = np.linalg.norm(w, axis=1)
    d = tr.body.dipole_direction
    L_body = np.asarray(tr.body.inertia) * w
    ang_wd = float(_angle(w[-1:], d[None, :])[0])
    ang_wd = min(ang_wd, 180.0 - ang_wd)             # rotation about d or about -d is the same state
    cone = _angle(L_body, np.broadcast_to(d, L_body.shape))
    tumbling = None
    if not tr.body.is_symmetric and not tr.phase_resolved:
        # an asymmetric body at an averaged phase: L runs round its polhode, so the slow quantity is
        # the swing of angle(d, L) over one period (``Trajectory.angle_d_L_range``): its lower end, the
        # nearest d comes to L, is compared (the swing about its middle is what the torque changes)
        lo, hi = tr.angle_d_L_range()
        cone = np.degrees(lo)
        tumbling = (float(np.degrees(lo[-1])), float(np.degrees(hi[-1])))
    late = tr.t >= tr.t[-1] * (2.0 / 3.0)
    late &= tr.t > 0
    expo = float(np.polyfit(np.log(tr.t[late]), np.log(mag[late]), 1)[0]) if late.sum() >= 3 else float("nan")
    ratio = float(mag[-1] / mag[0]) if mag[0] > 0 else float("nan")
    if ang_wd < 2.0 and abs(expo) < 0.05:
        state = f"residual rotation about the dipole (|Omega| -> {ratio:.3g} |Omega0|, angle(Omega, d) = {ang_wd:.2g} deg)"
    elif expo < -0.2:
        state = f"spinning down to rest (|Omega| ~ t^{expo:.2f}, now {ratio:.3g} |Omega0|)"
    else:
        state = f"still evolving (|Omega| ~ t^{expo:.2f}, angle(Omega, d) = {ang_wd:.3g} deg)"
    if tumbling is not None:
        state += _tumbling_words(tr, tumbling)
    return ModelSummary(tr.model, float(mag[-1]), ratio, expo, ang_wd, cone, state)


def _tumbling_words(tr: Trajectory, swing) -> str:
    """'; tumbling about e3 (largest moment), d 41-69 deg from L' for an asymmetric body's end."""
    from ..physics import polhode as PH

    J = tuple(float(x) for x in tr.body.inertia)
    try:
        c, s_c = PH.encircled_axis(J, tr.omega_body[-1])
    except PH.NoPolhode:
        return "; on the separatrix at the end"
    which = "largest" if J[c] == max(J) else "smallest"
    return f"; tumbling about {'+' if s_c > 0 else '-'}e{c + 1} ({which} moment), d {swing[0]:.3g}-{swing[1]:.3g} deg from L"


def compare(trajs: list[Trajectory]) -> Comparison:
    """Compare two trajectories of the same body and initial state, stored at the same times."""
    if len(trajs) != 2:
        raise ValueError(f"compare takes two trajectories (one model each), got {len(trajs)}")
    a, b = trajs
    resolved = a.phase_resolved and b.phase_resolved and a.q is not None and b.q is not None
    mis = dip = None
    first = {}
    if resolved:
        mis = np.degrees(R.misorientation(a.q, b.q))
        dip = _angle(a.dipole_world(), b.dipole_world())
        first["misorientation"] = {f"{x:g} deg": first_crossing(a.t, mis, x) for x in THRESHOLDS_DEG}
        first["dipole_direction"] = {f"{x:g} deg": first_crossing(a.t, dip, x) for x in THRESHOLDS_DEG}
    sa, sb = summarize(a), summarize(b)
    cone_diff = np.abs(sa.angle_d_L_deg - sb.angle_d_L_deg)
    first["angle(d, L)"] = {f"{x:g} deg": first_crossing(a.t, cone_diff, x) for x in THRESHOLDS_DEG}
    return Comparison(t=np.asarray(a.t), units=a.units, phase_resolved=resolved, misorientation_deg=mis,
                      dipole_angle_deg=dip, cone_difference_deg=cone_diff, first_exceed=first, models=[sa, sb],
                      omega_body={sa.model: a.omega_body, sb.model: b.omega_body})


def format_table(c: Comparison, title: str) -> str:
    """The comparison as the text ``spinviz compare`` prints: first crossings of 1 and 10 deg,
    then each model's end state, times in the scene's units."""
    units = c.units
    lines = [title, ""]
    if not c.phase_resolved:
        lines.append("orientations not compared turn by turn: the spin phase is beyond float64 resolution here;")
        lines.append("compared instead: each model's angle between d and its rotation axis L (a slow, physical quantity)")
        lines.append("")
    lines.append(f"{'first time the models differ by':<40} {'> 1 deg':>16} {'> 10 deg':>16}")
    names = {"misorientation": "misorientation (whole rotation)", "dipole_direction": "angle between the dipoles",
             "angle(d, L)": "difference of angle(d, L)"}
    for key, row in c.first_exceed.items():
        cells = [format_time(v, units) if v is not None else "never" for v in row.values()]
        lines.append(f"{names[key]:<40} {cells[0]:>16} {cells[1]:>16}")
    lines.append("")
    lines.append(f"at t = {format_time(c.t[-1], units)}:")
    for m in c.models:
        lines.append(f"  {m.model:<10} {m.final_state}; angle(d, L) = {m.angle_d_L_deg[-1]:.3g} deg")
    return "\n".join(lines)


DIFF_STYLES = {"misorientation": ("0.6", "-."), "dipoles": ("0.35", "--"), "cone": ("0.0", "-")}


def plot(c: Comparison, path: str, title: str) -> None:
    """How far apart the models drift, |Ω| and ∠(d, L) against time (PNG, atomic).

    Time on a log axis from the first output instant (both early departures and late
    asymptotics show; t = 0 is the common start), in days, years or τ₀; thresholds labelled;
    each model in its colour of the videos, differences between models in greys."""
    plt = pyplot()

    scale, tl = time_unit(float(c.t[-1]), c.units)
    pos = c.t > 0
    t = c.t[pos] / scale
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.6))
    ax = axes[0]
    if c.phase_resolved:
        col, ls = DIFF_STYLES["misorientation"]
        ax.plot(t, c.misorientation_deg[pos], color=col, ls=ls, label="misorientation (whole rotation)")
        col, ls = DIFF_STYLES["dipoles"]
        ax.plot(t, c.dipole_angle_deg[pos], color=col, ls=ls, label="angle between the two dipoles")
    col, ls = DIFF_STYLES["cone"]
    ax.plot(t, c.cone_difference_deg[pos], color=col, ls=ls, lw=1.6,
            label="|∠(d, L) reduced − ∠(d, L) truncated|")
    ax.set_yscale("symlog", linthresh=1.0, linscale=0.5)
    ax.set_ylim(0.0, 200.0)
    ax.set_yticks([0, 1, 10, 100, 180], ["0°", "1°", "10°", "100°", "180°"])
    for x in THRESHOLDS_DEG:
        ax.axhline(x, color="tab:red", lw=0.8, ls=":")
        ax.annotate(f"{x:g}° apart", (0.01, x), xycoords=("axes fraction", "data"), xytext=(2, 2),
                    textcoords="offset points", fontsize=8, color="tab:red", va="bottom")
    _time_axis(ax, tl, "angle between the predictions (°)", "reduced vs truncated: how far apart")
    ax = axes[1]
    for m, w in c.omega_body.items():
        ax.plot(t, np.linalg.norm(w[pos], axis=1), color=model_color(m), lw=1.6, label=m)
    ax.set_yscale("log")
    _time_axis(ax, tl, "|Ω| (rad/s)" if c.units == "cgs" else "|ω| (1/τ₀)", "spin rate")
    ax = axes[2]
    for m in c.models:
        ax.plot(t, m.angle_d_L_deg[pos], color=model_color(m.model), lw=1.6, label=m.model)
    top = max(float(np.max(m.angle_d_L_deg)) for m in c.models)
    ax.set_ylim(0.0, min(180.0, 1.15 * top + 1.0))          # headroom: a curve at its top stays visible
    ax.yaxis.set_major_formatter(lambda v, _: f"{v:g}°")
    _time_axis(ax, tl, "∠(d, L), dipole to angular momentum (°)", "dipole vs rotation axis")
    fig.suptitle(title)
    fig.tight_layout()
    save(fig, path)


def _time_axis(ax, xlabel, ylabel, title):
    """A log time axis (decades labelled once each, no tick over another) and the labels."""
    ax.set_xscale("log")
    ax.set_xlabel(xlabel + ", log scale")
    ax.set_ylabel(ylabel)
    ax.set_title(title)
    ax.grid(True, which="major", color="0.9", lw=0.6)
    ax.legend(fontsize=8)


def plot_hodograph(c: Comparison, path: str, title: str) -> None:
    """Ω(t) in the body frame for both models, as in the paper's figures 3 and 4, on the same
    axes ranges (the two curves compare at a glance), each model in its colour."""
    plt = pyplot()

    fig = plt.figure(figsize=(11, 5))
    scale = max(float(np.linalg.norm(w[0])) for w in c.omega_body.values()) or 1.0
    allw = np.vstack([w for w in c.omega_body.values()]) / scale
    lo, hi = np.minimum(allw.min(axis=0), 0.0), np.maximum(allw.max(axis=0), 0.0)
    pad = 0.05 * float(np.max(hi - lo) or 1.0)
    sym = "Ω" if c.units == "cgs" else "ω"
    for k, (m, w) in enumerate(c.omega_body.items()):
        ax = fig.add_subplot(1, 2, k + 1, projection="3d")
        x = w / scale
        ax.plot(x[:, 0], x[:, 1], x[:, 2], lw=1.2, color=model_color(m))
        ax.scatter(*x[0], color="black", s=18, marker="o", label="start")
        ax.scatter(*x[-1], color="black", s=24, marker="x", label="end")
        ax.set_xlim(lo[0] - pad, hi[0] + pad)
        ax.set_ylim(lo[1] - pad, hi[1] + pad)
        ax.set_zlim(lo[2] - pad, hi[2] + pad)
        for i, setter in enumerate((ax.set_xlabel, ax.set_ylabel, ax.set_zlabel)):
            setter(f"{sym}{'₁₂₃'[i]} / |{sym}₀|")
        ax.set_title(m, color=model_color(m))
        ax.legend(fontsize=8, loc="upper left")
    fig.suptitle(f"{title}\nbody-frame angular velocity, in units of |{sym}(0)|, same axes in both")
    fig.tight_layout()
    save(fig, path)
