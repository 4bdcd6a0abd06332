"""All the plans of a variant on one A3 landscape sheet, each TRUE TO SCALE (1 mm of the plan's
drawing = 1 mm on paper, at the scales its heading states), as seed 002 (Logvinenko, Nadtoka
2021, appendix B) puts them.

Each plan is drawn exactly as its own SVG sheet draws it (`draw.sheet`: its lines, arrowheads,
points and every label where `labels.Placer` put it clear of the others): the `plan` group of
that sheet is read from its elements, as its SVG writes them (`drawing`), placed on the page
(`pages`) and drawn into the PDF in millimetres (`draw_page`, `.pdf`). The
plans' extents (drawing, labels and a heading: title, then every scale the plan is drawn at) are
placed inside the frame, clear of the title block and the notes above it, never turned
(`layout`): in the texts' order (`texts_rank`: positions, mechanism, velocities, accelerations,
each group's plan and force polygon, the initial link, the lever; each right of or below every
plan before it; found depth first over the corners) where that fits, else packed (maximal rectangles, several rules and orders) and
the notes say so. The title block is GOST 2.104's form 1 (185 x 55 mm: roles, designation, name,
μ_l as its ratio, sheet and sheets; names and signatures left blank); the notes state the scales
and each one whose reference is drawn outside the guide's recommended length. Where the plans at the texts' scales do not fit one sheet, `one_sheet`
chooses the variant's scales together for it: velocity, acceleration and force scales a round
step coarser first, μ_l only where they cannot make room; where they fit only packed, the first
three coarser (at that μ_l) until they fit in the texts' order, if they can; the title block and the key name each
scale made coarser than the rule, and why. Where no choice fits them, further sheets take the
rest and the title block says so (no variant of the text's tasks: a test runs them all).

May use: the standard library, numpy, `build` of this package, `.core`, `.draw`, `.i18n`, `.kinematic`,
`.labels`, `.scales`, `.pdf`, `.solution` (the one analysis). Never matplotlib.
"""
from __future__ import annotations

import xml.etree.ElementTree as ET
from dataclasses import dataclass, field, replace
from types import MappingProxyType
from typing import Any, Mapping

import numpy as np

from .core import Scale
from .draw import SHEET_MM, language_part, scale_text, scales_of, sheet, title_of
from .i18n import LANGS, num, text
from .labels import ASCENT
from .pdf import text_width
from .scales import TARGET_MM
from .solution import Solution, solve

__all__ = ["Drawing", "Placement", "OneSheet", "Page", "drawing", "layout", "placed_in_order", "one_sheet", "pages", "draw_page", "AREA", "TITLE_BLOCK",
           "notes", "note_lines", "notes_mm", "notes_room", "NOTE_SIZE",
           "MIN_HEADING_MM", "RULES", "ORDERS", "FIRST", "FLOOR_MM", "IN_ORDER_TRIES"]

#: Where plans go on the A3 sheet (x0, y0, x1, y1), mm from the top left: inside the frame
#: (left 20 mm for binding, 5 mm elsewhere) below the sheet's title line.
AREA = (24.0, 13.0, 411.0, 288.0)
#: The main title block of GOST 2.104 (form 1, 185 x 55 mm), bottom right, mm.
TITLE_BLOCK = (230.0, 237.0, 415.0, 292.0)
#: The notes above the title block (its width; GOST 2.316 puts a drawing's text there): the
#: scales, their departures from the guide's, the order of the plans; their type and the step
#: between their lines, mm; their height is their lines' (`notes_mm`).
NOTE_SIZE, _NOTE_STEP = 2.5, 3.1
_NOTE_BASE = 1.5                            # the last line's baseline above the title block, mm
#: A plan's heading above its drawing (its title, 3.5 mm, then its scales, 3 mm) is broken into
#: lines no wider than the drawing, or than this where the drawing is narrower, mm.
MIN_HEADING_MM = 50.0
_GAP = 3.0                                  # between two drawings, mm


@dataclass(frozen=True)
class Drawing:
    """A plan's sheet drawing read back from its SVG: primitives in sheet mm (y down) and their box.
    lines: (x0, y0, x1, y1, width, dash, colour, name); polylines: (points, width, colour);
    polygons: (points, colour, name of its vector or "") (arrowheads, tip first); dots: (x, y, r); texts: (x, y, [(text, size, dy)])."""
    kind: str
    heading: tuple[str, str]
    lines: tuple
    polylines: tuple
    polygons: tuple
    dots: tuple
    texts: tuple
    box: tuple[float, float, float, float]


@dataclass(frozen=True)
class Placement:
    """A plan on a page: `page` (0-based) and the shift (dx, dy) from its own sheet's mm to the page's."""
    kind: str
    page: int
    dx: float
    dy: float


def _width(s: str, size_mm: float, weight: str = "normal") -> float:
    """Advance width of `s` (mm) at `size_mm`, DejaVu Sans of `weight` ("normal", "bold"), as the PDF sets it."""
    return text_width(s, size_mm, weight == "bold")


def _lines(s: str, size_mm: float, width_mm: float, weight: str = "normal") -> list[str]:
    """`s` broken at spaces into lines no wider than `width_mm` (a longer word alone)."""
    out, line = [], ""
    for word in s.split(" "):
        trial = f"{line} {word}" if line else word
        if line and _width(trial, size_mm, weight) > width_mm:
            out.append(line)
            line = word
        else:
            line = trial
    return out + [line]


def _xml_text(markup: str) -> str:
    """The text of escaped character data (a title, a tspan's content), as an XML reader reads it."""
    return (ET.fromstring(f"<t>{markup}</t>").text or "") if "&" in markup else markup


def _runs(markup: str, size: float) -> tuple[tuple[str, float, float], ...]:
    """A label's runs (text, size mm, how far below the baseline, mm) from its tspans' markup
    (`labels.label_markup`) at font size `size`."""
    runs, low = [], 0.0
    for t in ET.fromstring(f"<t>{markup}</t>").iter("tspan"):
        low += float(t.get("dy", "0"))
        runs.append((t.text or "", float(t.get("font-size", size)), low))
    return tuple(runs)


def _read(sheet, plan, lang: str) -> Drawing:
    """The plan group of a plan's one-angle sheet (`draw.sheet`: its elements, in the order its SVG
    writes them, coordinates to 0.001 mm as it writes them) as primitives, with its box."""
    lines, polylines, polygons, dots, texts = [], [], [], [], []
    xs, ys = [], []
    for el in sheet.elements:
        xy = el.xy[0]
        if el.tag == "polyline":
            xy = xy[np.isfinite(xy).all(axis=1)]
            if len(xy) < 2:
                continue
        elif el.tag == "g" or not np.isfinite(xy).all():
            continue
        p = [(x, y) for x, y in (np.rint(xy * 1000.0) / 1000.0 + 0.0).tolist()]     # as written: 0.001 mm
        a = el.attrs
        if el.tag == "line":
            (x0, y0), (x1, y1) = p
            lines.append((x0, y0, x1, y1, float(a.get("stroke-width", "0.13")), a.get("stroke-dasharray", ""),
                          a.get("stroke", "#000"), _xml_text(el.title)))
        elif el.tag == "polyline":
            polylines.append((p, float(a["stroke-width"]), a["stroke"]))
        elif el.tag == "path":                   # an arrowhead, its tip first: of the line before it
            owner = lines[-1][7] if lines and "arc" not in a.get("class", "") else ""
            polygons.append((p, a.get("fill", "#000"), owner))
        elif el.tag == "circle":
            (x, y), r = p[0], float(a["r"])
            dots.append((x, y, r))
            xs += [x - r, x + r]
            ys += [y - r, y + r]
            continue
        elif el.tag == "text":
            (x, y), size = p[0], float(a["font-size"])
            runs = _runs(el.texts[int(el.variant[0])], size)
            texts.append((x, y, runs))
            w = 0.0
            for t, s, _ in runs:                 # the runs' advances added in order
                w += _width(t, s)
            xs += [x, x + w]
            ys += [y - 0.95 * size, y + (runs[-1][2] if runs else 0.0) + 0.3 * size]
            continue
        xs += [x for x, _ in p]
        ys += [y for _, y in p]
    box = (min(xs), min(ys), max(xs), max(ys)) if xs else (0.0, 0.0, 0.0, 0.0)
    return Drawing(plan.kind, _heading_of(plan, lang), tuple(lines), tuple(polylines), tuple(polygons), tuple(dots),
                   tuple(texts), box)


def _heading_of(plan, lang: str) -> tuple[str, str]:
    """A plan's heading in `lang`: its title, and every scale it is drawn at."""
    scales = "; ".join(scale_text(s, lang) for s in scales_of(plan))
    return title_of(plan, lang), f"{text('scales', lang)}: {scales}"


def drawing(plan, lang: str, mechanism: str = "") -> Drawing:
    """The `plan` group of the plan's sheet (`draw.sheet`) as primitives, with its box."""
    return _read(sheet(plan, lang, mechanism), plan, lang)


def _heading(d: Drawing) -> list[tuple[str, float, str]]:
    """The heading's lines (text, size mm, weight): the title, then the scales, broken between
    scales to the drawing's width (at least MIN_HEADING_MM)."""
    width = max(d.box[2] - d.box[0], MIN_HEADING_MM)
    out = [(ln, 3.5, "bold") for ln in _lines(d.heading[0], 3.5, width, "bold")]
    line = ""
    for part in d.heading[1].split("; "):
        trial = f"{line}; {part}" if line else part
        if line and _width(trial, 3.0) > width:
            out.append((line + ";", 3.0, "normal"))
            line = part
        else:
            line = trial
    return out + [(line, 3.0, "normal")]


def _size(d: Drawing) -> tuple[float, float, float]:
    """(width, height, heading's height) of a drawing with its heading, mm."""
    head = _heading(d)
    top = sum(1.3 * size for _, size, _ in head) + 1.0
    return max(d.box[2] - d.box[0], *(_width(t, size, wt) for t, size, wt in head)), d.box[3] - d.box[1] + top, top


def _free(G: float, notes: float) -> list[tuple[float, float, float, float]]:
    """The free rectangles of an empty page for boxes grown by the gap G (right and bottom): AREA
    above the notes (`notes` mm high) over the title block, and AREA left of them (both maximal; they overlap)."""
    x0, y0, x1, y1 = AREA
    return [(x0, y0, x1 + G, TITLE_BLOCK[1] - notes - 2 + G), (x0, y0, TITLE_BLOCK[0] - 2 + G, y1 + G)]


#: The rules of `_place`, each a key of a free rectangle's corner (x, y, x1, y1) for a box w x h
#: to take the least of: its bottom highest, then leftmost (bottom-left, y down); its right
#: edge leftmost, then highest (columns from the left); the free rectangle it fills best (least
#: area left), then highest.
RULES = (lambda x, y, x1, y1, w, h: (y + h, x), lambda x, y, x1, y1, w, h: (x + w, y),
         lambda x, y, x1, y1, w, h: ((x1 - x) * (y1 - y) - w * h, y, x))
#: The rules of the texts' order (`_place_after`), each a key of a box's top left corner (x, y):
#: by rows (highest, then leftmost), by columns (leftmost, then highest).
READING = (lambda x, y: (y, x), lambda x, y: (x, y))
#: The plans in the order of the texts (seed 002 sec. 1.2, figs 1.5-1.12): the plan of positions,
#: the mechanism at the design position, velocities, accelerations; then each group's plan and its
#: force polygon, the last attached group first (the force analysis starts there: seed 000); the
#: initial link; the lever. A kind not named here goes last, in the order given.
TEXTS_ORDER = ("positions", "mechanism", "velocity", "acceleration", "group", "forces", "crank", "lever")


def texts_rank(kind: str) -> tuple:
    """Sort key of a plan kind in TEXTS_ORDER ("group:4,5" before "group:2,3", each group's plan
    before its force polygon)."""
    base, _, links = kind.partition(":")
    if base in ("group", "forces"):
        first = int(links.split(",")[0]) if links.split(",")[0].isdigit() else 0
        return (TEXTS_ORDER.index("group"), -first, base == "forces")
    return (TEXTS_ORDER.index(base) if base in TEXTS_ORDER else len(TEXTS_ORDER), 0, False)


def _after(box: tuple, before: tuple) -> bool:
    """Whether `box` (x0, y0, x1, y1, or its top left corner x0, y0) reads after `before` (x0, y0,
    x1, y1): right of it or below it."""
    return box[0] >= before[2] - 1e-9 or box[1] >= before[3] - 1e-9


def in_texts_order(kinds: list[str], boxes: list[tuple]) -> bool:
    """Whether the boxes (x0, y0, x1, y1, each a plan's with its heading) read in the texts' order
    (`texts_rank`): each right of or below every plan before it."""
    ranked = sorted(zip(kinds, boxes), key=lambda kb: texts_rank(kb[0]))
    return all(_after(b, a) for i, (_, b) in enumerate(ranked) for _, a in ranked[:i])


def placed_in_order(drawings: list[Drawing], places: list[Placement]) -> bool:
    """Whether the drawings, placed (`layout`), are all on one page in the texts' order
    (`in_texts_order` of their boxes with headings)."""
    boxes = []
    for d, p in zip(drawings, places):
        w, h, top = _size(d)
        boxes.append((d.box[0] + p.dx, d.box[1] + p.dy - top, d.box[0] + p.dx + w, d.box[1] + p.dy - top + h))
    return all(p.page == 0 for p in places) and in_texts_order([d.kind for d in drawings], boxes)


def _cut(free: list, box: tuple) -> tuple[list, list[int]]:
    """(the free rectangles with each one `box` (x0, y0, x1, y1) meets given way to its pieces
    beside the box, the indices of the pieces). A box w x h fits one of them where it fits one
    of `_split`'s, which drops only pieces inside another."""
    bx0, by0, bx1, by1 = box
    out, pieces = [], []
    for r in free:
        fx0, fy0, fx1, fy1 = r
        if bx0 >= fx1 or bx1 <= fx0 or by0 >= fy1 or by1 <= fy0:
            out.append(r)
            continue
        for c in ((fx0, fy0, bx0, fy1), (bx1, fy0, fx1, fy1), (fx0, fy0, fx1, by0), (fx0, by1, fx1, fy1)):
            if c[2] - c[0] > 1e-9 and c[3] - c[1] > 1e-9:
                pieces.append(len(out))
                out.append(c)
    return out, pieces


def _maximal(out: list, pieces: list[int]) -> list:
    """`out` (`_cut`) without the pieces inside another rectangle (of equal pieces the first kept).
    Only the pieces are tested: a rectangle the box does not meet is inside no piece, as each
    piece is inside the rectangle it came from and those given are maximal."""
    drop = set()
    for i in pieces:
        x0, y0, x1, y1 = out[i]
        for j, (qx0, qy0, qx1, qy1) in enumerate(out):
            if j != i and qx0 <= x0 and qy0 <= y0 and x1 <= qx1 and y1 <= qy1 and (j < i or out[j] != out[i]):
                drop.add(i)                      # inside another (an equal one after it: not)
                break
    return [r for i, r in enumerate(out) if i not in drop]


def _split(free: list, box: tuple) -> None:
    """The free rectangles (maximal: none inside another) split around `box` (x0, y0, x1, y1), in
    place: each one the box meets gives way to its pieces beside the box (`_cut`), and a piece
    inside another rectangle is dropped (`_maximal`)."""
    free[:] = _maximal(*_cut(free, box))


def _place(free: list, w: float, h: float, rule=RULES[0]) -> tuple[float, float] | None:
    """Where a box w x h goes among the free rectangles (maximal rectangles): at the top left
    corner of one it fits, the least by `rule` (RULES); None where it fits none. The free
    rectangles are split around the box (`_split`)."""
    spots = [(rule(fx, fy, fx1, fy1, w, h), fx, fy) for fx, fy, fx1, fy1 in free
             if fx + w <= fx1 + 1e-9 and fy + h <= fy1 + 1e-9]
    if not spots:
        return None
    _, x, y = min(spots)
    _split(free, (x, y, x + w, y + h))
    return x, y


def _place_after(free: list, w: float, h: float, placed: list, rule) -> list[tuple[float, float]]:
    """Where a box w x h may go inside one free rectangle, right of or below every box `placed`
    (grown by the gap, `_after`): the corners made by a free rectangle's edges and the placed
    boxes' right and bottom edges, least by `rule` (READING) first; none where none is free."""
    spots = set()
    for fx, fy, fx1, fy1 in free:
        if fx + w > fx1 + 1e-9 or fy + h > fy1 + 1e-9:
            continue                             # too small for the box at any corner
        for x in {fx, *(b[2] for b in placed if fx < b[2] <= fx1 - w + 1e-9)}:
            for y in {fy, *(b[3] for b in placed if fy < b[3] <= fy1 - h + 1e-9)}:
                if x + w <= fx1 + 1e-9 and y + h <= fy1 + 1e-9 and all(_after((x, y), b) for b in placed):
                    spots.add((rule(x, y), x, y))
    return [(x, y) for _, x, y in sorted(spots)]


#: The orders the packing tries (where the texts' order does not fit), each a key of a (width,
#: height) to sort by descending: height, width, area, longer side.
ORDERS = (lambda w, h: h, lambda w, h: w, lambda w, h: w * h, lambda w, h: max(w, h))


def _pack(sizes: list[tuple[float, float, float]], order: list[int], rule, notes: float) -> dict[int, tuple[int, float, float]]:
    """Each box (in `order`) at (page, x, y): the first page with room (`_place` by `rule`; the
    notes `notes` mm high), a new one else."""
    pages: list[list] = []
    out = {}
    for i in order:
        w, h = sizes[i][0] + _GAP, sizes[i][1] + _GAP
        for k, free in enumerate(pages + [_free(_GAP, notes)]):
            spot = _place(free, w, h, rule)
            if spot is not None:
                if k == len(pages):
                    pages.append(free)
                out[i] = (k, *spot)
                break
        else:                                    # larger than a page: alone on a page of its own
            pages.append([])
            out[i] = (len(pages) - 1, AREA[0], AREA[1])
    return out


#: The most corners `_in_order` tries for one layout (its first tries are the greedy's: each box
#: at the least corner by the rule; the others where a later box finds none).
IN_ORDER_TRIES = 2000


def _fits_somewhere(free: list, w: float, h: float) -> bool:
    """Whether a box w x h fits inside one of the free rectangles (at any place in it)."""
    return any(w <= fx1 - fx + 1e-9 and h <= fy1 - fy + 1e-9 for fx, fy, fx1, fy1 in free)


def _in_order(sizes: list[tuple[float, float, float]], order: list[int], rule, notes: float
              ) -> tuple[dict[int, tuple[int, float, float]] | None, bool]:
    """(each box (in `order`, the texts') at (0, x, y) on one page (the notes `notes` mm high), each right of or below every
    box before it: at a corner of `_place_after` by `rule`, the next corner where the boxes after
    it find no room (depth first, IN_ORDER_TRIES corners at most); None where none is found;
    whether every corner was searched). A corner after which a later box fits no free rectangle
    at all is passed over at once (nothing below it can fit), so the corners searched, and
    whether all were, are the same for every rule: only their order differs."""
    left = IN_ORDER_TRIES
    out: dict[int, tuple[int, float, float]] = {}
    grown = [(sizes[i][0] + _GAP, sizes[i][1] + _GAP) for i in order]

    def fill(k: int, free: list, placed: list) -> bool:
        nonlocal left
        if k == len(order):
            return True
        w, h = grown[k]
        for x, y in _place_after(free, w, h, placed, rule):
            left -= 1
            if left < 0:
                return False
            cut = _cut(free, (x, y, x + w, y + h))
            if all(_fits_somewhere(cut[0], *later) for later in grown[k + 1:]) and \
                    fill(k + 1, _maximal(*cut), [*placed, (x, y, x + w, y + h)]):
                out[order[k]] = (0, x, y)
                return True
        return False
    found = fill(0, _free(_GAP, notes), [])
    return (out if found else None), left >= 0


def _texts_layout(sizes: list[tuple[float, float, float]], order: list[int], notes: float
                  ) -> dict[int, tuple[int, float, float]] | None:
    """The boxes in the texts' `order` (`_in_order`) by the first rule of READING that places
    them; the next rule only where the one before ran out of tries (a search of every corner that
    found none finds none by any rule)."""
    for rule in READING:
        spots, searched_all = _in_order(sizes, order, rule, notes)
        if spots is not None or searched_all:
            return spots
    return None


def layout(drawings: list[Drawing], notes: float) -> list[Placement]:
    """The drawings (heading above each) on A3 pages inside AREA, clear of the title block and
    the notes above it (`notes` mm high: `notes_mm`), _GAP apart, never turned. In the texts' order (`texts_rank`: each plan
    right of or below every plan before it; `_in_order` by rows, then by columns) where that fits
    one page; else packed (maximal rectangles, `_place`, by each of the RULES, the drawings taken
    in the texts' order, then in each of the ORDERS; the first packing on one page kept, else the
    one on the fewest pages; `in_texts_order` tells which). A drawing that fits no page's room
    goes onto a further page."""
    sizes = [_size(d) for d in drawings]
    texts = sorted(range(len(drawings)), key=lambda i: (texts_rank(drawings[i].kind), i))
    spots = _texts_layout(sizes, texts, notes)
    best = None if spots is None else (1, spots)
    orders = [texts] + [sorted(range(len(drawings)), key=lambda i: (-key(*sizes[i][:2]), i)) for key in ORDERS]
    for rule in RULES if best is None else ():
        for order in orders:
            spots = _pack(sizes, order, rule, notes)
            n = 1 + max((k for k, _, _ in spots.values()), default=0)
            if best is None or n < best[0]:
                best = (n, spots)
            if n == 1:
                break
        if best[0] == 1:
            break
    out = []
    for i, d in enumerate(drawings):
        page, x, y = best[1][i]
        out.append(Placement(d.kind, page, x - d.box[0], y + sizes[i][2] - d.box[1]))
    return out


#: Of the scales coarsened to fit one sheet, these first (in this order among equals), each while
#: its reference (pa, πa, the largest force) stays at least FLOOR_MM long; then μ_l.
FIRST = ("mu_v", "mu_a", "mu_F")
_TRIES = 40                                 # steps of one scale at most (a round step is x1.25..2)
#: The shortest reference length a scale of FIRST is coarsened to (mm): half the recommended
#: length's lower end (`scales.TARGET_MM`), a vector still measured to about 1 %.
FLOOR_MM = {k: TARGET_MM[k][0] / 2 for k in FIRST}


@dataclass(frozen=True)
class OneSheet:
    """The plans of a variant at the scales that put them all on one A3 sheet (`one_sheet`):
    `plans` (`kinetostat.plans.Plans`), their drawings in `lang` and placements (`layout`), the
    scales the texts' rule chose (`rule`: symbol -> Scale) and the quantity each scale draws
    (`reference`, SI: `scales.references`), and each plan's sheet in `lang` (`sheets`: kind ->
    `draw.sheet` with its notes, as `Plans.write` writes it: drawn once for both)."""
    plans: Any
    lang: str
    drawings: tuple[Drawing, ...]
    places: tuple[Placement, ...]
    rule: Mapping[str, Scale]
    reference: Mapping[str, float]
    sheets: Mapping[str, Any] = field(default_factory=dict, compare=False, repr=False)

    def coarsened(self) -> list[tuple[Scale, Scale, float]]:
        """The scales made coarser than the rule's to fit one sheet: (rule's, chosen, the
        reference's drawn length at the chosen one, mm), in the order of SCALE_UNITS."""
        return [(self.rule[k], s, self.reference[k] / s.value) for k, s in self.plans.scales.items()
                if s.value > self.rule[k].value * (1 + 1e-9)]


def one_sheet(mech, at: float, lang: str, solution: Solution | None = None) -> OneSheet:
    """The plans of `mech` at crank angle `at` (deg), drawn in `lang`, at the texts' scales where
    they all fit one A3 sheet (`layout`) in every language of LANGS (so that a variant's scales do
    not depend on the language of its pack), else with scales chosen together for that sheet: the
    scale of FIRST whose plans take the most room (their boxes' area with headings) one round step
    coarser (`scales.next_coarser`) while its reference stays FLOOR_MM long, then μ_l (its GOST
    2.302 series, LENGTH_MANTISSAS), until they fit; then each scale of FIRST back one step finer
    while they still fit. The same `kinetostat.plans.build` that every sheet of the plans uses,
    with these scales given; each try a build (the plan of positions' 12 positions made once per
    μ_l, `kinematic.fixed_positions`), the drawings of the plans whose scales changed (in each
    language; drawn once for the languages whose letters and notes' room are the same,
    `draw.language_part`) and their layouts. Where no scale within _TRIES steps fits them, the last
    try is kept (more than one sheet). `solution`: the caller's one analysis of `mech` at [at]
    (`solution.solve`, frictionless), every build drawn from it (default: made here, once)."""
    from . import build
    from .kinematic import fixed_positions, starting_position
    from .scales import LENGTH_MANTISSAS, SCALE_UNITS, next_coarser, references
    solution = solution or solve(mech, [float(at)], other=False)
    reference = references(mech, solution.res)
    drawn: dict[tuple, Drawing] = {}            # (language, kind, its scales) -> its drawing
    native: dict[tuple, list[str]] = {}         # (kind, its scales) -> the languages it was drawn in
    parts: dict[tuple, tuple] = {}              # (language, kind, its scales) -> `language_part`
    sheets: dict[tuple, Any] = {}               # (kind, its scales) -> its sheet in `lang`, as Plans.write writes it

    def part(plan, lg: str, at_scales: tuple) -> tuple:
        if (lg, *at_scales) not in parts:
            parts[(lg, *at_scales)] = language_part(plan, lg)
        return parts[(lg, *at_scales)]

    def drawings(plans, lg: str) -> list[Drawing]:
        """The plans' drawings in `lg`, each drawn once for all the languages its plan group is
        the same in (`draw.language_part`, found where a language drawn before may be one; its
        heading in `lg`, its lines' tooltips the language's it was drawn in: `lang`'s drawings,
        the ones kept, are always drawn in `lang`, first); in `lang` with the notes and the
        mechanism's name (`Plans.write`'s sheet)."""
        out = []
        for k in plans:
            plan = plans[k]
            at_scales = (k, *(s.value for s in scales_of(plan)))
            if (lg, *at_scales) not in drawn:
                alike = [o for o in native.get(at_scales, []) if part(plan, o, at_scales) == part(plan, lg, at_scales)]
                if alike:
                    drawn[(lg, *at_scales)] = replace(drawn[(alike[0], *at_scales)], heading=_heading_of(plan, lg))
                else:
                    one = sheet(plan, lg, plans.mechanism_name(lg), notes=lg == lang)
                    if lg == lang:
                        sheets[at_scales] = one
                    native.setdefault(at_scales, []).append(lg)
                    drawn[(lg, *at_scales)] = _read(one, plan, lg)
            out.append(drawn[(lg, *at_scales)])
        return out

    fixed: dict[float, Any] = {}

    def positions(mu_l: float):
        """The plan of positions' 12 positions and paths at μ_l (m/mm), made once per μ_l."""
        if mu_l not in fixed:
            start = next(iter(fixed.values())).start if fixed else starting_position(mech, solution)
            fixed[mu_l] = fixed_positions(mech, Scale("mu_l", mu_l, SCALE_UNITS["mu_l"]), start, solution)
        return fixed[mu_l]

    tried: dict[tuple | None, tuple] = {}
    ruled: dict[str, Scale] = {}                # the texts' rule, once its try is made

    def placed(plans, ds: list[Drawing], lg: str) -> tuple[list[Placement], bool]:
        """The drawings `ds` in `lg` laid out clear of the notes their scales take in `lg` (`notes_mm`:
        the notes of the texts' order, else those of a packed sheet, a line more); in the texts' order?"""
        for in_order in (True, False):
            rows = _notes(plans.scales, ruled or plans.scales, reference, in_order, lg)
            places = layout(ds, notes_mm(len(note_lines(rows))))
            if placed_in_order(ds, places) or not in_order:
                return places, in_order and placed_in_order(ds, places)

    def attempt(given: Mapping[str, float] | None):
        """(plans, their drawings in `lang`, placements, on one page in every language, and in the
        texts' order in every language) at the scales `given` (None: the texts' rule)."""
        key = None if given is None else tuple(sorted(given.items()))
        if key not in tried:                     # the searches below come back to scales tried before
            if given is None:                    # the texts' rule: its μ_l is not known before
                plans = build(mech, at=at, solution=solution)
            else:
                pos = positions(given["mu_l"])
                plans = build(mech, at=at, scales=given, starting_deg=pos.start, positions=pos, solution=solution)
            ds = drawings(plans, lang)
            places, ordered = placed(plans, ds, lang)
            fit = all(p.page == 0 for p in places)
            for lg in LANGS:
                if lg != lang and fit:
                    other = drawings(plans, lg)
                    there, in_order = placed(plans, other, lg)
                    fit = all(p.page == 0 for p in there)
                    ordered = ordered and fit and in_order
            tried[key] = plans, ds, places, fit, fit and ordered
        return tried[key]

    ruled.update(attempt(None)[0].scales)
    tried[tuple(sorted((k, s.value) for k, s in ruled.items()))] = tried[None]   # the rule's scales, given: that try
    rule = dict(ruled)
    coarsest = {}                                # each scale of FIRST as coarse as its floor allows
    for k in FIRST:
        coarsest[k] = rule[k].value
        while reference[k] / next_coarser(coarsest[k]) >= FLOOR_MM[k]:
            coarsest[k] = next_coarser(coarsest[k])

    def search(good: int, mu_l: float = np.inf):
        """The scales by the rule above at which the try's flag `good` holds (3: one sheet; 4: one
        sheet in the texts' order), μ_l no coarser than `mu_l`; else the last try."""
        trial = attempt(None)
        given = {k: s.value for k, s in rule.items()}
        for _ in range(_TRIES):                  # μ_l: the finest at which they fit, the others at their floor
            if trial[good] or attempt({**given, **coarsest})[good] or given["mu_l"] >= mu_l * (1 - 1e-9):
                break
            given["mu_l"] = next_coarser(given["mu_l"], LENGTH_MANTISSAS)
        steps: dict[str, list[float]] = {k: [] for k in FIRST}   # the values each scale of FIRST left
        for _ in range(_TRIES):                  # the others from the rule's, the one with most room first
            if trial[good]:
                break
            plans, ds = trial[:2]
            room = dict.fromkeys(FIRST, 0.0)
            for d in ds:
                sym = plans[d.kind].scale.symbol
                if sym in room:
                    w, h, _ = _size(d)
                    room[sym] += w * h
            open_ = [k for k in FIRST if room[k] and given[k] < coarsest[k] * (1 - 1e-9)]
            if open_:
                k = max(open_, key=lambda k: (room[k], -FIRST.index(k)))
                steps[k].append(given[k])
                given[k] = next_coarser(given[k])
            elif given["mu_l"] < mu_l * (1 - 1e-9):  # (only where the search above ran out of tries)
                given["mu_l"] = next_coarser(given["mu_l"], LENGTH_MANTISSAS)
            else:
                break
            trial = attempt(given)
        for k in FIRST:                          # back towards the rule while they still fit
            while trial[good] and steps[k]:
                finer = attempt({**given, k: steps[k][-1]})
                if not finer[good]:
                    break
                given[k] = steps[k].pop()
                trial = finer
        return trial

    trial = search(3)
    if trial[3] and not trial[4]:                # the texts' order bought with μ_v, μ_a, μ_F, not μ_l
        ordered = search(4, trial[0].scales["mu_l"].value)
        trial = ordered if ordered[4] else trial
    plans, ds, places = trial[:3]
    return OneSheet(plans, lang, tuple(ds), tuple(places), MappingProxyType(rule), MappingProxyType(reference),
                    MappingProxyType({k: sheets[(k, *(s.value for s in scales_of(plans[k])))] for k in plans}))


@dataclass(frozen=True)
class Page:
    """One A3 sheet of `pages` as primitives in its mm from the top left (y down).
    lines: (x0, y0, x1, y1, width, dash (on, off mm; () solid), colour, gid); polylines: (points,
    width); polygons: (points, colour, gid) (arrowheads, tip first); dots: (x, y, r); texts: (x,
    baseline y, text, size, weight). A plan's line carries gid "<plan kind>/<segment>", its
    arrowhead "<plan kind>/<segment>^", so that a test can find them."""
    lines: tuple
    polylines: tuple
    polygons: tuple
    dots: tuple
    texts: tuple


#: The cells of the title block (GOST 2.104 form 1), mm from its top left (x0, y0, x1, y1): the
#: changes' header row and the signature rows (each a role, a name, a signature, a date), the
#: designation (graph 2), the name (1), the material (3), the letter (4), mass (5), scale (6),
#: sheet and sheets (7, 8) and the organisation (9), each with its header where it has one.
TB_ROWS = (0.0, 5.0, 10.0, 15.0, 20.0, 25.0, 30.0, 35.0, 40.0, 45.0, 50.0, 55.0)
TB_HEAD = (("rev", (0, 20, 7, 25)), ("sheet_no", (7, 20, 17, 25)), ("doc", (17, 20, 40, 25)),
           ("sign", (40, 20, 55, 25)), ("date", (55, 20, 65, 25)))
TB_ROLES = (("drawn", 25.0), ("checked", 30.0), ("tech", 35.0), ("", 40.0), ("norm", 45.0), ("approved", 50.0))
TB_CELLS = {"designation": (65, 0, 185, 15), "name": (65, 15, 135, 40), "material": (65, 40, 135, 55),
            "letter": (135, 15, 150, 20), "mass": (150, 15, 167, 20), "scale": (167, 15, 185, 20),
            "letter_value": (135, 20, 150, 35), "mass_value": (150, 20, 167, 35), "scale_value": (167, 20, 185, 35),
            "sheet": (135, 35, 155, 40), "sheets": (155, 35, 185, 40), "organisation": (135, 40, 185, 55)}
_TB_THICK, _TB_THIN = 0.5, 0.25            # the block's outline and graphs; the rows of the left part, mm


def scale_ratio(mu_l: float, lang: str) -> str:
    """μ_l (m/mm) as GOST 2.302 writes a scale of the drawing: 1:1,5 for 0.0015 m/mm (1 mm drawn =
    1.5 mm of the mechanism), 2:1 for 0.0005."""
    mm = mu_l * 1000.0
    return f"1:{num(mm, lang, 6)}" if mm >= 1 - 1e-9 else f"{num(1 / mm, lang, 6)}:1"


def _fit(s: str, width: float, size: float = 3.5, weight: str = "normal") -> float:
    """`size` (mm), made smaller down to 2.5 where `s` is wider than `width` (mm)."""
    return max(2.5, min(size, size * width / max(_width(s, size, weight), 1e-9)))


def _title_block(lines: list, texts: list, cells: Mapping[str, str], lang: str) -> None:
    """The title block (TITLE_BLOCK, TB_CELLS) and its texts: the headers in `lang`, and the lines
    of each cell of `cells` (cell name -> its text, broken to its width, `_cell_lines`)."""
    bx, by = TITLE_BLOCK[:2]

    def rule(x0, y0, x1, y1, width):
        lines.append((bx + x0, by + y0, bx + x1, by + y1, width, (), "#000", "title-block"))
    for x0, y0, x1, y1 in ((0, 0, 185, 0), (0, 0, 0, 55), (65, 0, 65, 55), (135, 15, 135, 55), (65, 15, 185, 15),
                           (135, 20, 185, 20), (135, 35, 185, 35), (135, 40, 185, 40), (65, 40, 135, 40),
                           (0, 20, 65, 20), (0, 25, 65, 25), (7, 0, 7, 25), (17, 0, 17, 55), (40, 0, 40, 55),
                           (55, 0, 55, 55), (150, 15, 150, 35), (167, 15, 167, 35), (155, 35, 155, 40)):
        rule(x0, y0, x1, y1, _TB_THICK)
    for y in TB_ROWS[1:-1]:
        if y not in (20.0, 25.0):
            rule(0, y, 65, y, _TB_THIN)
    for x in (140.0, 145.0):
        rule(x, 20, x, 35, _TB_THIN)
    heads = [(text(f"tb.{k}", lang), box) for k, box in TB_HEAD]
    heads += [(text(f"tb.{k}", lang), (0, y, 17, y + 5)) for k, y in TB_ROLES if k]
    heads += [(text(f"tb.{k}", lang), TB_CELLS[k]) for k in ("letter", "mass", "scale", "sheet", "sheets")]
    for s, (x0, y0, x1, y1) in heads:
        texts.append((bx + x0 + 0.8, by + y1 - 1.2, s, _fit(s, x1 - x0 - 1.6, 3.0), "normal"))
    for k, value in cells.items():
        x0, y0, x1, y1 = TB_CELLS[k]
        if k in ("sheet", "sheets"):                             # the number after its header
            x0 += _width(text(f"tb.{k}", lang), _fit(text(f"tb.{k}", lang), x1 - x0 - 1.6, 3.0)) + 2.0
        weight = "bold" if k in ("designation", "name") else "normal"
        size, rows = _cell_lines(value, x1 - x0 - 2.0, y1 - y0, weight)
        step = 1.3 * size
        y = (y0 + y1) / 2 - step * (len(rows) - 1) / 2 + 0.35 * size
        for r in rows:
            texts.append((bx + x0 + 1.0, by + y, r, size, weight))
            y += step


def _cell_lines(s: str, width: float, height: float, weight: str) -> tuple[float, list[str]]:
    """(size, lines) of `s` in a cell width x height (mm): the largest size of 3.5, 3, 2.5 mm at
    which its lines (`_lines`) fit the cell's height, else 2.5 mm."""
    for size in (3.5, 3.0, 2.5):
        rows = _lines(s, size, width, weight)
        if len(rows) * 1.3 * size <= height - 1.0 and all(_width(r, size, weight) <= width for r in rows):
            break
    return size, rows


def notes(sheet: OneSheet, in_order: bool, lang: str) -> list[str]:
    """The notes above the title block of `sheet` (`_notes`)."""
    return _notes(sheet.plans.scales, sheet.rule, sheet.reference, in_order, lang)


def _notes(sc: Mapping[str, Scale], rule: Mapping[str, Scale], reference: Mapping[str, float], in_order: bool,
           lang: str) -> list[str]:
    """The notes above the title block of plans at the scales `sc`: every plan true to scale; the
    scales (μ_l also as GOST 2.302's ratio); each scale whose reference (`scales.REFERENCE_NAMES`,
    `reference` SI) is drawn outside the guide's recommended length (`scales.TARGET_MM`), with that
    length, and each scale coarser than the texts' `rule`; where the plans are packed, not in
    the texts' order, that."""
    from .scales import REFERENCE_NAMES, TARGET_MM
    used = "; ".join(scale_text(s, lang) + (f" ({scale_ratio(s.value, lang)})" if k == "mu_l" else "")
                     for k, s in sc.items())
    out = [text("pack.a3_true", lang), f"{text('pack.scales', lang)}: {used}"]
    departs = []
    for k, s in sc.items():
        lo, hi = TARGET_MM[k]
        mm = reference[k] / s.value
        if not lo - 0.05 <= mm <= hi + 0.05:
            departs.append(text("a3.depart_one", lang, mm=num(mm, lang, decimals=1),
                                ref=REFERENCE_NAMES.get(k) or text("pack.largest_force", lang),
                                lo=num(lo, lang), hi=num(hi, lang)))
    if departs:
        out.append(text("a3.departs", lang, items="; ".join(departs)))
    coarser = [(rule[k], s) for k, s in sc.items() if s.value > rule[k].value * (1 + 1e-9)]
    if coarser:
        out.append(text("pack.a3_coarser", lang, scales="; ".join(
            text("pack.instead", lang, scale=scale_text(s, lang), rule=num(r.value, lang, 6)) for r, s in coarser)))
    if not in_order:
        out.append(text("a3.packed", lang))
    return out


def note_lines(rows: list[str]) -> list[str]:
    """The notes' lines as set above the title block: each note broken to its width at NOTE_SIZE."""
    return [ln for s in rows for ln in _lines(s, NOTE_SIZE, TITLE_BLOCK[2] - TITLE_BLOCK[0] - 2)]


def notes_mm(lines: int) -> float:
    """The height the notes' `lines` take above the title block, mm: the last baseline _NOTE_BASE
    above it, the lines _NOTE_STEP apart, the first line's ascent above its baseline."""
    return _NOTE_BASE + _NOTE_STEP * (lines - 1) + ASCENT * NOTE_SIZE if lines else 0.0


def notes_room(sheet: OneSheet) -> float:
    """The height of `sheet`'s notes above its title block as `pages` sets them, mm."""
    n = max(p.page for p in sheet.places) + 1 if sheet.places else 1
    rows = notes(sheet, placed_in_order(list(sheet.drawings), list(sheet.places)), sheet.lang)
    return notes_mm(len(note_lines(rows + ([text("pack.a3_more", sheet.lang, n=n)] if n > 1 else []))))


def pages(sheet: OneSheet, title: str) -> list[Page]:
    """The A3 sheets of `sheet` (`one_sheet`: one, unless its plans fit none): the frame, the
    title line, the notes (`notes`, and where the plans take more than one sheet, that) above the
    title block of GOST 2.104 (`_title_block`: `title` as the designation, the mechanism's name and
    the crank angle as the name, μ_l as its ratio, the sheet's number and count; the names,
    signatures and dates left blank for the student and the teacher) and each plan's drawing with
    its heading where `layout` placed it, 1 mm of the drawing = 1 mm of the page."""
    from ..model.lettering import lettering
    lang, drawings, places = sheet.lang, sheet.drawings, sheet.places
    n = max(p.page for p in places) + 1
    ordered = placed_in_order(drawings, places)
    mech = sheet.plans.mech
    name = lettering(mech).name(lang, mech.name)
    parts = [([], [], [], [], []) for _ in range(n)]           # lines, polylines, polygons, dots, texts
    tb = TITLE_BLOCK
    for k, (lines, polylines, polygons, dots, texts) in enumerate(parts):
        x0, y0, x1, y1 = 20.0, 5.0, 415.0, 292.0
        polylines.append((((x0, y0), (x1, y0), (x1, y1), (x0, y1), (x0, y0)), 0.7, "#000"))
        texts.append((24.0, 10.0, title, 4.0, "bold"))
        rows = note_lines(notes(sheet, ordered, lang) + ([text("pack.a3_more", lang, n=n)] if n > 1 else []))
        y = tb[1] - _NOTE_BASE - _NOTE_STEP * (len(rows) - 1)
        for s in rows:
            texts.append((tb[0] + 1.0, y, s, NOTE_SIZE, "normal"))
            y += _NOTE_STEP
        _title_block(lines, texts, {
            "designation": title, "name": f"{name}, φ = {num(sheet.plans.at, lang, 6)}°",
            "scale_value": scale_ratio(sheet.plans.scales["mu_l"].value, lang), "sheet": str(k + 1), "sheets": str(n)}, lang)
    for d, p in zip(drawings, places):
        lines, polylines, polygons, dots, texts = parts[p.page]
        dx, dy = p.dx, p.dy
        y = d.box[1] + dy - _size(d)[2]
        for line, size, weight in _heading(d):
            y += 1.3 * size
            texts.append((d.box[0] + dx, y - 0.3 * size, line, size, weight))
        polylines += [(tuple((a + dx, b + dy) for a, b in pts), width, colour) for pts, width, colour in d.polylines]
        lines += [(a0 + dx, b0 + dy, a1 + dx, b1 + dy, width, tuple(float(v) for v in dash.split(",")) if dash else (),
                   colour, f"{d.kind}/{name}") for a0, b0, a1, b1, width, dash, colour, name in d.lines]
        polygons += [(tuple((a + dx, b + dy) for a, b in pts), colour, f"{d.kind}/{owner}^")
                     for pts, colour, owner in d.polygons]
        dots += [(a + dx, b + dy, r) for a, b, r in d.dots]
        for a, b, runs in d.texts:
            x = a + dx
            for s, size, low in runs:
                texts.append((x, b + dy + low, s, size, "normal"))
                x += _width(s, size)
    return [Page(*(tuple(part) for part in page)) for page in parts]


def draw_page(pdf, page: Page) -> None:
    """`page` onto a new A3 page of `pdf` (`pdf.Canvas`)."""
    pdf.page(SHEET_MM)
    for pts, width, colour in page.polylines:
        pdf.polyline(pts, width, colour)
    for x0, y0, x1, y1, width, dash, colour, _ in page.lines:
        pdf.line(x0, y0, x1, y1, width, colour, dash, round_cap=not dash)
    for pts, colour, _ in page.polygons:
        pdf.polygon(pts, colour)
    for x, y, r in page.dots:
        pdf.dot(x, y, r)
    for x, y, s, size, weight in page.texts:
        pdf.text(x, y, s, size, bold=weight == "bold")
