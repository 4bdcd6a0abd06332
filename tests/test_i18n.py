"""Languages and lettering of the outputs (issue 20): one catalogue per language (en, uk, ru)
for every word a sheet, worksheet, key or index prints; a uk or ru output holds no English word
of the catalogue; the text's names (R43, R41, M_зр, F_зр, F_p) agree across every output of the
bundled ICE model; `plans` and `variant` write in the language of the model's text by default."""
from __future__ import annotations

import re
import string
import warnings
import xml.etree.ElementTree as ET

import pytest

import kinetostat
import kinetostat.plans as P
from conftest import sketch_report
from kinetostat import variants
from kinetostat.plans.i18n import LANGS, MESSAGES, PHRASES, UNITS, num, phrase, text, unit, words_en
from kinetostat.model.lettering import lettering, with_aliases
from kinetostat.plans.worksheet import worksheet


def _fields(s: str) -> frozenset[str]:
    return frozenset(f for _, f, _, _ in string.Formatter().parse(s) if f)


def test_catalogue_is_complete():
    for key, texts in MESSAGES.items():
        assert len(texts) == len(LANGS) and all(texts), key
        assert len({_fields(t) for t in texts}) == 1, key             # the same {fields} in every language
        assert not re.search(r"[A-Za-z]{4,}", re.sub(r"\{[^}]*\}|`[^`]*`", "", texts[1] + texts[2])), key
    for p in PHRASES:
        assert len(p) == 3 and not re.search(r"[A-Za-z]{3,}", p[1] + p[2]), p
    assert all(len(u) == 3 for u in UNITS.values())


@pytest.mark.parametrize("x, lang, want", [
    (3185.2, "uk", "3185"), (0.001, "ru", "0,001"), (2.852e-17, "uk", "0"), (-0.0, "en", "0"),
    (63.7, "en", "63.7"), (1.5e-5, "en", "0.000015"), (float("nan"), "uk", "—"), (12063.7, "uk", "12060")])
def test_numbers(x, lang, want):
    assert num(x, lang) == want


@pytest.mark.parametrize("n, uk, ru, en", [
    (1, "1 файл", "1 файл", "1 file"), (2, "2 файли", "2 файла", "2 files"), (4, "4 файли", "4 файла", "4 files"),
    (5, "5 файлів", "5 файлов", "5 files"), (11, "11 файлів", "11 файлов", "11 files"),
    (12, "12 файлів", "12 файлов", "12 files"), (21, "21 файл", "21 файл", "21 files"),
    (22, "22 файли", "22 файла", "22 files"), (111, "111 файлів", "111 файлов", "111 files")])
def test_plural_forms(n, uk, ru, en):
    for lang, want in (("uk", uk), ("ru", ru), ("en", en)):
        assert f" {want} -> " in text("cli.plans", lang, name="x", phi="30", scales="", n=n, out="o"), (lang, n)


def test_decimals_and_units():
    assert num(63.7, "uk", decimals=2) == "63,70" and unit("N m", "uk") == "Н·м" and unit("rad/s^2", "ru") == "рад/с²"
    assert phrase("position 0 at phi = 218.9 deg", "uk") == "положення 0 при φ = 218,9°"
    assert text("ws.angle", "ru", angle="12,5") == "под углом 12,5° к оси x"
    with pytest.raises(ValueError, match="lang"):
        text("scale", "fr")


def _words(path) -> str:
    """The words a reader sees in an output file: an SVG's or HTML's text, Markdown less its file
    names (`code` spans, link targets)."""
    raw = path.read_text(encoding="utf-8")
    if path.suffix in (".svg", ".html"):
        raw = re.sub(r"(?s)<style>.*?</style>|<code>[^<]*</code>", " ", raw)      # CSS, file names
        raw = re.sub(r'(</tspan>)?<tspan[^>]*dy="\d[^"]*">', "_", raw)     # a lettered subscript: h_Fp, as written
        raw = re.sub(r"<[^>]+>", " ", re.sub(r"</?tspan[^>]*>", "", raw)).replace("′", "'")    # a prime as typed
    return re.sub(r"`[^`]*`|\]\([^)]*\)", " ", raw)


#: A Latin word standing alone (not part of a symbol such as R43, h_G2, a^Cor, P(3,4), x_B, h_G3,Fp) ...
_LATIN = re.compile(r"(?<![\w^'’\\,])[A-Za-z]{2,}(?![\w^'’(\\])")
#: ... that is a letter name and not English: the Assur groups' kinds (RRP), a segment (ab, pa), cos.
_SYMBOLS = re.compile(r"[RP]{3}|[A-Z]{2}|[a-z]{2}|sin|cos|tan")


def _english(folder, skip: tuple[str, ...] = ()) -> dict[str, set[str]]:
    """English in a folder's outputs: a word of the catalogue's English side, or any other Latin
    word that is not a symbol or a letter name."""
    english = words_en()
    out = {}
    for path in sorted(folder.iterdir()):
        if path.suffix in (".svg", ".md", ".html") and path.name not in skip:
            words = _words(path)
            found = {w for w in re.findall(r"[A-Za-z]{3,}", words) if w.lower() in english}
            found |= {w for w in _LATIN.findall(words) if not _SYMBOLS.fullmatch(w)}
            if found:
                out[path.name] = found
    return out


@pytest.fixture(scope="module")
def ice():
    return kinetostat.load("ice_crank_slider")


@pytest.fixture(scope="module")
def ice_plans(ice):
    return P.build(ice, at=30)


@pytest.mark.parametrize("lang", ["uk", "ru"])
def test_plans_and_worksheet_print_no_english(ice, ice_plans, lang, tmp_path):
    plans = ice_plans
    plans.write(tmp_path, lang=lang)
    worksheet(ice, 30, mu_l=plans.scales["mu_l"].value, lang=lang).write(tmp_path)
    assert _english(tmp_path) == {}
    assert "H" not in (tmp_path / "worksheet.md").read_text(encoding="utf-8").replace("| H", "")


@pytest.mark.parametrize("lang", ["uk", "ru"])
def test_variant_key_and_index_print_no_english(lang, tmp_path):
    v = variants.variant(3, "479")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        key = variants.write_key(v, tmp_path, lang=lang, cycle_csv=False, teacher_pack=False)   # pack: test_pack
    variants.write_index(tmp_path, [key], lang)
    assert _english(tmp_path) == {}
    M = {"uk": "M_зр", "ru": "M_ур"}[lang]                              # as each language's texts write it
    assert f"\\|{M}\\|" in (tmp_path / "index.md").read_text(encoding="utf-8")     # a bar in a table cell
    printed = "\n".join(variants.summary(v, key, tmp_path, lang))     # what `kinetostat variant` prints
    words = re.sub(r"`[^`]*`|\S+\.toml|\S*_\S*|/\S+", "", printed)      # less file names and symbols (P_max)
    assert not {w for w in re.findall(r"[A-Za-z]{3,}", words) if w.lower() in words_en()}, printed
    assert f"{M} = " in printed and "Н·м" in printed


def test_english_is_found_where_it_is(ice_plans, tmp_path):
    """The check itself: an English sheet is caught."""
    (tmp_path / "velocity.svg").write_text(P.draw.svg(ice_plans["velocity"], lang="en"), encoding="utf-8")
    assert "velocity.svg" in _english(tmp_path)


def test_the_texts_names_agree_across_outputs(ice, ice_plans, tmp_path, monkeypatch):
    """Seed 002 numbers the cylinder 4 and writes R43, R41, M_зр, F_зр, F_p: the sheets, the
    worksheet, the report and cycle.csv's aliases say the same, and nothing says R03, R01 or M_bal."""
    L = lettering(ice)
    assert (L.frame, L.M_bal, L.F_bal, L.load("gas force")) == (4, "M_зр", "F_зр", "F_p")
    plans = ice_plans
    plans.write(tmp_path, lang="uk")
    sheets = {p.stem: _words(p) for p in tmp_path.glob("*.svg")}
    ws = worksheet(ice, 30, lang="uk")
    symbols = {r.symbol for r in ws.rows}
    assert {"R43", "R41", "R12", "R32", "R21", "R12t", "R12n", "a^r(4,3)", "M_зр", "F'_зр", "M'_зр", "F_p"} <= symbols
    assert {"R12t", "R12n"} <= {s.name for s in plans["group:2,3"].segments}          # one way, as the sheets
    assert "R43" in sheets["group_2-3"] and "R43" in sheets["forces_2-3"] and "F_p" in sheets["forces_2-3"]
    assert "R41" in sheets["crank"] and "M_зр" in sheets["crank"]
    assert "M'_зр" in sheets["lever"] and "F'_зр" in sheets["lever"]
    from kinetostat.report import run_validation, write_report
    sketch_report(monkeypatch)           # the report's text is read here, not its pictures (the sheets: above)
    write_report(run_validation(ice, [], steps=12), tmp_path / "report")
    (report,) = [f.read_text(encoding="utf-8") for f in (tmp_path / "report").glob("*/index.md")]
    assert re.search(r"^\| M\\?_зр \|", report, re.M) and "| R43 slider B" in report and "| R41 at O |" in report
    assert re.search(r"^\| R43 \| \\\|R43\\\|", report, re.M) and "| M_зр (lever) |" in report.replace("\\_", "_")
    for name, words in list(sheets.items()) + [("worksheet", ws.markdown()), ("report", report)]:
        assert not re.search(r"\bR0\d|\bR\d0\b|M_bal|F_bal|\bP3\b", words), name
    assert plans["forces:2,3"].segment("R43").value == pytest.approx(ws.value("R_0_3"), rel=1e-12)
    frame = with_aliases(kinetostat.analyze(ice, steps=12).to_frame(), ice)
    assert (frame["R_4_3"] == frame["R_0_3"]).all() and (frame["M_зр"] == frame["M_bal"]).all()
    assert frame.attrs["units"]["M_зр"] == "N m"


def test_svg_sheets_parse_in_every_language(ice_plans):
    plan = ice_plans["velocity"]
    for lang in LANGS:
        ET.fromstring(P.draw.svg(plan, lang=lang).encode())


def test_cli_defaults_to_the_texts_language(cli, tmp_path):
    r = cli("plans", "models/ice_crank_slider.toml", "--only", "velocity", "--out", tmp_path / "ice")
    assert r.returncode == 0, r.stderr
    assert "План швидкостей" in (tmp_path / "ice" / "velocity.svg").read_text(encoding="utf-8")     # [lettering] uk
    r = cli("plans", "models/scotch_yoke.toml", "--only", "velocity", "--out", tmp_path / "yoke")
    assert "Velocity plan" in (tmp_path / "yoke" / "velocity.svg").read_text(encoding="utf-8")      # none stated: en
    r = cli("plans", "models/ice_crank_slider.toml", "--only", "velocity", "--lang", "ru", "--out", tmp_path / "ru")
    assert "План скоростей" in (tmp_path / "ru" / "velocity.svg").read_text(encoding="utf-8")
    words = re.sub(r"\S+\.toml|\S*_\S*|/\S+", "", r.stdout)                # less file names and symbols
    assert re.search(r"\b2 файла\b", r.stdout) and not {w for w in re.findall(r"[A-Za-z]{3,}", words) if w.lower() in words_en()}


@pytest.mark.parametrize("table, field", [
    ('frame = 2', "lettering.frame"), ('frame = "4"', "lettering.frame"), ('M_bal = ""', "lettering.M_bal"),
    ('loads = { "gass force" = "F_p" }', "lettering.loads.gass force"), ('language = "fr"', "lettering.language"),
    ('name = { de = "x" }', "lettering.name.de"), ('colour = "red"', "lettering.colour")])
def test_bad_lettering_is_named(table, field):
    text_ = (kinetostat.examples.path("ice_crank_slider").read_text(encoding="utf-8").split("[lettering]")[0]
             + "[lettering]\n" + table + "\n")
    with pytest.raises(kinetostat.ModelError, match=re.escape(field)):
        kinetostat.loads(text_)
