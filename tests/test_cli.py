"""The command line: happy paths of every command, the validation gate's exit codes and JUnit
file, and every bad input giving exit code 2, one line naming the problem and no traceback.

Most tests call `kinetostat.cli.main` in this process (the `cli` fixture of conftest); the real
program (`python -m kinetostat`, the `kinetostat` script) runs where only a process shows it:
the interpreter's exit status, the entry points, output to a real pipe."""
from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import xml.etree.ElementTree as ET
from dataclasses import replace
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import kinetostat
from conftest import FOUR_BAR, ROOT
from kinetostat.cli import EXIT_FAIL, EXIT_NOT_CHECKED, EXIT_OK, EXIT_USAGE, exit_code
from kinetostat.report import junit_xml, quantities, run_validation
from kinetostat.tables import read_csv

ICE = ROOT / "models" / "ice_crank_slider.toml"
EXACT = ["pinocchio", "mujoco"]          # the fast engine routes


def run_process(*args, env: dict | None = None, cwd: Path | None = None) -> subprocess.CompletedProcess:
    """`python -m kinetostat ARGS` as a separate process."""
    e = dict(os.environ)
    e.pop("KINETOSTAT_MODELS", None)
    e.update(env or {})
    return subprocess.run([sys.executable, "-m", "kinetostat", *map(str, args)], capture_output=True, text=True,
                          env=e, cwd=cwd or ROOT, timeout=300)


@pytest.fixture
def four_bar(tmp_path) -> Path:
    p = tmp_path / "four_bar.toml"
    p.write_text(FOUR_BAR, encoding="utf-8")
    return p


# ----------------------------------------------------------------------------- help and entry points

def test_help_of_every_command(cli):
    top = cli("--help")
    assert top.returncode == 0
    for cmd in ("analyze", "structure", "validate", "report", "examples", "export", "plans", "variant"):
        assert cmd in top.stdout
        h = cli(cmd, "--help")
        assert h.returncode == 0, h.stderr
        assert "usage: kinetostat " + cmd in h.stdout
    assert "--junit" in cli("validate", "--help").stdout
    assert "--at" in cli("analyze", "--help").stdout
    flat = " ".join(top.stdout.split())
    assert "3 validate: nothing failed but a model was not checked" in flat and "130 interrupted" in flat
    sweep = " ".join(cli("sweep", "--help").stdout.split())
    assert "Exit codes: 0 the table written, also when some designs failed" in sweep


def test_console_script_entry_point():
    exe = shutil.which("kinetostat", path=os.path.dirname(sys.executable)) or shutil.which("kinetostat")
    if exe is None:
        pytest.skip("console script not installed (pip install -e .)")
    r = subprocess.run([exe, "structure", str(ICE)], capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    assert "I(0,1) <- II(2,3)" in r.stdout


@pytest.mark.parametrize("args", [[], ["analyze", "no_such_model.toml"]], ids=["no command", "missing file"])
def test_usage_error_is_the_process_exit_status(args, tmp_path):
    """The real program: exit status 2 and one error line, no traceback (also from another folder)."""
    r = run_process(*args, cwd=tmp_path)
    assert r.returncode == EXIT_USAGE
    assert "Traceback" not in r.stderr and r.stderr.startswith("kinetostat: error:")
    assert len(r.stderr.strip().splitlines()) == 1


# ----------------------------------------------------------------------------- structure and analyze

def test_structure_ice(cli):
    r = cli("structure", ICE)
    assert r.returncode == 0, r.stderr
    assert "W = 3n - 2p5 - p4 = 3*3 - 2*4 - 0 = 1" in r.stdout
    assert "II(2,3)  RRP (kind 2)" in r.stdout
    assert "structure formula: I(0,1) <- II(2,3)" in r.stdout


def test_structure_four_bar(cli, four_bar):
    r = cli("structure", four_bar)
    assert r.returncode == 0, r.stderr
    assert "RRR (kind 1)" in r.stdout and "= 1" in r.stdout


def test_analyze_cycle_to_csv(cli, tmp_path):
    out = tmp_path / "ice.csv"
    r = cli("analyze", ICE, "--steps", 36, "--out", out)
    assert r.returncode == 0, r.stderr
    df = read_csv(out)
    frame = kinetostat.analyze(kinetostat.load(ICE), steps=36).to_frame()
    assert len(df) == 36 and list(df.columns) == list(frame.columns)
    assert df.attrs["units"] == frame.attrs["units"]            # the header: "M_bal [N m]"
    assert "M_bal [N m]" in out.read_text().splitlines()[0]
    M = frame["M_bal"].to_numpy()
    np.testing.assert_allclose(df["M_bal"], M, rtol=0, atol=6e-12 * np.abs(M).max())   # 12 digits of the peak
    for text in ("I(0,1) <- II(2,3)", "R(0,1) at O", "balancing moment M_bal:", "lever discrepancy"):
        assert text in r.stdout


def test_analyze_at_angles_to_json(cli, four_bar, tmp_path):
    out = tmp_path / "fb.json"
    r = cli("analyze", four_bar, "--at", 0, 45, -90.5, "--out", out)
    assert r.returncode == 0, r.stderr
    doc = json.loads(out.read_text())
    rows = doc["rows"]
    res = kinetostat.analyze(kinetostat.load(four_bar), phi_deg=[0, 45, 269.5])
    assert len(rows) == 3 and doc["units"]["R_0_1"] == "N" and doc["units"]["phi_deg"] == "deg"
    assert [row["R_0_1"] for row in rows] == pytest.approx(np.linalg.norm(res.reaction(0, 1), axis=-1), rel=1e-11)
    assert "269.5" in r.stdout       # the per-angle values are printed for a few angles (-90.5 as 269.5)
    assert "-90.5 -> 269.5" in r.stderr


def test_analyze_csv_to_stdout(cli):
    r = cli("analyze", ICE, "--at", 30, "--out", "-")
    assert r.returncode == 0, r.stderr
    assert r.stdout.splitlines()[0].startswith("phi_deg [deg],")
    assert len(r.stdout.strip().splitlines()) == 2
    assert "balancing moment" in r.stderr       # the summary moves to stderr


def test_analyze_parquet(cli, tmp_path):
    out = tmp_path / "ice.parquet"
    r = cli("analyze", ICE, "--steps", 12, "--out", out)
    try:
        import pyarrow  # noqa: F401
    except ImportError:
        assert r.returncode == EXIT_USAGE
        assert "pyarrow" in r.stderr and len(r.stderr.strip().splitlines()) == 1
        assert not out.exists()
    else:
        assert r.returncode == 0, r.stderr
        df = pd.read_parquet(out)
        assert len(df) == 12 and df.attrs["units"]["R_0_1"] == "N" and "world frame" in df.attrs["frame"]


def test_singular_position_warning_is_one_line(cli, tmp_path):
    # rocker 0.05 m: at phi = 180 deg |AC| = 0.4 = l2 + l3, the dyad is stretched (toggle)
    p = tmp_path / "toggle.toml"
    p.write_text(FOUR_BAR.replace("C = [0.0, 0.0], B = [0.3, 0.0], S3 = [0.12, -0.01]",
                                  "C = [0.0, 0.0], B = [0.05, 0.0], S3 = [0.02, -0.01]"))
    r = cli("analyze", p, "--at", 179.9, 180.1)
    assert r.returncode == 0, r.stderr
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("kinetostat: warning:") and "singular" in lines[0]


# ----------------------------------------------------------------------------- validate

def test_validate_passes_on_exact_engines_and_writes_junit(cli, tmp_path):
    junit = tmp_path / "junit.xml"
    r = cli("validate", ICE, "--engines", *EXACT, "--junit", junit)
    assert r.returncode == EXIT_OK, r.stdout + r.stderr
    assert "Traceback" not in r.stderr
    n_q = len(quantities(kinetostat.load(ICE)))            # M_drive and 4 reactions
    n_pub = len(kinetostat.load(ICE).published)            # the seed's 15 published values
    assert r.stdout.count("PASS") >= 2 * n_q + n_pub
    root = ET.parse(junit).getroot()
    assert root.tag == "testsuites"
    assert (root.get("tests"), root.get("failures"), root.get("errors"), root.get("skipped")) == \
        (str(2 * n_q + 1 + n_pub), "0", "0", "0")               # 1: the lever identity
    cases = root.findall("./testsuite/testcase")
    assert len(cases) == 2 * n_q + 1 + n_pub
    assert {c.get("classname") for c in cases} == {"ice_crank_slider.lever", "ice_crank_slider.pinocchio",
                                                   "ice_crank_slider.mujoco", "ice_crank_slider.published"}


def test_validate_all_bundled_models_via_env(cli, four_bar, tmp_path):
    """Without MODEL: every *.toml of $KINETOSTAT_MODELS (here a directory holding the four-bar)."""
    r = cli("validate", "--engines", "pinocchio", "--steps", 24, env={"KINETOSTAT_MODELS": str(four_bar.parent)})
    assert r.returncode == EXIT_OK, r.stdout + r.stderr
    assert "== four_bar:" in r.stdout and "1 model(s)" in r.stdout


@pytest.fixture(scope="module")
def ice_cycle():
    mech = kinetostat.load(ICE)
    return mech, kinetostat.analyze(mech, steps=36)


def test_validate_fails_on_a_broken_solver_result(ice_cycle):
    """One reaction scaled by 1.01 must fail the gate, for that quantity only, on every route."""
    mech, res = ice_cycle
    good = run_validation(mech, EXACT, steps=36, res=res, path=ICE)
    assert exit_code([good]) == EXIT_OK
    p = mech.pair_between(1, 2)
    R = res.forces.R.copy()
    R[:, p.index] *= 1.01
    bad = replace(res, forces=replace(res.forces, R=R))
    run_bad = run_validation(mech, EXACT, steps=36, res=bad, path=ICE)
    assert exit_code([run_bad]) == EXIT_FAIL
    assert exit_code([good, run_bad]) == EXIT_FAIL
    assert {(r.route, r.quantity) for r in run_bad.failed} == {("pinocchio", "R(1,2)"), ("mujoco", "R(1,2)")}
    # error 0.01 |R| against the peak of the (scaled) result under test
    assert all(abs(r.peak_relative - 0.01 / 1.01) < 1e-9 for r in run_bad.failed)
    root = junit_xml([run_bad]).getroot()
    assert root.get("failures") == "2"
    failed = [c for c in root.iter("testcase") if c.find("failure") is not None]
    assert {c.get("name") for c in failed} == {"R(1,2)"}


def test_route_errors_and_skips_are_reported_not_raised(ice_cycle, monkeypatch):
    """A route that raises becomes an ERROR of that route (others still run); a route whose
    engine is missing is SKIPPED, never passed. JUnit: <error> and <skipped> per quantity."""
    from kinetostat_validation import compare as cmp
    mech, res = ice_cycle

    def broken(scene):
        raise RuntimeError("adapter exploded\nsecond line")

    monkeypatch.setitem(cmp.ROUTES, "broken", ("numpy", broken))
    monkeypatch.setitem(cmp.ROUTES, "absent", ("no_such_engine_pkg", broken))
    monkeypatch.setitem(cmp.TOLERANCES, "broken", cmp.Tolerance(1e-9, "test"))
    monkeypatch.setitem(cmp.TOLERANCES, "absent", cmp.Tolerance(1e-9, "test"))
    run_ = run_validation(mech, ["pinocchio", "broken", "absent"], steps=36, res=res, path=ICE)
    assert run_.errors == {"broken": "RuntimeError: adapter exploded"}
    assert "absent" in run_.skipped and run_.status("absent") == "SKIPPED"
    assert run_.status("pinocchio") == "PASS" and run_.status("broken") == "ERROR"
    assert exit_code([run_]) == EXIT_FAIL
    root = junit_xml([run_]).getroot()
    n_q, n_pub = len(quantities(mech)), len(mech.published)
    assert (root.get("tests"), root.get("failures"), root.get("errors"), root.get("skipped")) == \
        (str(3 * n_q + 1 + n_pub), "0", str(n_q), str(n_q))
    # only skipped routes on a model without published values: nothing checked is not a pass
    four = kinetostat.loads(FOUR_BAR)
    only_skipped = run_validation(four, ["absent"], steps=36)
    assert only_skipped.passed and [c.route for c in only_skipped.checks] == ["lever"]      # the identity alone
    assert not only_skipped.checked and exit_code([only_skipped]) == EXIT_NOT_CHECKED
    assert exit_code([run_validation(mech, EXACT, steps=36, res=res, path=ICE), only_skipped]) == EXIT_NOT_CHECKED


# ----------------------------------------------------------------------------- bad input

BROKEN_TOML = "[mechanism\nname = 'x'\n"


def _bad_cases(tmp: Path, four_bar: Path) -> dict[str, tuple[list, str]]:
    (tmp / "syntax.toml").write_text(BROKEN_TOML)
    (tmp / "noassy.toml").write_text(FOUR_BAR.replace("B = [0.35, 0.0], S2 = [0.15, 0.02]",
                                                      "B = [0.05, 0.0], S2 = [0.02, 0.01]"))
    # the rocker's pivot removed: W = 3*3 - 2*3 = 3, not a mobility-1 chain
    (tmp / "w2.toml").write_text(FOUR_BAR.replace('[[pair]]\nkind = "R"\nlinks = [0, 3]\npoint = "C"\n', "")
                                 .replace("C = [0.0, 0.0], B = [0.3, 0.0]", "Q = [0.0, 0.0], B = [0.3, 0.0]"))
    (tmp / "afile").write_text("not a directory")
    blocked = tmp / "afile"
    return {
        "missing file": (["analyze", tmp / "nope.toml"], "model file not found"),
        "missing file (validate)": (["validate", tmp / "nope.toml", "--engines", "pinocchio"], "not found"),
        "toml syntax": (["structure", tmp / "syntax.toml"], "TOML syntax error"),
        "unknown engine": (["validate", ICE, "--engines", "pinocchio", "warp"], "unknown engine route(s) warp"),
        "unknown engine (report)": (["report", ICE, "--engines", "bullet", "--out", tmp / "r"], "Valid names"),
        "bad --at": (["analyze", ICE, "--at", "thirty"], "invalid crank angle 'thirty'"),
        "--at nan": (["analyze", ICE, "--at", "nan"], "finite"),
        "--at and --steps": (["analyze", ICE, "--at", "30", "--steps", "10"], "not allowed with"),
        "bad --steps": (["validate", ICE, "--steps", "0"], "positive integer"),
        "not assemblable": (["analyze", tmp / "noassy.toml"], "cannot be assembled"),
        "not assemblable (report)": (["report", tmp / "noassy.toml", "--out", tmp / "r2"], "cannot be assembled"),
        "mobility 3": (["structure", tmp / "w2.toml"], "mobility W"),
        "unwritable --out file": (["analyze", ICE, "--out", blocked / "x.csv"], "cannot write --out"),
        "unknown table suffix": (["analyze", ICE, "--out", tmp / "x.xlsx"], "unknown table format"),
        "unwritable --out dir": (["report", ICE, "--out", blocked / "reports"], "cannot write --out"),
        "unwritable --junit": (["validate", ICE, "--engines", "pinocchio", "--junit", blocked / "j.xml"],
                               "cannot write --junit"),
        "empty models dir": (["validate", "--engines", "pinocchio"], "no bundled models"),
    }


CASES = ["missing file", "missing file (validate)", "toml syntax", "unknown engine", "unknown engine (report)",
         "bad --at", "--at nan", "--at and --steps", "bad --steps", "not assemblable", "not assemblable (report)",
         "mobility 3", "unwritable --out file", "unknown table suffix", "unwritable --out dir", "unwritable --junit",
         "empty models dir"]


@pytest.mark.parametrize("case", CASES)
def test_bad_input_exit_2_one_line_no_traceback(cli, case, tmp_path, four_bar):
    args, phrase = _bad_cases(tmp_path, four_bar)[case]
    empty = tmp_path / "empty"
    empty.mkdir()
    r = cli(*args, env={"KINETOSTAT_MODELS": str(empty)})
    assert r.returncode == EXIT_USAGE, (r.stdout, r.stderr)
    assert "Traceback" not in r.stderr
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1, r.stderr
    assert lines[0].startswith("kinetostat: error:") and phrase in lines[0], lines[0]


def test_model_error_lists_every_problem(cli, tmp_path):
    p = tmp_path / "bad.toml"
    p.write_text(FOUR_BAR.replace("mass = 1.5", "mass = -1.5").replace("I_S = 0.009", "I_S = 'big'"))
    r = cli("analyze", p)
    assert r.returncode == EXIT_USAGE and "Traceback" not in r.stderr
    assert "2 problems" in r.stderr and "mass: must be >= 0" in r.stderr and "I_S: expression \"big\": unknown name 'big'" in r.stderr
