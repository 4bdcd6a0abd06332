"""What every command shares: exit codes, CLIError, output that does not break a progress bar,
the verbosity (-q, -v: the package logger's level and its one stderr handler, `_logging`),
interrupts, atomic saving (`_save`), warnings as one line, progress bars, the argument types,
loading a model (`_load`), the analysis with its memory check (`_analyze`), the law of motion
(`_law`, --delta/--flywheel: `_coefficient`, `_inertia`), writable outputs,
the engine routes (`_engines`) and the models prepared for them (`_prepare`).

May use: every room of the solver; the harness only inside `_engines`.
"""
from __future__ import annotations

import argparse
import errno
import logging
import math
import os
import signal
import sys
import tempfile
import time
import warnings
from contextlib import contextmanager
from pathlib import Path
from typing import Callable, IO, Iterable, Iterator, Sequence

from .._io import Interrupt as _Interrupt, _sigint_deferred, atomic, checkpoint as _checkpoint, is_stream, \
    temporary_affixes
from .._text import one_line, visible


EXIT_OK, EXIT_FAIL, EXIT_USAGE, EXIT_NOT_CHECKED, EXIT_INTERRUPTED = 0, 1, 2, 3, 130

#: The verbosity of -q (errors only), of neither option, and of -v (also the progress lines).
QUIET, NORMAL, VERBOSE = -1, 0, 1
#: The package logger's level at each verbosity.
LOG_LEVELS = {QUIET: logging.ERROR, NORMAL: logging.INFO, VERBOSE: logging.DEBUG}

log = logging.getLogger(__name__)


TABLE_SUFFIXES = (".csv", ".parquet", ".json")


class CLIError(Exception):
    """A problem with the command's input or options: one message, exit code `code`. The message
    is one line (its newlines and control characters written as "\\n" etc.: no forged
    "kinetostat: error:" line from a name or a path), or the given `lines`, each made one line."""

    def __init__(self, message: str = "", code: int = EXIT_USAGE, lines: Sequence[str] = ()):
        self.lines = tuple(one_line(s) for s in (lines or [message]))
        super().__init__("\n".join(self.lines))
        self.code = code


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


class _LogLines(logging.Handler):
    """The command line's one handler of the package logger: each record one line on stderr,
    through `_Out` (a progress bar stays whole); a warning or error led by "kinetostat: warning: "
    or "kinetostat: error: ", progress and information lines as they are."""

    def emit(self, record: logging.LogRecord) -> None:
        lead = f"kinetostat: {record.levelname.lower()}: " if record.levelno >= logging.WARNING else ""
        _Out.write(lead + one_line(record.getMessage()), err=True)


def _log_lines(verbosity: int) -> None:
    """The package logger at the level of `verbosity` (LOG_LEVELS) with one `_LogLines` handler
    (one inherited by a forked worker replaced), not passed on to the root logger's handlers."""
    package = logging.getLogger("kinetostat")
    package.handlers[:] = [h for h in package.handlers if not isinstance(h, _LogLines)] + [_LogLines()]
    package.setLevel(LOG_LEVELS[verbosity])
    package.propagate = False


@contextmanager
def _logging(verbosity: int) -> Iterator[None]:
    """`_log_lines(verbosity)` while a command runs, then the package logger as it was."""
    package = logging.getLogger("kinetostat")
    saved = package.level, package.propagate, list(package.handlers)
    _log_lines(verbosity)
    try:
        yield
    finally:
        package.handlers[:] = saved[2]
        package.setLevel(saved[0])
        package.propagate = saved[1]


def _quiet() -> bool:
    """-q: errors only (no progress bar, information line, warning or `_done` line)."""
    return not log.isEnabledFor(logging.INFO)


def _done(text: str) -> None:
    """Lines on stdout saying what a command wrote where (a report's models, a sweep's table,
    the files of plans, page, export, variant --all), each made one line by the caller
    (`one_line`, `_lines`); none under -q."""
    if not _quiet():
        _Out.write(text)


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


def _on_sigint(signum, frame) -> None:
    """Ctrl-C while a command runs: recorded (`kinetostat._io.Interrupt`) before KeyboardInterrupt
    is raised. One that lands in a garbage-collection callback or a __del__ is swallowed there,
    unprinted (`_unraisable`), and the next `_checkpoint`, or a write before it puts its file in
    place, raises it again."""
    _Interrupt.seen = True
    raise KeyboardInterrupt


def _unraisable(previous: Callable) -> Callable:
    """A `sys.unraisablehook` that drops a swallowed KeyboardInterrupt (recorded already: no
    "Exception ignored in ..." traceback) and passes anything else to `previous`."""
    def hook(unraisable) -> None:
        if not isinstance(unraisable.exc_value, KeyboardInterrupt):
            previous(unraisable)
    return hook


@contextmanager
def _interrupts() -> Iterator[None]:
    """`_on_sigint` as the SIGINT handler while a command runs (main thread only), and `_unraisable`
    as sys.unraisablehook; then the old ones, and no Ctrl-C recorded (it was this command's)."""
    _Interrupt.seen = False
    try:
        old = signal.signal(signal.SIGINT, _on_sigint)
    except ValueError:                   # not the main thread: leave the handler as it is
        yield
        return
    hook, sys.unraisablehook = sys.unraisablehook, _unraisable(sys.unraisablehook)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, old)
        sys.unraisablehook = hook
        _Interrupt.seen = False


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


def _os_reason(exc: OSError, path: str | Path) -> str:
    """An OSError's reason, led by the file it names where that is not `path` itself (a file in
    the way inside an output folder: "out/task1_000: File exists")."""
    reason = exc.strerror or str(exc)
    named = exc.filename
    return f"{named}: {reason}" if named and os.fspath(named) != os.fspath(path) else reason


def _warn(msg: str) -> None:
    """The warning line, made one line; none under -q."""
    if log.isEnabledFor(logging.WARNING):
        _Out.write(f"kinetostat: warning: {one_line(msg)}", err=True)


def _showwarning(message, category, filename, lineno, file=None, line=None):
    text = str(message).splitlines()[0] if str(message) else category.__name__
    _warn(text if issubclass(category, UserWarning) else f"{category.__name__}: {text}")


class _NoBar:
    def update(self, n: int = 1): ...
    def set_postfix_str(self, s: str = ""): ...
    def close(self): ...


def _progress(total: int, desc: str, enabled: bool):
    """A tqdm bar on stderr when stderr is a terminal (and tqdm is installed), and not -q; else a no-op."""
    if not enabled or _quiet() or not sys.stderr.isatty():
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


def bundled_models() -> list[Path]:
    from ..examples import models_dir
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
    from ..errors import ModelError, StructureError
    from ..examples import hint, resolve
    from ..model import load
    p = resolve(path)
    if not p.exists():
        bundled = hint(p)
        raise CLIError(f"model file not found: {p}" + (f"; {bundled}" if bundled else ""))
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


def _read_number(path: str) -> int | None:
    """The integer a /proc or /sys file holds (its first word), None where it is missing, "max" or not a number."""
    try:
        with open(path, encoding="ascii") as f:
            return int(f.read(64).split()[0])
    except (OSError, ValueError, IndexError):
        return None


def _status_bytes(field: str) -> int | None:
    """A "kB" line of /proc/self/status (VmSize) or /proc/meminfo (MemAvailable), bytes; None where there is none."""
    for path in ("/proc/self/status", "/proc/meminfo"):
        try:
            with open(path, encoding="ascii") as f:
                for line in f:
                    if line.startswith(field + ":"):
                        return int(line.split()[1]) * 1024
        except (OSError, ValueError, IndexError):
            pass
    return None


def _available_memory() -> int | None:
    """Bytes of memory this process may still take, or None where nothing is known: the least of
    the memory available (Linux: MemAvailable; else free physical pages), the address-space
    limit (RLIMIT_AS) less the process's size (VmSize), and its cgroup's limit less its use
    (v2: memory.max - memory.current; v1: memory.limit_in_bytes - memory.usage_in_bytes)."""
    free = [_status_bytes("MemAvailable")]
    if free[0] is None:
        try:
            free = [os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")]
        except (AttributeError, ValueError, OSError):
            free = []
    try:
        import resource
        limit = resource.getrlimit(resource.RLIMIT_AS)[0]
        size = _status_bytes("VmSize")
        if limit != resource.RLIM_INFINITY and size is not None:
            free.append(limit - size)
    except (ImportError, OSError, ValueError):
        pass
    for cap, used in (("/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory.current"),
                      ("/sys/fs/cgroup/memory/memory.limit_in_bytes", "/sys/fs/cgroup/memory/memory.usage_in_bytes")):
        c, u = _read_number(cap), _read_number(used)
        if c is not None and u is not None:
            free.append(c - u)
    known = [x for x in free if x is not None]
    return max(0, min(known)) if known else None


#: `--steps` is refused where the analysis (and its table, with --out) would need more than the
#: memory this process may still take (`_available_memory`). The analysis' bytes per crank
#: position are measured on the model by a probe: the slope of tracemalloc's peak over two runs
#: of these many positions.
PROBE_STEPS = (8, 136)
#: The analysis' peak over the probe's slope: the peak per position varies with the number of
#: positions (ice_crank_slider: 1230 bytes at 1000 positions, the probe's 1215, 2207 at 16,000).
ANALYSIS_HEADROOM = 2.0
#: Bytes per cell (position x column) of the table an output path builds on top of the
#: analysis: documented constants, measured with tracemalloc at 20,000 positions
#: (ice_crank_slider, 81 columns; chain_unit_four_bar, 108): the DataFrame, its rounded copy and
#: a chunk of text, 27-29 for .csv and 24 for .json (both written a chunk of rows at a time);
#: .parquet taken as .csv (pyarrow's memory, which tracemalloc does not see: by the peak RSS,
#: below the CSV's); "-" (CSV on stdout, its whole text built first) 37.
TABLE_CELL_BYTES = {".csv": 32, ".json": 32, ".parquet": 32, "-": 48}
#: Bytes per crank position above any the guard has counted on a bundled model, headroom and a
#: stdout table included (ice_crank_slider 6.3 kB, furnace_loader_six_bar 10.5 kB, triad_six_bar
#: 11.2 kB): where `steps` of these fit, the probe's three analyses are not run.
CERTAINLY_FITS = 64 * 1024


def _probe(mech):
    """(the analysis' bytes per crank position, the last probe run's result): tracemalloc's peak
    of `analyze` on PROBE_STEPS positions, its slope (where tracemalloc already traces, as under
    a test, its trace goes on)."""
    import tracemalloc
    from ..solve import analyze
    analyze(mech, steps=PROBE_STEPS[0])      # the imports and caches of a first run are no position's
    own = not tracemalloc.is_tracing()
    if own:
        tracemalloc.start()
    try:
        peaks = []
        for n in PROBE_STEPS:
            base = tracemalloc.get_traced_memory()[0]
            tracemalloc.reset_peak()
            res = analyze(mech, steps=n)
            peaks.append(tracemalloc.get_traced_memory()[1] - base)
    finally:
        if own:
            tracemalloc.stop()
    return max(peaks[1] - peaks[0], 0) / (PROBE_STEPS[1] - PROBE_STEPS[0]), res


def _check_memory(mech, steps: int, out: str | None = None) -> None:
    """Refuse `steps` before anything is allocated where the analysis (ANALYSIS_HEADROOM times
    the bytes per crank position a probe measures on this model) and, with `out` (--out: a file
    whose suffix picks the format, or "-"), its table (TABLE_CELL_BYTES per cell) would not fit
    in the memory this process may still take (`_available_memory`); no probe where even
    CERTAINLY_FITS bytes a position fit."""
    free = _available_memory()
    if free is None or steps * CERTAINLY_FITS <= free:
        return
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            per_angle, res = _probe(mech)
            per_angle *= ANALYSIS_HEADROOM
            if out is not None:
                cell = TABLE_CELL_BYTES.get("-" if out == "-" else Path(out).suffix.lower(), TABLE_CELL_BYTES["-"])
                per_angle += cell * len(res.to_frame().columns)
        except Exception:                # noqa: BLE001 -- the real analysis reports the fault
            return
    need = steps * per_angle
    if need > free:
        what = "the analysis" + (f" and its table (--out {out})" if out is not None else "")
        raise CLIError(f"--steps {steps}: {what} would need about {_size(need)} of memory "
                       f"({_size(per_angle)} per crank position for this model), and {_size(free)} is "
                       f"available to this process; use fewer steps (at most about {int(free // per_angle):,})")


def _analyze(mech, path: Path, phi_deg=None, steps: int = 360, friction: str | None = None, out: str | None = None,
             law=None):
    """analyze() with AssemblyError and ModelError as a CLIError, warnings printed one line each;
    `steps` that would not fit in memory (with `out`, the --out table's too) are refused before
    anything is allocated. `law` (`_law`): at that true motion, at its angles unless `phi_deg`."""
    from ..solve import analyze
    from ..errors import AssemblyError, ModelError
    if phi_deg is None:
        _check_memory(mech, steps, out)
    t0 = time.perf_counter()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            res = analyze(mech, phi_deg=phi_deg, steps=steps, friction=friction, law=law)
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


def _law(mech, path: Path, delta: float | None = None, flywheel: float | None = None, steps: int = 360):
    """`kinetostat.law_of_motion` (--delta D, --flywheel J, or neither: the model's [flywheel])
    with its faults as a CLIError naming the file, warnings printed one line each."""
    from ..errors import AssemblyError, ModelError
    from ..motion import law_of_motion
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            motion = law_of_motion(mech, delta=delta, flywheel=flywheel, steps=steps)
        except ModelError as exc:
            raise CLIError(lines=_model_error_lines(exc)) from None
        except (AssemblyError, ValueError) as exc:
            raise CLIError(f"{path}: {exc}") from None
    for text in dict.fromkeys(str(w.message).splitlines()[0] for w in caught):
        _warn(f"{Path(path).name}: {text}")
    return motion


def _scheduler_installed(scheduler: str | None) -> None:
    """CLIError where --scheduler names Dask (and, for an address, `distributed`) but it is not
    installed; None (the designs run in this process) needs nothing."""
    if scheduler is None:
        return
    import importlib.util
    from ..sweep import LOCAL_SCHEDULERS
    needs = ["dask"] + ([] if scheduler in LOCAL_SCHEDULERS else ["distributed"])
    missing = [m for m in needs if importlib.util.find_spec(m) is None]
    if missing:
        raise CLIError(f"--scheduler {scheduler}: needs {' and '.join(missing)} (pip install "
                       f"'kinetostat[sweep]'); without --scheduler the designs run in this process")


def _coefficient(text: str) -> float:
    """An argparse type: --delta, a coefficient of fluctuation 0 < D < 2."""
    try:
        x = float(text)
    except ValueError:
        x = math.nan
    if not 0 < x < 2:
        raise argparse.ArgumentTypeError(f"invalid coefficient of fluctuation {text!r}: expected 0 < D < 2 "
                                         f"((omega_max - omega_min) / omega_mean), e.g. --delta 0.02")
    return x


def _inertia(text: str) -> float:
    """An argparse type: --flywheel, a moment of inertia J >= 0, kg m^2."""
    try:
        x = float(text)
    except ValueError:
        x = math.nan
    if not (math.isfinite(x) and x >= 0):
        raise argparse.ArgumentTypeError(f"invalid flywheel {text!r}: expected a moment of inertia >= 0 in "
                                         f"kg m^2, e.g. --flywheel 0.5")
    return x


def _probe_file(folder: Path) -> IO:
    """An empty temporary file in `folder`, named as the writes' own (`kinetostat._io.temporary_affixes`:
    a killed command's probe is removed by the next write there), gone when closed."""
    prefix, suffix = temporary_affixes()
    return tempfile.NamedTemporaryFile(dir=folder, prefix=prefix, suffix=suffix)


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
        with _sigint_deferred(), _probe_file(p.parent):
            pass                         # Ctrl-C held back till the probe is gone: none left behind
    except OSError as exc:
        raise CLIError(f"cannot write {option} {p}: {exc.strerror or exc}") from None
    return p


def _writable_dir(path: str, option: str) -> Path:
    p = Path(path)
    try:
        p.mkdir(parents=True, exist_ok=True)
        with _sigint_deferred(), _probe_file(p):
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
        log.debug("%s: loaded and analysed over %d positions in %.2f s", Path(path).name, steps, secs)
    if problems:
        for p in problems[:-1]:
            _error(p)
        raise CLIError(lines=problems[-1].lines + ((f"(nothing run: {len(problems)} of {len(paths)} models have "
                                                    f"errors)",) if len(paths) > 1 else ()))
    return jobs


def _fmt(x: float, unit: str = "") -> str:
    if not math.isfinite(x):
        return "n/a"
    return f"{x:.5g}{' ' + unit if unit else ''}"



def _parquet_engine(option: str, instead: str) -> None:
    """CLIError naming `option` where no Parquet engine (pyarrow, fastparquet) is installed."""
    import importlib.util
    if importlib.util.find_spec("pyarrow") is None and importlib.util.find_spec("fastparquet") is None:
        raise CLIError(f"{option}: writing .parquet needs pyarrow (pip install 'kinetostat[sweep]' or pyarrow); "
                       f"or write {instead}")
