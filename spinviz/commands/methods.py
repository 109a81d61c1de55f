"""``spinviz methods``: the integrators and their orders."""

from __future__ import annotations

from .shared import EXIT_OK


def add_parser(sub) -> None:
    """Add ``spinviz methods`` (the list of integrators) and its options to ``sub``."""
    sub.add_parser("methods", help="list the integrators")


def run(args) -> int:
    """Carry out ``spinviz methods`` with the parsed ``args``; return its exit status."""
    from ..integrators import get, names

    for n in names():
        m = get(n)
        order = f"order {m.order}" if m.order else "variable order"
        print(f"{n:<14} {order:<15} {'fixed step' if m.fixed_step else 'adaptive':<10} {m.description}")
    return EXIT_OK
