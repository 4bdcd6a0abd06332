"""Lettering at the drafting standard (issue 36, items 4 and 10): a symbol's sub- and superscripts
set as the texts set them (R with 12 below and t above, a with n above and BA below) on the sheets
and in the PDFs, capitals at least 2.5 mm (GOST 2.304), no Latin jargon in uk/ru and no Cyrillic
in en, and the scale wording of the how-to."""
from __future__ import annotations

import re
import warnings
import zlib
from pathlib import Path

import pytest

import kinetostat
import kinetostat.plans as P
from kinetostat.plans.draw import svg
from kinetostat.plans.labels import CAP, MIN_SCRIPT_MM, MIN_TEXT_MM, label_height, label_markup, label_width, text_width
from kinetostat.plans.pdf import Canvas
from kinetostat.plans.symbols import SUB, SUP, html, mark, runs, text_runs

ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.parametrize("name, want", [
    ("R12t", (("R", 0), ("12", SUB), ("t", SUP))),               # seed 002: R with 12 below, τ (t) above
    ("R12n", (("R", 0), ("12", SUB), ("n", SUP))),
    ("a^n_BA", (("a", 0), ("n", SUP), ("BA", SUB))),
    ("μ_l", (("μ", 0), ("l", SUB))),
    ("V_rel(4,3)", (("V", 0), ("rel(4,3)", SUB))),
    ("M_зр", (("M", 0), ("зр", SUB))),
    ("M'_зр", (("M′", 0), ("зр", SUB))),
    ("F_i2(h)", (("F", 0), ("i2", SUB), ("(h)", 0))),
    ("G2*", (("G", 0), ("2", SUB), ("*", 0))),
    ("S2_3", (("S", 0), ("2,3", SUB))),
    ("pi-a", (("πa", 0),)),
    ("n2-b", (("n", 0), ("2", SUB), ("b", 0))),
    ("B3B4", (("B3B4", 0),)),
    ("l_AB/l_OA", (("l", 0), ("AB", SUB), ("/l", 0), ("OA", SUB))),      # a ratio of two symbols                                       # letters after the digits: a name as it is
])
def test_a_symbol_splits_into_base_subscript_and_superscript(name, want):
    assert runs(name) == want


def test_a_text_letters_its_marked_names_and_its_words_with_scripts():
    """μ_l and M'_зр in a text are symbols; "A3" is a word; a marked R12t is a symbol."""
    got = text_runs(f"μ_l = 0.001 m/mm, A3 sheet, {mark('R12t')} = 5 N")
    assert got == (("μ", 0), ("l", SUB), (" = 0.001 m/mm, A3 sheet, R", 0), ("12", SUB), ("t", SUP), (" = 5 N", 0))
    assert html("a^n_BA < 1") == "a<sup>n</sup><sub>BA</sub> &lt; 1"


def test_the_sheet_sets_r12t_with_a_subscript_below_and_a_superscript_above():
    """label_markup: 12 a tspan 0.75 of the size dropped 0.22 of it, t raised 0.33 of it; the
    width and height the placer uses are those of that markup (DejaVu Sans advances)."""
    size = 3.5
    m = label_markup("R12t", size)
    assert m == ('<tspan>R</tspan><tspan font-size="2.62" dy="0.77">12</tspan>'
                 '<tspan font-size="2.62" dy="-1.93">t</tspan>')
    assert label_width("R12t", size) == pytest.approx(text_width("R", size) + text_width("12t", 0.75 * size))
    above, below = label_height("R12t", size)
    assert above == pytest.approx(0.33 * size + 0.93 * 0.75 * size) and below == pytest.approx(0.22 * size + 0.24 * 0.75 * size)


def _content(pdf: bytes) -> str:
    """The page content streams of a PDF (reportlab: Flate, ASCII85 over it), decoded."""
    import base64
    out = []
    for raw in re.findall(rb"stream\r?\n(.*?)endstream", pdf, re.S):
        data = raw.strip()
        try:
            data = base64.a85decode(data, adobe=True) if data.endswith(b"~>") else data
            data = zlib.decompressobj().decompress(data)
        except Exception:             # a font program: not a content stream
            continue
        if b" Tj" in data:
            out.append(data.decode("latin-1"))
    return "\n".join(out)


def test_the_pdf_sets_a_subscript_by_a_smaller_font_and_a_negative_rise():
    """`a^n_BA` and `μ_l`, typed flat in the PDFs before: "R" at 5 mm (14.17 pt), then "12" at
    0.75 of it (10.63 pt) with a rise of -0.22 em (-3.12 pt), "t" raised +0.33 em (4.68 pt)."""
    c = Canvas("t")
    c.page((210.0, 297.0))
    c.text(20.0, 20.0, mark("R12t"), 5.0)
    stream = _content(c.getvalue())
    assert re.search(r"0 Ts /F1\+0 14\.17323 Tf [^()]*\(R\) Tj -3\.11811 Ts /F1\+0 10\.62992 Tf [^()]*\(12\) Tj "
                     r"4\.677165 Ts /F1\+0 10\.62992 Tf [^()]*\(t\) Tj", stream), stream


@pytest.fixture(scope="module")
def ice30():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return P.build(kinetostat.load("ice_crank_slider"), at=30.0)


def _texts(sheet: str) -> list[tuple[float, str]]:
    """Each text's (font size of its letters, words) on an SVG sheet: a tspan's own size where set."""
    out = []
    for attrs, body in re.findall(r"<text([^>]*)>(.*?)</text>", sheet, re.S):
        size = float(re.search(r'font-size="([0-9.]+)"', attrs).group(1))
        spans = re.findall(r"<tspan([^>]*)>([^<]*)</tspan>", body) or [("", body)]
        out += [(float(m.group(1)) if (m := re.search(r'font-size="([0-9.]+)"', a)) else size, t) for a, t in spans]
    return out


def test_capitals_on_a_sheet_are_at_least_2_5_mm(ice30):
    """GOST 2.304: a size is the capitals' height, the smallest 2.5 mm (indices 1.8 mm). DejaVu
    Sans' capital H, read from the font, is CAP em high; every letter of every ICE sheet (labels,
    names, notes, title block) at least 2.5 mm, every script at least 1.8 mm (today: 1.8 mm
    capitals on the labels, 2.5 mm font)."""
    from matplotlib import font_manager
    from matplotlib.ft2font import FT2Font
    font = FT2Font(font_manager.findfont("DejaVu Sans"))
    font.set_size(100, 72)                                         # 100 px an em
    assert CAP == pytest.approx(font.load_char(ord("H")).height / 64 / 100, abs=0.005)
    assert CAP * MIN_TEXT_MM >= 2.5 and CAP * MIN_SCRIPT_MM >= 1.8
    for kind in ice30:
        sheet = svg(ice30[kind], "uk")
        for attrs in re.findall(r"<text([^>]*)>", sheet):              # a text's size: its capitals
            assert float(re.search(r'font-size="([0-9.]+)"', attrs).group(1)) * CAP >= 2.5 - 1e-9, (kind, attrs)
        assert min(s for s, t in _texts(sheet) if t.strip()) * CAP >= 1.8, kind        # a script's


def _words(sheet: str) -> str:
    return re.sub(r"<[^>]+>", "", re.sub(r"(?s)<title>.*?</title>", "", sheet))


@pytest.mark.parametrize("model", ["ice_crank_slider", "slotted_link_shaper", "triad_six_bar", "scotch_yoke"])
def test_uk_and_ru_sheets_name_groups_and_pairs_in_words(model):
    """No group kinds (RRP, RPR, PRP), no P(4,3) in uk/ru: "група 2-3 (2-го класу 2-го виду)",
    "напрямна 4-3" (the guide of the sliding pair 4-3); the mechanism's name in the sheet's language (the triads'
    and the scotch yoke's were English or said RPP)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        plans = P.build(kinetostat.load(model), at=30.0)
    mech = kinetostat.load(model)
    for lang in ("uk", "ru"):
        name = kinetostat.model.lettering.lettering(mech).name(lang, "")
        assert name and not re.search(r"[A-Za-z]{2,}", name), name
        for kind in ("positions", "mechanism", *(k for k in plans if k.startswith("group"))):
            words = _words(svg(plans[kind], lang, mechanism=name))
            assert not re.search(r"\b[RP]{3}\b|\bIII\d\b|\bP\(\d+,\d+\)|guide|branch", words), (model, lang, kind, words)
    words = _words(svg(plans["positions"], "uk"))
    if model == "ice_crank_slider":
        assert "група 2-3 (2-го класу 2-го виду)" in words
        assert "напрямна 4-3" in _words(svg(plans["mechanism"], "uk"))


def test_en_sheets_have_no_cyrillic(ice30):
    """The ICE's lettering is Ukrainian (M_зр, F_зр): its en sheets letter M_bal, F'_bal."""
    for kind in ice30:
        words = _words(svg(ice30[kind], "en"))
        assert not re.search(r"[\u0400-\u04ff]", words), (kind, re.findall(r"\S*[\u0400-\u04ff]\S*", words)[:5])
    assert "bal" in _words(svg(ice30["crank"], "en"))
    assert "зр" in _words(svg(ice30["crank"], "uk"))


def test_ru_sheets_letter_the_balancing_moment_as_russian_texts_do(ice30):
    """Russian texts write the balancing moment and force M_ур, F_ур (уравновешивающий; seed 003:
    "уравновешивающую силу"); the ICE's model letters its Ukrainian text's M_зр, F_зр: its ru
    sheets, the worksheet and the page's steps write M_ур, F'_ур (was: M_зр), its uk ones M_зр and
    its en ones M_bal; a model without lettering (the triad: M_bal) is lettered M_зр in uk."""
    from kinetostat.plans.page import _steps
    from kinetostat.plans.worksheet import worksheet
    from kinetostat.model.lettering import in_lang
    crank = {lang: _words(svg(ice30["crank"], lang)) for lang in ("uk", "ru", "en")}
    lever = {lang: _words(svg(ice30["lever"], lang)) for lang in ("uk", "ru", "en")}
    assert "Mур" in crank["ru"] and "F′ур" in lever["ru"] and "M′ур" in lever["ru"] and "зр" not in crank["ru"] + lever["ru"]
    assert "Mзр" in crank["uk"] and "F′зр" in lever["uk"] and "ур" not in crank["uk"] + lever["uk"]
    assert "Mbal" in crank["en"] and "F′bal" in lever["en"]
    mech = kinetostat.load("ice_crank_slider")
    ws = {lang: {r["key"]: r for r in worksheet(mech, 30.0, lang=lang).records()} for lang in ("uk", "ru")}
    assert ws["ru"]["M_bal"]["symbol"] == "M_ур" and ws["ru"]["delta_pct"]["note"] == "(M'_ур - M_ур) / M'_ур 100 %"
    assert ws["uk"]["M_bal"]["symbol"] == "M_зр"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = kinetostat.analyze(mech, phi_deg=[30.0])
    eqs = " ".join(s["eq"] for s in _steps(mech, res, ice30, "ru"))
    assert "M_ур" in eqs and "зр" not in eqs
    assert (in_lang("M_bal", "uk"), in_lang("M_ур", "uk"), in_lang("F'_зр", "ru"), in_lang("F_КО", "en")) == \
        ("M_зр", "M_зр", "F'_ур", "F_ur")


def test_the_how_to_states_the_drawing_ratio_of_its_length_scale():
    """0.0015 m/mm draws 1 mm for 1.5 mm of the mechanism: 1:1.5 (the how-to said GOST's 1:15)."""
    doc = (ROOT / "docs" / "how-to" / "teachers-pack.md").read_text(encoding="utf-8")
    pairs = re.findall(r"(\d+\.\d+) m/mm, a drawing at 1:([\d.]+)", doc)
    assert pairs
    for mu, ratio in pairs:
        assert float(ratio) == pytest.approx(float(mu) * 1000.0)


@pytest.mark.parametrize("name", ["Кривошипно-повзунний механізм ДВЗ",
                                  "Двотактний ДВЗ з протилежними циліндрами транспортної силової установки "
                                  "(Логвіненко, Надтока 2021, задача 2, варіант 479)"])
def test_the_mechanisms_name_stays_inside_the_title_block(ice30, name):
    """The title block (185 mm, its texts from 3 mm in): the mechanism's name, at 2.5 mm capitals
    at least, in one line where it fits, else in two (was: one line at the least size, running
    20 mm past the frame on task 2's sheets); every text of the block within it."""
    sheet = svg(ice30["crank"], "uk", mechanism=name)
    found = [(x, re.search(r'font-size="([0-9.]+)"', attrs).group(1), ident, body) for x, attrs, ident, body in
             re.findall(r'<text x="([0-9.]+)"([^>]*id="(mechanism(?:-2)?)"[^>]*)>(.*?)</text>', sheet)]
    assert [f[2] for f in found] == (["mechanism"] if len(name) < 60 else ["mechanism", "mechanism-2"]), found
    assert " ".join(re.sub(r"<[^>]*>", "", f[3]) for f in found) == name
    for x, size, _, body in found:
        assert float(size) >= MIN_TEXT_MM
        assert float(x) + text_width(re.sub(r"<[^>]*>", "", body), float(size)) <= 415.0 - 1.0       # the frame, less 1 mm
