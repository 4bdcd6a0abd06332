"""The compiled path of `kinetostat.sensitivity`: forward-mode derivatives generated from the
same source as the numpy and compiled analyses.

Every function of `groups` (but the five primitives) is turned, by a transformation of its
syntax tree (`jvp_source`), into `<name>_jvp`: the same statements on (value, tangent) pairs,
the chain rule applied to each operation (arithmetic, sqrt, maximum, conj, real, imag, sign,
cos, sin, abs) and, for the primitives, `PRIMITIVE_JVPS`. The kernel is `fast`'s kernel of the
analysis (its blocked loop, scratch rows and buffer layout) with the tangents spliced in
(`fast.Splice`): after each step's value, a `_jvp` call per parameter whose seed reaches the
step's arguments (the calls recompute the values, which LLVM merges: the functions are inlined
and pure); a tangent no parameter reaches is known zero, neither computed nor written. One pass
writes the analysis (`fast`'s rows) and the tangents (rows after them) into one buffer
(`run`); more than PASS tangents go in several passes, each writing the analysis again and its
own tangents' rows (`_passes`).
The constants' tangents are those `sensitivity` computes on duals (`sensitivity._seeded`,
`_design`); which of them are not zero picks the kernel (one per kind, pass and reach).

Loads besides gravity and inertia (tables, diagrams, springs, characteristics) are evaluated
between two passes, as `fast` does: the "motion" kernel writes the kinematics and their
tangents, `sensitivity` evaluates the loads on those duals (numpy, `applied.load_wrenches`),
the "full" kernel reads them and their tangents (rows of X).

May use: numpy, groups, fast (its layout, kernel source and module, runner, result, `Splice`), kernel_cache,
model (for type hints).
"""
from __future__ import annotations

import ast
import inspect
import textwrap
from typing import TYPE_CHECKING, Any, Callable, Mapping

import numpy as np

from . import fast, groups, kernel_cache

if TYPE_CHECKING:
    from .model import Mechanism

__all__ = ["jvp_source", "kernels", "pays", "refusal", "run", "PASS", "PRIMITIVE_JVPS"]


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
PASS = 3            # the most tangents one pass of a kernel carries (`_passes`)


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
    """The outputs whose tangents the `kind` kernel writes: "full", those `Sensitivity` keeps (as
    `sensitivity` keeps them on the numpy path); "motion", the kinematics the loads read."""
    links = range(1, mech.n_links)
    if kind == "motion":
        return (*(f"{s}{k}" for s in ("th", "O", "V", "A", "w", "e", "rot") for k in links),
                *(f"{s}{i}" for s in ("vs", "as") for i in fast._layout(mech).slides))
    return ("M_bal", *(("F_bal",) if mech.drive.kind == "machine" else ()), *(f"R{p.index}" for p in mech.pairs),
            *(f"{s}{k}" for s in ("O", "V", "A", "w", "e", "rot") for k in links))


def _is_complex(name: str) -> bool:
    return name.rstrip("0123456789") in _COMPLEX


def _rows(mech: "Mechanism", p: int) -> dict[str, int]:
    """Each output's first row (of n values) of tangents in the buffer, after the analysis' rows
    (`fast._layout`): its p tangents (a complex one two rows each, its real and imaginary parts
    interleaved: a view as complex, no copy); the motion kernel's and the full kernel's outputs."""
    rows, r = {}, fast._layout(mech).n_rows
    for name in dict.fromkeys(_outs(mech, "motion") + _outs(mech, "full")):
        rows[name] = r
        r += p * (2 if _is_complex(name) else 1)
    rows[""] = r
    return rows


def _splice(mech: "Mechanism", p: int, kind: str, live: tuple[frozenset[str], ...], qs: range) -> fast.Splice:
    """The tangents qs (of p) spliced into `fast`'s `kind` kernel, the kernel's tangent q being
    tangent qs[q]: tangent q of a value only where a seed of
    `live[q]` (constants, "w_in", "e_in", "X": the loads besides gravity) reaches it, else known
    zero and not computed, nor written (the buffer's rows stay zero). The constants' tangents are
    read from columns K (1 + q) + j of C, those of the crank's speeds from K (1 + p) + q and
    K (1 + p) + p + q (p here: len(qs), the pass' table, `_columns`); the loads' tangents from
    rows 3 (L - 1) (1 + q) + ... of X; the tangents written at rows `_rows(mech, p)`."""
    lay = fast._layout(mech)
    K, L = len(lay.consts), lay.L
    rows, p = _rows(mech, p), len(qs)
    on: list[set[str]] = [set() for _ in live]          # the kernel's identifiers with a tangent q

    def pro(v) -> list[str]:
        for q, seeds in enumerate(live):
            on[q].update(v(n) for n in seeds if n != "X")
        return ([f"{v(n)}_d{q} = C[d, {K * (1 + q) + j}]" + (".real" if real else "")
                 for q in range(p) for j, (n, real) in enumerate(zip(lay.consts, lay.real)) if v(n) in on[q]]
                + [f"{v(n)}_d{q} = C[d, {K * (1 + p) + p * s + q}].real"
                   for q in range(p) for s, n in enumerate(("w_in", "e_in")) if v(n) in on[q]])

    def jvp(fn: str, outs: list[str], args: list[str], q: int) -> list[str]:
        """fn's tangent q where an argument carries one (its outputs then carry it too; else not,
        also where an output overwrites an argument that did)."""
        if not any(a in on[q] for a in args):
            on[q].difference_update(outs)
            return []
        pairs = ", ".join(f"{a}, {f'{a}_d{q}' if a in on[q] else '0.0'}" for a in args)
        on[q].update(outs)
        return [f"{', '.join(f'_, {o}_d{q}' for o in outs)} = {fn}_jvp({pairs})"]

    def steps(sts, v, check) -> list[str]:
        arg = lambda a: v(a) if isinstance(a, str) else repr(a)
        lines = []
        for st in sts:
            if st.fn == "check":
                lines.append(check(0, *map(arg, st.args)))
                continue
            outs, args = [v(o) for o in st.out], [arg(a) for a in st.args]     # the tangents read the
            lines += [ln for q in range(p) for ln in jvp(st.fn, outs, args, q)]  # arguments before a value
            lines.append(f"{', '.join(outs)} = {st.fn}({', '.join(args)})")      # overwrites one
        return lines

    def link(k: int, v, row) -> tuple[list[str], list[str]]:
        pre, body = [], []
        for q in range(p):
            body += jvp("inertia", [f"r{k}", f"Fi{k}", f"Mi{k}"], [v(f"{s}{k}") for s in ("A", "w", "e", "rot", "com", "mass", "I_S")], q)
            body += jvp("weight", [f"Fa{k}", f"Ma{k}"], [f"r{k}", v(f"mass{k}"), v("g")], q)
            if "X" in live[q]:
                f, g, h = row(), row(), row()
                x = 3 * (L - 1) * (1 + q) + 3 * k
                pre += ["for j in range(m):", f"    T[{f} + j] = X[{x - 3}, i0 + j]", f"    T[{g} + j] = X[{x - 2}, i0 + j]",
                        f"    T[{h} + j] = X[{x - 1}, i0 + j]"]
                had = f"Fa{k}" in on[q]
                body += [f"Fa{k}_d{q} = " + (f"Fa{k}_d{q} + " if had else "") + f"complex(T[{f} + j], T[{g} + j])",
                         f"Ma{k}_d{q} = " + (f"Ma{k}_d{q} + " if had else "") + f"T[{h} + j]"]
                on[q].update((f"Fa{k}", f"Ma{k}"))
            body += jvp("wrench", [v(f"F{k}"), v(f"M{k}")], [f"Fa{k}", f"Ma{k}", f"Fi{k}", f"Mi{k}", f"r{k}"], q)
        return pre, body

    def stores(v) -> list[tuple[str, bool, int]]:
        return [(f"{v(n)}_d{q}", _is_complex(n), rows[n] + (2 if _is_complex(n) else 1) * qs[q])
                for n in _outs(mech, kind) for q in range(p) if v(n) in on[q]]

    return fast.Splice(pro, steps, link, stores, _scratch(mech, len(qs)))


def _scratch(mech: "Mechanism", p: int) -> int:
    """The most scratch rows `_splice`'s tangents take: the loads' and every output's."""
    return 3 * (mech.n_links - 1) * p + 2 * (_rows(mech, p)[""] - fast._layout(mech).n_rows)


def _passes(p: int) -> list[range]:
    """The tangents each pass of a kernel carries: PASS at most (LLVM left the chain unit's kernel
    of 5 tangents unvectorised, 0 packed instructions; of its two passes, that of h and l is
    vectorised, that of r, n_k and c is not)."""
    return [range(q, min(p, q + PASS)) for q in range(0, p, PASS)]


def _source(mech: "Mechanism", p: int, kind: str, live: tuple[frozenset[str], ...], qs: range) -> str:
    """The `kind` kernel ("motion" or "full") with the tangents qs of p: `fast`'s kernel of the
    analysis (`fast._source`), `_splice`'s tangents spliced in, and the `_jvp` functions it calls."""
    jvps = jvp_source() + "\n" + "\n\n".join(inspect.getsource(f) for f in PRIMITIVE_JVPS)
    return "\n".join([jvps, "for _name in [n for n in list(globals()) if n.endswith('_jvp')]:",
                      "    globals()[_name] = numba.njit(inline='always', error_model='numpy')(globals()[_name])", "",
                      fast._source(mech, fast._layout(mech), kind, _splice(mech, p, kind, live, qs))])


def _tangent(x: Any, p: int) -> np.ndarray:
    """The p tangents of a constant: a dual's `der` (any object with one), zeros for a number."""
    return np.broadcast_to(np.asarray(x.der), (p,)) if hasattr(x, "der") else np.zeros(p)


def _table(mech: "Mechanism", c: Mapping[str, Any], p: int) -> tuple[np.ndarray, tuple[set[str], ...]]:
    """The constants table of the kernels (1, K (1 + p) + 2 p: the constants, their p tangents,
    those of the crank's omega and eps; `_splice`) from the design's constants `c` (numbers, or
    duals with `val` and `der` (p,): `sensitivity._design`'s), and per tangent the names whose
    tangent is not zero."""
    lay = fast._layout(mech)
    base = fast._constants(mech)
    consts = [c.get(n, base[n]) for n in lay.consts]
    DC = np.array([_tangent(x, p) for x in consts], dtype=complex).reshape(len(consts), p)
    DW, DE = (np.real(_tangent(c[n], p)) if mech.drive.law is None and n in c else np.zeros(p) for n in ("w_in", "e_in"))
    C = np.concatenate([[complex(getattr(x, "val", x)) for x in consts], DC.T.reshape(-1), DW, DE])[None, :]
    live = tuple({n for n, d in zip(lay.consts, DC[:, q]) if d != 0} | {n for n, d in (("w_in", DW[q]), ("e_in", DE[q])) if d != 0}
                 for q in range(p))
    return C, live


def _columns(C: np.ndarray, K: int, p: int, qs: range) -> np.ndarray:
    """The constants table (`_table`'s, of K constants and p tangents) of the pass carrying the
    tangents qs: the constants, then those tangents' columns in the same order."""
    cols = [*range(K), *(K * (1 + q) + j for q in qs for j in range(K)), *(K * (1 + p) + q for q in qs),
            *(K * (1 + p) + p + q for q in qs)]
    return np.ascontiguousarray(C[:, cols])


def _kernel(mech: "Mechanism", p: int, kind: str, live: tuple[frozenset[str], ...], qs: range):
    """The compiled `kind` kernel with the tangents qs of p reaching from `live` (loaded or compiled)."""
    src = mech.memo(("sensitivity kernel source", p, kind, live, qs), lambda: _source(mech, p, kind, live, qs))
    with fast._LOCK:
        if src not in fast._KERNELS:
            fast._KERNELS[src] = kernel_cache.load(fast._module(src)).kernel
        held = mech.memo(("sensitivity kernels", p), dict)
        held[src] = fast._KERNELS[src]
        return fast._KERNELS[src]


def _held(mech: "Mechanism", p: int, kind: str, live: tuple[frozenset[str], ...], qs: range) -> bool:
    src = mech.memo(("sensitivity kernel source", p, kind, live, qs), lambda: _source(mech, p, kind, live, qs))
    with fast._LOCK:
        return src in fast._KERNELS


def _kinds(mech: "Mechanism") -> tuple[str, ...]:
    """The kernels `mech`'s sensitivities run: "motion" then "full" where it has loads besides gravity."""
    return ("motion", "full") if fast._has_loads(mech) else ("full",)


def pays(mech: "Mechanism", n: int, c: Mapping[str, Any], p: int) -> bool:
    """Whether `n` angles of `mech`'s sensitivities to p parameters (the design's constants `c`, as
    `run` takes them) go the compiled path: as `fast.pays` (FAST_MIN where this process holds
    its kernels, FAST_COLD where it would load or compile one) and `refusal` is None."""
    if n < fast.FAST_MIN or not fast.available() or refusal(mech) is not None:
        return False
    live = tuple(frozenset(x) for x in _table(mech, c, p)[1])
    held = all(_held(mech, p, _kinds(mech)[0], live[qs.start:qs.stop], qs) for qs in _passes(p))
    return n >= (fast.FAST_MIN if held else fast.FAST_COLD)


def kernels(mech: "Mechanism", p: int) -> list:
    """The compiled sensitivity kernels (numba dispatchers) with p tangents that this process has
    run for `mech` (one per kind and set of parameters' reach)."""
    return list(mech.memo(("sensitivity kernels", p), dict).values())


def _pair(r: Mapping[str, np.ndarray], S: np.ndarray, rows: Mapping[str, int], name: str, N: int, p: int):
    """The output `name`'s (value (N,), tangents (N, p)): views of the analysis' arrays `r`
    (`fast._views`) and of the tangent rows of the buffer S."""
    stem, k = name.rstrip("0123456789"), name[len(name.rstrip("0123456789")):]
    value = r[stem][:, int(k) if k else 0]
    at = rows[name]
    if _is_complex(name):
        return value, S[at * N:(at + 2 * p) * N].view(complex).reshape(p, N).T
    return value, S[at * N:(at + p) * N].reshape(p, N).T


def run(mech: "Mechanism", c: Mapping[str, Any], phi_deg: np.ndarray, p: int,
        loads: Callable[[dict[str, tuple[np.ndarray, np.ndarray]]], tuple[np.ndarray, np.ndarray]] | None = None,
        threads: int | None = None):
    """The analysis of `mech` at `phi_deg` (deg) and the tangents of the outputs `Sensitivity`
    keeps (`_outs`), in one pass of one kernel per PASS tangents (`_passes`; two kernels where
    `mech` has loads besides gravity), each output as (value (N,), tangents (N, p)) views of one
    buffer: the Analysis `fast.analyze_fast`
    gives (its guard's angles solved by the numpy path) and a dict of those pairs. `c`: the
    design's constants (numbers, or duals with `val` and `der` (p,): `sensitivity._design`'s).
    `loads(motion)`: where `mech` has loads besides gravity, those loads (3 (L - 1), N) (F_x, F_y,
    M of each moving link, as `fast` reads them) and their tangents (p, 3 (L - 1), N) from the
    motion kernel's outputs (pairs as above). NotImplementedError with `refusal`'s reason where
    it does not take `mech`."""
    why = refusal(mech)
    if why:
        raise NotImplementedError(f"{mech.name}: {why}")
    lay = fast._layout(mech)
    phi = np.radians(phi_deg)
    N = len(phi)
    rows = _rows(mech, p)
    S = np.zeros(rows[""] * N)
    r = fast._views(lay, S, N)
    r["rot"][:, 0] = 1.0              # the frame's e^{i theta}
    C, seeds = _table(mech, c, p)
    live = tuple(frozenset(x) for x in seeds)
    FL = np.zeros((1, N), bool)

    def passes(kind: str, live: tuple[frozenset[str], ...], X: Callable[[range], np.ndarray] | None = None) -> None:
        for qs in _passes(p):         # each writes the analysis (the same values) and its tangents
            other = (_kernel(mech, p, kind, live[qs.start:qs.stop], qs), _columns(C, len(lay.consts), p, qs),
                     _scratch(mech, len(qs)))
            fast._run([mech], phi, kind, None if X is None else X(qs), S=S, FL=FL, threads=threads, other=other)

    X = None
    if fast._has_loads(mech):
        passes("motion", live)
        x, dx = loads({n: _pair(r, S, rows, n, N, p) for n in _outs(mech, "motion")})
        X = lambda qs: np.ascontiguousarray(np.concatenate([x, dx[qs.start:qs.stop].reshape(-1, N)]), float)
        live = tuple(ls | {"X"} if np.any(dx[q]) else ls for q, ls in enumerate(live))
    passes("full", live, X)
    return fast._result(mech, phi_deg, r, FL[0]), {n: _pair(r, S, rows, n, N, p) for n in _outs(mech, "full")}
