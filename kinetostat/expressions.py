"""Arithmetic expressions of model files: the `[parameters]` table and numeric fields written as
strings ("3.05 * r", "G2 / g", "bar_inertia(m2, l_AB)").

An expression is parsed with `ast` and evaluated by walking the tree; only number literals,
names, + - * / **, unary + and -, parentheses and calls of FUNCTIONS (by name, positional
arguments) are allowed; nothing is ever executed. A parameter or a field is evaluated in floats
(`Expression.__call__`): every intermediate result must be finite and real. A law of motion
omega(phi) or a motor's M(omega) is evaluated over arrays (`over_arrays`), with numpy, so that the
complex step can differentiate it.

May use: the standard library and numpy.
"""
from __future__ import annotations

import ast
import difflib
import functools
import math
import operator
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from contextlib import contextmanager
from contextvars import ContextVar
from typing import Any, Iterator

import numpy as np

__all__ = ["ExpressionError", "Expression", "FUNCTIONS", "ARRAY_FUNCTIONS", "CONSTANTS", "HELPERS", "MAX_EXPRESSION",
           "MAX_EXPONENT", "parse", "over_arrays", "resolve", "bar_inertia", "mass_from_density", "mass_from_weight",
           "inertia_from_gyration", "gear_wheel_mass"]

#: Longest expression, characters.
MAX_EXPRESSION = 500
#: Largest |exponent| of a power, checked before the power is computed.
MAX_EXPONENT = 1000.0


class ExpressionError(ValueError):
    """An expression that cannot be read or evaluated; the message names no field (the caller does)."""


# ----------------------------------------------------------------------------- helpers of the texts

def bar_inertia(m: float, l: float) -> float:
    """I_S = m l^2 / 12, kg m^2: a uniform bar of mass m (kg) and length l (m) about its centre
    (seed 004, line 133)."""
    return m * l * l / 12


def mass_from_density(q: float, l: float) -> float:
    """m = q l, kg: a link of linear density q (kg/m) and length l (m) (seed 000 sec. 6.1, line 373)."""
    return q * l


def mass_from_weight(G: float, g: float) -> float:
    """m = G / g, kg: a link of weight G (N) at gravity g (m/s^2) (seed 002: G2, G3)."""
    return G / g


def inertia_from_gyration(m: float, rho: float) -> float:
    """I_S = m rho^2, kg m^2: a link of mass m (kg) and radius of gyration rho (m) about its centre."""
    return m * rho * rho


def gear_wheel_mass(m_g: float) -> float:
    """m_1 = 1.3 m_g, kg: the mass of the gear wheel on the crank shaft estimated from the mass m_g
    of its rim (seed 000, sec. 7.2: "m_1 = 1,3 m_g, де m_g - маса вінця колеса")."""
    return 1.3 * m_g


#: The helpers of the texts, by name (documented in models/FORMAT.md with formula and source).
HELPERS: Mapping[str, Callable[..., float]] = {
    "bar_inertia": bar_inertia, "mass_from_density": mass_from_density, "mass_from_weight": mass_from_weight,
    "inertia_from_gyration": inertia_from_gyration, "gear_wheel_mass": gear_wheel_mass}


def _at_least_two(f: Callable[..., float]) -> Callable[..., float]:
    def call(*args: float) -> float:
        if len(args) < 2:
            raise TypeError(f"{f.__name__}() takes at least 2 arguments ({len(args)} given)")
        return f(*args)
    return call


#: Every function an expression may call: name -> (function, number of arguments or None for 2+).
FUNCTIONS: Mapping[str, tuple[Callable[..., float], int | None]] = {
    **{n: (getattr(math, n), 1) for n in ("sqrt", "sin", "cos", "tan", "asin", "acos", "atan", "sinh", "cosh",
                                          "tanh", "radians", "degrees", "exp", "log")},
    "atan2": (math.atan2, 2), "hypot": (math.hypot, 2), "abs": (abs, 1),
    "min": (_at_least_two(min), None), "max": (_at_least_two(max), None),
    **{n: (f, f.__code__.co_argcount) for n, f in HELPERS.items()}}
#: Names an expression may use besides the parameters.
CONSTANTS: Mapping[str, float] = {"pi": math.pi}

_BINARY = {ast.Add: operator.add, ast.Sub: operator.sub, ast.Mult: operator.mul, ast.Div: operator.truediv,
           ast.Pow: operator.pow}
_UNARY = {ast.USub: operator.neg, ast.UAdd: operator.pos}
_WHAT = {ast.Attribute: "attribute access", ast.Subscript: "subscripts", ast.Lambda: "lambdas",
         ast.ListComp: "comprehensions", ast.SetComp: "comprehensions", ast.DictComp: "comprehensions",
         ast.GeneratorExp: "comprehensions", ast.Compare: "comparisons", ast.BoolOp: "'and'/'or'",
         ast.IfExp: "'if ... else'", ast.NamedExpr: "':='", ast.Starred: "'*' arguments",
         ast.JoinedStr: "strings", ast.List: "lists", ast.Tuple: "tuples", ast.Dict: "dicts", ast.Set: "sets",
         ast.Await: "'await'", ast.Yield: "'yield'", ast.YieldFrom: "'yield'"}
_ALLOWED = "numbers, parameter names, + - * / ** and parentheses, and calls of " + ", ".join(
    sorted(FUNCTIONS)) + "; constant pi"


@dataclass(frozen=True)
class Expression:
    """A checked expression: its text, its tree, and the names it reads (parameters, g)."""
    text: str
    tree: ast.Expression
    names: frozenset[str]

    def __call__(self, values: Mapping[str, float]) -> float:
        """The value with the names in `values` (unknown names are refused with a suggestion)."""
        try:
            x = _eval(self.tree.body, values)
        except (OverflowError, ZeroDivisionError, ValueError, TypeError) as exc:
            if isinstance(exc, ExpressionError):
                raise
            raise ExpressionError(_arith_message(exc)) from None
        return _checked(x)


#: The functions an expression over arrays may call (a law of motion omega(phi), a motor's
#: M(omega)), in numpy's form: they take arrays and complex numbers, and their complex extension is
#: analytic, so the complex step differentiates through them (abs, min, max, atan2 and hypot are
#: not analytic, and are refused there).
ARRAY_FUNCTIONS: Mapping[str, Callable] = {
    "sqrt": np.sqrt, "sin": np.sin, "cos": np.cos, "tan": np.tan, "asin": np.arcsin, "acos": np.arccos,
    "atan": np.arctan, "sinh": np.sinh, "cosh": np.cosh, "tanh": np.tanh, "exp": np.exp, "log": np.log,
    "radians": lambda x: x * (math.pi / 180.0), "degrees": lambda x: x * (180.0 / math.pi), **HELPERS}


def over_arrays(expr: Expression, values: Mapping[str, Any]) -> Any:
    """The value of `expr` with `values` bound to arrays (real or complex) or numbers, with numpy's
    semantics (1/0 is inf: the caller checks that the result is finite). ExpressionError for an
    unknown name or a function of FUNCTIONS that is not in ARRAY_FUNCTIONS."""
    def ev(node: ast.AST) -> Any:
        if isinstance(node, ast.Constant):
            return np.float64(node.value)
        if isinstance(node, ast.Name):
            if node.id in CONSTANTS:
                return CONSTANTS[node.id]
            if node.id not in values:
                raise ExpressionError(f"unknown name {node.id!r}{suggest(node.id, [*values, *CONSTANTS])}")
            return values[node.id]
        if isinstance(node, ast.UnaryOp):
            return _UNARY[type(node.op)](ev(node.operand))
        if isinstance(node, ast.BinOp):
            return _BINARY[type(node.op)](ev(node.left), ev(node.right))
        name = node.func.id
        if name not in ARRAY_FUNCTIONS:
            raise ExpressionError(f"{name}() is not allowed here: it is not smooth, and omega(phi) and M(omega) "
                                  f"are differentiated; functions: {', '.join(sorted(ARRAY_FUNCTIONS))}")
        return ARRAY_FUNCTIONS[name](*(ev(a) for a in node.args))
    with np.errstate(all="ignore"):
        return ev(expr.tree.body)


@functools.lru_cache(maxsize=1024)
def parse(text: str) -> Expression:
    """Check `text` and return it as an Expression; ExpressionError says what is not allowed.
    Cached (the designs of a sweep read the same expressions; an Expression is never changed)."""
    if len(text) > MAX_EXPRESSION:
        raise ExpressionError(f"{len(text)} characters, at most {MAX_EXPRESSION}")
    if not text.strip():
        raise ExpressionError("empty")
    try:
        tree = ast.parse(text.strip(), mode="eval")
    except SyntaxError as exc:
        raise ExpressionError(f"syntax error: {exc.msg}") from None
    except (RecursionError, MemoryError, ValueError):
        raise ExpressionError("nested too deeply") from None
    names: set[str] = set()
    for node in ast.walk(tree):
        _check_node(node, names)
    return Expression(text, tree, frozenset(names) - set(CONSTANTS))


def _check_node(node: ast.AST, names: set[str]) -> None:
    if isinstance(node, (ast.Expression, ast.Load, *_BINARY, *_UNARY)):
        return
    if isinstance(node, ast.Constant):
        if isinstance(node.value, bool) or not isinstance(node.value, (int, float)):
            raise ExpressionError(f"{type(node.value).__name__} literal {node.value!r:.40} is not allowed "
                                  f"(only numbers)")
        if not _finite_number(node.value):
            raise ExpressionError(f"{shown_number(node.value)} is too large (overflow)")
    elif isinstance(node, ast.Name):
        if node.id in FUNCTIONS:
            return          # checked as a call's function
        names.add(node.id)
    elif isinstance(node, ast.BinOp):
        if type(node.op) not in _BINARY:
            raise ExpressionError(f"operator {type(node.op).__name__} is not allowed (only + - * / **)")
    elif isinstance(node, ast.UnaryOp):
        if type(node.op) not in _UNARY:
            raise ExpressionError(f"operator {type(node.op).__name__} is not allowed (only + - * / **)")
    elif isinstance(node, ast.Call):
        f = node.func
        if not isinstance(f, ast.Name) or f.id not in FUNCTIONS:
            called = f.id if isinstance(f, ast.Name) else _WHAT.get(type(f), type(f).__name__)
            raise ExpressionError(f"call of {called!r} is not allowed{suggest(called, FUNCTIONS)}; "
                                  f"functions: {', '.join(sorted(FUNCTIONS))}")
        if node.keywords:
            raise ExpressionError(f"{f.id}() takes positional arguments only")
        n = FUNCTIONS[f.id][1]
        if n is not None and len(node.args) != n:
            raise ExpressionError(f"{f.id}() takes {n} argument{'s' if n > 1 else ''}, got {len(node.args)}")
        if n is None and len(node.args) < 2:
            raise ExpressionError(f"{f.id}() takes at least 2 arguments, got {len(node.args)}")
    else:
        what = _WHAT.get(type(node), type(node).__name__)
        raise ExpressionError(f"{what} not allowed; an expression has {_ALLOWED}")
    if isinstance(node, ast.Name) and node.id.startswith("__"):
        raise ExpressionError(f"name {node.id!r} is not allowed")


def _eval(node: ast.AST, values: Mapping[str, float]) -> float:
    if isinstance(node, ast.Constant):
        return _checked(float(node.value))
    if isinstance(node, ast.Name):
        if node.id in CONSTANTS:
            return CONSTANTS[node.id]
        if node.id in FUNCTIONS:
            raise ExpressionError(f"{node.id!r} is a function: call it, {node.id}(...)")
        if node.id not in values:
            raise ExpressionError(f"unknown name {node.id!r}{suggest(node.id, [*values, *CONSTANTS])}")
        return values[node.id]
    if isinstance(node, ast.UnaryOp):
        return _UNARY[type(node.op)](_eval(node.operand, values))
    if isinstance(node, ast.BinOp):
        a, b = _eval(node.left, values), _eval(node.right, values)
        if isinstance(node.op, ast.Pow) and abs(b) > MAX_EXPONENT:
            raise ExpressionError(f"exponent {b:g} is too large (|exponent| <= {MAX_EXPONENT:g})")
        if isinstance(node.op, ast.Pow) and a < 0 and b != int(b):
            raise ExpressionError(f"({a:g}) ** {b:g}: a negative number to a fractional power is not real")
        return _checked(_BINARY[type(node.op)](a, b))
    if isinstance(node, ast.Call):
        return _checked(float(FUNCTIONS[node.func.id][0](*(_eval(a, values) for a in node.args))))
    raise ExpressionError(f"{type(node).__name__} not allowed")     # parse() lets none through


def _finite_number(x: float) -> bool:
    """Finite, also as a float (an integer beyond 1.8e308 is not)."""
    try:
        return math.isfinite(x)
    except OverflowError:
        return False


def shown_number(x: Any) -> str:
    """`x` for a message: an integer too long to show as its digit count ("an integer of 401 digits")."""
    if isinstance(x, int) and not isinstance(x, bool) and x.bit_length() > 64:
        return f"an integer of {len(str(abs(x))) if x.bit_length() < 10_000 else 'over 3000'} digits"
    return repr(x)


def _checked(x: float) -> float:
    if not math.isfinite(x):
        raise ExpressionError(f"the result {x} is not a finite number")
    return x


def _arith_message(exc: Exception) -> str:
    if isinstance(exc, ZeroDivisionError):
        return "division by zero"
    if isinstance(exc, OverflowError):
        return "the result is too large (overflow)"
    return f"math domain error ({exc})" if "domain" in str(exc) else str(exc)


#: "Did you mean": names longer than this are not compared, nor candidates of a length more than
#: 3 apart, and at most SUGGEST_CANDIDATES candidates: a suggestion costs at most about
#: SUGGEST_CANDIDATES x SUGGEST_LENGTH^2 steps; and at most SUGGESTIONS are made while one model
#: is read (`suggestion_budget`), whatever the file holds.
SUGGEST_LENGTH, SUGGEST_CANDIDATES, SUGGESTIONS = 64, 50, 50
_SUGGESTIONS_LEFT: ContextVar[list[int] | None] = ContextVar("suggestions_left", default=None)


@contextmanager
def suggestion_budget(n: int = SUGGESTIONS) -> Iterator[None]:
    """At most `n` suggestions (`suggest`) in the block; after them, none."""
    token = _SUGGESTIONS_LEFT.set([n])
    try:
        yield
    finally:
        _SUGGESTIONS_LEFT.reset(token)


def suggest(name: str, valid) -> str:
    """" (did you mean 'mass'?)" when `name` is a near miss of one of `valid`, else ""."""
    left = _SUGGESTIONS_LEFT.get()
    if len(name) > SUGGEST_LENGTH or (left is not None and left[0] <= 0):
        return ""
    if left is not None:
        left[0] -= 1
    near = [v for v in map(str, valid) if abs(len(v) - len(name)) <= 3][:SUGGEST_CANDIDATES]
    close = difflib.get_close_matches(name, near, n=1, cutoff=0.6)
    return f" (did you mean {close[0]!r}?)" if close else ""



# ----------------------------------------------------------------------------- a table of parameters

def resolve(raw: Mapping[str, Any]) -> tuple[dict[str, float], dict[str, str]]:
    """Evaluate named values that may read each other in any order.

    `raw`: name -> a number or an expression string. Returns (values of those that evaluate,
    name -> problem of those that do not). A cycle is refused naming it ("a -> b -> a"); a value
    that reads a failed one is refused naming it."""
    values: dict[str, float] = {}
    problems: dict[str, str] = {}
    parsed: dict[str, Expression] = {}
    for name, x in raw.items():
        if isinstance(x, str):
            try:
                parsed[name] = parse(x)
            except ExpressionError as exc:
                problems[name] = f'expression "{x}": {exc}'
        elif isinstance(x, (int, float)) and not isinstance(x, bool) and _finite_number(x):
            values[name] = float(x)
        elif isinstance(x, int) and not isinstance(x, bool):
            problems[name] = f"{shown_number(x)} is too large for a floating-point number"
        else:
            problems[name] = f"expected a number or an expression string, got {x!r:.60}"
    state: dict[str, int] = {}          # 1: being evaluated, 2: done

    def finish(name: str) -> None:
        e = parsed[name]
        if name not in problems:
            bad = sorted(d for d in e.names if d in problems)
            if bad:
                problems[name] = f'expression "{e.text}": reads {", ".join(map(repr, bad))}, which has an error'
            else:
                try:
                    values[name] = e(values)
                except ExpressionError as exc:
                    problems[name] = f'expression "{e.text}": {exc}'
        state[name] = 2

    def deps(name: str) -> Iterator[str]:
        return iter(sorted(d for d in parsed[name].names if d in parsed))

    for start in parsed:                # depth first, with a stack of its own: 1000 parameters in a chain
        if state.get(start) == 2 or start in problems:
            continue
        path, todo = [start], [deps(start)]
        state[start] = 1
        while path:
            dep = next(todo[-1], None)
            if dep is None:
                todo.pop()
                finish(path.pop())
            elif state.get(dep) == 1:
                cycle = tuple(path[path.index(dep):]) + (dep,)
                for n in cycle[:-1]:
                    problems.setdefault(n, f'expression "{raw[n]}": cycle {" -> ".join(cycle)}')
            elif state.get(dep) != 2 and dep not in problems:
                state[dep] = 1
                path.append(dep)
                todo.append(deps(dep))
    return {n: values[n] for n in raw if n in values}, problems
