"""Structure formulas of the bundled models (seed 000 sec. 5; seed 002 sec. 1.2.1)."""
from __future__ import annotations

import pytest

import kinetostat
from conftest import ROOT

EXPECTED = {
    "ice_crank_slider": ("I(0,1) <- II(2,3)", ["RRP"], 3, 4),
    "compressor": ("I(0,1) <- II(2,3)", ["RRP"], 3, 4),
    "chain_unit_four_bar": ("I(0,1) <- II(2,3)", ["RRR"], 3, 4),
    "opposed_twin": ("I(0,1) <- II(2,3) <- II(4,5)", ["RRP", "RRP"], 5, 7),
    "slotted_link_shaper": ("I(0,1) <- II(2,3) <- II(4,5)", ["RPR", "PRP"], 5, 7),
    "rotating_slotted_link": ("I(0,1) <- II(2,3) <- II(4,5)", ["RPR", "RRP"], 5, 7),
    "furnace_loader_six_bar": ("I(0,1) <- II(2,3) <- II(4,5)", ["RRR", "RRP"], 5, 7),
    "scotch_yoke": ("I(0,1) <- II(2,3)", ["RPP"], 3, 4),
    "triad_six_bar": ("I(0,1) <- III(2,3,4,5)", ["RRR"], 5, 7),
    "triad_slider": ("I(0,1) <- III(2,3,4,5)", ["RRP"], 5, 7),
    "triad_rocking_block": ("I(0,1) <- III(2,3,4,5)", ["RRR"], 5, 7),
}


def test_every_bundled_model_has_an_expected_formula(model_path):
    assert model_path.stem in EXPECTED


@pytest.mark.parametrize("stem", sorted(EXPECTED))
def test_structure_formula(stem):
    formula, kinds, n, p5 = EXPECTED[stem]
    s = kinetostat.load(ROOT / "models" / f"{stem}.toml").structure
    assert s.formula == formula
    assert [g.kind for g in s.groups] == kinds
    assert (s.n, s.p5, s.p4, s.W) == (n, p5, 0, 1)       # Chebyshev: W = 3n - 2p5 - p4 = 1
    klass = 3 if formula.count("III") else 2
    assert (s.mechanism_class, s.order) == (klass, klass)


def test_seed_002_structure_text():
    s = kinetostat.load(ROOT / "models" / "ice_crank_slider.toml").structure
    assert str(s) == ("W = 3*3 - 2*4 - 0 = 1; I(0,1) <- II(2,3); class 2, order 2; "
                      "groups: II(2,3) RRP (kind 2)")
