"""The engines' applied loads (validation/scene.py `loads_at_centres`): gravity taken out, each
link's wrench moved from its local origin to its centre of mass."""
from __future__ import annotations

import numpy as np

import kinetostat
from conftest import ROOT
from kinetostat.planar import cross, rotate
from kinetostat_validation.scene import build_scene


def test_loads_at_centres_are_the_applied_wrench_less_gravity_about_the_centre_of_mass():
    """About the local origin O the engine's force F at the centre S plus the weight W gives back
    the solver's applied wrench: F + W = F_applied, M + (S - O) x (F + W) = M_applied. The scotch
    yoke's slider carries a force off its centre of mass, so the moment's transfer is exercised."""
    scene = build_scene(kinetostat.load(ROOT / "models" / "scotch_yoke.toml"), phi_deg=[0, 50, 130, 250])
    F, M = scene.external()
    res, kin = scene.res, scene.res.kin
    arms = 0.0
    for b in scene.bodies:
        W = b.mass * np.array([0.0, -scene.g])
        O = kin.origin[:, b.link]
        S = O + rotate(b.com, kin.theta[:, b.link])
        np.testing.assert_allclose(F[:, b.link] + W, res.F_applied[:, b.link], rtol=1e-12, atol=1e-9)
        np.testing.assert_allclose(M[:, b.link] + cross(S - O, F[:, b.link] + W), res.M_applied[:, b.link],
                                   rtol=1e-12, atol=1e-9)
        arms = max(arms, float(np.abs(cross(S - O, F[:, b.link])).max()))
    assert arms > 1.0                     # N m: a moment moved, not only forces at their origins
