"""
What a receiver would see
=========================

The paper's conclusion proposes to watch a spun-up 100 nm DAST cube for a few days and
decide between the two balance laws.  ``spinviz observe`` computes what a stated receiver
records from each model -- here the scene's default one: an antenna of 5 dBi, both
polarizations, 10 cm from the crystal, 5 K of system noise, a 1 MHz band following the line,
1 s per estimate -- how finely it measures the crystal's line (the Cramér–Rao bounds of
frequency, power and polarization angle), and when the two predictions part against the
resolution.  The receiver, its bounds and their checks: :doc:`../experiment`.
"""

# %%
# Both models of the scene over its ``[observe]`` horizon, received by its ``[observe]``
# receiver along its line of sight (``spinviz.observe``; receiver keys such as
# ``distance_cm=20`` would replace the scene's).  ``plots="dast_cube"`` writes the command's
# three pictures, shown below in this order:
#
# * what each model sends toward the antenna -- power, the strongest spectral line, the
#   polarization angle -- and below each the time the models part against the resolution,
#   with this receiver's 5σ marked;
# * the detector's record: the spectrogram over the run, the signal strength, and the
#   waveform at four instants (its spin phase reconstructed, as the plot says);
# * the receiver's view: the SNR of the line over the run, the resolutions of one
#   integration, the field at the antenna with all its terms, and the start-free test of
#   each model's own noisy line against the laws P ∝ f⁴ and P ∝ f²(f² − f∞²).
import spinviz

obs = spinviz.observe("../scenes/dast_cube.toml", samples=400, plots="dast_cube")
print(obs.table())
