"""`kinetostat motion` (issue 38): the table equals the API's arrays, the sheet carries Wittenbauer's
tangents and the intercept ab at the scales it states, the summary its numbers; hostile input is one
line, exit 2, nothing written; `analyze --delta` gives the balancing moment at the true law of motion."""
from __future__ import annotations

import csv
import re
import warnings
import xml.etree.ElementTree as ET

import numpy as np
import pytest

import kinetostat
from kinetostat.cli import main
from kinetostat.cli.motion import COLUMNS
from conftest import ROOT
from kinetostat.plans.i18n import num

MODEL = "scotch_yoke"            # an engine whose law takes ~0.15 s
DELTA = 0.02
SVG = "{http://www.w3.org/2000/svg}"


@pytest.fixture(scope="module")
def motion():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return kinetostat.law_of_motion(kinetostat.load(MODEL), delta=DELTA)


@pytest.fixture(scope="module")
def written(tmp_path_factory):
    """The command's folder (one run, in this process)."""
    out = tmp_path_factory.mktemp("motion")
    assert main(["-q", "motion", MODEL, "--delta", str(DELTA), "--lang", "en", "--out", str(out)]) == 0
    return out


def test_csv_is_the_apis_arrays_with_units(written, motion):
    with open(written / "motion.csv", encoding="utf-8") as f:
        rows = list(csv.reader(f))
    assert rows[0] == ["phi_deg [deg]", "J_red [kg m^2]", "dJ_red [kg m^2/rad]", "M_red [N m]", "M_drive [N m]",
                       "work [J]", "T [J]", "omega [rad/s]", "eps [rad/s^2]"]
    table = np.array(rows[1:], dtype=float)
    assert table.shape == (len(motion.phi_deg), len(COLUMNS))
    for j, key in enumerate(COLUMNS):
        want = np.asarray(getattr(motion, key), dtype=float)
        np.testing.assert_allclose(table[:, j], want, rtol=0, atol=1e-10 * max(np.abs(want).max(), 1e-300), err_msg=key)


def _panel(root, key):
    g = next(e for e in root.iter(f"{SVG}g") if e.get("data-key") == key)
    box = [float(v) for v in g.get("data-box").split()]
    return box, float(g.get("data-mu-x")), float(g.get("data-mu-y")), float(g.get("data-x-from")), float(g.get("data-y-top"))


def _line(root, gid):
    e = next(e for e in root.iter(f"{SVG}line") if e.get("data-gid") == gid)
    return [float(e.get(k)) for k in ("x1", "y1", "x2", "y2")]


def test_sheet_draws_the_tangents_and_ab_at_the_stated_scales(written, motion):
    root = ET.parse(written / "motion.svg").getroot()
    box, mu_x, mu_y, x_from, y_top = _panel(root, "wittenbauer")
    texts = ["".join(t.itertext()) for t in root.iter(f"{SVG}text")]
    stated = f"μJ = {num(mu_x, 'en', 6)} kg·m²/mm, μΔT = {num(mu_y, 'en', 6)} J/mm"
    assert stated in texts                                     # the scales the sheet states are the ones drawn at
    for (k, b), sub in zip(motion.wittenbauer, ("max", "min")):
        x0, y0, x1, y1 = _line(root, f"wittenbauer/tangent_{sub}")
        slope = -(y1 - y0) / (x1 - x0) * mu_y / mu_x           # mm back to J/(kg m^2), y down on the sheet
        assert slope == pytest.approx(k, rel=1e-6)
        assert y_top - (y0 - box[1]) * mu_y - slope * (x_from + (x0 - box[0]) * mu_x) == pytest.approx(b, rel=1e-6)
    a = _line(root, "wittenbauer/ab")
    ab_mm = abs(a[3] - a[1])
    assert ab_mm * mu_y / (motion.omega_mean ** 2 * motion.delta) == pytest.approx(motion.J_flywheel, rel=1e-6)
    assert any(t.startswith(f"ab = {num(ab_mm, 'en', decimals=1)} mm") for t in texts)


def test_summary_states_the_exact_and_approximate_flywheels(written, motion):
    text = (written / "summary.txt").read_text(encoding="utf-8")
    assert f"J_flywheel = {motion.J_flywheel:.6g} kg m^2 (exact; sized for delta = {DELTA:g} (--delta))" in text
    assert f"delta = {motion.delta:.6g}" in text and f"omega_mean = {motion.omega_mean:.6g} rad/s" in text
    for method, value in motion.approximate.items():
        diff = (value - motion.J_flywheel) / motion.J_flywheel * 100
        assert f"{method}: J_flywheel = {value:.6g} kg m^2 ({diff:+.3g} % from the exact)" in text
    assert f"M_drive = {motion.M_drive[0]:.6g} N m (constant)" in text
    assert (written / "motion.pdf").read_bytes().startswith(b"%PDF")


@pytest.mark.parametrize("args, says", [
    (["--delta", "0.02", "--flywheel", "1"], "argument --flywheel: not allowed with argument --delta"),
    (["--delta", "2"], "invalid coefficient of fluctuation '2': expected 0 < D < 2"),
    (["--delta", "nan"], "invalid coefficient of fluctuation 'nan'"),
    (["--flywheel", "-1"], "invalid flywheel '-1': expected a moment of inertia >= 0"),
])
def test_hostile_options_one_line_nothing_written(cli, tmp_path, args, says):
    out = tmp_path / "out"
    r = cli("motion", MODEL, *args, "--out", out)
    assert r.returncode == 2 and r.stdout == ""
    assert r.stderr.count("\n") == 1 and says in r.stderr
    assert not out.exists()


def test_model_without_work_to_balance_runs_free(cli, tmp_path):
    """Gravity only: no work over a cycle, so no drive (M_drive = 0), but the weights still swing the
    speed; the command writes the law with the summary saying so, the same delta as the API's."""
    out = tmp_path / "out"
    r = cli("motion", "chain_unit_four_bar", "--flywheel", "0.01", "--out", out)
    assert r.returncode == 0, r.stderr
    assert re.search(r"the loads' work over a cycle is \S+ J .*no drive to balance: M_drive = 0, the machine runs free",
                     (out / "summary.txt").read_text(encoding="utf-8"))
    m = kinetostat.law_of_motion(kinetostat.load(ROOT / "models" / "chain_unit_four_bar.toml"), flywheel=0.01)
    assert np.max(np.abs(m.M_drive)) < 1e-9 * np.max(np.abs(m.M_red)) and m.delta > 0
    assert f"delta = {m.delta:.6g}" in (out / "summary.txt").read_text(encoding="utf-8")


def test_analyze_delta_gives_the_laws_balancing_moment(cli, tmp_path, motion):
    table = tmp_path / "t.csv"
    r = cli("analyze", MODEL, "--delta", str(DELTA), "--at", "30", "--out", table)
    assert r.returncode == 0, r.stderr
    assert f"at the true law of motion (--delta): omega_mean = {motion.omega_mean:.6g} rad/s" in r.stdout
    with open(table, encoding="utf-8") as f:
        rows = list(csv.DictReader(f))
    M = float(rows[0]["M_bal [N m]"])
    mech = motion.mech
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        true = kinetostat.analyze(mech, phi_deg=[30.0], law=motion).balancing_moment[0]
        constant = kinetostat.analyze(mech, phi_deg=[30.0]).balancing_moment[0]
    assert M == pytest.approx(true, rel=1e-9)
    assert abs(true - constant) > 1e-3 * abs(constant)          # the true motion's M_bal is another number


def _section(name: str, engines: tuple[str, ...] = (), **law) -> str:
    from kinetostat.report.document import Doc
    from kinetostat.report.runs import ModelRun
    from kinetostat.report.writer import _motion_section
    mech = kinetostat.load(name)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        run = ModelRun(mech, kinetostat.analyze(mech, steps=360), engines=engines)
        doc = Doc("t")
        _motion_section(doc, run, **law)
    return doc.markdown()


def test_report_section_law_of_motion(motion):
    from kinetostat.report.document import _fmt
    md = _section(MODEL)
    assert "with the flywheel sized for δ = 0.02 by default (the model has no \\[flywheel\\])" in md
    assert f"| J_flywheel, kg·m² (exact) | {_fmt(motion.J_flywheel)} |" in md
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        true = kinetostat.analyze(motion.mech, phi_deg=[30.0], law=motion).balancing_moment[0]
        constant = kinetostat.analyze(motion.mech, phi_deg=[30.0]).balancing_moment[0]
    assert f"| M_bal, N·m | {_fmt(constant)} | {_fmt(true)} |" in md          # the model's symbol (lettering)
    assert f"flywheel J = 0.5 kg·m² given (--flywheel)" in _section(MODEL, flywheel=0.5)


@pytest.mark.engines
def test_report_section_has_the_engines_forward_dynamics():
    """With the engines among the run's routes the section gives each engine's omega(phi) against the
    law of the frictionless machine: RK4 at 90 steps a revolution, MuJoCo's soft loops to ~1e-6,
    Pinocchio to ~1e-7 (tests/test_motion_engines.py: they converge at the integrators' orders)."""
    pytest.importorskip("mujoco")
    pytest.importorskip("pinocchio")
    md = _section(MODEL, engines=("lever", "pinocchio", "mujoco"))
    rows = dict(re.findall(r"^\| (mujoco|pinocchio) \| (\S+) ", md, flags=re.M))
    assert set(rows) == {"mujoco", "pinocchio"}
    assert float(rows["mujoco"]) < 5e-6 and float(rows["pinocchio"]) < 5e-7
    assert "mujoco" not in _section(MODEL)                      # not among the routes: not run


def test_report_section_skips_a_model_with_no_drive_to_balance():
    md = _section("chain_unit_four_bar")
    assert re.search(r"Skipped: the loads' work over a cycle is \S+ J \(gravity and conservative loads only\): "
                     r"there is no drive to balance\.", md)


def test_plans_delta_draws_the_velocities_at_the_true_omega(cli, tmp_path, motion):
    values = {}
    for name, args in (("const", []), ("true", ["--delta", str(DELTA)])):
        r = cli("plans", MODEL, "--at", "30", "--only", "velocity", "--out", tmp_path / name, *args)
        assert r.returncode == 0, r.stderr
        with open(tmp_path / name / "segments.csv", encoding="utf-8") as f:
            values[name] = next(float(row["value"]) for row in csv.DictReader(f) if row["segment"] == "p-a1")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        omega = abs(kinetostat.analyze(motion.mech, phi_deg=[30.0], law=motion).omega(1)[0])
    assert values["true"] / values["const"] == pytest.approx(omega / motion.mech.drive.omega, rel=1e-9)
    assert abs(omega / motion.mech.drive.omega - 1) > 1e-4                 # the true speed differs at 30 deg
