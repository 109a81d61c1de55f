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

This is what ``spinviz compare scenes/dast_cube.toml`` prints and draws, step by step from
Python.  The crystal turns ~5e15 times in 19 days, far beyond float64's hold on the spin
phase, so ``auto`` follows it with the ``secular`` method and the models are compared by
the slow, physical angle between d and L rather than turn by turn.
"""

# %%
# The scene, and both models at the output times ``spinviz compare`` uses (evenly spaced
# plus as many log-spaced, so that both the early parting and the late asymptotics show).
import spinviz
from spinviz.analysis import compare

sc = spinviz.load_scene("../scenes/dast_cube.toml")
times = compare.compare_times(sc.t_end, 400)
runs = [spinviz.simulate_request(sc.request(model, t_eval=times)) for model in sc.models]
for tr in runs:
    print(tr)
    print("   method:", tr.stats["method"], "--", tr.stats["method_reason"])

# %%
# When the two predictions part, and how each run ends.
c = compare.compare(runs)
print(compare.format_table(c, sc.title))

# %%
# The comparison's first plot: how far apart the predictions are (left: 1° after 1.3 hours,
# 10° after 16 hours), the spin rate (middle: the truncated cube keeps slowing by a power
# law, the reduced one levels off at Ω3, 1/√2 of the start) and the angle between the
# dipole and the angular momentum (right: 45° kept, or brought to 0 within a few Θ).
compare.plot(c, "dast_cube_compare.png", sc.title)

# %%
# The hodographs of Ω in the body frame, as in the paper's figures 3 and 4.  A cube is a
# spherical top, so nothing precesses in the body frame: the reduced cube loses its cross
# spin Ω⊥ at constant Ω3 (a straight drop onto the e3 axis, the residual rotation about d),
# the truncated one shrinks along its own direction towards rest.
compare.plot_hodograph(c, "dast_cube_hodograph.png", sc.title)
