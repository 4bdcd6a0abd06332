"""Hostile reads and waits (issue 35, class 3): an input is read only where it
is a regular file of bounded size (a FIFO never blocks, /dev/zero is never read, also through a
link); the step summary is appended to a regular file only; a Dask scheduler that accepts and never
answers times out; a table's list is limited to MAX_TABLE_POINTS."""
from __future__ import annotations

import os
import socket
import sys
import threading
from pathlib import Path

import pytest

import kinetostat
from conftest import FOUR_BAR, ROOT, within
from kinetostat import ModelError
from kinetostat.model import MAX_FILE_BYTES

pytestmark = pytest.mark.skipif(not hasattr(os, "mkfifo") or not Path("/dev/zero").exists(), reason="POSIX only")

pytest_plugins = ["pytester"]


def _zero_link(tmp_path: Path, name: str) -> Path:
    link = tmp_path / name
    link.symlink_to("/dev/zero")
    return link


# ============================================================================ inputs and earlier outputs

def test_a_model_linked_to_dev_zero_is_refused_as_a_device(tmp_path):
    exc = within(lambda: kinetostat.load(_zero_link(tmp_path, "model.toml")))
    assert isinstance(exc, ModelError) and "a device, not a regular file" in str(exc), exc


@pytest.mark.parametrize("reader", [False, True], ids=["no reader", "a reader"])
def test_the_step_summary_is_not_written_into_a_fifo(reader, tmp_path, monkeypatch):
    """A FIFO as $GITHUB_STEP_SUMMARY: without a reader open() waited for ever; with one it was
    written as a stream. Now refused at once (an OSError the callers print as one warning line)."""
    from kinetostat.report import ci
    fifo = tmp_path / "summary.md"
    os.mkfifo(fifo)
    fd = os.open(fifo, os.O_RDONLY | os.O_NONBLOCK) if reader else None
    try:
        monkeypatch.setenv("GITHUB_STEP_SUMMARY", str(fifo))
        exc = within(lambda: ci.write_summary("## kinetostat: PASS\n"))
        assert isinstance(exc, OSError) and exc.filename == str(fifo), exc
        assert not reader or "a FIFO, not a regular file" in exc.strerror
        assert fd is None or os.read(fd, 100) == b""                      # nothing written into it
    finally:
        if fd is not None:
            os.close(fd)
    summary = tmp_path / "regular.md"
    summary.write_text("earlier\n", encoding="utf-8")
    monkeypatch.setenv("GITHUB_STEP_SUMMARY", str(summary))
    assert ci.write_summary("## now") and summary.read_text(encoding="utf-8") == "earlier\n## now\n\n"


def test_the_gate_reports_an_unreadable_toml_and_goes_on(pytester):
    """A 5 GiB *.toml ended the gate's collection with a MemoryError (read whole to look for a
    [mechanism] table): now one over MAX_FILE_BYTES is one failing item `<file>::read`, and the
    models are checked. (pytest visits regular files only: a FIFO in the tree is never opened.)"""
    models = pytester.path / "models"
    models.mkdir()
    (models / "good.toml").write_text((ROOT / "models" / "chain_unit_four_bar.toml").read_text(encoding="utf-8"),
                                      encoding="utf-8")
    os.mkfifo(models / "fifo.toml")                  # not visited
    with open(models / "big.toml", "wb") as f:       # sparse: nothing on disk, nothing read
        f.truncate(MAX_FILE_BYTES + 1)
    r = within(lambda: pytester.runpytest_inprocess("--kinetostat", "models", "--kinetostat-steps", "12",
                                                      "-k", "read or lever", "-p", "no:cacheprovider",
                                                      "-p", "no:hypothesispytest"), 120)
    out = r.stdout.str()
    assert r.ret == pytest.ExitCode.TESTS_FAILED, out
    r.assert_outcomes(failed=1, passed=1)                       # good.toml's lever identity ran
    assert f"models/big.toml: not read as a model file: larger than {MAX_FILE_BYTES} bytes" in out
    assert "Traceback" not in out


# ============================================================================ waits

@pytest.mark.parametrize("in_loop", [False, True], ids=["plain", "inside a running event loop"])
def test_a_scheduler_that_accepts_and_never_answers_times_out(in_loop, monkeypatch):
    """Also called where an event loop runs (a notebook's)."""
    import asyncio
    pytest.importorskip("distributed")
    sweep_module = sys.modules["kinetostat.sweep"]
    monkeypatch.setattr(sweep_module, "CONNECT_TIMEOUT", 0.5)
    server = socket.create_server(("127.0.0.1", 0))          # loopback only; accepts, never answers
    held: list[socket.socket] = []
    threading.Thread(target=lambda: held.extend(iter(lambda: server.accept()[0], None)), daemon=True).start()
    address = f"tcp://127.0.0.1:{server.getsockname()[1]}"
    try:
        call = lambda: kinetostat.sweep("ice_crank_slider", {"l_OA": [0.036]}, steps=12, scheduler=address)

        async def inside_a_loop():
            return call()
        exc = within((lambda: asyncio.run(inside_a_loop())) if in_loop else call, 20)
    finally:
        server.close()
        for s in held:
            s.close()
    assert isinstance(exc, ConnectionError), exc
    assert address in str(exc) and "no answer within 0.5 s" in str(exc)


# ============================================================================ tables

_LAW = FOUR_BAR.replace("rpm = 300.0\n", "").replace("eps = 0.0\n", "")
_LOAD = '\n[[load]]\nname = "press"\nlink = 3\npoint = "B"\ndirection = [0.0, -1.0]\n'


def _series(n: int, top: float = 359.0) -> str:
    return "[" + ", ".join(f"{top * i / (n - 1):.6f}" for i in range(n)) + "]"


@pytest.mark.parametrize("table, field", [
    (lambda n: f"{_LAW}\n[drive.omega_table]\nphi_deg = {_series(n)}\nomega = [{', '.join(['30.0'] * n)}]\n",
     "drive.omega_table.phi_deg"),
    (lambda n: f"{FOUR_BAR}{_LOAD}[load.table]\nphi_deg = {_series(n)}\nvalue = {_series(n, 1.0)}\n",
     "load[1].table.phi_deg"),
    (lambda n: f'{FOUR_BAR}\n[[load]]\nname = "motor"\nkind = "moment"\nlink = 1\n[load.characteristic]\n'
               f"omega = {_series(n, 40.0)}\nM = {_series(n, 1.0)}\n", "load[1].characteristic.omega"),
], ids=["omega_table", "load table", "characteristic"])
def test_a_table_longer_than_the_limit_is_refused_naming_the_field(table, field, monkeypatch):
    """The limit made small here (MAX_TABLE_POINTS is 200,000: a table that long takes seconds)."""
    monkeypatch.setattr(sys.modules["kinetostat.model.core"], "MAX_TABLE_POINTS", 50)
    kinetostat.loads(table(50))                                           # at the limit: read
    with pytest.raises(ModelError) as exc:
        kinetostat.loads(table(51))
    assert f"{field}: 51 values, at most 50 (MAX_TABLE_POINTS)" in str(exc.value)


def test_an_expected_cycle_that_is_a_fifo_is_refused_unread(tmp_path):
    from kinetostat.testing import check_cycle
    fifo = tmp_path / "expected.csv"
    os.mkfifo(fifo)                     # pandas' read_csv waited for a writer for ever
    exc = within(lambda: check_cycle("ice_crank_slider", expected=fifo, steps=12))
    assert isinstance(exc, ValueError) and f"{fifo}: the expected file is not read: a FIFO" in str(exc), exc


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="POSIX only")
def test_report_check_reads_earlier_files_bounded_and_never_waits_on_a_fifo(tmp_path, monkeypatch):
    """`report --check`'s comparison reads the committed reports, earlier outputs: a FIFO there
    is not a file of the report (never opened), and a file over MAX_REPORT_BYTES is named as
    not read instead of read whole."""
    from kinetostat.report import rerun
    for side in ("fresh", "old"):
        (tmp_path / side / "m").mkdir(parents=True)
        (tmp_path / side / "m" / "summary.json").write_text("{}", encoding="utf-8")
        (tmp_path / side / "m" / "index.md").write_text("# m\n" + "x" * 100, encoding="utf-8")
        (tmp_path / side / "m" / "worksheet.csv").write_text("a\n", encoding="utf-8")
    os.remove(tmp_path / "old" / "m" / "worksheet.csv")
    os.mkfifo(tmp_path / "old" / "m" / "worksheet.csv")
    monkeypatch.setattr(rerun, "MAX_REPORT_BYTES", 50)
    got = {d.file: d for d in rerun.compare_reports(tmp_path / "fresh", tmp_path / "old")}
    assert got["worksheet.csv"].committed == "absent"
    assert "not read (" in got["index.md"].committed and "index.md" in got["index.md"].committed
