"""`analyze(mech, phi_deg)`: the whole kinetostatic analysis as one frozen result object."""
from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from .kinematics import Kinematics, kinematics
from .kinetostatics import Forces, forces, friction_power, lever_moment
from .applied import applied_wrenches, com_motion, inertia_loads
from .planar import as_xy, cross_z
from .model import Mechanism

__all__ = ["Analysis", "InertiaLoad", "analyze"]


class InertiaLoad(NamedTuple):
    """Inertia of one link (seed 000 sec. 4), arrays lead with the angle axis."""
    force: np.ndarray    # (N, 2) main vector F_i = -m a_S at the centre of mass, N
    moment: np.ndarray   # (N,) main moment M_i = -I_S eps, N m about +z
    h: np.ndarray        # (N,) offset |M_i| / |F_i| of the single resultant from S, m
                         #   (0 in translation, inf for a pure couple: rotation about S)
    point: np.ndarray    # (N, 2) a point of the single resultant's line (S where h is 0 or inf)


@dataclass(frozen=True)
class Analysis:
    """Kinematics and kinetostatics of `mech` at N crank angles. Arrays lead with N.

    Units: SI; world frame; moments about +z. `R` follows the convention R_ij = force of
    link i on link j. Where `singular` is True (a group's condition number above COND_MAX)
    velocities, accelerations and all forces are NaN, and `cond` says why.
    """
    mech: Mechanism
    kin: Kinematics
    F_applied: np.ndarray   # (N, L, 2) applied loads without inertia, per link, N
    M_applied: np.ndarray   # (N, L) their moment about each link's local origin, N m
    F_i: np.ndarray         # (N, L, 2) inertia main vectors (at the centres of mass), N
    M_i: np.ndarray         # (N, L) inertia main moments, N m
    forces: Forces
    lever_moment: np.ndarray      # (N,) balancing moment by Zhukovsky's lever, N m
    friction_power: np.ndarray    # (N, n_pairs) power lost in each pair, W

    # -- angles
    @property
    def phi_deg(self) -> np.ndarray:
        """(N,) crank angle from the model's reference direction in its sense, deg."""
        return np.degrees(self.kin.phi)

    @property
    def singular(self) -> np.ndarray:
        """(N,) True where some group is at a singular position (values there are NaN)."""
        return self.kin.singular

    @property
    def cond(self) -> np.ndarray:
        """(N, n_groups) condition number of each group's plan (groups in attachment order)."""
        return self.kin.cond

    # -- kinematics
    def _point(self, name: str):
        k = self.mech.point_owner(name)
        return self.kin.point(k, self.mech.links[k].points[name])

    def position(self, name: str) -> np.ndarray:
        """(N, 2) world position of point `name`, m."""
        return self._point(name)[0]

    def velocity(self, name: str) -> np.ndarray:
        """(N, 2) velocity of point `name`, m/s."""
        return self._point(name)[1]

    def acceleration(self, name: str) -> np.ndarray:
        """(N, 2) acceleration of point `name`, m/s^2."""
        return self._point(name)[2]

    def _link(self, k: int) -> int:
        if not isinstance(k, (int, np.integer)) or not 0 <= k < self.mech.n_links:
            raise KeyError(f"unknown link {k!r}. Valid links: {list(range(self.mech.n_links))}")
        return int(k)

    def theta(self, k: int) -> np.ndarray:
        """(N,) angle of link k's local frame, rad about +z."""
        return self.kin.theta[:, self._link(k)]

    def omega(self, k: int) -> np.ndarray:
        """(N,) angular velocity of link k, rad/s about +z."""
        return self.kin.omega[:, self._link(k)]

    def eps(self, k: int) -> np.ndarray:
        """(N,) angular acceleration of link k, rad/s^2 about +z."""
        return self.kin.eps[:, self._link(k)]

    def slide_velocity(self, i: int, j: int) -> np.ndarray:
        """(N,) velocity of the slider relative to the guide of prismatic pair (i, j), along
        the guide direction, m/s."""
        return self.kin.v_slide[:, self.mech.pair_between(i, j).index]

    def slide_acceleration(self, i: int, j: int) -> np.ndarray:
        """(N,) its rate seen from the guide (the relative acceleration of the plans, without
        the Coriolis part), m/s^2."""
        return self.kin.a_slide[:, self.mech.pair_between(i, j).index]

    # -- kinetostatics
    def reaction(self, i: int, j: int) -> np.ndarray:
        """(N, 2) force exerted by link i on link j in their pair, N, world frame."""
        p = self.mech.pair_between(self._link(i), self._link(j))
        R = self.forces.R[:, p.index]
        return R if p.links == (i, j) else -R

    def reaction_offset(self, i: int, j: int) -> np.ndarray:
        """(N,) prismatic pair (i, j): the normal force acts on the line through the slider
        point + x d (d the guide direction), x in m; NaN where the normal force is 0 or only
        rounding (below 1e-12 of the largest reaction at that angle, e.g. at a dead centre)."""
        p = self.mech.pair_between(self._link(i), self._link(j))
        if p.kind != "P":
            raise KeyError(f"pair {p.label} is revolute: its reaction passes through {p.point!r}")
        return self.forces.x[:, p.index]

    @property
    def balancing_moment(self) -> np.ndarray:
        """(N,) moment the drive applies to the crank about +z (group by group), N m."""
        return self.forces.M_bal

    @property
    def balancing_force(self) -> np.ndarray:
        """(N, 2) working machine: balancing force of the pinion on the crank's gear at the
        pitch point, on the line of action, N. Zeros for an engine."""
        return self.forces.F_bal

    @property
    def lever_discrepancy(self) -> np.ndarray:
        """(N,) lever_moment - balancing_moment, N m (rounding only, for an exact solver)."""
        return self.lever_moment - self.balancing_moment

    def inertia(self, k: int) -> InertiaLoad:
        """Inertia force, moment, offset h and a point of the single resultant of link k."""
        k = self._link(k)
        link = self.mech.links[k]
        F, M = self.F_i[:, k], self.M_i[:, k]
        S = self.kin.point(k, link.points[link.com])[0] if link.com else self.kin.origin[:, k]
        F2 = np.sum(F * F, axis=-1)
        with np.errstate(divide="ignore", invalid="ignore"):
            h = np.where(M == 0, 0.0, np.abs(M) / np.sqrt(F2))
            # r x F = M with r perpendicular to F: r = -M rot90(F) / |F|^2
            shift = np.where((F2 > 0)[:, None], (-M / F2)[:, None] * np.stack([-F[:, 1], F[:, 0]], -1), 0.0)
        return InertiaLoad(F, M, h, S + shift)

    @property
    def friction_power_total(self) -> np.ndarray:
        """(N,) total power lost in friction, W."""
        return self.friction_power.sum(axis=1)

    def friction_energy(self) -> np.ndarray:
        """(n_pairs,) energy lost in each pair over one revolution, J: the integral of its power
        over the period (periodic trapezoid rule, exact for the sampled cycle). Needs the angles
        of a uniform full cycle, as `analyze(mech, steps=N)` gives."""
        phi = self.phi_deg
        if not np.allclose(phi, phi[0] + np.arange(len(phi)) * 360.0 / len(phi), rtol=0, atol=1e-9):
            raise ValueError("friction_energy: needs the angles of a uniform full cycle (analyze with steps=N)")
        return self.friction_power.mean(axis=0) * 2 * np.pi / self.mech.drive.omega

    # -- table
    def to_frame(self):
        """The whole analysis as a pandas DataFrame, one row per crank angle.

        Columns (SI): phi_deg; x_P, y_P, vx_P, vy_P, ax_P, ay_P for every point P;
        theta_k, omega_k, eps_k for every link k; Fix_k, Fiy_k, Mi_k, h_k inertia of every
        link with mass or inertia; Rx_i_j, Ry_i_j, R_i_j (force of i on j and its magnitude)
        for every pair, x_i_j and m_i_j (line of the normal force, its moment about the slider
        point) and vs_i_j, as_i_j (sliding velocity and acceleration) for prismatic pairs; M_bal, M_lever, and for a machine
        F_bal (magnitude) with F_balx, F_baly; Pfr_i_j per pair and Pfr_total when the model has
        friction; cond_<group> per group; singular.
        """
        import pandas as pd
        m = self.mech
        cols: dict[str, np.ndarray] = {"phi_deg": self.phi_deg}
        for name in m.point_names:
            P, V, A = self._point(name)
            for tag, arr in (("", P), ("v", V), ("a", A)):
                cols[f"{tag}x_{name}"], cols[f"{tag}y_{name}"] = arr[:, 0], arr[:, 1]
        for k in range(1, m.n_links):
            cols[f"theta_{k}"], cols[f"omega_{k}"], cols[f"eps_{k}"] = self.theta(k), self.omega(k), self.eps(k)
        for link in m.links[1:]:
            if link.mass or link.I_S:
                il = self.inertia(link.id)
                cols[f"Fix_{link.id}"], cols[f"Fiy_{link.id}"] = il.force[:, 0], il.force[:, 1]
                cols[f"Mi_{link.id}"], cols[f"h_{link.id}"] = il.moment, il.h
        for p in m.pairs:
            i, j = p.links
            R = self.forces.R[:, p.index]
            cols[f"Rx_{i}_{j}"], cols[f"Ry_{i}_{j}"] = R[:, 0], R[:, 1]
            cols[f"R_{i}_{j}"] = np.linalg.norm(R, axis=-1)
            if p.kind == "P":
                cols[f"x_{i}_{j}"] = self.forces.x[:, p.index]
                cols[f"m_{i}_{j}"] = self.forces.m[:, p.index]
                cols[f"vs_{i}_{j}"] = self.kin.v_slide[:, p.index]
                cols[f"as_{i}_{j}"] = self.kin.a_slide[:, p.index]
        cols["M_bal"], cols["M_lever"] = self.balancing_moment, self.lever_moment
        if m.drive.kind == "machine":
            cols["F_balx"], cols["F_baly"] = self.balancing_force[:, 0], self.balancing_force[:, 1]
            cols["F_bal"] = np.linalg.norm(self.balancing_force, axis=-1)
        if m.friction is not None:
            for p in m.pairs:
                cols[f"Pfr_{p.links[0]}_{p.links[1]}"] = self.friction_power[:, p.index]
            cols["Pfr_total"] = self.friction_power_total
        for n, g in enumerate(m.structure.groups):
            cols[f"cond_{g.label}"] = self.cond[:, n]
        cols["singular"] = self.singular
        return pd.DataFrame(cols)


def analyze(mech: Mechanism, phi_deg=None, steps: int = 360) -> Analysis:
    """Kinematic and kinetostatic analysis of `mech` at crank angles `phi_deg` (deg, array-like),
    or at `steps` equal steps over a full revolution when `phi_deg` is None."""
    if not isinstance(mech, Mechanism):
        raise TypeError(f"analyze: expected a Mechanism, got {type(mech).__name__}; "
                        f"read a model file with kinetostat.load(path)")
    if phi_deg is None:
        if not isinstance(steps, (int, np.integer)) or isinstance(steps, bool) or steps < 1:
            raise ValueError(f"steps: expected a positive integer, got {steps!r}")
        phi_deg = np.arange(steps) * (360.0 / steps)
    try:
        phi_deg = np.atleast_1d(np.asarray(phi_deg, dtype=float))
    except (TypeError, ValueError):
        raise ValueError(f"phi_deg: expected finite crank angles in degrees, got {phi_deg!r}") from None
    if phi_deg.ndim != 1 or not np.isfinite(phi_deg).all():
        raise ValueError(f"phi_deg: expected finite crank angles of shape (N,), got shape {phi_deg.shape}")
    kin = kinematics(mech, np.radians(phi_deg))
    with np.errstate(divide="ignore", invalid="ignore"):    # NaN only at angles marked singular
        return _kinetostatics(mech, kin)


def _kinetostatics(mech: Mechanism, kin: Kinematics) -> Analysis:
    r, aS = com_motion(mech, kin)
    F_app, M_app = applied_wrenches(mech, kin, r)
    F_i, M_i = inertia_loads(mech, kin, aS)
    F_all = F_app + F_i
    M_all = M_app + M_i + cross_z(r, F_i)
    frc = forces(mech, kin, F_all, M_all)
    lever = lever_moment(mech, kin, F_all, M_all)
    return Analysis(mech, kin, as_xy(F_app), M_app, as_xy(F_i), M_i, frc, lever,
                    friction_power(mech, kin, frc.R))
