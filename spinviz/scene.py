"""Scenes: the TOML schema, its validation, and units at the boundary.

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
the README for every key.  Angles are radians unless the key ends in ``_deg``.

Every problem is reported as ``SceneError(path, key, reason)``: one line naming the file,
the key and the reason.
"""

from __future__ import annotations

import math
import os
import stat
import tomllib
from dataclasses import dataclass, field, replace

import numpy as np

from . import rotations as R
from . import units as U
from .errors import SceneError, SpecError, brief
from .integrators.auto import check_cost
from .integrators.scaling import check_scale
from .physics import bodies as B
from .physics import presets as P
from .physics.equations import MODELS
from .rendering.spec import RenderSpec

__all__ = ["Scene", "SceneError", "load_scene", "parse_scene"]


class _Table:
    """A TOML table being read: typed getters, and a check that no key is left unknown."""

    def __init__(self, path: str, name: str, data):
        if not isinstance(data, dict):
            raise SceneError(path, name, f"must be a table, got {type(data).__name__}")
        self.path, self.name, self.data, self.used = path, name, data, set()

    def key(self, k: str) -> str:
        return f"[{self.name}].{k}" if self.name else k

    def has(self, k: str) -> bool:
        return k in self.data

    def error(self, k: str, reason: str) -> SceneError:
        return SceneError(self.path, self.key(k), reason)

    def raw(self, k: str, default=None, required=False):
        if k not in self.data:
            if required:
                raise self.error(k, "missing value")
            return default
        self.used.add(k)
        return self.data[k]

    def number(self, k: str, default=None, required=False, positive=False, nonneg=False, within=None) -> float | None:
        """A finite number; ``within=(lo, hi)`` with the reason a value outside makes no sense."""
        v = self.raw(k, default, required)
        if v is None:
            return None
        if isinstance(v, bool) or not isinstance(v, (int, float)):
            raise self.error(k, f"must be a number, got {brief(v)}")
        v = float(v)
        if not math.isfinite(v):
            raise self.error(k, f"must be finite, got {v}")
        if positive and v <= 0.0:
            raise self.error(k, f"must be positive, got {v:g}")
        if nonneg and v < 0.0:
            raise self.error(k, f"must not be negative, got {v:g}")
        if within is not None and not within[0] <= v <= within[1]:
            raise self.error(k, f"must lie in [{within[0]:g}, {within[1]:g}] ({within[2]}), got {v:g}")
        return v

    def integer(self, k: str, default=None, required=False, minimum=None) -> int | None:
        v = self.raw(k, default, required)
        if v is None:
            return None
        if isinstance(v, bool) or not isinstance(v, int):
            raise self.error(k, f"must be an integer, got {brief(v)}")
        if minimum is not None and v < minimum:
            raise self.error(k, f"must be at least {minimum}, got {v}")
        return v

    def vector(self, k: str, n: int = 3, default=None, required=False) -> np.ndarray | None:
        v = self.raw(k, default, required)
        if v is None:
            return None
        if not isinstance(v, (list, tuple)) or len(v) != n:
            raise self.error(k, f"must be a list of {n} numbers, got {brief(v)}")
        out = []
        for x in v:
            if isinstance(x, bool) or not isinstance(x, (int, float)):
                raise self.error(k, f"must be a list of {n} numbers, got {brief(v)}")
            if not math.isfinite(float(x)):
                raise self.error(k, f"must be finite, got {brief(v)}")
            out.append(float(x))
        return np.array(out)

    def string(self, k: str, default=None, required=False, choices=None) -> str | None:
        v = self.raw(k, default, required)
        if v is None:
            return None
        if not isinstance(v, str):
            raise self.error(k, f"must be a string, got {brief(v)}")
        if choices is not None and v not in choices:
            raise self.error(k, f"unknown value {v!r}; valid: {', '.join(choices)}")
        return v

    def angle(self, k: str, default=None, required=False) -> float | None:
        """An angle given as ``k`` (rad) or ``k_deg`` (degrees), returned in radians."""
        if self.has(k) and self.has(k + "_deg"):
            raise self.error(k, f"give {k} (rad) or {k}_deg, not both")
        if self.has(k + "_deg"):
            return float(U.deg_to_rad(self.number(k + "_deg")))
        return self.number(k, default, required)

    def one_of(self, *keys: str) -> str | None:
        present = [k for k in keys if self.has(k)]
        if len(present) > 1:
            raise self.error(present[1], f"give only one of {', '.join(keys)}")
        return present[0] if present else None

    def sub(self, k: str, required=False) -> _Table | None:
        if required and k not in self.data:
            raise SceneError(self.path, f"[{self.name}.{k}]" if self.name else f"[{k}]", "missing table")
        v = self.raw(k, None)
        if v is None:
            return None
        return _Table(self.path, f"{self.name}.{k}" if self.name else k, v)

    def finish(self):
        unknown = sorted(set(self.data) - self.used)
        if unknown:
            k = unknown[0]
            raise self.error(k, "unknown key" + (f" (also unknown: {', '.join(unknown[1:])})" if len(unknown) > 1 else ""))


@dataclass(frozen=True)
class ObserveSpec:
    """[observe]: how a detector watches the scene (``spinviz observe``, ``spinviz listen``).

    t_end : how long it watches, in the scene's time unit (None: the scene's horizon);
    line_of_sight : world-frame direction to the detector (None: across L(0));
    distance_cm : where the field is given; power_factor, frequency_resolution,
    polarization_deg : the resolutions at which the two models count as told apart.
    """

    t_end: float | None = None
    line_of_sight: tuple[float, float, float] | None = None
    distance_cm: float = 1.0
    power_factor: float = 2.0
    frequency_resolution: float = 0.01
    polarization_deg: float = 5.0


@dataclass(frozen=True)
class Scene:
    """A validated scene, in the body's units (CGS: s, rad/s; dimensionless: tau0, 1/tau0)."""

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

    @property
    def units(self) -> str:
        return self.body.units

    @property
    def model(self) -> str:
        return self.models[0]

    def simulation_kwargs(self, kinematics: str = "quaternion", t_eval=None) -> dict:
        """Keyword arguments for ``spinviz.simulate.simulate`` (without body and model): the
        scene's ``samples`` instants over [0, t_end], or the given ``t_eval``."""
        times = {"t_end": self.t_end, "samples": self.samples} if t_eval is None else {"t_eval": t_eval}
        return dict(omega0=self.omega0, q0=self.q0, method=self.method, rtol=self.rtol, atol=self.atol,
                    step=self.step, kinematics=kinematics, **times)


# --- body ---------------------------------------------------------------------------------
_BODY_FORMS = ("preset", "shape", "delta", "inertia")


def _body(t: _Table, units_hint: str | None) -> B.Body:
    form = t.one_of(*_BODY_FORMS)
    if form is None:
        raise t.error("preset", "missing value: give preset, shape, delta (with chi) or inertia (with dipole)")
    try:
        if form == "preset":
            return _preset(t)
        if form == "shape":
            return _shape(t)
        if form == "delta":
            delta = t.number("delta", required=True)
            chi = t.angle("chi", required=True)
            return B.symmetric_top(delta, chi, name=t.string("name", "symmetric top"))
        inertia = t.vector("inertia", required=True)
        units = units_hint or "dimensionless"
        if units == "cgs":
            d = t.one_of("dipole_debye", "dipole")
            if d is None:
                raise t.error("dipole_debye", "missing value (statC cm as dipole, or Debye as dipole_debye)")
            dipole = t.vector(d, required=True) * (U.DEBYE if d == "dipole_debye" else 1.0)
        else:
            dipole = t.vector("dipole", required=True)
        return B.custom(inertia, dipole, units=units, name=t.string("name", "custom body"))
    except B.BodyError as e:
        raise t.error(e.key, e.reason) from None


# Physical ranges of the CGS inputs: wide enough for any nanoparticle and for a metre-sized
# crystal, narrow enough that every derived quantity (I ~ rho L^5, tau0 ~ d^2/I) is a float64.
LENGTH_NM = (0.1, 1e9, "from an atom to a metre")
DENSITY = (1e-3, 1e3, "g/cm^3")
DIPOLE_DEBYE = (1e-6, 1e30, "D")
ASPECT = (1e-3, 1e3, "L/D")


def _preset(t: _Table) -> B.Body:
    name = t.string("preset", choices=tuple(P.PRESETS) + ("dast_box",))
    density = t.number("density", within=DENSITY)
    if name == "cellulose_rod":
        return P.cellulose_rod(density=density)
    if name == "dast_cube":
        return P.dast_cube(t.number("a_nm", 100.0, within=LENGTH_NM), density=density)
    if name == "dast_family1":
        return P.dast_family1(t.number("a_nm", 100.0, within=LENGTH_NM), t.number("c_nm", 50.0, within=LENGTH_NM),
                              density=density)
    a, b, c = (t.number(k, required=True, within=LENGTH_NM) for k in ("a_nm", "b_nm", "c_nm"))
    return P.dast_box(a, b, c, density=density)


def _shape(t: _Table) -> B.Body:
    kind = t.string("shape", choices=("rod", "box"))
    density = t.number("density", required=True, within=DENSITY)
    name = t.string("name", kind)
    if kind == "rod":
        length = t.number("length_nm", required=True, within=LENGTH_NM) * U.NM
        if t.has("diameter_nm") == t.has("aspect"):
            raise t.error("diameter_nm", "give diameter_nm or aspect (L/D), exactly one")
        if t.has("diameter_nm"):
            diameter = t.number("diameter_nm", within=LENGTH_NM) * U.NM
        else:
            diameter = length / t.number("aspect", within=ASPECT)
        dipole = t.number("dipole_debye", required=True, within=DIPOLE_DEBYE) * U.DEBYE
        return B.rod(length, diameter, density, dipole, t.angle("chi", 0.0), name=name)
    a, b, c = (t.number(k, required=True, within=LENGTH_NM) * U.NM for k in ("a_nm", "b_nm", "c_nm"))
    dipole = t.vector("dipole_debye", required=True)
    size = float(np.max(np.abs(dipole)))
    if not DIPOLE_DEBYE[0] <= size <= DIPOLE_DEBYE[1]:
        raise t.error("dipole_debye", f"the largest component must lie in [{DIPOLE_DEBYE[0]:g}, {DIPOLE_DEBYE[1]:g}] D, "
                                      f"got {size:g}")
    return B.box(a, b, c, density, dipole * U.DEBYE, name=name)


# --- the whole file -----------------------------------------------------------------------
def parse_scene(data: dict, path: str = "<scene>") -> Scene:
    """Validate a parsed TOML document; raise SceneError on the first problem."""
    top = _Table(path, "", data)
    title = top.string("title", os.path.splitext(os.path.basename(path))[0])
    top.string("description")
    bt = top.sub("body", required=True)
    it = top.sub("initial", required=True)
    st = top.sub("simulation", required=True)
    units_hint = st.string("units", choices=U.UNIT_SYSTEMS)
    body = _body(bt, units_hint)
    label = bt.string("name")
    if label is not None and label != body.name:
        body = replace(body, name=label)
    bt.finish()
    if units_hint is not None and units_hint != body.units:
        raise st.error("units", f"{units_hint!r} does not match the body, which is given in {body.units!r} units")
    omega0, q0 = _initial(it)
    try:
        check_scale(body, omega0)
    except SpecError as e:
        raise SceneError(path, "[initial].omega" if e.key == "omega" else "[body]", e.reason) from None
    sim = _simulation(st, body, omega0)
    render = _render(top, path, title, sim["t_end"])
    observe = _observe(top.sub("observe"), body, omega0, sim)
    top.finish()
    return Scene(path=str(path), title=title, body=body, omega0=omega0, q0=q0, render=render, observe=observe, **sim)


def _initial(it: _Table):
    """[initial]: (omega0 (3,), q0 (w, x, y, z))."""
    omega0 = it.vector("omega", required=True)
    form = it.one_of("euler_zxz", "euler_zxz_deg", "quaternion")
    if form == "euler_zxz":
        q0 = R.quat_from_euler_zxz(it.vector("euler_zxz"))
    elif form == "euler_zxz_deg":
        q0 = R.quat_from_euler_zxz(U.deg_to_rad(it.vector("euler_zxz_deg")))
    elif form == "quaternion":
        qv = it.vector("quaternion", 4)
        if not np.linalg.norm(qv) > 0:
            raise it.error("quaternion", "must not be zero")
        q0 = R.normalize(qv)
    else:
        q0 = np.array([1.0, 0.0, 0.0, 0.0])
    it.finish()
    return omega0, q0


def _models(st: _Table) -> tuple[str, ...]:
    mkey = st.one_of("model", "models")
    if mkey is None:
        raise st.error("model", f"missing value; valid: {', '.join(MODELS)}")
    if mkey == "model":
        return (st.string("model", choices=MODELS),)
    ms = st.raw("models")
    if not isinstance(ms, list) or not (1 <= len(ms) <= 2) or not all(isinstance(m, str) for m in ms):
        raise st.error("models", f"must be a list of one or two model names, got {ms!r}")
    for m in ms:
        if m not in MODELS:
            raise st.error("models", f"unknown model {m!r}; valid: {', '.join(MODELS)}")
    return tuple(ms)


MAX_SAMPLES = 1_000_000
RTOL_RANGE = (1e-15, 1e-1, "a few ulp of float64 at the tightest")
ATOL_RANGE = (1e-300, 1.0, "units where |omega(0)| = 1")

def _simulation(st: _Table, body: B.Body, omega0) -> dict:
    """[simulation]: models, horizon, samples and the integrator settings, as Scene fields."""
    models = _models(st)
    tkey = st.one_of("t_end", "t_end_T", "t_end_Theta")
    if tkey is None:
        raise st.error("t_end", "missing value (or give t_end_T / t_end_Theta)")
    t_end = st.number(tkey, positive=True)
    if tkey != "t_end":
        t_end *= _time_scale(body, omega0, tkey, st)
        if not math.isfinite(t_end):
            raise st.error(tkey, "the horizon in seconds is beyond float64")
    samples = st.integer("samples", required=True, minimum=2)
    if samples > MAX_SAMPLES:
        raise st.error("samples", f"must be at most {MAX_SAMPLES} (memory: {samples} instants x 11 numbers per model), "
                                  f"got {samples}")
    if not np.all(np.diff(np.linspace(0.0, t_end, samples)) > 0.0) or not t_end / body.tau0 > 0.0:
        raise st.error(tkey, f"{t_end:g} is too short to hold {samples} distinct instants")
    method = st.string("method", "auto")
    if method.lower() != "auto":
        from .integrators import get as method_named  # the registry only: no kernel is compiled

        try:
            method_named(method)
        except ValueError as e:
            raise st.error("method", str(e)) from None
    rtol = st.number("rtol", 1e-10, positive=True, within=RTOL_RANGE)
    atol = st.number("atol", 1e-12, positive=True, within=ATOL_RANGE)
    step = st.number("step", positive=True)
    try:
        for m in models:
            check_cost(body, m, omega0, t_end, method, step)
    except SpecError as e:
        raise st.error(tkey if e.key == "t_end" else e.key, e.reason) from None
    st.finish()
    return dict(models=models, t_end=t_end, samples=samples, method=method.lower(), rtol=rtol, atol=atol, step=step)


def _render(top: _Table, path: str, title: str, t_end: float) -> RenderSpec:
    """[render], validated by ``RenderSpec`` itself (the one place render inputs are checked)."""
    data = top.raw("render")
    try:
        spec = RenderSpec(title=title) if data is None else RenderSpec.from_mapping(data, title)
        spec.check_horizon(t_end)
    except SpecError as e:
        raise SceneError(path, e.key if e.key.startswith("[") else f"[render].{e.key}", e.reason) from None
    return spec


DISTANCE_CM = (1e-4, 1e30, "from a micron to a megaparsec")


def _observe(ot: _Table | None, body: B.Body, omega0, sim: dict) -> ObserveSpec:
    """[observe], optional: the detector's horizon, line of sight, distance and resolutions."""
    if ot is None:
        return ObserveSpec()
    t_end = None
    tkey = ot.one_of("t_end", "t_end_T", "t_end_Theta")
    if tkey is not None:
        t_end = ot.number(tkey, positive=True)
        if tkey != "t_end":
            t_end *= _time_scale(body, omega0, tkey, ot)
        if not math.isfinite(t_end) or not t_end / body.tau0 > 0.0:
            raise ot.error(tkey, "the horizon is beyond float64")
        try:
            for m in sim["models"]:
                check_cost(body, m, omega0, t_end, sim["method"], sim["step"])
        except SpecError as e:
            raise ot.error(tkey if e.key == "t_end" else e.key, e.reason) from None
    los = ot.vector("line_of_sight")
    if los is not None and not float(np.linalg.norm(los)) > 0.0:
        raise ot.error("line_of_sight", "must not be zero")
    spec = ObserveSpec(
        t_end=t_end, line_of_sight=None if los is None else tuple(float(x) for x in los),
        distance_cm=ot.number("distance_cm", 1.0, positive=True, within=DISTANCE_CM),
        power_factor=ot.number("power_factor", 2.0, within=(1.0001, 1e6, "a ratio above 1")),
        frequency_resolution=ot.number("frequency_resolution", 0.01, within=(1e-12, 0.5, "a relative difference")),
        polarization_deg=ot.number("polarization_deg", 5.0, within=(0.01, 89.0, "degrees")))
    ot.finish()
    return spec


def _time_scale(body: B.Body, omega0, key: str, st: _Table) -> float:
    """T = 1/(tau0 Omega20^2) or Theta = 1/(tau0 Omega3^2 eps^2) of the initial state.

    T is the paper's (after (3.9) and in (6.1)): Omega20 is the spin across the symmetry
    axis, here |Omega_perp(0)| = hypot(Omega1, Omega2), so the check scenes run the horizons
    `spinviz check` uses.
    """
    if key == "t_end_T":
        w_perp = math.hypot(float(omega0[0]), float(omega0[1]))
        if w_perp == 0.0:
            raise st.error(key, "T = 1/(tau0 Omega_perp^2) is infinite for Omega_perp = 0")
        return body.braking_time_T(w_perp)
    w3 = abs(float(omega0[2]))
    if w3 == 0.0:
        raise st.error(key, "Theta = 1/(tau0 Omega3^2 (I3/I1)^2) is infinite for Omega3 = 0")
    return body.residual_time_Theta(w3)


MAX_FILE_BYTES = 16_000_000     # a scene is a few hundred bytes; this bounds what a bad path can make us read


def read_toml(path, kind: str = "scene") -> dict:
    """The parsed TOML document at ``path``; ``SceneError(path, "(file)", reason)`` for anything
    that is not a readable regular UTF-8 TOML file of sensible size (a FIFO or a device would
    block or never end; nesting thousands deep would exhaust the parser's recursion)."""
    path = os.fspath(path)
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK)         # never blocks on a FIFO
    except FileNotFoundError:
        raise SceneError(path, "(file)", "no such file") from None
    except OSError as e:
        raise SceneError(path, "(file)", e.strerror or str(e)) from None
    try:
        st = os.fstat(fd)
        if stat.S_ISDIR(st.st_mode):
            raise SceneError(path, "(file)", f"is a directory, not a {kind} file")
        if not stat.S_ISREG(st.st_mode):
            raise SceneError(path, "(file)", f"not a regular file (a pipe, device or socket); a {kind} is a TOML file")
        if st.st_size > MAX_FILE_BYTES:
            raise SceneError(path, "(file)", f"{st.st_size} bytes is too large for a {kind} file (limit {MAX_FILE_BYTES})")
        raw = os.read(fd, MAX_FILE_BYTES + 1)
    except OSError as e:
        raise SceneError(path, "(file)", e.strerror or str(e)) from None
    finally:
        os.close(fd)
    try:
        return tomllib.loads(raw.decode("utf-8"))
    except UnicodeDecodeError:
        raise SceneError(path, "(file)", f"not a text (UTF-8) file; a {kind} is TOML") from None
    except tomllib.TOMLDecodeError as e:
        raise SceneError(path, "(file)", f"invalid TOML: {e}") from None
    except RecursionError:
        raise SceneError(path, "(file)", "values nested too deeply to be a scene") from None


def load_scene(path) -> Scene:
    """Read and validate a scene file; SceneError (one line: file, key, reason) on any problem."""
    path = os.fspath(path)
    return parse_scene(read_toml(path), path)
