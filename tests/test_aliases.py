"""One rule for module aliases, everywhere in the project: a module imported under an alias
has one alias, and an alias names one module (``import numpy as np`` in every file, never
``ST`` for two modules).  Names imported with ``as`` that are not modules (functions,
classes) are free."""

import ast
import importlib.util
from collections import defaultdict
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PLACES = ("spinviz", "tests", "examples", "benchmarks", "docs")


def _module_name(path: Path, level: int, module: str | None) -> str | None:
    """The absolute module a relative import in ``path`` names (None outside the package)."""
    if level == 0:
        return module
    parts = path.relative_to(ROOT).with_suffix("").parts
    if parts[0] != "spinviz":
        return None
    base = parts[:-1] if path.name != "__init__.py" else parts[:-1]
    base = base[: len(base) - (level - 1)]
    return ".".join(base + ((module,) if module else ()))


def _is_module(name: str) -> bool:
    try:
        return importlib.util.find_spec(name) is not None
    except (ImportError, ValueError):
        return False


def module_aliases() -> dict[str, dict[str, set[str]]]:
    """{module: {alias: files}} of every ``import M as A`` and ``from P import M as A`` of a module."""
    found: dict[str, dict[str, set[str]]] = defaultdict(lambda: defaultdict(set))
    for place in PLACES:
        for path in sorted((ROOT / place).rglob("*.py")):
            where = str(path.relative_to(ROOT))
            for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
                if isinstance(node, ast.Import):
                    for a in node.names:
                        if a.asname:
                            found[a.name][a.asname].add(where)
                elif isinstance(node, ast.ImportFrom):
                    parent = _module_name(path, node.level, node.module)
                    if parent is None:
                        continue
                    for a in node.names:
                        if a.asname and _is_module(f"{parent}.{a.name}"):
                            found[f"{parent}.{a.name}"][a.asname].add(where)
    return found


def test_every_module_has_one_alias_and_every_alias_one_module():
    found = module_aliases()
    assert "spinviz.physics.models" in found and "numpy" in found        # the scan sees relative and plain imports
    two_aliases = {m: sorted(a) for m, a in found.items() if len(a) > 1}
    assert not two_aliases, f"modules imported under more than one alias: {two_aliases}"
    by_alias = defaultdict(set)
    for module, aliases in found.items():
        for alias in aliases:
            by_alias[alias].add(module)
    shared = {a: sorted(m) for a, m in by_alias.items() if len(m) > 1}
    assert not shared, f"aliases naming more than one module: {shared}"
