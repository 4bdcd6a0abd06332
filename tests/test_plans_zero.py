"""Only what acts is drawn (issue 36 item 5): a zero ω, ε, inertia force or couple is not drawn and
a note says so; a plan that collapses names its special position; F_i(h) is drawn as the
alternative of F_i and M_i; a guide's normal force off its slider link is drawn there and warned
about. Checked on the sheets' data (`PlanCycle`) and the SVG they write."""
from __future__ import annotations

import math
import re
import warnings
from pathlib import Path

import numpy as np
import pytest

import kinetostat
from kinetostat import variants
from kinetostat.errors import ModelWarning
from kinetostat.plans.arcs import GRID_MM
from kinetostat.plans.core import Scale
from kinetostat.plans.draw import svg
from kinetostat.plans.forces import crank_plan, group_plans
from kinetostat.plans.kinematic import acceleration_plan, velocity_plan
from kinetostat.plans.mechanism import mechanism_plan
from kinetostat.plans.zero import ZERO_REL, translates

MODELS = Path(__file__).parent.parent / "models"
MU_L, MU_V, MU_A = Scale("mu_l", 0.002, "m/mm"), Scale("mu_v", 0.5, "m/(s mm)"), Scale("mu_a", 200.0, "m/(s^2 mm)")


def _notes(sheet: str) -> str:
    """The words of a sheet's notes as read (sub- and superscripts' markup left out)."""
    return re.sub(r"<[^>]+>", "", sheet.split('<g id="notes">')[1])


def _model(name: str):
    return kinetostat.load(MODELS / f"{name}.toml")


@pytest.fixture(scope="module")
def v2():
    """Variant 2/479 at 90 deg (rods' ω2 = ω4 = 0 there, ε2, ε4 not) and at 30 deg."""
    mech = kinetostat.from_dict(variants.variant(2, "479").model)
    return mech, kinetostat.analyze(mech, phi_deg=[90.0, 30.0])


def test_v2_479_at_90_draws_no_omega2_and_eps2_about_its_rod(v2):
    mech, res = v2
    assert abs(res.kin.omega[0, 2]) < 1e-12 * abs(res.kin.omega[0, 1]) and res.kin.omega[0, 2] != 0.0   # noise, not 0.0
    cyc = mechanism_plan(mech, res, {"mu_l": MU_L})
    at90, at30 = cyc.at(0), cyc.at(1)
    assert not np.isfinite(np.asarray(at90.paths["ω2"])).any() and not np.isfinite(np.asarray(at90.paths["ω4"])).any()
    assert np.isfinite(np.asarray(at30.paths["ω2"])).all()                               # drawn where the rod turns
    assert "ω2 = 0" in " ".join(at90.notes) and "ω2" not in " ".join(at30.notes)
    # ε2's arc is about the rod's midpoint (A + B)/2 at its radius (its points on the page's 0.1 mm
    # grid about it: arcs.GRID_MM), not about the crank's pivot O
    mid = (at90.points["A"] + at90.points["B"]) / 2
    arc = np.asarray(at90.paths["ε2"])
    assert np.allclose(np.abs(arc - mid), 10.0, atol=GRID_MM / math.sqrt(2)) and np.abs(arc - at90.points["O"]).min() > 20.0
    page = svg(at90, lang="uk")
    assert "ω2 = 0, ω4 = 0 (у цьому положенні): не показано" in _notes(page) and "<title>ω2</title>" not in page
    assert "<title>ε2</title>" in page


def test_a_link_that_translates_has_no_M_i_and_the_sheet_says_so():
    for name, link in (("furnace_loader_six_bar", 5), ("slotted_link_shaper", 5)):
        mech = _model(name)
        res = kinetostat.analyze(mech, phi_deg=[30.0])
        assert translates(mech, link) and mech.links[link].I_S > 0                 # the model gives it an I_S
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", ModelWarning)
            plan = next(p for p in group_plans(mech, res, MU_L) if link in map(int, p.kind[6:].split(","))).at(0)
        assert f"M_i{link}" not in plan.paths
        assert f"M_i{link} = 0 (link {link} translates): not drawn" in plan.notes
        assert np.isfinite(plan.paths[f"M_i{link - 1}"]).all()                     # link 4 turns: its M_i4 drawn


def test_translates_by_its_pairs():
    ice, shaper = _model("ice_crank_slider"), _model("slotted_link_shaper")
    assert [translates(ice, k) for k in range(4)] == [False, False, False, True]
    assert [translates(shaper, k) for k in range(6)] == [False, False, False, False, False, True]   # 4 slides on 3


def test_ice_at_dead_centre_eps2_noise_is_zero_no_M_i2_and_no_F_i2h():
    """At 0 deg the ICE's ε2 is rounding noise (-4e-12 rad/s² against ω1² = 2.2e5): M_i2 and
    F_i2(h) are not drawn, and the velocity plan names the special position p-b = 0."""
    mech = _model("ice_crank_slider")
    res = kinetostat.analyze(mech, phi_deg=[0.0, 30.0])
    eps2, w1 = res.kin.eps[0, 2], res.kin.omega[0, 1]
    assert eps2 != 0.0 and abs(eps2) <= ZERO_REL * w1 ** 2
    grp = group_plans(mech, res, MU_L)[0]
    at0, at30 = grp.at(0), grp.at(1)
    assert not np.isfinite(at0.paths["M_i2"]).any() and np.isfinite(at30.paths["M_i2"]).all()
    assert "F_i2(h)" not in {s.name for s in at0.segments if np.isfinite(s.value)}
    assert "M_i2 = 0 (at this angle): not drawn" in at0.notes
    vel = velocity_plan(mech, res, {"mu_v": MU_V}).at(0)
    assert "special position: p-b = 0, the plan collapses there" in vel.notes
    assert abs(vel.points["b"]) < 1e-9                                         # b really at the pole
    acc = acceleration_plan(mech, res, {"mu_a": MU_A})
    assert any(n.startswith("special position: n2-b = 0") for n in acc.at(0).notes)
    assert not any("special position" in n for n in acc.at(1).notes + velocity_plan(mech, res, {"mu_v": MU_V}).at(1).notes)


def test_F_i2h_is_drawn_as_the_alternative_with_a_note():
    mech = _model("ice_crank_slider")
    res = kinetostat.analyze(mech, phi_deg=[30.0])
    plan = group_plans(mech, res, MU_L)[0].at(0)
    seg = plan.segment("F_i2(h)")
    assert seg.kind == "alternative" and plan.segment("F_i2").kind == "vector"
    il = res.inertia(2)                                      # exact: F at K, |S K| = |M_i| / |F_i|
    assert seg.value == pytest.approx(math.hypot(*il.force[0]), rel=1e-12)
    assert plan.length_mm("z_2") * MU_L.value == pytest.approx(abs(il.moment[0]) / math.hypot(*il.force[0]), rel=1e-9)
    assert "F_i2(h) (dashed) replaces F_i2 and M_i2: one or the other acts, not both" in plan.notes
    page = svg(plan, lang="uk")
    assert re.search(r'<line [^>]*stroke-width="0.5" stroke-dasharray="3,1.5"><title>F_i2\(h\)</title>', page)
    assert "Fi2(h) (штрихова) замінює Fi2 і Mi2" in _notes(page)


def test_shaper_R05_off_the_ram_warns_at_those_angles_and_is_drawn_where_it_acts():
    mech = _model("slotted_link_shaper")
    phi = np.arange(0.0, 360.0, 30.0)
    res = kinetostat.analyze(mech, phi_deg=phi)
    x = res.reaction_offset(0, 5)
    # x re-computed from R05 and the moments about B (the ram's origin; R45 passes through B): the
    # normal force at B + x d (d = +x) has the moment x R05_y; it balances the applied loads' and
    # the inertia's (F_i5 at S5, M_i5 = 0)
    R, ram = res.reaction(0, 5), mech.links[5].points
    B, S = (res.kin.position_z(5, ram[n]) for n in ("B", "S5"))
    F = res.F_i[:, 5]
    M_B = res.M_applied[:, 5] + (S - B).real * F[:, 1] - (S - B).imag * F[:, 0] + res.M_i[:, 5]
    assert np.allclose(x, -M_B / R[:, 1], rtol=1e-9, atol=0)
    assert x[1] == pytest.approx(-1.475, abs=5e-4)                          # the crop's 1.475 m at 30 deg
    along = np.array([ram[n][0] for n in ram])                              # 0 .. 0.35 m along +x
    off = (x < along.min()) | (x > along.max())
    assert off[1] and not off.all()
    with pytest.warns(ModelWarning, match=r"pair P\(0,5\): the normal force R05 acts .* outside link 5 .* at phi = \[") as w:
        plan = group_plans(mech, res, MU_L)[1]
    msg = next(str(m.message) for m in w if "P(0,5)" in str(m.message))
    listed = [float(a) for a in msg.split("at phi = [")[1].split("]")[0].split(", ")]
    assert listed == phi[off].tolist()
    at30 = plan.at(1)
    ext = at30.segment("link 5 extended to R05")
    assert ext.kind == "extension"
    assert at30.points[ext.end] == pytest.approx(at30.points["R05:from"], abs=1e-9)     # on to where R05 acts
    assert at30.points[ext.start] == pytest.approx(at30.points["B"], abs=1e-9)          # from the ram's end
    assert abs(at30.points[ext.end] - at30.points["B"]) * MU_L.value == pytest.approx(abs(x[1]), rel=1e-9)
    assert any(n.startswith("R05 acts 1.475 m from B, outside link 5") for n in at30.notes)
    on = next(i for i in range(len(phi)) if not off[i] and np.isfinite(x[i]))
    assert not any("outside link" in n for n in plan.at(on).notes)


def test_crank_plan_leaves_out_the_evenly_turning_cranks_zero_F_i1_and_M_i1():
    """The furnace loader's crank turns at constant ω1 (ε1 = 0) about its centre of mass O1: its
    F_i1 = -m a_O1 and M_i1 = -I_S ε1 are zero, not drawn, and named in a note."""
    mech = _model("furnace_loader_six_bar")
    res = kinetostat.analyze(mech, phi_deg=[30.0])
    assert mech.links[1].com == mech.drive.pivot and mech.links[1].I_S > 0 and res.kin.eps[0, 1] == 0.0
    plan = crank_plan(mech, res, MU_L).at(0)
    assert "M_i1" not in plan.paths
    assert "F_i1" not in {s.name for s in plan.segments} and plan.segment("G1").value > 0
    assert "F_i1 = 0, M_i1 = 0 (at this angle): not drawn" in plan.notes


def test_a_side_within_a_translating_link_is_no_special_position():
    """The scotch yoke's a3-y joins two points of the yoke, which translates: zero at every angle,
    not a special position; at 90 deg its a1-a3 (the block's sliding) is, the crank pin at the
    top of its stroke."""
    mech = _model("scotch_yoke")
    res = kinetostat.analyze(mech, phi_deg=[30.0, 90.0])
    vel = velocity_plan(mech, res, {"mu_v": MU_V})
    assert vel.at(0).segment("a3-y").value == 0.0 and vel.at(0).notes == ()
    assert vel.at(1).notes == ("special position: a1-a3 = 0, the plan collapses there",)
