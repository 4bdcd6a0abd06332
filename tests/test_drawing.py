"""The drawing layer on arrays (issue 34 items 3-4): `draw.drawing(cycle)` computes every element
of a sheet at all N angles at once; `Drawing.svg(i)` writes the sheet of angle i (the page's
script writes the same from the same arrays); a one-angle sheet (`draw.svg`) is the N = 1 case.

At every angle of a cycle: the same elements as the one-angle sheet of that angle, moved as one
(one place of the plan on the sheet for the whole cycle), labels clear of labels, arrowheads and
points (a numeric check of the boxes here; in Chromium on a sample, every bundled model behind
`slow`), labels kept in place from angle to angle. Lettering widths are DejaVu Sans's own.
"""
from __future__ import annotations

import html
import re
import warnings

import numpy as np
import pytest

import kinetostat
from kinetostat.plans.core import ELEMENTS, Drawing, Element, PlanCycle, fixed
from kinetostat.plans.draw import drawing, svg
from kinetostat.plans.labels import ASCENT, DESCENT, Placer, text_width

import kinetostat.plans as P
import sheet_browser
from conftest import MODELS

ANGLES = (0.0, 30.0, 150.0, 250.0)          # 0: the ICE's dead centre (negligible vectors, R12t)


def cycles(mech, angles) -> dict[str, PlanCycle]:
    """Every plan of `mech` at `angles` (deg) from one analysis, at the cycle's scales."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = kinetostat.analyze(mech, phi_deg=np.asarray(angles, dtype=float))
        return P.build_cycle(mech, res, P.cycle_scales(mech, res=res))


@pytest.fixture(scope="module")
def ice_cycle():
    return cycles(kinetostat.load("ice_crank_slider"), ANGLES)


# ----------------------------------------------------------------------------- writing an angle

def test_an_element_is_written_as_the_page_writes_it():
    """The serialization the page's script follows: coordinates rint(1000 x) with 3 decimals,
    attrs in order, data-length-mm with 9 decimals, <title>, a text's variant; not drawn where NaN;
    a polyline through its finite points."""
    nan = np.nan
    d = Drawing("velocity", np.array([0.0, 90.0]), "<svg>\n" + ELEMENTS + "</svg>\n", (
        Element("line", [[[1.0625, -0.0004], [2.0, 3.0]], [[nan, 0.0], [1.0, 1.0]]], {"stroke": "#000"},
                title="p-b", length_mm=np.array([1.23456789012, 0.5])),
        Element("polyline", [[[0.0, 0.0], [nan, nan], [1.0, 2.0]]], {"fill": "none"}),
        Element("path", [[[0, 0], [1, 0], [0, 1]]], {"class": "arrowhead"}),
        Element("circle", [[[5.0, 6.0]], [[7.0, 8.0]]], {"r": "0.6"}),
        Element("g", [[[0.0, 0.0]], [[nan, nan]]], {"class": "negligible"}),
        Element("text", [[[-1.5, 2.25]]], {"class": "label"}, texts=("a", "b<tspan>1</tspan>"),
                variant=np.array([0, 1]))))
    assert d.svg(0) == ('<svg>\n<line x1="1.062" y1="0.000" x2="2.000" y2="3.000" stroke="#000" '
                        'data-length-mm="1.234567890"><title>p-b</title></line>\n'
                        '<polyline points="0.000,0.000 1.000,2.000" fill="none"></polyline>\n'
                        '<path d="M0.000,0.000 L1.000,0.000 L0.000,1.000 z" class="arrowhead"></path>\n'
                        '<circle cx="5.000" cy="6.000" r="0.6"></circle>\n<g class="negligible"></g>\n'
                        '<text x="-1.500" y="2.250" class="label">a</text>\n</svg>\n')
    assert d.svg(1) == ('<svg>\n<polyline points="0.000,0.000 1.000,2.000" fill="none"></polyline>\n'
                        '<path d="M0.000,0.000 L1.000,0.000 L0.000,1.000 z" class="arrowhead"></path>\n'
                        '<circle cx="7.000" cy="8.000" r="0.6"></circle>\n'
                        '<text x="-1.500" y="2.250" class="label">b<tspan>1</tspan></text>\n</svg>\n')
    assert [fixed(q, 3) for q in (-62, 5, 0, -1000, 123456)] == ["-0.062", "0.005", "0.000", "-1.000", "123.456"]
    with pytest.raises(IndexError, match="velocity: angle index 2"):
        d.svg(2)


# ----------------------------------------------------------------------------- a cycle's sheets

_SHAPES = re.compile(r'<(line|path|polyline|circle)( [^>]*)>')
_NUMS = re.compile(r'-?\d+\.\d+')


def _geometry(sheet: str) -> list[tuple[str, np.ndarray]]:
    """The plan's lines, arrowheads, polylines and dots (not the labels' leaders): (tag and
    attributes without numbers, coordinates)."""
    plan = sheet.split('<g id="plan"', 1)[1].split("</g>", 1)[0]
    out = []
    for tag, attrs in _SHAPES.findall(plan):
        if 'class="leader"' in attrs:
            continue
        coords = re.findall(r'(?:x1|y1|x2|y2|cx|cy|points|d)="([^"]*)"', attrs)
        rest = re.sub(r' (?:x1|y1|x2|y2|cx|cy|points|d)="[^"]*"', "", attrs)
        out.append((tag + rest, np.array([float(v) for c in coords for v in _NUMS.findall(c)])))
    return out


def test_each_angle_draws_the_plan_of_that_angle(ice_cycle):
    """At every angle of the cycle: the same lines, arrowheads, paths and dots as the one-angle
    sheet of that angle (`svg(cycle.at(i))`), all moved by one shift (the cycle's place on the
    sheet), and the title's φ that angle's: at the dead centre and at 150 deg."""
    for kind, cycle in ice_cycle.items():
        d = drawing(cycle, "uk")
        assert d.n == len(ANGLES)
        for i, at in ((0, 0.0), (2, 150.0)):
            got, want = _geometry(d.svg(i)), _geometry(svg(cycle.at(i), "uk", notes=False))
            assert [g[0] for g in got] == [w[0] for w in want], (kind, at)
            diff = np.concatenate([g[1] - w[1] for g, w in zip(got, want)]).reshape(-1, 2)
            assert np.ptp(diff, axis=0).max() <= 2.5e-3, (kind, at, np.ptp(diff, axis=0))
            assert f"φ = {at:g}°" in d.svg(i)


def test_one_angle_sheet_is_the_cycle_of_one(ice_cycle):
    """svg(plan) is drawing(PlanCycle.of(plan)) written, plus the notes: no second drawing code."""
    plan = ice_cycle["group:2,3"].at(1)
    one = drawing(PlanCycle.of(plan), "uk").svg(0)
    assert svg(plan, "uk", notes=False) == one
    with_notes = svg(plan, "uk")
    assert '<g id="notes">' in with_notes and re.sub(r'<g id="notes">.*?</g>\n', "", with_notes, flags=re.S) == one


# ----------------------------------------------------------------------------- labels

def _box(markup: str, x: float, y: float, size: float) -> tuple[float, float, float, float]:
    """A label's box from its markup at baseline (x, y): DejaVu Sans widths of its tspans, each at
    its own size and its baseline moved by its dy (a sub- or superscript)."""
    w, shift, top, below = 0.0, 0.0, -ASCENT * size, DESCENT * size
    for attrs, piece in re.findall(r"<tspan([^>]*)>([^<]*)</tspan>", markup):
        s = float(re.search(r'font-size="([0-9.]+)"', attrs).group(1)) if "font-size" in attrs else size
        shift += float(re.search(r'dy="(-?[0-9.]+)"', attrs).group(1)) if "dy=" in attrs else 0.0
        w += text_width(html.unescape(piece), s)
        top, below = min(top, shift - ASCENT * s), max(below, shift + DESCENT * s)
    return x, y + top, x + w, y + below


def clashes(d: Drawing, i: int, tol: float = 0.05) -> list[str]:
    """Labels of angle i over another label, an arrowhead or a point (by more than `tol` mm)."""
    labels, hard = [], []
    for e in d.elements:
        xy = e.xy[i if len(e.xy) > 1 else 0]
        if not np.isfinite(xy).all():
            continue
        if e.tag == "text" and e.attrs.get("class") in ("label", "name"):
            markup = e.texts[int(e.variant[i])]
            labels.append((re.sub("<[^>]+>", "", markup), _box(markup, *xy[0], float(e.attrs["font-size"]))))
        elif e.tag == "path":
            hard.append(("arrowhead", (*xy.min(axis=0), *xy.max(axis=0))))
        elif e.tag == "circle":
            r = float(e.attrs["r"])
            hard.append(("point", (xy[0, 0] - r, xy[0, 1] - r, xy[0, 0] + r, xy[0, 1] + r)))
    bad = []
    for k, (name, box) in enumerate(labels):
        bad += [f"{name!r} over {other!r}" for other, b in labels[k + 1:] if sheet_browser.overlap(box, b, tol)]
        bad += [f"{name!r} over a {what}" for what, b in hard if sheet_browser.overlap(box, b, tol)]
    return bad


def test_labels_are_clear_at_every_angle(ice_cycle):
    """No label over another label, an arrowhead or a point, at any angle of any plan of the ICE."""
    for kind, cycle in ice_cycle.items():
        d = drawing(cycle, "ru")
        for i in range(d.n):
            assert not clashes(d, i), (kind, ANGLES[i], clashes(d, i)[:5])


def test_a_crowded_label_beyond_the_room_finds_a_place_at_every_angle_of_a_page():
    """The rotating slotted link's lever over a page's 361 angles (labels searched at every
    STRIDE-th angle, kept between): near 285 deg its F_i5 and F_КО hang below the room, where
    only far rings are free; with rings out to 45 mm no place was free there and F_i5 lay over b
    (14 angles); rings out to 80 mm: no label over another, an arrowhead or a point anywhere."""
    mech = kinetostat.load("rotating_slotted_link")
    lever = cycles(mech, np.arange(0.0, 361.0))["lever"]
    d = drawing(lever, "en")
    bad = {i: clashes(d, i) for i in range(d.n)}
    assert not {i: b for i, b in bad.items() if b}


def test_the_numeric_check_finds_a_planted_clash(ice_cycle):
    """Negative control: a label moved onto another label at one angle is reported there only."""
    d = drawing(ice_cycle["velocity"], "uk")
    texts = [k for k, e in enumerate(d.elements) if e.tag == "text" and e.attrs.get("class") == "label"]
    a, b = d.elements[texts[0]], d.elements[texts[1]]
    xy = np.array(np.broadcast_to(a.xy, (d.n, 1, 2)))
    xy[2] = b.xy[2]
    moved = Element("text", xy, a.attrs, texts=a.texts, variant=a.variant)
    planted = Drawing(d.kind, d.phi_deg, d.static, d.elements[:texts[0]] + (moved,) + d.elements[texts[0] + 1:])
    assert clashes(planted, 2) and not clashes(planted, 1)


def test_labels_keep_their_place_from_angle_to_angle():
    """A label keeps one place beside its point over the angles where that place is free: on the
    ICE's velocity and acceleration plans every 5 deg, at least 90 % of the points' labels keep
    their offset between neighbouring angles (each angle's best place alone: 85 %)."""
    built = cycles(kinetostat.load("ice_crank_slider"), np.arange(0.0, 60.0, 5.0))
    kept = []
    for kind in ("velocity", "acceleration"):
        cycle = built[kind]
        for e in drawing(cycle, "uk").elements:
            if e.tag == "text" and e.attrs.get("class") == "label":
                name = re.sub("<[^>]+>", "", e.texts[0]).split(" ")[0]
                anchor = cycle.points["pi" if name == "π" else name]
                off = e.xy[:, 0] - np.column_stack([anchor.real, -anchor.imag])
                kept += list(np.hypot(*np.diff(off, axis=0).T) < 1e-6)
    assert len(kept) > 80 and np.mean(kept) >= 0.9, np.mean(kept)


def test_text_widths_are_dejavu_sans_advances():
    """The table of advance widths is DejaVu Sans's, as matplotlib's FT2Font reads the font it ships."""
    ft = pytest.importorskip("matplotlib.ft2font")
    import os

    import matplotlib

    from kinetostat.plans.dejavu import ADVANCES, EM
    font = ft.FT2Font(os.path.join(matplotlib.get_data_path(), "fonts", "ttf", "DejaVuSans.ttf"))
    flag = ft.LoadFlags.NO_SCALE if hasattr(ft, "LoadFlags") else ft.LOAD_NO_SCALING
    assert font.units_per_EM == EM
    for start, adv in ADVANCES.items():
        real = [font.load_char(c, flags=flag).horiAdvance if font.get_char_index(c) else 0
                for c in range(start, start + len(adv))]
        assert list(adv) == real, hex(start)
    assert text_width("Ж", 10.0) == pytest.approx(10.0 * 2206 / 2048)
    assert text_width("\U0001F600", 2.0) == 2.0          # no glyph: an em


def test_placer_clips_lines_exactly():
    """The placer's lines are segments clipped to each box (no samples): a line crossing a
    candidate's corner by a hair costs a hair; a label is placed off a line through its anchor."""
    from kinetostat.plans.labels import _clipped
    box = np.array([0.0, 0.0, 2.0, 1.0])
    assert _clipped(np.array([-1.0, 0.5, 3.0, 0.5]), box) == pytest.approx(2.0)
    assert _clipped(np.array([1.8, -0.1, 2.1, 0.2]), box) == pytest.approx(np.hypot(0.1, 0.1), rel=1e-9)
    assert _clipped(np.array([0.0, 0.0, 2.0, 0.0]), box) == 0.0                   # along an edge: not inside
    assert _clipped(np.array([1.0, 0.2, 1.0, 0.2]), box) == 0.0                   # a point
    placer = Placer(2, (0.0, 0.0, 100.0, 100.0))
    placer.line(np.array([[0.0, 50.0, 100.0, 50.0], [50.0, 0.0, 50.0, 100.0]]))
    pl = placer.place(("A",), np.zeros(2, dtype=int), 3.5, np.array([[50.0, 50.0], [50.0, 50.0]]))
    assert _clipped(np.array([0.0, 50.0, 100.0, 50.0]), pl.box[0]) == 0.0
    assert _clipped(np.array([50.0, 0.0, 50.0, 100.0]), pl.box[1]) == 0.0


# ----------------------------------------------------------------------------- in Chromium

@pytest.fixture(scope="module")
def page(chromium):
    return chromium.new_page()


def _browser_check(page, d: Drawing, angles) -> int:
    n = 0
    for i in angles:
        items = sheet_browser.measure(page, d.svg(i))
        bad = sheet_browser.overlaps(items)
        assert not bad, (d.kind, float(d.phi_deg[i]), bad[:5])
        n += sum(t["tag"] == "text" for t in items)
    return n


def test_cycle_sheets_do_not_overprint_in_chromium(page, ice_cycle):
    """The ICE's group plan and lever at the dead centre and at 150 deg, as Chromium sets them."""
    for kind in ("group:2,3", "lever"):
        assert _browser_check(page, drawing(ice_cycle[kind], "ru"), (0, 2)) > 20


@pytest.mark.slow
@pytest.mark.parametrize("path", MODELS, ids=[p.stem for p in MODELS])
def test_every_model_over_24_angles_in_chromium(page, path):
    """Every bundled model, every plan, a cycle of 24 angles (every 15 deg), each angle's sheet
    measured in Chromium: no label over a label or an arrowhead."""
    for kind, cycle in cycles(kinetostat.load(path), np.arange(0.0, 360.0, 15.0)).items():
        d = drawing(cycle, "uk")
        for i in range(d.n):
            assert not clashes(d, i), (path.stem, kind, float(d.phi_deg[i]), clashes(d, i)[:5])
        _browser_check(page, d, range(d.n))
