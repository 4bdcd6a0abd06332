"""The data of a drawn plan (issue: the graphical method): named points in millimetres on the
sheet, lettered segments, and the scale that turns a drawn length into the quantity it stands for.

Every plan of the method (positions, velocity, acceleration, a group's plan and force plan, the
initial link, Zhukovsky's lever) is built for N crank angles at once as a `PlanCycle` (arrays with
a leading angle axis: every point, segment value, path and result), and `PlanCycle.at(i)` is the
`Plan` of one angle (scalars); a sheet of one angle is the N = 1 case. Data first, drawn later (SVG sheets, matplotlib
figures) by `draw`, which this module never imports. A segment's drawn length times the plan's scale is the
magnitude of the quantity it stands for (`Segment.value`, SI).

May use: numpy and the standard library. Never matplotlib at import time, never the harness.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from types import MappingProxyType
from typing import Mapping

import numpy as np

__all__ = ["Scale", "Segment", "ROLES", "role_of", "Result", "Plan", "PlanCycle", "Element", "Drawing", "SEGMENT_COLUMNS",
           "extent", "extent_cycle", "ELEMENTS", "fixed", "construction", "alias", "UNMEASURED"]

#: Columns of segments.csv, in order.
SEGMENT_COLUMNS = ("plan", "segment", "from", "to", "x0_mm", "y0_mm", "x1_mm", "y1_mm", "length_mm",
                   "value", "unit", "scale")


@dataclass(frozen=True)
class Scale:
    """A drawing scale: `value` SI units of the quantity per millimetre drawn (the texts' μ)."""
    symbol: str          # "mu_l", "mu_v", "mu_a", "mu_F"
    value: float         # e.g. 0.001 for mu_l = 0.001 m/mm
    unit: str            # "m/mm", "m/(s mm)", "m/(s^2 mm)", "N/mm"

    def __str__(self) -> str:
        return f"{self.symbol} = {self.value:g} {self.unit}"


@dataclass(frozen=True)
class Segment:
    """One drawn segment from point `start` to point `end` of its plan.

    `name` is lettered as the texts letter it (`p-b`, `a-n2`, `R12`, `h_G2`); `value` is the
    quantity it stands for in SI units (signed where the texts sign it, else a magnitude), so that
    |value| = drawn length x scale for a vector or an arm drawn at the plan's scale; `kind` says how
    it is drawn: "vector" (an arrow), "link" (a link of the mechanism), "position" (a link at one
    of the other positions of the plan of positions, drawn thin), "arm" (a moment arm),
    "line" (a direction, a path), "construction" (a line of known direction drawn through the
    known point `start` toward the point `end` that its intersection with another fixes, drawn
    thin past both), "intersection" (the mark at `start` = `end` where construction lines meet),
    "alternative" (an arrow that replaces others
    drawn: F_i2(h) for F_i2 and M_i2, dashed), "extension" (a link's line drawn on, dashed, to a
    force acting off it). `role` says how heavy it is drawn (`ROLES`, `role_of`): "" takes
    its kind's (`KIND_ROLES`). A segment whose quantity is not at the plan's
    scale (a link of a lever, a path) has `value` NaN and unit "", unless it names its own `scale`
    (a force drawn on a group plan: |value| = drawn length x segment.scale).
    """
    name: str
    start: str
    end: str
    value: float
    unit: str
    kind: str = "vector"
    scale: Scale | None = None   # a segment drawn at another scale than its plan's (the loads on a
                                 # group plan, at a force scale); None: the plan's scale
    role: str = ""               # one of ROLES, or "": its kind's (KIND_ROLES)
    # In a PlanCycle, `value` is an (N,) array over its angles.

    def __post_init__(self) -> None:
        if self.role and self.role not in ROLES:
            raise ValueError(f"segment {self.name!r}: role {self.role!r} is none of {', '.join(ROLES)}")


#: A segment's role on its sheet, which sets its line weight (`draw.WEIGHT_MM`): "given" (known
#: before the plan is drawn: a load, the driving link's velocity or acceleration), "component" (a
#: part of a vector sum: a relative velocity, a normal, tangential or Coriolis part, R12n, R12t),
#: "result" (what the plan is drawn to find: an absolute velocity or acceleration, a whole
#: reaction, the balancing force), "construction" (a line of known direction), "link" (a link of
#: the mechanism, of the lever), "auxiliary" (the other positions, arms, a link drawn on).
ROLES = ("result", "link", "given", "component", "construction", "auxiliary")
#: The role of a segment that states none, by its kind (a vector: a given, unless its plan says).
KIND_ROLES = {"vector": "given", "alternative": "given", "link": "link", "line": "construction",
              "construction": "construction", "intersection": "construction", "position": "auxiliary", "arm": "auxiliary",
              "dimension": "auxiliary", "extension": "auxiliary"}


def role_of(s: Segment) -> str:
    """The segment's role (`ROLES`): its own, else its kind's (auxiliary for a kind not listed)."""
    return s.role or KIND_ROLES.get(s.kind, "auxiliary")


#: Kinds of segment no one measures: a position's link, a line, a construction line, a mark.
UNMEASURED = ("position", "line", "construction", "intersection")


def construction(point: str, lines: list[tuple[str, str]], order: str = "") -> list[Segment]:
    """The construction that fixes `point` (seed 002 sec. 1.2: "through a draw a line
    perpendicular to AB, through p a vertical line; their intersection is b"): for each
    (name, known point) of `lines` the line of known direction "line <name>" from the known point
    toward `point`, then the intersection's mark "point <point>"; nothing at a scale. `order`: a
    construction drawn at some angles only (a triad's, in one order of its sides): the lines run
    to, and the mark is at, the unlettered point '<point>:<order>' (`alias`), which the plan
    holds at those angles and NaN at the others."""
    end = alias(point, order)
    return [*(Segment(f"line {name}", known, end, math.nan, "", "construction") for name, known in lines),
            Segment(f"point {point}", end, end, math.nan, "", "intersection")]


def alias(point: str, order: str) -> str:
    """The name of `point` in a construction drawn in `order` only ('c:1'; `point` where no order):
    unlettered on a sheet (a ':' in its name)."""
    return f"{point}:{order}" if order else point


@dataclass(frozen=True)
class Result:
    """A result a sheet states beside its plan: `symbol` as the text letters it (M_зр, δ),
    `value` SI in `unit`, and `how`: a key of the message catalogue (`i18n.MESSAGES`) saying how
    it is obtained, or ""."""
    symbol: str
    value: float         # in a PlanCycle: an (N,) array over its angles
    unit: str
    how: str = ""        # in a PlanCycle: one key, or (N,) keys where it changes with the angle


@dataclass(frozen=True)
class Plan:
    """A plan of the method at one crank angle: points on the sheet (mm, x right, y up, the world's
    orientation unless the plan says otherwise, e.g. the lever's forces turned by 90 deg), its segments,
    and its scale. `kind` is one of "positions", "velocity", "acceleration", "group:<i,j>",
    "forces:<i,j>", "crank", "lever" (the `plan` column of segments.csv)."""
    kind: str
    title: str
    scale: Scale
    phi_deg: float
    points: Mapping[str, complex]          # name -> x + 1j*y on the sheet, mm
    segments: tuple[Segment, ...]
    paths: Mapping[str, tuple[complex, ...]] = field(default_factory=dict)   # polylines (mm), e.g. paths of S
    notes: tuple[str, ...] = ()            # lines of text the sheet shows beside the plan (e.g. the branches)
    results: tuple[Result, ...] = ()       # what the sheet finds (M_зр, δ), stated beside the plan
    equation: tuple[str, ...] = ()         # a force plan's vector equation: its sides' names in the order drawn
    accuracy: tuple[float, int] | None = None   # near a singular position: (digits left, fewer than this);
                                                # the sheet states it (i18n.accuracy)
    steps: tuple[str, ...] = ()            # the construction in the texts' order: segment names, numbered
                                           # 1, 2, ... on the sheet and in the page's "next step"

    def __post_init__(self) -> None:
        object.__setattr__(self, "points", MappingProxyType(dict(self.points)))
        object.__setattr__(self, "paths", MappingProxyType({k: tuple(v) for k, v in self.paths.items()}))
        object.__setattr__(self, "notes", tuple(self.notes))
        object.__setattr__(self, "results", tuple(self.results))
        object.__setattr__(self, "equation", tuple(self.equation))
        object.__setattr__(self, "steps", tuple(self.steps))

    def length_mm(self, name: str) -> float:
        """Drawn length of the segment `name`, mm."""
        s = self.segment(name)
        return abs(self.points[s.end] - self.points[s.start])

    def segment(self, name: str) -> Segment:
        for s in self.segments:
            if s.name == name:
                return s
        raise KeyError(f"{self.kind}: no segment {name!r}; segments: {', '.join(s.name for s in self.segments)}")

    def rows(self) -> list[dict]:
        """One dict per segment with the columns of segments.csv (SEGMENT_COLUMNS)."""
        out = []
        for s in self.segments:
            a, b = self.points[s.start], self.points[s.end]
            out.append({"plan": self.kind, "segment": s.name, "from": s.start, "to": s.end,
                        "x0_mm": a.real, "y0_mm": a.imag, "x1_mm": b.real, "y1_mm": b.imag,
                        "length_mm": abs(b - a), "value": s.value, "unit": s.unit,
                        "scale": str(s.scale or self.scale)})
        return out

    def __repr__(self) -> str:
        return (f"Plan({self.kind!r}, phi_deg={self.phi_deg:g}, {self.scale}, points={len(self.points)}, "
                f"segments={len(self.segments)})")


def extent(plan: Plan) -> tuple[float, float, float, float]:
    """(x0, y0, x1, y1) of the plan's finite points and paths, mm."""
    zs = [z for z in plan.points.values() if math.isfinite(z.real) and math.isfinite(z.imag)]
    zs += [z for p in plan.paths.values() for z in p if math.isfinite(z.real) and math.isfinite(z.imag)]
    if not zs:
        return 0.0, 0.0, 0.0, 0.0
    return min(z.real for z in zs), min(z.imag for z in zs), max(z.real for z in zs), max(z.imag for z in zs)


def extent_cycle(cycle: "PlanCycle") -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(x0, y0, x1, y1), each (N,) mm: `extent` of the plan at every angle of the cycle (its finite
    points and paths; 0 where none is finite)."""
    n = cycle.n
    cols = [v.reshape(n, 1) for v in cycle.points.values()]
    cols += [np.broadcast_to(v, (n, v.shape[1])) for v in cycle.paths.values()]
    if not cols:
        return tuple(np.zeros(n) for _ in range(4))
    z = np.concatenate(cols, axis=1)
    ok = np.isfinite(z.real) & np.isfinite(z.imag)
    some = ok.any(axis=1)
    out = []
    for part, lo in ((z.real, True), (z.imag, True), (z.real, False), (z.imag, False)):
        v = (np.min(part, axis=1, where=ok, initial=np.inf) if lo else np.max(part, axis=1, where=ok, initial=-np.inf))
        out.append(np.where(some, v, 0.0))
    x0, y0, x1, y1 = out
    return x0, y0, x1, y1


def _one(x, i: int) -> float:
    return float(np.asarray(x).reshape(-1)[i if np.size(x) > 1 else 0])


@dataclass(frozen=True, eq=False)
class PlanCycle:
    """A plan of the method at N crank angles at once, every scale fixed for them: what the plan
    builders make. The same element (point, segment, path) at every angle; where it is not drawn
    at an angle its points are NaN there. `at(i)` is the `Plan` of angle i.

    Arrays, each with the leading angle axis N: `phi_deg` (N,) deg; `points[name]` (N,) complex,
    mm on the sheet (x right, y up); each segment's `value` and each result's `value` (N,) SI;
    `paths[name]` (N, K) complex mm, or (1, K) where the path is the same at every angle;
    `accuracy`: (digits left (N,), the count under which a sheet states it) or None.
    A segment with a unit whose value is NaN at an angle is not drawn there (`drawn`); `equation`
    the side names at every angle, or N such tuples where the order changes with the angle (a
    triad's), and so `steps`; a result's `how` one key, or N keys."""
    kind: str
    titles: tuple[str, ...]                # (N,) the title at each angle
    scale: Scale
    phi_deg: np.ndarray
    points: Mapping[str, np.ndarray]
    segments: tuple[Segment, ...]
    paths: Mapping[str, np.ndarray] = field(default_factory=dict)
    notes: tuple[tuple[str, ...], ...] = ()   # (N,) each angle's notes (see Plan.notes); () none at any
    results: tuple[Result, ...] = ()
    equation: tuple[str, ...] = ()
    accuracy: tuple[np.ndarray, int] | None = None
    steps: tuple = ()                         # see Plan.steps; N such tuples where they change with the
                                              # angle (a triad's, its sides in another order)

    def __post_init__(self) -> None:
        phi = np.atleast_1d(np.asarray(self.phi_deg, dtype=float))
        n = len(phi)
        object.__setattr__(self, "phi_deg", phi)
        object.__setattr__(self, "titles", tuple(self.titles))
        if len(self.titles) != n:
            raise ValueError(f"{self.kind}: {len(self.titles)} titles for {n} angles")
        pts = {k: np.broadcast_to(np.asarray(v, dtype=complex), (n,)) for k, v in self.points.items()}
        object.__setattr__(self, "points", MappingProxyType(pts))
        paths = {k: np.atleast_2d(np.asarray(v, dtype=complex)) for k, v in self.paths.items()}
        object.__setattr__(self, "paths", MappingProxyType(paths))
        object.__setattr__(self, "notes", tuple(tuple(x) for x in self.notes))
        object.__setattr__(self, "results", tuple(self.results))
        object.__setattr__(self, "equation", tuple(self.equation))
        object.__setattr__(self, "steps", tuple(self.steps))

    @property
    def n(self) -> int:
        """The number of angles."""
        return len(self.phi_deg)

    @classmethod
    def of(cls, plan: Plan) -> "PlanCycle":
        """The plan of one angle as a cycle of N = 1."""
        acc = None if plan.accuracy is None else (np.array([plan.accuracy[0]]), plan.accuracy[1])
        return cls(plan.kind, (plan.title,), plan.scale, np.array([plan.phi_deg]),
                   {k: np.array([v]) for k, v in plan.points.items()},
                   tuple(replace(s, value=np.array([s.value], dtype=float)) for s in plan.segments),
                   {k: np.array([v], dtype=complex) for k, v in plan.paths.items()},
                   (plan.notes,), tuple(Result(r.symbol, np.array([r.value]), r.unit, r.how) for r in plan.results),
                   plan.equation, acc, plan.steps)

    def length_mm(self, name: str) -> np.ndarray:
        """Drawn length of the segment `name` at every angle, mm, (N,)."""
        s = next((s for s in self.segments if s.name == name), None)
        if s is None:
            raise KeyError(f"{self.kind}: no segment {name!r}; segments: {', '.join(s.name for s in self.segments)}")
        return np.abs(self.points[s.end] - self.points[s.start])

    def at(self, i: int) -> Plan:
        """The plan of angle i (0 <= i < n): scalars where the cycle holds arrays."""
        if not -self.n <= i < self.n:
            raise IndexError(f"{self.kind}: angle index {i} out of range for {self.n} angles")
        acc = None
        if self.accuracy is not None and float(self.accuracy[0][i]) < self.accuracy[1]:
            acc = (float(self.accuracy[0][i]), self.accuracy[1])
        return Plan(self.kind, self.titles[i], self.scale, float(self.phi_deg[i]),
                    {k: complex(v[i]) for k, v in self.points.items()},
                    tuple(replace(s, value=_one(s.value, i)) for s in self.segments if self.drawn(s)[i]),
                    {k: tuple(map(complex, v[i if len(v) > 1 else 0])) for k, v in self.paths.items()},
                    self.notes[i] if self.notes else (),
                    tuple(Result(r.symbol, _one(r.value, i), r.unit, r.how if isinstance(r.how, str) else r.how[i])
                          for r in self.results),
                    self.equation if not self.equation or isinstance(self.equation[0], str) else self.equation[i], acc,
                    self.steps_at(i))

    def steps_at(self, i: int) -> tuple[str, ...]:
        """The construction's steps at angle i (`Plan.steps`)."""
        return self.steps if not self.steps or isinstance(self.steps[0], str) else self.steps[i]

    def drawn(self, s: Segment) -> np.ndarray:
        """(N,) bool: the angles segment s is drawn at: all, but where a quantity's value (a
        segment with a unit) is NaN: an element that exists at other angles only (a triad's
        polygon in another order, an arm of a force that is zero there)."""
        return np.broadcast_to(~(bool(s.unit) & np.isnan(np.asarray(s.value, dtype=float))), (self.n,))

    def __repr__(self) -> str:
        return (f"PlanCycle({self.kind!r}, {self.n} angles, {self.scale}, points={len(self.points)}, "
                f"segments={len(self.segments)})")


#: The decimals the interactive page writes a sheet with (`Drawing.svg`'s coord, length): its
#: coordinates to 0.1 mm (a third of a pencil line, a third of a screen pixel at 96 dpi) and a
#: segment's data-length-mm to 1e-6 mm (the page contract: segments.csv's length to 1e-6 mm, 5e-7 at most off).
PAGE_DECIMALS = (1, 6)
#: Where a Drawing's `static` markup takes the elements of an angle (`Drawing.svg`).
ELEMENTS = "<!--elements-->\n"


def fixed(q: int, digits: int) -> str:
    """The integer q / 10**digits written with `digits` decimals, exactly ('-' only below zero)."""
    whole, frac = divmod(abs(int(q)), 10 ** digits)
    return f"{'-' if q < 0 else ''}{whole}.{frac:0{digits}d}"


@dataclass(frozen=True, eq=False)
class Element:
    """One element of a drawn sheet over N angles, in sheet millimetres (x right, y down: SVG's
    user units), ready to write at any angle i. `tag`: "line" (xy[i] = its two ends), "path" (a
    closed polygon through xy[i]: an arrowhead), "polyline" (through xy[i]), "circle" (centre
    xy[i, 0]; its "r" in attrs), "text" (a label or a line of text: anchor xy[i, 0]; its markup
    `texts[variant[i]]`, tspans placed relative to it), "g" (an empty group, no coordinates: a
    negligible vector's place in the page contract). `xy` (N, M, 2) float, or (1, M, 2) where the
    same at every angle; a NaN at angle i: the element is not drawn there (a polyline: through its
    finite points, drawn where at least two). `attrs`: attributes the same at every angle (stroke,
    class, data-plan, data-segment, ...) and `title`, its tooltip or "": markup, escaped already.
    `length_mm` (N,): a segment's drawn length at its scale (the page contract's data-length-mm),
    or None. `svg(i)` writes it (see `Drawing`)."""
    tag: str
    xy: np.ndarray
    attrs: Mapping[str, str] = field(default_factory=dict)
    title: str = ""
    texts: tuple[str, ...] = ()
    variant: np.ndarray | None = None
    length_mm: np.ndarray | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "xy", np.asarray(self.xy, dtype=float))
        object.__setattr__(self, "attrs", MappingProxyType(dict(self.attrs)))
        object.__setattr__(self, "texts", tuple(self.texts))

    def drawn(self) -> np.ndarray:
        """Whether the element is drawn at each angle, (N,) or (1,)."""
        fin = np.isfinite(self.xy).all(axis=2)
        return fin.sum(axis=1) >= 2 if self.tag == "polyline" else fin.all(axis=1)

    def svg(self, i: int, coord: int = 3, length: int = 9) -> str:
        """The element at angle i as SVG ("" where not drawn there): `<tag` + its coordinates,
        each q = rint(10^coord x) written with `coord` decimals (`fixed`) + ` k="v"` for each of
        attrs in order + ` data-length-mm="..."` (rint(10^length L), `length` decimals) where it has lengths + `>` +
        `<title>title</title>` where it has one + a text's markup + `</tag>`. Coordinates: line
        x1 y1 x2 y2; circle cx cy; text x y; polyline points="x,y x,y ..." (its finite points);
        path d="Mx,y Lx,y ... z"; g none."""
        xy = self.xy[i if len(self.xy) > 1 else 0]
        if self.tag == "polyline":
            xy = xy[np.isfinite(xy).all(axis=1)]
            if len(xy) < 2:
                return ""
        elif not np.isfinite(xy).all():
            return ""
        q = np.rint(xy * 10.0 ** coord).astype(np.int64).tolist()
        c = [[fixed(v, coord) for v in p] for p in q]
        if self.tag == "line":
            head = f' x1="{c[0][0]}" y1="{c[0][1]}" x2="{c[1][0]}" y2="{c[1][1]}"'
        elif self.tag == "circle":
            head = f' cx="{c[0][0]}" cy="{c[0][1]}"'
        elif self.tag == "text":
            head = f' x="{c[0][0]}" y="{c[0][1]}"'
        elif self.tag == "polyline":
            head = ' points="' + " ".join(f"{x},{y}" for x, y in c) + '"'
        elif self.tag == "path":
            head = ' d="M' + " L".join(f"{x},{y}" for x, y in c) + ' z"'
        else:
            head = ""
        head += "".join(f' {k}="{v}"' for k, v in self.attrs.items())
        if self.length_mm is not None:
            L = self.length_mm[i if len(self.length_mm) > 1 else 0]
            head += f' data-length-mm="{fixed(int(np.rint(L * 10.0 ** length)), length)}"'
        body = f"<title>{self.title}</title>" if self.title else ""
        if self.tag == "text":
            body += self.texts[int(self.variant[i if len(self.variant) > 1 else 0])]
        return f"<{self.tag}{head}>{body}</{self.tag}>"


@dataclass(frozen=True, eq=False)
class Drawing:
    """A plan's sheet at N angles as arrays (`draw.drawing`): `static` the SVG document the same
    at every angle (the XML declaration, the <svg> root, the sheet's frame, the parts of the title
    block that do not change) holding `ELEMENTS` once, where `elements`, in the order drawn, go.
    `svg(i)` in Python and the page's script in a browser write the same sheet of angle i from
    these arrays: `static` with ELEMENTS replaced by each element's `Element.svg(i)` + "\n"
    (those drawn there). A sheet's file writes coordinates to 0.001 mm and lengths to 1e-9 mm;
    the page to PAGE_DECIMALS."""
    kind: str
    phi_deg: np.ndarray                    # (N,) deg
    static: str
    elements: tuple[Element, ...]

    @property
    def n(self) -> int:
        """The number of angles."""
        return len(self.phi_deg)

    def svg(self, i: int, coord: int = 3, length: int = 9) -> str:
        """The whole SVG document of angle i (0 <= i < n), coordinates (mm) with `coord`
        decimals and lengths (mm) with `length` (`Element.svg`)."""
        if not -self.n <= i < self.n:
            raise IndexError(f"{self.kind}: angle index {i} out of range for {self.n} angles")
        body = "".join(s + "\n" for s in (e.svg(i, coord, length) for e in self.elements) if s)
        return self.static.replace(ELEMENTS, body, 1)
