"""`report`: the per-mechanism error reports, in worker processes (`--jobs`), most work first; its
first line (what it will do) once the options and models are checked, before any model's report,
then each model's progress (engine routes, figures, tables, plans and page) as each part is done,
logged at INFO.

May use: `.common`, `kinetostat._forecast` (the estimated time), the solver, `kinetostat.report` and the harness (imported inside the command).
"""
from __future__ import annotations

import logging
import os
import signal
import time
import warnings
from pathlib import Path
from typing import Sequence

from .._forecast import Forecast
from .._io import unique_names, unit
from .._text import one_line
from .common import CLIError, EXIT_FAIL, EXIT_INTERRUPTED, EXIT_OK, NORMAL, _Out, _checkpoint, _close, _done, _engines, _error, _load, _log_lines, _prepare, _progress, _warn, _writable_dir, bundled_models


#: path -> (mechanism, analysis, solver seconds) of the models `cmd_report` prepared: a forked
#: worker (or this process with --jobs 1) finds them here and does not load and analyse the model
#: again; under another start method the dict is empty and the job does both itself.
_PREPARED: dict[str, tuple] = {}

log = logging.getLogger(__name__)


def _report_job(path: str, engines: list[str], steps: int, out: str, folder: str, page: bool = True,
                friction: str = "first", law: tuple = (None, None)) -> dict:
    """One model's report: load, analyse (or take both from `_PREPARED`), run the routes, write
    `out/<folder>/` (`law`: --delta, --flywheel; with `page`, its page.html drawn; without, an
    earlier page.html removed). Returns {"summary", "warnings", "seconds", "page": "drawn" or
    None} or {"error"} (one line); raises only KeyboardInterrupt."""
    from ..examples import resolve
    from ..report import run_validation, write_report
    t0 = time.perf_counter()
    try:
        from ..solve import analyze
        if path in _PREPARED:
            mech, res, secs = _PREPARED[path]
        else:
            mech = _load(path)
            with warnings.catch_warnings():       # the main process printed the analysis' warnings
                warnings.simplefilter("ignore")
                t1 = time.perf_counter()
                res = analyze(mech, steps=steps)
                secs = time.perf_counter() - t1
        run = run_validation(mech, engines, steps, res=res, path=resolve(path), level=logging.INFO)
        run.solver_seconds = secs
        earlier = Path(out) / folder / "page.html"
        with unit(out) as tmp:                # the model's files swapped in as a set at the end
            summary = write_report(run, tmp, folder, page=page, friction=friction, delta=law[0], flywheel=law[1])
        notes = list(run.warnings)
        if not page and (earlier.is_file() or earlier.is_symlink()):
            try:
                earlier.unlink()              # an earlier run's page, no longer linked
            except OSError as exc:
                notes.append(f"report written; the earlier {earlier} not removed: {exc.strerror or exc}")
    except OSError as exc:
        return {"error": f"cannot write the report into {out}: {exc.strerror or exc}"}
    except Exception as exc:                  # noqa: BLE001 -- one model's fault is its error line
        msg = str(exc).strip().splitlines()
        return {"error": f"{type(exc).__name__}: {msg[0] if msg else ''}".rstrip(": ")}
    return {"summary": summary, "warnings": notes, "seconds": time.perf_counter() - t0, "page": "drawn" if page else None}


def _worker_init(verbosity: int = NORMAL) -> None:
    """A report worker ends at once, silently, on Ctrl-C (the terminal sends it to the whole
    process group): the main process reports the interruption. A KeyboardInterrupt would not
    do, as it can land in a garbage-collection callback, which swallows it. The temporary file
    of a write in progress is removed first (the files already written stay as they are). Its
    log lines go to stderr at the command's `verbosity`, under any start method, printed
    plainly (the progress bar is the main process's)."""
    from .._io import remove_temporary
    _Out.bar = None
    _log_lines(verbosity)

    def end(signum, frame):
        remove_temporary()
        os._exit(EXIT_INTERRUPTED)
    signal.signal(signal.SIGINT, end)


def _report_cost(mech) -> int:
    """A model's rough share of the report's time, to start the longest first: the work grows
    with the pairs, and the simulations run twice for a machine (its mesh force from a first run)."""
    return len(mech.pairs) * (2 if mech.drive.kind == "machine" else 1)


def _report_results(paths: list[Path], folders: list[str], engines: list[str], steps: int, out: Path, jobs: int,
                    costs: Sequence[int] = (), page: bool = True, friction: str = "first", verbosity: int = NORMAL,
                    law: tuple = (None, None)):
    """Yield (index into `paths`, result of _report_job) as each model finishes; `jobs` > 1 runs
    them in a process pool (only paths and names cross to the workers, so any start method
    works), the largest `costs` first, 1 in this process; the workers log at `verbosity`. Ctrl-C
    cancels the models not started and raises KeyboardInterrupt here."""
    if jobs == 1 or len(paths) == 1:
        for n, p in enumerate(paths):
            yield n, _report_job(str(p), engines, steps, str(out), folders[n], page, friction, law)
        return
    from concurrent.futures import ProcessPoolExecutor, as_completed
    pool = ProcessPoolExecutor(max_workers=min(jobs, len(paths)), initializer=_worker_init,
                               initargs=(verbosity,))
    try:
        first = sorted(range(len(paths)), key=lambda n: -costs[n] if costs else 0)
        futures = {pool.submit(_report_job, str(paths[n]), engines, steps, str(out), folders[n], page, friction, law): n
                   for n in first}
        for f in as_completed(futures):
            try:
                r = f.result()
            except Exception as exc:          # noqa: BLE001 -- a worker that died (BrokenProcessPool)
                r = {"error": f"its worker process failed ({type(exc).__name__}: {exc})"}
            yield futures[f], r
    except BaseException:
        pool.shutdown(wait=True, cancel_futures=True)
        raise
    pool.shutdown(wait=True)


def cmd_report(args) -> int:
    import importlib.util
    if importlib.util.find_spec("matplotlib") is None:
        raise CLIError("kinetostat report needs matplotlib: pip install 'kinetostat[reports]'")
    from ..report import MIN_REPORT_STEPS, write_index
    if args.steps < MIN_REPORT_STEPS:
        raise CLIError(f"--steps {args.steps}: a report over the cycle needs at least {MIN_REPORT_STEPS} positions")
    engines = _engines(args.engines)
    out = _writable_dir(args.out, "--out")
    earlier = _earlier_reports(args.check, out) if args.check is not None else None
    paths = args.models or bundled_models()
    prepared = _prepare(paths, args.steps)     # input errors stop the command before any route runs
    jobs, cores = args.jobs or os.cpu_count() or 1, os.cpu_count() or 1
    log.info(one_line(f"report: {len(paths)} model(s) into {out}: routes lever, {', '.join(engines)}; "
                      f"{'pages' if args.page else 'no pages'}; {min(jobs, len(paths))} at a time"))
    _PREPARED.clear()
    _PREPARED.update({str(p): (mech, res, secs) for p, mech, res, secs in prepared})
    order = [p for p, *_ in prepared]
    folders = unique_names([p.stem for p in order])     # never '.', '..' or a path; two a.toml: a, a-2
    t0 = time.perf_counter()
    summaries: dict[int, dict] = {}
    n_fail, n_err = 0, 0
    eta = Forecast(log, len(order), "model(s)", parallel=jobs,
                   faster=([f"--jobs {cores}"] if jobs < cores else []) + (["--no-page"] if args.page else [])
                   + (["--engines none"] if engines != ["reference"] else []))
    bar = _progress(len(order), "report", not args.no_progress)
    try:
        for n, r in _report_results(order, folders, engines, args.steps, out, jobs,
                                    [_report_cost(mech) for _, mech, *_ in prepared], args.page,
                                    args.friction or "first", args.verbosity, (args.delta, args.flywheel)):
            _checkpoint()
            path = order[n]
            bar.update()
            eta.done()
            if "error" in r:
                n_err += 1
                _error(f"{path.name}: {r['error']} (no report written)")
                continue
            for w in r["warnings"]:
                _warn(f"{path.name}: {w}")
            s = r["summary"]
            summaries[n] = s
            n_fail += not s["passed"]
            status = "PASS" if s["passed"] and s["checked"] else "FAIL" if not s["passed"] else "NOT CHECKED"
            routes = ", ".join(f"{name} {info['status']}" for name, info in s["routes"].items())
            page = f", page {r['page']}" if r.get("page") else ""
            _done(one_line(f"{path.stem:<26s} {status:<5s} ({routes})  {r['seconds']:5.1f} s{page}"
                                f"  -> {out / s['stem'] / 'index.html'}"))
        index = out / "index.md"
        keep = n_err and index.exists()     # a model without a report: the earlier index is not lost
        if not keep:
            try:
                index = write_index(out, [summaries[n] for n in range(len(order)) if n in summaries])
            except OSError as exc:
                raise CLIError(f"cannot write the index into {out}: {exc.strerror or exc}") from None
    finally:
        _close(bar)
    _done(one_line(f"report: {len(summaries)} mechanism(s), {n_fail} with failed checks"
                        + (f", {n_err} without a report (errors above)" if n_err else "")
                        + (f"; the earlier index {index} stays as it was" if keep else
                           f"; index -> {index} and {index.with_suffix('.html')}")
                        + f"; {time.perf_counter() - t0:.1f} s"))
    same = True if earlier is None else _check(out, earlier)
    return EXIT_FAIL if n_err or not same else EXIT_OK


def _earlier_reports(path: str, out: Path) -> Path:
    """--check's folder: an existing folder of reports other than `out` (CLIError otherwise)."""
    p = Path(path)
    if not p.is_dir():
        raise CLIError(f"--check {path}: not a folder of reports")
    if p.resolve() == out.resolve():
        raise CLIError(f"--check {path}: the same folder as --out; write the rerun elsewhere (--out) and "
                       f"compare it with {path}")
    return p


def _check(out: Path, earlier: Path) -> bool:
    """Print each difference of the reports in `out` from those in `earlier` and a last line;
    True when there is none."""
    from ..report import compare_reports
    diffs = compare_reports(out, earlier)
    for d in diffs:
        _Out.write(one_line(f"check: {d}"))
    _Out.write(one_line(f"check: {len(diffs)} difference(s) of {out} from {earlier} beyond their tolerances" if diffs
                        else f"check: {out} reproduces {earlier} within every tolerance"))
    return not diffs
