"""The accuracy gate in pytest (`kinetostat_validation.pytest_plugin`, run in process with
pytester): model files as items, a failure at the published value's line, engine routes
skipped when their engines are hidden, JUnit properties, GitHub Actions' annotations and
summary (plugin and `kinetostat validate`); the regression fixture `kinetostat.testing`."""
from __future__ import annotations

import json
import subprocess
import sys
import xml.etree.ElementTree as ET
from importlib.metadata import entry_points

import numpy as np
import pytest

import kinetostat
from conftest import ROOT, four_bar
from kinetostat.report import quantities
from kinetostat.testing import CycleMismatch, check_cycle, obtained_path

pytest_plugins = ["pytester"]

CHAIN = ROOT / "models" / "chain_unit_four_bar.toml"
ENGINES = ("pinocchio", "mujoco", "pymunk")
TEXT = CHAIN.read_text(encoding="utf-8")
#: the chain unit's first published value (F_O1 min = 38.4 N, tolerance 1 %), raised by 5 %
ALTERED = TEXT.replace("\nvalue = 38.4\n", "\nvalue = 40.32\n", 1)
BAD_LINE = ALTERED.splitlines().index("value = 40.32") + 1
N_REFERENCE = len(quantities(kinetostat.load(CHAIN), "reference"))
N_PUBLISHED = 3
LEVER_TRUST = "internal identity: Zhukovsky's lever vs group-by-group"


@pytest.fixture(scope="module", autouse=True)
def engines_imported_before_pytester():
    """The installed engines imported before any in-process run: pytester puts sys.modules back
    as it found it after each run, and an engine's compiled extension first imported inside a run
    and dropped then cannot be imported again (later tests in this process would see it missing)."""
    for name in ENGINES:
        try:
            __import__(name)
        except ImportError:
            pass


def run(pytester, *args):
    """pytest in this process, in pytester's folder, at 36 positions per cycle (unless `args` say
    otherwise); without the cache and hypothesis's plugin (which pytester would import and
    assertion-rewrite again on every run)."""
    return pytester.runpytest_inprocess("--kinetostat-steps", "36", *args, "-p", "no:cacheprovider",
                                        "-p", "no:hypothesispytest")


@pytest.fixture
def folder(pytester):
    """models/good.toml (the chain unit), models/bad.toml (one published value altered) and a
    TOML file that is no model."""
    assert ALTERED != TEXT
    (pytester.path / "models").mkdir()
    (pytester.path / "models" / "good.toml").write_text(TEXT, encoding="utf-8")
    (pytester.path / "models" / "bad.toml").write_text(ALTERED, encoding="utf-8")
    (pytester.path / "models" / "settings.toml").write_text("[tool]\nname = 'x'\n", encoding="utf-8")
    return pytester


def test_the_plugin_is_installed_as_an_entry_point():
    (ep,) = [ep for ep in entry_points(group="pytest11") if ep.name == "kinetostat"]
    assert ep.value == "kinetostat_validation.pytest_plugin"


def test_loading_the_plugin_imports_neither_numpy_nor_the_solver():
    code = ("import sys, kinetostat_validation.pytest_plugin\n"
            "print(sorted(m for m in ('numpy', 'kinetostat', 'pandas', 'mpmath') if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert out.stdout.strip() == "[]", out.stderr


def test_one_altered_published_value_fails_at_its_line(folder):
    r = run(folder, "--kinetostat", "models", "-m", "not engines", "--junitxml=j.xml")
    r.assert_outcomes(failed=1, passed=2 * (N_REFERENCE + 1 + N_PUBLISHED) - 1)
    out = r.stdout.str()
    assert "_ bad published F_O1 min _" in out                       # the header names the model
    assert f"models/bad.toml:{BAD_LINE}: published value F_O1 min of bad: error 4.76 % > tolerance 1 %" in out
    assert "error   tolerance  max |diff|  unit  angle   route" in out
    assert f"tolerance set at models/bad.toml:{BAD_LINE + 2}" in out
    assert "FAILED models/bad.toml::published::F_O1_min" in out and "settings.toml" not in out
    # the JUnit file: error, tolerance and trust for every item
    cases = ET.parse(folder.path / "j.xml").getroot().findall(".//testcase")
    assert len(cases) == 2 * (N_REFERENCE + 1 + N_PUBLISHED)
    for case in cases:
        props = {p.get("name"): p.get("value") for p in case.findall("./properties/property")}
        assert float(props["error"]) >= 0 and float(props["tolerance"]) > 0, props
        if props["route"] == "reference":
            assert props["trust"].startswith("40-digit re-solution") and float(props["error"]) < 1e-13
        elif props["route"] == "lever":
            assert props["trust"] == LEVER_TRUST and props["quantity"] == "M_drive" and float(props["error"]) < 1e-14
        else:
            assert props["trust"].startswith("published value: Potapov 2024") and props["file"].startswith("models/")
        failed = case.find("failure") is not None
        assert failed == (props["file"] == "models/bad.toml" and props["line"] == str(BAD_LINE))
        assert failed == (props["passed"] == "False")


def test_engines_hidden_skip_the_engine_routes_and_the_rest_pass(folder, monkeypatch):
    for name in ENGINES:
        monkeypatch.setitem(sys.modules, name, None)
    r = run(folder, "--kinetostat", "models/good.toml", "-rs")
    mech = kinetostat.load(CHAIN)
    n_engine = sum(len(quantities(mech, route)) for route in ("pinocchio", "mujoco", "mujoco-sim", "pymunk"))
    r.assert_outcomes(passed=N_REFERENCE + 1 + N_PUBLISHED, skipped=n_engine)
    for route, engine in (("pinocchio", "pinocchio"), ("mujoco", "mujoco"), ("mujoco-sim", "mujoco"),
                          ("pymunk", "pymunk")):
        r.stdout.fnmatch_lines([f"SKIPPED [[]*[]] models/good.toml: route {route}: {engine} not installed*"])


def test_a_gate_that_checked_nothing_fails(folder, monkeypatch):
    """mpmath hidden, the published values deselected: the reference is skipped and only the
    internal lever identity runs, which is no independent check (as `kinetostat validate`)."""
    monkeypatch.setitem(sys.modules, "mpmath", None)
    r = run(folder, "--kinetostat", "models/good.toml", "-m", "not engines", "-k", "not published")
    r.assert_outcomes(passed=1, skipped=N_REFERENCE)
    assert r.ret == pytest.ExitCode.TESTS_FAILED
    assert "kinetostat: nothing was checked: every gate item was skipped but the lever" in r.stdout.str()


def test_selection_by_marker_and_keyword(folder):
    r = run(folder, "--kinetostat", "models/good.toml", "--collect-only", "-q", "-m", "engines",
                                   "-k", "pinocchio and R_1_2")
    r.stdout.fnmatch_lines(["models/good.toml::pinocchio::R_1_2", "1/* tests collected*"])


def test_opt_in_only_and_the_ini_option_collects_only_what_it_names(folder):
    r = run(folder, "models")
    assert r.ret == pytest.ExitCode.NO_TESTS_COLLECTED
    r = run(folder, "--kinetostat", "models", "--kinetostat-steps", "0")
    assert r.ret == pytest.ExitCode.USAGE_ERROR and "must be a positive integer, got 0" in r.stderr.str()
    folder.makeini("[pytest]\nkinetostat_models = models/g*.toml\n")
    r = run(folder, "models", "--collect-only", "-q", "-k", "published")
    assert r.stdout.lines[:N_PUBLISHED] == [f"models/good.toml::published::{s}"
                                            for s in ("F_O1_min", "F_O1_max", "phi_k_at_F_O1_max")]
    assert "bad.toml" not in r.stdout.str() and "settings.toml" not in r.stdout.str()
    r = run(folder, "--kinetostat", "models/bad.toml", "--collect-only", "-q", "-k", "published")  # the flag wins
    assert r.stdout.lines[0] == "models/bad.toml::published::F_O1_min" and "good.toml" not in r.stdout.str()


def test_github_annotation_and_summary(folder, monkeypatch):
    summary = folder.path / "summary.md"
    monkeypatch.setenv("GITHUB_ACTIONS", "true")
    monkeypatch.setenv("GITHUB_WORKSPACE", str(folder.path))
    monkeypatch.setenv("GITHUB_STEP_SUMMARY", str(summary))
    r = run(folder, "--kinetostat", "models", "-k", "published")
    r.assert_outcomes(failed=1, passed=2 * N_PUBLISHED - 1)
    (line,) = [ln for ln in r.stdout.lines if ln.startswith("::error ")]
    assert line.startswith(f"::error file=models/bad.toml,line={BAD_LINE},title=kinetostat%3A ")
    text = summary.read_text(encoding="utf-8")
    assert text.startswith("## kinetostat (pytest): FAIL\n\n5 passed, 1 failed, 0 errors, 0 skipped.")
    assert f"| models/bad.toml::published::F_O1_min | models/bad.toml:{BAD_LINE} | 4.76 % | 1 % | N |" in text
    monkeypatch.setenv("GITHUB_STEP_SUMMARY", str(folder.path / "no" / "such" / "folder.md"))
    r = run(folder, "--kinetostat", "models/good.toml", "-k", "published and F_O1_min")
    r.assert_outcomes(passed=1)
    (line,) = [ln for ln in r.stdout.lines if "GITHUB_STEP_SUMMARY" in ln]
    assert line.startswith("kinetostat: warning: cannot write the summary to $GITHUB_STEP_SUMMARY: ")


def test_validate_writes_the_summary_and_annotations(cli, tmp_path, monkeypatch):
    (tmp_path / "bad.toml").write_text(ALTERED, encoding="utf-8")
    summary = tmp_path / "summary.md"
    r = cli("validate", "bad.toml", "--engines", "reference", "--no-progress", "--json", "v.json", "--junit", "v.xml",
            env={"GITHUB_ACTIONS": "true", "GITHUB_STEP_SUMMARY": str(summary), "GITHUB_WORKSPACE": str(tmp_path)},
            cwd=tmp_path)
    assert r.returncode == 1
    assert f"::error file=bad.toml,line={BAD_LINE},title=kinetostat%3A bad.published.F_O1 min::" in r.stdout
    text = summary.read_text(encoding="utf-8")
    assert text.startswith(f"## kinetostat validate: FAIL\n\n{N_REFERENCE + 1 + N_PUBLISHED - 1} passed, 1 failed")
    checks = json.loads((tmp_path / "v.json").read_text())["models"][0]["checks"]
    assert {c["trust"].partition(":")[0] for c in checks} == {"internal identity", "40-digit re-solution",
                                                             "published value"}
    (lever,) = [c for c in checks if c["route"] == "lever"]
    assert lever["trust"] == LEVER_TRUST and lever["passed"] and lever["error"] < 1e-14
    # a summary path that cannot be written: one warning line, the gate's verdict unchanged
    r = cli("validate", "bad.toml", "--engines", "none", "--no-progress", cwd=tmp_path,
            env={"GITHUB_STEP_SUMMARY": str(tmp_path / "no" / "such" / "folder.md")})
    assert r.returncode == 1 and "Traceback" not in r.stderr
    (line,) = [ln for ln in r.stderr.splitlines() if "GITHUB_STEP_SUMMARY" in ln]
    assert line.startswith("kinetostat: warning: cannot write the summary to $GITHUB_STEP_SUMMARY: ")
    props = ET.parse(tmp_path / "v.xml").getroot().iter("property")
    trusts = [p.get("value") for p in props if p.get("name") == "trust"]
    assert trusts == [c["trust"] for c in checks]


# ----------------------------------------------------------------------------- regression fixture

def test_check_cycle_catches_a_tenth_of_a_percent_of_one_mass(tmp_path):
    expected = tmp_path / "four_bar.csv"
    with pytest.raises(CycleMismatch, match="did not exist"):          # a first run is never a pass
        check_cycle(kinetostat.loads(four_bar()), expected, steps=36)
    assert check_cycle(kinetostat.loads(four_bar()), expected, steps=36) == expected
    heavier = kinetostat.loads(four_bar(("mass = 1.5", "mass = 1.5015")))      # the coupler, +0.1 %
    with pytest.raises(CycleMismatch) as exc:
        check_cycle(heavier, expected, steps=36)
    diffs = {d.column: d for d in exc.value.diffs}
    assert obtained_path(expected).exists() and "obtained written to" in str(exc.value)
    assert str(exc.value).splitlines()[-1] == ("to accept the obtained values: regenerate=True, or "
                                               "KINETOSTAT_REGENERATE=1 in the environment")
    # the differences, in each column's unit, are the two solutions' own
    old, new = (kinetostat.analyze(m, steps=36) for m in (kinetostat.loads(four_bar()), heavier))
    d = diffs["M_bal"]
    assert d.unit == "N m" and d.max_abs == pytest.approx(np.max(np.abs(new.balancing_moment - old.balancing_moment)),
                                                          rel=1e-12)
    assert diffs["R_1_2"].unit == "N" and "x_B" not in diffs and "theta_3" not in diffs   # kinematics unchanged
    assert "R_1_2" in str(exc.value) and " N " in str(exc.value)
    # forces within 1 N pass by their unit's tolerance; the inertia moment's N m still fails
    with pytest.raises(CycleMismatch) as exc:
        check_cycle(heavier, expected, steps=36, atol={"N": 1.0, "m": 1.0, "deg": 1.0})
    assert {d.unit for d in exc.value.diffs} == {"N m"}
    check_cycle(heavier, expected, steps=36, regenerate=True)
    assert check_cycle(heavier, expected, steps=36) == expected and not obtained_path(expected).exists()


def test_regression_fixture_regenerates_with_the_flag(pytester):
    """The test in tests/, run from the folder above: the model's relative path is the test file's."""
    (pytester.path / "tests").mkdir()
    model = pytester.path / "tests" / "m.toml"
    model.write_text(four_bar(), encoding="utf-8")
    (pytester.path / "tests" / "test_press.py").write_text(
        "def test_design(kinetostat_regression):\n    kinetostat_regression('m.toml', steps=12)\n", encoding="utf-8")
    expected = pytester.path / "tests" / "test_press" / "test_design.csv"
    run(pytester, "tests").assert_outcomes(failed=1)     # written
    assert expected.exists()
    run(pytester, "tests").assert_outcomes(passed=1)
    model.write_text(four_bar(("mass = 1.2", "mass = 1.2012")), encoding="utf-8")
    r = run(pytester, "tests")
    r.assert_outcomes(failed=1)
    out = r.stdout.str()
    assert obtained_path(expected).exists() and "columns beyond tolerance" in out
    assert "def check" not in out and "check_cycle(" not in out and "testing.py" not in out   # the table, no source
    assert ("to accept the obtained values: run pytest again with --kinetostat-regen (or KINETOSTAT_REGENERATE=1 "
            "in the environment)") in out and "regenerate=True" not in out          # the flag, not the API's argument
    run(pytester, "tests", "--kinetostat-regen").assert_outcomes(passed=1)
    run(pytester, "tests").assert_outcomes(passed=1)


def test_a_route_failure_names_the_pair_and_the_routes_tolerance(folder, monkeypatch):
    from kinetostat_validation import compare as cmp
    monkeypatch.setitem(cmp.TOLERANCES, "reference", cmp.Tolerance(1e-30, "below any rounding: every check fails"))
    r = run(folder, "--kinetostat", "models/good.toml", "-k", "reference and R_1_2")
    r.assert_outcomes(failed=1)
    lines = TEXT.splitlines()
    at = lines.index("links = [1, 2]")
    pair = at - lines[at::-1].index("[[pair]]") + 1          # the line of that pair's [[pair]] header
    tol_line = cmp.__file__, next(n for n, ln in enumerate(open(cmp.__file__, encoding="utf-8"), 1)
                                  if ln.lstrip().startswith('"reference": Tolerance('))
    out = r.stdout.str()
    assert f"models/good.toml:{pair}: R(1,2) of good on route reference: error " in out
    assert "> tolerance 1e-30" in out and "trust: 40-digit re-solution" in out
    failures = out.split("short test summary info")[0]       # (with CI set, pytest repeats the whole message there)
    assert failures.count("tolerance set at ") == 1 and f"compare.py:{tol_line[1]}" in failures


def test_a_broken_model_file_is_one_collection_error_without_traceback(folder):
    (folder.path / "models" / "good.toml").write_text(TEXT.replace("mass = ", "masss = ", 1), encoding="utf-8")
    r = run(folder, "--kinetostat", "models/good.toml")
    assert r.ret == pytest.ExitCode.INTERRUPTED and "1 error" in r.stdout.str()
    assert "masss: unknown field (did you mean 'mass'?)" in r.stdout.str() and "Traceback" not in r.stdout.str()


def test_the_exact_engine_routes_pass_and_say_so(folder):
    """A sample of the engine routes (Pinocchio and MuJoCo at the solver's state; the simulated
    routes run in `kinetostat validate`'s own tests)."""
    pytest.importorskip("pinocchio")
    pytest.importorskip("mujoco")
    r = run(folder, "--kinetostat", "models/good.toml", "-m", "engines", "-k", "pinocchio or (mujoco and not sim)",
            "--junitxml=j.xml")
    n = len(quantities(kinetostat.load(CHAIN), "pinocchio")) + len(quantities(kinetostat.load(CHAIN), "mujoco"))
    r.assert_outcomes(passed=n)
    for case in ET.parse(folder.path / "j.xml").getroot().iter("testcase"):
        props = {p.get("name"): p.get("value") for p in case.findall("./properties/property")}
        assert props["trust"].startswith("independent engine: ") and float(props["error"]) < 1e-12, props


@pytest.mark.slow
def test_every_route_of_a_bundled_model_passes_in_pytest(pytester):
    """The whole gate of the bundled models with every installed engine, as `pytest --kinetostat`."""
    r = run(pytester, "--kinetostat", str(ROOT / "models"), "-q")
    assert r.ret == 0 and r.parseoutcomes()["passed"] > 800, r.stdout.str()[-2000:]
