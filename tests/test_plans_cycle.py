"""The plans on arrays (issue 34): a cycle of N angles built in one pass (`plans.build_cycle`)
gives at each angle the plan that a build at that one angle gives (`plans.build`, the N = 1
case), element by element; singular positions are NaN, not drawn."""
from __future__ import annotations

import math
import warnings
from dataclasses import replace

import numpy as np
import pytest

import kinetostat
import kinetostat.plans as P
from kinetostat.plans.core import Plan

from conftest import MODELS, sampled

#: Every 15 deg: 24 angles.
ANGLES = np.arange(24) * 15.0


def _close(a: float, b: float) -> bool:
    return (math.isnan(a) and math.isnan(b)) or math.isclose(a, b, rel_tol=1e-9, abs_tol=1e-9)


def _drawn(plan: Plan) -> Plan:
    """The plan without what it does not draw: points with NaN coordinates, segments with such an
    end, paths with no finite point (a cycle's element at an angle where it is not drawn)."""
    points = {k: z for k, z in plan.points.items() if np.isfinite(z)}
    return replace(plan, points=points, segments=tuple(s for s in plan.segments if s.start in points and s.end in points),
                   paths={k: p for k, p in plan.paths.items() if np.isfinite(p).any()})


def _differences(cycle: Plan, one: Plan) -> list[str]:
    """What differs between the cycle's plan of an angle and the one-angle build's (empty: none):
    points, segments (by name; a name drawn twice by its order), paths (their drawn points),
    titles, notes, results, equation, accuracy, scales; of the cycle's, what it draws there."""
    cycle = _drawn(cycle)
    out = []
    for field in ("kind", "title", "scale", "phi_deg", "notes", "equation"):
        if getattr(cycle, field) != getattr(one, field):
            out.append(f"{field}: {getattr(cycle, field)!r} != {getattr(one, field)!r}")
    if set(cycle.points) != set(one.points):
        out.append(f"points {sorted(set(cycle.points) ^ set(one.points))}")
    out += [f"point {k}: {cycle.points[k]} != {v}" for k, v in one.points.items()
            if k in cycle.points and not (_close(cycle.points[k].real, v.real) and _close(cycle.points[k].imag, v.imag))]

    def keyed(plan: Plan) -> dict:
        seen: dict[str, int] = {}
        out = {}
        for s in plan.segments:
            out[(s.name, seen.get(s.name, 0))] = s
            seen[s.name] = seen.get(s.name, 0) + 1
        return out
    a, b = keyed(cycle), keyed(one)
    if set(a) != set(b):
        out.append(f"segments {sorted(set(a) ^ set(b))}")
    for k in set(a) & set(b):
        sa, sb = a[k], b[k]
        if (sa.start, sa.end, sa.unit, sa.kind, sa.scale) != (sb.start, sb.end, sb.unit, sb.kind, sb.scale) \
                or not _close(sa.value, sb.value):
            out.append(f"segment {k}: {sa} != {sb}")
    if set(cycle.paths) != set(one.paths):
        out.append(f"paths {sorted(set(cycle.paths) ^ set(one.paths))}")
    for k in set(cycle.paths) & set(one.paths):
        pa, pb = ([z for z in p[k] if np.isfinite(z)] for p in (cycle.paths, one.paths))
        if len(pa) != len(pb) or not all(_close(x.real, y.real) and _close(x.imag, y.imag) for x, y in zip(pa, pb)):
            out.append(f"path {k}")
    ra, rb = [(r.symbol, r.unit, r.how) for r in cycle.results], [(r.symbol, r.unit, r.how) for r in one.results]
    if ra != rb or not all(_close(x.value, y.value) for x, y in zip(cycle.results, one.results)):
        out.append(f"results {cycle.results} != {one.results}")
    if (cycle.accuracy is None) != (one.accuracy is None) or (
            cycle.accuracy is not None and not (_close(cycle.accuracy[0], one.accuracy[0]) and cycle.accuracy[1] == one.accuracy[1])):
        out.append(f"accuracy {cycle.accuracy} != {one.accuracy}")
    return out


@pytest.mark.parametrize("path", sampled(MODELS, keep=("ice_crank_slider", "triad_slider")))
def test_cycle_equals_one_angle_builds(path):
    """Every plan kind of the cycle at 24 angles (one analysis, one build) is, angle by angle, the
    plan `build` draws at that angle alone at the same scales: the same points, segments, values,
    paths, titles and notes (to 1e-9). triad_slider's special point S lies on other leashes over
    the cycle: its construction segments are drawn only at their angles."""
    mech = kinetostat.load(path)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = kinetostat.analyze(mech, phi_deg=ANGLES, friction="first")
        fixed = P.cycle_scales(mech, res=res)
        positions = P.fixed_positions(mech, fixed.base["mu_l"], starting_deg=0.0)
        cycles = P.build_cycle(mech, res, fixed, positions)
        assert all(c.n == len(ANGLES) for c in cycles.values())
        for i, at in enumerate(ANGLES):
            if res.singular[i]:
                assert all(np.isnan(list(c.at(i).points.values())).all() for c in cycles.values())
                continue
            one = P.build(mech, at=float(at), fixed=fixed, positions=positions)
            assert list(one) == list(cycles)
            for kind, plan in one.items():
                assert _differences(cycles[kind].at(i), plan) == [], f"{kind} at {at:g} deg"


def test_build_analyses_once(monkeypatch):
    """`build` analyses the mechanism once (`solution.solve`: the cycle grid and its angle; the
    plan of positions' 12 positions and paths, given, need no other; the other branch of the
    slider's group is positions only): no builder solves again."""
    import kinetostat.solve as solve
    mech = kinetostat.load(MODELS[0].parent / "ice_crank_slider.toml")
    fixed = P.cycle_scales(mech, step_deg=120.0)
    positions = P.fixed_positions(mech, fixed.base["mu_l"])
    calls = []
    real = solve.analyze
    monkeypatch.setattr(solve, "analyze", lambda *a, **k: calls.append(k.get("phi_deg")) or real(*a, **k))
    P.build(mech, at=30.0, fixed=fixed, positions=positions)
    assert len(calls) == 1 and 30.0 in calls[0]


def test_a_singular_angle_of_the_cycle_draws_nothing():
    """A toggle at 180 deg (tests/hostile/singular_toggle.toml): in a cycle over 30, 179 and 180 deg
    every plan's points are NaN at 180 (nothing drawn there), and the other angles are the
    one-angle builds, 179 deg stating its 8 digits left."""
    from conftest import ROOT
    mech = kinetostat.load(ROOT / "tests" / "hostile" / "singular_toggle.toml")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = kinetostat.analyze(mech, phi_deg=[30.0, 179.0, 180.0], friction="first")
        fixed = P.cycle_scales(mech, res=res)
        cycles = P.build_cycle(mech, res, fixed)
        ones = [P.build(mech, at=at, fixed=fixed, positions=P.fixed_positions(mech, fixed.base["mu_l"])) for at in (30.0, 179.0)]
    assert list(res.singular) == [False, False, True]
    for kind, cycle in cycles.items():
        assert np.isnan(np.array(list(cycle.points.values()))[:, 2]).all(), kind
        for i, one in enumerate(ones):
            assert _differences(cycle.at(i), one[kind]) == [], f"{kind} at {one.at:g} deg"
    assert cycles["velocity"].at(1).accuracy[0] == pytest.approx(8.0, abs=0.1)
