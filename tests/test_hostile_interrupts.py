"""Leftovers and interrupts (issue 35, class 7): the temporary files of a write killed outright
are removed by the next write into their folder (and only those: never a running write's);
Ctrl-C during a sweep on Dask's worker processes, or during `variant`, gives exit 130 and one
line, no worker's traceback, and leaves the earlier files as they were."""
from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from conftest import ROOT

#: A process that starts a write (a file, and a set of files) in the folder argv[1] and waits in
#: it: kinetostat._io loaded from its file alone (the standard library only), so that it starts at once.
WRITER = """
import importlib.util, sys, time
spec = importlib.util.spec_from_file_location("_io", sys.argv[2])
io = importlib.util.module_from_spec(spec)
spec.loader.exec_module(io)
with io.unit(sys.argv[1]) as tmp, io.atomic(sys.argv[1] + "/a.csv") as f:
    f.write("half a table")
    print("writing", flush=True)
    time.sleep(600)
"""


def _writers(folder: Path, n: int) -> list[subprocess.Popen]:
    """`n` processes, each in the middle of a write into `folder` (WRITER)."""
    ps = [subprocess.Popen([sys.executable, "-c", WRITER, str(folder), str(ROOT / "kinetostat" / "_io.py")],
                           stdout=subprocess.PIPE, cwd=ROOT)
          for _ in range(n)]
    assert [p.stdout.readline() for p in ps] == [b"writing\n"] * n
    return ps


def _temporary(folder: Path) -> list[str]:
    return sorted(q.name for q in folder.iterdir() if q.name.startswith(".kinetostat-"))


@pytest.mark.skipif(not hasattr(signal, "SIGKILL"), reason="POSIX only")
def test_the_leftovers_of_a_killed_write_are_removed_by_the_next_write_there(tmp_path, cli):
    """SIGKILL in the middle of a write left its temporary file and folder for good. The next
    write into the folder (here `analyze --out`) removes them; a write still running in another
    process keeps its own, and files not named as kinetostat's temporary ones stay."""
    out = tmp_path / "out"
    killed, running = _writers(out, 2)
    try:
        killed.kill()
        killed.wait(10)
        theirs = _temporary(out)
        assert len(theirs) == 4 and sum(f"-{killed.pid}-" in n for n in theirs) == 2
        mine = [".kinetostat-notes.tmp", ".kinetostat-12345678-x.txt", "a.csv"]
        for name in mine:
            (out / name).write_text("mine\n")
        p = cli("analyze", ROOT / "models" / "ice_crank_slider.toml", "--steps", "4", "--out", out / "t.csv")
        assert p.returncode == 0, p.stderr
        assert _temporary(out) == sorted([n for n in theirs if f"-{running.pid}-" in n] + mine[:2])
        assert (out / "a.csv").read_text() == "mine\n" and (out / "t.csv").is_file()
    finally:
        running.kill()
        running.wait(10)


def test_the_library_keeps_the_leftovers_it_cannot_tell_are_stale(tmp_path):
    """A leftover of another machine (a shared folder), or of a process id that runs, stays."""
    from kinetostat._io import _TEMPORARY, remove_stale, temporary_affixes
    prefix, suffix = temporary_affixes()
    host = prefix.split("-")[1]
    other = "0" * 8 if host != "0" * 8 else "1" * 8
    names = [f".kinetostat-{other}-4194304999-abc.tmp",            # another machine: its pid unknown here
             f".kinetostat-{host}-{os.getppid()}-abc.tmp",          # a process that runs
             f".kinetostat-{host}-4194304999-abc.tmp"]              # no such process on this machine
    assert all(_TEMPORARY.fullmatch(n) for n in names)
    for n in names:
        (tmp_path / n).write_text("")
    remove_stale(tmp_path)
    assert sorted(q.name for q in tmp_path.iterdir()) == sorted(names[:2])


# ============================================================================ Ctrl-C with Dask's worker processes

def _children(pid: int) -> list[int]:
    try:
        return [int(x) for x in Path(f"/proc/{pid}/task/{pid}/children").read_text().split()]
    except OSError:
        return []


@pytest.mark.skipif(not Path(f"/proc/{os.getpid()}/task/{os.getpid()}/children").exists(), reason="no /proc children")
@pytest.mark.parametrize("after", [0.2, pytest.param(1.5, marks=pytest.mark.slow)])
def test_ctrl_c_during_a_sweep_on_worker_processes_prints_one_line(after, tmp_path):
    """The terminal sends Ctrl-C to the whole group, here `after` seconds after the first worker
    process started. Workers still importing (0.1 to 0.8 s after) printed their KeyboardInterrupt
    tracebacks, 40 to 75 lines; now exit 130, the one line, no table, no temporary file and no
    worker left."""
    pytest.importorskip("dask")
    out = tmp_path / "s.csv"
    p = subprocess.Popen([sys.executable, "-m", "kinetostat", "sweep", "chain_unit_four_bar", "--param",
                          "r=0.05:0.11:0.002", "--param", "n_k=0,60,120", "--steps", "360", "--scheduler", "processes",
                          "--chunk", "2", "--out", str(out), "--no-progress"],
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, cwd=ROOT, start_new_session=True)
    deadline = time.monotonic() + 60
    while len(_children(p.pid)) < 2 and p.poll() is None and time.monotonic() < deadline:   # a worker besides the resource tracker
        time.sleep(0.001)
    time.sleep(after)
    workers = _children(p.pid)
    os.killpg(p.pid, signal.SIGINT)
    _, err = p.communicate(timeout=60)
    assert p.returncode == 130 and err.decode() == "kinetostat: error: interrupted\n", err.decode()
    assert list(tmp_path.iterdir()) == []
    time.sleep(0.2)
    assert [w for w in workers if Path(f"/proc/{w}").exists() and "zombie" not in Path(f"/proc/{w}/status").read_text()] == []


# ============================================================================ Ctrl-C during variant --lang uk

def _files(folder: Path) -> dict[str, bytes]:
    return {str(q.relative_to(folder)): q.read_bytes() for q in folder.rglob("*") if q.is_file()}


@pytest.fixture
def english_key(tmp_path, cli) -> Path:
    out = tmp_path / "key"
    p = cli("variant", "1", "000", "--lang", "en", "--out", out, "--no-pack")
    assert p.returncode == 0, p.stderr
    return out


@pytest.mark.parametrize("where", ["raised", "swallowed"])
def test_ctrl_c_during_variant_in_ukrainian_leaves_the_english_key(where, english_key, cli, monkeypatch):
    """Ctrl-C while the Ukrainian key is written. Raised: exit 130, one line, the English files
    as they were. Swallowed (it landed in a __del__): "Exception ignored in ..." and its
    traceback were printed, and the Ukrainian set was swapped in before exit 130; now the set is
    not swapped in, and the one line is all."""
    from kinetostat import variants
    before = _files(english_key)
    real, calls = variants.write_text, []

    class Swallows:
        def __del__(self):
            signal.raise_signal(signal.SIGINT)
            for _ in range(100):             # the handler runs here, inside __del__
                pass

    def interrupted(*args, **kwargs):
        calls.append(1)
        if len(calls) == 1 and where == "raised":
            os.kill(os.getpid(), signal.SIGINT)
        elif len(calls) == 1:
            Swallows()
        return real(*args, **kwargs)
    monkeypatch.setattr(variants, "write_text", interrupted)
    monkeypatch.setattr(sys, "unraisablehook", sys.__unraisablehook__)     # Python's, not pytest's
    p = cli("variant", "1", "000", "--lang", "uk", "--out", english_key, "--no-pack")
    assert (p.returncode, p.stderr, p.stdout) == (130, "kinetostat: error: interrupted\n", "")
    assert calls and _files(english_key) == before
    assert [q.name for q in english_key.iterdir() if q.name.startswith(".")] == []


def test_a_set_is_not_swapped_in_after_a_swallowed_ctrl_c(tmp_path, monkeypatch):
    """A Ctrl-C recorded while the set was written, its KeyboardInterrupt swallowed after the
    last file: raised again before the set is swapped in; the old file stays, nothing else."""
    from kinetostat import _io
    _io.write_text(tmp_path / "a.csv", "old\n")
    monkeypatch.setattr(_io.Interrupt, "seen", False)
    with pytest.raises(KeyboardInterrupt):
        with _io.unit(tmp_path) as tmp:
            _io.write_text(tmp / "a.csv", "new\n")
            _io.write_text(tmp / "b.csv", "new\n")
            _io.Interrupt.seen = True        # as the command line's handler records it
    assert _files(tmp_path) == {"a.csv": b"old\n"}
