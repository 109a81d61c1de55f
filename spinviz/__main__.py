"""``python -m spinviz``: the same as the ``spinviz`` command."""

from .commands import entry

if __name__ == "__main__":    # guarded: render workers are spawned and re-import __main__
    entry()
