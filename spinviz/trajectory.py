"""The frozen result of a simulation: what the renderer, ``compare`` and the checks consume.

A ``Trajectory`` is in the units of its body ("cgs": t in s, Omega in rad/s;
"dimensionless": tau and omega of (4.1)).  ``sample(times)`` gives the state at any
times inside the run -- Omega by cubic Hermite interpolation with the model's own
Omega_dot at the nodes, orientation by slerp between stored quaternions -- so frames
never step the integrator.
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass, field, replace

import numpy as np

from . import rotations as R
from . import units as U
from .atomic import JsonTooDeep, atomic_path, loads_json, open_regular, plain
from .errors import SpecTypeError, TrajectoryFileError
from .physics import models as M
from .physics.bodies import Body
from .physics.equations import angular_momentum_world, kinetic_energy

SLOW_SERIES = ("phi_L", "theta_L", "psi_L")       # the time series of a ``slow`` record


def _frozen(a):
    if a is None:
        return None
    a = np.array(a, dtype=float, copy=True)
    a.flags.writeable = False
    return a


@dataclass(frozen=True)
class Trajectory:
    """The result of one run: states at the output instants, in the units of ``body``.

    Attributes
    ----------
    t : ndarray, shape (N,)
        Output instants, s (CGS) or tau0 (dimensionless).
    omega : ndarray, shape (N, 3)
        The body-frame angular velocity Omega, rad/s or 1/tau0; documented as ``omega_body``
        (``omega`` stays the field's name, the constructor's keyword and the saved array's).
    q : ndarray, shape (N, 4), or None
        Orientation as unit quaternions (w, x, y, z), scalar first, of O = R_world_from_body;
        None when no orientation was integrated.
    body : Body
    model : {"reduced", "truncated", "free"}
    euler : ndarray, shape (N, 3), or None
        ZXZ Euler angles (phi, theta, psi), rad, only when the Poisson equations (6.4) were
        integrated instead of quaternions.
    stats : dict
        method, nfev or nsteps, runtime_s, rtol, atol, ... and the error statements of
        ``secular``.
    slow : dict or None
        For ``secular`` runs, the slow geometry: q_L (4,) taking world z to the fixed
        L_world -- or (N, 4), one per instant, where a trap's gas or field moves L -- and (N,)
        arrays theta_L (nutation of e3 from L), phi_L (precession phase) and psi_L (spin
        phase), rad.

    Notes
    -----
    When ``phase_resolved`` is False the phases (and so q) are beyond float64 resolution:
    only theta_L, L and |Omega| are physical.
    """

    t: np.ndarray
    omega: np.ndarray
    q: np.ndarray | None
    body: Body
    model: str
    euler: np.ndarray | None = None
    stats: dict = field(default_factory=dict, compare=False)
    slow: dict | None = field(default=None, compare=False)

    def __post_init__(self):
        for name in ("t", "omega", "q", "euler"):
            object.__setattr__(self, name, _frozen(getattr(self, name)))
        n = self.t.shape[0]
        if self.omega.shape != (n, 3):
            raise ValueError(f"omega must have shape ({n}, 3), got {self.omega.shape}")
        if self.q is not None and self.q.shape != (n, 4):
            raise ValueError(f"q must have shape ({n}, 4), got {self.q.shape}")

    @property
    def omega_body(self) -> np.ndarray:
        """Body-frame angular velocity Omega, shape (N, 3), rad/s (CGS) or 1/tau0: the
        documented name of ``omega`` (which stays, as the field, the constructor's keyword and
        the saved array's name)."""
        return self.omega

    # -- units ---------------------------------------------------------------------------
    @property
    def units(self) -> str:
        """The body's unit system: "cgs" (t in s, Omega in rad/s) or "dimensionless" (tau, omega of
        (4.1))."""
        return self.body.units

    @property
    def tau0(self) -> float:
        """tau0 in s (CGS) or 1 (dimensionless)."""
        return self.body.tau0

    # -- derived series ------------------------------------------------------------------
    @property
    def phase_resolved(self) -> bool:
        """Whether the orientation's phases are physical: False when the run (``secular``)
        estimates them wrong by more than 1e-3 rad, when they went through the oscillating
        regime "5", or when float64 cannot hold them (> 1e-3 rad per ulp, as after 1e16 turns
        of a real DAST cube).  Then only the slow geometry -- L, theta_L, |Omega| and the range
        of angle(d, L) -- is physical."""
        return (bool(self.stats.get("phases_resolved", True))
                and float(self.stats.get("phase_resolution_rad", 0.0)) <= 1e-3)

    @property
    def euler_zxz(self) -> np.ndarray:
        """ZXZ Euler angles (phi, theta, psi), rad, unwrapped along time, shape (N, 3)."""
        if self.euler is not None:
            return np.array(self.euler)
        self._need_q("euler_zxz")
        return R.unwrap_euler_zxz(R.euler_zxz_from_quat(self.q))

    @property
    def omega_magnitude(self) -> np.ndarray:
        """|Omega|, shape (N,), rad/s (CGS) or 1/tau0: the same in every frame."""
        return np.linalg.norm(self.omega, axis=-1)

    def dipole_world(self) -> np.ndarray:
        """Unit dipole direction in the world frame, O d/|d|, shape (N, 3)."""
        self._need_q("dipole_world")
        return self.body.dipole_world(self.q)

    def angular_momentum_world(self) -> np.ndarray:
        """L_world = O I Omega, shape (N, 3) (g cm^2/s, or relative units)."""
        self._need_q("angular_momentum_world")
        return angular_momentum_world(self.q, self.omega, self.body.inertia)

    def omega_world(self) -> np.ndarray:
        """Angular velocity in the world frame, O Omega, shape (N, 3)."""
        self._need_q("omega_world")
        return R.world_from_body(self.q, self.omega)

    def energy(self) -> np.ndarray:
        """Kinetic energy 1/2 Omega . I Omega, shape (N,)."""
        return kinetic_energy(self.omega, self.body.inertia)

    def omega_dot(self) -> np.ndarray:
        """Omega_dot of the model at the stored states, shape (N, 3), in the body's units."""
        s = self.body.system(self.model)
        tau0 = self.tau0
        # d omega / d tau in (4.1) units, then d/dt = (1/tau0) d/dtau and Omega = omega / tau0
        return U.omega_from_dimensionless(s.omega_dot(U.omega_to_dimensionless(self.omega, tau0)), tau0) / tau0

    # -- radiation ----------------------------------------------------------------
    def radiation(self, line_of_sight=None):
        """The radiation observables of this run as an ``xarray.Dataset`` with units (erg, s,
        statC cm for CGS bodies; I1 and tau0 units for dimensionless ones): Larmor power, energy,
        Schott energy, dE/dt always; with orientation the world-frame dipole and its derivatives
        (from the state and the model's own Omega_dot, Omega_ddot), the flux of L (2.4a), the
        Schott-like term (2.4b), dL/dt and L; with a ``line_of_sight`` (world, 3-vector) the far
        field's two polarizations and dP/dOmega toward it.  See ``physics.radiation``.

        Where ``phase_resolved`` is False the world-frame directions of the fast vectors are not
        physical (the invariants, L and the power per solid angle averaged over a turn are).

        ``line_of_sight`` is checked by the schema (``inputs.base.Direction``: three finite
        numbers, not all zero; ``SpecError("line_of_sight", ...)``) before anything is computed."""
        from .inputs.trajectory import RadiationRequest

        line_of_sight = RadiationRequest(line_of_sight=line_of_sight).line_of_sight
        try:
            import xarray as xr
        except ImportError:
            raise ImportError("radiation() needs xarray: pip install 'spinviz[ensemble]'", name="xarray") from None
        from .physics.radiation import observables

        data = observables(self.body, self.model, self.omega, self.q, line_of_sight)
        tu = "s" if self.units == "cgs" else "tau0"
        coords = {"time": ("time", np.array(self.t), {"units": tu}), "xyz": ["x", "y", "z"],
                  "polarization": ["u1", "u2"]}
        ds = xr.Dataset(data, coords=coords)
        ds.attrs.update({"model": self.model, "body": self.body.name, "units": self.units,
                         "phase_resolved": int(self.phase_resolved),
                         "frames": "world (O = R(q) maps body to world), quaternions (w, x, y, z)"})
        return ds

    def radiated_power(self, averaged: bool = True) -> np.ndarray:
        """Larmor power P(t) = (2/3c^3)|d_ddot|^2, shape (N,), erg/s (CGS) or I1/tau0^3, from Omega
        and the model's own Omega_dot.  ``averaged``: for a symmetric top, averaged over the free
        precession (what a detector integrating over many turns sees, and physical also where the
        phase is not resolved); an asymmetric body's is always the instantaneous value."""
        from .physics import radiation as RA

        s = self.body.system(self.model)
        w = U.omega_to_dimensionless(self.omega, self.tau0)
        p = (RA.precession_averaged_power if averaged and self.body.is_symmetric else RA.larmor_power)(
            self.model, w, s.inertia, s.coupling)
        return U.radiation_from_dimensionless(p, "power", self.body.I1, self.tau0)

    def _need_q(self, what: str):
        if self.q is None:
            raise ValueError(f"{what} needs the orientation, which this run did not integrate")

    # -- resampling ----------------------------------------------------------------------
    def sample(self, times) -> Trajectory:
        """The trajectory at other instants, without integrating: Omega by cubic Hermite
        interpolation with the model's own Omega_dot at the nodes, q by slerp between stored
        orientations.

        Parameters
        ----------
        times : array_like, shape (M,)
            Finite instants within [t[0], t[-1]], in the run's time unit (s or tau0);
            ``SpecError("times", ...)`` otherwise (``SpecTypeError`` for what is not numbers).

        Returns
        -------
        Trajectory
            omega_body (M, 3) body frame, q (M, 4) (w, x, y, z); ``self`` when ``times`` are
            the stored instants.

        Notes
        -----
        Between stored instants this is only as good as the storage: slerp needs neighbours
        less than half a turn apart (the renderer stores every frame for that reason), and
        for a run whose spin phase is unresolved (``phase_resolved`` False) only the nodes
        and the slow geometry are meaningful: there Omega's slow parts -- |Omega_perp| and
        Omega3 -- are interpolated linearly and the direction of Omega_perp along the shorter
        arc, since Hermite steps with Omega_dot, which turns with the precession many times
        between such nodes, would not be Omega at all.
        """
        from .inputs.trajectory import SampleRequest

        t = self.t
        lo, hi = t[0], t[-1]
        times = SampleRequest(times=times, start=float(lo), end=float(hi)).times   # SpecError("times", ...)
        if times.shape == t.shape and np.array_equal(times, t):
            return self                     # already stored at these instants (the renderer's case)
        times = np.clip(times, lo, hi)
        if t.size == 1:
            omega = np.repeat(self.omega, times.size, axis=0)
        elif not self.phase_resolved:
            omega = _slow_omega(t, self.omega, times)
        else:
            i = np.clip(np.searchsorted(t, times, side="right") - 1, 0, t.size - 2)
            h = (t[i + 1] - t[i])[:, None]
            s = (times - t[i])[:, None] / h
            dw = self.omega_dot()
            h00, h10 = 2 * s**3 - 3 * s**2 + 1, s**3 - 2 * s**2 + s
            h01, h11 = -2 * s**3 + 3 * s**2, s**3 - s**2
            omega = h00 * self.omega[i] + h10 * h * dw[i] + h01 * self.omega[i + 1] + h11 * h * dw[i + 1]
        q = None if self.q is None else R.slerp_series(t, self.q, times)
        euler = None
        if self.euler is not None:
            euler = np.stack([np.interp(times, t, self.euler[:, k]) for k in range(3)], axis=-1)
        slow = None
        if self.slow is not None:
            slow = {k: (np.interp(times, t, v) if k in SLOW_SERIES else v) for k, v in self.slow.items()}
            q_L = np.asarray(self.slow.get("q_L", ()), dtype=float)
            if q_L.ndim == 2:                   # L moves over the run (a trap's gas or field): one per instant
                slow["q_L"] = R.slerp_series(t, q_L, times)
        return replace(self, t=times, omega=omega, q=q, euler=euler, slow=slow)

    # -- people and notebooks ------------------------------------------------------------
    def __repr__(self) -> str:
        w = self.omega_magnitude
        tu, wu = ("s", "rad/s") if self.units == "cgs" else ("tau0", "1/tau0")
        orient = "quaternion" if self.q is not None else ("euler_zxz (6.4)" if self.euler is not None else "none")
        method = self.stats.get("method", "?")
        return (f"Trajectory({self.model}, {self.body.name!r}, {self.t.size} samples, t = 0..{self.t[-1]:.4g} {tu}, "
                f"|omega| {w[0]:.4g} -> {w[-1]:.4g} {wu}, orientation: {orient}, method: {method})")

    def angle_d_L(self) -> np.ndarray:
        """Angle between the dipole and the angular momentum, rad, shape (N,).  A body-frame
        quantity (d . I Omega), so it needs no orientation."""
        L_body = np.asarray(self.body.inertia, dtype=float) * self.omega
        return R.angle_between(np.broadcast_to(self.body.dipole_direction, L_body.shape), L_body)

    def angle_d_L_range(self) -> tuple[np.ndarray, np.ndarray]:
        """(lowest, highest) angle between d and L over one free precession turn, rad, (N,) each.

        For a symmetric top L_body = (w1, w2, J3 w3) turns about e3 at the fixed nutation
        theta_L = atan2(|w_perp|, J3 w3) while d sits at chi from e3, so the angle sweeps
        [|theta_L - chi|, theta_L + chi] (folded into [0, pi]) whatever the precession phase:
        it needs only the slow variables, so it is exact also where the phase is averaged
        (``secular``).  For an asymmetric body L runs round the polhode through Omega (the
        Euler-Poinsot motion, ``physics.polhode``): the range is taken over it, again whatever
        the phase (``polhode``); on the separatrix itself, the instantaneous angle twice."""
        if not self.body.is_symmetric:
            from .physics import polhode as PH

            a = self.angle_d_L()
            lo, hi = a.copy(), a.copy()
            J, d = tuple(float(x) for x in self.body.inertia), self.body.dipole_direction
            for i, w in enumerate(self.omega):
                try:
                    lo[i], hi[i] = PH.angle_range(PH.polhode_of(J, w), d)
                except PH.NoPolhode:
                    pass
            return lo, hi
        J3 = self.body.I3 / self.body.I1
        theta_L = np.arctan2(np.hypot(self.omega[:, 0], self.omega[:, 1]), J3 * self.omega[:, 2])
        chi = self.body.chi
        hi = theta_L + chi
        return np.abs(theta_L - chi), np.where(hi > np.pi, 2.0 * np.pi - hi, hi)

    def plot(self, path: str | None = None):
        """|Omega|(t), the angle between d and L, and the hodograph of Omega (body frame), as a
        matplotlib figure; also written to ``path`` (PNG) when given."""
        from .plotting import plot_trajectory

        return plot_trajectory(self, path)

    def to_xarray(self):
        """An ``xarray.Dataset`` with labelled dims (time, axis, quaternion component), units
        and the run's metadata as attributes -- ready for ``to_netcdf`` or ``to_zarr``."""
        try:
            import xarray as xr
        except ImportError:
            raise ImportError("to_xarray needs xarray: pip install 'spinviz[ensemble]'", name="xarray") from None
        tu, wu = ("s", "rad/s") if self.units == "cgs" else ("tau0", "1/tau0")
        data = {"omega": (("time", "axis"), np.array(self.omega),
                          {"units": wu, "long_name": "angular velocity, body frame"})}
        if self.q is not None:
            data["q"] = (("time", "quaternion_component"), np.array(self.q),
                         {"long_name": "orientation, body to world", "convention": "scalar first (w, x, y, z)"})
        if self.q is not None or self.euler is not None:
            data["euler_zxz"] = (("time", "euler_angle"), self.euler_zxz,
                                 {"units": "rad", "convention": "ZXZ, O = Rz(phi) Rx(theta) Rz(psi), unwrapped"})
        data["angle_d_L"] = (("time",), self.angle_d_L(), {"units": "rad", "long_name": "angle between d and L"})
        coords = {"time": ("time", np.array(self.t), {"units": tu}), "axis": ["e1", "e2", "e3"],
                  "quaternion_component": ["w", "x", "y", "z"], "euler_angle": ["phi", "theta", "psi"]}
        ds = xr.Dataset(data, coords=coords)
        ds.attrs.update({"spinviz_trajectory": json.dumps(self.metadata()), "model": self.model,
                         "body": self.body.name, "units": self.units})
        return ds

    # -- files -----------------------------------------------------------------------------
    def arrays(self) -> dict[str, np.ndarray]:
        """The arrays ``save`` writes: t, omega, q and euler_zxz (derived, for convenience)
        when orientation exists; the raw Euler-angle solution and the slow geometry of a
        ``secular`` run when present."""
        out = {"t": np.array(self.t), "omega": np.array(self.omega)}
        if self.q is not None:
            out["q"] = np.array(self.q)
        if self.q is not None or self.euler is not None:
            out["euler_zxz"] = self.euler_zxz
        if self.euler is not None:
            out["euler"] = np.array(self.euler)
        for k, v in (self.slow or {}).items():
            out[f"slow_{k}"] = np.asarray(v, dtype=float)
        return out

    def metadata(self) -> dict:
        """The JSON record saved beside the arrays (``save``): format, units, conventions
        (quaternion order, Euler convention), model, body and its full description, and stats."""
        b = self.body
        return {
            "format": FORMAT,
            "units": self.units,
            "time_unit": "s" if self.units == "cgs" else "tau0",
            "omega_unit": "rad/s" if self.units == "cgs" else "1/tau0",
            "quaternion_order": "w, x, y, z (scalar first); O = R(q) maps body to world",
            "euler_convention": "ZXZ, O = Rz(phi) Rx(theta) Rz(psi), rad, unwrapped",
            "model": self.model,
            "body": b.name,
            "inertia": list(b.inertia),
            "dipole": list(b.dipole),
            "tau0_s": b.tau0 if self.units == "cgs" else None,
            "body_description": b.to_dict(),
            "stats": _plain_stats(self.stats),
        }

    def save(self, path, radiation: bool = False) -> None:
        """Write the arrays and a JSON ``metadata`` entry (.npz), atomically (temp file + rename).
        ``Trajectory.load`` reads it back exactly.  ``radiation``: also the observables of
        ``physics.radiation.observables`` as ``radiation_<name>`` arrays, their units and dims in
        ``metadata["radiation"]`` (``spinviz simulate`` writes them).  An ``OSError`` (a full
        disk, no permission) names the path."""
        if not isinstance(path, (str, os.PathLike)):
            raise SpecTypeError("path", f"must be a file path (str or os.PathLike), got {type(path).__name__}")
        meta, arrays = self.metadata(), self.arrays()
        if radiation:
            from .physics.radiation import observables

            data = observables(self.body, self.model, self.omega, self.q)
            arrays.update({f"radiation_{k}": np.asarray(v, dtype=float) for k, (_, v, _) in data.items()})
            meta["radiation"] = {k: {"dims": list(dims), **a} for k, (dims, _, a) in data.items()}
        try:
            with atomic_path(path) as tmp, open(tmp, "wb") as fh:
                np.savez(fh, metadata=np.array(json.dumps(meta)), **arrays)
        except OSError as e:
            if e.filename is None:
                e.filename = os.fspath(path)
            raise

    save_npz = save

    @classmethod
    def load(cls, path) -> Trajectory:
        """A trajectory written by ``save`` (or ``spinviz simulate --out``): arrays, body, model,
        stats and slow geometry as they were.

        Raises ``TrajectoryFileError`` (a ValueError naming the file) for a file that is missing,
        unreadable, damaged or not a spinviz trajectory, and at once for a path that is not a
        regular file (a directory, FIFO, device or socket); never a zip, JSON or NumPy error."""
        if not isinstance(path, (str, bytes, os.PathLike)):
            raise SpecTypeError("path", f"must be the path of a .npz trajectory, got {type(path).__name__}")
        path = os.fsdecode(path)
        try:
            # a regular file only: a FIFO or a device is refused at once, never waited on
            with open_regular(path) as fh, np.load(fh, allow_pickle=False) as z:
                if not hasattr(z, "files"):
                    raise TrajectoryFileError(path, "a single NumPy array, not a spinviz trajectory (.npz)")
                if "metadata" not in z.files:
                    raise TrajectoryFileError(path, "not a spinviz trajectory (no metadata entry)")
                size = z.zip.getinfo("metadata.npy").file_size
                if size > MAX_METADATA_BYTES:
                    raise TrajectoryFileError(path, f"metadata of {size} bytes; a trajectory's are at most "
                                                    f"{MAX_METADATA_BYTES}")
                meta = loads_json(str(z["metadata"]))
                if not isinstance(meta, dict) or meta.get("format") != FORMAT:
                    raise TrajectoryFileError(path, f"not a spinviz trajectory of format {FORMAT!r}")
                arrays = {k: np.array(z[k]) for k in z.files if k != "metadata"}
        except TrajectoryFileError:
            raise
        except JsonTooDeep as e:
            raise TrajectoryFileError(path, f"metadata {e}") from None
        except FileNotFoundError:
            raise TrajectoryFileError(path, "no such file") from None
        except OSError as e:
            raise TrajectoryFileError(path, e.strerror or str(e)) from None
        except Exception as e:         # zip, zlib, EOF, JSON, pickle refusal: the file is damaged
            raise TrajectoryFileError(path, f"damaged or not a spinviz trajectory (.npz): {type(e).__name__}") from None
        return cls._from_file(path, meta, arrays)

    @classmethod
    def _from_file(cls, path: str, meta: dict, arrays: dict) -> Trajectory:
        """The trajectory of a read file, every part checked (``TrajectoryFileError`` names what is wrong)."""
        for k in ("t", "omega"):
            if k not in arrays:
                raise TrajectoryFileError(path, f"damaged: the array {k!r} is missing")
        for k in ("t", "omega", "q", "euler"):
            a = arrays.get(k)
            if a is not None and (a.dtype.kind not in "fiu" or not np.all(np.isfinite(a))):
                raise TrajectoryFileError(path, f"damaged: the array {k!r} is not finite numbers")
        t = arrays["t"]
        if t.ndim != 1 or t.size < 1 or np.any(np.diff(t) <= 0.0):
            raise TrajectoryFileError(path, "damaged: the times 't' are not increasing")
        try:
            body = Body.from_dict(meta["body_description"])
            model = meta["model"]
            stats = dict(meta["stats"])
        except Exception as e:         # KeyError, TypeError, BodyError: the metadata is damaged
            raise TrajectoryFileError(path, f"damaged metadata: {type(e).__name__} {e}") from None
        if model not in M.names():
            raise TrajectoryFileError(path, f"damaged metadata: unknown model {model!r}")
        slow = {k[5:]: v for k, v in arrays.items() if k.startswith("slow_")} or None
        try:
            return cls(t=t, omega=arrays["omega"], q=arrays.get("q"), euler=arrays.get("euler"), body=body, model=model,
                       stats=stats, slow=slow)
        except ValueError as e:
            raise TrajectoryFileError(path, f"damaged: {e}") from None


FORMAT = "spinviz-trajectory-1"
MAX_METADATA_BYTES = 16_000_000      # a trajectory's metadata (body, stats, slow geometry's labels) are a few kB


def _plain_stats(stats: dict) -> dict:
    """``stats`` as JSON-ready values (so that ``load`` gives back what ``save`` was given)."""
    return {k: v for k, v in plain(stats).items() if isinstance(v, (int, float, str, bool, type(None), list, dict))}


def radiated_power(trajectories, times=None) -> dict[str, np.ndarray]:
    """P(t) of each trajectory by model, {model: (M,) array} (``Trajectory.radiated_power``,
    precession-averaged), at ``times`` (sampled, no integration) or at the stored instants: the
    numbers a plot or a video inset of the radiated power draws for both models."""
    out = {}
    for tr in trajectories:
        out[tr.model] = (tr if times is None else tr.sample(times)).radiated_power()
    return out


def _slow_omega(t, omega, times) -> np.ndarray:
    """omega (body frame) at ``times`` from nodes (t, omega) whose precession phase is not
    resolved: |omega_perp| and omega3 linear in t, the direction of omega_perp across e3 along
    the shorter arc between the nodes' (the phase itself is not the run's)."""
    wp = np.hypot(omega[:, 0], omega[:, 1])
    ang = np.arctan2(omega[:, 1], omega[:, 0])
    i = np.clip(np.searchsorted(t, times, side="right") - 1, 0, t.size - 2)
    s = (times - t[i]) / (t[i + 1] - t[i])
    turn = np.remainder(ang[i + 1] - ang[i] + np.pi, 2.0 * np.pi) - np.pi
    a = ang[i] + s * turn
    p = wp[i] + s * (wp[i + 1] - wp[i])
    return np.stack([p * np.cos(a), p * np.sin(a), omega[i, 2] + s * (omega[i + 1, 2] - omega[i, 2])], axis=-1)
