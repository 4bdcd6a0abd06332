"""The teacher's pack (`kinetostat.plans.pack`, `kinetostat variant`): the student's sheet and the
answer key as PDFs that pdftotext reads back in the key's language, the key holding the balancing
moment, the four scales, the segments and a band per value, the sheet holding none of the key's
numbers; the A3 sheet of plans; standalone HTML and the --all index. The scale rule's crank at
30..35 mm as seed 002 sec. 1.2.2 asks."""
from __future__ import annotations

import contextlib
import io
import re
import shutil
import subprocess
import sys
import warnings
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import numpy as np
import pytest

import kinetostat
from kinetostat import variants
from kinetostat.plans import pack as P
from kinetostat.plans.drawing_error import simulate
from kinetostat.plans.worksheet import worksheet
from kinetostat.plans.i18n import num, words_en
from kinetostat.plans.scales import choose_scales

needs_poppler = pytest.mark.skipif(shutil.which("pdftotext") is None, reason="poppler's pdftotext not installed")
NUMBER = re.compile(r"(?<![\w.,])-?\d+(?:[.,]\d+)?(?![\w]|[.,]\d)")


def pdftext(path) -> str:
    return subprocess.run(["pdftotext", "-enc", "UTF-8", str(path), "-"], capture_output=True, text=True,
                          check=True).stdout


def english(text: str) -> set[str]:
    """The catalogue's English words in `text`, less the symbols' scripts (P_max, P<sub>max</sub>)."""
    words = re.findall(r"[A-Za-z]{3,}", re.sub(r"_\w+|<su[bp]>[^<]*</su[bp]>|<[^>]+>", " ", text))
    return {w for w in words if w.lower() in words_en()}


@dataclass(frozen=True)
class Written:
    """What a run of `kinetostat variant` wrote: its folder, its stdout and stderr, and the pack it
    wrote (`P.pack`'s)."""
    out: Path
    stdout: str
    stderr: str
    pack: P.Pack


def variant(out: Path, *args: str, mp: pytest.MonkeyPatch) -> Written:
    """`kinetostat variant *args --out out` in this process (warnings silenced), `P.pack` watched."""
    from kinetostat.cli import main
    packs, std, err = [], io.StringIO(), io.StringIO()
    pack = P.pack
    mp.setattr(P, "pack", lambda *a, **k: packs.append(pack(*a, **k)) or packs[-1])
    mp.setattr(warnings, "showwarning", warnings.showwarning)          # main() replaces it
    with warnings.catch_warnings(), contextlib.redirect_stdout(std), contextlib.redirect_stderr(err):
        warnings.simplefilter("ignore")
        assert main(["variant", *args, "--out", str(out)]) == 0, err.getvalue()
    (written,) = packs
    return Written(out, std.getvalue(), err.getvalue(), written)


@pytest.fixture(scope="module")
def written(tmp_path_factory) -> Written:
    """`kinetostat variant 1 479 --lang uk --out K`, as a teacher types it, on a plain install:
    without matplotlib and the harness (neither is in the core install; each import of them fails
    here)."""
    with pytest.MonkeyPatch.context() as mp:
        for name in ("matplotlib", "kinetostat_validation"):
            mp.setitem(sys.modules, name, None)
        return variant(tmp_path_factory.mktemp("K"), "1", "479", "--lang", "uk", mp=mp)


@pytest.fixture(scope="module")
def all_ru(tmp_path_factory) -> Written:
    """`kinetostat variant 1 --all --lang ru` of one code (479), its PDFs not drawn (the PDFs: the
    tests of `written` and test_the_same_in_russian_and_english; here the index)."""
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(variants, "codes", lambda: ["479"])
        for name in ("_pdf", "_plans_pdf"):
            mp.setattr(P, name, lambda *a: b"%PDF-1.4 drawn above\n")
        return variant(tmp_path_factory.mktemp("all"), "1", "--all", "--no-progress", "--lang", "ru", mp=mp)


@pytest.fixture(scope="module")
def pack_1_479(request):
    """Variant 1 / 479's pack in a language: the one `variant` wrote in uk (`written`) and in ru
    (`all_ru`); in en built here, its bands from 20 draws."""
    def get(lang: str) -> P.Pack:
        if lang in ("uk", "ru"):
            return request.getfixturevalue({"uk": "written", "ru": "all_ru"}[lang]).pack
        return built(1, "479", lang, draws=20)
    return get


@pytest.fixture(scope="module")
def uk_479(written) -> Path:
    return written.out


@pytest.fixture(scope="module")
def pack_uk(written) -> P.Pack:
    """The pack that `variant 1 479 --lang uk` wrote."""
    return written.pack


def built(task: int, code: str, lang: str, draws: int = P.BAND_DRAWS) -> P.Pack:
    """`P.pack` of variant task/code, built once per module (a pack takes seconds: its A3 sheet's
    search; `_built`, its arguments spelt one way for its cache)."""
    return _built(task, code, lang, draws)


@lru_cache(maxsize=None)
def _built(task: int, code: str, lang: str, draws: int) -> P.Pack:
    return P.pack(variants.variant(task, code), lang=lang, draws=draws)


def test_the_command_writes_the_pack(uk_479):
    for name in P.PACK_FILES:
        assert (uk_479 / name).stat().st_size > 0, name
    assert (uk_479 / "sheet.pdf").read_bytes().startswith(b"%PDF") and (uk_479 / "key.pdf").read_bytes()[:4] == b"%PDF"


@needs_poppler
def test_the_pdfs_read_back_in_ukrainian(uk_479):
    sheet, key = pdftext(uk_479 / "sheet.pdf"), pdftext(uk_479 / "key.pdf")
    a3 = pdftext(uk_479 / "plans_a3.pdf")
    for t in (sheet, key, a3):
        assert english(t) == set()
    assert "Кривошипно-повзунний механізм двотактного ДВЗ" in key.replace("\n", " ")
    assert "Частота обертання кривошипа" in sheet and "Вага шатуна" in sheet        # table 1.1's rows
    assert "План швидкостей" in a3 and "Важіль Жуковського" in a3


@needs_poppler
def test_the_key_holds_the_answers_and_their_bands(uk_479):
    key = pdftext(uk_479 / "key.pdf")
    flat = re.sub(r"\s+", " ", key)
    mech = variants.variant(1, "479").mechanism()
    M = kinetostat.analyze(mech, phi_deg=[150.0]).balancing_moment[0]
    assert "Mзр" in key and num(M, "uk", 4) in key                                   # 99,6 N m, exact solver
    # the A3 sheet's scales (in the texts' order only at μ_v = 0.4, μ_F = 50: tests/test_a3.py)
    for mu, value in (("μl", "0,0015"), ("μv", "0,4"), ("μa", "100"), ("μF", "50")):      # μ with its subscript
        assert re.search(rf"{mu} (\S+ )?{value} ", flat), mu         # pdftotext may read a header cell between
    assert "OA = 32 мм" in flat                                                        # the crank at 30..35 mm
    # the polygon's sides at mu_F = 50 N/mm: R12 = 7009 N is 140,2 mm, the scale beside it
    assert re.search(r"R12 140,2 μF = 50 Н/мм 7009 Н", flat)                          # μ_F: F set below
    # a band per drawn value: the 5-95 % of the seeded study, printed
    sol = simulate(mech, at=150.0, n=P.BAND_DRAWS, seed=0)
    lo, hi = np.percentile(sol.samples["M_bal"], P.BAND)
    assert lo < M < hi and hi - lo < 0.1 * M
    assert f"{num(lo, 'uk', 3)} … {num(hi, 'uk', 3)}" in key
    assert "|δ| не більше 5 %" in flat


def test_task_2_bands_both_groups_and_marks_a_value_outside_its_band():
    """Task 2 (opposed twin, two groups on the crank): both groups' reactions, both arms on the
    crank and M_зр have bands from the simulated drawings; R61 (4.2 N, a 0.04 mm closing side at
    μ_F = 100 N/mm) is read longer by every careful drawing, and the key says so."""
    v = variants.variant(2, "479")
    p = P.pack(v, lang="uk", draws=400)
    mech = v.mechanism()
    res = kinetostat.analyze(mech, phi_deg=[float(v.values["phi1"])])
    for key, exact in (("M_bal", res.balancing_moment[0]), ("R_1_2", np.hypot(*res.reaction(1, 2)[0])),
                       ("R_1_4", np.hypot(*res.reaction(1, 4)[0])), ("R_3_2", np.hypot(*res.reaction(3, 2)[0])),
                       ("R_5_4", np.hypot(*res.reaction(5, 4)[0]))):
        lo, hi = p.bands[key]
        assert lo < exact < hi and hi - lo < 0.05 * abs(exact), key
    assert {"h_R21", "h_R41"} <= set(p.bands)
    R01 = np.hypot(*res.reaction(0, 1)[0])
    assert R01 < p.bands["R_0_1"][0]
    notes = [b for kind, b in p.key if kind == "p"]
    assert any(b.startswith("* Точне значення поза межами") for b in notes)


@needs_poppler
def test_the_sheet_holds_no_answer(uk_479, pack_uk):
    sheet = pdftext(uk_479 / "sheet.pdf")
    found = set(NUMBER.findall(sheet))
    assert "4200" in found and "0,048" in found                                       # the data are there
    assert len(pack_uk.answers) > 100
    assert found & pack_uk.answers == set()
    assert "Mзр" in sheet and "R12" in sheet                                         # the tables to fill in


@needs_poppler
@pytest.mark.parametrize("lang, words", [
    ("ru", ("Ключ ответов", "Границы тщательного чертежа", "Частота вращения кривошипа")),
    pytest.param("en", ("Answer key", "Band of a careful drawing", "Crank speed"), marks=pytest.mark.slow)])
def test_the_same_in_russian_and_english(lang, words, tmp_path, pack_1_479):
    p = pack_1_479(lang)
    for name, blocks in (("sheet", p.sheet), ("key", p.key)):                        # as Pack.write renders them
        (tmp_path / f"{name}.pdf").write_bytes(P._pdf(blocks, name))
    sheet, key = pdftext(tmp_path / "sheet.pdf"), pdftext(tmp_path / "key.pdf")
    both = re.sub(r"\s+", " ", sheet + key)
    for w in words:
        assert w in both, w
    if lang != "en":
        assert english(sheet + key) == set()
    assert set(NUMBER.findall(sheet)) & p.answers == set()


def test_html_pages_stand_alone(uk_479):
    tmp_path = uk_479
    for name in ("sheet.html", "key.html", "plans.html", "worksheet.html"):
        page = (tmp_path / name).read_text(encoding="utf-8")
        assert page.startswith("<!DOCTYPE html>") and '<meta charset="utf-8">' in page and "@media print" in page
        assert '<html lang="uk">' in page and english(re.sub(r"(?s)<style>.*?</style>", "", page)) == set()
    assert '<div class="area">' in (tmp_path / "sheet.html").read_text(encoding="utf-8")
    assert 'src="velocity.svg"' in (tmp_path / "plans.html").read_text(encoding="utf-8")


@pytest.mark.parametrize("lang", ["en", "ru"])
def test_the_blocks_in_each_language(lang, pack_1_479):
    """The sheet and key, as their blocks (what both the PDF and the HTML print): every text in `lang`
    (the packs other tests here build)."""
    p = pack_1_479(lang)
    texts = [x for kind, x in p.sheet + p.key if kind in ("h1", "h2", "p")]
    texts += [c for kind, x in p.sheet + p.key if kind == "table" for row in (x.head,) + x.rows for c in row]
    assert (english(" ".join(texts)) == set()) is (lang != "en")
    assert not any(c for kind, x in p.sheet if kind == "table" for row in x.rows for i, c in enumerate(row)
                   if i in x.blank)                                                    # left blank to fill in


def test_all_writes_an_html_index_of_the_packs(all_ru):
    out = all_ru.out
    page = (out / "index.html").read_text(encoding="utf-8")
    assert page.startswith("<!DOCTYPE html>") and '<meta charset="utf-8">' in page
    assert 'href="task1_479/key.pdf"' in page and 'href="task1_479/sheet.pdf"' in page
    assert 'href="task1_479/worksheet.html"' in page
    assert len(re.findall(r"<th[ >]", page)) == 7 and "<td>|М_ур| " not in page and "|M_ур| наибольшее за цикл" in page   # one table
    assert (out / "task1_479" / "key.pdf").stat().st_size > 0
    assert re.search(r"Ключи ответов: 1 \(задания 1\) -> .*; оглавление -> .*index\.md; \d+,\d с", all_ru.stdout)


@pytest.mark.parametrize("task, code, want", [(1, "479", 32.0), (1, "000", 34.0), (3, "479", 32.0), (2, "111", 33.0)])
def test_the_crank_lands_at_30_to_35_mm(task, code, want):
    """Seed 002 sec. 1.2.2: OA drawn 30..35 mm; 1/479 (l_OA = 0.048 m) drew 24 mm at 0.002 m/mm."""
    v = variants.variant(task, code)
    mech = v.mechanism()
    sc = choose_scales(mech, kinetostat.analyze(mech, phi_deg=[v.values["phi1"]]))
    assert v.values["l_OA"] / sc["mu_l"].value == pytest.approx(want)


def test_a_plain_install_writes_the_whole_pack(written):
    """Without matplotlib and the harness (`written`: each import of them fails there) `variant`
    writes the key and the whole pack: its PDFs by reportlab with the bundled DejaVu Sans (the
    pack was left out without matplotlib)."""
    assert "pip install" not in written.stderr and (written.out / "worksheet.html").is_file()
    for name in P.PACK_FILES:
        assert (written.out / name).stat().st_size > 0, name
    if shutil.which("pdftotext"):
        assert "Ключ відповідей" in pdftext(written.out / "key.pdf")


def _drawn(pages, gid: str) -> np.ndarray:
    """The ends (a line) or vertices (an arrowhead) of the primitive `gid` on its page (`a3.pages`), mm."""
    for page in pages:
        for ln in page.lines:
            if ln[7] == gid:
                return np.reshape(ln[:4], (2, 2))
        for pts, _, g in page.polygons:
            if g == gid:
                return np.array(pts)
    raise KeyError(gid)


def test_the_a3_sheet_draws_every_plan_true_to_scale(pack_uk):
    """Measured on the page as the PDF draws it (`a3.pages`, drawn 1:1 by `a3.draw_page`): OA is the key's 32 mm (l_OA / μ_l), a side
    of the force polygon its segments.csv length, every vector of the crank plan drawn (line and
    arrowhead, to its tip) at its length; panels apart and clear of the title block."""
    from kinetostat.plans.a3 import AREA, TITLE_BLOCK, pages
    plans = pack_uk.plans
    figs, drawings, places = pages(pack_uk.a3, "t"), pack_uk.a3.drawings, pack_uk.a3.places
    assert len(figs) == 1 and {p.page for p in places} == {0}
    oa = _drawn(figs, "mechanism/OA")
    assert np.hypot(*(oa[1] - oa[0])) == pytest.approx(0.048 / 0.0015, abs=0.5)           # 32 mm, as the key
    assert plans["mechanism"].length_mm("OA") == pytest.approx(32.0)
    crank = plans["crank"]
    vectors = [s for s in crank.segments if s.kind == "vector"]
    assert {s.name for s in vectors} == {"R21", "R41"}
    for s in vectors + [plans["forces:2,3"].segment("R12")]:
        plan = crank if s in vectors else plans["forces:2,3"]
        start = _drawn(figs, f"{plan.kind}/{s.name}")[0]
        tip = _drawn(figs, f"{plan.kind}/{s.name}^")[0]
        assert np.hypot(*(tip - start)) == pytest.approx(plan.length_mm(s.name), abs=0.5), s.name
    boxes = []
    for d, p in zip(drawings, places):
        x0, y0, x1, y1 = d.box[0] + p.dx, d.box[1] + p.dy, d.box[2] + p.dx, d.box[3] + p.dy
        assert AREA[0] <= x0 and x1 <= AREA[2] and AREA[1] <= y0 and y1 <= AREA[3], d.kind
        assert x1 <= TITLE_BLOCK[0] or y1 <= TITLE_BLOCK[1], d.kind
        for q, b in boxes:
            assert q != p.page or x1 <= b[0] or b[2] <= x0 or y1 <= b[1] or b[3] <= y0, d.kind
        boxes.append((p.page, (x0, y0, x1, y1)))


@needs_poppler
def test_the_a3_pdf_titles_each_plan_with_its_scales(uk_479, pack_uk):
    """Each panel heads its plan with every scale it is drawn at: the force scales of the group,
    crank and lever plans appear on the sheet (at the sheet's own scales, `one_sheet`)."""
    page = pdftext(uk_479 / "plans_a3.pdf")
    plans = pack_uk.plans                                      # a3.one_sheet of variant 1 479 at phi1 = 150 deg, uk
    from kinetostat.plans.draw import scale_text, scales_of
    from kinetostat.plans.symbols import plain
    for kind in ("group:2,3", "crank", "lever"):
        assert len(scales_of(plans[kind])) == 2, kind
        for s in scales_of(plans[kind]):
            assert plain(scale_text(s, "uk")) in page, (kind, scale_text(s, "uk"))     # μ_l set as μ, l below
    assert "1 мм плану = 1 мм" in page


@pytest.mark.parametrize("task, code", [pytest.param(3, "123", marks=pytest.mark.slow), (1, "479")])
def test_the_key_states_each_plans_scales_and_its_arms_agree(task, code, pack_1_479):
    """Every scale each plan is drawn at is in the key (task 1's group loads at 200 N/mm and the
    crank's at 100 N/mm, besides the force plan's μ_F); the crank's arm h_R21 in the values table
    is its length in the segments table (task 3 123 printed 21.86 and 16.4 mm), both at the key's μ_l."""
    from kinetostat.plans.draw import scale_text, scales_of
    p = pack_1_479("en") if (task, code) == (1, "479") else built(task, code, "en", draws=20)
    tables = [x for kind, x in p.key if kind == "table"]
    flat = [c for t in tables for row in t.rows for c in row]
    mu_l = p.plans.scales["mu_l"]
    for kind in p.plans:
        for s in scales_of(p.plans[kind]):
            assert any(scale_text(s, "en") in c for c in flat), (kind, s)
        if kind.startswith(("group", "crank")):
            assert p.plans[kind].scale == mu_l, kind                     # one μ_l for every plan of links
    values = next(t for t in tables if t.head[-1] == "Band of a careful drawing" and
                  any(r[0] == "h_R21" for r in t.rows))
    h_value = next(r[1] for r in values.rows if r[0] == "h_R21")
    segments = tables[-1]
    h_segment = next(r for r in segments.rows if r[1] == "h_R21")
    assert float(h_value) == pytest.approx(float(h_segment[2]), abs=0.06)
    assert h_segment[3] == scale_text(mu_l, "en")
    assert float(h_segment[2]) == pytest.approx(p.plans["crank"].length_mm("h_R21"), abs=0.05)


@needs_poppler
def test_plans_html_prints_each_sheet_on_one_a3_page_at_true_size(uk_479, tmp_path, chromium):
    """Chromium prints plans.html: one A3 landscape page per plan (was two mostly blank pages with
    the sheets at a third of the width), the sheet filling it (its frame 20 mm from the left edge)."""
    page = chromium.new_page()
    page.goto((uk_479 / "plans.html").as_uri())
    page.pdf(path=str(tmp_path / "printed.pdf"), prefer_css_page_size=True)
    page.close()
    info = subprocess.run(["pdfinfo", str(tmp_path / "printed.pdf")], capture_output=True, text=True, check=True).stdout
    n_plans = (uk_479 / "plans.html").read_text(encoding="utf-8").count("<figure>")
    assert n_plans == 8 and int(re.search(r"Pages:\s+(\d+)", info).group(1)) == n_plans
    w, h = map(float, re.search(r"Page size:\s+([\d.]+) x ([\d.]+)", info).groups())
    assert w == pytest.approx(420 / 25.4 * 72, abs=1.5) and h == pytest.approx(297 / 25.4 * 72, abs=1.5)
    box = subprocess.run(["pdftotext", "-bbox", "-f", "1", "-l", "1", str(tmp_path / "printed.pdf"), "-"],
                         capture_output=True, text=True, check=True).stdout
    xs = [float(x) for x in re.findall(r'xMin="([\d.]+)"', box)]
    assert xs and max(xs) > 300 / 25.4 * 72                   # the title block's words at the right, true size


def test_a_zero_vector_has_no_direction():
    """Task 2, 479 at 90 deg: V_BA is 0 (printed so); the key gives it no angle, a non-zero vector keeps its own."""
    v = variants.variant(2, "479")
    rec = {r["key"]: r for r in worksheet(v.mechanism(), float(v.values["phi1"]), lang="uk").records()}
    assert num(rec["V_BA"]["value"], "uk") == "0" and rec["V_BA"]["direction"] == ""
    assert rec["V_B"]["value"] > 1 and rec["V_B"]["direction"].startswith("під кутом")


def test_the_figure_of_a_plan_holds_every_vector(pack_uk):
    """`draw.figure` (notebooks, the reports' PNGs): the crank plan's R21 and R41, drawn as arrows
    that count for no limits, lie inside the axes' limits (they fell outside and were not drawn)."""
    from kinetostat.plans.draw import figure
    plan = pack_uk.plans["crank"]
    ax = figure(plan, "uk").axes[0]
    (x0, x1), (y0, y1) = sorted(ax.get_xlim()), sorted(ax.get_ylim())
    for s in plan.segments:
        for z in (plan.points[s.start], plan.points[s.end]):
            assert x0 <= z.real <= x1 and y0 <= z.imag <= y1, s.name
    assert len([t for t in ax.texts if t.arrow_patch is not None]) == 2          # R21, R41


def test_the_pack_is_built_from_the_callers_analysis(monkeypatch, pack_uk):
    """Given the analyses at phi1 and the A3 sheet (as `variants.write_key` gives them), the pack's
    worksheet, bands and key are built from them, the solver not called again; the same key as
    the pack that makes its own analysis, and as the one `variant` wrote."""
    import kinetostat.solve as S
    from kinetostat.plans.solution import solve
    v = variants.variant(1, "479")
    alone = P.pack(v, lang="uk", a3=pack_uk.a3)
    solution = solve(v.mechanism(), [float(v.values["phi1"])])
    monkeypatch.setattr(S, "analyze", lambda *a, **k: pytest.fail("analyze called"))
    again = P.pack(v, lang="uk", a3=pack_uk.a3, solution=solution)
    assert again.key == alone.key == pack_uk.key and again.bands == alone.bands == pack_uk.bands
