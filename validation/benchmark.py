"""Benchmark: run time against error for the solver and every engine route, per bundled model.

    python -m kinetostat_validation.benchmark              # full study: writes ./reports/benchmark.{md,csv,png}
    python -m kinetostat_validation.benchmark --out DIR    # ... into DIR instead
    python -m kinetostat_validation.benchmark --quick      # fewer repeats and settings, prints only
    python -m kinetostat_validation.benchmark --drawing-budgets   # only the drawing layer's budgets, printed
    python -m kinetostat_validation.benchmark --tolerance 100000  # only a Monte Carlo tolerance study's rate, printed
    python -m kinetostat_validation.benchmark --sensitivity 100000  # only the compiled sensitivities' cost, printed
    python -m kinetostat_validation.benchmark --bound 100000  # only the four-bar's and the ICE's peaks against their bound, printed

Every route runs over the same full cycle (360 angles) and is timed as the median of repeated
runs in one process; its error is the worst peak-relative error over the driving moment and
all reactions against the mpmath reference (`validation.reference`, 40 digits). Figures are
printed and written, never asserted: speed is measured, not tested.

The section "Against the engines' compiled kernels and the machine's limit" sets the solver's
time per angle (360 and 10^6 angles) beside MuJoCo's and Pinocchio's own kernels and the
machine's limit (`kernels`), all measured in the same run; `fast_path_rows` is the hook that
times any `fast(mech, N)` the same way (the solver's rows come from it too). The section "The
compiled path" (`speed_study`) times `kinetostat.fast` (peaks on 1 and 2 threads, full results
in reused chunks, into one reused buffer and into fresh memory) beside the scalar kernel of
commit BEFORE, the numpy path and MuJoCo's kernels, in interleaved rounds, CPU and wall time,
each against its own limit, with the CPU, its flags and its load recorded. The section "The
peaks kernels against their bound" (`bound_study`) counts each peaks kernel's program by kind and
sets its time against the bound of this core's division, square-root and FMA rates.

May use: kinetostat, the scene, compare, reference, the engine adapters, kernels, study_cli, matplotlib.
"""
from __future__ import annotations

import dataclasses
import itertools
import math
import os
import statistics
import time
import warnings
from pathlib import Path
from typing import Callable

import numpy as np

import kinetostat
from kinetostat import fast
from kinetostat.analysis import crank_angles, exact
from kinetostat.kinematics import kinematics

from .compare import errors
from .kernels import Program
from .scene import EngineResult, Scene, build_scene
from .study_cli import parser, require_plots

ROOT = Path(__file__).resolve().parents[1]
ANGLES = 360
EXACT_SECONDS = 1.0     # an exact route is timed over at least 20 runs and at least this long


@dataclasses.dataclass(frozen=True)
class Timing:
    """Repeated runs of one call, s: CPU time (this process, all its threads) and wall time,
    minimum and median, and the number of runs."""
    cpu_min: float
    cpu_median: float
    wall_min: float
    wall_median: float
    runs: int


def timed_runs(fn: Callable[[], object], repeat: int, min_seconds: float = 0.0) -> tuple[Timing, object]:
    """CPU and wall time of `fn()` over at least `repeat` runs, and as many more as fill
    `min_seconds` of wall time (a sub-millisecond route then gets hundreds: one stall of the
    machine cannot move its median), after one warm-up, and its last result."""
    out = fn()
    cpu: list[float] = []
    wall: list[float] = []
    while len(wall) < repeat or sum(wall) < min_seconds:
        out = None          # the last result is released first: a run reuses its memory, as in a loop
        c, w = time.process_time(), time.perf_counter()
        out = fn()
        cpu.append(time.process_time() - c)
        wall.append(time.perf_counter() - w)
    return Timing(min(cpu), statistics.median(cpu), min(wall), statistics.median(wall), len(wall)), out


def _solver_result(scene: Scene) -> EngineResult:
    res = kinetostat.analyze(scene.mech, phi_deg=scene.phi_deg)
    return EngineResult("kinetostat", "exact", res.phi_deg, res.balancing_moment, res.forces.R)


def routes(quick: bool) -> list[tuple[str, str, Callable[[Scene], EngineResult]]]:
    """(route, setting, runner) for every route and setting of the study: pymunk single runs
    and Richardson pairs side by side (the route's own setting is Richardson 720/1440)."""
    from . import engine_mujoco, engine_pinocchio, engine_pymunk
    out = [("kinetostat", "closed form", _solver_result),
           ("pinocchio", "exact state", engine_pinocchio.solve),
           ("mujoco", "exact state", engine_mujoco.solve)]
    for n in ((3600,) if quick else (1800, 3600, 7200)):
        out.append(("mujoco-sim", f"{n} steps/rev", lambda s, n=n: engine_mujoco.simulate(s, steps_per_rev=n)))
    single = lambda n, **kw: lambda s: engine_pymunk.simulate(s, steps_per_rev=n, richardson=False, **kw)
    both = lambda n: lambda s: engine_pymunk.simulate(s, steps_per_rev=n, richardson=True)
    for n in ((1440,) if quick else (720, 1440, 2880)):
        out.append(("pymunk", f"{n} steps/rev", single(n)))
    out.append(("pymunk", "Richardson 720/1440 (route)", both(720)))
    if not quick:
        out.append(("pymunk", "1000 iterations", single(1440, iterations=1000)))
        out.append(("pymunk", "Richardson 1440/2880", both(1440)))
    return out


def worst_error(res: kinetostat.Analysis, M_ref: np.ndarray, R_ref: np.ndarray, er: EngineResult) -> float:
    """Worst peak-relative error of an engine result against the reference, over all quantities."""
    ref = dataclasses.replace(res, forces=dataclasses.replace(res.forces, R=R_ref, M_bal=M_ref))
    rows = [r for r in errors(ref, er, np.inf, "") if r.quantity == "M_drive" or r.quantity.startswith("R(")]
    return float(np.nanmax([r.peak_relative for r in rows]))


def study(models: list[Path], quick: bool) -> list[dict]:
    from .reference import reference
    rows = []
    for path in models:
        mech = kinetostat.load(path)
        scene = build_scene(mech, steps=ANGLES)
        M_ref, R_ref = reference(mech, scene.phi_deg, res=scene.res)
        for route, setting, run in routes(quick):
            exact = route in ("kinetostat", "pinocchio", "mujoco")
            repeat = 3 if quick else (20 if exact else 3)
            t, er = timed_runs(lambda: run(scene), repeat, EXACT_SECONDS if exact and not quick else 0.0)
            seconds = t.wall_median
            rows.append(dict(model=path.stem, route=route, setting=setting, seconds=seconds, cpu_min=t.cpu_min,
                             cpu_median=t.cpu_median, wall_min=t.wall_min, runs=t.runs,
                             error=worst_error(scene.res, M_ref, R_ref, er),
                             magnitudes_only=er.magnitudes_only))
            print(f"{path.stem:24s} {route:11s} {setting:28s} {seconds * 1e3:10.3f} ms  error {rows[-1]['error']:.2e}",
                  flush=True)
    return rows


def throughput(mech: kinetostat.Mechanism) -> list[dict]:
    """The solver's full kinetostatic analysis on large batches of angles: the first call of each
    size (after a warm-up of FAST_MIN angles that loads the compiled kernel: fresh memory from
    the operating system) and the median of repeated calls, and the size of the result per angle."""
    out = []
    rng = np.random.default_rng(0)
    fast.kernel(mech, "full")                       # the compiled kernel loaded: analyze takes it from FAST_MIN
    kinetostat.analyze(mech, steps=fast.FAST_MIN)   # memos (dead centres, diagrams)
    for n in (10**4, 10**5, 10**6):
        phi = rng.uniform(0.0, 360.0, n)
        t = time.perf_counter()
        res = kinetostat.analyze(mech, phi_deg=phi)
        first = time.perf_counter() - t
        size = _nbytes(res) / n
        del res
        t, _ = timed_runs(lambda: kinetostat.analyze(mech, phi_deg=phi), 5)
        out.append(dict(angles=n, first_seconds=first, seconds=t.wall_median, per_second=n / t.wall_median,
                        cpu_min=t.cpu_min, cpu_median=t.cpu_median, wall_min=t.wall_min, bytes_per_angle=size))
    return out


#: The models and sizes of `crossover`: the four-bar, the ICE (a gas diagram: loads per chunk) and
#: the six-link furnace loader (springs).
CROSSOVER_MODELS = ("chain_unit_four_bar", "ice_crank_slider", "furnace_loader_six_bar")
CROSSOVER_SIZES = (100, 300, 1_000, 3_000, 10_000, 100_000)


def crossover(repeat: int = 5) -> list[dict]:
    """Where the compiled path pays (`fast.threshold`): per model, the full analysis of N angles by
    the numpy path (`exact`) and by the compiled kernel already loaded (`fast.analyze_fast`), CPU
    s minimum of `repeat` calls or as many as fill 0.2 s, after a warm-up, at CROSSOVER_SIZES; the kernel's load from the
    disk cache in a fresh process (CPU s of `fast.kernel(mech, "full")` after `import kinetostat`:
    numba's import included), minimum of 3; the smallest size from which the loaded kernel is the
    faster at every larger size, and the positions from which a call that loads the kernel repays it (load / the saving per
    angle at the largest size)."""
    import subprocess
    import sys
    out = []
    for name in CROSSOVER_MODELS:
        mech = kinetostat.load(name)
        fast.kernel(mech, "full")
        sizes = []
        for n in CROSSOVER_SIZES:
            phi = crank_angles(None, n)
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                t_np, _ = timed_runs(lambda: exact(mech, phi), repeat, 0.2)
                t_c, _ = timed_runs(lambda: fast.analyze_fast(mech, phi), repeat, 0.2)
            sizes.append(dict(angles=n, numpy=t_np.cpu_min, compiled=t_c.cpu_min))
        probe = ("import time, kinetostat; from kinetostat import fast; m = kinetostat.load(%r); "
                 "t = time.process_time(); fast.kernel(m, 'full'); print(time.process_time() - t)" % name)
        load = min(float(subprocess.run([sys.executable, "-c", probe], check=True, capture_output=True,
                                        text=True).stdout) for _ in range(3))
        big = sizes[-1]
        saving = (big["numpy"] - big["compiled"]) / big["angles"]
        faster = [r["compiled"] < r["numpy"] for r in sizes]
        warm = next((r["angles"] for n, r in enumerate(sizes) if all(faster[n:])), None)
        out.append(dict(model=name, sizes=sizes, load=load, warm=warm, cold=load / saving if saving > 0 else math.inf))
        print(f"crossover {name}: load {load:.3f} s, the loaded kernel the faster from {warm} angles, a loading call "
              f"repaid from {out[-1]['cold']:.3g}", flush=True)
    return out


def crossover_lines(rows: list[dict]) -> list[str]:
    """The report's section on where the compiled path pays (`crossover`)."""
    head = " | ".join(f"{n:,}" for n in CROSSOVER_SIZES)
    lines = ["## Where the compiled path pays (`fast.FAST_MIN`, `fast.FAST_COLD`)", "",
             "`kinetostat.analyze` of N angles: the numpy path (`exact`) against the compiled kernel already "
             "loaded in the process (`fast.analyze_fast`), CPU ms (minimum of at least 5 calls, as many as fill 0.2 s, after a warm-up); the "
             "kernel's load from the disk cache in a fresh process (`fast.kernel`, numba's import included; "
             "minimum of 3); the smallest N here from which the loaded kernel is the faster at every larger N; and the N from which a "
             "call that must load the kernel repays the load (load / the saving per angle at "
             f"{CROSSOVER_SIZES[-1]:,} angles). `analyze` takes the compiled path from `FAST_MIN` = "
             f"{fast.FAST_MIN:,} angles where the process holds the kernel, from `FAST_COLD` = {fast.FAST_COLD:,} "
             "where the call would load it; a sweep decides once for all its positions.", "",
             f"| model | path | {head} |", "|---|---|" + "---|" * len(CROSSOVER_SIZES)]
    for r in rows:
        for path in ("numpy", "compiled"):
            lines.append(f"| {r['model']} | {path} | " + " | ".join(f"{x[path] * 1e3:.3g}" for x in r["sizes"]) + " |")
    lines += ["", "| model | kernel load, s CPU | the loaded kernel the faster from, angles | a loading call repaid from, angles |",
              "|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['model']} | {r['load']:.3f} | {r['warm'] if r['warm'] is not None else '-'} | {r['cold']:.3g} |")
    return lines


def _nbytes(obj, seen: set | None = None) -> int:
    """Memory held by the arrays of a result object (a dataclass or a dict of arrays) and the
    result objects inside it, bytes."""
    seen = set() if seen is None else seen
    total = 0
    items = obj.items() if isinstance(obj, dict) else ((f.name, getattr(obj, f.name)) for f in dataclasses.fields(obj))
    for _, v in items:
        if isinstance(v, np.ndarray):
            base = v if v.base is None else v.base
            if id(base) not in seen:
                seen.add(id(base))
                total += base.nbytes
        elif dataclasses.is_dataclass(v) and not isinstance(v, kinetostat.Mechanism):
            total += _nbytes(v, seen)
    return total


LARGE = 10**6           # the large batch of the kernel comparison, angles


def fast_path_rows(models: list[Path], fast: Callable[[kinetostat.Mechanism, int], object], label: str,
                   flops_per_angle: Callable[[kinetostat.Mechanism], int] | None = None,
                   sizes: tuple[int, ...] = (ANGLES, LARGE), repeat: int = 3) -> list[dict]:
    """The hook for a route of the solver: `fast(mech, N)` analyses N crank angles of `mech` and
    returns its result (a dataclass or a dict of arrays); each model and size gives a row with
    the seconds per angle (wall: median of `repeat` calls after one warm-up, the previous result
    released; CPU: minimum and median), the result's bytes per angle, the flops per angle when `flops_per_angle` is
    given (e.g. `kernels.count_flops` of the route's per-angle body) and the machine's limit
    for them (bytes only without flops)."""
    from .kernels import machine_limit
    rows = []
    for path in models:
        mech = kinetostat.load(path)
        flops = flops_per_angle(mech) if flops_per_angle is not None else None
        for n in sizes:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                t, res = timed_runs(lambda: fast(mech, n), repeat)
            size = _nbytes(res) / n
            del res
            rows.append(dict(model=path.stem, route=label, angles=n, seconds_per_angle=t.wall_median / n,
                             cpu_min_per_angle=t.cpu_min / n, cpu_median_per_angle=t.cpu_median / n,
                             bytes_per_angle=size, flops_per_angle=flops,
                             limit=machine_limit(flops or 0.0, size)))
    return rows


def _analyze(mech: kinetostat.Mechanism, n: int) -> kinetostat.Analysis:
    """Today's solver on n crank angles spread over the cycle (the fixed cost included)."""
    return kinetostat.analyze(mech, phi_deg=np.linspace(0.0, 360.0, n, endpoint=False))


def kernel_study(models: list[Path], quick: bool, extra_routes: tuple = (),
                 sizes: tuple[int, ...] = (ANGLES, LARGE)) -> dict:
    """The solver (by `fast_path_rows`, at `sizes` angles), MuJoCo's and Pinocchio's kernels
    (360 angles) per model, and the machine's rates, measured in one run. `extra_routes`:
    (fast, label, flops_per_angle or None) of further routes of the solver, e.g. a compiled
    fast path, each timed by `fast_path_rows` beside today's."""
    from .kernels import machine_rates, mujoco_kernel, pinocchio_kernel
    rates = machine_rates()
    repeat = 1 if quick else 5
    solver = fast_path_rows(models, _analyze, "kinetostat.analyze", sizes=sizes, repeat=repeat)
    extra = [r for fast, label, flops in extra_routes
             for r in fast_path_rows(models, fast, label, flops, sizes=sizes, repeat=repeat)]
    engines = []
    for path in models:
        scene = build_scene(kinetostat.load(path), steps=ANGLES)
        for kernel in (mujoco_kernel, pinocchio_kernel):
            k = kernel(scene, repeat=3 if quick else 11)
            engines.append(dict(model=path.stem, engine=k.engine, seconds_per_angle=k.seconds_per_angle,
                                overhead_per_angle=k.overhead_per_angle, note=k.note,
                                cpu_min=k.cpu_min_per_angle, cpu_median=k.cpu_median_per_angle))
    return dict(rates=rates, solver=solver, engines=engines, extra=extra, repeat=repeat,
                engine_repeat=3 if quick else 11)


SPEED_MODELS = ("chain_unit_four_bar", "furnace_loader_six_bar")
BEFORE = "f1f4d95"      # the commit whose compiled kernel (scalar) the speed study times beside today's


def _before_fast():
    """`kinetostat.fast` as it was at commit BEFORE (its scalar kernel), with the `groups` and
    `program` of that commit, from this checkout's git history, loaded as modules of the installed
    package (kinetostat._fast_before ...); None where git or the commit is absent."""
    import importlib.util
    import subprocess
    import sys
    module = None
    for name in ("groups", "program", "fast"):
        try:
            src = subprocess.run(["git", "-C", str(ROOT), "show", f"{BEFORE}:kinetostat/{name}.py"], check=True,
                                 capture_output=True, text=True).stdout
        except (OSError, subprocess.CalledProcessError):
            return None
        src = src.replace("from . import groups", "import kinetostat._groups_before as groups").replace(
            "from .program import", "from kinetostat._program_before import")
        spec = importlib.util.spec_from_loader(f"kinetostat._{name}_before", loader=None)
        module = importlib.util.module_from_spec(spec)
        module.__package__ = "kinetostat"
        sys.modules[spec.name] = module
        exec(compile(src, f"<kinetostat/{name}.py at {BEFORE}>", "exec"), module.__dict__)
    return module


def _timed(fn: Callable[[], object]) -> tuple[float, float]:
    """CPU time (this process, all threads) and wall time of one call of fn, s."""
    c, w = time.process_time(), time.perf_counter()
    fn()
    return time.process_time() - c, time.perf_counter() - w


def _compile_times(model: str, kinds: tuple[str, ...] = ("peaks", "full")) -> dict:
    """Fresh processes: the kernels of `model` compiled into an empty cache folder, then loaded
    from it by a second process; wall and CPU time of `fast.kernel` and its first call, s. The
    first process also inspects the peaks kernel it compiled (numba cannot inspect a cached one):
    the flops per angle of its vectorised loop and its packed and scalar instructions."""
    import json
    import os
    import subprocess
    import sys
    import tempfile
    script = ("import json, sys, time, numpy as np, kinetostat; from kinetostat import fast; "
              "from kinetostat_validation.kernels import count_flops_loop; "
              "m = kinetostat.load(sys.argv[1]); out = {}\n"
              "for kind in sys.argv[2:]:\n"
              "    c, w = time.process_time(), time.perf_counter()\n"
              "    fast._run([m], np.radians([0.0, 1.0]), kind, S=fast.buffer(m, 2))\n"
              "    out[kind] = [time.process_time() - c, time.perf_counter() - w]\n"
              "fn = fast.kernel(m, 'peaks')[0]\n"
              "if fn.stats.cache_misses:\n"
              "    out['flops'] = count_flops_loop(chr(10).join(fn.inspect_llvm().values()))\n"
              "    out['vector'] = fast.vector_report(fn)\n"
              "print(json.dumps(out))")
    times: dict = {}
    with tempfile.TemporaryDirectory(prefix="kinetostat-cache-") as folder:
        env = dict(os.environ, KINETOSTAT_CACHE=folder)
        for when in ("fresh", "cached"):
            out = json.loads(subprocess.run([sys.executable, "-c", script, model, *kinds], env=env, check=True,
                                            capture_output=True, text=True).stdout.splitlines()[-1])
            times.update({k: out.pop(k) for k in ("flops", "vector") if k in out})
            for kind, (cpu, wall) in out.items():
                times[f"{kind} {when}"] = {"cpu": cpu, "wall": wall}
    return times


def _mujoco_cycle(scene: Scene) -> tuple[float, float]:
    """MuJoCo's C loop over the scene's cycle once, timed by the program's own clocks: CPU and
    wall seconds per ANGLES angles."""
    from .kernels import mujoco_kernel
    k = mujoco_kernel(scene, repeat=1)
    return k.cpu_min_per_angle * ANGLES, k.seconds_per_angle * ANGLES


def speed_study(repeat: int = 5, N: int = 10**6, N_numpy: int = 10**5, N_full: int = 2 * 10**5) -> dict:
    """The compiled path against today's scalar kernel (commit BEFORE), the numpy path and
    MuJoCo's compiled kernels, on the four-bar and the six-link furnace loader (loads: springs),
    each route timed `repeat` times in interleaved rounds (every route once per round), in CPU
    time and wall time; the flops per angle of the peaks kernel's vectorised loop and the bytes
    the full kernel writes, against this machine's rates; compile and cache-load times in fresh
    processes; the CPU and its load."""
    from .kernels import cpu_info, machine_rates
    rates = machine_rates()
    info = {"before": cpu_info()}
    before = _before_fast()
    models, rows = {}, []
    for name in SPEED_MODELS:
        mech = kinetostat.load(name)
        phi = crank_angles(None, N)
        out = fast.buffer(mech, N_full)
        routes = {
            "numpy path (exact)": (N_numpy, lambda m=mech: exact(m, phi[:N_numpy])),
            "peaks, 1 thread": (N, lambda m=mech: fast.peaks([m], phi, threads=1)),
            "peaks, 2 threads": (N, lambda m=mech: fast.peaks([m], phi, threads=2)),
            "full, reused chunks of 16384 (chunks)": (N, lambda m=mech: [None for _ in fast.chunks(m, phi, threads=1)]),
            "full, one reused buffer (out=)": (N_full, lambda m=mech, o=out: fast.analyze_fast(m, phi[:N_full], threads=1, out=o)),
            "full, fresh memory (analyze)": (N_full, lambda m=mech: fast.analyze_fast(m, phi[:N_full], threads=1)),
        }
        if before is not None and not fast._has_loads(mech):       # the scalar kernel took no loads: numpy path then
            routes[f"scalar kernel of {BEFORE}, peaks, 1 thread"] = (N, lambda m=mech: before.peaks([m], phi, threads=1))
        scene = build_scene(mech, steps=ANGLES)
        mj: list[tuple[float, float]] = []
        routes["MuJoCo kernels (C loop, its own clocks)"] = (ANGLES, lambda s=scene: mj.append(_mujoco_cycle(s)))
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            for n, fn in routes.values():          # warm-up: compiled, loaded, memos filled
                fn()
            times = {label: [] for label in routes}
            for _ in range(repeat):                # interleaved rounds
                for label, (n, fn) in routes.items():
                    times[label].append(_timed(fn))
        times["MuJoCo kernels (C loop, its own clocks)"] = mj[1:]
        compiled = _compile_times(name)
        flops = compiled.pop("flops")
        written = fast.bytes_per_angle(mech)
        for label, (n, _) in routes.items():
            cpu = [c for c, _ in times[label]]
            wall = [w for _, w in times[label]]
            threads = 2 if "2 threads" in label else 1
            peaks_route = label.startswith("peaks")
            limit = (flops / rates.flops_per_second if peaks_route else
                     written / rates.bytes_per_second if label.startswith("full") else math.nan)
            rows.append(dict(model=name, route=label, angles=n, runs=len(cpu), threads=threads,
                             cpu_min=min(cpu) / n, cpu_median=statistics.median(cpu) / n,
                             wall_min=min(wall) / n, wall_median=statistics.median(wall) / n,
                             limit=limit, limit_kind="flops" if peaks_route else "bytes" if label.startswith("full") else ""))
            r = rows[-1]
            print(f"speed {name:24s} {label:44s} cpu {r['cpu_min'] * 1e9:8.1f} / {r['cpu_median'] * 1e9:8.1f} ns, "
                  f"wall {r['wall_min'] * 1e9:8.1f} / {r['wall_median'] * 1e9:8.1f} ns per angle", flush=True)
        models[name] = dict(flops=flops, written=written, buffer=fast._layout(mech).n_rows * 8,
                            vector=compiled.pop("vector"), compile=compiled)
        print(f"speed {name}: {flops:.0f} flops/angle, {written} B/angle written, {models[name]}", flush=True)
    info["after"] = cpu_info()
    return dict(rates=rates, rows=rows, models=models, info=info, repeat=repeat)


BOUND_MODELS = ("chain_unit_four_bar", "ice_crank_slider")


def _kernel_programs(model: str) -> dict[str, Program]:
    """The counted programs (`kernels.count_program`) of the kernels `fast.peaks` runs for
    `model` (the peaks kernel; the motion kernel first where it has loads), compiled by a fresh
    process into an empty cache folder (numba cannot inspect a kernel loaded from its cache)."""
    import json
    import subprocess
    import sys
    import tempfile
    script = ("import dataclasses, json, sys, numpy as np, kinetostat; from kinetostat import fast; "
              "from kinetostat_validation.kernels import count_program; m = kinetostat.load(sys.argv[1])\n"
              "fast.peaks([m], np.arange(64.0), threads=1)\n"
              "kinds = ('motion', 'peaks') if fast._has_loads(m) else ('peaks',)\n"
              "print(json.dumps({k: dataclasses.asdict(count_program(chr(10).join("
              "fast.kernel(m, k)[0].inspect_llvm().values()))) for k in kinds}))")
    with tempfile.TemporaryDirectory(prefix="kinetostat-cache-") as folder:
        out = subprocess.run([sys.executable, "-c", script, model], env=dict(os.environ, KINETOSTAT_CACHE=folder),
                             check=True, capture_output=True, text=True).stdout.splitlines()[-1]
    return {kind: Program(**counts) for kind, counts in json.loads(out).items()}


def bound_study(models: tuple[str, ...] = BOUND_MODELS, angles: int = 10**5, rounds: int = 3) -> dict:
    """Issue 40's honest bound: per model, the counted program of each kernel its peaks run
    (`_kernel_programs`) and that kernel's bound at this core's unit rates (`kernels.unit_rates`,
    measured in this run), and `fast.peaks` of `angles` angles on 1 thread, CPU time per angle
    (the minimum of `rounds` after a warm-up), against the sum of its kernels' bounds (they run
    one after the other; loads evaluated by numpy between them are not in any bound)."""
    from .kernels import bound, unit_rates
    load = os.getloadavg()
    rates = unit_rates()
    rows = []
    for name in models:
        mech = kinetostat.load(name)
        programs = _kernel_programs(name)
        phi = crank_angles(None, angles)
        run = lambda m=mech: fast.peaks([m], phi, threads=1)
        run()
        cpu = min(_timed(run)[0] for _ in range(rounds)) / angles
        bounds = {kind: bound(p, rates) for kind, p in programs.items()}
        total = sum(b.seconds for b in bounds.values())
        rows.append(dict(model=name, programs=programs, bounds=bounds, bound=total, cpu=cpu, ratio=cpu / total))
    return dict(rates=rates, rows=rows, angles=angles, rounds=rounds, load=(load, os.getloadavg()))


def bound_lines(study: dict) -> list[str]:
    """The report's section on each model's peaks kernels against their bound (`bound_study`)."""
    r, ns = study["rates"], lambda s: f"{s * 1e9:.1f}"
    lines = ["## The peaks kernels against their bound", "",
             f"This core, measured in this run ({r.note}): a division {ns(1 / r.div)} ns, a square root "
             f"{ns(1 / r.sqrt)} ns, an FMA {1e12 / r.fma:.0f} ps, an unfused multiply or add {1e12 / r.add_mul:.0f} ps "
             "per lane. A kernel's program is counted per angle in the LLVM IR of its vectorised loop over the "
             "angles (`kernels.count_program`; 'by zero': additions and multiplications with a literal zero and "
             "additions of such products, numba's promotion of a real operand to complex). Its bound is the larger "
             "of its port time (adds, multiplies, by zero at the unfused rate; FMAs at the FMA rate) and its "
             "divider time (divisions and square roots); a model's bound is the sum over the kernels its peaks "
             f"run (loads besides gravity are evaluated by numpy between them: in no bound). CPU: `fast.peaks`, 1 "
             f"thread, {study['angles']:,} angles, the minimum of {study['rounds']} rounds. Load average (1, 5, 15 "
             f"min) {' '.join(f'{x:.2f}' for x in study['load'][0])} before, "
             f"{' '.join(f'{x:.2f}' for x in study['load'][1])} after.", "",
             "| model | kernel | adds | multiplies | by zero | divisions | square roots | FMAs | others | flops | "
             "lanes | port ns | divider ns | bound ns | CPU ns/angle | CPU / bound |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for row in study["rows"]:
        for kind, p in row["programs"].items():
            b = row["bounds"][kind]
            last = kind == "peaks"
            lines.append(f"| {row['model']} | {kind} | {p.add:.0f} | {p.mul:.0f} | {p.by_zero:.0f} | {p.div:.0f} | "
                         f"{p.sqrt:.0f} | {p.fma:.0f} | {p.other:.0f} | {p.flops:.0f} | {p.width} | {ns(b.port)} | "
                         f"{ns(b.divider)} | {ns(b.seconds)} ({b.limit}) | " +
                         (f"{ns(row['cpu'])} | {row['ratio']:.2f} (bound {ns(row['bound'])}) |" if last else " | |"))
    return lines


#: `kinetostat report --jobs 2` before, measured on this machine, each in fresh processes: the
#: commit, its models, CPU s (user + sys, every process) and wall s of each run, the load average.
#: 4f33869: the 8 models of the session that set the target, by hand. 9e5daed: every model bundled
#: at that commit (before the figures' light axes and SVG), in its own checkout and virtual
#: environment on the quiet machine, by `_report_run` (3 runs, each into an empty folder).
MAIN_JOB_BEFORE = (
    dict(commit="4f33869", cpu=(20.8, 20.1), wall=(11.8, 11.4), load="0.9-1.3",
         models=("chain_unit_four_bar", "compressor", "furnace_loader_six_bar", "ice_crank_slider",
                 "opposed_twin", "rotating_slotted_link", "scotch_yoke", "slotted_link_shaper")),
    dict(commit="9e5daed", cpu=(21.05, 20.89, 20.62), wall=(11.13, 11.01, 10.73), load="1.4-1.7",
         models=("chain_unit_four_bar", "compressor", "furnace_loader_six_bar", "ice_crank_slider",
                 "opposed_twin", "rotating_slotted_link", "scotch_yoke", "slotted_link_shaper",
                 "triad_six_bar", "triad_slider")),
)


def _n_models() -> int:
    """How many models `kinetostat report` runs: every bundled one."""
    return len(kinetostat.examples.names())


def _child_run(args: list[str]) -> tuple[float, float, str]:
    """`args` run by this Python in a fresh process: (CPU s of it and every process it waited
    for, user + sys from getrusage of the waited-for children; wall s; its stdout)."""
    import resource
    import subprocess
    import sys
    r0, w0 = resource.getrusage(resource.RUSAGE_CHILDREN), time.perf_counter()
    out = subprocess.run([sys.executable, *args], check=True, capture_output=True, text=True).stdout
    w, r1 = time.perf_counter() - w0, resource.getrusage(resource.RUSAGE_CHILDREN)
    return r1.ru_utime - r0.ru_utime + r1.ru_stime - r0.ru_stime, w, out


def _command_run(*args: str) -> tuple[float, float]:
    """One `kinetostat ARGS` in a fresh process: (CPU s of the command and its workers; wall s)."""
    cpu, wall, _ = _child_run(["-m", "kinetostat", *args])
    return cpu, wall


def _report_run(folder: str, models: tuple[str, ...] = (), *options: str) -> tuple[float, float]:
    """One `kinetostat report --jobs 2` of `models` (default every bundled one) into `folder`, with
    `options`, in a fresh process: (CPU s of the command and its workers; wall s)."""
    return _command_run("report", *models, "--jobs", "2", "--no-progress", "--out", folder, *options)


def main_job(runs: int = 3) -> dict:
    """`kinetostat report` (--jobs 2, the default on 2 cores) in fresh processes, each into a new
    empty folder (every page drawn: a page is drawn every time): `runs` times every bundled model,
    and `runs` times the models of each MAIN_JOB_BEFORE entry. Returns {"all", "same"}: CPU and
    wall s of each run, the load before and after, the models."""
    import tempfile
    from .kernels import cpu_info
    n = _n_models()

    def measured(models: tuple[str, ...], times: int) -> dict:
        load, cpu, wall = [cpu_info()["load"]], [], []
        for _ in range(times):
            with tempfile.TemporaryDirectory(prefix="kinetostat-report-") as folder:
                c, w = _report_run(folder, models)
            cpu.append(c)
            wall.append(w)
            print(f"main job: kinetostat report, {len(models) or n} models: {c:.1f} s CPU, {w:.1f} s wall", flush=True)
        return dict(cpu=cpu, wall=wall, load=load + [cpu_info()["load"]], n=len(models) or n)

    every = measured((), runs)
    return dict(all=every, same=[measured(b["models"], runs) for b in MAIN_JOB_BEFORE])


def main_job_lines(mj: dict) -> list[str]:
    """The report's section on `kinetostat report` (`main_job`)."""
    row = lambda name, r: (f"| {name} | {r['n']} | {len(r['cpu'])} | {min(r['cpu']):.1f} / {statistics.median(r['cpu']):.1f} | "
                           f"{min(r['wall']):.1f} / {statistics.median(r['wall']):.1f} |")
    every = mj["all"]
    lines = ["## The main job: `kinetostat report` for every bundled model", "",
             "`kinetostat report --jobs 2` (per model: the solver, 5 engine routes, the 40-digit reference, "
             "plots, plans, the interactive page, HTML), in a fresh process per run, into an empty folder "
             "(a page is drawn every time); CPU = user + sys of the command and its two workers. Before: each "
             "commit below on its own models (no pages then), measured on this machine at the load average "
             f"given. After: this run; load average {every['load'][0]} before the first run and "
             f"{every['load'][1]} after.", "",
             "| the main job | models | runs | CPU s min / median | wall s min / median |", "|---|---|---|---|---|"]
    for b, r in zip(MAIN_JOB_BEFORE, mj["same"]):
        lines += [row(f"before ({b['commit']}, load {b['load']})", dict(b, n=len(b["models"]))),
                  row(f"after (this run), the models of {b['commit']}", r)]
    return lines + [row("after (this run), every bundled model", every)]


#: The drawing layer's budgets (issue 34), each a limit on what `drawing_budgets` measures: a page
#: of 361 frames over `kinetostat plans MODEL --at 30` (CPU, 1), `plans MODEL --at A` beyond
#: loading the model (CPU s), the main job with pages over --no-page (CPU, 1) and its wall time
#: (s, every bundled model), `variant TASK CODE` with its pack (CPU s), a page's size (bytes).
PAGE_OVER_PLANS, PLANS_CPU, PAGES_OVER_NO_PAGE, MAIN_JOB_WALL, VARIANT_CPU, PAGE_BYTES = 3.0, 0.3, 1.3, 15.0, 1.5, 300_000
#: The models of the page budget: the ICE and the largest bundled model (6 links, 7 pairs, a
#: class-III group: the most plans, and the largest page before issue 34, 827 kB).
PAGE_MODELS = ("ice_crank_slider", "triad_six_bar")
#: The angle of the plans budget, deg, and the variants timed (one code of each task).
PLANS_AT, VARIANTS = 30.0, (("1", "479"), ("2", "479"), ("3", "479"))
#: Run in a fresh process by `_plans_beyond_load`: the model loaded, then CPU s of `kinetostat
#: plans` on it (its first call: the plans' imports included) and of a second call, one a line.
_PLANS_CHILD = """
import sys, time, kinetostat
from kinetostat.cli import main
model, at, out = sys.argv[1:]
kinetostat.load(model)
for n in (1, 2):
    t = time.process_time()
    assert main(["-q", "plans", model, "--at", at, "--out", f"{out}/{n}"]) == 0
    print(time.process_time() - t)
"""


def _load_1min() -> float:
    """The machine's load average over the last minute (NaN where the system does not say)."""
    return os.getloadavg()[0] if hasattr(os, "getloadavg") else math.nan


def _budget(name: str, measured: float, limit: float, unit: str, cpu: float, wall: float, load: tuple) -> dict:
    """One row of `drawing_budgets`, printed as it is measured."""
    row = dict(name=name, measured=measured, limit=limit, unit=unit, cpu=cpu, wall=wall, load=load)
    print("budget: " + _budget_line(row)[2:-2].replace(" | ", "; "), flush=True)
    return row


def _plans_beyond_load(model: str, folder: Path) -> tuple[float, float, float]:
    """CPU s of `kinetostat plans MODEL --at PLANS_AT` in a process that has loaded the model
    already: its first call (the plans' imports included) and a second; and the process's wall s."""
    _, wall, out = _child_run(["-c", _PLANS_CHILD, model, f"{PLANS_AT:g}", str(folder)])
    first, second = map(float, out.split())
    return first, second, wall


def _installed_state() -> None:
    """The state a wheel's install leaves before the budgets are timed: kinetostat's and the
    harness's bytecode compiled (pip compiles a wheel's modules; an editable checkout run with
    PYTHONDONTWRITEBYTECODE would compile every module in every timed process), and the compiled
    kernels in their cache (one untimed `kinetostat page` of the smallest model)."""
    import compileall
    import kinetostat_validation
    for package in (kinetostat, kinetostat_validation):
        compileall.compile_dir(Path(package.__file__).parent, quiet=1)
    import tempfile
    with tempfile.TemporaryDirectory(prefix="kinetostat-warm-") as tmp:
        _command_run("page", "scotch_yoke", "--out", str(Path(tmp) / "page.html"), "-q")


def drawing_budgets(main_job: bool = True) -> list[dict]:
    """Every budget of the drawing layer (issue 34) measured in fresh processes, in one run, each
    with its CPU s (user + sys of the processes), wall s and the 1-minute load average before and
    after: (a) a page of 361 frames (`kinetostat page`) over `kinetostat plans MODEL --at 30` for
    PAGE_MODELS, CPU; (b) `plans MODEL --at 30` beyond loading the model, CPU s; (c) with
    `main_job`, `kinetostat report` of every bundled model (--jobs 2) into an empty folder with
    pages over the same into another with --no-page, CPU, and its wall s; (d) `variant TASK CODE`
    with its pack, CPU s, for VARIANTS; (e) each model's page.html of (c), bytes. Rows as
    `_budget` makes them, for `budget_lines`. Timed as installed (`_installed_state`)."""
    import tempfile
    _installed_state()
    rows = []
    with tempfile.TemporaryDirectory(prefix="kinetostat-budgets-") as tmp:
        tmp = Path(tmp)
        for model in PAGE_MODELS:
            load = _load_1min()
            page = _command_run("page", model, "--out", str(tmp / f"{model}.html"), "-q")
            plans = _command_run("plans", model, "--at", f"{PLANS_AT:g}", "--out", str(tmp / model), "-q")
            rows.append(_budget(f"(a) page of 361 frames / plans --at {PLANS_AT:g}, CPU, {model}",
                                page[0] / plans[0], PAGE_OVER_PLANS, "x", page[0], page[1], (load, _load_1min())))
            load = _load_1min()
            first, second, wall = _plans_beyond_load(model, tmp / f"{model}-loaded")
            rows.append(_budget(f"(b) plans --at {PLANS_AT:g} beyond loading the model, CPU, {model} (a second "
                                f"call in the same process: {second:.2f} s)", first, PLANS_CPU, "s", first, wall,
                                (load, _load_1min())))
        if main_job:
            load = _load_1min()
            drawn = _report_run(str(tmp / "pages"))
            none = _report_run(str(tmp / "no-page"), (), "--no-page")
            after = _load_1min()
            rows.append(_budget("(c) main job into an empty folder, pages / --no-page, CPU", drawn[0] / none[0],
                                PAGES_OVER_NO_PAGE, "x", drawn[0], drawn[1], (load, after)))
            rows.append(_budget(f"(c) main job into an empty folder with pages, wall, {_n_models()} models", drawn[1],
                                MAIN_JOB_WALL, "s", drawn[0], drawn[1], (load, after)))
            for page in sorted((tmp / "pages").glob("*/page.html")):
                rows.append(_budget(f"(e) page size, {page.parent.name}", page.stat().st_size / 1e3,
                                    PAGE_BYTES / 1e3, "kB", math.nan, math.nan, (after, after)))
        for task, code in VARIANTS:
            load = _load_1min()
            cpu, wall = _command_run("variant", task, code, "--out", str(tmp / f"task{task}_{code}"), "-q")
            rows.append(_budget(f"(d) variant {task} {code} with its pack, CPU", cpu, VARIANT_CPU, "s", cpu, wall,
                                (load, _load_1min())))
    return rows


def _budget_line(r: dict) -> str:
    """A row of `drawing_budgets` as a line of the table of `budget_lines`."""
    num = lambda x, f: "-" if math.isnan(x) else format(x, f)
    ratio = r["measured"] / r["limit"]
    return (f"| {r['name']} | {r['measured']:.3g} {r['unit']} | {r['limit']:g} {r['unit']} | {ratio:.2f} | "
            f"{'pass' if ratio <= 1 else '**FAIL**'} | {num(r['cpu'], '.2f')} | {num(r['wall'], '.2f')} | "
            f"{r['load'][0]:.2f} / {r['load'][1]:.2f} |")


def budget_lines(rows: list[dict]) -> list[str]:
    """The section "Drawing budgets" (`drawing_budgets`): one table, budget against measure."""
    return ["## Drawing budgets", "",
            "The drawing layer's budgets (issue 34), each measured in fresh processes in this run: CPU = user + sys "
            "of the command and every process it waited for (`resource.getrusage(RUSAGE_CHILDREN)`); ratio = "
            "measured / budget, pass where it is at most 1; load = the machine's 1-minute load average before / "
            "after the measure (a shared machine: read CPU time). Timed as a wheel's install runs: the modules' "
            "bytecode compiled and the compiled kernels in their cache (one untimed page drawn first). (a) `kinetostat page MODEL` (361 frames) over "
            f"`kinetostat plans MODEL --at {PLANS_AT:g}`, both with the interpreter's start and imports; (b) the "
            "plans command's CPU in a process that has loaded the model (its first call, with the plans' own "
            "imports); (c) `kinetostat report --jobs 2` of every bundled model into an empty folder, with pages "
            "and with `--no-page`; (d) `kinetostat variant TASK CODE` (its teacher's pack included); (e) each "
            "page.html of (c). Regenerate this section alone with "
            "`python -m kinetostat_validation.benchmark --drawing-budgets` (printed only).", "",
            "| budget | measured | limit | ratio | result | CPU s | wall s | load before / after |",
            "|---|---|---|---|---|---|---|---|"] + [_budget_line(r) for r in rows]


def speed_lines(sp: dict) -> list[str]:
    """The report's section on the compiled path (`speed_study`)."""
    info, rates = sp["info"], sp["rates"]
    ns = lambda s: f"{s * 1e9:,.1f}"
    lines = ["## The compiled path: peaks and full results", "",
             f"**Machine**: {info['before']['model']}, {info['before']['cores']} cores; vector flags in /proc/cpuinfo: "
             f"{info['before']['vector_flags']}; numba compiles for LLVM's `{info['before']['llvm_target']}`. "
             f"Load average (1, 5, 15 min) {info['before']['load']} before the study and {info['after']['load']} after "
             f"it: the machine was shared with other jobs, so CPU time (this process, all its threads) is the "
             f"figure to read, wall time beside it. One core does {rates.flops_per_second / 1e9:.3g} GFLOP/s and "
             f"memory takes {rates.bytes_per_second / 1e9:.3g} GB/s of writes ({rates.note}).", "",
             f"Each route ran {sp['repeat']} times in interleaved rounds (every route once per round) after a warm-up; "
             "per angle: minimum / median. A route's **limit** is its own: the flops per angle of the peaks kernel's "
             "vectorised loop (counted in its LLVM IR, lanes included) over the flop rate for 'peaks'; the bytes the "
             "full kernel writes per angle over the write bandwidth for 'full'. M/s per core = angles / CPU time "
             "(minimum). The scalar kernel is `kinetostat/fast.py` of commit "
             f"{BEFORE}, loaded from git history and run in this same process; MuJoCo's kernels are the C loop of "
             "`validation/kernels.py` (timed by its own clocks: CLOCK_PROCESS_CPUTIME_ID and CLOCK_MONOTONIC).", "",
             "| model | route | angles | CPU ns/angle min / median | wall ns/angle min / median | M/s per core (CPU) | "
             "M/s (wall) | limit ns/angle | CPU / limit |", "|---|---|---|---|---|---|---|---|---|"]
    for r in sp["rows"]:
        lim = "" if math.isnan(r["limit"]) else f"{ns(r['limit'])} ({r['limit_kind']})"
        ratio = "" if math.isnan(r["limit"]) else f"{r['cpu_min'] / r['limit']:.2g}"
        lines.append(f"| {r['model']} | {r['route']} | {r['angles']:,} | {ns(r['cpu_min'])} / {ns(r['cpu_median'])} | "
                     f"{ns(r['wall_min'])} / {ns(r['wall_median'])} | {1e-6 / r['cpu_min']:.3g} | "
                     f"{1e-6 / r['wall_min']:.3g} | {lim} | {ratio} |")
    lines += ["", "| model | flops/angle (peaks loop) | bytes written/angle (full) | buffer bytes/angle | packed (zmm + "
              "ymm + xmm) / scalar arithmetic instructions (peaks kernel) | compile, fresh process: peaks, full (CPU / wall s) | load from the cache: "
              "peaks, full (CPU / wall s) |", "|---|---|---|---|---|---|---|"]
    for name, m in sp["models"].items():
        c = m["compile"]
        v = m["vector"]
        cw = lambda k: f"{c[k]['cpu']:.2f} / {c[k]['wall']:.2f}"
        lines.append(f"| {name} | {m['flops']:.0f} | {m['written']} | {m['buffer']} | "
                     f"{v['packed_zmm'] + v['packed_ymm'] + v['packed_xmm']} ({v['packed_zmm']} + {v['packed_ymm']} + "
                     f"{v['packed_xmm']}) / {v['scalar']} | "
                     f"{cw('peaks fresh')}; {cw('full fresh')} | {cw('peaks cached')}; {cw('full cached')} |")
    return lines


def kernel_lines(study: dict) -> list[str]:
    """The report's section on the engines' compiled kernels and the machine's limit."""
    rates = study["rates"]
    eng = {(e["model"], e["engine"]): e for e in study["engines"]}
    notes = {e["engine"]: e["note"] for e in study["engines"]}
    us = lambda s: f"{s * 1e6:.3g}"
    lines = ["## Against the engines' compiled kernels and the machine's limit", "",
             f"Per angle, all measured in this run. **MuJoCo kernels**: a C program compiled with gcc against "
             f"the mujoco wheel's headers and library times the loop over {ANGLES} angles, zero Python "
             f"(state -> mj_kinematics, mj_comPos, mj_makeConstraint, mj_comVel, mj_rne, mj_applyFT, the "
             f"square solve of [S | J^T][tau; lambda], mj_rnePostConstraint; {notes['mujoco']}). "
             f"**Pinocchio kernels**: no Eigen headers ship with the pin wheel, so a Python loop calls the "
             f"bound C++ (computeJointJacobians, the loop closures' calc, getConstraintsJacobian, rnea, "
             f"numpy's solve, rnea again for the tree joints' forces; {notes['pinocchio']}); the loop's own "
             f"Python, measured by the same loop with stubs, is shown in brackets and is NOT subtracted. "
             f"Both give the exact routes' driving moment (tested). **Machine**: one core does "
             f"{rates.flops_per_second / 1e9:.3g} GFLOP/s, memory takes {rates.bytes_per_second / 1e9:.3g} GB/s "
             f"of writes ({rates.note}); the limit of a route is max(flops / flop rate, bytes of its result / "
             f"bandwidth), from the bytes alone where its flops are not counted: these rows are full results "
             f"(`kinetostat.analyze`: the numpy path at 360 angles, the compiled full kernel at "
             f"{LARGE:,}), whose limit is their bytes; the peaks path is set against its flops in the "
             f"next section.", "",
             "Per angle: CPU time (this process; MuJoCo's: its C program's CPU clock) minimum / median, and wall "
             "time (median); the ratios are of CPU minima. The solver's rows: "
             f"{study['repeat']} calls each; the engines' kernels: {study['engine_repeat']} runs.", "",
             "| model | route | angles | CPU per angle, us min / median | wall, us median | result, B/angle | "
             "flops/angle | machine limit, us | / MuJoCo kernel | / Pinocchio kernel | / machine limit |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    for model in dict.fromkeys(r["model"] for r in study["solver"]):
        mj, pn = eng[(model, "mujoco")], eng[(model, "pinocchio")]
        lines.append(f"| {model} | MuJoCo kernels (C loop) | {ANGLES} | {us(mj['cpu_min'])} / {us(mj['cpu_median'])} | "
                     f"{us(mj['seconds_per_angle'])} | | | | 1 | {mj['cpu_min'] / pn['cpu_min']:.2g} | |")
        lines.append(f"| {model} | Pinocchio kernels (Python loop [its own Python, wall]) | {ANGLES} | "
                     f"{us(pn['cpu_min'])} / {us(pn['cpu_median'])} | "
                     f"{us(pn['seconds_per_angle'])} [{us(pn['overhead_per_angle'])}] | | | | "
                     f"{pn['cpu_min'] / mj['cpu_min']:.2g} | 1 | |")
        for r in (r for r in study["solver"] + study["extra"] if r["model"] == model):
            flops = "-" if r["flops_per_angle"] is None else f"{r['flops_per_angle']:.0f}"
            lines.append(f"| {model} | {r['route']} | {r['angles']:,} | {us(r['cpu_min_per_angle'])} / "
                         f"{us(r['cpu_median_per_angle'])} | {us(r['seconds_per_angle'])} | "
                         f"{r['bytes_per_angle']:.0f} | {flops} | {r['limit'] * 1e6:.2g} | "
                         f"{r['cpu_min_per_angle'] / mj['cpu_min']:.2g} | "
                         f"{r['cpu_min_per_angle'] / pn['cpu_min']:.2g} | "
                         f"{r['cpu_min_per_angle'] / r['limit']:.3g} |")
    return lines


def kinematics_table(models: list[Path]) -> list[dict]:
    """Kinematics and full analysis of a 360-angle cycle, the analysis of one angle (the fixed
    cost of a call), and positions per second (10^5 angles)."""
    rows = []
    phi = np.radians(np.arange(360.0))
    batch = np.radians(np.random.default_rng(0).uniform(0, 360, 100_000))
    for path in models:
        mech = kinetostat.load(path)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            t_kin, _ = timed_runs(lambda: kinematics(mech, phi), 20)
            t_all, _ = timed_runs(lambda: kinetostat.analyze(mech, steps=360), 20, EXACT_SECONDS)
            t_one, _ = timed_runs(lambda: kinetostat.analyze(mech, steps=1), 20, EXACT_SECONDS)
            t_batch, _ = timed_runs(lambda: kinematics(mech, batch), 5)
        rows.append(dict(model=path.stem, kinematics_ms=t_kin.wall_median * 1e3, analysis_ms=t_all.wall_median * 1e3,
                         analysis_cpu_ms=t_all.cpu_min * 1e3, single_ms=t_one.wall_median * 1e3,
                         positions_per_s=len(batch) / t_batch.wall_median, positions_per_cpu_s=len(batch) / t_batch.cpu_min))
    return rows


def target_line(df, kin_rows: list[dict]) -> str:
    """The verdict on issue 6's target: the solver at least 50x faster than the fastest engine
    route of the same run, at an error no worse than 1e-10; with what bounds the ratio."""
    ratios = {}
    for model, g in df.groupby("model"):
        s = g[g.route == "kinetostat"].iloc[0]
        ratios[model] = (g[g.route != "kinetostat"].seconds.min() / s.seconds, s.error)
    met = [m for m, (r, e) in ratios.items() if r >= 50 and e <= 1e-10]
    fixed = [k["single_ms"] / k["analysis_ms"] for k in kin_rows]
    mj = df[df.route == "mujoco"].seconds * 1e6 / ANGLES
    worst = min(ratios.items(), key=lambda kv: kv[1][0])
    return (f"**Target** (solver >= 50x faster than the fastest engine route, error <= 1e-10): met on "
            f"{len(met)} of {len(ratios)} models; speed-ups {min(r for r, _ in ratios.values()):.0f}x .. "
            f"{max(r for r, _ in ratios.values()):.0f}x (slowest relative: {worst[0]}). At {ANGLES} angles "
            f"{min(fixed):.0%}-{max(fixed):.0%} of the solver's time is the fixed cost of a call (one angle "
            f"takes {min(k['single_ms'] for k in kin_rows):.2f}-{max(k['single_ms'] for k in kin_rows):.2f} ms: "
            f"numpy's per-operation overhead), while MuJoCo's exact route costs {min(mj):.0f}-{max(mj):.0f} us "
            f"per angle in this adapter.")


def _machine_line(before: dict, after: dict) -> str:
    return (f"**Machine**: {before['model']}, {before['cores']} cores; vector flags {before['vector_flags']}; "
            f"numba compiles for `{before['llvm_target']}`. Load average (1, 5, 15 min) {before['load']} at the start "
            f"of the run and {after['load']} at its end: the machine is shared, so read CPU time where it is given.")


def write_report(rows: list[dict], kin_rows: list[dict], thr: list[dict], kernels: dict, out: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import pandas as pd

    out.mkdir(parents=True, exist_ok=True)
    df = pd.DataFrame(rows)
    df.to_csv(out / "benchmark.csv", index=False)
    fig, ax = plt.subplots(figsize=(8.5, 6))
    markers = dict(zip(sorted(df.model.unique()), itertools.cycle("osD^v<>pPXh*")))
    colours = dict(zip(df.route.unique(), plt.rcParams["axes.prop_cycle"].by_key()["color"]))
    for (model, route), g in df.groupby(["model", "route"], sort=False):
        ax.scatter(g.seconds * 1e3, g.error.clip(lower=1e-17), marker=markers[model], color=colours[route],
                   s=36, alpha=0.85)
    for route, c in colours.items():
        ax.scatter([], [], color=c, label=route)
    for model, m in markers.items():
        ax.scatter([], [], color="grey", marker=m, label=model)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel(f"wall time of one cycle ({ANGLES} angles), ms (median of repeated runs)")
    ax.set_ylabel("worst peak-relative error vs 40-digit reference")
    ax.set_title("Run time against error, per route and setting")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7, ncol=2, loc="center right")
    fig.tight_layout()
    fig.savefig(out / "benchmark.png", dpi=120)
    plt.close(fig)

    lines = ["# Benchmark: run time against error", "",
             f"Every route runs the same full cycle ({ANGLES} crank angles) of each bundled model; time is the "
             f"median of repeated runs in one process (exact routes: at least 20 runs and {EXACT_SECONDS} s, "
             "simulations: 3 runs), error the "
             "worst peak-relative error over the driving moment and every reaction against the mpmath reference "
             "(`validation/reference.py`, 40 digits; pymunk: magnitudes). Regenerate with "
             "`python -m kinetostat_validation.benchmark`.", "", _machine_line(*kernels["machine"]), "",
             "![time against error](benchmark.png)", "",
             "## Solver against the fastest engine route (same run)", "", target_line(df, kin_rows), "",
             "| model | solver | its error | fastest engine route | its time | its error | speed-up |",
             "|---|---|---|---|---|---|---|"]
    for model, g in df.groupby("model"):
        s = g[g.route == "kinetostat"].iloc[0]
        e = g[g.route != "kinetostat"].sort_values("seconds").iloc[0]
        lines.append(f"| {model} | {s.seconds * 1e3:.3f} ms | {s.error:.1e} | {e.route} ({e.setting}) | "
                     f"{e.seconds * 1e3:.2f} ms | {e.error:.1e} | {e.seconds / s.seconds:.0f}x |")
    lines += ["", "## Every route and setting", "", "Exact routes: at least 20 runs and 1 s; simulations: 3 runs "
              "(a run takes up to seconds). CPU: this process, all its threads.", "",
              "| model | route | setting | runs | CPU, ms min / median | wall, ms min / median | error |",
              "|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['model']} | {r['route']} | {r['setting']} | {r['runs']} | {r['cpu_min'] * 1e3:.3f} / "
                     f"{r['cpu_median'] * 1e3:.3f} | {r['wall_min'] * 1e3:.3f} / {r['seconds'] * 1e3:.3f} | "
                     f"{r['error']:.2e} |")
    lines += ["", "## Solver: a 360-angle cycle, and positions per second", "",
              "Wall: median of at least 20 runs (kinematics of 10^5 angles: 5); CPU: minimum.", "",
              "| model | kinematics, ms wall | full analysis, ms CPU / wall | one angle, ms wall | "
              "positions/s (10^5 angles) CPU / wall |", "|---|---|---|---|---|"]
    for r in kin_rows:
        lines.append(f"| {r['model']} | {r['kinematics_ms']:.3f} | {r['analysis_cpu_ms']:.3f} / {r['analysis_ms']:.3f} | "
                     f"{r['single_ms']:.3f} | {r['positions_per_cpu_s']:.3g} / {r['positions_per_s']:.3g} |")
    lines += ["", "## Solver throughput on large batches (slotted-link shaper, full analysis)", "",
              f"The result holds every point, link and pair: {thr[-1]['bytes_per_angle'] / 1e3:.1f} kB per angle. "
              f"The compiled kernel is loaded first (`fast.kernel`) and a warm-up call of `fast.FAST_MIN` = "
              f"{fast.FAST_MIN:,} angles made, so the first call of a size pays for fresh memory from the operating system "
              "only; repeated calls (5, the previous result released) reuse it.", "",
              "| angles | first call, s wall | repeated, s CPU min / median | repeated, s wall min / median | "
              "angles/s (repeated, wall median) |", "|---|---|---|---|---|"]
    for r in thr:
        lines.append(f"| {r['angles']:,} | {r['first_seconds']:.3f} | {r['cpu_min']:.3f} / {r['cpu_median']:.3f} | "
                     f"{r['wall_min']:.3f} / {r['seconds']:.3f} | {r['per_second']:.3g} |")
    lines += [""] + kernel_lines(kernels) + [""] + speed_lines(kernels["speed"]) + [""] + bound_lines(kernels["bound"]) + [""] + crossover_lines(kernels["crossover"]) + [""] + main_job_lines(kernels["main_job"]) + [""] + budget_lines(kernels["budgets"])
    (out / "benchmark.md").write_text("\n".join(lines) + "\n", encoding="utf-8")


def tolerance_rate(samples: int = 10**5, steps: int = 360) -> dict:
    """A Monte Carlo tolerance study of the chain-unit four-bar (`samples` designs x `steps`
    angles, r and l toleranced) beside a plain sweep of as many designs, in this process, one
    after the other: positions (designs x angles) per second of CPU, i.e. per core, and the load."""
    out = dict(samples=samples, steps=steps, load_before=os.getloadavg())
    runs = (("tolerance", lambda: kinetostat.tolerance("chain_unit_four_bar", {"r": 1e-4, "l": 2e-4}, samples=samples,
                                                          steps=steps, seed=1)),
            ("sweep", lambda: kinetostat.sweep("chain_unit_four_bar", {"r": np.linspace(0.0799, 0.0801, samples)},
                                               steps=steps)))
    for name, run in runs:
        cpu, wall = time.process_time(), time.perf_counter()
        run()
        cpu, wall = time.process_time() - cpu, time.perf_counter() - wall
        out[name] = dict(cpu=cpu, wall=wall, per_core=samples * steps / cpu)
    out["load_after"] = os.getloadavg()
    return out


def tolerance_lines(r: dict) -> list[str]:
    return [f"{name}: {r['samples']:,} designs x {r['steps']} angles in {r[name]['wall']:.1f} s "
            f"({r[name]['cpu']:.1f} s CPU) = {r[name]['per_core']:.3g} positions/s per core"
            for name in ("tolerance", "sweep")] + [
        f"load average (1, 5, 15 min) before {r['load_before']}, after {r['load_after']}"]


def sensitivity_cost(models: tuple[str, ...] = ("chain_unit_four_bar", "ice_crank_slider"), angles: int = 10**5,
                     counts: tuple[int, ...] = (1, 2, 5), rounds: int = 3) -> list[dict]:
    """Issue 39's budget: the compiled sensitivities to p parameters (the first p of the model's
    [parameters], in order) against the plain compiled analysis (`fast.analyze_fast`) of the same
    `angles`, in one process: CPU time per angle, the minimum of `rounds` interleaved rounds,
    after a first call of each that loads or compiles its kernels (its time stated apart, and
    whether numba compiled them: its disk cache missed), against the budget (1 + 0.6 p)x."""
    from kinetostat import fast_sensitivity
    rows = []
    for model in models:
        mech = kinetostat.load(model)
        phi = crank_angles(None, angles)
        names = list(mech.parameters)
        runs = {0: lambda: fast.analyze_fast(mech, phi)}
        runs.update({p: (lambda p=p: kinetostat.sensitivity(mech, names[:p], phi_deg=phi, path="compiled"))
                     for p in counts})
        first = {p: _timed(run) for p, run in runs.items()}
        compiled = {p: any(k.stats.cache_misses for k in fast_sensitivity.kernels(mech, p)) for p in counts}
        load = os.getloadavg()
        best = dict.fromkeys(runs, math.inf)
        for _ in range(rounds):
            for p, run in runs.items():
                best[p] = min(best[p], _timed(run)[0])
        rows += [dict(model=model, p=p, params=names[:p], angles=angles, ns_per_angle=best[p] / angles * 1e9,
                      ratio=best[p] / best[0], budget=1 + 0.6 * p, first_cpu=first[p][0], first_wall=first[p][1],
                      compiled=compiled.get(p), load=(load, os.getloadavg())) for p in runs]
    return rows


def sensitivity_lines(rows: list[dict]) -> list[str]:
    out = ["| model | p (parameters) | CPU per angle, ns | x plain | budget | first call, s CPU / wall |",
           "|---|---|---|---|---|---|"]
    for r in rows:
        what = "plain analysis" if not r["p"] else f"{r['p']} ({', '.join(r['params'])})"
        first = f"{r['first_cpu']:.2f} / {r['first_wall']:.2f}" + (" (compiled)" if r["compiled"] else "")
        budget = f"{r['budget']:.1f}" if r["p"] else ""
        out.append(f"| {r['model']} | {what} | {r['ns_per_angle']:.0f} | {r['ratio']:.2f} | {budget} | {first} |")
    return out + [f"{r['angles']:,} angles; CPU: this process, all its threads; the minimum of interleaved rounds. Load "
                  f"average (1, 5, 15 min) {r['load'][0]} before the rounds, {r['load'][1]} after"
                  for r in rows if r["p"] == 0]


def main(argv: list[str] | None = None) -> None:
    ap = parser("benchmark", __doc__)
    ap.add_argument("--quick", action="store_true", help="fewer repeats and settings; print only")
    ap.add_argument("--drawing-budgets", action="store_true",
                    help="only the section 'Drawing budgets' (issue 34's budgets of the drawing layer); print only")
    ap.add_argument("--tolerance", metavar="N", type=int,
                    help="only a Monte Carlo tolerance study of N designs of the four-bar beside a sweep of as "
                         "many (positions per second per core); print only")
    ap.add_argument("--sensitivity", metavar="N", type=int,
                    help="only the compiled sensitivities' cost (p = 1, 2, 5) against the plain compiled analysis of "
                         "N angles of the four-bar and the ICE; print only")
    ap.add_argument("--bound", metavar="N", type=int,
                    help="only the peaks kernels' counted programs and bounds, and fast.peaks of N angles of the "
                         "four-bar and the ICE against them; print only")
    args = ap.parse_args(argv)
    if args.bound:
        print("\n".join(bound_lines(bound_study(angles=args.bound))))
        return
    if args.sensitivity:
        print("\n".join(sensitivity_lines(sensitivity_cost(angles=args.sensitivity))))
        return
    if args.tolerance:
        print("\n".join(tolerance_lines(tolerance_rate(args.tolerance))))
        return
    if args.drawing_budgets:
        print("\n".join(budget_lines(drawing_budgets())))
        return
    if not args.quick:
        require_plots(ap)
    from .kernels import cpu_info
    machine = cpu_info()
    models = [kinetostat.examples.path(name) for name in kinetostat.examples.names()]
    kin_rows = kinematics_table(models)
    for r in kin_rows:
        print(f"{r['model']:24s} kinematics {r['kinematics_ms']:.3f} ms, analysis {r['analysis_ms']:.3f} ms "
              f"(one angle {r['single_ms']:.3f} ms), "
              f"{r['positions_per_s']:.3g} positions/s")
    thr = throughput(kinetostat.load("slotted_link_shaper"))
    for r in thr:
        print(f"throughput: {r['angles']:>9,} angles in {r['seconds']:.3f} s (first call {r['first_seconds']:.3f} s) "
              f"= {r['per_second']:.3g} angles/s")
    kern = kernel_study(models, args.quick, extra_routes=(
        (lambda mech, N: exact(mech, crank_angles(None, N)), "numpy path (analyze below FAST_MIN)", None),))
    print("\n".join(kernel_lines(kern)))
    kern["speed"] = speed_study(repeat=3 if args.quick else 5)
    kern["crossover"] = crossover(repeat=3 if args.quick else 5)
    print("\n".join(crossover_lines(kern["crossover"])))
    print("\n".join(speed_lines(kern["speed"])))
    kern["bound"] = bound_study(models=tuple(n for n in kinetostat.examples.names()
                                             if fast.refusal(kinetostat.load(n)) is None))
    print("\n".join(bound_lines(kern["bound"])))
    rows = study(models, args.quick)
    if not args.quick:
        kern["main_job"] = main_job()
        kern["budgets"] = drawing_budgets()
        kern["machine"] = (machine, cpu_info())
        write_report(rows, kin_rows, thr, kern, args.out)
        print(f"wrote {args.out / 'benchmark.md'}")


if __name__ == "__main__":
    main()
