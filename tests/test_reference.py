"""The 40-digit reference itself: its linear solves (float64 LU refined to the working precision
in exact fixed-point residuals) agree with mpmath's LU solve, the work they take is counted, and
the route on its sampled angles still catches an error of the solver's model."""
from __future__ import annotations

import warnings

import numpy as np
import pytest
from mpmath import mp, mpf

import kinetostat
from conftest import ROOT
from kinetostat_validation import compare as cmp
from kinetostat_validation import reference as ref

ICE = ROOT / "models" / "ice_crank_slider.toml"


def _system(n: int, cond: float, seed: int):
    """An n x n system A x = b of 40-digit numbers with the given condition number."""
    rng = np.random.default_rng(seed)
    U, _ = np.linalg.qr(rng.normal(size=(n, n)))
    V, _ = np.linalg.qr(rng.normal(size=(n, n)))
    A = U @ np.diag(np.geomspace(1.0, 1.0 / cond, n)) @ V.T
    with mp.workdps(ref.DPS):
        third = mpf(1) / 3                         # entries with digits beyond float64
        return ([[mpf(float(v)) * (1 + third * 1e-20) for v in row] for row in A],
                [mpf(float(v)) + third * 1e-18 for v in rng.normal(size=n)])


@pytest.mark.parametrize("cond", [1.0, 1e8, 1e13])
def test_refined_solve_equals_mpmath_lu_to_the_working_precision(cond):
    A, b = _system(12, cond, seed=int(np.log10(cond)))
    with mp.workdps(ref.DPS):
        x = ref._solve(A, b)
        want = mp.lu_solve(mp.matrix(A), mp.matrix(b))
        err = max(abs(x[i] - want[i]) for i in range(12)) / max(abs(want[i]) for i in range(12))
        # both are within cond x 1e-40 of the exact solution
        assert err < cond * mpf(10) ** (2 - ref.DPS)
        # and the residual is at the working precision: at most n ulps of |A| |x| + |b|
        res = max(abs(b[i] - mp.fdot(A[i], x)) for i in range(12))
        size = max(sum(abs(v) for v in row) for row in A) * max(abs(v) for v in x) + max(abs(v) for v in b)
        assert res <= 12 * mp.eps * size


def test_a_system_float64_cannot_refine_is_solved_by_mpmath_lu(monkeypatch):
    A, b = _system(8, 1e20, seed=3)            # cond x 1e-16 > 1: the float64 corrections diverge
    calls = []
    real = mp.lu_solve
    monkeypatch.setattr(mp, "lu_solve", lambda *a: calls.append(1) or real(*a))
    with mp.workdps(ref.DPS):
        x = ref._solve(A, b)
        want = real(mp.matrix(A), mp.matrix(b))
        assert calls == [1] and all(x[i] == want[i] for i in range(8))
    with mp.workdps(ref.DPS), pytest.raises(ZeroDivisionError):
        ref._solve([[mpf(1), mpf(2)], [mpf(2), mpf(4)]], [mpf(1), mpf(1)])    # singular


def test_the_ice_sample_needs_no_mpmath_lu_and_few_refinements(monkeypatch):
    """Counted work: on the ICE's sampled angles every solve refines in float64, never falls
    back to mpmath's LU, and takes at most 4 float64 solves; Newton takes 2 steps from the
    solver's positions."""
    mech = kinetostat.load(ICE)
    res = kinetostat.analyze(mech, steps=72)
    phi = res.phi_deg[ref.sample_angles(res)]
    solves = []
    real = np.linalg.solve
    monkeypatch.setattr(mp, "lu_solve", lambda *a: pytest.fail("fell back to mpmath's LU"))
    monkeypatch.setattr(np.linalg, "solve", lambda A, b: solves.append(1) or real(A, b))
    counted = []
    inner = ref._solve
    monkeypatch.setattr(ref, "_solve", lambda A, b: counted.append(len(solves)) or inner(A, b))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        out = ref.reference_full(mech, phi, res=kinetostat.analyze(mech, phi_deg=phi), angle="double")
    per_solve = np.diff(counted + [len(solves)])
    assert len(counted) == 5 * len(phi)          # 2 Newton steps, velocities, accelerations, statics
    assert per_solve.max() <= 4 and (out.newton_iterations == 3).all()


def test_the_sample_holds_the_peaks_and_the_largest_inertia_loads():
    mech = kinetostat.load(ICE)
    res = kinetostat.analyze(mech, steps=360)
    idx = set(ref.sample_angles(res).tolist())
    assert set(range(0, 360, 360 // ref.EVENLY_SPACED)) <= idx
    assert int(np.argmax(np.abs(res.balancing_moment))) in idx
    for p in mech.pairs:
        assert int(np.argmax(np.linalg.norm(res.forces.R[:, p.index], axis=-1))) in idx
    for k in range(1, mech.n_links):
        assert int(np.argmax(np.abs(res.kin.eps[:, k]))) in idx
    assert len(idx) <= 6 + 1 + len(mech.pairs) + mech.n_links - 1


def test_the_route_catches_a_coupler_one_per_mille_heavier():
    """The solver's answer for a slightly different mechanism (the rod's mass + 0.1 %) fails the
    reference route on the sampled angles: a physics error, not a rounding one, is caught."""
    mech = kinetostat.load(ICE)
    heavier = kinetostat.load(ICE, parameters={"G2": 1.001 * mech.parameters["G2"]})
    bad = kinetostat.analyze(heavier, steps=72)
    c = cmp.compare(mech, engines=["reference"], res=bad)
    failed = {r.quantity for r in c.rows if not r.passed}
    assert not c.passed and {"M_drive", "R(1,2)", "R(2,3)"} <= failed
    worst = max(r.peak_relative for r in c.rows)
    assert 1e-5 < worst < 1e-2


def test_the_sample_is_stated_from_one_constant():
    """How many and which angles the reference re-solves: SAMPLE, made from EVENLY_SPACED, is what
    the route's tolerance (and so every report's table of routes) and the accuracy page of the docs say."""
    assert ref.SAMPLE.startswith(f"{ref.EVENLY_SPACED} equally spaced crank angles (every {360 // ref.EVENLY_SPACED}°)")
    assert ref.SAMPLE in cmp.TOLERANCES["reference"].reason
    assert ref.SAMPLE in " ".join((ROOT / "docs" / "explanation" / "accuracy.md").read_text(encoding="utf-8").split())
