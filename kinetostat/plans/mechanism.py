"""The mechanism at its design position, drawn as seed 002 fig. 1.6 draws it: the links to scale
(mu_l), the frame hatched under its pins and along its guides, the pairs drawn as pairs (a pin
as a small circle, a slider as a block on its guide), the centres of mass, and the senses of
every link's angular velocity ω and acceleration ε as arcs with an arrowhead, about the link,
each turned so that its arrowhead falls clear of the links (`arcs`); a zero ω or ε not drawn,
and named in a note.

Built at every angle of an analysis at once (`PlanCycle`: points (N,), marks (N, K)).
The drawing's marks are `PlanCycle.paths` (sheet mm) named by what they are: "pin A", "block B",
"support O", "hatch ..", "com S2", and "ω2", "ε2" for the senses; `draw` draws each by its name.

May use: numpy, `core`, `arcs` (the senses' arcs), `forces` (the links drawn at mu_l), `kinematic` (which angles draw), `zero`
(which ω, ε are zero).
Never matplotlib.
"""
from __future__ import annotations


import numpy as np

from .arcs import arc, heavy_lines
from .core import PlanCycle, Scale, Segment
from .forces import _link_drawing, _world
from .kinematic import _ok, _titles
from .zero import translates, zero_eps, zero_notes, zero_omega

__all__ = ["mechanism_plan", "PIN_MM", "BLOCK_MM", "ARC_MM"]

#: Radius of a pin, mm; a slider block (length, width), mm; radii of the ω and ε arcs, mm.
PIN_MM, BLOCK_MM, ARC_MM = 1.2, (10.0, 6.0), (7.0, 10.0)


def _circle(c: np.ndarray, r: float, n: int = 16) -> np.ndarray:
    """(N, n + 1) complex: a circle of radius r around each centre c (N,)."""
    return c[:, None] + r * np.exp(2j * np.pi * np.arange(n + 1) / n)


def _hatch(a: np.ndarray, b: np.ndarray, side, name: str, paths: dict) -> None:
    """The frame's hatching: the line a-b (each (N,)) and short strokes every 2 mm on its `side`
    (a unit, or (N,) units), as many at every angle as the stretch's length at the first."""
    paths[f"{name}"] = np.stack([a, b], axis=1)
    L = np.abs(b - a)
    u = np.where(L != 0, (b - a) / np.where(L != 0, L, 1.0), 1.0)
    for n, t in enumerate(np.arange(1.0, min(float(L[0]), 100.0), 2.0)):      # a frame's stretch: at most 50 strokes
        p = a + t * u
        paths[f"{name} {n}"] = np.stack([p, p + 2.0 * side - 1.5 * u], axis=1)


def _link_lines(mech, res, k: int, pts: dict, segs: list, mu: Scale) -> None:
    """Link k drawn through all its points: along each slot it carries, from end to end of what
    runs in it (O2-S3 on to B), and every point not on a drawn line joined to the nearest drawn
    point on the sheet (B-S5-T of a ram; distances within 1e-9 of each other tie, broken by
    name: a point midway between two pins joins the first by name at every angle), angle by
    angle: a join made at some angles only is NaN, not drawn, at the others."""
    n_at = len(res.phi_deg)
    names = list(mech.links[k].points)
    on_line = {n for s in segs if s.kind == "link" for n in (s.start, s.end)}
    drawn = {n: np.full(n_at, n in on_line) for n in names}
    for p in mech.pairs:
        if p.kind != "P" or p.links[0] != k or p.guide not in mech.links[k].points:
            continue
        G = pts[p.guide]
        d = complex(*p.direction) * res.kin.rot[:, k]
        on = {n: ((pts[n] - G) * d.conjugate()).real for n in names}
        on[p.point] = ((_world(res, p.links[1], p.point) / mu.value - G) * d.conjugate()).real
        along = np.stack(list(on.values()))
        lo, hi = along.min(axis=0), along.max(axis=0)
        name = f"slot {k} {p.point}"
        pts[f"{name}:from"], pts[f"{name}:to"] = G + lo * d, G + hi * d
        segs.append(Segment(name, f"{name}:from", f"{name}:to", (hi - lo) * mu.value, "m", "link"))
        for n in names:
            drawn[n] = drawn[n] | (np.abs(((pts[n] - G) * d.conjugate()).imag) < 1e-6)
    done = np.stack([drawn[n] for n in names], axis=1)                 # (N, points)
    if not names:
        return
    first = ~done.any(axis=1)                   # nothing drawn yet: the first point is
    done[first, 0] = True
    pairs = sorted(((a, b) for a in range(len(names)) for b in range(len(names)) if a != b),
                   key=lambda ab: (names[ab[0]], names[ab[1]]))           # ties by name
    A, B = np.array([a for a, _ in pairs], int), np.array([b for _, b in pairs], int)
    z = np.stack([pts[n] for n in names], axis=1)
    dist = np.abs(z[:, A] - z[:, B])                                    # (N, pairs)
    joins: dict[tuple[int, int], np.ndarray] = {}
    while not done.all():                       # the nearest point not yet drawn, joined to the drawing
        free = ~done[:, A] & done[:, B]
        key = np.where(free, dist, np.inf)
        near = free & (key <= key.min(axis=1, keepdims=True) * (1 + 1e-9))      # ties to rounding: by name
        best = np.where(free.any(axis=1), np.argmax(near, axis=1), -1)
        for j in np.unique(best[best >= 0]):
            at = best == j
            joins[pairs[j]] = joins.get(pairs[j], np.zeros(n_at, bool)) | at
            done[at, A[j]] = True
    for (a, b), at in joins.items():
        na, nb = names[a], names[b]
        segs.append(Segment(f"{nb}{na}", nb, na, np.where(at, np.abs(pts[na] - pts[nb]) * mu.value, np.nan), "m", "link"))


def mechanism_plan(mech, res, scales: dict[str, Scale]) -> PlanCycle:
    """The mechanism at every angle of `res` at mu_l: links, frame supports and guides hatched,
    pins and blocks, centres of mass, and the arcs of ω_k and ε_k of every link that does not
    translate, about the link (`_arc_centre`); an arc not drawn (NaN) at an angle where its
    quantity is zero (`zero`), and a note there says so."""
    mu = scales["mu_l"]
    pts: dict[str, np.ndarray] = {}
    segs: list = []
    paths: dict[str, np.ndarray] = {}
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
                paths[f"support {p.point}"] = np.stack([X, base - 3.0, base + 3.0, X], axis=1)
                _hatch(base - 4.0, base + 4.0, -1j, f"hatch {p.point}", paths)
            continue
        d = complex(*p.direction) * res.kin.rot[:, p.links[0]]
        n = 1j * d
        S = _world(res, p.links[1], p.point) / mu.value
        (l, w) = BLOCK_MM
        paths[f"block {p.point}"] = np.stack([S + z for z in (l / 2 * d + w / 2 * n, -l / 2 * d + w / 2 * n,
                                                              -l / 2 * d - w / 2 * n, l / 2 * d - w / 2 * n,
                                                              l / 2 * d + w / 2 * n)], axis=1)
        if 0 in p.links:                         # the frame's guide: hatched on one side, along the block
            for s in (1.0, -1.0):
                a, b = S - 14.0 * d + s * (w / 2 + 0.5) * n, S + 14.0 * d + s * (w / 2 + 0.5) * n
                _hatch(a, b, s * n, f"hatch {p.point}{'+' if s > 0 else '-'}", paths)
    zeros: dict[str, tuple[np.ndarray, str]] = {}
    lines = heavy_lines(pts, segs)
    for k in range(1, mech.n_links):
        link = mech.links[k]
        if link.com and link.com in pts:
            paths[f"com {link.com}"] = _circle(pts[link.com], 1.6, 12)
        if translates(mech, k):
            continue                              # a translating link turns not: no arcs, nothing to note
        turns = {f"ω{k}": (res.kin.omega[:, k], zero_omega(mech, res, k), ARC_MM[0]),
                 f"ε{k}": (res.kin.eps[:, k], zero_eps(mech, res, k), ARC_MM[1])}
        c = _arc_centre(mech, k, pts)
        for name, (v, zero, r) in turns.items():
            zeros[name] = (zero & _ok(res), "")
            if (~zero & _ok(res)).any():       # 240 deg from the upper left, its arrowhead clear of the links
                paths[name] = np.where(zero[:, None], np.nan, arc(c, r, np.sign(v), 150.0, 240.0, lines))
    return PlanCycle("mechanism", _titles("Mechanism at phi = {at:g} deg", res), mu, res.phi_deg, pts, tuple(segs), paths,
                     tuple(zero_notes(zeros, len(res.phi_deg))))


def _arc_centre(mech, k: int, pts: dict) -> np.ndarray:
    """(N,) sheet mm: where link k's ω and ε arcs are drawn, about the link itself: the crank's
    about its pivot, another link's midway between its first two joints (its only joint, or its
    first point, where it has fewer)."""
    if k == mech.drive.link:
        return pts[mech.drive.pivot]
    link = mech.links[k]
    joints = list(dict.fromkeys(p.point for p in mech.pairs if k in p.links and p.point in link.points))
    if len(joints) >= 2:
        return (pts[joints[0]] + pts[joints[1]]) / 2
    return pts[joints[0] if joints else next(iter(link.points))]
    return PlanCycle("mechanism", _titles("Mechanism at phi = {at:g} deg", res), mu, res.phi_deg, pts, tuple(segs), paths)
