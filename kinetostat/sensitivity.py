"""Exact design sensitivities (forward mode): the derivatives of the kinematics, of every reaction
and of the balancing load by the model's named parameters, at every crank angle.

The same program that `analyze` runs (`program.motion_program`, `program.statics_program`, over
`groups`' equations) runs here on `Dual` numbers: a value array and its derivatives by the p
parameters, in one object that numpy's ufuncs dispatch to (`__array_ufunc__`), so no equation is
written a second time and nothing is differenced. The parameters enter the design's constants
through the model's expressions (`Mechanism.expressions`, evaluated on duals by
`expressions.over_arrays`) and through the fields they fill (points, masses, moments of inertia,
bodies, g, the crank speed, load values and scales).

The compiled path (`path=`) is `fast_sensitivity`'s kernel over the same source, which writes
the nominal analysis (`fast.analyze_fast`'s) and the derivatives in one pass.

May use: numpy, analysis, applied, expressions, fast_sensitivity, groups, kinematics (its Kinematics), model
(parts.combine, the file's text), planar, program, units; xarray (an optional extra) only inside `to_xarray`.
"""
from __future__ import annotations

import re
from dataclasses import dataclass, replace
from types import MappingProxyType
from typing import TYPE_CHECKING, Any, Mapping

import numpy as np

from . import fast_sensitivity, groups
from .analysis import Analysis, _labelled, _xarray, crank_angles, exact
from .applied import load_wrenches, stroke
from .expressions import ExpressionError, over_arrays, parse
from .kinematics import Kinematics
from .model.parts import Body, combine
from .planar import as_xy, dot_z
from .program import constants, motion_program, run, statics_program
from .model.source import model_text
from .units import parameter_units

if TYPE_CHECKING:
    from .model import Mechanism

__all__ = ["Dual", "Sensitivity", "sensitivity"]


# ----------------------------------------------------------------------------- dual numbers
class Dual:
    """A value array `val` (real or complex, any shape S) with its derivatives `der` (S + (P,)) by
    P real parameters. numpy's ufuncs, and the operators, act on both (the chain rule); a
    comparison compares the values. A complex value's derivative is complex: d(x + iy)/dp."""

    __slots__ = ("val", "der")

    def __init__(self, val: Any, der: Any):
        self.val = np.asarray(val)
        self.der = np.asarray(der)

    # the partial derivative of each holomorphic (or real) ufunc by each argument, from the values
    # (None: 1, the argument's derivative passes as it is)
    _PARTIALS = {
        np.add: lambda a, b, r: (None, None), np.subtract: lambda a, b, r: (None, -1.0),
        np.multiply: lambda a, b, r: (b, a), np.true_divide: lambda a, b, r: (1.0 / b, -r / b),
        np.negative: lambda a, r: (-1.0,), np.positive: lambda a, r: (None,),
        np.sqrt: lambda a, r: (0.5 / r,), np.exp: lambda a, r: (r,), np.log: lambda a, r: (1.0 / a,),
        np.sin: lambda a, r: (np.cos(a),), np.cos: lambda a, r: (-np.sin(a),), np.tan: lambda a, r: (1.0 + r * r,),
        np.arcsin: lambda a, r: (1.0 / np.sqrt(1.0 - a * a),), np.arccos: lambda a, r: (-1.0 / np.sqrt(1.0 - a * a),),
        np.arctan: lambda a, r: (1.0 / (1.0 + a * a),), np.sinh: lambda a, r: (np.cosh(a),),
        np.cosh: lambda a, r: (np.sinh(a),), np.tanh: lambda a, r: (1.0 - r * r,),
        np.square: lambda a, r: (2.0 * a,), np.sign: lambda a, r: (0.0,),
        np.arctan2: lambda y, x, r: (x / (x * x + y * y), -y / (x * x + y * y)),
        np.maximum: lambda a, b, r: (a >= b, a < b), np.minimum: lambda a, b, r: (a <= b, a > b),
        np.power: lambda a, b, r: (b * a ** (b - 1.0), r * np.log(np.where(a > 0, a, 1.0))),   # (exponent's: a > 0)
    }
    _COMPARE = (np.less, np.less_equal, np.greater, np.greater_equal, np.equal, np.not_equal, np.isfinite,
                np.isnan, np.isinf, np.signbit)

    def __array_ufunc__(self, ufunc, method, *inputs, **kwargs):
        if method != "__call__" or kwargs:
            return NotImplemented
        vals = [x.val if isinstance(x, Dual) else x for x in inputs]
        if ufunc in self._COMPARE:
            return ufunc(*vals)
        out = np.asarray(ufunc(*vals))
        ders = [x.der if isinstance(x, Dual) else None for x in inputs]
        if ufunc is np.conjugate:
            return Dual(out, np.conjugate(ders[0]))
        if ufunc is np.absolute:
            a, d = vals[0], ders[0]
            if np.iscomplexobj(a):
                return Dual(out, np.real(np.conjugate(a)[..., None] * d) / out[..., None])
            return Dual(out, np.sign(a)[..., None] * d)
        if ufunc not in self._PARTIALS:
            raise TypeError(f"Dual: no derivative rule for numpy.{ufunc.__name__}")
        if ufunc is np.power and ders[1] is None:          # a constant exponent: no logarithm
            partials = (vals[1] * vals[0] ** (vals[1] - 1.0),)
        else:
            partials = self._PARTIALS[ufunc](*vals, out)
        der = None
        for part, d in zip(partials, ders):
            if d is not None:
                term = d if part is None else np.asarray(part)[..., None] * d
                der = term if der is None else der + term
        if der.shape[:-1] != out.shape:
            der = np.broadcast_to(der, out.shape + der.shape[-1:])
        return Dual(out, der)

    def __array_function__(self, func, types, args, kwargs):
        if func is np.interp and not kwargs:
            return _interp(*args)
        if func is np.where and len(args) == 3 and not kwargs:
            return _where(*args)
        if func in (np.real, np.imag, np.shape) and not kwargs:
            return getattr(args[0], func.__name__)
        if func is np.broadcast_to and not kwargs:
            x, shape = args
            return Dual(np.broadcast_to(x.val, shape), np.broadcast_to(x.der, tuple(shape) + x.der.shape[-1:]))
        return NotImplemented

    def astype(self, dtype) -> "Dual":
        """The value as `dtype` (float: a real value's), its derivatives alike."""
        return Dual(self.val.astype(dtype), self.der.astype(dtype))

    def __add__(self, o): return np.add(self, o)
    def __radd__(self, o): return np.add(o, self)
    def __sub__(self, o): return np.subtract(self, o)
    def __rsub__(self, o): return np.subtract(o, self)
    def __mul__(self, o): return np.multiply(self, o)
    def __rmul__(self, o): return np.multiply(o, self)
    def __truediv__(self, o): return np.true_divide(self, o)
    def __rtruediv__(self, o): return np.true_divide(o, self)
    def __pow__(self, o): return np.power(self, o)
    def __rpow__(self, o): return np.power(o, self)
    def __neg__(self): return np.negative(self)
    def __pos__(self): return self
    def __abs__(self): return np.absolute(self)
    def __eq__(self, o): return np.equal(self, o)
    def __ne__(self, o): return np.not_equal(self, o)
    __hash__ = None
    def __lt__(self, o): return np.less(self, o)
    def __le__(self, o): return np.less_equal(self, o)
    def __gt__(self, o): return np.greater(self, o)
    def __ge__(self, o): return np.greater_equal(self, o)

    def conjugate(self) -> "Dual":
        return np.conjugate(self)

    @property
    def real(self) -> "Dual":
        return Dual(np.real(self.val), np.real(self.der))

    @property
    def imag(self) -> "Dual":
        return Dual(np.imag(self.val), np.imag(self.der))

    @property
    def shape(self) -> tuple[int, ...]:
        return self.val.shape

    def __getitem__(self, idx) -> "Dual":
        return Dual(self.val[idx], self.der[idx])

    def __repr__(self) -> str:
        return f"Dual(shape={self.val.shape}, parameters={self.der.shape[-1]})"


def _interp(x: Any, xp: np.ndarray, fp: Any) -> Dual:
    """np.interp on duals (x and the table's values fp may be): within a segment the slope of the
    segment, so the derivative is exact there; at a knot, the slope of the segment above it (the
    last knot: below); outside the table (held at its end values) 0."""
    xv, fv, xp = value(x), np.asarray(value(fp)), np.asarray(xp, dtype=float)
    out = np.interp(xv, xp, fv)
    P = (x if isinstance(x, Dual) else fp).der.shape[-1]
    der = np.zeros(np.shape(out) + (P,))
    if isinstance(fp, Dual):
        der = der + np.stack([np.interp(xv, xp, fp.der[..., j]) for j in range(P)], axis=-1)
    if isinstance(x, Dual):
        i = np.clip(np.searchsorted(xp, xv, side="right"), 1, len(xp) - 1)
        dx = xp[i] - xp[i - 1]
        slope = np.where((xv < xp[0]) | (xv > xp[-1]) | (dx == 0), 0.0, (fv[i] - fv[i - 1]) / np.where(dx == 0, 1.0, dx))
        der = der + slope[..., None] * x.der
    return Dual(out, der)


def _where(cond: Any, a: Any, b: Any) -> Dual:
    """np.where on duals: the value and the derivatives of the branch taken."""
    cond = np.asarray(cond)
    val = np.where(cond, value(a), value(b))
    P = (a if isinstance(a, Dual) else b).der.shape[-1]
    return Dual(val, np.where(cond[..., None], derivative(a, val.shape, P), derivative(b, val.shape, P)))


def value(x: Any) -> Any:
    """The value of a Dual, or x itself."""
    return x.val if isinstance(x, Dual) else x


def derivative(x: Any, shape: tuple[int, ...], p: int) -> np.ndarray:
    """The derivatives of x (a Dual or a constant: zeros) broadcast to shape + (p,)."""
    return np.broadcast_to(x.der, shape + (p,)) if isinstance(x, Dual) else np.zeros(shape + (p,))


# ----------------------------------------------------------------------------- the design on duals
_POINT = re.compile(r"^(?:frame|link\[id=(\d+)\]\.points)\.(.+)\[([01])\]$")
_LINK = re.compile(r"^link\[id=(\d+)\]\.(mass|weight|I_S)$")
_BODY = re.compile(r"^link\[id=(\d+)\]\.body\[(\d+)\]\.(mass|weight|I_S|com\[([01])\])$")
_LOAD = re.compile(r"^load\[(\d+)\]\.(value|table\.scale)$")
_SPRING = re.compile(r"^spring\[(\d+)\]\.(stiffness|free_length)$")
_GEAR = re.compile(r"^drive\.gear\.(module|z_pinion|z_wheel|y)$")


def _seeded(mech: "Mechanism", params: tuple[str, ...]) -> tuple[dict[str, Any], dict[str, Any]]:
    """The parameters (and g) as duals, column i the derivative by params[i] as `load` with that
    parameter overridden gives it: params[i] moves by 1, the parameters given by expressions follow
    it (also one that is itself in `params`: its own column is 1 there), the others stay; and every
    field written as an expression, on those duals: (name -> value, field path -> value); a value
    that no differentiated parameter reaches stays a float."""
    unit = np.eye(len(params))
    values: dict[str, Any] = {**mech.parameters, "g": float(mech.g)}
    exprs = mech.memo("sensitivity: parsed expressions",
                      lambda: {path: parse(text) for path, (text, _) in mech.expressions.items()})
    pending = [path.split(".", 1)[1] for path in exprs if path.startswith("parameters.")]
    for i, name in enumerate(params):
        if name not in pending:
            values[name] = Dual(values[name], unit[i])
    while pending:                     # in the order of their dependencies
        ready = [n for n in pending if not (exprs[f"parameters.{n}"].names & set(pending))]
        for n in ready:
            v = _evaluate(exprs[f"parameters.{n}"], values, f"parameters.{n}")
            values[n] = v if n not in params else Dual(value(v), derivative(v, (), len(params)) + unit[params.index(n)])
        pending = [n for n in pending if n not in ready]
    fields = {path: _evaluate(e, values, path) for path, e in exprs.items() if not path.startswith("parameters.")}
    if "g" in params:
        fields["mechanism.g"] = values["g"]
    return values, {path: v for path, v in fields.items() if isinstance(v, Dual)}


def _evaluate(e, values: Mapping[str, Any], path: str) -> Any:
    """Expression `e` on the (dual) values; a float where it reads no dual."""
    if not any(isinstance(values.get(n), Dual) for n in e.names):
        return values[path.split(".", 1)[1]] if path.startswith("parameters.") else e(values)
    try:
        return over_arrays(e, values)
    except ExpressionError as exc:
        raise ValueError(f"sensitivity: {path}: cannot differentiate its expression \"{e.text}\": {exc}") from None


def _design(mech: "Mechanism", fields: Mapping[str, Any]) -> tuple[dict[str, Any], list[dict[str, Any]], "Mechanism"]:
    """The constants of the programs (`program.constants`, plus the crank's w_in, e_in) with the
    fields that the parameters reach as duals; the links' local points (dual where moved); and
    `mech` with its loads' values and scales and its springs as duals (for `applied`). ValueError
    naming a field that a differentiated parameter reaches but that this module does not carry."""
    c: dict[str, Any] = {**constants(mech), "w_in": float(mech.drive.omega or 0.0), "e_in": float(mech.drive.eps or 0.0)}
    pts: list[dict[str, Any]] = [dict(p) for p in mech.points_z]
    ids = {link.id: k for k, link in enumerate(mech.links)}
    masses: dict[int, dict[str, Any]] = {}
    bodies: dict[int, dict[int, dict[str, Any]]] = {}
    loads: dict[int, dict[str, Any]] = {}
    springs: dict[int, dict[str, Any]] = {}
    gear: dict[str, Any] = {}
    for path, v in fields.items():
        if m := _POINT.match(path):
            k = ids[int(m[1])] if m[1] else 0
            z = pts[k][m[2]]
            pts[k][m[2]] = v + 1j * z.imag if m[3] == "0" else z.real + 1j * v
        elif m := _LINK.match(path):
            masses.setdefault(ids[int(m[1])], {})[m[2]] = v
        elif m := _BODY.match(path):
            bodies.setdefault(ids[int(m[1])], {}).setdefault(int(m[2]), {})[m[4] or m[3]] = v
        elif m := _LOAD.match(path):
            loads.setdefault(int(m[1]), {})[m[2]] = v
        elif m := _SPRING.match(path):
            springs.setdefault(int(m[1]), {})[m[2]] = v
        elif m := _GEAR.match(path):
            gear[m[1]] = v
        elif path == "mechanism.g":
            c["g"] = v
        elif path in ("drive.rpm", "drive.omega") and mech.drive.law is None:
            c["w_in"] = v * (np.pi / 30) if path == "drive.rpm" else v
        elif path == "drive.eps" and mech.drive.law is None:
            c["e_in"] = v
        else:
            raise ValueError(f"sensitivity: a differentiated parameter enters {path}, whose derivative this version "
                             f"does not carry (points, masses, moments of inertia, bodies, g, the crank speed, load "
                             f"values and table scales, springs, the gear's module, teeth and y); leave that "
                             f"parameter out of params")
    g = c["g"]
    weighed = _weighed(mech) if isinstance(g, Dual) else frozenset()
    for k, link in enumerate(mech.links):
        for name, z in pts[k].items():
            c[f"x{k}_{name}"] = z
        if not k:
            continue
        if link.bodies:
            c[f"mass{k}"], com, c[f"I_S{k}"] = _bodies(link, pts[k], bodies.get(k, {}), g, weighed)
            c[f"x{k}_{link.com}"] = pts[k][link.com] = com
        else:
            given = masses.get(k, {})
            if "mass" in given:
                c[f"mass{k}"] = given["mass"]
            elif "weight" in given or (link.id, None) in weighed:
                c[f"mass{k}"] = given.get("weight", link.mass * float(mech.g)) / g
            if "I_S" in given:
                c[f"I_S{k}"] = given["I_S"]
        if link.com:
            c[f"com{k}"] = pts[k][link.com]
    if gear:
        c["gear_rb"] = replace(mech.drive.gear, **gear).r_b
    view = replace(mech, _derived={}, springs=tuple(replace(sp, **springs.get(n, {})) for n, sp in enumerate(mech.springs)),
                   loads=tuple(replace(ld, value=loads.get(n, {}).get("value", ld.value), table=ld.table if ld.table is None
                                       else replace(ld.table, scale=loads.get(n, {}).get("table.scale", ld.table.scale)))
                               for n, ld in enumerate(mech.loads)))
    return c, pts, view


def _bodies(link, pts: Mapping[str, Any], given: Mapping[int, Mapping[str, Any]], g: Any,
            weighed: frozenset[tuple[int, int | None]]) -> tuple[Any, Any, Any]:
    """Mass, centre of mass (complex) and I_S of a link given by bodies (`parts.combine` on duals)."""
    out = []
    for n, b in enumerate(link.bodies):
        f = given.get(n, {})
        com = _body_com(link, b, pts, f)
        mass = f["mass"] if "mass" in f else f["weight"] / g if "weight" in f else \
            b.mass * float(value(g)) / g if (link.id, n) in weighed else b.mass
        out.append(Body(b.name, mass, (com.real, com.imag), f.get("I_S", b.I_S)))
    m, S, I_S = combine(tuple(out), total=sum)
    return m, S[0] + 1j * S[1], I_S


def _weighed(mech: "Mechanism") -> frozenset[tuple[int, int | None]]:
    """The links (id, None) and bodies (id, index) that the model file gives by their weight: their
    masses are weight / g, so they follow g (the Mechanism keeps the masses only). Empty where the
    model has no file. Memoised per mechanism."""
    def make() -> frozenset[tuple[int, int | None]]:
        import tomllib
        text = model_text(mech)
        out: set[tuple[int, int | None]] = set()
        for t in tomllib.loads(text).get("link", []) if text else []:
            if "weight" in t:
                out.add((t.get("id"), None))
            out.update((t.get("id"), n) for n, b in enumerate(t.get("body", [])) if "weight" in b)
        return frozenset(out)
    return mech.memo("sensitivity: links given by weight", make)


def _body_com(link, b: Body, pts: Mapping[str, Any], f: Mapping[str, Any]) -> Any:
    """A body's centre of mass as a (dual) complex number: its [x, y] fields, or the link's point it
    names (the point with the body's coordinates)."""
    if "com[0]" in f or "com[1]" in f:
        return f.get("com[0]", b.com[0]) + 1j * f.get("com[1]", b.com[1])
    z = complex(*b.com)
    named = [name for name, p in link.points.items() if complex(*p) == z and name != link.com]
    return pts[named[0]] if named else z


# ----------------------------------------------------------------------------- the result
@dataclass(frozen=True)
class Sensitivity:
    """Derivatives of a design's outputs by its parameters at N crank angles (`sensitivity`).
    Each output's accessor gives a read-only mapping parameter -> array (per unit of the
    parameter, in the model's units for it). NaN where the analysis is singular."""
    mech: "Mechanism"
    params: tuple[str, ...]
    values: Mapping[str, float]        # the nominal values of the parameters
    phi_deg: np.ndarray                # (N,) deg
    result: Analysis                   # the nominal analysis at the same angles
    _env: Mapping[str, Any]            # the programs' outputs on duals
    _points: tuple[Mapping[str, Any], ...]   # the links' local points, dual where a parameter moves them

    def __repr__(self) -> str:
        return f"Sensitivity(positions={len(self.phi_deg)}, params={list(self.params)})"

    def _per_param(self, x: Any, vector: bool = False) -> Mapping[str, np.ndarray]:
        """parameter -> the derivative of x (N,), or of the plane vector x as (N, 2), read-only."""
        d = np.array(derivative(x, self.phi_deg.shape, len(self.params)), dtype=complex if vector else float)
        d[self.result.singular] = complex(np.nan, np.nan) if vector else np.nan
        out = {}
        for i, p in enumerate(self.params):
            a = as_xy(d[..., i]) if vector else d[..., i]
            a.flags.writeable = False
            out[p] = a
        return MappingProxyType(out)

    @property
    def error(self) -> np.ndarray:
        """(N,) estimated relative error of the derivatives at each angle: the analysis' error
        (`Analysis.error`) times the largest condition number of a group's plan there (the
        derivative of a solve with that matrix carries its inverse once more); inf where singular."""
        cond = np.where(np.isnan(self.result.cond), np.inf, self.result.cond).max(axis=1, initial=1.0)
        return np.where(self.result.singular, np.inf, self.result.error * np.maximum(cond, 1.0))

    @property
    def balancing_moment(self) -> Mapping[str, np.ndarray]:
        """parameter -> (N,) d M_bal / d p, N m per unit of p."""
        return self._per_param(self._env["M_bal"])

    @property
    def balancing_force(self) -> Mapping[str, np.ndarray]:
        """parameter -> (N, 2) d F_bal / d p (a working machine's), N per unit of p; an engine
        has none: AttributeError."""
        if self.mech.drive.kind != "machine":
            raise AttributeError(f"{self.mech.name!r} is an engine: its drive applies the couple balancing_moment, no force")
        return self._per_param(self._env["F_bal"], vector=True)

    def reaction(self, i: int, j: int) -> Mapping[str, np.ndarray]:
        """parameter -> (N, 2) d R_ij / d p, N per unit of p (R_ij the force of link i on link j)."""
        self.result.reaction(i, j)                  # KeyError naming a link or pair that is not there
        p = self.mech.pair_between(i, j)
        R = self._env[f"R{p.index}"]
        return self._per_param(R if p.links == (i, j) else -R, vector=True)

    def _motion(self, name: str) -> tuple[Any, Any, Any]:
        self.result.position(name)                  # KeyError naming an unknown point
        k = self.mech.point_owner(name)
        x = self._points[k][name]
        if not k:
            return x, 0.0, 0.0
        e = self._env
        return groups.point_motion(e[f"O{k}"], e[f"V{k}"], e[f"A{k}"], e[f"w{k}"], e[f"e{k}"], e[f"rot{k}"], x)

    def position(self, name: str) -> Mapping[str, np.ndarray]:
        """parameter -> (N, 2) d (position of point `name`) / d p, m per unit of p."""
        return self._per_param(self._motion(name)[0], vector=True)

    def velocity(self, name: str) -> Mapping[str, np.ndarray]:
        """parameter -> (N, 2) d (velocity of point `name`) / d p, m/s per unit of p."""
        return self._per_param(self._motion(name)[1], vector=True)

    def acceleration(self, name: str) -> Mapping[str, np.ndarray]:
        """parameter -> (N, 2) d (acceleration of point `name`) / d p, m/s^2 per unit of p."""
        return self._per_param(self._motion(name)[2], vector=True)

    def to_xarray(self):
        """Every output's derivative by every parameter as an xarray Dataset (the optional extra):
        dimensions `param` (its unit in the coordinate `param_unit`), `phi` (deg), `point`, `pair`
        (as `Analysis.to_xarray` names them: coordinates i, j), `xy`. Variables dM_bal (param, phi)
        [N m per unit of p], dR (param, phi, pair, xy) [N per unit of p], dposition, dvelocity,
        dacceleration (param, phi, point, xy) [m, m/s, m/s^2 per unit of p], dF_bal for a working
        machine, error (phi) [1]."""
        xr = _xarray()
        m, base = self.mech, self.result.to_xarray()
        stated = {**parameter_units(m, model_text(m)), "g": "m/s^2"}
        units = [stated[p] for p in self.params]
        per = "per unit of the parameter (its unit: param_unit)"

        def stack(acc, keys) -> np.ndarray:
            return np.stack([np.stack([acc(x)[p] for x in keys], axis=1) for p in self.params])
        data = {
            "dM_bal": _labelled(("param", "phi"), np.stack([self.balancing_moment[p] for p in self.params]),
                                "N m", "world", f"d M_bal / d p, {per}"),
            "error": _labelled(("phi",), self.error, "1", "none", "estimated relative error of the derivatives"),
            "dR": _labelled(("param", "phi", "pair", "xy"), stack(lambda ij: self.reaction(*ij),
                                                                  [pr.links for pr in m.pairs]),
                            "N", "world", f"d R_ij / d p, {per}")}
        for var, acc, unit in (("dposition", self.position, "m"), ("dvelocity", self.velocity, "m/s"),
                               ("dacceleration", self.acceleration, "m/s^2")):
            data[var] = _labelled(("param", "phi", "point", "xy"), stack(acc, m.point_names), unit, "world",
                                  f"d {var[1:]} / d p, {per}")
        if m.drive.kind == "machine":
            data["dF_bal"] = _labelled(("param", "phi", "xy"), np.stack([self.balancing_force[p] for p in self.params]),
                                       "N", "world", f"d F_bal / d p, {per}")
        coords = {"param": ("param", list(self.params)), "param_unit": ("param", units),
                  "value": ("param", [self.values[p] for p in self.params])}
        coords.update({k: base.coords[k] for k in ("phi", "point", "pair", "i", "j", "xy")})
        return xr.Dataset(data, coords=coords, attrs={"mechanism": m.name, "model_file": m.path or ""})


# ----------------------------------------------------------------------------- the analysis on duals
def sensitivity(mech: "Mechanism", params: list[str] | tuple[str, ...] | None = None, steps: int = 360,
                phi_deg=None, path: str = "auto") -> Sensitivity:
    """Exact derivatives of the kinematics, the reactions and the balancing load of `mech` by its
    parameters `params` (names of the model's [parameters], or "g"; None: every parameter) at
    `steps` equal crank angles over a turn, or at `phi_deg` (deg). Forward mode: the analysis'
    own program run on `Dual` numbers (no finite differences). The derivative by p is that of the
    model loaded with p overridden (`load(path, parameters={p: ...})`, as `sweep` sets it): the
    parameters written as expressions of p follow it (d/d r moves l = sqrt(r**2 + c**2)), and
    d/d l, for l itself written as an expression, moves l alone.
    The reactions are the frictionless ones (friction's first approximation). ValueError naming
    an unknown parameter, or a field that a parameter reaches and that is not carried.
    path: "numpy" (the program on `Dual` arrays), "compiled" (`fast_sensitivity`'s kernels over
    the same source, the loads besides gravity evaluated on duals between their two passes; the
    nominal analysis `sens.result` written by the same pass, `fast.analyze_fast`'s to rounding), or
    "auto": the compiled one where `fast_sensitivity.pays` (its kernel held from FAST_MIN angles, else
    from FAST_COLD; a mechanism it takes)."""
    valid = [*mech.parameters, "g"]
    params = tuple(valid[:-1] if params is None else ([params] if isinstance(params, str) else params))
    for p in params:
        if p not in valid:
            raise ValueError(f"sensitivity: {p!r} is not a parameter of the model. Parameters: {', '.join(valid)}")
    if len(set(params)) != len(params):
        raise ValueError(f"sensitivity: params names a parameter twice: {list(params)}")
    if not params:
        raise ValueError("sensitivity: params is empty (the model has no [parameters]: name 'g', or add parameters)")
    if any(g.klass == 3 for g in mech.structure.groups):
        raise ValueError("sensitivity: a class-III group (triad): its positions are Newton's, not a closed form; "
                         "this version differentiates dyads only")
    if path not in ("auto", "numpy", "compiled"):
        raise ValueError(f"sensitivity: path {path!r}: one of 'auto', 'numpy', 'compiled'")
    phi_deg = crank_angles(phi_deg, steps)
    values, fields = _seeded(mech, params)
    _refuse_unsmooth(mech, values)
    c, pts, view = _design(mech, fields)
    if path == "auto":
        path = "compiled" if fast_sensitivity.pays(mech, len(phi_deg), c, len(params)) else "numpy"
    if path == "compiled":
        result, keep = _compiled(mech, c, pts, view, phi_deg, len(params))
        return Sensitivity(mech, params, MappingProxyType({p: float(value(values[p])) for p in params}), phi_deg,
                           result, MappingProxyType(keep), tuple(MappingProxyType(p) for p in pts))
    result = exact(mech, phi_deg, "first")
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        env = _motion(mech, c, np.radians(phi_deg))
        for k in range(1, mech.n_links):
            r, F_i, M_i = groups.inertia(env[f"A{k}"], env[f"w{k}"], env[f"e{k}"], env[f"rot{k}"], env[f"com{k}"],
                                         env[f"mass{k}"], env[f"I_S{k}"])
            W, M_W = groups.weight(r, env[f"mass{k}"], env["g"])
            env[f"F{k}"], env[f"M{k}"] = groups.wrench(W, M_W, F_i, M_i, r)
        _travel_ends(mech, view, c, pts)
        for k, f, m in load_wrenches(view, _dual_motion(mech, env, pts, env["phi"], len(params))) \
                if mech.loads or mech.springs else ():
            if k:
                env[f"F{k}"], env[f"M{k}"] = env[f"F{k}"] + f, env[f"M{k}"] + m
        run(statics_program(mech), env)
    keep = {n: env[n] for n in ("M_bal", "F_bal", *(f"R{p.index}" for p in mech.pairs),
                                *(f"{s}{k}" for s in ("O", "V", "A", "w", "e", "rot") for k in range(1, mech.n_links)))}
    return Sensitivity(mech, params, MappingProxyType({p: float(value(values[p])) for p in params}), phi_deg, result,
                       MappingProxyType(keep), tuple(MappingProxyType(p) for p in pts))


def _compiled(mech: "Mechanism", c: Mapping[str, Any], pts, view: "Mechanism", phi_deg: np.ndarray,
              P: int) -> tuple[Analysis, dict[str, Dual]]:
    """The nominal analysis and the kept outputs by `fast_sensitivity.run`: where `mech` has loads
    besides gravity, those evaluated on the motion kernel's duals (as the numpy path evaluates them)."""
    def loads(motion: dict[str, tuple[np.ndarray, np.ndarray]]) -> tuple[np.ndarray, np.ndarray]:
        env = {n: Dual(*vd) for n, vd in motion.items()}
        _travel_ends(mech, view, c, pts)
        L, N = mech.n_links, len(phi_deg)
        F = [[0.0, 0.0] for _ in range(L)]
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            for k, f, m in load_wrenches(view, _dual_motion(mech, env, pts, np.radians(phi_deg), P)):
                F[k] = [F[k][0] + f, F[k][1] + m]
        cols = [x for k in range(1, L) for x in (np.real(F[k][0]), np.imag(F[k][0]), F[k][1])]
        x, dx = np.empty((len(cols), N)), np.empty((P, len(cols), N))     # dx contiguous: run reshapes it
        for i, col in enumerate(cols):
            x[i], dx[:, i] = value(col), derivative(col, (N,), P).T
        return x, dx

    result, out = fast_sensitivity.run(mech, c, phi_deg, P, loads)
    return result, {n: Dual(*vd) for n, vd in out.items()}


def _motion(mech: "Mechanism", env: dict[str, Any], phi: np.ndarray) -> dict[str, Any]:
    """The motion program run on the (dual) constants `env` at the crank angles `phi` (rad)."""
    env = dict(env, phi=phi)
    if mech.drive.law is not None:
        env["w_in"], env["e_in"] = mech.drive.speed(phi)
    return run(motion_program(mech), env)


@dataclass(frozen=True)
class _DualMotion(Kinematics):
    """Kinematics whose arrays are duals (N, L) read by column (`_Columns`): what `applied` reads of a motion, with a link's
    local point read as the dual the parameters move (found by its nominal coordinates)."""
    local: tuple[Mapping[str, Any], ...] = ()

    def _x(self, k: int, p) -> Any:
        z = complex(p[0], p[1])
        found = [x for x in self.local[k].values() if complex(value(x)) == z]
        moves = [x.der.tolist() if isinstance(x, Dual) else None for x in found]
        if any(d != moves[0] for d in moves):
            raise ValueError(f"sensitivity: link {k} has two points at {z} that the parameters move apart: a load "
                             f"at one of them is ambiguous; move one of them")
        return found[0] if found else z

    def position_z(self, k: int, p) -> Any:
        return groups.place(self.origin_z[:, k], self.rot[:, k], self._x(k, p))

    def velocity_z(self, k: int, p) -> Any:
        return self.point_z(k, p)[1]

    def point_z(self, k: int, p) -> tuple[Any, Any, Any]:
        return groups.point_motion(self.origin_z[:, k], self.v_z[:, k], self.a_z[:, k], self.omega[:, k],
                                   self.eps[:, k], self.rot[:, k], self._x(k, p))


@dataclass(frozen=True)
class _Columns:
    """The per-link (or per-pair) duals stem<k> of a program's environment read as an (N, count)
    dual's columns (rest where absent, or k < start): `[:, k]`, the only way `applied` reads a
    motion, gives column k's (N,) dual and builds nothing else (no (N, count, P) stack)."""
    env: Mapping[str, Any]
    stem: str
    rest: complex
    N: int
    P: int
    start: int = 1

    def __getitem__(self, idx: tuple[slice, int]) -> Dual:
        column = isinstance(idx, tuple) and len(idx) == 2 and idx[0] == slice(None)
        if not (column and isinstance(idx[1], (int, np.integer))):
            raise TypeError(f"sensitivity: a motion's {self.stem} is read by column ([:, k]) only, not {idx!r}")
        k = idx[1]
        x = self.env.get(f"{self.stem}{k}", self.rest) if k >= self.start else self.rest
        return Dual(np.broadcast_to(value(x), (self.N,)), derivative(x, (self.N,), self.P))


def _dual_motion(mech: "Mechanism", env: Mapping[str, Any], pts, phi: np.ndarray, P: int) -> _DualMotion:
    """The motion of the program's environment as `_DualMotion` (unguarded), its arrays `_Columns`."""
    N = len(phi)
    st = lambda stem, rest, start=1: _Columns(env, stem, rest, N, P, start)
    return _DualMotion(phi, st("th", 0.0), st("rot", 1.0 + 0j), st("O", 0j), st("V", 0j), st("A", 0j),
                       st("w", 0.0), st("e", 0.0), st("vs", 0.0, 0), st("as", 0.0, 0),
                       np.zeros((N, 0)), np.zeros(N, bool), np.zeros(N), None, tuple(pts))


def _travel_ends(mech: "Mechanism", view: "Mechanism", c: Mapping[str, Any], pts) -> None:
    """Each travel diagram's stroke ends on duals, kept in `view` where `applied.travel` reads
    them: the extreme projection at the dead centre phi* moves with the parameters as the point
    at phi* does (ds/dphi = 0 there: the envelope rule)."""
    for ld in view.loads:
        if ld.table is None or ld.table.argument != "travel":
            continue
        lo, hi, phi_lo, phi_hi = stroke(mech, ld)
        env = _motion(mech, dict(c), np.array([phi_lo, phi_hi]))
        k = ld.link
        X = groups.place(env[f"O{k}"], env[f"rot{k}"], pts[k][ld.point])
        s = dot_z(X, complex(*(ld.table.axis if ld.table.axis is not None else ld.direction)))
        stroke(view, ld, make=lambda: (s[0], s[1], phi_lo, phi_hi))


def _refuse_unsmooth(mech: "Mechanism", values: Mapping[str, Any]) -> None:
    """ValueError where a differentiated parameter reaches what this version does not carry: a
    law of motion omega(phi) or a characteristic M(omega) written as an expression that reads it
    (they keep the parameters' values; M(omega) itself follows omega)."""
    moved = {n for n, v in values.items() if isinstance(v, Dual)}
    reads = lambda law: sorted(parse(law.expression).names & moved) if law is not None and law.expression else []
    if reads(mech.drive.law):
        raise ValueError(f"sensitivity: the law of motion omega(phi) reads {reads(mech.drive.law)}: this version "
                         f"does not carry its derivative; leave them out of params")
    for n, ld in enumerate(mech.loads):
        if reads(ld.characteristic):
            raise ValueError(f"sensitivity: load {ld.name!r} (load[{n}]): its characteristic M(omega) reads "
                             f"{reads(ld.characteristic)}: this version does not carry that derivative; leave them "
                             f"out of params")
