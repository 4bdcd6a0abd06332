"""The one analysis every plan, sheet, page and pack is drawn from (`solve`), and the positions
alone (`positions`) where a search needs angles no analysis holds.

`solve(mech, at)` analyses `mech` once, frictionless at the model's drive, over the union of
the angles the drawings read: the cycle grid of CYCLE_STEPS steps and 360 deg (the starting
position's scan, the paths of the centres of mass, the scale rule's 72 steps, `cycle_scales`'
5 deg), the design position and the angles `at`; the plans at `at` drawn with friction in the
reactions or at a true law of motion are one more analysis each, at `at` only, and so is the
other friction mode of a model with [friction] (its worksheet's friction rows). Every part is
a `.take` of these (`Solution.on`). The starting position's refinement between grid angles and
its 12 positions, and the other assembly branch, are positions only (`kinetostat.kinematics`).

May use: numpy, `kinetostat.solve`, `kinetostat.analysis`, `kinetostat.kinematics`, `kinetostat.errors`.
"""
from __future__ import annotations

import warnings
from dataclasses import dataclass
from typing import Callable

import numpy as np

from ..analysis import Analysis
from ..errors import AssemblyError, SelfLockingWarning
from ..kinematics import Kinematics, kinematics

__all__ = ["CYCLE_STEPS", "Solution", "Positions", "solve", "positions", "assembled", "grid"]

#: Steps of the cycle grid (0.5 deg): a multiple of the paths' PATH_STEPS, the scale rule's 72 and 5 deg.
CYCLE_STEPS = 720


def grid(steps: int) -> np.ndarray:
    """(steps,) crank angles k 360 / steps, deg, k = 0 .. steps - 1 (as `analyze(steps=steps)` takes them)."""
    return np.arange(steps) * 360.0 / steps


@dataclass(frozen=True)
class Positions:
    """The positions of `mech`'s links at the crank angles `phi_deg` (deg) by the kinematics alone
    (`kinetostat.kinematics`; no forces): what `Analysis.position` reads, for angles no analysis holds."""
    mech: object
    phi_deg: np.ndarray
    kin: Kinematics

    def position(self, name: str) -> np.ndarray:
        """(N, 2) world position of point `name`, m."""
        k = self.mech.point_owner(name)
        return self.kin.point(k, self.mech.links[k].points[name])[0]


def positions(mech, phi_deg) -> Positions:
    """`Positions` of `mech` at `phi_deg` (deg, (N,)); AssemblyError where it does not assemble."""
    phi = np.array(phi_deg, float, ndmin=1)
    return Positions(mech, phi, kinematics(mech, np.radians(phi)))


def assembled(solve_at: Callable[[np.ndarray], object], phi_deg) -> tuple[object | None, np.ndarray]:
    """(solve_at(the angles of `phi_deg` where the linkage assembles), those angles (N,) bool): one
    solve, and one more without the angles an AssemblyError named; (None, all False) where it
    does not assemble at the rest either (or the model is refused: a ValueError)."""
    phi = np.asarray(phi_deg, float)
    where = np.ones(len(phi), bool)
    for _ in range(2):
        try:
            return solve_at(phi[where]), where
        except AssemblyError as exc:
            where = where & ~np.isin(np.round(phi, 9), exc.phi_deg)
            if not where.any():
                break
        except (ValueError, KeyError):
            break
    return None, np.zeros(len(phi), bool)


@dataclass(frozen=True)
class Solution:
    """The analyses one drawing is built from (`solve`): `cycle`, frictionless at the model's drive
    over the cycle grid, the design position and the angles drawn (those where `mech` assembles);
    `res` at the angles drawn in the mode they are drawn in; `other` there in the other friction
    mode (a model with [friction]), else None."""
    mech: object
    cycle: Analysis
    res: Analysis
    other: Analysis | None

    def among(self, phi_deg) -> Analysis | None:
        """`cycle` at those of the angles `phi_deg` (deg) it holds, in their order (None: at none)."""
        idx = _index(self.cycle.phi_deg, phi_deg)
        idx = idx[idx >= 0]
        return self.cycle.take(idx) if len(idx) else None

    def on(self, phi_deg) -> Analysis:
        """`cycle` at the angles `phi_deg` (deg); AssemblyError naming those where `mech` does not assemble."""
        idx = _index(self.cycle.phi_deg, phi_deg)
        if (idx < 0).any():
            missing = np.asarray(phi_deg, float)[idx < 0]
            raise AssemblyError("of the linkage", missing, "no assembly on the cycle")
        return self.cycle.take(idx)


def _index(held: np.ndarray, phi_deg) -> np.ndarray:
    """The index in `held` of each angle of `phi_deg` (equal as floats), -1 where it is not held."""
    match = np.asarray(held, float)[None, :] == np.asarray(phi_deg, float).reshape(-1, 1)
    return np.where(match.any(axis=1), match.argmax(axis=1), -1)


def solve(mech, at=(), friction: str = "first", law=None, other: bool = True, also=()) -> Solution:
    """The one analysis of `mech` for drawings at the crank angles `at` (deg; module docstring):
    frictionless over the cycle grid, the design position, `at` and `also` (more angles of the
    cycle: a table over it; one `analyze`, and one more
    without the angles an AssemblyError names); at `at` with `friction` ("first" or "reactions")
    or `law` (`kinetostat.law_of_motion`) one more; a model with [friction] and `other`: the other
    mode at `at`, one more (no SelfLockingWarning from it). ValueError (AssemblyError) where `mech` assembles at none of the grid, or not at `at`."""
    from ..solve import analyze
    at = np.array(at, float, ndmin=1)
    angles = np.unique(np.concatenate([grid(CYCLE_STEPS), [360.0, float(getattr(mech.drive, "design_deg", 30.0))], at,
                                       np.asarray(also, float)]))
    cycle, where = assembled(lambda phi: analyze(mech, phi_deg=phi, friction="first"), angles)
    if cycle is None:
        analyze(mech, phi_deg=angles, friction="first")           # its error: where it does not assemble
    sol = Solution(mech, cycle, cycle, None)
    drawn = sol.on(at)
    res = drawn if friction == "first" and law is None else analyze(mech, phi_deg=at, friction=friction, law=law)
    rows = None
    if other and mech.friction is not None:   # the worksheet's friction rows: they state eta, no self-locking warned of
        flip = "reactions" if friction == "first" else "first"
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", SelfLockingWarning)
            rows = drawn if flip == "first" and law is None else analyze(mech, phi_deg=at, friction=flip, law=law)
    return Solution(mech, cycle, res, rows)
