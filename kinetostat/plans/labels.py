"""Lettering on a sheet over N crank angles: the width of a text as DejaVu Sans sets it (its
advance widths, `dejavu`), a point's letter with its subscript as SVG markup, coincident points
lettered once, and a placer that puts each label beside its point or vector at every angle at
once where it overprints no other label, arrowhead or point, as a draughtsman would.

Sheet coordinates: mm, x right, y down (SVG user units). A box is (x0, y0, x1, y1); boxes,
anchors and segments are arrays with a leading angle axis N, NaN where absent at an angle.

The placer takes labels in the order given (points first, then names of vectors) and, for all
angles at once, each label's candidate places about its anchor (rings of 16 directions, or
beside its segment): a candidate's cost is its distance from the anchor plus the length of drawn
lines it covers (each line clipped to the box, exactly); a candidate over a hard obstacle
(arrowhead, point, line end, a label placed before) or outside the bounds is not free. At every
angle the least cost is found (candidates tested lazily, cheapest first, until none left can
beat it); then the label keeps one place where it may: the candidate within `SLACK` of the best
at the most angles is taken at all of them, and so on for the angles left. Obstacles and
candidates the same at every angle are tested once for the cycle. A label that had to move far
gets a thin leader line from its anchor.

May use: numpy, the standard library, `.dejavu`, `kinetostat._text` (XML-safe text).
"""
from __future__ import annotations

import re
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from .._text import xml_escape as escape     # also control characters, which XML cannot hold
from .dejavu import ADVANCES, EM

__all__ = ["text_width", "label_parts", "label_markup", "label_width", "label_height", "coincident", "Placer",
           "Placed", "MIN_TEXT_MM", "ASCENT", "DESCENT"]

#: Smallest text on a sheet, mm (the texts' standard lettering: 2.5 mm and up).
MIN_TEXT_MM = 2.5
#: DejaVu Sans ascent and descent, em: the box getBBox gives a text.
ASCENT, DESCENT = 0.93, 0.24
#: A character DejaVu Sans lacks (set by the browser in another font): this wide, em.
_UNKNOWN_EM = 1.0


@lru_cache(maxsize=None)
def _advance(ch: str) -> float:
    """Advance width of one character, em (DejaVu Sans; _UNKNOWN_EM where it has no glyph)."""
    code = ord(ch)
    for start, adv in ADVANCES.items():
        if start <= code < start + len(adv) and adv[code - start]:
            return adv[code - start] / EM
    return _UNKNOWN_EM


def text_width(s: str, size: float) -> float:
    """Advance width of `s` at font size `size` (mm), DejaVu Sans (no kerning: at least the width
    the browser sets)."""
    return sum(map(_advance, s)) * size


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
    """Width of a lettered name (several names joined by ' ≡ ' allowed), mm."""
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


def label_markup(name: str, size: float) -> str:
    """The content of a lettered name's <text> at font size `size`: letters, subscript (a smaller
    tspan below), primes; coincident names joined by ' ≡ '."""
    out = []
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
    return "".join(out)


def coincident(xy: np.ndarray, tol: float = 0.5) -> np.ndarray:
    """Points lettered once where they coincide: xy (N, M, 2) -> owner (N, M) int, at each angle
    the index of the point whose label names point m ('B1 ≡ B11' at B1): the first point, in the
    order given, within `tol` mm of it that names itself; -1 where m is not finite."""
    n, m = xy.shape[:2]
    owner = np.full((n, m), -1)
    for j in range(m):                          # over points, every angle at once
        near = (owner[:, :j] == np.arange(j)) & (np.hypot(*(xy[:, :j] - xy[:, j:j + 1]).transpose(2, 0, 1)) <= tol)
        first = near.argmax(axis=1) if j else np.zeros(n, dtype=int)
        fin = np.isfinite(xy[:, j]).all(axis=1)
        owner[:, j] = np.where(near.any(axis=1), first, np.where(fin, j, -1))
    return owner


def _constant(a: np.ndarray) -> np.ndarray:
    a.flags.writeable = False
    return a


#: The candidate places of a label about its anchor: 16 directions (unit vectors, y down) from
#: 45 deg, on rings of these clearances (mm), at a cost of 1.2 per mm, 0.3 more below the anchor.
_DIRS = _constant(np.column_stack([np.cos(np.radians(np.arange(0, 360, 22.5) + 45.0)),
                                   -np.sin(np.radians(np.arange(0, 360, 22.5) + 45.0))]))
_ABS_DIRS = _constant(np.abs(_DIRS))
_REACH = _constant(_ABS_DIRS.max(axis=0))      # a label's half size times this: how far its box reaches
_RINGS = _constant(np.array([0.5, 1.2, 2.2, 3.5, 5.0, 7.0, 10.0, 14.0, 19.0, 25.0, 33.0, 45.0]))
_RING_COST = _constant((1.2 * _RINGS[:, None] + np.where(_DIRS[:, 1] > 0, 0.3, 0.0)).reshape(-1))
#: Beside a segment: at these fractions T of its length, on either side S, at these clearances R
#: (mm), each (42,); the cost's part for leaving the middle, 6 |T - 0.5| (times min(L, 20) / 20).
_ALONG = tuple(_constant(g.reshape(-1)) for g in np.meshgrid(
    (0.5, 0.38, 0.62, 0.25, 0.75, 0.15, 0.85), (1.0, -1.0), (0.6, 1.5, 3.0), indexing="ij"))
_ALONG_OFF = _constant(6.0 * np.abs(_ALONG[0] - 0.5))
#: A label keeps one place over the angles where that place costs at most this more than the best.
SLACK = 1.5
#: The cost of covering a drawn line, per mm of it inside the label's box.
LINE_COST = 0.6 / 0.7
#: Candidates tested at once (cheapest first).
_BATCH = 48
#: A label whose box is this far (mm) beyond its reach from the anchor gets a leader.
LEADER_MM = 6.0


@dataclass(frozen=True)
class Placed:
    """A label placed at N angles: baseline start `xy` (N, 2), its `box` (N, 4) and a leader
    (N, 4) from its anchor to the box where far (else NaN); NaN where it is not placed."""
    xy: np.ndarray
    box: np.ndarray
    leader: np.ndarray


def _overlap(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Whether boxes a and b overlap (broadcast, last axis 4); False where either is NaN."""
    return (a[..., 0] < b[..., 2]) & (a[..., 2] > b[..., 0]) & (a[..., 1] < b[..., 3]) & (a[..., 3] > b[..., 1])


def _clipped(seg: np.ndarray, box: np.ndarray) -> np.ndarray:
    """Length (mm) of each segment (x0, y0, x1, y1) strictly inside each box (broadcast, last axis
    4): the segment clipped to the box (Liang-Barsky; a segment parallel to a side divides by a
    signed zero: +-inf inside the slab or out of it, NaN on its edge); 0 where either is NaN."""
    p, d = seg[..., :2], seg[..., 2:] - seg[..., :2]
    with np.errstate(divide="ignore", invalid="ignore"):
        t0, t1 = (box[..., :2] - p) / d, (box[..., 2:] - p) / d
        t_in = np.maximum(np.minimum(t0, t1).max(axis=-1), 0.0)
        t_out = np.minimum(np.maximum(t0, t1).min(axis=-1), 1.0)
        length = (t_out - t_in) * np.hypot(d[..., 0], d[..., 1])
    return np.where(length > 0, length, 0.0)


def _bounds(items: np.ndarray) -> np.ndarray:
    """Bounding boxes (..., 4) of boxes or segments (..., 4)."""
    return np.concatenate([np.minimum(items[..., :2], items[..., 2:]), np.maximum(items[..., :2], items[..., 2:])],
                          axis=-1)


def _near(items: np.ndarray, bb: np.ndarray, region: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Of `items` (N, H, 4) (boxes, or segments) with their bounding boxes `bb`, at each angle
    those whose box meets `region` (N, 4), packed (N, m, 4), NaN-padded (m the most at any
    angle), and their bounding boxes."""
    near = (bb[..., 0] <= region[:, None, 2]) & (bb[..., 2] >= region[:, None, 0]) \
        & (bb[..., 1] <= region[:, None, 3]) & (bb[..., 3] >= region[:, None, 1])
    if len(items) == 1:
        return items[:, near[0]], bb[:, near[0]]
    rank = np.cumsum(near, axis=1) - 1
    r, j = np.nonzero(near)
    out = np.full((2, len(items), int(near.sum(axis=1).max(initial=0)), 4), np.nan)
    out[0, r, rank[r, j]] = items[r, j]
    out[1, r, rank[r, j]] = bb[r, j]
    return out[0], out[1]


class Placer:
    """Places labels at N angles inside `bounds` (a box) so that none overlaps another, a hard
    obstacle (arrowheads, points, line ends, the title block) or leaves the bounds; drawn lines
    (soft obstacles) are covered as little as may be."""

    PAD = 0.35        # clearance between a label and anything else, mm

    def __init__(self, n: int, bounds: tuple[float, float, float, float]):
        self.n = n
        self.bounds = bounds
        # ("hard", still) -> boxes grown by PAD (R, S, 4); ("soft", still) -> lines and their bounding
        # boxes (R, S, 8); R = 1 where still (the same at every angle), else N
        self._parts: dict[tuple[str, bool], list[np.ndarray]] = {}
        self._stacked: dict[tuple[str, bool], tuple[int, np.ndarray]] = {}     # parts stacked, their stack

    def block(self, box) -> None:
        """Hard obstacles at every angle: boxes (4,), (R, 4) or (R, S, 4), R = N or 1 (the same at
        every angle); NaN where absent."""
        self._add("hard", self._rows(box) + np.array([-self.PAD, -self.PAD, self.PAD, self.PAD]))

    def line(self, seg) -> None:
        """Soft obstacles: drawn lines (x0, y0, x1, y1), shaped as `block`'s boxes; NaN where absent."""
        rows = self._rows(seg)
        self._add("soft", np.concatenate([rows, _bounds(rows)], axis=-1))

    def _rows(self, a) -> np.ndarray:
        """Obstacles as (R, S, 4): R = 1 where the same at every angle (given so, or found so)."""
        a = np.asarray(a, dtype=float)
        a = a.reshape(1, 1, 4) if a.ndim == 1 else a[:, None] if a.ndim == 2 else a
        return a[:1] if len(a) > 1 and np.array_equal(a, np.broadcast_to(a[:1], a.shape), equal_nan=True) else a

    def _add(self, key: str, part: np.ndarray) -> None:
        self._parts.setdefault((key, len(part) == 1), []).append(part)

    def _stack(self, key: str, still: bool) -> np.ndarray:
        """The hard obstacles (grown by PAD) (R, H, 4), or the lines and their bounding boxes
        (R, H, 8), the same at every angle (still: R = 1) or not (R = N): those added since the
        last call appended."""
        parts = self._parts.get((key, still), [])
        rows = 1 if still else self.n
        done, stacked = self._stacked.get((key, still), (0, np.empty((rows, 0, 4 if key == "hard" else 8))))
        if done < len(parts):
            stacked = np.concatenate([stacked, *(np.broadcast_to(p, (rows,) + p.shape[1:]) for p in parts[done:])],
                                     axis=1)
            self._stacked[key, still] = (len(parts), stacked)
        return stacked

    def place(self, names: tuple[str, ...], variant: np.ndarray, size: float, anchor: np.ndarray,
              along: np.ndarray | None = None) -> Placed:
        """Place at each angle the name `names[variant[i]]` beside the point `anchor` (N, 2), or,
        where `along` (N, 2) is finite, beside the segment from anchor to along. Not placed where
        the anchor is NaN."""
        n = self.n
        widths = np.array([label_width(s, size) for s in names])
        heights = np.array([label_height(s, size) for s in names])
        w, (up, down) = widths[variant], heights[variant].T
        half = np.column_stack([w / 2, (up + down) / 2])                 # (N, 2)
        A = np.asarray(anchor, dtype=float)
        cands, base = [], []
        if along is None:
            along = np.full((n, 2), np.nan)
        d = along - A
        L = np.hypot(d[:, 0], d[:, 1])
        has = np.isfinite(L)
        beside = has & (L > 1e-9)
        with np.errstate(invalid="ignore", divide="ignore"):
            u = d / L[:, None]
        nrm = np.column_stack([-u[:, 1], u[:, 0]])
        T, S, R = _ALONG
        clear = R[None, :] + (np.abs(nrm) * half).sum(axis=1)[:, None]    # (N, 42)
        cands.append(A[:, None] + T[None, :, None] * d[:, None] + S[None, :, None] * nrm[:, None] * clear[..., None])
        base.append(np.where(beside[:, None], R[None, :] + _ALONG_OFF[None, :] * np.minimum(L, 20.0)[:, None] / 20.0,
                             np.inf))
        C = np.where(has[:, None], A + d / 2, A)                          # rings about the segment's middle
        ring = _RINGS[None, :, None] + (half @ _ABS_DIRS.T)[:, None, :]   # (N, 12, 16)
        cands.append((C[:, None, None] + _DIRS[None, None] * ring[..., None]).reshape(n, -1, 2))
        base.append(_RING_COST[None, :] + np.where(has, 2.0, 0.0)[:, None])
        centres = np.concatenate(cands, axis=1)                           # (N, K, 2)
        boxes = np.concatenate([centres - half[:, None], centres + half[:, None]], axis=2)
        bx0, by0, bx1, by1 = self.bounds
        outside = (boxes[..., 0] < bx0) | (boxes[..., 1] < by0) | (boxes[..., 2] > bx1) | (boxes[..., 3] > by1)
        base = np.where(outside, np.inf, np.concatenate(base, axis=1))
        base[~np.isfinite(A).all(axis=1)] = np.inf
        k = self._choose(boxes, base)
        at = np.arange(n)
        box = np.where((k >= 0)[:, None], boxes[at, np.maximum(k, 0)], np.nan)
        centre = (box[:, :2] + box[:, 2:]) / 2
        far = np.hypot(*(centre - C).T) - half @ _REACH > LEADER_MM
        foot = np.clip(C, box[:, :2], box[:, 2:])
        leader = np.where(far[:, None], np.concatenate([C, foot], axis=1), np.nan)
        self.block(box)
        return Placed(np.column_stack([box[:, 0], box[:, 1] + up]), box, leader)

    @classmethod
    def _costs(cls, b: np.ndarray, c: np.ndarray, hard: np.ndarray, soft: np.ndarray) -> np.ndarray:
        """Costs c (n', B) of boxes b (n', B, 4): inf where a box meets a hard obstacle (n', H, 4),
        plus LINE_COST per mm of the lines (n', L, 8: with their bounding boxes) inside it."""
        free = np.isfinite(c)
        if not free.any() or not (hard.shape[1] or soft.shape[1]):
            return c
        region = np.concatenate([np.where(free[..., None], b[..., :2], np.inf).min(axis=1),
                                 np.where(free[..., None], b[..., 2:], -np.inf).max(axis=1)], axis=1)
        ob, _ = _near(hard, hard, region)
        if ob.shape[1]:
            c = np.where(_overlap(b[:, :, None], ob[:, None]).any(axis=2), np.inf, c)
        ln, bb = _near(soft[..., :4], soft[..., 4:], region)
        if ln.shape[1]:                             # the lines each free box covers
            c = c + cls._covered(b, np.isfinite(c), ln, bb)
        return c

    @staticmethod
    def _covered(b: np.ndarray, which: np.ndarray, ln: np.ndarray, bb: np.ndarray) -> np.ndarray:
        """LINE_COST times the length of the lines `ln` (n', m, 4) (bounding boxes `bb`) inside
        each box b (n', B, 4) where `which` (n', B), else 0: each line clipped only to the boxes
        its bounds meet."""
        r, j = np.nonzero(which)
        fb, lb = b[r, j][:, None], bb[r]
        f, m = np.nonzero((lb[..., 0] < fb[..., 2]) & (lb[..., 2] > fb[..., 0])
                          & (lb[..., 1] < fb[..., 3]) & (lb[..., 3] > fb[..., 1]))
        out = np.zeros(which.shape)
        out[r, j] = LINE_COST * np.bincount(f, _clipped(ln[r[f], m], fb[f, 0]), len(r))
        return out

    def _choose(self, boxes: np.ndarray, base: np.ndarray) -> np.ndarray:
        """The candidate (N,) taken at each angle (-1: none, the anchor NaN): free candidates'
        costs found cheapest first at every angle until none left can come within SLACK of the
        best; then the candidate within SLACK of the best at the most angles is taken there, and
        so on; where none is free, the cheapest (nowhere free: the test tells)."""
        n, K = base.shape
        order = np.argsort(np.where(np.isfinite(base), base, 1e9).mean(axis=0), kind="stable")
        ordered = base[:, order]
        rest = np.minimum.accumulate(ordered[:, ::-1], axis=1)[:, ::-1]   # least base from j on
        cost = np.full((n, K), np.inf)
        best = np.full(n, np.inf)
        still = np.array_equal(boxes, np.broadcast_to(boxes[:1], boxes.shape), equal_nan=True) \
            and np.array_equal(base, np.broadcast_to(base[:1], base.shape))   # the same candidates at every angle
        slack = SLACK if n > 1 else 0.0                                    # one angle: nothing to keep
        for start in range(0, K, _BATCH):
            rows = np.nonzero(rest[:, start] <= best + slack)[0]
            if not len(rows):
                break
            idx = order[start:start + _BATCH]
            b = boxes[rows[:, None], idx]                                   # (n', B, 4)
            c = base[rows[:, None], idx]
            if still:                                                       # the still obstacles once
                c = np.broadcast_to(self._costs(b[:1], c[:1], self._stack("hard", True), self._stack("soft", True)),
                                    c.shape)
            else:
                c = self._costs(b, c, *(np.broadcast_to(a, (len(rows),) + a.shape[1:])
                                        for a in (self._stack("hard", True), self._stack("soft", True))))
            c = self._costs(b, c, self._stack("hard", False)[rows], self._stack("soft", False)[rows])
            cost[rows[:, None], idx] = c
            best[rows] = np.minimum(best[rows], c.min(axis=1))
        ok = cost <= best[:, None] + slack
        k = np.where(np.isfinite(base).any(axis=1), order[np.argmax(np.isfinite(ordered), axis=1)], -1)
        todo = np.isfinite(best)
        while todo.any():
            hit = ok & todo[:, None]
            count = hit.sum(axis=0)
            total = np.where(hit, cost, 0.0).sum(axis=0)
            j = np.lexsort((order.argsort(), total, -count))[0]          # most angles, then least cost
            sel = hit[:, j]
            k[sel] = j
            todo &= ~sel
        return k
