"""Hostile outputs (issue 22, points 1, 4, 5): a device, FIFO or stdout named as an output is
written as a stream and never replaced by a file; writers stay inside their folder; a set of
files is written as a unit; an interrupt at any moment of a write leaves no temporary file."""
from __future__ import annotations

import contextlib
import io
import os
import shutil
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


@pytest.mark.skipif(not Path("/proc/self/fd/2").exists(), reason="no /proc")
@pytest.mark.parametrize("target", ["link", "same file"])
def test_export_to_a_link_to_its_own_stderr_writes_the_stream(target, tmp_path):
    """`export -o /dev/stderr 2>log` replaced /dev/stderr (a link to /proc/self/fd/2, stderr a
    regular file) by a file of its own, as root. Here a link made in tmp_path stands for it (never
    /dev/stderr itself); `-o log 2>log` names stderr's file by its own name. Both keep the link or
    the file (same inode) and write the MJCF into stderr's file."""
    log = tmp_path / "log"
    link = tmp_path / "stderr"
    link.symlink_to("/proc/self/fd/2")
    named = link if target == "link" else log
    env = {k: v for k, v in os.environ.items() if k != "KINETOSTAT_MODELS"}
    with open(log, "wb") as f:
        inode = os.fstat(f.fileno()).st_ino
        r = subprocess.run([sys.executable, "-m", "kinetostat", "export", str(ICE), "--mjcf", "-o", str(named)],
                           stdout=subprocess.PIPE, stderr=f, cwd=ROOT, env=env, timeout=120)
    assert r.returncode == 0, log.read_text()
    assert os.readlink(link) == "/proc/self/fd/2" and os.lstat(log).st_ino == inode
    assert b"<mujoco" in log.read_bytes() and b"</mujoco>" in log.read_bytes()
    assert sorted(q.name for q in tmp_path.iterdir()) == ["log", "stderr"]      # no temporary file


@pytest.mark.skipif(not Path("/proc/self/fd/0").exists(), reason="no /proc")
def test_the_library_never_replaces_a_link_into_proc_fd(tmp_path):
    """A link (or a link to a link, or a path through a linked folder) into /proc/self/fd is a
    stream: refused as a file to replace, appended to as a stream; the link stays."""
    from kinetostat._io import atomic, is_stream, unit, write_text
    log = tmp_path / "log"
    log.write_text("old\n")
    fd = os.open(log, os.O_WRONLY | os.O_APPEND)
    try:
        (tmp_path / "a").symlink_to(f"/proc/self/fd/{fd}")
        (tmp_path / "b").symlink_to("a")
        (tmp_path / "fds").symlink_to("/proc/self/fd")
        for name in ("a", "b", f"fds/{fd}"):
            assert is_stream(tmp_path / name), name
            with pytest.raises(OSError, match="not a regular file"):
                write_text(tmp_path / name, "new\n")
        assert not is_stream(log) and not is_stream(tmp_path / "nothing")
        with atomic(tmp_path / "b", stream=True) as f:
            f.write("appended\n")
        assert log.read_text() == "old\nappended\n"
        with pytest.raises(OSError, match="stream's link"):
            with unit(tmp_path) as tmp:
                (tmp / "a").write_text("x")
        assert os.readlink(tmp_path / "a") == f"/proc/self/fd/{fd}" and os.readlink(tmp_path / "b") == "a"
    finally:
        os.close(fd)


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


# ============================================================================ 4. writers stay inside their folder

def test_variant_all_refuses_a_planted_link_to_a_folder_elsewhere(tmp_path, cli, monkeypatch):
    """The audit's reproducer: `variant --all` with a linked task1_000 wrote 13 files where the
    link points. Now: one error line naming the variant, nothing written elsewhere."""
    from kinetostat import variants
    monkeypatch.setattr(variants, "codes", lambda: ["000"])
    out, elsewhere = tmp_path / "out", tmp_path / "elsewhere"
    out.mkdir()
    elsewhere.mkdir()
    (out / "task1_000").symlink_to(elsewhere)
    p = cli("variant", "1", "--all", "--no-pack", "--out", out, "--no-progress")
    assert p.returncode == 2 and "Traceback" not in p.stderr
    assert "task 1 variant 000" in p.stderr and "outside" in p.stderr, p.stderr
    assert list(elsewhere.iterdir()) == []


@pytest.mark.parametrize("force", [False, True])
def test_examples_copy_never_writes_through_a_link(force, tmp_path, cli):
    """A dangling link named FORMAT.md was followed (a file created outside); with --force a link
    to an outside FORMAT.md overwrote it. Now a link is a file already there, and --force
    replaces the link itself."""
    dest, outside = tmp_path / "models", tmp_path / "outside.md"
    dest.mkdir()
    (dest / "FORMAT.md").symlink_to(outside)
    if force:
        outside.write_text("mine\n")
    p = cli("examples", "--copy", dest, *(["--force"] if force else []))
    if force:
        assert p.returncode == 0, p.stderr
        assert outside.read_text() == "mine\n"
        assert not (dest / "FORMAT.md").is_symlink() and "kinetostat" in (dest / "FORMAT.md").read_text().lower()
    else:
        assert p.returncode == 2 and "FORMAT.md already exists" in p.stderr, p.stderr
        assert not outside.exists() and [q.name for q in dest.iterdir()] == ["FORMAT.md"]


# ============================================================================ 5. a set of files written as a unit

def _files(folder: Path) -> dict[str, bytes]:
    return {str(p.relative_to(folder)): p.read_bytes() for p in folder.rglob("*") if p.is_file()}


@pytest.fixture(scope="module")
def english_plans(tmp_path_factory) -> Path:
    """`kinetostat plans ICE` in English, written once for the module (each test reruns into a copy)."""
    from kinetostat.cli import main
    out = tmp_path_factory.mktemp("english") / "plans"
    with contextlib.redirect_stdout(io.StringIO()):
        assert main(["plans", str(ICE), "--out", str(out)]) == 0
    return out


@pytest.mark.parametrize("fault", ["full-disk", "ctrl-c"])
def test_plans_rerun_that_fails_midway_leaves_the_earlier_set(fault, tmp_path, cli, monkeypatch, english_plans):
    """`plans` in English, then in Ukrainian failing at the 4th file: every earlier file stays as
    it was (no Ukrainian sheet beside the English worksheet), no temporary file or folder."""
    import errno
    out = Path(shutil.copytree(english_plans, tmp_path / "plans"))
    before = _files(out)
    assert len(before) >= 8
    real, calls = os.fdopen, []

    def failing(*a, **k):
        calls.append(1)
        if len(calls) == 4:
            os.close(a[0])
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC)) if fault == "full-disk" else KeyboardInterrupt
        return real(*a, **k)
    monkeypatch.setattr(os, "fdopen", failing)
    again = cli("plans", ICE, "--out", out, "--lang", "uk")
    assert again.returncode == (2 if fault == "full-disk" else 130), again.stderr
    assert "Traceback" not in again.stderr and len(calls) == 4
    assert _files(out) == before
    assert [p.name for p in out.iterdir() if p.name.startswith(".kinetostat-")] == []


def test_a_set_is_swapped_in_whole(tmp_path):
    """`unit`: the new set replaces the old one file by file only after the last file is
    written; files the set does not hold stay; a link in the way is replaced, not followed."""
    from kinetostat._io import unit, write_text
    out, outside = tmp_path / "out", tmp_path / "outside.txt"
    out.mkdir()
    write_text(out / "a.csv", "old a\n")
    write_text(out / "mine.txt", "mine\n")
    outside.write_text("outside\n")
    (out / "b.csv").symlink_to(outside)
    with unit(out) as tmp:
        write_text(tmp / "a.csv", "new a\n")
        write_text(tmp / "b.csv", "new b\n")
        assert (out / "a.csv").read_text() == "old a\n"          # nothing seen before the end
    assert _files(out) == {"a.csv": b"new a\n", "b.csv": b"new b\n", "mine.txt": b"mine\n"}
    assert outside.read_text() == "outside\n" and not (out / "b.csv").is_symlink()


def test_ctrl_c_as_an_output_is_probed_leaves_no_probe(tmp_path, cli, monkeypatch):
    """Ctrl-C the moment the check that --out is writable has made its probe file (tempfile's
    window between creating the file and guarding it): the command stops (exit 130) once the
    probe is removed (a probe was once left beside the table)."""
    import signal
    import tempfile
    real, made = tempfile._mkstemp_inner, []

    def inner(*args, **kwargs):
        fd, name = real(*args, **kwargs)
        made.append(name)
        os.kill(os.getpid(), signal.SIGINT)
        return fd, name
    monkeypatch.setattr(tempfile, "_mkstemp_inner", inner)
    p = cli("analyze", ICE, "--steps", "4", "--out", tmp_path / "t.csv")
    assert p.returncode == 130 and len(made) == 1 and list(tmp_path.iterdir()) == [], p.stderr
