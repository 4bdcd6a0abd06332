"""The scale of the plan of positions (seed 002 sec. 1.2.2: OA taken about 30..35 mm, mu_l = l_OA / OA;
its worked example takes 36 mm for a round 0.001, so 30..36 mm)
over every code of the three tasks of Logvinenko, Nadtoka 2021 (tables 1.1-1.3)."""
import math

import pytest

import kinetostat
from kinetostat import variants
from kinetostat.plans.scales import LENGTH_MANTISSAS, choose_scales, length_scale


def test_every_code_of_every_task_draws_oa_30_to_36_mm():
    """All 3000 codes: the arithmetic of the rule on the tables' l_OA (no analysis)."""
    drawn = [variants.values(t, c)["l_OA"] / length_scale(variants.values(t, c)["l_OA"])
             for t in variants.TASKS for c in variants.codes()]
    assert len(drawn) == 3000
    assert 30.0 - 1e-9 <= min(drawn) and max(drawn) <= 36.0 + 1e-9


@pytest.mark.parametrize("l_oa, mu, oa_mm", [
    (0.048, 0.0015, 32.0),       # GOST 1:1.5 lands in range
    (0.034, 0.001, 34.0),        # a round 1 lands in range
    (0.036, 0.001, 36.0),        # the worked example's own scale and OA
    (0.09, 0.0025, 36.0),        # GOST 1:4 (x 10^-2) before the one-digit 0.003
    (0.029, 0.0009, 32.222),     # one digit before two: no GOST value lands in 30..36
    (0.042, 0.0013, 32.308)])
def test_the_rule_takes_the_roundest_scale_in_range(l_oa, mu, oa_mm):
    assert length_scale(l_oa) == mu
    assert l_oa / mu == pytest.approx(oa_mm, abs=1e-3)


def test_a_gost_value_wins_over_a_nearer_two_digit_one():
    """l_OA = 0.045: 1.5e-3 draws 30 mm (GOST 1:15), 1.4e-3 would draw 32.1 mm, nearer the middle."""
    mu = length_scale(0.045)
    m = mu / 10 ** math.floor(math.log10(mu))
    assert any(math.isclose(m, g) for g in LENGTH_MANTISSAS) and mu == 0.0015


@pytest.mark.parametrize("task, code", [(1, "036"), (2, "123"), (3, "123"), (2, "479")])
def test_choose_scales_uses_the_rule_for_a_sample_of_codes(task, code):
    v = variants.variant(task, code)
    mech = v.mechanism()
    sc = choose_scales(mech, kinetostat.analyze(mech, phi_deg=[v.values["phi1"]]))
    assert 30.0 <= v.values["l_OA"] / sc["mu_l"].value <= 36.0
