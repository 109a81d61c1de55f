"""
What a detector would see
=========================

The paper's conclusion proposes to watch a spun-up 100 nm DAST cube for a few days and
decide between the two balance laws.  ``spinviz observe`` computes what a detector 1 cm
away, across the initial angular momentum, would record from each model -- the power it
receives, the strongest spectral line, the polarization angle -- and when the two
predictions part by more than the detector's resolution (a factor 2 in power, 1 % in
frequency, 5° in polarization).
"""

# %%
# Both models of the scene over its ``[observe]`` horizon, observed along its line of sight.
import spinviz
from spinviz.analysis import observe

sc = spinviz.load_scene("../scenes/dast_cube.toml")
obs, runs = observe.run_scene(sc, samples=400)
print(observe.format_table(obs))

# %%
# Each observable against time and its difference in units of the resolution: the models
# part in frequency within hours and in power within two days, never in polarization.
observe.plot(obs, "dast_cube_observe.png")

# %%
# The detector's record: the spectrogram over the run, the field strength, and the
# waveform at four instants (its spin phase reconstructed, as the plot says).
observe.plot_detector(obs, "dast_cube_detector.png")
