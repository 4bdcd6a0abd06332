"""Planar vector algebra. Inside the solver a plane vector is a complex number x + iy (Raven's
complex-vector method): a turn by theta is a product with e^{i theta}, a turn by +90 deg a
product with i, and one numpy operation acts on a whole stack of vectors. Public arrays are
(..., 2) real; `as_xy` views complex stacks that way without copying.
"""
from __future__ import annotations

import numpy as np

__all__ = ["as_z", "as_xy", "cross_z", "dot_z", "decompose", "condition",
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


def cross_z(a, b):
    """z-component of a x b for complex plane vectors."""
    return a.real * b.imag - a.imag * b.real


def dot_z(a, b):
    return a.real * b.real + a.imag * b.imag


def decompose(v: np.ndarray, a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Solve v = alpha a + beta b (complex stacks; alpha, beta real): the closing of a vector
    polygon of a plan. Where a and b are parallel this divides by zero (inf/nan there, the
    callers run under np.errstate): the singular-position guard (`condition`) reports and marks it."""
    det = cross_z(a, b)
    return cross_z(v, b) / det, cross_z(a, v) / det


def condition(a: np.ndarray, b: np.ndarray, la: float | None = None, lb: float | None = None) -> np.ndarray:
    """2-norm condition number of [a/la b/lb], the measure of a singular position (inf where
    a and b are parallel). `la`, `lb` are reference sizes of the columns (default: their own
    lengths, a pure angle measure; pass a length scale for columns that are lengths, so that a
    vanishing arm counts)."""
    sa2 = a.real**2 + a.imag**2 if la is None else la * la
    sb2 = b.real**2 + b.imag**2 if lb is None else lb * lb
    frob = (a.real**2 + a.imag**2) / sa2 + (b.real**2 + b.imag**2) / sb2
    t = 0.5 * frob / np.abs(cross_z(a, b) / np.sqrt(sa2 * sb2))   # ||M||_F^2 / (2 |det M|)
    return t + np.sqrt(np.maximum(t * t - 1.0, 0.0))                # kappa + 1/kappa = 2 t


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
