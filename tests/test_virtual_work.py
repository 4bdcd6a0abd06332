"""The d'Alembert-Lagrange route (kinetostat.virtual_work) against the group-by-group route on
every bundled model and on random mechanisms of every group kind, and against seed 004's own
equations of work (1)-(11) for the chain-unit four-bar."""
from __future__ import annotations

import warnings

import numpy as np
import pytest
from hypothesis import given, settings

import kinetostat
from conftest import ROOT
from test_properties import KINDS, _SETTINGS, _peak_errors, load_scale, valid

#: The drawn mechanisms are plausible (as in test_properties): no ModelWarning.
pytestmark = pytest.mark.filterwarnings("error::kinetostat.ModelWarning")

#: Both routes are exact: they agree to rounding, relative to the peak (as test_properties).
ROUNDING = 1e-9
MODELS = sorted((ROOT / "models").glob("*.toml"))


def route_errors(mech, res, vw) -> tuple[float, float]:
    """Peak-relative differences of M_bal and of every reaction between two results."""
    R = np.stack([vw.reaction(*p.links) for p in mech.pairs], axis=1)
    R_ref = np.stack([res.reaction(*p.links) for p in mech.pairs], axis=1)
    return _peak_errors(res.balancing_moment, R_ref, vw.balancing_moment, R, load_scale(res))


@pytest.mark.parametrize("path", MODELS, ids=lambda p: p.stem)
def test_bundled_models_agree_with_the_group_route(path):
    mech = kinetostat.load(path)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", kinetostat.SingularPositionWarning)
        res, vw = kinetostat.analyze(mech, steps=360), kinetostat.virtual_work(mech, steps=360)
    eM, eR = route_errors(mech, res, vw)
    assert eM <= ROUNDING and eR <= ROUNDING, (eM, eR)
    np.testing.assert_array_equal(vw.singular, res.singular)
    peak = np.nanmax(np.linalg.norm(res.forces.R, axis=-1))
    for p in mech.pairs:
        if p.kind == "P":     # the couple of the guide on the slider, about the slider point
            np.testing.assert_allclose(vw.forces.m[:, p.index], res.forces.m[:, p.index],
                                       rtol=0, atol=ROUNDING * peak * mech.size)
    if mech.drive.kind == "machine":
        np.testing.assert_allclose(vw.balancing_force, res.balancing_force, rtol=0, atol=ROUNDING * peak)


@pytest.mark.parametrize("examples", [8, pytest.param(25, marks=pytest.mark.slow)])
@pytest.mark.parametrize("kind", KINDS)
def test_random_mechanisms_agree_with_the_group_route(kind, examples):
    @settings(max_examples=examples, **_SETTINGS)
    @given(valid(kind))
    def check(mr):
        mech, res = mr
        vw = kinetostat.virtual_work(mech, phi_deg=res.phi_deg)
        eM, eR = route_errors(mech, res, vw)
        assert eM <= ROUNDING and eR <= ROUNDING, (eM, eR)
    check()


def test_crank_released_moves_the_mechanism_as_it_moves():
    """The virtual motion with the drive released is the mechanism's own motion per radian of
    the crank: (v_origin, omega) / omega_1 of the kinematics (velocities by the plans)."""
    mech = kinetostat.load(ROOT / "models" / "slotted_link_shaper.toml")
    res = kinetostat.analyze(mech, steps=36)
    from kinetostat.virtual_work import virtual_motions
    dq = virtual_motions(mech, res.kin)[:, :, -1].reshape(36, -1, 3)
    w1 = res.omega(1)[:, None]
    np.testing.assert_allclose(dq[..., 0] + 1j * dq[..., 1], res.kin.v_z[:, 1:] / w1, atol=1e-12 * mech.size)
    np.testing.assert_allclose(dq[..., 2], res.kin.omega[:, 1:] / w1, atol=1e-12)


def test_bad_input_names_the_argument():
    mech = kinetostat.load(ROOT / "models" / "scotch_yoke.toml")
    with pytest.raises(TypeError, match="Mechanism"):
        kinetostat.virtual_work("models/scotch_yoke.toml")
    with pytest.raises(ValueError, match="phi_deg"):
        kinetostat.virtual_work(mech, phi_deg=[np.nan])
    with pytest.raises(ValueError, match="steps"):
        kinetostat.virtual_work(mech, steps=0)


# ----------------------------------------------------------------------------- seed 004

# The paper's data (seed 004, line 370), its geometry as the model reconstructs it.
r, h, c = 0.080, 0.585, 0.540
b, l = np.hypot(c, h), np.hypot(r, c)
m2, AC2, J_C2 = 7.791, 0.2566, 0.299
m3, O2C3, J_O2, m_tb, h_tb = 4.696, 0.3305, 0.736, 12.749, 0.5464
m1A, O1C1 = 3.864, 0.004762


def _cross(a, b):
    return (np.conj(a) * b).imag


def _centre(P, u, Q, v):
    """Instantaneous centre: the intersection of the lines P + s u and Q + t v (complex)."""
    return P + _cross(Q - P, v) / _cross(u, v) * u


def _turn(X, e, P2):
    """Signed turn of a body about P2 that moves its point X by the unit vector e."""
    t = e / (1j * (X - P2))
    assert np.max(np.abs(t.imag)) < 1e-9 * np.max(np.abs(t))     # P2 lies on the normal to e at X
    return t.real


def test_seed_004_equations_of_work():
    """Seed 004's route reproduced as the paper writes it: the coupler's load F2 = G2 + Phi2 from
    the accelerations of eq. (3), M2 = -J_C2 eps_AB, the rocker's multicomponent moment
    M3 = -M_O2(G3) - M_O2(G_tb) - J_O2 eps_h - m_tb h_tb^2 eps_h, the coupler turning about its
    instantaneous centre P2 (the normals to the released points' paths), and the equations of
    work (1), (4) for X_A, Y_A, (6), (8) for X_B, Y_B (part O1AB, the rocker held, the crank's
    load M_y of eq. (11)), (10)-(11) for M_y; the unbalanced crank's M_y = eq. (11) - M_O1(G'1).
    The distances AP2, BP2, r1, h1 of the paper's sine-theorem formulas are checked against P2.

    The figures with the signs of each term are missing from the text: each virtual
    displacement here carries its sign from the reconstructed geometry (the paper's c3..c10,
    c1, c2 are their magnitudes). The route's X_A, Y_A: R(1, 2), force of the crank on the
    coupler; X_B, Y_B: R(2, 3); M_y: in the sense of phi_k (clockwise: -M_bal)."""
    mech = kinetostat.load(ROOT / "models" / "chain_unit_four_bar.toml")
    phi_k = np.arange(5.0, 360.0, 10.0)              # off 0 and 180 deg, where psi = 0 puts P2 at infinity
    res = kinetostat.analyze(mech, phi_deg=phi_k)     # kinematics only: omega_AB, eps_AB, eps_h
    vw = kinetostat.virtual_work(mech, phi_deg=phi_k)
    g, w = mech.g, 120 * np.pi / 30
    pk = np.radians(phi_k)
    # lines 77-87: positions, the coupler's angle gamma and the rocker's psi
    xA, yA = r * np.sin(pk), r * np.cos(pk)
    phi = pk - np.arctan(c / h)
    a = np.sqrt(r**2 + b**2 - 2 * r * b * np.cos(phi))
    gamma = np.arctan((h - yA) / (c - xA)) - np.arccos((a**2 + l**2 - h**2) / (2 * a * l))
    psi = np.arctan(r * np.sin(phi) / (b - r * np.cos(phi))) + np.arccos((a**2 + h**2 - l**2) / (2 * a * h)) \
        - np.arctan(c / h)
    w_AB, e_AB, e_h = res.omega(2), res.eps(2), res.eps(3)
    # eq. (3): the coupler's centre of mass
    aA = r * w**2
    aCx = -aA * np.sin(pk) - w_AB**2 * AC2 * np.cos(gamma) - e_AB * AC2 * np.sin(gamma)
    aCy = -aA * np.cos(pk) - w_AB**2 * AC2 * np.sin(gamma) + e_AB * AC2 * np.cos(gamma)
    F2 = -m2 * aCx + 1j * (-m2 * g - m2 * aCy)       # Phi2x + i (G2 + Phi2y), G2 along -y
    M2 = -J_C2 * e_AB
    M3 = -m3 * g * O2C3 * np.sin(psi) - m_tb * g * h_tb * np.sin(psi) - J_O2 * e_h - m_tb * h_tb**2 * e_h
    A, O1, O2 = xA + 1j * yA, 0j, c + 1j * h
    B = O2 + h * (np.sin(psi) - 1j * np.cos(psi))
    C2 = A + AC2 * np.exp(1j * gamma)

    def coupler(P2, dphi2):            # virtual work of the coupler's loads turning about P2
        return (_cross(C2 - P2, F2) + M2) * dphi2

    # (10)-(11): the mechanism's own motion, P2 on O1A and on O2B
    P2 = _centre(O1, A - O1, O2, B - O2)
    dA = -1j * (A - O1)                               # phi_k grows clockwise: dA = -i (A - O1) dphi_k
    dphi2 = _turn(A, dA, P2)
    dpsi = _cross(B - O2, 1j * dphi2 * (B - P2)) / h**2
    r1, h1 = np.abs(A - P2), np.abs(B - P2)
    np.testing.assert_allclose(np.abs(dphi2), r / r1, rtol=1e-12)            # c1
    np.testing.assert_allclose(np.abs(dpsi), r * h1 / (r1 * h), rtol=1e-12)  # c2
    sin, deg90, gf = np.sin, np.pi / 2, -gamma     # the figures' gamma: the coupler's slope, clockwise
    np.testing.assert_allclose(r1, np.abs(sin(deg90 - psi - gf) * l / sin(pk + psi)), rtol=1e-9)
    np.testing.assert_allclose(h1, np.abs(sin(deg90 - pk + gf) * l / sin(pk + psi)), rtol=1e-9)
    M_y11 = -(coupler(P2, dphi2) + M3 * dpsi)
    G1 = m1A * g
    M_y = M_y11 - G1 * O1C1 * np.sin(pk)             # unbalanced crank: M_O1(G'1) = G'1 O1C1 sin phi_k
    peak_M = np.max(np.abs(M_y))
    np.testing.assert_allclose(M_y, -vw.balancing_moment, rtol=0, atol=ROUNDING * peak_M)

    R12, R23 = vw.reaction(1, 2), vw.reaction(2, 3)
    peak = max(np.max(np.abs(R12)), np.max(np.abs(R23)))
    printed_A = (   # the paper's AP2, BP2 for (1) and (4)
        (sin(deg90 - psi - gf) * l / sin(psi), sin(deg90 + gf) * l / sin(psi)),
        (sin(deg90 - psi - gf) * l / sin(deg90 - psi), l * sin(gf) / sin(deg90 + psi)))
    for k, e in enumerate((1.0, 1j)):                # (1)-(2) X_A, (4)-(5) Y_A: the crank held
        P2 = _centre(A, 1j * e, O2, B - O2)
        np.testing.assert_allclose(np.abs(A - P2), np.abs(printed_A[k][0]), rtol=1e-9)
        np.testing.assert_allclose(np.abs(B - P2), np.abs(printed_A[k][1]), rtol=1e-9)
        dphi2 = _turn(A, e, P2)
        dpsi = _cross(B - O2, 1j * dphi2 * (B - P2)) / h**2
        np.testing.assert_allclose(np.abs(dphi2), 1 / np.abs(A - P2), rtol=1e-12)                  # c3, c5
        np.testing.assert_allclose(np.abs(dpsi), np.abs(B - P2) / (h * np.abs(A - P2)), rtol=1e-12)  # c4, c6
        X = -(coupler(P2, dphi2) + M3 * dpsi)
        np.testing.assert_allclose(X, R12[:, k], rtol=0, atol=ROUNDING * peak)
    printed_B = (   # the paper's AP2, BP2 for (6) and (8)
        (sin(deg90 - gf) * l / sin(pk), sin(deg90 - pk + gf) * l / sin(pk)),
        (l * sin(gf) / sin(deg90 - pk), sin(deg90 + pk - gf) * l / sin(deg90 - pk)))
    for k, e in enumerate((1.0, 1j)):                # (6)-(7) X_B, (8)-(9) Y_B: the rocker held
        P2 = _centre(B, 1j * e, O1, A - O1)
        np.testing.assert_allclose(np.abs(A - P2), np.abs(printed_B[k][0]), rtol=1e-9)
        np.testing.assert_allclose(np.abs(B - P2), np.abs(printed_B[k][1]), rtol=1e-9)
        dphi2 = _turn(B, e, P2)
        dphi1 = _cross(A - O1, 1j * dphi2 * (A - P2)) / r**2      # counter-clockwise
        np.testing.assert_allclose(np.abs(dphi2), 1 / np.abs(B - P2), rtol=1e-12)                  # c8, c10
        np.testing.assert_allclose(np.abs(dphi1), np.abs(A - P2) / (r * np.abs(B - P2)), rtol=1e-12)  # c7, c9
        X = -(coupler(P2, dphi2) + M_y11 * -dphi1)     # M_y acts in the sense of phi_k (clockwise)
        np.testing.assert_allclose(-X, R23[:, k], rtol=0, atol=ROUNDING * peak)
