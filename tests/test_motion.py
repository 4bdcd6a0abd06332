"""The machine's own law of motion (`kinetostat.law_of_motion`, issue 38).

Independent sources: a crank alone under its own weight (J_red constant, the energy equation in
closed form: omega^2 = a - b sin(phi) and the flywheel for delta by hand); a crank-slider's J_red
and dJ_red against the kinetic energy by 9-point differences (conftest.kinetic_energy); the
motion's eps against the derivative of its omega (periodic spectral differentiation); the
balancing moment of the kinetostatics at the true motion against M_drive; the ICE and the
shaper at delta = 0.02 (the shaper's at 360 steps against 1440); a motor's characteristic
M(omega) against the machine integrated forward in time by scipy (DOP853) until periodic.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

import kinetostat
from kinetostat import ModelError
from kinetostat.analysis import exact
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


def test_the_law_of_motion_costs_a_few_batched_solves(ice, monkeypatch):
    """Every solve of a step (the grid with its Gauss nodes, or the candidates of all the
    extremes sought at once) is one call: a pass of the friction's fixed point costs the grid's
    solve and a few small ones, not one per extreme and refinement step."""
    from kinetostat import motion
    mech, ref = ice
    calls = []
    monkeypatch.setattr(motion, "exact", lambda m, phi_deg, *a: calls.append(len(phi_deg)) or exact(m, phi_deg, *a))
    mo = kinetostat.law_of_motion(mech, delta=0.02)
    assert mo.J_flywheel == pytest.approx(ref.J_flywheel, rel=1e-14)
    assert calls.count(len(mo.phi_deg) * (1 + motion.GAUSS_NODES)) == mo.passes
    assert len(calls) <= 5 * mo.passes + 5, calls


def test_the_shaper_s_travel_table_knots_are_found_so_the_work_converges():
    """The shaper's cutting force is a table against the ram's travel (kinks at its knots, a step
    at the dead centres): the Gauss pieces are cut where the travel passes them, so J_flywheel at
    360 steps is that at 1440 to rounding (7.4e-6 apart when the knots were not found)."""
    mech = kinetostat.load(ROOT / "models" / "slotted_link_shaper.toml")
    coarse, fine = (kinetostat.law_of_motion(mech, delta=0.02, steps=s) for s in (360, 1440))
    assert coarse.J_flywheel == pytest.approx(fine.J_flywheel, rel=1e-11)
    assert coarse.delta == pytest.approx(0.02, rel=1e-12)


# ------------------------------------------------------------------ a motor's characteristic M(omega)

#: The crank alone with a constant resisting moment C on it and a motor of the linear
#: characteristic M = MS (1 - omega/W0) (its working branch), on a flywheel J_FLY.
C, MS, W0, J_FLY = 3.0, 60.0, 12.0, 0.5
RESISTANCE = f"""
[[load]]
name = "resistance"
kind = "moment"
link = 1
value = {-C}
"""
MOTOR = """
[[load]]
name = "motor"
kind = "moment"
link = 1
characteristic = {motor}
"""


def _motor(characteristic: str):
    return kinetostat.loads(CRANK + RESISTANCE + MOTOR.format(motor=characteristic))


def _forward_in_time(phi_deg: np.ndarray, cycles: int = 12, flywheel: float = J_FLY) -> np.ndarray:
    """omega at `phi_deg` of the last of `cycles` cycles of the machine integrated forward from
    omega = W0 at phi = 0 (scipy's DOP853; phi is the independent variable:
    d omega/d phi = (M(omega) - C - M g R cos(phi)) / ((flywheel + J_O) omega)); the motor's
    damping leaves the periodic motion (the transient decays ~e^-5 a cycle)."""
    from scipy.integrate import solve_ivp

    def rate(phi, w):
        return (MS * (1 - w / W0) - C - M * G * R * np.cos(phi)) / ((flywheel + J_O) * w)
    last = 2 * np.pi * (cycles - 1) + np.radians(phi_deg)
    sol = solve_ivp(rate, (0.0, 2 * np.pi * cycles), [W0], method="DOP853", t_eval=last, rtol=1e-13, atol=1e-12)
    assert sol.success
    return sol.y[0]


@pytest.mark.parametrize("characteristic", [f'"{MS} * (1 - omega / {W0})"',
                                            "{ omega = [0.0, 9.0, 14.0], M = [30.0, 15.0, -10.0] }"],
                         ids=["expression", "table"])
def test_characteristic_drive_is_the_periodic_motion_of_forward_dynamics(characteristic):
    """The table is the expression's line between 9 and 14 rad/s, where the motion runs."""
    mech = _motor(characteristic)
    mo = kinetostat.law_of_motion(mech, flywheel=J_FLY, steps=90)
    w = _forward_in_time(mo.phi_deg)
    assert mo.drive == "characteristic"
    assert np.allclose(mo.omega, w, rtol=1e-8, atol=0)
    assert np.allclose(mo.M_drive, MS * (1 - mo.omega / W0), rtol=0, atol=1e-12 * MS)
    assert abs(np.mean(mo.M_red + mo.M_drive)) <= 1e-12 * MS      # the cycle's work closes
    assert np.allclose(mo.M_red, -C - M * G * R * np.cos(np.radians(mo.phi_deg)), rtol=0, atol=1e-12)
    assert 9.0 < w.min() and w.max() < 14.0 and mo.delta > 0.01


@pytest.mark.parametrize("characteristic, flywheel, message", [
    ('"2.0 * (1 - omega / 12.0)"', J_FLY, r"M\(0\) = 2 N m cannot drive the load \(its mean resisting moment 3 N m\)"),
    (f'"{MS} * (1 - omega / {W0})"', 0.0, "no periodic motion with J_flywheel = 0 kg m.2: the crank stops"),
], ids=["too weak to start", "stops in the cycle"])
def test_a_characteristic_that_cannot_drive_the_load_is_refused_by_its_field(characteristic, flywheel, message):
    with pytest.raises(ValueError, match=r"law_of_motion: load\[1\]\.characteristic \('motor'\): " + message):
        kinetostat.law_of_motion(_motor(characteristic), flywheel=flywheel, steps=36)


def test_a_characteristic_drive_sized_for_delta_holds_it():
    mech = _motor(f'"{MS} * (1 - omega / {W0})"')
    mo = kinetostat.law_of_motion(mech, delta=0.02, steps=36)
    assert mo.delta == pytest.approx(0.02, rel=1e-11) and mo.delta_target == 0.02
    again = kinetostat.law_of_motion(mech, flywheel=mo.J_flywheel, steps=36)
    assert np.allclose(again.omega, mo.omega, rtol=1e-11)
    assert np.allclose(_forward_in_time(mo.phi_deg, flywheel=mo.J_flywheel), mo.omega, rtol=1e-8)
