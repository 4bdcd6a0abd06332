"""Lettering on a sheet over N crank angles: the width of a text as DejaVu Sans sets it (its
advance widths, `dejavu`), a symbol with its sub- and superscripts as SVG markup (split as
`symbols.runs` splits it), coincident points
lettered once, and a placer that puts each label beside its point or vector at every angle at
once where it overprints no other label, arrowhead or point, as a draughtsman would.

Sheet coordinates: mm, x right, y down (SVG user units). A box is (x0, y0, x1, y1); boxes,
anchors and segments are arrays with a leading angle axis N, NaN where absent at an angle.

The placer takes labels in the order given (points first, then names of vectors) and, for all
angles at once, each label's candidate places about its anchor (rings of 16 directions, or
beside its segment): a candidate's cost is its distance from the anchor plus the length of drawn
lines it covers (each line clipped to the box, exactly), of a heavy line (a link, a vector:
`Placer.line(..., heavy=True)`) HEAVY_COST a mm, so that a label goes round it, or away with a
leader, rather than over it; plus, where labels would crowd round a point (more than CROWD_FREE of
that point's labels within CROWD_MM of it), CROWD_COST for each in that zone, so that a later one
goes out on a leader to a clear place nearby, or along its line; a candidate over a hard obstacle
(arrowhead, point, line end, a label placed before) or outside the bounds is not free. At every
angle the least cost is found (candidates tested lazily, cheapest first, until none left can
beat it); then the label keeps its place from angle to angle unless it must move (hysteresis): of
the candidates within `SLACK` of the best at each angle, the run over the angles of least total
cost with MOVE_COST added for each move from one place to another (`_kept`). Over a page's many
angles this search runs at every `STRIDE`-th angle; an angle between keeps a searched
neighbour's place where that is free (and off every heavy line), and only the angles where
neither is are searched.
Obstacles and candidates the same at every angle are tested once for the cycle. A label that
had to move far from its anchor (not beside its own segment) gets a thin leader line from its
point (a vector's: from its middle), which later labels keep off as a drawn line.

May use: numpy, the standard library, `.dejavu`, `.symbols`, `kinetostat._text` (XML-safe text).
"""
from __future__ import annotations

import re
from dataclasses import dataclass
from functools import lru_cache
from typing import Callable

import numpy as np

from .._text import xml_escape as escape     # also control characters, which XML cannot hold
from .dejavu import ADVANCES, EM
from .symbols import SCRIPT, SUB, SUB_DROP, SUP, SUP_RISE, runs

__all__ = ["text_width", "markup", "label_markup", "label_width", "label_height", "coincident", "Placer",
           "Placed", "MIN_TEXT_MM", "MIN_SCRIPT_MM", "CAP", "ASCENT", "DESCENT"]

#: DejaVu Sans' capital height, em (its "H": 1493 / 2048).
CAP = 0.729
#: Smallest text on a sheet, font size in mm: its capitals 2.55 mm high, GOST 2.304's smallest
#: size 2.5 (a size is the capitals' height).
MIN_TEXT_MM = 3.5
#: Smallest sub- or superscript, font size in mm: capitals 1.8 mm, GOST 2.304's size for indices.
MIN_SCRIPT_MM = 2.5
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


def _script(size: float) -> float:
    """Font size of a sub- or superscript of a symbol set at `size`, mm."""
    return max(MIN_SCRIPT_MM, SCRIPT * size)


def _run_size(level: int, size: float) -> float:
    return _script(size) if level else size


#: Where a label joins names: coincident ones (' ≡ '), a name and its value (' = ': an arm's mm).
_JOIN = re.compile(r"( [≡=] )")


def _joined(name: str) -> list[tuple[str, str]]:
    """A label as (joint before, name) pairs: 'h_G3 ≡ h_Fp = 54,6' -> ('', 'h_G3'), (' ≡ ', 'h_Fp'), (' = ', '54,6')."""
    pieces = _JOIN.split(name)
    return list(zip([""] + pieces[1::2], pieces[0::2]))


def _label_runs(name: str) -> tuple[tuple[str, int], ...]:
    """A label's (text, level) runs: each name's by `symbols.runs`, the joints between them, a
    value after ' = ' as it is."""
    rs: list[tuple[str, int]] = []
    for joint, part in _joined(name):
        rs += ([(joint, 0)] if joint else []) + ([(part, 0)] if joint == " = " else list(runs(part)))
    return tuple(rs)


@lru_cache(maxsize=4096)
def label_width(name: str, size: float) -> float:
    """Width of a lettered name (several names joined by ' ≡ ', a value after ' = ' allowed) as
    `label_markup` sets it, mm."""
    return sum(text_width(t, _run_size(level, size)) for t, level in _label_runs(name))


@lru_cache(maxsize=4096)
def label_height(name: str, size: float) -> tuple[float, float]:
    """(above, below) the baseline of a lettered name as `label_markup` sets it, mm."""
    levels = {level for _, level in _label_runs(name)}
    above, below = ASCENT * size, DESCENT * size
    if SUP in levels:
        above = max(above, SUP_RISE * size + ASCENT * _script(size))
    if SUB in levels:
        below = max(below, SUB_DROP * size + DESCENT * _script(size))
    return above, below


def markup(rs: tuple[tuple[str, int], ...], size: float) -> str:
    """SVG content of (text, level) runs (`symbols`) in a <text> of font size `size`: a script a
    smaller tspan, dropped SUB_DROP or raised SUP_RISE of the size; the baseline back after it."""
    out, shift = [], 0.0                          # how far the last tspan sits from the baseline, down
    for t, level in rs:
        dy = {0: 0.0, SUB: SUB_DROP * size, SUP: -SUP_RISE * size}[level] - shift
        attrs = (f' font-size="{_script(size):.2f}"' if level else "") + (f' dy="{dy:.2f}"' if abs(dy) > 1e-9 else "")
        out.append(f"<tspan{attrs}>{escape(t)}</tspan>")
        shift += dy
    return "".join(out)


def label_markup(name: str, size: float) -> str:
    """The content of a lettered name's <text> at font size `size`: each symbol's runs (`symbols.runs`:
    base, subscript, superscript) by `markup`; coincident names joined by ' ≡ ', a value after ' = '."""
    return markup(_label_runs(name), size)


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
#: 45 deg, on rings of these clearances (mm), at a cost of 1.2 per mm, 0.3 more below the anchor
#: (the far rings for a label whose anchor lies at the edge of the room or beyond it).
_DIRS = _constant(np.column_stack([np.cos(np.radians(np.arange(0, 360, 22.5) + 45.0)),
                                   -np.sin(np.radians(np.arange(0, 360, 22.5) + 45.0))]))
_ABS_DIRS = _constant(np.abs(_DIRS))
_REACH = _constant(_ABS_DIRS.max(axis=0))      # a label's half size times this: how far its box reaches
_RINGS = _constant(np.array([0.5, 1.2, 2.2, 3.5, 5.0, 7.0, 10.0, 14.0, 19.0, 25.0, 33.0, 45.0, 60.0, 80.0, 105.0, 135.0]))
_RING_DIRS = _constant(np.tile(_DIRS, (len(_RINGS), 1)))       # each ring candidate's direction, ring by ring
_RING_COST = _constant((1.2 * _RINGS[:, None] + np.where(_DIRS[:, 1] > 0, 0.3, 0.0)).reshape(-1))
#: Beside a segment: at these fractions T of its length, on either side S, at these clearances R
#: (mm), each (42,); the cost's part for leaving the middle, 6 |T - 0.5| (times min(L, 20) / 20).
_ALONG = tuple(_constant(g.reshape(-1)) for g in np.meshgrid(
    (0.5, 0.38, 0.62, 0.25, 0.75, 0.15, 0.85), (1.0, -1.0), (0.6, 1.5, 3.0), indexing="ij"))
_ALONG_OFF = _constant(6.0 * np.abs(_ALONG[0] - 0.5))
#: Every candidate, beside the segment (the first 42), then on the rings (224): ring or not, and
#: T, S, R and the cost's part for leaving the middle (0 on a ring); direction, ring, cost (0 beside).
_CAND_RING = _constant(np.r_[np.zeros(len(_ALONG_OFF), bool), np.ones(len(_RING_COST), bool)])
_CAND_T, _CAND_S, _CAND_R, _CAND_OFF = (_constant(np.r_[a, np.zeros(len(_RING_COST))]) for a in (*_ALONG, _ALONG_OFF))
_CAND_DIR_T = _constant(np.r_[np.zeros((len(_ALONG_OFF), 2)), _RING_DIRS].T.copy())     # (2, K)
_CAND_ABS_DIR_T = _constant(np.abs(_CAND_DIR_T))
_CAND_RAD = _constant(np.r_[np.zeros(len(_ALONG_OFF)), np.repeat(_RINGS, len(_DIRS))])
_CAND_COST = _constant(np.r_[np.zeros(len(_ALONG_OFF)), _RING_COST])
#: A label keeps its place over the angles where that place costs at most this more than the best
#: there (as much as 21 mm further out); over many angles, that lets a page's delta coder reuse
#: its place (issue 34: triad_six_bar's page 336.9 -> 298.5 kB with its construction drawn).
SLACK = 25.0
#: What a label's move from its place at one angle to another at the next costs: more than any
#: slack, so that a label moves only where its place is not free or beyond SLACK of the best.
MOVE_COST = 4 * SLACK
#: The cost of covering a drawn line, per mm of it inside the label's box.
LINE_COST = 0.6 / 0.7
#: The cost of covering a heavy line (a link, a vector), per mm of it inside the label's box: as
#: much as moving the label 25 mm further out.
HEAVY_COST = 30.0
#: Candidates tested at once (cheapest first): this many (a point label's six nearest rings),
#: twice as many from the third batch on (fewer, larger batches: the same choice, less CPU).
_BATCH = 96
#: Over many angles a label's places are searched at every STRIDE-th angle; the angles between
#: keep a neighbour's place where it is free (`Placer._choose`).
STRIDE = 8
#: A label whose box is this far (mm) beyond its reach from the anchor gets a leader.
LEADER_MM = 6.0
#: Crowding round a point: the zone within CROWD_MM (mm) of a label's anchor holds CROWD_FREE labels
#: of that point (anchored within ONE_POINT_MM of it: a pin and the loads on it, a pole and its
#: vectors) free; a candidate whose centre lies in the zone costs CROWD_COST for each label of the
#: point there already and itself beyond, so that a later one goes out of the crowd on a leader.
ONE_POINT_MM, CROWD_MM, CROWD_FREE, CROWD_COST = 3.0, 15.0, 4, 15.0


@dataclass(frozen=True)
class Placed:
    """A label placed at N angles: baseline start `xy` (N, 2), its `box` (N, 4) and a leader
    (N, 4) from its anchor to the box where far (else NaN); NaN where it is not placed."""
    xy: np.ndarray
    box: np.ndarray
    leader: np.ndarray


def _clipped(seg: np.ndarray, box: np.ndarray) -> np.ndarray:
    """Length (mm) of each segment (x0, y0, x1, y1) strictly inside each box (broadcast, last axis
    4): the segment clipped to the box (Liang-Barsky; a segment parallel to a side divides by a
    signed zero: +-inf inside the slab or out of it, NaN on its edge); 0 where either is NaN."""
    x, y = seg[..., 0], seg[..., 1]
    dx, dy = seg[..., 2] - x, seg[..., 3] - y
    with np.errstate(divide="ignore", invalid="ignore"):
        tx0, tx1, ty0, ty1 = (box[..., 0] - x) / dx, (box[..., 2] - x) / dx, (box[..., 1] - y) / dy, (box[..., 3] - y) / dy
        t_in = np.maximum(np.maximum(np.minimum(tx0, tx1), np.minimum(ty0, ty1)), 0.0)
        t_out = np.minimum(np.minimum(np.maximum(tx0, tx1), np.maximum(ty0, ty1)), 1.0)
        length = (t_out - t_in) * np.hypot(dx, dy)
    return np.where(length > 0, length, 0.0)


def _bounds(items: np.ndarray) -> np.ndarray:
    """Bounding boxes (..., 4) of boxes or segments (..., 4)."""
    return np.concatenate([np.minimum(items[..., :2], items[..., 2:]), np.maximum(items[..., :2], items[..., 2:])],
                          axis=-1)


def _meets(bb: np.ndarray, region: tuple[np.ndarray, ...]) -> tuple[np.ndarray, np.ndarray]:
    """(row, item) of the items whose bounding boxes `bb` (4, R, H) (x0, y0, x1, y1; R = 1: the
    same at every row) meet `region` (x0, y0, x1, y1, each (n', 1)), row by row."""
    x0, y0, x1, y1 = region
    hit = bb[0] <= x1
    hit &= bb[2] >= x0
    hit &= bb[1] <= y1
    hit &= bb[3] >= y0
    return _nonzero(hit)


def _nonzero(mask: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """np.nonzero of a 2-D bool array, the same (row, column) in the same order (row by row), by
    its flat indices (np.nonzero of a 2-D array takes several times longer)."""
    return np.divmod(np.flatnonzero(mask), mask.shape[1])


def _any_by_row(inside: np.ndarray, counts: np.ndarray) -> np.ndarray:
    """Of the rows of `inside` (pairs, B) bool, taken `counts` (n',) at a time in order, whether any
    is True, column by column (n', B) (no rows: False); the columns' bytes ORed a word at a time."""
    word = next(w for w in (8, 4, 2, 1) if inside.shape[1] % w == 0)
    starts = np.cumsum(counts) - counts
    some = counts > 0
    out = np.zeros((len(counts), inside.shape[1]), dtype=bool)
    if some.any():
        out[some] = np.bitwise_or.reduceat(np.ascontiguousarray(inside).view(f"u{word}"), starts[some],
                                           axis=0).view(bool)
    return out


def _kept(cost: np.ndarray, move: float) -> np.ndarray:
    """The column taken at each row (angle) of `cost` (n, C) (inf: not to be taken; each row has a
    finite one): the run of least total cost plus `move` for each row whose column differs from
    the row's before (Viterbi; ties: the first column)."""
    n, m = cost.shape
    back = np.zeros((n, m), dtype=np.intp)
    total = cost[0].copy()
    for i in range(1, n):
        j = int(np.argmin(total))
        stay = total <= total[j] + move
        back[i] = np.where(stay, np.arange(m), j)
        total = np.where(stay, total, total[j] + move) + cost[i]
    path = np.empty(n, dtype=np.intp)
    path[-1] = int(np.argmin(total))
    for i in range(n - 1, 0, -1):
        path[i - 1] = back[i, path[i]]
    return path


class Placer:
    """Places labels at N angles inside `bounds` (a box) so that none overlaps another, a hard
    obstacle (arrowheads, points, line ends, the title block) or leaves the bounds; drawn lines
    (soft obstacles) are covered as little as may be."""

    PAD = 0.35        # clearance between a label and anything else, mm

    def __init__(self, n: int, bounds: tuple[float, float, float, float]):
        self.n = n
        self.bounds = bounds
        # ("hard", still) -> boxes grown by PAD (4, R, S); ("soft", still) -> lines and their bounding
        # costs a mm (LINE_COST, or HEAVY_COST: a heavy line) and bounding boxes (9, R, S); float32,
        # coordinate by coordinate; R = 1 where still (the same at every angle), else N
        self._parts: dict[tuple[str, bool], list[np.ndarray]] = {}
        self._stacked: dict[tuple[str, bool], tuple[int, np.ndarray]] = {}     # parts stacked, their stack
        self._anchors = np.empty((0, n, 2))                               # the labels placed: their anchors,
        self._centres = np.empty((0, n, 2), dtype=np.float32)           # their boxes' centres

    def block(self, box) -> None:
        """Hard obstacles at every angle: boxes (4,), (R, 4) or (R, S, 4), R = N or 1 (the same at
        every angle); NaN where absent."""
        self._add("hard", self._rows(box) + np.array([-self.PAD, -self.PAD, self.PAD, self.PAD]))

    def line(self, seg, heavy: bool = False) -> None:
        """Soft obstacles: drawn lines (x0, y0, x1, y1), shaped as `block`'s boxes; NaN where absent.
        `heavy`: links, vectors, costed at HEAVY_COST a mm, not LINE_COST."""
        rows = self._rows(seg)
        cost = np.full(rows.shape[:-1] + (1,), HEAVY_COST if heavy else LINE_COST)
        self._add("soft", np.concatenate([rows, cost, _bounds(rows)], axis=-1))

    def _rows(self, a) -> np.ndarray:
        """Obstacles as (R, S, 4): R = 1 where the same at every angle (given so, or found so)."""
        a = np.asarray(a, dtype=float)
        a = a.reshape(1, 1, 4) if a.ndim == 1 else a[:, None] if a.ndim == 2 else a
        return a[:1] if len(a) > 1 and np.array_equal(a, np.broadcast_to(a[:1], a.shape), equal_nan=True) else a

    def _add(self, key: str, part: np.ndarray) -> None:
        self._parts.setdefault((key, len(part) == 1), []).append(part.astype(np.float32).transpose(2, 0, 1))

    def _stack(self, key: str, still: bool) -> np.ndarray:
        """The hard obstacles (grown by PAD) (4, R, H), or the lines, their costs a mm and their
        bounding boxes (9, R, H), the same at every angle (still: R = 1) or not (R = N): those
        added since the last call appended."""
        parts = self._parts.get((key, still), [])
        done, stacked = self._stacked.get((key, still), (0, None))
        if done < len(parts) or stacked is None:
            rows = 1 if still else self.n
            if stacked is None:
                stacked = np.empty((4 if key == "hard" else 9, rows, 0), dtype=np.float32)
            stacked = np.concatenate([stacked, *(np.broadcast_to(p, p.shape[:1] + (rows,) + p.shape[2:])
                                                 for p in parts[done:])], axis=2)
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
        if along is None:
            along = np.full((n, 2), np.nan)
        d = along - A
        L = np.hypot(d[:, 0], d[:, 1])
        has = np.isfinite(L)
        beside = has & (L > 1e-9)
        with np.errstate(invalid="ignore", divide="ignore"):
            u = d / L[:, None]
        nrm = np.column_stack([-u[:, 1], u[:, 0]])
        C = np.where(has[:, None], A + d / 2, A)                          # rings about the segment's middle
        CT = np.ascontiguousarray(C.T)                                    # (2, N)
        fixed = np.isfinite(A).all(axis=1)
        bx0, by0, bx1, by1 = self.bounds
        # each text's ring candidates about the centre (2, texts x K); 0 beside the segment
        hv = np.column_stack([widths / 2, heights.sum(axis=1) / 2])
        reach = _CAND_RAD + (hv[:, :1] * _CAND_ABS_DIR_T[0] + hv[:, 1:] * _CAND_ABS_DIR_T[1])           # (texts, K)
        ring_off = (_CAND_DIR_T[:, None] * reach).reshape(2, -1)
        K = len(_CAND_RING)
        ring_extra = np.where(has, 2.0, 0.0)

        def geometry(rows: np.ndarray, cols: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
            """Centres (2, r, m) and least costs (r, m) of the candidates `cols` (r, m), or (1, m)
            at every angle, at the angles `rows` (r,): beside the segment (`_ALONG`; a label with
            no segment: none, their centre the anchor's), then on the rings (`_RINGS`)."""
            hx, hy = half[rows, :1], half[rows, 1:]                                               # (r, 1)
            xy = CT[:, rows, None] + np.take(ring_off, variant[rows][:, None] * K + cols, axis=1)  # (2, r, m)
            ring = _CAND_RING[cols]
            base = np.where(ring, _CAND_COST[cols] + ring_extra[rows, None], np.inf)
            some = ~ring.all(axis=0)                                          # the columns beside the segment somewhere
            if has.any() and some.any():
                k, r_ring = cols[:, some], ring[:, some]
                n_r = nrm[rows][:, :, None]
                clear = _CAND_R[k] + (np.abs(n_r[:, 0]) * hx + np.abs(n_r[:, 1]) * hy)           # (r, m')
                at = A[rows][:, :, None] + _CAND_T[k][:, None] * d[rows][:, :, None] \
                    + _CAND_S[k][:, None] * n_r * clear[:, None]                                   # (r, 2, m')
                at = np.where(np.isfinite(at), at, C[rows][:, :, None])       # no centre beside no segment: never free
                xy[:, :, some] = np.where(r_ring, xy[:, :, some], np.moveaxis(at, 1, 0))
                base[:, some] = np.where(r_ring | ~beside[rows][:, None], base[:, some],
                                         _CAND_R[k] + _CAND_OFF[k] * np.minimum(L[rows], 20.0)[:, None] / 20.0)
            x, y = xy
            outside = (x < bx0 + hx) | (y < by0 + hy) | (x > bx1 - hx) | (y > by1 - hy)
            base[outside | ~fixed[rows][:, None]] = np.inf
            return xy, base

        still = n == 1 or bool(np.array_equal(A, np.broadcast_to(A[:1], A.shape), equal_nan=True)
                     and np.array_equal(d, np.broadcast_to(d[:1], d.shape), equal_nan=True)
                     and np.array_equal(half, np.broadcast_to(half[:1], half.shape)))
        with np.errstate(invalid="ignore"):
            k = self._choose(geometry, K, half.T.astype(np.float32), still, (A, self._crowded(A)), fixed)
            xy, _ = geometry(np.arange(n), np.maximum(k, 0)[:, None])
        c = np.where((k >= 0)[:, None], xy[:, :, 0].T, np.nan)
        box = np.concatenate([c - half, c + half], axis=1)
        ring = _CAND_RING[np.maximum(k, 0)]                              # beside its own segment: no leader
        far = ring & (np.hypot(*(c - C).T) - half @ _REACH > LEADER_MM)
        foot = np.clip(C, box[:, :2], box[:, 2:])
        leader = np.where(far[:, None], np.concatenate([C, foot], axis=1), np.nan)
        self.block(box)
        if far.any():
            self.line(leader)
        self._anchors = np.concatenate([self._anchors, A[None]])
        self._centres = np.concatenate([self._centres, c[None].astype(np.float32)])
        return Placed(np.column_stack([box[:, 0], box[:, 1] + up]), box, leader)

    def clear(self, box: np.ndarray) -> np.ndarray:
        """Whether each box (N, 4) is clear of every hard obstacle (arrowheads, points, line ends,
        labels placed) at its angle, (N,): meets none (not: keeps PAD from them, as a label placed
        does); False where the box is NaN."""
        box = np.asarray(box, dtype=float) + np.array([self.PAD, self.PAD, -self.PAD, -self.PAD])
        ok = np.isfinite(box).all(axis=1)
        centre = np.where(ok[:, None], (box[:, :2] + box[:, 2:]) / 2, 0.0)
        half = np.where(ok[:, None], (box[:, 2:] - box[:, :2]) / 2, 0.0)
        cost = self._costs(centre.T[:, :, None].astype(np.float32), half.T.astype(np.float32),
                           np.where(ok, 0.0, np.inf)[:, None], np.arange(self.n), (True, False), ("hard",))
        return np.isfinite(cost[:, 0])

    def _costs(self, p: np.ndarray, h: np.ndarray, c: np.ndarray, rows: np.ndarray, still: tuple[bool, ...],
               kinds: tuple[str, ...] = ("hard", "soft"), heavy: bool = False) -> np.ndarray:
        """Costs c (n', B) of the boxes centred at p (2, n', B), half size h (2, n'), at the angles
        `rows`: inf where a box meets a hard obstacle, plus LINE_COST per mm of the lines inside
        it (HEAVY_COST per mm of a heavy one); of the obstacles the same at every angle (`still`
        holds True) and of those that move (False); `kinds` ("hard",): whether free only, the
        lines not costed; `heavy`: the heavy lines costed only."""
        stacks = [(key, fixed, items) for key in kinds for fixed in still
                  for items in (self._stack(key, fixed),) if items.shape[2]]
        free = np.isfinite(c)
        if not stacks or not free.any():
            return c
        (px, py), (hx, hy) = p, h
        region = ((px.min(axis=1) - hx)[:, None], (py.min(axis=1) - hy)[:, None],
                  (px.max(axis=1) + hx)[:, None], (py.max(axis=1) + hy)[:, None])
        blocked = np.zeros(c.shape, dtype=bool)
        pairs = []
        for key, fixed, items in stacks:                                   # the hard ones first
            r, j = _meets(items[-4:] if fixed else np.take(items[-4:], rows, axis=1), region)
            if not len(r):
                continue
            at = j if fixed else rows[r] * items.shape[2] + j
            items = np.take(items.reshape(len(items), -1), at, axis=1)   # (4 or 9, pairs)
            counts = np.bincount(r, minlength=len(c))                     # r ascending: each row's pairs together
            X, Y, w, v = (np.repeat(a, counts, axis=0) for a in (px, py, hx, hy))
            inside = X > (items[-4] - w)[:, None]                         # a box over it: its centre in it grown by h
            inside &= X < (items[-2] + w)[:, None]
            inside &= Y > (items[-3] - v)[:, None]
            inside &= Y < (items[-1] + v)[:, None]                        # (pairs, B)
            if key == "hard":
                blocked |= _any_by_row(inside, counts)
            else:
                inside &= np.repeat(free & ~blocked, counts, axis=0)
                if heavy:
                    inside &= (items[4] == HEAVY_COST)[:, None]
                f, q = _nonzero(inside)
                pairs.append((r[f], q, np.take(items[:5], f, axis=1)))
        c = np.where(blocked, np.inf, c)
        for r, q, ln in pairs:                                             # the lines each free box covers
            x, y, w, v = px[r, q], py[r, q], hx[r], hy[r]
            covered = _clipped(ln[:4].T, np.stack([x - w, y - v, x + w, y + v], axis=-1)) * ln[4]
            c = c + np.bincount(r * c.shape[1] + q, covered, c.size).reshape(c.shape)
        return c

    def _crowded(self, anchor: np.ndarray) -> np.ndarray:
        """What a candidate in the zone of the point `anchor` (N, 2) costs at each angle (N,): CROWD_COST
        for each label of the point (anchored within ONE_POINT_MM of it) in the zone (its centre
        within CROWD_MM of it), and the new one, beyond CROWD_FREE."""
        with np.errstate(invalid="ignore"):
            same = np.hypot(*(self._anchors - anchor).transpose(2, 0, 1)) <= ONE_POINT_MM       # (L, N)
            near = np.hypot(*(self._centres - anchor).transpose(2, 0, 1)) <= CROWD_MM
        return CROWD_COST * np.maximum((same & near).sum(axis=0) + 1 - CROWD_FREE, 0)

    @staticmethod
    def _crowding(p: np.ndarray, rows: np.ndarray, zone: tuple[np.ndarray, np.ndarray]) -> np.ndarray:
        """The crowding cost (n', B) of the boxes centred at p (2, n', B) at the angles `rows`: the
        zone's (`_crowded`: its point (N, 2) and cost (N,)) where the centre lies in it."""
        (x, y), cost = zone[0][rows].T, zone[1][rows]
        inside = (p[0] - x[:, None]) ** 2 + (p[1] - y[:, None]) ** 2 <= CROWD_MM ** 2
        return np.where(inside, cost[:, None], 0.0)

    def _choose(self, geometry: Callable, K: int, half: np.ndarray, still: bool,
                zone: tuple[np.ndarray, np.ndarray] | None = None, anchored: np.ndarray | None = None) -> np.ndarray:
        """The candidate (N,) taken at each angle (-1: none, the anchor NaN) of the K candidates
        `geometry(rows, cols)` gives (their centres (2, r, m) and least costs (r, m) at the angles
        `rows` (r,), candidates `cols` (r, m) or (1, m)), half size `half` (2, N); `still`: the same
        candidates at every angle; `zone`: the label's point (N, 2) and what a candidate in its zone
        costs (N,) (`_crowded`; None: nothing); `anchored` (N,): the angles where the label has an
        anchor (None: every angle; elsewhere no candidate is free: -1 there, not searched). Over many
        angles (N >= 2 STRIDE) a label keeps its place from angle to angle unless it must move: the
        places are searched (`_search`) at every STRIDE-th angle (and the last); an angle between
        keeps the place of the searched angle before it, else of the one after it, where that place
        is free there (off every hard obstacle and every heavy line, and in the bounds); the angles
        where neither is are searched. An angle's choice is the same with or without the angles
        not anchored beside it in a search (no candidate of theirs counts)."""
        n = self.n
        zone = (np.zeros((n, 2)), np.zeros(n)) if zone is None else zone
        anchored = np.ones(n, dtype=bool) if anchored is None else anchored
        k = np.full(n, -1)
        if n < 2 * STRIDE:
            at = np.flatnonzero(anchored)
            k[at] = self._search(geometry, K, half, still, at, zone)
            return k
        done = np.zeros(n, dtype=bool)                              # searched, or a neighbour's place kept
        done[::STRIDE] = done[-1] = True
        sample = np.flatnonzero(done)
        at = sample[anchored[sample]]
        k[at] = self._search(geometry, K, half, still, at, zone)
        between = np.flatnonzero(~done & anchored)
        near = np.searchsorted(sample, between)
        guess = np.column_stack([k[sample[near - 1]], k[sample[near]]])    # the searched angle before, then after
        xy, base = geometry(between, np.maximum(guess, 0))
        free = self._costs(xy.astype(np.float32), half[:, between], base, between, (True, False),
                           heavy=True) <= base                  # free, and over no heavy line
        free &= np.isfinite(base)
        free &= guess >= 0
        first = np.argmax(free, axis=1)
        kept = free.any(axis=1)
        k[between[kept]] = guess[kept, first[kept]]
        at = between[~kept]
        k[at] = self._search(geometry, K, half, still, at, zone)
        return k

    def _search(self, geometry: Callable, K: int, half: np.ndarray, still: bool, at: np.ndarray,
                zone: tuple[np.ndarray, np.ndarray]) -> np.ndarray:
        """The candidate (len(at),) taken at each of the angles `at` (indices; -1: none), as
        `_choose`'s arguments give them (`zone`: its crowding). Free candidates' costs, with their
        crowding (`_crowding`), found in batches, in the order of their mean base where finite, at
        every angle until none left there can come within SLACK of the best; then of the
        candidates within SLACK of the best, the run over the angles in order that `_kept` takes
        (MOVE_COST a move; one angle: the cheapest); where none is free, the cheapest (nowhere
        free: the test tells)."""
        if not len(at):
            return np.full(0, -1)
        centres, base = geometry(at, np.arange(K)[None])
        centres = centres.astype(np.float32)
        n = len(at)
        fin = np.isfinite(base)
        with np.errstate(invalid="ignore"):                                # by the mean where finite; nowhere: last
            typical = np.where(fin, base, 0.0).sum(axis=0) / fin.sum(axis=0)
        order = np.argsort(np.where(np.isnan(typical), np.inf, typical), kind="stable")
        ordered = base[:, order]
        best = np.full(n, np.inf)
        slack = SLACK if n > 1 else 0.0                                    # one angle: nothing to keep
        tested = []
        start, size = 0, _BATCH
        while start < K:
            rest = ordered[:, start:].min(axis=1)                          # the least base left
            local = np.flatnonzero(np.isfinite(rest) & (rest <= best + slack))
            if not len(local):
                break
            rows = at[local]
            idx = order[start:start + size]
            c = ordered[local, start:start + size]
            if still and len(rows) > 1:                                     # the still obstacles once
                p, h = centres[:, :1, idx], half[:, rows[:1]]
                c = self._costs(p, h, c[:1], rows[:1], (True,))
                p = np.broadcast_to(p, (2,) + (len(rows), len(idx)))
                c = self._costs(p, np.broadcast_to(h, (2, len(rows))), np.broadcast_to(c, (len(rows), len(idx))),
                                rows, (False,))
            else:
                p = np.take(centres.reshape(2, -1), local[:, None] * K + idx, axis=1)    # (2, rows, batch)
                c = self._costs(p, half[:, rows], c, rows, (True, False))
            if zone[1][rows].any():
                c = c + self._crowding(p, rows, zone)
            cost = np.full((n, len(idx)), np.inf)
            cost[local] = c
            tested.append(cost)
            best[local] = np.minimum(best[local], c.min(axis=1))
            start, size = start + size, size * (2 if len(tested) > 1 else 1)
        cost = np.concatenate(tested, axis=1) if tested else np.full((n, 0), np.inf)    # of order[:start]
        ok = (cost <= best[:, None] + slack) & np.isfinite(cost)
        cols = np.flatnonzero(ok.any(axis=0))                              # within SLACK somewhere
        k = np.where(fin.any(axis=1), order[np.argmax(np.isfinite(ordered), axis=1)], -1)
        todo = np.isfinite(best)
        if todo.any():
            k[todo] = order[cols[_kept(np.where(ok, cost, np.inf)[todo][:, cols], MOVE_COST)]]
        return k
