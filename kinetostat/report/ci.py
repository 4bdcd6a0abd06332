"""The gate's checks as a CI pipeline shows them: where in a model file a check points (the line of
a published value, of the pair, drive or point a route's quantity belongs to) and where a
route's tolerance is set; one failure as a verdict line and a small table; GitHub Actions'
`::error file=...,line=...` commands; and the Markdown summary of a run, verdict first, for
$GITHUB_STEP_SUMMARY. Used by `kinetostat validate` and the pytest plugin
(`kinetostat_validation.pytest_plugin`). Every text from a model reaches each channel through
its one escaping function of `kinetostat._text`: `one_line` (the terminal),
`workflow_command_text` (the commands), `markdown_text` (the summary's cells).

May use: the standard library, `kinetostat._text`, the model's line finder and file reader, `_io`
(appending to a regular file), the runs room; the harness inside the function that needs it.
"""
from __future__ import annotations

import math
import os
import tomllib
from dataclasses import dataclass
from pathlib import Path
from typing import Iterable, Sequence

from .._io import open_append
from .._text import markdown_text, one_line, workflow_command_text
from ..model import Mechanism, _Lines, _read_text
from .runs import LEVER_ROUTE, PUBLISHED_ROUTE, Check, ModelRun, trust

@dataclass(frozen=True)
class Where:
    """A line of a file (line None: the file as a whole)."""
    file: str
    line: int | None = None

    def __str__(self) -> str:
        return self.file if self.line is None else f"{self.file}:{self.line}"


def model_lines(mech: Mechanism, text: str) -> dict[tuple[str, str], int]:
    """(route, quantity) -> line of the model file `text` that the check points at: a published
    value's `value` line (route "published", keyed by its symbol); for the routes' quantities
    ("" as route) the pair's table (R, P_f), the [drive] table (M_drive, F_bal), the line that
    places a tracked point (x, v, a)."""
    data = tomllib.loads(text)
    at = _Lines(text).line
    out: dict[tuple[str, str], int | None] = {("", "M_drive"): at(("drive",)), ("", "F_bal"): at(("drive",))}
    for k, t in enumerate(data.get("published", [])):
        if isinstance(t, dict) and isinstance(t.get("symbol"), str):
            out[(PUBLISHED_ROUTE, t["symbol"])] = at(("published", k, "value"))
            out[(PUBLISHED_ROUTE + ".tolerance", t["symbol"])] = at(("published", k, "tolerance_deg"
                                                                     if "tolerance_deg" in t else "tolerance"))
    tables = data.get("pair", [])
    for k, p in enumerate(mech.pairs):
        if k < len(tables) and isinstance(tables[k], dict) and tuple(tables[k].get("links", ())) == p.links:
            for sym in ("R", "P_f"):
                out[("", f"{sym}({p.links[0]},{p.links[1]})")] = at(("pair", k))
    frame = data.get("frame")
    points: dict[str, tuple] = {name: ("frame", name) for name in frame} if isinstance(frame, dict) else {}
    for k, t in enumerate(data.get("link", [])):
        if isinstance(t, dict) and isinstance(t.get("points"), dict):
            points.update({name: ("link", k, "points", name) for name in t["points"]})
    for name, path in points.items():
        for sym in "xva":
            out[("", f"{sym}({name})")] = at(path)
    return {k: v for k, v in out.items() if v is not None}


def check_where(lines: dict[tuple[str, str], int], file: str, route: str, quantity: str) -> Where:
    """The line of `file` a check of (route, quantity) points at (`model_lines`); the [drive]'s
    line, or the file as a whole, where none is known."""
    key = (PUBLISHED_ROUTE, quantity) if route == PUBLISHED_ROUTE else ("", quantity)
    return Where(file, lines.get(key, lines.get(("", "M_drive"))))


def tolerance_where(lines: dict[tuple[str, str], int], file: str, route: str, quantity: str) -> Where | None:
    """Where the tolerance of a check is set: the published value's `tolerance` line in the model
    file, or the route's entry in the harness' TOLERANCES (validation/compare.py)."""
    if route == PUBLISHED_ROUTE:
        line = lines.get((PUBLISHED_ROUTE + ".tolerance", quantity))
        return Where(file, line) if line else None
    from kinetostat_validation import compare
    src = Path(compare.__file__)
    for n, text in enumerate(src.read_text(encoding="utf-8").splitlines(), 1):
        if text.lstrip().startswith(f'"{route}": Tolerance('):
            return Where(str(src), n)
    return None


@dataclass(frozen=True)
class Outcome:
    """One check (or one route as a whole, when it was skipped or raised) as a pipeline shows it."""
    name: str              # the check's name: "<model>.<route>.<quantity>" or a pytest node id
    status: str            # "passed", "failed", "skipped" or "error"
    route: str
    where: Where | None    # the model file's line it points at
    trust: str
    check: Check | None = None   # the measurement, where one was made
    message: str = ""      # the reason of a skip or an error


def run_outcomes(runs: Sequence[ModelRun]) -> list[Outcome]:
    """Every check of `kinetostat validate`'s runs as Outcomes: each check, each skipped route
    and each route that raised (once)."""
    out = []
    for run in runs:
        file = "" if run.path is None else str(run.path)
        try:
            lines = model_lines(run.mech, _read_text(run.path)) if run.path is not None else {}
        except (OSError, ValueError):
            lines = {}
        routes = list(run.engines) + ([PUBLISHED_ROUTE] if run.published or PUBLISHED_ROUTE in run.errors else [])
        for route in routes:
            name = f"{run.stem}.{route}"
            if route in run.errors:
                out.append(Outcome(name, "error", route, Where(file) if file else None, trust(route),
                                   message=run.errors[route]))
            elif route in run.skipped:
                out.append(Outcome(name, "skipped", route, None, trust(route), message=run.skipped[route]))
            else:
                out += [Outcome(c.name, "passed" if c.passed else "failed", route,
                                check_where(lines, file, route, c.quantity) if file else None, c.trust, c)
                        for c in run.checks if c.route == route]
    return out


def _num(x: float, fmt: str) -> str:
    return format(x, fmt) if math.isfinite(x) else "NaN"


def measured(c: Check) -> tuple[str, str, str]:
    """(error, tolerance, angle) of a check as the tables print them."""
    if c.measure == "deg":
        err, tol = f"{_num(c.error, '.3g')} deg", f"{c.tolerance:g} deg"
    elif c.measure == "relative":
        err, tol = f"{_num(100 * c.error, '.3g')} %", f"{100 * c.tolerance:g} %"
    else:
        err, tol = f"{_num(c.error, '.2e')} of peak", f"{c.tolerance:.0e}"
    return err, tol, f"{_num(c.phi_deg, 'g')} deg"


def verdict_line(c: Check, where: Where | None) -> str:
    """One line: where, what and by how much a check missed its tolerance."""
    err, tol, _ = measured(c)
    what = (f"published value {c.quantity} of {c.model}" if c.route == PUBLISHED_ROUTE
            else f"{c.quantity} of {c.model} on route {c.route}")
    return f"{'' if where is None else f'{where}: '}{what}: error {err} > tolerance {tol}"


def failure_text(c: Check, where: Where | None, tolerance_at: Where | None) -> str:
    """A failed check for people: the verdict line, a small table (error, tolerance, unit, the
    angle of the worst error, route, trust), the check's own line and where its tolerance is set;
    each line `one_line` (a newline in a published value's source shown as "\\n")."""
    err, tol, phi = measured(c)
    head = ["error", "tolerance", "max |diff|", "unit", "angle", "route"]
    row = [err, tol, f"{_num(c.max_abs, '.4g')}", c.unit or "-", phi, c.route]
    w = [max(len(a), len(b)) for a, b in zip(head, row)]
    lines = [verdict_line(c, where), "",
             "  " + "  ".join(h.ljust(n) for h, n in zip(head, w)),
             "  " + "  ".join(r.ljust(n) for r, n in zip(row, w)), "",
             f"  {c.detail}",
             f"  trust: {c.trust if c.route != PUBLISHED_ROUTE else 'the published value (source above)'}"]
    if tolerance_at is not None:
        lines.append(f"  tolerance set at {tolerance_at}")
    return "\n".join(map(one_line, lines))


def annotation(where: Where, title: str, message: str, workspace: str | None = None) -> str:
    """GitHub Actions' `::error file=...,line=...,title=...::message` command; the file relative
    to `workspace` (default $GITHUB_WORKSPACE, else the working directory), as a pull request's
    diff names it."""
    file = where.file
    base = workspace or os.environ.get("GITHUB_WORKSPACE") or os.getcwd()
    try:
        file = os.path.relpath(os.path.abspath(file), base)
    except ValueError:                      # another drive (Windows)
        pass
    loc = f"file={workflow_command_text(file.replace(os.sep, '/'), True)}"
    if where.line is not None:
        loc += f",line={where.line}"
    return f"::error {loc},title={workflow_command_text(title, True)}::{workflow_command_text(message)}"


def annotations(outcomes: Iterable[Outcome]) -> list[str]:
    """One `::error` command per failed check or route error that points at a file."""
    out = []
    for o in outcomes:
        if o.status in ("failed", "error") and o.where is not None:
            msg = verdict_line(o.check, None) if o.check is not None else f"route {o.route}: {o.message}"
            out.append(annotation(o.where, f"kinetostat: {o.name}", f"{msg} ({o.trust})"))
    return out


def summary_markdown(outcomes: Sequence[Outcome], title: str) -> str:
    """The run as Markdown, verdict first: counts, a table of the failed checks and route errors
    (where, error, tolerance, unit, angle, route, trust), the skipped routes with their reasons,
    and every check in a collapsed table; every cell's text `markdown_text` (shown as text: no
    tag, link or extra cell)."""
    count = {s: sum(o.status == s for o in outcomes) for s in ("passed", "failed", "skipped", "error")}
    ok = not count["failed"] and not count["error"] and any(o.status == "passed" and o.route != LEVER_ROUTE
                                                            for o in outcomes)
    verdict = "PASS" if ok else "FAIL" if count["failed"] or count["error"] else "NOT CHECKED"
    lines = [f"## {title}: {verdict}", "",
             f"{count['passed']} passed, {count['failed']} failed, {count['error']} errors, "
             f"{count['skipped']} skipped.", ""]
    head = "| check | where | error | tolerance | unit | angle | route | trust |\n|---|---|---|---|---|---|---|---|"

    def row(o: Outcome) -> str:
        if o.check is None:
            cells = [o.name, str(o.where or ""), f"{o.status.upper()}: {o.message}", "", "", "", o.route, o.trust]
        else:
            err, tol, phi = measured(o.check)
            cells = [o.name, str(o.where or ""), err, tol, o.check.unit, phi, o.route, o.trust]
        return "| " + " | ".join(map(markdown_text, cells)) + " |"

    bad = [o for o in outcomes if o.status in ("failed", "error")]
    if bad:
        lines += ["### Failed", "", head, *map(row, bad), ""]
    skipped = dict.fromkeys(f"{o.route}: {o.message}" for o in outcomes if o.status == "skipped")
    if skipped:
        lines += ["### Skipped", "", *(f"- {markdown_text(s)}" for s in skipped), ""]
    ran = [o for o in outcomes if o.check is not None]
    if ran:
        lines += ["<details><summary>Every check</summary>", "", head, *map(row, ran), "", "</details>", ""]
    return "\n".join(lines)


def write_summary(markdown: str) -> bool:
    """Append `markdown` to $GITHUB_STEP_SUMMARY when it is set; True if written. Only to a
    regular file (`open_append`: a FIFO, device or socket raises at once, never blocks). An
    OSError (a path that cannot be written, or is not a regular file) is the caller's to report
    as one warning line."""
    dest = os.environ.get("GITHUB_STEP_SUMMARY")
    if not dest:
        return False
    with open_append(dest) as f:
        f.write(markdown.rstrip("\n") + "\n\n")
    return True
