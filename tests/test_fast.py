"""The compiled path (kinetostat.fast) against the numpy path: both run the same group
equations (kinetostat.groups), one per angle inside a numba kernel, the other over arrays; they
must agree to 1e-13 of each quantity's peak. A sample runs by default (each new structure costs
a few seconds of compilation, once per session: the kernels' cache is the session's folder);
every bundled model, full result and peaks, with -m slow."""
from __future__ import annotations

import os
import subprocess
import sys
import warnings

import numpy as np
import pytest

import kinetostat
from kinetostat import fast
from kinetostat.analysis import crank_angles, exact

TOL = 1e-13


def _close(a, b, floor: float = 0.0) -> float:
    """max |a - b| over the peak of |b| or `floor` (NaN where b is NaN must be NaN in a too)."""
    a, b = np.asarray(a), np.asarray(b)
    assert np.array_equal(np.isnan(a), np.isnan(b))
    ok = np.isfinite(b)
    peak = max(np.max(np.abs(b[ok]), initial=0.0), floor)
    return float(np.max(np.abs(a[ok] - b[ok]), initial=0.0) / peak) if peak else float(np.max(np.abs(a[ok]), initial=0.0))


def _agree(mech, phi_deg) -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        a = fast.analyze_fast(mech, crank_angles(phi_deg))
        b = exact(mech, crank_angles(phi_deg))
    force = np.nanmax(np.abs(b.forces.R))          # a quantity that is rounding only (the moment of a
    moment = force * mech.size                     # piston's reaction about its pin) against its kind's scale
    floors = {"normal": force, "F_bal": force, "m": moment, "M_bal": moment, "lever": moment}
    # the condition number is a diagnostic, not a result: near a toggle |det| is itself a difference
    # of nearly equal products, so its rounding is amplified (6.7e-13 of the peak on the furnace loader)
    tolerance = {"cond": 1e-10}
    for name, x, y in [("R", a.forces.R, b.forces.R), ("M_bal", a.balancing_moment, b.balancing_moment),
                       ("F_bal", a.forces.F_bal, b.forces.F_bal), ("lever", a.lever_moment, b.lever_moment),
                       ("normal", a.forces.normal, b.forces.normal), ("m", a.forces.m, b.forces.m),
                       ("omega", a.kin.omega, b.kin.omega), ("eps", a.kin.eps, b.kin.eps),
                       ("origin", a.kin.origin, b.kin.origin), ("v", a.kin.v_origin, b.kin.v_origin),
                       ("a", a.kin.a_origin, b.kin.a_origin), ("rot", a.kin.rot, b.kin.rot),
                       ("v_slide", a.kin.v_slide, b.kin.v_slide), ("a_slide", a.kin.a_slide, b.kin.a_slide),
                       ("cond", a.cond, b.cond), ("F_i", a.F_i, b.F_i), ("M_i", a.M_i, b.M_i),
                       ("F_applied", a.F_applied, b.F_applied), ("M_applied", a.M_applied, b.M_applied),
                       ("friction", a.friction_power, b.friction_power)]:
        assert _close(x, y, floors.get(name, 0.0)) < tolerance.get(name, TOL), (mech.name, name, _close(x, y, floors.get(name, 0.0)))
    assert np.array_equal(a.singular, b.singular)
    np.testing.assert_allclose(a.error, b.error, rtol=1e-6)


SAMPLE = ["chain_unit_four_bar"]      # the structure most other tests here compile anyway


@pytest.mark.parametrize("name", SAMPLE)
def test_both_paths_agree_on_a_sample_of_the_bundled_models(name):
    _agree(kinetostat.load(name), np.arange(0.0, 360.0, 0.5))


def _peaks_agree(mech, phi_deg) -> None:
    """fast.peaks (the peaks kernel) against the numpy path's largest |R|, |M_bal|, |F_bal|
    over the angles that are not singular: to 1e-13 of each."""
    pk = fast.peaks([mech], phi_deg)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = exact(mech, crank_angles(phi_deg))
    ok = ~res.singular
    for got, want in [(pk.R[0], np.linalg.norm(res.forces.R[ok], axis=-1).max(axis=0)),
                      (pk.M_bal[0], np.abs(res.balancing_moment[ok]).max()),
                      (pk.F_bal[0], np.linalg.norm(res.forces.F_bal[ok], axis=-1).max())]:
        np.testing.assert_allclose(got, want, rtol=TOL, atol=TOL * np.max(want))
    np.testing.assert_array_equal(pk.singular_deg[0], res.phi_deg[res.singular])


def _refused(mech) -> bool:
    """A model the compiled path refuses by name (a class-III group): both kernels say so."""
    if fast.refusal(mech) is None:
        return False
    for call in (lambda: fast.analyze_fast(mech, crank_angles([0.0])), lambda: fast.peaks([mech], [0.0])):
        with pytest.raises(NotImplementedError, match=r"compiled path does not take class-III groups \(III\("):
            call()
    return True


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(set(kinetostat.examples.names()) - set(SAMPLE)))
def test_both_paths_agree_on_every_bundled_model(name):
    """Every model the compiled path takes agrees with the numpy path; a triad model is refused by name."""
    mech = kinetostat.load(name)
    if not _refused(mech):
        _agree(mech, np.arange(0.0, 360.0, 0.5))


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(kinetostat.examples.names()))
def test_peaks_agree_on_every_bundled_model(name):
    """Every model's sweep takes the peaks kernel: the loads besides gravity (the ICE's gas
    diagram, the furnace loader's springs ...) evaluated per chunk between two passes; a triad
    model is refused by name (its sweep takes the numpy path)."""
    mech = kinetostat.load(name)
    if not _refused(mech):
        _peaks_agree(mech, np.arange(0.0, 360.0, 0.25))


#: Loads besides gravity and inertia on the four-bar of SAMPLE: a table of a force against the
#: angle, a resistance against the velocity, a spring and a damper. Its kernels are the four-bar's
#: (the loads enter per chunk, between the motion kernel and the statics kernel), so the test
#: compiles nothing the suite does not compile anyway.
LOADS = """
[[load]]
name = "a table force"
link = 3
point = "B"
direction = [0.0, -1.0]
[load.table]
phi_deg = [0, 90, 180, 270, 360]
value = [0.0, 300.0, 50.0, -120.0, 0.0]
[[load]]
name = "a resistance"
link = 2
point = "C2"
direction = "against_velocity"
value = 150.0
[[spring]]
name = "a spring"
a = { link = 0, point = "O2" }
b = { link = 2, point = "A" }
stiffness = 2000.0
free_length = 0.3
"""


def test_both_paths_agree_with_loads_in_the_kernel():
    """The loads-in-kernel path (tables, a resistance, a spring) on the four-bar: every array and
    the peaks to 1e-13 of the numpy path; the same kernels as the four-bar's without loads."""
    base = kinetostat.load(SAMPLE[0])
    mech = kinetostat.loads(kinetostat.examples.path(SAMPLE[0]).read_text(encoding="utf-8") + LOADS)
    assert fast._has_loads(mech) and not fast._has_loads(base)
    assert all(fast._source(mech, fast._layout(mech), k) == fast._source(base, fast._layout(base), k)
               for k in ("full", "peaks"))
    phi = np.arange(0.0, 360.0, 0.5)
    M, M0 = (exact(m, crank_angles(phi)).balancing_moment for m in (mech, base))
    assert np.max(np.abs(M - M0)) > 0.1 * np.max(np.abs(M0))      # the loads change the answer
    _agree(mech, phi)
    _peaks_agree(mech, phi)


def test_a_triad_is_refused_by_name_by_both_kernels():
    assert _refused(kinetostat.load("triad_slider"))


def _four_bar(rng) -> kinetostat.Mechanism:
    """A random Grashof crank-rocker with random masses, speed and acceleration."""
    r, l, h, b = 0.05 + 0.05 * rng.random(), 0.3 + 0.2 * rng.random(), 0.3 + 0.2 * rng.random(), 0.4 + 0.1 * rng.random()
    text = f"""
[mechanism]
name = "random four-bar"
g = 9.81
[drive]
link = 1
pivot = "O1"
point = "A"
reference = [1.0, 0.0]
sense = "ccw"
kind = "engine"
rpm = {50 + 400 * rng.random()}
eps = {50 * rng.standard_normal()}
[frame]
O1 = [0.0, 0.0]
O2 = [{b}, {0.1 * rng.standard_normal()}]
[[link]]
id = 1
points = {{ O1 = [0.0, 0.0], A = [{r}, 0.0], S1 = [{r / 3}, 0.0] }}
com = "S1"
mass = {rng.random()}
I_S = {0.01 * rng.random()}
[[link]]
id = 2
points = {{ A = [0.0, 0.0], B = [{l}, 0.0], S2 = [{l / 2}, {0.02 * rng.standard_normal()}] }}
mass = {1 + rng.random()}
I_S = {0.05 * rng.random()}
com = "S2"
[[link]]
id = 3
points = {{ O2 = [0.0, 0.0], B = [{h}, 0.0], S3 = [{h / 2}, 0.0] }}
mass = {1 + rng.random()}
I_S = {0.05 * rng.random()}
com = "S3"
[[pair]]
kind = "R"
links = [0, 1]
point = "O1"
[[pair]]
kind = "R"
links = [1, 2]
point = "A"
[[pair]]
kind = "R"
links = [2, 3]
point = "B"
[[pair]]
kind = "R"
links = [0, 3]
point = "O2"
[[group]]
links = [2, 3]
branch = {rng.choice([-1, 1])}
"""
    return kinetostat.loads(text)


@pytest.mark.parametrize("seed", range(4))
def test_both_paths_agree_on_random_four_bars(seed):
    _agree(_four_bar(np.random.default_rng(seed)), np.random.default_rng(seed).uniform(0, 360, 2000))


def test_peaks_of_a_batch_of_designs_equal_a_loop_of_analyze():
    """One kernel call over 6 random designs x 720 angles keeps each design's largest |R| and
    |M_bal|: the same as the numpy path design by design."""
    mechs = [_four_bar(np.random.default_rng(10 + d)) for d in range(6)]
    phi = np.arange(0.0, 360.0, 0.5)
    pk = fast.peaks(mechs, phi, threads=2)
    for d, m in enumerate(mechs):
        res = exact(m, crank_angles(phi))
        R = np.linalg.norm(res.forces.R, axis=-1).max(axis=0)
        np.testing.assert_allclose(pk.R[d], R, rtol=TOL, atol=0)
        assert abs(pk.M_bal[d] - np.abs(res.balancing_moment).max()) <= TOL * np.abs(res.balancing_moment).max()


def test_analyze_takes_the_compiled_path_where_it_pays_and_gives_the_same(monkeypatch):
    """FAST_MIN angles take the compiled path where this process holds the kernel, the numpy
    path where the call would load it (below FAST_COLD); the same results to 1e-13."""
    m = kinetostat.load("chain_unit_four_bar")
    fast.kernel(m, "full")
    calls = []
    compiled = fast.analyze_fast
    monkeypatch.setattr(fast, "analyze_fast", lambda mech, phi, **kw: calls.append(len(phi)) or compiled(mech, phi, **kw))
    assert fast.loaded(m) and fast.threshold(m) == fast.FAST_MIN < fast.FAST_COLD
    big = kinetostat.analyze(m, steps=fast.FAST_MIN)
    ref = exact(m, crank_angles(None, fast.FAST_MIN))
    assert _close(big.forces.R, ref.forces.R) < TOL and _close(big.balancing_moment, ref.balancing_moment) < TOL
    kinetostat.analyze(m, steps=fast.FAST_MIN - 1)
    assert calls == [fast.FAST_MIN]                      # below FAST_MIN: the numpy path
    monkeypatch.setattr(fast, "_KERNELS", {})             # a process that has not loaded it
    assert not fast.loaded(m) and fast.threshold(m) == fast.FAST_COLD
    kinetostat.analyze(m, steps=fast.FAST_MIN)
    assert calls == [fast.FAST_MIN]


def test_the_guard_angles_are_the_numpy_paths():
    """Angles with cond > COND_CHECK are solved again by the numpy path with its accuracy check:
    a four-bar passing near its toggle gets the same errors, singular flags and warnings."""
    m = kinetostat.load("chain_unit_four_bar")
    phi = np.concatenate([np.arange(0.0, 360.0, 1.0)])
    with warnings.catch_warnings(record=True) as w1:
        warnings.simplefilter("always")
        a = fast.analyze_fast(m, crank_angles(phi))
    with warnings.catch_warnings(record=True) as w2:
        warnings.simplefilter("always")
        b = exact(m, crank_angles(phi))
    assert [str(x.message) for x in w1] == [str(x.message) for x in w2]
    np.testing.assert_array_equal(a.singular, b.singular)


def test_chunks_and_out_give_the_same_analysis_in_reused_memory():
    """`chunks` hands out read-only Analyses of `size` angles, views of one reused buffer, equal
    to `analyze_fast` of the whole run; `out=` writes into the caller's buffer."""
    m = kinetostat.load("chain_unit_four_bar")
    phi = crank_angles(np.arange(0.0, 360.0, 0.3))
    whole = fast.analyze_fast(m, phi)
    bases, start = set(), 0
    for part in fast.chunks(m, phi, size=400):
        n = len(part.phi_deg)
        assert not part.forces.R.flags.writeable and not part.kin.rot.flags.writeable
        np.testing.assert_array_equal(part.forces.R, whole.forces.R[start:start + n])
        np.testing.assert_array_equal(part.kin.a_z, whole.kin.a_z[start:start + n])
        bases.add(part.forces.R.base.__array_interface__["data"][0])
        start += n
    assert start == len(phi) and len(bases) == 1            # 3 chunks, one buffer
    out = fast.buffer(m, len(phi))
    again = fast.analyze_fast(m, phi, out=out)
    assert np.shares_memory(again.forces.R, out) and np.shares_memory(again.balancing_moment, out)
    np.testing.assert_array_equal(again.balancing_moment, whole.balancing_moment)
    with pytest.raises(ValueError, match="out: a writeable contiguous float64 buffer of"):
        fast.analyze_fast(m, phi, out=np.zeros(10))


@pytest.mark.slow
def test_the_kernel_vectorises(tmp_path, monkeypatch):
    """LLVM vectorised the kernel's loop: its assembly holds packed double arithmetic (and
    the full kernel does as well as the peaks one). A kernel loaded from the cache keeps no
    assembly, so this compiles both afresh in an empty cache (about 15 s of CPU: slow)."""
    monkeypatch.setenv(fast.CACHE_ENV, str(tmp_path))
    monkeypatch.setattr(fast, "_KERNELS", {})     # not the kernels this process loaded before
    m = kinetostat.load("chain_unit_four_bar")
    for kind in ("peaks", "full"):
        fast.kernel(m, kind)[0](*_args(m, kind))
        counts = fast.vector_report(fast.kernel(m, kind)[0])
        assert counts["packed_ymm"] + counts["packed_zmm"] > 300, (kind, counts)


def _args(m, kind):
    """The arguments of one kernel call over 3 angles (the kernel compiled or loaded by it)."""
    lay = fast._layout(m)
    phi = np.radians([0.0, 1.0, 2.0])
    W, E = fast._speeds([m], phi)
    bd, b0, bn = fast._blocks(1, 0, 3)
    return (phi, W, E, fast._table([m], lay), fast._NO_LOADS, bd, b0, bn, np.uint64(3), np.zeros(3, bool),
            fast.buffer(m, 3), np.empty(fast._scratch_rows(lay) * fast.BLOCK), np.zeros((1, lay.P + 2)))


def test_a_later_process_loads_the_kernel_from_the_cache(kernel_cache):
    """The generated module lies in the cache folder under its source's hash, and a new process
    takes the compiled kernel from numba's cache: one hit, no compilation."""
    m = kinetostat.load("chain_unit_four_bar")
    fast.kernel(m, "full")[0](*_args(m, "full"))
    assert any(p.suffix == ".py" for p in kernel_cache.iterdir())
    script = ("import kinetostat, numpy as np; from kinetostat import fast; import test_fast as t; "
              "m = kinetostat.load('chain_unit_four_bar'); fn = fast.kernel(m, 'full')[0]; fn(*t._args(m, 'full')); "
              "print(sum(fn.stats.cache_hits.values()), sum(fn.stats.cache_misses.values()), len(fn.overloads))")
    env = dict(os.environ, KINETOSTAT_CACHE=str(kernel_cache), PYTHONPATH=os.path.dirname(__file__))
    out = subprocess.run([sys.executable, "-c", script], env=env, capture_output=True, text=True, check=True)
    hits, misses, overloads = out.stdout.split()[-3:]
    assert (hits, misses, overloads) == ("1", "0", "1")


@pytest.fixture(scope="module")
def primitives():
    """fast.cis and fast.phase compiled as the kernel compiles them, once for the module."""
    import numba
    return numba.njit(fast.cis), numba.njit(fast.phase)


@pytest.mark.parametrize("scale", [1e-3, 1.0, 30.0, 1e5])
def test_the_compiled_primitives_are_numpys_to_an_ulp(scale, primitives):
    """cis (polynomial sincos) and phase (polynomial atan2) against numpy's exp and arctan2,
    compiled as the kernel compiles them; NaN stays NaN; phase(0) = 0 as arctan2(0, 0)."""
    cis, phase = primitives
    rng = np.random.default_rng(int(scale * 7))
    th = scale * rng.standard_normal(2000)
    got = np.array([cis(t) for t in th])
    assert np.max(np.abs(got - np.exp(1j * th))) <= 2.5e-16 * max(1.0, scale * 1e-3)
    z = scale * (rng.standard_normal(2000) + 1j * rng.standard_normal(2000))
    z[:4] = [1.0, -1.0, 1j, -1j]
    assert np.max(np.abs(np.array([phase(w) for w in z]) - np.angle(z))) <= 4.5e-16
    assert phase(0j) == 0.0 and np.isnan(phase(complex(np.nan, 1.0))) and np.isnan(cis(np.nan).real)


DIVIDING = '''
def kernel(T, O, n):
    for i in range(n):
        u, w = complex(T[i], T[n + i]), complex(T[2 * n + i], T[3 * n + i])
        v, x = complex(T[4 * n + i], T[5 * n + i]), complex(T[6 * n + i], T[7 * n + i])
        det, r = T[8 * n + i], T[9 * n + i]
        a, b = solve2(u, w, det, v)
        c, d = solve2(u, w, det, x)
        q, s = over(v, r), ratio(v, w)
        O[i] = a + b + c + d + q.real + q.imag + s.real + s.imag + phase(x)
'''


def test_the_compiled_closed_forms_take_one_reciprocal_per_denominator():
    """Two solve2 on one det, z / r, z / w and atan2 in a kernel's vectorised loop (the kernel's
    own module, uncached): one division per denominator (det, r, |w|^2, the octant's), 4 an angle."""
    from kinetostat_validation.kernels import count_program
    ns: dict = {}
    exec(fast._module(DIVIDING).replace("cache=True", "cache=False"), ns)
    n = 64
    ns["kernel"](np.ones(10 * n), np.empty(n), n)
    assert count_program("\n".join(ns["kernel"].inspect_llvm().values())).div == 4
