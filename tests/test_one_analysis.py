"""Issue 34 item 1: a drawing command analyses its model once per friction mode (`plans.solution.solve`)
and every plan, sheet, page and pack is built from that result; nothing else in `kinetostat/plans`
calls the solver."""
from __future__ import annotations

import ast
import warnings
from collections import Counter

import numpy as np
import pytest

import kinetostat
import kinetostat.solve as S
from conftest import ROOT
from kinetostat import variants
from kinetostat.cli import main
from kinetostat.plans.solution import Positions, positions, solve


@pytest.fixture
def calls(monkeypatch) -> Counter:
    """Counts `kinetostat.solve.analyze` calls by friction mode ("first" unless asked)."""
    seen: Counter = Counter()
    real = S.analyze

    def counted(*a, **k):
        seen[k.get("friction") or "first"] += 1
        return real(*a, **k)
    monkeypatch.setattr(S, "analyze", counted)
    return seen


def test_only_the_solution_module_calls_the_solver():
    """No module of kinetostat/plans but solution.py calls `analyze` (found in the syntax tree, not in text)."""
    callers = []
    for path in sorted((ROOT / "kinetostat" / "plans").glob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Call) and getattr(node.func, "id", getattr(node.func, "attr", None)) == "analyze":
                callers.append(f"{path.name}:{node.lineno}")
    assert callers and [c for c in callers if not c.startswith("solution.py:")] == []


@pytest.mark.parametrize("model, modes", [("slotted_link_shaper", {"first": 1}),
                                          ("ice_crank_slider", {"first": 1, "reactions": 1})])   # [friction]: its worksheet's rows
def test_plans_at_an_angle_analyses_once_per_friction_mode(calls, tmp_path, model, modes):
    """`kinetostat plans MODEL --at 30` (the sheets and the worksheet): one analysis per friction mode
    (before: 16 for the ICE, the starting position's search alone 10)."""
    assert main(["plans", str(ROOT / "models" / f"{model}.toml"), "--at", "30", "--out", str(tmp_path / "p")]) == 0
    assert dict(calls) == modes


def test_plans_with_cycle_scales_and_friction_analyse_once_per_mode(calls, tmp_path):
    """--cycle-scales (the page's scales) and --friction reactions add no analysis: the cycle's scales
    from the one frictionless analysis, the plans and worksheet from the one with friction."""
    assert main(["plans", str(ROOT / "models" / "ice_crank_slider.toml"), "--at", "100", "--friction", "reactions",
                 "--cycle-scales", "--out", str(tmp_path / "p")]) == 0
    assert dict(calls) == {"first": 1, "reactions": 1}


def test_worksheet_and_page_analyse_once(calls):
    """The worksheet and a page (one frame): one analysis each (the ICE's worksheet: one per friction mode)."""
    from kinetostat.plans.page import page
    from kinetostat.plans.worksheet import worksheet
    worksheet(kinetostat.load("ice_crank_slider"), 30.0)
    assert dict(calls) == {"first": 1, "reactions": 1}
    calls.clear()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        page(kinetostat.load("slotted_link_shaper"), angles=[0.0])
    assert dict(calls) == {"first": 1}


@pytest.mark.parametrize("teacher_pack", [False, pytest.param(True, marks=pytest.mark.slow)])
def test_a_variants_key_analyses_once(calls, tmp_path, teacher_pack):
    """A variant's key (plans, worksheet, cycle.csv) and with it its teacher's pack (the A3 sheet's
    search builds the plans at each try): one analysis (before: 48 with the pack)."""
    variants.write_key(variants.variant(1, "479"), tmp_path / "key", lang="en", teacher_pack=teacher_pack)
    assert dict(calls) == {"first": 1}


def test_the_search_between_grid_angles_solves_positions_alone():
    """The starting position's refinement and the 12 positions read `Positions` (kinematics only):
    the same points as the analysis at those angles; a part at an angle not analysed: ValueError."""
    mech = kinetostat.load("ice_crank_slider")
    phi = [12.345, 200.0]
    pos, res = positions(mech, phi), kinetostat.analyze(mech, phi_deg=phi)
    assert isinstance(pos, Positions)
    for name in mech.point_names:
        assert np.array_equal(pos.position(name), res.position(name))
    sol = solve(mech, [30.0], other=False)
    assert sol.res.phi_deg.tolist() == [30.0] and sol.other is None
    with pytest.raises(ValueError, match="not an angle of"):
        sol.sub([31.0])
