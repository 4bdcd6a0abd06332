"""The PDF writer of the teacher's pack (`pack`, `a3`): reportlab's canvas in millimetres from a
page's top left (y down), DejaVu Sans and DejaVu Sans Bold embedded as TrueType subsets with their
Unicode map (so that pdftotext reads the Cyrillic back), and their advance widths.

The fonts are bundled in `fonts/` (its licence in fonts/LICENSE_DEJAVU), so that every install
writes the pack: DejaVu Sans 2.35 as matplotlib ships it, cut to Latin, Greek, Cyrillic,
punctuation, arrows and mathematical operators by fontTools:
`pyftsubset DejaVuSans.ttf --unicodes=U+0020-024F,U+0300-036F,U+0370-052F,U+2000-22FF,U+25A0-25FF
--no-hinting --layout-features='' --name-IDs='*' --name-languages='*'` (the same for the bold).

A symbol in a text (`symbols`: μ_l, a^n_BA, R12t where marked) is set with its sub- and superscripts
at a smaller size and a rise (the text operators Tf and Ts), as the sheets set them.

May use: reportlab, the standard library, `.symbols`. Never matplotlib.
"""
from __future__ import annotations

import io
from functools import lru_cache
from pathlib import Path

from .symbols import SCRIPT, SUB, SUB_DROP, SUP, SUP_RISE, text_runs

__all__ = ["Canvas", "text_width", "FONT", "BOLD", "PT", "ASCENT"]

FONT, BOLD = "DejaVuSans", "DejaVuSans-Bold"
#: Points per mm.
PT = 72.0 / 25.4
_FONTS = Path(__file__).with_name("fonts")
#: Top of a line of text above its baseline, em (DejaVu Sans' ascent of "l": 1556 / 2048).
ASCENT = 0.76


@lru_cache(maxsize=None)
def _registered() -> None:
    """DejaVu Sans and its bold registered with reportlab (once a process)."""
    from reportlab.pdfbase import pdfmetrics
    from reportlab.pdfbase.ttfonts import TTFont
    for name in (FONT, BOLD):
        pdfmetrics.registerFont(TTFont(name, str(_FONTS / f"{name}.ttf")))


def _runs(s: str, size_mm: float) -> tuple[tuple[str, float, float], ...]:
    """`s` as (text, font size mm, rise mm) runs: its symbols' sub- and superscripts (`symbols.text_runs`)
    SCRIPT of the size, dropped SUB_DROP or raised SUP_RISE of it."""
    rise = {0: 0.0, SUB: -SUB_DROP * size_mm, SUP: SUP_RISE * size_mm}
    return tuple((t, SCRIPT * size_mm if level else size_mm, rise[level]) for t, level in text_runs(s))


@lru_cache(maxsize=8192)
def text_width(s: str, size_mm: float, bold: bool = False) -> float:
    """Advance width of `s` (mm) at `size_mm`, DejaVu Sans (bold), as the PDF sets it (its symbols'
    scripts smaller: `Canvas.text`)."""
    from reportlab.pdfbase.pdfmetrics import stringWidth
    _registered()
    return sum(stringWidth(t, BOLD if bold else FONT, size) for t, size, _ in _runs(s, size_mm))


@lru_cache(maxsize=64)
def _rgb(colour: str) -> tuple[float, float, float]:
    """An SVG colour "#rgb" or "#rrggbb" as RGB fractions."""
    h = colour.lstrip("#")
    if len(h) == 3:
        h = "".join(c * 2 for c in h)
    return tuple(int(h[i:i + 2], 16) / 255 for i in (0, 2, 4))


class Canvas:
    """A PDF being written: pages of a size in mm, drawn in mm from the page's top left (y down);
    `getvalue()` when done. Title and creator in its metadata."""

    def __init__(self, title: str):
        from reportlab.pdfgen.canvas import Canvas as RLCanvas
        _registered()
        self._buf = io.BytesIO()
        self._c = RLCanvas(self._buf, pageCompression=1, initialFontName=FONT)
        self._c.setTitle(title)
        self._c.setCreator("kinetostat")
        self._h = None
        self._state: dict[str, object] = {}          # the graphics state set on this page (set once)

    def page(self, size_mm: tuple[float, float]) -> None:
        """A new page of `size_mm` (width, height): the one before it closed."""
        if self._h is not None:
            self._c.showPage()
        self._state = {}
        self._c.setPageSize((size_mm[0] * PT, size_mm[1] * PT))
        self._h = size_mm[1]

    def _xy(self, x: float, y: float) -> tuple[float, float]:
        return x * PT, (self._h - y) * PT

    def _set(self, key: str, value, setter) -> None:
        """`setter(*value)` unless `key` is at `value` on this page already."""
        if self._state.get(key) != value:
            self._state[key] = value
            setter(*value)

    def _stroke(self, width: float, colour: str, dash: tuple[float, ...], round_cap: bool) -> None:
        c = self._c
        self._set("width", (width * PT,), c.setLineWidth)
        self._set("stroke", _rgb(colour), c.setStrokeColorRGB)
        self._set("dash", ([d * PT for d in dash],), c.setDash)
        self._set("cap", (1 if round_cap else 0,), c.setLineCap)

    def line(self, x0: float, y0: float, x1: float, y1: float, width: float, colour: str = "#000",
             dash: tuple[float, ...] = (), round_cap: bool = False) -> None:
        """A straight line (mm; width mm; dash: on, off lengths in mm)."""
        self._stroke(width, colour, dash, round_cap)
        self._c.line(*self._xy(x0, y0), *self._xy(x1, y1))

    def polyline(self, points, width: float, colour: str = "#000", round_cap: bool = True) -> None:
        """An open path through `points` (mm)."""
        self._stroke(width, colour, (), round_cap)
        path = self._c.beginPath()
        path.moveTo(*self._xy(*points[0]))
        for p in points[1:]:
            path.lineTo(*self._xy(*p))
        self._c.drawPath(path, stroke=1, fill=0)

    def polygon(self, points, colour: str = "#000") -> None:
        """A filled closed polygon through `points` (mm), no outline."""
        self._set("fill", _rgb(colour), self._c.setFillColorRGB)
        path = self._c.beginPath()
        path.moveTo(*self._xy(*points[0]))
        for p in points[1:]:
            path.lineTo(*self._xy(*p))
        path.close()
        self._c.drawPath(path, stroke=0, fill=1)

    def dot(self, x: float, y: float, r: float, colour: str = "#000") -> None:
        """A filled circle of radius `r` (mm) at (x, y)."""
        self._set("fill", _rgb(colour), self._c.setFillColorRGB)
        self._c.circle(*self._xy(x, y), r * PT, stroke=0, fill=1)

    def text(self, x: float, y: float, s: str, size_mm: float, bold: bool = False, right: bool = False) -> None:
        """`s` with its baseline at y, starting (`right`: ending) at x, `size_mm` high (em), black; its
        symbols' sub- and superscripts (`symbols.text_runs`) smaller, below or above the baseline."""
        c = self._c
        font = BOLD if bold else FONT
        self._set("fill", (0.0, 0.0, 0.0), c.setFillColorRGB)
        self._set("font", (font, size_mm * PT), c.setFont)
        if right:
            x -= text_width(s, size_mm, bold)
        runs = _runs(s, size_mm)
        if len(runs) <= 1 and not any(rise for _, _, rise in runs):
            c.drawString(*self._xy(x, y), runs[0][0] if runs else "")
            return
        t = c.beginText(*self._xy(x, y))
        for piece, size, rise in runs:
            t.setFont(font, size * PT)
            t.setRise(rise * PT)
            t.textOut(piece)
        t.setFont(font, size_mm * PT)
        t.setRise(0)
        c.drawText(t)

    def getvalue(self) -> bytes:
        """The PDF, its last page closed."""
        self._c.showPage()
        self._c.save()
        return self._buf.getvalue()
