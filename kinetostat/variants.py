"""Seed 002's task variants: tables 1.1-1.3 as data, the model of any three-digit code, its answer key.

    >>> from kinetostat import variants
    >>> v = variants.variant(1, "479")
    >>> v.values["n1"], v.values["l_OA"], v.values["phi1"]
    (4200.0, 0.048, 150.0)
    >>> mech = v.mechanism()                        # kinetostat.from_dict(v.model)
    >>> key = variants.write_key(v, "out/task1_479")  # doctest: +SKIP

Seed 002 (UkrDUZT course guide "Technical mechanics", 2021; shared/seeds/002_*.txt) gives three
crank-slider tasks: 1, a two-stroke ICE (table 1.1, lines 84-114); 2, a two-stroke opposed-cylinder
ICE (table 1.2, lines 127-150); 3, a single-acting air compressor (table 1.3, lines 165-188).

**The code** (lines 56-63): a three-digit variant, e.g. "479", is written twice ("479479") with the
letters а б в г д е under the digits; a table row labelled with a letter takes the column (0-9)
of the digit under that letter. So а and г take the first digit, б and д the second, в and е the
third. The tables label their first six rows а..е and then start again at а: a later row with
letter а also takes the first digit, and so on. Every code 000..999 is a variant (1000 per task);
all 1000 of each task are distinct models.

**Ambiguities of the text and how they are resolved** (each also stated in the generated file):

1. Table 1.1 labels both G3 (piston weight, line 100/112) and G2 (rod weight, line 101/113) with
   row "б", and I_S2 (line 102/114) with "в". Taken as printed: G3 and G2 both take the second
   digit, I_S2 the third. Why: the letters are the only selection rule the text gives and they
   are unambiguous as printed; the next row being "в" (not "г") shows that the sequence was
   written with the repeated "б", not that one label is a typo. The other reading (G2 "в", I_S2
   "г") would change two labels, against one.
2. The transcription prints the letters г, д of table 1.1 as "z", "d" (italic Cyrillic read as
   Latin); by their place in the sequence а б в [г д е] а б б в they are г and д.
3. The worked example of sec. 1.2 (lines 193-204) is no code of table 1.1: n1 = 4500 and l_OA =
   0.036 are column 1 only (а = б = 1), but l_AB/l_OA = 3.05, d = 0.08 m and I_S2 = 0.0017 are in
   no column, and p_max = 2.4 (columns 0, 5), G3 = 3.8 (4, 5), G2 = 4.9 (4, 9) contradict а = б = 1.
   The intro's "479" only illustrates the rule. The bundled `models/ice_crank_slider.toml` is the
   example; `build(1, WORKED_EXAMPLE)` feeds its data through this builder (the nearest code is
   110: n1, l_OA, phi1 and l_AS2/l_AB agree, the other six rows differ).
4. Columns that break a table's pattern are taken as printed: table 1.1 I_S2 column 5 = 0.0023
   (then 0.0018 ... 0.0021); table 1.3 l_OA columns 7 and 8 both 0.08, n1 column 9 = 360;
   table 1.2 l_OA, d, p_max, G columns without a trend.
5. Lengths: l_AB = (l_AB/l_OA) * l_OA exactly; the worked example rounds l_AB to 0.11 m, the
   variants are not rounded.
6. The figures 1.1-1.3 (layouts and indicator diagrams) are not in the text. Each task reuses the
   assumptions of its bundled model, read from that model file so that both stay one:
   task 1 `ice_crank_slider` (vertical cylinder through O above the crank, phi from TDC, crank
   cw, massless crank, the assumed two-stroke diagram with p = 0.8 p_max at 30 deg as sec. 1.2
   states); task 2 `opposed_twin` (horizontal opposed cylinders, throws 180 deg apart, both
   diagrams in phase, rod I_S = m l^2/12, massless crank); task 3 `compressor` (vertical
   cylinder, the assumed compressor diagram against piston travel, the assumed spur reducer and
   gear-wheel crank, rod I_S = m l^2/12). The compressor diagram is a fraction of p_max and
   depends on p_max through the atmospheric pressure: table 1.3 has p_max = 0.2 MPa in every
   column, so the one diagram holds for every code.
7. Tables 1.2 and 1.3 give no rod I_S: I_S = m l^2/12 (uniform bar, line 360), m = G/g, g = 9.81
   (line 350). Table 1.1 gives I_S2, which is used.
8. Friction: the text ignores it (line 334), so the variants have none (the bundled
   ice_crank_slider adds a journal friction that changes only its friction power, not the
   reactions or M_bal).
9. Design position: phi1 of the table, from top dead centre (line 82; task 2: of cylinder 3) in
   the crank's sense; the key (worksheet, plans) is drawn there.

May use: the solver (`model`), `kinetostat.plans` (the key's plans and worksheet, from its one analysis `plans.solve`),
`examples` (the bundled models' assumptions), `_io`, `tables`; never the harness, the engines or `report`.
"""
from __future__ import annotations

import copy
import json
import math
import re
import textwrap
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from types import MappingProxyType
from typing import Any, Mapping

import numpy as np

from ._io import unit, write_text
from .model import Mechanism, Table, from_dict, load

__all__ = ["TASKS", "Row", "TaskTable", "Variant", "KeySummary", "variant", "build", "codes", "check_task",
           "check_code", "write_key", "index_markdown", "write_index", "to_toml", "WORKED_EXAMPLE", "G"]

#: Gravity of seed 002 (line 350), m/s^2.
G = 9.81
#: The letters of the code's digits (lines 56-63): letter -> position in the three-digit code.
LETTERS = {"а": 0, "б": 1, "в": 2, "г": 0, "д": 1, "е": 2}
#: The work the variants come from, by its citation (kinetostat.report.sources has the full reference).
SEED = "Logvinenko, Nadtoka 2021"


@dataclass(frozen=True)
class Row:
    """One row of a variant table: its letter (а..е), an ASCII `key`, the text's symbol, meaning,
    unit as printed and the values of columns 0..9."""
    letter: str
    key: str
    symbol: str
    meaning: str
    unit: str
    values: tuple[float, ...]


@dataclass(frozen=True)
class TaskTable:
    """A task of seed 002 and its table of initial data."""
    task: int
    table: str
    title: str
    bundled: str            # the bundled model whose assumptions the task reuses
    rows: tuple[Row, ...]


def _row(letter, key, symbol, meaning, unit, values) -> Row:
    values = tuple(float(x) for x in values)
    assert len(values) == 10 and letter in LETTERS, key
    return Row(letter, key, symbol, meaning, unit, values)


_PHI = (30, 60, 90, 120, 150) * 2
_HALF = (0.5,) * 10

#: The three tables as printed (Logvinenko, Nadtoka 2021, sec. 1.1).
TASKS: Mapping[int, TaskTable] = MappingProxyType({
    1: TaskTable(1, "1.1", "two-stroke ICE crank-slider of a water-pumping unit", "ice_crank_slider", (
        _row("а", "n1", "n_1", "crank speed", "rpm",
             (4400, 4500, 4400, 4300, 4200, 4100, 4000, 4400, 4200, 4300)),
        _row("б", "l_OA", "l_OA", "crank length", "m",
             (0.034, 0.036, 0.038, 0.04, 0.042, 0.044, 0.046, 0.048, 0.05, 0.052)),
        _row("в", "phi1", "φ_1", "design position from TDC", "deg", _PHI),
        _row("г", "ratio", "l_AB/l_OA", "rod to crank length", "1",
             (3.5, 3.55, 3.6, 3.65, 3.7, 3.75, 3.8, 3.85, 3.9, 3.95)),
        _row("д", "s_ratio", "l_AS2/l_AB", "rod centre of mass", "1", _HALF),
        _row("е", "d", "d", "cylinder diameter", "m", (0.070, 0.072, 0.074, 0.076, 0.078) * 2),
        _row("а", "p_max", "P_max", "maximum cylinder pressure", "MPa", (2.4, 2.5, 2.6, 2.7, 2.8) * 2),
        _row("б", "G3", "G_3", "piston weight", "N",
             (3.6, 3.65, 3.7, 3.75, 3.8, 3.8, 3.75, 3.7, 3.65, 3.6)),
        _row("б", "G2", "G_2", "rod weight", "N", (4.7, 4.75, 4.8, 4.85, 4.9) * 2),
        _row("в", "I_S2", "I_S2", "rod moment of inertia about S2", "kg m^2",
             (0.0018, 0.0019, 0.002, 0.0021, 0.0022, 0.0023, 0.0018, 0.0019, 0.002, 0.0021)),
    )),
    2: TaskTable(2, "1.2", "two-stroke opposed-cylinder ICE of a transport power unit", "opposed_twin", (
        _row("а", "n1", "n_1", "crankshaft speed", "rpm",
             (5000, 4500, 5100, 5200, 5000, 4500, 4400, 4800, 5000, 4400)),
        _row("б", "l_OA", "l_OA, l_OC", "crank throw length", "m",
             (0.035, 0.033, 0.037, 0.039, 0.04, 0.042, 0.033, 0.038, 0.042, 0.038)),
        _row("в", "ratio", "l_AB/l_OA, l_CD/l_OC", "rod to crank length", "1",
             (3.5, 3.55, 3.6, 3.65, 3.7, 3.75, 3.8, 3.85, 3.9, 3.95)),
        _row("г", "s_ratio", "l_AS2/l_AB, l_CS4/l_CD", "rods' centres of mass", "1", _HALF),
        _row("д", "phi1", "φ_1", "design position from TDC of cylinder 3", "deg", _PHI),
        _row("е", "d", "d", "cylinder diameter", "m",
             (0.075, 0.074, 0.072, 0.072, 0.078, 0.078, 0.078, 0.08, 0.07, 0.08)),
        _row("а", "p_max", "P_max", "maximum cylinder pressure", "MPa",
             (3.2, 3.4, 3.2, 3.0, 2.8, 3.0, 3.2, 3.4, 3.2, 3.0)),
        _row("б", "G_piston", "G_3, G_5", "piston weight", "N",
             (3.2, 3.6, 3.6, 3.2, 3.4, 3.6, 3.6, 3.4, 3.2, 3.4)),
        _row("в", "G_rod", "G_2, G_4", "rod weight", "N",
             (4.6, 4.2, 4.6, 4.0, 4.6, 4.2, 4.0, 4.6, 4.0, 4.2)),
    )),
    3: TaskTable(3, "1.3", "single-stage single-acting air compressor", "compressor", (
        _row("а", "n1", "n_1", "crank speed", "rpm", (380, 400, 375, 350, 325, 300, 325, 350, 375, 360)),
        _row("б", "l_OA", "l_OA", "crank radius", "m",
             (0.045, 0.05, 0.055, 0.06, 0.065, 0.07, 0.075, 0.08, 0.08, 0.09)),
        _row("в", "ratio", "l_AB/l_OA", "rod to crank length", "1",
             (3.5, 3.55, 3.6, 3.65, 3.7, 3.75, 3.8, 3.85, 3.9, 3.95)),
        _row("г", "G2", "G_2", "rod weight", "N", (50, 52, 54, 56, 58, 60, 62, 64, 66, 68)),
        _row("д", "G3", "G_3", "piston weight", "N", (40, 42, 44, 46, 48, 50, 48, 46, 44, 42)),
        _row("е", "s_ratio", "l_AS2/l_AB", "rod centre of mass", "1", _HALF),
        _row("а", "d", "d", "cylinder diameter", "m", (0.154,) * 10),
        _row("б", "p_max", "P_max", "maximum cylinder pressure (gauge)", "MPa", (0.2,) * 10),
        _row("в", "phi1", "φ_1", "design position from TDC", "deg", _PHI),
    )),
})

#: The worked example of sec. 1.2 (lines 193-204) as table-1.1 values: no code gives them (see the
#: module docstring, item 3); l_AB = 0.11 m as the text computes with it.
WORKED_EXAMPLE: Mapping[str, float] = MappingProxyType({
    "n1": 4500.0, "l_OA": 0.036, "phi1": 30.0, "ratio": 0.11 / 0.036, "s_ratio": 0.5, "d": 0.08,
    "p_max": 2.4, "G3": 3.8, "G2": 4.9, "I_S2": 0.0017})

_AMBIGUITY_G2 = ("Table 1.1 labels both G3 and G2 with row 'б' and I_S2 with 'в': taken as printed, G3 and G2 "
                 "take the second digit, I_S2 the third (the row after the repeated 'б' is 'в', not 'г', so "
                 "the sequence was written with it; the letters are the text's only selection rule).")
_ASSUMED = {
    1: ["Cylinder above the crank shaft, slider axis vertical through O; crank angle from top dead centre "
        "(sec. 1.1), crank turning clockwise (figure 1.1a not available; magnitudes are the same for either "
        "sense by mirror symmetry). As the bundled ice_crank_slider.",
        "Crank mass not given: treated as balanced and massless (the worked example does not use it).",
        "Indicator diagram (figure 1.1b not available): the bundled ice_crank_slider's assumed two-stroke "
        "diagram p/p_max against crank angle (p = 0.8 p_max at 30 deg, as sec. 1.2 states; expansion "
        "0-180 deg, driving in positions 0-6 and resisting in 6-12, sec. 1.1 task 1); the gas force acts on the "
        "piston crown towards the crank shaft (-y), pi/4 d^2 p."],
    2: ["Crankshaft with two throws 180 deg apart (A and C on opposite sides of O, boxer layout), cylinders "
        "horizontal on one axis through O: piston 3 to the right (+x), piston 5 to the left (-x); crank "
        "angle from the top dead centre of cylinder 3, crank turning clockwise (figure 1.2a not "
        "available). As the bundled opposed_twin.",
        "Indicator diagram (figure 1.2b not available): the bundled ice_crank_slider's assumed two-stroke "
        "diagram, one per cylinder, in phase (both pistons reach TDC together with 180-deg throws); gas "
        "force on each piston towards the crank shaft, pi/4 d^2 p.",
        "Rod centroidal moments of inertia not in table 1.2: I_S = m l^2/12 (uniform bar, sec. 1.2.3), m = G/g.",
        "Crankshaft mass not given: treated as balanced and massless."],
    3: ["Vertical cylinder above the crank shaft, slider axis through O (suction on the downward stroke, "
        "sec. 1.1 task 3); crank angle from top dead centre, crank turning clockwise (figure 1.3a not available). "
        "As the bundled compressor.",
        "Rod centroidal moment of inertia not in table 1.3: I_S2 = m l^2/12 (uniform bar, sec. 1.2.3), m = G/g.",
        "Reducer and crank wheel not specified: the bundled compressor's spur pair, wheel mass and inertia "
        "(Kiriienko 2019 sec. 7.2 estimate), the wheel carrying the crank pin; the pin radius of every column "
        "(<= 0.09 m) lies inside the wheel.",
        "Pressure diagram (figure 1.3b not available): the bundled compressor's assumed diagram, gauge "
        "pressure / p_max against piston travel from TDC (clearance 5 %, polytropic n = 1.3, suction "
        "slightly below atmospheric, delivery at p_max); it depends on p_max, which is 0.2 MPa in every "
        "column of table 1.3, so it holds for every code. Force pi/4 d^2 p on the crown towards the crank."],
}
_COMMON = ["Every number not derived from the table is an assumption of the bundled model named in these "
           "items (models/<name>.toml, whose header gives the reasons); the table's values are used as "
           "printed (columns that break a pattern included).",
           "l_AB = (l_AB/l_OA) * l_OA exactly (not rounded as in the worked example); l_AS = (l_AS/l_AB) * l_AB.",
           "Constant crank speed (eps = 0), no friction (the text ignores it, sec. 1.2.3), g = 9.81 (sec. 1.2.3); "
           "design position phi1 of the table."]


# ============================================================================ codes and values

def check_task(task: Any, name: str = "task") -> int:
    """The task number 1, 2 or 3 (int or its digit as text); ValueError naming `name` otherwise."""
    text = str(task).strip()
    if isinstance(task, bool) or text not in {str(t) for t in TASKS}:
        raise ValueError(f"{name}: unknown task {task!r}; Logvinenko, Nadtoka 2021 has tasks {', '.join(map(str, TASKS))}")
    return int(text)


def check_code(code: Any, task: int | None = None, name: str = "code") -> str:
    """The three-digit code as text ('000'..'999'); ValueError naming `name` otherwise (an int
    would lose a leading zero, so only text is taken)."""
    of = f" of task {task}" if task is not None else ""
    if not (isinstance(code, str) and len(code) == 3 and all(c in "0123456789" for c in code)):
        raise ValueError(f"{name}: {code!r} is not a variant{of}: expected three digits 000..999 "
                         f"(e.g. '479', as Logvinenko, Nadtoka 2021 numbers them in its introduction)")
    return code


def codes() -> list[str]:
    """Every code, '000'..'999'."""
    return [f"{n:03d}" for n in range(1000)]


def columns(task: int, code: str) -> dict[str, int]:
    """Row key -> the table column (0..9) that `code` selects for it."""
    code = check_code(code, task)
    return {r.key: int(code[LETTERS[r.letter]]) for r in TASKS[check_task(task)].rows}


def values(task: int, code: str) -> dict[str, float]:
    """Row key -> the value that `code` selects, in the table's units (rpm, m, deg, MPa, N, kg m^2)."""
    rows = {r.key: r for r in TASKS[check_task(task)].rows}
    return {k: rows[k].values[c] for k, c in columns(task, code).items()}


# ============================================================================ the model

@lru_cache(maxsize=None)
def _bundled(name: str) -> Mechanism:
    """The bundled model `name` (its assumptions are reused; read once per process)."""
    from . import examples
    try:
        return load(examples.path(name))
    except FileNotFoundError as exc:
        raise FileNotFoundError(f"the variants of Logvinenko, Nadtoka 2021 reuse the assumptions of the bundled model {name!r}: "
                                f"{exc}") from None


def _table(t: Table, scale: float) -> dict:
    """A load table as the model file writes it, with a new scale (N per unit)."""
    if t.argument == "phi":
        return {"phi_deg": list(t.x), "value": list(t.value), "scale": scale}
    out: dict[str, Any] = {"axis": list(t.axis), "origin": t.origin, "travel": list(t.x), "value": list(t.value)}
    if t.value_return is not None:
        out["value_return"] = list(t.value_return)
    return out | {"scale": scale}


def _gas_scale(d: float, p_max_mpa: float) -> float:
    """Piston area times p_max: pi/4 d^2 p_max, N."""
    return math.pi / 4 * d ** 2 * p_max_mpa * 1e6


def _slider_crank(rod: int, pin: str, end: str, com: str, length: float, s_ratio: float, G_rod: float,
                  I_S: float, G_piston: float, axis: list[float], gas: dict, gas_name: str) -> dict[str, list]:
    """Links, pairs, group and gas load of one rod `rod` (crank pin `pin` -> piston pin `end`) and its
    piston `rod + 1` sliding on the frame along `axis` through O, the gas force towards the crank."""
    piston = rod + 1
    return {
        "link": [{"id": rod, "name": f"connecting rod {pin}{end}",
                  "points": {pin: [0.0, 0.0], end: [length, 0.0], com: [s_ratio * length, 0.0]},
                  "weight": G_rod, "I_S": I_S, "com": com},
                 {"id": piston, "name": f"piston {piston}", "points": {end: [0.0, 0.0]},
                  "weight": G_piston, "I_S": 0.0, "com": end}],
        "pair": [{"kind": "R", "links": [1, rod], "point": pin},
                 {"kind": "R", "links": [rod, piston], "point": end},
                 {"kind": "P", "links": [0, piston], "guide": "O", "direction": axis, "point": end}],
        "group": [{"links": [rod, piston], "branch": 1}],
        "load": [{"name": gas_name, "link": piston, "point": end, "direction": [0.0 - a for a in axis],
                  "table": gas}],
    }


def _rod_inertia(G_rod: float, length: float) -> float:
    """I_S = m l^2/12 of a uniform bar of weight G_rod (N) and length (m), kg m^2 (line 360)."""
    return G_rod / G * length ** 2 / 12


#: Each task's title and the name of a variant in Ukrainian and Russian (the sheets' lettering).
TITLES = {
    1: ("Кривошипно-повзунний механізм двотактного ДВЗ водонасосної установки",
        "Кривошипно-ползунный механизм двухтактного ДВС водонасосной установки"),
    2: ("Двотактний ДВЗ з протилежними циліндрами транспортної силової установки",
        "Двухтактный ДВС с противолежащими цилиндрами транспортной силовой установки"),
    3: ("Одноступеневий повітряний компресор простої дії", "Одноступенчатый воздушный компрессор простого действия"),
}
_NAME = ("{title} (Логвіненко, Надтока 2021, задача {task}, {label})", "{title} (Логвиненко, Надтока 2021, задача {task}, {label})")
_LABEL = (("варіант {code}", "задані значення"), ("вариант {code}", "заданные значения"))


def task_title(task: int, lang: str = "en") -> str:
    """Task `task`'s title in `lang` ("en", "uk", "ru")."""
    return TASKS[task].title if lang == "en" else TITLES[task][lang == "ru"]


def _lettering(task: int, code: str | None) -> dict:
    """The variant's [lettering]: the bundled model's (frame, M_зр, F_зр, loads, language) and
    the variant's name in Ukrainian and Russian."""
    ref = dict(_bundled(TASKS[task].bundled).lettering)
    names = {}
    for lang, i in (("uk", 0), ("ru", 1)):
        label = _LABEL[i][0].format(code=code) if code else _LABEL[i][1]
        names[lang] = _NAME[i].format(title=TITLES[task][i], task=task, label=label)
    return {k: (dict(x) if isinstance(x, Mapping) else x) for k, x in ref.items() if k != "name"} | {"name": names}


def _model(task: int, v: Mapping[str, float], label: str, assumptions: list[str], code: str | None = None) -> dict:
    """The model dict of task `task` with table values `v`."""
    spec = TASKS[task]
    l_OA, length = v["l_OA"], v["ratio"] * v["l_OA"]
    drive = {"link": 1, "pivot": "O", "point": "A", "reference": [0.0, 1.0], "sense": "cw", "rpm": v["n1"],
             "eps": 0.0, "kind": "engine", "design_deg": v["phi1"]}
    crank: dict[str, Any] = {"id": 1, "name": "crank", "points": {"O": [0.0, 0.0], "A": [l_OA, 0.0]}, "mass": 0.0}
    diagram = _bundled("compressor" if task == 3 else "ice_crank_slider").loads[0].table
    gas = _table(diagram, _gas_scale(v["d"], v["p_max"]))
    if task == 1:
        parts = [_slider_crank(2, "A", "B", "S2", length, v["s_ratio"], v["G2"], v["I_S2"], v["G3"],
                               [0.0, 1.0], gas, "gas force")]
    elif task == 2:
        I_S = _rod_inertia(v["G_rod"], length)
        drive["reference"] = [1.0, 0.0]
        crank = crank | {"name": "crankshaft (two throws 180 deg apart)",
                         "points": {"O": [0.0, 0.0], "A": [l_OA, 0.0], "C": [-l_OA, 0.0]}}
        parts = [_slider_crank(2, "A", "B", "S2", length, v["s_ratio"], v["G_rod"], I_S, v["G_piston"],
                               [1.0, 0.0], gas, "gas force, cylinder 3"),
                 _slider_crank(4, "C", "D", "S4", length, v["s_ratio"], v["G_rod"], I_S, v["G_piston"],
                               [-1.0, 0.0], gas, "gas force, cylinder 5")]
    else:
        ref = _bundled(spec.bundled)
        gear = ref.drive.gear
        drive |= {"kind": "machine", "gear": {
            "module": gear.module, "z_pinion": gear.z_pinion, "z_wheel": gear.z_wheel,
            "correction": gear.correction, "alpha_w_deg": gear.alpha_w_deg,
            "centre_direction": list(gear.centre_direction)}}
        wheel = ref.links[1]
        crank = crank | {"name": f"crank (gear wheel z = {gear.z_wheel} with crank pin)", "mass": wheel.mass,
                         "I_S": wheel.I_S, "com": "O"}
        parts = [_slider_crank(2, "A", "B", "S2", length, v["s_ratio"], v["G2"], _rod_inertia(v["G2"], length),
                               v["G3"], [0.0, 1.0], gas, "air pressure force")]
    model: dict[str, Any] = {
        "mechanism": {"name": f"{spec.title} ({SEED}, task {task}, {label})",
                      "source": f"{SEED}, sec. 1.1 task {task}, table {spec.table}",
                      "assumptions": assumptions, "g": G},
        "drive": drive, "frame": {"O": [0.0, 0.0]}, "link": [crank], "pair": [{"kind": "R", "links": [0, 1],
                                                                              "point": "O"}],
        "group": [], "load": []}
    for part in parts:
        for key, items in part.items():
            model[key] += items
    model["link"].sort(key=lambda t: t["id"])
    model["lettering"] = _lettering(task, code)
    return model


@dataclass(frozen=True)
class Variant:
    """One variant of a seed 002 task: its code, the columns and values it selects, the model
    (`model`: a fresh dict each time, `kinetostat.from_dict` input) and the TOML file's header."""
    task: int
    code: str | None
    columns: Mapping[str, int]
    values: Mapping[str, float]
    _model: Mapping[str, Any]
    header: tuple[str, ...]

    @property
    def model(self) -> dict[str, Any]:
        """The model as a dict (a deep copy: editing it leaves the variant as it is)."""
        return copy.deepcopy(self._model)

    @property
    def name(self) -> str:
        """`task<T>_<CODE>`: the stem of its file and folder."""
        return f"task{self.task}_{self.code or 'custom'}"

    @property
    def spec(self) -> TaskTable:
        """The task's table of the text (`TASKS[task]`)."""
        return TASKS[self.task]

    @property
    def letters(self) -> dict[str, str]:
        """The code's digit under each letter of the text (а, б, в, г, д, е); empty without a code."""
        return {ch: self.code[i] for ch, i in LETTERS.items()} if self.code else {}

    def title(self, lang: str = "en") -> str:
        """The task's title in `lang` ("en", "uk", "ru")."""
        return task_title(self.task, lang)

    def mechanism(self) -> Mechanism:
        return from_dict(self._model, source=self.name)

    def toml(self) -> str:
        """The model as a readable TOML file: the header, then the tables."""
        return to_toml(self._model, self.header)


def build(task: int, v: Mapping[str, float], code: str | None = None, columns: Mapping[str, int] | None = None
          ) -> Variant:
    """The variant of task `task` from table values `v` (row key -> value, table units; e.g.
    WORKED_EXAMPLE), `code` and its `columns` when they come from the table."""
    task = check_task(task)
    spec = TASKS[task]
    missing = [r.key for r in spec.rows if r.key not in v]
    if missing:
        raise ValueError(f"values: task {task} needs {', '.join(missing)}")
    label = f"variant {code}" if code else "values given"
    chosen = (f"Variant {code}: rows а б в г д е take columns {' '.join(code * 2)} "
              f"(the rule of the text's introduction): " if code else "Values given, not a code: ")
    chosen += ", ".join(f"{r.symbol} = {v[r.key]:g}{_unit(r)}" for r in spec.rows) + "."
    assumptions = [chosen] + ([_AMBIGUITY_G2] if task == 1 else []) + _ASSUMED[task] + _COMMON
    model = _model(task, v, label, assumptions, code)
    return Variant(task, code, MappingProxyType(dict(columns or {})), MappingProxyType(dict(v)), model,
                   _header(spec, v, code, columns, model, assumptions))


def variant(task: int | str, code: str) -> Variant:
    """The variant `code` ('000'..'999') of seed 002's task `task` (1, 2, 3)."""
    task = check_task(task)
    code = check_code(code, task)
    return build(task, values(task, code), code, columns(task, code))


def _unit(r: Row) -> str:
    return "" if r.unit == "1" else f" {r.unit}"


def _header(spec: TaskTable, v, code, cols, model, assumptions) -> tuple[str, ...]:
    length = v["ratio"] * v["l_OA"]
    lines = [f"{SEED}, sec. 1.1, task {spec.task}: {spec.title}; table {spec.table}.",
             f"Written by `kinetostat variant {spec.task} {code}` (kinetostat.variants)." if code else
             "Written by kinetostat.variants.build from values given (not a code of the table).", ""]
    if code:
        lines += [f"The code (the text's introduction): \"{code}\" written twice, \"{code * 2}\", with а б в г д е under the",
                  "digits; a row labelled with a letter takes the column of the digit under it:",
                  "  " + "  ".join(f"{ch}={code[i]}" for ch, i in LETTERS.items()), ""]
    lines.append("Rows (letter, symbol = value [unit], column):")
    for r in spec.rows:
        c = cols[r.key] if cols else None
        where = f"column {c}" if c is not None else "given"
        lines.append(f"  {r.letter}  {r.symbol} = {v[r.key]:g}{_unit(r)}   ({r.meaning}; {where})")
    lines += ["", "Derived:",
              f"  l_AB = {v['ratio']:g} * {v['l_OA']:g} = {length:.12g} m;  l_AS = {v['s_ratio']:g} * l_AB "
              f"= {v['s_ratio'] * length:.12g} m",
              f"  gas force scale = pi/4 * {v['d']:g}^2 m^2 * {v['p_max']:g}e6 Pa = "
              f"{_gas_scale(v['d'], v['p_max']):.12g} N"]
    if spec.task != 1:
        rod = model["link"][1]
        lines.append(f"  rod I_S = ({rod['weight']:g}/{G}) * {length:.12g}^2 / 12 = {rod['I_S']:.12g} kg m^2")
    lines += ["", "Assumptions and the text's ambiguities (also in mechanism.assumptions):"]
    for a in assumptions[1:]:
        lines += textwrap.wrap(a, 96, initial_indent="  * ", subsequent_indent="    ")
    return tuple(lines)


# ============================================================================ TOML

def _key(k: str) -> str:
    """A TOML key: bare where it may be, else quoted."""
    return k if re.fullmatch(r"[A-Za-z0-9_-]+", k) else json.dumps(k, ensure_ascii=False)


def _value(x: Any) -> str:
    if isinstance(x, bool):
        return "true" if x else "false"
    if isinstance(x, (int, np.integer)):
        return str(int(x))
    if isinstance(x, (float, np.floating)):
        return repr(float(x))
    if isinstance(x, str):
        return json.dumps(x, ensure_ascii=False)
    if isinstance(x, (list, tuple)):
        return "[" + ", ".join(_value(y) for y in x) + "]"
    if isinstance(x, Mapping):
        return "{ " + ", ".join(f"{_key(k)} = {_value(y)}" for k, y in x.items()) + " }"
    raise TypeError(f"cannot write {type(x).__name__} to TOML")


def _body(path: str, table: Mapping, array: bool) -> list[str]:
    head = f"[[{path}]]" if array else f"[{path}]"
    lines, subs = ["", head], []
    for k, x in table.items():
        if isinstance(x, Mapping) and k not in ("points", "loads", "name"):
            subs.append((k, x))
        elif isinstance(x, list) and x and all(isinstance(s, str) for s in x) and len(_value(x)) > 80:
            lines.append(f"{k} = [")
            lines += [f"    {_value(s)}," for s in x]
            lines.append("]")
        else:
            lines.append(f"{_key(k)} = {_value(x)}")
    for k, x in subs:
        lines += _body(f"{path}.{k}", x, False)
    return lines


def to_toml(model: Mapping[str, Any], header: tuple[str, ...] | list[str] = ()) -> str:
    """A model dict as TOML text (`tomllib` reads it back to the same dict), led by `header` as
    comment lines. Tables, arrays of tables (`[[link]]`), `points` as inline tables; floats as
    Python's shortest round-trip repr."""
    lines = [f"# {h}".rstrip() for h in header]
    for key, x in model.items():
        if isinstance(x, Mapping):
            lines += _body(key, x, False)
        elif isinstance(x, list) and all(isinstance(t, Mapping) for t in x):
            for t in x:
                lines += _body(key, t, True)
        else:
            raise TypeError(f"model[{key!r}]: expected a table or an array of tables")
    return "\n".join(lines).lstrip("\n") + "\n"


# ============================================================================ the answer key

@dataclass(frozen=True)
class KeySummary:
    """The key's main numbers: at the design position phi1 the balancing moment (N m) and the
    largest reaction (pair label, N); over the cycle (360 steps) the largest |M_bal| and |R|."""
    name: str
    phi1: float
    M_bal: float
    largest: str
    R_max: float
    cycle_M_max: float
    cycle_R_max: float
    files: tuple[Path, ...] = ()


def _largest(res, mech: Mechanism, n: int = 0) -> tuple[str, float]:
    """The most loaded pair at angle n, named as the model's text names its reaction (R43), N."""
    from .model.lettering import lettering
    frame = lettering(mech).frame
    mags = {"R" + "".join(str(k or frame) for k in p.links): float(np.linalg.norm(res.forces.R[n, p.index]))
            for p in mech.pairs}
    label = max(mags, key=mags.get)
    return label, mags[label]


def write_key(v: Variant, out_dir: str | Path, lang: str = "en", cycle_csv: bool = True,
              steps: int = 360, root: str | Path | None = None, teacher_pack: bool = True,
              page: bool = False) -> KeySummary:
    """Write the variant's model file `<name>.toml` and its answer key into `out_dir` (created): the
    worksheet (worksheet.md/html/csv/json) and the plans (SVG sheets, segments.csv) at the design
    position in `lang` ("en", "uk", "ru"), and with `cycle_csv` the analysis over the cycle
    (cycle.csv, `steps` positions, with the text's names as alias columns: R_4_3, M_зр), and with
    `teacher_pack` the teacher's pack (`plans.pack`: sheet.pdf, key.pdf, plans_a3.pdf and their HTML), and with
    `page` the interactive page (page.html, `plans.page`: the key mode, the check at phi1). With the
    pack, the plans, worksheet and pack are drawn at the scales that put all the plans on its one
    A3 sheet (`plans.a3.one_sheet`, chosen once here; the plans' SVG sheets are those it drew,
    `OneSheet.sheets`); without it, at the texts' rule (page.html keeps its own scales, fixed over
    the cycle). cycle.csv is written without pandas (`Analysis.columns`, `tables.columns_csv`). The files
    are swapped in as a set (`kinetostat._io.unit`); `out_dir` must resolve inside `root`
    (default: itself), ValueError otherwise."""
    from .plans import build as build_plans, solve
    from .model.lettering import with_alias_columns
    from .plans.a3 import one_sheet
    from .plans.pack import pack
    from .plans.solution import grid
    from .plans.worksheet import worksheet_cycle
    from .tables import columns_csv
    out = Path(out_dir)
    mech = v.mechanism()
    phi1 = float(v.values["phi1"])
    from .plans.page import page_angles
    drawn = solve(mech, [phi1, *(page_angles(mech, at=phi1)[1] if page else [])], also=grid(steps))   # once: every file below
    solution = drawn.sub([phi1])
    at, res = solution.res, solution.on(grid(steps))
    a3 = one_sheet(mech, phi1, lang, solution=solution) if teacher_pack else None      # the scales of every file below
    plans = a3.plans if a3 else build_plans(mech, at=phi1, solution=solution)
    sheet = worksheet_cycle(mech, at, plans.scales["mu_l"].value, lang, solution.other).at(0)
    teacher = pack(v, lang, a3=a3, solution=solution) if teacher_pack else None
    with unit(out, root) as tmp:
        files = [write_text(tmp / f"{v.name}.toml", v.toml())]
        files += plans.write(tmp, lang=lang, sheets=a3.sheets if a3 else None) + sheet.write(tmp) + (teacher.write(tmp) if teacher else [])
        if cycle_csv:
            files.append(write_text(tmp / "cycle.csv", columns_csv(*with_alias_columns(*res.columns(), mech))))
        if page:
            from .plans.page import write_page
            files.append(write_page(mech, tmp / "page.html", lang=lang, at=phi1, solution=drawn))
    files = [out / f.relative_to(tmp) for f in files]
    label, R = _largest(at, mech)
    R_cycle = max(float(np.nanmax(np.linalg.norm(res.forces.R[:, p.index], axis=-1))) for p in mech.pairs)
    return KeySummary(v.name, phi1, float(at.balancing_moment[0]), label, R,
                      float(np.nanmax(np.abs(res.balancing_moment))), R_cycle, tuple(files))


def index_markdown(keys: list[KeySummary], lang: str = "en") -> str:
    """The teacher's index of answer keys in `lang` ("en", "uk", "ru"): per task a table code ->
    phi1, M_зр and the largest reaction at phi1, and the largest |M_зр| and |R| over the cycle;
    each code links to the worksheet in its folder `<name>/` (`KeySummary.name`)."""
    from .plans.i18n import num, text, unit
    M = lettering_of(1).in_lang(lang).M_bal
    Nm, N, deg = unit("N m", lang), unit("N", lang), unit("deg", lang)
    lines = [f"# {text('ix.title', lang)}", "", text("ix.intro", lang, M=M), ""]
    by_task: dict[str, list[KeySummary]] = {}
    for k in keys:
        by_task.setdefault(k.name.split("_")[0], []).append(k)
    for task, ks in by_task.items():
        spec = TASKS[int(task[4:])]
        title = task_title(spec.task, lang)
        cyc = text("ix.cycle", lang)
        lines += [f"## {text('ix.task', lang, task=spec.task, title=title, table=spec.table)}", "",
                  f"| {text('ix.code', lang)} | φ1, {deg} | {M} {text('ix.at', lang)}, {Nm} | "
                  f"{text('ix.largest', lang)}, {N} | \\|{M}\\| {cyc}, {Nm} | \\|R\\| {cyc}, {N} | "   # \| : a bar in a cell
                  f"{text('pack.files', lang)} |",
                  "|---|---:|---:|---|---:|---:|---|"]
        for k in ks:
            code = k.name.split("_", 1)[1]
            lines.append(f"| [{code}]({k.name}/worksheet.md) | {num(k.phi1, lang, 6)} | "
                         f"{num(k.M_bal, lang, decimals=2)} | {k.largest} = {num(k.R_max, lang, decimals=1)} | "
                         f"{num(k.cycle_M_max, lang, decimals=2)} | {num(k.cycle_R_max, lang, decimals=1)} | "
                         + " ".join(f"[{f.name}]({k.name}/{f.name})" for f in k.files
                                    if f.suffix == ".pdf" or f.name == "page.html") + " |")
        lines.append("")
    return "\n".join(lines)


def summary(v: Variant, k: KeySummary, out: str | Path, lang: str = "en") -> list[str]:
    """What `kinetostat variant TASK CODE` prints, in `lang`: the code's columns, the rows'
    values, M_зр and the largest reaction at phi1 and over the cycle, the files written."""
    from .plans.i18n import num, text, unit
    spec, L = TASKS[v.task], lettering_of(v.task).in_lang(lang)
    title = v.title(lang)
    Nm, N = unit("N m", lang), unit("N", lang)
    lines = [text("cli.variant", lang, task=v.task, title=title, code=v.code, table=spec.table)
             + " " + " ".join(f"{ch}={d}" for ch, d in v.letters.items())]
    lines += [f"  {r.letter}  {r.symbol:<22s} = {num(v.values[r.key], lang, 6)} {unit(r.unit, lang)}".rstrip()
              for r in spec.rows]
    lines += [text("cli.at", lang, phi=num(k.phi1, lang, 6), M=L.M_bal, M_value=f"{num(k.M_bal, lang, 5)} {Nm}",
                   R=k.largest, R_value=f"{num(k.R_max, lang, 5)} {N}"),
              text("cli.cycle", lang, M=L.M_bal, M_value=f"{num(k.cycle_M_max, lang, 5)} {Nm}",
                   R_value=f"{num(k.cycle_R_max, lang, 5)} {N}"),
              text("cli.files" if any(f.name == "key.pdf" for f in k.files) else "cli.files_keys", lang,
                   model=f"{v.name}.toml", n=len(k.files), out=out)]
    return lines


def lettering_of(task: int):
    """The lettering of task `task`'s variants (that of its bundled model)."""
    from .model.lettering import lettering
    return lettering(_bundled(TASKS[task].bundled))


def write_index(out_dir: str | Path, keys: list[KeySummary], lang: str = "en") -> Path:
    """`index_markdown(keys, lang)` into `out_dir/index.md` and as a standalone page into
    `out_dir/index.html` (links to the worksheets' HTML), each atomically; returns the Markdown's path."""
    from markdown_it import MarkdownIt

    from .plans.i18n import text
    from .plans.worksheet import html_document
    md = index_markdown(keys, lang)
    body = MarkdownIt("commonmark", {"html": False}).enable("table").render(md.replace("/worksheet.md)", "/worksheet.html)"))
    write_text(Path(out_dir) / "index.html", html_document(text("ix.title", lang), body, lang))
    return write_text(Path(out_dir) / "index.md", md)
