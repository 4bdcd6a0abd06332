"""The worksheet of the graphical-analytic method (issue 12, item 3): every intermediate value the
texts write down at one crank position, in their order (seed 002 sec. 1.2.2-1.2.3, seed 000
secs. 4, 6-8), with units and senses, taken from the exact solution (`analyze`). Built for the N
angles of one analysis at once (`worksheet_cycle`: each row's value an (N,) array; `at(i)` the
`Worksheet` of angle i); `worksheet(mech, at)` is its case of one angle.

Order: the initial link and each Assur group in the order of attachment (velocities, then
accelerations), the inertia loads and the applied loads, the reactions group by group from the
last group attached back to the crank, the crank, Zhukovsky's lever and the difference of the two
balancing moments. Outputs: Markdown, HTML, a pandas frame, CSV and JSON (written atomically).

May use: the solver's results (`analysis`, `applied`, `model`; analysed in `.solution`), `_io`, `_text` (safe cells), numpy; pandas inside
`Worksheet.frame` only. Never matplotlib, never the harness.
"""
from __future__ import annotations

import json
import re
import warnings
import math
from dataclasses import dataclass
from itertools import groupby
from pathlib import Path

import numpy as np

from ..analysis import Analysis
from ..applied import load_magnitude
from ..errors import SelfLockingWarning
from ..kinematics import DIGITS_WARN, leash_axes, special_point_z, special_index
from .._io import write_text
from .._text import csv_cell, html_text, markdown_text
from ..model import Mechanism
from ..tables import by_unit, plain, rows_csv
from .i18n import ZERO, accuracy, check_lang, num, phrase, text, unit
from ..model.lettering import in_lang, lettering
from .scales import solution_scales
from .solution import Solution, solve
from .symbols import html, mark

__all__ = ["Row", "Worksheet", "worksheet", "CycleRow", "WorksheetCycle", "worksheet_cycle", "COLUMNS", "CSS", "html_document"]

#: Columns of the worksheet's table (CSV, JSON, frame).
COLUMNS = ("section", "key", "symbol", "value", "unit", "direction", "note")

@dataclass(frozen=True)
class Row:
    """One written-down value: `key` a stable ASCII name (e.g. `V_BA`, `omega_2`, `R_1_2`),
    `symbol` as the texts write it, `value` in SI (`unit`; mm for arms and z), `direction` the
    sense of a rotation ("cw"/"ccw") or the angle of a vector from +x in degrees (as text),
    `note` the formula or the plan it is read from."""
    section: str
    key: str
    symbol: str
    value: float
    unit: str
    direction: str = ""
    note: str = ""


@dataclass(frozen=True)
class Worksheet:
    """The worksheet of `mech` at crank angle `phi_deg` (rows in the texts' order)."""
    mechanism: str
    phi_deg: float
    mu_l: float
    rows: tuple[Row, ...]
    lang: str = "en"
    digits: float = 16.0    # estimated significant digits left at this angle (fewer than DIGITS_WARN: stated)

    def __repr__(self) -> str:
        return f"Worksheet({self.mechanism!r}, phi_deg={self.phi_deg:g}, mu_l={self.mu_l:g}, rows={len(self.rows)})"

    def row(self, key: str) -> Row:
        for r in self.rows:
            if r.key == key:
                return r
        raise KeyError(f"worksheet: no value {key!r}; keys: {', '.join(r.key for r in self.rows)}")

    def value(self, key: str) -> float:
        """The value of row `key`, SI (mm for arms)."""
        return self.row(key).value

    def section(self, name: str) -> tuple[Row, ...]:
        return tuple(r for r in self.rows if r.section == name)

    # -- outputs
    def records(self) -> list[dict]:
        """The rows in the worksheet's language: sections, units, senses and notes translated
        (`i18n`), symbols as its texts write them (`lettering.in_lang`); values stay numbers."""
        lang = self.lang
        return [{"section": text(f"ws.{r.section}", lang), "key": r.key, "symbol": in_lang(r.symbol, lang), "value": r.value,
                 "unit": unit(r.unit, lang), "direction": _direction(r.direction, lang),
                 "note": in_lang(phrase(r.note, lang), lang)} for r in self.rows]

    def frame(self):
        """The rows as a pandas DataFrame (columns COLUMNS)."""
        import pandas as pd
        df = pd.DataFrame(self.records(), columns=list(COLUMNS))
        df.attrs.update(mechanism=self.mechanism, phi_deg=self.phi_deg, mu_l=self.mu_l)
        return df

    def _body(self) -> tuple[str, list[str], list[tuple[str, list[tuple[str, ...]]]]]:
        """What the Markdown and the HTML show under the title, in the worksheet's language: the
        scale line, the tables' header, and one table per run of rows of one section: (section,
        its rows' cells: symbol, value as the language writes it, unit, direction, note)."""
        lang = self.lang
        scale = f"{text('scale', lang)} μ_l = {num(self.mu_l, lang, 6)} {unit('m/mm', lang)}"
        head = [text(f"ws.head.{c}", lang) for c in ("symbol", "value", "unit", "direction", "note")]
        tables = [(section, [tuple(str(c) for c in (r["symbol"], num(r["value"], lang, 6), r["unit"], r["direction"],
                                                    r["note"])) for r in recs])
                  for section, recs in groupby(self.records(), key=lambda r: r["section"])]
        return scale, head, tables

    def markdown(self) -> str:
        """The worksheet as Markdown: a title, then one table per section (numbers as the
        worksheet's language writes them); near a singular position, the digits left."""
        lang = self.lang
        scale, head, tables = self._body()
        out = [f"# {text('ws.title', lang, name=markdown_text(self.mechanism), phi=num(self.phi_deg, lang, 6))}", "",
               scale]
        if self.digits < DIGITS_WARN:
            out += ["", accuracy(self.digits, DIGITS_WARN, lang)]
        for section, rows in tables:
            out += ["", f"## {section}", "", "| " + " | ".join(head) + " |", "|---|---:|---|---|---|"]
            out += ["| " + " | ".join(map(markdown_text, cells)) + " |" for cells in rows]
        return "\n".join(out) + "\n"

    def html(self) -> str:
        """A standalone HTML page (`html_document`): the Markdown as a CommonMark renderer with
        tables writes it (every text escaped, `_text.html_text`), written here directly, but for
        the symbols of its cells: their scripts in <sub> and <sup> (`_html_cell`)."""
        lang = self.lang
        title = text("ws.title", lang, name=self.mechanism, phi=num(self.phi_deg, lang, 6))
        scale, head, tables = self._body()
        out = [f"<h1>{html_text(title)}</h1>", f"<p>{html(html_text(scale), escaped=True)}</p>"]
        if self.digits < DIGITS_WARN:        # the Markdown's bold lead: "**Accuracy:** ..."
            lead, _, line = accuracy(self.digits, DIGITS_WARN, lang, markdown=False).partition(": ")
            out.append(f"<p><strong>{html_text(lead)}:</strong> {html_text(line)}</p>")
        align = ("", ' style="text-align:right"', "", "", "")          # the value column: right
        for section, rows in tables:
            out += [f"<h2>{html_text(section)}</h2>", "<table>", "<thead>", "<tr>",
                    *(f"<th{a}>{html_text(c)}</th>" for a, c in zip(align, head)), "</tr>", "</thead>", "<tbody>"]
            for cells in rows:
                out += ["<tr>", *(f"<td{a}>{_html_cell(c, k)}</td>" for k, (a, c) in enumerate(zip(align, cells))),
                        "</tr>"]
            out += ["</tbody>", "</table>"]
        return html_document(title, "\n".join(out) + "\n", lang)

    def to_csv(self, path: str | Path) -> None:
        """Write the rows as CSV, each value to 12 significant digits of the largest |value| of its
        unit (`kinetostat.tables.by_unit`), no cell read as a formula (atomic: a temporary file in the same folder, then replaced).
        Near a singular position the first row states the accuracy (key "digits")."""
        recs = self.records()
        values = by_unit([r["value"] for r in recs], [r["unit"] for r in recs])
        rows = [[v if c == "value" else r[c] for c in COLUMNS] for r, v in zip(recs, values)]
        if self.digits < DIGITS_WARN:          # the accuracy first: section "Accuracy", key "digits", the line as note
            head, _, note = accuracy(self.digits, DIGITS_WARN, self.lang, markdown=False).partition(": ")
            rows.insert(0, [head, "digits", "digits", round(self.digits, 1), "", "", note])
        write_text(path, rows_csv(COLUMNS, ([csv_cell(x) for x in row] for row in rows)))

    def to_json(self, path: str | Path) -> None:
        """Write the rows as a JSON list of objects, values as in `to_csv`, NaN as null (atomic)."""
        recs = self.records()
        values = by_unit([r["value"] for r in recs], [r["unit"] for r in recs])
        recs = [{**r, "value": plain(v)} for r, v in zip(recs, values)]
        doc = {"mechanism": self.mechanism, "phi_deg": self.phi_deg, "mu_l": self.mu_l,
               "digits": round(self.digits, 1), "rows": recs}
        write_text(path, json.dumps(doc, ensure_ascii=False, indent=1, allow_nan=False) + "\n")

    def write(self, out_dir: str | Path) -> list[Path]:
        """worksheet.md, .html, .csv and .json into `out_dir` (each atomic); returns the paths."""
        out = Path(out_dir)
        paths = [out / f"worksheet.{ext}" for ext in ("md", "html", "csv", "json")]
        write_text(paths[0], self.markdown())
        write_text(paths[1], self.html())
        self.to_csv(paths[2])
        self.to_json(paths[3])
        return paths


#: The style of every HTML page of the worksheet and the teacher's pack: screen and print (A4).
CSS = """body{font-family:"DejaVu Sans",Arial,sans-serif;font-size:11pt;line-height:1.35;margin:1.5em auto;
max-width:60em;padding:0 1em;color:#111}
h1{font-size:1.4em}h2{font-size:1.15em;margin-top:1.4em}
table{border-collapse:collapse;margin:.5em 0;width:100%}
th,td{border:1px solid #888;padding:.2em .45em;vertical-align:top}th{background:#eee;text-align:left}
td.num{text-align:right;white-space:nowrap}td.blank{min-width:6em;height:1.4em}
.area{border:1px solid #000;height:24cm;margin-top:1em;position:relative}
.titleblock{position:absolute;right:0;bottom:0;border-left:1px solid #000;border-top:1px solid #000;
padding:.3em .6em;width:40%}
.plans{display:grid;grid-template-columns:repeat(3,1fr);gap:.5em}.plans img{width:100%;border:1px solid #ccc}
@media (max-width:800px){table{display:block;overflow-x:auto}.plans{grid-template-columns:1fr}}
@media print{body{margin:0;max-width:none;font-size:10pt}h2{break-after:avoid}tr{break-inside:avoid}
.area{break-before:page;height:26cm}a{color:inherit;text-decoration:none}}
@page{size:A4;margin:12mm 10mm 12mm 20mm}
"""


#: A name of letters and digits in a note's formula (m2, ω1, R12, ps2, R12t; ω1² squared): a symbol, its digits a subscript.
_NOTE_SYMBOL = re.compile(r"(?<![\w'])[^\W\d_]+\d+[nt]?(?=[²³]|[^\w(]|$)")


def _html_cell(s: str, column: int) -> str:
    """A table cell's text as HTML (`_text.html_text`), its symbols' scripts in <sub> and <sup>
    by the one rule of `symbols` (`html`): the symbol column's (0) text one symbol (R12t as
    R<sub>12</sub><sup>t</sup>), in a note (column 4) also its names of letters and digits (m2 g);
    the value, unit and direction as they are."""
    cell = html_text(s)
    if column == 0:
        return html(mark(cell), escaped=True)
    return html(_NOTE_SYMBOL.sub(lambda m: mark(m.group()), cell), escaped=True) if column == 4 else cell


def html_document(title: str, body: str, lang: str, css: str = CSS) -> str:
    """A standalone HTML5 page in `lang`: UTF-8, `title` (escaped), the style `css` (screen and
    print), `body` (HTML, as given)."""
    from html import escape
    check_lang(lang)
    return (f'<!DOCTYPE html>\n<html lang="{lang}">\n<head>\n<meta charset="utf-8">\n'
            f'<meta name="viewport" content="width=device-width, initial-scale=1">\n<title>{escape(title)}</title>\n'
            f"<style>\n{css}</style>\n</head>\n<body>\n{body}</body>\n</html>\n")


def _direction(d: str, lang: str) -> str:
    if d in ("cw", "ccw"):
        return text(f"ws.{d}", lang)
    if d.startswith("angle:"):
        return text("ws.angle", lang, angle=num(float(d[6:]), lang, decimals=2))
    return d


# ----------------------------------------------------------------------------- the cycle

@dataclass(frozen=True)
class CycleRow:
    """A row of a `WorksheetCycle`, the same at every angle: `Row` without its value and
    direction. `direction`: "angle" (a vector's angle from +x), "sense" (cw/ccw) or "" (none);
    `notes`: the note's variants (`WorksheetCycle.note_index` picks the one of each angle), each
    a `str.format` template whose field `x` is the number it states at that angle
    (`WorksheetCycle.note_x`)."""
    section: str
    key: str
    symbol: str
    unit: str
    direction: str = ""
    notes: tuple[str, ...] = ("",)


@dataclass(frozen=True, eq=False)
class WorksheetCycle:
    """The worksheet of `mech` at N crank angles (`worksheet_cycle`), rows as arrays over the angles.

    `rows` (R): every row written at one angle or more, in the texts' order. Each (N, R):
    `values` SI (mm for arms and z; NaN where the row is not written at that angle), `present`
    (the row is written there: a translating link has no ω, an ε of 0 at rest none), `turn` (an
    "angle" row's angle in deg from +x, a "sense" row's sign: +1 ccw, -1 cw), `pointed` (the row
    has a direction there), `note_index` and `note_x` (`CycleRow.notes`). `digits` (N,): the
    significant digits left at each angle. `at(i)`: the `Worksheet` of angle i."""
    mechanism: str
    phi_deg: np.ndarray
    mu_l: float
    rows: tuple[CycleRow, ...]
    values: np.ndarray
    present: np.ndarray
    turn: np.ndarray
    pointed: np.ndarray
    note_index: np.ndarray
    note_x: np.ndarray
    lang: str = "en"
    digits: np.ndarray | None = None

    @property
    def n(self) -> int:
        """The number of angles."""
        return len(self.phi_deg)

    @property
    def keys(self) -> tuple[str, ...]:
        """The rows' keys, in the order of `values`' columns."""
        return tuple(r.key for r in self.rows)

    def __repr__(self) -> str:
        return f"WorksheetCycle({self.mechanism!r}, {self.n} angles, mu_l={self.mu_l:g}, rows={len(self.rows)})"

    def at(self, i: int) -> Worksheet:
        """The worksheet of angle i (0 <= i < n): the rows written there, directions and notes as text."""
        if not -self.n <= i < self.n:
            raise IndexError(f"worksheet: angle index {i} out of range for {self.n} angles")
        rows = []
        for r, spec in enumerate(self.rows):
            if not self.present[i, r]:
                continue
            d, t = "", float(self.turn[i, r])
            if self.pointed[i, r]:
                d = f"angle:{t:.6f}" if spec.direction == "angle" else "ccw" if t > 0 else "cw"
            note = spec.notes[self.note_index[i, r]].format(x=float(self.note_x[i, r]))
            rows.append(Row(spec.section, spec.key, spec.symbol, float(self.values[i, r]), spec.unit, d, note))
        return Worksheet(self.mechanism, float(self.phi_deg[i]), self.mu_l, tuple(rows), self.lang,
                         float(self.digits[i]))


def _literal(s: str) -> str:
    """`s` as a `str.format` template that writes it unchanged."""
    return s.replace("{", "{{").replace("}", "}}")


def _angle(v: np.ndarray) -> np.ndarray:
    """The angle of each vector v (N, 2) from +x, deg."""
    return np.degrees(np.arctan2(v[..., 1], v[..., 0]))


def _sense(x: np.ndarray, scale=0.0) -> tuple:
    """The sense of rotation of x (N,) as (turn, pointed): none where |x| is rounding of
    `scale` (an ω that is zero but for 1e-15 of the crank's has no sense to read)."""
    with np.errstate(invalid="ignore"):
        return np.where(x > 0, 1.0, -1.0), ~(np.abs(x) <= 1e-12 * scale)


def _across(v: np.ndarray) -> np.ndarray:
    """v (N, 2) turned by +90 deg."""
    return np.stack([-v[:, 1], v[:, 0]], axis=-1)


class _Sheet:
    """Collects the rows of a `WorksheetCycle` from an analysis at N angles, each row's value
    and direction as (N,) arrays."""

    def __init__(self, res: Analysis, mu_l: float):
        self.res, self.mech, self.mu_l = res, res.mech, mu_l
        self.N = len(res.phi_deg)
        self.rows: list[CycleRow] = []
        self.cols: list[tuple] = []          # per row: value, present, turn, pointed, note_index, note_x
        self.seen: set[str] = set()
        self.L = lettering(res.mech)

    def n(self, k: int) -> int:
        """Link k's number as the model's text letters it (the frame: 4 for seed 002's ICE)."""
        return k or self.L.frame

    def R(self, i: int, j: int) -> str:
        """R<i><j> with the frame lettered as the model's text letters it (R43 for seed 002's ICE)."""
        return f"R{self.n(i)}{self.n(j)}"

    def add(self, section, key, symbol, value, unit, direction=None, note="", x=None, present=None):
        """A row: `value` (N,) or one for all angles; `direction` None, ("sense", (turn, pointed))
        or ("angle", (deg, pointed)); `note` one text or (N,) texts (a template of field `x`,
        the (N,) numbers, where `x` is given); written only at the angles `present` (default
        all), and not at all where at none."""
        if present is not None:
            if not present.any():
                return
            value = np.where(present, value, np.nan)
        kind, (turn, pointed) = direction or ("", (np.nan, False))
        if isinstance(note, str):
            notes, index = (note,), 0
        else:
            notes, index = np.unique(np.asarray(note, dtype=object), return_inverse=True)
        notes = tuple(str(s) if x is not None else _literal(str(s)) for s in notes)
        self.rows.append(CycleRow(section, key, symbol, unit, kind, notes))
        self.cols.append((value, True if present is None else present, turn, pointed, index,
                          np.nan if x is None else x))

    def vector(self, section, key, symbol, v: np.ndarray, unit, note="", x=None, present=None):
        """A vector's magnitude and angle; one printed as 0 (below i18n.ZERO) has no direction."""
        size = np.hypot(v[..., 0], v[..., 1])
        self.add(section, key, symbol, size, unit, ("angle", (_angle(v), size >= ZERO)), note, x, present)

    def cycle(self, name: str, lang: str) -> WorksheetCycle:
        """The rows collected, as the worksheet of the analysis' angles named `name`."""
        shape = (self.N, len(self.rows))
        value, turn, x = np.empty(shape), np.empty(shape), np.empty(shape)
        present, pointed, index = np.empty(shape, bool), np.empty(shape, bool), np.empty(shape, int)
        for r, col in enumerate(self.cols):         # each row's columns, broadcast over the angles
            value[:, r], present[:, r], turn[:, r], pointed[:, r], index[:, r], x[:, r] = col
        return WorksheetCycle(name, self.res.phi_deg, self.mu_l, tuple(self.rows), value, present, turn, pointed,
                              index, x, lang, self.res.digits)

    # ---- kinematics
    def link_points(self, k: int, pairs) -> list[str]:
        link = self.mech.links[k]
        names = [p.point for p in pairs if k in p.links and p.point in link.points]
        if link.com:
            names.append(link.com)
        return list(dict.fromkeys(names))

    def velocity_rows(self, names: list[str]) -> None:
        """V_X of each point not written yet (the crank pin is written first)."""
        for name in names:
            if name not in self.seen and name != self.mech.drive.point:
                self.seen.add(name)
                self.vector("kinematics", f"V_{name}", f"V_{name}", self.res.velocity(name), "m/s",
                            f"p{name.lower()} μ_v")

    def kinematics(self) -> None:
        res, m, d = self.res, self.mech, self.mech.drive
        w1 = res.omega(d.link)
        self.add("kinematics", f"omega_{d.link}", f"ω{d.link}", abs(w1), "rad/s", ("sense", _sense(w1)), "π n1 / 30")
        self.vector("kinematics", f"V_{d.point}", f"V_{d.point}", res.velocity(d.point), "m/s",
                    f"ω{d.link} l_{d.pivot}{d.point}")
        accel = [("a", d.point, None)]
        for g in m.structure.groups:
            if g.klass == 3:
                accel += self.special_point(g)
            for link, outer, pin, _ in g.sides:
                pts = self.link_points(link, g.pairs)
                com = self.mech.links[link].com
                self.velocity_rows([n for n in pts if n != com])
                if outer.kind == "R" and pin.kind == "R":
                    rel = res.velocity(pin.point) - res.velocity(outer.point)
                    sym = f"V_{pin.point}{outer.point}"
                    self.vector("kinematics", sym, sym, rel, "m/s", f"{outer.point.lower()}{pin.point.lower()} μ_v")
                    accel.append(("rel", link, (outer.point, pin.point)))
                self.velocity_rows([com] if com else [])
                wk = res.omega(link)
                self.add("kinematics", f"omega_{link}", f"ω{link}", abs(wk), "rad/s", ("sense", _sense(wk, abs(w1))),
                         f"V_{pin.point}{outer.point} / l_{outer.point}{pin.point}" if outer.kind == pin.kind == "R" else "",
                         present=~((wk == 0) & (res.eps(link) == 0)))      # a translating link has no ω
                accel += [("a", name, None) for name in pts]
            for p in dict.fromkeys(g.pairs):
                if p.kind == "P":
                    key, sym = f"V_rel({p.links[0]},{p.links[1]})", f"V_rel({self.n(p.links[0])},{p.links[1]})"
                    self.add("kinematics", key, sym, abs(res.slide_velocity(*p.links)), "m/s", None,
                             f"along the guide of link {self.n(p.links[0])}")
                    accel.append(("cor", p, None))
            accel.append(("eps", g.links, None))
        self.accelerations(accel)

    def special_point(self, g) -> list:
        """A triad's base link first, by Assur's special point S (the axes of the two leashes
        that meet at the best angle at each angle, `special_index`): V_S and a_S from 2x2
        solves, then its pins, omega and eps from the third. Returns the acceleration steps of the base."""
        res, b = self.res, g.links[0]
        kin = res.kin
        S = special_point_z(self.mech, kin, g)
        k = special_index(self.mech, kin, g)
        r = (S - kin.origin_z[:, b]) / kin.rot[:, b] * kin.rot[:, b]      # as kin.point_z takes the local point
        w, e = kin.omega[:, b], kin.eps[:, b]
        V, A = kin.v_z[:, b] + 1j * w * r, kin.a_z[:, b] + (1j * e - w**2) * r
        order = [tuple(g.sides[(j + i) % 3] for i in (1, 2, 0)) for j in range(3)]     # special_sides at each k
        axes = [" and ".join(f"{o.point}{i.point}" if o.kind == i.kind == "R" else
                             f"⟂ guide at {o.point if i.kind == 'P' else i.point}" for _, o, i, _ in sides[:2])
                for sides in order]
        self.vector("kinematics", "V_S", "V_S", np.stack([V.real, V.imag], -1), "m/s",
                    np.array([f"ps μ_v; S on the axes {a}" for a in axes], dtype=object)[k])
        pts = self.link_points(b, g.pairs)
        self.velocity_rows(pts)
        wb = res.omega(b)
        X, u = (np.choose(k, z) for z in zip(*leash_axes(self.mech, kin, g)))   # the leash g.sides[k], not through S
        arm = ((X - S).conjugate() * u).imag
        self.add("kinematics", f"omega_{b}", f"ω{b}", abs(wb), "rad/s", ("sense", _sense(wb)),
                 np.array([f"leash {s[2][0]}'s axis, arm h_S = {{x:.4g}} m" for s in order], dtype=object)[k],
                 x=abs(arm))
        self.vector("accelerations", "a_S", "a_S", np.stack([A.real, A.imag], -1), "m/s^2", "πs μ_a")
        return [("a", name, None) for name in pts]

    def _split(self, g, side) -> tuple:
        """The outer pin reaction of a group's link `side` split: the unit axis e and across it t
        (world, (N, 2)), why R..t is known (None: not split) and the number that note states.
        Two pins: along the link, R..t from its moment about the inner pin; a triad's leash on an
        inner prismatic pair: along the guide's normal, R..t along the guide from the leash's
        forces along it."""
        link, outer, pin, _ = side
        res = self.res
        if outer.kind == "R" and pin.kind == "P" and g.klass == 3:
            d = complex(*pin.direction) * res.kin.rot[:, pin.links[0]]
            return np.stack([-d.imag, d.real], -1), np.stack([d.real, d.imag], -1), \
                f"Σ F along the guide = 0 of link {link}", None
        if outer.kind != "R" or pin.kind != "R":
            return None, None, None, None
        r = res.position(pin.point) - res.position(outer.point)
        l = np.hypot(r[:, 0], r[:, 1])
        e = r / l[:, None]
        return e, _across(e), _literal(f"Σ M_{pin.point} = 0 of link {link}, arm {outer.point}{pin.point} = ") \
            + "{x:.4g} mm", l / self.mu_l

    def accelerations(self, steps) -> None:
        res, d = self.res, self.mech.drive
        done: set = set()
        e1, w1 = res.eps(d.link), res.omega(d.link)
        for what, a, b in steps:
            if what == "a" and a not in done:
                done.add(a)
                note = f"π{a.lower()} μ_a"
                if a == d.point:
                    note = np.where(e1 != 0, note, f"ω{d.link}² l_{d.pivot}{d.point}")
                self.vector("accelerations", f"a_{a}", f"a_{a}", res.acceleration(a), "m/s^2", note)
            elif what == "rel":
                k, (outer, inner) = a, b
                r = res.position(inner) - res.position(outer)
                w, e = res.omega(k), res.eps(k)
                self.vector("accelerations", f"an_{inner}{outer}", f"a^n_{inner}{outer}", (-w * w)[:, None] * r,
                            "m/s^2", f"ω{k}² l_{outer}{inner}")
                self.vector("accelerations", f"at_{inner}{outer}", f"a^τ_{inner}{outer}", e[:, None] * _across(r),
                            "m/s^2", f"n{k}{inner.lower()} μ_a")
            elif what == "cor":
                p = a
                wg = res.omega(p.links[0])
                dvec = res.velocity(p.point) - _point_of(res, p.links[0], p.point)
                sym = f"a^Cor({self.n(p.links[0])},{self.n(p.links[1])})"
                self.vector("accelerations", f"aCor_{p.links[0]}_{p.links[1]}", sym, (2 * wg)[:, None] * _across(dvec),
                            "m/s^2", f"2 ω{p.links[0]} V_rel", present=wg != 0)
                ar = res.slide_acceleration(*p.links)
                sym = f"a^r({self.n(p.links[0])},{self.n(p.links[1])})"
                self.add("accelerations", f"ar_{p.links[0]}_{p.links[1]}", sym, abs(ar), "m/s^2", None, "along the guide")
            elif what == "eps":
                for k in a:
                    if ("eps", k) in done:
                        continue
                    done.add(("eps", k))
                    ek = res.eps(k)
                    self.add("accelerations", f"eps_{k}", f"ε{k}", abs(ek), "rad/s^2", ("sense", _sense(ek, w1 * w1 + abs(e1))),
                             "a^τ / l", present=~((ek == 0) & (res.omega(k) == 0)))
        self.add("accelerations", f"eps_{d.link}", f"ε{d.link}", abs(e1), "rad/s^2", ("sense", _sense(e1)), "given",
                 present=e1 != 0)

    # ---- loads
    def loads(self) -> None:
        res, m = self.res, self.mech
        down = ("angle", (_angle(np.array([0.0, -1.0])), True))
        for link in m.links[1:]:
            if not (link.mass or link.I_S):
                continue
            k = link.id
            il = res.inertia(k)
            self.add("inertia", f"m_{k}", f"m{k}", link.mass, "kg", None, f"G{k} / g")
            self.add("inertia", f"G_{k}", f"G{k}", link.mass * m.g, "N", down, f"m{k} g")
            S = link.com or "S"
            self.vector("inertia", f"F_i{k}", f"F_i{k}", il.force, "N", f"m{k} a_{S}, against a_{S}")
            if link.I_S:
                self.add("inertia", f"M_i{k}", f"M_i{k}", abs(il.moment), "N m", ("sense", _sense(il.moment)),
                         f"I_S{k} ε{k}, against ε{k}")
            arm = (il.moment != 0) & np.isfinite(il.h)
            self.add("inertia", f"h_{k}", f"h{k}", il.h, "m", None, f"M_i{k} / F_i{k}", present=arm)
            self.add("inertia", f"z_{k}", f"z{k}", il.h / self.mu_l, "mm", None, f"h{k} / μ_l", present=arm)
        for n, ld in enumerate(m.loads):
            u = "N m" if ld.kind == "moment" else "N"
            self.add("inertia", f"load_{n}", self.L.load(ld.name), abs(load_magnitude(m, res.kin, ld)), u, None,
                     "read from its diagram" if ld.table is not None else "given")

    # ---- reactions
    def reactions(self) -> None:
        res, m = self.res, self.mech
        for g in reversed(m.structure.groups):
            third = special_index(m, res.kin, g) if g.klass == 3 else None   # g.sides[third]: by Σ M_S
            split = [(j, side, *self._split(g, side)) for j, side in enumerate(g.sides)]
            for _, (link, _, _, other), e, t, why, x in split:
                if why:
                    Rt = np.sum(res.reaction(other, link) * t, axis=-1)
                    self.add("reactions", f"Rt_{other}_{link}", f"{self.R(other, link)}t", abs(Rt), "N",
                             ("angle", (_angle(np.sign(Rt)[:, None] * t), True)), why, x)
            for j, (link, _, _, other), e, _, why, _ in split:
                if why:
                    Rn = np.sum(res.reaction(other, link) * e, axis=-1)
                    how = "force plan of the group" if third is None else \
                        np.where(third == j, "Σ M_S = 0 of the group", "force plan of the group")
                    self.add("reactions", f"Rn_{other}_{link}", f"{self.R(other, link)}n", abs(Rn), "N",
                             ("angle", (_angle(np.sign(Rn)[:, None] * e), True)), how)
            for link, _, _, other in g.sides:
                self.vector("reactions", f"R_{other}_{link}", self.R(other, link), res.reaction(other, link), "N",
                            "force plan of the group")
            if g.klass == 3:
                b = g.links[0]
                for link, _, _, _ in g.sides:
                    self.vector("reactions", f"R_{link}_{b}", self.R(link, b), res.reaction(link, b), "N",
                                f"force plan of link {link}")
            else:
                j, k = g.links
                self.vector("reactions", f"R_{k}_{j}", self.R(k, j), res.reaction(k, j), "N",
                            f"force plan of link {j}")
            for p in dict.fromkeys(g.pairs):
                if p.kind == "P":
                    self.add("reactions", f"x_{p.links[0]}_{p.links[1]}", "x" + self.R(*p.links)[1:],
                             res.reaction_offset(*p.links), "m", None, f"Σ M_{p.point} = 0 of link {p.links[1]}")

    # ---- crank and lever
    def crank(self) -> None:
        res, m, d, L = self.res, self.mech, self.mech.drive, self.L
        O = res.position(d.pivot)
        for p in m.pairs:
            if d.link in p.links and 0 not in p.links:
                other = p.links[0] if p.links[1] == d.link else p.links[1]
                R = res.reaction(other, d.link)
                self.vector("crank", f"R_{other}_{d.link}", self.R(other, d.link), R, "N",
                            f"= -{self.R(d.link, other)}")
                r = res.position(p.point) - O
                arm = abs(r[:, 0] * R[:, 1] - r[:, 1] * R[:, 0]) / np.hypot(R[:, 0], R[:, 1]) / self.mu_l
                self.add("crank", f"h_R{other}{d.link}", f"h_{self.R(other, d.link)}", arm, "mm", None,
                         "arm about the crank axis, on the crank's plan")
        M = res.balancing_moment
        self.add("crank", "M_bal", L.M_bal, M, "N m", ("sense", _sense(M)), "Σ M_O = 0 of the crank (signed about +z)")
        if d.kind == "machine":
            self.vector("crank", "F_bal", L.F_bal, res.balancing_force, "N",
                        "F21 h / r_b, at the pitch point on the line of action")
            self.add("crank", "r_b", "r_b", d.gear.r_b, "m", None, "r_w cos α_w")
        self.vector("crank", f"R_0_{d.link}", self.R(0, d.link), res.reaction(0, d.link), "N", "force plan of the crank")
        l1 = math.dist(*(m.links[d.link].points[n] for n in (d.pivot, d.point)))
        ML = res.lever_moment
        F1, M1 = L.lever(L.F_bal), L.lever(L.M_bal)
        self.add("crank", "F_bal_lever", F1, abs(ML) / l1, "N", None,
                 f"at point {d.point}, ⟂ p{d.point.lower()}: Σ M_p = 0 on the lever")
        self.add("crank", "M_bal_lever", M1, ML, "N m", ("sense", _sense(ML)), f"{F1} l_{d.pivot}{d.point}")
        with np.errstate(divide="ignore", invalid="ignore"):
            delta = np.where(ML != 0, (ML - M) / ML * 100, np.nan)
        self.add("crank", "delta_pct", "δ", delta, "%", None, f"({M1} - {L.M_bal}) / {M1} 100 %")

    # ---- friction
    def friction(self, ex: Analysis, first: Analysis) -> None:
        """The friction terms (a model with [friction]; `ex` its analysis with friction in the
        reactions, `first` in the first approximation, one of them the sheet's own): per pair the
        friction circle rho = f r and the friction moment f r |R|, or the friction angle arctg f
        and force f |N|; M_bal with friction, the first approximation's and eta (where it is
        undefined, why in its note)."""
        m, L = self.mech, self.L
        f = m.friction.f
        for p in m.pairs:
            i, j = p.links
            R, q = self.R(i, j), ex.friction.load[:, p.index]
            Rf = R if ex is self.res else f"{R},f"
            if ex is not self.res:         # the sheet's reactions are frictionless: the frictional ones beside them
                self.add("friction", f"Rf_{i}_{j}", f"|{Rf}|", np.linalg.norm(ex.forces.R[:, p.index], axis=-1), "N",
                         None, "the reaction with friction in the reactions")
            if p.kind == "R":
                r = p.radius if p.radius is not None else m.friction.radius
                self.add("friction", f"rho_{i}_{j}", f"ρ{R[1:]}", f * r, "m", None, "f r")
                self.add("friction", f"Mf_{i}_{j}", f"M_f{R[1:]}", abs(q), "N m", ("sense", _sense(q)),
                         f"f r |{Rf}|, against the relative rotation")
            else:
                self.add("friction", f"phi_f_{i}_{j}", f"φ_f{R[1:]}", math.degrees(math.atan(f)), "deg", None,
                         "tan φ_f = f")
                self.add("friction", f"Ff_{i}_{j}", f"F_f{R[1:]}", abs(q), "N", None,
                         f"f |N{R[1:]}|, along the guide, against the sliding")
        M0, M1, Mf = ex.balancing_moment_frictionless, first.balancing_moment_with_friction, ex.balancing_moment
        if ex is self.res:             # the sheet's M_bal is the frictional one: the frictionless one beside it
            self.add("friction", "M_bal_0", f"{L.M_bal},0", M0, "N m", ("sense", _sense(M0)), "frictionless")
        self.add("friction", "M_bal_first", f"{L.M_bal} + P_f/ω1", M1, "N m", ("sense", _sense(M1)), "first approximation")
        self.add("friction", "M_bal_friction", f"{L.M_bal},f", Mf, "N m", ("sense", _sense(Mf)),
                 "friction in the reactions, {x:.0f} passes", x=ex.friction.passes.max(axis=1))
        why = ex.efficiency_reason
        with np.errstate(invalid="ignore"):
            rule = np.where(M0 * ex.omega(1) >= 0, f"{L.M_bal} / {L.M_bal},f", f"{L.M_bal},f / {L.M_bal}")
        self.add("friction", "eta", "η", ex.efficiency, "1", None,
                 np.where(why != "", "undefined: " + why, rule.astype(object)))


def _point_of(res: Analysis, k: int, name: str) -> np.ndarray:
    """Velocity (N, 2) of the point of link k at the current position of point `name`."""
    r = res.position(name) - res.kin.origin[:, k]
    return res.kin.v_origin[:, k] + res.omega(k)[:, None] * _across(r)


def worksheet_cycle(mech: Mechanism, res: Analysis, mu_l: float, lang: str = "en",
                    friction_res: Analysis | None = None) -> WorksheetCycle:
    """The worksheet of `mech` at every crank angle of `res` (its analysis, `analyze`; the
    graphical method's is frictionless, friction="first"), arms and z in mm at `mu_l` (m/mm),
    in `lang`. The friction rows of a model with [friction] from `friction_res`: its analysis at
    the same angles in the other friction mode (friction="reactions" beside a frictionless `res`,
    "first" beside one with friction in the reactions; `solution.solve` makes both); without it the
    sheet has no friction section. No Python loop over the angles."""
    check_lang(lang)
    if not (isinstance(mu_l, (int, float)) and not isinstance(mu_l, bool) and math.isfinite(mu_l) and mu_l > 0):
        raise ValueError(f"mu_l: expected a positive scale in m/mm, got {mu_l!r}")
    pair = None
    if mech.friction is not None and friction_res is not None:
        other = "first" if res.friction is not None else "reactions"
        if (friction_res.friction is None) != (other == "first") or not np.array_equal(friction_res.phi_deg, res.phi_deg):
            raise ValueError(f"friction_res: expected the analysis of {mech.name!r} at the angles of res with "
                             f"friction={other!r} (its friction rows), got {friction_res}")
        pair = (res, friction_res) if other == "first" else (friction_res, res)
    sheet = _Sheet(res, float(mu_l))
    sheet.kinematics()
    sheet.loads()
    sheet.reactions()
    sheet.crank()
    if pair:
        sheet.friction(*pair)
    return sheet.cycle(lettering(mech).name(lang, mech.name), lang)


def worksheet(mech: Mechanism, at: float | None = None, *, mu_l: float | None = None, lang: str = "en",
              friction: str = "first", law=None, solution: Solution | None = None) -> Worksheet:
    """The worksheet of `mech` at crank angle `at` (deg; default the model's design position):
    `worksheet_cycle` at the one angle of `solution` (`solution.solve(mech, [at], friction, law)`:
    at the true law of motion `law` where given; made here where not given). Self-locking is not
    warned of here: the sheet's rows state eta.

    mu_l: the scale of the plan of positions, m/mm, for the arms and z in mm (default: the
    crank drawn 30-35 mm at a round scale, as seed 002 chooses it). lang: "en", "uk" or "ru"
    (the mechanism named as its lettering names it in that language). Symbols as the model's
    lettering writes them (R43, M_зр). friction: "first" (the graphical method's frictionless
    reactions; a model with [friction] gets its friction section from the exact solution, its
    reactions with friction |R..,f| written beside) or "reactions" (every reaction and M_bal of
    the sheet with friction in the reactions, as `plans.build(..., friction="reactions")` draws them)."""
    check_lang(lang)
    if at is None:
        at = mech.drive.design_deg
    if mu_l is not None and not (isinstance(mu_l, (int, float)) and math.isfinite(mu_l) and mu_l > 0):
        raise ValueError(f"mu_l: expected a positive scale in m/mm, got {mu_l!r}")
    if friction not in ("first", "reactions"):
        raise ValueError(f"friction: expected 'first' or 'reactions', got {friction!r}")
    if solution is None:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", SelfLockingWarning)
            solution = solve(mech, [float(at)], friction, law)
    if mu_l is None:
        mu_l = solution_scales(mech, solution)["mu_l"].value
    return worksheet_cycle(mech, solution.res, float(mu_l), lang, solution.other).at(0)
