"""``spinviz simulate SCENE --out traj.npz [--model M] [--method NAME]``: integrate a scene."""

from __future__ import annotations

import dataclasses
import os

from ..errors import SimulationError, SpecError, UsageError
from .shared import EXIT_OK, cannot_write, out, p, say


def add_parser(sub) -> None:
    """Add ``spinviz simulate`` (the integration of a scene) and its options to ``sub``."""
    s = sub.add_parser("simulate", help="integrate a scene and write the trajectory and its radiation observables (.npz)")
    s.add_argument("scene")
    s.add_argument("--out", required=True, help="output .npz path")
    s.add_argument("--model", help="which of the scene's models (default: the first)")
    s.add_argument("--method", help="override the scene's integrator")


def run(args) -> int:
    """Carry out ``spinviz simulate`` with the parsed ``args``; return its exit status."""
    from ..atomic import check_outputs
    from ..driver import simulate_request
    from ..inputs.scene_spec import load_scene

    if os.path.splitext(args.out)[1].lower() != ".npz":
        raise UsageError(f"--out: {args.out}: a trajectory is written as .npz; give a path ending in .npz")
    check_outputs([args.out], [args.scene])
    sc = load_scene(args.scene)
    model = args.model or sc.model
    if model not in sc.models:
        raise UsageError(f"{args.scene}: --model {model!r} is not one of the scene's models ({', '.join(sc.models)})")
    request = sc.request(model)
    if args.method:                                 # the option replaces the scene's method, checked the same way
        try:
            request = dataclasses.replace(request, method=args.method)
        except SpecError as e:                      # a rule the method breaks is said as the option's
            raise e if e.key == "method" else SpecError("method", f"{e.key}: {e.reason}") from None
    try:
        traj = simulate_request(request)
    except SimulationError as e:
        raise SimulationError(f"{args.scene}: {e}") from None
    try:
        traj.save(args.out, radiation=True)
    except OSError as e:
        raise cannot_write(args.out, e) from None
    st = traj.stats
    cost = f"{st['nsteps']} steps" if "nsteps" in st else f"{st.get('nfev', '?')} rhs evaluations"
    out(f"{p(args.out)}: {traj.t.size} samples, model {model}, method {st['method']}, {cost}, {st['runtime_s']:.3f} s")
    for note in st.get("accuracy_notes", ()):
        say("note: ", note)
    return EXIT_OK
