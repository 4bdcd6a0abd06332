"""What laws of motion and motor characteristics evaluate: parsed expressions, kept, the
periodic cubic spline through a table of omega(phi), and the search for a pole of omega(phi)
between checked angles.

May use: the standard library, numpy, expressions.
"""
from __future__ import annotations

import functools
import math
from typing import Callable

import numpy as np

from ..expressions import ExpressionError, parse as parse_expression

def mentions_phi(text: str) -> bool:
    """Whether a drive's `omega` string is a law of motion (an expression of `phi`) rather than
    a constant speed written over the model's parameters (`"n1 * pi / 30"`)."""
    try:
        return "phi" in parse_expression(text).names
    except ExpressionError:
        return True                  # not a valid expression: the law's reader says why


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


def _hermite_at(x: np.ndarray, y: np.ndarray, dy: np.ndarray, phi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Value and first derivative at `phi` (rad) of the periodic cubic Hermite through the values
    `y` and slopes `dy` (per rad) at the increasing knots `x` (rad) of one period 2 pi."""
    xe, ye, de = np.append(x, x[0] + 2 * np.pi), np.append(y, y[0]), np.append(dy, dy[0])
    t = x[0] + np.mod(phi - x[0], 2 * np.pi)
    i = np.clip(np.searchsorted(xe, t, side="right") - 1, 0, len(x) - 1)
    h = xe[i + 1] - xe[i]
    s = (t - xe[i]) / h
    h00, h10, h01, h11 = (1 + 2 * s) * (1 - s) ** 2, s * (1 - s) ** 2, s * s * (3 - 2 * s), s * s * (s - 1)
    value = h00 * ye[i] + h10 * h * de[i] + h01 * ye[i + 1] + h11 * h * de[i + 1]
    slope = (6 * s * (s - 1) * (ye[i] - ye[i + 1]) / h + (1 - s) * (1 - 3 * s) * de[i]
             + s * (3 * s - 2) * de[i + 1])
    return value, slope


#: A law's value between two checked angles that exceeds this many times the largest value at
#: those angles is a pole (`pole`).
POLE_RISE = 1e3


def pole(law: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]], phi: np.ndarray, w: np.ndarray,
         dw: np.ndarray, depth: int = 60, most: int = 256) -> tuple[float, float, float, float] | None:
    """Where omega(phi) = `law(phi)[0]` grows without bound between the neighbouring angles `phi`
    (rad, increasing) at which it took the values `w` (rad/s, finite) and slopes `dw`: the
    interval is halved where its cubic through the ends' values and slopes misses the value at
    its middle by more than 1e-3 (a smooth law soon stops; a pole never, however short the
    interval), until the middle's value is not finite or exceeds POLE_RISE times the largest of
    `w`. Returns (the checked angles on either side, the angle reached, |omega| there: inf, or
    NaN where omega is not real there), deg and rad/s; None where nothing is found within
    `depth` halvings."""
    top = max(float(np.abs(w).max()), 1e-300)
    k = np.arange(len(phi) - 1)                       # each interval's first checked angle
    lo, hi, wa, wb, da, db = phi[:-1], phi[1:], w[:-1], w[1:], dw[:-1], dw[1:]
    for _ in range(depth):
        mid = (lo + hi) / 2
        with np.errstate(all="ignore"):
            wm, dm = law(mid)
            wild = ~(np.isfinite(wm) & np.isfinite(dm)) | (np.abs(wm) > POLE_RISE * top)
            if wild.any():
                n = int(np.argmax(wild))
                return (math.degrees(phi[k[n]]), math.degrees(phi[k[n] + 1]), math.degrees(mid[n]),
                        float(abs(wm[n])))
            cubic = (wa + wb) / 2 + (hi - lo) / 8 * (da - db)
            miss = np.abs(wm - cubic) / (np.maximum(np.maximum(np.abs(wa), np.abs(wb)), np.abs(wm)) + 1e-12 * top)
        odd = np.flatnonzero(miss > 1e-3)
        if len(odd) == 0:
            return None
        odd = odd[np.argsort(-np.abs(wm[odd]))[:most]]      # the largest values, where a pole would be
        k = np.concatenate([k[odd], k[odd]])
        lo, hi = np.concatenate([lo[odd], mid[odd]]), np.concatenate([mid[odd], hi[odd]])
        wa, wb = np.concatenate([wa[odd], wm[odd]]), np.concatenate([wm[odd], wb[odd]])
        da, db = np.concatenate([da[odd], dm[odd]]), np.concatenate([dm[odd], db[odd]])
    return None
