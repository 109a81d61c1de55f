"""``python -m spinviz``: the same as the ``spinviz`` command."""

from .cli import entry

entry()
