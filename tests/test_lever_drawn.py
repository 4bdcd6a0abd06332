"""Zhukovsky's lever as seed 002 draws it (fig. 1.12, issue 36 item 7): the velocity plan as it
is, every force turned by 90 deg clockwise at its like point, the arms as dimension lines from the
pole with their values in mm, lettered once where they coincide, and a note saying what is turned.
The arms' moments are recomputed from the drawn arrays, independently of the lever's own sum."""
from __future__ import annotations

import re
from functools import lru_cache

import numpy as np
import pytest

import kinetostat
from kinetostat import variants
from kinetostat.plans.core import Scale
from kinetostat.plans.draw import svg
from kinetostat.plans.forces import arm_name, crank_plan, group_plans
from kinetostat.plans.i18n import text
from kinetostat.plans.kinematic import velocity_plan
from kinetostat.plans.lever import lever_plan
from kinetostat.model.lettering import lettering

from conftest import MODELS, sampled

MU_V = 0.2


def _lever(mech, angles):
    res = kinetostat.analyze(mech, phi_deg=angles)
    return res, lever_plan(mech, res, MU_V)


@lru_cache(maxsize=None)
def _model(path) -> tuple:
    """A bundled model, its analysis at 30, 100 and 250 deg and its lever (shared by the tests)."""
    mech = kinetostat.load(path)
    return (mech, *_lever(mech, [30.0, 100.0, 250.0]))


@pytest.mark.parametrize("path", sampled(MODELS))
def test_drawn_arms_close_on_M_bal(path):
    """sum(F_k h_k) over the lever's forces, each h_k the drawn arm's exact length |foot - p| and
    its sign the sense of the force about p as drawn, x mu_v / omega_1 = M_bal of the force plans
    (to 1e-9 of the largest term), and F'_bal |pa| cancels it: the sum of moments about the pole
    closes with the arms the sheet draws."""
    mech, res, lever = _model(path)
    L = lettering(mech)
    F_bal = lever.segments[-1]
    assert F_bal.name == L.lever(L.F_bal)
    pts = lever.points
    total, largest = np.zeros(lever.n), np.zeros(lever.n)
    arms = {s.name: s for s in lever.segments if s.kind == "arm"}
    for s in lever.segments:
        if s.unit != "N" or s is F_bal or arm_name(s.name) not in arms:
            continue
        arm = arms[arm_name(s.name)]
        foot = pts[arm.end] - pts[arm.start]
        h = np.abs(foot)                                         # the arm as drawn, mm
        u = pts[s.end] - pts[s.start]                            # the force as drawn
        sense = np.sign(foot.real * u.imag - foot.imag * u.real)
        term = np.where(np.isfinite(h), sense * np.abs(s.value) * h, 0.0)
        assert np.allclose(np.nan_to_num(arm.value), np.nan_to_num(h), rtol=1e-12, atol=0)  # its value: the length
        total += term
        largest = np.maximum(largest, np.abs(term))
    omega1 = np.asarray(res.omega(mech.drive.link))
    M = np.asarray(res.balancing_moment)
    largest = np.maximum(largest, np.abs(M * omega1 / MU_V))
    assert np.all(np.abs(total * MU_V / omega1 - M) <= 1e-9 * largest * MU_V / np.abs(omega1)), (total * MU_V / omega1, M)
    pa = pts[F_bal.start] - pts["p"]
    f = pts[F_bal.end] - pts[F_bal.start]
    bal = np.abs(F_bal.value) * np.abs(pa) * np.sign(pa.real * f.imag - pa.imag * f.real)
    assert np.all(np.abs(bal + total) <= 1e-9 * largest)


def test_seed_002_arms_close_to_the_text():
    """The ICE at 30 deg (seed 002): the drawn arms give M'_зр = 102.97 N m (the text's lever) to
    1.5 %, and M_зр of the force plans to 1e-9."""
    mech = kinetostat.load("ice_crank_slider")
    res, lever = _lever(mech, [30.0])
    p = lever.at(0)
    terms = 0.0
    for s in p.segments:
        if s.unit == "N" and s is not p.segments[-1] and arm_name(s.name) in {a.name for a in p.segments}:
            arm = p.segment(arm_name(s.name))
            foot, u = p.points[arm.end], p.points[s.end] - p.points[s.start]
            terms += np.sign(foot.real * u.imag - foot.imag * u.real) * abs(s.value) * abs(foot)
    M = terms * MU_V / float(res.omega(1)[0])
    assert abs(M) == pytest.approx(102.97, rel=0.015)
    assert M == pytest.approx(float(res.balancing_moment[0]), rel=1e-9)


@pytest.mark.parametrize("path", sampled(MODELS))
def test_each_force_on_the_lever_is_turned_90_clockwise(path):
    """Every load on the lever is the same load of the group and crank plans (where the texts
    draw it as it acts) turned by 90 deg clockwise: the angle of the drawn vector less the angle
    of the plan's vector is -90 deg (1e-9 rad), at every angle; the plan is not turned: each image
    p-x is the velocity plan's; F'_bal lies across p-a."""
    mech, res, lever = _model(path)
    acting = {}
    for plan in group_plans(mech, res, 0.001) + [crank_plan(mech, res, 0.001)]:
        for s in plan.segments:
            if s.unit == "N" and s.name in {x.name for x in lever.segments}:
                acting.setdefault(s.name, plan.points[s.end] - plan.points[s.start])
    assert acting, "no load of the lever found on the group plans"
    checked = 0
    for name, v in acting.items():
        s = next(x for x in lever.segments if x.name == name)
        w = lever.points[s.end] - lever.points[s.start]
        ok = (np.abs(v) > 0) & (np.abs(w) > 0) & np.isfinite(v) & np.isfinite(w)
        turn = np.angle(w[ok] / v[ok])
        assert np.allclose(turn, -np.pi / 2, rtol=0, atol=1e-9), (name, np.degrees(turn))
        checked += ok.sum()
    assert checked >= lever.n
    vel = velocity_plan(mech, res, {"mu_v": Scale("mu_v", MU_V, "m/(s mm)")})
    images = [s for s in lever.segments if s.name.startswith("p-") and s.name in {x.name for x in vel.segments}]
    assert images
    for s in images:
        assert np.allclose(lever.points[s.end], vel.points[s.end], rtol=1e-12, atol=1e-12, equal_nan=True), s.name
    L = lettering(mech)
    F_bal = lever.segments[-1]
    pa = lever.points[F_bal.start] - lever.points["p"]
    f = lever.points[F_bal.end] - lever.points[F_bal.start]
    assert np.allclose((pa * f.conjugate()).real, 0.0, atol=1e-9 * np.max(np.abs(pa) * np.abs(f)))
    assert F_bal.name == L.lever(L.F_bal)


def _texts(sheet: str) -> list[str]:
    """Every <text> of a sheet as read (tspans joined)."""
    return [re.sub("<[^>]+>", "", t) for t in re.findall(r"<text[^>]*>(.*?)</text>", sheet, flags=re.S)]


@pytest.mark.parametrize("lang", ["uk", "ru", "en"])
def test_lever_sheet_says_what_is_turned_and_dimensions_its_arms(lang):
    """The ICE's lever sheet at 30 deg: the note that the plan is not turned and the forces are
    turned 90 deg clockwise; each arm a dimension line (an arrowhead at both ends) lettered with
    its value in mm; the three arms at b (F_i3, G3, F_p, all along p-b) lettered once."""
    mech = kinetostat.load("ice_crank_slider")
    _, lever = _lever(mech, [30.0])
    plan = lever.at(0)
    sheet = svg(plan, lang)
    texts = _texts(sheet)
    note = text("lever turned", lang)
    assert any(note[:40] in t for t in texts), note
    assert "90°" in note and ("clockwise" in note or "годинников" in note or "часовой" in note)
    arms = [s for s in plan.segments if s.kind == "arm"]
    assert len(arms) >= 5
    dims = sheet.count('class="arrowhead dimension"')
    assert dims == 2 * len({round(plan.points[s.end].real, 6) + 1j * round(plan.points[s.end].imag, 6) for s in arms})
    drawn = _texts(sheet.split('<g id="plan"', 1)[1].split("</g>", 1)[0])       # the plan's labels, no notes
    lettered = [t for t in drawn if t.startswith("h") and " = " in t]
    at_b = [t for t in lettered if "Fp" in t]
    assert len(at_b) == 1 and "G3" in at_b[0] and "Fi3" in at_b[0], lettered
    dec = "," if lang != "en" else "."
    assert any(t.startswith("hFi2 = 37" + dec) for t in lettered), lettered     # seed 002: h_Fi2 = 37.67 mm


def test_no_arm_where_the_force_line_meets_the_pole():
    """Variant 2/479 at 90 deg (the crank square to the cylinders: teach-09's pile-up at p): the
    weights G2..G5 turned lie on their points' lines through p, so they have no arm and none is
    drawn at p; every arm drawn is longer than rounding, and their moments still close."""
    mech = variants.variant(2, "479").mechanism()
    res, lever = _lever(mech, [90.0])
    plan = lever.at(0)
    arms = {s.name: plan.length_mm(s.name) for s in plan.segments if s.kind == "arm"}
    assert not {f"h_G{k}" for k in range(2, 6)} & set(arms), arms
    assert min(arms.values()) > 1.0 and len(arms) == 10
