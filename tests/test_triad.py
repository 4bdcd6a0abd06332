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

MODELS = ("triad_six_bar", "triad_slider")
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
    six steps from each block's start (the counts are the program's outputs)."""
    env = dict(constants(mech))
    env.update(phi=np.radians(np.arange(0.0, 360.0, 1.0)), w_in=1.0, e_in=0.0)
    out = program.run(motion_program(mech), env)
    L = max(kinetostat.kinematics.group_scales(mech))
    assert np.max(out["res0"]) <= 8 * np.finfo(float).eps * L
    assert 1 <= np.max(out["it0"]) <= 6


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
    """Velocity plan: s with v_S (from the outer pins of leashes 1 and 2); the group plan: S and
    the arms about it; the force polygon closes with R..n of leashes 1 and 2, and every reaction
    on it (outer, as chords over their parts, and inner, from each leash's polygon) is analyze's
    vector."""
    from kinetostat.kinematics import special_point_z
    from kinetostat.plans import forces, kinematic
    from kinetostat.plans.scales import choose_scales
    res = kinetostat.analyze(mech, phi_deg=[60.0])
    g = mech.structure.groups[0]
    sc = choose_scales(mech, res)
    v = kinematic.velocity_plan(mech, res, sc)
    S = special_point_z(mech, res.kin, g)[0]
    b = g.links[0]
    local = (S - res.kin.origin_z[0, b]) / res.kin.rot[0, b]
    vS = complex(res.kin.point_z(b, (local.real, local.imag))[1][0])
    assert abs(v.points["s"] * sc["mu_v"].value - vS) <= 1e-12 * abs(vS)
    assert {s.name for s in v.segments} >= {"a-s", "p-s"}
    (gp,) = forces.group_plans(mech, res, sc["mu_l"])
    assert abs(gp.points["S"] * sc["mu_l"].value - S) <= 1e-12
    assert any(s.name.endswith("(S)") for s in gp.segments)
    mu_F = forces.default_mu_F(mech, res)
    (fp,) = forces.force_plans(mech, res, mu_F)
    eq = fp.equation
    assert eq[-2:] == ("R12n", "R04n") and eq[0] == "R04t"
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
    with pytest.raises(NotImplementedError, match=r"group III\(2,3,4,5\) of kind R.. \(III3 R..\) is not drawn"):
        drawing_error.simulate(mech, n=10)
