"""The pymunk adapter (validation/engine_pymunk.py) against the exact solver, over full cycles.

pymunk's impulses are magnitudes, so |M_drive| and |R| of every pair are compared. The error
of one quantity is peak-relative: max over the cycle of ||engine| - |solver|| divided by max
over the cycle of |solver|. Scenes have 72 angles (every 5 deg).

Measured before the tolerances were set (peak-relative, worst quantity of each model):

| model                  | 1440 steps | 2880 steps | Richardson | iterations used |
|------------------------|-----------:|-----------:|-----------:|----------------:|
| chain_unit_four_bar    | 2.7e-5     | 6.7e-6     | 6.6e-8     | 50              |
| compressor (machine)   | 2.2e-5     | 5.4e-6     | 2.2e-8     | 50              |
| furnace_loader_six_bar | 8.6e-5     | 6.8e-4     | 8.6e-5     | 200 (100 at 2880) |
| ice_crank_slider       | 4.7e-5     | 1.2e-5     | 8.2e-8     | 50              |
| opposed_twin           | 6.6e-5     | 1.7e-5     | 1.1e-7     | 50              |
| rotating_slotted_link  | 2.2e-3     | 9.6e-4     | 5.5e-4     | 200             |
| scotch_yoke            | 1.7e-3     | 1.7e-3     | 1.7e-3     | 50              |
| slotted_link_shaper    | 2.4e-3     | 7.6e-4     | 1.8e-3     | 400             |
| four-bar of this file  | 1.2e-4     | 3.1e-5     | 1.2e-6     | 50              |

Light linkages converge as dt^2 and Richardson gains two to three digits. The heavy/light
machines (25-30 kg rams and sliders behind 0.8 kg blocks) are limited by the impulse solver's
iterations, not by the step. The scotch yoke's error sits at one angle: its pumping resistance
(against the velocity) flips sign at 0 deg, and 50 iterations do not absorb the jump in one step.
"""
from __future__ import annotations

import functools
import warnings
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("pymunk")

import kinetostat  # noqa: E402
from conftest import FOUR_BAR as LIGHT_FOUR_BAR, four_bar, sampled  # noqa: E402
from kinetostat_validation.compare import errors as gate_errors  # noqa: E402
from kinetostat_validation.engine_pymunk import simulate  # noqa: E402
from kinetostat_validation.scene import build_scene  # noqa: E402

MODELS = sorted((Path(__file__).resolve().parent.parent / "models").glob("*.toml"))

#: Every model at the default 1440 steps (iterations 50, doubled by the adapter while a run is
#: unstable): worst measured 2.4e-3 (slotted-link shaper, iteration-limited at 400 iterations);
#: 2x margin.
TOL_1440 = 5e-3
#: Every model with Richardson over 1440 and 2880 steps: the iteration-limited machines do not
#: improve (worst measured 1.8e-3, shaper), so the same bound as at 1440.
TOL_RICHARDSON = 5e-3
#: Light linkages whose impulse solver converges at 50 iterations (ICE crank-slider, the
#: four-bar of this file), 1440 steps: measured 4.7e-5 and 1.2e-4, an O(dt^2) step error.
TOL_CONVERGED_1440 = 5e-4
#: The same with Richardson (order 2): measured 8.2e-8 and 1.2e-6.
TOL_CONVERGED_RICHARDSON = 1e-5
#: Error ratio between 1440 and 2880 steps for an O(dt^2) method: 4 (measured 3.9-4.0).
ORDER_RATIO = (3.0, 5.0)

FOUR_BAR = four_bar(append="""
[[load]]
name = "weight hung at B"
link = 2
point = "B"
direction = [0.0, -1.0]
value = 50.0
""")


@functools.lru_cache(maxsize=None)
def _scene(key: str):
    """Scene of a model file (path) or of FOUR_BAR with replacements ('four-bar|old|new|...')."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        if key.startswith("four-bar"):
            text = FOUR_BAR
            parts = key.split("|")[1:]
            for old, new in zip(parts[::2], parts[1::2]):
                text = text.replace(old, new)
            mech = kinetostat.loads(text)
        else:
            mech = kinetostat.load(key)
        return build_scene(mech, steps=72)


def _model_scene(path: Path):
    try:
        return _scene(str(path))
    except Exception as exc:          # models are still being written: those that do not load
        pytest.skip(f"{path.name} does not load: {type(exc).__name__}: {exc}")


@functools.lru_cache(maxsize=None)
def _run(key: str, steps: int = 1440, richardson: bool = False):
    return simulate(_scene(key), steps, richardson=richardson)


def peak_errors(scene, res) -> dict[str, float]:
    """Peak-relative error of |M_drive| and of |R| of every pair (NaN angles left out)."""
    out = {}
    pairs = [("M_drive", np.abs(res.M_drive), np.abs(scene.M_drive))]
    pairs += [(p.label, np.linalg.norm(res.R[:, p.index], axis=-1),
               np.linalg.norm(scene.reaction(p), axis=-1)) for p in scene.mech.pairs]
    scale = max(np.nanmax(ref) for _, _, ref in pairs[1:])
    for name, eng, ref in pairs:
        peak = max(np.nanmax(ref), 1e-12 * scale)
        out[name] = float(np.nanmax(np.abs(eng - ref)) / peak)
    return out


def _fmt(err: dict[str, float]) -> str:
    return ", ".join(f"{k} {v:.1e}" for k, v in err.items())


#: The default sample of the two tests below, split between them: every group kind by the route at
#: 1440 steps or by its Richardson extrapolation (all four of EVERY_KIND by both with -m slow).
AT_1440, RICHARDSON = ("scotch_yoke", "slotted_link_shaper"), ("chain_unit_four_bar", "ice_crank_slider")


@pytest.mark.parametrize("path", sampled(MODELS, AT_1440))
def test_every_model_at_1440_steps(path):
    scene = _model_scene(path)
    res = _run(str(path))
    assert not np.isnan(res.M_drive).any() and not np.isnan(res.R).any(), res.note
    err = peak_errors(scene, res)
    assert max(err.values()) < TOL_1440, f"{_fmt(err)}; {res.note}"


@pytest.mark.parametrize("path", sampled(MODELS, RICHARDSON))
def test_every_model_with_richardson(path):
    scene = _model_scene(path)
    res = _run(str(path), richardson=True)
    assert not np.isnan(res.M_drive).any() and not np.isnan(res.R).any(), res.note
    err = peak_errors(scene, res)
    assert max(err.values()) < TOL_RICHARDSON, f"{_fmt(err)}; {res.note}"


@pytest.mark.parametrize("key", ["four-bar", "ice"])
def test_converged_linkages_are_second_order_and_richardson_gains(key):
    if key == "ice":
        path = Path(__file__).resolve().parent.parent / "models" / "ice_crank_slider.toml"
        _model_scene(path)
        key = str(path)
    scene = _scene(key)
    e1 = max(peak_errors(scene, _run(key, 1440)).values())
    e2 = max(peak_errors(scene, _run(key, 2880)).values())
    er = max(peak_errors(scene, _run(key, 1440, True)).values())
    assert e1 < TOL_CONVERGED_1440
    assert ORDER_RATIO[0] < e1 / e2 < ORDER_RATIO[1], (e1, e2)
    assert er < TOL_CONVERGED_RICHARDSON, (e1, e2, er)


def test_richardson_of_the_route_beats_both_of_its_runs():
    """The route's default, Richardson over 720 and 1440 steps, on the light four-bar: its worst
    error over every compared quantity (|M_drive|, |R|, point positions and velocities) is below
    that of each of its two single runs (measured 4.4e-4 at 720, 1.1e-4 at 1440, 3.9e-6)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        scene = build_scene(kinetostat.loads(LIGHT_FOUR_BAR), steps=72)

    def worst(res):
        rows = gate_errors(scene.res, res, 1.0, "pymunk")
        assert all(r.n_compared == 72 for r in rows)
        return max(r.peak_relative for r in rows)

    e720 = worst(simulate(scene, 720, richardson=False))
    e1440 = worst(simulate(scene, 1440, richardson=False))
    e_r = worst(simulate(scene))
    assert e_r < min(e720, e1440) / 10, (e720, e1440, e_r)


def test_result_is_magnitudes_with_the_scene_angles():
    scene = _scene("four-bar")
    res = _run("four-bar")
    N, n_pairs = len(scene.phi_deg), len(scene.mech.pairs)
    assert (res.engine, res.route, res.magnitudes_only) == ("pymunk", "simulation", True)
    np.testing.assert_array_equal(res.phi_deg, scene.phi_deg)
    assert res.M_drive.shape == (N,) and res.R.shape == (N, n_pairs, 2)
    assert np.all(res.R[..., 1] == 0) and np.all(res.R[..., 0] >= 0)
    assert res.build_seconds > 0 and res.run_seconds > 0
    assert "1440 steps/rev" in res.note and "magnitudes" in res.note


def test_driving_moment_is_signed():
    scene = _scene("four-bar")
    res = _run("four-bar")
    assert np.max(np.abs(res.M_drive - scene.M_drive)) / np.max(np.abs(scene.M_drive)) < TOL_CONVERGED_1440


def test_massless_crank_gets_a_cancelled_surrogate():
    path = Path(__file__).resolve().parent.parent / "models" / "ice_crank_slider.toml"
    scene = _model_scene(path)
    assert scene.bodies[scene.body_of(1)].mass == 0
    assert "link 1 massless" in _run(str(path)).note


def test_near_singular_position_gives_nan_and_names_the_angles():
    # ground 0.155 instead of 0.3: crank + coupler = ground + rocker + 0.005, nearly a
    # change-point linkage, folded at phi = 0 (condition number ~29 there). pymunk leaves the
    # exact motion right after passing it, even at 400 iterations.
    key = "four-bar|C = [0.3, 0.0]|C = [0.155, 0.0]"
    scene = _scene(key)
    res = _run(key)
    nan = np.isnan(res.M_drive)
    assert nan.any(), res.note
    assert "left the exact ones" in res.note or "oscillate" in res.note
    assert "values within" in res.note and "are NaN" in res.note
    phi = scene.phi_deg[nan] % 360.0
    assert np.all(np.minimum(phi, 360.0 - phi) <= 20.0), phi          # only next to phi = 0
    err = peak_errors(scene, res)
    assert max(err.values()) < TOL_1440, _fmt(err)                  # elsewhere as accurate


def test_angular_acceleration_of_the_crank_is_refused_as_nan():
    key = "four-bar|eps = 0.0|eps = 1.0"
    res = simulate(_scene(key), 1440)
    assert np.isnan(res.M_drive).all() and np.isnan(res.R).all()
    assert "drive.eps != 0" in res.note


def test_too_few_steps_is_an_error():
    with pytest.raises(ValueError, match=r"steps_per_rev: expected an integer >= 36, got 10"):
        simulate(_scene("four-bar"), 10)


def test_exact_poses_at_many_grid_indices_are_each_index_own():
    """`_Prep.pose` at an index array (a machine's mesh arms over every step) gives, row by row,
    the pose at each index alone: centre of mass (m) and angle (rad)."""
    from kinetostat_validation.engine_pymunk import _Prep
    prep = _Prep(_scene(str(MODELS[[p.stem for p in MODELS].index("compressor")])), 72)
    idx = np.arange(0, 2 * prep.steps, 5)
    for k in prep.links:
        S, th = prep.pose(k, idx)
        assert S.shape == (len(idx), 2) and th.shape == (len(idx),)
        for n, i in enumerate(idx):
            S1, th1 = prep.pose(k, int(i))
            assert np.array_equal(S[n], S1) and th[n] == th1
