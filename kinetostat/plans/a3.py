"""All the plans of a variant on A3 landscape sheets, each TRUE TO SCALE (1 mm of the plan's
drawing = 1 mm on paper, at the scales its heading states): seed 002 (Logvinenko, Nadtoka
2021, appendix B) puts them on one A3 sheet; here a further sheet takes what does not fit.

Each plan is drawn exactly as its own SVG sheet draws it (`draw.svg`: its lines, arrowheads,
points and every label where `labels.Placer` put it clear of the others): the `plan` group of
that sheet is read back (`drawing`) and redrawn by matplotlib's PDF backend in millimetres. The
plans' extents (drawing, labels and a heading: title, then every scale the plan is drawn at) are
shelf-packed (first fit, tallest first, columns within a shelf) inside the frame, clear of the
title block (`layout`);
what does not fit goes onto a further A3 sheet, never drawn smaller, and the title block says so.

May use: the standard library, `.draw`, `.i18n`, `.labels`; matplotlib inside `pages` only.
"""
from __future__ import annotations

import re
import xml.etree.ElementTree as ET
from dataclasses import dataclass

from .draw import SHEET_MM, scale_text, scales_of, svg, title_of
from .i18n import text

__all__ = ["Drawing", "Placement", "drawing", "layout", "pages", "AREA", "TITLE_BLOCK", "MIN_HEADING_MM"]

_NS = "{http://www.w3.org/2000/svg}"
#: Where plans go on the A3 sheet (x0, y0, x1, y1), mm from the top left: inside the frame
#: (left 20 mm for binding, 5 mm elsewhere) below the sheet's title line.
AREA = (24.0, 13.0, 411.0, 288.0)
#: The title block, bottom right (as `draw`'s sheets), mm.
TITLE_BLOCK = (230.0, 247.0, 415.0, 292.0)
#: A plan's heading above its drawing (its title, 3.5 mm, then its scales, 3 mm) is broken into
#: lines no wider than the drawing, or than this where the drawing is narrower, mm.
MIN_HEADING_MM = 50.0
_GAP = 4.0                                  # between two drawings, mm
_PT = 72.0 / 25.4                           # points per mm


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
    """Advance width of `s` (mm) at `size_mm`, DejaVu Sans, as matplotlib sets it."""
    from matplotlib.font_manager import FontProperties
    from matplotlib.textpath import text_to_path
    prop = FontProperties(family="DejaVu Sans", size=size_mm * _PT, weight=weight)
    return text_to_path.get_text_width_height_descent(s, prop, ismath=False)[0] / _PT


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


def _pts(s: str) -> list[tuple[float, float]]:
    nums = [float(v) for v in re.findall(r"-?\d+(?:\.\d+)?", s)]
    return list(zip(nums[::2], nums[1::2]))


def drawing(plan, lang: str) -> Drawing:
    """The `plan` group of the plan's SVG sheet (`draw.svg`) as primitives, with its box."""
    root = ET.fromstring(svg(plan, lang=lang).encode("utf-8"))
    group = next(g for g in root.iter(f"{_NS}g") if g.get("id") == "plan")
    lines, polylines, polygons, dots, texts = [], [], [], [], []
    xs, ys = [], []
    for el in group:
        tag = el.tag[len(_NS):]
        if tag == "line":
            x0, y0, x1, y1 = (float(el.get(k)) for k in ("x1", "y1", "x2", "y2"))
            title = el.find(f"{_NS}title")
            lines.append((x0, y0, x1, y1, float(el.get("stroke-width", "0.13")), el.get("stroke-dasharray", ""),
                          el.get("stroke", "#000"), title.text if title is not None else ""))
            xs += [x0, x1]
            ys += [y0, y1]
        elif tag == "polyline":
            p = _pts(el.get("points"))
            polylines.append((p, float(el.get("stroke-width")), el.get("stroke")))
        elif tag == "path":                      # an arrowhead, its tip first: of the line before it
            p = _pts(el.get("d"))
            owner = lines[-1][7] if lines and "arc" not in el.get("class", "") else ""
            polygons.append((p, el.get("fill", "#000"), owner))
        elif tag == "circle":
            x, y, r = (float(el.get(k)) for k in ("cx", "cy", "r"))
            dots.append((x, y, r))
            xs += [x - r, x + r]
            ys += [y - r, y + r]
        elif tag == "text":
            x, y, size = float(el.get("x")), float(el.get("y")), float(el.get("font-size"))
            runs, w, low = [], 0.0, 0.0
            for t in el.iter(f"{_NS}tspan"):
                s = float(t.get("font-size", size))
                low += float(t.get("dy", "0"))
                runs.append((t.text or "", s, low))
                w += _width(t.text or "", s)
            texts.append((x, y, tuple(runs)))
            xs += [x, x + w]
            ys += [y - 0.95 * size, y + low + 0.3 * size]
        for p in ([] if tag not in ("polyline", "path") else _pts(el.get("points") or el.get("d"))):
            xs.append(p[0])
            ys.append(p[1])
    scales = "; ".join(scale_text(s, lang) for s in scales_of(plan))
    box = (min(xs), min(ys), max(xs), max(ys)) if xs else (0.0, 0.0, 0.0, 0.0)
    return Drawing(plan.kind, (title_of(plan, lang), f"{text('scales', lang)}: {scales}"), tuple(lines),
                   tuple(polylines), tuple(polygons), tuple(dots), tuple(texts), box)


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


def _fits(x0: float, y0: float, w: float, h: float) -> bool:
    """Whether a box fits AREA clear of the title block."""
    clear = x0 + w <= TITLE_BLOCK[0] - 2 or y0 + h <= TITLE_BLOCK[1] - 2
    return x0 + w <= AREA[2] and y0 + h <= AREA[3] and clear


def layout(drawings: list[Drawing]) -> list[Placement]:
    """Shelf packing, first fit by decreasing height, of the drawings (heading above each) into
    AREA, clear of the title block. A shelf is as tall as its first (tallest) drawing and holds
    columns side by side; a drawing goes under the last in a column of a shelf where it fits
    (width and height), else into a new column of a shelf with room beside, else onto a new shelf
    below the last of the first page with room, else onto a new page (a further A3 sheet)."""
    sizes = [_size(d) for d in drawings]
    order = sorted(range(len(drawings)), key=lambda i: -sizes[i][1])
    out: dict[int, Placement] = {}
    shelves: list[dict] = []          # page, y, height, x (where a new column goes), columns [[x, width, next y]]
    bottoms: list[float] = []         # per page: where its next shelf would start
    for i in order:
        w, h, top = sizes[i]
        spot = None
        for sh in shelves:            # under a column
            for col in sh["columns"]:
                last = col is sh["columns"][-1]       # the last column may widen into the room beside it
                if (w <= col[1] or last) and col[2] + h <= sh["y"] + sh["height"] and _fits(col[0], col[2], w, h):
                    spot = (sh["page"], col[0], col[2])
                    col[1], col[2] = max(col[1], w), col[2] + h + _GAP
                    sh["x"] = max(sh["x"], col[0] + w + _GAP)
                    break
            if spot:
                break
        if spot is None:              # a new column beside, or a new shelf, or a new page
            sh = next((sh for sh in shelves if h <= sh["height"] and _fits(sh["x"], sh["y"], w, h)), None)
            if sh is None:
                page = next((k for k, y in enumerate(bottoms) if _fits(AREA[0], y, w, h)), None)
                if page is None:
                    bottoms.append(AREA[1])
                    page = len(bottoms) - 1
                sh = {"page": page, "y": bottoms[page], "height": h, "x": AREA[0], "columns": []}
                shelves.append(sh)
                bottoms[page] += h + _GAP
            spot = (sh["page"], sh["x"], sh["y"])
            sh["columns"].append([sh["x"], w, sh["y"] + h + _GAP])
            sh["x"] += w + _GAP
        page, x, y = spot
        d = drawings[i]
        out[i] = Placement(d.kind, page, x - d.box[0], y + top - d.box[1])
    return [out[i] for i in range(len(drawings))]


def pages(plans, lang: str, title: str):
    """The A3 sheets as matplotlib Figures, with the drawings and their placements. Each page's axes
    fill it: 1 data unit = 1 mm, y down. Lines and arrowheads carry gid "<plan kind>/<segment>"
    ("/<segment>^" for an arrowhead, its tip first), so that a test can measure them."""
    from matplotlib.figure import Figure
    from matplotlib.patches import Circle, Polygon

    drawings = [drawing(plans[k], lang) for k in plans]
    places = layout(drawings)
    n = max(p.page for p in places) + 1
    W, H = SHEET_MM
    figs = []
    for k in range(n):
        fig = Figure(figsize=(W / 25.4, H / 25.4))
        ax = fig.add_axes((0, 0, 1, 1))
        ax.set_xlim(0, W)
        ax.set_ylim(H, 0)
        ax.set_axis_off()
        x0, y0, x1, y1 = 20.0, 5.0, 415.0, 292.0
        ax.plot([x0, x1, x1, x0, x0], [y0, y0, y1, y1, y0], color="k", lw=0.7 * _PT)
        tb = TITLE_BLOCK
        ax.plot([tb[0], tb[0], tb[2]], [tb[3], tb[1], tb[1]], color="k", lw=0.5 * _PT)
        ax.text(24, 10, title, fontsize=4.0 * _PT, va="baseline", weight="bold")
        notes = [text("pack.a3_true", lang), text("pack.a3_page", lang, k=k + 1, n=n)]
        if n > 1:
            notes.append(text("pack.a3_more", lang, n=n))
        rows = [(ln, 3.5, "bold") for ln in _lines(title, 3.5, tb[2] - tb[0] - 6, "bold")]
        rows += [(ln, 2.8, "normal") for s in notes for ln in _lines(s, 2.8, tb[2] - tb[0] - 6)]
        y = tb[1] + 5.5
        for s, size, weight in rows:
            ax.text(tb[0] + 3, y, s, fontsize=size * _PT, va="baseline", weight=weight)
            y += 1.45 * size
        figs.append((fig, ax))
    for d, p in zip(drawings, places):
        ax = figs[p.page][1]
        X = lambda x: x + p.dx                                         # noqa: E731
        Y = lambda y: y + p.dy                                         # noqa: E731
        y = Y(d.box[1]) - _size(d)[2]
        for line, size, weight in _heading(d):
            y += 1.3 * size
            ax.text(X(d.box[0]), y - 0.3 * size, line, fontsize=size * _PT, va="baseline", weight=weight)
        for pts, width, colour in d.polylines:
            ax.plot([X(a) for a, _ in pts], [Y(b) for _, b in pts], color=colour, lw=width * _PT,
                    solid_capstyle="round")
        for a0, b0, a1, b1, width, dash, colour, name in d.lines:
            ls = (0, tuple(float(v) * _PT / (width * _PT) for v in dash.split(","))) if dash else "-"
            (ln,) = ax.plot([X(a0), X(a1)], [Y(b0), Y(b1)], color=colour, lw=width * _PT, ls=ls,
                            solid_capstyle="round")
            ln.set_gid(f"{d.kind}/{name}")
        for pts, colour, owner in d.polygons:
            poly = Polygon([(X(a), Y(b)) for a, b in pts], closed=True, facecolor=colour, edgecolor="none")
            poly.set_gid(f"{d.kind}/{owner}^")
            ax.add_patch(poly)
        for a, b, r in d.dots:
            ax.add_patch(Circle((X(a), Y(b)), r, facecolor="k", edgecolor="none"))
        for a, b, runs in d.texts:
            x = X(a)
            for s, size, low in runs:
                ax.text(x, Y(b) + low, s, fontsize=size * _PT, va="baseline", ha="left")
                x += _width(s, size)
    return [f for f, _ in figs], drawings, places
