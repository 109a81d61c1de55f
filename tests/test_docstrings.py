"""Every public function, class, method and property of the package says what it is.

The API reference (docs/, autodoc) is generated from the docstrings, so a public callable
without one is a hole in the documentation.  Also here: no function grows past ~60 lines
unless it says why in a ``# Long on purpose: ...`` comment (a numba kernel whose helpers
would cost a call per stage, say).
"""

from __future__ import annotations

import ast
import dataclasses
import functools
import importlib
import inspect
import pkgutil
from pathlib import Path

import spinviz

ROOT = Path(spinviz.__file__).resolve().parent
# Optional stacks a module may need to import at all (the "render" and "ensemble" extras).
OPTIONAL = {"pyvista", "vtk", "vtkmodules", "imageio", "imageio_ffmpeg", "PIL", "matplotlib", "dask", "distributed",
            "xarray", "zarr"}
MAX_LINES = 60          # of a function's body, its docstring not counted


def covered_modules():
    yield spinviz
    for info in pkgutil.walk_packages(spinviz.__path__, "spinviz."):
        if any(part.startswith("_") for part in info.name.split(".")[1:]):
            continue
        try:
            yield importlib.import_module(info.name)
        except ImportError as e:
            if (e.name or "").split(".")[0] not in OPTIONAL:
                raise


def _unwrap(obj):
    """The function behind a property, a cached property, a static or class method, a numba
    dispatcher (``py_func``) or a decorator that kept ``__wrapped__``."""
    if isinstance(obj, property):
        obj = obj.fget
    if isinstance(obj, functools.cached_property):
        obj = obj.func
    obj = getattr(obj, "__func__", obj)
    obj = getattr(obj, "py_func", obj)
    return inspect.unwrap(obj) if callable(obj) else obj


def _documented(obj) -> bool:
    if inspect.isclass(obj):
        doc = obj.__dict__.get("__doc__")
        # a dataclass without a docstring gets its signature as one
        if doc and dataclasses.is_dataclass(obj) and doc.startswith(obj.__name__ + "("):
            doc = None
        return bool((doc or "").strip())
    return bool((obj.__doc__ or "").strip())


def public_callables():
    """(qualified name, object) of every public function, class, and method or property
    defined in a public class, each counted in the module that defines it."""
    seen = set()
    for mod in covered_modules():
        for name, value in vars(mod).items():
            obj = _unwrap(value)
            if name.startswith("_") or not (inspect.isfunction(obj) or inspect.isclass(obj)):
                continue
            if getattr(obj, "__module__", None) != mod.__name__ or id(obj) in seen:
                continue                                    # imported here, or already seen
            seen.add(id(obj))
            yield f"{mod.__name__}.{name}", obj
            if inspect.isclass(obj):
                for attr, member in vars(obj).items():
                    fn = _unwrap(member)
                    if not attr.startswith("_") and inspect.isfunction(fn):
                        yield f"{mod.__name__}.{name}.{attr}", fn


def test_every_public_callable_has_a_docstring():
    items = list(public_callables())
    assert len(items) > 500                                  # the walk found the package
    missing = [name for name, obj in items if not _documented(obj)]
    assert not missing, f"{len(missing)} of {len(items)} public callables have no docstring:\n" + "\n".join(missing)


def test_no_function_is_long_without_a_reason():
    long = []
    for path in sorted(ROOT.rglob("*.py")):
        rel = path.relative_to(ROOT.parent)
        source = path.read_text()
        for node in ast.walk(ast.parse(source)):
            if not isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                continue
            body = node.body
            if body and isinstance(body[0], ast.Expr) and isinstance(getattr(body[0], "value", None), ast.Constant):
                body = body[1:]                                  # the docstring
            if not body:
                continue
            lines = body[-1].end_lineno - body[0].lineno + 1
            text = "\n".join(source.splitlines()[node.lineno - 1:node.end_lineno])
            if lines > MAX_LINES and "# Long on purpose:" not in text:
                long.append(f"{rel}:{node.lineno} {node.name} ({lines} lines)")
    assert not long, "functions over ~60 lines with no '# Long on purpose: ...' comment:\n" + "\n".join(long)
