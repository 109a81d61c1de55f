"""A scene: its file read through the schema into a ``Scene``, every rule joining its tables checked
here, once (units, the spin scale, the horizon, ``[render]``, ``[observe]``).

A scene file describes one run (or two models side by side).  The smallest scene is
dimensionless::

    [body]
    delta = 0.3          # 1 - I3/I1 of a symmetric top; or inertia = [I1, I2, I3] (relative)
    chi = 0.7            # dipole angle from e3 in the e1-e3 plane, rad; or dipole = [d1, d2, d3]
    [initial]
    omega = [0.0, 0.05, 0.3]                      # body frame, 1/tau0
    euler_zxz = [0.0, 1.5707963267948966, 0.0]    # phi, theta, psi in rad
    [simulation]
    model = "reduced"    # or "truncated", "free"; or models = ["reduced", "truncated"]
    t_end = 1200.0       # in tau0
    samples = 400

Physical bodies are given in CGS with named units (``preset = "dast_cube"``,
``shape = "rod"`` with ``length_nm`` ...), and then omega is in rad/s and t_end in s; see
docs/scenes.md for every key.  Angles are radians unless the key ends in ``_deg``.

Every table is declared once (``inputs.scene``, ``[render]`` in ``inputs.render``) and the
simulation settings are checked by the same ``SimulationRequest`` that checks
``spinviz.simulate``'s arguments, so a file, the command line and Python can never
disagree.  Every problem is reported as ``SceneError(path, key, reason)``: one line naming
the file, the key and the reason.

``Scene.request(model)`` is the typed, frozen request for one model's run
(``driver.simulate_request``); no keyword dictionary travels from a scene to the driver.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field, replace

import numpy as np

from ..errors import SceneError, SpecError, SpecTypeError, brief, printable
from ..physics import bodies as B
from . import scene as IS
from .environment import EnvironmentSpec
from .receiver import ReceiverSpec
from .render import MAX_TITLE, RenderSpec
from .simulation import SimulationRequest
from .toml import document, read_document, read_toml

__all__ = ["Scene", "ObserveSpec", "SceneError", "load_scene", "parse_scene", "read_toml"]


@dataclass(frozen=True)
class ObserveSpec:
    """[observe]: how a detector watches the scene (``spinviz observe``, ``spinviz listen``).

    t_end : how long it watches, in the scene's time unit (None: the scene's horizon);
    line_of_sight : world-frame direction to the detector (None: across L(0));
    receiver : the detector's distance, band, integration, noise and antenna
    (``inputs.receiver.ReceiverSpec``), from which the resolutions are computed.
    """

    t_end: float | None = None
    line_of_sight: tuple[float, float, float] | None = None
    receiver: ReceiverSpec = field(default_factory=ReceiverSpec)


def _readonly(a) -> np.ndarray:
    a = np.array(a, dtype=float)
    a.flags.writeable = False
    return a


@dataclass(frozen=True)
class Needs:
    """What a command asks of a scene beyond its own validity (``Scene.require``).

    models : how many models it compares (None: any); line_law : every model with a closed-form
    line and a body that radiates one line (d along the symmetry axis, or a sphere: (5.2),
    (5.4)); symmetric : a symmetric top (I1 = I2: the detector's lines are those of the free
    precession); cgs : a body in physical units (a receiver has distances, powers and noise).
    """

    models: int | None = None
    line_law: bool = False
    symmetric: bool = False
    cgs: bool = False


_COUNT = {1: "one", 2: "two", 3: "three"}

# what each library function that takes a scene needs of it, checked once when it starts
NEEDS = {
    "compare": Needs(models=2),
    "observe": Needs(models=2, symmetric=True),
    "listen": Needs(models=2, symmetric=True),
    "decide": Needs(models=2, line_law=True, cgs=True),
}


@dataclass(frozen=True)
class Scene:
    """A validated scene, in the body's units (CGS: s, rad/s; dimensionless: tau0, 1/tau0).

    omega0 : (3,) body frame; q0 : (w, x, y, z); t_end : horizon; samples : output instants;
    method, rtol, atol, step : the integrator settings (``SimulationRequest``'s);
    render : ``RenderSpec``; observe : ``ObserveSpec``; environment : ``EnvironmentSpec``
    (``[environment]``: the trap's gas and field; the perfect vacuum when absent).
    """

    path: str
    title: str
    body: B.Body
    models: tuple[str, ...]
    omega0: np.ndarray
    q0: np.ndarray
    t_end: float
    samples: int
    method: str = "auto"
    rtol: float = 1e-10
    atol: float = 1e-12
    step: float | None = None
    render: RenderSpec = field(default_factory=RenderSpec)
    observe: ObserveSpec = field(default_factory=ObserveSpec)
    environment: EnvironmentSpec = field(default_factory=EnvironmentSpec)

    def __post_init__(self):
        object.__setattr__(self, "omega0", _readonly(self.omega0))
        object.__setattr__(self, "q0", _readonly(self.q0))

    @property
    def units(self) -> str:
        """The unit system of the scene's body: "cgs" (t in s, Omega in rad/s) or "dimensionless"
        (tau, omega of (4.1))."""
        return self.body.units

    @property
    def model(self) -> str:
        """The first of the scene's models (the one ``spinviz simulate`` runs by default)."""
        return self.models[0]

    def require(self, command: str) -> Scene:
        """This scene, if it has what ``command`` (a key of ``NEEDS``) needs; ``SceneError``
        naming the file, the key and what is missing otherwise."""
        from ..physics import longitudinal as LG
        from ..physics import models as M

        if not isinstance(command, str) or command not in NEEDS:
            raise SpecError("command", f"unknown command {brief(command)}; valid: {', '.join(NEEDS)}")
        needs = NEEDS[command]
        if needs.models is not None and len(self.models) != needs.models:
            example = ", ".join(f'"{m}"' for m in M.with_line_law())
            raise SceneError(self.path, "[simulation].models",
                             f"{command} needs {_COUNT.get(needs.models, needs.models)} models, e.g. models = [{example}]")
        body = self.body
        if needs.cgs and body.units != "cgs":
            raise SceneError(self.path, "[body]", f"{command} needs a body in physical units (CGS): the receiver has "
                                                  f"distances, powers and noise")
        if needs.symmetric and not body.is_symmetric:
            raise SceneError(self.path, "[body]", f"{command} needs a symmetric top (I1 = I2): the detector's lines "
                                                  f"are those of the free precession; this body is asymmetric")
        if needs.line_law:
            if not LG.has_line_law(body.delta, body.chi, body.is_symmetric):
                shape = (f"delta = {body.delta:.3g}, chi = {math.degrees(body.chi):.3g} deg" if body.is_symmetric
                         else "an asymmetric top")
                raise SceneError(self.path, "[body]", f"{command} needs a dipole along the symmetry axis (chi = 0) or "
                                                      f"a spherical top (delta = 0), whose line is a closed form of "
                                                      f"the start ((5.2), (5.4)); this body has {shape}")
            without = [m for m in self.models if M.get(m).line is None]
            if without:
                raise SceneError(self.path, "[simulation].models",
                                 f"{command} compares models with a closed-form line "
                                 f"({', '.join(M.with_line_law())}); {without[0]!r} has none")
        return self

    def request(self, model: str | None = None, *, kinematics: str = "quaternion", t_eval=None) -> SimulationRequest:
        """The typed request for one run of ``model`` (default the first): the scene's
        ``samples`` instants over [0, t_end], or the given ``t_eval``; ``SpecError`` naming the
        argument if ``model``, ``kinematics`` or ``t_eval`` is not acceptable."""
        model = self.model if model is None else model
        if model not in self.models:
            raise SpecError("model", f"{brief(model)} is not one of the scene's models ({', '.join(self.models)})")
        times = {"t_end": self.t_end, "samples": self.samples} if t_eval is None else {"t_eval": t_eval}
        env = self.environment if self.environment.active else None
        if env is not None and kinematics == "none":
            kinematics = "quaternion"            # a trap's run carries the orientation whatever is drawn of it
        return SimulationRequest(body=self.body, model=model, omega0=self.omega0, q0=self.q0, method=self.method,
                                 rtol=self.rtol, atol=self.atol, step=self.step, kinematics=kinematics,
                                 environment=env, **times)

    def with_environment(self, **given) -> Scene:
        """This scene with the environment keys given (None: the scene's) in place of its
        ``[environment]``'s, checked by the schema and against the body (``SpecError`` naming
        the key: the option's or the argument's, as the receiver's options are)."""
        from .environment import check_body

        env = self.environment.with_options(**given)
        if env == self.environment:
            return self
        check_body(env, self.body)
        return replace(self, environment=env)


# --- the whole file -----------------------------------------------------------------------
def parse_scene(data: dict, path: str = "<scene>") -> Scene:
    """Validate a parsed TOML document; raise SceneError (file, key, reason) on the first problem."""
    path = os.fspath(path)
    return _scene(*document(IS.SceneFile, data, path, _TABLES, ("render", "environment")), path)


# every table of a scene, validated in one place (inputs.toml.document) before anything is computed
_TABLES = {"body": IS.BodyTable, "initial": IS.InitialTable, "simulation": IS.SimulationTable, "render": RenderSpec,
           "observe": IS.ObserveTable, "environment": EnvironmentSpec}


def _scene(top, tables: dict, path: str) -> Scene:
    """The scene of a validated document."""
    bt, it, st = tables["body"], tables["initial"], tables["simulation"]
    try:
        body = bt.build(st.units)
    except SpecError as e:
        raise SceneError(path, f"[body].{e.key}", e.reason) from None
    if bt.name is not None and bt.name != body.name:
        body = replace(body, name=bt.name)
    if st.units is not None and st.units != body.units:
        raise SceneError(path, "[simulation].units",
                         f"{st.units!r} does not match the body, which is given in {body.units!r} units")
    omega0, q0 = np.array(it.omega), it.q0()
    keys = _scene_keys(st, it)
    t_end = _horizon(path, "simulation", st, st.horizon_key, body, omega0, keys)
    env = _environment(tables["environment"], body, path)
    requests = [_checked(path, keys, body=body, model=m, omega0=omega0, q0=q0, t_end=t_end, samples=st.samples,
                         method=st.method, rtol=st.rtol, atol=st.atol, step=st.step,
                         environment=env if env.active else None) for m in st.model_names]
    title = top.title
    if title is None:   # from the file name, escaped and cut: a name may hold anything a file system allows
        title = printable(os.path.splitext(os.path.basename(path))[0], MAX_TITLE)
    render = _render(tables["render"], "title" in (top.render or {}), title, path, t_end)
    observe = _observe(tables["observe"], path, body, omega0, requests)
    return Scene(path=path, title=title, body=body, models=st.model_names, omega0=omega0, q0=q0, t_end=t_end,
                 samples=st.samples, method=requests[0].method, rtol=st.rtol, atol=st.atol, step=st.step, render=render,
                 observe=observe, environment=env)


def _environment(env: EnvironmentSpec, body: B.Body, path: str) -> EnvironmentSpec:
    """[environment] (validated; its defaults when absent), checked against the body."""
    from .environment import check_body

    try:
        check_body(env, body)
    except SpecError as e:
        raise SceneError(path, f"[environment].{e.key}", e.reason) from None
    return env


def _scene_keys(st, it) -> dict:
    """``SimulationRequest``'s argument names -> the scene's keys."""
    return {"omega0": "[initial].omega", "body": "[body]", "q0": f"[initial].{it.orientation_key}",
            "t_end": f"[simulation].{st.horizon_key}", "samples": "[simulation].samples",
            "method": "[simulation].method", "rtol": "[simulation].rtol", "atol": "[simulation].atol",
            "step": "[simulation].step", "model": "[simulation].model" if st.model else "[simulation].models"}


def _checked(path, keys: dict, **kw) -> SimulationRequest:
    """The run of one model checked by the request ``simulate`` checks its arguments with;
    its errors renamed to the scene's keys."""
    try:
        return SimulationRequest(**kw)
    except SpecError as e:
        key = keys.get(e.key, e.key)
        if e.key.startswith("environment."):
            key = f"[environment].{e.key.split('.', 1)[1]}"
        raise SceneError(path, key, e.reason) from None


def _horizon(path, name: str, t, key: str, body: B.Body, omega0, keys: dict) -> float:
    """The horizon of table ``t`` (``[simulation]`` or ``[observe]``) in the scene's time unit:
    t_end as given, or t_end_T / t_end_Theta times T = 1/(tau0 Omega20^2) or Theta = 1/(tau0
    Omega3^2 eps^2) of the initial state.

    T is the paper's (after (3.9) and in (6.1)): Omega20 is the spin across the symmetry
    axis, here |Omega_perp(0)| = hypot(Omega1, Omega2), so the check scenes run the horizons
    `spinviz check` uses."""
    value = getattr(t, key)
    if key == "t_end":
        return value
    try:
        from ..integrators.scaling import check_scale  # the integrators' package: loaded only for T and Theta

        check_scale(body, omega0)                   # T and Theta need a usable tau0 and spin
    except SpecError as e:
        raise SceneError(path, keys.get("omega0" if e.key == "omega" else e.key, e.key), e.reason) from None
    if key == "t_end_T":
        w_perp = math.hypot(float(omega0[0]), float(omega0[1]))
        if w_perp == 0.0:
            raise SceneError(path, f"[{name}].{key}", "T = 1/(tau0 Omega_perp^2) is infinite for Omega_perp = 0")
        scale = body.braking_time_T(w_perp)
    else:
        w3 = abs(float(omega0[2]))
        if w3 == 0.0:
            raise SceneError(path, f"[{name}].{key}", "Theta = 1/(tau0 Omega3^2 (I3/I1)^2) is infinite for Omega3 = 0")
        scale = body.residual_time_Theta(w3)
    horizon = value * scale
    if not math.isfinite(horizon):
        raise SceneError(path, f"[{name}].{key}", "the horizon in the scene's time unit is beyond float64")
    return horizon


def _render(spec: RenderSpec, own_title: bool, title: str, path: str, t_end: float) -> RenderSpec:
    """[render] (validated by ``RenderSpec``, the one place render inputs are checked) with the
    scene's title unless it has its own, checked against the scene's horizon."""
    if not own_title:
        try:
            spec = replace(spec, title=title)
        except SpecError as e:
            raise SceneError(path, "title", e.reason) from None
    try:
        spec.check_horizon(t_end)
    except SpecError as e:
        raise SceneError(path, f"[render].{e.key}", e.reason) from None
    return spec


def _observe(ot, path: str, body: B.Body, omega0, requests: list) -> ObserveSpec:
    """[observe] (``ot``, validated; None when absent): the detector's horizon (checked like
    the scene's: it is simulated), line of sight and receiver."""
    if ot is None:
        return ObserveSpec()
    t_end = None
    key = ot.horizon_key
    if key is not None:
        keys = {"omega0": "[initial].omega", "body": "[body]", "t_end": f"[observe].{key}"}
        t_end = _horizon(path, "observe", ot, key, body, omega0, keys)
        for r in requests:
            _checked(path, {**keys, "step": "[simulation].step", "method": "[simulation].method"},
                     **{f: getattr(r, f) for f in ("body", "model", "omega0", "q0", "method", "rtol", "atol", "step",
                                                   "environment")},
                     t_end=t_end, samples=2)
    return ObserveSpec(t_end=t_end, line_of_sight=ot.line_of_sight, receiver=ot.receiver())


def load_scene(path) -> Scene:
    """Read and validate a scene file; SceneError (one line: file, key, reason) on any problem."""
    if not isinstance(path, (str, bytes, os.PathLike)):
        raise SpecTypeError("path", f"must be the path of a scene file (str or os.PathLike), got {type(path).__name__}")
    path = os.fsdecode(path)
    return _scene(*read_document(path, IS.SceneFile, _TABLES, ("render", "environment")), path)
