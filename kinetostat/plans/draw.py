"""A plan drawn: an SVG sheet true to scale in millimetres (A3 landscape, 420 x 297 mm, as the
appendix sheets of seed 002: the plan in the drawing area, a title block that states the plan's
title and its scales, and beside it the notes: legend, the results the sheet finds, a force
plan's vector equation and every drawn segment with its length and value), and a matplotlib
Figure for notebooks and the reports' PNGs.

Drafting as the texts draw: arrowheads 3.5 mm long (shorter on short vectors), drawn as paths;
results (vectors, the design position) thick, construction thin; a vector shorter than 1 mm at
its scale is drawn out of scale at MIN_DRAWN_MM with a note, or, on a polygon whose sides must
close, lettered at its point and noted as negligible; every letter placed by `labels.Placer`
clear of every other letter, arrowhead and point; coincident points lettered once ("B1 ≡ B11");
no text under 2.5 mm. Words, units and numbers from the catalogue (`i18n`: en, uk, ru). Every
text that comes from a model (names, notes) is escaped.

May use: the standard library, numpy, `.core`, `.i18n`, `.labels`, `kinetostat._text` (XML-safe
text); matplotlib only inside `figure`.
"""
from __future__ import annotations

import math
import re

from .._text import xml_escape as escape     # also control characters, which XML cannot hold
from .core import Plan, Segment, extent
from .i18n import LANGS, MESSAGES, accuracy, check_lang, num, phrase, text, unit
from .labels import ASCENT, MIN_TEXT_MM, Placer, label_parts, label_svg, merge_coincident, text_width

__all__ = ["svg", "figure", "title_of", "scale_text", "scales_of", "fits", "LANGS", "SHEET_MM", "MIN_DRAWN_MM", "ARROW_MM", "ARC_HEAD_MM",
           "ROOM_MM"]

#: The sheet: A3 landscape, mm.
SHEET_MM = (420.0, 297.0)
_FRAME = (20.0, 5.0, 415.0, 292.0)          # inner frame: left 20 mm (binding), 5 mm elsewhere
_TITLE_BLOCK = (230.0, 247.0, 415.0, 292.0)  # bottom right, 185 x 45 mm
_AREA = (25.0, 10.0, 410.0, 242.0)          # where the plan is centred (above the notes)
#: Arrowhead: length and half-width, mm (drafting: 3-4 mm); shorter on a vector under 3 lengths.
ARROW_MM = (3.5, 0.6)
#: Arrowhead on an arc (the sense of ω, ε, a couple M), mm: drafting size whatever the arc's chord.
ARC_HEAD_MM = 2.8
#: A vector drawn shorter than this at its scale is drawn out of scale at MIN_DRAWN_MM.
TINY_MM, MIN_DRAWN_MM = 1.0, 6.0
#: A vector shorter than this (mm) is rounding noise of a zero (a load's arm at a dead centre): it
#: has no direction to draw it out of scale in, and is noted as negligible.
ZERO_MM = 1e-9
#: A vector drawn out of scale along another vector from the same point is drawn this far beside it, mm.
SIDE_MM = 1.8
_POINT_MM, _NAME_MM, _NUMBERED_MM, _NOTE_MM = 3.5, 3.0, 2.5, 2.5
_LINE_STEP = 3.6                             # line spacing of the notes, mm (room for a subscript)
_LEFT_NOTES_MM = 120.0                       # width of the notes beside a tall plan, mm

#: Room a plan has on its sheet (width, height), mm: above notes of a few lines, or beside a
#: column of notes at its left.
ROOM_MM = ((380.0, 185.0), (262.0, 228.0))


def fits(plan: Plan) -> float:
    """By how much the plan exceeds the room of its sheet (ROOM_MM): <= 1 where it fits."""
    x0, y0, x1, y1 = extent(plan)
    return min(max((x1 - x0) / w, (y1 - y0) / h) for w, h in ROOM_MM)


#: How each kind of segment is drawn: stroke width (mm), dash pattern, colour.
_STYLE = {"vector": (0.5, "", "#000"), "link": (0.7, "", "#000"), "position": (0.25, "", "#555"),
          "line": (0.25, "2,1.2", "#555"), "arm": (0.25, "4,1,1,1", "#a33")}


def _lang(lang: str) -> int:
    return check_lang(lang)


def title_of(plan: Plan, lang: str = "en") -> str:
    """The plan's title in `lang`, with its crank angle."""
    base, _, rest = plan.kind.partition(":")
    name = text(f"plan.{base}", lang) if f"plan.{base}" in MESSAGES else plan.title
    if rest:
        name += " " + rest.replace(",", "-")
    return f"{name}, φ = {num(plan.phi_deg, lang, 6)}°"


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
    if s.name.startswith("guide "):
        return f"{text('guide', lang)} {s.name[6:]}"
    if s.name.startswith("slot "):                  # mechanism.py: "slot <link> <point>"
        k, P = s.name[5:].split(" ", 1)
        return text("slot", lang, k=k, P=P)
    return text(s.name, lang) if s.name in MESSAGES else s.name


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


def _polygon_sides(plan: Plan) -> list[Segment]:
    """A force plan's sides in the order drawn (its vector equation), else []."""
    names = set(plan.equation)
    return [s for s in plan.segments if s.name in names]


# ----------------------------------------------------------------------------- SVG

def _n(name: str) -> str:
    """A name in a note, marked to be lettered as the drawing letters it (πa, F with subscript i2;
    of 'M_i2/l (a)' its first word)."""
    head, sep, tail = name.partition(" ")
    return f"\x01{head}\x02{sep}{tail}"


_NAMED = re.compile("\x01([^\x02]*)\x02")


def _runs(name: str) -> list[tuple[str, bool]]:
    """A name as (text, subscript?) runs, by `label_parts`; a segment 'pi-a' as its points' letters: πa."""
    parts = name.split("-") if re.fullmatch(r"[^-\s]+-[^-\s]+", name) else [name]
    return [(t, k == 1) for part in parts for k, t in enumerate(label_parts(part)) if t]


def _plain(s: str) -> str:
    """A note as read, without the names' marks (for its width)."""
    return _NAMED.sub(lambda m: "".join(t for t, _ in _runs(m.group(1))), s)


def _rich(s: str, size: float) -> str:
    """A note's SVG content: text escaped, marked names with their subscripts lowered 0.2 of the size
    (the same size: no note text under 2.5 mm)."""
    out, low = [], 0.0
    for k, piece in enumerate(_NAMED.split(s)):
        runs = _runs(piece) if k % 2 else [(piece, False)]
        for t, sub in runs:
            dy = (0.2 * size if sub else 0.0) - low
            out.append(f'<tspan dy="{dy:.2f}">{escape(t)}</tspan>' if dy else escape(t))
            low += dy
    return "".join(out)


def _t(x: float, y: float, s: str, size: float, anchor: str = "start", weight: str = "normal",
       ident: str = "", cls: str = "note") -> str:
    attrs = f' id="{ident}"' if ident else ""
    return (f'<text class="{cls}"{attrs} x="{x:.2f}" y="{y:.2f}" font-size="{size:.2f}" text-anchor="{anchor}" '
            f'font-weight="{weight}">{_rich(s, size)}</text>')


def _wrap(s: str, size: float, width: float) -> list[str]:
    """`s` broken at spaces into lines no wider than `width` mm at `size` (a longer word alone)."""
    out, line = [], ""
    for word in s.split(" "):
        trial = f"{line} {word}" if line else word
        if line and text_width(_plain(trial), size) > width:
            out.append(line)
            line = word
        else:
            line = trial
    return out + [line] if line else out


def _fit(s: str, size: float, width: float, least: float = MIN_TEXT_MM) -> float:
    """The font size, at most `size` and at least `least`, at which `s` fits `width` mm."""
    return max(least, min(size, size * width / max(text_width(_plain(s), size), 1e-9)))


def _tiny(plan: Plan) -> dict[str, str]:
    """Vectors under TINY_MM at their scale: name -> how drawn ("out" of scale at MIN_DRAWN_MM: a
    load at a scale of its own; "negligible": a polygon's side or a plan's vector, not laid off)."""
    how = {}
    for s in _drawable(plan):
        if s.kind == "vector" and abs(plan.points[s.end] - plan.points[s.start]) < TINY_MM:
            out = s.scale is not None and abs(plan.points[s.end] - plan.points[s.start]) > ZERO_MM
            how[s.name] = "out" if out else "negligible"
    return how


def _collinear(plan: Plan, s: Segment, tiny: dict[str, str]) -> bool:
    """Whether a vector drawn out of scale would lie on another vector of the plan: one from the
    same point (within 0.5 mm) in the same direction (within 5 degrees)."""
    a = plan.points[s.start]
    d = plan.points[s.end] - a
    for o in _drawable(plan):
        if o.kind != "vector" or o.name == s.name or o.name in tiny:
            continue
        e = plan.points[o.end] - plan.points[o.start]
        turn = e * d.conjugate()
        if abs(plan.points[o.start] - a) < 0.5 and abs(e) > 0 and abs(math.atan2(turn.imag, turn.real)) < math.radians(5.0):
            return True
    return False


def _result_line(plan: Plan, lang: str) -> list[str]:
    if not plan.results:
        return []
    parts = []
    for r in plan.results:
        part = f"{_n(r.symbol)} = {num(r.value, lang)}\u00a0{unit(r.unit, lang)}".rstrip()
        parts.append(part + (f" ({text(r.how, lang)})" if r.how else ""))
    return [f"{text('results', lang)}: " + "; ".join(parts)]


def _note_lines(plan: Plan, lang: str, tiny: dict[str, str]) -> list[str]:
    """The sheet's notes in `lang`: legend, the plan's notes, results, equation, tiny vectors."""
    base = plan.kind.partition(":")[0]
    lines = [text(f"legend.{base}", lang)] if f"legend.{base}" in MESSAGES else []
    lines += [phrase(n, lang) for n in plan.notes] + ([accuracy(*plan.accuracy, lang, False)] if plan.accuracy else [])
    lines += _result_line(plan, lang)
    if plan.equation:
        lines.append(f"{text('equation', lang)}: " + " + ".join(map(_n, plan.equation)) + " = 0")
    for s in _drawable(plan):
        if s.name in tiny:
            L = abs(plan.points[s.end] - plan.points[s.start])
            key = "out of scale" if tiny[s.name] == "out" else "negligible"
            mark = "*" if tiny[s.name] == "out" else ""
            lines.append(f"{_n(s.name)}{mark} = {num(s.value, lang)}\u00a0{unit(s.unit, lang)}: "
                         f"{text(key, lang, length=num(L, lang, decimals=2))}")
    if plan.kind == "lever":
        lines.append(text("arms natural", lang))
    return lines


def _table_rows(plan: Plan, lang: str) -> list[str]:
    """Every vector and arm drawn: its length and what it stands for."""
    mm = unit("mm", lang)
    sides = plan.kind.startswith("forces:")
    out = []
    for s in plan.segments:
        if s.kind not in ("vector", "arm") or not math.isfinite(s.value):
            continue
        L = num(plan.length_mm(s.name), lang, decimals=2)
        value = f"{num(s.value, lang)}\u00a0{unit(s.unit, lang)}".rstrip()
        if sides:
            out.append(f"{text('segment', lang)} {_n(s.start + '-' + s.end)} = {L} {mm} → {_n(s.name)} = {value}")
        elif s.unit == "mm":                      # a length kept as drawn (the lever's arms): once
            out.append(f"{_n(s.name)} = {L} {mm}")
        else:
            out.append(f"{_n(s.name)}: {L} {mm} → {value}")
    return out


def _notes_block(plan: Plan, lang: str, tiny: dict[str, str], left: bool, nofit: bool = False,
                 draw: bool = True) -> tuple[list[str], tuple[float, float, float, float]]:
    """SVG of the notes (none where not `draw`) and the drawing area they leave: below the plan
    (bottom left, from the frame's bottom up, beside the title block) or, for a tall plan, in a
    column at its left."""
    x0 = _FRAME[0] + 3
    width = _LEFT_NOTES_MM if left else _TITLE_BLOCK[0] - 3 - x0
    lines = [w for n in _note_lines(plan, lang, tiny) for w in _wrap(n, _NOTE_MM, width)]
    if nofit:
        lines.append(text("nofit", lang))
    rows = [w for r in _table_rows(plan, lang) for w in (_wrap(r, _NOTE_MM, width) if left else [r])]
    col_w = max((text_width(_plain(r), _NOTE_MM) for r in rows), default=0.0) + 4.0
    cols = 1 if left or not rows else max(1, int(width // col_w))
    per_col = -(-len(rows) // cols) if rows else 0
    height = _LINE_STEP * (len(lines) + per_col)
    top = _AREA[1] if left else _FRAME[3] - 1.5 - height
    out = []
    if draw:
        out.append('<g id="notes">')
        y = top + ASCENT * _NOTE_MM
        for line in lines:
            out.append(_t(x0, y, line, _NOTE_MM))
            y += _LINE_STEP
        for k, r in enumerate(rows):
            out.append(_t(x0 + col_w * (k // per_col), y + _LINE_STEP * (k % per_col), r, _NOTE_MM))
        out.append("</g>")
    if left:
        return out, (x0 + width + 4.0, _AREA[1], _AREA[2], _AREA[3]) if top + height < _FRAME[3] else None
    return out, (_AREA[0], _AREA[1], _AREA[2], min(_AREA[3], top - 3.0))


def _layout(plan: Plan, lang: str, tiny: dict[str, str],
            draw: bool = True) -> tuple[list[str], tuple[float, float, float, float]]:
    """The notes (SVG where `draw`) and the drawing area: notes below where the plan fits above
    them, else in a column at its left where it fits beside them, else below with a note that it
    does not fit (fitting: with MIN_DRAWN_MM to spare on every side, for a vector drawn out of scale)."""
    x0, y0, x1, y1 = extent(plan)
    for left in (False, True):
        notes, area = _notes_block(plan, lang, tiny, left, draw=draw)
        if area is not None and x1 - x0 + 2 * MIN_DRAWN_MM <= area[2] - area[0] \
                and y1 - y0 + 2 * MIN_DRAWN_MM <= area[3] - area[1]:      # room for a vector drawn out of scale
            return notes, area
    return _notes_block(plan, lang, tiny, False, nofit=True, draw=draw)


def _title_block(plan: Plan, lang: str, mechanism: str) -> list[str]:
    x0, y0, x1, y1 = _TITLE_BLOCK
    w = x1 - x0 - 6
    title = title_of(plan, lang)
    scales = scales_of(plan)
    sc = f"{text('scale' if len(scales) == 1 else 'scales', lang)}: " + "; ".join(scale_text(s, lang) for s in scales)
    angle = f"{text('angle', lang)} φ = {num(plan.phi_deg, lang, 6)}°"
    return [f'<g id="title-block"><rect x="{x0}" y="{y0}" width="{x1 - x0:g}" height="{y1 - y0:g}" fill="none" '
            f'stroke="#000" stroke-width="0.5"/>',
            f'<line x1="{x0}" y1="{y0 + 12}" x2="{x1}" y2="{y0 + 12}" stroke="#000" stroke-width="0.25"/>',
            f'<line x1="{x0}" y1="{y0 + 24}" x2="{x1}" y2="{y0 + 24}" stroke="#000" stroke-width="0.25"/>',
            _t(x0 + 3, y0 + 8, title, _fit(title, 5.0, w), weight="bold", cls="title"),
            _t(x0 + 3, y0 + 19.5, sc, _fit(sc, 4.5, w), ident="scale", cls="title"),
            _t(x0 + 3, y0 + 30, mechanism, _fit(mechanism, 3.0, w), ident="mechanism", cls="title"),
            _t(x0 + 3, y0 + 36, angle, 3.0, cls="title"),
            _t(x0 + 3, y0 + 42, text("sheet", lang), MIN_TEXT_MM, cls="title"),
            "</g>"]


def _arrowhead(a: tuple[float, float], b: tuple[float, float], length: float,
               arc: bool = False, colour: str = "#000") -> tuple[str, tuple, tuple]:
    """An arrowhead filled with its line's `colour`, its tip at b pointing from a: (svg path, its
    box, the line's new end); on an arc (a sense, a couple) ARC_HEAD_MM long whatever the chord a-b."""
    L = math.hypot(b[0] - a[0], b[1] - a[1])
    ux, uy = (b[0] - a[0]) / L, (b[1] - a[1]) / L
    h = ARC_HEAD_MM if arc else min(ARROW_MM[0], max(0.3 * L, 0.8), length)
    hw = max(0.3, ARROW_MM[1] * h / ARROW_MM[0] * 1.0)
    bx, by = b[0] - ux * h, b[1] - uy * h
    pts = [(b[0], b[1]), (bx - uy * hw, by + ux * hw), (bx + uy * hw, by - ux * hw)]
    d = "M" + " L".join(f"{x:.3f},{y:.3f}" for x, y in pts) + " z"
    xs, ys = [p[0] for p in pts], [p[1] for p in pts]
    return (f'<path class="arrowhead{" arc" if arc else ""}" d="{d}" fill="{colour}"/>', (min(xs), min(ys), max(xs), max(ys)),
            (b[0] - ux * 0.6 * h, b[1] - uy * 0.6 * h))


def svg(plan: Plan, lang: str = "en", mechanism: str = "", contract: bool = False, notes: bool = True) -> str:
    """The plan on an A3 landscape sheet, true to scale (1 user unit = 1 mm), as SVG text.
    `contract`: every segment's element carries data-plan, data-segment and data-length-mm (its
    length at the scale, as in segments.csv; a negligible vector, not drawn, an empty <g>): the
    interactive page's contract (`page`). `notes`: False leaves the notes out, their room kept
    (the plan drawn where it is with them; the page's tables hold them)."""
    _lang(lang)
    tiny = _tiny(plan)
    x0, y0, x1, y1 = extent(plan)
    block, (ax0, ay0, ax1, ay1) = _layout(plan, lang, tiny, draw=notes)
    tx, ty = (ax0 + ax1) / 2 - (x0 + x1) / 2, (ay0 + ay1) / 2 + (y0 + y1) / 2

    def P(z: complex) -> tuple[float, float]:
        return z.real + tx, ty - z.imag

    W, H = SHEET_MM
    out = ['<?xml version="1.0" encoding="UTF-8"?>',
           f'<svg xmlns="http://www.w3.org/2000/svg" width="{W:g}mm" height="{H:g}mm" viewBox="0 0 {W:g} {H:g}" '
           f'font-family="DejaVu Sans, Arial, sans-serif">',
           f'<title>{escape(title_of(plan, lang))}, {escape(scale_text(plan, lang))}</title>',
           f'<rect x="0" y="0" width="{W:g}" height="{H:g}" fill="#fff"/>',
           f'<rect x="{_FRAME[0]}" y="{_FRAME[1]}" width="{_FRAME[2] - _FRAME[0]:g}" height="{_FRAME[3] - _FRAME[1]:g}" '
           f'fill="none" stroke="#000" stroke-width="0.7"/>',
           '<g id="plan" stroke-linecap="round">']
    placer = Placer((ax0 - 4.0, _FRAME[1] + 1, _FRAME[2] - 1, min(ay1 + 4.0, _TITLE_BLOCK[1]) - 0.5))
    placer.block(_TITLE_BLOCK)
    named: list[tuple[str, tuple[float, float], tuple[float, float] | None]] = []   # (label, anchor, along)
    for name, path in plan.paths.items():
        xy = [P(z) for z in path if _finite(z)]
        if len(xy) < 2:
            continue
        width, colour = _PATH_STYLE.get(name.split(" ")[0], _PATH_STYLE.get(name[:1], (0.25, "#1f5fa8")))
        pts = " ".join(f"{a:.3f},{b:.3f}" for a, b in xy)
        tip = text(name, lang) if name in MESSAGES else name if name[:1] in "ωεM" else ""   # no English tooltip
        ident = f' data-plan="{escape(plan.kind)}" data-path="{escape(name)}"' if contract else ""
        out.append(f'<polyline points="{pts}" fill="none" stroke="{colour}" stroke-width="{width}"{ident}>'
                   + (f'<title>{escape(tip)}</title>' if tip else "") + '</polyline>')
        for (a, b), (c, d) in zip(xy, xy[1:]):
            placer.line(a, b, c, d)
        if name[:1] in "ωεM":                 # a rotation's sense, a couple: an arrowhead at the arc's end, its name
            head, box, _ = _arrowhead(xy[-2], xy[-1], ARC_HEAD_MM, arc=True, colour=colour)
            out.append(head)
            placer.block(box)
            named.append((name, xy[len(xy) // 2], None))
    sides = {s.name for s in _polygon_sides(plan)} or None        # a polygon: every side and chord named
    for s in _drawable(plan):
        a, b = P(plan.points[s.start]), P(plan.points[s.end])
        width, dash, colour = _STYLE.get(s.kind, _STYLE["line"])
        L = math.hypot(b[0] - a[0], b[1] - a[1])
        label = segment_label(s, lang)
        data = (f' data-plan="{escape(plan.kind)}" data-segment="{escape(s.name)}" '
                f'data-length-mm="{float(abs(plan.points[s.end] - plan.points[s.start]))!r}"') if contract else ""
        if s.name in tiny:
            if tiny[s.name] == "negligible":
                named.append((label, a, None))
                if contract:
                    out.append(f'<g class="negligible"{data}/>')
                continue
            b = (a[0] + (b[0] - a[0]) / L * MIN_DRAWN_MM, a[1] + (b[1] - a[1]) / L * MIN_DRAWN_MM)
            L, label = MIN_DRAWN_MM, label + "*"
            if _collinear(plan, s, tiny):              # beside the load it would hide under (G3* along F_p)
                nx, ny = -(b[1] - a[1]) / L * SIDE_MM, (b[0] - a[0]) / L * SIDE_MM
                a, b = (a[0] + nx, a[1] + ny), (b[0] + nx, b[1] + ny)
        end = b
        if s.kind == "vector":
            head, box, end = _arrowhead(a, b, L, colour=colour)
            placer.block(box)
        else:
            placer.block((b[0] - 0.5, b[1] - 0.5, b[0] + 0.5, b[1] + 0.5))      # a line's end
        attrs = f' stroke-dasharray="{dash}"' if dash else ""
        out.append(f'<line x1="{a[0]:.3f}" y1="{a[1]:.3f}" x2="{end[0]:.3f}" y2="{end[1]:.3f}" stroke="{colour}" '
                   f'stroke-width="{width}"{attrs}{data}><title>{escape(label)}</title></line>')
        if s.kind == "vector":
            out.append(head)
        placer.line(a[0], a[1], b[0], b[1])
        if s.kind != "link" and (not labelled(s.end) or (sides is not None and s.kind == "vector") or s.kind == "arm"):
            named.append((label, a, b))
    small = plan.kind == "positions"
    dots = []
    for name, z in plan.points.items():
        if not _finite(z) or not labelled(name):
            continue
        a, b = P(z)
        numbered = small and _numbered(plan, name)
        r = 0.4 if numbered else 0.6
        out.append(f'<circle cx="{a:.3f}" cy="{b:.3f}" r="{r}" fill="#000"/>')
        placer.block((a - r, b - r, a + r, b + r))
        dots.append((numbered, name, a, b))
    labels = []
    for numbered in (False, True):        # the design position's letters first, then the numbered ones
        group = [(n, a, b) for k, n, a, b in dots if k == numbered]
        for name, a, b in merge_coincident(group):
            pl = placer.place(name, _NUMBERED_MM if numbered else _POINT_MM, a, b)
            labels.append(label_svg(pl.x, pl.y, pl.name, pl.size))
            if pl.leader:
                labels.append(_leader(pl.leader))
    for name, a, along in named:
        pl = placer.place(name, _NAME_MM, a[0], a[1], along)
        labels.append(label_svg(pl.x, pl.y, pl.name, pl.size, cls="name"))
        if pl.leader:
            labels.append(_leader(pl.leader))
    out += labels
    out.append("</g>")
    out += _title_block(plan, lang, mechanism)
    out += block
    out.append("</svg>")
    return "\n".join(out) + "\n"


def _leader(seg: tuple[float, float, float, float]) -> str:
    a, b, c, d = seg
    return f'<line class="leader" x1="{a:.2f}" y1="{b:.2f}" x2="{c:.2f}" y2="{d:.2f}" stroke="#777" stroke-width="0.13"/>'


# ----------------------------------------------------------------------------- matplotlib

def _tex(name: str) -> str:
    """A point name as mathtext (letters with a subscript), or as it is where it is anything
    else: `figure` then draws it with mathtext off (a model's point may be named anything)."""
    head, sub, primes = label_parts(name)
    if not re.fullmatch(r"[A-Za-zπ]+", head):
        return name
    head = r"\pi" if head == "π" else re.sub(r"([\\{}_^$#%&~])", r"\\\1", head)
    return f"${head}" + (f"_{{{sub}}}" if sub else "") + ("'" * len(primes)) + "$"


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
        width, dash, colour = _STYLE.get(s.kind, _STYLE["line"])
        if s.kind == "vector":
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
