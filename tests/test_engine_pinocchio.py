"""Pinocchio adapter of the cross-validation harness: constrained inverse dynamics at the
solver's exact states must give the solver's driving moment and every pair's reaction, and
Pinocchio's constrained forward dynamics driven by that moment must give back the prescribed
crank acceleration."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

pin = pytest.importorskip("pinocchio")

import kinetostat  # noqa: E402
from conftest import EVERY_GROUP, four_bar, sampled  # noqa: E402
from kinetostat_validation.engine_pinocchio import PinocchioScene, forward_round_trip, solve  # noqa: E402
from kinetostat_validation.scene import build_scene  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
MODELS = sorted((ROOT / "models").glob("*.toml"))
STEPS = 360

#: Driving moment and reactions, peak-relative (max over the cycle of |engine - solver| over
#: the max of |solver|). Both sides are exact linear solves at the same exact state, so only
#: rounding separates them: measured 2e-16 .. 1e-14, and 2e-12 for a bearing whose small load
#: is the difference of large opposed forces (opposed twin, R(0,1)). Near (not at) a singular
#: position the group plans lose up to DIGITS_WARN = 10 digits (then warned). A modelling error
#: (wrong frame, sign, stale constraint Jacobian) shows up at 1e-3 .. 1e0.
EXACT = 1e-9
#: Crank acceleration of the forward round trip, relative to the cycle's acceleration scale
#: (max |qdd| of the joints, omega_crank^2): a KKT / proximal solve at the exact state, measured
#: 1e-15 .. 1e-13; a wrong drift term (J-dot v) shows up at 1e-2 .. 1e0.
FORWARD = 1e-10

# A four-bar written only here (nothing in the engine may be model-specific): crank 0.1 m,
# coupler 0.35 m, rocker 0.3 m, frame points O = (0, 0), C = (0.3, 0); off-axis centres of
# mass, crank accelerating, clockwise, a force, a moment and a spring as applied loads.
FOUR_BAR = four_bar(
    ("reference = [1.0, 0.0]", "reference = [0.0, 1.0]"), ('sense = "ccw"', 'sense = "cw"'),
    ("rpm = 300.0", "rpm = 240.0"), ("eps = 0.0", "eps = 15.0"),
    ("C = [0.3, 0.0]", "C = [0.3, 0.0]\nE = [0.45, 0.25]"),
    ("S3 = [0.12, -0.01] }", "S3 = [0.12, -0.01], F = [0.2, 0.0] }"),
    append="""
[[load]]
name = "tool force"
link = 2
point = "B"
direction = [0.6, -0.8]
value = 25.0

[[spring]]
name = "return spring"
a = { link = 0, point = "E" }
b = { link = 3, point = "F" }
stiffness = 400.0
free_length = 0.15
""")


def _peak_relative(engine: np.ndarray, exact: np.ndarray, fallback: float) -> float:
    """max |engine - exact| / max |exact| over the cycle (NaN angles: singular, skipped);
    `fallback` scale where the exact peak is zero (an unloaded pair)."""
    ok = np.isfinite(exact).all(axis=tuple(range(1, exact.ndim)))
    assert np.isfinite(engine[ok]).all(), "engine returned NaN where the solver has a value"
    if not ok.any():
        return 0.0
    peak = np.max(np.abs(exact[ok]))
    return float(np.max(np.abs(engine[ok] - exact[ok])) / (peak if peak > 0 else fallback))


def _check(scene) -> dict[str, float]:
    result = solve(scene)
    assert result.engine == "pinocchio" and result.route == "exact"
    n_pairs = len(scene.mech.pairs)
    assert result.M_drive.shape == scene.M_drive.shape
    assert result.R.shape == (len(scene.phi_deg), n_pairs, 2)
    np.testing.assert_array_equal(result.phi_deg, scene.phi_deg)
    force_scale = max(np.nanmax(np.abs(scene.res.forces.R)), 1e-300)
    errors = {"M_drive": _peak_relative(result.M_drive, scene.M_drive, 1.0)}
    for pair in scene.mech.pairs:
        errors[pair.label] = _peak_relative(result.R[:, pair.index], scene.reaction(pair), force_scale)
    bad = {k: v for k, v in errors.items() if not v < EXACT}
    assert not bad, f"{scene.mech.name}: peak-relative errors above {EXACT}: {bad}"
    return errors


def _forward(scene, method: str) -> float:
    err = forward_round_trip(scene, scene.M_drive, method=method)
    ok = np.isfinite(scene.qdd).all(axis=1)
    assert np.isfinite(err[ok]).all()
    scale = max(np.nanmax(np.abs(scene.qdd)), np.nanmax(scene.qd[:, scene.crank_joint] ** 2))
    rel = float(np.max(np.abs(err[ok])) / scale) if ok.any() else 0.0
    assert rel < FORWARD, f"{scene.mech.name}: forward round trip ({method}) off by {rel:.1e} of the scale"
    return rel


@pytest.fixture(scope="module", params=sampled(MODELS, EVERY_GROUP))     # every model with -m slow
def scene(request):
    try:
        mech = kinetostat.load(request.param)
    except kinetostat.ModelError as exc:           # a model still being written by someone else
        if request.param.stem == "ice_crank_slider":
            raise
        pytest.skip(f"{request.param.name} does not load: {exc}")
    return build_scene(mech, steps=STEPS)


def test_reference_model_present():
    assert (ROOT / "models" / "ice_crank_slider.toml") in MODELS


def test_inverse_dynamics_matches_solver(scene):
    _check(scene)


def test_forward_round_trip(scene):
    _forward(scene, "kkt")
    if all(p.kind == "R" for p in scene.cuts):     # Pinocchio's own algorithm where it applies
        _forward(scene, "constraintDynamics")


def test_four_bar_written_here():
    mech = kinetostat.loads(FOUR_BAR)
    scene = build_scene(mech, steps=STEPS)
    assert scene.mech.drive.eps != 0 and np.any(scene.res.F_applied != 0)
    _check(scene)
    _forward(scene, "kkt")
    _forward(scene, "constraintDynamics")


def test_four_bar_other_tree_and_reversed_pair():
    """The same four-bar with the rocker's frame pair listed first and as (3, 0): the scene's
    breadth-first tree then reaches the coupler through the rocker and cuts R(1,2) instead of
    R(2,3), and a tree joint's pair runs child -> parent. The reactions must not care."""
    block = '[[pair]]\nkind = "R"\nlinks = [0, 3]\npoint = "C"\n'
    assert block in FOUR_BAR
    text = FOUR_BAR.replace(block, "").replace(
        "[[pair]]", block.replace("[0, 3]", "[3, 0]") + "\n[[pair]]", 1)
    scene = build_scene(kinetostat.loads(text), steps=72)
    assert [p.links for p in scene.cuts] == [(1, 2)]
    assert any(j.pair.links == (3, 0) and j.parent == 0 for j in scene.joints)
    _check(scene)
    _forward(scene, "constraintDynamics")


def test_mass_matrix_is_pinocchios_crba_with_depth_first_joints():
    """Pinocchio's crba treats each subtree as one contiguous block of velocity indices: the
    joints must be added depth first (the scene lists them breadth first). The mass matrix
    from crba must equal the one from rnea's columns."""
    scene = build_scene(kinetostat.load(ROOT / "models" / "ice_crank_slider.toml"), phi_deg=[30.0, 200.0])
    ps = PinocchioScene(scene)
    assert sum(j.parent == 0 for j in scene.joints) >= 2    # the frame has two children here
    for n in range(2):
        q, v, a = ps.state(n)
        M = pin.crba(ps.model, ps.data, q).copy()
        M = np.triu(M) + np.triu(M, 1).T
        b = pin.rnea(ps.model, ps.data, q, v, np.zeros_like(a)).copy()
        cols = np.column_stack([pin.rnea(ps.model, ps.data, q, v, e).copy() - b for e in np.eye(ps.nv)])
        np.testing.assert_allclose(M, cols, rtol=0, atol=1e-12 * np.max(np.abs(cols)))


def test_build_and_run_time_recorded():
    scene = build_scene(kinetostat.load(ROOT / "models" / "ice_crank_slider.toml"), steps=36)
    result = solve(scene)
    assert result.build_seconds > 0 and result.run_seconds > 0
    assert "pin" in result.note
