"""The interactive page of a mechanism (issue 27): one self-contained, offline HTML file with an
angle slider over every plan, the force plans stepped through in the texts' order, a check of a
student's measured lengths at the scales he drew at, and print at true scale.

    >>> import kinetostat
    >>> from kinetostat.plans.page import page
    >>> html = page(kinetostat.load("ice_crank_slider"), lang="uk")      # doctest: +SKIP

Key mode (default): one analysis at every whole degree, the design position and the check's
angle; from it each plan of the cycle (`build_cycle`, every scale fixed for the whole cycle:
`cycle_scales`; the plan of positions' 12 positions and paths made once: `fixed_positions`) and
its sheet over all the angles as arrays (`draw.drawing`, with the page contract and each angle's
notes, their numbers as tokens page.js writes from the lengths and values the page holds: `_amounts`);
the worksheet's values of every angle
(`worksheet_cycle`); "Next step". Student mode (`student=True`): no answer in the page: the data,
the empty tables, an A3 sheet with a millimetre grid at true scale, and the check of typed lengths.
A page is drawn anew every time: nothing is cached.

Small: each sheet's arrays (`encode_drawing`): the elements' markup once (tag, attributes,
tooltip, the texts a label takes; texts with φ at every angle as their common start and end and
the angles once: `_shared_texts`), and as integers, element by element over the angles, whether it
is drawn, which text it shows, its coordinates and a segment's length as `Element.svg` rounds them
(COORD_DECIMALS, LENGTH_DECIMALS), each series as differences over the angle of the order that
suits it, as its jumps (`_jumps`: a label), as its least-squares prediction's misses (`_smooth`: a
length), as an earlier series of the sheet (moved by a constant), or less a multiple of an earlier
length (`_proportionals`: a velocity on its plan and on the lever; a value of the worksheet, its
vector's length times the scale), or a coordinate less the earlier series it follows most
closely (`_Earlier`: a label less its point), zigzag varints, deflated and written as text, 7 bits a
character (`_text7`); the worksheet's rows and the check's items in the blobs too.
The page's script (vanilla JavaScript, the browser's own DecompressionStream; without its comments,
`_bare`; deflated in blob "js", `_UNPACK` runs it) decodes them once, writes the check's rows, and writes the sheet of the angle chosen as
`Drawing.svg` writes it.
The page contract (the README): `<input type="range" id="phi">`; every segment's element
`data-plan`, `data-segment`, `data-length-mm` as in segments.csv (to 1e-9 mm); every value cell
`data-symbol`, `data-value`; `body[data-ready]`.
Print (`_CSS`): a first page with the title, the angle, the scales, the data and (key) the values
of that angle, or (student) the tables to fill in; then each sheet a page at true scale, A3 or (key,
A4 chosen) A4 around the plan with the title line and the notes on top (page.js `a4Title`).

May use: the plans (`build_cycle`, `cycle_scales`, `core`, `draw`, `forces`, `worksheet`
(`worksheet_cycle`), `solution` (the page's one analysis), `drawing_error`, `pack`, `labels`, `i18n`), `lettering`, `_io`,
`kinetostat._text` (`script_json`: the data block's JSON), numpy, the standard library. Never
matplotlib, never the harness; the solver only through `solution.solve` (the page's one
analysis).
"""
from __future__ import annotations

import base64
import json
import math
import os
import re
import warnings
import zlib
from collections.abc import Sequence
from html import escape
from importlib import resources
from pathlib import Path

import numpy as np

from .._io import write_text
from .._text import script_json, xml_escape
from .core import ELEMENTS, PAGE_DECIMALS, UNMEASURED, Drawing, PlanCycle
from .draw import RESULT, TINY_MM, TOKEN, segment_label, title_of
from .i18n import check_lang, num, text, unit
from .solution import Solution, solve

__all__ = ["page", "page_angles", "write_page", "encode_drawing", "PAGE_ANGLES", "TOLERANCE_PCT", "COORD_DECIMALS", "LENGTH_DECIMALS"]

#: The angles of the slider, deg (the design position is one more frame).
PAGE_ANGLES = tuple(float(a) for a in range(360))
#: The texts' rule for the two balancing moments (crank and lever), %.
TOLERANCE_PCT = 5.0
#: Decimals of a sheet's coordinates (mm) and of a segment's length (data-length-mm) in the page
#: (`core.PAGE_DECIMALS`; each rint(10^d x), `core.fixed`, as `Drawing.svg(i, *PAGE_DECIMALS)`).
COORD_DECIMALS, LENGTH_DECIMALS = PAGE_DECIMALS
#: Decimals of the check's exact lengths and bands (mm; a drawing is read to 0.1 mm).
CHECK_DECIMALS = 4
#: Significant digits of the worksheet's values in the page (of each value's largest |value| over
#: the cycle): the tables show 4; the files (worksheet.csv, cycle.csv) hold 12.
VALUE_DIGITS = 9

# ============================================================================ the numbers, small

def _varints(values: np.ndarray) -> bytes:
    """Zigzag LEB128 varints of int64 values (|v| < 2^53), vectorised."""
    v = np.asarray(values, dtype=np.int64).ravel()
    z = np.where(v >= 0, 2 * v, -2 * v - 1).astype(np.uint64)
    size = np.ones(len(z), dtype=np.int64)
    for k in range(1, 8):
        size += z >= np.uint64(1 << (7 * k))
    at = np.cumsum(size) - size
    out = np.zeros(int(size.sum()), dtype=np.uint8)
    for k in range(int(size.max(initial=1))):
        has = size > k
        byte = (z[has] >> np.uint64(7 * k)) & np.uint64(127)
        more = (size[has] > k + 1).astype(np.uint64) << np.uint64(7)
        out[at[has] + k] = (byte | more).astype(np.uint8)
    return out.tobytes()


#: Highest order of differences a series is stored as (`_serieses`); MAX_ORDER + 1: as `_jumps`;
#: MAX_ORDER + 2: as `_smooth`.
MAX_ORDER = 4
#: `_smooth`'s weights: of the last 24 values, the one next on the least-squares polynomial of
#: degree 8 through them.
SMOOTH = np.linalg.pinv(np.vander(np.arange(-24.0, 0.0), 9))[-1]
#: The smallest series (units of its last digit) `_smooth` is tried on: lengths and values.
SMOOTH_FROM = 10 ** 5
#: A step of a series whose slope changes by more than this (units of its last digit) is a jump
#: (`_jumps`: a label moved to another place).
JUMP = 3


def _last(mask: np.ndarray) -> np.ndarray:
    """Along each row of `mask` (m, n), the index of the last True at or before each column (-1: none)."""
    return np.maximum.accumulate(np.where(mask, np.arange(mask.shape[1]), -1), axis=1)


def _jumps(x: np.ndarray) -> np.ndarray:
    """Rows of int64 series (m, n) as their first value and, step by step, the step less the
    slope: the last step that was not a jump (0 at first), a jump a step that differs from the
    step before by more than JUMP. A label moving with its point costs the rounding's few units,
    and a jump to another place and back one number each (page.js `unjump` takes it back)."""
    m, n = x.shape
    d = np.zeros_like(x)
    d[:, 1:] = np.diff(x, axis=1)
    steady = np.ones((m, n), dtype=bool)
    steady[:, 0] = False
    steady[:, 2:] = np.abs(d[:, 2:] - d[:, 1:-1]) <= JUMP
    last = _last(steady)
    s = np.zeros_like(x)
    s[:, 1:] = np.where(last[:, :-1] >= 1, d[np.arange(m)[:, None], np.maximum(last[:, :-1], 0)], 0)
    out = d - s
    out[:, 0] = x[:, 0]
    return out


def _smooth(x: np.ndarray) -> np.ndarray:
    """Rows of int64 series (m, n) as each value less its prediction: floor(p + 0.5) of p = SMOOTH
    · the last len(SMOOTH) values (summed in order: page.js `unsmooth` the same in doubles) where
    that predicted the value before at least as well as 2 x[i-1] - x[i-2] did, else the latter
    (x[0] before the second, 0 before the first): a length to 1e-6 mm, smooth over the angles but
    for a kink here and there, costs a unit or two a value."""
    m, n = x.shape
    K = len(SMOOTH)
    line = np.zeros_like(x)
    line[:, 1:2] = x[:, :1]
    line[:, 2:] = 2 * x[:, 1:-1] - x[:, :-2]
    if n <= K + 1:
        return x - line
    acc = np.zeros((m, n - K))
    for k in range(K):
        acc = acc + SMOOTH[k] * x[:, k:n - K + k]
    fit = line.copy()
    fit[:, K:] = np.floor(acc + 0.5).astype(np.int64)
    better = np.zeros((m, n), dtype=bool)
    better[:, K + 1:] = np.abs(x - fit)[:, K:-1] <= np.abs(x - line)[:, K:-1]
    return x - np.where(better, fit, line)


def _serieses(arrays: Sequence[np.ndarray]) -> list[np.ndarray]:
    """Each of `arrays` (int64 series) as its order k (0..MAX_ORDER) followed by its k-th
    differences, each difference keeping the first value (a - [0, a[:-1]]), or as MAX_ORDER + 1
    followed by `_jumps`, or (SMOOTH_FROM units or more) as MAX_ORDER + 2 followed by `_smooth`:
    the one whose numbers are smallest (a sum of their bits), so that a smooth function of the
    angle becomes a few small numbers; the page's script takes k prefix sums. Those of one length
    at once."""
    out: list[np.ndarray] = [np.empty(0, dtype=np.int64)] * len(arrays)
    by_size: dict[int, list[int]] = {}
    for i, a in enumerate(arrays):
        by_size.setdefault(np.size(a), []).append(i)
    for idx in by_size.values():
        d = [np.stack([np.asarray(arrays[i], dtype=np.int64).ravel() for i in idx])]
        for _ in range(MAX_ORDER):
            d.append(np.diff(d[-1], axis=1, prepend=0))
        d.append(_jumps(d[0]))
        large = np.abs(d[0]).max(axis=1) >= SMOOTH_FROM
        d.append(d[0].copy())
        if large.any():
            d[-1][large] = _smooth(d[0][large])
        costs = np.stack([_bits(x) for x in d])                   # (order, series)
        costs[-1, ~large] = np.inf
        order = np.argmin(costs, axis=0)
        for j, i in enumerate(idx):
            out[i] = np.concatenate([[order[j]], d[order[j]][j]])
    return out


def _bits(d: np.ndarray) -> np.ndarray:
    """What series of integers cost as varints, roughly: the sum of their bits along the last
    axis (in float32: half the memory of doubles, and as good a guess)."""
    return np.log2(1 + np.abs(d).astype(np.float32)).sum(axis=-1)


def _cost(d: np.ndarray) -> float:
    """What a series of integers costs as varints, roughly: the sum of their bits (`_bits`)."""
    return float(_bits(d))


def _scaled(source: np.ndarray, f: float) -> np.ndarray:
    """floor(f source + 0.5), int64: what the page's script computes from an earlier series
    (page.js `plus`; one product and one sum in doubles, the same in both)."""
    return np.floor(source.astype(np.float64) * f + 0.5).astype(np.int64)


def _proportionals(qs: Sequence[np.ndarray], pool: Sequence[np.ndarray],
                   limits: Sequence[int], shown: Sequence[np.ndarray] | None = None) -> list[tuple[int, float] | None]:
    """For each series qs[i] (int64), the series of pool[:limits[i]] of which it is most nearly a
    multiple, (its index, the factor f), where q - `_scaled`(source, f) costs less than q
    (`_serieses`); None where none does (no source as long as q and, where q > 0, positive). A
    segment drawn on two plans at two scales (a velocity on its plan and on the lever), a value
    the length of its vector times the plan's scale: their remainders are a few units of the last
    digit. `shown` (each (N,) bool): compared only where qs[i] is read, the rest of it taken as
    the multiple (`_filled`: a construction line of a triad drawn in one order of its sides,
    whose length is its vector's)."""
    by_size: dict[int, list[int]] = {}
    for g, s in enumerate(pool):
        by_size.setdefault(len(s), []).append(g)
    stacks = {}
    for n, gs in by_size.items():
        stack = np.stack([pool[g] for g in gs]).astype(np.float64)
        stacks[n] = (np.asarray(gs), stack, (stack.min(axis=1) >= 0), (stack <= 0).astype(np.float64))
    picks: list[tuple[int, int, float]] = []                     # (i, g, f)
    for i, q in enumerate(qs):
        on = q > 0 if shown is None else (q > 0) & shown[i]
        if len(q) < 2 or on.sum() < 2 or len(q) not in stacks:
            continue
        index, stack, nonneg, off = stacks[len(q)]
        usable = np.flatnonzero((index < limits[i]) & nonneg & (off @ on == 0))     # positive wherever q is
        if len(usable):
            ratio = q[on] / stack[usable][:, on]
            g = int(np.argmin((ratio.max(axis=1) - ratio.min(axis=1)) / ratio.mean(axis=1)))
            picks.append((i, int(index[usable[g]]), float(f"{np.median(ratio[g]):.10g}")))   # 10 digits: the page's JSON short
    coded = _serieses([x for i, g, f in picks
                       for x in (_filled(qs[i], pool[g], f, None if shown is None else shown[i]) - _scaled(pool[g], f), qs[i])])
    out: list[tuple[int, float] | None] = [None] * len(qs)
    for n, (i, g, f) in enumerate(picks):
        if _cost(coded[2 * n][1:]) < _cost(coded[2 * n + 1][1:]):
            out[i] = (g, f)
    return out


def _filled(q: np.ndarray, source: np.ndarray, f: float, shown: np.ndarray | None) -> np.ndarray:
    """q where `shown`, elsewhere `_scaled`(source, f) (None: q everywhere): q with what is not read
    the multiple."""
    return q if shown is None else np.where(shown, q, _scaled(source, f))


def _held(x: np.ndarray, drawn: np.ndarray) -> np.ndarray:
    """`x` (N, ...) with each row where not `drawn` the last drawn row before it (the first drawn
    before the first): a series that pauses instead of jumping, zeros where never drawn."""
    if not drawn.any():
        return np.zeros_like(x)
    idx = np.where(drawn, np.arange(len(drawn)), -1)
    idx = np.maximum.accumulate(idx)
    idx[idx < 0] = int(np.argmax(drawn))
    return x[idx]


def _ints(x: np.ndarray, decimals: int) -> np.ndarray:
    """`x` as `Element.svg` rounds it: rint(10^decimals x), int64 (NaN as 0)."""
    return np.rint(np.where(np.isfinite(x), x, 0.0) * 10.0 ** decimals).astype(np.int64)


def _shown(e) -> np.ndarray:
    """Where element `e`'s length is shown: finite, and the element drawn (lengths one a row)."""
    L = np.asarray(e.length_mm, dtype=float).reshape(-1)
    drawn = np.asarray(e.drawn()).reshape(-1)
    return np.isfinite(L) & (drawn if len(L) == len(drawn) else True)


#: A coordinate series is compared with the sheet's earlier ones at this many of its angles
#: (`_changes`), and stored less the most alike where that is smaller.
PROBES = 24
#: The most pairs of series `_changes` compares in one array operation (its count: this many bytes).
CHUNK = 1 << 22


def _changes(x: np.ndarray, care: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For the coordinate series of one sheet, rows of `x` (int64 (m, n)) read where `care` (bool
    (m, n)): (changes, probes): changes[i, j] (j < i) is in how many steps between the PROBES or so
    angles of `care[i]` series j's difference from series i changes (0: j plus a constant there), n
    where j >= i; probes[i] how many angles those are. All at once: the series with the same
    angles as one 2-D comparison of their steps with every earlier series' steps there, a step at
    a time."""
    m, n = x.shape
    changes = np.full((m, m), n, dtype=np.int16)
    probes = np.zeros(m, dtype=np.int64)
    groups: dict[bytes, tuple[np.ndarray, list[int]]] = {}
    for i in range(m):
        at = np.flatnonzero(care[i])
        probe = at[:: max(1, len(at) // PROBES)]
        probes[i] = len(probe)
        if i and len(probe):
            groups.setdefault(probe.tobytes(), (probe, []))[1].append(i)
    for probe, rows in groups.values():
        steps = np.ascontiguousarray(np.diff(x[:, probe], axis=1).T[:255], dtype=np.int32)   # a row a step (0.1 mm)
        size = max(1, CHUNK // rows[-1])
        for k in range(0, len(rows), size):
            idx = np.asarray(rows[k:k + size])
            top, count = int(idx[-1]), np.zeros((len(idx), int(idx[-1])), dtype=np.uint8)   # at most PROBES * 2 steps
            for s in steps:
                np.add(count, np.not_equal(s[idx, None], s[None, :top]), out=count)
            changes[idx, :top] = np.where(np.arange(top) < idx[:, None], count, n)
    return changes, probes


class _Earlier:
    """The coordinate series of one sheet, for `encode_drawing`'s search for an earlier one that a
    coordinate series follows: compared all at once first (`_changes`, as drawn: `x`, `care`), then
    asked in their order, each as it is coded (`add`: the series as coded, which may hold other
    values where its element is not drawn)."""

    def __init__(self, x: np.ndarray, care: np.ndarray):
        self.changes, self.probes = _changes(x, care)
        self.rows: list[np.ndarray] = []
        self.index: list[int] = []

    def add(self, j: int, a: np.ndarray) -> None:
        """The next coordinate series, `a`, coded as series j of the sheet."""
        self.rows.append(a)
        self.index.append(j)

    def shifted(self, a: np.ndarray, care: np.ndarray) -> np.ndarray | None:
        """An earlier series plus a constant that equals `a` (the next coordinate series) wherever
        `care` (an element's coordinate read only where it is drawn: a leader's end on its point),
        else None."""
        i, at = len(self.rows), np.flatnonzero(care)
        if not len(at):
            return None
        for k in np.flatnonzero(self.changes[i, :i] == 0):
            c = self.rows[k][at[0]] - a[at[0]]
            if ((self.rows[k][at] - a[at]) == c).all():
                return self.rows[k] - c
        return None

    def near(self, a: np.ndarray, care: np.ndarray) -> tuple[int, np.ndarray] | None:
        """(j, r) of the earlier series j that differs from `a` (the next coordinate series) by a
        constant at the most of its probed angles (`_changes`): r is `a` less series j where
        `care`, held (`_held`) where not; None where there is none, or where even it does so at
        fewer than half of them (not worth `_serieses`' time)."""
        i = len(self.rows)
        if not i or self.probes[i] < 2:
            return None
        k = int(np.argmin(self.changes[i, :i]))
        if self.changes[i, k] > self.probes[i] // 2:
            return None
        return self.index[k], _held((a - self.rows[k])[:, None], care)[:, 0]


def encode_drawing(d: Drawing, earlier: Sequence[np.ndarray] = ()) -> tuple[dict, bytes, list[np.ndarray]]:
    """A sheet's arrays as (meta, numbers, lengths): `meta` = {"kind", "static", "elements": [{"tag",
    "attrs" [[name, value]...], "title", "texts", "m" points, "rows" (1: the same at every angle),
    "holes" (a polyline with points left out), "len" (has lengths), "from" (where its lengths are
    stored less a multiple of an earlier series: [index, factor], `_proportional`)}]}; `numbers`,
    element by element: where it is drawn (rows of 0/1, `Element.drawn`), its text's index at each
    angle (with more than one text), a polyline's finite points (with holes: m series of 0/1), its
    coordinates (m x 2 series over its rows, in 10^-COORD_DECIMALS mm, a row where not drawn
    holding the last drawn), its lengths (in 10^-LENGTH_DECIMALS mm, likewise held where not drawn
    or NaN; where "from": less `_scaled`(earlier[index], factor), and that multiple where not
    drawn, `_filled`); every series as differences of
    the order that suits it (`_serieses`), or, where an earlier series j of the sheet is the same (a
    line's end and its point), -1 - 3j, or where it is j plus a constant c (a point's label),
    -2 - 3j and c, or (a coordinate) where it costs less, -3 - 3j and its difference from j
    (`_Earlier.near`; a coordinate where its element is not drawn holding what makes it j plus a
    constant where there is such a j: `_Earlier.shifted`); as zigzag varints. `earlier`: the length
    series of the sheets before it on the page, in order; `lengths`: this sheet's, in order."""
    meta, series, seen, shapes = [], [], {}, {}
    shown = [_shown(e) for e in d.elements if e.length_mm is not None]
    lengths = [_ints(_held(np.asarray(e.length_mm, dtype=float).reshape(-1), on), LENGTH_DECIMALS)
               for e, on in zip((e for e in d.elements if e.length_mm is not None), shown)]
    pool = [*earlier, *lengths]
    sources = _proportionals(lengths, pool, range(len(earlier), len(pool)), shown)
    for i, source in enumerate(sources):      # where not read, each the multiple of its source (as page.js holds it)
        if source is not None:
            pool[len(earlier) + i] = lengths[i] = _filled(lengths[i], pool[source[0]], source[1], shown[i])
    sources, own = iter(sources), iter(lengths)

    def put(a, care: np.ndarray | None = None) -> None:
        a = np.asarray(a, dtype=np.int64).ravel()
        if care is not None and care.any() and not care.all():
            same = bank.shifted(a, care)
            a = a if same is None else same
        key, shape = a.tobytes(), (a - a[0]).tobytes()
        if key in seen:
            series.append((-1 - 3 * seen[key],))
        elif shape in shapes:
            j = shapes[shape]
            series.append((-2 - 3 * j, int(a[0] - raw[j][0])))
        else:
            near = bank.near(a, care) if care is not None else None
            if near is not None:                 # what it holds where not read: j plus the remainder held
                a = raw[near[0]] + near[1]
                key, shape = a.tobytes(), (a - a[0]).tobytes()     # a later copy copies what page.js holds
            series.append([(None, a), *([near] if near else [])])
        if care is not None:
            bank.add(len(raw), a)
        raw.append(a)
        seen.setdefault(key, len(series) - 1)
        shapes.setdefault(shape, len(series) - 1)
    raw: list[np.ndarray] = []
    shown = []                                   # each element's drawn, finite, coordinates (as coded), where read
    for e in d.elements:
        xy = np.asarray(e.xy, dtype=float)
        rows, m = xy.shape[0], xy.shape[1]
        drawn = np.asarray(e.drawn()).reshape(rows)
        finite = np.isfinite(xy).all(axis=2)
        held = (_held(np.where(finite[..., None], xy, np.nan), drawn) if m else xy).reshape(rows, -1)
        shown.append((drawn, finite, [(_ints(held[:, c], COORD_DECIMALS), drawn & finite[:, c // 2]) for c in range(2 * m)]))
    coords = [(a, care) for *_, xs in shown for a, care in xs if len(a) == d.n]
    bank = _Earlier(np.array([a for a, _ in coords], dtype=np.int64).reshape(-1, d.n),
                    np.array([care for _, care in coords], dtype=bool).reshape(-1, d.n))
    for e, (drawn, finite, xs) in zip(d.elements, shown):
        m = len(xs) // 2
        holes = e.tag == "polyline" and not finite[drawn].all()
        put(drawn)
        if len(e.texts) > 1:
            put(np.asarray(e.variant).reshape(-1))
        if holes:
            for k in range(m):
                put(finite[:, k])
        for a, care in xs:
            put(a, care if len(a) == d.n else None)
        source = None
        if e.length_mm is not None:
            q, source = next(own), next(sources)
            put(q if source is None else q - _scaled(pool[source[0]], source[1]))
        meta.append({"tag": e.tag, "attrs": [[k, v] for k, v in e.attrs.items()], "title": e.title,
                     "texts": list(e.texts), "m": m, "rows": len(drawn), "holes": holes,
                     "len": 0 if e.length_mm is None else int(np.size(e.length_mm)),
                     "variants": 0 if len(e.texts) <= 1 else int(np.size(e.variant))}
                    | ({"from": list(source)} if source else {}))
    coded = iter(_serieses([x for a in series if isinstance(a, list) for _, x in a]))
    series = [[(j, next(coded)) for j, _ in a] if isinstance(a, list) else a for a in series]
    pairs = [a for a in series if isinstance(a, list) and len(a) == 2]     # alone, or less an earlier series j
    bits = _bits(np.array([[c[1:] for _, c in a] for a in pairs])) if pairs else np.zeros((0, 2))
    less = iter(bits[:, 1] < bits[:, 0])
    for k, a in enumerate(series):
        if isinstance(a, list):              # the cheapest: alone, or less an earlier series j (-3 - 3j)
            j, best = a[1] if len(a) == 2 and next(less) else a[0]
            a = best if j is None else np.concatenate([[-3 - 3 * j], best])
        series[k] = np.asarray(a)
    return ({"kind": d.kind, "static": d.static, "elements": meta},
            _varints(np.concatenate(series)) if series else b"", lengths)


def _amounts(d: Drawing, cycle: PlanCycle, symbols: Sequence[str], lang: str) -> dict:
    """Where page.js `amounts` finds the numbers of the tokens in the notes of the sheet `d` of
    `cycle` (draw.TOKEN): {"seg": {segment's index: [the sheet's elements of its name (as the
    sheet's attribute holds it, escaped) with a length (their indices: page.js takes the one drawn at the angle, a
    triad's force polygon names a side anew at each angle), its scale's value (SI per mm)]}, "res": {result's
    index: its column in the values table: its symbol's, as `lang` letters both}}; `symbols`: the
    values table's symbols in order; each only where the notes have such tokens. ValueError where a
    result has no column."""
    from ..model.lettering import in_lang
    found = {(m[1], int(m[2])) for E in d.elements for t in E.texts for m in TOKEN.finditer(t)}
    seg, res = {}, {}
    for mark, k in sorted(found):
        if mark == RESULT:
            symbol = cycle.results[k].symbol
            shown = [in_lang(x, lang) for x in symbols]
            if in_lang(symbol, lang) not in shown:
                raise ValueError(f"{cycle.kind}: result {symbol} has no row in the values table")
            res[k] = shown.index(in_lang(symbol, lang))
        else:
            s = cycle.segments[k]
            seg[k] = [[n for n, E in enumerate(d.elements) if E.length_mm is not None and E.attrs.get("data-segment") == xml_escape(s.name)],
                      (s.scale or cycle.scale).value]
    return {k: v for k, v in (("seg", seg), ("res", res)) if v}


def _shared_texts(kinds: Sequence[dict]) -> tuple[list[dict], list[list[str]]]:
    """The sheets' `meta` (`encode_drawing`) with each element's texts of more than two (a title
    with φ at every angle) as {"pre", "suf", "mids"}: the texts' common start and end and the index
    of their middles in `mids`, the page's lists of middles, each once (the angles, alike on every
    sheet)."""
    mids: list[list[str]] = []
    out = []
    for K in kinds:
        elements = []
        for E in K["elements"]:
            texts = E["texts"]
            if len(texts) > 2:
                pre = os.path.commonprefix(texts)
                suf = os.path.commonprefix([t[len(pre):][::-1] for t in texts])[::-1]
                middle = [t[len(pre):len(t) - len(suf)] for t in texts]
                if middle not in mids:
                    mids.append(middle)
                E = {**E, "texts": {"pre": pre, "suf": suf, "mids": mids.index(middle)}}
            elements.append(E)
        out.append({**K, "elements": elements})
    return out, mids


def _columns(values: np.ndarray, lengths: Sequence[np.ndarray] = ()) -> tuple[list[int], list, bytes]:
    """Columns of values over frames (NaN: none): each column's exponent e (VALUE_DIGITS significant digits
    of its largest |value|), where a column is stored less a multiple of one of the page's `lengths`
    ([index, factor] or 0, `_proportional`: a value is its vector's length times the plan's scale), and
    column by column its NaN mask (1: none) and round(v / 10^e) (NaN as 0) less that multiple, each a
    `_serieses`, as zigzag varints."""
    exps = []
    for col in values.T:
        top = np.nanmax(np.abs(col)) if np.isfinite(col).any() else 0.0
        exps.append(int(math.floor(math.log10(top))) - (VALUE_DIGITS - 1) if top > 0 else 0)
    scaled = np.rint(np.where(np.isfinite(values), values, 0.0) / 10.0 ** np.array(exps, dtype=float)).astype(np.int64)
    mask = (~np.isfinite(values)).astype(np.int64)
    sources, parts = [], []
    for c, source in enumerate(_proportionals(list(scaled.T), lengths, [len(lengths)] * values.shape[1])):
        sources.append(list(source) if source else 0)
        rest = scaled[:, c] if source is None else scaled[:, c] - _scaled(lengths[source[0]], source[1])
        parts += [mask[:, c], rest]
    return exps, sources, _varints(np.concatenate(_serieses(parts))) if parts else b""


#: The 7-bit groups a blob's text (`_text7`) cannot hold as themselves: NUL (the HTML parser
#: replaces it), CR (it reads CR as LF) and "<" (nothing in a blob ends or opens an element).
ILLEGAL7 = (0, 13, 60)


def _text7(data: bytes) -> str:
    """`data` as text, 7 bits a character (14 % longer than the bytes; Ascii85 25 %, base64 33 %):
    its bits, zero-padded to a whole group, in groups of 7, each group as the character of that
    code; a group of ILLEGAL7 (the k-th) and the group after it as one character U+0100 + (k << 7 |
    next), a last group of ILLEGAL7 as U+0100 + ((3 + k) << 7); in the page's UTF-8 a character of
    U+0100 and up takes 2 bytes, as its 2 groups. Read back: the groups' bits, as many whole bytes
    as they hold."""
    bits = np.unpackbits(np.frombuffer(data, dtype=np.uint8))
    bits = np.concatenate([bits, np.zeros(-len(bits) % 7, dtype=np.uint8)])
    g = bits.reshape(-1, 7).astype(np.int64) @ (1 << np.arange(6, -1, -1))
    codes, keep = g.copy(), np.ones(len(g), dtype=bool)
    paired = -1                                  # the last group taken into a pair
    for i in np.flatnonzero(np.isin(g, ILLEGAL7)):
        if i <= paired:
            continue
        k = ILLEGAL7.index(int(g[i]))
        if i + 1 < len(g):
            codes[i], keep[i + 1], paired = 0x100 + (k << 7 | int(g[i + 1])), False, i + 1
        else:
            codes[i] = 0x100 + ((3 + k) << 7)
    return codes[keep].astype("<u4").tobytes().decode("utf-32-le")


def _packed(data: bytes) -> str:
    """`data` deflated as text (`_text7`): a blob of the page."""
    return _text7(_deflated(data))


def _deflated(data: bytes) -> bytes:
    """`data` deflated, raw (no wrapper: the script's DecompressionStream("deflate-raw"))."""
    z = zlib.compressobj(9, zlib.DEFLATED, -15)
    return z.compress(data) + z.flush()


# ============================================================================ what the page holds

def _moment(plan, M: str, names, couples=(), unknown: str | None = None) -> dict:
    """A moment equation about point M of `plan` as the page's script writes it at each angle
    (page.js `momentText`): the unknown [segment, arm, M at the arm's end?] (R^τ with its link, the
    lever's F'_bal with p-a), each force drawn with its arm h_.. about M ([force, arm, False]), each
    couple's arc (M_i/μ_l); the script takes the signs and the arms (mm) from the sheet drawn."""
    from .forces import arm_name
    segs = {s.name: s for s in plan.segments}
    terms = [[n, arm_name(n), False] for n in names if n in segs and arm_name(n) in segs]
    out = {"terms": terms, "couples": [c for c in couples if c in plan.paths]}
    if unknown is not None:
        X = plan.points[segs[unknown].start]              # where the unknown acts: the arm is M to there
        arm = next((x for x in plan.segments if x.kind in ("link", "vector") and x.name != unknown and M in (x.start, x.end)
                    and abs(plan.points[x.end if x.start == M else x.start] - X) < 1e-6), None)
        if arm is not None:
            out["unknown"] = [unknown, arm.name, arm.end == M]
    return out


def _steps(mech, res, plans, lang: str) -> list[dict]:
    """The analysis in the texts' order, one element a step: the velocity and the acceleration
    plans' construction (`Plan.steps`: the known vectors, the lines of known direction, their
    intersection), then the force analysis: per Assur group from the last
    attached, the unknowns found from moment equations (a dyad's R^τ from ΣM about the inner
    joint, its terms R^τ·l + Σ±F·h ± M_i/μ_l = 0; a triad's R^τ of each leash about its inner pin,
    then R^n of the leash whose axis is off Assur's point S from the group's moment about S), the
    polygon's sides in the order drawn, the inner reactions; then the initial link's loads and M_bal (M_bal + μ_l Σ±F·h =
    0); then the lever's loads and F'_bal·pa + Σ±F·h = 0. A step with "moment" has its equation's
    terms written by the page's script from the sheet of the angle shown. `res`: the analysis at
    the angle of `plans` (one angle). A step of a plan's `steps` has "n", its number on the sheet."""
    from .forces import _carried, _group_label, _later, _moment_equations, link_couples, link_loads, reaction_name
    from ..model.lettering import in_lang, lettering
    L = lettering(mech)
    out = [_construction_step(plans[kind], name, k, lang) for kind in ("velocity", "acceleration") if kind in plans
           for k, name in enumerate(plans[kind].steps, 1)]
    for g in reversed(mech.structure.groups):
        label = _group_label(g)
        forces, group = plans.get(f"forces:{label}"), plans.get(f"group:{label}")
        if forces is None:
            continue
        drawn = {s.name for s in group.segments} if group is not None else set()
        later = _later(mech, g)
        loads = {x: [ld.name for ld in link_loads(mech, res, x) + _carried(mech, res, x, later)] for x in g.links}
        couples = {x: [c.name for c in link_couples(mech, res, x)] for x in g.links}
        if g.klass == 3:
            moments = [(f"{reaction_name(mech, known, ell)}t", inner.point, str(ell), (ell,))
                       for ell, _, inner, known in g.sides]
            ell, _, _, known = g.sides[2]
            S = "S" if "S" not in mech.point_names else "S*"
            R3 = reaction_name(mech, known, ell)
            moments.append((f"{R3}n" if f"{R3}n" in drawn else R3, S, label, ()))
            inners = [(reaction_name(mech, g.links[0], ell), ell) for ell, _, _, _ in g.sides]
        else:
            taus = [n for n in forces.equation if n.startswith("R") and n.endswith("t")]
            moments = [(R, point, ",".join(map(str, links)), links)
                       for (links, point), R in zip(_moment_equations(g), taus)]
            j, k = g.links
            inners = [(reaction_name(mech, k, j), j)]
        for R, point, links, on in moments:
            if R in drawn:
                key = "page.tau" if on else "page.tau_S"             # a link's moment; the triad's about S
                step = {"plan": f"group:{label}", "segment": R, "eq": text(key, lang, R=R, P=point, k=links)}
                if on and R.endswith("t"):
                    step["moment"] = _moment(group, point, [n for x in on for n in loads[x]],
                                             [c for x in on for c in couples[x]], unknown=R)
                out.append(step)
        m = len(forces.equation)
        for k, name in enumerate(forces.steps, 1):
            if name in forces.equation:
                n = forces.equation.index(name) + 1
                eq = text("page.side", lang, sum=" + ".join(forces.equation[:n]) + (" = 0" if n == m else " + …"), n=n, m=m)
                out.append({"plan": f"forces:{label}", "segment": name, "n": k, "eq": eq})
            else:
                out.append(_construction_step(forces, name, k, lang))
        for inner, k in inners:
            out.append({"plan": f"forces:{label}", "segment": inner, "eq": text("page.inner", lang, R=inner, k=k)})
    crank = plans.get("crank")
    if crank is not None:
        vectors = [s.name for s in crank.segments if s.kind == "vector"]
        for name in vectors:
            out.append({"plan": "crank", "segment": name, "eq": text("page.crank", lang, F=in_lang(name, lang))})
        where = {"path": L.M_bal} if L.M_bal in crank.paths else {"segment": "r_b"}     # an engine's couple; a gear's arm
        M = in_lang(L.M_bal, lang)
        out.append({"plan": "crank", **where, "eq": text("page.M_crank", lang, M=M, O=mech.drive.pivot),
                    "moment": {**_moment(crank, mech.drive.pivot, vectors), "M": M}})
    lever = plans.get("lever")
    if lever is not None:
        vectors = [s.name for s in lever.segments if s.kind == "vector" and s.scale is not None and s.name != L.lever(L.F_bal)]
        for name in vectors:
            out.append({"plan": "lever", "segment": name, "eq": text("page.lever", lang, F=in_lang(name, lang))})
        out.append({"plan": "lever", "segment": L.lever(L.F_bal), "eq": text("page.M_lever", lang, M=in_lang(L.M_bal, lang), tol=num(TOLERANCE_PCT, lang)),
                    "moment": _moment(lever, "p", vectors, unknown=L.lever(L.F_bal))})
    return out


def _construction_step(plan, name: str, n: int, lang: str) -> dict:
    """Step `n` of a plan's construction (`Plan.steps`): a known vector, a line of known direction
    through its known point, the intersection that fixes a point."""
    s = plan.segment(name)
    where = title_of(plan, lang).split(",")[0]
    if s.kind == "construction":
        eq = text("page.line", lang, plan=where, P=s.start, V=name[5:])
    elif s.kind == "intersection":
        eq = text("page.point", lang, plan=where, P=name[len("point "):])        # its mark's point: a triad's 'c:2'
    else:
        eq = text("page.vector", lang, plan=where, V=name)
    return {"plan": plan.kind, "segment": name, "n": n, "eq": eq}


def _bands(mech, res, plans, fixed) -> tuple[dict[tuple[str, str], tuple[float, float]], dict[str, tuple[float, float]]]:
    """The bands a careful drawing lands in (5-95 % of `drawing_error.simulate` at the page's
    scales): (1) of each segment (mm) whose value is a value of the worksheet (matched by value and
    unit: the study reads the worksheet's values), that value's band at the segment's scale; (2) of
    the two balancing moments, signed (N m): "M_bal" from the force plans, "M_bal_lever" from the
    lever. None where the study does not draw the mechanism's groups (PRP, RPP, triads). `res`:
    the analysis at the angle of `plans` alone."""
    from .drawing_error import Scales, simulate
    from .pack import BAND, BAND_DRAWS
    sc = fixed.base
    mu_F = next((s.value for k, s in fixed.plan.items() if k.startswith("forces:")), sc["mu_F"].value)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            drawn = simulate(mech, at=float(res.phi_deg[0]), n=BAND_DRAWS, seed=0, res=res,
                             scales=Scales(sc["mu_l"].value, sc["mu_v"].value, sc["mu_a"].value, mu_F))
        except NotImplementedError:            # a group kind the study does not draw: no bands
            return {}, {}
    by_value = []
    for key, samples in drawn.samples.items():
        lo, hi = np.percentile(np.abs(samples), BAND)
        by_value.append((abs(drawn.exact[key]), drawn.units.get(key, ""), float(lo), float(hi)))
    out = {}
    for kind, plan in plans.items():
        for s in plan.segments:
            if s.kind != "vector" or not math.isfinite(s.value) or s.value == 0:
                continue
            scale = (s.scale or plan.scale).value
            for v, u, lo, hi in by_value:
                if u == s.unit and math.isclose(v, abs(s.value), rel_tol=1e-9):
                    out[(kind, s.name)] = (lo / scale, hi / scale)
                    break
    moments = {k: tuple(float(x) for x in np.percentile(drawn.samples[k], BAND))
               for k in ("M_bal", "M_bal_lever") if k in drawn.samples}
    return out, moments


def _data_rows(mech, res, lang: str) -> list[tuple[str, str, str]]:
    """The data a student starts from: ω1, ε1, g, each moving link's lengths, mass and moment of
    inertia, the applied forces at the angle of `res` (one angle) (symbol, value, unit)."""
    from .forces import _applied
    d = mech.drive
    rows = [("φ", num(float(res.phi_deg[0]), lang, 6), "°"), ("ω1", num(abs(d.omega), lang, 6), unit("rad/s", lang)),
            ("ε1", num(d.eps, lang, 6), unit("rad/s^2", lang)), ("g", num(mech.g, lang, 6), unit("m/s^2", lang))]
    for k, link in enumerate(mech.links):
        if k == 0:
            continue
        names = list(link.points)
        for a, b in zip(names, names[1:]):
            rows.append((f"l_{a}{b}", num(math.dist(link.points[a], link.points[b]), lang, 6), unit("m", lang)))
        if link.mass:
            rows.append((f"m{k}", num(link.mass, lang, 6), unit("kg", lang)))
        if link.I_S:
            rows.append((f"I_S{k}", num(link.I_S, lang, 6), unit("kg m^2", lang)))
        for ld in _applied(mech, res, k):
            rows.append((ld.name, num(abs(ld.force[0]), lang, 6), unit("N", lang)))
    return rows


# ============================================================================ the page

def page_angles(mech, student: bool = False, at: float | None = None,
                angles: Sequence[float] | None = None) -> tuple[list[float], list[float]]:
    """(the slider's frames, the angles the page is drawn from: the frames and `at`), deg, as `page`
    takes them."""
    design = float(getattr(mech.drive, "design_deg", 30.0))
    at = design if at is None else float(at)
    frames = [at] if student else [*map(float, PAGE_ANGLES if angles is None else angles), design]
    return frames, (frames if at in frames else [*frames, at])


def page(mech, lang: str = "en", student: bool = False, at: float | None = None,
         angles: Sequence[float] | None = None, fixed=None, solution: Solution | None = None) -> str:
    """The interactive page of `mech` in `lang` (module docstring). `at`: the angle of the check
    (and of a student's page; default the design position); `angles`: the slider's frames (deg;
    default PAGE_ANGLES); `fixed`: the plans' scales (default `cycle_scales` of the page's one
    analysis); `solution`: that analysis (`solution.solve`, frictionless, its `res` at least at
    `page_angles`; made here where not given). ValueError where `at` is a singular position."""
    from . import build_cycle, cycle_scales
    from .draw import drawing
    from .worksheet import worksheet_cycle
    from ..model.lettering import lettering
    check_lang(lang)
    design = float(getattr(mech.drive, "design_deg", 30.0))
    at = design if at is None else float(at)
    frames, phi = page_angles(mech, student, at, angles)
    i_at = phi.index(at)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        solution = (solution or solve(mech, phi)).sub(phi)   # the graphical method's; the other friction mode's rows
        res = solution.res
        if res.friction is not None:
            raise ValueError(f"solution: expected the frictionless analysis of {mech.name!r} (friction='first'), got {res}")
        fixed = fixed or cycle_scales(mech, res=res)
        cycles = build_cycle(mech, res, fixed, solution=solution)
        sheet = worksheet_cycle(mech, res, fixed.base["mu_l"].value, lang, friction_res=solution.other)
    if res.singular[i_at]:
        raise ValueError(f"at: {at:g} deg is a singular position: no plans to check there")
    name = lettering(mech).name(lang, mech.name)
    check = {kind: c.at(i_at) for kind, c in cycles.items()}
    one = res.take(np.array([i_at]))
    bands, moment_bands = _bands(mech, one, check, fixed)
    data: dict = {"lang": lang, "student": student, "design": design, "at": at,
                  "slider": len(frames) - 1, "tol": TOLERANCE_PCT,
                  "ui": {k: text(f"page.{k}", lang) for k in ("in_band", "out_band", "singular", "a4_cut", "sense", "both", "bad_scale")}
                  | {"negligible": text("page.negligible", lang, tiny=num(TINY_MM, lang))}, "tiny": TINY_MM,
                  "rule_ok": text("page.rule_ok", lang, tol=num(TOLERANCE_PCT, lang)),
                  "rule_bad": text("page.rule_bad", lang, tol=num(TOLERANCE_PCT, lang)),
                  "decimal": "." if lang == "en" else ",", "scalebar": scale_bar(lang), "mm": unit("mm", lang),
                  "coord": COORD_DECIMALS, "lengthd": LENGTH_DECIMALS, "elements": ELEMENTS,
                  "maxorder": MAX_ORDER, "jump": JUMP, "smooth": SMOOTH.tolist(), "illegal7": list(ILLEGAL7)}
    blobs: dict[str, str] = {}
    records = sheet.at(i_at).records()
    if not student:
        kinds, lengths = [], []
        symbols = [r["symbol"] for r in records]
        for kind, cycle in cycles.items():
            d = drawing(cycle, lang, name, contract=True, notes=True)
            meta, numbers, more = encode_drawing(d, lengths)
            amounts = _amounts(d, cycle, symbols, lang)
            kinds.append(meta | ({"amounts": amounts} if amounts else {}))
            lengths += more
            blobs[f"k{len(kinds) - 1}"] = _packed(numbers)
        values = np.array(sheet.values, dtype=float)
        values[np.asarray(res.singular)] = math.nan
        exps, sources, vbytes = _columns(values, lengths)
        blobs["values"] = _packed(vbytes)
        data.update(singular=np.flatnonzero(res.singular).tolist())
        rows = [{"symbol": r["symbol"], "shown": _symbol(r["symbol"], lang), "unit": r["unit"], "section": r["section"]}
                for r in records]
        kinds, mids = _shared_texts(kinds)
        blobs["meta"] = _packed(json.dumps({"kinds": kinds, "mids": mids, "steps": _steps(mech, one, check, lang),
                                            "rows": rows, "exps": exps, "sources": sources,
                                            "frames": [int(a) if a.is_integer() else a for a in phi]},
                                           ensure_ascii=False, separators=(",", ":")).encode())
    items, keys = [], []                      # keys: each item's scale (its input's name, value, unit)
    for kind, plan in check.items():
        for s in plan.segments:
            if s.kind in UNMEASURED or not math.isfinite(plan.length_mm(s.name)):
                continue
            lo_hi = bands.get((kind, s.name))
            mu, mu_name = _check_scale(kind, plan, s, fixed.base, lang)
            item = {"plan": kind, "segment": s.name, "exact": round(plan.length_mm(s.name), CHECK_DECIMALS),
                    "band": [round(x, CHECK_DECIMALS) for x in lo_hi] if lo_hi else None}
            if segment_label(s, lang) != s.name:             # else the row shows the segment's name
                item["label"] = segment_label(s, lang)
            if mu is (s.scale or plan.scale) and s.unit:    # the length stands for a quantity at mu
                item["u"] = unit(s.unit, lang)
            items.append(item)
            keys.append((mu_name, mu.value, unit(mu.unit, lang)))
    rank = {mu.symbol.replace("mu_", "μ_"): n for n, mu in enumerate(fixed.base.values())}
    scales = sorted(set(keys), key=lambda k: (rank.get(k[0], len(rank)), keys.index(k)))   # the base ones first
    for item, key in zip(items, keys):
        item["s"] = scales.index(key)
    results = list({r.symbol: (r.symbol, r.value) for kind in ("lever", "crank") if kind in check
                    for r in check[kind].results if r.unit == "N m"}.values())[::-1]    # M_bal (crank), M'_bal
    results = [(sym, v, moment_bands.get(key)) for (sym, v), key in zip(results, ("M_bal", "M_bal_lever"))]
    answers = {"items": items, "M": results, "scales": scales,
               "titles": {kind: title_of(plan, lang).split(",")[0] for kind, plan in check.items()}}
    blobs["check"] = _text7(_obscure(_deflated(json.dumps(answers, separators=(",", ":")).encode())))
    blank = _blank_tables(records, lang) if student else ""
    return _html(mech, name, lang, student, data, blobs, fixed, _data_rows(mech, one, lang), results, blank)


def _check_scale(kind: str, plan, s, base, lang: str):
    """The scale a check item's length is judged at (a Scale: the segment's own, else its plan's; a
    lever's arm, kept in mm, at the lever's μ_v, as it grows with the lever) and the name of the
    student's input for it, as the page's line of scales names it: the symbol where it is a base
    scale (μ_F); else the plan's name with it (a plan drawn coarser), with "(F)" (the loads on a
    group plan, the crank, the lever), or with the segment's (a friction detail drawn enlarged)."""
    own = s.scale or plan.scale
    mu = own if own.symbol.startswith("mu_") else plan.scale
    symbol = mu.symbol.replace("mu_", "μ_")
    if base.get(mu.symbol) == mu:
        return mu, symbol
    if mu == plan.scale:
        return mu, f"{_plan_name(kind, lang)}: {symbol}"
    if mu.symbol != plan.scale.symbol:
        return mu, f"{_plan_name(kind, lang)} (F): {symbol}"
    return mu, f"{_plan_name(kind, lang)}, {segment_label(s, lang)}: {symbol}"


def _blank_tables(records: list[dict], lang: str) -> str:
    """The worksheet's tables (its `records`) with their values and senses left blank, section by
    section (velocities, accelerations, reactions, M_bal), as the teacher's pack has them (`pack`)."""
    head = "".join(f"<th>{escape(text(f'ws.head.{k}', lang))}</th>" for k in ("symbol", "value", "unit", "direction"))
    out = [f'<section id="worksheet"><h2>{escape(text("pack.fill", lang))}</h2>']
    for section in dict.fromkeys(r["section"] for r in records):
        rows = "".join(f'<tr><td>{escape(_symbol(r["symbol"], lang))}</td><td class="blank"></td>'
                       f'<td>{escape(r["unit"])}</td><td class="blank"></td></tr>' for r in records if r["section"] == section)
        out.append(f'<h3>{escape(section)}</h3><table class="fill"><tr>{head}</tr>{rows}</table>')
    return "".join(out) + "</section>"


def _symbol(symbol: str, lang: str) -> str:
    """A worksheet's symbol as the page shows it in `lang` (a^Cor -> a^к); its data-symbol stays."""
    return symbol.replace("^Cor", "^" + text("coriolis", lang))


def _obscure(data: bytes) -> bytes:
    """`data` XORed with the xorshift32 keystream of seed 27 (the page's script undoes it): the
    check's answers, which a page that works offline must hold, kept from a glance at the file
    (not from a determined reader)."""
    out, x = bytearray(len(data)), 27
    for i, b in enumerate(data):
        x ^= (x << 13) & 0xFFFFFFFF
        x ^= x >> 17
        x ^= (x << 5) & 0xFFFFFFFF
        out[i] = b ^ (x & 255)
    return bytes(out)


def _html(mech, name: str, lang: str, student: bool, data: dict, blobs: dict[str, str], fixed,
          data_rows, results, blank: str = "") -> str:
    from .draw import scale_text
    title = f"{name}: {text('page.student' if student else 'page.key', lang)}"
    scales = "; ".join([scale_text(s, lang) for s in fixed.base.values()]
                       + [f"{_plan_name(k, lang)}: {scale_text(s, lang)}" for k, s in fixed.plan.items()
                          if s != fixed.base[s.symbol]]
                       + [f"{_plan_name(k, lang)} (F): {scale_text(s, lang)}" for k, s in fixed.forces_on.items()])
    head = "".join(f"<th>{escape(h)}</th>" for h in ("", "", ""))
    data_table = "".join(f'<tr><td>{escape(s)}</td><td class="num">{escape(v)}</td><td>{escape(u)}</td></tr>'
                         for s, v, u in data_rows)
    check_rows = []                             # the items' rows: the script writes them from the check's blob
    for n, (symbol, _, _) in enumerate(results):
        check_rows.append(f'<tr data-moment="{n}"><td></td><td>{escape(symbol)}, {escape(unit("N m", lang))}</td>'
                          f'<td><input type="text" inputmode="decimal" class="moment" data-symbol="{escape(symbol)}" '
                          f'size="7"></td><td></td><td class="exact num"></td><td class="band num"></td><td class="verdict"></td></tr>')
    if len(results) == 2:
        check_rows.append(f'<tr id="delta"><td></td><td>δ = ({escape(results[1][0])} − {escape(results[0][0])}) / '
                          f'{escape(results[1][0])} · 100 %</td><td></td><td></td><td></td><td class="num">|δ| ≤ '
                          f'{num(TOLERANCE_PCT, lang)} %</td><td class="verdict"></td></tr>')
    phi = num(data["at"], lang, 6)
    check = (f'<section id="check"><h2>{escape(text("page.check", lang))}</h2><p>{escape(text("page.check_note", lang, phi=phi, tol=num(TOLERANCE_PCT, lang)))}</p>'
             f'<p>{escape(text("page.your_scales", lang))}</p><table id="scale-table"></table>'
             f'<table id="check-table"><tr>' + "".join(f"<th>{escape(text('page.' + k, lang))}</th>"
                                                      for k in ("plan", "segment", "measured", "quantity", "exact", "band", "verdict"))
             + "</tr>" + "".join(check_rows) + "</table></section>")
    if student:
        body = (f'<section id="data"><h2>{escape(text("page.data", lang))}</h2><p>{escape(text("page.scales", lang))}: {escape(scales)}</p>'
                f'<table><tr>{head}</tr>{data_table}</table></section>'
                + blank
                + f'<section id="grid"><h2>{escape(text("page.sheet", lang))}</h2><div class="sheet">{_grid_sheet(name, title.removeprefix(name + ": "), lang)}</div></section>'
                + check)
    else:
        body = (f'<section id="controls"><label for="phi">{escape(text("page.phi", lang))}: <output id="phi-value"></output>°</label> '
                f'<input type="range" id="phi" min="0" max="359" step="1" value="0"> '
                f'<button id="design" type="button">{escape(text("page.design", lang))} ({num(data["design"], lang, 6)}°)</button> '
                f'<button id="prev" type="button">{escape(text("page.prev", lang))}</button> '
                f'<button id="next" type="button">{escape(text("page.next", lang))}</button> '
                f'<output id="step"></output> <label>{escape(text("page.paper", lang))}: <select id="paper"><option>A3</option>'
                f'<option>A4</option></select></label><p id="equation"></p><p class="hint">{escape(text("page.print", lang))}</p>'
                f'<p id="scales">{escape(text("page.scales", lang))}: {escape(scales)}</p></section>'
                f'<section id="sheets"><p id="status">{escape(text("page.loading", lang))}</p></section>'
                f'<section id="values"><h2>{escape(text("page.values", lang))}</h2><table id="value-table"></table></section>'
                f'<section id="data"><h2>{escape(text("page.data", lang))}</h2><table>{data_table}</table></section>'
                + check)
    script = _bare(resources.files("kinetostat.plans").joinpath("page.js").read_text(encoding="utf-8"))
    blobs = {**blobs, "js": base64.b64encode(_deflated(script.encode())).decode("ascii")}   # `_UNPACK` runs it
    payload = script_json(data)                 # no name in it (`</script>`, `<!--<script>`) ends its element
    blob_tags = "".join(f'<script type="application/octet-stream" id="blob-{k}">{v}</script>' for k, v in blobs.items())
    return (f'<!DOCTYPE html>\n<html lang="{lang}"><head><meta charset="utf-8">'
            f'<meta http-equiv="Content-Security-Policy" content="default-src \'none\'; style-src \'unsafe-inline\'; '
            f'script-src \'unsafe-inline\'; img-src data:">'
            f'<title>{escape(title)}</title><style>{_CSS}</style><style id="page-size">@page{{size:A3 landscape;margin:0}}</style>'
            f'</head><body>'
            f'<h1>{escape(title)}</h1>{body}{blob_tags}'
            f'<script id="page-data" type="application/json">{payload}</script><script>{_UNPACK}</script></body></html>\n')


#: The page's one script as written: the page's script (blob "js": deflated, base64; a third the
#: size of its text: the page's budget) inflated and run.
_UNPACK = ('(async()=>{const b=Uint8Array.from(atob(document.getElementById("blob-js").textContent),c=>c.charCodeAt(0)),'
           's=document.createElement("script");s.textContent=await new Response(new Blob([b]).stream()'
           '.pipeThrough(new DecompressionStream("deflate-raw"))).text();document.body.append(s)})();')


def _bare(script: str) -> str:
    """The page's script without its comments (a line's own, or after code and two spaces) and
    indentation: what the browser runs, line for line."""
    lines = (re.sub(r"\s{2,}// .*$", "", line).strip() for line in script.splitlines())
    return "\n".join(line for line in lines if line and not line.startswith("//"))


def _plan_name(kind: str, lang: str) -> str:
    """A plan kind as its sheet's title names it, without the angle (group:2,3 -> Plan of group 2-3)."""
    base, _, rest = kind.partition(":")
    return text(f"plan.{base}", lang) + (" " + rest.replace(",", "-") if rest else "")


def _grid_sheet(name: str, what: str, lang: str) -> str:
    """An empty A3 sheet at true scale: frame, a millimetre grid (1, 5 and 10 mm lines), the title
    block (the mechanism's `name` and `what` the page is, each on a line of its own, in a size that
    fits the block's 179 mm) and the 100 mm scale bar."""
    from .labels import text_width
    fit = lambda s, size: f"{max(1.8, min(size, size * 179.0 / max(text_width(s, size), 1e-9))):.2f}"
    title = (f'<text x="233" y="256" font-size="{fit(name, 4.0)}">{escape(name)}</text>'
             f'<text x="233" y="264" font-size="{fit(what, 3.5)}">{escape(what)}</text>')
    return ('<svg xmlns="http://www.w3.org/2000/svg" width="420mm" height="297mm" viewBox="0 0 420 297" '
            'font-family="DejaVu Sans, Arial, sans-serif"><defs>'
            '<pattern id="mm" width="10" height="10" patternUnits="userSpaceOnUse">'
            '<path d="M1 0V10M2 0V10M3 0V10M4 0V10M6 0V10M7 0V10M8 0V10M9 0V10M0 1H10M0 2H10M0 3H10M0 4H10M0 6H10M0 7H10M0 8H10M0 9H10" '
            'stroke="#e9b8a8" stroke-width="0.05"/><path d="M5 0V10M0 5H10" stroke="#d99580" stroke-width="0.1"/>'
            '<path d="M0 0V10M0 0H10" stroke="#c0603f" stroke-width="0.2"/></pattern></defs>'
            '<rect width="420" height="297" fill="#fff"/>'
            '<rect x="20" y="5" width="395" height="287" fill="url(#mm)" stroke="#000" stroke-width="0.7"/>'
            '<rect x="230" y="247" width="185" height="45" fill="#fff" stroke="#000" stroke-width="0.5"/>'
            f'{title}{scale_bar(lang)}</svg>')


def scale_bar(lang: str) -> str:
    """A 100 mm scale bar in the sheet's binding margin (x 16 mm, y 40-140 mm, 1 unit = 1 mm), ticks
    every 10 mm, lettered 0, 50 and 100 at its ticks: printed at true scale it measures 100 mm."""
    ticks = "".join(f"M{16 - (2 if k % 5 == 0 else 1)} {40 + 10 * k}H16" for k in range(11))
    labels = "".join(f'<text x="13" y="{40 + 10 * k + 0.9}" font-size="2.5" text-anchor="end">{10 * k}</text>'
                     for k in (0, 5, 10))
    return (f'<g id="scalebar"><path d="M16 40V140{ticks}" stroke="#000" stroke-width="0.3" fill="none"/>{labels}'
            f'<text x="13" y="145" font-size="2.5" text-anchor="end">{escape(unit("mm", lang))}</text></g>')


_CSS = """
body{font-family:"DejaVu Sans",Arial,sans-serif;margin:1em;color:#111}
h1{font-size:1.3em}h2{font-size:1.1em}
table{border-collapse:collapse;margin:.5em 0}td,th{border:1px solid #bbb;padding:2px 6px;font-size:.9em}
td.num{text-align:right;font-variant-numeric:tabular-nums}
table.fill td.blank{min-width:9em;height:1.6em}h3{font-size:1em;margin:.6em 0 .2em}
#controls{position:sticky;top:0;background:#fff;padding:.4em 0;border-bottom:1px solid #ccc;z-index:2}
#phi{width:40em;max-width:90vw;vertical-align:middle}
#equation{font-size:1.05em;min-height:1.3em;margin:.3em 0}.hint{color:#555;font-size:.85em;margin:.2em 0}
#sheets{display:grid;grid-template-columns:repeat(auto-fill,minmax(620px,1fr));gap:.6em}
.sheet{border:1px solid #ddd}.sheet svg{display:block;width:100%;height:auto;max-width:1260px}
@media screen{.hl{stroke:#d01c1c !important;stroke-width:1.2 !important}}
.sheet[data-a4]::before{content:attr(data-a4);color:#b01515}
.verdict.ok{color:#176317}.verdict.bad{color:#b01515}
@media print{
  body{margin:0;display:flex;flex-direction:column}#check,#status,#controls>*{display:none}
  h1,#controls,#data,#values,#worksheet{padding:0 10mm 0 25mm;font-size:9pt}
  #controls{position:static;border:0;order:0}#controls>label[for=phi],#scales{display:block}
  #data{order:1}#values,#worksheet{order:2}
  #data table,#value-table{display:block;columns:4;column-gap:8mm}
  #data tr,#value-table tr{display:flex;break-inside:avoid}#data td,#value-table td,#value-table th{flex:1;white-space:nowrap}
  #sheets,#grid{order:3;display:block;break-before:page}#grid h2{display:none}
  .sheet{border:0;margin:0;break-after:page}
  .sheet svg{width:420mm;height:297mm;max-width:none}
  [data-paper="A4"] .sheet svg{width:297mm;height:210mm}.sheet::before{display:none}
}
"""


def write_page(mech, out: str | Path, lang: str = "en", student: bool = False, at: float | None = None,
               solution: Solution | None = None) -> Path:
    """The page of `mech` (`page`, from `solution` where given), drawn anew, written to `out`
    atomically; returns its path."""
    path = Path(out)
    write_text(path, page(mech, lang=lang, student=student, at=at, solution=solution))
    return path
