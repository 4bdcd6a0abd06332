"""The sources' published values of a model (its `[[published]]` tables), set beside the exact ones.

May use: numpy, the solver (solve, analysis, model). Never matplotlib, the harness or the engines.
"""
from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from typing import Callable

import numpy as np

from ..analysis import Analysis
from ..solve import analyze
from ..model import Mechanism, Published


@dataclass(frozen=True)
class PublishedCheck:
    """One published value beside kinetostat's exact value of the same quantity."""
    entry: Published
    exact: float        # in entry.unit
    phi_deg: float      # crank angle of the exact value (where the min or max lies), deg; NaN if none

    @property
    def by_angle(self) -> bool:
        """True when the value is an angle (reduce = "angle_of_max"), compared in deg."""
        return self.entry.reduce == "angle_of_max"

    @property
    def difference(self) -> float:
        """exact - published: relative to the published value, or in deg for an angle."""
        d = self.exact - self.entry.value
        return d if self.by_angle else d / self.entry.value if self.entry.value else d

    @property
    def error(self) -> float:
        """|difference|, what the tolerance bounds."""
        return abs(self.difference)

    @property
    def passed(self) -> bool:
        return bool(math.isfinite(self.error) and self.error <= self.entry.tolerance)


def _norm(v: np.ndarray) -> np.ndarray:
    return np.linalg.norm(v, axis=-1)


def _relative(f: Callable[[str], np.ndarray], p: Published) -> np.ndarray:
    return f(p.point) - (f(p.relative_to) if p.relative_to else 0.0)


#: quantity -> its magnitude at every angle of an Analysis, (N,)
MAGNITUDE: dict[str, Callable[[Analysis, Published], np.ndarray]] = {
    "velocity": lambda r, p: _norm(_relative(r.velocity, p)),
    "acceleration": lambda r, p: _norm(_relative(r.acceleration, p)),
    "omega": lambda r, p: np.abs(r.omega(p.link)),
    "eps": lambda r, p: np.abs(r.eps(p.link)),
    "inertia_force": lambda r, p: _norm(r.inertia(p.link).force),
    "inertia_moment": lambda r, p: np.abs(r.inertia(p.link).moment),
    "reaction": lambda r, p: _norm(r.reaction(*p.pair)),
    "balancing_moment": lambda r, p: np.abs(r.balancing_moment),
    "lever_moment": lambda r, p: np.abs(r.lever_moment),
    "balancing_force": lambda r, p: _norm(r.balancing_force),
}


def exact_value(res: Analysis, p: Published) -> tuple[float, float]:
    """(value in p.unit, crank angle it belongs to, deg) of `p` from the solver's answer at p.angles."""
    mag = MAGNITUDE[p.quantity](res, p)
    if p.reduce is None:
        return float(mag[0]), p.angles[0]
    if not np.any(np.isfinite(mag)):
        return math.nan, math.nan
    k = int(np.nanargmin(mag) if p.reduce == "min" else np.nanargmax(mag))
    at = p.angles[k]                  # as the model states it (res.phi_deg went through radians)
    return (at if p.reduce == "angle_of_max" else float(mag[k])), at


def published_rows(mech: Mechanism, at: Callable[[tuple[float, ...]], Analysis] | None = None) -> list[PublishedCheck]:
    """Every `[[published]]` value of `mech` beside the exact one (empty if it has none); `at(angles)`:
    the analysis at a published value's angles (deg), by the model's friction method (a report
    run's `ModelRun.at`, shared with the report's other parts); default: the solver run once per
    distinct set of angles."""
    if at is None:
        at = functools.cache(lambda angles: analyze(mech, phi_deg=list(angles)))
    return [PublishedCheck(p, *exact_value(at(p.angles), p)) for p in mech.published]
