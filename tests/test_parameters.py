"""Parametric model files: the `[parameters]` table, numeric fields written as expressions, the
helpers of the texts, overrides by name, the seed models rewritten with the texts' data (same
results as before), and the chain-unit study over the paper's crank lengths and speeds."""
from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

import kinetostat
from conftest import FOUR_BAR, ROOT
from kinetostat.expressions import ExpressionError, gear_wheel_mass, parse, resolve
from kinetostat.report.writer import study_table

CHAIN = ROOT / "models" / "chain_unit_four_bar.toml"

#: Every bundled model's results before its data were rewritten as parameters (the committed files
#: of e1a1d1a, analysed at 360 angles): sum |R|, max |R|, sum |M_bal|, max |M_bal|, sum R^2.
BEFORE = {
    "chain_unit_four_bar": [286343.9168976229, 278.8508096357083, 1969.2693244629513, 12.104518611584947,
                            45842394.33557887],
    "compressor": [1770539.5446107907, 4802.465343419963, 13299.103849627667, 173.1386633613171,
                   4091056229.856123],
    "furnace_loader_six_bar": [2385973.161319136, 3328.3456666341144, 33624.45825105438, 302.93047719649735,
                               4442404074.056863],
    "ice_crank_slider": [6398978.474503269, 7957.348258882439, 30847.584897644043, 174.76345505158085,
                         24561351726.740463],
    "opposed_twin": [8237885.462527193, 10112.863413696636, 68934.39557905408, 363.23259697553124,
                     38150918005.813995],
    "rotating_slotted_link": [4187292.2003025776, 5180.530864430151, 52904.05250975165, 317.65342207281964,
                              8269243375.782669],
    "scotch_yoke": [173317.32681334615, 286.828921755418, 1720.7848693601404, 12.611695861393681,
                    35655834.349169314],
    "slotted_link_shaper": [4702903.367773654, 5219.463686150196, 59287.49676617111, 357.28080972724393,
                            11764796698.373758],
}


def _value(text: str, **values: float) -> float:
    return parse(text)(values)


def _problems(text: str, **kw) -> list[str]:
    with pytest.raises(kinetostat.ModelError) as exc:
        kinetostat.loads(text, **kw)
    return exc.value.located


PARAMETRIC = FOUR_BAR.replace("[drive]", """[parameters]
l_AB = "3.5 * r"
r = 0.1
G2 = "m2 * 9.81"
m2 = 2.0
[drive]""", 1)


# ----------------------------------------------------------------------------- the evaluator

@pytest.mark.parametrize("text, expected", [
    ("1 + 2 * 3 - 4 / 8", 6.5), ("-2 ** 2", -4.0), ("(1 + 1) ** 0.5", math.sqrt(2)), ("+3", 3.0),
    ("sqrt(16) + hypot(3, 4)", 9.0), ("degrees(atan2(1, 1))", 45.0), ("sin(radians(30))", 0.5),
    ("min(3, 1, 2) + max(1, 5) + abs(-2)", 8.0), ("exp(log(7))", 7.0), ("2 * pi", 2 * math.pi),
    ("acos(0) + asin(1)", math.pi), ("tan(atan(0.3))", 0.3), ("cos(0)", 1.0),
])
def test_arithmetic_and_functions(text, expected):
    assert _value(text) == pytest.approx(expected, rel=1e-15)


def test_helpers_give_the_texts_formulas():
    assert _value("bar_inertia(6.24, 0.52)") == pytest.approx(0.140608, rel=1e-15)       # m l^2 / 12
    assert _value("mass_from_density(12, 0.52)") == pytest.approx(6.24, rel=1e-15)       # q l
    assert _value("mass_from_weight(4.9, 9.81)") == 4.9 / 9.81                             # G / g
    assert _value("inertia_from_gyration(2, 0.1)") == pytest.approx(0.02, rel=1e-15)     # m rho^2
    # seed 000 sec. 7.2: m1 = 1.3 m_g; the furnace loader's wheel rim m_g = pi d_f2 S rho
    m_g = math.pi * 0.2875 * 6e-4 * 7100
    assert gear_wheel_mass(m_g) == pytest.approx(5.0020, abs=5e-5)


def test_parameters_read_each_other_in_any_order():
    values, problems = resolve({"a": "b * c", "b": "c + 1", "c": 2, "d": "a + b"})
    assert problems == {} and values == {"a": 6.0, "b": 3.0, "c": 2.0, "d": 9.0}
    assert list(values) == ["a", "b", "c", "d"]        # in the order given


def test_cycles_are_named():
    _, problems = resolve({"a": "b + 1", "b": "c * 2", "c": "a", "d": 1, "e": "d + a"})
    assert problems["a"] == 'expression "b + 1": cycle a -> b -> c -> a'
    assert "cycle" in problems["b"] and "cycle" in problems["c"]
    assert problems["e"] == "expression \"d + a\": reads 'a', which has an error"


@pytest.mark.parametrize("text, message", [
    ("().__class__", "attribute access not allowed"),
    ("(1).__class__", "attribute access not allowed"),
    ("__import__('os')", "call of '__import__' is not allowed"),
    ("open('x')", "call of 'open' is not allowed"),
    ("r[0]", "subscripts not allowed"),
    ("(lambda: 1)()", "call of 'lambdas' is not allowed"),
    ("[x for x in r]", "comprehensions not allowed"),
    ("'a'", "str literal 'a' is not allowed"),
    ("1j", "complex literal"),
    ("True + 1", "bool literal"),
    ("sqrt(x=4)", "positional arguments only"),
    ("sqrt(1, 2)", "sqrt() takes 1 argument, got 2"),
    ("max(1)", "max() takes at least 2 arguments"),
    ("1 if r else 2", "'if ... else' not allowed"),
    ("r < 1", "comparisons not allowed"),
    ("1 // 2", "operator FloorDiv is not allowed"),
    ("1 +", "syntax error"),
    ("1" + " + 1" * 200, "characters, at most 500"),
])
def test_what_is_not_arithmetic_is_refused(text, message):
    with pytest.raises(ExpressionError) as exc:
        parse(text)({"r": 1.0})
    assert message in str(exc.value)


@pytest.mark.parametrize("text, message", [
    ("10 ** 10 ** 10", "exponent 1e+10 is too large"),
    ("9.9 ** 999", "too large (overflow)"),
    ("1e308 * 10", "not a finite number"),
    ("1 / 0", "division by zero"),
    ("sqrt(-1)", "math domain error"),
    ("(-8) ** (1 / 3)", "not real"),
    ("exp(1000)", "too large (overflow)"),
    ("1" * 400, "too large (overflow)"),
])
def test_huge_or_non_finite_results_are_refused(text, message):
    with pytest.raises(ExpressionError) as exc:
        parse(text)({})
    assert message in str(exc.value)


def test_unknown_names_are_refused_with_a_suggestion():
    with pytest.raises(ExpressionError, match=r"unknown name 'g_' \(did you mean 'g'\?\)"):
        parse("G2 / g_")({"G2": 4.9, "g": 9.81})
    with pytest.raises(ExpressionError, match=r"'sqrt' is a function: call it"):
        parse("sqrt + 1")({})


# ----------------------------------------------------------------------------- in a model file

def test_fields_read_parameters_and_the_mechanism_keeps_both():
    text = PARAMETRIC.replace("B = [0.35, 0.0]", 'B = ["l_AB", 0.0]', 1).replace(
        "mass = 1.5", 'mass = "mass_from_weight(G2, g)"', 1)
    assert text.count('"l_AB"') == 1 and "mass_from_weight" in text
    m = kinetostat.loads(text)
    assert dict(m.parameters) == {"l_AB": 0.35000000000000003, "r": 0.1, "G2": 2.0 * 9.81, "m2": 2.0}
    assert m.links[2].points["B"] == (3.5 * 0.1, 0.0) and m.links[2].mass == pytest.approx(2.0, rel=1e-15)
    assert m.expressions["link[id=2].points.B[0]"] == ("l_AB", 3.5 * 0.1)
    assert m.expressions["parameters.l_AB"] == ("3.5 * r", 3.5 * 0.1)
    assert m.expressions["link[id=2].mass"][0] == "mass_from_weight(G2, g)"
    with pytest.raises(TypeError):
        m.parameters["r"] = 1.0                          # read-only
    # the same model with a parameter overridden by name: what reads it follows
    m2 = kinetostat.loads(text, parameters={"r": 0.2})
    assert m2.parameters["l_AB"] == pytest.approx(0.7) and m2.links[2].points["B"][0] == pytest.approx(0.7)


def test_errors_name_the_field_the_parameter_and_the_line():
    text = PARAMETRIC.replace("mass = 1.5", 'mass = "G2 / g_"', 1)
    (problem,) = _problems(text)
    line = next(n for n, s in enumerate(text.splitlines(), 1) if "g_" in s)
    assert problem == f"line {line}: link[id=2].mass: expression \"G2 / g_\": unknown name 'g_' (did you mean 'g'?)"
    text = PARAMETRIC.replace('"3.5 * r"', '"3.5 * rr"', 1).replace("B = [0.35, 0.0]", 'B = ["l_AB", 0.0]', 1)
    problems = _problems(text)
    assert problems[0].endswith("parameters.l_AB: expression \"3.5 * rr\": unknown name 'rr' (did you mean 'r'?)")
    assert problems[0].startswith(f"line {next(n for n, s in enumerate(text.splitlines(), 1) if 'rr' in s)}:")
    assert problems[1].endswith("link[id=2].points.B[0]: expression \"l_AB\": reads 'l_AB', which has an "
                                "error (see parameters.l_AB)")


@pytest.mark.parametrize("old, new, message", [
    ('r = 0.1', 'r = "m2 * l_AB"', "parameters.r: expression \"m2 * l_AB\": cycle "),
    ('r = 0.1', 'r = "().__class__"', 'parameters.r: expression "().__class__": attribute access not allowed'),
    ('r = 0.1', "r = \"__import__('os')\"", "parameters.r: expression \"__import__('os')\": call of '__import__'"),
    ('r = 0.1', 'r = "10 ** 10 ** 10"', 'parameters.r: expression "10 ** 10 ** 10": exponent 1e+10 is too large'),
    ('r = 0.1', 'r = "1e300 * 1e300"', 'parameters.r: expression "1e300 * 1e300": the result inf is not'),
    ('r = 0.1', 'r = "' + "1 + " * 150 + '1"', "parameters.r: expression \"1 + 1 + "),
    ('r = 0.1', 'g = 9.81', "parameters.g: g is mechanism.g"),
    ('r = 0.1', 'sqrt = 1.0', "parameters.sqrt: 'sqrt' is the name of a function"),
    ('r = 0.1', 'r = [0.1]', "parameters.r: expected a number or an expression string, got [0.1]"),
    ("mass = 1.5", 'mass = "-m2"', 'link[id=2].mass: must be >= 0.0, got -2.0 (= "-m2")'),
])
def test_refusals_in_a_model_name_the_parameter_or_field(old, new, message):
    problems = _problems(PARAMETRIC.replace(old, new, 1))
    assert any(message in p for p in problems), problems


def test_g_is_mechanism_g_and_may_be_an_expression_too():
    m = kinetostat.loads(PARAMETRIC.replace("g = 9.81", 'g = "G2 / m2"', 1))
    assert m.g == 9.81 and m.expressions["mechanism.g"] == ("G2 / m2", 9.81)
    text = PARAMETRIC.replace("g = 9.81", 'g = "G2 / m2"', 1).replace('"m2 * 9.81"', '"m2 * g"', 1)
    problems = _problems(text)
    assert any(p.endswith('parameters.G2: expression "m2 * g": cycle G2 -> g -> G2') for p in problems), problems
    assert any("mechanism.g: expression \"G2 / m2\": reads 'G2', which has an error" in p for p in problems)


def test_overrides_of_unknown_names_are_refused_with_a_suggestion():
    problems = _problems(PARAMETRIC, parameters={"rr": 0.2})
    assert any("parameters: cannot override 'rr': the model has no such parameter (did you mean 'r'?)" in p
               for p in problems), problems
    with pytest.raises(kinetostat.ModelError, match="cannot override 'n_kk'.*did you mean 'n_k'"):
        kinetostat.load(CHAIN, parameters={"n_kk": 60})


# ----------------------------------------------------------------------------- the seed models

@pytest.mark.parametrize("name", sorted(BEFORE))
def test_every_bundled_model_gives_its_results_from_before_the_rewrite(name):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = kinetostat.analyze(kinetostat.load(name), steps=360)
    R, M = np.asarray(res.forces.R), np.asarray(res.balancing_moment)
    now = [np.nansum(np.abs(R)), np.nanmax(np.abs(R)), np.nansum(np.abs(M)), np.nanmax(np.abs(M)), np.nansum(R**2)]
    np.testing.assert_allclose(now, BEFORE[name], rtol=1e-12, atol=0)


def test_the_rewritten_models_read_as_the_texts_give_them():
    ice = kinetostat.load("ice_crank_slider")
    assert ice.expressions["link[id=2].mass"] == ("mass_from_weight(G2, g)", 4.9 / 9.81)
    assert ice.parameters["l_AS2"] == 0.5 * 0.11 and ice.expressions["drive.rpm"] == ("n1", 4500.0)
    chain = kinetostat.load(CHAIN)
    assert chain.parameters["r"] == 0.08 and chain.parameters["n_k"] == 120.0
    assert chain.parameters["l"] == pytest.approx(0.5459, abs=5e-5)          # paper: l ~ 545.9 mm
    assert chain.drive.omega == pytest.approx(120 * math.pi / 30, rel=1e-15)


# ----------------------------------------------------------------------------- the chain-unit study

def test_the_chain_unit_study_keeps_the_published_range_at_r_80_n_120():
    m = kinetostat.load(CHAIN, parameters={"r": 0.08, "n_k": 120})
    F = np.linalg.norm(kinetostat.analyze(m, phi_deg=np.arange(0.0, 360.0, 10.0)).reaction(0, 1), axis=-1)
    assert F.min() == pytest.approx(38.4, rel=0.01) and F.max() == pytest.approx(286.9, rel=0.01)
    table = study_table(kinetostat.load(CHAIN))
    assert table.shape == (5, 5)
    assert table[2, 2] == F.max()                                # r = 80 mm, n_k = 120 rpm
    assert np.all(np.diff(table, axis=1) > 0) and np.all(np.diff(table, axis=0) > 0)   # grows with r and n_k


def test_the_chain_unit_at_standstill_is_in_static_equilibrium():
    """n_k = 0: the reactions balance the weights alone; checked against the nine equilibrium
    equations of the three links solved here (positions from the kinematics)."""
    m = kinetostat.load(CHAIN, parameters={"n_k": 0, "r": 0.11})
    phi = np.arange(0.0, 360.0, 30.0)
    res = kinetostat.analyze(m, phi_deg=phi)
    P = {n: res.position(n) for n in ("O1", "A", "C1", "C2", "B", "S3", "O2")}
    W = [np.array([0.0, -m.g * m.links[k].mass]) for k in (1, 2, 3)]

    def cross_row(r):       # the moment of a force F about a point, r x F = [-r_y, r_x] . F
        return [-r[1], r[0]]

    def _cross(r, F):
        return r[0] * F[1] - r[1] * F[0]

    for n in range(len(phi)):
        p = {k: v[n] for k, v in P.items()}
        A = np.zeros((9, 9))
        b = np.zeros(9)
        # unknowns: F_O1 (0 on 1), F_A (1 on 2), F_B (2 on 3), F_O2 (0 on 3), M (on the crank)
        A[0:2, 0:2], A[0:2, 2:4], b[0:2] = np.eye(2), -np.eye(2), -W[0]
        A[2, 2:4], A[2, 8], b[2] = np.negative(cross_row(p["A"] - p["O1"])), 1.0, -_cross(p["C1"] - p["O1"], W[0])
        A[3:5, 2:4], A[3:5, 4:6], b[3:5] = np.eye(2), -np.eye(2), -W[1]
        A[5, 4:6], b[5] = np.negative(cross_row(p["B"] - p["A"])), -_cross(p["C2"] - p["A"], W[1])
        A[6:8, 4:6], A[6:8, 6:8], b[6:8] = np.eye(2), np.eye(2), -W[2]
        A[8, 4:6], b[8] = cross_row(p["B"] - p["O2"]), -_cross(p["S3"] - p["O2"], W[2])
        x = np.linalg.solve(A, b)
        np.testing.assert_allclose(res.reaction(0, 1)[n], x[0:2], rtol=0, atol=1e-9 * np.abs(x).max())
        np.testing.assert_allclose(res.reaction(0, 3)[n], x[6:8], rtol=0, atol=1e-9 * np.abs(x).max())
        assert res.balancing_moment[n] == pytest.approx(x[8], rel=0, abs=1e-9 * np.abs(x).max())   # about +z


# ----------------------------------------------------------------------------- what is printed

def test_structure_prints_the_numbers_the_expressions_produced(cli):
    r = cli("structure", "models/ice_crank_slider.toml")
    assert r.returncode == 0
    assert "parameters: n1 = 4500, l_OA = 0.036, l_AB = 0.11, AS2_AB = 0.5, l_AS2 = 0.055" in r.stdout
    assert "  link[id=2].mass = mass_from_weight(G2, g) = 0.499490316" in r.stdout
    assert "  load[0].table.scale = pi / 4 * d**2 * p_max = 12063.71579" in r.stdout


def test_the_report_prints_the_parameters_their_numbers_and_the_study(tmp_path, sketched_plots):
    pytest.importorskip("matplotlib")
    from kinetostat.report import run_validation, write_report
    mech = kinetostat.load(CHAIN)
    write_report(run_validation(mech, [], steps=36, path=CHAIN), tmp_path)
    md = (tmp_path / "chain_unit_four_bar" / "index.md").read_text()
    assert "| l | sqrt(r\\*\\*2 + c\\*\\*2) | 0.5458937626 |" in md       # markdown-escaped
    assert "| link\\[id=3\\].body\\[1\\].mass | m_tb | 12.749 |" in md and "| m_tb | number | 12.749 |" in md
    assert "## Parameter study" in md
    row = next(s for s in md.splitlines() if s.startswith("| 0.08 |"))
    assert row.split("|")[4].strip() == f"{study_table(mech)[2, 2]:.1f}" == "287.7"
