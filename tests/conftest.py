"""Shared fixtures: the bundled models, a base model text for mutation tests, the command
line run in this process (`cli`), and the compiled kernels' cache in a folder of the session."""
from __future__ import annotations

import os
import warnings
from dataclasses import dataclass
import threading
from pathlib import Path

import numpy as np
import pytest

import kinetostat

ROOT = Path(__file__).resolve().parents[1]
MODELS = sorted((ROOT / "models").glob("*.toml"))


@pytest.hookimpl(tryfirst=True)
def pytest_cmdline_main(config: pytest.Config) -> None:
    """The whole suite (`python -m pytest`, no paths given) runs on every core when pytest-xdist
    is installed (`-n 0` or `-p no:xdist` runs it in one process; a run of chosen files or
    tests stays in one process unless `-n` says otherwise)."""
    if (config.pluginmanager.hasplugin("xdist") and config.option.numprocesses is None
            and config.args_source == pytest.Config.ArgsSource.TESTPATHS
            and "PYTEST_XDIST_WORKER" not in os.environ):
        config.option.numprocesses = "auto"
        config.option.dist = "loadfile"         # a module's fixtures and compiled kernels built once


#: Bundled models that together hold every group kind (RRR, RRP, RPR, PRP, RPP), engines and
#: machines: the default suite's sample where a test over every model is costly.
EVERY_KIND = ("chain_unit_four_bar", "ice_crank_slider", "scotch_yoke", "slotted_link_shaper")
#: EVERY_KIND and a triad (a class-III group): the sample where a triad's own rows matter too.
EVERY_GROUP = (*EVERY_KIND, "triad_slider")


def sampled(paths, keep=EVERY_KIND) -> list:
    """`paths` as pytest parameters (ids: their stems): those named in `keep` run by default,
    the others with -m slow."""
    return [pytest.param(p, id=p.stem, marks=() if p.stem in keep else pytest.mark.slow) for p in paths]


@pytest.fixture(scope="session")
def kernel_cache() -> Path:
    """The compiled kernels' cache folder of this machine (`fast.cache_dir()`): the suite loads
    the kernels it needs from it, as every later process does, and compiles only those it lacks
    (the first run on a machine, or after a change of the generated code)."""
    from kinetostat import fast
    return fast.cache_dir()


@pytest.fixture(scope="session")
def chromium():
    """Headless Chromium for the session's browser tests (`sheet_browser.chromium`: skipped,
    saying why, where it cannot be had): one per process, as Playwright's sync API allows."""
    import sheet_browser
    with sheet_browser.chromium() as browser:
        yield browser


@pytest.fixture(params=sampled(MODELS, EVERY_GROUP))
def model_path(request) -> Path:
    """Each bundled model: those of EVERY_GROUP by default, every one with -m slow."""
    return request.param


@pytest.fixture(scope="module")
def ice():
    """The seed 002 worked example: the ICE crank-slider at 30 deg from top dead centre."""
    mech = kinetostat.load(ROOT / "models" / "ice_crank_slider.toml")
    return kinetostat.analyze(mech, phi_deg=[30.0])


@pytest.fixture
def mech(model_path):
    return kinetostat.load(model_path)


@dataclass(frozen=True)
class CLIRun:
    """What a run of the command line gave: exit code and the text of stdout and stderr."""
    returncode: int
    stdout: str
    stderr: str


@pytest.fixture
def cli(capsys, monkeypatch):
    """`cli(*args, env=None, cwd=None)`: `kinetostat.cli.main(args)` run in this process, as
    `python -m kinetostat` would run (exit code, stdout, stderr; an uncaught exception fails the
    test, as a traceback would). $KINETOSTAT_MODELS is unset unless `env` sets it; the working
    directory is the checkout unless `cwd`. A separate process proves nothing more, except for
    the interpreter's own exit status and the entry points (kept as subprocess tests)."""
    from kinetostat.cli import main

    def run(*args, env: dict | None = None, cwd: Path | None = None) -> CLIRun:
        monkeypatch.delenv("KINETOSTAT_MODELS", raising=False)
        for k, v in (env or {}).items():
            monkeypatch.setenv(k, v)
        monkeypatch.chdir(cwd or ROOT)
        monkeypatch.setattr(warnings, "showwarning", warnings.showwarning)   # main() replaces it
        capsys.readouterr()
        try:
            code = main([str(a) for a in args])
        except SystemExit as exc:            # --help and --version exit through argparse
            code = exc.code if isinstance(exc.code, int) else int(exc.code is not None)
        out, err = capsys.readouterr()
        return CLIRun(code, out, err)
    return run


@pytest.fixture
def sketched_plots(monkeypatch):
    """`sketch_plots` for one test."""
    sketch_plots(monkeypatch)


def sketch_plots(monkeypatch: pytest.MonkeyPatch) -> None:
    """A report's plots and plan pictures each written as a 1-pixel PNG under its own name
    (atomically, as the real ones): for tests of what a report does with its folders, files
    and tables, at a tenth of the time. test_report and the injection tests draw them."""
    from kinetostat._io import atomic
    from kinetostat.report import writer

    def sketch(*args) -> Path:
        with atomic(args[-1]) as f:
            f.write('<svg xmlns="http://www.w3.org/2000/svg" width="1" height="1"/>\n')
        return Path(args[-1])
    for name in ("plot_mechanism", "plot_moment", "plot_balancing_force", "plot_reactions", "plot_errors",
                 "plot_hodographs", "plot_tornado"):
        monkeypatch.setattr(writer, name, sketch)


# A small four-bar written only here: frame O=(0,0), C=(0.3,0); crank 0.1, coupler 0.35, rocker 0.3.
FOUR_BAR = """
[mechanism]
name = "test four-bar"
g = 9.81
[drive]
pivot = "O"
point = "A"
reference = [1.0, 0.0]
sense = "ccw"
rpm = 300.0
eps = 0.0
kind = "engine"
[frame]
O = [0.0, 0.0]
C = [0.3, 0.0]
[[link]]
id = 1
points = { O = [0.0, 0.0], A = [0.1, 0.0], S1 = [0.03, 0.01] }
mass = 0.8
I_S = 0.001
com = "S1"
[[link]]
id = 2
points = { A = [0.0, 0.0], B = [0.35, 0.0], S2 = [0.15, 0.02] }
mass = 1.5
I_S = 0.016
com = "S2"
[[link]]
id = 3
points = { C = [0.0, 0.0], B = [0.3, 0.0], S3 = [0.12, -0.01] }
mass = 1.2
I_S = 0.009
com = "S3"
[[pair]]
kind = "R"
links = [0, 1]
point = "O"
[[pair]]
kind = "R"
links = [1, 2]
point = "A"
[[pair]]
kind = "R"
links = [2, 3]
point = "B"
[[pair]]
kind = "R"
links = [0, 3]
point = "C"
[[group]]
links = [2, 3]
branch = 1
[[load]]
name = "resisting moment"
kind = "moment"
link = 3
value = -4.0
"""


def four_bar(*edits: tuple[str, str], append: str = "") -> str:
    """FOUR_BAR with (old, new) text edits, each of which must apply, and tables appended:
    the variants the engine tests need (other sense, springs, forces) without copies of it."""
    text = FOUR_BAR
    for old, new in edits:
        assert old in text, old
        text = text.replace(old, new, 1)
    return text + append


def kinetic_energy(mech, phi_deg) -> np.ndarray:
    """Kinetic energy of all moving links at crank angles phi_deg, J (for energy-balance tests)."""
    import warnings
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", kinetostat.SingularPositionWarning)
        r = kinetostat.analyze(mech, phi_deg=phi_deg)
    T = np.zeros(len(r.phi_deg))
    for link in mech.links[1:]:
        if link.mass:
            v = r.kin.point(link.id, link.points[link.com])[1]
            T += 0.5 * link.mass * np.sum(v * v, axis=-1)
        T += 0.5 * link.I_S * r.omega(link.id) ** 2
    return T


def within(call, seconds: float = 10.0):
    """`call()` in a thread: what it returned or raised; a failure where it does not end in time."""
    out: list = []

    def run():
        try:
            out.append(call())
        except BaseException as exc:        # noqa: BLE001 (handed to the test)
            out.append(exc)
    t = threading.Thread(target=run, daemon=True)
    t.start()
    t.join(seconds)
    assert out, f"{call} did not return within {seconds} s"
    return out[0]


@pytest.fixture
def sketched_report(monkeypatch):
    """`sketch_report` for one test."""
    sketch_report(monkeypatch)


def sketch_report(monkeypatch: pytest.MonkeyPatch) -> None:
    """`sketch_plots`, and each plan sheet of a report (`kinetostat.plans.svg`, most of a sketched
    report's time) written as a 1-pixel SVG too: for tests of a report's text, tables, folders and
    errors that look at no picture (the sheets themselves: tests/test_plans*.py)."""
    import kinetostat.plans
    sketch_plots(monkeypatch)
    monkeypatch.setattr(kinetostat.plans, "svg", lambda plan, **_: '<svg xmlns="http://www.w3.org/2000/svg" width="1" height="1"/>\n')
