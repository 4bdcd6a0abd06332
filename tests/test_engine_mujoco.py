"""MuJoCo adapter (validation/engine_mujoco.py) against kinetostat's exact solver.

Error measure, per quantity over a full cycle: max |engine - solver| / max |solver| (the
driving moment; each pair's reaction as a vector), the denominator guarded by ZERO_PEAK.
"""
from __future__ import annotations

import functools
import math
import re
from pathlib import Path

import numpy as np
import pytest

mujoco = pytest.importorskip("mujoco")

import kinetostat  # noqa: E402
from conftest import EVERY_GROUP, four_bar  # noqa: E402
from kinetostat_validation.engine_mujoco import mjcf, simulate, solve  # noqa: E402
from kinetostat_validation.scene import build_scene  # noqa: E402

MODELS_DIR = Path(__file__).resolve().parent.parent / "models"
MODEL_FILES = sorted(MODELS_DIR.glob("*.toml"))

#: Exact route: MuJoCo evaluates the same Newton-Euler equations at the same state in another
#: order (spatial algebra, subtree-CoM frames); measured 1e-16 .. 1e-14 (5e-12 where a pin
#: force is the small difference of two large ones). 1e-9 leaves room for ill-conditioned
#: positions without hiding a real discrepancy (a wrong sign or term is >= 1e-3).
EXACT_TOL = 1e-9
#: Simulation route at the default 7200 steps per revolution: measured 2e-7 .. 1.7e-4 of the
#: peaks (worst: this file's four-bar, M_drive near 339 deg; 1.4e-4 where a load against the
#: velocity flips at a dead centre right at a sample). The error is first order in the step
#: (halving the step halves it), so this bound is ~3x the worst case at 7200 steps/rev.
SIM_TOL = 5e-4
#: A pair whose peak reaction is below this fraction of the mechanism's largest reaction is
#: compared relative to that largest reaction (rounding, not the pair, sets its error).
ZERO_PEAK = 1e-6
#: Convergence check: error(3600 steps) / error(7200 steps) of a first-order method is 2.
ORDER_RATIO = (1.5, 3.0)
#: MuJoCo's body poses at the exact joint coordinates against kinetostat's (m, rad).
POSE_TOL = 1e-12
#: Floors of massless bodies in the simulation route (1e-7 vs 1e-9 of the scales): they must
#: change the results by far less than SIM_TOL.
FLOOR_EFFECT_TOL = 1e-6

FOUR_BAR = four_bar(
    ("C = [0.3, 0.0]", "C = [0.3, 0.0]\nE = [0.1, 0.3]"),
    ("S2 = [0.15, 0.02] }", "S2 = [0.15, 0.02], D = [0.25, 0.05] }"),
    append="""
[[load]]
name = "resisting moment on the rocker"
kind = "moment"
link = 3
direction = "against_omega"
value = 4.0

[[load]]
name = "constant force on the coupler"
link = 2
point = "D"
direction = [0.0, -1.0]
value = 30.0

[[spring]]
name = "spring frame-coupler"
a = { link = 0, point = "E" }
b = { link = 2, point = "D" }
stiffness = 500.0
free_length = 0.1
""")


def _massless_blocks_shaper() -> str:
    """The shaper with blocks 2 and 4 massless (the text's own assumption): massless leaves
    of the spanning tree, one of them on a cut prismatic pair."""
    text = (MODELS_DIR / "slotted_link_shaper.toml").read_text(encoding="utf-8")
    text, n = re.subn(r"mass = 0\.8\nI_S = 5\.9333e-4", "mass = 0.0\nI_S = 0.0", text)
    assert n == 2
    return text


INLINE = {"four_bar (test)": lambda: FOUR_BAR,
          "shaper, massless blocks (test)": _massless_blocks_shaper}


@functools.lru_cache(maxsize=None)
def scene_of(name: str):
    """The 360-angle scene of a model file name or an INLINE key; skips what does not load
    (model files may be in the making)."""
    try:
        if name in INLINE:
            mech = kinetostat.loads(INLINE[name](), source=name)
        else:
            mech = kinetostat.load(MODELS_DIR / name)
        return build_scene(mech, steps=360)
    except Exception as exc:      # a model file being written: not this adapter's business
        return exc


def get_scene(name: str):
    sc = scene_of(name)
    if isinstance(sc, Exception):
        pytest.skip(f"{name} does not load: {type(sc).__name__}: {sc}")
    return sc


@functools.lru_cache(maxsize=None)
def exact_of(name: str):
    return solve(get_scene(name))


@functools.lru_cache(maxsize=None)
def simulated(name: str, steps_per_rev: int = 7200, floor: float | None = None):
    kw = {} if floor is None else {"floor": floor}
    return simulate(get_scene(name), steps_per_rev=steps_per_rev, **kw)


def errors(scene, result) -> dict[str, float]:
    """Peak-relative error of M_drive and of every pair's reaction over the cycle."""
    ok = ~scene.res.singular
    assert np.array_equal(np.isnan(result.M_drive), ~ok), "NaN exactly at the solver's singular angles"
    ref_M, M = scene.M_drive[ok], result.M_drive[ok]
    out = {"M_drive": float(np.max(np.abs(M - ref_M)) / max(np.max(np.abs(ref_M)), 1e-300))}
    R_ref, R = scene.res.forces.R[ok], result.R[ok]
    big = float(np.max(np.linalg.norm(R_ref, axis=-1)))
    for p in scene.mech.pairs:
        peak = float(np.max(np.linalg.norm(R_ref[:, p.index], axis=-1)))
        dev = float(np.max(np.linalg.norm(R[:, p.index] - R_ref[:, p.index], axis=-1)))
        out[p.label] = dev / max(peak, ZERO_PEAK * big)
    return out


#: Every bundled model and the scenes written here: those of EVERY_GROUP and the scenes by
#: default, every bundled model with -m slow.
ALL = [pytest.param(f.name, marks=() if f.stem in EVERY_GROUP else pytest.mark.slow)
       for f in MODEL_FILES] + list(INLINE)
SIMULATED = ALL          # ~0.15 s per model and cycle


# ----------------------------------------------------------------------------- MJCF

@pytest.mark.parametrize("name", ALL)
def test_mjcf_reference_pose_matches_the_scene(name):
    """Bodies placed by MuJoCo at the scene's joint coordinates are where kinetostat has
    them: the MJCF's qpos = 0 is the scene's q = 0 and the joint definitions agree."""
    sc = get_scene(name)
    m = mujoco.MjModel.from_xml_string(mjcf(sc))
    d = mujoco.MjData(m)
    assert m.ngeom == 0 and m.opt.disableflags & mujoco.mjtDisableBit.mjDSBL_CONTACT
    assert m.neq == len(sc.cuts)
    assert list(m.eq_type) == [mujoco.mjtEq.mjEQ_CONNECT if p.kind == "R" else mujoco.mjtEq.mjEQ_WELD
                                for p in sc.cuts]
    kin = sc.res.kin
    for i in (0, 77, 181, 299):
        d.qpos[:] = 0.0
        for n, j in enumerate(sc.joints):
            d.qpos[m.jnt_qposadr[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, f"pair{j.pair.index}")]] = sc.q[i, n]
        mujoco.mj_kinematics(m, d)
        for b in sc.bodies:
            k = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, f"link{b.link}")
            assert np.allclose(d.xpos[k, :2], kin.origin[i, b.link], rtol=0, atol=POSE_TOL)
            angle = 2 * math.atan2(d.xquat[k, 3], d.xquat[k, 0])
            assert abs(math.remainder(angle - kin.theta[i, b.link], 2 * math.pi)) < POSE_TOL


# ----------------------------------------------------------------------------- exact route

@pytest.mark.parametrize("name", ALL)
def test_exact_route_matches_solver(name):
    sc = get_scene(name)
    res = exact_of(name)
    assert res.engine == "mujoco" and res.route == "exact"
    np.testing.assert_array_equal(res.phi_deg, sc.phi_deg)
    err = errors(sc, res)
    bad = {k: v for k, v in err.items() if not v < EXACT_TOL}
    assert not bad, f"{name}: peak-relative errors above {EXACT_TOL}: {bad}"


@pytest.mark.parametrize("name", ["ice_crank_slider.toml", "opposed_twin.toml", "shaper, massless blocks (test)"])
def test_exact_route_placeholder_masses_do_not_matter(name):
    """MuJoCo needs positive masses in the MJCF; the exact route writes the exact zeros back.
    Keeping the placeholders (1e-12 of the scales) instead changes nothing beyond EXACT_TOL."""
    sc = get_scene(name)
    if not any(b.mass == 0 or b.I_S == 0 for b in sc.bodies):
        pytest.skip(f"{name} has no massless link any more")
    kept = solve(sc, keep_floors=True)
    exact = exact_of(name)
    assert max(errors(sc, kept).values()) < EXACT_TOL
    assert np.nanmax(np.abs(kept.M_drive - exact.M_drive)) <= EXACT_TOL * np.nanmax(np.abs(exact.M_drive))


def test_exact_route_massless_blocks_change_the_answer():
    """The massless-blocks shaper is a different mechanism, not the same one: guards against
    a test that would pass because masses are ignored."""
    a, b = get_scene("slotted_link_shaper.toml"), get_scene("shaper, massless blocks (test)")
    assert np.max(np.abs(a.M_drive - b.M_drive)) > 1e-3 * np.max(np.abs(a.M_drive))


# ----------------------------------------------------------------------------- simulation route

@pytest.mark.parametrize("name", SIMULATED)
def test_simulation_route_matches_solver(name):
    sc = get_scene(name)
    if sc.mech.drive.eps != 0.0:
        pytest.skip(f"{name}: accelerating crank, no single motion to simulate (see simulate)")
    res = simulated(name)
    assert res.route == "simulation"
    err = errors(sc, res)
    bad = {k: v for k, v in err.items() if not v < SIM_TOL}
    assert not bad, f"{name}: peak-relative errors above {SIM_TOL}: {bad}"


def test_simulation_error_is_first_order_in_the_step():
    """Halving the step halves the error: the discrepancy is the integrator's, not a model's."""
    name = "four_bar (test)"
    sc = get_scene(name)
    coarse = max(errors(sc, simulated(name, 3600)).values())
    fine = max(errors(sc, simulated(name, 7200)).values())
    assert ORDER_RATIO[0] < coarse / fine < ORDER_RATIO[1], (coarse, fine)


@pytest.mark.parametrize("name", ["ice_crank_slider.toml", "shaper, massless blocks (test)"])
def test_simulation_floor_masses_do_not_matter(name):
    """Massless links (the ICE's crank; the shaper's blocks, leaves on a slot) carry a floor
    mass in the simulation route: 1e-7 or 1e-9 of the scales changes nothing that matters
    (measured 5e-10 and 5e-8 of the peaks)."""
    sc = get_scene(name)
    a, b = simulated(name), simulated(name, 7200, 1e-9)
    scale = np.max(np.abs(sc.res.forces.R))
    assert np.max(np.abs(a.R - b.R)) < FLOOR_EFFECT_TOL * scale
    assert np.max(np.abs(a.M_drive - b.M_drive)) < FLOOR_EFFECT_TOL * np.max(np.abs(sc.M_drive))


@pytest.mark.parametrize("model", ["ice_crank_slider", "slotted_link_shaper"])
def test_rollout_route_within_its_tolerance_at_half_the_steps(model):
    """The rollout route (mujoco.rollout, crank tied to the clock) at 3600 steps/rev, every
    quantity the gate compares (forces, F_bal, friction losses, point kinematics): within the
    route's tolerance scaled by the step (first order: 2x at half the steps)."""
    from kinetostat_validation.compare import TOLERANCES, errors as gate_errors, quantity_names
    mech = kinetostat.load(MODELS_DIR / f"{model}.toml")
    sc = build_scene(mech, steps=72)
    res = simulate(sc, steps_per_rev=3600)
    assert "mujoco.rollout" in res.note
    rows = gate_errors(sc.res, res, 2 * TOLERANCES["mujoco-sim"].peak_relative, "mujoco-sim")
    assert [r.quantity for r in rows] == quantity_names(mech, "mujoco-sim")
    bad = {r.quantity: r.peak_relative for r in rows if not (r.passed and r.n_compared == 72)}
    assert not bad


def test_simulation_refuses_an_accelerating_crank():
    mech = kinetostat.loads(FOUR_BAR.replace("eps = 0.0", "eps = 10.0"))
    with pytest.raises(ValueError, match=r"constant speed \(drive.eps = 0\)"):
        simulate(build_scene(mech, steps=12))


def test_routes_report_their_timing_and_note():
    for res in (exact_of("four_bar (test)"), simulated("four_bar (test)")):
        assert res.build_seconds > 0 and res.run_seconds > 0
        assert "MuJoCo" in res.note
