"""The schema's building blocks: typed frozen request classes validated by pydantic, the field
types every input shares, and the translation of pydantic's errors into spinviz's one line.

``@request`` turns a class body of annotated fields into a frozen pydantic dataclass (strict:
no string is read as a number, no float as an integer, no bool as either; NaN and infinities
refused) whose construction raises ``SpecError(key, reason)`` -- ``SpecTypeError`` for a value
of the wrong kind -- instead of pydantic's ``ValidationError``.  The key is the field's name,
which is the TOML key or the Python argument it stands for; whoever reads a table or a
command line adds the file and table (``toml.table``) or turns the name into its option.

Field types (``Annotated`` aliases and helpers):

* ``Real``, ``Positive``, ``Int``, ``Text``, ``Line`` (one printable line), ``vector(n)``;
* ``between(lo, hi, why)``: a range stated in full, with the reason, when a value is outside;
* ``refused(reason)``: a key that is no longer accepted, and why;
* ``Literal[...]`` for a choice among names.

Cross-field rules go in ``@model_validator(mode="after")`` methods raising
``SpecError(key, reason)`` with the key they blame.
"""

from __future__ import annotations

import contextlib
import contextvars
import functools
import math
import os
import unicodedata
from collections.abc import Callable, Sequence
from typing import Annotated, Any

import numpy as np
from pydantic import AfterValidator, ConfigDict, Field, PlainValidator, ValidationError
from pydantic.dataclasses import dataclass as _pydantic_dataclass
from pydantic_core import PydanticCustomError

from ..errors import SpecError, SpecTypeError, brief

__all__ = ["request", "Real", "Positive", "NonNegative", "Int", "Text", "Line", "vector", "Direction", "check_vector",
           "between", "shown", "shown_bound",
           "at_most", "refused", "registered", "wrong_type", "one_line", "fields_of", "terms", "SpecError", "SpecTypeError"]

CONFIG = ConfigDict(strict=True, extra="forbid", allow_inf_nan=False, arbitrary_types_allowed=True)

# "key" while a TOML table is read, "argument" for a Python call: the word for a name that is
# not one of the schema's
_TERMS: contextvars.ContextVar[str] = contextvars.ContextVar("spinviz_input_terms", default="argument")


@contextlib.contextmanager
def terms(word: str):
    """Within the block, an unknown name is called an unknown ``word`` ("key" in files)."""
    token = _TERMS.set(word)
    try:
        yield
    finally:
        _TERMS.reset(token)


def wrong_type(reason: str) -> PydanticCustomError:
    """The error a validator raises for a value of the wrong kind (becomes ``SpecTypeError``)."""
    return PydanticCustomError("spinviz_type", "{reason}", {"reason": reason})


# --- field types ---------------------------------------------------------------------------
def _plain_number(v):
    """NumPy scalars as Python numbers (np.int64(3) is an integer, np.float32(2) a float)."""
    if isinstance(v, np.generic) and not isinstance(v, np.bool_):
        return v.item()
    return v


def _not_bool_int(v):
    """A whole number given as a float is refused like any float (strict), but said plainly."""
    v = _plain_number(v)
    if isinstance(v, bool) or not isinstance(v, int):
        raise wrong_type(f"must be an integer, got {brief(v)}")
    return v


def _number(v):
    v = _plain_number(v)
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        raise wrong_type(f"must be a number, got {brief(v)}")
    if not math.isfinite(v):
        raise ValueError(f"must be finite, got {v}")
    return float(v)


Real = Annotated[float, PlainValidator(_number)]
Positive = Annotated[float, PlainValidator(_number), Field(gt=0.0)]
NonNegative = Annotated[float, PlainValidator(_number), Field(ge=0.0)]
Int = Annotated[int, PlainValidator(_not_bool_int)]


def _text(v):
    if not isinstance(v, str):
        raise wrong_type(f"must be a string, got {brief(v)}")
    return v


def one_line(v):
    """``v`` if it is one line of printable text (no control, format or separator character)."""
    v = _text(v)
    if any(unicodedata.category(ch) in ("Cc", "Cf", "Zl", "Zp", "Cs") for ch in v):
        raise ValueError("must be one line of printable text (no newlines or control characters)")
    return v


Text = Annotated[str, PlainValidator(_text)]
Line = Annotated[str, PlainValidator(one_line)]


def between(lo: float, hi: float, why: str = "", lo_open: bool = False):
    """A validator: ``lo <= v <= hi`` (``lo < v`` with ``lo_open``), the whole range and the
    reason in the message, e.g. "must lie in [0.1, 1e+09] (from an atom to a metre), got -315"."""
    ends = f"{'(' if lo_open else '['}{_g(lo)}, {_g(hi)}]"
    because = f" ({why})" if why else ""

    def check(v):
        if v is not None and not ((lo < v if lo_open else lo <= v) and v <= hi):
            raise ValueError(f"must lie in {ends}{because}, got {shown(v, lo, hi)}")
        return v

    check.bounds = (lo, hi)            # the range, for whoever draws values from the schema (the fuzz tests)
    return AfterValidator(check)


def at_most(hi, why: str):
    """A validator: ``v <= hi``, with the reason the limit exists."""

    def check(v):
        if v is not None and v > hi:
            raise ValueError(f"must be at most {_g(hi)} ({why}), got {shown(v, hi)}")
        return v

    return AfterValidator(check)


def check_vector(v, n: int, what: str = "numbers") -> tuple[float, ...]:
    """``v`` -- a list, tuple or 1-D array of ``n`` finite numbers -- as a tuple of floats."""
    if isinstance(v, np.ndarray):
        if v.shape != (n,) or v.dtype.kind not in "iuf":
            raise wrong_type(f"must be a list of {n} {what}, got an array of shape {v.shape} ({v.dtype})")
        v = v.tolist()
    if not isinstance(v, (list, tuple)) or len(v) != n:
        raise wrong_type(f"must be a list of {n} {what}, got {brief(v)}")
    out = []
    for x in v:
        x = _plain_number(x)
        if isinstance(x, bool) or not isinstance(x, (int, float)):
            raise wrong_type(f"must be a list of {n} {what}, got {brief(v)}")
        if not math.isfinite(x):
            raise ValueError(f"must be finite, got {brief(v)}")
        out.append(float(x))
    return tuple(out)


def vector(n: int, what: str = "numbers"):
    """A list (tuple, 1-D array) of ``n`` finite numbers, as a tuple of floats."""
    return Annotated[tuple[float, ...], PlainValidator(lambda v: check_vector(v, n, what))]


def _direction(v) -> tuple[float, ...]:
    v = check_vector(v, 3)
    from ..rotations import unit_vector

    unit_vector(v)                      # the detector's own rule: every finite non-zero vector has a direction
    return v


# A direction X, Y, Z (a line of sight): three finite numbers, not all zero -- exactly what
# ``rotations.unit_vector`` (and so the detector) can normalise, 1e308 and 1e-320 components
# included; kept as given
Direction = Annotated[tuple[float, ...], PlainValidator(_direction)]


def _path(v):
    if v is None or isinstance(v, str | os.PathLike):
        return None if v is None else os.fspath(v)
    raise wrong_type(f"must be a path (str or os.PathLike), got {type(v).__name__} {brief(v)}")


def _flag(v):
    if not isinstance(v, bool):
        raise wrong_type(f"must be True or False, got {brief(v)}")
    return v


# An optional path (str or os.PathLike, kept as str) and a strict True/False argument
Path = Annotated[Any, PlainValidator(_path)]
Flag = Annotated[bool, PlainValidator(_flag)]


def refused(reason: str):
    """A key that is no longer part of the schema: any value is refused with ``reason``."""

    def check(v):
        if v is not None:
            raise ValueError(reason)
        return v

    return Annotated[Any, AfterValidator(check)]


def registered(valid: Callable[[], Sequence[str]]):
    """A choice among names a registry holds (``valid()`` lists them when a value is checked,
    so a name registered later is accepted): ``Literal``'s check, in ``Literal``'s words."""

    def check(v):
        if not isinstance(v, str):
            raise wrong_type(f"must be a string, got {brief(v)}")
        names = tuple(valid())
        if v not in names:
            raise ValueError(f"unknown value {brief(v)}; valid: {', '.join(names)}")
        return v

    return Annotated[str, PlainValidator(check)]


# --- request classes -----------------------------------------------------------------------
def request(cls=None, *, eq: bool = True):
    """Decorator: a frozen pydantic dataclass whose construction (and ``dataclasses.replace``)
    raises ``SpecError``/``SpecTypeError`` naming the field."""

    def make(c):
        pcls = _pydantic_dataclass(frozen=True, eq=eq, config=CONFIG)(c)
        init = pcls.__init__

        @functools.wraps(init)
        def __init__(self, *args, **kwargs):
            try:
                init(self, *args, **kwargs)
            except ValidationError as e:
                raise spec_error(e, pcls) from None

        pcls.__init__ = __init__
        return pcls

    return make if cls is None else make(cls)


def fields_of(cls) -> dict:
    """The schema's fields of a request class: name -> pydantic FieldInfo (default, metadata)."""
    return dict(cls.__pydantic_fields__)


_TYPE_ERRORS = {"spinviz_type", "unexpected_keyword_argument", "unexpected_positional_argument", "int_type", "float_type",
                "string_type", "bool_type", "tuple_type", "list_type", "dict_type", "is_instance_of", "dataclass_type",
                "model_type", "callable_type"}


def _bounds(cls, key: str):
    """(lower, lower open, upper, upper open) of field ``key`` of ``cls``, None where absent."""
    import typing

    import annotated_types as at

    lo = hi = None
    lo_open = hi_open = False
    field = getattr(cls, "__pydantic_fields__", {}).get(key) if cls is not None else None
    metadata = list(getattr(field, "metadata", ()))
    for arg in typing.get_args(getattr(field, "annotation", None)):      # an optional field: X | None
        for m in getattr(arg, "__metadata__", ()):
            metadata += list(getattr(m, "metadata", None) or [m])        # Field(ge=...) inside Annotated
    for m in metadata:
        if isinstance(m, at.Gt | at.Ge):
            lo, lo_open = (m.gt, True) if isinstance(m, at.Gt) else (m.ge, False)
        elif isinstance(m, at.Lt | at.Le):
            hi, hi_open = (m.lt, True) if isinstance(m, at.Lt) else (m.le, False)
    return lo, lo_open, hi, hi_open


def spec_error(e: ValidationError, cls=None) -> SpecError:
    """The first problem pydantic found, as spinviz's ``SpecError(key, reason)``: a value out
    of a field's range is told the whole range (``must lie in [1, 240], got 0``)."""
    err = e.errors(include_url=False)[0]
    names = [p for p in err["loc"] if isinstance(p, str)]
    key = names[0] if names else ""
    kind, ctx, value = err["type"], err.get("ctx") or {}, err.get("input")
    if kind == "value_error" and isinstance(ctx.get("error"), SpecError):
        inner = ctx["error"]
        return type(inner)(f"{key}.{inner.key}" if key and inner.key else (inner.key or key), inner.reason)
    lo, lo_open, hi, hi_open = _bounds(cls, key)
    if kind in ("greater_than", "greater_than_equal", "less_than", "less_than_equal") and lo is not None and hi is not None:
        reason = (f"must lie in {'(' if lo_open else '['}{_g(lo)}, {_g(hi)}{')' if hi_open else ']'}, "
                  f"got {shown(value, lo, hi)}")
    else:
        reason = _reason(kind, ctx, value, err.get("msg", ""))
    return (SpecTypeError if kind in _TYPE_ERRORS else SpecError)(key, reason)


def _g(x) -> str:
    """A bound for a message: whole numbers exactly (to 21 digits), floats in the short form
    when it is exact, else with every digit."""
    x = _plain_number(x)
    if isinstance(x, int) and not isinstance(x, bool):
        return str(x) if abs(x) < 10**21 else f"{x:.3g}"
    if isinstance(x, float):
        return f"{x:g}" if not math.isfinite(x) or float(f"{x:g}") == x else repr(x)
    return brief(x)


shown_bound = _g


def shown(x, *bounds) -> str:
    """A value for a message, with the digits that tell it from each of ``bounds``: whole
    numbers exactly (to 21 digits), floats in the short form (6 significant digits) unless
    that would print a value outside a bound as the bound itself or put it on the bound's
    other side ("must lie in (0, 1e+20], got 1.0000001e+20", not "got 1e+20"): then with as
    many digits as that takes, at most all 17."""
    x = _plain_number(x)
    if isinstance(x, bool) or not isinstance(x, int | float):
        return brief(x)
    if isinstance(x, int):
        return str(x) if abs(x) < 10**21 else f"{x:.6g}"
    if not math.isfinite(x):
        return f"{x:g}"
    marks = [float(_plain_number(b)) for b in bounds if isinstance(_plain_number(b), int | float)]
    for digits in range(6, 18):
        s = f"{x:.{digits}g}"
        y = float(s)
        if all((y < b) == (x < b) and (y > b) == (x > b) for b in marks):
            return s
    return repr(x)


def _reason(kind: str, ctx: dict, value, msg: str) -> str:
    if kind in ("value_error", "assertion_error"):
        return str(ctx.get("error", msg))
    if kind == "spinviz_type":
        return ctx["reason"]
    if kind in ("missing", "missing_argument", "missing_keyword_only_argument", "missing_positional_only_argument"):
        return "missing value"
    if kind in ("unexpected_keyword_argument", "extra_forbidden", "unexpected_positional_argument"):
        return f"unknown {_TERMS.get()}"
    if kind == "multiple_argument_values":
        return "given twice"
    if kind == "literal_error":
        valid = ctx.get("expected", "").replace("'", "").replace(" or ", ", ")
        return f"unknown value {brief(value)}; valid: {valid}"
    if kind == "greater_than":
        got = shown(value, ctx["gt"])
        return f"must be positive, got {got}" if ctx["gt"] == 0 else f"must be above {_g(ctx['gt'])}, got {got}"
    if kind == "greater_than_equal":
        got = shown(value, ctx["ge"])
        return f"must not be negative, got {got}" if ctx["ge"] == 0 else f"must be at least {_g(ctx['ge'])}, got {got}"
    if kind == "less_than":
        return f"must be below {_g(ctx['lt'])}, got {shown(value, ctx['lt'])}"
    if kind == "less_than_equal":
        return f"must be at most {_g(ctx['le'])}, got {shown(value, ctx['le'])}"
    if kind == "finite_number":
        return f"must be finite, got {_g(value)}"
    if kind == "int_type":
        return f"must be an integer, got {brief(value)}"
    if kind == "float_type":
        return f"must be a number, got {brief(value)}"
    if kind == "string_type":
        return f"must be a string, got {brief(value)}"
    if kind == "bool_type":
        return f"must be true or false, got {brief(value)}"
    if kind in ("dict_type", "dataclass_type", "model_type"):
        return f"must be a table, got {type(value).__name__}"
    if kind == "is_instance_of":
        return f"must be a {ctx.get('class', 'value of the documented type')}, got {type(value).__name__} {brief(value)}"
    return msg
