"""What the command line writes, under hostile input and failure: model strings that try to be
markup or links end as text in every report file; report folders stay inside --out; a full disk
or Ctrl-C leaves every earlier file as it was and no temporary file; stdout that cannot take the
text (an ASCII locale, /dev/full) and names the file system refuses give one error line; --steps
that would not fit in memory are refused before anything is allocated."""
from __future__ import annotations

import errno
import os
import signal
import subprocess
import sys
import time
import tracemalloc
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from conftest import FOUR_BAR, ROOT

pytest.importorskip("matplotlib")

ICE = ROOT / "models" / "ice_crank_slider.toml"
INJECTION = ROOT / "tests" / "hostile" / "reports" / "injection.toml"
QUICK = ("--steps", "12", "--engines", "none", "--jobs", "1", "--no-progress", "--no-page")


def _tokens(md: str):
    """Every token of `md` as GitHub would parse it (raw HTML recognised, strikethrough on)."""
    from markdown_it import MarkdownIt
    parser = MarkdownIt("commonmark", {"html": True}).enable(["table", "strikethrough"])

    def walk(ts):
        for t in ts:
            yield t
            yield from walk(t.children or [])
    return list(walk(parser.parse(md)))


def _files(folder: Path) -> dict[Path, bytes]:
    return {p.relative_to(folder): p.read_bytes() for p in folder.rglob("*") if p.is_file()}


def _temporary(folder: Path) -> list[Path]:
    return [p for p in folder.rglob("*") if p.name.startswith(".kinetostat-")]


# ============================================================================ script injection

@pytest.mark.parametrize("others", [(), pytest.param((ICE,), id="and-ice", marks=pytest.mark.slow)],
                         ids=["alone", "and-ice"])
def test_model_strings_are_text_in_every_report_file(tmp_path, cli, others):
    """javascript:, data:, vbscript: links, autolinks, a reference-style link over a newline, raw
    HTML, entities, backticks, '|' and '$' in the name, source, assumptions, link, point, load,
    spring names and the published fields: the .md files (as GitHub reads them) hold no raw HTML
    and no link but the report's own, each string reads back as its text, every table row keeps
    its cells; the HTML has no script, no javascript:/data:/vbscript: link. The name is also a
    mathtext error ($\\frac{$): the plots take it as text, and another model is reported too
    (with -m slow)."""
    import tomllib
    out = tmp_path / "out"
    r = cli("report", INJECTION, *others, "--out", out, *QUICK)
    assert r.returncode == 0, r.stderr
    assert (out / "injection" / "mechanism.svg").stat().st_size > 1000
    assert all((out / p.stem / "index.md").is_file() for p in others)
    data = tomllib.loads(INJECTION.read_text(encoding="utf-8"))
    strings = [data["mechanism"]["name"], data["mechanism"]["source"], *data["mechanism"]["assumptions"],
               data["drive"]["point"], *[t["name"] for t in data["link"]], *data["frame"],
               *[p for t in data["link"] for p in t["points"]], data["load"][0]["name"], data["spring"][0]["name"],
               *[data["published"][0][k] for k in ("symbol", "meaning", "source", "accuracy")]]
    own = {"cycle.csv.gz", "summary.json", "segments.csv", "worksheet.csv", "../index.md", "injection/index.md",
           "ice_crank_slider/index.md"}
    for md in (out / "injection" / "index.md", out / "index.md"):
        tokens = _tokens(md.read_text(encoding="utf-8"))
        assert not [t.content for t in tokens if t.type in ("html_inline", "html_block")]
        hrefs = {t.attrGet("href") for t in tokens if t.type == "link_open"} | \
                {t.attrGet("src") for t in tokens if t.type == "image"}
        own_page = lambda h: h.partition("#")[0] in own and h.partition("#")[2] in ("", "plans-of-the-graphical-method")
        assert all(own_page(h) or h.startswith("#") or h.endswith((".png", ".svg")) and "/" not in h for h in hrefs), hrefs
        rows = [t for t in tokens if t.type in ("tr_open", "th_open", "td_open", "tr_close")]
        cells, widths = 0, []
        for t in rows:
            cells += t.type in ("th_open", "td_open")
            if t.type == "tr_close":
                widths.append(cells)
                cells = 0
        assert widths and all(w == widths[0] for w in widths[:2])
        text = " ".join(t.content for t in tokens if t.type in ("text", "code_inline"))
        if md.parent.name == "injection":
            for s in strings:
                assert " ".join(s.splitlines()) in text, s
        else:
            assert " ".join(data["mechanism"]["name"].splitlines()) in text
    for page in (out / "injection" / "index.html", out / "index.html"):
        html = page.read_text(encoding="utf-8")
        for bad in ('href="javascript', 'href="data:', 'href="vbscript', "<script", "<img src=x", "<b>", "<u>",
                    'src="javascript'):
            assert bad not in html.lower(), (page, bad)
        assert "&lt;script&gt;alert(7)&lt;/script&gt;" in html or page.parent == out


def test_doc_tables_keep_their_cells():
    """A '|' or a backslash in a model string never splits a table cell."""
    from kinetostat.report.document import Doc, esc
    doc = Doc("t")
    doc.table(["a", "b"], [[esc("x | y \\| z \\"), esc("[a](javascript:x)")]])
    tokens = _tokens(doc.markdown())
    assert sum(t.type == "td_open" for t in tokens) == 2
    assert [t.content for t in tokens if t.type == "text"][-2:] == ["x | y \\| z \\", "[a](javascript:x)"]


# ============================================================================ paths

def test_report_folders_stay_inside_out_and_never_overwrite_each_other(tmp_path, cli, sketched_report):
    """A model file '...toml' (stem '..'), a stem of markup, a non-UTF-8 file name with a control
    character, and two files with the same stem: one folder each inside --out, nothing outside."""
    models = tmp_path / "models"
    (models / "b").mkdir(parents=True)
    names = ["...toml", "[x](javascript:y).toml", os.fsdecode(b"\xff\x01name.toml"), "same.toml", "b/same.toml"]
    for n in names:
        (models / n).write_text(FOUR_BAR, encoding="utf-8")
    out = tmp_path / "work" / "out"
    r = cli("report", *[models / n for n in names], "--out", out, *QUICK)
    assert r.returncode == 0, r.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["models", "work"]
    assert sorted(p.name for p in (tmp_path / "work").iterdir()) == ["out"]
    folders = sorted(p.name for p in out.iterdir() if p.is_dir())
    assert folders == ["model", "name", "same", "same-2", "x_javascript_y"]
    for f in folders:
        assert (out / f / "index.md").stat().st_size > 1000 and (out / f / "cycle.csv.gz").stat().st_size > 100
    index = (out / "index.md").read_text(encoding="utf-8")
    assert all(f"({f}/index.md)" in index for f in folders)
    assert "\\\\udcff" in (out / "name" / "index.md").read_text(encoding="utf-8")    # the file name, escaped
    junit = tmp_path / "v.xml"
    r = cli("validate", models / names[2], "--junit", junit, "--steps", "12", "--engines", "none", "--no-progress")
    assert r.returncode == 0, r.stderr
    ET.parse(junit)                       # a control character and a non-UTF-8 byte: still XML


def test_a_report_folder_that_leads_outside_is_refused(tmp_path):
    """A folder inside --out that is a link to elsewhere: nothing is written there."""
    import kinetostat
    from kinetostat.report import run_validation, write_report
    path = tmp_path / "four_bar.toml"
    path.write_text(FOUR_BAR, encoding="utf-8")
    elsewhere, out = tmp_path / "elsewhere", tmp_path / "out"
    elsewhere.mkdir()
    out.mkdir()
    (out / "four_bar").symlink_to(elsewhere)
    run = run_validation(kinetostat.load(path), [], steps=12, path=path)
    with pytest.raises(ValueError, match="outside"):
        write_report(run, out)
    with pytest.raises(ValueError, match="ASCII letters"):
        write_report(run, out, folder="..")
    assert list(elsewhere.iterdir()) == []


# ============================================================================ nothing lost

@pytest.fixture
def full_disk(monkeypatch):
    """Every file opened by `kinetostat._io.atomic` takes 700 bytes, then raises ENOSPC."""
    real = os.fdopen

    class Full:
        def __init__(self, f):
            self.f, self.n = f, 0

        def write(self, data):
            self.n += len(data)
            if self.n > 700:
                raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
            return self.f.write(data)

        def __getattr__(self, name):
            return getattr(self.f, name)

        def __enter__(self):
            return self

        def __exit__(self, *exc):
            return self.f.__exit__(*exc)

    monkeypatch.setattr(os, "fdopen", lambda *a, **k: Full(real(*a, **k)))


@pytest.mark.parametrize("args, written", [
    (("analyze", ICE, "--steps", "12", "--out", "t.csv"), "t.csv"),
    (("analyze", ICE, "--steps", "12", "--out", "t.json"), "t.json"),
    (("analyze", ICE, "--steps", "12", "--out", "t.parquet"), "t.parquet"),
    (("validate", ICE, "--steps", "12", "--engines", "none", "--junit", "v.xml", "--json", "v.json", "--no-progress"),
     "v.xml"),
    (("export", ICE, "--mjcf", "-o", "m.xml"), "m.xml"),
    (("report", ICE, "--out", "r", *QUICK), "r"),
], ids=["analyze-csv", "analyze-json", "analyze-parquet", "validate", "export", "report"])
def test_a_full_disk_leaves_the_old_files(args, written, tmp_path, cli, request):
    """A rerun on a full disk: one error line naming the file, exit non-zero, every file of the
    first run as it was (no truncated table, no 0-byte image or index), no temporary file."""
    if args[0] == "report":
        request.getfixturevalue("sketched_report")
    if args[-1] == "t.parquet":
        pytest.importorskip("pyarrow")
    first = cli(*args, cwd=tmp_path)
    assert first.returncode == 0, first.stderr
    before = _files(tmp_path)
    assert any(str(p).startswith(written) for p in before)
    request.getfixturevalue("full_disk")
    again = cli(*[a.replace("12", "24") if a == "12" else a for a in map(str, args)], cwd=tmp_path)
    assert again.returncode != 0 and "No space left on device" in again.stderr, again.stderr
    assert "Traceback" not in again.stderr
    assert _files(tmp_path) == before
    assert _temporary(tmp_path) == []


def _report_cmd(out: Path) -> list[str]:
    return [sys.executable, "-m", "kinetostat", "report", str(ICE), "--out", str(out), "--steps", "36",
            "--engines", "none", "--jobs", "1", "--no-progress", "--no-page"]


def _interrupt_when(cmd: list[str], out: Path, written: int) -> subprocess.Popen:
    """Run `cmd` and send it SIGINT once `written` of its files have been begun in `out` (a
    temporary file of this run holding data, or a file already renamed into place): a moment
    inside the run, chosen by what it has done, not by the clock. (A signal between a temporary
    file's creation and its registration leaves it behind: test_an_interrupt_as_the_temporary_
    file_is_made_leaves_nothing.)"""
    env = {k: v for k, v in os.environ.items() if k != "KINETOSTAT_MODELS"}
    inodes = {p: p.stat().st_ino for p in out.rglob("*")}
    p = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env, cwd=ROOT)
    seen: set[str] = set()
    while p.poll() is None:
        for f in out.rglob("*"):
            try:
                if (f.name.startswith(".kinetostat-") and f.stat().st_size) or f.stat().st_ino != inodes.get(f):
                    seen.add(f.name)
            except FileNotFoundError:         # renamed or removed meanwhile
                pass
        if len(seen) >= written:
            p.send_signal(signal.SIGINT)
            break
        time.sleep(0.001)
    return p


def _ctrl_c_trials(cmd: list[str], out: Path, moments: tuple[int, ...], enough: int = 0) -> int:
    """SIGINT at each moment (files begun) of a rerun of `cmd` into `out`: every run that was
    still going stops with exit 130 and no traceback, every file of the earlier run stays byte
    for byte, no temporary file is left. Returns how many runs were stopped (at most `enough`
    where given: the trials end there)."""
    first = subprocess.run(cmd, capture_output=True, text=True, cwd=ROOT, timeout=600)
    assert first.returncode == 0, first.stderr
    before = _files(out)
    stopped = 0
    for written in moments:
        p = _interrupt_when(cmd, out, written)
        running = p.returncode is None
        _, err = p.communicate(timeout=600)
        if running:
            stopped += 1
            assert p.returncode in (130, -signal.SIGINT), (written, p.returncode, err)
            assert "Traceback" not in err, err
        assert _files(out) == before, written
        assert _temporary(out) == [], written
        if stopped == enough:
            break
    return stopped


def test_ctrl_c_while_a_table_is_written_keeps_the_earlier_table(tmp_path):
    """SIGINT while `analyze` writes a table (6 MB): exit 130, the earlier table as it was (up to
    three tries, should a run finish before its temporary file is seen)."""
    cmd = [sys.executable, "-m", "kinetostat", "analyze", str(ICE), "--steps", "5000", "--out",
           str(tmp_path / "t.csv")]
    assert _ctrl_c_trials(cmd, tmp_path, (1, 1, 1), enough=1) == 1


@pytest.mark.slow
def test_ctrl_c_stops_the_report_and_keeps_every_earlier_file(tmp_path):
    """SIGINT at five moments of a `report` run (after 1 to 20 files begun): each run stops with
    exit 130 and one line, every file of the earlier run stays byte for byte, no temporary file
    is left."""
    out = tmp_path / "out"
    assert _ctrl_c_trials(_report_cmd(out), out, (1, 2, 5, 10, 20)) >= 3


def test_a_write_interrupted_removes_its_temporary_file(tmp_path):
    from kinetostat._io import atomic, write_text
    target = write_text(tmp_path / "a.md", "old\n")
    with pytest.raises(KeyboardInterrupt):
        with atomic(target) as f:
            f.write("half")
            raise KeyboardInterrupt
    assert target.read_text() == "old\n" and sorted(p.name for p in tmp_path.iterdir()) == ["a.md"]


# ============================================================================ the command line's streams and limits

def _four_bar_named(tmp_path: Path, name: str) -> Path:
    p = tmp_path / "named.toml"
    p.write_text(FOUR_BAR.replace('name = "test four-bar"', f'name = "{name}"'), encoding="utf-8")
    return p


@pytest.mark.parametrize("encoding", ["ascii", "latin-1"])
def test_a_non_ascii_name_under_an_ascii_or_latin1_locale(encoding, tmp_path):
    path = _four_bar_named(tmp_path, "Кривошип ✓ é")
    env = dict(os.environ, PYTHONIOENCODING=encoding, LC_ALL="C")
    r = subprocess.run([sys.executable, "-m", "kinetostat", "analyze", str(path), "--at", "0"], capture_output=True,
                       env=env, cwd=ROOT, timeout=120)
    out = r.stdout.decode(encoding)
    assert r.returncode == 0 and b"Traceback" not in r.stderr, r.stderr
    assert out.startswith("\\u041a\\u0440\\u0438\\u0432\\u043e\\u0448\\u0438\\u043f \\u2713 ")


@pytest.mark.skipif(not Path("/dev/full").exists(), reason="no /dev/full")
@pytest.mark.parametrize("args", [("analyze", ICE, "--steps", "12"), ("analyze", ICE, "--steps", "12", "--out", "-"),
                                  ("export", ICE, "--mjcf")], ids=["summary", "csv", "mjcf"])
def test_stdout_on_a_full_disk(args):
    with open("/dev/full", "w") as full:
        r = subprocess.run([sys.executable, "-m", "kinetostat", *map(str, args)], stdout=full, stderr=subprocess.PIPE,
                           text=True, cwd=ROOT, timeout=120)
    assert r.returncode == 2, r.stderr
    assert r.stderr.strip().splitlines()[-1] == "kinetostat: error: cannot write to stdout: No space left on device"
    assert "Traceback" not in r.stderr and "Exception ignored" not in r.stderr


@pytest.mark.parametrize("args", [
    ("analyze", "{long}.toml"),
    ("analyze", ICE, "--out", "{long}.csv"),
    ("validate", ICE, "--junit", "{long}.xml"),
    ("validate", ICE, "--json", "{long}.json"),
    ("export", ICE, "--mjcf", "-o", "{long}.xml"),
    ("report", ICE, "--out", "{long}"),
], ids=["model", "analyze-out", "junit", "json", "export", "report"])
def test_a_file_name_longer_than_255_bytes(args, tmp_path, cli):
    long = "é" * 128                    # 256 bytes in UTF-8
    r = cli(*[str(a).format(long=tmp_path / long) for a in args], "--steps", "12", cwd=tmp_path) \
        if args[0] != "export" else cli(*[str(a).format(long=tmp_path / long) for a in args], cwd=tmp_path)
    assert r.returncode == 2, r.stderr
    assert "File name too long" in r.stderr and "Traceback" not in r.stderr
    assert r.stderr.count("\n") == 1


@pytest.mark.parametrize("steps, size", [(10**9, "TB"), (10**20, "ZB")])
def test_steps_beyond_memory_are_refused_before_allocating(steps, size, cli):
    """The message names the bytes the result would need (and per crank position); nothing of
    that size is allocated: the peak of Python's and numpy's allocations stays small."""
    tracemalloc.start()
    try:
        r = cli("analyze", ICE, "--steps", steps)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert r.returncode == 2
    assert f"--steps {steps}: the analysis would need about " in r.stderr and f" {size} of memory (" in r.stderr
    assert "kB per crank position for this model)" in r.stderr and "use fewer steps" in r.stderr
    assert peak < 50e6, peak
