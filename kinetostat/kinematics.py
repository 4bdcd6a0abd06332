"""Exact kinematics over arrays of crank angles (seed 002 sec. 1.2.2, computed instead of drawn).

Groups are solved in the order of attachment. Each group kind has one small function that
finds the positions in closed form and closes the velocity and acceleration plans with
`decompose`, exactly as the vector equations of the texts read, for all angles at once.
"""
from __future__ import annotations

import warnings
from dataclasses import dataclass
from typing import TYPE_CHECKING, Callable

import numpy as np

from .errors import AssemblyError, SingularPositionWarning, singular_message
from .planar import cross, decompose, rot90, rotate

if TYPE_CHECKING:
    from .model import Mechanism, Pair
    from .structure import AssurGroup

__all__ = ["Kinematics", "kinematics", "COND_WARN", "COND_MAX"]

#: Above this condition number of a group's plan a SingularPositionWarning names the angles.
#: Results keep about 16 - log10(cond) significant digits, so 1e3 still leaves ~13.
COND_WARN = 1e3
#: Above this the group is taken as singular (toggle / dead centre of the group): velocities,
#: accelerations and every force at those angles are set to NaN and the reason is recorded.
#: Fewer than 8 digits would be meaningful and forces exceed 1e8 times the loads' scale.
COND_MAX = 1e8


@dataclass(frozen=True)
class Kinematics:
    """Motion of every link at N crank angles; arrays lead with the angle axis.

    Link k's local point p is at `origin[:, k] + rotate(p, theta[:, k])` (m, world frame).
    """
    phi: np.ndarray        # (N,) crank angle from drive.reference in drive.sense, rad
    theta: np.ndarray      # (N, L) link angles, rad, about +z
    origin: np.ndarray     # (N, L, 2) position of each link's local origin, m
    v_origin: np.ndarray   # (N, L, 2) its velocity, m/s
    a_origin: np.ndarray   # (N, L, 2) its acceleration, m/s^2
    omega: np.ndarray      # (N, L) angular velocity about +z, rad/s
    eps: np.ndarray        # (N, L) angular acceleration about +z, rad/s^2
    v_slide: np.ndarray    # (N, n_pairs) velocity of slider relative to guide along the guide, m/s (0 for R)
    a_slide: np.ndarray    # (N, n_pairs) its rate in the guide's frame, m/s^2
    cond: np.ndarray       # (N, n_groups) condition number of each group's plan
    singular: np.ndarray   # (N,) bool: some group's cond > COND_MAX (velocities etc. are NaN)

    def point(self, k: int, p: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Position, velocity, acceleration (each (N, 2)) of local point p of link k."""
        r = rotate(np.asarray(p, float), self.theta[:, k])
        w, e = self.omega[:, k, None], self.eps[:, k, None]
        return (self.origin[:, k] + r, self.v_origin[:, k] + w * rot90(r),
                self.a_origin[:, k] - w**2 * r + e * rot90(r))


class _Plan:
    """Work arrays filled group by group (internal; the public result is `Kinematics`)."""

    def __init__(self, mech: "Mechanism", phi: np.ndarray):
        N, L = len(phi), mech.n_links
        self.mech, self.phi = mech, phi
        self.th, self.w, self.e = np.zeros((N, L)), np.zeros((N, L)), np.zeros((N, L))
        self.O, self.V, self.A = np.zeros((N, L, 2)), np.zeros((N, L, 2)), np.zeros((N, L, 2))
        self.vs, self.as_ = np.zeros((N, len(mech.pairs))), np.zeros((N, len(mech.pairs)))
        self.L = mech.size

    def local(self, k: int, name: str) -> np.ndarray:
        return np.asarray(self.mech.links[k].points[name], float)

    def point(self, k: int, name: str):
        r = rotate(self.local(k, name), self.th[:, k])
        w, e = self.w[:, k, None], self.e[:, k, None]
        return self.O[:, k] + r, self.V[:, k] + w * rot90(r), self.A[:, k] - w**2 * r + e * rot90(r)

    def at(self, k: int, X: np.ndarray):
        """Velocity and acceleration of the point of link k that is at world position X."""
        r = X - self.O[:, k]
        w, e = self.w[:, k, None], self.e[:, k, None]
        return self.V[:, k] + w * rot90(r), self.A[:, k] - w**2 * r + e * rot90(r)

    def set_link(self, k: int, th, X, x_local, w, V, e, A) -> None:
        """Fix link k from its angle and the world state of one of its points."""
        r = rotate(np.asarray(x_local, float), th)
        self.th[:, k], self.w[:, k], self.e[:, k] = th, w, e
        self.O[:, k] = X - r
        self.V[:, k] = V - w[:, None] * rot90(r)
        self.A[:, k] = A + w[:, None] ** 2 * r - e[:, None] * rot90(r)

    def length(self, k: int, a: str, b: str) -> float:
        return float(np.linalg.norm(self.local(k, a) - self.local(k, b)))

    def angle_from(self, k: int, a: str, b: str, A: np.ndarray, B: np.ndarray) -> np.ndarray:
        """Angle of link k whose points a, b are at world A, B."""
        d = self.local(k, b) - self.local(k, a)
        return np.arctan2(B[:, 1] - A[:, 1], B[:, 0] - A[:, 0]) - np.arctan2(d[1], d[0])

    # --- prismatic pair geometry: the guide line is fixed in both links (equal rotation)
    def turned(self, p: "Pair", k: int, th_other: np.ndarray) -> np.ndarray:
        """Angle of link k of P pair p from the angle of the pair's other link."""
        return th_other + p.alpha if k == p.links[1] else th_other - p.alpha

    def guide(self, p: "Pair", k: int, th_k: np.ndarray) -> np.ndarray:
        """World unit direction d of pair p's guide, given the angle of its link k."""
        th_guide = th_k if k == p.links[0] else th_k - p.alpha
        return rotate(np.asarray(p.direction), th_guide)

    def offset(self, p: "Pair", k: int, name: str) -> float:
        """Signed distance c = (X - G) x d of point `name` of link k from the guide line."""
        x = self.local(k, name)
        if k == p.links[0]:
            return float(cross(x - self.local(k, p.guide), np.asarray(p.direction)))
        return float(-(x - self.local(k, p.point))[1])

    @staticmethod
    def anchor(p: "Pair", k: int) -> str:
        """A point of link k that lies on the guide line (c = 0)."""
        return p.guide if k == p.links[0] else p.point

    def slide(self, p: "Pair", mover: int, v, a) -> None:
        """Record the motion of `mover` relative to the pair's other link along d."""
        s = 1.0 if mover == p.links[1] else -1.0
        self.vs[:, p.index], self.as_[:, p.index] = s * v, s * a

    def reachable(self, g: "AssurGroup", disc: np.ndarray, scale: float, why: str) -> np.ndarray:
        """sqrt of a discriminant; AssemblyError naming the angles where it is negative."""
        bad = disc < -1e-12 * scale
        if bad.any():
            raise AssemblyError(g.label, np.degrees(self.phi[bad]), why)
        return np.sqrt(np.maximum(disc, 0.0))


def _rrr(pl: _Plan, g: "AssurGroup") -> np.ndarray:
    (pj, pin, pk), (j, k), (a, c) = g.pairs, g.links, g.known
    P, VP, AP = pl.point(a, pj.point)
    Q, VQ, AQ = pl.point(c, pk.point)
    lj, lk = pl.length(j, pj.point, pin.point), pl.length(k, pk.point, pin.point)
    d = np.linalg.norm(Q - P, axis=-1)
    u = (Q - P) / d[:, None]
    along = (lj**2 - lk**2 + d**2) / (2 * d)
    h = pl.reachable(g, lj**2 - along**2, lj**2, f"|{pj.point}{pk.point}| outside [|l{j} - l{k}|, l{j} + l{k}]")
    B = P + along[:, None] * u + g.branch * h[:, None] * rot90(u)
    # v_B = v_P + w_j x PB = v_Q + w_k x QB ;  a_B = a_P - w_j^2 PB + e_j x PB = ...
    wj, wk, cond = decompose(VQ - VP, rot90(B - P), -rot90(B - Q), pl.L, pl.L)
    VB = VP + wj[:, None] * rot90(B - P)
    ej, ek, _ = decompose(AQ - wk[:, None] ** 2 * (B - Q) - AP + wj[:, None] ** 2 * (B - P),
                          rot90(B - P), -rot90(B - Q), pl.L, pl.L)
    AB = AP - wj[:, None] ** 2 * (B - P) + ej[:, None] * rot90(B - P)
    pl.set_link(j, pl.angle_from(j, pj.point, pin.point, P, B), B, pl.local(j, pin.point), wj, VB, ej, AB)
    pl.set_link(k, pl.angle_from(k, pk.point, pin.point, Q, B), B, pl.local(k, pin.point), wk, VB, ek, AB)
    return cond


def _rrp(pl: _Plan, g: "AssurGroup") -> np.ndarray:
    (pj, pin, pk), (j, k), (a, b) = g.pairs, g.links, g.known
    P, VP, AP = pl.point(a, pj.point)
    th_k = pl.turned(pk, k, pl.th[:, b])
    d = pl.guide(pk, k, th_k)
    K, _, _ = pl.point(b, pl.anchor(pk, b))
    lj, cB = pl.length(j, pj.point, pin.point), pl.offset(pk, k, pin.point)
    w = K - cB * rot90(d) - P                        # B = K + t d - cB n lies on a circle about P
    wd = np.sum(w * d, axis=-1)
    root = pl.reachable(g, wd**2 - np.sum(w * w, axis=-1) + lj**2, lj**2,
                        f"the guide line is farther than l{j} from {pj.point}")
    B = K + (-wd + g.branch * root)[:, None] * d - cB * rot90(d)
    wb, eb = pl.w[:, b], pl.e[:, b]
    VBb, ABb = pl.at(b, B)
    # v_B = v_P + w_j x PB = v_B(b) + v_r d ; a_B = ... = a_B(b) + 2 w_b x v_r d + a_r d
    wj, vr, cond = decompose(VBb - VP, rot90(B - P), -d, pl.L, 1.0)
    VB = VP + wj[:, None] * rot90(B - P)
    ej, ar, _ = decompose(ABb + 2 * (wb * vr)[:, None] * rot90(d) - AP + wj[:, None] ** 2 * (B - P),
                          rot90(B - P), -d, pl.L, 1.0)
    AB = AP - wj[:, None] ** 2 * (B - P) + ej[:, None] * rot90(B - P)
    pl.set_link(j, pl.angle_from(j, pj.point, pin.point, P, B), B, pl.local(j, pin.point), wj, VB, ej, AB)
    pl.set_link(k, th_k, B, pl.local(k, pin.point), wb, VB, eb, AB)
    pl.slide(pk, k, vr, ar)
    return cond


def _rpr(pl: _Plan, g: "AssurGroup") -> np.ndarray:
    (pj, pin, pk), (j, k), (a, c) = g.pairs, g.links, g.known   # j slides on k's guide
    P, VP, AP = pl.point(a, pj.point)
    Q, VQ, AQ = pl.point(c, pk.point)
    e = pl.offset(pin, j, pj.point) - pl.offset(pin, k, pk.point)   # (P - Q) x d, constant
    PQ = P - Q
    rho = np.linalg.norm(PQ, axis=-1)
    pl.reachable(g, rho**2 - e**2, pl.L**2, f"{pj.point} comes closer than the guide offset to {pk.point}")
    s = np.arcsin(np.clip(e / rho, -1.0, 1.0))
    delta = np.arctan2(PQ[:, 1], PQ[:, 0]) + (s if g.branch > 0 else np.pi - s)
    d = np.stack([np.cos(delta), np.sin(delta)], axis=-1)
    th_k = delta - pin.alpha
    # v_P = v_Q + w_k x QP + v_r d ;  a_P = a_Q - w_k^2 QP + e_k x QP + 2 w_k x v_r d + a_r d
    wk, vr, cond = decompose(VP - VQ, rot90(PQ), d, pl.L, 1.0)
    ek, ar, _ = decompose(AP - AQ + wk[:, None] ** 2 * PQ - 2 * (wk * vr)[:, None] * rot90(d),
                          rot90(PQ), d, pl.L, 1.0)
    pl.set_link(k, th_k, Q, pl.local(k, pk.point), wk, VQ, ek, AQ)
    pl.set_link(j, th_k + pin.alpha, P, pl.local(j, pj.point), wk, VP, ek, AP)
    pl.slide(pin, j, vr, ar)
    return cond


def _prp(pl: _Plan, g: "AssurGroup") -> np.ndarray:
    (pj, pin, pk), (j, k), (a, c) = g.pairs, g.links, g.known
    th_j, th_k = pl.turned(pj, j, pl.th[:, a]), pl.turned(pk, k, pl.th[:, c])
    da, dc = pl.guide(pj, j, th_j), pl.guide(pk, k, th_k)
    Ka = pl.point(a, pl.anchor(pj, a))[0] - pl.offset(pj, j, pin.point) * rot90(da)
    Kc = pl.point(c, pl.anchor(pk, c))[0] - pl.offset(pk, k, pin.point) * rot90(dc)
    t, _, cond = decompose(Kc - Ka, da, -dc)        # B on both lines
    B = Ka + t[:, None] * da
    VBa, ABa = pl.at(a, B)
    VBc, ABc = pl.at(c, B)
    wa, wc = pl.w[:, a], pl.w[:, c]
    # v_B = v_B(a) + v1 d_a = v_B(c) + v2 d_c ; accelerations with the Coriolis terms
    v1, v2, _ = decompose(VBc - VBa, da, -dc)
    a1, a2, _ = decompose(ABc + 2 * (wc * v2)[:, None] * rot90(dc) - ABa - 2 * (wa * v1)[:, None] * rot90(da),
                          da, -dc)
    VB = VBa + v1[:, None] * da
    AB = ABa + 2 * (wa * v1)[:, None] * rot90(da) + a1[:, None] * da
    pl.set_link(j, th_j, B, pl.local(j, pin.point), wa, VB, pl.e[:, a], AB)
    pl.set_link(k, th_k, B, pl.local(k, pin.point), wc, VB, pl.e[:, c], AB)
    pl.slide(pj, j, v1, a1)
    pl.slide(pk, k, v2, a2)
    return cond


def _rpp(pl: _Plan, g: "AssurGroup") -> np.ndarray:
    (pj, pin, pk), (j, k), (a, c) = g.pairs, g.links, g.known
    P, VP, AP = pl.point(a, pj.point)
    th_k = pl.turned(pk, k, pl.th[:, c])
    th_j = pl.turned(pin, j, th_k)
    d_in, dc = pl.guide(pin, k, th_k), pl.guide(pk, k, th_k)
    rP = rotate(pl.local(j, pj.point), th_j)
    Oj = P - rP
    Kj = Oj + rotate(pl.local(j, pl.anchor(pin, j)), th_j)        # on the inner guide line
    Kc = pl.point(c, pl.anchor(pk, c))[0]                         # on the outer guide line
    rY = rotate(pl.local(k, pl.anchor(pin, k)), th_k)
    rX = rotate(pl.local(k, pl.anchor(pk, k)), th_k)
    # k's anchor Y = Kj + s d_in on the inner line, its anchor X = Y + rX - rY on the outer line
    _, s, cond = decompose(Kj + rX - rY - Kc, dc, -d_in)
    Ok = Kj + s[:, None] * d_in - rY
    wc, ec = pl.w[:, c], pl.e[:, c]
    VPc, APc = pl.at(c, P)
    # v_P = v_P(c) + v2 d_c + v1 d_in ; a_P = a_P(c) + 2 w x (v2 d_c + v1 d_in) + a2 d_c + a1 d_in
    v1, v2, _ = decompose(VP - VPc, d_in, dc)
    a1, a2, _ = decompose(AP - APc - 2 * wc[:, None] * (v1[:, None] * rot90(d_in) + v2[:, None] * rot90(dc)),
                          d_in, dc)
    pl.set_link(j, th_j, P, pl.local(j, pj.point), wc, VP, ec, AP)
    pl.set_link(k, th_k, P, rotate(P - Ok, -th_k), wc, VPc + v2[:, None] * dc,
                ec, APc + 2 * (wc * v2)[:, None] * rot90(dc) + a2[:, None] * dc)
    pl.slide(pin, j, v1, a1)
    pl.slide(pk, k, v2, a2)
    return cond


_GROUP_SOLVERS: dict[str, Callable[[_Plan, "AssurGroup"], np.ndarray]] = {
    "RRR": _rrr, "RRP": _rrp, "RPR": _rpr, "PRP": _prp, "RPP": _rpp}


def kinematics(mech: "Mechanism", phi: np.ndarray) -> Kinematics:
    """Positions, velocities and accelerations of every link at crank angles `phi` (rad, (N,)).

    Raises AssemblyError naming the angles where a group cannot be assembled; warns
    (SingularPositionWarning) where a group's plan is ill-conditioned and sets velocities and
    accelerations to NaN where its condition number exceeds COND_MAX.
    """
    phi = np.atleast_1d(np.asarray(phi, dtype=float))
    pl = _Plan(mech, phi)
    dr = mech.drive
    crank = mech.links[1]
    arm = np.subtract(crank.points[dr.point], crank.points[dr.pivot])
    th1 = np.arctan2(dr.reference[1], dr.reference[0]) + dr.sense * phi - np.arctan2(arm[1], arm[0])
    O = np.broadcast_to(np.asarray(mech.links[0].points[dr.pivot], float), (len(phi), 2))
    pl.set_link(1, th1, O, pl.local(1, dr.pivot), np.full_like(phi, dr.sense * dr.omega),
                np.zeros_like(O), np.full_like(phi, dr.sense * dr.eps), np.zeros_like(O))
    groups = mech.structure.groups
    cond = np.ones((len(phi), len(groups)))
    for n, g in enumerate(groups):
        cond[:, n] = _GROUP_SOLVERS[g.kind](pl, g)
    singular = _guard(mech, phi, cond)
    for arr in (pl.w, pl.e, pl.V, pl.A, pl.vs, pl.as_):
        arr[singular] = np.nan
    return Kinematics(phi, pl.th, pl.O, pl.V, pl.A, pl.w, pl.e, pl.vs, pl.as_, cond, singular)


def _guard(mech: "Mechanism", phi: np.ndarray, cond: np.ndarray) -> np.ndarray:
    cond = np.where(np.isnan(cond), np.inf, cond)
    for n, g in enumerate(mech.structure.groups):
        near = cond[:, n] > COND_WARN
        if near.any():
            warnings.warn(singular_message(g.label, np.degrees(phi[near]), cond[near, n],
                                           marked=bool((cond[near, n] > COND_MAX).any())),
                          SingularPositionWarning, stacklevel=3)
    return (cond > COND_MAX).any(axis=1)
