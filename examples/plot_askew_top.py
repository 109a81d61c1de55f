"""
An askew top: one run, its data and its hodographs
==================================================

A symmetric top whose dipole is tilted from its axis (δ = 1 − I3/I1, χ = the dipole's
angle from e3) is the paper's general case (section 4), in the dimensionless variables
(4.1) with τ0 = 1.  One run of the reduced equation: its summary, its three standard plots
and its arrays as an xarray Dataset; then both equations from the same start, as the
paper's figures 3 and 4 draw them.
"""

# %%
# The scene example of the documentation: δ = 0.3, χ = 0.7 rad, reduced equation.

# sphinx_gallery_thumbnail_number = 3
import spinviz

sc = spinviz.load_scene("../scenes/askew_example.toml")
tr = spinviz.simulate(sc.body, "reduced", sc.omega0, t_end=1200.0, samples=400, q0=sc.q0)
print(tr)

# %%
# ``Trajectory.plot()`` returns a matplotlib figure: the spin rate (log-log), the angle
# between d and L, and the hodograph of ω in the body frame.
fig = tr.plot()

# %%
# The same run as labelled arrays with units (``Trajectory.to_xarray``).
ds = tr.to_xarray()
print(ds)

# %%
# Both equations from the same start, δ = −0.6, χ = 55° (the DAST family-1 line of figure
# 5), to τ = 4000, by ``spinviz.compare``: the table says when the two predictions part;
# the pictures are how far apart they are and the hodographs of ω in the body frame.  Here
# the phases are resolved, so the whole rotations are compared, not only angle(d, L).
c = spinviz.compare("../scenes/hodograph_askew.toml", plots="askew")
print(c.table())
