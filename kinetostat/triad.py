"""The class-III group III3 (a triad; Artobolevsky's course, not among the seeds): a ternary base
link with the inner joints X1, X2, X3 and three leashes to known joints. Written with the
primitives of `groups`, in the same elementwise style:

- a leash's axis u (unit) and its miss f, by the kind of its pairs (`LEASH_KINDS`): "R" a
  two-pin leash A-X (u along A -> X, f = |AX| - l); "P" a slider, the inner pin X running on a
  line carried by the known link (the outer pair prismatic, its guide on either link; u the
  line's normal, f = (X - K) . u); "L" a leash on an inner prismatic pair (its guide on either
  link): it turns with the base, so a line carried by the base runs through its outer pin A (u
  the line's normal through A, f = (K - A) . u, K the line's point; the same `leash_slider`
  with the roles of the pin and the line's point swapped). The reaction of a prismatic pair
  is normal to its guide: each leash's unknown is its reaction's part along its axis;
- Assur's special point S, per angle where the two leash axes meeting at the best angle cross
  (any two may define it), taken as a point of the base: every linear solve of the group (a
  Newton step of the positions, the velocity and acceleration plans, the reactions) is
  x . u_i = r_i for those two, a vector x at S (a 2x2 solve), and one division by h, the arm of
  the third leash's axis about S. h = 0 (three axes through one point) is the group's singular
  position;
- the positions by Newton with continuation from the design position round the cycle, one
  angle per step with step control (`track`, once per mechanism: the mode's path, ending at a
  fold where the crank cannot pass), then at the angles asked all at once from the track
  (`iii3_positions`; numpy only: it reads the whole angle axis, so the compiled path and the
  Array API path refuse triads by name), each checked to stay on the track's path. The
  continuation's one angle a step, and up to FEW_ANGLES angles asked, are solved on Python
  scalars: the same `newton_step` bound to `_Scalars` (numpy's cost per call avoided).

May use: the standard library, numpy, groups.
"""
from __future__ import annotations

import cmath
import types
from dataclasses import dataclass
from functools import cached_property

import numpy as np
import numpy as xp

from . import groups
from .groups import cis, cross, dot, magnitude, over, solve2

__all__ = ["LEASH_KINDS", "leash_kinds", "leash_rr", "leash_slider", "special_point", "special_solve", "third_arm", "iii3_newton", "iii3_velocity",
           "iii3_acceleration", "iii3_condition", "rr_leash_motion", "slider_leash_motion",
           "rr_tangential", "line_tangential", "iii3_polygon", "iii3_positions", "track", "Track", "pose_distance", "jacobian_det", "misses", "modes",
           "MODE_SAMPLES", "FEW_ANGLES", "MAX_ITER", "STATION", "STEP_MIN", "EASY", "PREDICT", "ENDS", "MOVE", "CLOSURE_TOL", "EQUATIONS"]

#: The continuation's longest step along the crank's path (rad).
STATION = np.radians(3.0)
#: Its shortest: where a step would have to be shorter, the group's path cannot be followed on
#: (a fold: the crank cannot pass the group's dead position) and the track ends there.
STEP_MIN = 1e-7
#: A step is accepted where Newton closes in at most EASY steps, the closed pose is within
#: PREDICT L of the one extrapolated from the last two (inner pins, L the group's size) and no
#: inner pin moved more than MOVE L; else it is halved. An angle asked later, closed from the
#: track's pose interpolated for it, must land within PREDICT L of it (else: off the path).
EASY = 6
PREDICT = 1e-3
#: An angle this close to an end of the path is on it (rad): the continuation stops within
#: 1e-15 of its limit (relative), and its stations' sums round.
ENDS = 1e-13
MOVE = 0.05
#: Newton steps per solve at most.
MAX_ITER = 40
#: The largest miss of a leash accepted as closed, in rounding units of the group's size.
CLOSURE_TOL = 1e3
#: Up to this many angles asked at once, `iii3_positions` closes them one by one on Python
#: scalars (measured: at 1 to 4 angles 3 to 10 times cheaper than on arrays; at 16 dearer).
FEW_ANGLES = 8
#: Trial angles of the base per turn in the search for the modes.
MODE_SAMPLES = 3600
_EPS = np.finfo(float).eps
#: The kinds of leash by their code 0, 1, 2 (a program passes the code, a float): "R" two-pin,
#: "P" a slider on a line of the known link, "L" a line of the base through the outer pin.
LEASH_KINDS = "RPL"


def leash_kinds(codes) -> str:
    """The leashes' kinds ("R", "P", "L") from their codes (0., 1., 2.)."""
    return "".join(LEASH_KINDS[int(c)] for c in codes)


# -- elementwise equations (bound and rebound like `groups`)
def leash_rr(X, A, l):
    """A two-pin leash A-X of length l: its axis u (A -> X) and the miss |AX| - l."""
    r = magnitude(X - A)
    return over(X - A, r), r - l


def leash_slider(X, K, n):
    """A slider whose pin X runs on the guide line through K with unit normal n: axis n, miss (X - K) . n."""
    return n, dot(X - K, n)


def _pick(k, a1, a2, a3):
    """Leash values in the order (first, second, third) for the special point S of the leashes
    other than k (0, 1, 2; cyclic: k = 2 takes 1, 2 then 3)."""
    two, zero = k == 2.0, k == 0.0
    return (xp.where(two, a1, xp.where(zero, a2, a3)), xp.where(two, a2, xp.where(zero, a3, a1)),
            xp.where(two, a3, xp.where(zero, a1, a2)))


def special_point(X1, u1, X2, u2, X3, u3):
    """Assur's special point S, per angle where the two leash axes that meet at the best angle
    (the largest |u_i x u_j|) cross, taken as a point of the base; then u_first x u_second, and k
    (0., 1., 2.): the leash whose axis S is not on (its arm about S closes the group)."""
    d12, d23, d31 = cross(u1, u2), cross(u2, u3), cross(u3, u1)
    k = xp.where((abs(d12) >= abs(d23)) & (abs(d12) >= abs(d31)), 2.0, xp.where(abs(d23) >= abs(d31), 0.0, 1.0))
    (Xa, Xb, _), (ua, ub, _) = _pick(k, X1, X2, X3), _pick(k, u1, u2, u3)
    det = cross(ua, ub)
    return Xa + ua * (cross(Xb - Xa, ub) / det), det, k


def special_solve(u1, u2, u3, det, k, h, r1, r2, r3):
    """The group's linear solve at S (`special_point`'s det, k): the vector x (at S) with
    x . u_i = r_i for the two leashes through S, and y = (r_k - x . u_k) / h, the rate of turn
    that closes the third (arm h about S)."""
    (ua, ub, uc), (ra, rb, rc) = _pick(k, u1, u2, u3), _pick(k, r1, r2, r3)
    x = ra * ua + 1j * ua * ((rb - ra * dot(ua, ub)) / det)
    return x, (rc - dot(x, uc)) / h


def third_arm(S, k, X1, X2, X3, u1, u2, u3):
    """The arm about S of the axis of the leash not through it (0: the three axes meet in S)."""
    return cross(_pick(k, X1, X2, X3)[2] - S, _pick(k, u1, u2, u3)[2])


def iii3_newton(O, rot, S, det, k, X1, X2, X3, u1, u2, u3, f1, f2, f3):
    """One Newton step of the base link's pose (origin O, e^{i theta}): move S by dS and turn
    about it by dth so that each leash's miss f_i goes to zero to first order."""
    h = third_arm(S, k, X1, X2, X3, u1, u2, u3)
    dS, dth = special_solve(u1, u2, u3, det, k, h, -f1, -f2, -f3)
    turn = cis(dth)
    return S + dS + (O - S) * turn, rot * turn, magnitude(dS) + abs(dth * magnitude(O - S))


def iii3_velocity(S, X1, X2, X3, u1, u2, u3, det, k, V1, V2, V3):
    """Velocity plan at S: v_S = v_i + v_Si (v_Si _|_ u_i) for the two leashes through S, v_i the
    known velocity of leash i's reference (its outer pin; a slider's guide point under X); then
    (v_X - v_k) . u_k = 0 for the third gives omega. Returns v_S, omega, h (the third's arm)."""
    h = third_arm(S, k, X1, X2, X3, u1, u2, u3)
    vS, w = special_solve(u1, u2, u3, det, k, h, dot(V1, u1), dot(V2, u2), dot(V3, u3))
    return vS, w, h


def iii3_acceleration(S, X1, X2, X3, u1, u2, u3, det, k, h, w, A1, A2, A3, c1, c2, c3):
    """Acceleration plan at S: a_Xi . u_i = a_i . u_i + c_i (c_i: a leash's normal or Coriolis
    term), a_Xi = a_S + (i eps - w^2)(X_i - S). Returns a_S, eps."""
    w2 = w * w
    return special_solve(u1, u2, u3, det, k, h, dot(A1, u1) + c1 + w2 * dot(X1 - S, u1),
                         dot(A2, u2) + c2 + w2 * dot(X2 - S, u2), dot(A3, u3) + c3 + w2 * dot(X3 - S, u3))


def iii3_condition(u1, u2, u3, det, k, h, L):
    """Frobenius condition number of the group's system at S (rows u_i, arm about S / L; two
    arms 0): inf only where the three axes meet in one point (h = 0) or are all parallel."""
    ua, ub, uc = _pick(k, u1, u2, u3)
    c = h / L
    y1, y2 = solve2(ua, ub, det, uc)
    return xp.sqrt((3.0 + c * c) * (2.0 / (det * det) + (y1 * y1 + y2 * y2 + 1.0) / (c * c)))


def rr_leash_motion(X, A, VX, VA, AX, AA):
    """A two-pin leash from the motion of both pins: omega, eps and the normal term -l omega^2 of
    (a_X - a_A) . u (before eps is known, AX may be 0: the term reads only velocities)."""
    AX_ = X - A
    l2 = dot(AX_, AX_)
    w = cross(AX_, VX - VA) / l2
    return w, cross(AX_, AX - AA) / l2, -xp.sqrt(l2) * w * w


def slider_leash_motion(d, VX, VXg, AX, AXg, wg):
    """A slider on a guide (direction d, turning at wg): the sliding velocity and acceleration of
    its pin X relative to the guide's point under it, and the Coriolis term 2 wg v_r of
    (a_X - a_X(guide)) . n."""
    vr = dot(VX - VXg, d)
    return vr, dot(AX - AXg - 2j * wg * vr * d, d), 2.0 * wg * vr


def rr_tangential(u, MX, l):
    """R^tau of a two-pin leash (axis u, length l) on it at its outer pin, from the leash's
    moment MX about its inner pin: -l u x R^tau + MX = 0."""
    return 1j * u * (MX / l)


def line_tangential(u, F):
    """R^tau of a leash on an inner prismatic pair (the guide's normal u), on it at its outer
    pin, from the leash's force balance along the guide (the base pushes only along u):
    R^tau + F - (F . u) u = 0, F the leash's known loads."""
    return dot(F, u) * u - F


def iii3_polygon(S, X1, X2, X3, u1, u2, u3, det, k, T1, T2, T3, P1, P2, P3, m1, m2, m3, F, MS):
    """Reactions in the texts' order. T_i: leash i's R^tau (a two-pin leash's from its moment
    about its inner pin, `rr_tangential`; on an inner prismatic pair from its forces along the
    guide, `line_tangential`), acting at P_i (a slider: T = 0 and the couple m_i); F, MS: the group's known loads (sum of
    forces; moment about S). R^n of the leash off S (k) from the group's moment about S (the
    other two pass through S), then theirs from the group's force polygon. Returns the
    magnitudes along u_1, u_2, u_3."""
    h = third_arm(S, k, X1, X2, X3, u1, u2, u3)
    M = MS + cross(P1 - S, T1) + cross(P2 - S, T2) + cross(P3 - S, T3) + m1 + m2 + m3
    nc = -M / h
    ua, ub, uc = _pick(k, u1, u2, u3)
    na, nb = solve2(ua, ub, det, -(F + T1 + T2 + T3 + nc * uc))
    return (xp.where(k == 0.0, nc, xp.where(k == 2.0, na, nb)), xp.where(k == 1.0, nc, xp.where(k == 0.0, na, nb)),
            xp.where(k == 2.0, nc, xp.where(k == 1.0, na, nb)))


# -- the positions over the angles: Newton with continuation (numpy)
def pose_distance(x: tuple, O1, rot1, O2, rot2):
    """The largest distance between the three inner pins of two poses of the base (m)."""
    return largest(*(O1 - O2 + xi * (rot1 - rot2) for xi in x))


def misses(kinds: str, O, rot, x: tuple, P: tuple, c: tuple):
    """Per leash a world point X_i of its axis (the inner pin; "L": the outer pin), its axis u_i
    and miss f_i at the pose (O, rot); kinds[i] "R" (two-pin leash: x_i the inner pin, P_i the
    outer pin, c_i the length), "P" (slider: x_i the inner pin, P_i a point of the guide line,
    c_i its unit normal) or "L" (x_i a point of the base's line through the outer pin P_i, c_i
    its unit normal in the base's frame)."""
    out = []
    for k, xi, Pi, ci in zip(kinds, x, P, c):
        X = O + xi * rot
        out.append((X, *leash_rr(X, Pi, ci)) if k == "R" else (X, *leash_slider(X, Pi, ci)) if k == "P" else
                   (Pi, *leash_slider(X, Pi, ci * rot)))
    return out


def jacobian_det(leashes, O):
    """The determinant of the group's Jacobian (rows u_i, (X_i - O) x u_i: the misses' rates
    per move of the base's origin O and turn about it) from `misses`' (X_i, u_i, f_i): zero
    where the three axes meet in one point, of one sign along a path that passes no fold."""
    (X1, u1, _), (X2, u2, _), (X3, u3, _) = leashes
    h = [cross(X - O, u) for X, u in ((X1, u1), (X2, u2), (X3, u3))]
    return cross(u2, u3) * h[0] + cross(u3, u1) * h[1] + cross(u1, u2) * h[2]


def largest(f1, f2, f3):
    """The largest of three leashes' |miss| (NaN where any is NaN)."""
    return xp.maximum(xp.maximum(abs(f1), abs(f2)), abs(f3))


def newton_step(kinds: str, O, rot, x: tuple, P: tuple, c: tuple, L: float):
    """One Newton step of the base's pose (`iii3_newton` at the `special_point` of the
    `misses`): the pose moved (rot back on the unit circle), and whether the pose was closed
    already (the step, or each leash's miss, below rounding)."""
    (X1, u1, f1), (X2, u2, f2), (X3, u3, f3) = misses(kinds, O, rot, x, P, c)
    S, det, k = special_point(X1, u1, X2, u2, X3, u3)
    O_new, rot_new, step = iii3_newton(O, rot, S, det, k, X1, X2, X3, u1, u2, u3, f1, f2, f3)
    return O_new, rot_new / abs(rot_new), (step <= 8 * _EPS * L) | (largest(f1, f2, f3) <= 2 * _EPS * L)


def _newton(kinds, O, rot, x, P, c, L):
    """Newton on every angle at once until each step, or each leash's miss, is below rounding
    (MAX_ITER at most; near a singular position the steps stay at rounding times its condition);
    the pose, the steps taken and the largest miss left."""
    its = np.zeros(O.shape, int)
    for _ in range(MAX_ITER):
        O_new, rot_new, done = newton_step(kinds, O, rot, x, P, c, L)
        moving = ~done
        its += moving
        O, rot = np.where(moving, O_new, O), np.where(moving, rot_new, rot)
        if not moving.any():
            break
    return O, rot, its, largest(*(f for _, _, f in misses(kinds, O, rot, x, P, c)))


class _Scalars:
    """The names of `xp` that `newton_step`, `misses`, `largest`, `jacobian_det` and
    `pose_distance` call, on Python scalars (np.maximum's NaN included)."""
    where = staticmethod(lambda c, a, b: a if c else b)
    maximum = staticmethod(lambda a, b: a if a >= b or a != a else b)
    exp = staticmethod(cmath.exp)
    real = staticmethod(lambda z: z.real)
    imag = staticmethod(lambda z: z.imag)
    conj = staticmethod(lambda z: z.conjugate())


def _bind_scalars() -> types.SimpleNamespace:
    """`newton_step`, `misses`, `largest`, `jacobian_det` and `pose_distance` (and what they
    call) rebuilt over a copy of the globals of `groups` and this module in which `xp` is
    `_Scalars`, as `program.bind` rebinds the equations to a namespace."""
    env = {**vars(groups), **globals(), "xp": _Scalars}
    for name, f in list(env.items()):
        if isinstance(f, types.FunctionType) and f.__module__ in (__name__, groups.__name__):
            env[name] = types.FunctionType(f.__code__, env, name, f.__defaults__, f.__closure__)
    names = ("newton_step", "misses", "largest", "jacobian_det", "pose_distance")
    return types.SimpleNamespace(**{n: env[n] for n in names})


def _newton_each(kinds: str, O, rot, x: tuple, P: tuple, c: tuple, L: float):
    """`_newton` angle by angle on Python scalars (`_newton_one`; O, rot, P, c arrays over the
    angles): for a few angles, where numpy's cost per call outweighs the work."""
    x, L = tuple(complex(v) for v in x), float(L)
    rows = [_newton_one(kinds, complex(O[i]), complex(rot[i]), x, tuple(v[i].item() for v in P),
                        tuple(v[i].item() for v in c), L)[:4] for i in np.ndindex(O.shape)]
    return tuple(np.array(col, t).reshape(O.shape) for col, t in zip(zip(*rows), (complex, complex, int, float)))


def _newton_one(kinds: str, O: complex, rot: complex, x: tuple, P: tuple, c: tuple, L: float):
    """`_newton` at one angle on Python scalars (the continuation solves one angle a step, where
    numpy's cost per call would be most of the work): the same `newton_step`s, bound to
    `_Scalars`. A step that divides by zero or leaves the floats fails the solve (NaN), as
    numpy's inf and NaN do. The pose, the steps taken, the largest miss left and the sign of the
    group's Jacobian there (`jacobian_det`)."""
    its = 0
    try:
        for _ in range(MAX_ITER):
            O_new, rot_new, done = _SCALAR.newton_step(kinds, O, rot, x, P, c, L)
            if done:
                break
            its, O, rot = its + 1, O_new, rot_new
        leashes = _SCALAR.misses(kinds, O, rot, x, P, c)
        return O, rot, its, _SCALAR.largest(*(f for _, _, f in leashes)), float(np.sign(_SCALAR.jacobian_det(leashes, O)))
    except (ArithmeticError, ValueError):
        return complex(np.nan, np.nan), complex(np.nan, np.nan), MAX_ITER, np.nan, np.nan


@dataclass(frozen=True)
class Track:
    """A triad's path from the design position: the base link's pose at the continuation's
    stations, u = phi - phi0 (rad) ascending, u[-1] - u[0] <= 2 pi."""
    u: np.ndarray       # (M,) rad
    O: np.ndarray       # (M,) complex, m: the base link's local origin
    rot: np.ndarray     # (M,) complex e^{i theta}
    steps: int          # Newton solves the continuation made (accepted or not)
    mismatch: float     # m: where the path reaches +-pi from both sides, how far the two poses
                        #   are apart (0 to rounding: the path closes over a turn); nan: a fold
    sign: float         # the sign of the group's Jacobian (`jacobian_det`) along the path

    @property
    def full(self) -> bool:
        """Whether the path covers a whole turn (the crank turns fully)."""
        return bool(self.u[-1] - self.u[0] >= 2 * np.pi * (1 - 1e-12))

    def start(self, u):
        """At u (rad, any turn): the pose interpolated on the path, and whether u is on it. An
        angle within ENDS of either end is on it (at that end); on a full track, whose two ends
        are one pose, every angle is (the seam, the half-turn from the design angle, at either)."""
        span = self.u[-1] - self.u[0]
        w = np.mod(u - self.u[0], 2 * np.pi)
        seam = (w > span) & (self.full | (w - span <= ENDS) | (2 * np.pi - w <= ENDS))
        w = np.where(seam, np.where(w - span <= 2 * np.pi - w, span, 0.0), w)
        u = self.u[0] + w
        O = np.interp(u, self.u, self.O.real) + 1j * np.interp(u, self.u, self.O.imag)
        return O, np.exp(1j * np.interp(u, self.u, self.theta)), w <= span

    @cached_property
    def theta(self) -> np.ndarray:
        """(M,) rad: the base link's angle at the stations, unwrapped (once per track)."""
        return np.unwrap(np.angle(self.rot))


def _follow(solve, path: list, side: float, limit: float, sign: float, x: tuple, L: float, tol: float) -> int:
    """Continue `path` ((|u|, O, rot) from the design pose) along side * u up to |u| = limit,
    one angle per step: a step is accepted where Newton closes in at most EASY steps, within
    PREDICT L of the pose extrapolated from the last two (and, past the first step, within 0.3
    of the move from the last pose: the path's curvature resolved), no inner pin moving
    more than MOVE L, and the group's Jacobian keeping its sign `sign` (a step over a fold or
    past a near-crossing of two modes lands where it has the other); else halved, down to
    STEP_MIN (a fold: the path ends). The solves made."""
    h, count = STATION, 0
    while path[-1][0] < limit * (1 - 1e-15) and h >= STEP_MIN:
        u0, Oa, ra = path[-1]
        h = min(h, limit - u0)
        t = h / (u0 - path[-2][0]) if len(path) > 1 else 0.0
        Ob, rb = path[-2][1:] if len(path) > 1 else (Oa, ra)
        Op, rp = Oa + t * (Oa - Ob), ra * cmath.exp(1j * t * cmath.phase(ra / rb))
        On, rn, its, res, sn = solve(side * (u0 + h), Op, rp)
        count += 1
        miss, move = _SCALAR.pose_distance(x, On, rn, Op, rp), _SCALAR.pose_distance(x, On, rn, Oa, ra)
        if sn == sign and res <= tol and its <= EASY and miss <= PREDICT * L and move <= MOVE * L and \
                (len(path) == 1 or miss <= 0.3 * move + 1e-6 * L):
            path.append((u0 + h, On, rn))
            h = min(2 * h, STATION) if miss <= PREDICT * L / 4 and (len(path) == 2 or miss <= 0.1 * move) else h
        else:
            h /= 2
    return count


def track(kinds: str, pins, phi0: float, O0: complex, rot0: complex, x: tuple, L: float) -> Track:
    """The base link's path by Newton with continuation along the crank's path from the design
    angle phi0 (rad), where the pose is near (O0, rot0), both ways round (`_follow`) to +-pi;
    where one way ends at a fold, the other goes on (up to a whole turn in all).
    `pins(phi)`: the known joints' (P, c) at the angle phi (rad, a float) as `misses` reads them,
    or None where an earlier group does not close (the path ends there too)."""
    def solve(u, O, rot):
        known = pins(phi0 + u)
        if known is None:
            return O, rot, MAX_ITER, np.inf, 0.0
        P, c = (tuple(np.asarray(v).item() for v in part) for part in known)
        return _newton_one(kinds, complex(O), complex(rot), x, P, c, L)

    L, tol = float(L), CLOSURE_TOL * _EPS * L
    O, rot, _, res, sign = solve(0.0, O0, rot0)
    up, down = [(0.0, O, rot)], [(0.0, O, rot)]
    count = 1
    if res <= tol:
        go = lambda path, side, limit: _follow(solve, path, side, limit, sign, x, L, tol)
        count += go(up, 1.0, np.pi) + go(down, -1.0, np.pi)
        if up[-1][0] < np.pi * (1 - 1e-15) <= down[-1][0]:
            count += go(down, -1.0, 2 * np.pi - up[-1][0])
        elif down[-1][0] < np.pi * (1 - 1e-15) <= up[-1][0]:
            count += go(up, 1.0, 2 * np.pi - down[-1][0])
    both = down[:0:-1] + up
    u = np.array([-e[0] for e in down[:0:-1]] + [e[0] for e in up])
    closes = abs(up[-1][0] - np.pi) < 1e-12 and abs(down[-1][0] - np.pi) < 1e-12
    mismatch = float(pose_distance(x, up[-1][1], up[-1][2], down[-1][1], down[-1][2])) if closes else np.nan
    return Track(u, np.array([e[1] for e in both]), np.array([e[2] for e in both]), count, mismatch, float(sign))


def iii3_positions(phi, phi0, kind1, kind2, kind3, x1, x2, x3, P1, P2, P3, c1, c2, c3, L, track):
    """The program's step: the base link's pose O, e^{i theta} at the crank angles phi (rad),
    closed by Newton on all the angles at once from the `track` (a Track) interpolated at each
    (up to FEW_ANGLES of them one by one on Python scalars, `_newton_each`);
    then per angle the closure (0, or -1 where a leash misses by more than CLOSURE_TOL rounding
    units of L, or the angle lies beyond the track's end: the mode drawn at the design position
    cannot be assembled there), the path (0, or -1 where the closed pose lies more than PREDICT
    L from the track's, or where the group's Jacobian has the other sign than along the track:
    Newton left the mode's path, however near the mode it landed in; one of the same sign
    nearer than PREDICT L, three modes near a cusp, is not told apart), the Newton steps and
    the largest miss (m).
    kind<i>: leash i's code (`LEASH_KINDS`); x, P, c as `misses` reads them. Numpy only (it
    reads the whole angle axis), so the compiled path and the Array API path refuse triads by
    name."""
    kinds = leash_kinds((kind1, kind2, kind3))
    u = np.mod(np.asarray(phi, float) - phi0 + np.pi, 2 * np.pi) - np.pi
    x = (x1, x2, x3)
    O0, rot0, on = track.start(u)
    P = tuple(np.broadcast_to(p, u.shape) for p in (P1, P2, P3))
    c = tuple(np.broadcast_to(v, u.shape) for v in (c1, c2, c3))
    O, rot, its, res = (_newton_each if 0 < u.size <= FEW_ANGLES else _newton)(kinds, O0, rot0, x, P, c, L)
    tol = CLOSURE_TOL * _EPS * L
    closed = on & (res <= tol)
    flipped = np.sign(jacobian_det(misses(kinds, O, rot, x, P, c), O)) != track.sign
    left = closed & (~(pose_distance(x, O, rot, O0, rot0) <= PREDICT * L) | flipped)
    return O, rot, np.where(closed, 0.0, -1.0), np.where(left, -1.0, 0.0), its.astype(float), res


#: The names a program may call (`program.bind` binds them with `groups`'); all but
#: iii3_positions are elementwise.
EQUATIONS = ("leash_rr", "leash_slider", "special_point", "special_solve", "third_arm", "iii3_newton", "iii3_velocity",
             "iii3_acceleration", "iii3_condition", "rr_leash_motion", "slider_leash_motion", "rr_tangential",
             "line_tangential", "iii3_polygon", "iii3_positions")


def _locus(kind: str, x, P, c, rot):
    """Where leash `kind` (x, P, c as `misses` reads them) lets the base's origin O lie when the
    base is at the angle rot: a circle (centre, radius) for a two-pin leash, else a line (a
    point of it, its unit normal)."""
    return P - x * rot, (c * rot if kind == "L" else c)


def _false_positions(kinds: str, x: tuple, P: tuple, c: tuple, L: float, t, sign: float):
    """The method of false positions at the trial angles t of the base (rad): each leash puts
    its origin on a circle or a line (`_locus`); the first two of the leashes taken two-pin
    first, then "L", then sliders close it (two circles or a circle and a line on the side
    `sign`; two lines meet once), and the third's miss is measured (NaN where the two cannot
    close). Returns O, rot, f3."""
    rot = cis(t)
    i, j, k = sorted(range(3), key=lambda n: "RLP".index(kinds[n]))
    (Ci, ri), (Cj, rj) = _locus(kinds[i], x[i], P[i], c[i], rot), _locus(kinds[j], x[j], P[j], c[j], rot)
    if kinds[j] == "R":         # two circles
        d = Cj - Ci
        dd = np.abs(d)
        along = (ri**2 - rj**2 + dd**2) / (2 * dd)
        h2 = ri**2 - along**2
        O, ok = Ci + d / dd * (along + 1j * sign * np.sqrt(np.maximum(h2, 0.0))), h2 >= 0
    elif kinds[i] == "R":       # a circle and a line
        foot = Ci - dot(Ci - Cj, rj) * rj
        h2 = ri**2 - np.abs(foot - Ci)**2
        O, ok = foot + sign * 1j * rj * np.sqrt(np.maximum(h2, 0.0)), h2 >= 0
    else:                       # two lines
        det = cross(ri, rj)
        a, b = dot(Ci, ri), dot(Cj, rj)
        O, ok = a * ri + 1j * ri * ((b - a * dot(ri, rj)) / det), det != 0
    return O, rot, np.where(ok, misses(kinds, O, rot, x, P, c)[k][2], np.nan)


def _roots(f3) -> np.ndarray:
    """Indices i where the sampled miss f3 changes sign between i and i + 1."""
    p = f3[:-1] * f3[1:]
    return np.flatnonzero(np.where(np.isfinite(p), p, 1.0) <= 0)


def modes(kinds: str, x: tuple, P: tuple, c: tuple, L: float) -> list[tuple[complex, complex]]:
    """Every assembly mode (base pose O, e^{i theta}) at one position of the known joints (P, c
    scalars as `misses` reads them), by the texts' method of false positions
    (`_false_positions`) at MODE_SAMPLES trial angles of the base (half a step off 0, the angle
    the model draws it at); each change of sign of the miss is refined by Newton on the whole
    group. Two modes closer than the samples leave no change of sign: round each local minimum of |miss| the interval of its two neighbours is
    sampled MODE_SAMPLES times again and searched the same way. Modes that coincide to 1e-9 L
    are one."""
    t = (np.arange(MODE_SAMPLES + 1) + 0.5) * (2 * np.pi / MODE_SAMPLES)   # the drawn mode, theta = 0, between two
    found: list[tuple[complex, complex]] = []
    for sign in (1.0, -1.0):
        O, rot, f3 = _false_positions(kinds, x, P, c, L, t, sign)
        a = np.where(np.isfinite(f3), np.abs(f3), np.inf)
        low = np.flatnonzero((a[1:-1] < a[:-2]) & (a[1:-1] <= a[2:])) + 1
        starts = [(O[_roots(f3)], rot[_roots(f3)])]
        for i in low:
            Of, rf, ff = _false_positions(kinds, x, P, c, L, np.linspace(t[i - 1], t[i + 1], MODE_SAMPLES + 1), sign)
            starts.append((Of[_roots(ff)], rf[_roots(ff)]))
        Os, rots = np.concatenate([s_[0] for s_ in starts]), np.concatenate([s_[1] for s_ in starts])
        if not len(Os):
            continue
        Os, rots, _, res = _newton(kinds, Os, rots, x, tuple(np.full(len(Os), p) for p in P),
                                   tuple(np.full(len(Os), v) for v in c), L)
        for O_, rot_ in zip(Os[res <= CLOSURE_TOL * _EPS * L], rots[res <= CLOSURE_TOL * _EPS * L]):
            if all(abs(O_ - Ok) + L * abs(rot_ - rk) > 1e-9 * L for Ok, rk in found):
                found.append((complex(O_), complex(rot_)))
    return found


_SCALAR = _bind_scalars()
