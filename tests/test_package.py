"""The package as users get it: the bundled models by name (`kinetostat.examples`, `kinetostat
examples`), the harness not shadowed by a user's own `validation/` folder, and (slow) the wheel
installed into a fresh virtual environment and run from a folder outside the checkout."""
from __future__ import annotations

import os
import re
import subprocess
import sys
import tomllib
import venv
from pathlib import Path

import pytest

import kinetostat
from conftest import MODELS, ROOT
from kinetostat import examples
from kinetostat.cli import EXIT_OK, EXIT_USAGE
from test_readme import readme_examples, readme_python, run_example

NAMES = [p.stem for p in MODELS]
FOREIGN = 'raise ImportError("the foreign validation package of the working directory was imported")\n'


def _env() -> dict:
    """This environment less what could point a child process at the checkout's models or code."""
    e = {k: v for k, v in os.environ.items() if k not in ("KINETOSTAT_MODELS", "PYTHONPATH")}
    e["PIP_DISABLE_PIP_VERSION_CHECK"] = "1"
    return e


def _run(*cmd, cwd: Path, timeout: float = 600) -> subprocess.CompletedProcess:
    return subprocess.run([str(c) for c in cmd], cwd=cwd, env=_env(), capture_output=True, text=True,
                          timeout=timeout, stdin=subprocess.DEVNULL)


@pytest.fixture(autouse=True)
def bundled_models_only(monkeypatch):
    monkeypatch.delenv("KINETOSTAT_MODELS", raising=False)


@pytest.fixture
def foreign_cwd(tmp_path) -> Path:
    """A working directory holding a user's own `validation/` package that fails on import."""
    work = tmp_path / "work"
    (work / "validation").mkdir(parents=True)
    for name in ("__init__.py", "compare.py"):
        (work / "validation" / name).write_text(FOREIGN, encoding="utf-8")
    shadow = _run(sys.executable, "-c", "import validation", cwd=work)     # it is in the way there
    assert shadow.returncode != 0 and "foreign validation package" in shadow.stderr
    return work


# ----------------------------------------------------------------------------- kinetostat.examples

def test_names_and_paths_are_the_checkout_models():
    assert examples.names() == NAMES
    assert [examples.path(n) for n in NAMES] == [examples.path(n + ".toml") for n in NAMES]
    assert [examples.path(n).read_bytes() for n in NAMES] == [p.read_bytes() for p in MODELS]
    assert (examples.models_dir() / "FORMAT.md").is_file()
    with pytest.raises(FileNotFoundError, match="no bundled model named 'nope'; bundled: chain_unit_four_bar"):
        examples.path("nope")


def test_load_by_name_is_the_file():
    by_name = kinetostat.load("ice_crank_slider")
    by_file = kinetostat.load(ROOT / "models" / "ice_crank_slider.toml")
    assert by_name.structure.formula == by_file.structure.formula == "I(0,1) <- II(2,3)"
    assert by_name.links == by_file.links and by_name.pairs == by_file.pairs


def test_copy_refuses_to_overwrite(tmp_path):
    dest = tmp_path / "models"
    written = examples.copy(dest)
    assert sorted(p.name for p in written) == sorted([f"{n}.toml" for n in NAMES] + ["FORMAT.md"])
    assert all((dest / p.name).read_bytes() == p.read_bytes() for p in MODELS)
    (dest / "scotch_yoke.toml").write_text("# my edit\n")
    with pytest.raises(FileExistsError) as exc:
        examples.copy(dest)
    assert exc.value.filename == str(dest / f"{NAMES[0]}.toml")                 # the first one there
    assert (dest / "scotch_yoke.toml").read_text() == "# my edit\n"          # nothing written
    examples.copy(dest, overwrite=True)
    assert (dest / "scotch_yoke.toml").read_bytes() == (ROOT / "models" / "scotch_yoke.toml").read_bytes()
    with pytest.raises(NotADirectoryError):
        examples.copy(dest / "FORMAT.md")


# ----------------------------------------------------------------------------- kinetostat examples

def test_examples_lists_name_formula_and_source(cli):
    r = cli("examples")
    assert r.returncode == EXIT_OK, r.stderr
    rows = r.stdout.splitlines()[1:]
    assert [row.split()[0] for row in rows] == NAMES
    for name, row in zip(NAMES, rows):
        m = kinetostat.load(name)
        assert m.structure.formula in row and m.source in row


def test_examples_follow_kinetostat_models(cli, tmp_path):
    (tmp_path / "mine.toml").write_text((ROOT / "models" / "scotch_yoke.toml").read_text())
    r = cli("examples", env={"KINETOSTAT_MODELS": str(tmp_path)})
    assert r.returncode == EXIT_OK and [row.split()[0] for row in r.stdout.splitlines()[1:]] == ["mine"]


def test_examples_copy_then_refuse_then_force(cli, tmp_path):
    dest = tmp_path / "mine"
    r = cli("examples", "--copy", dest)
    assert r.returncode == EXIT_OK, r.stderr
    assert sorted(p.name for p in dest.iterdir()) == sorted([f"{n}.toml" for n in NAMES] + ["FORMAT.md"])
    (dest / "FORMAT.md").write_text("my notes\n")
    r = cli("examples", "--copy", dest)
    assert r.returncode == EXIT_USAGE
    line, = r.stderr.strip().splitlines()
    assert line.startswith("kinetostat: error: --copy") and str(dest / "chain_unit_four_bar.toml") in line
    assert "--force" in line and (dest / "FORMAT.md").read_text() == "my notes\n"
    assert cli("examples", "--copy", dest, "--force").returncode == EXIT_OK
    assert (dest / "FORMAT.md").read_bytes() == (ROOT / "models" / "FORMAT.md").read_bytes()
    r = cli("examples", "--copy", dest / "FORMAT.md")
    assert r.returncode == EXIT_USAGE and "is not a directory" in r.stderr
    r = cli("examples", "--force")
    assert r.returncode == EXIT_USAGE and "--force only goes with --copy" in r.stderr


# ----------------------------------------------------------------------------- no clash with validation/

def test_a_foreign_validation_folder_does_not_shadow_the_harness(foreign_cwd):
    """`python -m` puts the working directory first on sys.path: the harness must not be `validation`."""
    pytest.importorskip("pinocchio")
    r = _run(sys.executable, "-m", "kinetostat", "validate", "chain_unit_four_bar", "--engines", "pinocchio",
             "--steps", 36, "--no-progress", cwd=foreign_cwd)            # one model: the harness is imported for any
    assert r.returncode == EXIT_OK, r.stdout + r.stderr
    assert "validate: 1 model(s)" in r.stdout and " 0 FAILED" in r.stdout


# ----------------------------------------------------------------------------- the wheel, installed

@pytest.mark.slow
@pytest.mark.timeout(4 * 3600)     # the README's examples besides the install: longer than the suite's 300 s
def test_wheel_in_a_fresh_environment(tmp_path, foreign_cwd):
    """Build the wheel, install it with [all] into a new virtual environment (no system site
    packages, nothing of the checkout), and run the commands from a folder outside the checkout
    that holds a foreign `validation/` package (~1.5 min: the install, ~35 s, and the report); then
    the README's Python and every example of its bash blocks, each from an empty folder (as
    tests/test_readme.py's slow tests do, but with the wheel: the long part)."""
    dist = tmp_path / "dist"
    r = _run(sys.executable, "-m", "pip", "wheel", "--no-deps", "--quiet", "-w", dist, ROOT, cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    wheel, = dist.glob("kinetostat-*.whl")
    venv.create(tmp_path / "venv", with_pip=True)
    bin_ = tmp_path / "venv" / ("Scripts" if os.name == "nt" else "bin")
    py, exe = bin_ / "python", bin_ / "kinetostat"
    r = _run(py, "-m", "pip", "install", "--quiet", f"{wheel}[all]", cwd=tmp_path)
    assert r.returncode == 0, r.stderr

    work = foreign_cwd
    r = _run(py, "-c", "import kinetostat, kinetostat_validation; kinetostat.load('ice_crank_slider'); "
                       "print(kinetostat.examples.models_dir()); print(kinetostat_validation.__file__)", cwd=work)
    assert r.returncode == 0, r.stderr
    models_dir, harness = r.stdout.split()
    for where in (models_dir, harness):               # the installed package, not the checkout
        assert str(tmp_path / "venv") in where and str(ROOT) not in where

    r = _run(exe, "validate", "--engines", "pinocchio", "mujoco", "--steps", 36, "--no-progress", cwd=work)
    assert r.returncode == EXIT_OK, r.stdout + r.stderr
    assert f"validate: {len(NAMES)} model(s)" in r.stdout and " 0 FAILED" in r.stdout

    r = _run(exe, "report", "--out", work / "out", "--steps", 36, "--engines", "pinocchio", "--no-progress", "--no-page",
             cwd=work)
    assert r.returncode == EXIT_OK, r.stdout + r.stderr
    assert (work / "out" / "index.md").is_file()
    assert all((work / "out" / n / "index.html").is_file() for n in NAMES)

    r = _run(exe, "examples", "--copy", work / "mine", cwd=work)
    assert r.returncode == EXIT_OK, r.stderr
    assert sorted(p.name for p in (work / "mine").iterdir()) == sorted([f"{n}.toml" for n in NAMES] + ["FORMAT.md"])

    # two models by file; and report's default output folder is ./reports of the working directory
    r = _run(exe, "validate", "mine/ice_crank_slider.toml", "mine/scotch_yoke.toml", "--engines", "pinocchio",
             "--steps", 36, "--no-progress", cwd=work)
    assert r.returncode == EXIT_OK and "validate: 2 model(s)" in r.stdout, r.stdout + r.stderr
    r = _run(exe, "report", "mine/scotch_yoke.toml", "--steps", 36, "--engines", "pinocchio", "--no-progress",
             cwd=work)
    assert r.returncode == EXIT_OK, r.stdout + r.stderr
    assert (work / "reports" / "scotch_yoke" / "index.md").is_file()

    # the README's and the docs' examples, each from an empty folder, with this wheel installed (tests/test_readme.py)
    empty = tmp_path / "readme"
    empty.mkdir()
    for code in readme_python():
        r = _run(py, "-c", code, cwd=empty)
        assert r.returncode == 0, r.stderr[-3000:]
    for n, command in enumerate(readme_examples()):
        (empty / str(n)).mkdir()
        r = run_example(command, empty / str(n), bin_)
        assert r.returncode == 0 and "Traceback" not in r.stderr, (command, r.stdout[-2000:], r.stderr[-2000:])


def test_the_commands_take_a_bundled_models_name(cli, tmp_path):
    """`kinetostat analyze ice_crank_slider` means the bundled model, as kinetostat.load does;
    a file of that name in the working folder would come first, and a name that is neither
    is still 'model file not found'."""
    by_name = cli("analyze", "ice_crank_slider", "--at", "30", cwd=tmp_path)
    by_path = cli("analyze", kinetostat.examples.path("ice_crank_slider"), "--at", "30", cwd=tmp_path)
    assert by_name.returncode == 0, by_name.stderr
    # the same analysis: every line after the first, which echoes the MODEL as given
    assert by_name.stdout.splitlines()[1:] == by_path.stdout.splitlines()[1:] and len(by_name.stdout) > 500
    r = cli("validate", "chain_unit_four_bar", "--engines", "none", "--steps", "36", "--no-progress", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    missing = cli("analyze", "no_such_model", cwd=tmp_path)
    assert missing.returncode == 2 and "model file not found: no_such_model" in missing.stderr


def test_a_missing_path_that_names_a_bundled_model_names_it(cli, tmp_path, monkeypatch):
    """`models/ice_crank_slider.toml` from a folder without it (a README line run elsewhere): one
    error line naming the bundled model and the copy command, from the CLI and from load; a
    path that names no bundled model gets no hint."""
    r = cli("analyze", "models/ice_crank_slider.toml", "--at", "30", cwd=tmp_path)
    assert r.returncode == 2 and len(r.stderr.splitlines()) == 1, r.stderr
    assert ("model file not found: models/ice_crank_slider.toml; ice_crank_slider is a bundled model: "
            "kinetostat.load('ice_crank_slider')") in r.stderr and "kinetostat examples --copy models" in r.stderr
    monkeypatch.chdir(tmp_path)
    with pytest.raises(kinetostat.ModelFileNotFound) as e:
        kinetostat.load("models/ice_crank_slider.toml")
    assert e.value.problems == ["cannot read file: no such file; " + kinetostat.examples.hint("models/ice_crank_slider.toml")]
    assert "`kinetostat report ice_crank_slider`" in e.value.problems[0]
    assert kinetostat.examples.hint("models/no_such_model.toml") == kinetostat.examples.hint("ice_crank_slider.csv") == ""


def test_the_version_is_the_changelogs_latest_release():
    """pyproject.toml, kinetostat.__version__ (--version, the reports) and CHANGELOG.md's newest
    release heading (`## [0.2.0] - 2026-11-29`, keep-a-changelog) name one version."""
    project = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]["version"]
    releases = re.findall(r"^## \[(\d+\.\d+\.\d+)\] - \d{4}-\d{2}-\d{2}$", (ROOT / "CHANGELOG.md").read_text(encoding="utf-8"), re.M)
    assert project == kinetostat.__version__ == releases[0] == "0.2.0" and releases[-1] == "0.1.0"
