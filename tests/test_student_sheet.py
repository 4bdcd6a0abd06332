"""Issue 36 item 1: a student can solve the task from `sheet.pdf` alone. The sheet's blocks (what
the PDF and the HTML print) are read back as text: the table's rows, the pressure diagram's
points and the pressure marked at φ1, the further data (crank, inertia, cylinder axes, gear pair).
A model built from those numbers gives the key's printed values (F_p, M_зр, F_зр, the reactions)
to the key's digits: 1/479 (p read at 150°), 2/479 (both cylinders), 3/479 and 3/123 (the
compressor's diagram on the stroke from TDC, the gear pair that carries F_зр)."""
from __future__ import annotations

import math
import re
import warnings
from dataclasses import replace

import pytest

import kinetostat
from kinetostat import variants
from kinetostat.plans import pack as P
from kinetostat.plans.i18n import num, text
from kinetostat.plans.solution import solve
from kinetostat.plans.worksheet import worksheet_cycle


def sheet_pack(task: int, code: str, finer_rule: str | None = None, lang: str = "uk") -> P.Pack:
    """The pack of the variant with its plans at the texts' rule on a stand-in of the one A3
    sheet (`a3.one_sheet`, seconds a variant, is not under test here: the sheet's data and the
    key's values do not depend on the scales); with `finer_rule`, that scale's rule twice as
    fine, so that the plans' scale reads as one the pack coarsened."""
    from kinetostat.plans import build
    from kinetostat.plans.a3 import OneSheet
    from kinetostat.plans.scales import references
    v = variants.variant(task, code)
    mech = v.mechanism()
    phi1 = float(v.values["phi1"])
    solution = solve(mech, [phi1])
    plans = build(mech, at=phi1, solution=solution)
    rule = {k: replace(s, value=s.value / 2) if k == finer_rule else s for k, s in plans.scales.items()}
    a3 = OneSheet(plans, lang, (), (), rule, references(mech, solution.res))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return P.pack(v, lang=lang, a3=a3, draws=20, solution=solution)


def number(cell: str) -> float:
    return float(cell.replace(",", "."))


def after(blocks, heading_key: str, lang: str, **fields):
    """The blocks after the h2 whose text starts as `heading_key` does (its fields filled), to the next h2."""
    start = text(heading_key, lang, **fields)
    i = next(i for i, (k, x) in enumerate(blocks) if k == "h2" and x.startswith(start))
    out = []
    for kind, x in blocks[i + 1:]:
        if kind == "h2":
            break
        out.append((kind, x))
    return out


def diagram_points(table) -> list[tuple[float, ...]]:
    """The diagram's points from its table, its groups of columns read down each group first."""
    n = len(set(table.head))
    groups = len(table.head) // n
    pts = [row[g * n:(g + 1) * n] for g in range(groups) for row in table.rows]
    return [tuple(number(c) for c in p) for p in pts if p[0]]


def read_sheet(p, task: int) -> dict:
    """Everything the sheet gives, as numbers: table values by row key, each diagram (kind,
    points, the pressure marked at φ1 per load symbol), the further data by symbol, the scales."""
    lang = p.lang
    data = next(x for k, x in after(p.sheet, "pack.data", lang, table=variants.TASKS[task].table) if k == "table")
    by_symbol = {r.symbol: r.key for r in variants.TASKS[task].rows}
    values = {by_symbol[row[2]]: number(row[3]) for row in data.rows}
    figures = [i for i, (k, _) in enumerate(p.sheet) if k == "figure"]
    diagrams = []
    for i in figures:
        note, table = p.sheet[i + 1][1], p.sheet[i + 2][1]
        marked = {}
        for symbols, value in re.findall(r"((?:F_\w+(?:, )?)+): p = (-?[\d,]+)", note):
            for s in symbols.split(", "):
                marked[s] = number(value)
        diagrams.append(("phi" if table.head[0].startswith("φ") else "travel", diagram_points(table), marked))
    extra = {row[1]: number(row[2]) for k, x in after(p.sheet, "pack.model_data", lang) if k == "table" for row in x.rows}
    return {"values": values, "diagrams": diagrams, "extra": extra}


def model_from_sheet(task: int, given: dict) -> kinetostat.Mechanism:
    """The task's model from the sheet's numbers: the layout the task's text describes
    (`variants.build` of the table's values), every load diagram, mass, inertia and gear datum
    replaced by the sheet's, each cylinder axis checked against the sheet's."""
    v = given["values"]
    model = variants.build(task, v).model
    extra = given["extra"]
    area = math.pi / 4 * v["d"] ** 2
    loads = [ld for ld in model["load"] if "table" in ld]
    assert len(given["diagrams"]) == 1 and len(loads) == (2 if task == 2 else 1)
    kind, points, _ = given["diagrams"][0]
    for ld in loads:
        if kind == "phi":
            ld["table"] = {"phi_deg": [x for x, _ in points], "value": [y for _, y in points], "scale": area * 1e6}
        else:
            ld["table"] = {"axis": [0.0, 1.0], "origin": "max", "travel": [x for x, *_ in points],
                           "value": [a for _, a, _ in points], "value_return": [b for *_, b in points], "scale": area * 1e6}
    for link in model["link"]:
        k = link["id"]
        link.pop("weight", None) if k == 1 else None
        if k == 1:
            link["mass"] = extra["G_1"] / variants.G
        if f"I_S{k}" in extra:
            link["I_S"] = extra[f"I_S{k}"]
    for pair in model["pair"]:
        if pair["kind"] == "P":
            beta = math.radians(extra[f"β_{pair['links'][1]}"])
            assert pair["direction"] == pytest.approx([math.cos(beta), math.sin(beta)], abs=1e-12)
    if task == 3:
        theta = math.radians(extra["θ"])
        model["drive"]["gear"] = {"module": extra["m"] / 1000, "z_pinion": int(extra["z_ш"]), "z_wheel": int(extra["z_к"]),
                                  "correction": "none" if extra["y"] == 0 else "unequal", "alpha_w_deg": extra["α_w"],
                                  "centre_direction": [round(math.cos(theta), 12), round(math.sin(theta), 12)]}
    else:
        assert "m" not in extra
    return kinetostat.from_dict(model, source="the sheet")


def key_values(p) -> dict[str, str]:
    """Symbol -> value as the key prints it (its worksheet tables)."""
    head = text("ws.head.symbol", p.lang)
    return {row[0]: row[1] for k, x in p.key if k == "table" and x.head[0] == head and len(x.head) == 5 for row in x.rows}


@pytest.mark.parametrize("task, code", [(1, "479"), (2, "479"), (3, "479"), (3, "123")])
def test_a_model_built_from_the_sheet_alone_gives_the_keys_values(task, code):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        p = sheet_pack(task, code)
        given = read_sheet(p, task)
        mech = model_from_sheet(task, given)
        phi1 = given["values"]["phi1"]
        solution = solve(mech, [phi1])
        ws = worksheet_cycle(mech, solution.res, p.plans.scales["mu_l"].value, "uk", solution.other).at(0)
    key = key_values(p)
    area = math.pi / 4 * given["values"]["d"] ** 2
    kind, _, marked = given["diagrams"][0]
    assert set(marked) == ({"F_p3", "F_p5"} if task == 2 else {"F_p"})
    for symbol, pressure in marked.items():                      # F = π d²/4 · p at the pressure marked at φ1
        assert num(area * abs(pressure) * 1e6, "uk", 4) == key[symbol], symbol
    mine = {r.symbol: num(r.value, "uk", 4) for r in ws.rows}
    wanted = [s for s in key if re.fullmatch(r"R\d\d[tn]?|M_зр|F_зр|r_b|F_p\d?", s)]
    assert "M_зр" in wanted and len([s for s in wanted if s.startswith("R")]) >= 6
    assert ("F_зр" in wanted and "r_b" in wanted) is (task == 3)
    assert {s: mine[s] for s in wanted} == {s: key[s] for s in wanted}


def test_the_pressure_marked_is_the_diagrams_at_phi1():
    """1/479: the ICE diagram at φ1 = 150° gives p = 0.05 P_max = 0.14 MPa (table 1.1's P_max =
    2.8 MPa), the point drawn on the figure at its stated scales; the key's F_p = 669 N from it."""
    p = sheet_pack(1, "479")
    figure = next(x for k, x in p.sheet if k == "figure")
    (x, y, label), = figure.marks
    assert (x, y) == pytest.approx((150.0, 0.14)) and "p = 0,14 МПа" in label
    assert (figure.mu_x, figure.mu_y) == (2.5, 0.05) and "μ_p = 0,05 МПа/мм" in figure.scales
    assert key_values(p)["F_p"] == "669"


def _plan_scales(blocks) -> list:
    return [x.rows for k, x in blocks if k == "table" and x.head[0] == text("pack.plan", "uk") and len(x.head) == 2]


def test_the_sheet_gives_the_scales_where_the_pack_chose_them():
    """Where the plans are drawn coarser than the texts' rule (here μ_F against a rule twice as
    fine), the sheet lists every plan's scales as the key does; at the rule's scales it lists none."""
    coarse = sheet_pack(2, "479", finer_rule="mu_F")
    assert [s.symbol for _, s, _ in coarse.a3.coarsened()] == ["mu_F"]
    sheet_scales = _plan_scales(after(coarse.sheet, "pack.use_scales", "uk"))
    assert sheet_scales == _plan_scales(coarse.key) and any("μ_F = " in r[1] for r in sheet_scales[0])
    plain = sheet_pack(2, "479")
    assert not plain.a3.coarsened() and not any(x == text("pack.use_scales", "uk") for k, x in plain.sheet if k == "h2")


@pytest.mark.slow
def test_the_sheet_of_2_479_gives_the_scales_one_sheet_chose():
    """2/479 as `kinetostat variant` packs it: one A3 sheet takes μ_l, μ_a, μ_F coarser than the
    rule (the key says so), and the sheet gives the student every plan's scales, μ_F = 100 N/mm."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        p = P.pack(variants.variant(2, "479"), lang="uk", draws=20)
    assert {s.symbol for _, s, _ in p.a3.coarsened()} == {"mu_l", "mu_a", "mu_F"}
    sheet_scales = _plan_scales(after(p.sheet, "pack.use_scales", "uk"))
    assert sheet_scales == _plan_scales(p.key) and any("μ_F = 100 Н/мм" in r[1] for r in sheet_scales[0])


@pytest.mark.parametrize("task, code", [(1, "479"), (2, "479"), (3, "123")])
def test_the_pressure_diagram_is_lettered_at_the_sheets_least_size_and_nothing_collides(task, code):
    """The diagram's texts (ticks, axes' names, scales, the mark's label) at the sheets' least font
    size, capitals >= 2.5 mm (ГОСТ 2.304; were 1.8 mm), in the PDF and the HTML's SVG; no two texts'
    boxes overlap, and no mark's label lies on a curve or on the mark's own lines."""
    import numpy as np
    from kinetostat.model.lettering import lettering
    from kinetostat.plans import givens as G
    from kinetostat.plans.labels import CAP, MIN_TEXT_MM
    v = variants.variant(task, code)
    mech = v.mechanism()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = kinetostat.analyze(mech, phi_deg=[float(v.values["phi1"])])
    (d,) = {g.diagram for g in G.diagrams(mech, res, float(v.values["d"]), "uk", lettering(mech))}
    lines, paths, dots, texts = G.layout(d)
    assert CAP * G._SIZE >= 2.5 and G._SIZE == MIN_TEXT_MM
    assert f'font-size="{MIN_TEXT_MM}"' in G.svg(d) and "F_p" not in G.svg(d)          # its symbols set with scripts
    boxes = [G.text_box(*t) for t in texts]
    for i, a in enumerate(boxes):
        for b in boxes[:i]:
            assert min(a[2], b[2]) <= max(a[0], b[0]) or min(a[3], b[3]) <= max(a[1], b[1]), (a, b)
    drawn = np.concatenate([np.linspace(p, q, 50) for pts, _ in paths for p, q in zip(pts, pts[1:])]
                           + [np.linspace((a, b), (c, e), 50) for a, b, c, e, *_ in lines])
    for t in texts[-len(d.marks):]:
        x0, y0, x1, y1 = G.text_box(*t)
        assert not ((x0 < drawn[:, 0]) & (drawn[:, 0] < x1) & (y0 < drawn[:, 1]) & (drawn[:, 1] < y1)).any(), t   # a leader ends at its corner


def test_the_russian_sheet_and_key_letter_the_balancing_moment_m_ur():
    """1/479 in Russian: the tables to fill in and the key's tables write M_ур, F'_ур, M'_ур (Russian
    texts' уравновешивающий; the model's Ukrainian text letters M_зр), the statement M_ур; no зр left."""
    p = sheet_pack(1, "479", lang="ru")
    cells = {c for blocks in (p.sheet, p.key) for k, x in blocks if k == "table" for row in x.rows for c in row}
    texts = " ".join(x for blocks in (p.sheet, p.key) for k, x in blocks if k in ("h1", "h2", "p"))
    assert {"M_ур", "F'_ур", "M'_ур"} <= cells and "M_ур" in texts
    assert not [c for c in cells if "зр" in c] and "зр" not in texts
