"""Potapov (seed 004): the chain-unit four-bar's rocker angle in closed form and the reported
range of the crank-bearing reaction."""
from __future__ import annotations

import numpy as np
import pytest

import kinetostat
from conftest import ROOT

r, h, c = 0.080, 0.585, 0.540
b = np.hypot(c, h)          # the paper: b = sqrt(c^2 + h^2) = 796.13 mm, printed as 796.1
l = np.hypot(r, c)
#: The paper reports F_O1 to 0.1 N from its own sampling; its geometry is reconstructed (see the model).
PAPER = 0.01


@pytest.fixture(scope="module")
def mech():
    return kinetostat.load(ROOT / "models" / "chain_unit_four_bar.toml")


def test_rocker_angle_equals_the_papers_closed_form(mech):
    """psi(phi_k) of seed 004 (eqs. at lines 81-87): from the downward vertical at O2 to O2B."""
    phi_k = np.arange(0.0, 360.0, 0.5)
    res = kinetostat.analyze(mech, phi_deg=phi_k)
    phi = np.radians(phi_k) - np.arctan(c / h)
    a = np.sqrt(r**2 + b**2 - 2 * r * b * np.cos(phi))
    psi = np.arctan(r * np.sin(phi) / (b - r * np.cos(phi))) + np.arccos((a**2 + h**2 - l**2) / (2 * a * h)) \
        - np.arctan(c / h)
    B, O2 = res.position("B"), res.position("O2")
    psi_solver = np.arctan2(B[:, 0] - O2[:, 0], O2[:, 1] - B[:, 1])
    assert np.max(np.abs(psi_solver - psi)) < 1e-10


def test_crank_bearing_reaction_range(mech):
    """The paper: O1 is the most loaded pair, F_O1 from 38.4 N to 286.9 N, the maximum near 90 deg
    (its cycle sampled every 10 deg)."""
    res = kinetostat.analyze(mech, phi_deg=np.arange(0.0, 360.0, 10.0))
    F = np.linalg.norm(res.reaction(0, 1), axis=-1)
    assert F.min() == pytest.approx(38.4, rel=PAPER)
    assert F.max() == pytest.approx(286.9, rel=PAPER)
    assert 80.0 <= res.phi_deg[np.argmax(F)] <= 100.0
    # the most loaded pair of the mechanism
    others = [np.linalg.norm(res.reaction(i, j), axis=-1).max() for i, j in ((1, 2), (2, 3), (0, 3))]
    assert F.max() > max(others)


def test_the_study_redone_with_derivatives(mech):
    """Seed 004's study (crank radius r x crank speed n_k, the largest |R(0,1)| on the paper's 10-deg grid)
    by exact derivatives at each of its cases: the trend the table shows, and its differences."""
    from kinetostat.report.writer import study_slopes, study_table
    table = study_table(mech)
    slopes, angles = study_slopes(mech)
    d_r, d_n = slopes[..., 0], slopes[..., 1]
    assert np.all(d_r > 0)                                  # the peak grows with r at every speed ...
    assert np.all(np.diff(d_r, axis=1) > 0)                 # ... the more, the faster the crank turns
    assert np.all(np.abs(d_n[:, 0]) < 1e-12 * table[:, 0])  # flat in n_k at standstill (inertia ~ n_k^2)
    assert np.all(d_n[:, 1:] > 0) and np.all(np.diff(d_n, axis=1) > 0)
    r = np.array(mech.study.vary[0][1])
    centred = (table[2:] - table[:-2]) / (r[2:] - r[:-2])[:, None]      # the table's own differences, 15 mm apart
    same = (angles[2:] == angles[1:-1]) & (angles[:-2] == angles[1:-1])  # the three cases peak at one grid angle
    assert same.sum() >= 10
    np.testing.assert_allclose(centred[same], d_r[1:-1][same], rtol=5e-3)   # O(h^2) of the 15 mm steps
    step = r[1] - r[0]
    simpson = step / 3 * (d_r[0] + 4 * d_r[1] + 2 * d_r[2] + 4 * d_r[3] + d_r[4])
    np.testing.assert_allclose(simpson, table[-1] - table[0], rtol=1e-2)    # r = 50 -> 110 mm
