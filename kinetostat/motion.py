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
from .applied import applied_moment, com_motion
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
#: this, deg, or for at most REFINE_PASSES evaluations.
REFINE_DEG = 1e-9
REFINE_PASSES = 8
#: Passes of that fixed point before omega changes by less than this (relative) refine the
#: extremes once only; the later passes to REFINE_DEG.
ROUGH = 1e-6
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
    omega_mean is what the characteristic makes it, not the nominal), else a constant moment
    -mean(M_red) (an engine's consumer, a machine's motor) with omega_mean = the drive's omega.
    A(phi): Gauss-Legendre (GAUSS_NODES a piece) over each grid step, cut at the knots of a load's
    crank-angle table. Speed-dependent loads and M(omega): a fixed point over the motion to
    SPEED_TOL (`passes`, `settled`), omega between the grid's angles by the periodic cubic Hermite
    through omega and d omega/d phi = eps/omega. omega_max and omega_min are the continuous
    curve's: each extreme located on that Hermite and evaluated exactly there. Sizing for delta:
    Wittenbauer's tangents at the exact slopes omega_m^2 (1 +- delta/2)^2 / 2 give the exact
    smallest J (0 where the machine alone holds delta)."""
    if not isinstance(mech, Mechanism):
        raise TypeError(f"law_of_motion: expected a Mechanism, got {type(mech).__name__}")
    J_fly, target = _flywheel(mech, delta, flywheel)
    nominal = _nominal(mech)
    phi_deg = crank_angles(None, steps)
    cycle = _Cycle.of(mech, phi_deg)
    chars = _characteristics(mech)
    varying = bool(chars) or mech.friction is not None or any(
        ld.kind == "damper" or ld.characteristic is not None for ld in mech.loads)
    n = cycle.n
    speed = _Speed(phi_deg, np.full(n, nominal), np.zeros(n), chars)
    passes, red, change = 0, None, np.inf
    while True:
        passes += 1
        if red is None or varying:
            red = _reduced(mech, cycle.angles, speed)
            _check_work(mech, red, chars)
        M_drive, level, shift = (_characteristic_drive(chars, red, cycle, speed) if chars else
                                 (np.full(len(cycle.angles), -cycle.mean(red.M)), nominal, 0.0))
        pieces = _Pieces(mech, cycle, red, M_drive, speed, shift,
                         REFINE_PASSES if not varying or change <= ROUGH else 1)
        J = J_fly if target is None else _sized(pieces, level, target)
        T0, top, bottom = _level(pieces, J, level)
        omega = np.sqrt(np.maximum(2 * (T0 + pieces.A) / (J + red.J[:n]), 0.0))
        new = _Speed(phi_deg, omega, _eps(red, M_drive, omega, J, n) / omega, chars)
        change = float(np.abs(new.at(cycle.angles) - speed.at(cycle.angles)).max()) / level
        speed = new
        if not varying or change <= SPEED_TOL:
            break
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
    grid's steps cut at the knots of a load's crank-angle table), deg, and the weights, rad."""
    n: int                    # grid angles (the first n of `angles`)
    angles: np.ndarray        # (n + P G,) deg
    weights: np.ndarray       # (P, G) rad
    step: np.ndarray          # (P,) the grid step each piece lies in
    knots: np.ndarray         # the knots of the loads' crank-angle tables in [0, 360), deg

    @classmethod
    def of(cls, mech: Mechanism, phi_deg: np.ndarray) -> "_Cycle":
        n = len(phi_deg)
        knots = np.concatenate([np.mod(np.asarray(ld.table.x, float), 360.0) for ld in mech.loads
                                if ld.table is not None and ld.table.argument == "phi"] or [np.empty(0)])
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
    J_flywheel (kg m^2) on the crank about its axis (added to the crank's I_S)."""
    law = SpeedLaw(tuple(map(float, phi_deg)), tuple(map(float, omega)), slope=tuple(map(float, domega)))
    drive = replace(mech.drive, law=law, omega=float(np.max(omega)), eps=float(np.abs(omega * domega).max()))
    links = mech.links
    if J_flywheel:
        crank = links[mech.drive.link]
        links = links[:crank.id] + (replace(crank, I_S=crank.I_S + J_flywheel),) + links[crank.id + 1:]
    return replace(mech, drive=drive, links=links, _derived={})


# ------------------------------------------------------------------------------ the motion

def _eps(red: _Reduced, M_drive: np.ndarray, omega: np.ndarray, J: float, n: int) -> np.ndarray:
    """eps = (M_red + M_drive - 0.5 dJ_red omega^2) / (J + J_red) at the first n angles, rad/s^2."""
    return (red.M[:n] + M_drive[:n] - 0.5 * red.dJ[:n] * omega ** 2) / (J + red.J[:n])


def _characteristic_drive(chars: tuple, red: _Reduced, cycle: _Cycle, speed: _Speed) -> tuple[np.ndarray, float]:
    """The characteristic drive's moment at the cycle's angles, N m, at the motion `speed` moved
    by the constant c that closes the cycle's work (mean(M_red + M(omega + c)) = 0, a scalar root),
    and the level (omega_max + omega_min)/2 that motion has, rad/s."""
    w = speed.at(cycle.angles)

    def closure(c: float) -> float:
        return cycle.mean(red.M + sum((ld.characteristic(w + c) for ld in chars), np.zeros_like(w)))
    c = _root(closure, -w.min(), float(w.max()) or 1.0, "the motor's characteristic M(omega): no steady speed "
              "balances the cycle's work (M(omega) must fall as omega rises through the working speed)")
    M = sum((ld.characteristic(w + c) for ld in chars), np.zeros_like(w))
    g = w[:cycle.n] + c
    return M, float(g.max() + g.min()) / 2, c


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
    other angle: A by Gauss-Legendre from the grid angle below, cut at the table knots."""

    def __init__(self, mech: Mechanism, cycle: _Cycle, red: _Reduced, M_drive: np.ndarray, speed: _Speed,
                 shift: float, refine: int):
        n = cycle.n
        self.refine = refine
        self.mech, self.cycle, self.red, self.speed, self.shift = mech, cycle, red, speed, shift
        self.M_drive = M_drive
        self.phi = cycle.angles[:n]
        self.A = cycle.work(red.M + M_drive)
        self.J, self.dJ, self.dA = red.J[:n], red.dJ[:n], (red.M + M_drive)[:n]

    def drive_at(self, angles: np.ndarray) -> np.ndarray:
        """M_drive at `angles` (deg): the constant, or M(omega + shift) of the characteristic."""
        if not self.speed.chars:
            return np.full(len(angles), self.M_drive[0])
        w = self.speed.at(angles) + self.shift
        return sum((ld.characteristic(w) for ld in self.speed.chars), np.zeros_like(w))

    def exact(self, at: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """A (J), J_red (kg m^2), dJ_red (kg m^2/rad) and dA = M_red + M_drive (N m) at the angles
        `at` (deg, in [0, 360))."""
        if not len(at):
            return np.empty(0), np.empty(0), np.empty(0), np.empty(0)
        i = np.clip(np.searchsorted(self.phi, at, side="right") - 1, 0, len(self.phi) - 1)
        x, w = np.polynomial.legendre.leggauss(GAUSS_NODES)
        nodes, weights, owner = [], [], []
        for q, (a, b) in enumerate(zip(self.phi[i], at)):       # the few points located, not the grid
            cuts = self.cycle.knots[(self.cycle.knots > a) & (self.cycle.knots < b)]
            edges = np.concatenate([[a], cuts, [b]])
            lo, hi = edges[:-1], edges[1:]
            nodes.append((0.5 * (lo + hi)[:, None] + 0.5 * (hi - lo)[:, None] * x).ravel())
            weights.append((np.radians(0.5 * (hi - lo))[:, None] * w).ravel())
            owner.append(np.full(nodes[-1].size, q))
        nodes, weights, owner = np.concatenate(nodes), np.concatenate(weights), np.concatenate(owner)
        red = _reduced(self.mech, np.concatenate([at, nodes]), self.speed)
        k = len(at)
        f = red.M[k:] + self.drive_at(nodes)
        return (self.A[i] + np.bincount(owner, weights * f, minlength=k), red.J[:k], red.dJ[:k],
                red.M[:k] + self.drive_at(at))

    def locate(self, y: np.ndarray, dy: np.ndarray, most: int = 6) -> np.ndarray:
        """The angles (deg) of the `most` largest local maxima of the periodic cubic Hermite
        through the values `y` and slopes `dy` (per rad) at the grid, each inside its grid step."""
        n, phi = len(y), self.phi
        peak = np.flatnonzero((y >= np.roll(y, 1)) & (y >= np.roll(y, -1)))
        peak = peak[np.argsort(-y[peak])][:most]
        a = np.where(dy[peak] > 0, peak, peak - 1) % n           # the step the maximum lies in
        b = (a + 1) % n
        h = np.radians(np.where(b > a, phi[b] - phi[a], phi[b] + 360.0 - phi[a]))
        y0, y1, d0, d1 = y[a], y[b], dy[a] * h, dy[b] * h
        # h p'(s) = c2 s^2 + c1 s + c0 on s in [0, 1]
        c2, c1, c0 = 6 * (y0 - y1) + 3 * d0 + 3 * d1, -6 * (y0 - y1) - 4 * d0 - 2 * d1, d0
        with np.errstate(all="ignore"):
            disc = np.sqrt(np.maximum(c1 * c1 - 4 * c2 * c0, 0.0))
            roots = np.stack([(-c1 - disc) / (2 * c2), (-c1 + disc) / (2 * c2), -c0 / c1])
        s = np.where(np.isfinite(roots) & (roots >= 0) & (roots <= 1), roots, np.nan)
        h00, h10, h01, h11 = (1 + 2 * s) * (1 - s) ** 2, s * (1 - s) ** 2, s * s * (3 - 2 * s), s * s * (s - 1)
        value = np.where(np.isnan(s), -np.inf, h00 * y0 + h10 * d0 + h01 * y1 + h11 * d1)
        best = np.nan_to_num(np.take_along_axis(s, np.argmax(value, axis=0)[None], 0)[0], nan=0.0)
        return phi[a] + np.degrees(best * h), phi[a], phi[a] + np.degrees(h)

    def peaks(self, y: np.ndarray, dy: np.ndarray, slope, most: int = 6) -> tuple[np.ndarray, tuple]:
        """The angles (deg) of the local maxima of a function of the energy equation's terms,
        given at the grid as values `y` and slopes `dy`, and its terms exactly there (`exact`):
        each located on the Hermite (`locate`), then by regula falsi (Illinois) on the exact slope
        `slope(A, J_red, dJ_red, dA)` within its grid step, to REFINE_DEG."""
        x, lo, hi = self.locate(y, dy, most)
        g_lo, g_hi = np.ones_like(x), -np.ones_like(x)        # the slope's signs at the ends of a maximum
        terms = self.exact(np.mod(x, 360.0))
        for _ in range(self.refine):
            g = slope(*terms)
            up = g > 0
            moved = x.copy()
            lo, hi = np.where(up, x, lo), np.where(up, hi, x)
            g_lo, g_hi = np.where(up, g, g_lo * np.where(up, 1.0, 0.5)), np.where(up, g_hi * 0.5, g)
            with np.errstate(all="ignore"):
                x = np.where(g == 0, x, lo + (hi - lo) * g_lo / (g_lo - g_hi))
            x = np.where(np.isfinite(x), x, 0.5 * (lo + hi))
            terms = self.exact(np.mod(x, 360.0))
            if np.abs(x - moved).max(initial=0.0) <= REFINE_DEG:
                break
        return np.mod(x, 360.0), terms

    def sup(self, k: float, sign: float) -> tuple[float, float]:
        """The largest of sign (A - k J_red) over the continuous cycle, J, and its angle (deg):
        the grid's, and each local maximum located (`locate`) and evaluated exactly."""
        at, (A, J, _, _) = self.peaks(sign * (self.A - k * self.J), sign * (self.dA - k * self.dJ),
                                      lambda A, J, dJ, dA: sign * (dA - k * dJ))
        values = sign * np.concatenate([self.A - k * self.J, A - k * J])
        best = int(np.argmax(values))
        return float(values[best]), float(np.concatenate([self.phi, at])[best])


def _sized(pieces: _Pieces, level: float, delta: float) -> float:
    """The smallest J_flywheel (kg m^2) whose motion has (omega_max - omega_min)/level = delta at
    (omega_max + omega_min)/2 = level: Wittenbauer's tangents at the exact slopes k = omega^2/2,
    J = (b_max - b_min) / (k_max - k_min); 0 where the machine alone holds delta."""
    k_max, k_min = 0.5 * (level * (1 + delta / 2)) ** 2, 0.5 * (level * (1 - delta / 2)) ** 2
    b_max, b_min = pieces.sup(k_max, 1.0)[0], -pieces.sup(k_min, -1.0)[0]
    return max((b_max - b_min) / (k_max - k_min), 0.0)


def _level(pieces: _Pieces, J: float, level: float) -> tuple[float, tuple[float, float], tuple[float, float]]:
    """T0 (J) such that (omega_max + omega_min)/2 = level for the flywheel J, and the continuous
    curve's (phi_deg, omega) at its largest and smallest omega; ValueError where the crank stops."""
    A, Jr = pieces.A, pieces.J
    extra_A, extra_J, extra_phi = np.empty(0), np.empty(0), np.empty(0)
    for _ in range(3):          # the grid, then twice with the extremes located at the last T0
        cand_A, cand_J = np.concatenate([A, extra_A]), np.concatenate([Jr, extra_J])

        def miss(T0: float) -> float:
            w2 = 2 * (T0 + cand_A) / (J + cand_J)
            return 0.5 * (math.sqrt(w2.max()) + math.sqrt(max(w2.min(), 0.0))) - level
        lo = float(-cand_A.min())
        if miss(lo) > 0:
            raise ValueError(f"law_of_motion: flywheel: J_flywheel = {J:.6g} kg m^2 is too small for the machine to "
                             f"run at omega_mean = {level:.6g} rad/s: the crank would stop (the cycle's work swing "
                             f"{float(np.ptp(A)):.6g} J exceeds what the inertia stores); give a larger flywheel or delta")
        T0 = _root(miss, lo, 0.5 * level ** 2 * float((J + Jr).mean()), "no level of the kinetic energy gives omega_mean")
        w = np.sqrt(np.maximum(2 * (T0 + A) / (J + Jr), 0.0))
        with np.errstate(divide="ignore", invalid="ignore"):
            dw = np.where(w > 0, (pieces.dA - 0.5 * pieces.dJ * w ** 2) / ((J + Jr) * w), 0.0)
        def slope(sign: float):
            return lambda A_, J_, dJ_, dA_: sign * (dA_ - dJ_ * (T0 + A_) / (J + J_))   # (J + J_red) omega omega'
        top, t_terms = pieces.peaks(w, dw, slope(1.0), 2)
        bottom, b_terms = pieces.peaks(-w, -dw, slope(-1.0), 2)
        extra_phi = np.concatenate([top, bottom])
        extra_A, extra_J = np.concatenate([t_terms[0], b_terms[0]]), np.concatenate([t_terms[1], b_terms[1]])
    w_all = np.sqrt(np.maximum(2 * (T0 + np.concatenate([A, extra_A])) / (J + np.concatenate([Jr, extra_J])), 0.0))
    phi_all = np.concatenate([pieces.phi, extra_phi])
    top, bottom = int(np.argmax(w_all)), int(np.argmin(w_all))
    return T0, (float(phi_all[top]), float(w_all[top])), (float(phi_all[bottom]), float(w_all[bottom]))


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
    scale = delta * mean ** 2
    b_max, b_min = pieces.sup(0.5 * mean ** 2 * (1 + delta), 1.0)[0], -pieces.sup(0.5 * mean ** 2 * (1 - delta), -1.0)[0]
    swing = pieces.sup(0.0, 1.0)[0] + pieces.sup(0.0, -1.0)[0]
    crank = mech.links[mech.drive.link]
    u = kinematics(mech, np.zeros(1), unit_speed=True)
    J_crank = float(reduced_inertia(replace(mech, links=tuple(
        link if link.id == crank.id else replace(link, mass=0.0, I_S=0.0) for link in mech.links), _derived={}), u)[0][0])
    k = 0.5 * mean ** 2
    swing_I = pieces.sup(k, 1.0)[0] + pieces.sup(k, -1.0)[0]
    return {"wittenbauer": (b_max - b_min) / scale, "formula": swing / scale - float(pieces.J.mean()),
            "mertsalov": swing_I / scale - J_crank}
