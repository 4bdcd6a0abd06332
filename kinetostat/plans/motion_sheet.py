"""The sheet of the machine's law of motion (issue 38): one A3 landscape sheet of diagrams against
the crank angle φ, each at round scales it states (seed 000, the dynamic analysis of the machine):
the reduced moments M_red and M_drive; the work of the loads and of the drive; ΔT; J_red;
Wittenbauer's energy-mass curve ΔT(J_red) with its two tangents at ω_max²/2 and ω_min²/2 and the
segment ab they cut on the ΔT axis (J_flywheel = ab·μ_ΔT / (ω_m² δ)); ω(φ) with ω_max, ω_min and
ω_m marked. The ΔT diagram and the energy-mass curve share μ_ΔT, J_red(φ) and the curve share μ_J.

The sheet is laid out once as an `a3.Page` (lines, polylines, dots, texts in mm from the top
left) and written by both renderers: `MotionSheet.svg` and `MotionSheet.pdf` (`a3.draw_page`);
the title block is GOST 2.104's (`a3._title_block`). Line weights by role (`draw.WEIGHT_MM`): the
curves found are results, M_drive a given, the axes components, the tangents and the levels of
ω constructions. No text under `labels.MIN_TEXT_MM` (capitals 2.5 mm); every curve's name placed by
`labels.Placer` clear of every text and dot; symbols with true sub- and superscripts (`symbols`).

May use: the standard library, numpy, `.a3`, `.draw`, `.i18n`, `.labels`, `.pdf`, `.scales`,
`.symbols`, `kinetostat._text`, `kinetostat.model.lettering` (the mechanism's name). Never matplotlib, never the harness: the Motion is passed in.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .._text import xml_escape
from .a3 import Page, _title_block, draw_page
from .draw import SHEET_MM, WEIGHT_MM
from .i18n import MESSAGES, num, text, unit
from .labels import MIN_TEXT_MM, Placer, markup
from .pdf import Canvas, text_width
from .scales import coarser, next_coarser
from .symbols import text_runs
from ..model.lettering import lettering

__all__ = ["Panel", "MotionSheet", "motion_sheet", "work_parts", "no_drive", "NO_WORK"]

#: The loads' work over a cycle below this share of 2 pi max |M_red|: no work, no drive to balance.
NO_WORK = 1e-9

_FRAME = (20.0, 5.0, 415.0, 292.0)
_TB = (230.0, 237.0, 415.0, 292.0)                 # the title block (a3.TITLE_BLOCK)
_COLS = (22.0, 153.0, 284.0, 413.0)                # the panels' cells, mm
_ROWS = (14.0, 124.0, 234.0)
_SIZE = MIN_TEXT_MM                                # every text: capitals 2.5 mm
_HEAD = 4.0                                        # a panel's heading, mm
_STEP = 5.1                                        # line spacing of the notes, mm
_INSET = (19.0, 17.0, 9.0, 8.0)                    # plot inside its cell: left (ticks), top (heading, scales), right, bottom
_TICK_MM = 12.0                                    # at least this between two value ticks, mm


@dataclass(frozen=True)
class Panel:
    """One diagram: its key, plot box (x0, y0, x1, y1) mm, the values at the box's left and top
    (`x_from`, `y_top`) and its scales (units per mm): value x is drawn at box[0] + (x - x_from) / mu_x,
    value y at box[1] + (y_top - y) / mu_y."""
    key: str
    box: tuple[float, float, float, float]
    x_from: float
    y_top: float
    mu_x: float
    mu_y: float

    def X(self, x):
        return self.box[0] + (np.asarray(x, dtype=float) - self.x_from) / self.mu_x

    def Y(self, y):
        return self.box[1] + (self.y_top - np.asarray(y, dtype=float)) / self.mu_y


@dataclass(frozen=True)
class MotionSheet:
    """The sheet in `lang`: its page of primitives, its panels by key, its title."""
    page: Page
    panels: dict
    lang: str
    title: str

    def svg(self) -> str:
        """The sheet as SVG, 1 unit = 1 mm; each line of a construction with its data-gid, each
        panel's scales as data attributes."""
        w, h = SHEET_MM
        out = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{w:g}mm" height="{h:g}mm" viewBox="0 0 {w:g} {h:g}" '
               f'font-family="DejaVu Sans, sans-serif">', f'<title>{xml_escape(self.title)}</title>',
               f'<rect width="{w:g}" height="{h:g}" fill="#fff"/>']
        for p in self.panels.values():
            out.append(f'<g class="panel" data-key="{p.key}" data-mu-x="{p.mu_x!r}" data-mu-y="{p.mu_y!r}" '
                       f'data-box="{" ".join(f"{v:.4f}" for v in p.box)}" data-x-from="{p.x_from!r}" data-y-top="{p.y_top!r}"/>')
        for pts, width, colour in self.page.polylines:
            out.append(f'<polyline fill="none" stroke="{colour}" stroke-width="{width}" stroke-linejoin="round" '
                       f'points="{" ".join(f"{x:.3f},{y:.3f}" for x, y in pts)}"/>')
        for x0, y0, x1, y1, width, dash, colour, gid in self.page.lines:
            d = f' stroke-dasharray="{" ".join(f"{v:g}" for v in dash)}"' if dash else ""
            g = f' data-gid="{xml_escape(gid)}"' if gid else ""
            out.append(f'<line x1="{x0:.6f}" y1="{y0:.6f}" x2="{x1:.6f}" y2="{y1:.6f}" stroke="{colour}" '
                       f'stroke-width="{width}"{d}{g}/>')
        for x, y, r in self.page.dots:
            out.append(f'<circle cx="{x:.3f}" cy="{y:.3f}" r="{r}"/>')
        for x, y, s, size, weight in self.page.texts:
            bold = ' font-weight="bold"' if weight == "bold" else ""
            out.append(f'<text x="{x:.3f}" y="{y:.3f}" font-size="{size:g}"{bold}>{markup(text_runs(s), size)}</text>')
        return "\n".join(out + ["</svg>"]) + "\n"

    def pdf(self) -> bytes:
        """The sheet as a one-page A3 PDF (`a3.draw_page`)."""
        c = Canvas(self.title)
        draw_page(c, self.page)
        return c.getvalue()


def work_parts(motion) -> tuple[np.ndarray, np.ndarray]:
    """The work of the drive and of the loads from phi_deg[0] to each angle and on to the cycle's
    end (N + 1,), J: the trapezoid rule over the closed cycle of M_drive and M_red."""
    phi = np.radians(np.append(motion.phi_deg, motion.phi_deg[0] + 360.0))

    def integral(m):
        m = np.append(m, m[0])
        return np.concatenate([[0.0], np.cumsum(0.5 * (m[1:] + m[:-1]) * np.diff(phi))])
    return integral(np.asarray(motion.M_drive, float)), integral(np.asarray(motion.M_red, float))


def no_drive(M_red) -> str:
    """Why a machine whose loads' reduced moment over a uniform full cycle is `M_red` (N m) has no
    drive to balance ("" where it has one): their work over the cycle (2 pi mean M_red) is 0 to
    NO_WORK of 2 pi max |M_red| (gravity and conservative loads only)."""
    M_red = np.asarray(M_red, dtype=float)
    work = float(np.mean(M_red)) * 2 * math.pi
    if abs(work) <= NO_WORK * 2 * math.pi * float(np.max(np.abs(M_red), initial=0.0)):
        return (f"the loads' work over a cycle is {work:.3g} J (gravity and conservative loads only): there is no "
                "drive to balance")
    return ""


def _closed(a) -> np.ndarray:
    """A periodic quantity over the cycle with its value at phi_deg[0] + 360 (= the first) appended."""
    a = np.asarray(a, dtype=float)
    return np.append(a, a[0])


def _range(lo: float, hi: float, height: float, mu: float = 0.0, gap: float = _TICK_MM) -> tuple[float, float, float, float]:
    """(mu, first tick, tick step, last tick): the finest round scale (units/mm), not finer than
    `mu`, at which the ticks' span round lo .. hi fits `height` mm, its ticks at least `gap` mm apart."""
    span = max(hi - lo, abs(hi) * 1e-6, 1e-12)
    mu = max(mu, coarser(span / height, 1.0))
    while True:
        step = coarser(mu * gap, 1.0)
        a, b = math.floor(lo / step + 1e-9) * step, math.ceil(hi / step - 1e-9) * step
        if (b - a) / mu <= height + 1e-9:
            return mu, a, step, b
        mu = next_coarser(mu)


class _Layout:
    """The page's primitives being laid out, and the placer of the curves' names."""

    def __init__(self, lang: str):
        self.lang = lang
        self.lines, self.polylines, self.dots, self.texts = [], [], [], []
        self.names: list[tuple[str, tuple[float, float]]] = []          # (name, anchor) to place last

    def text(self, x: float, y: float, s: str, size: float = _SIZE, weight: str = "normal", right: bool = False):
        if right:
            x -= text_width(s, size, weight == "bold")
        self.texts.append((x, y, s, size, weight))

    def line(self, x0, y0, x1, y1, role: str, dash=(), gid: str = ""):
        self.lines.append((float(x0), float(y0), float(x1), float(y1), WEIGHT_MM[role], tuple(dash), "#000", gid))


def _panel(L: _Layout, key: str, cell: tuple[float, float, float, float], heading: str, x_name: str, y_name: str,
           x: tuple[float, float, float], y: tuple[float, float, float], scales: str, x_axis_at: float | None = 0.0):
    """A panel in `cell`: heading, scales line, the axes with their ticks and names. `x`, `y`: (mu,
    first tick, step) of each axis (`_range`); the x axis drawn at value `x_axis_at` where it lies
    inside the y range, else at the bottom."""
    x0 = cell[0] + _INSET[0]
    y0 = cell[1] + _INSET[1]
    mu_x, xa, xs, xb = x
    mu_y, ya, ys, yb = y
    x_ticks = [xa + k * xs for k in range(round((xb - xa) / xs) + 1)]
    y_ticks = [ya + k * ys for k in range(round((yb - ya) / ys) + 1)]
    p = Panel(key, (x0, y0, x0 + (xb - xa) / mu_x, y0 + (yb - ya) / mu_y), xa, yb, mu_x, mu_y)
    L.text(cell[0] + 2.0, cell[1] + 5.0, heading, _HEAD, "bold")
    L.text(cell[0] + 2.0, cell[1] + 5.0 + _STEP, scales)
    at = x_axis_at if x_axis_at is not None and ya - 1e-12 <= x_axis_at <= yb + 1e-12 else ya
    ax_y = float(p.Y(at))
    L.line(p.box[0], ax_y, p.box[2] + 4.0, ax_y, "component", gid=f"{key}/x_axis")
    L.line(p.box[0], p.box[3], p.box[0], p.box[1] - 3.0, "component", gid=f"{key}/y_axis")
    for v in x_ticks:
        X = float(p.X(v))
        L.line(X, ax_y, X, ax_y + 1.2, "construction")
        s = num(v, L.lang, 6)
        L.text(X - text_width(s, _SIZE) / 2, p.box[3] + 1.5 + _SIZE if at == ya else ax_y + 1.5 + _SIZE, s)
    for v in y_ticks:
        Y = float(p.Y(v))
        L.line(p.box[0] - 1.2, Y, p.box[0], Y, "construction")
        L.text(p.box[0] - 2.0, Y + 0.36 * _SIZE, num(v, L.lang, 6), right=True)
    L.names.append((x_name, (p.box[2] + 4.0, ax_y)))          # placed clear of the curves (`_place_names`)
    L.text(p.box[0] + 1.5, p.box[1] - 1.0, y_name)
    return p


def _curve(L: _Layout, p: Panel, xs, ys, role: str, name: str = "", where: float = 0.7):
    """A curve of the panel (a polyline at `role`'s weight), its name (where the panel has more
    than one) anchored at the fraction `where` of its points."""
    X, Y = p.X(xs), p.Y(ys)
    pts = tuple((float(a), float(b)) for a, b in zip(X, Y))
    L.polylines.append((pts, WEIGHT_MM[role], "#000"))
    if name:
        L.names.append((name, pts[min(int(where * (len(pts) - 1)), len(pts) - 1)]))


def _clip(p: Panel, k: float, b: float) -> tuple[float, float, float, float] | None:
    """The line y = k x + b (values) inside the panel's box, mm (Liang-Barsky), or None."""
    x_lo, x_hi = p.x_from, p.x_from + (p.box[2] - p.box[0]) * p.mu_x
    y_lo, y_hi = p.y_top - (p.box[3] - p.box[1]) * p.mu_y, p.y_top
    t0, t1 = x_lo, x_hi
    if abs(k) > 0:
        a, c = sorted(((y_lo - b) / k, (y_hi - b) / k))
        t0, t1 = max(t0, a), min(t1, c)
    elif not y_lo <= b <= y_hi:
        return None
    if t0 >= t1:
        return None
    return float(p.X(t0)), float(p.Y(k * t0 + b)), float(p.X(t1)), float(p.Y(k * t1 + b))


def _symbols(lang: str, kind: str) -> dict[str, str]:
    """The sheet's symbols in `lang` (the texts' letters: зв/пр reduced; the drive's moment an
    engine's consumer (сп/потр) or a working machine's motor (р/дв) by the drive's `kind`)."""
    out = {k: text(f"motion.sym_{k}", lang) for k in ("M_red", "A_red", "J_red", "J_fly")}
    drive = text(f"motion.sym_drive_{'engine' if kind == 'engine' else 'machine'}", lang)
    return out | {"M_drive": f"M_{drive}", "A_drive": f"A_{drive}"}


def _mu(sym: str, value: float, u: str, lang: str) -> str:
    return f"μ_{sym} = {num(value, lang, 6)} {u}/{unit('mm', lang)}"


def motion_sheet(motion, lang: str = "en") -> MotionSheet:
    """The sheet of `motion` (`kinetostat.Motion`) in `lang`, the mechanism's name (`lettering`) in
    its title block."""
    mech = motion.mech
    name = lettering(mech).name(lang, mech.name)
    S = _symbols(lang, motion.mech.drive.kind)
    L = _Layout(lang)
    panels = {}
    phi = np.append(motion.phi_deg, motion.phi_deg[0] + 360.0)
    A_drive, A_red = work_parts(motion)
    dT = np.append(motion.work, motion.work[0])
    om = _closed(motion.omega)
    J = _closed(motion.J_red)
    u = {k: unit(k, lang) for k in ("deg", "N m", "J", "kg m^2", "rad/s")}
    cells = [(_COLS[c], _ROWS[r], _COLS[c + 1], _ROWS[r + 1]) for r in range(2) for c in range(3)]
    wid = cells[0][2] - cells[0][0] - _INSET[0] - _INSET[2]
    hei = cells[0][3] - cells[0][1] - _INSET[1] - _INSET[3]
    f0 = float(motion.phi_deg[0])
    xphi = (coarser(360.0 / wid, 1.0), f0, 60.0, f0 + 360.0)
    phi_name = f"φ, {u['deg']}"

    def rng(*arrays, zero: bool = True):
        lo = min(float(np.min(a)) for a in arrays)
        hi = max(float(np.max(a)) for a in arrays)
        if zero:
            lo, hi = min(lo, 0.0), max(hi, 0.0)
        return _range(lo, hi, hei - 2.0)

    M_drive = _closed(motion.M_drive)
    M_red = _closed(motion.M_red)
    y = rng(M_red, M_drive)
    p = panels["moments"] = _panel(L, "moments", cells[0], text("motion.h_moments", lang), phi_name, f"M, {u['N m']}",
                                   xphi, y, f"{_mu('φ', xphi[0], u['deg'], lang)}, {_mu('M', y[0], u['N m'], lang)}")
    _curve(L, p, phi, M_red, "result", S["M_red"], 0.35)
    _curve(L, p, phi, M_drive, "given", S["M_drive"], 0.85)

    y = rng(A_drive, A_red)
    p = panels["work"] = _panel(L, "work", cells[1], text("motion.h_work", lang), phi_name, f"A, {u['J']}",
                                xphi, y, f"{_mu('φ', xphi[0], u['deg'], lang)}, {_mu('A', y[0], u['J'], lang)}")
    _curve(L, p, phi, A_drive, "given", S["A_drive"], 0.75)
    _curve(L, p, phi, A_red, "result", S["A_red"], 0.6)

    lo, hi = float(om.min()), float(om.max())
    pad = max(hi - lo, 1e-9 * hi) * 0.25
    y = _range(lo - pad, hi + pad, hei - 2.0)
    p = panels["omega"] = _panel(L, "omega", cells[2], text("motion.h_omega", lang), phi_name, f"ω, {u['rad/s']}",
                                 xphi, y, f"{_mu('φ', xphi[0], u['deg'], lang)}, {_mu('ω', y[0], u['rad/s'], lang)}",
                                 x_axis_at=None)
    _curve(L, p, phi, om, "result")
    levels = (("max", hi, (2.0, 1.0)), ("min", lo, (2.0, 1.0)), ("m", float(motion.omega_mean), (6.0, 1.0, 1.0, 1.0)))
    for sub, v, dash in levels:
        Yv = float(p.Y(v))
        L.line(p.box[0], Yv, p.box[2], Yv, "construction", dash, gid=f"omega/{sub}")
        L.names.append((f"ω_{sub}", (p.box[2], Yv)))

    # J_red(φ) and the energy panels: ΔT(φ) beside the energy-mass curve at one μ_ΔT, J_red at one μ_J
    (k_max, b_max), (k_min, b_min) = motion.wittenbauer
    yT = rng(dT, [b_max, b_min])
    muJ = 0.0
    while True:                       # one μ_J for J_red(φ) (J up) and the curve (J across)
        xJ = _range(0.0, float(J.max()), wid - 4.0, muJ, 1.5 * _TICK_MM)
        yJ = _range(0.0, float(J.max()), hei - 2.0, xJ[0])
        if yJ[0] == xJ[0]:
            break
        muJ = yJ[0]
    muJ = xJ[0]
    p = panels["inertia"] = _panel(L, "inertia", cells[3], text("motion.h_inertia", lang), phi_name,
                                   f"{S['J_red']}, {u['kg m^2']}", xphi, yJ,
                                   f"{_mu('φ', xphi[0], u['deg'], lang)}, {_mu('J', muJ, u['kg m^2'], lang)}")
    _curve(L, p, phi, J, "result")

    p = panels["energy"] = _panel(L, "energy", cells[4], text("motion.h_energy", lang), phi_name, f"ΔT, {u['J']}",
                                  xphi, yT, f"{_mu('φ', xphi[0], u['deg'], lang)}, {_mu('ΔT', yT[0], u['J'], lang)}")
    _curve(L, p, phi, dT, "result")

    p = panels["wittenbauer"] = _panel(L, "wittenbauer", cells[5], text("motion.h_wittenbauer", lang),
                                       f"{S['J_red']}, {u['kg m^2']}", f"ΔT, {u['J']}", xJ, yT,
                                       f"{_mu('J', muJ, u['kg m^2'], lang)}, {_mu('ΔT', yT[0], u['J'], lang)}")
    _curve(L, p, J, dT, "result")
    for sub, k, b in (("max", k_max, b_max), ("min", k_min, b_min)):
        seg = _clip(p, k, b)
        if seg is not None:
            L.line(*seg, "construction", gid=f"wittenbauer/tangent_{sub}")
    ya, yb = float(p.Y(b_max)), float(p.Y(b_min))
    L.line(p.box[0], ya, p.box[0], yb, "result", gid="wittenbauer/ab")
    L.dots += [(p.box[0], ya, 0.6), (p.box[0], yb, 0.6)]
    L.text(p.box[0] + 1.5, ya - 1.0, "a")
    L.text(p.box[0] + 1.5, yb + 1.0 + _SIZE * 0.73, "b")
    ab_mm = abs(yb - ya)

    _notes(L, motion, S, ab_mm, panels["wittenbauer"].mu_y)
    title = text("motion.title", lang)
    L.polylines.append((((_FRAME[0], _FRAME[1]), (_FRAME[2], _FRAME[1]), (_FRAME[2], _FRAME[3]), (_FRAME[0], _FRAME[3]),
                         (_FRAME[0], _FRAME[1])), WEIGHT_MM["result"], "#000"))
    lines: list = []
    texts: list = []
    _title_block(lines, texts, {"designation": title, "name": name, "scale_value": "—",
                                "sheet": "1", "sheets": "1"}, lang)
    L.lines += lines
    L.texts += texts
    _place_names(L)
    page = Page(tuple(L.lines), tuple(L.polylines), (), tuple(L.dots), tuple(L.texts))
    return MotionSheet(page, panels, lang, f"{title}: {name}")


def _notes(L: _Layout, motion, S: dict, ab_mm: float, mu_T: float) -> None:
    """The results below the panels, left of the title block."""
    lang = L.lang
    J_fly = motion.J_flywheel
    rows = [text("motion.n_speed", lang, omega=num(motion.omega_mean, lang, 6), unit=unit("rad/s", lang),
                 delta=num(motion.delta, lang, 4))
            + ("" if motion.delta_target is None else text("motion.n_target", lang, delta=num(motion.delta_target, lang, 4))),
            text("motion.n_flywheel", lang, J=S["J_fly"], value=num(J_fly, lang, 6), unit=unit("kg m^2", lang),
                 M=S["M_drive"], M_value=num(float(np.mean(motion.M_drive)), lang, 6), M_unit=unit("N m", lang))]
    if motion.delta > 0:
        rows.append(text("motion.n_ab", lang, ab=num(ab_mm, lang, decimals=1), mm=unit("mm", lang), J=S["J_fly"],
                         value=num(ab_mm * mu_T / (motion.omega_mean ** 2 * motion.delta), lang, 6),
                         unit=unit("kg m^2", lang)))
    for method, value in motion.approximate.items():
        diff = (value - J_fly) / J_fly * 100.0 if J_fly > 0 else math.nan
        rows.append(text("motion.n_approx", lang, method=text(f"motion.m_{method}", lang) if f"motion.m_{method}" in MESSAGES else method,
                         J=S["J_fly"], value=num(value, lang, 6), unit=unit("kg m^2", lang),
                         diff=num(round(diff, 2) + 0.0, lang, decimals=2)))
    y = _TB[1] + 5.0
    for s in rows:
        L.text(_FRAME[0] + 4.0, y, s)
        y += _STEP


def _place_names(L: _Layout) -> None:
    """Each curve's name beside its anchor, clear of every text, dot and other name (`Placer`)."""
    placer = Placer(1, (_FRAME[0] + 1, _FRAME[1] + 1, _FRAME[2] - 1, _FRAME[3] - 1))
    placer.block(np.array(_TB))
    for x, y, s, size, weight in L.texts:
        w = text_width(s, size, weight == "bold")
        placer.block(np.array([x, y - 0.76 * size, x + w, y + 0.24 * size]))
    for x, y, r in L.dots:
        placer.block(np.array([x - r, y - r, x + r, y + r]))
    segs = [(a, b, c, d) for a, b, c, d, *_ in L.lines]
    segs += [(*u, *v) for pts, *_ in L.polylines for u, v in zip(pts[::4], pts[4::4])]
    placer.line(np.array(segs)[None])
    for name, (x, y) in L.names:
        pl = placer.place((name,), np.zeros(1, dtype=int), _SIZE, np.array([[x, y]]))
        if np.isfinite(pl.xy).all():
            L.texts.append((float(pl.xy[0, 0]), float(pl.xy[0, 1]), name, _SIZE, "normal"))
            if np.isfinite(pl.leader).all():
                a, b, c, d = pl.leader[0]
                L.line(a, b, c, d, "auxiliary")

