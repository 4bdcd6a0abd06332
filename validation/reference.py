"""A high-precision reference solution, independent of kinetostat's solution path.

`reference(mech, phi_deg) -> (M_bal (N,), R (N, n_pairs, 2))` solves the whole problem again in
mpmath at `DPS` = 40 significant digits, with a different formulation from the solver's
group-by-group closed forms:

- **Positions**: the 3 (n) absolute coordinates (x, y, theta of every moving link's local
  origin) are the unknowns of the loop-closure equations of ALL pairs at once plus the drive
  constraint theta_1 = theta_1(phi): a revolute pair makes its point coincide on both links
  (2 rows); a prismatic pair keeps the slider point on the guide line, n . (X_s(S) - X_g(G)) = 0,
  and locks the relative rotation, theta_s - theta_g = alpha (2 rows). Newton's method on this
  square system starts from the solver's double-precision answer (the only thing taken from the
  solver's kinematics: it picks the assembly branch) and is iterated in extended precision to
  a residual below 1e-35 of the mechanism's size. The branch of every RRR/RRP/RPR group is then
  re-derived from the converged positions by the definitions of models/FORMAT.md and checked
  against the model's `branch`, so a solver on the wrong branch cannot pass unnoticed. A
  triad (III3) has no branch sign: its assembly mode is the one Newton converges to from the
  solver's positions (the mode the model's points draw is checked by the solver's own tests).
- **Velocities and accelerations**: linear solves J qd = (drive row), J qdd = -(J-dot qd)
  (the quadratic velocity terms written out for both pair kinds) in mpmath.
- **Kinetostatics**: one global Newton-Euler system, 3 equations per moving link (force x, y
  and moment about its centre of mass), unknowns 2 per revolute pair (force of links[0] on
  links[1]), 2 per prismatic pair (normal force N along the guide's world normal n, acting at
  the slider point, and a couple m of the guide on the slider), and the balancing moment M_bal
  on the crank (drive.kind = "engine") or the magnitude f of the pinion's force on the crank's
  gear (drive.kind = "machine", kinetostatics.py's convention: F_bal = f (s cos a rot90(e) -
  sin a e) at the pitch point O + r_w e with s = sign(M_bal); the system is solved with s = +1
  and again with s = -1 if that gives f < 0). 3 n = 2 p5 + 1 for W = 1, so the system is square.

Applied loads: gravity, constant forces and moments (with `against_velocity` / `against_omega`
directions from the reference velocities; a force against the velocity vanishes where its
point's speed is below 1e-9 x size x omega, kinetostat.applied's dead-centre convention) and springs are evaluated here in mpmath. The
MAGNITUDE of a tabulated load (`[load.table]`, by crank angle or by travel) is taken from
`kinetostat.applied.load_magnitude` at the solver's kinematics at the same angles (a
piecewise-linear table read in double precision; the travel tables also need the stroke
extremes that kinetostat finds by sampling); its direction is computed here.

Nothing else of kinetostat is used: the model is read from the `Mechanism` object (links,
points, pairs, loads, drive, and the group decomposition `mech.structure` for the branch check).

Linear solves (Newton steps, velocities, accelerations, statics) by iterative refinement in
mixed precision (`_solve`): corrections from numpy's float64 LU, residuals summed exactly in
integers, until the residual is at the working precision, the backward error of mpmath's LU
solve, which is used itself where float64 cannot get there. Speed: a few milliseconds per angle
of a 6-link model, about a tenth of the time with mpmath's LU solves.

`route(scene)` is the accuracy gate's route "reference" (`compare.ROUTES`): the reference at
`sample_angles` of the scene's cycle as an `EngineResult`, so that a CI without any physics
engine can still gate the solver's accuracy.

May use: kinetostat (model, analysis, applied loads), the scene, mpmath, numpy.
"""
from __future__ import annotations

import math
import time
import warnings
from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from mpmath import mp, mpf

from kinetostat import Analysis, Mechanism, analyze
from kinetostat.applied import load_magnitude
from kinetostat.friction import RATE_TOL

from .scene import EngineResult, Scene

__all__ = ["DPS", "EVENLY_SPACED", "SAMPLE", "Reference", "reference", "reference_full", "BranchMismatch", "sample_angles", "route"]

#: Working precision of the reference, decimal digits.
DPS = 40
#: The route "reference" re-solves this many equally spaced crank angles of the cycle, plus the
#: angles where the solver's error shows most (`sample_angles`).
EVENLY_SPACED = 6
#: The route's angles as the tolerances, the reports and the README state them (from EVENLY_SPACED).
SAMPLE = (f"{EVENLY_SPACED} equally spaced crank angles (every {360 / EVENLY_SPACED:g}°) plus the angle of each "
          "quantity's peak (the largest |M_bal|, each pair's largest |R|) and each moving link's largest |ε|")


class BranchMismatch(AssertionError):
    """The solver's positions (the Newton start) lie on the other assembly branch of a group."""


@dataclass(frozen=True)
class Reference:
    """The reference answer at N crank angles (float arrays; NaN where the position is singular)."""
    phi_deg: np.ndarray     # (N,)
    theta: np.ndarray       # (N, L) link angles, rad (link 0: 0)
    origin: np.ndarray      # (N, L, 2) world position of each link's local origin, m
    omega: np.ndarray       # (N, L) rad/s
    eps: np.ndarray         # (N, L) rad/s^2
    v_origin: np.ndarray    # (N, L, 2)
    a_origin: np.ndarray    # (N, L, 2)
    M_bal: np.ndarray       # (N,) moment of the drive on the crank about +z, N m
    F_bal: np.ndarray       # (N, 2) machine: pinion force on the crank's gear, N (zeros for an engine)
    R: np.ndarray           # (N, n_pairs, 2) force of pair.links[0] on pair.links[1], N
    couple: np.ndarray      # (N, n_pairs) P pairs: couple of the guide on the slider about the
                            #   slider point, N m (NaN for R pairs)
    newton_iterations: np.ndarray   # (N,) position iterations used
    residual: np.ndarray    # (N,) final loop-closure residual / mechanism size


# ----------------------------------------------------------------------------- mp helpers

def _rot(c, s, p):
    return (c * p[0] - s * p[1], s * p[0] + c * p[1])


def _r90(a):
    return (-a[1], a[0])


def _dot(a, b):
    return a[0] * b[0] + a[1] * b[1]


def _cross(a, b):
    return a[0] * b[1] - a[1] * b[0]


def _sub(a, b):
    return (a[0] - b[0], a[1] - b[1])


def _add(a, b):
    return (a[0] + b[0], a[1] + b[1])


def _mul(k, a):
    return (k * a[0], k * a[1])


def _unit(v):
    n = mp.sqrt(v[0] ** 2 + v[1] ** 2)
    return (v[0] / n, v[1] / n)


def _wrap(a):
    two_pi = 2 * mp.pi
    return a - two_pi * mp.nint(a / two_pi)


@lru_cache(maxsize=1024)
def _cos_sin(theta, prec: int):
    """cos and sin of the angle theta (an mpf) at `prec` bits; remembered, as every point of a
    link asks for them again."""
    return mp.cos_sin(theta)


class _Model:
    """The mechanism's data as mpf numbers, and the constraint equations over q = (x, y, theta)
    of links 1..L-1 (column 3 (k - 1) + 0, 1, 2)."""

    def __init__(self, mech: Mechanism):
        self.mech = mech
        self.L = mech.n_links
        self.n = 3 * (self.L - 1)
        self.pts = [{name: (mpf(p[0]), mpf(p[1])) for name, p in link.points.items()} for link in mech.links]
        self.pairs = []
        for p in mech.pairs:
            if p.kind == "R":
                self.pairs.append(("R", p))
            else:
                d = _unit((mpf(p.direction[0]), mpf(p.direction[1])))
                self.pairs.append(("P", p, d, mp.atan2(d[1], d[0])))
        dr = mech.drive
        ref = _unit((mpf(dr.reference[0]), mpf(dr.reference[1])))
        arm = _sub(self.pts[1][dr.point], self.pts[1][dr.pivot])
        self.th1_0 = mp.atan2(ref[1], ref[0]) - mp.atan2(arm[1], arm[0])
        self.sense, self.omega1, self.eps1 = dr.sense, mpf(dr.omega), mpf(dr.eps)
        self.size = mpf(mech.size)
        if dr.kind == "machine":
            gr = dr.gear
            self.e = _unit((mpf(gr.centre_direction[0]), mpf(gr.centre_direction[1])))
            al = mp.radians(mpf(gr.alpha_w_deg))
            r = mpf(gr.module) * gr.z_wheel / 2
            if gr.correction == "unequal":
                r = r * (1 + 2 * mpf(gr.y) / (gr.z_pinion + gr.z_wheel))
            self.r_w, self.cos_a, self.sin_a = r, mp.cos(al), mp.sin(al)

    @staticmethod
    def col(k: int) -> int:
        return 3 * (k - 1)

    # -- state of a link from q, qd, qdd
    def cs(self, q, k):
        if k == 0:
            return mpf(1), mpf(0)
        return _cos_sin(q[self.col(k) + 2], mp.prec)

    def rvec(self, q, k, name):
        """World vector from link k's origin to its point `name` (the point itself for the frame)."""
        c, s = self.cs(q, k)
        return _rot(c, s, self.pts[k][name])

    def X(self, q, k, name):
        if k == 0:
            return self.pts[0][name]
        i = self.col(k)
        return _add((q[i], q[i + 1]), self.rvec(q, k, name))

    def w(self, qd, k):
        return mpf(0) if k == 0 else qd[self.col(k) + 2]

    def V(self, q, qd, k, name):
        if k == 0:
            return (mpf(0), mpf(0))
        i = self.col(k)
        return _add((qd[i], qd[i + 1]), _mul(qd[i + 2], _r90(self.rvec(q, k, name))))

    def A(self, q, qd, qdd, k, name):
        if k == 0:
            return (mpf(0), mpf(0))
        i = self.col(k)
        r = self.rvec(q, k, name)
        return _add(_add((qdd[i], qdd[i + 1]), _mul(qdd[i + 2], _r90(r))), _mul(-qd[i + 2] ** 2, r))

    def guide(self, q, entry):
        """World guide direction d and normal n of a P pair."""
        _, p, d, _ = entry
        c, s = self.cs(q, p.links[0])
        dw = _rot(c, s, d)
        return dw, _r90(dw)

    # -- constraint equations
    def th1(self, phi):
        return self.th1_0 + self.sense * phi

    def phi_rows(self, q, phi):
        out = [_wrap(q[2] - self.th1(phi))]
        for entry in self.pairs:
            p = entry[1]
            i, j = p.links
            if entry[0] == "R":
                out.extend(_sub(self.X(q, i, p.point), self.X(q, j, p.point)))
            else:
                _, n = self.guide(q, entry)
                out.append(_dot(n, _sub(self.X(q, j, p.point), self.X(q, i, p.guide))))
                th_i = q[self.col(i) + 2] if i else mpf(0)
                th_j = q[self.col(j) + 2] if j else mpf(0)
                out.append(_wrap(th_j - th_i - entry[3]))
        return out

    def jacobian(self, q):
        J = _zeros(self.n)
        J[0][2] = 1
        row = 1
        for entry in self.pairs:
            p = entry[1]
            i, j = p.links
            if entry[0] == "R":
                for k, sgn in ((i, 1), (j, -1)):
                    if k:
                        c, r = self.col(k), _r90(self.rvec(q, k, p.point))
                        J[row][c], J[row + 1][c + 1] = sgn, sgn
                        J[row][c + 2], J[row + 1][c + 2] = sgn * r[0], sgn * r[1]
            else:
                dw, n = self.guide(q, entry)
                if j:
                    c = self.col(j)
                    J[row][c], J[row][c + 1] = n
                    J[row][c + 2] = _dot(n, _r90(self.rvec(q, j, p.point)))
                    J[row + 1][c + 2] = 1
                if i:
                    c = self.col(i)
                    delta = _sub(self.X(q, j, p.point), self.X(q, i, p.guide))
                    J[row][c], J[row][c + 1] = -n[0], -n[1]
                    J[row][c + 2] = -_dot(n, _r90(self.rvec(q, i, p.guide))) - _dot(dw, delta)
                    J[row + 1][c + 2] = -1
            row += 2
        return J

    def quadratic(self, q, qd):
        """The velocity-squared part Q of each constraint's second time derivative: J qdd = -Q."""
        out = [mpf(0)]
        for entry in self.pairs:
            p = entry[1]
            i, j = p.links
            if entry[0] == "R":
                ri, rj = self.rvec(q, i, p.point), self.rvec(q, j, p.point)
                wi, wj = self.w(qd, i), self.w(qd, j)
                qi = _sub(_mul(-wi ** 2, ri) if i else (0, 0), _mul(-wj ** 2, rj) if j else (0, 0))
                out.extend(qi)
            else:
                dw, n = self.guide(q, entry)
                wg, ws = self.w(qd, i), self.w(qd, j)
                delta = _sub(self.X(q, j, p.point), self.X(q, i, p.guide))
                ddelta = _sub(self.V(q, qd, j, p.point), self.V(q, qd, i, p.guide))
                rs = self.rvec(q, j, p.point) if j else (0, 0)
                rg = self.rvec(q, i, p.guide) if i else (0, 0)
                Q = (-wg ** 2 * _dot(n, delta) + 2 * _dot(_mul(-wg, dw), ddelta)
                     + _dot(n, _add(_mul(-ws ** 2, rs), _mul(wg ** 2, rg))))
                out.extend([Q, mpf(0)])
        return out


#: Most refinement steps of a solve before it falls back to mpmath's LU (each step gains about
#: 16 - log10(cond A) digits: 3 or 4 reach DPS digits on a well-conditioned system).
REFINE_STEPS = 8
#: Bits beyond the working precision in the fixed-point residual of a refinement step.
GUARD = 32


def _zeros(n: int) -> list[list]:
    """An n x n matrix of zeros as a list of rows (plain lists: mpmath's matrix type costs more
    in indexing than the reference spends in arithmetic)."""
    return [[mpf(0)] * n for _ in range(n)]


def _fixed(v, shift: int) -> int:
    """The mpf (or int) v times 2**shift, truncated to an integer."""
    sign, man, exp, _ = (v if isinstance(v, mpf) else mpf(v))._mpf_
    e = exp + shift
    k = man << e if e >= 0 else man >> -e
    return -k if sign else k


def _solve(A: list[list], b: list) -> list:
    """x with A x = b at the working precision (A a list of rows), by iterative refinement in
    mixed precision: each correction is solved in float64 (LAPACK's LU through numpy), each
    residual b - A x is summed exactly in integers, with A, x and b as fixed-point numbers of
    GUARD bits more than the working precision. It stops when the residual is at most n ulps of
    |A| |x| + |b| at the working precision, the backward error of mpmath's own LU solve; where
    float64 cannot get there (cond A near 1e16 or more, or an exactly singular A) it is mpmath's
    LU solve itself (ZeroDivisionError where A is singular)."""
    n = len(A)
    A64 = np.array([[float(v) for v in row] for row in A])
    b64 = np.array([float(v) for v in b])
    if not np.any(b64) and not any(b):
        return [mpf(0)] * n
    ulp = n * float(mp.eps)
    with np.errstate(all="ignore"):
        try:
            dx = np.linalg.solve(A64, b64)
        except np.linalg.LinAlgError:
            dx = np.array([np.nan])
        a_max, x_max = np.abs(A64).max(), np.abs(dx).max()
        if np.isfinite(dx).all() and x_max > 0:
            # fixed point: A's entries with pa fraction bits, x's with px, the residual with pa + px
            pa = mp.prec + GUARD - math.frexp(a_max)[1]
            px = mp.prec + GUARD - math.frexp(x_max)[1]
            Ai = [[(j, _fixed(v, pa)) for j, v in enumerate(row) if v] for row in A]     # the nonzeros
            Bi = [_fixed(v, pa + px) for v in b]
            X = [0] * n
            bound = ulp * (np.abs(A64).sum(axis=1).max() * x_max + np.abs(b64).max())
            for _ in range(REFINE_STEPS):
                X = [xj + int(math.ldexp(d, px)) for xj, d in zip(X, dx.tolist())]
                r = np.array([math.ldexp(float(bi - sum(a * X[j] for j, a in row)), -(pa + px))
                              for bi, row in zip(Bi, Ai)])
                if np.abs(r).max() <= bound:
                    return [mp.ldexp(mpf(xj), -px) for xj in X]
                try:
                    dx = np.linalg.solve(A64, r)
                except np.linalg.LinAlgError:
                    break
                if not np.isfinite(dx).all():
                    break
    return list(mp.lu_solve(mp.matrix(A), mp.matrix(b)))


def _orientation(m: _Model, q) -> int:
    """The sign of the whole constraint Jacobian's determinant at q: constant along a path that
    passes no singular position, so the mode continuous from the design position keeps it. In
    doubles where |det| is above 1e-8 of Hadamard's bound (the product of the rows' norms: the
    rounding of the double determinant is ~n eps of it, so its sign is exact), else in 40 digits."""
    J = m.jacobian(q)
    A = np.array([[float(x) for x in row] for row in J])
    sign, logdet = np.linalg.slogdet(A)
    norms = np.linalg.norm(A, axis=1)
    if sign != 0 and np.all(norms > 0) and logdet - np.log(norms).sum() > math.log(1e-8):
        return int(sign)
    return int(mp.sign(mp.det(mp.matrix(J))))


def _design_orientation(m: _Model) -> int:
    """`_orientation` at the design position, from the solver's pose there (the mode the
    model's points draw; the group is far from singular there, so the double pose's sign is
    the exact one)."""
    mech = m.mech
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        kin = analyze(mech, phi_deg=[mech.drive.design_deg]).kin
    q = [mpf(0)] * m.n
    for k in range(1, m.L):
        c = m.col(k)
        q[c], q[c + 1], q[c + 2] = mpf(float(kin.origin[0, k, 0])), mpf(float(kin.origin[0, k, 1])), mpf(float(kin.theta[0, k]))
    return _orientation(m, q)


def _branch_check(m: _Model, q, phi_deg: float, design: int | None = None) -> None:
    """Re-derive each group's branch from the converged positions (models/FORMAT.md); with a
    triad, `design` (`_design_orientation`): the converged positions keep the design position's
    orientation (a jump to a neighbouring mode, across a fold, flips it)."""
    if design is not None and _orientation(m, q) != design:
        raise BranchMismatch(f"phi = {phi_deg:.6g} deg: the solver's positions are not in the mode continuous from the "
                             f"design position (the constraint Jacobian's determinant changed sign)")
    for g in m.mech.structure.groups:
        if g.klass == 3 or g.kind not in ("RRR", "RRP", "RPR"):
            continue                 # a triad: the orientation above
        pj, pin, pk = g.pairs
        j, k = g.links
        if g.kind == "RRR":
            P, Q, B = m.X(q, j, pj.point), m.X(q, k, pk.point), m.X(q, j, pin.point)
            val = _cross(_sub(Q, P), _sub(B, P))
            scale = m.size ** 2
        elif g.kind == "RRP":
            entry = m.pairs[pk.index]
            dw, _ = m.guide(q, entry)
            # the slider point B moves on a line parallel to d; F the foot from P
            P, B = m.X(q, j, pj.point), m.X(q, j, pin.point)
            val = _dot(dw, _sub(B, P))
            scale = m.size
        else:
            entry = m.pairs[pin.index]
            dw, _ = m.guide(q, entry)
            P, Q = m.X(q, j, pj.point), m.X(q, k, pk.point)
            val = _dot(dw, _sub(P, Q))
            scale = m.size
        if abs(val) > mpf(10) ** -12 * scale and int(mp.sign(val)) != g.branch:
            raise BranchMismatch(f"group {g.label} ({g.kind}) at phi = {phi_deg:.6g} deg: the solver's "
                                 f"positions are on branch {int(mp.sign(val))}, the model says {g.branch}")


def _applied(m: _Model, q, qd, phi_index: int, mags: dict, wrench_F, wrench_M, S) -> None:
    """Add gravity, loads and springs to the per-link force (world) and moment about S[k]."""
    mech = m.mech
    G = -mpf(mech.g)
    for link in mech.links[1:]:
        if link.mass:
            wrench_F[link.id] = _add(wrench_F[link.id], (mpf(0), mpf(link.mass) * G))  # at S: no moment
    for n, ld in enumerate(mech.loads):
        k = ld.link
        mag = mpf(ld.value) if ld.table is None else mpf(float(mags[n][phi_index]))
        if ld.kind == "moment":
            if ld.direction == "against_omega":
                mag = -mp.sign(m.w(qd, k)) * abs(mag)
            wrench_M[k] += mag
            continue
        X = m.X(q, k, ld.point)
        if ld.direction == "against_velocity":
            v = m.V(q, qd, k, ld.point)
            sp = mp.sqrt(_dot(v, v))
            # kinetostat.applied's convention: no force where the speed is below 1e-9 size omega
            e = (mpf(0), mpf(0)) if sp <= 1e-9 * m.size * m.omega1 else _mul(-1 / sp, v)
        else:
            e = _unit((mpf(ld.direction[0]), mpf(ld.direction[1])))
        f = _mul(mag, e)
        wrench_F[k] = _add(wrench_F[k], f)
        wrench_M[k] += _cross(_sub(X, S[k]), f)
    for sp in mech.springs:
        A, B = m.X(q, sp.a[0], sp.a[1]), m.X(q, sp.b[0], sp.b[1])
        AB = _sub(B, A)
        length = mp.sqrt(_dot(AB, AB))
        f_on_b = _mul(-mpf(sp.stiffness) * (length - mpf(sp.free_length)) / length, AB)
        for k, X, f in ((sp.b[0], B, f_on_b), (sp.a[0], A, _mul(-1, f_on_b))):
            if k:
                wrench_F[k] = _add(wrench_F[k], f)
                wrench_M[k] += _cross(_sub(X, S[k]), f)


def _friction_signs(m: _Model, q, qd, qdd) -> list:
    """Per pair: the sign of the motion of pair.links[1] relative to links[0] (omega_j - omega_i;
    the sliding velocity along the guide), computed here from the reference's own velocities;
    where it is below RATE_TOL x the crank's (x size for a slider), minus the sign of its rate
    (the motion just before: kinetostat.friction's convention), 0 at standstill."""
    out = []
    for entry in m.pairs:
        p = entry[1]
        i, j = p.links
        if entry[0] == "R":
            rate, acc, tol = m.w(qd, j) - m.w(qd, i), m.w(qdd, j) - m.w(qdd, i), RATE_TOL
        else:
            dw, _ = m.guide(q, entry)
            X = m.X(q, j, p.point)
            wi, ei = m.w(qd, i), m.w(qdd, i)
            if i:
                c = m.col(i)
                r = _sub(X, (q[c], q[c + 1]))
                Vi = _add((qd[c], qd[c + 1]), _mul(wi, _r90(r)))
                Ai = _add(_add((qdd[c], qdd[c + 1]), _mul(ei, _r90(r))), _mul(-wi ** 2, r))
            else:
                Vi = Ai = (mpf(0), mpf(0))
            v_rel = _sub(m.V(q, qd, j, p.point), Vi)
            a_rel = _sub(_sub(m.A(q, qd, qdd, j, p.point), Ai), _mul(2 * wi, _r90(v_rel)))
            rate, acc, tol = _dot(dw, v_rel), _dot(dw, a_rel), RATE_TOL * m.size
        crank = abs(m.w(qd, 1))
        out.append(mp.sign(rate) if abs(rate) > tol * crank else (-mp.sign(acc) if crank else 0))
    return out


def _friction_terms(m: _Model, q, x, S, signs, coef, row) -> tuple[list, list]:
    """The friction loads of every pair as the left-hand side Phi(x) of the Newton-Euler rows
    (added like the reactions' own terms) and their Jacobian dPhi/dx (lists)."""
    n = m.n
    phi, J = [mpf(0)] * n, _zeros(n)
    for u, entry in enumerate(m.pairs):
        p, c, s = entry[1], 2 * u, signs[u]
        i, j = p.links
        if not s:
            continue
        if entry[0] == "R":
            mag = mp.sqrt(x[c] ** 2 + x[c + 1] ** 2)
            grad = {c: x[c] / mag, c + 1: x[c + 1] / mag} if mag else {}
            for k, sgn in ((j, 1), (i, -1)):
                if k:
                    r = row(k) + 2
                    phi[r] += -sgn * coef[u] * s * mag
                    for col, g in grad.items():
                        J[r][col] += -sgn * coef[u] * s * g
        else:
            dw, _ = m.guide(q, entry)
            X = m.X(q, j, p.point)
            mag, g = abs(x[c]), mp.sign(x[c])
            for k, sgn in ((j, 1), (i, -1)):
                if k:
                    r = row(k)
                    unit = _mul(-sgn * coef[u] * s, dw)          # d(force on k) / d|N|
                    arm = _cross(_sub(X, S[k]), unit)
                    for dr, val in ((0, unit[0]), (1, unit[1]), (2, arm)):
                        phi[r + dr] += val * mag
                        J[r + dr][c] += val * g
    return phi, J


def _statics(m: _Model, q, qd, qdd, phi_index: int, mags: dict, s_gear: int, friction: bool = False):
    """The global Newton-Euler system at one state; returns the unknown vector (a list). With
    `friction`: the friction loads of every pair (kinetostat.friction's laws) are unknowns'
    functions, and the whole nonlinear system is solved at once by Newton's method from the
    frictionless solution, to a residual below 1e-30 of the largest load."""
    mech = m.mech
    L = m.L
    n = m.n
    S = [None] * L
    for link in mech.links[1:]:
        c = m.col(link.id)          # moments about the centre of mass, or the local origin
        S[link.id] = m.X(q, link.id, link.com) if link.com else (q[c], q[c + 1])
    Fk = [(mpf(0), mpf(0)) for _ in range(L)]
    Mk = [mpf(0) for _ in range(L)]
    _applied(m, q, qd, phi_index, mags, Fk, Mk, S)
    A = _zeros(n)
    b = [mpf(0)] * n

    def row(k):
        return 3 * (k - 1)

    # right-hand side: m a_S - F_known ; I eps - M_known (about S)
    for link in mech.links[1:]:
        k, r = link.id, row(link.id)
        aS = m.A(q, qd, qdd, k, link.com) if link.com else (mpf(0), mpf(0))
        mass = mpf(link.mass)
        b[r] = mass * aS[0] - Fk[k][0]
        b[r + 1] = mass * aS[1] - Fk[k][1]
        b[r + 2] = mpf(link.I_S) * m.w(qdd, k) - Mk[k]
    # reaction unknowns
    for u, entry in enumerate(m.pairs):
        p = entry[1]
        i, j = p.links
        c = 2 * u
        if entry[0] == "R":
            for k, sgn in ((j, 1), (i, -1)):
                if k:
                    r = row(k)
                    arm = _sub(m.X(q, k, p.point), S[k])
                    A[r][c], A[r + 1][c + 1] = sgn, sgn
                    # moment of (sgn Rx, sgn Ry) about S: arm x R
                    A[r + 2][c] += -sgn * arm[1]
                    A[r + 2][c + 1] += sgn * arm[0]
        else:
            _, nn = m.guide(q, entry)
            X = m.X(q, j, p.point)
            for k, sgn in ((j, 1), (i, -1)):
                if k:
                    r = row(k)
                    arm = _sub(X, S[k])
                    A[r][c] += sgn * nn[0]
                    A[r + 1][c] += sgn * nn[1]
                    A[r + 2][c] += sgn * _cross(arm, nn)
                    A[r + 2][c + 1] += sgn
    last = n - 1
    if mech.drive.kind == "engine":
        A[2][last] = 1
    else:
        u_dir = _sub(_mul(s_gear * m.cos_a, _r90(m.e)), _mul(m.sin_a, m.e))
        O = m.X(q, 1, mech.drive.pivot)
        Pp = _add(O, _mul(m.r_w, m.e))
        A[0][last], A[1][last] = u_dir
        A[2][last] = _cross(_sub(Pp, S[1]), u_dir)
    x = _solve(A, b)
    if friction and m.mech.friction is not None:
        fr = m.mech.friction
        coef = [mpf(fr.f) * (mpf(e[1].radius if e[1].radius is not None else fr.radius) if e[0] == "R" else 1)
                for e in m.pairs]
        signs = _friction_signs(m, q, qd, qdd)
        scale = max(abs(v) for v in b) + max(abs(v) for v in x)
        for _ in range(60):
            phi, J = _friction_terms(m, q, x, S, signs, coef, row)
            res = [sum(a * xi for a, xi in zip(Ar, x)) + f - bi for Ar, f, bi in zip(A, phi, b)]
            if max(abs(v) for v in res) <= mpf(10) ** (10 - mp.dps) * scale:
                break
            dx = _solve([[a + jj for a, jj in zip(Ar, Jr)] for Ar, Jr in zip(A, J)], res)
            x = [xi - d for xi, d in zip(x, dx)]
        else:
            raise ArithmeticError("reference: Newton on the frictional equilibrium did not converge")
        along = [-coef[u] * signs[u] * abs(x[2 * u]) for u in range(len(m.pairs))]
    else:
        along = [mpf(0)] * len(m.pairs)
    F_bal = (mpf(0), mpf(0))
    if mech.drive.kind == "engine":
        M_bal = x[last]
    else:
        F_bal = _mul(x[last], u_dir)
        M_bal = _cross(_mul(m.r_w, m.e), F_bal)
    return x, M_bal, F_bal, along


def reference_full(mech: Mechanism, phi_deg, res: Analysis | None = None, dps: int = DPS,
                   check_branch: bool = True, angle: str = "decimal", friction: bool = False) -> Reference:
    """The reference at crank angles `phi_deg` (deg). `res`: the solver's answer at the same
    angles (its positions are the Newton start; computed if not given). `friction`: with the
    model's friction in the reactions, the whole mechanism's equilibrium at once by Newton
    (a prismatic pair's R then includes its friction force along the guide).

    `angle`: "decimal" (default) takes each angle as the exact number of degrees it is (90.0 is
    pi/2 exactly); "double" takes the double-precision radians the solver itself works with,
    np.radians(phi_deg), as exact, so that the rounding of the input angle is not counted as
    the solver's error; "next_double" the next double above it (one ulp of the angle)."""
    if angle not in ("decimal", "double", "next_double"):
        raise ValueError(f"angle: expected 'decimal', 'double' or 'next_double', got {angle!r}")
    phi_deg = np.atleast_1d(np.asarray(phi_deg, dtype=float))
    if res is None:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            res = analyze(mech, phi_deg=phi_deg)
    if len(res.phi_deg) != len(phi_deg) or not np.allclose(res.phi_deg, phi_deg, rtol=0, atol=1e-9):
        raise ValueError("reference: `res` must be the solver's answer at the same angles")
    N, L, P = len(phi_deg), mech.n_links, len(mech.pairs)
    out = dict(theta=np.zeros((N, L)), origin=np.zeros((N, L, 2)), omega=np.zeros((N, L)),
               eps=np.zeros((N, L)), v_origin=np.zeros((N, L, 2)), a_origin=np.zeros((N, L, 2)),
               M_bal=np.full(N, np.nan), F_bal=np.zeros((N, 2)), R=np.full((N, P, 2), np.nan),
               couple=np.full((N, P), np.nan), newton_iterations=np.zeros(N, int),
               residual=np.zeros(N))
    mags = {n: load_magnitude(mech, res.kin, ld) for n, ld in enumerate(mech.loads) if ld.table is not None}
    with mp.workdps(dps):
        m = _Model(mech)
        tol = mpf(10) ** (5 - dps) * m.size
        design = _design_orientation(m) if check_branch and any(g.klass == 3 for g in mech.structure.groups) else None
        for a in range(N):
            if angle == "decimal":
                phi = mp.radians(mpf(float(phi_deg[a])))
            elif angle == "double":
                phi = mpf(float(np.radians(phi_deg[a])))
            else:                           # one ulp above: the inherent uncertainty of a double angle
                phi = mpf(float(np.nextafter(np.radians(phi_deg[a]), np.inf)))
            q = [mpf(0)] * m.n
            for k in range(1, L):
                c = m.col(k)
                q[c], q[c + 1], q[c + 2] = (mpf(float(res.kin.origin[a, k, 0])), mpf(float(res.kin.origin[a, k, 1])),
                                            mpf(float(res.kin.theta[a, k])))
            it, ok = 0, False
            for it in range(1, 60):
                r = m.phi_rows(q, phi)
                rmax = max(abs(x) for x in r)
                if rmax < tol:
                    ok = True
                    break
                try:
                    q = [qi - d for qi, d in zip(q, _solve(m.jacobian(q), r))]
                except ZeroDivisionError:
                    break
            out["newton_iterations"][a] = it
            out["residual"][a] = float(max(abs(x) for x in m.phi_rows(q, phi)) / m.size)
            if not ok:
                out["theta"][a], out["origin"][a] = np.nan, np.nan
                continue
            if check_branch:
                _branch_check(m, q, float(phi_deg[a]), design)
            for k in range(1, L):
                c = m.col(k)
                out["theta"][a, k] = float(q[c + 2])
                out["origin"][a, k] = float(q[c]), float(q[c + 1])
            try:
                J = m.jacobian(q)
                rhs = [mpf(0)] * m.n
                rhs[0] = m.sense * m.omega1
                qd = _solve(J, rhs)
                Q = m.quadratic(q, qd)
                rhs = [-x for x in Q]
                rhs[0] = m.sense * m.eps1
                qdd = _solve(J, rhs)
                x, M_bal, F_bal, along = _statics(m, q, qd, qdd, a, mags, 1, friction)
                if mech.drive.kind == "machine" and x[m.n - 1] < 0:
                    x, M_bal, F_bal, along = _statics(m, q, qd, qdd, a, mags, -1, friction)
            except ZeroDivisionError:           # exactly singular position
                out["omega"][a] = out["eps"][a] = np.nan
                out["v_origin"][a] = out["a_origin"][a] = np.nan
                continue
            for k in range(1, L):
                c = m.col(k)
                out["omega"][a, k], out["eps"][a, k] = float(qd[c + 2]), float(qdd[c + 2])
                out["v_origin"][a, k] = float(qd[c]), float(qd[c + 1])
                out["a_origin"][a, k] = float(qdd[c]), float(qdd[c + 1])
            out["M_bal"][a] = float(M_bal)
            out["F_bal"][a] = float(F_bal[0]), float(F_bal[1])
            for u, entry in enumerate(m.pairs):
                if entry[0] == "R":
                    out["R"][a, u] = float(x[2 * u]), float(x[2 * u + 1])
                else:
                    dw, nn = m.guide(q, entry)
                    t = along[u]
                    out["R"][a, u] = float(x[2 * u] * nn[0] + t * dw[0]), float(x[2 * u] * nn[1] + t * dw[1])
                    out["couple"][a, u] = float(x[2 * u + 1])
    return Reference(phi_deg=phi_deg, **out)


def reference(mech: Mechanism, phi_deg, res: Analysis | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Balancing moment (N,) and reactions (N, n_pairs, 2) (force of pair.links[0] on
    pair.links[1], world, N) at crank angles `phi_deg`, computed in mpmath at DPS digits."""
    ref = reference_full(mech, phi_deg, res=res)
    return ref.M_bal, ref.R


def peak_relative_error(res: Analysis, ref: Reference) -> dict[str, float]:
    """Per quantity (M_bal, R(i,j)): max over the angles of |solver - reference| divided by the
    max over the angles of |reference|; angles where either is NaN are left out."""
    out = {}
    items = [("M_bal", res.balancing_moment[:, None], ref.M_bal[:, None])]
    items += [(f"R({p.links[0]},{p.links[1]})", res.forces.R[:, p.index], ref.R[:, p.index]) for p in res.mech.pairs]
    for name, got, want in items:
        ok = np.isfinite(got).all(axis=-1) & np.isfinite(want).all(axis=-1)
        if not ok.any():
            out[name] = math.nan
            continue
        peak = float(np.max(np.linalg.norm(want[ok], axis=-1)))
        err = float(np.max(np.linalg.norm(got[ok] - want[ok], axis=-1)))
        out[name] = err / peak if peak > 0 else err
    return out


def sample_angles(res: Analysis, n: int = EVENLY_SPACED) -> np.ndarray:
    """Indices of `res`'s angles for the reference route (SAMPLE), sorted, without repeats: `n`
    equally spaced over the cycle, and the angles where an error of the solver
    shows most: the largest |M_bal| and each pair's largest |R| (the peak-relative error's
    denominator is there, and an error in proportion to the load is largest there), and each
    moving link's largest |eps| (the largest inertia loads)."""
    N = len(res.phi_deg)
    idx = set(np.linspace(0, N, min(n, N), endpoint=False).astype(int).tolist())
    mags = [np.abs(res.balancing_moment)] + [np.linalg.norm(res.forces.R[:, p.index], axis=-1) for p in res.mech.pairs]
    mags += [np.abs(res.kin.eps[:, k]) for k in range(1, res.mech.n_links)]
    for mag in mags:
        if np.any(np.isfinite(mag)) and np.nanmax(mag) > 0:
            idx.add(int(np.nanargmax(mag)))
    return np.array(sorted(idx), dtype=int)


def route(scene: Scene, n: int = EVENLY_SPACED) -> EngineResult:
    """The gate's route "reference": the 40-digit answer at `sample_angles(scene.res, n)`, each
    angle taken as the double the solver works with (angle="double"). The Newton start comes
    from a fresh solver run at those angles, not from the result under test."""
    mech = scene.mech
    phi = scene.phi_deg[sample_angles(scene.res, n)]
    t0 = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        start = analyze(mech, phi_deg=phi)
    build = time.perf_counter() - t0
    ref = reference_full(mech, phi, res=start, angle="double")
    return EngineResult("mpmath", "reference", phi.copy(), ref.M_bal, ref.R, build_seconds=build,
                        run_seconds=time.perf_counter() - t0 - build,
                        note=f"{DPS}-digit re-solution at {len(phi)} of the {len(scene.phi_deg)} angles")
