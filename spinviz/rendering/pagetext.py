"""The words of the turnable page: ``page_texts(plan)``.

A page is read by people who came for the crystals, not for the paper: on an ``"outreach"``
scene (``[render].captions``) every caption is in plain words -- what the two crystals are
and what differs between them, in one sentence up front; the headings without equation
numbers; the time in days or years, the slider marked in them; the spin's slowdown in words
-- and a text alternative says what the 3-D view shows.  A ``"physics"`` scene keeps the
video's captions (``captions.texts_of``: equation numbers, Θ, ∠(d, L)).  Pure Python and
NumPy; every text here reaches the page as text (escaped markup, or set with textContent).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..presentation import style as model_style
from .captions import (
    Captions,
    _deg,
    _people_unit,
    nice_step,
    people_time,
    radiation_band,
    sci,
    texts_of,
    words,
)

__all__ = ["PageTexts", "page_texts", "ARROW_LABELS", "big_words"]

ARROW_LABELS = {"dipole": "d", "L": "L", "omega": "Ω"}      # on the arrows in the view
PLAIN_LEGEND = {"dipole": "the dipole: where the crystal's electric charges point",
                "L": "the spin axis (angular momentum)", "omega": "the rotation axis at this moment"}
SHAPE_WORDS = {"omega": "blue", "L": "green", "dipole": "red"}


@dataclass
class PageTexts:
    """Everything the page says, for n panels and F frames.

    title; lead : one sentence, what the crystals are and what differs; headings : per panel
    (heading, secondary: equation numbers or ""); subtitles : per panel; legend : (key,
    symbol, words) per drawn arrow (and the stand-in body); scale : what the slider spans;
    ticks : (position 0..1, label) of its marks; time, notes, readouts : per frame (readouts
    per panel, then frame: lines); alt : the text alternative of the 3-D view; how : what the
    controls do; no_webgl : what a browser without WebGL is told; one : a single panel.
    """

    title: str
    lead: str
    headings: list
    subtitles: list
    legend: list
    scale: str
    ticks: list
    time: list
    notes: list
    readouts: list
    alt: str
    how: str
    no_webgl: str
    one: bool


def big_words(x: float) -> str:
    """A large factor for people: "870", "5 billion", "1.3 million billion"."""
    if x >= 1e15:
        return big_words(x / 1e9) + " billion"
    return words(x, 2)


def page_texts(plan) -> PageTexts:
    """The page's words for ``plan``, in plain words on an outreach scene.

    Parameters
    ----------
    plan : FramePlan

    Returns
    -------
    PageTexts
    """
    video = texts_of(plan)
    n = len(plan.panels)
    one = n == 1
    alt = _alt(plan)
    how = ("Drag to turn the crystal" if one else "Drag to turn both crystals") + \
        ", pinch or scroll to zoom; Play and the slider run the video's clock."
    no_webgl = ("This browser cannot draw 3-D (no WebGL), so the picture shows the start only; the captions and "
                "the slider still work, and the video shows the same motion.")
    if plan.spec.captions == "physics":
        return PageTexts(title=video.footer, lead=_lead_physics(plan), headings=[list(h) for h in video.headings],
                         subtitles=list(video.subtitles), legend=[(k, s, nm) for k, s, nm in video.legend],
                         scale=video.scale, ticks=list(video.bar_ticks), time=list(video.time), notes=list(video.notes),
                         readouts=video.readouts, alt=alt, how=how, no_webgl=no_webgl, one=one)
    cap = Captions(plan)
    legend = [(k, ARROW_LABELS[k], PLAIN_LEGEND[k]) for k, _, _ in cap.legend(plan.spec.show)]
    if "body" in plan.spec.show and plan.shape is not None and "inertia" in plan.shape.label:
        legend.append(("body", "box", "the crystal's shape is not known: a box that turns as it would"))
    F = plan.frames
    return PageTexts(
        title=video.footer, lead=_lead(plan), headings=[[_heading(p.model, "outreach")[0], ""] for p in plan.panels],
        subtitles=list(video.subtitles), legend=legend, scale=_scale(plan), ticks=_ticks(plan),
        time=[_time(plan, f) for f in range(F)], notes=[_notes(plan, f) for f in range(F)],
        readouts=[[_readouts(plan, k, f) for f in range(F)] for k in range(n)], alt=alt, how=how,
        no_webgl=no_webgl, one=one)


def _what(plan) -> tuple[str, str]:
    """(the crystal in words, the radiation in words)."""
    cgs = plan.units == "cgs"
    if cgs:
        w = max(float(p.omega_mag[0]) for p in plan.panels)
        rays = f"{radiation_band(w)} waves"
    else:
        rays = "radiation"
    thing = "crystal" if cgs else "spinning top"
    name = plan.body_name
    return (f"{thing} ({name})" if name and name.lower() not in (thing, "symmetric top", "custom body") else thing,
            rays)


def _heading(model: str, register: str) -> tuple[str, str]:
    """The model's (name, equations) over a panel in ``register`` (``presentation``)."""
    return model_style(model).heading.get(register, (model, ""))


def _model_words(model: str) -> str:
    return model_style(model).phrase or f"the {model} equation"


def _lead(plan) -> str:
    """One sentence: what the crystals are and what differs between them."""
    thing, rays = _what(plan)
    models = [p.model for p in plan.panels]
    if len(models) == 1:
        how = "as " + _model_words(models[0]) + " describes that braking" if models[0] != "free" else \
            "shown with no braking at all"
        return f"A {thing}, set spinning, is slowed by the {rays} it gives off, {how}."
    if models[0] == models[1]:
        return (f"Two runs of the same {thing} under {_model_words(models[0])}, side by side, each slowed by the "
                f"{rays} it gives off.")
    a, b = (_model_words(m) for m in models)
    return (f"Two copies of the same {thing}, set spinning the same way, are slowed by the {rays} they give off; "
            f"they differ only in the theory of that braking: {a} or {b}, each shown under its name.")


def _lead_physics(plan) -> str:
    names = [" ".join(x for x in _heading(p.model, "physics") if x) for p in plan.panels]
    body = plan.body_name
    if len(names) == 1:
        return f"{body} under the {names[0]} equation of motion."
    return f"{body} from one start under two equations of motion: {names[0]} and {names[1]}."


def _alt(plan) -> str:
    """What the 3-D view shows, for someone who cannot see it."""
    show = plan.spec.show
    n = len(plan.panels)
    body = {"rod": "a rod", "box": "a box"}.get(plan.shape.kind if plan.shape else "", "a ball")
    parts = []
    if "body" in show:
        parts.append(f"{body} (the crystal)")
    for key in ("dipole", "L", "omega"):
        if key in show:
            parts.append(f"a {SHAPE_WORDS[key]} arrow labelled {ARROW_LABELS[key]} ({PLAIN_LEGEND[key]})")
    inside = " inside a wire sphere" if "sphere" in show else ""
    what = ", ".join(parts) if parts else "the crystal"
    names = [_heading(p.model, "outreach")[0] for p in plan.panels]
    if n == 1:
        where = f"A turnable 3-D view of {what}{inside}, under the heading {names[0]}."
    else:
        where = (f"A turnable 3-D view in two parts, the same drawing twice: {what}{inside}; first under the heading "
                 f"{names[0]}, then under {names[1]}.")
    return (where + " As the video plays the crystal turns and its arrows swing; the numbers under each part and the "
            "time below say what it shows at each moment.")


def _scale(plan) -> str:
    """What the slider spans, in people's units."""
    if plan.units == "cgs":
        return f"The slider spans {people_time(plan.t_end)} of the crystal's life."
    return (f"The slider spans {plan.t_end:.3g} τ₀; τ₀ is the paper's unit of time, "
            f"set by the crystal's size and charge.")


def _ticks(plan) -> list:
    """The slider's marks in people's units (CGS: days, years, ...) or τ₀."""
    spec, t_end = plan.spec, plan.t_end
    if plan.units == "cgs":
        unit, sym = _people_unit(t_end)
        long = {"yr": "years", "d": "days", "h": "hours", "min": "min", "s": "s"}[sym]
    else:
        unit, long = 1.0, "τ₀"
    end = t_end / unit
    if spec.time_map == "linear":
        step = nice_step(end, 6)
        vals = [step * i for i in range(1, int(end / step * (1 + 1e-9)) + 1)]
    else:
        k = spec.knee(t_end) / unit
        lo = math.floor(math.log10(k))
        vals = [10.0 ** e for e in range(lo, math.ceil(math.log10(end)) + 1) if k * 0.5 <= 10.0 ** e <= end * (1 + 1e-9)]
    return [(float(spec.video_fraction(v * unit, t_end)), f"{v:g} {long}") for v in vals]


def _time(plan, f: int) -> str:
    t = float(plan.sim_t[f])
    if t <= 0.0:
        return "at the start"
    return "after " + (people_time(t) if plan.units == "cgs" else f"{t:.3g} τ₀")


def _notes(plan, f: int) -> list[str]:
    out = []
    if plan.spin_mode == "slowed":
        factor = float(plan.slowdown[f])
        if factor >= 1.0:
            out.append(f"The real crystal spins {big_words(factor)} times faster than shown: slowed down so you can "
                       f"see it turn.")
        else:
            out.append(f"The real crystal spins {big_words(1.0 / factor)} times slower than shown: sped up so you "
                       f"can see it turn.")
    elif plan.spin_mode == "aliased":
        out.append("The crystal spins too fast for the video: its turning is shown only roughly.")
    if not plan.phase_resolved and plan.spin_mode != "slowed":
        out.append("Over this long a time its exact angle cannot be computed: the pose is illustrative.")
    if plan.spec.time_map == "log":
        out.append("Time speeds up as the video plays: each mark on the slider is ten times later than the one "
                   "before.")
    return out


def _readouts(plan, k: int, f: int) -> list[str]:
    p = plan.panels[k]
    w = float(p.omega_mag[f])
    out = [f"turns {words(w / (2 * math.pi))} times a second" if plan.units == "cgs"
           else f"spin rate {sci(w, 2)} per τ₀"]
    if p.angle_dL_range_deg is not None:
        lo, hi = p.angle_dL_range_deg[f]
        out.append(f"dipole at {_deg(lo)}–{_deg(hi)} to the spin axis as it wobbles" if hi - lo >= 0.5
                   else f"dipole at {_deg(0.5 * (lo + hi))} to the spin axis")
    elif p.angle_dL_deg is not None:
        out.append(f"dipole at {_deg(float(p.angle_dL_deg[f]))} to the spin axis")
    return out
