"""The studies that write files (`python -m kinetostat_validation.drawing_error`, `.stability`,
`.benchmark`) write where `--out` says, by default ./reports of the working directory (before,
`reports/` beside the installed package: inside site-packages for a wheel), and without
matplotlib they exit 2 with one line naming the extra, before any work, writing nothing."""
from __future__ import annotations

import subprocess
import sys

import pytest

from kinetostat_validation import benchmark, drawing_error, stability

STUDIES = {"drawing_error": (drawing_error, []), "stability": (stability, []), "benchmark": (benchmark, [])}


@pytest.mark.parametrize("name", STUDIES)
def test_a_study_without_matplotlib_names_the_extra(name, monkeypatch, tmp_path, capsys):
    module, argv = STUDIES[name]
    monkeypatch.setitem(sys.modules, "matplotlib", None)         # as where the extra is not installed
    monkeypatch.chdir(tmp_path)
    with pytest.raises(SystemExit) as e:
        module.main(argv)
    err = capsys.readouterr().err
    assert e.value.code == 2 and err == (f"python -m kinetostat_validation.{name}: error: its plots need "
                                         f"matplotlib: pip install 'kinetostat[reports]'\n")
    assert list(tmp_path.iterdir()) == []


def test_the_refusal_is_one_line_from_python_m(tmp_path):
    """The real command (`python -m`), in a process whose matplotlib cannot be imported: no traceback."""
    code = ("import sys, runpy; sys.modules['matplotlib'] = None; sys.argv[0] = 'x'; "
            "runpy.run_module('kinetostat_validation.drawing_error', run_name='__main__')")
    r = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True, text=True, timeout=60)
    assert r.returncode == 2 and len(r.stderr.splitlines()) == 1 and "kinetostat[reports]" in r.stderr, r.stderr
    assert list(tmp_path.iterdir()) == []


def test_a_study_writes_into_out_by_default_reports_of_the_working_directory(monkeypatch, tmp_path):
    """drawing_error's files into ./reports, then into a nested --out, nothing elsewhere (the study
    and its drawing replaced by stand-ins that write the file they are given: the slow test below
    runs the real one)."""
    monkeypatch.setattr(drawing_error, "study", dict)
    monkeypatch.setattr(drawing_error, "write_plot", lambda r, path: path.write_text("png"))
    monkeypatch.setattr(drawing_error, "write_report", lambda r, md, png: md.write_text(png.name))
    monkeypatch.chdir(tmp_path)
    assert drawing_error.main([]) == 0
    assert sorted(p.name for p in (tmp_path / "reports").iterdir()) == ["drawing_error.md", "drawing_error.png"]
    assert drawing_error.main(["--out", "a/b"]) == 0
    assert sorted(p.name for p in (tmp_path / "a" / "b").iterdir()) == ["drawing_error.md", "drawing_error.png"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a", "reports"]


@pytest.mark.slow
def test_the_drawing_error_study_runs_from_an_empty_folder(tmp_path):
    """The real study, a few draws, as `python -m` from an empty folder: its files in ./reports."""
    code = ("import kinetostat_validation.drawing_error as d; d.N = 20; "
            "raise SystemExit(d.main([]))")
    r = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["reports"]
    assert "![drawing error](drawing_error.png)" in (tmp_path / "reports" / "drawing_error.md").read_text()
