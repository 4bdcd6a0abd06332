"""A plan cycle for the drawing's tests made by stacking one-angle plans: `plans.build` at each
angle at the cycle's fixed scales and positions, each kind's plans joined into one `PlanCycle`
(an element missing at an angle: NaN points there). A stand-in for the vectorised builders'
cycle (`plans.build_cycle`) where those are not there.

May use: kinetostat, numpy, the standard library.
"""
from __future__ import annotations

import warnings

import numpy as np

import kinetostat.plans as P
from kinetostat.plans.core import PlanCycle, Result, Segment


def stacked(mech, angles, step_deg: float = 30.0) -> dict[str, PlanCycle]:
    """Every plan kind of `mech` at `angles` (deg) as cycles, stacked from `plans.build`."""
    fixed = P.cycle_scales(mech, step_deg=step_deg)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        positions = P.fixed_positions(mech, fixed.base["mu_l"])
        built = [P.build(mech, at=float(a), fixed=fixed, positions=positions) for a in angles]
    return {kind: _stack([b[kind] for b in built]) for kind in built[0]}


def _stack(plans) -> PlanCycle:
    n = len(plans)
    names = list(dict.fromkeys(k for p in plans for k in p.points))
    points = {k: np.array([p.points.get(k, complex(np.nan, np.nan)) for p in plans]) for k in names}
    segs: dict[str, Segment] = {}
    for p in plans:
        for s in p.segments:
            segs.setdefault(s.name, s)
    values = {k: np.array([next((s.value for s in p.segments if s.name == k), np.nan) for p in plans]) for k in segs}
    paths = {}
    for k in dict.fromkeys(k for p in plans for k in p.paths):
        longest = max(len(p.paths.get(k, ())) for p in plans)
        paths[k] = np.array([list(p.paths.get(k, ())) + [complex(np.nan, np.nan)] * (longest - len(p.paths.get(k, ())))
                             for p in plans])
    first = plans[0]
    results = tuple(Result(r.symbol, np.array([next(x.value for x in p.results if x.symbol == r.symbol) for p in plans]),
                           r.unit, r.how) for r in first.results)
    acc = None
    if any(p.accuracy for p in plans):
        acc = (np.array([p.accuracy[0] if p.accuracy else np.inf for p in plans]),
               next(p.accuracy[1] for p in plans if p.accuracy))
    return PlanCycle(first.kind, tuple(p.title for p in plans), first.scale, np.array([p.phi_deg for p in plans]),
                     points, tuple(Segment(s.name, s.start, s.end, values[s.name], s.unit, s.kind, s.scale)
                                   for s in segs.values()),
                     paths, tuple(p.notes for p in plans), results, first.equation, acc)
