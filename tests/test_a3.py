"""The one A3 sheet of plans (`kinetostat.plans.a3`): every variant's plans on ONE sheet, true to
scale, boxes apart and clear of the title block; the scales chosen together for that sheet only
where the texts' do not fit it (μ_l last), named in the key and on the sheet; and the same scales
in every file of the pack, down to a length measured in the PDF."""
from __future__ import annotations

import base64
import re
import shutil
import subprocess
import warnings
import zlib
from dataclasses import dataclass
from functools import lru_cache
from unittest import mock

import numpy as np
import pytest

import kinetostat
from kinetostat import variants
from kinetostat.plans import a3 as A3
from kinetostat.plans import pack as P
from kinetostat.plans.drawing_error import Scales, simulate
from kinetostat.plans.draw import scale_text
from kinetostat.plans.i18n import text
from kinetostat.plans.scales import LENGTH_MANTISSAS, ROUND_MANTISSAS, next_coarser

needs_poppler = pytest.mark.skipif(shutil.which("pdftotext") is None, reason="poppler's pdftotext not installed")
PT = 72.0 / 25.4                                       # points per mm


def _one(task: int, code: str, lang: str = "en") -> A3.OneSheet:
    """`one_sheet` of variant task/code at phi1 in `lang`, made once per module (a sheet's search
    takes seconds; `_sheet`, its arguments spelt one way for its cache); those of _COUNTED are the
    ones `_counted` made."""
    return _counted(task, code, lang).one if (task, code, lang) in _COUNTED else _sheet(task, code, lang)


@lru_cache(maxsize=None)
def _sheet(task: int, code: str, lang: str) -> A3.OneSheet:
    v = variants.variant(task, code)
    return A3.one_sheet(v.mechanism(), float(v.values["phi1"]), lang)


@dataclass(frozen=True)
class Counted:
    """A sheet and the work `one_sheet` did for it: the scales of each build of the plans (None:
    the rule's), the positions given to each build, and each plan drawn (language, kind, scales)."""
    one: A3.OneSheet
    built: tuple
    positions: tuple
    drawn: tuple


#: The sheets `_counted` makes: task 2 / 479 in English (its search comes back to scales tried
#: before), task 1 / 479 in Ukrainian (its search steps back to the rule's scales).
_COUNTED = ((2, "479", "en"), (1, "479", "uk"))


@lru_cache(maxsize=None)
def _counted(task: int = 2, code: str = "479", lang: str = "en") -> Counted:
    """The sheet of variant task/code in `lang` (_COUNTED), its builds of the plans and its
    drawings counted (`kinetostat.plans.build` and `a3.sheet` wrapped while it runs)."""
    import kinetostat.plans as KP
    built, drawn, positions = [], [], []
    build, sheet = KP.build, A3.sheet

    def counted(mech, at, scales=None, **kw):
        built.append(None if scales is None else tuple(sorted(scales.items())))
        positions.append(kw.get("positions"))
        return build(mech, at=at, scales=scales, **kw)
    v = variants.variant(task, code)
    with mock.patch.object(KP, "build", counted), mock.patch.object(A3, "sheet", lambda plan, lang, *a, **kw: drawn.append(
            (lang, plan.kind, tuple(s.value for s in A3.scales_of(plan)))) or sheet(plan, lang, *a, **kw)):
        one = A3.one_sheet(v.mechanism(), float(v.values["phi1"]), lang)
    return Counted(one, tuple(built), tuple(positions), tuple(drawn))


def _room(one: A3.OneSheet, plans, lang: str) -> float:
    """The notes' room above the title block of `plans` on `one`'s sheet in `lang`, in the texts' order."""
    return A3.notes_mm(len(A3.note_lines(A3._notes(plans.scales, one.rule, one.reference, True, lang))))


def _check_sheet(one: A3.OneSheet) -> None:
    """One page; every plan's box (drawing with its heading) inside AREA, clear of the title block
    and of every other box."""
    assert {p.page for p in one.places} == {0}
    boxes = []
    for d, p in zip(one.drawings, one.places):
        w, h, top = A3._size(d)
        x0, y0 = d.box[0] + p.dx, d.box[1] + p.dy - top
        x1, y1 = x0 + w, y0 + h
        assert A3.AREA[0] - 1e-9 <= x0 and x1 <= A3.AREA[2] + 1e-9 and A3.AREA[1] - 1e-9 <= y0 and y1 <= A3.AREA[3] + 1e-9, d.kind
        assert x1 <= A3.TITLE_BLOCK[0] or y1 <= A3.TITLE_BLOCK[1] - A3.notes_room(one), d.kind
        for kind, b in boxes:
            assert x1 <= b[0] or b[2] <= x0 or y1 <= b[1] or b[3] <= y0, (d.kind, kind)
        boxes.append((d.kind, (x0, y0, x1, y1)))
    assert len(boxes) == len(one.plans)


def _round(value: float, mantissas) -> bool:
    m = value / 10.0 ** np.floor(np.log10(value))
    return any(np.isclose(m, x) for x in mantissas)


def test_task_1_479_fits_one_sheet_in_the_texts_order():
    """The shelf packer put the lever on a second sheet: now all 8 plans on one, in the texts' order,
    μ_l and μ_a the rule's (OA 32 mm). At the rule's μ_v = 0.25, μ_F = 40 no layout in the texts'
    order exists (the lever, its arms dimension lines, 118 x 77 mm; the force polygon 206 mm tall
    with its construction): `one_sheet` coarsens μ_v to 0.4 (pa 53 mm) and μ_F to 50 (R12 140 mm,
    within the guide's 100-200) rather than pack out of order (main packed at μ_v 0.4, μ_F 40)."""
    one = _one(1, "479", "uk")
    assert len(one.plans) == 8
    _check_sheet(one)
    assert {c.symbol: c.value for _, c, _ in one.coarsened()} == {"mu_v": 0.4, "mu_F": 50.0}
    assert A3.placed_in_order(one.drawings, one.places)
    assert one.plans["mechanism"].length_mm("OA") == pytest.approx(32.0)


@pytest.mark.parametrize("task, code", [(1, "479"), pytest.param(3, "388", marks=pytest.mark.slow)])
def test_the_scales_do_not_depend_on_the_language(task, code):
    """Task 3 / 388 fitted at μ_l = 0.0025 with English headings and labels, at 0.004 with Ukrainian
    ones; task 1 / 479 (the sheets other tests build) at μ_v = 0.25, μ_F = 50 in English, μ_v = 0.4,
    μ_F = 40 in Ukrainian: the scales are chosen to fit in every language, so each pack of a variant
    states the same."""
    en, uk = _one(task, code, "en"), _one(task, code, "uk")
    assert dict(en.plans.scales) == dict(uk.plans.scales)
    _check_sheet(en)
    _check_sheet(uk)


@pytest.mark.parametrize("task, code", [(1, "479"), (2, "479"),    # the sheets other tests build
                                         *(pytest.param(t, c, marks=pytest.mark.slow) for t, c in ((3, "123"), (1, "905")))])
def test_a_sample_of_variants_fits_one_sheet(task, code):
    """Task 2 / 479 took 3 sheets (138,000 mm² of plans at the rule's scales), 3 / 123 two: each
    on one now; a coarsened scale is a round value of its series, one step or more above the
    rule's, its reference (pa, πa, the largest force) at least FLOOR_MM long."""
    one = _one(task, code)
    _check_sheet(one)
    for rule, chosen, mm in one.coarsened():
        assert chosen.value > rule.value
        assert _round(chosen.value, LENGTH_MANTISSAS if chosen.symbol == "mu_l" else ROUND_MANTISSAS), chosen
        assert mm == pytest.approx(one.reference[chosen.symbol] / chosen.value)
        if chosen.symbol in A3.FIRST:
            assert mm >= A3.FLOOR_MM[chosen.symbol]


def test_mu_l_is_coarsened_only_where_the_others_cannot_make_room():
    """Task 2 / 479: its mechanism and positions plans are 322 mm wide at the rule's μ_l = 0.0012;
    with the velocity, acceleration and force scales at their floor they still take two sheets (in
    a language of the pack) at μ_l one step finer than the chosen one (0.0015), so μ_l = 0.002
    (OA 19 mm) is the finest that fits; and each other coarsened scale one step finer does not fit."""
    one = _one(2, "479")
    mu_l = one.plans.scales["mu_l"].value
    assert one.rule["mu_l"].value == pytest.approx(0.0012) and mu_l == pytest.approx(0.002)
    floor = {}
    for k in A3.FIRST:
        floor[k] = one.rule[k].value
        while one.reference[k] / next_coarser(floor[k]) >= A3.FLOOR_MM[k]:
            floor[k] = next_coarser(floor[k])
    mech = one.plans.mech
    plans = kinetostat.plans.build(mech, at=one.plans.at, scales={"mu_l": 0.0015, **floor})
    assert any(max(p.page for p in A3.layout([A3.drawing(plans[k], lang) for k in plans], _room(one, plans, lang))) >= 1
               for lang in ("en", "uk", "ru"))
    for rule, chosen, _ in one.coarsened():
        if chosen.symbol in A3.FIRST:
            finer = max(v for v in (rule.value, *(m * 10.0 ** e for e in range(-4, 5) for m in ROUND_MANTISSAS))
                        if v < chosen.value * (1 - 1e-9))
            given = {k: s.value for k, s in one.plans.scales.items()} | {chosen.symbol: finer}
            plans = kinetostat.plans.build(mech, at=one.plans.at, scales=given)
            assert any(max(p.page for p in A3.layout([A3.drawing(plans[k], lang) for k in plans], _room(one, plans, lang))) >= 1
                       for lang in ("en", "uk", "ru")), chosen


def test_each_scale_choice_is_built_and_drawn_once():
    """Task 2 / 479 (its search comes back to scales tried before): `one_sheet` builds the plans of
    each choice of scales once (was: 9 builds for 8 choices) and draws each plan once at its
    scales for all the languages that draw it alike (`draw.language_part`: was once a language:
    the velocity plan, lettered the same in all three, drawn three times; a group plan, whose
    guide is lettered in each language, is drawn again in the others; the velocity plan in uk, whose
    construction lines' tooltips differ from en's but whose letters and notes' room do not, is
    en's drawing: was drawn again); every build after the
    rule's is given the plan of positions' 12 positions at its μ_l, made once per μ_l (was: made
    again in each build). (The same sheet as a call not counted: test_write_key_draws_every_file_at_the_one_sheets_scales.)"""
    c = _counted()
    built, drawn = c.built, c.drawn
    assert len(built) == len(set(built)) >= 5
    assert len(drawn) == len(set(drawn)) and {lang for lang, _, _ in drawn} == {"en", "uk", "ru"}
    again = {kind for lang, kind, _ in drawn if lang != "en"}
    assert "group:2,3" in again and not any(lang == "uk" and kind == "velocity" for lang, kind, _ in drawn)
    given = c.positions[1:]
    assert all(p is not None and p.mu.value == dict(b)["mu_l"] for p, b in zip(given, built[1:]))
    assert len({id(p) for p in given}) == len({p.mu.value for p in given}) < len(given)


def test_the_rules_scales_given_are_the_rules_try():
    """Task 1 / 479 in Ukrainian: its search steps back to the rule's scales (μ_v 0.25 with μ_F
    40); that try is the rule's own, its plans not built again (was: built and laid out again)."""
    c = _counted(1, "479", "uk")
    rule = tuple(sorted((k, s.value) for k, s in c.one.rule.items()))
    assert c.built[0] is None and rule not in c.built
    assert len(c.built) == len(set(c.built)) >= 4


def test_a_plans_drawing_is_its_sheets_plan_group_as_written():
    """`drawing` reads the plan group of the plan's sheet from its elements (no SVG text written and
    parsed back): the same lines (ends to 0.001 mm, as the SVG writes them; each named by its
    tooltip, a guide in the sheet's language), arrowheads, points and labels (their tspans) as the
    plan group of the sheet's SVG."""
    import xml.etree.ElementTree as ET
    from kinetostat.plans.draw import svg
    ns = "{http://www.w3.org/2000/svg}"
    plan = _one(1, "479").plans["group:2,3"]
    d = A3.drawing(plan, "uk")
    group = next(g for g in ET.fromstring(svg(plan, "uk", notes=False)).iter(f"{ns}g") if g.get("id") == "plan")
    lines = [(*(float(el.get(k)) for k in ("x1", "y1", "x2", "y2")), el.findtext(f"{ns}title") or "")
             for el in group.iter(f"{ns}line")]
    assert [(*ln[:4], ln[7]) for ln in d.lines] == lines and any(ln[4] == "напрямна 4-3" for ln in lines)
    assert [(x, y, tuple(r[0] for r in runs)) for x, y, runs in d.texts] == [
        (float(el.get("x")), float(el.get("y")), tuple(t.text for t in el.iter(f"{ns}tspan")))
        for el in group.iter(f"{ns}text")]
    assert len(d.polygons) == len(group.findall(f"{ns}path")) and len(d.dots) == len(group.findall(f"{ns}circle"))


def test_the_plans_sheets_are_the_one_sheets_drawn_ones(tmp_path):
    """The key's plans are written from the sheets `one_sheet` drew in its language (`OneSheet.sheets`,
    not drawn again): the same files as `Plans.write` draws them, title block and notes included."""
    one = _one(1, "479", "uk")
    shared = one.plans.write(tmp_path / "shared", "uk", sheets=one.sheets)
    drawn = one.plans.write(tmp_path / "drawn", "uk")
    assert len(shared) == len(one.plans) + 1
    assert [p.read_bytes() for p in shared] == [p.read_bytes() for p in drawn]


def test_the_packer_counts_its_work():
    """The layout tries the texts' order by each of READING, each placing every plan once at most;
    depth first, IN_ORDER_TRIES corners at most; task 2 / 479 fits so, and nothing is packed."""
    one = _one(2, "479")
    calls = {"_place": [], "_place_after": []}
    saved = {k: getattr(A3, k) for k in calls}

    def counted(k):
        return lambda *a: calls[k].append(1) or saved[k](*a)
    try:
        for k in calls:
            setattr(A3, k, counted(k))
        A3.layout(list(one.drawings), A3.notes_room(one))
    finally:
        for k, f in saved.items():
            setattr(A3, k, f)
    n = len(one.drawings)
    assert 0 < len(calls["_place_after"]) <= len(A3.READING) * (A3.IN_ORDER_TRIES + n)
    assert len(calls["_place"]) == 0                  # it fits in the texts' order: nothing packed


def _pdf_lines(pdf: bytes) -> list[tuple[float, float, float, float]]:
    """Every straight segment "x0 y0 m x1 y1 l" of the PDF's content streams (Flate, or ASCII85
    then Flate, as reportlab writes them), mm from the top left."""
    out = []
    for head, raw in re.findall(rb"<<([^>]*)>>\s*stream\r?\n(.*?)\r?\n?endstream", pdf, re.S):
        try:
            if b"ASCII85Decode" in head:
                raw = base64.a85decode(raw.strip().removeprefix(b"<~").removesuffix(b"~>"))
            body = zlib.decompress(raw).decode("latin-1")
        except (zlib.error, ValueError):
            continue
        for m in re.finditer(r"(-?[\d.]+) (-?[\d.]+) m\s+(-?[\d.]+) (-?[\d.]+) l", body):
            x0, y0, x1, y1 = (float(v) / PT for v in m.groups())
            out.append((x0, 297.0 - y0, x1, 297.0 - y1))
    return out


@pytest.fixture(scope="module")
def task2_pack():
    """Task 2 / 479 in English, its bands from 20 draws (the scales are what is tested)."""
    return P.pack(variants.variant(2, "479"), lang="en", a3=_one(2, "479"), draws=20)


@pytest.fixture(scope="module")
def task2_pdf(task2_pack, tmp_path_factory):
    """Its plans_a3.pdf, as `Pack.write` writes it."""
    path = tmp_path_factory.mktemp("a3") / "plans_a3.pdf"
    path.write_bytes(P._plans_pdf(task2_pack.a3, "t"))
    return path


def test_the_key_length_is_the_length_in_the_pdf(task2_pack, task2_pdf):
    """OA of task 2 / 479 at the one sheet's μ_l = 0.002: the key's segment length (19 mm) is the
    line OA found in the PDF's content stream (the page A3, 1 mm = 1 mm) to 0.01 mm, where the
    page (`A3.pages`) put it; the key and the title block say why μ_l is not the rule's 0.0012."""
    p = task2_pack
    pdf = task2_pdf.read_bytes()
    boxes = re.findall(rb"/MediaBox \[ 0 0 ([\d.]+) ([\d.]+) \]", pdf)
    assert len(boxes) == 1 and [float(v) / PT for v in boxes[0]] == pytest.approx([420.0, 297.0])    # one A3 page
    key_rows = [r for kind, x in p.key if kind == "table" and x.head[2:3] == ("Length, mm",) for r in x.rows]
    oa = next(r for r in key_rows if r[1] == "OA" and r[0].startswith("Mechanism"))
    assert float(oa[2]) == pytest.approx(19.0) and oa[3] == "μ_l = 0.002 m/mm"
    (page,) = A3.pages(p.a3, "t")
    ends = np.reshape(next(ln[:4] for ln in page.lines if ln[7] == "mechanism/OA"), (2, 2))
    found = [s for s in _pdf_lines(pdf) if np.allclose(s, ends.ravel(), atol=0.01)
             or np.allclose(s, ends[::-1].ravel(), atol=0.01)]
    assert found, ends
    x0, y0, x1, y1 = found[0]
    assert np.hypot(x1 - x0, y1 - y0) == pytest.approx(p.plans["mechanism"].length_mm("OA"), abs=0.01)
    assert np.hypot(x1 - x0, y1 - y0) == pytest.approx(float(oa[2]), abs=0.05)      # as the key prints it
    (note,) = [x for kind, x in p.key if kind == "p" and "instead of the rule's" in x]
    assert note.startswith("Scales coarser than the text's rule, so that all the plans fit one A3 sheet")
    assert "μ_l = 0.002 m/mm instead of the rule's 0.0012, OA drawn 19.0 mm, not the recommended 30–36 mm" in note
    assert note.count("instead of the rule's") == len(p.a3.coarsened()) >= 2


@needs_poppler
def test_the_sheet_names_the_coarsened_scales(task2_pdf):
    info = subprocess.run(["pdfinfo", str(task2_pdf)], capture_output=True, text=True, check=True).stdout
    assert re.search(r"Pages:\s+1\n", info)
    page = " ".join(subprocess.run(["pdftotext", str(task2_pdf), "-"], capture_output=True,
                                   text=True, check=True).stdout.split())
    assert "Scales coarser than the text's rule, so that all the plans fit this one sheet" in page
    assert "μl = 0.002 m/mm (rule: 0.0012)" in page                                   # μ_l: l set below


def test_the_bands_are_drawn_at_the_one_sheets_scales(task2_pack):
    """The key's bands are the drawing-error study at the one sheet's scales (μ_l = 0.002, μ_F = 100:
    coarser than the rule's, so wider), its scales table those scales."""
    p = task2_pack
    sc = p.plans.scales
    drawn = simulate(p.plans.mech, at=p.plans.at, n=20, seed=0,
                     scales=Scales(*(sc[k].value for k in ("mu_l", "mu_v", "mu_a", "mu_F"))))
    for k, (lo, hi) in p.bands.items():
        assert (lo, hi) == pytest.approx(tuple(np.percentile(drawn.samples[k], P.BAND))), k
    scales = next(x for kind, x in p.key if kind == "table" and x.rows[0][0] == "μ_l")
    # μ_v, μ_a coarser than the rule's: GOST 2.304's 3.5 mm lettering, the title block and the lever's arms take room
    # (μ_a 250, was 200 before labels crowding round a point went out on leaders: the acceleration plan's box grew)
    assert {r[0]: r[1] for r in scales.rows} == {"μ_l": "0.002", "μ_v": "0.4", "μ_a": "250", "μ_F": "100"}


def test_write_key_draws_every_file_at_the_one_sheets_scales(tmp_path, monkeypatch):
    """`write_key` chooses the scales once (`one_sheet`) and hands them to the SVG sheets, the
    worksheet and the pack: task 2 / 479's mechanism sheet and worksheet at μ_l = 0.002, not the
    rule's 0.0012 (which the keys without a pack keep); its sheet is the one `_counted` made (no
    state kept between calls of `one_sheet`)."""
    got = []

    class Fake:                                        # the pack itself: the tests above
        def write(self, out):
            return []
    monkeypatch.setattr(P, "pack", lambda v, lang, a3=None, solution=None: got.append(a3) or Fake())
    v = variants.variant(2, "479")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        variants.write_key(v, tmp_path / "pack", lang="en", cycle_csv=False)
        variants.write_key(v, tmp_path / "rule", lang="en", cycle_csv=False, teacher_pack=False)
    (one,) = got
    assert scale_text(one.plans.scales["mu_l"], "en") == "μ_l = 0.002 m/mm" and one.lang == "en"
    assert one.places == _one(2, "479").places and one.drawings == _one(2, "479").drawings    # no state kept between calls
    for folder, mu_l in (("pack", "μ_l = 0.002 m/mm"), ("rule", "μ_l = 0.0012 m/mm")):
        assert mu_l in (tmp_path / folder / "mechanism.svg").read_text(encoding="utf-8")
        assert f"scale {mu_l}" in (tmp_path / folder / "worksheet.md").read_text(encoding="utf-8")
    mu_a = scale_text(one.plans.scales["mu_a"], "en")
    assert mu_a == "μ_a = 250 m/(s²·mm)" and mu_a in (tmp_path / "pack" / "acceleration.svg").read_text(encoding="utf-8")


@pytest.mark.slow
@pytest.mark.parametrize("task, hundred", [(t, h) for t in sorted(variants.TASKS) for h in range(10)])
def test_every_variant_fits_one_sheet(task, hundred):
    """All 1000 codes of each task, a hundred a test (each under the 300 s timeout): one sheet,
    boxes apart and clear of the title block."""
    for code in variants.codes()[100 * hundred:100 * (hundred + 1)]:
        v = variants.variant(task, code)
        _check_sheet(A3.one_sheet(v.mechanism(), float(v.values["phi1"]), "uk"))


def _boxes(one: A3.OneSheet) -> dict[str, tuple[float, float, float, float]]:
    """Each plan's box on the page (drawing with its heading), mm."""
    out = {}
    for d, p in zip(one.drawings, one.places):
        w, h, top = A3._size(d)
        x0, y0 = d.box[0] + p.dx, d.box[1] + p.dy - top
        out[d.kind] = (x0, y0, x0 + w, y0 + h)
    return out


def _reads_after(b, a) -> bool:
    return b[0] >= a[2] - 1e-6 or b[1] >= a[3] - 1e-6


def test_the_plans_read_in_the_texts_order():
    """Task 1 / 479 (was: the force polygon top left, the velocity plan at the bottom, packed):
    seed 002's figures 1.5-1.12 in turn, each plan right of or below every plan before it: the
    plan of positions top left, the mechanism, velocities, accelerations, the group plan, its force
    polygon, the crank, the lever; the boxes apart and clear of the title block and its notes."""
    one = _one(1, "479", "uk")
    _check_sheet(one)
    b = _boxes(one)
    texts = ["positions", "mechanism", "velocity", "acceleration", "group:2,3", "forces:2,3", "crank", "lever"]
    assert sorted(b) == sorted(texts)
    assert b["positions"][:2] == pytest.approx((A3.AREA[0], A3.AREA[1]))            # top left
    for i, later in enumerate(texts):
        for before in texts[:i]:
            assert _reads_after(b[later], b[before]), (later, before)
    assert b["forces:2,3"][0] >= b["positions"][2]
    (page,) = A3.pages(one, "t")
    assert text("a3.packed", "uk") not in {s for _, _, s, _, _ in page.texts}


def test_the_texts_order_puts_the_last_attached_group_first():
    """Seed 000: the force analysis starts at the last attached group (4-5), each group's plan
    before its force polygon; the crank and the lever after them; unknown kinds last."""
    kinds = ["lever", "forces:2,3", "group:2,3", "forces:4,5", "group:4,5", "crank", "acceleration", "velocity",
             "mechanism", "positions", "detail"]
    assert sorted(kinds, key=A3.texts_rank) == ["positions", "mechanism", "velocity", "acceleration", "group:4,5",
                                                "forces:4,5", "group:2,3", "forces:2,3", "crank", "lever", "detail"]


def test_a_sheet_packed_out_of_the_texts_order_says_so(monkeypatch):
    """Task 2 / 479's ten plans packed (as `layout` packs where no order of READING fits; the
    greedy found none for it before the depth-first search): one sheet, apart, and the notes
    above the title block say so."""
    room = A3.notes_mm(len(A3.note_lines(A3.notes(_one(2, "479"), False, "en"))))
    packed = A3.layout(list(_one(2, "479").drawings), room)
    monkeypatch.setattr(A3, "READING", ())
    from dataclasses import replace
    one = replace(_one(2, "479"), places=tuple(A3.layout(list(_one(2, "479").drawings), room)))
    assert A3.placed_in_order(_one(2, "479").drawings, packed)
    b = _boxes(one)
    assert not A3.in_texts_order(list(b), list(b.values()))
    page = A3.pages(one, "t")[0]
    notes = " ".join(s for x, y, s, size, _ in page.texts if x == A3.TITLE_BLOCK[0] + 1.0 and size == 2.5)
    assert "Packed to fit: in the texts' order the plans do not fit this sheet" in notes


def _in_cell(page: A3.Page, cell: tuple) -> list[str]:
    """The texts whose start lies in `cell` (x0, y0, x1, y1 mm from the title block's top left)."""
    bx, by = A3.TITLE_BLOCK[:2]
    return [s for x, y, s, _, _ in page.texts if bx + cell[0] < x < bx + cell[2] and by + cell[1] < y < by + cell[3]]


def test_the_title_block_of_gost_2_104():
    """Bottom right, 185 x 55 mm (GOST 2.104 form 1): its roles, headers and graphs named in the
    sheet's language; the designation the sheet's title, the name the mechanism's; the scale μ_l =
    0.0015 m/mm as 1:1,5; sheet 1 of 1; the names, signatures and dates blank for the student and
    the teacher; the notes above it within its width, clear of the plans."""
    one = _one(1, "479", "uk")
    (page,) = A3.pages(one, "Плани механізму: Завдання 1")
    rules = [ln for ln in page.lines if ln[7] == "title-block"]
    xs, ys = [v for ln in rules for v in ln[0:4:2]], [v for ln in rules for v in ln[1:4:2]]
    assert (min(xs), min(ys), max(xs), max(ys)) == pytest.approx((230.0, 237.0, 415.0, 292.0))
    assert (max(xs) - min(xs), max(ys) - min(ys)) == pytest.approx((185.0, 55.0))
    cell = {"Зм.": (0, 20, 7, 25), "Арк.": (7, 20, 17, 25), "№ докум.": (17, 20, 40, 25), "Підпис": (40, 20, 55, 25),
            "Дата": (55, 20, 65, 25), "Розроб.": (0, 25, 17, 30), "Перев.": (0, 30, 17, 35), "Т.контр.": (0, 35, 17, 40),
            "Н.контр.": (0, 45, 17, 50), "Затв.": (0, 50, 17, 55), "Літ.": (135, 15, 150, 20), "Маса": (150, 15, 167, 20),
            "Масштаб": (167, 15, 185, 20), "Аркуш": (135, 35, 155, 40), "Аркушів": (155, 35, 185, 40)}
    for label, box in cell.items():
        assert label in _in_cell(page, box), label
    assert _in_cell(page, (167, 20, 185, 35)) == ["1:1,5"]
    assert _in_cell(page, (135, 35, 155, 40)) == ["Аркуш", "1"] and _in_cell(page, (155, 35, 185, 40)) == ["Аркушів", "1"]
    assert " ".join(_in_cell(page, (65, 0, 185, 15))) == "Плани механізму: Завдання 1"
    assert " ".join(_in_cell(page, (65, 15, 135, 40))).startswith("Кривошипно-повзунний механізм двотактного ДВЗ")
    assert _in_cell(page, (17, 0, 65, 20)) == [] and _in_cell(page, (17, 25, 65, 55)) == []      # for the hand
    tb = A3.TITLE_BLOCK
    notes = [(x, y, s, size) for x, y, s, size, _ in page.texts if x == tb[0] + 1.0 and y < tb[1]]
    assert notes and all(tb[1] - A3.notes_room(one) < y < tb[1] and A3._width(s, size) <= tb[2] - tb[0] for x, y, s, size in notes)
    for x0, y0, x1, y1 in _boxes(one).values():
        assert x1 <= tb[0] or y1 <= tb[1] - A3.notes_room(one)


def test_the_notes_take_the_room_of_their_lines():
    """The notes above the title block take the height of their lines (was: 20 mm whatever their
    number): on 1/479's sheet five lines of 2.5 mm type 3.1 mm apart, the last 1.5 mm above the
    block, 16.2 mm from the first line's ascent; the plans laid out clear of that room, and a
    drawing across the sheet that fits above five lines' notes, not above 20 mm, is placed."""
    one = _one(1, "479", "uk")
    (page,) = A3.pages(one, "t")
    tb = A3.TITLE_BLOCK
    notes = [(y, size) for x, y, s, size, _ in page.texts if x == tb[0] + 1.0 and y < tb[1]]
    top = min(y - A3.ASCENT * size for y, size in notes)
    assert len(notes) == 5 and tb[1] - top == pytest.approx(A3.notes_room(one)) == pytest.approx(1.5 + 4 * 3.1 + 0.93 * 2.5)
    assert A3.layout(list(one.drawings), A3.notes_room(one)) == list(one.places)
    from dataclasses import replace
    probe = A3.Drawing("positions", ("", ""), (), (), (), (), (), (0.0, 0.0, 380.0, 0.0))
    wide = replace(probe, box=(0.0, 0.0, 380.0, 204.0 - A3._size(probe)[1]))    # 204 mm with its heading
    small = replace(probe, kind="lever", box=(0.0, 0.0, 20.0, 20.0))
    assert [max(p.page for p in A3.layout([wide, small], room)) for room in (A3.notes_room(one), 20.0)] == [0, 1]


@pytest.mark.parametrize("mu_l, lang, ratio", [(0.0015, "uk", "1:1,5"), (0.0015, "en", "1:1.5"), (0.001, "en", "1:1"),
                                               (0.004, "ru", "1:4"), (0.0005, "en", "2:1"), (0.0012, "uk", "1:1,2")])
def test_mu_l_as_gost_writes_a_scale(mu_l, lang, ratio):
    """1 mm drawn is μ_l x 1000 mm of the mechanism: 0.0015 m/mm is a reduction 1:1.5 (not 1:15)."""
    assert A3.scale_ratio(mu_l, lang) == ratio


def test_the_notes_state_the_scales_and_their_departures():
    """Task 1 / 479 at the rule: every scale, μ_l with its ratio; OA (32 mm) within 30-36 mm is no
    departure, πa (92.9 mm) beyond 70-90 mm is. Task 2 / 479 made coarser: OA 19.0 mm (l_OA /
    μ_l, measured on its mechanism plan) is stated with the recommended range."""
    one = _one(1, "479", "en")
    notes = A3.notes(one, True, "en")
    assert notes[1] == "Scales: μ_l = 0.0015 m/mm (1:1.5); μ_v = 0.4 m/(s·mm); μ_a = 100 m/(s²·mm); μ_F = 50 N/mm"
    pi_a = one.reference["mu_a"] / 100.0
    (departs,) = [s for s in notes if s.startswith("Outside the guide's recommended lengths: ")]
    assert f"πa {pi_a:.1f} mm (70–90)" in departs and "OA" not in departs and pi_a > 90
    two = _one(2, "479")
    oa = two.plans["mechanism"].length_mm("OA")
    (departs,) = [s for s in A3.notes(two, False, "en") if s.startswith("Outside")]
    assert f"OA {oa:.1f} mm (30–36)" in departs and round(oa) == 19


def test_free_rectangles_split_around_a_box_stay_maximal():
    """`_split` (maximal rectangles): a box inside a free rectangle leaves the four rectangles
    beside it; a piece inside another rectangle (another's piece, or one the box does not meet) is
    dropped; the rectangles the box does not meet stay as they are."""
    free = [(0.0, 0.0, 10.0, 10.0)]
    A3._split(free, (2.0, 2.0, 4.0, 4.0))
    assert free == [(0.0, 0.0, 2.0, 10.0), (4.0, 0.0, 10.0, 10.0), (0.0, 0.0, 10.0, 2.0), (0.0, 4.0, 10.0, 10.0)]
    free = [(0.0, 0.0, 10.0, 10.0), (0.0, 0.0, 20.0, 3.0), (0.0, 0.0, 2.0, 20.0)]
    A3._split(free, (2.0, 2.0, 4.0, 6.0))
    assert free == [(4.0, 0.0, 10.0, 10.0), (0.0, 6.0, 10.0, 10.0), (4.0, 0.0, 20.0, 3.0), (0.0, 0.0, 20.0, 2.0),
                    (0.0, 0.0, 2.0, 20.0)]
    A3._split(free, (40.0, 40.0, 41.0, 41.0))                      # meets none of them
    assert free == [(4.0, 0.0, 10.0, 10.0), (0.0, 6.0, 10.0, 10.0), (4.0, 0.0, 20.0, 3.0), (0.0, 0.0, 20.0, 2.0),
                    (0.0, 0.0, 2.0, 20.0)]

def _counting(monkeypatch, name: str) -> list:
    """Calls of A3.`name` counted (one entry each) while the test runs."""
    calls, saved = [], getattr(A3, name)
    monkeypatch.setattr(A3, name, lambda *a: calls.append(1) or saved(*a))
    return calls


def test_the_texts_order_search_passes_over_a_corner_a_later_plan_cannot_follow(monkeypatch):
    """Three small plans and one wider than the sheet: no corner of the first can be followed by
    the wide one, so each is passed over at once (the corners of the second plan never searched);
    none is found, and every corner was searched."""
    calls = _counting(monkeypatch, "_place_after")
    sizes = [(50.0, 40.0, 5.0), (50.0, 40.0, 5.0), (50.0, 40.0, 5.0), (500.0, 10.0, 5.0)]
    assert A3._in_order(sizes, [0, 1, 2, 3], A3.READING[0], 10.0) == (None, True)
    assert len(calls) == 1


def test_a_texts_order_search_of_every_corner_is_not_repeated_by_the_next_rule(monkeypatch):
    """Where the first rule of READING searched every corner and found none, the next finds none
    either (the same corners in another order): it is not run. Where the first ran out of
    tries, it is."""
    calls = _counting(monkeypatch, "_in_order")
    sizes = [(200.0, 150.0, 5.0), (200.0, 150.0, 5.0), (200.0, 150.0, 5.0)]   # no two fit side by side under the third
    assert A3._texts_layout(sizes, [0, 1, 2], 10.0) is None
    assert len(calls) == 1
    monkeypatch.setattr(A3, "IN_ORDER_TRIES", 0)
    assert A3._texts_layout(sizes, [0, 1, 2], 10.0) is None
    assert len(calls) == 1 + len(A3.READING)
