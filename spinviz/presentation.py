"""How each model is presented wherever it is drawn: its colour, its line in the plots and its
words on screen -- one table for the videos, the web page, the glTF and every plot.

The equations themselves are ``physics.models``; a registered model needs a row here too
(``tests/test_models.py`` holds every registered model to it).  Plain data; imports nothing.
Colours are RGB integers in 0..255.
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["ModelStyle", "STYLES", "style", "color_hex", "line_kwargs"]


@dataclass(frozen=True)
class ModelStyle:
    """A model's presentation.

    color : RGB 0..255, the same in headings, insets, plots and pages.
    line : (matplotlib line style, width) in the plots (both visible where two models coincide).
    heading : {"outreach": (name, equations), "physics": (name, equations)} over a panel.
    subtitle : {"outreach": ..., "physics": ...}: what the model predicts in general, one line.
    phrase : the model in a sentence for people ("the reduced equation").
    """

    color: tuple[int, int, int]
    line: tuple[str, float]
    heading: dict
    subtitle: dict
    phrase: str = ""


STYLES = {
    "reduced": ModelStyle(
        color=(0, 128, 128), line=("-", 2.4),
        heading={"outreach": ("Reduced equation", "(2.2)+(2.3)"), "physics": ("reduced", "(2.2)+(2.3)")},
        subtitle={"outreach": "radiation slows the tumbling; a spin about the dipole can last",
                  "physics": "Ω̇, Ω̈ in the torque taken from the free motion"},
        phrase="the reduced equation"),
    "truncated": ModelStyle(
        color=(136, 60, 180), line=("--", 1.7),
        heading={"outreach": ("Truncated equation", "(2.5)"), "physics": ("truncated", "(2.5)")},
        subtitle={"outreach": "radiation slows every rotation, all the way to rest",
                  "physics": "textbook torque without the Schott-like term"},
        phrase="the truncated equation"),
    "free": ModelStyle(
        color=(120, 120, 120), line=(":", 1.7),
        heading={"outreach": ("No radiation", "(2.3a)"), "physics": ("free", "d = 0")},
        subtitle={"outreach": "no braking: the top turns freely", "physics": "torque-free Euler top"},
        phrase="no braking at all"),
}

# what a name without a row gets (a model registered in a session without its presentation)
_FALLBACK = ModelStyle(color=(90, 90, 90), line=("-", 1.7), heading={}, subtitle={})


def style(model: str) -> ModelStyle:
    """The model's row of ``STYLES`` (a neutral grey row for a name without one)."""
    return STYLES.get(model, _FALLBACK)


def color_hex(model: str) -> str:
    """The model's colour as "#rrggbb" (matplotlib, CSS)."""
    return "#{:02x}{:02x}{:02x}".format(*style(model).color)


def line_kwargs(model: str, **kw) -> dict:
    """matplotlib keywords of the model's curve: colour, line style, width (``kw`` overrides)."""
    ls, lw = style(model).line
    return {"color": color_hex(model), "ls": ls, "lw": lw, **kw}
