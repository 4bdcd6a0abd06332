"""Per-mechanism error reports: the solver against every engine route, and against the seeds.

`run_validation(mech, engines)` runs the accuracy gate (`validation.compare.compare`) one route
at a time, so that a route that raises is recorded as an error of that route instead of
stopping the others. `write_report(run, out)` writes `out/<model stem>/` with `index.md`,
a self-contained `index.html` (images embedded), the PNG plots and `cycle.csv`;
`write_index(out)` writes `out/index.md` and `out/index.html` over every report found there.

matplotlib is imported inside the plotting functions only: the core package imports without it.
Plots use `matplotlib.figure.Figure` directly (no pyplot, no global backend state).
"""
from __future__ import annotations

import base64
import datetime
import html
import json
import math
import re
import time
import warnings
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Sequence

import numpy as np

from .analysis import Analysis, analyze
from .model import Mechanism
from .structure import GROUP_KINDS

__all__ = ["PUBLISHED", "PublishedValue", "PublishedSet", "ModelRun", "run_validation", "quantities",
           "junit_xml", "write_report", "write_index", "published_rows", "MIN_REPORT_STEPS"]

#: Fewer positions than this make the plots over the cycle meaningless.
MIN_REPORT_STEPS = 8


# ============================================================================ published values

@dataclass(frozen=True)
class PublishedValue:
    """One number a seed prints, and how to get the same quantity from an Analysis."""
    symbol: str                         # as the source names it
    meaning: str                        # what it is, in this project's terms
    value: float                        # the published number
    unit: str
    compute: Callable[[Analysis], float]
    tolerance: float                    # accepted |difference|: relative, or deg when unit == "deg"


@dataclass(frozen=True)
class PublishedSet:
    """A seed's published results for one bundled model, at the crank angles it used."""
    source: str
    phi_deg: tuple[float, ...]          # angles the source evaluated (deg, model's convention)
    accuracy: str                       # why the tolerance is what it is
    values: tuple[PublishedValue, ...]
    picture_deg: float = 30.0           # position of the mechanism picture in the report


def _n(a) -> float:
    return float(np.linalg.norm(np.asarray(a)[0]))


def _F_O1(res: Analysis) -> np.ndarray:
    return np.linalg.norm(res.reaction(0, 1), axis=-1)


_G = 0.005      # seed 002 reads its plans to 0.1 mm on ~80 mm vectors: 0.5 %
_P = 0.01       # seed 004 prints 0.1 N of its own sampling on a reconstructed geometry: 1 %

#: The seeds' published numbers, in ONE place, keyed by model stem.
PUBLISHED: dict[str, PublishedSet] = {
    "ice_crank_slider": PublishedSet(
        source="seed 002 (UkrDUZT course guide, part 1), sec. 1.2.2-1.2.3: the worked example "
               "at phi = 30 deg from top dead centre, velocity, acceleration and force plans drawn "
               "and measured, and Zhukovsky's lever",
        phi_deg=(30.0,),
        accuracy="values measured on drawn plans (lengths to 0.1 mm on ~80 mm vectors): 0.5 %",
        picture_deg=30.0,
        values=(
            PublishedValue("V_B", "|v_B|, piston velocity", 10.94, "m/s", lambda r: _n(r.velocity("B")), _G),
            PublishedValue("V_BA", "|v_B - v_A|, relative velocity", 14.92, "m/s",
                           lambda r: _n(r.velocity("B") - r.velocity("A")), _G),
            PublishedValue("V_S2", "|v_S2|, rod centre of mass", 12.2, "m/s", lambda r: _n(r.velocity("S2")), _G),
            PublishedValue("omega2", "|omega_2|, rod", 135.6, "rad/s", lambda r: abs(float(r.omega(2)[0])), _G),
            PublishedValue("a_B", "|a_B|, piston acceleration", 8311.0, "m/s^2",
                           lambda r: _n(r.acceleration("B")), _G),
            PublishedValue("a_S2", "|a_S2|, rod centre of mass", 7875.0, "m/s^2",
                           lambda r: _n(r.acceleration("S2")), _G),
            PublishedValue("eps2", "|eps_2|, rod", 33782.0, "rad/s^2", lambda r: abs(float(r.eps(2)[0])), _G),
            PublishedValue("F_i2", "|F_i2|, rod inertia force", 3937.5, "N", lambda r: _n(r.inertia(2).force), _G),
            PublishedValue("F_i3", "|F_i3|, piston inertia force", 3216.4, "N", lambda r: _n(r.inertia(3).force), _G),
            PublishedValue("M_i2", "|M_i2|, rod inertia moment", 57.43, "N m",
                           lambda r: abs(float(r.inertia(2).moment[0])), _G),
            PublishedValue("R12", "|R(1,2)|, crank on rod at A", 3172.0, "N", lambda r: _n(r.reaction(1, 2)), _G),
            PublishedValue("R43", "|R(0,3)|, cylinder (frame, the text's link 4) on piston", 780.5, "N",
                           lambda r: _n(r.reaction(0, 3)), _G),
            PublishedValue("R32", "|R(3,2)|, piston on rod at B", 6481.0, "N", lambda r: _n(r.reaction(3, 2)), _G),
            PublishedValue("M_bal (force plans)", "|M_bal|, group by group", 102.74, "N m",
                           lambda r: abs(float(r.balancing_moment[0])), _G),
            PublishedValue("M_bal (lever)", "|M_bal| by Zhukovsky's lever", 102.97, "N m",
                           lambda r: abs(float(r.lever_moment[0])), _G),
        )),
    "chain_unit_four_bar": PublishedSet(
        source="seed 004, V. A. Potapov (2024), force analysis of the chain-unit drive mechanism, "
               "line 389: the crank bearing O1 is the most loaded pair, F_O1 = 38.4 .. 286.9 N, "
               "largest near phi_k = 90 deg",
        phi_deg=tuple(float(a) for a in range(0, 360, 10)),
        accuracy="the paper's cycle sampled every 10 deg from phi_k = 0, values printed to 0.1 N, "
                 "geometry reconstructed from its formulas: 1 %; the angle of the maximum 'near 90 deg': 10 deg",
        picture_deg=90.0,
        values=(
            PublishedValue("F_O1 min", "min |R(0,1)| over the sampled cycle", 38.4, "N",
                           lambda r: float(np.nanmin(_F_O1(r))), _P),
            PublishedValue("F_O1 max", "max |R(0,1)| over the sampled cycle", 286.9, "N",
                           lambda r: float(np.nanmax(_F_O1(r))), _P),
            PublishedValue("phi_k at F_O1 max", "crank angle of the maximum (paper: 'near 90 deg')", 90.0, "deg",
                           lambda r: float(r.phi_deg[np.nanargmax(_F_O1(r))]), 10.0),
        )),
}


def published_rows(mech: Mechanism, stem: str) -> list[dict[str, Any]] | None:
    """Exact values of this model next to the seed's published ones (None if none published)."""
    pub = PUBLISHED.get(stem)
    if pub is None:
        return None
    res = analyze(mech, phi_deg=list(pub.phi_deg))
    out = []
    for v in pub.values:
        got = v.compute(res)
        if v.unit == "deg":
            diff, ok = got - v.value, abs(got - v.value) <= v.tolerance
        else:
            diff = 100.0 * (got - v.value) / v.value
            ok = abs(diff) <= 100.0 * v.tolerance
        out.append(dict(symbol=v.symbol, meaning=v.meaning, published=v.value, exact=got, unit=v.unit,
                        diff=diff, diff_unit="deg" if v.unit == "deg" else "%", tolerance=v.tolerance, ok=ok))
    return out


# ============================================================================ validation runs

def quantities(mech: Mechanism) -> list[str]:
    """The quantities compare() checks, named as its rows name them."""
    return ["M_drive"] + [f"R({p.links[0]},{p.links[1]})" for p in mech.pairs]


@dataclass
class ModelRun:
    """The solver's cycle of one model checked route by route (one `compare` call per route)."""
    mech: Mechanism
    res: Analysis
    path: Path | None = None
    engines: tuple[str, ...] = ()
    rows: list = field(default_factory=list)            # validation.compare.Row
    results: dict = field(default_factory=dict)         # route -> EngineResult
    skipped: dict[str, str] = field(default_factory=dict)   # route -> reason
    errors: dict[str, str] = field(default_factory=dict)    # route -> "ExcType: message"
    warnings: list[str] = field(default_factory=list)       # one line each, de-duplicated
    seconds: dict[str, float] = field(default_factory=dict)  # route -> wall time of its compare call
    tolerances: dict = field(default_factory=dict)      # route -> Tolerance
    solver_seconds: float = 0.0                         # wall time of analyze() over the cycle

    @property
    def stem(self) -> str:
        return self.path.stem if self.path is not None else re.sub(r"\W+", "_", self.mech.name).strip("_").lower()

    @property
    def failed(self) -> list:
        return [r for r in self.rows if not r.passed]

    @property
    def passed(self) -> bool:
        """No row beyond tolerance and no route that raised (skipped routes do not count)."""
        return not self.failed and not self.errors

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
                   path: str | Path | None = None, on_route: Callable[[str], None] | None = None) -> ModelRun:
    """Check `res` (default: `analyze(mech, steps=steps)`) against every route in `engines`.

    Each route runs in its own `compare(..., engines=[route], res=res)` call; an exception of a
    route is recorded in `errors` (that route fails) and the other routes still run. Warnings
    raised meanwhile are collected, one line each, in `warnings`. `on_route(route)` is called
    after each route (progress bars).
    """
    from validation.compare import TOLERANCES, compare

    run = ModelRun(mech, res, Path(path) if path is not None else None, tuple(engines))
    if res is None:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            t0 = time.perf_counter()
            run.res = analyze(mech, steps=steps)
            run.solver_seconds = time.perf_counter() - t0
        _record(caught, "", run.warnings)
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
        if on_route is not None:
            on_route(route)
    return run


# ============================================================================ JUnit

def junit_xml(runs: Sequence[ModelRun], name: str = "kinetostat validate") -> ET.ElementTree:
    """One testcase per model x route x quantity; failures as <failure>, skipped routes as
    <skipped>, a route that raised as <error> on each of its quantities."""
    root = ET.Element("testsuites", name=name)
    totals = dict(tests=0, failures=0, errors=0, skipped=0)
    total_time = 0.0
    for run in runs:
        suite = ET.SubElement(root, "testsuite", name=run.stem)
        props = ET.SubElement(suite, "properties")
        ET.SubElement(props, "property", name="model", value=str(run.path or run.mech.name))
        ET.SubElement(props, "property", name="structure", value=run.mech.structure.formula)
        ET.SubElement(props, "property", name="positions", value=str(len(run.res.phi_deg)))
        counts = dict(tests=0, failures=0, errors=0, skipped=0)
        qs = quantities(run.mech)
        for route in run.engines:
            secs = run.seconds.get(route, 0.0) / max(len(qs), 1)
            rows = {r.quantity: r for r in run.rows if r.route == route}
            for q in qs:
                case = ET.SubElement(suite, "testcase", classname=f"{run.stem}.{route}", name=q,
                                     time=f"{secs:.6f}")
                counts["tests"] += 1
                if route in run.errors:
                    ET.SubElement(case, "error", message=run.errors[route], type="RouteError")
                    counts["errors"] += 1
                elif route in run.skipped:
                    ET.SubElement(case, "skipped", message=run.skipped[route])
                    counts["skipped"] += 1
                elif q not in rows:
                    ET.SubElement(case, "error", message=f"route {route} returned no row for {q}", type="MissingRow")
                    counts["errors"] += 1
                elif not rows[q].passed:
                    r = rows[q]
                    f = ET.SubElement(case, "failure", type="ToleranceExceeded",
                                      message=f"peak-relative error {r.peak_relative:.3e} > tolerance {r.tolerance:.1e}"
                                      if r.n_compared else "no angle compared (engine returned NaN everywhere)")
                    f.text = (f"max abs {r.max_abs:.6g}, rms relative {r.rms_relative:.3e}, peak {r.peak:.6g}, "
                              f"{r.n_compared} angles compared, {r.n_skipped} left out")
                    counts["failures"] += 1
        t = sum(run.seconds.values())
        total_time += t
        for k, v in counts.items():
            suite.set(k, str(v))
            totals[k] += v
        suite.set("time", f"{t:.6f}")
    for k, v in totals.items():
        root.set(k, str(v))
    root.set("time", f"{total_time:.6f}")
    tree = ET.ElementTree(root)
    ET.indent(tree)
    return tree


# ============================================================================ documents

def _fmt(x: float | None, digits: int = 4) -> str:
    if x is None or (isinstance(x, float) and math.isnan(x)):
        return "n/a"
    if x == 0:
        return "0"
    a = abs(x)
    if 1e-3 <= a < 1e6:
        return f"{x:.{digits}g}"
    return f"{x:.{max(digits - 2, 1)}e}"


def _fe(x: float | None) -> str:
    if x is None or (isinstance(x, float) and math.isnan(x)):
        return "n/a"
    return "0" if x == 0 else f"{x:.2e}"


class Doc:
    """A small document model rendered both to Markdown and to self-contained HTML.

    Inline text uses Markdown's `code`, **bold** and [text](href); everything else is literal.
    """

    def __init__(self, title: str):
        self.title = title
        self.blocks: list[tuple] = []

    def h(self, level: int, text: str):
        self.blocks.append(("h", level, text))

    def p(self, text: str):
        self.blocks.append(("p", text))

    def ul(self, items: Sequence[str]):
        if items:
            self.blocks.append(("ul", list(items)))

    def table(self, header: Sequence[str], rows: Sequence[Sequence[Any]], align: str | None = None):
        """align: one letter per column, 'l' or 'r' (default: all left)."""
        self.blocks.append(("table", list(header), [[str(c) for c in r] for r in rows],
                            align or "l" * len(header)))

    def img(self, path: Path, caption: str):
        self.blocks.append(("img", Path(path), caption))

    def pre(self, text: str):
        self.blocks.append(("pre", text))

    # -- Markdown
    def markdown(self) -> str:
        out = []
        for b in self.blocks:
            kind = b[0]
            if kind == "h":
                out.append("#" * b[1] + " " + b[2])
            elif kind == "p":
                out.append(b[1])
            elif kind == "ul":
                out.append("\n".join(f"- {i}" for i in b[1]))
            elif kind == "table":
                _, header, rows, align = b
                cell = lambda s: str(s).replace("|", "\\|").replace("\n", " ")
                lines = ["| " + " | ".join(cell(h) for h in header) + " |",
                         "|" + "|".join("---:" if a == "r" else "---" for a in align) + "|"]
                lines += ["| " + " | ".join(cell(c) for c in r) + " |" for r in rows]
                out.append("\n".join(lines))
            elif kind == "img":
                out.append(f"![{b[2]}]({b[1].name})\n\n*{b[2]}*")
            elif kind == "pre":
                out.append("```\n" + b[1].rstrip("\n") + "\n```")
        return "\n\n".join(out) + "\n"

    # -- HTML
    @staticmethod
    def inline(text: str) -> str:
        s = html.escape(str(text), quote=False)
        s = re.sub(r"`([^`]+)`", r"<code>\1</code>", s)
        s = re.sub(r"\*\*([^*]+)\*\*", r"<b>\1</b>", s)
        s = re.sub(r"\[([^\]]+)\]\(([^)\s]+)\)", lambda m: f'<a href="{html.escape(m[2])}">{m[1]}</a>', s)
        return s

    def html(self) -> str:
        body = []
        for b in self.blocks:
            kind = b[0]
            if kind == "h":
                body.append(f"<h{b[1]}>{self.inline(b[2])}</h{b[1]}>")
            elif kind == "p":
                body.append(f"<p>{self.inline(b[1])}</p>")
            elif kind == "ul":
                body.append("<ul>" + "".join(f"<li>{self.inline(i)}</li>" for i in b[1]) + "</ul>")
            elif kind == "table":
                _, header, rows, align = b
                cls = lambda a: ' class="r"' if a == "r" else ""
                head = "".join(f"<th{cls(a)}>{self.inline(h)}</th>" for h, a in zip(header, align))
                trs = []
                for r in rows:
                    tds = []
                    for c, a in zip(r, align):
                        mark = ' class="fail"' if c.startswith(("**FAIL", "**ERROR")) else \
                            ' class="pass"' if c.startswith("**PASS") else ""
                        tds.append(f"<td{cls(a) if not mark else mark}>{self.inline(c)}</td>")
                    trs.append("<tr>" + "".join(tds) + "</tr>")
                body.append(f"<table><thead><tr>{head}</tr></thead><tbody>{''.join(trs)}</tbody></table>")
            elif kind == "img":
                data = base64.b64encode(b[1].read_bytes()).decode("ascii")
                body.append(f'<figure><img src="data:image/png;base64,{data}" alt="{html.escape(b[2])}">'
                            f"<figcaption>{self.inline(b[2])}</figcaption></figure>")
            elif kind == "pre":
                body.append(f"<pre>{html.escape(b[1])}</pre>")
        return _HTML.format(title=html.escape(self.title), body="\n".join(body))


_HTML = """<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>{title}</title>
<meta name="viewport" content="width=device-width, initial-scale=1">
<style>
body {{ font-family: system-ui, -apple-system, "Segoe UI", sans-serif; max-width: 1100px; margin: 2em auto;
       padding: 0 1em; color: #222; line-height: 1.45; }}
table {{ border-collapse: collapse; margin: 0.8em 0; font-size: 0.92em; }}
th, td {{ border: 1px solid #ccc; padding: 0.25em 0.6em; text-align: left; vertical-align: top; }}
th {{ background: #f2f2f2; }}
td.r, th.r {{ text-align: right; font-variant-numeric: tabular-nums; }}
td.pass {{ background: #e6f4e6; }} td.fail {{ background: #fbe3e3; }}
figure {{ margin: 1em 0; }} img {{ max-width: 100%; }}
figcaption {{ font-style: italic; color: #555; }}
code, pre {{ background: #f6f6f6; }} pre {{ padding: 0.6em; overflow-x: auto; }}
</style></head>
<body>
{body}
</body></html>
"""


# ============================================================================ plots

_ROUTE_STYLE = {"pinocchio": ("tab:blue", (0, (6, 3))), "mujoco": ("tab:orange", (0, (2, 2))),
                "mujoco-sim": ("tab:green", (0, (6, 2, 1, 2))), "pymunk": ("tab:red", (0, (1, 1.5)))}
_EXTRA = ["tab:purple", "tab:brown", "tab:pink", "tab:olive", "tab:cyan"]


def _style(route: str, n: int = 0) -> tuple[str, Any]:
    return _ROUTE_STYLE.get(route, (_EXTRA[n % len(_EXTRA)], (0, (4, 2))))


def _figure(w: float, h: float):
    from matplotlib.figure import Figure
    return Figure(figsize=(w, h), layout="constrained")


def _save(fig, path: Path) -> Path:
    """PNG at 110 dpi, reduced to a 256-colour palette without dithering: a third of the size
    of the RGBA file and visually the same for line plots (the HTML embeds every image)."""
    import io
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=110, metadata={"Software": None})
    try:
        from PIL import Image
        img = Image.open(buf).convert("RGB").quantize(colors=256, method=Image.Quantize.FASTOCTREE,
                                                      dither=Image.Dither.NONE)
        img.save(path, format="PNG", compress_level=6)
    except ImportError:       # Pillow comes with matplotlib; keep the plain PNG if it does not
        Path(path).write_bytes(buf.getvalue())
    return path


def _phi_axis(ax, label: bool = True, step: int = 60):
    ax.set_xlim(0, 360)
    ax.set_xticks(range(0, 361, step))
    if label:
        ax.set_xlabel("crank angle φ, deg")
    ax.grid(True, alpha=0.3)


def _pair_name(mech: Mechanism, p) -> str:
    i, j = p.links
    where = f"at {p.point}" if p.kind == "R" else f"slider {p.point} on guide {p.guide}"
    return f"R({i},{j}) {where}"


def _link_name(mech: Mechanism, k: int) -> str:
    return "frame" if k == 0 else mech.links[k].name


def _wrap(text: str, width: int = 52) -> str:
    import textwrap
    return textwrap.fill(text, width)


def _grid(n: int) -> tuple[int, int]:
    cols = 1 if n == 1 else 2 if n <= 4 else 3
    return math.ceil(n / cols), cols


def _closed(phi: np.ndarray, *ys: np.ndarray):
    """Close a full-cycle curve at 360 deg (phi equally spaced from 0)."""
    if len(phi) > 2 and abs(phi[0]) < 1e-9 and abs(phi[-1] + (phi[1] - phi[0]) - 360.0) < 1e-6:
        return (np.append(phi, 360.0),) + tuple(np.concatenate([y, y[:1]]) for y in ys)
    return (phi,) + ys


def _world(res: Analysis, i: int) -> dict[int, dict[str, np.ndarray]]:
    """World positions of every link's points at angle index i."""
    m, kin = res.mech, res.kin
    out = {0: {n: np.asarray(xy, float) for n, xy in m.links[0].points.items()}}
    for link in m.links[1:]:
        out[link.id] = {n: kin.point(link.id, np.asarray(xy, float))[0][i] for n, xy in link.points.items()}
    return out


def _hull(pts: np.ndarray) -> np.ndarray:
    """Convex hull (monotone chain) of a few 2-D points, counter-clockwise."""
    P = sorted(set(map(tuple, np.round(pts, 12))))
    if len(P) <= 2:
        return np.array(P)
    cross = lambda o, a, b: (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
    lower, upper = [], []
    for p in P:
        while len(lower) >= 2 and cross(lower[-2], lower[-1], p) <= 0:
            lower.pop()
        lower.append(p)
    for p in reversed(P):
        while len(upper) >= 2 and cross(upper[-2], upper[-1], p) <= 0:
            upper.pop()
        upper.append(p)
    return np.array(lower[:-1] + upper[:-1])


def plot_mechanism(res: Analysis, cycle: Analysis, path: Path) -> Path:
    """The linkage at res's single angle; `cycle` gives the point paths and guide strokes."""
    from matplotlib.patches import Polygon

    m = res.mech
    fig = _figure(8, 6.5)
    ax = fig.subplots()
    W = _world(res, 0)
    size = m.size
    colors = {k: f"C{k % 10}" for k in range(1, m.n_links)}
    # point paths over the cycle
    for link in m.links[1:]:
        for name, xy in link.points.items():
            P = cycle.kin.point(link.id, np.asarray(xy, float))[0]
            if np.ptp(P[:, 0]) + np.ptp(P[:, 1]) > 1e-9 * size:
                ax.plot(*_closed(cycle.phi_deg, P[:, 0], P[:, 1])[1:], color="0.75", lw=0.8, ls=":", zorder=1)
    # gear: pitch circle of the wheel on the crank shaft
    if m.drive.kind == "machine" and m.drive.gear is not None:
        c = W[0][m.drive.pivot] if m.drive.pivot in W[0] else W[1][m.drive.pivot]
        t = np.linspace(0, 2 * np.pi, 200)
        rw = m.drive.gear.r_w
        ax.plot(c[0] + rw * np.cos(t), c[1] + rw * np.sin(t), color="0.55", lw=1, ls="--", zorder=1,
                label=f"pitch circle of the crank's wheel, r = {rw:.4g} m")
    # links
    from matplotlib.colors import to_rgba
    for link in m.links[1:]:
        pts = np.array(list(W[link.id].values()))
        h = _hull(pts)
        col = colors[link.id]
        label = f"{link.id}: {link.name}"
        area = 0.5 * abs(np.dot(h[:, 0], np.roll(h[:, 1], 1)) - np.dot(h[:, 1], np.roll(h[:, 0], 1))) if len(h) >= 3 else 0.0
        span = max((np.linalg.norm(a - b) for a in pts for b in pts), default=0.0)
        if len(h) >= 3 and area > 0.02 * span**2:
            ax.add_patch(Polygon(h, closed=True, facecolor=to_rgba(col, 0.22), edgecolor=col, lw=2.5,
                                 joinstyle="round", zorder=3, label=label))
        elif span > 0:   # two points, or all on a line: a bar between the farthest two
            i, j = max(((i, j) for i in range(len(pts)) for j in range(len(pts))),
                       key=lambda ij: np.linalg.norm(pts[ij[0]] - pts[ij[1]]))
            ax.plot(pts[[i, j], 0], pts[[i, j], 1], color=col, lw=4, solid_capstyle="round", zorder=3, label=label)
        else:
            ax.plot([], [], color=col, lw=4, label=label)     # a one-point link: drawn as its block
    # prismatic pairs: guide line and block
    blk_l, blk_w = 0.16 * size, 0.08 * size
    for p in m.pairs:
        if p.kind != "P":
            continue
        g, s = p.links
        d_loc = np.asarray(p.direction, float)
        th_g = res.kin.theta[0, g]
        d = np.array([math.cos(th_g) * d_loc[0] - math.sin(th_g) * d_loc[1],
                      math.sin(th_g) * d_loc[0] + math.cos(th_g) * d_loc[1]])
        n = np.array([-d[1], d[0]])
        G, S = W[g][p.guide], W[s][p.point]
        # stroke of the slider along the guide over the cycle, in the guide's frame
        thc = cycle.kin.theta[:, g]
        Gc = cycle.kin.point(g, np.asarray(m.links[g].points[p.guide], float))[0] if g else \
            np.broadcast_to(G, (len(thc), 2))
        Sc = cycle.kin.point(s, np.asarray(m.links[s].points[p.point], float))[0]
        dc = np.stack([np.cos(thc) * d_loc[0] - np.sin(thc) * d_loc[1],
                       np.sin(thc) * d_loc[0] + np.cos(thc) * d_loc[1]], -1)
        u = np.sum((Sc - Gc) * dc, axis=-1)
        u = u[np.isfinite(u)]
        lo, hi = (float(u.min()), float(u.max())) if u.size else (0.0, 0.0)
        lo, hi = lo - 0.6 * blk_l, hi + 0.6 * blk_l
        a, b = G + lo * d, G + hi * d
        if g == 0:   # a fixed guide: its axis, two rails and hatching outside them (a cylinder / slideway)
            a0, b0 = G + min(lo, 0.0) * d, G + max(hi, 0.0) * d     # the axis reaches the guide point
            ax.plot([a0[0], b0[0]], [a0[1], b0[1]], color="0.45", lw=0.8, ls="-.", zorder=2)
            for sgn in (-1, 1):
                r0, r1 = a + sgn * 0.6 * blk_w * n, b + sgn * 0.6 * blk_w * n
                ax.plot([r0[0], r1[0]], [r0[1], r1[1]], color="0.3", lw=1.4, zorder=2)
                for t in np.linspace(0.04, 0.96, 12):
                    q = r0 + t * (r1 - r0)
                    e = q + sgn * 0.3 * blk_w * n + 0.3 * blk_w * d
                    ax.plot([q[0], e[0]], [q[1], e[1]], color="0.5", lw=0.7, zorder=2)
        else:        # a guide on a moving link: the slot, drawn in that link's colour
            ax.plot([a[0], b[0]], [a[1], b[1]], color=colors[g], lw=2.5, alpha=0.8, zorder=2)
            for sgn in (-1, 1):
                r0, r1 = a + sgn * 0.6 * blk_w * n, b + sgn * 0.6 * blk_w * n
                ax.plot([r0[0], r1[0]], [r0[1], r1[1]], color=colors[g], lw=1.0, zorder=2)
        corners = [S + a * 0.5 * blk_l * d + b * 0.5 * blk_w * n for a, b in ((-1, -1), (1, -1), (1, 1), (-1, 1))]
        ax.add_patch(Polygon(np.array(corners), closed=True, facecolor=colors[s], alpha=0.55,
                             edgecolor="black", lw=1.2, zorder=4))
    # springs: zigzag between their ends
    for sp in m.springs:
        A, B = W[sp.a[0]][sp.a[1]], W[sp.b[0]][sp.b[1]]
        t = np.linspace(0, 1, 25)
        v = B - A
        L = np.linalg.norm(v) or 1.0
        nn = np.array([-v[1], v[0]]) / L
        wig = np.where((np.arange(25) % 2 == 1) & (t > 0.1) & (t < 0.9), 1.0, 0.0) * np.where(np.arange(25) % 4 == 1, 1, -1)
        Z = A + np.outer(t, v) + np.outer(0.04 * size * wig, nn)
        ax.plot(Z[:, 0], Z[:, 1], color="tab:gray", lw=1.2, zorder=2, label=f"spring: {sp.name}")
    # revolute pairs: circles; fixed ones get a ground mark
    for p in m.pairs:
        if p.kind != "R":
            continue
        k = p.links[1] if p.links[0] == 0 else p.links[0]
        X = W[k][p.point]
        if 0 in p.links:
            tri = np.array([X, X + size * np.array([-0.06, -0.09]), X + size * np.array([0.06, -0.09])])
            ax.add_patch(Polygon(tri, closed=True, facecolor="0.85", edgecolor="0.3", zorder=2))
            ax.plot([X[0] - 0.09 * size, X[0] + 0.09 * size], [X[1] - 0.09 * size] * 2, color="0.3", lw=1.5, zorder=2)
        ax.plot(*X, marker="o", ms=9, mfc="white", mec="black", mew=1.6, zorder=6)
    # points that are not revolute pairs: centres of mass filled, others hollow, frame points grey
    placed: dict[str, np.ndarray] = {}
    for k in range(m.n_links):
        for name, X in W[k].items():
            placed.setdefault(name, X)
    pivots = {p.point for p in m.pairs if p.kind == "R"}
    coms = {link.com for link in m.links[1:] if link.com}
    for name, X in placed.items():
        if name in pivots:
            continue
        if name in coms:
            ax.plot(*X, marker="o", ms=5, color="black", zorder=7)
        elif name in W[0]:
            ax.plot(*X, marker="s", ms=5, mfc="0.8", mec="0.3", zorder=7)
        else:
            ax.plot(*X, marker="o", ms=4.5, mfc="white", mec="black", zorder=7)
    # labels: points closer than 3 % of the size share one label ("O1, C1")
    groups: list[tuple[list[str], np.ndarray]] = []
    for name, X in placed.items():
        for names, Y in groups:
            if np.linalg.norm(X - Y) < 0.03 * size:
                names.append(name)
                break
        else:
            groups.append(([name], X))
    centre = np.mean(np.array(list(placed.values())), axis=0)
    for names, X in groups:
        off = X - centre
        off = off / (np.linalg.norm(off) or 1.0)
        ax.annotate(", ".join(names), X, xytext=(7 * off[0] + 6, 7 * off[1] + 8), textcoords="offset points",
                    fontsize=10, fontweight="bold", zorder=8,
                    bbox=dict(boxstyle="round,pad=0.1", fc="white", ec="none", alpha=0.7))
    ax.set_aspect("equal", adjustable="datalim")
    ax.grid(True, alpha=0.3)
    ax.set_xlabel("x, m")
    ax.set_ylabel("y, m")
    ax.set_title(f"{m.name}\nat φ = {res.phi_deg[0]:.4g}° (dotted: paths of the points over the cycle)",
                 fontsize=10)
    ax.legend(loc="best", fontsize=8, framealpha=0.85)
    return _save(fig, path)


def plot_moment(run: ModelRun, path: Path) -> Path:
    res, m = run.res, run.mech
    fig = _figure(9.5, 6.5)
    ax, ax2 = fig.subplots(2, 1, sharex=True, height_ratios=[3, 1])
    phi = res.phi_deg
    ax.plot(*_closed(phi, res.balancing_moment), color="black", lw=2.6, label="kinetostat: group by group")
    ax.plot(*_closed(phi, res.lever_moment), color="0.55", lw=1.4, ls="--", label="kinetostat: Zhukovsky's lever")
    for n, (route, er) in enumerate(run.results.items()):
        col, ls = _style(route, n)
        ax.plot(*_closed(er.phi_deg, er.M_drive), color=col, ls=ls, lw=1.6, label=f"{route} ({er.route})")
    ax.axhline(0, color="0.3", lw=0.6)
    ax.set_ylabel("balancing moment on the crank M_bal, N·m")
    kind = "moment of the drive on the crank about +z"
    ax.set_title(f"{m.name}\nbalancing moment ({kind}) over the cycle", fontsize=10)
    ax.legend(fontsize=8, loc="best")
    _phi_axis(ax, label=False, step=30)
    ax2.plot(*_closed(phi, res.lever_discrepancy), color="0.3", lw=1)
    ax2.set_ylabel("lever − groups, N·m", fontsize=9)
    ax2.ticklabel_format(axis="y", style="sci", scilimits=(-3, 3))
    _phi_axis(ax2, step=30)
    return _save(fig, path)


def plot_reactions(run: ModelRun, path: Path) -> Path:
    res, m = run.res, run.mech
    rows, cols = _grid(len(m.pairs))
    fig = _figure(4.6 * cols + 0.6, 3.0 * rows + 0.9)
    axes = fig.subplots(rows, cols, squeeze=False).ravel()
    handles = {}
    for n_ax, (ax, p) in enumerate(zip(axes, m.pairs)):
        mag = np.linalg.norm(res.forces.R[:, p.index], axis=-1)
        h, = ax.plot(*_closed(res.phi_deg, mag), color="black", lw=2.4)
        handles["kinetostat"] = h
        for n, (route, er) in enumerate(run.results.items()):
            col, ls = _style(route, n)
            h, = ax.plot(*_closed(er.phi_deg, np.linalg.norm(er.R[:, p.index], axis=-1)), color=col, ls=ls, lw=1.5)
            handles[f"{route} ({er.route})"] = h
        ax.set_title(_wrap(f"{_pair_name(m, p)}: {_link_name(m, p.links[0])} on {_link_name(m, p.links[1])}"), fontsize=9)
        ax.set_ylabel("|R|, N")
        ax.set_ylim(bottom=0)
        _phi_axis(ax, label=n_ax + cols >= len(m.pairs))
    for ax in axes[len(m.pairs):]:
        ax.set_visible(False)
    fig.suptitle(f"{m.name}\nreaction magnitudes over the cycle (R(i,j): force of link i on link j)", fontsize=10)
    fig.legend(list(handles.values()), list(handles), loc="outside lower center", ncols=min(len(handles), 5),
               fontsize=8)
    return _save(fig, path)


def _error_curves(res: Analysis, er) -> dict[str, tuple[np.ndarray, np.ndarray, float]]:
    """quantity -> (phi, |engine - solver|, peak |solver|), as compare.errors measures them."""
    out = {}
    m = res.mech
    items = [("M_drive", res.balancing_moment[:, None], er.M_drive[:, None])]
    items += [(f"R({p.links[0]},{p.links[1]})", res.forces.R[:, p.index], er.R[:, p.index]) for p in m.pairs]
    for name, ref, got in items:
        if er.magnitudes_only:
            ref = np.linalg.norm(ref, axis=-1, keepdims=True)
            got = np.linalg.norm(got, axis=-1, keepdims=True)
        err = np.linalg.norm(got - ref, axis=-1)
        peak = float(np.nanmax(np.linalg.norm(ref, axis=-1))) if np.any(np.isfinite(ref)) else 0.0
        out[name] = (er.phi_deg, err, peak)
    return out


def plot_errors(run: ModelRun, path: Path) -> Path:
    res, m = run.res, run.mech
    qs = quantities(m)
    rows, cols = _grid(len(qs))
    fig = _figure(4.6 * cols + 0.6, 3.0 * rows + 1.1)
    axes = fig.subplots(rows, cols, squeeze=False).ravel()
    curves = {route: _error_curves(res, er) for route, er in run.results.items()}
    handles = {}
    for n_ax, (ax, q) in enumerate(zip(axes, qs)):
        unit = "N·m" if q == "M_drive" else "N"
        any_drawn = False
        for n, route in enumerate(run.results):
            col, ls = _style(route, n)
            phi, err, peak = curves[route][q]
            e = np.where(err > 0, err, np.nan)
            if np.any(np.isfinite(e)):
                h, = ax.semilogy(*_closed(phi, e), color=col, lw=1.3)
                handles[f"{route}: |engine − kinetostat|"] = h
                any_drawn = True
            tol = run.tolerances.get(route)
            if tol is not None and peak > 0:
                h = ax.axhline(tol.peak_relative * peak, color=col, ls="--", lw=1)
                handles[f"{route}: tolerance × peak"] = h
        if not any_drawn:
            ax.text(0.5, 0.5, "no differences to draw\n(no engine results, or exactly equal)",
                    transform=ax.transAxes, ha="center", va="center", fontsize=8, color="0.4")
            ax.set_yscale("log")
        title = "M_drive: balancing moment" if q == "M_drive" else \
            _pair_name(m, m.pair_between(*map(int, q[2:-1].split(","))))
        ax.set_title(_wrap(title), fontsize=9)
        ax.set_ylabel(f"|error|, {unit}")
        _phi_axis(ax, label=n_ax + cols >= len(qs))
        ax.grid(True, which="major", alpha=0.3)
    for ax in axes[len(qs):]:
        ax.set_visible(False)
    fig.suptitle(f"{m.name}\nerror of each engine route against kinetostat (log scale; "
                 f"dashed: the route's tolerance × the cycle's peak)", fontsize=10)
    if handles:
        fig.legend(list(handles.values()), list(handles), loc="outside lower center",
                   ncols=min(len(handles), 4), fontsize=8)
    return _save(fig, path)


def plot_hodographs(run: ModelRun, path: Path) -> Path:
    """Tip of each revolute pair's reaction vector over the cycle (seed 004, figs. 13-14)."""
    res, m = run.res, run.mech
    pairs = [p for p in m.pairs if p.kind == "R"]
    rows, cols = _grid(len(pairs))
    fig = _figure(4.8 * cols + 0.4, 4.6 * rows + 0.8)
    axes = fig.subplots(rows, cols, squeeze=False).ravel()
    phi = res.phi_deg
    handles = {}
    for ax, p in zip(axes, pairs):
        R = res.forces.R[:, p.index]
        _, Rx, Ry = _closed(phi, R[:, 0], R[:, 1])
        h, = ax.plot(Rx, Ry, color="black", lw=2)
        handles["kinetostat"] = h
        for n, (route, er) in enumerate(run.results.items()):
            if er.magnitudes_only:
                continue
            col, ls = _style(route, n)
            E = er.R[:, p.index]
            h, = ax.plot(*_closed(er.phi_deg, E[:, 0], E[:, 1])[1:], color=col, ls=ls, lw=1.3)
            handles[f"{route} ({er.route})"] = h
        ax.plot(0, 0, marker="+", ms=12, color="black")
        mag = np.linalg.norm(R, axis=-1)
        fin = np.isfinite(mag)
        # rays at every 30 deg of the cycle, labelled with the angle
        for a in range(0, 360, 30):
            i = int(np.argmin(np.abs(((phi - a) + 180) % 360 - 180)))
            if abs(((phi[i] - a) + 180) % 360 - 180) > 2.5 or not fin[i] or mag[i] < 0.12 * np.nanmax(mag):
                continue      # short rays near the origin would only clutter the labels
            ax.annotate("", xy=R[i], xytext=(0, 0),
                        arrowprops=dict(arrowstyle="-|>", color="0.6", lw=0.7, shrinkA=0, shrinkB=0))
            ax.annotate(f"{phi[i]:.0f}°", R[i], xytext=(3, 3), textcoords="offset points", fontsize=7, color="0.25")
        if fin.any():
            i = int(np.nanargmax(mag))
            h, = ax.plot(*R[i], marker="o", ms=6, color="tab:red", ls="none")
            ax.annotate(f"max {mag[i]:.4g} N\nat {phi[i]:.4g}°", R[i], xytext=(6, -14), textcoords="offset points",
                        fontsize=7, color="tab:red")
        ax.set_aspect("equal", adjustable="datalim")
        ax.grid(True, alpha=0.3)
        ax.set_xlabel("R_x, N")
        ax.set_ylabel("R_y, N")
        ax.set_title(_wrap(f"{_pair_name(m, p)}: {_link_name(m, p.links[0])} on {_link_name(m, p.links[1])}"), fontsize=9)
    for ax in axes[len(pairs):]:
        ax.set_visible(False)
    fig.suptitle(f"{m.name}\nhodographs of the revolute pairs' reactions "
                 f"(tip of the force vector over the cycle, world frame; grey rays every 30° of φ)", fontsize=10)
    fig.legend(list(handles.values()), list(handles), loc="outside lower center", ncols=min(len(handles), 4),
               fontsize=8)
    return _save(fig, path)


# ============================================================================ the report

def _versions() -> str:
    from importlib import metadata

    from . import __version__
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


def write_report(run: ModelRun, out: Path, steps_note: str | None = None) -> dict[str, Any]:
    """Write `out/<stem>/` for one model; returns the summary also saved as summary.json."""
    from validation.compare import TOLERANCES

    m, res = run.mech, run.res
    d = Path(out) / run.stem
    d.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    pub = PUBLISHED.get(run.stem)
    published = published_rows(m, run.stem) if pub is not None else None
    pic_deg = pub.picture_deg if pub is not None else 30.0
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

    if published is not None:
        doc.h(2, "Against the published values")
        doc.p(f"Source: {pub.source}. Evaluated at φ = "
              + (f"{pub.phi_deg[0]:g}°" if len(pub.phi_deg) == 1 else
                 f"{pub.phi_deg[0]:g}°, {pub.phi_deg[1]:g}°, ..., {pub.phi_deg[-1]:g}° ({len(pub.phi_deg)} positions)")
              + f". Expected agreement: {pub.accuracy}.")
        rows = []
        for r in published:
            diff = f"{r['diff']:+.3f} %" if r["diff_unit"] == "%" else f"{r['diff']:+.3g}°"
            tol = f"±{100 * r['tolerance']:g} %" if r["diff_unit"] == "%" else f"±{r['tolerance']:g}°"
            rows.append([r["symbol"], r["meaning"], f"{r['published']:g}", f"{r['exact']:.6g}", r["unit"], diff, tol,
                         "yes" if r["ok"] else "**NO**"])
        doc.table(["quantity", "meaning", "published", "kinetostat (exact)", "unit", "difference", "accepted",
                   "within"], rows, "llrrlrrl")

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
                   published=None if published is None else dict(
                       n=len(published), within=sum(bool(r["ok"]) for r in published),
                       worst_percent=max((abs(r["diff"]) for r in published if r["diff_unit"] == "%"), default=None)),
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
