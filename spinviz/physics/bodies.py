"""Bodies: inertia, dipole and shape of a rigid body; the shapes that make one.

A ``Body`` holds principal moments along body axes e1, e2, e3 and the body-frame
dipole, in one of two unit systems (see ``spinviz.units``):

* ``"cgs"``: inertia in g cm^2, dipole in statC cm, shape dimensions in cm;
* ``"dimensionless"``: inertia relative (only ratios matter), dipole a direction; the
  dipole's size is implied by tau0 = 2|d|^2 / (3 I1 c^3) = 1.

The presets of section 6 (cellulose rod, DAST crystals) are in ``presets``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .. import units as U
from ..errors import SpecError, SpecTypeError, brief
from ..rotations import world_from_body
from .equations import is_symmetric
from .models import System


class BodyError(SpecError):
    """A body that is not physical: a ``SpecError`` (so one rule for every public callable)
    whose ``key`` names the offending argument of the body's constructor."""


class BodyTypeError(BodyError, SpecTypeError):
    """A body argument of the wrong kind (a string where a number is expected)."""


def _number(key: str, x) -> float:
    """``x`` as a float, or ``BodyTypeError`` naming ``key`` (a string, None, a list)."""
    if isinstance(x, bool) or not isinstance(x, int | float | np.integer | np.floating):
        raise BodyTypeError(key, f"must be a number, got {brief(x)}")
    return float(x)


def _numbers(key: str, v, n: int = 3) -> tuple[float, ...]:
    """``v`` as ``n`` floats, or ``BodyTypeError`` naming ``key``."""
    if isinstance(v, str | bytes) or not hasattr(v, "__len__") or len(v) != n:
        raise BodyTypeError(key, f"must be {n} numbers, got {brief(v)}")
    return tuple(_number(key, x) for x in (v.tolist() if isinstance(v, np.ndarray) else v))


@dataclass(frozen=True)
class Shape:
    """Geometry for drawing, in the shape's own frame.

    kind : "rod" (a cylinder along the shape's z axis; dims = (length, diameter)) or
           "box" (edges a, b, c along the shape's x, y, z; dims = (a, b, c)).
    dims : cm for CGS bodies, arbitrary units for dimensionless ones.
    q_body_from_shape : (w, x, y, z), rotation from the shape frame to the body frame
           (identity except for the DAST cube, whose body axes put e3 along d).
    label : what is drawn, e.g. "cylinder" or "inertia-equivalent box".
    """

    kind: str
    dims: tuple[float, ...]
    q_body_from_shape: tuple[float, float, float, float] = (1.0, 0.0, 0.0, 0.0)
    label: str = ""


@dataclass(frozen=True)
class PrintedFigure:
    """A number the paper prints, to be set beside the one spinviz computes.

    key : a ``Body.figures`` key; value in the units given there; where : the place in
    the paper; approx : True when the paper gives only an order of magnitude ("~").
    """

    key: str
    value: float
    where: str
    approx: bool = False


@dataclass(frozen=True)
class Body:
    """A rigid body with a permanent dipole (principal axes e1, e2, e3).

    Attributes
    ----------
    name : str
    units : {"cgs", "dimensionless"}
        The unit system of everything derived from the body and of its runs.
    inertia : tuple of 3 float
        (I1, I2, I3), g cm^2 ("cgs") or relative ("dimensionless").
    dipole : tuple of 3 float
        (d1, d2, d3) in the body frame, statC cm ("cgs") or a direction ("dimensionless").
    shape : Shape or None
        What is drawn.
    source : str
        Where the numbers come from.
    printed : tuple of PrintedFigure
        The figures the paper prints for this body, to set beside the computed ones.
    reference_omega : float or None
        rad/s, the spin the paper uses for T and Theta (pi 1e10 s^-1).
    extra : dict
        Further derived numbers of a preset (density, mass, ...).
    """

    name: str
    units: str
    inertia: tuple[float, float, float]
    dipole: tuple[float, float, float]
    shape: Shape | None = None
    source: str = ""
    printed: tuple[PrintedFigure, ...] = ()
    reference_omega: float | None = None
    extra: dict = field(default_factory=dict, compare=False)

    def __post_init__(self):
        if not isinstance(self.name, str):
            raise BodyTypeError("name", f"must be a string, got {brief(self.name)}")
        if not isinstance(self.units, str):
            raise BodyTypeError("units", f"must be a string, got {brief(self.units)}")
        validate_inertia(self.inertia)
        d = np.asarray(_numbers("dipole", self.dipole), dtype=float)
        if not np.all(np.isfinite(d)):
            raise BodyError("dipole", f"must be three finite numbers, got {brief(self.dipole)}")
        if not np.any(d != 0.0):
            raise BodyError("dipole", "is zero: tau0 (3.8) is undefined; give a dipole and use model = \"free\" "
                                      "for torque-free motion")
        if self.units not in U.UNIT_SYSTEMS:
            raise BodyError("units", f"unknown unit system {self.units!r}; valid: {', '.join(U.UNIT_SYSTEMS)}")

    # -- plain data (saved trajectories carry their body) ---------------------------------
    def to_dict(self) -> dict:
        """JSON-ready description from which ``Body.from_dict`` rebuilds this body exactly."""
        shape = None if self.shape is None else {
            "kind": self.shape.kind, "dims": list(self.shape.dims),
            "q_body_from_shape": list(self.shape.q_body_from_shape), "label": self.shape.label}
        return {"name": self.name, "units": self.units, "inertia": [float(x) for x in self.inertia],
                "dipole": [float(x) for x in self.dipole], "shape": shape, "source": self.source,
                "printed": [dict(vars(p)) for p in self.printed], "reference_omega": self.reference_omega,
                "extra": {k: float(v) for k, v in self.extra.items()}}

    @classmethod
    def from_dict(cls, d: dict) -> Body:
        """The body ``to_dict`` described (as saved in a trajectory file's metadata), rebuilt
        exactly."""
        sh = d.get("shape")
        shape = None if sh is None else Shape(sh["kind"], tuple(sh["dims"]), tuple(sh["q_body_from_shape"]), sh["label"])
        return cls(name=d["name"], units=d["units"], inertia=tuple(d["inertia"]), dipole=tuple(d["dipole"]),
                   shape=shape, source=d.get("source", ""),
                   printed=tuple(PrintedFigure(**p) for p in d.get("printed", ())),
                   reference_omega=d.get("reference_omega"), extra=dict(d.get("extra", {})))

    # -- derived quantities --------------------------------------------------------------
    @property
    def I1(self) -> float:
        """I1, the first principal moment: g cm^2 (CGS) or 1 (dimensionless, the unit of inertia)."""
        return float(self.inertia[0])

    @property
    def I2(self) -> float:
        """I2, the second principal moment, in the units of ``I1``."""
        return float(self.inertia[1])

    @property
    def I3(self) -> float:
        """I3, the third principal moment (about e3, the symmetry axis of a symmetric top), in the
        units of ``I1``."""
        return float(self.inertia[2])

    @property
    def epsilon(self) -> float:
        """I3 / I1 (the small parameter of (6.1)-(6.6))."""
        return self.I3 / self.I1

    @property
    def delta(self) -> float:
        """delta = 1 - I3/I1 (3.6); the paper's elongation parameter of a symmetric top."""
        return 1.0 - self.I3 / self.I1

    @property
    def is_symmetric(self) -> bool:
        """I1 = I2, the symmetric top of section 3 (e3 the symmetry axis)."""
        return is_symmetric(self.inertia)

    @property
    def dipole_magnitude(self) -> float:
        """|d|: statC cm ("cgs"); in dimensionless units |d| is set by tau0 = 1."""
        return float(np.linalg.norm(self.dipole))

    @property
    def dipole_direction(self) -> np.ndarray:
        """Unit body-frame dipole direction, shape (3,)."""
        d = np.asarray(self.dipole, dtype=float)
        d = d / np.max(np.abs(d))                # |d| of a 1e300 or 1e-200 vector would overflow or underflow
        return d / np.linalg.norm(d)

    @property
    def chi(self) -> float:
        """Angle of d from e3, rad (3.2); meaningful as the paper's chi when d2 = 0."""
        n = self.dipole_direction
        return float(math.atan2(math.hypot(n[0], n[1]), n[2]))

    @property
    def tau0(self) -> float:
        """tau0 = 2 d^2 / (3 I1 c^3) (3.8): seconds ("cgs"); 1 by definition ("dimensionless")."""
        if self.units == "dimensionless":
            return 1.0
        return U.tau0_cgs(self.dipole_magnitude, self.I1)

    def braking_time_T(self, omega0: float) -> float:
        """T = 1 / (tau0 Omega0^2), section 3 after (3.9): the power-law braking time."""
        return 1.0 / (self.tau0 * omega0**2)

    def residual_time_Theta(self, omega3: float) -> float:
        """Theta = 1 / (tau0 Omega3^2 (I3/I1)^2), after (5.2): the drift to residual rotation."""
        return 1.0 / (self.tau0 * omega3**2 * self.epsilon**2)

    def system(self, model: str) -> System:
        """The dimensionless system (4.1) the integrators see: J = I / I1, g = d / |d|."""
        J = tuple(float(x) / self.I1 for x in self.inertia)
        return System(model=model, inertia=J, coupling=tuple(float(x) for x in self.dipole_direction))

    def dipole_world(self, q) -> np.ndarray:
        """Unit dipole direction in the world frame, O d / |d|; q shape (..., 4), (w, x, y, z)."""
        return world_from_body(q, self.dipole_direction)

    def figures(self) -> dict[str, tuple[float, str]]:
        """Derived quantities by key: value and unit, CGS (or relative when dimensionless)."""
        out: dict[str, tuple[float, str]] = {}
        cgs = self.units == "cgs"
        iu = "g cm^2" if cgs else "(relative)"
        out["I1"] = (self.I1, iu)
        out["I2"] = (self.I2, iu)
        out["I3"] = (self.I3, iu)
        out["epsilon"] = (self.epsilon, "")
        out["delta"] = (self.delta, "")
        out["chi_deg"] = (math.degrees(self.chi), "deg")
        if cgs:
            out["d_debye"] = (self.dipole_magnitude / U.DEBYE, "D")
            out["tau0"] = (self.tau0, "s")
            for k in ("density", "mass"):
                if k in self.extra:
                    out[k] = (self.extra[k], {"density": "g/cm^3", "mass": "g"}[k])
            if self.reference_omega:
                w = self.reference_omega
                out["T"] = (self.braking_time_T(w), "s")
                out["Theta"] = (self.residual_time_Theta(w), "s")
        else:
            out["tau0"] = (1.0, "tau0")
        return out


# The rod has I3/I1 = 0.015 and the checks go to 1e-4.  Measured with Radau on an askew top:
# at 1e-6 a run of 10 T takes ~2.5 min, at 1e-7 ~2 min per T, at 1e-9 nine minutes per T.
MIN_INERTIA_RATIO = 1e-6


def validate_inertia(inertia) -> None:
    """Raise BodyError unless inertia is three finite positive moments obeying I_i <= I_j + I_k."""
    if isinstance(inertia, str | bytes) or not hasattr(inertia, "__len__") or len(inertia) != 3:
        raise BodyTypeError("inertia", f"must be three principal moments, got {brief(inertia)}")
    a = np.asarray(_numbers("inertia", inertia), dtype=float)
    if not np.all(np.isfinite(a)):
        raise BodyError("inertia", f"must be finite, got {list(a)}")
    if np.any(a <= 0.0):
        raise BodyError("inertia", f"principal moments must be positive, got {list(a)}")
    if a.min() < MIN_INERTIA_RATIO * a.max():
        raise BodyError("inertia", f"smallest/largest moment = {a.min() / a.max():.2g} is below {MIN_INERTIA_RATIO:g}: "
                                   f"a needle this thin makes (4.4) too stiff to integrate (it divides by I3/I1)")
    for i in range(3):
        j, k = (i + 1) % 3, (i + 2) % 3
        if a[i] > (a[j] + a[k]) * (1.0 + 1e-12):
            raise BodyError(
                "inertia",
                f"I{i + 1} = {a[i]:g} exceeds I{j + 1} + I{k + 1} = {a[j] + a[k]:g}: no rigid body has these moments",
            )


# Physical ranges of the CGS inputs (the scene's schema reads them from here): wide enough for
# any nanoparticle and for a metre-sized crystal, narrow enough that every derived quantity
# (I ~ rho L^5, tau0 ~ d^2/I) is a float64.
LENGTH_NM = (0.1, 1e9, "from an atom to a metre")
DENSITY = (1e-3, 1e3, "g/cm^3")
DIPOLE_DEBYE = (1e-6, 1e30, "D")


def _positive(key: str, x: float) -> float:
    x = _number(key, x)
    if not math.isfinite(x) or x <= 0.0:
        raise BodyError(key, f"must be a positive finite number, got {brief(x)}")
    return x


def _within(key: str, x, lo: float, hi: float, why: str, unit: float = 1.0) -> float:
    """``x`` (in the caller's unit) with ``x / unit`` in [lo, hi], or ``BodyError`` naming ``key``
    with the whole range -- before anything derived from it can overflow."""
    x = _number(key, x)
    if not (math.isfinite(x) and lo <= x / unit <= hi):
        raise BodyError(key, f"must lie in [{lo * unit:g}, {hi * unit:g}] ({why}), got {brief(x)}")
    return x


def _length_cm(key: str, x) -> float:
    return _within(key, x, *LENGTH_NM, U.NM)


def _density(key: str, x) -> float:
    return _within(key, x, *DENSITY)


# --- shapes ------------------------------------------------------------------------------
def cylinder_inertia(length: float, diameter: float, density: float) -> tuple[float, float, float]:
    """Principal moments of a solid cylinder along e3: I1 = I2 = m (3 R^2 + L^2)/12, I3 = m R^2/2."""
    r = 0.5 * diameter
    m = density * math.pi * r * r * length
    i1 = m * (3.0 * r * r + length * length) / 12.0
    return (i1, i1, 0.5 * m * r * r)


def box_inertia(a: float, b: float, c: float, density: float) -> tuple[float, float, float]:
    """Principal moments of a solid a x b x c box, edges along e1, e2, e3: I1 = m (b^2 + c^2)/12, ..."""
    m = density * a * b * c
    return (m * (b * b + c * c) / 12.0, m * (a * a + c * c) / 12.0, m * (a * a + b * b) / 12.0)


def box_from_inertia(inertia) -> tuple[float, float, float]:
    """Edges (a, b, c) of the uniform box with principal moments proportional to ``inertia``.

    a^2 : b^2 : c^2 = (I2 + I3 - I1) : (I1 + I3 - I2) : (I1 + I2 - I3), scaled so the
    longest edge is 1.  Used to draw dimensionless bodies with their true proportions.
    """
    a = np.asarray(inertia, dtype=float)
    I1, I2, I3 = a / a.max()                         # only ratios matter; 1e308 moments would overflow below
    sq = np.array([I2 + I3 - I1, I1 + I3 - I2, I1 + I2 - I3]).clip(min=0.0)
    e = np.sqrt(sq)
    e = e / e.max()
    return tuple(float(x) for x in np.maximum(e, 1e-3))


def _shape_inertia(inertia, keys: str, whose: str):
    """The moments a shape gives, checked (``validate_inertia``); a rule they break is blamed on
    the shape's dimensions ``keys`` (a needle too thin to integrate comes from its edges)."""
    try:
        validate_inertia(inertia)
    except BodyError as e:
        raise BodyError(keys, f"{whose} principal moments: {e.reason}") from None
    return inertia


def rod(length, diameter, density, dipole, dipole_angle=0.0, name="rod", **kw) -> Body:
    """Solid cylinder (CGS: cm, g/cm^3, statC cm); axis e3, dipole in the e1-e3 plane at
    ``dipole_angle`` (rad) from the axis (the paper's chi)."""
    length = _length_cm("length", length)
    diameter = _length_cm("diameter", diameter)
    density = _density("density", density)
    dipole = _within("dipole", dipole, *DIPOLE_DEBYE, U.DEBYE)
    chi = _number("dipole_angle", dipole_angle)
    if not math.isfinite(chi):
        raise BodyError("dipole_angle", f"must be finite, got {brief(chi)}")
    inertia = _shape_inertia(cylinder_inertia(length, diameter, density), "length, diameter", "the rod's")
    mass = density * math.pi * 0.25 * diameter**2 * length
    return Body(
        name=name,
        units="cgs",
        inertia=inertia,
        dipole=(dipole * math.sin(chi), 0.0, dipole * math.cos(chi)),
        shape=Shape("rod", (length, diameter), label="cylinder"),
        extra={"density": density, "mass": mass},
        **kw,
    )


def box(a, b, c, density, dipole, name="box", q_body_from_shape=(1.0, 0.0, 0.0, 0.0), **kw) -> Body:
    """Solid a x b x c parallelepiped (CGS: cm, g/cm^3), edges along e1, e2, e3; ``dipole``
    the body-frame dipole vector (statC cm)."""
    a, b, c = (_length_cm(k, v) for k, v in (("a", a), ("b", b), ("c", c)))
    density = _density("density", density)
    return Body(
        name=name,
        units="cgs",
        inertia=_shape_inertia(box_inertia(a, b, c, density), "a, b, c", "the box's"),
        dipole=_numbers("dipole", dipole),
        shape=Shape("box", (a, b, c), _numbers("q_body_from_shape", q_body_from_shape, 4), label="parallelepiped"),
        extra={"density": density, "mass": density * a * b * c},
        **kw,
    )


def custom(inertia, dipole, units="cgs", name="custom", **kw) -> Body:
    """Any principal moments and dipole vector (asymmetric bodies included).

    Parameters
    ----------
    inertia : sequence of 3 float
        (I1, I2, I3), g cm^2 ("cgs") or relative to I1 ("dimensionless").
    dipole : sequence of 3 float
        d in the body frame (principal axes), statC cm ("cgs") or a direction ("dimensionless").
    units : {"cgs", "dimensionless"}
    name : str
    **kw
        Further ``Body`` fields (source, printed, reference_omega, ...).

    Returns
    -------
    Body
        Drawn as the uniform box with the same principal moments.
    """
    validate_inertia(inertia)
    inertia = _numbers("inertia", inertia)
    shape = Shape("box", box_from_inertia(inertia), label="inertia-equivalent box")
    return Body(name=name, units=units, inertia=inertia, dipole=_numbers("dipole", dipole), shape=shape, **kw)


def symmetric_top(delta: float, chi: float, name="symmetric top", **kw) -> Body:
    """Dimensionless symmetric top of section 3: I = (1, 1, 1 - delta), d = (sin chi, 0, cos chi).

    Parameters
    ----------
    delta : float
        1 - I3/I1 (3.6), in [-1, 1) (a prolate top above 0, an oblate one below).
    chi : float
        Angle of d from the symmetry axis e3, rad, d in the e1-e3 plane.
    name : str
    **kw
        Further ``Body`` fields.

    Returns
    -------
    Body
        units "dimensionless": tau0 = 1 (3.8), so times are in tau0 and rates in 1/tau0 (4.1).
    """
    delta = _number("delta", delta)
    if not math.isfinite(delta) or not (-1.0 <= delta < 1.0):
        raise BodyError("delta", f"must satisfy -1 <= delta < 1 (3.6), got {brief(delta)}")
    if 1.0 - delta < MIN_INERTIA_RATIO:
        raise BodyError("delta", f"1 - delta = I3/I1 = {1.0 - delta:.2g} is below {MIN_INERTIA_RATIO:g}: a needle this thin "
                                 f"makes (4.4) too stiff to integrate")
    chi = _number("chi", chi)
    if not math.isfinite(chi):
        raise BodyError("chi", f"must be finite, got {brief(chi)}")
    return custom((1.0, 1.0, 1.0 - delta), (math.sin(chi), 0.0, math.cos(chi)), units="dimensionless", name=name, **kw)
