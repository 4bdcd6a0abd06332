"""Regression checks for a user's own mechanisms: freeze a design's cycle (reactions, balancing
moment, kinematics: `Analysis.to_frame()`) in a CSV file and be told, column by column in each
column's unit, when a change to the model moves it.

    from kinetostat.testing import check_cycle
    check_cycle("models/press.toml", expected="tests/expected/press.csv", rtol=1e-9, atol={"N": 1e-6})

The first run writes the expected file and fails (look at it, commit it). A later run that
differs writes `<expected>.obtained.csv` beside it and raises `CycleMismatch`, whose message
lists the columns beyond tolerance; `regenerate=True` (or $KINETOSTAT_REGENERATE=1, or pytest's
`--kinetostat-regen` with the `kinetostat_regression` fixture) rewrites the expected file instead.

May use: numpy, pandas, the solver, `_io` (atomic writes, bounded reads).
"""
from __future__ import annotations

import math
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Mapping, Sequence

import numpy as np

from ._io import FileTooLarge, NotRegularFile, atomic, read_regular
from .solve import analyze
from .model import Mechanism, load

__all__ = ["check_cycle", "cycle_table", "ColumnDiff", "CycleMismatch", "obtained_path"]

#: Units whose columns are angles: compared as the shortest turn between the two values.
_TURN = {"deg": 360.0, "rad": 2 * math.pi}


@dataclass(frozen=True)
class ColumnDiff:
    """One column beyond its tolerance: the largest |obtained - expected|, in the column's unit."""
    column: str
    unit: str
    max_abs: float        # in `unit`; inf where one side is NaN and the other not
    tolerance: float      # atol + rtol * peak |expected|, in `unit`
    phi_deg: float        # crank angle of the largest difference, deg
    expected: float       # the two values there, in `unit`
    obtained: float


#: How a mismatch's message says to accept the obtained values through this API (the pytest
#: fixture names its `--kinetostat-regen` instead).
ACCEPT = "to accept the obtained values: regenerate=True, or KINETOSTAT_REGENERATE=1 in the environment"


class CycleMismatch(AssertionError):
    """The cycle differs from the expected file; `diffs` lists the columns beyond tolerance.
    `finding` is the message without the line `accept` (how to accept the obtained values, ""
    where there is nothing to accept), which ends it where given."""

    def __init__(self, message: str, diffs: Sequence[ColumnDiff] = (), accept: str = ""):
        super().__init__(f"{message}\n{accept}" if accept else message)
        self.finding, self.accept = message, accept
        self.diffs = tuple(diffs)


def cycle_table(model: Mechanism | str | Path, steps: int = 360, columns: Sequence[str] | None = None):
    """The model's cycle over `steps` equally spaced crank angles as a DataFrame (`to_frame`, the
    flag `singular` as 0/1), restricted to `columns` if given; `attrs["units"]` per column."""
    mech = model if isinstance(model, Mechanism) else load(model)
    df = analyze(mech, steps=steps).to_frame()
    units = dict(df.attrs["units"])
    if columns is not None:
        unknown = [c for c in columns if c not in df.columns]
        if unknown:
            raise ValueError(f"columns {unknown} are not in the cycle's table (columns: {list(df.columns)})")
        df = df[["phi_deg", *[c for c in columns if c != "phi_deg"]]]
    df = df.astype(float)
    df.attrs["units"] = {c: units[c] for c in df.columns}
    return df


def obtained_path(expected: str | Path) -> Path:
    """`x.csv` -> `x.obtained.csv`, beside it."""
    p = Path(expected)
    return p.with_name(p.stem + ".obtained" + p.suffix)


def _write(df, path: Path) -> None:
    """The table as CSV, headers `name [unit]`, every number to 17 significant digits."""
    path.parent.mkdir(parents=True, exist_ok=True)
    out = df.rename(columns={c: f"{c} [{df.attrs['units'][c]}]" for c in df.columns})
    with atomic(path) as f:
        out.to_csv(f, index=False, float_format="%.17g", lineterminator="\n")


#: Largest expected file read, bytes (a cycle of 360 positions of a bundled model: 0.3-0.6 MB).
MAX_EXPECTED_BYTES = 256 * 2**20


def _read(path: Path):
    """The expected table at `path`: a regular file of at most MAX_EXPECTED_BYTES (`read_regular`:
    a FIFO or a device there is a ValueError naming it, never waited on or read)."""
    import io

    import pandas as pd

    try:
        data = read_regular(path, MAX_EXPECTED_BYTES)
    except (NotRegularFile, FileTooLarge) as exc:
        raise ValueError(f"{path}: the expected file is not read: {exc.strerror}") from None
    raw = pd.read_csv(io.BytesIO(data))
    names, units = [], {}
    for head in raw.columns:
        name, _, unit = str(head).rpartition(" [")
        if not name or not unit.endswith("]"):
            raise ValueError(f"{path}: column {head!r} has no unit: expected 'name [unit]' (rewrite it with "
                             "regenerate=True)")
        names.append(name)
        units[name] = unit[:-1]
    raw.columns = names
    raw = raw.astype(float)
    raw.attrs["units"] = units
    return raw


def _tolerance(atol: float | Mapping[str, float] | None, column: str, unit: str) -> float:
    if atol is None:
        return 0.0
    if isinstance(atol, Mapping):
        return float(atol.get(column, atol.get(unit, 0.0)))
    return float(atol)


def _diff(column: str, unit: str, phi: np.ndarray, exp: np.ndarray, obt: np.ndarray, rtol: float,
          atol: float) -> ColumnDiff | None:
    """The column's ColumnDiff, or None when within atol + rtol * peak |expected|."""
    d = obt - exp
    if unit in _TURN:
        d = (d + _TURN[unit] / 2) % _TURN[unit] - _TURN[unit] / 2
    d = np.abs(d)
    both_nan = np.isnan(exp) & np.isnan(obt)
    d = np.where(both_nan, 0.0, np.where(np.isnan(d), np.inf, d))
    finite = np.abs(exp[np.isfinite(exp)])
    tol = atol + rtol * (float(finite.max()) if finite.size else 0.0)
    if not d.size or float(d.max()) <= tol:
        return None
    k = int(np.argmax(d))
    return ColumnDiff(column, unit, float(d[k]), tol, float(phi[k]), float(exp[k]), float(obt[k]))


def _table(diffs: Sequence[ColumnDiff], limit: int = 20) -> str:
    worst = sorted(diffs, key=lambda c: c.max_abs / c.tolerance if c.tolerance else math.inf, reverse=True)
    rows = [("column", "unit", "max |diff|", "tolerance", "at phi, deg", "expected", "obtained")]
    rows += [(c.column, c.unit, f"{c.max_abs:.3e}", f"{c.tolerance:.3e}", f"{c.phi_deg:g}", f"{c.expected:.10g}",
              f"{c.obtained:.10g}") for c in worst[:limit]]
    w = [max(len(r[i]) for r in rows) for i in range(len(rows[0]))]
    lines = ["  " + "  ".join(v.ljust(n) for v, n in zip(r, w)) for r in rows]
    if len(worst) > limit:
        lines.append(f"  ... and {len(worst) - limit} more columns")
    return "\n".join(lines)


def _regenerate_flag() -> bool:
    return os.environ.get("KINETOSTAT_REGENERATE", "").strip().lower() in ("1", "true", "yes")


def check_cycle(model: Mechanism | str | Path, expected: str | Path, *, rtol: float = 1e-9,
                atol: float | Mapping[str, float] | None = None, steps: int = 360,
                columns: Sequence[str] | None = None, regenerate: bool | None = None) -> Path:
    """Compare the model's cycle (`cycle_table`) with the CSV file `expected`, column by column.

    A column passes when max over the angles of |obtained - expected| <= atol + rtol * (the
    column's peak |expected|), both in the column's unit (angles: the shortest turn; NaN equals
    only NaN). `atol`: one number for every column, or a mapping from column name or unit
    ("N", "N m", "m/s^2", ...) to an absolute tolerance in that unit (0 for those not named).
    `regenerate` (default: $KINETOSTAT_REGENERATE) rewrites `expected` and passes. A missing
    expected file is written and the check fails, so that a first run is never taken as a pass.
    On a difference `<expected>.obtained.csv` is written and `CycleMismatch` raised, its message
    ending with how to accept the obtained values (ACCEPT); a pass removes the obtained file.
    Returns the expected file's path.
    """
    __tracebackhide__ = True             # pytest: a mismatch shows its table, not this function's source
    path = Path(expected)
    obt = cycle_table(model, steps, columns)
    name = model.name if isinstance(model, Mechanism) else str(model)
    if regenerate is None:
        regenerate = _regenerate_flag()
    out = obtained_path(path)
    if regenerate or not path.exists():
        _write(obt, path)
        if regenerate:
            out.unlink(missing_ok=True)
            return path
        raise CycleMismatch(f"{path} did not exist: the cycle of {name} is written there; look at it, keep it "
                            "under version control and run again")
    exp = _read(path)
    problems = []
    if list(exp.columns) != list(obt.columns):
        gone = [c for c in exp.columns if c not in obt.columns]
        new = [c for c in obt.columns if c not in exp.columns]
        problems.append(f"columns differ: missing {gone}, new {new}" if gone or new else "columns in another order")
    if len(exp) != len(obt):
        problems.append(f"{len(exp)} crank angles expected, {len(obt)} obtained (steps = {steps})")
    diffs = []
    if not problems:
        phi = obt["phi_deg"].to_numpy()
        units = obt.attrs["units"]
        for c in obt.columns:
            if exp.attrs["units"][c] != units[c]:
                problems.append(f"column {c}: unit {exp.attrs['units'][c]!r} expected, {units[c]!r} obtained")
                continue
            d = _diff(c, units[c], phi, exp[c].to_numpy(), obt[c].to_numpy(), rtol, _tolerance(atol, c, units[c]))
            if d is not None:
                diffs.append(d)
    if not problems and not diffs:
        out.unlink(missing_ok=True)          # a previous failure's table, no longer true
        return path
    _write(obt, out)
    head = (f"the cycle of {name} differs from {path} "
            f"(rtol {rtol:g} of each column's peak, atol {atol if atol is not None else 0}); "
            f"obtained written to {out}")
    body = "\n".join(f"  {p}" for p in problems) if problems else (
        f"{len(diffs)} of {len(obt.columns)} columns beyond tolerance:\n" + _table(diffs))
    raise CycleMismatch(f"{head}\n{body}", diffs, ACCEPT)
