"""The parts a Mechanism is made of, as the model file gives them: links (and their bodies),
pairs, loads (and their diagrams and characteristics), springs, the drive (its gear and law of
motion), friction, published values, a study. Each frozen.

Field meanings and units are those of `models/FORMAT.md`. All coordinates in metres, masses in
kg, moments of inertia in kg m^2, angles in radians unless the name says `_deg`.

May use: the standard library, numpy, errors, expressions, laws.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Callable, Literal, Mapping

import numpy as np

from ..errors import ModelError
from ..expressions import over_arrays, parse as parse_expression
from .laws import _hermite_at, _periodic_spline, _spline_at

Vec = tuple[float, float]


@dataclass(frozen=True)
class Body:
    """One of several bodies that make up a link (`[[link.body]]`), as the file gives it."""
    name: str
    mass: float                # kg
    com: Vec                   # its centre of mass, link's local frame, m
    I_S: float = 0.0           # kg m^2, about its own centre (0: a point mass)


@dataclass(frozen=True)
class Link:
    """A rigid link. `points`: name -> local coordinates (m); link 0 (frame): world coordinates.
    With `bodies`, mass, com and I_S are theirs combined (I_S by the parallel-axis theorem)."""
    id: int
    name: str
    points: Mapping[str, Vec]
    mass: float = 0.0          # kg
    I_S: float = 0.0           # kg m^2, about the centre of mass
    com: str | None = None     # name of the centre-of-mass point
    bodies: tuple[Body, ...] = ()


def combine(bodies: tuple[Body, ...], total: Callable = math.fsum) -> tuple[float, Vec, float]:
    """Total mass (kg), centre of mass (local, m) and I_S about it (kg m^2) of `bodies`:
    m = sum m_b, S = sum m_b S_b / m, I_S = sum (I_b + m_b |S_b - S|^2). `total`: the sum taken
    (`sum` where the numbers are `sensitivity.Dual`s)."""
    m = total(b.mass for b in bodies)
    if m == 0:
        return 0.0, (0.0, 0.0), 0.0
    S = (total(b.mass * b.com[0] for b in bodies) / m, total(b.mass * b.com[1] for b in bodies) / m)
    I_S = total(b.I_S + b.mass * ((b.com[0] - S[0]) ** 2 + (b.com[1] - S[1]) ** 2) for b in bodies)
    return m, S, I_S


@dataclass(frozen=True)
class Pair:
    """A lower kinematic pair. For P: `links` = (guide link, slider link), `point` on the slider."""
    index: int
    kind: Literal["R", "P"]
    links: tuple[int, int]
    point: str                        # R: the shared point; P: slider point on the guide line
    guide: str | None = None          # P: a point of the guide link on the guide line
    direction: Vec | None = None      # P: unit guide direction, guide link's local frame
    radius: float | None = None       # journal radius for friction, m

    @property
    def label(self) -> str:
        return f"{self.kind}({self.links[0]},{self.links[1]})"

    @property
    def alpha(self) -> float:
        """Angle of the slider's frame relative to the guide link's frame (P pairs), rad."""
        return math.atan2(self.direction[1], self.direction[0])


@dataclass(frozen=True)
class Table:
    """A piecewise-linear load diagram; the force or moment is `scale * value`."""
    argument: Literal["phi", "travel"]
    x: tuple[float, ...]                    # deg (phi, periodic) or fraction of stroke (travel)
    value: tuple[float, ...]                # forward stroke (or all angles for phi)
    value_return: tuple[float, ...] | None  # travel only: return stroke (None: as forward)
    scale: float = 1.0
    axis: Vec | None = None                 # travel only: world axis of the stroke
    origin: Literal["max", "min"] = "max"   # travel only: extreme the travel is measured from

    def __repr__(self) -> str:
        back = ", with a return stroke" if self.value_return is not None else ""
        return (f"Table({self.argument}, {len(self.x)} points, x={self.x[0]:g}..{self.x[-1]:g}, "
                f"value={min(self.value):g}..{max(self.value):g}, scale={self.scale:g}{back})")


@dataclass(frozen=True)
class Characteristic:
    """A speed-dependent moment M(omega): a motor's mechanical characteristic (seed 000 sec. 1).
    Both omega (rad/s) and M (N m) are measured in the drive's sense; a table is interpolated
    linearly (its end values held outside it), an expression is a function of `omega`."""
    omega: tuple[float, ...] = ()
    M: tuple[float, ...] = ()
    expression: str | None = None
    parameters: tuple[tuple[str, float], ...] = ()   # the model's parameters the expression may read

    def __call__(self, omega: np.ndarray) -> np.ndarray:
        """M (N m) at the angular velocities `omega` (rad/s), both in the drive's sense."""
        if self.expression is not None:
            value = over_arrays(parse_expression(self.expression), {**dict(self.parameters), "omega": omega})
            return np.broadcast_to(value, np.shape(omega)).astype(float)
        return np.interp(omega, self.omega, self.M)


@dataclass(frozen=True)
class Load:
    """An external force at a point (`kind='force'`), a moment on a link (`kind='moment'`), or a
    viscous damper on a pair (`kind='damper'`: `value` is its coefficient c, N m s/rad for a
    revolute pair, N s/m for a prismatic one; `pair` the pair's links, `link` its second)."""
    name: str
    kind: Literal["force", "moment", "damper"]
    link: int
    point: str | None
    direction: Vec | Literal["against_velocity", "against_omega"] | None
    value: float | None
    table: Table | None
    characteristic: Characteristic | None = None   # moment only: M(omega of `link`)
    pair: tuple[int, int] | None = None            # damper only: the pair's links, as listed


@dataclass(frozen=True)
class Spring:
    """A linear spring between point a of one link and point b of another (N/m, m)."""
    name: str
    a: tuple[int, str]
    b: tuple[int, str]
    stiffness: float
    free_length: float


@dataclass(frozen=True)
class Gear:
    """The last gear pair of a working machine's drive (seed 000, sec. 7.1); lengths in m."""
    module: float
    z_pinion: int
    z_wheel: int
    correction: Literal["none", "equal", "unequal"]
    alpha_w_deg: float
    y: float
    centre_direction: Vec   # unit, from the crank axis to the pinion axis

    @property
    def r_w(self) -> float:
        """Pitch (rolling) radius of the wheel on the crank shaft, m."""
        r = self.module * self.z_wheel / 2
        if self.correction == "unequal":
            return r * (1 + 2 * self.y / (self.z_pinion + self.z_wheel))
        return r

    @property
    def r_b(self) -> float:
        """Arm of the balancing force about the crank axis (base-circle radius), m."""
        return self.r_w * math.cos(math.radians(self.alpha_w_deg))


@dataclass(frozen=True)
class SpeedLaw:
    """The crank's law of motion omega(phi) over one revolution (seed 000 sec. 1, seed 003).

    A table (`phi_deg`, `omega`) is interpolated by the periodic cubic spline through its points
    (C2: omega, d omega/d phi and eps = omega d omega/d phi are continuous, on any spacing of the
    angles); an expression is a function of `phi` (rad), differentiated exactly by the complex
    step. omega in rad/s, >= 0, in the drive's sense. With `slope` (a law found by
    `kinetostat.law_of_motion`, never read from a file): the periodic cubic Hermite through the
    table's values and these slopes (C1: omega and d omega/d phi exactly the given ones at the
    table's angles)."""
    phi_deg: tuple[float, ...] = ()
    omega: tuple[float, ...] = ()
    expression: str | None = None
    parameters: tuple[tuple[str, float], ...] = ()   # the model's parameters the expression may read
    slope: tuple[float, ...] = ()    # d omega / d phi at phi_deg, rad/s per rad (a one-revolution table, no repeated end)

    def __call__(self, phi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(omega, d omega / d phi) at crank angles `phi` (rad), rad/s and rad/s per rad."""
        phi = np.asarray(phi, dtype=float)
        if self.expression is not None:
            h = 1e-30                         # complex step: exact derivative, no cancellation
            expr, values = parse_expression(self.expression), dict(self.parameters)
            with np.errstate(all="ignore"):   # outside its real domain (sqrt, log of x < 0) omega is NaN
                w = np.broadcast_to(over_arrays(expr, {**values, "phi": phi}), phi.shape).astype(float)
                z = np.broadcast_to(over_arrays(expr, {**values, "phi": phi + 1j * h}), phi.shape)
            return w, np.where(np.isfinite(w), z.imag / h, np.nan)
        if self.slope:
            return _hermite_at(np.radians(self.phi_deg), np.asarray(self.omega), np.asarray(self.slope), phi)
        x, y, m = _periodic_spline(self.phi_deg, self.omega)
        return _spline_at(x, y, m, phi)


@dataclass(frozen=True)
class Drive:
    """The initial link I(0,1): crank angle reference, sense, speed."""
    link: int
    pivot: str
    point: str
    reference: Vec              # unit world direction of phi = 0
    sense: int                  # +1 ccw, -1 cw
    omega: float                # rad/s, >= 0 (0: statics), in `sense` (with a law: its largest value, the speed scale)
    eps: float                  # rad/s^2, in `sense` (with a law: the largest |eps| over the cycle)
    kind: Literal["engine", "machine"]
    gear: Gear | None = None
    design_deg: float = 30.0    # the design position: crank angle of the mechanism's picture, deg
    law: SpeedLaw | None = None   # omega(phi); None: the constant omega and eps above
    source: str = field(default="model", compare=False)   # the model file, for the law's errors

    @property
    def steady(self) -> bool:
        """Does the crank turn at one constant speed (no law, eps = 0)?"""
        return self.law is None and self.eps == 0.0

    def speed(self, phi: np.ndarray) -> tuple[np.ndarray | float, np.ndarray | float]:
        """(omega, eps) of the crank at angles `phi` (rad), in the drive's sense: the constants,
        or omega(phi) and eps = omega d omega / d phi of the law."""
        if self.law is None:
            return self.omega, self.eps
        w, dw = self.law(phi)
        eps = w * dw
        bad = ~(np.isfinite(w) & np.isfinite(eps) & (w >= 0))
        if bad.any():                     # between the angles checked at load: a pole, a NaN band, a dip
            where = "drive.omega_table" if self.law.expression is None else "drive.omega"
            at = np.round(np.degrees(np.asarray(phi, float)[bad]), 6)
            shown = ", ".join(f"{a:g}" for a in at[:8]) + (f", ... ({len(at)} angles)" if len(at) > 8 else "")
            raise ModelError([f"{where}: the law of motion gives omega = {w[bad][0]:.6g} rad/s, eps = "
                              f"{eps[bad][0]:.6g} rad/s^2 at phi = {shown} deg: omega must be real, finite and "
                              f">= 0 (in the drive's sense), eps finite"], source=self.source)
        return w, eps


@dataclass(frozen=True)
class Flywheel:
    """`[flywheel]`: a flywheel on the crank shaft, its centre on the crank's axis: its moment of
    inertia `J` (kg m^2, >= 0), or the coefficient of fluctuation `delta` (1, 0 < delta < 2) to size
    it for (`kinetostat.law_of_motion`); exactly one of the two."""
    J: float | None = None
    delta: float | None = None


@dataclass(frozen=True)
class Friction:
    f: float                   # reduced friction coefficient
    radius: float | None       # default journal radius, m
    method: str = "first"      # analyze's default: "first" (the first approximation) or "reactions"


#: What a `[[published]]` entry may measure -> the SI unit of its magnitude.
PUBLISHED_UNITS: Mapping[str, str] = MappingProxyType({
    "velocity": "m/s", "acceleration": "m/s^2", "omega": "rad/s", "eps": "rad/s^2",
    "inertia_force": "N", "inertia_moment": "N m", "reaction": "N",
    "balancing_moment": "N m", "lever_moment": "N m", "balancing_force": "N"})


@dataclass(frozen=True)
class Published:
    """A value a source prints for this model (`[[published]]`), and what it measures.

    The measured quantity is a magnitude at one crank angle, or (`reduce`) its min or max over
    several angles, or the angle of its max ("angle_of_max", value and tolerance in deg)."""
    symbol: str                    # as the source names it
    quantity: str                  # a key of PUBLISHED_UNITS
    value: float                   # the published number, in `unit`
    unit: str                      # PUBLISHED_UNITS[quantity], or "deg" for angle_of_max
    angles: tuple[float, ...]      # crank angles, deg (model's reference and sense)
    reduce: Literal["min", "max", "angle_of_max"] | None   # None: the value at the single angle
    tolerance: float               # accepted |difference|: relative, or deg for angle_of_max
    source: str                    # where the number is printed
    meaning: str = ""              # what it is, in this project's terms
    accuracy: str = ""             # why the tolerance is what it is
    point: str | None = None       # velocity, acceleration: the point
    relative_to: str | None = None  # ... minus this point's (relative velocity or acceleration)
    link: int | None = None        # omega, eps, inertia_force, inertia_moment: the link
    pair: tuple[int, int] | None = None   # reaction: R(i, j), force of link i on link j


@dataclass(frozen=True)
class Study:
    """A parameter study the model declares (`[study]`): the largest |R(i,j)| of one pair over the
    cycle for every combination of the parameters' values (first parameter: rows, second: columns)."""
    title: str
    vary: tuple[tuple[str, tuple[float, ...]], ...]   # (parameter, its values), one or two
    pair: tuple[int, int]                             # R(i, j): force of link i on link j
    steps: int                                        # crank angles per cycle, equally spaced from 0
