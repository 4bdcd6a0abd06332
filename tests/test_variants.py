"""Seed 002's task variants (`kinetostat.variants`, `kinetostat variant`): the code selects the
columns the text says, the built model equals a model written by hand from the table and the
bundled models of the same data, and every code builds and runs."""
from __future__ import annotations

import json
import random
import warnings
from pathlib import Path

import numpy as np
import pytest

import kinetostat
from kinetostat import variants

ROOT = Path(__file__).resolve().parents[1]
HAND_479 = ROOT / "tests" / "data" / "task1_479.toml"


def _same_numbers(a: kinetostat.Mechanism, b: kinetostat.Mechanism, rtol: float = 1e-12) -> None:
    """Every reaction and the balancing moment at 360 crank angles agree to `rtol` of their peak."""
    ra, rb = kinetostat.analyze(a, steps=360), kinetostat.analyze(b, steps=360)
    assert ra.forces.R.shape == rb.forces.R.shape
    R_peak = np.max(np.abs(rb.forces.R))
    M_peak = np.max(np.abs(rb.balancing_moment))
    assert np.max(np.abs(ra.forces.R - rb.forces.R)) <= rtol * R_peak
    assert np.max(np.abs(ra.balancing_moment - rb.balancing_moment)) <= rtol * M_peak


# ----------------------------------------------------------------------------- the code

def test_code_479_selects_the_columns_the_text_names():
    # seed 002 lines 58-63: "479479" under а б в г д е -> а 4, б 7, в 9, г 4, д 7, е 9
    cols = variants.columns(1, "479")
    assert cols == {"n1": 4, "l_OA": 7, "phi1": 9, "ratio": 4, "s_ratio": 7, "d": 9,
                    "p_max": 4, "G3": 7, "G2": 7, "I_S2": 9}
    # the values as table 1.1 prints them in those columns (lines 88-114, read here by hand)
    assert variants.values(1, "479") == {"n1": 4200, "l_OA": 0.048, "phi1": 150, "ratio": 3.7, "s_ratio": 0.5,
                                         "d": 0.078, "p_max": 2.8, "G3": 3.7, "G2": 4.8, "I_S2": 0.0021}
    # tables 1.2 and 1.3 (lines 131-150, 169-188)
    assert variants.values(2, "479") == {"n1": 5000, "l_OA": 0.038, "ratio": 3.95, "s_ratio": 0.5, "phi1": 90,
                                         "d": 0.08, "p_max": 2.8, "G_piston": 3.4, "G_rod": 4.2}
    assert variants.values(3, "479") == {"n1": 325, "l_OA": 0.08, "ratio": 3.95, "G2": 58, "G3": 46,
                                         "s_ratio": 0.5, "d": 0.154, "p_max": 0.2, "phi1": 150}


def test_tables_have_ten_columns_and_the_texts_letters():
    for spec in variants.TASKS.values():
        assert [r.letter for r in spec.rows][:6] == list("абвгде")
        assert all(len(r.values) == 10 for r in spec.rows)
    # table 1.1: the repeated row "б" (G3 and G2), then "в" (I_S2): both weights take the second digit
    t1 = {r.key: r.letter for r in variants.TASKS[1].rows}
    assert (t1["G3"], t1["G2"], t1["I_S2"]) == ("б", "б", "в")


# ----------------------------------------------------------------------------- task 1, code 479

def test_variant_1_479_by_the_command_equals_the_hand_written_model(cli, tmp_path):
    run = cli("variant", "1", "479", "--out", tmp_path, "--no-pack")      # the pack: test_pack
    assert run.returncode == 0, run.stderr
    assert "а=4 б=7 в=9 г=4 д=7 е=9" in run.stdout
    for name in ("task1_479.toml", "worksheet.md", "worksheet.html", "worksheet.csv", "worksheet.json",
                 "positions.svg", "velocity.svg", "acceleration.svg", "forces_2-3.svg", "lever.svg",
                 "segments.csv", "cycle.csv"):
        assert (tmp_path / name).stat().st_size > 0, name
    built = kinetostat.load(tmp_path / "task1_479.toml")
    hand = kinetostat.load(HAND_479)
    assert built.drive.design_deg == hand.drive.design_deg == 150.0
    _same_numbers(built, hand)
    # the key's worksheet is at phi1 = 150 deg and its M_bal is the hand model's there
    sheet = json.loads((tmp_path / "worksheet.json").read_text())
    assert sheet["phi_deg"] == 150.0
    rows = {r["key"]: r for r in sheet["rows"]}
    M_hand = kinetostat.analyze(hand, phi_deg=[150.0]).balancing_moment[0]
    assert rows["M_bal"]["value"] == pytest.approx(M_hand, rel=1e-12)
    cycle = np.loadtxt(tmp_path / "cycle.csv", delimiter=",", skiprows=1, usecols=0)
    assert len(cycle) == 360


def test_generated_file_states_the_assumptions():
    text = variants.variant(1, "479").toml()
    header = "\n".join(line for line in text.splitlines() if line.startswith("#"))
    for words in ("а=4  б=7  в=9  г=4  д=7  е=9", "labels both G3 and G2 with row 'б'", "Indicator diagram",
                  "figure 1.1b not available", "no friction", "l_AB = 3.7 * 0.048"):
        assert words in header, words
    assert len(kinetostat.loads(text).assumptions) >= 6


# ----------------------------------------------------------------------------- the bundled models

def test_worked_example_through_the_builder_is_the_bundled_ice_model():
    """Sec. 1.2's data are no code of table 1.1 (l_AB/l_OA = 3.05, d = 0.08, I_S2 = 0.0017 are in no
    column): fed as values, the builder gives the bundled ice_crank_slider's numbers, whose friction
    changes only the friction power, and the text's M_bal = 102.74 N m (force plans, 0.5 %)."""
    built = variants.build(1, variants.WORKED_EXAMPLE).mechanism()
    bundled = kinetostat.load("ice_crank_slider")
    _same_numbers(built, bundled)
    M = kinetostat.analyze(built, phi_deg=[30.0]).balancing_moment[0]
    assert abs(M) == pytest.approx(102.74, rel=0.005)


@pytest.mark.parametrize("task, bundled", [(2, "opposed_twin"), (3, "compressor")])
def test_variant_000_is_the_bundled_model(task, bundled):
    """The bundled opposed_twin and compressor were written by hand for code 000."""
    _same_numbers(variants.variant(task, "000").mechanism(), kinetostat.load(bundled))


# ----------------------------------------------------------------------------- every code

def _runs(task: int, code: str) -> None:
    v = variants.variant(task, code)
    mech = v.mechanism()
    res = kinetostat.analyze(mech, steps=360)
    assert not res.singular.any()
    # Zhukovsky's lever, an independent route to M_bal, agrees with the group-by-group M_bal
    assert np.max(np.abs(res.lever_discrepancy)) <= 1e-9 * np.max(np.abs(res.balancing_moment))
    # the written file is the model
    assert kinetostat.loads(v.toml()).links == mech.links


SAMPLE = sorted(random.Random(2002).sample(variants.codes(), 30))


@pytest.mark.parametrize("task", [1, 2, 3])
def test_a_sample_of_codes_builds_and_runs(task):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for code in SAMPLE:
            _runs(task, code)


@pytest.mark.slow
@pytest.mark.parametrize("task", [1, 2, 3])
def test_every_code_builds_and_runs(task):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for code in variants.codes():
            _runs(task, code)


def test_all_writes_one_key_per_code_and_an_index(cli, tmp_path, monkeypatch):
    monkeypatch.setattr(variants, "codes", lambda: ["000", "479", "999"])
    run = cli("variant", "3", "--all", "--out", tmp_path, "--no-progress", "--no-pack")
    assert run.returncode == 0, run.stderr
    index = (tmp_path / "index.md").read_text()
    for code in ("000", "479", "999"):
        folder = tmp_path / f"task3_{code}"
        assert (folder / f"task3_{code}.toml").is_file() and (folder / "worksheet.md").is_file()
        assert not (folder / "cycle.csv").exists()
        M = kinetostat.analyze(variants.variant(3, code).mechanism(),
                               phi_deg=[variants.values(3, code)["phi1"]]).balancing_moment[0]
        assert f"| [{code}](task3_{code}/worksheet.md) | " in index
        assert f"| {M:.2f} |".replace(".", ",") in index           # seed 002's language, its decimal comma
    assert index.startswith("# Логвіненко, Надтока 2021")


# ----------------------------------------------------------------------------- bad input

@pytest.mark.parametrize("args, names", [
    (["4", "479"], "TASK: unknown task '4'; Logvinenko, Nadtoka 2021 has tasks 1, 2, 3"),
    (["0", "000"], "TASK: unknown task '0'"),
    (["one", "479"], "TASK: unknown task 'one'"),
    (["1", "47"], "CODE: '47' is not a variant of task 1: expected three digits 000..999"),
    (["2", "4790"], "CODE: '4790' is not a variant of task 2"),
    (["3", "4a9"], "CODE: '4a9' is not a variant of task 3"),
    (["1"], "TASK and CODE are required"),
    (["1", "479", "--all"], "CODE '479': not with --all"),
])
def test_bad_task_or_code_exit_2_naming_it(cli, args, names, tmp_path):
    run = cli("variant", *args, "--out", tmp_path / "out")
    assert run.returncode == 2
    assert names in run.stderr
    assert "Traceback" not in run.stderr and len(run.stderr.strip().splitlines()) == 1
    assert not (tmp_path / "out").exists()


def test_api_errors_name_the_argument():
    with pytest.raises(ValueError, match="^task: unknown task 5"):
        variants.variant(5, "000")
    with pytest.raises(ValueError, match="^code: 479 is not a variant of task 1"):
        variants.variant(1, 479)            # an int would lose a leading zero: text only
    with pytest.raises(ValueError, match="values: task 2 needs"):
        variants.build(2, {"n1": 5000.0})


def test_help_names_the_command_and_its_options(cli):
    assert "variant" in cli("--help").stdout
    h = cli("variant", "--help")
    assert h.returncode == 0 and "usage: kinetostat variant" in h.stdout
    for word in ("TASK", "CODE", "--all", "--out", "--lang"):
        assert word in h.stdout
