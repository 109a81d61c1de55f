"""The tables of a scene file: ``[body]``, ``[initial]``, ``[simulation]``, ``[observe]`` and
the top level (``[render]`` is ``inputs.render.RenderSpec``, ``[environment]``
``inputs.environment.EnvironmentSpec``).

Each table is a request class whose fields are its TOML keys; ``spinviz.scene.parse_scene``
validates each table with it (``toml.table``: errors name the file, table and key) and then
checks what joins tables -- units, the spin scale, the horizon -- by building one
``SimulationRequest`` per model, the very object ``spinviz.simulate`` checks its arguments
with.  Lengths are in nm, densities g/cm^3, dipoles D (``_debye``) or statC cm, angles rad
unless the key ends in ``_deg``.
"""

from __future__ import annotations

import math
from typing import Annotated, Literal

import numpy as np
from pydantic import PlainValidator, model_validator

from .. import rotations as R
from .. import units as U
from ..errors import SpecError, brief
from ..physics import bodies as B
from ..physics import models as M
from ..physics import presets as P
from . import receiver as RX
from .base import Direction, Line, Positive, Real, Text, between, check_vector, one_line, refused, request, shown, wrong_type
from .render import MAX_TITLE
from .simulation import Atol, Method, ModelName, Quaternion, Rtol, Samples, Vector3
from .toml import Table

# Physical ranges of the CGS inputs, the body constructors' own (physics.bodies): the same
# value gets the same reason from a scene and from Python.
LENGTH_NM, DENSITY, DIPOLE_DEBYE = B.LENGTH_NM, B.DENSITY, B.DIPOLE_DEBYE
ASPECT = (1e-3, 1e3, "L/D")

# the arguments of physics.bodies.rod / box, as [body]'s keys (a rod's diameter may come from aspect)
_SHAPE_KEYS = {"length": "length_nm", "diameter": "diameter_nm", "length, diameter": "length_nm, diameter_nm",
               "a": "a_nm", "b": "b_nm", "c": "c_nm", "a, b, c": "a_nm, b_nm, c_nm", "dipole": "dipole_debye"}

Length = Annotated[Real, between(*LENGTH_NM)]
Density = Annotated[Real, between(*DENSITY)]


def _number_or_vector(v):
    """A rod's dipole is one number (D); a box's or a custom body's a body-frame vector."""
    if isinstance(v, (list, tuple, np.ndarray)):
        return check_vector(v, 3)
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        raise wrong_type(f"must be a number (a rod) or a list of 3 numbers, got {brief(v)}")
    if not math.isfinite(v):
        raise ValueError(f"must be finite, got {v}")
    return float(v)


def _title(v):
    v = one_line(v)
    if len(v) > MAX_TITLE:
        raise ValueError(f"must be at most {MAX_TITLE} characters, got {len(v)}")
    return v


def _models(v):
    if not isinstance(v, list | tuple) or not 1 <= len(v) <= 2 or not all(isinstance(m, str) for m in v):
        raise wrong_type(f"must be a list of one or two model names, got {brief(v)}")
    for m in v:
        if m not in M.names():
            raise ValueError(f"unknown model {brief(m)}; valid: {', '.join(M.names())}")
    if len(set(v)) != len(v):
        raise ValueError(f"{v[0]!r} named twice")
    return tuple(v)


def one_of(table, *keys: str) -> str | None:
    """The one of ``keys`` that is set (None if none); ``SpecError`` if more than one is."""
    present = [k for k in keys if getattr(table, k) is not None]
    if len(present) > 1:
        raise SpecError(present[1], f"give only one of {', '.join(keys)}")
    return present[0] if present else None


# --- [body] --------------------------------------------------------------------------------
BODY_FORMS = ("preset", "shape", "delta", "inertia")
_FORM_KEYS = {            # which keys each way of giving a body takes (besides "name")
    "cellulose_rod": {"preset", "density"},
    "dast_cube": {"preset", "density", "a_nm"},
    "dast_family1": {"preset", "density", "a_nm", "c_nm"},
    "dast_box": {"preset", "density", "a_nm", "b_nm", "c_nm"},
    "rod": {"shape", "density", "length_nm", "diameter_nm", "aspect", "dipole_debye", "chi", "chi_deg"},
    "box": {"shape", "density", "a_nm", "b_nm", "c_nm", "dipole_debye"},
    "delta": {"delta", "chi", "chi_deg"},
    "inertia": {"inertia", "dipole", "dipole_debye"},
}


@request
class BodyTable:
    """``[body]``: a preset, a shape (CGS), a dimensionless symmetric top (delta, chi) or any
    principal moments and dipole (inertia, dipole; ``units`` from ``[simulation]``)."""

    preset: Literal["cellulose_rod", "dast_cube", "dast_family1", "dast_box"] | None = None
    shape: Literal["rod", "box"] | None = None
    delta: Real | None = None
    chi: Real | None = None
    chi_deg: Real | None = None
    inertia: Vector3 | None = None
    dipole: Vector3 | None = None
    dipole_debye: Annotated[float | tuple, PlainValidator(_number_or_vector)] | None = None
    a_nm: Length | None = None
    b_nm: Length | None = None
    c_nm: Length | None = None
    length_nm: Length | None = None
    diameter_nm: Length | None = None
    aspect: Annotated[Real, between(*ASPECT)] | None = None
    density: Density | None = None
    name: Line | None = None

    @model_validator(mode="after")
    def _form(self):
        form = one_of(self, *BODY_FORMS)
        if form is None:
            raise SpecError("preset", "missing value: give preset, shape, delta (with chi) or inertia (with dipole)")
        if self.chi is not None and self.chi_deg is not None:
            raise SpecError("chi", "give chi (rad) or chi_deg, not both")
        kind = self.preset or self.shape or form
        allowed = _FORM_KEYS[kind] | {"name"}
        for k in type(self).__pydantic_fields__:
            if getattr(self, k) is not None and k not in allowed:
                raise SpecError(k, f"unknown key for a body given by {form} = {kind!r}" if form in ("preset", "shape")
                                else f"unknown key for a body given by {form}")
        return self

    @property
    def form(self) -> str:
        """Which way the table gives the body: the first of ``BODY_FORMS`` it sets ("preset",
        "shape", "delta" or "inertia")."""
        return next(k for k in BODY_FORMS if getattr(self, k) is not None)

    def _need(self, *keys: str):
        for k in keys:
            if getattr(self, k) is None:
                raise SpecError(k, "missing value")
        return [getattr(self, k) for k in keys]

    def _chi(self, default=None) -> float:
        if self.chi_deg is not None:
            return float(U.deg_to_rad(self.chi_deg))
        if self.chi is None and default is None:
            raise SpecError("chi", "missing value")
        return self.chi if self.chi is not None else default

    def build(self, units_hint: str | None) -> B.Body:
        """The body (``SpecError`` naming the key when it is not physical)."""
        try:
            return self._build(units_hint)
        except B.BodyError as e:                          # the constructor's argument, as this table's key
            key = _SHAPE_KEYS.get(e.key, e.key) if self.form == "shape" else e.key
            raise SpecError(key, e.reason) from None

    def _build(self, units_hint):
        form = self.form
        if form == "preset":
            name = self.preset
            if name == "cellulose_rod":
                return P.cellulose_rod(density=self.density)
            if name == "dast_cube":
                return P.dast_cube(self.a_nm if self.a_nm is not None else 100.0, density=self.density)
            if name == "dast_family1":
                return P.dast_family1(self.a_nm if self.a_nm is not None else 100.0,
                                      self.c_nm if self.c_nm is not None else 50.0, density=self.density)
            return P.dast_box(*self._need("a_nm", "b_nm", "c_nm"), density=self.density)
        if form == "shape":
            (density,) = self._need("density")
            name = self.name or self.shape
            if self.shape == "rod":
                (length,) = self._need("length_nm")
                if (self.diameter_nm is None) == (self.aspect is None):
                    raise SpecError("diameter_nm", "give diameter_nm or aspect (L/D), exactly one")
                diameter = self.diameter_nm * U.NM if self.diameter_nm is not None else length * U.NM / self.aspect
                (d,) = self._need("dipole_debye")
                if isinstance(d, tuple):
                    raise SpecError("dipole_debye", f"a rod's dipole is one number (D, at chi from the axis), got {brief(d)}")
                if not DIPOLE_DEBYE[0] <= d <= DIPOLE_DEBYE[1]:
                    raise SpecError("dipole_debye", f"must lie in [{DIPOLE_DEBYE[0]:g}, {DIPOLE_DEBYE[1]:g}] (D), "
                                                    f"got {shown(d, *DIPOLE_DEBYE)}")
                return B.rod(length * U.NM, diameter, density, d * U.DEBYE, self._chi(0.0), name=name)
            a, b, c = self._need("a_nm", "b_nm", "c_nm")
            (d,) = self._need("dipole_debye")
            if not isinstance(d, tuple):
                raise SpecError("dipole_debye", f"a box's dipole is [d1, d2, d3] (D, body frame), got {d:g}")
            size = max(abs(x) for x in d)
            if not DIPOLE_DEBYE[0] <= size <= DIPOLE_DEBYE[1]:
                raise SpecError("dipole_debye", f"the largest component must lie in [{DIPOLE_DEBYE[0]:g}, "
                                                f"{DIPOLE_DEBYE[1]:g}] D, got {shown(size, *DIPOLE_DEBYE)}")
            return B.box(a * U.NM, b * U.NM, c * U.NM, density, np.array(d) * U.DEBYE, name=name)
        if form == "delta":
            return B.symmetric_top(self.delta, self._chi(), name=self.name or "symmetric top")
        units = units_hint or "dimensionless"
        if units == "cgs":
            key = one_of(self, "dipole_debye", "dipole")
            if key is None:
                raise SpecError("dipole_debye", "missing value (statC cm as dipole, or Debye as dipole_debye)")
            d = getattr(self, key)
            if not isinstance(d, tuple):
                raise SpecError(key, f"must be a list of 3 numbers, got {d:g}")
            dipole = np.array(d) * (U.DEBYE if key == "dipole_debye" else 1.0)
        else:
            if self.dipole_debye is not None:
                raise SpecError("dipole_debye", "a dimensionless body's dipole is a direction: give dipole")
            dipole = np.array(self._need("dipole")[0])
        return B.custom(np.array(self.inertia), dipole, units=units, name=self.name or "custom body")


# --- [initial] -----------------------------------------------------------------------------
@request
class InitialTable:
    """``[initial]``: omega (body frame; rad/s or 1/tau0) and the orientation: euler_zxz (rad),
    euler_zxz_deg or quaternion (w, x, y, z); identity by default."""

    omega: Vector3
    euler_zxz: Vector3 | None = None
    euler_zxz_deg: Vector3 | None = None
    quaternion: Quaternion | None = None

    @model_validator(mode="after")
    def _orientation(self):
        one_of(self, "euler_zxz", "euler_zxz_deg", "quaternion")
        if self.quaternion is not None and not math.hypot(*self.quaternion) > 0.0:
            raise SpecError("quaternion", "must not be zero")
        return self

    @property
    def orientation_key(self) -> str:
        """The key the initial orientation was given by ("euler_zxz", "euler_zxz_deg" or
        "quaternion", the default)."""
        return one_of(self, "euler_zxz", "euler_zxz_deg", "quaternion") or "quaternion"

    def q0(self) -> np.ndarray:
        """The initial orientation, (w, x, y, z), unit norm."""
        if self.euler_zxz is not None:
            return R.quat_from_euler_zxz(np.array(self.euler_zxz))
        if self.euler_zxz_deg is not None:
            return R.quat_from_euler_zxz(U.deg_to_rad(np.array(self.euler_zxz_deg)))
        if self.quaternion is not None:
            return R.normalize(np.array(self.quaternion))
        return np.array([1.0, 0.0, 0.0, 0.0])


# --- [simulation] --------------------------------------------------------------------------
HORIZON_KEYS = ("t_end", "t_end_T", "t_end_Theta")


@request
class SimulationTable:
    """``[simulation]``: model(s), horizon (t_end in the body's time unit, or t_end_T /
    t_end_Theta in the paper's T or Theta), samples, units and the integrator settings."""

    samples: Samples
    model: ModelName | None = None
    models: Annotated[tuple, PlainValidator(_models)] | None = None
    t_end: Positive | None = None
    t_end_T: Positive | None = None
    t_end_Theta: Positive | None = None
    units: Literal["cgs", "dimensionless"] | None = None
    method: Method = "auto"
    rtol: Rtol = 1e-10
    atol: Atol = 1e-12
    step: Positive | None = None

    @model_validator(mode="after")
    def _choices(self):
        if one_of(self, "model", "models") is None:
            raise SpecError("model", f"missing value; valid: {', '.join(M.names())}")
        if one_of(self, *HORIZON_KEYS) is None:
            raise SpecError("t_end", "missing value (or give t_end_T / t_end_Theta)")
        return self

    @property
    def model_names(self) -> tuple[str, ...]:
        """The scene's models in order: ``models``, or the one ``model``."""
        return self.models if self.models is not None else (self.model,)

    @property
    def horizon_key(self) -> str:
        """The key the horizon was given by ("t_end", "t_end_T" or "t_end_Theta"), to name it in
        messages."""
        return one_of(self, *HORIZON_KEYS)


# --- [observe] -----------------------------------------------------------------------------
@request
class ObserveTable:
    """``[observe]``: how a detector watches the scene (``spinviz observe``, ``decide``, ``listen``)
    -- the horizon, the line of sight, and the receiver (``inputs.receiver.ReceiverSpec``'s keys,
    with its defaults); the same keys are the commands' options (``--distance-cm`` ...).  The
    resolutions are computed from the receiver, so the fixed thresholds power_factor,
    frequency_resolution and polarization_deg are refused with the reason."""

    t_end: Positive | None = None
    t_end_T: Positive | None = None
    t_end_Theta: Positive | None = None
    line_of_sight: Direction | None = None
    distance_cm: RX.Distance = RX.DEFAULT_DISTANCE_CM
    bandwidth_hz: RX.Bandwidth = RX.DEFAULT_BANDWIDTH_HZ
    integration_s: RX.Integration = RX.DEFAULT_INTEGRATION_S
    noise_temperature_k: RX.NoiseTemperature | None = None
    noise_density_w_per_hz: RX.NoiseDensity | None = None
    antenna_gain_dbi: RX.GainDbi | None = None
    antenna_area_cm2: RX.AreaCm2 | None = None
    power_factor: refused(RX.RESOLUTION_COMPUTED) = None
    frequency_resolution: refused(RX.RESOLUTION_COMPUTED) = None
    polarization_deg: refused(RX.RESOLUTION_COMPUTED) = None

    @model_validator(mode="after")
    def _check(self):
        one_of(self, *HORIZON_KEYS)
        self.receiver()                                      # one of each noise and antenna key
        return self

    @property
    def horizon_key(self) -> str | None:
        """The key the detector's horizon was given by, or None (the scene's horizon)."""
        return one_of(self, *HORIZON_KEYS)

    def receiver(self) -> RX.ReceiverSpec:
        """The table's receiver (its detector keys, defaults where absent)."""
        return RX.ReceiverSpec(**{k: getattr(self, k) for k in RX.DETECTOR_KEYS})


# --- the file ------------------------------------------------------------------------------
@request
class SceneFile:
    """The top level of a scene file: its tables and free text."""

    body: Table
    initial: Table
    simulation: Table
    title: Annotated[str, PlainValidator(_title)] | None = None
    description: Text | None = None
    render: Table | None = None
    observe: Table | None = None
    environment: Table | None = None
