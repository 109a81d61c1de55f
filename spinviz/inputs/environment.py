"""The trap around the crystal: ``EnvironmentSpec``, a scene's ``[environment]`` table, the
``environment=`` argument of ``spinviz.simulate`` and the environment options of ``observe``
and ``decide`` -- one schema, one set of reasons.

Keys (all optional; absent, the crystal is alone in a perfect vacuum and every result is what
it is without the table):

* ``pressure_mbar``: the residual gas's pressure (0: no gas);
* ``gas``: its species (``physics.gas.GASES``: H2, He, Ne, N2, O2, Ar, CO2, Xe), default N2;
* ``gas_temperature_k``: its temperature, default 300 K;
* ``accommodation``: the share of molecules re-emitted diffusely (the rest bounce
  specularly), default 1;
* ``body_temperature_k``: the crystal's surface temperature, which sets the re-emitted
  molecules' speeds; default the gas's;
* ``field_v_per_m``: a static electric field, world frame (X, Y, Z), V/m; default none;
* ``seed``: the seed of the collisions' random streams (a run is reproduced by it).

What joins the table to the body (a surface, CGS units, free-molecular flow) is checked by
``check_body``, which the run's request (``inputs.simulation``) calls.
"""

from __future__ import annotations

import math
from typing import Annotated

import numpy as np
from pydantic import PlainValidator

from .. import units as U
from ..errors import SpecError, brief
from ..physics import gas as G
from .base import Int, Real, between, check_vector, registered, request, wrong_type

PRESSURE_MBAR = (0.0, 1e3, "mbar: 0 is the perfect vacuum, 1000 an atmosphere")
TEMPERATURE_K = (0.1, 1e4, "K")
FIELD_V_PER_M = 1e10            # V/m: beyond the fields any surface holds (field evaporation at ~1e10 V/m)
KNUDSEN_MIN = 10.0              # the gas's mean free path over the body's size: free-molecular flow above
MAX_SEED = 2**63 - 1
GasName = registered(lambda: tuple(G.GASES))


def _field(v):
    """A world-frame field X, Y, Z (V/m): three finite numbers, each at most ``FIELD_V_PER_M``."""
    v = check_vector(v, 3, "numbers (V/m, world frame)")
    big = max(abs(x) for x in v)
    if big > FIELD_V_PER_M:
        raise ValueError(f"must be at most {FIELD_V_PER_M:g} V/m a component (a surface field-evaporates beyond), "
                         f"got {brief(v)}")
    return v


Field = Annotated[tuple[float, ...], PlainValidator(_field)]


@request
class EnvironmentSpec:
    """The crystal's surroundings (module docstring): the residual gas, a static field, the
    seed of the collisions."""

    pressure_mbar: Annotated[Real, between(*PRESSURE_MBAR)] = 0.0
    gas: GasName = "N2"
    gas_temperature_k: Annotated[Real, between(*TEMPERATURE_K)] = 300.0
    accommodation: Annotated[Real, between(0.0, 1.0, "the share of molecules re-emitted diffusely")] = 1.0
    body_temperature_k: Annotated[Real, between(*TEMPERATURE_K)] | None = None
    field_v_per_m: Field = (0.0, 0.0, 0.0)
    seed: Annotated[Int, between(0, MAX_SEED, "NumPy's generator")] = 1

    # -- what it holds ---------------------------------------------------------------------
    @property
    def has_gas(self) -> bool:
        """A residual gas (pressure above 0)."""
        return self.pressure_mbar > 0.0

    @property
    def has_field(self) -> bool:
        """A static field (a non-zero component)."""
        return any(x != 0.0 for x in self.field_v_per_m)

    @property
    def active(self) -> bool:
        """Anything beyond the perfect vacuum: then the run carries it; otherwise every result
        is the vacuum's, bit for bit."""
        return self.has_gas or self.has_field

    def gas_model(self) -> G.Gas | None:
        """The gas (``physics.gas.Gas``, CGS), or None at pressure 0."""
        if not self.has_gas:
            return None
        return G.Gas(self.gas, float(U.pressure_from_mbar(self.pressure_mbar)), self.gas_temperature_k,
                     self.accommodation, self.body_temperature_k)

    def field_cgs(self) -> np.ndarray:
        """The static field in the world frame, statV/cm, shape (3,)."""
        return np.asarray(U.field_from_v_per_m(self.field_v_per_m), dtype=float)

    @property
    def field_magnitude_v_per_m(self) -> float:
        """|E|, V/m."""
        return float(math.hypot(*self.field_v_per_m))

    def record(self) -> dict:
        """The table as plain numbers (JSON), defaults filled in."""
        return {"pressure_mbar": self.pressure_mbar, "gas": self.gas, "gas_temperature_k": self.gas_temperature_k,
                "accommodation": self.accommodation,
                "body_temperature_k": (self.gas_temperature_k if self.body_temperature_k is None
                                       else self.body_temperature_k),
                "field_v_per_m": list(self.field_v_per_m), "seed": self.seed}

    def describe(self) -> str:
        """One line for reports."""
        parts = []
        if self.has_gas:
            tb = "" if self.body_temperature_k is None else f", surface at {self.body_temperature_k:g} K"
            parts.append(f"{self.gas} at {self.pressure_mbar:.3g} mbar, {self.gas_temperature_k:g} K{tb}, "
                         f"accommodation {self.accommodation:g}")
        if self.has_field:
            parts.append(f"static field {self.field_magnitude_v_per_m:.3g} V/m along "
                         f"({', '.join(f'{x:.3g}' for x in self.field_v_per_m)})")
        return "; ".join(parts) if parts else "perfect vacuum, no field"

    def with_options(self, **given) -> EnvironmentSpec:
        """This environment with the values given (None: not given) in place of its own, checked
        by this schema (``SpecError`` naming the key)."""
        names = type(self).__pydantic_fields__
        unknown = sorted(set(given) - set(names))
        if unknown:
            raise SpecError(unknown[0], f"not an environment key; valid: {', '.join(names)}")
        given = {k: v for k, v in given.items() if v is not None}
        if not given:
            return self
        return EnvironmentSpec(**{**{k: getattr(self, k) for k in names}, **given})


def environment(value) -> EnvironmentSpec | None:
    """``environment=`` of the Python API: an ``EnvironmentSpec``, a dict of its keys (checked by
    this schema) or None."""
    if value is None or isinstance(value, EnvironmentSpec):
        return value
    if isinstance(value, dict):
        if not all(isinstance(k, str) for k in value):
            raise SpecError("environment", f"keys must be names, got {brief(value)}")
        return EnvironmentSpec(**value)
    raise wrong_type(f"must be a spinviz.Environment, a dict of its keys or None, got {type(value).__name__} "
                     f"{brief(value)}")


def check_body(env: EnvironmentSpec, body) -> None:
    """What joins the environment to the body: physical units, a surface for a gas, and
    free-molecular flow (the mean free path at least ``KNUDSEN_MIN`` times the body's size).
    ``SpecError`` naming the environment's key."""
    if not env.active:
        return
    key = "pressure_mbar" if env.has_gas else "field_v_per_m"
    if body.units != "cgs":
        raise SpecError(key, "an environment needs a body in physical units (CGS): pressures and fields have sizes")
    if not env.has_gas:
        return
    from ..physics.surface import surface_of

    try:
        surface = surface_of(body)
    except SpecError as e:
        raise SpecError(key, e.reason) from None
    gas = env.gas_model()
    kn = gas.mean_free_path / surface.size
    if not kn >= KNUDSEN_MIN:
        raise SpecError(key, f"the gas's mean free path ({gas.mean_free_path:.3g} cm) is {kn:.3g} times the body's size "
                             f"({surface.size:.3g} cm): the model is free-molecular flow, which needs at least "
                             f"{KNUDSEN_MIN:g}")
