"""What each frame shows: ``Panel`` and ``FramePlan``, plain data for the render workers.

Kept apart from ``timeline`` (which computes them from trajectories) so that a render
worker, which receives a pickled plan, imports only NumPy and this module -- not the
rotation library, numba or scipy that planning needs.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .spec import RenderSpec


@dataclass(frozen=True)
class ShapeInfo:
    """The drawn body, as plain numbers (see ``physics.bodies.Shape``): kind "rod" (dims =
    length, diameter) or "box" (dims = a, b, c); q_body_from_shape (w, x, y, z); label."""

    kind: str
    dims: tuple[float, ...]
    q_body_from_shape: tuple[float, float, float, float] = (1.0, 0.0, 0.0, 0.0)
    label: str = ""

    @classmethod
    def of(cls, shape) -> ShapeInfo | None:
        if shape is None:
            return None
        return cls(kind=str(shape.kind), dims=tuple(float(x) for x in shape.dims),
                   q_body_from_shape=tuple(float(x) for x in shape.q_body_from_shape), label=str(shape.label))


@dataclass
class Panel:
    """What one model's panel shows at each frame (F frames).

    q : (F, 4) display orientation, body -> world, (w, x, y, z); dipole : (F, 3) unit, world;
    omega, L : (F, 3) world vectors scaled to |x(t)|/|x(0)| of the reference panel;
    omega_body : (F, 3) body-frame angular velocity / |omega(0)| (hodograph);
    omega_mag : (F,) |Omega| in scene units;
    angle_dL_deg : (F,) the instantaneous angle between d and L (a body-frame quantity);
    angle_dL_range_deg : (F, 2) the lowest and highest angle over a precession turn, shown
        instead when the phases on screen are re-timed (slowed spin) or not resolved.
    Arrays a scene does not show are None (not computed).
    """

    model: str
    omega_mag: np.ndarray
    q: np.ndarray | None = None
    dipole: np.ndarray | None = None
    omega: np.ndarray | None = None
    L: np.ndarray | None = None
    omega_body: np.ndarray | None = None
    angle_dL_deg: np.ndarray | None = None
    angle_dL_range_deg: np.ndarray | None = None


@dataclass
class FramePlan:
    """Everything the renderer needs: frame times, per-panel arrays, spin mode, labels.

    time_scale : (symbol, value in scene units) of the time bar's unit -- ("Θ", Theta) or
        ("T", T) of the initial state -- or None (marked in the scene's time unit).
    phase_resolved : False when some run's spin phase is not physical (float64 resolution,
        averaging): then no frame presents the shown pose as the true one.
    """

    spec: RenderSpec
    video_t: np.ndarray
    sim_t: np.ndarray
    panels: list[Panel]
    units: str
    body_name: str
    shape: ShapeInfo | None
    dipole_body: np.ndarray  # unit, body frame
    spin_mode: str
    slowdown: np.ndarray | None = None      # (F,) true / shown phase rate (slowed mode)
    notes: list[str] = field(default_factory=list)
    time_scale: tuple[str, float] | None = None
    phase_resolved: bool = True

    @property
    def frames(self) -> int:
        return self.video_t.size

    @property
    def t_end(self) -> float:
        return float(self.sim_t[-1])

    def hud_lines(self, panel_index: int, f: int) -> list[str]:
        """The text of one panel at frame f (heading, readouts), then the shared lines."""
        from . import captions

        c = captions.Captions(self)
        return [c.heading(panel_index)[0], *c.readouts(panel_index, f), c.time_text(f), *c.notes(f)]
