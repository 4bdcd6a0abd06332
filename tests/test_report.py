"""The per-mechanism error reports: the files, their tables, the linked images, the index, the
comparison with the seeds' published values, and the check of a rerun against earlier reports."""
from __future__ import annotations

import contextlib
import gzip
import io
import json
import multiprocessing
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import kinetostat
import kinetostat.report
import kinetostat.tables
from conftest import FOUR_BAR, MODELS, ROOT, sketch_plots, sketch_report
from kinetostat import cli
from kinetostat.report import published_rows, run_validation, write_index, write_report
from kinetostat.report.document import ROUNDING_NOTE, Doc
from kinetostat.report.plots import pair_name
from kinetostat.tables import read_csv

pytest.importorskip("matplotlib")

ICE = ROOT / "models" / "ice_crank_slider.toml"
SHAPER = ROOT / "models" / "slotted_link_shaper.toml"      # a working machine
FIGURES = ["mechanism.svg", "balancing_moment.svg", "reactions.svg", "errors.svg", "hodographs.svg"]


def _report(out: Path, *args: str) -> subprocess.CompletedProcess:
    env = {k: v for k, v in os.environ.items() if k != "KINETOSTAT_MODELS"}
    r = subprocess.run([sys.executable, "-m", "kinetostat", "report", *REPORT_ARGS, "--out", str(out), *args],
                       capture_output=True, text=True, env=env, cwd=ROOT, timeout=300)
    assert r.returncode == 0, r.stdout + r.stderr
    assert "Traceback" not in r.stderr
    return r


REPORT_ARGS = (str(ICE), str(SHAPER), "--steps", "36", "--engines", "pinocchio", "mujoco", "--no-progress", "--no-page")


#: (model, angles, first angle, friction method) of each analysis the report package asked for
#: while `ice_report` was written (`_count_report_analyses`).
REPORT_ANALYSES: list[tuple] = []


def _count_report_analyses(mp: pytest.MonkeyPatch) -> None:
    """Each `analyze` called from the report package (`kinetostat.report.*`) recorded in
    REPORT_ANALYSES (by the numpy path `analyze` takes at a report's few angles)."""
    import kinetostat.solve
    exact = kinetostat.solve.exact

    def counted(mech, phi_deg, friction="first"):
        if sys._getframe(2).f_globals["__name__"].startswith("kinetostat.report"):   # analyze's caller
            REPORT_ANALYSES.append((Path(mech.path).stem, len(phi_deg), float(phi_deg[0]), friction))
        return exact(mech, phi_deg, friction)
    REPORT_ANALYSES.clear()
    mp.setattr(kinetostat.solve, "exact", counted)


@pytest.fixture(scope="module")
def ice_report(tmp_path_factory) -> Path:
    """Two reports written by `kinetostat report` in this process (plots sketched,
    `sketch_plots`; the real plots and worker processes: -m slow) into a folder holding a stale
    report of an earlier run."""
    folder = tmp_path_factory.mktemp("report")
    stale = folder / "stale_model"
    stale.mkdir()
    (stale / "summary.json").write_text(json.dumps(dict(stem="stale_model", name="stale", formula="x",
                                                        passed=True, checks=1, routes={}, published=None)))
    out = io.StringIO()
    with pytest.MonkeyPatch.context() as mp, contextlib.redirect_stdout(out):
        sketch_plots(mp)
        _count_report_analyses(mp)
        assert cli.main(["report", *REPORT_ARGS, "--out", str(folder), "--jobs", "1"]) == 0
    assert "ice_crank_slider" in out.getvalue() and "slotted_link_shaper" in out.getvalue() and "PASS" in out.getvalue()
    return folder


@pytest.mark.slow
def test_reruns_are_byte_identical_and_jobs_do_not_matter(tmp_path):
    """No date, run time or process-dependent byte in any file: a run in one process reproduces
    every file of a run by two worker processes exactly, the real SVG plots included."""
    parallel, serial = tmp_path / "parallel", tmp_path / "serial"
    _report(parallel, "--jobs", "2")
    _report(serial, "--jobs", "1")
    files = sorted(p.relative_to(serial) for p in serial.rglob("*") if p.is_file())
    for f in files:
        assert (parallel / f).read_bytes() == (serial / f).read_bytes(), f
    plans = {m: len(kinetostat.plans.build(kinetostat.load(p))) for m, p in (("ice", ICE), ("shaper", SHAPER))}
    # the index; ice: 5 figures and the sensitivity's, md, html, csv, json, an svg per plan, segments.csv,
    # worksheet.csv; the shaper (no [parameters]: no sensitivity) the balancing force's figure in its place
    assert len(files) == 2 + (10 + plans["ice"] + 2) + (10 + plans["shaper"] + 2)
    for fig in FIGURES:
        data = (serial / "ice_crank_slider" / fig).read_text(encoding="utf-8")
        assert "<svg" in data[:400] and len(data) > 10_000 and "<dc:date>" not in data, fig


def test_a_rerun_writes_the_same_text_files(four_bar_runs):
    """The sample of the above: the text files of a four-bar's report (Markdown, HTML, tables,
    summary) and its index, written twice, are the same bytes (the figures' own reruns: -m slow)."""
    a, b = four_bar_runs / "a", four_bar_runs / "b"
    files = sorted(f.relative_to(a) for f in a.rglob("*") if f.is_file())
    assert {f.suffix for f in files} >= {".md", ".html", ".csv", ".json"}
    assert files == sorted(f.relative_to(b) for f in b.rglob("*") if f.is_file())
    for f in files:
        assert (a / f).read_bytes() == (b / f).read_bytes(), f


def test_report_files(ice_report):
    d = ice_report / "ice_crank_slider"
    for name in ["index.md", "index.html", "cycle.csv.gz", "summary.json", *FIGURES]:
        assert (d / name).is_file(), name
    for fig in FIGURES:
        assert b"<svg" in (d / fig).read_bytes()[:400], fig     # sketched; real ones: -m slow
    cycle = read_csv(d / "cycle.csv.gz")        # gzip, read as it is; the same table as to_frame's CSV
    res = kinetostat.analyze(kinetostat.load(ICE), steps=36)
    assert gzip.decompress((d / "cycle.csv.gz").read_bytes()).decode() == kinetostat.tables.csv_text(res.to_frame())
    assert len(cycle) == 36 and {"phi_deg", "M_bal", "M_lever", "R_0_1"} <= set(cycle.columns)
    assert cycle.attrs["units"]["R_0_1"] == "N" and cycle.attrs["units"]["M_bal"] == "N m"
    summary = json.loads((d / "summary.json").read_text())
    n_q = sum(len(kinetostat.report.quantities(kinetostat.load(ICE), r)) for r in ("pinocchio", "mujoco"))
    n_q += 1 + len(kinetostat.load(ICE).published)  # 2 x (M_drive, 4 R, 4 P_f, 4 points x 3) + lever + 15 published
    assert summary["passed"] and summary["checked"] and summary["checks"] == n_q
    assert set(summary["routes"]) == {"lever", "pinocchio", "mujoco"}
    assert summary["routes"]["pinocchio"]["tolerance"] == 1e-9
    text = (d / "summary.json").read_text() + (d / "index.md").read_text()
    assert not re.search(r"20\d\d-\d\d-\d\d|seconds", text)     # no dates, no run times


def test_verdict_failed_checks_and_contents_on_top(ice_report):
    md = (ice_report / "ice_crank_slider" / "index.md").read_text()
    head = md.split("\n## ")[0]
    lines = [ln for ln in head.splitlines() if ln]
    n = json.loads((ice_report / "ice_crank_slider" / "summary.json").read_text())["checks"]
    assert n > 15 and lines[1].startswith(f"**PASS**: all {n} checks within tolerance")
    assert lines[2] == "Failed checks: none."
    toc = re.findall(r"^- \[(.+)\]\(#([^)]+)\)$", head, re.M)
    sections = re.findall(r"^## (.+)$", md, re.M)
    assert [t for t, _ in toc] == sections and "Errors against the engines" in sections
    # the links of the contents land on the headings' ids in the HTML (a browser decodes the %-escapes)
    from urllib.parse import unquote
    html = (ice_report / "ice_crank_slider" / "index.html").read_text()
    hrefs = [unquote(h) for h in re.findall(r'href="#([^"]+)"', html)]
    ids = re.findall(r'<h2 id="([^"]+)"', html)
    assert hrefs == [a for _, a in toc] == ids


def test_failed_checks_are_listed(tmp_path, sketched_report):
    """A solver answer that is wrong on purpose: the report says FAIL and names the checks."""
    from dataclasses import replace
    p = tmp_path / "four_bar.toml"
    p.write_text(FOUR_BAR)
    mech = kinetostat.load(p)
    res = kinetostat.analyze(mech, steps=24)
    wrong = replace(res, forces=replace(res.forces, M_bal=res.forces.M_bal * 1.01))
    run = run_validation(mech, ["pinocchio"], steps=24, res=wrong, path=p)
    summary = write_report(run, tmp_path / "out")
    md = (tmp_path / "out" / "four_bar" / "index.md").read_text()
    assert not summary["passed"] and summary["failed"] == 2          # pinocchio, and the lever identity
    assert f"**FAIL**: 2 of {len(run.checks)} checks beyond tolerance" in md.split("## ")[0]
    assert re.search(r"^- lever M_drive: peak-relative error 9\.9\de-03 > tolerance 1e-11 ", md, re.M)
    assert re.search(r"^- pinocchio M_drive: peak-relative error 9\.9\de-03 > tolerance 1e-09 "
                     r"\(max [\d.]+ N m at φ = [\d.]+°\)$", md, re.M)


def test_report_markdown_has_data_tables_and_images(ice_report):
    md = (ice_report / "ice_crank_slider" / "index.md").read_text()
    mech = kinetostat.load(ICE)
    # mechanism data, structure, assumptions
    assert mech.name in md and mech.source in md and "g** = 9.81" in md
    assert "| id | name | mass, kg | I_S, kg m² |" in md and "| P(0,3) | prismatic |" in md
    assert "3·3 − 2·4 − 0 = **1**" in md and "`I(0,1) <- II(2,3)`" in md
    # the error table: every route x quantity (named as the text: M_зр, R43) with the angle of its maximum,
    # its tolerance and verdict
    assert ("| route | quantity | max abs error | at φ, deg | peak relative, 1 | tolerance, 1 | RMS relative, 1 |"
            in md)
    rows = re.findall(r"^\| (pinocchio|mujoco) \| (M\\_зр|R\d\d) \| (.*?) \| (.*?) \| (.*?) \| 1e-09 \|"
                      r".*\| \*\*PASS\*\* \|$", md, re.M)
    assert len(rows) == 10
    # exact routes agree to rounding: their digits, marked as at rounding level (angle left out)
    assert all(re.fullmatch(r"\d\.\d\de-1[1-9] N( m)? †", r[2]) and r[3] == "-"
               and re.fullmatch(r"\d\.\d\de-1[5-9] †", r[4]) for r in rows), rows
    assert "≈ 0" not in md and "(rounding)" not in md and not re.search(r"\| rounding[ |]", md)
    assert f"\n{ROUNDING_NOTE}\n" in md
    assert "| route | kind | tolerance (peak-relative, 1) | why this tolerance |" in md
    # the seed's published values, with the difference in %
    assert "## Against the published values" in md
    for symbol, value in [("V_B", "10.94"), ("R32", "6481"), (r"M\_зр (lever)", "102.97")]:
        assert re.search(rf"^\| {re.escape(symbol)} \|.*\| {value} \|.*%", md, re.M), symbol
    # images linked next to the markdown; an engine has no balancing force section
    for fig in FIGURES:
        assert f"]({fig})" in md
    assert "## Balancing force" not in md


def test_machine_report_shows_the_balancing_force(ice_report):
    d = ice_report / "slotted_link_shaper"
    md = (d / "index.md").read_text()
    assert "## Balancing force" in md and "](balancing_force.svg)" in md
    res = kinetostat.analyze(kinetostat.load(SHAPER), steps=36)
    F = np.linalg.norm(res.balancing_force, axis=-1)
    i = int(np.argmax(F))
    assert f"| \\|F\\_зр\\| | {F[i]:.5g} | {res.phi_deg[i]:.4g} |" in md          # the text's F_зр
    assert b"<svg" in (d / "balancing_force.svg").read_bytes()[:400]


def test_report_shows_the_peak_reactions_elasticities(ice_report):
    """The sensitivity section (issue 39): the five largest elasticities of a pair's peak |R| over the
    report's 36 positions, each the peak's own central difference over a reloaded model (h = 1e-6 p);
    a model without [parameters] (the shaper) has no section."""
    md = (ice_report / "ice_crank_slider" / "index.md").read_text()
    section = md.split("## Sensitivity\n", 1)[1].split("\n## ", 1)[0]
    rows = [r.split("|")[1:-1] for r in section.splitlines() if r.startswith("| R")]
    assert len(rows) == 5 and "![Elasticities" in section and (ice_report / "ice_crank_slider" / "sensitivity.svg").is_file()
    elasticities = [float(r[6]) for r in rows]
    assert elasticities == sorted(elasticities, key=abs, reverse=True)
    mech = kinetostat.load(ICE)
    for pair_cell, param, *_, printed in rows:
        pair = next(p for p in mech.pairs if pair_name(mech, p) == pair_cell.strip())
        p, v = param.strip(), {**mech.parameters, "g": mech.g}[param.strip()]

        def peak(x: float) -> float:
            res = kinetostat.analyze(kinetostat.load(ICE, parameters={p: x}), steps=36)
            return float(np.linalg.norm(res.reaction(*pair.links), axis=-1).max())
        h = 1e-6 * v
        assert float(printed) == pytest.approx(v / peak(v) * (peak(v + h) - peak(v - h)) / (2 * h), abs=1e-4)
    assert "## Sensitivity" not in (ice_report / "slotted_link_shaper" / "index.md").read_text()


def test_report_html_is_markdown_it_rendering(ice_report):
    from markdown_it import MarkdownIt
    d = ice_report / "ice_crank_slider"
    html = (d / "index.html").read_text()
    plans = kinetostat.plans.build(kinetostat.load(ICE))
    # the figures and the plans (the sheets of `kinetostat plans`), linked as the files beside the page,
    # never embedded; each plan a link to its SVG file
    for fig in FIGURES:
        assert html.count(f'src="{fig}"') == 1, fig
    for plan in plans.values():
        name = "plan_" + kinetostat.plans.plan_file_name(plan)
        assert f'<a href="{name}"><img src="{name}"' in html
        assert (d / name).read_text() == kinetostat.plans.svg(plan, mechanism=kinetostat.load(ICE).name)
    assert "data:" not in html and "<svg" not in html
    assert html.count('src="sensitivity.svg"') == 1                  # the sensitivity section's tornado chart
    assert html.count("<img ") == len(FIGURES) + 1 + len(plans) and len(html) < 100_000
    assert '<div class="scroll"><table>' in html and 'class="pass"' in html
    assert 'href="../index.html"' in html and 'href="cycle.csv.gz"' in html
    # the body is markdown-it's rendering of the Markdown file (tables as it renders them)
    cell = MarkdownIt("commonmark").enable("table").render("| a |\n|---:|\n| **PASS** |\n")
    assert '<td style="text-align:right"><strong>PASS</strong></td>' in cell
    assert '<td style="text-align:right">' in html and "<strong>PASS</strong>" in html


def test_index_lists_only_this_run(ice_report):
    md = (ice_report / "index.md").read_text()
    # the verdict second, in a table of five columns; the errors route by route in a second table
    assert "| model | result | mechanism; structure formula | published values | plans |" in md
    assert "| model | lever | pinocchio | mujoco |" in md
    assert "[ice_crank_slider](ice_crank_slider/index.md) | **PASS** |" in md and "`I(0,1) <- II(2,3)`" in md
    assert "[plans](ice_crank_slider/index.md#plans-of-the-graphical-method)" in md
    assert "[slotted_link_shaper](slotted_link_shaper/index.md)" in md
    assert "stale" not in md
    # beside each error (its digits, marked at rounding level) the route's tolerance
    assert re.search(r"\| \d\.\d\de-1[5-9] † ≤ 1e-09 PASS \|", md) and f"\n{ROUNDING_NOTE}\n" in md
    assert "rounding ≤" not in md
    assert "15/15 within" in md
    html = (ice_report / "index.html").read_text()
    assert 'href="ice_crank_slider/index.html"' in html and "stale" not in html
    assert 'href="ice_crank_slider/index.html#plans-of-the-graphical-method"' in html
    ice = (ice_report / "ice_crank_slider" / "index.html").read_text()
    assert 'id="plans-of-the-graphical-method"' in ice
    # the sources the reports cite, in full
    assert "## Sources" in md and "**Logvinenko, Nadtoka 2021**: Логвіненко О. А., Надтока О. В." in md


def test_index_links_the_studies_in_its_folder(tmp_path, ice_report):
    summary = json.loads((ice_report / "ice_crank_slider" / "summary.json").read_text())
    write_index(tmp_path, [summary])
    assert "## Studies" not in (tmp_path / "index.md").read_text()
    (tmp_path / "stability.md").write_text("# study\n\nWritten by validation/stability.py.\n\n| a | b |\n|---|---:|\n| x | 1 |\n")
    write_index(tmp_path, [summary])
    md = (tmp_path / "index.md").read_text()
    assert "## Studies" in md and "](stability.html)" in md and "](stability.md)" in md and "drawing_error" not in md
    assert 'href="stability.html"' in (tmp_path / "index.html").read_text()   # the study's HTML, as the reports
    page = (tmp_path / "stability.html").read_text()
    assert page.startswith("<!DOCTYPE html>") and '<h1 id="study">study</h1>' in page and "<table>" in page
    assert page.index("kinetostat_validation") < page.index("Written by validation/stability.py")   # said where it is


def test_reports_cite_their_sources_and_show_no_seed_or_line_number(ice_report):
    """No "seed 00x" and no line number of a source file anywhere a reader sees: the short citations
    ("Logvinenko, Nadtoka 2021") resolve to full references in each report's Sources."""
    for md in ice_report.rglob("index.md"):
        text = md.read_text()
        assert not re.search(r"\bseed 00\d|\blines? \d", text, re.I), md
        if md.parent == ice_report:
            continue                                    # the index lists what the reports cite
        for key in re.findall(r"\*\*([^*]+)\*\*: ", text.partition("## Sources")[2].partition("## Files")[0]):
            assert key in text.partition("## Sources")[0], (md, key)
    md = (ice_report / "ice_crank_slider" / "index.md").read_text()
    assert "- **Potapov 2024**: Потапов В. А." in md and "- **Logvinenko, Nadtoka 2021**:" in md


def test_every_parameter_shows_its_unit():
    from kinetostat.report.writer import parameter_units      # the report's spelling of kinetostat.units
    for path in MODELS:
        units = parameter_units(kinetostat.load(path))
        assert "not stated" not in units.values(), (path.stem, units)
    units = parameter_units(kinetostat.load(ICE))
    assert (units["n1"], units["l_AB"], units["AS2_AB"], units["p_max"], units["I_S2"]) == ("rpm", "m", "1", "Pa", "kg m²")


def test_log_ticks_are_plain_text():
    from kinetostat.report.plots import _decade
    assert [_decade(v) for v in (1e-15, 1e-3, 1.0, 100.0)] == ["1e-15", "1e-3", "1", "1e2"]


@pytest.mark.parametrize("lo, hi, log", [(1000 - 3e-9, 1000 + 3e-9, False), (-312.0, 110.0, False),
                                          (-1.7e-13, 1.7e-13, False), (2e-3, 7e-3, True), (1e-16, 5.6, True)])
def test_the_light_axes_label_ticks_that_read_back_as_the_ticks(lo, hi, log):
    """The figures' own axes (`_axes`): within the view, at least two ticks, each label distinct and
    read back as its grid line's value (to 1e-12 of the view's span): a curve that barely moves
    about 1000, the shaper's moment, the lever's rounding, a log view of less than a decade."""
    from matplotlib.figure import Figure
    from kinetostat.report.plots import _axes
    ax = Figure(figsize=(4, 3)).subplots()
    ax.plot([0, 1], [lo, hi])
    if log:
        ax.set_yscale("log")
    ax.set_ylim(lo, hi)
    _axes(ax, xnumbers=False)                                        # its texts: the y labels only
    ys = ax.texts
    values = [float(t.get_text().replace("−", "-")) for t in ys]
    grid = ax.collections[-1].get_paths()[0].vertices                # one path: its lines NaN apart
    lines = [grid[i:i + 2] for i in range(0, len(grid), 3)]
    assert np.isnan(grid[2::3]).all() and len(lines) * 3 == len(grid)
    across = [a[1] for a, b in lines if a[1] == b[1]]                # the y grid: horizontal lines
    assert len(ys) >= 2 and len(set(t.get_text() for t in ys)) == len(ys)
    np.testing.assert_allclose(values, across, rtol=1e-12 if log else 0, atol=0 if log else 1e-12 * (hi - lo))
    assert all(lo <= v <= hi for v in values)


def test_report_of_a_model_without_published_values(tmp_path, sketched_report):
    p = tmp_path / "four_bar.toml"
    p.write_text(FOUR_BAR)
    mech = kinetostat.load(p)
    run = run_validation(mech, ["pinocchio"], steps=24, path=p)
    summary = write_report(run, tmp_path / "out")
    md = (tmp_path / "out" / "four_bar" / "index.md").read_text()
    assert summary["passed"] and summary["published"] is None
    assert "published values" not in md and "| pinocchio | R03 |" in md
    write_index(tmp_path / "out", [summary])
    assert "[four_bar](four_bar/index.md)" in (tmp_path / "out" / "index.md").read_text()


def test_a_report_is_written_without_pandas(tmp_path, sketched_report, monkeypatch):
    """A report of a model without [study] imports no pandas (its import was most of the cycle table's
    time): cycle.csv.gz is written from `Analysis.columns` (`tables.columns_csv`), the bytes
    `csv_text` writes of `to_frame` (the bool column singular among the floats), gzip-compressed at
    CYCLE_GZIP_LEVEL with no time in it."""
    p = tmp_path / "four_bar.toml"
    p.write_text(FOUR_BAR)
    run = run_validation(kinetostat.load(p), [], steps=12, path=p)
    with monkeypatch.context() as mp:
        mp.setitem(sys.modules, "pandas", None)          # `import pandas` raises ImportError
        write_report(run, tmp_path / "out")
    data = (tmp_path / "out" / "four_bar" / "cycle.csv.gz").read_bytes()
    text = gzip.decompress(data).decode()
    assert text == kinetostat.tables.csv_text(run.res.to_frame()) and ",False\n" in text
    assert data == gzip.compress(text.encode(), compresslevel=kinetostat.report.writer.CYCLE_GZIP_LEVEL, mtime=0)


WITH_PUBLISHED = [p for p in MODELS if kinetostat.load(p).published]


def test_the_seeds_models_have_published_values():
    assert {p.stem for p in WITH_PUBLISHED} >= {"ice_crank_slider", "chain_unit_four_bar"}


@pytest.mark.parametrize("path", WITH_PUBLISHED, ids=[p.stem for p in WITH_PUBLISHED])
def test_published_values_agree(path):
    """Every bundled model's published values agree within their stated accuracy."""
    rows = published_rows(kinetostat.load(path))
    assert rows and all(r.passed for r in rows), [(r.entry.symbol, r.difference) for r in rows if not r.passed]


def test_model_strings_cannot_inject_html_or_links(tmp_path, sketched_report):
    """A model's name is text: markdown-it (raw HTML off) escapes tags; no javascript: link."""
    p = tmp_path / "evil.toml"
    p.write_text(FOUR_BAR.replace('name = "test four-bar"',
                                  'name = "<script>alert(1)</script> [x](javascript:alert(1)) *b*"'))
    run = run_validation(kinetostat.load(p), ["pinocchio"], steps=12, path=p)
    write_report(run, tmp_path / "out")
    html = (tmp_path / "out" / "evil" / "index.html").read_text()
    assert "<script>" not in html and "&lt;script&gt;alert(1)&lt;/script&gt;" in html
    assert 'href="javascript' not in html and "<em>b</em>" not in html


def test_report_cli_errors_become_one_line(tmp_path, monkeypatch, capsys):
    """A model whose report fails is its error line (exit 1), not a traceback; --jobs 0 is bad input."""
    from kinetostat import cli
    from kinetostat import report

    def broken(run, out, folder=None, page=False, friction="first", delta=None, flywheel=None):
        raise RuntimeError("plotting failed\nsecond line")
    monkeypatch.setattr(report, "write_report", broken)
    code = cli.main(["report", str(ICE), "--out", str(tmp_path), "--steps", "12", "--engines", "pinocchio",
                     "--jobs", "1", "--no-progress"])
    err = capsys.readouterr().err
    assert code == 1 and "Traceback" not in err
    assert "kinetostat: error: ice_crank_slider.toml: RuntimeError: plotting failed (no report written)" in err
    if multiprocessing.get_start_method() == "fork":     # the workers inherit the broken write_report
        code = cli.main(["report", str(ICE), str(SHAPER), "--out", str(tmp_path), "--steps", "12",
                         "--engines", "pinocchio", "--jobs", "2", "--no-progress"])
        err = capsys.readouterr().err
        assert code == 1 and "Traceback" not in err
        assert err.count("RuntimeError: plotting failed (no report written)") == 2
    assert cli.main(["report", str(ICE), "--out", str(tmp_path), "--jobs", "0"]) == 2
    assert "invalid number of jobs '0'" in capsys.readouterr().err


def test_doc_renders_markdown_and_html():
    doc = Doc("t")
    doc.h(2, "A <b> title")
    doc.table(["a", "b"], [["x|y", "**FAIL**"]], "lr")
    doc.p("see [here](x/index.md#a) and [study](s.md) and `code` and [bad](javascript:alert(1))")
    md, html = doc.markdown(), doc.html()
    assert "| x\\|y | **FAIL** |" in md and "|---|---:|" in md
    assert '<h2 id="a-b-title">A &lt;b&gt; title</h2>' in html
    assert '<td style="text-align:right" class="fail"><strong>FAIL</strong></td>' in html
    assert '<a href="x/index.html#a">here</a>' in html and "<code>code</code>" in html
    assert '<a href="s.md">study</a>' in html         # only a report's index.md becomes its HTML page
    assert 'href="javascript' not in html


def test_doc_parses_plain_texts_at_once_into_markdown_its_own_tokens():
    """`Doc.html`'s markdown-it skips the inline parse of a text without markup (`document._inline`):
    the tokens are plain markdown-it's for every inline rule's markup, in paragraphs, headings and cells."""
    from markdown_it import MarkdownIt
    from kinetostat.report.document import _markdown_it
    texts = ["plain 1.5e-05 N·m (at 30°): ~ $ # % + - = > @ ^ { } ≤ 3", "*em* and **strong**", "R_0_1 and _x_",
             "a \\* b", "c \\# d", "`code`", "[link](x.md)", "![image](a.svg)", "<http://example.com>", "&amp; &lt;",
             "line\nbreak", "hard  \nbreak", ""]
    md = "\n\n".join([f"## {texts[1]}", *texts, "| a | b |\n|---|---:|\n" + "".join(f"| {t} | {t} |\n" for t in texts
                                                                            if "\n" not in t)])
    assert _markdown_it().parse(md) == MarkdownIt("commonmark", {"html": False}).enable("table").parse(md)


def test_an_error_at_rounding_level_keeps_its_digits_and_is_marked():
    """The rule: below 1000 ulp of the peak (2.2e-13 of it) an error is at rounding level: its
    digits printed, the mark beside them; an exact 0 is 0."""
    from kinetostat.report.document import ROUNDING, _err, _rel
    assert ROUNDING == pytest.approx(2.22e-13, rel=1e-3)
    assert _err(8.0452e-14, 1200.0, "N") == "8.05e-14 N †"
    assert _err(8.0452e-14, 0.1, "N") == "8.05e-14 N"         # 8e-13 of a 0.1 N peak: a real number
    assert _rel(1.1e-15) == "1.10e-15 †" and _rel(3e-13) == "3.00e-13" and _rel(0.0) == _err(0.0, 1.0, "N")[:1] == "0"


def test_report_shows_friction_in_the_reactions_beside_the_first_approximation(ice_report):
    """The ICE has [friction]: its M_bal at the design position with friction in the reactions and
    in the first approximation (numbers from analyze), the self-locking zone near top dead centre
    with its edges, and the checks; the shaper (no friction) has no such section."""
    md = (ice_report / "ice_crank_slider" / "index.md").read_text()
    mech = kinetostat.load(ICE)
    exact = kinetostat.analyze(mech, [30.0], friction="reactions")
    first = kinetostat.analyze(mech, [30.0], friction="first")
    row = re.search(r"^\| M\\_зр at φ = 30°, N·m \| (\S+) \| (\S+) \| (\S+) \|$", md, re.M)
    assert row and [float(x) for x in row.groups()] == pytest.approx(
        [first.balancing_moment[0], first.balancing_moment_with_friction[0], exact.balancing_moment[0]], rel=1e-3)
    assert "| quantity | frictionless | first approximation | friction in the reactions |" in md
    zone = re.search(r"edges to 1e-9° by bisection on the crank angle: 0\.000000000° to (1\.\d{9})°", md)
    assert zone and 1.0 < float(zone.group(1)) < 2.0
    assert "their joint friction is a constant limit torque" in md
    checks = md.split("## Friction in the reactions")[1].split("\n## ")[0]
    assert re.search(r"max \|difference\| \d\.\d+e-1\d N·m †", checks) and ROUNDING_NOTE in checks
    assert "## Friction in the reactions" not in (ice_report / "slotted_link_shaper" / "index.md").read_text()


@pytest.fixture(scope="module")
def four_bar_runs(tmp_path_factory) -> Path:
    """The four-bar's report and index written twice (plots and plan sheets sketched), into a/ and b/."""
    folder = tmp_path_factory.mktemp("reruns")
    p = folder / "four_bar.toml"
    p.write_text(FOUR_BAR)
    with pytest.MonkeyPatch.context() as mp:
        sketch_report(mp)
        for name in ("a", "b"):
            summary = write_report(run_validation(kinetostat.load(p), [], steps=12, path=p), folder / name)
            write_index(folder / name, [summary])
    return folder


def _rerun(runs: Path, tmp_path: Path) -> tuple[Path, Path]:
    """A copy of the rerun b/ to change, and the earlier run a/."""
    return Path(shutil.copytree(runs / "b", tmp_path / "b")), runs / "a"


def test_the_check_passes_a_rerun_and_names_only_a_number_beyond_its_tolerance(tmp_path, four_bar_runs):
    """compare_reports on a real rerun: nothing; then, in the rerun, a reaction moved by 1e-9 of the
    force scale (beyond 1e-11), the balancing moment by 3e-12 of its scale, the lever's error at
    rounding level changed and an error figure of the index rewritten (all within): exactly the
    reaction is named, with its angle, both values and the tolerance."""
    import pandas as pd
    from kinetostat.report import compare_reports
    b, a = _rerun(four_bar_runs, tmp_path)
    assert compare_reports(b, a) == []
    cycle = b / "four_bar" / "cycle.csv.gz"
    df = pd.read_csv(cycle)
    force = max(df[c].abs().max() for c in df.columns if c.endswith(" [N]"))
    moment = max(df[c].abs().max() for c in df.columns if c.endswith(" [N m]"))
    df.loc[3, "R_0_1 [N]"] += 1e-9 * force
    df.loc[5, "M_bal [N m]"] += 3e-12 * moment
    df.to_csv(cycle, index=False, float_format="%.17g")         # gzip, by the name's suffix
    summary = b / "four_bar" / "summary.json"
    data = json.loads(summary.read_text())
    assert 0 < data["routes"]["lever"]["worst"] < 1e-13
    data["routes"]["lever"]["worst"] *= 1.7
    summary.write_text(json.dumps(data, indent=1))
    index = b / "index.md"
    text = index.read_text()
    figure = re.search(r"\d\.\d\de-1\d †", text).group(0)
    index.write_text(text.replace(figure, "9.99e-15 †"))
    diffs = compare_reports(b, a)
    phi = float(df.loc[3, "phi_deg [deg]"])
    assert [(d.model, d.file, d.what, d.where) for d in diffs] == [("four_bar", "cycle.csv.gz", "R_0_1 [N]", f"φ = {phi:g}°")]
    was = float(pd.read_csv(a / "four_bar" / "cycle.csv.gz").loc[3, "R_0_1 [N]"])
    assert float(diffs[0].committed) == pytest.approx(was, rel=1e-11)
    assert float(diffs[0].fresh) == pytest.approx(was + 1e-9 * force, rel=1e-11)
    assert str(diffs[0]).startswith("four_bar/cycle.csv.gz: R_0_1 [N] at φ = ") and f"1e-11 of the N scale {force:.6g} N" in str(diffs[0])


def test_the_check_leaves_out_the_index_studies_and_still_reads_the_lines_after_them(tmp_path, four_bar_runs):
    """The committed folder holds a study (its index lists it under "Studies"), a rerun into an
    empty folder does not: no difference. A word changed after that section is still named, at
    the rerun's line."""
    from kinetostat.report import compare_reports
    b, _ = _rerun(four_bar_runs, tmp_path)
    a = Path(shutil.copytree(four_bar_runs / "a", tmp_path / "a"))
    (a / "stability.md").write_text("# Stability\n")
    write_index(a, [json.loads((a / "four_bar" / "summary.json").read_text())])
    assert "## Studies" in (a / "index.md").read_text() and 'id="studies"' in (a / "index.html").read_text()
    assert compare_reports(b, a) == []
    text = (b / "index.md").read_text().splitlines()
    n = next(i for i, line in enumerate(text, 1) if line == "The works the reports cite.")
    (b / "index.md").write_text("\n".join(text).replace("The works the reports cite.", "The works cited.") + "\n")
    assert [(d.file, d.what, d.where) for d in compare_reports(b, a)] == [("index.md", "text", f"line {n}")]


def test_the_check_names_a_changed_verdict_a_missing_file_and_a_changed_line(tmp_path, four_bar_runs):
    """Beyond numbers: a route's status, a file only one side has, a word of the Markdown."""
    from kinetostat.report import compare_reports
    b, a = _rerun(four_bar_runs, tmp_path)
    d = b / "four_bar"
    data = json.loads((d / "summary.json").read_text())
    data["routes"]["lever"]["status"] = "FAIL"
    (d / "summary.json").write_text(json.dumps(data, indent=1))
    (d / "worksheet.csv").unlink()
    (d / "index.md").write_text((d / "index.md").read_text().replace("Mechanism data", "Mechanism figures"))
    found = {(x.file, x.what, x.fresh, x.committed) for x in compare_reports(b, a)}
    assert ("summary.json", "routes.lever.status", '"FAIL"', '"PASS"') in found
    assert ("worksheet.csv", "file", "absent", "present") in found
    assert any(f == "index.md" and w == "text" and "figures" in a and "data" in b for f, w, a, b in found)
    assert len(found) == 3 + 1       # and the table of contents' line naming the same heading


def test_the_check_names_a_cycle_table_that_is_not_gzip_cut_short_or_a_bomb(tmp_path, four_bar_runs, monkeypatch):
    """The rerun's cycle.csv.gz is read decompressed within MAX_REPORT_BYTES: a file that is not
    gzip, one cut short, and one that inflates beyond the limit (a 'zip bomb') are each named as
    not read, never inflated into memory whole."""
    from kinetostat.report import compare_reports, rerun
    b, a = _rerun(four_bar_runs, tmp_path)
    cycle = b / "four_bar" / "cycle.csv.gz"
    whole = cycle.read_bytes()
    limit = 4 * max(f.stat().st_size for f in b.rglob("*") if f.is_file())     # a bomb of a test's size
    monkeypatch.setattr(rerun, "MAX_REPORT_BYTES", limit)
    assert compare_reports(b, a) == []
    for data, why in ((b"phi_deg [deg]\n0\n", "not gzip"), (whole[:len(whole) // 2], "cut short"),
                      (gzip.compress(b"0" * (limit + 1)), "bytes decompressed")):
        cycle.write_bytes(data)
        diffs = compare_reports(b, a)
        assert [(d.file, d.what) for d in diffs] == [("cycle.csv.gz", "file")], diffs
        assert why in diffs[0].committed and "a regular file" == diffs[0].tolerance, diffs[0]


def test_report_check_refuses_its_own_output_folder_and_a_missing_one(tmp_path, capsys):
    """--check names a folder of earlier reports other than --out: else exit 2 and one error line,
    before any model runs."""
    for check in (tmp_path, tmp_path / "nowhere"):
        code = cli.main(["report", str(ICE), "--out", str(tmp_path), "--check", str(check), "--no-progress"])
        err = capsys.readouterr().err
        assert code == 2 and "Traceback" not in err and f"--check {check}:" in err, err


def test_report_check_says_a_rerun_reproduces_or_prints_each_difference(tmp_path, capsys, sketched_report):
    """`kinetostat report --out B --check A`: a rerun that reproduces A exits 0 and says so; where
    it differs (A's count of checks edited), each difference is printed and the command fails."""
    p = tmp_path / "four_bar.toml"
    p.write_text(FOUR_BAR)
    args = ["report", str(p), "--steps", "12", "--engines", "none", "--no-page", "--no-progress", "--jobs", "1"]
    assert cli.main([*args, "--out", str(tmp_path / "a")]) == 0
    capsys.readouterr()
    assert cli.main([*args, "--out", str(tmp_path / "b"), "--check", str(tmp_path / "a")]) == 0    # a rerun
    assert f"check: {tmp_path / 'b'} reproduces {tmp_path / 'a'} within every tolerance" in capsys.readouterr().out
    summary = tmp_path / "a" / "four_bar" / "summary.json"
    summary.write_text(summary.read_text().replace('"checks": ', '"checks": 1'))
    from kinetostat.cli.report import _check           # the command's last step, on B as written
    assert _check(tmp_path / "b", tmp_path / "a") is False
    out = capsys.readouterr().out
    assert re.search(r"^check: four_bar/summary.json: checks: rerun (\d+), committed 1\1 \(tolerance: equal\)$", out, re.M)
    assert "check: 1 difference(s)" in out


def _outline(d: str, relative: bool) -> list[tuple]:
    """An SVG path's data as absolute commands with their points: (letter, x, y, ...) each, "z"
    alone; relative data (m, l, c, q: steps from the current point, a repeated letter left out)
    summed back."""
    out: list[tuple] = []
    here = start = np.zeros(2)
    for cmd, numbers in re.findall(r"([MLCQZmlcqz])([^MLCQZmlcqz]*)", d):
        if cmd in "zZ":
            out.append(("z",))
            here = start
            continue
        v = np.array([float(x) for x in re.findall(r"-?(?:\d+\.?\d*|\.\d+)", numbers)]).reshape(-1, 2)
        k = {"m": 1, "l": 1, "q": 2, "c": 3}[cmd.lower()]
        for i in range(0, len(v), k):                                  # a letter left out: the command again
            pts = here + v[i:i + k] if relative else v[i:i + k]
            out.append(("L" if cmd in "mM" and i else cmd.upper(), *pts.ravel()))
            here = pts[-1]
            if cmd in "mM" and not i:
                start = here
    return out


def test_figures_keep_every_coordinate_to_a_tenth_of_a_point_in_fewer_bytes():
    """`plots._compact`: the same paths (commands, and points to 0.05 pt: relative steps of 0.1 pt
    that add up to the rounded points), texts and markers (places to 0.005 pt) in under half of
    matplotlib's bytes of coordinates; everything else untouched but a text's rotation by 0° and
    the texts' font, named once in the style sheet (DejaVu Sans, `plain_text`)."""
    from matplotlib.backends.backend_svg import FigureCanvasSVG
    from matplotlib.figure import Figure
    from matplotlib.patches import PathPatch
    from matplotlib.path import Path
    from kinetostat.report.plots import _compact, plain_text
    with plain_text():
        fig = Figure(figsize=(4, 3))
        x = np.linspace(0, 2 * np.pi, 361)
        wiggle = np.random.default_rng(1).normal(size=x.size)         # kept by matplotlib's path simplification
        ax = fig.add_subplot()
        ax.plot(x, np.sin(x) + 0.1 * wiggle, x, 1e-3 * wiggle)
        ax.plot(x[::40], np.cos(x[::40]), "o")                          # markers: C commands, then z
        ax.add_patch(PathPatch(Path.make_compound_path(Path.unit_rectangle(), Path.unit_circle())))   # z, then m
        buf = io.StringIO()
        FigureCanvasSVG(fig).print_svg(buf, metadata={"Date": None, "Creator": None})
    svg = buf.getvalue()
    small = _compact(svg)
    data, places = re.compile(r' d="([^"]*)"'), re.compile(r' (?:x|y|transform)="([^"]*)"')
    before, after = data.findall(svg), data.findall(small)
    assert len(before) == len(after) > 2 and sum(map(len, after)) < 0.5 * sum(map(len, before))
    assert any("C" in d for d in before) and any("z" in d for d in before)
    for a, b in zip(before, after):
        wide, short = _outline(a, relative=False), _outline(b, relative=True)
        assert [c[0] for c in wide] == [c[0] for c in short]                    # the same commands
        np.testing.assert_allclose(np.concatenate([c[1:] for c in short]), np.concatenate([c[1:] for c in wide]),
                                   atol=0.05 + 1e-9)
    unrotated = re.sub(r' transform="rotate\(-?0 [-\d. ]+\)"', "", svg)
    before, after = places.findall(unrotated), places.findall(small)
    assert len(before) == len(after) > 2 and len(unrotated) < len(svg)
    for a, b in zip(before, after):
        assert re.sub(r"[-\d.]+", "#", " ".join(a.split())) == re.sub(r"[-\d.]+", "#", b)
        np.testing.assert_allclose([float(v) for v in re.findall(r"-?\d+\.?\d*", b)],
                                   [float(v) for v in re.findall(r"-?\d+\.?\d*", a)], atol=0.005 + 1e-12)
    font = "font-family: 'DejaVu Sans', sans-serif"
    rest = lambda text: places.sub("", data.sub("", text)).replace(font + "; ", "").replace("; " + font, "")
    assert rest(small) == rest(unrotated).replace("<style type=\"text/css\">*{", "<style type=\"text/css\">text{%s}*{" % font)
    assert small.count(font) == 1 and svg.count(font) > 5 and "Bitstream" not in small



def test_a_report_analyses_each_set_of_angles_once(ice_report):
    """The report's parts at the same angles and friction method share one analysis (`ModelRun.at`):
    the ICE (published values at 30°, its design position; [friction]) is analysed by the report
    package once at 30° frictionless, once at 30° and once over the cycle with friction in the
    reactions, the shaper (no friction) once at 30°; each once more at 30° at its true law of motion
    (the law-of-motion section: another motion, another analysis); the cycle itself is the run's
    `res`, never analysed again. (The plans, drawn by `kinetostat.plans` from their own analysis,
    are not counted.)"""
    assert sorted(REPORT_ANALYSES) == [("ice_crank_slider", 1, 30.0, "first"), ("ice_crank_slider", 1, 30.0, "first"),
                                       ("ice_crank_slider", 1, 30.0, "reactions"), ("ice_crank_slider", 36, 0.0, "reactions"),
                                       ("slotted_link_shaper", 1, 30.0, "first"), ("slotted_link_shaper", 1, 30.0, "first")]
