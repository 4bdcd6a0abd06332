"""MuJoCo and Pinocchio integrate the machine forward with a free crank, its flywheel and the drive's
moment (kinetostat_validation.motion): their omega(phi) against kinetostat's law of motion
(`kinetostat.law_of_motion`), their energy balance, and the convergence with the time step.

Independent source: the engines' own constrained forward dynamics (MuJoCo's mj_forward, Pinocchio's
constraintDynamics / KKT), integrated by RK4 from kinetostat's omega(phi_0); kinetostat's omega(phi)
comes from the energy equation with the reduced inertia and moments, no time integration at all.

Tolerances: the measured error at that step (ICE without friction, delta = 0.02, M_drive -16.015
N m, J_flywheel 0.0607 kg m^2), times about 3. A missing flywheel, a drive moment of the wrong sign
or a load left out shows up at 1e-3 .. 1e-1 of omega_mean.
"""
from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

import kinetostat
from kinetostat_validation.motion import ENGINES, convergence, forward, integrate, observed_order

pytestmark = pytest.mark.engines

ROOT = Path(__file__).resolve().parents[1]
#: The default runs: 60 steps per revolution over 2 cycles (about 2 s an engine).
QUICK = (60, 2)
#: Their max |omega_engine - omega_kinetostat| / omega_mean: measured mujoco 1.02e-6 (its soft
#: constraints), pinocchio 3.3e-7 (RK4 at 60 steps).
QUICK_ERROR = {"mujoco": 3e-6, "pinocchio": 1e-6}
#: Their energy balance, max |T + V - W - start| over the work's swing: measured 3.4e-5, 2.7e-5.
QUICK_ENERGY = 1e-4


def _ice():
    return replace(kinetostat.load(ROOT / "models" / "ice_crank_slider.toml"), friction=None)


@pytest.fixture(scope="module")
def ice():
    mech = _ice()
    return mech, kinetostat.law_of_motion(mech, delta=0.02)


@pytest.fixture(scope="module", params=ENGINES)
def quick_run(request, ice):
    pytest.importorskip(request.param)
    mech, motion = ice
    return forward(mech, motion, request.param, *QUICK)


def test_engine_follows_the_law_of_motion(quick_run, ice):
    """The engine's omega at kinetostat's angles of its last cycle is kinetostat's omega(phi)."""
    _, motion = ice
    assert quick_run.omega.shape == motion.omega.shape
    np.testing.assert_array_equal(quick_run.phi_deg, motion.phi_deg)
    assert quick_run.error < QUICK_ERROR[quick_run.engine], quick_run.trajectory.note
    # the run covers the cycles asked, from kinetostat's omega(phi_0); its last step aims at the
    # end by phi + omega h + eps h^2 / 2 (measured 2.7e-5 deg short at 60 steps per revolution)
    tr = quick_run.trajectory
    assert tr.omega[0] == pytest.approx(motion.omega[0], rel=1e-12)
    assert np.degrees(tr.phi[-1] - tr.phi[0]) == pytest.approx(360.0 * QUICK[1], abs=1e-4)


def test_engine_energy_balance_closes(quick_run):
    """T + V - W (W: the work of the drive and the loads) stays at its start value."""
    assert quick_run.trajectory.energy_error < QUICK_ENERGY


def test_engines_refuse_what_they_cannot_model(ice):
    """Friction (the engines model none), an unknown engine, too few steps: a ValueError naming it,
    before any engine is built."""
    mech, motion = ice
    rubbing = kinetostat.load(ROOT / "models" / "ice_crank_slider.toml")
    assert rubbing.friction is not None
    args = (motion.J_flywheel, float(motion.M_drive[0]), 0.0, float(motion.omega[0]), motion.omega_mean)
    with pytest.raises(ValueError, match="friction"):
        integrate(rubbing, *args)
    with pytest.raises(ValueError, match="engine"):
        integrate(mech, *args, engine="bullet")
    with pytest.raises(ValueError, match="steps_per_rev"):
        integrate(mech, *args, steps_per_rev=3)
    with pytest.raises(ValueError, match="omega0"):
        integrate(mech, motion.J_flywheel, float(motion.M_drive[0]), 0.0, 0.0, motion.omega_mean)


def test_observed_order():
    assert observed_order([1.6e-5, 1e-6, 6.25e-8], [90, 180, 360]) == [None, pytest.approx(4.0), pytest.approx(4.0)]
    assert observed_order([1e-6, 0.0], [90, 180]) == [None, None]


# ----------------------------------------------------------------------------- convergence (slow)

#: ICE, 3 cycles at 90, 180, 360 steps per revolution: Pinocchio measured 8.5e-8, 5.7e-9, 3.6e-10
#: (order 3.90, 3.99: RK4's 4); MuJoCo 6.9e-7, 2.1e-7, 6.7e-8 (order 1.75, 1.61: its soft
#: equality constraints, impedance 0.9999 and a time constant of 4 steps, dominate RK4's error).
ORDER = {"pinocchio": (3.5, 4.5), "mujoco": (1.3, 2.2)}
FINEST_ERROR = {"pinocchio": 1e-9, "mujoco": 2e-7}
#: The energy balance shrinks with the step: Pinocchio 7.0e-6, 4.5e-7, 2.9e-8; MuJoCo 3.4e-5,
#: 8.0e-6, 2.8e-6.
FINEST_ENERGY = {"pinocchio": 1e-7, "mujoco": 1e-5}


@pytest.mark.slow
def test_agreement_converges_at_the_integrators_order(ice):
    mech, motion = ice
    engines = tuple(e for e in ENGINES if pytest.importorskip(e))
    rows = convergence(mech, motion, engines, (90, 180, 360), cycles=3)
    for engine in engines:
        mine = [r for r in rows if r.engine == engine]
        assert [r.steps_per_rev for r in mine] == [90, 180, 360]
        lo, hi = ORDER[engine]
        assert all(lo < r.order < hi for r in mine[1:]), [(r.steps_per_rev, r.error, r.order) for r in mine]
        assert mine[-1].error < FINEST_ERROR[engine]
        energy = [r.energy_error for r in mine]
        assert energy == sorted(energy, reverse=True) and energy[-1] < FINEST_ENERGY[engine], energy


#: The shaper (delta = 0.02, J_flywheel 451 kg m^2; its cutting force a table in the ram's travel,
#: whose kinks the steps land on), 3 cycles at 90 and 180 steps per revolution: Pinocchio (KKT
#: with Baumgarte terms: two slots) measured 8.6e-8, 5.4e-9 (order 3.98); MuJoCo 1.29e-5, 2.9e-6
#: (order 2.14); energy 2.0e-6, 1.3e-7 and 1.8e-5, 3.3e-6.
SHAPER_ORDER = {"pinocchio": (3.5, 4.5), "mujoco": (1.6, 2.6)}
SHAPER_ERROR = {"pinocchio": 2e-8, "mujoco": 8e-6}
SHAPER_ENERGY = {"pinocchio": 1e-6, "mujoco": 1e-5}


@pytest.mark.slow
@pytest.mark.parametrize("engine", ENGINES)
def test_shaper_converges_to_the_law_of_motion(engine):
    pytest.importorskip(engine)
    mech = replace(kinetostat.load(ROOT / "models" / "slotted_link_shaper.toml"), friction=None)
    coarse, fine = convergence(mech, kinetostat.law_of_motion(mech, delta=0.02), (engine,), (90, 180), cycles=3)
    lo, hi = SHAPER_ORDER[engine]
    assert lo < fine.order < hi and fine.error < SHAPER_ERROR[engine], (coarse, fine)
    assert fine.energy_error < coarse.energy_error and fine.energy_error < SHAPER_ENERGY[engine]


def test_runs_step_together_with_one_load_pass_a_stage(ice, monkeypatch):
    """`forwards` drives its runs in lockstep: each stage's loads of both engines come from one
    `_loads` call of two angles, and each run's omega is what it gives alone."""
    import kinetostat_validation.motion as motion_module
    pytest.importorskip("mujoco")
    pytest.importorskip("pinocchio")
    mech, motion = ice
    alone = [forward(mech, motion, e, 12, 1) for e in ENGINES]
    sizes = []
    loads = motion_module._loads
    monkeypatch.setattr(motion_module, "_loads", lambda m, s, phi, w: (sizes.append(len(phi)), loads(m, s, phi, w))[1])
    together = motion_module.forwards(mech, motion, tuple((e, 12) for e in ENGINES), 1)
    assert sizes and set(sizes) <= {1, 2} and sizes.count(2) >= 4 * 12
    assert len(sizes) < sum(4 * len(r.trajectory.t) for r in alone)
    for a, b in zip(alone, together):
        np.testing.assert_allclose(b.omega, a.omega, rtol=1e-12)


def test_loads_at_unit_speed_scaled_are_the_loads_at_that_speed():
    """`_loads` at several angles, each at its own speed, against the load model run on the
    mechanism driven at that speed, one angle at a time."""
    from kinetostat.applied import applied_wrenches, com_motion
    from kinetostat.kinematics import kinematics
    from kinetostat.planar import as_xy
    from kinetostat_validation.motion import _loads
    from kinetostat_validation.scene import build_scene, loads_at_centres
    mech = replace(kinetostat.load(ROOT / "models" / "slotted_link_shaper.toml"), friction=None)
    scene = build_scene(mech, phi_deg=[0.0])
    phi, w = np.radians([10.0, 95.0, 250.0]), np.array([0.5, 3.0, 12.0]) * mech.drive.omega
    F, M = _loads(mech, scene, phi, w)
    for i in range(3):
        at = replace(mech, drive=replace(mech.drive, omega=float(w[i]), eps=0.0, law=None))
        kin = kinematics(at, phi[i:i + 1])
        Fa, Ma = applied_wrenches(at, kin, com_motion(at, kin)[0])
        Fi, Mi = loads_at_centres(scene.bodies, scene.g, kin, as_xy(Fa), Ma)
        scale = np.abs(Fi).max()
        np.testing.assert_allclose(F[i], Fi[0], rtol=0, atol=1e-12 * scale)
        np.testing.assert_allclose(M[i], Mi[0], rtol=0, atol=1e-12 * np.abs(Mi).max())
