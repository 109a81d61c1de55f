"""``spinviz info PRESET_OR_SCENE [--json]``: derived quantities beside the paper's figures."""

from __future__ import annotations

import json
import os

from ..errors import UsageError
from .shared import EXIT_OK, out, p


def add_parser(sub) -> None:
    """Add ``spinviz info`` (a preset's or scene's derived quantities) and its options to ``sub``."""
    i = sub.add_parser("info", help="derived quantities of a preset or scene, beside the paper's figures")
    i.add_argument("target", help="a preset name (cellulose_rod, dast_cube, dast_family1) or a scene file")
    i.add_argument("--json", action="store_true")


def run(args) -> int:
    """Carry out ``spinviz info`` with the parsed ``args``; return its exit status."""
    from ..analysis import info
    from ..physics.presets import PRESETS

    target = args.target
    if target in PRESETS:
        body = PRESETS[target]()
        title, omega = f"{body.name}  (preset {target})", None
    elif os.path.exists(target) or target.endswith(".toml"):
        from ..inputs.scene_spec import load_scene

        sc = load_scene(target)
        body, title, omega = sc.body, f"{sc.title}  ({p(target)}): {sc.body.name}", sc.omega0
    else:
        raise UsageError(f"{p(target)}: not a preset ({', '.join(PRESETS)}) nor a scene file")
    if args.json:
        print(json.dumps(info.rows(body, omega), indent=2, default=float))
    else:
        out(info.format_info(body, title, omega))
    return EXIT_OK
