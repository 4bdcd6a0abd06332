"""`validate`: the solver cross-checked against the engine routes, its table, JSON and GitHub
annotations, and its exit code (`exit_code`).

May use: `.common`, `kinetostat._forecast` (the estimated time), the solver, the harness (imported inside the command).
"""
from __future__ import annotations

import logging
import os
import time
from typing import Sequence

from .._forecast import Forecast
from .._text import one_line
from .common import EXIT_FAIL, EXIT_NOT_CHECKED, EXIT_OK, _Out, _checkpoint, _done, _close, _engines, _error, _is_stdout, _lines, _prepare, _progress, _save, _warn, _writable_file, bundled_models

log = logging.getLogger(__name__)


def exit_code(runs, absent: Sequence[str] = ()) -> int:
    """The exit code of `validate` for these ModelRuns: 1 (EXIT_FAIL) if a check (a route's error,
    the lever identity or a published value) failed or a route raised; else 3 (EXIT_NOT_CHECKED)
    if a model, or the run, has no check beyond the lever identity (every route skipped, no
    published value), or a route named with --engines is `absent` (its engine not installed);
    else 0."""
    if any(not r.passed for r in runs):
        return EXIT_FAIL
    if not runs or any(not r.checked for r in runs) or absent:
        return EXIT_NOT_CHECKED
    return EXIT_OK


def _coverage(run) -> str:
    """One line for people: what checked this model (routes with their number of quantities,
    the published values) and what was skipped, and why."""
    from ..report.runs import LEVER_ROUTE as LEVER, PUBLISHED_ROUTE as PUBLISHED
    done = [f"{route} ({n} {'quantity' if n == 1 else 'quantities'})" for route in run.engines
            if route != LEVER and (n := sum(c.route == route for c in run.checks))]
    if run.published:
        done.append(f"{PUBLISHED} ({len(run.published)} values)")
    skipped = [f"{route} ({why})" for route, why in run.skipped.items()]
    if not run.published and PUBLISHED not in run.errors:
        skipped.append(f"{PUBLISHED} (the model has no [[published]] values)")
    identity = "; the lever identity held" if any(c.route == LEVER and c.passed for c in run.checks) else ""
    return (f"  checked by: {', '.join(done) or 'nothing'}{identity}"
            + (f"; not checked by: {'; '.join(skipped)}" if skipped else ""))


def validation_table(run) -> str:
    """The checks of one ModelRun, one line each: route (or "published"), quantity, error,
    tolerance, max abs error, verdict; skipped and failed routes one line each."""
    from ..report.runs import PUBLISHED_ROUTE as PUBLISHED
    m = run.mech
    checks = run.checks
    w = max([9] + [len(c.quantity) for c in checks])
    lines = [f"== {run.stem}: {m.name}   {m.structure.formula}, {len(run.res.phi_deg)} positions",
             f"  {'route':<11s} {'quantity':<{w}s} {'error':>12s} {'tolerance':>9s} {'max abs err':>15s}  result"]
    routes = list(run.engines) + ([PUBLISHED] if run.published or PUBLISHED in run.errors else [])
    for route in routes:
        if route in run.errors:
            lines.append(f"  {route:<11s} {'(all)':<{w}s} {'-':>12s} {'-':>9s} {'-':>15s}  ERROR: {run.errors[route]}")
            continue
        if route in run.skipped:
            lines.append(f"  {route:<11s} {'(all)':<{w}s} {'-':>12s} {'-':>9s} {'-':>15s}  SKIPPED: {run.skipped[route]}")
            continue
        for c in (c for c in checks if c.route == route):
            row = next((r for r in run.rows if r.route == route and r.quantity == c.quantity), None)
            extra = f" ({row.n_skipped} NaN angles left out)" if row is not None and row.n_skipped else ""
            err, tol = ((f"{c.error:8.3g} deg", f"{c.tolerance:5g} deg") if c.measure == "deg"
                        else (f"{c.error:12.2e}", f"{c.tolerance:9.0e}"))
            lines.append(f"  {route:<11s} {c.quantity:<{w}s} {err:>12s} {tol:>9s} "
                         f"{c.max_abs:11.3e} {c.unit:<3s}  {'PASS' if c.passed else 'FAIL'}{extra}")
    n, f = len(checks), sum(not c.passed for c in checks)
    verdict = "PASS" if run.passed and run.checked else "FAIL" if not run.passed else "NOT CHECKED (nothing compared)"
    lines.append(_coverage(run))
    lines.append(f"  => {verdict}: {n} checks ({len(run.published)} published values), {f} failed, "
                 f"{len(run.skipped)} route(s) skipped, {len(run.errors)} with errors")
    return _lines(lines)


def cmd_validate(args) -> int:
    from ..report import run_validation
    engines = _engines(args.engines)
    junit = _writable_file(args.junit, "--junit") if args.junit else None
    to_json = (None if args.json is None else "-" if _is_stdout(args.json)
               else _writable_file(args.json, "--json"))
    err = to_json == "-"                 # the JSON on stdout: the people's lines go to stderr
    paths = args.models or bundled_models()
    jobs = _prepare(paths, args.steps)
    runs = []
    t0 = time.perf_counter()
    eta = Forecast(log, len(jobs), "model(s)", faster=["--engines none"] if engines != ["reference"] else [])
    bar = _progress(len(jobs) * len(engines), "validate", not args.no_progress)
    try:
        for path, mech, res, secs in jobs:
            bar.set_postfix_str(path.stem)
            run = run_validation(mech, engines, args.steps, res=res, path=path,
                                 on_route=lambda r: (_checkpoint(), bar.update()))
            run.solver_seconds = secs
            runs.append(run)
            for w in run.warnings:
                _warn(f"{path.name}: {w}")
            _Out.write(validation_table(run), err=err)
            eta.done()
    finally:
        _close(bar)
    checks = [c for run in runs for c in run.checks]
    n_fail = sum(not c.passed for c in checks)
    n_pub = sum(len(run.published) for run in runs)
    n_err = sum(len(run.errors) for run in runs)
    n_skip = sum(len(run.skipped) for run in runs)
    from kinetostat_validation.compare import available
    absent = [r for r in engines if args.engines and available(r)]     # named, and not installed
    code = exit_code(runs, absent)
    unchecked = [run.stem for run in runs if not run.checked]
    _Out.write(f"validate: {len(runs)} model(s), {len(checks)} checks ({n_pub} published values): "
               f"{len(checks) - n_fail} passed, {n_fail} FAILED; {n_err} route error(s), {n_skip} route(s) skipped; "
               f"{len(unchecked)} model(s) NOT CHECKED{': ' + ', '.join(unchecked) if unchecked else ''}; "
               f"{time.perf_counter() - t0:.1f} s"
               + {EXIT_OK: "", EXIT_FAIL: " -> FAIL", EXIT_NOT_CHECKED: " -> NOT CHECKED (exit 3)"}[code], err=err)
    if not any(run.checked for run in runs):
        _error("nothing was checked: every route was skipped or raised, and no model has published values "
               "(the lever identity alone is no independent check)")
    if absent:
        _error(f"--engines {' '.join(absent)}: not installed, so nothing was checked by "
               f"{'it' if len(absent) == 1 else 'them'} (pip install 'kinetostat[engines]')")
    _github(runs, err)
    if to_json is not None:
        _write_validation_json(runs, code, to_json)
    if junit is not None:
        from ..report import junit_xml
        tree = junit_xml(runs)
        _save(junit, "--junit", lambda f: tree.write(f, encoding="utf-8", xml_declaration=True), binary=True)
        _done(one_line(f"JUnit XML -> {junit}"))
    return code


def _github(runs, err: bool) -> None:
    """Under GitHub Actions: an `::error file=...,line=...` command per failed check (the model
    file's line; on stderr when `err`, the JSON then holding stdout) and the Markdown summary,
    verdict first, appended to $GITHUB_STEP_SUMMARY (wherever that variable is set)."""
    if os.environ.get("GITHUB_ACTIONS") != "true" and not os.environ.get("GITHUB_STEP_SUMMARY"):
        return
    from ..report import ci
    outcomes = ci.run_outcomes(runs)
    if os.environ.get("GITHUB_ACTIONS") == "true":
        for line in ci.annotations(outcomes):
            _Out.write(line, err=err)
    try:
        ci.write_summary(ci.summary_markdown(outcomes, "kinetostat validate"))
    except OSError as exc:
        _warn(f"cannot write the summary to $GITHUB_STEP_SUMMARY: {exc.strerror or exc}")


def _write_validation_json(runs, code: int, dest) -> None:
    """`validate --json`: the checks of every run as JSON (NaN as null), to a file or stdout ('-')."""
    import json
    from ..report import validation_json
    text = json.dumps(validation_json(runs, code), indent=1, allow_nan=False) + "\n"
    if dest == "-":
        _Out.write(text.rstrip("\n"))
        return
    _save(dest, "--json", lambda f: f.write(text))
    _done(one_line(f"JSON -> {dest}"))
