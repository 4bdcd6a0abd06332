"""kinetostat.sensitivity: exact forward-mode derivatives of the kinematics, reactions and M_bal by a
model's parameters, against an independent route: central differences of whole analyses of the model
re-loaded with the parameter overridden (`kinetostat.load(path, parameters=...)`, as `sweep` sets
parameters), Richardson-extrapolated in float64 (truncation O(h^4))."""
from __future__ import annotations

import numpy as np
import pytest

import kinetostat
from kinetostat.analysis import exact

from conftest import ROOT

CHAIN = ROOT / "models" / "chain_unit_four_bar.toml"
ICE = ROOT / "models" / "ice_crank_slider.toml"
PHI = np.arange(360.0)
#: Agreement asked for: the largest difference over the angles, relative to the output's largest |value|.
RTOL = 1e-8

#: What is compared: (name, Analysis -> array, Sensitivity -> parameter -> array).
OUTPUTS = (("M_bal", lambda r: r.balancing_moment, lambda s: s.balancing_moment),
           ("R01", lambda r: r.reaction(0, 1), lambda s: s.reaction(0, 1)),
           ("R12", lambda r: r.reaction(1, 2), lambda s: s.reaction(1, 2)),
           ("R32", lambda r: r.reaction(3, 2), lambda s: s.reaction(3, 2)),
           ("x_B", lambda r: r.position("B"), lambda s: s.position("B")),
           ("v_B", lambda r: r.velocity("B"), lambda s: s.velocity("B")),
           ("a_B", lambda r: r.acceleration("B"), lambda s: s.acceleration("B")))


def richardson(path, name: str, x0: float, rel_step: float = 1e-3):
    """output -> d output / d name at x0, by central differences of analyses of the model re-loaded
    with name = x0 +- h, x0 +- h/2, Richardson-extrapolated."""
    h = rel_step * abs(x0)
    runs = {k: exact(kinetostat.load(path, parameters={name: x0 + k * h}), PHI, "first") for k in (-1, -0.5, 0.5, 1)}

    def of(output) -> np.ndarray:
        D = lambda k: (np.asarray(output(runs[k])) - np.asarray(output(runs[-k]))) / (2 * k * h)
        return (4 * D(0.5) - D(1)) / 3
    return of


def worst(path, names) -> dict[tuple[str, str], float]:
    """(parameter, output) -> the largest relative difference of the exact derivative from Richardson's."""
    sens = kinetostat.sensitivity(kinetostat.load(path), params=names, phi_deg=PHI)
    out = {}
    for name in names:
        differences = richardson(path, name, sens.values[name])
        for label, of_result, of_sens in OUTPUTS:
            ref = differences(of_result)
            scale = np.abs(ref).max()
            got = of_sens(sens)[name]
            out[name, label] = 0.0 if scale == 0 and not np.abs(got).max() else float(np.abs(got - ref).max() / scale)
    return out


CHAIN_SAMPLE = ["r", "h", "m2", "J_C2", "g"]             # a length, a frame point, a mass, an inertia, g
ICE_SAMPLE = ["l_OA", "n1", "p_max", "G2"]               # a length, the speed, the gas table's scale, a weight
CHAIN_ALL = ["r", "n_k", "c", "h", "m1_mA", "J_1", "m2", "AC2", "J_C2", "m3", "O2C3", "J_O2", "m_tb", "O2Sh", "g"]
ICE_ALL = ["n1", "l_OA", "l_AB", "AS2_AB", "d", "p_max", "G2", "G3", "I_S2", "g"]


@pytest.mark.parametrize("path, names", [(CHAIN, CHAIN_SAMPLE), (ICE, ICE_SAMPLE)], ids=["chain_unit", "ice"])
def test_agrees_with_richardson_differences(path, names):
    """Kinematics, reactions and M_bal of the chain-unit four-bar (its bodies, a dependent coupler
    length l = sqrt(r^2 + c^2)) and the ICE crank-slider (a phi table load scaled by p_max, masses from
    weights) at 360 angles, to 1e-8 of each output's scale."""
    bad = {k: v for k, v in worst(path, names).items() if not v <= RTOL}
    assert not bad, bad


@pytest.mark.slow
@pytest.mark.parametrize("path, names", [(CHAIN, CHAIN_ALL), (ICE, ICE_ALL)], ids=["chain_unit", "ice"])
def test_every_parameter_agrees_with_richardson_differences(path, names):
    bad = {k: v for k, v in worst(path, names).items() if not v <= RTOL}
    assert not bad, bad


def test_balancing_moment_is_affine_in_g():
    """M_bal = M_0 + g M_g (masses given as masses): d M_bal / d g is exactly its gravity part over g."""
    sens = kinetostat.sensitivity(kinetostat.load(CHAIN), params=["g", "r"], steps=90)
    g = sens.values["g"]
    weightless = exact(kinetostat.load(CHAIN, parameters={"g": 0.0}), sens.phi_deg, "first").balancing_moment
    gravity_part = sens.result.balancing_moment - weightless
    np.testing.assert_allclose(sens.balancing_moment["g"], gravity_part / g, rtol=0,
                               atol=1e-12 * np.abs(gravity_part / g).max())


def test_reactions_are_affine_in_the_gas_pressure():
    """The gas force is the only load p_max scales: d R / d p_max = (R - R at p_max = 0) / p_max."""
    sens = kinetostat.sensitivity(kinetostat.load(ICE), params=["p_max"], steps=72)
    p = sens.values["p_max"]
    idle = exact(kinetostat.load(ICE, parameters={"p_max": 0.0}), sens.phi_deg, "first")
    for i, j in ((0, 1), (1, 2), (3, 2), (0, 3)):
        part = (sens.result.reaction(i, j) - idle.reaction(i, j)) / p
        np.testing.assert_allclose(sens.reaction(i, j)["p_max"], part, rtol=0, atol=1e-12 * np.abs(part).max())


def test_result_is_the_analysis_and_arrays_are_read_only():
    mech = kinetostat.load(CHAIN)
    sens = kinetostat.sensitivity(mech, params=["r"], steps=36)
    ref = kinetostat.analyze(mech, steps=36)
    np.testing.assert_array_equal(sens.result.balancing_moment, ref.balancing_moment)
    assert sens.params == ("r",) and sens.values == {"r": 0.08} and sens.phi_deg.shape == (36,)
    d = sens.reaction(1, 2)["r"]
    assert d.shape == (36, 2) and not d.flags.writeable
    np.testing.assert_array_equal(sens.reaction(2, 1)["r"], -d)       # R_21 = -R_12
    assert np.all(sens.error < 1e-10) and sens.error.shape == (36,)
    with pytest.raises(AttributeError, match="engine"):
        sens.balancing_force


def test_every_parameter_by_default():
    mech = kinetostat.load(ICE)
    sens = kinetostat.sensitivity(mech, steps=8)
    assert sens.params == tuple(mech.parameters)


@pytest.mark.parametrize("params, match", [(["r", "nope"], "'nope' is not a parameter.*Parameters: r, n_k"),
                                           (["r", "r"], "names a parameter twice"), ([], "params is empty")])
def test_bad_params_are_named(params, match):
    with pytest.raises(ValueError, match=match):
        kinetostat.sensitivity(kinetostat.load(CHAIN), params=params, steps=4)


def test_to_xarray_has_every_output_by_every_parameter_with_units():
    pytest.importorskip("xarray")
    ds = kinetostat.sensitivity(kinetostat.load(CHAIN), params=["r", "m2"], steps=12).to_xarray()
    assert ds["dM_bal"].dims == ("param", "phi") and ds["dR"].dims == ("param", "phi", "pair", "xy")
    assert list(ds["param"].values) == ["r", "m2"] and list(ds["param_unit"].values) == ["m", "kg"]
    assert ds["dR"].attrs["units"] == "N" and "per unit of the parameter" in ds["dR"].attrs["long_name"]
    assert ds["dposition"].sizes["point"] == len(kinetostat.load(CHAIN).point_names)
