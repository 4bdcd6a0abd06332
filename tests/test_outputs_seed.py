"""Outputs the seeds name: axial force of two-pin links (seed 004), reaction angles, the centre
of oscillation K (seed 000 sec. 4) and the work of each load over a cycle."""
from __future__ import annotations

import tomllib

import numpy as np
import pytest

import kinetostat
from conftest import ROOT


def model(name: str, **drive):
    data = tomllib.loads((ROOT / "models" / f"{name}.toml").read_text(encoding="utf-8"))
    data["drive"].update(drive)
    return kinetostat.from_dict(data)


def test_axial_force_of_the_coupler_by_hand():
    """Chain-unit coupler AB at phi_k = 200 deg: the pin forces on the coupler, from the balance
    of the rocker about O2 and of the coupler (hand computation with the kinematics only), along
    the line AB; compression there, as seed 004 says (line 389)."""
    mech = model("chain_unit_four_bar")
    res = kinetostat.analyze(mech, phi_deg=[200.0])
    A, B, O2 = (res.position(n)[0] for n in ("A", "B", "O2"))
    cr = lambda a, b: a[0] * b[1] - a[1] * b[0]
    g = mech.g
    l2, l3 = mech.links[2], mech.links[3]
    W2, W3 = np.array([0.0, -l2.mass * g]), np.array([0.0, -l3.mass * g])
    F2 = W2 + res.inertia(2).force[0]
    F3 = W3 + res.inertia(3).force[0]
    S2, S3 = res.position("C2")[0], res.position("S3")[0]
    M2, M3 = res.inertia(2).moment[0], res.inertia(3).moment[0]
    # unknown R = force of the coupler on the rocker at B (2 components):
    #   rocker about O2:  (B - O2) x R + (S3 - O2) x F3 + M3 = 0
    #   coupler about A:  (B - A) x (-R) + (S2 - A) x F2 + M2 = 0
    a1, b1 = np.array([-(B - O2)[1], (B - O2)[0]]), -(cr(S3 - O2, F3) + M3)
    a2, b2 = np.array([(B - A)[1], -(B - A)[0]]), -(cr(S2 - A, F2) + M2)
    R23 = np.linalg.solve(np.array([a1, a2]), np.array([b1, b2]))
    R12 = R23 - F2                                   # coupler: R12 + R32 + F2 = 0, R32 = -R23
    u = (B - A) / np.linalg.norm(B - A)
    at_A, at_B = R12 @ -u, -R23 @ u                  # pulling away from the other pin: tension
    assert res.axial_force(2, at="A")[0] == pytest.approx(at_A, rel=1e-10)
    assert res.axial_force(2, at="B")[0] == pytest.approx(at_B, rel=1e-10)
    assert res.axial_force(2)[0] == pytest.approx(0.5 * (at_A + at_B), rel=1e-10)
    assert res.axial_force(2)[0] < -80.0             # compressed, by about 88 N
    with pytest.raises(KeyError, match="not a two-pin link"):
        res.axial_force(0)
    with pytest.raises(KeyError, match="pins"):
        res.axial_force(2, at="O1")


def test_reaction_angle_is_the_direction_of_the_reaction():
    res = kinetostat.analyze(model("slotted_link_shaper"), steps=72)
    for p in res.mech.pairs:
        i, j = p.links
        R = res.reaction(i, j)
        np.testing.assert_allclose(res.reaction_angle(i, j), np.degrees(np.arctan2(R[:, 1], R[:, 0])), atol=1e-12)
        # the other link's reaction points the opposite way
        diff = np.mod(res.reaction_angle(j, i) - res.reaction_angle(i, j), 360.0)
        np.testing.assert_allclose(diff, 180.0, atol=1e-9)
    assert res.to_frame().attrs["units"]["angle_R_0_1"] == "deg"


def test_centre_of_oscillation_of_a_crank_about_its_pivot():
    """Rotation about a fixed axis O (seed 000 sec. 4): K on the line OS beyond S, l_SK =
    rho_S^2 / l_OS, at any omega and eps; the inertia resultant passes through K."""
    mech = model("chain_unit_four_bar", eps=-40.0)        # an accelerating crank
    res = kinetostat.analyze(mech, steps=24)
    crank = mech.links[1]
    rho2, l_OS = crank.I_S / crank.mass, 0.004762
    K = res.centre_of_oscillation(1)
    np.testing.assert_allclose(K.l_SK, rho2 / l_OS, rtol=1e-12)
    O, S = res.position("O1"), res.position("C1")
    np.testing.assert_allclose(K.point, S + (S - O) / l_OS * (rho2 / l_OS), atol=1e-12)
    for k in (1, 2, 3):      # on the single resultant's line of every link
        il, Kk = res.inertia(k), res.centre_of_oscillation(k)
        scale = np.linalg.norm(il.force, axis=-1) * np.linalg.norm(Kk.point - il.point, axis=-1).max()
        d, F = Kk.point - il.point, il.force
        np.testing.assert_array_less(np.abs(d[:, 0] * F[:, 1] - d[:, 1] * F[:, 0]), 1e-12 * scale + 1e-300)


def test_centre_of_oscillation_translation_and_pure_couple():
    res = kinetostat.analyze(model("ice_crank_slider"), steps=12)
    np.testing.assert_array_equal(res.centre_of_oscillation(3).point, res.position("B"))   # the piston translates
    np.testing.assert_array_equal(res.centre_of_oscillation(3).l_SK, 0.0)
    units = res.to_frame().attrs["units"]
    assert units["lSK_2"] == units["xK_2"] == "m" and units["Fax_2"] == "N"


@pytest.mark.parametrize("name", ["ice_crank_slider", "compressor", "scotch_yoke", "furnace_loader_six_bar"])
def test_work_over_a_cycle_balances(name):
    """Energy balance over a steady cycle: gravity and inertia do no net work; all loads and the
    balancing moment together none (the balancing moment is frictionless); friction loses."""
    res = kinetostat.analyze(model(name), steps=360)
    W = res.work()
    scale = max(abs(v) for v in W.values())
    assert scale > 1.0
    for key, v in W.items():
        if key.startswith(("gravity", "inertia")):
            assert abs(v) <= 1e-12 * scale, (key, v)
        if key.startswith("friction"):
            assert v < 0
    assert abs(sum(v for k, v in W.items() if not k.startswith("friction"))) <= 1e-12 * scale
    loads = [k for k in W if k.startswith(("load", "spring"))]
    assert loads and "balancing moment" in W


def test_work_of_the_ice_gas_force_equals_the_friction_energy_route():
    """The friction entries are the pairs' energies over the cycle (friction_energy), negative."""
    res = kinetostat.analyze(model("ice_crank_slider"), steps=360)
    W = res.work()
    np.testing.assert_allclose([W[f"friction {p.label}"] for p in res.mech.pairs], -res.friction_energy(), rtol=1e-14)


def test_work_needs_a_full_cycle():
    res = kinetostat.analyze(model("scotch_yoke"), phi_deg=[0.0, 10.0, 20.0])
    with pytest.raises(ValueError, match="work: needs the angles of a uniform full cycle"):
        res.work()
