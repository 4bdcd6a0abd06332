"""The command line: `kinetostat analyze | structure | validate | report | examples` (also `python -m kinetostat`).

Exit codes: 0 success; 1 `validate` found a check beyond tolerance, a route that raised, or
nothing to compare; 2 bad input or options (model file, structure, assembly, angles, engine
names, output path). Expected problems print one `kinetostat: error: ...` line (a model file's
problem list prints one line per problem) and never a traceback; warnings print one line each.
"""
from __future__ import annotations

import argparse
import math
import os
import sys
import tempfile
import time
import warnings
from pathlib import Path
from typing import Sequence

EXIT_OK, EXIT_FAIL, EXIT_USAGE = 0, 1, 2
TABLE_SUFFIXES = (".csv", ".parquet", ".json")

__all__ = ["main", "build_parser", "exit_code", "bundled_models", "CLIError"]


class CLIError(Exception):
    """A problem with the command's input or options: one message, exit code `code`."""

    def __init__(self, message: str, code: int = EXIT_USAGE):
        super().__init__(message)
        self.code = code


# ============================================================================ output helpers

class _Out:
    """stderr/stdout writers that do not break an active progress bar."""
    bar = None

    @classmethod
    def write(cls, text: str, err: bool = False) -> None:
        stream = sys.stderr if err else sys.stdout
        if cls.bar is not None:
            from tqdm import tqdm
            tqdm.write(text, file=stream)
        else:
            print(text, file=stream)


def _error(msg: str) -> None:
    _Out.write(f"kinetostat: error: {msg}", err=True)


def _warn(msg: str) -> None:
    _Out.write(f"kinetostat: warning: {msg}", err=True)


def _showwarning(message, category, filename, lineno, file=None, line=None):
    text = str(message).splitlines()[0] if str(message) else category.__name__
    _warn(text if issubclass(category, UserWarning) else f"{category.__name__}: {text}")


class _NoBar:
    def update(self, n: int = 1): ...
    def set_postfix_str(self, s: str = ""): ...
    def close(self): ...


def _progress(total: int, desc: str, enabled: bool):
    """A tqdm bar on stderr when stderr is a terminal (and tqdm is installed), else a no-op."""
    if not enabled or not sys.stderr.isatty():
        return _NoBar()
    try:
        from tqdm import tqdm
    except ImportError:
        return _NoBar()
    bar = tqdm(total=total, desc=desc, unit="step", file=sys.stderr, delay=0.3, leave=False, dynamic_ncols=True)
    _Out.bar = bar
    return bar


def _close(bar) -> None:
    bar.close()
    _Out.bar = None


# ============================================================================ argument types

def _angle(text: str) -> float:
    try:
        x = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"invalid crank angle {text!r}: expected a number of degrees, "
                                         f"e.g. --at 0 30 45.5") from None
    if not math.isfinite(x):
        raise argparse.ArgumentTypeError(f"invalid crank angle {text!r}: expected a finite number of degrees")
    return x


def _steps(text: str) -> int:
    try:
        n = int(text)
    except ValueError:
        n = 0
    if n < 1:
        raise argparse.ArgumentTypeError(f"invalid number of positions {text!r}: expected a positive integer, "
                                         f"e.g. --steps 360")
    return n


class _Parser(argparse.ArgumentParser):
    """argparse that raises CLIError (one line, exit 2) instead of printing usage and exiting."""

    def error(self, message: str):
        raise CLIError(f"{message} (see '{self.prog} --help')")


# ============================================================================ models and paths

def bundled_models() -> list[Path]:
    from .examples import models_dir
    d = models_dir()
    if not d.is_dir():
        raise CLIError(f"no bundled models: {d} is not a directory "
                       f"(give MODEL files, or set KINETOSTAT_MODELS to a directory of *.toml models)")
    files = sorted(d.glob("*.toml"))
    if not files:
        raise CLIError(f"no bundled models: no *.toml file in {d} "
                       f"(give MODEL files, or set KINETOSTAT_MODELS to a directory of *.toml models)")
    return files


def _model_error_text(exc) -> str:
    """A ModelError as the CLI prints it: the file, then each problem led by its line."""
    if len(exc.located) == 1:
        return f"{exc.source}: {exc.located[0]}"
    return f"{exc.source}: {len(exc.located)} problems:\n" + "\n".join(f"  - {p}" for p in exc.located)


def _load(path: str | Path):
    """Load a model; every expected fault becomes a CLIError naming the file."""
    from .errors import ModelError, StructureError
    from .model import load
    p = Path(path)
    if not p.exists():
        raise CLIError(f"model file not found: {p}")
    if p.is_dir():
        raise CLIError(f"model file expected, got a directory: {p}")
    try:
        return load(p)
    except ModelError as exc:
        raise CLIError(_model_error_text(exc)) from None
    except StructureError as exc:
        msg = str(exc)
        raise CLIError(msg if msg.startswith(str(p)) else f"{p}: {msg}") from None


def _analyze(mech, path: Path, phi_deg=None, steps: int = 360):
    """analyze() with AssemblyError and ModelError as a CLIError, warnings printed one line each."""
    from .analysis import analyze
    from .errors import AssemblyError, ModelError
    t0 = time.perf_counter()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            res = analyze(mech, phi_deg=phi_deg, steps=steps)
        except AssemblyError as exc:
            raise CLIError(f"{path}: {exc}") from None
        except ModelError as exc:       # faults that show only over the cycle (a travel diagram's stroke)
            raise CLIError(_model_error_text(exc)) from None
    seen = set()
    for w in caught:
        text = str(w.message).splitlines()[0]
        if text not in seen:
            seen.add(text)
            _warn(f"{Path(path).name}: {text}")
    return res, time.perf_counter() - t0


def _writable_file(path: str, option: str) -> Path:
    """Check that `path` can be written now (so that a long run does not fail at its end)."""
    p = Path(path)
    if p.is_dir():
        raise CLIError(f"cannot write {option} {p}: it is a directory")
    existed = p.exists()
    try:
        with open(p, "a", encoding="utf-8"):
            pass
    except OSError as exc:
        raise CLIError(f"cannot write {option} {p}: {exc.strerror or exc}") from None
    if not existed:
        p.unlink()
    return p


def _writable_dir(path: str, option: str) -> Path:
    p = Path(path)
    try:
        p.mkdir(parents=True, exist_ok=True)
        with tempfile.NamedTemporaryFile(dir=p, prefix=".kinetostat-probe-"):
            pass
    except OSError as exc:
        raise CLIError(f"cannot write {option} {p}: {exc.strerror or exc}") from None
    return p


#: `--engines none`: no physics engine, only the 40-digit reference route (and the published values).
NO_ENGINE = "none"


def _engines(names: Sequence[str] | None) -> list[str]:
    """The routes of `--engines` (default: every route); `none` alone means the reference route only."""
    from kinetostat_validation.compare import ROUTES
    if names is None:
        return list(ROUTES)
    if NO_ENGINE in names:
        if len(names) > 1:
            raise CLIError(f"--engines {NO_ENGINE} stands alone (it means no engine: the reference route and the "
                           f"published values only), got {' '.join(names)}")
        return ["reference"]
    unknown = [n for n in names if n not in ROUTES]
    if unknown:
        hint = " (put MODEL files before --engines)" if any(n.endswith(".toml") for n in unknown) else ""
        raise CLIError(f"unknown engine route(s) {', '.join(unknown)}{hint}. "
                       f"Valid names: {', '.join(ROUTES)}, {NO_ENGINE}")
    return list(dict.fromkeys(names))


def _prepare(paths: Sequence[str | Path], steps: int):
    """Load and analyse every model before any engine runs: input errors stop the command."""
    jobs, problems = [], []
    for path in paths:
        try:
            mech = _load(path)
            res, secs = _analyze(mech, Path(path), steps=steps)
        except CLIError as exc:
            problems.append(str(exc))
            continue
        jobs.append((Path(path), mech, res, secs))
    if problems:
        for p in problems[:-1]:
            _error(p)
        raise CLIError(problems[-1] + (f"\n(nothing run: {len(problems)} of {len(paths)} models have errors)"
                                       if len(paths) > 1 else ""))
    return jobs


# ============================================================================ analyze

def _fmt(x: float, unit: str = "") -> str:
    if not math.isfinite(x):
        return "n/a"
    return f"{x:.5g}{' ' + unit if unit else ''}"


def _summary(res, path: Path) -> list[str]:
    import numpy as np
    m = res.mech
    s = m.structure
    phi = res.phi_deg
    lines = [f"{m.name}   [{path}]",
             f"structure: {s.formula}   (W = 3*{s.n} - 2*{s.p5} - {s.p4} = {s.W})",
             f"{len(phi)} crank position(s), phi = {phi.min():g} .. {phi.max():g} deg; "
             f"omega1 = {m.drive.omega:.6g} rad/s ({m.drive.omega * 30 / math.pi:.6g} rpm, "
             f"{'ccw' if m.drive.sense > 0 else 'cw'})"]
    lines.append("peak reactions |R(i,j)| (force of link i on link j):")
    for p in m.pairs:
        mag = np.linalg.norm(res.forces.R[:, p.index], axis=-1)
        where = f"at {p.point}" if p.kind == "R" else f"guide {p.guide}"
        name = f"R({p.links[0]},{p.links[1]}) {where}"
        if np.any(np.isfinite(mag)):
            i = int(np.nanargmax(mag))
            lines.append(f"  {name:<22s} {_fmt(mag[i], 'N'):>14s}  at phi = {phi[i]:g} deg")
        else:
            lines.append(f"  {name:<22s} {'n/a':>14s}")
    M = res.balancing_moment
    if np.any(np.isfinite(M)):
        i, j = int(np.nanargmin(M)), int(np.nanargmax(M))
        lines.append(f"balancing moment M_bal: {_fmt(M[i], 'N m')} (phi = {phi[i]:g} deg) .. "
                     f"{_fmt(M[j], 'N m')} (phi = {phi[j]:g} deg)")
    if m.drive.kind == "machine":
        F = np.linalg.norm(res.balancing_force, axis=-1)
        if np.any(np.isfinite(F)):
            lines.append(f"balancing force |F_bal| on the gear mesh: {_fmt(np.nanmin(F), 'N')} .. {_fmt(np.nanmax(F), 'N')}")
    d = res.lever_discrepancy
    if np.any(np.isfinite(d)):
        k = int(np.nanargmax(np.abs(d)))
        lines.append(f"lever discrepancy max |M_lever - M_bal|: {abs(d[k]):.3g} N m (phi = {phi[k]:g} deg)")
    n_sing = int(np.sum(res.singular))
    if n_sing:
        lines.append(f"singular positions: {n_sing} (their values are NaN)")
    if len(phi) <= 12:
        head = f"  {'phi, deg':>9s} {'M_bal, N m':>12s} " + " ".join(
            f"{'|R(%d,%d)|, N' % p.links:>13s}" for p in m.pairs)
        lines += ["values:", head]
        for n in range(len(phi)):
            lines.append(f"  {phi[n]:9.4g} {M[n]:12.6g} " + " ".join(
                f"{np.linalg.norm(res.forces.R[n, p.index]):13.6g}" for p in m.pairs))
    return lines


def _write_json(df, path: str) -> None:
    """Records (one object per crank position), floats as Python writes them, NaN as null."""
    import json

    import numpy as np

    def plain(x):
        if isinstance(x, (np.bool_, bool)):
            return bool(x)
        if isinstance(x, (np.integer, int)):
            return int(x)
        x = float(x)
        return x if math.isfinite(x) else None

    records = [{k: plain(v) for k, v in zip(df.columns, row)} for row in df.itertuples(index=False, name=None)]
    with open(path, "w", encoding="utf-8") as f:
        json.dump(records, f, indent=1, allow_nan=False)
        f.write("\n")


def cmd_analyze(args) -> int:
    out = args.out
    if out is not None and out != "-":
        suffix = Path(out).suffix.lower()
        if suffix not in TABLE_SUFFIXES:
            raise CLIError(f"--out {out}: unknown table format {suffix or '(no suffix)'!r}; "
                           f"use one of {', '.join(TABLE_SUFFIXES)} (or '-' for CSV on stdout)")
        if suffix == ".parquet":
            import importlib.util
            if importlib.util.find_spec("pyarrow") is None and importlib.util.find_spec("fastparquet") is None:
                raise CLIError(f"--out {out}: writing .parquet needs pyarrow (pip install pyarrow); "
                               f"or write .csv / .json")
        _writable_file(out, "--out")
    path = Path(args.model)
    mech = _load(path)
    res, _ = _analyze(mech, path, phi_deg=args.at, steps=args.steps)
    lines = _summary(res, path)
    if out is not None:
        df = res.to_frame()
        if out == "-":
            df.to_csv(sys.stdout, index=False)
        else:
            suffix = Path(out).suffix.lower()
            try:
                if suffix == ".csv":
                    df.to_csv(out, index=False)
                elif suffix == ".json":
                    _write_json(df, out)
                else:
                    df.to_parquet(out, index=False)
            except OSError as exc:
                raise CLIError(f"cannot write --out {out}: {exc.strerror or exc}") from None
            lines.append(f"table: {len(df)} rows x {len(df.columns)} columns -> {out}")
    else:
        lines.append("(the full table: --out FILE.csv | FILE.parquet | FILE.json)")
    _Out.write("\n".join(lines), err=(out == "-"))
    return EXIT_OK


# ============================================================================ structure

def cmd_structure(args) -> int:
    from .structure import GROUP_KINDS
    path = Path(args.model)
    m = _load(path)
    s = m.structure
    pairs = ", ".join(f"{p.label} at {p.point}" if p.kind == "R" else f"{p.label} guide {p.guide}" for p in m.pairs)
    crank = next(p for p in m.pairs if set(p.links) == {0, 1})
    lines = [f"{m.name}   [{path}]",
             f"moving links n = {s.n}: " + ", ".join(f"{k.id} {k.name}" for k in m.links[1:]),
             f"lower pairs p5 = {s.p5}: {pairs}",
             f"higher pairs p4 = {s.p4}",
             f"mobility (Chebyshev): W = 3n - 2p5 - p4 = 3*{s.n} - 2*{s.p5} - {s.p4} = {s.W}",
             f"initial mechanism I(0,1): crank 1 on the frame at {crank.point} ({crank.label})",
             "Assur groups, in order of attachment:"]
    for g in s.groups:
        outer_j, inner, outer_k = g.pairs
        lines.append(f"  {g.label}  {g.kind} (kind {GROUP_KINDS[g.kind]})  links {g.links[0]}, {g.links[1]}; "
                     f"outer pairs {outer_j.label}, {outer_k.label} (to links {g.known[0]}, {g.known[1]}), "
                     f"inner {inner.label}; branch {g.branch:+d}")
    if not s.groups:
        lines.append("  none")
    lines.append(f"structure formula: {s.formula}")
    lines.append(f"class {s.mechanism_class}, order {s.order}")
    _Out.write("\n".join(lines))
    return EXIT_OK


# ============================================================================ validate

def exit_code(runs) -> int:
    """The exit code of `validate` for these ModelRuns: 1 if a check (a route's error or a
    published value) failed, a route raised, or no check ran at all (every route skipped and no
    published value); else 0."""
    if not runs or any(not r.passed for r in runs):
        return EXIT_FAIL
    if not any(r.checks for r in runs):
        return EXIT_FAIL
    return EXIT_OK


def validation_table(run) -> str:
    """The checks of one ModelRun, one line each: route (or "published"), quantity, error,
    tolerance, max abs error, verdict; skipped and failed routes one line each."""
    from .report.runs import PUBLISHED_ROUTE as PUBLISHED
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
    verdict = "PASS" if run.passed and n else "FAIL" if not run.passed else "NOT CHECKED"
    lines.append(f"  => {verdict}: {n} checks ({len(run.published)} published values), {f} failed, "
                 f"{len(run.skipped)} route(s) skipped, {len(run.errors)} with errors")
    return "\n".join(lines)


def cmd_validate(args) -> int:
    from .report import run_validation
    engines = _engines(args.engines)
    junit = _writable_file(args.junit, "--junit") if args.junit else None
    to_json = None if args.json is None else args.json if args.json == "-" else _writable_file(args.json, "--json")
    err = to_json == "-"                 # the JSON on stdout: the people's lines go to stderr
    paths = args.models or bundled_models()
    jobs = _prepare(paths, args.steps)
    runs = []
    t0 = time.perf_counter()
    bar = _progress(len(jobs) * len(engines), "validate", not args.no_progress)
    try:
        for path, mech, res, secs in jobs:
            bar.set_postfix_str(path.stem)
            run = run_validation(mech, engines, args.steps, res=res, path=path, on_route=lambda r: bar.update())
            run.solver_seconds = secs
            runs.append(run)
            for w in run.warnings:
                _warn(f"{path.name}: {w}")
            _Out.write(validation_table(run), err=err)
    finally:
        _close(bar)
    checks = [c for run in runs for c in run.checks]
    n_fail = sum(not c.passed for c in checks)
    n_pub = sum(len(run.published) for run in runs)
    n_err = sum(len(run.errors) for run in runs)
    n_skip = sum(len(run.skipped) for run in runs)
    code = exit_code(runs)
    _Out.write(f"validate: {len(runs)} model(s), {len(checks)} checks ({n_pub} published values): "
               f"{len(checks) - n_fail} passed, {n_fail} FAILED; {n_err} route error(s), {n_skip} route(s) skipped; "
               f"{time.perf_counter() - t0:.1f} s" + ("" if code == EXIT_OK else " -> FAIL"), err=err)
    if not checks:
        _error("nothing was checked: every route was skipped or raised, and no model has published values")
    if to_json is not None:
        _write_validation_json(runs, code, to_json)
    if junit is not None:
        from .report import junit_xml
        try:
            junit_xml(runs).write(junit, encoding="utf-8", xml_declaration=True)
        except OSError as exc:
            raise CLIError(f"cannot write --junit {junit}: {exc.strerror or exc}") from None
        _Out.write(f"JUnit XML -> {junit}")
    return code


def _write_validation_json(runs, code: int, dest) -> None:
    """`validate --json`: the checks of every run as JSON (NaN as null), to a file or stdout ('-')."""
    import json
    from .report import validation_json
    text = json.dumps(validation_json(runs, code), indent=1, allow_nan=False) + "\n"
    if dest == "-":
        sys.stdout.write(text)
        return
    try:
        Path(dest).write_text(text, encoding="utf-8")
    except OSError as exc:
        raise CLIError(f"cannot write --json {dest}: {exc.strerror or exc}") from None
    _Out.write(f"JSON -> {dest}")


# ============================================================================ report

def cmd_report(args) -> int:
    import importlib.util
    if importlib.util.find_spec("matplotlib") is None:
        raise CLIError("kinetostat report needs matplotlib: pip install 'kinetostat[reports]'")
    from .report import MIN_REPORT_STEPS, run_validation, write_index, write_report
    if args.steps < MIN_REPORT_STEPS:
        raise CLIError(f"--steps {args.steps}: a report over the cycle needs at least {MIN_REPORT_STEPS} positions")
    engines = _engines(args.engines)
    out = _writable_dir(args.out, "--out")
    paths = args.models or bundled_models()
    jobs = _prepare(paths, args.steps)
    t0 = time.perf_counter()
    n_fail = 0
    bar = _progress(len(jobs) * (len(engines) + 1), "report", not args.no_progress)
    try:
        for path, mech, res, secs in jobs:
            bar.set_postfix_str(path.stem)
            t1 = time.perf_counter()
            run = run_validation(mech, engines, args.steps, res=res, path=path, on_route=lambda r: bar.update())
            run.solver_seconds = secs
            for w in run.warnings:
                _warn(f"{path.name}: {w}")
            try:
                write_report(run, out)
            except OSError as exc:
                raise CLIError(f"cannot write the report of {path.name} into {out}: {exc.strerror or exc}") from None
            bar.update()
            n_fail += not run.passed
            status = "PASS" if run.passed and run.rows else "FAIL" if not run.passed else "NOT CHECKED"
            routes = ", ".join(f"{r} {run.status(r)}" for r in engines)
            _Out.write(f"{path.stem:<26s} {status:<5s} ({routes})  {time.perf_counter() - t1:5.1f} s"
                       f"  -> {out / path.stem / 'index.html'}")
        index = write_index(out)
    finally:
        _close(bar)
    _Out.write(f"report: {len(jobs)} mechanism(s), {n_fail} with failed checks; index -> {index} and "
               f"{index.with_suffix('.html')}; {time.perf_counter() - t0:.1f} s")
    return EXIT_OK


# ============================================================================ export

def _file_mode(path: Path) -> int:
    """The mode of the file `path` replaces, or of a new file under the process's umask (a
    temporary file is created 0600)."""
    if path.exists():
        return path.stat().st_mode & 0o7777
    umask = os.umask(0)
    os.umask(umask)
    return 0o666 & ~umask


def _write_atomic(path: Path, text: str, option: str) -> None:
    """Write `text` to `path` through a temporary file in the same folder and os.replace: a
    reader never sees half a file, and a failed write leaves the old file as it was."""
    if path.is_dir():
        raise CLIError(f"cannot write {option} {path}: it is a directory")
    tmp = None
    try:
        with tempfile.NamedTemporaryFile("w", encoding="utf-8", dir=path.parent, prefix=f".{path.name}.",
                                         suffix=".tmp", delete=False) as f:
            tmp = f.name
            f.write(text)
        os.chmod(tmp, _file_mode(path))
        os.replace(tmp, path)
    except OSError as exc:
        if tmp is not None and os.path.exists(tmp):
            os.unlink(tmp)
        raise CLIError(f"cannot write {option} {path}: {exc.strerror or exc}") from None


def cmd_export(args) -> int:
    from .errors import AssemblyError, ModelError
    path = Path(args.model)
    mech = _load(path)
    from kinetostat_validation.export import to_mjcf, to_urdf
    try:
        text = to_mjcf(mech) if args.format == "mjcf" else to_urdf(mech)
    except AssemblyError as exc:
        raise CLIError(f"{path}: {exc}") from None
    except ModelError as exc:       # faults that show only over the cycle (a travel diagram's stroke)
        raise CLIError(_model_error_text(exc)) from None
    if args.output is None or args.output == "-":
        sys.stdout.write(text)
        return EXIT_OK
    _write_atomic(Path(args.output), text, "-o")
    _Out.write(f"{args.format.upper()} of {path.name} -> {args.output}")
    return EXIT_OK


# ============================================================================ examples

def cmd_examples(args) -> int:
    from . import examples
    if args.force and args.copy is None:
        raise CLIError("--force only goes with --copy DIR (it replaces files already in DIR)")
    if args.copy is not None:
        try:
            written = examples.copy(args.copy, overwrite=args.force)
        except FileExistsError as exc:
            raise CLIError(f"--copy {args.copy}: {exc.filename} {exc.strerror}; nothing copied "
                           f"(--force replaces them)") from None
        except OSError as exc:
            raise CLIError(f"cannot write --copy {args.copy}: {exc.strerror or exc}") from None
        _Out.write(f"{len(written)} files ({', '.join(p.name for p in written)}) -> {args.copy}")
        return EXIT_OK
    lines = [f"bundled models in {examples.models_dir()} (by name: kinetostat.load(NAME); "
             f"copies: kinetostat examples --copy DIR):"]
    for path in bundled_models():
        m = _load(path)
        lines.append(f"  {path.stem:<24s} {m.structure.formula:<34s} {m.source or m.name}")
    _Out.write("\n".join(lines))
    return EXIT_OK


# ============================================================================ parser and main

def build_parser() -> argparse.ArgumentParser:
    from . import __version__
    p = _Parser(prog="kinetostat",
                description="Kinetostatic analysis of planar linkages (graphical-analytic method, computed "
                            "exactly over the crank cycle) and its cross-validation against physics engines.",
                epilog="Exit codes: 0 ok; 1 validation failed; 2 bad input or options. "
                       "Bundled models ship inside the package ('kinetostat examples' lists them); "
                       "$KINETOSTAT_MODELS names another folder of *.toml models to use instead.")
    p.add_argument("--version", action="version", version=f"kinetostat {__version__}")
    sub = p.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    sub.required = True
    routes = "pinocchio, mujoco, mujoco-sim, pymunk, reference (40-digit mpmath, no engine); none: reference only"

    a = sub.add_parser("analyze", help="kinematics and kinetostatics of one model: summary and full table",
                       description="Analyse MODEL over the crank cycle (or at given angles): print a summary "
                                   "(structure formula, peak reaction of every pair and where, balancing moment "
                                   "range, lever discrepancy) and write the full table of res.to_frame().")
    a.add_argument("model", metavar="MODEL", help="model file (TOML, see models/FORMAT.md)")
    g = a.add_mutually_exclusive_group()
    g.add_argument("--at", metavar="DEG", nargs="+", type=_angle,
                   help="crank angles in degrees (model's reference and sense), e.g. --at 0 30 90")
    g.add_argument("--steps", metavar="N", type=_steps, default=360,
                   help="N equal steps over a revolution (default 360)")
    a.add_argument("--out", metavar="FILE",
                   help="write the full table: FILE.csv, FILE.parquet (needs pyarrow) or FILE.json "
                        "(records); '-' writes CSV to stdout and the summary to stderr")
    a.set_defaults(func=cmd_analyze)

    s = sub.add_parser("structure", help="mobility, Assur groups and structure formula of one model",
                       description="Structural analysis of MODEL: mobility W by Chebyshev's formula with its "
                                   "arithmetic, the Assur groups with their kinds, the structure formula.")
    s.add_argument("model", metavar="MODEL", help="model file (TOML)")
    s.set_defaults(func=cmd_structure)

    e = sub.add_parser("export", help="write a model as MJCF (MuJoCo) or URDF for physics engines",
                       description="Write MODEL's links (mass, centre of mass, I_S), pairs and gravity as an "
                                   "engine model, from the scene the validation harness builds. --mjcf: the "
                                   "spanning tree with the loop-closing pairs as equality constraints and a "
                                   "keyframe 'phi0' (assembled at phi = 0). --urdf: the spanning tree only; URDF "
                                   "cannot express closed loops, so each loop-closing pair is written as an XML "
                                   "comment '<!-- loop closure ... -->' for you to add as a constraint. Loads, "
                                   "drive and friction are not exported.")
    e.add_argument("model", metavar="MODEL", help="model file (TOML)")
    fmt = e.add_mutually_exclusive_group(required=True)
    fmt.add_argument("--mjcf", dest="format", action="store_const", const="mjcf", help="MuJoCo MJCF")
    fmt.add_argument("--urdf", dest="format", action="store_const", const="urdf",
                     help="URDF of the spanning tree, loop closures as comments")
    e.add_argument("-o", "--output", metavar="FILE",
                   help="write FILE (atomically: a temporary file in the same folder, then renamed); "
                        "default: stdout")
    e.set_defaults(func=cmd_export)

    v = sub.add_parser("validate", help="cross-check the solver against the engine routes (exit 1 on failure)",
                       description="Run the accuracy gate: for every MODEL (default: all bundled models) compare "
                                   "the solver's balancing moment and every reaction over the cycle with each "
                                   "route (the engines, and 'reference': a 40-digit mpmath re-solution that needs "
                                   "no engine), check the model's published values ([[published]] tables), and "
                                   "print route, quantity, error, tolerance and PASS/FAIL. Routes whose engine is "
                                   "not installed are SKIPPED. Exit code 1 when any check fails, a route raises, "
                                   "or nothing was checked.")
    v.add_argument("models", metavar="MODEL", nargs="*",
                   help="model files (default: every bundled model, see 'kinetostat examples')")
    v.add_argument("--engines", metavar="ROUTE", nargs="+", help=f"engine routes to run (default: all): {routes}")
    v.add_argument("--steps", metavar="N", type=_steps, default=360, help="positions over the cycle (default 360)")
    v.add_argument("--junit", metavar="FILE", help="also write JUnit XML: one testcase per model x route x quantity "
                                                   "and per published value, each with its measured error")
    v.add_argument("--json", metavar="FILE", nargs="?", const="-",
                   help="also write every check as JSON (name, route, quantity, error, tolerance, unit, angle, "
                        "passed; totals; exit code) to FILE, or to stdout with '-' or no FILE (the table then "
                        "goes to stderr)")
    v.add_argument("--no-progress", action="store_true", help="no progress bar")
    v.set_defaults(func=cmd_validate)

    r = sub.add_parser("report", help="write the per-mechanism error reports (Markdown + HTML + plots)",
                       description="Write OUT/<model>/index.md and a self-contained index.html per MODEL "
                                   "(default: all bundled models) with the mechanism's data, its picture, "
                                   "plots over the cycle, error tables per engine route, the seeds' published "
                                   "values where known, and cycle.csv; plus OUT/index.md and OUT/index.html. "
                                   "Exits 0 once the reports are written, also when checks fail (use "
                                   "'kinetostat validate' as the gate).")
    r.add_argument("models", metavar="MODEL", nargs="*",
                   help="model files (default: every bundled model, see 'kinetostat examples')")
    r.add_argument("--out", metavar="DIR", default="reports", help="output directory (default: ./reports)")
    r.add_argument("--steps", metavar="N", type=_steps, default=360, help="positions over the cycle (default 360)")
    r.add_argument("--engines", metavar="ROUTE", nargs="+", help=f"engine routes to run (default: all): {routes}")
    r.add_argument("--no-progress", action="store_true", help="no progress bar")
    r.set_defaults(func=cmd_report)

    e = sub.add_parser("examples", help="list the bundled models, or copy them (with FORMAT.md) into a folder",
                       description="List the bundled models (the seeds' worked cases shipped inside the package, "
                                   "or the *.toml files of $KINETOSTAT_MODELS): name, structure formula, source. "
                                   "With --copy DIR, copy them and FORMAT.md into DIR to edit and run them.")
    e.add_argument("--copy", metavar="DIR", help="copy every bundled model and FORMAT.md into DIR (created)")
    e.add_argument("--force", action="store_true", help="with --copy: replace files already in DIR")
    e.set_defaults(func=cmd_examples)
    return p


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the `kinetostat` console script; returns the exit code."""
    warnings.showwarning = _showwarning
    try:
        parser = build_parser()
        args = parser.parse_args(argv)
        return args.func(args)
    except CLIError as exc:
        _error(str(exc))
        return exc.code
    except KeyboardInterrupt:
        _error("interrupted")
        return 130
    except BrokenPipeError:
        try:
            sys.stdout = open(os.devnull, "w")
        except OSError:
            pass
        return EXIT_OK


if __name__ == "__main__":
    sys.exit(main())
