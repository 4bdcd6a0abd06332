"""The crank's law of motion omega(phi), standstill (omega = 0), speed-dependent loads (a motor's
characteristic M(omega), a viscous damper) and links made of several bodies.

Independent sources: the energy balance M_bal omega_1 + sum P(loads) = dT/dt with dT/dphi by
9-point differences of the kinetic energy (conftest.kinetic_energy) along the cycle; at
standstill the balancing moment from the potential energy by differences of positions alone
(virtual work by hand, no velocity plan) and a crank-slider's free-body hand solution; the
parallel-axis theorem by hand for a link of several bodies.
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import kinetostat
from kinetostat import ModelError
from kinetostat.model import SpeedLaw
from conftest import four_bar, kinetic_energy

#: As tests/test_properties.py: dT/dphi by 9-point central differences at h = 5e-4 rad.
STENCIL = {1: 4 / 5, 2: -1 / 5, 3: 4 / 105, 4: -1 / 280}
H_DEG = math.degrees(5e-4)
POWER = 1e-8

# A crank-slider with masses (crank 0.1, rod 0.4, offset 0.02): slider on the frame's x axis.
CRANK_SLIDER = """
[mechanism]
name = "test crank-slider"
g = 9.81
[drive]
pivot = "O"
point = "A"
reference = [1.0, 0.0]
sense = "ccw"
rpm = 300.0
[frame]
O = [0.0, 0.0]
G = [0.0, -0.02]
[[link]]
id = 1
points = { O = [0.0, 0.0], A = [0.1, 0.0], S1 = [0.04, 0.0] }
mass = 1.0
I_S = 0.002
com = "S1"
[[link]]
id = 2
points = { A = [0.0, 0.0], B = [0.4, 0.0], S2 = [0.13, 0.0] }
mass = 2.0
I_S = 0.03
com = "S2"
[[link]]
id = 3
points = { B = [0.0, 0.0] }
mass = 3.0
com = "B"
[[pair]]
kind = "R"
links = [0, 1]
point = "O"
[[pair]]
kind = "R"
links = [1, 2]
point = "A"
[[pair]]
kind = "R"
links = [2, 3]
point = "B"
[[pair]]
kind = "P"
links = [0, 3]
point = "B"
guide = "G"
direction = [1.0, 0.0]
[[group]]
links = [2, 3]
branch = 1
[[load]]
name = "gas force"
kind = "force"
link = 3
point = "B"
direction = [-1.0, 0.0]
value = 150.0
"""

TABLE = """[drive.omega_table]
phi_deg = [0.0, 60.0, 130.0, 200.0, 290.0, 360.0]
rpm = [300.0, 340.0, 310.0, 250.0, 270.0, 300.0]
"""
EXPRESSION = 'omega = "10*pi*(1 + 0.2*sin(phi) + 0.05*cos(2*phi))"\n'


def _with_drive(text: str, law: str) -> str:
    """`text` with its constant rpm replaced by a law of motion (a table or an expression)."""
    law = law if law.endswith("\n") else law + "\n"
    text = text.replace("rpm = 300.0\n", "" if law.startswith("[") else law).replace("eps = 0.0\n", "")
    return text + ("\n" + law if law.startswith("[") else "")


def _balance(mech, steps: int = 48) -> tuple[float, float]:
    """Largest |M_bal omega_1 + sum P(loads) - dT/dt| over the cycle, and the power scale."""
    phi = np.arange(steps) * 360.0 / steps + 1.3
    res = kinetostat.analyze(mech, phi_deg=phi)
    T = {s: kinetic_energy(mech, phi + s * H_DEG) for s in range(-4, 5)}
    dT_dphi = np.degrees(sum(c * (T[s] - T[-s]) for s, c in STENCIL.items()) / H_DEG)
    dT_dt = dT_dphi * mech.drive.sense * res.omega(1)
    P_loads = np.sum(res.F_applied * res.kin.v_origin, axis=-1) + res.M_applied * res.kin.omega
    P_drive = res.balancing_moment * res.omega(1)
    residual = P_drive + P_loads[:, 1:].sum(axis=1) - dT_dt
    scale = max(np.abs(P_drive).max(), np.abs(dT_dt).max(), np.abs(P_loads).max())
    return float(np.abs(residual).max()), float(scale)


MODELS = {"four-bar": four_bar(), "crank-slider": CRANK_SLIDER}


@pytest.mark.parametrize("law", [TABLE, EXPRESSION], ids=["table", "expression"])
@pytest.mark.parametrize("model", MODELS)
def test_energy_balance_with_a_varying_speed(model, law):
    mech = kinetostat.loads(_with_drive(MODELS[model], law))
    res = kinetostat.analyze(mech, steps=36)
    assert np.ptp(res.omega(1)) > 0.1 * mech.drive.omega       # the speed does vary
    assert np.abs(res.eps(1)).max() > 0
    residual, scale = _balance(mech)
    assert residual <= POWER * scale, residual / scale
    # every load's work over a cycle sums to 0, inertia included (T returns to its start)
    assert abs(sum(res.work().values())) <= 1e-9 * 2 * np.pi * np.abs(res.balancing_moment).max()


def test_table_law_is_the_periodic_spline_through_its_points():
    law = SpeedLaw((0.0, 60.0, 130.0, 200.0, 290.0, 360.0), (3.0, 4.0, 3.5, 2.0, 2.5, 3.0))
    w, dw = law(np.radians([0.0, 60.0, 130.0, 200.0, 290.0, 360.0, 720.0]))
    assert np.allclose(w, [3.0, 4.0, 3.5, 2.0, 2.5, 3.0, 3.0], rtol=0, atol=1e-13)
    phi = np.linspace(0.0, 2 * np.pi, 2001)
    w, dw = law(phi)
    # the derivative it reports is the derivative of its values (central differences) ...
    assert np.allclose(np.gradient(w, phi)[1:-1], dw[1:-1], rtol=0, atol=2e-5 * np.abs(dw).max())
    # ... and continuous across the knots and the period (eps = omega domega/dphi continuous)
    assert np.abs(np.diff(dw)).max() < 0.01 * np.abs(dw).max()
    assert dw[0] == pytest.approx(dw[-1], abs=1e-12)


def test_expression_law_gives_its_exact_derivative():
    mech = kinetostat.loads(_with_drive(four_bar(), EXPRESSION))
    res = kinetostat.analyze(mech, steps=24)
    phi = np.radians(res.phi_deg)
    w = 10 * np.pi * (1 + 0.2 * np.sin(phi) + 0.05 * np.cos(2 * phi))
    dw = 10 * np.pi * (0.2 * np.cos(phi) - 0.1 * np.sin(2 * phi))
    assert np.allclose(res.omega(1), w, rtol=1e-15, atol=0)
    assert np.allclose(res.eps(1), w * dw, rtol=1e-13, atol=1e-12)


@pytest.mark.parametrize("law, message", [
    ('omega = "__import__(1)"', "call of '__import__' is not allowed"),
    ('omega = "phi.real"', "attribute access not allowed"),
    ('omega = "1 + abs(sin(phi))"', "abs\\(\\) is not allowed here: it is not smooth"),
    ('omega = "1 + sin(phi/2)"', "must be periodic"),
    ('omega = "sin(phi)"', "must be >= 0"),
    ('omega = "1 + fi"', "unknown name 'fi'"),
    ('omega = "1/0 + 0*phi"', "not finite"),
    ('omega = "' + "(" * 300 + "phi" + ")" * 300 + '"', "at most 500"),
    ('omega = "10 + sin(phi)"\neps = 3.0\n', "drive.eps: a law of motion gives eps"),
    ("[drive.omega_table]\nphi_deg = [0.0, 180.0]\nomega = [1.0, 2.0]\n", "at least 3 angles"),
    ("[drive.omega_table]\nphi_deg = [0.0, 180.0, 360.0]\nomega = [1.0, 2.0, 3.0]\n", "the law is periodic"),
])
def test_bad_laws_are_refused_by_name(law, message):
    with pytest.raises(ModelError, match=message):
        kinetostat.loads(_with_drive(four_bar(), law))


# ----------------------------------------------------------------------------- standstill

def _potential_energy(mech, phi_deg) -> np.ndarray:
    """Potential energy of gravity at the angles, from positions alone, J."""
    res = kinetostat.analyze(mech, phi_deg=phi_deg)
    return sum(link.mass * mech.g * res.position(link.com)[:, 1] for link in mech.links[1:] if link.mass)


def test_standstill_four_bar_against_virtual_work_by_hand():
    """rpm = 0 (tests/hostile/rpm_zero.toml): M_bal dphi = dV - M3 dtheta3 by differences of the
    positions (the potential energy and the rocker's angle), no velocity plan."""
    mech = kinetostat.load(Path(__file__).parent / "hostile" / "rpm_zero.toml")
    phi = np.arange(0.0, 360.0, 15.0) + 2.0
    res = kinetostat.analyze(mech, phi_deg=phi)
    assert (res.omega(1) == 0).all() and (res.kin.omega == 0).all() and (res.kin.eps == 0).all()
    assert (res.F_i == 0).all() and (res.M_i == 0).all()
    dV = np.degrees(sum(c * (_potential_energy(mech, phi + s * H_DEG) - _potential_energy(mech, phi - s * H_DEG))
                        for s, c in STENCIL.items()) / H_DEG)

    def theta3(p):
        return np.unwrap(kinetostat.analyze(mech, phi_deg=p).theta(3))
    dth3 = np.degrees(sum(c * (theta3(phi + s * H_DEG) - theta3(phi - s * H_DEG)) for s, c in STENCIL.items()) / H_DEG)
    M3 = -4.0
    by_hand = dV - M3 * dth3          # ccw drive: dphi = dtheta1
    assert np.allclose(res.balancing_moment, by_hand, rtol=0, atol=1e-8 * np.abs(by_hand).max())
    assert np.allclose(res.lever_moment, res.balancing_moment, rtol=0, atol=1e-12 * np.abs(by_hand).max())
    assert np.isfinite(res.forces.R).all()
    assert res.friction_power_total.tolist() == [0.0] * len(phi)
    W = kinetostat.analyze(mech, steps=72).work()
    assert abs(sum(W.values())) <= 1e-9 * 2 * np.pi * np.abs(by_hand).max()   # statics: M_bal balances
    assert W["load resisting moment"] == pytest.approx(0.0, abs=1e-12)     # rocker returns: no net turn


def test_standstill_crank_slider_by_free_body_hand_solution():
    """omega = 0, gravity off, a horizontal force P on the slider: the rod is a two-force member
    (no weight), its force S = P / cos(beta) along the rod, M_bal = -(A x S) . z = P r sin(phi + beta)
    / cos(beta) (the classical formula), here with the offset e: sin(beta) = (r sin(phi) + e) / l."""
    mech = kinetostat.loads(CRANK_SLIDER.replace("rpm = 300.0", "rpm = 0").replace("g = 9.81", "g = 0.0"))
    phi = np.arange(0.0, 360.0, 20.0) + 5.0
    res = kinetostat.analyze(mech, phi_deg=phi)
    r, l, e, P = 0.1, 0.4, 0.02, 150.0
    p = np.radians(phi)
    beta = np.arcsin((r * np.sin(p) + e) / l)              # rod's angle below the line A -> B
    # force of the rod on the slider: S along A->B with x-component balancing P: S_x = P
    # on the crank the rod pushes back with -S at A; M_bal = -(A x (-S)) = A x S
    S = P * np.stack([np.ones_like(p), -np.tan(beta)], axis=-1)
    A = r * np.stack([np.cos(p), np.sin(p)], axis=-1)
    M_hand = A[:, 0] * S[:, 1] - A[:, 1] * S[:, 0]
    assert np.allclose(res.balancing_moment, M_hand, rtol=0, atol=1e-10 * P * r)
    assert np.allclose(res.lever_moment, M_hand, rtol=0, atol=1e-10 * P * r)
    assert np.allclose(res.reaction(2, 3), S, rtol=0, atol=1e-10 * P)


# ----------------------------------------------------------------------------- speed-dependent loads

MOTOR = """
[[load]]
name = "motor"
kind = "moment"
link = 1
characteristic = { omega = [0.0, 30.0, 40.0], M = [20.0, 8.0, 0.0] }
"""
MOTOR_EXPRESSION = """
[[load]]
name = "motor"
kind = "moment"
link = 1
characteristic = "6*(1 - omega/50)"
"""
ROTARY_DAMPER = """
[[load]]
name = "damper"
kind = "damper"
pair = [2, 3]
c = 0.05
"""
SLIDE_DAMPER = """
[[load]]
name = "damper"
kind = "damper"
pair = [0, 3]
c = 4.0
"""


@pytest.mark.parametrize("model, extra", [
    ("four-bar", MOTOR + ROTARY_DAMPER), ("crank-slider", MOTOR_EXPRESSION + SLIDE_DAMPER)])
def test_motor_and_damper_keep_the_energy_balance(model, extra):
    mech = kinetostat.loads(_with_drive(MODELS[model], TABLE) + extra)
    residual, scale = _balance(mech)
    assert residual <= POWER * scale, residual / scale


def test_motor_characteristic_is_read_at_the_link_speed():
    mech = kinetostat.loads(_with_drive(four_bar(), TABLE) + MOTOR)
    res = kinetostat.analyze(mech, steps=36)
    w = res.omega(1)
    assert np.allclose(res.M_applied[:, 1] - kinetostat.analyze(
        kinetostat.loads(_with_drive(four_bar(), TABLE)), steps=36).M_applied[:, 1], np.interp(w, [0, 30, 40], [20, 8, 0]),
        rtol=0, atol=1e-12)


def test_damper_dissipates_c_v_squared():
    rot = kinetostat.loads(_with_drive(four_bar(), TABLE) + ROTARY_DAMPER)
    res = kinetostat.analyze(rot, steps=72)
    dw = res.omega(3) - res.omega(2)
    W = res.work()
    assert W["damper damper"] == pytest.approx(-np.mean(0.05 * dw**2 / res.omega(1)) * 2 * np.pi, rel=1e-12)
    # per angle: the damper's moments' power on both links is -c dw^2
    base = kinetostat.analyze(kinetostat.loads(_with_drive(four_bar(), TABLE)), steps=72)
    dM = np.asarray(res.M_applied) - base.M_applied
    P = (dM * res.kin.omega)[:, 1:].sum(axis=1)
    assert np.allclose(P, -0.05 * dw**2, rtol=1e-12, atol=1e-15)
    sl = kinetostat.loads(CRANK_SLIDER + SLIDE_DAMPER)
    res = kinetostat.analyze(sl, steps=72)
    v = res.slide_velocity(0, 3)
    base = kinetostat.analyze(kinetostat.loads(CRANK_SLIDER), steps=72)
    dF = np.asarray(res.F_applied) - base.F_applied
    assert np.allclose(dF[:, 3, 0], -4.0 * v, rtol=1e-12, atol=1e-12)
    P = np.sum(dF * res.kin.v_origin, axis=-1)[:, 1:].sum(axis=1) + ((res.M_applied - base.M_applied) * res.kin.omega)[:, 1:].sum(axis=1)
    assert np.allclose(P, -4.0 * v**2, rtol=1e-10, atol=1e-12)


# ----------------------------------------------------------------------------- several bodies on one link

# seed 004's rocker and tie bar (chain unit): rocker 4.696 kg at 0.3305 m from O2, J_O2 = 0.736;
# tie bar 12.749 kg at 0.5464 m. The rocker along its local x; a point mass of 0.5 kg at B too.
BODIES = """
[[link.body]]
name = "rocker"
mass = 4.696
com = [0.3305, 0.0]
I_S = {I_rocker}
[[link.body]]
name = "tie bar"
mass = 12.749
com = [0.5464, 0.0]
[[link.body]]
name = "pin mass"
mass = 0.5
com = "B"
"""


def test_bodies_combine_by_the_parallel_axis_theorem():
    I_rocker = 0.736 - 4.696 * 0.3305**2                   # J_O2 moved to the rocker's own centre
    link3 = ('[[link]]\nid = 3\npoints = { C = [0.0, 0.0], B = [0.3, 0.0], S3 = [0.12, -0.01] }\nmass = 1.2\n'
             'I_S = 0.009\ncom = "S3"\n')
    bodies = ('[[link]]\nid = 3\npoints = { C = [0.0, 0.0], B = [0.3, 0.0] }\n'
              + BODIES.format(I_rocker=I_rocker))
    text = four_bar((link3, ""))
    # the [[link.body]] tables must follow their [[link]]: put link 3 last among the links
    text = text.replace("[[pair]]", bodies + "[[pair]]", 1)
    mech = kinetostat.loads(text)
    link = mech.links[3]
    m = 4.696 + 12.749 + 0.5
    x = (4.696 * 0.3305 + 12.749 * 0.5464 + 0.5 * 0.3) / m
    I = (I_rocker + 4.696 * (0.3305 - x)**2 + 12.749 * (0.5464 - x)**2 + 0.5 * (0.3 - x)**2)
    assert link.mass == pytest.approx(m, rel=1e-15)
    assert link.points[link.com] == pytest.approx((x, 0.0), rel=1e-15)
    assert link.I_S == pytest.approx(I, rel=1e-14)
    # the same about O2 (C): J_O2 of the rocker plus the tie bar and the pin as point masses
    assert link.I_S + m * x**2 == pytest.approx(0.736 + 12.749 * 0.5464**2 + 0.5 * 0.3**2, rel=1e-14)
    assert [b.name for b in link.bodies] == ["rocker", "tie bar", "pin mass"]
    # an analysis with the bodies equals one with the link combined by hand
    by_hand = four_bar((link3, f'[[link]]\nid = 3\npoints = {{ C = [0.0, 0.0], B = [0.3, 0.0], S3 = [{x!r}, 0.0] }}\n'
                               f'mass = {m!r}\nI_S = {I!r}\ncom = "S3"\n'))
    a = kinetostat.analyze(mech, steps=36)
    b = kinetostat.analyze(kinetostat.loads(by_hand), steps=36)
    peak = np.abs(b.forces.R).max()
    assert np.abs(a.forces.R - b.forces.R).max() <= 1e-12 * peak
    assert np.abs(a.balancing_moment - b.balancing_moment).max() <= 1e-12 * np.abs(b.balancing_moment).max()


@pytest.mark.parametrize("body, message", [
    ('[[link.body]]\nmass = 1.0\n', "com"),
    ('[[link.body]]\nmass = 1.0\ncom = "Q"\n', "unknown point 'Q'"),
    ('[[link.body]]\ncom = [0.1, 0.0]\n', "give exactly one of mass or weight"),
    ('[[link.body]]\nmass = -1.0\ncom = [0.1, 0.0]\n', "must be >= 0"),
])
def test_bad_bodies_are_refused_by_name(body, message):
    link3 = ('[[link]]\nid = 3\npoints = { C = [0.0, 0.0], B = [0.3, 0.0], S3 = [0.12, -0.01] }\nmass = 1.2\n'
             'I_S = 0.009\ncom = "S3"\n')
    text = four_bar((link3, "")).replace("[[pair]]", '[[link]]\nid = 3\npoints = { C = [0.0, 0.0], B = [0.3, 0.0] }\n'
                                          + body + "[[pair]]", 1)
    with pytest.raises(ModelError, match=r"link\[id=3\]\.body\[0\]") as exc:
        kinetostat.loads(text)
    assert message in str(exc.value)


# ----------------------------------------------------------------------------- engines

def test_exact_engine_routes_check_a_varying_speed_and_the_rest_say_why_not():
    """Pinocchio and MuJoCo take q, v, a and the applied loads from the scene (the solver's exact
    motion, omega(phi) included): they must agree to rounding; the simulations and the mpmath
    reference are skipped with their reason."""
    pytest.importorskip("pinocchio")
    pytest.importorskip("mujoco")
    from kinetostat_validation.compare import compare
    mech = kinetostat.loads(_with_drive(CRANK_SLIDER, EXPRESSION) + SLIDE_DAMPER + MOTOR)
    c = compare(mech, steps=72)
    assert not c.failed
    assert {r.route for r in c.rows} == {"pinocchio", "mujoco"}
    assert max(r.peak_relative for r in c.rows) <= 1e-9
    assert set(c.skipped) == {"mujoco-sim", "pymunk", "reference"}
    assert all("law of motion" in why for why in c.skipped.values())
    still = compare(kinetostat.loads(CRANK_SLIDER.replace("rpm = 300.0", "rpm = 0")), steps=36,
                    engines=("pinocchio", "reference", "pymunk"))
    assert {r.route for r in still.rows} == {"pinocchio", "reference"} and not still.failed
    assert max(r.peak_relative for r in still.rows) <= 1e-9
    assert "standstill" in still.skipped["pymunk"]


@pytest.mark.parametrize("text", [
    _with_drive(four_bar(), TABLE) + MOTOR + ROTARY_DAMPER, _with_drive(CRANK_SLIDER, EXPRESSION) + SLIDE_DAMPER,
    CRANK_SLIDER.replace("rpm = 300.0", "rpm = 0")], ids=["table-motor-damper", "expression-damper", "standstill"])
def test_virtual_work_route_agrees_at_any_speed_law(text):
    """The d'Alembert-Lagrange route (its own constraint Jacobian, sharing only the kinematics)
    against the group route, with omega(phi), speed-dependent loads, and at standstill."""
    mech = kinetostat.loads(text)
    phi = np.arange(0.0, 360.0, 10.0) + 1.0
    vw, res = kinetostat.virtual_work(mech, phi), kinetostat.analyze(mech, phi_deg=phi)
    peak = np.abs(res.forces.R).max()
    assert np.abs(vw.balancing_moment - res.balancing_moment).max() <= 1e-9 * np.abs(res.balancing_moment).max()
    for p in mech.pairs:
        assert np.abs(vw.reaction(*p.links) - res.reaction(*p.links)).max() <= 1e-9 * peak


def test_standstill_has_no_plans_to_draw_but_says_why():
    from kinetostat.plans import build
    with pytest.raises(ValueError, match=r"stands still \(omega_1 = 0\)"):
        build(kinetostat.load(Path(__file__).parent / "hostile" / "rpm_zero.toml"))


def test_omega_string_without_phi_is_a_constant_speed_over_parameters():
    """`omega = "n1 * pi / 30"` is the constant speed its parameters give (no law of motion);
    `omega = "400 + 50*sin(phi)"` is a law: the reader tells them apart by the name phi."""
    text = kinetostat.examples.path("ice_crank_slider").read_text(encoding="utf-8")
    assert 'rpm = "n1"' in text
    plain = kinetostat.loads(text)
    by_omega = kinetostat.loads(text.replace('rpm = "n1"', 'omega = "n1 * pi / 30"'))
    assert by_omega.drive.law is None and by_omega.drive.omega == pytest.approx(plain.drive.omega, rel=1e-15)
    law = kinetostat.loads(text.replace('rpm = "n1"', 'omega = "400 + 50*sin(phi)"').replace("eps = 0.0\n", ""))
    assert law.drive.law is not None and law.drive.omega == pytest.approx(450.0, rel=1e-6)


def test_a_law_reads_the_models_parameters():
    """A law of motion is an expression of the file's one grammar: it may read the parameters."""
    text = kinetostat.examples.path("ice_crank_slider").read_text(encoding="utf-8").replace("eps = 0.0\n", "")
    law = kinetostat.loads(text.replace('rpm = "n1"', 'omega = "n1 * pi / 30 * (1 + 0.1 * sin(phi))"'))
    phi = np.radians([0.0, 90.0, 270.0])
    w, dw = law.drive.law(phi)
    assert w == pytest.approx(4500 * np.pi / 30 * (1 + 0.1 * np.sin(phi)), rel=1e-15)
    assert dw == pytest.approx(4500 * np.pi / 30 * 0.1 * np.cos(phi), rel=1e-12, abs=1e-9)
    fast = kinetostat.loads(text.replace('rpm = "n1"', 'omega = "n1 * pi / 30 * (1 + 0.1 * sin(phi))"'),
                            parameters={"n1": 9000.0})
    assert fast.drive.law(phi)[0] == pytest.approx(2 * w, rel=1e-15)
