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
from dataclasses import dataclass, replace

import numpy as np

from ..analysis import Analysis
from ..errors import AssemblyError, SelfLockingWarning
from ..kinematics import Kinematics, kinematics

__all__ = ["CYCLE_STEPS", "Solution", "Positions", "solve", "positions", "grid"]

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


@dataclass(frozen=True)
class Solution:
    """The analyses one drawing is built from (`solve`): `cycle`, frictionless at the model's drive
    over the cycle grid, the design position and the angles drawn (those where `mech` assembles);
    `res` at the angles drawn in the mode they are drawn in; `other` there in the other friction
    mode (a model with [friction]), else None; `left_out`: the AssemblyError that left the angles
    where `mech` does not assemble out of `cycle` (None: none left out)."""
    mech: object
    cycle: Analysis
    res: Analysis
    other: Analysis | None
    left_out: AssemblyError | None = None

    def sub(self, phi_deg) -> "Solution":
        """The same with `res` and `other` at those of their angles `phi_deg` (deg), in that order
        (the parts of one command drawn at some of its angles); ValueError naming an angle not analysed."""
        idx = _index(self.res.phi_deg, phi_deg)
        if (idx < 0).any():
            raise ValueError(f"phi_deg: {np.asarray(phi_deg, float)[idx < 0][0]:g} deg is not an angle of {self.res}")
        return replace(self, res=self.res.take(idx), other=None if self.other is None else self.other.take(idx))

    def among(self, phi_deg) -> Analysis | None:
        """`cycle` at those of the angles `phi_deg` (deg) it holds, in their order (None: at none)."""
        idx = _index(self.cycle.phi_deg, phi_deg)
        idx = idx[idx >= 0]
        return self.cycle.take(idx) if len(idx) else None

    def on(self, phi_deg) -> Analysis:
        """`cycle` at the angles `phi_deg` (deg); `left_out` (an AssemblyError) at those where `mech`
        does not assemble, ValueError at an angle not analysed."""
        idx = _index(self.cycle.phi_deg, phi_deg)
        if (idx < 0).any():
            missing = np.asarray(phi_deg, float)[idx < 0]
            if self.left_out is not None and np.isin(np.round(missing, 9), self.left_out.phi_deg).all():
                raise AssemblyError(self.left_out.group, missing, self.left_out.why)
            raise ValueError(f"phi_deg: {missing[0]:g} deg is not an angle of {self.cycle}")
        return self.cycle.take(idx)


def _index(held: np.ndarray, phi_deg) -> np.ndarray:
    """The index in `held` of each angle of `phi_deg` (equal as floats), -1 where it is not held."""
    match = np.asarray(held, float)[None, :] == np.asarray(phi_deg, float).reshape(-1, 1)
    return np.where(match.any(axis=1), match.argmax(axis=1), -1)


def solve(mech, at=(), friction: str = "first", law=None, other: bool = True, also=()) -> Solution:
    """The one analysis of `mech` for drawings at the crank angles `at` (deg; module docstring):
    frictionless over the cycle grid, the design position, `at` and `also` (more angles of the
    cycle: a table over it; one `analyze`, and one more without the angles an AssemblyError
    names, `Solution.left_out`); at `at` with `friction` ("first" or "reactions")
    or `law` (`kinetostat.law_of_motion`) one more; a model with [friction] and `other`: the other
    mode at `at`, one more (no SelfLockingWarning from it). ValueError (AssemblyError) where `mech` assembles at none of the grid, or not at `at`."""
    from ..solve import analyze
    at = np.array(at, float, ndmin=1)
    angles = np.unique(np.concatenate([grid(CYCLE_STEPS), [360.0, float(getattr(mech.drive, "design_deg", 30.0))], at,
                                       np.asarray(also, float)]))
    try:
        cycle, left_out = analyze(mech, phi_deg=angles, friction="first"), None
    except AssemblyError as exc:              # where it does not assemble: no plans there
        keep = ~np.isin(np.round(angles, 9), exc.phi_deg)
        if not keep.any():
            raise
        cycle, left_out = analyze(mech, phi_deg=angles[keep], friction="first"), exc
    sol = Solution(mech, cycle, cycle, None, left_out)
    drawn = sol.on(at)
    res = drawn if friction == "first" and law is None else analyze(mech, phi_deg=at, friction=friction, law=law)
    rows = None
    if other and mech.friction is not None:   # the worksheet's friction rows: they state eta, no self-locking warned of
        flip = "reactions" if friction == "first" else "first"
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", SelfLockingWarning)
            rows = drawn if flip == "first" and law is None else analyze(mech, phi_deg=at, friction=flip, law=law)
    return Solution(mech, cycle, res, rows, left_out)
