"""The mechanism model: built once from a TOML file (or a dict), validated, never mutated.

Field meanings and units are those of `models/FORMAT.md`. All coordinates in metres, masses in
kg, moments of inertia in kg m^2, angles in radians unless the name says `_deg`.

May use: the standard library, numpy, errors, expressions, planar, structure, examples.
"""
from __future__ import annotations

import functools
import keyword
import math
import re
import stat
import sys
import tomllib
import unicodedata
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType
from typing import Any, Callable, Literal, Mapping

import numpy as np

from .errors import ModelError, ModelFileNotFound, ModelWarning, StructureError
from .expressions import CONSTANTS, FUNCTIONS, ExpressionError, over_arrays, parse as parse_expression, shown_number
from .expressions import _finite_number, suggest, suggestion_budget
from .expressions import resolve as resolve_parameters
from .planar import diameter
from .structure import Structure, analyse_structure

__all__ = ["Link", "Body", "Pair", "Table", "Load", "Characteristic", "SpeedLaw", "combine", "Spring", "Gear", "Drive", "Friction", "Published", "Study", "Mechanism",
           "PUBLISHED_UNITS", "load", "loads", "from_dict"]

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


def combine(bodies: tuple[Body, ...]) -> tuple[float, Vec, float]:
    """Total mass (kg), centre of mass (local, m) and I_S about it (kg m^2) of `bodies`:
    m = sum m_b, S = sum m_b S_b / m, I_S = sum (I_b + m_b |S_b - S|^2)."""
    m = math.fsum(b.mass for b in bodies)
    if m == 0:
        return 0.0, (0.0, 0.0), 0.0
    S = (math.fsum(b.mass * b.com[0] for b in bodies) / m, math.fsum(b.mass * b.com[1] for b in bodies) / m)
    I_S = math.fsum(b.I_S + b.mass * ((b.com[0] - S[0]) ** 2 + (b.com[1] - S[1]) ** 2) for b in bodies)
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
            value = over_arrays(_expression(self.expression), {**dict(self.parameters), "omega": omega})
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
    step. omega in rad/s, >= 0, in the drive's sense."""
    phi_deg: tuple[float, ...] = ()
    omega: tuple[float, ...] = ()
    expression: str | None = None
    parameters: tuple[tuple[str, float], ...] = ()   # the model's parameters the expression may read

    def __call__(self, phi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(omega, d omega / d phi) at crank angles `phi` (rad), rad/s and rad/s per rad."""
        phi = np.asarray(phi, dtype=float)
        if self.expression is not None:
            h = 1e-30                         # complex step: exact derivative, no cancellation
            expr, values = _expression(self.expression), dict(self.parameters)
            with np.errstate(all="ignore"):   # outside its real domain (sqrt, log of x < 0) omega is NaN
                w = np.broadcast_to(over_arrays(expr, {**values, "phi": phi}), phi.shape).astype(float)
                z = np.broadcast_to(over_arrays(expr, {**values, "phi": phi + 1j * h}), phi.shape)
            return w, np.where(np.isfinite(w), z.imag / h, np.nan)
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
class Friction:
    f: float                   # reduced friction coefficient
    radius: float | None       # default journal radius, m
    method: str = "first"      # analyze's default: "first" (seed 003's first approximation) or "reactions"


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


@dataclass(frozen=True)
class Mechanism:
    """A planar one-degree-of-freedom linkage. Build with `kinetostat.load`; never mutated."""
    name: str
    source: str
    assumptions: tuple[str, ...]
    g: float
    links: tuple[Link, ...]           # index = link id, links[0] is the frame
    pairs: tuple[Pair, ...]
    branches: Mapping[frozenset, int]
    loads: tuple[Load, ...]
    springs: tuple[Spring, ...]
    drive: Drive
    friction: Friction | None
    published: tuple[Published, ...] = ()   # the sources' printed values for this model
    path: str | None = None
    #: `[parameters]`: name -> value, in the file's order (overrides applied)
    parameters: Mapping[str, float] = field(default_factory=lambda: MappingProxyType({}))
    #: every field and parameter given as an expression: field path -> (expression, value)
    expressions: Mapping[str, tuple[str, float]] = field(default_factory=lambda: MappingProxyType({}))
    study: Study | None = None
    #: `[lettering]`: the names the model's source text uses (frame, M_bal, F_bal, loads, name,
    #: language), as given; read through `kinetostat.plans.lettering.lettering`
    lettering: Mapping[str, Any] = field(default_factory=lambda: MappingProxyType({}))
    #: Structural analysis (mobility, Assur groups, structure formula), derived from the pairs
    #: when the mechanism is built; raises StructureError for what kinetostat does not analyse.
    structure: Structure = field(init=False, repr=False, compare=False)
    # memo of quantities derived from the (immutable) data, e.g. the strokes of travel tables
    _derived: dict = field(default_factory=dict, repr=False, compare=False)

    def __post_init__(self):
        object.__setattr__(self, "structure", analyse_structure(self.n_links, self.pairs, self.branches))

    def __repr__(self) -> str:
        return (f"Mechanism(name={_abbreviate(self.name)!r}, links={self.n_links}, pairs={len(self.pairs)}, "
                f"structure={self.structure.formula!r}, drive={self.drive.kind} {self.drive.omega:.4g} rad/s)")

    @property
    def n_links(self) -> int:
        """Number of links including the frame."""
        return len(self.links)

    def point_owner(self, name: str) -> int:
        """Id of the first link that carries point `name`."""
        for link in self.links:
            if name in link.points:
                return link.id
        raise KeyError(f"unknown point {name!r}. Valid names: {sorted(self.point_names)}")

    @property
    def point_names(self) -> list[str]:
        seen: dict[str, None] = {}
        for link in self.links:
            seen.update(dict.fromkeys(link.points))
        return list(seen)

    def pair_between(self, i: int, j: int) -> Pair:
        for p in self.pairs:
            if set(p.links) == {i, j}:
                return p
        raise KeyError(f"no kinematic pair between links {i} and {j}. "
                       f"Pairs: {[p.label for p in self.pairs]}")

    def memo(self, key: Any, make: Callable[[], Any]) -> Any:
        """make(), computed once per key and kept; its arrays (alone or in a tuple) read-only, so
        that no caller can change what later analyses read."""
        if key not in self._derived:
            value = make()
            for a in value if isinstance(value, tuple) else (value,):
                if isinstance(a, np.ndarray):
                    a.flags.writeable = False
            self._derived[key] = value
        return self._derived[key]

    @property
    def inertia_arrays(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(mass (L,), I_S (L,), centre of mass in the local frame (L,) complex), read-only."""
        return self.memo("inertia", lambda: (
            np.array([link.mass for link in self.links]), np.array([link.I_S for link in self.links]),
            np.array([complex(*link.points[link.com]) if link.com else 0j for link in self.links])))

    @property
    def points_z(self) -> tuple[Mapping[str, complex], ...]:
        """Every link's points in its local frame as complex numbers x + iy, read-only."""
        return self.memo("points_z", lambda: tuple(
            MappingProxyType({n: complex(*xy) for n, xy in link.points.items()}) for link in self.links))

    @property
    def size(self) -> float:
        """Characteristic length: the largest distance between two points of one link, m."""
        return self.memo("size", self._largest_link)

    def _largest_link(self) -> float:
        return max((_span(link.points.values()) for link in self.links[1:]), default=0.0) or 1.0


# ----------------------------------------------------------------------------- laws and characteristics

def _mentions_phi(text: str) -> bool:
    """Whether a drive's `omega` string is a law of motion (an expression of `phi`) rather than
    a constant speed written over the model's parameters (`"n1 * pi / 30"`)."""
    try:
        return "phi" in _expression(text).names
    except ExpressionError:
        return True                  # not a valid expression: the law's reader says why


#: A checked expression, parsed once (laws of motion and characteristics are evaluated per call).
_expression = functools.lru_cache(maxsize=256)(parse_expression)


@functools.lru_cache(maxsize=64)
def _periodic_spline(x_deg: tuple, y: tuple) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Knots x (rad, increasing, within one period 2 pi; a last knot at x[0] + 2 pi repeats the
    first and is dropped), values y and second derivatives m of the periodic cubic spline
    through the points (x_deg, deg; y)."""
    x, y = np.radians(x_deg), np.asarray(y, float)
    if np.isclose(x[-1] - x[0], 2 * np.pi, rtol=0, atol=1e-12):
        x, y = x[:-1], y[:-1]
    n = len(x)
    h = np.diff(np.append(x, x[0] + 2 * np.pi))           # h[i] = x[i+1] - x[i], cyclically
    slope = (np.roll(y, -1) - y) / h
    r = 6 * (slope - np.roll(slope, 1))
    if n < 3:                                             # both neighbours are one knot
        return x, y, np.linalg.solve(np.diag(2 * (np.roll(h, 1) + h)) + np.diag(h.sum() * np.ones(n - 1), 1)
                                     + np.diag(h.sum() * np.ones(n - 1), -1), r)
    return x, y, _cyclic_tridiagonal(np.roll(h, 1), 2 * (np.roll(h, 1) + h), h, r)


def _cyclic_tridiagonal(sub: np.ndarray, diag: np.ndarray, sup: np.ndarray, r: np.ndarray) -> np.ndarray:
    """x of A x = r, A tridiagonal with corners (n >= 3): A[i, i-1] = sub[i], A[i, i] = diag[i],
    A[i, i+1] = sup[i], indices cyclic (sub[0] = A[0, n-1], sup[n-1] = A[n-1, 0]). The Thomas
    algorithm with the Sherman-Morrison correction for the corners: O(n) work and memory."""
    n = len(diag)
    beta, alpha, gamma = float(sub[0]), float(sup[-1]), -float(diag[0])
    b = [float(v) for v in diag]
    b[0] -= gamma
    b[-1] -= alpha * beta / gamma
    a, c, d = [float(v) for v in sub], [float(v) for v in sup], [float(v) for v in r]
    u = [gamma] + [0.0] * (n - 2) + [alpha]
    cp, xp, zp = [0.0] * n, [0.0] * n, [0.0] * n       # forward sweep for r and u together
    cp[0], xp[0], zp[0] = c[0] / b[0], d[0] / b[0], u[0] / b[0]
    for i in range(1, n):
        m = b[i] - a[i] * cp[i - 1]
        cp[i] = c[i] / m
        xp[i] = (d[i] - a[i] * xp[i - 1]) / m
        zp[i] = (u[i] - a[i] * zp[i - 1]) / m
    for i in range(n - 2, -1, -1):
        xp[i] -= cp[i] * xp[i + 1]
        zp[i] -= cp[i] * zp[i + 1]
    x, z = np.array(xp), np.array(zp)
    return x - z * (x[0] + beta * x[-1] / gamma) / (1 + z[0] + beta * z[-1] / gamma)


def _spline_at(x: np.ndarray, y: np.ndarray, m: np.ndarray, phi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Value and first derivative of the periodic cubic spline (x, y, m) at `phi` (rad)."""
    xe, ye, me = np.append(x, x[0] + 2 * np.pi), np.append(y, y[0]), np.append(m, m[0])
    t = x[0] + np.mod(phi - x[0], 2 * np.pi)
    i = np.clip(np.searchsorted(xe, t, side="right") - 1, 0, len(x) - 1)
    h = xe[i + 1] - xe[i]
    a, b = xe[i + 1] - t, t - xe[i]
    ca, cb = ye[i] / h - me[i] * h / 6, ye[i + 1] / h - me[i + 1] * h / 6
    # the same cubic, written so that it is exact at a knot (a table's 0 stays 0, never -1e-21)
    value = ye[i] * (a / h) + ye[i + 1] * (b / h) + (me[i] * a * (a * a - h * h) + me[i + 1] * b * (b * b - h * h)) / (6 * h)
    slope = (-me[i] * a**2 + me[i + 1] * b**2) / (2 * h) - ca + cb
    return value, slope


def _span(points) -> float:
    """Largest distance between two of `points` ((x, y) pairs), m."""
    return diameter(complex(*xy) for xy in points)


def _abbreviate(text: str, limit: int = 90) -> str:
    """`text` cut to `limit` characters with an ellipsis: a name as a summary shows it."""
    return text if len(text) <= limit else text[:limit - 1] + "\u2026"


# ----------------------------------------------------------------------------- loading

def load(path: str | Path, parameters: Mapping[str, Any] | None = None) -> Mechanism:
    """Read and validate a model file (TOML), or a bundled model by name (`load("ice_crank_slider")`).
    `parameters`: values (numbers or expressions) that replace those of the file's `[parameters]`.

    Raises `ModelError` listing every problem (`ModelFileNotFound`, also a FileNotFoundError,
    where the file does not exist)."""
    from .examples import resolve
    path = resolve(path)
    return loads(_read_text(path), source=str(path), parameters=parameters)


def _read_text(path: Path) -> str:
    """The text of a model file: a regular file (never a FIFO or a device, which would block or
    never end) of at most MAX_FILE_BYTES, UTF-8."""
    try:
        st = path.stat()
        if not stat.S_ISREG(st.st_mode):
            what = "a directory" if stat.S_ISDIR(st.st_mode) else "not a regular file (a FIFO, device or socket)"
            raise ModelError([f"cannot read file: {what}; a model is a regular TOML file"], source=str(path))
        if st.st_size > MAX_FILE_BYTES:
            raise ModelError([f"file of {st.st_size} bytes is too large for a model (at most {MAX_FILE_BYTES})"],
                             source=str(path))
        with open(path, "rb") as f:
            raw = f.read(MAX_FILE_BYTES + 1)      # the size may change between stat and read
    except FileNotFoundError:
        raise ModelFileNotFound(str(path)) from None
    except OSError as exc:
        raise ModelError([f"cannot read file: {exc.strerror}"], source=str(path)) from None
    if len(raw) > MAX_FILE_BYTES:
        raise ModelError([f"file is too large for a model (more than {MAX_FILE_BYTES} bytes)"], source=str(path))
    try:
        return raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise ModelError([f"not UTF-8 text: byte 0x{exc.object[exc.start]:02x} at offset {exc.start}"],
                         source=str(path)) from None


def loads(text: str, source: str = "<string>", parameters: Mapping[str, Any] | None = None) -> Mechanism:
    """Parse a model from TOML text; `parameters` as for `load`."""
    _check_key_cost(text, source)
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ModelError([f"TOML syntax error: {exc}"], source=source) from None
    except RecursionError:
        raise ModelError(["TOML nested too deeply (arrays or tables within each other)"], source=source) from None
    with suggestion_budget():       # "did you mean" work bounded per model
        return _Reader(data, source, text, parameters).mechanism()


def _check_key_cost(text: str, source: str) -> None:
    """Refuse keys whose parsing would take too much memory, before tomllib sees them: tomllib
    keeps the path of every level of every key, so memory grows with the number of keys and as
    the square of their depth (measured: 65 keys 3000 levels deep, 390 kB, took 2.3 GB)."""
    cost = 0
    for n, line in enumerate(text.splitlines(), 1):
        head = line.lstrip()
        key = head if head.startswith("[") else line.partition("=")[0]
        if len(key) > MAX_KEY:
            raise ModelError([f"line {n}: a key of {len(key)} characters (at most {MAX_KEY})"], source=source)
        if not head.startswith("#") and ("=" in line or head.startswith("[")):
            cost += _KEY_BYTES + _LEVEL_BYTES * (key.count(".") + 1) ** 2
            if cost > MAX_KEY_MEMORY:
                raise ModelError([f"line {n}: the keys up to here would take about {cost / 2**20:.0f} MiB to "
                                  f"parse (at most {MAX_KEY_MEMORY / 2**20:.0f} MiB): too many keys, or keys "
                                  f"nested too deeply (this one has {key.count('.') + 1} dotted parts)"],
                                 source=source)


def from_dict(data: Mapping[str, Any], source: str = "<dict>",
              parameters: Mapping[str, Any] | None = None) -> Mechanism:
    """Build a Mechanism from the parsed structure of a model file; `parameters` as for `load`."""
    with suggestion_budget():       # "did you mean" work bounded per model
        return _Reader(data, source, overrides=parameters).mechanism()


#: The variables of laws of motion (phi, rad) and of motor characteristics (omega, rad/s): no parameter's name.
LAW_VARIABLES = ("phi", "omega")


def _code_points(name: str) -> str:
    """A name with the code points that are not ASCII named: 'µ' -> "'µ' (U+00B5 MICRO SIGN)"."""
    odd = [f"U+{ord(c):04X} {unicodedata.name(c, '?')}" for c in dict.fromkeys(name) if ord(c) > 127]
    return f"{name!r}" + (f" ({', '.join(odd[:4])}{', ...' if len(odd) > 4 else ''})" if odd else "")


def _suggest(name: Any, valid) -> str:
    """" (did you mean 'mass'?)" when `name` is a near miss of one of `valid`, else "" (bounded
    work: `expressions.suggest`)."""
    return suggest(name, valid) if isinstance(name, str) else ""


class _Lines:
    """Where each table and key of a TOML text sits: field path -> line number (best effort:
    tomllib gives no positions, so the text is scanned for table headers and keys)."""

    _HEADER = re.compile(r"\s*(\[\[?)\s*([A-Za-z0-9_\-.\"' ]+?)\s*\]\]?\s*(#.*)?$")   # not a row [x, y],
    _PART = r"""(?:[A-Za-z0-9_\-]+|"[^"]*"|'[^']*')"""
    _KEY = re.compile(rf"\s*({_PART}(?:\s*\.\s*{_PART})*)\s*=")
    _INLINE_KEY = re.compile(r"[{,]\s*([A-Za-z0-9_\-]+|\"[^\"]*\"|'[^']*')\s*=")

    def __init__(self, text: str):
        self.at: dict[tuple, int] = {}
        arrays: dict[tuple, int] = {}         # array-of-tables path -> tables seen so far
        current: tuple = ()
        in_string = False
        for n, line in enumerate(text.splitlines(), 1):
            if (line.count('"""') + line.count("\'\'\'")) % 2:
                in_string = not in_string
                if not in_string:
                    continue
            if in_string:
                continue
            head = self._HEADER.match(line)
            if head:
                parts = self._split(head[2])
                if head[1] == "[[":
                    parts = self._resolve(parts[:-1], arrays) + parts[-1:]
                    arrays[parts] = arrays.get(parts, 0) + 1
                    current = parts + (arrays[parts] - 1,)
                else:
                    current = self._resolve(parts, arrays)
                self.at.setdefault(current, n)
                continue
            key = self._KEY.match(line)
            if key:
                path = current + self._split(key[1])
                self.at.setdefault(path, n)
                for inner in self._INLINE_KEY.findall(line):
                    self.at.setdefault(path + (inner.strip("\"'"),), n)

    @staticmethod
    def _split(key: str) -> tuple:
        return tuple(p.strip().strip("\"'") for p in key.split("."))

    @staticmethod
    def _resolve(parts: tuple, arrays: dict[tuple, int]) -> tuple:
        out: tuple = ()
        for p in parts:
            out += (p,)
            if out in arrays:
                out += (arrays[out] - 1,)
        return out

    def line(self, path: tuple) -> int | None:
        """Line of `path` or of its nearest enclosing table or key."""
        for end in range(len(path), 0, -1):
            if path[:end] in self.at:
                return self.at[path[:end]]
        return None


#: Longest key (or table header) of a model file, characters.
MAX_KEY = 10_000
#: Largest model file read, bytes (a model is a few kB; 4000 links take 0.8 MB).
MAX_FILE_BYTES = 32 * 2**20
#: Memory tomllib may take for the keys of one file, estimated as _KEY_BYTES per key plus
#: _LEVEL_BYTES per square of its depth (fitted to measurements: 266k two-level keys of a
#: 4 MB file took 220 MB, 29k keys of 64 levels 1.1 GB).
MAX_KEY_MEMORY = 256 * 2**20
_KEY_BYTES, _LEVEL_BYTES = 800, 9
#: Largest magnitude of any number in a model file (m, kg, N, ...): beyond it squares overflow.
MAX_VALUE = 1e12
#: Most points of one link.
MAX_POINTS = 10_000
#: Shortest nonzero span of a link, m: sqrt of the smallest normal double, so that squares of
#: lengths stay normal numbers.
MIN_LENGTH = 1e-150
#: Smallest base radius of the drive's gear wheel, relative to the largest link.
MIN_GEAR = 1e-6
#: A ModelWarning asks whether a model was drawn in millimetres above these: the largest link,
#: m, and the crank pin's speed, m/s (machines of the texts: links below 2 m, pins below 30 m/s).
LARGEST_LINK, FASTEST_PIN = 20.0, 340.0
#: Warned: a link whose radius of gyration exceeds this many times its span (I_S in g mm^2 makes it
#: 30000 times too long; a flywheel on a crank, a few spans), and a
#: force diagram whose largest force is below this fraction of the mechanism's weights and
#: inertia forces (a pressure in MPa times an area in m^2?).
GYRATION_SPANS, FORCE_SCALE = 100.0, 1e-4

_TOP_KEYS = {"mechanism", "parameters", "drive", "frame", "link", "pair", "group", "load", "spring", "friction",
             "published", "study", "lettering"}
#: Most parameters of one file, and most values one parameter takes in a study.
MAX_PARAMETERS, MAX_STUDY_VALUES = 1000, 50
#: Most crank angles one `[[published]]` entry may list.
MAX_PUBLISHED_ANGLES = 3600


#: Characters of an expression quoted in a message.
MAX_SHOWN = 120
#: Longest name of the mechanism, a point, link, body, load or spring (each labels plots and plans:
#: 10,000 characters took a report two minutes, a mechanism's name of 100,000 characters 24 s).
MAX_NAME = 200
#: Most problems listed for one file (the rest are counted): 300,000 unknown keys stay one short list.
MAX_PROBLEMS = 100


def _finite(x: Any) -> bool:
    """A finite number, also as a float (an integer of 400 digits is not)."""
    return isinstance(x, (int, float)) and not isinstance(x, bool) and _finite_number(x)


def _subnormal(x: float) -> bool:
    """Nonzero but below the smallest normal double: no model number is meant so."""
    return 0 < abs(x) < sys.float_info.min


class _Reader:
    """Reads the raw TOML structure, collecting every problem instead of stopping at the first."""

    def __init__(self, data: Mapping[str, Any], source: str, text: str | None = None,
                 overrides: Mapping[str, Any] | None = None):
        self.data, self.source, self.problems, self.lines = data, source, [], []
        self.overrides = dict(overrides or {})
        self.values: dict[str, float] = {}        # parameters and g, as expressions read them
        self.failed: set[str] = set()             # parameters (or g) whose value is in error
        self.expressions: dict[str, tuple[str, float]] = {}   # field path -> (expression, value)
        self.where_lines = _Lines(text) if text is not None else None
        self.link_table: dict[int, int] = {}      # link id -> index of its [[link]] table
        # causes already reported, whose consequences are not reported again:
        self.ids_unknown = False                  # some [[link]] has no valid id: "unknown link" follows
        self.points_unread: set[tuple[int, str | None]] = set()   # (link, point) that failed (None: all)
        self.misspelled: set[str] = set()         # field paths given under a near-miss name
        self.unshown = 0                          # problems beyond MAX_PROBLEMS, counted only
        self.group_tables: dict[frozenset, tuple[int, tuple]] = {}   # group -> (its [[group]], links as listed)
        self.coincident: dict[int, str] = {}      # links whose points all coincide -> their field path
        self.slider_axes: set[int] = set()        # P pairs (index) whose slider frame the file states

    def err(self, msg: str) -> None:
        path = msg.partition(": ")[0]
        if path in self.misspelled and msg[len(path):].startswith(": missing"):
            return          # "mass: missing" after "masss: unknown field (did you mean 'mass'?)"
        if len(self.problems) >= MAX_PROBLEMS:
            self.unshown += 1
            return
        self.problems.append(msg)
        self.lines.append(self.line_of(path))

    _STEP = re.compile(r"(\[\[(\w+)\]\] #(\d+)|[^.\[]+)(?:\[(id=)?(\d+)\])?")

    def line_of(self, path: str) -> int | None:
        """Line of the file where the field `path` of a message (e.g. `link[id=2].mass`) sits."""
        if self.where_lines is None or " " in path.replace("<top level>", "").replace("[[link]] #", ""):
            return None
        steps: tuple = ()
        for part in path.split("."):
            m = self._STEP.fullmatch(part)
            if m is None:
                return None
            if m[2]:                                  # [[link]] #3: the third table
                steps += (m[2], int(m[3]) - 1)
                continue
            steps += () if m[1] == "<top level>" else (m[1],)
            if m[5] is not None:
                steps += (self.link_table.get(int(m[5]), -1) if m[4] else int(m[5]),)
        return self.where_lines.line(steps) if steps else None

    # -- parameters and expressions
    def read_parameters(self, head: Mapping) -> None:
        """Evaluate `[parameters]` (with the overrides) and g (mechanism.g, which expressions read
        as `g`), in any order, into self.values; problems are recorded against each parameter."""
        t = self.data.get("parameters", {})
        if not isinstance(t, dict):
            self.err("parameters: expected a table of named numbers and expressions")
            t = {}
        if len(t) > MAX_PARAMETERS:
            self.err(f"parameters: {len(t)} parameters, at most {MAX_PARAMETERS}")
            t = {}
        raw = dict(t)
        for name in raw:
            if name == "g":
                self.err("parameters.g: g is mechanism.g (m/s^2), which expressions read as g: give it there")
            elif name in FUNCTIONS or name in CONSTANTS:
                self.err(f"parameters.{name}: {name!r} is the name of a function or constant of expressions")
            elif name in LAW_VARIABLES:
                self.err(f"parameters.{name}: {name!r} is the variable of a law of motion omega(phi) or of a "
                         f"characteristic M(omega), which would hide this parameter there; choose another name")
            elif unicodedata.normalize("NFKC", name) != name:
                self.err(f"parameters.{name}: {_code_points(name)} reads as {_code_points(unicodedata.normalize('NFKC', name))} "
                         f"in expressions (Unicode NFKC, as Python folds names); write it so")
            elif keyword.iskeyword(name):
                self.err(f"parameters.{name}: {name!r} is a Python keyword, which an expression reads as itself, "
                         f"never as this parameter; choose another name")
            elif not name.isidentifier() or name.startswith("__"):
                self.err(f"parameters.{name}: a parameter's name is a Python-style identifier (letters, digits, _)")
        for name, x in self.overrides.items():
            if name != "g" and name not in raw:
                self.err(f"parameters: cannot override {name!r}: the model has no such parameter"
                         f"{_suggest(name, [*raw, 'g'])}. Parameters: {sorted(raw)}")
            elif name != "g":
                raw[name] = x
        raw = {n: x for n, x in raw.items() if n != "g"}
        if "g" in head or "g" in self.overrides:
            raw["g"] = self.overrides.get("g", head.get("g"))
        values, problems = resolve_parameters(raw)
        for name, msg in problems.items():
            if name != "g":             # mechanism.g reports its own problem when read
                self.err(f"parameters.{name}: {msg}")
        self.values, self.failed = values, set(problems)
        for name, x in raw.items():
            if isinstance(x, str) and name in values:
                self.expressions["mechanism.g" if name == "g" else f"parameters.{name}"] = (x, values[name])

    def scalar(self, x: Any, path: str) -> Any:
        """`x` itself, or the value of the expression `x` (a string) over the parameters; None
        after recording a problem (naming `path` and the parameter that fails)."""
        if path == "mechanism.g" and "g" in self.values:      # also a number that an override of g replaces
            return self.values["g"]
        if not isinstance(x, str):
            return x
        try:
            e = parse_expression(x)
            bad = sorted(n for n in e.names if n in self.failed)
            if bad:
                raise ExpressionError(f"reads {', '.join(map(repr, bad))}, which has an error (see "
                                      f"{', '.join('mechanism.g' if n == 'g' else f'parameters.{n}' for n in bad)})")
            value = e(self.values)
        except ExpressionError as exc:
            self.err(f'{path}: expression "{x:.{MAX_SHOWN}}": {exc}')
            return None
        self.expressions[path] = (x, value)
        return value

    # -- typed getters: each returns None after recording a problem
    def number(self, tab: Mapping, key: str, where: str, *, default: Any = "required",
               minimum: float | None = None, positive: bool = False) -> float | None:
        if key not in tab:
            if default == "required":
                self.err(f"{where}.{key}: missing (a number is required)")
                return None
            return default
        x = self.scalar(tab[key], f"{where}.{key}")
        if x is None:
            return None
        shown = shown_number(x) if not isinstance(tab[key], str) else f'{x!r} (= "{tab[key]:.{MAX_SHOWN}}")'
        if not _finite(x):
            self.err(f"{where}.{key}: expected a finite number, got {shown}")
            return None
        if abs(x) > MAX_VALUE:
            self.err(f"{where}.{key}: {shown} is out of range (|value| <= {MAX_VALUE:g})")
            return None
        if (positive or key in ("g", "rpm", "omega")) and _subnormal(x):   # a speed, module, radius or g: a divisor
            self.err(f"{where}.{key}: {shown} is subnormal (0 < |value| < {sys.float_info.min:.3g}): it loses its "
                     f"digits, and its products turn into 0, NaN or inf; write 0 or the value meant")
            return None
        if positive and x <= 0:
            self.err(f"{where}.{key}: must be > 0, got {shown}")
            return None
        if minimum is not None and x < minimum:
            self.err(f"{where}.{key}: must be >= {minimum}, got {shown}")
            return None
        return float(x)

    def vec(self, x: Any, where: str, *, unit: bool = False) -> Vec | None:
        if isinstance(x, list) and len(x) == 2:
            x = [self.scalar(c, f"{where}[{i}]") for i, c in enumerate(x)]
            if None in x:
                return None
        if not (isinstance(x, list) and len(x) == 2 and all(_finite(c) for c in x)):
            self.err(f"{where}: expected [x, y] with two finite numbers, got {x!r}")
            return None
        if max(abs(x[0]), abs(x[1])) > MAX_VALUE:
            self.err(f"{where}: {x!r} is out of range (|coordinate| <= {MAX_VALUE:g})")
            return None
        if unit:
            n = math.hypot(*x)
            if n == 0:
                self.err(f"{where}: direction must not be zero")
                return None
            return (x[0] / n, x[1] / n)
        return (float(x[0]), float(x[1]))

    def string(self, tab: Mapping, key: str, where: str, *, choices: tuple[str, ...] | None = None,
               default: Any = "required") -> str | None:
        if key not in tab:
            if default == "required":
                self.err(f"{where}.{key}: missing (a string is required)")
                return None
            return default
        x = tab[key]
        if not isinstance(x, str):
            self.err(f"{where}.{key}: expected a string, got {x!r}")
            return None
        if choices and x not in choices:
            self.err(f"{where}.{key}: invalid value {x!r}{_suggest(x, choices)}. Valid values: {list(choices)}")
            return None
        if key == "name" and len(x) > MAX_NAME:
            self.err(f"{where}.name: {len(x)} characters, at most {MAX_NAME} (it labels plots and plans)")
            return None
        return x

    def integer(self, tab: Mapping, key: str, where: str) -> int | None:
        x = self.scalar(tab.get(key), f"{where}.{key}")     # an expression must give a whole number
        if isinstance(x, float) and x.is_integer() and isinstance(tab.get(key), str):
            x = int(x)
        if not isinstance(x, int) or isinstance(x, bool):
            self.err(f"{where}.{key}: expected an integer, got {x!r}" if key in tab
                     else f"{where}.{key}: missing (an integer is required)")
            return None
        return x

    def lettering(self, links: list[Link], loads: list[Load]) -> Mapping[str, Any]:
        """`[lettering]`: the text's names (models/FORMAT.md), checked; frozen."""
        t = self.data.get("lettering", {})
        if not isinstance(t, dict):
            self.err("lettering: expected a table")
            return MappingProxyType({})
        self.unknown_keys(t, {"frame", "M_bal", "F_bal", "loads", "name", "language"}, "lettering")
        out: dict[str, Any] = {}
        if "frame" in t:
            k = t["frame"]
            if not isinstance(k, int) or isinstance(k, bool) or not 0 <= k <= 99 or (k and k < len(links)):
                self.err(f"lettering.frame: expected the frame's number 0..99, not a moving link's "
                         f"(1..{len(links) - 1}), got {k!r}")
            else:
                out["frame"] = k
        for key in ("M_bal", "F_bal"):
            x = self.string(t, key, "lettering", default=None)
            if x is not None and not (0 < len(x) <= 16 and x.isprintable()):
                self.err(f"lettering.{key}: expected a symbol of 1..16 printable characters, got {x!r}")
            elif x is not None:
                out[key] = x
        x = self.string(t, "language", "lettering", choices=("en", "uk", "ru"), default=None)
        if x is not None:
            out["language"] = x
        names = {ld.name for ld in loads}
        for key, valid in (("loads", names), ("name", {"en", "uk", "ru"})):
            tab = t.get(key, {})
            if not isinstance(tab, dict) or not all(isinstance(v, str) and v.isprintable() for v in tab.values()):
                self.err(f"lettering.{key}: expected a table of strings")
                continue
            bad = sorted(set(tab) - valid)
            if bad:
                self.err(f"lettering.{key}.{bad[0]}: no such {'load' if key == 'loads' else 'language'}. "
                         f"Valid: {sorted(valid)}")
                continue
            if tab:
                out[key] = MappingProxyType(dict(tab))
        return MappingProxyType(out)

    def table_list(self, key: str) -> list:
        x = self.data.get(key, [])
        if not isinstance(x, list) or not all(isinstance(t, dict) for t in x):
            self.err(f"{key}: expected an array of tables ([[{key}]])")
            return []
        return x

    def unknown_keys(self, tab: Mapping, allowed: set[str], where: str) -> None:
        unused = sorted(allowed.difference(tab))
        for k in tab:
            if k not in allowed and len(self.problems) >= MAX_PROBLEMS:
                self.unshown += 1
            elif k not in allowed:
                hint = _suggest(k, unused)
                if hint:
                    self.misspelled.add(f"{where}.{hint.split(chr(39))[1]}")
                self.err(f"{where}.{k}: unknown field{hint}. Valid fields: {sorted(allowed)}")

    # -- sections
    def mechanism(self) -> Mechanism:
        d = self.data
        self.unknown_keys(d, _TOP_KEYS, "<top level>")
        head = d.get("mechanism", {})
        if not isinstance(head, dict):
            self.err("mechanism: expected a table")
            head = {}
        self.unknown_keys(head, {"name", "source", "assumptions", "g"}, "mechanism")
        self.read_parameters(head)
        name = self.string(head, "name", "mechanism", default="unnamed")
        source = self.string(head, "source", "mechanism", default="")
        assumptions = head.get("assumptions", [])
        if not (isinstance(assumptions, list) and all(isinstance(a, str) for a in assumptions)):
            self.err("mechanism.assumptions: expected a list of strings")
            assumptions = []
        g = self.number(head, "g", "mechanism", minimum=0.0)

        links = self.links(g)
        pairs = self.pairs(links)
        drive = self.drive(links, pairs)
        branches = self.groups(links)
        loads_ = self.loads(links, pairs)
        springs = self.springs(links)
        friction = self.friction()
        published = self.published(links, pairs, drive)
        study = self.study(pairs)
        lettering = self.lettering(links, loads_)
        if friction is not None and friction.radius is None:
            for p in pairs:
                if p.kind == "R" and p.radius is None:
                    self.err(f"pair[{p.index}].radius: missing; friction losses need the journal radius "
                             f"of every revolute pair (or a default friction.radius)")
        if self.problems:
            more = [f"... and {self.unshown} more problems (the first {MAX_PROBLEMS} are shown)"] if self.unshown else []
            raise ModelError(self.problems + more, source=self.source, lines=self.lines + [None] * len(more))
        try:
            mech = Mechanism(name=name, source=source, assumptions=tuple(assumptions), g=g,
                             links=tuple(links), pairs=tuple(pairs),
                             branches=MappingProxyType(branches), loads=tuple(loads_),
                             springs=tuple(springs), drive=drive, friction=friction,
                             published=tuple(published), path=self.source,
                             parameters=MappingProxyType({n: v for n, v in self.values.items() if n != "g"}),
                             expressions=MappingProxyType(self.expressions), study=study, lettering=lettering)
        except StructureError as exc:
            raise StructureError(f"{self.source}: {exc}") from None
        for path, msg in self.doubts(mech):
            line = self.line_of(path)
            warnings.warn(f"{self.source}: {'' if line is None else f'line {line}: '}{path}: {msg}",
                          ModelWarning, stacklevel=4)
        return mech

    def doubts(self, mech: Mechanism):
        """(field path, message) for what loads but looks like a mistake: a number far out of
        the usual, or a rule the file relies on that is easily misread."""
        crank = mech.links[1].points
        r = math.dist(crank[mech.drive.pivot], crank[mech.drive.point])
        if mech.size > LARGEST_LINK or r * mech.drive.omega > FASTEST_PIN:
            yield "link", (f"the largest link spans {mech.size:.4g} m and the crank pin moves at "
                           f"{r * mech.drive.omega:.4g} m/s: lengths are read in metres; was the model drawn "
                           f"in millimetres? (warned above {LARGEST_LINK:g} m or {FASTEST_PIN:g} m/s)")
        if mech.g and not 1.0 <= mech.g <= 100.0:
            yield "mechanism.g", (f"{mech.g:g} m/s^2 is far from the 9.81 of the texts (warned outside 1..100): "
                                  f"is it in m/s^2? (0 switches gravity off)")
        for link in mech.links[1:]:
            span = _span(link.points.values())
            if link.mass > 0 and span > 0 and math.sqrt(link.I_S / link.mass) > GYRATION_SPANS * span:
                yield f"link[id={link.id}].I_S", (
                    f"{link.I_S:.4g} kg m^2 gives a radius of gyration of {math.sqrt(link.I_S / link.mass):.4g} m, "
                    f"more than {GYRATION_SPANS:g} times the link's span {span:.4g} m: is it in kg m^2? "
                    f"(g mm^2 is 1e-9 kg m^2, kg mm^2 1e-6)")
        scale = FORCE_SCALE * max([mech.g * link.mass for link in mech.links]
                                  + [link.mass * _span(link.points.values()) * mech.drive.omega**2 for link in mech.links])
        for n, ld in enumerate(mech.loads):
            if ld.kind == "force" and ld.table is not None and 0 < max(map(abs, ld.table.value)) * abs(ld.table.scale) < scale:
                peak = max(map(abs, ld.table.value)) * abs(ld.table.scale)
                yield f"load[{n}].table.scale", (
                    f"the diagram's largest force is {peak:.4g} N, below {FORCE_SCALE:g} of the mechanism's weights "
                    f"and inertia forces ({scale / FORCE_SCALE:.4g} N): is a pressure in MPa multiplied by an area "
                    f"in m^2? (scale in N per table unit: 1 MPa = 1e6 Pa)")
        for g in mech.structure.groups:
            n, listed = self.group_tables.get(frozenset(g.links), (None, ()))
            if g.kind == "RRR" and n is not None and listed[0] > listed[1]:
                yield f"group[{n}].links", (
                    f"{list(listed)}: in an RRR group j is the lower id, {listed[1]} (P on link {listed[1]}), "
                    f"whatever the order listed; if branch was computed with j = {listed[0]}, flip its sign; "
                    f"list the links as {sorted(listed)} to silence this warning")
        for p in mech.pairs:
            slider = mech.links[p.links[1]]
            if p.kind != "P" or abs(p.alpha) <= 1e-9 or p.index in self.slider_axes:
                continue                  # a guide along x (to rounding): both readings are the same
            y0 = slider.points[p.point][1]
            off = [n for n, xy in slider.points.items() if abs(xy[1] - y0) > 1e-9 * mech.size]
            if off:
                yield f"pair[{p.index}]", (
                    f"slider link {slider.id}'s points are read in a frame whose x axis runs along the guide "
                    f"(direction {list(p.direction)} in link {p.links[0]}'s frame), and {off[0]!r} lies "
                    f"{abs(slider.points[off[0]][1] - y0):.4g} m off the guide line in it; if the points were "
                    f"drawn in another frame (e.g. the world's), give slider_axis = the guide direction in "
                    f"that frame (slider_axis = [1.0, 0.0] confirms the default)")

    def points(self, raw: Any, where: str, lid: int | None = None) -> dict[str, Vec]:
        """A table of named points; those that fail are recorded in points_unread for link `lid`."""
        if not isinstance(raw, dict) or not raw or len(raw) > MAX_POINTS:
            self.err(f"{where}: {'missing: ' if raw is None else ''}expected a table of named points {{A = [x, y], ...}}"
                     + (f", at most {MAX_POINTS} of them, got {len(raw)}" if raw and isinstance(raw, dict) else ""))
            self.points_unread.add((lid, None))
            return {}
        out = {}
        for name, xy in raw.items():
            if len(name) > MAX_NAME:
                self.err(f"{where}: a point name of {len(name)} characters ({name[:20]!r}...), at most {MAX_NAME} "
                         f"(it labels plots and plans)")
                self.points_unread.add((lid, name))
                continue
            v = self.vec(xy, f"{where}.{name}")
            if v is not None:
                out[name] = v
            else:
                self.points_unread.add((lid, name))
        return out

    def links(self, g: float | None) -> list[Link]:
        frame = Link(0, "frame", MappingProxyType(self.points(self.data.get("frame"), "frame", 0)))
        raw = self.table_list("link")
        by_id: dict[int, Link] = {}
        allowed = {"id", "name", "points", "mass", "weight", "I_S", "com", "body"}
        for n, t in enumerate(raw):
            lid = t.get("id")
            valid_id = isinstance(lid, int) and not isinstance(lid, bool) and lid > 0
            # named by its id, as the texts number links; by its table's place only without one
            where = f"link[id={lid}]" if valid_id and lid not in by_id else f"[[link]] #{n + 1}"
            if valid_id and lid not in by_id:
                self.link_table[lid] = n
            self.unknown_keys(t, allowed, where)
            if valid_id and lid in by_id:
                self.err(f"{where}.id: duplicate link id {lid} (link[id={lid}] is [[link]] "
                         f"#{self.link_table[lid] + 1})")
            elif isinstance(lid, int) and not isinstance(lid, bool) and lid <= 0:
                self.err(f"{where}.id: moving links are numbered from 1 (0 is the frame), got {lid}")
            elif not valid_id:
                self.integer(t, "id", where)
            if not valid_id or lid in by_id:
                self.ids_unknown = True
                lid = None
            pts = self.points(t.get("points"), f"{where}.points", lid)
            bodies: tuple[Body, ...] = ()
            if "body" in t:
                bodies = self.bodies(t, where, pts, g)
                if bodies:
                    m_total, S, I_total = combine(bodies)
                    com = t.get("com", f"S{lid if lid is not None else n + 1}")
                    if not isinstance(com, str) or com in pts:
                        self.err(f"{where}.com: with bodies, com names the new point of their combined centre "
                                 f"of mass; got {com!r}" + (", already a point of the link" if com in pts else ""))
                    elif lid is not None:
                        pts[com] = S
                        by_id[lid] = Link(lid, self.string(t, "name", where, default=f"link {lid}"),
                                          MappingProxyType(pts), m_total, I_total, com, bodies)
                continue
            if "mass" in t and "weight" in t:
                self.err(f"{where}: give mass or weight, not both")
            if "weight" in t:
                w = self.number(t, "weight", where, minimum=0.0)
                mass = None if (w is None or not g) else w / g
                if w is not None and g == 0:     # (a missing or invalid g is reported already)
                    self.err(f"{where}.weight: a weight needs mechanism.g > 0 to give a mass")
                elif mass is not None and not mass <= MAX_VALUE:
                    self.err(f"{where}.weight: {w:g} N / g = {w:g} / {g:g} m/s^2 gives a mass of {mass:g} kg, "
                             f"out of range (<= {MAX_VALUE:g} kg): is mechanism.g right?")
                    mass = None
            else:
                mass = self.number(t, "mass", where, default=0.0, minimum=0.0)
            I_S = self.number(t, "I_S", where, default=0.0, minimum=0.0)
            com = self.string(t, "com", where, default=None)
            if com is not None and pts and com not in pts:
                self.err(f"{where}.com: unknown point {com!r}{_suggest(com, pts)}. Valid names: {sorted(pts)}")
            if mass and com is None:
                self.err(f"{where}.com: missing (a link with mass needs its centre-of-mass point)")
            span = _span(pts.values()) if pts else None
            if span == 0 and len(pts) >= 2:
                self.coincident[lid if lid is not None else -n - 1] = where     # refused unless in a P pair
            elif span is not None and 0 < span < MIN_LENGTH:
                self.err(f"{where}.points: the link spans only {span:.3g} m: below {MIN_LENGTH:g} m the squares of "
                         f"its lengths underflow (accelerations and forces turn into 0 or NaN); is the unit right?")
            if lid is not None:
                by_id[lid] = Link(lid, self.string(t, "name", where, default=f"link {lid}"),
                                  MappingProxyType(pts), mass or 0.0, I_S or 0.0, com)
        ids = sorted(by_id)
        if ids != list(range(1, len(ids) + 1)) or self.ids_unknown:
            if not self.ids_unknown:        # a table without a valid id is the cause of any gap
                self.err(f"link: ids must be 1..n without gaps, got {ids}")
            self.ids_unknown = True
            return [frame]
        return [frame] + [by_id[i] for i in ids]

    def bodies(self, t: Mapping, where: str, pts: dict[str, Vec], g: float | None) -> tuple[Body, ...]:
        """[[link.body]]: each with mass (or weight), com (a point of the link or [x, y]) and
        I_S about its own centre (default 0, a point mass); () after recording a problem."""
        raw = t["body"]
        for key in ("mass", "weight", "I_S"):
            if key in t:
                self.err(f"{where}.{key}: a link given by bodies takes its {key} from them; remove it")
        if not (isinstance(raw, list) and raw and all(isinstance(b, dict) for b in raw)):
            self.err(f"{where}.body: expected an array of tables [[link.body]] (mass, com, I_S)")
            return ()
        n0, out = len(self.problems), []
        for n, b in enumerate(raw):
            w = f"{where}.body[{n}]"
            self.unknown_keys(b, {"name", "mass", "weight", "com", "I_S"}, w)
            if ("mass" in b) == ("weight" in b):
                self.err(f"{w}: give exactly one of mass or weight")
                continue
            mass = self.number(b, "mass", w, minimum=0.0) if "mass" in b else None
            if "weight" in b:
                wt = self.number(b, "weight", w, minimum=0.0)
                if wt is not None and not g:
                    self.err(f"{w}.weight: a weight needs mechanism.g > 0 to give a mass")
                mass = None if wt is None or not g else wt / g
            raw_com = b.get("com")
            if isinstance(raw_com, str):
                com = pts.get(raw_com)
                if com is None:
                    self.err(f"{w}.com: unknown point {raw_com!r}{_suggest(raw_com, pts)}. Valid names: {sorted(pts)}")
            else:
                com = self.vec(raw_com, f"{w}.com")
            I_S = self.number(b, "I_S", w, default=0.0, minimum=0.0)
            if None not in (mass, com, I_S):
                out.append(Body(self.string(b, "name", w, default=f"body {n + 1}"), mass, com, I_S))
        return tuple(out) if len(self.problems) == n0 else ()

    def link_ok(self, links: list[Link], lid: Any, where: str, *, first: int = 0) -> bool:
        """Is `lid` the id of a link (>= `first`)? Unknown ids are not reported while some
        [[link]] table has no valid id: that table's problem is the cause."""
        if not isinstance(lid, int) or isinstance(lid, bool) or not first <= lid < len(links):
            if not self.ids_unknown:
                moving = " moving" if first else ""
                self.err(f"{where}: unknown{moving} link {lid!r}. Valid links: {list(range(first, len(links)))}")
            return False
        return True

    def point_ok(self, links: list[Link], lid: int, name: Any, where: str, why: str = "") -> bool:
        if not isinstance(name, str) or name not in links[lid].points:
            if (lid, None) not in self.points_unread and (lid, name) not in self.points_unread:
                self.err(f"{where}: link {lid} has no point {name!r}{_suggest(name, links[lid].points)}{why}. "
                         f"Valid names: {sorted(links[lid].points)}")
            return False
        return True

    def pairs(self, links: list[Link]) -> list[Pair]:
        out = []
        for n, t in enumerate(self.table_list("pair")):
            where = f"pair[{n}]"
            kind = self.string(t, "kind", where, choices=("R", "P"))
            self.unknown_keys(t, {"kind", "links", "point", "radius"} | (
                {"guide", "direction", "slider_axis"} if kind == "P" else set()), where)
            lk = t.get("links")
            if not (isinstance(lk, list) and len(lk) == 2):
                self.err(f"{where}.links: expected two link ids [i, j], got {lk!r}")
                continue
            if not all(self.link_ok(links, x, f"{where}.links") for x in lk):
                continue
            if lk[0] == lk[1]:
                self.err(f"{where}.links: a pair joins two different links, got {lk}")
                continue
            radius = self.number(t, "radius", where, default=None, positive=True)
            if kind == "R":
                pt = t.get("point")
                if all(self.point_ok(links, x, pt, f"{where}.point") for x in lk):
                    out.append(Pair(len(out), "R", tuple(lk), pt, radius=radius))
            elif kind == "P":
                pt, gd = t.get("point"), t.get("guide")
                pts = lambda k: links[k].points
                if pt not in pts(lk[1]) and gd not in pts(lk[0]) and pt in pts(lk[0]) and gd in pts(lk[1]):
                    self.err(f"{where}.links: a prismatic pair lists [guide link, slider link], and {lk} reads "
                             f"reversed: point {pt!r} is on link {lk[0]} and guide {gd!r} on link {lk[1]}; "
                             f"write links = [{lk[1]}, {lk[0]}]")
                    continue
                order = " (links = [guide link, slider link]: the {} is on link {})"
                ok = self.point_ok(links, lk[1], pt, f"{where}.point", order.format("point", lk[1]))
                ok &= self.point_ok(links, lk[0], gd, f"{where}.guide", order.format("guide point", lk[0]))
                d = self.vec(t.get("direction"), f"{where}.direction", unit=True)
                axis = self.vec(t["slider_axis"], f"{where}.slider_axis", unit=True) if "slider_axis" in t else None
                if ok and d is not None and ("slider_axis" not in t or axis is not None):
                    if axis is not None:
                        self.slider_axes.add(len(out))
                        links[lk[1]] = _turned_slider(links[lk[1]], axis)
                    out.append(Pair(len(out), "P", tuple(lk), pt, gd, d, radius))
        seen: dict[frozenset, int] = {}
        for p in out:
            key = frozenset(p.links)
            if key in seen:
                self.err(f"pair[{p.index}]: links {sorted(key)} are already joined by pair[{seen[key]}]")
            seen[key] = p.index
        in_p = {k for p in out if p.kind == "P" for k in p.links}
        for lid, where in self.coincident.items():
            if lid not in in_p:     # a guide or a slider takes its direction from its pair
                self.err(f"{where}.points: all points coincide (zero-length link)")
        sliders = [p.links[1] for p in out if p.kind == "P"]
        for n in self.slider_axes:
            if sliders.count(out[n].links[1]) > 1:
                self.err(f"pair[{n}].slider_axis: link {out[n].links[1]} slides in more than one prismatic pair; "
                         f"give its points in the frame of its guides instead")
        # the CSV columns of a point (x_P, vx_P, ...) must not be those of a prismatic pair (x_i_j)
        for p in out:
            name = f"{p.links[0]}_{p.links[1]}"
            for link in links if p.kind == "P" else ():
                if name in link.points:
                    self.err(f"{'frame' if link.id == 0 else f'link[id={link.id}].points'}.{name}: the point's "
                             f"table column x_{name} would be that of prismatic pair {p.label} (x_{name}, the "
                             f"line of its normal force): rename the point")
        # a point name on two links must be the revolute pair that joins them (or a chain of
        # revolute pairs at that point: several links on one pin)
        owners: dict[str, list[int]] = {}
        for link in links:
            for name in link.points:
                owners.setdefault(name, []).append(link.id)
        pins: dict[str, list[tuple[int, int]]] = {}
        for p in out:
            if p.kind == "R":
                pins.setdefault(p.point, []).append(p.links)
        for name, ids in owners.items():
            if len(ids) > 1:
                comp = _components(pins.get(name, []))
                for a, b in zip(ids, ids[1:]):
                    if comp.get(a, -a - 1) != comp.get(b, -b - 1):
                        self.err(f"point {name!r} is on links {a} and {b}, which share no revolute pair "
                                 f"at {name!r}: rename one of them")
        return out

    def drive(self, links: list[Link], pairs: list[Pair]) -> Drive | None:
        t = self.data.get("drive")
        if not isinstance(t, dict):
            self.err("drive: missing table [drive]")
            return None
        w = "drive"
        self.unknown_keys(t, {"link", "pivot", "point", "reference", "sense", "rpm", "omega", "omega_table",
                              "eps", "kind", "gear", "design_deg"}, w)
        link = t.get("link", 1)
        if link != 1:
            self.err(f"drive.link: the crank must be link 1, got {link!r}")
        pivot, point = t.get("pivot"), t.get("point")
        if len(links) > 1:
            if self.point_ok(links, 1, pivot, "drive.pivot") & self.point_ok(links, 1, point, "drive.point") \
                    and links[1].points[pivot] == links[1].points[point]:
                self.err(f"drive.point: {point!r} coincides with the pivot {pivot!r} "
                         f"(zero crank length: the crank angle has no direction)")
            if not any(p.kind == "R" and set(p.links) == {0, 1} and p.point == pivot for p in pairs):
                self.err(f"drive.pivot: the crank needs a revolute pair with the frame at {pivot!r}")
        ref = self.vec(t.get("reference"), "drive.reference", unit=True)
        sense = self.string(t, "sense", w, choices=("ccw", "cw"))
        law = None
        if sum(k in t for k in ("rpm", "omega", "omega_table")) != 1:
            self.err("drive: give exactly one of rpm, omega (a number, or an expression of phi) or omega_table")
            omega = None
        elif "omega_table" in t:
            law = self.speed_table(t["omega_table"], "drive.omega_table")
        elif isinstance(t.get("omega"), str) and _mentions_phi(t["omega"]):
            law = self.speed_expression(t["omega"], "drive.omega")
        elif "rpm" in t:
            rpm = self.number(t, "rpm", w, minimum=0.0)
            omega = None if rpm is None else rpm * math.pi / 30
        else:
            omega = self.number(t, "omega", w, minimum=0.0)
        if law is not None and "eps" in t:
            self.err("drive.eps: a law of motion gives eps = omega d omega / d phi itself; remove eps")
        eps = self.number(t, "eps", w, default=0.0)
        if "omega_table" in t or isinstance(t.get("omega"), str) and _mentions_phi(t["omega"]):
            omega, eps = (None, None) if law is None else self.law_scales(law)
        design = self.number(t, "design_deg", w, default=30.0)
        kind = self.string(t, "kind", w, choices=("engine", "machine"), default="engine")
        gear = None
        if kind == "machine":
            gear = self.gear(t.get("gear"), max((_span(k.points.values()) for k in links[1:]), default=0.0))
        elif "gear" in t:
            self.err("drive.gear: only a working machine (drive.kind = 'machine') has a gear mesh")
        if None in (ref, sense, omega, eps, design) or (kind == "machine" and gear is None):
            return None
        return Drive(1, pivot, point, ref, 1 if sense == "ccw" else -1, omega, eps, kind, gear, design, law,
                     self.source)

    def speed_table(self, t: Any, where: str) -> SpeedLaw | None:
        """[drive.omega_table]: phi_deg and omega (rad/s) or rpm over one revolution."""
        if not isinstance(t, dict):
            self.err(f"{where}: expected a table {{ phi_deg = [...], omega = [...] }} (or rpm = [...])")
            return None
        self.unknown_keys(t, {"phi_deg", "omega", "rpm"}, where)
        if ("omega" in t) == ("rpm" in t):
            self.err(f"{where}: give exactly one of omega (rad/s) or rpm")
            return None
        xs = self.series(t.get("phi_deg"), f"{where}.phi_deg")
        key = "omega" if "omega" in t else "rpm"
        vs = self.series(t.get(key), f"{where}.{key}")
        if xs is None or vs is None:
            return None
        n = len(self.problems)
        if len(vs) != len(xs):
            self.err(f"{where}.{key}: {len(vs)} values for {len(xs)} angles")
        if len(xs) < 3:
            self.err(f"{where}.phi_deg: a periodic spline needs at least 3 angles, got {len(xs)}")
        if any(b <= a for a, b in zip(xs, xs[1:])):
            self.err(f"{where}.phi_deg: the angles must increase strictly")
        elif not xs[-1] - xs[0] <= 360:
            self.err(f"{where}.phi_deg: the angles must lie within one revolution (last - first <= 360)")
        elif xs[-1] - xs[0] == 360 and len(vs) == len(xs) and vs[0] != vs[-1]:
            self.err(f"{where}.{key}: the law is periodic, but its values at {xs[0]:g} and {xs[-1]:g} deg "
                     f"({vs[0]:g}, {vs[-1]:g}) differ")
        if any(v < 0 for v in vs):
            self.err(f"{where}.{key}: the crank turns in the drive's sense: speeds must be >= 0")
        if len(self.problems) > n:
            return None
        scale = 1.0 if key == "omega" else math.pi / 30
        return SpeedLaw(xs, tuple(v * scale for v in vs))

    def speed_expression(self, text: str, where: str) -> SpeedLaw | None:
        """drive.omega as an expression of phi (rad), periodic over a revolution."""
        law = SpeedLaw(expression=text, parameters=tuple(self.values.items()))
        try:
            law(np.zeros(1))
        except ValueError as exc:
            self.err(f'{where}: "{text:.{MAX_SHOWN}}": {exc}')
            return None
        return law

    def law_scales(self, law: SpeedLaw) -> tuple[float | None, float | None]:
        """The largest omega and |eps| of `law` over a revolution, after checking that omega is
        finite, >= 0 and periodic; (None, None) after recording a problem."""
        where = "drive.omega_table" if law.expression is None else "drive.omega"
        phi = np.linspace(0.0, 2 * np.pi, 721)
        w, dw = law(phi)
        if not (np.isfinite(w).all() and np.isfinite(dw).all()):
            at = np.degrees(phi[~(np.isfinite(w) & np.isfinite(dw))])
            self.err(f"{where}: omega(phi) is not finite (or not real) over the whole revolution: so at phi = "
                     f"{at[0]:.4g} deg" + (f" ({len(at)} of 721 angles checked, up to {at[-1]:.4g} deg)"
                                           if len(at) > 1 else ""))
        elif (w < 0).any():
            self.err(f"{where}: omega(phi) must be >= 0 (in the drive's sense); it is "
                     f"{w.min():.4g} rad/s at phi = {np.degrees(phi[np.argmin(w)]):.4g} deg")
        elif np.abs(w.max()) > MAX_VALUE:
            self.err(f"{where}: omega(phi) reaches {w.max():.4g} rad/s (at most {MAX_VALUE:g})")
        elif law.expression is not None and not (
                abs(w[-1] - w[0]) <= 1e-9 * max(abs(w).max(), 1.0) and abs(dw[-1] - dw[0]) <= 1e-9 * max(abs(dw).max(), 1.0)):
            self.err(f"{where}: omega(phi) must be periodic over a revolution (value and slope at 0 and 2 pi): "
                     f"omega = {w[0]:.6g}, {w[-1]:.6g}; d omega/d phi = {dw[0]:.6g}, {dw[-1]:.6g}")
        else:
            return float(w.max()), float(np.abs(w * dw).max())
        return None, None

    def gear(self, t: Any, size: float) -> Gear | None:
        """[drive.gear]; `size`: the largest link, m (the wheel must not be vanishingly small beside it)."""
        w = "drive.gear"
        if not isinstance(t, dict):
            self.err(f"{w}: a working machine needs the table [drive.gear] (module, z_pinion, z_wheel, ...)")
            return None
        self.unknown_keys(t, {"module", "z_pinion", "z_wheel", "correction", "alpha_w_deg", "y",
                              "centre_direction"}, w)
        module = self.number(t, "module", w, positive=True)
        z1, z2 = self.integer(t, "z_pinion", w), self.integer(t, "z_wheel", w)
        for key, z in (("z_pinion", z1), ("z_wheel", z2)):
            if z is not None and z < 5:
                self.err(f"{w}.{key}: a gear needs at least 5 teeth, got {z}")
        corr = self.string(t, "correction", w, choices=("none", "equal", "unequal"), default="none")
        if corr == "unequal" and "alpha_w_deg" not in t:
            self.err(f"{w}.alpha_w_deg: required for an unequal correction (25-26 deg typically)")
        alpha = self.number(t, "alpha_w_deg", w, default=20.0, positive=True)
        if alpha is not None and alpha >= 45:
            self.err(f"{w}.alpha_w_deg: pressure angle must be below 45 deg, got {alpha}")
        y = self.number(t, "y", w, default=0.0)
        cd = self.vec(t.get("centre_direction"), f"{w}.centre_direction", unit=True)
        if None in (module, z1, z2, corr, alpha, y, cd):
            return None
        gear = Gear(module, z1, z2, corr, alpha, y, cd)
        if gear.r_w <= 0:
            self.err(f"{w}.y: the wheel's pitch radius r_w = r (1 + 2y/(z1 + z2)) = {gear.r_w:g} m must be > 0")
            return None
        if gear.r_b < MIN_GEAR * size:
            self.err(f"{w}.module: the wheel's base radius r_b = {gear.r_b:.3g} m is below {MIN_GEAR:g} of the "
                     f"largest link ({size:.3g} m): the balancing force M_bal / r_b would be out of range; "
                     f"is the module in metres (0.010 for 10 mm)?")
            return None
        return gear

    def groups(self, links: list[Link]) -> dict[frozenset, int]:
        out = {}
        for n, t in enumerate(self.table_list("group")):
            where = f"group[{n}]"
            self.unknown_keys(t, {"links", "branch"}, where)
            lk = t.get("links")
            if not (isinstance(lk, list) and len(lk) == 2
                    and all(self.link_ok(links, x, f"{where}.links") for x in lk)):
                if not isinstance(lk, list) or len(lk) != 2:
                    self.err(f"{where}.links: expected two link ids, got {lk!r}")
                continue
            b = t.get("branch")
            if not isinstance(b, int) or isinstance(b, bool) or b not in (1, -1):
                self.err(f"{where}.branch: expected +1 or -1, got {b!r}"
                         + (" (an integer: write it without a decimal point)" if isinstance(b, float) else ""))
                continue
            key = frozenset(lk)
            if key in out and out[key] != b:
                first = self.group_tables[key][0]
                self.err(f"{where}.branch: group {sorted(key)} is already given branch = {out[key]:+d} by "
                         f"group[{first}]; this entry says {b:+d}: keep one")
                continue
            out[key] = b
            self.group_tables.setdefault(key, (n, tuple(lk)))
        return out

    def loads(self, links: list[Link], pairs: list[Pair]) -> list[Load]:
        out = []
        for n, t in enumerate(self.table_list("load")):
            where = f"load[{n}]"
            kind = self.string(t, "kind", where, choices=("force", "moment", "damper"), default="force")
            name = self.string(t, "name", where, default=f"load {n}")
            if kind == "damper":
                self.unknown_keys(t, {"name", "kind", "pair", "c"}, where)
                damper = self.damper(t, where, name, links, pairs)
                if damper is not None:
                    out.append(damper)
                continue
            self.unknown_keys(t, {"name", "kind", "link", "point", "direction", "value", "table"}
                              | ({"characteristic"} if kind == "moment" else set()), where)
            lid = t.get("link")
            if not self.link_ok(links, lid, f"{where}.link"):
                continue
            if lid == 0:
                self.err(f"{where}.link: loads on the frame do not enter the analysis")
                continue
            point, direction = None, None
            if kind == "force":
                if not self.point_ok(links, lid, t.get("point"), f"{where}.point"):
                    continue
                point = t["point"]
                raw = t.get("direction")
                direction = ("against_velocity" if raw == "against_velocity"
                             else self.vec(raw, f"{where}.direction", unit=True))
            else:
                raw = t.get("direction")
                if raw not in (None, "against_omega"):
                    self.err(f"{where}.direction: a moment takes no direction or 'against_omega', got {raw!r}")
                direction = raw
            if sum(k in t for k in ("value", "table", "characteristic")) != 1:
                self.err(f"{where}: give exactly one of value or table"
                         + (" or characteristic" if kind == "moment" else ""))
                continue
            value = self.number(t, "value", where) if "value" in t else None
            table = self.table(t["table"], f"{where}.table") if "table" in t else None
            if "characteristic" in t:
                if direction is not None:
                    self.err(f"{where}.direction: a characteristic M(omega) gives its own sign")
                    continue
                characteristic = self.characteristic(t["characteristic"], f"{where}.characteristic")
                if characteristic is not None:
                    out.append(Load(name, kind, lid, None, None, None, None, characteristic))
                continue
            if table is not None and table.argument == "travel":
                if kind == "moment":
                    self.err(f"{where}.table.travel: a moment acts on a link, not at a point, so it has no "
                             f"travel to follow; use phi_deg (the crank angle), or make it a force at a point")
                    continue
                if table.axis is None and direction == "against_velocity":
                    self.err(f"{where}.table.axis: missing: the travel is measured along axis, and a force "
                             f"directed 'against_velocity' has no fixed direction to take it from (give the "
                             f"world direction of the stroke, e.g. axis = [0.0, 1.0])")
                    continue
            if kind == "force" and direction is None:
                continue
            if value is not None or table is not None:
                out.append(Load(name, kind, lid, point, direction, value, table))
        return out

    def characteristic(self, t: Any, where: str) -> Characteristic | None:
        """A motor's M(omega): { omega = [...], M = [...] } or an expression of omega."""
        if isinstance(t, str):
            c = Characteristic(expression=t, parameters=tuple(self.values.items()))
            try:
                value = c(np.array([0.0, 1.0]))
            except ValueError as exc:
                self.err(f'{where}: "{t:.{MAX_SHOWN}}": {exc}')
                return None
            if not np.isfinite(value).all():
                self.err(f'{where}: "{t:.{MAX_SHOWN}}" is not finite at omega = 0 or 1 rad/s')
                return None
            return c
        if not isinstance(t, dict):
            self.err(f"{where}: expected {{ omega = [...], M = [...] }} (rad/s, N m) or an expression of omega")
            return None
        self.unknown_keys(t, {"omega", "M"}, where)
        ws, ms = self.series(t.get("omega"), f"{where}.omega"), self.series(t.get("M"), f"{where}.M")
        if ws is None or ms is None:
            return None
        if len(ws) != len(ms):
            self.err(f"{where}.M: {len(ms)} values for {len(ws)} speeds")
        elif any(b <= a for a, b in zip(ws, ws[1:])):
            self.err(f"{where}.omega: the speeds must increase strictly")
        else:
            return Characteristic(ws, ms)
        return None

    def damper(self, t: Mapping, where: str, name: str, links: list[Link], pairs: list[Pair]) -> Load | None:
        """A viscous damper on the pair `pair` = [i, j]: coefficient c >= 0."""
        lk = t.get("pair")
        c = self.number(t, "c", where, minimum=0.0)
        if not (isinstance(lk, list) and len(lk) == 2 and all(self.link_ok(links, x, f"{where}.pair") for x in lk)):
            if not isinstance(lk, list) or len(lk) != 2:
                self.err(f"{where}.pair: expected the two link ids [i, j] of a pair, got {lk!r}")
            return None
        if not any(set(p.links) == set(lk) for p in pairs):
            self.err(f"{where}.pair: no kinematic pair joins links {lk}. Pairs: {[list(p.links) for p in pairs]}")
            return None
        if c is None:
            return None
        return Load(name, "damper", lk[1], None, None, c, None, None, (lk[0], lk[1]))

    def table(self, t: Any, where: str) -> Table | None:
        if not isinstance(t, dict):
            self.err(f"{where}: expected a table")
            return None
        self.unknown_keys(t, {"phi_deg", "travel", "value", "value_return", "scale", "axis", "origin"}, where)
        if ("phi_deg" in t) == ("travel" in t):
            self.err(f"{where}: give exactly one argument, phi_deg or travel")
            return None
        arg = "phi" if "phi_deg" in t else "travel"
        xs = self.series(t.get("phi_deg" if arg == "phi" else "travel"), f"{where}.{'phi_deg' if arg == 'phi' else 'travel'}")
        vs = self.series(t.get("value"), f"{where}.value")
        vr = self.series(t["value_return"], f"{where}.value_return") if "value_return" in t else None
        scale = self.number(t, "scale", where, default=1.0)
        if xs is None or vs is None or scale is None:
            return None
        if any(b <= a for a, b in zip(xs, xs[1:])):
            self.err(f"{where}: the argument must increase strictly")
        for nm, v in (("value", vs), ("value_return", vr)):
            if v is not None and len(v) != len(xs):
                self.err(f"{where}.{nm}: {len(v)} values for {len(xs)} arguments")
        if arg == "phi" and (xs[0] < 0 or xs[-1] > 360):
            self.err(f"{where}.phi_deg: angles must lie in [0, 360]")
        elif arg == "phi" and xs[0] == 0 and xs[-1] == 360 and len(vs) == len(xs) and vs[0] != vs[-1]:
            self.err(f"{where}: a crank-angle diagram is periodic, but its value at 0 deg ({vs[0]:g}) "
                     f"and at 360 deg ({vs[-1]:g}) differ")
        if arg == "travel" and (xs[0] < 0 or xs[-1] > 1):
            self.err(f"{where}.travel: fractions of stroke must lie in [0, 1]")
        if arg == "phi" and ("value_return" in t or "axis" in t or "origin" in t):
            self.err(f"{where}: value_return, axis and origin belong to a travel table")
        axis = self.vec(t["axis"], f"{where}.axis", unit=True) if "axis" in t else None
        origin = self.string(t, "origin", where, choices=("max", "min"), default="max")
        return Table(arg, xs, vs, vr, scale, axis, origin)

    def series(self, x: Any, where: str) -> tuple[float, ...] | None:
        if isinstance(x, list):
            x = [self.scalar(v, f"{where}[{i}]") for i, v in enumerate(x)]
            if None in x:
                return None
        if not (isinstance(x, list) and len(x) >= 2 and all(_finite(v) and abs(v) <= MAX_VALUE for v in x)):
            self.err(f"{where}: expected a list of at least two finite numbers (|value| <= {MAX_VALUE:g})")
            return None
        return tuple(float(v) for v in x)

    def springs(self, links: list[Link]) -> list[Spring]:
        out = []
        for n, t in enumerate(self.table_list("spring")):
            where = f"spring[{n}]"
            self.unknown_keys(t, {"name", "a", "b", "stiffness", "free_length"}, where)
            ends = []
            for e in ("a", "b"):
                end = t.get(e)
                if not isinstance(end, dict):
                    self.err(f"{where}.{e}: expected {{ link = i, point = 'P' }}")
                    continue
                if self.link_ok(links, end.get("link"), f"{where}.{e}.link") and \
                        self.point_ok(links, end["link"], end.get("point"), f"{where}.{e}.point"):
                    ends.append((end["link"], end["point"]))
            if len(ends) == 2 and ends[0][1] == ends[1][1]:
                self.err(f"{where}: both ends are the point {ends[0][1]!r}: the spring has no length or direction")
                ends = []
            k = self.number(t, "stiffness", where, minimum=0.0)
            l0 = self.number(t, "free_length", where, minimum=0.0)
            if len(ends) == 2 and k is not None and l0 is not None:
                out.append(Spring(self.string(t, "name", where, default=f"spring {n}"), ends[0], ends[1], k, l0))
        return out

    def study(self, pairs: list[Pair]) -> Study | None:
        """[study]: vary = { name = [values], ... } (one or two parameters), pair = [i, j], steps."""
        t = self.data.get("study")
        if t is None:
            return None
        if not isinstance(t, dict):
            self.err("study: expected a table")
            return None
        self.unknown_keys(t, {"title", "vary", "pair", "steps"}, "study")
        title = self.string(t, "title", "study", default="parameter study")
        vary, v = [], t.get("vary")
        if not (isinstance(v, dict) and 1 <= len(v) <= 2):
            self.err(f"study.vary: expected a table of one or two parameters and their values, "
                     f"e.g. {{ r = [0.05, 0.08], n_k = [60, 120] }}, got {v!r:.80}")
        else:
            for name, xs in v.items():
                if name not in self.values or name == "g":
                    self.err(f"study.vary.{name}: not a parameter of the model{_suggest(name, self.values)}. "
                             f"Parameters: {sorted(n for n in self.values if n != 'g')}")
                elif not (isinstance(xs, list) and 1 <= len(xs) <= MAX_STUDY_VALUES and all(_finite(x) for x in xs)):
                    self.err(f"study.vary.{name}: expected a list of 1..{MAX_STUDY_VALUES} finite numbers")
                else:
                    vary.append((name, tuple(float(x) for x in xs)))
        pair = t.get("pair")
        if not (isinstance(pair, list) and len(pair) == 2 and all(isinstance(i, int) for i in pair)
                and any(set(p.links) == set(pair) and pair[0] != pair[1] for p in pairs)):
            self.err(f"study.pair: expected [i, j] of a kinematic pair (R(i, j), force of link i on link j), "
                     f"got {pair!r:.60}. Pairs: {[list(p.links) for p in pairs]}")
            return None
        steps = t.get("steps", 36)
        if not (isinstance(steps, int) and not isinstance(steps, bool) and 1 <= steps <= 3600):
            self.err(f"study.steps: expected an integer 1..3600 (crank angles per cycle), got {steps!r}")
            return None
        if not isinstance(v, dict) or len(vary) != len(v):
            return None
        return Study(title, tuple(vary), (pair[0], pair[1]), steps)

    def friction(self) -> Friction | None:
        t = self.data.get("friction")
        if t is None:
            return None
        if not isinstance(t, dict):
            self.err("friction: expected a table")
            return None
        self.unknown_keys(t, {"f", "radius", "method"}, "friction")
        f = self.number(t, "f", "friction", minimum=0.0)
        r = self.number(t, "radius", "friction", default=None, positive=True)
        method = t.get("method", "first")
        if method not in ("first", "reactions"):
            self.err(f"friction.method: expected 'first' or 'reactions', got {method!r}")
        return None if f is None else Friction(f, r, method)

    def published(self, links: list[Link], pairs: list[Pair], drive: Drive | None) -> list[Published]:
        out: list[Published] = []
        first: dict[str, int] = {}
        for n, t in enumerate(self.table_list("published")):
            entry = self.published_entry(t, f"published[{n}]", links, pairs, drive)
            if entry is None:
                continue
            if entry.symbol in first:
                self.err(f"published[{n}].symbol: {entry.symbol!r} is already used by published[{first[entry.symbol]}]")
                continue
            first[entry.symbol] = n
            out.append(entry)
        return out

    def published_entry(self, t: Mapping, where: str, links: list[Link], pairs: list[Pair],
                        drive: Drive | None) -> Published | None:
        quantity = self.string(t, "quantity", where, choices=tuple(PUBLISHED_UNITS))
        needs = {"velocity": {"point", "relative_to"}, "acceleration": {"point", "relative_to"},
                 "omega": {"link"}, "eps": {"link"}, "inertia_force": {"link"}, "inertia_moment": {"link"},
                 "reaction": {"pair"}}.get(quantity, set())
        self.unknown_keys(t, {"symbol", "meaning", "quantity", "value", "unit", "angle", "reduce", "tolerance",
                              "tolerance_deg", "source", "accuracy"} | needs, where)
        n_problems = len(self.problems)
        symbol = self.string(t, "symbol", where)
        source = self.string(t, "source", where)
        meaning = self.string(t, "meaning", where, default="")
        accuracy = self.string(t, "accuracy", where, default="")
        value = self.number(t, "value", where)
        angles = self.published_angles(t.get("angle"), f"{where}.angle")
        reduce = self.string(t, "reduce", where, choices=("min", "max", "angle_of_max"), default=None)
        if isinstance(t.get("angle"), list) and reduce is None and "reduce" not in t:
            self.err(f"{where}.reduce: missing: a list of angles needs reduce = 'min', 'max' or 'angle_of_max'")
        elif reduce is not None and not isinstance(t.get("angle"), list):
            self.err(f"{where}.reduce: only with a list of angles (angle = [...])")
        by_angle = reduce == "angle_of_max"
        tol_key, other = ("tolerance_deg", "tolerance") if by_angle else ("tolerance", "tolerance_deg")
        if other in t:
            self.err(f"{where}.{other}: " + ("the angle of the maximum takes tolerance_deg (deg)" if by_angle
                                             else "only reduce = 'angle_of_max' takes tolerance_deg; "
                                                  "give tolerance (relative, e.g. 0.01 for 1 %)"))
        tolerance = self.number(t, tol_key, where, positive=True)
        unit = "deg" if by_angle else PUBLISHED_UNITS.get(quantity)
        if "unit" in t and unit is not None and t["unit"] != unit:
            self.err(f"{where}.unit: {quantity if not by_angle else 'angle_of_max'} is in {unit!r}, "
                     f"got {t['unit']!r}")
        point = relative_to = link = pair = None
        if "point" in needs:
            point = self.published_point(t, "point", where, links, required=True)
            relative_to = self.published_point(t, "relative_to", where, links, required=False)
        elif "link" in needs:
            link = t.get("link")
            self.link_ok(links, link, f"{where}.link", first=1)
        elif "pair" in needs:
            pair = t.get("pair")
            if not (isinstance(pair, list) and len(pair) == 2
                    and all(isinstance(x, int) and not isinstance(x, bool) for x in pair)):
                self.err(f"{where}.pair: expected two link ids [i, j] (R(i, j), force of i on j), got {pair!r}")
            elif not any(set(p.links) == set(pair) and pair[0] != pair[1] for p in pairs):
                self.err(f"{where}.pair: no kinematic pair joins links {pair!r}. "
                         f"Pairs: {[list(p.links) for p in pairs]}")
            else:
                pair = (pair[0], pair[1])
        if quantity == "balancing_force" and drive is not None and drive.kind != "machine":
            self.err(f"{where}.quantity: a balancing force needs drive.kind = 'machine' (an engine has a moment)")
        if len(self.problems) > n_problems or None in (symbol, source, quantity, value, angles, tolerance):
            return None
        return Published(symbol, quantity, value, unit, angles, reduce, tolerance, source, meaning, accuracy,
                         point, relative_to, link, pair)

    def published_angles(self, x: Any, where: str) -> tuple[float, ...] | None:
        items = [self.scalar(a, f"{where}[{i}]") for i, a in enumerate(x)] if isinstance(x, list) \
            else [self.scalar(x, where)]
        if None in items and x is not None:
            return None
        if x is None or not items or len(items) > MAX_PUBLISHED_ANGLES or \
                not all(_finite(a) and abs(a) <= MAX_VALUE for a in items):
            self.err(f"{where}: " + ("missing (a crank angle in deg, or a list of them)" if x is None else
                                     f"expected a finite number of deg or a list of 1..{MAX_PUBLISHED_ANGLES} "
                                     f"of them, got {x!r}"[:200]))
            return None
        return tuple(float(a) for a in items)

    def published_point(self, t: Mapping, key: str, where: str, links: list[Link], *, required: bool) -> str | None:
        name = t.get(key)
        if name is None and not required:
            return None
        if not isinstance(name, str) or not any(name in link.points for link in links):
            known = sorted({p for link in links for p in link.points})
            self.err(f"{where}.{key}: " + (f"missing (a point name is required). Valid names: {known}" if name is None
                                           else f"unknown point {name!r}. Valid names: {known}"))
            return None
        return name


def _turned_slider(link: Link, axis: Vec) -> Link:
    """The slider `link` with its points turned from the author's frame, in which the guide runs
    along `axis`, into the documented one, whose x axis runs along the guide."""
    turn = complex(*axis).conjugate()
    pts = {n: ((z := complex(*xy) * turn).real, z.imag) for n, xy in link.points.items()}
    return Link(link.id, link.name, MappingProxyType(pts), link.mass, link.I_S, link.com, link.bodies)


def _components(edges: list[tuple[int, int]]) -> dict[int, int]:
    """Connected components of the links joined by `edges`: link -> representative."""
    parent: dict[int, int] = {}

    def root(x: int) -> int:
        parent.setdefault(x, x)
        while parent[x] != x:
            parent[x] = parent[parent[x]]
            x = parent[x]
        return x

    for i, j in edges:
        parent[root(i)] = root(j)
    return {x: root(x) for x in parent}
