"""`tolerance`: the tolerances' effect on the forces, first order and Monte Carlo: a table, an
xarray file and a tornado chart.

--tol NAME=VALUE[UNIT]: VALUE in the model's unit of the parameter; UNIT one of that unit's
family (`SCALES`: mm for a length in m, g for a mass in kg, ...), or % of the parameter's
nominal value.

May use: `.common`, the solver, `kinetostat.tolerance`, `kinetostat.sweep` (its schedulers' names).
"""
from __future__ import annotations

import argparse
import html
import math
import re
import sys
import time
from pathlib import Path

from .common import CLIError, EXIT_OK, _done, _lines, _load, _quiet, _save, _scheduler_installed, _writable_dir

#: The units a --tol may be given in, by the parameter's own unit: each with its size in that unit.
SCALES = {"m": {"m": 1.0, "cm": 1e-2, "mm": 1e-3, "um": 1e-6}, "kg": {"kg": 1.0, "g": 1e-3},
          "kg m^2": {"kg m^2": 1.0, "g m^2": 1e-3}, "N": {"N": 1.0, "kN": 1e3}, "N m": {"N m": 1.0},
          "rpm": {"rpm": 1.0}, "rad/s": {"rad/s": 1.0}, "deg": {"deg": 1.0}, "m/s^2": {"m/s^2": 1.0}}

_TOL = re.compile(r"^\s*([A-Za-z_]\w*)\s*=\s*([-+0-9.eE]+)\s*(%|[A-Za-z][A-Za-z0-9 ^/]*)?\s*$")


def _tol(text: str) -> tuple[str, float, str]:
    """`--tol NAME=VALUE[UNIT]` as (name, value, unit or '')."""
    m = _TOL.match(text)
    try:
        value = float(m.group(2)) if m else math.nan
    except ValueError:
        value = math.nan
    if not m or not math.isfinite(value) or value <= 0:
        raise argparse.ArgumentTypeError(f"invalid --tol {text!r}: expected NAME=VALUE[UNIT] with a positive VALUE, "
                                         f"e.g. --tol r=0.1mm, --tol m2=2% or --tol l=1e-4 (the model's unit)")
    return m.group(1), value, (m.group(3) or "").strip()


def _limit(name: str, value: float, unit: str, own: str, nominal: float) -> float:
    """The limit in the model's unit `own` of the parameter: `value` in `unit` ('' the model's,
    '%' of `nominal`). CLIError naming the option where the unit does not fit."""
    if unit == "":
        return value
    if unit == "%":
        if nominal == 0:
            raise CLIError(f"--tol {name}={value:g}%: {name} is 0 in the model; give the limit in {own}")
        return abs(nominal) * value / 100
    scales = SCALES.get(own, {})
    if unit not in scales:
        fits = ", ".join([*scales, "%"]) if scales else f"a bare number (the model states no unit for {name}) or %"
        raise CLIError(f"--tol {name}={value:g}{unit}: {unit!r} is not a unit of {name} ({own}); use {fits}")
    return value * scales[unit]


def cmd_tolerance(args) -> int:
    from ..model import model_text
    from ..tolerance import tolerance
    from ..units import parameter_units
    names = [n for n, _, _ in args.tol]
    twice = sorted({n for n in names if names.count(n) > 1})
    if twice:
        raise CLIError(f"--tol {twice[0]}: given more than once")
    _scheduler_installed(args.scheduler)
    out = _writable_dir(args.out, "--out")
    path = Path(args.model)
    mech = _load(path)
    units = {**parameter_units(mech, model_text(mech)), "g": "m/s^2"}
    limits = {}
    for name, value, unit in args.tol:
        if name not in units:
            from ..model import _suggest
            raise CLIError(f"--tol {name}: not a parameter of the model{_suggest(name, list(units))}. "
                           f"Parameters: {', '.join(units)}")
        nominal = mech.g if name == "g" else float(mech.parameters[name])
        limits[name] = _limit(name, value, unit, units[name], nominal)
    t0 = time.perf_counter()
    try:
        tol = tolerance(mech, limits, samples=args.samples, seed=args.seed, dist=args.dist, steps=args.steps,
                        scheduler=args.scheduler, chunk=args.chunk,
                        progress=not args.no_progress and not _quiet() and sys.stderr.isatty())
    except ValueError as exc:
        why = str(exc)
        raise CLIError(f"--chunk {why.removeprefix('chunk: ')}" if why.startswith("chunk: ") else
                       f"--tol: {why.removeprefix('tolerance: ')}") from None
    except ConnectionError as exc:
        raise CLIError(f"--scheduler {args.scheduler}: {str(exc).partition(': ')[2]}") from None
    secs = time.perf_counter() - t0
    from .. import tables
    table, nc, svg = out / "tolerance.csv", out / "tolerance.nc", out / "tornado.svg"
    _save(table, "--out", lambda f: tables.write_csv(tol.table(), f))
    written = [f"table: one row per output's peak -> {table}"]
    engine = _netcdf_engine()
    if engine:
        _save(nc, "--out", lambda f: f.write(tol.to_xarray().to_netcdf(engine=engine)), binary=True)
        written.append(f"every output at every angle (xarray, NetCDF by {engine}) -> {nc}")
    else:
        written.append("no xarray file: xarray and a NetCDF engine (scipy) are not installed "
                       "(pip install 'kinetostat[xarray]' scipy)")
    _save(svg, "--out", lambda f: f.write(tornado_svg(tol)))
    written.append(f"tornado chart of the shares in each peak's variance -> {svg}")
    mc = tol.monte_carlo
    lines = [f"{mech.name}   [{path}]",
             f"{mc.samples} designs ({tol.dist}: " + ", ".join(
                 f"{p} {'+-' if tol.dist == 'uniform' else 'sigma '}{t:g} {u}" for p, t, u in
                 zip(tol.params, tol.limits, tol.units)) + f"; seed {tol.seed}) x {len(tol.phi_deg)} crank positions "
             f"in {secs:.2f} s", *written]
    if mc.failed:
        lines.append(f"{mc.failed} design(s) failed (left out), the first: {mc.first_error}")
    _done(_lines(lines))
    return EXIT_OK


def _netcdf_engine() -> str | None:
    """scipy, xarray's NetCDF engine the project's extras name, where xarray and it are installed."""
    import importlib.util
    return "scipy" if all(importlib.util.find_spec(m) for m in ("xarray", "scipy")) else None


def tornado_svg(tol) -> str:
    """The tornado chart: per output's peak, one bar per parameter (largest share first) from
    the nominal peak to +-(d peak/dp) t_p, the first-order swing, labelled with its share."""
    lin, share = tol.linear, tol.contributions.peak
    P = len(tol.params)
    row, width, left, mid_w = 18, 760, 120, 420
    h_panel = (P + 2) * row
    head = 2 * row + 12                          # the title in two lines: the mechanism, then what is drawn
    parts = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{h_panel * len(tol.outputs) + head}" '
             f'font-family="DejaVu Sans, sans-serif" font-size="12">',
             f'<text x="10" y="18" font-weight="bold">{html.escape(tol.mechanism)}</text>',
             f'<text x="10" y="{18 + row}">first-order swing of each peak (+- limit), share of its variance</text>']
    for k, (name, unit) in enumerate(zip(tol.outputs, tol.output_units)):
        y0 = head + k * h_panel
        swing = [abs(lin.peak_derivative[p, k]) * tol.limits[p] for p in range(P)]
        top = max(swing) or 1.0
        parts.append(f'<text x="10" y="{y0 + row - 4}" font-weight="bold">peak {name} = {lin.peak[k]:.6g} {unit} '
                     f'(at {lin.peak_deg[k]:g} deg)</text>')
        centre = left + mid_w / 2
        parts.append(f'<line x1="{centre}" y1="{y0 + row}" x2="{centre}" y2="{y0 + (P + 1) * row}" stroke="black"/>')
        for n, p in enumerate(sorted(range(P), key=lambda q: -share[q, k] if share[q, k] == share[q, k] else 0)):
            y = y0 + (n + 1) * row + 3
            half = swing[p] / top * mid_w / 2
            pct = "n/a" if share[p, k] != share[p, k] else f"{100 * share[p, k]:.1f}%"
            parts += [f'<text x="10" y="{y + 11}">{html.escape(tol.params[p])}</text>',
                      f'<rect x="{centre - half:.1f}" y="{y}" width="{2 * half:.1f}" height="{row - 6}" '
                      f'fill="#4477aa"/>',
                      f'<text x="{left + mid_w + 10}" y="{y + 11}">+-{swing[p]:.3g} {unit}  {pct}</text>']
    parts.append("</svg>\n")
    return "\n".join(parts)
