"""Hostile outputs (issue 22, points 1, 4, 5): a device, FIFO or stdout named as an output is
written as a stream and never replaced by a file; writers stay inside their folder; a set of
files is written as a unit; an interrupt at any moment of a write leaves no temporary file."""
from __future__ import annotations

import os
import stat
import subprocess
import sys
import threading
from pathlib import Path

import pytest

from conftest import ROOT

ICE = ROOT / "models" / "ice_crank_slider.toml"


def _read_fifo(fifo: Path, got: list) -> threading.Thread:
    t = threading.Thread(target=lambda: got.append(fifo.read_bytes()), daemon=True)
    t.start()
    return t


# ============================================================================ 1. devices, FIFOs, stdout

@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="POSIX only")
def test_export_into_a_fifo_writes_a_stream_and_keeps_the_fifo(tmp_path, cli):
    fifo = tmp_path / "model.xml"
    os.mkfifo(fifo)
    got: list[bytes] = []
    reader = _read_fifo(fifo, got)
    p = cli("export", ICE, "--mjcf", "-o", fifo)
    reader.join(10)
    assert p.returncode == 0, p.stderr
    assert stat.S_ISFIFO(os.lstat(fifo).st_mode)                  # still the FIFO, not a file
    assert got and got[0].lstrip().startswith(b"<") and b"<mujoco" in got[0]
    assert [q.name for q in tmp_path.iterdir()] == ["model.xml"]  # no temporary file


@pytest.mark.skipif(not Path("/proc/self/fd/1").exists(), reason="no /proc")
@pytest.mark.parametrize("redirect", ["pipe", "file"])
def test_export_to_dev_stdout_prints_and_replaces_nothing(redirect, tmp_path):
    """/dev/stdout is a link to /proc/self/fd/1; the test names the latter, which a faulty
    writer cannot replace (/dev/stdout it could, as root)."""
    out = tmp_path / "stdout.txt"
    cmd = [sys.executable, "-m", "kinetostat", "export", str(ICE), "--urdf", "-o", "/proc/self/fd/1"]
    env = {k: v for k, v in os.environ.items() if k != "KINETOSTAT_MODELS"}
    with open(out, "wb") as f:
        r = subprocess.run(cmd, stdout=subprocess.PIPE if redirect == "pipe" else f, stderr=subprocess.PIPE,
                           cwd=ROOT, env=env, timeout=120)
    text = r.stdout if redirect == "pipe" else out.read_bytes()
    assert r.returncode == 0, r.stderr
    assert b"<robot" in text and b"</robot>" in text
    assert redirect == "pipe" or stat.S_ISREG(os.lstat(out).st_mode)


def test_the_library_refuses_to_replace_a_fifo(tmp_path):
    from kinetostat._io import write_text
    fifo = tmp_path / "segments.csv"
    os.mkfifo(fifo)
    with pytest.raises(OSError, match="not a regular file"):
        write_text(fifo, "a,b\n")
    assert stat.S_ISFIFO(os.lstat(fifo).st_mode) and [q.name for q in tmp_path.iterdir()] == ["segments.csv"]


@pytest.mark.parametrize("moment", range(4))
def test_an_interrupt_anywhere_in_a_write_leaves_no_temporary_file(moment, tmp_path, monkeypatch):
    """KeyboardInterrupt raised at each system call of a write, just after it returned (the window
    the audit hit once in 115 trials between mkstemp and try): the old file stays, nothing else."""
    from kinetostat import _io
    target = _io.write_text(tmp_path / "a.md", "old\n")
    calls = {"open": os.open, "fdopen": os.fdopen, "chmod": os.chmod, "replace": os.replace}
    name = list(calls)[moment]

    def interrupted(*a, **k):
        out = calls[name](*a, **k)
        if name == "replace":            # the rename happened: the new file is complete
            raise KeyboardInterrupt
        if name == "fdopen":
            out.close()
        raise KeyboardInterrupt
    monkeypatch.setattr(os, name, interrupted)
    with pytest.raises(KeyboardInterrupt):
        _io.write_text(target, "new\n")
    monkeypatch.undo()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.md"]
    assert target.read_text() == ("new\n" if name == "replace" else "old\n")
    assert not _io._PENDING
