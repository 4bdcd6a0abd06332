"""Kinematics against seed 002's worked example, closed forms and finite differences."""
from __future__ import annotations

import numpy as np
import pytest

import kinetostat
import ice_reference as ref

#: Drawn-and-measured plans of the textbook: the text reads lengths to 0.1 mm on ~80 mm vectors.
GRAPHICAL = 0.005
#: The exact solver against the closed form written in the test: rounding only.
EXACT = 1e-6
#: Central differences (5-point stencil, h = 1e-3 rad) against the analytic plans.
FINITE_DIFF = 1e-6


# seed 002, sec. 1.2.2: V_B = 10.94, V_BA = 14.92, V_S2 = 12.2, omega2 = 135.6, a_B = 8311,
# a_S2 = 7875, eps2 = 33782 (measured on the plans)
@pytest.mark.parametrize("name, textbook", [
    ("V_B", 10.94), ("V_BA", 14.92), ("V_S2", 12.2), ("omega2", 135.6),
    ("a_A", 7994.38), ("a_B", 8311.0), ("a_S2", 7875.0), ("eps2", 33782.0)])
def test_seed_002_example_kinematics(ice, name, textbook):
    got = {
        "V_B": np.linalg.norm(ice.velocity("B")), "V_S2": np.linalg.norm(ice.velocity("S2")),
        "V_BA": np.linalg.norm(ice.velocity("B") - ice.velocity("A")),
        "omega2": abs(ice.omega(2)[0]), "eps2": abs(ice.eps(2)[0]),
        "a_A": np.linalg.norm(ice.acceleration("A")),
        "a_B": np.linalg.norm(ice.acceleration("B")), "a_S2": np.linalg.norm(ice.acceleration("S2")),
    }[name]
    k = ref.kinematics(30.0)
    exact = {
        "V_B": np.linalg.norm(k["vB"]), "V_S2": np.linalg.norm(k["vS2"]),
        "V_BA": np.linalg.norm(k["vB"] - k["vA"]), "omega2": abs(k["w2"]), "eps2": abs(k["e2"]),
        "a_A": np.linalg.norm(k["aA"]), "a_B": np.linalg.norm(k["aB"]), "a_S2": np.linalg.norm(k["aS2"]),
    }[name]
    assert got == pytest.approx(exact, rel=EXACT)
    assert got == pytest.approx(textbook, rel=GRAPHICAL)


def test_seed_002_positions_and_senses(ice):
    k = ref.kinematics(30.0)
    for name, key in (("A", "A"), ("B", "B"), ("S2", "S2")):
        np.testing.assert_allclose(ice.position(name)[0], k[key], rtol=0, atol=1e-12)
    # the crank turns clockwise: omega1 < 0 about +z; the rod's omega2 and eps2 signs as derived
    assert ice.omega(1)[0] == pytest.approx(-ref.w1)
    assert ice.omega(2)[0] == pytest.approx(k["w2"], rel=EXACT)
    assert ice.eps(2)[0] == pytest.approx(k["e2"], rel=EXACT)


def _stencil(f, x, h):
    """First and second derivatives by 5-point central differences."""
    fm2, fm1, f0, fp1, fp2 = (f(x + s * h) for s in (-2, -1, 0, 1, 2))
    d1 = (fm2 - 8 * fm1 + 8 * fp1 - fp2) / (12 * h)
    d2 = (-fm2 + 16 * fm1 - 30 * f0 + 16 * fp1 - fp2) / (12 * h**2)
    return d1, d2


def test_velocities_and_accelerations_are_derivatives_of_positions(mech):
    """v = dP/dphi * phidot and a = d2P/dphi2 * phidot^2 + dP/dphi * phiddot over the full cycle."""
    phi = np.arange(0.0, 360.0, 2.0)
    res = kinetostat.analyze(mech, phi_deg=phi)
    w, e = mech.drive.omega, mech.drive.eps            # in the crank's sense, like phi
    h = np.degrees(1e-3)
    for name in mech.point_names:
        pos = lambda p: kinetostat.analyze(mech, phi_deg=p).position(name)
        d1, d2 = _stencil(pos, phi, h)
        d1, d2 = np.degrees(d1), np.degrees(np.degrees(d2))   # per radian
        v, a = res.velocity(name), res.acceleration(name)
        v_fd, a_fd = d1 * w, d2 * w**2 + d1 * e
        # scales: the peak of the quantity, or its natural size where it vanishes (a fixed point)
        v_scale = max(np.max(np.abs(v)), mech.size * w)
        assert np.max(np.abs(v - v_fd)) <= FINITE_DIFF * v_scale, name
        assert np.max(np.abs(a - a_fd)) <= FINITE_DIFF * max(np.max(np.abs(a)), v_scale * w), name
    for k in range(1, mech.n_links):
        th0 = res.theta(k)
        # angle increments from the centre value, wrapped to (-pi, pi]
        th = lambda p: np.angle(np.exp(1j * (kinetostat.analyze(mech, phi_deg=p).theta(k) - th0)))
        d1, d2 = _stencil(th, phi, h)
        d1, d2 = np.degrees(d1), np.degrees(np.degrees(d2))
        om, ep = res.omega(k), res.eps(k)
        om_scale = max(np.max(np.abs(om)), w)
        assert np.max(np.abs(om - d1 * w)) <= FINITE_DIFF * om_scale, k
        assert np.max(np.abs(ep - (d2 * w**2 + d1 * e))) <= FINITE_DIFF * max(np.max(np.abs(ep)), om_scale * w), k


def test_sliding_velocity_is_derivative_of_travel(mech):
    """For every prismatic pair: the first and second time derivatives of the slider point's
    travel along the guide are the relative sliding velocity and acceleration."""
    phi = np.arange(0.0, 360.0, 5.0)
    res = kinetostat.analyze(mech, phi_deg=phi)
    h = np.degrees(1e-3)
    for p in mech.pairs:
        if p.kind != "P":
            continue
        def travel(x):
            r = kinetostat.analyze(mech, phi_deg=x)
            S = r.position(p.point)
            G = r.kin.point(p.links[0], mech.links[p.links[0]].points[p.guide])[0]
            c, s = np.cos(r.theta(p.links[0])), np.sin(r.theta(p.links[0]))
            d = np.stack([c * p.direction[0] - s * p.direction[1], s * p.direction[0] + c * p.direction[1]], -1)
            return np.sum((S - G) * d, axis=-1)
        d1, d2 = _stencil(travel, phi, h)
        w, e = mech.drive.omega, mech.drive.eps
        d1, d2 = np.degrees(d1), np.degrees(np.degrees(d2))
        v, a = res.slide_velocity(*p.links), res.slide_acceleration(*p.links)
        v_scale = max(np.max(np.abs(v)), mech.size * w)
        assert np.max(np.abs(v - d1 * w)) <= FINITE_DIFF * v_scale, p.label
        assert np.max(np.abs(a - (d2 * w**2 + d1 * e))) <= FINITE_DIFF * max(np.max(np.abs(a)), v_scale * w), p.label


def test_batch_equals_one_by_one(mech):
    phi = np.array([0.0, 47.0, 181.5, 300.0])
    batch = kinetostat.analyze(mech, phi_deg=phi)
    for n, p in enumerate(phi):
        one = kinetostat.analyze(mech, phi_deg=[p])
        np.testing.assert_allclose(one.kin.origin[0], batch.kin.origin[n], rtol=0, atol=1e-13)
        np.testing.assert_allclose(one.balancing_moment[0], batch.balancing_moment[n], rtol=1e-13)


def test_diameter_equals_the_largest_pairwise_distance():
    """planar.diameter (hull and calipers) gives the very float of the all-pairs maximum: random
    clouds, points on a circle, grids full of ties and collinear runs, fewer than three points."""
    from kinetostat.planar import diameter
    rng = np.random.default_rng(19)
    for trial in range(400):
        n = int(rng.integers(0, 30))
        z = [rng.normal(size=n) + 1j * rng.normal(size=n),
             np.exp(2j * np.pi * rng.integers(0, 12, n) / 12) * rng.choice([1.0, 2.0], n),
             rng.integers(-3, 4, n) + 1j * rng.integers(-3, 4, n),
             rng.integers(-3, 4, n) * (1 + 2j) + 0.5][trial % 4]
        pts = [complex(c) for c in z]
        assert diameter(pts) == max((abs(a - b) for a in pts for b in pts), default=0.0), pts
