"""Splitting integrators, the half-turn guard of the Lie methods, compensated summation."""

import math

import numpy as np
import pytest

from spinviz import rotations as R
from spinviz.driver import simulate
from spinviz.physics import bodies as B
from spinviz.physics import closed_forms as CF

SPHERE = B.symmetric_top(0.0, 0.0)


def errors_6_10(method, steps, w=0.3, periods_T=2.0):
    """Orientation error at periods_T T against (6.10), for each step (T/m exactly)."""
    w2 = w3 = w / math.sqrt(2.0)
    T = 1.0 / w2**2
    out = []
    for h in steps:
        tr = simulate(SPHERE, "truncated", (0.0, w2, w3), t_end=periods_T * T, samples=2,
                      euler_zxz0=(0.0, math.pi / 4, 0.0), method=method, step=h)
        exact = R.quat_from_euler_zxz(CF.euler_eq6_10(tr.t, 1.0, w2, w3))
        out.append(R.misorientation(tr.q, exact).max())
    return np.array(out), T


@pytest.mark.parametrize("method,order,m", [("split2", 2, (8, 16, 32)), ("split4", 4, (8, 16, 32)),
                                            ("split6", 6, (16, 32)), ("split8", 8, (10, 14, 20))])
def test_splitting_earns_its_order_against_6_10(method, order, m):
    """Composition of the exact free flow with the radiation flow: slope of log(error) vs
    log(h) against the exact (6.10); steps are fractions of the braking time T (errors
    between 1e-2 and 1e-12; orders 6 and 8 measured in their asymptotic range)."""
    _, T = errors_6_10(method, [1.0])
    steps = [2.0 * T / k for k in m]
    errs, _ = errors_6_10(method, steps)
    slope = np.polyfit(np.log(steps), np.log(errs), 1)[0]
    assert abs(slope - order) < 0.5, (errs, slope)


def test_splitting_step_is_set_by_braking_not_spin():
    """(6.10) over 1e5 turns with 120 steps (T/40): the exact free flow carries every turn,
    and compensated summation keeps the phase (6e5 rad) to < 1e-9 rad."""
    turns = 1e5
    w = 2.0 * (math.sqrt(7.0) - 1.0) / (2.0 * math.pi * turns)
    w2 = w / math.sqrt(2.0)
    T = 1.0 / w2**2
    tr = simulate(SPHERE, "truncated", (0.0, w2, w2), t_end=3.0 * T, samples=11, euler_zxz0=(0.0, math.pi / 4, 0.0),
                  method="split8", step=T / 40)
    assert tr.stats["nsteps"] == 120
    exact = R.quat_from_euler_zxz(CF.euler_eq6_10(tr.t, 1.0, w2, w2))
    assert R.misorientation(tr.q, exact).max() < 1e-9


def test_splitting_needs_a_symmetric_top():
    body = B.custom((1.0, 0.8, 0.5), (0.0, 0.0, 1.0), units="dimensionless")
    with pytest.raises(ValueError, match="needs a symmetric top"):
        simulate(body, "reduced", (0.1, 0.1, 0.1), t_end=10.0, samples=3, method="split8", step=1.0)


def test_taylor_resolves_every_turn_of_6_10():
    """On (6.10) the body turns about a fixed axis at a steady rate: the quaternion's Taylor
    series converges only within ~a radian of spin, so Taylor's method takes at least a step a
    turn (measured ~2.6) and stays exact to 1e-9 rad."""
    w2 = 0.02 / math.sqrt(2.0)
    T = 1.0 / w2**2
    tr = simulate(SPHERE, "truncated", (0.0, w2, w2), t_end=2.0 * T, samples=2, euler_zxz0=(0.0, math.pi / 4, 0.0),
                  rtol=1e-10, atol=1e-12)
    turns = CF.euler_eq6_10(tr.t, 1.0, w2, w2)[-1, 0] / (2 * math.pi)
    assert tr.stats["nsteps"] >= turns
    assert R.misorientation(tr.q, R.quat_from_euler_zxz(CF.euler_eq6_10(tr.t, 1.0, w2, w2))).max() < 1e-9


def test_compensated_summation_keeps_the_low_bits():
    """add_compensated: a million additions of 1e-10 to 1 give 1 + 1e-4 to the last bit,
    where plain addition drifts by ~1e-13 (the effect that, integrated over 1e4 turns,
    cost 5e-8 rad of spin phase before the kernels used it)."""
    from spinviz.integrators.kernels import add_compensated

    y, err = np.array([1.0]), np.zeros(1)
    plain = 1.0
    for _ in range(1_000_000):
        add_compensated(y, 0, 1e-10, err)
        plain += 1e-10
    exact = 1.0001
    assert abs(y[0] + err[0] - exact) <= 2.3e-16
    assert abs(plain - exact) > 1e-14
