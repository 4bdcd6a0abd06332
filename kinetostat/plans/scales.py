"""Scale factors of the plans (the texts' μ), chosen as the texts choose them or given by the user.

The rule (seed 002 sec. 1.2.2): a reference quantity is drawn at a recommended length and the
scale is its value over that length, rounded to a value an engineer can multiply by in the head.
Here a round scale is m x 10^k with the mantissa m one of ROUND_MANTISSAS = (1, 2, 2.5, 4, 5)
(the reduction and enlargement scales of GOST 2.302); of the round scales, the one whose drawn
reference length is nearest the recommended range (in ratio; ties go to the larger drawing) is
taken, then made coarser step by step while the plan would not fit the drawing area of an A3
sheet (FIT_MM).

The plan of positions follows the text's own words (sec. 1.2.2): "the crank's length OA is taken
(30..35 mm recommended); then mu_l = l_OA / OA", and its worked example takes OA = 36 mm for the
round mu_l = 0.001. So OA is chosen "about 30..35 mm", 30..36 mm (the example's own practice), and
mu_l follows from it, as round as that allows (`length_scale`): a GOST 2.302 value
(LENGTH_MANTISSAS, with the mantissas 1.5 and 7.5 of 1:15 and 1:75; mu_l = 0.0015 m/mm is a
drawing at 1:1.5) where one lands OA in the range, else two significant
digits (l_OA = 0.036 m: 0.001 m/mm, OA = 36 mm, as the example).

    mu_l: the crank O-A drawn 30..36 mm;
    mu_v: the crank pin's velocity p-a drawn 70..90 mm (seed 002: 85 mm, mu_v = 0.2);
    mu_a: the crank pin's acceleration pi-a drawn 70..90 mm (seed 002: 79.94 mm, mu_a = 100);
    mu_F: the largest force at that angle (a reaction, an applied load or an inertia force)
          drawn 100..200 mm: the texts give the force plan a sheet of its own (seed 002 draws
          its 9651 N gas force 193 mm long at mu_F = 50 N/mm).

May use: numpy, `.solution` (the one analysis; made here only where `choose_scales` is not given
the cycle of positions), `.core`.
"""
from __future__ import annotations

import math
from typing import Mapping

import numpy as np

from .core import Scale

__all__ = ["choose_scales", "solution_scales", "references", "round_scale", "length_scale", "coarser", "next_coarser", "check_given", "ScaleError", "SCALE_UNITS", "ROUND_MANTISSAS",
           "LENGTH_MANTISSAS", "REFERENCE_NAMES", "FIT_STEPS", "FIT_MM", "MAX_EXTENT_MM", "PLAN_OF"]

#: Unit of each scale, per millimetre drawn.
SCALE_UNITS = {"mu_l": "m/mm", "mu_v": "m/(s mm)", "mu_a": "m/(s^2 mm)", "mu_F": "N/mm"}
#: Mantissas of a round scale.
ROUND_MANTISSAS = (1.0, 2.0, 2.5, 4.0, 5.0)
#: Mantissas of the plan of positions' scale mu_l: ROUND_MANTISSAS and those of GOST 2.302's 1:15 and 1:75.
LENGTH_MANTISSAS = (1.0, 1.5, 2.0, 2.5, 4.0, 5.0, 7.5)
#: Recommended drawn length of each scale's reference quantity, mm.
TARGET_MM = {"mu_l": (30.0, 36.0), "mu_v": (70.0, 90.0), "mu_a": (70.0, 90.0), "mu_F": (100.0, 200.0)}
#: Crank angles over the cycle whose positions the plan of positions must fit (every 5 deg).
FIT_STEPS = 72
#: Drawing area of an A3 landscape sheet a plan must fit (width, height), mm: inside the frame,
#: above the title block.
FIT_MM = (380.0, 220.0)
#: The largest extent a plan may have on its sheet, mm: a given scale that draws a plan larger is
#: refused (a sheet 100 m long is a typing error, and its drawing would take unbounded memory).
MAX_EXTENT_MM = 1e5
#: The name of the quantity each scale draws at its recommended length (mu_F: the largest force,
#: no one name).
REFERENCE_NAMES = {"mu_l": "OA", "mu_v": "pa", "mu_a": "πa"}
#: The plan that each scale draws first (named when that scale is refused).
PLAN_OF = {"mu_l": "mechanism", "mu_v": "velocity", "mu_a": "acceleration", "mu_F": "forces"}


class ScaleError(ValueError):
    """A given scale that cannot be drawn: the message names the scale and the plan."""


def _round_candidates(value: float, mantissas: tuple[float, ...] = ROUND_MANTISSAS) -> list[float]:
    """Round scales around `value`, ascending."""
    k0 = math.floor(math.log10(value))
    return sorted(m * 10.0 ** k for k in range(k0 - 2, k0 + 3) for m in mantissas)


def round_scale(reference: float, lo_mm: float, hi_mm: float, extent: tuple[float, float] = (0.0, 0.0),
                fit_mm: tuple[float, float] = FIT_MM, mantissas: tuple[float, ...] = ROUND_MANTISSAS) -> float:
    """The round scale (SI per mm, a mantissa of `mantissas` x 10^k) that draws `reference` (SI)
    nearest [lo_mm, hi_mm] and the plan's extent (width, height, SI) within `fit_mm`."""
    if not (reference > 0 and math.isfinite(reference)):
        reference = max(extent)
        if not (reference > 0 and math.isfinite(reference)):
            return 1.0                # nothing to draw: any scale will do
    cands = _round_candidates(reference / hi_mm, mantissas)

    def miss(c: float) -> float:      # how far the drawn length lies outside [lo, hi], in log ratio
        length = reference / c
        return max(math.log(lo_mm / length), math.log(length / hi_mm), 0.0)

    best = min(cands, key=lambda c: (round(miss(c), 12), c))
    for c in cands[cands.index(best):]:
        if extent[0] / c <= fit_mm[0] and extent[1] / c <= fit_mm[1]:
            return c
    k = max(extent[0] / fit_mm[0], extent[1] / fit_mm[1])     # beyond the candidates: next round value
    return min(m * 10.0 ** math.ceil(math.log10(k) - math.log10(m)) for m in ROUND_MANTISSAS)


def length_scale(l_oa: float, lo_mm: float = TARGET_MM["mu_l"][0], hi_mm: float = TARGET_MM["mu_l"][1]) -> float:
    """mu_l (m/mm) of a crank `l_oa` m long drawn OA in [lo_mm, hi_mm] (seed 002 sec. 1.2.2: mu_l =
    l_OA / OA): of the scales in that range, a LENGTH_MANTISSAS value first, then the one of
    fewest significant digits; among equals, the one drawing OA nearest the range's middle.
    Two digits always land in it when hi/lo > 1.1 (their steps are at most 10 %)."""
    lo, hi = l_oa / hi_mm, l_oa / lo_mm                     # the scales that draw OA in range
    best = None
    for digits in (1, 2, 3):
        for e in {math.floor(math.log10(lo)), math.floor(math.log10(hi))}:       # the decades it spans
            exp = e - digits + 1
            for n in range(math.ceil(lo / 10.0 ** exp), math.floor(hi / 10.0 ** exp) + 1):
                c = float(f"{n}e{exp}")                                      # exact in decimal
                if not lo <= c <= hi:
                    continue
                m = c / 10.0 ** math.floor(math.log10(c))
                rank = (0 if any(math.isclose(m, g) for g in LENGTH_MANTISSAS) else digits,
                        abs(l_oa / c - (lo_mm + hi_mm) / 2))
                best = min(best or (rank, c), (rank, c))
        if best is not None and digits >= 2:          # GOST's 1.5, 2.5, 7.5 have two digits
            return best[1]
    return best[1] if best else l_oa / ((lo_mm + hi_mm) / 2)


def coarser(value: float, factor: float) -> float:
    """The smallest round scale at least `value` x `factor` (a drawing `factor` times too large
    made to fit)."""
    want = value * factor * (1 - 1e-12)
    k = math.floor(math.log10(want))
    return min(m * 10.0 ** e for e in (k, k + 1) for m in ROUND_MANTISSAS if m * 10.0 ** e >= want)


def next_coarser(value: float, mantissas: tuple[float, ...] = ROUND_MANTISSAS) -> float:
    """The next round scale above `value` (a mantissa of `mantissas` x 10^k): one step of the
    series, e.g. 0.25 -> 0.4, 0.0015 -> 0.002 (LENGTH_MANTISSAS: 0.0015 -> 0.002 -> 0.0025)."""
    k = math.floor(math.log10(value))
    return min(m * 10.0 ** e for e in (k, k + 1) for m in mantissas if m * 10.0 ** e > value * (1 + 1e-9))


def check_given(given: Mapping[str, float] | None) -> dict[str, float]:
    """The user's scales, checked: known keys, finite positive numbers (ValueError naming the key)."""
    out = {}
    for key, value in (given or {}).items():
        if key not in SCALE_UNITS:
            raise ValueError(f"unknown scale {key!r}: expected one of {', '.join(SCALE_UNITS)}")
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value) or value <= 0:
            raise ValueError(f"scale {key}: expected a positive number in {SCALE_UNITS[key]}, got {value!r}")
        out[key] = float(value)
    return out


def _extent(z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(width, height) of the finite points of z (N, M) at each angle, each (N,); 0 where none."""
    z = np.asarray(z)
    ok = np.isfinite(z)
    some = ok.any(axis=1)

    def ptp(v: np.ndarray) -> np.ndarray:
        hi = np.max(v, axis=1, where=ok, initial=-np.inf)
        return np.where(some, hi - np.min(v, axis=1, where=ok, initial=np.inf), 0.0)
    return ptp(z.real), ptp(z.imag)


def _per_angle(mech, res) -> dict[str, np.ndarray]:
    """The quantity each scale draws at its recommended length (TARGET_MM), SI, (N,) at every
    angle of `res` (see `references`)."""
    d = mech.drive
    crank = mech.links[d.link].points
    n = len(res.phi_deg)
    forces = np.concatenate([np.hypot(*np.moveaxis(a, -1, 0)).reshape(n, -1)
                             for a in (res.forces.R, res.F_applied, res.F_i)], axis=1)
    return {"mu_l": np.full(n, math.dist(crank[d.pivot], crank[d.point])),
            "mu_v": np.hypot(*res.velocity(d.point).T),
            "mu_a": np.hypot(*res.acceleration(d.point).T),
            "mu_F": np.nanmax(forces, axis=1, initial=0.0)}


def references(mech, res) -> dict[str, float]:
    """The quantity each scale draws at its recommended length (TARGET_MM), SI, the largest over
    the angles of `res`: mu_l the crank l_OA (m), mu_v |v_A| (m/s), mu_a |a_A| (m/s^2) of the
    crank pin, mu_F the largest force (a reaction, an applied load or an inertia force; N)."""
    return {k: float(np.max(v)) for k, v in _per_angle(mech, res).items()}


def choose_scales(mech, res, given: Mapping[str, float] | None = None,
                  cycle=None) -> dict[str, Scale]:
    """Scales mu_l, mu_v, mu_a, mu_F for the plans of `res` (an Analysis at one crank angle or
    more): the given ones as given, the others by the texts' rule (module docstring), each the
    coarsest it chooses at the angles of `res` that are not singular. `cycle`: an Analysis over
    the cycle whose positions the plan of positions must fit (default: the FIT_STEPS angles of
    `solution.solve(mech)`, positions only)."""
    given = check_given(given)
    if cycle is None:
        from .solution import grid, solve
        cycle = solve(mech, other=False).on(grid(FIT_STEPS))
    ok = ~np.asarray(res.singular, bool)
    if not ok.any():
        ok[:] = True
    ref = {k: v[ok] for k, v in _per_angle(mech, res).items()}
    n = int(ok.sum())
    pos = np.concatenate([cycle.kin.point_z(k, p)[0] for k, link in enumerate(mech.links) if k
                          for p in link.points.values()] + [np.array([complex(*p) for p in mech.links[0].points.values()])])
    names = mech.point_names
    vel = np.stack([np.zeros(n, complex)] + [_z(res.velocity(m)[ok]) for m in names], axis=1)
    acc = np.stack([np.zeros(n, complex)] + [_z(res.acceleration(m)[ok]) for m in names], axis=1)
    pos_extent = tuple(float(e[0]) for e in _extent(pos[None, :]))
    extent = {"mu_l": (np.full(n, pos_extent[0]), np.full(n, pos_extent[1])), "mu_v": _extent(vel),
              "mu_a": _extent(acc), "mu_F": (np.zeros(n), np.zeros(n))}
    out = {}
    for key, unit in SCALE_UNITS.items():
        reference, (width, height) = ref[key], extent[key]
        if key in given:
            value = given[key]
            size = max(float(np.max(reference)), float(np.max(width)), float(np.max(height))) / value
            if not size <= MAX_EXTENT_MM:
                raise ScaleError(f"{key}={value:g} {unit} would draw the {PLAN_OF[key]} plan "
                                 f"{f'{size:.3g} mm' if size < math.inf else 'beyond 1e308 mm'} across (at most {MAX_EXTENT_MM:g} mm); use a larger scale")
        elif key == "mu_l" and ref["mu_l"][0] > 0:
            value = length_scale(float(ref["mu_l"][0]))
            factor = max(pos_extent[0] / value / FIT_MM[0], pos_extent[1] / value / FIT_MM[1])
            if factor > 1:                   # the positions would not fit the sheet: coarser
                value = coarser(value, factor)
        else:                                # the coarsest of the angles' (a scalar rule, angle by angle)
            value = max(round_scale(float(r), *TARGET_MM[key], extent=(float(w), float(h)))
                        for r, w, h in set(zip(reference, width, height)))
        out[key] = Scale(key, value, unit)
    return out


def solution_scales(mech, solution, given: Mapping[str, float] | None = None) -> dict[str, Scale]:
    """`choose_scales` of the plans of `solution.res` (`solution.solve`), the plan of positions
    fitted over the FIT_STEPS angles of its cycle."""
    from .solution import grid
    return choose_scales(mech, solution.res, given, cycle=solution.on(grid(FIT_STEPS)))


def _z(xy: np.ndarray) -> np.ndarray:
    return xy[:, 0] + 1j * xy[:, 1]
