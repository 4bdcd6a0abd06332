"""`analyze(mech, phi_deg)`: the whole kinetostatic analysis as one frozen result object.

May use: model, kinematics, kinetostatics, applied, planar; pandas only inside `to_frame`.
"""
from __future__ import annotations

from dataclasses import dataclass, fields
from typing import NamedTuple

import numpy as np

from .kinematics import Kinematics, kinematics
from .kinetostatics import Forces, forces, friction_power, lever_moment
from .applied import applied_wrenches, com_motion, inertia_loads
from .planar import as_xy, cross_z
from .model import Mechanism, _abbreviate

__all__ = ["Analysis", "InertiaLoad", "analyze", "FRAME_NOTE"]

#: The frame and sign conventions of every vector, moment and angle of a result (also in
#: `Analysis.to_frame().attrs["frame"]`).
FRAME_NOTE = ("SI units; world frame: x right, y up, gravity along -y; moments, angles, angular "
              "velocities and accelerations about +z (counter-clockwise positive); phi_deg: crank angle "
              "from the model's drive.reference in the drive's sense; R_i_j, Rx_i_j, Ry_i_j: force exerted "
              "by link i on link j (R_j_i = -R_i_j); M_bal: moment the drive applies to the crank; inertia "
              "loads: main vector at the centre of mass and main moment; NaN where singular is True")


class InertiaLoad(NamedTuple):
    """Inertia of one link (seed 000 sec. 4), arrays lead with the angle axis."""
    force: np.ndarray    # (N, 2) main vector F_i = -m a_S at the centre of mass, N
    moment: np.ndarray   # (N,) main moment M_i = -I_S eps, N m about +z
    h: np.ndarray        # (N,) offset |M_i| / |F_i| of the single resultant from S, m
                         #   (0 in translation, inf for a pure couple: rotation about S)
    point: np.ndarray    # (N, 2) a point of the single resultant's line (S where h is 0 or inf)

    def __repr__(self) -> str:
        return f"InertiaLoad(positions={len(self.moment)}: force (N, 2) N, moment N m, h m, point (N, 2) m)"


@dataclass(frozen=True)
class Analysis:
    """Kinematics and kinetostatics of `mech` at N crank angles. Arrays lead with N.

    Units: SI; world frame; moments about +z. `R` follows the convention R_ij = force of
    link i on link j. Where `singular` is True (a group's condition number above COND_MAX)
    velocities, accelerations and all forces are NaN, and `cond` says why.
    """
    mech: Mechanism
    phi_deg: np.ndarray     # (N,) crank angle from the model's reference direction in its sense, deg
                            #   (exactly the angles asked for; read-only)
    kin: Kinematics
    F_applied: np.ndarray   # (N, L, 2) applied loads without inertia, per link, N
    M_applied: np.ndarray   # (N, L) their moment about each link's local origin, N m
    F_i: np.ndarray         # (N, L, 2) inertia main vectors (at the centres of mass), N
    M_i: np.ndarray         # (N, L) inertia main moments, N m
    forces: Forces
    lever_moment: np.ndarray      # (N,) balancing moment by Zhukovsky's lever, N m
    friction_power: np.ndarray    # (N, n_pairs) power lost in each pair, W

    def __repr__(self) -> str:
        phi = self.phi_deg
        span = f"{phi[0]:g}" if len(phi) == 1 else f"{phi.min():g}..{phi.max():g}"
        return (f"Analysis(mechanism={_abbreviate(self.mech.name)!r}, positions={len(phi)}, "
                f"phi_deg={span}, singular={int(self.singular.sum())})")

    # -- angles
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

        Columns (unit in brackets): phi_deg [deg]; for every point P x_P, y_P [m], vx_P, vy_P
        [m/s], ax_P, ay_P [m/s^2]; for every moving link k theta_k [rad], omega_k [rad/s], eps_k
        [rad/s^2]; for every link with mass or inertia Fix_k, Fiy_k [N] (inertia main vector at
        the centre of mass), Mi_k [N m] (main moment), h_k [m] (offset of the single resultant);
        for every pair Rx_i_j, Ry_i_j, R_i_j [N] (force of link i on link j, its magnitude); for
        prismatic pairs also x_i_j [m] and m_i_j [N m] (line of the normal force, its moment
        about the slider point), vs_i_j [m/s] and as_i_j [m/s^2] (sliding velocity and
        acceleration); M_bal, M_lever [N m]; for a working machine F_balx, F_baly, F_bal [N]; with
        friction Pfr_i_j per pair and Pfr_total [W]; cond_<group> [1] per Assur group; singular
        [bool].

        `df.attrs["units"]` maps every column to its unit ("1": dimensionless, "bool": a flag);
        `df.attrs["frame"]` states the frame and sign conventions; `df.attrs["mechanism"]` the
        model's name. Vectors are in the world frame (x right, y up, gravity along -y), moments
        and angles about +z.
        """
        import pandas as pd
        m = self.mech
        cols: dict[str, np.ndarray] = {}
        units: dict[str, str] = {}

        def put(unit: str, **columns: np.ndarray) -> None:
            cols.update(columns)
            units.update(dict.fromkeys(columns, unit))

        put("deg", phi_deg=self.phi_deg)
        for name in m.point_names:
            for tag, arr, unit in zip(("", "v", "a"), self._point(name), ("m", "m/s", "m/s^2")):
                put(unit, **{f"{tag}x_{name}": arr[:, 0], f"{tag}y_{name}": arr[:, 1]})
        for k in range(1, m.n_links):
            put("rad", **{f"theta_{k}": self.theta(k)})
            put("rad/s", **{f"omega_{k}": self.omega(k)})
            put("rad/s^2", **{f"eps_{k}": self.eps(k)})
        for link in m.links[1:]:
            if link.mass or link.I_S:
                il = self.inertia(link.id)
                put("N", **{f"Fix_{link.id}": il.force[:, 0], f"Fiy_{link.id}": il.force[:, 1]})
                put("N m", **{f"Mi_{link.id}": il.moment})
                put("m", **{f"h_{link.id}": il.h})
        for p in m.pairs:
            ij = f"{p.links[0]}_{p.links[1]}"
            R = self.forces.R[:, p.index]
            put("N", **{f"Rx_{ij}": R[:, 0], f"Ry_{ij}": R[:, 1], f"R_{ij}": np.linalg.norm(R, axis=-1)})
            if p.kind == "P":
                put("m", **{f"x_{ij}": self.forces.x[:, p.index]})
                put("N m", **{f"m_{ij}": self.forces.m[:, p.index]})
                put("m/s", **{f"vs_{ij}": self.kin.v_slide[:, p.index]})
                put("m/s^2", **{f"as_{ij}": self.kin.a_slide[:, p.index]})
        put("N m", M_bal=self.balancing_moment, M_lever=self.lever_moment)
        if m.drive.kind == "machine":
            F = self.balancing_force
            put("N", F_balx=F[:, 0], F_baly=F[:, 1], F_bal=np.linalg.norm(F, axis=-1))
        if m.friction is not None:
            put("W", **{f"Pfr_{p.links[0]}_{p.links[1]}": self.friction_power[:, p.index] for p in m.pairs})
            put("W", Pfr_total=self.friction_power_total)
        put("1", **{f"cond_{g.label}": self.cond[:, n] for n, g in enumerate(m.structure.groups)})
        put("bool", singular=self.singular)
        df = pd.DataFrame(cols)
        df.attrs.update(mechanism=m.name, units=units, frame=FRAME_NOTE)
        return df


def analyze(mech: Mechanism, phi_deg=None, steps: int = 360) -> Analysis:
    """Kinematic and kinetostatic analysis of `mech` at crank angles `phi_deg` (deg, array-like),
    or at `steps` equal steps over a full revolution when `phi_deg` is None."""
    if not isinstance(mech, Mechanism):
        raise TypeError(f"analyze: expected a Mechanism, got {type(mech).__name__}; "
                        f"read a model file with kinetostat.load(path)")
    if phi_deg is None:
        if not isinstance(steps, (int, np.integer)) or isinstance(steps, bool) or steps < 1:
            raise ValueError(f"steps: expected a positive integer, got {steps!r}")
        phi_deg = np.arange(steps) * 360.0 / steps     # k 360 / N rounded once: 30.0 exactly, not 29.999...
    try:
        phi_deg = np.array(phi_deg, dtype=float, ndmin=1)   # a copy: the result owns its angles
    except (TypeError, ValueError):
        raise ValueError(f"phi_deg: expected finite crank angles in degrees, got {phi_deg!r}") from None
    if phi_deg.ndim != 1 or not np.isfinite(phi_deg).all():
        raise ValueError(f"phi_deg: expected finite crank angles of shape (N,), got shape {phi_deg.shape}")
    phi_deg.flags.writeable = False
    kin = kinematics(mech, np.radians(phi_deg))
    with np.errstate(divide="ignore", invalid="ignore"):    # NaN only at angles marked singular
        return _kinetostatics(mech, phi_deg, kin)


def _kinetostatics(mech: Mechanism, phi_deg: np.ndarray, kin: Kinematics) -> Analysis:
    r, aS = com_motion(mech, kin)
    F_app, M_app = applied_wrenches(mech, kin, r)
    F_i, M_i = inertia_loads(mech, kin, aS)
    F_all = F_app + F_i
    M_all = M_app + M_i + cross_z(r, F_i)
    frc = forces(mech, kin, F_all, M_all)
    lever = lever_moment(mech, kin, F_all, M_all)
    return _read_only(Analysis(mech, phi_deg, kin, as_xy(F_app), M_app, as_xy(F_i), M_i, frc, lever,
                               friction_power(mech, kin, frc.R)))


def _read_only(res: Analysis) -> Analysis:
    """`res` with every array it holds (its own, its Kinematics' and Forces') read-only: a
    frozen result whose numbers no caller can change in place."""
    for part in (res, res.kin, res.forces):
        for f in fields(part):
            value = getattr(part, f.name)
            if isinstance(value, np.ndarray):
                value.flags.writeable = False
    return res
