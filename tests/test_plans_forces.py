"""Group plans, force plans, the crank plan and Zhukovsky's lever (issue 12): seed 002's measured
lengths at its scales, and on every bundled model the closure of each polygon, the values against
`analyze`, and the lever's moment against M_bal."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import kinetostat
from kinetostat.plans.core import Scale
from kinetostat.plans.forces import arm_name, crank_plan, default_mu_F, force_plans, group_plans, link_loads, reaction_name
from kinetostat.model.lettering import lettering
from kinetostat.plans.lever import lever_check, lever_plan, pole_moment

MODELS = sorted((Path(__file__).parent.parent / "models").glob("*.toml"))
MU_L, MU_V, MU_F = Scale("mu_l", 0.001, "m/mm"), Scale("mu_v", 0.2, "m/(s mm)"), Scale("mu_F", 50.0, "N/mm")


@pytest.fixture(scope="module")
def ice():
    mech = kinetostat.load(Path(__file__).parent.parent / "models" / "ice_crank_slider.toml")
    return mech, kinetostat.analyze(mech, phi_deg=[30.0])


# seed 002 sec. 1.2.3: (plan, segment, the text's length in mm)
SEED_002 = [
    ("forces:2,3", "R12", 63.44), ("forces:2,3", "R43", 15.61), ("forces:2,3", "R32", 129.62),
    ("group:2,3", "h_Fi2", 22.48), ("group:2,3", "h_G2", 9.0), ("crank", "h_R21", 32.39),
    ("lever", "a-b", 74.62), ("lever", "h_Fi2", 37.67), ("lever", "h_G2", 48.61), ("lever", "p-b", 54.71),
]


def _plans(mech, res, mu_F=MU_F):
    plans = group_plans(mech, res, MU_L) + force_plans(mech, res, mu_F) + [crank_plan(mech, res, MU_L, mu_F),
                                                                             lever_plan(mech, res, MU_V)]
    return {p.kind: p.at(0) for p in plans}           # one angle: the cycle's N = 1 plans


@pytest.mark.parametrize("kind, name, text_mm", SEED_002)
def test_seed_002_lengths(ice, kind, name, text_mm):
    plan = _plans(*ice)[kind]
    assert plan.length_mm(name) == pytest.approx(text_mm, rel=0.015)


def test_seed_002_lever_force_and_moments(ice):
    mech, res = ice
    chk = lever_check(mech, res, MU_V)
    assert chk["F_bal_lever"] == pytest.approx(2860.18, rel=0.015)            # the text's F_zp
    assert chk["M_bal_lever"] == pytest.approx(102.97, rel=0.015)
    assert chk["M_bal_forces"] == pytest.approx(102.74, rel=0.015)
    assert abs(chk["M_bal_lever"]) == pytest.approx(chk["F_bal_lever"] * chk["l_OA"], rel=1e-12)
    assert abs(chk["difference_pct"]) < 1e-9                                  # exact: rounding only
    # the text's lettering: the cylinder is link 4 (R43, R41 at O)
    assert reaction_name(mech, 0, 3) == "R43" and _plans(*ice)["crank"].segment("R41").value > 0


def test_seed_002_polygon_order(ice):
    """R12t + G2 + F_i2 + G3 + F_i3 + F_p + R43 + R12n = 0, from the known R12t (seed 002)."""
    plan = _plans(*ice)["forces:2,3"]
    order = [s.name for s in plan.segments][:8]
    assert order == ["R12t", "G2", "F_i2", "G3", "F_i3", "F_p", "R43", "R12n"]    # the text's lettering
    assert plan.equation == tuple(order)


def _angles(mech):
    design = getattr(mech.drive, "design_deg", 30.0)
    return [design, design + 75.0, design + 160.0, design + 250.0]


CASES = [(path, n) for path in MODELS for n in range(4)]


@pytest.fixture(scope="module")
def analysed():
    out = {}
    for path in MODELS:
        mech = kinetostat.load(path)
        for n, at in enumerate(_angles(mech)):
            out[path, n] = (mech, kinetostat.analyze(mech, phi_deg=[at]))
    return out


def test_every_group_kind_is_bundled():
    kinds = {g.kind for path in MODELS for g in kinetostat.load(path).structure.groups}
    assert kinds == {"RRR", "RRP", "RPR", "PRP", "RPP"}


@pytest.mark.parametrize("path, n", CASES, ids=[f"{p.stem}-{n}" for p, n in CASES])
def test_every_model(analysed, path, n):
    mech, res = analysed[path, n]
    if res.singular[0]:
        pytest.skip("singular position")
    mu_F = default_mu_F(mech, res)
    plans = _plans(mech, res, mu_F)
    for plan in plans.values():
        for s in plan.segments:              # drawn length x its scale = |value|
            if np.isfinite(s.value) and s.unit:
                scale = (s.scale or plan.scale).value
                assert plan.length_mm(s.name) * scale == pytest.approx(abs(s.value), rel=1e-9, abs=1e-12 * scale), \
                    (plan.kind, s.name)
    for g in mech.structure.groups:
        if g.klass == 3:               # a triad's plans: tests/test_triad.py
            continue
        j, k = g.links
        label = f"{min(j, k)},{max(j, k)}"
        plan = plans[f"forces:{label}"]
        pts = plan.points
        # the polygon (the segments before the chords) closes, in its own coordinates
        drawn_to_scale = [s for s in plan.segments if s.kind not in ("construction", "intersection")]
        n_sides = len(drawn_to_scale) - (2 if g.kind in ("RRR", "RRP") else 1) - (g.kind == "RRR")
        sides = [pts[s.end] - pts[s.start] for s in drawn_to_scale[:n_sides]]
        assert drawn_to_scale[n_sides - 1].end == drawn_to_scale[0].start
        largest = max(abs(v) for v in sides)
        assert abs(sum(sides)) <= 1e-9 * largest
        # every reaction on the plan is the one of `analyze`, as a vector
        for i_, j_ in [(g.known[0], j), (g.known[1], k), (k, j)]:
            R = complex(*res.reaction(i_, j_)[0])
            s = plan.segment(reaction_name(mech, i_, j_))
            assert s.value == pytest.approx(abs(R), rel=1e-9)
            drawn = (pts[s.end] - pts[s.start]) * mu_F.value
            assert abs(drawn - R) <= 1e-9 * max(abs(R), largest * mu_F.value)
        # the loads: weights m g, inertia from analyze, and all loads of a link = analyze's
        for x in (j, k):
            total = 0j
            for ld in link_loads(mech, res, x):
                s = plan.segment(ld.name)
                drawn = (pts[s.end] - pts[s.start]) * mu_F.value
                total += drawn
                if ld.name.startswith("F_i"):
                    assert abs(drawn - complex(*res.inertia(x).force[0])) <= 1e-9 * abs(drawn)
                if ld.name.startswith("G"):
                    assert drawn == pytest.approx(-1j * mech.g * mech.links[x].mass, rel=1e-9)
            expected = complex(*res.F_applied[0, x]) + complex(*res.F_i[0, x])
            assert abs(total - expected) <= 1e-9 * max(abs(expected), largest * mu_F.value)
    # the lever: the loads' moment about the pole x mu_v / omega_1 = M_bal, and F'_bal cancels it
    lever = plans["lever"]
    F_bal = lettering(mech).lever(lettering(mech).F_bal)       # F'_bal, or the text's F'_зр
    assert lever.segments[-1].name == F_bal
    omega1 = res.omega(1)[0]
    arms = {s.name for s in lever.segments if s.kind == "arm"}          # none where the line meets the pole
    terms = [abs(s.value) * lever.length_mm(arm_name(s.name)) for s in lever.segments
             if s.unit == "N" and arm_name(s.name) in arms]
    largest = max(terms + [abs(res.balancing_moment[0]) * abs(omega1) / MU_V.value])
    M = res.balancing_moment[0]
    assert abs(pole_moment(lever) - M * omega1 / MU_V.value) <= 1e-9 * largest
    assert abs(pole_moment(lever, without=())) <= 1e-9 * largest
    # the crank: its loads' moments about the pivot balance M_bal (engine) or F_bal r_b (machine)
    crank = plans["crank"]
    if mech.drive.kind == "machine":
        F_bal = np.hypot(*res.balancing_force[0])
        assert crank.segment(lettering(mech).F_bal).value == pytest.approx(F_bal, rel=1e-9)
        assert crank.segment("r_b").value == pytest.approx(mech.drive.gear.r_b, rel=1e-9)
        assert F_bal * mech.drive.gear.r_b == pytest.approx(abs(M), rel=1e-9)
    else:
        if not mech.links[1].mass and sum(1 for p in mech.pairs if 1 in p.links) == 2:   # seed 002's crank
            R21 = crank.segment(reaction_name(mech, 2, 1))
            assert R21.value * crank.segment(f"h_{R21.name}").value == pytest.approx(abs(M), rel=1e-9)


def test_bad_input(ice):
    mech, res = ice
    with pytest.raises(ValueError, match="one crank angle"):
        lever_check(mech, kinetostat.analyze(mech, phi_deg=[10.0, 20.0]), MU_V)
    with pytest.raises(ValueError, match="mu_F"):
        force_plans(mech, res, -1.0)
