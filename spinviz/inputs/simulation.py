"""One run, asked for: ``SimulationRequest`` -- the arguments of ``spinviz.simulate``, and what
a scene's ``[body]``, ``[initial]`` and ``[simulation]`` tables become for each model.

Every value is checked here once, in the units of the body (CGS: s and rad/s;
dimensionless: tau0 and 1/tau0), together with what the machine and float64 can hold: the
spin scale tau0 |Omega0| (``integrators.scaling.check_scale``), the number of output
instants (memory), and a horizon that can finish (``integrators.auto.check_cost``).  Errors
name the argument (``SpecError("rtol", ...)``); a scene renames them to its keys.
"""

from __future__ import annotations

import math
from typing import Annotated, Any, Literal

import numpy as np
from pydantic import Field, PlainValidator, model_validator

from ..errors import SpecError, brief
from ..physics import models as M
from ..physics.bodies import Body
from .base import Int, Positive, Real, at_most, between, registered, request, vector, wrong_type

KINEMATICS = ("quaternion", "euler_zxz", "none")
MAX_SAMPLES = 1_000_000         # 11 numbers an instant per model, ~90 MB at the limit
RTOL_RANGE = (1e-19, 1e-1, "the long double's precision at the tightest")
ATOL_RANGE = (1e-300, 1.0, "units where |omega(0)| = 1")
MIN_SPIN_RAD = 1e-12            # the shortest horizon, in radians turned: below it the spin-unit times are noise


def _body(v):
    if isinstance(v, Body):
        return v
    hint = " (a scene's body is spinviz.load_scene(path).body)" if isinstance(v, str) or hasattr(v, "__fspath__") else ""
    raise wrong_type(f"must be a Body (spinviz.symmetric_top(...), spinviz.PRESETS[name]() or spinviz.Body(...)), "
                     f"got {type(v).__name__} {brief(v)}{hint}")


def _method(v):
    if not isinstance(v, str):
        raise wrong_type(f"must be a method name, got {brief(v)}")
    name = v.lower()
    if name != "auto":
        from ..integrators import get  # the registry only: no kernel is compiled

        get(name)                             # ValueError: unknown method ..., valid: ...
    return name


def _times(v):
    """Output instants: a 1-D list or array of finite numbers from 0, increasing, 2..MAX_SAMPLES."""
    if isinstance(v, (str, bytes, bool)) or not hasattr(v, "__len__"):
        raise wrong_type(f"must be a list of output times, got {brief(v)}")
    if len(v) > MAX_SAMPLES:
        raise ValueError(f"must hold at most {MAX_SAMPLES} instants (memory), got {len(v)}")
    try:
        a = np.array(v, dtype=float)
    except (TypeError, ValueError):
        raise wrong_type(f"must be a list of numbers, got {brief(v)}") from None
    if a.ndim != 1 or a.size < 2:
        raise ValueError(f"must be a 1-D list of at least two instants, got shape {a.shape}")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"must be finite, got {brief(v)}")
    if a[0] != 0.0 or not np.all(np.diff(a) > 0.0):
        raise ValueError("must start at 0 and increase")
    a.flags.writeable = False
    return a


ModelName = registered(M.names)
Kinematics = Literal["quaternion", "euler_zxz", "none"]
Method = Annotated[str, PlainValidator(_method)]
Vector3 = vector(3)
Quaternion = vector(4, "numbers (w, x, y, z)")
Samples = Annotated[Int, Field(ge=2), at_most(MAX_SAMPLES, "memory: 11 numbers an instant per model")]
Rtol = Annotated[Real, between(*RTOL_RANGE)]
Atol = Annotated[Real, between(*ATOL_RANGE)]
Times = Annotated[np.ndarray, PlainValidator(_times)]


def _environment(v):
    from .environment import environment

    return environment(v)


@request(eq=False)
class SimulationRequest:
    """Everything one run needs, validated (the arguments of ``spinviz.simulate``).

    body : Body -- its ``units`` are the units of everything below (``time_unit``, ``omega_unit``).
    model : a registered model ("reduced" (2.2)+(2.3), "truncated" (2.5), "free"; ``physics.models``).
    omega0 : (3,) body-frame angular velocity at t = 0 (rad/s or 1/tau0).
    t_end, samples : ``samples`` instants evenly spaced over [0, t_end]; or
    t_eval : (N,) increasing output times from 0.
    q0 : (w, x, y, z) initial orientation (normalized here); or euler_zxz0 : (phi, theta, psi) rad.
    method : a registered integrator name or "auto" (case-insensitive).
    rtol, atol : tolerances in spin units (|omega(0)| = 1); atol defaults to rtol / 100.
    step : fixed-step methods' step, in the time unit.
    kinematics : "quaternion", "euler_zxz" (6.4) or "none".
    environment : the trap (``inputs.environment.EnvironmentSpec``, or a dict of its keys): a
    residual gas, a static field; None or inactive, the perfect vacuum.
    """

    body: Annotated[Body, PlainValidator(_body)]
    model: ModelName
    omega0: Vector3
    t_end: Positive | None = None
    samples: Samples | None = None
    t_eval: Times | None = None
    q0: Quaternion | None = None
    euler_zxz0: Vector3 | None = None
    method: Method = "auto"
    rtol: Rtol = 1e-10
    atol: Atol | None = None
    step: Positive | None = None
    kinematics: Kinematics = "quaternion"
    environment: Annotated[Any, PlainValidator(_environment)] = None

    @model_validator(mode="after")
    def _together(self):
        if self.t_eval is not None:
            for k in ("t_end", "samples"):
                if getattr(self, k) is not None:
                    raise SpecError(k, "give t_end and samples, or t_eval, not both")
        elif self.t_end is None or self.samples is None:
            raise SpecError("t_end" if self.t_end is None else "samples", "missing value (give t_end and samples, or t_eval)")
        elif not np.all(np.diff(np.linspace(0.0, self.t_end, self.samples)) > 0.0):
            raise SpecError("t_end", f"{self.t_end:g} is too short to hold {self.samples} distinct instants")
        if self.q0 is not None and self.euler_zxz0 is not None:
            raise SpecError("euler_zxz0", "give q0 or euler_zxz0, not both")
        if self.q0 is not None and not math.hypot(*self.q0) > 0.0:
            raise SpecError("q0", "must not be zero (a rotation is a unit quaternion; it is normalized here)")
        from ..integrators import get
        from ..integrators.auto import check_cost
        from ..integrators.scaling import check_scale

        try:
            check_scale(self.body, self.omega0)
        except SpecError as e:
            raise SpecError("omega0" if e.key == "omega" else e.key, e.reason) from None
        turned = self.horizon * math.hypot(*self.omega0)           # rad of spin without braking
        if not turned >= MIN_SPIN_RAD:
            raise SpecError(self.time_key, f"{self.horizon:g} {self.time_unit} is {turned:.3g} rad of spin at |omega0|: too "
                                           f"short to integrate (at least {MIN_SPIN_RAD:g} rad)")
        if self.method != "auto":
            m = get(self.method)
            if self.kinematics not in m.kinematics:
                raise SpecError("method", f"{m.name!r} does not support kinematics {self.kinematics!r} "
                                          f"(it supports {', '.join(m.kinematics)})")
            if m.symmetric_only and not self.body.is_symmetric:
                raise SpecError("method", f"{m.name!r} needs a symmetric top (I1 = I2)")
            if m.compiled and M.get(self.model).kernel_id is None:
                raise SpecError("method", f"{m.name!r} runs on compiled kernels, which do not know the model "
                                          f"{self.model!r}; Taylor's method and SciPy's integrate it")
            if m.fixed_step and self.step is None:
                raise SpecError("step", f"method {m.name} is fixed-step: give step > 0")
        trap = self.environment is not None and self.environment.active
        gas = self._trap_gas() if trap else None
        try:
            check_cost(self.body, self.model, np.asarray(self.omega0), self.horizon, self.method, self.step,
                       kinematics=self.kinematics, braking_rate=0.0 if gas is None else self._gas_braking(gas))
        except SpecError as e:
            raise SpecError(self.time_key if e.key == "t_end" else e.key, e.reason) from None
        if trap:
            self._check_environment(gas)
        return self

    def _trap_gas(self):
        """The trap's gas acting on this body (``physics.gas.GasModel``; None without a gas),
        once the body is one it can act on (CGS, a surface, free-molecular flow)."""
        from .environment import check_body

        try:
            check_body(self.environment, self.body)
        except SpecError as e:
            raise SpecError(f"environment.{e.key}", e.reason) from None
        gas = self.environment.gas_model()
        if gas is None:
            return None
        from ..physics.gas import GasModel
        from ..physics.surface import surface_of

        return GasModel(gas, surface_of(self.body), tuple(self.body.inertia))

    def _gas_braking(self, model) -> float:
        """The least rate at which the gas ``model`` brakes |Omega| (1/s): its linear drag, at a
        spin far below the gas's speeds (a faster body rams the gas and brakes faster)."""
        w = np.asarray(self.omega0, dtype=float)
        slow = w / float(np.linalg.norm(w)) * 1e-6 * model.gas.mean_speed / model.surface.size
        return max(model.damping_rate(slow), 0.0)

    def _check_environment(self, model):
        """A run in a trap (its body checked by ``_trap_gas``, whose gas is ``model``, or None): a
        method that carries it (``integrators.environment``) and a cost that can finish."""
        from ..integrators import environment as IE
        from ..integrators.auto import choose_method

        env = self.environment
        key = "environment.pressure_mbar" if env.has_gas else "environment.field_v_per_m"
        if self.kinematics != "quaternion":
            raise SpecError("kinematics", "a run in a trap needs the orientation (kinematics \"quaternion\"): the field "
                                          "acts in the world frame, and the collisions turn L in it")
        method = self.method
        if method == "auto":
            method = choose_method(self.body, self.model, np.asarray(self.omega0), self.horizon, self.kinematics,
                                   rtol=self.rtol)[0]
        why = IE.refusal(method)
        if why is not None:
            raise SpecError("method" if self.method != "auto" else key,
                            why if self.method != "auto" else f"auto picks {method!r} for this run, and {why}")
        if model is None:
            return
        if method in ("taylor", "taylor-long"):
            n = IE.estimated_collisions(model, self.omega0, self.horizon)
            if n > IE.MAX_COLLISIONS:
                raise SpecError(self.time_key, f"the gas hits the body ~{n:.3g} times over the run, and {method} applies "
                                               f"each collision (at most {IE.MAX_COLLISIONS:g} can finish): shorten it, "
                                               f"lower [environment].pressure_mbar, or let secular carry it")
        elif method == "secular":
            from ..integrators.secular_env import MAX_CHUNKS

            n = IE.estimated_chunks(model, self.body, self.model, self.omega0, self.horizon, len(self.times()))
            if n > MAX_CHUNKS:
                raise SpecError(self.time_key, f"the gas brakes the body so fast against the run's length that secular "
                                               f"would take ~{n:.3g} chunks (at most {MAX_CHUNKS:g} can finish): "
                                               f"shorten it or lower [environment].pressure_mbar")

    # -- derived ------------------------------------------------------------------------------
    @property
    def units(self) -> str:
        """"cgs" or "dimensionless": the body's, and so the request's."""
        return self.body.units

    @property
    def time_unit(self) -> str:
        """Unit of every time of the request: "s" (CGS body) or "tau0" (dimensionless)."""
        return "s" if self.units == "cgs" else "tau0"

    @property
    def omega_unit(self) -> str:
        """Unit of ``omega0`` and of the run's Omega: "rad/s" (CGS body) or "1/tau0"."""
        return "rad/s" if self.units == "cgs" else "1/tau0"

    @property
    def time_key(self) -> str:
        """The argument that set the horizon: "t_eval" or "t_end"."""
        return "t_eval" if self.t_eval is not None else "t_end"

    @property
    def horizon(self) -> float:
        """The end of the run, in ``time_unit``: the last of ``t_eval``, or ``t_end``."""
        return float(self.t_eval[-1]) if self.t_eval is not None else float(self.t_end)

    def times(self) -> np.ndarray:
        """The output instants, shape (N,), in ``time_unit``."""
        return np.array(self.t_eval) if self.t_eval is not None else np.linspace(0.0, self.t_end, self.samples)

    @property
    def atol_or_default(self) -> float:
        """atol, or rtol / 100 when not given (in spin units the state is O(1): atol >= rtol would rule)."""
        return self.rtol * 1e-2 if self.atol is None else self.atol

