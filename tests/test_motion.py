"""The machine's own law of motion (`kinetostat.law_of_motion`, issue 38).

Independent sources: a crank alone under its own weight (J_red constant, the energy equation in
closed form: omega^2 = a - b sin(phi) and the flywheel for delta by hand); a crank-slider's J_red
and dJ_red against the kinetic energy by 9-point differences (conftest.kinetic_energy); the
motion's eps against the derivative of its omega (periodic spectral differentiation); the
balancing moment of the kinetostatics at the true motion against M_drive; the ICE and the
shaper at delta = 0.02.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

import kinetostat
from kinetostat import ModelError
from conftest import ROOT, kinetic_energy
from test_law_of_motion import CRANK_SLIDER, H_DEG, STENCIL

M, R, I_S, G, RPM = 2.0, 0.1, 0.01, 9.81, 120.0
#: A crank alone: mass M at R from its pivot; gravity is its only load (M_red = -M g R cos(phi)).
CRANK = f"""
[mechanism]
name = "crank alone"
g = {G}
[drive]
pivot = "O"
point = "A"
reference = [1.0, 0.0]
sense = "ccw"
rpm = {RPM}
[frame]
O = [0.0, 0.0]
[[link]]
id = 1
points = {{ O = [0.0, 0.0], A = [{R}, 0.0] }}
mass = {M}
I_S = {I_S}
com = "A"
[[pair]]
kind = "R"
links = [0, 1]
point = "O"
"""
W_N = RPM * math.pi / 30
J_O = I_S + M * R * R


def _closed_form(J_fly: float, phi_deg: np.ndarray) -> tuple[np.ndarray, float]:
    """omega(phi) and delta of the crank alone: 0.5 J omega^2 = T0 - M g R sin(phi) with
    (omega_max + omega_min)/2 = W_N: omega^2 = a - b sin(phi), a = W_N^2 + b^2/(4 W_N^2)."""
    b = 2 * M * G * R / (J_fly + J_O)
    a = W_N ** 2 + b * b / (4 * W_N ** 2)
    return np.sqrt(a - b * np.sin(np.radians(phi_deg))), (math.sqrt(a + b) - math.sqrt(a - b)) / W_N


@pytest.fixture(scope="module")
def crank():
    return kinetostat.loads(CRANK)


def test_crank_alone_against_the_closed_form(crank):
    mo = kinetostat.law_of_motion(crank, flywheel=0.05, steps=72)
    w, delta = _closed_form(0.05, mo.phi_deg)
    assert np.allclose(mo.J_red, J_O, rtol=1e-14) and np.allclose(mo.dJ_red, 0, atol=1e-14)
    assert np.allclose(mo.M_red, -M * G * R * np.cos(np.radians(mo.phi_deg)), rtol=0, atol=1e-12)
    assert np.allclose(mo.M_drive, 0, atol=1e-12)
    assert np.allclose(mo.omega, w, rtol=1e-12)
    assert np.allclose(mo.eps, -0.5 * (2 * M * G * R / (0.05 + J_O)) * np.cos(np.radians(mo.phi_deg)), rtol=0,
                       atol=1e-10)
    assert mo.delta == pytest.approx(delta, rel=1e-10)
    assert mo.omega_mean == pytest.approx(W_N, rel=1e-13)
    assert mo.drive == "constant" and mo.delta_target is None and mo.J_flywheel == 0.05


def test_crank_alone_sized_by_hand(crank):
    """omega_max^2 - omega_min^2 = 2 delta W_N^2 = 2 b: J_fly + J_O = 2 M g R / (delta W_N^2); the
    extremes at 90 and 270 deg lie between the grid's angles (steps = 7) and are found exactly."""
    mo = kinetostat.law_of_motion(crank, delta=0.02, steps=7)
    # 4 Gauss nodes over a 51 deg step integrate sin to ~1e-9
    assert mo.J_flywheel == pytest.approx(2 * M * G * R / (0.02 * W_N ** 2) - J_O, rel=1e-8)
    assert mo.delta == pytest.approx(0.02, rel=1e-10)
    assert mo.omega_max == pytest.approx(W_N * 1.01, rel=1e-12)
    assert mo.omega.max() < mo.omega_max            # the grid misses the extreme
    again = kinetostat.law_of_motion(crank, flywheel=mo.J_flywheel, steps=7)
    assert again.delta == pytest.approx(0.02, rel=1e-10)
    # Wittenbauer at the exact slopes gives it; the texts' slopes (1 +- delta) differ by ~delta^2
    assert mo.approximate["wittenbauer"] == pytest.approx(mo.J_flywheel, rel=1e-3)
    # J_red is constant here: the formula Delta A / (delta W^2) - J_red is the exact one to ~delta^2
    assert mo.approximate["formula"] == pytest.approx(mo.J_flywheel, rel=1e-3)


def test_crank_slider_reduced_inertia_against_kinetic_energy_differences():
    mech = kinetostat.loads(CRANK_SLIDER)
    mo = kinetostat.law_of_motion(mech, flywheel=1.0, steps=24)
    w = mech.drive.omega
    J = 2 * kinetic_energy(mech, mo.phi_deg) / w ** 2
    assert np.allclose(mo.J_red, J, rtol=1e-13)
    dJ = np.degrees(sum(c * (kinetic_energy(mech, mo.phi_deg + s * H_DEG) - kinetic_energy(mech, mo.phi_deg - s * H_DEG))
                        for s, c in STENCIL.items()) / H_DEG) * 2 / w ** 2
    assert np.allclose(mo.dJ_red, dJ, rtol=0, atol=1e-8 * np.abs(dJ).max())


def test_motion_is_periodic_balanced_and_eps_is_the_derivative_of_omega():
    mech = kinetostat.loads(CRANK_SLIDER)
    mo = kinetostat.law_of_motion(mech, flywheel=0.02, steps=90)
    assert np.allclose(mo.T - mo.T[0], mo.work, rtol=0, atol=1e-12 * np.abs(mo.T).max())
    assert np.allclose(mo.T, 0.5 * (mo.J_flywheel + mo.J_red) * mo.omega ** 2, rtol=1e-13)
    # the cycle's work closes: the drive's constant moment balances the loads' mean
    assert abs(np.mean(mo.M_red + mo.M_drive)) <= 1e-13 * np.abs(mo.M_red).max()
    k = np.fft.rfftfreq(len(mo.omega), 1.0 / len(mo.omega))
    dw = np.fft.irfft(1j * k * np.fft.rfft(mo.omega), len(mo.omega))
    assert np.allclose(mo.eps, mo.omega * dw, rtol=0, atol=1e-9 * np.abs(mo.eps).max())
    assert mo.delta > 0.01             # the motion does fluctuate


def test_balancing_moment_at_the_true_motion_is_the_drive_moment():
    mech = kinetostat.loads(CRANK_SLIDER)
    mo = kinetostat.law_of_motion(mech, delta=0.05, steps=36)
    res = kinetostat.analyze(mech, law=mo)
    assert np.allclose(res.phi_deg, mo.phi_deg)
    assert np.allclose(res.omega(1), mech.drive.sense * mo.omega, rtol=1e-15)
    assert np.allclose(res.balancing_moment, mech.drive.sense * mo.M_drive, rtol=0,
                       atol=1e-11 * np.abs(mo.M_red).max())
    const = kinetostat.analyze(mech, phi_deg=mo.phi_deg)        # at the constant speed it is not
    assert np.abs(const.balancing_moment - mech.drive.sense * mo.M_drive).max() > 1e-3 * np.abs(mo.M_red).max()


@pytest.fixture(scope="module")
def ice():
    mech = kinetostat.load(ROOT / "models" / "ice_crank_slider.toml")
    return mech, kinetostat.law_of_motion(mech, delta=0.02)


@pytest.mark.slow      # ~9 s: the friction's fixed point refines its extremes by many small re-solves
def test_ice_at_delta_002(ice):
    mech, mo = ice
    assert mo.delta == pytest.approx(0.02, rel=1e-10)
    assert mo.omega_mean == pytest.approx(mech.drive.omega, rel=1e-13)
    assert 0 < mo.J_flywheel < 1 and np.isfinite(list(mo.approximate.values())).all()
    assert mo.M_drive[0] < 0            # the engine's consumer
    assert mo.settled <= 1e-12 and mo.passes > 1    # friction depends on the motion: a fixed point
    res = kinetostat.analyze(mech, law=mo)
    # friction (first approximation) is part of M_red: the drive with friction balances it
    assert np.allclose(res.balancing_moment_with_friction, mech.drive.sense * mo.M_drive, rtol=0,
                       atol=1e-11 * np.abs(mo.M_red).max())
    flat = kinetostat.law_of_motion(mech, flywheel=mo.J_flywheel)
    assert flat.delta == pytest.approx(0.02, rel=1e-9)


@pytest.mark.parametrize("kwargs, message", [
    ({"delta": 0.02, "flywheel": 1.0}, "not both"),
    ({"delta": 0.0}, "delta: expected 0 < delta < 2"),
    ({"delta": 2.0}, "delta: expected 0 < delta < 2"),
    ({"delta": float("nan")}, "delta: expected"),
    ({"flywheel": -1.0}, "flywheel: expected a moment of inertia >= 0"),
    ({"flywheel": float("inf")}, "flywheel: expected"),
    ({"flywheel": "1"}, "flywheel: expected"),
])
def test_bad_arguments_are_refused_by_name(crank, kwargs, message):
    with pytest.raises(ValueError, match=message):
        kinetostat.law_of_motion(crank, steps=12, **kwargs)


@pytest.mark.parametrize("change, message", [
    ((f"rpm = {RPM}", 'omega = "10 + sin(phi)"'), "drive.omega: the law of motion is what law_of_motion finds"),
    ((f"rpm = {RPM}", "rpm = 0.0"), "drive.omega: the nominal speed must be > 0"),
    ((f"rpm = {RPM}", f"rpm = {RPM}\neps = 1.0"), "drive.eps"),
    ((f"g = {G}", "g = 0.0"), "no load does work"),
])
def test_bad_drives_are_refused_naming_the_field(change, message):
    mech = kinetostat.loads(CRANK.replace(*change))
    with pytest.raises(ModelError, match=message):
        kinetostat.law_of_motion(mech, delta=0.02, steps=12)


def test_a_flywheel_too_small_to_keep_the_crank_turning_is_refused_by_name():
    slow = kinetostat.loads(CRANK.replace(f"rpm = {RPM}", "rpm = 30.0"))
    with pytest.raises(ValueError, match="flywheel: J_flywheel = 0 kg m.2 is too small .* the crank would stop"):
        kinetostat.law_of_motion(slow, flywheel=0.0, steps=12)


def test_the_model_flywheel_is_taken_and_an_argument_overrides_it(crank):
    mech = kinetostat.loads(CRANK + "[flywheel]\nJ = 0.05\n")
    assert mech.flywheel == kinetostat.Flywheel(J=0.05)
    assert kinetostat.law_of_motion(mech, steps=12).J_flywheel == 0.05
    assert kinetostat.law_of_motion(mech, flywheel=0.1, steps=12).J_flywheel == 0.1
    sized = kinetostat.loads(CRANK + "[flywheel]\ndelta = 0.02\n")
    assert kinetostat.law_of_motion(sized, steps=12).delta == pytest.approx(0.02, rel=1e-10)


def test_analyze_refuses_another_mechanism_s_motion(crank):
    mo = kinetostat.law_of_motion(crank, delta=0.02, steps=12)
    with pytest.raises(ValueError, match="law: the Motion of another mechanism"):
        kinetostat.analyze(kinetostat.loads(CRANK_SLIDER), law=mo)
