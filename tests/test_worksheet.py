"""The worksheet (issue 12, item 3): seed 002's published values at 30 deg, every value against
`analyze`, the senses by the text's own rule, every bundled model without NaN, the outputs; the
worksheet of a cycle (`worksheet_cycle`, one analysis at N angles) is the one-angle worksheet at each."""
from __future__ import annotations

import functools
import json
import math
import re
from dataclasses import replace

import numpy as np
import pytest

import kinetostat
from conftest import EVERY_KIND, MODELS, sampled
from kinetostat.plans.solution import solve
from kinetostat.plans.worksheet import _NOTE_SYMBOL, worksheet, worksheet_cycle

# seed 002 sec. 1.2.2-1.2.3 at phi = 30 deg (drawn and measured: the text rounds)
SEED_002 = {"V_B": 10.94, "V_BA": 14.92, "V_S2": 12.2, "omega_2": 135.6, "a_A": 7994.38, "a_B": 8311,
            "a_S2": 7875, "eps_2": 33782, "F_i2": 3937.5, "F_i3": 3216.4, "M_i2": 57.43, "R_1_2": 3172,
            "R_0_3": 780.5, "R_3_2": 6481, "M_bal": 102.74, "M_bal_lever": 102.97}


@pytest.fixture(scope="module")
def ice_sheet():
    return worksheet(kinetostat.load("ice_crank_slider"), at=30.0)


@pytest.mark.parametrize("key", SEED_002)
def test_seed_002_published_values(ice_sheet, key):
    assert abs(ice_sheet.value(key)) == pytest.approx(SEED_002[key], rel=0.005)


def test_seed_002_order_and_scale(ice_sheet):
    keys = [r.key for r in ice_sheet.rows]
    text_order = ["V_A", "V_B", "V_BA", "V_S2", "omega_2", "a_A", "an_BA", "at_BA", "a_B", "a_S2", "eps_2",
                  "m_2", "F_i2", "M_i2", "Rt_1_2", "R_1_2", "R_0_3", "R_3_2", "M_bal", "F_bal_lever", "M_bal_lever"]
    assert [k for k in keys if k in text_order] == text_order
    assert ice_sheet.mu_l == 0.001                       # seed 002: mu_l = 0.036 / 36
    assert ice_sheet.value("Rt_1_2") == pytest.approx(1326.37, rel=0.005)
    assert ice_sheet.value("load_0") == pytest.approx(9650.97, rel=1e-6)     # F_p = 0.8 p_max pi d^2 / 4
    assert ice_sheet.value("h_R21") == pytest.approx(32.39, rel=0.005)       # the crank's arm, mm
    assert abs(ice_sheet.value("delta_pct")) < 1e-9


def test_senses_by_the_texts_rule(ice_sheet):
    """Seed 002: the sense of omega2 is that of B turning about A with V_BA moved to B; of eps2,
    that of a^tau_BA moved to B. Here from the worksheet's own vectors' directions."""
    res = kinetostat.analyze(kinetostat.load("ice_crank_slider"), phi_deg=[30.0])
    AB = res.position("B")[0] - res.position("A")[0]
    for key, sym in (("omega_2", "V_BA"), ("eps_2", "at_BA")):
        ang = math.radians(float(ice_sheet.row(sym).direction[6:]))
        turn = AB[0] * math.sin(ang) - AB[1] * math.cos(ang)
        assert ice_sheet.row(key).direction == ("ccw" if turn > 0 else "cw")
    assert ice_sheet.row("omega_2").direction == "ccw" and ice_sheet.row("eps_2").direction == "cw"
    assert ice_sheet.row("omega_1").direction == "cw"                     # the model's crank turns clockwise


def test_every_value_is_analyze_exactly(mech):
    at = getattr(mech.drive, "design_deg", 30.0)
    ws = worksheet(mech, at=at)
    res = kinetostat.analyze(mech, phi_deg=[at])
    expect = {"M_bal": res.balancing_moment[0], "M_bal_lever": res.lever_moment[0]}
    for p in mech.pairs:
        i, j = p.links
        expect[f"R_{i}_{j}"] = np.hypot(*res.reaction(i, j)[0])
    for k in range(1, mech.n_links):
        expect[f"omega_{k}"] = abs(res.omega(k)[0])
        expect[f"eps_{k}"] = abs(res.eps(k)[0])
        if mech.links[k].mass:
            expect[f"F_i{k}"] = np.hypot(*res.F_i[0, k])
    for name in mech.point_names:
        expect[f"V_{name}"] = np.hypot(*res.velocity(name)[0])
        expect[f"a_{name}"] = np.hypot(*res.acceleration(name)[0])
    checked = 0
    for r in ws.rows:
        if r.key in expect:
            assert r.value == pytest.approx(expect[r.key], rel=1e-12, abs=1e-12 * max(1.0, abs(expect[r.key])))
            checked += 1
        assert math.isfinite(r.value), r.key
    assert checked >= 8


def test_outputs(ice_sheet, tmp_path):
    md = ice_sheet.markdown()
    assert "| V_BA | 14.8925 | m/s |" in md
    html = ice_sheet.html()
    assert "<table>" in html and "<td>V<sub>BA</sub></td>" in html
    df = ice_sheet.frame()
    assert list(df.columns) == ["section", "key", "symbol", "value", "unit", "direction", "note"]
    ice_sheet.to_csv(tmp_path / "w.csv")
    ice_sheet.to_json(tmp_path / "w.json")
    doc = json.loads((tmp_path / "w.json").read_text(encoding="utf-8"))
    assert doc["rows"][0]["key"] == "omega_1" and len(doc["rows"]) == len(ice_sheet.rows)
    assert (tmp_path / "w.csv").read_text(encoding="utf-8").splitlines()[0] == "section,key,symbol,value,unit,direction,note"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["w.csv", "w.json"]     # no temporary left
    uk = worksheet(kinetostat.load("ice_crank_slider"), lang="uk")
    assert "за годинниковою стрілкою" in uk.markdown() and "Реакції" in uk.markdown()


HOSTILE = ["*a*", "_b_", "x_y", "__init__", "[l](u)", "a | b", "\\", "\\|", "~~s~~", "`c`", "&amp; <i>", '"q" \'s\'',
           "\u00a0 edge \u3000", "\u2028line\u2029", "\ufefffeff", "tab\there", "nl\nhere", "\x00\x1b[2J", "# h", "> q",
           "- li", "1. li", "---", "    code", "<https://a.b>", "&#65; &copy;", "\\*", "  ", "", "😀 μ_l²_x",
           "a  b"]


@functools.cache
def _markdown_it():
    from markdown_it import MarkdownIt
    return MarkdownIt("commonmark", {"html": False}).enable("table")


def _commonmark(sheet) -> str:
    """The page as markdown-it-py renders the sheet's Markdown (CommonMark with tables, no raw HTML),
    its symbols' scripts inline (`symbols.plain`) as `_flat` reads the page: the rows' symbols and
    notes, and the scale line, as the worksheet's records write them, set flat."""
    from dataclasses import replace
    from kinetostat.plans.worksheet import html_document
    from kinetostat.plans.i18n import num, text
    from kinetostat.plans.symbols import mark, plain
    rows = tuple(replace(r, symbol=plain(mark(rec["symbol"])), note=plain(_NOTE_SYMBOL.sub(lambda m: mark(m.group()), rec["note"])))
                 for r, rec in zip(sheet.rows, sheet.records()))
    body = _markdown_it().render(replace(sheet, rows=rows).markdown())
    body = re.sub(r"^(<p>[^<]*)μ_l", r"\1μl", body, count=1, flags=re.M)                # the scale line
    return html_document(text("ws.title", sheet.lang, name=sheet.mechanism, phi=num(sheet.phi_deg, sheet.lang, 6)),
                         body, sheet.lang)


def _flat(page: str) -> str:
    """The HTML page with its <sub> and <sup> tags taken out (their text left inline)."""
    return re.sub(r"</?su[bp]>", "", page)


def test_the_worksheet_html_sets_symbols_with_true_scripts(ice_sheet):
    """worksheet.html sets each symbol by `symbols`' rule: R12t as R<sub>12</sub><sup>t</sup>,
    a^n_BA as a<sup>n</sup><sub>BA</sub>, a note's m2 as m<sub>2</sub>; no "R12t", "^" or "_"
    left in the text a reader sees."""
    from html import unescape
    for lang in ("en", "uk", "ru"):
        page = replace(ice_sheet, lang=lang).html()
        assert "<td>R<sub>12</sub><sup>t</sup></td>" in page and "<td>a<sup>n</sup><sub>BA</sub></td>" in page
        assert "m<sub>2</sub> g" in page and "ω<sub>1</sub>² l<sub>OA</sub>" in page and "μ<sub>l</sub> = " in page
        seen = unescape(re.sub(r"<(su[bp])>.*?</\1>|<[^>]+>", " ", page.split("<body>")[1]))
        assert not re.search(r"R\d\d[nt]\b|[\^_]", seen), lang


def test_the_html_is_the_markdown_as_commonmark_renders_it(ice_sheet):
    """worksheet.html is written without a Markdown renderer: it is markdown-it-py's page of
    worksheet.md (its symbols' scripts aside: `_flat`) in every language, with the accuracy line, sections that come back (a triad's
    a_S amid its velocities), and hostile names, symbols, units and notes (Markdown, HTML,
    controls, edge spaces)."""
    from dataclasses import replace
    from kinetostat.plans.worksheet import Row
    rows = tuple(Row("kinematics" if i % 3 else "inertia", f"k{i}", h, float(i), h, h, h)
                 for i, h in enumerate(HOSTILE))
    for lang in ("en", "uk", "ru"):
        sheet = replace(ice_sheet, lang=lang)
        assert _flat(sheet.html()) == _commonmark(sheet)
        near = replace(sheet, digits=3.25)
        assert _flat(near.html()) == _commonmark(near) and "<strong>" in near.html()
    hostile = replace(ice_sheet, rows=rows)
    assert _flat(hostile.html()) == _commonmark(hostile)
    for h in HOSTILE:
        titled = replace(ice_sheet, mechanism=f"{h} mechanism {h}", rows=())
        assert _flat(titled.html()) == _commonmark(titled), h


def test_bad_options():
    mech = kinetostat.load("ice_crank_slider")
    with pytest.raises(ValueError, match="lang"):
        worksheet(mech, lang="fr")
    with pytest.raises(ValueError, match="mu_l"):
        worksheet(mech, mu_l=-1.0)


def test_analyze_at_prints_the_worksheet(cli):
    r = cli("analyze", "models/ice_crank_slider.toml", "--at", 30)
    assert r.returncode == 0
    assert "V_BA" in r.stdout and "14.893 m/s" in r.stdout and "ε2" in r.stdout and "F_i2" in r.stdout
    r = cli("analyze", "models/ice_crank_slider.toml", "--at", 30, 60)
    assert "worksheet" not in r.stdout


def test_a_rod_at_rest_has_no_sense():
    """Task 2 of Logvinenko, Nadtoka 2021, variant 479, at phi = 90 deg: the rods translate,
    omega_2 is zero but for rounding (8e-15 rad/s, its sign rounding's), and the worksheet gives
    it no sense; at 60 deg it has one."""
    from kinetostat import variants
    mech = variants.variant(2, "479").mechanism()
    w1 = abs(kinetostat.analyze(mech, phi_deg=[90.0]).omega(1)[0])
    at_rest, moving = worksheet(mech, 90.0), worksheet(mech, 60.0)
    assert 0 < at_rest.value("omega_2") < 1e-12 * w1 and at_rest.row("omega_2").direction == ""
    assert moving.value("omega_2") > 0.1 and moving.row("omega_2").direction in ("cw", "ccw")


def _close(a: float, b: float, scale: float) -> bool:
    return (math.isnan(a) and math.isnan(b)) or abs(a - b) <= 1e-12 * max(abs(a), abs(b), scale)


@pytest.mark.parametrize("friction", ["first", "reactions"])
@pytest.mark.parametrize("path", sampled(MODELS, EVERY_KIND + ("triad_slider",)))     # a triad: its S by angle
def test_the_cycle_is_the_one_angle_worksheet_at_every_angle(path, friction):
    """One analysis at 24 angles, the rows built as arrays: at each angle the same rows (keys,
    symbols, units, notes), values to 1e-12 of the largest of their unit over the cycle (of 100 %; δ not where both balancing moments are rounding), directions to 1e-9 deg,
    as `worksheet(mech, at)`; `.values` holds them, NaN where a row is not written."""
    mech = kinetostat.load(path)
    if friction == "reactions" and mech.friction is None:
        pytest.skip("no [friction]")
    angles = np.arange(0.0, 360.0, 15.0)
    sol = solve(mech, angles, friction)
    res, other = sol.res, sol.other
    cyc = worksheet_cycle(mech, res, 0.002, "uk", other)
    assert cyc.values.shape == (24, len(cyc.rows)) and cyc.n == 24
    largest = {"%": 100.0}                # δ: the lever's and the groups' M_зр agree to rounding
    for r, col in zip(cyc.rows, np.abs(cyc.values).T):
        largest[r.unit] = max(largest.get(r.unit, 0.0), float(np.nanmax(col, initial=0.0)))
    for i, at in enumerate(angles):
        one, got = worksheet(mech, float(at), mu_l=0.002, lang="uk", friction=friction), cyc.at(i)
        assert (got.mechanism, got.phi_deg, got.mu_l, got.digits) == (one.mechanism, one.phi_deg, one.mu_l, one.digits)
        assert [(r.section, r.key, r.symbol, r.unit, r.note) for r in got.rows] == \
            [(r.section, r.key, r.symbol, r.unit, r.note) for r in one.rows], at
        column = dict(zip(cyc.keys, cyc.values[i]))
        dead = abs(one.value("M_bal_lever")) <= 1e-9 * largest["N m"]     # δ = 0/0: a ratio of rounding
        for r, g in zip(one.rows, got.rows):
            assert (dead and r.key == "delta_pct") or _close(g.value, r.value, largest[r.unit]) and _close(column[r.key], r.value, largest[r.unit]), \
                (at, r, g)
            if r.direction.startswith("angle:"):
                assert g.direction.startswith("angle:") and abs(float(g.direction[6:]) - float(r.direction[6:])) < 1e-9
            else:
                assert g.direction == r.direction, (at, r, g)
        written = {r.key for r in one.rows}
        assert all(math.isnan(v) for k, v in column.items() if k not in written)


def test_the_cycle_analyses_nothing(monkeypatch):
    """worksheet_cycle builds from the analyses it is given (the friction rows included): the
    solver is not called again."""
    import kinetostat.solve as S
    mech = kinetostat.load("ice_crank_slider")                  # has [friction]
    sol = solve(mech, [30.0, 60.0])
    res, other = sol.res, sol.other
    monkeypatch.setattr(S, "analyze", lambda *a, **k: pytest.fail("analyze called"))
    cyc = worksheet_cycle(mech, res, 0.001, friction_res=other)
    assert cyc.at(1).value("M_bal_friction") == pytest.approx(float(other.balancing_moment[1]), rel=1e-12)


def test_the_friction_rows_come_from_the_other_mode():
    """A model with [friction]: its friction rows with the analysis in the other mode at the same
    angles, none without it; the wrong mode or other angles: ValueError naming friction_res."""
    mech = kinetostat.load("ice_crank_slider")
    sol = solve(mech, [30.0])
    res, other = sol.res, sol.other
    assert worksheet_cycle(mech, res, 0.001, friction_res=other).at(0).section("friction")
    assert not worksheet_cycle(mech, res, 0.001).at(0).section("friction")
    for bad in (res, solve(mech, [31.0]).other):               # the same mode, other angles
        with pytest.raises(ValueError, match="friction_res: .*friction='reactions'"):
            worksheet_cycle(mech, res, 0.001, friction_res=bad)
    with pytest.raises(ValueError, match="mu_l"):
        worksheet_cycle(mech, res, float("nan"), friction_res=other)
