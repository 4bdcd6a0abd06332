"""Logging and verbosity: the package logger `kinetostat`, -q/-v on every command, and the
estimated time a long job logs once its first item is done (`kinetostat._forecast`)."""
from __future__ import annotations

import itertools
import logging
import os
import re

import pytest

from conftest import FOUR_BAR, ROOT, sketch_report
from kinetostat import _forecast
from kinetostat.cli import build_parser

ICE, FOUR_BAR_MODEL = ROOT / "models" / "ice_crank_slider.toml", ROOT / "models" / "chain_unit_four_bar.toml"


@pytest.fixture
def clock(monkeypatch):
    """The forecasts' clock: 120 s more at each reading."""
    ticks = itertools.count(step=120.0)
    monkeypatch.setattr(_forecast, "now", lambda: next(ticks))


def test_quiet_and_verbose_before_or_after_every_command():
    parser = build_parser()
    commands = next(a for a in parser._actions if a.choices and "analyze" in a.choices).choices
    needs = {"analyze": ["m"], "structure": ["m"], "export": ["m", "--mjcf"], "plans": ["m", "--out", "d"],
             "page": ["m", "--out", "p.html"], "sweep": ["m", "--param", "r=1", "--out", "s.csv"],
             "motion": ["m", "--out", "d"],
             "tolerance": ["m", "--tol", "r=1", "--out", "d"]}
    for name in commands:
        rest = needs.get(name, [])
        assert parser.parse_args([name, *rest]).verbosity == 0
        assert parser.parse_args(["-q", name, *rest]).verbosity == -1
        assert parser.parse_args([name, *rest, "-q"]).verbosity == -1
        assert parser.parse_args(["--verbose", name, *rest]).verbosity == 1
        assert parser.parse_args([name, "-v", *rest]).verbosity == 1


def test_quiet_report_prints_nothing_and_verbose_shows_its_progress(cli, tmp_path, monkeypatch):
    """On the small four-bar of conftest (no study to redo: a third of the chain unit's report)."""
    sketch_report(monkeypatch)
    model, out = tmp_path / "four_bar.toml", tmp_path / "out"
    model.write_text(FOUR_BAR, encoding="utf-8")
    quick = ["--engines", "none", "--no-page", "--steps", "8", "--jobs", "1", "--out", out]
    r = cli("-q", "report", model, *quick)
    assert (r.returncode, r.stdout, r.stderr) == (0, "", "")
    assert (out / "four_bar" / "index.html").is_file() and (out / "index.html").is_file()
    r = cli("report", model, *quick, "-v")
    assert r.returncode == 0 and "four_bar                   PASS" in r.stdout and "report: 1 mechanism(s)" in r.stdout
    for line in ("four_bar.toml: loaded and analysed over 8 positions in ",
                 "four_bar: route reference PASS (", "four_bar: figures mechanism, moment, ",
                 "four_bar: plans, worksheet ("):
        assert any(s.startswith(line) for s in r.stderr.splitlines()), (line, r.stderr)
    # the library's logger as it was after the command: its NullHandler alone, its level unset
    package = logging.getLogger("kinetostat")
    assert package.level == logging.NOTSET and package.propagate
    assert [type(h) for h in package.handlers] == [logging.NullHandler]


def test_report_says_what_it_will_do_first_then_each_part_of_a_model(tmp_path, monkeypatch, capsys):
    """The first line once the options and models are checked, before the first model's report (an
    input error is the one line it prints: test_cli); then, at the
    default verbosity, each model's parts as they are done (its routes, figures, tables, plans),
    each with its time (-q: none of them, test_quiet_report_prints_nothing_...)."""
    from kinetostat import cli
    from kinetostat.cli import report
    sketch_report(monkeypatch)
    before_models = []
    reports = report._report_results
    monkeypatch.setattr(report, "_report_results",
                        lambda *a: (before_models.append(capsys.readouterr().err), reports(*a))[1])
    quick = ["--engines", "none", "--no-page", "--steps", "8", "--jobs", "1", "--no-progress", "--out", str(tmp_path)]
    assert cli.main(["report", str(FOUR_BAR_MODEL), *quick]) == 0
    assert before_models == [f"report: 1 model(s) into {tmp_path}: routes lever, reference; no pages; 1 at a time\n"]
    err = capsys.readouterr().err.splitlines()
    parts = ["chain_unit_four_bar: route reference PASS (", "chain_unit_four_bar: figures mechanism, moment, ",
             "chain_unit_four_bar: law of motion (", "chain_unit_four_bar: the study by derivatives (",
             "chain_unit_four_bar: sensitivity (", "chain_unit_four_bar: cycle.csv.gz and the tables (",
             "chain_unit_four_bar: plans, worksheet ("]
    assert [next((i for i, s in enumerate(err) if s.startswith(p)), None) for p in parts] == list(range(7)), err
    assert all(re.search(r"\(\d+\.\d s\)$", s) for s in err[:7]), err


def test_a_long_report_says_its_time_and_what_is_faster(cli, tmp_path, monkeypatch, clock):
    """Each model's report made up (an error line): the forecast after the first, with the options
    that apply (--jobs while fewer than the cores, --no-page with pages, --engines none with engines)."""
    from kinetostat.cli import report
    monkeypatch.setattr(report, "_report_results", lambda paths, *a, **k: ((n, {"error": "made up"})
                                                                          for n in range(len(paths))))
    monkeypatch.setattr(os, "cpu_count", lambda: 4)
    models = [FOUR_BAR_MODEL] * 3
    r = cli("report", *models, "--steps", "8", "--jobs", "2", "--engines", "pymunk", "--out", tmp_path)
    assert [s for s in r.stderr.splitlines() if not s.startswith("kinetostat: error: ")] == [
        f"report: 3 model(s) into {tmp_path}: routes lever, pymunk; pages; 2 at a time",
        "about 2 min for the remaining 2 model(s) (2 min for the first, 2 at a time); faster: --jobs 4 / --no-page "
        "/ --engines none"]
    r = cli("report", *models * 2, "--steps", "8", "--no-page", "--engines", "none", "--out", tmp_path)
    assert [s for s in r.stderr.splitlines() if not s.startswith("kinetostat: error: ")] == [       # 4 started
        f"report: 6 model(s) into {tmp_path}: routes lever, reference; no pages; 4 at a time",
        "about 2 min for the remaining 5 model(s) (2 min for the first, 4 at a time)"]
    r = cli("-q", "report", *models, "--steps", "8", "--out", tmp_path)
    assert "about" not in r.stderr and r.stderr.count("kinetostat: error: ") == 3


def test_quiet_analyze_keeps_its_results_on_stdout_and_drops_warnings(cli):
    r = cli("analyze", ICE, "--at", "400")
    assert r.returncode == 0 and r.stderr.startswith("kinetostat: warning: --at: angles outside [0, 360)")
    shown = r.stdout
    r = cli("-q", "analyze", ICE, "--at", "400")
    assert (r.returncode, r.stdout, r.stderr) == (0, shown, "")
    r = cli("-q", "analyze", "no_such_model.toml")                      # an error is still said
    assert r.returncode == 2 and r.stderr.startswith("kinetostat: error: ") and r.stdout == ""


def test_a_long_sweep_says_its_time_and_what_is_faster(cli, tmp_path, clock):
    args = ["sweep", FOUR_BAR_MODEL, "--param", "r=0.05,0.06,0.07", "--chunk", "1", "--steps", "8",
            "--out", tmp_path / "s.csv"]
    r = cli(*args)
    assert r.returncode == 0 and "3 designs" in r.stdout
    assert r.stderr == ("about 4 min for the remaining 2 design(s) (2 min for the first); faster: --scheduler "
                     "processes (the API's scheduler='processes')\n")
    r = cli("-q", *args)
    assert (r.returncode, r.stdout, r.stderr) == (0, "", "")


def test_validate_and_variant_all_say_their_time(cli, tmp_path, monkeypatch, clock):
    r = cli("validate", FOUR_BAR_MODEL, FOUR_BAR_MODEL, "--engines", "none", "--steps", "8")
    assert r.returncode == 0 and r.stderr == "about 2 min for the remaining 1 model(s) (2 min for the first)\n"
    monkeypatch.setattr("kinetostat.variants.codes", lambda: ["479"])            # one code of each task
    r = cli("variant", "--all", "--no-pack", "--out", tmp_path)
    assert r.returncode == 0 and r.stderr == (f"variant --all: 3 code(s) of task(s) 1, 2, 3 into {tmp_path}, no pack\n"
                                              "about 4 min for the remaining 2 variant(s) (2 min for the first); "
                                              "faster: one TASK\n")


def test_a_forecast_at_the_first_items_pace(caplog, clock, monkeypatch):
    log = logging.getLogger("kinetostat.test")
    caplog.set_level(logging.DEBUG, "kinetostat")
    eta = _forecast.Forecast(log, 1000, "variant(s)", faster=["--no-pack", "one TASK"])
    eta.done()
    eta.done()                                            # said once only
    assert [(r.levelno, r.getMessage()) for r in caplog.records] == [
        (logging.INFO, "about 33.3 h for the remaining 999 variant(s) (2 min for the first); faster: --no-pack / one TASK")]
    caplog.clear()
    _forecast.Forecast(log, 9, "model(s)", parallel=4).done()      # 8 left, 3 of them ending with the first: 2 rounds
    assert caplog.records[0].getMessage() == "about 4 min for the remaining 8 model(s) (2 min for the first, 4 at a time)"
    caplog.clear()
    monkeypatch.setattr(_forecast, "LONG", 300.0)                  # a job that is not long: its forecast for -v only
    _forecast.Forecast(log, 3, "model(s)").done()
    assert [(r.levelno, r.getMessage()) for r in caplog.records] == [
        (logging.DEBUG, "about 4 min for the remaining 2 model(s) (2 min for the first)")]
    monkeypatch.setattr(_forecast, "LONG", 30.0)
    caplog.clear()
    _forecast.Forecast(log, 1, "model(s)").done()                  # a job of one item: nothing to forecast
    _forecast.Forecast(log, 65, "design(s)").done(32)              # the first chunk: 3.75 s a design
    assert [(r.levelno, r.getMessage()) for r in caplog.records] == [
        (logging.INFO, "about 2 min for the remaining 33 design(s) (3.8 s for the first)")]
    assert [_forecast.duration(s) for s in (0.034, 4.2, 40, 12 * 60, 3.5 * 3600)] == [
        "0.034 s", "4.2 s", "40 s", "12 min", "3.5 h"]
