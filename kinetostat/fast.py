"""The compiled path: a mechanism's programs (`kinetostat.program`, the same group equations as
the numpy path) generated into one numba kernel that runs in parallel over blocks of (design,
angles) and fuses, per angle, the kinematics, the loads, the reactions of every group and the
balancing moment into one pass: no array is written but the results asked for.

- `analyze_fast(mech, phi_deg)`: the whole `Analysis`, the same as `kinetostat.analyze` gives
  (which calls it where it pays: `FAST_MIN` positions or more).
- `peaks(mechs, phi_deg)`: what a sweep keeps of each design: the largest |R| of every pair and
  |M_bal| (and |F_bal|) over the cycle, and the angles that need the exact guard.

Angles where a group's plan is ill-conditioned (cond > COND_CHECK), or cannot be assembled,
are flagged by the kernel and solved again by the numpy path with its accuracy guard, so the
results are the numpy path's there too. Loads other than gravity and inertia (tables, springs,
dampers, characteristics) are evaluated by `applied.applied_wrenches` on the chunk's motion
between two passes of the kernel. Long inputs run in chunks of CHUNK angles through buffers
reused from chunk to chunk: memory stays bounded, and no pass pays fresh page faults.

May use: numpy, numba, program, groups, kinematics, kinetostatics, applied, analysis (results),
model and structure (for type hints).
"""
from __future__ import annotations

import os
import threading
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Sequence

import numpy as np

from . import groups
from .program import Identifiers, bind, code, constants, free_names, motion_program, statics_program

if TYPE_CHECKING:
    from .analysis import Analysis
    from .model import Mechanism

__all__ = ["analyze_fast", "peaks", "Peaks", "FAST_MIN", "CHUNK", "available"]

#: From this many positions (designs x angles) on, `kinetostat.analyze` takes the compiled path.
FAST_MIN = 50_000
#: Angles per chunk: the buffers of one chunk are reused for the next.
CHUNK = 1 << 16
#: Angles per block of the parallel loop (a block is one design's run of angles).
BLOCK = 4096
#: Threads the kernel runs on (one per core by default).
THREADS = os.cpu_count() or 1


def available() -> bool:
    """Is numba importable (the compiled path)?"""
    try:
        import numba  # noqa: F401
    except ImportError:       # pragma: no cover - numba is a dependency
        return False
    return True


# ----------------------------------------------------------------------------- code generation
_KIND = {"full", "peaks", "motion"}
_LOCK = threading.Lock()
_KERNELS: dict[tuple, Any] = {}


def _has_loads(mech: "Mechanism") -> bool:
    """Does `mech` carry loads besides gravity and inertia (evaluated between two passes)?"""
    return bool(mech.loads or mech.springs)


@dataclass(frozen=True)
class _Layout:
    """What a kernel reads and writes: the base constants (in the order of the C columns), the
    moving links, the pairs and which are prismatic, the groups."""
    consts: tuple[str, ...]
    real: tuple[bool, ...]
    L: int
    P: int
    prismatic: tuple[int, ...]
    slides: tuple[int, ...]
    G: int
    machine: bool


def _layout(mech: "Mechanism") -> _Layout:
    motion, statics = motion_program(mech), statics_program(mech)
    base = constants(mech)
    consts = tuple(dict.fromkeys(n for n in free_names(motion) + free_names(statics) if n in base)) + tuple(
        f"{s}{k}" for k in range(1, mech.n_links) for s in ("com", "mass", "I_S")) + ("g",)
    consts = tuple(dict.fromkeys(consts))
    return _Layout(consts, tuple(not isinstance(base[n], complex) for n in consts), mech.n_links, len(mech.pairs),
                   tuple(p.index for p in mech.pairs if p.kind == "P"),
                   tuple(sorted(int(o[2:]) for o in motion.outputs if o.startswith("vs"))),
                   len(mech.structure.groups), mech.drive.kind == "machine")


#: The result's arrays as the kernel writes them, (D, N, columns): real and complex, in order.
REAL = ("th", "w", "e", "vs", "as", "cond", "M_app", "M_i", "normal", "m", "M_bal", "lever")
COMPLEX = ("rot", "O", "V", "A", "F_app", "F_i", "R", "F_bal")


def _width(lay: _Layout, name: str) -> int:
    return {"vs": lay.P, "as": lay.P, "normal": lay.P, "m": lay.P, "R": lay.P, "cond": lay.G,
            "M_bal": 1, "lever": 1, "F_bal": 1}.get(name, lay.L)


def _source(mech: "Mechanism", lay: _Layout, kind: str, loads: bool) -> str:
    """The kernel's Python source (compiled by numba): the programs' steps inside a parallel
    loop over blocks (design, run of angles) and a loop over each block's angles. `kind`
    "full" writes every array of the result into OR (real) and OC (complex); "peaks" keeps
    per block the largest |R| of each pair, |M_bal| and |F_bal| (PK). Both flag in FL the
    angles the exact guard must see."""
    from .kinematics import COND_CHECK
    from .program import Program
    motion, statics = motion_program(mech), statics_program(mech)
    v = Identifiers().__getitem__
    L, P = lay.L, lay.P
    head = ["def kernel(phi, W, E, C, bd, b0, b1, FA, MA, FL, OR, OC, PK):",
            "    for b in range(bd.shape[0]):",
            "        d = bd[b]",
            "        wd = d if W.shape[0] > 1 else 0",
            "        ws = 1 if W.shape[1] > 1 else 0",
            "        ed = d if E.shape[0] > 1 else 0",
            "        es = 1 if E.shape[1] > 1 else 0"]
    pro = [f"{v(n)} = C[d, {j}]" + (".real" if real else "") for j, (n, real) in enumerate(zip(lay.consts, lay.real))]
    # hoisted: the steps that read constants only (derived constants: lengths, offsets, phases)
    fixed = set(lay.consts)
    hoisted, moving = [], []
    for st in motion.steps + statics.steps:
        if st.fn != "check" and all(not isinstance(a, str) or a in fixed for a in st.args):
            fixed.update(st.out)
            hoisted.append(st)
        else:
            moving.append(st)
    pro += code(Program(tuple(hoisted), (), ()), v, lambda *a: "")
    n_pk = P + 2
    pro += [f"pk{q} = 0.0" for q in range(n_pk)] if kind == "peaks" else []
    check = lambda i, disc, scale: f"if not ({disc} >= -1e-12 * {scale}): flag = True"
    in_motion = set(motion.steps)
    body = [f"{v('phi')} = phi[i]", f"{v('w_in')} = W[wd, i * ws]", f"{v('e_in')} = E[ed, i * es]", "flag = False"]
    body += code(Program(tuple(st for st in moving if st in in_motion), (), motion.outputs), v, check)
    body += [f"if not ({v(f'cond{n}')} <= {COND_CHECK!r}): flag = True" for n in range(lay.G)]
    body.append("FL[d, i] = flag")
    for k in range(1, L):
        body.append(f"r{k}, Fi{k}, Mi{k} = inertia({v(f'A{k}')}, {v(f'w{k}')}, {v(f'e{k}')}, {v(f'rot{k}')}, "
                    f"{v(f'com{k}')}, {v(f'mass{k}')}, {v(f'I_S{k}')})")
        body.append(f"Fa{k}, Ma{k} = FA[d, i, {k}], MA[d, i, {k}]" if loads else
                    f"Fa{k}, Ma{k} = weight(r{k}, {v(f'mass{k}')}, {v('g')})")
        body.append(f"{v(f'F{k}')}, {v(f'M{k}')} = wrench(Fa{k}, Ma{k}, Fi{k}, Mi{k}, r{k})")
    if kind == "full":           # Zhukovsky's lever, before the groups change the known wrenches
        pw = " + ".join(f"power({v(f'F{k}')}, {v(f'M{k}')}, {v(f'V{k}')}, {v(f'w{k}')})" for k in range(1, L))
        body.append(f"lever = -({pw}) / {v('w1')}")
    body += code(Program(tuple(st for st in moving if st not in in_motion), (), statics.outputs), v, check)
    if kind == "full":
        value = {("th", k): v(f"th{k}") for k in range(1, L)}
        for s in ("w", "e", "rot", "O", "V", "A"):
            value.update({(s, k): v(f"{s}{k}") for k in range(1, L)})
        value.update({(s, p): v(f"{s}{p}") for s in ("vs", "as") for p in lay.slides})
        value.update({("cond", n): v(f"cond{n}") for n in range(lay.G)})
        for k in range(1, L):
            value.update({("M_app", k): f"Ma{k}", ("M_i", k): f"Mi{k}", ("F_app", k): f"Fa{k}", ("F_i", k): f"Fi{k}"})
        value.update({("R", p): v(f"R{p}") for p in range(P)})
        value.update({(s, p): v(f"{t}{p}") for s, t in (("normal", "N"), ("m", "m")) for p in lay.prismatic})
        value.update({("M_bal", 0): v("M_bal"), ("F_bal", 0): v("F_bal"), ("lever", 0): "lever"})
        for (name, col), val in value.items():
            arr = f"OR[{REAL.index(name)}]" if name in REAL else f"OC[{COMPLEX.index(name)}]"
            body.append(f"{arr}[d, i, {col}] = {val}")
    else:
        body.append("if not flag:")
        body += [f"    pk{p} = max(pk{p}, abs({v(f'R{p}')}))" for p in range(P)]
        body += [f"    pk{P} = max(pk{P}, abs({v('M_bal')}))", f"    pk{P + 1} = max(pk{P + 1}, abs({v('F_bal')}))"]
    loop = ["for i in range(b0[b], b1[b]):"] + ["    " + ln for ln in body]
    tail = [f"PK[b, {q}] = pk{q}" for q in range(n_pk)] if kind == "peaks" else []
    return "\n".join(head + ["        " + ln for ln in pro + loop + tail]) + "\n"


def kernel(mech: "Mechanism", kind: str, loads: bool = False):
    """The compiled kernel of `mech`'s structure for `kind` ("full" or "peaks") and its layout,
    compiled once per structure (memoised across designs: their numbers enter through C)."""
    lay = _layout(mech)
    key = (motion_program(mech).steps, statics_program(mech).steps, lay, kind, loads)
    with _LOCK:
        if key not in _KERNELS:
            import numba
            scope = dict(vars(bind(np, _njit)))
            exec(compile(_source(mech, lay, kind, loads), f"<kinetostat {kind} kernel>", "exec"), scope)
            _KERNELS[key] = (numba.njit(nogil=True, error_model="numpy")(scope["kernel"]), lay)
        return _KERNELS[key]


def _njit(fn):
    import numba
    return numba.njit(fn, error_model="numpy")      # x / 0 is inf or NaN, as in numpy: the guard flags it


# ----------------------------------------------------------------------------- running
def _table(mechs: Sequence["Mechanism"], lay: _Layout) -> np.ndarray:
    """The base constants of every design, (D, K) complex."""
    C = np.empty((len(mechs), len(lay.consts)), complex)
    for d, m in enumerate(mechs):
        c = m.memo(("constants", id(m.points_z)), lambda: constants(m))
        C[d] = [c[n] for n in lay.consts]
    return C


def _speeds(mechs: Sequence["Mechanism"], phi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The crank's omega and eps per design, each (D, N) or (D, 1) for constants, in the drive's sense."""
    pairs = [m.drive.speed(phi) for m in mechs]
    n = len(phi) if any(np.ndim(x) for pair in pairs for x in pair) else 1
    W, E = (np.array([np.broadcast_to(np.asarray(pr[q], float), (n,)) for pr in pairs]) for q in (0, 1))
    return W, E


def _blocks(D: int, N: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Blocks of the parallel loop over designs x angles: design, first and end angle."""
    edges = np.arange(0, N, BLOCK)
    bd = np.repeat(np.arange(D), len(edges))
    b0 = np.tile(edges, D)
    return bd, b0, np.minimum(b0 + BLOCK, N)


def _run(mechs: Sequence["Mechanism"], phi: np.ndarray, kind: str, FA=None, MA=None, out=None,
         threads: int | None = None):
    """The kernel over all designs and angles `phi` (rad), its blocks shared among `threads`
    threads (default THREADS)."""
    fn, lay = kernel(mechs[0], kind, FA is not None)
    D, N = len(mechs), len(phi)
    W, E = _speeds(mechs, phi)
    bd, b0, b1 = _blocks(D, N)
    FL = np.empty((D, N), bool)
    dummy = np.zeros((1, 1, 1), complex)
    FA = dummy if FA is None else FA
    MA = np.zeros((1, 1, 1)) if MA is None else MA
    if kind == "full":
        OR, OC = out
        PK = np.zeros((1, 1))
    else:
        OR, OC = (np.zeros((1, 1, 1)),), (dummy,)
        PK = np.empty((len(bd), lay.P + 2))
    C = _table(mechs, lay)
    n = max(1, min(threads or THREADS, len(bd)))
    parts = [slice(q * len(bd) // n, (q + 1) * len(bd) // n) for q in range(n)]

    def part(s: slice) -> None:
        fn(phi, W, E, C, bd[s], b0[s], b1[s], FA, MA, FL, OR, OC, PK[s] if kind == "peaks" else PK)

    if n == 1:
        part(parts[0])
    else:                     # the kernel releases the GIL: one thread per core, each on its own blocks
        with ThreadPoolExecutor(n) as pool:
            list(pool.map(part, parts))
    return FL, PK, bd


def _result_arrays(lay: _Layout, D: int, N: int) -> tuple[tuple[np.ndarray, ...], tuple[np.ndarray, ...]]:
    """The result's arrays, zero (the frame's columns and the revolute pairs' entries stay so;
    the frame's e^{i theta} is 1)."""
    OR = tuple(np.zeros((D, N, _width(lay, n))) for n in REAL)
    OC = tuple(np.zeros((D, N, _width(lay, n)), complex) for n in COMPLEX)
    OC[COMPLEX.index("rot")][..., 0] = 1.0
    return OR, OC


def analyze_fast(mech: "Mechanism", phi_deg: np.ndarray, threads: int | None = None) -> "Analysis":
    """`kinetostat.analyze(mech, phi_deg)` by the compiled kernel: the same Analysis (to
    rounding), with the angles the guard must see (cond > COND_CHECK, or not assembled) solved
    by the numpy path. phi_deg: (N,) read-only crank angles, deg, as `analysis.crank_angles` gives."""
    from .analysis import Analysis, _read_only, exact
    from .applied import applied_wrenches
    from .kinematics import Kinematics, a_priori_error
    from .kinetostatics import Forces, friction_power
    from .planar import as_xy
    phi = np.radians(phi_deg)
    N = len(phi)
    _, lay = kernel(mech, "full")
    OR, OC = _result_arrays(lay, 1, N)
    FL, _, _ = _run([mech], phi, "full", out=(OR, OC), threads=threads)
    r = dict(zip(REAL, (a[0] for a in OR)))
    c = dict(zip(COMPLEX, (a[0] for a in OC)))

    def motion() -> Kinematics:
        return Kinematics(phi, r["th"], c["rot"], c["O"], c["V"], c["A"], r["w"], r["e"], r["vs"], r["as"],
                          r["cond"], np.zeros(N, bool), a_priori_error(r["cond"]))

    if _has_loads(mech):      # loads that depend on the motion: evaluated on it, then the forces again
        kin = motion()
        F_app, M_app = applied_wrenches(mech, kin, mech.inertia_arrays[2] * kin.rot)
        FL, _, _ = _run([mech], phi, "full", F_app[None], M_app[None], out=(OR, OC), threads=threads)
    kin = motion()
    res = Analysis(mech, phi_deg, kin, as_xy(c["F_app"]), r["M_app"], as_xy(c["F_i"]), r["M_i"],
                   Forces(as_xy(c["R"]), r["normal"], r["m"], r["M_bal"][:, 0], as_xy(c["F_bal"][:, 0])),
                   r["lever"][:, 0], np.zeros((N, lay.P)))
    if (r["w"][:, 1] == 0).any():     # at standstill the lever needs the plan at unit speed
        from .kinetostatics import lever_moment
        F_all = c["F_app"] + c["F_i"]
        M_all = r["M_app"] + r["M_i"] + groups.cross(mech.inertia_arrays[2] * kin.rot, c["F_i"])
        res.lever_moment[:] = lever_moment(mech, kin, F_all, M_all)
    flagged = np.flatnonzero(FL[0])
    if len(flagged):          # the guard's angles: the numpy path, with its accuracy check and warnings
        _scatter(res, exact(mech, phi_deg[flagged]), flagged)
    res.friction_power[:] = friction_power(mech, res.kin, res.forces.R)
    return _read_only(res)


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


def peaks(mechs: Sequence["Mechanism"], phi_deg: np.ndarray, threads: int | None = None) -> Peaks:
    """The largest |R| of every pair, |M_bal| and |F_bal| over the angles `phi_deg` (deg) of
    every design in `mechs` (one structure, e.g. the designs of a sweep), by one call of the
    compiled kernel; the angles the guard must see are solved by the numpy path, and excluded
    where they are singular. Designs with loads besides gravity and inertia, or at standstill,
    go through the numpy path whole."""
    from .analysis import exact
    phi_deg = np.asarray(phi_deg, float)
    D = len(mechs)
    R, M, F = np.zeros((D, len(mechs[0].pairs))), np.zeros(D), np.zeros(D)
    singular: list[np.ndarray] = [np.empty(0)] * D
    warned, worst = [np.empty(0)] * D, np.full(D, np.nan)    # only angles the guard sends on have < 11 digits
    compiled = [d for d, m in enumerate(mechs) if not _has_loads(m) and (m.drive.law or m.drive.omega)]
    kinds: dict[tuple, list[int]] = {}          # one kernel per structure and branches
    for d in compiled:
        kinds.setdefault((motion_program(mechs[d]).steps, statics_program(mechs[d]).steps), []).append(d)
    todo = {d: np.arange(len(phi_deg)) for d in range(D) if d not in compiled}
    P = R.shape[1]
    for same in kinds.values():
        FL, PK, bd = _run([mechs[d] for d in same], np.radians(phi_deg), "peaks", threads=threads)
        for q, d in enumerate(same):
            rows = PK[bd == q]
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
            F[d] = max(F[d], np.linalg.norm(res.balancing_force[ok], axis=-1).max())
        singular[d] = res.phi_deg[res.singular]
        warned[d], worst[d] = warned_band(res)
    return Peaks(R, M, F, tuple(singular), tuple(warned), worst)


def warned_band(res) -> tuple[np.ndarray, float]:
    """The angles (deg) whose values `res` keeps with fewer than DIGITS_WARN digits, and the fewest
    digits there (NaN where there is none)."""
    from .kinematics import DIGITS_WARN
    low = ~res.singular & (res.digits < DIGITS_WARN)
    return res.phi_deg[low], float(res.digits[low].min()) if low.any() else np.nan
