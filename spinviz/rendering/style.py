"""Colours and sizes of everything drawn: the 3-D theme, the arrows, the HUD palette (each
model's own colour, line and words are ``spinviz.presentation``'s, shared with the plots).

Plain data; ``theme(background, body_name)`` gathers the colours of one video.  Imports nothing.
Colours of the 3-D scene are RGB floats in [0, 1]; colours of text and 2-D marks are RGB
integers in 0..255.  Lengths of the 3-D scene are in units of the dipole arrow (its tip
lies on the unit sphere).
"""

from __future__ import annotations

from dataclasses import dataclass

# the 3-D scene per background: sphere cage, its outline (limb), axes, trail; bg_rgb is the clear colour
COLORS = {
    "white": {"bg": "white", "sphere": (0.70, 0.72, 0.77), "limb": (0.55, 0.57, 0.63), "axes": (0.30, 0.30, 0.34),
              "trail": (0.86, 0.08, 0.24), "bg_rgb": (1.0, 1.0, 1.0)},
    "black": {"bg": "black", "sphere": (0.30, 0.32, 0.38), "limb": (0.45, 0.47, 0.53), "axes": (0.75, 0.75, 0.78),
              "trail": (1.0, 0.3, 0.4), "bg_rgb": (0.0, 0.0, 0.0)},
}
BODY_COLORS = {"DAST": (0.96, 0.52, 0.16), "cellulose": (0.93, 0.74, 0.38)}
ROD_SECOND_COLOR = (0.28, 0.16, 0.07)      # the rod's dark half: its axial spin shows
BODY_COLOR = (0.72, 0.66, 0.58)
DIPOLE_COLOR = (0.86, 0.08, 0.24)
OMEGA_COLOR = (0.12, 0.35, 0.85)
L_COLOR = (0.10, 0.58, 0.25)
HODO_COLOR = (0.12, 0.35, 0.85)            # omega's curve: the colour of the Omega arrow
HODO_MARKER_COLOR = (0.10, 0.10, 0.12)      # "now" on the curve
ARROW_COLORS = {"dipole": DIPOLE_COLOR, "omega": OMEGA_COLOR, "L": L_COLOR}

# arrow geometry, in units of the dipole arrow: shaft radius, head length, head radius, and the
# length at full magnitude; the part beyond ARROW_BASE (about the body's surface) grows with
# |Omega| and |L| relative to their start, so the braking shows in the arrows.  Omega is thin
# and longer than L: for a sphere they are parallel and both stay visible.
ARROWS = {"dipole": (0.024, 0.20, 0.065, 1.0), "L": (0.034, 0.21, 0.08, 1.35), "omega": (0.016, 0.17, 0.052, 1.6)}
ARROW_BASE = 0.55
AXIS_LENGTH = 1.25
BODY_RADIUS = 0.62       # the body's bounding radius (the dipole arrow's tip is on the unit sphere)
TRAIL_POINTS = 64
AMBIENT = 0.30           # CPU lighting of the solids: ambient term, then Lambert from the lights
VIEW_ANGLE = 30.0        # the camera's vertical view angle, deg


@dataclass(frozen=True)
class Palette:
    """Colours of text and 2-D marks (RGB 0..255): fg (numbers), bg, muted (labels), track and
    fill (the time bar before and after now), divider (between panels, plot frames)."""

    fg: tuple
    bg: tuple
    muted: tuple
    track: tuple
    fill: tuple
    divider: tuple


def palette(background: str) -> Palette:
    """The HUD colours for a ``[render].background`` ("white" or "black")."""
    if background == "black":
        return Palette(fg=(235, 235, 235), bg=(0, 0, 0), muted=(165, 165, 170), track=(45, 45, 52),
                       fill=(70, 92, 130), divider=(90, 90, 96))
    return Palette(fg=(25, 25, 28), bg=(255, 255, 255), muted=(105, 105, 112), track=(232, 233, 237),
                   fill=(190, 205, 230), divider=(175, 175, 180))


def body_color(name: str) -> tuple[float, float, float]:
    """The body's colour (RGB floats) from its name: DAST orange, cellulose straw, else a neutral tan."""
    for key, color in BODY_COLORS.items():
        if key.lower() in name.lower():
            return color
    return BODY_COLOR


@dataclass(frozen=True)
class Theme:
    """The colours of one video: ``scene`` (the 3-D theme, ``COLORS[background]``: RGB floats
    under "sphere", "limb", "axes", "trail", "bg_rgb"), ``body`` (RGB floats), ``hud`` (the
    ``Palette``), ``chips`` (legend chips, RGB 0..255, per arrow key and "body")."""

    scene: dict
    body: tuple
    hud: Palette
    chips: dict


def theme(background: str, body_name: str) -> Theme:
    """The colours of one video.

    Parameters
    ----------
    background : str
        ``[render].background``: "white" or "black".
    body_name : str
        The body's name (its colour: DAST orange, cellulose straw, else tan).

    Returns
    -------
    Theme
        3-D colours as RGB floats in [0, 1], HUD colours as RGB 0..255.
    """
    body = body_color(body_name)
    chips = {k: tuple(int(round(255 * c)) for c in v) for k, v in ARROW_COLORS.items()}
    chips["body"] = tuple(int(round(255 * 0.6 * c)) for c in body)
    return Theme(scene=COLORS[background], body=body, hud=palette(background), chips=chips)
