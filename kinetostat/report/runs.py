"""A validation run: the solver's cycle of one model checked route by route, and against the
model's published values; every check of a run as one `Check`.

May use: numpy, the solver, and the harness (`kinetostat_validation`), imported inside the
functions that need it. Never matplotlib.
"""
from __future__ import annotations

import logging
import time
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Sequence

import numpy as np

from .._io import safe_name
from ..analysis import Analysis, friction_method
from ..solve import analyze
from ..model import Mechanism
from .published import PublishedCheck, published_rows

log = logging.getLogger(__name__)

#: The route name under which a model's published values are checked.
PUBLISHED_ROUTE = "published"
#: The route name of the internal identity checked in every run: Zhukovsky's lever against the
#: balancing moment found group by group (`kinetostat_validation.compare.LEVER`, `lever_row`).
LEVER_ROUTE = "lever"

#: What a route's checks rest on (JUnit property "trust", JSON "trust"): an independent engine,
#: the 40-digit re-solution, an internal identity, or (route "published") the source's printed value.
TRUST: dict[str, str] = {
    "pinocchio": "independent engine: Pinocchio's constrained inverse dynamics at the solver's state",
    "mujoco": "independent engine: MuJoCo's inverse dynamics at the solver's state",
    "mujoco-sim": "independent engine: MuJoCo's own forward simulation of the cycle",
    "pymunk": "independent engine: pymunk's impulse solver simulating the cycle",
    "reference": "40-digit re-solution: the whole problem solved again in mpmath, another formulation",
    LEVER_ROUTE: "internal identity: Zhukovsky's lever vs group-by-group",
}


def trust(route: str, source: str = "") -> str:
    """What a check of `route` rests on; `source`: where a published value is printed."""
    if route == PUBLISHED_ROUTE:
        return f"published value: {source}" if source else "published value"
    return TRUST.get(route, f"route {route}")


def quantities(mech: Mechanism, route: str | None = None) -> list[str]:
    """The quantities compare() checks (on `route`), named as its rows name them: the driving
    moment, every reaction, a machine's F_bal, the friction losses P_f(i,j) where the model has
    friction, and x, v, a of every tracked point (only those a route gives, POINT_KINEMATICS;
    `kinetostat_validation.compare.quantity_names`)."""
    from kinetostat_validation.compare import quantity_names

    return quantity_names(mech, route)


@dataclass(frozen=True)
class Check:
    """One check of a validation run: a route's error on one quantity, or one published value."""
    model: str           # the model's stem
    route: str           # engine route, "reference", or "published"
    quantity: str        # "M_drive", "R(i,j)", or the published symbol
    error: float         # what the tolerance bounds: peak-relative (routes), relative or deg (published)
    measure: str         # "peak_relative", "relative" or "deg": the kind of `error` and `tolerance`
    tolerance: float
    max_abs: float       # routes: max |route - solver|; published: |exact - published|; in `unit`
    unit: str
    phi_deg: float       # crank angle of the largest error (routes) or of the exact value (published), deg
    passed: bool
    detail: str          # one line for people
    trust: str = ""      # what the check rests on (`trust`)

    @property
    def name(self) -> str:
        return f"{self.model}.{self.route}.{self.quantity}"


def _row_check(model: str, r) -> Check:
    return Check(model, r.route, r.quantity, r.peak_relative, "peak_relative", r.tolerance, r.max_abs, r.unit,
                 r.phi_deg_max, r.passed,
                 f"peak-relative error {r.peak_relative:.3e} (tolerance {r.tolerance:.1e}), max abs {r.max_abs:.6g} "
                 f"{r.unit} at phi = {r.phi_deg_max:g} deg, peak {r.peak:.6g} {r.unit}, {r.n_compared} angles "
                 f"compared, {r.n_skipped} left out", trust(r.route))


def _published_check(model: str, c: PublishedCheck) -> Check:
    e = c.entry
    where = f"{e.reduce} over {len(e.angles)} angles" if e.reduce else f"at phi = {e.angles[0]:g} deg"
    diff = f"{c.difference:+.3g} deg" if c.by_angle else f"{100 * c.difference:+.3f} %"
    tol = f"{e.tolerance:g} deg" if c.by_angle else f"{100 * e.tolerance:g} %"
    return Check(model, PUBLISHED_ROUTE, e.symbol, c.error, "deg" if c.by_angle else "relative", e.tolerance,
                 abs(c.exact - e.value), e.unit, c.phi_deg, c.passed,
                 f"published {e.value:g} {e.unit}, exact {c.exact:.6g} {e.unit} ({where}): {diff} "
                 f"(tolerance {tol}); source: {e.source}", trust(PUBLISHED_ROUTE, e.source))


@dataclass
class ModelRun:
    """The solver's cycle of one model checked route by route (one `compare` call per route)."""
    mech: Mechanism
    res: Analysis
    path: Path | None = None
    engines: tuple[str, ...] = ()                       # the routes run: LEVER_ROUTE, then the engine routes
    rows: list = field(default_factory=list)            # kinetostat_validation.compare.Row
    results: dict = field(default_factory=dict)         # route -> EngineResult
    skipped: dict[str, str] = field(default_factory=dict)   # route -> reason
    errors: dict[str, str] = field(default_factory=dict)    # route -> "ExcType: message"
    warnings: list[str] = field(default_factory=list)       # one line each, de-duplicated
    seconds: dict[str, float] = field(default_factory=dict)  # route -> wall time of its compare call
    tolerances: dict = field(default_factory=dict)      # route -> Tolerance
    solver_seconds: float = 0.0                         # wall time of analyze() over the cycle
    published: list[PublishedCheck] = field(default_factory=list)   # the model's published values
    analyses: dict = field(default_factory=dict)        # (angles, friction method) -> Analysis (`at`)

    def at(self, phi_deg: Sequence[float], friction: str | None = None) -> Analysis:
        """The model's analysis at the crank angles `phi_deg` (deg) by the friction method
        `friction` (`analyze`'s; None: the model's), made once in a run: the parts of a report at
        the same angles and method (figures, friction section, published values) share it, and
        `res` stands for its own angles and method. The analysis' warnings are raised by the call
        that makes it."""
        key = (tuple(float(x) for x in phi_deg), friction_method(self.mech, friction) if self.mech.friction else "none")
        if key not in self.analyses:
            self.analyses[key] = analyze(self.mech, phi_deg=list(key[0]), friction=friction)
        return self.analyses[key]

    @property
    def stem(self) -> str:
        """The model's name in file names and check names: its file's stem (or its name), only
        ASCII letters, digits, '_' and '-' (`kinetostat._io.safe_name`)."""
        return safe_name(self.path.stem) if self.path is not None else safe_name(self.mech.name).lower()

    @property
    def failed(self) -> list:
        """The routes' error rows beyond tolerance."""
        return [r for r in self.rows if not r.passed]

    @property
    def checks(self) -> list[Check]:
        """Every check that ran: the routes' error rows, then the published values."""
        return [_row_check(self.stem, r) for r in self.rows] + [_published_check(self.stem, c) for c in self.published]

    @property
    def passed(self) -> bool:
        """No check beyond tolerance and no route that raised (skipped routes do not count)."""
        return not self.errors and all(c.passed for c in self.checks)

    @property
    def checked(self) -> bool:
        """A check beyond the internal lever identity ran: an engine route, the reference or a
        published value (the identity alone checks nothing against an independent source)."""
        return any(c.route != LEVER_ROUTE for c in self.checks)

    def status(self, route: str) -> str:
        if route in self.errors:
            return "ERROR"
        if route in self.skipped:
            return "SKIPPED"
        rows = [r for r in self.rows if r.route == route]
        return "PASS" if rows and all(r.passed for r in rows) else "FAIL"

    def worst(self, route: str) -> float | None:
        vals = [r.peak_relative for r in self.rows if r.route == route]
        if not vals:
            return None
        return float(np.nanmax(vals)) if np.any(np.isfinite(vals)) else float("nan")


def _one_line(exc: BaseException) -> str:
    msg = str(exc).strip().splitlines()
    return f"{type(exc).__name__}: {msg[0] if msg else ''}".rstrip(": ")


def _record(caught, where: str, out: list[str]) -> None:
    for w in caught:
        line = f"{where}{w.category.__name__}: {str(w.message).splitlines()[0] if str(w.message) else ''}"
        if line not in out:
            out.append(line)


def run_validation(mech: Mechanism, engines: Sequence[str], steps: int = 360, res: Analysis | None = None,
                   path: str | Path | None = None, on_route: Callable[[str], None] | None = None,
                   level: int = logging.DEBUG) -> ModelRun:
    """Check `res` (default: `analyze(mech, steps=steps)`) by the internal lever identity (route
    LEVER_ROUTE, always), against every route in `engines`, and against the model's published
    values (an exception there is the error of route "published").

    Each route runs in its own `compare(..., engines=[route], res=res)` call; an exception of a
    route is recorded in `errors` (that route fails) and the other routes still run. Warnings
    raised meanwhile are collected, one line each, in `warnings`. `on_route(route)` is called
    after each route (progress bars); each route's verdict and time is logged at `level`
    (DEBUG: the -v line of `validate`; the report command's progress: INFO).
    """
    from kinetostat_validation.compare import LEVER, TOLERANCES, compare, lever_row

    run = ModelRun(mech, res, Path(path) if path is not None else None, (LEVER_ROUTE, *engines))
    if res is None:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            t0 = time.perf_counter()
            run.res = analyze(mech, steps=steps, friction="first")   # the engines' frictionless reactions
            run.solver_seconds = time.perf_counter() - t0
        _record(caught, "", run.warnings)
    run.analyses[(tuple(float(x) for x in run.res.phi_deg), run.res.friction_method)] = run.res
    run.rows.append(lever_row(run.res))
    run.tolerances[LEVER] = TOLERANCES[LEVER]
    t0 = time.perf_counter()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            run.published = published_rows(mech, run.at)
        except Exception as exc:              # e.g. a published angle where the linkage does not assemble
            run.errors[PUBLISHED_ROUTE] = _one_line(exc)
    if mech.published:
        run.seconds[PUBLISHED_ROUTE] = time.perf_counter() - t0
    _record(caught, f"{PUBLISHED_ROUTE}: ", run.warnings)
    for route in engines:
        t0 = time.perf_counter()
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            try:
                c = compare(mech, engines=[route], steps=steps, res=run.res)
            except Exception as exc:          # an adapter's fault is this route's error, not ours
                run.errors[route] = _one_line(exc)
            else:
                run.rows += list(c.rows)
                run.results.update(c.results)
                run.skipped.update(c.skipped)
                run.errors.update({r: m.splitlines()[0] for r, m in c.failed.items()})
        run.seconds[route] = time.perf_counter() - t0
        if route in TOLERANCES:
            run.tolerances[route] = TOLERANCES[route]
        _record(caught, f"{route}: ", run.warnings)
        log.log(level, "%s: route %s %s (%.1f s)", run.stem, route, run.status(route), run.seconds[route])
        if on_route is not None:
            on_route(route)
    return run
