"""The one line of a top with d along its axis (physics.longitudinal): its state from (5.2) and
(5.4) against the paper's closed forms as written, the P-f laws it implies, and which tops have them."""

import math

import numpy as np
import pytest

from spinviz.physics import closed_forms as CF
from spinviz.physics import longitudinal as LG
from spinviz.physics import models as M

W = math.pi * 1e10


@pytest.mark.parametrize("delta,w20,w30", [(0.0, W, W), (0.985, W, W), (-0.6, 0.3 * W, 1.7 * W), (0.4, W, 1e-3 * W)])
def test_state_is_the_closed_forms_5_2_and_5_4(delta, w20, w30):
    """u = Omega_perp^2 and b = eps^2 Omega3^2 from ``state`` against CF.omega_eq5_2 / eq5_4
    (dimensionless, written as the paper prints them) over five decades of time, to 1e-12."""
    tau0 = 3.4e-27
    eps = 1.0 - delta
    t = np.geomspace(1e-3, 1e3, 25) / (tau0 * (w20**2 + w30**2))
    u0, b0 = w20**2, eps**2 * w30**2
    for model, cf in (("reduced", CF.omega_eq5_2), ("truncated", CF.omega_eq5_4)):
        u, b = M.get(model).line.state(t, u0, b0, tau0)
        with np.errstate(over="ignore"):                         # expm1 overflows where u -> 0
            w = cf(t / tau0, delta, w20 * tau0, w30 * tau0) / tau0
        assert np.allclose(u, w[:, 0] ** 2 + w[:, 1] ** 2, rtol=1e-12, atol=0), model
        assert np.allclose(b, eps**2 * w[:, 2] ** 2, rtol=1e-12, atol=0), model


def test_sphere_is_6_7_and_6_9():
    """The spherical top (eps = 1) in CGS: (6.7) reduced, (6.9) truncated."""
    tau0 = 3.4e-27
    t = np.geomspace(1.0, 1e7, 30)
    u, b = LG.reduced_state(t, W**2, W**2, tau0)
    w = CF.omega_eq6_7(t, tau0, W, W)
    assert np.allclose(np.sqrt(u), w[:, 1], rtol=1e-12, atol=0) and np.allclose(np.sqrt(b), w[:, 2], rtol=1e-15)
    u, b = LG.truncated_state(t, W**2, W**2, tau0)
    w = CF.omega_eq6_9(t, tau0, W, W)
    assert np.allclose(np.sqrt(u), w[:, 1], rtol=1e-12, atol=0) and np.allclose(np.sqrt(b), w[:, 2], rtol=1e-12)


@pytest.mark.parametrize("model", M.with_line_law())
def test_power_follows_its_law_along_the_run(model):
    """Eliminating t: the power shape Omega_perp^2 omega_L^2 over the law (f^4, or f^2 (f^2 - f_inf^2)
    with f_inf = sqrt(b0)/2 pi) is the same constant at every time -- and not under the other law.
    (To 1.3 Theta: later f^2 - f_inf^2 = u/4 pi^2 is a difference of nearly equal numbers.)"""
    tau0 = 3.4e-27
    u0, b0 = 0.8 * W**2, 1.3 * W**2
    t = np.geomspace(1.0, 3e5, 40)
    f, shape = M.get(model).line.line(t, u0, b0, tau0)
    f_inf = math.sqrt(b0) / (2 * math.pi)
    own = shape / M.get(model).line.law(f, f_inf)
    other = shape / M.get("truncated" if model == "reduced" else "reduced").line.law(f, f_inf)
    assert np.ptp(own) / own.mean() < 1e-12
    assert np.ptp(other) / other.mean() > 0.1


def test_which_tops_have_the_law():
    assert LG.has_line_law(0.985, 0.0, True) and LG.has_line_law(0.0, 0.7, True) and LG.has_line_law(0.3, math.pi, True)
    assert not LG.has_line_law(0.3, 0.7, True) and not LG.has_line_law(0.0, 0.0, False)


def test_start_state_splits_omega_about_the_dipole():
    u0, b0 = LG.start_state([3.0, 0.0, 4.0], [0.0, 0.0, 1.0], 0.5)
    assert (u0, b0) == (9.0, 0.25 * 16.0)
