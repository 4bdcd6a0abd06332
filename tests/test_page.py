"""The interactive page (issue 27) in a real browser: Debian's headless Chromium driven by Playwright
(tests/sheet_browser.py; a fresh profile per launch). The slider's sheets carry every segment's
length as segments.csv has it; "Next step" follows seed 002's order of the force analysis; the
student's page holds no answer and judges typed lengths at the scales typed; the print's 100 mm bar measures 100 mm
in the PDF; the pages make no request. By default the ICE (seed 002) on a page of three angles;
with `-m slow` the whole page of `kinetostat page` against `kinetostat plans --cycle-scales`.
"""
from __future__ import annotations

import csv
import hashlib
import html
import io
import math
import re
import shutil
import subprocess
import warnings

import pytest

import kinetostat
import kinetostat.plans as P
from kinetostat.plans.core import PAGE_DECIMALS
from kinetostat.plans.i18n import num
from kinetostat.plans.forces import _group_label
from kinetostat.plans.page import _steps, page as make_page
from kinetostat.plans.worksheet import worksheet

import sheet_browser
from conftest import MODELS, ROOT, sampled

ANGLES = (0.0, 30.0, 150.0)


@pytest.fixture(scope="module")
def ice(tmp_path_factory):
    """The ICE, its cycle scales (sampled every 30 deg: quick), its key page at ANGLES and its
    student's page, written to files."""
    mech = kinetostat.load("ice_crank_slider")
    fixed = P.cycle_scales(mech, step_deg=30.0)
    d = tmp_path_factory.mktemp("page")
    key, student = d / "key.html", d / "student.html"
    key.write_text(make_page(mech, lang="uk", angles=ANGLES, fixed=fixed), encoding="utf-8")
    student.write_text(make_page(mech, lang="uk", student=True, fixed=fixed), encoding="utf-8")
    return mech, fixed, key, student


def _open(chromium, path, requests=None):
    pg = chromium.new_page(viewport={"width": 1300, "height": 900})
    errors = []
    pg.on("pageerror", lambda e: errors.append(str(e)))
    if requests is not None:
        pg.on("request", lambda r: requests.append(r.url))
    pg.goto(path.as_uri())
    try:
        pg.wait_for_selector("body[data-ready]", state="attached", timeout=20000)
    except Exception as exc:                        # noqa: BLE001 - say why: the script's errors
        raise AssertionError(f"the page did not get ready: {errors or exc}") from None
    assert not errors, errors
    return pg


def _slide(pg, deg: float) -> None:
    pg.evaluate("d => { const s = document.getElementById('phi'); s.value = d; s.dispatchEvent(new Event('input')); }", deg)


def _segments(pg) -> dict[tuple[str, str], float]:
    rows = pg.evaluate("() => [...document.querySelectorAll('svg [data-plan][data-segment]')]"
                       ".map(e => [e.dataset.plan, e.dataset.segment, e.dataset.lengthMm])")
    out = {(p, s): float(x) for p, s, x in rows}
    assert len(out) == len(rows), "a segment drawn twice"
    return out


def _csv(plans) -> dict[tuple[str, str], float]:
    """segments.csv as `kinetostat plans` writes it: (plan, segment) -> length_mm of each segment
    with finite ends (drawn)."""
    out = {}
    for r in csv.DictReader(io.StringIO(plans.segments_csv())):
        if all(math.isfinite(float(r[c] or "nan")) for c in ("x0_mm", "y0_mm", "x1_mm", "y1_mm")):
            out[(r["plan"], r["segment"])] = float(r["length_mm"])
    return out


def _build(mech, at, fixed):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return P.build(mech, at=at, fixed=fixed)


def _one(mech, at):
    """The analysis at `at` (default the design position) alone."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return kinetostat.analyze(mech, phi_deg=[mech.drive.design_deg if at is None else at])


def _compare(got: dict, want: dict, where: str) -> None:
    """The page contract: every segment's data-length-mm is segments.csv's length to 1e-6 mm."""
    assert set(got) == set(want), (where, set(got) ^ set(want))
    bad = {k: (got[k], want[k]) for k in want if abs(got[k] - want[k]) > 1e-6}
    assert not bad, (where, bad)


def test_slider_draws_every_segment_as_segments_csv(chromium, ice):
    """At 30, 0 and 150 deg and the design position every segment's data-length-mm equals
    segments.csv of the plans at the page's scales to 1e-6 mm, and the values table follows; the
    page, loaded, slid and stepped, asks for nothing but itself (its CSP forbids the rest)."""
    mech, fixed, key, _ = ice
    requests: list[str] = []
    pg = _open(chromium, key, requests)
    for at in (30.0, 0.0, 150.0):
        _slide(pg, at)
        plans = _build(mech, at, fixed)
        _compare(_segments(pg), _csv(plans), f"{at:g} deg")
        assert len(plans["velocity"].segments) <= len(_segments(pg))
        cell = pg.get_attribute('td[data-symbol="V_B"]', "data-value")
        ws = worksheet(mech, at, mu_l=fixed.base["mu_l"].value)
        assert float(cell) == pytest.approx(ws.value("V_B"), rel=1e-8)      # VALUE_DIGITS
    pg.click("#design")
    _compare(_segments(pg), _csv(_build(mech, mech.drive.design_deg, fixed)), "design position")
    assert pg.text_content("#phi-value") == "30"
    pg.click("#next")
    pg.select_option("#paper", "A4")
    assert requests == [key.as_uri()], requests
    assert "default-src 'none'" in key.read_text(encoding="utf-8")
    pg.close()


def test_next_step_follows_the_texts_order(chromium, ice):
    """Seed 002 (figs. 1.7, 1.8, 1.10): the velocity plan (p-a, the line through a square to AB, the
    vertical through p, b at their intersection) and the acceleration plan (pi-a, a-n2, the lines
    through n2 and pi, b), each step with its number on the sheet; then R12t from ΣM_B of the rod,
    the polygon R12t + G2 + F_i2 + G3 + F_i3 + F_p, the lines of R12n and R43 and their
    intersection h, R43 + R12n = 0, then the inner reaction R32, then the crank (R21 and M_зр),
    then the lever; one element highlighted at a time, on the plan it belongs to."""
    mech, fixed, key, _ = ice
    pg = _open(chromium, key)
    _slide(pg, 30)
    steps = pg.evaluate("""n => [...Array(n)].map(() => {
        document.getElementById('next').click();
        const s = document.getElementById('step').dataset, key = e => [e.plan, e.segment || e.path];
        return [key(s), [...document.querySelectorAll('.hl')].map(e => key(e.dataset)),
                document.getElementById('equation').textContent, s.n];
    })""", 26)
    for step, lit, _, _ in steps:
        assert lit == [step], (step, lit)            # one element lit at a time: the step's
    seen = [tuple(step) for step, _, _, _ in steps]
    kinematic = [("velocity", n) for n in ("p-a", "line a-b", "line p-b", "point b")] \
        + [("acceleration", n) for n in ("pi-a", "a-n2", "line n2-b", "line pi-b", "point b")]
    assert seen[:9] == kinematic
    assert [n for *_, n in steps[:9]] == ["1", "2", "3", "4", "1", "2", "3", "4", "5"]      # as on the sheets
    assert "перетині" in steps[3][2] and "a-b" in steps[1][2]
    steps = [s[:3] for s in steps[9:]]
    seen = seen[9:]
    polygon = [("forces:2,3", n) for n in ("R12t", "G2", "F_i2", "G3", "F_i3", "F_p", "line R12n", "line R43",
                                           "point h", "R43", "R12n")]
    assert seen[:13] == [("group:2,3", "R12t"), *polygon, ("forces:2,3", "R32")]
    assert seen[13] == ("crank", "R21") and ("crank", "M_зр") in seen[13:]
    assert steps[0][2].startswith("R12t з ΣM_B(ланка 2) = 0") and "R32" in steps[12][2]
    assert "G2" in steps[2][2] and "нехтовно мала" in steps[2][2]          # 0,049 mm: said, not an empty light
    plans = _build(mech, 30.0, fixed)
    crank_M = next(e for (plan, seg), _, e in steps if seg == "M_зр")
    lever = pg.evaluate("""() => { for (let i = 0; i < 30; i++) { document.getElementById('next').click();
        if (document.getElementById('step').dataset.segment === "F'_зр") return document.getElementById('equation').textContent; } }""")
    couples = {"M_i2": float(kinetostat.analyze(mech, phi_deg=[30.0]).inertia(2).moment[0])}
    for plan, eq in (("group:2,3", steps[0][2]), ("crank", crank_M), ("lever", lever)):
        _balanced(plans[plan], eq, fixed.base["mu_l"].value, couples)
    pg.close()


def _balanced(plan, eq: str, mu_l: float, couples: dict[str, float]) -> None:
    """A moment equation as the page writes it ("±F·h ± M/μ_l … = 0", h in mm; the crank's "M_зр
    + μ_l·(…) = 0") sums to zero with the forces and couples of the exact solution: the signs the
    script read off the sheet are the moments' senses, the arms their lengths (4 digits)."""
    body = eq.split(": ", 1)[1].split(" = 0")[0]
    total, big = 0.0, 0.0
    if body.startswith("M_зр + μ_l·("):
        total = big = plan.results[0].value / mu_l                     # N mm
        body = body[len("M_зр + μ_l·("):-1]
    F = {s.name: s.value for s in plan.segments if s.kind == "vector"}
    for sign, term in re.findall(r"(^−|^| [+−] )([^+−]+?)(?= [+−] |$)", body):
        if term.endswith("/μ_l"):
            value = abs(couples[term[:-4]]) / mu_l
        else:
            name, arm = term.rsplit("·", 1)
            value = F[name] * float(arm.replace(",", "."))
        value *= -1 if "−" in sign else 1
        total += value
        big = max(big, abs(value))
    assert abs(total) < 2e-3 * big, (eq, total, big)


def test_student_page_holds_no_answer_and_judges_typed_lengths(chromium, ice):
    """The student's page: no plan, no data-length-mm, none of the key's lengths or values in the
    file; typed lengths get their verdict against the band, the two M_зр against the 5 % rule; no
    request but the page itself."""
    mech, fixed, _, student = ice
    html = student.read_text(encoding="utf-8")
    plans = _build(mech, 30.0, fixed)
    assert not re.search(r'data-length-mm="\d', html) and 'id="phi"' not in html
    ws = worksheet(mech, 30.0, mu_l=fixed.base["mu_l"].value)
    answers = {num(plans[k].length_mm(s.name), "uk", decimals=2) for k in plans for s in plans[k].segments
               if s.kind == "vector" and plans[k].length_mm(s.name) > 1}
    answers |= {num(r.value, "uk", 4) for r in ws.rows if r.section != "kinematics" and abs(r.value) > 1}
    answers = {a for a in answers if "," in a}              # with decimals: not a bare small integer
    requests: list[str] = []
    pg = _open(chromium, student, requests)
    shown = pg.inner_text("body")                           # the text shown (no script)
    plain = re.sub(r'<script type="application/octet-stream"[^>]*>[^<]*</script>', "", html)   # the blobs: base85
    assert not [a for a in answers if re.search(rf"(?<![\d,]){re.escape(a)}(?!\d)", plain + shown)]
    assert pg.eval_on_selector_all("td.exact", "es => es.every(e => e.textContent === '')")

    def verdict(selector: str, typed: str) -> str:
        pg.fill(selector, typed)
        return pg.eval_on_selector(selector, "e => e.closest('tr').querySelector('.verdict').dataset.verdict")
    pb = plans["velocity"].length_mm("p-b")
    sel = 'input[data-plan="velocity"][data-segment="p-b"]'
    assert verdict(sel, num(pb, "uk", decimals=2)) == "ok"
    assert verdict(sel, num(pb + 3.0, "uk", decimals=2)) == "bad"
    M = plans["crank"].results[0].value                    # seed 002: 103 N m, counter-clockwise
    crank, lever = 'input.moment[data-symbol="M_зр"]', """input.moment[data-symbol="M'_зр"]"""

    def moments(typed_crank: str, typed_lever: str) -> tuple[str, str, str, str]:
        pg.fill(crank, typed_crank)
        pg.fill(lever, typed_lever)
        return tuple(pg.eval_on_selector_all("tr[data-moment] .verdict, #delta .verdict",
                                             "es => es.map(e => e.dataset.verdict || '')")) + (pg.text_content("#delta .verdict"),)
    assert moments(f"{M:.1f}", f"{M * 1.01:.1f}")[:3] == ("ok", "ok", "ok")
    # the texts' rule is on the student's own two moments: 98 and 108 are each near 103, δ ≈ 9 %
    assert moments("98", "108")[2] == "bad"
    # the sense counts: a moment of the wrong sign is wrong whatever its size
    assert moments(f"{-M:.1f}", f"{-M:.1f}")[:2] == ("bad", "bad")
    # δ judged as shown, to 0.1 %: δ = (103,1 − 97,9)/103,1 = 5,0 % is within 5 %
    v = moments("97,9", "103,1")
    assert v[2] == "ok" and "+5,0 %" in v[3] and "в межах" in v[3], v
    v = moments("97,8", "103,1")
    assert v[2] == "bad" and "+5,1 %" in v[3], v
    # the worksheet's tables to fill in, as the teacher's pack: every value and sense blank
    symbols = pg.eval_on_selector_all("#worksheet table.fill tr td:first-child", "es => es.map(e => e.textContent)")
    assert {"V_B", "M_зр", "R12"} <= set(symbols), symbols
    assert pg.eval_on_selector_all("#worksheet td.blank", "es => es.length > 0 && es.every(e => e.textContent === '')")
    # the title block's lines stay inside it (x 230-415 mm)
    right = pg.eval_on_selector_all("#grid svg text", "es => es.filter(e => +e.getAttribute('x') > 230)"
                                    ".map(e => e.getBBox().x + e.getBBox().width)")
    assert len(right) == 2 and max(right) < 415.0, right
    assert requests == [student.as_uri()], requests
    pg.close()


#: Seed 002 sec. 1.2 (the ICE at 30 deg): the guide's scales and the lengths it measured at them, mm.
GUIDE_SCALES = {"velocity": "0,2", "acceleration": "100", "forces:2,3": "50"}
GUIDE_MM = {("velocity", "p-b"): 54.7, ("velocity", "a-b"): 74.6, ("velocity", "p-s2"): 61.0,
            ("acceleration", "pi-b"): 83.11, ("acceleration", "pi-s2"): 78.75, ("acceleration", "n2-b"): 37.16,
            ("acceleration", "a-n2"): 20.23,
            ("forces:2,3", "R12"): 63.44, ("forces:2,3", "R43"): 15.61, ("forces:2,3", "R32"): 129.62}


def _item(plan: str, segment: str) -> str:
    return f'input.measured[data-plan="{plan}"][data-segment="{segment}"]'


#: Types each [item's selector, length, scale or null] as a student would (an input event each): the
#: scale into the input of the item's scale (data-scale) where given, then the length; the item
#: rows' [data-verdict, verdict text, quantity shown, the scale row's note] after each.
_TYPE = """rows => rows.map(([sel, typed, scale]) => {
  const e = document.querySelector(sel), type = (i, v) => { i.value = v; i.dispatchEvent(new Event('input')); };
  const mu = document.querySelector(`input.scale[data-scale="${e.dataset.scale}"]`);
  if (scale !== null) type(mu, scale);
  type(e, typed);
  const tr = e.closest('tr'), v = tr.querySelector('.verdict');
  return [v.dataset.verdict || '', v.textContent, tr.querySelector('.quantity').textContent,
          mu.closest('tr').querySelector('.verdict').textContent];
})"""


def _judged(pg, *rows: tuple[str, str, str, str | None]) -> list[tuple[str, str, str, str]]:
    """(plan, segment, typed, scale or None) each typed in turn (`_TYPE`): what each row then shows."""
    return [tuple(x) for x in pg.evaluate(_TYPE, [[_item(p, s), t, mu] for p, s, t, mu in rows])]


def test_check_judges_the_guides_lengths_at_the_guides_scales(chromium, ice):
    """Before, the check assumed the page's scales: seed 002's R12 = 63,44 mm, drawn at μ_F = 50 N/mm,
    read "+99 %, outside the band" on a page at μ_F = 100. Now the student types the scales he drew
    at, and every length the guide measured (sec. 1.2: the velocity, acceleration and force plans) at
    the guide's scales is in the band, its quantity shown (R12 = 63,44 · 50 = 3172 N, the guide's);
    a wrong length at those scales is not; a scale of 0, below 0 or not a number is named, never NaN."""
    mech, fixed, key, student = ice
    assert fixed.plan["forces:2,3"].value != 50.0           # the page's own scale is not the guide's
    pg = _open(chromium, student)
    R12 = ("forces:2,3", "R12", "63,44")
    assert _judged(pg, (*R12, None))[0][0] == "bad"                      # at the page's scale (before)
    got = _judged(pg, *[(p, s, num(mm, "uk", 6), GUIDE_SCALES[p]) for (p, s), mm in GUIDE_MM.items()])
    assert [g[0] for g in got] == ["ok"] * len(GUIDE_MM), list(zip(GUIDE_MM, got))
    shown = {k: g[2] for k, g in zip(GUIDE_MM, got)}
    assert (shown[("forces:2,3", "R12")], shown[("forces:2,3", "R32")], shown[("velocity", "p-b")]) \
        == ("3172 Н", "6481 Н", "10,94 м/с")                          # the guide's R12, R32, V_B
    # wrong at the guide's scales: 2 mm too long on the force plan (100 N), 1 mm on the velocity plan
    got = _judged(pg, ("forces:2,3", "R12", "65,44", None), ("velocity", "p-b", "55,7", None))
    assert [g[0] for g in got] == ["bad", "bad"], got
    # a scale that is not a number above 0: named on its own row and on the rows at it, never NaN
    said = "μ_F: введіть число, більше за 0"
    for bad in ("0", "-50", "п'ятдесят", ""):
        assert _judged(pg, (*R12, bad)) == [("none", said, "", said)], bad
        assert "NaN" not in pg.text_content("#check")
    assert _judged(pg, (*R12, "50")) == [("ok", _judged(pg, (*R12, None))[0][1], "3172 Н", "")]    # and back
    pg.close()
    # the key: the exact length and band at the scale typed (twice the page's at half its μ_F)
    pg = _open(chromium, key)
    exact = float(pg.get_attribute('svg [data-plan="forces:2,3"][data-segment="R12"]', "data-length-mm"))   # at 30°
    _judged(pg, (*R12, num(fixed.plan["forces:2,3"].value / 2, "uk", 6)))
    assert pg.eval_on_selector(_item("forces:2,3", "R12"), "e => e.closest('tr').querySelector('.exact').textContent") \
        == num(2 * exact, "uk", 4)
    pg.close()


def test_check_judges_variant_1_479_at_the_keys_scale(chromium, tmp_path):
    """Variant 1/479 at φ1 = 150°: its key (`kinetostat variant 1 479`, key.pdf) draws the force plan
    at μ_F = 40 N/mm, R12n 174,6 mm; its page (`variant --page`: the cycle's scales, μ_F = 100) marked
    that +150 %. At μ_F = 40 it is in the band; 180 mm is not. (The cycle's scales sampled every 30°.)"""
    from kinetostat import variants
    mech = variants.variant(1, "479").mechanism()
    f = tmp_path / "student.html"
    f.write_text(make_page(mech, lang="uk", student=True, at=150.0, fixed=P.cycle_scales(mech, step_deg=30.0)),
                 encoding="utf-8")
    pg = _open(chromium, f)
    k = pg.get_attribute(_item("forces:2,3", "R12n"), "data-scale")
    assert pg.input_value(f'input.scale[data-scale="{k}"]') != "40"
    got = _judged(pg, ("forces:2,3", "R12n", "174,6", None), ("forces:2,3", "R12n", "174,6", "40"),
                  ("forces:2,3", "R12n", "180", None))
    assert [g[0] for g in got] == ["bad", "ok", "bad"], got              # at the page's scale (before); at 40
    assert got[1][2] == "6984 Н"                                         # the key: R12n = 6982 N
    pg.close()


def _bars_mm(pdf) -> tuple[set[tuple[float, float]], list[dict[str, float]], int]:
    """(the pages' sizes in pt, on each page with the 100 mm bar its labels 0, 50, 100 -> their
    centres' y in mm, the number of pages) of a PDF (pdftotext -bbox); the bar's labels are the
    words "0", "50", "100" left of 20 mm whose right ends (the labels are set flush right) lie within
    1.5 mm of the leftmost right end (on A4 the notes, moved to the top, begin 12 mm in: a value
    row's "0" ends further right)."""
    box = subprocess.run(["pdftotext", "-bbox", str(pdf), "-"], capture_output=True, text=True, check=True).stdout
    sizes, bars = set(), []
    for page in box.split("</page>")[:-1]:
        size = re.search(r'<page width="([\d.]+)" height="([\d.]+)"', page)
        sizes.add((float(size[1]), float(size[2])))
        words = re.findall(r'<word xMin="([\d.]+)" yMin="([\d.]+)" xMax="([\d.]+)" yMax="([\d.]+)">([^<]*)</word>', page)
        near = [w for w in words if float(w[0]) * 25.4 / 72 < 20.0 and w[4] in ("0", "50", "100")]
        right = min((float(w[2]) for w in near), default=0.0)
        y = {w[4]: (float(w[1]) + float(w[3])) / 2 * 25.4 / 72 for w in near if float(w[2]) < right + 1.5 * 72 / 25.4}
        if y:
            bars.append(y)
    return sizes, bars, box.count("<page ")


def _printed(pg, pdf) -> list[str]:
    """The page printed to `pdf` as Chromium prints it (the page's own @page size), each printed
    page's text (pdftotext -raw: in the order drawn)."""
    pg.pdf(path=str(pdf), prefer_css_page_size=True, print_background=True)
    raw = subprocess.run(["pdftotext", "-raw", str(pdf), "-"], capture_output=True, text=True, check=True).stdout
    return raw.split("\f")[:-1]


def test_a4_white_under_the_moved_notes_covers_their_text_only(chromium, ice):
    """Printed on A4, the title line and the notes (the segments' value rows among them, a row a
    line of one text) move to the top on white: the white under the notes is as wide as their
    widest line, so the plan beside them stays drawn. Was: the width of the rows' text run laid
    end to end (~500 mm) under the title's full height, the ICE's group plan blanked on A4."""
    pg = _open(chromium, ice[2])
    pg.select_option("#paper", "A4")
    sheets = pg.evaluate("""() => [...document.querySelectorAll('svg')].filter((s) => s.querySelector('#a4-title')).map((svg) => {
        const rects = [...svg.querySelectorAll('#a4-title rect')].map((r) => r.getBBox());
        const notes = [...svg.querySelectorAll('text.note')].map((n) => n.getBoundingClientRect().width);
        const m = svg.getScreenCTM().a;                 // px a mm
        return {rects: rects.map((r) => [r.x, r.y, r.width, r.height]), widest: Math.max(0, ...notes) / m};
    })""")
    pg.close()
    assert sheets
    for s in sheets:
        notes = s["rects"][1:]
        assert len(notes) <= 1
        for x, y, w, h in notes:
            assert w <= s["widest"] + 2.5, (w, s["widest"])
        if s["widest"]:
            assert notes, s


def test_print_scale_bar_measures_100_mm(chromium, ice, tmp_path):
    """Printed to PDF, a first page of data, then each sheet a page at true scale, A3 landscape
    (the whole sheet) or, with A4 chosen, A4 landscape (the 297 x 210 mm around the plan): on
    every sheet the 100 mm bar's labels 0 and 100 lie 100 mm apart (pdftotext -bbox: the labels'
    centres)."""
    if shutil.which("pdftotext") is None:
        pytest.skip("no pdftotext (apt-get install poppler-utils)")
    mech, fixed, key, _ = ice
    pg = _open(chromium, key)
    pg.click("#next")                                   # a step lit on screen, not in print
    lit = "() => getComputedStyle(document.querySelector('.hl')).stroke"
    assert pg.evaluate(lit) == "rgb(208, 28, 28)"
    pg.emulate_media(media="print")
    assert pg.evaluate(lit) != "rgb(208, 28, 28)"
    pg.emulate_media(media="no-override")
    sheets = len(_build(mech, 30.0, fixed))
    for paper, (w, h) in (("A3", (420, 297)), ("A4", (297, 210))):
        pg.select_option("#paper", paper)
        pdf = tmp_path / f"{paper}.pdf"
        pg.pdf(path=str(pdf), prefer_css_page_size=True, print_background=True)
        sizes, bars, pages = _bars_mm(pdf)
        assert len(sizes) == 1 and sizes.pop() == pytest.approx((w / 25.4 * 72, h / 25.4 * 72), abs=1.0), paper   # Chromium: whole px
        assert len(bars) == sheets and pages == sheets + 1, (paper, len(bars), pages)  # the data's page first
        for y in bars:
            assert y["100"] - y["0"] == pytest.approx(100.0, abs=0.2), paper
            assert y["50"] - y["0"] == pytest.approx(50.0, abs=0.2), paper
        words = subprocess.run(["pdftotext", "-layout", str(pdf), "-"], capture_output=True, text=True, check=True).stdout
        titled = [p for p in words.split("\f") if "φ = 30°" in p and "ДВЗ" in p and "мм" in p]
        assert len(titled) == sheets, (paper, sheets, len(titled))   # A3: the title block; A4: the line on top
        if paper == "A4":                                   # the positions plan is taller than A4: said on it
            assert sum("обрізаний" in p for p in titled) >= 1
    pg.close()


def _bare_text(s: str) -> str:
    """Text without its markup and whitespace: a line of a sheet as pdftotext reads it, whatever the
    line breaks and the subscripts' runs."""
    return re.sub(r"\s+", "", html.unescape(re.sub(r"<[^>]+>", "", s)))


def _sheet_notes(mech, fixed, at: float, name: str) -> dict[str, list[str]]:
    """kind -> the notes of its own one-angle sheet at `at` (`kinetostat plans --at`: `_note_lines`
    and a row per segment, `_table_rows`, with their numbers), markup-free, each checked to be on
    that sheet as it draws them."""
    from kinetostat.plans import draw
    from kinetostat.plans.symbols import plain
    want = {}
    for kind, plan in _build(mech, at, fixed).items():
        svg = P.svg(plan, "uk", name)
        sheet = _bare_text(svg[svg.index('<g id="notes">'):])
        notes = [_bare_text(plain(n)) for n in draw._note_lines(plan, "uk", draw._tiny_at(draw._tiny(P.PlanCycle.of(plan)), 0))
                 + draw._table_rows(plan, "uk")]
        assert all(n in sheet for n in notes), kind     # the notes as the sheet draws them, unwrapped
        want[kind] = notes
    return want


def test_print_keeps_title_data_scales_and_notes(chromium, ice, tmp_path):
    """Printed (A3 and A4 at 30 deg, A3 at 150 deg), the key page's first page holds the title, the
    angle, the scales, every data row and every value of the angle shown; each sheet's page holds
    the notes of the plan's own one-angle SVG sheet (`kinetostat plans --at`) with their numbers:
    the results (M_зр, F'_зр, δ: 103,1 and 51,33 N·m), each tiny vector's value and length at the
    scale (G2* = 4,9 Н, 0,01 мм) and each segment's row (pa: 84,82 мм → 16,96 м/с); the student's
    page prints its title, scales and data too. Before: print hid all of them; then the notes came
    without their numbers; then without the segments' rows."""
    if shutil.which("pdftotext") is None:
        pytest.skip("no pdftotext (apt-get install poppler-utils)")
    from kinetostat.model.lettering import lettering
    mech, fixed, key, student = ice
    name = lettering(mech).name("uk", mech.name)
    data = [(r[0], r[1]) for r in make_page.__globals__["_data_rows"](mech, _one(mech, None), "uk")]
    pg = _open(chromium, key)
    for at, papers in ((30.0, ("A3", "A4")), (150.0, ("A3",))):
        want = _sheet_notes(mech, fixed, at, name)
        assert any("G2*=4,9Н:показанопозамасштабом(0,01ммумасштабі)" in x for x in want["lever"])
        assert any(x.startswith("Результати:Mзр=" + ("103,1" if at == 30.0 else "51,33")) for x in want["crank"])
        assert at != 30.0 or "pa:84,82мм→16,96м/с" in want["velocity"]          # seed 002: pa = 84.8 mm at 0.2 m/(s·mm)
        _slide(pg, at)
        rows = pg.eval_on_selector_all("#value-table td.num", "es => es.map(e => [e.dataset.symbol, e.textContent])")
        for paper in papers:
            pg.select_option("#paper", paper)
            first, *sheets = _printed(pg, tmp_path / f"{paper}.pdf")
            flat = _bare_text(first)
            assert _bare_text(name) in flat and f"Куткривошипаφ:{at:g}°" in flat and "μ_F=400Н/мм" in flat, first[:300]
            for symbol, value in data + [(s, v) for s, v in rows]:
                assert _bare_text(symbol + value) in flat, (paper, symbol, value)
            assert len(sheets) == len(want)
            for (kind, lines), page in zip(want.items(), sheets):
                missing = [x for x in lines if x not in _bare_text(page)]
                assert not missing, (at, paper, kind, missing)
    pg.close()
    pg = _open(chromium, student)
    first = _bare_text("".join(_printed(pg, tmp_path / "student.pdf")[:-1]))
    assert _bare_text(name) in first and "Масштаби" in first and "μ_l=0,001м/мм" in first
    for symbol, value in data:
        assert _bare_text(symbol + value) in first, symbol
    pg.close()


@pytest.mark.parametrize("path", sampled(MODELS))
def test_every_step_names_a_drawn_vector(path):
    """Each step of "Next step" lights a segment (or a couple's arc) its plan draws, every group's
    polygon side once in the order of its equation (its construction lines between), the groups
    from the last attached."""
    mech = kinetostat.load(path)
    plans = _build(mech, None, None)
    steps = _steps(mech, _one(mech, None), plans, "en")
    for s in steps:
        plan = plans[s["plan"]]
        assert (s["path"] in plan.paths) if "path" in s else any(x.name == s["segment"] for x in plan.segments), s
    for g in mech.structure.groups:
        label = _group_label(g)
        sides = [s["segment"] for s in steps if s["plan"] == f"forces:{label}"
                 and plans[s["plan"]].segment(s["segment"]).kind == "vector"]     # not its construction
        inner = 3 if g.klass == 3 else 1                 # a triad: the base's reaction on each leash
        assert sides[:-inner] == list(plans[f"forces:{label}"].equation)
        assert len(set(sides[-inner:])) == inner
    groups = list(dict.fromkeys(s["plan"].split(":")[1] for s in steps if s["plan"].startswith("forces:")))
    assert groups == [_group_label(g) for g in reversed(mech.structure.groups)]


def test_triad_steps_follow_the_texts_order():
    """A triad (Artobolevsky 1988, plans/forces.py): R^τ of each leash about its inner pin, then R^n
    of leash 3 from the group's moment about Assur's point S, then the polygon in the order drawn,
    then the base's reaction on each leash; every step a vector its plan draws."""
    mech = kinetostat.load("triad_six_bar")
    plans = _build(mech, None, None)
    steps = _steps(mech, _one(mech, None), plans, "uk")
    g = next(g for g in mech.structure.groups if g.klass == 3)
    label = _group_label(g)
    taus = [s for s in steps if s["plan"] == f"group:{label}"]
    assert [s["segment"][-1] for s in taus] == ["t", "t", "t", "n"][:len(taus)] and len(taus) >= 2
    assert taus[-1]["eq"].startswith(f"{taus[-1]['segment']} з ΣM_S") and "(група 2,3,4,5)" in taus[-1]["eq"]
    first = steps.index(taus[0])
    assert steps[first + len(taus)]["plan"] == f"forces:{label}"
    for s in steps:
        assert any(x.name == s.get("segment") for x in plans[s["plan"]].segments) or s.get("path") in plans[s["plan"]].paths, s


@pytest.mark.slow
def test_whole_page_against_plans_cycle_scales(chromium, tmp_path, cli):
    """`kinetostat page ice_crank_slider --lang uk`: 360 angles and the design position, at most
    300 kB; at 0, 30, 90, 150, 270 and 359 deg every segment as `kinetostat plans --at A
    --cycle-scales` writes it in segments.csv."""
    out = tmp_path / "ice.html"
    run = cli("page", "ice_crank_slider", "--lang", "uk", "--out", str(out))
    assert run.returncode == 0, run.stderr
    assert out.stat().st_size <= 300_000
    pg = _open(chromium, out)
    for at in (0, 30, 90, 150, 270, 359):
        d = tmp_path / f"plans_{at}"
        assert cli("plans", "ice_crank_slider", "--at", str(at), "--cycle-scales", "--out", str(d)).returncode == 0
        want = {}
        for r in csv.DictReader((d / "segments.csv").open(encoding="utf-8")):
            if all(math.isfinite(float(r[c] or "nan")) for c in ("x0_mm", "y0_mm", "x1_mm", "y1_mm")):
                want[(r["plan"], r["segment"])] = float(r["length_mm"])
        _slide(pg, at)
        _compare(_segments(pg), want, f"{at} deg")
    pg.close()


@pytest.mark.slow
def test_report_and_variant_link_their_pages(tmp_path, cli):
    """`report` writes page.html beside the report and links it; `variant 1 479 --page` writes the
    variant's page with its check at phi1."""
    r = cli("report", "ice_crank_slider", "--engines", "none", "--steps", "36", "--out", str(tmp_path / "r"),
            "--no-progress")
    assert r.returncode == 0, r.stderr
    folder = next(p for p in (tmp_path / "r").iterdir() if p.is_dir())
    assert (folder / "page.html").stat().st_size > 100_000
    assert "](page.html)" in (folder / "index.md").read_text(encoding="utf-8")
    v = cli("variant", "1", "479", "--page", "--no-pack", "--out", str(tmp_path / "v"))
    assert v.returncode == 0, v.stderr
    html = (tmp_path / "v" / "page.html").read_text(encoding="utf-8")
    assert '"at": 150.0' in html or '"at": 150' in html


def test_page_command_refuses_a_folder_as_out(cli, tmp_path):
    """`kinetostat page` checks --out before the minute of work: a folder is one line, exit 2."""
    r = cli("page", "ice_crank_slider", "--out", str(tmp_path))
    assert r.returncode == 2 and r.stderr.strip() == f"kinetostat: error: cannot write --out {tmp_path}: it is a directory"


def test_shaper_check_and_values_in_ukrainian():
    """The shaper's slots and Coriolis accelerations in the page's tables come from the catalogue:
    "паз ланки 3 (A)", a^к, not "slot 3 A", a^Cor (their data-segment, data-symbol stay)."""
    from kinetostat.plans.draw import segment_label
    from kinetostat.plans.page import _symbol
    mech = kinetostat.load("slotted_link_shaper")
    plans = _build(mech, 30.0, None)
    labels = {segment_label(s, "uk") for k in plans for s in plans[k].segments}
    assert {"паз ланки 3 (A)", "паз ланки 3 (B)"} <= labels and not [x for x in labels if "slot" in x]
    shown = [_symbol(r.symbol, "uk") for r in worksheet(mech, 30.0, lang="uk").rows]
    assert "a^к(3,2)" in shown and not [x for x in shown if "Cor" in x]
    assert _symbol("a^Cor(3,2)", "en") == "a^Cor(3,2)"


def test_report_draws_its_page_every_time(tmp_path, monkeypatch, cli, sketched_plots):
    """`kinetostat report` writes and links each model's page by default, drawn anew every time:
    a page.html planted in the model's folder is replaced, even one sealed as the removed cache
    accepted a page (its own key kept, the SHA-256 of its bytes on its last line); --no-page
    removes the earlier page.
    (The scotch yoke, without [friction] and [study] and their sections; a page of two angles at
    scales sampled every 90 deg, the plots sketched: quick.)"""
    import kinetostat.plans.page as pg
    monkeypatch.setattr(pg, "PAGE_ANGLES", (0.0, 150.0))
    cycle = P.cycle_scales
    monkeypatch.setattr(P, "cycle_scales", lambda mech, res=None: cycle(mech, step_deg=90.0))
    model = next(p for p in MODELS if p.stem == "scotch_yoke")
    out = tmp_path / "r"
    html, md = out / model.stem / "page.html", out / model.stem / "index.md"

    def report(*more) -> str:
        r = cli("report", str(model), "--engines", "none", "--steps", "8", "--jobs", "1", "--no-progress",
                "--out", str(out), *more)
        assert r.returncode == 0, r.stderr
        return r.stdout

    assert ", page drawn  ->" in report() and "](page.html)" in md.read_text(encoding="utf-8")
    assert "[page](scotch_yoke/page.html)" in (out / "index.md").read_text(encoding="utf-8")
    first = html.read_bytes()
    body = re.sub(rb"<!-- kinetostat-page-sha256 \w+ -->\n$", b"", first).replace(b"</body>", b"<p>planted</p></body>")
    planted = body + b"<!-- kinetostat-page-sha256 " + hashlib.sha256(body).hexdigest().encode() + b" -->\n"
    html.write_bytes(planted)                      # sealed as the removed page cache accepted a page as its own
    assert ", page drawn  ->" in report() and html.read_bytes() == first           # replaced, not kept
    report("--no-page")
    assert not html.exists() and "page.html" not in md.read_text(encoding="utf-8")        # none, none linked


def test_variant_all_writes_a_page_per_code_linked_from_its_index(tmp_path, monkeypatch, cli):
    """`kinetostat variant 1 --all --page` (one code here): each code's folder holds its page, in
    the key's language with the check at phi1, and both indexes link it. (Two angles: quick.)"""
    import kinetostat.plans.page as pg
    from kinetostat import variants
    monkeypatch.setattr(variants, "codes", lambda: ["479"])
    monkeypatch.setattr(pg, "PAGE_ANGLES", (0.0, 150.0))
    cycle = P.cycle_scales
    monkeypatch.setattr(P, "cycle_scales", lambda mech, res=None: cycle(mech, step_deg=90.0))
    run = cli("variant", "1", "--all", "--page", "--no-pack", "--out", tmp_path, "--no-progress")
    assert run.returncode == 0, run.stderr
    page = tmp_path / "task1_479" / "page.html"
    phi1 = variants.values(1, "479")["phi1"]
    html = page.read_text(encoding="utf-8")
    assert '<html lang="uk">' in html and f'"at": {float(phi1)!r}' in html
    for index in ("index.md", "index.html"):
        assert "task1_479/page.html" in (tmp_path / index).read_text(encoding="utf-8")


def _script_page(drawings, n: int) -> str:
    """A page of the hand-made `drawings` (Drawing's, n angles) and no values: the key page's
    script on the elements it looks for (page.py `_html`)."""
    import json
    from importlib import resources

    import numpy as np

    import kinetostat.plans.page as pg
    from kinetostat.plans.core import ELEMENTS
    kinds, blobs, lengths = [], {}, []
    for k, d in enumerate(drawings):
        meta, numbers, more = pg.encode_drawing(d, lengths)
        kinds.append(meta)
        lengths += more
        blobs[f"k{k}"] = pg._packed(numbers)
    kinds, mids = pg._shared_texts(kinds)
    blobs["meta"] = pg._packed(json.dumps({"kinds": kinds, "mids": mids, "steps": [], "rows": [], "exps": [], "sources": [], "frames": list(range(n))}).encode())
    blobs["values"] = pg._packed(pg._columns(np.zeros((n, 0)))[2])
    blobs["check"] = pg._text7(pg._obscure(pg._deflated(b'{"items": [], "M": [], "scales": [], "titles": {}}')))
    data = {"student": False, "slider": n - 1, "design": 0.0, "coord": pg.COORD_DECIMALS,
            "lengthd": pg.LENGTH_DECIMALS, "elements": ELEMENTS, "maxorder": pg.MAX_ORDER, "jump": pg.JUMP, "smooth": pg.SMOOTH.tolist(), "illegal7": list(pg.ILLEGAL7), "singular": [], "ui": {}, "decimal": ".", "scalebar": '<g id="scalebar"/>',
            "mm": "mm", "tiny": 1.0, "tol": 5.0}
    script = resources.files("kinetostat.plans").joinpath("page.js").read_text(encoding="utf-8")
    return ('<!DOCTYPE html><html><head><meta charset="utf-8"><style id="page-size"></style></head><body>'
            '<input type="range" id="phi" min="0" max="359"><output id="phi-value"></output><button id="design"></button>'
            '<button id="prev"></button><button id="next"></button><output id="step"></output>'
            '<select id="paper"><option>A3</option><option>A4</option></select><p id="equation"></p>'
            '<section id="sheets"></section><table id="value-table"></table><table id="check-table"><tr></tr></table>'
            + "".join(f'<script type="application/octet-stream" id="blob-{k}">{v}</script>' for k, v in blobs.items())
            + f'<script id="page-data" type="application/json">{json.dumps(data)}</script><script>{script}</script></body></html>')


def test_script_writes_a_hand_made_drawing_at_each_angle(chromium, tmp_path):
    """A Drawing made by hand (a segment with the contract's attributes, drawn at angles 0 and 2
    only; a fixed polyline; an arrowhead; a point; a label with two texts) written by the page's
    script at each angle: every element's coordinates to COORD_DECIMALS, a negative one, a length
    to LENGTH_DECIMALS, a label's text and a segment left out where its points are NaN."""
    import numpy as np

    from kinetostat.plans.core import ELEMENTS, Drawing, Element
    nan = np.nan
    line = Element("line", [[[10.004, 20.0], [30.5, 40.25]], [[nan, nan], [1, 2]], [[12.0, 21.0], [-3.126, 45.0]]],
                   {"stroke": "#000", "data-plan": "velocity", "data-segment": "p-b"}, "p-b",
                   length_mm=np.array([54.123456789, nan, 3.5]))
    arrow = Element("path", [[[1, 1], [2, 2], [3, 1]]] * 3, {"class": "arrowhead", "fill": "#000"})
    path = Element("polyline", [[[0, 0], [1.5, 2], [3, 0]]], {"fill": "none"})
    dot = Element("circle", [[[5, 5]], [[6, 6]], [[7.777, 7]]], {"r": "0.6", "fill": "#000"})
    label = Element("text", [[[8, 9]], [[8.5, 9]], [[9, 9]]], {"font-size": "3.50"},
                    texts=("B", 'A<tspan dy="0.70">2</tspan>'), variant=np.array([0, 1, 0]))
    hole = Element("polyline", [[[0, 0], [nan, nan], [1, 1], [2, 0]], [[0, 1], [1, 1], [2, 1], [nan, nan]],
                                [[nan, nan], [nan, nan], [1, 1], [nan, nan]]], {"stroke": "#1f5fa8"})
    negligible = Element("g", np.zeros((1, 0, 2)), {"class": "negligible", "data-plan": "velocity", "data-segment": "G2"},
                         length_mm=np.array([0.04, 0.05, 0.0]))
    d = Drawing("velocity", np.array([0.0, 1.0, 2.0]), '<?xml version="1.0"?>\n<svg><g id="plan">\n' + ELEMENTS + "</g>\n</svg>\n",
                (line, arrow, path, dot, label, hole, negligible))
    f = tmp_path / "hand.html"
    f.write_text(_script_page([d], 3), encoding="utf-8")
    pg = _open(chromium, f)
    got = [pg.evaluate("i => window.sheetSvg(0, i)", i) for i in range(3)]
    pg.close()
    assert got == [d.svg(i, *PAGE_DECIMALS) for i in range(3)]
    assert got[0] == ('<?xml version="1.0"?>\n<svg><g id="plan">\n'
                      '<line x1="10.0" y1="20.0" x2="30.5" y2="40.2" stroke="#000" data-plan="velocity" data-segment="p-b" '
                      'data-length-mm="54.123457"><title>p-b</title></line>\n'
                      '<path d="M1.0,1.0 L2.0,2.0 L3.0,1.0 z" class="arrowhead" fill="#000"></path>\n'
                      '<polyline points="0.0,0.0 1.5,2.0 3.0,0.0" fill="none"></polyline>\n'
                      '<circle cx="5.0" cy="5.0" r="0.6" fill="#000"></circle>\n'
                      '<text x="8.0" y="9.0" font-size="3.50">B</text>\n'
                      '<polyline points="0.0,0.0 1.0,1.0 2.0,0.0" stroke="#1f5fa8"></polyline>\n'
                      '<g class="negligible" data-plan="velocity" data-segment="G2" data-length-mm="0.040000"></g>\n</g>\n</svg>\n')
    assert "<line" not in got[1] and '<text x="8.5" y="9.0" font-size="3.50">A<tspan dy="0.70">2</tspan></text>' in got[1]
    assert '<line x1="12.0" y1="21.0" x2="-3.1" y2="45.0"' in got[2] and 'data-length-mm="3.500000"' in got[2]
    assert 'points="0.0,1.0 1.0,1.0 2.0,1.0"' in got[1] and got[2].count("<polyline") == 1


def test_script_writes_a_label_that_follows_its_point_and_a_leader_drawn_at_some_angles(chromium, tmp_path, monkeypatch):
    """Over 90 angles, a point, its label beside it (on one side, or the other with a leader at
    some angles) and the leader from the point: the label stored less the point it follows, the
    leader's end where the leader is not drawn holding the point's series (`_Earlier`); the page
    is a fifth smaller than without, and its script writes every angle exactly as `Drawing.svg`."""
    import numpy as np

    import kinetostat.plans.page as pg
    from kinetostat.plans.core import ELEMENTS, Drawing, Element
    n = 90
    t = np.radians(np.arange(n) * 4.0)
    point = np.stack([150 + 60 * np.cos(t), 120 + 45 * np.sin(t)], axis=1)
    far = (np.arange(n) // 9) % 3 == 2                               # the label away, with a leader
    label = point + np.where(far[:, None], [-9.13, 6.07], [1.37, -2.21])
    leader = np.where(far[:, None, None], np.stack([point, label], axis=1), np.nan)
    d = Drawing("velocity", np.arange(n, dtype=float), '<?xml version="1.0"?>\n<svg><g id="plan">\n' + ELEMENTS + "</g>\n</svg>\n",
                (Element("circle", point[:, None], {"r": "0.6"}), Element("text", label[:, None], {"font-size": "3.50"}, texts=("B",), variant=np.zeros(1, dtype=int)),
                 Element("line", leader, {"class": "leader"})))
    size = len(pg._deflated(pg.encode_drawing(d)[1]))
    f = tmp_path / "follow.html"
    f.write_text(_script_page([d], n), encoding="utf-8")
    page = _open(chromium, f)
    got = page.evaluate(f"() => [...Array({n}).keys()].map((i) => window.sheetSvg(0, i))")
    page.close()
    assert got == [d.svg(i, *PAGE_DECIMALS) for i in range(n)]
    monkeypatch.setattr(pg._Earlier, "near", lambda self, a, care: None)
    monkeypatch.setattr(pg._Earlier, "shifted", lambda self, a, care: None)
    assert size < 0.8 * len(pg._deflated(pg.encode_drawing(d)[1]))


def test_script_writes_jumps_smooth_lengths_moved_series_scaled_lengths_and_shared_texts(chromium, tmp_path):
    """Over 60 angles, a sheet whose series the page stores in its shorter forms, written by the
    page's script exactly as `Drawing.svg`: a label that jumps between two places and back as it
    moves (`_jumps`), a length to 1e-6 mm on its least-squares polynomial (`_smooth`), a point that is another moved by a constant (a reference and the constant),
    a segment's length half another's on an earlier sheet plus a little (`_proportional`: "from"),
    a title with φ at every angle (`_shared_texts`)."""
    import numpy as np

    import kinetostat.plans.page as pg
    from kinetostat.plans.core import ELEMENTS, Drawing, Element
    n = 60
    t = np.radians(np.arange(n) * 1.0)
    centre = np.stack([100 + 30 * np.cos(t), 100 + 20 * np.sin(t)], axis=1)
    side = np.where((np.arange(n) // 7) % 2 == 0, 4.0, -3.5)
    label_xy = centre + np.stack([side, np.full(n, 2.0)], axis=1)
    L = 50 + 10 * np.sin(4 * t)
    root = '<?xml version="1.0"?>\n<svg><g id="plan">\n' + ELEMENTS + "</g>\n</svg>\n"
    seg = lambda name, length: Element("line", np.stack([centre, centre + 5], axis=1), {"data-plan": "p", "data-segment": name},
                                       length_mm=length)
    first = Drawing("velocity", np.arange(n, dtype=float), root, (seg("a", L),))
    second = Drawing("lever", np.arange(n, dtype=float), root, (
        seg("b", L / 2 + 1e-6 * (np.arange(n) % 3)),
        Element("circle", centre[:, None], {"r": "0.6"}), Element("circle", centre[:, None] + [12.3, -4.5], {"r": "0.6"}),
        Element("text", label_xy[:, None], {"class": "name"}, texts=("B",), variant=np.zeros(1, dtype=int)),
        Element("text", np.full((n, 1, 2), 5.0), {"class": "title"}, texts=tuple(f"Lever, φ = {k}°" for k in range(n)),
                variant=np.arange(n))))
    assert pg._serieses([pg._ints(label_xy[:, 0], pg.COORD_DECIMALS)])[0][0] == pg.MAX_ORDER + 1
    assert pg._serieses([pg._ints(L, pg.LENGTH_DECIMALS)])[0][0] == pg.MAX_ORDER + 2
    metas = pg.encode_drawing(second, pg.encode_drawing(first)[2])[0]["elements"]
    assert metas[0]["from"][0] == 0 and pg._shared_texts([{"elements": metas}])[0][0]["elements"][-1]["texts"]["pre"] == "Lever, φ = "
    f = tmp_path / "stored.html"
    f.write_text(_script_page([first, second], n), encoding="utf-8")
    page = _open(chromium, f)
    got = [[page.evaluate("([k, i]) => window.sheetSvg(k, i)", [k, i]) for i in range(n)] for k in range(2)]
    page.close()
    assert got == [[d.svg(i, *PAGE_DECIMALS) for i in range(n)] for d in (first, second)]


#: Each sheet of the page as its script wrote it: (kind, the SVG).
_SHEETS = """() => [...document.querySelectorAll('.sheet')].map(s => [s.dataset.kind, s.querySelector('svg').outerHTML])"""


def _page_overlaps(chromium, path, angles) -> list[str]:
    """Every label over another label, an arrowhead or a point (`sheet_browser.overlaps`) on each
    sheet the page's script writes at each of `angles`, each sheet set at its own size in Chromium
    (`sheet_browser.measure`)."""
    pg, sheet = _open(chromium, path), chromium.new_page()
    bad = []
    for at in angles:
        _slide(pg, at)
        for kind, svg in pg.evaluate(_SHEETS):
            bad += [f"{at:g} deg, {kind}: {b}" for b in sheet_browser.overlaps(sheet_browser.measure(sheet, svg))]
    pg.close()
    sheet.close()
    return bad


OVERLAP_ANGLES = tuple(float(a) for a in range(0, 360, 15))


def test_ice_page_has_no_overlap_at_24_angles(chromium, tmp_path):
    """The ICE's page at 24 angles (every 15 deg): no label over another label, an arrowhead or a
    point on any sheet, as Chromium lays them out."""
    mech = kinetostat.load("ice_crank_slider")
    f = tmp_path / "ice.html"
    f.write_text(make_page(mech, lang="uk", angles=OVERLAP_ANGLES), encoding="utf-8")
    assert _page_overlaps(chromium, f, OVERLAP_ANGLES) == []


@pytest.mark.slow
@pytest.mark.parametrize("path", MODELS, ids=lambda p: p.stem)
def test_every_page_has_no_overlap_and_fits_300_kb(chromium, tmp_path, path):
    """Every bundled model's whole page in Ukrainian (its texts the most bytes; a triad's with its
    construction): at most 300 kB; at 24 angles no label over another label, an arrowhead or a point."""
    mech = kinetostat.load(path)
    f = tmp_path / "page.html"
    f.write_text(make_page(mech, lang="uk"), encoding="utf-8")
    assert f.stat().st_size <= 300_000
    assert _page_overlaps(chromium, f, OVERLAP_ANGLES) == []


def test_script_writes_every_sheet_as_drawing_svg(chromium, ice):
    """The key page's script writes each plan's sheet at each angle exactly as `Drawing.svg`
    writes it from the same cycle (ICE, ANGLES and the design position)."""
    from kinetostat.model.lettering import lettering
    from kinetostat.plans.draw import drawing
    mech, fixed, key, _ = ice
    phi = [*ANGLES, mech.drive.design_deg]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = kinetostat.analyze(mech, phi_deg=phi)
    cycles = P.build_cycle(mech, res, fixed, P.fixed_positions(mech, fixed.base["mu_l"]))
    pg = _open(chromium, key)
    for k, cycle in enumerate(cycles.values()):
        d = drawing(cycle, "uk", lettering(mech).name("uk", mech.name), contract=True, notes=True)
        for i in range(len(phi)):
            assert pg.evaluate("([k, i]) => window.sheetSvg(k, i)", [k, i]) == d.svg(i, *PAGE_DECIMALS), (cycle.kind, phi[i])
    pg.close()


@pytest.mark.parametrize("data", [b"", b"\x00", b"\x00" * 9, bytes(range(256)) * 3, b"<\r\x00" * 40,
                                  bytes([0b0011110, 0b0000000]), bytes([0x01, 0x80 | 0x3C]), bytes([0xFF] * 6 + [0x3C])],
                         ids=["empty", "nul", "nuls", "all", "illegal", "nul-paired", "nul-last-alone", "lt-last-alone"])
def test_a_blob_holds_7_bits_a_character_and_no_lt_cr_or_nul(data):
    """A blob's text (`_text7`, read back as the test of the hostile page reads it, as page.js
    does): the same bytes; no "<", CR or NUL in it; in UTF-8 at most 8/7 of the bytes and 2 bytes
    more (was Ascii85: 5/4), whatever the data, an illegal group last or illegal groups in a row."""
    import zlib
    from kinetostat.plans import page as pg
    from test_hostile_page import _unpacked
    z = zlib.compressobj(9, zlib.DEFLATED, -15)
    packed = z.compress(data) + z.flush()
    text = pg._text7(packed)
    assert not set(text) & {"<", "\r", "\x00"}
    assert _unpacked(text) == data
    assert len(text.encode()) <= len(packed) * 8 / 7 + 2
    raw = pg._text7(data)                                     # the groups as they come, not deflated
    groups = "".join(format(b, "08b") for b in data)
    assert len(raw) <= -(-len(groups) // 7) and len(raw.encode()) <= len(data) * 8 / 7 + 2


def test_triad_page_names_the_tiny_vectors_of_its_one_angle_sheets():
    """The page's cycle of the triad (30 and 150 deg) finds the same tiny vectors, drawn the same
    way, as each force plan's one-angle sheet: on the force polygon, whose sides a triad names anew at
    each angle, R05n (0,75 mm) at 30 deg, not R12n (4,22 mm there; its side of the same name is
    0,75 mm only at 150 deg). Before: found by the first segment of each name."""
    from kinetostat.plans import draw
    from kinetostat.plans.solution import solve
    mech = kinetostat.load("triad_six_bar")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        fixed = P.cycle_scales(mech)                    # the page's (`kinetostat plans --cycle-scales`)
        res = solve(mech, [30.0, 150.0]).res
        cycles = P.build_cycle(mech, res, fixed)
    for i, at in enumerate((30.0, 150.0)):
        for kind, plan in _build(mech, at, fixed).items():
            if kind in ("mechanism", "positions", "velocity", "acceleration"):
                continue
            one = draw._tiny_at(draw._tiny(P.PlanCycle.of(plan)), 0)
            assert draw._tiny_at(draw._tiny(cycles[kind]), i) == one, (at, kind)
            if kind.startswith("forces:") and at == 30.0:
                assert one == {"R05n": "negligible"}, one


def test_changes_of_a_sheets_coordinate_series_equal_a_plain_pairwise_count(monkeypatch):
    """`_changes` (the encoder's all-at-once comparison of a sheet's coordinate series, in chunks, a
    step at a time) gives for every pair the count a plain loop gives: at the PROBES of series i's
    angles, how many of the steps of series j less series i are not 0 (j < i); a follower (a label
    less its point) found with 0 changes; n where j >= i. Series read at all angles, at some, at one."""
    import numpy as np

    import kinetostat.plans.page as pg
    rng = np.random.default_rng(36)
    m, n = 40, 90
    x = rng.integers(-50, 50, (m, n)).cumsum(axis=1)
    x[7] = x[3] + 12                                          # a label that follows its point
    x[9, ::2] = x[2, ::2] - 5                                 # one that follows at every other angle
    care = np.ones((m, n), dtype=bool)
    care[5:15] = rng.random((10, n)) < 0.4
    care[20, 1:] = False
    care[21] = False
    changes, probes = pg._changes(x, care)
    for i in range(m):
        at = np.flatnonzero(care[i])
        probe = at[:: max(1, len(at) // pg.PROBES)]
        assert probes[i] == len(probe)
        for j in range(m):
            want = int((np.diff(x[j, probe] - x[i, probe]) != 0).sum()) if j < i and len(probe) else n
            assert changes[i, j] == want, (i, j)
    assert changes[7, 3] == 0 and pg._changes(x, care)[0][7].argmin() == 3
    monkeypatch.setattr(pg, "CHUNK", 50)                     # chunks of one or two series
    assert (pg._changes(x, care)[0] == changes).all()


@pytest.mark.slow
def test_script_writes_every_sheet_of_the_triad_page_as_drawing_svg(chromium, tmp_path):
    """triad_six_bar's page at every 10 deg (its sheets less the notes, whose numbers come from the
    values table this page has not): the page's script writes every sheet at every angle exactly
    as `Drawing.svg`; the sheets whose coordinate series follow earlier ones most (the force
    polygon's, a triad's sides named anew at each angle, their labels and leaders). Before: main's
    one-series-at-a-time search wrote 23 of the 37 frames of the force polygon wrong."""
    from dataclasses import replace

    import kinetostat.plans.page as pg
    from kinetostat.plans.draw import TOKEN
    sheets = []
    encode = pg.encode_drawing

    def keep(d, earlier=()):
        sheets.append(replace(d, elements=tuple(e for e in d.elements if not any(TOKEN.search(t) for t in e.texts))))
        return encode(d, earlier)
    with warnings.catch_warnings(), pytest.MonkeyPatch.context() as mp:
        warnings.simplefilter("ignore")
        mp.setattr(pg, "encode_drawing", keep)
        pg.page(kinetostat.load("triad_six_bar"), angles=[float(a) for a in range(0, 360, 10)])
    n = sheets[0].n
    f = tmp_path / "triad.html"
    f.write_text(_script_page(sheets, n), encoding="utf-8")
    page = _open(chromium, f)
    for k, d in enumerate(sheets):
        got = page.evaluate(f"() => [...Array({n}).keys()].map((i) => window.sheetSvg({k}, i))")
        assert got == [d.svg(i, *PAGE_DECIMALS) for i in range(n)], d.kind
    page.close()


def test_a_length_drawn_at_some_angles_is_stored_as_the_multiple_of_one_drawn_at_all():
    """A segment drawn at some angles only (a triad's construction line in one order of its sides)
    whose length is there twice another's drawn at every angle: the encoder stores it as that
    multiple ("from": [0, 2.0]), the rest of it (where not drawn) taken as the multiple too, and
    its lengths where drawn as drawn. Before: compared at every angle, the series held still where
    not drawn, it matched no multiple and was stored alone."""
    import numpy as np

    import kinetostat.plans.page as pg
    from kinetostat.plans.core import Drawing, Element
    n = 60
    L = 20.0 + 5.0 * np.sin(np.arange(n) / 7.0)
    on = (np.arange(n) >= 20) & (np.arange(n) < 45)
    full = np.stack([np.zeros((n, 2)), np.column_stack([L, np.zeros(n)])], axis=1)
    part = np.where(on[:, None, None], np.stack([np.full((n, 2), 10.0), np.column_stack([10.0 + 2 * L, np.full(n, 10.0)])], axis=1), np.nan)
    d = Drawing("velocity", np.arange(n, dtype=float), "", (
        Element("line", full, {"data-segment": "a-b"}, length_mm=L),
        Element("line", part, {"data-segment": "line a-b"}, length_mm=np.where(on, 2 * L, np.nan))))
    meta, _, lengths = pg.encode_drawing(d)
    assert meta["elements"][1].get("from") == [0, 2.0]
    assert (lengths[1][on] == np.rint(2 * L[on] * 10.0 ** pg.LENGTH_DECIMALS)).all()
    assert (lengths[1][~on] == pg._scaled(lengths[0], 2.0)[~on]).all()
