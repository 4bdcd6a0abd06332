"""The tables a user gets (`analyze --out`, a report's cycle.csv, sweep tables, a variant's
cycle.csv; segments.csv and the worksheets round with `rounded` and `value`), written one way: CSV, JSON or Parquet of a pandas DataFrame whose `attrs["units"]`
gives each column's unit, with the units in every format and the numbers of the text formats
to the digits that mean something.

- CSV: the header names each column with its unit, `R_0_1 [N]` (a text column: its bare name);
  `read_csv` reads such a file back with bare names and `attrs["units"]`.
- JSON: `{"mechanism", "units", "frame", "rows": [one object per row]}`, NaN as null.
- Parquet: the full binary values, `attrs` (units, frame, mechanism) in the file's pandas metadata.

Text formats round each float column to `DIGITS` significant digits of the column's largest
|value| (`rounded`): the solver's accuracy is relative to a quantity's peak (about 1e-15), so
digits below 1e-12 of the peak are rounding noise that differs between machines (a last-ulp
difference, or a value that is 0 within rounding printed as 3e-17).

May use: numpy, the standard library; pandas is passed in (never imported here).
"""
from __future__ import annotations

import io
import json
import math
import re
from typing import IO, Any

import numpy as np

__all__ = ["DIGITS", "ERROR_DIGITS", "rounded", "value", "error", "header", "write_csv", "csv_text", "plain",
           "json_document", "write_json", "write_parquet", "read_csv"]

#: Significant digits of a value in a text output, counted on its column's largest |value|.
DIGITS = 12
#: Significant digits of an error (a difference between two routes, a relative error).
ERROR_DIGITS = 3
#: Units that are no unit: a column of text (no bracket in a CSV header).
_NO_UNIT = ("text", "")
_HEADER = re.compile(r"^(?P<name>.*?) \[(?P<unit>[^\[\]]*)\]$")


def value(x: float, digits: int = DIGITS) -> float:
    """`x` rounded to `digits` significant digits (NaN and inf as they are)."""
    x = float(x)
    return float(f"{x:.{digits}g}") if math.isfinite(x) else x


def error(x: float) -> float:
    """An error figure rounded to `ERROR_DIGITS` significant digits."""
    return value(x, ERROR_DIGITS)


def _column_rounded(col: np.ndarray) -> np.ndarray:
    finite = np.abs(col[np.isfinite(col)])
    peak = float(finite.max()) if finite.size else 0.0
    decimals = DIGITS - 1 - math.floor(math.log10(peak)) if peak > 0.0 else 0
    if decimals > 290:                       # a column of subnormal-sized values: 10**decimals overflows
        return col + 0.0
    if decimals < 0:                         # peak >= 1e12: np.round would multiply by 10**-decimals, inexactly
        q = 10.0 ** -decimals
        return np.array([float(f"{round(x / q):.0f}e{-decimals}") if math.isfinite(x) else x for x in col]) + 0.0
    return np.round(col, decimals) + 0.0     # + 0.0: -0.0 as 0.0


def rounded(df):
    """A copy of `df` with every float column rounded to `DIGITS` significant digits of its
    largest |value| (NaN kept); `attrs` kept."""
    # built from df.items() (type(df): pandas is passed in): indexing a wide frame by name, and
    # setting each column back, cost most of a report's CSV writing
    out = type(df)({name: _column_rounded(col.to_numpy(dtype=float)) if col.dtype.kind == "f" else col
                        for name, col in df.items()}, index=df.index)
    out.attrs = dict(df.attrs)
    return out


def header(df) -> list[str]:
    """The CSV header of `df`: each column as `name [unit]` (`attrs["units"]`), text columns bare."""
    units = df.attrs.get("units", {})
    return [name if units.get(name, "") in _NO_UNIT else f"{name} [{units[name]}]" for name in df.columns]


def write_csv(df, f: IO[str]) -> None:
    """`df` as CSV into the open text file `f`: units in the header, values `rounded`."""
    rounded(df).to_csv(f, index=False, header=header(df), lineterminator="\n")


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


def json_document(df) -> dict[str, Any]:
    """`df` as a JSON-ready dict: mechanism, units, frame (where `attrs` has them) and rows."""
    df_r = rounded(df)
    rows = [{k: plain(v) for k, v in zip(df_r.columns, row)} for row in df_r.itertuples(index=False, name=None)]
    meta = {k: df.attrs[k] for k in ("mechanism", "units", "frame") if k in df.attrs}
    return {**meta, "rows": rows}


def write_json(df, f: IO[str]) -> None:
    """`df` as JSON (`json_document`) into the open text file `f`."""
    json.dump(json_document(df), f, indent=1, allow_nan=False, ensure_ascii=False)
    f.write("\n")


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
