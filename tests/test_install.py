"""Every install runs every command it offers, and `validate` says what it did not check.

Default: `validate`'s statement per model (what checked it, what did not and why) and its exit
code 3 for a model that nothing checked. Slow: the wheel installed WITHOUT extras into a fresh
venv runs analyze, structure, plans, variant, sweep (in process, CSV) and validate --engines none."""
from __future__ import annotations

import json
import os
import subprocess
import sys
import venv
from pathlib import Path

import pytest

from conftest import FOUR_BAR, ROOT
from kinetostat.cli import EXIT_NOT_CHECKED, EXIT_OK

ICE = ROOT / "models" / "ice_crank_slider.toml"


@pytest.fixture
def absent_route(monkeypatch):
    """A route "absent" whose engine package is not installed (so every model skips it)."""
    from kinetostat_validation import compare as cmp
    monkeypatch.setitem(cmp.ROUTES, "absent", ("no_such_engine_pkg", None))
    monkeypatch.setitem(cmp.TOLERANCES, "absent", cmp.Tolerance(1e-9, "test"))
    return "absent"


def test_a_model_nothing_checked_is_not_checked_exit_3(cli, tmp_path, absent_route):
    """The ICE model has 15 published values (checked); the four-bar has none and its only route
    is skipped: it is NOT CHECKED (never a pass), the run exits 3, and the JSON says the same."""
    (tmp_path / "four_bar.toml").write_text(FOUR_BAR)
    r = cli("validate", ICE, tmp_path / "four_bar.toml", "--engines", absent_route, "--steps", "12",
            "--json", tmp_path / "v.json", "--no-progress")
    assert r.returncode == EXIT_NOT_CHECKED == 3, r.stderr
    blocks = r.stdout.split("== ")
    ice, four = blocks[1], blocks[2]
    assert "checked by: published (15 values); the lever identity held; not checked by: absent (" in ice and "=> PASS" in ice
    assert "checked by: nothing; the lever identity held; not checked by: absent (" in four
    assert "published (the model has no [[published]] values)" in four
    assert "=> NOT CHECKED" in four and "=> PASS" not in four
    assert "1 model(s) NOT CHECKED: four_bar" in r.stdout
    doc = json.loads((tmp_path / "v.json").read_text())
    assert doc["exit_code"] == 3 and not doc["passed"] and doc["totals"]["not_checked"] == 1
    assert [m["status"] for m in doc["models"]] == ["passed", "not checked"]


def test_a_named_route_that_is_not_installed_exits_3(cli, absent_route):
    """--engines names the route: its absence is not a pass, even where other checks passed."""
    r = cli("validate", ICE, "--engines", "reference", absent_route, "--steps", "12", "--no-progress")
    assert r.returncode == EXIT_NOT_CHECKED, r.stderr
    assert "checked by: reference (9 quantities), published (15 values); the lever identity held; not checked by: absent (" in r.stdout
    assert "kinetostat: error: --engines absent: not installed, so nothing was checked by it" in r.stderr


def test_every_model_checked_exits_0_and_names_its_routes(cli):
    r = cli("validate", ICE, "--engines", "none", "--steps", "12", "--no-progress")
    assert r.returncode == EXIT_OK, r.stderr
    assert "checked by: reference (9 quantities), published (15 values)" in r.stdout
    assert "0 model(s) NOT CHECKED" in r.stdout


# ----------------------------------------------------------------------------- the wheel, no extras

def _venv_without_extras(tmp: Path) -> Path:
    """A fresh venv with the wheel built from this checkout installed, no extras; its bin/."""
    dist = tmp / "dist"
    subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "-q", "-w", dist, ROOT],
                   check=True, timeout=600)
    wheel = next(dist.glob("kinetostat-*.whl"))
    env_dir = tmp / "venv"
    venv.create(env_dir, with_pip=True)
    py = env_dir / "bin" / "python"
    subprocess.run([py, "-m", "pip", "install", "-q", wheel], check=True, timeout=900)
    return env_dir / "bin"


@pytest.mark.slow
def test_the_wheel_without_extras_runs_every_command(tmp_path):
    bindir = _venv_without_extras(tmp_path)
    py = bindir / "python"
    missing = subprocess.run([py, "-c", "import importlib.util as u; print([m for m in ('matplotlib', 'tqdm', "
                              "'dask', 'pyarrow', 'pytest', 'pinocchio', 'mujoco', 'pymunk') if u.find_spec(m)])"],
                             capture_output=True, text=True, check=True).stdout.strip()
    assert missing == "[]", f"the venv has extras installed: {missing}"
    work = tmp_path / "work"
    work.mkdir()
    env = {k: v for k, v in os.environ.items() if k not in ("KINETOSTAT_MODELS", "PYTHONPATH")}
    commands = [
        ["analyze", "ice_crank_slider", "--at", "30"],
        ["analyze", "chain_unit_four_bar", "--steps", "36", "--out", "cycle.csv"],
        ["structure", "slotted_link_shaper"],
        ["plans", "ice_crank_slider", "--out", "plans"],
        ["variant", "1", "479", "--out", "key_479"],
        ["sweep", "chain_unit_four_bar", "--param", "r=0.05,0.08", "--steps", "36", "--out", "sweep.csv"],
        ["validate", "--engines", "none", "--steps", "36", "--no-progress"],
    ]
    for args in commands:
        r = subprocess.run([bindir / "kinetostat", *args], capture_output=True, text=True, cwd=work, env=env,
                           timeout=600)
        assert r.returncode == 0, (args, r.stdout[-2000:], r.stderr[-2000:])
        assert "Traceback" not in r.stderr, (args, r.stderr[-2000:])
    for args, phrase in ((["sweep", "chain_unit_four_bar", "--param", "r=0.05", "--out", "s.parquet"],
                          "--out s.parquet: writing .parquet needs pyarrow"),
                         (["sweep", "chain_unit_four_bar", "--param", "r=0.05", "--scheduler", "threads", "--out",
                           "s2.csv"], "--scheduler threads: needs dask"),
                         (["analyze", "ice_crank_slider", "--out", "c.parquet"], "writing .parquet needs pyarrow")):
        r2 = subprocess.run([bindir / "kinetostat", *args], capture_output=True, text=True, cwd=work, env=env,
                            timeout=600)
        assert r2.returncode == 2 and "Traceback" not in r2.stderr, (args, r2.stderr[-2000:])
        assert r2.stderr.count("\n") == 1 and phrase in r2.stderr, r2.stderr
    assert (work / "plans" / "worksheet.html").is_file() and (work / "key_479" / "worksheet.html").is_file()
    assert (work / "key_479" / "cycle.csv").is_file() and (work / "sweep.csv").is_file()
    assert (work / "key_479" / "key.pdf").is_file() and (work / "key_479" / "plans_a3.pdf").is_file()   # fonts in the wheel
    assert "0 model(s) NOT CHECKED" in r.stdout and " 0 FAILED" in r.stdout


# ----------------------------------------------------------------------------- quick fixes a new user meets

def test_an_engine_has_no_balancing_force_and_says_why(ice):
    """ice_crank_slider is an engine: no silent zeros, an AttributeError naming the moment instead."""
    with pytest.raises(AttributeError, match=r"is an engine .*balancing_moment \(N m\)"):
        ice.balancing_force
    assert not hasattr(ice, "balancing_force") and "F_bal" not in ice.to_frame().columns


def test_a_machine_has_its_balancing_force():
    import numpy as np

    import kinetostat
    res = kinetostat.analyze(kinetostat.load("compressor"), phi_deg=[30.0])
    F = res.balancing_force
    gear = res.mech.drive.gear
    r = gear.r_w * np.asarray(gear.centre_direction)
    assert F.shape == (1, 2) and np.hypot(*F[0]) > 0
    assert abs(r[0] * F[0, 1] - r[1] * F[0, 0] - res.balancing_moment[0]) <= 1e-12 * abs(res.balancing_moment[0])


def test_the_api_takes_any_angle_as_the_crank_position_modulo_360():
    """analyze keeps the angles as given (a run over several turns keeps its axis) and computes
    the crank position of each modulo 360."""
    import numpy as np

    import kinetostat
    mech = kinetostat.load("ice_crank_slider")
    res = kinetostat.analyze(mech, phi_deg=[400.0, -720.5, 30.0])
    same = kinetostat.analyze(mech, phi_deg=[40.0, 359.5, 30.0])
    assert res.phi_deg.tolist() == [400.0, -720.5, 30.0]
    peak = np.abs(same.forces.R).max()
    np.testing.assert_allclose(res.forces.R, same.forces.R, rtol=0, atol=1e-12 * peak)


def test_the_cli_tells_the_user_which_angle_it_took(cli, tmp_path):
    r = cli("analyze", "ice_crank_slider", "--at", "400", "30", "-.00000000000000001")
    assert r.returncode == 0 and "phi = 0 .. 40 deg" in r.stdout
    assert r.stderr == ("kinetostat: warning: --at: angles outside [0, 360) deg taken modulo 360 (the same crank "
                        "position): 400 -> 40, -1e-17 -> 0\n")
    r = cli("plans", "ice_crank_slider", "--at", "390", "--only", "positions", "--out", tmp_path)
    assert r.returncode == 0 and "φ = 30°" in r.stdout
    assert "--at: angles outside [0, 360) deg taken modulo 360 (the same crank position): 390 -> 30" in r.stderr


@pytest.mark.slow
def test_the_issues_sweep_keeps_the_failing_design_and_exits_0(cli, tmp_path):
    """The issue's reproducer as written: 2 designs x 25,000 angles run the compiled kernel; r = 0.6 m
    cannot be assembled. Exit 0 (the table is written), one line naming the failure, no traceback."""
    from kinetostat.tables import read_csv
    r = cli("sweep", "chain_unit_four_bar", "--param", "r=0.08,0.6", "--steps", "25000", "--out", tmp_path / "s.csv",
            "--no-progress")
    assert r.returncode == 0 and "Traceback" not in r.stderr + r.stdout
    assert "1 design(s) failed" in r.stdout + r.stderr
    table = read_csv(tmp_path / "s.csv")
    assert table["error"].iloc[0] != table["error"].iloc[0] or table["error"].iloc[0] == ""    # NaN or empty: no error
    assert table["error"].iloc[1].startswith("AssemblyError: group II(2,3) cannot be assembled")
    assert table["peak_R_0_1"].iloc[0] > 0 and table["peak_R_0_1"].isna().iloc[1]
