"""Design sweeps: one model analysed for every combination of some of its parameters' values.

    >>> import kinetostat
    >>> sw = kinetostat.sweep("chain_unit_four_bar", {"r": [0.05, 0.08, 0.11], "n_k": [0, 120]}, steps=36)
    >>> sw.shape, sw.peak("R_0_1").shape
    ((3, 2), (3, 2))

The designs are the Cartesian product of the values (first parameter the slowest), split into
chunks; each chunk is one task, `_chunk`, run in this process or on Dask (local threads or
processes, or a `distributed` scheduler). A task's arguments are plain and picklable: the model
file's text and source name and the designs' parameter values; the worker parses the text once
per chunk (`kinetostat.model.parse_text`) and builds each design's Mechanism from it (`build`).

A design whose mechanism does not load, build or assemble keeps its row: NaN peaks and its
reason in the `error` column (the sweep goes on). Warnings (singular positions, doubts about a
model) are not printed: the table's `n_singular` and `singular_deg` say where a design is singular
(values NaN), `warned_deg` and `worst_digits` where its values are kept with fewer than
DIGITS_WARN digits and the fewest digits there; `eta_cycle_reason` why a design's cycle efficiency
is undefined, and one UndefinedFigureWarning after the sweep counts those designs by cause.

May use: model, analysis, solve, fast, errors, examples, units, _io (Ctrl-C held back), _forecast (the
estimated time, logged once the first chunk is done in this process); pandas (imported when a sweep runs, so that
`import kinetostat` does not load it); dask and distributed (imported only for a
Dask scheduler), tqdm (only for a progress bar) and xarray (only in `Sweep.to_xarray`, through analysis'
`_xarray`). Never the harness, the engines, matplotlib or
`kinetostat.report`.
"""
from __future__ import annotations

import functools
import itertools
import logging
import math
import threading
import warnings
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable, Iterator, Mapping

import numpy as np

from ._forecast import Forecast
from .analysis import FRAME_NOTE, Analysis, _labelled, _xarray, crank_angles, friction_method
from .solve import analyze
from .errors import (AssemblyError, ModelError, ModelWarning, SelfLockingWarning, SingularPositionWarning, StructureError,
                     UndefinedFigureWarning)
from .model import Mechanism, _read_text, _suggest, build, load, model_text, parse_text
from .units import parameter_units

if TYPE_CHECKING:
    import pandas as pd

__all__ = ["Sweep", "sweep", "CHUNK", "LOCAL_SCHEDULERS"]

log = logging.getLogger(__name__)

#: Designs per Dask task, by default.
CHUNK = 32
#: The `scheduler` names of Dask's local schedulers; any other string is a `distributed` address.
LOCAL_SCHEDULERS = ("threads", "processes")
#: Most designs of one sweep (the product of the parameters' numbers of values), checked before any is made.
MAX_DESIGNS = 1_000_000
#: `eta_cycle_reason` where the angles are not a uniform full cycle (no cycle efficiency to give).
NOT_A_CYCLE = "the angles are not a uniform full cycle (sweep with steps=N)"
#: Seconds to wait for a distributed scheduler to answer (to connect and send its greeting), and
#: for its first worker.
CONNECT_TIMEOUT = 10.0


@dataclass(frozen=True, eq=False)
class Sweep:
    """The result of `sweep`: one row per design, and every angle's rows when asked for."""
    table: pd.DataFrame          # one row per design: its parameters, peak_<col>, n_singular, singular_deg, error
    angles: pd.DataFrame | None  # the designs' parameters, then `Analysis.to_frame`'s columns; None unless full
    shape: tuple[int, ...]       # the design axes: the number of values of each parameter, in order
    phi_deg: np.ndarray          # (N,) the crank angles of every design, deg

    def __repr__(self) -> str:
        failed = int((self.table["error"] != "").sum())
        return (f"Sweep(designs={len(self.table)}, shape={self.shape}, positions={len(self.phi_deg)}, "
                f"failed={failed}, angles={'kept' if self.angles is not None else 'not kept'})")

    def peak(self, col: str) -> np.ndarray:
        """The peak of the cycle table's column `col` ("R_0_1" or "peak_R_0_1") over the cycle
        for every design, shape `shape` (NaN where a design failed)."""
        name = col if col.startswith("peak_") else f"peak_{col}"
        valid = [c for c in self.table.columns if c.startswith("peak_")]
        if name not in valid:
            raise KeyError(f"no peak of {col!r}{_suggest(name, valid)}. Peaks: {[c[5:] for c in valid]}")
        return self.table[name].to_numpy(dtype=float).reshape(self.shape)

    def to_xarray(self):
        """The sweep as an xarray Dataset (the optional extra: pip install 'kinetostat[xarray]').

        One dimension per swept parameter, in the sweep's order (its values the coordinate, its
        unit the model's, "not stated" where the model states none), then, where the angles are
        kept (`full`), the crank angle `phi` (deg): the design axes before the crank-angle axis.
        Variables over the design axes: the table's columns (peak_R_i_j, peak_M_bal, n_singular,
        ..., error); with the angles kept also every numeric column of the angles' table
        (`Analysis.to_frame`'s names: x_A, omega_2, Rx_0_1, M_bal, ...) over (designs, phi). Every
        variable has attrs units (the table's), frame and long_name. Counts and flags are floats:
        NaN where a design failed (its `error` says why)."""
        xr = _xarray()
        n_axes = len(self.shape)
        names = list(self.table.columns[:n_axes])
        units = self.table.attrs["units"]
        axes = tuple(names)
        coords = {}
        for k, name in enumerate(names):
            grid = self.table[name].to_numpy(dtype=float).reshape(self.shape)
            coords[name] = _labelled(name, grid[tuple(slice(None) if a == k else 0 for a in range(n_axes))],
                                     units[name], "none", f"swept parameter {name}")
        data = {col: _labelled(axes, _design_values(self.table[col]).reshape(self.shape), units[col], "none",
                               _meaning(col))
                for col in self.table.columns[n_axes:]}
        if self.angles is not None:
            coords["phi"] = _labelled("phi", self.phi_deg, "deg", "world",
                                      "crank angle from the model's drive reference in the drive's sense")
            ran = (self.table["error"] == "").to_numpy()
            angle_units = self.angles.attrs.get("units", {})
            for col in self.angles.columns[n_axes:]:
                if col == "phi_deg" or self.angles[col].dtype.kind not in "biuf":
                    continue
                values = np.full((len(ran), len(self.phi_deg)), np.nan)
                values[ran] = self.angles[col].to_numpy(dtype=float).reshape(int(ran.sum()), len(self.phi_deg))
                unit = angle_units[col]
                data[col] = _labelled((*axes, "phi"), values.reshape(*self.shape, len(self.phi_deg)), unit,
                                      "none" if unit in ("1", "bool") else "world",
                                      f"{col} at each crank angle (Analysis.to_frame)")
        return xr.Dataset(data, coords=coords, attrs={
            "mechanism": self.table.attrs["mechanism"],
            "conventions": f"design axes ({', '.join(names)}) before the crank-angle axis phi; {FRAME_NOTE}"})


#: What each column of a sweep's table but the peaks holds (`Sweep.to_xarray`'s long names).
_TABLE_MEANING = {
    "n_singular": "number of singular crank angles", "singular_deg": "the singular crank angles",
    "worst_digits": "fewest significant digits left among the warned angles",
    "warned_deg": "the crank angles kept with fewer than DIGITS_WARN digits", "eta_cycle": "cycle efficiency",
    "eta_cycle_reason": "why eta_cycle is NaN", "n_self_locking": "number of self-locking crank angles",
    "error": "why the design failed ('' where it ran)"}


def _meaning(col: str) -> str:
    """What the sweep table's column `col` holds: a peak's, or `_TABLE_MEANING`'s."""
    return f"largest |{col.removeprefix('peak_')}| over the cycle" if col.startswith("peak_") else _TABLE_MEANING[col]


def _design_values(col: pd.Series) -> np.ndarray:
    """A column of the sweep's table as an array: text as str, numbers (counts too) as float, NaN for a missing value."""
    return col.to_numpy(dtype=float, na_value=np.nan) if col.dtype.kind in "biuf" else col.to_numpy(dtype=str)


def sweep(model: str | Path | Mechanism, params: Mapping[str, Any], *, steps: int = 360, phi_deg=None,
          full: bool = False, scheduler: Any = None, chunk: int = CHUNK, progress: bool = False,
          friction: str | None = None) -> Sweep:
    """Analyse `model` (a file, a bundled model's name, or a Mechanism read from a file) for every
    combination of `params` (name -> values, array-like; the first parameter the slowest) at
    `steps` crank angles over a cycle, or at `phi_deg` (deg).

    `full`: also keep every angle's row (`Sweep.angles`). `scheduler`: None runs in this
    process (no Dask); "threads" or "processes": Dask's local schedulers; another string: the
    address of a `distributed` scheduler; or a `distributed.Client`. `chunk`: designs per task.
    `progress`: a tqdm bar over the chunks on stderr. In this process, the time the remaining
    designs will take is logged once the first chunk is done (INFO, logger "kinetostat.sweep").
    `friction`: as `analyze` takes it (default:
    the model's); with friction in the reactions each row also has `eta_cycle` (the cycle
    efficiency, NaN unless the angles are a uniform full cycle), `eta_cycle_reason` (why it is NaN,
    `Analysis.cycle_efficiency_reason`; "" where it is a number) and `n_self_locking` (the count of
    self-locking angles, `Analysis.self_locking`); one UndefinedFigureWarning, after the sweep,
    counts the designs whose eta_cycle is undefined over a uniform full cycle, by cause.

    ValueError names an unknown parameter, an empty or non-finite list of values, a parameter
    named as a column of the angles' table (with `full`), or a bad
    `chunk`; the model itself must load with its own parameters (ModelError otherwise);
    ConnectionError: no `distributed` scheduler at the address."""
    import pandas as pd
    text, source, base = _model_text(model)
    names = list(params)
    valid = [*base.parameters, "g"]
    for name in names:
        if name not in valid:
            raise ValueError(f"sweep: {name!r} is not a parameter of the model{_suggest(name, valid)}. "
                             f"Parameters: {', '.join(valid)}")
    values = [_values(name, params[name]) for name in names]
    n_designs = math.prod(len(v) for v in values)
    if n_designs > MAX_DESIGNS:
        raise ValueError(f"sweep: {' x '.join(str(len(v)) for v in values)} = {n_designs:.3g} designs, at most "
                         f"{MAX_DESIGNS}; sweep fewer values")
    if not isinstance(chunk, (int, np.integer)) or isinstance(chunk, bool) or chunk < 1:
        raise ValueError(f"chunk: expected a positive number of designs per task, got {chunk!r}")
    phi_deg = crank_angles(phi_deg, steps)
    if full:
        clash = [name for name in names if name in _angle_columns(base, phi_deg)]
        if clash:
            raise ValueError(f"sweep: parameter {clash[0]!r} has the name of a column of the angles' table "
                             f"(full=True: the parameters lead `Analysis.to_frame`'s columns); rename it in the model")
    designs = [dict(zip(names, d)) for d in itertools.product(*values)]
    parts = [designs[k:k + chunk] for k in range(0, len(designs), chunk)]
    friction_method(base, friction)                 # ValueError for a bad method, before any design runs
    from . import fast
    n = len(designs) * len(phi_deg)                 # decided here once, so every chunk (any worker) agrees
    compiled = not full and fast.pays(base, n, "peaks")
    results = _run(parts, functools.partial(_chunk, text, source, phi_deg=phi_deg, full=full, friction=friction,
                                            compiled=compiled), scheduler, progress)
    table = _tidy(pd.concat([rows for rows, _ in results], ignore_index=True), names, base, friction)
    if "eta_cycle_reason" in table:
        _warn_undefined_eta(table["eta_cycle_reason"])
    angles = None
    if full:
        frames = [a for _, a in results if a is not None and len(a)]
        angles = pd.concat(frames, ignore_index=True) if frames else pd.DataFrame(columns=names)
        angles.attrs.update(mechanism=base.name, units=_units(frames, _parameter_units(base, names)))
    return Sweep(table, angles, tuple(len(v) for v in values), phi_deg)


# ----------------------------------------------------------------------------- one chunk of designs

def _chunk(text: str, source: str, designs: list[dict[str, float]], phi_deg: np.ndarray,
           full: bool, friction: str | None = None, compiled: bool = False) -> tuple[pd.DataFrame, pd.DataFrame | None]:
    """The rows of `designs` (each: parameter -> value) of the model `text`: one per design (its
    parameters, peaks, singular angles, error), and with `full` every angle's row (None without);
    `compiled`: the peaks by the compiled kernel (`sweep` decides it for the whole sweep: where
    its positions reach `fast.threshold` in the calling process).
    A Dask task: plain, picklable arguments."""
    import pandas as pd
    from . import fast
    rows, frames, built = [], [], []
    with _quiet():
        model = parse_text(text, source)            # once: each design is built from the parsed text
        for design in designs:
            try:
                mech = build(model, parameters=design)
                kernel = _kernel(mech, compiled, friction)
                res = None if kernel else analyze(mech, phi_deg=phi_deg, friction=friction)
            except (ModelError, StructureError, AssemblyError) as exc:
                rows.append({**design, "error": _reason(exc)})
                continue
            if kernel:
                rows.append({**design, "error": ""})
                built.append((len(rows) - 1, mech))
                continue
            sing = res.phi_deg[res.singular]
            rows.append({**design, **{name: _peak(column(res)) for name, column in _peak_columns(mech).items()},
                         "n_singular": len(sing), "singular_deg": " ".join(f"{x:g}" for x in sing),
                         **_accuracy(*fast.warned_band(res)), **_friction_columns(res), "error": ""})
            if full:
                frames.append(_with_design(res.to_frame(), design))
        if built:       # the peaks of every design of the chunk in one call of the compiled kernel
            _peaks_into(rows, built, np.asarray(phi_deg, float))
    if not full:
        return pd.DataFrame(rows), None
    angles = pd.concat(frames, ignore_index=True) if frames else pd.DataFrame(columns=list(designs[0]))
    angles.attrs["units"] = _units(frames, {})
    return pd.DataFrame(rows), angles


def _kernel(mech: Mechanism, compiled: bool, friction: str | None = None) -> bool:
    """Whether a design of a run that takes the compiled path (`compiled`) goes there: not a triad's
    (the numpy path), nor with friction in the reactions (the kernel has no friction)."""
    from . import fast
    return compiled and fast.refusal(mech) is None and friction_method(mech, friction) != "reactions"


def _peaks_into(rows: list[dict], built: list[tuple[int, Mechanism]], phi_deg: np.ndarray) -> None:
    """Fill each built design's row with its peaks and singular angles (`fast.peaks`: one kernel
    call per structure; a design that cannot be assembled at some angle keeps its error row)."""
    from . import fast
    try:
        pk = fast.peaks([m for _, m in built], phi_deg)
    except AssemblyError as exc:      # this design fails; of several: find which, one by one
        if len(built) == 1:
            rows[built[0][0]]["error"] = _reason(exc)
        else:
            for one in built:
                _peaks_into(rows, [one], phi_deg)
        return
    for q, (n, m) in enumerate(built):
        sing = pk.singular_deg[q]
        everything = len(sing) == len(phi_deg)          # no regular angle: no peak
        peak = dict(zip((f"peak_R_{p.links[0]}_{p.links[1]}" for p in m.pairs), pk.R[q]))
        peak["peak_M_bal"] = pk.M_bal[q]
        if m.drive.kind == "machine":
            peak["peak_F_bal"] = pk.F_bal[q]
        rows[n].update({k: np.nan if everything else float(v) for k, v in peak.items()},
                       n_singular=len(sing), singular_deg=" ".join(f"{x:g}" for x in sing),
                       **_accuracy(pk.warned_deg[q], pk.worst_digits[q]))
        rows[n] = {**{k: v for k, v in rows[n].items() if k != "error"}, "error": rows[n]["error"]}


def _friction_columns(res: Analysis) -> dict[str, Any]:
    """With friction in the reactions: the cycle efficiency (NaN unless the angles are a uniform
    full cycle), why it is NaN (no warning per design) and the number of self-locking angles;
    nothing otherwise."""
    if res.friction is None:
        return {}
    try:
        why = res.cycle_efficiency_reason()
    except ValueError:
        why = NOT_A_CYCLE
    return {"eta_cycle": math.nan if why else res.cycle_efficiency(), "eta_cycle_reason": why,
            "n_self_locking": int(res.self_locking.sum())}


def _warn_undefined_eta(reasons: pd.Series) -> None:
    """One UndefinedFigureWarning for all the designs whose eta_cycle is undefined over a uniform
    full cycle (`reasons`: the eta_cycle_reason column): how many, and how many of them by each
    cause (a reason's text before its figures in parentheses)."""
    causes = reasons[(reasons != "") & (reasons != NOT_A_CYCLE)].str.split(" (", n=1, regex=False).str[0]
    if len(causes):
        why = "; ".join(f"{n} where {cause}" for cause, n in causes.value_counts(sort=False).items())
        warnings.warn(UndefinedFigureWarning(f"sweep: eta_cycle undefined (NaN) for {len(causes)} of {len(reasons)} "
                                             f"design(s): {why} (each design's reason in eta_cycle_reason)", why),
                      stacklevel=3)


def _accuracy(warned_deg: np.ndarray, worst: float) -> dict[str, Any]:
    """The columns of the warned band: the angles kept with fewer than DIGITS_WARN digits, and the
    fewest digits there (NaN where none is warned)."""
    return {"worst_digits": round(float(worst), 1), "warned_deg": " ".join(f"{x:g}" for x in warned_deg)}


def _peak_columns(m: Mechanism) -> dict[str, Callable[[Analysis], np.ndarray]]:
    """The cycle table's force columns whose peaks a sweep keeps, named `peak_<col>`, each with
    how to read it from an analysis: every pair's |R_i_j|, M_bal, a working machine's |F_bal|."""
    cols: dict[str, Callable[[Analysis], np.ndarray]] = {
        f"peak_R_{p.links[0]}_{p.links[1]}": lambda res, k=p.index: np.linalg.norm(res.forces.R[:, k], axis=-1)
        for p in m.pairs}
    cols["peak_M_bal"] = lambda res: res.balancing_moment
    if m.drive.kind == "machine":
        cols["peak_F_bal"] = lambda res: np.linalg.norm(res.balancing_force, axis=-1)
    return cols


def _peak(x: np.ndarray) -> float:
    """max |x| over the cycle, ignoring singular (NaN) angles; NaN where every angle is singular."""
    return float(np.fmax.reduce(np.abs(x)))


def _reason(exc: Exception) -> str:
    """Why a design failed, on one line."""
    text = "; ".join(exc.located) if isinstance(exc, ModelError) else str(exc)
    return f"{type(exc).__name__}: {' '.join(text.split())}"


def _angle_columns(mech: Mechanism, phi_deg: np.ndarray) -> set[str]:
    """The columns of `mech`'s cycle table (`Analysis.to_frame`, from its first angle); none where
    it does not assemble there (the table's writer then refuses a repeated name)."""
    with _quiet():
        try:
            return set(analyze(mech, phi_deg=phi_deg[:1]).to_frame().columns)
        except (AssemblyError, ValueError):
            return set()


def _with_design(df: pd.DataFrame, design: Mapping[str, float]) -> pd.DataFrame:
    """`df` (one analysis's cycle table) led by the design's parameters as columns (units: the
    table's; `sweep` adds the parameters')."""
    import pandas as pd
    lead = pd.DataFrame({name: np.full(len(df), value) for name, value in design.items()})
    out = pd.concat([lead, df], axis=1)
    out.attrs["units"] = _units([df], {})
    return out


@contextmanager
def _quiet() -> Iterator[None]:
    """kinetostat's warnings silenced (the rows say where a design is singular). On the main
    thread for the block only; on another thread (Dask's thread pool, a `distributed` worker)
    the filter stays in that process, since `catch_warnings` is not thread-safe: `sweep` itself
    restores the filters around Dask's local threads."""
    if threading.current_thread() is threading.main_thread():
        with warnings.catch_warnings():
            for category in (ModelWarning, SingularPositionWarning, SelfLockingWarning):
                warnings.simplefilter("ignore", category)
            yield
    else:
        for category in (ModelWarning, SingularPositionWarning, SelfLockingWarning):
            warnings.simplefilter("ignore", category)
        yield


# ----------------------------------------------------------------------------- running the chunks

def _run(parts: list, task: Callable[[Any], Any], scheduler: Any, progress: bool, name: str = "sweep") -> list:
    """`task(part)` of every chunk in `parts` (a list of designs each, or what `task` takes; `task`
    picklable: a module's function, or a partial of one), the results in the order of `parts`:
    in this process (each chunk logged, DEBUG; the time of the rest logged after the first,
    INFO: `Forecast`), or over Dask (tasks named kinetostat-<name>-chunk-<k>)."""
    bar = _bar(len(parts), progress)
    try:
        if scheduler is None:
            out = []
            eta = Forecast(log, sum(map(len, parts)), "design(s)",
                           faster=["--scheduler processes (the API's scheduler='processes')"])
            for k, part in enumerate(parts):
                out.append(task(part))
                log.debug("%s: chunk %d of %d done (%d design(s))", name, k + 1, len(parts), len(part))
                bar.update()
                eta.done(len(part))
            return out
        import dask
        keys = [f"kinetostat-{name}-chunk-{k}" for k in range(len(parts))]
        tasks = [dask.delayed(task, pure=True)(part, dask_key_name=key) for part, key in zip(parts, keys)]
        if isinstance(scheduler, str) and scheduler in LOCAL_SCHEDULERS:
            from dask.callbacks import Callback
            finished = set(keys)

            def count(key, result, dsk, state, worker_id):
                if key in finished:
                    bar.update()
            with warnings.catch_warnings(), Callback(posttask=count), _workers(scheduler, len(parts)) as pool:
                return list(dask.compute(*tasks, scheduler=scheduler, **pool))
        return _distributed(tasks, scheduler, bar)
    finally:
        bar.close()


@contextmanager
def _workers(scheduler: str, tasks: int) -> Iterator[dict[str, Any]]:
    """Dask's keyword for the local `scheduler`: for "processes", a pool of worker processes (as
    many as Dask's num_workers, by default one per core; at most one per task) that ignore
    Ctrl-C, ended with the block (terminated: an interrupted sweep leaves no worker running). The terminal sends Ctrl-C to the whole group:
    the main process reports it, and no worker prints a traceback, also one still starting
    Python: each starts with SIGINT blocked (this thread's mask while the pool starts, which a
    new process inherits) and ignores it before unblocking it. A Ctrl-C while the pool starts is
    held back till it has started (`_io._sigint_deferred`), so that no worker is left half-made."""
    if scheduler != "processes":
        yield {}
        return
    import functools
    import signal
    import dask
    from dask.multiprocessing import get_context, initialize_worker_process
    from dask.system import CPU_COUNT
    from ._io import _sigint_deferred
    blocks = hasattr(signal, "pthread_sigmask")
    n = max(1, min(dask.config.get("num_workers", None) or CPU_COUNT, tasks))
    start = functools.partial(initialize_worker_process, user_initializer=_ignore_sigint)
    pool = None
    try:
        if blocks:
            from multiprocessing import resource_tracker
            resource_tracker.ensure_running()     # started first: starting it unblocks SIGINT in this thread
        with _sigint_deferred():
            old = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT}) if blocks else None
            try:
                pool = get_context().Pool(n, initializer=start)
            finally:
                if blocks:
                    signal.pthread_sigmask(signal.SIG_SETMASK, old)
        yield {"pool": pool}
    finally:
        if pool is not None:
            pool.terminate()
            pool.join()


def _ignore_sigint() -> None:
    """A worker process ignores Ctrl-C (the terminal sends it to the whole group), then takes
    SIGINT off the mask it was started with (`_workers`)."""
    import signal
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    if hasattr(signal, "pthread_sigmask"):
        signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})


def _distributed(tasks: list, scheduler: Any, bar) -> list:
    """The tasks' results from a `distributed` scheduler (an address, or a Client)."""
    from distributed import Client, as_completed
    if isinstance(scheduler, str):
        if scheduler.partition("://")[0] in ("tls", "ucx"):
            raise ConnectionError(f"scheduler {scheduler!r}: a {scheduler.partition('://')[0].upper()} scheduler "
                                  f"needs its security or transport set up: connect a distributed.Client yourself "
                                  f"and pass it (the API's scheduler=client)")
        try:
            _greeted(scheduler, CONNECT_TIMEOUT)
            client = Client(scheduler, timeout=CONNECT_TIMEOUT)
        except TimeoutError:
            raise ConnectionError(f"scheduler {scheduler!r}: no answer within {CONNECT_TIMEOUT:g} s (CONNECT_TIMEOUT); "
                                  f"is a distributed scheduler listening there?") from None
        except (OSError, ValueError, TypeError) as exc:
            raise ConnectionError(f"scheduler {scheduler!r}: no distributed scheduler there ({exc}); "
                                  f"or use {' or '.join(map(repr, LOCAL_SCHEDULERS))}") from None
        with client:
            try:
                client.wait_for_workers(1, timeout=CONNECT_TIMEOUT)
            except (OSError, TimeoutError) as exc:
                raise ConnectionError(f"scheduler {scheduler!r}: no worker joined it within {CONNECT_TIMEOUT:g} s "
                                      f"({type(exc).__name__}); start workers (dask worker {scheduler})") from None
            return _gather(client, tasks, bar, as_completed)
    if not isinstance(scheduler, Client):
        raise TypeError(f"scheduler: expected None, {' or '.join(map(repr, LOCAL_SCHEDULERS))}, a distributed "
                        f"scheduler's address or a distributed.Client, got {type(scheduler).__name__}")
    return _gather(scheduler, tasks, bar, as_completed)


def _greeted(address: str, timeout: float) -> None:
    """Connect to the distributed scheduler at `address` and read its greeting (distributed's
    handshake) within `timeout` s, then hang up: TimeoutError where the port accepts but never
    answers, which `distributed.Client` would wait on for ever. In a thread of its own, with
    its own event loop (the caller's thread may run one: a notebook's)."""
    import asyncio
    from concurrent.futures import ThreadPoolExecutor

    from distributed.comm import connect

    async def hello() -> None:
        comm = await connect(address, timeout=timeout)
        await comm.close()
    with ThreadPoolExecutor(1) as pool:
        pool.submit(lambda: asyncio.run(asyncio.wait_for(hello(), timeout))).result()


def _gather(client, tasks: list, bar, as_completed) -> list:
    futures = client.compute(tasks)
    for _ in as_completed(futures):
        bar.update()
    return client.gather(futures)


class _NoBar:
    def update(self, n: int = 1) -> None: ...
    def close(self) -> None: ...


def _bar(total: int, enabled: bool):
    """A tqdm bar over the chunks on stderr, or a no-op."""
    if not enabled:
        return _NoBar()
    from tqdm import tqdm
    return tqdm(total=total, desc="designs' chunks", unit="chunk", leave=False, dynamic_ncols=True)


# ----------------------------------------------------------------------------- inputs and the table

def _model_text(model: str | Path | Mechanism) -> tuple[str, str, Mechanism]:
    """The model file's text, its source name, and the mechanism it gives with its own parameters.
    A Mechanism is read again from its file (`.path`): ValueError where it has none, or where it
    differs from what its file gives now (loaded with overrides, or the file changed)."""
    if isinstance(model, Mechanism):
        if model.path is None:
            raise ValueError("sweep: the Mechanism was not read from a file (its .path is None); give the "
                             "model file, or write the model to one")
        base = load(model.path)
        if dict(base.parameters) != dict(model.parameters):
            raise ValueError(f"sweep: the Mechanism's parameters differ from those of its file {model.path} (loaded "
                             f"with parameters=..., or the file changed); give the file and sweep those parameters")
        path = Path(model.path)
    else:
        from .examples import resolve
        path = resolve(model)
        base = load(path)
    return _read_text(path), str(path), base


def _values(name: str, x: Any) -> list[float]:
    """The values of parameter `name`: a number or a 1-D array-like of finite numbers."""
    try:
        v = np.array(x, dtype=float, ndmin=1)
    except (TypeError, ValueError):
        raise ValueError(f"sweep: {name}: expected numbers, got {x!r:.60}") from None
    if v.ndim != 1 or len(v) == 0 or not np.isfinite(v).all():
        raise ValueError(f"sweep: {name}: expected a non-empty list of finite numbers, got {x!r:.60}")
    return [float(a) for a in v]


def _tidy(table: pd.DataFrame, names: list[str], base: Mechanism, friction: str | None = None) -> pd.DataFrame:
    """The rows in the sweep's column order (NaN peaks for a failed design), with their units."""
    peaks = list(_peak_columns(base))
    exact = base.friction is not None and friction_method(base, friction) == "reactions"
    table = table.reindex(columns=[*names, *peaks, "n_singular", "singular_deg", "worst_digits", "warned_deg",
                                   *(["eta_cycle", "eta_cycle_reason", "n_self_locking"] if exact else []), "error"])
    if exact:
        table["eta_cycle"] = table["eta_cycle"].astype(float)
        table["n_self_locking"] = table["n_self_locking"].astype("Int64")
        table["eta_cycle_reason"] = table["eta_cycle_reason"].astype(object).fillna("").astype(str)
    table["worst_digits"] = table["worst_digits"].astype(float)
    table["warned_deg"] = table["warned_deg"].astype(object).fillna("").astype(str)
    table[peaks] = table[peaks].astype(float)
    table["n_singular"] = table["n_singular"].astype("Int64")
    for text in ("singular_deg", "error"):          # every design failed: a column of NaN, no text
        table[text] = table[text].astype(object).fillna("").astype(str)
    table.attrs.update(mechanism=base.name, units={
        **_parameter_units(base, names), **{c: "N m" if c == "peak_M_bal" else "N" for c in peaks},
        "n_singular": "1", "singular_deg": "deg", "worst_digits": "1", "warned_deg": "deg", "error": "text",
        **({"eta_cycle": "1", "eta_cycle_reason": "text", "n_self_locking": "1"} if exact else {})})
    return table


def _parameter_units(base: Mechanism, names: list[str]) -> dict[str, str]:
    """The unit of each swept parameter (`kinetostat.units.parameter_units`; g in m/s^2)."""
    stated = {**parameter_units(base, model_text(base)), "g": "m/s^2"}
    return {name: stated[name] for name in names}


def _units(frames: list[pd.DataFrame], params: Mapping[str, str]) -> dict[str, str]:
    """The units of the columns of `frames`, led by the parameters' `params` (name -> unit)."""
    units = dict(params)
    for f in frames:
        units.update({k: u for k, u in f.attrs.get("units", {}).items() if k not in params})
    return units
