"""Triad leashes with a prismatic pair other than the slider on the known link's guide: the
inner pair prismatic, its guide on the base (the bundled triad_rocking_block) or on the leash
(the same mechanism written the other way round), and the outer pair prismatic with its guide on
the leash (triad_slider written the other way round). Each variant runs test_triad's checks
against independent formulations (the constraint Jacobian, the group's 12 x 12 system, virtual
work, the engines, the 40-digit reference); a leash with two prismatic pairs is refused by name."""
from __future__ import annotations

import numpy as np
import pytest

import kinetostat
from conftest import ROOT
from test_triad import (test_group_order_reactions_equal_the_groups_full_linear_system,  # noqa: F401 (run here)
                        test_special_point_velocities_equal_the_jacobians, test_the_exact_routes_agree_on_a_sample_of_the_cycle,
                        test_virtual_work_and_the_lever_agree_over_the_cycle)

PHI = np.arange(0.0, 360.0, 15.0)
#: (bundled model, its prismatic pair as bundled, the same pair written the other way round)
VARIANTS = {
    "guide on the leash": ("triad_rocking_block", 'links = [3, 5]        # the guide (the arm) on the base, the block '
                           'slides on it\nguide = "D"\ndirection = [1.0, 0.0]\npoint = "F"',
                           'links = [5, 3]\nguide = "F"\ndirection = [1.0, 0.0]\npoint = "D"'),
    "outer guide on the leash": ("triad_slider", 'links = [0, 5]\nguide = "G"\ndirection = [1.0, 0.0]\npoint = "D"',
                                 'links = [5, 0]\nguide = "D"\ndirection = [1.0, 0.0]\npoint = "G"'),
}


def _variant(name: str):
    stem, old, new = VARIANTS[name]
    text = (ROOT / "models" / f"{stem}.toml").read_text()
    assert old in text
    return kinetostat.load(ROOT / "models" / f"{stem}.toml"), kinetostat.loads(text.replace(old, new))


@pytest.fixture(scope="module", params=sorted(VARIANTS))
def mech(request):
    return _variant(request.param)[1]


@pytest.mark.parametrize("name", sorted(VARIANTS))
def test_the_pair_written_either_way_is_the_same_mechanism(name):
    """A prismatic pair's guide on either of its links is one constraint: the variant's base
    pose, M_bal and reactions equal the bundled model's to rounding (the pair's reaction, of
    its first link on its second, with the sign flipped); the structure names the pairs."""
    bundled, variant = _variant(name)
    a, b = kinetostat.analyze(bundled, phi_deg=PHI), kinetostat.analyze(variant, phi_deg=PHI)
    g = variant.structure.groups[0]
    assert (g.kind, g.inner) == (("RRR", "RRP") if name == "guide on the leash" else ("RRP", "RRR"))
    assert "III3" in g.describe() and ("inner pairs RRP" in g.describe()) == (name == "guide on the leash")
    assert np.max(np.abs(a.kin.origin_z[:, 3] - b.kin.origin_z[:, 3])) <= 1e-15
    peak = np.max(np.abs(a.balancing_moment))
    assert np.max(np.abs(a.balancing_moment - b.balancing_moment)) <= 1e-13 * peak
    R = np.max(np.abs(a.forces.R))
    for p in bundled.pairs:
        assert np.max(np.abs(a.reaction(*p.links) - b.reaction(*p.links))) <= 1e-13 * R, p.label


def test_a_leash_with_two_prismatic_pairs_is_refused_by_name():
    """The block of triad_rocking_block also sliding in a vertical guide of the frame (instead of
    rocking on the pin F): its two prismatic pairs only lock the base's angle to the frame's."""
    text = (ROOT / "models" / "triad_rocking_block.toml").read_text()
    moved = text.replace('kind = "R"\nlinks = [0, 5]\npoint = "F"',
                         'kind = "P"\nlinks = [0, 5]\nguide = "G"\ndirection = [0.0, 1.0]\npoint = "Q"') \
        .replace('F = [1.20, 0.30]\n\n[[link]]', 'G = [1.20, 0.30]\n\n[[link]]') \
        .replace('points = { F = [1.20, 0.30] }', 'points = { F = [1.20, 0.30], Q = [1.20, 0.30] }')
    with pytest.raises(kinetostat.StructureError, match=r"triad III\(2,3,4,5\): leash 5 joins the base 3 by the "
                                                        r"prismatic pair P\(3,5\) and link 0 by the prismatic pair "
                                                        r"P\(0,5\)"):
        kinetostat.loads(moved)


def test_pymunk_follows_a_guide_on_the_leash(mech):
    """pymunk's groove goes on the base or the known link where the guide is on a triad's leash
    (on the 3 kg block the simulation oscillated, 1.7e-2 of the peak reaction; with the frame as
    the slider no cycle closed): every quantity within pymunk's tolerance (measured 2.4e-7 and
    3.8e-7 of the peak reaction)."""
    from kinetostat_validation import compare as cmp
    if cmp.available("pymunk"):
        pytest.skip(cmp.available("pymunk"))
    c = cmp.compare(mech, engines=("pymunk",), steps=24)
    assert not c.failed and all(r.passed for r in c.rows)
    assert max(r.peak_relative for r in c.rows if r.quantity.startswith(("R(", "M_drive"))) <= 1e-5
