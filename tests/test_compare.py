"""The accuracy gate: every bundled model x every engine route over a full cycle, and proof
that the gate fails on a wrong solver result."""
from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import kinetostat
from kinetostat_validation import compare as cmp
from conftest import FOUR_BAR, MODELS, ROOT, sampled

pytest.importorskip("pinocchio")
pytest.importorskip("mujoco")
pytest.importorskip("pymunk")


@pytest.mark.parametrize("path", sampled(MODELS))
def test_every_route_passes_on_every_bundled_model(path):
    """At 72 angles (every 5 deg): the simulations integrate at their own steps per revolution, so
    each angle's comparison is the one a 360-angle run makes there, at a fifth of the exact routes' cost."""
    mech = kinetostat.load(path)
    c = cmp.compare(mech, steps=72)
    assert not c.skipped
    assert set(c.results) == set(cmp.ROUTES)
    failed = [(r.route, r.quantity, r.peak_relative) for r in c.rows if not r.passed]
    assert not failed
    # every quantity (drive, pairs, F_bal, P_f, kinematics) is compared by every route, at every angle
    for route in cmp.ROUTES:
        assert [r.quantity for r in c.rows if r.route == route] == cmp.quantity_names(mech, route)
    for r in c.rows:
        if r.route in ("pinocchio", "mujoco"):
            assert r.n_compared == 72 and r.peak_relative < 1e-9


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


@pytest.mark.parametrize("name, expected", [
    ("compressor", {"F_bal"}),                                       # a working machine
    ("ice_crank_slider", {"P_f(0,1)", "P_f(1,2)", "P_f(2,3)", "P_f(0,3)"}),   # friction losses
])
def test_exact_routes_give_kinematics_f_bal_and_friction_within_1e_9(name, expected):
    mech = kinetostat.load(ROOT / "models" / f"{name}.toml")
    c = cmp.compare(mech, engines=("pinocchio", "mujoco"), steps=72)
    for route in ("pinocchio", "mujoco"):
        rows = {r.quantity: r for r in c.rows if r.route == route}
        assert expected <= set(rows)
        assert {"x(S2)", "v(S2)", "a(S2)", "x(B)", "v(B)", "a(B)"} <= set(rows)
        assert all(r.peak_relative < 1e-9 and r.n_compared == 72 for r in rows.values()), route
        assert rows["a(S2)"].unit == "m/s^2" and rows[sorted(expected)[0]].unit in ("N", "W")


def test_a_perturbed_acceleration_is_caught(four_bar):
    """The rocker's reported point accelerations 1 % (of the largest) off, its joint motion (what
    the engines are given: angles, rates, angular accelerations) untouched: the accelerations of
    its points fail, nothing else."""
    res = kinetostat.analyze(four_bar, steps=72)
    a_z = res.kin.a_z.copy()
    a_z[:, 3] += 0.01 * np.abs(a_z).max()
    bad = dataclasses.replace(res, kin=dataclasses.replace(res.kin, a_z=a_z))
    c = cmp.compare(four_bar, engines=("pinocchio", "mujoco"), res=bad)
    failing = {(r.route, r.quantity) for r in c.rows if not r.passed}
    assert failing == {(route, q) for route in ("pinocchio", "mujoco") for q in ("a(S3)", "a(B)", "a(C)")}


def test_a_wrong_friction_coefficient_is_caught():
    """The solver's losses with f = 0.06 instead of the model's 0.05: every P_f row fails."""
    path = ROOT / "models" / "ice_crank_slider.toml"
    mech = kinetostat.load(path)
    wrong = kinetostat.loads(path.read_text(encoding="utf-8").replace("f = 0.05", "f = 0.06"))
    res = kinetostat.analyze(mech, steps=72)
    bad = dataclasses.replace(res, friction_power=kinetostat.analyze(wrong, steps=72).friction_power)
    c = cmp.compare(mech, engines=("pinocchio", "mujoco", "pymunk"), res=bad)
    failing = {(r.route, r.quantity) for r in c.rows if not r.passed}
    assert failing == {(route, f"P_f{p.label[1:]}") for route in ("pinocchio", "mujoco", "pymunk")
                       for p in mech.pairs}
