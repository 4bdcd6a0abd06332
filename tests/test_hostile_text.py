"""Hostile names and expressions in what kinetostat writes (issue 22, points 9, 10): every XML
writer (MJCF, URDF, SVG sheets) stays well-formed, no CSV cell is a formula, Markdown carries
no tag, the terminal gets no escape sequence, and a newline cannot forge an error line. A model
file's names hold no control character (the reader refuses them, issue 35): the XML writers are
checked with such a name given through the API, the terminal with the reader's refusal."""
from __future__ import annotations

import csv
import io
import xml.etree.ElementTree as ET
from dataclasses import replace
from pathlib import Path

import pytest

import kinetostat
import kinetostat.plans as P

from conftest import FOUR_BAR, ROOT

ICE = ROOT / "models" / "ice_crank_slider.toml"
CONTROLS = "a\\nb\\u0001c\\u000bd\\ufffee"          # TOML escapes: newline, U+0001, U+000B, U+FFFE
FORMULA_POINT, FORMULA_LOAD = "=1+2", "-2+3+cmd|' /C calc'!A0"
TERMINAL = "\\u001b]52;c;ZXZpbA==\\u0007\\u001b[2Jname"   # OSC 52 (sets the clipboard), ESC [2J (clears)


def _model(tmp_path: Path, name: str = "four-bar", point: str = "P", load: str = "resisting moment") -> Path:
    text = (FOUR_BAR.replace('name = "test four-bar"', f'name = "{name}"')
            .replace('S3 = [0.12, -0.01] }', f'S3 = [0.12, -0.01], "{point}" = [0.2, 0.05] }}')
            .replace('name = "resisting moment"', f'name = "{load}"'))
    p = tmp_path / "m.toml"
    p.write_text(text, encoding="utf-8")
    return p


# ============================================================================ 9. XML writers

def _named(tmp_path: Path, name: str):
    """The model of `_model` renamed `name` through the API (a model file's name cannot hold it)."""
    return replace(kinetostat.load(_model(tmp_path)), name=name)


@pytest.mark.parametrize("fmt", ["mjcf", "urdf"])
def test_export_of_a_name_with_control_characters_is_well_formed(fmt, tmp_path):
    from kinetostat_validation.export import to_mjcf, to_urdf
    text = (to_mjcf if fmt == "mjcf" else to_urdf)(_named(tmp_path, CONTROLS.encode().decode("unicode_escape")))
    root = ET.fromstring(text)                      # ParseError before
    assert root.tag == ("mujoco" if fmt == "mjcf" else "robot")
    assert "a\\nb\\x01c\\x0bd\\ufffee" in text      # the name, its controls visible
    assert not any(c in text for c in "\x01\x0b\ufffe")


def test_every_svg_sheet_of_a_name_with_control_characters_is_well_formed(tmp_path):
    out = tmp_path / "plans"
    P.build(_named(tmp_path, CONTROLS.encode().decode("unicode_escape"))).write(out)
    sheets = sorted(out.glob("*.svg"))
    assert len(sheets) >= 3
    for sheet in sheets:
        text = sheet.read_text(encoding="utf-8")
        ET.fromstring(text)                         # ParseError before
        assert "\x01" not in text and "\ufffe" not in text
    assert "\\x01" in (out / "positions.svg").read_text(encoding="utf-8")


# ============================================================================ 10. spreadsheets, Markdown, terminal

def _cells(path: Path) -> list[str]:
    return [c for row in csv.reader(io.StringIO(path.read_text(encoding="utf-8"))) for c in row]


def _formula(cell: str) -> bool:
    """A cell a spreadsheet would run: it starts with = + - @ and is no number."""
    if not cell.startswith(("=", "+", "-", "@", "\t", "\r")):
        return False
    try:
        float(cell)
        return False
    except ValueError:
        return True


def test_no_csv_cell_is_a_formula(tmp_path, cli):
    """A point '=1+2' and a load "-2+3+cmd|' /C calc'!A0" became formula cells in segments.csv
    and worksheet.csv; the bundled ICE worksheet held '= -R12'. Each is now led by a quote."""
    out = tmp_path / "plans"
    p = cli("plans", _model(tmp_path, point=FORMULA_POINT, load=FORMULA_LOAD.replace("'", "\\u0027")), "--out", out)
    assert p.returncode == 0, p.stderr
    ice = tmp_path / "ice"
    assert cli("plans", ICE, "--out", ice).returncode == 0
    for path in (out / "segments.csv", out / "worksheet.csv", ice / "segments.csv", ice / "worksheet.csv"):
        cells = _cells(path)
        assert not [c for c in cells if _formula(c)], path
    assert "'= -R12" in _cells(ice / "worksheet.csv")
    assert any(c.startswith("'=1+2") for c in _cells(out / "segments.csv"))
    assert any(c.startswith("-") for c in _cells(ice / "segments.csv"))    # negative numbers stay numbers


def test_worksheet_markdown_carries_no_tag_from_a_name(tmp_path, cli):
    out = tmp_path / "plans"
    p = cli("plans", _model(tmp_path, name="<script>alert(1)</script> [x](javascript:alert(2)) a|b __bold__ _em_"),
            "--out", out)
    assert p.returncode == 0, p.stderr
    md = (out / "worksheet.md").read_text(encoding="utf-8")
    assert "<script" not in md and "&lt;script>alert(1)&lt;/script>" in md
    assert "\\[x\\](javascript:alert(2))" in md and "a\\|b" in md
    assert "\\_\\_bold\\_\\_ \\_em\\_" in md                   # no emphasis from underscores
    assert "<script" not in (out / "worksheet.html").read_text(encoding="utf-8")


@pytest.mark.parametrize("command", ["analyze", "structure", "sweep"])
def test_terminal_escapes_in_a_name_are_refused_as_text(command, tmp_path, cli):
    model = _model(tmp_path, name=TERMINAL)
    more = {"analyze": ["--steps", "4"], "structure": [],
            "sweep": ["--param", "m3=1.0,1.2", "--steps", "4", "--out", tmp_path / "s.csv", "--no-progress"]}
    p = cli(command, model, *more[command])
    assert p.returncode == 2 and "mechanism.name: " in p.stderr, p.stderr
    assert "\x1b" not in p.stdout + p.stderr and "\x07" not in p.stderr
    assert "\\x1b]52;c;ZXZpbA==\\x07\\x1b[2Jname" in p.stderr


def test_a_newline_in_an_expression_cannot_forge_an_error_line(tmp_path, cli):
    model = tmp_path / "m.toml"
    model.write_text(FOUR_BAR.replace("mass = 1.5", 'mass = "1.5 +\\nkinetostat: error: none, all is well"'),
                     encoding="utf-8")
    p = cli("analyze", model, "--steps", "4")
    assert p.returncode == 2 and "Traceback" not in p.stderr
    assert p.stderr.count("kinetostat: error:") == 2 and p.stderr.count("\n") == 1, p.stderr   # one line
    assert '"1.5 +\\nkinetostat: error: none' in p.stderr


FORGED = "a\\nkinetostat: error: forged"       # a TOML escape: a newline in the name


@pytest.mark.parametrize("command", ["analyze", "structure", "sweep"])
def test_a_newline_in_a_name_cannot_forge_a_line(command, tmp_path, cli):
    model = _model(tmp_path, name=FORGED)
    more = {"analyze": ["--steps", "4"], "structure": [],
            "sweep": ["--param", "m3=1.0,1.2", "--steps", "4", "--out", tmp_path / "s.csv", "--no-progress"]}
    p = cli(command, model, *more[command])
    assert p.returncode == 2 and p.stdout == "", p.stderr
    lines = p.stderr.splitlines()
    assert [line for line in lines if line.startswith("kinetostat:")] == lines[:1], p.stderr   # the refusal's own
    assert "mechanism.name: 'a\\nkinetostat: error: forged' holds the control character U+000A" in p.stderr


@pytest.mark.parametrize("case", ["out", "model"])
def test_a_newline_in_a_path_is_one_error_line(case, tmp_path, cli):
    """An --out folder that cannot be made (under a file) and a missing model file, each named
    with a newline: one "kinetostat: error:" line, the newline printed as \\n."""
    (tmp_path / "file").write_text("x")
    bad = f"{tmp_path}/file/x\nkinetostat: error: forged"
    args = ["plans", ICE, "--out", bad] if case == "out" else ["analyze", f"{tmp_path}/no\nkinetostat: error: forged"]
    p = cli(*args)
    assert p.returncode == 2 and "Traceback" not in p.stderr
    assert p.stderr.count("\n") == 1 and p.stderr.count("kinetostat: error:") == 2, p.stderr
    assert "\\nkinetostat: error: forged" in p.stderr


def test_a_model_files_problem_list_keeps_one_line_per_problem(tmp_path, cli):
    model = tmp_path / "m.toml"
    model.write_text(FOUR_BAR.replace("mass = 1.5", 'mass = "x\\ny"').replace("mass = 1.2", "mass = -1"),
                     encoding="utf-8")
    p = cli("analyze", model)
    lines = p.stderr.splitlines()
    assert p.returncode == 2 and lines[0].startswith("kinetostat: error:") and lines[0].endswith("2 problems:"), p.stderr
    assert len(lines) == 3 and all(line.startswith("  - ") for line in lines[1:]) and "x\\ny" in p.stderr


def test_a_newline_in_an_output_path_prints_one_line_on_stdout(tmp_path, cli):
    out = tmp_path / "m\nkinetostat: error: forged.xml"
    p = cli("export", ICE, "--mjcf", "-o", out)
    assert p.returncode == 0 and out.exists(), p.stderr
    assert p.stdout.count("\n") == 1 and "m\\nkinetostat: error: forged.xml" in p.stdout, p.stdout
