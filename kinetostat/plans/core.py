"""The data of a drawn plan (issue: the graphical method): named points in millimetres on the
sheet, lettered segments, and the scale that turns a drawn length into the quantity it stands for.

Every plan of the method (positions, velocity, acceleration, a group's plan and force plan, the
initial link, Zhukovsky's lever) is a `Plan`: data first, drawn later (SVG sheets, matplotlib
figures) by `draw`, which this module never imports. A segment's drawn length times the plan's scale is the
magnitude of the quantity it stands for (`Segment.value`, SI).

May use: numpy and the standard library. Never matplotlib at import time, never the harness.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Mapping

__all__ = ["Scale", "Segment", "Result", "Plan", "SEGMENT_COLUMNS", "extent"]

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
    "line" (a construction line: a direction, a path). A segment whose quantity is not at the plan's
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


@dataclass(frozen=True)
class Result:
    """A result a sheet states beside its plan: `symbol` as the text letters it (M_зр, δ),
    `value` SI in `unit`, and `how`: a key of the message catalogue (`i18n.MESSAGES`) saying how
    it is obtained, or ""."""
    symbol: str
    value: float
    unit: str
    how: str = ""


@dataclass(frozen=True)
class Plan:
    """A plan of the method at one crank angle: points on the sheet (mm, x right, y up, the world's
    orientation unless the plan says otherwise, e.g. the lever turned by 90 deg), its segments,
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

    def __post_init__(self) -> None:
        object.__setattr__(self, "points", MappingProxyType(dict(self.points)))
        object.__setattr__(self, "paths", MappingProxyType({k: tuple(v) for k, v in self.paths.items()}))
        object.__setattr__(self, "notes", tuple(self.notes))
        object.__setattr__(self, "results", tuple(self.results))
        object.__setattr__(self, "equation", tuple(self.equation))

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
