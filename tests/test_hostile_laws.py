"""Hostile laws of motion, overrides and parameter names (issue 22, points 2, 3, 11): omega(phi),
eps(phi) and a motor's M(omega) checked where they are used (real, finite, omega >= 0 in the
drive's sense), so that no absurd force or silent NaN comes out; `sweep --param g=...` reaches g;
names that Python's NFKC folding would read as another, and the laws' variables, are refused."""
from __future__ import annotations

import re

import numpy as np
import pytest

import kinetostat
from kinetostat import ModelError
from conftest import FOUR_BAR


def _with_law(law: str) -> str:
    if law.startswith("["):
        return FOUR_BAR.replace("rpm = 300.0\n", "").replace("eps = 0.0\n", "") + "\n" + law
    return FOUR_BAR.replace("rpm = 300.0\n", law + "\n").replace("eps = 0.0\n", "")


MOTOR_NAN_AT_SPEED = '\n[[load]]\nname = "motor"\nkind = "moment"\nlink = 1\ncharacteristic = "6*sqrt(20 - omega)"\n'

# (model text, angles analysed, the message's parts): each was accepted with exit 0 before
LAWS = {
    # the audit's reproducer: the complex step read sqrt(<0)'s imaginary part as a slope (eps 1e31)
    "sqrt-of-negative": (_with_law('omega = "10 + sqrt(cos(phi) - 0.99)"'), [30.0],
                         ["drive.omega", "not finite (or not real)", "phi = 8.5 deg"]),
    # a NaN band 0.006 deg wide between the 721 angles checked at load
    "nan-band": (_with_law('omega = "10 + sqrt((sin(phi) - 0.3)**2 - 1e-8)"'), [0.0, float(np.degrees(np.arcsin(0.3)))],
                 ["drive.omega", "phi = 17.4576 deg", "real, finite and >= 0"]),
    # knots all >= 0, the spline dips below 0 between 90 and 90.3 deg: the crank would turn backwards
    "spline-dips-below-zero": (_with_law("[drive.omega_table]\nphi_deg = [0.0, 90.0, 90.3, 180.0, 270.0, 360.0]\n"
                                         "omega = [5.0, 0.0, 0.0, 5.0, 5.0, 5.0]\n"), [90.15],
                               ["drive.omega_table", "omega = -3.1", "phi = 90.15 deg"]),
    # the motor's characteristic is NaN at the running speed (300 rpm): M_bal was silently dropped
    "characteristic-nan-at-speed": (FOUR_BAR + MOTOR_NAN_AT_SPEED, [0.0, 30.0],
                                    ["load 'motor'", "not finite at omega = 31.4159 rad/s", "phi = 0 deg"]),
}


@pytest.mark.parametrize("name", LAWS)
def test_a_law_outside_its_domain_is_refused_naming_the_angle(name):
    text, phi, parts = LAWS[name]
    with pytest.raises(ModelError) as exc:
        kinetostat.analyze(kinetostat.loads(text), phi_deg=phi)
    for part in parts:
        assert part in str(exc.value), str(exc.value)


@pytest.mark.parametrize("name", LAWS)
def test_the_cli_gives_one_line_and_no_table(name, tmp_path, cli):
    text, phi, parts = LAWS[name]
    model, out = tmp_path / "m.toml", tmp_path / "t.csv"
    model.write_text(text, encoding="utf-8")
    p = cli("analyze", model, "--at", *phi, "--out", out)
    assert p.returncode == 2 and "Traceback" not in p.stderr
    assert p.stderr.startswith("kinetostat: error:") and p.stderr.count("\n") == 1, p.stderr
    assert parts[-1] in p.stderr and not out.exists()


def test_a_real_law_keeps_its_exact_derivative():
    """The check leaves a law inside its domain as it was: sqrt(2 + cos) and its complex-step slope."""
    mech = kinetostat.loads(_with_law('omega = "10 + sqrt(2 + cos(phi))"'))
    phi = np.radians([0.0, 45.0, 200.0])
    w, eps = mech.drive.speed(phi)
    root = np.sqrt(2 + np.cos(phi))
    np.testing.assert_allclose(w, 10 + root, rtol=1e-15)
    np.testing.assert_allclose(eps, (10 + root) * -np.sin(phi) / (2 * root), rtol=1e-14)


# ============================================================================ 3. an override reaches every field it names

WEIGHTED = FOUR_BAR.replace("mass = 1.5\n", "mass = \"mass_from_weight(19.62, g)\"\n", 1)


def test_an_override_of_g_reaches_mechanism_g_and_the_weights():
    """mechanism.g written as a number was never overridden: g = 1 made a 19.62 N rod 19.62 kg
    while gravity stayed 9.81. Now both read the override: the rod weighs 19.62 N at any g."""
    assert WEIGHTED != FOUR_BAR
    for g in (1.0, 9.81, 50.0):
        mech = kinetostat.loads(WEIGHTED, parameters={"g": g})
        assert mech.g == g
        rod = next(k for k in mech.links if k.mass and k.id == 2)
        assert rod.mass * mech.g == pytest.approx(19.62, rel=1e-15)


def test_a_sweep_over_g_changes_the_gravity_moment(tmp_path):
    """The audit's reproducer: three identical rows for g = 0, 9.8, 50. At 0 rpm (statics) the
    balancing moment is affine in g: M(g) = M(0) + g dM/dg at every angle."""
    static = FOUR_BAR.replace("rpm = 300.0", "rpm = 0.0")
    model = tmp_path / "m.toml"
    model.write_text(static, encoding="utf-8")
    gs = [0.0, 9.8, 50.0]
    sw = kinetostat.sweep(kinetostat.load(model), {"g": gs}, steps=12, full=True)
    M = {g: sw.angles[sw.angles["g"] == g]["M_bal"].to_numpy() for g in gs}
    slope = (M[9.8] - M[0.0]) / 9.8
    assert np.abs(slope).max() > 0.1                                     # gravity does act
    np.testing.assert_allclose(M[50.0], M[0.0] + 50.0 * slope, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(sw.table["peak_M_bal"], [np.abs(M[g]).max() for g in gs], rtol=1e-12)


# ============================================================================ 11. look-alike and reserved names

@pytest.mark.parametrize("params, message", [
    # FULLWIDTH l: Python folds it to l_OA in an expression, so it silently read the other parameter
    ('"ｌ_OA" = 0.1\nl_OA = 0.2\n', "'ｌ_OA' (U+FF4C FULLWIDTH LATIN SMALL LETTER L) reads as 'l_OA'"),
    # MICRO SIGN: could not be used, and the message showed the same-looking name
    ('"µ" = 0.1\n', "'µ' (U+00B5 MICRO SIGN) reads as 'μ' (U+03BC GREEK SMALL LETTER MU)"),
    # the variables of laws and characteristics shadowed the parameter silently
    ("omega = 3.0\n", "parameters.omega: 'omega' is the variable of a law of motion"),
    ("phi = 1.0\n", "parameters.phi: 'phi' is the variable of a law of motion"),
    # Python keywords: an expression reads True, None, lambda as themselves, never as the parameter
    ("True = 2.0\n", "parameters.True: 'True' is a Python keyword"),
    ("None = 2.0\n", "parameters.None: 'None' is a Python keyword"),
    ("lambda = 2.0\n", "parameters.lambda: 'lambda' is a Python keyword"),
])
def test_look_alike_and_reserved_parameter_names_are_refused(params, message, tmp_path, cli):
    text = FOUR_BAR.replace("[drive]", "[parameters]\n" + params + "[drive]")
    with pytest.raises(ModelError, match=re.escape(message)):
        kinetostat.loads(text)
    model = tmp_path / "m.toml"
    model.write_text(text, encoding="utf-8")
    p = cli("analyze", model, "--steps", "4")
    assert p.returncode == 2 and message in p.stderr and p.stderr.count("\n") == 1, p.stderr
