"""The data a student's sheet (`pack`) gives beyond the task's table, so that the task can be solved
from the sheet alone (issue 36): each pressure diagram of the model drawn true to its stated scales
(p against the crank angle, or against the piston's travel from TDC on both strokes) with the
pressure at φ1 marked, and its points as a table; the model's data the table leaves out (the crank's
weight, the links' moments of inertia, the gear pair that carries F_зр); the scales to draw at, where
the pack chose them.

A diagram is laid out once (`layout`: lines, paths, dots and texts in mm from its top left) and
drawn by both renderers: `draw_pdf` (a `pdf.Canvas`) and `svg` (the HTML sheet).

May use: numpy, `kinetostat.applied` (where a load's diagram is read), `.i18n`, `.labels` (a
text's width, its SVG markup, the least size), `.scales`, `.symbols`. Never `kinetostat.variants`, matplotlib or the harness.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..applied import forward_stroke, load_magnitude, travel
from .i18n import num, text, unit
from .labels import CAP, DESCENT, MIN_TEXT_MM, markup, text_width
from .scales import coarser
from .symbols import plain, text_runs

__all__ = ["Diagram", "Given", "diagrams", "model_data", "layout", "text_box", "draw_pdf", "svg", "PLOT_MM", "MPA"]

#: The largest plot of a diagram on the A4 sheet: width, height, mm.
PLOT_MM = (150.0, 60.0)
#: Pa per MPa: the diagrams are printed in MPa, as seed 002's tables give P_max.
MPA = 1e6
_LEFT, _TOP, _BOTTOM, _RIGHT = 16.0, 7.0, 12.0, 16.0   # room for the p ticks, the scales' line, the x ticks, the x name, mm
_SIZE = MIN_TEXT_MM                           # lettering: the sheets' smallest font size, capitals 2.55 mm (ГОСТ 2.304: 2.5)
#: How far above or below its point a mark's label may be lifted clear of the curves and texts
#: (a thin leader joins them), mm.
_LIFTS = (0.0, 4.0, 8.0, 12.0, 16.0, 20.0, 24.0)


@dataclass(frozen=True)
class Diagram:
    """A diagram of y against x drawn true to its scales (`mu_x`, `mu_y`: units per mm): its
    `curves` (x, y tuples; a travel diagram's forward and return strokes), the points marked
    ((x, y, label)), the axes' names, their ticks and the line stating the scales."""
    x_name: str
    y_name: str
    curves: tuple[tuple[tuple[float, ...], tuple[float, ...]], ...]
    marks: tuple[tuple[float, float, str], ...]
    mu_x: float
    mu_y: float
    x_ticks: tuple[float, ...]
    y_ticks: tuple[float, ...]
    scales: str
    lang: str

    @property
    def size(self) -> tuple[float, float]:
        """Width and height of the whole figure, mm."""
        return (_LEFT + max(self.x_ticks) / self.mu_x + _RIGHT,
                _TOP + (max(self.y_ticks) - min(self.y_ticks)) / self.mu_y + _BOTTOM)


def _ticks(lo: float, hi: float, step: float) -> tuple[float, ...]:
    """Multiples of `step` from lo down to hi up (each rounded to the step's digits)."""
    k = np.arange(math.floor(lo / step + 1e-9), math.ceil(hi / step - 1e-9) + 1)
    return tuple(round(float(n * step), 12) for n in k)


def _area(d: float) -> float:
    """The piston's area pi d^2 / 4, m^2."""
    return math.pi / 4 * d ** 2


@dataclass(frozen=True)
class Given:
    """One pressure diagram as the sheet gives it: its heading, the Diagram, its points as a table
    (`head`, `rows`, column `widths`), the note with the pressures read at φ1, and every number
    these print (`printed`: data, not answers)."""
    heading: str
    diagram: Diagram
    head: tuple[str, ...]
    rows: tuple[tuple[str, ...], ...]
    widths: tuple[float, ...]
    note: str
    printed: frozenset[str]


def diagrams(mech, res, d: float, lang: str, L) -> list[Given]:
    """Each distinct pressure diagram of `mech`'s loads (cylinder bore `d`, m) at the analysis
    `res` (one angle, φ1), p in MPa, the loads reading it marked at φ1 with their pressure.
    `L`: the model's lettering."""
    out: dict = {}
    A = _area(d)
    for ld in mech.loads:
        t = ld.table
        if ld.kind != "force" or t is None:
            continue
        p = float(load_magnitude(mech, res.kin, ld)[0]) / A / MPA
        x = (float(np.degrees(res.kin.phi[0])) % 360.0 if t.argument == "phi"
             else float(travel(mech, res.kin, ld)[0]))
        forward = t.argument == "phi" or bool(forward_stroke(mech, res.kin, ld)[0])
        out.setdefault(t, []).append((L.load(ld.name), x, p, forward))
    return [_diagram(t, loads, A, lang) for t, loads in out.items()]


def _diagram(t, loads, A: float, lang: str) -> Given:
    """The Diagram of table `t` (its loads: (symbol, x, p MPa, on the forward stroke) at φ1), its rows."""
    to_p = t.scale / A / MPA
    xs = tuple(float(x) for x in t.x)
    fwd = tuple(float(v) * to_p for v in t.value)
    curves = [(xs, fwd)] + ([(xs, tuple(float(v) * to_p for v in t.value_return))] if t.value_return else [])
    mpa = unit("MPa", lang)
    if t.argument == "phi":
        x_name, x_unit, x_step, x_digits = "φ", unit("deg", lang), 30.0, 6
        head = (f"φ, {x_unit}", f"p, {mpa}")
        rows = tuple((num(x, lang, 6), num(y, lang, 6)) for x, y in zip(xs, fwd))
    else:
        x_name, x_unit, x_step, x_digits = "s/H", "", 0.1, 4
        head = ("s/H", text("pack.p_down", lang, unit=mpa), text("pack.p_up", lang, unit=mpa))
        rows = tuple((num(x, lang, 6), num(a, lang, 6), num(b, lang, 6)) for x, a, b in zip(xs, *[c[1] for c in curves]))
    marks: dict[tuple[float, float], list[str]] = {}
    for symbol, x, p, forward in loads:
        marks.setdefault((round(x, 9), round(p, 9)), []).append(symbol)
    shown = {c for r in rows for c in r}
    mark_rows = []
    for (x, p), symbols in marks.items():
        label = text("pack.p_at", lang, p=num(p, lang, 4), unit=mpa, x_name=x_name,
                     x=num(x, lang, x_digits) + (x_unit if x_unit == "°" else f" {x_unit}".rstrip()), loads=", ".join(symbols))
        mark_rows.append((x, p, label))
        shown.update({num(p, lang, 4), num(x, lang, x_digits)})
    span_x = xs[-1] if t.argument == "travel" else 360.0
    lo, hi = min(min(c[1]) for c in curves + [((), (0.0,))]), max(max(c[1]) for c in curves)
    mu_x, mu_y = coarser(span_x / PLOT_MM[0], 1.0), coarser((hi - min(lo, 0.0)) / PLOT_MM[1], 1.0)
    y_step = coarser(mu_y * 8.0, 1.0)
    scales = text("pack.diagram_scales", lang, x_name=x_name, mu_x=num(mu_x, lang, 6),
                  x_unit=(x_unit or "1") + "/" + unit("mm", lang), mu_p=num(mu_y, lang, 6),
                  p_unit=f"{mpa}/{unit('mm', lang)}")
    shown.update({num(mu_x, lang, 6), num(mu_y, lang, 6)})
    diagram = Diagram(f"{x_name}" + (f", {x_unit}" if x_unit else ""), f"p, {mpa}", tuple(curves), tuple(mark_rows),
                      mu_x, mu_y, _ticks(0.0, span_x, x_step), _ticks(min(lo, 0.0), hi, y_step), scales, lang)
    symbols = ", ".join(dict.fromkeys(symbol for symbol, *_ in loads))
    heading = text("pack.diagram_phi" if t.argument == "phi" else "pack.diagram_travel", lang, loads=symbols)
    note = text("pack.diagram_note", lang, marks="; ".join(m[2] for m in mark_rows))
    head, rows, widths = _columns(head, rows, 4 if len(head) == 2 else 2)
    shown |= {num(x, lang, 6) for x in diagram.y_ticks + diagram.x_ticks}
    return Given(heading, diagram, head, rows, widths, note, frozenset(shown))


def _columns(head: tuple[str, ...], rows: tuple[tuple[str, ...], ...], n: int):
    """The table's rows in `n` groups of columns side by side, read down each group first (the
    last group padded with blank cells); with the groups' column widths (fractions of the text width)."""
    k = math.ceil(len(rows) / n)
    blank = ("",) * len(head)
    out = tuple(sum((rows[g * k + r] if g * k + r < len(rows) else blank for g in range(n)), ()) for r in range(k))
    return head * n, out, (1.0 / (n * len(head)),) * (n * len(head))


def model_data(mech, rows_given: set[str], lang: str, g: float) -> tuple[tuple[tuple[str, ...], ...], frozenset[str]]:
    """Rows (parameter, symbol, value, unit) of the model's data that the task's table leaves out
    (`rows_given`: the table's row keys): the crank's weight, every moving link's moment of
    inertia about its centre of mass where the table gives none, each cylinder's axis (through
    O, its direction towards the piston), and the drive's gear pair (the crank's wheel carries
    F_зр); values to 6 digits. With the numbers printed."""
    rows = [(text("pack.g_crank", lang), "G_1", num(mech.links[1].mass * g, lang, 6), unit("N", lang))]
    for link in mech.links[1:]:
        if link.I_S > 0 and f"I_S{link.id}" not in rows_given:
            rows.append((text("pack.i_link", lang, k=link.id), f"I_S{link.id}", num(link.I_S, lang, 6), unit("kg m^2", lang)))
    for pair in mech.pairs:
        if pair.kind == "P" and 0 in pair.links:
            k = pair.links[1] if pair.links[0] == 0 else pair.links[0]
            angle = math.degrees(math.atan2(pair.direction[1], pair.direction[0]))
            rows.append((text("pack.cylinder", lang, k=k), f"β_{k}", num(angle, lang, 6), unit("deg", lang)))
    gear = mech.drive.gear
    if gear is not None:
        e = math.degrees(math.atan2(gear.centre_direction[1], gear.centre_direction[0]))
        rows += [(text("pack.g_module", lang), "m", num(gear.module * 1e3, lang, 6), unit("mm", lang)),
                 (text("pack.g_z_pinion", lang), text("pack.sym_z_pinion", lang), str(gear.z_pinion), ""),
                 (text("pack.g_z_wheel", lang), text("pack.sym_z_wheel", lang), str(gear.z_wheel), ""),
                 (text("pack.g_alpha", lang), "α_w", num(gear.alpha_w_deg, lang, 6), unit("deg", lang)),
                 (text("pack.g_correction", lang), "y", num(gear.y, lang, 6) if gear.correction == "unequal" else "0", ""),
                 (text("pack.g_centres", lang), "θ", num(e, lang, 6), unit("deg", lang))]
    return tuple(rows), frozenset(r[2] for r in rows)


# ============================================================================ drawing

def layout(d: Diagram):
    """The diagram's primitives in mm from its top left: lines (x0, y0, x1, y1, width, dashed),
    paths (points, width), dots (x, y, r) and texts (x, y baseline, text, right-aligned), the
    texts at _SIZE; each mark's label where it covers no other text and the fewest curve points
    (`_place`)."""
    y_lo, y_hi = min(d.y_ticks), max(d.y_ticks)                            # the ticks span the curves
    X = lambda x: _LEFT + x / d.mu_x                                        # noqa: E731
    Y = lambda y: _TOP + (y_hi - y) / d.mu_y                                # noqa: E731
    x_end = X(max(d.x_ticks))
    lines, paths, dots, texts = [], [], [], []
    lines += [(X(0), Y(0), x_end + 6, Y(0), 0.35, False), (X(0), Y(y_lo), X(0), Y(y_hi) - 5, 0.35, False)]
    for x in d.x_ticks:                                                     # each number centred under its tick
        lines.append((X(x), Y(0), X(x), Y(0) + 1.2, 0.25, False))
        label = num(x, d.lang, 6)
        texts.append((X(x) - text_width(label, _SIZE) / 2, Y(y_lo) + 5.5, label, False))
    for y in d.y_ticks:
        lines.append((X(0) - 1.2, Y(y), X(0), Y(y), 0.25, False))
        texts.append((X(0) - 2.0, Y(y) + CAP * _SIZE / 2, num(y, d.lang, 6), True))
    texts += [(x_end + 7.0, Y(0) + CAP * _SIZE / 2, d.x_name, False), (X(0) + 2.0, Y(y_hi) - 2.5, d.y_name, False),
              (x_end + 6, _TOP - 3.0, d.scales, True)]
    for xs, ys in d.curves:
        paths.append(([(X(x), Y(y)) for x, y in zip(xs, ys)], 0.5))
    for x, y, _ in d.marks:
        dots.append((X(x), Y(y), 0.9))
        lines += [(X(x), Y(y), X(x), Y(0), 0.2, True), (X(x), Y(y), X(0), Y(y), 0.2, True)]
    segments = [pair for pts, _ in paths for pair in zip(pts, pts[1:])] + [((a, b), (c, e)) for a, b, c, e, *_ in lines]
    drawn = np.concatenate([np.linspace(a, b, 2 + int(math.dist(a, b) / 0.5)) for a, b in segments])    # every 0.5 mm
    taken = [text_box(*t) for t in texts] + [(x - r, y - r, x + r, y + r) for x, y, r in dots]
    for x, y, label in d.marks:
        placed, leader = _place(X(x), Y(y), label, drawn, (X(0), 0.0, x_end + _RIGHT, Y(y_lo)), taken)
        texts.append(placed)
        taken.append(text_box(*placed))
        lines += [leader] if leader else []
    return lines, paths, dots, texts


def text_box(x: float, y: float, s: str, right: bool) -> tuple[float, float, float, float]:
    """The box (x0, y0, x1, y1), mm, of a text of the layout at _SIZE: its baseline y, from x (`right`: to x)."""
    w = text_width(plain(s), _SIZE)
    x0 = x - w if right else x
    return x0, y - CAP * _SIZE, x0 + w, y + DESCENT * _SIZE


def _overlap(a: tuple, b: tuple) -> float:
    """The area two boxes (x0, y0, x1, y1) share, mm²."""
    return max(0.0, min(a[2], b[2]) - max(a[0], b[0])) * max(0.0, min(a[3], b[3]) - max(a[1], b[1]))


def _place(x: float, y: float, label: str, drawn, bounds, taken: list) -> tuple[tuple, tuple | None]:
    """The mark's label beside its point (x, y), mm: of the four corners around it, each lifted by
    one of _LIFTS away from it, the one inside `bounds` (x0, y0, x1, y1), then covering the least
    of the `taken` texts' boxes, then the fewest of the curves' `drawn` points (K, 2), then the
    least lifted. Returns its text (x, baseline, label, right-aligned) and, where lifted, a thin
    leader from the point to the label's near corner (a line of `layout`)."""
    width, px, py = text_width(plain(label), _SIZE), *drawn.T

    def spot(right: bool, above: bool, lift: float) -> tuple[float, float]:
        return x + (-1.8 if right else 1.8), y - 1.5 - lift if above else y + 1.5 + CAP * _SIZE + lift

    def cost(right: bool, above: bool, lift: float) -> tuple:
        bx, by = spot(right, above, lift)
        box = text_box(bx, by, label, right)
        inside = int(np.count_nonzero((box[0] <= px) & (px <= box[2]) & (box[1] - 0.5 <= py) & (py <= box[3] + 0.5)))
        out = max(bounds[0] - box[0], box[2] - bounds[2], 0.0) + max(bounds[1] - box[1], box[3] - bounds[3], 0.0)
        return out, sum(_overlap(box, t) for t in taken), inside, lift

    right, above, lift = min(((r, a, h) for h in _LIFTS for r in (False, True) for a in (True, False)), key=lambda c: cost(*c))
    bx, by = spot(right, above, lift)
    leader = None
    if lift:
        corner = (bx, by + DESCENT * _SIZE if above else by - CAP * _SIZE - 0.5)
        leader = (x, y, *corner, 0.2, False)
    return (bx, by, label, right), leader


def draw_pdf(pdf, x0: float, y0: float, d: Diagram) -> None:
    """`d` on the `pdf.Canvas` page with its top left at (x0, y0), mm."""
    lines, paths, dots, texts = layout(d)
    for a, b, c, e, w, dashed in lines:
        pdf.line(x0 + a, y0 + b, x0 + c, y0 + e, w, dash=(1.0, 0.8) if dashed else ())
    for pts, w in paths:
        pdf.polyline([(x0 + x, y0 + y) for x, y in pts], w)
    for x, y, r in dots:
        pdf.dot(x0 + x, y0 + y, r)
    for x, y, s, right in texts:
        pdf.text(x0 + x, y0 + y, s, _SIZE, right=right)


def svg(d: Diagram) -> str:
    """`d` as an inline SVG element, 1 unit = 1 mm (the HTML sheet)."""
    w, h = d.size
    lines, paths, dots, texts = layout(d)
    out = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{w:.1f}mm" height="{h:.1f}mm" viewBox="0 0 {w:.2f} {h:.2f}" '
           f'font-family="DejaVu Sans, sans-serif" font-size="{_SIZE}">']
    for a, b, c, e, sw, dashed in lines:
        dash = ' stroke-dasharray="1 0.8"' if dashed else ""
        out.append(f'<line x1="{a:.2f}" y1="{b:.2f}" x2="{c:.2f}" y2="{e:.2f}" stroke="#000" stroke-width="{sw}"{dash}/>')
    for pts, sw in paths:
        out.append('<polyline fill="none" stroke="#000" stroke-width="{}" points="{}"/>'.format(
            sw, " ".join(f"{x:.2f},{y:.2f}" for x, y in pts)))
    for x, y, r in dots:
        out.append(f'<circle cx="{x:.2f}" cy="{y:.2f}" r="{r}"/>')
    for x, y, s, right in texts:
        anchor = ' text-anchor="end"' if right else ""
        out.append(f'<text x="{x:.2f}" y="{y:.2f}"{anchor}>{markup(text_runs(s), _SIZE)}</text>')
    return "\n".join(out + ["</svg>"])
