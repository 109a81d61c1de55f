"""The residual gas (physics.gas, physics.surface, integrators.collisions): the free-molecular
coefficients against the exact element forces, the sphere's damping rate 10 p / (pi rho a v_bar),
the box's and the rod's drag tensors against the surface quadrature and against a Monte Carlo of
single collisions, fluctuation and dissipation from the same gas (the impulses' second moment at
rest is 2 k T times the drag), a crystal left in the gas at the gas's rotational temperature, and
one collision's change of Omega against its kinetic-theory distribution."""

import math

import numpy as np
import pytest

from spinviz import units as U
from spinviz.integrators import collisions as CO
from spinviz.physics import gas as G
from spinviz.physics import presets as P
from spinviz.physics import surface as SUR
from spinviz.physics.bodies import Body, Shape

N2 = G.Gas("N2", float(U.pressure_from_mbar(1e-9)), 300.0)


def sphere_body(radius_cm=5e-6, density=1.3):
    """A solid sphere (CGS) with a small dipole: the gas's sphere."""
    I = 8.0 * math.pi * density * radius_cm**5 / 15.0
    return Body("sphere", "cgs", (I, I, I), (0.0, 0.0, 1e-18), shape=Shape("sphere", (2.0 * radius_cm,)),
                extra={"density": density})


def test_flux_integrals_are_the_integrals():
    """I_k(s) = int_0^oo y^k exp(-(y - s)^2) dy, k = 0..4, by quadrature, for faces moving into and
    away from the gas."""
    from scipy.integrate import quad

    for s in (-6.0, -2.0, -0.3, 0.0, 0.7, 3.0, 10.0):
        got = G.flux_integrals(np.array([s]))[:, 0]
        ref = [quad(lambda y, k=k, s=s: y**k * math.exp(-(y - s) ** 2), 0, np.inf, epsabs=0, epsrel=1e-13)[0]
               for k in range(5)]
        assert got == pytest.approx(ref, rel=1e-9), s


def test_linear_coefficients_are_the_slopes_of_the_exact_forces():
    """c_t = alpha m n v_bar / 4 and c_n = m n v_bar ((2 - alpha)/2 + alpha (pi/8) sqrt(T_b/T)) are the
    derivatives at rest of the exact element force (flux times the mean momentum handed over); at
    alpha = 1, T_b = T they are m n v_bar / 4 and m n v_bar (1/2 + pi/8)."""
    n = np.array([0.0, 0.0, 1.0])
    for gas in (N2, G.Gas("He", 1e-3, 77.0, 0.6, 300.0), G.Gas("Xe", 1e-3, 20.0, 0.0)):
        ct, cn = gas.linear_coefficients()
        h = 1e-6 * gas.mean_speed

        def force(u, gas=gas):
            flux, mean, _ = G.element_moments(gas, np.asarray(u, dtype=float), n)
            return gas.mass * flux * mean

        dn = (force([0, 0, h]) - force([0, 0, -h]))[2] / (2 * h)
        dt = (force([h, 0, 0]) - force([-h, 0, 0]))[0] / (2 * h)
        assert -dn == pytest.approx(cn, rel=1e-7) and -dt == pytest.approx(ct, rel=1e-7, abs=1e-30)
    mnv = N2.mass * N2.density * N2.mean_speed
    assert N2.linear_coefficients() == pytest.approx((mnv / 4, mnv * (0.5 + math.pi / 8)), rel=1e-14)


def test_sphere_brakes_at_ten_p_over_pi_rho_a_vbar():
    """On a sphere Omega x r is tangential at any speed: the drag is linear in Omega and brakes |L|
    at gamma = 10 p / (pi rho a v_bar), slow or far faster than the gas."""
    body = sphere_body()
    model = G.GasModel(N2, SUR.surface_of(body), body.inertia)
    a = 5e-6
    gamma = 10.0 * N2.pressure / (math.pi * 1.3 * a * N2.mean_speed)
    for spin in (1e6, 4e10, 1e12):
        assert model.damping_rate(np.array([0.3, -0.2, 0.9]) * spin) == pytest.approx(gamma, rel=1e-6)


@pytest.mark.parametrize("kind", ["box", "rod"])
def test_drag_tensors_of_a_box_and_a_rod(kind):
    """The written-out drag tensors K = c_t S + (c_n - c_t) T of a box (unequal edges) and a rod equal
    the surface quadrature of the exact element forces at a slow spin, for any accommodation and
    surface temperature."""
    for gas in (N2, G.Gas("He", 1e-6, 300.0, 0.4, 77.0)):
        ct, cn = gas.linear_coefficients()
        dims, surf = ((1e-5, 2e-5, 3e-5), SUR.box_surface(1e-5, 2e-5, 3e-5)) if kind == "box" else \
            ((3.15e-5, 3.15e-6), SUR.rod_surface(3.15e-5, 3.15e-6))
        K = G.linear_drag_tensor(kind, dims, ct, cn)
        model = G.GasModel(gas, surf, (1.0, 1.0, 1.0))
        spin = 1e-4 * gas.mean_speed / surf.r_max
        for axis in np.eye(3):
            assert -model.torque(axis * spin) / spin == pytest.approx(K @ axis, rel=1e-6, abs=1e-12 * K.max())


@pytest.mark.parametrize("shape", ["sphere", "box", "rod"])
@pytest.mark.parametrize("alpha", [1.0, 0.3])
def test_fluctuation_and_dissipation_come_from_one_gas(shape, alpha):
    """At rest the impulses' second moment per unit time is 2 k T times the drag tensor (the body at
    the gas's temperature): then the Fokker-Planck equation of L has the Boltzmann distribution at
    T as its steady state, <1/2 Omega.I Omega> = 3/2 k T."""
    gas = G.Gas("N2", 1e-3, 300.0, alpha)
    surf = {"sphere": SUR.sphere_surface(1e-5), "box": SUR.box_surface(1e-5, 2e-5, 3e-5),
            "rod": SUR.rod_surface(3.15e-5, 3.15e-6)}[shape]
    K = -np.stack([G.GasModel(gas, surf, (1, 1, 1)).torque(e * 1e-2 * gas.mean_speed / surf.r_max)
                   for e in np.eye(3)], axis=1) / (1e-2 * gas.mean_speed / surf.r_max)
    Q = G.GasModel(gas, surf, (1, 1, 1)).impulse_covariance(np.zeros(3))
    assert Q == pytest.approx(2.0 * U.K_BOLTZMANN * 300.0 * K, rel=2e-4, abs=1e-6 * np.abs(Q).max())


def test_one_collision_at_rest_against_kinetic_theory():
    """At a resting sphere a collision's J = m a n x (w_t - w'_t): each tangential component the
    difference of two Gaussians, so |Delta Omega| = |J| / I is Rayleigh with scale
    m a sqrt(kT/m + kT_b/m) / I (a Kolmogorov-Smirnov test of 4000 draws) and the rate is the wall
    flux n v_bar / 4 times the area."""
    from scipy import stats

    body = sphere_body()
    gas = G.Gas("N2", 1e-6, 300.0, 1.0, 77.0)
    col = CO.Collider(gas, SUR.surface_of(body), np.random.default_rng(4))
    J, tries = CO.many(col.rng, np.zeros(3), 4000, *col.args)
    assert tries == 4000                                    # at rest every candidate is kept
    a, I = 5e-6, body.I1
    scale = gas.mass * a * math.hypot(gas.sigma, gas.sigma_body) / I
    assert stats.kstest(np.linalg.norm(J, axis=1) / I, stats.rayleigh(scale=scale).cdf).pvalue > 0.01
    assert col.bound(0.0)[1] == pytest.approx(gas.wall_flux * 4 * math.pi * a * a, rel=1e-12)


@pytest.mark.parametrize("body", ["cube", "rod"])
def test_single_collisions_add_up_to_the_quadrature(body):
    """An independent Monte Carlo of single collisions (20 000 at the real spin, surfaces moving faster
    than the molecules): its rate, mean torque and impulse second moment agree with the gas's
    quadrature within their statistical errors."""
    b = P.dast_cube() if body == "cube" else P.cellulose_rod()
    surf = SUR.surface_of(b)
    omega = np.array([0.0, 3.14e10, 3.14e10]) if body == "cube" else np.array([3.14e9, 0.0, 3.14e10])
    gas = G.Gas("N2", 1e-6, 300.0, 0.8, 200.0)
    col = CO.Collider(gas, surf, np.random.default_rng(11))
    n = 20000
    J, tries = CO.many(col.rng, omega, n, *col.args)
    _, lam = col.bound(float(np.linalg.norm(omega)))
    rate, N, Q = G.GasModel(gas, surf, b.inertia).moments(omega)
    p = n / tries
    assert lam * p == pytest.approx(rate, rel=4.0 * math.sqrt((1 - p) / n))
    err = J.std(axis=0) / math.sqrt(n) * rate
    assert np.all(np.abs(J.mean(axis=0) * rate - N) < 4.0 * err + 1e-12 * np.abs(N).max())
    JJ = np.einsum("ki,kj->kij", J, J)
    err2 = JJ.std(axis=0) / math.sqrt(n) * rate
    assert np.all(np.abs(JJ.mean(axis=0) * rate - Q) < 4.0 * err2 + 1e-9 * np.abs(Q).max())


def test_a_crystal_left_in_the_gas_takes_its_temperature():
    """A 3 nm DAST cube (a spherical top: between collisions Omega stays) in N2 at 300 K, seen at the
    candidates of a fixed bound (uniformization: averages over them are averages over time), from
    rest at a tenth of the thermal spin: <1/2 Omega.I Omega> = 3/2 k T to 3 % (the draw, recoil-free,
    heats it by O(m a^2 / I) = 0.4 % here; 1e-7 for the 100 nm cube)."""
    body = P.dast_cube(3.0)
    gas = G.Gas("N2", 1e3, 300.0)
    col = CO.Collider(gas, SUR.surface_of(body), np.random.default_rng(8))
    I = np.asarray(body.inertia)
    w_th = math.sqrt(U.K_BOLTZMANN * 300.0 / I[0])
    s, _ = col.bound(8.0 * w_th)
    E, outside = CO.uniformized_walk(col.rng, np.array([0.0, 0.0, 0.1 * w_th]), I, 400_000, *col.args, s)
    assert outside == 0
    assert E / (1.5 * U.K_BOLTZMANN * 300.0) == pytest.approx(1.0, abs=0.03)


def test_knudsen_and_surfaces_are_required():
    """No gas for a body without a surface; the surfaces hold their areas."""
    from spinviz.errors import SpecError
    from spinviz.physics.bodies import custom

    with pytest.raises(SpecError, match="surface"):
        SUR.surface_of(custom((1e-26, 1e-26, 1e-26), (0, 0, 1e-10)))
    assert SUR.surface_of(P.dast_cube()).total_area == pytest.approx(6e-10, rel=1e-12)
    r = SUR.rod_surface(3.15e-5, 3.15e-6)
    assert r.total_area == pytest.approx(math.pi * 3.15e-6 * 3.15e-5 + 2 * math.pi * (1.575e-6) ** 2, rel=1e-12)
    for surf in (SUR.surface_of(P.dast_cube()), r, SUR.sphere_surface(1e-5)):
        _, _, w = surf.nodes(8)
        assert w.sum() == pytest.approx(surf.total_area, rel=1e-12)
