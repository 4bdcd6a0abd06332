"""The accuracy gate: every bundled model x every engine route over a full cycle, and proof
that the gate fails on a wrong solver result."""
from __future__ import annotations

import dataclasses

import pytest

import kinetostat
from kinetostat_validation import compare as cmp
from conftest import FOUR_BAR

pytest.importorskip("pinocchio")
pytest.importorskip("mujoco")
pytest.importorskip("pymunk")


def test_every_route_passes_on_every_bundled_model(mech):
    c = cmp.compare(mech, steps=360)
    assert not c.skipped
    assert set(c.results) == set(cmp.ROUTES)
    failed = [(r.route, r.quantity, r.peak_relative) for r in c.rows if not r.passed]
    assert not failed
    # every pair and the drive are compared by every route, at every angle
    assert len(c.rows) == len(cmp.ROUTES) * (1 + len(mech.pairs))
    for r in c.rows:
        if r.route in ("pinocchio", "mujoco"):
            assert r.n_compared == 360 and r.peak_relative < 1e-9


@pytest.fixture(scope="module")
def four_bar():
    return kinetostat.loads(FOUR_BAR)


def test_a_perturbed_reaction_is_caught(four_bar):
    res = kinetostat.analyze(four_bar, steps=72)
    R = res.forces.R.copy()
    R[:, four_bar.pair_between(2, 3).index] *= 1.01            # one reaction 1 % off
    bad = dataclasses.replace(res, forces=dataclasses.replace(res.forces, R=R))
    c = cmp.compare(four_bar, engines=("pinocchio", "mujoco", "pymunk"), res=bad)
    assert not c.passed
    failing = {(r.route, r.quantity) for r in c.rows if not r.passed}
    assert failing == {("pinocchio", "R(2,3)"), ("mujoco", "R(2,3)"), ("pymunk", "R(2,3)")}


def test_a_dropped_inertia_is_caught(four_bar):
    """The solver run on a model whose coupler lost its moment of inertia, engines on the true one."""
    wrong = kinetostat.loads(FOUR_BAR.replace("I_S = 0.016", "I_S = 0.0"))
    c = cmp.compare(four_bar, engines=("pinocchio", "mujoco"), res=kinetostat.analyze(wrong, steps=72))
    assert not c.passed
    assert {r.quantity for r in c.rows if not r.passed} >= {"M_drive", "R(1,2)"}


def test_missing_engine_is_skipped_not_passed(four_bar, monkeypatch):
    monkeypatch.setitem(cmp.ROUTES, "pymunk", ("no_such_engine_package", cmp.ROUTES["pymunk"][1]))
    c = cmp.compare(four_bar, engines=("pinocchio", "pymunk"), steps=36)
    assert "pymunk" in c.skipped and "no_such_engine_package" in c.skipped["pymunk"]
    assert {r.route for r in c.rows} == {"pinocchio"}


def test_a_route_that_raises_fails_the_gate_but_not_the_others(four_bar, monkeypatch):
    def broken(scene):
        raise RuntimeError("engine crashed")
    monkeypatch.setitem(cmp.ROUTES, "pymunk", ("pymunk", broken))
    c = cmp.compare(four_bar, engines=("pinocchio", "pymunk"), steps=36)
    assert c.failed == {"pymunk": "RuntimeError: engine crashed"}
    assert all(r.passed for r in c.rows) and not c.passed


def test_unknown_route_is_named(four_bar):
    with pytest.raises(ValueError, match=r"unknown engine route\(s\) \['bullet'\]. Valid names: \['pinocchio'"):
        cmp.compare(four_bar, engines=("bullet",))


def test_tolerances_have_reasons():
    for route in cmp.ROUTES:
        tol = cmp.TOLERANCES[route]
        assert 0 < tol.peak_relative < 0.1 and len(tol.reason) > 40
