"""The mechanism at its design position, drawn as seed 002 fig. 1.6 draws it: the links to scale
(mu_l), the frame hatched under its pins and along its guides, the pairs drawn as pairs (a pin
as a small circle, a slider as a block on its guide), the centres of mass, and the senses of
every link's angular velocity ω and acceleration ε as arcs with an arrowhead.

The drawing's marks are `Plan.paths` (sheet mm) named by what they are: "pin A", "block B",
"support O", "hatch ..", "com S2", and "ω2", "ε2" for the senses; `draw` draws each by its name.

May use: numpy, `core`, `forces` (the links drawn at mu_l). Never matplotlib.
"""
from __future__ import annotations

import math

import numpy as np

from .core import Plan, Scale, Segment
from .forces import _link_drawing, _world

__all__ = ["mechanism_plan", "PIN_MM", "BLOCK_MM", "ARC_MM"]

#: Radius of a pin, mm; a slider block (length, width), mm; radii of the ω and ε arcs, mm.
PIN_MM, BLOCK_MM, ARC_MM = 1.2, (10.0, 6.0), (7.0, 10.0)


def _circle(c: complex, r: float, n: int = 16) -> tuple[complex, ...]:
    return tuple(c + r * np.exp(2j * np.pi * np.arange(n + 1) / n))


def _hatch(a: complex, b: complex, side: complex, name: str, paths: dict) -> None:
    """The frame's hatching: the line a-b and short strokes every 2 mm on its `side` (a unit)."""
    paths[f"{name}"] = (a, b)
    L = abs(b - a)
    u = (b - a) / L if L else 1.0
    for n, t in enumerate(np.arange(1.0, min(L, 100.0), 2.0)):      # a frame's stretch: at most 50 strokes
        p = a + t * u
        paths[f"{name} {n}"] = (p, p + 2.0 * side - 1.5 * u)


def _arc(c: complex, r: float, sense: float) -> tuple[complex, ...]:
    """A 240-degree arc around c, from the upper left, in the sense's direction (ccw for +)."""
    t = np.linspace(0.0, np.radians(240.0), 25)
    return tuple(c + r * np.exp(1j * (np.radians(150.0) + sense * t)))


def _link_lines(mech, res, k: int, pts: dict, segs: list, mu: Scale) -> None:
    """Link k drawn through all its points: along each slot it carries, from end to end of what
    runs in it (O2-S3 on to B), and every point not on a drawn line joined to the nearest drawn
    point (B-S5-T of a ram)."""
    drawn = {n for s in segs if s.kind == "link" for n in (s.start, s.end)} & set(mech.links[k].points)
    for p in mech.pairs:
        if p.kind != "P" or p.links[0] != k or p.guide not in mech.links[k].points:
            continue
        G = pts[p.guide]
        d = complex(*p.direction) * complex(res.kin.rot[0, k])
        on = {n: ((pts[n] - G) * d.conjugate()).real for n in mech.links[k].points}
        on[p.point] = ((_world(res, p.links[1], p.point) / mu.value - G) * d.conjugate()).real
        lo, hi = min(on.values()), max(on.values())
        name = f"slot {k} {p.point}"
        pts[f"{name}:from"], pts[f"{name}:to"] = G + lo * d, G + hi * d
        segs.append(Segment(name, f"{name}:from", f"{name}:to", (hi - lo) * mu.value, "m", "link"))
        drawn |= {n for n in mech.links[k].points if abs(((pts[n] - G) * d.conjugate()).imag) < 1e-6}
    rest = [n for n in mech.links[k].points if n not in drawn]
    if not drawn and rest:
        drawn.add(rest.pop(0))
    while rest:                                   # the nearest point not yet drawn, joined to the drawing
        a, b = min(((a, b) for a in rest for b in drawn),          # ties by name: the same sheet every run
                   key=lambda ab: (abs(pts[ab[0]] - pts[ab[1]]), ab))
        segs.append(Segment(f"{b}{a}", b, a, abs(pts[a] - pts[b]) * mu.value, "m", "link"))
        drawn.add(a)
        rest.remove(a)


def mechanism_plan(mech, res, scales: dict[str, Scale]) -> Plan:
    """The mechanism at the analysis's angle at mu_l: links, frame supports and guides hatched,
    pins and blocks, centres of mass, and the arcs of ω_k and ε_k of every turning link."""
    mu = scales["mu_l"]
    at = float(res.phi_deg[0])
    pts: dict[str, complex] = {}
    segs: list = []
    paths: dict[str, tuple[complex, ...]] = {}
    for k in range(1, mech.n_links):
        _link_drawing(mech, res, k, pts, segs, mu)
        _link_lines(mech, res, k, pts, segs, mu)
    segs = list({s.name: s for s in segs}.values())        # a guide drawn by both its links: once
    for p in mech.pairs:
        if p.kind == "R":
            owner = next(k for k in p.links[::-1] if k and p.point in mech.links[k].points)
            X = _world(res, owner, p.point) / mu.value
            paths[f"pin {p.point}"] = _circle(X, PIN_MM)
            if 0 in p.links:
                base = X - 5.0j
                paths[f"support {p.point}"] = (X, base - 3.0, base + 3.0, X)
                _hatch(base - 4.0, base + 4.0, -1j, f"hatch {p.point}", paths)
            continue
        d = complex(*p.direction) * complex(res.kin.rot[0, p.links[0]])
        n = 1j * d
        S = _world(res, p.links[1], p.point) / mu.value
        (l, w) = BLOCK_MM
        paths[f"block {p.point}"] = tuple(S + z for z in (l / 2 * d + w / 2 * n, -l / 2 * d + w / 2 * n,
                                                        -l / 2 * d - w / 2 * n, l / 2 * d - w / 2 * n,
                                                        l / 2 * d + w / 2 * n))
        if 0 in p.links:                         # the frame's guide: hatched on one side, along the block
            for s in (1.0, -1.0):
                a, b = S - 14.0 * d + s * (w / 2 + 0.5) * n, S + 14.0 * d + s * (w / 2 + 0.5) * n
                _hatch(a, b, s * n, f"hatch {p.point}{'+' if s > 0 else '-'}", paths)
    for k in range(1, mech.n_links):
        link = mech.links[k]
        if link.com and link.com in pts:
            paths[f"com {link.com}"] = _circle(pts[link.com], 1.6, 12)
        w, e = float(res.kin.omega[0, k]), float(res.kin.eps[0, k])
        if w == 0 and e == 0:
            continue                              # a translating link turns not
        joints = [s for s in segs if s.kind == "link" and s.start in link.points]
        c = pts[joints[0].start] if k == mech.drive.link else (
            (pts[joints[0].start] + pts[joints[0].end]) / 2 if joints else pts[next(iter(link.points))])
        if w:
            paths[f"ω{k}"] = _arc(c, ARC_MM[0], math.copysign(1.0, w))
        if e:
            paths[f"ε{k}"] = _arc(c, ARC_MM[1], math.copysign(1.0, e))
    return Plan("mechanism", f"Mechanism at phi = {at:g} deg", mu, at, pts, tuple(segs), paths)
