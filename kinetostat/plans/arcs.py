"""The arc of a rotation's sense (ω, ε on the mechanism) or of a couple (M_i, M_bal on a group
or crank plan), built turned about its centre so that its arrowhead, drawn at the arc's end,
falls clear of the heavy lines there: the links and the vectors of its plan.

The turn is chosen at each angle from that angle's geometry alone (the first of `TURNS_DEG`
whose arrowhead keeps `CLEAR_MM` from every heavy line, else the one that keeps the most), so
the sheet of one angle and the page's frame of that angle draw the same arc, and an arc keeps
its turn from angle to angle until a line comes near its arrowhead.

Plan coordinates: mm, complex x + iy, arrays with a leading angle axis N, NaN where absent.

May use: numpy and `core`.
"""
from __future__ import annotations

import numpy as np

from .core import PAGE_DECIMALS, Segment

__all__ = ["arc", "heavy_lines", "TURNS_DEG", "CLEAR_MM", "HEAD_MM", "MIN_DRAWN_MM", "STEP_DEG", "GRID_MM"]

#: A vector drawn shorter than TINY_MM at its scale is drawn out of scale at MIN_DRAWN_MM, mm (`draw`).
MIN_DRAWN_MM = 6.0
#: The turns an arc may take about its centre, deg, tried in this order.
TURNS_DEG = (0.0, -45.0, 45.0, -90.0, 90.0, -135.0, 135.0, 180.0)
#: How far the arrowhead's axis keeps from a heavy line's axis, mm: the arrowhead's half-width
#: (0.48), a thick line's (0.35) and 0.37 between.
CLEAR_MM = 1.2
#: The arc's last stretch where its arrowhead is drawn (`draw.ARC_HEAD_MM` = 2.8, and a little), mm.
HEAD_MM = 3.0
#: An arc's points are this far apart about its centre, deg.
STEP_DEG = 15.0
#: The grid an arc's offsets from its centre are rounded to, mm: the page's coordinates'
#: (`core.PAGE_DECIMALS`), so that where an arc keeps its turn and sense, its points' coordinates
#: over the angles are its first point's plus a constant, which the page stores as such.
GRID_MM = 10.0 ** -PAGE_DECIMALS[0]
#: The segments' kinds an arrowhead must keep clear of: links and vectors.
HEAVY = ("link", "vector", "alternative")


def heavy_lines(pts: dict, segs: list[Segment]) -> tuple[np.ndarray, np.ndarray]:
    """The heavy lines of a plan as built so far: (starts, ends), each (N, L) complex mm: every
    link, and every vector at least MIN_DRAWN_MM long from its start (as a short one is drawn);
    NaN where a line is not drawn (a segment with a unit whose value is NaN there)."""
    heavy = [s for s in segs if s.kind in HEAVY]
    if not heavy:
        return np.zeros((1, 0), complex), np.zeros((1, 0), complex)
    drawn = np.stack([np.broadcast_to(~(bool(s.unit) & np.isnan(np.asarray(s.value, dtype=float))),
                                      np.shape(pts[s.start])) for s in heavy], axis=1)     # as PlanCycle.drawn
    a = np.where(drawn, np.stack([pts[s.start] for s in heavy], axis=1), np.nan)
    b = np.stack([pts[s.end] for s in heavy], axis=1)
    vec = np.array([s.kind != "link" for s in heavy])
    d = b - a
    L = np.abs(d)
    with np.errstate(invalid="ignore", divide="ignore"):
        longer = np.where(vec & (L < MIN_DRAWN_MM) & (L > 0), a + d / L * MIN_DRAWN_MM, b)
    return a, longer


def _distance(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Distance (mm) of points p (N, T, S, 1) from segments a-b (N, 1, 1, L); inf where NaN."""
    d = b - a
    with np.errstate(invalid="ignore", divide="ignore"):
        t = np.clip(((p - a) * d.conjugate()).real / (d * d.conjugate()).real, 0.0, 1.0)
        t = np.where(np.isfinite(t), t, 0.0)
        dist = np.abs(p - (a + t * d))
    return np.where(np.isnan(dist), np.inf, dist)


def arc(c: np.ndarray, r: float, sense: np.ndarray, start_deg, sweep_deg: float,
        lines: tuple[np.ndarray, np.ndarray]) -> np.ndarray:
    """(N, K) complex mm: arcs of radius r about the centres c (N,), a point every STEP_DEG, from start_deg (one, or (N,);
    measured ccw, y up) through sweep_deg in the sense's direction (N,; ccw for +), each turned about its
    centre by the first of TURNS_DEG at which the arrowhead's stretch (the last HEAD_MM of the
    arc) keeps CLEAR_MM from every one of `lines` (`heavy_lines`), else by the one that keeps the
    most. Each point's offset from its centre on the grid of the page's coordinates (`GRID_MM`)."""
    c = np.asarray(c, dtype=complex)
    s = np.asarray(sense, dtype=float)[:, None]
    start = np.reshape(np.asarray(start_deg, dtype=float), (-1, 1))
    turns = np.radians(np.array(TURNS_DEG))                                     # (T,)
    end = np.radians(start + sweep_deg * s) + turns                         # (N, T)
    back = np.array([0.0, HEAD_MM / 2, HEAD_MM]) / r                            # along the arc from its end, rad
    head = c[:, None, None] + r * np.exp(1j * (end[:, :, None] - s[:, :, None] * back))      # (N, T, 3)
    a, b = lines
    if a.shape[1]:
        near = _distance(head[..., None], a[:, None, None, :], b[:, None, None, :]).min(axis=(2, 3))   # (N, T)
    else:
        near = np.full(end.shape, np.inf)
    clear = near >= CLEAR_MM
    pick = np.where(clear.any(axis=1), np.argmax(clear, axis=1), np.argmax(near, axis=1))
    t = np.radians(start + s * np.arange(0.0, sweep_deg + STEP_DEG / 2, STEP_DEG)) + turns[pick][:, None]
    off = r * np.exp(1j * t) / GRID_MM
    return c[:, None] + (np.round(off.real) + 1j * np.round(off.imag)) * GRID_MM
