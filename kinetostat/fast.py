"""The compiled path: a mechanism's programs (`kinetostat.program`, calls of the group equations
of `kinetostat.groups`, the numpy path's very source) generated into numba kernels that fuse,
per angle, the kinematics, the loads, the reactions of every group and the balancing moment.

- `analyze_fast(mech, phi_deg, out=None)`: the whole `Analysis`, as `kinetostat.analyze`
  gives it (which calls it from `threshold(mech)` angles on: FAST_MIN where this process holds the
  kernel, FAST_COLD where the call would load it), its arrays views of one flat buffer
  (`buffer`: pass one as `out` to reuse caller-owned memory across calls).
- `chunks(mech, phi_deg, size)`: the same, as read-only Analyses of `size` angles in turn,
  each a view of one buffer reused from chunk to chunk (valid until the next is asked for).
- `peaks(mechs, phi_deg)`: what a sweep keeps of each design: the largest |R| of every pair,
  |M_bal| and |F_bal| over the cycle, and the angles that need the exact guard.
- `analyses(mechs, phi_deg)`: `analyze_fast` of many designs, those of one structure a batch at a
  time in one kernel call (a Monte Carlo study's designs).
- `refusal(mech)`: why a mechanism is not taken (a class-III group), None where it is; the
  four above raise NotImplementedError with it, and `analyze` and the sweeps use the numpy path.
- `Splice`: what another kernel of the same layout adds to the analysis kernel's source
  (`fast_sensitivity`'s tangents, written in the same pass).

The kernel: the five primitives of `groups` (|z|, complex / real, complex / complex, e^{i th},
atan2) bound to branch-free versions (sincos and atan by polynomials, a division as one
reciprocal multiplied part by part, atan2 with one division); an outer loop over blocks of BLOCK
angles (one design each), an inner loop with an unsigned index from 0, the guard a boolean value,
each per-angle output stored at a compile-time row of one flat buffer (row-major: rows of
angles), peaks as per-block maxima of squares. LLVM
vectorises that inner loop (`vector_report` counts the packed instructions). No fast-math:
every operation keeps IEEE semantics, so a NaN or inf that enters propagates (a non-finite peak
flags the angle, below). The primitives agree with numpy's operators to rounding on finite values of
1e-154 < |z| < 1e154, where x^2 + y^2 neither overflows nor underflows; at the edges they differ:
|z| and complex / complex overflow or underflow outside that range (|1e155| is inf,
(1+1j)/(1e155+1e155j) is 0), |inf + nan j| is nan (numpy: inf), phase(inf + inf j) is nan
(numpy: pi/4), (1+1j)/(inf+0j) is nan (numpy: 0), and cis reduces its angle exactly only to
|th| ~ 1e6 rad. The generated module is written to a cache folder (`cache_dir`) under the hash
of its source and compiled with numba's disk cache: compiled once per machine. What of that
folder is trusted, and how, is `kernel_cache`'s.

Angles where a group's plan is ill-conditioned (cond > COND_CHECK), cannot be assembled, or
give a non-finite peak, are flagged by the kernel and solved again by the numpy path with its
accuracy guard. Loads other than gravity and inertia (tables, diagrams, springs, dampers, laws
of motion) are evaluated by `applied.applied_wrenches` per chunk of CHUNK angles, on the motion
a first pass of the motion kernel (the kinematics only) wrote, and read by the full or the
peaks kernel.

May use: numpy, numba, kernel_cache (the kernels' folder), program, groups, kinematics, kinetostatics, applied, planar, analysis (the
result and the numpy path), model and structure (for type hints).
"""
from __future__ import annotations

import inspect
import math
import os
import re
import threading
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Callable, Iterator, Sequence

import numpy as np

from . import groups, kernel_cache
from .analysis import Analysis, _read_only, exact
from .applied import applied_wrenches
from .kernel_cache import CACHE_ENV, cache_dir
from .kinematics import COND_CHECK, DIGITS_WARN, Kinematics, a_priori_error
from .kinetostatics import Forces, friction_power, lever_moment
from .planar import as_xy
from .program import Identifiers, Program, code, constants, free_names, motion_program, statics_program

if TYPE_CHECKING:
    from .model import Mechanism

__all__ = ["analyze_fast", "analyses", "chunks", "buffer", "peaks", "Peaks", "FAST_MIN", "FAST_COLD", "CHUNK", "BLOCK", "available",
           "cache_dir", "kernel", "loaded", "threshold", "pays", "vector_report", "bytes_per_angle"]

#: From this many positions (designs x angles) on, `kinetostat.analyze` and sweeps take the
#: compiled path where this process holds the kernel already (`threshold`). Measured
#: (reports/benchmark.md, "Where the compiled path pays"): the loaded kernel is the faster at
#: every size from 100 angles on the four-bar (3.3x at 10^4) and the six-link (1.7x); on the ICE
#: (its gas diagram evaluated per chunk) from 3,000 (1.4x at 10^4, even at 10^5; an earlier run
#: had it 0.9x at 10^5).
FAST_MIN = 10_000
#: ... and from this many where the call would load the kernel: its load from the disk cache
#: (about 0.14 s of CPU, numba's import included; a first compile per machine takes seconds) is
#: repaid within the call from about 1.2e5 positions (the six-link) to 8.4e5 (the four-bar; on
#: the ICE hardly ever; the same section).
FAST_COLD = 500_000
#: Angles per chunk: `chunks`' default size, and the run of angles whose loads are evaluated at once.
CHUNK = 1 << 14
#: Angles per block of the kernel's loop (not a multiple of 512: 4 KiB aliasing of the rows in L1).
BLOCK = 264
#: Designs per call of the full kernel in `analyses` (its guard flags take D^2 N bools).
BATCH = 32
#: Threads the kernel runs on (one per core by default).
THREADS = os.cpu_count() or 1


def available() -> bool:
    """Is numba importable (the compiled path)?"""
    try:
        import numba  # noqa: F401
    except ImportError:       # pragma: no cover - numba is a dependency
        return False
    return True


# ----------------------------------------------------------------------------- the compiled primitives
# Branch-free versions of groups' five primitives, compiled into the kernel in their place (their
# source is copied into the generated module: they hold their constants as literals).

def magnitude(z):
    """|z| as sqrt(x^2 + y^2) (no hypot call: it has no vector version)."""
    return math.sqrt(z.real * z.real + z.imag * z.imag)


def over(z, r):
    """z / r as z times one reciprocal of r, part by part (numba promotes complex / real to
    complex / complex)."""
    k = 1.0 / r
    return complex(z.real * k, z.imag * k)


def ratio(z, w):
    """z / w as z conj(w) times one reciprocal of |w|^2 (numba's complex division has branches)."""
    k = 1.0 / (w.real * w.real + w.imag * w.imag)
    return complex((z.real * w.real + z.imag * w.imag) * k, (z.imag * w.real - z.real * w.imag) * k)


def cis(th):
    """e^{i th} by fdlibm's sin and cos kernels on th reduced to [-pi/4, pi/4] (Cody-Waite,
    three parts of pi/2: exact reduction to |th| ~ 1e6 rad), the quadrant by selects."""
    k = math.floor(th * 0.6366197723675814 + 0.5)
    r = ((th - k * 1.5707963267341256) - k * 6.077100506303966e-11) - k * 2.0222662487111665e-21
    z = r * r
    s = r + r * z * (-1.66666666666666324348e-01 + z * (8.33333333332248946124e-03 + z * (
        -1.98412698298579493134e-04 + z * (2.75573137070700676789e-06 + z * (
            -2.50507602534068634195e-08 + z * 1.58969099521155010221e-10)))))
    c = 1.0 - 0.5 * z + z * z * (4.16666666666666019037e-02 + z * (-1.38888888888741095749e-03 + z * (
        2.48015872894767294178e-05 + z * (-2.75573143513906633035e-07 + z * (
            2.08757232129817482790e-09 + z * -1.13596475577881948265e-11)))))
    q = k - 4.0 * math.floor(k * 0.25)            # the quadrant, 0..3
    odd = (q == 1.0) | (q == 3.0)
    cs = s if odd else c
    sn = c if odd else s
    return complex(-cs if (q == 1.0) | (q == 2.0) else cs, -sn if q >= 2.0 else sn)


def phase(x):
    """atan2(Im x, Re x): atan of a = min/max of |x|, |y| by fdlibm's polynomial on
    [-tan(pi/8), tan(pi/8)] (atan a = pi/4 + atan((min - max)/(min + max)) above), octant by
    selects; one division."""
    X, Y = x.real, x.imag
    ax, ay = abs(X), abs(Y)
    mx = ay if ay > ax else ax
    mn = ax if ay > ax else ay
    big = mn > 0.41421356237309503 * mx
    t = (mn - mx if big else mn) / (mn + mx if big else (mx if mx > 0.0 else 1.0))
    z = t * t
    p = t - t * z * (3.33333333333329318027e-01 + z * (-1.99999999998764832476e-01 + z * (
        1.42857142725034663711e-01 + z * (-1.11111104054623557880e-01 + z * (
            9.09088713343650656196e-02 + z * (-7.69187620504482999495e-02 + z * (
                6.66107313738753120669e-02 + z * (-5.83357013379057348645e-02 + z * (
                    4.97687799461593236017e-02 + z * (-3.65315727442169155270e-02 + z * 1.62858201153657823623e-02))))))))))
    r = p + 0.7853981633974483 if big else p
    r = 1.5707963267948966 - r if ay > ax else r
    r = 3.141592653589793 - r if math.copysign(1.0, X) < 0.0 else r
    r = math.copysign(r, Y)
    return r if (X == X) & (Y == Y) else X + Y


PRIMITIVES = (magnitude, over, ratio, cis, phase)


# ----------------------------------------------------------------------------- the layout
_LOCK = threading.Lock()
_KERNELS: dict[tuple, Any] = {}

#: The Analysis' arrays in the flat buffer, real and complex, in order ("friction" and "error"
#: are filled by numpy after the kernel).
REAL = ("th", "w", "e", "vs", "as", "cond", "M_app", "M_i", "normal", "m", "M_bal", "lever", "friction", "error")
COMPLEX = ("rot", "O", "V", "A", "F_app", "F_i", "R", "F_bal")
#: The arrays the "motion" kernel writes: the kinematics and the groups' condition numbers.
MOTION = ("th", "w", "e", "vs", "as", "cond", "rot", "O", "V", "A")


def _has_loads(mech: "Mechanism") -> bool:
    """Does `mech` carry loads besides gravity and inertia (evaluated between two passes)?"""
    return bool(mech.loads or mech.springs)


@dataclass(frozen=True)
class _Layout:
    """What a kernel reads and writes: the base constants (in the order of the C columns), the
    moving links, the pairs and which are prismatic, the groups; `rows`: each array's first row
    in the flat buffer (a complex column takes two rows: its values interleaved) and its width."""
    consts: tuple[str, ...]
    real: tuple[bool, ...]
    L: int
    P: int
    prismatic: tuple[int, ...]
    slides: tuple[int, ...]
    G: int
    machine: bool
    rows: tuple[tuple[str, int, int], ...]
    n_rows: int

    def row(self, name: str) -> int:
        return next(r for n, r, _ in self.rows if n == name)


_GROUP_MOTION = ("rrr_motion", "rrp_motion", "rpr_motion", "prp_motion", "rpp_motion")


def _motion(mech: "Mechanism") -> Program:
    """`mech`'s kinematics program with each group's assembly branch read from the constant
    branch<n> instead of written in: one kernel serves every choice of branches."""
    def make() -> Program:
        steps = []
        groups_seen = 0
        for st in motion_program(mech).steps:
            if st.fn in _GROUP_MOTION:            # one per group, in the groups' order
                params = list(inspect.signature(getattr(groups, st.fn)).parameters)
                if "branch" in params:
                    args = list(st.args)
                    args[params.index("branch")] = f"branch{groups_seen}"
                    st = st._replace(args=tuple(args))
                groups_seen += 1
            steps.append(st)
        prog = motion_program(mech)
        return Program(tuple(steps), prog.inputs, prog.outputs)
    return mech.memo(("fast motion", _branches(mech)), make)


def _branches(mech: "Mechanism") -> tuple[int, ...]:
    return tuple(g.branch for g in mech.structure.groups)


def _constants(mech: "Mechanism") -> dict[str, Any]:
    """The base constants of `mech`'s kernels: `program.constants` and the branches (memoised)."""
    return mech.memo(("fast constants", id(mech.points_z), _branches(mech)), lambda: {
        **constants(mech), **{f"branch{n}": float(b) for n, b in enumerate(_branches(mech))}})


def refusal(mech: "Mechanism") -> str | None:
    """Why the compiled path does not take `mech`, None where it does: a class-III group (its
    positions are a continuation over the angle axis, not a closed form per angle)."""
    triads = [g.label for g in mech.structure.groups if g.klass == 3]
    return (f"the compiled path does not take class-III groups ({', '.join(triads)}): a triad's positions "
            f"are a continuation over the angle axis; the numpy path (kinetostat.analyze) solves it") if triads else None


def _layout(mech: "Mechanism") -> _Layout:
    """The layout of `mech`'s kernels and buffer (memoised per mechanism)."""
    return mech.memo(("fast layout", _branches(mech)), lambda: _make_layout(mech))


def _make_layout(mech: "Mechanism") -> _Layout:
    why = refusal(mech)
    if why:
        raise NotImplementedError(f"{mech.name}: {why}")
    motion, statics = _motion(mech), statics_program(mech)
    base = _constants(mech)
    consts = tuple(dict.fromkeys(n for n in free_names(motion) + free_names(statics) if n in base)) + tuple(
        f"{s}{k}" for k in range(1, mech.n_links) for s in ("com", "mass", "I_S")) + ("g",)
    consts = tuple(dict.fromkeys(consts))
    L, P, G = mech.n_links, len(mech.pairs), len(mech.structure.groups)
    width = lambda name: {"vs": P, "as": P, "normal": P, "m": P, "R": P, "friction": P, "cond": G,
                          "M_bal": 1, "lever": 1, "F_bal": 1, "error": 1}.get(name, L)
    rows, r = [], 0
    for name in REAL + COMPLEX:
        rows.append((name, r, width(name)))
        r += width(name) * (2 if name in COMPLEX else 1)
    return _Layout(consts, tuple(not isinstance(base[n], complex) for n in consts), L, P,
                   tuple(p.index for p in mech.pairs if p.kind == "P"),
                   tuple(sorted(int(o[2:]) for o in motion.outputs if o.startswith("vs"))), G,
                   mech.drive.kind == "machine", tuple(rows), r)


def bytes_per_angle(mech: "Mechanism") -> int:
    """Bytes the full kernel writes per angle into the flat buffer (the columns it fills: not the
    frame's, nor a revolute pair's normal force, nor an engine's F_bal) and its guard flag."""
    lay = _layout(mech)
    values = _value_map(lay, Identifiers().__getitem__)
    return 1 + sum(16 if name in COMPLEX else 8 for name, _ in values)


def _views(lay: _Layout, buf: np.ndarray, n: int) -> dict[str, np.ndarray]:
    """The arrays (n, width) of the flat buffer `buf` of n angles: views, the angle axis first."""
    out = {}
    for name, r, w in lay.rows:
        if name in COMPLEX:
            out[name] = buf[r * n:(r + 2 * w) * n].view(complex).reshape(w, n).T
        else:
            out[name] = buf[r * n:(r + w) * n].reshape(w, n).T
    return out


def buffer(mech: "Mechanism", n: int) -> np.ndarray:
    """A flat buffer for the Analysis of n angles of `mech` (zero): pass it as
    `analyze_fast(..., out=)` to reuse it. 8 x rows x n bytes."""
    return np.zeros(_layout(mech).n_rows * n)


# ----------------------------------------------------------------------------- code generation
def _value_map(lay: _Layout, v) -> dict[tuple[str, int], str]:
    """(array, column) -> the kernel's expression of its value at an angle, for every column the
    full kernel writes (the frame's, a revolute pair's normal force, an engine's F_bal: never)."""
    L = lay.L
    value = {}
    for s in ("th", "w", "e", "rot", "O", "V", "A"):
        value.update({(s, k): v(f"{s}{k}") for k in range(1, L)})
    value.update({(s, p): v(f"{s}{p}") for s in ("vs", "as") for p in lay.slides})
    value.update({("cond", n): v(f"cond{n}") for n in range(lay.G)})
    for k in range(1, L):
        value.update({("M_i", k): f"Mi{k}", ("F_i", k): f"Fi{k}", ("M_app", k): f"Ma{k}", ("F_app", k): f"Fa{k}"})
    value.update({("R", p): v(f"R{p}") for p in range(lay.P)})
    value.update({(s, p): v(f"{t}{p}") for s, t in (("normal", "N"), ("m", "m")) for p in lay.prismatic})
    value.update({("M_bal", 0): v("M_bal"), ("lever", 0): "lever"})
    if lay.machine:
        value[("F_bal", 0)] = v("F_bal")
    return value


def _scratch_rows(lay: _Layout) -> int:
    """Rows of BLOCK values in a thread's scratch: the speeds, the loads (a complex column in
    two rows), and every row the kernel may write or the squares it keeps."""
    return 2 + 3 * lay.L + lay.n_rows + lay.P + 2


def hoist(steps: tuple, consts) -> tuple[list, list]:
    """(the steps that read constants only, directly or through other such steps: run once per
    design before the loop over angles; the rest, in order). An assembly check is never hoisted."""
    fixed = set(consts)
    hoisted, moving = [], []
    for st in steps:
        if st.fn != "check" and all(not isinstance(a, str) or a in fixed for a in st.args):
            fixed.update(st.out)
            hoisted.append(st)
        else:
            moving.append(st)
    return hoisted, moving


@dataclass(frozen=True)
class Splice:
    """What another kernel of the same layout computes besides the analysis (`fast_sensitivity`'s
    tangents), spliced into `_source`'s, each given `var` (a program's name -> the kernel's
    identifier): `pro(var)`, lines after the constants are read; `steps(steps, var, check)`, the
    lines of program steps (in place of `program.code`'s); `link(k, var, row)`, the lines (before
    the loop, in it) after link k's wrench, `row()` giving the next scratch row; `stores(var)`,
    called after those: (expression, complex?, first row of S) written per angle after the
    analysis' arrays; `scratch`, the most scratch rows it takes besides `_scratch_rows`."""
    pro: Callable[[Callable[[str], str]], list[str]]
    steps: Callable[[Sequence, Callable[[str], str], Callable[[int, str, str], str]], list[str]]
    link: Callable[[int, Callable[[str], str], Callable[[], str]], tuple[list[str], list[str]]]
    stores: Callable[[Callable[[str], str]], Sequence[tuple[str, bool, int]]]
    scratch: int


def _store(t: Callable[[], str], val: str, is_complex: bool, first: int) -> tuple[list[str], list[str]]:
    """The loop's line(s) keeping the value `val` in the next scratch row(s) and the lines after
    the loop copying them to row `first` of S (a complex value interleaved in two rows)."""
    if is_complex:
        re_, im = t(), t()
        return ([f"T[{re_} + j] = {val}.real", f"T[{im} + j] = {val}.imag"],
                [f"c = U({first}) * n + i0 + i0", "for j in range(m):",
                 f"    S[c + j + j] = T[{re_} + j]", f"    S[c + j + j + U(1)] = T[{im} + j]"])
    tr = t()
    return [f"T[{tr} + j] = {val}"], [f"c = U({first}) * n + i0", "for j in range(m):", f"    S[c + j] = T[{tr} + j]"]


def _source(mech: "Mechanism", lay: _Layout, kind: str, splice: Splice | None = None) -> str:
    """The kernel's Python source (compiled by numba): the programs' steps inside a loop over
    blocks (design, first angle, count) and an unsigned loop over each block's angles that reads
    and writes the thread's scratch T only, at compile-time rows of BLOCK values (so LLVM sees
    no aliasing and vectorises it). Before it, the block's speeds and the loads besides gravity
    (X's rows, or zero where X is empty) are copied into T; after it, "full" copies every array
    of the result (a complex one interleaved) into the flat buffer S (rows of n angles);
    "peaks" keeps per block the largest |R| of each pair, |M_bal| and |F_bal| (PK) from the
    squares in T; "motion" runs the kinematics program only and copies its arrays (MOTION), the
    first pass of a mechanism whose loads depend on the motion. All flag in FL the angles the
    exact guard must see. `splice`: another kernel's additions (`Splice`)."""
    motion, statics = _motion(mech), statics_program(mech)
    v = Identifiers().__getitem__
    L, P = lay.L, lay.P
    row = iter(range(_scratch_rows(lay) + (splice.scratch if splice else 0)))
    t = lambda: f"U({next(row) * BLOCK})"          # the next scratch row
    head = ["def kernel(phi, W, E, C, X, bd, b0, bn, n, FL, S, T, PK):",
            "    for b in range(bd.shape[0]):",
            "        d = bd[b]",
            "        i0 = b0[b]",
            "        m = bn[b]",
            "        fl = d * n + i0"]
    pre, post = [], []
    speeds = []
    for X in "WE":          # the crank's speeds of the block, (D or 1, N or 1) broadcast
        tr = t()
        speeds.append(f"T[{tr} + j]")
        pre += [f"{X.lower()}d = d if {X}.shape[0] > 1 else U(0)", f"if {X}.shape[1] > 1:",
                "    for j in range(m):", f"        T[{tr} + j] = {X}[{X.lower()}d, i0 + j]",
                "else:", "    for j in range(m):", f"        T[{tr} + j] = {X}[{X.lower()}d, 0]"]
    pro = [f"{v(n)} = C[d, {j}]" + (".real" if real else "") for j, (n, real) in enumerate(zip(lay.consts, lay.real))]
    steps = (lambda sts, check: splice.steps(sts, v, check)) if splice else \
        lambda sts, check: code(Program(tuple(sts), (), ()), v, check)
    hoisted, moving = hoist(motion.steps + (() if kind == "motion" else statics.steps), lay.consts)
    pro += (splice.pro(v) if splice else []) + steps(hoisted, lambda *a: "")
    check = lambda i, disc, scale: f"ok &= {disc} >= -1e-12 * {scale}"
    in_motion = set(motion.steps)
    body = [f"{v('phi')} = phi[i0 + j]", f"{v('w_in')} = {speeds[0]}", f"{v('e_in')} = {speeds[1]}", "ok = True"]
    body += steps([st for st in moving if st in in_motion], check)
    body += [f"ok &= {v(f'cond{n}')} <= {COND_CHECK!r}" for n in range(lay.G)]
    first = {name: r for name, r, _ in lay.rows}
    for k in range(1, L if kind != "motion" else 1):
        body.append(f"r{k}, Fi{k}, Mi{k} = inertia({v(f'A{k}')}, {v(f'w{k}')}, {v(f'e{k}')}, {v(f'rot{k}')}, "
                    f"{v(f'com{k}')}, {v(f'mass{k}')}, {v(f'I_S{k}')})")
        f, g, h = t(), t(), t()       # the loads besides gravity: X's rows, or zero
        pre += ["if X.shape[0] > 0:", "    for j in range(m):", f"        T[{f} + j] = X[{3 * k - 3}, i0 + j]",
                f"        T[{g} + j] = X[{3 * k - 2}, i0 + j]", f"        T[{h} + j] = X[{3 * k - 1}, i0 + j]",
                "else:", "    for j in range(m):", f"        T[{f} + j] = 0.0", f"        T[{g} + j] = 0.0",
                f"        T[{h} + j] = 0.0"]
        body.append(f"Fa{k}, Ma{k} = weight(r{k}, {v(f'mass{k}')}, {v('g')})")
        body.append(f"Fa{k}, Ma{k} = Fa{k} + complex(T[{f} + j], T[{g} + j]), Ma{k} + T[{h} + j]")
        body.append(f"{v(f'F{k}')}, {v(f'M{k}')} = wrench(Fa{k}, Ma{k}, Fi{k}, Mi{k}, r{k})")
        if splice:
            more_pre, more = splice.link(k, v, t)
            pre, body = pre + more_pre, body + more
    if kind == "full":       # Zhukovsky's lever, before the groups change the known wrenches
        pw = " + ".join(f"power({v(f'F{k}')}, {v(f'M{k}')}, {v(f'V{k}')}, {v(f'w{k}')})" for k in range(1, L))
        body.append(f"lever = -({pw}) / {v('w1')}")
    if kind != "motion":
        body += steps([st for st in moving if st not in in_motion], check)
    if kind == "peaks":
        sq = [f"square({v(f'R{p}')}.real) + square({v(f'R{p}')}.imag)" for p in range(P)] + [f"square({v('M_bal')})"]
        sq += [f"square({v('F_bal')}.real) + square({v('F_bal')}.imag)"] if lay.machine else []
        body += [f"q{q} = {x}" for q, x in enumerate(sq)]
        body.append(f"ok &= math.isfinite({' + '.join(f'q{q}' for q in range(len(sq)))})")
        for q in range(P + 2):
            if q < len(sq):
                tr = t()
                body.append(f"T[{tr} + j] = q{q} if ok else 0.0")
                post += ["top = 0.0", "for j in range(m):", f"    top = max(top, T[{tr} + j])",
                         f"PK[b, {q}] = math.sqrt(top)"]
            else:
                post.append(f"PK[b, {q}] = 0.0")
    else:
        for (name, col), val in _value_map(lay, v).items():
            if kind == "motion" and name not in MOTION:
                continue
            more, after = _store(t, val, name in COMPLEX, first[name] + (2 if name in COMPLEX else 1) * col)
            body, post = body + more, post + after
        for val, is_complex, at in splice.stores(v) if splice else ():
            more, after = _store(t, val, is_complex, at)
            body, post = body + more, post + after
    body.append("FL[fl + j] = not ok")
    loop = ["for j in range(m):"] + ["    " + ln for ln in body]
    return "\n".join(head + ["        " + ln for ln in pre + pro + loop + post]) + "\n"


def _module(kernel_source: str) -> str:
    """The generated module: groups' source (the numpy path's equations, verbatim), the compiled
    primitives in place of groups' five, every function inlined (numba's inline="always"), and
    the kernel, compiled with numba's disk cache."""
    eq = re.sub(r"^from __future__ import annotations\n", "", inspect.getsource(groups), flags=re.M)
    prims = "\n\n".join(inspect.getsource(f) for f in PRIMITIVES)
    return "\n".join([
        "# Generated by kinetostat.fast: a kernel over the group equations of kinetostat.groups.",
        "import math", "import numba", "import numpy as np", "U = np.uint64", "",
        "# ---- kinetostat/groups.py", eq, "# ---- the compiled primitives (kinetostat/fast.py)", prims, "",
        "for _name in __all__:",
        "    globals()[_name] = numba.njit(inline='always', error_model='numpy')(globals()[_name])",
        "", "# ---- the kernel", kernel_source,
        "kernel = numba.njit(nogil=True, error_model='numpy', cache=True)(kernel)", ""])


def kernel(mech: "Mechanism", kind: str):
    """The compiled kernel of `mech`'s structure for `kind` ("full", "peaks" or "motion") and its layout:
    generated once per structure (designs enter through C; structures whose programs differ
    only in names share one), loaded from the cache folder where an earlier process compiled it."""
    lay = _layout(mech)
    src = mech.memo(("kernel source", kind), lambda: _source(mech, lay, kind))
    with _LOCK:
        if src not in _KERNELS:
            _KERNELS[src] = kernel_cache.load(_module(src)).kernel
        return _KERNELS[src], lay


def loaded(mech: "Mechanism", kind: str = "full") -> bool:
    """Whether this process holds the compiled kernel of `mech`'s structure for `kind` (loaded or
    compiled by an earlier call, for this mechanism or another of the same structure)."""
    if refusal(mech) is not None:
        return False
    src = mech.memo(("kernel source", kind), lambda: _source(mech, _layout(mech), kind))
    with _LOCK:
        return src in _KERNELS


def threshold(mech: "Mechanism", kind: str = "full") -> int:
    """The positions from which the compiled path pays for `mech` in this process: FAST_MIN where
    its `kind` kernel is `loaded`, FAST_COLD where the call would load it."""
    return FAST_MIN if loaded(mech, kind) else FAST_COLD


def pays(mech: "Mechanism", n: int, kind: str = "full") -> bool:
    """Whether `n` positions of `mech` go the compiled path: numba is there, the kernel takes
    `mech` (`refusal`) and n reaches `threshold` (the cheap bound FAST_MIN first)."""
    return n >= FAST_MIN and available() and refusal(mech) is None and n >= threshold(mech, kind)


def vector_report(fn) -> dict[str, int]:
    """Counts of the packed (ymm/zmm/xmm ...pd) and scalar (...sd) double arithmetic instructions
    in a compiled kernel's assembly: how much of it LLVM vectorised. ValueError where the kernel
    holds no assembly to read (loaded from numba's disk cache: compile it in a fresh cache folder,
    `CACHE_ENV`, as tests/test_fast.py does)."""
    asm = "\n".join(fn.inspect_asm().values())
    if not asm.strip():
        raise ValueError("vector_report: the kernel holds no assembly (loaded from numba's disk cache); "
                         f"compile it afresh (an empty {CACHE_ENV} folder) to read it")
    ops = r"(?:add|sub|mul|div|sqrt|fmadd\w*|fmsub\w*|fnmadd\w*|fnmsub\w*|max|min)"
    packed = re.findall(rf"\bv{ops}pd\s+%?([xyz])mm", asm)
    return {"packed_ymm": packed.count("y"), "packed_zmm": packed.count("z"), "packed_xmm": packed.count("x"),
            "scalar": len(re.findall(rf"\bv{ops}sd\b", asm))}


# ----------------------------------------------------------------------------- running
def _table(mechs: Sequence["Mechanism"], lay: _Layout) -> np.ndarray:
    """The base constants of every design, (D, K) complex."""
    C = np.empty((len(mechs), len(lay.consts)), complex)
    for d, m in enumerate(mechs):
        c = _constants(m)
        C[d] = [c[n] for n in lay.consts]
    return C


def _speeds(mechs: Sequence["Mechanism"], phi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The crank's omega and eps per design, each (D, N) or (D, 1) for constants, in the drive's sense."""
    pairs = [m.drive.speed(phi) for m in mechs]
    n = len(phi) if any(np.ndim(x) for pair in pairs for x in pair) else 1
    W, E = (np.array([np.broadcast_to(np.asarray(pr[q], float), (n,)) for pr in pairs]) for q in (0, 1))
    return W, E


def _blocks(D: int, a: int, b: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Blocks of the kernel's loop over designs x angles [a, b): design, first angle, count."""
    edges = np.arange(a, b, BLOCK, dtype=np.uint64)
    bd = np.repeat(np.arange(D, dtype=np.uint64), len(edges))
    b0 = np.tile(edges, D)
    return bd, b0, np.minimum(b0 + np.uint64(BLOCK), np.uint64(b)) - b0


def _run(mechs: Sequence["Mechanism"], phi: np.ndarray, kind: str, X: np.ndarray | None = None,
         S: np.ndarray | None = None, span: tuple[int, int] | None = None, FL: np.ndarray | None = None,
         threads: int | None = None, blocks: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None,
         other: tuple[Any, np.ndarray, int] | None = None):
    """The kernel over all designs and the angles span (default all) of `phi` (rad), or over
    `blocks` (design, first angle, count: `_end_to_end`'s), S the flat buffer of len(phi) angles,
    X the loads besides gravity ((3 (L - 1), len(phi)): F_x, F_y, M of each moving link) or None,
    its blocks shared among `threads` threads (default THREADS), one scratch each. Returns the
    flags (D, len(phi)), the peaks per block and the blocks' designs. `other`: another kernel of
    this layout (`Splice`'s), its constants table (D, >= K) and extra scratch rows."""
    fn, lay = kernel(mechs[0], kind) if other is None else (other[0], _layout(mechs[0]))
    D, N = len(mechs), len(phi)
    a, b = span or (0, N)
    W, E = _speeds(mechs, phi)
    bd, b0, bn = blocks or _blocks(D, a, b)
    FL = np.zeros((D, N), bool) if FL is None else FL
    S = np.zeros(1) if S is None else S
    PK = np.zeros((len(bd), lay.P + 2))
    C = _table(mechs, lay) if other is None else other[1]
    rows = _scratch_rows(lay) + (other[2] if other else 0)
    n = max(1, min(threads or THREADS, len(bd)))
    parts = [slice(q * len(bd) // n, (q + 1) * len(bd) // n) for q in range(n)]

    def part(s: slice) -> None:
        T = np.empty(rows * BLOCK)
        fn(phi, W, E, C, _NO_LOADS if X is None else X, bd[s], b0[s], bn[s], np.uint64(N), FL.reshape(-1), S, T, PK[s])

    if n == 1:
        part(parts[0])
    else:                     # the kernel releases the GIL: one thread per core, each on its own blocks
        list(_pool(n).map(part, parts))
    return FL, PK, bd


_POOLS: dict[int, ThreadPoolExecutor] = {}


def _pool(n: int) -> ThreadPoolExecutor:
    """A pool of n threads kept for the process (starting threads per call costs ms on a busy machine)."""
    with _LOCK:
        if n not in _POOLS:
            _POOLS[n] = ThreadPoolExecutor(n, thread_name_prefix="kinetostat-fast")
        return _POOLS[n]


_NO_LOADS = np.zeros((0, 1))


def _kinematics(mech: "Mechanism", phi: np.ndarray, r: dict[str, np.ndarray], error: np.ndarray):
    return Kinematics(phi, r["th"], r["rot"], r["O"], r["V"], r["A"], r["w"], r["e"], r["vs"], r["as"],
                      r["cond"], np.zeros(len(phi), bool), error)


def _loads(mech: "Mechanism", phi: np.ndarray, r: dict[str, np.ndarray]) -> np.ndarray:
    """The loads on `mech` besides gravity at the motion in the views `r` (angles phi, rad), as
    the kernel reads them: (3 (L - 1), N) rows F_x, F_y, M of each moving link about its origin."""
    kin = _kinematics(mech, phi, r, r["error"][:, 0])
    arm = mech.inertia_arrays[2] * kin.rot
    F, M = applied_wrenches(mech, kin, arm)
    W, M_W = groups.weight(arm, mech.inertia_arrays[0], mech.g)
    X = np.empty((mech.n_links - 1, 3, len(phi)))
    F -= W
    X[:, 0], X[:, 1], X[:, 2] = F.real[:, 1:].T, F.imag[:, 1:].T, (M - M_W)[:, 1:].T
    return X.reshape(-1, len(phi))


def _fill(mech: "Mechanism", phi: np.ndarray, buf: np.ndarray, threads: int | None) -> tuple[dict, np.ndarray]:
    """Run the full kernel over the angles `phi` (rad) into `buf`; where `mech` has loads besides
    gravity, per chunk of CHUNK angles: the motion kernel, the loads, the full kernel with them.
    The views and the flags."""
    lay = _layout(mech)
    N = len(phi)
    r = _views(lay, buf, N)
    r["rot"][:, 0] = 1.0              # the frame's e^{i theta}; the frame's other columns stay zero
    if not _has_loads(mech):
        FL, _, _ = _run([mech], phi, "full", S=buf, threads=threads)
        return r, FL
    FL = np.zeros((1, N), bool)
    X = np.empty((3 * (lay.L - 1), N))
    for a in range(0, N, CHUNK):
        span = (a, min(a + CHUNK, N))
        _run([mech], phi, "motion", S=buf, span=span, FL=FL, threads=threads)
        X[:, span[0]:span[1]] = _loads(mech, phi[span[0]:span[1]], {k: x[span[0]:span[1]] for k, x in r.items()})
        _run([mech], phi, "full", X, S=buf, span=span, FL=FL, threads=threads)
    return r, FL


def _analysis(mech: "Mechanism", phi_deg: np.ndarray, buf: np.ndarray, threads: int | None) -> "Analysis":
    """The Analysis of `mech` at `phi_deg` (deg) whose arrays are views of the flat buffer `buf`."""
    r, FL = _fill(mech, np.radians(phi_deg), buf, threads)
    return _result(mech, phi_deg, r, FL[0])


def _result(mech: "Mechanism", phi_deg: np.ndarray, r: dict[str, np.ndarray], flags: np.ndarray) -> "Analysis":
    """The Analysis of `mech` at `phi_deg` (deg) from the full kernel's arrays `r` (views, the
    angle axis first) and its guard's flags (N,): those angles solved by the numpy path."""
    phi = np.radians(phi_deg)
    N = len(phi)
    xy = lambda z: z.T.view(np.float64).reshape(z.shape[1], N, 2).transpose(1, 0, 2)   # (N, w, 2), a view
    r["error"][:, 0] = a_priori_error(r["cond"])
    kin = _kinematics(mech, phi, r, r["error"][:, 0])
    res = Analysis(mech, phi_deg, kin, xy(r["F_app"]), r["M_app"], xy(r["F_i"]), r["M_i"],
                   Forces(xy(r["R"]), r["normal"], r["m"], r["M_bal"][:, 0], xy(r["F_bal"])[:, 0]),
                   r["lever"][:, 0], r["friction"])
    if (r["w"][:, 1] == 0).any():     # at standstill the lever needs the plan at unit speed
        F_all = r["F_app"] + r["F_i"]
        M_all = r["M_app"] + r["M_i"] + groups.cross(mech.inertia_arrays[2] * kin.rot, r["F_i"])
        res.lever_moment[:] = lever_moment(mech, kin, F_all, M_all)
    flagged = np.flatnonzero(flags)
    if len(flagged):          # the guard's angles: the numpy path, with its accuracy check and warnings
        _scatter(res, exact(mech, phi_deg[flagged]), flagged)
    if mech.friction is not None:
        res.friction_power[:] = friction_power(mech, res.kin, as_xy(r["R"]))
    return _read_only(res)


def _check_buffer(mech: "Mechanism", out: np.ndarray, n: int) -> np.ndarray:
    need = _layout(mech).n_rows * n
    if not (isinstance(out, np.ndarray) and out.dtype == np.float64 and out.ndim == 1 and out.flags.c_contiguous
            and out.flags.writeable and out.size == need):
        raise ValueError(f"out: a writeable contiguous float64 buffer of {need} values "
                         f"(fast.buffer(mech, {n})) for {n} angles of {mech.name!r}")
    return out


def analyze_fast(mech: "Mechanism", phi_deg: np.ndarray, threads: int | None = None,
                 out: np.ndarray | None = None) -> "Analysis":
    """`kinetostat.analyze(mech, phi_deg)` by the compiled kernel: the same Analysis (to
    rounding), with the angles the guard must see (cond > COND_CHECK, or not assembled) solved
    by the numpy path. phi_deg: (N,) read-only crank angles, deg, as `analysis.crank_angles`
    gives. Its arrays are (strided) views of one flat buffer: a fresh one (the first touch of
    its pages costs about as much again as the kernel's work on the four-bar, 123 against 60 ns
    an angle, and a third more on the six-link, 461 against 345 ns: reports/benchmark.md), or
    `out` (`buffer(mech, N)`, reused: it is overwritten, and the previous Analysis with it)."""
    N = len(phi_deg)
    buf = buffer(mech, N) if out is None else _check_buffer(mech, out, N)
    return _analysis(mech, phi_deg, buf, threads)


def analyses(mechs: Sequence["Mechanism"], phi_deg: np.ndarray) -> list["Analysis"]:
    """`analyze_fast(mech, phi_deg, threads=1)` of every design in `mechs` (the same Analyses):
    the designs of one structure without loads besides gravity in one call of the full kernel per
    BATCH of them, on this thread, their angles laid end to end in one buffer (each Analysis a
    read-only view of its batch's buffer); the others one by one. For the many small designs of a
    Monte Carlo study, where the per-call work (layout, kernel look-up) outweighs 360 angles'."""
    phi_deg = np.asarray(phi_deg, float)
    out: list[Analysis | None] = [None] * len(mechs)
    kinds: dict[tuple, list[int]] = {}
    for d, m in enumerate(mechs):
        if _has_loads(m):
            out[d] = analyze_fast(m, phi_deg, threads=1)
        else:
            kinds.setdefault((_motion(m).steps, statics_program(m).steps), []).append(d)
    for same in kinds.values():
        for k in range(0, len(same), BATCH):
            batch = same[k:k + BATCH]
            for d, res in zip(batch, _end_to_end([mechs[d] for d in batch], phi_deg)):
                out[d] = res
    return out


def _end_to_end(mechs: Sequence["Mechanism"], phi_deg: np.ndarray) -> list["Analysis"]:
    """The Analyses of `mechs` (one kernel, no loads besides gravity) at `phi_deg` (deg, N) from one
    call of the full kernel over D N angles: design d's blocks cover angles [d N, (d + 1) N) of the
    angles repeated D times, reading design d's constants and speeds (its flags: row d of (D, D N))."""
    D, N = len(mechs), len(phi_deg)
    phi = np.tile(np.radians(phi_deg), D)
    lay = _layout(mechs[0])
    buf = np.zeros(lay.n_rows * D * N)
    r = _views(lay, buf, D * N)
    r["rot"][:, 0] = 1.0
    bd, b0, bn = _blocks(D, 0, N)
    FL, _, _ = _run(mechs, phi, "full", S=buf, FL=np.zeros((D, D * N), bool), threads=1,
                    blocks=(bd, b0 + bd * np.uint64(N), bn))
    return [_result(m, phi_deg, {k: x[d * N:(d + 1) * N] for k, x in r.items()}, FL[d, d * N:(d + 1) * N])
            for d, m in enumerate(mechs)]


def chunks(mech: "Mechanism", phi_deg: np.ndarray, size: int = CHUNK, threads: int | None = None) -> Iterator["Analysis"]:
    """The Analysis of `mech` at `phi_deg` (deg) in turn for runs of `size` angles: read-only
    views of one buffer reused from chunk to chunk (each valid until the next is asked for;
    copy what must outlive it), so memory stays bounded and no chunk pays fresh page faults."""
    buf = buffer(mech, size)
    for a in range(0, len(phi_deg), size):
        part = phi_deg[a:a + size]
        if len(part) < size:           # the last, shorter chunk: a buffer of its own layout
            buf = buffer(mech, len(part))
        yield _analysis(mech, part, buf, threads)


def _scatter(res: "Analysis", part: "Analysis", idx: np.ndarray) -> None:
    """Write the analysis `part` (at the angles idx) into `res`'s arrays."""
    from dataclasses import fields
    for a, b in ((res, part), (res.kin, part.kin), (res.forces, part.forces)):
        for f in fields(a):
            x = getattr(a, f.name)
            if isinstance(x, np.ndarray) and f.name not in ("phi", "phi_deg"):
                x[idx] = getattr(b, f.name)


@dataclass(frozen=True)
class Peaks:
    """What a sweep keeps of each design over the cycle (designs along the first axis)."""
    R: np.ndarray          # (D, n_pairs) largest |R| of every pair, N
    M_bal: np.ndarray      # (D,) largest |M_bal|, N m
    F_bal: np.ndarray      # (D,) largest |F_bal|, N (0 for an engine)
    singular_deg: tuple    # per design: the crank angles where the values are NaN (singular), deg
    warned_deg: tuple = ()  # per design: the angles whose values are kept with fewer than DIGITS_WARN digits, deg
    worst_digits: np.ndarray | None = None   # (D,) fewest digits left at those angles; NaN where none


def _loaded_peaks(mech: "Mechanism", phi: np.ndarray, threads: int | None) -> tuple[np.ndarray, np.ndarray]:
    """Peaks per block and flags of one design with loads besides gravity: per chunk of CHUNK
    angles, the motion kernel into a reused buffer, the loads, the peaks kernel."""
    lay = _layout(mech)
    N = len(phi)
    FL, PK, buf = np.zeros((1, N), bool), [], None
    for a in range(0, N, CHUNK):
        part = phi[a:a + CHUNK]
        n = len(part)
        if buf is None or len(buf) != lay.n_rows * n:       # one buffer for every whole chunk
            buf = buffer(mech, n)
        r = _views(lay, buf, n)
        r["rot"][:, 0] = 1.0
        fl, _, _ = _run([mech], part, "motion", S=buf, threads=threads)
        fl2, pk, _ = _run([mech], part, "peaks", _loads(mech, part, r), threads=threads)
        FL[0, a:a + n] = fl[0] | fl2[0]
        PK.append(pk)
    return FL, np.concatenate(PK)


def peaks(mechs: Sequence["Mechanism"], phi_deg: np.ndarray, threads: int | None = None) -> Peaks:
    """The largest |R| of every pair, |M_bal| and |F_bal| over the angles `phi_deg` (deg) of
    every design in `mechs` (one structure, e.g. the designs of a sweep) by the compiled kernel
    (one call for the designs without loads; per design and chunk with them); the angles the
    guard must see are solved by the numpy path, and excluded where they are singular. Designs
    at standstill go through the numpy path whole."""
    phi_deg = np.asarray(phi_deg, float)
    phi = np.radians(phi_deg)
    D = len(mechs)
    R, M, F = np.zeros((D, len(mechs[0].pairs))), np.zeros(D), np.zeros(D)
    singular: list[np.ndarray] = [np.empty(0)] * D
    warned, worst = [np.empty(0)] * D, np.full(D, np.nan)    # only angles the guard sends on have < 11 digits
    compiled = [d for d, m in enumerate(mechs) if m.drive.law or m.drive.omega]
    kinds: dict[tuple, list[int]] = {}          # one kernel per structure and branches
    for d in compiled:
        kinds.setdefault((_motion(mechs[d]).steps, statics_program(mechs[d]).steps,
                          _has_loads(mechs[d])), []).append(d)
    todo = {d: np.arange(len(phi_deg)) for d in range(D) if d not in compiled}
    P = R.shape[1]
    for key, same in kinds.items():
        runs = [([d], *_loaded_peaks(mechs[d], phi, threads)) for d in same] if key[2] else \
            [(same, *_run([mechs[d] for d in same], phi, "peaks", threads=threads)[:2])]
        for ds, FL, PK in runs:
            per = len(PK) // len(ds)
            for q, d in enumerate(ds):
                rows = PK[q * per:(q + 1) * per]
                R[d], M[d], F[d] = rows[:, :P].max(axis=0), rows[:, P].max(), rows[:, P + 1].max()
                todo[d] = np.flatnonzero(FL[q])
    for d, idx in todo.items():
        if not len(idx):
            continue
        res = exact(mechs[d], phi_deg[idx])
        ok = ~res.singular
        if ok.any():
            R[d] = np.maximum(R[d], np.linalg.norm(res.forces.R[ok], axis=-1).max(axis=0))
            M[d] = max(M[d], np.abs(res.balancing_moment[ok]).max())
            F[d] = max(F[d], np.linalg.norm(res.forces.F_bal[ok], axis=-1).max())
        singular[d] = res.phi_deg[res.singular]
        warned[d], worst[d] = warned_band(res)
    return Peaks(R, M, F, tuple(singular), tuple(warned), worst)


def warned_band(res) -> tuple[np.ndarray, float]:
    """The angles (deg) whose values `res` keeps with fewer than DIGITS_WARN digits, and the fewest
    digits there (NaN where there is none)."""
    low = ~res.singular & (res.digits < DIGITS_WARN)
    return res.phi_deg[low], float(res.digits[low].min()) if low.any() else np.nan
