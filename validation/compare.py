"""The accuracy gate: the solver against every engine route over a full cycle.

`compare(mech, engines=..., steps=...)` builds one scene, runs every requested route, and
returns a `Comparison`: per route and quantity (driving moment, each pair's reaction) the max
absolute error, the max error relative to the cycle's peak, the RMS (relative to the peak),
and pass/fail against the route's tolerance in `TOLERANCES`. An engine that is not installed
is reported as skipped, never passed. The route "reference" needs no engine, only mpmath: the
40-digit re-solution of `reference.py` at a sample of the cycle's angles (`reference.SAMPLE`).

May use: kinetostat, the scene, the reference's SAMPLE (its text), and each route's adapter
(imported when the route runs).
"""
from __future__ import annotations

import importlib
import time
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from kinetostat import Analysis, Mechanism, analyze
from kinetostat.kinetostatics import friction_power, gear_force

from .reference import SAMPLE
from .scene import EngineResult, Scene, build_scene, tracked_points

__all__ = ["ROUTES", "TOLERANCES", "LEVER", "Tolerance", "Row", "Comparison", "compare", "errors", "series",
           "quantity_names", "angle_index", "lever_row"]

#: The check of an internal identity, not a route of ROUTES: Zhukovsky's lever against the
#: balancing moment found group by group (`lever_row`).
LEVER = "lever"


@dataclass(frozen=True)
class Tolerance:
    """Peak-relative tolerance of one route, with the reason for its value."""
    peak_relative: float
    reason: str


#: Every route's tolerance, in one place. Peak-relative: max over the cycle of
#: |engine - solver| divided by max over the cycle of |solver|, per quantity.
TOLERANCES: dict[str, Tolerance] = {
    "pinocchio": Tolerance(1e-9, "constrained inverse dynamics at the solver's exact state: the same "
                                 "equations in another formulation, so rounding only (measured ~1e-13)"),
    "mujoco": Tolerance(1e-9, "MuJoCo's mass matrix, bias forces and equality Jacobian at the exact "
                              "state, solved for torque and constraint forces: rounding only"),
    "mujoco-sim": Tolerance(1e-3, "MuJoCo's own forward dynamics (mujoco.rollout) at 7200 steps per revolution, "
                                  "the crank tied to a clock flywheel: the error is first order in the step "
                                  "(halving with it). Forces measured worst 1.4e-4 (scotch yoke); the velocities "
                                  "of a semi-implicit Euler state lag half a step, pi/7200 = 4.4e-4 of their "
                                  "peak (kinematics measured worst 6.1e-4, a(Y) of the scotch yoke); constraints "
                                  "stay slightly soft (impedance < 1) but the step dominates"),
    "pymunk": Tolerance(4e-3, "pymunk's iterative impulse solver, Richardson extrapolation (order 2) over 720 and "
                              "1440 steps per revolution, at least 50 iterations (raised automatically where a "
                              "run goes unstable): light linkages 2e-7 .. 2e-6, the heavy/light machines 7e-6 .. "
                              "5e-4 (iteration-limited); worst 1.7e-3, the scotch yoke, whose load flips at a "
                              "sample; the public API gives impulse magnitudes, so |M_drive| and |R| are "
                              "compared; positions and velocities of the points, no accelerations"),
    "reference": Tolerance(1e-11, "the whole problem solved again in mpmath at 40 digits (another formulation: "
                                  f"all loop closures at once, one global Newton-Euler system) at {SAMPLE}: "
                                  "the solver's rounding only, measured 2e-16 .. 1.4e-15 on the bundled models "
                                  "and 1.3e-13 on a crank bearing whose small load is the difference of two large opposed gas forces "
                                  "(opposed_twin); 1e-11 leaves room for such cancellation, while a wrong "
                                  "inertia, load or sign shows at 1e-4 .. 1"),
    "lever": Tolerance(1e-11, "an internal identity: the balancing moment from the velocity plan alone "
                              "(Zhukovsky's lever, the power balance) against the one found group by group "
                              "from the reactions, two formulations over the same kinematics: rounding only, "
                              "measured 2.8e-16 .. 8.0e-16 on the bundled models; 1e-11 as for the reference, "
                              "while a wrong inertia, load or sign in one of the two shows at 1e-4 .. 1"),
}


def _route(module: str, func: str, **kw) -> Callable[[Scene], EngineResult]:
    def run(scene: Scene) -> EngineResult:
        mod = importlib.import_module(f".{module}", __package__)
        return getattr(mod, func)(scene, **kw)
    return run


#: route name -> (engine package to import, runner)
ROUTES: dict[str, tuple[str, Callable[[Scene], EngineResult]]] = {
    "pinocchio": ("pinocchio", _route("engine_pinocchio", "solve")),
    "mujoco": ("mujoco", _route("engine_mujoco", "solve")),
    "mujoco-sim": ("mujoco", _route("engine_mujoco", "simulate")),
    "pymunk": ("pymunk", _route("engine_pymunk", "simulate")),
    "reference": ("mpmath", _route("reference", "route")),
}


@dataclass(frozen=True)
class Row:
    """One route x quantity of a comparison."""
    route: str
    quantity: str          # "M_drive", "R(i,j)" (force of i on j), "F_bal", "P_f(i,j)", "x(P)", "v(P)", "a(P)"
    max_abs: float         # N m or N
    peak_relative: float   # max |engine - solver| / max |solver|
    rms_relative: float    # RMS of |engine - solver| / max |solver|
    peak: float            # max |solver| over the cycle (all its finite angles, compared or not)
    tolerance: float
    n_compared: int        # angles compared (the route's angles; NaN ones are left out, and counted)
    n_skipped: int
    unit: str = ""         # unit of max_abs and peak ("N m", "N", ...)
    phi_deg_max: float = float("nan")   # crank angle of the largest |engine - solver|, deg

    @property
    def passed(self) -> bool:
        return bool(self.peak_relative <= self.tolerance) and self.n_compared > 0


@dataclass(frozen=True)
class Comparison:
    """The gate's answer for one mechanism."""
    mech: Mechanism
    res: Analysis
    rows: tuple[Row, ...]
    results: dict[str, EngineResult]
    skipped: dict[str, str] = field(default_factory=dict)   # route -> reason
    failed: dict[str, str] = field(default_factory=dict)    # route -> exception raised by it
    solver_seconds: float = 0.0

    @property
    def passed(self) -> bool:
        """Every compared quantity within tolerance, no route raised, something was compared."""
        return bool(self.rows) and not self.failed and all(r.passed for r in self.rows)

    def to_frame(self):
        import pandas as pd
        cols = ["route", "quantity", "max_abs", "peak_relative", "rms_relative", "peak", "tolerance",
                "n_compared", "n_skipped", "unit", "phi_deg_max"]
        df = pd.DataFrame([[getattr(r, c) for c in cols] for r in self.rows], columns=cols)
        df["passed"] = [r.passed for r in self.rows]
        return df


def angle_index(res: Analysis, phi_deg: np.ndarray) -> np.ndarray:
    """Indices into the solver's angles of the angles `phi_deg` a route was evaluated at."""
    phi_deg = np.asarray(phi_deg, float)
    if phi_deg.shape == res.phi_deg.shape and np.array_equal(phi_deg, res.phi_deg):
        return np.arange(len(phi_deg))
    gap = np.abs(phi_deg[:, None] - res.phi_deg[None, :])
    idx = np.argmin(gap, axis=1) if len(res.phi_deg) else np.zeros(len(phi_deg), int)
    if len(res.phi_deg) == 0 or np.any(gap[np.arange(len(phi_deg)), idx] > 1e-9):
        raise ValueError("the route's angles are not among the solver's angles")
    return idx


#: The point kinematics a route gives, when not all of x, v and a (see the adapter's docstring):
#: pymunk has no accelerations of its own, the 40-digit reference solves forces only.
POINT_KINEMATICS = {"pymunk": "xv", "reference": ""}


def quantity_names(mech: Mechanism, route: str | None = None) -> list[str]:
    """Names of the quantities `errors` compares for `mech` (on `route`: only the point
    kinematics listed in POINT_KINEMATICS; LEVER: the driving moment alone), in its row order."""
    if route == LEVER:
        return ["M_drive"]
    names = ["M_drive"] + [f"R({p.links[0]},{p.links[1]})" for p in mech.pairs]
    if mech.drive.kind == "machine":
        names.append("F_bal")
    if mech.friction is not None:
        names += [f"P_f({p.links[0]},{p.links[1]})" for p in mech.pairs]
    kinds = POINT_KINEMATICS.get(route, "xva")
    for name, _ in tracked_points(mech):
        names += [f"{sym}({name})" for sym in kinds]
    return names


def series(res: Analysis, er: EngineResult) -> list[tuple[str, str, np.ndarray, np.ndarray]]:
    """(quantity, unit, solver (N, d) over all its angles, engine (n, d) at `er.phi_deg`) of every
    quantity compared, d = 1 or 2.

    M_drive and R(i,j): as the engine gives them (magnitudes if `er.magnitudes_only`).
    F_bal (working machines): the mesh force of the engine's own M_drive (`gear_force`) against
    the solver's balancing force. P_f(i,j) (models with friction): seed 003's losses,
    `friction_power`, applied to the engine's reactions against the solver's losses (the
    formulas use |R|, so magnitudes suffice). x, v, a of every tracked point: the engine's own
    kinematics at the state it used (those it gives).
    """
    m = res.mech
    out = [("M_drive", "N m", res.balancing_moment[:, None], er.M_drive[:, None])]
    out += [(f"R({p.links[0]},{p.links[1]})", "N", res.forces.R[:, p.index], er.R[:, p.index]) for p in m.pairs]
    if er.magnitudes_only:
        out = [(q, u, np.linalg.norm(a, axis=-1, keepdims=True), np.linalg.norm(b, axis=-1, keepdims=True))
               for q, u, a, b in out]
    if m.drive.kind == "machine":
        out.append(("F_bal", "N", res.balancing_force, gear_force(m.drive.gear, er.M_drive)))
    if m.friction is not None:
        at = angle_index(res, er.phi_deg)
        kin = res.kin if len(at) == len(res.phi_deg) else analyze(m, phi_deg=res.phi_deg[at]).kin
        P = friction_power(m, kin, er.R)
        out += [(f"P_f({p.links[0]},{p.links[1]})", "W", res.friction_power[:, p.index, None], P[:, p.index, None])
                for p in m.pairs]
    if er.points:
        for n, (name, k) in enumerate(er.points):
            ref = res.kin.point(k, m.links[k].points[name])
            for sym, unit, r, got in zip("xva", ("m", "m/s", "m/s^2"), ref, (er.x, er.v, er.a)):
                if got is not None:
                    out.append((f"{sym}({name})", unit, r, got[:, n]))
    return out


def _kinematic_scales(res: Analysis, er: EngineResult) -> dict[str, float]:
    """'x', 'v', 'a' -> the largest solver value of that kind over the cycle and all of the
    engine's points: the scale of every kinematics row (a point on a fixed pivot, such as a
    balanced crank's centre of mass, has no peak of its own)."""
    if not er.points:
        return {}
    m = res.mech
    ref = np.array([res.kin.point(k, m.links[k].points[name]) for name, k in er.points])   # (P, 3, N, 2)
    peaks = np.nanmax(np.linalg.norm(ref, axis=-1), axis=(0, 2), initial=0.0)
    return dict(zip("xva", peaks))


def errors(res: Analysis, er: EngineResult, tolerance: float, route: str) -> list[Row]:
    """Error rows of one engine result against the solver's answer (quantities: `series`).

    Relative to the quantity's peak over the cycle; a kinematics row (x, v, a of a point)
    relative to the largest of its kind over all points (`Row.peak` is then that scale). A route
    evaluated at some of the solver's angles is compared there, against the peak over all of them."""
    rows = []
    at = angle_index(res, er.phi_deg)
    kin_scale = _kinematic_scales(res, er)
    for name, unit, cycle, got in series(res, er):
        finite = np.isfinite(cycle).all(axis=-1)
        peak = float(np.max(np.linalg.norm(cycle[finite], axis=-1))) if finite.any() else 0.0
        peak = kin_scale.get(name[0], peak) if name[1] == "(" and name[0] in "xva" else peak
        scale = peak if peak > 0 else 1.0
        ref = cycle[at]
        ok = np.isfinite(got).all(axis=-1) & finite[at]
        err = np.linalg.norm(got[ok] - ref[ok], axis=-1)
        rows.append(Row(route, name, float(err.max()) if ok.any() else np.nan,
                        float(err.max() / scale) if ok.any() else np.nan,
                        float(np.sqrt(np.mean(err**2)) / scale) if ok.any() else np.nan,
                        peak, tolerance, int(ok.sum()), int((~ok).sum()), unit,
                        float(res.phi_deg[at][ok][np.argmax(err)]) if ok.any() else np.nan))
    return rows


def lever_row(res: Analysis) -> Row:
    """The row of LEVER: `res.lever_moment` against `res.balancing_moment` (quantity "M_drive",
    N m) over the cycle, peak-relative as `errors` measures, against TOLERANCES[LEVER]."""
    tol = TOLERANCES[LEVER].peak_relative
    M, d = res.balancing_moment, res.lever_discrepancy
    finite = np.isfinite(M)
    ok = finite & np.isfinite(d)
    peak = float(np.max(np.abs(M[finite]))) if finite.any() else 0.0
    scale = peak if peak > 0 else 1.0
    err = np.abs(d[ok])
    if not ok.any():
        return Row(LEVER, "M_drive", np.nan, np.nan, np.nan, peak, tol, 0, len(M), "N m")
    return Row(LEVER, "M_drive", float(err.max()), float(err.max() / scale), float(np.sqrt(np.mean(err**2)) / scale),
               peak, tol, int(ok.sum()), int((~ok).sum()), "N m", float(res.phi_deg[ok][np.argmax(err)]))


def available(route: str) -> str | None:
    """None if the route's engine imports, else the reason it is skipped."""
    package = ROUTES[route][0]
    try:
        importlib.import_module(package)
    except ImportError as exc:
        return f"{package} not installed ({exc})"
    return None


def unsupported(route: str, mech: Mechanism) -> str | None:
    """None if the route can check `mech`, else why it is skipped: the simulations follow a crank
    turning at one constant speed > 0 (not a law of motion omega(phi), not standstill); the
    mpmath reference integrates the constant omega and eps itself and evaluates the loads it
    knows (not a motor characteristic or a damper). The exact routes (pinocchio, mujoco) take q,
    v, a and the applied loads from the scene, so they check every model."""
    dr = mech.drive
    if route in ("mujoco-sim", "pymunk"):
        if dr.law is not None:
            return "the crank follows a law of motion omega(phi): a simulation here drives it at one constant speed"
        if dr.omega == 0:
            return "standstill (omega = 0): a simulation has no motion to follow"
    if route == "reference":
        if dr.law is not None:
            return "the crank follows a law of motion omega(phi): the reference integrates a constant omega and eps"
        kinds = sorted({"motor characteristic" if ld.characteristic is not None else "damper"
                        for ld in mech.loads if ld.kind == "damper" or ld.characteristic is not None})
        if kinds:
            return f"speed-dependent loads ({', '.join(kinds)}): the reference evaluates only the loads it knows"
    return None


def compare(mech: Mechanism, engines=tuple(ROUTES), steps: int = 360, res: Analysis | None = None,
            tolerances: dict[str, Tolerance] | None = None) -> Comparison:
    """Cross-validate `mech` (or a given solver result `res` of it) against engine routes.

    `engines`: route names from ROUTES. `res`: the solver's answer to check (default: analyze);
    passing a deliberately wrong one shows that the gate can fail.
    """
    unknown = [e for e in engines if e not in ROUTES]
    if unknown:
        raise ValueError(f"unknown engine route(s) {unknown}. Valid names: {list(ROUTES)}")
    tol = TOLERANCES if tolerances is None else tolerances
    t0 = time.perf_counter()
    if res is None:                       # the engines have no f r |R| friction: the first approximation
        res = analyze(mech, steps=steps, friction="first")
    solver_seconds = time.perf_counter() - t0
    scene = build_scene(mech, res=res)
    rows, results, skipped, failed = [], {}, {}, {}
    for route in engines:
        why = available(route) or unsupported(route, mech)
        if why:
            skipped[route] = why
            continue
        try:
            er = ROUTES[route][1](scene)
        except Exception as exc:   # one broken route must not hide the others' verdicts
            failed[route] = f"{type(exc).__name__}: {exc}"
            continue
        results[route] = er
        rows += errors(res, er, tol[route].peak_relative, route)
    return Comparison(mech, res, tuple(rows), results, skipped, failed, solver_seconds)
