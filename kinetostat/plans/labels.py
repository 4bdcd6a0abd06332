"""Lettering on a sheet: the size of a text as the browser sets it (DejaVu Sans), the SVG of a
point's letter with its subscript, and a placer that puts each label beside its point or vector
where it overprints no other label, arrowhead, point or line end, as a draughtsman would.

Sheet coordinates: mm, x right, y down (SVG user units). A box is (x0, y0, x1, y1).

The placer is greedy: labels in the order given (points first, then names of vectors), each at
the candidate position of least cost (distance from its anchor, lines crossed) among those that
overlap nothing placed before; far from its anchor a label gets a thin leader line. Coincident
points are lettered once, "B1 ≡ B11" (`merge_coincident`).

May use: numpy, the standard library, `kinetostat._text` (XML-safe text).
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass

import numpy as np

from .._text import xml_escape as escape     # also control characters, which XML cannot hold

__all__ = ["text_width", "text_box", "label_parts", "label_svg", "label_width", "Placer", "Placed",
           "merge_coincident", "MIN_TEXT_MM", "ASCENT", "DESCENT"]

#: Smallest text on a sheet, mm (the texts' standard lettering: 2.5 mm and up).
MIN_TEXT_MM = 2.5
#: DejaVu Sans ascent and descent, em: the box getBBox gives a text.
ASCENT, DESCENT = 0.93, 0.24
_NARROW = set("iljtfrI.,:;'′|!()[] -")
_WIDE = set("mwMWЖШЩЮжшщюΣ≡→")


def text_width(s: str, size: float) -> float:
    """Advance width of `s` at font size `size` (mm), DejaVu Sans, slightly generous."""
    w = 0.0
    for ch in s:
        if ch in _NARROW:
            w += 0.36
        elif ch in _WIDE:
            w += 0.98
        elif ch.isupper():
            w += 0.76
        else:
            w += 0.65
    return w * size


def text_box(x: float, y: float, s: str, size: float, anchor: str = "start") -> tuple[float, float, float, float]:
    """Box of a one-line text at baseline (x, y)."""
    w = text_width(s, size)
    x0 = x - (w if anchor == "end" else w / 2 if anchor == "middle" else 0.0)
    return x0, y - ASCENT * size, x0 + w, y + DESCENT * size


_LABEL = re.compile(r"^([^\d_']*)([\d_]*)('*)$")


def label_parts(name: str) -> tuple[str, str, str]:
    """A point name as (letters, subscript, primes): 's2' -> ('s', '2', ''), 'S2_3' -> ('S', '2,3', ''),
    'pi' -> ('π', '', ''), "B'" -> ('B', '', '′'); 'R12t' -> ('R', '12', 't') is not split this
    way: a name with letters after its digits is written as it is; 'F_i2' -> ('F', 'i2', '')."""
    if name == "pi":
        return "π", "", ""
    m = _LABEL.match(name)
    if (not m or not m.group(1)) and "_" in name.strip("_"):
        head, _, sub = name.partition("_")
        return head, sub, ""
    if not m or not m.group(1):
        return name, "", ""
    return m.group(1), m.group(2).strip("_").replace("_", ","), "′" * len(m.group(3))


def _sub(size: float) -> float:
    return max(MIN_TEXT_MM, 0.75 * size)


def label_width(name: str, size: float) -> float:
    """Width of a lettered name (several names joined by ' ≡ ' allowed)."""
    w = 0.0
    for k, part in enumerate(name.split(" ≡ ")):
        head, sub, primes = label_parts(part)
        w += text_width(head, size) + text_width(sub, _sub(size)) + text_width(primes, size)
        if k:
            w += text_width(" ≡ ", size)
    return w


def label_height(name: str, size: float) -> tuple[float, float]:
    """(above, below) the baseline of a lettered name, mm."""
    below = DESCENT * size
    if any(label_parts(p)[1] for p in name.split(" ≡ ")):
        below = max(below, 0.3 * size + DESCENT * _sub(size))
    return ASCENT * size, below


def label_svg(x: float, y: float, name: str, size: float, cls: str = "label") -> str:
    """A lettered name at baseline (x, y): letters, subscript (a smaller tspan below), primes;
    coincident names joined by ' ≡ '."""
    out = [f'<text class="{cls}" x="{x:.2f}" y="{y:.2f}" font-size="{size:.2f}">']
    low = 0.0                                     # how far below the baseline the last tspan sits
    for k, part in enumerate(name.split(" ≡ ")):
        head, sub, primes = label_parts(part)
        for piece, dy, small in (((" ≡ " if k else ""), -low, False), (head, 0.0, False),
                                 (sub, 0.3 * size, True), (primes, -0.3 * size if sub else 0.0, False)):
            if not piece:
                continue
            attrs = f' font-size="{_sub(size):.2f}"' if small else ""
            attrs += f' dy="{dy:.2f}"' if dy else ""
            out.append(f"<tspan{attrs}>{escape(piece)}</tspan>")
            low += dy
    return "".join(out) + "</text>"


def merge_coincident(points: list[tuple[str, float, float]], tol: float = 0.5) -> list[tuple[str, float, float]]:
    """Points (name, x, y) within `tol` mm of one another lettered once: 'B1 ≡ B11' (names in
    the order given), at the first point."""
    out: list[list] = []
    for name, x, y in points:
        for group in out:
            if math.hypot(group[1] - x, group[2] - y) <= tol:
                group[0].append(name)
                break
        else:
            out.append([[name], x, y])
    return [(" ≡ ".join(names), x, y) for names, x, y in out]


def _constant(a: np.ndarray) -> np.ndarray:
    a.flags.writeable = False
    return a


#: The candidate places of a label about its anchor: 16 directions (unit vectors, y down) from
#: 45 deg, on rings of these clearances (mm), at a cost of 1.2 per mm, 0.3 more below the anchor.
_DIRS = _constant(np.column_stack([np.cos(np.radians(np.arange(0, 360, 22.5) + 45.0)),
                                   -np.sin(np.radians(np.arange(0, 360, 22.5) + 45.0))]))
_ABS_DIRS = _constant(np.abs(_DIRS))
_REACH = _constant(_ABS_DIRS.max(axis=0))      # a label's half size times this: how far its box reaches
_RINGS = _constant(np.array([0.5, 1.2, 2.2, 3.5, 5.0, 7.0, 10.0, 14.0, 19.0, 25.0, 33.0, 45.0])[:, None, None])
_RING_COST = _constant(1.2 * _RINGS[:, :, 0] + np.where(_DIRS[:, 1] > 0, 0.3, 0.0))
#: Beside a segment: at these fractions T of its length, on either side S, at these clearances R
#: (mm), each (42, 1); the cost's part for leaving the middle, 6 |T - 0.5| (times min(L, 20) / 20).
_ALONG = tuple(_constant(g.reshape(-1, 1)) for g in np.meshgrid(
    (0.5, 0.38, 0.62, 0.25, 0.75, 0.15, 0.85), (1.0, -1.0), (0.6, 1.5, 3.0), indexing="ij"))
_ALONG_OFF = _constant(6.0 * np.abs(_ALONG[0][:, 0] - 0.5))


@dataclass(frozen=True)
class Placed:
    """A placed label: baseline start (x, y), its box, and a leader from its anchor if far."""
    name: str
    x: float
    y: float
    size: float
    box: tuple[float, float, float, float]
    leader: tuple[float, float, float, float] | None


class Placer:
    """Places labels inside `bounds` (a box) so that none overlaps another, an obstacle box
    (arrowheads, points, line ends, the title block) or leaves the bounds; lines (soft
    obstacles) are crossed as little as may be."""

    PAD = 0.35        # clearance between a label and anything else, mm

    def __init__(self, bounds: tuple[float, float, float, float]):
        self.bounds = bounds
        self._boxes: list[tuple[float, float, float, float]] = []
        self._padded = np.empty((0, 4))                 # the first len(_padded) boxes, grown by PAD
        self._lines: list[tuple[float, float, float, float]] = []
        self._all_samples: np.ndarray | None = None    # the lines' samples, made once per change
        self._by_x: tuple[np.ndarray, np.ndarray] | None = None     # and sorted by x
        self.placed: list[Placed] = []

    def block(self, box) -> None:
        """A hard obstacle: nothing is placed over it."""
        self._boxes.append(tuple(float(v) for v in box))

    def _obstacles(self) -> np.ndarray:
        """Every hard obstacle's box grown by PAD on each side (N, 4); the boxes added since the
        last call appended."""
        if len(self._padded) < len(self._boxes):
            new = np.asarray(self._boxes[len(self._padded):]) + np.array([-self.PAD, -self.PAD, self.PAD, self.PAD])
            self._padded = np.concatenate([self._padded, new])
        return self._padded

    def line(self, x0: float, y0: float, x1: float, y1: float) -> None:
        """A soft obstacle: a drawn line, sampled every 0.7 mm (`_samples`)."""
        self._lines.append((x0, y0, x1, y1))
        self._all_samples = self._by_x = None

    def _samples(self) -> np.ndarray:
        """Every line's samples (M, 2), all lines at once: n = 1 + length / 0.7 mm (2 at least, a
        sheet's length at most) points from end to end, each line as np.linspace(0, 1, n) puts them."""
        if self._all_samples is None:
            x0, y0, x1, y1 = np.asarray(self._lines, float).reshape(-1, 4).T
            n = np.minimum(np.maximum(2.0, np.hypot(x1 - x0, y1 - y0) / 0.7 + 1), 1e4).astype(int)
            start = np.cumsum(n) - n                     # each line's first sample
            line = np.repeat(np.arange(len(n)), n)
            t = (np.arange(n.sum()) - start[line]) * (1.0 / (n - 1))[line]
            t[start + n - 1] = 1.0
            self._all_samples = np.column_stack([x0[line] + t * (x1 - x0)[line], y0[line] + t * (y1 - y0)[line]])
        return self._all_samples

    def _samples_by_x(self) -> tuple[np.ndarray, np.ndarray]:
        """`_samples` sorted by x, and their x: the samples over an x range are a slice."""
        if self._by_x is None:
            s = self._samples()
            s = s[np.argsort(s[:, 0])]
            self._by_x = s, np.ascontiguousarray(s[:, 0])
        return self._by_x

    def _best(self, boxes: np.ndarray, base: np.ndarray) -> int:
        """Index of the candidate box (K, 4) of least cost: `base` plus 0.6 per line sample inside
        it; inf where it overlaps a hard obstacle or leaves the bounds; the first of equal costs;
        0 where none is free. The candidates inside the bounds are tested in batches in order of
        `base`, against the obstacles and samples near the batch, until the next base exceeds the
        best cost found (a count only adds): the same choice as testing all."""
        bx0, by0, bx1, by1 = self.bounds
        out = ((boxes[:, :2] < (bx0, by0)) | (boxes[:, 2:] > (bx1, by1))).any(axis=1)
        cost = np.where(out, np.inf, base.astype(float))
        order = np.lexsort((np.arange(len(cost)), cost))
        ob = self._obstacles()
        o0, o1, o2, o3 = ob.T
        s_all, xs = self._samples_by_x() if self._lines else (None, None)
        best, k_best = math.inf, 0
        for start in range(0, len(order), 32):
            idx = order[start:start + 32]
            first = float(cost[idx[0]])
            if first == math.inf or first > best:
                break
            c, b = cost[idx], boxes[idx]
            (lo0, lo1), (hi0, hi1) = b[:, :2].min(axis=0).tolist(), b[:, 2:].max(axis=0).tolist()
            near = ob[(o2 > lo0) & (o0 < hi0) & (o3 > lo1) & (o1 < hi1)]
            keep = c <= best                            # free and not already beaten
            if len(near):
                keep &= ~((b[:, None, 0] < near[None, :, 2]) & (b[:, None, 2] > near[None, :, 0])
                          & (b[:, None, 1] < near[None, :, 3]) & (b[:, None, 3] > near[None, :, 1])).any(axis=1)
            if not keep.any():
                continue
            idx, c, b = idx[keep], c[keep], b[keep]
            if s_all is not None:                       # the samples strictly inside some box left
                (lo0, lo1), (hi0, hi1) = b[:, :2].min(axis=0).tolist(), b[:, 2:].max(axis=0).tolist()
                s = s_all[xs.searchsorted(lo0, "right"):xs.searchsorted(hi0, "left")]
                y = s[:, 1]
                s = s[(y > lo1) & (y < hi1)]
                if len(s):
                    inside = ((s[None, :, 0] > b[:, None, 0]) & (s[None, :, 0] < b[:, None, 2])
                              & (s[None, :, 1] > b[:, None, 1]) & (s[None, :, 1] < b[:, None, 3]))
                    c = c + 0.6 * inside.sum(axis=1)
            least = c.min()
            k = int(idx[c == least].min())
            if least < best or (least == best and k < k_best):
                best, k_best = float(least), k
        return k_best

    def _boxes_at(self, centres: np.ndarray, w: float, up: float, down: float) -> np.ndarray:
        """Boxes of a label whose box centre is at each of `centres` (K, 2)."""
        half = (w / 2, (up + down) / 2)
        return np.concatenate([centres - half, centres + half], axis=1)

    def place(self, name: str, size: float, ax: float, ay: float,
              along: tuple[float, float] | None = None) -> Placed:
        """Place `name` beside point (ax, ay), or beside the segment from (ax, ay) to `along`."""
        w = label_width(name, size)
        up, down = label_height(name, size)
        half = np.array([w / 2, (up + down) / 2])
        A = np.array([ax, ay])
        cands, base = [], []                        # blocks of candidate centres (K, 2) and costs (K,)
        if along is not None:
            d = np.array([along[0] - ax, along[1] - ay])
            L = float(np.hypot(*d))
            if L > 1e-9:
                u = d / L
                nrm = np.array([-u[1], u[0]])
                T, S, R = _ALONG
                cands.append(A + T * d + S * nrm * (R + abs(nrm) @ half))
                base.append(R[:, 0] + _ALONG_OFF * min(L, 20.0) / 20.0)
            ax, ay = (ax + along[0]) / 2, (ay + along[1]) / 2
            A = np.array([ax, ay])
        cands.append((A + _DIRS * (_RINGS + (_ABS_DIRS @ half)[:, None])).reshape(-1, 2))
        base.append((_RING_COST + (2.0 if along is not None else 0.0)).reshape(-1))
        cands_a = np.concatenate(cands)
        boxes = self._boxes_at(cands_a, w, up, down)
        k = self._best(boxes, np.concatenate(base))    # nowhere free: 0, the nearest place (the test tells)
        x0, y0, x1, y1 = boxes[k]
        box = (float(x0), float(y0), float(x1), float(y1))
        cx, cy = (x0 + x1) / 2, (y0 + y1) / 2
        leader = None
        if math.hypot(cx - ax, cy - ay) - float(_REACH @ half) > 6.0:
            qx, qy = min(max(ax, x0), x1), min(max(ay, y0), y1)
            leader = (ax, ay, float(qx), float(qy))
        pl = Placed(name, float(x0), float(y0 + up), size, box, leader)
        self.placed.append(pl)
        self._boxes.append(box)
        return pl
