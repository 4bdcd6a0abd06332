"""The construction drawn in steps (issue 36 item 3): seed 002 sec. 1.2, the ICE at 30 deg.

Velocity plan (fig. 1.7): "through a a line perpendicular to AB, through P a vertical line; at
their intersection mark b". Acceleration plan (fig. 1.8): through n2 a line perpendicular to AB,
through the pole a vertical line, meeting in b. Force plan of group 2-3 (fig. 1.10): R12t, G2,
F_i2, G3, F_i3, F_p laid end to end, the line of R12n (along AB) through the start of R12t, the
line of R43 (square to the guide) through the end of F_p, their intersection fixing both."""
from __future__ import annotations

import re
import warnings

import numpy as np
import pytest

import kinetostat
import kinetostat.plans as P
from kinetostat.plans.draw import PAST_MM, svg
from kinetostat.plans.page import _steps


@pytest.fixture(scope="module")
def ice():
    mech = kinetostat.load("ice_crank_slider")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = kinetostat.analyze(mech, phi_deg=[30.0])
        plans = P.build(mech, at=30.0)
    xy = {n: complex(*res.position(n)[0]) for n in ("A", "B")}
    guide = next(complex(*p.direction) for p in mech.pairs if p.kind == "P" and 0 in p.links)
    return mech, res, plans, xy["B"] - xy["A"], guide


def _meet(p1: complex, d1: complex, p2: complex, d2: complex) -> complex:
    """The intersection of the lines p1 + t d1 and p2 + s d2."""
    t = ((p2 - p1).conjugate() * d2).imag / (d1.conjugate() * d2).imag
    return p1 + t * d1


def _check(plan, lines: list[tuple[str, str, complex]], point: str) -> None:
    """Each construction line (name, known point it passes through, the exact direction) runs
    through that point in that direction; the lines of the exact directions through the known
    points meet at the plan's point to 1e-9 mm; the mark is there."""
    got = {s.name: s for s in plan.segments if s.kind in ("construction", "intersection")}
    ends = []
    for name, through, d in lines:
        s = got[f"line {name}"]
        assert s.start == through and s.end == point
        drawn = plan.points[s.end] - plan.points[s.start]
        assert abs((drawn.conjugate() * d).imag) <= 1e-12 * abs(drawn) * abs(d)         # parallel
        ends.append((plan.points[through], d))
    assert abs(_meet(*ends[0], *ends[1]) - plan.points[point]) < 1e-9
    mark = got[f"point {point}"]
    assert mark.start == mark.end == point


def test_velocity_plan_b_at_the_lines_square_to_AB_and_along_the_guide(ice):
    _, _, plans, AB, guide = ice
    v = plans["velocity"]
    _check(v, [("a-b", "a", 1j * AB), ("p-b", "p", guide)], "b")
    assert v.steps == ("p-a", "line a-b", "line p-b", "point b")


def test_acceleration_plan_b_from_n2_square_to_AB_and_the_pole_along_the_guide(ice):
    _, _, plans, AB, guide = ice
    a = plans["acceleration"]
    _check(a, [("n2-b", "n2", 1j * AB), ("pi-b", "pi", guide)], "b")
    assert a.steps == ("pi-a", "a-n2", "line n2-b", "line pi-b", "point b")


def test_force_polygon_closed_by_R12n_along_AB_and_R43_square_to_the_guide(ice):
    _, _, plans, AB, guide = ice
    f = plans["forces:2,3"]
    known = ("R12t", "G2", "F_i2", "G3", "F_i3", "F_p")
    assert f.equation == (*known, "R43", "R12n")
    start, end_Fp = f.segment("R12t").start, f.segment("F_p").end
    _check(f, [("R12n", start, AB), ("R43", end_Fp, 1j * guide)], f.segment("R43").end)
    assert f.steps == (*known, "line R12n", "line R43", f"point {f.segment('R43').end}", "R43", "R12n")


def _numbers(sheet: str) -> dict[int, tuple[float, float]]:
    """The step numbers on a sheet: k -> where "(k)" is written (x, y mm)."""
    found = re.findall(r'<text x="([-\d.]+)" y="([-\d.]+)" class="step"[^>]*>(.*?)</text>', sheet)
    return {int(re.sub(r"<[^>]*>", "", t).strip("()")): (float(x), float(y)) for x, y, t in found}


@pytest.mark.parametrize("kind", ["velocity", "acceleration", "forces:2,3"])
def test_sheet_numbers_the_steps_as_the_page_does(ice, kind):
    """Every step of the plan is numbered on its sheet, (1) to (n), the intersection's number
    beside its mark and each line's past the intersection; the page's "next step" gives the
    same step the same number."""
    mech, res, plans, _, _ = ice
    plan = plans[kind]
    sheet = svg(plan, lang="uk")
    numbers = _numbers(sheet)
    assert sorted(numbers) == list(range(1, len(plan.steps) + 1))
    marks = re.findall(r'<circle cx="([-\d.]+)" cy="([-\d.]+)" r="1.2" fill="none"', sheet)
    assert len(marks) == 1
    mark = np.array(marks[0], float)
    k = plan.steps.index(next(s for s in plan.steps if s.startswith("point "))) + 1
    assert np.hypot(*(np.array(numbers[k]) - mark)) < 10.0          # its baseline's start, 3.5 mm text
    lines = re.findall(r'<line x1="([-\d.]+)" y1="([-\d.]+)" x2="([-\d.]+)" y2="([-\d.]+)" stroke="#000" '
                       r'stroke-width="0.25"><title>', sheet)
    assert len(lines) == 2
    for x1, y1, x2, y2 in lines:          # past the known point and past the intersection
        assert np.hypot(float(x2) - float(x1), float(y2) - float(y1)) > 2 * PAST_MM
    page = [(s["segment"], s["n"]) for s in _steps(mech, res, plans, "uk") if s["plan"] == kind and "n" in s]
    assert page == [(name, k) for k, name in enumerate(plan.steps, 1)]
