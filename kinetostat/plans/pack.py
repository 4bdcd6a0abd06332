"""The teacher's pack of a seed 002 variant (issue 21): the student's sheet, the answer key and one
A3 sheet with all the plans, as PDF and as standalone HTML.

    >>> from kinetostat import variants
    >>> from kinetostat.plans.pack import pack
    >>> p = pack(variants.variant(1, "479"), lang="uk")
    >>> paths = p.write("out/task1_479")                            # doctest: +SKIP

- `sheet.pdf` / `sheet.html`: the task in the text's words, the variant's data (table 1.1-1.3 rows
  with their letters), what the task needs beyond the table (`givens`: each pressure diagram drawn
  at stated scales with p at φ1 marked, and its points; the crank's weight, the links' inertia,
  the gear pair; where the plans' scales were chosen for one A3 sheet, the scales to draw at), the
  worksheet's tables with their values left blank, and an A3 drawing area with a title block. No
  answer: no value or length the key gives, beyond those data.
- `key.pdf` / `key.html`: every worksheet value with its unit and sense, and the band a careful
  drawing lands in (the 5-95 % range of `drawing_error.simulate`, BAND_DRAWS draws, seeded); the
  scales μ_l, μ_v, μ_a, μ_F with the reference length each draws, and every scale each plan is
  drawn at; δ with the texts' 5 % rule; every segment a student measures on the plans, in mm, with
  the scale it is drawn at.
- `plans_a3.pdf` / `plans.html`: the plans, each true to scale, on one A3 landscape sheet (seed
  002, appendix B puts the results on one A3 sheet; `a3`); plans.html shows each plan's own SVG
  sheet. Where the plans at the texts' recommended lengths do not fit that sheet, their scales
  are chosen together for it (`a3.one_sheet`), and the key states which are coarser and why: every
  part of the pack (the key's scales, segment lengths and bands, the SVG sheets, the worksheet,
  the A3 sheet) is drawn at those scales.

Both documents are one list of blocks (headings, paragraphs, tables, figures, the drawing area), rendered
twice: to PDF by reportlab (`.pdf`: DejaVu Sans embedded as a TrueType subset with its Unicode
map, so pdftotext reads the Cyrillic back) and to HTML (`worksheet.html_document`). Every word comes from the catalogue (`i18n`).

May use: `build` of this package, `.a3`, `.givens`, `.worksheet`, `.drawing_error`, `.core`, `.draw`, `.i18n`,
`model.lettering`, `.pdf`, `.symbols`, `kinetostat._io`. Never matplotlib, never the harness, nor `kinetostat.variants` (the variant
is passed in and says its task, title and letters).
"""
from __future__ import annotations

import math
import textwrap
from dataclasses import dataclass
from html import escape
from pathlib import Path
from typing import Any, Mapping

import numpy as np

from .._io import write_bytes, write_text
from .core import UNMEASURED
from .draw import scale_text, scales_of, segment_label, title_of
from .i18n import check_lang, num, text, unit
from .pdf import ASCENT, Canvas
from .scales import REFERENCE_NAMES as _REFERENCE
from .symbols import html, mark
from ..model.lettering import lettering
from .solution import Solution, solve
from .worksheet import CSS, Worksheet, html_document, worksheet_cycle

__all__ = ["Pack", "pack", "BAND", "BAND_DRAWS", "PACK_FILES"]

#: The band of a careful drawing: these percentiles of the simulated drawings, %.
BAND = (5.0, 95.0)
#: Monte Carlo draws of the band (`drawing_error.simulate`, seed 0): enough for 5-95 % to 2 digits.
BAND_DRAWS = 400
#: The files `Pack.write` writes.
PACK_FILES = ("sheet.pdf", "key.pdf", "plans_a3.pdf", "sheet.html", "key.html", "plans.html")

A4, A3 = (210.0, 297.0), (420.0, 297.0)
_MARGIN = (20.0, 10.0, 12.0, 12.0)        # left (binding), right, top, bottom, mm
_PT = 25.4 / 72.0                          # mm per point


@dataclass(frozen=True)
class Table:
    """A table block: header cells, rows of cells, column widths (fractions of the text width),
    the columns of numbers (right-aligned), the blank columns (to fill in by hand) and the columns
    of symbols (lettered with their sub- and superscripts: `symbols.runs`)."""
    head: tuple[str, ...]
    rows: tuple[tuple[str, ...], ...]
    widths: tuple[float, ...]
    numeric: frozenset[int] = frozenset()
    blank: frozenset[int] = frozenset()
    symbols: frozenset[int] = frozenset()

    def cell(self, row: tuple[str, ...], i: int) -> str:
        """Cell i of `row` as written: a symbol marked (`symbols.mark`)."""
        return mark(row[i]) if i in self.symbols and row[i] else row[i]


@dataclass(frozen=True)
class Pack:
    """The pack of one variant in `lang`: the blocks of the sheet and of the key (("h1"|"h2"|"p",
    text), ("table", Table), ("figure", `givens.Diagram`), ("area", title-block lines)), the plans on their one A3 sheet
    (`a3`: `a3.OneSheet`), the numbers of the key as printed (`answers`) and the bands
    (worksheet key -> (low, high), SI)."""
    name: str
    lang: str
    title: str
    sheet: tuple[tuple[str, Any], ...]
    key: tuple[tuple[str, Any], ...]
    a3: Any
    answers: frozenset[str]
    bands: Mapping[str, tuple[float, float]]

    @property
    def plans(self):
        """The plans (`kinetostat.plans.Plans`) at the scales of the one A3 sheet."""
        return self.a3.plans

    def write(self, out_dir: str | Path) -> list[Path]:
        """PACK_FILES into `out_dir`, each atomically; returns the paths."""
        out = Path(out_dir)
        sheet_t, key_t = f"{text('pack.sheet', self.lang)}: {self.title}", f"{text('pack.key', self.lang)}: {self.title}"
        out.mkdir(parents=True, exist_ok=True)
        paths = [out / f for f in PACK_FILES]
        write_bytes(paths[0], _pdf(self.sheet, sheet_t))
        write_bytes(paths[1], _pdf(self.key, key_t))
        write_bytes(paths[2], _plans_pdf(self.a3, f"{text('pack.a3', self.lang)}: {self.title}"))
        write_text(paths[3], html_document(sheet_t, _html(self.sheet), self.lang))
        write_text(paths[4], html_document(key_t, _html(self.key), self.lang))
        write_text(paths[5], _plans_html(self.plans, self.lang, f"{text('pack.a3', self.lang)}: {self.title}"))
        return paths


# ============================================================================ content

def pack(v, lang: str = "en", a3=None, draws: int = BAND_DRAWS, solution: Solution | None = None) -> Pack:
    """The pack of variant `v` (`variants.Variant`) in `lang` at its design position, every part
    at the scales that put the plans on one A3 sheet (`a3`: `a3.one_sheet` in `lang`, when chosen
    already); `draws`: Monte Carlo draws of the bands; `solution`: the caller's one analysis of the
    variant at [phi1] (`solution.solve`), from which every part is built (default: made here, once)."""
    from .a3 import one_sheet
    from .drawing_error import Scales, simulate
    check_lang(lang)
    mech = v.mechanism()
    phi1 = float(v.values["phi1"])
    solution = solution or solve(mech, [phi1])
    res, other = solution.res, solution.other
    a3 = a3 or one_sheet(mech, phi1, lang, solution=solution)
    plans = a3.plans
    sc = plans.scales
    ws = worksheet_cycle(mech, res, sc["mu_l"].value, lang, other).at(0)
    L = lettering(mech).in_lang(lang)
    spec, name = v.spec, v.title(lang)
    title = text("pack.task", lang, task=v.task, code=v.code or "—",
                 title=name[0].upper() + name[1:] if lang == "en" else name)
    drawn = simulate(mech, n=draws, seed=0, scales=Scales(*(sc[k].value for k in ("mu_l", "mu_v", "mu_a", "mu_F"))),
                     res=res)
    bands = {k: tuple(float(x) for x in np.percentile(s, BAND)) for k, s in drawn.samples.items()}
    data = Table((text("pack.letter", lang), text("pack.parameter", lang), text("ws.head.symbol", lang),
                  text("ws.head.value", lang), text("ws.head.unit", lang)),
                 tuple((r.letter, text(f"row.{r.key}", lang), r.symbol, num(v.values[r.key], lang, 6),
                        unit(r.unit, lang)) for r in spec.rows), (0.07, 0.5, 0.18, 0.13, 0.12), frozenset({3}),
                 symbols=frozenset({2}))
    sheet = [("h1", title), ("p", text("pack.statement", lang, M=L.M_bal)), ("p", text("pack.assume", lang)),
             ("h2", text("pack.data", lang, table=spec.table)), ("table", data)]
    if v.code:
        sheet.append(("p", "  ".join(f"{ch} = {d}" for ch, d in v.letters.items())))
    given_here = _givens(sheet, mech, res, v, a3, lang, L)
    key = [("h1", f"{text('pack.key', lang)}. {title}")]          # scales, values and bands, δ, segments
    answers: set[str] = set()
    key += [("h2", text("pack.scales", lang)), ("table", _scales_table(mech, ws, sc, lang, answers))]
    if a3.coarsened():
        key.append(("p", _coarsened(a3, lang)))
    key += [("h2", text("pack.plan_scales", lang)), ("table", _plan_scales_table(plans, lang, answers))]
    sheet.append(("h2", text("pack.fill", lang)))
    recs = ws.records()
    outside = False                     # an exact value beyond its band (a segment shorter than the error)
    for section in dict.fromkeys(r.section for r in ws.rows):
        idx = [i for i, r in enumerate(ws.rows) if r.section == section]
        sheet.append(("h2", recs[idx[0]]["section"]))
        sheet.append(("table", Table((text("ws.head.symbol", lang), text("ws.head.value", lang),
                                      text("ws.head.unit", lang), text("ws.head.direction", lang)),
                                     tuple((recs[i]["symbol"], "", recs[i]["unit"], "") for i in idx),
                                     (0.2, 0.25, 0.2, 0.35), blank=frozenset({1, 3}), symbols=frozenset({0}))))
        krows = []
        for i in idx:
            r = ws.rows[i]
            value = num(r.value, lang, 4)
            lo_hi = bands.get(r.key)
            band = f"{num(lo_hi[0], lang, 3)} … {num(lo_hi[1], lang, 3)}" if lo_hi else text("pack.no_band", lang)
            if lo_hi and not lo_hi[0] <= r.value <= lo_hi[1]:
                band += " *"
                outside = True
            krows.append((recs[i]["symbol"], value, recs[i]["unit"], recs[i]["direction"], band))
            answers.add(value)
            if lo_hi:
                answers.update(num(x, lang, 3) for x in lo_hi)
        key += [("h2", recs[idx[0]]["section"]),
                ("table", Table((text("ws.head.symbol", lang), text("ws.head.value", lang), text("ws.head.unit", lang),
                                 text("ws.head.direction", lang), text("pack.band", lang)), tuple(krows),
                                (0.14, 0.15, 0.12, 0.3, 0.29), frozenset({1, 4}), symbols=frozenset({0})))]
    key.append(("p", text("pack.band_note", lang, lo=num(BAND[0], lang), hi=num(BAND[1], lang), n=draws,
                          mm=num(drawn.length_mm, lang), deg=num(drawn.angle_deg, lang))))
    if outside:
        key.append(("p", text("pack.band_outside", lang)))
    if not drawn.forces_drawn:
        key.append(("p", text("pack.band_partial", lang, M=L.M_bal, kinds=text("group.kinds_12", lang))))
    delta = text("pack.delta", lang, M=L.M_bal, ML=L.lever(L.M_bal), delta=num(ws.value("delta_pct"), lang, decimals=2))
    if "delta_pct" in bands:            # the study draws the force plans of RRR and RRP (frame guide) groups only
        lo, hi = (num(x, lang, decimals=2) for x in bands["delta_pct"])
        delta += " " + text("pack.delta_band", lang, lo=lo, hi=hi)
    key.append(("p", delta))
    key += [("h2", text("pack.segments", lang)), ("table", _segments_table(plans, lang, answers))]
    sheet.append(("area", (text("pack.area", lang), (title, *(f"{text(k, lang)}: " for k in
                                                               ("pack.student", "pack.group", "pack.checked"))))))
    given = {num(v.values[r.key], lang, 6) for r in spec.rows} | given_here
    answers = {a for a in answers if a not in given and a not in ("0", "—")}
    return Pack(v.name, lang, title, tuple(sheet), tuple(key), a3, frozenset(answers), bands)


def _givens(sheet: list, mech, res, v, a3, lang: str, L) -> set[str]:
    """Append to `sheet` what the task needs beyond its table (`givens`): each pressure diagram
    drawn with p at φ1 marked and its points, the model's further data (the crank, the links'
    inertia, the gear pair), and, where `a3` chose scales coarser than the texts' rule, the scales
    of every plan to draw at. Returns the numbers these print (data, not answers)."""
    from .givens import diagrams, model_data
    printed: set[str] = set()
    for g in diagrams(mech, res, float(v.values["d"]), lang, L):
        sheet += [("h2", g.heading), ("figure", g.diagram), ("p", g.note),
                  ("table", Table(g.head, g.rows, g.widths, frozenset(range(len(g.head)))))]
        printed |= g.printed
    rows, numbers = model_data(mech, {r.key for r in v.spec.rows}, lang, float(mech.g))
    sheet += [("h2", text("pack.model_data", lang)),
              ("table", Table((text("pack.parameter", lang), text("ws.head.symbol", lang), text("ws.head.value", lang),
                               text("ws.head.unit", lang)), rows, (0.57, 0.14, 0.16, 0.13), frozenset({2})))]
    printed |= numbers
    if a3.coarsened():
        scales: set[str] = set()
        sheet += [("h2", text("pack.use_scales", lang)), ("table", _plan_scales_table(a3.plans, lang, scales))]
        printed |= scales
    return printed


def _scales_table(mech, ws: Worksheet, scales, lang: str, answers: set[str]) -> Table:
    """μ_l, μ_v, μ_a, μ_F: value, unit and the reference each draws (OA, pa, πa in mm); the
    values printed added to `answers`."""
    rows = []
    for s in scales.values():
        ref = _REFERENCE.get(s.symbol)
        drawn_mm = f"{ref} = {num(_reference_mm(mech, ws, s), lang, 3)} {unit('mm', lang)}" if ref else ""
        rows.append(("μ_" + s.symbol.split("_", 1)[1], num(s.value, lang, 6), unit(s.unit, lang), drawn_mm))
        answers.add(num(s.value, lang, 6))
    return Table((text("ws.head.symbol", lang), text("ws.head.value", lang), text("ws.head.unit", lang),
                  text("pack.drawn", lang)), tuple(rows), (0.15, 0.2, 0.25, 0.4), frozenset({1}))


def _coarsened(a3, lang: str) -> str:
    """The key's note on the scales coarser than the texts' rule (`a3.OneSheet.coarsened`): each
    with the rule's value and its reference's drawn length against the recommended one
    (`scales.TARGET_MM`: outside it, or still within it), why (one A3 sheet), and that the
    students need these scales."""
    from .scales import TARGET_MM
    items = []
    for rule, chosen, drawn_mm in a3.coarsened():
        lo, hi = TARGET_MM[chosen.symbol]
        items.append(text("pack.coarsened_within" if lo <= drawn_mm <= hi else "pack.coarsened_one", lang,
                          scale=scale_text(chosen, lang), rule=num(rule.value, lang, 6),
                          ref=_REFERENCE.get(chosen.symbol) or text("pack.largest_force", lang),
                          mm=num(drawn_mm, lang, decimals=1), lo=num(lo, lang), hi=num(hi, lang)))
    return text("pack.coarsened", lang, scales="; ".join(items))


def _plan_scales_table(plans, lang: str, answers: set[str]) -> Table:
    """Every scale each plan is drawn at (`draw.scales_of`: its own, and the force scale of the
    loads on a group plan or the crank); the values printed added to `answers`."""
    rows = []
    for kind in plans:
        scales = scales_of(plans[kind])
        rows.append((title_of(plans[kind], lang), "; ".join(scale_text(s, lang) for s in scales)))
        answers.update(num(s.value, lang, 6) for s in scales)
    return Table((text("pack.plan", lang), text("scales", lang)), tuple(rows), (0.5, 0.5))


def _segments_table(plans, lang: str, answers: set[str]) -> Table:
    """Every segment a student lays off or measures (vectors, links, arms; not the other
    positions or the construction lines): its plan, name, length in mm at the scale stated, and
    the value it stands for; the lengths printed added to `answers`."""
    rows = []
    for kind in plans:
        plan = plans[kind]
        for s in plan.segments:
            length = plan.length_mm(s.name)
            if s.kind in UNMEASURED or not math.isfinite(length):
                continue
            value = "" if not math.isfinite(s.value) else f"{num(s.value, lang, 4)} {unit(s.unit, lang)}".strip()
            scale = scale_text(s.scale or plan.scale, lang) if s.unit != "mm" else ""    # an arm kept as drawn: none
            rows.append((title_of(plan, lang), segment_label(s, lang), num(length, lang, decimals=1), scale, value))
            answers.add(num(length, lang, decimals=1))
    return Table((text("pack.plan", lang), text("segment", lang), text("pack.length", lang), text("scale", lang),
                  text("ws.head.value", lang)), tuple(rows), (0.3, 0.14, 0.12, 0.24, 0.2), frozenset({2, 4}),
                 symbols=frozenset({1}))


def _reference_mm(mech, ws: Worksheet, scale) -> float:
    """The drawn length (mm) of the reference quantity of `scale` (the crank OA, pa, πa)."""
    d = mech.drive
    points = mech.links[d.link].points
    value = {"mu_l": math.dist(points[d.pivot], points[d.point]), "mu_v": ws.value(f"V_{d.point}"),
             "mu_a": ws.value(f"a_{d.point}")}[scale.symbol]
    return value / scale.value


# ============================================================================ HTML

def _html(blocks) -> str:
    """The blocks as the body of an HTML page (every text escaped, its symbols' scripts in <sub> and
    <sup>: `symbols.html`)."""
    out = []
    for kind, x in blocks:
        if kind in ("h1", "h2", "p"):
            out.append(f"<{kind}>{html(x)}</{kind}>")
        elif kind == "table":
            out.append("<table>\n<tr>" + "".join(f"<th>{html(h)}</th>" for h in x.head) + "</tr>")
            for row in x.rows:
                cells = []
                for i in range(len(row)):
                    cls = ' class="blank"' if i in x.blank else ' class="num"' if i in x.numeric else ""
                    cells.append(f"<td{cls}>{html(x.cell(row, i))}</td>")
                out.append("<tr>" + "".join(cells) + "</tr>")
            out.append("</table>")
        elif kind == "figure":
            from .givens import svg
            out.append(f'<figure class="diagram">{svg(x)}</figure>')
        else:                                   # the drawing area with its title block
            out.append(f'<div class="area">{escape(x[0])}<div class="titleblock">' + "<br>".join(escape(s) for s in x[1])
                       + "</div></div>")
    return "\n".join(out) + "\n"


def _plans_html(plans, lang: str, title: str) -> str:
    """The plans' SVG sheets (written beside it by `Plans.write`) side by side on screen, each a
    link to itself at full size; in print
    each sheet one A3 landscape page at its true size (_PRINT_A3)."""
    from . import plan_file_name
    imgs = "\n".join(f'<figure><a href="{escape(plan_file_name(plans[k]))}"><img src="{escape(plan_file_name(plans[k]))}" '
                     f'alt="{escape(title_of(plans[k], lang))}"></a>'
                     f"<figcaption>{escape(title_of(plans[k], lang))}</figcaption></figure>" for k in plans)
    return html_document(title, f"<h1>{escape(title)}</h1>\n<div class=\"plans\">\n{imgs}\n</div>\n", lang,
                         CSS + _PRINT_A3)


#: Print: each plan's SVG sheet alone on an A3 landscape page at its true size (420 x 297 mm, no
#: margin: the sheet has its own frame); the page's heading and captions are for the screen.
_PRINT_A3 = """@page{size:420mm 297mm;margin:0}
@media print{body{margin:0;padding:0;max-width:none}h1,figcaption{display:none}.plans{display:block}
.plans figure{margin:0;break-after:page;break-inside:avoid}.plans figure:last-child{break-after:auto}
.plans img{display:block;width:420mm;height:296.9mm;border:none}}
"""


# ============================================================================ PDF

def _wrap(s: str, width_mm: float, size: float) -> list[str]:
    """`s` in lines of about `width_mm` at `size` pt (DejaVu Sans: about 0.57 em a character)."""
    chars = max(int(width_mm / (0.57 * size * _PT)), 4)
    return textwrap.wrap(s, chars, break_long_words=True) or [""]


class _Flow:
    """Blocks laid out top to bottom on A4 portrait pages of `pdf` (`pdf.Canvas`, mm from the top left)."""

    def __init__(self, pdf):
        self.pdf, self.size, self.y = pdf, None, 0.0
        self.x0, self.width = _MARGIN[0], A4[0] - _MARGIN[0] - _MARGIN[1]

    def page(self, size=A4) -> None:
        self.pdf.page(size)
        self.size, self.y = size, _MARGIN[2]

    def room(self, h: float) -> bool:
        """A new page unless `h` mm fit below; True when a page was started."""
        if self.size != A4 or self.y + h > A4[1] - _MARGIN[3]:
            self.page()
            return True
        return False

    def text(self, x: float, y: float, s: str, size: float, right: bool = False) -> None:
        """`s` at `size` pt, the top of its line at y (mm)."""
        self.pdf.text(x, y + ASCENT * size * _PT, s, size * _PT, right=right)

    def line(self, x0: float, y0: float, x1: float, y1: float, lw: float = 0.5) -> None:
        """A line `lw` pt wide (mm)."""
        self.pdf.line(x0, y0, x1, y1, lw * _PT)

    def paragraph(self, s: str, size: float, after: float = 2.0) -> None:
        lh = size * _PT * 1.35
        lines = _wrap(s, self.width, size)
        self.room(lh * min(len(lines), 3))
        for ln in lines:
            self.room(lh)
            self.text(self.x0, self.y, ln, size)
            self.y += lh
        self.y += after

    def table(self, t: Table, size: float = 8.0) -> None:
        lh, pad = size * _PT * 1.3, 1.0
        widths = [w * self.width for w in t.widths]

        def draw(row, bold=False, blank=()):
            wrapped = [_wrap(c if bold else t.cell(row, i), w - 2 * pad, size) for i, (c, w) in enumerate(zip(row, widths))]
            h = max(len(c) for c in wrapped) * lh + 2 * pad + (2.5 if blank else 0)
            if self.room(h) and not bold:
                draw(t.head, bold=True)
            x = self.x0
            for i, (lines, w) in enumerate(zip(wrapped, widths)):
                for k, ln in enumerate(lines):
                    right = i in t.numeric and not bold
                    self.text(x + (w - pad if right else pad), self.y + pad + k * lh, ln, size, right=right)
                self.line(x, self.y, x, self.y + h)
                x += w
            self.line(x, self.y, x, self.y + h)
            self.line(self.x0, self.y, x, self.y)
            self.line(self.x0, self.y + h, x, self.y + h)
            self.y += h

        draw(t.head, bold=True)
        for row in t.rows:
            draw(row, blank=t.blank)
        self.y += 3.0

    def figure(self, diagram) -> None:
        """A diagram (`givens.Diagram`) at its true scales, below the text so far."""
        from .givens import draw_pdf
        h = diagram.size[1]
        self.room(h)
        draw_pdf(self.pdf, self.x0, self.y, diagram)
        self.y += h + 2.0

    def area(self, text_area: str, lines) -> None:
        """An A3 landscape page: the frame, the drawing area (`text_area` at its top left), the
        title block (bottom right: `lines`)."""
        self.page(A3)
        self.line(20, 5, 415, 5, 1.0), self.line(20, 292, 415, 292, 1.0)
        self.line(20, 5, 20, 292, 1.0), self.line(415, 5, 415, 292, 1.0)
        self.line(230, 247, 415, 247, 1.0), self.line(230, 247, 230, 292, 1.0)
        self.text(25, 7, text_area, 8)
        for k, s in enumerate(lines):             # the title (two lines), then rows of 10 mm to fill in
            y = 249 if k == 0 else 250 + 10 * k + 1
            for j, ln in enumerate(_wrap(s, 178, 9)):
                self.text(233, y + j * 1.2 * 9 * _PT, ln, 9)
            if k:
                self.line(230, y - 1.5, 415, y - 1.5, 0.3)


def _pdf(blocks, title: str) -> bytes:
    """The blocks as PDF (A4 portrait, the drawing area on A3 landscape)."""
    pdf = Canvas(title)
    flow = _Flow(pdf)
    for kind, x in blocks:
        if kind == "h1":
            flow.paragraph(x, 13, after=3)
        elif kind == "h2":
            flow.room(20)
            flow.paragraph(x, 10.5, after=1.5)
        elif kind == "p":
            flow.paragraph(x, 9)
        elif kind == "table":
            flow.table(x)
        elif kind == "figure":
            flow.figure(x)
        else:
            flow.area(*x)
    return pdf.getvalue()


def _plans_pdf(a3, title: str) -> bytes:
    """All the plans true to scale on one A3 landscape sheet (`a3.pages`, drawn by `a3.draw_page`)."""
    from .a3 import draw_page, pages
    pdf = Canvas(title)
    for page in pages(a3, title):
        draw_page(pdf, page)
    return pdf.getvalue()
