"""
Reduced against truncated: the DAST cube
========================================

The paper's central question, on its own example: the 100 nm DAST cube of section 6.2 with
its real parameters (τ0 = 3.7e-27 s), spun at Ω20 = Ω30 = π·1e10 rad/s with the dipole
along e3, integrated over 6 Θ (19 days) by both equations of motion from the same start.

* The **reduced** equation (2.2)+(2.3) drives the dipole onto the rotation axis,
  θ ~ exp(−t/Θ) (6.7), (6.8): the crystal keeps spinning about its dipole.
* The **truncated** equation (2.5) spins the crystal down by a power law and keeps the
  dipole at 45° from the axis (6.9), (6.10).

This is what ``spinviz compare scenes/dast_cube.toml`` prints and draws, from Python:
``spinviz.compare`` runs both models at the same instants and returns the comparison.
The crystal turns about 10¹⁶ times in 19 days (the run below says how many), far beyond
float64's hold on the spin phase, so ``auto`` follows it with the ``secular`` method and
the models are compared by the slow, physical angle between d and L rather than turn by
turn.
"""

# %%
# One run first, to see which method ``auto`` picks and why: the scene's own request for
# the reduced model (``Scene.request``), run by ``spinviz.simulate_request``.
import spinviz

sc = spinviz.load_scene("../scenes/dast_cube.toml")
tr = spinviz.simulate_request(sc.request("reduced"))
print(tr)
print(f"{tr.stats['turns']:.3g} turns; method {tr.stats['method']}: {tr.stats['method_reason']}")

# %%
# Both models at the output times ``spinviz compare`` uses (evenly spaced plus as many
# log-spaced, so that both the early parting and the late asymptotics show): when the two
# predictions part, and how each run ends.  ``plots="dast_cube"`` writes the command's two
# pictures.  The first: how far apart the predictions are (left), the spin rate (middle:
# the truncated cube keeps slowing by a power law, the reduced one levels off at Ω3, 1/√2 of
# the start) and the angle between the dipole and the angular momentum (right: 45° kept, or
# brought to 0 within a few Θ).  The second: the hodographs of Ω in the body frame, as in
# the paper's figures 3 and 4.  A cube is a spherical top, so nothing precesses in the body
# frame: the reduced cube loses its cross spin Ω⊥ at constant Ω3 (a straight drop onto the
# e3 axis, the residual rotation about d), the truncated one shrinks along its own direction
# towards rest.
c = spinviz.compare(sc, samples=400, plots="dast_cube")
print(c.table())
