"""``python -m spinviz.regimes SPEC.toml [options]``: the atlas command on its own, with the
command line's conventions (one-line errors, exit status 2 for bad input, 128 + signal on
SIGINT / SIGTERM / SIGHUP after a clean stop)."""

from __future__ import annotations

import argparse
import sys
import warnings

from .. import interrupt
from ..errors import SceneError, SpecError, UsageError, printable


class _Parser(argparse.ArgumentParser):
    def error(self, message):
        self.exit(2, f"spinviz: error: {printable(message)} (see '{printable(self.prog)} --help')\n")


def main(argv=None) -> int:
    from . import command

    top = _Parser(prog="python -m spinviz.regimes")
    sub = top.add_subparsers(dest="command", parser_class=_Parser)
    command.add_parser(sub)
    argv = list(sys.argv[1:] if argv is None else argv)
    args = top.parse_args(["atlas"] + argv)
    with interrupt.handlers(), warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        try:
            return command.run(args)
        except (UsageError, SceneError, SpecError) as e:
            print(f"spinviz: error: {printable(e)}", file=sys.stderr)
            return 2
        except interrupt.Interrupted as e:
            print(f"spinviz: interrupted by {e}", file=sys.stderr)
            return e.exit_status


if __name__ == "__main__":
    sys.exit(main())
