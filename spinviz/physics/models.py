"""The equations of motion as data: one frozen ``Model`` per equation, in one registry.

Every place that needs to know which equations exist -- the schema's model names, the
integrators' compiled kernels and Taylor systems, the averaged flows, the atlas's type
labels, the experiment's line laws -- reads this registry, so adding an equation is one
``register(Model(...))`` plus its physics (the rate function, and whatever optional parts
it supports).  How a model is drawn (colour, line, caption words) is presentation, kept in
``spinviz.presentation``, which must cover every registered model.

A ``Model`` carries:

* ``name``: the lower-case key used by scenes, the command line and Python;
* ``equations``: the paper's equation numbers; ``summary``: what it predicts, one line;
* ``terms(w1, w2, w3, J, g, free)``: body-frame Omega_dot written component-wise in plain
  arithmetic, so that one source is evaluated by Python, compiled by numba and built into a
  heyoka expression (``free`` = 0 keeps the radiation part alone; see
  ``equations.reduced_terms``);
* ``kernel_id``: its number in the compiled kernels (``integrators.kernels.terms``), or None:
  then only the methods that evaluate ``terms`` directly (Taylor's method, SciPy's) run it;
* ``brakes``: whether it has a radiation torque (False for the torque-free top);
* ``symmetric_rate``: the symmetric top's written-out rate ((4.2)-(4.4) form) the atlas
  integrates, or None;
* ``averaged``: the averaged flow's harmonics and coefficients (``Averaged``), or None;
* ``line``: the longitudinal top's line and its power-frequency law (``LineLaw``), or None;
* ``type_labels``: the atlas classifier's class -> the paper's type label, or None.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from types import MappingProxyType

import numpy as np

from . import equations as E
from . import harmonics as H
from . import longitudinal as LG

__all__ = ["Model", "Averaged", "LineLaw", "System", "register", "unregister", "get", "names", "with_line_law",
           "for_atlas", "kernel_id", "rate_function", "radiation_function", "omega_dot", "jacobian", "CLASSES"]

# the atlas classifier's classes (regimes.engine.classify), each mapped by a model to its type label
CLASSES = ("axial-stopped", "axial-spiral", "balanced-spiral", "transverse-spiral", "libration", "transverse-frozen",
           "residual")


@dataclass(frozen=True)
class Averaged:
    """A model's averaged (secular) flow of the symmetric top (``physics.averaged``).

    harmonics : {"z": terms, "w3": terms}, each term (m, j, k, l, c(delta, n1, n3)) of the
        radiation part of z' and omega3' (``harmonics`` module).
    coefficients : (delta, chi) -> (P, Q, R, S) of d wp/dtau = -wp (P wp^2 + Q w3^2),
        d w3/dtau = -w3 (R wp^2 + S w3^2).
    source : where the flow comes from (an equation number, or spinviz's derivation).
    """

    harmonics: Mapping
    coefficients: Callable
    source: str


@dataclass(frozen=True)
class LineLaw:
    """The one spectral line of a longitudinal or spherical top under a model
    (``physics.longitudinal``).

    state : (t, u0, b0, tau0) -> (u, b), u = Omega_perp^2, b = eps^2 Omega3^2 (rad^2/s^2).
    drift : (u, b, tau0) -> (f'/f, f''/f), the line's relative drift and its rate.
    law : (f, f_inf) -> the power-frequency law up to a constant.
    formula : the law in words, "P ∝ f⁴"; equation : the closed form it follows from.
    """

    state: Callable
    drift: Callable
    law: Callable
    formula: str
    equation: str

    def line(self, t, u0, b0, tau0):
        """(f, shape): the line's frequency (Hz) and power up to a constant at times t (s)."""
        return LG.line_from_state(*self.state(t, u0, b0, tau0))


@dataclass(frozen=True)
class Model:
    """One equation of motion and what spinviz knows about it (module docstring)."""

    name: str
    equations: str
    summary: str
    terms: Callable
    kernel_id: int | None = None
    brakes: bool = True
    symmetric_rate: Callable | None = None
    averaged: Averaged | None = None
    line: LineLaw | None = None
    type_labels: Mapping[str, str] | None = field(default=None)

    def __post_init__(self):
        if not isinstance(self.name, str) or not self.name or self.name != self.name.lower() or not self.name.isidentifier():
            raise ValueError(f"a model's name is a lower-case identifier, got {_brief(self.name)}")
        for key in ("equations", "summary"):
            if not isinstance(getattr(self, key), str):
                raise TypeError(f"model {self.name!r}: {key} is text, got {_brief(getattr(self, key))}")
        for key, kind in (("terms", None), ("symmetric_rate", None), ("averaged", Averaged), ("line", LineLaw)):
            value = getattr(self, key)
            if value is None and key != "terms":
                continue
            if not (callable(value) if kind is None else isinstance(value, kind)):
                want = "a function (w1, w2, w3, J, g[, free])" if kind is None else f"a {kind.__name__}"
                raise TypeError(f"model {self.name!r}: {key} must be {want}, got {_brief(value)}")
        if self.kernel_id is not None and (isinstance(self.kernel_id, bool) or not isinstance(self.kernel_id, int)):
            raise TypeError(f"model {self.name!r}: kernel_id is a whole number or None, got {_brief(self.kernel_id)}")
        if not isinstance(self.brakes, bool):
            raise TypeError(f"model {self.name!r}: brakes is True or False, got {_brief(self.brakes)}")
        if self.type_labels is not None and not isinstance(self.type_labels, Mapping):
            raise TypeError(f"model {self.name!r}: type_labels maps each class to a label, got {_brief(self.type_labels)}")
        if self.type_labels is not None:
            missing = set(CLASSES) - set(self.type_labels)
            if missing:
                raise ValueError(f"model {self.name!r}: type_labels lacks {', '.join(sorted(missing))}")
            object.__setattr__(self, "type_labels", MappingProxyType(dict(self.type_labels)))

    def rate(self, w1, w2, w3, J, g):
        """The whole Omega_dot (``terms`` with free = 1)."""
        return self.terms(w1, w2, w3, J, g, 1.0)

    def radiation(self, w1, w2, w3, J, g):
        """The radiation part of Omega_dot alone (``terms`` with free = 0): no cancellation
        against the free part, which is 1e16 times larger for real particles."""
        return self.terms(w1, w2, w3, J, g, 0.0)


_REGISTRY: dict[str, Model] = {}


def _brief(value) -> str:
    """A short, printable repr of a value a caller handed in (``errors.brief``)."""
    from ..errors import brief

    return brief(value)


def register(model: Model) -> Model:
    """Add ``model`` to the registry (its name must be new); returns it."""
    if not isinstance(model, Model):
        raise TypeError(f"register takes a Model, got {_brief(model)}")
    if model.name in _REGISTRY:
        raise ValueError(f"model {model.name!r} is already registered")
    if model.kernel_id is not None and any(m.kernel_id == model.kernel_id for m in _REGISTRY.values()):
        raise ValueError(f"model {model.name!r}: kernel id {model.kernel_id} is taken")
    _REGISTRY[model.name] = model
    return model


def unregister(name: str) -> None:
    """Remove a model (tests that register a model of their own); a name not registered is
    nothing to remove."""
    if isinstance(name, str):
        _REGISTRY.pop(name, None)


def names() -> tuple[str, ...]:
    """Every registered model's name, in registration order (reduced, truncated, free, ...)."""
    return tuple(_REGISTRY)


def get(name) -> Model:
    """The model registered as ``name``; ``ValueError`` naming the valid ones otherwise."""
    if isinstance(name, Model):
        return name
    try:
        return _REGISTRY[name]
    except (KeyError, TypeError):
        raise ValueError(f"unknown model {_brief(name)}; valid: {', '.join(_REGISTRY)}") from None


def with_line_law() -> tuple[str, ...]:
    """The models whose longitudinal line is known in closed form: the ones an experiment
    compares (``observe``'s parting times, ``decide``, the P-f test)."""
    return tuple(m.name for m in _REGISTRY.values() if m.line is not None)


def for_atlas() -> tuple[str, ...]:
    """The models the regime atlas can map: those with the symmetric top's written-out rate,
    an averaged flow and the classifier's type labels."""
    return tuple(m.name for m in _REGISTRY.values()
                 if m.symmetric_rate is not None and m.averaged is not None and m.type_labels is not None)


def kernel_id(name: str, method: str) -> int:
    """The model's number in the compiled kernels; ``ValueError`` saying which methods can run
    it where it has none."""
    m = get(name)
    if m.kernel_id is None:
        raise ValueError(f"{method}: the model {name!r} has no compiled kernel; Taylor's method and SciPy's integrate it")
    return m.kernel_id


def rate_function(name: str):
    """The Omega_dot function (w1, w2, w3, J, g) of a model name."""
    return get(name).rate


def radiation_function(name: str):
    """(w1, w2, w3, J, g) -> the radiation part of Omega_dot alone (rate minus free rate,
    computed without the cancellation of subtracting them)."""
    return get(name).radiation


def omega_dot(model: str, omega_body, J, g) -> np.ndarray:
    """The model's angular acceleration at many states at once.

    Parameters
    ----------
    model : str
        A registered model name ("reduced" (2.2)+(2.3), "truncated" (2.5), "free" (2.3a), ...).
    omega_body : array_like, shape (..., 3)
        Body-frame angular velocity, rad/s (CGS) or 1/tau0 (4.1), matching ``J`` and ``g``.
    J : sequence of 3 float
        Principal moments (g cm^2, or relative to I1).
    g : sequence of 3 float
        Body-frame radiation coupling sqrt(2/3c^3) d (the unit dipole direction in (4.1)).

    Returns
    -------
    ndarray, shape (..., 3)
        Body-frame Omega_dot, rad/s^2 or 1/tau0^2.
    """
    omega_body = np.asarray(omega_body, dtype=float)
    out = rate_function(model)(omega_body[..., 0], omega_body[..., 1], omega_body[..., 2], tuple(J), tuple(g))
    return np.stack(np.broadcast_arrays(*out), axis=-1)


def jacobian(model: str, omega_body, J, g) -> np.ndarray:
    """d Omega_dot / d Omega at one body-frame state ``omega_body`` (3,), shape (3, 3), in
    the units of ``J`` and ``g`` (see ``omega_dot``); exact to round-off.

    Complex-step differentiation of the model's own formula: for a real-analytic f,
    f(x + i h e_k) = f(x) + i h df/dx_k + O(h^2), with no subtraction, so with h = 1e-30
    |omega| the imaginary part is the derivative to the last bit.  Every model is a
    polynomial or rational function of Omega, so this is the analytic Jacobian without
    a hand-expanded (and error-prone) copy of (2.2).
    """
    f = rate_function(model)
    w = np.asarray(omega_body, dtype=float)
    h = 1e-30 * max(float(np.max(np.abs(w))), 1e-300)
    Jt, gt = tuple(J), tuple(g)
    out = np.empty((3, 3))
    for k in range(3):
        z = [complex(w[0]), complex(w[1]), complex(w[2])]
        z[k] += 1j * h
        col = f(z[0], z[1], z[2], Jt, gt)
        out[:, k] = [c.imag / h for c in col]
    return out


@dataclass(frozen=True)
class System:
    """What the integrators see: a model and the dimensionless body (4.1).

    inertia : (J1, J2, J3), principal moments scaled by I1 (J1 = 1 for a physical body).
    coupling : (g1, g2, g3), body-frame radiation coupling, |g|^2 / J1 = tau0 = 1.
    model : a registered model name.
    """

    model: str
    inertia: tuple[float, float, float]
    coupling: tuple[float, float, float]

    def __post_init__(self):
        get(self.model)  # validates the name

    @property
    def spec(self) -> Model:
        """The registered ``Model``."""
        return get(self.model)

    @property
    def is_symmetric(self) -> bool:
        """J1 = J2 to 1e-12 relative: the paper's symmetric top (``equations.is_symmetric``)."""
        return E.is_symmetric(self.inertia)

    def rate(self):
        """Closure (w1, w2, w3) -> Omega_dot components, parameters bound."""
        f = rate_function(self.model)
        J, g = tuple(map(float, self.inertia)), tuple(map(float, self.coupling))
        return lambda w1, w2, w3: f(w1, w2, w3, J, g)

    def radiation(self):
        """Closure (w1, w2, w3) -> the radiation part of Omega_dot alone."""
        f = radiation_function(self.model)
        J, g = tuple(map(float, self.inertia)), tuple(map(float, self.coupling))
        return lambda w1, w2, w3: f(w1, w2, w3, J, g)

    def omega_dot(self, omega_body) -> np.ndarray:
        """Body-frame Omega_dot (..., 3) at body-frame states ``omega_body`` (..., 3), 1/tau0^2
        and 1/tau0 (4.1): the module function ``omega_dot`` with this system's J and g."""
        return omega_dot(self.model, omega_body, self.inertia, self.coupling)

    def jacobian(self, omega_body) -> np.ndarray:
        """Exact d Omega_dot / d Omega, shape (3, 3), at one body-frame state (3,), (4.1) units."""
        return jacobian(self.model, omega_body, self.inertia, self.coupling)

    def rhs(self):
        """f(t, y) for y = (w1, w2, w3, q0, q1, q2, q3): Euler equation + quaternion kinematics."""
        rate = self.rate()

        def f(t, y):
            w1, w2, w3, q0, q1, q2, q3 = y.tolist()
            a1, a2, a3 = rate(w1, w2, w3)
            d0, d1, d2, d3 = E.quat_rate(q0, q1, q2, q3, w1, w2, w3)
            return np.array((a1, a2, a3, d0, d1, d2, d3))

        return f

    def rhs_jacobian(self):
        """J(t, y), shape (7, 7), of ``rhs``: exact Euler block, exact kinematics blocks."""
        model, inertia, coupling = self.model, self.inertia, self.coupling

        def jac(t, y):
            w = y[:3]
            q0, q1, q2, q3 = y[3:].tolist()
            w1, w2, w3 = w.tolist()
            out = np.zeros((7, 7))
            out[:3, :3] = jacobian(model, w, inertia, coupling)
            # d q_dot / d omega = 1/2 [q]_L restricted to the vector part
            out[3:, :3] = 0.5 * np.array(
                [[-q1, -q2, -q3], [q0, -q3, q2], [q3, q0, -q1], [-q2, q1, q0]]
            )
            # d q_dot / d q = 1/2 [(0, omega)]_R
            out[3:, 3:] = 0.5 * np.array(
                [[0.0, -w1, -w2, -w3], [w1, 0.0, w3, -w2], [w2, -w3, 0.0, w1], [w3, w2, -w1, 0.0]]
            )
            return out

        return jac


# --- the paper's equations ------------------------------------------------------------------
REDUCED = register(Model(
    name="reduced", equations="(2.2)+(2.3)",
    summary="Omega_dot, Omega_ddot in the torque taken from the free motion: a residual rotation about the dipole can last",
    terms=E.reduced_terms, kernel_id=1, symmetric_rate=E.symmetric_reduced_rate,
    averaged=Averaged(H.REDUCED, H.reduced_coefficients, "(4.12)"),
    line=LineLaw(LG.reduced_state, LG.reduced_drift, LG.reduced_law, "P ∝ f²(f² − f∞²)", "(5.2)"),
    type_labels={"axial-stopped": "1", "axial-spiral": "2", "balanced-spiral": "3", "transverse-spiral": "4",
                 "libration": "5", "transverse-frozen": "3.9", "residual": "R"},
))
TRUNCATED = register(Model(
    name="truncated", equations="(2.5)",
    summary="the textbook torque without the Schott-like term: every rotation brakes to rest by a power law",
    terms=E.truncated_terms, kernel_id=2, symmetric_rate=E.symmetric_truncated_rate,
    averaged=Averaged(H.TRUNCATED, H.truncated_coefficients, "spinviz's derivation from (2.5)"),
    line=LineLaw(LG.truncated_state, LG.truncated_drift, LG.truncated_law, "P ∝ f⁴", "(5.4)"),
    type_labels={"axial-stopped": "T1", "axial-spiral": "T2", "balanced-spiral": "Tcone", "transverse-spiral": "T4",
                 "libration": "T5", "transverse-frozen": "TF", "residual": "R"},
))
FREE = register(Model(
    name="free", equations="(2.3a)", summary="the torque-free Euler top (d = 0): nothing brakes",
    terms=E.free_terms, kernel_id=0, brakes=False,
))
