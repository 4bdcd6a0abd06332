"""Line weights by role and the legend of each sheet (issue 36 item 4; ГОСТ 2.303: the solid thick
main line S = 0.5-1.4 mm, thin lines S/3-S/2): every segment of the ICE's sheets at 30 deg drawn
in the width of its role, the roles of seed 002 § 1.2 (figs 1.6-1.11), the legend's strokes in the
widths the sheet uses, the legend clear of every label, note and line."""
from __future__ import annotations

import html
import re

import numpy as np
import pytest

import kinetostat
import kinetostat.plans as P
from kinetostat.plans.core import role_of
from kinetostat.plans.draw import S_MM, WEIGHT_MM, svg
from kinetostat.plans.labels import ASCENT, DESCENT, text_width

#: Seed 002 § 1.2 at φ1 = 30°: what each plan lays off from the data (given), the parts of its
#: vector sums (component), what it is drawn to find (result), the mechanism's links.
SEED = {
    "mechanism": {"OA": "link", "AB": "link"},
    "positions": {"O-A": "link", "A-B": "link", "O-A1": "auxiliary"},
    "velocity": {"p-a": "given", "a-b": "component", "p-b": "result", "p-s2": "result"},
    "acceleration": {"pi-a": "given", "a-n2": "component", "n2-b": "component", "a-b": "component",
                     "pi-b": "result", "pi-s2": "result"},
    "group:2,3": {"AB": "link", "G2": "given", "F_i2": "given", "F_p": "given", "R12n": "component",
                  "R12t": "component", "R43": "result"},
    "forces:2,3": {"G2": "given", "F_i2": "given", "G3": "given", "F_i3": "given", "F_p": "given",
                   "R12t": "component", "R12n": "component", "R12": "result", "R43": "result", "R32": "result"},
    "crank": {"OA": "link", "R21": "given", "R41": "result"},
}

_SEGMENT = re.compile(r'<line [^>]*stroke-width="([0-9.]+)"[^>]*data-segment="([^"]+)"')
_LEGEND = re.compile(r'<line data-role="(\w+)" x1="([0-9.]+)" y1="([0-9.]+)" x2="([0-9.]+)" y2="([0-9.]+)" '
                     r'stroke="[^"]+" stroke-width="([0-9.]+)"')


@pytest.fixture(scope="module")
def ice():
    return P.build(kinetostat.load("ice_crank_slider"), at=30)


def _widths(sheet: str) -> dict[str, set[float]]:
    """segment name -> the stroke widths of its lines on a contract sheet (mm)."""
    out: dict[str, set[float]] = {}
    for w, name in _SEGMENT.findall(sheet):
        out.setdefault(html.unescape(name), set()).add(float(w))
    return out


def _legend(sheet: str) -> dict[str, float]:
    """The legend's roles -> their sample strokes' widths (mm)."""
    return {m[0]: float(m[5]) for m in _LEGEND.findall(sheet)}


def test_every_segment_is_drawn_in_the_width_of_its_role(ice):
    """Every segment of every ICE sheet at 30 deg: its SVG width is its role's (`WEIGHT_MM`); the
    seed's roles (SEED) as the plans state them."""
    for kind, plan in ice.items():
        sheet = svg(plan, "uk", contract=True)
        widths = _widths(sheet)
        drawn = {s.name: s for s in plan.segments if s.name in widths}
        lines = [s for s in plan.segments if s.kind != "intersection"]       # a mark is a circle
        assert len(drawn) >= len(lines) - 2, (kind, set(widths))             # G2, G3: negligible, not drawn
        for name, s in drawn.items():
            assert widths[name] == {WEIGHT_MM[role_of(s)]}, (kind, name, widths[name], role_of(s))
        for name, role in SEED.get(kind, {}).items():
            assert role_of(plan.segment(name)) == role, (kind, name)
            assert widths.get(name, {WEIGHT_MM[role]}) == {WEIGHT_MM[role]}, (kind, name, widths[name])


def test_results_at_S_components_at_half_of_it(ice):
    """ГОСТ 2.303: results and links at S = 0.7 mm (0.5-1.4), components S/2, construction and
    auxiliary lines S/3-S/2, givens between; on the force plan R12 twice as wide as R12n and R12t."""
    assert 0.5 <= S_MM <= 1.4 and WEIGHT_MM["result"] == WEIGHT_MM["link"] == S_MM == 0.7
    for role in ("component", "construction", "auxiliary"):
        assert S_MM / 3 - 0.02 <= WEIGHT_MM[role] <= S_MM / 2 + 1e-12, role
    assert WEIGHT_MM["component"] < WEIGHT_MM["given"] < WEIGHT_MM["result"]
    widths = _widths(svg(ice["forces:2,3"], "en", contract=True))
    (R12,), (R12n,), (R12t,), (F_p,) = widths["R12"], widths["R12n"], widths["R12t"], widths["F_p"]
    assert R12 / R12n == R12 / R12t == pytest.approx(2.0) and R12n < F_p < R12
    widths = _widths(svg(ice["velocity"], "en", contract=True))
    assert widths["p-b"] == {0.7} and widths["a-b"] == {0.35} and widths["p-a"] == {0.5}


@pytest.mark.parametrize("lang", ["uk", "ru", "en"])
def test_each_sheet_has_a_legend_of_the_widths_it_uses(ice, lang):
    """Each sheet's legend: one sample stroke per role drawn there, in the width that role's
    segments have on the sheet; its words in `lang`."""
    words = {"uk": "товщина ліній, мм:", "ru": "толщина линий, мм:", "en": "line widths, mm:"}[lang]
    for kind, plan in ice.items():
        sheet = svg(plan, lang, contract=True)
        legend = _legend(sheet)
        used: dict[str, set[float]] = {}
        widths = _widths(sheet)
        for s in plan.segments:
            if s.name in widths:
                used.setdefault(role_of(s), set()).update(widths[s.name])
        assert set(legend) == set(used), (kind, legend, used)
        for role, w in legend.items():
            assert used[role] == {w}, (kind, role)
        assert words in sheet, kind


def _text_box(markup: str, x: float, y: float, size: float) -> tuple[float, float, float, float]:
    """A text's box at baseline (x, y): DejaVu Sans widths, room below for a subscript (lowered 0.2
    of the size, as the notes letter it)."""
    plain = html.unescape(re.sub("<[^>]+>", "", markup))
    return x, y - ASCENT * size, x + text_width(plain, size), y + (DESCENT + 0.2) * size


def _overlap(a, b, tol: float = 0.05) -> bool:
    return min(a[2], b[2]) - max(a[0], b[0]) > tol and min(a[3], b[3]) - max(a[1], b[1]) > tol


def _legend_boxes(sheet: str) -> list[tuple[float, float, float, float]]:
    block = re.search(r'<g id="legend"[^>]*>(.*?)</g>', sheet, re.S).group(1)
    boxes = [_text_box(t, float(x), float(y), 2.5) for x, y, t in re.findall(r'<text x="([0-9.]+)" y="([0-9.]+)">(.*?)</text>', block)]
    boxes += [(float(m[1]), float(m[2]) - 0.5, float(m[3]), float(m[4]) + 0.5) for m in _LEGEND.findall(block)]
    return boxes


def _others(sheet: str) -> list[tuple[str, tuple[float, float, float, float]]]:
    """Every other text's box (labels, notes, title block) and every drawn line's, arrowhead's and
    curve's (the plan's)."""
    out = []
    rest = re.sub(r'<g id="legend".*?</g>', "", sheet, flags=re.S)
    for attrs, body in re.findall(r"<text ([^>]*)>(.*?)</text>", rest, re.S):
        x, y = (float(re.search(fr'\b{k}="([-0-9.]+)"', attrs).group(1)) for k in "xy")
        size = float(re.search(r'font-size="([0-9.]+)"', attrs).group(1))
        out.append((re.sub("<[^>]+>", "", body), _text_box(body, x, y, size)))
    plan = re.search(r'<g id="plan".*?</g>', rest, re.S).group(0)
    for tag, attrs in re.findall(r"<(line|path|polyline) ([^>]*)>", plan):
        coords = re.search(r'(?:x1="[^"]*" y1="[^"]*" x2="[^"]*" y2="[^"]*"|d="[^"]*"|points="[^"]*")', attrs).group(0)
        xy = np.array([float(v) for v in re.findall(r"-?[0-9]+(?:\.[0-9]+)?", re.sub(r'[xy][12]=', "", coords))])
        xy = xy.reshape(-1, 2)
        out.append((tag, (*xy.min(axis=0), *xy.max(axis=0))))
    return out


def test_the_legend_is_clear_of_every_label_note_and_line():
    """The ICE's sheets at the dead centre and at 150 deg (30 deg: the tests above), in ru (the longest
    words), with their notes: no label, note, title or drawn line over the legend's strokes or words."""
    mech = kinetostat.load("ice_crank_slider")
    res = kinetostat.analyze(mech, phi_deg=np.array([0.0, 150.0]))
    for kind, cycle in P.build_cycle(mech, res, P.cycle_scales(mech, res=res)).items():
        for i in range(cycle.n):
            sheet = svg(cycle.at(i), "ru")
            legend = _legend_boxes(sheet)
            assert legend, kind
            others = _others(sheet)
            assert sum(what in ("line", "path") for what, _ in others) > 1, kind
            bad = [(what, box) for what, box in others for b in legend if _overlap(box, b)]
            assert not bad, (kind, float(cycle.phi_deg[i]), bad[:3])
