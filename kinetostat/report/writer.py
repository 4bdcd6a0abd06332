"""Writes a model's report folder and the index over the reports of one run.

May use: every other room, the solver, `kinetostat._io` (atomic writes, safe folder names) and the
harness's tolerances.
"""
from __future__ import annotations

import functools
import gzip
import itertools
import json
import logging
import math
import time
import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Sequence

import numpy as np

from .._io import atomic, inside, safe_name, write_text
from ..model import Mechanism, Pair, model_text
from ..virtual_work import virtual_work
from ..structure import GROUP_KINDS

log = logging.getLogger(__name__)
from ..sweep import sweep
from .. import units as model_units
from ..tables import columns_csv, error, plain
from .document import ROUNDING, ROUNDING_MARK, ROUNDING_NOTE, Doc, _err, _fmt, _is_rounding, _rel, esc, slug
from .plots import (pair_name, plain_text, quantity_name, plot_balancing_force, plot_errors, plot_hodographs,
                    plot_mechanism, plot_moment, plot_reactions, plot_tornado)
from .published import PublishedCheck
from .runs import ModelRun, trust
from .sources import WORKS, Work, cited

#: The table of the cycle in a report folder: `res.to_frame()` as `tables.csv_text` writes it (written from
#: `res.columns()` by `tables.columns_csv`, the same text without pandas), gzip-compressed at CYCLE_GZIP_LEVEL
#: (deterministic: no name, no time; 2.4x smaller, read by pandas, numpy, R as is).
CYCLE_FILE = "cycle.csv.gz"
#: gzip's level for CYCLE_FILE: a quarter of level 9's time, 3 % more bytes (the bundled models' tables:
#: 2.19 MB, at level 9 2.12 MB).
CYCLE_GZIP_LEVEL = 4
#: Fewer positions than this make the plots over the cycle meaningless.
MIN_REPORT_STEPS = 8
#: The heading of a report's plans (the index links to it).
PLANS_HEADING = "Plans of the graphical method"
#: The heading of a report's law of motion (the index links to it).
MOTION_HEADING = "Law of motion"
#: The coefficient of fluctuation the law-of-motion section sizes the flywheel for where the model
#: has no [flywheel] and the run gives no --delta or --flywheel.
DEFAULT_DELTA = 0.02
#: The angle of the section's M_bal at constant omega and at the true omega(phi), deg.
MOTION_AT_DEG = 30.0
#: The engines' forward dynamics in the law-of-motion section: RK4 steps a revolution (one cycle; at
#: 90 the error is about 1e-6 for MuJoCo's soft loops and 1e-7 for Pinocchio, about 1 s a model).
MOTION_STEPS_PER_REV = 90

#: The project's studies, linked from the index where their files are in its folder.
STUDIES = (("stability.md", "Stability: the solver's accuracy near singular positions"),
           ("drawing_error.md", "Drawing error: the spread of a careful drawing of the plans"),
           ("benchmark.md", "Benchmark: speed of the solver and the engines"))
#: Said at the top of a study's HTML that names files of the validation/ folder.
REPO_NOTE = ("*Paths `validation/...` name files of the project's source repository; an installed kinetostat "
             "holds them as the module `kinetostat_validation` (e.g. `python -m kinetostat_validation.stability`).*")


def study_page(out: Path, name: str, title: str) -> str:
    """The study `out/name` (Markdown) rendered beside it as HTML, as the reports are (`Doc.html`:
    the same Markdown, images linked), with REPO_NOTE under its title where it names a path of
    validation/; returns the HTML file's name."""
    md = (Path(out) / name).read_text(encoding="utf-8")
    if "validation/" in md:
        head, sep, rest = md.partition("\n")
        md = f"{head}{sep}\n{REPO_NOTE}\n{rest}" if head.startswith("#") else f"{REPO_NOTE}\n\n{md}"
    page = Path(name).with_suffix(".html").name
    write_text(Path(out) / page, Doc(title).html(md))
    return page


@functools.cache
def _versions() -> str:
    """The versions of kinetostat and the libraries behind a report's numbers, once a process (each
    metadata lookup reads the installed packages' folders)."""
    from importlib import metadata

    from .. import __version__
    out = [f"kinetostat {__version__}", f"numpy {np.__version__}"]
    for dist in ("pin", "mujoco", "pymunk", "matplotlib"):
        try:
            out.append(f"{dist} {metadata.version(dist)}")
        except metadata.PackageNotFoundError:
            pass
    return ", ".join(out)


def _vec(v) -> str:
    return "(" + ", ".join(f"{c:.6g}" for c in v) + ")"


def _unit_text(unit: str) -> str:
    return unit.replace("^2", "²").replace("^3", "³")


def parameter_units(m: Mechanism) -> dict[str, str]:
    """Each [parameter]'s unit (`kinetostat.units.parameter_units`) as the report prints it."""
    return {name: _unit_text(u) for name, u in model_units.parameter_units(m, model_text(m)).items()}


def _rounding_note(doc: Doc, texts: Sequence[Any]) -> None:
    """ROUNDING_NOTE as a paragraph where any of `texts` (the cells or lines just written) carries
    ROUNDING_MARK."""
    if any(ROUNDING_MARK in str(t) for t in texts):
        doc.p(ROUNDING_NOTE)


def _parameters_section(doc: Doc, m: Mechanism) -> None:
    """The model's [parameters] and every number an expression produced (shown where there are any)."""
    given = m.expressions
    if m.parameters:
        units = parameter_units(m)
        doc.h(3, "Parameters")
        doc.table(["parameter", "given as", "value", "unit"],
                  [[esc(n), esc(given[f"parameters.{n}"][0]) if f"parameters.{n}" in given else "number", f"{v:.10g}",
                    units[n]] for n, v in m.parameters.items()], "llrl")
    fields = [(path, e) for path, e in given.items() if not path.startswith("parameters.")]
    if fields:
        doc.h(3, "Numbers from expressions")
        doc.table(["field", "expression", "value", "unit"],
                  [[esc(path), esc(text), f"{v:.10g}", _unit_text(model_units.field_unit(path) or model_units.NOT_STATED)] for path, (text, v) in fields],
                  "llrl")


def study_table(m: Mechanism) -> np.ndarray:
    """The model's `[study]`: the largest |R(i,j)| over the cycle, N, for every case, shape (values of
    the first parameter, values of the second or 1). Computed as a design sweep (`kinetostat.sweep`
    of the model file `m.path` over the study's parameters, `steps` crank angles from 0); NaN where
    the case does not load or assemble."""
    st = m.study
    p = m.pair_between(*st.pair)
    sw = sweep(m.path, dict(st.vary), steps=st.steps)
    return sw.peak(f"R_{p.links[0]}_{p.links[1]}").reshape(len(st.vary[0][1]), -1)


def study_slopes(m: Mechanism) -> tuple[np.ndarray, np.ndarray]:
    """The model's `[study]` redone with exact derivatives: at every case (the model file, parsed once,
    built with its values, as `study_table`), d max |R(i,j)| / d p by each varied parameter p (`peak_slopes`
    of a `kinetostat.sensitivity` at the study's angles), N per unit of p, shape (values of the
    first, values of the second or 1, varied parameters); and the crank angle of each case's peak,
    deg, shape (values of the first, of the second or 1)."""
    from ..model import _read_text, build, parse_text
    from ..sensitivity import sensitivity
    st = m.study
    names = [name for name, _ in st.vary]
    pair = m.pair_between(*st.pair)
    cases = list(itertools.product(*(xs for _, xs in st.vary)))
    slopes, angles = np.empty((len(cases), len(names))), np.empty(len(cases))
    model = parse_text(_read_text(Path(m.path)), m.path)     # once: each case is built from the parsed text
    for n, case in enumerate(cases):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            sens = sensitivity(build(model, parameters=dict(zip(names, case))), params=names, steps=st.steps)
        k, by = peak_slopes(sens, pair)
        slopes[n], angles[n] = [by[p] for p in names], sens.phi_deg[k]
    shape = (len(st.vary[0][1]), -1)
    return slopes.reshape(*shape, len(names)), angles.reshape(shape)


def _signs(m: Mechanism, slopes: np.ndarray) -> list[str]:
    """Which way the study's peak moves with each varied parameter, from the signs of `study_slopes`."""
    out = []
    for n, (name, _) in enumerate(m.study.vary):
        d = slopes[..., n]
        zero = np.abs(d) <= 1e-12 * np.max(np.abs(d))
        way = ("grows" if np.all(d[~zero] > 0) else "falls" if np.all(d[~zero] < 0) else None) if (~zero).any() else None
        out.append(f"The peak {way} with {esc(name)} at every case{f' but {int(zero.sum())} where it is flat' if zero.any() else ''}."
                   if way else f"The peak does not move one way with {esc(name)} over the study.")
    return out


def _per_unit(unit: str) -> str:
    """The unit of a force's derivative by a parameter of unit `unit`: N/m, N (a ratio), N per m/s², N per
    kg m², N per not stated (a unit of more than one word or with a slash)."""
    return "N" if unit == "1" else f"N per {unit}" if " " in unit or "/" in unit else f"N/{unit}"


def _simpson(y: np.ndarray, x: Sequence[float]) -> np.ndarray | None:
    """The integral of y (first axis over the values x) by Simpson's rule; None unless the x are
    equally spaced and odd in number (3 or more)."""
    x = np.asarray(x, float)
    if len(x) < 3 or len(x) % 2 == 0 or not np.allclose(np.diff(x), x[1] - x[0], rtol=1e-9, atol=0):
        return None
    w = np.ones(len(x))
    w[1:-1:2], w[2:-1:2] = 4, 2
    return (x[1] - x[0]) / 3 * np.tensordot(w, y, axes=1)


def _study_derivatives(doc: Doc, m: Mechanism, table: np.ndarray) -> None:
    """The study redone with derivatives (`study_slopes`): d peak / d p by each varied parameter at
    every case, against the table's centred differences (over cases whose peaks lie at one angle
    of the study's grid) and integrated by Simpson's rule against the table's change."""
    t0 = time.perf_counter()
    try:
        slopes, angles = study_slopes(m)
    except (ValueError, NotImplementedError) as exc:
        doc.p(f"The study by exact derivatives: skipped: {esc(str(exc).strip().splitlines()[0])}.")
        return
    st = m.study
    i, j = st.pair
    units = parameter_units(m)
    (first, xs) = st.vary[0]
    ys = st.vary[1][1] if len(st.vary) > 1 else ()
    x = np.asarray(xs, float)
    centred = (table[2:] - table[:-2]) / (x[2:] - x[:-2])[:, None]
    exact = slopes[1:-1, :, 0]
    same = (angles[2:] == angles[1:-1]) & (angles[:-2] == angles[1:-1])
    off = np.abs(centred - exact) / np.abs(exact)
    words = [f"The study redone with exact derivatives (`kinetostat.sensitivity` at each case; the derivative of "
             f"the peak by the envelope rule at its angle): d max|R({i},{j})| / d {esc(first)} at every case below"]
    if same.any():
        words.append(f"the table's centred differences over its steps of {esc(first)} agree with them within "
                     f"{100 * off[same].max():.2g} % where the three cases peak at one angle of the study's grid")
    if (~same).any():
        words.append(f"{int((~same).sum())} case(s) whose peak moves to another angle of that grid differ by up to "
                     f"{100 * off[~same].max():.2g} %")
    integral = _simpson(slopes[:, :, 0], xs)
    if integral is not None:
        change = table[-1] - table[0]
        words.append(f"Simpson's rule over these derivatives gives the table's change from {esc(first)} = {xs[0]:g} "
                     f"to {xs[-1]:g} within {100 * np.max(np.abs(integral - change) / np.abs(change)):.2g} %")
    doc.p("; ".join(words) + ". " + " ".join(_signs(m, slopes)))
    second = st.vary[1][0] if ys else ""
    head = ([f"{esc(first)}, {units.get(first, model_units.NOT_STATED)} \\ {esc(second)}, "
             f"{units.get(second, model_units.NOT_STATED)}", *(f"{y:g}" for y in ys)] if ys
            else [f"{esc(first)}, {units.get(first, model_units.NOT_STATED)}", "value"])
    for n, (name, _) in enumerate(st.vary):
        doc.p(f"d max|R({i},{j})| / d {esc(name)}, {_per_unit(units.get(name, model_units.NOT_STATED))}:")
        doc.table(head, [[f"{xv:g}", *(_fmt(v, 5) for v in row)] for xv, row in zip(xs, slopes[:, :, n])],
                  "r" * len(head))
    log.info("%s: the study by derivatives (%.1f s)", Path(m.path).stem, time.perf_counter() - t0)


def study_command(m: Mechanism) -> str:
    """The `kinetostat sweep` command line that computes the model's `[study]`."""
    params = " ".join(f"--param {name}={','.join(f'{x:.15g}' for x in xs)}" for name, xs in m.study.vary)
    return f"kinetostat sweep {Path(m.path).name} {params} --steps {m.study.steps} --out study.csv"


def _study_section(doc: Doc, m: Mechanism) -> None:
    """The table of the model's `[study]`, when it declares one and its file can be read again."""
    if m.study is None or m.path is None or not Path(m.path).is_file():
        return
    st = m.study
    table = study_table(m)
    i, j = st.pair
    command = study_command(m)
    doc.h(2, "Parameter study")
    doc.p(f"{esc(st.title)}. Largest |R({i},{j})| over the cycle, N ({st.steps} crank angles from 0°, every "
          f"{360 / st.steps:.4g}°); computed as a design sweep, each case the model file loaded with its "
          f"parameter values; the same table (column peak_R_{'_'.join(map(str, m.pair_between(i, j).links))}) "
          f"comes from {f'`{command}`' if esc(command) == command else esc(command)}; \u2014: the case does not "
          f"load or assemble.")
    (first, xs) = st.vary[0]
    second, ys = st.vary[1] if len(st.vary) > 1 else ("", ())
    units = parameter_units(m)
    header = ([f"{esc(first)}, {units.get(first, 'not stated')} \\ {esc(second)}, {units.get(second, 'not stated')}",
               *(f"{y:g}" for y in ys)] if second
              else [f"{esc(first)}, {units.get(first, 'not stated')}", f"max |R({i},{j})|, N"])
    doc.table(header, [[f"{x:g}"] + [f"{v:.1f}" if np.isfinite(v) else "\u2014" for v in row]
                       for x, row in zip(xs, table)], "r" * len(header))
    _study_derivatives(doc, m, table)


#: The report's sensitivity section: rows of its table and bars of its tornado chart.
SENSITIVITY_ROWS, TORNADO_BARS = 5, 10
SENSITIVITY_HEADING = "Sensitivity"


@dataclass(frozen=True)
class PeakElasticity:
    """How one pair's peak |R| over the cycle moves with one parameter."""

    pair: Pair
    param: str
    value: float          # the parameter's nominal value, its unit
    peak: float           # max |R(i,j)| over the cycle, N
    phi_deg: float        # the crank angle of the peak, deg
    slope: float          # d peak / d param, N per unit of the parameter
    elasticity: float     # (param / peak) d peak / d param, 1


def free_parameters(m: Mechanism) -> tuple[str, ...]:
    """The parameters the model file gives as numbers (not expressions of others), and g: those the
    report differentiates, each then moving the parameters whose expressions use it (d l / d r
    through l = sqrt(r**2 + c**2)), as a design sweep of it does."""
    return (*(p for p in m.parameters if f"parameters.{p}" not in m.expressions), "g")


def peak_slopes(sens, pair: Pair) -> tuple[int, dict[str, float]] | None:
    """The index of the crank angle where |R| of `pair` peaks over the cycle of a
    `kinetostat.sensitivity` result, and d peak / d p there for each of its parameters, N per unit
    of p: (R . dR/dp) / |R| at the peak (the envelope rule: it holds where the peak over the cycle's
    grid is reached at one angle). None where the pair carries no load."""
    R = sens.result.reaction(*pair.links)
    mag = np.linalg.norm(R, axis=-1)
    if not np.any(np.isfinite(mag)) or np.nanmax(mag) == 0:
        return None
    k = int(np.nanargmax(mag))
    dR = sens.reaction(*pair.links)
    return k, {p: float(R[k] @ dR[p][k]) / float(mag[k]) for p in sens.params}


def peak_elasticities(sens) -> list[PeakElasticity]:
    """Every (pair, parameter) of a `kinetostat.sensitivity` result (`peak_slopes`), the largest
    |elasticity| first. Pairs that carry no load have none."""
    res = sens.result
    out = []
    for pair in res.mech.pairs:
        found = peak_slopes(sens, pair)
        if found is None:
            continue
        k, slopes = found
        peak = float(np.linalg.norm(res.reaction(*pair.links)[k]))
        out += [PeakElasticity(pair, p, sens.values[p], peak, float(res.phi_deg[k]), slope,
                               sens.values[p] * slope / peak) for p, slope in slopes.items()]
    return sorted(out, key=lambda e: -abs(e.elasticity))


def _sensitivity_section(doc: Doc, run: ModelRun, d: Path) -> Path | None:
    """The elasticities of the pairs' peak reactions to the model's `free_parameters` (`peak_elasticities`
    of one `kinetostat.sensitivity` call at the report's angles): the SENSITIVITY_ROWS largest as a
    table, the TORNADO_BARS largest as a tornado chart (returned); a model without [parameters] has
    no section, one the sensitivities refuse a line saying why."""
    from ..errors import AssemblyError, ModelError
    from ..sensitivity import sensitivity
    m = run.mech
    if not m.parameters:
        return None
    doc.h(2, SENSITIVITY_HEADING)
    t0 = time.perf_counter()
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            sens = sensitivity(m, params=free_parameters(m), phi_deg=run.res.phi_deg)
        rows = peak_elasticities(sens)
    except (ModelError, AssemblyError, ValueError, NotImplementedError) as exc:
        doc.p(f"Skipped: {esc(str(exc).strip().splitlines()[0])}.")
        return None
    units = {**parameter_units(m), "g": "m/s²"}
    doc.p(f"Exact derivatives (`kinetostat.sensitivity`, forward mode) of every pair's peak |R| over the cycle "
          f"({len(run.res.phi_deg)} positions) with respect to each parameter the model gives as a number, and g "
          f"({esc(', '.join(sens.params))}): "
          "d peak / d p is that of |R| at the angle of the peak, (R · dR/dp) / |R| (the envelope rule: the peak "
          "reached at one angle). Elasticity (p / peak) · d peak / d p: the peak's relative change for a relative "
          "change of p (0.5: 1 % more p, 0.5 % more peak); a parameter that other parameters' expressions use moves "
          f"them too, as in a design sweep. The {SENSITIVITY_ROWS} largest |elasticities| over the pairs and parameters:")
    doc.table(["pair", "parameter", "value", "peak |R|, N", "at φ, deg", "d peak / d p", "elasticity, 1"],
              [[esc(pair_name(m, e.pair)), esc(e.param), f"{e.value:.6g} {units[e.param]}".removesuffix(" 1"),
                f"{e.peak:.6g}", f"{e.phi_deg:.4g}", f"{_fmt(e.slope, 5)} {_per_unit(units[e.param])}", f"{e.elasticity:+.4f}"]
               for e in rows[:SENSITIVITY_ROWS]], "llrrrrr")
    bars = rows[:TORNADO_BARS]
    with plain_text():
        image = plot_tornado(m, [f"{pair_name(m, e.pair)}: {e.param}" for e in bars],
                             [e.elasticity for e in bars], d / "sensitivity.svg")
    doc.img(image, f"Elasticities of the peak reactions, the {len(bars)} largest: red, the peak grows with the "
                   "parameter; blue, it falls")
    log.info("%s: sensitivity (%.1f s)", run.stem, time.perf_counter() - t0)
    return image


def _mechanism_section(doc: Doc, m: Mechanism, path: Path | None) -> None:
    d = m.drive
    doc.h(2, "Mechanism data")
    items = [f"**Name**: {esc(m.name)}", f"**Source**: {esc(m.source or 'not stated')}"]
    if path is not None:
        items.append(f"**Model file**: {esc(path.name)}")
    items.append(f"**g** = {m.g:g} m/s² along −y")
    rpm = d.omega * 30 / math.pi
    items.append(f"**Drive** ({d.kind}): crank 1 turns about {esc(d.pivot)}; φ = angle from the world "
                 f"direction {_vec(d.reference)} to {esc(d.pivot)}→{esc(d.point)}, positive {'counter-clockwise' if d.sense > 0 else 'clockwise'}; "
                 + (f"ω₁ = {d.omega:.6g} rad/s ({rpm:.6g} rpm), ε₁ = {d.eps:g} rad/s²; " if d.law is None else
                    f"ω₁(φ) by a law of motion ({'ω = ' + esc(d.law.expression) if d.law.expression else f'periodic cubic spline through {len(d.law.phi_deg)} points'}), "
                    f"ω₁ up to {d.omega:.6g} rad/s, |ε₁| = |ω₁ dω₁/dφ| up to {d.eps:.6g} rad/s²; ")
                 + ("the unknown is the balancing moment on the crank" if d.kind == "engine" else
                    "the unknown is the balancing force of the pinion on the crank's wheel"))
    if d.gear is not None:
        gr = d.gear
        items.append(f"**Gear mesh**: module {gr.module * 1e3:g} mm, z_pinion {gr.z_pinion}, z_wheel {gr.z_wheel}, "
                     f"correction {gr.correction}, α_w = {gr.alpha_w_deg:g}°, pitch radius r_w = {gr.r_w:.6g} m, "
                     f"arm r_b = {gr.r_b:.6g} m, pinion towards {_vec(gr.centre_direction)}")
    if m.friction is not None:
        items.append(f"**Friction**: reduced coefficient f = {m.friction.f:g}"
                     + (f", default journal radius {m.friction.radius:g} m" if m.friction.radius else ""))
    else:
        items.append("**Friction**: none")
    doc.ul(items)
    _parameters_section(doc, m)
    doc.h(3, "Assumptions")
    doc.ul([esc(a) for a in m.assumptions] or ["none stated"])
    doc.h(3, "Links")
    rows = []
    for link in m.links:
        pts = ", ".join(f"{esc(n)} {_vec(xy)}" for n, xy in link.points.items())
        if link.id == 0:
            rows.append([0, "frame", "-", "-", "-", pts + " (world)"])
        else:
            rows.append([link.id, esc(link.name), f"{link.mass:.6g}", f"{link.I_S:.6g}", esc(link.com or "-"), pts])
    doc.table(["id", "name", "mass, kg", "I_S, kg m²", "centre of mass", "points (local frame), m"], rows, "llrrll")
    doc.h(3, "Kinematic pairs")
    rows = []
    for p in m.pairs:
        if p.kind == "R":
            geo = f"point {esc(p.point)}"
        else:
            geo = (f"guide point {esc(p.guide)} on link {p.links[0]}, direction {_vec(p.direction)} (guide frame), "
                   f"slider point {esc(p.point)}")
        r = p.radius if p.radius is not None else (m.friction.radius if m.friction and m.friction.radius else None)
        rows.append([p.label, "revolute" if p.kind == "R" else "prismatic", f"{p.links[0]}, {p.links[1]}", geo,
                     f"{r:g}" if r else "-"])
    doc.table(["pair", "kind", "links", "geometry", "journal radius, m"], rows)
    if m.loads:
        doc.h(3, "Applied loads")
        rows = []
        for ld in m.loads:
            if ld.table is not None:
                t = ld.table
                val = (f"table over {'φ, deg' if t.argument == 'phi' else 'fraction of stroke'} "
                       f"({len(t.x)} points), scale {t.scale:.6g}")
            elif ld.characteristic is not None:
                c = ld.characteristic
                val = (f"M(ω) = {esc(c.expression)}" if c.expression else f"M(ω) table ({len(c.omega)} points)")
            elif ld.kind == "damper":
                val = f"c = {ld.value:.6g} on pair {ld.pair[0]}–{ld.pair[1]}"
            else:
                val = f"{ld.value:.6g}"
            unit = {"moment": "N m", "force": "N"}.get(ld.kind)
            if ld.kind == "damper":
                unit = "N m s/rad" if m.pair_between(*ld.pair).kind == "R" else "N s/m"
            elif ld.characteristic is not None:
                unit = "N m (ω in rad/s)"
            elif ld.table is not None:
                unit = unit + " (the scale)"
            direction = ld.direction if isinstance(ld.direction, str) or ld.direction is None else _vec(ld.direction)
            rows.append([esc(ld.name), ld.kind, ld.link, esc(ld.point or "-"), esc(direction or "-"), val, unit])
        doc.table(["name", "kind", "link", "point", "direction", "value", "unit"], rows)
    if m.springs:
        doc.h(3, "Springs")
        doc.table(["name", "end a", "end b", "stiffness, N/m", "free length, m"],
                  [[esc(s.name), f"link {s.a[0]} {esc(s.a[1])}", f"link {s.b[0]} {esc(s.b[1])}", f"{s.stiffness:g}",
                    f"{s.free_length:g}"] for s in m.springs])


def _structure_section(doc: Doc, m: Mechanism) -> None:
    s = m.structure
    doc.h(2, "Structure")
    doc.p(f"Mobility (Chebyshev): W = 3n − 2p₅ − p₄ = 3·{s.n} − 2·{s.p5} − {s.p4} = **{s.W}**. "
          f"Structure formula: **`{s.formula}`** (class {s.mechanism_class}, order {s.order}).")
    rows = [["I(0,1)", "initial mechanism", "-", "0, 1",
             next(p.label for p in m.pairs if set(p.links) == {0, 1}), "-"]]
    for g in s.groups:
        if g.klass == 3:      # a triad: base and leashes; its mode is the one the model draws
            inner = "" if g.inner == "RRR" else f", inner {g.inner}"
            rows.append([g.label, f"III3 (outer pairs {g.kind}{inner})", "-", ", ".join(map(str, g.links)),
                         " / ".join(p.label for p in g.pairs), "mode drawn"])
            continue
        rows.append([g.label, g.kind, GROUP_KINDS[g.kind], f"{g.links[0]}, {g.links[1]}",
                     " / ".join(p.label for p in g.pairs), f"{g.branch:+d}"])
    doc.table(["group", "kind", "kind no.", "links", "pairs (outer, inner, outer)", "branch"], rows)


def _row_status(r) -> str:
    return "**PASS**" if r.passed else "**FAIL**"


def _angles(c: PublishedCheck) -> str:
    a = c.entry.angles
    if len(a) == 1:
        return f"{a[0]:g}°"
    listed = ", ".join(f"{x:g}°" for x in a) if len(a) <= 4 else f"{a[0]:g}°, {a[1]:g}°, ..., {a[-1]:g}°"
    return f"{c.entry.reduce.replace('_', ' ')} over {listed} ({len(a)} positions)"


def _published_section(doc: Doc, m: Mechanism, published: Sequence[PublishedCheck]) -> None:
    """The sources' published numbers beside the exact ones (nothing if the model has none)."""
    if not published:
        return
    doc.h(2, "Against the published values")
    doc.p("Numbers printed by the model's sources (its `[[published]]` tables) beside kinetostat's exact "
          "values of the same quantities. Sources and the agreement to expect:")
    doc.ul(list(dict.fromkeys(esc(c.entry.source) + (f". Expected agreement: {esc(c.entry.accuracy)}"
                                                     if c.entry.accuracy else "") for c in published)))
    rows = []
    for c in published:
        e = c.entry
        diff = f"{c.difference:+.3g}°" if c.by_angle else f"{100 * c.difference:+.3f} %"
        tol = f"±{e.tolerance:g}°" if c.by_angle else f"±{100 * e.tolerance:g} %"
        rows.append([esc(quantity_name(m, e.symbol)), esc(quantity_name(m, e.meaning)), _angles(c), f"{e.value:g}", f"{c.exact:.6g}", esc(e.unit), diff, tol,
                     "yes" if c.passed else "**NO**"])
    doc.table(["quantity", "meaning", "φ", "published", "kinetostat (exact)", "unit", "difference", "accepted",
               "within"], rows, "lllrrlrrl")


def _plans_section(doc: Doc, m: Mechanism, d: Path, page: bool = False, friction: str = "first",
                   law=None, law_said: str = "") -> list[Path]:
    """The plans of the graphical method at the model's design position (`kinetostat.plans`),
    one picture each, with their segments.csv and the worksheet beside them, and with `page` the
    interactive page (`plans.page`, page.html, drawn anew) linked; `friction`: the method they are drawn with (`plans.build`);
    `law`: the plans and worksheet at that true law of motion (`law_said` says which); returns the files."""
    from ..plans import build, plan_file_name, solve, svg
    from ..plans.page import page_angles
    from ..plans.worksheet import worksheet
    at = m.drive.design_deg
    shared = page and friction == "first" and law is None      # the page's analysis holds the plans' too
    doc.h(2, PLANS_HEADING)
    t0 = time.perf_counter()
    try:
        with warnings.catch_warnings():         # the cycle's warnings are reported below
            warnings.simplefilter("ignore")
            drawn = solve(m, page_angles(m)[1] if shared else [at], friction, law)   # once; the page's too where shared
            solution = drawn.sub([at])
            plans = build(m, friction=friction, law=law, solution=solution)
            sheet = worksheet(m, mu_l=plans.scales["mu_l"].value, friction=friction, law=law, solution=solution)
    except ValueError as exc:
        doc.p(f"No plans at this position: {esc(str(exc))}")
        return []
    doc.p(f"The plans at φ = {at:g}° as the course texts draw them, from the exact solution"
          + (" with friction in the reactions (each revolute pair's friction circle drawn, its reaction tangent to it)"
             if friction == "reactions" else "")
          + (f", at the true law of motion ({law_said}; the interactive page at the model's constant speed)"
             if law is not None else "") + ", at the scales "
          + ", ".join(f"`{s}`" for s in plans.scales.values())
          + ": positions, velocities, accelerations, each Assur group with its loads and arms, the "
            "force polygons, the initial link and Zhukovsky's lever, each on an A3 sheet true to scale in mm "
            "(the SVG sheets of `kinetostat plans`; open a sheet to see it at full size). Every drawn segment "
            "with its length and the quantity it stands for: [segments.csv](segments.csv); every value the "
            "texts write down at this position: [worksheet.csv](worksheet.csv).")
    files = []
    if page:
        from ..plans.page import write_page
        files.append(write_page(m, d / "page.html", solution=drawn if shared else None))
        doc.p("[The interactive page](page.html): every plan at every degree of the crank at scales fixed for "
              "the cycle, the values, the force plans step by step, a check of measured lengths (one offline file"
              + ("; the graphical method's first approximation: reactions without friction" if m.friction is not None else "")
              + ").")
    for plan in plans.values():
        path = d / ("plan_" + plan_file_name(plan, ".svg"))
        write_text(path, svg(plan, mechanism=m.name))
        doc.img(path, f"{esc(plan.title)}, {plan.scale}", link=True)
        files.append(path)
    write_text(d / "segments.csv", plans.segments_csv())
    sheet.to_csv(d / "worksheet.csv")
    log.info("%s: plans, worksheet%s (%.1f s)", d.name, " and page" if page else "", time.perf_counter() - t0)
    return files + [d / "segments.csv", d / "worksheet.csv"]


def _verdict(run: ModelRun) -> str:
    n_checks, n_fail = len(run.checks), sum(not c.passed for c in run.checks)
    if run.passed and run.checked:
        return f"**PASS**: all {n_checks} checks within tolerance"
    if run.passed:
        return "**NOT CHECKED**: no route ran and the model has no published values"
    return f"**FAIL**: {n_fail} of {n_checks} checks beyond tolerance" + \
        (f", routes with errors: {', '.join(run.errors)}" if run.errors else "")


def _failed_checks(run: ModelRun, published: Sequence[PublishedCheck]) -> list[str]:
    """One line per check beyond tolerance, route that raised, or published value not within."""
    out = [f"{r.route} {esc(r.quantity)}: peak-relative error {_rel(r.peak_relative)} > tolerance {r.tolerance:.0e} "
           f"(max {_err(r.max_abs, r.peak, r.unit)} at φ = {r.phi_deg_max:.4g}°)" for r in run.failed]
    out += [f"{route}: **ERROR** {esc(why)}" for route, why in run.errors.items()]
    out += [f"published value {esc(c.entry.symbol)} not within the accepted difference"
            for c in published if not c.passed]
    return out


def _extremes(values: np.ndarray, phi: np.ndarray) -> list[str]:
    """max, its φ, min, its φ of a quantity over the cycle (n/a where it is all NaN)."""
    if not np.any(np.isfinite(values)):
        return ["n/a"] * 4
    i, j = int(np.nanargmax(values)), int(np.nanargmin(values))
    return [f"{values[i]:.5g}", f"{phi[i]:.4g}", f"{values[j]:.5g}", f"{phi[j]:.4g}"]


def _balancing_force_section(doc: Doc, res, image: Path) -> None:
    """Working machine: the force of the pinion on the crank's wheel, plot and extremes."""
    doc.h(2, "Balancing force")
    F, m = res.balancing_force, res.mech
    doc.p("The unknown of a working machine: the force of the pinion on the crank's wheel at the pitch point, "
          f"along the line of action of the mesh (world frame); {esc(quantity_name(m, 'M_bal'))} above is its moment "
          "about the crank's pivot.")
    doc.img(image, "Balancing force over the cycle: magnitude and world components, N")
    phi = res.phi_deg
    doc.table(["quantity", "max, N", "at φ, deg", "min, N", "at φ, deg"],
              [[esc(quantity_name(m, "|F_bal|")), *_extremes(np.linalg.norm(F, axis=-1), phi)],
               [esc(quantity_name(m, "F_bal,x")), *_extremes(F[:, 0], phi)],
               [esc(quantity_name(m, "F_bal,y")), *_extremes(F[:, 1], phi)]], "lrrrr")


def _three_routes_section(doc: Doc, m: Mechanism, res) -> None:
    """The balancing moment and the reactions by the three routes of the texts: group by group,
    Zhukovsky's lever (balancing moment only) and d'Alembert-Lagrange (Potapov 2024, `virtual_work`)."""
    vw = virtual_work(m, phi_deg=res.phi_deg)

    def worst(a, b) -> tuple[float, float]:
        ok = np.isfinite(a).all(axis=tuple(range(1, a.ndim))) & np.isfinite(b).all(axis=tuple(range(1, b.ndim)))
        size = (lambda x: np.abs(x)) if a.ndim == 1 else (lambda x: np.linalg.norm(x, axis=-1))
        if not ok.any():
            return float("nan"), 0.0
        return float(np.max(size(a[ok] - b[ok]))), float(np.max(size(b[ok])))

    doc.h(2, "Three routes")
    doc.p("The balancing moment and every reaction by three independent routes sharing only the kinematics: "
          "group by group (the solver), Zhukovsky's lever (the balancing moment from the velocity plan) and "
          "d'Alembert–Lagrange (Potapov 2024: each reaction component from the virtual work of all loads, inertia "
          "included, in the virtual motion of the mechanism with that one constraint released; "
          "`kinetostat.virtual_work`). Max |difference| over the cycle, and relative to the cycle's peak.")
    def row(quantity: str, route: str, a, b, unit: str) -> list[str]:
        x, peak = worst(a, b)
        return [quantity, route, _err(x, peak, unit), _rel(x / peak) if peak > 0 and math.isfinite(x) else "n/a"]

    M = esc(quantity_name(m, "M_bal"))
    rows = [row(M, "Zhukovsky's lever", res.lever_moment, res.balancing_moment, "N·m"),
            row(M, "d'Alembert–Lagrange", vw.balancing_moment, res.balancing_moment, "N·m")]
    rows += [row(esc(pair_name(m, p)), "d'Alembert–Lagrange", vw.reaction(*p.links), res.reaction(*p.links), "N")
             for p in m.pairs]
    doc.table(["quantity", "route against group by group", "max |difference|", "peak relative, 1"], rows, "llrr")
    _rounding_note(doc, [c for r in rows for c in r])


def _figure(value: Callable[[], float], why: str) -> str:
    """A figure's table cell: `value()`, or "undefined: `why`" where it is undefined (value not called)."""
    return esc(f"undefined: {why}") if why else _fmt(value())


def _friction_section(doc: Doc, run: ModelRun) -> None:
    """With [friction]: the exact solution with friction in the reactions beside the first
    approximation of the course text (`run.res`, the cycle the engines checked): M_bal at the design
    position, the energy lost per pair, the efficiency, the self-locking zones, the checks; the
    analyses the run's (`ModelRun.at`)."""
    m, res = run.mech, run.res
    if m.friction is None or not len(res.phi_deg):
        return
    from ..errors import SelfLockingWarning
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SelfLockingWarning)
        ex = run.at(res.phi_deg, friction="reactions")
        at = run.at([m.drive.design_deg], friction="reactions")
        first = run.at([m.drive.design_deg], friction="first")
    M = esc(quantity_name(m, "M_bal"))
    doc.h(2, "Friction in the reactions")
    doc.p("The course text on friction computes the losses *in the first approximation*: the frictionless reactions "
          f"go into f·r·|R|·|ω_rel| (revolute) and f·|R|·|v_rel| (prismatic), {M} stays frictionless (the columns "
          "Pfr of cycle.csv.gz, and every route above). The exact solution puts the friction into the reactions: a "
          "friction moment f·r·|R| against the relative rotation in each revolute pair (the reaction tangent to the "
          "friction circle ρ = f·r), a friction force f·|N| against the sliding in each prismatic pair (the reaction "
          "leaning by arctg f), each group solved again with these loads until its reactions stop changing "
          f"(at most {int(ex.friction.passes.max(initial=0))} passes per group here). Where a pair's relative motion "
          "is zero its friction is that of the motion just before. The physics engines cannot check this: their joint "
          "friction is a constant limit torque, not f·r·|R|.")
    phi0 = m.drive.design_deg
    rows = [[f"{M} at φ = {phi0:g}°, N·m", _fmt(at.balancing_moment_frictionless[0]),
             _fmt(first.balancing_moment_with_friction[0]), _fmt(at.balancing_moment[0])],
            [f"η at φ = {phi0:g}°, 1", "1"] + [_figure(lambda: r.efficiency[0], r.efficiency_reason[0]) for r in (first, at)]]
    try:
        lost0, lost = res.friction_energy(), ex.friction_energy()
        rows.append(["cycle efficiency, 1", "1"] + [_figure(r.cycle_efficiency, r.cycle_efficiency_reason()) for r in (res, ex)])
        rows += [[f"energy lost in {esc(pair_name(m, p))} per cycle, J", "0", _fmt(lost0[p.index]), _fmt(lost[p.index])]
                 for p in m.pairs]
    except ValueError:                  # not a uniform full cycle: no cycle integrals
        pass
    doc.table(["quantity", "frictionless", "first approximation", "friction in the reactions"], rows, "lrrr")
    zones = ex.self_locking_zones()
    doc.p("Self-locking (η ≤ 0: the loads cannot drive the crank through friction, or no equilibrium exists), "
          "edges to 1e-9° by bisection on the crank angle: "
          + ("; ".join(f"{round(a, 9) + 0.0:.9f}° to {round(b, 9) + 0.0:.9f}°" for a, b in zones) if len(zones) else "none")
          + f" (first approximation: {'; '.join(f'{round(a, 6) + 0.0:.6f}° to {round(b, 6) + 0.0:.6f}°' for a, b in res.self_locking_zones()) or 'none'}).")
    ok = ex.friction.solved & np.isfinite(ex.balancing_moment)
    if ok.any():
        peak = np.nanmax(np.abs(ex.balancing_moment))
        dP = (ex.balancing_moment - ex.balancing_moment_frictionless) * ex.omega(1) - ex.friction_power_total
        W = ex.work()
        checks = [f"Zhukovsky's lever with the friction loads applied against group by group: max |difference| "
                  f"{_err(float(np.max(np.abs(ex.lever_discrepancy[ok]))), peak, 'N·m')}",
                  f"power balance, ({M} − {M},0)·ω₁ against the sum of the pairs' friction powers: max |difference| "
                  f"{_err(float(np.max(np.abs(dP[ok]))), float(np.nanmax(ex.friction_power_total)), 'W')}",
                  f"work over the cycle, all loads, {M} and friction: sum {_fmt(sum(W.values()))} J "
                  f"(of {_fmt(sum(abs(v) for v in W.values()))} J moved)" if len(W) else "work: n/a"]
        doc.ul(checks)
        _rounding_note(doc, checks)


def _law_choice(m: Mechanism, delta: float | None, flywheel: float | None) -> tuple[dict, str]:
    """law_of_motion's arguments for the report's section, and the words saying which flywheel:
    --delta, --flywheel, the model's [flywheel], else DEFAULT_DELTA."""
    if delta is not None:
        return {"delta": delta}, f"the flywheel sized for δ = {delta:g} (--delta)"
    if flywheel is not None:
        return {"flywheel": flywheel}, f"the flywheel J = {flywheel:g} kg·m² given (--flywheel)"
    fw = m.flywheel
    if fw is not None:
        return {}, ("the flywheel sized for the model's [flywheel] δ = " + f"{fw.delta:g}" if fw.J is None
                    else f"the model's [flywheel] J = {fw.J:g} kg·m²")
    return {"delta": DEFAULT_DELTA}, f"the flywheel sized for δ = {DEFAULT_DELTA:g} by default (the model has no [flywheel])"


def _forward_dynamics(doc: Doc, run: ModelRun, kwargs: dict) -> None:
    """The engines' check of the law (`kinetostat_validation.motion.check_law_of_motion`): MuJoCo
    and Pinocchio, those of them among the run's routes, integrate the machine forward with its
    flywheel and drive moment (RK4, MOTION_STEPS_PER_REV steps a revolution, one cycle from
    kinetostat's state at phi_0) on the mechanism without friction (the engines model none); their
    omega(phi) against kinetostat's law of the same machine, and their energy balance."""
    from kinetostat_validation.motion import ENGINES, check_law_of_motion
    engines = tuple(e for e in ENGINES if e in run.engines)
    if not engines:
        return
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        check = check_law_of_motion(run.mech, engines=engines, steps_per_rev=(MOTION_STEPS_PER_REV,), cycles=1, **kwargs)
    doc.p(f"Forward dynamics of the same machine by the engines (RK4 at {MOTION_STEPS_PER_REV} steps a revolution, "
          f"one cycle from kinetostat's state at φ₀{'; ' + esc(check.note) if check.note else ''}): ω(φ) against "
          f"kinetostat's law of that machine (J_flywheel = {_fmt(check.J_flywheel)} kg·m², its energy balance "
          f"{_rel(check.energy_error)} of the work's swing). The engines' error falls with the step at their "
          "integrators' orders (tests/test_motion_engines.py).")
    doc.table(["engine", "max |Δω| / ω_mean", "energy balance, of the work's swing"],
              [[a.engine, _rel(a.error), _rel(a.energy_error)] for a in check.rows]
              + [[e, "SKIPPED: not installed", "-"] for e in check.skipped], "lrr")


def _motion_section(doc: Doc, run: ModelRun, delta: float | None = None, flywheel: float | None = None):
    """The machine's law of motion (`kinetostat.law_of_motion`) at the flywheel `_law_choice` picks:
    omega_mean, delta, J_flywheel exact and by the texts' approximate methods, and M_bal at
    MOTION_AT_DEG at constant omega beside the true omega(phi); a model with no drive to balance
    (or whose law cannot be found) is skipped with a line saying why. Returns the Motion, or None."""
    from ..errors import AssemblyError, ModelError
    from ..motion import law_of_motion
    from ..plans.motion_sheet import no_drive
    from ..solve import analyze
    m = run.mech
    doc.h(2, MOTION_HEADING)
    kwargs, said = _law_choice(m, delta, flywheel)
    t0 = time.perf_counter()
    motion = None
    why = no_drive(-run.res.balancing_moment)      # at constant omega the inertia does no work over the cycle
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            if not why:
                motion = law_of_motion(m, **kwargs)
                why = no_drive(motion.M_red)
            if not why:
                true = analyze(m, phi_deg=[MOTION_AT_DEG], law=motion)
                const = run.at([MOTION_AT_DEG])
    except (ModelError, AssemblyError, ValueError) as exc:
        why = str(exc).strip().splitlines()[0]
    log.info("%s: law of motion (%.1f s)", run.stem, time.perf_counter() - t0)
    if why:
        doc.p(f"Skipped: {esc(why)}.")
        return None
    doc.p(f"The steady periodic motion of the machine (the dynamic analysis before kinetostatics, "
          f"`kinetostat motion`), with {esc(said)}, over {len(motion.phi_deg)} positions; the drive: "
          f"{esc(motion.drive)} (M_drive = {_fmt(float(np.mean(motion.M_drive)))} N·m on average, in the crank's sense of rotation).")
    J = motion.J_flywheel
    rows = [["ω_mean, rad/s", _fmt(motion.omega_mean), ""], ["δ, 1", _fmt(motion.delta), ""],
            ["J_flywheel, kg·m² (exact)", _fmt(J), ""]]
    rows += [[f"J_flywheel, kg·m² ({esc(k)})", _fmt(v), f"{(v - J) / J * 100:+.3g} %" if J > 0 else "-"]
             for k, v in motion.approximate.items()]
    doc.table(["quantity", "value", "from the exact"], rows, "lrr")
    s = m.drive.sense
    doc.table([f"at φ = {MOTION_AT_DEG:g}°", "constant ω", "true ω(φ)"],
              [[f"{esc(quantity_name(m, 'M_bal'))}, N·m", _fmt(const.balancing_moment[0]), _fmt(true.balancing_moment[0])]]
              + ([[f"{esc(quantity_name(m, 'M_bal'))} with friction (first approximation), N·m",
                   _fmt(const.balancing_moment_with_friction[0]), _fmt(true.balancing_moment_with_friction[0])]]
                 if m.friction is not None else [])
              + [["ω₁, rad/s", _fmt(s * const.omega(1)[0]), _fmt(s * true.omega(1)[0])],
                 ["ε₁, rad/s²", _fmt(s * const.eps(1)[0]), _fmt(s * true.eps(1)[0])]], "lrr")
    doc.p("At the true ω(φ) the crank carries the flywheel, so the balancing moment"
          + (" with friction" if m.friction is not None else "") + " is the drive's moment at every angle "
          "(the moment about +z).")
    _forward_dynamics(doc, run, kwargs)
    return motion


def _error_rows(run: ModelRun) -> list[list[str]]:
    rows = []
    for r in run.rows:
        rows.append([r.route, esc(quantity_name(run.mech, r.quantity)), _err(r.max_abs, r.peak, r.unit),
                     f"{r.phi_deg_max:.4g}" if math.isfinite(r.phi_deg_max) and not _is_rounding(r.peak_relative)
                     else "-",
                     _rel(r.peak_relative), f"{r.tolerance:.0e}", _rel(r.rms_relative),
                     f"{r.n_compared}" + (f" ({r.n_skipped} NaN left out)" if r.n_skipped else ""),
                     _row_status(r)])
    for route, why in run.skipped.items():
        rows.append([route, "all", "-", "-", "-", "-", "-", "-", f"SKIPPED: {esc(why)}"])
    for route, why in run.errors.items():
        rows.append([route, "all", "-", "-", "-", "-", "-", "-", f"**ERROR**: {esc(why)}"])
    return rows


def _tolerance(run: ModelRun, route: str):
    """The route's Tolerance as the run used it (the harness's default otherwise), or None."""
    from kinetostat_validation.compare import TOLERANCES
    return run.tolerances.get(route) or TOLERANCES.get(route)


def write_report(run: ModelRun, out: Path, folder: str | None = None, page: bool = False,
                 friction: str = "first", delta: float | None = None, flywheel: float | None = None) -> dict[str, Any]:
    """Write `out/<folder>/` for one model (default folder: `run.stem`); returns the summary
    also saved as summary.json.

    `folder` is a name of ASCII letters, digits, '_' and '-' (`kinetostat._io.safe_name`), and
    the folder must resolve to a place inside `out` (ValueError otherwise); `page`: also the
    model's interactive page, page.html, linked from the plans' section (`plans.page.write_page`);
    `friction`: the method
    of the plans and worksheet ("first": the graphical method's; "reactions": with friction in the
    reactions, a model with [friction] only). `delta`, `flywheel`: the law-of-motion section's
    flywheel (`_law_choice`), and the plans and worksheet at that true law of motion. Every file is
    written atomically: an interrupted or failed run leaves each earlier file as it was. Every
    file depends only on the model, the routes and the steps (and the libraries' versions): no
    dates and no run times (printed by the command line only). A rerun reproduces the numbers
    within their tolerances, not byte for byte: errors at rounding level differ in their last
    digits from machine to machine (`kinetostat.report.compare_reports` checks a rerun). Its
    progress is logged (INFO) as each part is done: the figures, cycle.csv.gz with the tables, then
    the plans with their worksheet and page, each with its time.
    """
    m, res = run.mech, run.res
    folder = run.stem if folder is None else folder
    if folder != safe_name(folder):
        raise ValueError(f"report folder {folder!r}: expected a name of ASCII letters, digits, '_' and '-'")
    d = Path(out) / folder
    d.mkdir(parents=True, exist_ok=True)
    inside(out, d)
    published = run.published
    pic_deg = m.drive.design_deg
    at = run.at([pic_deg])
    machine = m.drive.kind == "machine"
    t0 = time.perf_counter()
    with plain_text():
        images = {
            "mechanism": plot_mechanism(at, res, d / "mechanism.svg"),
            "moment": plot_moment(run, d / "balancing_moment.svg"),
            **({"force": plot_balancing_force(res, d / "balancing_force.svg")} if machine else {}),
            "reactions": plot_reactions(run, d / "reactions.svg"),
            "errors": plot_errors(run, d / "errors.svg"),
            "hodographs": plot_hodographs(run, d / "hodographs.svg"),
        }
    log.info("%s: figures %s (%.1f s)", folder, ", ".join(images), time.perf_counter() - t0)
    t0 = time.perf_counter()
    with atomic(d / CYCLE_FILE, binary=True) as f:
        f.write(gzip.compress(columns_csv(*res.columns()).encode("utf-8"), compresslevel=CYCLE_GZIP_LEVEL, mtime=0))

    N = len(res.phi_deg)
    routes = list(run.engines)
    doc = Doc(f"{m.name}: kinetostat error report")
    doc.h(1, esc(m.name))
    doc.p(_verdict(run) + ". Routes: " + ", ".join(f"{r} {run.status(r)}" for r in routes) + ".")
    failed = _failed_checks(run, published)
    if failed:
        doc.p("Failed checks:")
        doc.ul(failed)
    else:
        doc.p("Failed checks: none.")
    doc.p(f"Error report of `{folder}` over {N} crank positions (every {360 / N:.4g}°), made with "
          f"{_versions()}. Full table of the cycle: [{CYCLE_FILE}]({CYCLE_FILE}). [All mechanisms](../index.md)")
    doc.p("Contents:")
    doc.toc()

    _mechanism_section(doc, m, run.path)
    _structure_section(doc, m)

    doc.h(2, f"The mechanism at φ = {pic_deg:g}°")
    doc.img(images["mechanism"], f"{esc(m.name)} at φ = {pic_deg:g}°: links as lines/polygons between their "
                                 f"points, revolute pairs as circles, prismatic pairs as a guide with a block; metres")

    doc.h(2, "Balancing moment")
    lever = np.nanmax(np.abs(res.lever_discrepancy)) if np.any(np.isfinite(res.lever_discrepancy)) else float("nan")
    peak_m = np.nanmax(np.abs(res.balancing_moment)) if np.any(np.isfinite(res.balancing_moment)) else 0.0
    lever_text = (f"Group by group (force analysis from the last Assur group to the crank) against Zhukovsky's lever "
                  f"and against each engine route's driving moment. Largest |lever − groups| over the cycle: "
                  f"{_err(lever, peak_m, 'N·m')}.")
    doc.p(lever_text)
    _rounding_note(doc, [lever_text])
    doc.img(images["moment"], "Balancing moment on the crank over the cycle, N·m")
    doc.table(["quantity", "max, N·m", "at φ, deg", "min, N·m", "at φ, deg"],
              [[esc(quantity_name(m, "M_bal")), *_extremes(res.balancing_moment, res.phi_deg)]], "lrrrr")
    if machine:
        _balancing_force_section(doc, res, images["force"])

    doc.h(2, "Reactions")
    doc.p("Magnitude of every pair's reaction R_ij (force of link i on link j; the frame lettered as the model's "
          "text letters it), kinetostat and each "
          "engine route overlaid.")
    doc.img(images["reactions"], "Reaction magnitudes over the cycle, N")
    doc.table(["pair", "max |R|, N", "at φ, deg", "min |R|, N", "at φ, deg"],
              [[esc(pair_name(m, p)), *_extremes(np.linalg.norm(res.forces.R[:, p.index], axis=-1), res.phi_deg)]
               for p in m.pairs], "lrrrr")

    _three_routes_section(doc, m, res)
    _friction_section(doc, run)
    motion = _motion_section(doc, run, delta, flywheel)
    _study_section(doc, m)
    sens_image = _sensitivity_section(doc, run, d)
    log.info("%s: cycle.csv.gz and the tables (%.1f s)", folder, time.perf_counter() - t0)

    doc.h(2, "Errors against the engines")
    doc.p("Per route and quantity: max |engine − kinetostat| over the cycle (absolute) and the crank angle "
          "where it occurs, the maximum (peak relative) and RMS of the error relative to the cycle's peak "
          "|kinetostat|, beside the route's tolerance. Routes that only give magnitudes (pymunk) are compared "
          f"in magnitude. The angle of an error at rounding level ({ROUNDING_MARK}) is left out: "
          "it is where the rounding happens to peak.")
    if run.results:
        doc.img(images["errors"], "|engine − kinetostat| over the cycle, log scale; dashed: tolerance × peak")
    error_rows = _error_rows(run)
    doc.table(["route", "quantity", "max abs error", "at φ, deg", "peak relative, 1", "tolerance, 1", "RMS relative, 1",
               "angles compared", "result"], error_rows, "llrrrrrrl")
    _rounding_note(doc, [c for r in error_rows for c in r])
    doc.h(3, "Routes and their tolerances")
    rows = []
    for route in routes:
        tol = _tolerance(run, route)
        er = run.results.get(route)
        rows.append([route, er.route if er else "-", f"{tol.peak_relative:.0e}" if tol else "-",
                     tol.reason if tol else "-",
                     esc((er.note if er and er.note else "") or run.skipped.get(route, run.errors.get(route, ""))),
                     esc(trust(route))])
    doc.table(["route", "kind", "tolerance (peak-relative, 1)", "why this tolerance", "note", "rests on"], rows,
              "llrlll")

    doc.h(2, "Hodographs of the reactions")
    doc.p("The tip of each revolute pair's reaction vector (force of link i on link j, world frame) traced "
          "over the cycle, as Potapov 2024 draws them; grey rays every 30° of φ; the red dot marks the maximum.")
    doc.img(images["hodographs"], "Hodographs of the revolute pairs' reactions, N")

    _published_section(doc, m, published)
    asked = delta is not None or flywheel is not None
    plan_files = _plans_section(doc, m, d, page, friction if m.friction is not None else "first",
                                motion if asked else None, _law_choice(m, delta, flywheel)[1])

    sing = int(np.sum(res.singular))
    if run.warnings or sing:
        doc.h(2, "Warnings")
        doc.ul(([f"{sing} positions are singular (values there are NaN)"] if sing else [])
               + [esc(w) for w in run.warnings])
    works = cited([doc.markdown()])
    if works:
        doc.h(2, "Sources")
        doc.ul([_work(w) for w in works])
    doc.h(2, "Files")
    doc.ul([f"[{p.name}]({p.name})" for p in [*images.values(), *([sens_image] if sens_image else []), *plan_files]]
           + [f"[{CYCLE_FILE}]({CYCLE_FILE}): `res.to_frame()` of the cycle as CSV, gzip-compressed",
                                                                  "[summary.json](summary.json)"])

    doc.write(d)

    summary = dict(stem=folder, name=m.name, formula=m.structure.formula, positions=N, plans=bool(plan_files),
                   page=any(p.name == "page.html" for p in plan_files),
                   sources=[w.key for w in works],
                   units=dict(worst="1 (largest |route - kinetostat| over the cycle's peak |kinetostat|; "
                                    f"below {ROUNDING:.1e}: at rounding level, its digits differ from machine to "
                                    "machine)",
                              tolerance="1 (of the peak)", worst_percent="%"),
                   passed=run.passed, checked=run.checked, checks=len(run.checks), failed=sum(not c.passed for c in run.checks),
                   routes={r: dict(status=run.status(r), worst=_worst(run, r),
                                   tolerance=_tolerance(run, r).peak_relative if _tolerance(run, r) else None,
                                   why=run.skipped.get(r) or run.errors.get(r)) for r in routes},
                   published=None if not published else dict(
                       n=len(published), within=sum(c.passed for c in published),
                       worst_percent=error(max((100 * c.error for c in published if not c.by_angle), default=float("nan")))))
    write_text(d / "summary.json", json.dumps(_clean(summary), indent=1, allow_nan=False) + "\n")
    return _clean(summary)


def _worst(run: ModelRun, route: str) -> float | None:
    """The route's worst peak-relative error to `ERROR_DIGITS` (`kinetostat.tables.error`)."""
    w = run.worst(route)
    return None if w is None else error(w)


def _work(w: Work) -> str:
    return f"**{esc(w.key)}**: {esc(w.reference)}"


def _clean(x):
    """JSON-safe copy: NaN/inf -> None, numpy scalars -> Python."""
    if isinstance(x, dict):
        return {str(k): _clean(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_clean(v) for v in x]
    return plain(x)


def write_index(out: Path, summaries: list[dict[str, Any]]) -> Path:
    """`out/index.md` and `out/index.html` over the reports of this run (`summaries`, as
    `write_report` returns them, in the order given); other folders in `out` are not listed. The
    verdicts come first, in a table narrow enough for a page 800 px wide; the errors route by route
    in a second table; then the studies found in `out` (each rendered to HTML beside it,
    `study_page`) and the sources the reports cite."""
    out = Path(out)
    sums = list(summaries)
    routes: list[str] = []
    for s in sums:
        for r in s["routes"]:
            if r not in routes:
                routes.append(r)
    doc = Doc("kinetostat: error reports")
    doc.h(1, "kinetostat error reports")
    n_pass = sum(1 for s in sums if s["passed"] and s["checked"])
    doc.p(f"{len(sums)} mechanisms, {n_pass} pass every check. Made with {_versions()}.")
    rows = []
    for s in sums:
        pub = s.get("published")
        pubcell = "-" if not pub else f"{pub['within']}/{pub['n']} within" + \
            (f" (max {pub['worst_percent']:.2f} %)" if pub.get("worst_percent") is not None else "")
        verdict = "**PASS**" if s["passed"] and s["checked"] else "**FAIL**" if not s["passed"] else "not checked"
        plans = f"[plans]({s['stem']}/index.md#{slug(PLANS_HEADING)})" if s.get("plans") else "-"
        if s.get("page"):
            plans += f", [page]({s['stem']}/page.html)"
        rows.append([f"[{s['stem']}]({s['stem']}/index.md)", verdict, f"{esc(s['name'])}; `{s['formula']}`", pubcell,
                     plans])
    doc.table(["model", "result", "mechanism; structure formula", "published values", "plans"], rows, "lllll")
    doc.h(2, "Errors route by route")
    doc.p(f"Each cell: the worst peak-relative error of the route over the mechanism's quantities (driving "
          f"moment, every reaction; |route − kinetostat| over the cycle's peak |kinetostat|, dimensionless), "
          f"the route's tolerance, and the verdict. "
          f"The tolerances and why: each report's table *Routes and their tolerances*.")
    rows = []
    for s in sums:
        cells = []
        for r in routes:
            info = s["routes"].get(r)
            if info is None:
                cells.append("-")
            elif info["status"] in ("SKIPPED", "ERROR"):
                cells.append(info["status"] if info["status"] == "SKIPPED" else "**ERROR**")
            else:
                tol = f" ≤ {info['tolerance']:.0e}" if info.get("tolerance") is not None else ""
                verdict = "PASS" if info["status"] == "PASS" else "**FAIL**"
                cells.append(f"{_rel(info['worst'])}{tol if verdict == 'PASS' else tol.replace('≤', '>')} {verdict}")
        rows.append([f"[{s['stem']}]({s['stem']}/index.md)", *cells])
    doc.table(["model", *routes], rows, "l" + "r" * len(routes))
    _rounding_note(doc, [c for r in rows for c in r])
    studies = [(name, title) for name, title in STUDIES if (out / name).is_file()]
    if studies:
        doc.h(2, "Studies")
        doc.ul([f"[{title}]({study_page(out, name, title)}) (Markdown: [{name}]({name}))" for name, title in studies])
    keys = {k for s in sums for k in s.get("sources", ())}
    if keys:
        doc.h(2, "Sources")
        doc.p("The works the reports cite.")
        doc.ul([_work(w) for w in WORKS if w.key in keys])
    return doc.write(out)
