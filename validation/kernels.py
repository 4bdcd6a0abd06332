"""The engines' compiled kernels per angle, and this machine's limit: the honest yardsticks of speed.

Engines, with as little Python as possible, doing what their exact routes do for the driving
moment and the reactions at a set state (`engine_mujoco.solve`, `engine_pinocchio.solve`):

- MuJoCo (`mujoco_kernel`): a small C program, compiled here with gcc against the mujoco wheel's
  own headers and libmujoco, loads the very model the exact route compiles (`engine_mujoco`'s
  model with the exact masses written back, saved as MJB: the MJCF alone carries placeholder
  masses) and times, in C, the loop over the angles: the state written to qpos/qvel/qacc,
  mj_kinematics, mj_comPos, mj_makeConstraint, mj_comVel (mj_fwdPosition + mj_fwdVelocity
  without factorising the inertia matrix), mj_rne, the applied loads (xfrc_applied, mj_applyFT),
  the square solve [S | J^T][tau; lambda] = rne - Q (Gaussian elimination, partial pivoting)
  and mj_rnePostConstraint (the tree joints' forces cfrc_int). Zero Python inside the loop.
- Pinocchio (`pinocchio_kernel`): the pin wheel ships no Eigen headers, so no C++ program can be
  built against it here; the loop is Python calling the bound C++ per angle:
  computeJointJacobians, each loop closure's calc, getConstraintsJacobian, rnea (applied loads
  as fext), numpy's solve of [S | Jc^T][tau; lambda] = b, and a second rnea (the pass that gives
  the tree joints' forces; its fext here are the applied loads only: the same compiled work,
  without the adapter's Python that maps lambda to fext). A prismatic loop closure is a
  CONTACT_6D model whose normal and rotation rows are kept (they span the adapter's own rows,
  so tau is the same). The loop's own Python is measured by running the identical loop with
  every engine and numpy call replaced by a stub returning a preallocated result, and is
  reported beside the total, never subtracted.

The machine (`machine_rates`, `machine_limit`): the write bandwidth of memory (a numba loop
filling a 256 MiB buffer that is reused, so no page faults) and the double-precision throughput
of one core (a numba loop of independent multiply-adds, fused to FMAs by fastmath); a per-angle
limit is max(flops / flop rate, bytes / bandwidth). `count_flops` counts the floating-point
operations of a compiled per-angle numba function from its LLVM IR (a vector operation counts
its lanes); `count_flops_loop` the flops per angle of a kernel's vectorised loop, `count_program`
that loop's operations per angle by kind (adds, multiplies, divisions, square roots, FMAs, and
operations with a literal zero: numba's promotion of a real operand to complex).

A kernel's bound (`unit_rates`, `bound`): this core's vectorised throughput of division, square
root, FMA and unfused multiply and add, measured by numba loops over arrays in the L1 cache; a
program's bound is max(port time of its adds, multiplies and FMAs, divider time of its divisions
and square roots). `cpu_info`
names the CPU, its vector flags and the target numba compiles for, to record with every figure.

May use: kinetostat, the scene, engine_mujoco and engine_pinocchio (their models and states),
mujoco, pinocchio, numba, numpy; gcc on the PATH for the MuJoCo kernel.
"""
from __future__ import annotations

import functools
import math
import os
import re
import shutil
import statistics
import subprocess
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .scene import Scene

__all__ = ["KernelTiming", "mujoco_kernel", "pinocchio_kernel", "MachineRates", "machine_rates",
           "machine_limit", "count_flops", "count_flops_ir", "count_flops_loop", "bytes_per_angle", "cpu_info",
           "Program", "count_program", "UnitRates", "unit_rates", "Bound", "bound"]


@dataclass(frozen=True)
class KernelTiming:
    """An engine kernel over the scene's regular angles: wall seconds per angle (median of the
    repeats), the loop's own Python overhead per angle where the loop is Python (NaN for C), the
    driving moment it computed at every angle (NaN at singular angles), N m, and the CPU seconds
    per angle (this process' CPU clock), minimum and median of the repeats."""
    engine: str
    seconds_per_angle: float
    overhead_per_angle: float
    M_drive: np.ndarray
    note: str
    cpu_min_per_angle: float
    cpu_median_per_angle: float


# ----------------------------------------------------------------------------- MuJoCo, in C

_MUJOCO_C = r"""
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <mujoco/mujoco.h>

static double now(clockid_t c) {
  struct timespec t; clock_gettime(c, &t); return t.tv_sec + 1e-9 * t.tv_nsec;
}

/* solve A x = b in place (A n x n, row-major), partial pivoting; 0 if singular */
static int solve(double *A, double *b, int n) {
  for (int c = 0; c < n; c++) {
    int p = c;
    for (int r = c + 1; r < n; r++) if (fabs(A[r*n+c]) > fabs(A[p*n+c])) p = r;
    if (A[p*n+c] == 0.0) return 0;
    if (p != c) {
      for (int k = 0; k < n; k++) { double t = A[c*n+k]; A[c*n+k] = A[p*n+k]; A[p*n+k] = t; }
      double t = b[c]; b[c] = b[p]; b[p] = t;
    }
    for (int r = c + 1; r < n; r++) {
      double f = A[r*n+c] / A[c*n+c];
      for (int k = c; k < n; k++) A[r*n+k] -= f * A[c*n+k];
      b[r] -= f * b[c];
    }
  }
  for (int c = n - 1; c >= 0; c--) {
    for (int k = c + 1; k < n; k++) b[c] -= A[c*n+k] * b[k];
    b[c] /= A[c*n+c];
  }
  return 1;
}

/* argv: model.mjb states.bin N repeat crank_dof out.bin row0 row1 ...
   states.bin: qpos (N nq), qvel (N nv), qacc (N nv), xfrc (N nbody 6), doubles
   out.bin: tau (N), then the wall seconds of each repeat, then its CPU seconds (this process) */
int main(int argc, char **argv) {
  mjModel *m = mj_loadModel(argv[1], NULL);
  if (!m) { fprintf(stderr, "cannot load %s\n", argv[1]); return 2; }
  mjData *d = mj_makeData(m);
  int N = atoi(argv[3]), repeat = atoi(argv[4]), crank = atoi(argv[5]);
  int nrows = argc - 7, nq = m->nq, nv = m->nv, nb = m->nbody, n = 1 + nrows;
  int *rows = malloc(sizeof(int) * (nrows + 1));
  for (int k = 0; k < nrows; k++) rows[k] = atoi(argv[7 + k]);
  if (n != nv) { fprintf(stderr, "system not square: %d unknowns, nv = %d\n", n, nv); return 2; }
  size_t len = (size_t)N * (nq + 2 * nv + 6 * nb);
  double *st = malloc(sizeof(double) * len);
  FILE *f = fopen(argv[2], "rb");
  if (!f || fread(st, sizeof(double), len, f) != len) { fprintf(stderr, "cannot read states\n"); return 2; }
  fclose(f);
  double *qpos = st, *qvel = qpos + (size_t)N * nq, *qacc = qvel + (size_t)N * nv, *xfrc = qacc + (size_t)N * nv;
  double *tau = malloc(sizeof(double) * N), *secs = malloc(sizeof(double) * 2 * repeat);
  double *rne = malloc(sizeof(double) * nv), *qfrc = malloc(sizeof(double) * nv);
  double *A = malloc(sizeof(double) * n * n), *x = malloc(sizeof(double) * n);
  for (int r = 0; r < repeat; r++) {
    double t0 = now(CLOCK_MONOTONIC), c0 = now(CLOCK_PROCESS_CPUTIME_ID);
    for (int i = 0; i < N; i++) {
      mju_copy(d->qpos, qpos + (size_t)i * nq, nq);
      mju_copy(d->qvel, qvel + (size_t)i * nv, nv);
      mju_copy(d->qacc, qacc + (size_t)i * nv, nv);
      mj_kinematics(m, d); mj_comPos(m, d); mj_makeConstraint(m, d); mj_comVel(m, d);
      mj_rne(m, d, 1, rne);
      mju_zero(qfrc, nv);
      mju_copy(d->xfrc_applied, xfrc + (size_t)i * nb * 6, nb * 6);
      for (int b = 1; b < nb; b++) {
        const double *w = d->xfrc_applied + 6 * b;
        if (w[0] != 0 || w[1] != 0 || w[2] != 0 || w[3] != 0 || w[4] != 0 || w[5] != 0)
          mj_applyFT(m, d, w, w + 3, d->xipos + 3 * b, b, qfrc);
      }
      for (int a = 0; a < nv; a++) {
        A[a * n] = (a == crank);
        for (int k = 0; k < nrows; k++) A[a * n + 1 + k] = d->efc_J[rows[k] * nv + a];
        x[a] = rne[a] - qfrc[a];
      }
      if (!solve(A, x, n)) { tau[i] = NAN; continue; }
      mju_zero(d->efc_force, d->nefc);
      for (int k = 0; k < nrows; k++) d->efc_force[rows[k]] = x[1 + k];
      mj_rnePostConstraint(m, d);
      tau[i] = x[0];
    }
    secs[r] = now(CLOCK_MONOTONIC) - t0;
    secs[repeat + r] = now(CLOCK_PROCESS_CPUTIME_ID) - c0;
  }
  f = fopen(argv[6], "wb");
  fwrite(tau, sizeof(double), N, f); fwrite(secs, sizeof(double), 2 * repeat, f); fclose(f);
  mj_deleteData(d); mj_deleteModel(m);
  return 0;
}
"""


@functools.cache
def _mujoco_program() -> Path:
    """The MuJoCo kernel's executable, compiled once per process (gcc -O2 against the wheel's
    include/ and libmujoco.so); RuntimeError when gcc or the wheel's headers are missing."""
    import mujoco
    pkg = Path(mujoco.__file__).parent
    libs = sorted(pkg.glob("libmujoco.so*"))
    gcc = shutil.which("gcc")
    if not (gcc and libs and (pkg / "include" / "mujoco" / "mujoco.h").exists()):
        raise RuntimeError(f"the MuJoCo kernel needs gcc and the wheel's include/ and libmujoco.so "
                           f"(gcc: {gcc}, library: {libs}, headers in {pkg / 'include'})")
    folder = Path(tempfile.mkdtemp(prefix="kinetostat-kernel-"))
    src, exe = folder / "mujoco_kernel.c", folder / "mujoco_kernel"
    src.write_text(_MUJOCO_C)
    subprocess.run([gcc, "-O2", "-o", str(exe), str(src), f"-I{pkg / 'include'}", f"-L{pkg}",
                    f"-l:{libs[0].name}", f"-Wl,-rpath,{pkg}", "-lm"], check=True, capture_output=True, text=True)
    return exe


def mujoco_kernel(scene: Scene, repeat: int = 5) -> KernelTiming:
    """MuJoCo's compiled inverse dynamics, timed in C over the scene's regular angles (see the
    module docstring): median over `repeat` runs of the loop, wall seconds per angle, and the
    loop's CPU time (CLOCK_PROCESS_CPUTIME_ID of the C program), minimum and median."""
    import mujoco
    from . import engine_mujoco as em
    mm = em._compile(scene, em.EXACT_FLOOR, exact_masses=True)
    m, d = mm.m, mm.d
    em._kinematics(m, d)                          # every equality is always active: fixed rows
    rows = np.concatenate([em._rows(mm, p.index) for p in scene.cuts] + [np.zeros(0, int)])
    ok = ~scene.res.singular
    qpos, qvel, qacc = (a[ok] for a in em._exact_state(scene, mm))
    F, M = scene.external()
    xfrc = em._xfrc(scene, mm, F[ok], M[ok])
    N = int(ok.sum())
    with tempfile.TemporaryDirectory(prefix="kinetostat-mj-") as tmp:
        tmp = Path(tmp)
        mujoco.mj_saveModel(m, str(tmp / "model.mjb"), None)
        np.concatenate([a.ravel() for a in (qpos, qvel, qacc, xfrc)]).astype(np.float64).tofile(tmp / "states.bin")
        subprocess.run([str(_mujoco_program()), str(tmp / "model.mjb"), str(tmp / "states.bin"), str(N),
                        str(repeat), str(mm.crank_dof), str(tmp / "out.bin"), *map(str, rows)],
                       check=True, capture_output=True, text=True)
        out = np.fromfile(tmp / "out.bin", dtype=np.float64)
    M_drive = np.full(len(ok), np.nan)
    M_drive[ok] = out[:N]
    wall, cpu = out[N:N + repeat], out[N + repeat:]
    return KernelTiming("mujoco", statistics.median(wall) / N, math.nan, M_drive,
                        f"MuJoCo {mujoco.__version__}, C loop (gcc -O2) over {N} angles, {repeat} runs",
                        min(cpu) / N, statistics.median(cpu) / N)


# ----------------------------------------------------------------------------- Pinocchio, a Python loop

def _pin_loop(calls, model, data, calcs, cmodels, cdatas, states, fexts, A, keep, tau) -> None:
    """The Pinocchio kernel's loop over the angles; `calls` = (computeJointJacobians,
    getConstraintsJacobian, rnea, solve), the real ones or stubs (to time the loop's own Python)."""
    jacobians, constraints_jacobian, rnea, solve = calls
    for i, (q, v, a) in enumerate(states):
        jacobians(model, data, q)
        for calc, cd in zip(calcs, cdatas):
            calc(model, data, cd)
        A[:, 1:] = constraints_jacobian(model, data, cmodels, cdatas)[keep].T
        x = solve(A, rnea(model, data, q, v, a, fexts[i]))
        rnea(model, data, q, v, a, fexts[i])           # the tree joints' forces pass (data.f)
        tau[i] = x[0]


def _pin_closures(ps):
    """The adapter's loop closures as Pinocchio constraint models and the kept rows: a revolute
    cut's CONTACT_3D (rows x, y), a prismatic cut's CONTACT_6D in the guide's frame, x along the
    guide, both frames aligned at assembly (rows: normal y, rotation z)."""
    import pinocchio as pin
    from .engine_pinocchio import _rz, _v3
    cmodels, keep, first = pin.StdVec_RigidConstraintModel(), [], 0
    for cm in ps.cmodels:
        cmodels.append(cm)
        keep += [first, first + 1]
        first += 3
    for pair, x_slider, d_guide in ps.p_cuts:
        g, s = pair.links
        beta = math.atan2(d_guide[1], d_guide[0])
        m1 = pin.SE3(_rz(beta), _v3(ps._local(g, pair.guide)))
        m2 = pin.SE3(_rz(beta - pair.alpha), x_slider)
        cmodels.append(pin.RigidConstraintModel(pin.ContactType.CONTACT_6D, ps.model, ps.jid[g], m1,
                                                ps.jid[s], m2, pin.ReferenceFrame.LOCAL))
        keep += [first + 1, first + 5]
        first += 6
    cdatas = pin.StdVec_RigidConstraintData()
    for cm in cmodels:
        cdatas.append(cm.createData())
    return cmodels, cdatas, np.array(keep)


def pinocchio_kernel(scene: Scene, repeat: int = 5) -> KernelTiming:
    """Pinocchio's compiled calls in a Python loop over the scene's regular angles (see the
    module docstring): median over `repeat` runs, wall seconds per angle, its CPU time (this
    process) minimum and median, and the same loop with stubs for every engine and numpy call
    (the loop's own Python), wall seconds per angle."""
    import pinocchio as pin
    from .engine_pinocchio import PinocchioScene
    ps = PinocchioScene(scene)
    model, data = ps.model, ps.data
    cmodels, cdatas, keep = _pin_closures(ps)
    ok = np.flatnonzero(~scene.res.singular)
    states = [ps.state(n) for n in ok]
    fexts = []
    for n, (q, v, a) in zip(ok, states):
        pin.forwardKinematics(model, data, q)                 # data.oMi for the loads' frames
        fexts.append(ps.applied_fext(n))
    A = np.zeros((ps.nv, ps.nv))
    A[ps.crank_v, 0] = 1.0
    tau = np.full(len(ok), np.nan)
    calcs = [cm.calc for cm in cmodels]
    real = (pin.computeJointJacobians, pin.getConstraintsJacobian, pin.rnea, np.linalg.solve)
    Jc, b, x = pin.getConstraintsJacobian(model, data, cmodels, cdatas).copy(), np.zeros(ps.nv), np.zeros(ps.nv)
    nothing = lambda *args: None
    stubs = (nothing, lambda *args: Jc, lambda *args: b, lambda *args: x)

    def run(calls, calc_fns) -> tuple[float, float]:
        t, c = time.perf_counter(), time.process_time()
        _pin_loop(calls, model, data, calc_fns, cmodels, cdatas, states, fexts, A, keep, tau)
        return time.perf_counter() - t, time.process_time() - c

    run(real, calcs)
    wall, cpu = zip(*(run(real, calcs) for _ in range(repeat)))
    M_drive = np.full(len(scene.phi_deg), np.nan)
    M_drive[ok] = tau
    overhead = statistics.median(run(stubs, [nothing] * len(calcs))[0] for _ in range(repeat)) / len(ok)
    return KernelTiming("pinocchio", statistics.median(wall) / len(ok), overhead, M_drive,
                        f"pin {pin.__version__}, Python loop over {len(ok)} angles, {4 + len(calcs)} bound calls "
                        f"per angle, {repeat} runs", min(cpu) / len(ok), statistics.median(cpu) / len(ok))


# ----------------------------------------------------------------------------- flops of a compiled kernel

_TYPE = r"(?:[a-z]+\s+)*(?:<(\d+) x (?:double|float)>|double|float)"
_ARITH = re.compile(r"=\s*(?:fadd|fsub|fmul|fdiv|frem)\s+" + _TYPE)
_CALL = re.compile(r"call\s+" + _TYPE + r"\s+@(?:llvm\.)?(fma|fmuladd|sqrt|sin|cos|tan|atan2|atan|asin|acos|exp|log|pow|hypot)\b")
_LABEL = re.compile(r"^([\w.$-]+):")
_TARGET = re.compile(r"label %([\w.$-]+)")


def count_flops_ir(ir: str) -> int:
    """Floating-point operations in one LLVM IR function body (straight-line code): fadd, fsub,
    fmul, fdiv, frem count 1, fma and fmuladd 2, a call of sqrt or of a libm function (sin, cos,
    atan2, exp, ...) 1; a vector operation counts its lanes. ValueError if the body loops (its
    control-flow graph has a cycle): the count is then not per call."""
    counts, zeros = dict.fromkeys(_KINDS, 0.0), set()
    blocks: dict[str, set[str]] = {}
    current = "entry"
    for line in ir.splitlines():
        if (m := _LABEL.match(line)) is not None:
            current = m.group(1)
        blocks.setdefault(current, set())
        blocks[current].update(_TARGET.findall(line))     # br, switch and its case lines
        _count_line(line, counts, zeros)
    if _has_cycle(blocks):
        raise ValueError("the kernel loops: count_flops wants the per-angle body (a function of "
                         "scalars without loops), whose flops are then flops per angle")
    return int(Program(**counts).flops)


def _has_cycle(succ: dict[str, set[str]]) -> bool:
    state: dict[str, int] = {}                    # 1 on the DFS stack, 2 done

    def visit(b: str) -> bool:
        state[b] = 1
        for c in succ.get(b, ()):
            if state.get(c) == 1 or (c not in state and visit(c)):
                return True
        state[b] = 2
        return False

    return any(b not in state and visit(b) for b in list(succ))


def count_flops(dispatcher, signature=None) -> int:
    """Floating-point operations of one call of a compiled numba function (its first compiled
    signature unless `signature` is given), counted in its optimised LLVM IR (`count_flops_ir`);
    meant for the per-angle body of a kernel, whose count is then flops per angle."""
    sig = signature if signature is not None else dispatcher.signatures[0]
    name = dispatcher.overloads[sig].fndesc.mangled_name
    lines = dispatcher.inspect_llvm(sig).splitlines()
    start = next(i for i, line in enumerate(lines) if line.startswith("define") and f"@{name}(" in line)
    end = next(i for i in range(start, len(lines)) if lines[i].startswith("}"))
    return count_flops_ir("\n".join(lines[start + 1:end]))


_VECTOR_BODY = re.compile(r"^((?:[\w.$-]*\.)?vector\.body[\w.$-]*):")
_STEP = re.compile(r"%index\.next[\w.]* = add (?:nuw )?(?:nsw )?i64 %index[\w.]*, (\d+)")
_ZERO = r"(?:zeroinitializer|-?0\.0+e\+00|splat \((?:double|float) -?0\.0+e\+00\))"
_BY_ZERO = re.compile(r"=\s*(?:fadd|fsub|fmul)\s+" + _TYPE + r"\s+(?:" + _ZERO + r",|[^,]+,\s*" + _ZERO + r"\s*(?:,|$))")


@dataclass(frozen=True)
class Program:
    """A kernel's counted program per angle, by kind (a vector operation counts its lanes):
    additions and subtractions, multiplications, divisions, square roots, fused multiply-adds,
    additions, subtractions and multiplications with a literal zero operand and additions and
    subtractions of a product by one (numba's promotion of a real operand to complex: kept out of
    `add` and `mul`), others (frem, libm calls); the widest
    vector (lanes) of the loop."""
    add: float = 0.0
    mul: float = 0.0
    div: float = 0.0
    sqrt: float = 0.0
    fma: float = 0.0
    by_zero: float = 0.0
    other: float = 0.0
    width: int = 1

    @property
    def flops(self) -> float:
        """Flops per angle: an FMA counts 2, every other operation 1."""
        return self.add + self.mul + self.div + self.sqrt + 2 * self.fma + self.by_zero + self.other

    def per(self, step: int) -> "Program":
        """The counts over `step` angles (one pass of a vector loop) as counts per angle."""
        return Program(*(getattr(self, k) / step for k in _KINDS), width=self.width)


_KINDS = ("add", "mul", "div", "sqrt", "fma", "by_zero", "other")
_VALUE = re.compile(r"%[\w.$-]+")


def _count_line(line: str, counts: dict[str, float], zeros: set[str]) -> int:
    """Add one IR line's floating-point operation to `counts` (lanes of it) by kind; its lanes
    (0 where the line is no such operation). `zeros`: the values that are products by a literal
    zero so far (a product by zero joins them; an addition of one counts as by zero)."""
    if (m := _ARITH.search(line)) is not None:
        lanes, (name, rest) = int(m.group(1) or 1), line.split("=", 1)
        op = rest.split()[0]
        by_zero = _BY_ZERO.search(line) is not None or (
            op in ("fadd", "fsub") and any(v in zeros for v in _VALUE.findall(rest)))
        if by_zero and op == "fmul":
            zeros.add(name.strip())
        kind = ("by_zero" if by_zero else "add" if op in ("fadd", "fsub") else "mul" if op == "fmul"
                else "div" if op == "fdiv" else "other")
    elif (m := _CALL.search(line)) is not None:
        lanes, fn = int(m.group(1) or 1), m.group(2)
        kind = "fma" if fn in ("fma", "fmuladd") else "sqrt" if fn == "sqrt" else "other"
    else:
        return 0
    counts[kind] += lanes
    return lanes


def count_program(ir: str) -> Program:
    """The counted program per iteration of the scalar loop that LLVM vectorised into the
    `vector.body` block of the IR `ir` with the most flops (a kernel's loop over the angles): the
    block's operations by kind (`Program`) over the iterations one pass of it does (its index
    step). ValueError if no loop was vectorised."""
    best: tuple[float, Program] = (0.0, Program())
    counts, width, step, current, zeros = dict.fromkeys(_KINDS, 0.0), 1, 0, None, set()
    for line in ir.splitlines() + ["end:"]:
        if (m := _LABEL.match(line)) is not None:
            if current is not None and step:
                block = Program(**counts, width=width)
                best = max(best, (block.flops, block.per(step)), key=lambda fp: fp[0])
            current = m.group(1) if _VECTOR_BODY.match(line) and not m.group(1).startswith("vec.epilog") else None
            counts, width, step = dict.fromkeys(_KINDS, 0.0), 1, 0
            continue
        if current is None:
            continue
        if (m := _STEP.search(line)) is not None:
            step = int(m.group(1))
        width = max(width, _count_line(line, counts, zeros))
    if not best[0]:
        raise ValueError("no vectorised loop (vector.body) in this IR")
    return best[1]


def count_flops_loop(ir: str) -> float:
    """Floating-point operations per iteration of the scalar loop that LLVM vectorised into the
    largest `vector.body` block of the IR `ir` (a kernel's loop over the angles): the flops of
    `count_program`. ValueError if no loop was vectorised."""
    return count_program(ir).flops


def cpu_info() -> dict[str, str]:
    """This machine's CPU as /proc/cpuinfo names it, its vector flags (avx2, fma, avx512*), the
    CPU and features LLVM compiles numba's kernels for, and the load average (1, 5, 15 min)."""
    import llvmlite.binding as llvm
    model, flags = "unknown", set()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            key, _, value = line.partition(":")
            if key.strip() == "model name":
                model = value.strip()
            elif key.strip() == "flags":
                flags = set(value.split())
    except OSError:
        pass
    vector = sorted(f for f in flags if f in ("avx", "avx2", "fma") or f.startswith("avx512"))
    load = os.getloadavg() if hasattr(os, "getloadavg") else (math.nan,) * 3
    return {"model": model, "cores": str(os.cpu_count()), "vector_flags": " ".join(vector) or "none",
            "llvm_target": llvm.get_host_cpu_name(), "load": " ".join(f"{x:.2f}" for x in load)}


# ----------------------------------------------------------------------------- the machine's limit

#: The throughput kernel's independent accumulators: enough chains to hide the FMA latency
#: (4-5 cycles, 2 units) at the vector widths of x86 (to 8 doubles).
_CHAINS = 64


def _fma_chains(n: int, acc: np.ndarray) -> None:
    """n rounds of acc[k] = acc[k] * b + c over _CHAINS independent chains (2 flops each)."""
    b, c = 0.999999999, 1e-9
    for _ in range(n):
        for k in range(_CHAINS):
            acc[k] = acc[k] * b + c


def _fill(buf: np.ndarray, x: float) -> None:
    for i in range(buf.size):
        buf[i] = x


@dataclass(frozen=True)
class MachineRates:
    """One core's double-precision arithmetic throughput (flop/s) and memory write bandwidth
    (bytes/s), measured here in this thread's CPU time, best of the repeats; how they were measured."""
    flops_per_second: float
    bytes_per_second: float
    note: str


@functools.cache
def machine_rates(repeat: int = 5, buffer_bytes: int = 256 * 2**20) -> MachineRates:
    """Measure the machine once per process (see the module docstring): best of `repeat` runs,
    each in this thread's CPU time (time.thread_time)."""
    import numba
    fma = numba.njit(fastmath=True)(_fma_chains)
    fill = numba.njit(_fill)
    acc = np.ones(_CHAINS)
    rounds = 2_000_000
    fma(10, acc)
    t_fma = min(_timed(lambda: fma(rounds, acc)) for _ in range(repeat))
    buf = np.empty(buffer_bytes // 8)
    fill(buf, 0.5)                                          # every page touched before timing
    t_fill = min(_timed(lambda: fill(buf, 1.5)) for _ in range(repeat))
    return MachineRates(2 * _CHAINS * rounds / t_fma, buf.nbytes / t_fill,
                        f"numba {numba.__version__}: {_CHAINS} independent multiply-add chains (fastmath, FMA), "
                        f"one core; a numba loop writing a reused {buffer_bytes / 2**20:.0f} MiB buffer; "
                        f"thread CPU time, best of {repeat}")


def _timed(fn) -> float:
    """CPU time of this thread running fn, s: the clock the kernels' rows are timed in, so the
    share of the core that other processes take on a loaded machine counts in neither."""
    t = time.thread_time()
    fn()
    return time.thread_time() - t


def machine_limit(flops_per_angle: float, bytes_per_angle: float, cores: int = 1,
                  rates: MachineRates | None = None) -> float:
    """The least time per angle this machine allows, s: max(flops / flop rate of `cores` cores,
    bytes / write bandwidth), the bandwidth shared by the cores."""
    rates = rates if rates is not None else machine_rates()
    return max(flops_per_angle / (rates.flops_per_second * cores), bytes_per_angle / rates.bytes_per_second)


# ----------------------------------------------------------------------------- a kernel's bound

def _divide(x: np.ndarray, rounds: int) -> None:
    """`rounds` passes of x[i] = 1 / x[i]: one division per element, independent across elements."""
    for _ in range(rounds):
        for i in range(x.size):
            x[i] = 1.0 / x[i]


def _root(x: np.ndarray, rounds: int) -> None:
    """`rounds` passes of x[i] = sqrt(x[i]): one square root per element."""
    for _ in range(rounds):
        for i in range(x.size):
            x[i] = math.sqrt(x[i])


def _multiply_add(x: np.ndarray, rounds: int) -> None:
    """`rounds` passes over the columns of x (8, n): 8 independent chains a column, each 8 steps
    of v * b + c (fused to FMAs where compiled with contraction)."""
    b, c = 0.999999999, 1e-9
    for _ in range(rounds):
        for i in range(x.shape[1]):
            p, q, r, s, t, u, v, w = x[0, i], x[1, i], x[2, i], x[3, i], x[4, i], x[5, i], x[6, i], x[7, i]
            for _k in range(8):
                p, q, r, s = p * b + c, q * b + c, r * b + c, s * b + c
                t, u, v, w = t * b + c, u * b + c, v * b + c, w * b + c
            x[0, i], x[1, i], x[2, i], x[3, i], x[4, i], x[5, i], x[6, i], x[7, i] = p, q, r, s, t, u, v, w


@dataclass(frozen=True)
class UnitRates:
    """One core's vectorised double-precision throughput, operations (lanes) per second of this
    thread's CPU time: divisions, square roots, fused multiply-adds, and multiplications and
    additions unfused (as the kernels, compiled without fast-math, run them); how measured."""
    div: float
    sqrt: float
    fma: float
    add_mul: float
    note: str


@functools.cache
def unit_rates(repeat: int = 3, size: int = 2048, rounds: int = 20_000) -> UnitRates:
    """Measure the units once per process: numba loops over arrays of `size` doubles (in the L1
    cache), `rounds` passes, each timed in this thread's CPU time, best of `repeat`."""
    import numba
    runs = {"div": (numba.njit(error_model="numpy")(_divide), (size,), 1),
            "sqrt": (numba.njit(error_model="numpy")(_root), (size,), 1),
            "fma": (numba.njit(error_model="numpy", fastmath={"contract"})(_multiply_add), (8, size // 8), 8),
            "add_mul": (numba.njit(error_model="numpy")(_multiply_add), (8, size // 8), 16)}
    rates = {}
    for unit, (fn, shape, per_element) in runs.items():
        x = np.full(shape, 1.5)
        fn(x, 1)                                            # compiled, x in the cache
        rates[unit] = per_element * size * rounds / min(_timed(lambda: fn(x, rounds)) for _ in range(repeat))
    return UnitRates(**rates, note=f"numba {numba.__version__} loops over {size} doubles (L1): x = 1/x, x = sqrt(x), "
                                   f"8 independent chains of v * b + c fused (FMA) and unfused (a multiply and an add); "
                                   f"{rounds:,} passes, thread CPU time, best of {repeat}")


@dataclass(frozen=True)
class Bound:
    """A kernel's least time per angle on this core, s: its adds, multiplies and FMAs at the
    measured port rates (`port`), its divisions and square roots at the divider's (`divider`,
    one unit for both); the bound is the larger."""
    port: float
    divider: float

    @property
    def seconds(self) -> float:
        return max(self.port, self.divider)

    @property
    def limit(self) -> str:
        """Which limit binds: "divider" or "ports"."""
        return "divider" if self.divider > self.port else "ports"


def bound(program: Program, rates: UnitRates) -> Bound:
    """The bound of a counted program (per angle) at the units' rates: port time = (adds +
    multiplies + operations by zero + others) / the unfused multiply-add rate + FMAs / the FMA
    rate; divider time = divisions / the division rate + square roots / the square-root rate."""
    port = (program.add + program.mul + program.by_zero + program.other) / rates.add_mul + program.fma / rates.fma
    return Bound(port, program.div / rates.div + program.sqrt / rates.sqrt)


def bytes_per_angle(arrays, n_angles: int) -> float:
    """Bytes written per angle by a result given as a dict of arrays (or of their nbytes), over
    n_angles angles."""
    return sum(a if isinstance(a, (int, float)) else a.nbytes for a in arrays.values()) / n_angles
