"""Hostile inputs: every bad model file or option must give one clear error naming the field or
the crank angle, from the API (`kinetostat.load` / `analyze`) and from the command line
(`kinetostat analyze FILE`, run in this process by conftest's `cli`: exit code 2, no
traceback, no partial output).

The corpus is `tests/hostile/*.toml`; each file starts with a header read by this module:

    # hostile: what is wrong
    # expect: ModelError | StructureError | AssemblyError | SingularPositionWarning
    # match: a text the message must contain (case-insensitive; one line per text)
    # stage: analyze             (the fault shows only in analyze(); default: load)
    # phi_deg: 0 30 60           (the angles analyze() is asked for; default: 12 steps)
    # nan_at: 180                (SingularPositionWarning: forces there are NaN, finite elsewhere)
    # cli: 0                     (expected exit code of the CLI; default 2)
    # xfail: why                 (a known bug: the input is accepted or crashes today)

An edge once refused and now legal stays in the corpus as `expect: valid` (no match): it must
load and analyze to finite numbers, and the CLI must write its table (exit 0).

Generated inputs (huge files, deep nesting, bad analyze options) are built in the tests below.
"""
from __future__ import annotations

import math
import sys
import tomllib
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pytest

import kinetostat
from kinetostat import AssemblyError, ModelError, SingularPositionWarning, StructureError
from conftest import FOUR_BAR, ROOT, within

HOSTILE = Path(__file__).resolve().parent / "hostile"
CORPUS = sorted(HOSTILE.glob("*.toml"))
ERRORS = {"ModelError": ModelError, "StructureError": StructureError, "AssemblyError": AssemblyError}


@dataclass
class Case:
    path: Path
    what: str = ""
    expect: str = ""
    match: list[str] = field(default_factory=list)
    stage: str = "load"
    phi_deg: list[float] | None = None
    nan_at: list[float] = field(default_factory=list)
    cli: int = 2
    xfail: str | None = None


def parse(path: Path) -> Case:
    c = Case(path)
    for raw in path.read_bytes().decode("utf-8", errors="replace").splitlines():
        if not raw.startswith("# ") or ":" not in raw:
            break
        key, _, value = raw[2:].partition(":")
        value = value.strip()
        if key == "hostile":
            c.what = value
        elif key == "expect":
            c.expect = value
        elif key == "match":
            c.match.append(value)
        elif key == "stage":
            c.stage = value
        elif key == "phi_deg":
            c.phi_deg = [float(x) for x in value.split()]
        elif key == "nan_at":
            c.nan_at = [float(x) for x in value.split()]
        elif key == "cli":
            c.cli = int(value)
        elif key == "xfail":
            c.xfail = value
    assert c.expect and (c.match or c.expect == "valid"), f"{path.name}: header needs expect and match lines"
    if c.expect == "valid":
        c.cli = 0
    return c


CASES = [parse(p) for p in CORPUS]


def _params(cases):
    return [pytest.param(c, id=c.path.stem,
                         marks=[pytest.mark.xfail(reason=c.xfail, strict=False)] if c.xfail else [])
            for c in cases]


def _contains_all(text: str, needles: list[str]) -> None:
    low = text.lower()
    missing = [n for n in needles if n.lower() not in low]
    assert not missing, f"message lacks {missing}:\n{text}"


def _analyze(mech, c: Case):
    return kinetostat.analyze(mech, phi_deg=c.phi_deg) if c.phi_deg else kinetostat.analyze(mech, steps=12)


def test_corpus_is_there():
    assert len(CASES) >= 70
    assert {c.expect for c in CASES} >= {"ModelError", "StructureError", "AssemblyError", "SingularPositionWarning"}


# ----------------------------------------------------------------------------- the API

@pytest.mark.parametrize("c", _params(CASES))
def test_api_gives_a_clear_error(c: Case):
    if c.expect == "valid":
        res = _analyze(kinetostat.load(c.path), c)
        assert np.isfinite(res.balancing_moment).all() and np.isfinite(res.forces.R).all()
        return
    if c.expect == "SingularPositionWarning":
        mech = kinetostat.load(c.path)
        with pytest.warns(SingularPositionWarning) as rec:
            res = _analyze(mech, c)
        _contains_all(" | ".join(str(w.message) for w in rec), c.match)
        bad = np.isin(res.phi_deg, c.nan_at)
        assert bad.any()
        assert np.isnan(res.balancing_moment[bad]).all() and np.isnan(res.forces.R[bad]).all()
        assert np.isfinite(res.balancing_moment[~bad]).all() and np.isfinite(res.forces.R[~bad]).all()
        return
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)     # a numpy overflow is no clear error
        with pytest.raises(ERRORS[c.expect]) as exc:
            _analyze(kinetostat.load(c.path), c)
    _contains_all(str(exc.value), c.match)
    if isinstance(exc.value, ModelError):
        assert str(exc.value).startswith(str(c.path))      # the file is named
        assert exc.value.problems


# ----------------------------------------------------------------------------- the CLI

def _cli_available() -> bool:
    return (ROOT / "kinetostat" / "cli" / "__init__.py").exists()


@pytest.mark.skipif(not _cli_available(), reason="kinetostat/cli/ not written yet")
@pytest.mark.parametrize("c", _params(CASES))
def test_cli_exits_cleanly(c: Case, tmp_path, cli):
    out = tmp_path / "table.csv"
    angles = ["--at", *map(str, c.phi_deg)] if c.phi_deg else ["--steps", "12"]
    p = cli("analyze", c.path, *angles, "--out", out)
    assert "Traceback" not in p.stderr, p.stderr
    assert p.returncode == c.cli, (p.returncode, p.stderr)
    if c.cli:
        assert not out.exists(), "partial output written"
        assert p.stderr.startswith("kinetostat: error:"), p.stderr
    else:
        assert out.exists()
        assert c.expect == "valid" or "kinetostat: warning:" in p.stderr
    _contains_all(p.stderr, c.match)


# ----------------------------------------------------------------------------- options of analyze

@pytest.fixture(scope="module")
def four_bar():
    return kinetostat.loads(FOUR_BAR)


@pytest.mark.parametrize("kw, message", [
    (dict(phi_deg=[0.0, math.nan]), "phi_deg: expected finite crank angles"),
    (dict(phi_deg=[math.inf]), "phi_deg: expected finite crank angles"),
    (dict(phi_deg=[[0.0, 90.0]]), "phi_deg: expected finite crank angles of shape (N,), got shape (1, 2)"),
    (dict(phi_deg=[None]), "phi_deg: expected finite crank angles"),
    (dict(steps=0), "steps: expected a positive integer, got 0"),
    (dict(steps=-3), "steps: expected a positive integer, got -3"),
    (dict(steps=2.5), "steps: expected a positive integer, got 2.5"),
    (dict(steps="36"), "steps: expected a positive integer, got '36'"),
    (dict(phi_deg="abc"), "phi_deg: expected finite crank angles in degrees, got 'abc'"),
    (dict(phi_deg=[1 + 2j]), "phi_deg: expected finite crank angles in degrees, got [(1+2j)]"),
])
def test_bad_analyze_options(four_bar, kw, message):
    with pytest.raises(ValueError) as exc:
        kinetostat.analyze(four_bar, **kw)
    assert message in str(exc.value)


def test_analyze_of_a_path_says_what_it_wants():
    with pytest.raises((TypeError, ValueError), match="Mechanism"):
        kinetostat.analyze(str(ROOT / "models" / "ice_crank_slider.toml"), steps=4)


def test_missing_file_and_directory(tmp_path):
    with pytest.raises(ModelError, match="cannot read file"):
        kinetostat.load(tmp_path / "none.toml")
    with pytest.raises(FileNotFoundError) as exc:          # also what `except FileNotFoundError` catches
        kinetostat.load(tmp_path / "none.toml")
    assert isinstance(exc.value, ModelError) and exc.value.filename == str(tmp_path / "none.toml")
    with pytest.raises(ModelError, match="cannot read file: a directory"):
        kinetostat.load(tmp_path)


@pytest.mark.skipif(not Path("/dev/zero").exists() or not hasattr(__import__("os"), "mkfifo"), reason="POSIX only")
def test_fifo_and_device_are_refused_without_reading(tmp_path):
    import os
    fifo = tmp_path / "model.toml"
    os.mkfifo(fifo)                          # opening it for reading would block until a writer comes
    for path in (fifo, Path("/dev/zero")):   # /dev/zero would never end
        exc = within(lambda: kinetostat.load(path))
        assert isinstance(exc, ModelError) and "not a regular file" in str(exc), exc


def test_oversized_file_is_refused_before_reading(tmp_path):
    from kinetostat.model import MAX_FILE_BYTES
    big = tmp_path / "big.toml"
    with open(big, "wb") as f:               # sparse: no disk used, nothing read
        f.truncate(MAX_FILE_BYTES + 1)
    exc = within(lambda: kinetostat.load(big))
    assert isinstance(exc, ModelError) and f"at most {MAX_FILE_BYTES}" in str(exc), exc


@pytest.mark.skipif(not _cli_available(), reason="kinetostat/cli/ not written yet")
@pytest.mark.parametrize("args, message", [
    (["--at", "nan"], "invalid crank angle 'nan'"),
    (["--at", "inf"], "invalid crank angle 'inf'"),
    (["--at", "abc"], "invalid crank angle 'abc'"),
    (["--steps", "0"], "invalid number of positions '0'"),
    (["--steps", "-5"], "invalid number of positions '-5'"),
    (["--steps", "2.5"], "invalid number of positions '2.5'"),
    (["--steps", "10", "--at", "0"], "not allowed with argument"),
    (["--out", "table.xlsx"], "unknown table format '.xlsx'"),
])
def test_cli_bad_options(args, message, tmp_path, cli):
    args = [str(tmp_path / a) if a.startswith("table.") else a for a in args]
    p = cli("analyze", ROOT / "models" / "ice_crank_slider.toml", *args)
    assert p.returncode == 2 and "Traceback" not in p.stderr, p.stderr
    assert message in p.stderr
    assert not list(tmp_path.iterdir())


@pytest.mark.skipif(not _cli_available(), reason="kinetostat/cli/ not written yet")
def test_cli_missing_model_file(tmp_path, cli):
    p = cli("analyze", tmp_path / "none.toml", "--out", tmp_path / "t.csv")
    assert p.returncode == 2 and "Traceback" not in p.stderr
    assert "model file not found" in p.stderr
    assert not (tmp_path / "t.csv").exists()


# ----------------------------------------------------------------------------- huge and deep files

def test_five_megabytes_of_comments_load_fast(tmp_path, cli):
    text = FOUR_BAR + ("# " + "x" * 78 + "\n") * 65_000          # 5.3 MB
    mech = kinetostat.loads(text)
    assert np.isfinite(kinetostat.analyze(mech, steps=12).balancing_moment).all()
    if _cli_available():
        path = tmp_path / "commented.toml"
        path.write_text(text, encoding="utf-8")
        p = cli("analyze", path, "--steps", "12")
        assert p.returncode == 0 and "Traceback" not in p.stderr


def test_five_megabyte_string_loads_fast():
    """A 5 MB free-text string (the mechanism's source; its name is held to MAX_NAME characters)."""
    text = FOUR_BAR.replace('name = "test four-bar"', 'name = "test four-bar"\nsource = "' + "x" * 5_000_000 + '"')
    assert len(kinetostat.loads(text).source) == 5_000_000


def chain_text(n_dyads: int, one_pin: bool = False) -> str:
    """A valid mechanism of 1 + 2 n_dyads moving links: n_dyads copies of the four-bar's coupler
    and rocker on the crank pin (each at its own point name A<i>, or all on one pin A)."""
    pin = (lambda i: "A") if one_pin else (lambda i: f"A{i}")
    parts = ['[mechanism]\nname = "chain"\ng = 9.81\n[drive]\npivot = "O"\n',
             f'point = "{pin(0)}"\nreference = [1.0, 0.0]\nsense = "ccw"\nrpm = 300.0\n[frame]\nO = [0.0, 0.0]\n']
    parts += [f"C{i} = [0.3, 0.0]\n" for i in range(n_dyads)]
    crank = ", ".join(dict.fromkeys(f"{pin(i)} = [0.1, 0.0]" for i in range(n_dyads)))
    parts.append(f'[[link]]\nid = 1\npoints = {{ O = [0.0, 0.0], {crank} }}\n')
    for i in range(n_dyads):
        parts.append(f'[[link]]\nid = {2 + 2 * i}\npoints = {{ {pin(i)} = [0.0, 0.0], B{i} = [0.35, 0.0] }}\n'
                     f'mass = 1.0\ncom = "B{i}"\n[[link]]\nid = {3 + 2 * i}\n'
                     f'points = {{ C{i} = [0.0, 0.0], B{i} = [0.3, 0.0] }}\n')
    parts.append('[[pair]]\nkind = "R"\nlinks = [0, 1]\npoint = "O"\n')
    for i in range(n_dyads):
        j, k = 2 + 2 * i, 3 + 2 * i
        parts.append(f'[[pair]]\nkind = "R"\nlinks = [1, {j}]\npoint = "{pin(i)}"\n[[pair]]\nkind = "R"\n'
                     f'links = [{j}, {k}]\npoint = "B{i}"\n[[pair]]\nkind = "R"\nlinks = [0, {k}]\n'
                     f'point = "C{i}"\n[[group]]\nlinks = [{j}, {k}]\nbranch = 1\n')
    return "".join(parts)


def own_lines(fn) -> int:
    """The lines of kinetostat's own Python that `fn()` runs (line events of the tracer): its
    work, independent of the clock and the machine's load."""
    root = str(Path(kinetostat.__file__).resolve().parent)
    count = 0

    def line(frame, event, arg):
        nonlocal count
        count += event == "line"
        return line

    previous = sys.gettrace()
    sys.settrace(lambda frame, event, arg: line if frame.f_code.co_filename.startswith(root) else None)
    try:
        fn()
    finally:
        sys.settrace(previous)
    return count


@pytest.mark.parametrize("one_pin", [False, True], ids=["own-pins", "one-pin"])
def test_load_and_analyze_work_grows_linearly_with_the_groups(one_pin):
    """Loading and analysing a chain of n dyads (steps=12; each on its own crank pin, or all on
    one) runs kinetostat code in proportion to n: from 16 to 32 dyads the work grows by the
    same amount as from 8 to 16, times 2 (a quadratic step, such as a scan of all pairs per
    group, makes that factor 4)."""
    work = [own_lines(lambda n=n: kinetostat.analyze(kinetostat.loads(chain_text(n, one_pin)), steps=12))
            for n in (8, 16, 32)]
    growth = (work[2] - work[1]) / (work[1] - work[0])
    assert 1.9 < growth < 2.1, (work, growth)


@pytest.mark.parametrize("n", [200, pytest.param(2000, marks=pytest.mark.slow)])
def test_a_chain_of_dyads_carries_the_sum_of_its_dyads(n):
    """n dyads on one crank (2000: 4001 links, a 0.8 MB file): the balancing moment is n times
    one four-bar's."""
    mech = kinetostat.loads(chain_text(n))
    res = kinetostat.analyze(mech, steps=12)
    assert mech.n_links == 2 * n + 2 and len(mech.structure.groups) == n
    one = kinetostat.analyze(kinetostat.loads(chain_text(1)), steps=12).balancing_moment
    np.testing.assert_allclose(res.balancing_moment, n * one, rtol=1e-9)


def test_deep_dotted_key_is_refused_in_bounded_time():
    # tomllib keeps the key path of every level: memory grows as depth^2 (3000 levels: ~50 MB,
    # 10^4 levels (20 kB of text): ~400 MB, 10^5: out of memory). 3000 is safe to run.
    text = "a" + ".a" * 3000 + " = 1\n" + FOUR_BAR
    with pytest.raises(ModelError, match=r"<top level>\.a: unknown field"):
        kinetostat.loads(text)


@pytest.mark.parametrize("keys, depth, header", [
    (200, 401, False),         # many moderately deep keys (200 x 400 levels, 160 kB)
    (200, 401, True),          # as table headers
    (400_000, 2, False),       # very many shallow keys (5.6 MB)
], ids=["deep-keys", "deep-headers", "many-keys"])
def test_costly_keys_are_refused_before_parsing(keys, depth, header, monkeypatch):
    """tomllib's memory grows with the number of keys and the square of their depth (65 keys of
    3000 levels: 2.3 GB measured): the estimate refuses before tomllib runs."""
    dotted = ".".join(["a"] * (depth - 1))
    text = "".join((f"[k{i}.{dotted}]\nx = 1\n" if header else f"k{i}.{dotted} = 1\n") for i in range(keys))
    monkeypatch.setattr(tomllib, "loads", lambda *a, **k: pytest.fail("tomllib ran on a refused file"))
    with pytest.raises(ModelError, match=rf"MiB to parse .*this one has {depth} dotted parts"):
        kinetostat.loads(text + FOUR_BAR)


def test_deep_inline_tables_and_arrays_are_refused():
    for text in ("x = " + "{a = " * 3000 + "1" + "}" * 3000 + "\n", "x = " + "[" * 3000 + "]" * 3000 + "\n"):
        with pytest.raises(ModelError, match="nested too deeply"):
            kinetostat.loads(text + FOUR_BAR)


@pytest.mark.parametrize("values, points", [(20_000, 1000), pytest.param(200_000, 5000, marks=pytest.mark.slow)])
def test_huge_array_and_many_points_load(values, points):
    """A diagram of many values and a link of many points load (the largest distance between
    the points: hull and calipers, n log n)."""
    table = FOUR_BAR + ('[[load]]\nname = "big"\nlink = 3\npoint = "B"\ndirection = [0.0, -1.0]\n[load.table]\n'
                        'phi_deg = [' + ", ".join(f"{360 * i / (values - 1):.6f}" for i in range(values)) + ']\n'
                        'value = [' + ", ".join(["1.0"] * values) + ']\n')
    pts = ", ".join(f"P{i} = [{i * 1e-5}, 0.0]" for i in range(points))
    many = FOUR_BAR.replace("S3 = [0.12, -0.01] }", "S3 = [0.12, -0.01], " + pts + " }")
    assert len(kinetostat.loads(table).loads[-1].table.x) == values
    assert kinetostat.loads(many).size == pytest.approx(0.35)


def test_too_many_points_are_refused():
    from kinetostat.model import MAX_POINTS
    too_many = ", ".join(f"P{i} = [{i * 1e-6}, 0.0]" for i in range(MAX_POINTS + 1))
    with pytest.raises(ModelError, match=f"at most {MAX_POINTS} of them"):
        kinetostat.loads(FOUR_BAR.replace("S3 = [0.12, -0.01] }", "S3 = [0.12, -0.01], " + too_many + " }"))
