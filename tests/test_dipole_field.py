"""The whole field of a point dipole (physics.dipole_field) against closed forms at R << lambda,
R ~ lambda and R >> lambda, and the line (phasor) form against the time-domain retarded form."""

import math

import numpy as np
import pytest

from spinviz.physics import dipole_field as DF

C = 2.99792458e10          # cm/s
F = 7.0710678e9            # Hz: the DAST cube's line at the start
W = 2 * math.pi * F
K = W / C
LAM = C / F
P0 = 5.6e7 * 1e-18         # statC cm: a 5.6e7 D dipole turning in the x-y plane


def rotating(t):
    """p(t) = P0 (cos wt, sin wt, 0) and its first two derivatives, (N, 3) each."""
    c, s, z = np.cos(W * t), np.sin(W * t), np.zeros_like(t)
    return (P0 * np.stack([c, s, z], -1), P0 * W * np.stack([-s, c, z], -1), -P0 * W**2 * np.stack([c, s, z], -1))


P_AMP = 0.5 * P0 * np.array([1.0, -1.0j, 0.0])      # p(t) = 2 Re(P_AMP exp(i w t))


@pytest.mark.parametrize("kr", [1e-3, 0.5, 1.0, 2 * math.pi, 50.0, 1e4])
@pytest.mark.parametrize("n", [(1.0, 0.0, 0.0), (0.0, 0.0, 1.0), (0.6, 0.0, 0.8)])
def test_line_form_is_the_retarded_field(kr, n):
    """2 Re(E~ exp(i w t)) from ``line_field`` equals the time-domain sum of the three terms with
    p, p_dot, p_ddot at the retarded time t - R/c, at every instant of a turn, to round-off (the
    retarded phase w (t - R/c) is kR radians and carries kR ulps: hence the 1e-15 kR)."""
    R = kr / K
    n = np.array(n)
    t = np.linspace(0.0, 1.0 / F, 13)
    E_time = DF.retarded_field(*rotating(t - R / C), n, R, C)
    E_line = 2.0 * np.real(DF.line_field(P_AMP, n, R, K)[None, :] * np.exp(1j * W * t)[:, None])
    scale = np.max(np.linalg.norm(E_time, axis=1))
    assert np.max(np.abs(E_line - E_time)) < (1e-12 + 1e-15 * kr) * scale


def test_near_zone_is_the_static_dipole_field():
    """At R << lambda the field is the instantaneous dipole field [3 n (n.p) - p] / R^3: the
    amplitude differs from it by the induction term, first order in kR (and in quadrature), so
    its size by O((kR)^2)."""
    n = np.array([0.6, 0.0, 0.8])
    vec, size = [], []
    for kr in (1e-2, 1e-3):
        R = kr / K
        static = (3.0 * n * (n @ P_AMP) - P_AMP) / R**3
        full = DF.line_field(P_AMP, n, R, K) * np.exp(1j * K * R)           # the retardation phase aside
        vec.append(np.linalg.norm(full - static) / np.linalg.norm(static))
        size.append(abs(DF.rms(full[None, None, :]) / DF.rms(static[None, None, :]) - 1.0))
    assert vec[1] == pytest.approx(1e-3, rel=1e-3) and vec[0] / vec[1] == pytest.approx(10.0, rel=1e-3)
    assert size[1] < 1e-6 and size[0] / size[1] == pytest.approx(100.0, rel=1e-2)


def test_radiation_zone_is_the_radiation_term():
    """At R >> lambda the field is k^2 p_perp / R, the far field the paper's Larmor power rests on;
    the rest falls as 1/(kR)."""
    n = np.array([1.0, 0.0, 0.0])
    errors = []
    for kr in (1e3, 1e4):
        R = kr / K
        far = DF.line_terms(P_AMP, n, R, K)["radiation"]
        errors.append(np.linalg.norm(DF.line_field(P_AMP, n, R, K) - far) / np.linalg.norm(far))
    assert errors[1] < 2.5e-4
    assert errors[0] / errors[1] == pytest.approx(10.0, rel=1e-3)           # first order in 1/(kR)


@pytest.mark.parametrize("R", [LAM / (2 * math.pi), LAM, 2.4 * LAM])
def test_on_the_axis_at_a_wavelength(R):
    """On the rotation axis the field of a rotating dipole is circular with the closed-form size
    |E| = P0 |k^2/R - 1/R^3 - i k/R^2| at every instant (n . p = 0): at kR = 1 the 1/R and 1/R^3
    terms cancel and only the induction term is left."""
    n = np.array([0.0, 0.0, 1.0])
    t = np.linspace(0.0, 1.0 / F, 9)
    E = DF.retarded_field(*rotating(t - R / C), n, R, C)
    expected = P0 * abs(K**2 / R - 1.0 / R**3 - 1j * K / R**2)
    assert np.allclose(np.linalg.norm(E, axis=1), expected, rtol=1e-12, atol=0)
    assert DF.rms(DF.line_field(P_AMP, n, R, K)[None, None, :]) == pytest.approx(expected, rel=1e-12)


def test_zones_at_their_boundaries():
    lam = np.array([10.0, 10.0, 10.0, 10.0])
    R = np.array([1.0, 10.0 / (2 * math.pi), 9.99, 10.0])
    assert [DF.zone(r, 10.0).item() for r in R] == ["near", "intermediate", "intermediate", "radiation"]
    assert DF.zone(1.0, lam).tolist() == ["near"] * 4
