"""Benchmark: run time of the solver (and of every engine route) per bundled model.

    python -m validation.benchmark            # print the figures
    python -m validation.benchmark --engines  # also time the engine routes over the same cycle

Prints figures only; nothing is asserted (speed is measured, not tested).
"""
from __future__ import annotations

import argparse
import statistics
import time
import warnings
from pathlib import Path

import numpy as np

import kinetostat
from kinetostat.kinematics import kinematics

ROOT = Path(__file__).resolve().parents[1]


def median_seconds(fn, repeat: int = 15) -> float:
    """Median wall time of `fn()` over `repeat` runs after one warm-up, s."""
    fn()
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t)
    return statistics.median(times)


def solver_table(models: list[Path]) -> list[dict]:
    rows = []
    phi = np.radians(np.arange(360.0))
    batch = np.radians(np.random.default_rng(0).uniform(0, 360, 100_000))
    for path in models:
        mech = kinetostat.load(path)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            t_kin = median_seconds(lambda: kinematics(mech, phi))
            t_all = median_seconds(lambda: kinetostat.analyze(mech, steps=360))
            t_batch = median_seconds(lambda: kinematics(mech, batch), repeat=3)
        rows.append(dict(model=path.stem, kin_ms=t_kin * 1e3, kinetostatics_ms=t_all * 1e3,
                         positions_per_s=len(batch) / t_batch))
    return rows


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--engines", action="store_true", help="also time the engine routes")
    args = ap.parse_args(argv)
    models = sorted((ROOT / "models").glob("*.toml"))
    print(f"{'model':26s} {'kinematics 360':>15s} {'full analysis 360':>18s} {'kinematics, 1e5 angles':>24s}")
    for r in solver_table(models):
        print(f"{r['model']:26s} {r['kin_ms']:12.3f} ms {r['kinetostatics_ms']:15.3f} ms "
              f"{r['positions_per_s']:17.3g} pos/s")
    if args.engines:
        from validation.compare import ROUTES, available
        from validation.scene import build_scene
        print(f"\n{'model':26s} {'route':12s} {'build':>10s} {'cycle (360)':>12s}")
        for path in models:
            scene = build_scene(kinetostat.load(path), steps=360)
            for route, (_, run) in ROUTES.items():
                if available(route):
                    continue
                er = run(scene)
                print(f"{path.stem:26s} {route:12s} {er.build_seconds * 1e3:7.1f} ms {er.run_seconds * 1e3:9.1f} ms")


if __name__ == "__main__":
    main()
