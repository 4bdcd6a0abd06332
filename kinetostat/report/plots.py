"""The report's figures (matplotlib, imported inside the functions: no pyplot, no global state
beyond `plain_text`'s settings while the figures are made).

Every text of a figure is plain text: a model's name or a point's name is never parsed as a
mathtext formula or given to LaTeX (`plain_text`).

Names as the model's text letters them (`model.lettering`: R43 for the ICE's R(0,3), M_зр): every
quantity a figure or a table shows goes through `quantity_name`.

May use: numpy, matplotlib, the solver's results, the runs room, `kinetostat._io` (atomic writes)
and the model's lettering (`model.lettering`).
"""
from __future__ import annotations

import functools
import io
import math
import re
from contextlib import contextmanager
from pathlib import Path
from typing import Any, Iterator

import numpy as np

from .._io import atomic
from ..analysis import Analysis
from ..model import Mechanism
from ..model.lettering import lettering, pair_name, reaction_name
from .runs import ModelRun, quantities


_ROUTE_STYLE = {"pinocchio": ("tab:blue", (0, (6, 3))), "mujoco": ("tab:orange", (0, (2, 2))),
                "mujoco-sim": ("tab:green", (0, (6, 2, 1, 2))), "pymunk": ("tab:red", (0, (1, 1.5)))}
_EXTRA = ["tab:purple", "tab:brown", "tab:pink", "tab:olive", "tab:cyan"]


def _style(route: str, n: int = 0) -> tuple[str, Any]:
    return _ROUTE_STYLE.get(route, (_EXTRA[n % len(_EXTRA)], (0, (4, 2))))


def _figure(w: float, h: float, left: float, right: float, top: float, bottom: float):
    """A figure w x h inches with a fixed layout: the margins around its axes grid in inches
    (no constrained layout: it measured every text of the figure, and drew it twice). Titles
    are set with y=1.0: a fixed place, not one found by measuring the axes' tick labels."""
    from matplotlib.figure import Figure
    fig = Figure(figsize=(w, h), layout=None)
    fig.subplots_adjust(left=left / w, right=1 - right / w, top=1 - top / h, bottom=bottom / h)
    return fig


#: Grid of small panels, inches: panel size, gaps (room for tick labels, a two-line title and
#: the y label), margins (a two-line suptitle on top, the x label and legend below).
_CELL_W, _CELL_H, _GAP_W, _GAP_H, _LEFT, _RIGHT = 3.7, 2.3, 0.95, 0.85, 0.85, 0.2
_LINE_10PT, _LEGEND_ROW, _CHARS_PER_INCH_10PT = 0.19, 0.22, 12.5
#: characters of a 9 pt panel title on one line of a panel
_TITLE_CHARS = int(_CELL_W * _CHARS_PER_INCH_10PT * 10 / 9)


def _panels(n: int, title: str, n_legend: int, ncols_legend: int, cell_h: float = _CELL_H):
    """Figure, its n axes (in a rows x cols grid, row by row) and cols: the title on top
    (wrapped to the width), room for a legend of n_legend entries in ncols_legend columns below."""
    rows, cols = _grid(n)
    w = _LEFT + _RIGHT + cols * _CELL_W + (cols - 1) * _GAP_W
    lines = "\n".join(_wrap(t, int(w * _CHARS_PER_INCH_10PT), 3) for t in title.splitlines())
    top = 0.15 + _LINE_10PT * (lines.count("\n") + 1) + 0.45       # the title, then a two-line panel title
    bottom = 0.55 + _LEGEND_ROW * math.ceil(n_legend / max(ncols_legend, 1)) + 0.1
    h = top + bottom + rows * cell_h + (rows - 1) * _GAP_H
    fig = _figure(w, h, _LEFT, _RIGHT, top, bottom)
    fig.subplots_adjust(wspace=_GAP_W / _CELL_W, hspace=_GAP_H / cell_h)
    fig.suptitle(lines, fontsize=10, y=1 - 0.1 / h, va="top")
    grid = fig.add_gridspec(rows, cols)
    return fig, [fig.add_subplot(grid[i // cols, i % cols]) for i in range(n)], cols     # no axes for an empty cell


def _legend(fig, handles: dict, ncols: int) -> None:
    if handles:
        fig.legend(list(handles.values()), list(handles), loc="lower center", ncols=ncols, fontsize=8,
                   bbox_to_anchor=(0.5, 0.02 / fig.get_figheight()), frameon=False)


def _legend_cols(n: int, most: int) -> int:
    return max(1, min(n, most))


@contextmanager
def plain_text() -> Iterator[None]:
    """Figures made in this block take every text literally: no mathtext (a model named
    "$\\frac{$" would abort the drawing) and no LaTeX, whatever the user's matplotlibrc says;
    tick labels and offsets as plain numbers (1e-13, not a mathtext power of ten); glyphs
    measured unhinted (matplotlib's default hints each glyph at 8x its width, for a raster
    the figures are not); the SVG's text as text (`_save`), without a date or random ids, in
    DejaVu Sans (matplotlib's own font, always there; the SVG names it alone, not the ten
    fallbacks of matplotlib's default list in every text)."""
    import matplotlib
    with matplotlib.rc_context({"text.parse_math": False, "text.usetex": False, "axes.formatter.use_mathtext": False,
                                "text.hinting": "none", "svg.fonttype": "none", "svg.hashsalt": "kinetostat",
                                "font.family": "sans-serif", "font.sans-serif": ["DejaVu Sans"]}):
        yield


#: In matplotlib's SVG: a path's data (absolute M, L, Q, C and z commands, six decimals of a
#: point), a text's or a marker's place and transform (`_compact`); a number in those.
_PATH_DATA = re.compile(r' d="([^"]*)"')
_PLACES = re.compile(r'( (?:x|y|transform)=")([^"]*)')
_COORDINATE = re.compile(r"-?\d+\.\d+")
#: every text's font (`plain_text`), given once for all texts in the SVG's style sheet
_FONT = "font-family: 'DejaVu Sans', sans-serif"
_NO_ROTATION = re.compile(r' transform="rotate\(-?0 [-\d. ]+\)"')
#: coordinate pairs after each command of a path
_PAIRS = {"M": 1, "L": 1, "Q": 2, "C": 3}


@functools.lru_cache(maxsize=4096)
def _tenths(n: int) -> str:
    """n tenths of a point, the SVG's shortest way: 0, 12, .5, -3.7 (kept for the steps that recur:
    a figure's paths hold about 100 000 of them, mostly a few hundred small ones)."""
    whole, part = divmod(abs(n), 10)
    text = (str(whole) if whole else "") + (f".{part}" if part else "")
    return ("-" + text if n < 0 else text) or "0"


def _relative(d: str) -> str:
    """matplotlib's path data as relative commands (m, l, q, c; a repeated command's letter
    left out) on coordinates rounded to 0.1 pt (0.035 mm: a fraction of a screen's pixel even at
    400 %): the same outline, each point given as the step from the one before (rounded first,
    so the steps add up to the rounded points exactly)."""
    tokens = d.split()
    out: list[str] = []
    x0 = y0 = sx = sy = 0          # the current point and the subpath's start, 0.1 pt
    last, i = "", 0
    while i < len(tokens):
        cmd = tokens[i]
        i += 1
        if cmd not in _PAIRS:       # z: back to the subpath's start
            out.append(cmd.lower())
            x0, y0, last = sx, sy, "z"
            continue
        n = 2 * _PAIRS[cmd]
        xy = [round(float(t) * 10) for t in tokens[i:i + n]]
        i += n
        steps = " ".join(_tenths(v - (y0 if k % 2 else x0)) for k, v in enumerate(xy))
        letter = cmd.lower()
        out.append((letter if letter != last or letter == "m" else " ") + steps)
        x0, y0, last = xy[-2], xy[-1], letter
        if letter == "m":
            sx, sy = x0, y0
    return "".join(out).replace(" -", "-")


def _compact(svg: str) -> str:
    """matplotlib's SVG with a text's or a marker's place to 0.01 pt, a path's data as relative
    steps of 0.1 pt (`_relative`), a text's rotation by 0° left out, the texts' font named once
    (`_FONT`): the figures drawn the same in fewer bytes."""
    def point(m: re.Match) -> str:
        return f"{round(float(m[0]), 2) + 0.0:.2f}".rstrip("0").rstrip(".")
    svg = _PATH_DATA.sub(lambda m: f' d="{_relative(m[1])}"', svg)
    svg = _NO_ROTATION.sub("", svg)
    svg = svg.replace(_FONT + "; ", "").replace("; " + _FONT, "").replace('<style type="text/css">*{',
                                                                         '<style type="text/css">text{%s}*{' % _FONT, 1)
    return _PLACES.sub(lambda m: m[1] + _COORDINATE.sub(point, " ".join(m[2].split())), svg)


def _save(fig, path: Path) -> Path:
    """The figure as SVG (matplotlib's SVG backend, in `plain_text`, `_compact`): vector lines,
    and text as text a reader can search and copy (half the time of rendering a PNG and writing
    it: the report's figures were its largest cost); no date or software version in the file, so
    it depends on the figure only. Written atomically (an interrupt leaves the previous file as it was)."""
    from matplotlib.backends.backend_svg import FigureCanvasSVG
    buf = io.StringIO()
    FigureCanvasSVG(fig).print_svg(buf, metadata={"Date": None, "Creator": None})
    with atomic(path) as f:
        f.write(_compact(buf.getvalue()))
    return path


def _decade(value: float) -> str:
    """A log axis' tick label as plain text: 1e-3, 1, 1e+2 (matplotlib's own log labels are
    mathtext, which `plain_text` prints literally)."""
    if not value > 0:
        return ""
    e = round(math.log10(value))
    if abs(math.log10(value) - e) > 1e-9:
        return f"{value:.0e}".replace("e-0", "e-").replace("e+0", "e")
    return "1" if e == 0 else f"1e{e}"


#: The light axes (`_axes`): tick labels' size and gap to the frame, the axis labels' size, pt.
_TICK_PT, _PAD_PT, _LABEL_PT = 10.0, 5.0, 10.0


def _names(values, log: bool) -> list[str]:
    """Tick labels as plain text, each with the fewest significant digits (at least 3) that tell
    the ticks apart: 0, 90, −4000, 2.5e-14, 1000.000001 (a curve that barely moves about 1000);
    a log axis' labels `_decade`. A negative number's sign is U+2212 (matplotlib's), an
    exponent's sign is plain: 1e-15, −1e-14."""
    if log:
        return [_decade(v) for v in values]
    for digits in range(3, 18):
        names = [re.sub(r"e([+-])0*(\d)", lambda m: "e" + m.group(1).replace("+", "") + m.group(2),
                        f"{v:.{digits}g}") if v else "0" for v in values]
        if len(set(names)) == len(names):
            break
    return [n[0].replace("-", "−") + n[1:] for n in names]


def _nice(n: int = 6):
    """A linear axis' ticks: at most n + 1 at steps of 1, 2, 2.5 or 5 times a power of ten
    (matplotlib's own default steps: never 80 or 150)."""
    from matplotlib.ticker import MaxNLocator
    return MaxNLocator(n, steps=[1, 2, 2.5, 5, 10])


def _ticks(lo: float, hi: float, log: bool, loc=None) -> list[float]:
    """The ticks of `loc` within [lo, hi] (the view); without `loc`, `_nice()`, or on a log axis
    LogLocator(numticks=6)'s decades, with 2 and 5 between them where fewer than two fall in view."""
    from matplotlib.ticker import LogLocator
    f = np.log10 if log else float
    tol = 1e-9 * (f(hi) - f(lo))
    ticks: list[float] = []
    for loc in [loc] if loc else [LogLocator(numticks=6), LogLocator(numticks=6, subs=(1.0, 2.0, 5.0))] if log else [_nice()]:
        ticks = [t for t in loc.tick_values(lo, hi) if (t > 0 or not log) and f(lo) - tol <= f(t) <= f(hi) + tol]
        if len(ticks) >= 2:
            break
    return ticks


def _axes(ax, x=None, y=None, xlabel: str | None = None, ylabel: str | None = None, ylabel_pt: float = _LABEL_PT,
          xnumbers: bool = True) -> None:
    """ax's two axes drawn light, after its data and limits are set: `x`, `y` are tick locators
    (`_ticks`; labels `_names`); the ticks within the view are drawn as one grid path (both
    axes' grids), a text per label, the axis labels as texts and the frame as one rectangle, in
    place of matplotlib's own axes, which make five artists per tick (half of these figures'
    drawing time) and four spines. No tick marks: the grid carries the ticks. `xnumbers` False:
    the x grid without its labels (a panel above another on the same x)."""
    from matplotlib.collections import LineCollection
    from matplotlib.patches import Rectangle
    from matplotlib.transforms import offset_copy
    ax.apply_aspect()
    widest = 0
    grid: list[tuple[float, float]] = []          # the grid's lines in data coordinates, NaN between
    (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
    for axis, loc in ((ax.xaxis, x), (ax.yaxis, y)):
        along_x = axis is ax.xaxis
        log = axis.get_scale() == "log"
        ticks = _ticks(*sorted(axis.get_view_interval()), log, loc)
        names = _names(ticks, log)
        for t in ticks:
            grid += [(t, y0), (t, y1), (math.nan, math.nan)] if along_x else [(x0, t), (x1, t), (math.nan, math.nan)]
        if along_x and not xnumbers:
            continue
        trans, va, ha = (ax.get_xaxis_text1_transform if along_x else ax.get_yaxis_text1_transform)(_PAD_PT)
        for t, name in zip(ticks, names):
            ax.text(*((t, 0) if along_x else (0, t)), name, transform=trans, va=va, ha=ha, fontsize=_TICK_PT)
        widest = 0 if along_x else max(map(len, names), default=0)
    if grid:              # a collection (not a line): a legend's "best" place does not avoid it
        ax.add_collection(LineCollection([grid], colors="#b0b0b0", alpha=0.3, linewidths=0.8, zorder=0.5),
                          autolim=False)
    ax.spines[:].set_visible(False)                 # the frame as one rectangle in place of four spines
    ax.add_artist(Rectangle((0, 0), 1, 1, transform=ax.transAxes, fill=False, edgecolor="black", lw=0.8,
                            joinstyle="miter", zorder=2.5, clip_on=False))
    ax.set_xlim(ax.get_xlim())                      # frozen: nothing added later moves the grid
    ax.set_ylim(ax.get_ylim())
    ax.xaxis.set_visible(False)
    ax.yaxis.set_visible(False)
    if xlabel:
        ax.text(0.5, 0, xlabel, transform=offset_copy(ax.transAxes, ax.figure, y=-(_PAD_PT + 1.3 * _TICK_PT + 3),
                                                      units="points"), ha="center", va="top", fontsize=_LABEL_PT)
    if ylabel:
        ax.text(0, 0.5, ylabel, transform=offset_copy(ax.transAxes, ax.figure, x=-(_PAD_PT + 0.64 * _TICK_PT * widest + 4),
                                                      units="points"), ha="right", va="center", rotation=90, fontsize=ylabel_pt)


def _hline(ax, y: float, **style) -> Any:
    """A line across ax at height y (data), as `axhline` draws it (y in the data limits) but as two
    points: `axhline` gives a log axis' line 100 points."""
    h, = ax.plot([0, 1], [y, y], transform=ax.get_yaxis_transform(), **style)
    return h


def _phi_axes(ax, label: bool = True, step: int = 90, y=None, ylabel: str | None = None, ylabel_pt: float = _LABEL_PT,
              xnumbers: bool = True) -> None:
    """`_axes` with the crank-angle axis 0..360 deg, ticks every `step` deg."""
    from matplotlib.ticker import FixedLocator
    ax.set_xlim(0, 360)
    _axes(ax, FixedLocator(range(0, 361, step)), y, "crank angle φ, deg" if label else None, ylabel, ylabel_pt, xnumbers)


def quantity_name(mech: Mechanism, q: str) -> str:
    """A quantity (or a phrase naming quantities) as the model's text names them: R(0,3) -> R43
    (the frame lettered 4), M_drive and M_bal -> M_зр, F_bal -> F_зр; other words as they are."""
    L = lettering(mech)
    q = re.sub(r"R\((\d+),(\d+)\)", lambda m: reaction_name(mech, int(m.group(1)), int(m.group(2))), q)
    q = re.sub(r"\bM_(bal|drive)\b", lambda _: L.M_bal, q)
    return re.sub(r"\bF_bal\b", lambda _: L.F_bal, q)


def _link_name(mech: Mechanism, k: int) -> str:
    return "frame" if k == 0 else mech.links[k].name


def _wrap(text: str, width: int = _TITLE_CHARS, lines: int = 2) -> str:
    """text on at most `lines` lines of `width` characters (cut with "…" beyond)."""
    import textwrap
    return textwrap.fill(text, width, max_lines=lines, placeholder=" …")


def _grid(n: int) -> tuple[int, int]:
    """rows, cols of n panels: at most two columns, so that a page 800 px wide shows the
    figure at three quarters of its size or more (readable tick labels)."""
    cols = 1 if n == 1 else 2
    return math.ceil(n / cols), cols


def _closed(phi: np.ndarray, *ys: np.ndarray):
    """Close a full-cycle curve at 360 deg (phi equally spaced from 0)."""
    if len(phi) > 2 and abs(phi[0]) < 1e-9 and abs(phi[-1] + (phi[1] - phi[0]) - 360.0) < 1e-6:
        return (np.append(phi, 360.0),) + tuple(np.concatenate([y, y[:1]]) for y in ys)
    return (phi,) + ys


def _line(er, res: Analysis, col, ls, lw: float) -> dict[str, Any]:
    """Line style of a route's curve: a line over the whole cycle, or markers where the route
    evaluated only some of the angles (the reference route)."""
    if len(er.phi_deg) < len(res.phi_deg):
        return dict(color=col, ls="none", marker="o", ms=3.5)
    return dict(color=col, ls=ls, lw=lw)


def _world(res: Analysis, i: int) -> dict[int, dict[str, np.ndarray]]:
    """World positions of every link's points at angle index i."""
    m, kin = res.mech, res.kin
    out = {0: {n: np.asarray(xy, float) for n, xy in m.links[0].points.items()}}
    for link in m.links[1:]:
        out[link.id] = {n: kin.point(link.id, np.asarray(xy, float))[0][i] for n, xy in link.points.items()}
    return out


def _hull(pts: np.ndarray) -> np.ndarray:
    """Convex hull (monotone chain) of a few 2-D points, counter-clockwise."""
    P = sorted(set(map(tuple, np.round(pts, 12))))
    if len(P) <= 2:
        return np.array(P)
    cross = lambda o, a, b: (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
    lower, upper = [], []
    for p in P:
        while len(lower) >= 2 and cross(lower[-2], lower[-1], p) <= 0:
            lower.pop()
        lower.append(p)
    for p in reversed(P):
        while len(upper) >= 2 and cross(upper[-2], upper[-1], p) <= 0:
            upper.pop()
        upper.append(p)
    return np.array(lower[:-1] + upper[:-1])


def plot_mechanism(res: Analysis, cycle: Analysis, path: Path) -> Path:
    """The linkage at res's single angle; `cycle` gives the point paths and guide strokes."""
    from matplotlib.patches import Polygon

    m = res.mech
    fig = _figure(8, 6.5, left=0.8, right=0.2, top=0.6, bottom=0.6)
    ax = fig.subplots()
    W = _world(res, 0)
    size = m.size
    colors = {k: f"C{k % 10}" for k in range(1, m.n_links)}
    # point paths over the cycle
    for link in m.links[1:]:
        for name, xy in link.points.items():
            P = cycle.kin.point(link.id, np.asarray(xy, float))[0]
            if np.ptp(P[:, 0]) + np.ptp(P[:, 1]) > 1e-9 * size:
                ax.plot(*_closed(cycle.phi_deg, P[:, 0], P[:, 1])[1:], color="0.75", lw=0.8, ls=":", zorder=1)
    # gear: pitch circle of the wheel on the crank shaft
    if m.drive.kind == "machine" and m.drive.gear is not None:
        c = W[0][m.drive.pivot] if m.drive.pivot in W[0] else W[1][m.drive.pivot]
        t = np.linspace(0, 2 * np.pi, 200)
        rw = m.drive.gear.r_w
        ax.plot(c[0] + rw * np.cos(t), c[1] + rw * np.sin(t), color="0.55", lw=1, ls="--", zorder=1,
                label=f"pitch circle of the crank's wheel, r = {rw:.4g} m")
    # links
    from matplotlib.colors import to_rgba
    for link in m.links[1:]:
        pts = np.array(list(W[link.id].values()))
        h = _hull(pts)
        col = colors[link.id]
        label = f"{link.id}: {link.name}"
        area = 0.5 * abs(np.dot(h[:, 0], np.roll(h[:, 1], 1)) - np.dot(h[:, 1], np.roll(h[:, 0], 1))) if len(h) >= 3 else 0.0
        span = max((np.linalg.norm(a - b) for a in pts for b in pts), default=0.0)
        if len(h) >= 3 and area > 0.02 * span**2:
            ax.add_patch(Polygon(h, closed=True, facecolor=to_rgba(col, 0.22), edgecolor=col, lw=2.5,
                                 joinstyle="round", zorder=3, label=label))
        elif span > 0:   # two points, or all on a line: a bar between the farthest two
            i, j = max(((i, j) for i in range(len(pts)) for j in range(len(pts))),
                       key=lambda ij: np.linalg.norm(pts[ij[0]] - pts[ij[1]]))
            ax.plot(pts[[i, j], 0], pts[[i, j], 1], color=col, lw=4, solid_capstyle="round", zorder=3, label=label)
        else:
            ax.plot([], [], color=col, lw=4, label=label)     # a one-point link: drawn as its block
    # prismatic pairs: guide line and block
    blk_l, blk_w = 0.16 * size, 0.08 * size
    for p in m.pairs:
        if p.kind != "P":
            continue
        g, s = p.links
        d_loc = np.asarray(p.direction, float)
        th_g = res.kin.theta[0, g]
        d = np.array([math.cos(th_g) * d_loc[0] - math.sin(th_g) * d_loc[1],
                      math.sin(th_g) * d_loc[0] + math.cos(th_g) * d_loc[1]])
        n = np.array([-d[1], d[0]])
        G, S = W[g][p.guide], W[s][p.point]
        # stroke of the slider along the guide over the cycle, in the guide's frame
        thc = cycle.kin.theta[:, g]
        Gc = cycle.kin.point(g, np.asarray(m.links[g].points[p.guide], float))[0] if g else \
            np.broadcast_to(G, (len(thc), 2))
        Sc = cycle.kin.point(s, np.asarray(m.links[s].points[p.point], float))[0]
        dc = np.stack([np.cos(thc) * d_loc[0] - np.sin(thc) * d_loc[1],
                       np.sin(thc) * d_loc[0] + np.cos(thc) * d_loc[1]], -1)
        u = np.sum((Sc - Gc) * dc, axis=-1)
        u = u[np.isfinite(u)]
        lo, hi = (float(u.min()), float(u.max())) if u.size else (0.0, 0.0)
        lo, hi = lo - 0.6 * blk_l, hi + 0.6 * blk_l
        a, b = G + lo * d, G + hi * d
        if g == 0:   # a fixed guide: its axis, two rails and hatching outside them (a cylinder / slideway)
            a0, b0 = G + min(lo, 0.0) * d, G + max(hi, 0.0) * d     # the axis reaches the guide point
            ax.plot([a0[0], b0[0]], [a0[1], b0[1]], color="0.45", lw=0.8, ls="-.", zorder=2)
            for sgn in (-1, 1):
                r0, r1 = a + sgn * 0.6 * blk_w * n, b + sgn * 0.6 * blk_w * n
                ax.plot([r0[0], r1[0]], [r0[1], r1[1]], color="0.3", lw=1.4, zorder=2)
                q = r0 + np.linspace(0.04, 0.96, 12)[:, None] * (r1 - r0)      # 12 hatches: one line, NaN between
                e = q + sgn * 0.3 * blk_w * n + 0.3 * blk_w * d
                ax.plot(*np.stack([q, e, np.full_like(q, np.nan)], 1).reshape(-1, 2).T, color="0.5", lw=0.7, zorder=2)
        else:        # a guide on a moving link: the slot, drawn in that link's colour
            ax.plot([a[0], b[0]], [a[1], b[1]], color=colors[g], lw=2.5, alpha=0.8, zorder=2)
            for sgn in (-1, 1):
                r0, r1 = a + sgn * 0.6 * blk_w * n, b + sgn * 0.6 * blk_w * n
                ax.plot([r0[0], r1[0]], [r0[1], r1[1]], color=colors[g], lw=1.0, zorder=2)
        corners = [S + a * 0.5 * blk_l * d + b * 0.5 * blk_w * n for a, b in ((-1, -1), (1, -1), (1, 1), (-1, 1))]
        ax.add_patch(Polygon(np.array(corners), closed=True, facecolor=colors[s], alpha=0.55,
                             edgecolor="black", lw=1.2, zorder=4))
    # springs: zigzag between their ends
    for sp in m.springs:
        A, B = W[sp.a[0]][sp.a[1]], W[sp.b[0]][sp.b[1]]
        t = np.linspace(0, 1, 25)
        v = B - A
        L = np.linalg.norm(v) or 1.0
        nn = np.array([-v[1], v[0]]) / L
        wig = np.where((np.arange(25) % 2 == 1) & (t > 0.1) & (t < 0.9), 1.0, 0.0) * np.where(np.arange(25) % 4 == 1, 1, -1)
        Z = A + np.outer(t, v) + np.outer(0.04 * size * wig, nn)
        ax.plot(Z[:, 0], Z[:, 1], color="tab:gray", lw=1.2, zorder=2, label=f"spring: {sp.name}")
    # revolute pairs: circles; fixed ones get a ground mark
    for p in m.pairs:
        if p.kind != "R":
            continue
        k = p.links[1] if p.links[0] == 0 else p.links[0]
        X = W[k][p.point]
        if 0 in p.links:
            tri = np.array([X, X + size * np.array([-0.06, -0.09]), X + size * np.array([0.06, -0.09])])
            ax.add_patch(Polygon(tri, closed=True, facecolor="0.85", edgecolor="0.3", zorder=2))
            ax.plot([X[0] - 0.09 * size, X[0] + 0.09 * size], [X[1] - 0.09 * size] * 2, color="0.3", lw=1.5, zorder=2)
        ax.plot(*X, marker="o", ms=9, mfc="white", mec="black", mew=1.6, zorder=6)
    # points that are not revolute pairs: centres of mass filled, others hollow, frame points grey
    placed: dict[str, np.ndarray] = {}
    for k in range(m.n_links):
        for name, X in W[k].items():
            placed.setdefault(name, X)
    pivots = {p.point for p in m.pairs if p.kind == "R"}
    coms = {link.com for link in m.links[1:] if link.com}
    for name, X in placed.items():
        if name in pivots:
            continue
        if name in coms:
            ax.plot(*X, marker="o", ms=5, color="black", zorder=7)
        elif name in W[0]:
            ax.plot(*X, marker="s", ms=5, mfc="0.8", mec="0.3", zorder=7)
        else:
            ax.plot(*X, marker="o", ms=4.5, mfc="white", mec="black", zorder=7)
    # labels: points closer than 3 % of the size share one label ("O1, C1")
    groups: list[tuple[list[str], np.ndarray]] = []
    for name, X in placed.items():
        for names, Y in groups:
            if np.linalg.norm(X - Y) < 0.03 * size:
                names.append(name)
                break
        else:
            groups.append(([name], X))
    centre = np.mean(np.array(list(placed.values())), axis=0)
    for names, X in groups:
        off = X - centre
        off = off / (np.linalg.norm(off) or 1.0)
        ax.annotate(", ".join(names), X, xytext=(7 * off[0] + 6, 7 * off[1] + 8), textcoords="offset points",
                    fontsize=10, fontweight="bold", zorder=8,
                    bbox=dict(boxstyle="round,pad=0.1", fc="white", ec="none", alpha=0.7))
    ax.set_aspect("equal", adjustable="datalim")
    _axes(ax, xlabel="x, m", ylabel="y, m")
    ax.set_title(f"{m.name}\nat φ = {res.phi_deg[0]:.4g}° (dotted: paths of the points over the cycle)",
                 fontsize=10, y=1.0)
    ax.legend(loc="best", fontsize=8, framealpha=0.85)
    return _save(fig, path)


def plot_moment(run: ModelRun, path: Path) -> Path:
    res, m = run.res, run.mech
    fig = _figure(9.5, 6.5, left=1.0, right=0.2, top=0.6, bottom=0.6)
    fig.subplots_adjust(hspace=0.15)
    ax, ax2 = fig.subplots(2, 1, sharex=True, height_ratios=[3, 1])
    phi = res.phi_deg
    ax.plot(*_closed(phi, res.balancing_moment), color="black", lw=2.6, label="kinetostat: group by group")
    ax.plot(*_closed(phi, res.lever_moment), color="0.55", lw=1.4, ls="--", label="kinetostat: Zhukovsky's lever")
    for n, (route, er) in enumerate(run.results.items()):
        col, ls = _style(route, n)
        ax.plot(*_closed(er.phi_deg, er.M_drive), **_line(er, res, col, ls, 1.6), label=f"{route} ({er.route})")
    _hline(ax, 0, color="0.3", lw=0.6)
    kind = "moment of the drive on the crank about +z"
    ax.set_title(f"{m.name}\nbalancing moment ({kind}) over the cycle", fontsize=10, y=1.0)
    ax.legend(fontsize=8, loc="best")
    _phi_axes(ax, label=False, step=30, xnumbers=False, ylabel=f"balancing moment on the crank {quantity_name(m, 'M_bal')}, N·m")
    ax2.plot(*_closed(phi, res.lever_discrepancy), color="0.3", lw=1)
    _phi_axes(ax2, step=30, y=_nice(3), ylabel="lever − groups, N·m", ylabel_pt=9)
    return _save(fig, path)


def plot_reactions(run: ModelRun, path: Path) -> Path:
    res, m = run.res, run.mech
    ncols = _legend_cols(1 + len(run.results), 5)
    fig, axes, cols = _panels(len(m.pairs), f"{m.name}\nreaction magnitudes over the cycle "
                              f"(R(i,j): force of link i on link j)", 1 + len(run.results), ncols)
    handles = {}
    for n_ax, (ax, p) in enumerate(zip(axes, m.pairs)):
        mag = np.linalg.norm(res.forces.R[:, p.index], axis=-1)
        h, = ax.plot(*_closed(res.phi_deg, mag), color="black", lw=2.4)
        handles["kinetostat"] = h
        for n, (route, er) in enumerate(run.results.items()):
            col, ls = _style(route, n)
            h, = ax.plot(*_closed(er.phi_deg, np.linalg.norm(er.R[:, p.index], axis=-1)), **_line(er, res, col, ls, 1.5))
            handles[f"{route} ({er.route})"] = h
        ax.set_title(_wrap(f"{pair_name(m, p)}: {_link_name(m, p.links[0])} on {_link_name(m, p.links[1])}"), fontsize=9, y=1.0)
        ax.set_ylim(bottom=0)
        _phi_axes(ax, label=n_ax + cols >= len(m.pairs), y=_nice(4), ylabel="|R|, N")
    _legend(fig, handles, ncols)
    return _save(fig, path)


def _error_curves(res: Analysis, er) -> dict[str, tuple[np.ndarray, np.ndarray, float]]:
    """quantity -> (phi, |engine - solver|, peak |solver|), as compare.errors measures them, at
    the route's angles (all of the solver's, or some of them)."""
    out = {}
    m = res.mech
    at = np.abs(np.asarray(er.phi_deg)[:, None] - res.phi_deg[None, :]).argmin(axis=1)
    items = [("M_drive", res.balancing_moment[:, None], er.M_drive[:, None])]
    items += [(f"R({p.links[0]},{p.links[1]})", res.forces.R[:, p.index], er.R[:, p.index]) for p in m.pairs]
    for name, ref, got in items:
        if er.magnitudes_only:
            ref = np.linalg.norm(ref, axis=-1, keepdims=True)
            got = np.linalg.norm(got, axis=-1, keepdims=True)
        err = np.linalg.norm(got - ref[at], axis=-1)
        peak = float(np.nanmax(np.linalg.norm(ref, axis=-1))) if np.any(np.isfinite(ref)) else 0.0
        out[name] = (er.phi_deg, err, peak)
    return out


def plot_errors(run: ModelRun, path: Path) -> Path:
    from matplotlib.ticker import FixedLocator
    res, m = run.res, run.mech
    qs = [q for q in quantities(m) if q == "M_drive" or q.startswith("R(")]   # the force quantities
    ncols = _legend_cols(2 * len(run.results), 4)
    fig, axes, cols = _panels(len(qs), f"{m.name}\nerror of each engine route against kinetostat (log scale; "
                                       f"dashed: the route's tolerance × the cycle's peak)", 2 * len(run.results), ncols)
    curves = {route: _error_curves(res, er) for route, er in run.results.items()}
    handles = {}
    for n_ax, (ax, q) in enumerate(zip(axes, qs)):
        unit = "N·m" if q == "M_drive" else "N"
        any_drawn = False
        ax.set_yscale("log")
        for n, route in enumerate(run.results):
            col, ls = _style(route, n)
            phi, err, peak = curves[route][q]
            e = np.where(err > 0, err, np.nan)
            if np.any(np.isfinite(e)):
                h, = ax.plot(*_closed(phi, e), **_line(run.results[route], res, col, "-", 1.3))
                handles[f"{route}: |engine − kinetostat|"] = h
                any_drawn = True
            tol = run.tolerances.get(route)
            if tol is not None and peak > 0:
                handles[f"{route}: tolerance × peak"] = _hline(ax, tol.peak_relative * peak, color=col, ls="--", lw=1)
        if not any_drawn:
            ax.text(0.5, 0.5, "no differences to draw\n(no engine results, or exactly equal)",
                    transform=ax.transAxes, ha="center", va="center", fontsize=8, color="0.4")
        title = f"{quantity_name(m, q)}: balancing moment" if q == "M_drive" else \
            pair_name(m, m.pair_between(*map(int, q[2:-1].split(","))))
        ax.set_title(_wrap(title), fontsize=9, y=1.0)
        _phi_axes(ax, label=n_ax + cols >= len(qs), ylabel=f"|error|, {unit}",
                  y=None if ax.get_lines() else FixedLocator([]))     # nothing drawn: no scale to read
    _legend(fig, handles, ncols)
    return _save(fig, path)


def _offset(ax, x_pt: float, y_pt: float):
    """ax's data coordinates shifted by x_pt, y_pt points (a label beside a point)."""
    from matplotlib.transforms import offset_copy
    return offset_copy(ax.transData, ax.figure, x_pt, y_pt, units="points")


def _arrows(ax, tips: np.ndarray, color: str, lw: float, head_pt: tuple[float, float] = (4.0, 2.0)) -> None:
    """Arrows from the origin to each of `tips` (data, n x 2) as `annotate`'s "-|>" draws them
    (a filled head `head_pt` long and half wide, points), as one line of shafts and one collection of
    heads instead of an artist each. After ax's limits are fixed (`_axes`): the heads are shaped
    in points."""
    from matplotlib.collections import PolyCollection
    if not len(tips):
        return
    (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
    k = np.array([ax.bbox.width / (x1 - x0), ax.bbox.height / (y1 - y0)]) * 72 / ax.figure.dpi   # pt per unit
    v = tips * k
    u = v / np.linalg.norm(v, axis=-1, keepdims=True)
    n = u @ np.array([[0.0, 1.0], [-1.0, 0.0]])
    base = v - head_pt[0] * u
    heads = np.stack([v, base + head_pt[1] * n, base - head_pt[1] * n], axis=1) / k
    shafts = np.concatenate([np.zeros_like(base)[:, None], (base / k)[:, None], np.full_like(base, np.nan)[:, None]], 1)
    ax.plot(*shafts.reshape(-1, 2).T, color=color, lw=lw, zorder=3)
    ax.add_collection(PolyCollection(heads, facecolors=color, edgecolors=color, linewidths=lw, zorder=3), autolim=False)


def plot_hodographs(run: ModelRun, path: Path) -> Path:
    """Tip of each revolute pair's reaction vector over the cycle (as Potapov 2024 draws them, figs. 13-14)."""
    res, m = run.res, run.mech
    pairs = [p for p in m.pairs if p.kind == "R"]
    n_legend = 1 + sum(not er.magnitudes_only for er in run.results.values())
    ncols = _legend_cols(n_legend, 4)
    fig, axes, cols = _panels(len(pairs), f"{m.name}\nhodographs of the revolute pairs' reactions (tip of the force "
                                          f"vector over the cycle, world frame; grey rays every 30° of φ)",
                              n_legend, ncols, cell_h=3.6)
    phi = res.phi_deg
    handles = {}
    for ax, p in zip(axes, pairs):
        R = res.forces.R[:, p.index]
        _, Rx, Ry = _closed(phi, R[:, 0], R[:, 1])
        h, = ax.plot(Rx, Ry, color="black", lw=2)
        handles["kinetostat"] = h
        for n, (route, er) in enumerate(run.results.items()):
            if er.magnitudes_only:
                continue
            col, ls = _style(route, n)
            E = er.R[:, p.index]
            h, = ax.plot(*_closed(er.phi_deg, E[:, 0], E[:, 1])[1:], **_line(er, res, col, ls, 1.3))
            handles[f"{route} ({er.route})"] = h
        ax.plot(0, 0, marker="+", ms=12, color="black")
        mag = np.linalg.norm(R, axis=-1)
        fin = np.isfinite(mag)
        if fin.any():
            i = int(np.nanargmax(mag))
            ax.plot(*R[i], marker="o", ms=6, color="tab:red", ls="none")
            ax.text(*R[i], f"max {mag[i]:.4g} N\nat {phi[i]:.4g}°", transform=_offset(ax, 6, -14), fontsize=7,
                    color="tab:red")
        ax.set_aspect("equal", adjustable="datalim")
        _axes(ax, _nice(4), _nice(5), "R_x, N", "R_y, N")     # 4 on x: room for "−4000" on a narrow panel
        # rays at every 30 deg of the cycle, labelled with the angle
        rays = []
        for a in range(0, 360, 30):
            i = int(np.argmin(np.abs(((phi - a) + 180) % 360 - 180)))
            if abs(((phi[i] - a) + 180) % 360 - 180) > 2.5 or not fin[i] or mag[i] < 0.12 * np.nanmax(mag):
                continue      # short rays near the origin would only clutter the labels
            rays.append(R[i])
            ax.text(*R[i], f"{phi[i]:.0f}°", transform=_offset(ax, 3, 3), fontsize=7, color="0.25")
        _arrows(ax, np.reshape(rays, (-1, 2)), color="0.6", lw=0.7)
        ax.set_title(_wrap(f"{pair_name(m, p)}: {_link_name(m, p.links[0])} on {_link_name(m, p.links[1])}"), fontsize=9, y=1.0)
    _legend(fig, handles, ncols)
    return _save(fig, path)


def plot_balancing_force(res: Analysis, path: Path) -> Path:
    """Working machine: the balancing force of the pinion on the crank's wheel over the cycle,
    its magnitude and its world components (it acts along the fixed line of action)."""
    m = res.mech
    fig = _figure(9.5, 4.8, left=1.0, right=0.2, top=0.6, bottom=0.6)
    ax = fig.subplots()
    F = res.balancing_force
    phi = res.phi_deg
    ax.plot(*_closed(phi, np.linalg.norm(F, axis=-1)), color="black", lw=2.4, label=quantity_name(m, "|F_bal|"))
    ax.plot(*_closed(phi, F[:, 0]), color="tab:blue", lw=1.4, ls="--", label=quantity_name(m, "F_bal,x"))
    ax.plot(*_closed(phi, F[:, 1]), color="tab:orange", lw=1.4, ls=(0, (2, 2)), label=quantity_name(m, "F_bal,y"))
    _hline(ax, 0, color="0.3", lw=0.6)
    ax.set_title(f"{m.name}\nbalancing force of the pinion on the crank's wheel (pitch point, line of action)",
                 fontsize=10, y=1.0)
    ax.legend(fontsize=8, loc="best")
    _phi_axes(ax, step=30, ylabel="balancing force, N")
    return _save(fig, path)


def plot_tornado(mech: Mechanism, labels: list[str], values: list[float], path: Path) -> Path:
    """A tornado chart of the elasticities `values` (1, signed) named `labels`, the largest |value|
    on top: bars to the right (red) where the quantity grows with the parameter, to the left (blue)
    where it falls."""
    fig = _figure(9.5, 0.9 + 0.34 * len(values), left=3.0, right=0.3, top=0.6, bottom=0.55)
    ax = fig.subplots()
    y = np.arange(len(values))[::-1]
    ax.barh(y, values, height=0.6, color=["tab:red" if v > 0 else "tab:blue" for v in values])
    from matplotlib.transforms import offset_copy
    beside = offset_copy(ax.get_yaxis_transform(), fig, x=-_PAD_PT, units="points")
    for yy, label in zip(y, labels):
        ax.text(0, yy, label, transform=beside, ha="right", va="center", fontsize=9)
    reach = max((abs(v) for v in values), default=1.0) or 1.0
    ax.set_xlim(-1.1 * reach, 1.1 * reach)
    ax.set_ylim(-0.6, len(values) - 0.4)
    ax.axvline(0, color="0.3", lw=0.8)
    ax.set_title(f"{mech.name}\nelasticity of the peak reaction: (p / peak) · d peak / d p", fontsize=10, y=1.0)
    from matplotlib.ticker import FixedLocator
    _axes(ax, _nice(6), FixedLocator([]), "elasticity, 1")
    return _save(fig, path)
