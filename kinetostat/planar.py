"""Planar vector algebra. Inside the solver a plane vector is a complex number x + iy (Raven's
complex-vector method): a turn by theta is a product with e^{i theta}, a turn by +90 deg a
product with i, and one numpy operation acts on a whole stack of vectors. Public arrays are
(..., 2) real; `as_xy` views complex stacks that way without copying.

May use: numpy only.
"""
from __future__ import annotations

import numpy as np

__all__ = ["as_z", "as_xy", "cross_z", "dot_z", "Basis", "condition", "diameter",
           "cross", "rot90", "rotate", "unit"]


def as_z(p) -> np.ndarray:
    """(..., 2) real -> (...) complex."""
    p = np.asarray(p, dtype=float)
    return p[..., 0] + 1j * p[..., 1]


def as_xy(z: np.ndarray) -> np.ndarray:
    """(...) complex -> (..., 2) real view (no copy when z is contiguous)."""
    z = np.asarray(z, dtype=complex)
    flat = z.reshape(-1)
    if not flat.flags.c_contiguous:
        flat = flat.copy()
    return flat.view(np.float64).reshape(z.shape + (2,))


# Im and Re of conj(a) b: the same two products and one sum as the component formulas, in
# fewer array operations (which is what costs at a few hundred angles).
def cross_z(a, b):
    """z-component of a x b for complex plane vectors."""
    return (a.conjugate() * b).imag


def dot_z(a, b):
    """Scalar product a . b for complex plane vectors."""
    return (a * b.conjugate()).real if isinstance(b, complex) else (a.conjugate() * b).real


class Basis:
    """Two plane directions a, b (complex stacks) along which vector polygons close:
    v = alpha a + beta b with alpha, beta real. One basis serves a group's velocity and
    acceleration plans (or its force polygon); det = a x b is formed once."""
    __slots__ = ("a", "b", "det")

    def __init__(self, a: np.ndarray, b: np.ndarray):
        self.a, self.b, self.det = a, b, cross_z(a, b)

    def solve(self, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(alpha, beta) closing the polygon of v. Where a and b are parallel this divides by
        zero (inf/nan there; the callers run under np.errstate): the singular-position guard
        (`condition`) reports and marks it."""
        return cross_z(v, self.b) / self.det, cross_z(self.a, v) / self.det


def condition(frob, det) -> np.ndarray:
    """2-norm condition number of a 2x2 matrix M from ||M||_F^2 and det M (inf where det is 0):
    kappa + 1/kappa = ||M||_F^2 / |det M|. Used on the plans' matrices with each column divided
    by a reference size (a length scale for columns that are lengths, so that a vanishing arm
    counts), the measure of a singular position."""
    t = 0.5 * frob / np.abs(det)
    return t + np.sqrt(np.maximum(t * t - 1.0, 0.0))


# -- the same operations on public (..., 2) arrays
def cross(a, b) -> np.ndarray:
    """z-component of a x b for stacks of 2-vectors (..., 2)."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def rot90(a) -> np.ndarray:
    """(..., 2) vectors turned by +90 deg (z x a)."""
    return as_xy(1j * as_z(a))


def rotate(p, theta) -> np.ndarray:
    """Local vectors p (..., 2) turned by angles theta (...)."""
    return as_xy(as_z(p) * np.exp(1j * np.asarray(theta)))


def unit(a) -> np.ndarray:
    a = np.asarray(a, dtype=float)
    return a / np.linalg.norm(a, axis=-1, keepdims=True)


def diameter(points) -> float:
    """Largest distance between two of `points` (complex), 0 for fewer than two: the convex hull
    (monotone chain), then its antipodal pairs (rotating calipers). Work O(n log n)."""
    pts = sorted(set(points), key=lambda z: (z.real, z.imag))
    turn = lambda o, a, b: (a.real - o.real) * (b.imag - o.imag) - (a.imag - o.imag) * (b.real - o.real)

    def chain(seq) -> list[complex]:
        h: list[complex] = []
        for p in seq:
            while len(h) >= 2 and turn(h[-2], h[-1], p) <= 0:
                h.pop()
            h.append(p)
        return h[:-1]

    hull = chain(pts) + chain(reversed(pts))        # counter-clockwise, no collinear vertices
    if len(hull) < 3:
        return abs(pts[-1] - pts[0]) if pts else 0.0
    n, j, best = len(hull), 1, 0.0
    for i in range(n):
        a, b = hull[i], hull[(i + 1) % n]
        while turn(a, b, hull[(j + 1) % n]) > turn(a, b, hull[j]):
            j = (j + 1) % n
        best = max(best, abs(a - hull[j]), abs(b - hull[j]))
    return best
