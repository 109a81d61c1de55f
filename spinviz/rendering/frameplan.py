"""What each frame shows: ``Panel`` and ``FramePlan``, plain data for the render workers.

Kept apart from ``timeline`` (which computes them from trajectories, with the physics it
needs) so that a render worker, which receives a pickled plan, imports only NumPy and the
planning modules -- not numba or scipy.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..inputs.render import RenderSpec
from ..rotations import matrix_from_quat


@dataclass(frozen=True)
class ShapeInfo:
    """The drawn body, as plain numbers (see ``physics.bodies.Shape``): kind "rod" (dims =
    length, diameter) or "box" (dims = a, b, c); q_body_from_shape (w, x, y, z) and the same
    rotation as a matrix, R_body_from_shape (3, 3) nested tuples; label."""

    kind: str
    dims: tuple[float, ...]
    q_body_from_shape: tuple[float, float, float, float] = (1.0, 0.0, 0.0, 0.0)
    R_body_from_shape: tuple = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))
    label: str = ""

    @classmethod
    def of(cls, shape) -> ShapeInfo | None:
        """The plain numbers of a ``physics.bodies.Shape`` (None stays None)."""
        if shape is None:
            return None
        q = tuple(float(x) for x in shape.q_body_from_shape)
        return cls(kind=str(shape.kind), dims=tuple(float(x) for x in shape.dims), q_body_from_shape=q,
                   R_body_from_shape=tuple(map(tuple, matrix_from_quat(np.asarray(q)).tolist())),
                   label=str(shape.label))


@dataclass
class Panel:
    """What one model's panel shows at each of the F frames.  Arrays a scene does not show are
    None (not computed).

    model : "reduced", "truncated" or "free".
    omega_mag : (F,) |Omega|, rad/s (CGS) or 1/tau0 (dimensionless).
    q : (F, 4) display orientation, body -> world, (w, x, y, z) scalar first;
        R_world_from_body : (F, 3, 3) the same as matrices.
    d_world : (F, 3) unit dipole direction, world frame.
    omega_world, L_world : (F, 3) angular velocity and angular momentum, world frame, scaled
        by |x(0)| of the reference panel (so |x(t)| / |x(0)| sets the arrow's length).
    omega_body : (F, 3) angular velocity, body frame, / |Omega(0)| of the reference panel (hodograph).
    angle_dL_deg : (F,) the instantaneous angle between d and L, deg (a body-frame quantity).
    angle_dL_range_deg : (F, 2) the lowest and highest angle over a precession turn, deg, shown
        instead when the phases on screen are re-timed (slowed spin) or not resolved.
    power : (F,) the radiated (Larmor) power P, erg/s (CGS) or I1/tau0^3 (dimensionless),
        averaged over the free precession for a symmetric top (``trajectory.radiated_power``).
    """

    model: str
    omega_mag: np.ndarray
    q: np.ndarray | None = None
    R_world_from_body: np.ndarray | None = None
    d_world: np.ndarray | None = None
    omega_world: np.ndarray | None = None
    L_world: np.ndarray | None = None
    omega_body: np.ndarray | None = None
    angle_dL_deg: np.ndarray | None = None
    angle_dL_range_deg: np.ndarray | None = None
    power: np.ndarray | None = None


@dataclass
class FramePlan:
    """What each frame shows, independent of the frame size: frame times, per-panel arrays,
    spin mode, labels.  ``picture.plan_picture`` lays it out on a frame.

    video_t, sim_t : (F,) frame times: video seconds and simulation time (scene unit).
    panels : one ``Panel`` per model, side by side.  units : "cgs" or "dimensionless".
    shape : the drawn body (None: unknown).  d_body : (3,) unit dipole direction, body frame.
    spin_mode : "true", "slowed" or "aliased" (``timeline.choose_spin_mode``).
    slowdown : (F,) true / shown phase rate in slowed mode, else None.
    notes : what the plan chose and why.
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
    d_body: np.ndarray
    spin_mode: str
    slowdown: np.ndarray | None = None
    notes: list[str] = field(default_factory=list)
    time_scale: tuple[str, float] | None = None
    phase_resolved: bool = True

    @property
    def frames(self) -> int:
        """F, the number of frames."""
        return self.video_t.size

    @property
    def t_end(self) -> float:
        """The last frame's simulation time, scene unit."""
        return float(self.sim_t[-1])

    def hud_lines(self, panel_index: int, f: int) -> list[str]:
        """The text of one panel at frame f (heading, readouts), then the shared lines (time, notes)."""
        from . import captions

        c = captions.Captions(self)
        return [c.heading(panel_index)[0], *c.readouts(panel_index, f), c.time_text(f), *c.notes(f)]
