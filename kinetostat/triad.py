"""The class-III group III3 (a triad; Artobolevsky's course, not among the seeds): a ternary base
link with the inner joints X1, X2, X3 and three leashes to known joints. Written with the
primitives of `groups`, in the same elementwise style:

- a leash's axis u (unit) and its miss f: a two-pin leash A-X (u along A -> X, f = |AX| - l),
  or a slider whose pin X runs on a guide line (u the line's normal, f = (X - K) . u);
- Assur's special point S, where the axes of leashes 1 and 2 meet, taken as a point of the base:
  every linear solve of the group (a Newton step of the positions, the velocity and acceleration
  plans, the reactions) is x . u1 = r1, x . u2 = r2 for a vector x at S (a 2x2 solve) and one
  division by h3 = (X3 - S) x u3, the arm of leash 3's axis about S. h3 = 0 (three axes through
  one point) is the group's singular position;
- the positions by Newton with continuation from the design position over the stations round
  the cycle, all the angles of a block at once (`positions`, once per mechanism: the track), then
  at the angles asked all at once from the track (`iii3_positions`; numpy only: it reads the
  whole angle axis, so the compiled path and the Array API path refuse triads by name).

May use: numpy, groups.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy as xp

from .groups import cis, cross, dot, magnitude, over, solve2

__all__ = ["leash_rr", "leash_slider", "special_point", "special_solve", "iii3_newton", "iii3_velocity",
           "iii3_acceleration", "iii3_condition", "rr_leash_motion", "slider_leash_motion",
           "rr_tangential", "iii3_polygon", "iii3_positions", "positions", "misses", "stations", "modes", "MODE_SAMPLES", "Positions", "BLOCK", "MAX_ITER", "RETRIES",
           "STATION", "CLOSURE_TOL", "EQUATIONS"]

#: Continuation: angles within BLOCK (rad) of the last solved one are solved together, from the
#: linear extrapolation of the last two solutions.
BLOCK = np.radians(6.0)
#: The continuation's stations (rad apart) round the cycle: the track every angle starts from.
STATION = np.radians(3.0)
#: Newton steps per block at most.
MAX_ITER = 40
#: Angles of a block that do not close are solved again from the nearest closed angle before
#: them, at most this many times.
RETRIES = 3
#: The largest miss of a leash accepted as closed, in rounding units of the group's size.
CLOSURE_TOL = 1e3
#: Trial positions of leash 1 per turn (or along a slider's line) in the search for the modes.
MODE_SAMPLES = 3600
_EPS = np.finfo(float).eps


# -- elementwise equations (bound and rebound like `groups`)
def leash_rr(X, A, l):
    """A two-pin leash A-X of length l: its axis u (A -> X) and the miss |AX| - l."""
    r = magnitude(X - A)
    return over(X - A, r), r - l


def leash_slider(X, K, n):
    """A slider whose pin X runs on the guide line through K with unit normal n: axis n, miss (X - K) . n."""
    return n, dot(X - K, n)


def special_point(X1, u1, X2, u2):
    """Assur's special point S = the meeting point of the axes (X1, u1) and (X2, u2), and u1 x u2."""
    det = cross(u1, u2)
    return X1 + u1 * (cross(X2 - X1, u2) / det), det


def special_solve(u1, u2, u3, det, h3, r1, r2, r3):
    """The group's linear solve at S: the vector x (at S) with x . u1 = r1, x . u2 = r2, and
    y = (r3 - x . u3) / h3, the rate of turn that closes leash 3 (arm h3 about S)."""
    x = r1 * u1 + 1j * u1 * ((r2 - r1 * dot(u1, u2)) / det)
    return x, (r3 - dot(x, u3)) / h3


def iii3_newton(O, rot, S, det, X3, u1, u2, u3, f1, f2, f3):
    """One Newton step of the base link's pose (origin O, e^{i theta}): move S by dS and turn
    about it by dth so that each leash's miss f_i goes to zero to first order."""
    h3 = cross(X3 - S, u3)
    dS, dth = special_solve(u1, u2, u3, det, h3, -f1, -f2, -f3)
    turn = cis(dth)
    return S + dS + (O - S) * turn, rot * turn, magnitude(dS) + abs(dth * magnitude(O - S))


def iii3_velocity(S, X3, u1, u2, u3, det, V1, V2, V3):
    """Velocity plan at S: v_S = v_1 + v_S1 (v_S1 _|_ u1) = v_2 + v_S2 (v_S2 _|_ u2), v_i the known
    velocity of leash i's reference (its outer pin; a slider's guide point under X); then
    (v_X3 - v_3) . u3 = 0 gives omega. Returns v_S, omega, h3."""
    h3 = cross(X3 - S, u3)
    vS, w = special_solve(u1, u2, u3, det, h3, dot(V1, u1), dot(V2, u2), dot(V3, u3))
    return vS, w, h3


def iii3_acceleration(S, X1, X2, X3, u1, u2, u3, det, h3, w, A1, A2, A3, c1, c2, c3):
    """Acceleration plan at S: a_Xi . u_i = a_i . u_i + c_i (c_i: a leash's normal or Coriolis
    term), a_Xi = a_S + (i eps - w^2)(X_i - S). Returns a_S, eps."""
    w2 = w * w
    return special_solve(u1, u2, u3, det, h3, dot(A1, u1) + c1 + w2 * dot(X1 - S, u1),
                         dot(A2, u2) + c2 + w2 * dot(X2 - S, u2), dot(A3, u3) + c3 + w2 * dot(X3 - S, u3))


def iii3_condition(u1, u2, u3, det, h3, L):
    """Frobenius condition number of the group's system at S (rows u_i, arm h_i / L; h1 = h2 = 0):
    inf where the three axes meet in one point (h3 = 0) or axes 1 and 2 are parallel."""
    c = h3 / L
    y1, y2 = solve2(u1, u2, det, u3)
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


def iii3_polygon(S, X3, u1, u2, u3, det, T1, T2, T3, P1, P2, P3, m1, m2, m3, F, MS):
    """Reactions in the texts' order. T_i: leash i's R^tau (from its moment about its inner pin),
    acting at P_i (a slider: T = 0 and the couple m_i); F, MS: the group's known loads (sum of
    forces; moment about S). R^n of leash 3 from the group's moment about S (R^n_1, R^n_2 pass
    through S), then R^n_1, R^n_2 from the group's force polygon. Returns the magnitudes along u_i."""
    h3 = cross(X3 - S, u3)
    M = MS + cross(P1 - S, T1) + cross(P2 - S, T2) + cross(P3 - S, T3) + m1 + m2 + m3
    n3 = -M / h3
    n1, n2 = solve2(u1, u2, det, -(F + T1 + T2 + T3 + n3 * u3))
    return n1, n2, n3


def stations(phi0: float) -> np.ndarray:
    """The design angle phi0 and the angles STATION apart from it round the cycle (rad), in
    the order of u = phi - phi0 from -pi to pi: the continuation's track."""
    k = np.arange(-int(np.pi / STATION), int(np.pi / STATION) + 1)
    return phi0 + STATION * k


# -- the positions over the angles: Newton with continuation (numpy)
@dataclass(frozen=True)
class Positions:
    """The base link's pose at each angle, and how it was found."""
    O: np.ndarray          # (N,) complex, m: the base link's local origin
    rot: np.ndarray        # (N,) complex e^{i theta}
    iterations: np.ndarray  # (N,) Newton steps taken at each angle (from its block's start)
    residual: np.ndarray   # (N,) largest |miss| of the three leashes after the last step, m


def misses(kinds: str, O, rot, x: tuple, P: tuple, c: tuple):
    """Per leash the world inner pin X_i, axis u_i and miss f_i at the pose (O, rot); kinds[i]
    "R" (two-pin leash: P_i the outer pin, c_i the length) or "P" (slider: P_i a point of the
    guide line, c_i its unit normal)."""
    out = []
    for k, xi, Pi, ci in zip(kinds, x, P, c):
        X = O + xi * rot
        out.append((X, *(leash_rr(X, Pi, ci) if k == "R" else leash_slider(X, Pi, ci))))
    return out


def _newton(kinds, O, rot, x, P, c, L):
    """Newton on every angle at once until each step is below rounding (MAX_ITER at most);
    the pose, the steps taken and the largest miss left."""
    its = np.zeros(O.shape, int)
    for _ in range(MAX_ITER):
        (X1, u1, f1), (X2, u2, f2), (X3, u3, f3) = misses(kinds, O, rot, x, P, c)
        S, det = special_point(X1, u1, X2, u2)
        O_new, rot_new, step = iii3_newton(O, rot, S, det, X3, u1, u2, u3, f1, f2, f3)
        moving = ~(step <= 8 * _EPS * L)
        its += moving
        O, rot = np.where(moving, O_new, O), np.where(moving, rot_new / np.abs(rot_new), rot)
        if not moving.any():
            break
    return O, rot, its, np.max([np.abs(f) for _, _, f in misses(kinds, O, rot, x, P, c)], axis=0)


def positions(kinds: str, phi, phi0: float, O0: complex, rot0: complex, x: tuple, P: tuple, c: tuple,
              L: float) -> Positions:
    """The base link's pose at the crank angles phi (rad, (N,)) by Newton with continuation
    along the crank's path from the design angle phi0 where the pose is near (O0, rot0), both
    ways round (to +-pi). The angles are taken in blocks of BLOCK: each block starts from the
    linear extrapolation of two solved poses (the last, and the farthest from it of the block's
    first and the previous block's last), and Newton runs on the block's angles
    at once; an angle that does not close is solved again from the nearest closed one before it. P and c as `misses` reads them, arrays over phi (or constants)."""
    phi = np.asarray(phi, float)
    u, first, back = np.unique(np.mod(phi - phi0 + np.pi, 2 * np.pi) - np.pi, return_index=True,
                               return_inverse=True)           # along the path, in [-pi, pi); each angle once
    phi, N = phi[first], len(first)
    P = tuple(np.broadcast_to(p, back.shape)[first] for p in P)
    c = tuple(np.broadcast_to(v, back.shape)[first] for v in c)
    O, rot = np.empty(N, complex), np.empty(N, complex)
    its, res = np.zeros(N, int), np.zeros(N)
    at = lambda idx, arrs: tuple(a[idx] for a in arrs)
    # the design pose itself: the mode the model's points draw (O0, rot0 refined)
    seed = np.argmin(np.abs(u))
    O_s, rot_s, _, _ = _newton(kinds, np.array([O0]), np.array([rot0]), x, at([seed], P), at([seed], c), L)
    for side in (1.0, -1.0):
        on = np.flatnonzero(side * u >= 0 if side > 0 else u < 0)
        on = on[np.argsort(side * u[on], kind="stable")]
        last = [(0.0 if abs(u[seed]) == 0 else u[seed], O_s[0], rot_s[0])]
        start = 0
        while start < len(on):
            stop = start + np.searchsorted(side * u[on[start:]], side * last[-1][0] + BLOCK, side="right")
            idx = on[start:max(stop, start + 1)]
            (u1, O1, r1), (u2, O2, r2) = (last[-2] if len(last) > 1 else last[-1]), last[-1]
            t = (u[idx] - u2) / (u2 - u1) if u2 != u1 else np.zeros(len(idx))
            th2 = np.angle(r2)
            Og, thg = O2 + t * (O2 - O1), th2 + t * np.angle(r2 / r1)
            O[idx], rot[idx], its[idx], res[idx] = _newton(kinds, Og, np.exp(1j * thg), x, at(idx, P), at(idx, c), L)
            for _ in range(RETRIES):        # a miss: again from the nearest closed angle before it
                ok = res[idx] <= CLOSURE_TOL * _EPS * L
                prev = np.maximum.accumulate(np.where(ok, np.arange(len(idx)), -1))
                redo = np.flatnonzero(~ok & (prev >= 0))
                if not len(redo):
                    break
                j, src = idx[redo], idx[prev[redo]]
                O[j], rot[j], more, res[j] = _newton(kinds, O[src], rot[src], x, at(j, P), at(j, c), L)
                its[j] += more
            new = (u[idx[-1]], O[idx[-1]], rot[idx[-1]])      # extrapolate from the two farthest apart
            first = (u[idx[0]], O[idx[0]], rot[idx[0]])
            last = [max(last[-1], first, key=lambda e: abs(e[0] - new[0])), new]
            start += len(idx)
    return Positions(O[back], rot[back], its[back], res[back])


def iii3_positions(phi, phi0, slider1, slider2, slider3, x1, x2, x3, P1, P2, P3, c1, c2, c3, L, track):
    """The program's step: the base link's pose O, e^{i theta}, the closure (0, or -1 where a
    leash misses by more than CLOSURE_TOL rounding units of L: the group cannot be assembled
    there), the Newton steps and the largest miss (m). slider<i>: 1.0 where leash i is a
    slider, else 0.0. `track`: None, or the poses (u, O, rot) solved at the stations (`stations`
    with no angle asked; u = phi - phi0 in [-pi, pi), sorted): None runs the continuation from
    the design pose (the base link's local frame: the model's points drawn in world
    coordinates); a track gives every angle its start, interpolated between the stations
    around it, and Newton runs on all the angles at once."""
    kinds = "".join("P" if s else "R" for s in (slider1, slider2, slider3))
    if track is None:
        pos = positions(kinds, phi, phi0, 0j, 1 + 0j, (x1, x2, x3), (P1, P2, P3), (c1, c2, c3), L)
        O, rot, its, res = pos.O, pos.rot, pos.iterations, pos.residual
    else:
        tu, tO, trot = track
        u = np.mod(np.asarray(phi, float) - phi0 + np.pi, 2 * np.pi) - np.pi
        th = np.unwrap(np.angle(trot))
        O, rot, its, res = _newton(kinds, np.interp(u, tu, tO.real) + 1j * np.interp(u, tu, tO.imag),
                                   np.exp(1j * np.interp(u, tu, th)), (x1, x2, x3),
                                   tuple(np.broadcast_to(p, u.shape) for p in (P1, P2, P3)),
                                   tuple(np.broadcast_to(v, u.shape) for v in (c1, c2, c3)), L)
    return O, rot, np.where(res <= CLOSURE_TOL * _EPS * L, 0.0, -1.0), its.astype(float), res


#: The names a program may call (`program.bind` binds them with `groups`'); all but
#: iii3_positions are elementwise.
EQUATIONS = ("leash_rr", "leash_slider", "special_point", "special_solve", "iii3_newton", "iii3_velocity",
             "iii3_acceleration", "iii3_condition", "rr_leash_motion", "slider_leash_motion", "rr_tangential",
             "iii3_polygon", "iii3_positions")


def modes(kinds: str, x: tuple, P: tuple, c: tuple, L: float) -> list[tuple[complex, complex]]:
    """Every assembly mode (base pose O, e^{i theta}) at one position of the known joints (P, c
    scalars as `misses` reads them), by the texts' method of false positions: leash 1 is set at
    MODE_SAMPLES trial positions (a two-pin leash turned round its outer pin; a slider's pin
    moved along its line over +-4 L), the base turned about it until leash 2 closes (two ways,
    as a dyad closes), and the miss of leash 3 read; each change of sign of the miss is refined
    by Newton on the whole group. Modes that coincide to 1e-9 L are one."""
    t = np.linspace(0.0, 2 * np.pi, MODE_SAMPLES + 1)
    X1 = P[0] + c[0] * cis(t) if kinds[0] == "R" else P[0] + 1j * c[0] * (4 * L) * (t / np.pi - 1.0)
    r12 = x[1] - x[0]
    rho = abs(r12)
    found: list[tuple[complex, complex]] = []
    for sign in (1.0, -1.0):
        if kinds[1] == "R":         # C on the circle (X1, rho) and on the circle (A2, l2)
            d = P[1] - X1
            dd = np.abs(d)
            along = (rho**2 - c[1]**2 + dd**2) / (2 * dd)
            C = X1 + d / dd * (along + 1j * sign * np.sqrt(np.maximum(rho**2 - along**2, 0.0)))
            ok = rho**2 - along**2 >= 0
        else:                       # C on the circle (X1, rho) and on the line (K2, normal n2)
            foot = X1 - dot(X1 - P[1], c[1]) * c[1]
            h2 = rho**2 - np.abs(foot - X1)**2
            C = foot + sign * 1j * c[1] * np.sqrt(np.maximum(h2, 0.0))
            ok = h2 >= 0
        rot = (C - X1) / r12
        O = X1 - x[0] * rot
        f3 = misses(kinds, O, rot, x, P, c)[2][2]
        f3 = np.where(ok, f3, np.nan)
        at = np.flatnonzero((f3[:-1] * f3[1:] <= 0) & np.isfinite(f3[:-1] * f3[1:]))
        if not len(at):
            continue
        Os, rots, _, res = _newton(kinds, O[at], rot[at], x, tuple(np.full(len(at), p) for p in P),
                                   tuple(np.full(len(at), v) for v in c), L)
        for O_, rot_ in zip(Os[res <= CLOSURE_TOL * _EPS * L], rots[res <= CLOSURE_TOL * _EPS * L]):
            if all(abs(O_ - Ok) + L * abs(rot_ - rk) > 1e-9 * L for Ok, rk in found):
                found.append((complex(O_), complex(rot_)))
    return found
