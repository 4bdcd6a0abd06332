"""Reactions group by group (seed 000 sec. 6), the initial link (sec. 7), Zhukovsky's lever
(sec. 8) and friction losses (seed 003), in closed form for all crank angles at once.

Groups are taken from the last attached to the first. In each, the known loads on its two
links (applied, inertia, and the reactions carried back from groups already solved) are
balanced by the reactions of its three pairs; the reactions on the outer links are then
carried to those links with the sign reversed, as the texts do.

May use: numpy, program, groups, model, structure, kinematics (its results), planar.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from . import groups
from .kinematics import kinematics
from .planar import as_xy, as_z, dot_z
from .program import constants, run, statics_program

if TYPE_CHECKING:
    from .kinematics import Kinematics
    from .model import Gear, Mechanism

__all__ = ["Forces", "forces", "statics_environment", "packed", "gear_force", "lever_moment", "friction_power"]


@dataclass(frozen=True)
class Forces:
    """Reactions and balancing loads at N crank angles."""
    R: np.ndarray         # (N, n_pairs, 2) force of pair.links[0] on pair.links[1], N, world
    normal: np.ndarray    # (N, n_pairs) P pairs: that force along n = i d (d the guide direction,
                          #   in the guide's frame), N; 0 for R pairs
    m: np.ndarray         # (N, n_pairs) P pairs: moment of the reaction about the slider point, N m
                          #   (= x N; carries a pure couple where N = 0); 0 for R pairs
    M_bal: np.ndarray     # (N,) moment the drive applies to the crank about +z, N m
    F_bal: np.ndarray     # (N, 2) machine: balancing force at the pitch point, N (zeros for an engine)

    def __repr__(self) -> str:
        return f"Forces(positions={self.R.shape[0]}, pairs={self.R.shape[1]})"

    @property
    def x(self) -> np.ndarray:
        """(N, n_pairs) P pairs: the normal force acts on the line slider point + x d, m, as
        (x d) x (N n) = x N = m. NaN for R pairs, and where the normal force is 0 or only
        rounding (a dead centre): below 1e-12 of the largest reaction at that angle."""
        with np.errstate(divide="ignore", invalid="ignore"):
            x = self.m / self.normal
        largest = np.hypot(self.R[..., 0], self.R[..., 1]).max(axis=1, keepdims=True)
        x[np.abs(self.normal) <= 1e-12 * largest] = np.nan
        return x


def forces(mech: "Mechanism", kin: "Kinematics", F: np.ndarray, M: np.ndarray) -> Forces:
    """Reactions in every pair and the balancing load, from the known wrenches F (complex),
    M per link (applied + inertia, about each link's local origin). Call under
    np.errstate(divide="ignore", invalid="ignore"), as `analyze` does: at angles the kinematics
    marked singular the divisions give NaN, by design."""
    env = statics_environment(mech, kin, F, M)
    run(statics_program(mech), env)
    return packed(mech, env, len(kin.phi))


def statics_environment(mech: "Mechanism", kin: "Kinematics", F: np.ndarray, M: np.ndarray) -> dict:
    """The environment the statics program runs in: the design's constants, the motion (rot<k>,
    O<k>) and the known wrenches (F<k>, M<k>) of every moving link."""
    env = dict(mech.memo(("constants", id(mech.points_z)), lambda: constants(mech)))
    for k in range(1, mech.n_links):
        env.update({f"rot{k}": kin.rot[:, k], f"O{k}": kin.origin_z[:, k], f"F{k}": F[:, k], f"M{k}": M[:, k]})
    return env


def packed(mech: "Mechanism", env: dict, N: int) -> Forces:
    """The statics program's outputs in `env` as Forces at N angles."""
    n = len(mech.pairs)
    R = np.empty((N, n), complex)
    normal, m = np.zeros((2, N, n))
    for p in mech.pairs:
        R[:, p.index] = env[f"R{p.index}"]
        if p.kind == "P":
            normal[:, p.index], m[:, p.index] = env[f"N{p.index}"], env[f"m{p.index}"]
    F_bal = np.empty(N, complex)
    F_bal[:] = env["F_bal"]
    return Forces(as_xy(R), normal, m, env["M_bal"], as_xy(F_bal))


def gear_force(gear: "Gear", M: np.ndarray) -> np.ndarray:
    """Force (N, 2) of the pinion on the crank's gear at the pitch point O + r_w e that applies
    the moment M (N,) about the crank axis (seed 000 sec. 7.1): it pushes on the tooth along the
    line of action at alpha_w to the tangent, the one that turns the crank the way M must:
    (r_w e) x F = sign(M) |F| r_b = M."""
    return as_xy(_gear_force_z(gear, np.asarray(M, dtype=float)))


def _gear_force_z(gear: "Gear", M: np.ndarray) -> np.ndarray:
    """`gear_force` as complex x + iy, (N,)."""
    return groups.gear_force(M, complex(*gear.centre_direction), math.radians(gear.alpha_w_deg), gear.r_b)


def lever_moment(mech: "Mechanism", kin: "Kinematics", F: np.ndarray, M: np.ndarray) -> np.ndarray:
    """Zhukovsky's rigid lever: the balancing moment from the velocity plan alone.

    Every applied and inertia load moved to its like point of the plan turned by 90 deg has a
    moment about the pole proportional to its virtual power per unit crank speed, F . v' (M w'
    for a couple), v' = dv/d(omega_1) the velocity plan drawn for omega_1 = 1; the lever's
    equilibrium is the vanishing of the total, so M_bal = -sum(F . v' + M w'). Velocities are
    linear in omega_1, so v' = v / omega_1 where the crank turns; at standstill (omega_1 = 0)
    v' comes from the plan at unit speed: the route never divides by zero.
    Reactions do no work and never enter: this route is independent of the group-by-group one.
    F (N, L) complex and M (N, L): all applied and inertia loads per link about its origin.
    """
    v, w = kin.v_z, kin.omega
    still = w[:, 1] == 0
    if still.any():                           # standstill: the plan at unit crank speed there
        unit = kinematics(mech, kin.phi[still], unit_speed=True)
        v, w = v.copy(), w.copy()
        v[still], w[still] = unit.v_z, unit.omega
    power = dot_z(F, v) + M * w
    moving = np.ones(mech.n_links)            # the sum over the moving links as one matrix product
    moving[0] = 0.0
    return -(power @ moving) / w[:, 1]


def friction_power(mech: "Mechanism", kin: "Kinematics", R: np.ndarray) -> np.ndarray:
    """Power lost in every pair (seed 003), W, (N, n_pairs): R f r |w_i - w_j| in a revolute
    pair, R f |v_rel| in a prismatic one, from the frictionless reactions. Zeros without friction."""
    fr = mech.friction
    if fr is None:
        return np.zeros(R.shape[:2])
    if "friction" not in mech._derived:
        mech._derived["friction"] = (
            *np.array([p.links for p in mech.pairs]).T, np.array([p.kind == "R" for p in mech.pairs]),
            np.array([(p.radius if p.radius is not None else fr.radius) if p.kind == "R" else 0.0 for p in mech.pairs]))
    i, j, revolute, r = mech._derived["friction"]
    speed = np.where(revolute, r * np.abs(kin.omega[:, i] - kin.omega[:, j]), np.abs(kin.v_slide))
    return np.abs(as_z(R)) * fr.f * speed
