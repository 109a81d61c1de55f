"""A file of measurements of the crystal's line -- frequency and power with their errors -- for
the start-free power-frequency test (``spinviz decide SCENE --measurements FILE``).

CSV (``.csv``): a header naming the columns, then one measurement a row; blank lines and lines
starting with ``#`` are skipped::

    # power in any one unit: the laws' constant absorbs it; t_s is optional
    t_s,f_hz,power,sigma_f_hz,sigma_power
    0.5,7071067811.8,1.31e-19,0.009,2.2e-21
    ...

JSON (``.json``): an object of equally long arrays under the same names, and optionally a
``"power_unit"`` string (nested at most ``atomic.MAX_JSON_DEPTH`` levels)::

    {"f_hz": [...], "power": [...], "sigma_f_hz": [...], "sigma_power": [...], "power_unit": "W"}

Every row is checked by ``MeasurementRow`` (f_hz and power positive, sigma_power positive,
sigma_f_hz not negative, all finite); a problem is one line naming the file, the row (and its
line in a CSV) and the column.  At least ``MIN_ROWS`` rows: the general law has three
parameters.  The file is read as every input is: a regular file only (a FIFO is refused at
once, never waited on), at most ``MAX_FILE_BYTES``, UTF-8 (a byte order mark is skipped).
"""

from __future__ import annotations

import csv
import json
import os

from ..atomic import JsonTooDeep, NotRegularFile, loads_json, read_regular
from ..errors import SceneError, SpecError, SpecTypeError, brief
from .base import Line, NonNegative, Positive, Real, request
from .toml import MAX_FILE_BYTES

COLUMNS = ("f_hz", "power", "sigma_f_hz", "sigma_power")
OPTIONAL = ("t_s",)
MIN_ROWS = 4
MAX_ROWS = 1_000_000


@request
class MeasurementRow:
    """One measurement: the line's frequency f_hz and power (any unit), their 1-sigma errors,
    and optionally the time t_s of the measurement."""

    f_hz: Positive
    power: Positive
    sigma_f_hz: NonNegative
    sigma_power: Positive
    t_s: Real | None = None


@request
class MeasurementHeader:
    """The file's own settings: the unit of its powers (text, for reports)."""

    power_unit: Line = "arbitrary units"


def _number(text: str, path: str, where: str, col: str):
    try:
        return float(text)
    except ValueError:
        raise SceneError(path, f"{where}, {col}", f"expected a number, got {brief(text)}") from None


def _cells(line: str, path: str, where: str) -> list[str]:
    """One CSV line's fields; the parser's own refusals (a field beyond its size limit, a NUL)
    said as the file's, at ``where``."""
    try:
        return next(csv.reader([line]))
    except csv.Error as e:
        raise SceneError(path, where, f"not a CSV line ({e})") from None


def _rows_from_csv(text: str, path: str) -> list[tuple[str, dict]]:
    lines = [(i + 1, s) for i, s in enumerate(text.splitlines()) if s.strip() and not s.lstrip().startswith("#")]
    if not lines:
        raise SceneError(path, "(file)", f"no header: the first line names the columns {', '.join(COLUMNS)}")
    header_line, header = lines[0]
    names = [c.strip() for c in _cells(header, path, f"line {header_line}")]
    for c in names:
        if c not in COLUMNS + OPTIONAL:
            raise SceneError(path, f"line {header_line}", f"unknown column {brief(c)}; valid: {', '.join(COLUMNS + OPTIONAL)}")
    for c in COLUMNS:
        if c not in names:
            raise SceneError(path, f"line {header_line}", f"missing column {c!r}")
    rows = []
    for n, (lineno, s) in enumerate(lines[1:], start=1):
        where = f"row {n} (line {lineno})"
        cells = [c.strip() for c in _cells(s, path, where)]
        if len(cells) != len(names):
            raise SceneError(path, where, f"{len(cells)} values for {len(names)} columns")
        rows.append((where, {c: _number(v, path, where, c) for c, v in zip(names, cells)}))
    return rows


def _rows_from_json(text: str, path: str) -> tuple[list[tuple[str, dict]], dict]:
    try:
        data = loads_json(text)
    except JsonTooDeep as e:
        raise SceneError(path, "(file)", str(e)) from None
    except json.JSONDecodeError as e:
        raise SceneError(path, "(file)", f"invalid JSON: {e}") from None
    if not isinstance(data, dict):
        raise SceneError(path, "(file)", f"must be a JSON object of arrays ({', '.join(COLUMNS)}), got {type(data).__name__}")
    header = {k: data[k] for k in ("power_unit",) if k in data}
    for k in data:
        if k not in COLUMNS + OPTIONAL + ("power_unit",):
            raise SceneError(path, k, f"unknown key; valid: {', '.join(COLUMNS + OPTIONAL + ('power_unit',))}")
    lengths = set()
    for c in COLUMNS + OPTIONAL:
        if c not in data:
            if c in COLUMNS:
                raise SceneError(path, c, "missing array")
            continue
        if not isinstance(data[c], list):
            raise SceneError(path, c, f"must be an array of numbers, got {brief(data[c])}")
        lengths.add(len(data[c]))
    if len(lengths) > 1:
        raise SceneError(path, "(file)", f"the arrays differ in length ({', '.join(str(n) for n in sorted(lengths))})")
    n = lengths.pop()
    rows = [(f"row {i + 1}", {c: data[c][i] for c in COLUMNS + OPTIONAL if c in data}) for i in range(n)]
    return rows, header


def read_measurements(path) -> tuple[dict, str]:
    """The measurements in the CSV or JSON file at ``path`` as arrays ({column: list of floats},
    ``t_s`` only when given) and the unit of the powers; ``SceneError(path, where, reason)`` on
    the first problem."""
    if not isinstance(path, str | bytes | os.PathLike):
        raise SpecTypeError("measurements", f"must be the path of a CSV or JSON file (str or os.PathLike), got "
                                            f"{type(path).__name__} {brief(path)}")
    path = os.fsdecode(path)
    kind = os.path.splitext(path)[1].lower()
    if kind not in (".csv", ".json"):
        raise SceneError(path, "(file)", "a measurements file ends in .csv or .json")
    try:
        raw = read_regular(path, MAX_FILE_BYTES)          # a FIFO or a device is refused at once, never waited on
    except NotRegularFile as e:
        raise SceneError(path, "(file)", f"{e.strerror}; measurements are a CSV or JSON file") from None
    except FileNotFoundError:
        raise SceneError(path, "(file)", "no such file") from None
    except (OSError, ValueError) as e:
        raise SceneError(path, "(file)", getattr(e, "strerror", None) or str(e)) from None
    if len(raw) > MAX_FILE_BYTES:
        raise SceneError(path, "(file)", f"larger than {MAX_FILE_BYTES} bytes")
    try:
        text = raw.decode("utf-8-sig")                    # a spreadsheet's byte order mark is not a column's name
    except UnicodeDecodeError:
        raise SceneError(path, "(file)", "not a text (UTF-8) file") from None
    if kind == ".csv":
        rows, header = _rows_from_csv(text, path), {}
    else:
        rows, header = _rows_from_json(text, path)
    try:
        unit = MeasurementHeader(**header).power_unit
    except SpecError as e:
        raise SceneError(path, e.key, e.reason) from None
    if not MIN_ROWS <= len(rows) <= MAX_ROWS:
        raise SceneError(path, "(file)", f"{len(rows)} measurements; the test needs {MIN_ROWS} to {MAX_ROWS}")
    out: dict = {c: [] for c in COLUMNS + OPTIONAL}
    for where, row in rows:
        try:
            m = MeasurementRow(**row)
        except SpecError as e:
            raise SceneError(path, f"{where}, {e.key}", e.reason) from None
        for c in COLUMNS + OPTIONAL:
            out[c].append(getattr(m, c))
    if any(v is None for v in out["t_s"]) or not out["t_s"]:
        out.pop("t_s")
    return out, unit
