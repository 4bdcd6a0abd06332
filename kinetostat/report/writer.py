"""Writes a model's report folder and the index over all reports.

May use: every other room, the solver, and the harness's tolerances.
"""
from __future__ import annotations

import datetime
import json
import math
import re
import time
from pathlib import Path
from typing import Any, Sequence

import numpy as np

from ..analysis import analyze
from ..model import Mechanism
from ..structure import GROUP_KINDS
from .document import Doc, _fe, _fmt
from .plots import _pair_name, plot_errors, plot_hodographs, plot_mechanism, plot_moment, plot_reactions
from .published import PublishedCheck
from .runs import ModelRun

#: Fewer positions than this make the plots over the cycle meaningless.
MIN_REPORT_STEPS = 8


def _versions() -> str:
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


def _mechanism_section(doc: Doc, m: Mechanism, path: Path | None) -> None:
    d = m.drive
    doc.h(2, "Mechanism data")
    items = [f"**Name**: {m.name}", f"**Source**: {m.source or 'not stated'}"]
    if path is not None:
        items.append(f"**Model file**: `{path.name}`")
    items.append(f"**g** = {m.g:g} m/s² along −y")
    rpm = d.omega * 30 / math.pi
    items.append(f"**Drive** ({d.kind}): crank 1 turns about {d.pivot}; φ = angle from the world direction "
                 f"{_vec(d.reference)} to {d.pivot}→{d.point}, positive {'counter-clockwise' if d.sense > 0 else 'clockwise'}; "
                 f"ω₁ = {d.omega:.6g} rad/s ({rpm:.6g} rpm), ε₁ = {d.eps:g} rad/s²; "
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
    doc.h(3, "Assumptions")
    doc.ul(list(m.assumptions) or ["none stated"])
    doc.h(3, "Links")
    rows = []
    for link in m.links:
        pts = ", ".join(f"{n} {_vec(xy)}" for n, xy in link.points.items())
        if link.id == 0:
            rows.append([0, "frame", "-", "-", "-", pts + " (world)"])
        else:
            rows.append([link.id, link.name, f"{link.mass:.6g}", f"{link.I_S:.6g}", link.com or "-", pts])
    doc.table(["id", "name", "mass, kg", "I_S, kg m²", "centre of mass", "points (local frame), m"], rows, "llrrll")
    doc.h(3, "Kinematic pairs")
    rows = []
    for p in m.pairs:
        if p.kind == "R":
            geo = f"point {p.point}"
        else:
            geo = f"guide point {p.guide} on link {p.links[0]}, direction {_vec(p.direction)} (guide frame), slider point {p.point}"
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
            else:
                val = f"{ld.value:.6g}"
            direction = ld.direction if isinstance(ld.direction, str) or ld.direction is None else _vec(ld.direction)
            rows.append([ld.name, ld.kind, ld.link, ld.point or "-", direction or "-", val])
        doc.table(["name", "kind", "link", "point", "direction", "value (N or N m)"], rows)
    if m.springs:
        doc.h(3, "Springs")
        doc.table(["name", "end a", "end b", "stiffness, N/m", "free length, m"],
                  [[s.name, f"link {s.a[0]} {s.a[1]}", f"link {s.b[0]} {s.b[1]}", f"{s.stiffness:g}",
                    f"{s.free_length:g}"] for s in m.springs])


def _structure_section(doc: Doc, m: Mechanism) -> None:
    s = m.structure
    doc.h(2, "Structure")
    doc.p(f"Mobility (Chebyshev): W = 3n − 2p₅ − p₄ = 3·{s.n} − 2·{s.p5} − {s.p4} = **{s.W}**. "
          f"Structure formula: **`{s.formula}`** (class {s.mechanism_class}, order {s.order}).")
    rows = [["I(0,1)", "initial mechanism", "-", "0, 1",
             next(p.label for p in m.pairs if set(p.links) == {0, 1}), "-"]]
    for g in s.groups:
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


def _published_section(doc: Doc, published: Sequence[PublishedCheck]) -> None:
    """The sources' published numbers beside the exact ones (nothing if the model has none)."""
    if not published:
        return
    doc.h(2, "Against the published values")
    doc.p("Numbers printed by the model's sources (its `[[published]]` tables) beside kinetostat's exact "
          "values of the same quantities. Sources and the agreement to expect:")
    doc.ul(list(dict.fromkeys(c.entry.source + (f". Expected agreement: {c.entry.accuracy}" if c.entry.accuracy else "")
                              for c in published)))
    rows = []
    for c in published:
        e = c.entry
        diff = f"{c.difference:+.3g}°" if c.by_angle else f"{100 * c.difference:+.3f} %"
        tol = f"±{e.tolerance:g}°" if c.by_angle else f"±{100 * e.tolerance:g} %"
        rows.append([e.symbol, e.meaning, _angles(c), f"{e.value:g}", f"{c.exact:.6g}", e.unit, diff, tol,
                     "yes" if c.passed else "**NO**"])
    doc.table(["quantity", "meaning", "φ", "published", "kinetostat (exact)", "unit", "difference", "accepted",
               "within"], rows, "lllrrlrrl")


def write_report(run: ModelRun, out: Path, steps_note: str | None = None) -> dict[str, Any]:
    """Write `out/<stem>/` for one model; returns the summary also saved as summary.json."""
    from kinetostat_validation.compare import TOLERANCES

    m, res = run.mech, run.res
    d = Path(out) / run.stem
    d.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    published = run.published
    pic_deg = m.drive.design_deg
    at = analyze(m, phi_deg=[pic_deg])
    images = {
        "mechanism": plot_mechanism(at, res, d / "mechanism.png"),
        "moment": plot_moment(run, d / "balancing_moment.png"),
        "reactions": plot_reactions(run, d / "reactions.png"),
        "errors": plot_errors(run, d / "errors.png"),
        "hodographs": plot_hodographs(run, d / "hodographs.png"),
    }
    res.to_frame().to_csv(d / "cycle.csv", index=False)

    N = len(res.phi_deg)
    doc = Doc(f"{m.name}: kinetostat error report")
    doc.h(1, f"{m.name}")
    doc.p(f"Error report of `{run.stem}` over {N} crank positions (every {360 / N:.4g}°). "
          f"Generated {datetime.date.today().isoformat()} with {_versions()}. "
          f"Full table of the cycle: [cycle.csv](cycle.csv). [All mechanisms](../index.md)")
    routes = list(run.engines)
    n_rows, n_fail = len(run.rows), len(run.failed)
    if run.passed and n_rows:
        verdict = f"**PASS**: all {n_rows} checks within tolerance"
    elif run.passed:
        verdict = "**NOT CHECKED**: no engine route ran"
    else:
        verdict = f"**FAIL**: {n_fail} of {n_rows} checks beyond tolerance" + \
            (f", routes with errors: {', '.join(run.errors)}" if run.errors else "")
    doc.p(verdict + ". Routes: " + ", ".join(f"{r} {run.status(r)}" for r in routes) + ".")

    _mechanism_section(doc, m, run.path)
    _structure_section(doc, m)

    doc.h(2, f"The mechanism at φ = {pic_deg:g}°")
    doc.img(images["mechanism"], f"{m.name} at φ = {pic_deg:g}°: links as lines/polygons between their points, "
                                 f"revolute pairs as circles, prismatic pairs as a guide with a block; metres")

    doc.h(2, "Balancing moment")
    lever = np.nanmax(np.abs(res.lever_discrepancy)) if np.any(np.isfinite(res.lever_discrepancy)) else float("nan")
    doc.p(f"Group by group (force analysis from the last Assur group to the crank) against Zhukovsky's lever "
          f"and against each engine route's driving moment. Largest |lever − groups| over the cycle: "
          f"{_fe(lever)} N·m.")
    doc.img(images["moment"], "Balancing moment on the crank over the cycle, N·m")

    doc.h(2, "Reactions")
    doc.p("Magnitude of every pair's reaction R(i,j) (force of link i on link j), kinetostat and each "
          "engine route overlaid.")
    doc.img(images["reactions"], "Reaction magnitudes over the cycle, N")
    pk = []
    for p in m.pairs:
        mag = np.linalg.norm(res.forces.R[:, p.index], axis=-1)
        if np.any(np.isfinite(mag)):
            i, j = int(np.nanargmax(mag)), int(np.nanargmin(mag))
            pk.append([_pair_name(m, p), f"{mag[i]:.5g}", f"{res.phi_deg[i]:.4g}", f"{mag[j]:.5g}", f"{res.phi_deg[j]:.4g}"])
    doc.table(["pair", "max |R|, N", "at φ, deg", "min |R|, N", "at φ, deg"], pk, "lrrrr")

    doc.h(2, "Errors against the engines")
    doc.p("Per route and quantity: max |engine − kinetostat| over the cycle (absolute), RMS and maximum of "
          "the error relative to the cycle's peak |kinetostat| (peak-relative), against the route's "
          "tolerance. Routes that only give magnitudes (pymunk) are compared in magnitude.")
    if run.results:
        doc.img(images["errors"], "|engine − kinetostat| over the cycle, log scale; dashed: tolerance × peak")
    rows = []
    for r in run.rows:
        unit = "N·m" if r.quantity == "M_drive" else "N"
        rows.append([r.route, r.quantity, f"{_fmt(r.max_abs)} {unit}", _fe(r.rms_relative), _fe(r.peak_relative),
                     f"{r.tolerance:.0e}", f"{r.n_compared}" + (f" ({r.n_skipped} NaN left out)" if r.n_skipped else ""),
                     _row_status(r)])
    for route, why in run.skipped.items():
        rows.append([route, "all", "-", "-", "-", "-", "-", f"SKIPPED: {why}"])
    for route, why in run.errors.items():
        rows.append([route, "all", "-", "-", "-", "-", "-", f"**ERROR**: {why}"])
    doc.table(["route", "quantity", "max abs error", "RMS relative", "peak relative", "tolerance",
               "angles compared", "result"], rows, "llrrrrrl")
    doc.h(3, "Routes and their tolerances")
    rows = []
    for route in routes:
        tol = run.tolerances.get(route) or TOLERANCES.get(route)
        er = run.results.get(route)
        rows.append([route, er.route if er else "-", f"{tol.peak_relative:.0e}" if tol else "-",
                     tol.reason if tol else "-",
                     f"{er.build_seconds:.3f}" if er else "-", f"{er.run_seconds:.3f}" if er else "-",
                     (er.note if er and er.note else "") or run.skipped.get(route, run.errors.get(route, ""))])
    doc.table(["route", "kind", "tolerance (peak-relative)", "why this tolerance", "build, s", "run, s", "note"],
              rows, "llrlrrl")

    doc.h(2, "Hodographs of the reactions")
    doc.p("The tip of each revolute pair's reaction vector (force of link i on link j, world frame) traced "
          "over the cycle, as seed 004 draws them; grey rays every 30° of φ; the red dot marks the maximum.")
    doc.img(images["hodographs"], "Hodographs of the revolute pairs' reactions, N")

    _published_section(doc, published)

    doc.h(2, "Timings")
    doc.ul([f"kinetostat analysis of the {N} positions: {run.solver_seconds:.3f} s"]
           + [f"route {r}: {s:.3f} s wall time (scene, engine build and run, error rows)"
              for r, s in run.seconds.items()])
    sing = int(np.sum(res.singular))
    if run.warnings or sing:
        doc.h(2, "Warnings")
        doc.ul(([f"{sing} positions are singular (values there are NaN)"] if sing else []) + run.warnings)
    doc.h(2, "Files")
    doc.ul([f"[{p.name}]({p.name})" for p in images.values()] + ["[cycle.csv](cycle.csv): `res.to_frame()` of the cycle",
                                                                  "[summary.json](summary.json)"])

    (d / "index.md").write_text(doc.markdown(), encoding="utf-8")
    (d / "index.html").write_text(doc.html().replace('href="../index.md"', 'href="../index.html"'), encoding="utf-8")

    summary = dict(stem=run.stem, name=m.name, formula=m.structure.formula, positions=N,
                   passed=run.passed, checks=n_rows, failed=n_fail,
                   routes={r: dict(status=run.status(r), worst=run.worst(r), seconds=run.seconds.get(r),
                                   why=run.skipped.get(r) or run.errors.get(r)) for r in routes},
                   published=None if not published else dict(
                       n=len(published), within=sum(c.passed for c in published),
                       worst_percent=max((100 * c.error for c in published if not c.by_angle), default=None)),
                   report_seconds=time.perf_counter() - t0,
                   date=datetime.date.today().isoformat())
    (d / "summary.json").write_text(json.dumps(_clean(summary), indent=1, allow_nan=False), encoding="utf-8")
    return summary


def _clean(x):
    """JSON-safe copy: NaN/inf -> None, numpy scalars -> Python."""
    if isinstance(x, dict):
        return {str(k): _clean(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_clean(v) for v in x]
    if isinstance(x, (bool, np.bool_)):
        return bool(x)
    if isinstance(x, (int, np.integer)):
        return int(x)
    if isinstance(x, (float, np.floating)):
        return float(x) if math.isfinite(x) else None
    return x


def write_index(out: Path) -> Path:
    """`out/index.md` and `out/index.html` over every report (`*/summary.json`) in `out`."""
    out = Path(out)
    sums = []
    for f in sorted(out.glob("*/summary.json")):
        try:
            sums.append(json.loads(f.read_text(encoding="utf-8")))
        except (OSError, ValueError):
            continue
    routes: list[str] = []
    for s in sums:
        for r in s["routes"]:
            if r not in routes:
                routes.append(r)
    doc = Doc("kinetostat: error reports")
    doc.h(1, "kinetostat error reports")
    n_pass = sum(1 for s in sums if s["passed"] and s["checks"])
    doc.p(f"{len(sums)} mechanisms, {n_pass} pass every check. Each cell: the worst peak-relative error "
          f"of the route over the mechanism's quantities (driving moment, every reaction) and its verdict "
          f"against the route's tolerance. Generated {datetime.date.today().isoformat()} with {_versions()}.")
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
                cells.append(f"{_fe(info['worst'])} {'PASS' if info['status'] == 'PASS' else '**FAIL**'}")
        pub = s.get("published")
        pubcell = "-" if not pub else f"{pub['within']}/{pub['n']} within" + \
            (f" (max {pub['worst_percent']:.2f} %)" if pub.get("worst_percent") is not None else "")
        verdict = "**PASS**" if s["passed"] and s["checks"] else "**FAIL**" if not s["passed"] else "not checked"
        rows.append([f"[{s['stem']}]({s['stem']}/index.md)", s["name"], f"`{s['formula']}`", *cells, pubcell, verdict])
    doc.table(["model", "mechanism", "structure formula", *routes, "published values", "result"], rows,
              "lll" + "r" * len(routes) + "ll")
    doc.p("Tolerances (peak-relative): see each report's table *Routes and their tolerances*.")
    (out / "index.md").write_text(doc.markdown(), encoding="utf-8")
    (out / "index.html").write_text(re.sub(r'href="([\w.-]+)/index\.md"', r'href="\1/index.html"', doc.html()),
                                    encoding="utf-8")
    return out / "index.md"
