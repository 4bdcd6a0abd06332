"""The kinematic plans (issue 12): seed 002's measured lengths, every segment against the exact
solution of `analyze`, the dead centre found, the sheets and the command line."""
from __future__ import annotations

import csv
import math
import xml.etree.ElementTree as ET

import numpy as np
import pytest

import kinetostat
import kinetostat.plans as P
from kinetostat.plans.core import SEGMENT_COLUMNS

from conftest import EVERY_GROUP, MODELS, ROOT, sampled

SEED_002_SCALES = {"mu_l": 0.001, "mu_v": 0.2, "mu_a": 100.0, "mu_F": 50.0}


@pytest.fixture(scope="module")
def ice_plans():
    return P.build(kinetostat.load(ROOT / "models" / "ice_crank_slider.toml"), at=30, scales=SEED_002_SCALES)


@pytest.mark.parametrize("plan, segment, text_mm", [
    ("velocity", "p-b", 54.7), ("velocity", "a-b", 74.6), ("velocity", "p-s2", 61.0),
    ("acceleration", "a-n2", 20.23), ("acceleration", "pi-b", 83.11), ("acceleration", "n2-b", 37.16),
    ("acceleration", "pi-s2", 78.75)])
def test_seed_002_lengths(ice_plans, plan, segment, text_mm):
    """Seed 002 sec. 1.2.2 measures these on its plans at mu_v = 0.2, mu_a = 100."""
    assert ice_plans[plan].length_mm(segment) == pytest.approx(text_mm, rel=0.015)


def test_seed_002_scales_chosen_by_the_rule():
    """The texts' rule (pa and pi-a 70-90 mm, round values) lands on seed 002's own mu_v = 0.2,
    mu_a = 100, and OA taken about 30-35 mm its mu_l = 0.001 (OA = 36 mm, as the worked example)."""
    plans = P.build(kinetostat.load(ROOT / "models" / "ice_crank_slider.toml"), at=30)
    assert {k: plans.scales[k].value for k in ("mu_l", "mu_v", "mu_a")} == {"mu_l": 0.001, "mu_v": 0.2, "mu_a": 100.0}
    assert plans["mechanism"].length_mm("OA") == pytest.approx(36.0)


def _exact_values(mech, res, plans):
    """What each vector of the velocity and acceleration plans must measure, from analyze alone."""
    exp = {}
    names = {n: pt._replace(local=complex(np.ravel(pt.local)[0]))       # a guide's point: (N,) local coordinates
             for n, pt in P.kinematic.plan_point_names(mech, res).items()}
    for n, pt in names.items():
        r, v, a = (complex(z[0]) for z in res.kin.point_z(pt.link, (pt.local.real, pt.local.imag)))
        exp[("velocity", f"p-{n}")] = abs(v)
        exp[("acceleration", f"pi-{n}")] = abs(a)
    for g in mech.structure.groups:
        for k, ref, q in P.kinematic._normals(mech, g):
            qn = q if q in names else P.kinematic._name_of(mech, q)
            rq = complex(*res.kin.point(names[qn].link, (names[qn].local.real, names[qn].local.imag))[0][0])
            l = abs(rq - complex(*res.position(ref)[0]))
            w, e = res.omega(k)[0], res.eps(k)[0]
            refn = P.kinematic._name_of(mech, ref) or "pi"
            exp[("acceleration", f"{refn}-n{k}")] = w * w * l
            exp[("acceleration", f"n{k}-{qn}")] = abs(e) * l
    for s, sa in zip(P.kinematic._slidings(mech, "p"), P.kinematic._slidings(mech, "pi")):   # a frame point: the pole
        i, g = s.pair.index, s.pair.links[0]
        exp[("velocity", f"{s.start}-{s.end}")] = abs(res.kin.v_slide[0, i])
        cor = [n for n in plans["acceleration"].segments if n.start == sa.start and n.name.split("-")[1].startswith("k")]
        if cor:
            exp[("acceleration", cor[0].name)] = 2 * abs(res.omega(g)[0] * res.kin.v_slide[0, i])
            exp[("acceleration", f"{cor[0].end}-{sa.end}")] = abs(res.kin.a_slide[0, i])
    return exp


KINEMATIC = ("positions", "velocity", "acceleration")


@pytest.mark.parametrize("path", sampled(MODELS, EVERY_GROUP))
def test_every_segment_is_the_exact_value(path):
    """At the design position and three other angles: drawn length x scale = |value| (1e-9),
    value = the quantity from analyze (v, a, omega^2 l, |eps| l, 2|omega v_rel|, a_rel) to 1e-9,
    and the velocity polygons p-a + a-b = p-b close to 1e-9 of the largest side."""
    mech = kinetostat.load(path)
    for at in (mech.drive.design_deg, 75.0, 160.0, 290.0):
        plans = P.build(mech, at=at, only=KINEMATIC)      # the force plans: tests/test_plans_forces.py
        res = kinetostat.analyze(mech, phi_deg=[at])
        for plan in plans.values():
            big = max(abs(z) for z in plan.points.values()) * plan.scale.value
            for s in plan.segments:
                if math.isnan(s.value):
                    assert s.kind in ("line", "construction", "intersection")
                    continue
                assert plan.length_mm(s.name) * plan.scale.value == pytest.approx(abs(s.value), rel=1e-9,
                                                                                   abs=1e-12 * big), (at, s.name)
        exp = _exact_values(mech, res, plans)
        checked = 0
        for (kind, name), value in exp.items():
            seg = plans[kind].segment(name)
            scale = plans[kind].scale.value
            big = max(abs(z) for z in plans[kind].points.values()) * scale
            assert seg.value == pytest.approx(value, rel=1e-9, abs=1e-9 * big), (at, kind, name)
            assert plans[kind].length_mm(name) * scale == pytest.approx(value, rel=1e-9, abs=1e-9 * big), (at, kind, name)
            checked += 1
        assert checked >= 4
        vel = plans["velocity"]
        for s in vel.segments:
            if s.start != "p" and s.unit:   # a relative vector closes the triangle p-x, x-y, p-y
                pa, pb = vel.points[s.start], vel.points[s.end]
                largest = max(abs(pa), abs(pb), abs(pb - pa))
                rel = (s.value / vel.scale.value) * (pb - pa) / abs(pb - pa) if abs(pb - pa) else 0
                assert abs(pa + rel - pb) <= 1e-9 * largest, (at, s.name)


def test_relative_velocities_are_omega_times_length():
    """a-b of the rod = |omega_2| l_AB (an independent route to the same length)."""
    mech = kinetostat.load(ROOT / "models" / "ice_crank_slider.toml")
    res = kinetostat.analyze(mech, phi_deg=[30.0])
    plans = P.build(mech, at=30, scales=SEED_002_SCALES)
    assert plans["velocity"].length_mm("a-b") * 0.2 == pytest.approx(abs(res.omega(2)[0]) * 0.11, rel=1e-12)
    assert plans["acceleration"].length_mm("n2-b") * 100 == pytest.approx(abs(res.eps(2)[0]) * 0.11, rel=1e-12)


@pytest.mark.parametrize("name, crank_pin, rod_end", [("ice_crank_slider", "A", "B"), ("chain_unit_four_bar", "A", "B")])
def test_starting_position_is_the_outer_dead_centre(name, crank_pin, rod_end):
    mech = kinetostat.load(name)
    start = P.starting_position(mech)
    res = kinetostat.analyze(mech, phi_deg=[start])
    O = complex(*res.position(mech.drive.pivot)[0])
    A, B = complex(*res.position(crank_pin)[0]), complex(*res.position(rod_end)[0])
    angle = abs(np.angle((B - A) / (A - O)))          # 0: in one line, stretched
    assert angle < 1e-9
    plans = P.build(mech, only=["positions"])
    pos = plans["positions"]
    assert abs(pos.points[f"{crank_pin}0"] * pos.scale.value - A) < 1e-12


def test_positions_plan_has_twelve_positions_design_and_paths(ice_plans):
    pos = ice_plans["positions"]
    assert all(f"A{i}" in pos.points and f"B{i}" in pos.points for i in range(12))
    assert "A" in pos.points and "S2" in pos.points and "S2_3" in pos.points
    assert set(pos.paths) == {"S2", "B"}
    assert "B'" in pos.points and any("branch +1" in n for n in pos.notes)
    # the design position at 30 deg is position 1 (positions from TDC every 30 deg)
    assert pos.points["A"] == pytest.approx(pos.points["A1"], abs=1e-12)


def test_positions_made_once_draw_the_same_plan_and_only_for_their_mechanism_and_scale(ice_plans):
    """The 12 positions and paths made once for many angles (`fixed_positions`, as the page uses
    them) draw the plan of positions `build` draws without them; another mechanism's or another
    scale's, or those from another starting position, are refused, naming `fixed`."""
    mech = ice_plans.mech
    fixed = P.fixed_positions(mech, ice_plans.scales["mu_l"])
    for at in (30.0, 200.0):
        alone = P.build(mech, at=at, scales=SEED_002_SCALES, only=["positions"])["positions"]
        made = P.build(mech, at=at, scales=SEED_002_SCALES, only=["positions"], positions=fixed)["positions"]
        assert (made.points, made.paths, made.notes) == (alone.points, alone.paths, alone.notes)
        assert P.svg(made) == P.svg(alone)                 # its segments (a branch mark's value is NaN)
    other = kinetostat.load(ROOT / "models" / "ice_crank_slider.toml")         # equal, but another object
    with pytest.raises(ValueError, match="fixed"):
        P.build(other, at=30, scales=SEED_002_SCALES, only=["positions"], positions=fixed)
    with pytest.raises(ValueError, match="fixed"):
        P.build(mech, at=30, scales={**SEED_002_SCALES, "mu_l": 0.002}, only=["positions"], positions=fixed)
    with pytest.raises(ValueError, match="starting_deg = 45"):           # made from the dead centre, not 45 deg
        P.build(mech, at=30, scales=SEED_002_SCALES, only=["positions"], positions=fixed, starting_deg=45)


def test_svg_sheet(ice_plans, tmp_path):
    written = ice_plans.write(tmp_path, lang="uk")
    assert {p.name for p in written} == {"mechanism.svg", "positions.svg", "velocity.svg", "acceleration.svg", "group_2-3.svg",
                                         "forces_2-3.svg", "crank.svg", "lever.svg", "segments.csv"}
    for p in written[:-1]:
        root = ET.parse(p).getroot()
        assert root.get("width") == "420mm" and root.get("height") == "297mm" and root.get("viewBox") == "0 0 420 297"
        scale = root.find(".//{http://www.w3.org/2000/svg}text[@id='scale']")
        assert scale is not None and "масштаб" in "".join(scale.itertext())
    text = (tmp_path / "velocity.svg").read_text(encoding="utf-8")
    assert "μ_v = 0,2 м/(с·мм)" in text
    with open(tmp_path / "segments.csv", newline="", encoding="utf-8") as f:
        rows = list(csv.DictReader(f))
    assert tuple(rows[0]) == SEGMENT_COLUMNS
    pb = next(r for r in rows if r["plan"] == "velocity" and r["segment"] == "p-b")
    # the file holds 12 significant digits of each column's largest value (kinetostat.tables)
    assert float(pb["length_mm"]) * 0.2 == pytest.approx(float(pb["value"]), rel=1e-10)


def test_svg_escapes_model_text():
    plan = P.Plan("velocity", "t", P.Scale("mu_v", 1.0, "m/(s mm)"), 0.0, {"p": 0j, "a<&>": 1 + 1j},
                  (P.Segment("p-a", "p", "a<&>", 1.0, "m/s"),), notes=("<script>",))
    root = ET.fromstring(P.draw.svg(plan, mechanism="<b>&"))
    assert "<b>&" in "".join(root.itertext()) and "<script>" in "".join(root.itertext())


@pytest.mark.parametrize("path", sampled(MODELS, keep=("slotted_link_shaper",)))
def test_figures_render(path, tmp_path):
    """Every plan of every bundled model, force plans and lever included, as a Figure (PNG) and as
    an SVG sheet. (By default the shaper, its sliders, slots and Coriolis terms: a PNG takes 0.4 s,
    matplotlib's mathtext; the others with -m slow.)"""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    mech = kinetostat.load(path)
    plans = P.build(mech)
    assert {"positions", "velocity", "acceleration", "crank", "lever"} <= set(plans)
    assert any(k.startswith("forces:") for k in plans) and any(k.startswith("group:") for k in plans)
    for plan in plans.values():
        fig = P.figure(plan, lang="uk")
        FigureCanvasAgg(fig).print_png(tmp_path / "plan.png")
        assert (tmp_path / "plan.png").stat().st_size > 5000
        ET.fromstring(P.draw.svg(plan, lang="en", mechanism=mech.name))


def test_cli_plans(cli, tmp_path):
    r = cli("plans", "models/ice_crank_slider.toml", "--at", "30", "--scale", "mu_l=0.001", "mu_v=0.2", "mu_a=100",
            "mu_F=50", "--lang", "uk", "--out", tmp_path / "all")
    assert r.returncode == 0, r.stderr
    assert {p.name for p in (tmp_path / "all").iterdir()} == {
        "mechanism.svg", "positions.svg", "velocity.svg", "acceleration.svg", "group_2-3.svg", "forces_2-3.svg",
        "crank.svg", "lever.svg", "segments.csv", "worksheet.md", "worksheet.html", "worksheet.csv", "worksheet.json"}
    with open(tmp_path / "all" / "segments.csv", newline="", encoding="utf-8") as f:
        rows = {(row["plan"], row["segment"]): row for row in csv.DictReader(f)}
    assert float(rows[("velocity", "p-b")]["length_mm"]) == pytest.approx(54.7, rel=0.015)
    assert float(rows[("forces:2,3", "R32")]["length_mm"]) == pytest.approx(129.62, rel=0.015)    # seed 002
    r = cli("plans", "models/slotted_link_shaper.toml", "--only", "positions", "--out", tmp_path / "pos")
    assert r.returncode == 0, r.stderr
    assert {p.name for p in (tmp_path / "pos").iterdir()} == {"positions.svg", "segments.csv"}


@pytest.mark.parametrize("args, names", [
    (["--scale", "mu_x=1"], "--scale"), (["--scale", "mu_v=-0.2"], "--scale"), (["--scale", "mu_v"], "--scale"),
    (["--only", "nonsense"], "--only"), (["--at", "abc"], "--at")])
def test_cli_plans_bad_options(cli, tmp_path, args, names):
    r = cli("plans", "models/ice_crank_slider.toml", *args, "--out", tmp_path)
    assert r.returncode == 2 and names in r.stderr and "Traceback" not in r.stderr


def test_cli_plans_unwritable_out(cli, tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("x")
    r = cli("plans", "models/ice_crank_slider.toml", "--only", "positions", "--out", blocker / "sub")
    assert r.returncode == 2 and "--out" in r.stderr


def test_given_scales_are_checked():
    mech = kinetostat.load("ice_crank_slider")
    with pytest.raises(ValueError, match="mu_q"):
        P.build(mech, scales={"mu_q": 1.0})
    with pytest.raises(ValueError, match="mu_l"):
        P.build(mech, scales={"mu_l": 0.0})
    with pytest.raises(ValueError, match="at"):
        P.build(mech, at=float("nan"))


def test_the_sheets_do_not_depend_on_the_hash_seed(tmp_path):
    """The furnace loader's S3 lies midway between B and O2 (a tie of the mechanism sheet's
    nearest drawn point): two processes with other string hash seeds write the same files."""
    import os
    import subprocess
    import sys
    outs = []
    for seed in ("1", "3"):          # on the old code these two drew S3 from O2 and from B
        out = tmp_path / seed
        subprocess.run([sys.executable, "-m", "kinetostat", "plans", str(ROOT / "models" / "furnace_loader_six_bar.toml"),
                        "--only", "mechanism", "--lang", "en", "--out", str(out)], check=True, capture_output=True,
                       env=dict(os.environ, PYTHONHASHSEED=seed), cwd=ROOT)
        outs.append({p.name: p.read_bytes() for p in sorted(out.iterdir())})
    assert outs[0] == outs[1] and "mechanism.svg" in outs[0]
