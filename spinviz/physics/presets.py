"""The section-6 presets: the cellulose nanocrystal and the DAST crystals, with provenance.

Each preset states where its numbers come from and keeps the figures the paper prints, so
``spinviz info`` can show both (docs/design.md, "Verified against the paper").  CGS throughout.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from .. import units as U
from ..rotations import quat_from_axis_angle
from .bodies import DENSITY, LENGTH_NM, Body, BodyError, PrintedFigure, Shape, _within, box, rod


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
        """Volume of one unit cell, cm^3 (1.04 x 1.13 x 1.79 nm^3 = 2.10e-21 cm^3)."""
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


def dast_box(a_nm: float, b_nm: float, c_nm: float, density: float | None = None, name=None,
             crystal: DastCrystal = DAST, **kw) -> Body:
    """A DAST a x b x c (nm) parallelepiped from the crystal data; edges along e1, e2, e3.

    density : g/cm^3, default from the crystal data (1.30); pass 1.37 for the paper's value.
    The dipole is the dipole density times the volume, along the crystal direction.
    """
    a, b, c = (_within(k, v, *LENGTH_NM) * U.NM for k, v in (("a_nm", a_nm), ("b_nm", b_nm), ("c_nm", c_nm)))
    rho = crystal.density if density is None else _within("density", density, *DENSITY)
    d = crystal.dipole_density * a * b * c * crystal.dipole_direction_crystal
    kw.setdefault("source", _DAST_SOURCE)
    kw.setdefault("reference_omega", OMEGA_PAPER)
    try:
        return box(a, b, c, rho, d, name=name or f"DAST {a_nm:g} x {b_nm:g} x {c_nm:g} nm", **kw)
    except BodyError as e:                                   # box's edges are these, in nm
        raise BodyError("a_nm, b_nm, c_nm" if e.key == "a, b, c" else e.key, e.reason) from None


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
    a_nm = _within("a_nm", a_nm, *LENGTH_NM)                # named before it is used in a name
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
    a_nm, c_nm = _within("a_nm", a_nm, *LENGTH_NM), _within("c_nm", c_nm, *LENGTH_NM)
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


def dast_families() -> list[dict]:
    """The two families of axially symmetric DAST boxes (section 6.2, figure 5) as lines of
    the diagram, derived from the crystal data (``DAST``: the dipole lies in the
    a-c plane at 35 deg from the a axis, e1):

    * family 1, a = b != c: the symmetry axis is c, so chi = 90 - 35 = 55 deg whatever c/a,
      and delta = 1 - I3/I1 = (c^2 - a^2)/(c^2 + a^2) runs over (-1, 1): a horizontal line
      (the paper's solid line; a = b = 100 nm, c = 50 nm is delta = -0.6);
    * family 2, a != b = c: the symmetry axis is a (e1), so chi = 35 deg, and
      delta = (a^2 - b^2)/(a^2 + b^2) again covers (-1, 1): a second horizontal line (the
      dash-dotted one).  The box inertia of a b = c box is I_a = m 2b^2/12,
      I_b = I_c = m (a^2 + b^2)/12, hence that delta.

    At delta = 0 (the cube) both meet the degenerate case where any axes are principal and
    e3 may be taken along d (chi = 0)."""
    t = DAST.dipole_angle_from_e1_deg
    d = np.linspace(-1.0, 1.0, 201)[1:-1]
    return [
        {"name": f"DAST family 1 (a = b, chi = {90.0 - t:g} deg)", "short": "DAST family 1 (a = b)", "delta": d,
         "chi": np.full_like(d, math.radians(90.0 - t)), "style": "-"},
        {"name": f"DAST family 2 (b = c, chi = {t:g} deg)", "short": "DAST family 2 (b = c)", "delta": d,
         "chi": np.full_like(d, math.radians(t)), "style": "-."},
    ]
