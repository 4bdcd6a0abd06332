"""The machine's own law of motion (issue 38): the inertia and the moments reduced to the crank,
the steady periodic omega(phi) from the energy equation, the coefficient of fluctuation, the
flywheel that holds a given one (exactly, and by the texts' approximate methods), as one frozen
result (`Motion`); `kinetostat.analyze(mech, law=motion)` analyses the machine at it.

Conventions: phi, omega, eps, M_red and M_drive are in the drive's sense (the texts' reduction to
the crank: a moment is positive where it drives the crank forward); about +z they are these times
`mech.drive.sense`. The flywheel sits on the crank shaft, its centre on the crank's axis.

May use: model, kinematics, analysis, applied, planar, errors.
"""
from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field, replace
from types import MappingProxyType
from typing import Mapping

import numpy as np

from .analysis import Analysis, crank_angles, exact
from .applied import applied_moment, com_motion, travel_rates
from .errors import ModelError, SelfLockingWarning, SingularPositionWarning
from .kinematics import Kinematics, kinematics
from .model import Flywheel, Mechanism, SpeedLaw
from .planar import dot_z

__all__ = ["Motion", "Flywheel", "law_of_motion", "at_motion", "GAUSS_NODES", "SPEED_TOL", "MAX_PASSES"]

#: Gauss-Legendre nodes per piece of the work integral (a grid step, cut at a load table's knots).
GAUSS_NODES = 4
#: The fixed point over speed-dependent loads (friction, dampers, characteristics, a motor's
#: M(omega)) stops when omega changes by less than this, relative to omega_mean, between passes.
SPEED_TOL = 1e-12
#: A continuous extreme's angle is refined on the exact energy equation until it moves less than
#: this, deg, or for at most REFINE_PASSES solves (each one for all the extremes sought together).
REFINE_DEG = 1e-9
REFINE_PASSES = 12
#: The most passes of that fixed point before a ValueError says it did not settle.
MAX_PASSES = 200


@dataclass(frozen=True)
class Motion:
    """The steady periodic motion of `mech` with its flywheel, over a uniform cycle of crank
    angles (arrays (N,), read-only). Units SI; angles, speeds and moments in the drive's sense."""
    mech: Mechanism = field(repr=False, compare=False)
    phi_deg: np.ndarray       # (N,) deg, a uniform full cycle from 0
    J_red: np.ndarray         # (N,) kg m^2: every link's inertia reduced to the crank, flywheel excluded
    dJ_red: np.ndarray        # (N,) kg m^2/rad: d J_red / d phi
    M_red: np.ndarray         # (N,) N m: reduced moment of every load but the drive and inertia
    M_drive: np.ndarray       # (N,) N m: the drive's moment on the crank
    work: np.ndarray          # (N,) J: A(phi) = integral from phi_deg[0] of (M_red + M_drive) d phi = Delta T
    T: np.ndarray             # (N,) J: kinetic energy, flywheel included, 0.5 (J_flywheel + J_red) omega^2
    omega: np.ndarray         # (N,) rad/s: the steady motion, periodic
    eps: np.ndarray           # (N,) rad/s^2: (M_red + M_drive - 0.5 dJ_red omega^2) / (J_flywheel + J_red)
    omega_mean: float         # rad/s: (omega_max + omega_min) / 2
    delta: float              # 1: (omega_max - omega_min) / omega_mean
    J_flywheel: float         # kg m^2: on the crank shaft
    delta_target: float | None   # the delta sized for (None: J given)
    drive: str                # "constant" or "characteristic"
    wittenbauer: tuple        # ((k_max, b_max), (k_min, b_min)): tangents y = k x + b to (J_red, work), k = omega_^2/2
    approximate: Mapping[str, float]   # the texts' approximate J_flywheel by method, kg m^2
    omega_max: float = 0.0    # rad/s: the largest omega of the continuous curve (between the angles too)
    omega_min: float = 0.0    # rad/s: the smallest
    passes: int = 1           # passes of the fixed point over speed-dependent loads
    settled: float = 0.0      # the last pass's largest change of omega over omega_mean

    def __repr__(self) -> str:
        return (f"Motion(positions={len(self.phi_deg)}, omega_mean={self.omega_mean:.6g} rad/s, "
                f"delta={self.delta:.6g}, J_flywheel={self.J_flywheel:.6g} kg m^2, drive={self.drive!r})")


def law_of_motion(mech: Mechanism, delta: float | None = None, flywheel: float | None = None,
                  steps: int = 360) -> Motion:
    """The steady periodic law of motion of `mech` (see `Motion`) with a flywheel on the crank
    shaft: `flywheel` J (kg m^2, >= 0) given, or the smallest one that holds the coefficient of
    fluctuation `delta` (0 < delta < 2), or neither: the model's [flywheel], else none.

    The energy equation 0.5 (J_flywheel + J_red) omega^2 = T0 + A(phi). J_red = sum m |v_S|^2 +
    I_S omega_k^2 and dJ_red = 2 sum (m v_S . a_S + I_S omega_k eps_k) at unit crank speed (exact
    derivatives, no differences). M_red: the work per radian of every load but inertia and the
    drive (`Analysis._work_per_radian`): gravity, forces, moments, springs, dampers and, with
    [friction], the friction of the first approximation at the true motion (the power lost in
    each pair on the frictionless reactions of the analysis at omega(phi), eps(phi)): the drive
    supplies it, so analyze(mech, law=motion)'s balancing_moment_with_friction is M_drive.
    The drive: a characteristic moment M(omega) on the crank where the model gives one (then
    omega_mean is what the characteristic makes it, not the nominal: the periodic motion by
    periodic shooting, Newton's method with the monodromy, `_shoot`), else a constant moment
    -mean(M_red) (an engine's consumer, a machine's motor) with omega_mean = the drive's omega.
    A(phi): Gauss-Legendre (GAUSS_NODES a piece) over each grid step, cut at the knots of a load's
    crank-angle table and where a travel table's point passes its knots or turns. Speed-dependent
    loads (friction, dampers, characteristics but the drive's), and the flywheel sized for delta
    under a characteristic drive (by the secant): a fixed point over the motion to SPEED_TOL
    (`passes`, `settled`), omega between the grid's angles by the periodic cubic Hermite
    through omega and d omega/d phi = eps/omega. omega_max and omega_min are the continuous
    curve's: each extreme located on that Hermite, then refined on the exact energy equation, all
    the extremes sought together, one solve per step (a pass of the fixed point starts from the
    last pass's angles). Sizing for delta:
    Wittenbauer's tangents at the exact slopes omega_m^2 (1 +- delta/2)^2 / 2 give the exact
    smallest J (0 where the machine alone holds delta)."""
    if not isinstance(mech, Mechanism):
        raise TypeError(f"law_of_motion: expected a Mechanism, got {type(mech).__name__}")
    J_fly, target = _flywheel(mech, delta, flywheel)
    nominal = _nominal(mech)
    phi_deg = crank_angles(None, steps)
    cycle = _Cycle.of(mech, phi_deg)
    chars = _characteristics(mech)
    loads_vary = mech.friction is not None or any(
        ld.kind == "damper" or (ld.characteristic is not None and ld not in chars) for ld in mech.loads)
    varying = loads_vary or bool(chars and target is not None)
    n = cycle.n
    speed = _Speed(phi_deg, np.full(n, nominal), np.zeros(n), chars)
    passes, red, change, seeds, last = 0, None, np.inf, None, None
    J = J_fly if target is None else None          # None: sized in this pass
    while True:
        passes += 1
        if red is None or loads_vary:
            red = _reduced(mech, cycle.angles, speed)
            _check_work(mech, red, chars)
        if chars and J is not None:                # the characteristic's periodic motion at this flywheel
            M_drive, T0 = _shoot(mech, chars, red, cycle, J, nominal)
            pieces = _Pieces(mech, cycle, red, M_drive, speed, _motion(phi_deg, cycle, red, M_drive, J, T0, chars))
            T0, top, bottom, extremes = _level(pieces, J, None, seeds, fixed=T0)
            level = 0.5 * (top[1] + bottom[1])
            J_next, tangents = (J, None) if target is None else _sized(pieces, level, target, seeds)
            if target is not None:
                J_next, last = _secant(J, J_next, last), (J, J_next)
        else:                                      # a constant drive (or a characteristic's first sizing)
            M_drive = np.full(len(cycle.angles), -cycle.mean(red.M))
            level = _balancing_speed(mech, chars, cycle.mean(red.M), nominal) if chars else nominal
            pieces = _Pieces(mech, cycle, red, M_drive, speed)
            J, tangents = (J, None) if target is None else _sized(pieces, level, target, seeds)
            T0, top, bottom, extremes = _level(pieces, J, level, tangents or seeds)
            J_next = J
        seeds = (np.concatenate([extremes[0]] + ([] if tangents is None else [tangents[0]])), None)
        new = _motion(phi_deg, cycle, red, M_drive, J, T0, chars)
        change = max(float(np.abs(new.at(cycle.angles) - speed.at(cycle.angles)).max()) / level,
                     abs(J_next - J) / J if J else 0.0)
        speed = new
        if not varying or (change <= SPEED_TOL and not (chars and pieces.driven is None)):
            change = change if varying else 0.0     # the loads do not depend on the motion: exact at once
            break
        J = J_next
        if passes >= MAX_PASSES:
            raise ValueError(f"law_of_motion: the speed-dependent loads' fixed point did not settle in {MAX_PASSES} "
                             f"passes (the last changed omega by {change:.3g} of omega_mean)")
    return _result(mech, pieces, J, T0, top, bottom, target, passes, change)


# ---------------------------------------------------------------------------------- the input

def _flywheel(mech: Mechanism, delta, flywheel) -> tuple[float, float | None]:
    """(J_flywheel given or 0, delta to size for or None), checked; ValueError naming the argument."""
    if delta is not None and flywheel is not None:
        raise ValueError(f"law_of_motion: give delta ({delta!r}) or flywheel ({flywheel!r}), not both")
    if delta is None and flywheel is None and mech.flywheel is not None:
        return (0.0, mech.flywheel.delta) if mech.flywheel.J is None else (mech.flywheel.J, None)
    if delta is not None:
        return 0.0, _number(delta, "delta", lambda d: 0 < d < 2, "0 < delta < 2")
    if flywheel is not None:
        return _number(flywheel, "flywheel", lambda j: j >= 0, "a moment of inertia >= 0, kg m^2"), None
    return 0.0, None


def _number(value, name: str, ok, meaning: str) -> float:
    """`value` as a finite float that `ok` accepts, else ValueError naming `name`."""
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)) \
            or not math.isfinite(value) or not ok(float(value)):
        raise ValueError(f"law_of_motion: {name}: expected {meaning}, got {value!r}")
    return float(value)


def _nominal(mech: Mechanism) -> float:
    """The drive's constant speed, rad/s: the steady motion's mean; ModelError naming the field
    where the drive has a law of motion, stands still or accelerates."""
    d = mech.drive
    problem = ("drive.omega: the law of motion is what law_of_motion finds; give the nominal constant speed "
               "(omega or rpm) instead of a law" if d.law is not None else
               "drive.omega: the nominal speed must be > 0 (the crank stands still)" if d.omega <= 0 else
               f"drive.eps: the steady motion has no constant acceleration (eps = {d.eps:g}); set eps = 0"
               if d.eps != 0 else None)
    if problem:
        raise ModelError([f"law_of_motion: {problem}"], source=mech.path or mech.name)
    return float(d.omega)


def _characteristics(mech: Mechanism) -> tuple:
    """The characteristic moments M(omega) on the crank: the drive, where there are any."""
    return tuple(ld for ld in mech.loads
                 if ld.kind == "moment" and ld.characteristic is not None and ld.link == mech.drive.link)


def _check_work(mech: Mechanism, red: "_Reduced", chars: tuple) -> None:
    """ValueError naming the model where no load does work: nothing for a drive to balance."""
    if not chars and not np.any(red.M):
        raise ModelError(["law_of_motion: no load does work on the machine (M_red = 0 at every angle): there is "
                          "nothing for the drive to balance; add [[load]]s or gravity"], source=mech.path or mech.name)


# --------------------------------------------------------------------------------- the cycle

@dataclass(frozen=True)
class _Cycle:
    """The grid's angles, then the Gauss nodes of every piece of the work integral (pieces: the
    grid's steps cut at the knots of a load's crank-angle table and at `_travel_knots`), deg, and
    the weights, rad."""
    n: int                    # grid angles (the first n of `angles`)
    angles: np.ndarray        # (n + P G,) deg
    weights: np.ndarray       # (P, G) rad
    step: np.ndarray          # (P,) the grid step each piece lies in
    knots: np.ndarray         # those cuts in [0, 360), deg

    @classmethod
    def of(cls, mech: Mechanism, phi_deg: np.ndarray) -> "_Cycle":
        n = len(phi_deg)
        knots = np.concatenate([np.mod(np.asarray(ld.table.x, float), 360.0) for ld in mech.loads
                                if ld.table is not None and ld.table.argument == "phi"] + [_travel_knots(mech)])
        edges = np.unique(np.concatenate([phi_deg, knots]))
        edges = edges[np.append(True, np.diff(edges) > 1e-9)]
        lo, hi = edges, np.append(edges[1:], 360.0)
        x, w = np.polynomial.legendre.leggauss(GAUSS_NODES)
        nodes = (0.5 * (lo + hi)[:, None] + 0.5 * (hi - lo)[:, None] * x)
        step = np.searchsorted(phi_deg, lo, side="right") - 1
        return cls(n, np.concatenate([phi_deg, nodes.ravel()]), np.radians(0.5 * (hi - lo))[:, None] * w,
                   step, np.unique(knots))

    def integrals(self, f: np.ndarray) -> np.ndarray:
        """(n,) the integral of f (given at `angles`) over each grid step, J for f in N m."""
        return np.bincount(self.step, (self.weights * f[self.n:].reshape(self.weights.shape)).sum(axis=1),
                           minlength=self.n)

    def mean(self, f: np.ndarray) -> float:
        """The cycle's mean of f (given at `angles`)."""
        return float(self.integrals(f).sum() / (2 * np.pi))

    def work(self, f: np.ndarray) -> np.ndarray:
        """(n,) the integral of f from the first grid angle to each grid angle."""
        return np.concatenate([[0.0], np.cumsum(self.integrals(f))[:-1]])


def _travel_knots(mech: Mechanism) -> np.ndarray:
    """The crank angles (deg, in [0, 360)) where a travel table's point passes one of the table's
    inner knots, or turns (a dead centre: the table's forward and return values meet there):
    bracketed on a scan at every degree, then by Newton's method kept inside the brackets (else
    bisection) on the exact travel and its derivatives, every bracket in one solve per step."""
    loads = [ld for ld in mech.loads if ld.table is not None and ld.table.argument == "travel"]
    if not loads:
        return np.empty(0)
    scan = np.radians(np.arange(361.0))
    owner, level, turn, lo, hi = [], [], [], [], []
    for q, ld in enumerate(loads):
        s, ds, _ = travel_rates(mech, kinematics(mech, scan, unit_speed=True), ld)
        for x, f, is_turn in [(x, s - x, False) for x in ld.table.x if 0.0 < x < 1.0] + [(0.0, ds, True)]:
            at = np.flatnonzero((f[:-1] == 0) | (np.sign(f[:-1]) * np.sign(f[1:]) < 0))
            owner += [q] * len(at)
            level += [x] * len(at)
            turn += [is_turn] * len(at)
            lo, hi = lo + list(scan[at]), hi + list(scan[at + 1])
    if not lo:
        return np.empty(0)
    owner, level, turn, lo, hi = map(np.asarray, (owner, level, turn, lo, hi))

    def value(phi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        kin = kinematics(mech, phi, unit_speed=True)
        f, df = np.empty(len(phi)), np.empty(len(phi))
        for q, ld in enumerate(loads):
            m = owner == q
            s, ds, d2s = (r[m] for r in travel_rates(mech, kin, ld))
            f[m], df[m] = np.where(turn[m], ds, s - level[m]), np.where(turn[m], d2s, ds)
        return f, df
    f_lo = value(lo)[0]
    x = 0.5 * (lo + hi)
    for _ in range(60):
        f, df = value(x)
        same = np.sign(f) == np.sign(f_lo)
        lo, f_lo, hi = np.where(same, x, lo), np.where(same, f, f_lo), np.where(same, hi, x)
        with np.errstate(all="ignore"):
            step = x - f / df
        step = np.where(f == 0, x, np.where(np.isfinite(step) & (step > lo) & (step < hi), step, 0.5 * (lo + hi)))
        if np.abs(step - x).max() <= 1e-15 * 2 * np.pi:
            break
        x = step
    return np.mod(np.degrees(x), 360.0)


# ------------------------------------------------------------------------ reduced quantities

@dataclass(frozen=True)
class _Reduced:
    """J_red, dJ_red (kg m^2, per rad), M_red and the crank's characteristic moments (N m, drive's
    sense) at a cycle's angles, from the analysis at omega there."""
    J: np.ndarray
    dJ: np.ndarray
    M: np.ndarray


def reduced_inertia(mech: Mechanism, u: Kinematics) -> tuple[np.ndarray, np.ndarray]:
    """J_red (kg m^2) and d J_red / d phi (kg m^2/rad) from the motion `u` at unit crank speed
    (its velocities are d/d phi, its accelerations d^2/d phi^2): sum m |v_S|^2 + I_S omega_k^2
    and 2 sum (m v_S . a_S + I_S omega_k eps_k)."""
    mass, I_S, _ = mech.inertia_arrays
    r, aS = com_motion(mech, u)
    vS = u.v_z + 1j * u.omega * r
    J = (mass * np.abs(vS) ** 2 + I_S * u.omega ** 2).sum(axis=1)
    dJ = 2 * (mass * dot_z(vS, aS) + I_S * u.omega * u.eps).sum(axis=1)
    return J, dJ


@dataclass(frozen=True)
class _Speed:
    """A motion omega(phi) known at the grid `phi_deg` with its slope d omega/d phi, and the
    crank's characteristic moments (the drive, or none)."""
    phi_deg: np.ndarray
    omega: np.ndarray
    slope: np.ndarray
    chars: tuple

    def at(self, angles: np.ndarray) -> np.ndarray:
        """omega at `angles` (deg): the periodic cubic Hermite through the grid's values and slopes."""
        law = SpeedLaw(tuple(self.phi_deg), tuple(self.omega), slope=tuple(self.slope))
        return law(np.radians(angles))[0]

    def drive(self, angles: np.ndarray) -> np.ndarray:
        """The characteristic drive's moment M(omega) at `angles` (deg), N m in the drive's sense."""
        w = self.at(angles)
        return sum((ld.characteristic(w) for ld in self.chars), np.zeros_like(w))


def _reduced(mech: Mechanism, angles: np.ndarray, speed: _Speed) -> _Reduced:
    """The reduced quantities at `angles` (deg), the loads at the motion `speed` (the drive's
    constant speed where it does not vary)."""
    m = mech if not speed.slope.any() else at_motion(mech, speed.phi_deg, speed.omega, speed.slope, 0.0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SelfLockingWarning)
        res = exact(m, angles)
    u = res._unit_motion()
    J, dJ = reduced_inertia(mech, u)
    skip = {f"inertia {k}" for k in range(mech.n_links)} | {"balancing moment"}
    M = sum(v for k, v in res._work_per_radian().items() if k not in skip)
    for ld in speed.chars:
        M = M - applied_moment(m, res.kin, ld) * u.omega[:, ld.link]
    if not np.isfinite(M).all() or not np.isfinite(J).all():
        bad = angles[~(np.isfinite(M) & np.isfinite(J))]
        raise ModelError([f"law_of_motion: the reduced moment or inertia is not finite at phi = {bad[0]:.6g} deg"
                          f"{f' and {len(bad) - 1} more angles' if len(bad) > 1 else ''} (a singular position in the "
                          f"cycle): no steady motion through it"], source=mech.path or mech.name)
    return _Reduced(J, dJ, np.broadcast_to(M, J.shape).astype(float))


def at_motion(mech: Mechanism, phi_deg: np.ndarray, omega: np.ndarray, domega: np.ndarray,
              J_flywheel: float) -> Mechanism:
    """`mech` driven by the law omega(phi) (the periodic cubic Hermite through omega and
    d omega/d phi at the uniform cycle `phi_deg`, rad/s and rad/s per rad), with a flywheel of
    J_flywheel (kg m^2) on the crank about its axis (added to the crank's I_S). Without a
    flywheel it keeps a copy of `mech`'s derived data (programs, constants, tracks: the geometry's
    and the masses', none reads the drive's speed), so that a solve at a motion compiles nothing."""
    law = SpeedLaw(tuple(map(float, phi_deg)), tuple(map(float, omega)), slope=tuple(map(float, domega)))
    drive = replace(mech.drive, law=law, omega=float(np.max(omega)), eps=float(np.abs(omega * domega).max()))
    links = mech.links
    if J_flywheel:
        crank = links[mech.drive.link]
        links = links[:crank.id] + (replace(crank, I_S=crank.I_S + J_flywheel),) + links[crank.id + 1:]
    return replace(mech, drive=drive, links=links, _derived={} if J_flywheel else dict(mech._derived))


# ------------------------------------------------------------------------------ the motion

def _motion(phi_deg: np.ndarray, cycle: _Cycle, red: _Reduced, M_drive: np.ndarray, J: float, T0: float,
            chars: tuple) -> _Speed:
    """The motion of the energy equation 0.5 (J + J_red) omega^2 = T0 + A(phi) at the grid."""
    n = cycle.n
    omega = np.sqrt(np.maximum(2 * (T0 + cycle.work(red.M + M_drive)) / (J + red.J[:n]), 0.0))
    return _Speed(phi_deg, omega, _eps(red, M_drive, omega, J, n) / omega, chars)


def _secant(J: float, sized: float, last: tuple[float, float] | None) -> float:
    """The next flywheel (kg m^2) of the fixed point J -> sized(J): the root of sized(J) - J by
    the secant through this pass's (J, sized) and the last pass's, else `sized`."""
    if last is None or sized - J == last[1] - last[0]:
        return sized
    g, g_last = sized - J, last[1] - last[0]
    return max(J - g * (J - last[0]) / (g - g_last), 0.0)


def _eps(red: _Reduced, M_drive: np.ndarray, omega: np.ndarray, J: float, n: int) -> np.ndarray:
    """eps = (M_red + M_drive - 0.5 dJ_red omega^2) / (J + J_red) at the first n angles, rad/s^2."""
    return (red.M[:n] + M_drive[:n] - 0.5 * red.dJ[:n] * omega ** 2) / (J + red.J[:n])


def _characteristic_field(mech: Mechanism, chars: tuple) -> str:
    """The model's fields of the drive's characteristics, as an error names them."""
    return " + ".join(f"load[{mech.loads.index(ld)}].characteristic ({ld.name!r})" for ld in chars)


def _collocation() -> tuple[np.ndarray, np.ndarray]:
    """Gauss-Legendre collocation's matrix a_ij = integral from 0 to c_i of the j-th Lagrange
    polynomial through the nodes c (GAUSS_NODES, on [0, 1]), and its weights b."""
    x, w = np.polynomial.legendre.leggauss(GAUSS_NODES)
    c = 0.5 * (x + 1)
    k = np.arange(GAUSS_NODES)
    lagrange = np.linalg.inv(c[:, None] ** k[None, :])          # column j: the coefficients of the j-th
    return (c[:, None] ** (k + 1) / (k + 1)) @ lagrange, 0.5 * w


def _shoot(mech: Mechanism, chars: tuple, red: _Reduced, cycle: _Cycle, J: float, guess: float
           ) -> tuple[np.ndarray, float]:
    """The characteristic drive's periodic motion for the flywheel J: its moment M(omega) at the
    cycle's angles (N m) and the kinetic energy T0 at phi_deg[0] (J).

    The energy equation dE/dphi = M_red + M(omega), E = 0.5 (J + J_red) omega^2, is integrated
    over each piece of the cycle by Gauss-Legendre collocation at the pieces' Gauss nodes (where
    M_red and J_red are solved: order 2 GAUSS_NODES), and the periodic solution E(phi_0 + 2 pi) =
    E(phi_0) found by Newton's method on every piece's start and stages at once: the linearised
    step carries dE from piece to piece with each piece's multiplier m = dE_end/dE_start, and
    closes the cycle with their product, the monodromy mu = dE(phi_0 + 2 pi)/dE(phi_0):
    dE(phi_0) = mu S / (1 - mu), the shooting Newton step (S: the carried residuals). A stable
    steady motion has mu < 1 (M(omega) falls as omega rises). Started from the constant speed
    where M balances the cycle's mean load (searched upwards from `guess`, rad/s). ValueError
    naming the characteristic where it cannot drive the load (the crank stops) or no periodic
    motion settles."""
    field = _characteristic_field(mech, chars)
    n, (P, G) = cycle.n, cycle.weights.shape
    h = cycle.weights.sum(axis=1)                         # (P,) rad
    a, b = _collocation()
    Jt = J + red.J[n:].reshape(P, G)
    Mr = red.M[n:].reshape(P, G)

    def drive(w: np.ndarray) -> np.ndarray:
        return sum((ld.characteristic(w) for ld in chars), np.zeros_like(w))
    load = cycle.mean(red.M)
    w_c = _balancing_speed(mech, chars, load, guess)
    f = Mr + drive(np.full((P, G), w_c))
    start = np.concatenate([[0.0], np.cumsum(h * (f @ b))[:-1]])
    E0 = 0.5 * float(Jt.mean()) * w_c ** 2 - float(start.mean())
    E = E0 + start                                        # (P,) at the pieces' starts
    K = E[:, None] + h[:, None] * (f @ a.T)               # (P, G) at their stages
    scale = float(np.abs(K).max())
    for _ in range(MAX_PASSES):
        if not (K > 0).all() or not np.isfinite(K).all():
            raise ValueError(f"law_of_motion: {field}: no periodic motion with J_flywheel = {J:.6g} kg m^2: the "
                             f"crank stops (the cycle's work swing exceeds what the motor and the inertia keep up)")
        w = np.sqrt(2 * K / Jt)
        f = Mr + drive(w)
        dw = 1e-7 * np.maximum(w, 1.0)
        p = (drive(w + dw) - drive(w - dw)) / (2 * dw) / (Jt * w)          # d f / d E
        R = K - E[:, None] - h[:, None] * (f @ a.T)
        L = np.eye(G) - h[:, None, None] * a[None] * p[:, None, :]
        u = np.linalg.solve(L, np.ones((P, G, 1)))[..., 0]
        v = np.linalg.solve(L, -R[..., None])[..., 0]
        m = 1 + h * ((b * p * u).sum(axis=1))
        r = E + h * (f @ b) + h * (b * p * v).sum(axis=1) - np.roll(E, -1)
        carried = np.concatenate([[1.0], np.cumprod(m)])
        mu = carried[-1]
        if not mu < 1:
            raise ValueError(f"law_of_motion: {field}: M(omega) does not fall as omega rises through the working "
                             f"speed (monodromy {mu:.6g} >= 1): no stable steady motion")
        S = np.cumsum(r / carried[1:])
        d0 = mu * S[-1] / (1 - mu)
        dE = carried[:-1] * (d0 + np.concatenate([[0.0], S[:-1]]))
        dK = u * dE[:, None] + v
        t = 1.0
        while not (K + t * dK > 0).all() and t > 1e-6:     # a step that would stop the crank: shortened
            t *= 0.5
        E, K = E + t * dE, K + t * dK
        if t == 1.0 and max(np.abs(dE).max(), np.abs(dK).max()) <= 1e-14 * scale:
            break
    else:
        raise ValueError(f"law_of_motion: {field}: Newton's method found no periodic motion in {MAX_PASSES} steps")
    w_grid = np.sqrt(2 * E[np.searchsorted(cycle.step, np.arange(n))] / (J + red.J[:n]))
    return np.concatenate([drive(w_grid), drive(np.sqrt(2 * K / Jt)).ravel()]), float(E[0])


def _balancing_speed(mech: Mechanism, chars: tuple, load: float, guess: float) -> float:
    """The constant speed (rad/s) at which the characteristic drive balances the cycle's mean
    load moment `load` (N m, M_red's mean): M(omega) + load = 0, searched upwards from 0 in steps
    from `guess`; ValueError naming the characteristic where M(0) cannot turn the crank."""
    field = _characteristic_field(mech, chars)

    def surplus(w: float) -> float:
        return float(sum(ld.characteristic(np.array([w]))[0] for ld in chars)) + load
    if not surplus(0.0) > 0:
        raise ValueError(f"law_of_motion: {field}: M(0) = {surplus(0.0) - load:.6g} N m cannot drive the load "
                         f"(its mean resisting moment {-load:.6g} N m): the crank stops")
    return _root(surplus, 0.0, guess, f"{field}: no speed at which M(omega) balances the load's mean moment "
                 f"{-load:.6g} N m")


def _root(f, lo: float, step: float, why: str, tol: float = 0.0) -> float:
    """x where the monotone f changes sign, searched upwards from `lo` in steps doubling from
    `step`, then bisected to the last bit; ValueError saying `why` where it does not."""
    f_lo = f(lo)
    hi, f_hi = lo + step, f(lo + step)
    for _ in range(200):
        if np.sign(f_hi) != np.sign(f_lo) or f_hi == 0:
            break
        lo, f_lo, step = hi, f_hi, 2 * step
        hi, f_hi = lo + step, f(lo + step)
    else:
        raise ValueError(f"law_of_motion: {why}")
    for _ in range(2000):
        mid = 0.5 * (lo + hi)
        if not lo < mid < hi or hi - lo <= tol:
            break
        f_mid = f(mid)
        if f_mid == 0:
            return mid
        lo, f_lo, hi = (mid, f_mid, hi) if np.sign(f_mid) == np.sign(f_lo) else (lo, f_lo, mid)
    return 0.5 * (lo + hi)


class _Pieces:
    """The energy equation's terms at the grid (A, J_red and their slopes), and exactly at any
    other angles: A by Gauss-Legendre from the grid angle below, cut at the table knots, all the
    angles asked for in one solve."""

    def __init__(self, mech: Mechanism, cycle: _Cycle, red: _Reduced, M_drive: np.ndarray, speed: _Speed,
                 driven: _Speed | None = None):
        n = cycle.n
        self.mech, self.cycle, self.red, self.speed, self.driven = mech, cycle, red, speed, driven
        self.M_drive = M_drive
        self.phi = cycle.angles[:n]
        self.A = cycle.work(red.M + M_drive)
        self.A_end = float(cycle.integrals(red.M + M_drive).sum())     # A at 360 deg: the cycle's work
        self.J, self.dJ, self.dA = red.J[:n], red.dJ[:n], (red.M + M_drive)[:n]

    def drive_at(self, angles: np.ndarray) -> np.ndarray:
        """M_drive at `angles` (deg): the constant, or the characteristic's M(omega) at the
        motion `driven` it drives."""
        return np.full(len(angles), self.M_drive[0]) if self.driven is None else self.driven.drive(angles)

    def grid(self, i: np.ndarray) -> tuple[np.ndarray, ...]:
        """The terms (A, J_red, dJ_red, dA) at the grid angles of index `i` (0..n: n is 360 deg)."""
        k = i % len(self.phi)
        return np.where(i < len(self.phi), self.A[k], self.A_end), self.J[k], self.dJ[k], self.dA[k]

    def exact(self, at: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """A (J), J_red (kg m^2), dJ_red (kg m^2/rad) and dA = M_red + M_drive (N m) at the angles
        `at` (deg, in [0, 360)): one solve at them and at the Gauss nodes from the grid angle
        below each (the knots between them cut the interval)."""
        if not len(at):
            return np.empty(0), np.empty(0), np.empty(0), np.empty(0)
        i = np.clip(np.searchsorted(self.phi, at, side="right") - 1, 0, len(self.phi) - 1)
        a, knots = self.phi[i], self.cycle.knots
        first = np.searchsorted(knots, a, side="right")
        count = np.searchsorted(knots, at, side="left") - first
        r = np.arange(count.max(initial=0))
        cuts = np.where(r < count[:, None], knots[np.minimum(first[:, None] + r, len(knots) - 1)] if len(knots)
                        else at[:, None], at[:, None])
        edges = np.column_stack([a, cuts, at])             # (m, K + 2): padded with `at` (empty pieces)
        lo, hi = edges[:, :-1, None], edges[:, 1:, None]
        x, w = np.polynomial.legendre.leggauss(GAUSS_NODES)
        nodes = (0.5 * (lo + hi) + 0.5 * (hi - lo) * x).reshape(len(at), -1)
        weights = (np.radians(0.5 * (hi - lo)) * w).reshape(len(at), -1)
        red = _reduced(self.mech, np.concatenate([at, nodes.ravel()]), self.speed)
        k = len(at)
        f = (red.M[k:] + self.drive_at(nodes.ravel())).reshape(nodes.shape)
        return self.A[i] + (weights * f).sum(axis=1), red.J[:k], red.dJ[:k], red.M[:k] + self.drive_at(at)

    def locate(self, y: np.ndarray, dy: np.ndarray, most: int = 6) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The angles (deg) of the `most` largest local maxima of the periodic cubic Hermite
        through the values `y` and slopes `dy` (per rad) at the grid, and the indices of the grid
        angles a and a + 1 of the step each lies in (a + 1 = n: 360 deg)."""
        n, phi = len(y), self.phi
        peak = np.flatnonzero((y >= np.roll(y, 1)) & (y >= np.roll(y, -1)))
        peak = peak[np.argsort(-y[peak])][:most]
        a = np.where(dy[peak] > 0, peak, peak - 1) % n           # the step the maximum lies in
        b = a + 1
        h = np.radians(np.where(b < n, phi[b % n], 360.0) - phi[a])
        y0, y1, d0, d1 = y[a], y[b % n], dy[a] * h, dy[b % n] * h
        # h p'(s) = c2 s^2 + c1 s + c0 on s in [0, 1]
        c2, c1, c0 = 6 * (y0 - y1) + 3 * d0 + 3 * d1, -6 * (y0 - y1) - 4 * d0 - 2 * d1, d0
        with np.errstate(all="ignore"):
            disc = np.sqrt(np.maximum(c1 * c1 - 4 * c2 * c0, 0.0))
            roots = np.stack([(-c1 - disc) / (2 * c2), (-c1 + disc) / (2 * c2), -c0 / c1])
        s = np.where(np.isfinite(roots) & (roots >= 0) & (roots <= 1), roots, np.nan)
        h00, h10, h01, h11 = (1 + 2 * s) * (1 - s) ** 2, s * (1 - s) ** 2, s * s * (3 - 2 * s), s * s * (s - 1)
        value = np.where(np.isnan(s), -np.inf, h00 * y0 + h10 * d0 + h01 * y1 + h11 * d1)
        best = np.nan_to_num(np.take_along_axis(s, np.argmax(value, axis=0)[None], 0)[0], nan=0.0)
        return phi[a] + np.degrees(best * h), a, b


#: A function of the energy equation's terms to maximise: its values and slopes (per rad) at the
#: grid, its exact slope as a function of the terms (A, J_red, dJ_red, dA) at any angles, and how
#: many of its largest local maxima to refine.
Objective = tuple


def _refine(pieces: _Pieces, objectives: list, seeds: tuple | None = None, after=None) -> list[tuple]:
    """The local maxima of every objective (`Objective`), each located on the grid's Hermite
    (`locate`; or at a seed angle in its grid step: `seeds` = (angles, terms there or None)),
    then all of them together by the secant on the exact slope, kept inside the step (else
    regula falsi), to REFINE_DEG: one solve per step for all. `after(terms)` is called with the
    terms at every candidate after each solve (a caller's parameters the slopes read).
    Returns per objective (angles deg in [0, 360), terms there)."""
    located = [pieces.locate(y, dy, most) for y, dy, _, most in objectives]
    x = np.concatenate([np.asarray(p[0], float) for p in located])
    a, b = (np.concatenate([p[k] for p in located]) for k in (1, 2))
    owner = np.concatenate([np.full(len(p[0]), q) for q, p in enumerate(located)])
    lo, hi = pieces.phi[a], np.where(b < len(pieces.phi), pieces.phi[b % len(pieces.phi)], 360.0)
    T = None
    if seeds is not None and len(seeds[0]):
        s = np.asarray(seeds[0], float)
        inside = (s[None, :] >= lo[:, None]) & (s[None, :] <= hi[:, None])
        has = inside.any(axis=1)
        which = np.argmax(inside, axis=1)
        x = np.where(has, s[which], x)
        if seeds[1] is not None and has.all():
            T = tuple(t[which] for t in seeds[1])
    T = pieces.exact(np.mod(x, 360.0)) if T is None else T
    T_lo, T_hi = pieces.grid(a), pieces.grid(b)

    def slope(terms) -> np.ndarray:
        out = np.empty(len(owner))
        for q, obj in enumerate(objectives):
            m = owner == q
            out[m] = obj[2](*(t[m] for t in terms))
        return out

    def pick(mask, t1, t2):
        return tuple(np.where(mask, u, v) for u, v in zip(t1, t2))

    prev = None
    for _ in range(REFINE_PASSES):
        if after is not None:
            after(T)
        g, g_lo, g_hi = slope(T), slope(T_lo), slope(T_hi)
        up = g > 0                                  # a maximum: the slope falls through 0
        lo, T_lo, g_lo = np.where(up, x, lo), pick(up, T, T_lo), np.where(up, g, g_lo)
        hi, T_hi, g_hi = np.where(up, hi, x), pick(up, T_hi, T), np.where(up, g_hi, g)
        other, g_other = (np.where(up, hi, lo), np.where(up, g_hi, g_lo)) if prev is None else (prev[0], slope(prev[1]))
        with np.errstate(all="ignore"):
            step = x - g * (x - other) / (g - g_other)
            fall = lo + (hi - lo) * g_lo / (g_lo - g_hi)
        step = np.where(np.isfinite(step) & (step > lo) & (step < hi), step,
                        np.where(np.isfinite(fall), fall, 0.5 * (lo + hi)))
        step = np.where(g == 0, x, step)
        if np.abs(step - x).max(initial=0.0) <= REFINE_DEG:
            break
        prev = (x, T)
        x, T = step, pieces.exact(np.mod(step, 360.0))
    else:
        if after is not None:
            after(T)
    x = np.mod(x, 360.0)
    return [(x[owner == q], tuple(t[owner == q] for t in T)) for q in range(len(objectives))]


def _sups(pieces: _Pieces, lines: list[tuple[float, float]], seeds: tuple | None = None) -> tuple[list, tuple]:
    """For each (k, sign) of `lines`: the largest of sign (A - k J_red) over the continuous cycle
    (J) and its angle (deg), the grid's and every local maximum refined (`_refine`, together);
    and the refined angles with the terms there (seeds for later refinements)."""
    found = _refine(pieces, [(sign * (pieces.A - k * pieces.J), sign * (pieces.dA - k * pieces.dJ),
                              lambda A, J, dJ, dA, k=k, sign=sign: sign * (dA - k * dJ), 6) for k, sign in lines],
                    seeds)
    out = []
    for (k, sign), (at, (A, J, _, _)) in zip(lines, found):
        values = sign * np.concatenate([pieces.A - k * pieces.J, A - k * J])
        best = int(np.argmax(values))
        out.append((float(values[best]), float(np.concatenate([pieces.phi, at])[best])))
    angles = np.concatenate([at for at, _ in found])
    return out, (angles, tuple(np.concatenate([t[j] for _, t in found]) for j in range(4)))


def _sized(pieces: _Pieces, level: float, delta: float, seeds: tuple | None = None) -> tuple[float, tuple]:
    """The smallest J_flywheel (kg m^2) whose motion has (omega_max - omega_min)/level = delta at
    (omega_max + omega_min)/2 = level: Wittenbauer's tangents at the exact slopes k = omega^2/2,
    J = (b_max - b_min) / (k_max - k_min); 0 where the machine alone holds delta. With the
    tangent points found (angles, terms: the extremes of omega for that J)."""
    k_max, k_min = 0.5 * (level * (1 + delta / 2)) ** 2, 0.5 * (level * (1 - delta / 2)) ** 2
    ((b_max, _), (minus_b_min, _)), found = _sups(pieces, [(k_max, 1.0), (k_min, -1.0)], seeds)
    return max((b_max + minus_b_min) / (k_max - k_min), 0.0), found


def _T0(pieces: _Pieces, J: float, level: float, A: np.ndarray, Jr: np.ndarray) -> float:
    """The kinetic energy at phi_deg[0] (J) such that the omega at the angles of (A, Jr) has
    (max + min)/2 = level; ValueError where the crank would stop."""
    def miss(T0: float) -> float:
        w2 = 2 * (T0 + A) / (J + Jr)
        return 0.5 * (math.sqrt(w2.max()) + math.sqrt(max(w2.min(), 0.0))) - level
    lo = float(-A.min())
    if miss(lo) > 0:
        raise ValueError(f"law_of_motion: flywheel: J_flywheel = {J:.6g} kg m^2 is too small for the machine to "
                         f"run at omega_mean = {level:.6g} rad/s: the crank would stop (the cycle's work swing "
                         f"{float(np.ptp(pieces.A)):.6g} J exceeds what the inertia stores); give a larger flywheel or delta")
    return _root(miss, lo, 0.5 * level ** 2 * float((J + pieces.J).mean()), "no level of the kinetic energy gives omega_mean")


def _level(pieces: _Pieces, J: float, level: float | None, seeds: tuple | None = None, fixed: float | None = None
           ) -> tuple[float, tuple[float, float], tuple[float, float], tuple]:
    """T0 (J) such that (omega_max + omega_min)/2 = level for the flywheel J (or the `fixed`
    T0), the continuous curve's (phi_deg, omega) at its largest and smallest omega, and their
    angles (seeds); ValueError where the crank stops. The extremes are refined together with
    T0: after each solve, T0 again over the grid and the candidates."""
    A, Jr = pieces.A, pieces.J
    T0 = [_T0(pieces, J, level, A, Jr) if fixed is None else fixed]

    def after(T) -> None:
        if fixed is None:
            T0[0] = _T0(pieces, J, level, np.concatenate([A, T[0]]), np.concatenate([Jr, T[1]]))

    w = np.sqrt(np.maximum(2 * (T0[0] + A) / (J + Jr), 0.0))
    with np.errstate(divide="ignore", invalid="ignore"):
        dw = np.where(w > 0, (pieces.dA - 0.5 * pieces.dJ * w ** 2) / ((J + Jr) * w), 0.0)

    def slope(sign: float):       # (J + J_red) omega omega': the sign of omega's slope
        return lambda A_, J_, dJ_, dA_: sign * (dA_ - dJ_ * (T0[0] + A_) / (J + J_))
    (top, t_terms), (bottom, b_terms) = _refine(pieces, [(w, dw, slope(1.0), 2), (-w, -dw, slope(-1.0), 2)],
                                                seeds, after)
    extra_A, extra_J = np.concatenate([t_terms[0], b_terms[0]]), np.concatenate([t_terms[1], b_terms[1]])
    w_all = np.sqrt(np.maximum(2 * (T0[0] + np.concatenate([A, extra_A])) / (J + np.concatenate([Jr, extra_J])), 0.0))
    phi_all = np.concatenate([pieces.phi, top, bottom])
    i, j = int(np.argmax(w_all)), int(np.argmin(w_all))
    angles = np.concatenate([top, bottom])
    return T0[0], (float(phi_all[i]), float(w_all[i])), (float(phi_all[j]), float(w_all[j])), (angles, None)


def _result(mech: Mechanism, pieces: _Pieces, J: float, T0: float, top: tuple, bottom: tuple,
            target: float | None, passes: int, change: float) -> Motion:
    """The Motion of the last pass, its arrays read-only."""
    n = pieces.cycle.n
    red = pieces.red
    omega = np.sqrt(np.maximum(2 * (T0 + pieces.A) / (J + pieces.J), 0.0))
    eps = _eps(red, pieces.M_drive, omega, J, n)
    w_max, w_min = top[1], bottom[1]
    mean = 0.5 * (w_max + w_min)
    delta = (w_max - w_min) / mean
    k_max, k_min = 0.5 * w_max ** 2, 0.5 * w_min ** 2
    arrays = dict(phi_deg=pieces.phi.copy(), J_red=pieces.J.copy(), dJ_red=pieces.dJ.copy(), M_red=red.M[:n].copy(),
                  M_drive=pieces.M_drive[:n].copy(), work=pieces.A.copy(), T=T0 + pieces.A, omega=omega, eps=eps)
    for a in arrays.values():
        a.flags.writeable = False
    return Motion(mech=mech, **arrays, omega_mean=mean, delta=delta, J_flywheel=J, delta_target=target,
                  drive="characteristic" if pieces.speed.chars else "constant",
                  wittenbauer=((k_max, k_max * J - T0), (k_min, k_min * J - T0)),
                  approximate=MappingProxyType(_approximate(mech, pieces, mean, target if target is not None else delta)),
                  omega_max=w_max, omega_min=w_min, passes=passes, settled=change)


def _approximate(mech: Mechanism, pieces: _Pieces, mean: float, delta: float) -> dict[str, float]:
    """The texts' approximate J_flywheel (kg m^2) for `delta` at omega_m = `mean`
    (/work/notes/flywheel_texts.md: the course texts' methods):
    "wittenbauer": the tangents at the texts' slopes omega_m^2 (1 +- delta) / 2, J = ab / (delta omega_m^2);
    "formula": Delta A_max / (delta omega_m^2) - mean J_red (J_red taken constant);
    "mertsalov": the swing of A - 0.5 (J_red - J_crank) omega_m^2 over delta omega_m^2, less J_crank
    (the crank's own reduced inertia J_crank, constant)."""
    scale, k = delta * mean ** 2, 0.5 * mean ** 2
    sups, _ = _sups(pieces, [(k * (1 + delta), 1.0), (k * (1 - delta), -1.0), (0.0, 1.0), (0.0, -1.0), (k, 1.0), (k, -1.0)])
    b_max, minus_b_min, A_max, minus_A_min, I_max, minus_I_min = (value for value, _ in sups)
    crank = mech.links[mech.drive.link]
    u = kinematics(mech, np.zeros(1), unit_speed=True)
    J_crank = float(reduced_inertia(replace(mech, links=tuple(
        link if link.id == crank.id else replace(link, mass=0.0, I_S=0.0) for link in mech.links), _derived={}), u)[0][0])
    return {"wittenbauer": (b_max + minus_b_min) / scale, "formula": (A_max + minus_A_min) / scale - float(pieces.J.mean()),
            "mertsalov": (I_max + minus_I_min) / scale - J_crank}
