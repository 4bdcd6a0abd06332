"""The equations of the method, written once: every Assur group's closed forms (positions,
velocity and acceleration plans, seed 002 sec. 1.2.2; the force polygon, seed 000 sec. 6) and
the rigid-body transfers between them, as pure elementwise functions of complex plane vectors
x + iy and real numbers.

Elementwise means each function reads its inputs one position at a time: the same code runs
on numpy arrays over the angles (and designs), on any Array API library's arrays (`program.bind`
binds `xp` to the namespace at hand), and on scalars inside a compiled loop over the angles
(`fast` compiles this very source). So the functions use only arithmetic, xp.sqrt, maximum,
conj, real, imag, sign and five named primitives, no branch on a value. The primitives
(`magnitude`, `over`, `ratio`, `cis`, `phase`) are the operations a compiler lowers badly
(libm calls, division with branches); here they are today's operators, and `fast` binds
branch-free inline versions of the same five names.

May use: nothing but the namespace `xp` it is bound to (numpy by default).
"""
from __future__ import annotations

import numpy as xp

__all__ = ["magnitude", "over", "ratio", "cis", "phase", "cross", "dot", "solve2", "condition", "point_motion", "origin_motion", "motion_at",
           "aligned", "same", "scaled", "sub", "add", "length", "square", "guide_offset",
           "slider_offset", "turn", "unturn", "place", "local_of", "off_line", "times", "crank", "rrr_motion", "rrp_motion", "rpr_motion",
           "prp_motion", "rpp_motion", "moment_about", "carry", "revolute_pair", "prismatic_pair",
           "rrr_polygon", "rrp_polygon", "rpr_polygon", "prp_polygon", "rpp_polygon", "inertia", "weight", "wrench",
           "gear_force", "power"]


# -- the primitives (`fast` rebinds these five names)
def magnitude(z):
    """|z| of a plane vector."""
    return abs(z)


def over(z, r):
    """A plane vector over a real number, z / r."""
    return z / r


def ratio(z, w):
    """A plane vector over a plane vector, z / w (complex division)."""
    return z / w


def cis(th):
    """e^{i th}: the unit vector at angle th (rad)."""
    return xp.exp(1j * th)


def phase(x):
    """The angle of the plane vector x, rad, in (-pi, pi]."""
    return xp.atan2(xp.imag(x), xp.real(x))


# -- plane vector algebra (Raven's complex vectors: Im and Re of conj(a) b)
def cross(a, b):
    """z-component of a x b."""
    return xp.imag(xp.conj(a) * b)


def dot(a, b):
    """Scalar product a . b."""
    return xp.real(xp.conj(a) * b)


def solve2(a, b, det, v):
    """(alpha, beta) closing the polygon v = alpha a + beta b (alpha, beta real), det = a x b:
    a vector equation of the plans solved for its two unknown magnitudes, by one reciprocal of
    det (compiled, the calls on one det share it). Where a and b are parallel it divides by
    zero: the singular-position guard marks those positions."""
    k = 1.0 / det
    return cross(v, b) * k, cross(a, v) * k


def condition(frob, det):
    """2-norm condition number of a 2x2 matrix from ||M||_F^2 and det M (inf where det is 0):
    kappa + 1/kappa = ||M||_F^2 / |det M|, the measure of a singular position."""
    t = 0.5 * frob / abs(det)
    return t + xp.sqrt(xp.maximum(t * t - 1.0, 0.0))


# -- rigid-body transfer (O, V, A: position, velocity, acceleration of a link's local origin;
# w, e: its angular velocity and acceleration; rot = e^{i theta}; x: a local point)
def point_motion(O, V, A, w, e, rot, x):
    """Position, velocity and acceleration of the local point x of a link."""
    r = x * rot
    return O + r, V + 1j * w * r, A + (1j * e - w**2) * r


def origin_motion(X, V, A, w, e, rot, x):
    """The link's local origin, from the motion X, V, A of its local point x."""
    r = x * rot
    return X - r, V - 1j * w * r, A - (1j * e - w**2) * r


def motion_at(O, V, A, w, e, X):
    """Velocity and acceleration of the point of a link that is at world position X."""
    r = X - O
    return V + 1j * w * r, A + (1j * e - w**2) * r


def aligned(X, x, phase_x):
    """Angle and e^{i theta} of a link whose local vector x (its angle phase_x) is the world
    vector X of the same length."""
    return phase(X) - phase_x, ratio(X, x)


def turn(th, rot, alpha, d):
    """Angle and e^{i theta} turned by alpha, d = e^{i alpha} (a slider's frame from its guide's)."""
    return th + alpha, rot * d


def unturn(th, rot, alpha, d):
    """`turn` undone (a guide's frame from its slider's)."""
    return th - alpha, ratio(rot, d)


def place(O, rot, x):
    """World position of the local point x of a link."""
    return O + x * rot


def same(x):
    """x itself (a name given to a value)."""
    return x


def scaled(x, k):
    """k x."""
    return k * x


def sub(a, b):
    """a - b."""
    return a - b


def add(a, b):
    """a + b."""
    return a + b


def length(a, b):
    """|a - b|."""
    return magnitude(a - b)


def square(x):
    """x^2."""
    return x * x


def guide_offset(x, x_guide, d):
    """Signed distance (x - x_guide) x d of a point of the guide link from its guide line."""
    return cross(x - x_guide, d)


def slider_offset(x, x_point):
    """Signed distance of a point of the slider from the guide line (the slider's local x axis
    is the guide direction, through its point x_point)."""
    return -xp.imag(x - x_point)


def local_of(X, O, rot):
    """The local coordinates of world point X in a link's frame."""
    return ratio(X - O, rot)


def off_line(K, c, d):
    """The point at offset c from K across the line of direction d: K - c i d."""
    return K - c * 1j * d


def times(a, b):
    """a b (a guide's world direction from its local one and the link's e^{i theta}; a normal i d)."""
    return a * b


def crank(phi, sense, offset):
    """The initial link's angle and e^{i theta} at crank angle phi (rad)."""
    th = sense * phi + offset
    return th, cis(th)


# -- the groups' kinematics: positions in closed form, then the velocity and acceleration
# plans closed with `solve2`. Each returns the discriminant of its assembly (< 0: the group
# cannot be assembled), the unknowns, and ||M||_F^2, det M of its plans' matrix with columns
# divided by reference sizes (L for a column that is a length, 1 for a unit direction).
def rrr_motion(P, VP, AP, Q, VQ, AQ, lj, lk, branch, L):
    """RRR: links j (P-B, length lj) and k (Q-B, length lk) meet at B.
    v_B = v_P + w_j x PB = v_Q + w_k x QB ;  a_B = a_P - w_j^2 PB + e_j x PB = ..."""
    PQ = Q - P
    d = magnitude(PQ)
    along = (lj**2 - lk**2 + d**2) / (2 * d)
    disc = lj**2 - along**2
    B = P + over(PQ, d) * (along + 1j * branch * xp.sqrt(xp.maximum(disc, 0.0)))
    PB, QB = B - P, B - Q
    a, b = 1j * PB, -1j * QB
    det = cross(a, b)
    wj, wk = solve2(a, b, det, VQ - VP)
    ej, ek = solve2(a, b, det, AQ - wk**2 * QB - AP + wj**2 * PB)
    return disc, B, PB, QB, wj, wk, ej, ek, (lj**2 + lk**2) / L**2, det / L**2


def rrp_motion(P, VP, AP, K, d, cB, lj, branch, Ob, Vb, Ab, wb, eb, L):
    """RRP: link j (P-B, length lj) turns about P; B slides (relative velocity vr along d) on the
    guide line through K of link b (its motion Ob, Vb, Ab, wb, eb), cB the offset of B from it.
    v_B = v_P + w_j x PB = v_B(b) + v_r d ; a_B = ... = a_B(b) + 2 w_b x v_r d + a_r d."""
    w = K - 1j * cB * d - P
    wd = dot(w, d)
    disc = wd**2 - dot(w, w) + lj**2
    B = K + (branch * xp.sqrt(xp.maximum(disc, 0.0)) - wd - 1j * cB) * d
    PB = B - P
    VBb, ABb = motion_at(Ob, Vb, Ab, wb, eb, B)
    a = 1j * PB
    det = cross(a, -d)
    wj, vr = solve2(a, -d, det, VBb - VP)
    ej, ar = solve2(a, -d, det, ABb + 2j * wb * vr * d - AP + wj**2 * PB)
    return disc, B, PB, wj, VP + wj * a, ej, AP + ej * a - wj**2 * PB, vr, ar, lj**2 / L**2 + 1.0, det / L


def rpr_motion(P, VP, AP, Q, VQ, AQ, e, branch, L):
    """RPR: the block j (pin P) slides along d on link k (pin Q), e = (P - Q) x d the constant
    offset. v_P = v_Q + w_k x QP + v_r d ;  a_P = a_Q - w_k^2 QP + e_k x QP + 2 w_k x v_r d + a_r d."""
    QP = P - Q
    rho2 = dot(QP, QP)
    disc = rho2 - e**2
    d = over(QP * (branch * xp.sqrt(xp.maximum(disc, 0.0)) + 1j * e), rho2)
    a = 1j * QP
    det = cross(a, d)
    wk, vr = solve2(a, d, det, VP - VQ)
    ek, ar = solve2(a, d, det, AP - AQ + wk**2 * QP - 2j * wk * vr * d)
    return disc, d, phase(d), wk, ek, vr, ar, rho2 / L**2 + 1.0, det / L


def prp_motion(Ka, da, Kc, dc, Oa, Va, Aa, wa, ea, Oc, Vc, Ac, wc, ec):
    """PRP: the pin B lies on the guide line (Ka, da) of link a and (Kc, dc) of link c.
    v_B = v_B(a) + v1 d_a = v_B(c) + v2 d_c ; accelerations with the Coriolis terms."""
    det = cross(da, -dc)
    t, _ = solve2(da, -dc, det, Kc - Ka)
    B = Ka + t * da
    VBa, ABa = motion_at(Oa, Va, Aa, wa, ea, B)
    VBc, ABc = motion_at(Oc, Vc, Ac, wc, ec, B)
    v1, v2 = solve2(da, -dc, det, VBc - VBa)
    ca, cc = 2j * wa * v1 * da, 2j * wc * v2 * dc
    a1, a2 = solve2(da, -dc, det, ABc + cc - ABa - ca)
    return B, VBa + v1 * da, ABa + ca + a1 * da, v1, v2, a1, a2, 2.0, det


def rpp_motion(P, VP, AP, Kj, d_in, dc, Kc, rX, rY, Oc, Vc, Ac, wc, ec):
    """RPP: link j (pin P) slides along d_in on link k, which slides along dc on link c; k turns
    with c. k's anchor Y = Kj + s d_in lies on the inner line, its anchor X = Y + rX - rY on the
    outer one. v_P = v_P(c) + v2 d_c + v1 d_in ; a_P = a_P(c) + 2 w x (v2 d_c + v1 d_in) + ..."""
    _, s = solve2(dc, -d_in, cross(dc, -d_in), Kj + rX - rY - Kc)
    Ok = Kj + s * d_in - rY
    VPc, APc = motion_at(Oc, Vc, Ac, wc, ec, P)
    det = cross(d_in, dc)
    v1, v2 = solve2(d_in, dc, det, VP - VPc)
    a1, a2 = solve2(d_in, dc, det, AP - APc - 2j * wc * v1 * d_in - 2j * wc * v2 * dc)
    return Ok, VPc + v2 * dc, APc + 2j * wc * v2 * dc + a2 * dc, v1, v2, a1, a2, 2.0, det


# -- the force side: known wrenches per link (force F, moment M about the link's local origin O)
def moment_about(M, O, F, X):
    """Moment about X of the known loads (F, M about O) on a link."""
    return M + cross(O - X, F)


def carry(F, M, O, R, X, m):
    """A link exerts force R through X (and couple m) on a solved group: by action and reaction
    it bears -R and -m. Returns its known wrench updated."""
    return F - R, M - (cross(X - O, R) + m)


def revolute_pair(R, sign):
    """The force of the pair's first link on its second, from R given by one of them (sign +-1)."""
    return sign * R


def prismatic_pair(N, n, m, X0, S, sign):
    """The normal force f = N n whose moment about X0 is m: f, and (as the pair's first link
    gives it, sign +-1) the force, its normal magnitude and its moment about the slider point S."""
    f = N * n
    return f, sign * f, sign * N, sign * (m + cross(X0 - S, f))


def rrr_polygon(P, B, Q, lj, lk, Fj, Fk, MjB, MkB):
    """RRR: tangential parts of the outer reactions from the moments of each link about B,
    normal parts from the closed force polygon of the group."""
    uj, uk = over(B - P, lj), over(B - Q, lk)
    nj, nk = over(1j * uj * MjB, lj), over(1j * uk * MkB, lk)       # one reciprocal of each length
    aj, ak = solve2(uj, uk, cross(uj, uk), -(Fj + Fk + nj + nk))
    R_aj = aj * uj + nj
    return R_aj, Fj + R_aj, ak * uk + nk


def rrp_polygon(P, B, lj, n, Fj, Fk, MjB, MkB):
    """RRP: the reaction at P from j's moment about B and the polygon; the guide's normal force
    N n on k, its moment about B balancing k's."""
    uj = over(B - P, lj)
    nj = over(1j * uj * MjB, lj)
    aj, N = solve2(uj, n, cross(uj, n), -(Fj + Fk + nj))
    R_aj = aj * uj + nj
    return R_aj, Fj + R_aj, N, -MkB


def rpr_polygon(P, Q, n, mP, mQ):
    """RPR: the moment of the whole group about Q fixes the normal force of the slotted link on
    the block."""
    return (mP + mQ) / cross(P - Q, n)


def prp_polygon(na, nc, Fj, Fk):
    """PRP: both guides' normal forces from the group's force polygon."""
    return solve2(na, nc, cross(na, nc), -(Fj + Fk))


def rpp_polygon(n_in, nc, Fk):
    """RPP: link k's balance F_k - f_kj + f_ck = 0 with both forces normal to their guides."""
    return solve2(n_in, -nc, cross(n_in, -nc), Fk)


def inertia(A, w, e, rot, s, mass, I_S):
    """A link's arm r = s rot from its local origin to its centre of mass (local s), the inertia
    main vector -m a_S (at the centre of mass) and main moment -I_S eps (seed 000 sec. 4)."""
    r = s * rot
    return r, -mass * (A + (1j * e - w**2) * r), -I_S * e


def weight(r, mass, g):
    """A link's weight (at its centre of mass, arm r) and its moment about the local origin."""
    W = -1j * g * mass
    return W, cross(r, W)


def wrench(F_app, M_app, F_i, M_i, r):
    """The known wrench of a link about its local origin: applied loads and inertia."""
    return F_app + F_i, M_app + M_i + cross(r, F_i)


def gear_force(M_bal, e_centre, alpha, r_b):
    """Force of the pinion on the crank's gear at the pitch point that applies M_bal about the
    crank axis (seed 000 sec. 7.1), on the line of action at alpha to the tangent."""
    return (abs(M_bal) / r_b) * (xp.sign(M_bal) * (xp.cos(alpha) * 1j * e_centre) - xp.sin(alpha) * e_centre)


def power(F, M, V, w):
    """Power of a wrench (F, M about a link's local origin) on the link: F . V + M w, V the
    velocity of the origin, w the angular velocity."""
    return dot(F, V) + M * w
