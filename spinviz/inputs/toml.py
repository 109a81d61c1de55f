"""TOML at the boundary: reading a file safely, and validating one of its tables as a request
class, with errors naming the file, the table and the key."""

from __future__ import annotations

import os
import tomllib
from typing import Annotated

from pydantic import PlainValidator

from ..atomic import NotRegularFile, open_regular
from ..errors import SceneError, SpecError
from .base import terms, wrong_type

MAX_FILE_BYTES = 16_000_000     # a scene is a few hundred bytes; this bounds what a bad path can make us read


def _table(v):
    if not isinstance(v, dict):
        raise wrong_type(f"must be a table, got {type(v).__name__}")
    return v


Table = Annotated[dict, PlainValidator(_table)]     # a sub-table, validated later by its own class


def key_name(table: str, key: str) -> str:
    """How a key is named in messages: ``[simulation].samples``, ``[grid.delta].cells``, ``title``."""
    if not key:
        return f"[{table}]" if table else "(file)"
    return f"[{table}].{key}" if table else key


def table(cls, data, name: str, path: str, subtables: tuple = ()):
    """``data`` (a parsed TOML table; ``name`` "" for the top level) validated as ``cls``.

    ``subtables``: the fields of ``cls`` that are themselves tables, so that a missing or
    mistyped one is named ``[name]`` ("missing table").  Raises ``SceneError(path, key, reason)``."""
    if not isinstance(data, dict):
        raise SceneError(path, key_name(name, ""), f"must be a table, got {type(data).__name__}")
    try:
        with terms("key"):
            return cls(**data)
    except SpecError as e:
        head = e.key.split(".")[0]
        if head in subtables:
            full = f"{name}.{head}" if name else head
            reason = "missing table" if e.reason == "missing value" else e.reason
            raise SceneError(path, f"[{full}]", reason) from None
        raise SceneError(path, key_name(name, e.key), e.reason) from None


def read_toml(path, kind: str = "scene") -> dict:
    """The parsed TOML document at ``path``; ``SceneError(path, "(file)", reason)`` for anything
    that is not a readable regular UTF-8 TOML file of sensible size (a FIFO or a device would
    block or never end; nesting thousands deep would exhaust the parser's recursion)."""
    path = os.fspath(path)
    try:
        with open_regular(path) as fh:                           # never blocks on a FIFO
            size = os.fstat(fh.fileno()).st_size
            if size > MAX_FILE_BYTES:
                raise SceneError(path, "(file)", f"{size} bytes is too large for a {kind} file (limit {MAX_FILE_BYTES})")
            raw = fh.read(MAX_FILE_BYTES + 1)
    except SceneError:
        raise
    except NotRegularFile as e:
        what = f"not a {kind} file" if e.kind == "a directory" else f"a {kind} is a TOML file"
        raise SceneError(path, "(file)", f"{e.strerror}; {what}") from None
    except FileNotFoundError:
        raise SceneError(path, "(file)", "no such file") from None
    except (OSError, ValueError) as e:                           # ValueError: an embedded NUL
        raise SceneError(path, "(file)", getattr(e, "strerror", None) or str(e)) from None
    if len(raw) > MAX_FILE_BYTES:                                # it grew while being read
        raise SceneError(path, "(file)", f"more than {MAX_FILE_BYTES} bytes is too large for a {kind} file")
    try:
        return tomllib.loads(raw.decode("utf-8"))
    except UnicodeDecodeError:
        raise SceneError(path, "(file)", f"not a text (UTF-8) file; a {kind} is TOML") from None
    except tomllib.TOMLDecodeError as e:
        raise SceneError(path, "(file)", f"invalid TOML: {e}") from None
    except RecursionError:
        raise SceneError(path, "(file)", f"values nested too deeply to be a {kind}") from None


def document(cls, data, path: str, tables: dict, empty: tuple = (), nested: dict | None = None) -> tuple:
    """A whole parsed document validated in one place: its top level as ``cls`` (every field
    named in ``tables`` a sub-table), then each sub-table ``name`` as ``tables[name]``, then
    each field ``"name.key"`` of ``nested`` that holds a table as ``nested["name.key"]`` (a
    field that may be a list or a table: ``[grid].delta = {min, max, cells}``).

    Returns ``(top, {name: validated})``; an absent sub-table is None, or validated from ``{}``
    (its defaults) when its name is in ``empty``; a nested field that is not a table is None.
    Errors as ``table``'s."""
    top = table(cls, data, "", path, tuple(tables))
    subs = {}
    for name, sub in tables.items():
        value = getattr(top, name)
        subs[name] = None if value is None and name not in empty else table(sub, {} if value is None else value, name, path)
    for name, sub in (nested or {}).items():
        outer, key = name.split(".")
        value = getattr(subs[outer], key, None) if subs.get(outer) is not None else None
        subs[name] = table(sub, value, name, path) if isinstance(value, dict) else None
    return top, subs


def read_document(path, cls, tables: dict, empty: tuple = (), kind: str = "scene", nested: dict | None = None) -> tuple:
    """``document`` of the file at ``path`` (``read_toml``)."""
    return document(cls, read_toml(path, kind), os.fspath(path), tables, empty, nested)
