"""The receiver (analysis.receiver): its Cramer-Rao bounds against Monte Carlo of noisy tones and
chirps, its detection threshold against simulated periodograms, and its budget of the DAST
cube against closed forms (received power, SNR, the field at the antenna in all its terms)."""

import math

import numpy as np
import pytest

from spinviz import units as U
from spinviz.analysis import receiver as RC
from spinviz.errors import SpecError
from spinviz.inputs.receiver import ReceiverSpec

N = 256                      # samples of one interval, at 1 sample per unit time: T = N
TRIALS = 400                 # the std of an estimate comes to ~1/sqrt(2 TRIALS) = 3.5 %


def fit_sinusoid(x, t, f0, fdot0=None, iterations=8):
    """Least-squares (= maximum-likelihood in white noise) estimates of f (and f_dot) of
    a cos(theta) + b sin(theta), theta = 2 pi f t (+ pi f_dot t^2), per row of x: Gauss-Newton from
    (f0, fdot0), the amplitudes (a, b) solved with them.  Vectorized over the rows."""
    m = x.shape[0]
    f = np.full(m, f0)
    fd = None if fdot0 is None else np.full(m, fdot0)
    th = 2 * np.pi * f0 * t + (0.0 if fdot0 is None else np.pi * fdot0 * t**2)
    a = 2.0 / t.size * x @ np.cos(th)                            # the amplitudes at the start (near orthogonal)
    b = 2.0 / t.size * x @ np.sin(th)
    for _ in range(iterations):
        th = 2 * np.pi * f[:, None] * t + (0.0 if fd is None else np.pi * fd[:, None] * t**2)
        c, s = np.cos(th), np.sin(th)
        d = -a[:, None] * s + b[:, None] * c
        cols = [c, s, 2 * np.pi * t * d] + ([] if fd is None else [np.pi * t**2 * d])
        J = np.stack(cols, axis=2)                                  # (m, N, p)
        r = x - (a[:, None] * c + b[:, None] * s)
        step = np.linalg.solve(np.einsum("mnp,mnq->mpq", J, J), np.einsum("mnp,mn->mp", J, r)[..., None])[..., 0]
        a, b, f = a + step[:, 0], b + step[:, 1], f + step[:, 2]
        if fd is not None:
            fd = fd + step[:, 3]
    return f, fd


@pytest.mark.parametrize("rho", [30.0, 300.0])
def test_tone_frequency_bound_against_monte_carlo(rho):
    """A real tone of unknown amplitude and phase in white noise, N samples, rho = N A^2/(2 sigma^2):
    the maximum-likelihood frequency scatters by sqrt(12)/(2 pi T sqrt(rho)) (T = N samples), to
    the Monte Carlo's 3.5 % (12 % allowed: 3.4 of its standard errors)."""
    rng = np.random.default_rng(11)
    t = np.arange(N, dtype=float)
    sigma = math.sqrt(N / (2 * rho))
    f_true = 0.1234
    x = np.cos(2 * np.pi * f_true * t + rng.uniform(0, 2 * np.pi, (TRIALS, 1))) + sigma * rng.standard_normal((TRIALS, N))
    f, _ = fit_sinusoid(x, t, f_true)
    assert np.std(f) / RC.crb_tone(rho, N) == pytest.approx(1.0, abs=0.12)
    assert abs(np.mean(f) - f_true) < 4 * RC.crb_tone(rho, N) / math.sqrt(TRIALS)       # unbiased


def test_chirp_bounds_against_monte_carlo():
    """A linear chirp over a centred interval: its centre frequency scatters as a tone's,
    sqrt(12)/(2 pi T sqrt(rho)) (fitting the rate costs the centre nothing: t and t^2 are
    orthogonal there), and its rate by sqrt(180)/(pi T^2 sqrt(rho))."""
    rng = np.random.default_rng(12)
    rho = 200.0
    t = np.arange(N, dtype=float) - (N - 1) / 2
    sigma = math.sqrt(N / (2 * rho))
    f_true, fdot_true = 0.2, 3e-4               # drifts by 0.077 cycles/sample over the interval: 20 bins
    phase = rng.uniform(0, 2 * np.pi, (TRIALS, 1))
    x = np.cos(2 * np.pi * f_true * t + np.pi * fdot_true * t**2 + phase) + sigma * rng.standard_normal((TRIALS, N))
    f, fd = fit_sinusoid(x, t, f_true, fdot_true)
    sf, sfd = RC.crb_chirp(rho, N)
    assert sf == RC.crb_tone(rho, N)
    assert np.std(f) / sf == pytest.approx(1.0, abs=0.12)
    assert np.std(fd) / sfd == pytest.approx(1.0, abs=0.12)


@pytest.mark.parametrize("p_out", [0.05, 0.01])
def test_threshold_bounds_the_outliers_of_a_periodogram(p_out):
    """At rho = detection_threshold(K, p_out) for K = N/2 bins, the periodogram's strongest bin lies
    away from the tone in at most p_out of the intervals (a union bound: 2.2 % at 5 % and 0.33 % at
    1 % in these 6000 intervals; more than a fifth of it, so the bound is not loose by orders)."""
    rng = np.random.default_rng(13)
    k = N // 2
    rho = RC.detection_threshold(k, p_out)
    sigma = math.sqrt(N / (2 * rho))
    t = np.arange(N)
    m = 6000
    x = np.cos(2 * np.pi * 40 / N * t + rng.uniform(0, 2 * np.pi, (m, 1))) + sigma * rng.standard_normal((m, N))
    peak = np.argmax(np.abs(np.fft.rfft(x, axis=1))[:, 1:k], axis=1) + 1
    rate = np.mean(np.abs(peak - 40) > 1)
    assert p_out / 5 < rate < p_out


def test_the_exact_threshold_is_the_false_alarm_point():
    """exact_threshold(K, 1 %) is where noise outshines the line in 1 % of the intervals: the line's
    bin |sqrt(rho/2) + z|^2 and the largest of K exponential noise bins drawn 200 000 times
    (K = 1e6: the 1 MHz band over 1 s) put the noise on top in 1.00 % (+- 0.07) of them; the
    detection rule's union bound (70.9) lies above the exact point (59.0)."""
    rng = np.random.default_rng(21)
    K, n = 1e6, 200_000
    rho = RC.exact_threshold(K, 0.01)
    assert rho == pytest.approx(59.0, abs=0.1) and float(RC.detection_threshold(K, 0.01)) > rho + 10
    z = (rng.standard_normal(n) + 1j * rng.standard_normal(n)) / math.sqrt(2)
    line = np.abs(math.sqrt(rho / 2) + z) ** 2
    noise_max = -np.log1p(-rng.uniform(size=n) ** (1.0 / K))      # the largest of K Exp(1): (1 - e^-x)^K
    assert np.mean(noise_max > line) == pytest.approx(0.01, abs=0.0007)


def test_coherent_interval_and_drift():
    """T_c is the least of the integration, the chirp's (6/|f_ddot|)^(1/3) and the band's B/|f_dot|;
    the drift of a quadratic series is exact."""
    assert RC.coherent_interval(0.0, 6.0, 10.0, 1e6) == pytest.approx(1.0)
    assert RC.coherent_interval(1e4, 0.0, 10.0, 1e3) == pytest.approx(0.1)
    assert RC.coherent_interval(0.0, 0.0, 2.5, 1e3) == 2.5
    t = np.geomspace(1.0, 100.0, 50)
    fdot, fddot = RC.drift(t, 3.0 + 2.0 * t + 0.5 * t**2)
    assert np.allclose(fdot, 2.0 + t, rtol=1e-12) and np.allclose(fddot, 1.0, rtol=1e-9)


def test_receiver_spec_takes_one_of_each():
    with pytest.raises(SpecError, match="noise_density_w_per_hz: give only one of"):
        ReceiverSpec(noise_temperature_k=4.0, noise_density_w_per_hz=1e-22)
    with pytest.raises(SpecError, match="antenna_area_cm2: give only one of"):
        ReceiverSpec(antenna_gain_dbi=3.0, antenna_area_cm2=10.0)
    with pytest.raises(SpecError, match=r"bandwidth_hz: must lie in \[1, 1e\+12\]"):
        ReceiverSpec(bandwidth_hz=0.5)
    assert ReceiverSpec().noise_density == pytest.approx(1.380649e-16 * 5.0)
    assert ReceiverSpec(noise_density_w_per_hz=1e-22).noise_density == pytest.approx(1e-15)
    assert ReceiverSpec(antenna_gain_dbi=0.0).effective_area_cm2(U.C_LIGHT / 10.0) == pytest.approx(100 / (4 * math.pi))


def test_cube_budget_at_the_start(observed_cube):
    """The DAST cube seen across L at 10 cm by the default receiver: received power = dP/dOmega
    G lambda^2/(4 pi R^2) (G = 5 dBi), SNR of one second 2 S/N0 (N0 = k_B 5 K), the frequency to
    sqrt(12)/(2 pi sqrt(rho)) Hz; in the radiation zone (R = 2.36 lambda)."""
    obs = observed_cube
    bg = obs.budgets[0]
    d = obs.detections[0]
    i = 1
    k = bg.dominant[i]
    lam = U.C_LIGHT / d.f_dom[i]
    S = d.power_sr[i] * 10 ** 0.5 * lam**2 / (4 * math.pi) / 10.0**2
    rho = 2 * S * 1.0 / (1.380649e-16 * 5.0)
    assert bg.signal[i, k] == pytest.approx(S, rel=1e-12) and bg.rho[i, k] == pytest.approx(rho, rel=1e-12)
    assert bg.sigma_f[i] == pytest.approx(math.sqrt(12) / (2 * math.pi * math.sqrt(rho)), rel=1e-12)
    assert bg.sigma_lnp[i] == pytest.approx(2 / math.sqrt(rho), rel=1e-12)
    assert bg.sigma_pol[i] == pytest.approx(1 / math.sqrt(rho), rel=1e-9)         # linear: p = 1
    assert bg.zone[i] == "radiation" and 10.0 / lam == pytest.approx(2.358, abs=1e-3)


def test_cube_field_at_the_antenna_has_all_three_terms(observed_cube):
    """Across the rotation axis (n in the plane the dipole's moving part turns in) the rotating
    dipole's field has a longitudinal part 2 p (1/R^3 + i k/R^2) and a transverse one
    p (k^2/R - 1/R^3 - i k/R^2) of equal |p|: the whole field over its radiation term is their
    closed form; the radiation term alone is the detector's far field (E R = d_ddot across n / c^2)."""
    obs = observed_cube
    bg, d = obs.budgets[0], obs.detections[0]
    R = 10.0
    for i in (1, 400):
        k = 2 * math.pi * d.f_dom[i] / U.C_LIGHT
        closed = math.sqrt(abs(2 * (1 / R**3 + 1j * k / R**2)) ** 2 + abs(k**2 / R - 1 / R**3 - 1j * k / R**2) ** 2)
        assert bg.field_full_rms[i] / bg.field_radiation_rms[i] == pytest.approx(closed / (k**2 / R), rel=1e-9)
        assert bg.field_radiation_rms[i] == pytest.approx(d.field_rms[i], rel=1e-9)


def test_dimensionless_detection_has_no_receiver():
    from spinviz.analysis.detector import Detection

    det = Detection(model="reduced", units="dimensionless", t=np.zeros(1), line_of_sight=np.array([1.0, 0, 0]),
                    distance_cm=1.0, freq=np.ones((1, 1)), line_power_sr=np.ones((1, 1)),
                    line_field=np.ones((1, 1, 2)), line_ddot=np.ones((1, 1, 3)), power=np.ones(1),
                    power_sr=np.ones(1), field_rms=np.ones(1), f_dom=np.ones(1), f_rot=np.ones(1), f_prec=np.ones(1),
                    pol_angle=np.zeros(1), linear=np.ones(1), circular=np.zeros(1), photons_sr=None,
                    phase_resolved=True)
    with pytest.raises(ValueError, match="physical units"):
        RC.budget(det, ReceiverSpec())
