"""The command line: `kinetostat analyze | structure | plans | validate | report | export | examples | variant | sweep`
(also `python -m kinetostat`).

Exit codes: 0 success; 1 `validate` found a check beyond tolerance or a route that raised, or
`report` could not make a model's report; 2 bad input or options (model file, structure,
assembly, angles, engine names, output path, stdout that cannot be written); 3 `validate`: no
failure, but a model that nothing checked (every route skipped, no published values), or a
route named with --engines whose engine is not installed; 130 interrupted (Ctrl-C). `sweep`
exits 0 once its table is written, also where designs failed (each keeps its row with the
reason in `error`). Expected problems print one `kinetostat: error: ...` line (a model file's
problem list prints one line per problem) and never a traceback; warnings print one line each. Every output file is written atomically (`kinetostat._io.atomic`): an interrupt or a full
disk leaves the previous file as it was; a device, FIFO, or the process's own stdout or stderr
(also through a link, e.g. /dev/stderr) named as an output is written as a stream, never replaced; the files of `plans`, `variant` and each model's `report` are
swapped in as a set (`kinetostat._io.unit`). Text from a model is printed with its control
characters visible, and every error, warning and summary line stays one line (a newline as \\n).

May use: every room of the package, and the harness inside the commands that need it
(imported there, so that `import kinetostat.cli` loads no engine).
"""
from __future__ import annotations

import argparse
import errno
import math
import os
import signal
import sys
import tempfile
import time
import warnings
from contextlib import contextmanager
from pathlib import Path
from typing import IO, Callable, Iterable, Iterator, Sequence

from ._io import _sigint_deferred, atomic, is_stream, unique_names, unit
from ._text import one_line, visible

EXIT_OK, EXIT_FAIL, EXIT_USAGE, EXIT_NOT_CHECKED, EXIT_INTERRUPTED = 0, 1, 2, 3, 130
TABLE_SUFFIXES = (".csv", ".parquet", ".json")

__all__ = ["main", "build_parser", "exit_code", "bundled_models", "CLIError"]


class CLIError(Exception):
    """A problem with the command's input or options: one message, exit code `code`. The message
    is one line (its newlines and control characters written as "\\n" etc.: no forged
    "kinetostat: error:" line from a name or a path), or the given `lines`, each made one line."""

    def __init__(self, message: str = "", code: int = EXIT_USAGE, lines: Sequence[str] = ()):
        self.lines = tuple(one_line(s) for s in (lines or [message]))
        super().__init__("\n".join(self.lines))
        self.code = code


# ============================================================================ output helpers

class _Out:
    """stderr/stdout writers that do not break an active progress bar."""
    bar = None

    @classmethod
    def write(cls, text: str, err: bool = False) -> None:
        stream = sys.stderr if err else sys.stdout
        text = visible(text)             # a name's ESC [2J or OSC 52 printed as text, never acted on
        try:
            if cls.bar is not None:
                from tqdm import tqdm
                tqdm.write(text, file=stream)
            else:
                print(text, file=stream)
        except BrokenPipeError:
            raise
        except OSError as exc:           # stdout on a full disk: one error line, not a traceback
            raise CLIError(f"cannot write to {'stderr' if err else 'stdout'}: {exc.strerror or exc}") from None


def _lines(lines: Iterable[str]) -> str:
    """Lines for stdout, each made one line: a name's newline prints as "\\n", never a forged line."""
    return "\n".join(map(one_line, lines))


def _error(msg: str | CLIError) -> None:
    """The error line (a CLIError's lines, each made one line already)."""
    try:
        _Out.write(f"kinetostat: error: {msg if isinstance(msg, CLIError) else one_line(msg)}", err=True)
    except (CLIError, OSError):          # stderr itself cannot be written: the exit code says it
        pass


def _readable_streams() -> None:
    """stdout and stderr write what their encoding cannot hold (a non-ASCII model name under
    LC_ALL=C or PYTHONIOENCODING=latin-1, a non-UTF-8 file name) as backslash escapes."""
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.reconfigure(errors="backslashreplace")
        except (AttributeError, ValueError, OSError):
            pass


def _quiet_stdout() -> None:
    """After stdout failed (a closed pipe, a full disk): what is still buffered goes to
    /dev/null, so that the interpreter's own flush at exit does not fail again."""
    try:
        fd = os.open(os.devnull, os.O_WRONLY)
        os.dup2(fd, sys.stdout.fileno())
        os.close(fd)
    except (AttributeError, ValueError, OSError):
        pass


class _Interrupt:
    """Ctrl-C while a command runs. The handler records it before it raises KeyboardInterrupt:
    an interrupt that lands in a garbage-collection callback or a __del__ is swallowed there
    ("Exception ignored in ..."), and the next `_checkpoint` raises it again."""
    seen = False


def _on_sigint(signum, frame) -> None:
    _Interrupt.seen = True
    raise KeyboardInterrupt


def _checkpoint() -> None:
    """Raise KeyboardInterrupt if Ctrl-C was pressed, also if its first raise was swallowed."""
    if _Interrupt.seen:
        raise KeyboardInterrupt


@contextmanager
def _interrupts() -> Iterator[None]:
    """`_on_sigint` as the SIGINT handler while a command runs (main thread only), then the old one."""
    _Interrupt.seen = False
    try:
        old = signal.signal(signal.SIGINT, _on_sigint)
    except ValueError:                   # not the main thread: leave the handler as it is
        yield
        return
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, old)


def _is_stdout(path: str | Path) -> bool:
    """`path` is '-' or names this process's stdout (/dev/stdout, /proc/self/fd/1, the file it goes to)."""
    if str(path) == "-":
        return True
    try:
        return os.path.samestat(os.stat(path), os.fstat(sys.stdout.fileno()))
    except (OSError, ValueError, AttributeError):
        return False


def _save(path: str | Path, option: str, write: Callable[[IO], None], binary: bool = False) -> None:
    """`write(file)` into `path` atomically (`kinetostat._io.atomic`); '-' or stdout itself gets the
    data through sys.stdout, a device or FIFO as a stream (never replaced by a file). A failure is
    a CLIError naming `option`, and the old file stays as it was."""
    if _is_stdout(path):
        import io
        buf = io.BytesIO() if binary else io.StringIO()
        write(buf)
        sys.stdout.flush()
        (sys.stdout.buffer if binary else sys.stdout).write(buf.getvalue())
        sys.stdout.flush()
        return
    try:
        with atomic(path, binary=binary, stream=True) as f:
            write(f)
    except OSError as exc:
        raise CLIError(f"cannot write {option} {path}: {exc.strerror or exc}") from None


def _warn(msg: str) -> None:
    _Out.write(f"kinetostat: warning: {one_line(msg)}", err=True)


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


def _turn(deg, option: str):
    """Typed crank angle(s) (a float, a list, or None) in [0, 360): one outside is the same crank
    position as the angle modulo 360 and is taken so, with a warning line naming it."""
    if deg is None:
        return None
    many = isinstance(deg, list)
    given = deg if many else [deg]
    taken = [x % 360.0 if x % 360.0 != 360.0 else 0.0 for x in given]      # -1e-20 % 360 rounds to 360
    moved = [f"{a:g} -> {b:g}" for a, b in zip(given, taken) if a != b]
    if moved:
        _warn(f"{option}: angles outside [0, 360) deg taken modulo 360 (the same crank position): {', '.join(moved)}")
    return taken if many else taken[0]


def _positive(what: str, example: str):
    """An argparse type: a positive integer, or an error naming `what` with an example."""
    def parse(text: str) -> int:
        try:
            n = int(text)
        except ValueError:
            n = 0
        if n < 1:
            raise argparse.ArgumentTypeError(f"invalid {what} {text!r}: expected a positive integer, e.g. {example}")
        return n
    return parse


_steps = _positive("number of positions", "--steps 360")
_jobs = _positive("number of jobs", "--jobs 4")


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


def _model_error_lines(exc) -> list[str]:
    """A ModelError as the CLI prints it: the file, then each problem led by its line."""
    if len(exc.located) == 1:
        return [f"{exc.source}: {exc.located[0]}"]
    return [f"{exc.source}: {len(exc.located)} problems:"] + [f"  - {p}" for p in exc.located]


def _load(path: str | Path):
    """Load a model file, or a bundled model by name; every expected fault becomes a CLIError
    naming the file."""
    from .errors import ModelError, StructureError
    from .examples import resolve
    from .model import load
    p = resolve(path)
    if not p.exists():
        raise CLIError(f"model file not found: {p}")
    if p.is_dir():
        raise CLIError(f"model file expected, got a directory: {p}")
    try:
        return load(p)
    except ModelError as exc:
        raise CLIError(lines=_model_error_lines(exc)) from None
    except StructureError as exc:
        msg = str(exc)
        raise CLIError(msg if msg.startswith(str(p)) else f"{p}: {msg}") from None


def _size(n: float) -> str:
    """A number of bytes for people: "1.3 kB", "8.1 TB", "1.3e+23 bytes" beyond yottabytes."""
    for unit in ("bytes", "kB", "MB", "GB", "TB", "PB", "EB", "ZB", "YB"):
        if n < 999.5:
            return f"{n:.3g} {unit}"
        n /= 1000
    return f"{n * 1e24:.3g} bytes"


def _available_memory() -> int | None:
    """Bytes of memory available now (Linux: MemAvailable; else free physical pages), or None."""
    try:
        with open("/proc/meminfo", encoding="ascii") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    try:
        return os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (AttributeError, ValueError, OSError):
        return None


def _result_bytes(x, seen: set[int] | None = None) -> int:
    """Bytes of the numpy arrays an analysis result holds (the mechanism itself not counted)."""
    import numpy as np
    from .model import Mechanism
    seen = set() if seen is None else seen
    if id(x) in seen or isinstance(x, (Mechanism, str, bytes, int, float, type(None))):
        return 0
    seen.add(id(x))
    if isinstance(x, np.ndarray):
        return x.nbytes
    if isinstance(x, dict):
        return sum(_result_bytes(v, seen) for v in x.values())
    if isinstance(x, (list, tuple)):
        return sum(_result_bytes(v, seen) for v in x)
    fields = getattr(x, "__dict__", None)
    return sum(_result_bytes(v, seen) for v in fields.values()) if fields else 0


#: `--steps` is refused where the result alone would need more than the memory available now.
#: The bytes per crank position are measured on this many positions of the model.
_SAMPLE_STEPS = 4


def _check_memory(mech, steps: int) -> None:
    """Refuse `steps` before anything is allocated where the result's arrays (measured per crank
    position on a few positions of this model) would not fit in the memory available now."""
    from .analysis import analyze
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            per_angle = _result_bytes(analyze(mech, steps=_SAMPLE_STEPS)) / _SAMPLE_STEPS
        except Exception:                # noqa: BLE001 -- the real analysis reports the fault
            return
    need, free = steps * per_angle, _available_memory()
    if free is not None and need > free:
        raise CLIError(f"--steps {steps}: the result alone would need {_size(need)} of memory "
                       f"({_size(per_angle)} per crank position for this model), and {_size(free)} is "
                       f"available; use fewer steps (at most about {int(free // per_angle):,})")


def _analyze(mech, path: Path, phi_deg=None, steps: int = 360):
    """analyze() with AssemblyError and ModelError as a CLIError, warnings printed one line each;
    `steps` that would not fit in memory are refused before anything is allocated."""
    from .analysis import analyze
    from .errors import AssemblyError, ModelError
    if phi_deg is None:
        _check_memory(mech, steps)
    t0 = time.perf_counter()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            res = analyze(mech, phi_deg=phi_deg, steps=steps)
        except AssemblyError as exc:
            raise CLIError(f"{path}: {exc}") from None
        except ModelError as exc:       # faults that show only over the cycle (a travel diagram's stroke)
            raise CLIError(lines=_model_error_lines(exc)) from None
    seen = set()
    for w in caught:
        text = str(w.message).splitlines()[0]
        if text not in seen:
            seen.add(text)
            _warn(f"{Path(path).name}: {text}")
    return res, time.perf_counter() - t0


def _writable_file(path: str, option: str) -> Path:
    """Check that `path` can be written now (so that a long run does not fail at its end): its
    folder takes a temporary file, and the name itself is one the file system can hold."""
    p = Path(path)
    if _is_stdout(p) or is_stream(p):    # written as a stream (`_save`)
        if str(p) != "-" and not os.access(p, os.W_OK):
            raise CLIError(f"cannot write {option} {p}: permission denied")
        return p
    try:
        if p.is_dir():
            raise CLIError(f"cannot write {option} {p}: it is a directory")
        if len(os.fsencode(p.name)) > os.pathconf(p.parent, "PC_NAME_MAX"):
            raise OSError(errno.ENAMETOOLONG, os.strerror(errno.ENAMETOOLONG))
        with _sigint_deferred(), tempfile.NamedTemporaryFile(dir=p.parent, prefix=".kinetostat-probe-"):
            pass                         # Ctrl-C held back till the probe is gone: none left behind
    except OSError as exc:
        raise CLIError(f"cannot write {option} {p}: {exc.strerror or exc}") from None
    return p


def _writable_dir(path: str, option: str) -> Path:
    p = Path(path)
    try:
        p.mkdir(parents=True, exist_ok=True)
        with _sigint_deferred(), tempfile.NamedTemporaryFile(dir=p, prefix=".kinetostat-probe-"):
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
            problems.append(exc)
            continue
        jobs.append((Path(path), mech, res, secs))
    if problems:
        for p in problems[:-1]:
            _error(p)
        raise CLIError(lines=problems[-1].lines + ((f"(nothing run: {len(problems)} of {len(paths)} models have "
                                                    f"errors)",) if len(paths) > 1 else ()))
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


def _worksheet_lines(mech, phi: float) -> list[str]:
    """The worksheet's kinematic and inertia values at one position, as a student compares them."""
    import warnings

    from .plans.worksheet import worksheet
    with warnings.catch_warnings():          # the analysis above has warned already
        warnings.simplefilter("ignore")
        ws = worksheet(mech, at=phi)
    lines = [f"worksheet at phi = {phi:g} deg (kinematics, inertia and loads; mu_l = {ws.mu_l:g} m/mm):"]
    for r in ws.rows:
        if r.section in ("kinematics", "accelerations", "inertia"):
            sense = r.direction if r.direction in ("cw", "ccw") else ""
            lines.append(f"  {r.symbol:<14s} {_fmt(r.value, r.unit):>18s}  {sense}".rstrip())
    return lines


def cmd_analyze(args) -> int:
    out = args.out
    if out is not None and out != "-":
        suffix = Path(out).suffix.lower()
        if suffix not in TABLE_SUFFIXES:
            raise CLIError(f"--out {out}: unknown table format {suffix or '(no suffix)'!r}; "
                           f"use one of {', '.join(TABLE_SUFFIXES)} (or '-' for CSV on stdout)")
        if suffix == ".parquet":
            _parquet_engine(f"--out {out}", ".csv / .json")
        _writable_file(out, "--out")
    path = Path(args.model)
    mech = _load(path)
    res, _ = _analyze(mech, path, phi_deg=_turn(args.at, "--at"), steps=args.steps)
    lines = _summary(res, path)
    if len(res.phi_deg) == 1:
        lines += _worksheet_lines(mech, float(res.phi_deg[0]))
    if out is not None:
        from . import tables
        df = res.to_frame()
        if out == "-":
            _Out.write(tables.csv_text(df).rstrip("\n"))
        else:
            suffix = Path(out).suffix.lower()
            write = {".csv": tables.write_csv, ".json": tables.write_json}.get(suffix, tables.write_parquet)
            _save(out, "--out", lambda f: write(df, f), binary=suffix == ".parquet")
            lines.append(f"table: {len(df)} rows x {len(df.columns)} columns -> {out}")
    else:
        lines.append("(the full table: --out FILE.csv | FILE.parquet | FILE.json)")
    _Out.write(_lines(lines), err=(out == "-"))
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
    if m.parameters:
        lines.append("parameters: " + ", ".join(f"{n} = {v:.10g}" for n, v in m.parameters.items()))
    if m.expressions:
        lines.append("numbers from expressions:")
        lines += [f"  {path} = {text} = {v:.10g}" for path, (text, v) in m.expressions.items()]
    _Out.write(_lines(lines))
    return EXIT_OK


# ============================================================================ validate

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
    from .report.runs import LEVER_ROUTE as LEVER, PUBLISHED_ROUTE as PUBLISHED
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
    verdict = "PASS" if run.passed and run.checked else "FAIL" if not run.passed else "NOT CHECKED (nothing compared)"
    lines.append(_coverage(run))
    lines.append(f"  => {verdict}: {n} checks ({len(run.published)} published values), {f} failed, "
                 f"{len(run.skipped)} route(s) skipped, {len(run.errors)} with errors")
    return _lines(lines)


def cmd_validate(args) -> int:
    from .report import run_validation
    engines = _engines(args.engines)
    junit = _writable_file(args.junit, "--junit") if args.junit else None
    to_json = (None if args.json is None else "-" if _is_stdout(args.json)
               else _writable_file(args.json, "--json"))
    err = to_json == "-"                 # the JSON on stdout: the people's lines go to stderr
    paths = args.models or bundled_models()
    jobs = _prepare(paths, args.steps)
    runs = []
    t0 = time.perf_counter()
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
        from .report import junit_xml
        tree = junit_xml(runs)
        _save(junit, "--junit", lambda f: tree.write(f, encoding="utf-8", xml_declaration=True), binary=True)
        _Out.write(one_line(f"JUnit XML -> {junit}"))
    return code


def _github(runs, err: bool) -> None:
    """Under GitHub Actions: an `::error file=...,line=...` command per failed check (the model
    file's line; on stderr when `err`, the JSON then holding stdout) and the Markdown summary,
    verdict first, appended to $GITHUB_STEP_SUMMARY (wherever that variable is set)."""
    if os.environ.get("GITHUB_ACTIONS") != "true" and not os.environ.get("GITHUB_STEP_SUMMARY"):
        return
    from .report import ci
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
    from .report import validation_json
    text = json.dumps(validation_json(runs, code), indent=1, allow_nan=False) + "\n"
    if dest == "-":
        _Out.write(text.rstrip("\n"))
        return
    _save(dest, "--json", lambda f: f.write(text))
    _Out.write(one_line(f"JSON -> {dest}"))


# ============================================================================ report

def _report_job(path: str, engines: list[str], steps: int, out: str, folder: str, page: bool = False) -> dict:
    """One model's report: load, analyse, run the routes, write `out/<folder>/`. Returns
    {"summary", "warnings", "seconds"} or {"error"} (one line); raises only KeyboardInterrupt."""
    from .report import run_validation, write_report
    t0 = time.perf_counter()
    try:
        from .analysis import analyze
        mech = _load(path)
        with warnings.catch_warnings():       # the main process printed the analysis' warnings
            warnings.simplefilter("ignore")
            t1 = time.perf_counter()
            res = analyze(mech, steps=steps)
            secs = time.perf_counter() - t1
        run = run_validation(mech, engines, steps, res=res, path=path)
        run.solver_seconds = secs
        with unit(out) as tmp:                # the model's files swapped in as a set at the end
            summary = write_report(run, tmp, folder, page=page)
    except OSError as exc:
        return {"error": f"cannot write the report into {out}: {exc.strerror or exc}"}
    except Exception as exc:                  # noqa: BLE001 -- one model's fault is its error line
        msg = str(exc).strip().splitlines()
        return {"error": f"{type(exc).__name__}: {msg[0] if msg else ''}".rstrip(": ")}
    return {"summary": summary, "warnings": run.warnings, "seconds": time.perf_counter() - t0}


def _worker_init() -> None:
    """A report worker ends at once, silently, on Ctrl-C (the terminal sends it to the whole
    process group): the main process reports the interruption. A KeyboardInterrupt would not
    do, as it can land in a garbage-collection callback, which swallows it. The temporary file
    of a write in progress is removed first (the files already written stay as they are)."""
    from ._io import remove_temporary

    def end(signum, frame):
        remove_temporary()
        os._exit(EXIT_INTERRUPTED)
    signal.signal(signal.SIGINT, end)


def _report_cost(mech) -> int:
    """A model's rough share of the report's time, to start the longest first: the work grows
    with the pairs, and the simulations run twice for a machine (its mesh force from a first run)."""
    return len(mech.pairs) * (2 if mech.drive.kind == "machine" else 1)


def _report_results(paths: list[Path], folders: list[str], engines: list[str], steps: int, out: Path, jobs: int,
                    costs: Sequence[int] = (), page: bool = False):
    """Yield (index into `paths`, result of _report_job) as each model finishes; `jobs` > 1 runs
    them in a process pool (only paths and names cross to the workers, so any start method
    works), the largest `costs` first, 1 in this process. Ctrl-C cancels the models not started
    and raises KeyboardInterrupt here."""
    if jobs == 1 or len(paths) == 1:
        for n, p in enumerate(paths):
            yield n, _report_job(str(p), engines, steps, str(out), folders[n], page)
        return
    from concurrent.futures import ProcessPoolExecutor, as_completed
    pool = ProcessPoolExecutor(max_workers=min(jobs, len(paths)), initializer=_worker_init)
    try:
        first = sorted(range(len(paths)), key=lambda n: -costs[n] if costs else 0)
        futures = {pool.submit(_report_job, str(paths[n]), engines, steps, str(out), folders[n], page): n for n in first}
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
    from .report import MIN_REPORT_STEPS, write_index
    if args.steps < MIN_REPORT_STEPS:
        raise CLIError(f"--steps {args.steps}: a report over the cycle needs at least {MIN_REPORT_STEPS} positions")
    engines = _engines(args.engines)
    out = _writable_dir(args.out, "--out")
    paths = args.models or bundled_models()
    prepared = _prepare(paths, args.steps)     # input errors stop the command before any route runs
    order = [p for p, *_ in prepared]
    folders = unique_names([p.stem for p in order])     # never '.', '..' or a path; two a.toml: a, a-2
    t0 = time.perf_counter()
    summaries: dict[int, dict] = {}
    n_fail, n_err = 0, 0
    bar = _progress(len(order), "report", not args.no_progress)
    try:
        for n, r in _report_results(order, folders, engines, args.steps, out, args.jobs or os.cpu_count() or 1,
                                    [_report_cost(mech) for _, mech, *_ in prepared], args.page):
            _checkpoint()
            path = order[n]
            bar.update()
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
            _Out.write(one_line(f"{path.stem:<26s} {status:<5s} ({routes})  {r['seconds']:5.1f} s"
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
    _Out.write(one_line(f"report: {len(summaries)} mechanism(s), {n_fail} with failed checks"
                        + (f", {n_err} without a report (errors above)" if n_err else "")
                        + (f"; the earlier index {index} stays as it was" if keep else
                           f"; index -> {index} and {index.with_suffix('.html')}")
                        + f"; {time.perf_counter() - t0:.1f} s"))
    return EXIT_FAIL if n_err else EXIT_OK


# ============================================================================ export

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
        raise CLIError(lines=_model_error_lines(exc)) from None
    if args.output is None or args.output == "-":
        _Out.write(text.rstrip("\n"))
        return EXIT_OK
    _save(args.output, "-o", lambda f: f.write(text))
    _Out.write(one_line(f"{args.format.upper()} of {path.name} -> {args.output}"))
    return EXIT_OK


# ============================================================================ plans

def _scale_item(text: str) -> tuple[str, float]:
    from .plans.scales import SCALE_UNITS
    key, eq, value = text.partition("=")
    if not eq or key not in SCALE_UNITS:
        raise argparse.ArgumentTypeError(f"invalid --scale {text!r}: expected KEY=VALUE with KEY one of "
                                         f"{', '.join(SCALE_UNITS)}, e.g. --scale mu_l=0.001 mu_v=0.2")
    try:
        x = float(value)
    except ValueError:
        x = math.nan
    if not (math.isfinite(x) and x >= sys.float_info.min):      # a subnormal scale divides to inf
        raise argparse.ArgumentTypeError(f"invalid --scale {text!r}: {key} must be a positive number "
                                         f"in {SCALE_UNITS[key]} (at least {sys.float_info.min:.3g})")
    return key, x


def _plan_names(text: str) -> list[str]:
    from .plans import BUILDERS
    names = [n.strip() for n in text.split(",") if n.strip()]
    valid = [n for n, _ in BUILDERS]
    bad = [n for n in names if n not in valid]
    if bad or not names:
        raise argparse.ArgumentTypeError(f"invalid --only {text!r}: expected plan names from {', '.join(valid)}, "
                                         f"comma-separated")
    return names


def cmd_plans(args) -> int:
    import numpy as np
    from .errors import SingularPositionWarning
    from .plans import build, cycle_scales
    from .plans.worksheet import worksheet
    from .plans.lettering import lettering
    from .plans.scales import ScaleError
    path = Path(args.model)
    mech = _load(path)
    args.lang = args.lang or lettering(mech).language or "en"
    out = _writable_dir(args.out, "--out")
    only = [n for group in (args.only or []) for n in group] or None
    args.at, args.starting = _turn(args.at, "--at"), _turn(args.starting, "--starting")
    try:
        with warnings.catch_warnings(record=True) as caught:     # the accuracy at this angle: said below
            warnings.simplefilter("always")
            fixed = cycle_scales(mech) if args.cycle_scales else None          # the page's scales
            plans = build(mech, at=args.at, scales=dict(args.scale or []), starting_deg=args.starting, only=only,
                          fixed=fixed)
            sheet = None if only else worksheet(mech, plans.at, mu_l=plans.scales["mu_l"].value, lang=args.lang)
    except ScaleError as exc:             # a plan beyond a sheet's size, before any of it is drawn
        raise CLIError(f"--scale {exc}") from None
    except ValueError as exc:
        raise CLIError(f"--at {args.at if args.at is not None else 'design position'}: {exc}") from None
    try:
        with unit(out) as tmp:                # swapped in as a set: never new sheets beside an old worksheet
            written = plans.write(tmp, lang=args.lang) + (sheet.write(tmp) if sheet is not None else [])
    except (OSError, ValueError) as exc:
        raise CLIError(f"cannot write --out {out}: {getattr(exc, 'strerror', None) or exc}") from None
    at_plan = [w for w in caught if issubclass(w.category, SingularPositionWarning)
               and np.isclose(w.message.phi_deg, plans.at).all()]          # not the plan of positions' angles
    for text in dict.fromkeys(str(w.message).splitlines()[0] for w in at_plan):
        _warn(f"{path.name}: {text}")
    _Out.write(one_line(plans.summary(path.name, len(written), out, args.lang)))
    return EXIT_OK


def cmd_page(args) -> int:
    from .plans.lettering import lettering
    from .plans.page import write_page
    mech = _load(Path(args.model))
    out = _writable_file(args.out, "--out")
    try:
        path = write_page(mech, out, lang=args.lang or lettering(mech).language or "en", student=args.student,
                          at=_turn(args.at, "--at"))
    except ValueError as exc:
        raise CLIError(f"--at {args.at if args.at is not None else 'design position'}: {exc}") from None
    _Out.write(one_line(f"{Path(args.model).name}: page -> {path} ({_size(path.stat().st_size)})"))
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
        _Out.write(one_line(f"{len(written)} files ({', '.join(p.name for p in written)}) -> {args.copy}"))
        return EXIT_OK
    lines = [f"bundled models in {examples.models_dir()} (by name: kinetostat.load(NAME); "
             f"copies: kinetostat examples --copy DIR):"]
    for path in bundled_models():
        m = _load(path)
        lines.append(f"  {path.stem:<24s} {m.structure.formula:<34s} {m.source or m.name}")
    _Out.write(_lines(lines))
    return EXIT_OK


# ============================================================================ variant

def cmd_variant(args) -> int:
    from . import variants
    from .errors import AssemblyError, ModelError
    try:
        tasks = list(variants.TASKS) if args.task is None else [variants.check_task(args.task, "TASK")]
        if args.all and args.code is not None:
            raise CLIError(f"CODE {args.code!r}: not with --all (--all writes every code of the task)")
        if not args.all:
            if args.task is None or args.code is None:
                raise CLIError("TASK and CODE are required (e.g. 'kinetostat variant 1 479'), or --all")
            jobs = [variants.variant(tasks[0], variants.check_code(args.code, tasks[0], "CODE"))]
        else:
            jobs = [(t, c) for t in tasks for c in variants.codes()]
    except ValueError as exc:
        raise CLIError(f"{exc} (see 'kinetostat variant --help')") from None
    args.lang = args.lang or "uk"                   # seed 002's language (its models' [lettering])
    import importlib.util
    teacher_pack = not args.no_pack and importlib.util.find_spec("matplotlib") is not None
    if not (args.no_pack or teacher_pack):          # a plain install: the keys, and a word on the pack
        _Out.write("no teacher's pack (sheet.pdf, key.pdf, plans_a3.pdf): its PDFs need matplotlib: "
                   "pip install 'kinetostat[reports]'", err=True)
    default = "task_variants" if args.all else jobs[0].name
    out = _writable_dir(args.out or default, "--out")
    t0 = time.perf_counter()
    keys = []
    bar = _progress(len(jobs), "variants", args.all and not args.no_progress)
    try:
        for job in jobs:
            _checkpoint()
            v = job if not args.all else variants.variant(*job)
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                try:
                    keys.append(variants.write_key(v, out / v.name if args.all else out, lang=args.lang,
                                                   cycle_csv=not args.all, root=out, teacher_pack=teacher_pack,
                                                   page=args.page))
                except (AssemblyError, ModelError, ValueError) as exc:   # also a folder linked outside --out
                    raise CLIError(f"task {v.task} variant {v.code}: {exc}") from None
                except OSError as exc:
                    raise CLIError(f"cannot write --out {out}: {exc.strerror or exc}") from None
            bar.update()
        if args.all:
            try:
                index = variants.write_index(out, keys, args.lang)
            except OSError as exc:
                raise CLIError(f"cannot write the index into {out}: {exc.strerror or exc}") from None
    finally:
        _close(bar)
    if args.all:
        _Out.write(one_line(f"{len(keys)} answer keys (tasks {', '.join(map(str, tasks))}) -> {out}/task<T>_<CODE>/; "
                            f"index -> {index}; {time.perf_counter() - t0:.1f} s"))
        return EXIT_OK
    lines = variants.summary(jobs[0], keys[0], out, args.lang)
    _Out.write(_lines(lines))
    return EXIT_OK


# ============================================================================ sweep

def _param(text: str) -> tuple[str, list[float]]:
    """`--param NAME=VALUES`: a range start:stop:step that includes its stop, a list a,b,c, or one value."""
    name, eq, spec = text.partition("=")
    name = name.strip()
    if not eq or not name or not spec.strip():
        raise argparse.ArgumentTypeError(f"invalid --param {text!r}: expected NAME=VALUES, e.g. --param r=0.05:0.11:0.015 "
                                         f"(start:stop:step, stop included), --param n_k=0,60,120 or --param c=0.54")
    try:
        if ":" in spec:
            return name, _range(*(float(x) for x in spec.split(":")))
        values = [float(x) for x in spec.split(",")]
    except (TypeError, ValueError) as exc:
        why = str(exc) if isinstance(exc, _RangeError) else "expected numbers"
        raise argparse.ArgumentTypeError(f"invalid --param {text!r}: {why} (a range start:stop:step includes its "
                                         f"stop; a list a,b,c)") from None
    if not all(map(math.isfinite, values)):
        raise argparse.ArgumentTypeError(f"invalid --param {text!r}: expected finite numbers")
    return name, values


class _RangeError(ValueError):
    pass


def _range(start: float, stop: float, step: float) -> list[float]:
    """start, start + step, ..., stop (included, as the texts' ranges are), each start + k step
    rounded to 12 digits of the range's scale; the step must divide stop - start."""
    if not all(map(math.isfinite, (start, stop, step))) or step == 0:
        raise _RangeError("the range's start, stop and step must be finite and the step non-zero")
    n = (stop - start) / step
    k = round(n)
    if n < -1e-9 or abs(n - k) > 1e-9 * max(1.0, abs(n)):
        raise _RangeError(f"the step {step:g} does not go from {start:g} to {stop:g} in whole steps")
    if k >= 100_000:
        raise _RangeError(f"{k + 1} values: at most 100000 per parameter")
    decimals = 12 - math.floor(math.log10(max(abs(start), abs(stop), abs(step))))
    return [round(start + i * step, decimals) for i in range(k)] + [stop]


def _parquet_engine(option: str, instead: str) -> None:
    """CLIError naming `option` where no Parquet engine (pyarrow, fastparquet) is installed."""
    import importlib.util
    if importlib.util.find_spec("pyarrow") is None and importlib.util.find_spec("fastparquet") is None:
        raise CLIError(f"{option}: writing .parquet needs pyarrow (pip install 'kinetostat[sweep]' or pyarrow); "
                       f"or write {instead}")


def _table_writer(out: str):
    """How `--out` is written, by its suffix: (write(df, file), binary)."""
    from . import tables
    suffix = Path(out).suffix.lower()
    if suffix == ".csv":
        return tables.write_csv, False
    if suffix == ".parquet":
        _parquet_engine(f"--out {out}", ".csv")
        return tables.write_parquet, True
    raise CLIError(f"--out {out}: unknown table format {suffix or '(no suffix)'!r}; use .parquet or .csv")


def cmd_sweep(args) -> int:
    from .sweep import sweep
    write, binary = _table_writer(args.out)
    names = [n for n, _ in args.param]
    twice = sorted({n for n in names if names.count(n) > 1})
    if twice:
        raise CLIError(f"--param {twice[0]}: given more than once; give all its values in one --param")
    if args.scheduler is not None:
        import importlib.util
        from .sweep import LOCAL_SCHEDULERS
        needs = ["dask"] + ([] if args.scheduler in LOCAL_SCHEDULERS else ["distributed"])
        missing = [m for m in needs if importlib.util.find_spec(m) is None]
        if missing:
            raise CLIError(f"--scheduler {args.scheduler}: needs {' and '.join(missing)} (pip install "
                           f"'kinetostat[sweep]'); without --scheduler the designs run in this process")
    out = _writable_file(args.out, "--out")
    angles_out = out.with_name(f"{out.stem}.angles{out.suffix}") if args.full else None
    if angles_out is not None:
        _writable_file(str(angles_out), "--out")
    path = Path(args.model)
    mech = _load(path)
    t0 = time.perf_counter()
    try:
        sw = sweep(mech, dict(args.param), steps=args.steps, full=args.full, scheduler=args.scheduler,
                   chunk=args.chunk, progress=not args.no_progress and sys.stderr.isatty())
    except ValueError as exc:
        raise CLIError(f"--param: {str(exc).removeprefix('sweep: ')}") from None
    except ConnectionError as exc:       # no distributed scheduler at that address
        raise CLIError(f"--scheduler {args.scheduler}: {str(exc).partition(': ')[2]}") from None
    secs = time.perf_counter() - t0
    _save(out, "--out", lambda f: write(sw.table, f), binary)
    lines = [f"{mech.name}   [{path}]",
             f"{len(sw.table)} designs ({' x '.join(f'{n} {k}' for n, k in zip(names, sw.shape))}) x "
             f"{len(sw.phi_deg)} crank positions in {secs:.2f} s",
             f"table: {len(sw.table)} rows x {len(sw.table.columns)} columns -> {out}"]
    if angles_out is not None:
        _save(angles_out, "--out", lambda f: write(sw.angles, f), binary)
        lines.append(f"every angle: {len(sw.angles)} rows x {len(sw.angles.columns)} columns -> {angles_out}")
    failed = sw.table[sw.table["error"] != ""]
    if len(failed):
        lines.append(f"{len(failed)} design(s) failed (NaN peaks, the reason in the column 'error'), the first: "
                     f"{failed['error'].iloc[0]}")
    singular = int((sw.table["n_singular"].fillna(0) > 0).sum())
    if singular:
        lines.append(f"{singular} design(s) pass through singular positions (columns n_singular, singular_deg)")
    warned = sw.table["worst_digits"].dropna()
    if len(warned):
        from .kinematics import DIGITS_WARN
        lines.append(f"{len(warned)} design(s) keep values with fewer than {DIGITS_WARN} significant digits near a "
                     f"singular position, down to {warned.min():.1f} (columns worst_digits, warned_deg)")
    _Out.write(_lines(lines))
    return EXIT_OK


# ============================================================================ parser and main

def build_parser() -> argparse.ArgumentParser:
    from . import __version__
    from .sweep import CHUNK
    p = _Parser(prog="kinetostat",
                description="Kinetostatic analysis of planar linkages (graphical-analytic method, computed "
                            "exactly over the crank cycle) and its cross-validation against physics engines.",
                epilog="Exit codes: 0 ok; 1 validate: a check failed (report: a model's report not made); 2 bad input or options; 3 validate: "
                       "nothing failed but a model was not checked (or a route named with --engines is not "
                       "installed); 130 interrupted (Ctrl-C). "
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
    a.add_argument("model", metavar="MODEL", help="model file (TOML, see models/FORMAT.md) or a bundled model's name")
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
    s.add_argument("model", metavar="MODEL", help="model file (TOML) or a bundled model's name")
    s.set_defaults(func=cmd_structure)

    e = sub.add_parser("export", help="write a model as MJCF (MuJoCo) or URDF for physics engines",
                       description="Write MODEL's links (mass, centre of mass, I_S), pairs and gravity as an "
                                   "engine model, from the scene the validation harness builds. --mjcf: the "
                                   "spanning tree with the loop-closing pairs as equality constraints and a "
                                   "keyframe 'phi0' (assembled at phi = 0). --urdf: the spanning tree only; URDF "
                                   "cannot express closed loops, so each loop-closing pair is written as an XML "
                                   "comment '<!-- loop closure ... -->' for you to add as a constraint. Loads, "
                                   "drive and friction are not exported.")
    e.add_argument("model", metavar="MODEL", help="model file (TOML) or a bundled model's name")
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
                                   "print route, quantity, error, tolerance and PASS/FAIL, and per model what checked it "
                                   "and what did not, and why. Routes whose engine is not installed (or that cannot "
                                   "check a model) are SKIPPED, never passed. Exit code 0: every model checked and "
                                   "every check passed; 1: a check failed or a route raised; 3: no failure, but a "
                                   "model that nothing checked (NOT CHECKED), or a route named with --engines that "
                                   "is not installed. Without --engines, the routes whose engine is not installed "
                                   "are skipped and named, and the others decide.")
    v.add_argument("models", metavar="MODEL", nargs="*",
                   help="model files or bundled models' names (default: every bundled model, see 'kinetostat examples')")
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
                                   "The files carry no dates or run times (a rerun reproduces them byte for "
                                   "byte); run times are printed here only. Every file is written atomically: "
                                   "Ctrl-C (exit 130) or a full disk leaves the earlier files as they were, and "
                                   "when a model's report cannot be made the earlier index stays. Folders are "
                                   "named after the model files (ASCII letters, digits, '_', '-'; a repeated "
                                   "name gets -2, -3). Exits 0 once the reports are written, also when checks "
                                   "fail (use 'kinetostat validate' as the gate); 1 when a model's report could "
                                   "not be made.")
    r.add_argument("models", metavar="MODEL", nargs="*",
                   help="model files or bundled models' names (default: every bundled model, see 'kinetostat examples')")
    r.add_argument("--out", metavar="DIR", default="reports", help="output directory (default: ./reports)")
    r.add_argument("--steps", metavar="N", type=_steps, default=360, help="positions over the cycle (default 360)")
    r.add_argument("--engines", metavar="ROUTE", nargs="+", help=f"engine routes to run (default: all): {routes}")
    r.add_argument("--jobs", "-j", metavar="N", type=_jobs, default=None,
                   help="models reported in parallel by N worker processes (default: the number of cores; "
                        "1: in this process)")
    r.add_argument("--no-progress", action="store_true", help="no progress bar")
    r.add_argument("--page", action="store_true", help="also each model's interactive page (page.html, linked; "
                                                       "about 40 s a model)")
    r.set_defaults(func=cmd_report)

    pl = sub.add_parser("plans", help="draw the plans of the graphical method (SVG sheets, segments.csv)",
                        description="Draw MODEL's plans at one crank angle as the course texts draw them: the plan "
                                    "of positions (12 positions from the dead centre, the design position, the "
                                    "paths of the centres of mass, the assembly branches), the velocity and "
                                    "acceleration plans; one SVG sheet per plan (A3, true to scale in mm) and "
                                    "DIR/segments.csv (every drawn segment: its length in mm, the value it stands "
                                    "for, the scale). --only positions is the quick preview of a model.")
    pl.add_argument("model", metavar="MODEL", help="model file (TOML) or a bundled model's name")
    pl.add_argument("--at", metavar="DEG", type=_angle,
                    help="crank angle in degrees (default: the model's design position, drive.design_deg)")
    pl.add_argument("--scale", metavar="KEY=VALUE", nargs="+", type=_scale_item,
                    help="scales to use instead of the texts' rule: mu_l [m/mm], mu_v [m/(s mm)], "
                         "mu_a [m/(s^2 mm)], mu_F [N/mm], e.g. --scale mu_l=0.001 mu_v=0.2 mu_a=100 mu_F=50")
    pl.add_argument("--starting", metavar="DEG", type=_angle,
                    help="position 0 of the plan of positions (default: found, crank and rod in line)")
    pl.add_argument("--lang", choices=("en", "uk", "ru"), default=None,
                    help="language of the sheets and worksheet (default: the language of the model's text, "
                         "[lettering] language, else en)")
    pl.add_argument("--only", metavar="PLANS", type=_plan_names, action="append",
                    help="draw only these plans, comma-separated: positions, velocity, acceleration")
    pl.add_argument("--out", metavar="DIR", required=True, help="output directory (created)")
    pl.add_argument("--cycle-scales", action="store_true",
                    help="every plan at the scales of the interactive page (`kinetostat page`): chosen once for "
                         "the whole cycle (--scale is then not used)")
    pl.set_defaults(func=cmd_plans)

    pg = sub.add_parser("page", help="the interactive page of a mechanism: one offline HTML file, an angle slider "
                                     "over every plan", description="Write one self-contained HTML file (no network): "
                        "MODEL's plans at every degree and the design position at scales fixed for the cycle, the "
                        "values table, the force plans step by step, a check of measured lengths (README: the page).")
    pg.add_argument("model", metavar="MODEL", help="model file (TOML) or a bundled model's name")
    pg.add_argument("--lang", choices=("en", "uk", "ru"), default=None, help="language (default: the model's, else en)")
    pg.add_argument("--student", action="store_true", help="the student's page: data, empty tables, the grid; no answer")
    pg.add_argument("--at", metavar="DEG", type=_angle, help="angle of the check (default: the design position)")
    pg.add_argument("--out", metavar="FILE", required=True, help="the HTML file to write")
    pg.set_defaults(func=cmd_page)

    e = sub.add_parser("examples", help="list the bundled models, or copy them (with FORMAT.md) into a folder",
                       description="List the bundled models (the seeds' worked cases shipped inside the package, "
                                   "or the *.toml files of $KINETOSTAT_MODELS): name, structure formula, source. "
                                   "With --copy DIR, copy them and FORMAT.md into DIR to edit and run them.")
    e.add_argument("--copy", metavar="DIR", help="copy every bundled model and FORMAT.md into DIR (created)")
    e.add_argument("--force", action="store_true", help="with --copy: replace files already in DIR")
    e.set_defaults(func=cmd_examples)

    va = sub.add_parser("variant", help="the task variants of Logvinenko, Nadtoka 2021 (tables 1.1-1.3): the model and its answer key",
                        description="Build the model of task TASK of Logvinenko, Nadtoka 2021 (1: ICE crank-slider, table 1.1; 2: "
                                    "opposed-cylinder ICE, table 1.2; 3: air compressor, table 1.3) for the three-"
                                    "digit variant CODE (the digits, written twice, select the columns of the rows "
                                    "labelled а б в г д е), run it, and write into DIR the model file "
                                    "task<T>_<CODE>.toml (its header states the columns and every assumption the "
                                    "text leaves open), its answer key at the design position phi1 (worksheet.md/"
                                    "html/csv/json and the plans' SVG sheets with segments.csv), cycle.csv and the teacher's "
                                    "pack (the student's sheet.pdf, the answer key key.pdf with the bands of a careful "
                                    "drawing, all plans on one A3 sheet plans_a3.pdf, and their HTML). "
                                    "--all writes the keys of every code (of TASK, or of all three tasks) into "
                                    "DIR/task<T>_<CODE>/ (no cycle.csv) with DIR/index.md and index.html, code -> M_bal, "
                                    "the largest reaction and the pack.")
    va.add_argument("task", metavar="TASK", nargs="?", help="task of Logvinenko, Nadtoka 2021: 1, 2 or 3 (with --all: default all)")
    va.add_argument("code", metavar="CODE", nargs="?", help="three-digit variant 000..999, e.g. 479")
    va.add_argument("--all", action="store_true", help="every code of TASK (or of every task), for a teacher")
    va.add_argument("--out", metavar="DIR", help="output directory (created; default ./task<T>_<CODE>, "
                                                 "with --all ./task_variants)")
    va.add_argument("--lang", choices=("en", "uk", "ru"), default=None,
                    help="language of the key and the index (default uk: the language of Logvinenko, Nadtoka 2021)")
    va.add_argument("--no-pack", action="store_true", help="no teacher's pack (sheet.pdf, key.pdf, plans_a3.pdf "
                                                           "and their HTML): the keys only, about 4 s faster a code")
    va.add_argument("--no-progress", action="store_true", help="no progress bar (--all)")
    va.add_argument("--page", action="store_true", help="also the variant's interactive page (page.html, linked from "
                                                        "the index; about 40 s a code)")
    va.set_defaults(func=cmd_variant)

    sw = sub.add_parser("sweep", help="analyse every combination of some parameters' values: a row of peaks per design",
                        description="Load MODEL once for every combination of the --param values (the first "
                                    "parameter the slowest), analyse it over the crank cycle and write one row per "
                                    "design: its parameters (in the model's units), peak_R_i_j (max |R(i,j)| over "
                                    "the cycle) for every pair, peak_M_bal (max |M_bal|), for a working machine "
                                    "peak_F_bal, n_singular and singular_deg (its singular crank angles), and "
                                    "error (why a design did not load or assemble; its peaks are then empty). "
                                    "The chunks of designs run in this process, or over Dask with --scheduler. "
                                    "Exit codes: 0 the table written, also when some designs failed (their rows "
                                    "keep the reason in 'error', and the summary counts them); 2 bad input; "
                                    "130 interrupted (Ctrl-C).")
    sw.add_argument("model", metavar="MODEL", help="model file (TOML) or a bundled model's name")
    sw.add_argument("--param", metavar="NAME=VALUES", type=_param, action="append", required=True,
                    help="a parameter of the model's [parameters] (or g) and its values: a range start:stop:step "
                         "that includes its stop (r=0.05:0.11:0.015 is 0.05, 0.065, 0.08, 0.095, 0.11), a list "
                         "(n_k=0,60,120,240,487) or one value; repeat for each parameter")
    sw.add_argument("--steps", metavar="N", type=_steps, default=360,
                    help="N equal steps over a revolution for every design (default 360)")
    sw.add_argument("--out", metavar="FILE", required=True,
                    help="the table, one row per design: FILE.parquet or FILE.csv (written atomically)")
    sw.add_argument("--full", action="store_true",
                    help="also write every angle's row of every design (the design's parameters, then the "
                         "columns of 'kinetostat analyze --out') to <stem>.angles<suffix> beside --out, e.g. "
                         "sweep.angles.parquet")
    sw.add_argument("--scheduler", metavar="WHERE",
                    help="run the chunks over Dask: 'threads' or 'processes' (this machine), or the address of a "
                         "distributed scheduler, e.g. tcp://10.0.0.5:8786 (default: in this process, no Dask)")
    sw.add_argument("--chunk", metavar="N", type=_positive("number of designs per task", "--chunk 32"), default=CHUNK,
                    help=f"designs per task (default {CHUNK})")
    sw.add_argument("--no-progress", action="store_true", help="no progress bar")
    sw.set_defaults(func=cmd_sweep)
    return p


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the `kinetostat` console script; returns the exit code."""
    warnings.showwarning = _showwarning
    _readable_streams()
    with _interrupts():
        try:
            parser = build_parser()
            args = parser.parse_args(argv)
            code = args.func(args)
            _checkpoint()
            sys.stdout.flush()           # stdout on a full disk fails here, not at the interpreter's exit
            return code
        except CLIError as exc:
            _error(exc)
            return exc.code
        except KeyboardInterrupt:
            _error("interrupted")
            return EXIT_INTERRUPTED
        except BrokenPipeError:          # `kinetostat ... | head`: the reader has what it wanted
            _quiet_stdout()
            return EXIT_OK
        except OSError as exc:           # stdout on a full disk, a name the file system cannot hold
            _quiet_stdout()
            where = f"{exc.filename}: " if exc.filename else "cannot write to stdout: "
            _error(f"{where}{exc.strerror or exc}")
            return EXIT_USAGE


if __name__ == "__main__":
    sys.exit(main())
