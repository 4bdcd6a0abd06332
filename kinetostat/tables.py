"""The tables a user gets (`analyze --out`, sweep tables; segments.csv, the worksheets, a report's
and a variant's cycle.csv: rows rounded by `rounded_columns` and `by_unit`, written by `rows_csv`
and `columns_csv` without pandas, as `write_csv` writes a frame), written one way: CSV, JSON
or Parquet of a pandas DataFrame whose `attrs["units"]` gives each column's unit, with the units
in every format and the numbers of the text formats to the digits that mean something.

- CSV: the header names each column with its unit, `R_0_1 [N]` (a text column: its bare name);
  `read_csv` reads such a file back with bare names and `attrs["units"]`.
- JSON: `{"mechanism", "units", "frame", "rows": [one object per row]}`, NaN as null.
- Parquet: the full binary values, `attrs` (units, frame, mechanism) in the file's pandas metadata.

Text formats round each float column to `DIGITS` significant digits of its unit's scale, the
largest |value| among all the table's columns of that unit (`rounded`; a column with no unit:
its own largest |value|): the solver's accuracy is relative to a quantity's peak (about 1e-15),
so digits below 1e-12 of the peak are rounding noise that differs between machines (a last-ulp
difference, or a value that is 0 within rounding printed as 3e-17, which prints 0). A rounded
value is the double nearest its decimal, so it prints with at most `DIGITS` significant digits.

May use: numpy, the standard library; pandas is passed in (never imported here).
"""
from __future__ import annotations

import csv
import io
import json
import math
import re
from decimal import Decimal
from typing import IO, Any, Iterable

import numpy as np

__all__ = ["DIGITS", "ERROR_DIGITS", "rounded", "rounded_columns", "by_unit", "cell_text", "rows_csv", "columns_csv", "value", "error",
           "header", "write_csv", "csv_text", "plain", "json_document", "write_json", "write_parquet", "read_csv"]

#: Significant digits of a value in a text output, counted on its unit's largest |value|.
DIGITS = 12
#: Significant digits of an error (a difference between two routes, a relative error).
ERROR_DIGITS = 3
#: Units that are no unit: a column of text (no bracket in a CSV header).
_NO_UNIT = ("text", "")
#: The text of a float in a CSV: `DIGITS` significant digits at most (pandas' `float_format`).
FLOAT_FORMAT = f"%.{DIGITS}g"
_HEADER = re.compile(r"^(?P<name>.*?) \[(?P<unit>[^\[\]]*)\]$")


def value(x: float, digits: int = DIGITS) -> float:
    """`x` rounded to `digits` significant digits (NaN and inf as they are)."""
    x = float(x)
    return float(f"{x:.{digits}g}") if math.isfinite(x) else x


def error(x: float) -> float:
    """An error figure rounded to `ERROR_DIGITS` significant digits."""
    return value(x, ERROR_DIGITS)


def _peak(col: np.ndarray) -> float:
    finite = np.abs(col[np.isfinite(col)])
    return float(finite.max()) if finite.size else 0.0


def _column_rounded(col: np.ndarray, scale: float) -> np.ndarray:
    """`col` rounded to the decimal of `DIGITS` significant digits of `scale` (> 0), each value the
    double nearest its decimal; NaN and inf kept, -0 as 0. The step 10^e: an integer number of
    steps times or over the exact power 10^|e| (|e| <= 22), one correctly rounded operation;
    beyond, exact decimal rounding (`Decimal.quantize`)."""
    if not (math.isfinite(scale) and scale > 0.0):
        return col + 0.0
    e = math.floor(math.log10(scale)) - DIGITS + 1
    if -22 <= e <= 0:
        f = float(10 ** -e)
        return np.rint(col * f) / f + 0.0
    if 0 < e <= 22:
        f = float(10 ** e)
        return np.rint(col / f) * f + 0.0
    step = Decimal(1).scaleb(e)
    return np.array([float(Decimal(x).quantize(step)) if math.isfinite(x) else x for x in col.tolist()],
                    dtype=float) + 0.0


def by_unit(values: Iterable[float], units: Iterable[str]) -> list[float]:
    """Each of `values` rounded to `DIGITS` significant digits of the largest |value| of its unit
    (the matching item of `units`) among `values`: a table of mixed units in one column."""
    x, u = np.asarray(list(values), dtype=float), np.asarray(list(units), dtype=object)
    out = x + 0.0
    for unit in set(u.tolist()):
        sel = u == unit
        out[sel] = _column_rounded(x[sel], _peak(x[sel]))
    return out.tolist()


def rounded(df, units: dict[str, str] | None = None):
    """A copy of `df` with every float column rounded to `DIGITS` significant digits of its unit's
    scale: the largest |value| among the float columns of the same unit (`units`, default
    `attrs["units"]`; a column with no unit: its own largest |value|). NaN kept; `attrs` kept.
    ValueError: a column name that appears twice."""
    twice = sorted(set(df.columns[df.columns.duplicated()]))
    if twice:
        raise ValueError(f"a table with the column {twice[0]!r} twice: a column is named once")
    units = df.attrs.get("units", {}) if units is None else units
    attrs, df = dict(df.attrs), df.copy(deep=False)
    df.attrs = {}              # pandas deep-copies `attrs` into every column `items` hands out
    cols = rounded_columns({name: col.to_numpy(dtype=float) for name, col in df.items() if col.dtype.kind == "f"},
                           units)
    # built from df.items() (type(df): pandas is passed in): indexing a wide frame by name, and
    # setting each column back, cost most of a report's CSV writing
    out = type(df)({name: cols.get(name, col) for name, col in df.items()}, index=df.index)
    out.attrs = attrs
    return out


def rounded_columns(cols: dict[str, np.ndarray], units: dict[str, str]) -> dict[str, np.ndarray]:
    """Float columns (name -> array) each rounded to `DIGITS` significant digits of its unit's
    scale: the largest |value| among the columns of the same unit (`units`; a column with no unit:
    its own largest |value|), as `rounded` rounds a frame's."""
    scale: dict[Any, float] = {}
    for name, col in cols.items():
        key = units.get(name) or ("column", name)
        scale[key] = max(scale.get(key, 0.0), _peak(col))
    return {name: _column_rounded(col, scale[units.get(name) or ("column", name)]) for name, col in cols.items()}


def header(df) -> list[str]:
    """The CSV header of `df`: each column as `name [unit]` (`attrs["units"]`), text columns bare."""
    return _named(df.columns, df.attrs.get("units", {}))


def _named(names: Iterable[str], units: dict[str, str]) -> list[str]:
    """Each column's name in a CSV header: `name [unit]`, a text column bare."""
    return [name if units.get(name, "") in _NO_UNIT else f"{name} [{units[name]}]" for name in names]


#: Rows of a CSV formatted at a time (`write_csv`): the text of all rows at once took 7 kB a row.
CSV_CHUNK = 4096


def write_csv(df, f: IO[str]) -> None:
    """`df` as CSV into the open text file `f`: units in the header, values `rounded`, as pandas'
    `to_csv(index=False, float_format=FLOAT_FORMAT)` writes them (a float `FLOAT_FORMAT`, NaN
    empty; other cells `str`, a missing one (None, NaN, NA) empty; quoted where the csv module must), column by
    column here (pandas formats cell by cell, half of a report's CSV time), CSV_CHUNK rows at a time."""
    def cells(col) -> list[str]:
        text = (lambda v: FLOAT_FORMAT % v) if col.dtype.kind == "f" else str
        return ["" if na else text(v) for v, na in zip(col.tolist(), col.isna().tolist())]
    w = csv.writer(f, lineterminator="\n")
    w.writerow(header(df))
    table = rounded(df)
    table.attrs = {}           # pandas deep-copies `attrs` into every column and every slice of one
    cols = [col for _, col in table.items()]
    for start in range(0, len(df), CSV_CHUNK):
        w.writerows(zip(*(cells(col.iloc[start:start + CSV_CHUNK]) for col in cols)))


def cell_text(x: Any) -> str:
    """One cell as `write_csv` writes it: a float `FLOAT_FORMAT`, a missing one (None, NaN) empty,
    other cells `str`."""
    if x is None:
        return ""
    if isinstance(x, (float, np.floating)):
        return "" if math.isnan(x) else FLOAT_FORMAT % x
    return str(x)


def rows_csv(names: Iterable[str], rows: Iterable[Iterable[Any]]) -> str:
    """CSV text of the header `names` and `rows` (each a row's cells, `cell_text`), lines ending
    "\\n", quoted where the csv module must: the text `write_csv` writes of a frame, without pandas."""
    return _csv(names, ([cell_text(x) for x in row] for row in rows))


def _csv(names: Iterable[str], rows: Iterable[Iterable[str]]) -> str:
    """CSV text of the header `names` and `rows` of cells already text, lines ending "\\n", quoted
    where the csv module must."""
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(names)
    w.writerows(rows)
    return buf.getvalue()


def columns_csv(cols: dict[str, np.ndarray], units: dict[str, str]) -> str:
    """Columns (name -> (N,) array) with their units as CSV text without pandas: the text
    `write_csv` writes of the frame of these columns with these `attrs["units"]` (float columns
    `rounded_columns`, cells `cell_text`)."""
    floats = rounded_columns({k: v for k, v in cols.items() if v.dtype.kind == "f"}, units)
    return _csv(_named(cols, units), zip(*(_cells(floats.get(k, v)) for k, v in cols.items())))


def _cells(col: np.ndarray) -> list[str]:
    """A column's cells as `cell_text` writes them; a float column without a test per value (a
    report's cycle.csv.gz has about 50 000)."""
    if col.dtype.kind != "f":
        return [cell_text(x) for x in col.tolist()]
    cells = [FLOAT_FORMAT % x for x in col.tolist()]
    for i in np.flatnonzero(np.isnan(col)).tolist():
        cells[i] = ""
    return cells


def csv_text(df) -> str:
    """`df` as the text `write_csv` writes."""
    buf = io.StringIO()
    write_csv(df, buf)
    return buf.getvalue()


def plain(x: Any) -> Any:
    """A cell as JSON: Python bool/int/float/str, NaN as None."""
    if isinstance(x, (bool, np.bool_)):
        return bool(x)
    if isinstance(x, (int, np.integer)):
        return int(x)
    if isinstance(x, (float, np.floating)):
        return float(x) if math.isfinite(x) else None
    return x


def _json_rows(df) -> Iterable[dict[str, Any]]:
    """The rows of `df`, `rounded`, one JSON-ready dict at a time."""
    df_r = rounded(df)
    return ({k: plain(v) for k, v in zip(df_r.columns, row)} for row in df_r.itertuples(index=False, name=None))


def _json_meta(df) -> dict[str, Any]:
    return {k: df.attrs[k] for k in ("mechanism", "units", "frame") if k in df.attrs}


def json_document(df) -> dict[str, Any]:
    """`df` as a JSON-ready dict: mechanism, units, frame (where `attrs` has them) and rows."""
    return {**_json_meta(df), "rows": list(_json_rows(df))}


def write_json(df, f: IO[str]) -> None:
    """`df` as JSON (`json_document`) into the open text file `f`, the text `json.dump(...,
    indent=1)` writes, one row at a time (the document of all rows at once took 11 kB a row)."""
    def dumps(x) -> str:
        return json.dumps(x, indent=1, allow_nan=False, ensure_ascii=False)
    head = dumps({**_json_meta(df), "rows": []})             # ... "rows": []\n}
    rows = iter(_json_rows(df))
    first = next(rows, None)
    if first is None:
        f.write(head + "\n")
        return
    f.write(head[:-len("[]\n}")] + "[\n  " + dumps(first).replace("\n", "\n  "))
    for row in rows:
        f.write(",\n  " + dumps(row).replace("\n", "\n  "))
    f.write("\n ]\n}\n")


def write_parquet(df, f: IO[bytes]) -> None:
    """`df` as Parquet into the open binary file `f`: full values, `attrs` in the pandas metadata."""
    df.to_parquet(f, index=False)


def read_csv(path):
    """A CSV written by `write_csv` as a DataFrame with bare column names and `attrs["units"]`."""
    import pandas as pd
    df = pd.read_csv(path)
    names, units = [], {}
    for col in df.columns:
        m = _HEADER.match(col)
        name = m["name"] if m else col
        names.append(name)
        units[name] = m["unit"] if m else "text"
    df.columns = names
    df.attrs["units"] = units
    return df
