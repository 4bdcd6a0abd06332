"""Hostile input still open from earlier audits (issue 35, class 8): `sweep --param g` reaches the
weights, a pole of omega(phi) between the checked angles, a g so small that its weights vanish, a
gas-force scale that holds a pressure combined with pressures in the diagram (or a pressure
stated in MPa), and the file in the way of `variant --all` named."""
from __future__ import annotations

import pytest

import kinetostat
from kinetostat import ModelError, ModelWarning
from conftest import FOUR_BAR, ROOT

ICE = (ROOT / "models" / "ice_crank_slider.toml").read_text(encoding="utf-8")


def _edit(text: str, old: str, new: str) -> str:
    assert old in text, old
    return text.replace(old, new, 1)


# ============================================================================ sweep --param g

def test_sweep_over_g_from_the_command_line_scales_a_static_weight_moment(tmp_path, cli):
    """At standstill with no load but the weights, M_bal is the weights' moment: g times a
    function of the angle, so g = 2 and 4 give 2 and 4 times the moment of g = 1 at every angle."""
    import pandas as pd
    model = tmp_path / "static.toml"
    static = _edit(_edit(FOUR_BAR, "rpm = 300.0", "rpm = 0.0"), "value = -4.0", "value = 0.0")
    model.write_text(static, encoding="utf-8")
    p = cli("sweep", model, "--param", "g=1,2,4", "--steps", "12", "--full", "--out", tmp_path / "s.csv")
    assert p.returncode == 0, p.stderr
    angles = pd.read_csv(tmp_path / "s.angles.csv")
    M = {g: angles[angles["g [m/s^2]"] == g]["M_bal [N m]"].to_numpy() for g in (1, 2, 4)}
    assert abs(M[1]).max() > 0.05                        # the weights do act
    assert M[2] == pytest.approx(2 * M[1], rel=1e-10, abs=1e-15)        # the table's 12 digits
    assert M[4] == pytest.approx(4 * M[1], rel=1e-10, abs=1e-15)


# ============================================================================ a pole of omega(phi)

def _law(omega: str) -> str:
    return _edit(_edit(FOUR_BAR, "rpm = 300.0", f'omega = "{omega}"'), "eps = 0.0\n", "")


@pytest.mark.parametrize("omega", [
    "10/sin(phi-1.234)**2",      # periodic and >= 0: loaded, 8e5 rad/s at 70.5 deg, infinite at 70.70 deg
    "10/(phi-1.234)",            # refused only as "omega < 0", the pole unnamed
    "2 + 1/(1.000000001 - cos(phi-1.234))",     # finite, but 1e9 rad/s there, 1.5e5 at most where checked
])
def test_a_pole_of_omega_between_the_checked_angles_is_refused_with_its_interval(omega):
    with pytest.raises(ModelError) as exc:
        kinetostat.loads(_law(omega))
    (problem,) = exc.value.problems
    assert problem.startswith("drive.omega: omega(phi) has a pole between phi = 70.5 and 71 deg"), problem
    assert "at phi = 70.7" in problem


@pytest.mark.filterwarnings("ignore:.*crank pin moves at:kinetostat.ModelWarning")
@pytest.mark.parametrize("omega", ["50*(1 + 0.3*cos(phi))", "10 + 1/(1.0001 - cos(phi - 1.234))"])
def test_a_smooth_law_with_a_steep_finite_peak_still_loads(omega):
    """The second peaks at 1e4 rad/s between two checked angles: steep, but no pole."""
    assert kinetostat.loads(_law(omega)).drive.law is not None


# ============================================================================ a vanishing g

@pytest.mark.parametrize("g", ["3e-308", "1e-200"])
def test_a_g_whose_weights_vanish_is_refused(g, tmp_path, cli):
    """3e-308 is a normal double, but 0.8 kg times it is not: it loaded with a warning, exit 0."""
    model = tmp_path / "tiny_g.toml"
    model.write_text(_edit(FOUR_BAR, "g = 9.81", f"g = {g}"), encoding="utf-8")
    p = cli("analyze", model, "--steps", "4")
    assert p.returncode == 2 and p.stdout == "", p.stdout
    assert p.stderr.splitlines() == [f"kinetostat: error: {model}: line 4: mechanism.g: {float(g):g} m/s^2 is below "
                                     f"1e-150: the weights g m would lose their digits or vanish; write 0 to "
                                     f"switch gravity off, or g in m/s^2 (9.81)"]


# ============================================================================ a gas force's units

MPA_PRESSURES = "value = [2.4, 2.23, 1.92, 1.49, 1.08, 0.6, 0.29, 0.12, 0.05, 0.07, 0.14, 0.29, 0.72, 1.44, 2.04, 2.4]"


def test_pressures_in_mpa_under_a_scale_in_n_are_warned():
    """The diagram's values as pressures in MPa while the scale is the piston area times p_max
    (N): the gas force 2.4 times too large, silently."""
    text = _edit(ICE, "value = [1.0, 0.93, 0.8, 0.62, 0.45, 0.25, 0.12, 0.05, 0.02, 0.03, 0.06, 0.12, 0.3, 0.6, 0.85, 1.0]",
                 MPA_PRESSURES)
    with pytest.warns(ModelWarning) as caught:
        kinetostat.loads(text, "ice.toml")
    said = [str(w.message) for w in caught if "table.value" in str(w.message)]
    assert said == ["ice.toml: line 102: load[0].table.value: the diagram's values reach 2.4, but its scale "
                    "(\"pi / 4 * d**2 * p_max\" = 12063.7 N) already holds the pressure parameters.p_max: the values "
                    "are then fractions of it (at most 1); are they pressures (MPa)? Give them as p/p_max, or a scale "
                    "of the area alone (m^2, values in Pa)"]


@pytest.mark.filterwarnings("ignore:.*the diagram's largest force:kinetostat.ModelWarning")
def test_a_pressure_stated_in_mpa_in_a_scale_in_n_is_warned():
    text = _edit(ICE, "p_max = 2.4e6                # largest cylinder pressure, Pa",
                 "p_max = 2.4                  # largest cylinder pressure, MPa")
    with pytest.warns(ModelWarning, match=r"line 103: load\[0\]\.table\.scale: reads parameters\.p_max, stated in "
                                          r"MPa; .* give p_max in Pa \(1 MPa = 1e6 Pa\)"):
        kinetostat.loads(text, "ice.toml")


def test_the_bundled_gas_diagrams_raise_no_doubt_about_their_units(recwarn):
    for name in ("ice_crank_slider", "compressor", "opposed_twin"):
        kinetostat.load(name)
    assert not [w for w in recwarn if "table." in str(w.message)]


# ============================================================================ variant --all: the file in the way

def test_variant_all_names_the_file_in_the_way(tmp_path, cli, monkeypatch):
    """A file named like a variant's folder: 'cannot write --out OUT: File exists', no name."""
    from kinetostat import variants
    monkeypatch.setattr(variants, "codes", lambda: ["000"])
    out = tmp_path / "out"
    out.mkdir()
    (out / "task1_000").write_text("mine\n")
    p = cli("variant", "1", "--all", "--out", out, "--no-progress", "--no-pack")
    assert p.returncode == 2 and "Traceback" not in p.stderr
    lines = p.stderr.splitlines()                   # the job's first line, then the error where it stopped
    assert lines[-1] == f"kinetostat: error: cannot write --out {out}: {out / 'task1_000'}: File exists"
    assert lines[:-1] == [f"variant --all: 1 code(s) of task(s) 1 into {out}, no pack"], lines
    assert (out / "task1_000").read_text() == "mine\n"
