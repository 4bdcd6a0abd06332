"""The force plans and the lever vectorised over the angles (issue 34 item 2): for every bundled
model (and both friction modes of a model with friction) the cycle built from one analysis at 24
angles gives, angle by angle, the plan an analysis at that one angle gives (`PlanCycle.at`)."""
from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

import kinetostat
from kinetostat import examples
from kinetostat.plans.core import Plan, Scale
from kinetostat.plans.forces import crank_plan, default_mu_F, force_plans, group_plans, link_loads
from kinetostat.plans.lever import pole_moment, lever_plan

ANGLES = np.arange(0.0, 360.0, 15.0)
MU_L, MU_V = Scale("mu_l", 0.002, "m/mm"), Scale("mu_v", 0.05, "m/(s mm)")
CASES = [(name, fr) for name in examples.names()
         for fr in (("first", "reactions") if kinetostat.load(name).friction is not None else ("first",))]


def _build(mech, res, mu_F):
    """Every force plan and the lever at the fixed scales: group scales and lever force scale
    those of the first angle's build, so the cycle and the one-angle builds draw alike."""
    return (group_plans(mech, res, MU_L, mu_F["group"]) + force_plans(mech, res, mu_F["forces"])
            + [crank_plan(mech, res, MU_L, mu_F["crank"]), lever_plan(mech, res, MU_V, mu_F["lever"])])


def _same(a: Plan, b: Plan) -> None:
    """Plan a (of the cycle) equals b (of one angle): points, segments, paths, texts to 1e-9."""
    where = f"{b.kind} at {b.phi_deg:g} deg"
    assert (a.kind, a.title, a.scale, a.notes, a.equation) == (b.kind, b.title, b.scale, b.notes, b.equation), where
    drawn = {n: z for n, z in a.points.items() if math.isfinite(z.real) and math.isfinite(z.imag)}
    assert drawn.keys() == {n for n, z in b.points.items() if math.isfinite(z.real) and math.isfinite(z.imag)}, where
    for n, z in drawn.items():
        assert abs(z - b.points[n]) <= 1e-9 * max(1.0, abs(z)), (where, n)
    sa = [s for s in a.segments if math.isfinite(abs(a.points[s.start])) and math.isfinite(abs(a.points[s.end]))]
    sb = [s for s in b.segments if math.isfinite(abs(b.points[s.start])) and math.isfinite(abs(b.points[s.end]))]
    assert [(s.name, s.start, s.end, s.unit, s.kind, s.scale) for s in sa] == \
           [(s.name, s.start, s.end, s.unit, s.kind, s.scale) for s in sb], where
    for s, t in zip(sa, sb):
        assert (math.isnan(s.value) and math.isnan(t.value)) or s.value == pytest.approx(t.value, rel=1e-9, abs=1e-12), \
            (where, s.name)
    drawn = {n for n, p in a.paths.items() if np.isfinite(p).any()}       # a couple zero at an angle: NaN there
    assert drawn == {n for n, p in b.paths.items() if np.isfinite(p).any()}, where
    for n in drawn:
        assert np.allclose(a.paths[n], b.paths[n], rtol=1e-9, atol=1e-9), (where, n)
    assert [(r.symbol, r.unit, r.how) for r in a.results] == [(r.symbol, r.unit, r.how) for r in b.results], where
    for r, t in zip(a.results, b.results):
        assert r.value == pytest.approx(t.value, rel=1e-9, abs=1e-12), (where, r.symbol)


def _compared(mech, res, every: bool) -> list[int]:
    """The angle indices compared: all, or a few (the first, a third and two thirds round, and the
    first angle of each order of a triad's sides, `kinematics.special_index`)."""
    from kinetostat.kinematics import special_index
    n = len(res.phi_deg)
    if every:
        return list(range(n))
    firsts = {int(np.argmax(k == x)) for g in mech.structure.groups if g.klass == 3
              for k in [special_index(mech, res.kin, g)] for x in set(k.tolist())}
    return sorted({0, n // 3, 2 * n // 3} | firsts)


@pytest.mark.parametrize("name, friction", CASES, ids=[f"{n}-{f}" for n, f in CASES])
def test_cycle_equals_one_angle_builds(name, friction):
    _check(name, friction, every=False)


@pytest.mark.slow
@pytest.mark.parametrize("name, friction", CASES, ids=[f"{n}-{f}" for n, f in CASES])
def test_cycle_equals_one_angle_builds_at_every_angle(name, friction):
    _check(name, friction, every=True)


def _check(name: str, friction: str, every: bool) -> None:
    """The cycle at ANGLES (singular ones and, with friction, self-locking ones left out) against
    an analysis and a build at each compared angle alone."""
    mech = kinetostat.load(name)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = kinetostat.analyze(mech, phi_deg=ANGLES, friction=friction)
        ok = ~res.singular
        if res.friction is not None:
            ok &= res.friction.solved
        angles = ANGLES[ok]
        res = kinetostat.analyze(mech, phi_deg=angles, friction=friction)
        first = _build(mech, kinetostat.analyze(mech, phi_deg=angles[:1], friction=friction),
                       {"group": None, "forces": default_mu_F(mech, res), "crank": None, "lever": None})
        mu_F = {"group": {p.kind.partition(":")[2]: next(s.scale for s in p.segments if s.scale is not None)
                          for p in first if p.kind.startswith("group:")},
                "forces": default_mu_F(mech, res), "crank": next(s.scale for s in first[-2].segments if s.scale is not None),
                "lever": next(s.scale for s in first[-1].segments if s.unit == "N")}
        cycle = _build(mech, res, mu_F)
        for i in _compared(mech, res, every):
            one = _build(mech, kinetostat.analyze(mech, phi_deg=[angles[i]], friction=friction), mu_F)
            assert [p.kind for p in cycle] == [p.kind for p in one]
            for c, p in zip(cycle, one):
                assert c.n == len(angles)
                _same(c.at(i), p.at(0))


def test_one_angle_cycle_keeps_the_plan_of_today():
    """N = 1: loads are (1,) arrays and the lever's moment a float off its Plan (seed 002 at 30 deg)."""
    mech = kinetostat.load("ice_crank_slider")
    res = kinetostat.analyze(mech, phi_deg=[30.0])
    (G2, F_i2, *_rest) = link_loads(mech, res, 2)
    assert G2.force.shape == (1,) and G2.force[0] == -1j * mech.g * mech.links[2].mass
    lever = lever_plan(mech, res, 0.2)
    assert lever.n == 1 and isinstance(pole_moment(lever.at(0)), float)
    assert pole_moment(lever)[0] == pytest.approx(pole_moment(lever.at(0)), rel=1e-15)
