"""The class-III group III3 (a triad, Artobolevsky 1988): positions by Newton with continuation,
velocities, accelerations and reactions at Assur's special point S, checked against independent
formulations (the mechanism's constraint Jacobian; the group's full linear system of 12
equilibrium equations), the assembly modes, and the refusals of the paths that do not take it."""
from __future__ import annotations

import numpy as np
import pytest

import kinetostat
from conftest import ROOT
from kinetostat import fast, program
from kinetostat.applied import applied_wrenches, com_motion, inertia_loads
from kinetostat.kinematics import assembly_modes, kinematics
from kinetostat.program import constants, motion_program
from kinetostat.virtual_work import constraint_jacobian

MODELS = ("triad_six_bar", "triad_slider", "triad_rocking_block")
PHI = np.arange(0.0, 360.0, 15.0)


@pytest.fixture(scope="module", params=MODELS)
def mech(request):
    return kinetostat.load(ROOT / "models" / f"{request.param}.toml")


def test_structure_names_the_class_and_the_triad(mech):
    s = mech.structure
    assert s.formula == "I(0,1) <- III(2,3,4,5)" and (s.mechanism_class, s.order) == (3, 3)
    g = s.groups[0]
    assert (g.links, g.known) == ((3, 2, 4, 5), (1, 0, 0))
    assert "class 3, order 3" in str(s)


def test_special_point_velocities_equal_the_jacobians(mech):
    """v_S from the 2x2 solve at S, omega from leash 3's arm: the same as J qd = (0, ..., 1), the
    whole mechanism's constraint Jacobian (two rows per pair) solved at unit crank speed."""
    kin = kinematics(mech, np.radians(PHI), unit_speed=True)
    J = constraint_jacobian(mech, kin)
    rhs = np.zeros(J.shape[:2])
    rhs[:, -1] = 1.0
    qd = np.linalg.solve(J, rhs[..., None])[..., 0].reshape(len(PHI), -1, 3)
    mine = np.stack([kin.v_z.real, kin.v_z.imag, kin.omega], axis=-1)[:, 1:]
    assert np.max(np.abs(mine - qd)) <= 1e-14 * np.max(np.abs(qd))


def test_group_order_reactions_equal_the_groups_full_linear_system(mech):
    """The reactions found in the texts' order (R^tau by each leash's moment, R^n of leash 3 by
    the group's moment about S, the polygon, the leashes' polygons) against the 12 x 12 system of
    the group's four links (force and moment balance), solved by LU."""
    res = kinetostatic = kinetostat.analyze(mech, phi_deg=PHI)
    kin = kinetostatic.kin
    r, aS = com_motion(mech, kin)
    F, M = applied_wrenches(mech, kin, r)
    F_i, M_i = inertia_loads(mech, kin, aS)
    F, M = F + F_i, M + M_i + (np.conj(r) * F_i).imag
    g = mech.structure.groups[0]
    links = list(g.links)
    pairs = [p for p in mech.pairs if set(p.links) & set(links)]
    assert len(pairs) == 6
    pts = mech.points_z
    for n in range(len(PHI)):
        A = np.zeros((12, 12))
        b = np.zeros(12)
        for e, k in enumerate(links):
            b[3 * e:3 * e + 3] = -F[n, k].real, -F[n, k].imag, -M[n, k]
        for c, p in enumerate(pairs):
            X = kin.origin_z[n, p.links[1]] + pts[p.links[1]][p.point] * kin.rot[n, p.links[1]]
            if p.kind == "R":
                cols = ((1.0, 0j + 1.0, 0.0), (1.0, 1j, 0.0))      # unit force along x, along y
            else:
                nrm = 1j * complex(*p.direction) * kin.rot[n, p.links[0]]
                cols = ((1.0, nrm, 0.0), (1.0, 0j, 1.0))          # normal force; couple
            for q, (_, f, couple) in enumerate(cols):
                for k, s in ((p.links[1], 1.0), (p.links[0], -1.0)):
                    if k in links:
                        e = links.index(k)
                        arm = X - kin.origin_z[n, k]
                        A[3 * e:3 * e + 3, 2 * c + q] += s * np.array(
                            [f.real, f.imag, (np.conj(arm) * f).imag + couple])
        x = np.linalg.solve(A, b)
        for c, p in enumerate(pairs):
            got = res.forces.R[n, p.index] if p.kind == "R" else \
                np.array([res.forces.normal[n, p.index], res.forces.m[n, p.index]])
            scale = np.max(np.abs(res.forces.R[n]))
            assert np.max(np.abs(got - x[2 * c:2 * c + 2])) <= 1e-12 * scale, (PHI[n], p.label)


def test_newton_converges_to_rounding_in_few_steps(mech):
    """The continuation's Newton: every leash closed to a few ulps of the group's size, within
    six steps from the track's pose (the counts are the program's outputs)."""
    env = dict(constants(mech), **kinetostat.kinematics.tracks(mech))
    env.update(phi=np.radians(np.arange(0.0, 360.0, 1.0)), w_in=1.0, e_in=0.0)
    out = program.run(motion_program(mech), env)
    L = max(kinetostat.kinematics.group_scales(mech))
    assert np.max(out["res0"]) <= 8 * np.finfo(float).eps * L
    assert 1 <= np.max(out["it0"]) <= 6


def _newton_on_arrays(kinds, O, rot, x, P, c, L):
    """The continuation's one-angle solve on one-element numpy arrays (`triad._newton`, then the
    sign of the group's Jacobian), as `triad.track` solved before it ran on Python scalars."""
    from kinetostat import triad
    P, c = tuple(np.array([v]) for v in P), tuple(np.array([v]) for v in c)
    O, rot, its, res = triad._newton(kinds, np.array([O]), np.array([rot]), x, P, c, L)
    return O[0], rot[0], its[0], res[0], np.sign(triad.jacobian_det(triad.misses(kinds, O, rot, x, P, c), O))[0]


def _track_inputs(mech):
    """Triad 0's (kinds, pins, phi0, O0, rot0, x, L) as `kinematics.tracks` passes them to `triad.track`."""
    from kinetostat.kinematics import _known_joints, group_scales
    kinds, x, pins = _known_joints(mech, 0, {**constants(mech), "w_in": 1.0, "e_in": 0.0})
    return kinds, pins, np.radians(mech.drive.design_deg), 0j, 1 + 0j, x, group_scales(mech)[0]


def test_the_track_solved_on_scalars_keeps_the_stations_and_the_branch_of_the_arrays(mech, monkeypatch):
    """The continuation solves one angle a step on Python scalars (`triad._newton_one`: the same
    `newton_step` bound to `_Scalars`, without numpy's cost per call): the same stations and
    solves, hence the same path and branch, as on one-element arrays, the poses to rounding; the
    poses closed from either track on a 0.5 deg grid agree to rounding, none off the path."""
    from kinetostat import triad
    args = _track_inputs(mech)
    kinds, pins, phi0, _, _, x, L = args
    scalar = triad.track(*args)
    monkeypatch.setattr(triad, "_newton_one", _newton_on_arrays)
    arrays = triad.track(*args)
    assert scalar.full and np.array_equal(scalar.u, arrays.u) and scalar.steps == arrays.steps
    assert scalar.sign == arrays.sign and np.max(np.abs(scalar.O - arrays.O)) <= 1e-13 * L
    assert np.max(np.abs(scalar.rot - arrays.rot)) <= 1e-13
    phi = np.radians(np.arange(0.0, 360.0, 0.5))
    P, c = pins(phi)
    codes = [float(triad.LEASH_KINDS.index(k)) for k in kinds]
    (O, rot, closure, path, _, _), (O_, rot_, closure_, path_, _, _) = (
        triad.iii3_positions(phi, phi0, *codes, *x, *P, *c, L, tr) for tr in (scalar, arrays))
    assert not closure.any() and not path.any() and not closure_.any() and not path_.any()
    assert np.max(np.abs(O - O_)) <= 1e-13 * L and np.max(np.abs(rot - rot_)) <= 1e-13


def test_a_one_angle_solve_that_divides_by_zero_fails_as_on_arrays():
    """A pose that puts a two-pin leash's inner pin on its outer pin (|AX| = 0, base turned to
    rot = 0): on arrays numpy's NaN runs through every step; on scalars the ZeroDivisionError
    ends the solve. Both are a failed solve (MAX_ITER steps, NaN miss and sign), which the
    continuation rejects, instead of an exception out of the analysis."""
    from kinetostat import triad
    mech = kinetostat.load(ROOT / "models" / "triad_six_bar.toml")
    kinds, pins, phi0, _, _, x, L = _track_inputs(mech)
    P, c = (tuple(np.asarray(v).item() for v in part) for part in pins(phi0))
    i = kinds.index("R")
    with np.errstate(all="ignore"):
        got, ref = triad._newton_one(kinds, P[i], 0j, x, P, c, L), _newton_on_arrays(kinds, P[i], 0j, x, P, c, L)
    for solve in (got, ref):
        assert solve[2] == triad.MAX_ITER and np.isnan(solve[3]) and np.isnan(solve[4]) and np.isnan(solve[0])


def test_a_few_angles_closed_one_by_one_on_scalars_equal_the_arrays(mech):
    """Up to FEW_ANGLES angles (the forward dynamics asks 1 to 4 a stage) `iii3_positions`
    closes one by one on Python scalars (`triad._newton_each`): the same poses to rounding, the
    same Newton steps and misses as on arrays, at 1, 4 and FEW_ANGLES angles over the cycle and
    at an angle whose start is NaN (a failed solve on both)."""
    from kinetostat import triad
    kinds, pins, phi0, _, _, x, L = _track_inputs(mech)
    tr = kinetostat.kinematics.tracks(mech)["track0"]
    for phi in (np.radians([200.0]), np.radians([10.0, 97.3, 200.0, 333.3]), np.linspace(0.0, 6.2, triad.FEW_ANGLES)):
        P, c = pins(phi)
        O0, rot0, _ = tr.start(np.mod(phi - phi0 + np.pi, 2 * np.pi) - np.pi)
        O0[-1] = O0[-1] * np.nan if len(phi) == triad.FEW_ANGLES else O0[-1]
        with np.errstate(all="ignore"):
            (O, rot, its, res), (O_, rot_, its_, res_) = (f(kinds, O0, rot0, x, P, c, L)
                                                          for f in (triad._newton_each, triad._newton))
        assert np.array_equal(its, its_) and np.array_equal(np.isnan(res), np.isnan(res_))
        ok = ~np.isnan(res_)
        assert np.max(np.abs(O[ok] - O_[ok])) <= 1e-13 * L and np.max(np.abs(rot[ok] - rot_[ok])) <= 1e-13
        assert max(np.max(res[ok]), np.max(res_[ok])) <= 8 * np.finfo(float).eps * L
    assert not ok[-1] and its[-1] == triad.MAX_ITER


@pytest.mark.parametrize("step", [5.0, 7.0, 13.0, 360.0])
def test_the_result_does_not_depend_on_the_angles_asked(mech, step):
    """The continuation (with its stations every 3 deg) stays on the drawn mode whatever grid is
    asked for: a grid of 5 deg once jumped modes at 280 deg, where two of its angles and a
    station nearly coincide."""
    fine = kinetostat.kinematics.kinematics(mech, np.radians(np.arange(0.0, 360.0, 0.5)))
    phi = np.arange(0.0, 360.0, step) + 200.0 * (step == 360.0)
    kin = kinetostat.kinematics.kinematics(mech, np.radians(phi))
    on_fine = np.round(np.mod(phi, 360.0) * 2).astype(int)
    assert np.max(np.abs(kin.origin_z - fine.origin_z[on_fine])) <= 1e-14


def test_the_modes_at_the_design_position_are_listed_and_the_drawn_one_chosen(mech):
    (am,) = assembly_modes(mech)
    assert len(am.O) >= 2 and am.drawn_miss <= 1e-11                  # the drawing, written to 12 decimals
    assert abs(am.O[am.chosen]) < 1e-11 and abs(am.rot[am.chosen] - 1) < 1e-11   # the base's frame is the world's
    assert am.separation > kinetostat.kinematics.MODES_CLOSE
    assert "<- solved (drawn by the model)" in am.lines()[am.chosen]


def test_a_drawing_off_the_assembly_is_warned_and_its_nearest_mode_solved():
    text = (ROOT / "models" / "triad_six_bar.toml").read_text()
    moved = kinetostat.loads(text.replace("D = [0.834305347347, 0.311006393347]", "D = [0.834305347347, 0.321006393347]"))
    with pytest.warns(kinetostat.ModelWarning, match=r"III\(2,3,4,5\): the base link's points do not draw"):
        res = kinetostat.analyze(moved, phi_deg=[0.0, 90.0])
    (am,) = assembly_modes(moved)
    assert 1e-3 < am.drawn_miss < 0.02 and np.isfinite(res.balancing_moment).all()


def test_the_compiled_path_and_the_array_api_refuse_a_triad_by_name(mech):
    assert "III(2,3,4,5)" in fast.refusal(mech)
    with pytest.raises(NotImplementedError, match=r"class-III groups \(III\(2,3,4,5\)\)"):
        fast.analyze_fast(mech, np.arange(0.0, 360.0, 30.0))
    pytest.importorskip("array_api_strict")
    import array_api_strict as xp
    from kinetostat import arrays
    with pytest.raises(NotImplementedError, match=r"class-III group \(III\(2,3,4,5\)\)"):
        arrays.solve(kinetostat.loads((ROOT / "models" / "triad_six_bar.toml").read_text().split("[[load]]")[0]),
                     xp.asarray([0.0, 1.0]))


def _six_bar_with_crank(r: float):
    """The bundled six-bar with the crank radius r (the rod keeps B where it is drawn)."""
    text = (ROOT / "models" / "triad_six_bar.toml").read_text()
    return kinetostat.loads(text.replace('A = [0.10, 0.0] }\nmass = 2.0', f'A = [{r!r}, 0.0] }}\nmass = 2.0')
                            .replace('points = { A = [0.10, 0.0], B', f'points = {{ A = [{r!r}, 0.0], B'))


def test_a_crank_that_brushes_the_triads_singular_position_is_flagged_and_its_accuracy_estimated():
    """With the crank radius 1e-9 m short of 0.1171630935799 m (where the crank's circle touches
    the fold of the triad: the three leash axes through one point), the mechanism passes the
    singular position at phi ~ 198.372 deg: cond 2.1e4 there. The guard measures the accuracy
    (perturbed re-solves) as for a dyad, warns, and sets NaN where fewer than 6 digits are left;
    the estimate bounds the error against the 40-digit reference where values are kept."""
    from kinetostat_validation.reference import reference_full
    mech = _six_bar_with_crank(0.11716309257991407)
    phi = np.array([90.0, 198.0, 198.3718])
    with pytest.warns(kinetostat.ModelWarning, match=r"III\(2,3,4,5\): the base link's points do not draw"), \
            pytest.warns(kinetostat.SingularPositionWarning, match=r"group III\(2,3,4,5\) is near a singular position"):
        res = kinetostat.analyze(mech, phi_deg=phi)       # the base is drawn for the bundled crank
    np.testing.assert_allclose(res.cond[:, 0], [5.54, 667, 2.14e4], rtol=0.01)
    assert list(res.singular) == [False, False, True]
    assert res.digits[0] > 12 and 6 < res.digits[1] < 10
    assert np.isnan(res.forces.R[2]).all() and np.isfinite(res.forces.R[:2]).all()
    ref = reference_full(mech, phi[:2], res=res.take([0, 1]), angle="double")
    err = np.max(np.linalg.norm(res.forces.R[:2] - ref.R, axis=-1), axis=1) / \
        np.max(np.linalg.norm(ref.R, axis=-1), axis=1)
    assert (err <= res.error[:2]).all() and err[1] > 1e-12      # the lost digits are real, and bounded


@pytest.mark.parametrize("route", ["pinocchio", "mujoco", "reference"])
def test_the_exact_routes_agree_on_a_sample_of_the_cycle(mech, route):
    """Kinematics, reactions and M_bal of the group route against an engine or the 40-digit
    reference at 24 angles (the whole cycle, with the simulations too, runs in test_compare's
    gate under -m slow): within 1e-9 of each quantity's peak (measured: 4e-15)."""
    from kinetostat_validation import compare as cmp
    if cmp.available(route):
        pytest.skip(cmp.available(route))
    c = cmp.compare(mech, engines=(route,), steps=24)
    assert not c.failed and c.rows
    worst = max(r.peak_relative for r in c.rows)
    assert worst <= 1e-9 and all(r.passed for r in c.rows)


def test_virtual_work_and_the_lever_agree_over_the_cycle(mech):
    from kinetostat.virtual_work import virtual_work
    res = kinetostat.analyze(mech)
    vw = virtual_work(mech)
    peak = np.max(np.abs(res.balancing_moment))
    assert np.max(np.abs(vw.balancing_moment - res.balancing_moment)) <= 1e-12 * peak
    assert np.max(np.abs(res.lever_discrepancy)) <= 1e-12 * peak
    R = np.abs(res.forces.R).max()
    assert np.max(np.abs(vw.forces.R - res.forces.R)) <= 1e-12 * R


def test_the_plans_draw_s_and_the_force_polygon_in_the_texts_order(mech):
    """Velocity plan: s with v_S (from the outer pins of the leashes through S, the two whose axes
    meet at the best angle: 5 and 2 on the six-bar at 60 deg); the group plan: S and the arms
    about it; the force polygon closes with R..n of those two, and every reaction
    on it (outer, as chords over their parts, and inner, from each leash's polygon) is analyze's
    vector."""
    from kinetostat.kinematics import special_point_z
    from kinetostat.plans import forces, kinematic
    from kinetostat.plans.scales import choose_scales
    res = kinetostat.analyze(mech, phi_deg=[60.0])
    g = mech.structure.groups[0]
    sc = choose_scales(mech, res)
    v = kinematic.velocity_plan(mech, res, sc).at(0)          # the cycle of one angle
    S = special_point_z(mech, res.kin, g)[0]
    b = g.links[0]
    local = (S - res.kin.origin_z[0, b]) / res.kin.rot[0, b]
    vS = complex(res.kin.point_z(b, (local.real, local.imag))[1][0])
    assert abs(v.points["s"] * sc["mu_v"].value - vS) <= 1e-12 * abs(vS)
    assert {s.name for s in v.segments} >= {"a-s", "p-s"}
    acc = kinematic.acceleration_plan(mech, res, sc).at(0)
    aS = complex(res.kin.point_z(b, (local.real, local.imag))[2][0])
    a_A = complex(res.kin.point_z(1, tuple(mech.links[1].points["A"]))[2][0])
    seg = acc.segment("a-s")
    assert abs(seg.value - abs(aS - a_A)) <= 1e-12 * abs(aS)                     # a_S = a_A + a_SA
    assert abs(abs(acc.points["s"] - acc.points["a"]) * sc["mu_a"].value - seg.value) <= 1e-12 * abs(aS)
    (gp,) = (p.at(0) for p in forces.group_plans(mech, res, sc["mu_l"]))
    assert abs(gp.points["S"] * sc["mu_l"].value - S) <= 1e-12
    assert any(s.name.endswith("(S)") for s in gp.segments)
    mu_F = forces.default_mu_F(mech, res)
    (fp,) = (p.at(0) for p in forces.force_plans(mech, res, mu_F))
    eq = fp.equation
    (l1, _, _, a1), (l2, _, _, a2), (l3, _, _, a3) = kinetostat.kinematics.special_sides(mech, res.kin, g)
    best = {"RRR": (5, 2), "RRP": (2, 4)}[g.kind] if g.inner == "RRR" else (2, 4)     # S: the best-met axes
    assert {l1, l2, l3} == {2, 4, 5} and (l1, l2) == best
    name = lambda a, ell: forces.reaction_name(mech, a, ell)
    assert eq[-2:] == (name(a1, l1) + "n", name(a2, l2) + "n") and eq[0] == name(a2, l2) + "t"
    n = len(eq)
    sides = [fp.points[s.end] - fp.points[s.start] for s in fp.segments[:n]]
    assert abs(sum(sides)) <= 1e-12 * max(map(abs, sides))
    for i, j in [(1, 2), (0, 4), (3, 2), (3, 4), (3, 5)] + ([(0, 5)] if g.kind == "RRR" else []):
        s = fp.segment(forces.reaction_name(mech, i, j))
        drawn = (fp.points[s.end] - fp.points[s.start]) * mu_F.value
        assert abs(drawn - complex(*res.reaction(i, j)[0])) <= 1e-9 * abs(drawn)


def test_the_drawing_error_simulation_refuses_a_triad_by_name(mech):
    from kinetostat.plans import drawing_error
    assert not drawing_error.draws_forces(mech)
    with pytest.raises(NotImplementedError, match=r"group III\(2,3,4,5\) of kind R.. \(III3 R..(, inner RRP)?\) is not drawn"):
        drawing_error.simulate(mech, n=10)


def test_near_the_singular_position_the_mode_drawn_is_kept_on_a_fine_grid():
    """Crank r = 0.1171 m (4.3e-5 m short of touching the fold): the path passes close to the
    other mode near phi = 202 deg. On a 0.01 deg grid the base turns smoothly (the true rate is
    below 0.0018 deg per 0.01 deg; the old block continuation jumped 1.6 deg at 202.14 deg and
    followed the other mode to 240 deg), and the base's angle equals an independent continuation
    (a 3x3 Newton on the three leashes' closure, finite-difference Jacobian, 0.01 deg steps from
    the design position both ways: /tmp/t2_fine.py in the review's scratch) to 1e-9 deg."""
    import warnings
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", kinetostat.ModelWarning)     # the base is drawn for r = 0.10
        mech = _six_bar_with_crank(0.1171)
        phi = np.arange(195.0, 245.0, 0.01)
        kin = kinematics(mech, np.radians(phi))
        th = np.degrees(np.unwrap(np.angle(kin.rot[:, 3])))
        assert np.max(np.abs(np.diff(th))) <= 0.002 and np.max(kin.cond) < 90
        at = kinematics(mech, np.radians([150.0, 202.14, 202.15, 240.0, 300.0]))
    fine = [7.941273160, 12.561725178, 12.560127420, 6.568191905, 0.463113479]
    assert np.max(np.abs(np.degrees(np.angle(at.rot[:, 3])) - fine)) <= 1e-8
    tr = kinetostat.kinematics.tracks(mech)["track0"]
    assert tr.full and tr.mismatch <= 1e-12 and tr.steps < 400     # the path closes over the turn


def test_a_crank_stopped_by_a_fold_is_solved_where_it_turns_and_refused_by_name_beyond(tmp_path, cli):
    """Crank r = 0.125 m: the triad's fold stops the crank at 166.5 deg going up and 230.2 deg
    going down (the group's condition number grows without bound there). Angles asked on the
    path are solved (no error for angles nobody asked); one beyond names itself alone; the CLI
    says so in one line, exit 2."""
    import warnings
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", kinetostat.ModelWarning)
        mech = _six_bar_with_crank(0.125)
        res = kinetostat.analyze(mech, phi_deg=[60.0, 90.0, 300.0])
        assert np.isfinite(res.balancing_moment).all()
        tr = kinetostat.kinematics.tracks(mech)["track0"]
        ends = np.degrees(tr.u[[0, -1]]) + 60.0
        np.testing.assert_allclose(ends, [230.19 - 360.0, 166.51], atol=0.01)
        with pytest.warns(kinetostat.SingularPositionWarning, match=r"phi = \[166.5, 230.2\] deg"):
            near = kinematics(mech, np.radians([166.5, 230.2, 100.0]))
        assert (near.cond[:2, 0] > 200).all() and near.cond[2, 0] < 10
        with pytest.raises(kinetostat.AssemblyError, match=r"III\(2,3,4,5\).* at phi = \[180\] deg"):
            kinetostat.analyze(mech, phi_deg=[60.0, 180.0])
    bad = tmp_path / "far.toml"       # the frame pin F moved 2 m off: the crank no longer reaches 84 deg
    bad.write_text((ROOT / "models" / "triad_six_bar.toml").read_text().replace("F = [0.95, 0.80]", "F = [2.95, 0.80]"))
    assert cli("structure", bad, "--modes").returncode == 0
    out = cli("analyze", bad)
    assert out.returncode == 2 and out.stderr.strip().splitlines()[-1].startswith("kinetostat: error:")
    assert "at phi = [84, 85" in out.stderr


def _renumbered(text: str) -> str:
    """The same mechanism with the leashes' links renumbered 2 -> 5, 4 -> 2, 5 -> 4 (the group's
    leashes 1 and 2, the lowest ids, become the rocker E-C and the rod)."""
    import re
    new = {2: 5, 4: 2, 5: 4}
    text = re.sub(r"^id = (\d+)", lambda g: f"id = {new.get(int(g[1]), int(g[1]))}", text, flags=re.M)
    return re.sub(r"^links = \[(\d+), (\d+)\]",
                  lambda g: f"links = [{new.get(int(g[1]), int(g[1]))}, {new.get(int(g[2]), int(g[2]))}]", text, flags=re.M)


def test_any_two_leashes_define_s_so_the_numbering_does_not_matter():
    """F moved so that the axes of the rocker E-C and of F-D are parallel at 60 deg (the
    review's six_parF): renumbered, those are leashes 1 and 2 (S from them alone failed at 119
    angles). S from the two axes meeting at the best angle: the renumbered mechanism gives the
    same reactions and M_bal to rounding, no angle singular (cond <= 5.1: the three axes never
    meet in one point), and the reactions still equal the constraint Jacobian's virtual work."""
    from kinetostat.virtual_work import virtual_work
    text = (ROOT / "models" / "triad_six_bar.toml").read_text().replace(
        "F = [0.95, 0.80]", "F = [0.8497800941, 0.8132618385270001]")
    a, b = kinetostat.loads(text), kinetostat.loads(_renumbered(text))
    assert b.structure.groups[0].known == (0, 0, 1)
    phi = np.arange(0.0, 360.0, 5.0)
    with pytest.warns(kinetostat.ModelWarning, match="do not draw"):        # the base drawn for F as bundled
        ra = kinetostat.analyze(a, phi_deg=phi)
    with pytest.warns(kinetostat.ModelWarning, match="do not draw"):
        rb = kinetostat.analyze(b, phi_deg=phi)
    peak = np.max(np.abs(ra.balancing_moment))
    assert np.max(np.abs(ra.balancing_moment - rb.balancing_moment)) <= 1e-12 * peak
    Rmax = np.max(np.abs(ra.forces.R))
    for i, j in [(1, 2), (0, 4), (0, 5), (2, 3), (3, 4), (3, 5)]:
        jb, ib = {2: 5, 4: 2, 5: 4}.get(j, j), {2: 5, 4: 2, 5: 4}.get(i, i)
        assert np.max(np.abs(ra.reaction(i, j) - rb.reaction(ib, jb))) <= 1e-12 * Rmax
    assert not rb.singular.any() and np.max(rb.cond) < 5.1
    with pytest.warns(kinetostat.ModelWarning, match="do not draw"):         # on every analysis
        vw = virtual_work(b, phi_deg=phi)
    assert np.max(np.abs(vw.balancing_moment - rb.balancing_moment)) <= 1e-12 * peak


def test_two_modes_closer_than_the_samples_are_both_found_and_warned():
    """The crank r = 0.11716309257991407 m with the design position at 198 deg, next to the
    fold: two modes 0.125 deg apart in the base's angle (13.420 and 13.545 deg) (with the trial
    positions of leash 1 both lay between two of the 3600 samples, no change of sign of the miss
    there: one mode was listed, separation inf, no warning; now the base's angle is sampled). Each mode found closes the three leashes (their lengths
    measured here from the model's points) to rounding, and the warning names the closeness."""
    text = (ROOT / "models" / "triad_six_bar.toml").read_text().replace("design_deg = 60.0", "design_deg = 198.0")
    mech = kinetostat.loads(text.replace('A = [0.10, 0.0] }\nmass = 2.0', 'A = [0.11716309257991407, 0.0] }\nmass = 2.0')
                            .replace('points = { A = [0.10, 0.0], B', 'points = { A = [0.11716309257991407, 0.0], B'))
    with pytest.warns(Warning) as got:                 # both asserted below
        (am,) = assembly_modes(mech)
        kinetostat.kinematics.kinematics(mech, np.radians([198.0]))
    assert any("another assembly mode is within 0.00319" in str(w.message) for w in got)
    assert any(isinstance(w.message, kinetostat.SingularPositionWarning) for w in got)    # cond 670 there
    th = np.degrees(np.angle(np.array(am.rot)))
    np.testing.assert_allclose(np.sort(th), [13.4203, 13.5455], atol=1e-4)
    assert 0.003 < am.separation < 0.0033
    pts = mech.points_z
    A = 0.11716309257991407 * np.exp(1j * np.radians(198.0))
    for O, rot in zip(am.O, am.rot):
        B, C, D = (O + pts[3][p] * rot for p in "BCD")
        miss = [abs(B - A) - abs(pts[2]["B"] - pts[2]["A"]), abs(C - pts[0]["E"]) - abs(pts[4]["C"] - pts[4]["E"]),
                abs(D - pts[0]["F"]) - abs(pts[5]["D"] - pts[5]["F"])]
        assert np.max(np.abs(miss)) <= 1e-15


def test_the_newton_residual_is_reported_per_angle_and_printed(cli):
    """Kinematics.residual (N, groups), m: the triad's largest leash miss after its Newton, the
    same as the misses measured here from the public positions (the three leashes' lengths);
    `kinetostat analyze` prints the largest."""
    mech = kinetostat.load(ROOT / "models" / "triad_six_bar.toml")
    kin = kinematics(mech, np.radians(PHI))
    pts, L = mech.points_z, kinetostat.kinematics.group_scales(mech)[0]
    miss = []
    for ell, outer, inner in [(2, "A", "B"), (4, "E", "C"), (5, "F", "D")]:
        X = kin.position_z(3, (pts[3][inner].real, pts[3][inner].imag))
        P = kin.position_z(ell, (pts[ell][outer].real, pts[ell][outer].imag))
        miss.append(np.abs(np.abs(X - P) - abs(pts[ell][inner] - pts[ell][outer])))
    assert kin.residual.shape == (len(PHI), 1) and np.max(kin.residual) <= 8 * np.finfo(float).eps * L
    assert np.max(np.abs(kin.residual[:, 0] - np.max(miss, axis=0))) <= 4 * np.finfo(float).eps * L
    out = cli("analyze", "triad_six_bar", "--steps", "12")
    assert out.returncode == 0 and "triads' closure (Newton) residual: largest leash miss" in out.stdout


def test_the_reference_refuses_positions_in_another_mode():
    """The 40-digit reference's branch check covers triads: positions in the other assembly
    mode (from `assembly_modes`, each leash laid between its pins) converge in 40 digits, but
    the constraint Jacobian's determinant has the other sign than at the design position: a
    BranchMismatch; the solver's own positions pass."""
    from dataclasses import replace
    from kinetostat_validation.reference import BranchMismatch, reference_full
    mech = kinetostat.load(ROOT / "models" / "triad_six_bar.toml")
    res = kinetostat.analyze(mech, phi_deg=[60.0])
    assert np.isfinite(reference_full(mech, [60.0], res=res).M_bal).all()
    (am,) = assembly_modes(mech)
    O, rot = next((O, r) for i, (O, r) in enumerate(zip(am.O, am.rot)) if i != am.chosen)
    pts, kin = mech.points_z, res.kin
    oz, rz = kin.origin_z.copy(), kin.rot.copy()
    oz[0, 3], rz[0, 3] = O, rot
    for ell, outer, inner in [(2, "A", "B"), (4, "E", "C"), (5, "F", "D")]:
        P, X = kin.position_z(ell, (pts[ell][outer].real, pts[ell][outer].imag))[0], O + pts[3][inner] * rot
        rz[0, ell] = (X - P) / (pts[ell][inner] - pts[ell][outer])
        oz[0, ell] = P - pts[ell][outer] * rz[0, ell]
    other = replace(res, kin=replace(kin, origin_z=oz, rot=rz, theta=np.angle(rz)))
    with pytest.raises(BranchMismatch, match="not in the mode continuous from the design position"):
        reference_full(mech, [60.0], res=other)


def test_a_pose_in_a_neighbouring_mode_is_refused_however_near():
    """A track whose poses lie in the other mode at the design position, but which keeps the
    drawn mode's sign of the group's Jacobian: Newton closes there at once (the pose moves 0 m,
    within PREDICT L), and the sign alone says the path was left."""
    from kinetostat import triad
    from kinetostat.kinematics import _known_joints, tracks
    mech = kinetostat.load(ROOT / "models" / "triad_six_bar.toml")
    env = {**constants(mech), **tracks(mech), "w_in": 1.0, "e_in": 0.0}
    kinds, x, pins = _known_joints(mech, 0, env)
    phi0 = np.radians([mech.drive.design_deg])
    P, c = pins(phi0)
    (am,) = assembly_modes(mech)
    drawn = env["track0"]
    codes = [float(triad.LEASH_KINDS.index(k)) for k in kinds]
    L = kinetostat.kinematics.group_scales(mech)[0]
    for i, (O, rot) in enumerate(zip(am.O, am.rot)):
        fake = triad.Track(np.array([-np.pi, np.pi]), np.array([O, O]), np.array([rot, rot]), 0, 0.0, drawn.sign)
        O_, rot_, closure, path, its, _ = triad.iii3_positions(phi0, phi0[0], *codes, *x, *P, *c, L, fake)
        assert closure[0] == 0.0 and abs(O_[0] - O) <= 1e-12 * L and its[0] <= 1
        assert path[0] == (0.0 if i == am.chosen else -1.0)


def _drawn_at(name: str, d: float) -> str:
    """Model `name` with its base link drawn at the crank angle d (deg; its points, and a guide
    it carries, written in world coordinates from the bundled model's pose there, to 17 digits)
    and design_deg = d: the same mechanism, the same mode, another design position."""
    import re
    text = (ROOT / "models" / f"{name}.toml").read_text()
    mech = kinetostat.load(ROOT / "models" / f"{name}.toml")
    kin = kinematics(mech, np.radians([d]))
    b = mech.structure.groups[0].links[0]
    xy = lambda z: f"[{float(z.real)!r}, {float(z.imag)!r}]"
    pts = ", ".join(f"{p} = {xy(kin.position_z(b, (z.real, z.imag))[0])}" for p, z in mech.points_z[b].items())
    text = re.sub(r"points = \{ B = [^}]*\}", "points = { " + pts + " }", text)
    text = re.sub(r"(links = \[3, 5\].*\nguide = .*\ndirection = )\[1.0, 0.0\]",
                  lambda m: m[1] + xy(kin.rot[0, b]), text)
    return re.sub(r"design_deg = [0-9.]+", f"design_deg = {float(d)!r}", text)


def _base_pins(mech, kin) -> np.ndarray:
    """(3, N) complex, m: the base link's inner points B, C, D (world)."""
    b = mech.structure.groups[0].links[0]
    return np.array([kin.position_z(b, (mech.points_z[b][p].real, mech.points_z[b][p].imag)) for p in "BCD"])


_DESIGNS = [(name, d) for name in MODELS for d in range(0, 360, 7)]
_DESIGNS_SAMPLE = [("triad_six_bar", 77), ("triad_slider", 0), ("triad_rocking_block", 98)]


@pytest.fixture(scope="module")
def bundled_pins():
    """Per model the base's inner points at every degree, from the bundled model."""
    out = {}
    for name in MODELS:
        mech = kinetostat.load(ROOT / "models" / f"{name}.toml")
        out[name] = _base_pins(mech, kinematics(mech, np.radians(np.arange(0.0, 360.0, 1.0))))
    return out


def _check_design(name: str, d: int, bundled_pins) -> None:
    """The model drawn at design angle d turns the crank fully and puts the base where the
    bundled model (drawn at its own design angle) does, at every degree, the half-turn from d
    included: the two ends of the track (the continuation stops a few ulps short of -pi or
    +pi) are one seam (before: 20 of the 156 designs failed there, e.g. the six-bar drawn at
    77 deg at 257 deg, the slider drawn at 0 deg at 180 deg)."""
    mech = kinetostat.loads(_drawn_at(name, d))
    assert kinetostat.kinematics.tracks(mech)["track0"].full
    kin = kinematics(mech, np.radians(np.arange(0.0, 360.0, 1.0)))
    assert np.max(np.abs(_base_pins(mech, kin) - bundled_pins[name])) <= 1e-12


@pytest.mark.parametrize("name, d", _DESIGNS_SAMPLE)
def test_any_design_angle_solves_the_half_turn_from_it(name, d, bundled_pins):
    _check_design(name, d, bundled_pins)


@pytest.mark.slow
@pytest.mark.parametrize("name, d", _DESIGNS)
def test_every_design_angle_solves_the_whole_turn(name, d, bundled_pins):
    _check_design(name, d, bundled_pins)


def _drawn_off(tmp_path):
    """The six-bar with its base's pin D drawn 10 mm off the assembly."""
    far = tmp_path / "drawn_off.toml"
    far.write_text((ROOT / "models" / "triad_six_bar.toml").read_text().replace(
        "D = [0.834305347347, 0.311006393347]", "D = [0.834305347347, 0.321006393347]"))
    return far


def test_the_triads_model_warnings_reach_the_cli(tmp_path, cli):
    """The warnings are kept per mechanism and issued on every analysis (the CLI's memory check
    runs a first analysis with warnings ignored: it used to use them up). `analyze` prints the
    drawing's miss; `structure --modes` prints two modes 0.125 deg apart with the analysis' own
    closeness warning (it printed none)."""
    out = cli("analyze", _drawn_off(tmp_path), "--steps", "12")
    assert out.returncode == 0 and "III(2,3,4,5): the base link's points do not draw" in out.stderr
    r = "0.11716309257991407"
    close = tmp_path / "close.toml"
    close.write_text((ROOT / "models" / "triad_six_bar.toml").read_text().replace("design_deg = 60.0", "design_deg = 198.0")
                     .replace('A = [0.10, 0.0] }\nmass = 2.0', f'A = [{r}, 0.0] }}\nmass = 2.0')
                     .replace('points = { A = [0.10, 0.0], B', f'points = {{ A = [{r}, 0.0], B'))
    out = cli("structure", close, "--modes")
    assert out.returncode == 0 and out.stdout.count(" mode ") == 2
    assert "another assembly mode is within 0.00319 of the group's size" in out.stderr


def test_the_plans_print_the_triads_model_warnings(tmp_path, cli):
    """`plans` printed only the warnings of the plan's own angle: the model's are printed too."""
    out = cli("plans", _drawn_off(tmp_path), "--at", "30", "--only", "velocity", "--out", tmp_path / "p")
    assert out.returncode == 0 and "the pins miss the nearest mode by 0.0145 m" in out.stderr
