"""The independent route for `kinetostat.sensitivity`: central differences of the outputs with respect
to one model parameter, Richardson-extrapolated in float64.

The model file is loaded again with the parameter moved to p ± h, p ± h/2, p ± h/4
(`kinetostat.load(..., parameters={name: value})`, as a design sweep loads its designs: a parameter
that other parameters' expressions use moves them too), and analysed at the same crank angles. The
central differences D(h) = (f(p + h) − f(p − h)) / 2h carry an error c₂h² + c₄h⁴ + …; two steps of
Richardson's extrapolation remove the h² and h⁴ terms:

    D₁(h) = (4 D(h/2) − D(h)) / 3,    D₂ = (16 D₁(h/2) − D₁(h)) / 15,

and |D₂ − D₁(h/2)| (the error of the less extrapolated value, so an upper bound of D₂'s in the
asymptotic range) is the route's own error estimate. Its step is REL_STEP of |p| (an absolute
REL_STEP where p = 0): truncation then falls to ~1e-18 of the derivative, and rounding (≈ 1e-16 of
the output over h/2, times the extrapolation's weights) stays near 1e-12 of the output per unit
of p. Nothing of `kinetostat.sensitivity` is used: only the solver, run on reloaded models.

The outputs: "M_bal" (N,) and, for a working machine, "F_bal" (N,); "R_i_j" (N, 2) for every pair
(i, j) as `Analysis.reaction(i, j)` gives it (the model's order of the pair's links).

`agreement(sens, mech, cd)` compares a Sensitivity with this route: per output, the largest difference
over the cycle relative to the largest derivative over the cycle (`scale`, `relative_difference`).

May use: kinetostat, numpy. Never the engines or the report.
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any, Mapping

import numpy as np

import kinetostat

#: The largest step h of the differences, relative to |p| (absolute where p = 0).
REL_STEP = 1e-3
#: An output whose largest derivative over the cycle stays below this fraction of its peak / |p| (an
#: elasticity under 1e-4: a moment of inertia at constant crank speed, a load that cancels) is judged on
#: that scale instead: the differences resolve ~1e-13 of peak / |p|, so 1e-8 of it stays judged.
INDEPENDENT = 1e-4


@dataclass(frozen=True)
class CentralDifference:
    """d output / d `param` at the crank angles `phi_deg` by Richardson-extrapolated central differences."""

    param: str
    value: float                      # the nominal value of the parameter (model units)
    step: float                       # the largest step h, model units of the parameter
    phi_deg: np.ndarray               # (N,) deg
    outputs: Mapping[str, np.ndarray]      # nominal outputs: "M_bal" (N,), "F_bal" (N,), "R_i_j" (N, 2)
    derivative: Mapping[str, np.ndarray]   # the same names: output units per unit of the parameter
    error: Mapping[str, float]             # the route's own error estimate, max over the cycle, same units


def outputs(res: Any, mech: kinetostat.Mechanism) -> dict[str, np.ndarray]:
    """The outputs this route differentiates, of one Analysis: M_bal, F_bal (a working machine), every R_ij."""
    out = {"M_bal": np.asarray(res.balancing_moment, float)}
    if mech.drive.kind == "machine":
        out["F_bal"] = np.asarray(res.balancing_force, float)
    for p in mech.pairs:
        i, j = p.links
        out[f"R_{i}_{j}"] = np.asarray(res.reaction(i, j), float)
    return out


def _analysed(model: str | Path, param: str, value: float, phi_deg: np.ndarray) -> dict[str, np.ndarray]:
    mech = kinetostat.load(model, parameters={param: value})
    res = kinetostat.analyze(mech, phi_deg=phi_deg)
    if np.any(res.singular):
        raise ValueError(f"{model}: {param} = {value!r}: singular at crank angles "
                         f"{res.phi_deg[res.singular][:5].tolist()} deg; central differences need a regular cycle")
    return outputs(res, mech)


def central_difference(model: str | Path, param: str, *, steps: int = 360, phi_deg: Any = None,
                       rel_step: float = REL_STEP) -> CentralDifference:
    """d output / d `param` of the model file (or bundled model) `model` at `steps` crank angles from 0
    (or at `phi_deg`, deg), by central differences at h, h/2, h/4 extrapolated twice (module docstring).
    `param`: a name of the model's [parameters], or "g". ValueError where it is neither."""
    base = kinetostat.load(model)
    values = {**base.parameters, "g": base.g}
    if param not in values:
        raise ValueError(f"{model}: {param!r} is not a parameter of the model (its parameters: "
                         f"{', '.join(values)})")
    phi = (np.arange(steps) * (360.0 / steps) if phi_deg is None else np.asarray(phi_deg, float))
    p = float(values[param])
    h = rel_step * (abs(p) if p != 0 else 1.0)
    nominal = _analysed(model, param, p, phi)

    def diff(step: float) -> dict[str, np.ndarray]:
        up, down = _analysed(model, param, p + step, phi), _analysed(model, param, p - step, phi)
        return {k: (up[k] - down[k]) / (2 * step) for k in nominal}

    d = [diff(h), diff(h / 2), diff(h / 4)]
    d1 = [{k: (4 * b[k] - a[k]) / 3 for k in nominal} for a, b in zip(d, d[1:])]
    d2 = {k: (16 * d1[1][k] - d1[0][k]) / 15 for k in nominal}
    error = {k: float(np.max(np.abs(d2[k] - d1[1][k]))) for k in nominal}
    return CentralDifference(param, p, h, phi, nominal, d2, error)


def scale(cd: CentralDifference, name: str) -> float:
    """The scale the output `name`'s derivative is judged on: max over the cycle |cd| (every component);
    where the output does not depend on the parameter (max |cd| <= INDEPENDENT * peak / |p|), peak / |p|
    (per unit of p; peak where p = 0), peak being max |output| over the cycle, for a reaction that of
    every pair's reactions (as validation/stability.py measures reactions: a pair whose load cancels, as
    the main bearing of an opposed twin, carries the rounding of the forces that cancel)."""
    names = [k for k in cd.outputs if k.startswith("R_")] if name.startswith("R_") else [name]
    peak = max(float(np.max(np.abs(cd.outputs[k]))) for k in names) / (abs(cd.value) or 1.0)
    return max(float(np.max(np.abs(cd.derivative[name]))), INDEPENDENT * peak) or 1.0


def relative_difference(exact: np.ndarray, cd: CentralDifference, name: str) -> float:
    """max over the cycle |exact - cd| of the output `name` over its `scale`."""
    ref = cd.derivative[name]
    return float(np.max(np.abs(np.asarray(exact, float).reshape(ref.shape) - ref)) / scale(cd, name))


def route_error(cd: CentralDifference, name: str) -> float:
    """The route's own error estimate of the output `name`'s derivative over its `scale`."""
    return cd.error[name] / scale(cd, name)


def exact_derivatives(sens: Any, mech: kinetostat.Mechanism, param: str) -> dict[str, np.ndarray]:
    """The outputs of `outputs` (same names) differentiated by `sens`, a `kinetostat.sensitivity` result."""
    out = {"M_bal": np.asarray(sens.balancing_moment[param], float)}
    if mech.drive.kind == "machine":
        out["F_bal"] = np.asarray(sens.balancing_force[param], float)
    for p in mech.pairs:
        i, j = p.links
        out[f"R_{i}_{j}"] = np.asarray(sens.reaction(i, j)[param], float)
    return out


def agreement(sens: Any, mech: kinetostat.Mechanism, cd: CentralDifference) -> dict[str, float]:
    """Per output: `relative_difference` of `sens`'s derivative to `cd.param` against the route's."""
    exact = exact_derivatives(sens, mech, cd.param)
    return {name: relative_difference(exact[name], cd, name) for name in cd.derivative}
