"""``spinviz listen SCENE --out X.wav``: hear the crystal spin down -- the detector's signal of
both models as a stereo WAV (left one model, right the other), with its spectrogram."""

from __future__ import annotations

import os

from ..errors import SimulationError
from .shared import EXIT_OK, add_detector_options, cannot_write, need_matplotlib, out, p, positive, real, receiver_options


def add_parser(sub) -> None:
    """Add ``spinviz listen`` (the detector's signal as sound) and its options to ``sub``."""
    li = sub.add_parser("listen", help="hear the crystal spin down: the detector's signal of both models as a stereo "
                                       "WAV (left one model, right the other), with its spectrogram")
    li.add_argument("scene")
    li.add_argument("--out", required=True, help="output .wav")
    li.add_argument("--png", help="spectrogram of the WAV (default: beside it, .png)")
    li.add_argument("--duration", type=real, default=20.0, help="seconds of sound (default 20)")
    li.add_argument("--f0", type=real, default=440.0, help="pitch of the initial rotation frequency, Hz (default 440)")
    li.add_argument("--time-map", choices=("log", "linear"), default="log", help="how sound time maps to the run's")
    li.add_argument("--pitch", choices=("auto", "linear"), default="auto",
                    help="linear: every frequency times one factor; auto: that, unless the frequency falls more than "
                         "16x, which is then compressed into 16x (default)")
    li.add_argument("--dynamic-range-db", type=real, default=60.0,
                    help="the field's range in dB is compressed into this many dB of sound when larger (default 60)")
    add_detector_options(li, hidden=("integration_s", "antenna_gain_dbi", "noise_temperature_k"))
    li.add_argument("--samples", type=positive, default=800, help="evenly spaced plus as many log-spaced instants")


def run(args) -> int:
    """Carry out ``spinviz listen`` with the parsed ``args``; return its exit status."""
    from .. import experiment
    from ..analysis import sonify

    need_matplotlib("listen's spectrogram")
    try:
        mapping = experiment.listen(args.scene, args.out, png=args.png, duration=args.duration, f0=args.f0,
                                    time_map=args.time_map, pitch=args.pitch, dynamic_range_db=args.dynamic_range_db,
                                    samples=args.samples, line_of_sight=args.line_of_sight, **receiver_options(args))
    except SimulationError as e:
        raise SimulationError(f"{args.scene}: {e}") from None
    except OSError as e:
        raise cannot_write(args.out, e) from None
    png = args.png or os.path.splitext(args.out)[0] + ".png"
    out(f"{p(args.out)}: {mapping.duration_s:g} s, {mapping.rate} Hz, 16-bit stereo")
    out(mapping.statement())
    if mapping.dropped_above_nyquist:
        out(f"note: {mapping.dropped_above_nyquist} line(s) above {sonify.NYQUIST_SHARE * mapping.rate:.0f} Hz left "
            f"out (lower --f0 to hear them)")
    if mapping.below_audible_s > 0.0:
        out(f"note: for {mapping.below_audible_s:.1f} s the strongest line is below 20 Hz (raise --f0)")
    out(f"{p(png)}: spectrogram of the WAV")
    return EXIT_OK
