"""Exact kinematics over arrays of crank angles (seed 002 sec. 1.2.2, computed instead of drawn).

Groups are solved in the order of attachment. Each group kind has one small elementwise
function (`kinetostat.groups`) that finds the positions in closed form and closes the velocity
and acceleration plans, exactly as the vector equations of the texts read; `kinetostat.program`
strings them into the mechanism's program, run here over all angles at once.

The singular-position guard: near a dead centre or toggle of a group the answer itself is that
sensitive to its inputs, so where a group plan's condition number exceeds COND_CHECK the
accuracy is measured, not inferred from the condition number: the kinematics is solved again
with every input (each point of the linkage, the crank angle) moved by PERTURB_ULPS ulps, and
the change is the error estimate (`Kinematics.error`). Fewer than DIGITS_WARN digits left: a
SingularPositionWarning names the angles and the digits; fewer than DIGITS_MIN: NaN.

May use: program, sizes, triad, planar, errors (model and structure for type hints only).
"""
from __future__ import annotations

import math
import warnings
import zlib
from dataclasses import dataclass, fields, replace
from typing import TYPE_CHECKING, Any, Mapping

import numpy as np

from .errors import AssemblyError, ModelWarning, SingularPositionWarning, singular_message
from .planar import as_xy
from .program import Program, Step, constants, motion_program, run
from .sizes import group_scales, kinematic_size
from .triad import PREDICT, leash_kinds, modes, special_point, track

if TYPE_CHECKING:
    from .model import Mechanism

__all__ = ["Kinematics", "kinematics", "COND_CHECK", "COND_MAX", "DIGITS_WARN", "DIGITS_MIN",
           "kinematic_size", "kinematic_deviation", "group_scales", "solve_checked", "guard",
           "a_priori_error", "relative_change", "digits", "assemble", "AssemblyModes", "assembly_modes", "leash_axes",
           "MODES_CLOSE", "triad_warnings", "special_point_z", "special_index", "special_sides", "tracks"]

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
#: Two assembly modes of a triad closer than this (the largest move of an inner pin, in units of
#: the group's size) at the design position: a ModelWarning.
MODES_CLOSE = 0.05
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
    residual: np.ndarray | None = None   # (N, n_groups) m: the largest miss of a triad's three
                           #   leashes after its Newton (0 for a dyad, closed in closed form);
                           #   None where the route does not give it (the compiled path)

    def __repr__(self) -> str:
        N, L = self.theta.shape
        return f"Kinematics(positions={N}, links={L}, groups={self.cond.shape[1]}, singular={int(self.singular.sum())})"

    @property
    def digits(self) -> np.ndarray:
        """(N,) estimated significant digits left, -log10(error) within [0, 16]."""
        return digits(self.error)

    def take(self, idx: np.ndarray) -> "Kinematics":
        """The same motion at the angles `idx` only."""
        return Kinematics(*(None if getattr(self, f.name) is None else getattr(self, f.name)[idx] for f in fields(self)))

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


@dataclass(frozen=True)
class AssemblyModes:
    """The assembly modes of a triad at the design position (the texts' method of false
    positions, `triad.modes`): the base link's pose in each, the one solved (the mode the
    model's points draw), and how far the nearest other mode is."""
    group: str
    O: tuple[complex, ...]       # base link's local origin per mode, m (world, complex)
    rot: tuple[complex, ...]     # its e^{i theta} per mode
    chosen: int                  # index of the mode solved
    drawn_miss: float            # how far the model's drawing is from the chosen mode (inner pins), m
    separation: float            # nearest other mode: largest move of an inner pin / group size (inf: none)

    def lines(self) -> list[str]:
        """One line per mode, the chosen one marked."""
        return [f"  {self.group} mode {i + 1}: base origin ({round(O.real, 9) + 0.0:.6g}, {round(O.imag, 9) + 0.0:.6g}) m, theta "
                f"{round(math.degrees(math.atan2(r.imag, r.real)), 7) + 0.0:.6g} deg" + ("   <- solved (drawn by the model)" if
                                                                          i == self.chosen else "")
                for i, (O, r) in enumerate(zip(self.O, self.rot))]


def assembly_modes(mech: "Mechanism") -> tuple[AssemblyModes, ...]:
    """Per triad of `mech` (memoised), its assembly modes at the design position (drive.design_deg)."""
    def make() -> tuple[AssemblyModes, ...]:
        triads = [(n, g) for n, g in enumerate(mech.structure.groups) if g.klass == 3]
        if not triads:
            return ()
        phi0 = np.radians([mech.drive.design_deg])
        kin, out = _solve(mech, phi0, mech.points_z), []
        for n, g in triads:
            b, L = g.links[0], group_scales(mech)[n]
            kinds, x, known = _known_joints(mech, n, {**constants(mech), **tracks(mech), "w_in": 1.0, "e_in": 0.0})
            P, c = known(phi0)
            found = modes(kinds, x, tuple(complex(v[0]) for v in P), tuple(complex(v[0]) for v in c), L)
            pins = lambda O, r: np.array([O + xi * r for xi in x])
            solved = pins(kin.origin_z[0, b], kin.rot[0, b])
            apart = [float(np.abs(pins(O, r) - solved).max()) for O, r in found]
            chosen = int(np.argmin(apart))
            others = [float(np.abs(pins(O, r) - pins(*found[chosen])).max()) / L
                      for i, (O, r) in enumerate(found) if i != chosen]
            out.append(AssemblyModes(g.label, tuple(O for O, _ in found), tuple(r for _, r in found), chosen,
                                     float(np.abs(solved - np.array(x)).max()), min(others, default=math.inf)))
        return tuple(out)
    return mech.memo("assembly modes", make)


def special_point_z(mech: "Mechanism", kin: Kinematics, g) -> np.ndarray:
    """(N,) complex, m: Assur's special point S of triad g as the solver takes it, where the two
    leash axes meeting at the best angle cross (a two-pin leash's axis: outer pin -> inner pin;
    a slider's: the guide's normal through its inner pin; a leash on an inner prismatic pair:
    the guide's normal through its outer pin)."""
    return _special(mech, kin, g)[0]


def special_index(mech: "Mechanism", kin: Kinematics, g) -> np.ndarray:
    """(N,) int: per angle the index k (0, 1, 2) of `Triad.sides` whose leash closes triad g about
    S (`triad.special_point`); the solver's order there is sides k+1, k+2, k (`special_sides`)."""
    return _special(mech, kin, g)[1].astype(int)


def special_sides(mech: "Mechanism", kin: Kinematics, g, at: int = 0) -> tuple:
    """Triad g's sides (`Triad.sides`) at angle index `at` in the solver's order there: the two
    leashes whose axes meet in S, then the one whose arm about S closes the group."""
    k = int(special_index(mech, kin.take([at]), g)[0])
    return tuple(g.sides[(k + i) % 3] for i in (1, 2, 0))


def leash_axes(mech: "Mechanism", kin: Kinematics, g) -> list[tuple[np.ndarray, np.ndarray]]:
    """Per leash of triad g (`Triad.sides`' order) a point X of its axis and the axis' unit
    direction u, each (N,) complex (m; 1): a two-pin leash's inner pin, outer -> inner; a
    slider's inner pin, its guide's normal; a leash on an inner prismatic pair's outer pin, its
    guide's normal."""
    pts, out = mech.points_z, []
    for ell, outer, inner, a in g.sides:
        if inner.kind == "P":
            out.append((kin.position_z(ell, _xy(pts[ell][outer.point])),
                        1j * complex(*inner.direction) * kin.rot[:, inner.links[0]]))
            continue
        X = kin.position_z(ell, _xy(pts[ell][inner.point]))
        if outer.kind == "R":
            r = X - kin.position_z(ell, _xy(pts[ell][outer.point]))
            out.append((X, r / np.abs(r)))
        else:
            out.append((X, 1j * complex(*outer.direction) * kin.rot[:, outer.links[0]]))
    return out


def _special(mech: "Mechanism", kin: Kinematics, g) -> tuple[np.ndarray, np.ndarray]:
    """S (complex, m) and k (`triad.special_point`), each (N,)."""
    (X1, u1), (X2, u2), (X3, u3) = leash_axes(mech, kin, g)
    S, _, k = special_point(X1, u1, X2, u2, X3, u3)
    return S, k


def _xy(z: complex) -> tuple[float, float]:
    return z.real, z.imag


def triad_warnings(mech: "Mechanism") -> tuple[str, ...]:
    """The texts of the triads' model warnings (memoised per mechanism; `solve_checked` issues
    them on every analysis, `kinetostat structure --modes` prints them): where a triad's model
    does not draw it assembled at the design position, where another mode is closer than
    MODES_CLOSE there, and where the mode's path does not close over a turn (the two ways round
    meet in different poses)."""
    def make() -> tuple[str, ...]:
        out, scales, labels = [], group_scales(mech), [g.label for g in mech.structure.groups]
        for am in assembly_modes(mech):
            n = labels.index(am.group)
            if am.drawn_miss > 1e-6 * scales[n]:
                out.append(f"group {am.group}: the base link's points do not draw the group assembled at the design "
                           f"position (design_deg = {mech.drive.design_deg:g}; the pins miss the nearest mode by "
                           f"{am.drawn_miss:.3g} m); that mode is solved: give the triad's points in world coordinates "
                           f"at the design position")
            if am.separation < MODES_CLOSE:
                out.append(f"group {am.group}: another assembly mode is within {am.separation:.3g} of the group's size "
                           f"at the design position (kinetostat structure MODEL --modes lists them)")
            tr = tracks(mech)[f"track{n}"]
            if tr.mismatch > PREDICT * scales[n]:
                out.append(f"group {am.group}: the mode followed from the design position does not close over a turn: "
                           f"at phi = {(mech.drive.design_deg + 180.0) % 360:g} deg the paths both ways round differ by "
                           f"{tr.mismatch:.3g} m (each angle is solved on the path within 180 deg of the design angle)")
        return tuple(out)
    return mech.memo("triad warnings", make)


def solve_checked(mech: "Mechanism", phi: np.ndarray,
                  unit_speed: bool = False) -> tuple[Kinematics, np.ndarray, list[Kinematics]]:
    """The kinematics at `phi` (unguarded: nothing NaN yet, `error` not set), the indices of the
    angles where some group's cond exceeds COND_CHECK, and the kinematics at those angles solved
    again on inputs moved by PERTURB_ULPS ulps (one per sign pattern); the triads' model warnings
    (`triad_warnings`) issued. Call under np.errstate as `kinematics` does."""
    for text in triad_warnings(mech):
        warnings.warn(ModelWarning(text), stacklevel=4)
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


def _solve(mech: "Mechanism", phi: np.ndarray, locals_: tuple[Mapping[str, complex], ...],
           unit_speed: bool = False) -> Kinematics:
    """The motion program of `mech` run over the angles `phi` with the local points `locals_`."""
    w, e = (1.0, 0.0) if unit_speed else mech.drive.speed(phi)      # the constants, or per angle by the law
    env = dict(mech.memo(("constants", id(locals_)), lambda: constants(mech, locals_)))
    env.update(tracks(mech), phi=phi, w_in=w, e_in=e)
    return assemble(mech, phi, run(motion_program(mech), env))


def tracks(mech: "Mechanism") -> dict[str, Any]:
    """Each triad's track<n> (memoised per mechanism): its base link's path from the design
    position (`triad.track`), the known joints at each step from the motion program's steps
    before the group's (run on that one angle)."""
    def make() -> dict[str, Any]:
        out: dict[str, Any] = {}
        env = dict(constants(mech), w_in=1.0, e_in=0.0)
        phi0 = math.radians(mech.drive.design_deg)
        for n, g in enumerate(mech.structure.groups):
            if g.klass != 3:
                continue
            kinds, x, pins = _known_joints(mech, n, {**env, **out})
            out[f"track{n}"] = track(kinds, pins, phi0, 0j, 1 + 0j, x, group_scales(mech)[n])
        return out
    return mech.memo("triad tracks", make)


def _known_joints(mech: "Mechanism", n: int, env: Mapping[str, Any]) -> tuple[str, tuple, Any]:
    """Triad n's leash kinds, its x as `triad.misses` reads them (constants: from the program's
    steps that derive constants) and pins(phi): the known joints' (P, c) at the angles phi (rad,
    (m,); or one angle, a float: scalars, the cheapest for `triad.track`'s one angle a step)
    from the motion program's steps before the group's, run in `env` (None where an earlier
    group does not close there)."""
    prog = motion_program(mech)
    at = next(i for i, st in enumerate(prog.steps) if st.fn == "iii3_positions" and f"it{n}" in st.out)
    args = prog.steps[at].args
    wanted = tuple(Step("same", (a,), (f"pin{n}_{i}",)) for i, a in enumerate(args[5:14]))
    consts = tuple(st for st in prog.steps[:at] if all(o.startswith("c_") for o in st.out))
    got = run(Program(consts + wanted[:3], (), tuple(st.out[0] for st in wanted[:3])), dict(env))
    x = tuple(complex(got[f"pin{n}_{i}"]) for i in range(3))
    head = Program(prog.steps[:at] + wanted[3:], ("phi",), tuple(st.out[0] for st in wanted[3:]))

    def pins(phi):
        try:
            got = run(head, {**env, "phi": phi})
        except AssemblyError:
            return None
        vals = [got[f"pin{n}_{i}"] for i in range(3, 9)]
        if np.ndim(phi):
            vals = [np.broadcast_to(v, np.shape(phi)) for v in vals]
        return tuple(vals[:3]), tuple(vals[3:])
    return leash_kinds(args[2:5]), x, pins


def assemble(mech: "Mechanism", phi, env: Mapping[str, Any], xp: Any = np) -> Kinematics:
    """The Kinematics (unguarded) from a run of the motion program: the per-link names of the
    environment stacked into (N, L) arrays (the frame's column at rest)."""
    N, L, G = phi.shape[-1], mech.n_links, len(mech.structure.groups)
    lead = phi.shape[:-1]

    def stack(stem: str, count: int, rest, dtype, start: int = 1):
        if xp is np:          # columns written in place: the cheapest at a few hundred angles
            out = np.empty(lead + (N, count), dtype)
            for k in range(count):
                out[..., k] = env.get(f"{stem}{k}", rest) if k >= start else rest
            return out
        return xp.stack([xp.broadcast_to(xp.asarray(env.get(f"{stem}{k}", rest) if k >= start else rest, dtype=dtype),
                                         lead + (N,)) for k in range(count)], axis=-1)

    f, c = xp.float64, xp.complex128
    return Kinematics(phi, stack("th", L, 0.0, f), stack("rot", L, 1.0, c), stack("O", L, 0.0, c),
                      stack("V", L, 0.0, c), stack("A", L, 0.0, c), stack("w", L, 0.0, f), stack("e", L, 0.0, f),
                      stack("vs", len(mech.pairs), 0.0, f, 0), stack("as", len(mech.pairs), 0.0, f, 0),
                      stack("cond", G, 0.0, f, 0), xp.zeros(lead + (N,), dtype=xp.bool), xp.zeros(lead + (N,), dtype=f),
                      stack("res", G, 0.0, f, 0))


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
