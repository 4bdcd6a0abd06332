"""The accuracy gate as a pytest plugin (entry point `pytest11`, name "kinetostat"): model files
collected as tests, one item per route and quantity and one per published value, e.g.
`models/ice_crank_slider.toml::reference::R_1_2` and `...::published::M_bal_lever`.

Opt-in: `pytest --kinetostat [PATHS]` collects every visited `*.toml` with a `[mechanism]` table
(one that is not a regular file or holds more than the model's MAX_FILE_BYTES is not read: one
failing item `<file>::read` says so, and the gate goes on);
the ini option `kinetostat_models` (glob patterns relative to the rootdir, like
`--doctest-glob`) collects the visited TOML files it matches when `--kinetostat` is not given
(with the flag, the patterns are not applied).
Otherwise nothing is collected and no hook but the options' runs. Engine routes carry the marker
`engines` (`-m "not engines"`: the engine-free gate, the 40-digit reference, the internal lever
identity and the published values); a route whose engine is not installed is SKIPPED with the
reason. A session whose gate items checked nothing beyond the lever identity (all skipped) ends
with exit code 1 and the line "kinetostat: nothing was checked", as `kinetostat validate` does.
A failure names the model file and the line of the published value (route checks: the pair,
drive or point of the quantity, and the line of the route's tolerance), then a verdict line and
a small table, under a header "<model> <route> <quantity>". Each
item's JUnit <properties>: error, measure, tolerance, max_abs, unit, phi_deg, trust, route, file,
line. Under GitHub Actions: `::error file=...,line=...` commands and a Markdown summary in
$GITHUB_STEP_SUMMARY. Text from a model file (a published value's source) reaches each of these
through its channel's escaping (`kinetostat.report.ci`): a failure's lines `one_line` (a newline
shown as "\\n", so that no line of it is read as a workflow command), the commands and the
summary's cells escaped as GitHub and Markdown need. The fixture `kinetostat_regression` is
`kinetostat.testing.check_cycle` with the model and expected files taken from the test file's folder (`--kinetostat-regen`
rewrites the expected file).

It lives in the harness so that pytest's start-up imports only this module (no numpy, no
solver); everything else is imported when a model file is collected.

May use: pytest and the standard library at import; kinetostat and the harness inside functions.
"""
from __future__ import annotations

import fnmatch
import os
import re
from dataclasses import replace
from pathlib import Path
from typing import Any, Callable

import pytest

#: Marker of the engine routes' items, and the routes that need no engine.
ENGINES_MARK = "engines"
ENGINE_FREE = ("reference", "lever", "published")
_MECHANISM = re.compile(rb"^\s*\[\s*mechanism\s*\]", re.MULTILINE)


def pytest_addoption(parser: pytest.Parser) -> None:
    group = parser.getgroup("kinetostat", "kinetostat accuracy gate")
    group.addoption("--kinetostat", action="store_true",
                    help="collect kinetostat model files (*.toml with a [mechanism] table) among the given paths: "
                         "one test per route x quantity and per published value")
    group.addoption("--kinetostat-steps", type=int, default=None, metavar="N",
                    help="crank positions over the cycle of each model (default: ini kinetostat_steps, 360)")
    group.addoption("--kinetostat-regen", action="store_true",
                    help="kinetostat_regression: rewrite the expected CSV files instead of comparing")
    parser.addini("kinetostat_models", type="args", default=[],
                  help="glob patterns (relative to the rootdir) of kinetostat model files to collect; "
                       "when set the gate runs without --kinetostat (--kinetostat PATHS overrides them)")
    parser.addini("kinetostat_steps", default="360", help="crank positions over the cycle of each model")


def _active(config: pytest.Config) -> bool:
    return bool(config.getoption("kinetostat") or config.getini("kinetostat_models"))


def pytest_configure(config: pytest.Config) -> None:
    config.addinivalue_line("markers", "kinetostat: a check of kinetostat's accuracy gate (a model file's item)")
    config.addinivalue_line("markers", f"{ENGINES_MARK}: a kinetostat check against a physics engine route "
                                       "(deselect with -m 'not engines')")
    if _active(config):
        _steps(config)
        config.pluginmanager.register(_Gate(config), "kinetostat-gate")


def _steps(config: pytest.Config) -> int:
    """Crank positions per cycle: --kinetostat-steps, else the ini option (a usage error if not a positive integer)."""
    opt = config.getoption("kinetostat_steps")
    raw = opt if opt is not None else config.getini("kinetostat_steps")
    try:
        steps = int(raw)
    except (TypeError, ValueError):
        steps = 0
    if steps < 1:
        raise pytest.UsageError(f"kinetostat: the number of positions must be a positive integer, got {raw!r}")
    return steps


def pytest_collect_file(file_path: Path, parent: pytest.Collector) -> pytest.Collector | None:
    if file_path.suffix != ".toml" or not _active(parent.config):
        return None
    from kinetostat._text import one_line
    if one_line(str(file_path)) != str(file_path):     # pytest prints a node's path raw: a newline in it
        parent.config.pluginmanager.get_plugin("kinetostat-gate").uncollected.append(one_line(str(file_path)))
        return None                                     # would start a line of its own (a forged '::' command)
    patterns = [] if parent.config.getoption("kinetostat") else parent.config.getini("kinetostat_models")
    if patterns:
        rel = file_path.relative_to(parent.config.rootpath).as_posix() \
            if file_path.is_relative_to(parent.config.rootpath) else file_path.as_posix()
        if not any(fnmatch.fnmatch(rel, p) for p in patterns):
            return None
    else:
        from kinetostat._io import FileTooLarge, NotRegularFile, read_regular
        from kinetostat.model import MAX_FILE_BYTES
        try:
            if not _MECHANISM.search(read_regular(file_path, MAX_FILE_BYTES)):
                return None
        except (NotRegularFile, FileTooLarge) as exc:       # a model or not: it cannot be told without reading it
            return UnreadFile.from_parent(parent, path=file_path, why=exc.strerror)
        except OSError:
            return None
    return ModelFile.from_parent(parent, path=file_path)


def _node_name(text: str, taken: set[str]) -> str:
    """`text` as a node name that -k can select: "R(1,2)" -> "R_1_2", "M_bal (lever)" -> "M_bal_lever"."""
    base = re.sub(r"\W+", "_", text).strip("_") or "value"
    name, n = base, 2
    while name in taken:
        name, n = f"{base}_{n}", n + 1
    taken.add(name)
    return name


class CheckFailed(Exception):
    """A check beyond its tolerance, or a route that raised: the text pytest shows."""


class ModelFile(pytest.File):
    """A model file: its routes (engines, "reference") and its published values as collectors."""

    def collect(self):
        from kinetostat import load
        from kinetostat.model import _read_text
        from kinetostat.report import quantities
        from kinetostat.report.ci import model_lines
        from kinetostat_validation.compare import LEVER, ROUTES

        self.mech = load(self.path)
        self.lines = model_lines(self.mech, _read_text(self.path))
        self._res = None
        self._runs: dict[str, Any] = {}
        self.add_marker("kinetostat")
        for route in (*ROUTES, LEVER):
            yield Route.from_parent(self, name=route, quantities=quantities(self.mech, route))
        if self.mech.published:
            from kinetostat.report.runs import PUBLISHED_ROUTE
            yield Route.from_parent(self, name=PUBLISHED_ROUTE, quantities=[e.symbol for e in self.mech.published])

    def run(self, route: str):
        """The ModelRun that holds `route`'s checks (`kinetostat.report.run_validation`), computed
        once per session: an engine route's own run, or (the lever identity, the published
        values) the run of no engine route; the cycle analysed once."""
        from kinetostat_validation.compare import ROUTES

        key = route if route in ROUTES else ""
        if key not in self._runs:
            from kinetostat import analyze
            from kinetostat.report import run_validation

            if self._res is None:
                self._res = analyze(self.mech, steps=_steps(self.config))
            self._runs[key] = run_validation(self.mech, [key] if key else [], _steps(self.config), res=self._res,
                                             path=self.path)
        return self._runs[key]

    def repr_failure(self, excinfo, style=None):
        from kinetostat.errors import AssemblyError, ModelError, StructureError
        if isinstance(excinfo.value, (ModelError, StructureError, AssemblyError)):
            from kinetostat._text import one_line
            return f"{one_line(str(self.path))}: {excinfo.value}"
        return super().repr_failure(excinfo, style)


class UnreadFile(pytest.File):
    """A visited `*.toml` that is not read (a FIFO, a device, or more than MAX_FILE_BYTES): one
    failing item, `<file>::read`, that says why; the other files are checked as usual."""

    def __init__(self, *, why: str, **kw):
        super().__init__(**kw)
        self.why = why

    def collect(self):
        self.add_marker("kinetostat")
        yield UnreadItem.from_parent(self, name="read")


class UnreadItem(pytest.Item):
    """The item of an `UnreadFile`: fails with the file's name and the reason it was not read."""

    def __init__(self, **kw):
        super().__init__(**kw)
        self.user_properties += [("route", "(model file)"), ("trust", ""), ("file", str(self.path)), ("line", "")]

    def runtest(self) -> None:
        raise CheckFailed(f"{self.path}: not read as a model file: {self.parent.why}")

    def repr_failure(self, excinfo, style=None):
        return str(excinfo.value) if isinstance(excinfo.value, CheckFailed) else super().repr_failure(excinfo, style)

    def reportinfo(self):
        return self.path, None, f"{self.path.name} not read"


class Route(pytest.Collector):
    """One route of a model file: an item per quantity (published values: per symbol)."""

    def __init__(self, *, quantities: list[str], **kw):
        super().__init__(**kw)
        self.quantities = quantities
        if self.name not in ENGINE_FREE:
            self.add_marker(ENGINES_MARK)

    def collect(self):
        taken: set[str] = set()
        for q in self.quantities:
            yield CheckItem.from_parent(self, name=_node_name(q, taken), quantity=q)


class CheckItem(pytest.Item):
    """One check: a route's error on one quantity over the cycle, or one published value."""

    def __init__(self, *, quantity: str, **kw):
        super().__init__(**kw)
        self.quantity = quantity
        self.route = self.parent.name
        self.model: ModelFile = self.parent.parent
        from kinetostat.report.ci import check_where
        from kinetostat.report.runs import trust
        self.where = check_where(self.model.lines, self._rel(self.path), self.route, quantity)
        source = next((e.source for e in self.model.mech.published if e.symbol == quantity), "") \
            if self.route == "published" else ""
        self.user_properties += [("route", self.route), ("quantity", quantity), ("trust", trust(self.route, source)),
                                 ("file", self.where.file), ("line", self.where.line or "")]

    def _rel(self, path: Path | str) -> str:
        """`path` relative to the rootdir, as pytest's node ids name files."""
        p = Path(path)
        return p.relative_to(self.config.rootpath).as_posix() if p.is_relative_to(self.config.rootpath) else str(p)

    def runtest(self) -> None:
        from kinetostat.report.ci import failure_text, tolerance_where

        run = self.model.run(self.route)
        if self.route in run.errors:
            raise CheckFailed(f"{self.where}: route {self.route} raised on {run.stem}: {run.errors[self.route]}")
        if self.route in run.skipped:
            pytest.skip(f"route {self.route}: {run.skipped[self.route]}")
        c = next((c for c in run.checks if c.route == self.route and c.quantity == self.quantity), None)
        if c is None:
            raise CheckFailed(f"{self.where}: route {self.route} returned no row for {self.quantity}")
        self.user_properties += [("check", c.name), ("error", c.error), ("measure", c.measure),
                                 ("tolerance", c.tolerance), ("max_abs", c.max_abs), ("unit", c.unit),
                                 ("phi_deg", c.phi_deg), ("passed", c.passed), ("detail", c.detail)]
        if not c.passed:
            tol = tolerance_where(self.model.lines, self.where.file, self.route, self.quantity)
            if tol is not None and Path(tol.file).is_absolute():
                tol = type(tol)(self._rel(tol.file), tol.line)
            raise CheckFailed(failure_text(c, self.where, tol))

    def repr_failure(self, excinfo, style=None):
        if isinstance(excinfo.value, CheckFailed):
            return str(excinfo.value)
        return super().repr_failure(excinfo, style)

    def reportinfo(self):
        return self.path, (self.where.line - 1 if self.where.line else None), \
            f"{self.path.stem} {self.route} {self.quantity}"


class _Gate:
    """The active gate's session hooks: each item's outcome kept for GitHub Actions' annotations
    and step summary (from the reports' user_properties, so that pytest-xdist's workers count)."""

    def __init__(self, config: pytest.Config):
        self.config = config
        self.outcomes: list = []
        self.uncollected: list[str] = []     # model files whose names hold control characters, as one line each

    def pytest_runtest_logreport(self, report: pytest.TestReport) -> None:
        props = dict(report.user_properties)
        if "trust" not in props or "route" not in props:
            return
        if report.when == "call" or (report.when == "setup" and not report.passed):
            self.outcomes.append(_outcome(report, props))

    @pytest.hookimpl(wrapper=True)
    def pytest_runtest_makereport(self, item: pytest.Item, call):
        """A skipped check is reported at its model file (no line: one line of `-rs` per route)."""
        report = yield
        if isinstance(item, CheckItem) and report.skipped and isinstance(report.longrepr, tuple):
            report.longrepr = (item._rel(item.path), None, report.longrepr[2])
        return report

    def pytest_collectreport(self, report: pytest.CollectReport) -> None:
        if report.failed and report.nodeid.endswith(".toml"):
            from kinetostat.report.ci import Outcome, Where
            self.outcomes.append(Outcome(report.nodeid, "error", "(model file)", Where(report.nodeid), "",
                                         message=str(report.longrepr).strip().splitlines()[-1]))

    def _nothing_checked(self) -> bool:
        """Gate items ran, and every one beyond the lever identity was skipped (or none was there)."""
        from kinetostat.report.runs import LEVER_ROUTE
        return bool(self.outcomes) and all(o.status == "skipped" or (o.route == LEVER_ROUTE and o.status == "passed")
                                           for o in self.outcomes)

    @pytest.hookimpl(tryfirst=True)
    def pytest_sessionfinish(self, session: pytest.Session) -> None:
        if self._nothing_checked() and session.exitstatus == pytest.ExitCode.OK:
            session.exitstatus = pytest.ExitCode.TESTS_FAILED
        if self.uncollected and session.exitstatus in (pytest.ExitCode.OK, pytest.ExitCode.NO_TESTS_COLLECTED):
            session.exitstatus = pytest.ExitCode.TESTS_FAILED

    def pytest_terminal_summary(self, terminalreporter, exitstatus: int, config: pytest.Config) -> None:
        for name in self.uncollected:
            terminalreporter.write_line(f"kinetostat: not collected: {name}: its name holds a control character "
                                        "(pytest would print it raw); rename it -> exit code 1", red=True)
        if not self.outcomes:
            return
        if self._nothing_checked():
            terminalreporter.write_line("kinetostat: nothing was checked: every gate item was skipped but the lever "
                                        "identity, which alone is no independent check -> exit code 1", red=True)
        from kinetostat.report import ci
        if os.environ.get("GITHUB_ACTIONS") == "true" and \
                not config.pluginmanager.hasplugin("pytest_github_actions_annotate_failures"):
            root = config.rootpath
            for line in ci.annotations(replace(o, where=o.where and replace(o.where, file=str(root / o.where.file)))
                                       for o in self.outcomes):
                terminalreporter.write_line(line)
        try:
            if ci.write_summary(ci.summary_markdown(self.outcomes, "kinetostat (pytest)")):
                terminalreporter.write_line("kinetostat: summary -> $GITHUB_STEP_SUMMARY")
        except OSError as exc:
            terminalreporter.write_line(f"kinetostat: warning: cannot write the summary to $GITHUB_STEP_SUMMARY: "
                                        f"{exc.strerror or exc}", yellow=True)


def _outcome(report: pytest.TestReport, props: dict):
    """A report of a CheckItem as a `kinetostat.report.ci.Outcome`."""
    from kinetostat.report.ci import Outcome, Where
    from kinetostat.report.runs import Check

    where = Where(props["file"], props["line"] or None)
    check = None
    if "error" in props:
        model = Path(props["file"]).stem
        check = Check(model, props["route"], props["quantity"], props["error"], props["measure"], props["tolerance"],
                      props["max_abs"], props["unit"], props["phi_deg"], props["passed"], props["detail"],
                      props["trust"])
    status = "passed" if report.passed else "skipped" if report.skipped else "failed" if check else "error"
    message = ""
    if report.skipped and isinstance(report.longrepr, tuple):
        message = report.longrepr[2].removeprefix("Skipped: ").partition(": ")[2]
    elif report.failed and check is None:
        message = str(report.longrepr).strip().splitlines()[0]
    return Outcome(report.nodeid, status, props["route"], where, props["trust"], check, message)


#: The last line of a failing `kinetostat_regression` check: how to accept the obtained values.
REGEN_ACCEPT = ("to accept the obtained values: run pytest again with --kinetostat-regen "
                "(or KINETOSTAT_REGENERATE=1 in the environment)")


@pytest.fixture
def kinetostat_regression(request: pytest.FixtureRequest) -> Callable[..., Path]:
    """`check(model, expected=None, **kw)`: `kinetostat.testing.check_cycle` with the expected CSV
    at `<test file's folder>/<test module>/<test name>.csv` unless `expected` is given. A relative
    `model` or `expected` path is taken from the test file's folder (not the current directory).
    `--kinetostat-regen` rewrites the expected file (keywords as check_cycle's: rtol, atol, steps,
    columns). A mismatch fails the test with check_cycle's message and table alone (no traceback),
    ending with how to accept the obtained values: the flag (REGEN_ACCEPT)."""
    from kinetostat.testing import CycleMismatch, check_cycle

    def check(model, expected: str | Path | None = None, **kw) -> Path:
        __tracebackhide__ = True
        here = request.node.path.parent
        if isinstance(model, (str, os.PathLike)):
            model = here / model
        if expected is None:
            test = request.node
            expected = test.path.parent / test.path.stem / (re.sub(r"\W+", "_", test.name).strip("_") + ".csv")
        if request.config.getoption("kinetostat_regen"):
            kw.setdefault("regenerate", True)
        try:
            return check_cycle(model, here / expected, **kw)
        except CycleMismatch as exc:
            message = f"{exc.finding}\n{REGEN_ACCEPT}" if exc.accept else str(exc)
        pytest.fail(message, pytrace=False)        # outside the except: no "during handling" chain
    return check
