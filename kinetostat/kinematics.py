"""Exact kinematics over arrays of crank angles (seed 002 sec. 1.2.2, computed instead of drawn).

Groups are solved in the order of attachment. Each group kind has one small function that
finds the positions in closed form and closes the velocity and acceleration plans with
`Basis.solve`, exactly as the vector equations of the texts read, for all angles at once.

The singular-position guard: near a dead centre or toggle of a group the answer itself is that
sensitive to its inputs, so where a group plan's condition number exceeds COND_CHECK the
accuracy is measured, not inferred from the condition number: the kinematics is solved again
with every input (each point of the linkage, the crank angle) moved by PERTURB_ULPS ulps, and
the change is the error estimate (`Kinematics.error`). Fewer than DIGITS_WARN digits left: a
SingularPositionWarning names the angles and the digits; fewer than DIGITS_MIN: NaN.

May use: planar, errors (model and structure for type hints only).
"""
from __future__ import annotations

import cmath
import math
import warnings
import zlib
from dataclasses import dataclass, fields, replace
from typing import TYPE_CHECKING, Callable

import numpy as np

from .errors import AssemblyError, SingularPositionWarning, singular_message
from .planar import Basis, as_xy, condition, cross_z, dot_z

if TYPE_CHECKING:
    from .model import Mechanism, Pair
    from .structure import AssurGroup

__all__ = ["Kinematics", "kinematics", "COND_CHECK", "COND_MAX", "DIGITS_WARN", "DIGITS_MIN",
           "kinematic_size", "kinematic_deviation", "group_scales", "solve_checked", "guard",
           "a_priori_error", "relative_change", "digits"]

#: Above this condition number of a group's plan the accuracy is measured by a second solve on
#: perturbed inputs. Below it the error is bounded by the measured law (reports/stability.md):
#: at most A_PRIORI cond^3, 2e-12 at COND_CHECK (more than 11 digits).
COND_CHECK = 10.0
#: The a-priori relative error at cond (used below COND_CHECK): the worst families measured, a
#: four-bar at its change point and a slotted link whose block passes its pivot, lose up to
#: 1.3e-15 cond^3 (a dyad's toggle or dead centre only ~3e-16 cond^2).
A_PRIORI = 2e-15
#: Above this condition number the group is taken as singular (toggle / dead centre of the
#: group) whatever the estimate says: the perturbation is no longer small against the distance
#: to the singular position. Velocities, accelerations and every force there are NaN.
COND_MAX = 1e5
#: Fewer significant digits than this (estimated) left: a SingularPositionWarning names the angles.
DIGITS_WARN = 10
#: Fewer than this: the values at that angle are set to NaN (`singular` True).
DIGITS_MIN = 6
#: Size of the input perturbation of the accuracy check, in units of the double-precision
#: rounding of each input; two solves with independent signs per input.
PERTURB_ULPS = 4
_EPS = np.finfo(float).eps
_TINY = np.finfo(float).tiny


@dataclass(frozen=True)
class Kinematics:
    """Motion of every link at N crank angles; arrays lead with the angle axis.

    Positions, velocities and accelerations of the link frames are complex (x + iy) inside the
    solver; `origin`, `v_origin`, `a_origin` and `point` give the public (..., 2) real views.
    Link k's local point p is at origin_z[:, k] + p rot[:, k] (m, world frame).
    """
    phi: np.ndarray        # (N,) crank angle from drive.reference in drive.sense, rad
    theta: np.ndarray      # (N, L) link angles, rad, about +z (modulo 2 pi: no common range)
    rot: np.ndarray        # (N, L) complex e^{i theta}
    origin_z: np.ndarray   # (N, L) complex position of each link's local origin, m
    v_z: np.ndarray        # (N, L) complex velocity of the local origin, m/s
    a_z: np.ndarray        # (N, L) complex acceleration of the local origin, m/s^2
    omega: np.ndarray      # (N, L) angular velocity about +z, rad/s
    eps: np.ndarray        # (N, L) angular acceleration about +z, rad/s^2
    v_slide: np.ndarray    # (N, n_pairs) velocity of slider relative to guide along the guide, m/s (0 for R)
    a_slide: np.ndarray    # (N, n_pairs) its rate in the guide's frame, m/s^2
    cond: np.ndarray       # (N, n_groups) condition number of each group's plan
    singular: np.ndarray   # (N,) bool: some group's cond > COND_MAX, or fewer than DIGITS_MIN
                           #   digits left (velocities, accelerations etc. are NaN)
    error: np.ndarray      # (N,) estimated relative error (see `kinematic_deviation`): measured
                           #   where cond > COND_CHECK, A_PRIORI cond^3 elsewhere; inf where singular

    def __repr__(self) -> str:
        N, L = self.theta.shape
        return f"Kinematics(positions={N}, links={L}, groups={self.cond.shape[1]}, singular={int(self.singular.sum())})"

    @property
    def digits(self) -> np.ndarray:
        """(N,) estimated significant digits left, -log10(error) within [0, 16]."""
        return digits(self.error)

    def take(self, idx: np.ndarray) -> "Kinematics":
        """The same motion at the angles `idx` only."""
        return Kinematics(*(getattr(self, f.name)[idx] for f in fields(self)))

    @property
    def origin(self) -> np.ndarray:
        """(N, L, 2) position of each link's local origin, m."""
        return as_xy(self.origin_z)

    @property
    def v_origin(self) -> np.ndarray:
        """(N, L, 2) velocity of each link's local origin, m/s."""
        return as_xy(self.v_z)

    @property
    def a_origin(self) -> np.ndarray:
        """(N, L, 2) acceleration of each link's local origin, m/s^2."""
        return as_xy(self.a_z)

    def position_z(self, k: int, p) -> np.ndarray:
        """Complex position (N,) of local point p of link k."""
        return self.origin_z[:, k] + complex(p[0], p[1]) * self.rot[:, k]

    def velocity_z(self, k: int, p) -> np.ndarray:
        """Complex velocity (N,) of local point p of link k."""
        return self.v_z[:, k] + 1j * self.omega[:, k] * (complex(p[0], p[1]) * self.rot[:, k])

    def point_z(self, k: int, p) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Complex position, velocity, acceleration (each (N,)) of local point p of link k."""
        r = complex(p[0], p[1]) * self.rot[:, k]
        w, e = self.omega[:, k], self.eps[:, k]
        return self.origin_z[:, k] + r, self.v_z[:, k] + 1j * w * r, self.a_z[:, k] + (1j * e - w**2) * r

    def point(self, k: int, p) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Position, velocity, acceleration (each (N, 2)) of local point p of link k."""
        return tuple(as_xy(z) for z in self.point_z(k, p))


class _Plan:
    """Work arrays filled group by group (internal; the public result is `Kinematics`)."""

    def __init__(self, mech: "Mechanism", phi: np.ndarray, locals_: list[dict[str, complex]]):
        N, L = len(phi), mech.n_links
        self.phi = phi
        self.th, self.w, self.e = np.zeros((3, N, L))            # the frame's column stays 0
        self.rot = np.ones((N, L), complex)
        self.O, self.V, self.A = np.zeros((3, N, L), complex)
        self.vs, self.as_ = np.zeros((2, N, len(mech.pairs)))
        self.L = 1.0          # the length scale of the group being solved (set by `_solve`)
        self.locals = locals_

    def local(self, k: int, name: str) -> complex:
        return self.locals[k][name]

    # The frame does not move: its points are constants with no velocity or acceleration.
    def position(self, k: int, name: str) -> np.ndarray | complex:
        return self.O[:, k] + self.local(k, name) * self.rot[:, k] if k else self.local(0, name)

    def point(self, k: int, name: str):
        if not k:
            return self.local(0, name), 0.0, 0.0
        r = self.local(k, name) * self.rot[:, k]
        w, e = self.w[:, k], self.e[:, k]
        return self.O[:, k] + r, self.V[:, k] + 1j * w * r, self.A[:, k] + (1j * e - w**2) * r

    def at(self, k: int, X: np.ndarray):
        """Velocity and acceleration of the point of link k that is at world position X."""
        if not k:
            return 0.0, 0.0
        r = X - self.O[:, k]
        w, e = self.w[:, k], self.e[:, k]
        return self.V[:, k] + 1j * w * r, self.A[:, k] + (1j * e - w**2) * r

    def coriolis(self, k: int, v: np.ndarray, d: np.ndarray) -> np.ndarray | float:
        """Coriolis acceleration 2 w_k x (v d) of a point sliding at v along d in link k."""
        return 2j * self.w[:, k] * v * d if k else 0.0

    def set_link(self, k: int, th, rot, X, x_local: complex | np.ndarray, w, V, e, A) -> None:
        """Fix link k from its angle th, rot = e^{i th}, and the world position, velocity and
        acceleration X, V, A of its local point x_local (a constant, or (N,) for a point
        moving in the link)."""
        self.th[:, k], self.rot[:, k], self.w[:, k], self.e[:, k] = th, rot, w, e
        if isinstance(x_local, np.ndarray) or x_local:      # X is not already the local origin
            r = x_local * rot
            X, V, A = X - r, V - 1j * w * r, A - (1j * e - w**2) * r
        self.O[:, k], self.V[:, k], self.A[:, k] = X, V, A

    @staticmethod
    def aligned(x_local: complex, X: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Angle and e^{i theta} of a link whose local vector x_local is the world vector X
        (of the same length)."""
        return np.angle(X) - cmath.phase(x_local), X / x_local

    # --- prismatic pair geometry: the guide line is fixed in both links (equal rotation), and
    # the slider's local x axis is the guide direction d (its angle alpha in the guide's frame)
    @staticmethod
    def turned(p: "Pair", k: int, th: np.ndarray, rot: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Angle and e^{i theta} of link k of P pair p from those of the pair's other link."""
        if not p.alpha:
            return th, rot
        if k == p.links[1]:
            return th + p.alpha, rot * complex(*p.direction)
        return th - p.alpha, rot / complex(*p.direction)

    @staticmethod
    def guide(p: "Pair", k: int, rot_k: np.ndarray) -> np.ndarray:
        """World unit direction d of pair p's guide, given e^{i theta} of its link k."""
        return complex(*p.direction) * rot_k if k == p.links[0] else rot_k

    def offset(self, p: "Pair", k: int, name: str) -> float:
        """Signed distance c = (X - G) x d of point `name` of link k from the guide line."""
        x = self.local(k, name)
        if k == p.links[0]:
            return float(cross_z(x - self.local(k, p.guide), complex(*p.direction)))
        return float(-(x - self.local(k, p.point)).imag)

    @staticmethod
    def anchor(p: "Pair", k: int) -> str:
        """A point of link k that lies on the guide line (c = 0)."""
        return p.guide if k == p.links[0] else p.point

    def slide(self, p: "Pair", mover: int, v, a) -> None:
        """Record the motion of `mover` relative to the pair's other link along d."""
        if mover == p.links[1]:
            self.vs[:, p.index], self.as_[:, p.index] = v, a
        else:
            self.vs[:, p.index], self.as_[:, p.index] = -v, -a

    def reachable(self, g: "AssurGroup", disc: np.ndarray, scale: float, why: str) -> np.ndarray:
        """sqrt of a discriminant; AssemblyError naming the angles where it is negative."""
        bad = disc < -1e-12 * scale
        if bad.any():
            raise AssemblyError(g.label, np.degrees(self.phi[bad]), why)
        return np.sqrt(np.maximum(disc, 0.0))


# Each solver returns ||M||_F^2 and det M of its plans' matrix M, columns scaled by reference
# sizes (the group's own length scale pl.L, `group_scale`, for a column that is a length, 1 for a
# unit direction: guide directions are unit, as the model reader makes Pair.direction):
# `condition` of them is taken once for all groups.
_Conditioning = tuple[float | np.ndarray, np.ndarray]


def _rrr(pl: _Plan, g: "AssurGroup") -> _Conditioning:
    (pj, pin, pk), (j, k), (a, c) = g.pairs, g.links, g.known
    P, VP, AP = pl.point(a, pj.point)
    Q, VQ, AQ = pl.point(c, pk.point)
    xj, xk = pl.local(j, pin.point) - pl.local(j, pj.point), pl.local(k, pin.point) - pl.local(k, pk.point)
    lj, lk = abs(xj), abs(xk)
    PQ = Q - P
    d = np.abs(PQ)
    along = (lj**2 - lk**2 + d**2) / (2 * d)
    h = pl.reachable(g, lj**2 - along**2, lj**2, f"|{pj.point}{pk.point}| outside [|l{j} - l{k}|, l{j} + l{k}]")
    B = P + PQ / d * (along + 1j * g.branch * h)
    PB, QB = B - P, B - Q
    # v_B = v_P + w_j x PB = v_Q + w_k x QB ;  a_B = a_P - w_j^2 PB + e_j x PB = ...
    plan = Basis(1j * PB, -1j * QB)
    wj, wk = plan.solve(VQ - VP)
    ej, ek = plan.solve(AQ - wk**2 * QB - AP + wj**2 * PB)
    pl.set_link(j, *pl.aligned(xj, PB), P, pl.local(j, pj.point), wj, VP, ej, AP)
    pl.set_link(k, *pl.aligned(xk, QB), Q, pl.local(k, pk.point), wk, VQ, ek, AQ)
    return (lj**2 + lk**2) / pl.L**2, plan.det / pl.L**2


def _rrp(pl: _Plan, g: "AssurGroup") -> _Conditioning:
    (pj, pin, pk), (j, k), (a, b) = g.pairs, g.links, g.known
    P, VP, AP = pl.point(a, pj.point)
    th_k, rot_k = pl.turned(pk, k, pl.th[:, b], pl.rot[:, b])
    d = pl.guide(pk, k, rot_k)
    K = pl.position(b, pl.anchor(pk, b))
    xj, cB = pl.local(j, pin.point) - pl.local(j, pj.point), pl.offset(pk, k, pin.point)
    lj = abs(xj)
    w = K - 1j * cB * d - P                        # B = K + t d - cB n lies on a circle about P
    wd = dot_z(w, d)
    root = pl.reachable(g, wd**2 - dot_z(w, w) + lj**2, lj**2,
                        f"the guide line is farther than l{j} from {pj.point}")
    B = K + (g.branch * root - wd - 1j * cB) * d
    PB = B - P
    wb, eb = pl.w[:, b], pl.e[:, b]
    VBb, ABb = pl.at(b, B)
    # v_B = v_P + w_j x PB = v_B(b) + v_r d ; a_B = ... = a_B(b) + 2 w_b x v_r d + a_r d
    plan = Basis(1j * PB, -d)
    wj, vr = plan.solve(VBb - VP)
    VB = VP + wj * plan.a
    ej, ar = plan.solve(ABb + pl.coriolis(b, vr, d) - AP + wj**2 * PB)
    AB = AP + ej * plan.a - wj**2 * PB
    pl.set_link(j, *pl.aligned(xj, PB), P, pl.local(j, pj.point), wj, VP, ej, AP)
    pl.set_link(k, th_k, rot_k, B, pl.local(k, pin.point), wb, VB, eb, AB)
    pl.slide(pk, k, vr, ar)
    return lj**2 / pl.L**2 + 1.0, plan.det / pl.L


def _rpr(pl: _Plan, g: "AssurGroup") -> _Conditioning:
    (pj, pin, pk), (j, k), (a, c) = g.pairs, g.links, g.known   # j slides on k's guide
    P, VP, AP = pl.point(a, pj.point)
    Q, VQ, AQ = pl.point(c, pk.point)
    e = pl.offset(pin, j, pj.point) - pl.offset(pin, k, pk.point)   # (P - Q) x d, constant
    QP = P - Q
    rho2 = dot_z(QP, QP)
    root = pl.reachable(g, rho2 - e**2, pl.L**2, f"{pj.point} comes closer than the guide offset to {pk.point}")
    d = QP * (g.branch * root + 1j * e) / rho2     # the unit d with QP x d = e, on the branch's side
    th_j = np.angle(d)
    # v_P = v_Q + w_k x QP + v_r d ;  a_P = a_Q - w_k^2 QP + e_k x QP + 2 w_k x v_r d + a_r d
    plan = Basis(1j * QP, d)
    wk, vr = plan.solve(VP - VQ)
    ek, ar = plan.solve(AP - AQ + wk**2 * QP - 2j * wk * vr * d)
    pl.set_link(k, *pl.turned(pin, k, th_j, d), Q, pl.local(k, pk.point), wk, VQ, ek, AQ)
    pl.set_link(j, th_j, d, P, pl.local(j, pj.point), wk, VP, ek, AP)
    pl.slide(pin, j, vr, ar)
    return rho2 / pl.L**2 + 1.0, plan.det / pl.L


def _prp(pl: _Plan, g: "AssurGroup") -> _Conditioning:
    (pj, pin, pk), (j, k), (a, c) = g.pairs, g.links, g.known
    th_j, rot_j = pl.turned(pj, j, pl.th[:, a], pl.rot[:, a])
    th_k, rot_k = pl.turned(pk, k, pl.th[:, c], pl.rot[:, c])
    da, dc = pl.guide(pj, j, rot_j), pl.guide(pk, k, rot_k)
    Ka = pl.position(a, pl.anchor(pj, a)) - pl.offset(pj, j, pin.point) * 1j * da
    Kc = pl.position(c, pl.anchor(pk, c)) - pl.offset(pk, k, pin.point) * 1j * dc
    plan = Basis(da, -dc)
    t, _ = plan.solve(Kc - Ka)        # B on both lines
    B = Ka + t * da
    VBa, ABa = pl.at(a, B)
    VBc, ABc = pl.at(c, B)
    wa, wc = pl.w[:, a], pl.w[:, c]
    # v_B = v_B(a) + v1 d_a = v_B(c) + v2 d_c ; accelerations with the Coriolis terms
    v1, v2 = plan.solve(VBc - VBa)
    a1, a2 = plan.solve(ABc + pl.coriolis(c, v2, dc) - ABa - pl.coriolis(a, v1, da))
    VB = VBa + v1 * da
    AB = ABa + pl.coriolis(a, v1, da) + a1 * da
    pl.set_link(j, th_j, rot_j, B, pl.local(j, pin.point), wa, VB, pl.e[:, a], AB)
    pl.set_link(k, th_k, rot_k, B, pl.local(k, pin.point), wc, VB, pl.e[:, c], AB)
    pl.slide(pj, j, v1, a1)
    pl.slide(pk, k, v2, a2)
    return 2.0, plan.det


def _rpp(pl: _Plan, g: "AssurGroup") -> _Conditioning:
    (pj, pin, pk), (j, k), (a, c) = g.pairs, g.links, g.known
    P, VP, AP = pl.point(a, pj.point)
    th_k, rot_k = pl.turned(pk, k, pl.th[:, c], pl.rot[:, c])
    th_j, rot_j = pl.turned(pin, j, th_k, rot_k)
    d_in, dc = pl.guide(pin, k, rot_k), pl.guide(pk, k, rot_k)
    Oj = P - pl.local(j, pj.point) * rot_j
    Kj = Oj + pl.local(j, pl.anchor(pin, j)) * rot_j             # on the inner guide line
    Kc = pl.position(c, pl.anchor(pk, c))                         # on the outer guide line
    rY = pl.local(k, pl.anchor(pin, k)) * rot_k
    rX = pl.local(k, pl.anchor(pk, k)) * rot_k
    # k's anchor Y = Kj + s d_in on the inner line, its anchor X = Y + rX - rY on the outer line
    _, s = Basis(dc, -d_in).solve(Kj + rX - rY - Kc)
    Ok = Kj + s * d_in - rY
    wc, ec = pl.w[:, c], pl.e[:, c]
    VPc, APc = pl.at(c, P)
    # v_P = v_P(c) + v2 d_c + v1 d_in ; a_P = a_P(c) + 2 w x (v2 d_c + v1 d_in) + a2 d_c + a1 d_in
    plan = Basis(d_in, dc)
    v1, v2 = plan.solve(VP - VPc)
    a1, a2 = plan.solve(AP - APc - pl.coriolis(c, v1, d_in) - pl.coriolis(c, v2, dc))
    pl.set_link(j, th_j, rot_j, P, pl.local(j, pj.point), wc, VP, ec, AP)
    pl.set_link(k, th_k, rot_k, P, (P - Ok) / rot_k, wc, VPc + v2 * dc, ec, APc + pl.coriolis(c, v2, dc) + a2 * dc)
    pl.slide(pin, j, v1, a1)
    pl.slide(pk, k, v2, a2)
    return 2.0, plan.det


_GROUP_SOLVERS: dict[str, Callable[[_Plan, "AssurGroup"], _Conditioning]] = {
    "RRR": _rrr, "RRP": _rrp, "RPR": _rpr, "PRP": _prp, "RPP": _rpp}


def kinematics(mech: "Mechanism", phi: np.ndarray, unit_speed: bool = False) -> Kinematics:
    """Positions, velocities and accelerations of every link at crank angles `phi` (rad, (N,)).

    The crank turns as the drive says (a constant omega and eps, or the law omega(phi)); with
    `unit_speed`, at d phi/dt = 1 rad/s and eps = 0, so that velocities are the derivatives d/d phi
    (the plans' analogues: per unit crank speed, defined at standstill too) and accelerations
    d^2/d phi^2.

    Raises AssemblyError naming the angles where a group cannot be assembled. Where a group's
    plan is ill-conditioned (cond > COND_CHECK) the accuracy is measured (`Kinematics.error`);
    a SingularPositionWarning names the angles with fewer than DIGITS_WARN digits left, and
    velocities and accelerations are NaN where fewer than DIGITS_MIN are left or cond > COND_MAX.
    """
    phi = np.atleast_1d(np.asarray(phi, dtype=float))
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):   # singular angles: the guard marks them
        kin, checked, trials = solve_checked(mech, phi, unit_speed)
        error = a_priori_error(kin.cond)
        if len(checked):
            nominal = kin.take(checked)
            error[checked] = np.max([kinematic_deviation(mech, nominal, t) for t in trials], axis=0)
    return guard(mech, kin, error)


def solve_checked(mech: "Mechanism", phi: np.ndarray,
                  unit_speed: bool = False) -> tuple[Kinematics, np.ndarray, list[Kinematics]]:
    """The kinematics at `phi` (unguarded: nothing NaN yet, `error` not set), the indices of the
    angles where some group's cond exceeds COND_CHECK, and the kinematics at those angles solved
    again on inputs moved by PERTURB_ULPS ulps (one per sign pattern). Call under np.errstate
    as `kinematics` does."""
    kin = _solve(mech, phi, mech.points_z, unit_speed)
    checked = np.flatnonzero(~(kin.cond <= COND_CHECK).all(axis=1))       # NaN cond: checked
    trials = []
    if len(checked):
        sub = phi[checked]
        for draw in (0, 1):
            trials.append(_solve(mech, sub + _signs(len(sub), draw, "phi") * PERTURB_ULPS * _EPS
                                 * np.maximum(np.abs(sub), math.pi), _perturbed_points(mech, draw), unit_speed))
    return kin, checked, trials


def _signs(n: int, draw: int, key: str) -> np.ndarray:
    """n signs +-1, fixed by (draw, key) alone, so that the pattern of one input does not depend
    on which other points the model has."""
    seed = zlib.crc32(f"{draw}:{key}".encode())
    return np.where(np.random.default_rng(seed).integers(0, 2, n) == 1, 1.0, -1.0)


def _perturbed_points(mech: "Mechanism", draw: int) -> list[dict[str, complex]]:
    """Every point's local coordinates moved by PERTURB_ULPS ulps of the point (|x + iy|), each
    coordinate with its own sign (memoised per draw)."""
    key = f"perturbed_points_{draw}"
    if key not in mech._derived:
        out = []
        for link, pts in zip(mech.links, mech.points_z):
            moved = {}
            for name, z in pts.items():
                sx, sy = _signs(2, draw, f"{link.id}:{name}")
                moved[name] = z + PERTURB_ULPS * _EPS * abs(z) * complex(sx, sy)
            out.append(moved)
        mech._derived[key] = out
    return mech._derived[key]


def _solve(mech: "Mechanism", phi: np.ndarray, locals_: list[dict[str, complex]],
           unit_speed: bool = False) -> Kinematics:
    pl = _Plan(mech, phi, locals_)
    dr = mech.drive
    arm = pl.local(1, dr.point) - pl.local(1, dr.pivot)
    th1 = dr.sense * phi + (math.atan2(dr.reference[1], dr.reference[0]) - cmath.phase(arm))
    w, e = (1.0, 0.0) if unit_speed else dr.speed(phi)      # the constants, or per angle by the law
    pl.set_link(1, th1, np.exp(1j * th1), pl.local(0, dr.pivot), pl.local(1, dr.pivot),
                dr.sense * w, 0.0, dr.sense * e, 0.0)
    groups = mech.structure.groups
    frob, det = np.empty((2, len(phi), len(groups)))
    for n, (g, scale) in enumerate(zip(groups, group_scales(mech))):
        pl.L = scale
        frob[:, n], det[:, n] = _GROUP_SOLVERS[g.kind](pl, g)
    cond = condition(frob, det)
    N = len(phi)
    return Kinematics(phi, pl.th, pl.rot, pl.O, pl.V, pl.A, pl.w, pl.e, pl.vs, pl.as_, cond,
                      np.zeros(N, bool), np.zeros(N))


# -- length scales: only the points of the pairs (the joints) count; a point that carries a load,
# a centre of mass, or no pair at all plays no part in a group's geometry.
def _joint_extents(mech: "Mechanism") -> list[float]:
    """Per link: the largest distance between two of its joint points (points of its pairs), m."""
    if "joint_extents" not in mech._derived:
        joints: list[set[str]] = [set() for _ in mech.links]
        for p in mech.pairs:
            if p.kind == "R":
                joints[p.links[0]].add(p.point)
                joints[p.links[1]].add(p.point)
            else:
                joints[p.links[0]].add(p.guide)
                joints[p.links[1]].add(p.point)
        mech._derived["joint_extents"] = [
            max((abs(pts[a] - pts[b]) for a in names for b in names), default=0.0)
            for pts, names in zip(mech.points_z, joints)]
    return mech._derived["joint_extents"]


def kinematic_size(mech: "Mechanism") -> float:
    """The linkage's length scale for the accuracy measure: the largest distance between two
    joint points of one moving link, m (mech.size if no link has two)."""
    return max(_joint_extents(mech)[1:], default=0.0) or mech.size


def group_scales(mech: "Mechanism") -> list[float]:
    """Per Assur group, its length scale for the condition number, m: the largest distance
    between two joint points of one of its links or of the moving links it is attached to."""
    if "group_scales" not in mech._derived:
        ext = _joint_extents(mech)
        mech._derived["group_scales"] = [max((ext[k] for k in (*g.links, *g.known) if k), default=0.0)
                                         or kinematic_size(mech) for g in mech.structure.groups]
    return mech._derived["group_scales"]


# -- the accuracy estimate and the guard
def a_priori_error(cond: np.ndarray) -> np.ndarray:
    """(N,) relative error bound from the largest group cond at each angle: A_PRIORI cond^3
    (the measured law; used below COND_CHECK, where it leaves more than 11 digits)."""
    c = np.where(np.isnan(cond), np.inf, cond).max(axis=1, initial=1.0)
    return A_PRIORI * c**3


def digits(error: np.ndarray) -> np.ndarray:
    """Significant digits left for a relative error: -log10(error) within [0, 16]."""
    with np.errstate(divide="ignore"):
        return np.clip(-np.log10(error), 0.0, 16.0)


def relative_change(new: np.ndarray, old: np.ndarray, floor: float | np.ndarray) -> np.ndarray:
    """(N,) per angle (axis 0): the largest |new - old| / max(|old|, floor) over the other
    axes; inf where `new` is not finite and `old` is."""
    d = np.abs(new - old) / np.maximum(np.maximum(np.abs(old), floor), _TINY)
    d = np.where(np.isnan(d), np.inf, d).reshape(len(d), -1)
    return d.max(axis=1, initial=0.0)


def kinematic_deviation(mech: "Mechanism", a: Kinematics, b: Kinematics) -> np.ndarray:
    """(N,) how far the motion b is from a: the largest relative change of any link's position,
    orientation, angular velocity and acceleration, velocity and acceleration, and of any
    sliding velocity and acceleration, each against max(|value|, scale) with the scales
    L (kinematic_size), 1, w, e, L w, L e (w = |omega_1|, e = omega_1^2 + |eps_1|: the drive's
    constants, or the largest of a's crank over its angles, as for a law of motion or a motion at
    unit crank speed)."""
    L = kinematic_size(mech)
    w = max(abs(mech.drive.omega), _largest(a.omega[:, 1]))
    e = w * w + max(abs(mech.drive.eps), _largest(a.eps[:, 1]))
    return np.max([relative_change(b.origin_z, a.origin_z, L), relative_change(b.rot, a.rot, 1.0),
                   relative_change(b.omega, a.omega, w), relative_change(b.eps, a.eps, e),
                   relative_change(b.v_z, a.v_z, L * w), relative_change(b.a_z, a.a_z, L * e),
                   relative_change(b.v_slide, a.v_slide, L * w), relative_change(b.a_slide, a.a_slide, L * e)],
                  axis=0)


def _largest(x: np.ndarray) -> float:
    """Largest finite |x|, 0 if none."""
    return float(np.max(np.abs(x), initial=0.0, where=np.isfinite(x)))


def guard(mech: "Mechanism", kin: Kinematics, error: np.ndarray, stacklevel: int = 3) -> Kinematics:
    """`kin` with its error estimate set, NaN velocities and accelerations where fewer than
    DIGITS_MIN digits are left or cond > COND_MAX (`singular`), and a SingularPositionWarning
    per group for the angles with fewer than DIGITS_WARN digits left (named by the group with
    the largest cond there)."""
    if (error <= 10.0**-DIGITS_WARN).all() and (kin.cond <= COND_MAX).all():     # the regular case
        return replace(kin, error=error)
    cond = np.where(np.isnan(kin.cond), np.inf, kin.cond)
    error = np.where((cond > COND_MAX).any(axis=1), np.inf, np.where(np.isnan(error), np.inf, error))
    singular = ~(error <= 10.0**-DIGITS_MIN)
    low = ~(error <= 10.0**-DIGITS_WARN)
    if low.any():
        worst = np.argmax(cond, axis=1)
        left = digits(error)
        phi_deg = np.degrees(kin.phi)
        for n, g in enumerate(mech.structure.groups):
            at = low & (worst == n)
            if at.any():
                warnings.warn(SingularPositionWarning(
                    singular_message(g.label, phi_deg[at], cond[at, n], left[at], DIGITS_MIN),
                    group=g.label, phi_deg=phi_deg[at], cond=cond[at, n], digits=left[at]),
                    stacklevel=stacklevel)
    if not singular.any():
        return replace(kin, error=error)
    arrays = {name: getattr(kin, name).copy() for name in ("omega", "eps", "v_z", "a_z", "v_slide", "a_slide")}
    for arr in arrays.values():
        arr[singular] = np.nan
    return replace(kin, error=error, singular=singular, **arrays)
