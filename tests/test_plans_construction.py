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



@pytest.mark.parametrize("kind", ["velocity", "acceleration"])
def test_page_draws_a_construction_line_to_its_points_and_past_them_by_markers(ice, kind):
    """On the page (`contract`) a construction line's element runs from its known point to the point
    it fixes, and the PAST_MM beyond each is drawn by the marker "past" at both ends (a stroke
    PAST_MM long): the one-angle sheet's line less PAST_MM at each end, as the sheet places it.
    Before: the page's element was the sheet's, its ends new coordinates at every angle."""
    from kinetostat.plans.core import PlanCycle
    from kinetostat.plans.draw import WEIGHT_MM, drawing
    _, _, plans, _, _ = ice
    cycle = PlanCycle.of(plans[kind])
    page, sheet = drawing(cycle, contract=True), drawing(cycle)
    lines = [e for e in page.elements if e.attrs.get("data-segment", "").startswith("line ")]
    drawn = [e for e in sheet.elements if e.tag == "line" and e.title.startswith("line ")]
    assert len(lines) == len(drawn) == 2
    assert f'<marker id="past"' in page.static and f'd="M0,0 L{PAST_MM:g},0" stroke="#000" stroke-width="{WEIGHT_MM["construction"]}"' in page.static
    assert '<marker id="past"' not in sheet.static
    for e, f in zip(lines, drawn):
        assert e.attrs["marker-start"] == e.attrs["marker-end"] == "url(#past)"
        (a, b), (a0, b0) = e.xy[0], f.xy[0]
        u = (b - a) / np.hypot(*(b - a))
        assert np.allclose(a0, a - PAST_MM * u) and np.allclose(b0, b + PAST_MM * u)


# ----------------------------------------------------------------------------- triads

TRIADS = ("triad_six_bar", "triad_rocking_block", "triad_slider")
#: Angles at which S lies on each pair of leashes the models take (`kinematics.special_index`).
TRIAD_ANGLES = [30.0, 90.0, 150.0, 330.0]


def _axes(mech, res, g, i: int) -> dict[int, tuple[complex, complex]]:
    """Per leash of triad g at angle index i: (a point of its axis, its direction), world, from the
    positions alone: a two-pin leash outer pin -> inner pin, a slider the normal to its frame
    guide through its pin, a rocking block the normal to the base's arm through its frame pin."""
    z = lambda n: complex(*res.position(n)[i])
    out = {}
    for ell, o, inner, _ in g.sides:
        if inner.kind == "P":                    # the arm of the base: its direction turned with the base
            b = g.links[0]
            local = [complex(*xy) for xy in mech.links[b].points.values()][:2]
            world = [z(n) for n in list(mech.links[b].points)[:2]]
            out[ell] = (z(o.point), 1j * complex(*inner.direction) * (world[1] - world[0]) / (local[1] - local[0]))
        elif o.kind == "P":
            out[ell] = (z(inner.point), 1j * complex(*o.direction))
        else:
            out[ell] = (z(inner.point), z(inner.point) - z(o.point))
    return out


def _world(mech, res, g, name: str, i: int, S: complex) -> complex:
    """A velocity plan point's model point, world (s: Assur's point S; f3: the base's point under F)."""
    return S if name.rstrip(":0123456789") == "s" else complex(*res.position(name.split(":")[0].rstrip("0123456789").upper())[i])


@pytest.fixture(scope="module", params=TRIADS)
def triad(request):
    from kinetostat.kinematics import special_point_z
    mech = kinetostat.load(request.param)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = kinetostat.analyze(mech, phi_deg=TRIAD_ANGLES)
        fixed = P.cycle_scales(mech, step_deg=120.0)
        cycles = P.build_cycle(mech, res, fixed, only=["velocity", "acceleration", "forces"])
    g = next(g for g in mech.structure.groups if g.klass == 3)
    return mech, res, g, cycles, special_point_z(mech, res.kin, g)


def _lines_meet(plan, lines: list[tuple[str, complex]], point: str) -> None:
    """Each line (name, the exact direction) runs from its known point parallel to it; the lines
    of those directions through the known points meet at the plan's point to 1e-9 mm; its mark is there."""
    got = {s.name: s for s in plan.segments if s.kind in ("construction", "intersection") and np.isfinite(plan.points[s.end])}
    ends = []
    for name, d in lines:
        s = got[f"line {name}"]
        drawn = plan.points[s.end] - plan.points[s.start]
        assert abs((drawn.conjugate() * d).imag) <= 1e-9 * abs(drawn) * abs(d), name
        ends.append((plan.points[s.start], d))
    assert abs(_meet(*ends[0], *ends[1]) - plan.points[point]) < 1e-9
    assert plan.points[got[f"point {point}"].start] == plan.points[point]


def test_triad_velocity_plan_through_assurs_point(triad):
    """Artobolevsky's construction: s where the lines square to the axes of the two leashes
    through S (through their outer pins' points) meet; the third leash's inner point on the line
    square to S-Q through s and its leash's line; the other two on the lines square to the base's
    sides from it and their leashes' lines. Every direction from the positions alone; the
    intersections at the solver's velocities to 1e-9 mm; at angles where S lies on each pair."""
    mech, res, g, cycles, S = triad
    outer = {ell: (o.point.lower() if o.kind == "R" and 0 not in o.links else "p") for ell, o, _, _ in g.sides}
    inner = {ell: (i.point.lower() + (str(i.links[0]) if i.kind == "P" else "")) for ell, _, i, _ in g.sides}
    orders = set()
    for i in range(len(TRIAD_ANGLES)):
        v = cycles["velocity"].at(i)
        axes = _axes(mech, res, g, i)
        lines = [s for s in v.segments if s.kind == "construction" and np.isfinite(v.points[s.end])]
        through_s = [ell for ell, (X, u) in axes.items() if abs(((S[i] - X).conjugate() * u).imag) < 1e-9 * abs(u)]
        assert len(through_s) == 2
        third = next(ell for ell in axes if ell not in through_s)
        orders.add(third)
        q3 = inner[third]
        q1, q2 = (inner[ell] for ell in through_s)
        expected = {"s": [(f"{outer[ell]}-s", 1j * axes[ell][1]) for ell in through_s],
                    q3: [(f"s-{q3}", 1j * (_world(mech, res, g, q3, i, S[i]) - S[i])), (f"{outer[third]}-{q3}", 1j * axes[third][1])]}
        for ell, q in zip(through_s, (q1, q2)):
            expected[q] = [(f"{q3}-{q}", 1j * (_world(mech, res, g, q, i, S[i]) - _world(mech, res, g, q3, i, S[i]))),
                           (f"{outer[ell]}-{q}", 1j * axes[ell][1])]
        assert sorted(s.name for s in lines) == sorted(f"line {n}" for ls in expected.values() for n, _ in ls)
        for q, ls in expected.items():
            _lines_meet(v, ls, q)
        assert [n for n in v.steps if n.startswith("point ")] == ["point s", f"point {q3}", f"point {q1}", f"point {q2}"] \
            or [n for n in v.steps if n.startswith("point ")] == ["point s", f"point {q3}", f"point {q2}", f"point {q1}"]
        assert set(v.steps) <= {s.name for s in v.segments if s.kind != "vector" or np.isfinite(v.points[s.end])}
    assert len(orders) == 2


def test_triad_acceleration_plan_through_assurs_point(triad):
    """Artobolevsky's a_S = a_O + a^n_QO + a^n_SQ + a^t (both tangential parts square to the
    leash's axis through S; a slider's: a^n_SQ + a part along its guide): s where the lines of
    those directions through the ends of the normal parts meet; Q3 from s (a^n_Q3S, square to
    S Q3) and its leash (a^n_Q3O, square to its axis); the other two from Q3 likewise. Every
    known point and direction from the positions, omega and the outer pins' accelerations alone;
    the intersections at the solver's accelerations to 1e-9 mm. A rocking block (a leash on an
    inner prismatic pair) has none."""
    mech, res, g, cycles, S = triad
    acc = cycles["acceleration"]
    if any(i.kind == "P" for _, _, i, _ in g.sides):
        assert not any(s.kind == "construction" for s in acc.segments) and acc.steps == ()
        return
    mu = acc.scale.value
    base = g.links[0]
    for i in range(len(TRIAD_ANGLES)):
        a = acc.at(i)
        z = lambda n: complex(*res.position(n)[i])
        acc_of = lambda n: complex(*res.acceleration(n)[i]) / mu
        w2 = res.omega(base)[i] ** 2
        axes = _axes(mech, res, g, i)
        leash = {}                 # leash -> (inner point, the end of its known parts (plan), the line's direction)
        for ell, o, inner, _ in g.sides:
            Q = z(inner.point)
            if o.kind == "R":
                leash[ell] = (inner.point, acc_of(o.point) - res.omega(ell)[i] ** 2 * (Q - z(o.point)) / mu, 1j * axes[ell][1])
            else:
                leash[ell] = (inner.point, 0j, complex(*o.direction))
        through_s = [ell for ell, (X, u) in axes.items() if abs(((S[i] - X).conjugate() * u).imag) < 1e-9 * abs(u)]
        third = next(ell for ell in axes if ell not in through_s)
        ends = []
        for ell in through_s:
            Q, known, d = leash[ell]
            ends.append((known - w2 * (S[i] - z(Q)) / mu, d))
        assert abs(_meet(*ends[0], *ends[1]) - a.points["s"]) < 1e-9
        Q3, known3, d3 = leash[third]
        at_s = a.points["s"] - w2 * (z(Q3) - S[i]) / mu
        assert abs(_meet(at_s, 1j * (z(Q3) - S[i]), known3, d3) - a.points[Q3.lower()]) < 1e-9
        for ell in through_s:
            Q, known, d = leash[ell]
            at_q3 = a.points[Q3.lower()] - w2 * (z(Q) - z(Q3)) / mu
            assert abs(_meet(at_q3, 1j * (z(Q) - z(Q3)), known, d) - a.points[Q.lower()]) < 1e-9
        lines = [s for s in a.segments if s.kind == "construction" and np.isfinite(a.points[s.end])]
        assert len(lines) == 8
        for s in lines:                   # each drawn from one of those known points along one of those directions
            start, q = a.points[s.start], a.points[s.end]
            assert any(abs(start - p) < 1e-9 and abs(((q - start).conjugate() * d).imag) <= 1e-9 * abs(q - start) * abs(d)
                       for p, d in [*ends, (at_s, 1j * (z(Q3) - S[i])), (known3, d3)]
                       + [(a.points[Q3.lower()] - w2 * (z(leash[e][0]) - z(Q3)) / mu, 1j * (z(leash[e][0]) - z(Q3))) for e in through_s]
                       + [(leash[e][1], leash[e][2]) for e in through_s]), s.name
        assert [n for n in a.steps if n.startswith("point ")][:2] == ["point s", f"point {Q3.lower()}"]
        drawn = {s.name for s in a.segments if s.kind != "vector" or np.isfinite(a.points[s.end])}
        assert set(a.steps) <= drawn                  # every step a segment drawn at this angle


def test_triad_force_polygon_closed_along_the_axes_through_S(triad):
    """The polygon closed by R..n of the two leashes through S: their lines along those leashes'
    axes (from the positions) through the polygon's start and the last known force's end, meeting
    at the vertex the solver's reactions put there, to 1e-9 mm; the steps: the known sides, the
    lines, the intersection, the two unknowns."""
    mech, res, g, cycles, S = triad
    cycle = next(c for k, c in cycles.items() if k.startswith("forces:"))
    for i in range(len(TRIAD_ANGLES)):
        f = cycle.at(i)
        axes = _axes(mech, res, g, i)
        last, before = f.equation[-1], f.equation[-2]
        leash = lambda R: int(R[2])               # R<known><leash>n
        _lines_meet(f, [(last, axes[leash(last)][1]), (before, axes[leash(before)][1])], f.segment(before).end)
        assert f.steps == (*f.equation[:-2], f"line {last}", f"line {before}", f"point {f.segment(before).end}", before, last)


def test_triad_sheet_numbers_every_step(triad):
    """The one-angle sheets of a triad number each step (1)..(n) as `Plan.steps` lists them."""
    mech, res, g, cycles, S = triad
    for kind, cycle in cycles.items():
        if kind in ("velocity",) or kind.startswith("forces:"):
            plan = cycle.at(0)
            assert len(plan.steps) >= 4 and sorted(_numbers(svg(plan, lang="uk"))) == list(range(1, len(plan.steps) + 1)), kind


def test_page_draws_the_triad_construction_of_each_one_angle_sheet(monkeypatch):
    """The page of every angle (triad_six_bar at 30 and 150 deg) draws in its velocity and
    acceleration plans each angle's construction lines and marks, and numbers them (1)..(n), as
    the one-angle sheet of that angle does (`kinetostat plans --at A --cycle-scales`). Before: the
    page left them out (`without_triad_construction`)."""
    import kinetostat.plans.page as pg
    mech = kinetostat.load("triad_six_bar")
    sheets = {}
    encode = pg.encode_drawing

    def keep(d, earlier=()):
        sheets[d.kind] = d
        return encode(d, earlier)
    monkeypatch.setattr(pg, "encode_drawing", keep)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        pg.page(mech, angles=[30.0, 150.0])
        fixed = P.cycle_scales(mech)
    for i, at in enumerate((30.0, 150.0)):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            plans = P.build(mech, at=at, fixed=fixed)
        for kind in ("velocity", "acceleration"):
            page, one = sheets[kind].svg(i), plans[kind]
            marks = sorted(set(re.findall(r'<line [^>]*data-segment="([^"]+)"[^>]*marker-start="url\(#past\)"', page)
                               + re.findall(r'<circle [^>]*data-segment="([^"]+)"', page)))
            want = sorted({s.name for s in one.segments if s.kind in ("construction", "intersection")})
            assert want and marks == want, (at, kind, marks, want)
            assert sorted(_numbers(page)) == list(range(1, len(one.steps) + 1)) == sorted(_numbers(svg(one, lang="en"))), (at, kind)
