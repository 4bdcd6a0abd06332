"""A plan drawn: an SVG sheet true to scale in millimetres (A3 landscape, 420 x 297 mm, as the
appendix sheets of seed 002; the plan centred in the drawing area, a title block that states
the plan's title and scale), and a matplotlib Figure for notebooks and the reports' PNGs.

Labels in English or Ukrainian (`lang="en" | "uk"`): titles, the scale line, the legend and the
table of segments; point letters stay as the texts letter them (digits drawn as subscripts, the
acceleration pole `pi` as π). The SVG is written with the standard library; every text that
comes from a model (names, notes) is escaped.

May use: the standard library, `.core`, `kinetostat._text` (XML-safe text); matplotlib only inside `figure`.
"""
from __future__ import annotations

import math
import re
from .._text import xml_escape as escape     # also control characters, which XML cannot hold

from .core import Plan, Segment

__all__ = ["svg", "figure", "title_of", "scale_text", "LANGS", "SHEET_MM"]

LANGS = ("en", "uk")
#: The sheet: A3 landscape, mm.
SHEET_MM = (420.0, 297.0)
_FRAME = (20.0, 5.0, 415.0, 292.0)          # inner frame: left 20 mm (binding), 5 mm elsewhere
_TITLE_BLOCK = (230.0, 247.0, 415.0, 292.0)  # bottom right, 185 x 45 mm
_AREA = (25.0, 10.0, 410.0, 242.0)          # where the plan is centred

_TITLES = {
    "positions": ("Plan of positions", "План положень"),
    "velocity": ("Velocity plan", "План швидкостей"),
    "acceleration": ("Acceleration plan", "План прискорень"),
    "group": ("Plan of group", "План групи"),
    "forces": ("Force plan of group", "План сил групи"),
    "crank": ("Plan of the initial link", "План початкової ланки"),
    "lever": ("Zhukovsky's lever", "Важіль Жуковського"),
}
_WORDS = {
    "angle": ("crank angle", "кут кривошипа"),
    "scale": ("scale", "масштаб"),
    "sheet": ("sheet A3, true to scale in mm", "аркуш А3, креслення в мм у масштабі"),
    "segment": ("segment", "відрізок"),
    "value": ("value", "значення"),
    "more": ("more segments in segments.csv", "інші відрізки в segments.csv"),
    "nofit": ("the plan does not fit the sheet at this scale", "план не вміщується на аркуші в цьому масштабі"),
}
_LEGENDS = {
    "positions": (("bold: the design position; thin: positions 0-11 every 30 deg; curves: paths of the centres "
                   "of mass", "жирно: розрахункове положення; тонко: положення 0-11 через 30°; криві: "
                   "траєкторії центрів мас"),),
    "velocity": (("p: pole; vectors p-x: absolute velocities; the others: relative velocities",
                  "p: полюс; вектори p-x: абсолютні швидкості; інші: відносні швидкості"),),
    "acceleration": (("π: pole; n: normal, n-x: tangential, k: Coriolis, k-x: relative parts",
                      "π: полюс; n: нормальні, n-x: дотичні, k: коріолісові, k-x: відносні складові"),),
}
#: Phrases of the generated notes, in Ukrainian.
_NOTE_UK = [("position 0 at phi =", "положення 0 при φ ="), ("(crank and rod in line), then every 30 deg",
            "(кривошип і шатун на одній прямій), далі через 30°"), ("design position phi =", "розрахункове положення φ ="),
            ("drawn with plain letters", "позначене літерами без індексу"), ("branch", "складання"),
            ("drawn", "накреслено"), ("dashed to", "штрихом до"), ("the other branch", "інше складання"),
            ("one assembly", "єдине складання"), ("does not assemble here", "тут не складається"),
            ("looks the same here", "тут має той самий вигляд"), (" deg", "°")]
_UNITS = {"m/mm": ("m/mm", "м/мм"), "m/(s mm)": ("m/(s·mm)", "м/(с·мм)"), "m/(s^2 mm)": ("m/(s²·mm)", "м/(с²·мм)"),
          "N/mm": ("N/mm", "Н/мм"), "m/s": ("m/s", "м/с"), "m/s^2": ("m/s²", "м/с²"), "m": ("m", "м"),
          "N": ("N", "Н"), "N m": ("N m", "Н·м"), "mm": ("mm", "мм"), "": ("", "")}


def _lang(lang: str) -> int:
    if lang not in LANGS:
        raise ValueError(f"lang: expected one of {', '.join(LANGS)}, got {lang!r}")
    return LANGS.index(lang)


def _num(x: float, lang: str, fmt: str = ".4g") -> str:
    s = format(x, fmt)
    return s.replace(".", ",") if lang == "uk" else s


def _unit(u: str, lang: str) -> str:
    return _UNITS.get(u, (u, u))[_lang(lang)]


def title_of(plan: Plan, lang: str = "en") -> str:
    """The plan's title in `lang`, with its crank angle."""
    i = _lang(lang)
    base, _, rest = plan.kind.partition(":")
    name = _TITLES[base][i] if base in _TITLES else plan.title
    if rest:
        name += " " + rest.replace(",", "-")
    return f"{name}, φ = {_num(plan.phi_deg, lang, 'g')}°"


def scale_text(plan: Plan, lang: str = "en") -> str:
    """The scale line, e.g. 'μ_v = 0.2 m/(s·mm)'."""
    s = plan.scale
    return f"{s.symbol.replace('mu_', 'μ_')} = {_num(s.value, lang, 'g')} {_unit(s.unit, lang)}"


def _note(text: str, lang: str) -> str:
    if lang == "uk":
        for en, uk in _NOTE_UK:
            text = text.replace(en, uk)
    return text


_LABEL = re.compile(r"^([^\d_']*)([\d_]*)('*)$")


def labelled(name: str) -> bool:
    """Whether a point is lettered on the drawing: the texts' points are; a construction point (an
    arrow's tip or an arm's foot, named '<segment>:to', '<segment>:foot') is not."""
    return ":" not in name


def _label_parts(name: str) -> tuple[str, str, str]:
    """A point name as (letters, subscript, primes): 's2' -> ('s', '2', ''), 'S2_3' -> ('S', '2,3', ''),
    'pi' -> ('π', '', ''), "B'" -> ('B', '', '′')."""
    if name == "pi":
        return "π", "", ""
    m = _LABEL.match(name)
    if not m or not m.group(1):
        return name, "", ""
    return m.group(1), m.group(2).strip("_").replace("_", ","), "′" * len(m.group(3))


# ----------------------------------------------------------------------------- geometry shared by both

def _bbox(plan: Plan) -> tuple[float, float, float, float]:
    zs = [z for z in plan.points.values() if _finite(z)] + [z for p in plan.paths.values() for z in p if _finite(z)]
    if not zs:
        return 0.0, 0.0, 0.0, 0.0
    xs, ys = [z.real for z in zs], [z.imag for z in zs]
    return min(xs), min(ys), max(xs), max(ys)


def _finite(z: complex) -> bool:
    return math.isfinite(z.real) and math.isfinite(z.imag)


def _drawable(plan: Plan) -> list[Segment]:
    return [s for s in plan.segments if _finite(plan.points[s.start]) and _finite(plan.points[s.end])]


_STYLE = {"vector": (0.35, "", "#000"), "link": (0.7, "", "#000"), "position": (0.18, "", "#555"),
          "line": (0.2, "2,1.2", "#555"), "arm": (0.2, "4,1,1,1", "#a33")}


# ----------------------------------------------------------------------------- SVG

def _svg_label(x: float, y: float, name: str, size: float) -> str:
    head, sub, primes = _label_parts(name)
    out = f'<text x="{x:.3f}" y="{y:.3f}" font-size="{size:.2f}">{escape(head)}'
    if sub:
        out += f'<tspan font-size="{0.7 * size:.2f}" dy="{0.3 * size:.2f}">{escape(sub)}</tspan>'
    if primes:
        out += f'<tspan dy="{-0.3 * size if sub else 0:.2f}">{primes}</tspan>'
    return out + "</text>"


def _svg_text(x: float, y: float, text: str, size: float, anchor: str = "start", weight: str = "normal") -> str:
    return (f'<text x="{x:.3f}" y="{y:.3f}" font-size="{size:.2f}" text-anchor="{anchor}" '
            f'font-weight="{weight}">{escape(text)}</text>')


def svg(plan: Plan, lang: str = "en", mechanism: str = "") -> str:
    """The plan on an A3 landscape sheet, true to scale (1 user unit = 1 mm), as SVG text."""
    _lang(lang)
    x0, y0, x1, y1 = _bbox(plan)
    ax0, ay0, ax1, ay1 = _AREA
    tx, ty = (ax0 + ax1) / 2 - (x0 + x1) / 2, (ay0 + ay1) / 2 + (y0 + y1) / 2

    def P(z: complex) -> tuple[float, float]:
        return z.real + tx, ty - z.imag

    W, H = SHEET_MM
    out = ['<?xml version="1.0" encoding="UTF-8"?>',
           f'<svg xmlns="http://www.w3.org/2000/svg" width="{W:g}mm" height="{H:g}mm" viewBox="0 0 {W:g} {H:g}" '
           f'font-family="DejaVu Sans, Arial, sans-serif">',
           f'<title>{escape(title_of(plan, lang))}, {escape(scale_text(plan, lang))}</title>',
           '<defs><marker id="arrow" viewBox="0 0 10 10" refX="10" refY="5" markerWidth="9" markerHeight="9" '
           'markerUnits="userSpaceOnUse" orient="auto"><path d="M0,2 L10,5 L0,8 z" fill="#000"/></marker></defs>',
           f'<rect x="0" y="0" width="{W:g}" height="{H:g}" fill="#fff"/>',
           f'<rect x="{_FRAME[0]}" y="{_FRAME[1]}" width="{_FRAME[2] - _FRAME[0]:g}" height="{_FRAME[3] - _FRAME[1]:g}" '
           f'fill="none" stroke="#000" stroke-width="0.7"/>',
           '<g id="plan" stroke-linecap="round">']
    for name, path in plan.paths.items():
        pts = " ".join(f"{a:.3f},{b:.3f}" for a, b in (P(z) for z in path if _finite(z)))
        out.append(f'<polyline points="{pts}" fill="none" stroke="#1f5fa8" stroke-width="0.25">'
                   f'<title>{escape(name)}</title></polyline>')
    for s in _drawable(plan):
        (a, b), (c, d) = P(plan.points[s.start]), P(plan.points[s.end])
        width, dash, colour = _STYLE.get(s.kind, _STYLE["line"])
        if s.kind == "vector" and math.hypot(c - a, d - b) < 0.05:
            continue                       # a zero vector: its two points coincide
        attrs = f' stroke-dasharray="{dash}"' if dash else ""
        attrs += ' marker-end="url(#arrow)"' if s.kind == "vector" else ""
        out.append(f'<line x1="{a:.3f}" y1="{b:.3f}" x2="{c:.3f}" y2="{d:.3f}" stroke="{colour}" '
                   f'stroke-width="{width}"{attrs}><title>{escape(s.name)}</title></line>')
        if not labelled(s.end):            # a load or an arm ends at a construction point: letter the segment
            out.append(_svg_text(c + 1.0, d - 1.0, s.name, 2.8))
    small = plan.kind == "positions"
    for name, z in plan.points.items():
        if not _finite(z) or not labelled(name):
            continue
        a, b = P(z)
        numbered = small and bool(re.search(r"\d$", name)) and name not in _frame_like(plan)
        size = 2.2 if numbered else 3.5
        out.append(f'<circle cx="{a:.3f}" cy="{b:.3f}" r="{0.35 if numbered else 0.6}" fill="#000"/>')
        out.append(_svg_label(a + 0.8, b - 0.8, name, size))
    out.append("</g>")
    out += _svg_title_block(plan, lang, mechanism)
    out += _svg_notes(plan, lang, fits=(x1 - x0 <= ax1 - ax0 and y1 - y0 <= ay1 - ay0))
    out.append("</svg>")
    return "\n".join(out) + "\n"


def _frame_like(plan: Plan) -> set[str]:
    """Names of points that are the same in every position (the frame's), from the link segments."""
    return {n for n in plan.points if not any(n in (s.start, s.end) for s in plan.segments if s.kind == "position")}


def _svg_title_block(plan: Plan, lang: str, mechanism: str) -> list[str]:
    i = _lang(lang)
    x0, y0, x1, y1 = _TITLE_BLOCK
    out = [f'<g id="title-block"><rect x="{x0}" y="{y0}" width="{x1 - x0:g}" height="{y1 - y0:g}" fill="none" '
           f'stroke="#000" stroke-width="0.5"/>',
           f'<line x1="{x0}" y1="{y0 + 12}" x2="{x1}" y2="{y0 + 12}" stroke="#000" stroke-width="0.25"/>',
           f'<line x1="{x0}" y1="{y0 + 24}" x2="{x1}" y2="{y0 + 24}" stroke="#000" stroke-width="0.25"/>',
           _svg_text(x0 + 3, y0 + 8, title_of(plan, lang), 5, weight="bold"),
           f'<text id="scale" x="{x0 + 3:.1f}" y="{y0 + 20:.1f}" font-size="4.5">{escape(_WORDS["scale"][i])}: '
           f'{escape(scale_text(plan, lang))}</text>',
           _svg_text(x0 + 3, y0 + 30, _clip(mechanism, 70), 3),
           _svg_text(x0 + 3, y0 + 36, f"{_WORDS['angle'][i]} φ = {_num(plan.phi_deg, lang, 'g')}°", 3),
           _svg_text(x0 + 3, y0 + 42, _WORDS["sheet"][i], 2.5),
           "</g>"]
    return out


def _clip(text: str, n: int) -> str:
    return text if len(text) <= n else text[:n - 1] + "…"


def _svg_notes(plan: Plan, lang: str, fits: bool) -> list[str]:
    """Legend, notes and (for vector plans) the table of segments, bottom left of the sheet."""
    i = _lang(lang)
    x, y = _FRAME[0] + 3, _TITLE_BLOCK[1] + 4
    lines = [legend[i] for legend in _LEGENDS.get(plan.kind.partition(":")[0], ())]
    lines += [_note(n, lang) for n in plan.notes]
    if not fits:
        lines.append(_WORDS["nofit"][i])
    out = ['<g id="notes">']
    for k, text in enumerate(lines[:4]):
        out.append(_svg_text(x, y + 3.2 * k, _clip(text, 120), 2.4))
    rows = [s for s in plan.segments if s.kind in ("vector", "arm") and math.isfinite(s.value)]
    if rows:
        top = y + 3.2 * min(len(lines), 4) + 1
        per_col, col_w = max(1, int((_FRAME[3] - top - 1) // 3)), 70.0
        cols = max(1, int((_TITLE_BLOCK[0] - x - 2) // col_w))
        shown = rows[:per_col * cols]
        for k, s in enumerate(shown):
            cx, cy = x + col_w * (k // per_col), top + 3 + 3 * (k % per_col)
            text = (f"{s.name}: {_num(plan.length_mm(s.name), lang, '.2f')} {_unit('mm', lang)} → "
                    f"{_num(s.value, lang)} {_unit(s.unit, lang)}")
            out.append(_svg_text(cx, cy, _clip(text, 44), 2.3))
        if len(rows) > len(shown):
            out.append(_svg_text(x + col_w * (cols - 1), _FRAME[3] - 1, _WORDS["more"][i], 2.0))
    out.append("</g>")
    return out


# ----------------------------------------------------------------------------- matplotlib

def _tex(name: str) -> str:
    """A point name as mathtext (letters with a subscript), or as it is where it is anything
    else: `figure` then draws it with mathtext off (a model's point may be named anything)."""
    head, sub, primes = _label_parts(name)
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
        x0, y0, x1, y1 = _bbox(plan)
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
            ax.annotate(s.name, (b.real, b.imag), xytext=(3, -9), textcoords="offset points", fontsize=8,
                        color=colour)
    small = plan.kind == "positions"
    frame = _frame_like(plan) if small else set()
    for name, z in plan.points.items():
        if not _finite(z) or not labelled(name):
            continue
        numbered = small and bool(re.search(r"\d$", name)) and name not in frame
        ax.plot([z.real], [z.imag], "o", color="k", ms=1.5 if numbered else 3)
        label = _tex(name)
        ax.annotate(label, (z.real, z.imag), xytext=(3, 3), textcoords="offset points", parse_math=label != name,
                    fontsize=6 if numbered else 10)
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel(_unit("mm", lang))
    ax.set_ylabel(_unit("mm", lang))
    ax.set_title(f"{title_of(plan, lang)}\n{scale_text(plan, lang)}", fontsize=10)
    ax.grid(True, lw=0.3, alpha=0.5)
    return fig
