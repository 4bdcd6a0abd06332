"""Friction in the reactions (kinetostat.friction, issue 26), checked by routes that do not share
its solution path: the frictionless solver (zero friction, bit for bit), the power balance
(sum of friction powers = change of the drive's power), the sign of every contact's power, the
friction laws on the converged reactions, Zhukovsky's lever with the friction loads applied, the
cycle's work, and the 40-digit reference that solves the whole frictional equilibrium at once
by Newton (validation/reference.py). On the bundled ICE (the model with friction data), on
every bundled model with a friction added, and on random mechanisms of every group kind
(tests/test_properties.py's strategies; a quick sample by default, more with -m slow).
The physics engines cannot check this: their joint friction is a constant limit torque, not
f r |R|.
"""
from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

import kinetostat
from conftest import EVERY_GROUP, EVERY_KIND, sampled
from kinetostat.errors import ModelWarning, SelfLockingWarning
from kinetostat.friction import MAX_PASSES, NEWTON_STEPS, RATE_TOL, relative_rate
from test_properties import KINDS, _SETTINGS, dead_centres, valid

MODELS = Path(__file__).resolve().parents[1] / "models"
ICE = MODELS / "ice_crank_slider.toml"
#: Identities that hold to rounding, relative to the peak force (x size for a moment).
ROUNDING = 1e-9
#: Random mechanisms per kind: default suite, -m slow.
QUICK, FULL = 2, 25


def with_friction(path: Path, f: float = 0.1, radius: float | None = None, method: str = "") -> kinetostat.Mechanism:
    """The bundled model at `path` with [friction] f (journal radius 0.05 x size unless given),
    replacing its own."""
    text = path.read_text()
    mech = kinetostat.loads(text, source=str(path)) if "[friction]" in text else None
    size = (mech or kinetostat.load(path)).size
    r = radius if radius is not None else 0.05 * size
    lines = [f"f = {f!r}", f"radius = {r!r}"] + ([f"method = {method!r}"] if method else [])
    head, _, tail = text.partition("[friction]")
    if tail:
        tail = tail.split("\n[", 1)
        tail = "\n[" + tail[1] if len(tail) > 1 else ""
    return kinetostat.loads(head + "[friction]\n" + "\n".join(lines) + "\n" + tail, source=str(path))


def coefficients(mech) -> np.ndarray:
    fr = mech.friction
    return np.array([fr.f * ((p.radius or fr.radius) if p.kind == "R" else 1.0) for p in mech.pairs])


def scales(res) -> tuple[np.ndarray, float]:
    """(N,) the largest reaction or load at each angle, N (0 where there is no equilibrium), and
    the mechanism's size, m."""
    R = np.max([np.linalg.norm(x, axis=-1).max(axis=1) for x in (res.forces.R, res.F_applied, res.F_i)], axis=0)
    return np.nan_to_num(R), res.mech.size


def reactions(mech, phi=None, steps: int = 360, **kw):
    """analyze(friction="reactions"), asserting that its SelfLockingWarning names exactly the
    self-locking angles (none where there are none)."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", SelfLockingWarning)
        res = kinetostat.analyze(mech, phi, steps=steps, friction="reactions", **kw)
    lock = [w.message for w in caught if isinstance(w.message, SelfLockingWarning)]
    assert len(lock) == int(res.self_locking.any())
    if lock:
        np.testing.assert_allclose(lock[0].phi_deg, np.round(res.phi_deg[res.self_locking], 9))
    return res


def check_identities(mech, phi) -> None:
    """Every identity of the module docstring that needs no reference, at the angles `phi`."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SelfLockingWarning)       # random mechanisms: read from the result
        warnings.simplefilter("ignore", kinetostat.SingularPositionWarning)
        res = kinetostat.analyze(mech, phi, friction="reactions")
        first = kinetostat.analyze(mech, phi, friction="first")
    ok = res.friction.solved & ~res.singular
    F, size = scales(res)
    if not ok.any() or not F.max() > 0:
        return
    w1 = res.omega(1)
    # the power balance: what friction takes, the drive gives on top
    dP = (res.balancing_moment - first.balancing_moment) * w1
    assert np.abs(dP - res.friction_power.sum(axis=1))[ok].max() <= ROUNDING * (F * size * np.abs(w1))[ok].max()
    # every contact dissipates: friction load x relative motion <= 0 (where the motion is more
    # than rounding: at rest the friction is the one of the motion just before)
    rate = relative_rate(mech, res.kin)[0]
    moving = np.abs(rate) > RATE_TOL * np.abs(w1)[:, None] * np.where([p.kind == "R" for p in mech.pairs], 1, size)
    assert (res.friction.load * rate)[ok[:, None] & moving].max(initial=0.0) <= 0.0
    # the reported losses are the signed -(load x rate), not a magnitude: >= 0 since each opposes its motion
    np.testing.assert_array_equal(res.friction_power[ok[:, None] & moving], -(res.friction.load * rate)[ok[:, None] & moving])
    assert (res.friction_power[ok] >= 0).all()
    # the friction laws hold on the converged reactions: f r |R|, f |N|
    R = np.linalg.norm(res.forces.R, axis=-1)
    mag = np.where([p.kind == "R" for p in mech.pairs], R, np.abs(res.forces.normal)) * coefficients(mech)
    err = np.abs(np.abs(res.friction.load) - mag)[ok[:, None] & moving]
    assert err.max(initial=0.0) <= ROUNDING * F.max() * size
    # Zhukovsky's lever with the friction loads applied gives the same M_bal
    assert np.abs(res.lever_discrepancy)[ok].max() <= ROUNDING * F.max() * size
    # the passes are counted and bounded
    assert (res.friction.passes[ok] >= 1).all() and res.friction.passes.max() <= MAX_PASSES + NEWTON_STEPS


# ----------------------------------------------------------------------------- the ICE worked example

@pytest.fixture(scope="module")
def ice():
    return kinetostat.load(ICE)


def test_zero_friction_gives_the_frictionless_result_bit_for_bit(ice):
    mech = with_friction(ICE, f=0.0)
    phi = np.arange(0.0, 360.0, 15.0) + 0.5
    a = kinetostat.analyze(mech, phi, friction="first")
    b = kinetostat.analyze(mech, phi, friction="reactions")
    assert np.array_equal(a.forces.R, b.forces.R) and np.array_equal(a.balancing_moment, b.balancing_moment)
    assert np.array_equal(a.lever_moment, b.lever_moment) and np.array_equal(a.forces.normal, b.forces.normal)
    assert (b.friction.passes[:, 0] == 1).all() and not b.self_locking[np.abs(a.balancing_moment) > 1e-6].any()
    assert np.array_equal(b.efficiency[np.isfinite(b.efficiency)], np.ones(np.isfinite(b.efficiency).sum()))


@pytest.mark.parametrize("path", sampled(sorted(MODELS.glob("*.toml")), keep=EVERY_GROUP))
def test_zero_friction_is_bit_for_bit_on_every_bundled_model(path):
    """EVERY_GROUP's models by default, every one with -m slow."""
    mech = with_friction(path, f=0.0)
    phi = np.arange(0.0, 360.0, 45.0) + 0.5
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", kinetostat.SingularPositionWarning)
        a = kinetostat.analyze(mech, phi, friction="first")
        b = reactions(mech, phi)
    for x, y in ((a.forces.R, b.forces.R), (a.balancing_moment, b.balancing_moment), (a.lever_moment, b.lever_moment),
                 (a.forces.normal, b.forces.normal), (a.forces.F_bal, b.forces.F_bal)):
        np.testing.assert_array_equal(x, y)
    assert np.abs(b.friction_power).max() == 0.0


def test_ice_at_30_deg_agrees_with_the_40_digit_newton_solution(ice):
    from kinetostat_validation.reference import reference_full
    phi = np.array([0.0, 30.0, 90.0, 180.0, 1.0, 200.0, 300.0])
    res = reactions(ice, phi)
    ref = reference_full(ice, phi, res=res, friction=True)
    F, size = scales(res)
    assert np.abs(ref.M_bal - res.balancing_moment).max() <= ROUNDING * F.max() * size
    assert np.abs(ref.R - res.forces.R).max() <= ROUNDING * F.max()
    # friction moves M_bal at 30 deg: by more than the rounding, less than its own size
    assert 0.01 < abs(res.balancing_moment[1] - res.balancing_moment_frictionless[1]) < 0.2 * abs(res.balancing_moment[1])


def test_ice_identities_over_the_cycle(ice):
    check_identities(ice, np.arange(0.0, 360.0, 5.0) + 0.25)


def test_ice_work_balances_to_rounding_with_friction_in_the_reactions(ice):
    res = reactions(ice, steps=360)
    W = res.work()
    lost = sum(v for k, v in W.items() if k.startswith("friction"))
    assert lost < 0 and abs(sum(W.values())) <= 1e-12 * sum(abs(v) for v in W.values())
    np.testing.assert_allclose(-np.array([W[f"friction {p.label}"] for p in ice.pairs]), res.friction_energy(),
                               rtol=1e-12)
    # the first approximation's work does not balance: its friction is not in M_bal
    W1 = kinetostat.analyze(ice, steps=360, friction="first").work()
    assert abs(sum(W1.values()) - sum(v for k, v in W1.items() if k.startswith("friction"))) <= 1e-12 * abs(lost)
    # cycle efficiency: the engine's shaft work over the gas's, both routes
    eta = res.cycle_efficiency()
    assert eta == pytest.approx(-W["balancing moment"] / W["load gas force"], rel=1e-12)
    assert 0 < eta < 1


def test_cycle_integrals_with_friction_are_converged_across_the_jumps(ice):
    """With friction the integrands jump (M_bal where a relative motion turns) and kink (f |N|
    where a normal force turns, the gas diagram's knots): integrated piecewise between them, the
    cycle efficiency and the energies do not depend on the sampling (36 or 360 angles) nor on the
    nodes a piece, and the plain trapezoid at 7200 angles (first order across the jumps) lies
    within its own O(h) error of them; the trapezoid at 360 angles (the old rule, 0.5530683 and
    7.9445 J) does not."""
    import kinetostat.analysis as A
    coarse, fine = reactions(ice, steps=36), reactions(ice, steps=360)
    eta, E = fine.cycle_efficiency(), fine.friction_energy()
    assert coarse.cycle_efficiency() == pytest.approx(eta, rel=1e-12)
    np.testing.assert_allclose(coarse.friction_energy(), E, rtol=1e-11)
    nodes = A.CYCLE_NODES
    try:
        A.CYCLE_NODES = 2 * nodes
        assert reactions(ice, steps=360).cycle_efficiency() == pytest.approx(eta, rel=1e-12)
    finally:
        A.CYCLE_NODES = nodes

    def trapezoid(N: int) -> tuple[float, float]:
        r = reactions(ice, steps=N)
        u = r._unit_motion()
        W0, Wf = ((M * u.omega[:, 1]).mean() for M in (r.balancing_moment_frictionless, r.balancing_moment))
        return Wf / W0, float(r._friction_power(u)[:, ice.pair_between(0, 3).index].mean() * 2 * np.pi)
    (e1, E1), (e2, E2) = trapezoid(3600), trapezoid(7200)
    assert abs(e2 - eta) <= 2 * abs(e2 - e1) and abs(E2 - E[ice.pair_between(0, 3).index]) <= 2 * abs(E2 - E1)
    e360, E360 = trapezoid(360)
    assert abs(e360 - eta) > 1e-5 and abs(E360 - E[ice.pair_between(0, 3).index]) > 1e-3
    assert round(eta, 6) == 0.553036 and round(float(E[ice.pair_between(0, 3).index]), 4) == 7.9460


def test_self_locking_zone_near_top_dead_centre_and_its_edges(ice):
    res = reactions(ice, steps=360)
    zones = res.self_locking_zones()
    tdc = zones[np.argmin(np.abs(zones[:, 0]))]
    assert abs(tdc[0]) <= 1e-9 and 0.5 < tdc[1] < 5.0          # from the dead centre to where the gas wins
    lo, hi = tdc[1] - 1e-9, tdc[1] + 1e-9
    r = reactions(ice, [lo, hi])
    assert r.self_locking.tolist() == [True, False]
    # inside the zone the equilibrium exists (a number, not NaN) and the drive must help the gas
    inside = reactions(ice, [0.5 * tdc[1]])
    assert inside.friction.solved.all() and inside.efficiency[0] < 0
    assert inside.balancing_moment[0] * inside.balancing_moment_frictionless[0] < 0


def test_zero_relative_motion_takes_the_side_the_motion_comes_from(ice):
    """At top dead centre the piston is at rest: its friction is the one just before (the crank
    turns towards increasing phi), not the one just after. Same for the rod-piston pin where
    omega_2 = 0."""
    res = reactions(ice, steps=360)
    w2_zero = [np.degrees(np.arccos(0.0))]              # omega_2 = 0 where the crank is at 90 deg
    P, B = ice.pair_between(0, 3).index, ice.pair_between(2, 3).index
    for phi0, pair in ((0.0, P), (180.0, P), (w2_zero[0], B), (270.0, B)):
        d = 1e-7
        r = reactions(ice, [phi0 - d, phi0, phi0 + d])
        before, at, after = r.friction.load[:, pair]
        rate = relative_rate(ice, r.kin)[0][:, pair]
        assert rate[0] * rate[2] < 0, "a sign change of the relative motion"
        assert at == pytest.approx(before, rel=1e-5) and at * after < 0
        assert abs(at - before) < 1e-4 * abs(after - at)


def test_every_self_locking_angle_is_named_with_its_reason_and_never_a_silent_number():
    """A friction so large (f = 3.5, r = 1 mm) that pairs wedge: the warning names every
    self-locking angle with its reason. No equilibrium: M_bal NaN. Wedged (friction gain >= 1):
    M_bal is an equilibrium (the lever and the power balance hold there to rounding) but not the
    only one, so eta is NaN. eta <= 0: the equilibrium value, eta a number <= 0."""
    with pytest.warns(ModelWarning, match="friction.f: 3.5 is a friction angle of 74.1 deg"):     # the model check
        mech = with_friction(ICE, f=3.5, radius=0.001)
    with pytest.warns(SelfLockingWarning, match=r"self-locking with friction in the reactions at \d+ angle") as w:
        res = kinetostat.analyze(mech, steps=72, friction="reactions")
    msg = w[0].message
    why = res.self_locking_reason
    np.testing.assert_allclose(msg.phi_deg, res.phi_deg[res.self_locking])
    assert list(msg.reasons) == list(why[res.self_locking])
    for key in ("no equilibrium", "wedged", "eta<=0"):
        assert (why == key).any() and f"{key} at phi = [" in str(msg)
    none, wedged, eta0 = (why == "no equilibrium"), (why == "wedged"), (why == "eta<=0")
    assert np.isnan(res.balancing_moment[none]).all() and np.isnan(res.efficiency[none | wedged]).all()
    assert np.isfinite(res.balancing_moment[~none]).all() and (res.efficiency[eta0 & np.isfinite(res.efficiency)] <= 0).all()
    assert np.isfinite(res.efficiency[~res.self_locking]).any()
    # at a wedged angle M_bal is an equilibrium: Zhukovsky's lever with the friction loads and the
    # power balance agree with it to rounding
    F, size = scales(res)
    w1 = res.omega(1)
    assert np.abs(res.lever_discrepancy[wedged]).max() <= ROUNDING * F.max() * size
    dP = (res.balancing_moment - res.balancing_moment_frictionless) * w1 - res.friction_power.sum(axis=1)
    assert np.abs(dP[wedged]).max() <= ROUNDING * (F * size * np.abs(w1)).max()


def test_eta_is_undefined_near_a_dead_centre_by_the_40_digit_moments(ice):
    """eta is NaN exactly where |M0| <= DEAD_CENTRE |Mf - M0|, M0 and Mf taken from the 40-digit
    reference (frictionless and frictional); a number elsewhere, with the sign of its rule. At
    the dead centres and 1e-6 deg past them it is NaN (no longer 0 and -1.4e6); self-locking
    still follows eta's sign there."""
    from kinetostat.friction import DEAD_CENTRE
    from kinetostat_validation.reference import reference_full
    phi = np.array([0.0, 1e-6, 0.01, 0.3, 3.0, 20.0, 179.0, 179.9, 180.0, 180.1, 183.0, 359.9])
    with pytest.warns(SelfLockingWarning):
        res = kinetostat.analyze(ice, phi, friction="reactions")
    M0 = reference_full(ice, phi, res=res).M_bal
    Mf = reference_full(ice, phi, res=res, friction=True).M_bal
    dead = np.abs(M0) <= DEAD_CENTRE * np.abs(Mf - M0)
    assert dead[[0, 1, 2, 7, 8, 9, 11]].all() and not dead[[4, 5, 6]].any()
    assert np.isnan(res.efficiency[dead]).all() and np.isfinite(res.efficiency[~dead]).all()
    turn = np.sign(res.omega(1))
    eta = np.where(M0 * turn >= 0, M0 / Mf, Mf / M0)
    np.testing.assert_allclose(res.efficiency[~dead], eta[~dead], rtol=1e-9)
    assert res.self_locking[[0, 1, 2]].all()                        # the drive must carry the crank past TDC


def test_friction_method_is_an_argument_and_a_model_default(ice):
    assert kinetostat.analyze(ice, [30.0]).friction_method == "first"
    assert kinetostat.analyze(ice, [30.0], friction="reactions").friction_method == "reactions"
    mech = with_friction(ICE, f=0.05, radius=0.012, method="reactions")
    assert kinetostat.analyze(mech, [30.0]).friction_method == "reactions"
    assert kinetostat.analyze(mech, [30.0], friction="first").friction_method == "first"
    with pytest.raises(ValueError, match="friction: expected one of"):
        kinetostat.analyze(ice, [30.0], friction="exact")
    with pytest.raises(kinetostat.ModelError, match="friction.method"):
        with_friction(ICE, method="second")
    frictionless = kinetostat.load(MODELS / "scotch_yoke.toml")
    assert kinetostat.analyze(frictionless, [30.0], friction="reactions").friction_method == "none"
    df = kinetostat.analyze(ice, [30.0, 31.0], friction="reactions").to_frame()
    assert df.attrs["units"]["eta"] == "1" and df.attrs["units"]["self_locking"] == "bool"
    assert df.attrs["units"]["M_bal_0"] == "N m" and df.attrs["units"]["Ffr_0_3"] == "N"


# ----------------------------------------------------------------------------- every bundled model, random mechanisms

@pytest.mark.parametrize("path", sampled(sorted(MODELS.glob("*.toml")), keep=EVERY_KIND), ids=lambda p: p.stem)
def test_bundled_models_with_friction(path):
    """Every group kind: the identities over a cycle, and the 40-digit Newton solution at 4 angles."""
    from kinetostat_validation.reference import reference_full
    mech = with_friction(path, f=0.1)
    check_identities(mech, np.arange(0.0, 360.0, 10.0) + 3.0)
    phi = np.array([17.0, 107.0, 197.0, 287.0])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SelfLockingWarning)
        res = kinetostat.analyze(mech, phi, friction="reactions")
    ok = res.friction.solved & ~res.friction.wedged
    ref = reference_full(mech, phi[ok], friction=True)
    F, size = scales(res)
    assert np.abs(ref.M_bal - res.balancing_moment[ok]).max() <= ROUNDING * F.max() * size
    assert np.abs(ref.R - res.forces.R[ok]).max() <= ROUNDING * F.max()


@pytest.mark.parametrize("size", [QUICK, pytest.param(FULL, marks=pytest.mark.slow)], ids=["quick", "full"])
@pytest.mark.parametrize("kind", KINDS)
def test_random_mechanisms_with_friction(kind, size):
    from kinetostat_validation.reference import reference_full

    @settings(max_examples=size, **_SETTINGS)
    @given(valid(kind), st.floats(0.0, 0.3), st.floats(0.0, 0.2), st.floats(0.0, 30.0))
    def check(case, f, r, offset):
        data = dict(case.data, friction={"f": f, "radius": max(r, 1e-3) * case[0].size})
        mech = kinetostat.from_dict(data)
        phi = np.arange(0.0, 360.0, 30.0) + offset
        check_identities(mech, phi)
        at = phi[::4]
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", SelfLockingWarning)
            warnings.simplefilter("ignore", kinetostat.SingularPositionWarning)
            res = kinetostat.analyze(mech, at, friction="reactions")
        ok = res.friction.solved & ~res.friction.wedged & ~res.singular    # a wedged pair: not unique
        ok &= ~dead_centres(res)      # a load against a velocity of ~0: its direction is rounding (test_properties)
        F, length = scales(res)
        assume(ok.any() and F.max() > 0)
        ref = reference_full(mech, at[ok], friction=True)      # where the passes found the equilibrium
        assert np.abs(ref.M_bal - res.balancing_moment[ok]).max() <= ROUNDING * F.max() * length
        assert np.abs(ref.R - res.forces.R[ok]).max() <= ROUNDING * F.max()
        checked.append(int(res.friction.passes.max()))
    checked: list[int] = []
    check()
    assert len(checked) == size, checked          # every example reached the reference


def test_worksheet_names_the_friction_terms(ice):
    """The worksheet's friction section: the friction circle f r and moment f r |R| per revolute
    pair, the friction angle and force per prismatic pair, M_bal with friction and eta, the same
    numbers as analyze(friction="reactions"); a model without friction has no such rows."""
    from kinetostat.plans.worksheet import worksheet
    ws = worksheet(ice, 30.0)
    res = kinetostat.analyze(ice, [30.0], friction="reactions")
    f, r = ice.friction.f, ice.friction.radius
    for p in ice.pairs:
        i, j = p.links
        R = np.linalg.norm(res.forces.R[0, p.index])
        if p.kind == "R":
            assert ws.value(f"rho_{i}_{j}") == pytest.approx(f * r, rel=1e-15)
            assert ws.value(f"Mf_{i}_{j}") == pytest.approx(f * r * R, rel=1e-12)
        else:
            assert ws.value(f"Ff_{i}_{j}") == pytest.approx(f * abs(res.forces.normal[0, p.index]), rel=1e-12)
            N = abs(res.forces.normal[0, p.index])                              # the reaction leans by arctg f
            assert np.degrees(np.arccos(N / R)) == pytest.approx(ws.value(f"phi_f_{i}_{j}"), rel=1e-9)
    assert ws.value("M_bal_friction") == res.balancing_moment[0] and ws.value("eta") == res.efficiency[0]
    assert "## Friction in the reactions" in ws.markdown()
    assert not worksheet(kinetostat.load(MODELS / "scotch_yoke.toml")).section("friction")


def test_plans_with_friction_draw_the_circles_and_the_tangent_reactions(ice):
    """plans.build(friction="reactions"): each revolute reaction's drawn line passes at rho = f r
    from its pin (measured on the sheet, x mu_l), on the side that gives the friction moment's
    sense; the guide's reaction leans by arctg f from the normal; every force polygon closes with
    the frictional reactions, whose drawn lengths are the 40-digit reference's |R|; the worksheet
    at friction="reactions" writes the same reactions (R41 = 3122.02 N, M_f41 = f r R41)."""
    from kinetostat.plans.worksheet import worksheet
    from kinetostat_validation.reference import reference_full
    plans = kinetostat.plans.build(ice, at=30.0, friction="reactions")
    res = reactions(ice, [30.0])
    ref = reference_full(ice, [30.0], res=res, friction=True)
    f, r = ice.friction.f, ice.friction.radius
    g, mu = plans["group:2,3"], plans["group:2,3"].scale.value
    A = g.points["A"]
    R12 = complex(*res.reaction(1, 2)[0])
    X = g.points["R12n:from"]                        # the drawn line of R12 (R12n, R12t start on it)
    arm = abs(((X - A) * (R12 / abs(R12)).conjugate()).imag) * mu
    assert arm == pytest.approx(f * r, rel=1e-9) and g.length_mm("ρ12") * mu == pytest.approx(f * r, rel=1e-12)
    q = res.friction.load[0, ice.pair_between(1, 2).index]
    assert np.sign(((X - A).conjugate() * R12).imag) == np.sign(q) != 0          # r x R = q: its sense
    assert any(k.startswith("friction circle ρ12") for k in g.paths) and any("detail ρ12" in n for n in g.notes)
    N43, R43 = res.forces.normal[0, ice.pair_between(0, 3).index], res.reaction(0, 3)[0]
    assert np.degrees(np.arccos(abs(N43) / np.linalg.norm(R43))) == pytest.approx(np.degrees(np.arctan(f)), rel=1e-9)
    fp = plans["forces:2,3"]
    drawn = {s.name: fp.length_mm(s.name) * fp.scale.value for s in fp.segments}
    sides = [fp.points[fp.segment(n).end] - fp.points[fp.segment(n).start] for n in fp.equation]
    assert abs(sum(sides)) <= 1e-9 * max(map(abs, sides))
    assert drawn["R43"] == pytest.approx(np.linalg.norm(ref.R[0, ice.pair_between(0, 3).index]), rel=1e-9)
    assert drawn["R12"] == pytest.approx(np.linalg.norm(ref.R[0, ice.pair_between(1, 2).index]), rel=1e-9)
    frame = plans.segments_frame()
    assert frame.loc[frame.segment == "R12", "value"].iloc[0] == pytest.approx(3122.018, rel=1e-6)
    ws = worksheet(ice, 30.0, friction="reactions")
    R41 = np.linalg.norm(ref.R[0, ice.pair_between(0, 1).index])
    assert ws.value("R_0_1") == pytest.approx(R41, rel=1e-9) and R41 == pytest.approx(3122.02, abs=0.01)
    assert ws.value("Mf_0_1") == pytest.approx(f * r * R41, rel=1e-9)
    first = worksheet(ice, 30.0)                     # frictionless reactions, the frictional ones beside them
    assert first.value("R_0_1") == pytest.approx(3184.85, abs=0.01) and first.value("Rf_0_1") == pytest.approx(R41, rel=1e-9)


def test_a_sweep_of_a_model_with_friction_in_the_reactions_solves_it(tmp_path, monkeypatch):
    """A model whose friction.method is "reactions": a sweep large enough for the compiled kernel
    (which has no friction) takes the numpy path, and its peaks are the frictional ones."""
    text = ICE.read_text().replace("radius = 0.012\n", 'radius = 0.012\nmethod = "reactions"\n', 1)
    mech = tmp_path / "ice.toml"
    mech.write_text(text)
    phi = np.linspace(0.0, 360.0, 5001)[:-1]
    from kinetostat import fast
    from kinetostat.sweep import sweep
    monkeypatch.setattr(fast, "FAST_COLD", 0)          # the sweep large enough for the kernel, loaded or not
    assert 2 * len(phi) >= fast.FAST_MIN
    table = sweep(mech, {"n1": [4500.0, 3000.0]}, phi_deg=phi).table
    for n1, row in zip([4500.0, 3000.0], table.itertuples()):
        res = reactions(kinetostat.load(mech, parameters={"n1": n1}), phi)
        assert res.friction_method == "reactions"
        assert row.peak_M_bal == pytest.approx(np.max(np.abs(res.balancing_moment)), rel=1e-12)


def test_the_engines_plans_and_worksheet_keep_the_frictionless_method(tmp_path):
    """A model whose default is friction in the reactions: the engine routes (frictionless joints)
    are compared with the first approximation's reactions, and the plans of the graphical method
    and the worksheet's reactions stay frictionless; only analyze's own default changes."""
    from kinetostat.plans.worksheet import worksheet
    from kinetostat_validation.scene import build_scene
    text = ICE.read_text().replace("radius = 0.012\n", 'radius = 0.012\nmethod = "reactions"\n', 1)
    mech = kinetostat.loads(text, source=str(ICE))
    first = kinetostat.analyze(mech, [30.0], friction="first")
    assert reactions(mech, [30.0]).friction_method == "reactions"
    assert build_scene(mech, phi_deg=[30.0]).res.friction_method == "first"
    ws = worksheet(mech, 30.0)
    assert ws.value("M_bal") == first.balancing_moment[0] != ws.value("M_bal_friction")
    plans = kinetostat.plans.build(mech, only=["crank"])
    assert plans["crank"].results[0].value == pytest.approx(first.balancing_moment[0], rel=1e-12)


def test_cli_analyze_with_friction_in_the_reactions(capsys):
    from kinetostat import cli
    assert cli.main(["analyze", "ice_crank_slider", "--at", "0", "30", "--friction", "reactions"]) == 0
    out = capsys.readouterr().out
    res = kinetostat.analyze(kinetostat.load(ICE), [0.0, 30.0], friction="reactions")
    assert "friction (reactions): self-locking at 1 of 2 positions, eta 0.9395 .. 0.9395 elsewhere" in out
    assert f"{res.balancing_moment[1]:12.6g}" in out
    assert cli.main(["analyze", "ice_crank_slider", "--at", "30"]) == 0
    assert "friction (first): self-locking at 0 of 1 positions, eta 0.9379" in capsys.readouterr().out
