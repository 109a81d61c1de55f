"""2-D plots (matplotlib, imported only when a plot is drawn), their atomic saving, and what
every plot of spinviz shares: each model's colour and line (``presentation``) and the time
axis's unit."""

from __future__ import annotations

from . import units as U
from .atomic import atomic_path
from .presentation import color_hex as model_color
from .presentation import line_kwargs as model_line

__all__ = ["pyplot", "save", "model_color", "model_line", "time_unit", "plot_trajectory"]


def pyplot():
    """matplotlib.pyplot on the Agg backend; a clear ImportError when matplotlib is missing."""
    try:
        import matplotlib
    except ImportError:
        raise ImportError("plots need matplotlib: pip install 'spinviz[render]'", name="matplotlib") from None
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def save(fig, path: str, dpi: int = 110, close: bool = True) -> None:
    """Write ``fig`` as a PNG atomically, then close it (unless ``close`` is False)."""
    import matplotlib.pyplot as plt

    try:
        with atomic_path(path) as tmp:
            fig.savefig(tmp, dpi=dpi, format="png")
    finally:
        if close:
            plt.close(fig)


def time_unit(t_end: float, units: str) -> tuple[float, str]:
    """(seconds per unit, axis label) for times up to t_end: hours, days or years (10⁶ years
    beyond a million), or τ₀ for dimensionless runs."""
    if units != "cgs":
        return 1.0, "time t (τ₀)"
    if t_end >= 2e6 * U.YEAR:
        return 1e6 * U.YEAR, "time t (million years)"
    if t_end >= 2 * U.YEAR:
        return U.YEAR, "time t (years)"
    if t_end >= 2 * U.DAY:
        return U.DAY, "time t (days)"
    if t_end >= 2 * U.HOUR:
        return U.HOUR, "time t (hours)"
    return 1.0, "time t (s)"


def plot_trajectory(traj, path: str | None = None):
    """Three panels for one run: |Omega|(t) (log-log), the angle between d and L (t), and the
    hodograph of Omega in the body frame (as the paper's figures 3 and 4).  Returns the
    figure; also writes it to ``path`` (PNG, atomic) when given."""
    import numpy as np

    plt = pyplot()
    cgs = traj.units == "cgs"
    t, w = traj.t, traj.omega
    tl = "t [s]" if cgs else "t [\u03c4\u2080]"
    fig = plt.figure(figsize=(13, 4))
    ax = fig.add_subplot(1, 3, 1)
    m = t > 0
    ax.loglog(t[m], np.linalg.norm(w[m], axis=1))
    ax.set_xlabel(tl)
    ax.set_ylabel("|\u03a9| [rad/s]" if cgs else "|\u03c9| [1/\u03c4\u2080]")
    ax.set_title("spin rate")
    ax = fig.add_subplot(1, 3, 2)
    ax.plot(t, np.degrees(traj.angle_d_L()))
    ax.set_xlabel(tl)
    ax.set_ylabel("\u2220(d, L) [deg]")
    ax.set_title("angle between dipole d and angular momentum L")
    ax = fig.add_subplot(1, 3, 3, projection="3d")
    x = w / (float(np.linalg.norm(w[0])) or 1.0)
    ax.plot(x[:, 0], x[:, 1], x[:, 2], lw=1.0)
    ax.scatter(*x[0], color="green", s=12, label="start")
    ax.scatter(*x[-1], color="crimson", s=12, label="end")
    ax.set_xlabel("\u03c9\u2081")
    ax.set_ylabel("\u03c9\u2082")
    ax.set_zlabel("\u03c9\u2083")
    ax.set_title("hodograph, body frame (units of |\u03c9\u2080|)")
    ax.legend(fontsize=8)
    fig.suptitle(f"{traj.body.name}: {traj.model} model")
    fig.tight_layout()
    if path is not None:
        save(fig, path, close=False)
    return fig
