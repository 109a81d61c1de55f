"""``spinviz listen``: the detector's signal made audible -- left ear one model, right ear the other.

The detected field (``detector.Detection``: the spectral lines toward the detector at each
stored instant) is replayed with three stated mappings, the same for both ears:

* time: ``duration`` seconds of sound cover the run, logarithmically by default,
  t = k ((1 + t_end/k)^(s/duration) - 1) with the knee k = t_end/1000 (early and late both get
  time), or linearly, t = t_end s/duration;
* pitch: every frequency times one factor, which puts the initial rotation frequency at ``f0``
  (440 Hz): a GHz line becomes an A4, and the spin-down a glide whose ratios are the true ones;
* loudness: the field's amplitude along one antenna axis across the line of sight (the initial
  polarization's major axis), one scale for both ears, its range in dB compressed into
  ``dynamic_range_db`` (60 dB) when larger.

Each line is a sine whose phase is the integral of its scaled frequency; its start phase is the
line's own.  The fast phase of a real particle is not resolved (1e16 turns), so the waveform is
reconstructed from the slow variables -- what one hears is the true spectrum, slowed and
transposed, not a recording.  The statement is printed, written into the WAV's LIST/INFO chunk
(ICMT: the text and a JSON record) and onto the spectrogram of the WAV.
"""

from __future__ import annotations

import json
import math
import struct
from dataclasses import asdict, dataclass

import numpy as np

from .. import __version__
from .. import units as U
from .detector import Detection

RATE = 44_100
NYQUIST_SHARE = 0.45          # lines above 0.45 x the sample rate are dropped (they would alias)
AUDIBLE_HZ = 20.0
PITCH_RANGE = 16.0            # pitch="auto": a fall in frequency beyond 16x (4 octaves) is compressed into it


@dataclass(frozen=True)
class Mapping:
    """How the run becomes sound: the record written into the WAV (ICMT, JSON)."""

    left: str
    right: str
    duration_s: float
    rate: int
    time_map: str                 # "log" or "linear"
    t_end: float                  # the run's horizon, in its time unit
    knee: float                   # log map's k
    time_unit: str
    freq_scale: float             # audio Hz per Hz (or per cycle per tau0) at f0_source
    pitch_exponent: float         # f_audio = f0_audio (f / f0_source)^pitch_exponent (1: ratios kept)
    f0_audio: float
    f0_source: float
    freq_unit: str
    loudness_db_range: float      # the field's range in dB over the run (both ears)
    loudness_compression: float   # sound dB per field dB (1: true amplitudes)
    antenna: list
    line_of_sight: list
    phase_resolved: bool
    dropped_above_nyquist: int
    below_audible_s: float        # seconds of sound whose strongest line is under 20 Hz

    def audio_time_to_t(self, s):
        """The run's time at sound time ``s`` (seconds)."""
        return audio_time_to_t(np.asarray(s, dtype=float), self.duration_s, self.t_end, self.time_map, self.knee)

    def statement(self) -> str:
        """The mapping in words, one line each."""
        unit = self.time_unit
        if self.time_map == "log":
            tm = (f"time: {self.duration_s:g} s of sound = {_fmt_t(self.t_end, unit)}, logarithmic: "
                  f"t = k ((1 + t_end/k)^(s/{self.duration_s:g} s) - 1), k = {_fmt_t(self.knee, unit)}")
        else:
            tm = f"time: {self.duration_s:g} s of sound = {_fmt_t(self.t_end, unit)}, linear"
        src = U.format_frequency(self.f0_source) if self.freq_unit == "Hz" else f"{self.f0_source:.4g} {self.freq_unit}"
        if self.pitch_exponent == 1.0:
            pitch = (f"pitch: every frequency x {self.freq_scale:.4g} ({src} rotation at the start -> {self.f0_audio:g} Hz; "
                     f"ratios kept)")
        else:
            pitch = (f"pitch: f -> {self.f0_audio:g} Hz x (f / {src})^{self.pitch_exponent:.3g}: the run's fall in frequency "
                     f"compressed into {PITCH_RANGE:g}x ({math.log2(PITCH_RANGE):g} octaves); order kept, ratios not")
        comp = ("true amplitudes" if self.loudness_compression >= 1.0 else
                f"its {self.loudness_db_range:.0f} dB range compressed x{self.loudness_compression:.2f} into "
                f"{self.loudness_db_range * self.loudness_compression:.0f} dB")
        loud = f"loudness: the field at the detector along one antenna axis, one scale for both ears, {comp}"
        phase = ("phase: as simulated" if self.phase_resolved else
                 "phase: reconstructed from the slow variables (the spin phase of the run is not resolved)")
        return "\n".join([f"left ear: {self.left}, right ear: {self.right}", tm, pitch, loud, phase])


def _fmt_t(t: float, unit: str) -> str:
    return U.human_time(t) if unit == "s" else f"{t:.4g} tau0"


def audio_time_to_t(s, duration: float, t_end: float, time_map: str, knee: float):
    """Sound time s in [0, duration] -> the run's time (the mappings of the module docstring)."""
    x = np.clip(np.asarray(s, dtype=float) / duration, 0.0, 1.0)
    if time_map == "linear":
        return t_end * x
    return knee * np.expm1(x * math.log1p(t_end / knee))


def antenna_axis(dets) -> np.ndarray:
    """(a1, a2): the antenna along the major axis of the louder model's polarization at the
    start, on (u1, u2); the same for both ears."""
    d = max(dets, key=lambda d: float(d.power_sr[0]))
    ang = float(d.pol_angle[0]) if d.linear[0] > 0.05 else 0.0
    return np.array([math.cos(ang), math.sin(ang)])


def synthesize(dets: list[Detection], duration: float = 20.0, f0: float = 440.0, time_map: str = "log",
               dynamic_range_db: float = 60.0, rate: int = RATE, knee: float | None = None,
               pitch: str = "auto") -> tuple[np.ndarray, Mapping]:
    """Stereo samples (n, 2) float in [-1, 1] (left: dets[0], right: dets[1]) and the mapping.

    knee : the log time map's k (default t_end/1000); pitch : "linear" (every frequency times
    one factor) or "auto" (that, unless the dominant frequency falls by more than 16x over the
    run: then f0 (f/f_start)^gamma with gamma putting the whole fall into 16x).  The sound's
    arguments are ``inputs.options.ListenRequest``'s (``experiment.listen`` checks them)."""
    a, b = dets
    t = np.asarray(a.t, dtype=float)
    t_end = float(t[-1])
    knee = t_end / 1000.0 if knee is None else float(knee)
    f_src = float(a.f_rot[0]) or float(a.f_dom[0])
    if not f_src > 0:
        raise ValueError("the run does not rotate at the start: nothing to hear")
    f_low = min(float(np.min(np.where(d.f_dom > 0, d.f_dom, np.inf))) for d in dets)
    fall = f_src / f_low if math.isfinite(f_low) else 1.0
    gamma = math.log(PITCH_RANGE) / math.log(fall) if pitch == "auto" and fall > PITCH_RANGE else 1.0
    scale = f0 / f_src
    n = int(round(duration * rate))
    s = np.arange(n) / rate
    ts = audio_time_to_t(s, duration, t_end, time_map, knee)
    ant = antenna_axis(dets)
    amps, freqs, dropped = [], [], 0
    for d in dets:
        e = d.line_field @ ant                                              # (N, K) complex, on the antenna
        amps.append(2.0 * np.abs(e))
        freqs.append(f0 * (d.freq / f_src) ** gamma)
    peak = max(float(np.max(x)) for x in amps) or 1.0
    with np.errstate(divide="ignore"):
        db = [20.0 * np.log10(np.maximum(x.max(axis=1), 1e-300) / peak) for x in amps]
    lowest = min(float(np.min(x[np.isfinite(x)])) for x in db)
    db_range = max(-lowest, 1e-9)
    comp = min(1.0, dynamic_range_db / db_range)
    out = np.zeros((n, 2))
    below = np.zeros(n, dtype=bool)
    for ch, (d, amp, fr) in enumerate(zip(dets, amps, freqs)):
        out[:, ch], strongest, lost = _channel(d, amp / peak, fr, t, ts, ant, comp, rate)
        dropped += lost
        below |= (strongest > 0) & (strongest < AUDIBLE_HZ)
    top = float(np.max(np.abs(out))) or 1.0
    out *= 0.8 / top
    cgs = a.units == "cgs"
    mapping = Mapping(left=a.model, right=b.model, duration_s=float(duration), rate=int(rate), time_map=time_map,
                      t_end=t_end, knee=knee, time_unit="s" if cgs else "tau0", freq_scale=scale,
                      pitch_exponent=float(gamma), f0_audio=float(f0),
                      f0_source=f_src, freq_unit=a.freq_unit, loudness_db_range=float(db_range),
                      loudness_compression=float(comp), antenna=ant.tolist(), line_of_sight=a.line_of_sight.tolist(),
                      phase_resolved=bool(a.phase_resolved and b.phase_resolved), dropped_above_nyquist=dropped,
                      below_audible_s=float(below.sum() / rate))
    return out, mapping


def _channel(d: Detection, amp, fr, t, ts, ant, comp: float, rate: int):
    """One ear: the sum of the detection's lines as tones at the sound's instants.

    amp, fr : (N, K) line amplitudes on the antenna (relative to the loudest of both ears) and
    audio frequencies (Hz) at the run's samples t (N,); ts : (n,) the run's time of each sound
    sample.
    Returns (samples (n,), the frequency of the strongest line per sample (n,), Hz, the number
    of lines left out above ``NYQUIST_SHARE`` of the rate)."""
    n = ts.size
    out = np.zeros(n)
    strongest = np.zeros(n)
    dropped = 0
    for k in range(fr.shape[1]):
        ak = np.interp(ts, t, amp[:, k])
        if not np.any(ak > 1e-9):
            continue
        fk = np.interp(ts, t, fr[:, k])
        if np.any(fk > NYQUIST_SHARE * rate):
            dropped += 1
            continue
        # compress in dB: a -> a^comp keeps the loudest at its level and lifts the quiet ones
        ak = np.power(np.maximum(ak, 0.0), comp)
        phase = 2.0 * math.pi * np.cumsum(fk) / rate + float(np.angle(d.line_field[0, k] @ ant))
        out += ak * np.cos(phase)
        strongest = np.where(ak > strongest, fk, strongest)
    return out, strongest, dropped


# --- the WAV file ---------------------------------------------------------------------------
def _info_chunk(items: dict[bytes, str]) -> bytes:
    body = b"INFO"
    for key, text in items.items():
        data = text.encode("utf-8") + b"\0"
        if len(data) % 2:
            data += b"\0"
        body += key + struct.pack("<I", len(data)) + data
    return b"LIST" + struct.pack("<I", len(body)) + body


def wav_bytes(samples: np.ndarray, rate: int, title: str, mapping: Mapping) -> bytes:
    """A 16-bit PCM stereo WAV with a LIST/INFO chunk: INAM the title, ICMT the mapping in words
    and as JSON (after a line 'spinviz-mapping: '), ISFT the software."""
    pcm = np.clip(np.round(samples * 32767.0), -32768, 32767).astype("<i2")
    channels = pcm.shape[1]
    fmt = struct.pack("<HHIIHH", 1, channels, rate, rate * 2 * channels, 2 * channels, 16)
    comment = mapping.statement() + "\nspinviz-mapping: " + json.dumps(asdict(mapping))
    info = _info_chunk({b"INAM": title, b"ICMT": comment, b"ISFT": f"spinviz {__version__}"})
    data = pcm.tobytes()
    chunks = b"fmt " + struct.pack("<I", len(fmt)) + fmt + info + b"data" + struct.pack("<I", len(data)) + data
    return b"RIFF" + struct.pack("<I", 4 + len(chunks)) + b"WAVE" + chunks


def read_info(path) -> dict:
    """The LIST/INFO items of a WAV (INAM, ICMT, ...) and, from ICMT, the mapping as a dict
    under "mapping"."""
    from ..atomic import loads_json, read_regular

    raw = read_regular(path)                  # a FIFO or device is refused at once, never waited on
    if raw[:4] != b"RIFF" or raw[8:12] != b"WAVE":
        raise ValueError(f"{path}: not a WAV file")
    out, pos = {}, 12
    while pos + 8 <= len(raw):
        cid, size = raw[pos:pos + 4], struct.unpack("<I", raw[pos + 4:pos + 8])[0]
        if cid == b"LIST" and raw[pos + 8:pos + 12] == b"INFO":
            p, end = pos + 12, pos + 8 + size
            while p + 8 <= end:
                key, n = raw[p:p + 4].decode("ascii"), struct.unpack("<I", raw[p + 4:p + 8])[0]
                out[key] = raw[p + 8:p + 8 + n].rstrip(b"\0").decode("utf-8")
                p += 8 + n + (n % 2)
        pos += 8 + size + (size % 2)
    for line in out.get("ICMT", "").splitlines():
        if line.startswith("spinviz-mapping: "):
            out["mapping"] = loads_json(line[len("spinviz-mapping: "):])
    return out


def plot_wav(path_wav, path_png, title: str = "") -> None:
    """The spectrogram of the WAV as written (read back with scipy: what one hears), left and
    right ear, sound time and pitch on the axes, the run's time and frequency on the opposite
    axes from the file's own mapping; the mapping stated under the title (PNG, atomic)."""
    from scipy.io import wavfile

    from ..plotting import model_color, pyplot, save

    plt = pyplot()
    rate, data = wavfile.read(path_wav)
    info = read_info(path_wav)
    m = info.get("mapping", {})
    specs, top, fmax = _spectrograms(data.astype(float) / 32768.0, rate)
    fig, axes = plt.subplots(1, 2, figsize=(15, 7.4), sharey=True)
    for ch, (ax, (f, tt, S)) in enumerate(zip(axes, specs)):
        keep = f <= fmax                                   # draw only the rows on screen
        f, S = f[keep], S[keep]
        db = 10 * np.log10(np.maximum(S, top * 1e-12) / top)
        mesh = ax.pcolormesh(tt, f, db, vmin=-80, vmax=0, cmap="magma", shading="nearest", rasterized=True)
        model = m.get("left" if ch == 0 else "right", "")
        ax.set_title(f"{'left' if ch == 0 else 'right'} ear: {model}", color=model_color(model) if model else "k")
        ax.set_ylim(0, fmax)
        ax.set_xlabel("sound time (s)")
        if m:
            sec = ax.secondary_xaxis("top", functions=(lambda v: v, lambda v: v))      # relabelled below
            ticks = np.linspace(0, m["duration_s"], 6)
            sec.set_ticks(ticks, labels=[_fmt_t(float(audio_time_to_t(s, m["duration_s"], m["t_end"], m["time_map"],
                                                                      m["knee"])), m["time_unit"]) for s in ticks])
            sec.set_xlabel("time in the run")
    axes[0].set_ylabel("pitch (Hz)")
    if m:
        unit = 1e9 if m["freq_unit"] == "Hz" else 1.0
        g, fa, fs = m["pitch_exponent"], m["f0_audio"], m["f0_source"]
        sec = axes[1].secondary_yaxis("right", functions=(
            lambda v: fs * np.power(np.maximum(v, 1e-9) / fa, 1.0 / g) / unit,
            lambda v: fa * np.power(np.maximum(v, 1e-30) * unit / fs, g)))
        sec.set_ylabel("frequency in the run (GHz)" if m["freq_unit"] == "Hz" else f"frequency ({m['freq_unit']})")
    fig.subplots_adjust(left=0.06, right=0.86, top=0.80, bottom=0.27, wspace=0.08)
    cax = fig.add_axes((0.93, 0.27, 0.012, 0.53))
    fig.colorbar(mesh, cax=cax, label="dB re the loudest (spectrogram of the file)")
    mapping = info.get("ICMT", "").split("\nspinviz-mapping: ")[0]
    fig.suptitle(title or info.get("INAM", ""), fontsize=12)
    fig.text(0.06, 0.02, "the mapping, as written in the file:\n" + mapping, fontsize=9, va="bottom", family="monospace")
    save(fig, path_png)


def _spectrograms(x, rate: int):
    """Both channels' spectrograms of samples ``x`` (n, 2) in [-1, 1]: ([(f, t, S)] per channel,
    the largest S of both, the highest frequency worth drawing, Hz)."""
    from scipy.signal import spectrogram

    nper = 4096
    top = 0.0
    specs = []
    for ch in range(2):
        # no detrending: removing each segment's mean from a tone puts a broadband step in it (-45 dB
        # fringes); Blackman-Harris sidelobes sit at -92 dB
        f, tt, S = spectrogram(x[:, ch], fs=rate, nperseg=nper, noverlap=nper * 3 // 4, window="blackmanharris",
                               detrend=False)
        specs.append((f, tt, S))
        top = max(top, float(S.max()))
    fmax = 0.0
    for f, _, S in specs:
        strong = S.max(axis=1) > top * 1e-6
        fmax = max(fmax, float(f[strong].max()) if strong.any() else 0.0)
    return specs, top, min(rate / 2, 1.25 * fmax or rate / 4)


def audio_frequency(f, mapping: dict):
    """The pitch (Hz) a frequency of the run is played at, from a WAV's mapping record."""
    return mapping["f0_audio"] * (np.asarray(f, dtype=float) / mapping["f0_source"]) ** mapping["pitch_exponent"]


def listen_scene(sc, out_wav: str, out_png: str | None, req, line_of_sight=None, receiver=None):
    """Simulate and detect both models of scene ``sc`` (``observe.run_scene``), synthesize and
    write the WAV (and its spectrogram PNG, unless ``out_png`` is None); returns the Mapping.
    ``req``: the sound, an ``inputs.options.ListenRequest`` (checked by its maker,
    ``experiment.listen``, before any run); ``receiver``: where the detector stands (its
    distance sets the field's zone; nothing is received).  The caller makes the paths atomic as
    a group (these write in place)."""
    from .observe import run_scene

    duration, f0, time_map, pitch = req.duration, req.f0, req.time_map, req.pitch
    obs, _ = run_scene(sc, req.samples, line_of_sight, receiver, receive=False, command="listen")
    # the log map's knee: a tenth of the braking time 1/(tau0 |Omega0|^2), where the motion starts to
    # change, unless t_end/1000 comes first (a geological horizon must not spend its first second on nothing)
    w0 = np.asarray(sc.omega0, dtype=float)
    horizon = float(obs.horizon)
    knee = min(horizon / 1000.0, 0.1 / (sc.body.tau0 * float(w0 @ w0))) if float(w0 @ w0) > 0 else horizon / 1000.0
    data, mapping = synthesize(obs.detections, duration, f0, time_map, req.dynamic_range_db, knee=knee, pitch=pitch)
    with open(out_wav, "wb") as fh:
        fh.write(wav_bytes(data, mapping.rate, sc.title, mapping))
    if out_png:
        plot_wav(out_wav, out_png, f"{sc.title}: the WAV as heard")
    return mapping
