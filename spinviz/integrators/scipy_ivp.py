"""scipy.integrate.solve_ivp methods (RK45, DOP853, Radau, BDF, LSODA) behind ``Integrator``.

The right-hand side is the component-wise ``System.rhs`` (Python floats, no NumPy
per-call overhead on 3-vectors); the implicit methods get the exact Jacobian
``System.rhs_jacobian`` instead of finite differences.
"""

from __future__ import annotations

import numpy as np

from ..physics.equations import euler_zxz_rate
from .base import Integrator, Problem, Solution, register
from .status import runaway_bound


def _euler_rhs(system):
    rate = system.rate()

    def f(t, y):
        w1, w2, w3, phi, theta, psi = y.tolist()
        a = rate(w1, w2, w3)
        e = euler_zxz_rate(phi, theta, psi, w1, w2, w3)
        return np.array((a[0], a[1], a[2], e[0], e[1], e[2]))

    return f


def _omega_rhs(system):
    rate = system.rate()

    def f(t, y):
        return np.array(rate(*y.tolist()))

    return f


def build_ivp(problem: Problem):
    """(fun, jac, y0) of the first-order system for ``problem.kinematics``."""
    s = problem.system
    w0 = np.asarray(problem.omega0, dtype=float)
    if problem.kinematics == "quaternion":
        return s.rhs(), s.rhs_jacobian(), np.concatenate([w0, np.asarray(problem.q0, dtype=float)])
    if problem.kinematics == "euler_zxz":
        return _euler_rhs(s), None, np.concatenate([w0, np.asarray(problem.euler0, dtype=float)])
    if problem.kinematics == "none":
        return _omega_rhs(s), (lambda t, y: s.jacobian(y)), w0.copy()
    raise ValueError(f"unknown kinematics {problem.kinematics!r}")


def split_state(problem: Problem, y: np.ndarray) -> dict:
    """State array (N, k) -> omega, q, euler by ``problem.kinematics``."""
    out = {"omega": y[:, :3], "q": None, "euler": None}
    if problem.kinematics == "quaternion":
        out["q"] = y[:, 3:7]
    elif problem.kinematics == "euler_zxz":
        out["euler"] = y[:, 3:6]
    return out


def _make_solver(method: str, implicit: bool):
    def solve(problem: Problem, rtol: float = 1e-10, atol: float = 1e-12, step: float | None = None, fun=None) -> Solution:
        f, jac, y0 = build_ivp(problem)
        if fun is not None:        # a caller-supplied right-hand side (the benchmark baseline)
            f, jac = fun, None
        t = np.asarray(problem.t_eval, dtype=float)
        kw = {"rtol": rtol, "atol": atol}
        if implicit and jac is not None:
            kw["jac"] = jac
        if step is not None:
            kw["max_step"] = step
        from scipy.integrate import solve_ivp

        w_max = runaway_bound(float(np.dot(problem.system.coupling, problem.system.coupling)))

        def runaway(s, y):
            return float(y[0] * y[0] + y[1] * y[1] + y[2] * y[2]) - w_max * w_max

        runaway.terminal = True
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
            res = solve_ivp(f, (t[0], t[-1]), y0, method=method, t_eval=t, events=runaway, **kw)
        ok = res.status == 0 and res.y.shape[1] == t.size and bool(np.all(np.isfinite(res.y)))
        y = res.y.T if ok else np.full((t.size, y0.size), np.nan)
        if ok:
            y[0] = y0
        parts = split_state(problem, y)
        stats = {"method": method.lower(), "nfev": int(res.nfev), "njev": int(res.njev), "nlu": int(res.nlu)}
        message = "" if ok else f"solve_ivp({method}) failed: {res.message}"
        if res.status == 1 and res.t_events[0].size:
            stats.update(runaway_at=float(res.t_events[0][0]), runaway_omega=res.y_events[0][0][:3].tolist())
            message = "the solution runs away"
        return Solution(t=t, success=ok, message=message, stats=stats, **parts)

    return solve


_DESCRIPTIONS = {
    "RK45": "scipy Dormand-Prince 5(4), adaptive",
    "DOP853": "scipy Dormand-Prince 8(5,3), adaptive; also integrates the Euler-angle kinematics (6.4)",
    "Radau": "scipy implicit Radau IIA order 5, exact Jacobian; for stiff runs",
    "BDF": "scipy variable-order BDF, exact Jacobian; for stiff runs",
    "LSODA": "scipy LSODA, switches between Adams and BDF automatically, exact Jacobian",
}
_ORDERS = {"RK45": 5, "DOP853": 8, "Radau": 5, "BDF": None, "LSODA": None}
# Below these rtol the orientation error stops following the tolerance (measured on 400 turns of
# an askew asymmetric body at tau0 |Omega0| = 1e-2 and 1e-8, spinviz bench; DOP853's is SciPy's
# own lower limit, 100 machine epsilons): radau stalls at ~2e-11 rad, lsoda at ~1e-8.
_FLOORS = {"RK45": 1e-13, "DOP853": 2.2e-14, "Radau": 1e-10, "BDF": 1e-12, "LSODA": 1e-10}

for _m, _implicit in (("RK45", False), ("DOP853", False), ("Radau", True), ("BDF", True), ("LSODA", True)):
    register(
        Integrator(
            name=_m.lower(),
            order=_ORDERS[_m],
            fixed_step=False,
            solve=_make_solver(_m, _implicit),
            description=_DESCRIPTIONS[_m],
            kinematics=("quaternion", "euler_zxz", "none"),
            stiff=_implicit,
            rtol_floor=_FLOORS[_m],
        )
    )
