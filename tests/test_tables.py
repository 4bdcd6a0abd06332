"""The tables a user gets (kinetostat.tables): units in every format, plain numbers, and the
digits that mean something, so that a last-ulp difference between machines prints the same."""
from __future__ import annotations

import io
import json
import re
import warnings
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import kinetostat
from kinetostat import tables

from conftest import EVERY_GROUP, MODELS, sampled


def _frame(values: dict, units: dict) -> pd.DataFrame:
    df = pd.DataFrame(values)
    df.attrs.update(mechanism="m", units=units, frame="world frame")
    return df


def test_a_last_ulp_difference_and_rounding_noise_print_the_same():
    x = np.array([2862.81234567891, -1234.5, 3e-17, 0.1 + 0.2])
    y = np.nextafter(x, np.inf)                        # one ulp up: another machine's rounding
    y[2] = -5e-17                                      # a zero within rounding, other sign
    units = {"R": "N"}
    a, b = tables.csv_text(_frame({"R": x}, units)), tables.csv_text(_frame({"R": y}, units))
    assert a == b == "R [N]\n2862.81234568\n-1234.5\n0\n0.3\n"     # 12 digits of the column's peak


def test_a_column_of_rounding_noise_prints_0():
    """The scale is the unit's, shared by its columns: a column that is noise alone prints 0, in
    every text format, and no cell has more than 12 significant digits (np.round's 1e-18 artifacts)."""
    df = _frame({"x_A": [0.12, -0.05], "x_B": [-3.4694469519500004e-18, 2e-17], "F": [9.520000000000001e-24, 0.0],
                 "M": [1 / 3, 2.0]}, {"x_A": "m", "x_B": "m", "F": "N", "M": "N m"})
    assert tables.csv_text(df) == "x_A [m],x_B [m],F [N],M [N m]\n0.12,0,9.52e-24,0.33333333333\n-0.05,0,0,2\n"
    assert tables.json_document(df)["rows"][0] == {"x_A": 0.12, "x_B": 0.0, "F": 9.52e-24, "M": 0.33333333333}
    assert tables.by_unit([0.12, 3e-17, 1 / 3], ["m", "m", "N"]) == [0.12, 0.0, 0.333333333333]
    assert tables.by_unit([1.23456789012345e14, 5.0, -4.4e-12], ["Pa", "Pa", "m"]) == [1.23456789012e14, 0.0, -4.4e-12]


def _digits(cell: str) -> int:
    """Significant digits of a CSV number cell (0 for text)."""
    m = re.fullmatch(r"-?(\d+)(?:\.(\d+))?(?:e[-+]?\d+)?", cell)
    return len((m[1] + (m[2] or "")).lstrip("0")) if m else 0


@pytest.mark.parametrize("path", sampled(MODELS, EVERY_GROUP))
def test_the_bundled_models_cycle_csv_prints_no_noise(path):
    """Every cell of a bundled model's cycle CSV has at most 12 significant digits, and a nonzero
    cell is at least 1e-12 of its unit's largest |value| (a value 0 within rounding prints 0).
    (Every group kind by default, every bundled model with -m slow.)"""
    df = kinetostat.analyze(kinetostat.load(path), steps=72).to_frame()
    text = tables.csv_text(df).splitlines()
    units = df.attrs["units"]
    peak: dict[str, float] = {}
    for c in df.columns:
        if df[c].dtype.kind == "f":
            v = np.abs(df[c].to_numpy(dtype=float))
            peak[units[c]] = max(peak.get(units[c], 0.0), float(v[np.isfinite(v)].max(initial=0.0)))
    floor = [0.99e-12 * peak[units[c]] if df[c].dtype.kind == "f" else None for c in df.columns]   # per column, once
    for line in text[1:]:
        for c, least, cell in zip(df.columns, floor, line.split(",")):
            assert _digits(cell) <= 12, (c, cell)
            if least is not None and cell not in ("", "inf", "-inf"):
                assert float(cell) == 0.0 or abs(float(cell)) >= least, (c, cell)


def test_units_in_the_header_and_read_back():
    df = _frame({"phi_deg": [0.0, 30.0], "R_0_1": [1.5, np.nan], "error": ["", "AssemblyError: x"]},
                {"phi_deg": "deg", "R_0_1": "N", "error": "text"})
    text = tables.csv_text(df)
    assert text.splitlines()[0] == "phi_deg [deg],R_0_1 [N],error"
    back = tables.read_csv(io.StringIO(text))
    assert list(back.columns) == ["phi_deg", "R_0_1", "error"] and back.attrs["units"]["R_0_1"] == "N"
    doc = tables.json_document(df)
    assert doc["units"] == df.attrs["units"] and doc["frame"] == "world frame"
    assert doc["rows"][1] == {"phi_deg": 30.0, "R_0_1": None, "error": "AssemblyError: x"}
    json.dumps(doc, allow_nan=False)


def test_segments_and_worksheet_hold_plain_numbers(tmp_path):
    """segments.csv held repr() of numpy scalars (np.float64(20.16...)); every number cell parses."""
    plans = kinetostat.plans.build(kinetostat.load("ice_crank_slider"), at=30.0, only=["velocity"])
    text = plans.segments_csv()
    assert "np." not in text
    seg = pd.read_csv(io.StringIO(text))
    pb = seg[seg.segment == "p-b"].iloc[0]
    assert abs(pb.length_mm - 54.6) < 0.01 and abs(pb.length_mm * 0.2 - pb.value) <= 1e-10 * pb.value
    from kinetostat.plans.worksheet import worksheet
    sheet = worksheet(kinetostat.load("ice_crank_slider"), 30.0)
    sheet.to_csv(tmp_path / "w.csv")
    w = pd.read_csv(tmp_path / "w.csv")
    assert "np." not in (tmp_path / "w.csv").read_text() and w["value"].dtype == float
    exact = sheet.value("omega_1")
    assert float(w.loc[w.key == "omega_1", "value"].iloc[0]) == float(f"{exact:.12g}")


def test_write_csv_writes_what_pandas_to_csv_writes():
    """The CSV writer (column by column) against pandas' own to_csv of the rounded frame: floats
    with NaN and inf, nullable integers and booleans with NA, text with a comma, a quote and a
    newline, None; a failed design of a sweep is such a row (NA peaks, the reason in text)."""
    df = pd.DataFrame({"x": [0.1, np.nan, np.inf, -1.5e-7, 30.0],
                       "n": pd.array([1, None, 3, 0, -2], dtype="Int64"),
                       "ok": pd.array([True, None, False, True, False], dtype="boolean"),
                       "why": ['a, "b"', None, "line\nbreak", "", "plain"],
                       "k": [1, 2, 3, 4, 5]})
    df.attrs["units"] = {"x": "m", "n": "1", "ok": "1", "why": "text", "k": "1"}
    want = tables.rounded(df).to_csv(index=False, header=tables.header(df), lineterminator="\n",
                                     float_format=tables.FLOAT_FORMAT)
    assert tables.csv_text(df) == want
    assert "x [m],n [1]" in want and ',,,,2\n' in want          # the NA row: every missing cell empty


def test_rows_csv_writes_what_pandas_to_csv_writes():
    """segments.csv and the worksheet's CSV are written without pandas (`rows_csv`): each cell as
    pandas' to_csv(float_format=FLOAT_FORMAT) writes it: floats with NaN and inf, None, text with
    a comma, a quote and a newline, a formula led by a quote, integers, booleans; and `columns_csv`
    (a report's cycle.csv.gz) of arrays what `csv_text` writes of their frame."""
    cols = {"x": [0.1, np.nan, np.inf, -1.5e-7, 30.0, 1 / 3],
            "why": ['a, "b"', None, "line\nbreak", "", "plain", "'=1"], "k": [1, 2, 3, 4, 5, -6],
            "ok": [True, False] * 3}
    want = pd.DataFrame(cols).to_csv(index=False, lineterminator="\n", float_format=tables.FLOAT_FORMAT)
    assert tables.rows_csv(cols, zip(*cols.values())) == want
    assert tables.rows_csv(cols, []) == "x,why,k,ok\n"
    arrays = {"x": np.array(cols["x"]), "k": np.array(cols["k"]), "ok": np.array(cols["ok"])}   # columns_csv's own cells
    frame = pd.DataFrame(arrays)
    frame.attrs["units"] = {"x": "m"}
    assert tables.columns_csv(arrays, {"x": "m"}) == tables.csv_text(frame)


def test_a_variants_cycle_csv_is_the_frames_csv_without_pandas():
    """A variant's cycle.csv is written from `Analysis.columns` (`columns_csv`, no pandas): the
    bytes `csv_text` writes of `to_frame` with the text's names (`with_aliases`), for a model with
    friction in the reactions (Pfr_, eta, the bool self_locking, the integer passes) and a variant
    whose frame is lettered 4 (R_4_1 after R_0_1, M_зр after M_bal)."""
    from kinetostat.model.lettering import with_alias_columns, with_aliases
    ice = kinetostat.load(Path(__file__).resolve().parents[1] / "models" / "ice_crank_slider.toml")
    variant = kinetostat.variants.variant(1, "479").mechanism()
    for mech, friction in ((variant, "first"), (ice, "reactions")):
        with warnings.catch_warnings():             # the ICE self-locks with friction at its dead centres
            warnings.simplefilter("ignore", kinetostat.errors.SelfLockingWarning)
            res = kinetostat.analyze(mech, steps=24, friction=friction)
        text = tables.columns_csv(*with_alias_columns(*res.columns(), mech))
        assert text == tables.csv_text(with_aliases(res.to_frame(), mech))
    assert {"R_4_1 [N]", "M_зр [N m]"} <= set(tables.columns_csv(*with_alias_columns(
        *kinetostat.analyze(variant, steps=2).columns(), variant)).splitlines()[0].split(","))


def test_a_column_named_twice_is_refused():
    df = pd.DataFrame([[1.0, 2.0]], columns=["phi_deg", "phi_deg"])
    with pytest.raises(ValueError, match="column 'phi_deg' twice"):
        tables.csv_text(df)


class _Copies:
    """An `attrs` value that counts its deep copies (pandas deep-copies `attrs` into what it derives)."""
    made = 0

    def __deepcopy__(self, memo):
        _Copies.made += 1
        return self


@pytest.mark.parametrize("columns, rows", [(2, 10), (40, 10), (2, 2 * tables.CSV_CHUNK + 1)])
def test_write_csv_copies_the_tables_attrs_a_fixed_number_of_times(columns, rows):
    """A cycle.csv of 153 columns took three deep copies of its units a column (half of its writing
    time): their number does not grow with the columns or the rows."""
    df = _frame({f"x{k}": np.arange(rows, dtype=float) for k in range(columns)}, {"x0": "N"})
    df.attrs["counted"] = _Copies()
    _Copies.made = 0
    tables.write_csv(df, io.StringIO())
    assert _Copies.made <= 2
