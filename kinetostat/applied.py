"""Applied loads (seed 000 sec. 2-4): gravity, external forces and moments, springs, inertia.

Every load is reduced to a wrench per link: force F (N, world, complex x + iy) and moment M
(N m, about +z) about the link's local origin, stacked as F (N, L), M (N, L).

May use: numpy, groups, model, kinematics (its results), planar, errors.
"""
from __future__ import annotations

import warnings
from typing import TYPE_CHECKING, Callable, NamedTuple

import numpy as np

from . import groups
from .errors import ModelError, SingularPositionWarning
from .planar import cross_z, dot_z

if TYPE_CHECKING:
    from .kinematics import Kinematics
    from .model import Load, Mechanism

__all__ = ["applied_wrenches", "load_wrenches", "stroke", "com_motion", "inertia_loads", "load_magnitude", "point_forces", "PointForce", "applied_moment",
           "travel", "travel_rates", "forward_stroke"]


def com_motion(mech: "Mechanism", kin: "Kinematics") -> tuple[np.ndarray, np.ndarray]:
    """Arm r from each link's local origin to its centre of mass (N, L) complex, m (0 where a
    link has no centre of mass), and the centres' accelerations a_S (N, L) complex, m/s^2."""
    r = mech.inertia_arrays[2] * kin.rot
    return r, kin.a_z + (1j * kin.eps - kin.omega**2) * r


def inertia_loads(mech: "Mechanism", kin: "Kinematics", aS: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Main vector F_i = -m a_S (N, L) complex, at the centre of mass, and main moment
    M_i = -I_S eps (N, L)."""
    mass, I_S, _ = mech.inertia_arrays
    return -mass * aS, -I_S * kin.eps


def applied_wrenches(mech: "Mechanism", kin: "Kinematics", r: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """All applied loads (gravity, external forces and moments, springs; no inertia) on each link
    as a wrench about its local origin: F (N, L) complex, M (N, L). r: arms to the centres of
    mass (N, L), as `com_motion` gives."""
    weight, M = groups.weight(r, mech.inertia_arrays[0], mech.g)
    F = np.empty(r.shape, complex)
    F[:] = weight
    for k, f, m in load_wrenches(mech, kin):
        if k:
            F[:, k] += f
            M[:, k] += m
        unknown = np.isnan(f)
        if np.any(unknown):                  # e.g. a spring of zero length: every force there is unknown
            F[unknown], M[unknown] = np.nan, np.nan
    return F, M


def load_wrenches(mech: "Mechanism", kin: "Kinematics") -> list[tuple[int, object, object]]:
    """Every applied load but gravity as (link k, force (N,) complex or 0, its moment about link
    k's local origin (N,)), in the order `applied_wrenches` adds them (k = 0: on the frame, kept
    for its NaN). Elementwise: it also runs on `sensitivity.Dual` motions and loads."""
    out: list[tuple[int, object, object]] = []
    for ld in mech.loads:
        if ld.kind == "moment":
            out.append((ld.link, 0.0, applied_moment(mech, kin, ld)))
        elif ld.kind == "damper" and mech.pair_between(*ld.pair).kind == "R":
            m = load_magnitude(mech, kin, ld)            # on link pair[1]; the opposite on pair[0]
            out.append((ld.pair[1], 0.0, m))
            if ld.pair[0]:
                out.append((ld.pair[0], 0.0, -m))
    for f in point_forces(mech, kin):
        out.append((f.link, f.force, cross_z(f.X - kin.origin_z[:, f.link], f.force)))
    return out


def applied_moment(mech: "Mechanism", kin: "Kinematics", ld: "Load") -> np.ndarray:
    """(N,) the moment load `ld` on its link about +z, N m ("against_omega": opposing its rotation)."""
    mag = load_magnitude(mech, kin, ld)
    if ld.direction == "against_omega":
        mag = -np.sign(kin.omega[:, ld.link]) * np.abs(mag)
    return mag


class PointForce(NamedTuple):
    """One applied force at a point of a link, over the angles."""
    name: str            # the load's or spring's name
    link: int
    point: str           # the point of application, as the model names it
    X: np.ndarray        # (N,) complex: its world position, m
    force: np.ndarray    # (N,) complex: the force on `link`, N (world frame)
    source: str = "load"  # what gives it: "load", "spring" or "damper"


def point_forces(mech: "Mechanism", kin: "Kinematics") -> list[PointForce]:
    """Every external force load and both ends of every spring, as forces at points (gravity,
    moments and inertia are not here). A spring of zero length has no line of action: its force
    is NaN there, with a SingularPositionWarning naming the angles."""
    out = []
    for ld in mech.loads:
        if ld.kind == "moment":
            continue
        if ld.kind == "damper":
            out.extend(_damper_forces(mech, kin, ld))
            continue
        p = mech.links[ld.link].points[ld.point]
        X = kin.position_z(ld.link, p)
        needs_v = ld.direction == "against_velocity" or (
            ld.table is not None and ld.table.argument == "travel" and ld.table.value_return is not None)
        V = kin.velocity_z(ld.link, p) if needs_v else None
        mag = load_magnitude(mech, kin, ld, X, V)
        if ld.direction == "against_velocity":
            speed = np.abs(V)
            # at a dead centre the direction is undefined: no force where the speed is rounding
            moving = speed > 1e-9 * mech.size * mech.drive.omega
            e = np.where(moving, -V / np.where(moving, speed, 1.0), 0.0)
        else:
            e = complex(*ld.direction)
        out.append(PointForce(ld.name, ld.link, ld.point, X, mag * e))
    for sp in mech.springs:
        A = kin.position_z(sp.a[0], mech.links[sp.a[0]].points[sp.a[1]])
        B = kin.position_z(sp.b[0], mech.links[sp.b[0]].points[sp.b[1]])
        length = np.abs(B - A)
        if (length == 0).any():     # no line of action: the forces there are NaN, and said so
            warnings.warn(f"spring {sp.name!r} has zero length at phi = "
                          f"{np.round(np.degrees(kin.phi[length == 0]), 9).tolist()} deg: its line of action "
                          f"is undefined, forces there are NaN", SingularPositionWarning, stacklevel=3)
        f_on_b = -sp.stiffness * (length - sp.free_length) * (B - A) / length
        out.append(PointForce(sp.name, sp.b[0], sp.b[1], B, f_on_b, "spring"))
        out.append(PointForce(sp.name, sp.a[0], sp.a[1], A, -f_on_b, "spring"))
    return out


def _damper_forces(mech: "Mechanism", kin: "Kinematics", ld: "Load") -> list[PointForce]:
    """A damper on a prismatic pair: -c v_rel along the guide on the slider at its point, the
    opposite on the guide at the same place ([] for a revolute pair: its moments are couples)."""
    p = mech.pair_between(*ld.pair)
    if p.kind != "P":
        return []
    guide, slider = p.links
    X = kin.position_z(slider, mech.links[slider].points[p.point])
    d = complex(*p.direction) * kin.rot[:, guide] if guide else complex(*p.direction)
    f = -ld.value * kin.v_slide[:, p.index] * d
    return [PointForce(ld.name, slider, p.point, X, f, "damper"), PointForce(ld.name, guide, p.point, X, -f, "damper")]


def load_magnitude(mech: "Mechanism", kin: "Kinematics", ld: "Load", X: np.ndarray | None = None,
                   V: np.ndarray | None = None) -> np.ndarray:
    """Magnitude of load `ld` at every angle: N for a force, N m for a moment. X, V: complex
    position and velocity of the load's point, if the caller has them already."""
    N = len(kin.phi)
    if ld.kind == "damper":           # on link pair[1]: -c (w_j - w_i), or -c v_rel along the guide
        p = mech.pair_between(*ld.pair)
        i, j = ld.pair
        return -ld.value * (kin.omega[:, j] - kin.omega[:, i] if p.kind == "R" else kin.v_slide[:, p.index])
    if ld.characteristic is not None:   # M(omega), both in the drive's sense
        s = mech.drive.sense
        w = s * kin.omega[:, ld.link]
        with np.errstate(all="ignore"):
            M = ld.characteristic(w)
        bad = ~np.isfinite(M) & np.isfinite(w)
        if bad.any():                    # never a silent NaN in M_bal: the speed and angle are named
            raise ModelError([f"load {ld.name!r}: its characteristic M(omega) is not finite at omega = "
                              f"{w[bad][0]:.6g} rad/s (phi = {np.degrees(kin.phi[bad][0]):.6g} deg"
                              + (f" and {int(bad.sum()) - 1} more angles)" if bad.sum() > 1 else ")")],
                             source=mech.path or mech.name)
        return s * M
    if ld.table is None:
        return ld.value + np.zeros(N)
    t = ld.table
    if t.argument == "phi":
        xp, vp = mech.memo(("periodic", id(t)), lambda: (   # the diagram (rad) over [-4 pi, 4 pi]: fmod lands inside
            np.concatenate([np.radians(t.x) + 2 * np.pi * n for n in (-2, -1, 0, 1)]), t.scale * np.tile(t.value, 4)))
        return np.interp(np.fmod(kin.phi, 2 * np.pi), xp, vp)
    xs, fwd, ret = mech.memo(("diagram", id(t)), lambda: (   # scaled once: np.interp converts tuples per call
        np.asarray(t.x), t.scale * np.asarray(t.value),
        None if t.value_return is None else t.scale * np.asarray(t.value_return)))
    s = travel(mech, kin, ld, X)
    return np.interp(s, xs, fwd) if ret is None else np.where(forward_stroke(mech, kin, ld, V), np.interp(s, xs, fwd),
                                                              np.interp(s, xs, ret))


def _travel_axis(ld: "Load") -> complex:
    """The world axis a travel table's stroke is measured along (its own, else the load's direction)."""
    return complex(*(ld.table.axis if ld.table.axis is not None else ld.direction))


def travel(mech: "Mechanism", kin: "Kinematics", ld: "Load", X: np.ndarray | None = None) -> np.ndarray:
    """The travel of load `ld`'s point (a travel table's) from the table's origin at every angle,
    as a fraction of the stroke (0..1): where the diagram is read. X: the point's complex
    position, if the caller has it already. ModelError where the point does not move along the axis."""
    if X is None:
        X = kin.position_z(ld.link, mech.links[ld.link].points[ld.point])
    lo, hi = _stroke_ends(mech, ld)
    s = dot_z(X, _travel_axis(ld))
    return (hi - s) / (hi - lo) if ld.table.origin == "max" else (s - lo) / (hi - lo)


def travel_rates(mech: "Mechanism", kin: "Kinematics", ld: "Load") -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The travel of load `ld`'s point (`travel`, 0..1) and its first two derivatives by the crank
    angle (per rad, per rad^2), from kinematics `kin` at unit crank speed (`unit_speed=True`)."""
    X, V, A = kin.point_z(ld.link, mech.links[ld.link].points[ld.point])
    lo, hi = _stroke_ends(mech, ld)
    scale = (-1.0 if ld.table.origin == "max" else 1.0) / (hi - lo)
    axis = _travel_axis(ld)
    return travel(mech, kin, ld, X), scale * dot_z(V, axis), scale * dot_z(A, axis)


def _stroke_ends(mech: "Mechanism", ld: "Load") -> tuple[float, float]:
    """The extreme projections (m) of load `ld`'s point on its travel axis (memoised);
    ModelError where the point does not move along the axis."""
    lo, hi, _, _ = stroke(mech, ld)
    if not hi - lo > 1e-9 * mech.size:
        n = mech.loads.index(ld)
        raise ModelError([f"load[{n}].table: a travel diagram needs a moving point, but {ld.point!r} of link "
                          f"{ld.link} travels {hi - lo:.3g} m along the axis over the cycle"], source=mech.path or "model")
    return lo, hi


def stroke(mech: "Mechanism", ld: "Load", make: Callable[[], tuple] | None = None) -> tuple:
    """The extreme projections lo, hi (m) of load `ld`'s point on its travel axis over a cycle and
    the crank angles (rad) where the point is there (memoised per mechanism). `make`: what to keep
    instead, where none is kept yet (`sensitivity`: the ends on duals)."""
    p = mech.links[ld.link].points[ld.point]
    axis = _travel_axis(ld)
    return mech.memo(("stroke", ld.link, tuple(p), axis), make or (lambda: _stroke(mech, ld.link, p, axis)))


def forward_stroke(mech: "Mechanism", kin: "Kinematics", ld: "Load", V: np.ndarray | None = None) -> np.ndarray:
    """Whether load `ld`'s point (a travel table's) moves away from the table's origin at every
    angle: the diagram's `value` holds there, its `value_return` elsewhere. V: the point's complex
    velocity, if the caller has it already."""
    v = dot_z(kin.velocity_z(ld.link, mech.links[ld.link].points[ld.point]) if V is None else V, _travel_axis(ld))
    return v <= 0 if ld.table.origin == "max" else v >= 0


def _stroke(mech: "Mechanism", k: int, p, axis: complex) -> tuple[float, float, float, float]:
    """Extreme projections of a point's path on `axis` over a full cycle, m, and their crank
    angles, rad: the dead centres, where ds/dphi = 0, found by Newton's method from a coarse scan
    with the exact plans."""
    from .kinematics import kinematics

    def state(phi):                               # s, ds/dphi, d2s/dphi2
        X, V, A = kinematics(mech, phi, unit_speed=True).point_z(k, p)
        return dot_z(X, axis), dot_z(V, axis), dot_z(A, axis)

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        phi = np.linspace(0.0, 2 * np.pi, 72, endpoint=False)
        s, d1, _ = state(phi)
        turn = np.flatnonzero(np.sign(d1) != np.sign(np.roll(d1, -1)))
        x = phi[turn] + np.pi / 72
        for _ in range(5):
            _, d1x, d2x = state(x)
            x = x - np.where(d2x != 0, d1x / d2x, 0.0)
        sx = state(x)[0] if len(x) else np.empty(0)
    values, angles = np.concatenate([s, sx]), np.concatenate([phi, x])
    lo, hi = np.nanargmin(values), np.nanargmax(values)
    return float(values[lo]), float(values[hi]), float(angles[lo]), float(angles[hi])
