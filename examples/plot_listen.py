"""
The detector's signal as sound
==============================

``spinviz listen`` replays what the detector of :doc:`plot_observe` receives as a 20-second
stereo WAV, the reduced model in the left ear and the truncated one in the right: time on a
logarithmic scale (20 s of sound for the 19 days of the run), every frequency multiplied by
one factor (the initial rotation sounds at 440 Hz), loudness from the field along the
initial polarization, one scale for both ears.  The mappings are printed, written into the
WAV's INFO chunk and onto its spectrogram.  The DAST cube: two A4s gliding down, the left
one levelling off as it fades away (the dark residual rotation about d), the right one
sliding on and staying audible.
"""

# %%
# Simulate, detect and synthesize (``spinviz.listen``, the command's own call); the WAV goes
# to a scratch folder (removed after), its spectrogram (the file as written, read back) is
# shown below.
import tempfile
from pathlib import Path

import spinviz

with tempfile.TemporaryDirectory() as scratch:
    wav = Path(scratch) / "dast_cube.wav"
    mapping = spinviz.listen("../scenes/dast_cube.toml", str(wav), png="dast_cube_listen.png", duration=20.0)
    print(f"{wav.name}: {mapping.duration_s:g} s, {mapping.rate} Hz, 16-bit stereo, {wav.stat().st_size / 1e6:.1f} MB")
print(mapping.statement())
