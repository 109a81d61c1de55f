"""Command line: a thin ``main(argv) -> int`` that parses, delegates and maps errors to
exit codes (0 success, 1 a check or run failed, 2 bad input).  No physics here."""

from __future__ import annotations

import argparse
import json
import os
import sys

EXIT_OK, EXIT_FAIL, EXIT_USAGE = 0, 1, 2


class UserError(Exception):
    """Bad input: printed as one line, exit status 2."""


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="spinviz", description="Rotation of a dipolar nanocrystal braked by radiation reaction "
                                "(reduced (2.2)+(2.3) vs truncated (2.5) Euler equations).")
    sub = p.add_subparsers(dest="command", metavar="COMMAND")
    sub.required = True

    c = sub.add_parser("check", help="validate the integrators against the paper's closed forms")
    c.add_argument("--json", action="store_true", help="print a JSON list of records instead of a table")

    i = sub.add_parser("info", help="derived quantities of a preset or scene, beside the paper's figures")
    i.add_argument("target", help="a preset name (cellulose_rod, dast_cube, dast_family1) or a scene file")
    i.add_argument("--json", action="store_true")

    s = sub.add_parser("simulate", help="integrate a scene and write the trajectory (.npz)")
    s.add_argument("scene")
    s.add_argument("--out", required=True, help="output .npz path")
    s.add_argument("--model", help="which of the scene's models (default: the first)")
    s.add_argument("--method", help="override the scene's integrator")

    sub.add_parser("methods", help="list the integrators")
    return p


def main(argv: list[str] | None = None) -> int:
    args = _parser().parse_args(argv)
    from .scene import SceneError
    from .simulate import SimulationError

    try:
        return _COMMANDS[args.command](args)
    except (UserError, SceneError) as e:
        print(f"spinviz: error: {e}", file=sys.stderr)
        return EXIT_USAGE
    except SimulationError as e:
        print(f"spinviz: run failed: {e}", file=sys.stderr)
        return EXIT_FAIL
    except KeyboardInterrupt:
        print("spinviz: interrupted", file=sys.stderr)
        return 130


def _cmd_check(args) -> int:
    from . import checks

    results = checks.run_all()
    if args.json:
        print(json.dumps([r.record() for r in results], indent=2, default=float))
    else:
        print(checks.format_table(results))
    return EXIT_OK if all(r.passed for r in results) else EXIT_FAIL


def _cmd_info(args) -> int:
    from . import info
    from .physics.bodies import PRESETS

    target = args.target
    if target in PRESETS:
        body, title, omega = PRESETS[target](), f"{PRESETS[target]().name}  (preset {target})", None
    elif os.path.exists(target) or target.endswith(".toml"):
        from .scene import load_scene

        sc = load_scene(target)
        body, title, omega = sc.body, f"{sc.title}  ({target}): {sc.body.name}", sc.omega0
    else:
        raise UserError(f"{target}: not a preset ({', '.join(PRESETS)}) nor a scene file")
    if args.json:
        print(json.dumps(info.rows(body, omega), indent=2, default=float))
    else:
        print(info.format_info(body, title, omega))
    return EXIT_OK


def _cmd_simulate(args) -> int:
    from .scene import load_scene
    from .simulate import SimulationError, simulate

    sc = load_scene(args.scene)
    model = args.model or sc.model
    if model not in sc.models:
        raise UserError(f"{args.scene}: --model {model!r} is not one of the scene's models ({', '.join(sc.models)})")
    kw = sc.simulation_kwargs()
    if args.method:
        from .integrators import names

        if args.method != "auto" and args.method.lower() not in names():
            raise UserError(f"--method {args.method!r}: unknown method; valid: auto, {', '.join(names())}")
        kw["method"] = args.method.lower()
    try:
        traj = simulate(sc.body, model, **kw)
    except SimulationError as e:
        raise SimulationError(f"{args.scene}: {e}") from None
    except ValueError as e:
        raise UserError(f"{args.scene}: {e}") from None
    try:
        traj.save_npz(args.out)
    except OSError as e:
        raise UserError(f"{args.out}: cannot write: {e.strerror or e}") from None
    st = traj.stats
    print(f"{args.out}: {traj.t.size} samples, model {model}, method {st['method']}, "
          f"{st.get('nfev', '?')} rhs evaluations, {st['runtime_s']:.3f} s")
    return EXIT_OK


def _cmd_methods(args) -> int:
    from .integrators import get, names

    for n in names():
        m = get(n)
        order = f"order {m.order}" if m.order else "variable order"
        print(f"{n:<14} {order:<15} {'fixed step' if m.fixed_step else 'adaptive':<10} {m.description}")
    return EXIT_OK


_COMMANDS = {"check": _cmd_check, "info": _cmd_info, "simulate": _cmd_simulate, "methods": _cmd_methods}


def entry() -> None:
    """Console-script entry point."""
    sys.exit(main())
