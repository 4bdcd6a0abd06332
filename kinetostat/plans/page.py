"""The interactive page of a mechanism (issue 27): one self-contained, offline HTML file with an
angle slider over every plan, the force plans stepped through in the texts' order, a check of a
student's measured lengths, and print at true scale.

    >>> import kinetostat
    >>> from kinetostat.plans.page import page
    >>> html = page(kinetostat.load("ice_crank_slider"), lang="uk")      # doctest: +SKIP

Key mode (default): the sheets of `kinetostat plans` (`draw.svg`, the same lettering and label
placement) at every whole degree and the design position, every scale fixed for the whole cycle
(`cycle_scales`), the plan of positions' 12 positions and paths made once for all of them
(`fixed_positions`), drawn without the sheets' notes (`svg(notes=False)`: the page's tables take
their place); the worksheet's values; "Next step". Student mode (`student=True`): no answer in
the page: the data, the empty tables, an A3 sheet with a millimetre grid at true scale, and the
check of typed lengths.

Small: the sheets of all angles are cut into templates (the markup, a few per plan) and numbers
(`_split`, one regex pass a sheet), each plan's templates stored as a table of their distinct
lines (`_lines`); the numbers of each template slot are stored as second
differences over the angle (the drawing's coordinates at 0.1 mm, each segment's length and each
value to 12 significant digits), as zigzag varints, gzip-compressed and base64-encoded; the
page's script (vanilla JavaScript, the browser's own DecompressionStream) decodes them once and
builds the sheet of the angle chosen.
The page contract (the README): `<input type="range" id="phi">`; every segment's element
`data-plan`, `data-segment`, `data-length-mm` as in segments.csv; every value cell `data-symbol`,
`data-value`.

May use: the plans (`build`, `cycle_scales`, `draw`, `forces`, `worksheet`, `drawing_error`,
`i18n`, `lettering`), the solver, `kinetostat._text` (`script_json`: the data block's JSON),
numpy, the standard library. Never matplotlib, never the harness.
"""
from __future__ import annotations

import base64
import gzip
import hashlib
import json
import math
import multiprocessing
import os
import re
import warnings
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, fields, is_dataclass
from collections.abc import Mapping, Sequence
from functools import cache, partial
from html import escape
from importlib import resources
from pathlib import Path

import numpy as np

from .._io import read_regular, write_bytes, write_text
from .._text import script_json
from .draw import TINY_MM, segment_label, svg, title_of
from .i18n import check_lang, num, text, unit

__all__ = ["page", "write_page", "page_key", "key_of", "code_files", "encode", "PAGE_ANGLES", "TOLERANCE_PCT", "KEY_META"]

#: The angles of the slider, deg (the design position is one more frame).
PAGE_ANGLES = tuple(float(a) for a in range(360))
#: The texts' rule for the two balancing moments (crank and lever), %.
TOLERANCE_PCT = 5.0
#: Resolution of a segment's length in the page, mm (its data-length-mm): 12 significant digits
#: of a 100 mm segment, as segments.csv.
LENGTH_Q = 1e-10
_NUM = re.compile(r"(-?)(\d+)(?:([.,])(\d+))?")
#: The attributes that place a drawing's elements (mm), and their decimals in the page.
COORDINATES = frozenset({"x", "y", "x1", "y1", "x2", "y2", "cx", "cy", "dx", "dy", "points", "d"})
COORD_DECIMALS = 1
#: A tag, or (between tags) a number: `_NUM`'s groups after the tag's.
_PIECE = re.compile(r"(<[^>]*>)|" + _NUM.pattern)
_COORD_FORMAT = f"\x00.{COORD_DECIMALS}\x00"
_ATTR = re.compile(r'([\w:-]+)="([^"]*)"')

# ============================================================================ the numbers, small

@dataclass(frozen=True)
class Encoded:
    """Sheets cut into templates and numbers (`encode`): `templates[t]` alternates literal text and
    a number's format ("" integer, ".2" two decimals after a point, ",1" after a comma, "L" a
    length at LENGTH_Q); `keys[t]` the series of each of its slots (`_slot_keys`), as differences
    from the slot before (the first from -1); `frames[f]` the template of each frame (-1: none);
    `data` the numbers, series by series, each the second differences over the frames it is in."""
    templates: tuple[tuple[str, ...], ...]
    keys: tuple[tuple[int, ...], ...]
    frames: tuple[int, ...]
    data: bytes


_IDENT = re.compile(r'data-(?:segment|path)="([^"]*)"')


def _slot_keys(template: tuple[str, ...]) -> list[tuple]:
    """What each number of a template is, the same in every template that has it: the element it
    is in (its data-segment or data-path; a label's text; else "after" the last element that had
    one), the element's text up to the number, and how many slots before had that key. A label
    or an arrowhead that comes or goes between angles then shifts no other series."""
    s = "\x00".join(template[0::2])
    out, seen, last = [], {}, ""
    for m in re.finditer("\x00", s):
        p = m.start()
        a, b = s.rfind("<", 0, p), s.find(">", p)
        tag = s[a:b]
        ident = _IDENT.search(tag)
        if ident:
            who = last = ident.group(1)
        elif tag.startswith("<text"):
            who = last = "text:" + re.sub(r"<[^>]*>|\x00", "", s[b + 1:s.find("</text>", b)])
        else:
            who = ("after", last)
        key = (who, s[a:p])
        seen[key] = seen.get(key, -1) + 1
        out.append((*key, seen[key]))
    return out


def _split(sheet: str) -> tuple[tuple[str, ...], list[int]]:
    """A sheet as (template, numbers): data-length-mm as integers of LENGTH_Q; a drawing's
    coordinates (COORDINATES' attributes) rounded to COORD_DECIMALS (0.1 mm: finer than a ruler
    reads); every other number (a stroke's width, a font's size, a number in a text) as written;
    a zero-padded number ("000" of a colour) kept as text. One pass of `re.sub` over the sheet,
    each number replaced by its format between two NULs (which XML cannot hold), then split there."""
    nums: list[int] = []
    push = nums.append

    def as_written(m: re.Match) -> str:                  # of `_NUM` or of `_PIECE`
        sign, whole, sep, frac = m.groups()[-4:]
        if len(whole) > 1 and whole[0] == "0":
            return m[0]
        if frac:
            n = int(whole + frac)
            push(-n if sign else n)
            return f"\x00{sep}{len(frac)}\x00"
        push(-int(whole) if sign else int(whole))
        return "\x00\x00"

    def coordinate(m: re.Match) -> str:
        sign, whole, sep, frac = m.groups()
        if not frac or len(frac) <= COORD_DECIMALS or sep != ".":     # "217,69": two integers of a list
            return as_written(m)
        if len(whole) > 1 and whole[0] == "0":
            return m[0]
        cut = 10 ** (len(frac) - COORD_DECIMALS)
        n = (int(whole + frac) + cut // 2) // cut
        push(-n if sign else n)
        return _COORD_FORMAT

    def attribute(m: re.Match) -> str:
        name, value = m.groups()
        if name == "data-length-mm":
            push(round(float(value) / LENGTH_Q))
            return 'data-length-mm="\x00L\x00"'
        return f'{name}="{_NUM.sub(coordinate if name in COORDINATES else as_written, value)}"'

    def piece(m: re.Match) -> str:                       # a tag: its attributes; else a number in a text
        return _ATTR.sub(attribute, m[0]) if m[1] else as_written(m)

    return tuple(_PIECE.sub(piece, sheet).split("\x00")), nums


def _varints(values: np.ndarray) -> bytes:
    """Zigzag LEB128 varints of int64 values (|v| < 2^53)."""
    z = np.where(values >= 0, 2 * values, -2 * values - 1).astype(np.uint64)
    out = bytearray()
    for v in z.tolist():
        while v >= 128:
            out.append((v & 127) | 128)
            v >>= 7
        out.append(v)
    return bytes(out)


def _second_differences(a: np.ndarray) -> np.ndarray:
    """Second differences of int64 rows along axis 0 (the first row as it is, the second as its
    first difference): a smooth function of the angle becomes a few small numbers."""
    d = a.copy()
    d[1:] -= a[:-1]
    d[2:] -= a[1:-1] - a[:-2]
    return d


def encode(sheets: list[str | None]) -> Encoded:
    """Sheets of one plan at successive angles (None: not drawn there) as templates and, template
    by template, slot by slot, the second differences of the slot's numbers over the frames that
    use that template."""
    return _encode_split([None if s is None else _split(s) for s in sheets])


def _encode_split(split: list[tuple[tuple[str, ...], list[int]] | None]) -> Encoded:
    """`encode` of sheets already `_split`."""
    templates: dict[tuple[str, ...], int] = {}
    keys: dict[tuple, int] = {}
    slots: list[list[int]] = []
    frames: list[int] = []
    series: dict[int, list[int]] = {}
    for one in split:
        if one is None:
            frames.append(-1)
            continue
        t, nums = one
        tid = templates.get(t)
        if tid is None:
            tid = templates[t] = len(templates)
            slots.append([keys.setdefault(k, len(keys)) for k in _slot_keys(t)])
        frames.append(tid)
        for k, v in zip(slots[tid], nums):
            series.setdefault(k, []).append(v)
    data = b"".join(_varints(_second_differences(np.array(series[k], dtype=np.int64))) for k in range(len(keys)))
    deltas = tuple(tuple(np.diff([-1, *ks]).tolist()) for ks in slots)
    return Encoded(tuple(templates), deltas, tuple(frames), data)


def _columns(values: np.ndarray) -> tuple[list[int], bytes]:
    """Columns of values over frames (NaN: none): each column's exponent e (12 significant digits
    of its largest |value|), and column by column the NaN mask (1: none), then column by column the
    second differences over the frames of round(v / 10^e) (NaN as 0)."""
    exps = []
    for col in values.T:
        top = np.nanmax(np.abs(col)) if np.isfinite(col).any() else 0.0
        exps.append(int(math.floor(math.log10(top))) - 11 if top > 0 else 0)
    scaled = np.where(np.isfinite(values), values, 0.0) / 10.0 ** np.array(exps, dtype=float)
    d = _second_differences(np.rint(scaled).astype(np.int64))
    mask = (~np.isfinite(values)).astype(np.int64)
    return exps, _varints(np.concatenate([mask.T.ravel(), d.T.ravel()]))


def _lines(templates: tuple[tuple[str, ...], ...]) -> tuple[list[str], list[list[int]]]:
    """Templates as one table of their distinct lines and each template as its lines' indices (a
    template joined by NUL, split at newlines; the page's script joins and splits back): the
    templates of one plan differ by a few lines (a leader, a label, a vector drawn or not), and
    gzip's 32 kB window would not reach the template before a large one."""
    table: dict[str, int] = {}
    rows = [[table.setdefault(line, len(table)) for line in "\0".join(t).split("\n")] for t in templates]
    return list(table), rows


def _b64gz(data: bytes) -> str:
    return base64.b64encode(gzip.compress(data, 9, mtime=0)).decode("ascii")


# ============================================================================ what the page holds

def _sheets_of(plans, lang: str, name: str) -> dict[str, str]:
    """The page's sheets of one angle: `draw.svg` with the contract, without the notes (the page's
    tables hold them) and the XML declaration."""
    return {kind: svg(p, lang=lang, mechanism=name, contract=True, notes=False).split("?>", 1)[-1].lstrip()
            for kind, p in plans.items()}


def _moment(plan, M: str, names, couples=(), unknown: str | None = None) -> dict:
    """A moment equation about point M of `plan` as the page's script writes it at each angle
    (page.js `momentText`): the unknown [segment, arm, M at the arm's end?] (R^τ with its link, the
    lever's F'_bal with p-a), each force drawn with its arm h_.. about M ([force, arm, False]), each
    couple's arc (M_i/μ_l); the script takes the signs and the arms (mm) from the sheet drawn."""
    from .forces import arm_name
    segs = {s.name: s for s in plan.segments}
    terms = [[n, arm_name(n), False] for n in names if n in segs and arm_name(n) in segs]
    out = {"terms": terms, "couples": [c for c in couples if c in plan.paths]}
    if unknown is not None:
        X = plan.points[segs[unknown].start]              # where the unknown acts: the arm is M to there
        arm = next((x for x in plan.segments if x.kind in ("link", "vector") and x.name != unknown and M in (x.start, x.end)
                    and abs(plan.points[x.end if x.start == M else x.start] - X) < 1e-6), None)
        if arm is not None:
            out["unknown"] = [unknown, arm.name, arm.end == M]
    return out


def _plans_at(mech, positions, fixed, a: float):
    """The plans at `a` deg at the page's scales, the plan of positions on its 12 positions and
    paths made once (`fixed_positions`); None at a singular position."""
    from . import build
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            return build(mech, at=a, fixed=fixed, positions=positions)
        except ValueError:                     # a singular position
            return None


def _frame(mech, positions, fixed, lang: str, name: str, a: float) -> tuple[dict, dict | None, list | None]:
    """One frame of the slider: each plan's sheet `_split` (kind -> (template, numbers)), the
    worksheet's values (key -> value) and its records; ({}, None, None) at a singular position."""
    from .worksheet import worksheet
    plans = _plans_at(mech, positions, fixed, a)
    if plans is None:
        return {}, None, None
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ws = worksheet(mech, a, mu_l=fixed.base["mu_l"].value, lang=lang)
    return ({k: _split(v) for k, v in _sheets_of(plans, lang, name).items()},
            {r.key: r.value for r in ws.rows}, ws.records())


#: Frames per page below which they are drawn in this process (a test's few angles).
PARALLEL_FROM = 24


_WORK = None                   # the function a forked worker applies (`_map`): inherited, not pickled


def _work(item):
    return _WORK(item)


def _map(fn, items: list) -> list:
    """`fn` over `items` in order, on every core this process may use (forked workers, which
    inherit `fn` and what it holds: a mechanism is not picklable) when there are PARALLEL_FROM
    items or more, else here."""
    global _WORK
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1)
    if cores < 2 or len(items) < PARALLEL_FROM or "fork" not in multiprocessing.get_all_start_methods():
        return list(map(fn, items))
    _WORK, n = fn, min(cores, 8)
    try:
        with ProcessPoolExecutor(n, mp_context=multiprocessing.get_context("fork")) as ex:
            return list(ex.map(_work, items, chunksize=max(1, len(items) // (4 * n))))
    finally:
        _WORK = None


def _steps(mech, plans, lang: str) -> list[dict]:
    """The force analysis in the texts' order, one vector a step: per Assur group from the last
    attached, the unknowns found from moment equations (a dyad's R^τ from ΣM about the inner
    joint, its terms R^τ·l + Σ±F·h ± M_i/μ_l = 0; a triad's R^τ of each leash about its inner pin,
    then R^n of the leash whose axis is off Assur's point S from the group's moment about S), the
    polygon's sides in the order drawn, the inner reactions; then the initial link's loads and M_bal (M_bal + μ_l Σ±F·h =
    0); then the lever's loads and F'_bal·pa + Σ±F·h = 0. A step with "moment" has its equation's
    terms written by the page's script from the sheet of the angle shown."""
    from ..solve import analyze
    from .forces import _carried, _group_label, _later, _moment_equations, link_couples, link_loads, reaction_name
    from ..model.lettering import lettering
    L = lettering(mech)
    any_plan = next(iter(plans.values()))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = analyze(mech, phi_deg=[any_plan.phi_deg])
    out = []
    for g in reversed(mech.structure.groups):
        label = _group_label(g)
        forces, group = plans.get(f"forces:{label}"), plans.get(f"group:{label}")
        if forces is None:
            continue
        drawn = {s.name for s in group.segments} if group is not None else set()
        later = _later(mech, g)
        loads = {x: [ld.name for ld in link_loads(mech, res, x) + _carried(mech, res, x, later)] for x in g.links}
        couples = {x: [c.name for c in link_couples(mech, res, x)] for x in g.links}
        if g.klass == 3:
            moments = [(f"{reaction_name(mech, known, ell)}t", inner.point, str(ell), (ell,))
                       for ell, _, inner, known in g.sides]
            ell, _, _, known = g.sides[2]
            S = "S" if "S" not in mech.point_names else "S*"
            R3 = reaction_name(mech, known, ell)
            moments.append((f"{R3}n" if f"{R3}n" in drawn else R3, S, label, ()))
            inners = [(reaction_name(mech, g.links[0], ell), ell) for ell, _, _, _ in g.sides]
        else:
            taus = [n for n in forces.equation if n.startswith("R") and n.endswith("t")]
            moments = [(R, point, ",".join(map(str, links)), links)
                       for (links, point), R in zip(_moment_equations(g), taus)]
            j, k = g.links
            inners = [(reaction_name(mech, k, j), j)]
        for R, point, links, on in moments:
            if R in drawn:
                key = "page.tau" if on else "page.tau_S"             # a link's moment; the triad's about S
                step = {"plan": f"group:{label}", "segment": R, "eq": text(key, lang, R=R, P=point, k=links)}
                if on and R.endswith("t"):
                    step["moment"] = _moment(group, point, [n for x in on for n in loads[x]],
                                             [c for x in on for c in couples[x]], unknown=R)
                out.append(step)
        m = len(forces.equation)
        for n, name in enumerate(forces.equation):
            out.append({"plan": f"forces:{label}", "segment": name,
                        "eq": text("page.side", lang, sum=" + ".join(forces.equation[:n + 1]) + (" = 0" if n + 1 == m else " + …"),
                                  n=n + 1, m=m)})
        for inner, k in inners:
            out.append({"plan": f"forces:{label}", "segment": inner, "eq": text("page.inner", lang, R=inner, k=k)})
    crank = plans.get("crank")
    if crank is not None:
        vectors = [s.name for s in crank.segments if s.kind == "vector"]
        for name in vectors:
            out.append({"plan": "crank", "segment": name, "eq": text("page.crank", lang, F=name)})
        where = {"path": L.M_bal} if L.M_bal in crank.paths else {"segment": "r_b"}     # an engine's couple; a gear's arm
        out.append({"plan": "crank", **where, "eq": text("page.M_crank", lang, M=L.M_bal, O=mech.drive.pivot),
                    "moment": {**_moment(crank, mech.drive.pivot, vectors), "M": L.M_bal}})
    lever = plans.get("lever")
    if lever is not None:
        vectors = [s.name for s in lever.segments if s.kind == "vector" and s.scale is not None and s.name != L.lever(L.F_bal)]
        for name in vectors:
            out.append({"plan": "lever", "segment": name, "eq": text("page.lever", lang, F=name)})
        out.append({"plan": "lever", "segment": L.lever(L.F_bal), "eq": text("page.M_lever", lang, M=L.M_bal, tol=num(TOLERANCE_PCT, lang)),
                    "moment": _moment(lever, "p", vectors, unknown=L.lever(L.F_bal))})
    return out


def _bands(mech, plans, fixed, at: float) -> tuple[dict[tuple[str, str], tuple[float, float]], dict[str, tuple[float, float]]]:
    """The bands a careful drawing lands in (5-95 % of `drawing_error.simulate` at the page's
    scales): (1) of each segment (mm) whose value is a value of the worksheet (matched by value and
    unit: the study reads the worksheet's values), that value's band at the segment's scale; (2) of
    the two balancing moments, signed (N m): "M_bal" from the force plans, "M_bal_lever" from the
    lever. None where the study does not draw the mechanism's groups (PRP, RPP, triads)."""
    from .drawing_error import Scales, simulate
    from .pack import BAND, BAND_DRAWS
    sc = fixed.base
    mu_F = next((s.value for k, s in fixed.plan.items() if k.startswith("forces:")), sc["mu_F"].value)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            drawn = simulate(mech, at=at, n=BAND_DRAWS, seed=0,
                             scales=Scales(sc["mu_l"].value, sc["mu_v"].value, sc["mu_a"].value, mu_F))
        except NotImplementedError:            # a group kind the study does not draw: no bands
            return {}, {}
    by_value = []
    for key, samples in drawn.samples.items():
        lo, hi = np.percentile(np.abs(samples), BAND)
        by_value.append((abs(drawn.exact[key]), drawn.units.get(key, ""), float(lo), float(hi)))
    out = {}
    for kind, plan in plans.items():
        for s in plan.segments:
            if s.kind != "vector" or not math.isfinite(s.value) or s.value == 0:
                continue
            scale = (s.scale or plan.scale).value
            for v, u, lo, hi in by_value:
                if u == s.unit and math.isclose(v, abs(s.value), rel_tol=1e-9):
                    out[(kind, s.name)] = (lo / scale, hi / scale)
                    break
    moments = {k: tuple(float(x) for x in np.percentile(drawn.samples[k], BAND))
               for k in ("M_bal", "M_bal_lever") if k in drawn.samples}
    return out, moments


def _data_rows(mech, res, lang: str) -> list[tuple[str, str, str]]:
    """The data a student starts from: ω1, ε1, g, each moving link's lengths, mass and moment of
    inertia, the applied forces at this angle (symbol, value, unit)."""
    from .forces import _applied
    d = mech.drive
    rows = [("φ", num(float(res.phi_deg[0]), lang, 6), "°"), ("ω1", num(abs(d.omega), lang, 6), unit("rad/s", lang)),
            ("ε1", num(d.eps, lang, 6), unit("rad/s^2", lang)), ("g", num(mech.g, lang, 6), unit("m/s^2", lang))]
    for k, link in enumerate(mech.links):
        if k == 0:
            continue
        names = list(link.points)
        for a, b in zip(names, names[1:]):
            rows.append((f"l_{a}{b}", num(math.dist(link.points[a], link.points[b]), lang, 6), unit("m", lang)))
        if link.mass:
            rows.append((f"m{k}", num(link.mass, lang, 6), unit("kg", lang)))
        if link.I_S:
            rows.append((f"I_S{k}", num(link.I_S, lang, 6), unit("kg m^2", lang)))
        for ld in _applied(mech, res, k):
            rows.append((ld.name, num(abs(ld.force[0]), lang, 6), unit("N", lang)))
    return rows


# ============================================================================ the page

def page(mech, lang: str = "en", student: bool = False, at: float | None = None,
         angles: Sequence[float] | None = None, fixed=None) -> str:
    """The interactive page of `mech` in `lang` (module docstring). `at`: the angle of the check
    (and of a student's page; default the design position); `angles`: the slider's frames (deg;
    default PAGE_ANGLES);
    `fixed`: the plans' scales (default `cycle_scales(mech)`)."""
    from ..solve import analyze
    from . import cycle_scales, fixed_positions
    from ..model.lettering import lettering
    check_lang(lang)
    key = page_key(mech, lang, student, at, angles, fixed)
    design = float(getattr(mech.drive, "design_deg", 30.0))
    at = design if at is None else float(at)
    fixed = fixed or cycle_scales(mech)
    positions = fixed_positions(mech, fixed.base["mu_l"])
    name = lettering(mech).name(lang, mech.name)
    frames = [at] if student else [*map(float, PAGE_ANGLES if angles is None else angles), design]

    plans_at = partial(_plans_at, mech, positions, fixed)
    check = plans_at(at)
    if check is None:
        raise ValueError(f"at: {at:g} deg is a singular position: no plans to check there")
    bands, moment_bands = _bands(mech, check, fixed, at)
    data: dict = {"lang": lang, "student": student, "design": design, "at": at, "frames": frames,
                  "tol": TOLERANCE_PCT, "ui": {k: text(f"page.{k}", lang) for k in ("in_band", "out_band", "singular", "a4_cut", "sense", "both")}
                  | {"negligible": text("page.negligible", lang, tiny=num(TINY_MM, lang))}, "tiny": TINY_MM,
                  "rule_ok": text("page.rule_ok", lang, tol=num(TOLERANCE_PCT, lang)),
                  "rule_bad": text("page.rule_bad", lang, tol=num(TOLERANCE_PCT, lang)),
                  "decimal": "." if lang == "en" else ",", "scalebar": scale_bar(lang), "mm": unit("mm", lang)}
    blobs: dict[str, str] = {}
    if not student:
        per_kind: dict[str, list] = {k: [] for k in check}
        values, rows = [], None
        for split, got, records in _map(partial(_frame, mech, positions, fixed, lang, name), frames):
            for kind in per_kind:
                per_kind[kind].append(split.get(kind))
            if got is not None:
                rows = rows or records
                values.append([got.get(r["key"], math.nan) for r in rows])
            else:
                values.append(None)
        width = len(rows)
        table = np.array([v if v is not None else [math.nan] * width for v in values], dtype=float)
        exps, vbytes = _columns(table)
        kinds = []
        for kind, sheets in per_kind.items():
            enc = _encode_split(sheets)
            lines, templates = _lines(enc.templates)
            kinds.append({"kind": kind, "lines": lines, "templates": templates, "keys": enc.keys, "frames": enc.frames})
            blobs[f"k{len(kinds) - 1}"] = _b64gz(enc.data)
        blobs["values"] = _b64gz(vbytes)
        data.update(kinds=kinds, rows=[{"key": r["key"], "symbol": r["symbol"], "shown": _symbol(r["symbol"], lang), "unit": r["unit"],
                                        "section": r["section"]} for r in rows], exps=exps,
                    steps=_steps(mech, check, lang))
        blobs["meta"] = _b64gz(json.dumps({"kinds": data.pop("kinds"), "steps": data.pop("steps")},
                                          ensure_ascii=False).encode())
    items = []
    for kind, plan in check.items():
        for s in plan.segments:
            if s.kind in ("position", "line") or not math.isfinite(plan.length_mm(s.name)):
                continue
            lo_hi = bands.get((kind, s.name))
            items.append({"plan": kind, "segment": s.name, "title": title_of(plan, lang).split(",")[0],
                          "label": segment_label(s, lang), "exact": plan.length_mm(s.name),
                          "band": list(lo_hi) if lo_hi else None})
    results = list({r.symbol: (r.symbol, r.value) for kind in ("lever", "crank") if kind in check
                    for r in check[kind].results if r.unit == "N m"}.values())[::-1]    # M_bal (crank), M'_bal
    results = [(sym, v, moment_bands.get(key)) for (sym, v), key in zip(results, ("M_bal", "M_bal_lever"))]
    blobs["check"] = base64.b64encode(_obscure(gzip.compress(json.dumps({"items": items, "M": results}).encode(),
                                                             9, mtime=0))).decode("ascii")
    res = analyze(mech, phi_deg=[at])
    blank = _blank_tables(mech, at, fixed, lang) if student else ""
    return _sealed(_html(mech, name, lang, student, data, blobs, fixed, _data_rows(mech, res, lang), items, results, blank, key))


def _blank_tables(mech, at: float, fixed, lang: str) -> str:
    """The worksheet's tables with their values and senses left blank, section by section
    (velocities, accelerations, reactions, M_bal), as the teacher's pack has them (`pack`)."""
    from .worksheet import worksheet
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ws = worksheet(mech, at, mu_l=fixed.base["mu_l"].value, lang=lang)
    recs = ws.records()
    head = "".join(f"<th>{escape(text(f'ws.head.{k}', lang))}</th>" for k in ("symbol", "value", "unit", "direction"))
    out = [f'<section id="worksheet"><h2>{escape(text("pack.fill", lang))}</h2>']
    for section in dict.fromkeys(r["section"] for r in recs):
        rows = "".join(f'<tr><td>{escape(_symbol(r["symbol"], lang))}</td><td class="blank"></td>'
                       f'<td>{escape(r["unit"])}</td><td class="blank"></td></tr>' for r in recs if r["section"] == section)
        out.append(f'<h3>{escape(section)}</h3><table class="fill"><tr>{head}</tr>{rows}</table>')
    return "".join(out) + "</section>"


def _symbol(symbol: str, lang: str) -> str:
    """A worksheet's symbol as the page shows it in `lang` (a^Cor -> a^к); its data-symbol stays."""
    return symbol.replace("^Cor", "^" + text("coriolis", lang))


def _obscure(data: bytes) -> bytes:
    """`data` XORed with the xorshift32 keystream of seed 27 (the page's script undoes it): the
    check's answers, which a page that works offline must hold, kept from a glance at the file
    (not from a determined reader)."""
    out, x = bytearray(len(data)), 27
    for i, b in enumerate(data):
        x ^= (x << 13) & 0xFFFFFFFF
        x ^= x >> 17
        x ^= (x << 5) & 0xFFFFFFFF
        out[i] = b ^ (x & 255)
    return bytes(out)


def _html(mech, name: str, lang: str, student: bool, data: dict, blobs: dict[str, str], fixed,
          data_rows, items, results, blank: str = "", key: str | None = None) -> str:
    from .draw import scale_text
    title = f"{name}: {text('page.student' if student else 'page.key', lang)}"
    scales = "; ".join([scale_text(s, lang) for s in fixed.base.values()]
                       + [f"{_plan_name(k, lang)}: {scale_text(s, lang)}" for k, s in fixed.plan.items()
                          if s != fixed.base[s.symbol]]
                       + [f"{_plan_name(k, lang)} (F): {scale_text(s, lang)}" for k, s in fixed.forces_on.items()])
    head = "".join(f"<th>{escape(h)}</th>" for h in ("", "", ""))
    data_table = "".join(f'<tr><td>{escape(s)}</td><td class="num">{escape(v)}</td><td>{escape(u)}</td></tr>'
                         for s, v, u in data_rows)
    check_rows = []
    for n, it in enumerate(items):
        check_rows.append(f'<tr data-item="{n}"><td>{escape(it["title"])}</td><td>{escape(it["label"])}</td>'
                          f'<td><input type="text" inputmode="decimal" class="measured" data-plan="{escape(it["plan"])}" '
                          f'data-segment="{escape(it["segment"])}" size="7"></td>'
                          f'<td class="exact num"></td><td class="band num"></td><td class="verdict"></td></tr>')
    for n, (symbol, _, _) in enumerate(results):
        check_rows.append(f'<tr data-moment="{n}"><td></td><td>{escape(symbol)}, {escape(unit("N m", lang))}</td>'
                          f'<td><input type="text" inputmode="decimal" class="moment" data-symbol="{escape(symbol)}" '
                          f'size="7"></td><td class="exact num"></td><td class="band num"></td><td class="verdict"></td></tr>')
    if len(results) == 2:
        check_rows.append(f'<tr id="delta"><td></td><td>δ = ({escape(results[1][0])} − {escape(results[0][0])}) / '
                          f'{escape(results[1][0])} · 100 %</td><td></td><td></td><td class="num">|δ| ≤ '
                          f'{num(TOLERANCE_PCT, lang)} %</td><td class="verdict"></td></tr>')
    phi = num(data["at"], lang, 6)
    check = (f'<section id="check"><h2>{escape(text("page.check", lang))}</h2><p>{escape(text("page.check_note", lang, phi=phi, tol=num(TOLERANCE_PCT, lang)))}</p>'
             f'<table><tr>' + "".join(f"<th>{escape(text('page.' + k, lang))}</th>" for k in ("plan", "segment", "measured", "exact", "band", "verdict"))
             + "</tr>" + "".join(check_rows) + "</table></section>")
    if student:
        body = (f'<section id="data"><h2>{escape(text("page.data", lang))}</h2><p>{escape(text("page.scales", lang))}: {escape(scales)}</p>'
                f'<table><tr>{head}</tr>{data_table}</table></section>'
                + blank
                + f'<section id="grid"><h2>{escape(text("page.sheet", lang))}</h2><div class="sheet">{_grid_sheet(name, title.removeprefix(name + ": "), lang)}</div></section>'
                + check)
    else:
        body = (f'<section id="controls"><label for="phi">{escape(text("page.phi", lang))}: <output id="phi-value"></output>°</label> '
                f'<input type="range" id="phi" min="0" max="359" step="1" value="0"> '
                f'<button id="design" type="button">{escape(text("page.design", lang))} ({num(data["design"], lang, 6)}°)</button> '
                f'<button id="prev" type="button">{escape(text("page.prev", lang))}</button> '
                f'<button id="next" type="button">{escape(text("page.next", lang))}</button> '
                f'<output id="step"></output> <label>{escape(text("page.paper", lang))}: <select id="paper"><option>A3</option>'
                f'<option>A4</option></select></label><p id="equation"></p><p class="hint">{escape(text("page.print", lang))}</p>'
                f'<p>{escape(text("page.scales", lang))}: {escape(scales)}</p></section>'
                f'<section id="sheets"><p id="status">{escape(text("page.loading", lang))}</p></section>'
                f'<section id="values"><h2>{escape(text("page.values", lang))}</h2><table id="value-table"></table></section>'
                f'<section id="data"><h2>{escape(text("page.data", lang))}</h2><table>{data_table}</table></section>'
                + check)
    script = resources.files("kinetostat.plans").joinpath("page.js").read_text(encoding="utf-8")
    payload = script_json(data)                 # no name in it (`</script>`, `<!--<script>`) ends its element
    blob_tags = "".join(f'<script type="application/octet-stream" id="blob-{k}">{v}</script>' for k, v in blobs.items())
    return (f'<!DOCTYPE html>\n<html lang="{lang}"><head><meta charset="utf-8">'
            + (f'<meta name="{KEY_META}" content="{key}">' if key else "") +
            f'<meta http-equiv="Content-Security-Policy" content="default-src \'none\'; style-src \'unsafe-inline\'; '
            f'script-src \'unsafe-inline\'; img-src data:">'
            f'<title>{escape(title)}</title><style>{_CSS}</style><style id="page-size">@page{{size:A3 landscape;margin:0}}</style>'
            f'</head><body>'
            f'<h1>{escape(title)}</h1>{body}{blob_tags}'
            f'<script id="page-data" type="application/json">{payload}</script><script>{script}</script></body></html>\n')


def _plan_name(kind: str, lang: str) -> str:
    """A plan kind as its sheet's title names it, without the angle (group:2,3 -> Plan of group 2-3)."""
    base, _, rest = kind.partition(":")
    return text(f"plan.{base}", lang) + (" " + rest.replace(",", "-") if rest else "")


def _grid_sheet(name: str, what: str, lang: str) -> str:
    """An empty A3 sheet at true scale: frame, a millimetre grid (1, 5 and 10 mm lines), the title
    block (the mechanism's `name` and `what` the page is, each on a line of its own, in a size that
    fits the block's 179 mm) and the 100 mm scale bar."""
    from .labels import text_width
    fit = lambda s, size: f"{max(1.8, min(size, size * 179.0 / max(text_width(s, size), 1e-9))):.2f}"
    title = (f'<text x="233" y="256" font-size="{fit(name, 4.0)}">{escape(name)}</text>'
             f'<text x="233" y="264" font-size="{fit(what, 3.5)}">{escape(what)}</text>')
    return ('<svg xmlns="http://www.w3.org/2000/svg" width="420mm" height="297mm" viewBox="0 0 420 297" '
            'font-family="DejaVu Sans, Arial, sans-serif"><defs>'
            '<pattern id="mm" width="10" height="10" patternUnits="userSpaceOnUse">'
            '<path d="M1 0V10M2 0V10M3 0V10M4 0V10M6 0V10M7 0V10M8 0V10M9 0V10M0 1H10M0 2H10M0 3H10M0 4H10M0 6H10M0 7H10M0 8H10M0 9H10" '
            'stroke="#e9b8a8" stroke-width="0.05"/><path d="M5 0V10M0 5H10" stroke="#d99580" stroke-width="0.1"/>'
            '<path d="M0 0V10M0 0H10" stroke="#c0603f" stroke-width="0.2"/></pattern></defs>'
            '<rect width="420" height="297" fill="#fff"/>'
            '<rect x="20" y="5" width="395" height="287" fill="url(#mm)" stroke="#000" stroke-width="0.7"/>'
            '<rect x="230" y="247" width="185" height="45" fill="#fff" stroke="#000" stroke-width="0.5"/>'
            f'{title}{scale_bar(lang)}</svg>')


def scale_bar(lang: str) -> str:
    """A 100 mm scale bar in the sheet's binding margin (x 16 mm, y 40-140 mm, 1 unit = 1 mm), ticks
    every 10 mm, lettered 0, 50 and 100 at its ticks: printed at true scale it measures 100 mm."""
    ticks = "".join(f"M{16 - (2 if k % 5 == 0 else 1)} {40 + 10 * k}H16" for k in range(11))
    labels = "".join(f'<text x="13" y="{40 + 10 * k + 0.9}" font-size="2.5" text-anchor="end">{10 * k}</text>'
                     for k in (0, 5, 10))
    return (f'<g id="scalebar"><path d="M16 40V140{ticks}" stroke="#000" stroke-width="0.3" fill="none"/>{labels}'
            f'<text x="13" y="145" font-size="2.5" text-anchor="end">{escape(unit("mm", lang))}</text></g>')


_CSS = """
body{font-family:"DejaVu Sans",Arial,sans-serif;margin:1em;color:#111}
h1{font-size:1.3em}h2{font-size:1.1em}
table{border-collapse:collapse;margin:.5em 0}td,th{border:1px solid #bbb;padding:2px 6px;font-size:.9em}
td.num{text-align:right;font-variant-numeric:tabular-nums}
table.fill td.blank{min-width:9em;height:1.6em}h3{font-size:1em;margin:.6em 0 .2em}
#controls{position:sticky;top:0;background:#fff;padding:.4em 0;border-bottom:1px solid #ccc;z-index:2}
#phi{width:40em;max-width:90vw;vertical-align:middle}
#equation{font-size:1.05em;min-height:1.3em;margin:.3em 0}.hint{color:#555;font-size:.85em;margin:.2em 0}
#sheets{display:grid;grid-template-columns:repeat(auto-fill,minmax(620px,1fr));gap:.6em}
.sheet{border:1px solid #ddd}.sheet svg{display:block;width:100%;height:auto;max-width:1260px}
@media screen{.hl{stroke:#d01c1c !important;stroke-width:1.2 !important}}
.sheet[data-a4]::before{content:attr(data-a4);color:#b01515}
.verdict.ok{color:#176317}.verdict.bad{color:#b01515}
@media print{
  body{margin:0}h1,h2,#controls,#values,#data,#check,.hint,#status{display:none}
  #sheets{display:block}.sheet{border:0;margin:0;page-break-after:always;break-after:page}
  .sheet svg{width:420mm;height:297mm;max-width:none}
  [data-paper="A4"] .sheet svg{width:297mm;height:210mm}.sheet::before{display:none}
}
"""


def write_page(mech, out: str | Path, lang: str = "en", student: bool = False, at: float | None = None,
               reuse: str | Path | None = None) -> Path:
    """The page of `mech` (`page`) written to `out` atomically; returns its path. `reuse`: an
    earlier page (e.g. the one `out` replaces); where it is whole and its key (`key_of`) equals
    this page's (`page_key`), its bytes are written instead of drawing the page again."""
    path = Path(out)
    key = page_key(mech, lang, student, at)
    earlier = _earlier_page(reuse) if key is not None and reuse is not None else None
    if earlier is not None and _key_in(earlier) == key:
        write_bytes(path, earlier)
    else:
        write_text(path, page(mech, lang=lang, student=student, at=at))
    return path


# ============================================================================ what a page is drawn from

#: The name of the meta element that holds a page's key (`page_key`).
KEY_META = "kinetostat-page"
_KEY = re.compile(rb'<meta name="' + KEY_META.encode() + rb'" content="([0-9a-f]{64})">')
#: A page's last line: the SHA-256 of every byte before it (`_sealed`, `key_of`).
_SEAL = re.compile(rb"<!-- kinetostat-page-sha256 ([0-9a-f]{64}) -->\n\Z")


def page_key(mech, lang: str = "en", student: bool = False, at: float | None = None,
             angles: Sequence[float] | None = None, fixed=None) -> str | None:
    """What the page `page(mech, lang, student, at, angles, fixed)` is drawn from, as a SHA-256
    hex digest: every field of the mechanism but where its file lies (its `path`, and that path
    wherever a text holds it, as a drive's `source` does), the arguments, and
    the code that draws it (`code_files`). Equal keys: the same page. The libraries' versions are
    left out by choice, so that a checkout's committed pages stay current on another machine: a
    page drawn with other versions of numpy or Python is kept. None where the mechanism holds
    something other than numbers, text, arrays and containers of them (no key: never reused)."""
    h = hashlib.sha256(_code_digest())
    try:
        _feed(h, (lang, student, at, tuple(map(float, PAGE_ANGLES if angles is None else angles)), fixed))
        _feed(h, mech, skip=("path", "structure", "_derived"), where=mech.path)
    except TypeError:
        return None
    return h.hexdigest()


#: Largest earlier page read (`key_of`, `write_page(reuse=)`), bytes: the bundled models' pages
#: are below 1 MB; a larger file is not read, and the page is drawn again.
MAX_PAGE_BYTES = 64 * 2**20


def _earlier_page(path: str | Path) -> bytes | None:
    """The bytes of the earlier page at `path`: a regular file of at most MAX_PAGE_BYTES
    (`read_regular`: a FIFO or /dev/zero there is not read); None otherwise."""
    try:
        return read_regular(path, MAX_PAGE_BYTES)
    except OSError:
        return None


def key_of(path: str | Path) -> str | None:
    """The key of the page written at `path` (its KEY_META element); None where there is no file,
    no regular file of at most MAX_PAGE_BYTES, no key, or the page is not whole (its last line, the
    SHA-256 of the bytes before it, missing or not theirs: a page cut short or edited)."""
    data = _earlier_page(path)
    return None if data is None else _key_in(data)


def _key_in(data: bytes) -> str | None:
    """The key of the page `data` (`key_of`)."""
    seal = _SEAL.search(data)
    if seal is None or hashlib.sha256(data[:seal.start()]).hexdigest().encode() != seal.group(1):
        return None
    m = _KEY.search(data, 0, 4096)
    return m.group(1).decode() if m else None


def _sealed(html: str) -> str:
    """`html` with its seal: a last line holding the SHA-256 of its UTF-8 bytes."""
    return f"{html}<!-- kinetostat-page-sha256 {hashlib.sha256(html.encode()).hexdigest()} -->\n"


@cache
def _code_digest() -> bytes:
    """SHA-256 of the code a page is drawn by (`code_files`), each file by its path relative to the
    package and its bytes, in order."""
    root = Path(__file__).resolve().parents[1]
    h = hashlib.sha256()
    for f in code_files():
        h.update(f.relative_to(root).as_posix().encode() + b"\0" + f.read_bytes() + b"\0")
    return h.digest()


def code_files() -> list[Path]:
    """The files of the code a page is drawn by, sorted: this module and every module of the
    package it imports, directly or through others, at module level or inside a function (read
    from their source, with each package's __init__), and the .js and .json files in their
    folders (regular files, not hidden, not an editor's lock). An edit to another module (the
    command line, the reports) leaves a page's key as it is."""
    root = Path(__file__).resolve().parents[1]
    todo, seen = [Path(__file__).resolve()], set()
    while todo:
        f = todo.pop()
        if f not in seen:
            seen.add(f)
            todo += _imported(f, root)
    data = {g for f in seen for g in f.parent.iterdir()
            if g.suffix in (".js", ".json") and g.name[0] not in ".#" and g.is_file() and not g.is_symlink()}
    return sorted(seen | data)


#: An import statement at the start of a line: `from X import names` (X relative or absolute;
#: names in parentheses over lines, with comments) or `import names`, at any indentation; one in a
#: docstring counts too. Not seen: an import after `;` or continued by a backslash (a test checks
#: the package's sources against Python's parser).
_IMPORT = re.compile(r"^[ \t]*(?:from[ \t]+([.\w]+)[ \t]+import[ \t]+(\([^)]*\)|[^\n#;]*)|import[ \t]+([^\n#;]*))", re.M)


def _imported(f: Path, root: Path) -> list[Path]:
    """The package's modules the module `f` imports (relative or absolute; of `from X import a`, X
    and a submodule a), each with the __init__ of every package on its way."""
    package = [*f.parent.relative_to(root.parent).parts]          # e.g. ["kinetostat", "plans"]
    out = []

    def add(parts: list[str]) -> None:
        if not parts or parts[0] != root.name:
            return
        for n in range(1, len(parts) + 1):
            p = root.parent.joinpath(*parts[:n])
            out.extend(g for g in (p / "__init__.py", p.with_suffix(".py")) if g.is_file())
    names = lambda text: [a.split()[0] for a in re.sub(r"#[^\n]*", "", text).strip("() \t\n").split(",") if a.strip()]
    for m in _IMPORT.finditer(f.read_text(encoding="utf-8")):
        source, what, plain = m.groups()
        if plain is not None:
            for name in names(plain):
                add(name.split("."))
            continue
        level = len(source) - len(source.lstrip("."))
        base = (package[:len(package) - level + 1] if level else []) + [x for x in source.lstrip(".").split(".") if x]
        add(base)
        for name in names(what):
            add(base + [name])
    return out


def _feed(h, x, skip: tuple[str, ...] = (), where: str | None = None) -> None:
    """Feed `x` to the hash `h` unambiguously: its type, then its value (a float exactly, a text
    with the path `where` in it made a placeholder, an array by dtype, shape and bytes, a
    dataclass field by field but `skip`, a mapping item by item); TypeError for anything else (a
    function, an object of its own)."""
    if isinstance(x, str) and where:
        x = x.replace(where, "\0model file\0")
    if x is None or isinstance(x, (bool, int, float, complex, str)):
        h.update(f"{type(x).__name__}:{x!r};".encode())
    elif isinstance(x, np.generic):
        _feed(h, x.item(), where=where)
    elif isinstance(x, np.ndarray):
        h.update(f"ndarray:{x.dtype.str}:{x.shape};".encode() + np.ascontiguousarray(x).tobytes())
    elif is_dataclass(x) and not isinstance(x, type):
        h.update(f"{type(x).__qualname__}{{".encode())
        for f in fields(x):
            if f.name not in skip:
                h.update(f.name.encode() + b"=")
                _feed(h, getattr(x, f.name), where=where)
        h.update(b"}")
    elif isinstance(x, Mapping):
        h.update(f"map:{len(x)}{{".encode())
        for k, v in x.items():
            _feed(h, k, where=where)
            _feed(h, v, where=where)
        h.update(b"}")
    elif isinstance(x, (tuple, list)):
        h.update(f"{type(x).__name__}:{len(x)}(".encode())
        for v in x:
            _feed(h, v, where=where)
        h.update(b")")
    elif isinstance(x, (frozenset, set)):
        _feed(h, sorted(x, key=repr), where=where)
    else:
        raise TypeError(f"cannot key a {type(x).__qualname__}")
