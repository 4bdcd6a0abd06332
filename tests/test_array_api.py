"""The Array API path (kinetostat.arrays) under array-api-strict, the standard's strictest
implementation (no GPU in CI): the same programs bound to its namespace give the numpy path's
motion, reactions and M_bal to 1e-13 of their peaks, and the arrays stay of that library."""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

import kinetostat
from kinetostat import arrays
from kinetostat.analysis import crank_angles, exact

xps = pytest.importorskip("array_api_strict")
sys.path.insert(0, str(Path(__file__).parent))
from test_fast import _four_bar  # noqa: E402


def _numpy(x) -> np.ndarray:
    return np.from_dlpack(x)


def _agree(mech, phi_deg) -> None:
    out = arrays.solve(mech, xps.asarray(np.radians(phi_deg)))
    assert all(type(v).__module__.startswith("array_api_strict") for v in out.values())
    ref = exact(mech, crank_angles(phi_deg))
    for name, want in [("R", kinetostat.planar.as_z(ref.forces.R)), ("M_bal", ref.balancing_moment),
                       ("omega", ref.kin.omega), ("eps", ref.kin.eps), ("origin", ref.kin.origin_z),
                       ("a", ref.kin.a_z), ("cond", ref.cond)]:
        got = _numpy(out[name])
        assert np.max(np.abs(got - want)) <= 1e-13 * np.max(np.abs(want)), name


def test_the_chain_unit_four_bar_on_array_api_strict():
    _agree(kinetostat.load("chain_unit_four_bar"), np.arange(0.0, 360.0, 1.0))


@pytest.mark.parametrize("seed", range(3))
def test_random_four_bars_on_array_api_strict(seed):
    _agree(_four_bar(np.random.default_rng(seed)), np.random.default_rng(seed).uniform(0, 360, 500))


def test_models_with_other_loads_are_refused_by_name():
    with pytest.raises(NotImplementedError, match="gas force"):
        arrays.solve(kinetostat.load("ice_crank_slider"), xps.asarray(np.zeros(3)))
