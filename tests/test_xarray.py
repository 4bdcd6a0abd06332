"""`Analysis.to_xarray` and `Sweep.to_xarray`: the values are the result's own arrays, exactly;
dimensions, coordinates and attrs as documented; without xarray an ImportError names the extra."""
from __future__ import annotations

import sys

import numpy as np
import pytest

import kinetostat
from kinetostat.model.lettering import pair_name

VARIABLE_ATTRS = {"units", "frame", "long_name"}


@pytest.fixture(scope="module")
def xr():
    return pytest.importorskip("xarray", reason="xarray (the optional extra 'kinetostat[xarray]') is not installed")


@pytest.fixture(scope="module")
def ice():
    return kinetostat.analyze(kinetostat.load("ice_crank_slider"), steps=36)


@pytest.fixture(scope="module")
def four_bar_sweep():
    """A sweep with every angle kept, whose last design (r = 3 m) cannot be assembled."""
    return kinetostat.sweep("chain_unit_four_bar", {"r": [0.05, 0.08, 3.0], "n_k": [0, 120]}, steps=12, full=True)


def test_without_xarray_to_xarray_names_the_extra(monkeypatch, ice, four_bar_sweep):
    monkeypatch.setitem(sys.modules, "xarray", None)       # `import xarray` raises ImportError
    for result in (ice, four_bar_sweep):
        with pytest.raises(ImportError, match=r"to_xarray needs xarray.*pip install 'kinetostat\[xarray\]'"):
            result.to_xarray()


def test_the_ice_dataset_holds_the_analysis_arrays_exactly(xr, ice):
    ds, m = ice.to_xarray(), ice.mech
    eq = np.testing.assert_array_equal
    eq(ds.phi, ice.phi_deg)
    for p in m.pairs:
        i, j = p.links
        R = ds.R.sel(pair=pair_name(m, p))
        assert (int(R.i), int(R.j)) == (i, j)
        eq(R, ice.reaction(i, j))
        eq(-R, ice.reaction(j, i))
    eq(ds.M_bal, ice.balancing_moment)
    eq(ds.M_lever, ice.lever_moment)
    for k in range(1, m.n_links):
        for name, of in (("theta", ice.theta), ("omega", ice.omega), ("eps", ice.eps)):
            eq(ds[name].sel(link=k), of(k))
        eq(ds.F_i.sel(link=k), ice.F_i[:, k])
        eq(ds.M_i.sel(link=k), ice.M_i[:, k])
        eq(ds.F_applied.sel(link=k), ice.F_applied[:, k])
    for name in m.point_names:
        eq(ds.position.sel(point=name), ice.position(name))
        eq(ds.velocity.sel(point=name), ice.velocity(name))
        eq(ds.acceleration.sel(point=name), ice.acceleration(name))
    eq(ds.error, ice.error)
    eq(ds.singular, ice.singular)
    eq(ds.cond, ice.cond)
    eq(ds.eta, ice.efficiency)                 # the ICE's friction: the first approximation
    eq(ds.self_locking, ice.self_locking)
    eq(ds.P_fr.sel(pair="R12 at A"), ice.friction_power[:, m.pair_between(1, 2).index])


def test_the_ice_dataset_names_its_dimensions_units_frames_and_conventions(xr, ice):
    ds = ice.to_xarray()
    assert dict(ds.sizes) == {"phi": 36, "point": 4, "xy": 2, "link": 3, "pair": 4, "group": 1}
    assert ds.phi.attrs == {"units": "deg", "frame": "world", "long_name": "crank angle",
                            "reference_direction": "(0, 1) in the world frame", "sense": "clockwise"}
    assert ds.pair.values.tolist() == ["R41 at O", "R12 at A", "R23 at B", "R43 slider B on guide O"]
    assert (ds.i.values.tolist(), ds.j.values.tolist()) == ([0, 1, 2, 0], [1, 2, 3, 3])
    assert ds.pair_kind.values.tolist() == ["R", "R", "R", "P"]
    assert ds.link.values.tolist() == [1, 2, 3]
    assert ds.link_name.values.tolist() == ["crank", "connecting rod", "piston"]
    assert ds.point.values.tolist() == ["O", "A", "B", "S2"] and ds.point_link.values.tolist() == [0, 1, 2, 2]
    assert ds.xy.values.tolist() == ["x", "y"]
    assert ds.R.dims == ("phi", "pair", "xy") and ds.position.dims == ("phi", "point", "xy")
    assert ds.omega.dims == ("phi", "link") and ds.M_bal.dims == ("phi",)
    for name, var in ds.data_vars.items():
        assert set(var.attrs) >= VARIABLE_ATTRS, name
        assert var.attrs["frame"] in ("world", "none"), name
    units = {name: var.attrs["units"] for name, var in ds.data_vars.items()}
    assert units == {"position": "m", "velocity": "m/s", "acceleration": "m/s^2", "theta": "rad", "omega": "rad/s",
                     "eps": "rad/s^2", "F_applied": "N", "M_applied": "N m", "F_i": "N", "M_i": "N m", "R": "N",
                     "M_bal": "N m", "M_lever": "N m", "error": "1", "singular": "bool", "cond": "1", "P_fr": "W",
                     "eta": "1", "self_locking": "bool"}
    assert "F_bal" not in ds                    # an engine: its drive applies a couple, no force
    assert ds.R.attrs["long_name"] == "reaction: force exerted by link i on link j in the pair"
    assert ds.attrs["mechanism"] == ice.mech.name
    assert ds.attrs["model_file"].endswith("ice_crank_slider.toml")
    assert (ds.attrs["g"], ds.attrs["g_units"], ds.attrs["drive"], ds.attrs["friction_method"]) == \
        (9.81, "m/s^2", "engine", "first")
    assert "R: force exerted by link i on link j" in ds.attrs["conventions"]


def test_friction_in_the_reactions_and_a_machine_add_their_variables(xr):
    with pytest.warns(kinetostat.SelfLockingWarning):
        res = kinetostat.analyze(kinetostat.load("ice_crank_slider"), steps=12, friction="reactions")
    ds, m = res.to_xarray(), res.mech
    assert ds.attrs["friction_method"] == "reactions"
    assert ds.revolute_pair.values.tolist() == ["R41 at O", "R12 at A", "R23 at B"]
    assert ds.prismatic_pair.values.tolist() == ["R43 slider B on guide O"]
    assert (ds.M_fr.attrs["units"], ds.F_fr.attrs["units"]) == ("N m", "N")
    np.testing.assert_array_equal(ds.M_fr.sel(revolute_pair="R23 at B"), res.friction.load[:, m.pair_between(2, 3).index])
    np.testing.assert_array_equal(ds.F_fr.sel(prismatic_pair="R43 slider B on guide O"),
                                  res.friction.load[:, m.pair_between(0, 3).index])
    np.testing.assert_array_equal(ds.M_bal_0, res.balancing_moment_frictionless)
    machine = kinetostat.analyze(kinetostat.load("compressor"), steps=12)
    dm = machine.to_xarray()
    assert dm.F_bal.dims == ("phi", "xy") and dm.attrs["drive"] == "machine"
    np.testing.assert_array_equal(dm.F_bal, machine.balancing_force)


def test_the_sweep_dataset_holds_its_tables_design_axes_before_the_angle(xr, four_bar_sweep):
    sw = four_bar_sweep
    ds = sw.to_xarray()
    assert dict(ds.sizes) == {"r": 3, "n_k": 2, "phi": 12}
    assert ds.r.values.tolist() == [0.05, 0.08, 3.0] and ds.n_k.values.tolist() == [0.0, 120.0]
    assert (ds.r.attrs["units"], ds.n_k.attrs["units"], ds.phi.attrs["units"]) == ("m", "rpm", "deg")
    table = sw.table
    np.testing.assert_array_equal(ds.peak_R_0_1, sw.peak("R_0_1"))
    np.testing.assert_array_equal(ds.peak_M_bal.values.ravel(), table["peak_M_bal"].to_numpy(dtype=float))
    assert ds.error.values.ravel().tolist() == table["error"].tolist()
    assert ds.peak_R_0_1.attrs == {"units": "N", "frame": "none", "long_name": "largest |R_0_1| over the cycle"}
    assert ds.M_bal.dims == ("r", "n_k", "phi") and ds.M_bal.attrs["units"] == "N m"
    angles = sw.angles
    for r, n_k in ((0.05, 0.0), (0.08, 120.0)):
        rows = angles[(angles.r == r) & (angles.n_k == n_k)]
        design = ds.sel(r=r, n_k=n_k)
        for col in ("Rx_1_2", "omega_2", "x_B", "M_bal"):
            np.testing.assert_array_equal(design[col], rows[col].to_numpy())
        np.testing.assert_array_equal(design.singular, rows.singular.to_numpy(dtype=float))
    failed = ds.sel(r=3.0)
    assert failed.error.str.startswith("AssemblyError").all()
    assert np.isnan(failed.M_bal).all() and np.isnan(failed.singular).all() and np.isnan(failed.peak_M_bal).all()
    for name, var in ds.variables.items():
        if name not in ds.dims:
            assert set(var.attrs) >= VARIABLE_ATTRS, name


def test_a_sweep_of_peaks_only_gives_a_dataset_over_the_designs(xr):
    sw = kinetostat.sweep("chain_unit_four_bar", {"n_k": [0, 60, 120]}, steps=12)
    ds = sw.to_xarray()
    assert dict(ds.sizes) == {"n_k": 3} and "phi" not in ds.coords
    np.testing.assert_array_equal(ds.peak_R_2_3, sw.peak("R_2_3"))


def test_netcdf_round_trip(xr, ice, tmp_path):
    pytest.importorskip("scipy", reason="no NetCDF engine: scipy (netCDF3, the engine tested here) is not installed")
    ds = ice.to_xarray()
    ds.to_netcdf(tmp_path / "ice.nc", engine="scipy")
    xr.testing.assert_identical(xr.load_dataset(tmp_path / "ice.nc", engine="scipy"), ds)
