"""The force analysis drawn (seed 000 secs. 6-7, seed 002 sec. 1.2.3): the plan of every Assur
group with its loads, reactions and arms (`group_plans`), the force polygon of every group
(`force_plans`) and the plan of the initial link (`crank_plan`), as `Plan` data built from the
exact solution `res = kinetostat.analyze(mech, phi_deg=[at])`.

Lettering (the texts'): R<i><j> is the force of link i on link j (R12, R43, R32); a pin
reaction split along and across the link is R<i><j>n, R<i><j>t (R^n_12, R^tau_12); G<k> a
weight, F_i<k> an inertia main vector at S_k, M_i<k> an inertia main moment, F_i<k>(h) the
single inertia resultant offset by h from S_k (drawn at z = h/mu_l, seed 000 sec. 4), P<k> an
applied force on link k (P<k>a, P<k>b, ... when there are several; springs included), M<k> an
applied moment; h_<load> an arm of a moment equation, x_<i><j> the offset of a prismatic
pair's normal force from its slider point. The frame is lettered 0 as seed 000 letters it,
unless the model's `[[published]]` reactions letter it otherwise: seed 002 calls the ICE's
cylinder link 4 (R43, R41), and the ICE model publishes R43 for the pair (0, 3).

With friction in the reactions (`res.friction`), a revolute pair's reaction is drawn on its line
tangent to the pair's friction circle rho = f r (drawn at mu_l, its radius a segment rho<ij>),
a prismatic pair's reaction whole, leaning by arctg f from the normal; the force polygons close
with these reactions.

Forces on a group plan or the crank plan are drawn at a force scale of their own, stated on each
segment (`Segment.scale`); arms, links and offsets at the plan's mu_l.

May use: numpy, the solver's public results (`Analysis`, `Mechanism`), `kinetostat.applied`
(load magnitudes) and `core`. Never matplotlib, never the harness.
"""
from __future__ import annotations

import math
import string
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ..applied import applied_moment, point_forces
from .core import Plan, Result, Scale, Segment
from ..model.lettering import lettering, link_number, reaction_name
from .scales import round_scale

if TYPE_CHECKING:
    from ..analysis import Analysis
    from ..model import Mechanism
    from ..structure import AssurGroup

__all__ = ["Load", "link_loads", "link_couples", "frame_number", "reaction_name", "force_scale",
           "default_mu_F", "arm_name", "group_plans", "force_plans", "crank_plan"]


@dataclass(frozen=True)
class Load:
    """A force on a link at one angle: world point (m) and vector (N), complex x + iy."""
    name: str
    link: int
    point: complex
    force: complex
    at: str | None = None      # the named point it acts at, if it has one


@dataclass(frozen=True)
class Couple:
    """A moment on a link at one angle, N m about +z."""
    name: str
    link: int
    moment: float


# -- lettering

def frame_number(mech: "Mechanism") -> int:
    """The number the texts give the frame: 0 (seed 000) unless the model's lettering or a
    published reaction letters it otherwise (seed 002's ICE: R43 for the pair (0, 3), the frame is 4)."""
    return lettering(mech).frame


def arm_name(load: str) -> str:
    """The arm of a load as the texts letter it: h_G2, h_Fi2, h_R21."""
    return "h_" + load.replace("_", "")


def _single(res: "Analysis") -> None:
    if len(res.phi_deg) != 1:
        raise ValueError(f"plans: analyse at one crank angle, e.g. analyze(mech, phi_deg=[30]); "
                         f"got {len(res.phi_deg)} angles")
    if res.singular[0]:
        raise ValueError(f"plans: phi = {res.phi_deg[0]:g} deg is a singular position: no plan of forces there")


def _scale(mu, symbol: str, unit: str) -> Scale:
    """A Scale from a Scale or a number (SI per mm)."""
    if isinstance(mu, Scale):
        return mu
    value = float(mu)
    if not value > 0 or not math.isfinite(value):
        raise ValueError(f"{symbol}: expected a positive scale in {unit}, got {mu!r}")
    return Scale(symbol, value, unit)


def force_scale(forces, longest_mm: float = 40.0) -> Scale:
    """A round force scale (N/mm) at which the largest of `forces` (N) is drawn between half of
    `longest_mm` and `longest_mm` (`scales.round_scale`)."""
    largest = max((abs(f) for f in forces), default=0.0)
    return Scale("mu_F", round_scale(largest, longest_mm / 2, longest_mm), "N/mm")


def default_mu_F(mech: "Mechanism", res: "Analysis") -> Scale:
    """A round mu_F at which the largest force of the group polygons is drawn at most 200 mm."""
    _single(res)
    return force_scale(np.hypot(*res.forces.R[0].T), 200.0)


# -- the loads of a link

def _world(res: "Analysis", k: int, name: str) -> complex:
    return complex(res.kin.position_z(k, res.mech.links[k].points[name])[0])


def _applied(mech: "Mechanism", res: "Analysis", k: int) -> list[Load]:
    """The model's force loads and spring forces on link k at angle 0 of `res`, named as the
    model's lettering names them (F_p), else P<k> (P<k>a, P<k>b, ... when there are several)."""
    out = [Load(f.name, k, complex(f.X[0]), complex(f.force[0]), f.point)
           for f in point_forces(mech, res.kin) if f.link == k]
    L = lettering(mech)
    if len(out) == 1:
        return [Load(L.load(out[0].name, f"P{k}"), k, out[0].point, out[0].force, out[0].at)]
    return [Load(L.load(ld.name, f"P{k}{string.ascii_lowercase[n]}"), k, ld.point, ld.force, ld.at)
            for n, ld in enumerate(out)]


def link_loads(mech: "Mechanism", res: "Analysis", k: int) -> list[Load]:
    """The forces on moving link k in the texts' order: its weight G<k> and inertia main vector
    F_i<k> at the centre of mass, then the applied forces P<k> (loads, springs). Reactions not
    included (see `_carried`)."""
    link, out = mech.links[k], []
    if link.com is not None and link.mass:
        S = _world(res, k, link.com)
        out.append(Load(f"G{k}", k, S, -1j * mech.g * link.mass, link.com))
        F = complex(*res.inertia(k).force[0])
        out.append(Load(f"F_i{k}", k, S, F, link.com))
    return out + _applied(mech, res, k)


def link_couples(mech: "Mechanism", res: "Analysis", k: int) -> list[Couple]:
    """The moments on moving link k: inertia main moment M_i<k>, applied moments M<k>."""
    out = []
    if mech.links[k].I_S:
        out.append(Couple(f"M_i{k}", k, float(res.inertia(k).moment[0])))
    moments = [ld for ld in mech.loads if ld.link == k and ld.kind == "moment"]
    for n, ld in enumerate(moments):
        mag = applied_moment(mech, res.kin, ld)[0]
        suffix = string.ascii_lowercase[n] if len(moments) > 1 else ""
        out.append(Couple(f"M{k}{suffix}", k, float(mag)))
    return out


def _reaction_load(mech: "Mechanism", res: "Analysis", i: int, j: int, name: str | None = None) -> Load:
    """The force of link i on link j as a Load on j, at its pair's point (a prismatic pair's
    normal force at its offset x along the guide)."""
    p = mech.pair_between(i, j)
    slider = p.links[1]
    X = _world(res, slider, p.point)
    if p.kind == "P":
        x = res.reaction_offset(*p.links)[0]
        d = complex(*p.direction) * res.kin.rot[0, p.links[0]]
        X = X + (0.0 if math.isnan(x) else x) * d
    else:
        X = X + _friction_offset(res, p)
    return Load(name or reaction_name(mech, i, j), j, complex(X), complex(*res.reaction(i, j)[0]), p.point)


#: A friction circle drawn under this radius (mm) gets an enlarged detail beside the plan, of
#: about this radius (mm), this far (mm) right of the plan's points.
DETAIL_MIN_MM, DETAIL_RADIUS_MM, DETAIL_GAP_MM = 1.0, 8.0, 20.0


def _nice(x: float) -> float:
    """The largest of 1, 2, 5 x 10^n not above x (at least 1)."""
    e = 10.0 ** math.floor(math.log10(x)) if x >= 1 else 1.0
    return max(m * e for m in (1.0, 2.0, 5.0) if m * e <= max(x, 1.0))


def _friction_offset(res: "Analysis", p) -> complex:
    """Revolute pair p with friction in the reactions (`res.friction`): where its reaction's line
    touches the friction circle, from the pin, world m (0 without): the foot r with r x R = q,
    q the friction moment on p.links[1], R the force of links[0] on it; |r| = f r_pin = rho."""
    if res.friction is None:
        return 0j
    R, q = complex(*res.forces.R[0, p.index]), float(res.friction.load[0, p.index])
    return -q * 1j * R / abs(R) ** 2 if abs(R) > 0 else 0j


def _friction_circles(mech: "Mechanism", res: "Analysis", pairs, pts: dict, segs: list, paths: dict,
                      mu_l: Scale) -> list[str]:
    """With friction in the reactions: each revolute pair's friction circle rho = f r at its pin
    (a path at mu_l) and the radius rho<ij> from the pin to where the reaction's line touches it
    (a segment: value rho, m); each prismatic pair's friction angle. Returns the sheet's notes:
    rho in mm, and where it is drawn under 1 mm, that it is drawn at true scale (too small to read);
    the angle arctg f a guide's reaction leans by from its normal."""
    if res.friction is None:
        return []
    notes = []
    finite = [z for z in pts.values() if math.isfinite(z.real) and math.isfinite(z.imag)]
    corner = complex(max(z.real for z in finite) + DETAIL_GAP_MM, max(z.imag for z in finite))
    for p in dict.fromkeys(pairs):
        name = reaction_name(mech, *p.links)[1:]
        if p.kind == "R":
            rho = mech.friction.f * (p.radius if p.radius is not None else mech.friction.radius)
            pin = _world(res, p.links[1], p.point)
            paths[f"friction circle ρ{name}"] = _circle(pin / mu_l.value, rho / mu_l.value)
            touch = pin + _friction_offset(res, p)
            pts[f"ρ{name}:pin"], pts[f"ρ{name}:touch"] = pin / mu_l.value, touch / mu_l.value
            segs.append(Segment(f"ρ{name}", f"ρ{name}:pin", f"ρ{name}:touch", rho, "m", "arm"))
            drawn = rho / mu_l.value
            notes.append(f"friction circle ρ{name} = f r = {rho * 1e3:.4g} mm, drawn {drawn:.3g} mm: R{name} is tangent to it")
            if drawn < DETAIL_MIN_MM:                # too small to read: an enlarged detail beside the plan
                k = _nice(DETAIL_RADIUS_MM / drawn)
                corner -= 3.4j * DETAIL_RADIUS_MM
                C = corner + DETAIL_RADIUS_MM
                R = complex(*res.forces.R[0, p.index])
                u = _friction_offset(res, p)
                t = C + k * u / mu_l.value
                paths[f"detail ρ{name} x{k:g}"] = _circle(C, k * drawn)
                pts[f"ρ{name} x{k:g}:pin"], pts[f"ρ{name} x{k:g}:touch"] = C, t
                segs.append(Segment(f"ρ{name} x{k:g}", f"ρ{name} x{k:g}:pin", f"ρ{name} x{k:g}:touch", rho, "m", "arm",
                                    Scale("mu_l", mu_l.value / k, "m/mm")))
                if abs(R) > 0:
                    e = R / abs(R)
                    pts[f"R{name} x{k:g}:from"], pts[f"R{name} x{k:g}:to"] = t - 1.6 * DETAIL_RADIUS_MM * e, t + 1.6 * DETAIL_RADIUS_MM * e
                    segs.append(Segment(f"R{name} x{k:g}", f"R{name} x{k:g}:from", f"R{name} x{k:g}:to",
                                        float("nan"), "", "line"))
                notes.append(f"detail ρ{name} x{k:g}: the friction circle enlarged {k:g} times, the line of R{name} tangent to it")
        else:
            notes.append(f"friction angle φ{name} = {math.degrees(math.atan(mech.friction.f)):.4g} deg (tan φ{name} = f): "
                         f"R{name} leans from the normal to the guide")
    return notes


def _carried(mech: "Mechanism", res: "Analysis", k: int, solved: set[int]) -> list[Load]:
    """The reactions on link k from the links of groups already solved (carried back)."""
    return [_reaction_load(mech, res, m, k) for p in mech.pairs if k in p.links
            for m in [p.links[0] if p.links[1] == k else p.links[1]] if m in solved]


def _later(mech: "Mechanism", g: "AssurGroup") -> set[int]:
    groups = mech.structure.groups
    return {x for h in groups[groups.index(g) + 1:] for x in h.links}


def _group_label(g: "AssurGroup") -> str:
    return ",".join(map(str, sorted(g.links)))


# -- the reactions of a group, as the texts split them

@dataclass(frozen=True)
class _Parts:
    """One outer reaction of a group: whole, and (pin of RRR, RRP) its normal and tangential parts."""
    whole: Load
    normal: complex | None = None      # along the link, N
    tangential: complex | None = None  # across it


def _outer(mech: "Mechanism", res: "Analysis", g: "AssurGroup", side: int) -> _Parts:
    """The reaction of the known link on the group's link at outer pair `side` (0: j, 1: k)."""
    link, pair, known = g.links[side], g.pairs[2 * side], g.known[side]
    whole = _reaction_load(mech, res, known, link)
    split = (g.kind == "RRR") or (g.kind == "RRP" and side == 0)
    if not split:
        return _Parts(whole)
    u = _world(res, link, g.pairs[1].point) - _world(res, link, pair.point)
    u /= abs(u)
    n = (whole.force * u.conjugate()).real * u
    return _Parts(whole, n, whole.force - n)


def _moment_equations(g: "AssurGroup") -> list[tuple[tuple[int, ...], str]]:
    """(links, point) of each moment equation the texts write for this group kind: R^tau of a
    pin from its link about the inner joint (RRR, RRP); the slot's normal force from the whole
    group about the slotted link's pivot (RPR). PRP and RPP: offsets x only."""
    j, k = g.links
    inner, outer_k = g.pairs[1].point, g.pairs[2].point
    return {"RRR": [((j,), inner), ((k,), inner)], "RRP": [((j,), inner)],
            "RPR": [((j, k), outer_k)]}.get(g.kind, [])


def _foot(X: complex, F: complex, M: complex) -> complex:
    """Foot of the perpendicular from M on the line through X along F."""
    u = F / abs(F)
    return X + ((M - X) * u.conjugate()).real * u


def _arrow(segs: list, pts: dict, name: str, X: complex, F: complex, mu_l: Scale, mu_F: Scale) -> None:
    """A force F (N) at world point X (m), drawn at mu_F from X/mu_l."""
    start = f"{name}:from"
    pts[start] = X / mu_l.value
    pts[f"{name}:to"] = pts[start] + F / mu_F.value
    segs.append(Segment(name, start, f"{name}:to", abs(F), "N", "vector", mu_F))


def _arm(segs: list, pts: dict, name: str, M: complex, M_name: str, X: complex, F: complex, mu_l: Scale) -> None:
    """Arm of force F through X about point M (world, m), drawn at mu_l."""
    foot = _foot(X, F, M)
    pts[M_name] = M / mu_l.value
    pts[f"{name}:foot"] = foot / mu_l.value
    segs.append(Segment(name, M_name, f"{name}:foot", abs(foot - M), "m", "arm"))


def _couple_path(S: complex, moment: float, radius_mm: float) -> tuple[complex, ...]:
    """A 270-degree arc around S (mm) in the sense of the moment (ccw for positive)."""
    sense = 1.0 if moment >= 0 else -1.0
    return tuple(S + radius_mm * np.exp(1j * sense * t) for t in np.linspace(-0.75 * np.pi, 0.75 * np.pi, 19))


def _link_drawing(mech: "Mechanism", res: "Analysis", k: int, pts: dict, segs: list, mu_l: Scale) -> None:
    """Link k at mu_l: its points, and a segment between every two of its joints."""
    joints = [p.point for p in mech.pairs if k in p.links and p.point in mech.links[k].points]
    joints += [p.guide for p in mech.pairs if p.links[0] == k and p.guide in mech.links[k].points]
    names = list(dict.fromkeys(joints)) or list(mech.links[k].points)[:1]
    for name in mech.links[k].points:
        pts[name] = _world(res, k, name) / mu_l.value
    for a in range(len(names)):
        for b in range(a + 1, len(names)):
            A, B = names[a], names[b]
            segs.append(Segment(f"{A}{B}", A, B, abs(pts[B] - pts[A]) * mu_l.value, "m", "link"))
    for p in mech.pairs:
        if p.kind == "P" and k in p.links:
            X = _world(res, p.links[1], p.point) / mu_l.value
            d = complex(*p.direction) * complex(res.kin.rot[0, p.links[0]])
            name = f"guide P({link_number(mech, p.links[0])},{link_number(mech, p.links[1])})"     # the text's numbers
            pts[f"{name}:from"], pts[f"{name}:to"] = X - 40 * d, X + 40 * d
            segs.append(Segment(name, f"{name}:from", f"{name}:to", float("nan"), "", "line"))


# -- the plans

def group_plans(mech: "Mechanism", res: "Analysis", mu_l, mu_F: dict[str, Scale] | None = None) -> list[Plan]:
    """The plan of every Assur group at mu_l (seed 002 fig. 1.9, seed 000 figs. 6.1-6.3): the
    group's links, every load at its point (weights, inertia main vectors F_i at S with their
    moments M_i as arcs, and the single resultant F_i(h) at z = h/mu_l from S), the carried
    reactions, the unknown reactions (pins of RRR, RRP split into R..n along and R..t across the
    link; prismatic normal forces at their offset x, with the arm x_..), and the arms h_.. of
    the moment equations. Forces are drawn at a round force scale of their own: `mu_F[label]` (label
    "2,3" of group:2,3) where given, else chosen at this angle."""
    _single(res)
    mu_l = _scale(mu_l, "mu_l", "m/mm")
    plans = []
    for g in mech.structure.groups:
        if g.klass == 3:
            plans.append(_triad_group_plan(mech, res, g, mu_l, (mu_F or {}).get(_group_label(g))))
            continue
        j, k = g.links
        later = _later(mech, g)
        loads = {x: link_loads(mech, res, x) + _carried(mech, res, x, later) for x in (j, k)}
        outer = [_outer(mech, res, g, 0), _outer(mech, res, g, 1)]
        mu_g = (mu_F or {}).get(_group_label(g)) or force_scale([ld.force for x in (j, k) for ld in loads[x]]
                                                                + [o.whole.force for o in outer])
        pts: dict[str, complex] = {}
        segs: list[Segment] = []
        paths: dict[str, tuple[complex, ...]] = {}
        _links_and_loads(mech, res, loads, pts, segs, paths, mu_l, mu_g)
        for o in outer:
            w = o.whole
            if o.normal is None:
                _arrow(segs, pts, w.name, w.point, w.force, mu_l, mu_g)
            else:
                _arrow(segs, pts, f"{w.name}n", w.point, o.normal, mu_l, mu_g)
                _arrow(segs, pts, f"{w.name}t", w.point, o.tangential, mu_l, mu_g)
        for p, on in ((g.pairs[0], j), (g.pairs[1], j), (g.pairs[2], k)):
            if p.kind == "P":
                _offset(mech, res, p, on, pts, segs, mu_l)
        for links, M_name in _moment_equations(g):
            M = _world(res, next(x for x in links[::-1] if M_name in mech.links[x].points), M_name)
            for x in links:
                for ld in loads[x]:
                    if abs(ld.force) > 0 and abs(ld.point - M) > 1e-12 * mech.size:
                        _arm(segs, pts, arm_name(ld.name), M, M_name, ld.point, ld.force, mu_l)
        notes = _friction_circles(mech, res, g.pairs, pts, segs, paths, mu_l)
        plans.append(Plan(f"group:{_group_label(g)}", f"Group {_group_label(g)} ({g.kind}): loads and reactions"
                          + (" with friction" if res.friction is not None else "") + f"; forces drawn at {mu_g}",
                          mu_l, float(res.phi_deg[0]), pts, tuple(segs), paths, notes=notes))
    return plans


def _links_and_loads(mech: "Mechanism", res: "Analysis", loads: dict[int, list[Load]], pts: dict, segs: list,
                     paths: dict, mu_l: Scale, mu_F: Scale) -> None:
    """The links of a group (the keys of `loads`) at mu_l, their loads at mu_F, the inertia
    moments as arcs and the single inertia resultants."""
    for x in loads:
        _link_drawing(mech, res, x, pts, segs, mu_l)
    for x in loads:
        for ld in loads[x]:
            _arrow(segs, pts, ld.name, ld.point, ld.force, mu_l, mu_F)
        for c in link_couples(mech, res, x):
            link = mech.links[x]
            S = _world(res, x, link.com) if link.com else complex(res.kin.origin_z[0, x])
            paths[c.name] = _couple_path(S / mu_l.value, c.moment, 8.0)
        _resultant(mech, res, x, pts, segs, mu_l, mu_F)


def _leash_parts(mech: "Mechanism", res: "Analysis", side) -> _Parts:
    """The reaction of the known link on a triad's leash: a two-pin leash's split along its axis
    (outer pin -> inner pin) and across it; a leash on an inner prismatic pair's along its axis
    (the guide's normal) and along the guide; a slider's normal force whole."""
    ell, outer, inner, known = side
    whole = _reaction_load(mech, res, known, ell)
    if outer.kind != "R":
        return _Parts(whole)
    if inner.kind == "P":
        u = 1j * complex(*inner.direction) * complex(res.kin.rot[0, inner.links[0]])
    else:
        u = _world(res, ell, inner.point) - _world(res, ell, outer.point)
        u /= abs(u)
    n = (whole.force * u.conjugate()).real * u
    return _Parts(whole, n, whole.force - n)


def _special_point(mech: "Mechanism", res: "Analysis", g) -> tuple[str, complex]:
    """The name on the plans and the world position (m) of a triad's special point S."""
    from ..kinematics import special_point_z
    return ("S" if "S" not in mech.point_names else "S*"), complex(special_point_z(mech, res.kin, g)[0])


def _triad_group_plan(mech: "Mechanism", res: "Analysis", g, mu_l: Scale, mu_F: Scale | None = None) -> Plan:
    """A triad's plan (Artobolevsky 1988): its four links with their loads and the carried
    reactions; each leash's outer reaction (a two-pin leash's split into R..n along its axis and
    R..t across it, a leash on an inner prismatic pair's likewise, R..t along the guide; a
    slider's normal force at its offset x); the axes of the two leashes through Assur's special
    point S drawn through it; the arms of each two-pin leash's moment equation about its inner
    pin (R..t) and of the group's about S (R..n of the third leash, marked (S))."""
    later = _later(mech, g)
    loads = {x: link_loads(mech, res, x) + _carried(mech, res, x, later) for x in g.links}
    parts = [_leash_parts(mech, res, side) for side in g.sides]
    mu_F = mu_F or force_scale([ld.force for x in g.links for ld in loads[x]] + [o.whole.force for o in parts])
    pts: dict[str, complex] = {}
    segs: list[Segment] = []
    paths: dict[str, tuple[complex, ...]] = {}
    _links_and_loads(mech, res, loads, pts, segs, paths, mu_l, mu_F)
    S_name, S = _special_point(mech, res, g)
    pts[S_name] = S / mu_l.value
    for (ell, outer, inner, _), o in zip(g.sides, parts):
        w = o.whole
        if o.normal is None:
            _arrow(segs, pts, w.name, w.point, w.force, mu_l, mu_F)
            _offset(mech, res, outer, ell, pts, segs, mu_l)
        else:
            _arrow(segs, pts, f"{w.name}n", w.point, o.normal, mu_l, mu_F)
            _arrow(segs, pts, f"{w.name}t", w.point, o.tangential, mu_l, mu_F)
            X = _world(res, ell, inner.point)
            for ld in loads[ell] if inner.kind == "R" else ():
                if abs(ld.force) > 0 and abs(ld.point - X) > 1e-12 * mech.size:
                    _arm(segs, pts, arm_name(ld.name), X, inner.point, ld.point, ld.force, mu_l)
    from ..kinematics import special_sides
    for ell, outer, inner, _ in special_sides(mech, res.kin, g)[:2]:
        on = outer.point if inner.kind == "P" else inner.point        # a point of the leash's axis
        segs.append(Segment(f"axis {on}{S_name}", on, S_name, abs(_world(res, ell, on) - S), "m", "line"))
    for x in g.links:
        for ld in loads[x]:
            if abs(ld.force) > 0 and abs(ld.point - S) > 1e-12 * mech.size:
                _arm(segs, pts, f"{arm_name(ld.name)}({S_name})", S, S_name, ld.point, ld.force, mu_l)
    return Plan(f"group:{_group_label(g)}", f"Group {g.label} (III3, Assur's point {S_name}): loads and reactions; "
                f"forces drawn at {mu_F}", mu_l, float(res.phi_deg[0]), pts, tuple(segs), paths)


def _triad_polygon(mech: "Mechanism", res: "Analysis", g) -> tuple[list[tuple[str, complex]], list, list]:
    """A triad's vector equation in an order that keeps each leash's forces together, leashes 1
    and 2 those through S and 3 the third (`kinematics.special_sides`): R..t of leash 2, its
    loads, the base's loads, R..n and R..t of leash 3 (R..n known from the group's moment about
    S), its loads, leash 1's loads, its R..t, and the unknowns R..n of leashes 1 and 2 closing
    the polygon. Also, per leash, the indices of its first and last forces (its inner
    reaction closes its own polygon from the one to the other) and of its two reaction parts."""
    from ..kinematics import special_sides
    later = _later(mech, g)
    sides = special_sides(mech, res.kin, g)
    parts = [_leash_parts(mech, res, side) for side in sides]
    loads = lambda x: [(ld.name, ld.force) for ld in link_loads(mech, res, x) + _carried(mech, res, x, later)]
    t = lambda o: [] if o.normal is None else [(f"{o.whole.name}t", o.tangential)]
    n = lambda o: [(o.whole.name, o.whole.force)] if o.normal is None else [(f"{o.whole.name}n", o.normal)]
    (l1, l2, l3), (o1, o2, o3) = [s[0] for s in sides], parts
    blocks = [t(o2) + loads(l2), loads(g.links[0]), n(o3) + t(o3) + loads(l3), loads(l1) + t(o1) + n(o1), n(o2)]
    seq = [f for b in blocks for f in b]
    at = [0]
    for b in blocks:
        at.append(at[-1] + len(b))
    # leash -> (first, one past its last) in the cyclic order: leash 2 wraps round
    spans = [(at[3], at[4]), (at[4], at[5] + len(t(o2) + loads(l2))), (at[2], at[3])]
    whole = [(at[4] - len(t(o1) + n(o1)), at[4]) if o1.normal is not None else None,
             (at[4], at[5] + len(t(o2))) if o2.normal is not None else None,
             (at[2], at[2] + 2) if o3.normal is not None else None]
    return seq, spans, whole


def _resultant(mech: "Mechanism", res: "Analysis", k: int, pts: dict, segs: list, mu_l: Scale, mu_F: Scale) -> None:
    """The single inertia resultant F_i<k>(h) of a link with both a main vector and a main
    moment, at z = h/mu_l from S on the side whose moment opposes eps (seed 000 sec. 4), and z."""
    link = mech.links[k]
    il = res.inertia(k)
    F, M = complex(*il.force[0]), il.moment[0]
    if link.com is None or F == 0 or M == 0 or not link.mass:
        return
    S, K = _world(res, k, link.com), complex(*il.point[0])
    _arrow(segs, pts, f"F_i{k}(h)", K, F, mu_l, mu_F)
    pts[f"z_{k}:S"] = S / mu_l.value
    segs.append(Segment(f"z_{k}", f"z_{k}:S", f"F_i{k}(h):from", float(il.h[0]), "m", "arm"))


def _offset(mech: "Mechanism", res: "Analysis", p, on: int, pts: dict, segs: list, mu_l: Scale) -> None:
    """The offset x of prismatic pair p's normal force from its slider point, along the guide."""
    x = res.reaction_offset(*p.links)[0]
    if math.isnan(x):
        return
    X = _world(res, p.links[1], p.point)
    d = complex(*p.direction) * complex(res.kin.rot[0, p.links[0]])
    name = "x_" + reaction_name(mech, *p.links)[1:]
    pts[f"{name}:from"], pts[f"{name}:to"] = X / mu_l.value, (X + x * d) / mu_l.value
    segs.append(Segment(name, f"{name}:from", f"{name}:to", abs(x), "m", "arm"))


def _polygon(mech: "Mechanism", res: "Analysis", g: "AssurGroup") -> tuple[list[tuple[str, complex]], int, int]:
    """The group's vector equation in the texts' order, as (name, force N): the known part of
    j's outer reaction (R..t) or the whole of it, j's loads, k's loads, then k's outer reaction
    (R..t known, R..n unknown; or the normal force) and j's R..n closing it. Also the index of
    the last of j's loads (the internal reaction closes j's polygon there) and the index at
    which j's whole outer reaction starts (the vertex after the closing side; 0 if unsplit)."""
    j, k = g.links
    later = _later(mech, g)
    oj, ok = _outer(mech, res, g, 0), _outer(mech, res, g, 1)
    seq: list[tuple[str, complex]] = []
    if oj.normal is None:
        seq.append((oj.whole.name, oj.whole.force))
    else:
        seq.append((f"{oj.whole.name}t", oj.tangential))
    seq += [(ld.name, ld.force) for ld in link_loads(mech, res, j) + _carried(mech, res, j, later)]
    end_j = len(seq)
    seq += [(ld.name, ld.force) for ld in link_loads(mech, res, k) + _carried(mech, res, k, later)]
    if ok.normal is None:
        seq.append((ok.whole.name, ok.whole.force))
    else:
        seq += [(f"{ok.whole.name}t", ok.tangential), (f"{ok.whole.name}n", ok.normal)]
    if oj.normal is not None:
        seq.append((f"{oj.whole.name}n", oj.normal))
    return seq, end_j, 0 if oj.normal is None else len(seq) - 1


def _vertex(n: int) -> str:
    return string.ascii_lowercase[n] if n < 26 else f"v{n}"


def force_plans(mech: "Mechanism", res: "Analysis", mu_F) -> list[Plan]:
    """The force plan of every Assur group at mu_F (seed 002 fig. 1.10, seed 000 sec. 6): the
    polygon of the group's vector equation in the texts' order, vertices lettered a, b, c, ...
    from the start of the first known force, closed by the unknowns; the whole outer reactions
    (R12 = R12n + R12t, ...) as chords; and the internal reaction (R32: of link k on link j) from
    the polygon of link j, the chord from the end of j's loads to the start of j's outer
    reaction. Each segment's value is the force's magnitude, N."""
    _single(res)
    mu_F = _scale(mu_F, "mu_F", "N/mm")
    plans = []
    for g in mech.structure.groups:
        if g.klass == 3:
            plans.append(_triad_force_plan(mech, res, g, mu_F))
            continue
        j, k = g.links
        seq, end_j, start_j = _polygon(mech, res, g)
        pts, segs = _closed_polygon(seq, mu_F)
        oj, ok = _outer(mech, res, g, 0), _outer(mech, res, g, 1)
        X = _vertex(start_j)
        if oj.normal is not None:     # whole pin reactions as chords: R = R^n + R^tau
            segs.append(Segment(oj.whole.name, X, _vertex(1), abs(oj.whole.force), "N"))
        if ok.normal is not None:
            first = len(seq) - 3
            segs.append(Segment(ok.whole.name, _vertex(first), _vertex(first + 2), abs(ok.whole.force), "N"))
        internal = complex(*res.reaction(k, j)[0])
        segs.append(Segment(reaction_name(mech, k, j), _vertex(end_j), X, abs(internal), "N"))
        plans.append(Plan(f"forces:{_group_label(g)}", f"Force plan of group {_group_label(g)} ({g.kind}): "
                          + " + ".join(name for name, _ in seq) + " = 0", mu_F, float(res.phi_deg[0]),
                          pts, tuple(segs), equation=tuple(name for name, _ in seq),
                          notes=("the reactions with friction in the reactions",) if res.friction is not None else ()))
    return plans


def _closed_polygon(seq: list[tuple[str, complex]], mu_F: Scale) -> tuple[dict, list]:
    """The polygon of `seq` at mu_F: vertices a, b, c, ... from the start of the first force,
    the last force ending at the first vertex."""
    pts = {_vertex(0): 0j}
    segs = []
    for n, (name, F) in enumerate(seq):
        a, b = _vertex(n), _vertex((n + 1) % len(seq))
        if b not in pts:
            pts[b] = pts[a] + F / mu_F.value
        segs.append(Segment(name, a, b, abs(F), "N"))
    return pts, segs


def _triad_force_plan(mech: "Mechanism", res: "Analysis", g, mu_F: Scale) -> Plan:
    """A triad's force plan: its polygon (`_triad_polygon`) closed by R..n of the leashes through S,
    the whole reaction of each two-pin leash as a chord over its two parts, and each leash's
    inner reaction (of the base on it) from its own polygon: the chord from the end of its
    forces back to their start."""
    from ..kinematics import special_sides
    seq, spans, whole = _triad_polygon(mech, res, g)
    pts, segs = _closed_polygon(seq, mu_F)
    m = len(seq)
    sides = special_sides(mech, res.kin, g)
    for (ell, _, _, known), w in zip(sides, whole):
        if w is not None:
            segs.append(Segment(reaction_name(mech, known, ell), _vertex(w[0] % m), _vertex(w[1] % m),
                                float(np.hypot(*res.reaction(known, ell)[0])), "N"))
    for (ell, _, _, _), (a, b) in zip(sides, spans):
        segs.append(Segment(reaction_name(mech, g.links[0], ell), _vertex(b % m), _vertex(a % m),
                            float(np.hypot(*res.reaction(g.links[0], ell)[0])), "N"))
    return Plan(f"forces:{_group_label(g)}", f"Force plan of group {g.label} (III3): "
                + " + ".join(name for name, _ in seq) + " = 0", mu_F, float(res.phi_deg[0]),
                pts, tuple(segs), equation=tuple(name for name, _ in seq))


#: The longest force on the plan of the initial link when it takes a force scale of its own, mm.
CRANK_FORCE_MM = 80.0


def crank_plan(mech: "Mechanism", res: "Analysis", mu_l, mu_F=None) -> Plan:
    """The initial link at mu_l with its loads drawn at mu_F (seed 002 fig. 1.11, seed 000
    sec. 7): the reactions of the groups on it (R21 at A, ...), its own weight and inertia, the
    frame's reaction at the pivot (R01; R41 for seed 002's ICE), the arms h_.. of its moment
    equation about the pivot, and the balancing load: an engine's couple M_bal (an arc, its
    value M_bal = sum of the arms' moments); a working machine's gear mesh (pitch circles of
    wheel and pinion, pitch point P, line of action at alpha_w, F_bal at P and its arm r_b).
    mu_F None: a round force scale of its own, the largest reaction at most CRANK_FORCE_MM."""
    _single(res)
    mu_l = _scale(mu_l, "mu_l", "m/mm")
    if mu_F is None:
        mu_F = force_scale(np.hypot(*res.forces.R[0].T), CRANK_FORCE_MM)
    mu_F = _scale(mu_F, "mu_F", "N/mm")
    dr, L = mech.drive, lettering(mech)
    pts: dict[str, complex] = {}
    segs: list[Segment] = []
    paths: dict[str, tuple[complex, ...]] = {}
    _link_drawing(mech, res, 1, pts, segs, mu_l)
    O = _world(res, 1, dr.pivot)
    on_crank = _carried(mech, res, 1, set(range(2, mech.n_links))) + link_loads(mech, res, 1)
    for ld in on_crank:
        _arrow(segs, pts, ld.name, ld.point, ld.force, mu_l, mu_F)
    for ld in on_crank:
        if abs(ld.force) > 0 and abs(ld.point - O) > 1e-12 * mech.size:
            _arm(segs, pts, arm_name(ld.name), O, dr.pivot, ld.point, ld.force, mu_l)
    for c in link_couples(mech, res, 1):
        paths[c.name] = _couple_path(O / mu_l.value, c.moment, 6.0)
    R01 = _reaction_load(mech, res, 0, 1)
    _arrow(segs, pts, R01.name, R01.point, R01.force, mu_l, mu_F)
    M_bal = float(res.balancing_moment[0])
    if dr.kind == "machine":
        gear = dr.gear
        e = complex(*gear.centre_direction)
        r_pinion = gear.r_w * gear.z_pinion / gear.z_wheel
        P = O + gear.r_w * e
        paths["pitch circle of the wheel"] = _circle(O / mu_l.value, gear.r_w / mu_l.value)
        paths["pitch circle of the pinion"] = _circle((O + (gear.r_w + r_pinion) * e) / mu_l.value, r_pinion / mu_l.value)
        F_bal = complex(*res.balancing_force[0])
        line = F_bal / abs(F_bal) if abs(F_bal) > 0 else _line_of_action(gear, M_bal)
        pts["P"] = P / mu_l.value
        pts["line of action:from"], pts["line of action:to"] = pts["P"] - 40 * line, pts["P"] + 40 * line
        segs.append(Segment("line of action", "line of action:from", "line of action:to", float("nan"), "", "line"))
        _arrow(segs, pts, L.F_bal, P, F_bal, mu_l, mu_F)
        foot = _foot(P, line, O)
        pts["r_b:foot"] = foot / mu_l.value
        segs.append(Segment("r_b", dr.pivot, "r_b:foot", abs(foot - O), "m", "arm"))
        title = (f"Initial link: gear mesh alpha_w = {gear.alpha_w_deg:g} deg, {L.F_bal} = {abs(F_bal):.6g} N, "
                 f"r_b = {gear.r_b * 1e3:.6g} mm, {L.M_bal} = {L.F_bal} r_b = {M_bal:.6g} N m")
        results = (Result(L.F_bal, abs(F_bal), "N"), Result("r_b", gear.r_b, "m"),
                   Result(L.M_bal, M_bal, "N m", "M = F r_b"))
    else:
        paths[L.M_bal] = _couple_path(O / mu_l.value, M_bal, 10.0)
        title = f"Initial link: balancing couple {L.M_bal} = {M_bal:.6g} N m"
        results = (Result(L.M_bal, M_bal, "N m", "M = sum"),)
    notes = _friction_circles(mech, res, [p for p in mech.pairs if dr.link in p.links], pts, segs, paths, mu_l)
    return Plan("crank", f"{title}; forces drawn at {mu_F}", mu_l, float(res.phi_deg[0]), pts, tuple(segs), paths,
                notes=notes, results=results)


def _line_of_action(gear, M: float) -> complex:
    e, alpha = complex(*gear.centre_direction), math.radians(gear.alpha_w_deg)
    return (1.0 if M >= 0 else -1.0) * math.cos(alpha) * 1j * e - math.sin(alpha) * e


def _circle(C: complex, r: float) -> tuple[complex, ...]:
    return tuple(C + r * np.exp(1j * t) for t in np.linspace(0.0, 2 * np.pi, 73))
