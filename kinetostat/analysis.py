"""The whole kinetostatic analysis as one frozen result object (`Analysis`), and the numpy path
that computes it (`exact`); `kinetostat.solve.analyze` chooses between it and the compiled path.

May use: model (with `model.lettering`: the pairs' names a warning gives), groups, kinematics,
kinetostatics, applied, planar, friction, errors; pandas only inside `to_frame` (`columns`: its
table without pandas), xarray (an optional extra) only inside `to_xarray`.
"""
from __future__ import annotations

import warnings
from dataclasses import dataclass, fields, replace
from functools import cached_property
from types import MappingProxyType
from typing import Callable, Mapping, NamedTuple

import numpy as np

from .kinematics import (Kinematics, a_priori_error, guard, kinematic_deviation, kinematic_size, kinematics,
                         relative_change, solve_checked)
from .kinetostatics import Forces, forces, friction_power, lever_moment
from . import friction as _friction, groups
from .applied import applied_moment, applied_wrenches, com_motion, load_magnitude, point_forces
from .planar import as_xy, as_z, dot_z
from .friction import relative_rate
from .errors import (SelfLockingWarning, SingularFrictionWarning, SingularPositionWarning, UndefinedFigureWarning,
                     self_locking_message, singular_friction_message)
from .model import Mechanism, _abbreviate
from .model.lettering import pair_name

__all__ = ["Analysis", "InertiaLoad", "CentreOfOscillation", "exact", "friction_method", "crank_angles", "FRAME_NOTE", "DATASET_NOTE", "deviation",
           "force_deviation"]

#: The frame and sign conventions of every vector, moment and angle of a result (also in
#: `Analysis.to_frame().attrs["frame"]`).
FRAME_NOTE = ("SI units; world frame: x right, y up, gravity along -y; moments, angles, angular "
              "velocities and accelerations about +z (counter-clockwise positive); phi_deg: crank angle "
              "from the model's drive.reference in the drive's sense; R_i_j, Rx_i_j, Ry_i_j: force exerted "
              "by link i on link j (R_j_i = -R_i_j); M_bal: moment the drive applies to the crank; inertia "
              "loads: main vector at the centre of mass and main moment; NaN where singular is True")
#: The same conventions in the names of `Analysis.to_xarray` (its attrs["conventions"]).
DATASET_NOTE = ("SI units; world frame: x right, y up, gravity along -y; moments, angles (theta from the world "
                "x axis), angular velocities and accelerations about +z (counter-clockwise positive); phi: crank "
                "angle from the drive's reference direction in the drive's sense (the phi coordinate's attrs); "
                "R: force exerted by link i on link j of each pair (the pair's coordinates i and j; R_ji = -R_ij); "
                "M_bal: moment the drive applies to the crank; F_i: inertia main vector at the centre of mass, "
                "M_i: main moment; NaN where singular is True")


#: Gauss-Legendre nodes per smooth piece of a cycle integral with friction (`Analysis._cycle_integral`).
CYCLE_NODES = 24
#: The sign changes of relative motion, found to this, deg (`Analysis._breakpoints`).
BREAK_TOL_DEG = 1e-9


class InertiaLoad(NamedTuple):
    """Inertia of one link (seed 000 sec. 4), arrays lead with the angle axis."""
    force: np.ndarray    # (N, 2) main vector F_i = -m a_S at the centre of mass, N
    moment: np.ndarray   # (N,) main moment M_i = -I_S eps, N m about +z
    h: np.ndarray        # (N,) offset |M_i| / |F_i| of the single resultant from S, m
                         #   (0 in translation, inf for a pure couple: rotation about S)
    point: np.ndarray    # (N, 2) a point of the single resultant's line (S where h is 0 or inf)

    def __repr__(self) -> str:
        return f"InertiaLoad(positions={len(self.moment)}: force (N, 2) N, moment N m, h m, point (N, 2) m)"


class CentreOfOscillation(NamedTuple):
    """Centre of oscillation K of a link's inertia resultant (seed 000 sec. 4)."""
    point: np.ndarray    # (N, 2) K, m (S where the link translates; inf where a_S = 0: a pure couple)
    l_SK: np.ndarray     # (N,) distance S-K = rho_S^2 / l_QS, m (Q the centre of accelerations)

    def __repr__(self) -> str:
        return f"CentreOfOscillation(positions={len(self.l_SK)}: point (N, 2) m, l_SK m)"


@dataclass(frozen=True)
class Analysis:
    """Kinematics and kinetostatics of `mech` at N crank angles. Arrays lead with N.

    Units: SI; world frame; moments about +z. `R` follows the convention R_ij = force of
    link i on link j. `error` is the estimated relative error at each angle (measured by a
    perturbed re-solve where a group's cond exceeds COND_CHECK). Where `singular` is True (cond
    above COND_MAX, or fewer than DIGITS_MIN digits left) velocities, accelerations and all
    forces are NaN, and `cond` and `error` say why.
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
    lever_moment: np.ndarray      # (N,) balancing moment by Zhukovsky's lever, N m (with friction in
                                  #   the reactions: the friction loads applied on the lever too)
    friction_power: np.ndarray    # (N, n_pairs) power lost in each pair, W (>= 0)
    friction: _friction.FrictionSolution | None = None   # friction in the reactions (None: the first
                                  #   approximation or no friction; `friction_method` says which)

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

    @property
    def error(self) -> np.ndarray:
        """(N,) estimated relative error of the values at each angle: the largest relative change
        of the kinematics (`kinematic_deviation`) and of the forces (`force_deviation`) when the
        inputs move by a few ulps (where cond > COND_CHECK; A_PRIORI cond^3 elsewhere); inf
        where singular."""
        return self.kin.error

    @property
    def digits(self) -> np.ndarray:
        """(N,) estimated significant digits left at each angle, -log10(error) within [0, 16]."""
        return self.kin.digits

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
        pitch point, on the line of action, N. An engine has none (its drive applies the couple
        `balancing_moment`): AttributeError with that reason, so `hasattr(res, "balancing_force")`
        is False (never a force of 0 N)."""
        if self.mech.drive.kind != "machine":
            raise AttributeError(f"balancing_force: {_abbreviate(self.mech.name)!r} is an engine (drive.kind = "
                                 f"'{self.mech.drive.kind}'): its drive applies the couple balancing_moment (N m) to "
                                 f"the crank, no force; only a working machine (a gear mesh, drive.kind = 'machine') "
                                 f"has a balancing force")
        return self.forces.F_bal

    @property
    def lever_discrepancy(self) -> np.ndarray:
        """(N,) lever_moment - balancing_moment, N m (rounding only, for an exact solver)."""
        return self.lever_moment - self.balancing_moment

    def take(self, idx: np.ndarray) -> "Analysis":
        """The analysis at the angles `idx` only."""
        f = self.forces
        return Analysis(self.mech, self.phi_deg[idx], self.kin.take(idx), self.F_applied[idx],
                        self.M_applied[idx], self.F_i[idx], self.M_i[idx],
                        type(f)(f.R[idx], f.normal[idx], f.m[idx], f.M_bal[idx], f.F_bal[idx]),
                        self.lever_moment[idx], self.friction_power[idx],
                        None if self.friction is None else self.friction.take(idx))

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

    def reaction_angle(self, i: int, j: int) -> np.ndarray:
        """(N,) direction of reaction(i, j), deg from +x, counter-clockwise, in (-180, 180]."""
        R = self.reaction(i, j)
        return np.degrees(np.arctan2(R[:, 1], R[:, 0]))

    def _two_pins(self, k: int) -> tuple:
        """The two revolute pairs of a two-pin link k, or KeyError saying why it is not one."""
        k = self._link(k)
        pairs = [p for p in self.mech.pairs if k in p.links]
        if k == 0 or len(pairs) != 2 or any(p.kind != "R" for p in pairs) or pairs[0].point == pairs[1].point:
            raise KeyError(f"link {k} is not a two-pin link (exactly two revolute pairs at two points); "
                           f"its pairs: {[p.label for p in pairs]}")
        return pairs

    def axial_force(self, k: int, at: str | None = None) -> np.ndarray:
        """(N,) axial force of two-pin link k, N: tension positive, compression negative.

        At each pin, the component of the force the other link exerts on k along the line of
        the pins, pointing away from the link's other pin (it pulls: tension). `at`: that pin's
        point name; None: the mean of the two ends, the axial force at the middle of a bar whose
        own loads (gravity, inertia, loads on it) are carried by the pins. The two ends are equal
        when the link carries no load along its line."""
        pairs = self._two_pins(k)
        ends = {}
        for p, q in (pairs, pairs[::-1]):
            other = p.links[0] if p.links[1] == k else p.links[1]
            u = self.position(p.point) - self.position(q.point)
            u /= np.linalg.norm(u, axis=-1, keepdims=True)
            ends[p.point] = np.sum(self.reaction(other, k) * u, axis=-1)
        if at is None:
            return 0.5 * sum(ends.values())
        if at not in ends:
            raise KeyError(f"axial_force: link {k}'s pins are {list(ends)}, got at={at!r}")
        return ends[at]

    def centre_of_oscillation(self, k: int) -> CentreOfOscillation:
        """Centre of oscillation K of link k and l_SK, m (seed 000 sec. 4).

        Rotation about a fixed axis O: the inertia resultant passes through K on the line OS,
        beyond S, l_SK = rho_S^2 / l_OS with rho_S^2 = I_S / m. In general plane motion the same
        holds with O replaced by the centre of accelerations Q (the point of zero acceleration,
        S - Q = a_S / (i eps - omega^2)): K = S + rho_S^2 (S - Q) / |S - Q|^2, on the line of
        the single resultant (`inertia(k)`). Translation: K = S; a_S = 0 (a pure couple): inf.
        NaN for a link without mass."""
        k = self._link(k)
        mass, I_S, _ = self.mech.inertia_arrays
        com = self.mech.links[k].com
        S, aS = (as_z(self.position(com)), as_z(self.acceleration(com))) if com else \
            (self.kin.origin_z[:, k], self.kin.a_z[:, k])
        rho2 = I_S[k] / mass[k] if mass[k] > 0 else np.nan
        w, e = self.kin.omega[:, k], self.kin.eps[:, k]
        with np.errstate(divide="ignore", invalid="ignore"):
            SK = rho2 * np.conj(1j * e - w**2) / np.conj(aS)        # rho^2 (S - Q) / |S - Q|^2
        SK[(aS == 0) & (rho2 != 0)] = np.inf
        K = as_xy(S + np.where(np.isinf(SK), 0.0, SK))
        K[np.isinf(SK)] = np.inf
        return CentreOfOscillation(K, np.abs(SK))

    @property
    def friction_power_total(self) -> np.ndarray:
        """(N,) total power lost in friction, W."""
        return self.friction_power.sum(axis=1)

    def friction_energy(self) -> np.ndarray:
        """(n_pairs,) energy lost in each pair over one revolution, J: the integral of its power
        over the crank angle (`_cycle_integral`). Needs the angles of a uniform full cycle, as
        `analyze(mech, steps=N)` gives. NaN, with an UndefinedFigureWarning, where some angle of the
        integral has no equilibrium with friction."""
        E = self._cycle_integral(lambda r: r._friction_power(r._unit_motion()), "friction_energy")
        self._warn_undefined("friction_energy", self._unsolved_in_cycle())
        return E

    def _friction_power(self, kin: Kinematics) -> np.ndarray:
        """(N, n_pairs) power lost in each pair at the motion `kin` (the same angles), W: from the
        friction loads of the exact solution, or seed 003's formulas on the frictionless reactions."""
        if self.friction is None:
            return friction_power(self.mech, kin, self.forces.R)
        return _friction.power(self.mech, kin, self.friction.load)

    @property
    def friction_method(self) -> str:
        """"reactions" (friction in the reactions, exact), "first" (seed 003's first approximation:
        frictionless reactions and M_bal, friction power from them) or "none" (no [friction])."""
        return "none" if self.mech.friction is None else "first" if self.friction is None else "reactions"

    @property
    def balancing_moment_frictionless(self) -> np.ndarray:
        """(N,) balancing moment without friction, N m about +z."""
        return self.balancing_moment if self.friction is None else self.friction.M_bal_frictionless

    @property
    def balancing_moment_with_friction(self) -> np.ndarray:
        """(N,) balancing moment with friction, N m about +z: the exact one with friction in the
        reactions; in the first approximation M_bal + (total friction power) / omega_1 (the drive
        supplies the losses on top, seed 003), M_bal where the crank stands still."""
        if self.friction is not None or self.mech.friction is None:
            return self.balancing_moment
        w = self.kin.omega[:, 1]
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(w != 0, self.balancing_moment + self.friction_power_total / w, self.balancing_moment)

    def _turn(self) -> np.ndarray:
        """(N,) sign of the crank's rotation (the drive's sense where it stands still)."""
        w = np.sign(self.kin.omega[:, 1])
        return np.where(w != 0, w, self.mech.drive.sense)

    def _eta(self) -> np.ndarray:
        """(N,) eta by its rule everywhere (`friction.efficiency`), before the dead centres and the
        wedged angles are made NaN: its sign decides self-locking."""
        R = np.linalg.norm(self.forces.R, axis=-1).max(axis=1, initial=0.0)
        return _friction.efficiency(self.balancing_moment_frictionless, self.balancing_moment_with_friction,
                                    self._turn(), 1e-12 * R * self.mech.size)

    @property
    def efficiency(self) -> np.ndarray:
        """(N,) instantaneous efficiency eta(phi), 1: M0 / Mf where the drive works against the
        loads (M0 omega_1 >= 0), Mf / M0 where the loads drive the crank (an engine's expansion
        stroke), M0 and Mf the balancing moments without and with friction
        (`balancing_moment_with_friction`: the first approximation's where friction is not in the
        reactions; 1 without friction). Undefined (NaN) near a dead centre, where
        |M0| <= friction.DEAD_CENTRE x |Mf - M0| (the frictionless moment below a tenth of the
        moment friction takes: a ratio ruled by the vanishing M0, |eta| above about 10 or below
        0.09)
        or where both moments are rounding (below 1e-12 x the largest reaction x size); NaN where
        no equilibrium was found and where a pair wedges (`self_locking_reason`); `efficiency_reason`
        says why at each angle."""
        return np.where(self.efficiency_reason != "", np.nan, self._eta())

    @property
    def efficiency_reason(self) -> np.ndarray:
        """(N,) str: why `efficiency` is undefined (NaN) at each angle, "" where it is a number."""
        eta = self._eta()
        M0, Mf = self.balancing_moment_frictionless, self.balancing_moment_with_friction
        with np.errstate(invalid="ignore"):
            dead = np.abs(M0) <= _friction.DEAD_CENTRE * np.abs(Mf - M0)
        why = np.where(np.isnan(eta), "the balancing moment is NaN", "")
        why = np.where(np.isnan(eta) & np.isfinite(M0) & np.isfinite(Mf),
                       "both balancing moments at rounding level (a dead centre)", why)
        why = np.where(dead, f"near a dead centre (the frictionless balancing moment at most {_friction.DEAD_CENTRE:g} of "
                             "the moment friction takes)", why)
        if self.friction is not None:
            why = np.where(self.friction.wedged, "a pair wedges (friction gain >= 1: the equilibrium is not unique)", why)
            why = np.where(~self.friction.solved, "no equilibrium with friction (self-locking)", why)
        return np.where(self.singular, "singular position (its values NaN)", why).astype(object)

    @property
    def self_locking(self) -> np.ndarray:
        """(N,) bool: eta <= 0 by its rule (also where `efficiency` reports NaN near a dead
        centre), or, with friction in the reactions, a pair wedges or no equilibrium is found
        (`self_locking_reason` says which; a SelfLockingWarning names every such angle)."""
        return self.self_locking_reason != ""

    @property
    def self_locking_reason(self) -> np.ndarray:
        """(N,) str: why each angle is self-locking, "" where it is not. "no equilibrium": neither
        the friction passes nor Newton's method find one (M_bal and the forces NaN); "wedged": a
        pair's friction gain is >= 1 (`friction.FrictionSolution.wedged`), an equilibrium exists
        but not a unique one (M_bal is the one reached from the frictionless solution, eta NaN);
        "eta<=0": the loads cannot drive the crank through friction (M_bal the equilibrium, the
        drive must help)."""
        with np.errstate(invalid="ignore"):
            why = np.where(self._eta() <= 0, "eta<=0", "")
        if self.friction is not None:
            why = np.where(self.friction.wedged, "wedged", why)
            why = np.where(~self.friction.solved, "no equilibrium", why)
        return np.where(self.singular, "", why).astype(object)

    def self_locking_zones(self, tol_deg: float = 1e-9) -> np.ndarray:
        """(n_zones, 2) start and end of each run of self-locking angles, deg, start < end (a zone
        across 0 starts below 0 on a full cycle), its edges found to `tol_deg` by bisection on the
        crank angle between the angles of this result (re-solved at the same friction method).
        On a uniform full cycle the angles wrap around; a zone narrower than the step between
        two angles of the result can be missed."""
        phi, lock = np.asarray(self.phi_deg, float), self.self_locking
        cyclic = len(phi) > 1 and np.allclose(np.diff(phi), 360.0 / len(phi), rtol=0, atol=1e-9)
        nxt = np.arange(1, len(phi) + 1) % len(phi) if cyclic else np.arange(1, len(phi))
        lo = phi[:len(nxt)]
        hi = np.where(nxt > np.arange(len(nxt)), phi[nxt], phi[nxt] + 360.0)
        cut = np.flatnonzero(lock[:len(nxt)] != lock[nxt])
        lo, hi, rising = lo[cut], hi[cut], ~lock[cut]
        method = "reactions" if self.friction is not None else "first"
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", SelfLockingWarning)
            while len(lo) and (hi - lo).max() > tol_deg:
                mid = 0.5 * (lo + hi)
                at = exact(self.mech, mid, method).self_locking
                left = at == ~rising                # mid on the side of lo
                lo, hi = np.where(left, mid, lo), np.where(left, hi, mid)
        edge = 0.5 * (lo + hi)
        starts, ends = list(edge[rising]), list(edge[~rising])
        if lock[0] and not cyclic:
            starts.insert(0, phi[0])
        if lock[-1] and not cyclic:
            ends.append(phi[-1])
        if cyclic and starts and ends and ends[0] < starts[0]:
            starts = [starts[-1] - 360.0] + starts[:-1]
        return np.array(list(zip(starts, ends)), float).reshape(-1, 2)

    def cycle_efficiency(self) -> float:
        """Efficiency over one revolution, 1: the same rule as `efficiency` over the works of the
        balancing moment without (W0) and with (Wf) friction: W0 / Wf where the drive does work
        on the loads over the cycle (W0 > 0), Wf / W0 where the loads drive it (an engine).
        Needs a uniform full cycle of angles. NaN, with an UndefinedFigureWarning saying why
        (`cycle_efficiency_reason`), where the loads do no net work over the cycle (|W0| at
        rounding level, `friction.cycle_efficiency`) or some angle has no equilibrium."""
        eta, why = self._cycle_efficiency
        self._warn_undefined("cycle_efficiency", why)
        return eta

    def cycle_efficiency_reason(self) -> str:
        """Why `cycle_efficiency` is NaN ("" where it is a number), without a warning: the cause,
        then its figures in parentheses."""
        return self._cycle_efficiency[1]

    @cached_property
    def _cycle_efficiency(self) -> tuple[float, str]:
        """The cycle efficiency and why it is undefined ("" where it is not)."""
        def drive(r: Analysis) -> np.ndarray:
            w1 = r._unit_motion().omega[:, 1]
            P0 = r.balancing_moment_frictionless * w1
            return np.stack([P0, r.balancing_moment_with_friction * w1, np.abs(P0)], -1)
        W0, Wf, scale = self._cycle_integral(drive, "cycle_efficiency")
        eta = _friction.cycle_efficiency(W0, Wf, scale)
        why = self._unsolved_in_cycle()
        if not why and not np.isfinite(W0 + Wf + scale):
            why = "the drive's work over the cycle is not finite (NaN at singular positions)"
        elif not why and np.isnan(eta):
            why = (f"the loads do no net work over the cycle (the frictionless drive's work {W0:.3g} J is rounding "
                   f"of the {scale:.3g} J it moves to and fro)")
        return eta, why

    @staticmethod
    def _warn_undefined(who: str, why: str) -> None:
        """An UndefinedFigureWarning: `who` is NaN because `why` (nothing where `why` is "")."""
        if why:
            warnings.warn(UndefinedFigureWarning(f"{who}: undefined (NaN): {why}", why), stacklevel=3)

    def _unsolved_in_cycle(self) -> str:
        """"" where every angle of the cycle integrals (`_cycle_nodes`) has an equilibrium, else
        how many have none, and where."""
        at = self._cycle_nodes[0]
        if at.friction is None or at.friction.solved.all():
            return ""
        phi = np.mod(at.phi_deg[~at.friction.solved], 360.0)
        return (f"no equilibrium with friction at some angles of the cycle ({len(phi)} of its {len(at.phi_deg)} "
                f"integration angles, phi = {phi.min():.6g} .. {phi.max():.6g} deg; self-locking)")

    def _unit_motion(self) -> Kinematics:
        """The motion at the same angles at unit crank speed (d phi/dt = 1 rad/s): its velocities
        are d/d phi, so a load's power there is its work per radian of crank turn."""
        return kinematics(self.mech, np.radians(self.phi_deg), unit_speed=True)

    def _cycle_integral(self, integrand: Callable[["Analysis"], np.ndarray], who: str) -> np.ndarray:
        """Integral over one revolution of a work per radian of crank turn, `integrand(res)` (N, ...)
        J/rad of a result at N angles (a power at unit crank speed), J. Over the crank angle, not
        time: defined at any speed law, standstill included. Needs this result's angles to be a
        uniform full cycle (ValueError naming `who` otherwise).

        Without [friction]: the periodic trapezoid rule on this result's angles (spectrally
        accurate for a smooth periodic integrand). With [friction] the integrand jumps or kinks
        where a pair's relative motion changes sign (the friction turns), and kinks at the knots
        of a load's crank-angle table: it is integrated piecewise between these angles
        (`_breakpoints`), CYCLE_NODES Gauss-Legendre nodes a piece, at which the mechanism is
        solved again by the same method. Kinks it does not find (a travel table's knots, a
        characteristic) leave the rule's algebraic error there."""
        phi = self.phi_deg
        if not np.allclose(phi, phi[0] + np.arange(len(phi)) * 360.0 / len(phi), rtol=0, atol=1e-9):
            raise ValueError(f"{who}: needs the angles of a uniform full cycle (analyze with steps=N)")
        at, weights = self._cycle_nodes
        if weights is None:
            return integrand(self).mean(axis=0) * 2 * np.pi
        return np.tensordot(weights, integrand(at), axes=(0, 0))

    @cached_property
    def _cycle_nodes(self) -> tuple["Analysis", np.ndarray | None]:
        """The result at the angles of the cycle integrals and their weights, rad (`_cycle_integral`):
        this result and None (the periodic trapezoid rule), or the Gauss-Legendre nodes between
        the `_breakpoints` solved again by the same method."""
        edges = self._breakpoints if self.mech.friction is not None else np.empty(0)
        if not len(edges):
            return self, None
        x, w = np.polynomial.legendre.leggauss(CYCLE_NODES)
        lo, hi = edges, np.append(edges[1:], edges[0] + 360.0)
        nodes = (0.5 * (lo + hi)[:, None] + 0.5 * (hi - lo)[:, None] * x).ravel()
        weights = (np.radians(0.5 * (hi - lo))[:, None] * w).ravel()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", SelfLockingWarning)
            warnings.simplefilter("ignore", SingularPositionWarning)
            at = exact(self.mech, nodes, "reactions" if self.friction is not None else "first")
        return at, weights

    @cached_property
    def _breakpoints(self) -> np.ndarray:
        """(n,) sorted crank angles in [phi_0, phi_0 + 360), deg, where a cycle integrand with
        friction is not smooth: each sign change of a pair's relative motion (the friction turns)
        or of a prismatic pair's normal force (f |N| kinks) between two of this result's angles,
        found by bisection to BREAK_TOL_DEG (re-solved by the same method; two changes between
        the same two angles are missed), and each knot of a load's crank-angle table."""
        m, phi0 = self.mech, float(self.phi_deg[0])
        phi = np.asarray(self.phi_deg, float)
        method = "reactions" if self.friction is not None else "first"

        def signs(a: np.ndarray, c: np.ndarray) -> np.ndarray:
            """(len(a),) the sign of column c (`s` below) at the angles a: a pair's relative motion
            (kinematics only), or a prismatic pair's normal force (solved again)."""
            out = np.sign(relative_rate(m, kinematics(m, np.radians(a), unit_speed=True))[0][np.arange(len(a)), c % n])
            force = c >= n
            if force.any():
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore", SelfLockingWarning)
                    warnings.simplefilter("ignore", SingularPositionWarning)
                    out[force] = np.sign(exact(m, a[force], method).forces.normal[np.arange(force.sum()), c[force] - n])
            return out
        n = len(m.pairs)
        s = np.sign(np.concatenate([relative_rate(m, self._unit_motion())[0],
                                    np.where([p.kind == "P" for p in m.pairs], self.forces.normal, 0.0)], axis=1))
        s_next = np.roll(s, -1, axis=0)
        k, c = np.nonzero(s * s_next < 0)
        lo, hi = phi[k], phi[k] + 360.0 / len(phi)
        while len(lo) and (hi - lo).max() > BREAK_TOL_DEG:
            mid = 0.5 * (lo + hi)
            left = signs(mid, c) == s[k, c]
            lo, hi = np.where(left, mid, lo), np.where(left, hi, mid)
        k0, _ = np.nonzero((s == 0) & (np.roll(s, 1, axis=0) * s_next < 0))     # a zero at one of the angles
        knots = [np.asarray(ld.table.x, float) for ld in m.loads if ld.table is not None and ld.table.argument == "phi"]
        found = np.concatenate([0.5 * (lo + hi), phi[k0], *knots])
        at = np.sort(phi0 + np.mod(found - phi0, 360.0))
        keep = np.append(True, np.diff(at) > 1e-9) & (at < phi0 + 360.0 - 1e-9)   # one of two within 1e-9 deg
        return at[keep] if len(at) else at

    def work(self) -> Mapping[str, float]:
        """Work of each load over one revolution, J (positive: the load drives the mechanism): the
        integral over the crank angle of its power per unit crank speed, F . dv/dphi + M
        d omega/dphi (the same as the time integral of F . v + M omega where the crank turns, and
        defined at standstill, as the texts' J per revolution). Needs a uniform full cycle of angles;
        with friction in the reactions, NaN entries and an UndefinedFigureWarning where some angle of
        the integral has no equilibrium.

        Keys: "gravity k" and "inertia k" per link with mass or inertia (inertia: F_i = -m a_S at
        S and M_i = -I_S eps; -(change of kinetic energy), 0 over a steady cycle); "load NAME"
        per applied force or moment (loads of one name summed); "spring NAME" (both ends);
        "damper NAME" (both links: -(energy dissipated)); "balancing moment" (M_bal omega_1; for
        a working machine the pinion's force, the same power); with friction "friction R(i,j)" per
        pair, the energy lost (negative). With friction in the reactions every entry sums to 0 (to
        rounding); in the first approximation the balancing moment is frictionless: every entry
        but friction sums to 0 at any speed law, and the friction entries are what the drive must
        supply on top (seed 003)."""
        names = list(self._work_per_radian())
        W = self._cycle_integral(lambda r: np.stack(list(r._work_per_radian().values()), axis=-1), "work")
        self._warn_undefined("work", self._unsolved_in_cycle())
        return MappingProxyType(dict(zip(names, W.tolist())))

    def _work_per_radian(self) -> dict[str, np.ndarray]:
        """Each load's work per radian of crank turn at this result's angles (`work`), J/rad."""
        m, kin, u = self.mech, self.kin, self._unit_motion()
        per_radian: dict[str, np.ndarray] = {}

        def add(name: str, P: np.ndarray) -> None:
            per_radian[name] = per_radian.get(name, 0.0) + P

        r, _ = com_motion(m, kin)
        vS = u.v_z + 1j * u.omega * r
        mass, I_S, _ = m.inertia_arrays
        for k in range(1, m.n_links):
            if mass[k]:
                add(f"gravity {k}", -m.g * mass[k] * vS[:, k].imag)
            if mass[k] or I_S[k]:
                il = self.inertia(k)
                add(f"inertia {k}", dot_z(as_z(il.force), vS[:, k]) + il.moment * u.omega[:, k])
        for ld in m.loads:
            if ld.kind == "moment":
                add(f"load {ld.name}", applied_moment(m, kin, ld) * u.omega[:, ld.link])
            elif ld.kind == "damper" and m.pair_between(*ld.pair).kind == "R":
                i, j = ld.pair
                add(f"damper {ld.name}", load_magnitude(m, kin, ld) * (u.omega[:, j] - u.omega[:, i]))
        for f in point_forces(m, kin):
            v = u.v_z[:, f.link] + 1j * u.omega[:, f.link] * (f.X - u.origin_z[:, f.link])
            add(f"{f.source} {f.name}", dot_z(f.force, v))
        add("balancing moment", self.balancing_moment * u.omega[:, 1])
        if m.friction is not None:
            lost = self._friction_power(u)
            for p in m.pairs:
                add(f"friction {p.label}", -lost[:, p.index])
        return per_radian

    # -- table
    def to_frame(self):
        """The whole analysis as a pandas DataFrame, one row per crank angle: the columns of
        `columns`. `df.attrs["units"]` maps every column to its unit ("1": dimensionless, "bool": a
        flag); `df.attrs["frame"]` states the frame and sign conventions; `df.attrs["mechanism"]` the
        model's name."""
        import pandas as pd
        cols, units = self.columns()
        df = pd.DataFrame(cols)
        df.attrs.update(mechanism=self.mech.name, units=units, frame=FRAME_NOTE)
        return df

    def columns(self) -> tuple[dict[str, np.ndarray], dict[str, str]]:
        """The whole analysis as columns over the crank angles (name -> (N,) array) and each
        column's unit (name -> unit; "1": dimensionless, "bool": a flag), in `to_frame`'s order.

        Columns (unit in brackets): phi_deg [deg]; for every point P x_P, y_P [m], vx_P, vy_P
        [m/s], ax_P, ay_P [m/s^2]; for every moving link k theta_k [rad], omega_k [rad/s], eps_k
        [rad/s^2]; for every link with mass or inertia Fix_k, Fiy_k [N] (inertia main vector at
        the centre of mass), Mi_k [N m] (main moment), h_k [m] (offset of the single resultant);
        for every link with mass xK_k, yK_k, lSK_k [m] (centre of oscillation K of the inertia
        resultant, |SK|); for every pair Rx_i_j, Ry_i_j, R_i_j [N] (force of link i on link j, its
        magnitude), angle_R_i_j [deg] (its direction from +x, counter-clockwise); for
        prismatic pairs also x_i_j [m] and m_i_j [N m] (line of the normal force, its moment
        about the slider point), vs_i_j [m/s] and as_i_j [m/s^2] (sliding velocity and
        acceleration); Fax_k [N] for every two-pin link (axial force, tension positive, the mean of
        its two ends: `axial_force`); M_bal, M_lever [N m]; for a working machine F_balx, F_baly, F_bal [N]; with
        friction Pfr_i_j per pair and Pfr_total [W], eta [1] (`efficiency`), self_locking [bool],
        and with friction in the reactions Ffr_i_j per pair (friction moment on link j [N m] in
        a revolute pair, friction force on the slider along the guide [N] in a prismatic one) and
        M_bal_0 [N m] (the frictionless balancing moment) and passes [1] (the most friction passes
        of a group at that angle, `FrictionSolution.passes`); cond_<group> [1] per Assur group;
        singular [bool]. Vectors are in the world frame (x right, y up, gravity along -y), moments
        and angles about +z.
        """
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
                if link.mass:
                    K = self.centre_of_oscillation(link.id)
                    put("m", **{f"xK_{link.id}": K.point[:, 0], f"yK_{link.id}": K.point[:, 1], f"lSK_{link.id}": K.l_SK})
        for p in m.pairs:
            ij = f"{p.links[0]}_{p.links[1]}"
            R = self.forces.R[:, p.index]
            put("N", **{f"Rx_{ij}": R[:, 0], f"Ry_{ij}": R[:, 1], f"R_{ij}": np.linalg.norm(R, axis=-1)})
            put("deg", **{f"angle_R_{ij}": self.reaction_angle(*p.links)})
            if p.kind == "P":
                put("m", **{f"x_{ij}": self.forces.x[:, p.index]})
                put("N m", **{f"m_{ij}": self.forces.m[:, p.index]})
                put("m/s", **{f"vs_{ij}": self.kin.v_slide[:, p.index]})
                put("m/s^2", **{f"as_{ij}": self.kin.a_slide[:, p.index]})
        for link in m.links[1:]:
            try:
                put("N", **{f"Fax_{link.id}": self.axial_force(link.id)})
            except KeyError:        # not a two-pin link
                pass
        put("N m", M_bal=self.balancing_moment, M_lever=self.lever_moment)
        if m.drive.kind == "machine":
            F = self.balancing_force
            put("N", F_balx=F[:, 0], F_baly=F[:, 1], F_bal=np.linalg.norm(F, axis=-1))
        if m.friction is not None:
            put("W", **{f"Pfr_{p.links[0]}_{p.links[1]}": self.friction_power[:, p.index] for p in m.pairs})
            put("W", Pfr_total=self.friction_power_total)
            if self.friction is not None:
                for p in m.pairs:
                    put("N m" if p.kind == "R" else "N", **{f"Ffr_{p.links[0]}_{p.links[1]}": self.friction.load[:, p.index]})
                put("N m", M_bal_0=self.balancing_moment_frictionless)
                put("1", passes=self.friction.passes.max(axis=1))
            put("1", eta=self.efficiency)
            put("bool", self_locking=self.self_locking)
        put("1", **{f"cond_{g.label}": self.cond[:, n] for n, g in enumerate(m.structure.groups)})
        put("bool", singular=self.singular)
        return cols, units

    # -- labelled arrays
    def to_xarray(self):
        """The whole analysis as an xarray Dataset (the optional extra: pip install 'kinetostat[xarray]').

        Dimensions: `phi` (crank angle, deg: from the drive's reference direction in its sense,
        both in the coordinate's attrs), `point` (the model's point names; `point_link` its
        link), `link` (the moving links' ids; `link_name`), `pair` (each pair as the outputs name
        it, `pair_name`: "R12 at A"; `i`, `j` the model's link ids of R_ij, `pair_kind` R or P),
        `xy` (x, y of a world vector), `group` (the Assur groups).

        Variables (every one with attrs units, frame, long_name): position, velocity,
        acceleration (phi, point, xy) [m, m/s, m/s^2]; theta, omega, eps (phi, link) [rad,
        rad/s, rad/s^2]; F_applied (phi, link, xy) [N], M_applied (phi, link) [N m] (applied
        loads without inertia, the moment about the link's local origin); F_i (phi, link, xy)
        [N], M_i (phi, link) [N m] (inertia main vector at the centre of mass, main moment); R
        (phi, pair, xy) [N] (force exerted by link i on link j); M_bal, M_lever (phi) [N m]; for a
        working machine F_bal (phi, xy) [N]; with friction P_fr (phi, pair) [W], eta (phi) [1],
        self_locking (phi) [bool], and with friction in the reactions M_bal_0 (phi) [N m], M_fr
        (phi, revolute_pair) [N m] (friction moment on link j) and F_fr (phi, prismatic_pair) [N]
        (friction force on the slider along the guide); error (phi) [1] (the singular guard's
        estimate of the relative error), singular (phi) [bool], cond (phi, group) [1].
        The arrays are the Analysis' own (read-only). `attrs`: mechanism, model_file, g [m/s^2],
        drive, friction_method, conventions.
        """
        xr = _xarray()
        m, world = self.mech, "world"
        moving = [link.id for link in m.links[1:]]
        pairs = list(m.pairs)
        order = [p.index for p in pairs]
        by_point = [self._point(name) for name in m.point_names]
        sense = "counter-clockwise" if m.drive.sense > 0 else "clockwise"
        reference = f"({m.drive.reference[0]:g}, {m.drive.reference[1]:g}) in the world frame"
        coords = {
            "phi": _labelled("phi", self.phi_deg, "deg", world, "crank angle", reference_direction=reference,
                             sense=sense),
            "point": ("point", m.point_names), "point_link": ("point", [m.point_owner(n) for n in m.point_names]),
            "link": ("link", moving), "link_name": ("link", [m.links[k].name for k in moving]),
            "pair": ("pair", [pair_name(m, p) for p in pairs]),
            "i": ("pair", [p.links[0] for p in pairs], {"long_name": "id of the link exerting R"}),
            "j": ("pair", [p.links[1] for p in pairs], {"long_name": "id of the link R acts on"}),
            "pair_kind": ("pair", [p.kind for p in pairs]),
            "xy": ("xy", ["x", "y"]),
            "group": ("group", [g.label for g in m.structure.groups])}
        vectors, links, angle = ("phi", "point", "xy"), ("phi", "link"), ("phi",)
        data = {
            "position": _labelled(vectors, np.stack([k[0] for k in by_point], axis=1), "m", world, "position of the point"),
            "velocity": _labelled(vectors, np.stack([k[1] for k in by_point], axis=1), "m/s", world, "velocity of the point"),
            "acceleration": _labelled(vectors, np.stack([k[2] for k in by_point], axis=1), "m/s^2", world,
                                      "acceleration of the point"),
            "theta": _labelled(links, self.kin.theta[:, moving], "rad", world,
                               "angle of the link's local frame from the world x axis, about +z"),
            "omega": _labelled(links, self.kin.omega[:, moving], "rad/s", world, "angular velocity, about +z"),
            "eps": _labelled(links, self.kin.eps[:, moving], "rad/s^2", world, "angular acceleration, about +z"),
            "F_applied": _labelled(links + ("xy",), self.F_applied[:, moving], "N", world,
                                   "applied loads without inertia: their resultant force"),
            "M_applied": _labelled(links, self.M_applied[:, moving], "N m", world,
                                   "applied loads without inertia: their moment about the link's local origin, about +z"),
            "F_i": _labelled(links + ("xy",), self.F_i[:, moving], "N", world,
                             "inertia main vector -m a_S, at the centre of mass"),
            "M_i": _labelled(links, self.M_i[:, moving], "N m", world, "inertia main moment -I_S eps, about +z"),
            "R": _labelled(("phi", "pair", "xy"), self.forces.R[:, order], "N", world,
                           "reaction: force exerted by link i on link j in the pair"),
            "M_bal": _labelled(angle, self.balancing_moment, "N m", world,
                               "balancing moment: the moment the drive applies to the crank, about +z"),
            "M_lever": _labelled(angle, self.lever_moment, "N m", world, "balancing moment by Zhukovsky's lever"),
            "error": _labelled(angle, self.error, "1", "none",
                               "estimated relative error of the values (the singular guard; inf where singular)"),
            "singular": _labelled(angle, self.singular, "bool", "none", "a group at a singular position (values NaN)"),
            "cond": _labelled(("phi", "group"), self.cond, "1", "none", "condition number of the group's plan")}
        if m.drive.kind == "machine":
            data["F_bal"] = _labelled(("phi", "xy"), self.balancing_force, "N", world,
                                      "balancing force of the pinion on the crank's gear, at the pitch point")
        if m.friction is not None:
            data.update(
                P_fr=_labelled(("phi", "pair"), self.friction_power[:, order], "W", "none", "power lost in the pair (>= 0)"),
                eta=_labelled(angle, self.efficiency, "1", "none", "instantaneous efficiency"),
                self_locking=_labelled(angle, self.self_locking, "bool", "none", "self-locking at this angle"))
        if self.friction is not None:
            data["M_bal_0"] = _labelled(angle, self.balancing_moment_frictionless, "N m", world,
                                        "balancing moment without friction, about +z")
            for kind, name, dim, unit, meaning in (("R", "M_fr", "revolute_pair", "N m", "friction moment on link j, about +z"),
                                                   ("P", "F_fr", "prismatic_pair", "N",
                                                    "friction force on the slider, along the guide")):
                these = [p for p in pairs if p.kind == kind]
                if these:
                    coords[dim] = (dim, [pair_name(m, p) for p in these])
                    data[name] = _labelled(("phi", dim), self.friction.load[:, [p.index for p in these]], unit, world,
                                           meaning)
        method = "reactions" if self.friction is not None else "first" if m.friction is not None else "none"
        return xr.Dataset(data, coords=coords, attrs={
            "mechanism": m.name, "model_file": m.path or "", "g": m.g, "g_units": "m/s^2", "drive": m.drive.kind,
            "friction_method": method, "conventions": DATASET_NOTE})


def _xarray():
    """The xarray module, or an ImportError naming the optional extra that installs it."""
    try:
        import xarray
    except ImportError:
        raise ImportError("to_xarray needs xarray, an optional extra: pip install 'kinetostat[xarray]'",
                          name="xarray") from None
    return xarray


def _labelled(dims, values, units: str, frame: str, long_name: str, **more: str) -> tuple:
    """An xarray variable (dims, values, attrs) that says its unit, its frame ("world", or
    "none" for a quantity of no direction) and what it is."""
    return dims, values, {"units": units, "frame": frame, "long_name": long_name, **more}


def crank_angles(phi_deg=None, steps: int = 360) -> np.ndarray:
    """The crank angles asked for, deg, as a read-only (N,) copy: `phi_deg` (array-like), or
    `steps` equal steps over a full revolution when it is None. ValueError naming the argument.
    Any finite angle is accepted as given: an angle outside [0, 360) is the crank position of
    that angle modulo 360 (a run over several turns, a finite difference across 0 keep their
    angle axis); the command line takes a typed angle modulo 360 and says so."""
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
    return phi_deg


def friction_method(mech: Mechanism, friction: str | None) -> str:
    """The friction method `analyze` takes: `friction`, else the model's, else "first";
    ValueError naming the argument if it is not one of friction.METHODS."""
    method = friction if friction is not None else mech.friction.method if mech.friction is not None else "first"
    if method not in _friction.METHODS:
        raise ValueError(f"friction: expected one of {list(_friction.METHODS)}, got {friction!r}")
    return method


def exact(mech: Mechanism, phi_deg: np.ndarray, friction: str = "first") -> Analysis:
    """`analyze` by the numpy path at the crank angles `phi_deg` (deg, (N,)), with the accuracy
    guard: where a group's cond exceeds COND_CHECK the error is measured by perturbed re-solves.
    `friction`: "first" or "reactions" (see `analyze`); a SelfLockingWarning names the angles
    where friction in the reactions leaves no equilibrium, and a SingularFrictionWarning those of
    them where Newton's Jacobian is singular, with the pairs whose friction loads it found dependent."""
    reactions = friction == "reactions" and mech.friction is not None
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):   # NaN only at angles marked singular
        kin, checked, trials = solve_checked(mech, np.radians(phi_deg))
        res = _kinetostatics(mech, phi_deg, kin, reactions)
        error = a_priori_error(kin.cond)
        if len(checked):
            nominal = res.take(checked)
            error[checked] = np.max([deviation(nominal, _kinetostatics(mech, phi_deg[checked], t, reactions))
                                     for t in trials], axis=0)
        kin = guard(mech, kin, error)
        res = _kinetostatics(mech, phi_deg, kin, reactions) if kin.singular.any() else replace(res, kin=kin)
    if res.friction is not None and res.self_locking.any():
        why = res.self_locking_reason
        warnings.warn(SelfLockingWarning(self_locking_message(phi_deg[why != ""], why[why != ""]),
                                         phi_deg[why != ""], why[why != ""]), stacklevel=3)
        tied = res.friction.dependent & ~res.singular[:, None]
        if tied.any():
            at = tied.any(axis=1)
            names = [tuple(pair_name(mech, p) for p in mech.pairs if row[p.index]) for row in tied[at]]
            warnings.warn(SingularFrictionWarning(singular_friction_message(phi_deg[at], names), phi_deg[at], names),
                          stacklevel=3)
    return _read_only(res)


def force_deviation(a: Analysis, b: Analysis) -> np.ndarray:
    """(N,) how far b's forces are from a's: the largest change of any reaction over the force
    scale at that angle (the largest reaction, applied or inertia force), and of the balancing
    moment (and force) over max(|M_bal|, that scale x kinematic_size)."""
    R = np.max([np.linalg.norm(x, axis=-1).max(axis=1, initial=0.0) for x in (a.forces.R, a.F_applied, a.F_i)], axis=0)
    dR = np.linalg.norm(b.forces.R - a.forces.R, axis=-1)
    return np.max([relative_change(dR, 0.0, R[:, None]),
                   relative_change(b.forces.M_bal, a.forces.M_bal, R * kinematic_size(a.mech)),
                   relative_change(b.forces.F_bal, a.forces.F_bal, R[:, None])], axis=0)


def deviation(a: Analysis, b: Analysis) -> np.ndarray:
    """(N,) the measure of `Analysis.error`: max of the kinematic and the force deviation."""
    return np.maximum(kinematic_deviation(a.mech, a.kin, b.kin), force_deviation(a, b))


def _kinetostatics(mech: Mechanism, phi_deg: np.ndarray, kin: Kinematics, reactions: bool = False) -> Analysis:
    """The forces at the motion `kin`; `reactions`: with friction in the reactions."""
    mass, I_S, com = mech.inertia_arrays
    r, F_i, M_i = groups.inertia(kin.a_z, kin.omega, kin.eps, kin.rot, com, mass, I_S)
    F_app, M_app = applied_wrenches(mech, kin, r)
    F_all, M_all = groups.wrench(F_app, M_app, F_i, M_i, r)
    frc = forces(mech, kin, F_all, M_all)
    if not reactions:
        return _read_only(Analysis(mech, phi_deg, kin, as_xy(F_app), M_app, as_xy(F_i), M_i, frc,
                                   lever_moment(mech, kin, F_all, M_all), friction_power(mech, kin, frc.R)))
    with np.errstate(all="ignore"):
        frc, sol = _friction.solve(mech, kin, F_all, M_all, frc.M_bal)
    lever = lever_moment(mech, kin, F_all + sol.F, M_all + sol.M)
    return _read_only(Analysis(mech, phi_deg, kin, as_xy(F_app), M_app, as_xy(F_i), M_i, frc, lever,
                               _friction.power(mech, kin, sol.load), sol))


def _read_only(res: Analysis) -> Analysis:
    """`res` with every array it holds (its own, its Kinematics' and Forces') read-only: a
    frozen result whose numbers no caller can change in place."""
    for part in (res, res.kin, res.forces) + (() if res.friction is None else (res.friction,)):
        for f in fields(part):
            value = getattr(part, f.name)
            if isinstance(value, np.ndarray):
                value.flags.writeable = False
    return res
