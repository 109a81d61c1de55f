"""Bodies and materials: inertia, dipole, shape, and the presets of section 6.

A ``Body`` holds principal moments along body axes e1, e2, e3 and the body-frame
dipole, in one of two unit systems (see ``spinviz.units``):

* ``"cgs"``: inertia in g cm^2, dipole in statC cm, shape dimensions in cm;
* ``"dimensionless"``: inertia relative (only ratios matter), dipole a direction; the
  dipole's size is implied by tau0 = 2|d|^2 / (3 I1 c^3) = 1.

Each preset states where its numbers come from, and keeps the figures the paper
prints, so ``spinviz info`` can show both (DESIGN.md, section 2).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from .. import units as U
from ..rotations import quat_from_axis_angle, world_from_body
from .equations import System, is_symmetric


class BodyError(ValueError):
    """A body that is not physical; ``key`` names the offending parameter."""

    def __init__(self, key: str, reason: str):
        super().__init__(f"{key}: {reason}")
        self.key = key
        self.reason = reason


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

    inertia : (I1, I2, I3) -- g cm^2 ("cgs") or relative ("dimensionless").
    dipole : (d1, d2, d3) body frame -- statC cm ("cgs") or a direction ("dimensionless").
    reference_omega : rad/s, the spin the paper uses for T and Theta (pi 1e10 s^-1), or None.
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
        validate_inertia(self.inertia)
        d = np.asarray(self.dipole, dtype=float)
        if d.shape != (3,) or not np.all(np.isfinite(d)):
            raise BodyError("dipole", f"must be three finite numbers, got {self.dipole!r}")
        if not np.any(d != 0.0):
            raise BodyError("dipole", "is zero: tau0 (3.8) is undefined; give a dipole and use model = \"free\" for torque-free motion")
        if self.units not in U.UNIT_SYSTEMS:
            raise BodyError("units", f"unknown unit system {self.units!r}; valid: {', '.join(U.UNIT_SYSTEMS)}")

    # -- derived quantities --------------------------------------------------------------
    @property
    def I1(self) -> float:
        return float(self.inertia[0])

    @property
    def I2(self) -> float:
        return float(self.inertia[1])

    @property
    def I3(self) -> float:
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


def validate_inertia(inertia) -> None:
    """Raise BodyError unless inertia is three finite positive moments obeying I_i <= I_j + I_k."""
    a = np.asarray(inertia, dtype=float)
    if a.shape != (3,):
        raise BodyError("inertia", f"must be three principal moments, got {inertia!r}")
    if not np.all(np.isfinite(a)):
        raise BodyError("inertia", f"must be finite, got {list(a)}")
    if np.any(a <= 0.0):
        raise BodyError("inertia", f"principal moments must be positive, got {list(a)}")
    for i in range(3):
        j, k = (i + 1) % 3, (i + 2) % 3
        if a[i] > (a[j] + a[k]) * (1.0 + 1e-12):
            raise BodyError(
                "inertia",
                f"I{i + 1} = {a[i]:g} exceeds I{j + 1} + I{k + 1} = {a[j] + a[k]:g}: no rigid body has these moments",
            )


def _positive(key: str, x: float) -> float:
    x = float(x)
    if not math.isfinite(x) or x <= 0.0:
        raise BodyError(key, f"must be a positive finite number, got {x!r}")
    return x


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
    I1, I2, I3 = (float(x) for x in inertia)
    sq = np.array([I2 + I3 - I1, I1 + I3 - I2, I1 + I2 - I3]).clip(min=0.0)
    e = np.sqrt(sq)
    e = e / e.max()
    return tuple(float(x) for x in np.maximum(e, 1e-3))


def rod(length, diameter, density, dipole, dipole_angle=0.0, name="rod", **kw) -> Body:
    """Solid cylinder (CGS: cm, g/cm^3, statC cm); axis e3, dipole in the e1-e3 plane at
    ``dipole_angle`` (rad) from the axis (the paper's chi)."""
    length = _positive("length", length)
    diameter = _positive("diameter", diameter)
    density = _positive("density", density)
    dipole = _positive("dipole", dipole)
    chi = float(dipole_angle)
    inertia = cylinder_inertia(length, diameter, density)
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
    a, b, c = (_positive(k, v) for k, v in (("a", a), ("b", b), ("c", c)))
    density = _positive("density", density)
    return Body(
        name=name,
        units="cgs",
        inertia=box_inertia(a, b, c, density),
        dipole=tuple(float(x) for x in dipole),
        shape=Shape("box", (a, b, c), tuple(q_body_from_shape), label="parallelepiped"),
        extra={"density": density, "mass": density * a * b * c},
        **kw,
    )


def custom(inertia, dipole, units="cgs", name="custom", **kw) -> Body:
    """Any principal moments and dipole vector (asymmetric bodies included)."""
    inertia = tuple(float(x) for x in inertia)
    validate_inertia(inertia)
    shape = Shape("box", box_from_inertia(inertia), label="inertia-equivalent box")
    return Body(name=name, units=units, inertia=inertia, dipole=tuple(float(x) for x in dipole), shape=shape, **kw)


def symmetric_top(delta: float, chi: float, name="symmetric top", **kw) -> Body:
    """Dimensionless symmetric top of section 3: I = (1, 1, 1 - delta), d = (sin chi, 0, cos chi)."""
    delta = float(delta)
    if not math.isfinite(delta) or not (-1.0 <= delta < 1.0):
        raise BodyError("delta", f"must satisfy -1 <= delta < 1 (3.6), got {delta!r}")
    chi = float(chi)
    if not math.isfinite(chi):
        raise BodyError("chi", f"must be finite, got {chi!r}")
    return custom((1.0, 1.0, 1.0 - delta), (math.sin(chi), 0.0, math.cos(chi)), units="dimensionless", name=name, **kw)


# --- materials ---------------------------------------------------------------------------
@dataclass(frozen=True)
class DastCrystal:
    """DAST (4-dimethylamino-N-methyl-4-stilbazolium tosylate) crystal data, section 6.2.

    Source: the paper, section 6.2, after Ref. [MNS03]: cell 1.04 x 1.13 x 1.79 nm,
    molecular weight 410.5, Z = 4 molecules per cell, 30 D per ion pair in the e1-e3
    plane at 35 deg to e1; dipoles add up over the crystal.
    """

    cell_nm: tuple[float, float, float] = (1.04, 1.13, 1.79)
    molar_mass: float = 410.5
    z_per_cell: int = 4
    pair_dipole_debye: float = 30.0
    dipole_angle_from_e1_deg: float = 35.0

    @property
    def cell_volume_cm3(self) -> float:
        a, b, c = self.cell_nm
        return a * b * c * U.NM**3

    @property
    def density(self) -> float:
        """rho = Z mu m_u / V_cell, g/cm^3 (1.30 from these data; the paper prints 1.37)."""
        return self.z_per_cell * self.molar_mass * U.AMU / self.cell_volume_cm3

    @property
    def dipole_density(self) -> float:
        """Dipole per volume, statC cm / cm^3 (about 57 D/nm^3)."""
        return self.z_per_cell * self.pair_dipole_debye * U.DEBYE / self.cell_volume_cm3

    @property
    def dipole_direction_crystal(self) -> np.ndarray:
        """Unit dipole in the crystal frame (a, b, c axes): 35 deg from a, in the a-c plane."""
        t = math.radians(self.dipole_angle_from_e1_deg)
        return np.array([math.cos(t), 0.0, math.sin(t)])


DAST = DastCrystal()
OMEGA_PAPER = math.pi * 1e10   # rad/s, the spin of Ref. [JYRLYZ21] used throughout section 6

_DAST_SOURCE = (
    "DAST crystal data of section 6.2 (cell 1.04 x 1.13 x 1.79 nm, mu = 410.5, Z = 4, "
    "30 D per ion pair at 35 deg to e1 in the e1-e3 plane); density and dipole computed from them"
)


def dast_box(a_nm: float, b_nm: float, c_nm: float, density: float | None = None, name=None, crystal: DastCrystal = DAST, **kw) -> Body:
    """A DAST a x b x c (nm) parallelepiped from the crystal data; edges along e1, e2, e3.

    density : g/cm^3, default from the crystal data (1.30); pass 1.37 for the paper's value.
    The dipole is the dipole density times the volume, along the crystal direction.
    """
    a, b, c = (_positive(k, v) * U.NM for k, v in (("a_nm", a_nm), ("b_nm", b_nm), ("c_nm", c_nm)))
    rho = crystal.density if density is None else _positive("density", density)
    d = crystal.dipole_density * a * b * c * crystal.dipole_direction_crystal
    kw.setdefault("source", _DAST_SOURCE)
    kw.setdefault("reference_omega", OMEGA_PAPER)
    return box(a, b, c, rho, d, name=name or f"DAST {a_nm:g} x {b_nm:g} x {c_nm:g} nm", **kw)


# --- presets of section 6 ------------------------------------------------------------------
def cellulose_rod(density: float | None = None) -> Body:
    """Cellulose nanocrystal, section 6.1 (Ref. [F-PBL14]): L = 315 nm, L/D = 10,
    rho = 1.6 g/cm^3 (or ``density``), 4400 D along the axis (chi = 0)."""
    L = 315.0 * U.NM
    return rod(
        L, L / 10.0, 1.6 if density is None else density, 4400.0 * U.DEBYE, 0.0,
        name="cellulose nanocrystal",
        source="section 6.1 after Ref. [F-PBL14]: L = 315 nm, L/D = 10, rho = 1.6 g/cm^3, 4400 D along the axis",
        reference_omega=OMEGA_PAPER,
        printed=(
            PrintedFigure("I1", 3.3e-26, "section 6.1"),
            PrintedFigure("I3", 4.11e-28, "section 6.1 (its epsilon = 0.015 fits 4.87e-28)"),
            PrintedFigure("epsilon", 0.015, "section 6.1"),
            PrintedFigure("tau0", 1.4e-35, "section 6.1"),
            PrintedFigure("T", 3e6 * U.YEAR, "section 6.1, after (6.1)", approx=True),
            PrintedFigure("Theta", 1e10 * U.YEAR, "section 6.1, before (6.1)", approx=True),
        ),
    )


def dast_cube(a_nm: float = 100.0, density: float | None = None) -> Body:
    """Cubic DAST nanocrystal, section 6.2: a = 100 nm, a spherical top (delta = 0).

    Any axes are principal for a cube; as the paper does, the body frame has e3 along d
    (chi = 0), reached from the crystal axes by a rotation about b.  The drawn cube keeps
    its crystal faces through ``Shape.q_body_from_shape``.
    """
    base = dast_box(a_nm, a_nm, a_nm, density)
    n_c = DAST.dipole_direction_crystal
    beta = -math.atan2(n_c[0], n_c[2])                     # rotation about b taking d to e3
    q = tuple(float(x) for x in quat_from_axis_angle((0.0, 1.0, 0.0), beta))
    s = base.shape
    return Body(
        name=f"DAST cube {a_nm:g} nm",
        units="cgs",
        inertia=base.inertia,
        dipole=(0.0, 0.0, base.dipole_magnitude),
        shape=Shape("box", s.dims, q, label="cube (crystal faces)"),
        source=_DAST_SOURCE + "; body axes with e3 along d, as in section 6.2",
        reference_omega=OMEGA_PAPER,
        extra=dict(base.extra),
        printed=(
            PrintedFigure("density", 1.37, "section 6.2"),
            PrintedFigure("I1", 2.3e-26, "section 6.2, after (6.10)"),
            PrintedFigure("d_debye", 5.6e7, "section 6.2, after (6.10)"),
            PrintedFigure("tau0", 3.4e-27, "section 6.2, after (6.10)"),
            PrintedFigure("Theta", 4.0 * U.DAY, "section 6.2, after (6.10)", approx=True),
        ) if a_nm == 100.0 else (),
    )


def dast_family1(a_nm: float = 100.0, c_nm: float = 50.0, density: float | None = None) -> Body:
    """DAST family-1 box a = b = 100 nm, c = 50 nm (section 6.2): delta = -0.6, chi = 55 deg."""
    body = dast_box(a_nm, a_nm, c_nm, density, name=f"DAST family-1 box {a_nm:g} x {a_nm:g} x {c_nm:g} nm")
    if (a_nm, c_nm) != (100.0, 50.0):
        return body
    return replace(
        body,
        printed=(
            PrintedFigure("density", 1.37, "section 6.2"),
            PrintedFigure("I1", 7.14e-27, "section 6.2, family 1"),
            PrintedFigure("delta", -0.6, "section 6.2, family 1"),
            PrintedFigure("chi_deg", 55.0, "section 6.2, family 1"),
            PrintedFigure("d_debye", 2.8e7, "section 6.2, family 1"),
        ),
    )


PRESETS = {
    "cellulose_rod": cellulose_rod,
    "dast_cube": dast_cube,
    "dast_family1": dast_family1,
}
