"""The worksheet of the graphical-analytic method (issue 12, item 3): every intermediate value the
texts write down at one crank position, in their order (seed 002 sec. 1.2.2-1.2.3, seed 000
secs. 4, 6-8), with units and senses, taken from the exact solution (`analyze`).

Order: the initial link and each Assur group in the order of attachment (velocities, then
accelerations), the inertia loads and the applied loads, the reactions group by group from the
last group attached back to the crank, the crank, Zhukovsky's lever and the difference of the two
balancing moments. Outputs: Markdown, HTML, a pandas frame, CSV and JSON (written atomically).

May use: the solver (`solve`, `analysis`, `applied`, `model`), `_io`, `_text` (safe cells), numpy; pandas and markdown-it-py inside the
output methods only. Never matplotlib, never the harness.
"""
from __future__ import annotations

import json
import warnings
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..analysis import Analysis
from ..solve import analyze
from ..applied import load_magnitude
from ..errors import SelfLockingWarning
from ..kinematics import DIGITS_WARN, leash_axes, special_point_z, special_sides
from .._io import write_text
from .._text import csv_cell, markdown_text
from ..model import Mechanism
from ..tables import FLOAT_FORMAT, by_unit, plain
from .i18n import ZERO, accuracy, check_lang, num, phrase, text, unit
from ..model.lettering import lettering
from .scales import choose_scales

__all__ = ["Row", "Worksheet", "worksheet", "COLUMNS", "CSS", "html_document"]

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
        (`i18n`); values stay numbers."""
        lang = self.lang
        return [{"section": text(f"ws.{r.section}", lang), "key": r.key, "symbol": r.symbol, "value": r.value,
                 "unit": unit(r.unit, lang), "direction": _direction(r.direction, lang),
                 "note": phrase(r.note, lang)} for r in self.rows]

    def frame(self):
        """The rows as a pandas DataFrame (columns COLUMNS)."""
        import pandas as pd
        df = pd.DataFrame(self.records(), columns=list(COLUMNS))
        df.attrs.update(mechanism=self.mechanism, phi_deg=self.phi_deg, mu_l=self.mu_l)
        return df

    def markdown(self) -> str:
        """The worksheet as Markdown: a title, then one table per section (numbers as the
        worksheet's language writes them); near a singular position, the digits left."""
        lang = self.lang
        out = [f"# {text('ws.title', lang, name=markdown_text(self.mechanism), phi=num(self.phi_deg, lang, 6))}", "",
               f"{text('scale', lang)} μ_l = {num(self.mu_l, lang, 6)} {unit('m/mm', lang)}"]
        if self.digits < DIGITS_WARN:
            out += ["", accuracy(self.digits, DIGITS_WARN, lang)]
        section = None
        head = [text(f"ws.head.{c}", lang) for c in ("symbol", "value", "unit", "direction", "note")]
        for rec in self.records():
            if rec["section"] != section:
                section = rec["section"]
                out += ["", f"## {section}", "", "| " + " | ".join(head) + " |", "|---|---:|---|---|---|"]
            cells = (rec["symbol"], num(rec["value"], lang, 6), rec["unit"], rec["direction"], rec["note"])
            out.append("| " + " | ".join(markdown_text(str(c)) for c in cells) + " |")
        return "\n".join(out) + "\n"

    def html(self) -> str:
        """A standalone HTML page (`html_document`): the Markdown rendered (CommonMark with tables;
        raw HTML is not passed through)."""
        from markdown_it import MarkdownIt
        body = MarkdownIt("commonmark", {"html": False}).enable("table").render(self.markdown())
        return html_document(text("ws.title", self.lang, name=self.mechanism, phi=num(self.phi_deg, self.lang, 6)),
                             body, self.lang)

    def to_csv(self, path: str | Path) -> None:
        """Write the rows as CSV, each value to 12 significant digits of the largest |value| of its
        unit (`kinetostat.tables.by_unit`), no cell read as a formula (atomic: a temporary file in the same folder, then replaced).
        Near a singular position the first row states the accuracy (key "digits")."""
        import pandas as pd
        df = self.frame()
        df["value"] = by_unit(df["value"], df["unit"])
        if self.digits < DIGITS_WARN:          # the accuracy first: section "Accuracy", key "digits", the line as note
            head, _, note = accuracy(self.digits, DIGITS_WARN, self.lang, markdown=False).partition(": ")
            df = pd.concat([pd.DataFrame([{"section": head, "key": "digits", "symbol": "digits",
                                           "value": round(self.digits, 1), "unit": "", "direction": "",
                                           "note": note}]), df], ignore_index=True)
        write_text(path, df.map(csv_cell).to_csv(index=False, float_format=FLOAT_FORMAT))

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


# ----------------------------------------------------------------------------- building

def _angle(v: np.ndarray) -> str:
    return f"angle:{math.degrees(math.atan2(v[1], v[0])):.6f}"


def _sense(x: float, scale: float = 0.0) -> str:
    """The sense of rotation of x, none where |x| is rounding of `scale` (an ω that is zero but
    for 1e-15 of the crank's has no sense to read)."""
    return "" if abs(x) <= 1e-12 * scale else "ccw" if x > 0 else "cw"


class _Sheet:
    """Collects the rows of one position (index 0 of a one-angle Analysis)."""

    def __init__(self, res: Analysis, mu_l: float):
        self.res, self.mech, self.mu_l, self.rows = res, res.mech, mu_l, []
        self.seen: set[str] = set()
        self.L = lettering(res.mech)

    def n(self, k: int) -> int:
        """Link k's number as the model's text letters it (the frame: 4 for seed 002's ICE)."""
        return k or self.L.frame

    def R(self, i: int, j: int) -> str:
        """R<i><j> with the frame lettered as the model's text letters it (R43 for seed 002's ICE)."""
        return f"R{self.n(i)}{self.n(j)}"

    def add(self, section, key, symbol, value, unit, direction="", note=""):
        self.rows.append(Row(section, key, symbol, float(value), unit, direction, note))

    def vector(self, section, key, symbol, v: np.ndarray, unit, note=""):
        """A vector's magnitude and angle; one printed as 0 (below i18n.ZERO) has no direction."""
        size = np.hypot(*v)
        self.add(section, key, symbol, size, unit, _angle(v) if size >= ZERO else "", note)

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
                self.vector("kinematics", f"V_{name}", f"V_{name}", self.res.velocity(name)[0], "m/s",
                            f"p{name.lower()} μ_v")

    def kinematics(self) -> None:
        res, m, d = self.res, self.mech, self.mech.drive
        w1 = res.omega(d.link)[0]
        self.add("kinematics", f"omega_{d.link}", f"ω{d.link}", abs(w1), "rad/s", _sense(w1), "π n1 / 30")
        self.vector("kinematics", f"V_{d.point}", f"V_{d.point}", res.velocity(d.point)[0], "m/s",
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
                    rel = res.velocity(pin.point)[0] - res.velocity(outer.point)[0]
                    sym = f"V_{pin.point}{outer.point}"
                    self.vector("kinematics", sym, sym, rel, "m/s", f"{outer.point.lower()}{pin.point.lower()} μ_v")
                    accel.append(("rel", link, (outer.point, pin.point)))
                self.velocity_rows([com] if com else [])
                wk = res.omega(link)[0]
                if not (wk == 0 and res.eps(link)[0] == 0):      # a translating link has no ω
                    self.add("kinematics", f"omega_{link}", f"ω{link}", abs(wk), "rad/s", _sense(wk, abs(w1)),
                             f"V_{pin.point}{outer.point} / l_{outer.point}{pin.point}" if outer.kind == pin.kind == "R" else "")
                accel += [("a", name, None) for name in pts]
            for p in dict.fromkeys(g.pairs):
                if p.kind == "P":
                    vr = res.slide_velocity(*p.links)[0]
                    key, sym = f"V_rel({p.links[0]},{p.links[1]})", f"V_rel({self.n(p.links[0])},{p.links[1]})"
                    self.add("kinematics", key, sym, abs(vr), "m/s", "",
                             f"along the guide of link {self.n(p.links[0])}")
                    accel.append(("cor", p, vr))
            accel.append(("eps", g.links, None))
        self.accelerations(accel)

    def special_point(self, g) -> list:
        """A triad's base link first, by Assur's special point S (the axes of the two leashes
        that meet at the best angle, `special_sides`): V_S and a_S from 2x2 solves, then its
        pins, omega and eps from the third. Returns the acceleration steps of the base."""
        res, b = self.res, g.links[0]
        kin = res.kin
        S = special_point_z(self.mech, kin, g)[0]
        loc = (S - kin.origin_z[0, b]) / kin.rot[0, b]
        V, A = (complex(z[0]) for z in kin.point_z(b, (loc.real, loc.imag))[1:])
        sides = special_sides(self.mech, kin, g)
        axes = " and ".join(f"{o.point}{i.point}" if o.kind == i.kind == "R" else
                            f"⟂ guide at {o.point if i.kind == 'P' else i.point}" for _, o, i, _ in sides[:2])
        self.vector("kinematics", "V_S", "V_S", np.array([V.real, V.imag]), "m/s", f"ps μ_v; S on the axes {axes}")
        pts = self.link_points(b, g.pairs)
        self.velocity_rows(pts)
        wb = res.omega(b)[0]
        self.add("kinematics", f"omega_{b}", f"ω{b}", abs(wb), "rad/s", _sense(wb),
                 f"leash {sides[2][0]}'s axis, arm h_S = {abs(self._arm3(g, S, sides[2])):.4g} m")
        self.vector("accelerations", "a_S", "a_S", np.array([A.real, A.imag]), "m/s^2", "πs μ_a")
        return [("a", name, None) for name in pts]

    def _arm3(self, g, S: complex, side) -> float:
        """The arm about S of the axis of the leash `side` (the one not through S), m."""
        X, u = (complex(z[0]) for z in leash_axes(self.mech, self.res.kin, g)[g.sides.index(side)])
        return float(((X - S).conjugate() * u).imag)

    def _split(self, g, side) -> tuple:
        """The outer pin reaction of a group's link `side` split: the unit axis e and across it t
        (world, (2,)), and why R..t is known (None: not split). Two pins: along the link, R..t
        from its moment about the inner pin; a triad's leash on an inner prismatic pair: along
        the guide's normal, R..t along the guide from the leash's forces along it."""
        link, outer, pin, _ = side
        res = self.res
        if outer.kind == "R" and pin.kind == "P" and g.klass == 3:
            d = complex(*pin.direction) * complex(res.kin.rot[0, pin.links[0]])
            return np.array([-d.imag, d.real]), np.array([d.real, d.imag]), f"Σ F along the guide = 0 of link {link}"
        if outer.kind != "R" or pin.kind != "R":
            return None, None, None
        r = res.position(pin.point)[0] - res.position(outer.point)[0]
        l = np.hypot(*r)
        e = r / l
        return e, np.array([-e[1], e[0]]), \
            f"Σ M_{pin.point} = 0 of link {link}, arm {outer.point}{pin.point} = {l / self.mu_l:.4g} mm"

    def accelerations(self, steps) -> None:
        res, d = self.res, self.mech.drive
        done: set = set()
        e1, w1 = res.eps(d.link)[0], res.omega(d.link)[0]
        for what, a, b in steps:
            if what == "a" and a not in done:
                done.add(a)
                note = f"ω{d.link}² l_{d.pivot}{d.point}" if a == d.point and not e1 else f"π{a.lower()} μ_a"
                self.vector("accelerations", f"a_{a}", f"a_{a}", res.acceleration(a)[0], "m/s^2", note)
            elif what == "rel":
                k, (outer, inner) = a, b
                r = res.position(inner)[0] - res.position(outer)[0]
                w, e = res.omega(k)[0], res.eps(k)[0]
                self.vector("accelerations", f"an_{inner}{outer}", f"a^n_{inner}{outer}", -w * w * r, "m/s^2",
                            f"ω{k}² l_{outer}{inner}")
                self.vector("accelerations", f"at_{inner}{outer}", f"a^τ_{inner}{outer}", e * np.array([-r[1], r[0]]),
                            "m/s^2", f"n{k}{inner.lower()} μ_a")
            elif what == "cor":
                p = a
                wg = res.omega(p.links[0])[0]
                if wg:
                    dvec = res.velocity(p.point)[0] - _point_of(res, p.links[0], p.point)
                    cor = 2 * wg * np.array([-dvec[1], dvec[0]])
                    sym = f"a^Cor({self.n(p.links[0])},{self.n(p.links[1])})"
                    self.vector("accelerations", f"aCor_{p.links[0]}_{p.links[1]}", sym, cor, "m/s^2",
                                f"2 ω{p.links[0]} V_rel")
                ar = res.slide_acceleration(*p.links)[0]
                sym = f"a^r({self.n(p.links[0])},{self.n(p.links[1])})"
                self.add("accelerations", f"ar_{p.links[0]}_{p.links[1]}", sym, abs(ar), "m/s^2", "", "along the guide")
            elif what == "eps":
                for k in a:
                    if ("eps", k) in done:
                        continue
                    done.add(("eps", k))
                    ek = res.eps(k)[0]
                    if ek == 0 and res.omega(k)[0] == 0:
                        continue
                    self.add("accelerations", f"eps_{k}", f"ε{k}", abs(ek), "rad/s^2", _sense(ek, w1 * w1 + abs(e1)), "a^τ / l")
        if e1:
            self.add("accelerations", f"eps_{d.link}", f"ε{d.link}", abs(e1), "rad/s^2", _sense(e1), "given")

    # ---- loads
    def loads(self) -> None:
        res, m = self.res, self.mech
        for link in m.links[1:]:
            if not (link.mass or link.I_S):
                continue
            k = link.id
            il = res.inertia(k)
            self.add("inertia", f"m_{k}", f"m{k}", link.mass, "kg", "", f"G{k} / g")
            self.add("inertia", f"G_{k}", f"G{k}", link.mass * m.g, "N", _angle(np.array([0.0, -1.0])), f"m{k} g")
            S = link.com or "S"
            self.vector("inertia", f"F_i{k}", f"F_i{k}", il.force[0], "N", f"m{k} a_{S}, against a_{S}")
            if link.I_S:
                self.add("inertia", f"M_i{k}", f"M_i{k}", abs(il.moment[0]), "N m", _sense(il.moment[0]),
                         f"I_S{k} ε{k}, against ε{k}")
            if il.moment[0] and np.isfinite(il.h[0]):
                self.add("inertia", f"h_{k}", f"h{k}", il.h[0], "m", "", f"M_i{k} / F_i{k}")
                self.add("inertia", f"z_{k}", f"z{k}", il.h[0] / self.mu_l, "mm", "", f"h{k} / μ_l")
        for n, ld in enumerate(m.loads):
            mag = load_magnitude(m, res.kin, ld)[0]
            u = "N m" if ld.kind == "moment" else "N"
            self.add("inertia", f"load_{n}", self.L.load(ld.name), abs(mag), u, "",
                     "read from its diagram" if ld.table is not None else "given")

    # ---- reactions
    def reactions(self) -> None:
        res, m = self.res, self.mech
        for g in reversed(m.structure.groups):
            third = special_sides(m, res.kin, g)[2] if g.klass == 3 else None
            split = [(side, *self._split(g, side)) for side in g.sides]
            for (link, _, _, other), e, t, why in split:
                if why:
                    R = res.reaction(other, link)[0]
                    self.add("reactions", f"Rt_{other}_{link}", f"{self.R(other, link)}t", abs(R @ t), "N",
                             _angle(np.sign(R @ t) * t), why)
            for side, e, _, why in split:
                link, other = side[0], side[3]
                if why:
                    R = res.reaction(other, link)[0]
                    self.add("reactions", f"Rn_{other}_{link}", f"{self.R(other, link)}n", abs(R @ e), "N",
                             _angle(np.sign(R @ e) * e), "Σ M_S = 0 of the group" if side == third
                             else "force plan of the group")
            for link, _, _, other in g.sides:
                self.vector("reactions", f"R_{other}_{link}", self.R(other, link), res.reaction(other, link)[0], "N",
                            "force plan of the group")
            if g.klass == 3:
                b = g.links[0]
                for link, _, _, _ in g.sides:
                    self.vector("reactions", f"R_{link}_{b}", self.R(link, b), res.reaction(link, b)[0], "N",
                                f"force plan of link {link}")
            else:
                j, k = g.links
                self.vector("reactions", f"R_{k}_{j}", self.R(k, j), res.reaction(k, j)[0], "N",
                            f"force plan of link {j}")
            for p in dict.fromkeys(g.pairs):
                if p.kind == "P":
                    x = res.reaction_offset(*p.links)[0]
                    self.add("reactions", f"x_{p.links[0]}_{p.links[1]}", "x" + self.R(*p.links)[1:], x, "m", "",
                             f"Σ M_{p.point} = 0 of link {p.links[1]}")

    # ---- crank and lever
    def crank(self) -> None:
        res, m, d, L = self.res, self.mech, self.mech.drive, self.L
        O = res.position(d.pivot)[0]
        for p in m.pairs:
            if d.link in p.links and 0 not in p.links:
                other = p.links[0] if p.links[1] == d.link else p.links[1]
                R = res.reaction(other, d.link)[0]
                X = res.position(p.point)[0]
                self.vector("crank", f"R_{other}_{d.link}", self.R(other, d.link), R, "N",
                            f"= -{self.R(d.link, other)}")
                r = X - O
                arm = abs(r[0] * R[1] - r[1] * R[0]) / np.hypot(*R) / self.mu_l
                self.add("crank", f"h_R{other}{d.link}", f"h_{self.R(other, d.link)}", arm, "mm", "",
                         "arm about the crank axis, on the crank's plan")
        M = res.balancing_moment[0]
        self.add("crank", "M_bal", L.M_bal, M, "N m", _sense(M), "Σ M_O = 0 of the crank (signed about +z)")
        if d.kind == "machine":
            F = res.balancing_force[0]
            self.vector("crank", "F_bal", L.F_bal, F, "N", "F21 h / r_b, at the pitch point on the line of action")
            self.add("crank", "r_b", "r_b", d.gear.r_b, "m", "", "r_w cos α_w")
        R01 = res.reaction(0, d.link)[0]
        self.vector("crank", f"R_0_{d.link}", self.R(0, d.link), R01, "N", "force plan of the crank")
        l1 = math.dist(*(m.links[d.link].points[n] for n in (d.pivot, d.point)))
        ML = res.lever_moment[0]
        F1, M1 = L.lever(L.F_bal), L.lever(L.M_bal)
        self.add("crank", "F_bal_lever", F1, abs(ML) / l1, "N", "",
                 f"at point {d.point}, ⟂ p{d.point.lower()}: Σ M_p = 0 on the lever")
        self.add("crank", "M_bal_lever", M1, ML, "N m", _sense(ML), f"{F1} l_{d.pivot}{d.point}")
        self.add("crank", "delta_pct", "δ", (ML - M) / ML * 100 if ML else math.nan, "%", "",
                 f"({M1} - {L.M_bal}) / {M1} 100 %")


    # ---- friction
    def friction(self, at: float) -> None:
        """The friction terms (a model with [friction]): per pair the friction circle rho = f r and
        the friction moment f r |R|, or the friction angle arctg f and force f |N|, from the
        exact solution with friction in the reactions; M_bal with friction, the first
        approximation's and eta (where it is undefined, why in its note)."""
        m, L = self.mech, self.L
        if m.friction is None:
            return
        ex = self.res
        if ex.friction is None:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", SelfLockingWarning)
                ex = analyze(m, phi_deg=[at], friction="reactions")
        f = m.friction.f
        for p in m.pairs:
            i, j = p.links
            R, q = self.R(i, j), ex.friction.load[0, p.index]
            Rf = R if ex is self.res else f"{R},f"
            if ex is not self.res:         # the sheet's reactions are frictionless: the frictional ones beside them
                self.add("friction", f"Rf_{i}_{j}", f"|{Rf}|", float(np.linalg.norm(ex.forces.R[0, p.index])), "N", "",
                         "the reaction with friction in the reactions")
            if p.kind == "R":
                r = p.radius if p.radius is not None else m.friction.radius
                self.add("friction", f"rho_{i}_{j}", f"ρ{R[1:]}", f * r, "m", "", "f r")
                self.add("friction", f"Mf_{i}_{j}", f"M_f{R[1:]}", abs(q), "N m", _sense(q),
                         f"f r |{Rf}|, against the relative rotation")
            else:
                self.add("friction", f"phi_f_{i}_{j}", f"φ_f{R[1:]}", math.degrees(math.atan(f)), "deg", "", "tan φ_f = f")
                self.add("friction", f"Ff_{i}_{j}", f"F_f{R[1:]}", abs(q), "N", "",
                         f"f |N{R[1:]}|, along the guide, against the sliding")
        first = self.res if ex is not self.res else analyze(m, phi_deg=[at], friction="first")   # the sheet's own, or made
        M0, M1, Mf = ex.balancing_moment_frictionless[0], first.balancing_moment_with_friction[0], ex.balancing_moment[0]
        if ex is self.res:             # the sheet's M_bal is the frictional one: the frictionless one beside it
            self.add("friction", "M_bal_0", f"{L.M_bal},0", M0, "N m", _sense(M0), "frictionless")
        self.add("friction", "M_bal_first", f"{L.M_bal} + P_f/ω1", M1, "N m", _sense(M1), "first approximation")
        self.add("friction", "M_bal_friction", f"{L.M_bal},f", Mf, "N m", _sense(Mf),
                 f"friction in the reactions, {int(ex.friction.passes[0].max())} passes")
        why = ex.efficiency_reason[0]
        self.add("friction", "eta", "η", ex.efficiency[0], "1", "", f"undefined: {why}" if why else
                 f"{L.M_bal} / {L.M_bal},f" if M0 * ex.omega(1)[0] >= 0 else f"{L.M_bal},f / {L.M_bal}")


def _point_of(res: Analysis, k: int, name: str) -> np.ndarray:
    """Velocity (2,) of the point of link k at the current position of point `name`."""
    X = res.position(name)[0]
    O = res.kin.origin[0, k]
    w = res.omega(k)[0]
    r = X - O
    return res.kin.v_origin[0, k] + w * np.array([-r[1], r[0]])


def worksheet(mech: Mechanism, at: float | None = None, *, mu_l: float | None = None, lang: str = "en",
              friction: str = "first") -> Worksheet:
    """The worksheet of `mech` at crank angle `at` (deg; default the model's design position).

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
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SelfLockingWarning)       # the sheet's friction rows state eta
        res = analyze(mech, phi_deg=[float(at)], friction=friction)   # default: the graphical method's, frictionless
    if mu_l is None:
        mu_l = choose_scales(mech, res)["mu_l"].value
    sheet = _Sheet(res, float(mu_l))
    sheet.kinematics()
    sheet.loads()
    sheet.reactions()
    sheet.crank()
    sheet.friction(float(at))
    return Worksheet(lettering(mech).name(lang, mech.name), float(at), float(mu_l), tuple(sheet.rows), lang,
                     float(res.digits[0]))
