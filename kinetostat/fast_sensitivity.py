"""The compiled path of `kinetostat.sensitivity`: forward-mode derivatives generated from the
same source as the numpy and compiled analyses.

Every function of `groups` (but the five primitives) is turned, by a transformation of its
syntax tree (`jvp_source`), into `<name>_jvp`: the same statements on (value, tangent) pairs,
the chain rule applied to each operation (arithmetic, sqrt, maximum, conj, real, imag, sign,
cos, sin, abs) and, for the primitives, `PRIMITIVE_JVPS`. The kernel runs the mechanism's
motion and statics programs (`program.motion_program`, `statics_program`, as `fast` does)
calling the `_jvp` functions once per parameter; every call recomputes the values, which
LLVM merges (the functions are inlined and pure). The constants' tangents are those
`sensitivity` computes on duals (`sensitivity._seeded`, `_design`).

Loads besides gravity and inertia (tables, diagrams, springs, characteristics) are evaluated
between two passes, as `fast` does: the "motion" kernel writes the kinematics and their
tangents, `sensitivity` evaluates the loads on those duals (numpy, `applied.load_wrenches`),
the "full" kernel reads them (X) and their tangents (DX).

May use: numpy, groups, program, fast (its layout, kernel module, speeds, pool, `loaded`), kernel_cache, model
(for type hints).
"""
from __future__ import annotations

import ast
import inspect
import textwrap
from typing import TYPE_CHECKING, Any, Mapping

import numpy as np

from . import fast, groups, kernel_cache
from .program import Identifiers, statics_program

if TYPE_CHECKING:
    from .model import Mechanism

__all__ = ["jvp_source", "kernels", "pays", "refusal", "tangents", "PRIMITIVE_JVPS"]


# ----------------------------------------------------------------------------- the primitives' rules
def magnitude_jvp(z, dz):
    """|z| and its tangent (z . dz) / |z|."""
    m = magnitude(z)  # noqa: F821 - bound in the generated module
    return m, (z.real * dz.real + z.imag * dz.imag) / m


def over_jvp(z, dz, r, dr):
    """z / r and its tangent (dz - q dr) / r."""
    q = over(z, r)  # noqa: F821
    return q, over(dz - q * dr, r)  # noqa: F821


def ratio_jvp(z, dz, w, dw):
    """z / w and its tangent (dz - q dw) / w."""
    q = ratio(z, w)  # noqa: F821
    return q, ratio(dz - q * dw, w)  # noqa: F821


def cis_jvp(th, dth):
    """e^{i th} and its tangent i e^{i th} dth."""
    c = cis(th)  # noqa: F821
    return c, complex(-c.imag * dth, c.real * dth)


def phase_jvp(x, dx):
    """atan2(Im x, Re x) and its tangent (x x dx) / |x|^2."""
    return phase(x), (x.real * dx.imag - x.imag * dx.real) / (x.real * x.real + x.imag * x.imag)  # noqa: F821


PRIMITIVE_JVPS = (magnitude_jvp, over_jvp, ratio_jvp, cis_jvp, phase_jvp)
_PRIMITIVES = tuple(f.__name__[:-4] for f in PRIMITIVE_JVPS)


# ----------------------------------------------------------------------------- groups' source on tangents
def _outputs(fn: ast.FunctionDef, counts: Mapping[str, int]) -> int:
    """How many values `fn` returns."""
    ret = next(s for s in fn.body if isinstance(s, ast.Return)).value
    if isinstance(ret, ast.Tuple):
        return len(ret.elts)
    if isinstance(ret, ast.Call) and isinstance(ret.func, ast.Name) and ret.func.id in counts:
        return counts[ret.func.id]
    return 1


class _Tangent:
    """One function's statements on (value, tangent) pairs: each subexpression a temporary with
    its tangent D__<name> (None: known zero)."""

    def __init__(self, counts: Mapping[str, int], args: list[str]):
        self.counts, self.lines, self.n = counts, [], 0
        self.tan: dict[str, str | None] = {a: f"D__{a}" for a in args}

    def tmp(self) -> str:
        self.n += 1
        return f"t__{self.n}"

    def let(self, val: str, tan: str | None) -> tuple[str, str | None]:
        t = self.tmp()
        self.lines.append(f"{t} = {val}")
        if tan is not None:
            self.lines.append(f"D__{t} = {tan}")
        return t, (f"D__{t}" if tan is not None else None)

    def call(self, name: str, args: list[ast.expr]) -> str:
        """`name`_jvp on the arguments' (value, tangent) pairs: the flat tuple it returns."""
        pairs = [self.expr(a) for a in args]
        return f"{name}_jvp({', '.join(f'{v}, {d or 0.0}' for v, d in pairs)})"

    def expr(self, e: ast.expr) -> tuple[str, str | None]:
        if isinstance(e, ast.Constant):
            return repr(e.value), None
        if isinstance(e, ast.Name):
            return e.id, self.tan.get(e.id)
        if isinstance(e, ast.UnaryOp) and isinstance(e.op, ast.USub):
            v, d = self.expr(e.operand)
            return self.let(f"-{v}", None if d is None else f"-{d}")
        if isinstance(e, ast.BinOp):
            (a, da), (b, db) = self.expr(e.left), self.expr(e.right)
            if isinstance(e.op, (ast.Add, ast.Sub)):
                s = "+" if isinstance(e.op, ast.Add) else "-"
                d = db and (f"{s}{db}" if da is None else f"{da} {s} {db}")
                return self.let(f"{a} {s} {b}", da if db is None else d)
            if isinstance(e.op, ast.Mult):
                terms = [f"{da} * {b}"] * (da is not None) + [f"{a} * {db}"] * (db is not None)
                return self.let(f"{a} * {b}", " + ".join(terms) or None)
            if isinstance(e.op, ast.Div):
                t = self.tmp()
                self.lines.append(f"{t} = {a} / {b}")
                if da is None and db is None:
                    return t, None
                num = f"{da or 0.0} - {t} * {db}" if db is not None else da
                self.lines.append(f"D__{t} = ({num}) / {b}")
                return t, f"D__{t}"
            if isinstance(e.op, ast.Pow) and isinstance(e.right, ast.Constant):
                k = e.right.value
                return self.let(f"{a}**{k!r}", None if da is None else f"{k!r} * {a}**{k - 1!r} * {da}")
        if isinstance(e, ast.Call):
            return self.function(e)
        raise NotImplementedError(f"fast_sensitivity: no tangent rule for {ast.unparse(e)}")

    def function(self, e: ast.Call) -> tuple[str, str | None]:
        f = e.func
        if isinstance(f, ast.Name) and (f.id in self.counts or f.id in _PRIMITIVES):
            if self.counts.get(f.id, 1) != 1:
                raise NotImplementedError(f"fast_sensitivity: {f.id} returns several values inside an expression")
            t = self.tmp()
            self.lines.append(f"{t}, D__{t} = {self.call(f.id, e.args)}")
            return t, f"D__{t}"
        pairs = [self.expr(a) for a in e.args]
        (a, da) = pairs[0]
        name = f.attr if isinstance(f, ast.Attribute) else f.id
        val = f"xp.{name}({', '.join(v for v, _ in pairs)})" if name != "abs" else f"abs({a})"
        if name in ("sign",):
            return self.let(val, None)
        if name == "maximum":
            (b, db) = pairs[1]
            return self.let(val, None if da is None and db is None else f"{da or 0.0} if {a} >= {b} else {db or 0.0}")
        if da is None:
            return self.let(val, None)
        rule = {"sqrt": lambda r: f"0.5 * {da} / {r}", "conj": lambda r: f"xp.conj({da})",
                "real": lambda r: f"xp.real({da})", "imag": lambda r: f"xp.imag({da})",
                "cos": lambda r: f"-xp.sin({a}) * {da}", "sin": lambda r: f"xp.cos({a}) * {da}",
                "abs": lambda r: f"xp.sign({a}) * {da}"}
        if name not in rule:
            raise NotImplementedError(f"fast_sensitivity: no tangent rule for {name}")
        t = self.tmp()
        self.lines.append(f"{t} = {val}")
        self.lines.append(f"D__{t} = {rule[name](t)}")
        return t, f"D__{t}"

    def statement(self, s: ast.stmt) -> None:
        if isinstance(s, ast.Expr) and isinstance(s.value, ast.Constant):
            return                                                    # the docstring
        if isinstance(s, ast.Assign):
            target = s.targets[0]
            names = [n.id for n in target.elts] if isinstance(target, ast.Tuple) else [target.id]
            if isinstance(s.value, ast.Tuple):    # a, b = x, y
                pairs = [self.expr(x) for x in s.value.elts]
                for n, (v, d) in zip(names, pairs):
                    self.lines += [f"{n} = {v}", f"D__{n} = {d or 0.0}"]
                    self.tan[n] = f"D__{n}"
                return
            if len(names) > 1:                    # a call of a function of several values
                call = s.value
                self.lines.append(f"{', '.join(f'{n}, D__{n}' for n in names)} = "
                                  f"{self.call(call.func.id, call.args)}")
                self.tan.update({n: f"D__{n}" for n in names})
                return
            v, d = self.expr(s.value)
            self.lines.append(f"{names[0]} = {v}")
            self.lines.append(f"D__{names[0]} = {d or 0.0}")
            self.tan[names[0]] = f"D__{names[0]}"
            return
        if isinstance(s, ast.Return):
            r = s.value
            if isinstance(r, ast.Call) and isinstance(r.func, ast.Name) and self.counts.get(r.func.id, 1) > 1:
                self.lines.append(f"return {self.call(r.func.id, r.args)}")
                return
            elts = r.elts if isinstance(r, ast.Tuple) else [r]
            pairs = [self.expr(x) for x in elts]
            self.lines.append(f"return {', '.join(f'{v}, {d or 0.0}' for v, d in pairs)}")
            return
        raise NotImplementedError(f"fast_sensitivity: no tangent rule for the statement {ast.unparse(s)}")


def jvp_source() -> str:
    """Python source of `<name>_jvp` for every function of `groups` but the primitives: arguments
    (x, dx, y, dy, ...), the values returned as (value, tangent, value, tangent, ...)."""
    tree = ast.parse(inspect.getsource(groups))
    fns = [n for n in tree.body if isinstance(n, ast.FunctionDef) and n.name not in _PRIMITIVES]
    counts: dict[str, int] = {}
    for fn in fns:                           # a function calls only those above it
        counts[fn.name] = _outputs(fn, counts)
    out = []
    for fn in fns:
        args = [a.arg for a in fn.args.args]
        tr = _Tangent(counts, args)
        for s in fn.body:
            tr.statement(s)
        sig = ", ".join(f"{a}, D__{a}" for a in args)
        out.append(f"def {fn.name}_jvp({sig}):\n" + textwrap.indent("\n".join(tr.lines), "    ") + "\n")
    return "\n".join(out)


# ----------------------------------------------------------------------------- the kernel
_COMPLEX = ("O", "V", "A", "rot", "R", "F_bal")  # the others (th, w, e, vs, as, M_bal) are real


def refusal(mech: "Mechanism") -> str | None:
    """Why the compiled sensitivity does not take `mech` (None where it does): `fast.refusal`'s."""
    return fast.refusal(mech)


def _outs(mech: "Mechanism", kind: str) -> tuple[str, ...]:
    """The outputs of the `kind` kernel: "full", those `Sensitivity` keeps (as `sensitivity` keeps
    them on the numpy path); "motion", the kinematics the loads read."""
    links = range(1, mech.n_links)
    if kind == "motion":
        return (*(f"{s}{k}" for s in ("th", "O", "V", "A", "w", "e", "rot") for k in links),
                *(f"{s}{i}" for s in ("vs", "as") for i in fast._layout(mech).slides))
    return ("M_bal", *(("F_bal",) if mech.drive.kind == "machine" else ()), *(f"R{p.index}" for p in mech.pairs),
            *(f"{s}{k}" for s in ("O", "V", "A", "w", "e", "rot") for k in links))


def _is_complex(name: str) -> bool:
    return name.rstrip("0123456789") in _COMPLEX


def _rows(mech: "Mechanism", p: int, kind: str) -> dict[str, int]:
    """Each output's first row (of n values) in the buffer: its value, then its p tangents (a complex
    one two rows each, its real and imaginary parts interleaved: a view as complex, no copy)."""
    rows, r = {}, 0
    for name in _outs(mech, kind):
        rows[name] = r
        r += (1 + p) * (2 if _is_complex(name) else 1)
    rows[""] = r
    return rows


def _step_lines(steps, v, p: int) -> list[str]:
    """The steps as calls of the `_jvp` functions, once per tangent (the values from the first)."""
    arg = lambda a, q: (f"{v(a)}_d{q}" if isinstance(a, str) else "0.0")
    lines = []
    for st in steps:
        if st.fn == "check":
            lines.append(f"ok &= {v(st.args[0])} >= -1e-12 * {v(st.args[1]) if isinstance(st.args[1], str) else repr(st.args[1])}")
            continue
        for q in range(p):
            outs = ", ".join(f"{v(o) if q == 0 else '_'}, {v(o)}_d{q}" for o in st.out)
            args = ", ".join(f"{v(a) if isinstance(a, str) else repr(a)}, {arg(a, q)}" for a in st.args)
            lines.append(f"{outs} = {st.fn}_jvp({args})")
    return lines


def _source(mech: "Mechanism", p: int, kind: str) -> str:
    """The `kind` kernel ("motion" or "full"): angles [a, b) of phi, constants C (K,) and their
    tangents DC (p, K), the crank's speeds W, E ((1, N) or (1, 1)) and their tangents DW, DE (p,),
    the loads besides gravity X (3 (L - 1), N: F_x, F_y, M of each moving link; empty where there
    are none) and their tangents DX (p, 3 (L - 1), N); writes every output's value and tangents
    at rows of n angles of S (`_rows`)."""
    lay = fast._layout(mech)
    motion, statics = fast._motion(mech), statics_program(mech)
    v = Identifiers().__getitem__
    rows = _rows(mech, p, kind)
    loads = mech.loads or mech.springs
    pro = []
    for j, (n, real) in enumerate(zip(lay.consts, lay.real)):
        pro.append(f"{v(n)} = C[{j}]" + (".real" if real else ""))
        pro += [f"{v(n)}_d{q} = DC[{q}, {j}]" + (".real" if real else "") for q in range(p)]
    hoisted, moving = fast.hoist(motion.steps + (() if kind == "motion" else statics.steps), lay.consts)
    pro += _step_lines(hoisted, v, p)
    in_motion = set(motion.steps)
    body = [f"{v('phi')} = phi[i]", f"{v('w_in')} = W[0, i if W.shape[1] > 1 else U(0)]",
            f"{v('e_in')} = E[0, i if E.shape[1] > 1 else U(0)]", "ok = True"]
    body += [f"{v(n)}_d{q} = {x}" for q in range(p) for n, x in (("phi", "0.0"), ("w_in", f"DW[{q}]"), ("e_in", f"DE[{q}]"))]
    body += _step_lines([st for st in moving if st in in_motion], v, p)
    for k in range(1, lay.L if kind == "full" else 1):
        for q in range(p):
            keep = lambda name: name if q == 0 else "_"
            a = lambda n: f"{v(n)}, {v(n)}_d{q}"
            body.append(f"{keep(f'r{k}')}, r{k}_d{q}, {keep(f'Fi{k}')}, Fi{k}_d{q}, {keep(f'Mi{k}')}, Mi{k}_d{q} = inertia_jvp("
                        f"{a(f'A{k}')}, {a(f'w{k}')}, {a(f'e{k}')}, {a(f'rot{k}')}, {a(f'com{k}')}, {a(f'mass{k}')}, "
                        f"{a(f'I_S{k}')})")
            body.append(f"{keep(f'Fa{k}')}, Fa{k}_d{q}, {keep(f'Ma{k}')}, Ma{k}_d{q} = weight_jvp(r{k}, r{k}_d{q}, "
                        f"{a(f'mass{k}')}, {a('g')})")
            if loads:
                if q == 0:
                    body += [f"Fa{k} = Fa{k} + complex(X[{3 * k - 3}, i], X[{3 * k - 2}, i])", f"Ma{k} = Ma{k} + X[{3 * k - 1}, i]"]
                body += [f"Fa{k}_d{q} = Fa{k}_d{q} + complex(DX[{q}, {3 * k - 3}, i], DX[{q}, {3 * k - 2}, i])",
                         f"Ma{k}_d{q} = Ma{k}_d{q} + DX[{q}, {3 * k - 1}, i]"]
            body.append(f"{keep(v(f'F{k}'))}, {v(f'F{k}')}_d{q}, {keep(v(f'M{k}'))}, {v(f'M{k}')}_d{q} = wrench_jvp("
                        f"Fa{k}, Fa{k}_d{q}, Ma{k}, Ma{k}_d{q}, Fi{k}, Fi{k}_d{q}, Mi{k}, Mi{k}_d{q}, r{k}, r{k}_d{q})")
    if kind == "full":
        body += _step_lines([st for st in moving if st not in in_motion], v, p)
    for name in _outs(mech, kind):
        r = rows[name]
        for q, x in enumerate([v(name)] + [f"{v(name)}_d{q}" for q in range(p)]):
            if _is_complex(name):
                body += [f"S[U({r + 2 * q}) * n + i + i] = {x}.real", f"S[U({r + 2 * q}) * n + i + i + U(1)] = {x}.imag"]
            else:
                body.append(f"S[U({r + q}) * n + i] = {x}")
    body.append("FL[i] = not ok")
    head = ["def kernel(phi, W, E, C, DC, DW, DE, X, DX, a, b, n, S, FL):"]
    loop = ["for i in range(a, b):"] + ["    " + ln for ln in body]
    jvps = jvp_source() + "\n" + "\n\n".join(inspect.getsource(f) for f in PRIMITIVE_JVPS)
    return "\n".join([jvps, "for _name in [n for n in list(globals()) if n.endswith('_jvp')]:",
                      "    globals()[_name] = numba.njit(inline='always', error_model='numpy')(globals()[_name])", ""]
                     + head + ["    " + ln for ln in pro + loop]) + "\n"


def pays(mech: "Mechanism", n: int, p: int) -> bool:
    """Whether `n` angles of `mech`'s sensitivities to p parameters go the compiled path: as
    `fast.pays` (FAST_MIN where this process holds the kernels, its own and the analysis' that
    gives `sens.result`; FAST_COLD where it would load or compile one) and `refusal` is None."""
    if n < fast.FAST_MIN or not fast.available() or refusal(mech) is not None:
        return False
    held = True
    for kind in _kinds(mech):
        src = mech.memo(("sensitivity kernel source", p, kind), lambda: _source(mech, p, kind))
        with fast._LOCK:
            held &= src in fast._KERNELS
        held &= fast.loaded(mech, kind)
    return n >= (fast.FAST_MIN if held else fast.FAST_COLD)


def _kinds(mech: "Mechanism") -> tuple[str, ...]:
    """The kernels `mech`'s sensitivities run: "motion" then "full" where it has loads besides gravity."""
    return ("motion", "full") if mech.loads or mech.springs else ("full",)


def kernels(mech: "Mechanism", p: int) -> list:
    """The compiled kernels (numba dispatchers) of `mech`'s sensitivities to p parameters, loaded
    or compiled as a call would (`_kinds`)."""
    return [_kernel(mech, p, kind) for kind in _kinds(mech)]


def _kernel(mech: "Mechanism", p: int, kind: str):
    src = mech.memo(("sensitivity kernel source", p, kind), lambda: _source(mech, p, kind))
    with fast._LOCK:
        if src not in fast._KERNELS:
            fast._KERNELS[src] = kernel_cache.load(fast._module(src)).kernel
        return fast._KERNELS[src]


def _tangent(x: Any, p: int) -> np.ndarray:
    """The p tangents of a constant: a dual's `der` (any object with one), zeros for a number."""
    return np.broadcast_to(np.asarray(x.der), (p,)) if hasattr(x, "der") else np.zeros(p)


def tangents(mech: "Mechanism", c: Mapping[str, Any], phi: np.ndarray, p: int, kind: str = "full",
             X: np.ndarray | None = None, DX: np.ndarray | None = None,
             threads: int | None = None) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """The outputs of the `kind` kernel (`_outs`: "full", those `Sensitivity` keeps; "motion", the
    kinematics), each as (value (N,), tangents (N, p)), at the crank angles `phi` (rad), from the
    design's constants `c` (numbers, or duals with `val` and `der` (p,): `sensitivity._design`'s)
    and, for "full" where `mech` has loads besides gravity, those loads X and their tangents DX
    (`_source`). NotImplementedError with `refusal`'s reason where it does not take `mech`."""
    why = refusal(mech)
    if why:
        raise NotImplementedError(f"{mech.name}: {why}")
    lay = fast._layout(mech)
    base = fast._constants(mech)
    consts = [c.get(n, base[n]) for n in lay.consts]
    C = np.array([complex(getattr(x, "val", x)) for x in consts])
    DC = np.array([_tangent(x, p) for x in consts], dtype=complex).T.copy()
    W, E = fast._speeds([mech], phi)
    DW, DE = (np.real(_tangent(c[n], p)) if mech.drive.law is None else np.zeros(p) for n in ("w_in", "e_in"))
    N = len(phi)
    rows = _rows(mech, p, kind)
    S, FL = np.empty(rows[""] * N), np.zeros(N, bool)
    fn = _kernel(mech, p, kind)
    X = np.zeros((0, 1)) if X is None else np.ascontiguousarray(X, float)
    DX = np.zeros((p, 0, 1)) if DX is None else np.ascontiguousarray(DX, float)
    n = max(1, min(threads or fast.THREADS, N // fast.BLOCK or 1))
    spans = [(np.uint64(q * N // n), np.uint64((q + 1) * N // n)) for q in range(n)]
    run = lambda s: fn(phi, W, E, C, DC, DW, DE, X, DX, s[0], s[1], np.uint64(N), S, FL)
    if n == 1:
        run(spans[0])
    else:
        list(fast._pool(n).map(run, spans))
    out = {}
    for name in _outs(mech, kind):
        r = rows[name]
        if _is_complex(name):
            z = S[r * N:(r + 2 * (1 + p)) * N].view(complex).reshape(1 + p, N)
        else:
            z = S[r * N:(r + 1 + p) * N].reshape(1 + p, N)
        out[name] = (z[0], z[1:].T)
    return out
