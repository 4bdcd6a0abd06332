"""Planar vector algebra on stacks of 2-vectors, shape (..., 2)."""
from __future__ import annotations

import numpy as np

__all__ = ["cross", "rot90", "rotate", "unit", "decompose"]


def cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """z-component of a x b for stacks of 2-vectors: shape (...,)."""
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def rot90(a: np.ndarray) -> np.ndarray:
    """a turned by +90 deg (z x a)."""
    return np.stack([-a[..., 1], a[..., 0]], axis=-1)


def rotate(p: np.ndarray, theta: np.ndarray) -> np.ndarray:
    """Local vectors p (..., 2) turned by angles theta (...)."""
    c, s = np.cos(theta), np.sin(theta)
    return np.stack([c * p[..., 0] - s * p[..., 1], s * p[..., 0] + c * p[..., 1]], axis=-1)


def unit(a: np.ndarray) -> np.ndarray:
    return a / np.linalg.norm(a, axis=-1, keepdims=True)


def decompose(v: np.ndarray, a: np.ndarray, b: np.ndarray,
              la: float | None = None, lb: float | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Solve v = alpha a + beta b for every row: the closing of a vector polygon of a plan.

    Returns alpha, beta and the 2-norm condition number of [a/la b/lb], the measure of a
    singular position (inf where a and b are parallel). `la`, `lb` are reference sizes of
    the columns (default: their own lengths, which makes the condition number a pure angle
    measure; pass a length scale for columns that are lengths, so that a vanishing arm counts).
    """
    det = cross(a, b)
    with np.errstate(divide="ignore", invalid="ignore"):
        alpha = cross(v, b) / det
        beta = cross(a, v) / det
        sa = np.linalg.norm(a, axis=-1) if la is None else la
        sb = np.linalg.norm(b, axis=-1) if lb is None else lb
        p, q = np.sum(a * a, axis=-1) / sa**2, np.sum(b * b, axis=-1) / sb**2
        r = np.sum(a * b, axis=-1) / (sa * sb)
        s1 = 0.5 * (p + q) + np.sqrt(0.25 * (p - q) ** 2 + r**2)   # largest squared singular value
        cond = s1 / np.abs(det / (sa * sb))                       # sigma1 / sigma2 = s1 / |det|
    return alpha, beta, cond
