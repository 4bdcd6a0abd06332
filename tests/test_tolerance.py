"""Tolerance studies (`kinetostat.tolerance`): chunk invariance of the Monte Carlo, first order
against Monte Carlo, the shares, the quantile sketch's bound, bad input, the command line."""
from __future__ import annotations

import dataclasses
import importlib
import math

import numpy as np
import pytest

import kinetostat
from kinetostat.model import parse_text
from kinetostat.sweep import _model_text
from kinetostat.tolerance import first_order, tolerance

tolmod = importlib.import_module("kinetostat.tolerance")      # the module (kinetostat.tolerance is the function)

CHAIN = "chain_unit_four_bar"
LIMITS = {"r": 1e-4, "l": 2e-4}          # m: a tenth and a fifth of a millimetre


def _same(a: tolmod.Tolerance, b: tolmod.Tolerance) -> None:
    """Every Monte Carlo figure of a and b identical, bit for bit (NaN where NaN)."""
    for f in dataclasses.fields(tolmod.MonteCarlo):
        x, y = getattr(a.monte_carlo, f.name), getattr(b.monte_carlo, f.name)
        assert (np.array_equal(x, y, equal_nan=True) if isinstance(x, np.ndarray) else x == y), f.name


@pytest.fixture(scope="module")
def small():
    """80 designs (four seed blocks) x 8 angles in one chunk, in this process: the reference split."""
    return tolerance(CHAIN, LIMITS, samples=80, steps=8, seed=3, chunk=80)


@pytest.mark.parametrize("chunk, scheduler", [(40, None), (20, "threads")])
def test_samples_split_any_way_give_identical_results(small, chunk, scheduler):
    other = tolerance(CHAIN, LIMITS, samples=80, steps=8, seed=3, chunk=chunk, scheduler=scheduler)
    _same(small, other)
    assert small.monte_carlo.failed == 0 and small.monte_carlo.count.min() == 80


def test_another_seed_draws_other_designs(small):
    other = tolerance(CHAIN, LIMITS, samples=20, steps=8, seed=4)
    assert not np.array_equal(small.monte_carlo.peaks[:20], other.monte_carlo.peaks)


@pytest.mark.slow
def test_ten_thousand_samples_split_three_ways_and_on_every_scheduler():
    distributed = pytest.importorskip("distributed")
    ref = tolerance(CHAIN, LIMITS, samples=10_000, steps=36, seed=1, chunk=10_000)
    for chunk, scheduler in [(2500, "threads"), (1000, "processes")]:
        _same(ref, tolerance(CHAIN, LIMITS, samples=10_000, steps=36, seed=1, chunk=chunk, scheduler=scheduler))
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None,
                                  scheduler_kwargs={"dashboard_address": ":0"}) as lc:
        _same(ref, tolerance(CHAIN, LIMITS, samples=10_000, steps=36, seed=1, chunk=1000,
                             scheduler=lc.scheduler_address))


@pytest.fixture(scope="module")
def study():
    """120 designs x 12 angles: first order against Monte Carlo."""
    return tolerance(CHAIN, LIMITS, samples=120, steps=12, seed=7)


def _rss_within_sampling_error(tol: tolmod.Tolerance) -> None:
    """The first-order RSS agrees with the Monte Carlo standard deviation within 4 standard
    errors of a sample standard deviation, SE/std ~ 1/sqrt(2 (n - 1)) (normal-theory bound; a
    uniform's lighter tails make it smaller), at every angle and of every peak."""
    n = tol.monte_carlo.samples
    bound = 4 / math.sqrt(2 * (n - 1))
    at_angle = np.abs(tol.linear.rss / tol.monte_carlo.std - 1)
    peak = np.abs(tol.linear.peak_rss / tol.monte_carlo.peak_std - 1)
    assert at_angle.max() < bound, (at_angle.max(), bound)
    assert peak.max() < bound, (peak.max(), bound)


def test_first_order_rss_agrees_with_the_monte_carlo_std(study):
    _rss_within_sampling_error(study)


@pytest.mark.slow
def test_first_order_rss_agrees_with_the_monte_carlo_std_at_ten_thousand_samples():
    for dist in ("uniform", "normal"):
        _rss_within_sampling_error(tolerance(CHAIN, LIMITS, samples=10_000, steps=36, seed=2, dist=dist))


def test_the_shares_of_each_output_sum_to_one(study):
    np.testing.assert_allclose(study.contributions.at_angle.sum(axis=0), 1.0, rtol=1e-12)
    np.testing.assert_allclose(study.contributions.peak.sum(axis=0), 1.0, rtol=1e-12)
    assert ((study.contributions.peak >= 0) & (study.contributions.peak <= 1)).all()


def test_the_derivatives_agree_with_central_differences(study):
    """dy/dp of every output at every angle against central differences of the analysis (h = 1e-6 m),
    each toleranced parameter set as the samples set it: d/dr holds l fixed (the model writes
    l = sqrt(r**2 + c**2); unpinned, l would follow r)."""
    nominal = dict(zip(study.params, study.values))
    for n, p in enumerate(study.params):
        h = 1e-6
        ys = [tolmod._values(m, kinetostat.analyze(m, phi_deg=study.phi_deg)) for m in
              (kinetostat.load(CHAIN, parameters={**nominal, p: nominal[p] + s}) for s in (h, -h))]
        cd = (ys[0] - ys[1]) / (2 * h)
        np.testing.assert_allclose(study.linear.derivative[n], cd, rtol=1e-5, atol=1e-6 * np.abs(cd).max())


def test_first_order_stacks_by_hand():
    """Two parameters, one output at three angles: the worst case, RSS, the peak by the envelope rule."""
    nominal = np.array([[1.0], [-5.0], [2.0]])          # the peak |y| = 5 at the second angle, y < 0 there
    D = np.array([[[1.0], [2.0], [0.0]], [[0.0], [-1.0], [3.0]]])
    t, sigma = np.array([0.1, 0.2]), np.array([0.1, 0.2]) / math.sqrt(3)
    lin, share = first_order(nominal, D, np.array([0.0, 120.0, 240.0]), t, sigma)
    np.testing.assert_allclose(lin.worst[:, 0], [0.1, 0.2 + 0.2, 0.6])
    np.testing.assert_allclose(lin.rss[:, 0], np.sqrt([0.01 / 3, (0.04 + 0.04) / 3, 0.36 / 3]))
    assert lin.peak[0] == 5.0 and lin.peak_deg[0] == 120.0
    np.testing.assert_allclose(lin.peak_derivative[:, 0], [-2.0, 1.0])   # d|y|/dp = sign(y) dy/dp
    np.testing.assert_allclose(share.peak[:, 0], [0.5, 0.5])
    np.testing.assert_allclose(share.at_angle[:, 2, 0], [0.0, 1.0])


def test_the_histogram_quantiles_lie_within_their_stated_error(small):
    """The sketch's quantiles against the exact order statistics x_(ceil(q n)) of the same designs."""
    study = small
    text, source, _ = _model_text(CHAIN)
    spec = tolmod._Spec(list(study.params), study.values, study.limits, study.dist, study.seed, study.phi_deg,
                        False, study.linear.nominal)
    y = tolmod._outputs(parse_text(text, source), spec, range(study.monte_carlo.samples))[0]
    exact = np.quantile(y, tolmod.QUANTILES, axis=0, method="inverted_cdf")
    mc = study.monte_carlo
    assert (np.abs(mc.quantile - exact) <= mc.quantile_error).all()
    assert np.nanmax(mc.quantile_error / (mc.max - mc.min)) < 0.05        # cells of <= 1/128 of the pilot's 2x range
    np.testing.assert_array_equal(mc.min, y.min(axis=0))
    np.testing.assert_allclose(mc.std, y.std(axis=0, ddof=1), rtol=1e-9)
    np.testing.assert_array_equal(mc.peak_quantiles, np.quantile(np.abs(y).max(axis=1), tolmod.QUANTILES, axis=0))


@pytest.mark.parametrize("limits, kwargs, message", [
    ({"rr": 1e-4}, {}, "'rr' is not a parameter of the model"),
    ({"r": -1e-4}, {}, "r: expected a positive finite limit"),
    ({"r": float("nan")}, {}, "r: expected a positive finite limit"),
    ({}, {}, "no parameter given a tolerance"),
    (LIMITS, {"dist": "triangular"}, "dist: expected 'uniform' or 'normal'"),
    (LIMITS, {"samples": 0}, "samples: expected a whole number >= 1"),
    (LIMITS, {"chunk": 30}, r"chunk: expected a multiple of SEED_BLOCK \(20\)"),
])
def test_bad_input_is_named(limits, kwargs, message):
    with pytest.raises(ValueError, match=message):
        tolerance(CHAIN, limits, **{"samples": 20, "steps": 4, **kwargs})


# ----------------------------------------------------------------------------- the command line

def test_the_command_writes_a_table_an_xarray_file_and_a_tornado_chart(cli, tmp_path):
    import xml.etree.ElementTree as ET
    pytest.importorskip("xarray")
    r = cli("tolerance", CHAIN, "--tol", "r=0.1mm", "--tol", "l=2e-4", "--samples", "20", "--steps", "8",
            "--out", tmp_path)
    assert r.returncode == 0, r.stderr
    head = (tmp_path / "tolerance.csv").read_text().splitlines()
    assert head[0].startswith("output,unit,nominal [N or N m],peak_deg [deg],linear_worst [N or N m]")
    assert head[0].endswith("share_r [1],share_l [1]") and len(head) == 6        # four pairs and M_bal
    import xarray as xr
    with xr.open_dataset(tmp_path / "tolerance.nc", engine="scipy") as ds:
        assert ds["M_bal_mc_std"].attrs["units"] == "N m" and ds.sizes["phi"] == 8
        assert ds.attrs["limits"] == "r: 0.0001 m, l: 0.0002 m"                 # 0.1 mm in the model's metres
    svg = ET.parse(tmp_path / "tornado.svg").getroot()
    assert sum(1 for e in svg.iter() if e.tag.endswith("rect")) == 2 * 5        # a bar per parameter and peak


@pytest.mark.parametrize("args, message", [
    (["--tol", "m2=0.1mm"], "--tol m2=0.1mm: 'mm' is not a unit of m2 (kg); use kg, g, %"),
    (["--tol", "r=abc"], "invalid --tol 'r=abc': expected NAME=VALUE[UNIT] with a positive VALUE"),
    (["--tol", "rr=1mm"], "--tol rr: not a parameter of the model (did you mean 'r'?)"),
    (["--tol", "r=1mm", "--tol", "r=2mm"], "--tol r: given more than once"),
    (["--tol", "r=1mm", "--chunk", "30"], "--chunk expected a multiple of SEED_BLOCK (20) samples, got 30"),
])
def test_bad_options_are_one_line_naming_the_option(cli, tmp_path, args, message):
    r = cli("tolerance", CHAIN, *args, "--samples", "20", "--steps", "4", "--out", tmp_path / "out")
    assert r.returncode == 2 and message in r.stderr and "Traceback" not in r.stderr, r.stderr
    assert not any((tmp_path / "out").glob("*"))                               # nothing written
