"""A plan drawn: an SVG sheet true to scale in millimetres (A3 landscape, 420 x 297 mm, as the
appendix sheets of seed 002: the plan in the drawing area, a title block that states the plan's
title and its scales, and beside it the notes: legend, the results the sheet finds, a force
plan's vector equation and every drawn segment with its length and value), and a matplotlib
Figure for notebooks and the reports' PNGs.

One renderer: `drawing(cycle)` computes every element of a plan's sheet at all N angles of a
`PlanCycle` at once, as arrays (`core.Drawing`: one place of the plan on the sheet for the whole
cycle, the title's φ a text with a variant per angle); `Drawing.svg(i)` writes the sheet of
angle i; `sheet(plan)`, the sheet of one angle, is `drawing` of the cycle of one, with its
notes, and `svg(plan)` that sheet written.

Drafting as the texts draw: arrowheads 3.5 mm long (shorter on short vectors), drawn as paths;
each segment as heavy as its role (`WEIGHT_MM`, after ГОСТ 2.303: results and links at S = 0.7 mm,
givens 0.5, components S/2, construction 0.25), with a legend of the strokes at the bottom left of
each sheet; an alternative (F_i2(h)) and a link drawn on to a force off it dashed; a plan's notes with their symbols lettered as drawn; a
vector shorter than 1 mm at its scale is drawn out of scale at MIN_DRAWN_MM with a note, or, on a
polygon whose sides must close, lettered at its point and noted as negligible; the lever's arms as
dimension lines with their mm (`_dimensions`); every letter placed by `labels.Placer`
(for all angles at once) clear of every other letter, arrowhead and point, and off the links and
vectors (heavy lines; a leader back to its point where it had to go far); coincident points lettered once ("B1 ≡ B11");
no text under 2.5 mm. Words, units and numbers from the catalogue (`i18n`: en, uk, ru). Every
text that comes from a model (names, notes) is escaped.

May use: the standard library, numpy, `.arcs` (a short vector's drawn length), `.core`, `.i18n`, `.labels`, `.symbols`, `.forces` (an arm's
name), `kinetostat._text` (XML-safe text), `kinetostat.model.lettering` (a symbol in the sheet's
language); matplotlib only inside `figure`.
"""
from __future__ import annotations

import math
import re
import warnings
from collections.abc import Mapping
from dataclasses import dataclass, replace
from functools import lru_cache

import numpy as np

from .._text import xml_escape as escape     # also control characters, which XML cannot hold
from .arcs import MIN_DRAWN_MM
from .core import ELEMENTS, ROLES, Drawing, Element, Plan, PlanCycle, Segment, extent, extent_cycle, role_of
from .forces import arm_name
from .i18n import LANGS, MESSAGES, accuracy, check_lang, num, phrase, text, unit
from .labels import ASCENT, DESCENT, MIN_TEXT_MM, Placer, coincident, label_markup, markup, text_width
from .symbols import SUB, SUB_DROP, mark, plain, runs, text_runs
from ..model.lettering import in_lang

__all__ = ["drawing", "sheet", "svg", "language_part", "figure", "title_of", "scale_text", "scales_of", "fits", "style", "LANGS",
           "SHEET_MM", "MIN_DRAWN_MM", "ARROW_MM", "ARC_HEAD_MM", "ROOM_MM", "S_MM", "WEIGHT_MM"]

#: The sheet: A3 landscape, mm.
SHEET_MM = (420.0, 297.0)
_FRAME = (20.0, 5.0, 415.0, 292.0)          # inner frame: left 20 mm (binding), 5 mm elsewhere
_TITLE_BLOCK = (230.0, 247.0, 415.0, 292.0)  # bottom right, 185 x 45 mm
_AREA = (25.0, 10.0, 410.0, 242.0)          # where the plan is centred (above the notes)
#: Arrowhead: length and half-width, mm (drafting: 3-4 mm); shorter on a vector under 3 lengths.
ARROW_MM = (3.5, 0.6)
#: Arrowhead on an arc (the sense of ω, ε, a couple M), mm: drafting size whatever the arc's chord.
ARC_HEAD_MM = 2.8
#: A vector drawn shorter than this at its scale is drawn out of scale at MIN_DRAWN_MM (`arcs`).
TINY_MM = 1.0
#: A vector shorter than this (mm) is rounding noise of a zero (a load's arm at a dead centre): it
#: has no direction to draw it out of scale in, and is noted as negligible.
ZERO_MM = 1e-9
#: A construction line is drawn this far past its known point and past the intersection, mm; the
#: intersection is marked by a circle of this radius, mm.
PAST_MM, MARK_MM = 12.0, 1.2
#: A vector drawn out of scale along another vector from the same point is drawn this far beside it, mm.
SIDE_MM = 1.8
#: Font sizes of the points' letters, the vectors' names, the numbered positions' letters and the
#: notes, mm: none under MIN_TEXT_MM (capitals 2.5 mm, GOST 2.304).
_POINT_MM = _NAME_MM = _NUMBERED_MM = _NOTE_MM = MIN_TEXT_MM
_LINE_STEP = 5.1                             # line spacing of the notes, mm (room for a sub- and superscript)
_LEFT_NOTES_MM = 120.0                       # width of the notes beside a tall plan, mm
_BELOW_NOTES_MM = _TITLE_BLOCK[0] - 3 - (_FRAME[0] + 3)   # width of the notes below a plan, beside the title block, mm

#: Room a plan has on its sheet (width, height), mm: above notes of a few lines, or beside a
#: column of notes at its left.
ROOM_MM = ((380.0, 185.0), (262.0, 228.0))


def fits(plan: Plan) -> float:
    """By how much the plan exceeds the room of its sheet (ROOM_MM): <= 1 where it fits."""
    x0, y0, x1, y1 = extent(plan)
    return min(max((x1 - x0) / w, (y1 - y0) / h) for w, h in ROOM_MM)


#: The solid thick main line of ГОСТ 2.303 (which allows S = 0.5-1.4 mm), mm.
S_MM = 0.7
#: A segment's line weight by its role (`core.role_of`), mm. The rule, after ГОСТ 2.303 (a solid
#: thick main line S; thin lines, solid, dashed or dash-dotted, S/3-S/2) and seed 002 § 1.2 (a
#: plan is drawn from the known vectors, the unknowns fixed by lines of known direction through
#: the known points, the whole reaction the sum of its parts, figs 1.7-1.10): what a plan is drawn
#: to find (a result: p-b, π-b, R12, R43, R32, F_зр) and the mechanism's links at S; what is laid
#: off from the data (a given: p-a, G2, F_i2, F_p) at S/1.4 = 0.5 mm, the next pen of the
#: drafting series 0.25-0.35-0.5-0.7, so that the result reads first; the parts of a vector sum
#: (a component: a-b, a^n_BA, a^t_BA, R12n, R12t) at S/2; the lines of known direction (kinds
#: "line", "construction") and the auxiliary lines (the other positions, arms, a link drawn on)
#: at 0.25 mm, about S/3.
WEIGHT_MM = {"result": S_MM, "link": S_MM, "given": 0.5, "component": S_MM / 2, "construction": 0.25,
             "auxiliary": 0.25}
#: How each kind of segment is drawn besides its weight: dash pattern, colour.
_STYLE = {"vector": ("", "#000"), "link": ("", "#000"), "position": ("", "#555"),
          "line": ("2,1.2", "#555"), "arm": ("4,1,1,1", "#a33"),
          "alternative": ("3,1.5", "#000"), "extension": ("3,1.5", "#000"), "dimension": ("", "#a33"),
          "construction": ("", "#000"), "intersection": ("", "#000")}
#: The kinds drawn as arrows: a vector, and one drawn as the alternative of others (F_i2(h), dashed).
_ARROWS = ("vector", "alternative")
#: A dimension line's arrowheads (the lever's arms), mm: the drafting size of a thin line's arrow.
DIMENSION_ARROW_MM = 2.5
_DIM_HALF = ARROW_MM[1] * DIMENSION_ARROW_MM / ARROW_MM[0]
#: The page's dimension arrowhead: an SVG marker at both ends of the line (no coordinates per angle).
_DIMENSION_MARKER = (f'<defs><marker id="dimension" markerUnits="userSpaceOnUse" orient="auto-start-reverse" '
                     f'markerWidth="{DIMENSION_ARROW_MM:g}" markerHeight="{2 * _DIM_HALF:g}" '
                     f'viewBox="0 0 {DIMENSION_ARROW_MM:g} {2 * _DIM_HALF:g}" refX="{DIMENSION_ARROW_MM:g}" '
                     f'refY="{_DIM_HALF:g}"><path d="M{DIMENSION_ARROW_MM:g},{_DIM_HALF:g} L0,0 L0,{2 * _DIM_HALF:g} z" '
                     f'fill="{_STYLE["dimension"][1]}"/></marker></defs>')


#: The page's construction line past its two points: an SVG marker at both ends of the line from
#: the known point to the point it fixes (`_construction`), PAST_MM long, the line's stroke.
_PAST_MARKER = (f'<defs><marker id="past" markerUnits="userSpaceOnUse" orient="auto-start-reverse" overflow="visible" '
                f'markerWidth="{PAST_MM:g}" markerHeight="1" refX="0" refY="0"><path d="M0,0 L{PAST_MM:g},0" '
                f'stroke="{_STYLE["construction"][1]}" stroke-width="{WEIGHT_MM["construction"]}" stroke-linecap="round"/></marker></defs>')


def style(s: Segment) -> tuple[float, str, str]:
    """How segment s is drawn: stroke width (mm, by its role: `WEIGHT_MM`), dash pattern, colour
    (by its kind: a kind not listed as a line)."""
    dash, colour = _STYLE.get(s.kind, _STYLE["line"])
    return WEIGHT_MM[role_of(s)], dash, colour


def _lang(lang: str) -> int:
    return check_lang(lang)


def title_of(plan: Plan, lang: str = "en") -> str:
    """The plan's title in `lang`, with its crank angle."""
    return f"{_plan_name(plan.kind, plan.title, lang)}, φ = {num(plan.phi_deg, lang, 6)}°"


def scale_text(plan_or_scale, lang: str = "en") -> str:
    """A scale line, e.g. 'μ_v = 0.2 m/(s·mm)' (of a Plan's scale, or of a Scale)."""
    s = plan_or_scale.scale if isinstance(plan_or_scale, Plan) else plan_or_scale
    return f"{s.symbol.replace('mu_', 'μ_')} = {num(s.value, lang, 6)} {unit(s.unit, lang)}"


def scales_of(plan: Plan) -> list:
    """Every scale the plan is drawn at: its own, then those of its segments drawn at another
    (the loads on a group plan, at a force scale)."""
    return [plan.scale] + list(dict.fromkeys(s.scale for s in plan.segments
                                             if s.scale is not None and s.scale.symbol.startswith("mu_")))


def labelled(name: str) -> bool:
    """Whether a point is lettered on the drawing: the texts' points are; a construction point (an
    arrow's tip or an arm's foot, named '<segment>:to', '<segment>:foot') is not."""
    return ":" not in name


def segment_label(s: Segment, lang: str) -> str:
    """A segment's name as the sheet letters it (a guide or a line of action in `lang`)."""
    if s.name.startswith("guide "):                 # "guide P(4,3)": the guide of the sliding pair 4-3, "напрямна 4-3"
        return text("guide", lang, pair=re.sub(r"^P\((\d+),(\d+)\)$", r"\1-\2", s.name[6:]))
    if s.name.startswith("slot "):                  # mechanism.py: "slot <link> <point>"
        k, P = s.name[5:].split(" ", 1)
        return text("slot", lang, k=k, P=P)
    if s.kind == "construction":                    # core.construction: "line <name>", "point <P>"
        return text("construction.line", lang, name=in_lang(s.name[5:], lang), P=s.start)
    if s.kind == "intersection":
        return text("construction.point", lang, P=s.start)
    return text(s.name, lang) if s.name in MESSAGES else in_lang(s.name, lang)


# ----------------------------------------------------------------------------- geometry shared by both

def _finite(z: complex) -> bool:
    return math.isfinite(z.real) and math.isfinite(z.imag)


def _drawable(plan: Plan) -> list[Segment]:
    return [s for s in plan.segments if _finite(plan.points[s.start]) and _finite(plan.points[s.end])]


#: How a path is drawn, by the first word of its name (mechanism sheet) or its first letter (ω, ε,
#: a couple M):
#: stroke width (mm), colour; any other path (paths of centres of mass, circles) thin and blue.
_PATH_STYLE = {"pin": (0.35, "#000"), "block": (0.5, "#000"), "support": (0.35, "#000"), "hatch": (0.25, "#000"),
               "com": (0.3, "#000"), "ω": (0.35, "#000"), "ε": (0.35, "#a33"), "M": (0.5, "#000")}


def _numbered(plan: Plan, name: str) -> bool:
    """Whether a point of the plan of positions is one of the numbered positions (A3, S2_3): its
    name less the position's number is the design position's point (A, S2)."""
    base = re.sub(r"_?\d+$", "", name)
    return base != name and base in plan.points


def _polygon_sides(plan: Plan | PlanCycle) -> list[Segment]:
    """A force plan's sides (its vector equation's; of a cycle whose order changes with the angle,
    those of any angle), else []."""
    names = {n for e in plan.equation for n in ((e,) if isinstance(e, str) else e)}
    return [s for s in plan.segments if s.name in names]


# ----------------------------------------------------------------------------- SVG

def _n(name: str, lang: str) -> str:
    """A name in a note, marked to be lettered as the drawing letters it (πa, F with subscript i2;
    of 'M_i2/l (a)' its first word), in `lang`'s letters (`lettering.in_lang`)."""
    head, sep, tail = in_lang(name, lang).partition(" ")
    return f"{mark(head)}{sep}{tail}"


#: A symbol in a plan's note: ω2, M_i5, F_i2(h), R05, ρ12 (letters, a digit, an optional (h)), or a
#: side of a plan between two points, p-b, pi-b, n2-b (short point names).
_SYMBOL = re.compile(r"(?<![\w\x01-])([A-Za-zωεπρ]+_?[A-Za-z]*\d+(?:\([a-z]\))?|[a-z]{1,2}\d*-[a-z]{1,2}\d*)(?![\w(-])")


def _symbols(note: str, lang: str) -> str:
    """A plan's note with its symbols marked (`_n`): lettered as the drawing letters them."""
    return _SYMBOL.sub(lambda m: _n(m.group(1), lang), note)


def _rich(s: str, size: float) -> str:
    """A note's SVG content: text escaped, its symbols (marked names, words with _ or ^) with their
    sub- and superscripts (`symbols.text_runs`, `labels.markup`)."""
    return markup(text_runs(s), size)


def _text_element(x: float, y: float, texts: list[str], variant, size: float, anchor: str = "start",
                  weight: str = "normal", ident: str = "", cls: str = "note") -> Element:
    """A line of text (its variants over the angles: notes marked as `_rich` letters them) at (x, y)."""
    attrs = {"class": cls, **({"id": ident} if ident else {}), "font-size": f"{size:.2f}", "text-anchor": anchor,
             "font-weight": weight}
    return Element("text", np.array([[[x, y]]]), attrs, texts=tuple(_rich(s, size) for s in texts),
                   variant=np.asarray(variant, dtype=int))


def _t(x: float, y: float, s: str, size: float, anchor: str = "start", weight: str = "normal",
       ident: str = "", cls: str = "note") -> str:
    return _text_element(x, y, [s], [0], size, anchor, weight, ident, cls).svg(0)


@lru_cache(maxsize=8192)
def _word_width(word: str, size: float) -> float:
    """Width of a word of a note at `size`, mm, as `_wrap` measures it (a page's token as wide as
    _TOKEN_SAMPLE): the notes of a page's angles repeat their words."""
    return text_width(TOKEN.sub(_TOKEN_SAMPLE, plain(word)), size)


def _wrap(s: str, size: float, width: float) -> list[str]:
    """`s` broken at spaces into lines no wider than `width` mm at `size` (a longer word alone);
    a line's width the sum of its words' and spaces' (a symbol's mark never holds a space; a page's
    token as wide as _TOKEN_SAMPLE)."""
    out, line, used = [], "", 0.0
    space = text_width(" ", size)
    for word in s.split(" "):
        w = _word_width(word, size)
        if line and used + space + w > width:
            out.append(line)
            line, used = word, w
        else:
            line, used = (f"{line} {word}", used + space + w) if line else (word, w)
    return out + [line] if line else out


def _fit(s: str, size: float, width: float, least: float = MIN_TEXT_MM) -> float:
    """The font size, at most `size` and at least `least`, at which `s` fits `width` mm."""
    return max(least, min(size, size * width / max(text_width(plain(s), size), 1e-9)))


#: How a vector under TINY_MM is drawn at an angle (`_tiny`): as it is, out of scale, negligible.
_AS_IS, _OUT, _NEGLIGIBLE = 0, 1, 2


def _tiny(cycle: PlanCycle) -> dict[str, np.ndarray]:
    """Vectors under TINY_MM at their scale at some angle where drawn: name -> how drawn at each angle (N,)
    (_OUT of scale at MIN_DRAWN_MM: a load at a scale of its own; _NEGLIGIBLE: a polygon's side
    or a plan's vector, not laid off; _AS_IS where not tiny or not drawn)."""
    how: dict[str, np.ndarray] = {}
    for s in cycle.segments:
        if s.kind not in _ARROWS:
            continue
        L = np.abs(cycle.points[s.end] - cycle.points[s.start])      # its own: a triad's force polygon
        tiny = (L < TINY_MM) & cycle.drawn(s)                          # names its sides anew at each angle
        if tiny.any():
            out = (s.scale is not None) & (L > ZERO_MM)
            how[s.name] = np.where(tiny, np.where(out, _OUT, _NEGLIGIBLE), how.get(s.name, _AS_IS))
    return how


def _tiny_at(tiny: dict[str, np.ndarray], i: int) -> dict[str, str]:
    """The tiny vectors of angle i: name -> "out" or "negligible" (the notes' words)."""
    return {k: "out" if v[i] == _OUT else "negligible" for k, v in tiny.items() if v[i] != _AS_IS}


def _collinear(cycle: PlanCycle, s: Segment, tiny: dict[str, np.ndarray]) -> np.ndarray:
    """At each angle (N,), whether a vector drawn out of scale would lie on another vector of the
    plan: one from the same point (within 0.5 mm) in the same direction (within 5 degrees), drawn
    as it is there."""
    a = cycle.points[s.start]
    d = cycle.points[s.end] - a
    out = np.zeros(cycle.n, dtype=bool)
    for o in cycle.segments:
        if o.kind not in _ARROWS or o.name == s.name:
            continue
        e = cycle.points[o.end] - cycle.points[o.start]
        turn = e * d.conjugate()
        as_is = tiny[o.name] == _AS_IS if o.name in tiny else True
        out |= as_is & (np.abs(cycle.points[o.start] - a) < 0.5) & (np.abs(e) > 0) \
            & (np.abs(np.angle(turn)) < math.radians(5.0))
    return out


#: The page's stand-ins for a note's numbers (`_note_lines` with `page`; page.js `amounts` writes
#: them at each angle), `_token`: a segment's value (its length times its scale, `num`), its length
#: (mm, 2 decimals), a result (`num`): the mark, the segment's index in its cycle or the result's, END.
VALUE, LENGTH, RESULT, END = "\ue000", "\ue002", "\ue003", "\ue001"
TOKEN = re.compile(f"([{VALUE}{LENGTH}{RESULT}])(\\d+){END}")
_TOKEN_SAMPLE = "-0000,00"                    # a token's width on the sheet: the widest number it may write


def _token(mark: str, k: int) -> str:
    """The token of `mark` (VALUE, LENGTH, RESULT) for the segment or result of index k."""
    return f"{mark}{k}{END}"


def _result_line(plan: Plan, lang: str, page: Mapping[str, int] | None = None) -> list[str]:
    """The results line; where `page`, the values as the page's tokens (`RESULT`)."""
    if not plan.results:
        return []
    parts = []
    for k, r in enumerate(plan.results):
        value = num(r.value, lang) if page is None else _token(RESULT, k)
        part = f"{_n(r.symbol, lang)} = {value}\u00a0{unit(r.unit, lang)}".rstrip()
        parts.append(part + (f" ({text(r.how, lang)})" if r.how else ""))
    return [f"{text('results', lang)}: " + "; ".join(parts)]


def _note_lines(plan: Plan, lang: str, tiny: dict[str, str], page: Mapping[str, int] | None = None) -> list[str]:
    """The sheet's notes in `lang`: legend, the plan's notes, results, equation, tiny vectors with
    their values and lengths; where `page` (segment name -> its index in the cycle), those numbers
    as the page's tokens (`VALUE`, `LENGTH`, `RESULT`: page.js writes them at each angle)."""
    base = plan.kind.partition(":")[0]
    lines = [text(f"legend.{base}", lang)] if f"legend.{base}" in MESSAGES else []
    lines += [_symbols(phrase(n, lang), lang) for n in plan.notes] + ([accuracy(*plan.accuracy, lang, False)] if plan.accuracy else [])
    lines += _result_line(plan, lang, page)
    if plan.equation:
        lines.append(f"{text('equation', lang)}: " + " + ".join(_n(e, lang) for e in plan.equation) + " = 0")
    for s in _drawable(plan):
        if s.name in tiny:
            L = abs(plan.points[s.end] - plan.points[s.start])
            key = "out of scale" if tiny[s.name] == "out" else "negligible"
            star = "*" if tiny[s.name] == "out" else ""
            value, length = (num(s.value, lang), num(L, lang, decimals=2)) if page is None else \
                (_token(VALUE, page[s.name]), _token(LENGTH, page[s.name]))
            lines.append(f"{_n(s.name, lang)}{star} = {value}\u00a0{unit(s.unit, lang)}: {text(key, lang, length=length)}")
    if plan.kind == "lever":
        lines += [text("lever turned", lang), text("arms natural", lang)]
    return lines


def _table_row(s: Segment, length: str, value: str, lang: str, sides: bool) -> str:
    """The notes' row of a vector or arm drawn: its length `length` (mm) and, but for an arm kept
    in mm, what it stands for (`value`, in its unit); a force plan's side by its ends."""
    mm = unit("mm", lang)
    if sides:
        return f"{text('segment', lang)} {_n(s.start + '-' + s.end, lang)} = {length} {mm} → {_n(s.name, lang)} = {value}\u00a0{unit(s.unit, lang)}".rstrip()
    if s.unit == "mm":                            # a length kept as drawn (the lever's arms): once
        return f"{_n(s.name, lang)} = {length} {mm}"
    return f"{_n(s.name, lang)}: {length} {mm} → {value}\u00a0{unit(s.unit, lang)}".rstrip()


def _tabled(s: Segment) -> bool:
    """Whether segment s has a row in the notes (`_table_row`): a vector or an arm."""
    return s.kind in (*_ARROWS, "arm")


def _table_rows(plan: Plan, lang: str) -> list[str]:
    """Every vector and arm drawn: its length and what it stands for."""
    return [_table_row(s, num(plan.length_mm(s.name), lang, decimals=2), num(s.value, lang), lang,
                       plan.kind.startswith("forces:"))
            for s in plan.segments if _tabled(s) and math.isfinite(s.value)]


#: The legend's sample stroke and the gaps after it and after its words, mm.
_SAMPLE_MM, _SAMPLE_GAP, _ENTRY_GAP = 7.0, 1.2, 3.5


def _legend(cycle: PlanCycle, lang: str) -> tuple[list[str], tuple[float, float, float, float]]:
    """The sheet's legend of line weights (`WEIGHT_MM`): a sample stroke of each role drawn on the
    sheet, in the width of that role and the dash and colour of its first segment, with the
    role's name and width, in rows at the frame's bottom left beside the title block: its SVG and
    its box (x0, y0, x1, y1), mm (its top y0: the notes go above it)."""
    first = {}
    for s in cycle.segments:
        if cycle.drawn(s).any():
            first.setdefault(role_of(s), s)
    x0, x1 = _FRAME[0] + 3, _TITLE_BLOCK[0] - 3
    head = text("legend.lines", lang)
    entries = [(first[r], f"{text(f'role.{r}', lang)} {num(WEIGHT_MM[r], lang, decimals=2)}") for r in ROLES if r in first]
    start = x0 + text_width(head, _NOTE_MM) + _ENTRY_GAP             # each row's first entry: after the head
    rows, x, row = [], start, 0
    for seg, words in entries:
        w = _SAMPLE_MM + _SAMPLE_GAP + text_width(words, _NOTE_MM)
        if x + w > x1 and x > start:
            x, row = start, row + 1
        rows.append((seg, words, x, row))
        x += w + _ENTRY_GAP
    n_rows = row + 1 if entries else 0
    if not n_rows:
        return [], (x0, _FRAME[3] - 1.5, x0, _FRAME[3] - 1.5)
    y0 = _FRAME[3] - 1.5 - _LINE_STEP * n_rows
    base = y0 + ASCENT * _NOTE_MM
    size = f'font-size="{_NOTE_MM:.2f}"'
    out = [f'<g id="legend" class="note"><text x="{x0:.1f}" y="{base:.1f}" {size}>{escape(head)}</text>']
    for seg, words, x, row in rows:
        width, dash, colour = style(seg)
        y = base + _LINE_STEP * row
        dashed = f' stroke-dasharray="{dash}"' if dash else ""
        out.append(f'<line data-role="{role_of(seg)}" x1="{x:.1f}" y1="{y - 0.9:.1f}" x2="{x + _SAMPLE_MM:.1f}" '
                   f'y2="{y - 0.9:.1f}" stroke="{colour}" stroke-width="{width}"{dashed}/>'
                   f'<text x="{x + _SAMPLE_MM + _SAMPLE_GAP:.1f}" y="{y:.1f}" {size}>{escape(words)}</text>')
    out.append("</g>")
    right = max(x + _SAMPLE_MM + _SAMPLE_GAP + text_width(words, _NOTE_MM) for _, words, x, _ in rows)
    return out, (x0, y0, right, _FRAME[3] - 1.5)


def _row_columns(rows: list[str], width: float, left: bool) -> tuple[float, int]:
    """The notes' rows of segments in columns across `width` mm (one in a column at the plan's
    left): the columns' pitch (the widest row and 4 mm; a page's token as wide as _TOKEN_SAMPLE),
    rows in a column."""
    col_w = max((text_width(TOKEN.sub(_TOKEN_SAMPLE, plain(r)), _NOTE_MM) for r in rows), default=0.0) + 4.0
    cols = 1 if left or not rows else max(1, int(width // col_w))
    return col_w, -(-len(rows) // cols)


def _notes_block(plan: Plan, lang: str, tiny: dict[str, str], left: bool, nofit: bool = False,
                 draw: bool = True, bottom: float = _FRAME[3] - 1.5, least: Mapping[bool, int] | None = None
                 ) -> tuple[list[str], tuple[float, float, float, float], tuple[float, float, float]]:
    """SVG of the notes (none where not `draw`), the drawing area they leave: below the plan
    (bottom left, from `bottom` up (the legend's top), beside the title block) or, for a tall
    plan, in a column at its left, and where the notes' lines go (x, first baseline, width; mm);
    room for at least `least[left]` lines (the page's notes of every angle: `_room`)."""
    x0 = _FRAME[0] + 3
    width = _LEFT_NOTES_MM if left else _BELOW_NOTES_MM
    lines = [w for n in _note_lines(plan, lang, tiny) for w in _wrap(n, _NOTE_MM, width)]
    if nofit:
        lines.append(text("nofit", lang))
    rows = [w for r in _table_rows(plan, lang) for w in (_wrap(r, _NOTE_MM, width) if left else [r])]
    col_w, per_col = _row_columns(rows, width, left)
    height = _LINE_STEP * max(len(lines) + per_col, (least or {}).get(left, 0))
    top = _AREA[1] if left else bottom - height
    out, where = [], (x0, top + ASCENT * _NOTE_MM, width)
    if draw:
        out.append('<g id="notes">')
        y = where[1]
        for line in lines:
            out.append(_t(x0, y, line, _NOTE_MM))
            y += _LINE_STEP
        for k, r in enumerate(rows):
            out.append(_t(x0 + col_w * (k // per_col), y + _LINE_STEP * (k % per_col), r, _NOTE_MM))
        out.append("</g>")
    if left:
        return out, (x0 + width + 4.0, _AREA[1], _AREA[2], _AREA[3]) if top + height < bottom else None, where
    return out, (_AREA[0], _AREA[1], _AREA[2], min(_AREA[3], top - 3.0)), where


def _placed_clear(box: tuple[float, float, float, float], spare: float, area: tuple[float, float, float, float],
                  notes: tuple[float, float, float, float]) -> bool:
    """Whether a drawing of extent `box` (plan mm), grown by `spare` mm on every side and centred
    in `area` as `_sheet` places it, lies inside the frame and clear of the notes' block `notes`
    (x0, y0, x1, y1; with the legend below it) and the title block (sheet mm)."""
    w, h = box[2] - box[0] + 2 * spare, box[3] - box[1] + 2 * spare
    cx, cy = (area[0] + area[2]) / 2, (area[1] + area[3]) / 2
    x0, y0, x1, y1 = cx - w / 2, cy - h / 2, cx + w / 2, cy + h / 2
    inside = _FRAME[0] <= x0 and _FRAME[1] <= y0 and x1 <= _FRAME[2] and y1 <= _FRAME[3]
    return inside and not any(x0 < b[2] and b[0] < x1 and y0 < b[3] and b[1] < y1 for b in (notes, _TITLE_BLOCK))


def _layout(plan: Plan, lang: str, tiny: dict[str, str], box: tuple[float, float, float, float], spare: float,
            draw: bool = True, bottom: float = _FRAME[3] - 1.5, least: tuple[Mapping[bool, int] | None, ...] = (None,)
            ) -> tuple[list[str], tuple[float, float, float, float], tuple[float, float, float]]:
    """The notes of `plan` (SVG where `draw`, above `bottom`), the drawing area for a drawing of
    extent `box` and where the notes' lines go (`_notes_block`):
    notes below where it fits above them, else in a column at its left where it fits beside them,
    else below with the drawing at their right, above the title block, where it fits there (a tall
    narrow plan under many notes: the lever of a slotted link with a far point a'), else below
    with a note that it does not fit. Fitting: as drawn, `spare` mm to spare on every
    side (room for a vector drawn out of scale: `_room`), inside the frame and clear of the notes
    (their block from their first line down to the frame, the legend's row with it) and the title
    block (`_placed_clear`); room for at least the lines of the first of `least` with which it fits,
    else of the last (`_notes_block`)."""
    for lines in least:
        for left in (False, True):
            notes, area, where = _notes_block(plan, lang, tiny, left, draw=draw, bottom=bottom, least=lines)
            if area is not None and _placed_clear(box, spare, area, (where[0], where[1] - ASCENT * _NOTE_MM,
                                                                      where[0] + where[2], _FRAME[3])):
                return notes, area, where
    notes, _, where = _notes_block(plan, lang, tiny, False, draw=draw, bottom=bottom, least=least[-1])
    beside = (where[0] + where[2] + 4.0, _AREA[1], _AREA[2], _TITLE_BLOCK[1] - 3.0)
    if _placed_clear(box, spare, beside, (where[0], where[1] - ASCENT * _NOTE_MM, where[0] + where[2], _FRAME[3])):
        return notes, beside, where
    return _notes_block(plan, lang, tiny, False, nofit=True, draw=draw, bottom=bottom, least=least[-1])


def _note_groups(cycle: PlanCycle, lang: str, tiny: dict[str, np.ndarray]) -> tuple[list[list[str]], np.ndarray]:
    """The notes of every angle (`_note_lines`, their numbers as the page's tokens), the angles
    grouped by what their notes are made of (the plan's notes, tiny vectors, accuracy, equation,
    how each result is found) in one pass: each group's lines (read once, of the plan cut to its
    tiny vectors; in the order of their first angle) and each angle's group (N,)."""
    segments = tuple(s for s in cycle.segments if s.name in tiny)       # all of its drawing the notes read
    index = {s.name: k for k, s in enumerate(cycle.segments)}
    light = replace(cycle, points={k: cycle.points[k] for s in segments for k in (s.start, s.end)},
                    segments=segments, paths={})
    drawn = np.array([light.drawn(s) for s in segments], dtype=bool).reshape(len(segments), cycle.n)
    acc = np.full(cycle.n, -1.0) if cycle.accuracy is None else \
        np.where(cycle.accuracy[0] < cycle.accuracy[1], cycle.accuracy[0], -1.0)     # stated where below the rule
    per_angle_equation = cycle.equation and not isinstance(cycle.equation[0], str)
    keys = np.column_stack([*tiny.values(), drawn.T, acc,                   # what an angle's notes are made of
                            _variants(list(cycle.notes) if cycle.notes else [()] * cycle.n)[1],
                            _variants(list(cycle.equation) if per_angle_equation else [()] * cycle.n)[1],
                            *(_variants([r.how] * cycle.n if isinstance(r.how, str) else list(r.how))[1]
                              for r in cycle.results)])
    _, first, inverse = np.unique(keys.astype(float), axis=0, return_index=True, return_inverse=True)
    order = np.argsort(first)                          # the groups in the order of their first angle
    first, inverse = first[order], np.argsort(order)[inverse.reshape(-1)]
    return [_note_lines(light.at(j), lang, _tiny_at(tiny, j), page=index) for j in first.tolist()], inverse


def _wrapped(groups: list[list[str]], width: float) -> list[list[str]]:
    """Each group's note lines wrapped to `width` mm (`_wrap`; each distinct line once)."""
    wrapped: dict[str, list[str]] = {}
    for notes in groups:
        for n in notes:
            if n not in wrapped:
                wrapped[n] = _wrap(n, _NOTE_MM, width)
    return [[w for n in notes for w in wrapped[n]] for notes in groups]


def _cycle_notes(cycle: PlanCycle, notes: tuple[list[list[str]], np.ndarray],
                 where: tuple[float, float, float], bottom: float, placer: Placer) -> list[Element]:
    """The notes of every angle (`notes`: `_note_groups`, wrapped to the width of `where`:
    `_wrapped`; page.js writes each angle's numbers from
    the lengths and values the page holds) as lines of text at `where` (x, first baseline, width;
    `_notes_block`), as many as fit above `bottom` (the legend's top): line k shows the k-th line
    of each angle's notes where it has one (its texts once, an index per angle) and where it is
    clear of the plan's arrowheads, points and letters (`placer`: the plan of an angle may reach
    into the notes' room where the cycle's is larger than the room; a token as wide as
    _TOKEN_SAMPLE)."""
    x, y, width = where
    room = int((bottom - (y - ASCENT * _NOTE_MM)) / _LINE_STEP + 1e-9)     # whole lines (2 x 5.1 mm is 2)
    groups = [lines[:room] for lines in notes[0]]
    inverse = notes[1]
    out = []
    for k in range(max(map(len, groups), default=0)):
        texts, variant = _variants([lines[k] if k < len(lines) else "" for lines in groups])
        variant = variant[inverse]
        base = y + k * _LINE_STEP
        w = np.array([text_width(TOKEN.sub(_TOKEN_SAMPLE, plain(t)), _NOTE_MM) for t in texts])[variant]
        box = np.column_stack([np.full(cycle.n, x), np.full(cycle.n, base - ASCENT * _NOTE_MM), x + w,
                               np.full(cycle.n, base + (SUB_DROP + DESCENT) * _NOTE_MM)])
        has = np.array([k < len(lines) for lines in groups])[inverse] & placer.clear(box)
        e = _text_element(x, base, texts, variant, _NOTE_MM, cls="note")
        out.append(Element("text", np.where(has[:, None, None], e.xy, np.nan), e.attrs, texts=e.texts, variant=e.variant))
    return out


def _page_rows(cycle: PlanCycle, lang: str) -> tuple[list[str], list[np.ndarray]]:
    """The rows of the segments with a value at some angle (`_table_row`, their numbers as the
    page's tokens), and at which angles each has one (N,)."""
    sides = cycle.kind.startswith("forces:")
    value = [(k, np.broadcast_to(np.isfinite(np.asarray(s.value, dtype=float)), (cycle.n,)))
             for k, s in enumerate(cycle.segments) if _tabled(s)]
    return ([_table_row(cycle.segments[k], _token(LENGTH, k), _token(VALUE, k), lang, sides) for k, v in value if v.any()],
            [v for _, v in value if v.any()])


def _cycle_rows(cycle: PlanCycle, lang: str, where: tuple[float, float, float], first: int, bottom: float,
                placer: Placer) -> list[Element]:
    """The rows of the segments (`_table_row`, their numbers as the page's tokens: page.js writes
    each angle's from the lengths the page holds and the scale) below the notes' first `first`
    lines at `where` (x, first baseline, width), in as many columns as the width holds (as
    `_notes_block`), those that fit above `bottom`: one text of a line per row, at each angle the
    rows of the segments with a value there whose line is clear of the plan (`placer`; a token as
    wide as _TOKEN_SAMPLE)."""
    x, y, width = where
    rows, value = _page_rows(cycle, lang)
    if not rows:
        return []
    col_w, per_col = _row_columns(rows, width, width == _LEFT_NOTES_MM)
    room = int((bottom - (y - ASCENT * _NOTE_MM)) / _LINE_STEP + 1e-9) - first
    lines, shown = [], []
    for j, (r, v) in enumerate(zip(rows, value)):
        if j % per_col >= room:
            continue
        w = text_width(TOKEN.sub(_TOKEN_SAMPLE, plain(r)), _NOTE_MM)
        rx, base = x + col_w * (j // per_col), y + (first + j % per_col) * _LINE_STEP
        box = np.tile([rx, base - ASCENT * _NOTE_MM, rx + w, base + (SUB_DROP + DESCENT) * _NOTE_MM], (cycle.n, 1))
        lines.append(f'<tspan x="{rx:.1f}" y="{base:.1f}">{_rich(r, _NOTE_MM)}</tspan>')
        shown.append(v & placer.clear(box))
    texts, variant = _variants([tuple(np.flatnonzero(m)) for m in np.array(shown, dtype=bool).T])
    e = _text_element(x, y, [""], [0], _NOTE_MM, cls="note")
    return [Element("text", e.xy, e.attrs, texts=tuple("".join(lines[j] for j in t) for t in texts), variant=variant)]


def _variants(strings: list) -> tuple[list, np.ndarray]:
    """Per-angle strings (or other hashables) as (the distinct ones, in order of first use; each
    angle's index (N,))."""
    index: dict = {}
    variant = np.array([index.setdefault(s, len(index)) for s in strings], dtype=int)
    return list(index), variant


def _plan_name(kind: str, title: str, lang: str) -> str:
    """A plan's name in `lang` (its title where the catalogue has none), with its group: 'Plan of group 2-3'."""
    base, _, rest = kind.partition(":")
    name = text(f"plan.{base}", lang) if f"plan.{base}" in MESSAGES else title
    return name + (" " + rest.replace(",", "-") if rest else "")


def _title_block(cycle: PlanCycle, lang: str, mechanism: str) -> list[Element]:
    """The title block's texts over the angles (the title and the angle line change with φ)."""
    x0, y0, x1, y1 = _TITLE_BLOCK
    w = x1 - x0 - 6
    phi = [num(p, lang, 6) for p in cycle.phi_deg.tolist()]
    titles, tv = _variants([f"{_plan_name(cycle.kind, t, lang)}, φ = {p}°" for t, p in zip(cycle.titles, phi)])
    angles, av = _variants([f"{text('angle', lang)} φ = {p}°" for p in phi])
    scales = scales_of(cycle)
    sc = f"{text('scale' if len(scales) == 1 else 'scales', lang)}: " + "; ".join(scale_text(s, lang) for s in scales)
    return [_text_element(x0 + 3, y0 + 8, titles, tv, min(_fit(t, 5.0, w) for t in titles), weight="bold", cls="title"),
            _text_element(x0 + 3, y0 + 19.5, [sc], [0], _fit(sc, 4.5, w), ident="scale", cls="title"),
            *_mechanism_lines(mechanism, x0 + 3, y0, w),
            _text_element(x0 + 3, y0 + 36.3, angles, av, MIN_TEXT_MM, cls="title"),
            _text_element(x0 + 3, y0 + 42, [text("sheet", lang)], [0], MIN_TEXT_MM, cls="title")]


def _mechanism_lines(mechanism: str, x: float, y0: float, w: float) -> list[Element]:
    """The mechanism's name in the title block (top `y0`, `w` mm wide): one line at y0 + 30 where it
    fits at MIN_TEXT_MM (at most 3.5 mm), else broken in two lines at y0 + 27.9 and y0 + 31.9
    (the second "mechanism-2"), each fit to the width, none under MIN_TEXT_MM."""
    lines = _wrap(mechanism, MIN_TEXT_MM, w) if text_width(plain(mechanism), MIN_TEXT_MM) > w else [mechanism]
    if len(lines) < 2:
        return [_text_element(x, y0 + 30, [mechanism], [0], _fit(mechanism, MIN_TEXT_MM, w), ident="mechanism", cls="title")]
    first, rest = lines[0], " ".join(lines[1:])
    return [_text_element(x, y0 + 27.9, [first], [0], _fit(first, MIN_TEXT_MM, w), ident="mechanism", cls="title"),
            _text_element(x, y0 + 31.9, [rest], [0], _fit(rest, MIN_TEXT_MM, w), ident="mechanism-2", cls="title")]


def _arrowhead(a: np.ndarray, b: np.ndarray, length: np.ndarray | float,
               arc: bool = False) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Arrowheads, tips at b (N, 2) pointing from a: (their corners (N, 3, 2), tip first; their
    boxes (N, 4); the lines' new ends (N, 2)); on an arc (a sense, a couple) ARC_HEAD_MM long
    whatever the chord a-b, else at most ARROW_MM, 0.3 of the line and `length`."""
    d = b - a
    L = np.hypot(d[:, 0], d[:, 1])
    with np.errstate(invalid="ignore", divide="ignore"):
        u = d / L[:, None]
    h = np.full(len(L), ARC_HEAD_MM) if arc else np.minimum(np.minimum(ARROW_MM[0], np.maximum(0.3 * L, 0.8)), length)
    hw = np.maximum(0.3, ARROW_MM[1] * h / ARROW_MM[0])
    back = b - u * h[:, None]
    side = np.column_stack([-u[:, 1], u[:, 0]]) * hw[:, None]
    pts = np.stack([b, back + side, back - side], axis=1)
    box = np.concatenate([pts.min(axis=1), pts.max(axis=1)], axis=1)
    return pts, box, b - u * (0.6 * h)[:, None]


def _on_sheet(z: np.ndarray, tx, ty) -> np.ndarray:
    """Plan points (N, complex, mm, y up) or paths (N or 1, K) on the sheet (..., 2) (mm, y down),
    moved by (tx, ty) (scalars, or (N,) one each angle); NaN where not finite."""
    if np.ndim(tx) and z.ndim == 2:
        tx, ty = tx[:, None], ty[:, None]
    xy = np.stack([z.real + tx, ty - z.imag], axis=-1)
    return np.where(np.isfinite(xy).all(axis=-1, keepdims=True), xy, np.nan)


def _extents(cycle: PlanCycle) -> np.ndarray:
    """`extent_cycle` as rows (N, 4), NaN at an angle where nothing is finite (drawn)."""
    ext = np.column_stack(extent_cycle(cycle))
    some = np.zeros(cycle.n, dtype=bool)
    for v in (*cycle.points.values(), *cycle.paths.values()):
        some |= (np.isfinite(v.real) & np.isfinite(v.imag)).reshape(len(v), -1).any(axis=1)
    return np.where(some[:, None], ext, np.nan)


def _union(ext: np.ndarray) -> tuple[float, float, float, float]:
    """The extent over every angle (the cycle's `extent`), (0, 0, 0, 0) where nothing is finite."""
    if not np.isfinite(ext).any():
        return 0.0, 0.0, 0.0, 0.0
    return (float(np.nanmin(ext[:, 0])), float(np.nanmin(ext[:, 1])), float(np.nanmax(ext[:, 2])),
            float(np.nanmax(ext[:, 3])))


def _shifts(ext: np.ndarray, area: tuple[float, float, float, float], tx: float, ty: float):
    """The plan's place on the sheet at each angle: (tx, ty) of the whole cycle, moved at an angle
    only as far as brings that angle's extent inside the area (centred where wider): scalars where
    it moves at no angle, else (N,) each."""
    lo, hi = np.array(area[:2]), np.array(area[2:])
    s0 = np.column_stack([ext[:, 0] + tx, ty - ext[:, 3]])          # each angle's box on the sheet
    s1 = np.column_stack([ext[:, 2] + tx, ty - ext[:, 1]])
    move = np.where(s1 - s0 > hi - lo, (lo + hi) / 2 - (s0 + s1) / 2,
                    np.where(s0 < lo, lo - s0, np.where(s1 > hi, hi - s1, 0.0)))
    move = np.nan_to_num(move)
    if not move.any():
        return tx, ty
    return tx + move[:, 0], ty + move[:, 1]


def _where(mask: np.ndarray, xy: np.ndarray) -> np.ndarray:
    """xy (N, ..., 2) where mask (N,), else NaN."""
    return np.where(mask.reshape(-1, *([1] * (xy.ndim - 1))), xy, np.nan)


def _packed(xy: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """A polyline's finite points first, in order (R, K, 2), and how many at each angle (R,)."""
    fin = np.isfinite(xy).all(axis=2)
    idx = np.argsort(~fin, axis=1, kind="stable")
    return np.take_along_axis(xy, idx[..., None], axis=1), fin.sum(axis=1)


def _lines(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Segments (..., 4) from a to b (..., 2)."""
    return np.concatenate([a, b], axis=-1)


@dataclass(frozen=True)
class _Name:
    """A label to place: its text at each angle (`texts[variant]`), anchor (N, 2), the segment's
    other end (N, 2) or None, size and class."""
    texts: tuple[str, ...]
    variant: np.ndarray
    anchor: np.ndarray
    along: np.ndarray | None
    size: float
    cls: str


def _labels(placer: Placer, names: list[_Name]) -> list[Element]:
    """Each label placed at every angle (in order), as its text and its leader."""
    out = []
    for nm in names:
        pl = placer.place(nm.texts, nm.variant, nm.size, nm.anchor, nm.along)
        out.append(Element("text", pl.xy[:, None], {"class": nm.cls, "font-size": f"{nm.size:.2f}"},
                           texts=tuple(label_markup(t, nm.size) for t in nm.texts), variant=nm.variant))
        if np.isfinite(pl.leader).any():
            out.append(Element("line", pl.leader.reshape(-1, 2, 2), {"class": "leader", "stroke": "#777",
                                                                       "stroke-width": "0.13"}))
    return out


def _paths(cycle: PlanCycle, lang: str, contract: bool, at, placer: Placer,
           names: list[_Name]) -> list[Element]:
    """The plan's polylines (a rotation's sense, a couple: with an arrowhead at the arc's end and
    its name), their lines given to the placer."""
    out = []
    n = cycle.n
    for name, path in cycle.paths.items():
        xy = at(path)                                           # (N or 1, K, 2)
        pts, count = _packed(xy)
        if not (count >= 2).any():
            continue
        width, colour = _PATH_STYLE.get(name.split(" ")[0], _PATH_STYLE.get(name[:1], (0.25, "#1f5fa8")))
        tip = text(name, lang) if name in MESSAGES else in_lang(name, lang) if name[:1] in "ωεM" else ""   # no English tooltip
        attrs = {"fill": "none", "stroke": colour, "stroke-width": f"{width}"}
        if contract:
            attrs.update({"data-plan": escape(cycle.kind), "data-path": escape(name)})
        out.append(Element("polyline", xy, attrs, title=escape(tip)))
        placer.line(_lines(pts[:, :-1], pts[:, 1:]))
        if name[:1] in "ωεM":                 # a rotation's sense, a couple: an arrowhead at the arc's end, its name
            drawn = count >= 2
            r = np.arange(len(pts))
            last, prev = pts[r, np.maximum(count - 1, 0)], pts[r, np.maximum(count - 2, 0)]
            head, box, _ = _arrowhead(prev, last, ARC_HEAD_MM, arc=True)
            out.append(Element("path", _where(drawn, head), {"class": "arrowhead arc", "fill": colour}))
            placer.block(_where(drawn, box))
            mid = _where(drawn, pts[r, count // 2])
            names.append(_Name((in_lang(name, lang),), np.zeros(n, dtype=int), np.broadcast_to(mid, (n, 2)), None,
                               _NAME_MM, "name"))
    return out


def _segments(cycle: PlanCycle, lang: str, contract: bool, at, tiny: dict[str, np.ndarray], placer: Placer,
              names: list[_Name]) -> list[Element]:
    """Every segment drawn where its ends are finite: its line (out of scale where tiny, a
    negligible one not at all: an empty <g> in the contract), a vector's arrowhead; its name
    where the texts letter it, and where negligible; obstacles given to the placer."""
    out = []
    n = cycle.n
    sides = {s.name for s in _polygon_sides(cycle)} or None        # a polygon: every side and chord named
    zero = np.zeros(n, dtype=int)
    spots: dict[str, tuple[np.ndarray, np.ndarray | None]] = {}       # where each step's number goes
    for s in cycle.segments:
        if _dimension(cycle, s):
            continue
        za, zb = cycle.points[s.start], cycle.points[s.end]
        a, b = at(za), at(zb)
        ok = np.isfinite(a).all(axis=1) & np.isfinite(b).all(axis=1) & cycle.drawn(s)
        if not ok.any():
            continue
        width, dash, colour = style(s)
        label = escape(segment_label(s, lang))
        Lz = np.abs(zb - za)
        data = {"data-plan": escape(cycle.kind), "data-segment": escape(s.name)} if contract else {}
        attrs = {"stroke": colour, "stroke-width": f"{width}", **({"stroke-dasharray": dash} if dash else {}), **data}
        if s.kind in ("construction", "intersection"):
            element, spot = _construction(s.kind, a, b, ok, attrs, label, placer, contract)
            if s.name in spots:               # the same step in another order of a triad's sides
                spot = (np.where(np.isfinite(spot[0]), spot[0], spots[s.name][0]), None)
            spots[s.name] = spot
            out.append(replace(element, length_mm=Lz if contract else None))
            none = ok & ~np.asarray(element.drawn()).reshape(-1)       # a line of no direction (v_B = 0): not drawn
            if contract and none.any():
                out.append(Element("g", _where(none, a)[:, None], {"class": "negligible", **data}, length_mm=Lz))
            continue
        spots[s.name] = (a, b)
        L = Lz.copy()
        how = np.where(ok, tiny.get(s.name, zero), _AS_IS)
        out_ = how == _OUT
        if out_.any():
            with np.errstate(invalid="ignore", divide="ignore"):
                u = (b - a) / L[:, None]
            side = _where(out_ & _collinear(cycle, s, tiny), np.column_stack([-u[:, 1], u[:, 0]]) * SIDE_MM)
            shift = np.nan_to_num(side)                          # beside the load it would hide under (G3* along F_p)
            a = a + shift
            b = np.where(out_[:, None], a + u * MIN_DRAWN_MM, b)
            L = np.where(out_, MIN_DRAWN_MM, L)
        neg = how == _NEGLIGIBLE
        if contract and neg.any():
            out.append(Element("g", _where(neg, a)[:, None], {"class": "negligible", **data}, length_mm=Lz))
        drawn = ok & ~neg
        if s.kind in _ARROWS:
            head, box, end = _arrowhead(a, b, L)
            placer.block(_where(drawn, box))
        else:
            end = b
            placer.block(_where(drawn, np.concatenate([b - 0.5, b + 0.5], axis=1)))     # a line's end
        for code, title in ((_AS_IS, label), (_OUT, label + "*")):
            lit = drawn & (how == code)
            if lit.any():
                out.append(Element("line", _where(lit, np.stack([a, end], axis=1)), attrs, title=title,
                                   length_mm=Lz if contract else None))
        if s.kind in _ARROWS:
            out.append(Element("path", _where(drawn, head), {"class": "arrowhead", "fill": colour}))
        placer.line(_where(drawn, _lines(a, b)), heavy=s.kind in _ARROWS or role_of(s) == "link")
        named = s.kind not in ("link", "extension") and (not labelled(s.end) or (sides is not None and s.kind == "vector")
                                                         or s.kind == "arm")
        lettered = neg | (drawn & named)
        if lettered.any():
            names.append(_Name((segment_label(s, lang), segment_label(s, lang) + "*"), out_.astype(int),
                               _where(lettered, a), _where(drawn & named, b), _NAME_MM, "name"))
    steps = [cycle.steps_at(i) for i in range(n)]       # the construction's steps numbered: (1), (2), ...
    for name in dict.fromkeys(name for at_i in steps for name in at_i):
        if name in spots:
            numbers = [at_i.index(name) + 1 if name in at_i else 0 for at_i in steps]
            texts, variant = _variants([f"({k})" if k else "" for k in numbers])
            on = np.array(numbers) > 0
            a, b = spots[name]
            names.append(_Name(tuple(texts), variant, _where(on, a), None if b is None else _where(on, b), _NUMBERED_MM, "step"))
    return out


def _dimension(cycle: PlanCycle, s: Segment) -> bool:
    """Whether `s` is drawn as a dimension line (`_dimensions`): an arm on the lever."""
    return cycle.kind == "lever" and s.kind == "arm"


def _dimensions(cycle: PlanCycle, lang: str, contract: bool, at, placer: Placer, names: list[_Name]) -> list[Element]:
    """The lever's arms as dimension lines (seed 002 fig. 1.12: h_Fi2 = 37.67 mm): each a thin
    line from the pole to the foot on its force's line, with an arrowhead at both ends (on a
    sheet, the force's line carried on to the foot as a thin construction line); arms that
    coincide at an angle (the loads at b of a slider, all across p-b) drawn and lettered once,
    their loads in one subscript, 'h_G3,Fi3,Fp = 54,60'; the value (mm, as drawn) on a sheet,
    the names only on the page (`contract`: its step equations give the lengths), whose
    arrowheads are the line's markers (`_DIMENSION_MARKER`: no coordinates per angle).
    Obstacles given to the placer."""
    arms = [s for s in cycle.segments if _dimension(cycle, s)]
    if not arms:
        return []
    (dash, colour), width = _STYLE["dimension"], WEIGHT_MM["auxiliary"]
    (ext_dash, ext_colour), ext_width = _STYLE["line"], WEIGHT_MM["construction"]
    forces = {arm_name(f.name): f for f in cycle.segments if f.unit == "N"}
    starts = [at(cycle.points[s.start]) for s in arms]
    ends = [at(cycle.points[s.end]) for s in arms]
    owner = coincident(np.stack(ends, axis=1))                     # (N, M): the arm lettered for each
    mm = [cycle.length_mm(s.name) for s in arms]
    out = []
    for j, (s, a, b) in enumerate(zip(arms, starts, ends)):
        ok = np.isfinite(a).all(axis=1) & np.isfinite(b).all(axis=1) & cycle.drawn(s)
        if not ok.any():
            continue
        if not contract:                          # the force's line carried to the foot (an extension line)
            c = at(cycle.points[forces[s.name].start])
            far = ok & (np.hypot(*(b - c).T) > 0.5)
            out.append(Element("line", _where(far, np.stack([c, b], axis=1)),
                               {"stroke": ext_colour, "stroke-width": f"{ext_width}", "stroke-dasharray": ext_dash}))
            placer.line(_where(far, _lines(c, b)))
        data = {"data-plan": escape(cycle.kind), "data-segment": escape(s.name),
                "marker-start": "url(#dimension)", "marker-end": "url(#dimension)"} if contract else {}
        out.append(Element("line", _where(ok, np.stack([a, b], axis=1)), {"stroke": colour, "stroke-width": f"{width}", **data},
                           title=escape(segment_label(s, lang)), length_mm=mm[j] if contract else None))
        lead = ok & (owner[:, j] == j)
        placer.line(_where(ok, _lines(a, b)))
        for tail, tip in ((a, b), (b, a)):
            head, box, _ = _arrowhead(tail, tip, DIMENSION_ARROW_MM)
            if not contract:
                out.append(Element("path", _where(lead, head), {"class": "arrowhead dimension", "fill": colour}))
            placer.block(_where(ok, box))
        strings = ["h_" + ",".join(arms[m].name[2:] for m in np.nonzero(owner[i] == j)[0])     # h_G3,Fi3,Fp
                   + ("" if contract else f" = {num(mm[j][i], lang, decimals=2)}") if lead[i] else ""
                   for i in range(cycle.n)]
        texts, variant = _variants(strings)
        names.append(_Name(tuple(texts), variant, _where(lead, a), _where(lead, b), _NAME_MM, "name"))
    return out


def _construction(kind: str, a: np.ndarray, b: np.ndarray, ok: np.ndarray, attrs: dict, title: str,
                  placer: Placer, contract: bool) -> tuple[Element, tuple[np.ndarray, None]]:
    """A construction line from its known point a through the point b it fixes (N, 2), drawn
    PAST_MM past both (`contract`: the page's, its element from a to b, the two pieces past them
    its markers: coordinates the page holds already), or an intersection's mark at a (a circle
    MARK_MM across); given to the placer; with where its step's number goes (past the line's
    end, beside the mark)."""
    if kind == "intersection":
        at = _where(ok, a)
        placer.block(np.concatenate([at - MARK_MM, at + MARK_MM], axis=1))
        return Element("circle", at[:, None], {"r": f"{MARK_MM}", "fill": "none", **attrs}, title=title), (at, None)
    d = b - a
    L = np.hypot(d[:, 0], d[:, 1])
    with np.errstate(invalid="ignore", divide="ignore"):
        u = np.where((L > ZERO_MM)[:, None], d / L[:, None], np.nan)
    ends = _where(ok, np.stack([a - PAST_MM * u, b + PAST_MM * u], axis=1))
    placer.line(_lines(ends[:, 0], ends[:, 1]))
    if contract:                          # from a to b, the rest drawn by its markers (`_PAST_MARKER`)
        known = _where(ok & (L > ZERO_MM), np.stack([a, b], axis=1))
        element = Element("line", known, {**attrs, "marker-start": "url(#past)", "marker-end": "url(#past)"}, title=title)
    else:
        element = Element("line", ends, attrs, title=title)
    return element, (ends[:, 1], None)


def _distinct_rows(mask: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """np.unique(mask, axis=0, return_inverse=True) of a bool array (R, M), by the rows' bytes (the
    same sorted rows; the structured-dtype sort of np.unique costs milliseconds a call)."""
    keys = [row.tobytes() for row in np.ascontiguousarray(mask)]
    distinct = sorted(set(keys))
    index = {k: i for i, k in enumerate(distinct)}
    rows = np.frombuffer(b"".join(distinct), dtype=bool).reshape(len(distinct), mask.shape[1])
    return rows, np.array([index[k] for k in keys], dtype=int)


def _points(cycle: PlanCycle, at, placer: Placer) -> tuple[list[Element], list[_Name]]:
    """The lettered points' dots and their labels (the design position's first, then the numbered
    ones of a plan of positions), coincident points lettered once ('B1 ≡ B11')."""
    small = cycle.kind == "positions"
    dots, groups = [], {False: [], True: []}
    for name, z in cycle.points.items():
        if not labelled(name):
            continue
        xy = at(z)
        if not np.isfinite(xy).all(axis=1).any():
            continue
        numbered = small and _numbered(cycle, name)
        r = 0.4 if numbered else 0.6
        dots.append(Element("circle", xy[:, None], {"r": f"{r}", "fill": "#000"}))
        placer.block(np.concatenate([xy - r, xy + r], axis=1))
        groups[numbered].append((name, xy))
    labels = []
    for numbered, group in groups.items():
        if not group:
            continue
        xy = np.stack([p for _, p in group], axis=1)          # (N, M, 2)
        owner = coincident(xy)
        for j, (name, p) in enumerate(group):
            lead = owner[:, j] == j
            if not lead.any():
                continue
            rows, inverse = _distinct_rows((owner == j)[lead])
            variant = np.zeros(len(lead), dtype=int)
            variant[lead] = inverse
            texts = tuple(" ≡ ".join(group[m][0] for m in np.nonzero(row)[0]) for row in rows)
            labels.append(_Name(texts, variant, _where(lead, p), None,
                                _NUMBERED_MM if numbered else _POINT_MM, "label"))
    return dots, labels


def _room(cycle: PlanCycle, lang: str, notes: bool, page: bool = False):
    """The notes block (SVG where `notes`, of the angle whose notes take the most lines below the
    plan: the page's notes of every angle fit its room), the drawing area they leave and where the
    notes go, the legend of line weights (`_legend`: SVG, box), with what they were found from:
    (block, area, where, legend, legend's box, tiny, extents, box, the notes of every angle:
    `_note_groups`). `page`: room for the page's notes of every angle and its rows of segments
    (`_cycle_notes`, `_cycle_rows`) beside or below the plan, else, where the plan would not fit
    beside them, for its notes (the rows as many as fit)."""
    tiny = _tiny(cycle)
    ext = _extents(cycle)
    box = _union(ext)
    groups, inverse = _note_groups(cycle, lang, tiny)
    lines = np.array([len(g) for g in _wrapped(groups, _BELOW_NOTES_MM)])[inverse]
    i = int(np.argmax(lines))                                  # the notes' room: at the angle with the most lines
    legend, key = _legend(cycle, lang)
    spare = MIN_DRAWN_MM if any((v == _OUT).any() for v in tiny.values()) else 0.0   # a vector drawn out of scale
    rows = _page_rows(cycle, lang)[0] if page else []
    least = tuple({left: max(map(len, _wrapped(groups, w)), default=0) + _row_columns(r, w, left)[1]
                   for left, w in ((False, _BELOW_NOTES_MM), (True, _LEFT_NOTES_MM))} for r in (rows, [])) if page else (None,)
    block, area, where = _layout(cycle.at(i), lang, _tiny_at(tiny, i), box, spare, draw=notes, bottom=key[1], least=least)
    return block, area, where, legend, key, tiny, ext, box, (groups, inverse)


def language_part(plan: Plan, lang: str) -> tuple:
    """All that the plan's drawing in `lang` (every element of its sheet's plan group and each
    label's place: `sheet`) takes from the language but its tooltips: the drawing area its notes
    leave and the letters of its segments (a construction line or intersection is not lettered,
    its name only its tooltip) and paths. Two languages with the same part draw the same plan
    group, but for the tooltips."""
    _lang(lang)
    area = _room(PlanCycle.of(plan), lang, notes=False)[1]
    return (area, tuple(segment_label(s, lang) for s in plan.segments if s.kind not in ("construction", "intersection")),
            tuple(text(name, lang) if name in MESSAGES else in_lang(name, lang) for name in plan.paths))


def _sheet(cycle: PlanCycle, lang: str, mechanism: str, contract: bool, notes: bool, cycle_notes: bool = False) -> Drawing:
    """The sheet of the cycle at every angle (`drawing`); with the notes block (of angle 0) where
    `notes`, the notes of every angle (`_cycle_notes`) where `cycle_notes`."""
    _lang(lang)
    block, (ax0, ay0, ax1, ay1), where, legend, key, tiny, ext, box, note_groups = _room(cycle, lang, notes, page=cycle_notes)
    x0, y0, x1, y1 = box
    tx, ty = _shifts(ext, (ax0, ay0, ax1, ay1), (ax0 + ax1) / 2 - (x0 + x1) / 2, (ay0 + ay1) / 2 + (y0 + y1) / 2)

    def at(z: np.ndarray) -> np.ndarray:
        return _on_sheet(z, tx, ty)

    placer = Placer(cycle.n, (ax0 - 4.0, _FRAME[1] + 1, _FRAME[2] - 1, min(ay1 + 4.0, _TITLE_BLOCK[1]) - 0.5))
    placer.block(_TITLE_BLOCK)
    placer.block(key)
    names: list[_Name] = []
    elements = _paths(cycle, lang, contract, at, placer, names)
    dimensions: list[_Name] = []
    elements += _dimensions(cycle, lang, contract, at, placer, dimensions)       # under the vectors, lettered after
    elements += _segments(cycle, lang, contract, at, tiny, placer, names)
    names += dimensions
    dots, points = _points(cycle, at, placer)
    elements += dots + _labels(placer, points + names)
    if cycle_notes:
        wrapped = _wrapped(note_groups[0], where[2])
        elements += _cycle_notes(cycle, (wrapped, note_groups[1]), where, key[1], placer)
        elements += _cycle_rows(cycle, lang, where, max(map(len, wrapped), default=0), key[1], placer)
    title = _title_block(cycle, lang, mechanism)
    W, H = SHEET_MM
    x0, y0, x1, y1 = _TITLE_BLOCK
    static = ['<?xml version="1.0" encoding="UTF-8"?>',
              f'<svg xmlns="http://www.w3.org/2000/svg" width="{W:g}mm" height="{H:g}mm" viewBox="0 0 {W:g} {H:g}" '
              f'font-family="DejaVu Sans, Arial, sans-serif">',
              f'<title>{escape(_plan_name(cycle.kind, cycle.titles[0], lang))}, {escape(scale_text(cycle.scale, lang))}</title>',
              f'<rect x="0" y="0" width="{W:g}" height="{H:g}" fill="#fff"/>',
              f'<rect x="{_FRAME[0]}" y="{_FRAME[1]}" width="{_FRAME[2] - _FRAME[0]:g}" height="{_FRAME[3] - _FRAME[1]:g}" '
              f'fill="none" stroke="#000" stroke-width="0.7"/>',
              *([_DIMENSION_MARKER] if contract and any(_dimension(cycle, s) for s in cycle.segments) else []),
              *([_PAST_MARKER] if contract and any(s.kind == "construction" for s in cycle.segments) else []),
              '<g id="plan" stroke-linecap="round">', ELEMENTS.rstrip("\n"), "</g>",
              f'<g id="title-block"><rect x="{x0}" y="{y0}" width="{x1 - x0:g}" height="{y1 - y0:g}" fill="none" '
              f'stroke="#000" stroke-width="0.5"/>',
              f'<line x1="{x0}" y1="{y0 + 12}" x2="{x1}" y2="{y0 + 12}" stroke="#000" stroke-width="0.25"/>',
              f'<line x1="{x0}" y1="{y0 + 24}" x2="{x1}" y2="{y0 + 24}" stroke="#000" stroke-width="0.25"/>',
              *(t.svg(0) for t in title if len(t.texts) == 1), "</g>", *legend, *block, "</svg>"]
    return Drawing(cycle.kind, cycle.phi_deg, "\n".join(static) + "\n",
                   tuple(t for t in title if len(t.texts) > 1) + tuple(elements))


def drawing(cycle: PlanCycle, lang: str = "en", mechanism: str = "", contract: bool = False,
            notes: bool = False) -> Drawing:
    """The plan's A3 sheet at each angle of the cycle, true to scale (1 user unit = 1 mm), as
    arrays (`Drawing`): one place of the plan on the sheet for the whole cycle (its extent over
    every angle centred in the room its notes leave at the angle with the most of them; moved at an
    angle only as far as keeps that angle's plan in the room, where the cycle's is larger), every
    element at every angle, labels placed for the cycle at once (`labels.Placer`); the notes left
    out, their room kept, or where `notes` each angle's notes, their numbers as the page's tokens
    (`_cycle_notes`: page.js writes them), but its segments' lengths (the page's values table). `contract`: every segment's element carries
    data-plan, data-segment and its drawn length (data-length-mm, as in segments.csv; a negligible
    vector, not drawn, an empty <g>): the interactive page's contract (`page`)."""
    return _sheet(cycle, lang, mechanism, contract, notes=False, cycle_notes=notes)


def sheet(plan: Plan, lang: str = "en", mechanism: str = "", contract: bool = False, notes: bool = True) -> Drawing:
    """The plan on an A3 landscape sheet as arrays: the one-angle `drawing` of the plan, with the
    notes block where `notes` (False: left out, their room kept); `svg` writes it."""
    return _sheet(PlanCycle.of(plan), lang, mechanism, contract, notes)


def svg(plan: Plan, lang: str = "en", mechanism: str = "", contract: bool = False, notes: bool = True) -> str:
    """The plan on an A3 landscape sheet, as SVG text: its `sheet`, written (`Drawing.svg`)."""
    return sheet(plan, lang, mechanism, contract, notes).svg(0)


# ----------------------------------------------------------------------------- matplotlib

def _tex(name: str) -> str:
    """A point name as mathtext (letters with their sub- and superscripts, `symbols.runs`), or as it
    is where it is anything else: `figure` then draws it with mathtext off (a model's point may be
    named anything)."""
    rs = runs(name)
    if not re.fullmatch(r"[A-Za-zπ]+′*", rs[0][0]) or any(re.search(r"[\\{}$^_#%&~\s]", t) for t, _ in rs):
        return name
    out = []
    for t, level in rs:
        t = t.replace("π", r"\pi ").replace("′", "'")
        out.append(t if not level else f"{'_' if level == SUB else '^'}{{{t}}}")
    return "$" + "".join(out) + "$"


def figure(plan: Plan, lang: str = "en", ax=None):
    """The plan as a matplotlib Figure: equal aspect, axes in mm of the drawing, title and scale
    in `lang`. Draws into `ax` when given (its figure is returned)."""
    _lang(lang)
    if ax is None:
        from matplotlib.figure import Figure
        x0, y0, x1, y1 = extent(plan)
        w, h = max(x1 - x0, 1.0), max(y1 - y0, 1.0)
        height = min(max(8.0 * h / w, 3.0), 10.0) + 0.8
        fig = Figure(figsize=(8.0, height), layout=None)     # a fixed layout: margins in inches
        fig.subplots_adjust(left=0.7 / 8.0, right=1 - 0.2 / 8.0, bottom=0.55 / height, top=1 - 0.6 / height)
        ax = fig.add_subplot()
    else:
        fig = ax.figure
    for name, path in plan.paths.items():
        zs = [z for z in path if _finite(z)]
        ax.plot([z.real for z in zs], [z.imag for z in zs], color="#1f5fa8", lw=0.8)
    for s in _drawable(plan):
        a, b = plan.points[s.start], plan.points[s.end]
        width, dash, colour = style(s)
        if s.kind in _ARROWS:
            if abs(b - a) >= 0.05:
                ax.annotate("", xy=(b.real, b.imag), xytext=(a.real, a.imag),
                            arrowprops=dict(arrowstyle="-|>", color=colour, lw=1.0, shrinkA=0, shrinkB=0))
        else:
            ax.plot([a.real, b.real], [a.imag, b.imag], color=colour, lw=width * 3,
                    ls=(0, tuple(float(v) * 2 for v in dash.split(","))) if dash else "-")
        if not labelled(s.end):            # a load or an arm ends at a construction point: letter the segment
            ax.annotate(segment_label(s, lang), (b.real, b.imag), xytext=(3, -9), textcoords="offset points", fontsize=8,
                        color=colour)
    small = plan.kind == "positions"
    for name, z in plan.points.items():
        if not _finite(z) or not labelled(name):
            continue
        numbered = small and _numbered(plan, name)
        ax.plot([z.real], [z.imag], "o", color="k", ms=1.5 if numbered else 3)
        label = _tex(name)
        ax.annotate(label, (z.real, z.imag), xytext=(3, 3), textcoords="offset points", parse_math=label != name,
                    fontsize=6 if numbered else 10)
    ends = [(z.real, z.imag) for s in _drawable(plan) for z in (plan.points[s.start], plan.points[s.end])]
    if ends:                            # an arrow (annotate) counts for no limits: its ends do
        ax.update_datalim(ends)
        ax.autoscale_view()
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel(unit("mm", lang))
    ax.set_ylabel(unit("mm", lang))
    ax.set_title(f"{title_of(plan, lang)}\n{scale_text(plan, lang)}", fontsize=10)
    ax.grid(True, lw=0.3, alpha=0.5)
    return fig
