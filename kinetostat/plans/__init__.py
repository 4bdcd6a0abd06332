"""The graphical method drawn: the plans of the texts as data, built from the exact solution.

    >>> import kinetostat, kinetostat.plans
    >>> mech = kinetostat.load("ice_crank_slider")
    >>> plans = kinetostat.plans.build(mech, at=30)
    >>> round(plans["velocity"].length_mm("p-b"), 1)        # seed 002: pb = 54.7 mm at mu_v = 0.2
    54.7
    >>> fig = kinetostat.plans.figure(plans["acceleration"], lang="uk")   # a matplotlib Figure
    >>> plans.write("out", lang="en")                       # one SVG sheet per plan + segments.csv

`build` -> `Plans`, a frozen mapping kind -> `Plan` (`core`), the N = 1 case of `build_cycle`
(every plan at the N angles of one analysis, `PlanCycle`s at the cycle's scales, `cycle_scales`);
scales by the texts' rule or given
(`scales`); the kinematic plans (`kinematic`); SVG sheets and Figures (`draw`, matplotlib only
there and only when a figure is drawn). Every plan is drawn from one analysis (`solution.solve`),
made at the entry (`build`, `cycle_scales`) where the caller does not pass it.

May use: numpy, the solver's results (`kinetostat.analysis`, `kinetostat.model`; analysed in `.solution`), `_io`, `_text`, `tables`;
pandas only inside `Plans.segments_frame`; never the harness or
`kinetostat.report`.
"""
from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, replace
from functools import partial
from pathlib import Path
from types import MappingProxyType
from typing import Any, Callable, Iterable

from .._io import write_text
from .._text import csv_cell
from ..kinematics import DIGITS_WARN
from ..tables import by_unit, rounded_columns, rows_csv
from .core import SEGMENT_COLUMNS, Plan, PlanCycle, Scale, Segment, extent, extent_cycle
from .draw import ROOM_MM, figure, sheet, svg
from .forces import CRANK_FORCE_MM, crank_plan, force_plans, force_scale, group_plans
from ..model.lettering import lettering
from .mechanism import mechanism_plan
from .kinematic import FixedPositions, acceleration_plan, fixed_positions, positions_plan, starting_position, velocity_plan
from .lever import lever_plan
from .scales import MAX_EXTENT_MM, ScaleError, choose_scales, coarser, solution_scales
from .solution import CYCLE_STEPS, Solution, solve

__all__ = ["build", "build_cycle", "Plans", "BUILDERS", "Plan", "PlanCycle", "Scale", "Segment", "SEGMENT_COLUMNS", "svg",
           "figure", "choose_scales", "starting_position", "fixed_positions", "plan_file_name", "CycleScales",
           "cycle_scales", "fits_cycle", "Solution", "solve"]


#: The plans in the order the texts draw them: (name for --only, builder(mech, res, scales) ->
#: PlanCycle or list of PlanCycles at the angles of `res`).
BUILDERS: tuple[tuple[str, Callable], ...] = (
    ("mechanism", mechanism_plan),
    ("positions", positions_plan),
    ("velocity", velocity_plan),
    ("acceleration", acceleration_plan),
    ("groups", lambda mech, res, sc: _fitted(lambda mu: group_plans(mech, res, mu), sc["mu_l"])),
    ("forces", lambda mech, res, sc: _fitted(lambda mu: force_plans(mech, res, mu), sc["mu_F"])),
    ("crank", lambda mech, res, sc: _crank(mech, res, sc)),
    ("lever", lambda mech, res, sc: _fitted(lambda mu: lever_plan(mech, res, mu), sc["mu_v"])),
)


def _crank(mech, res, sc) -> list[PlanCycle]:
    """The initial link at the plans' mu_l (its arms in mm as the worksheet gives them), its forces
    at a mu_F of its own (`forces.crank_plan`'s, for the largest reaction at the angles of `res`),
    made coarser while the plan overflows its sheet."""
    import numpy as np
    mu_F = force_scale([np.hypot(res.forces.R[..., 0], res.forces.R[..., 1])], CRANK_FORCE_MM)
    return _fitted(lambda mu: crank_plan(mech, res, sc["mu_l"], mu), mu_F)


def fits_cycle(cycle: PlanCycle):
    """(N,): by how much the plan exceeds the room of its sheet (`draw.ROOM_MM`) at each angle of
    the cycle: <= 1 where it fits (`draw.fits` angle by angle)."""
    import numpy as np
    x0, y0, x1, y1 = extent_cycle(cycle)
    return np.min([np.maximum((x1 - x0) / w, (y1 - y0) / h) for w, h in ROOM_MM], axis=0)


def _fitted(make: Callable, mu: Scale) -> list[PlanCycle]:
    """make(mu) -> a PlanCycle or a list of them, made again at the next coarser round scale while
    one of them overflows its sheet at some angle (`fits_cycle`: a group's reaction far out on its guide,
    a polygon longer than its largest force, a lever whose forces reach beyond the velocity plan):
    the sheet states the scale it is drawn at. A few tries at most; the last is kept."""
    import numpy as np
    value = mu.value
    for _ in range(4):
        made = make(Scale(mu.symbol, value, mu.unit))
        plans = list(made) if isinstance(made, (list, tuple)) else [made]
        factor = max(float(np.max(fits_cycle(p), initial=0.0)) for p in plans)
        if factor <= 1:
            break
        value = coarser(value, factor)
    return plans


@dataclass(frozen=True)
class CycleScales:
    """Every scale of every plan, fixed for the whole cycle (`cycle_scales`): so that a plan's vectors
    grow and shrink with the crank angle as a student's would at one scale. `base`: mu_l, mu_v, mu_a,
    mu_F; `plan`: the scale each plan kind is drawn at (group:2,3, forces:2,3, crank, lever);
    `forces_on`: the force scale of the loads drawn on a group plan, the crank, the lever."""
    base: Mapping[str, Scale]
    plan: Mapping[str, Scale]
    forces_on: Mapping[str, Scale]

    def builders(self) -> dict[str, Callable]:
        """BUILDERS' steps that draw at these scales."""
        group = {k.partition(":")[2]: s for k, s in self.forces_on.items() if k.startswith("group:")}
        kind = {k.partition(":")[0]: s for k, s in self.plan.items()}
        return {"groups": lambda mech, res, sc: group_plans(mech, res, kind["group"], group),
                "forces": lambda mech, res, sc: force_plans(mech, res, kind["forces"]),
                "crank": lambda mech, res, sc: crank_plan(mech, res, self.plan["crank"], self.forces_on["crank"]),
                "lever": lambda mech, res, sc: lever_plan(mech, res, self.plan["lever"], self.forces_on["lever"])}


#: The plans whose scale the cycle fixes beyond the base scales (`CycleScales.plan`).
_FITTED = ("groups", "forces", "crank", "lever")


def cycle_angles(mech, step_deg: float = 5.0):
    """The angles `cycle_scales` samples, deg: 0, step_deg, ... below 360 and the design position;
    step_deg a multiple of the cycle grid's step (360 / CYCLE_STEPS deg: `solution`)."""
    import numpy as np
    if not (isinstance(step_deg, (int, float)) and 0 < step_deg <= 360 and (step_deg * CYCLE_STEPS / 360).is_integer()):
        raise ValueError(f"step_deg: expected a step in (0, 360] deg, a multiple of {360 / CYCLE_STEPS:g} deg, "
                         f"got {step_deg!r}")
    return np.array([*np.arange(0.0, 360.0, step_deg), float(getattr(mech.drive, "design_deg", 30.0))])


def cycle_scales(mech, step_deg: float = 5.0, res=None, solution: Solution | None = None) -> CycleScales:
    """The scales of `mech`'s plans fixed for the cycle: each the coarsest the texts' rule (and the
    fitting of each plan to its sheet) chooses at the angles 0, step_deg, ... and the design
    position (`cycle_angles`), or at the angles of `res` where given, so that every plan fits its
    sheet at every angle (a peak between two angles 5 deg apart exceeds the sampled one by under
    0.4 % of a cosine; the round scales leave more room). Taken from `solution` (`solution.solve`;
    made here where neither it nor `res` is given), one build of the plans at every angle at the base scales, each plan's scale then
    made coarser while it overflows its sheet at some angle. Singular positions and angles where
    the linkage does not assemble are left out."""
    import warnings

    import numpy as np

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        if res is None:                             # where the linkage does not assemble: no plans
            res = (solution or solve(mech, other=False)).among(cycle_angles(mech, step_deg))
        keep = np.zeros(0, bool) if res is None else ~np.asarray(res.singular, bool) & (res.omega(1) != 0)
        if not keep.any():
            raise ValueError(f"{mech.name}: no crank angle where the plans can be drawn")
        drawn = res.take(np.flatnonzero(keep))
        base = choose_scales(mech, drawn, cycle=res)
        steps = dict(BUILDERS)
        plans = [p for name in _FITTED for p in steps[name](mech, drawn, base)]
    plan: dict[str, Scale] = {p.kind: p.scale for p in plans}
    forces_on: dict[str, Scale] = {}
    for p in plans:
        on = [s.scale for s in p.segments if s.scale is not None and s.scale.symbol == "mu_F"]
        if on:
            forces_on[p.kind] = max(on, key=lambda c: c.value)
    group = max((s for k, s in plan.items() if k.startswith("group:")), key=lambda s: s.value, default=None)
    forces = max((s for k, s in plan.items() if k.startswith("forces:")), key=lambda s: s.value, default=None)
    plan.update({k: group for k in plan if k.startswith("group:")})      # one mu_l for the group plans,
    plan.update({k: forces for k in plan if k.startswith("forces:")})    # one mu_F for the polygons, as build
    return CycleScales(MappingProxyType(base), MappingProxyType(plan), MappingProxyType(forces_on))


def _positions(mech, res, sc, starting_deg: float | None, fixed: FixedPositions | None,
               solution: Solution | None = None) -> PlanCycle:
    """The plan of positions at mu_l; at the angles where the other branch's dashed mark alone
    would run off the sheet (a slider's other branch below the crank), the mark left out and
    noted (the scale rule keeps the crank at the length the text asks). `fixed` made from
    `solution` where not given."""
    fixed = fixed or fixed_positions(mech, sc["mu_l"], starting_deg, solution)
    plan = positions_plan(mech, res, sc, starting_deg, fixed=fixed)
    fit = fits_cycle(plan) <= 1
    return plan if fit.all() else positions_plan(mech, res, sc, starting_deg, other_branch=fit, fixed=fixed)


def _blank(cycle: PlanCycle, where) -> PlanCycle:
    """The cycle with every point, path, segment value and result NaN at the angles `where` (N,)
    bool (singular positions: nothing drawn there)."""
    import numpy as np
    if not where.any():
        return cycle

    def nan(v):
        v = np.asarray(v)
        return np.where(where.reshape((-1,) + (1,) * (v.ndim - 1)), np.nan, v) if len(v) == len(where) else v
    return replace(cycle, points={k: nan(v) for k, v in cycle.points.items()},
                   paths={k: nan(np.broadcast_to(v, (len(where), v.shape[1]))) for k, v in cycle.paths.items()},
                   segments=tuple(replace(s, value=nan(np.broadcast_to(s.value, where.shape))) for s in cycle.segments),
                   results=tuple(replace(r, value=nan(np.broadcast_to(r.value, where.shape))) for r in cycle.results))


def _cycles(mech, res, sc: Mapping[str, Scale], chosen: list[str], steps: Mapping[str, Callable]) -> list[PlanCycle]:
    """Every chosen plan at every angle of `res` (BUILDERS' order) drawn at `sc` by `steps`, each
    stating the accuracy at its angles, NaN at singular positions."""
    import numpy as np
    cycles: list[PlanCycle] = []
    for name, _ in BUILDERS:
        if name in chosen:
            made = steps[name](mech, res, sc)
            cycles.extend(made if isinstance(made, (list, tuple)) else [made])
    digits = np.asarray(res.digits, float)
    if (digits < DIGITS_WARN).any():                 # each sheet states the accuracy at its angle
        cycles = [replace(p, accuracy=(digits, DIGITS_WARN)) for p in cycles]
    singular = np.asarray(res.singular, bool)
    return [_blank(p, singular) for p in cycles]


def _chosen(only: Iterable[str] | None) -> list[str]:
    """The names of BUILDERS asked for (default all); ValueError naming an unknown one."""
    names = [n for n, _ in BUILDERS]
    chosen = list(names if only is None else only)
    unknown = [n for n in chosen if n not in names]
    if unknown:
        raise ValueError(f"unknown plan {unknown[0]!r}: expected one of {', '.join(names)}")
    return chosen


def build_cycle(mech, res, fixed: CycleScales, positions: FixedPositions | None = None,
                only: Iterable[str] | None = None, solution: Solution | None = None) -> dict[str, PlanCycle]:
    """Every plan of `mech` (`only`: names of BUILDERS, default all) at every angle of `res` (an
    Analysis of `mech`, N angles) at the cycle's fixed scales `fixed` (`cycle_scales`), as
    PlanCycles: kind -> PlanCycle, kinds as in `build`. At a singular position of `res` every
    point and value is NaN (nothing drawn). `positions`: the plan of positions' 12 positions and
    paths (`fixed_positions` of `mech` at fixed.base["mu_l"]; made here from `solution` where not given)."""
    steps = dict(BUILDERS) | fixed.builders()
    steps["positions"] = partial(_positions, starting_deg=None if positions is None else positions.start, fixed=positions,
                                 solution=solution)
    return {p.kind: p for p in _cycles(mech, res, dict(fixed.base), _chosen(only), steps)}


class Plans(Mapping):
    """The plans of one mechanism at one crank angle: a frozen mapping kind -> Plan (kinds as in
    the `plan` column of segments.csv), with the scales they are drawn at."""

    def __init__(self, mech, at: float, scales: Mapping[str, Scale], plans: Iterable[Plan]):
        self.mech, self.at = mech, float(at)
        self.scales = MappingProxyType(dict(scales))
        self._plans = MappingProxyType({p.kind: p for p in plans})

    def __getitem__(self, kind: str) -> Plan:
        try:
            return self._plans[kind]
        except KeyError:
            raise KeyError(f"no plan {kind!r}; plans: {', '.join(self._plans)}") from None

    def __iter__(self):
        return iter(self._plans)

    def __len__(self) -> int:
        return len(self._plans)

    def __repr__(self) -> str:
        scales = ", ".join(str(s) for s in self.scales.values())
        return f"Plans(phi_deg={self.at:g}, [{', '.join(self._plans)}], {scales})"

    def rows(self) -> list[dict]:
        return [r for p in self._plans.values() for r in p.rows()]

    def summary(self, name: str, n_files: int, out, lang: str = "en") -> str:
        """One line for the command line in `lang`: the model, the angle, the scales, the files."""
        from .draw import scale_text
        from .i18n import num, text
        scales = ", ".join(scale_text(s, lang) for s in self.scales.values())
        return text("cli.plans", lang, name=name, phi=num(self.at, lang, 6), scales=scales, n=n_files, out=out)

    def segments_frame(self):
        """Every drawn segment as a pandas DataFrame with the columns of segments.csv."""
        import pandas as pd
        return pd.DataFrame(self.rows(), columns=list(SEGMENT_COLUMNS))

    def segments_csv(self) -> str:
        """segments.csv, plain numbers: the drawing's coordinates and lengths to 12 significant
        digits of their largest |value| (all in mm; `kinetostat.tables.rounded_columns`), each value to
        12 significant digits of the largest |value| of its unit (`kinetostat.tables.by_unit`); no text cell a spreadsheet reads as a formula."""
        import numpy as np
        rows = self.rows()
        mm = [c for c in SEGMENT_COLUMNS if c.endswith("_mm")]
        cols: dict[str, list] = {c: [r[c] for r in rows] for c in SEGMENT_COLUMNS}
        cols |= {c: v.tolist() for c, v in rounded_columns({c: np.array(cols[c], float) for c in mm},
                                                           dict.fromkeys(mm, "mm")).items()}
        cols["value"] = by_unit(cols["value"], cols["unit"])
        return rows_csv(SEGMENT_COLUMNS, zip(*(map(csv_cell, cols[c]) for c in SEGMENT_COLUMNS)))  # no formula cell

    def mechanism_name(self, lang: str = "en") -> str:
        """The mechanism as the plans' sheets name it in `lang` (the model's lettering)."""
        return lettering(self.mech).name(lang, self.mech.name)

    def write(self, out_dir: str | Path, lang: str = "en", sheets: Mapping[str, Any] | None = None) -> list[Path]:
        """Write one SVG sheet per plan (`plan_file_name`) in `lang` ("en", "uk", "ru"; the
        mechanism named as `mechanism_name`) and segments.csv into `out_dir` (created), each
        atomically; returns the paths written. `sheets`: kind -> that plan's sheet drawn already
        in `lang` (`draw.sheet` with the notes and the mechanism's name: `a3.OneSheet.sheets`),
        written as it is."""
        out = Path(out_dir)
        out.mkdir(parents=True, exist_ok=True)
        written = []
        sheets = sheets or {}
        for plan in self._plans.values():
            path = out / plan_file_name(plan)
            drawn = sheets[plan.kind] if plan.kind in sheets else sheet(plan, lang=lang, mechanism=self.mechanism_name(lang))
            write_text(path, drawn.svg(0))
            written.append(path)
        write_text(out / "segments.csv", self.segments_csv())
        return written + [out / "segments.csv"]


def plan_file_name(plan: Plan, suffix: str = ".svg") -> str:
    """File name of a plan's sheet: its kind with ':' and ',' made safe (group:2,3 -> group_2-3)."""
    return plan.kind.replace(":", "_").replace(",", "-") + suffix


def build(mech, at: float | None = None, scales: Mapping[str, float] | None = None,
          starting_deg: float | None = None, only: Iterable[str] | None = None,
          fixed: CycleScales | None = None, friction: str = "first",
          positions: FixedPositions | None = None, law=None, solution: Solution | None = None) -> Plans:
    """The plans of `mech` at crank angle `at` (deg; default: the model's design position
    `drive.design_deg`). `scales`: any of mu_l [m/mm], mu_v [m/(s mm)], mu_a [m/(s^2 mm)],
    mu_F [N/mm] (the others chosen by the texts' rule, `choose_scales`); `starting_deg`: position
    0 of the plan of positions (default: found, `starting_position`); `only`: names of BUILDERS
    to draw (default all); `fixed`: every plan at these scales (`cycle_scales`; `scales` then
    unused). `friction`: "first" (default: the frictionless reactions of the graphical method) or
    "reactions" (a model with [friction]: the group plans, force polygons and crank plan with the
    reactions with friction, each revolute pair's friction circle drawn, `forces`). `positions`:
    the plan of positions' 12 positions and paths made once for many angles (`fixed_positions` of
    `mech` at the mu_l drawn at; from `starting_deg` where it is given, else ValueError). `law`: at
    that true law of motion (`kinetostat.law_of_motion`: omega and eps at `at`, the flywheel's
    moment on the crank), not the model's drive. `solution`: the one analysis to draw from
    (`solution.solve(mech, [at], friction, law)`; made here where not given). ValueError for
    a bad angle or name, or an angle with no equilibrium with friction; ScaleError (a ValueError)
    for a scale that would draw a plan beyond MAX_EXTENT_MM."""
    import math

    if at is None:
        at = getattr(mech.drive, "design_deg", 30.0)
    if isinstance(at, bool) or not isinstance(at, (int, float)) or not math.isfinite(at):
        raise ValueError(f"at: expected a finite crank angle in degrees, got {at!r}")
    chosen = _chosen(only)
    if friction not in ("first", "reactions"):
        raise ValueError(f"friction: expected 'first' or 'reactions', got {friction!r}")
    solution = solution or solve(mech, [float(at)], friction, law, other=False)    # default: the graphical method's frictionless reactions
    res = solution.res
    if len(res.phi_deg) != 1 or res.phi_deg[0] != float(at):
        raise ValueError(f"solution: expected the analysis of {mech.name!r} at {float(at):g} deg, got {res}")
    if res.friction is not None and not res.friction.solved[0]:
        raise ValueError(f"at {at:g} deg there is no equilibrium with friction in the reactions (self-locking): "
                         f"no plans of the forces to draw")
    if res.singular[0]:
        raise ValueError(f"at {at:g} deg the mechanism is at a singular position "
                         f"(cond {res.cond[0].max():.3g}): velocities and accelerations undefined")
    if res.omega(1)[0] == 0:
        raise ValueError("the crank stands still (omega_1 = 0): the velocity and acceleration plans have no "
                         "size to draw; the statics is in the tables (reactions, balancing moment)")
    sc = dict(fixed.base) if fixed is not None else solution_scales(mech, solution, scales)
    steps = dict(BUILDERS) | (fixed.builders() if fixed is not None else {})
    steps["positions"] = partial(_positions, starting_deg=starting_deg, fixed=positions, solution=solution)
    plans = [p.at(0) for p in _cycles(mech, res, sc, chosen, steps)]
    for p in plans:
        x0, y0, x1, y1 = extent(p)
        ends = [r[c] for r in p.rows() for c in ("x0_mm", "y0_mm", "x1_mm", "y1_mm")]
        if not (max(x1 - x0, y1 - y0) <= MAX_EXTENT_MM and all(map(math.isfinite, ends))):
            raise ScaleError(f"{p.scale.symbol}={p.scale.value:g} {p.scale.unit} would draw the {p.kind} plan "
                             f"beyond {MAX_EXTENT_MM:g} mm; use a larger scale")
    return Plans(mech, float(at), sc, plans)
