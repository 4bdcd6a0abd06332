"""The worksheet (issue 12, item 3): seed 002's published values at 30 deg, every value against
`analyze`, the senses by the text's own rule, every bundled model without NaN, the outputs."""
from __future__ import annotations

import json
import math

import numpy as np
import pytest

import kinetostat
from kinetostat.plans.worksheet import worksheet

# seed 002 sec. 1.2.2-1.2.3 at phi = 30 deg (drawn and measured: the text rounds)
SEED_002 = {"V_B": 10.94, "V_BA": 14.92, "V_S2": 12.2, "omega_2": 135.6, "a_A": 7994.38, "a_B": 8311,
            "a_S2": 7875, "eps_2": 33782, "F_i2": 3937.5, "F_i3": 3216.4, "M_i2": 57.43, "R_1_2": 3172,
            "R_0_3": 780.5, "R_3_2": 6481, "M_bal": 102.74, "M_bal_lever": 102.97}


@pytest.fixture(scope="module")
def ice_sheet():
    return worksheet(kinetostat.load("ice_crank_slider"), at=30.0, mu_l=0.001)     # the text's own OA = 36 mm


@pytest.mark.parametrize("key", SEED_002)
def test_seed_002_published_values(ice_sheet, key):
    assert abs(ice_sheet.value(key)) == pytest.approx(SEED_002[key], rel=0.005)


def test_seed_002_order_and_scale(ice_sheet):
    keys = [r.key for r in ice_sheet.rows]
    text_order = ["V_A", "V_B", "V_BA", "V_S2", "omega_2", "a_A", "an_BA", "at_BA", "a_B", "a_S2", "eps_2",
                  "m_2", "F_i2", "M_i2", "Rt_1_2", "R_1_2", "R_0_3", "R_3_2", "M_bal", "F_bal_lever", "M_bal_lever"]
    assert [k for k in keys if k in text_order] == text_order
    assert ice_sheet.mu_l == 0.001                       # seed 002: mu_l = 0.036 / 36, as given
    assert ice_sheet.value("Rt_1_2") == pytest.approx(1326.37, rel=0.005)
    assert ice_sheet.value("load_0") == pytest.approx(9650.97, rel=1e-6)     # F_p = 0.8 p_max pi d^2 / 4
    assert ice_sheet.value("h_R21") == pytest.approx(32.39, rel=0.005)       # the crank's arm, mm
    assert abs(ice_sheet.value("delta_pct")) < 1e-9


def test_senses_by_the_texts_rule(ice_sheet):
    """Seed 002: the sense of omega2 is that of B turning about A with V_BA moved to B; of eps2,
    that of a^tau_BA moved to B. Here from the worksheet's own vectors' directions."""
    res = kinetostat.analyze(kinetostat.load("ice_crank_slider"), phi_deg=[30.0])
    AB = res.position("B")[0] - res.position("A")[0]
    for key, sym in (("omega_2", "V_BA"), ("eps_2", "at_BA")):
        ang = math.radians(float(ice_sheet.row(sym).direction[6:]))
        turn = AB[0] * math.sin(ang) - AB[1] * math.cos(ang)
        assert ice_sheet.row(key).direction == ("ccw" if turn > 0 else "cw")
    assert ice_sheet.row("omega_2").direction == "ccw" and ice_sheet.row("eps_2").direction == "cw"
    assert ice_sheet.row("omega_1").direction == "cw"                     # the model's crank turns clockwise


def test_a_rod_at_rest_has_no_sense():
    """Task 2 of Logvinenko, Nadtoka 2021, variant 479, at phi = 90 deg: the rods translate,
    omega_2 is zero but for rounding (8e-15 rad/s, its sign rounding's), and the worksheet gives
    it no sense; at 60 deg it has one."""
    from kinetostat import variants
    mech = variants.variant(2, "479").mechanism()
    w1 = abs(kinetostat.analyze(mech, phi_deg=[90.0]).omega(1)[0])
    at_rest, moving = worksheet(mech, 90.0), worksheet(mech, 60.0)
    assert 0 < at_rest.value("omega_2") < 1e-12 * w1 and at_rest.row("omega_2").direction == ""
    assert moving.value("omega_2") > 0.1 and moving.row("omega_2").direction in ("cw", "ccw")
