"""What a detector and a stated receiver record, when the two models part across resolutions,
the start-free test on each model's own line, and the sonification."""

import json
import math
import re
from pathlib import Path

import numpy as np
import pytest
from scipy.io import wavfile
from scipy.optimize import brentq

import spinviz
from spinviz.analysis import observe as OB
from spinviz.analysis import sonify as SO
from spinviz.commands import main
from spinviz.inputs.scene_spec import load_scene
from spinviz.physics import closed_forms as CF
from spinviz.physics import models as M

ROOT = Path(__file__).resolve().parents[1]
SCENES = ROOT / "scenes"
W = math.pi * 1e10                     # the scenes' Omega20 = Omega30, rad/s


def run(argv, capsys):
    try:
        code = main([str(a) for a in argv])
    except SystemExit as e:                 # argparse's own errors (one line, status 2)
        code = e.code
    out, err = capsys.readouterr()
    return code, out, err


@pytest.fixture(scope="module")
def cube(observed_cube):
    """(scene, observation, trajectories) of scenes/dast_cube.toml (conftest's session run)."""
    return load_scene(SCENES / "dast_cube.toml"), observed_cube, observed_cube.trajectories


def cube_closed_forms(t, tau0):
    """|Omega| and |Omega across d| of the DAST cube scene: (6.7) reduced, (6.9) truncated."""
    red = CF.omega_eq6_7(t, tau0, W, W)
    tru = CF.omega_eq6_9(t, tau0, W, W)
    return (np.linalg.norm(red, axis=1), red[:, 1]), (np.linalg.norm(tru, axis=1), tru[:, 1])


def test_cube_models_part_when_the_closed_forms_say(cube):
    """DAST cube (sphere, d along e3): the power toward a detector across L goes as |Omega|^2
    |Omega across d|^2 and the only line is at |Omega|/2 pi, so (6.7) and (6.9) give the parting
    times in closed form: a factor 2 in power (ln 2), 1 % and 1e-6 in frequency.  The parting
    curves (from physics.longitudinal's closed forms on a dense log grid) find them to 1e-4, and
    the polarization (linear, along the same axis for both) never parts."""
    sc, obs, _ = cube
    tau0 = sc.body.tau0

    def power_ratio(t):
        (wr, pr), (wt, pt) = cube_closed_forms(np.array([t]), tau0)
        return float(((wt * pt) ** 2 / (wr * pr) ** 2)[0])      # the truncated top keeps more power

    def freq_ratio(t):
        (wr, _), (wt, _) = cube_closed_forms(np.array([t]), tau0)
        return float((wr / wt)[0])

    t_power = brentq(lambda t: power_ratio(t) - 2.0, 1.0, sc.t_end)
    t_freq = brentq(lambda t: freq_ratio(t) - 1.01, 1.0, sc.t_end)
    t_1e6 = brentq(lambda t: freq_ratio(t) - 1.0 - 1e-6, 1.0, sc.t_end)
    assert obs.parting["power"].at(math.log(2.0)) == pytest.approx(t_power, rel=1e-4)
    assert obs.parting["frequency"].at(0.01) == pytest.approx(t_freq, rel=1e-4)
    assert obs.parting["frequency"].at(1e-6) == pytest.approx(t_1e6, rel=1e-4)
    assert obs.parting["polarization"].at(math.radians(0.1)) is None
    # docs/experiment.md's numbers: 1.9 days, 8.6 hours, 4.5 minutes, against Theta = 3.15 days
    assert t_power / 86400 == pytest.approx(1.92, abs=0.01) and t_freq / 3600 == pytest.approx(8.6, abs=0.05)
    assert t_1e6 / 60 == pytest.approx(4.54, abs=0.01)


def test_parting_curves_agree_with_the_runs_and_never_go_back(cube):
    """Where the differences are well above the runs' accuracy (1e-11), the integrated runs part
    when the closed forms say (to the 1.7 % spacing of their log-spaced instants); a parting time
    never decreases with the resolution."""
    from spinviz.analysis import parting as PT

    _, obs, _ = cube
    runs = PT.differences(*obs.detections)
    t = obs.detections[0].t
    for key, r in (("frequency", 1e-6), ("frequency", 1e-3), ("power", 0.01), ("power", 0.3)):
        assert PT.parting_time(t, runs[key], r) == pytest.approx(obs.parting[key].at(r), rel=0.02), (key, r)
    for c in obs.parting.values():
        ok = np.isfinite(c.times)
        assert np.all(np.diff(c.times[ok]) >= 0)


def test_receiver_parts_the_cube_at_five_sigma(cube):
    """This receiver (5 dBi at 10 cm, 5 K, 1 s): the frequency differs by more than 5 sigma of one
    integration at the first one (1 s: 1.1e-11 against a relative resolution of 2.2e-12); the power
    first when ln(P_tru/P_red) = 5 sigma_P/P, with sigma_P/P = 2/sqrt(rho) of the fainter model."""
    from spinviz.physics import longitudinal as LG

    sc, obs, _ = cube
    f = obs.parting["frequency"]
    u0, b0 = LG.start_state(sc.omega0, sc.body.dipole_direction, 1.0)
    fr, _ = M.get("reduced").line.line(1.0, u0, b0, sc.body.tau0)
    ft, _ = M.get("truncated").line.line(1.0, u0, b0, sc.body.tau0)
    bg = obs.budgets[0]
    rel = bg.sigma_f[1] / bg.freq[1, bg.dominant[1]]
    assert f.setup_time == pytest.approx(1.0, rel=1e-6)
    assert abs(fr / ft - 1) > 5 * rel and rel == pytest.approx(2.2e-12, rel=0.02)
    p = obs.parting["power"]
    i = np.searchsorted(p.t, p.setup_time)
    assert p.D[i] >= 5 * p.sigma[i] and p.D[i - 1] < 5 * p.sigma[i - 1]
    assert p.setup_time / 86400 == pytest.approx(1.75, abs=0.01)


def test_observe_record_is_strict_json(cube):
    """The cube's record (receiver, budgets, parting curves, P-f tests with an infinite Z) holds no
    NaN or Infinity: None stands for them."""
    _, obs, _ = cube
    rec = json.loads(json.dumps(obs.record(), allow_nan=False))
    assert rec["pf_test"]["fits"]["truncated"]["reduced_law_rejected_outright"] is True
    assert rec["parting"]["frequency"]["setup_time"] == pytest.approx(1.0)


def test_cube_line_as_this_receiver_measures_it_passes_the_pf_test(cube):
    """Each model's own line, one 1 s integration at each instant where it is detected in the
    radiation zone (with the receiver's noise): the reduced run goes to the reduced law (f_inf near
    5 GHz), the truncated run to the truncated law, which rejects the reduced start's 5 GHz outright."""
    _, obs, _ = cube
    red, tru = obs.pf["reduced"], obs.pf["truncated"]
    assert red.verdict == "reduced" and red.z > 50 and red.f_inf == pytest.approx(5e9, rel=2e-3)
    assert tru.verdict == "truncated" and tru.z_expected == math.inf and abs(tru.exponent - 4) < 3 * tru.exponent_sigma


def test_cube_detector_sees_larmor_toward_n(cube):
    """At the start the dipole turns about L (along z) at sqrt(2) pi 1e10 rad/s at 45 deg: seen
    across L the field is linear along u1 and dP/dOmega = (3/16 pi) P (half of the rotating
    d_ddot projects on the line of sight's plane); the line is at |Omega|/2 pi = 7.07 GHz."""
    _, obs, trajs = cube
    for d in obs.detections:
        assert d.power_sr[0] == pytest.approx(3.0 / (16.0 * math.pi) * d.power[0], rel=1e-9, abs=0)
        assert d.f_dom[0] == pytest.approx(math.sqrt(2) * W / (2 * math.pi), rel=1e-12)
        assert d.linear[0] == pytest.approx(1.0, abs=1e-9) and abs(d.pol_angle[0]) < 1e-9
    red, tru = obs.detections
    (wr, pr), (wt, pt) = cube_closed_forms(red.t, trajs[0].body.tau0)
    # reduced: the dark residual rotation (power -> 0, frequency -> Omega3/2 pi); truncated: 1/F^4
    assert np.allclose(red.f_dom, wr / (2 * math.pi), rtol=1e-9, atol=0)
    assert np.allclose(tru.f_dom, wt / (2 * math.pi), rtol=1e-9, atol=0)
    assert red.f_dom[-1] == pytest.approx(W / (2 * math.pi), rel=2e-6)      # -> Omega3: 1.5e-6 above it at 6 Theta
    assert np.allclose(red.power_sr / red.power_sr[0], (wr * pr) ** 2 / (wr[0] * pr[0]) ** 2, rtol=1e-6, atol=0)
    assert np.allclose(tru.power_sr / tru.power_sr[0], (wt * pt) ** 2 / (wt[0] * pt[0]) ** 2, rtol=1e-6, atol=0)


def test_rod_parts_in_frequency_after_a_hundred_T_and_in_power_after_Theta():
    """The cellulose rod (chi = 0), over its [observe] horizon of 2e4 T: (5.2) and (5.4) are exact,
    and the only line is at |L|/(2 pi I1) = sqrt(w_perp^2 + eps^2 w3^2)/2 pi; the reduced top keeps
    w3, so the lines part by 1 % once eps^2 w3^2 ~ 0.02 w_perp^2 (~90 T, 2e8 years), and the power
    w_perp^2 (w_perp^2 + eps^2 w3^2) by a factor 2 only after Theta (~1.5 Theta, 1.5e10 years).  The
    default receiver never detects it: 4.7e-26 W in all, an SNR of 1e-5 in a second."""
    sc = load_scene(SCENES / "cellulose_rod.toml")
    obs, _ = OB.run_scene(sc, samples=800)
    b = sc.body
    delta, eps = b.delta, b.epsilon
    w20, w30 = (x * b.tau0 for x in (W, W))

    def states(t):
        tau = np.array([t / b.tau0])
        return CF.omega_eq5_2(tau, delta, w20, w30)[0], CF.omega_eq5_4(tau, delta, w20, w30)[0]

    def freq(w):
        return math.sqrt(w[0] ** 2 + w[1] ** 2 + eps**2 * w[2] ** 2)

    def power(w):
        p2 = w[0] ** 2 + w[1] ** 2
        return p2 * (p2 + eps**2 * w[2] ** 2)

    t_freq = brentq(lambda t: freq(states(t)[0]) / freq(states(t)[1]) - 1.01, b.tau0, obs.horizon)
    t_power = brentq(lambda t: power(states(t)[1]) / power(states(t)[0]) - 2.0, b.tau0, obs.horizon)
    assert obs.parting["frequency"].at(0.01) == pytest.approx(t_freq, rel=1e-4)
    assert obs.parting["power"].at(math.log(2.0)) == pytest.approx(t_power, rel=1e-4)
    T, Theta = obs.scales["T"], obs.scales["Theta"]
    assert 80 < t_freq / T < 100 and 1.3 < t_power / Theta < 1.7
    for bg in obs.budgets:
        assert not np.any(bg.detected) and np.nanmax(bg.rho) < 1e-4
    assert all(c.setup_time is None for c in obs.parting.values())


@pytest.mark.slow
def test_observe_command_prints_the_answer_and_writes_three_plots(tmp_path, capsys):
    """The parting times test_cube_models_part_when_the_closed_forms_say finds from the closed forms
    (1.92 days at ln 2 in power, 8.62 h at 1 % in frequency), this receiver's (1 s and 1.75 days),
    the start's line at sqrt(2) pi 1e10 / 2 pi = 7.071 GHz in the radiation zone, the reduced cube's
    end at Omega3 / 2 pi = 5 GHz, Theta = 3.15 days, the P-f verdicts; and three drawn plots."""
    from PIL import Image

    code, out, err = run(["observe", SCENES / "dast_cube.toml", "--out", tmp_path / "cube", "--samples", "200"], capsys)
    assert code == 0, err
    assert re.search(r"power +0\.001: .*; 0\.693: 1\.92 days\n +this receiver \(5σ in one 1 s integration, [\d.]+\): "
                     r"1\.75 days", out), out
    assert re.search(r"frequency +1e-12: .*; 0\.01: 8\.62 h\n +this receiver .*: 1 s ", out), out
    assert re.search(r"dominant frequency +7\.071 GHz +7\.071 GHz\n(.*\n)*.*dominant frequency +5 GHz", out), out
    assert re.search(r"wavelength, zone at the antenna +4\.24 cm, radiation +4\.24 cm, radiation", out), out
    assert "verdict: reduced" in out and "verdict: truncated" in out
    assert re.search(r"Theta += 3\.15 days +\(the paper, section 6\.2", out), out
    for name in ("cube_observe.png", "cube_detector.png", "cube_receiver.png"):
        img = np.asarray(Image.open(tmp_path / name).convert("L"))
        assert min(img.shape) > 800 and 0.01 < (img < 128).mean() < 0.5, (name, img.shape)   # drawn, not blank or solid


def test_antenna_inside_a_wavelength_gets_no_snr():
    """At 1 cm the cube's 4.2 cm line has the antenna in the intermediate zone: the whole field is
    given (1.84 times the radiation term: the closed form of test_receiver's), the radiation-zone
    SNR is not, and so no parting for this receiver."""
    obs = spinviz.observe(SCENES / "dast_cube.toml", samples=50, distance_cm=1.0)
    rec = json.loads(json.dumps(obs.record(), allow_nan=False))          # strict JSON: no NaN, no Infinity
    start = rec["budget"]["reduced"]["first"]
    assert start["zone"] == "intermediate" and start["snr_integration"] is None and start["received_w"] is None
    assert start["field_full_rms_v_per_m"] / start["field_radiation_term_rms_v_per_m"] == pytest.approx(1.84, abs=0.01)
    assert all(rec["parting"][k]["setup_time"] is None for k in ("power", "frequency", "polarization"))
    assert "near zone" in OB.format_table(obs) or "intermediate" in OB.format_table(obs)


def spectral_peak(x, rate, center_s, window_s=0.25):
    """The frequency of the strongest line of x around ``center_s`` (Blackman-Harris window,
    zero-padded 16x, parabolic interpolation of the log peak: ~0.1 Hz)."""
    n = int(window_s * rate)
    i0 = int(center_s * rate) - n // 2
    seg = x[i0:i0 + n] * np.blackman(n)
    spec = np.abs(np.fft.rfft(seg, 16 * n))
    k = int(np.argmax(spec))
    a, b, c = np.log(spec[k - 1:k + 2])
    return (k + 0.5 * (a - c) / (a - 2 * b + c)) * rate / (16 * n), float(np.sqrt(np.mean(seg**2)))


@pytest.mark.slow
def test_wav_follows_the_scaled_rotation_frequency(tmp_path, capsys):
    """``spinviz listen`` on the DAST cube: the WAV read back with scipy is 16-bit stereo; in each
    ear the strongest line follows the rotation frequency |Omega|/2 pi of (6.7) (left, reduced) and
    (6.9) (right, truncated) through the time and pitch maps stated in the file's metadata, to
    0.1 % (measured <= 5e-4: the line glides by up to 1 % across the 0.25 s window, and the log
    peak is not exactly parabolic there); the left ear fades with the
    reduced model's power (the dark residual rotation), the right one much less."""
    wav = tmp_path / "cube.wav"
    code, out, err = run(["listen", SCENES / "dast_cube.toml", "--out", wav, "--duration", "8", "--samples", "400"],
                         capsys)
    assert code == 0, err
    assert "left ear: reduced, right ear: truncated" in out and "pitch: every frequency x" in out
    rate, data = wavfile.read(wav)
    assert rate == 44100 and data.dtype == np.int16 and data.shape == (8 * 44100, 2)
    info = SO.read_info(wav)
    m = info["mapping"]
    assert m["left"] == "reduced" and m["right"] == "truncated" and "time: 8 s of sound" in info["ICMT"]
    tau0 = load_scene(SCENES / "dast_cube.toml").body.tau0
    x = data.astype(float) / 32768.0
    rms = {}
    for s in (0.5, 2.0, 4.0, 6.0, 7.5):
        t = float(SO.audio_time_to_t(s, m["duration_s"], m["t_end"], m["time_map"], m["knee"]))
        (wr, _), (wt, _) = cube_closed_forms(np.array([t]), tau0)
        for ch, w in ((0, wr[0]), (1, wt[0])):
            f, level = spectral_peak(x[:, ch], rate, s)
            assert f == pytest.approx(float(SO.audio_frequency(w / (2 * math.pi), m)), rel=1e-3), (s, ch)
            rms[s, ch] = level
    assert rms[7.5, 0] / rms[0.5, 0] < 0.02          # reduced: fades to the dark residual rotation
    assert rms[7.5, 1] / rms[0.5, 1] > 0.05          # truncated: keeps radiating as it spins down
    assert (tmp_path / "cube.png").stat().st_size > 50_000      # the spectrogram of the WAV


def test_synthesized_tone_has_the_metadata_pitch():
    """The mapping's pitch law round-trips: f0 at the start, exponent 1 when the fall is small."""
    m = {"f0_audio": 440.0, "f0_source": 7e9, "pitch_exponent": 1.0}
    assert SO.audio_frequency(7e9, m) == pytest.approx(440.0)
    assert SO.audio_frequency(3.5e9, m) == pytest.approx(220.0)


ONE_MODEL = """
[body]
delta = 0.3
chi = 0.7
[initial]
omega = [0.0, 0.05, 0.3]
[simulation]
model = "reduced"
t_end = 100.0
samples = 40
"""

TWO_MODELS = ONE_MODEL.replace('model = "reduced"', 'models = ["reduced", "truncated"]')


@pytest.mark.parametrize("argv,text,message", [
    (["observe", "{scene}"], ONE_MODEL, "[simulation].models: observe needs two models"),
    (["observe", "{scene}"], TWO_MODELS.replace("delta = 0.3\nchi = 0.7", "inertia = [1.0, 0.8, 0.55]\ndipole = [0.5, 0.3, 0.8]"),
     "needs a symmetric top"),
    (["observe", "{scene}", "--los", "1,2"], TWO_MODELS, "--los: expected three numbers"),
    (["observe", "{scene}", "--los", "0,0,0"], TWO_MODELS, "--los: must not be zero"),
    (["observe", "{scene}", "--power-factor", "2"], TWO_MODELS,
     "argument --power-factor: the resolutions are computed from the receiver"),
    (["observe", "{scene}"], TWO_MODELS + "[observe]\nfrequency_resolution = 0.01\n",
     "[observe].frequency_resolution: the resolutions are computed from the receiver"),
    (["observe", "{scene}"], TWO_MODELS + "[observe]\nnoise_temperature_k = 4.0\nnoise_density_w_per_hz = 1e-22\n",
     "[observe].noise_density_w_per_hz: give only one of noise_temperature_k, noise_density_w_per_hz"),
    (["observe", "{scene}"], TWO_MODELS + "[observe]\nintegration_s = 0.0\n", "[observe].integration_s: must lie in"),
    (["observe", "{scene}", "--distance-cm", "0"], TWO_MODELS, "--distance-cm: must lie in"),
    (["observe", "{scene}"], TWO_MODELS + "[observe]\ncolour = 1\n", "[observe].colour: unknown key"),
    (["observe", "{scene}"], TWO_MODELS + "[observe]\nline_of_sight = [0.0, 0.0, 0.0]\n",
     "[observe].line_of_sight: must not be zero"),
    (["observe", "{scene}"], TWO_MODELS + "[observe]\nt_end_T = -3\n", "[observe].t_end_T: must be positive"),
    (["listen", "{scene}", "--out", "{tmp}/x.mp3"], TWO_MODELS, "--out: "),
    (["listen", "{scene}", "--out", "{tmp}/x.wav", "--f0", "1e5"], TWO_MODELS, "--f0: must lie in [20, 5000]"),
    (["listen", "{scene}", "--out", "{tmp}/x.wav"], ONE_MODEL, "[simulation].models: listen needs two models"),
])
def test_bad_input_is_one_line_exit_2_and_writes_nothing(argv, text, message, tmp_path, capsys):
    scene = tmp_path / "scene.toml"
    scene.write_text(text)
    out_dir = tmp_path / "out"
    argv = [a.replace("{scene}", str(scene)).replace("{tmp}", str(out_dir)) for a in argv]
    if argv[0] == "observe":
        argv += ["--out", str(out_dir / "p")]
    code, out, err = run(argv, capsys)
    assert code == 2, (out, err)
    assert len(err.strip().splitlines()) == 1 and message in err, err
    assert "Traceback" not in err
    assert not out_dir.exists() or not any(out_dir.iterdir())


def test_dimensionless_askew_scene_is_observed_with_its_precession_lines(tmp_path):
    """A dimensionless askew top (delta = 0.3, chi = 0.7) precesses: its spectrum holds the rotation
    line and the sidebands at |L|/I1 +- delta omega3, and the body-precession frequency is
    |delta omega3|/2 pi per tau0."""
    scene = tmp_path / "scene.toml"
    scene.write_text(TWO_MODELS)
    obs, trajs = OB.run_scene(load_scene(scene), samples=100)
    d = obs.detections[0]
    w = trajs[0].omega[0]
    assert d.f_prec[0] == pytest.approx(0.3 * abs(w[2]) / (2 * math.pi), rel=1e-12)
    strong = d.freq[0][d.line_power_sr[0] > 1e-6 * d.line_power_sr[0].max()]
    for f in (d.f_rot[0], d.f_rot[0] + d.f_prec[0], abs(d.f_rot[0] - d.f_prec[0])):
        assert np.min(np.abs(strong - f)) < 1e-12 * d.f_rot[0]
