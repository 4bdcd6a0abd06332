"""Accuracy near singular positions (issue 13, items 1 and 2), against the 40-digit mpmath
reference of validation/reference.py.

On a sample of each family of validation/stability.py `NEAR` (a handful of angles close to the
singular one): wherever the solver returns a value its error is within the guard's estimate,
and the solver's error is never more than 10 times what one ulp of one input (a coordinate of a
point, the crank angle) does to the exact answer. The audit's cases give a warning with the
digits left, or NaN. The singular-position measure does not depend on a point that plays no
part in any group.
"""
from __future__ import annotations

import copy
import warnings

import numpy as np
import pytest

import kinetostat
from kinetostat import DIGITS_MIN, DIGITS_WARN, SingularPositionWarning
from kinetostat.kinematics import kinematics
from kinetostat_validation.reference import reference_full
from kinetostat_validation.stability import NEAR, crank_slider, four_bar, measure, slotted_link, unguarded

#: family -> (parameter, angles): a few angles where the accuracy is measured, kept, warned and NaN
SAMPLE = {
    "grashof": (1e-8, [179.9, 180.0]),
    "change_point": (0.0, [175.0, 179.0, 179.99]),
    "crank_slider": (1e-8, [89.99, 90.0]),
    "slotted_link": (1e-4, [89.999, 90.0]),
}


def _analyze(mech, phi):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", SingularPositionWarning)
        res = kinetostat.analyze(mech, phi_deg=phi)
    return res, [w.message for w in caught if issubclass(w.category, SingularPositionWarning)]


@pytest.mark.parametrize("family", list(SAMPLE))
def test_error_within_the_estimate_and_the_inputs_ulps(family):
    value, phi = SAMPLE[family]
    near = measure(family, value, NEAR[family][3](value), phi)
    kept = ~near.singular
    assert kept.any()
    assert (near.err[kept] <= near.estimate[kept]).all(), (near.err, near.estimate)
    # the formulation: never more than 10 x the change one ulp of one input makes (1e-15: rounding)
    assert (np.maximum(near.err, 1e-15) <= 10 * np.maximum(near.sens, 1e-15)).all(), (near.err, near.sens)
    # warned exactly where fewer than DIGITS_WARN digits are estimated left
    np.testing.assert_array_equal(near.warned, near.estimate > 10.0**-DIGITS_WARN)


def test_change_point_four_bar_warns_with_digits_or_nan():
    """The audit: a change-point four-bar kept 7 digits at cond 433 without a warning, and was
    1.5 % off at cond 4.6e4 and 2.3 % at cond 6e4 with values kept."""
    mech = kinetostat.from_dict(four_bar(0.2, 0.2))
    phi = np.array([179.695, 179.99713, 179.9978])
    res, warned = _analyze(mech, phi)
    np.testing.assert_allclose(res.cond[:, 0], [434, 4.61e4, 6.01e4], rtol=0.01)
    assert len(warned) == 1 and list(warned[0].phi_deg) == list(phi)
    assert list(res.singular) == [False, True, True]
    assert 6 < res.digits[0] < DIGITS_WARN and np.isfinite(res.balancing_moment[0])
    assert np.isnan(res.balancing_moment[1:]).all() and np.isnan(res.forces.R[1:]).all()
    # the digits stated at 179.695 are there, against the reference
    ref = reference_full(mech, phi[:1], res=res.take([0]), angle="double")
    R, R_ref = res.forces.R[0], ref.R[0]
    err = np.max(np.linalg.norm(R - R_ref, axis=-1)) / np.max(np.linalg.norm(R_ref, axis=-1))
    assert err <= res.error[0]
    # and the dropped values were as bad as estimated: percent-level at 179.99713
    raw = unguarded(mech, phi[1:2])
    ref = reference_full(mech, phi[1:2], res=raw, angle="double")
    assert np.max(np.abs(raw.forces.R[0] - ref.R[0])) / np.max(np.abs(ref.R[0])) > 1e-4


def test_kinematics_alone_is_guarded():
    mech = kinetostat.from_dict(four_bar(0.2, 0.2))
    with pytest.warns(SingularPositionWarning, match=r"estimated significant digits left"):
        kin = kinematics(mech, np.radians([90.0, 179.99]))
    assert list(kin.singular) == [False, True]
    assert np.isnan(kin.eps[1, 2]) and np.isfinite(kin.eps[0]).all()
    assert kin.digits[0] > DIGITS_WARN and kin.digits[1] < DIGITS_MIN


def test_slotted_link_peak_does_not_come_from_the_near_pivot_angle():
    """The block passes 4.4e-6 m from the pivot at 90 deg: there the answer moves by ~1e-2 for
    one ulp of the crank angle. The solver's value at 90 deg would be the cycle's peak of
    |M_bal|; the guard drops it, and the peak comes from an angle with its digits."""
    mech = kinetostat.from_dict(slotted_link(4.4e-5))
    res, warned = _analyze(mech, None)
    at90 = res.phi_deg == 90.0
    assert np.argmax(np.abs(unguarded(mech, res.phi_deg).balancing_moment)) == np.flatnonzero(at90)[0]
    assert res.singular[at90].all() and not res.singular[~at90].any()
    assert len(warned) == 1 and list(warned[0].phi_deg) == [90.0] and warned[0].digits[0] < DIGITS_MIN
    peak = np.nanargmax(np.abs(res.balancing_moment))
    assert res.phi_deg[peak] != 90.0 and res.digits[peak] >= DIGITS_WARN


@pytest.mark.parametrize("build", [lambda: crank_slider(3.5), lambda: slotted_link(0.5), lambda: four_bar()],
                         ids=["RRP", "RPR", "RRR"])
@pytest.mark.parametrize("far", [1e4, 1e5])
def test_far_unused_point_changes_nothing(build, far):
    """Issue 13 item 2: a point of no pair 10 km (100 km) away on the crank made every angle
    'near singular' (every value NaN): the length scale of a group now counts joint points only."""
    data = build()
    with_far = copy.deepcopy(data)
    with_far["link"][0]["points"]["FAR"] = [far, 0.0]
    with warnings.catch_warnings():
        warnings.simplefilter("error", SingularPositionWarning)
        a = kinetostat.analyze(kinetostat.from_dict(data), steps=72)
        with pytest.warns(kinetostat.ModelWarning, match="was the model drawn in millimetres"):
            far_mech = kinetostat.from_dict(with_far)        # a 10 km link is asked about, rightly
        b = kinetostat.analyze(far_mech, steps=72)
    np.testing.assert_array_equal(a.cond, b.cond)
    np.testing.assert_array_equal(a.singular, b.singular)
    np.testing.assert_array_equal(a.error, b.error)
    assert not b.singular.any() and b.cond.max() < 10
    np.testing.assert_allclose(b.forces.R, a.forces.R, rtol=0, atol=1e-12 * np.abs(a.forces.R).max())
    np.testing.assert_allclose(b.balancing_moment, a.balancing_moment, rtol=1e-12)
