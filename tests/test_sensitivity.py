"""kinetostat.sensitivity: exact forward-mode derivatives of the kinematics, reactions and M_bal by a
model's parameters, against an independent route: central differences of whole analyses of the model
re-loaded with the parameter overridden (`kinetostat.load(path, parameters=...)`, as `sweep` sets
parameters), Richardson-extrapolated in float64 (truncation O(h^4))."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import kinetostat
from kinetostat import SingularPositionWarning
from kinetostat.analysis import exact

from conftest import FOUR_BAR, ROOT

CHAIN = ROOT / "models" / "chain_unit_four_bar.toml"
ICE = ROOT / "models" / "ice_crank_slider.toml"
COMPRESSOR = ROOT / "models" / "compressor.toml"
YOKE = ROOT / "models" / "scotch_yoke.toml"
PHI = np.arange(360.0)
#: Agreement asked for: the largest difference over the angles, relative to the largest |derivative|.
RTOL = 1e-8


def outputs(mech, point: str) -> list:
    """What is compared: (name, Analysis -> array, Sensitivity -> parameter -> array): M_bal (and
    F_bal), every pair's reaction, the motion of `point`."""
    out = [("M_bal", lambda r: r.balancing_moment, lambda s: s.balancing_moment)]
    if mech.drive.kind == "machine":
        out.append(("F_bal", lambda r: r.balancing_force, lambda s: s.balancing_force))
    for p in mech.pairs:
        out.append((f"R{p.links}", lambda r, ij=p.links: r.reaction(*ij), lambda s, ij=p.links: s.reaction(*ij)))
    return out + [(f"{what}_{point}", lambda r, w=what: getattr(r, w)(point), lambda s, w=what: getattr(s, w)(point))
                  for what in ("position", "velocity", "acceleration")]


def richardson(path, name: str, x0: float, rel_step: float = 1e-3):
    """output -> d output / d name at x0, by central differences of analyses of the model re-loaded
    with name = x0 +- h, x0 +- h/2, Richardson-extrapolated."""
    h = rel_step * abs(x0)
    runs = {k: exact(kinetostat.load(path, parameters={name: x0 + k * h}), PHI, "first") for k in (-1, -0.5, 0.5, 1)}

    def of(output) -> np.ndarray:
        D = lambda k: (np.asarray(output(runs[k])) - np.asarray(output(runs[-k]))) / (2 * k * h)
        return (4 * D(0.5) - D(1)) / 3
    return of


def worst(path, names, point: str = "B") -> dict[tuple[str, str], float]:
    """(parameter, output) -> the largest difference of the exact derivative from Richardson's over
    the angles, relative to the largest |derivative| (outputs that do not move: to 1 unit)."""
    mech = kinetostat.load(path)
    sens = kinetostat.sensitivity(mech, params=names, phi_deg=PHI)
    out = {}
    for name in names:
        differences = richardson(path, name, sens.values[name])
        for label, of_result, of_sens in outputs(mech, point):
            ref = differences(of_result)
            out[name, label] = float(np.abs(of_sens(sens)[name] - ref).max() / max(np.abs(ref).max(), 1.0))
    return out


def parametric_yoke(tmp_path) -> Path:
    """The bundled Scotch yoke (an RPP group, a return spring, a resistance against the velocity)
    with its crank, spring and resistance as [parameters], and its block given by its weight (its
    mass follows g)."""
    text = YOKE.read_text(encoding="utf-8").replace(
        "g = 9.81\n", "g = 9.81\n\n[parameters]\nr = 0.05\nk = 2000.0\nl0 = 0.10\nF = 150.0\n", 1)
    for old, new in (("A = [0.05, 0.0]", 'A = ["r", 0.0]'), ("mass = 0.3", "weight = 2.943"),
                     ("stiffness = 2000.0", 'stiffness = "k"'),
                     ("free_length = 0.10", 'free_length = "l0"'), ("value = 150.0", 'value = "F"')):
        assert old in text
        text = text.replace(old, new, 1)
    path = tmp_path / "yoke.toml"
    path.write_text(text, encoding="utf-8")
    return path


#: the crank r and the coupler l = sqrt(r**2 + c**2) together (d/d r moves l with r, d/d l moves l alone: as
#: the model loaded with one of them overridden), a frame point, a mass, an inertia, g
CHAIN_SAMPLE = ["r", "l", "h", "m2", "J_C2", "g"]
ICE_SAMPLE = ["l_OA", "n1", "p_max", "G2"]               # a length, the speed, the gas table's scale, a weight
COMPRESSOR_SAMPLE = ["l_OA", "AB_OA", "module", "d"]     # the stroke (the travel diagram's ends), the gear
CHAIN_ALL = [*kinetostat.load(CHAIN).parameters, "g"]
ICE_ALL = [*kinetostat.load(ICE).parameters, "g"]
COMPRESSOR_ALL = [n for n in [*kinetostat.load(COMPRESSOR).parameters, "g"] if n != "z_wheel"]   # an integer


@pytest.mark.parametrize("path, names", [(CHAIN, CHAIN_SAMPLE), (ICE, ICE_SAMPLE), (COMPRESSOR, COMPRESSOR_SAMPLE)],
                         ids=["chain_unit", "ice", "compressor"])
def test_agrees_with_richardson_differences(path, names):
    """Kinematics, reactions and M_bal at 360 angles, to 1e-8 of each output's scale: the chain-unit
    four-bar (bodies, a dependent coupler length l = sqrt(r^2 + c^2)), the ICE crank-slider (a phi
    diagram scaled by p_max, masses from weights), the compressor (a working machine's gear, a
    travel diagram with a return stroke whose stroke the crank sets)."""
    bad = {k: v for k, v in worst(path, names).items() if not v <= RTOL}
    assert not bad, bad


def test_spring_resistance_against_the_velocity_and_a_weight_agree(tmp_path):
    bad = {k: v for k, v in worst(parametric_yoke(tmp_path), ["r", "k", "l0", "F", "g"], "S3").items()
           if not v <= RTOL}
    assert not bad, bad


@pytest.mark.slow
@pytest.mark.parametrize("path, names", [(CHAIN, CHAIN_ALL), (ICE, ICE_ALL), (COMPRESSOR, COMPRESSOR_ALL)],
                         ids=["chain_unit", "ice", "compressor"])
def test_every_parameter_agrees_with_richardson_differences(path, names):
    bad = {k: v for k, v in worst(path, names).items() if not v <= RTOL}
    assert not bad, bad


def test_balancing_moment_is_affine_in_g():
    """M_bal = M_0 + g M_g (masses given as masses): d M_bal / d g is exactly its gravity part over g."""
    sens = kinetostat.sensitivity(kinetostat.load(CHAIN), params=["g", "r"], steps=90)
    g = sens.values["g"]
    weightless = exact(kinetostat.load(CHAIN, parameters={"g": 0.0}), sens.phi_deg, "first").balancing_moment
    gravity_part = sens.result.balancing_moment - weightless
    np.testing.assert_allclose(sens.balancing_moment["g"], gravity_part / g, rtol=0,
                               atol=1e-12 * np.abs(gravity_part / g).max())


def test_reactions_are_affine_in_the_gas_pressure():
    """The gas force is the only load p_max scales: d R / d p_max = (R - R at p_max = 0) / p_max."""
    sens = kinetostat.sensitivity(kinetostat.load(ICE), params=["p_max"], steps=72)
    p = sens.values["p_max"]
    idle = exact(kinetostat.load(ICE, parameters={"p_max": 0.0}), sens.phi_deg, "first")
    for i, j in ((0, 1), (1, 2), (3, 2), (0, 3)):
        part = (sens.result.reaction(i, j) - idle.reaction(i, j)) / p
        np.testing.assert_allclose(sens.reaction(i, j)["p_max"], part, rtol=0, atol=1e-12 * np.abs(part).max())


def test_result_is_the_analysis_and_arrays_are_read_only():
    mech = kinetostat.load(CHAIN)
    sens = kinetostat.sensitivity(mech, params=["r"], steps=36)
    ref = kinetostat.analyze(mech, steps=36)
    np.testing.assert_array_equal(sens.result.balancing_moment, ref.balancing_moment)
    assert sens.params == ("r",) and sens.values == {"r": 0.08} and sens.phi_deg.shape == (36,)
    d = sens.reaction(1, 2)["r"]
    assert d.shape == (36, 2) and not d.flags.writeable
    np.testing.assert_array_equal(sens.reaction(2, 1)["r"], -d)       # R_21 = -R_12
    assert np.all(sens.error < 1e-10) and sens.error.shape == (36,)
    with pytest.raises(AttributeError, match="engine"):
        sens.balancing_force


def test_every_parameter_by_default():
    mech = kinetostat.load(ICE)
    sens = kinetostat.sensitivity(mech, steps=8)
    assert sens.params == tuple(mech.parameters)


@pytest.mark.parametrize("params, match", [(["r", "nope"], "'nope' is not a parameter.*Parameters: r, n_k"),
                                           (["r", "r"], "names a parameter twice"), ([], "params is empty")])
def test_bad_params_are_named(params, match):
    with pytest.raises(ValueError, match=match):
        kinetostat.sensitivity(kinetostat.load(CHAIN), params=params, steps=4)


def test_to_xarray_has_every_output_by_every_parameter_with_units():
    pytest.importorskip("xarray")
    ds = kinetostat.sensitivity(kinetostat.load(CHAIN), params=["r", "m2"], steps=12).to_xarray()
    assert ds["dM_bal"].dims == ("param", "phi") and ds["dR"].dims == ("param", "phi", "pair", "xy")
    assert list(ds["param"].values) == ["r", "m2"] and list(ds["param_unit"].values) == ["m", "kg"]
    assert ds["dR"].attrs["units"] == "N" and "per unit of the parameter" in ds["dR"].attrs["long_name"]
    assert ds["dposition"].sizes["point"] == len(kinetostat.load(CHAIN).point_names)


def test_near_a_singular_position_the_guard_applies_to_the_derivatives():
    """A four-bar through a toggle at 180 deg (test_kinetostatics' TOGGLE): at 179 deg the values keep
    ~8 digits (warned) and the derivatives' estimate is that error times the plan's condition number;
    at 179.99 deg the analysis is singular: every derivative NaN, error inf."""
    toggle = (FOUR_BAR.replace("B = [0.35, 0.0], S2 = [0.15, 0.02]", "B = [0.2, 0.0], S2 = [0.1, 0.02]")
              .replace("B = [0.3, 0.0], S3", "B = [0.2, 0.0], S3"))
    with pytest.warns(SingularPositionWarning, match=r"values set to NaN at \[179\.99\] deg"):
        sens = kinetostat.sensitivity(kinetostat.loads(toggle), params=["g"], phi_deg=[90.0, 179.0, 179.99])
    res, cond = sens.result, sens.result.cond.max(axis=1)
    assert list(res.singular) == [False, False, True]
    np.testing.assert_allclose(sens.error[:2], res.error[:2] * cond[:2])
    assert sens.error[0] < 1e-12 < 1e-8 < sens.error[1] and sens.error[2] == np.inf
    for d in (sens.balancing_moment["g"], sens.reaction(1, 2)["g"], sens.position("B")["g"]):
        assert np.isfinite(d[:2]).all() and np.isnan(d[2]).all()


#: A crank alone driven at n rpm with a motor's characteristic M(omega) on it ({char}).
MOTOR_CRANK = """
[mechanism]
name = "crank alone with a motor"
g = 9.81
[parameters]
n = 90.0
R = 0.1
MS = 60.0
[drive]
pivot = "O"
point = "A"
reference = [1.0, 0.0]
sense = "ccw"
rpm = "n"
[frame]
O = [0.0, 0.0]
[[link]]
id = 1
points = {{ O = [0.0, 0.0], A = ["R", 0.0] }}
mass = 2.0
I_S = 0.01
com = "A"
[[pair]]
kind = "R"
links = [0, 1]
point = "O"
[[load]]
name = "motor"
kind = "moment"
link = 1
characteristic = {char}
"""


@pytest.mark.parametrize("char", ['"MS * (1 - omega / 12)"', "{ omega = [0.0, 9.0, 14.0], M = [30.0, 15.0, -10.0] }"],
                         ids=["expression", "table"])
def test_a_motor_characteristic_follows_the_speed(char):
    """M_bal carries d M(omega) / d omega d omega / d n; the crank's length moves the weight's moment."""
    text = MOTOR_CRANK.format(char=char)
    sens = kinetostat.sensitivity(kinetostat.loads(text), params=["n", "R"], steps=36)
    for name in ("n", "R"):
        x0, h = sens.values[name], 1e-3 * sens.values[name]
        f = lambda x: exact(kinetostat.loads(text, parameters={name: x}), sens.phi_deg, "first").balancing_moment
        D = lambda h: (f(x0 + h) - f(x0 - h)) / (2 * h)
        ref = (4 * D(h / 2) - D(h)) / 3
        assert np.abs(sens.balancing_moment[name] - ref).max() <= RTOL * np.abs(ref).max()


def test_a_characteristic_that_reads_the_parameter_is_refused_by_name():
    with pytest.raises(ValueError, match=r"load 'motor' \(load\[0\]\): its characteristic M\(omega\) reads \['MS'\]"):
        kinetostat.sensitivity(kinetostat.loads(MOTOR_CRANK.format(char='"MS * (1 - omega / 12)"')), params=["MS"])


# ----------------------------------------------------------------------------- the compiled path
def _jvp_scope() -> dict:
    """groups' functions and their generated `_jvp` versions in one pure-Python scope (numpy's
    primitives), so the tangent transform is checked without a compile."""
    import inspect
    from kinetostat import fast_sensitivity, groups
    scope = dict(vars(groups))
    exec(compile(fast_sensitivity.jvp_source() + "\n" + "\n".join(
        inspect.getsource(f) for f in fast_sensitivity.PRIMITIVE_JVPS), "<jvp>", "exec"), scope)
    return scope


def test_generated_tangents_match_duals_on_the_group_equations():
    """Every group equation's generated `_jvp` gives the tangent the numpy path's Dual gives (one
    direction), on random points (the RRR and RRP assemblies, polygons, inertia, gear force)."""
    from kinetostat.sensitivity import Dual
    scope, rng = _jvp_scope(), np.random.default_rng(3)
    z = lambda: complex(*rng.normal(size=2))
    cases = {"rrr_motion": [0.1 + 0j, z(), z(), 1.0 + 0.2j, z(), z(), 0.8, 0.7, 1.0, 1.0],
             "rrp_motion": [0.1j, z(), z(), 0.5 + 0j, (0.6 + 0.8j), 0.1, 2.5, -1.0, z(), z(), z(), 0.4, 0.2, 1.0],
             "rpr_motion": [1.0 + 0.5j, z(), z(), 0j, z(), z(), 0.1, 1.0, 1.0],
             "rrr_polygon": [z(), z(), z(), 1.1, 0.9, z(), z(), 0.3, -0.2],
             "inertia": [z(), 0.7, 0.2, np.exp(0.4j), z(), 2.0, 0.1],
             "gear_force": [1.5, np.exp(0.3j), 0.35, 0.04]}
    for fn, args in cases.items():
        tans = [z() if isinstance(a, complex) else float(rng.normal()) for a in args]
        duals = [Dual(np.asarray(a), np.asarray([t])) for a, t in zip(args, tans)]
        want = scope[fn](*duals)
        want = want if isinstance(want, tuple) else (want,)
        got = scope[f"{fn}_jvp"](*[x for pair in zip(args, tans) for x in pair])
        for k, w in enumerate(want):
            w = w if isinstance(w, Dual) else Dual(w, np.zeros(1))
            assert np.allclose(got[2 * k], w.val, rtol=1e-13, atol=1e-13), (fn, k)
            assert np.allclose(got[2 * k + 1], w.der[..., 0], rtol=1e-11, atol=1e-12), (fn, k)


def test_unknown_path_is_refused_by_name():
    with pytest.raises(ValueError, match="path 'gpu'"):
        kinetostat.sensitivity(kinetostat.load(CHAIN), ["r"], steps=8, path="gpu")


@pytest.mark.slow   # compiles its kernels (minutes on a busy 2-core machine, once per machine)
@pytest.mark.parametrize("path, params", [(CHAIN, ["r", "l", "m2"]), (ICE, ["l_OA", "p_max", "G2"])],
                         ids=["chain_unit_four_bar", "ice_crank_slider"])
def test_compiled_and_numpy_paths_agree(path, params):
    """path='compiled' (the ICE: its gas diagram on the motion kernel's duals between the two
    passes) gives the numpy path's derivatives to 1e-12 of each output's largest, and its nominal
    analysis (the compiled one, `fast.analyze_fast`) the numpy path's."""
    mech = kinetostat.load(path)
    a = kinetostat.sensitivity(mech, params, steps=360, path="numpy")
    b = kinetostat.sensitivity(mech, params, steps=360, path="compiled")
    for x, y in ((a.result.balancing_moment, b.result.balancing_moment), (a.result.forces.R, b.result.forces.R)):
        assert np.max(np.abs(x - y)) <= 1e-12 * np.max(np.abs(x))
    for name, _, acc in outputs(mech, mech.point_names[-1]):
        for p in params:
            x, y = acc(a)[p], acc(b)[p]
            assert np.nanmax(np.abs(x - y)) <= 1e-12 * np.nanmax(np.abs(x)), (name, p)


@pytest.mark.slow   # compiles two kernels (minutes on a busy 2-core machine, once per machine)
def test_five_parameters_run_in_two_passes_and_agree():
    """The chain unit's sensitivities to 5 parameters (the benchmark's) run in two compiled passes
    of 3 and 2 tangents (`fast_sensitivity.PASS`) and agree with the numpy path to 1e-12."""
    from kinetostat import fast_sensitivity
    mech = kinetostat.load(CHAIN)
    params = CHAIN_ALL[:5]
    a = kinetostat.sensitivity(mech, params, steps=360, path="numpy")
    b = kinetostat.sensitivity(mech, params, steps=360, path="compiled")
    assert len(fast_sensitivity.kernels(mech, 5)) == 2
    for name, _, acc in outputs(mech, mech.point_names[-1]):
        for p in params:
            x, y = acc(a)[p], acc(b)[p]
            assert np.nanmax(np.abs(x - y)) <= 1e-12 * np.nanmax(np.abs(x)), (name, p)


def _python_kernel(mech, p, kind, live, qs):
    """`fast_sensitivity`'s kernel run as Python (numba's njit the identity): its generated
    source checked at a few angles without a compile, and not kept among the compiled kernels."""
    import sys
    import types

    import numba
    from kinetostat import fast, fast_sensitivity
    fake = types.ModuleType("numba")
    fake.njit = lambda *a, **k: (lambda f: f)
    scope: dict = {}
    saved = numba                     # restored after (also where nothing had imported it yet)
    sys.modules["numba"] = fake
    try:
        exec(compile(fast._module(fast_sensitivity._source(mech, p, kind, live, qs)), "<kernel>", "exec"), scope)
    finally:
        sys.modules["numba"] = saved
    return scope["kernel"]


@pytest.mark.parametrize("path, params, passes", [(CHAIN, ["r", "l", "m2"], 3), (ICE, ["l_OA", "p_max", "G2"], 3),
                                                  (CHAIN, ["r", "l", "m2"], 2), (ICE, ["G2", "l_OA", "p_max"], 2)],
                         ids=["chain_unit_four_bar", "ice_crank_slider", "chain_unit_two_passes", "ice_two_passes"])
def test_one_pass_kernel_source_gives_the_numpy_derivatives(path, params, passes, monkeypatch):
    """The compiled path's kernel source (the analysis and the tangents in one pass, each tangent
    only where its parameter reaches: m2 reaches the statics only, p_max the gas load only), run
    as Python at 6 angles, gives the numpy path's nominal analysis and derivatives to 1e-12: a
    step whose value overwrites an argument (carry) has its tangents from the argument's old value.
    With PASS 2 the three tangents go in two passes (2 + 1), each writing its own rows (the ICE's
    second, p_max, reading its loads' tangents)."""
    from kinetostat import fast_sensitivity
    monkeypatch.setattr(fast_sensitivity, "_kernel", _python_kernel)
    monkeypatch.setattr(fast_sensitivity, "PASS", passes)
    mech = kinetostat.load(path)
    phi = np.array([5.0, 63.0, 131.0, 199.0, 262.0, 331.0])
    a = kinetostat.sensitivity(mech, params, phi_deg=phi, path="numpy")
    b = kinetostat.sensitivity(mech, params, phi_deg=phi, path="compiled")
    for x, y in ((a.result.balancing_moment, b.result.balancing_moment), (a.result.forces.R, b.result.forces.R)):
        assert np.max(np.abs(x - y)) <= 1e-12 * np.max(np.abs(x))
    for name, _, acc in outputs(mech, mech.point_names[-1]):
        for p in params:
            x, y = acc(a)[p], acc(b)[p]
            assert np.max(np.abs(x - y)) <= 1e-12 * np.max(np.abs(x)) + 1e-300, (name, p)


def test_auto_path_does_not_compile_for_few_angles():
    """path='auto' at 360 angles (below fast.FAST_MIN) takes the numpy path: the same numbers as path='numpy'."""
    from kinetostat import fast_sensitivity
    mech = kinetostat.load(CHAIN)
    assert not fast_sensitivity.pays(mech, 360, {}, 2) and not fast_sensitivity.pays(mech, 20_000, {}, 7)
    a, b = (kinetostat.sensitivity(mech, ["r", "m2"], steps=360, path=p) for p in ("auto", "numpy"))
    assert np.array_equal(a.balancing_moment["r"], b.balancing_moment["r"])


def test_dual_motion_builds_only_the_columns_read():
    """The loads' dual motion (`_dual_motion`) gives column k of a kinematic output as the
    environment's dual (the frame's rest value before `start`) and refuses any other read."""
    from kinetostat.sensitivity import Dual, _dual_motion
    mech = kinetostat.load(ICE)
    N, P = 4, 2
    O2 = Dual(np.arange(N) + 1j, np.ones((N, P)))
    kin = _dual_motion(mech, {"O2": O2, "w1": 3.0}, [{}] * mech.n_links, np.zeros(N), P)
    assert np.array_equal(kin.origin_z[:, 2].val, O2.val) and np.array_equal(kin.origin_z[:, 2].der, O2.der)
    assert np.array_equal(kin.rot[:, 0].val, np.ones(N)) and not kin.rot[:, 0].der.any()
    assert np.array_equal(kin.omega[:, 1].val, np.full(N, 3.0)) and kin.omega[:, 1].der.shape == (N, P)
    with pytest.raises(TypeError, match=r"motion.s O is read by column"):
        kin.origin_z[0]
