"""The atlas spec: a TOML file, validated like a scene (one line naming file, key, reason).

A spec says which model(s), which (delta, chi) cells, which initial conditions at each cell,
how far and how finely to integrate, and how to classify::

    title = "reduced model, 12 x 12 cells, 8 members"
    models = ["reduced"]                  # or model = "reduced"; ["reduced", "truncated"] for both

    [grid]
    delta = { min = -1.0, max = 1.0, cells = 12 }   # centres of 12 equal cells of (min, max)
    chi_deg = { min = 0.0, max = 90.0, cells = 12 } # or chi (rad); or a list of values

    [members]
    count = 8                             # initial conditions per cell
    seed = 1                              # directions of omega(0) uniform on the sphere, from this seed
    omega = 0.1                           # |omega(0)| (dimensionless, 1/tau0)
    # or: list = [[0.0, 0.1, 0.0], ...]   explicit omega(0) vectors, body frame

    [run]
    tau_end = 1e10                        # horizon, tau = t/tau0
    tau_start = 1e-2                      # first sample after 0
    samples_per_decade = 20
    rtol = 1e-8                           # Taylor tolerance on omega sqrt(1 + tau/T) / |omega0| (T = 1/|omega0|^2)
    max_steps = 20000000                  # step budget of one run

    [classify]
    window_decades = 2.0                  # decades at the end of a run the classifier analyses

Every member uses the same omega(0) at every cell and in both models, so that cells and
models are compared on the same starts (paired), and the store records them.

Defaults and why: the asymptotic laws of section 4 need tau |omega0|^2 >> 1 (T = 1/|omega0|^2
is the braking time); with |omega0| = 0.1 the default horizon 1e10 is 1e8 T.  The slowest
regimes need it: near (delta, chi) = (0.3, 0.72) type 3's amplitudes still drift ~9 % a
decade after 10 decades, and a type-4 phase with beta just below -3/4 is captured into type
5 only at tau ~ 1e16.  Spirals cost ~ sqrt(tau_end) steps (~0.005-0.4 s a run at 1e10, up
to ~3 s in the worst cells), so 1e10 is where the labels of the prototype's studies stopped
changing while a 12 x 12 x 8 atlas still runs in minutes on two cores.  rtol 1e-8: Taylor's
method on the scaled omega sqrt(1 + tau/T) / |omega0|, so the tolerance holds relative to the
braking law to the end of the run (docs/atlas.md: labels and amplitudes against rtol).
20 samples a decade and a 2-decade window: 41 samples, the labels are the same at 10-50.
"""

from __future__ import annotations

import hashlib
import json
import math
import os
from dataclasses import dataclass

import numpy as np

from ..errors import SceneError, brief
from ..physics.bodies import MIN_INERTIA_RATIO
from ..scene import _Table, read_toml
from .runs import Settings

MODELS = ("reduced", "truncated")
FORMAT = 2                       # the store's version (identity): 2 = Taylor's method (heyoka), no atol
MAX_RUNS = 100_000_000
MAX_CELLS = 4096                 # per axis
MAX_MEMBERS = 100_000
OMEGA_MAX = 10.0                 # |omega(0)| beyond which the start is hopelessly stiff (tau0 Omega >> 1)


@dataclass(frozen=True)
class AtlasSpec:
    """A validated atlas spec.

    deltas : shape (n_delta,), (3.6), each in (-1, 1).  chis : shape (n_chi,), rad, in [0, pi/2].
    omega0 : shape (members, 3), body-frame starts (dimensionless), the same at every cell.
    settings : how each run is integrated and classified.
    """

    path: str
    title: str
    description: str
    models: tuple
    deltas: np.ndarray
    chis: np.ndarray
    omega0: np.ndarray
    settings: Settings
    seed: int | None = None
    omega_magnitude: float | None = None

    @property
    def members(self) -> int:
        return int(self.omega0.shape[0])

    @property
    def runs(self) -> int:
        return len(self.models) * len(self.deltas) * len(self.chis) * self.members

    def canonical(self) -> dict:
        """Everything that decides the numbers, as plain JSON types (title and description
        excluded: renaming a study does not change it)."""
        s = self.settings
        return {
            "format": FORMAT,
            "models": list(self.models),
            "delta": [float(x) for x in self.deltas],
            "chi": [float(x) for x in self.chis],
            "members": {"count": self.members, "seed": self.seed, "omega": self.omega_magnitude,
                        "omega0": [[float(x) for x in row] for row in self.omega0]},
            "run": {"tau_end": s.tau_end, "tau_start": s.tau_start, "samples_per_decade": s.per_decade,
                    "rtol": s.rtol, "max_steps": s.max_steps},
            "classify": {"window_decades": s.window},
        }

    def canonical_json(self) -> str:
        return json.dumps(self.canonical(), sort_keys=True, separators=(",", ":"))

    def identity(self) -> str:
        """sha256 of the canonical JSON (with the classifier's version): equal identities,
        equal numbers."""
        from .classify import VERSION

        return hashlib.sha256(f"classifier {VERSION}\n{self.canonical_json()}".encode()).hexdigest()


def load_spec(path) -> AtlasSpec:
    """Read and validate an atlas spec; ``SceneError`` (file, key, reason) on any problem."""
    path = os.fspath(path)
    return parse_spec(read_toml(path, kind="atlas spec"), path)


def parse_spec(data: dict, path: str = "<atlas spec>") -> AtlasSpec:
    """Validate a parsed TOML document (see the module docstring for every key)."""
    top = _Table(path, "", data)
    title = top.string("title", default="") or ""
    description = top.string("description", default="") or ""
    models = _models(top)
    grid = top.sub("grid", required=True)
    deltas = _axis(grid, "delta", (-1.0, 1.0), open_ends=True, unit="")
    if grid.has("chi") and grid.has("chi_deg"):
        raise grid.error("chi", "give chi (rad) or chi_deg, not both")
    if grid.has("chi_deg"):
        chis_deg = _axis(grid, "chi_deg", (0.0, 90.0), open_ends=False, unit=" deg")
        chis = np.radians(chis_deg)
        chis[chis_deg == 90.0] = 0.5 * math.pi             # exactly pi/2: the transverse case (5.5)
    else:
        chis = _axis(grid, "chi", (0.0, 0.5 * math.pi), open_ends=False, unit=" rad", required=True)
    grid.finish()
    for d in deltas:
        if 1.0 - d < MIN_INERTIA_RATIO:
            raise grid.error("delta", f"delta = {d:g}: 1 - delta = I3/I1 is below {MIN_INERTIA_RATIO:g}, too thin to integrate")
    omega0, seed, mag = _members(top)
    settings = _run(top)
    top.finish()
    n_runs = len(models) * len(deltas) * len(chis) * len(omega0)
    if n_runs > MAX_RUNS:
        raise SceneError(path, "[grid]", f"{n_runs} runs exceed the limit of {MAX_RUNS}")
    return AtlasSpec(path=path, title=title, description=description, models=models, deltas=deltas, chis=chis,
                     omega0=omega0, settings=settings, seed=seed, omega_magnitude=mag)


def _models(top: _Table) -> tuple:
    key = top.one_of("model", "models")
    if key is None:
        return ("reduced",)
    if key == "model":
        return (top.string("model", choices=MODELS),)
    v = top.raw("models")
    if not isinstance(v, list) or not v:
        raise top.error("models", f"must be a non-empty list of {', '.join(MODELS)}, got {brief(v)}")
    out = []
    for m in v:
        if m not in MODELS:
            raise top.error("models", f"unknown model {brief(m)}; valid: {', '.join(MODELS)}")
        if m in out:
            raise top.error("models", f"{m!r} named twice")
        out.append(m)
    return tuple(out)


def _axis(t: _Table, k: str, bounds: tuple, open_ends: bool, unit: str, required: bool = True):
    """A grid axis: a list of values, or ``{min, max, cells}`` (the centres of ``cells``
    equal cells, so never an end of the range)."""
    v = t.raw(k, required=required)
    lo, hi = bounds
    ends = f"({lo:g}, {hi:g})" if open_ends else f"[{lo:g}, {hi:g}]"
    if isinstance(v, dict):
        r = _Table(t.path, f"{t.name}.{k}" if t.name else k, v)
        a = r.number("min", required=True)
        b = r.number("max", required=True)
        n = r.integer("cells", required=True, minimum=1)
        r.finish()
        if not a < b:
            raise r.error("max", f"must exceed min ({a:g}), got {b:g}")
        if a < lo or b > hi:
            raise r.error("min" if a < lo else "max", f"the range must lie within {ends}{unit}, got [{a:g}, {b:g}]")
        if n > MAX_CELLS:
            raise r.error("cells", f"at most {MAX_CELLS}, got {n}")
        v = a + (np.arange(n) + 0.5) * (b - a) / n
        v[np.abs(v) < 1e-12 * (b - a)] = 0.0       # an odd count centred on 0 hits it exactly (delta = 0: (5.2))
        return v
    if isinstance(v, list):
        if not v:
            raise t.error(k, "is empty: give at least one value, or {min, max, cells}")
        vals = []
        for x in v:
            if isinstance(x, bool) or not isinstance(x, (int, float)) or not math.isfinite(float(x)):
                raise t.error(k, f"must be a list of finite numbers, got {brief(v)}")
            x = float(x)
            inside = lo < x < hi if open_ends else lo <= x <= hi
            if not inside:
                raise t.error(k, f"{x:g} is outside {ends}{unit}")
            vals.append(x)
        if len(set(vals)) != len(vals):
            raise t.error(k, "a value is listed twice")
        if any(b <= a for a, b in zip(vals, vals[1:])):
            raise t.error(k, "values must increase")
        if len(vals) > MAX_CELLS:
            raise t.error(k, f"at most {MAX_CELLS} values, got {len(vals)}")
        return np.array(vals)
    raise t.error(k, f"must be a list of values or a table {{min, max, cells}}, got {brief(v)}")


def _members(top: _Table):
    m = top.sub("members", required=True)
    if m.has("list"):
        for other in ("count", "seed", "omega"):
            if m.has(other):
                raise m.error(other, "give list (explicit starts) or count, seed and omega, not both")
        v = m.raw("list")
        if not isinstance(v, list) or not v:
            raise m.error("list", f"must be a non-empty list of [w1, w2, w3], got {brief(v)}")
        rows = []
        for row in v:
            if not isinstance(row, list) or len(row) != 3 or any(isinstance(x, bool) or not isinstance(x, (int, float))
                                                                 for x in row):
                raise m.error("list", f"each start must be [w1, w2, w3] (numbers), got {brief(row)}")
            r = np.array(row, dtype=float)
            if not np.all(np.isfinite(r)):
                raise m.error("list", f"each start must be finite, got {brief(row)}")
            n = float(np.linalg.norm(r))
            if not 0.0 < n <= OMEGA_MAX:
                raise m.error("list", f"|omega(0)| must lie in (0, {OMEGA_MAX:g}], got {n:g} for {brief(row)}")
            rows.append(r)
        if len(rows) > MAX_MEMBERS:
            raise m.error("list", f"at most {MAX_MEMBERS} starts, got {len(rows)}")
        m.finish()
        return np.array(rows), None, None
    count = m.raw("count", required=True)
    if isinstance(count, bool) or not isinstance(count, int):
        raise m.error("count", f"must be a whole number, got {brief(count)}")
    if count <= 0:
        raise m.error("count", f"must be at least 1, got {count}")
    if count > MAX_MEMBERS:
        raise m.error("count", f"at most {MAX_MEMBERS}, got {count}")
    seed = m.integer("seed", required=True, minimum=0)
    mag = m.number("omega", default=0.1, positive=True)
    if mag > OMEGA_MAX:
        raise m.error("omega", f"must not exceed {OMEGA_MAX:g} (tau0 |Omega| >> 1 is outside the model), got {mag:g}")
    m.finish()
    return directions(count, seed) * mag, int(seed), float(mag)


def directions(count: int, seed: int) -> np.ndarray:
    """``count`` unit vectors uniform on the sphere (normalized Gaussians), from ``seed``; shape (count, 3)."""
    v = np.random.default_rng(seed).normal(size=(count, 3))
    return v / np.linalg.norm(v, axis=1, keepdims=True)


def _run(top: _Table) -> Settings:
    d = Settings()
    r = top.sub("run")
    c = top.sub("classify")
    if r is None:
        r = _Table(top.path, "run", {})
    tau_end = r.number("tau_end", default=d.tau_end, positive=True)
    tau_start = r.number("tau_start", default=d.tau_start, positive=True)
    per = r.integer("samples_per_decade", default=d.per_decade, minimum=6)
    if per > 1000:
        raise r.error("samples_per_decade", f"at most 1000, got {per}")
    rtol = r.number("rtol", default=d.rtol, within=(1e-14, 1e-3, "Taylor's method in float64"))
    if r.has("atol"):
        raise r.error("atol", "is not used since the atlas integrates with Taylor's method: its one tolerance, rtol, "
                              "holds on omega sqrt(1 + tau/T) / |omega0| (docs/atlas.md); remove the key")
    max_steps = r.integer("max_steps", default=d.max_steps, minimum=1000)
    r.finish()
    window = d.window
    if c is not None:
        window = c.number("window_decades", default=d.window, within=(0.5, 6.0, "the classifier's window"))
        c.finish()
    if tau_end > 1e16:
        raise r.error("tau_end", f"at most 1e16 (float64 time steps), got {tau_end:g}")
    decades = math.log10(tau_end / tau_start)
    if decades < 2.0 * window:
        raise r.error("tau_end", f"tau_end/tau_start spans {decades:.2g} decades; the classifier needs at least "
                                 f"2 x window_decades = {2 * window:g} (one window, and one before it to see the label hold)")
    if per * window < 12:
        raise r.error("samples_per_decade", f"{per} a decade gives {per * window:g} samples in the {window:g}-decade "
                                            f"window; the classifier needs 12")
    return Settings(tau_end=tau_end, tau_start=tau_start, per_decade=per, rtol=rtol, max_steps=max_steps,
                    window=window)
