"""The d'Alembert-Lagrange route (seed 004): every reaction component and the balancing moment
from the virtual work of all loads, inertia included, independently of the group-by-group route.

For one reaction component: release that one constraint (a revolute pair's pin may separate
along world x, or y; a prismatic pair's slider may leave its guide along the normal, or turn
relative to it; the crank may turn: the balancing moment), give the mechanism the one virtual
motion that violates the released constraint by a unit and keeps every other one (seed 004
finds it with instantaneous centres; here it is the kinematics of the released mechanism: a
column of the inverse of the constraint Jacobian J), and read the component from
R du + sum(F . dr + M dtheta) = 0.

Coordinates q: (x, y, theta) of every moving link's local origin; constraints, in the order of
the pairs: R pair (i, j) at P: X_j(P) - X_i(P) = 0 (two rows: x, y); P pair (guide i, slider j):
the slider point's distance from the guide along its normal n, and the relative turn
theta_j - theta_i (two rows); the drive: theta_1 = phi (last row). The reaction conjugate to a
unit violation is the force of link i on link j (world x, y), the normal force along n and the
couple about the slider point (as `kinetostatics.Forces`), and the moment of the drive on the
crank. All angles are solved at once on (N, m, m) stacks.

Shares with the group route only the kinematics (`kinematics.kinematics`) and the load
definitions of `applied`; for a working machine the balancing moment is turned into the
pinion's force by the gear mesh's definition (`kinetostatics.gear_force`). May use: model,
kinematics, applied, planar, analysis (its angle parsing and its result accessors), the
`Forces` record and `gear_force` of kinetostatics (never its group solvers).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .analysis import Analysis, crank_angles
from .applied import applied_wrenches, com_motion, inertia_loads
from .kinematics import Kinematics, kinematics
from .kinetostatics import Forces, gear_force
from .model import Mechanism, _abbreviate
from .planar import as_xy, cross_z, dot_z

__all__ = ["VirtualWork", "virtual_work", "constraint_jacobian", "virtual_motions"]


@dataclass(frozen=True)
class VirtualWork:
    """Reactions and balancing load of `mech` at N crank angles by d'Alembert-Lagrange.

    Same conventions and accessors as `Analysis`: `reaction(i, j)` (N, 2) force of link i on
    link j, N, world frame; `reaction_offset(i, j)` (prismatic pairs) m; `balancing_moment`
    (N,) N m; `balancing_force` (N, 2) N (working machine). NaN where `singular`."""
    mech: Mechanism
    phi_deg: np.ndarray     # (N,) crank angles, deg
    kin: Kinematics
    forces: Forces

    def __repr__(self) -> str:
        return (f"VirtualWork(mechanism={_abbreviate(self.mech.name)!r}, positions={len(self.phi_deg)}, "
                f"singular={int(self.kin.singular.sum())})")

    # the result's accessors are those of Analysis, on the same `mech` and `forces` fields
    _link = Analysis._link
    reaction = Analysis.reaction
    reaction_offset = Analysis.reaction_offset
    balancing_moment = Analysis.balancing_moment
    balancing_force = Analysis.balancing_force

    @property
    def singular(self) -> np.ndarray:
        """(N,) True where some group is at a singular position (values there are NaN)."""
        return self.kin.singular


def _column(k: int) -> int:
    """First column (x) of moving link k's coordinates (x, y, theta)."""
    return 3 * (k - 1)


def constraint_jacobian(mech: Mechanism, kin: Kinematics) -> np.ndarray:
    """(N, m, m) Jacobian of the constraints (rows: two per pair in pair order, then the
    drive) with respect to q = (x, y, theta) of links 1..L-1 (columns), m = 3 (L - 1)."""
    N, n = len(kin.phi), 3 * (mech.n_links - 1)
    J = np.zeros((N, len(mech.pairs) * 2 + 1, n))
    local = mech.points_z
    for p in mech.pairs:
        i, j = p.links
        row = 2 * p.index
        X = kin.origin_z[:, j] + local[j][p.point] * kin.rot[:, j]   # the pin, or the slider point
        n_guide = 1j * complex(*p.direction) * kin.rot[:, i] if p.kind == "P" else None
        for k, s in ((i, -1.0), (j, 1.0)):
            if not k:
                continue
            c = _column(k)
            arm = 1j * (X - kin.origin_z[:, k])       # d X_k / d theta_k
            if p.kind == "R":                           # rows: separation along x, along y
                J[:, row, c], J[:, row + 1, c + 1] = s, s
                J[:, row, c + 2], J[:, row + 1, c + 2] = s * arm.real, s * arm.imag
            else:                                       # rows: along the normal, relative turn
                J[:, row, c], J[:, row, c + 1] = s * n_guide.real, s * n_guide.imag
                J[:, row, c + 2] = s * dot_z(arm, n_guide)
                J[:, row + 1, c + 2] = s
    J[:, -1, 2] = 1.0                                   # the crank's turn theta_1
    if J.shape[1] != n:
        raise ValueError(f"virtual_work: {J.shape[1]} constraints for {n} coordinates: "
                         f"the mechanism is not one of single mobility with lower pairs only")
    return J


def virtual_motions(mech: Mechanism, kin: Kinematics) -> np.ndarray:
    """(N, m, m): column c is the virtual motion dq of the mechanism with constraint c released:
    unit violation of c, every other constraint kept (the Jacobian of the others has this one
    direction as its null space). NaN at singular angles. The last column (crank released) is
    the mechanism's own motion per radian of the crank."""
    J = constraint_jacobian(mech, kin)
    bad = kin.singular
    J[bad] = np.eye(J.shape[1])               # solved, then set to NaN: one stack, no loop
    D = np.linalg.solve(J, np.broadcast_to(np.eye(J.shape[1]), J.shape))
    D[bad] = np.nan
    return D


def _generalised_loads(mech: Mechanism, kin: Kinematics) -> np.ndarray:
    """(N, m) the loads' components along q: force x, y and moment about the local origin of
    every moving link; applied loads and inertia (F_i = -m a_S at S, M_i = -I_S eps)."""
    r, aS = com_motion(mech, kin)
    F, M = applied_wrenches(mech, kin, r)
    F_i, M_i = inertia_loads(mech, kin, aS)
    F, M = F + F_i, M + M_i + cross_z(r, F_i)
    Q = np.stack([F.real, F.imag, M], axis=-1)[:, 1:]     # (N, L-1, 3)
    return Q.reshape(len(kin.phi), -1)


def virtual_work(mech: Mechanism, phi_deg=None, steps: int = 360) -> VirtualWork:
    """Every pair's reaction and the balancing moment of `mech` at crank angles `phi_deg` (deg),
    or `steps` equal steps over a revolution, by the principle of virtual work (seed 004)."""
    if not isinstance(mech, Mechanism):
        raise TypeError(f"virtual_work: expected a Mechanism, got {type(mech).__name__}; "
                        f"read a model file with kinetostat.load(path)")
    phi_deg = crank_angles(phi_deg, steps)
    kin = kinematics(mech, np.radians(phi_deg))
    with np.errstate(divide="ignore", invalid="ignore"):
        D = virtual_motions(mech, kin)
        Q = _generalised_loads(mech, kin)
        # R du + Q . dq = 0 with du = 1 on the released component: one component per column
        lam = -np.einsum("nqc,nq->nc", D, Q)
    pairs = lam[:, :-1].reshape(len(phi_deg), len(mech.pairs), 2)
    prismatic = np.array([p.kind == "P" for p in mech.pairs])
    normal = np.where(prismatic, pairs[..., 0], 0.0)
    couple = np.where(prismatic, pairs[..., 1], 0.0)
    R = pairs[..., 0] + 1j * pairs[..., 1]
    for p in mech.pairs:
        if p.kind == "P":
            R[:, p.index] = normal[:, p.index] * 1j * complex(*p.direction) * kin.rot[:, p.links[0]]
    M_bal = lam[:, -1]
    F_bal = np.zeros((len(phi_deg), 2))
    dr = mech.drive
    if dr.kind == "machine":
        # the released crank's moment is the pinion's force at the pitch point, on its line of
        # action; the bearing carries the rest of the force the drive row and pair (0, 1) found
        F_bal = gear_force(dr.gear, M_bal)
        p = mech.pair_between(0, 1)
        R[:, p.index] -= (1 if p.links == (0, 1) else -1) * (F_bal[:, 0] + 1j * F_bal[:, 1])
    return VirtualWork(mech, phi_deg, kin, Forces(as_xy(R), normal, couple, M_bal, F_bal))
