"""The gate needs no engine: the models' published values ([[published]]) and the 40-digit
reference route are checks of `kinetostat validate`, which still gates accuracy with Pinocchio,
MuJoCo and pymunk hidden; JUnit and JSON carry every check's measured error."""
from __future__ import annotations

import json
import math
import sys
from dataclasses import replace

import numpy as np
import pytest

import kinetostat
from conftest import FOUR_BAR, ROOT
from kinetostat.errors import ModelError
from kinetostat.report import junit_xml, published_rows, quantities, run_validation, validation_json
from kinetostat_validation import compare as cmp
from kinetostat_validation.reference import sample_angles
from kinetostat_validation.scene import EngineResult

ICE = ROOT / "models" / "ice_crank_slider.toml"
CHAIN = ROOT / "models" / "chain_unit_four_bar.toml"
SIX = ROOT / "models" / "furnace_loader_six_bar.toml"
#: reference-route checks of the ICE and the chain unit together (forces, F_bal, friction losses)
N_REFERENCE = sum(len(quantities(kinetostat.load(p), "reference")) for p in (ICE, CHAIN))
ENGINES = ("pinocchio", "mujoco", "pymunk")

@pytest.fixture
def hidden(monkeypatch) -> None:
    """Every physics engine unimportable in this process for the test (as on a CI without them):
    `import pinocchio` raises ImportError, as `kinetostat_validation.compare.available` reads it."""
    for name in ENGINES:
        monkeypatch.setitem(sys.modules, name, None)


# ----------------------------------------------------------------------------- published values

def by_symbol(path) -> dict:
    return {c.entry.symbol: c for c in published_rows(kinetostat.load(path))}


def test_ice_published_values_reproduce_the_seed():
    """Seed 002 prints M_bal = 102.74 N m (force plans) and 102.97 N m (lever) at 30 deg."""
    got = by_symbol(ICE)
    assert len(got) == 15
    for symbol, seed in [("M_bal (force plans)", 102.74), ("M_bal (lever)", 102.97), ("R32", 6481.0),
                         ("V_B", 10.94), ("eps2", 33782.0)]:
        c = got[symbol]
        assert c.entry.value == seed and c.entry.tolerance == 0.005 and c.entry.angles == (30.0,)
        assert abs(c.exact - seed) <= 0.005 * seed and c.passed, symbol
    assert got["V_BA"].entry.relative_to == "A" and got["R43"].entry.pair == (0, 3)


def test_chain_unit_published_range_reproduces_the_paper():
    """Seed 004, line 389: F_O1 = 38.4 .. 286.9 N over the 10-deg cycle, largest near 90 deg."""
    got = by_symbol(CHAIN)
    assert abs(got["F_O1 max"].exact - 286.9) <= 0.01 * 286.9
    assert abs(got["F_O1 min"].exact - 38.4) <= 0.01 * 38.4
    top = got["phi_k at F_O1 max"]
    assert top.by_angle and top.exact == 90.0 and top.entry.unit == "deg" and top.entry.tolerance == 10.0
    assert len(top.entry.angles) == 36 and top.passed
    # the same number straight from the solver over the paper's sampling
    res = kinetostat.analyze(kinetostat.load(CHAIN), phi_deg=np.arange(0.0, 360.0, 10.0))
    assert got["F_O1 max"].exact == pytest.approx(np.linalg.norm(res.reaction(0, 1), axis=-1).max(), rel=1e-14)


def test_a_model_without_published_values_has_none():
    mech = kinetostat.loads(FOUR_BAR)
    assert mech.published == () and published_rows(mech) == []
    assert mech.drive.design_deg == 30.0


def test_design_position_is_read_from_the_model():
    assert kinetostat.load(CHAIN).drive.design_deg == 90.0
    assert kinetostat.load(ICE).drive.design_deg == 30.0
    with pytest.raises(ModelError, match=r"drive\.design_deg: expression \"top\": unknown name 'top'"):
        kinetostat.loads(FOUR_BAR.replace('kind = "engine"', 'kind = "engine"\ndesign_deg = "top"'))


GOOD = '''
[[published]]
symbol = "R12"
quantity = "reaction"
pair = [1, 2]
angle = 30.0
value = 100.0
tolerance = 0.01
source = "test"
'''

BAD_ENTRIES = {
    "unknown point": (GOOD.replace('quantity = "reaction"\npair = [1, 2]', 'quantity = "velocity"\npoint = "Q"'),
                      r"published\[0\]\.point: unknown point 'Q'"),
    "no such pair": (GOOD.replace("pair = [1, 2]", "pair = [1, 3]"), r"published\[0\]\.pair: no kinematic pair"),
    "frame as link": (GOOD.replace('quantity = "reaction"\npair = [1, 2]', 'quantity = "omega"\nlink = 0'),
                      r"published\[0\]\.link: unknown moving link 0"),
    "unknown quantity": (GOOD.replace('"reaction"', '"power"'), r"published\[0\]\.quantity: invalid value 'power'"),
    "field of another quantity": (GOOD.replace("pair = [1, 2]", "pair = [1, 2]\npoint = \"A\""),
                                  r"published\[0\]\.point: unknown field"),
    "list without reduce": (GOOD.replace("angle = 30.0", "angle = [0.0, 90.0]"), r"published\[0\]\.reduce: missing"),
    "reduce on one angle": (GOOD.replace("angle = 30.0", 'angle = 30.0\nreduce = "max"'),
                            r"published\[0\]\.reduce: only with a list"),
    "deg tolerance on a force": (GOOD.replace("tolerance = 0.01", "tolerance_deg = 5.0"),
                                 r"published\[0\]\.tolerance_deg: only reduce = 'angle_of_max'"),
    "wrong unit": (GOOD.replace("value = 100.0", 'value = 100.0\nunit = "kN"'),
                   r"published\[0\]\.unit: reaction is in 'N', got 'kN'"),
    "no source": (GOOD.replace('source = "test"\n', ""), r"published\[0\]\.source: missing"),
    "nan angle": (GOOD.replace("angle = 30.0", "angle = nan"), r"published\[0\]\.angle: expected a finite number"),
    "zero tolerance": (GOOD.replace("tolerance = 0.01", "tolerance = 0.0"), r"published\[0\]\.tolerance: must be > 0"),
    "repeated symbol": (GOOD + GOOD, r"published\[1\]\.symbol: 'R12' is already used by published\[0\]"),
    "balancing force of an engine": (GOOD.replace('quantity = "reaction"\npair = [1, 2]',
                                                  'quantity = "balancing_force"'),
                                     r"published\[0\]\.quantity: a balancing force needs drive\.kind = 'machine'"),
}


def test_a_good_entry_is_read():
    (p,) = kinetostat.loads(FOUR_BAR + GOOD).published
    assert (p.symbol, p.quantity, p.pair, p.angles, p.reduce, p.unit) == ("R12", "reaction", (1, 2), (30.0,), None, "N")


@pytest.mark.parametrize("case", sorted(BAD_ENTRIES))
def test_a_bad_published_entry_names_the_field(case):
    text, pattern = BAD_ENTRIES[case]
    with pytest.raises(ModelError, match=pattern):
        kinetostat.loads(FOUR_BAR + text)


def test_a_failing_published_value_fails_the_run():
    mech = kinetostat.loads(FOUR_BAR + GOOD.replace("value = 100.0", "value = 1.0"))
    run = run_validation(mech, [], steps=24)
    lever, check = run.checks                      # the lever identity runs in every validation
    assert lever.route == "lever" and lever.passed
    assert check.name.endswith(".published.R12") and not check.passed and check.error > 0.01
    assert not run.passed


def test_the_lever_identity_is_a_check_that_can_fail():
    """Zhukovsky's lever against the groups' balancing moment: rounding only on the solver; a
    lever moment off by 1e-6 of itself fails; alone it is no independent check."""
    mech = kinetostat.loads(FOUR_BAR)
    res = kinetostat.analyze(mech, steps=24)
    run = run_validation(mech, [], res=res)
    (lever,) = run.checks
    assert lever.name.endswith(".lever.M_drive") and lever.unit == "N m" and lever.passed
    assert lever.error == pytest.approx(np.max(np.abs(res.lever_discrepancy)) / np.max(np.abs(res.balancing_moment)))
    assert lever.error < 1e-14 and lever.tolerance == cmp.TOLERANCES["lever"].peak_relative
    assert lever.trust == "internal identity: Zhukovsky's lever vs group-by-group"
    assert run.passed and not run.checked
    off = run_validation(mech, [], res=replace(res, lever_moment=res.lever_moment * (1 + 1e-6)))
    (lever,) = off.checks
    assert not lever.passed and lever.error == pytest.approx(1e-6, rel=1e-3) and not off.passed


# ----------------------------------------------------------------------------- the reference route

@pytest.mark.parametrize("path", [ICE, SIX], ids=["ice", "six_bar"])
def test_reference_route_passes_on_the_solver(path):
    mech = kinetostat.load(path)
    c = cmp.compare(mech, engines=["reference"], steps=72)
    assert c.passed and not c.skipped
    assert {r.quantity for r in c.rows} == set(quantities(mech, "reference"))
    tol = cmp.TOLERANCES["reference"].peak_relative
    for r in c.rows:
        assert r.route == "reference" and r.tolerance == tol and r.peak_relative < tol
        assert r.n_compared == len(sample_angles(kinetostat.analyze(mech, steps=72))) and r.n_skipped == 0
        assert r.phi_deg_max in c.results["reference"].phi_deg


def test_reference_route_catches_a_reaction_one_percent_off():
    mech = kinetostat.load(ICE)
    res = kinetostat.analyze(mech, steps=72)
    R = res.forces.R.copy()
    R[:, mech.pair_between(1, 2).index] *= 1.01
    bad = replace(res, forces=replace(res.forces, R=R))
    c = cmp.compare(mech, engines=["reference"], res=bad)
    assert not c.passed
    (failed,) = [r for r in c.rows if not r.passed]
    assert failed.quantity == "R(1,2)" and failed.peak_relative == pytest.approx(0.01 / 1.01, rel=1e-9)


def test_rows_of_a_route_on_some_of_the_angles():
    """An engine result at a subset of the solver's angles is compared at those angles only."""
    mech = kinetostat.loads(FOUR_BAR)
    res = kinetostat.analyze(mech, steps=36)
    at = np.array([3, 17, 30])
    er = EngineResult("test", "exact", res.phi_deg[at], res.balancing_moment[at] + 1.0, res.forces.R[at])
    rows = {r.quantity: r for r in cmp.errors(res, er, 1e-9, "test")}
    M = rows["M_drive"]
    assert M.n_compared == 3 and M.max_abs == pytest.approx(1.0)
    assert M.peak == pytest.approx(np.max(np.abs(res.balancing_moment)))
    assert rows["R(0,1)"].max_abs == 0.0
    with pytest.raises(ValueError, match="not among the solver's angles"):
        cmp.errors(res, replace(er, phi_deg=res.phi_deg[at] + 1.0), 1e-9, "test")


def test_reference_route_is_skipped_without_mpmath(monkeypatch):
    assert cmp.available("reference") is None
    monkeypatch.setitem(sys.modules, "mpmath", None)
    assert "mpmath not installed" in cmp.available("reference")


# ----------------------------------------------------------------------------- JUnit and JSON

def test_junit_carries_every_checks_error_also_when_passing():
    mech = kinetostat.load(ICE)
    run = run_validation(mech, ["reference"], steps=36, path=ICE)
    root = junit_xml([run]).getroot()
    cases = root.findall("./testsuite/testcase")
    names = {f"{c.get('classname')}.{c.get('name')}" for c in cases}
    assert names == {c.name for c in run.checks}
    assert "ice_crank_slider.reference.R(1,2)" in names and "ice_crank_slider.published.M_bal (lever)" in names
    assert "ice_crank_slider.lever.M_drive" in names
    assert root.get("tests") == str(len(quantities(mech, "reference")) + 1 + 15) and root.get("failures") == "0"
    for case in cases:
        props = {p.get("name"): p.get("value") for p in case.findall("./properties/property")}
        assert float(props["error"]) <= float(props["tolerance"]) and case.find("system-out").text


def test_json_writes_nan_as_null():
    mech = kinetostat.loads(FOUR_BAR)
    res = kinetostat.analyze(mech, steps=24)
    R = res.forces.R.copy()
    R[:, 0] = np.nan                                   # a quantity the solver has no value for
    run = run_validation(mech, ["reference"], res=replace(res, forces=replace(res.forces, R=R)))
    doc = json.loads(json.dumps(validation_json([run], 1), allow_nan=False))
    (nan_check,) = [c for c in doc["models"][0]["checks"] if c["error"] is None]
    assert nan_check["passed"] is False and doc["totals"]["failed"] >= 1 and not doc["passed"]


# ----------------------------------------------------------------------------- the CLI without engines

def test_validate_with_the_engines_hidden(cli, hidden):
    r = cli("validate", ICE, CHAIN, "--steps", 72, "--no-progress")
    assert r.returncode == 0, r.stdout + r.stderr
    assert "Traceback" not in r.stderr
    for engine in ENGINES:
        assert f"SKIPPED: {engine} not installed" in r.stdout
    assert r.stdout.count("route(s) skipped") == 3
    for stem, n_pub in (("ice_crank_slider", 15), ("chain_unit_four_bar", 3)):
        assert f"== {stem}:" in r.stdout and f"({n_pub} published values)" in r.stdout
    lines = r.stdout.splitlines()
    assert sum(ln.split()[:1] == ["reference"] and ln.endswith("PASS") for ln in lines) == N_REFERENCE
    assert sum(ln.split()[:1] == ["published"] and ln.endswith("PASS") for ln in lines) == 18
    assert "4 route(s) skipped" in lines[-1] or "8 route(s) skipped" in lines[-1]


def test_validate_json_with_the_engines_hidden(cli, hidden):
    r = cli("validate", ICE, CHAIN, "--steps", 72, "--json", "-")
    assert r.returncode == 0, r.stderr
    doc = json.loads(r.stdout)
    assert doc["passed"] and doc["exit_code"] == 0
    assert doc["totals"]["checks"] == N_REFERENCE + 2 + 18 and doc["totals"]["failed"] == 0   # 2: the lever
    ice = doc["models"][0]
    assert ice["model"] == "ice_crank_slider" and set(ice["skipped"]) == {"pinocchio", "mujoco", "mujoco-sim", "pymunk"}
    checks = {c["name"]: c for c in ice["checks"]}
    ref = checks["ice_crank_slider.reference.M_drive"]
    assert ref["measure"] == "peak_relative" and ref["unit"] == "N m" and 0 <= ref["error"] < ref["tolerance"]
    lever = checks["ice_crank_slider.lever.M_drive"]
    assert lever["trust"].startswith("internal identity") and 0 <= lever["error"] < lever["tolerance"]
    pub = checks["ice_crank_slider.published.M_bal (lever)"]
    assert pub["measure"] == "relative" and pub["tolerance"] == 0.005 and pub["passed"]
    assert math.isfinite(pub["error"]) and pub["phi_deg"] == 30.0
    assert "== ice_crank_slider:" in r.stderr           # the people's table went to stderr


def test_engines_none_stands_alone(cli):
    r = cli("validate", ICE, "--engines", "none", "pinocchio")
    assert r.returncode == 2 and "stands alone" in r.stderr and "Traceback" not in r.stderr


def test_report_without_engines(tmp_path, cli, hidden, sketched_report):
    pytest.importorskip("matplotlib")
    r = cli("report", "ice_crank_slider", "--engines", "none", "--steps", 12, "--out", tmp_path, "--no-progress",
            "--no-page")                                # a bundled model by its name
    assert r.returncode == 0, r.stdout + r.stderr
    md = (tmp_path / "ice_crank_slider" / "index.md").read_text()
    assert "- **Model file**: ice_crank_slider.toml" in md   # the file's name, as a run from its path says
    assert not (tmp_path / "ice_crank_slider" / "page.html").exists() and "page.html" not in md     # --no-page
    assert "## Against the published values" in md and r"| M\_зр (lever) |" in md      # the text's lettering
    assert r"| reference | M\_зр |" in md and "| reference | mpmath |" not in md
    assert "## The mechanism at φ = 30°" in md
