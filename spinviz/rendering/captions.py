"""The words and numbers on screen, in two registers: ``"outreach"`` (plain words, numbers
for people) and ``"physics"`` (symbols, equation numbers, scientific notation).

``texts_of(plan)`` says everything once, as plain data (``Texts``: the headings, the legend,
the time bar's ticks, and per frame the panels' numbers, the time and the notes); ``layout``
and ``overlay`` decide where it goes.  Pure Python and NumPy.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .. import units as U
from ..presentation import style as model_style

ARROW_NAMES = {"dipole": ("d", "dipole"), "L": ("L", "angular momentum"), "omega": ("Ω", "rotation")}

# the unit the power plot is drawn in: W for CGS scenes (the physics stays in erg/s), and the
# unit of the dimensionless variables (4.1) otherwise
POWER_UNIT = {"cgs": "W", "dimensionless": "I₁/τ₀³"}
# what a lay viewer calls radiation of a frequency, Hz: radio up to 300 GHz (microwaves included),
# infrared up to 400 THz, then light
BANDS = ((3e11, "radio"), (4e14, "infrared"), (math.inf, "light"))

_SUP = str.maketrans("0123456789-", "⁰¹²³⁴⁵⁶⁷⁸⁹⁻")
_WORDS = ((1e12, "trillion"), (1e9, "billion"), (1e6, "million"), (1e3, "thousand"))


def superscript(n: int) -> str:
    """An integer in superscript digits: 15 -> "¹⁵"."""
    return str(int(n)).translate(_SUP)


def decade(e: int) -> str:
    """A power of ten as a tick label: -17 -> "10⁻¹⁷", 0 -> "1", 1 -> "10"."""
    return {0: "1", 1: "10"}.get(int(e), f"10{superscript(e)}")


def radiation_band(omega: float) -> str:
    """The everyday name of the radiation of a dipole turning at ``omega`` rad/s: "radio",
    "infrared" or "light", judged at the rotation frequency |Omega|/2 pi (where a turning
    dipole radiates; 7 GHz for the DAST cube: radio)."""
    f = abs(float(omega)) / (2.0 * math.pi)
    return next(name for top, name in BANDS if f < top)


def sci(x: float, digits: int = 2) -> str:
    """x with ``digits`` significant figures, as "3.8 × 10¹⁵" when it is large or small."""
    x = float(x)
    if not math.isfinite(x) or x == 0.0:
        return f"{x:g}"
    e = math.floor(math.log10(abs(x)))
    m = round(x / 10.0**e, digits - 1)
    if abs(m) >= 10.0:
        m, e = m / 10.0, e + 1
    if -3 <= e < 4:
        return f"{x:.{digits}g}"
    return f"{m:.{digits - 1}f} × 10{superscript(e)}"


def words(x: float, digits: int = 2) -> str:
    """A count for people: "5 billion", "1.3 million", "870"; beyond a trillion, "3.8 × 10¹⁵"."""
    x = float(x)
    a = abs(x)
    if not math.isfinite(x):
        return f"{x:g}"
    if a >= 1e15:
        return sci(x, digits)
    for scale, name in _WORDS:
        if a >= scale:
            return f"{_sig(x / scale, digits)} {name}"
    return _sig(x, digits) if a >= 1 else f"{x:.{digits}g}"


def _sig(x: float, digits: int) -> str:
    """Significant figures without exponent and without trailing zeros: 5, 1.3, 870."""
    if x == 0:
        return "0"
    places = max(0, digits - 1 - math.floor(math.log10(abs(x))))
    s = f"{x:.{places}f}"
    return s.rstrip("0").rstrip(".") if "." in s else s


def people_time(seconds: float) -> str:
    """A duration for people: "40 s", "23 minutes", "9.5 days", "1.3 million years"."""
    s = float(seconds)
    if not math.isfinite(s):
        return f"{s:g} s"
    a = abs(s)
    if a < 1.0:
        return f"{sci(s, 2)} s" if a > 0 else "0 s"
    value, unit = U.time_in_unit(s, long_names=True, years_from=2 * U.YEAR)
    return f"{words(value, 2) if unit == 'years' else _sig(value, 2)} {unit}"


def sim_time(t: float, units: str, register: str) -> str:
    """A simulation time in the scene's units: people's units (CGS), or tau0 (dimensionless)."""
    if units != "cgs":
        return f"{_sig(t, 3) if t >= 1 else f'{t:.2g}'} τ₀"
    if register == "outreach":
        return people_time(t)
    return U.human_time(t)


@dataclass
class Texts:
    """Every text of a video, F frames and n panels.

    headings : per panel (heading, equation numbers); subtitles : per panel, one line (the
    layout wraps it); legend : (key, symbol, name) per drawn arrow, and the body's entry when
    the drawn body is a stand-in; footer : the title line; scale : what the time bar's unit is
    ("" without one); bar_ticks : (position 0..1, label) of its marks; readouts : [panel][frame]
    -> lines; time : per frame; notes : per frame -> lines (how time and spin are shown);
    plot_titles : the title of each live plot shown ("angle", "omega" for ``inset``,
    "power"), in the inset's order.
    """

    headings: list
    subtitles: list
    legend: list
    footer: str
    scale: str
    bar_ticks: list
    readouts: list
    time: list
    notes: list
    plot_titles: dict = field(default_factory=dict)


def texts_of(plan) -> Texts:
    """All the words of ``plan``, in the register of its ``[render].captions``.

    Parameters
    ----------
    plan : FramePlan
        Frame times (scene unit), |Omega| per panel (rad/s or 1/tau0), angles (deg).

    Returns
    -------
    Texts
        Headings, subtitles, legend, footer, the time bar's scale and ticks, and per frame
        (F of each) the panels' numbers, the time and the notes.
    """
    cap = Captions(plan)
    n, F = len(plan.panels), plan.frames
    show = plan.spec.show
    legend = cap.legend(show)
    if "body" in show and plan.shape is not None and "inertia" in plan.shape.label:
        legend.append(("body", "box", "with the top's inertia"))      # the drawn body is not the crystal's shape
    return Texts(headings=[cap.heading(k) for k in range(n)], subtitles=[cap.subtitle(k) for k in range(n)],
                 legend=legend, footer=cap.footer(), scale=cap.scale_text(), bar_ticks=cap.bar_ticks(),
                 readouts=[[cap.readouts(k, f) for f in range(F)] for k in range(n)],
                 time=[cap.time_text(f) for f in range(F)], notes=[cap.notes(f) for f in range(F)],
                 plot_titles=cap.plot_titles(show))


class Captions:
    """The texts of a plan's frames in the register of its ``[render].captions``."""

    def __init__(self, plan):
        self.plan = plan
        self.spec = plan.spec
        self.register = plan.spec.captions
        self.cgs = plan.units == "cgs"

    # -- per panel -------------------------------------------------------------------------
    def heading(self, k: int) -> tuple[str, str]:
        """(heading, secondary text: the equation numbers) of panel k."""
        model = self.plan.panels[k].model
        return model_style(model).heading.get(self.register, (model, ""))

    def subtitle(self, k: int) -> str:
        """Panel k's plain-words line: the scene's ``[render].subtitles``, or what its model predicts."""
        subs = self.spec.subtitles
        if k < len(subs):
            return subs[k]
        return model_style(self.plan.panels[k].model).subtitle.get(self.register, "")

    def readouts(self, k: int, f: int) -> list[str]:
        """Panel k's numbers at frame f: its spin rate and the angle between d and L."""
        p = self.plan.panels[k]
        w = float(p.omega_mag[f])
        out = []
        if self.cgs and self.register == "outreach":
            out.append(f"turns {words(w / (2 * math.pi))} times a second")
        elif self.cgs:
            out.append(f"|Ω| = {sci(w, 3)} rad/s")
        else:
            out.append(f"|ω| = {w:.3g} /τ₀")
        name = "angle d–L" if self.register == "outreach" else "∠(d, L)"
        if p.angle_dL_range_deg is not None:
            lo, hi = p.angle_dL_range_deg[f]
            if hi - lo < 0.5:
                out.append(f"{name} = {_deg(0.5 * (lo + hi))}")
            else:
                out.append(f"{name} swings {_deg(lo)}–{_deg(hi)} each turn")
        elif p.angle_dL_deg is not None:
            out.append(f"{name} = {_deg(p.angle_dL_deg[f])}")
        return out

    # -- shared ----------------------------------------------------------------------------
    def time_text(self, f: int) -> str:
        """The simulation time of frame f: "after 9.5 days" (outreach), "t = 8.2e5 s = 3.01 Θ" (physics)."""
        t = float(self.plan.sim_t[f])
        if self.register == "outreach":
            return ("after " if t > 0 else "start, ") + sim_time(t, self.plan.units, "outreach")
        text = f"t = {sim_time(t, self.plan.units, 'physics')}"
        ts = self.plan.time_scale
        if ts is not None:
            text += f" = {t / ts[1]:.2f} {ts[0]}"
        return text

    def scale_text(self) -> str:
        """What the time bar's unit is: "Θ = 3.2 days" (empty without a scale)."""
        ts = self.plan.time_scale
        if ts is None:
            return ""
        return f"{ts[0]} = {sim_time(ts[1], self.plan.units, self.register)}"

    def notes(self, f: int) -> list[str]:
        """How time and spin are shown: the slowed spin's factor, the log time axis, and any
        phase that is not the true one."""
        plan, out = self.plan, []
        outreach = self.register == "outreach"
        if plan.spin_mode == "slowed":
            factor = float(plan.slowdown[f])
            if factor >= 1.0:
                x = sci(factor, 2)
                out.append(f"spin shown {x} times slower" if outreach else f"spin shown slowed {x}×")
            else:                                   # a slow top shown at the set turn rate
                x = sci(1.0 / factor, 2)
                out.append(f"spin shown {x} times faster" if outreach else f"spin shown sped up {x}×")
        elif plan.spin_mode == "aliased":
            out.append("spin too fast for the frame rate: shown aliased" if outreach
                       else "spin aliased (too fast for the frame rate)")
        if not plan.phase_resolved and plan.spin_mode != "slowed":
            out.append("spin phase not resolved: the pose is illustrative")
        if self.spec.time_map == "log":
            if outreach:
                out.append("log time: ticks 10× apart")
            else:
                k = self.spec.knee(plan.t_end)
                out.append(f"time axis logarithmic after {sim_time(k, plan.units, 'physics')}")
        return out

    def plot_titles(self, show) -> dict[str, str]:
        """The titles of the live plots ``show`` asks for: angle(d, L) and |Omega| / |Omega(0)|
        ("inset"), the radiated power ("power")."""
        out = {}
        if "inset" in show:
            out["angle"] = "∠(d, L)"
            out["omega"] = "|Ω| / |Ω₀|" if self.cgs else "|ω| / |ω₀|"
        if "power" in show:
            out["power"] = self.power_title()
        return out

    def power_title(self) -> str:
        """The title of the radiated-power plot, with its unit: "radio power (W)" (outreach; the
        band named from the highest rotation rate shown), "P (W)" (physics); in I1/tau0^3 for a
        dimensionless scene ("radiated power": no frequency is known there)."""
        if not self.cgs:
            return f"{'radiated power' if self.register == 'outreach' else 'P'} ({POWER_UNIT['dimensionless']})"
        if self.register == "physics":
            return f"P ({POWER_UNIT['cgs']})"
        w = max(float(np.max(p.omega_mag)) for p in self.plan.panels)
        return f"{radiation_band(w)} power ({POWER_UNIT['cgs']})"

    def footer(self) -> str:
        """The title line: the scene's title, or the body's name."""
        return self.spec.title or self.plan.body_name

    def legend(self, show) -> list[tuple[str, str, str]]:
        """(key, symbol, name) of each drawn arrow."""
        return [(key, *ARROW_NAMES[key]) for key in ("dipole", "L", "omega") if key in show]

    def bar_ticks(self) -> list[tuple[float, str]]:
        """(position 0..1 along the time bar, label) of its marks: multiples of Theta or T
        (linear map) or their decades (log map); in people's units (CGS) or tau0 without a scale."""
        plan, spec, t_end = self.plan, self.spec, self.plan.t_end
        if plan.time_scale is not None:
            sym, unit = plan.time_scale
            suffix = f" {sym}"
        elif self.cgs:
            unit, sym = _people_unit(t_end)
            suffix = f" {sym}"
        else:
            unit, suffix = 1.0, " τ₀"
        end = t_end / unit
        if spec.time_map == "linear":
            step = nice_step(end, 6)
            vals = np.arange(step, end * (1 + 1e-9), step)
        else:
            k = spec.knee(t_end) / unit
            lo = math.floor(math.log10(k))
            vals = np.array([10.0 ** e for e in range(lo, math.ceil(math.log10(end)) + 1) if 10.0 ** e <= end * (1 + 1e-9)])
            vals = vals[vals >= k * 0.5]
        return [(float(spec.video_fraction(v * unit, t_end)), _fmt_tick(float(v)) + suffix) for v in vals]


def nice_step(span: float, most: int) -> float:
    """The smallest of 1, 2, 5 x 10^k that cuts ``span`` into at most ``most`` steps (ticks)."""
    raw = span / max(1, most)
    e = 10.0 ** math.floor(math.log10(raw))
    for m in (1.0, 2.0, 5.0, 10.0):
        if m * e >= raw:
            return m * e
    return 10.0 * e


def _fmt_tick(x: float) -> str:
    return f"{x:g}" if abs(x) >= 1e-3 or x == 0 else f"{x:.0e}"


def _people_unit(t_end: float) -> tuple[float, str]:
    """The largest of yr, d, h, min that t_end (s) holds twice, else s."""
    for unit, name in ((U.YEAR, "yr"), (U.DAY, "d"), (U.HOUR, "h"), (U.MINUTE, "min")):
        if t_end >= 2 * unit:
            return unit, name
    return 1.0, "s"


def _deg(x: float) -> str:
    return f"{x:.0f}°" if x >= 9.5 else f"{x:.1f}°"
