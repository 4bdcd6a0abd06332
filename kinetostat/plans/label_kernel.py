"""The label placer's costs over many angles as one compiled loop (numba), for `labels.Placer`.

`costs` finds, at every angle, the cost of a label's candidate places exactly as the placer's
numpy path does (the same float32 geometry, the same float64 sums in the same order): its base
cost, infinite where its box overlaps a hard obstacle, plus `line_cost` per mm of the drawn lines
inside its box (each clipped to the box, Liang-Barsky). Candidates are taken in the order given
(cheapest first on the whole), in windows of `first` candidates, then `first`, then twice as
many each time; each window's obstacles are those that can meet one of its boxes, found once
per angle and window. A candidate whose base is more than `slack` over the best cost so far is
not tested (inf), and an angle stops where no base left can come within `slack` of its best:
what is left untested can never be within `slack` of the best, so the places the placer keeps
are those of testing every candidate.

The kernel is generated as a module's text and compiled with numba's disk cache through
`kernel_cache.load` (a trusted folder, signed pickles), once per machine.

May use: numpy, numba (in the generated module), `kinetostat.kernel_cache`.
"""
from __future__ import annotations

import inspect
import math
import threading

import numpy as np

from .. import kernel_cache

__all__ = ["CELL", "MARGIN", "span", "clipped", "cell_of", "grid", "covers", "costs", "kernel"]

#: The side (mm) of the cells of the grid the still obstacles are found by.
CELL = 8.0
#: How far (mm) beyond a box its grid cells are looked in (rounding of its float32 edges).
MARGIN = 1e-3


def span(x0, y0, x1, y1):
    """Length (mm, float32) of the segment (x0, y0)-(x1, y1), float32: hypot as numpy's."""
    return np.float32(math.hypot(x1 - x0, y1 - y0))


def clipped(x0, y0, x1, y1, length, bx0, by0, bx1, by1):
    """Length (mm, float32) of the segment (x0, y0)-(x1, y1) (its `span` `length`) strictly inside
    the box (bx0, by0, bx1, by1), all float32: Liang-Barsky as `labels._clipped` computes it (a
    NaN parameter, a segment on a side's edge or absent, gives 0)."""
    dx, dy = x1 - x0, y1 - y0
    tx0, tx1, ty0, ty1 = (bx0 - x0) / dx, (bx1 - x0) / dx, (by0 - y0) / dy, (by1 - y0) / dy
    if tx0 != tx0 or tx1 != tx1 or ty0 != ty0 or ty1 != ty1:
        return np.float32(0.0)
    t_in = max(max(min(tx0, tx1), min(ty0, ty1)), np.float32(0.0))
    t_out = min(min(max(tx0, tx1), max(ty0, ty1)), np.float32(1.0))
    length = (t_out - t_in) * length
    return length if length > np.float32(0.0) else np.float32(0.0)


def grid(items, lo, cell):
    """The items (M, >= lo + 4) whose boxes (columns lo..lo+3: x0, y0, x1, y1) are finite in a
    uniform grid of square cells `cell` mm wide: (first, members, x0, y0, nx, ny), cell (ix, iy)
    holding members[first[c]:first[c + 1]], c = iy * nx + ix, items in their order."""
    x0, y0, x1, y1 = np.inf, np.inf, -np.inf, -np.inf
    for o in range(items.shape[0]):
        if items[o, lo] <= items[o, lo + 2] and items[o, lo + 1] <= items[o, lo + 3]:    # not NaN
            x0, y0 = min(x0, items[o, lo]), min(y0, items[o, lo + 1])
            x1, y1 = max(x1, items[o, lo + 2]), max(y1, items[o, lo + 3])
    nx = max(1, min(512, int((x1 - x0) / cell) + 1)) if x0 <= x1 else 1
    ny = max(1, min(512, int((y1 - y0) / cell) + 1)) if y0 <= y1 else 1
    first = np.zeros(nx * ny + 1, np.int64)
    for o in range(items.shape[0]):
        if items[o, lo] <= items[o, lo + 2] and items[o, lo + 1] <= items[o, lo + 3]:
            for iy in range(cell_of(items[o, lo + 1], y0, cell, ny), cell_of(items[o, lo + 3], y0, cell, ny) + 1):
                for ix in range(cell_of(items[o, lo], x0, cell, nx), cell_of(items[o, lo + 2], x0, cell, nx) + 1):
                    first[iy * nx + ix + 1] += 1
    first = np.cumsum(first)
    members = np.empty(first[-1], np.int64)
    filled = first[:-1].copy()
    for o in range(items.shape[0]):
        if items[o, lo] <= items[o, lo + 2] and items[o, lo + 1] <= items[o, lo + 3]:
            for iy in range(cell_of(items[o, lo + 1], y0, cell, ny), cell_of(items[o, lo + 3], y0, cell, ny) + 1):
                for ix in range(cell_of(items[o, lo], x0, cell, nx), cell_of(items[o, lo + 2], x0, cell, nx) + 1):
                    members[filled[iy * nx + ix]] = o
                    filled[iy * nx + ix] += 1
    return first, members, x0, y0, nx, ny


def cell_of(x, x0, cell, nx):
    """The cell (0..nx-1) of the coordinate x in a grid from x0 of cells `cell` wide."""
    k = int(math.floor((x - x0) / cell)) if x == x else 0
    return min(max(k, 0), nx - 1)


def covers(first, members, x0, y0, nx, ny, cell, seen, mark, still, spans, X, Y, w, v, lines):
    """A still grid's items that the box centred at (X, Y), half size (w, v), may meet (each
    once: seen[item] set to `mark`): with `lines`, the float64 sum of the lengths of the lines
    (`still` (S, 8), their `span`s `spans`) inside the box; else 1.0 where it overlaps a hard obstacle (`still` (H, 4),
    grown by the clearance), 0.0 where none."""
    covered = 0.0
    for iy in range(cell_of(Y - v - MARGIN, y0, cell, ny), cell_of(Y + v + MARGIN, y0, cell, ny) + 1):
        for ix in range(cell_of(X - w - MARGIN, x0, cell, nx), cell_of(X + w + MARGIN, x0, cell, nx) + 1):
            c = iy * nx + ix
            for k in range(first[c], first[c + 1]):
                o = members[k]
                if seen[o] == mark:
                    continue
                seen[o] = mark
                if lines:
                    if X > still[o, 4] - w and X < still[o, 6] + w and Y > still[o, 5] - v and Y < still[o, 7] + v:
                        covered += clipped(still[o, 0], still[o, 1], still[o, 2], still[o, 3], spans[o], X - w, Y - v, X + w,
                                           Y + v)
                elif X > still[o, 0] - w and X < still[o, 2] + w and Y > still[o, 1] - v and Y < still[o, 3] + v:
                    return 1.0
    return covered


def costs(cx, cy, hx, hy, base, hard_still, hard_moving, soft_still, soft_moving, line_cost, slack, first,
          cost, best):
    """Fill cost (N, K) and best (N,) for the candidates centred at (cx, cy) (N, K), float32, half
    size (hx, hy) (N,), base costs `base` (N, K) (inf: not free), in the order to test them; hard
    obstacles grown by the clearance (H, 4) still and (N, H', 4) moving, lines and their bounding
    boxes (S, 8) still and (N, S', 8) moving, all float32, NaN where absent. inf where not tested."""
    n, K = base.shape
    hm, sm = hard_moving.shape[1], soft_moving.shape[1]
    hfirst, hmembers, hx0, hy0, hnx, hny = grid(hard_still, 0, CELL)
    sfirst, smembers, sx0, sy0, snx, sny = grid(soft_still, 4, CELL)
    hseen, sseen = np.full(hard_still.shape[0], -1, np.int64), np.full(soft_still.shape[0], -1, np.int64)
    grown = np.empty((hm, 4), np.float32)                    # the window's moving hard obstacles, grown by the half size
    lines = np.empty((sm, 9), np.float32)                    # the window's moving lines, grown bounding boxes, spans
    spans = np.empty(soft_still.shape[0], np.float32)
    for o in range(soft_still.shape[0]):
        spans[o] = span(soft_still[o, 0], soft_still[o, 1], soft_still[o, 2], soft_still[o, 3])
    rest = np.empty(K + 1)
    inf32 = np.float32(np.inf)
    mark = 0
    for i in range(n):
        rest[K] = np.inf
        for j in range(K - 1, -1, -1):
            rest[j] = min(base[i, j], rest[j + 1])
            cost[i, j] = np.inf
        w, v = hx[i], hy[i]
        top = np.inf
        j, size, windows = 0, first, 0
        while j < K and rest[j] < np.inf and rest[j] <= top + slack:
            end = min(K, j + size)
            x0, y0, x1, y1 = inf32, inf32, -inf32, -inf32
            for q in range(j, end):
                if base[i, q] < np.inf:
                    x0, x1 = min(x0, cx[i, q]), max(x1, cx[i, q])
                    y0, y1 = min(y0, cy[i, q]), max(y1, cy[i, q])
            nh = 0
            for o in range(hm):
                g0, g1 = hard_moving[i, o, 0] - w, hard_moving[i, o, 1] - v
                g2, g3 = hard_moving[i, o, 2] + w, hard_moving[i, o, 3] + v
                if g0 < x1 and g2 > x0 and g1 < y1 and g3 > y0:
                    grown[nh, 0], grown[nh, 1], grown[nh, 2], grown[nh, 3] = g0, g1, g2, g3
                    nh += 1
            nl = 0
            for o in range(sm):
                g0, g1 = soft_moving[i, o, 4] - w, soft_moving[i, o, 5] - v
                g2, g3 = soft_moving[i, o, 6] + w, soft_moving[i, o, 7] + v
                if g0 < x1 and g2 > x0 and g1 < y1 and g3 > y0:
                    for a in range(4):
                        lines[nl, a] = soft_moving[i, o, a]
                    lines[nl, 4], lines[nl, 5], lines[nl, 6], lines[nl, 7] = g0, g1, g2, g3
                    lines[nl, 8] = span(lines[nl, 0], lines[nl, 1], lines[nl, 2], lines[nl, 3])
                    nl += 1
            for q in range(j, end):
                c = base[i, q]
                if not c <= top + slack:
                    continue
                X, Y = cx[i, q], cy[i, q]
                free = True
                for o in range(nh):
                    if X > grown[o, 0] and X < grown[o, 2] and Y > grown[o, 1] and Y < grown[o, 3]:
                        free = False
                        break
                mark += 1
                if not free or covers(hfirst, hmembers, hx0, hy0, hnx, hny, CELL, hseen, mark, hard_still, spans,
                                      X, Y, w, v, False) > 0.0:
                    continue
                c = c + line_cost * covers(sfirst, smembers, sx0, sy0, snx, sny, CELL, sseen, mark, soft_still, spans,
                                           X, Y, w, v, True)
                covered = 0.0
                for o in range(nl):
                    if X > lines[o, 4] and X < lines[o, 6] and Y > lines[o, 5] and Y < lines[o, 7]:
                        covered += clipped(lines[o, 0], lines[o, 1], lines[o, 2], lines[o, 3], lines[o, 8],
                                           X - w, Y - v, X + w, Y + v)
                c = c + line_cost * covered
                cost[i, q] = c
                top = min(top, c)
            j, windows = end, windows + 1
            if windows > 1:
                size *= 2
        best[i] = top


def _module() -> str:
    """The generated module: `clipped` inlined into the kernel `costs`, compiled with numba's disk cache."""
    return "\n".join([
        "# Generated by kinetostat.plans.label_kernel: the label placer's costs.",
        "import math", "import numba", "import numpy as np", "",
        f"CELL = {CELL!r}", f"MARGIN = {MARGIN!r}", "",
        *(f"{inspect.getsource(f)}\n{f.__name__} = numba.njit(error_model='numpy')({f.__name__})\n"
          for f in (span, clipped, cell_of, grid, covers)),
        inspect.getsource(costs), "kernel = numba.njit(nogil=True, error_model='numpy', cache=True)(costs)", ""])


_LOCK = threading.Lock()
_KERNEL: list = []


def kernel():
    """The compiled `costs` (loaded from the kernels' cache where an earlier process compiled it)."""
    with _LOCK:
        if not _KERNEL:
            _KERNEL.append(kernel_cache.load(_module()).kernel)
        return _KERNEL[0]
