"""The per-mechanism error reports: the files, their tables, the embedded images, the index,
and the comparison with the seeds' published values."""
from __future__ import annotations

import json
import os
import re
import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest

import kinetostat
import kinetostat.report
from conftest import FOUR_BAR, MODELS, ROOT
from kinetostat.report import published_rows, run_validation, write_index, write_report
from kinetostat.report.document import Doc

pytest.importorskip("matplotlib")

ICE = ROOT / "models" / "ice_crank_slider.toml"
PNGS = ["mechanism.png", "balancing_moment.png", "reactions.png", "errors.png", "hodographs.png"]


@pytest.fixture(scope="module")
def ice_report(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("reports")
    env = {k: v for k, v in os.environ.items() if k != "KINETOSTAT_MODELS"}
    r = subprocess.run([sys.executable, "-m", "kinetostat", "report", str(ICE), "--out", str(out),
                        "--steps", "36", "--engines", "pinocchio", "mujoco"],
                       capture_output=True, text=True, env=env, cwd=ROOT, timeout=300)
    assert r.returncode == 0, r.stdout + r.stderr
    assert "Traceback" not in r.stderr
    assert "ice_crank_slider" in r.stdout and "PASS" in r.stdout
    return out


def test_report_files(ice_report):
    d = ice_report / "ice_crank_slider"
    for name in ["index.md", "index.html", "cycle.csv", "summary.json", *PNGS]:
        assert (d / name).is_file(), name
    for png in PNGS:
        data = (d / png).read_bytes()
        assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 10_000, png
    cycle = pd.read_csv(d / "cycle.csv")
    assert len(cycle) == 36 and {"phi_deg", "M_bal", "M_lever", "R_0_1"} <= set(cycle.columns)
    summary = json.loads((d / "summary.json").read_text())
    n_q = sum(len(kinetostat.report.quantities(kinetostat.load(ICE), r)) for r in ("pinocchio", "mujoco"))
    assert summary["passed"] and summary["checks"] == n_q       # 2 x (M_drive, 4 R, 4 P_f, 4 points x 3)
    assert set(summary["routes"]) == {"pinocchio", "mujoco"}


def test_report_markdown_has_data_tables_and_images(ice_report):
    md = (ice_report / "ice_crank_slider" / "index.md").read_text()
    mech = kinetostat.load(ICE)
    # mechanism data, structure, assumptions
    assert mech.name in md and mech.source in md and "g** = 9.81" in md
    assert mech.assumptions[0] in md
    assert "| id | name | mass, kg | I_S, kg m² |" in md and "| P(0,3) | prismatic |" in md
    assert "3·3 − 2·4 − 0 = **1**" in md and "`I(0,1) <- II(2,3)`" in md
    # the error table: every route x quantity with its tolerance and verdict
    assert "| route | quantity | max abs error | RMS relative | peak relative | tolerance |" in md
    rows = re.findall(r"^\| (pinocchio|mujoco) \| (M_drive|R\(\d,\d\)) \|.*\| \*\*PASS\*\* \|$", md, re.M)
    assert len(rows) == 10
    assert "| route | kind | tolerance (peak-relative) | why this tolerance |" in md
    # the seed's published values, with the difference in %
    assert "## Against the published values" in md
    for symbol, value in [("V_B", "10.94"), ("R32", "6481"), ("M_bal (lever)", "102.97")]:
        assert re.search(rf"^\| {re.escape(symbol)} \|.*\| {value} \|.*%", md, re.M), symbol
    # images linked next to the markdown
    for png in PNGS:
        assert f"]({png})" in md


def test_report_html_is_self_contained(ice_report):
    html = (ice_report / "ice_crank_slider" / "index.html").read_text()
    assert html.count('src="data:image/png;base64,') == len(PNGS)
    assert not re.search(r'src="(?!data:)', html)
    assert "<table>" in html and 'class="pass"' in html
    assert 'href="../index.html"' in html


def test_index_over_reports(ice_report):
    md = (ice_report / "index.md").read_text()
    assert "| model | mechanism | structure formula | pinocchio | mujoco |" in md
    assert "[ice_crank_slider](ice_crank_slider/index.md)" in md and "`I(0,1) <- II(2,3)`" in md
    assert "15/15 within" in md
    html = (ice_report / "index.html").read_text()
    assert 'href="ice_crank_slider/index.html"' in html


def test_report_of_a_model_without_published_values(tmp_path):
    p = tmp_path / "four_bar.toml"
    p.write_text(FOUR_BAR)
    mech = kinetostat.load(p)
    run = run_validation(mech, ["pinocchio"], steps=24, path=p)
    summary = write_report(run, tmp_path / "out")
    md = (tmp_path / "out" / "four_bar" / "index.md").read_text()
    assert summary["passed"] and summary["published"] is None
    assert "published values" not in md and "| pinocchio | R(0,3) |" in md
    write_index(tmp_path / "out")
    assert "[four_bar](four_bar/index.md)" in (tmp_path / "out" / "index.md").read_text()


WITH_PUBLISHED = [p for p in MODELS if kinetostat.load(p).published]


def test_the_seeds_models_have_published_values():
    assert {p.stem for p in WITH_PUBLISHED} >= {"ice_crank_slider", "chain_unit_four_bar"}


@pytest.mark.parametrize("path", WITH_PUBLISHED, ids=[p.stem for p in WITH_PUBLISHED])
def test_published_values_agree(path):
    """Every bundled model's published values agree within their stated accuracy."""
    rows = published_rows(kinetostat.load(path))
    assert rows and all(r.passed for r in rows), [(r.entry.symbol, r.difference) for r in rows if not r.passed]


def test_doc_renders_markdown_and_html():
    doc = Doc("t")
    doc.h(2, "A <b> title")
    doc.table(["a", "b"], [["x|y", "**FAIL**"]], "lr")
    doc.p("see [here](x.md) and `code`")
    md, html = doc.markdown(), doc.html()
    assert "| x\\|y | **FAIL** |" in md and "|---|---:|" in md
    assert "A &lt;b&gt; title" in html and '<td class="fail"><b>FAIL</b></td>' in html
    assert '<a href="x.md">here</a>' in html and "<code>code</code>" in html
