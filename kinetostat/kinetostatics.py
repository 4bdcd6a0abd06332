"""Reactions group by group (seed 000 sec. 6), the initial link (sec. 7), Zhukovsky's lever
(sec. 8) and friction losses (seed 003), in closed form for all crank angles at once.

Groups are taken from the last attached to the first. In each, the known loads on its two
links (applied, inertia, and the reactions carried back from groups already solved) are
balanced by the reactions of its three pairs; the reactions on the outer links are then
carried to those links with the sign reversed, as the texts do.

May use: numpy, model, structure, kinematics (its results), planar.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Callable

import numpy as np

from .kinematics import kinematics
from .planar import Basis, as_xy, as_z, cross_z, dot_z

if TYPE_CHECKING:
    from .kinematics import Kinematics
    from .model import Gear, Mechanism, Pair
    from .structure import AssurGroup

__all__ = ["Forces", "forces", "gear_force", "lever_moment", "friction_power"]


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


class _Statics:
    """Known wrenches per link about its local origin (complex forces), updated as groups are solved."""

    def __init__(self, mech: "Mechanism", kin: "Kinematics", F: np.ndarray, M: np.ndarray):
        self.kin, self.locals = kin, mech.points_z
        self.F, self.M = F.copy(), M.copy()
        N = len(kin.phi)
        self.R = np.zeros((N, len(mech.pairs)), complex)
        self.normal_force = np.zeros((N, len(mech.pairs)))     # P pairs: along n = i d
        self.m = np.zeros((N, len(mech.pairs)))

    def at(self, k: int, name: str) -> np.ndarray:
        return self.kin.origin_z[:, k] + self.locals[k][name] * self.kin.rot[:, k]

    def moment(self, k: int, X: np.ndarray) -> np.ndarray:
        """Moment about X of the known loads on link k."""
        return self.M[:, k] + cross_z(self.kin.origin_z[:, k] - X, self.F[:, k])

    def carry(self, k: int, R: np.ndarray, X: np.ndarray, m: np.ndarray | None = None) -> None:
        """Link k exerts force R through X (and couple m) on a solved group: by action and
        reaction it bears -R and -m. The frame's own balance is never asked for, so its loads
        are not kept."""
        if k:
            dM = cross_z(X - self.kin.origin_z[:, k], R)
            self.F[:, k] -= R
            self.M[:, k] -= dM if m is None else dM + m

    def normal(self, p: "Pair") -> np.ndarray:
        """World unit normal n = i d of P pair p's guide."""
        return 1j * complex(*p.direction) * self.kin.rot[:, p.links[0]]

    def revolute(self, p: "Pair", giver: int, R: np.ndarray) -> None:
        """Record the force R that `giver` exerts on the other link of pair p."""
        self.R[:, p.index] = R if giver == p.links[0] else -R

    def prismatic(self, p: "Pair", giver: int, N: np.ndarray, n: np.ndarray, m: np.ndarray,
                  X0: np.ndarray) -> np.ndarray:
        """Record the normal force f = N n (n = self.normal(p)) of `giver` whose moment about X0
        is m, and its moment about the slider point S; return f."""
        f = N * n
        S = self.at(p.links[1], p.point)
        m_S = m + cross_z(X0 - S, f)
        if giver == p.links[0]:
            self.R[:, p.index], self.normal_force[:, p.index], self.m[:, p.index] = f, N, m_S
        else:
            self.R[:, p.index], self.normal_force[:, p.index], self.m[:, p.index] = -f, -N, -m_S
        return f


def _rrr(st: _Statics, g: "AssurGroup") -> None:
    (pj, pin, pk), (j, k), (a, c) = g.pairs, g.links, g.known
    P, B, Q = st.at(j, pj.point), st.at(j, pin.point), st.at(k, pk.point)
    lj = abs(st.locals[j][pin.point] - st.locals[j][pj.point])
    lk = abs(st.locals[k][pin.point] - st.locals[k][pk.point])
    uj, uk = (B - P) / lj, (B - Q) / lk
    # tangential parts from the moments of each link about B, normal parts from the polygon
    nj, nk = 1j * uj * (st.moment(j, B) / lj), 1j * uk * (st.moment(k, B) / lk)
    aj, ak = Basis(uj, uk).solve(-(st.F[:, j] + st.F[:, k] + nj + nk))
    R_aj, R_ck = aj * uj + nj, ak * uk + nk
    st.revolute(pj, a, R_aj)
    st.revolute(pin, j, st.F[:, j] + R_aj)
    st.revolute(pk, c, R_ck)
    st.carry(a, R_aj, P)
    st.carry(c, R_ck, Q)


def _rrp(st: _Statics, g: "AssurGroup") -> None:
    (pj, pin, pk), (j, k), (a, b) = g.pairs, g.links, g.known
    P, B = st.at(j, pj.point), st.at(j, pin.point)
    lj = abs(st.locals[j][pin.point] - st.locals[j][pj.point])
    uj, n = (B - P) / lj, st.normal(pk)
    nj = 1j * uj * (st.moment(j, B) / lj)
    aj, N = Basis(uj, n).solve(-(st.F[:, j] + st.F[:, k] + nj))
    R_aj = aj * uj + nj
    m_bk = -st.moment(k, B)
    st.revolute(pj, a, R_aj)
    st.revolute(pin, j, st.F[:, j] + R_aj)
    f_bk = st.prismatic(pk, b, N, n, m_bk, B)
    st.carry(a, R_aj, P)
    st.carry(b, f_bk, B, m_bk)


def _rpr(st: _Statics, g: "AssurGroup") -> None:
    (pj, pin, pk), (j, k), (a, c) = g.pairs, g.links, g.known   # j slides on k's guide
    P, Q, n = st.at(j, pj.point), st.at(k, pk.point), st.normal(pin)
    mP = st.moment(j, P)
    # moment of the whole group about Q fixes the normal force of the slotted link on the block
    f_kj = st.prismatic(pin, k, (mP + st.moment(k, Q)) / cross_z(P - Q, n), n, -mP, P)
    R_aj, R_ck = -st.F[:, j] - f_kj, f_kj - st.F[:, k]
    st.revolute(pj, a, R_aj)
    st.revolute(pk, c, R_ck)
    st.carry(a, R_aj, P)
    st.carry(c, R_ck, Q)


def _prp(st: _Statics, g: "AssurGroup") -> None:
    (pj, pin, pk), (j, k), (a, c) = g.pairs, g.links, g.known
    B, na, nc = st.at(j, pin.point), st.normal(pj), st.normal(pk)
    Na, Nc = Basis(na, nc).solve(-(st.F[:, j] + st.F[:, k]))
    m_aj, m_ck = -st.moment(j, B), -st.moment(k, B)
    f_aj = st.prismatic(pj, a, Na, na, m_aj, B)
    st.revolute(pin, j, st.F[:, j] + f_aj)
    f_ck = st.prismatic(pk, c, Nc, nc, m_ck, B)
    st.carry(a, f_aj, B, m_aj)
    st.carry(c, f_ck, B, m_ck)


def _rpp(st: _Statics, g: "AssurGroup") -> None:
    (pj, pin, pk), (j, k), (a, c) = g.pairs, g.links, g.known
    P, n_in, nc = st.at(j, pj.point), st.normal(pin), st.normal(pk)
    # link k: F_k - f_kj + f_ck = 0 with both forces normal to their guides
    N1, Nc = Basis(n_in, -nc).solve(st.F[:, k])
    mj = st.moment(j, P)
    m_ck = -(mj + st.moment(k, P))
    f_kj = st.prismatic(pin, k, N1, n_in, -mj, P)
    f_ck = st.prismatic(pk, c, Nc, nc, m_ck, P)
    R_aj = -st.F[:, j] - f_kj
    st.revolute(pj, a, R_aj)
    st.carry(a, R_aj, P)
    st.carry(c, f_ck, P, m_ck)


_GROUP_SOLVERS: dict[str, Callable[[_Statics, "AssurGroup"], None]] = {
    "RRR": _rrr, "RRP": _rrp, "RPR": _rpr, "PRP": _prp, "RPP": _rpp}


def forces(mech: "Mechanism", kin: "Kinematics", F: np.ndarray, M: np.ndarray) -> Forces:
    """Reactions in every pair and the balancing load, from the known wrenches F (complex),
    M per link (applied + inertia, about each link's local origin). Call under
    np.errstate(divide="ignore", invalid="ignore"), as `analyze` does: at angles the kinematics
    marked singular the divisions give NaN, by design."""
    st = _Statics(mech, kin, F, M)
    for g in reversed(mech.structure.groups):
        _GROUP_SOLVERS[g.kind](st, g)
    dr = mech.drive
    M_bal = -st.moment(1, st.at(1, dr.pivot))
    F_bal = _gear_force_z(dr.gear, M_bal) if dr.kind == "machine" else np.zeros_like(M_bal, complex)
    st.revolute(mech.pair_between(0, 1), 0, -(st.F[:, 1] + F_bal))
    return Forces(as_xy(st.R), st.normal_force, st.m, M_bal, as_xy(F_bal))


def gear_force(gear: "Gear", M: np.ndarray) -> np.ndarray:
    """Force (N, 2) of the pinion on the crank's gear at the pitch point O + r_w e that applies
    the moment M (N,) about the crank axis (seed 000 sec. 7.1): it pushes on the tooth along the
    line of action at alpha_w to the tangent, the one that turns the crank the way M must:
    (r_w e) x F = sign(M) |F| r_b = M."""
    return as_xy(_gear_force_z(gear, np.asarray(M, dtype=float)))


def _gear_force_z(gear: "Gear", M: np.ndarray) -> np.ndarray:
    """`gear_force` as complex x + iy, (N,)."""
    e = complex(*gear.centre_direction)
    alpha = math.radians(gear.alpha_w_deg)
    return (np.abs(M) / gear.r_b) * (np.sign(M) * (math.cos(alpha) * 1j * e) - math.sin(alpha) * e)


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
