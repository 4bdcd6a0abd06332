"""The force analysis drawn (seed 000 secs. 6-7, seed 002 sec. 1.2.3): the plan of every Assur
group with its loads, reactions and arms (`group_plans`), the force polygon of every group
(`force_plans`) and the plan of the initial link (`crank_plan`), each a `PlanCycle` built at
once for the N angles of the exact solution `res = kinetostat.analyze(mech, phi_deg=angles)`:
every point, value and path an array over the angles, no loop over them. An element is drawn
where it exists at any of the angles; at an angle where it does not (a load of zero, an arm
through its own pole), its points and value are NaN there (`PlanCycle.at` leaves it out). A
triad whose leash closing it about S changes with the angle (`kinematics.special_index`) has
each order's polygon, axes and construction, each at the angles of that order.

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

Only what acts is drawn: an inertia force or couple zero at an angle (`zero`: M_i of a link that
translates is none at all) is NaN there, and the plan's note of that angle names it; F_i<k>(h),
which replaces F_i<k> and M_i<k>, is drawn as their alternative (kind "alternative", dashed) with a
note; a prismatic pair's normal force whose offset x falls outside its slider link is drawn where
it acts, the link's line drawn on to it (kind "extension"), with a note and a ModelWarning.

May use: numpy, the solver's public results (`Analysis`, `Mechanism`), `kinetostat.applied`
(load magnitudes), `kinetostat.errors` (the warning), `core`, `zero` and `arcs` (a couple's arc,
turned so that its arrowhead falls clear of the plan's links and vectors). Never matplotlib, never
the harness.
"""
from __future__ import annotations

import math
import string
import warnings
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import numpy as np

from ..applied import applied_moment, point_forces
from .arcs import arc, heavy_lines
from .core import PlanCycle, Result, Scale, Segment, alias, construction
from ..model.lettering import lettering, link_number, reaction_name
from .scales import round_scale
from ..errors import ModelWarning, _angle_list
from .zero import ZERO_REL, translates, zero_eps, zero_inertia_force, zero_notes, zero_of

if TYPE_CHECKING:
    from ..analysis import Analysis
    from ..model import Mechanism
    from ..structure import AssurGroup

__all__ = ["Load", "link_loads", "link_couples", "frame_number", "reaction_name", "force_scale",
           "default_mu_F", "arm_name", "group_plans", "force_plans", "crank_plan"]


@dataclass(frozen=True)
class Load:
    """A force on a link at the N angles of an analysis: world point (m) and vector (N), each
    (N,) complex x + iy."""
    name: str
    link: int
    point: np.ndarray
    force: np.ndarray
    at: str | None = None      # the named point it acts at, if it has one


@dataclass(frozen=True)
class Couple:
    """A moment on a link at the N angles of an analysis, N m about +z, (N,)."""
    name: str
    link: int
    moment: np.ndarray


# -- lettering

def frame_number(mech: "Mechanism") -> int:
    """The number the texts give the frame: 0 (seed 000) unless the model's lettering or a
    published reaction letters it otherwise (seed 002's ICE: R43 for the pair (0, 3), the frame is 4)."""
    return lettering(mech).frame


def arm_name(load: str) -> str:
    """The arm of a load as the texts letter it: h_G2, h_Fi2, h_R21."""
    return "h_" + load.replace("_", "")


def _drawable(res: "Analysis") -> None:
    """ValueError where no angle of `res` has a plan of forces: every one singular."""
    if np.all(res.singular):
        at = ", ".join(f"{x:g}" for x in res.phi_deg[:5]) + (", ..." if len(res.phi_deg) > 5 else "")
        raise ValueError(f"plans: phi = {at} deg is a singular position: no plan of forces there")


def _scale(mu, symbol: str, unit: str) -> Scale:
    """A Scale from a Scale or a number (SI per mm)."""
    if isinstance(mu, Scale):
        return mu
    value = float(mu)
    if not value > 0 or not math.isfinite(value):
        raise ValueError(f"{symbol}: expected a positive scale in {unit}, got {mu!r}")
    return Scale(symbol, value, unit)


def force_scale(forces, longest_mm: float = 40.0) -> Scale:
    """A round force scale (N/mm) at which the largest of `forces` (N; scalars or arrays over the
    angles, NaN left out) is drawn between half of `longest_mm` and `longest_mm` (`scales.round_scale`)."""
    sizes = [_abs(f).reshape(-1) for f in forces]
    every = np.concatenate(sizes) if sizes else np.zeros(0)
    largest = float(np.nanmax(every)) if np.isfinite(every).any() else 0.0
    return Scale("mu_F", round_scale(largest, longest_mm / 2, longest_mm), "N/mm")


def _all_reactions(res: "Analysis") -> np.ndarray:
    """|R| of every pair at every angle, N."""
    return np.hypot(res.forces.R[..., 0], res.forces.R[..., 1])


def default_mu_F(mech: "Mechanism", res: "Analysis") -> Scale:
    """A round mu_F at which the largest force of the group polygons over the angles of `res` is
    drawn at most 200 mm."""
    _drawable(res)
    return force_scale([_all_reactions(res)], 200.0)


# -- the loads of a link

def _world(res: "Analysis", k: int, name: str) -> np.ndarray:
    """(N,) complex: point `name` of link k in the world, m."""
    return np.asarray(res.kin.position_z(k, res.mech.links[k].points[name]), dtype=complex)


def _z(xy: np.ndarray) -> np.ndarray:
    """(N, 2) -> (N,) complex."""
    return xy[..., 0] + 1j * xy[..., 1]


def _applied(mech: "Mechanism", res: "Analysis", k: int) -> list[Load]:
    """The model's force loads and spring forces on link k at the angles of `res`, named as the
    model's lettering names them (F_p), else P<k> (P<k>a, P<k>b, ... when there are several)."""
    out = [Load(f.name, k, np.asarray(f.X, dtype=complex), np.asarray(f.force, dtype=complex), f.point)
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
        out.append(Load(f"G{k}", k, S, np.full(len(S), -1j * mech.g * link.mass), link.com))
        out.append(Load(f"F_i{k}", k, S, _z(res.inertia(k).force), link.com))
    return out + _applied(mech, res, k)


def link_couples(mech: "Mechanism", res: "Analysis", k: int) -> list[Couple]:
    """The moments on moving link k: inertia main moment M_i<k> (none on a link that translates,
    `zero.translates`), applied moments M<k>."""
    out = []
    if mech.links[k].I_S and not translates(mech, k):
        out.append(Couple(f"M_i{k}", k, np.asarray(res.inertia(k).moment, dtype=float)))
    moments = [ld for ld in mech.loads if ld.link == k and ld.kind == "moment"]
    for n, ld in enumerate(moments):
        suffix = string.ascii_lowercase[n] if len(moments) > 1 else ""
        out.append(Couple(f"M{k}{suffix}", k, np.asarray(applied_moment(mech, res.kin, ld), dtype=float)))
    return out


def _guide(res: "Analysis", p) -> np.ndarray:
    """(N,) complex: the unit direction of prismatic pair p's guide in the world."""
    return _mul(complex(*p.direction), res.kin.rot[:, p.links[0]])


def _reaction_load(mech: "Mechanism", res: "Analysis", i: int, j: int, name: str | None = None) -> Load:
    """The force of link i on link j as a Load on j, at its pair's point (a prismatic pair's
    normal force at its offset x along the guide, at the slider point where x is undefined)."""
    p = mech.pair_between(i, j)
    X = _world(res, p.links[1], p.point)
    if p.kind == "P":
        x = res.reaction_offset(*p.links)
        X = X + np.where(np.isnan(x), 0.0, x) * _guide(res, p)
    else:
        X = X + _friction_offset(res, p)
    return Load(name or reaction_name(mech, i, j), j, X, _z(res.reaction(i, j)), p.point)


#: A friction circle drawn under this radius (mm) gets an enlarged detail beside the plan, of
#: about this radius (mm), this far (mm) right of the plan's points.
DETAIL_MIN_MM, DETAIL_RADIUS_MM, DETAIL_GAP_MM = 1.0, 8.0, 20.0


def _nice(x: float) -> float:
    """The largest of 1, 2, 5 x 10^n not above x (at least 1)."""
    e = 10.0 ** math.floor(math.log10(x)) if x >= 1 else 1.0
    return max(m * e for m in (1.0, 2.0, 5.0) if m * e <= max(x, 1.0))


def _abs(z) -> np.ndarray:
    """|z| as Python's abs of a complex rounds it (hypot; numpy's abs of a complex differs in the last bit)."""
    z = np.asarray(z)
    return np.hypot(z.real, z.imag)


def _mul(a, b) -> np.ndarray:
    """a b for complex a, b, rounded as Python's complex product (numpy's may fuse a multiply-add)."""
    a, b = np.asarray(a, dtype=complex), np.asarray(b, dtype=complex)
    out = np.empty(np.broadcast(a, b).shape, dtype=complex)
    out.real, out.imag = a.real * b.real - a.imag * b.imag, a.real * b.imag + a.imag * b.real
    return out


def _dot(a, b) -> np.ndarray:
    """Re(a conj(b)): the dot product of complex a, b as 2-vectors."""
    a, b = np.asarray(a, dtype=complex), np.asarray(b, dtype=complex)
    return a.real * b.real + a.imag * b.imag


def _over(z, s) -> np.ndarray:
    """z / s for complex z and real s, each part divided as Python's complex / float divides it
    (numpy's complex division multiplies by 1/s: the last bit differs)."""
    z, s = np.asarray(z, dtype=complex), np.asarray(s, dtype=float)
    out = np.empty(np.broadcast(z, s).shape, dtype=complex)
    out.real, out.imag = z.real / s, z.imag / s
    return out


def _unit(F: np.ndarray) -> np.ndarray:
    """F / |F| (N,), NaN where F = 0."""
    a = _abs(F)
    return np.where(a > 0, _over(F, np.where(a > 0, a, 1.0)), np.nan)


def _friction_offset(res: "Analysis", p) -> np.ndarray:
    """Revolute pair p with friction in the reactions (`res.friction`): where its reaction's line
    touches the friction circle, from the pin, world m (0 without, and where R = 0), (N,): the
    foot r with r x R = q, q the friction moment on p.links[1], R the force of links[0] on it;
    |r| = f r_pin = rho."""
    if res.friction is None:
        return np.zeros(len(res.phi_deg), dtype=complex)
    R, q = _z(res.forces.R[:, p.index]), res.friction.load[:, p.index]
    a2 = _abs(R) ** 2
    return np.where(a2 > 0, _over(-q * 1j * R, np.where(a2 > 0, a2, 1.0)), 0j)


def _finite_corner(pts: dict, n: int) -> np.ndarray:
    """(N,) complex: the largest x and the largest y of the plan's finite points at each angle, mm."""
    if not pts:
        return np.full(n, np.nan + 0j)
    z = np.stack(list(pts.values()))
    ok = np.isfinite(z.real) & np.isfinite(z.imag)
    with np.errstate(invalid="ignore"):
        x = np.where(ok, z.real, -np.inf).max(axis=0)
        y = np.where(ok, z.imag, -np.inf).max(axis=0)
    return np.where(ok.any(axis=0), x + 1j * y, np.nan)


def _friction_circles(mech: "Mechanism", res: "Analysis", pairs, pts: dict, segs: list, paths: dict,
                      mu_l: Scale) -> list[str]:
    """With friction in the reactions: each revolute pair's friction circle rho = f r at its pin
    (a path at mu_l) and the radius rho<ij> from the pin to where the reaction's line touches it
    (a segment: value rho, m); each prismatic pair's friction angle. Returns the sheet's notes
    (the same at every angle): rho in mm, and where it is drawn under 1 mm, that it is drawn at
    true scale (too small to read); the angle arctg f a guide's reaction leans by from its normal."""
    if res.friction is None:
        return []
    n = len(res.phi_deg)
    notes = []
    corner = _finite_corner(pts, n) + DETAIL_GAP_MM
    for p in dict.fromkeys(pairs):
        name = reaction_name(mech, *p.links)[1:]
        if p.kind == "R":
            rho = mech.friction.f * (p.radius if p.radius is not None else mech.friction.radius)
            pin = _world(res, p.links[1], p.point)
            paths[f"friction circle ρ{name}"] = _circle(_over(pin, mu_l.value), rho / mu_l.value)
            u = _friction_offset(res, p)
            pts[f"ρ{name}:pin"], pts[f"ρ{name}:touch"] = _over(pin, mu_l.value), _over(pin + u, mu_l.value)
            segs.append(Segment(f"ρ{name}", f"ρ{name}:pin", f"ρ{name}:touch", np.full(n, rho), "m", "arm"))
            drawn = rho / mu_l.value
            notes.append(f"friction circle ρ{name} = f r = {rho * 1e3:.4g} mm, drawn {drawn:.3g} mm: R{name} is tangent to it")
            if drawn < DETAIL_MIN_MM:                # too small to read: an enlarged detail beside the plan
                k = _nice(DETAIL_RADIUS_MM / drawn)
                corner = corner - 3.4j * DETAIL_RADIUS_MM
                C = corner + DETAIL_RADIUS_MM
                t = C + _over(k * u, mu_l.value)
                paths[f"detail ρ{name} x{k:g}"] = _circle(C, k * drawn)
                pts[f"ρ{name} x{k:g}:pin"], pts[f"ρ{name} x{k:g}:touch"] = C, t
                segs.append(Segment(f"ρ{name} x{k:g}", f"ρ{name} x{k:g}:pin", f"ρ{name} x{k:g}:touch", np.full(n, rho),
                                    "m", "arm", Scale("mu_l", mu_l.value / k, "m/mm")))
                e = _unit(_z(res.forces.R[:, p.index]))
                if np.isfinite(e).any():             # its line where R is not zero
                    pts[f"R{name} x{k:g}:from"] = t - 1.6 * DETAIL_RADIUS_MM * e
                    pts[f"R{name} x{k:g}:to"] = t + 1.6 * DETAIL_RADIUS_MM * e
                    segs.append(Segment(f"R{name} x{k:g}", f"R{name} x{k:g}:from", f"R{name} x{k:g}:to",
                                        np.full(n, np.nan), "", "line"))
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
    """One outer reaction of a group: whole, and (pin of RRR, RRP) its normal and tangential
    parts, (N,) complex N."""
    whole: Load
    normal: np.ndarray | None = None      # along the link, N
    tangential: np.ndarray | None = None  # across it


def _split(whole: Load, u: np.ndarray) -> _Parts:
    """`whole` split along the unit u (N,) and across it."""
    n = _dot(whole.force, u) * u
    return _Parts(whole, n, whole.force - n)


def _outer(mech: "Mechanism", res: "Analysis", g: "AssurGroup", side: int) -> _Parts:
    """The reaction of the known link on the group's link at outer pair `side` (0: j, 1: k)."""
    link, pair, known = g.links[side], g.pairs[2 * side], g.known[side]
    whole = _reaction_load(mech, res, known, link)
    if not ((g.kind == "RRR") or (g.kind == "RRP" and side == 0)):
        return _Parts(whole)
    u = _world(res, link, g.pairs[1].point) - _world(res, link, pair.point)
    return _split(whole, _over(u, _abs(u)))


def _moment_equations(g: "AssurGroup") -> list[tuple[tuple[int, ...], str]]:
    """(links, point) of each moment equation the texts write for this group kind: R^tau of a
    pin from its link about the inner joint (RRR, RRP); the slot's normal force from the whole
    group about the slotted link's pivot (RPR). PRP and RPP: offsets x only."""
    j, k = g.links
    inner, outer_k = g.pairs[1].point, g.pairs[2].point
    return {"RRR": [((j,), inner), ((k,), inner)], "RRP": [((j,), inner)],
            "RPR": [((j, k), outer_k)]}.get(g.kind, [])


def _foot(X: np.ndarray, F: np.ndarray, M: np.ndarray) -> np.ndarray:
    """Foot of the perpendicular from M on the line through X along F (NaN where F = 0)."""
    u = _unit(F)
    return X + _dot(M - X, u) * u


def _arrow(segs: list, pts: dict, name: str, X: np.ndarray, F: np.ndarray, mu_l: Scale, mu_F: Scale,
           kind: str = "vector", role: str = "given") -> None:
    """A force F (N) at world point X (m), each (N,), drawn at mu_F from X/mu_l (`kind`
    "alternative": one that replaces others drawn, dashed; `role`: `core.ROLES`, a load given)."""
    start = f"{name}:from"
    pts[start] = np.where(np.isnan(F), np.nan, _over(X, mu_l.value))      # a force NaN where it is not drawn
    pts[f"{name}:to"] = pts[start] + _over(F, mu_F.value)
    segs.append(Segment(name, start, f"{name}:to", _abs(F), "N", kind, mu_F, role))


def _has_arm(mech: "Mechanism", F: np.ndarray, X: np.ndarray, M: np.ndarray) -> np.ndarray:
    """(N,) bool: where force F through X has an arm about M (F not zero, X off M)."""
    return (_abs(F) > 0) & (_abs(X - M) > 1e-12 * mech.size)


def _arm(mech: "Mechanism", segs: list, pts: dict, name: str, M: np.ndarray, M_name: str, X: np.ndarray,
         F: np.ndarray, mu_l: Scale) -> None:
    """Arm of force F through X about point M (world, m), drawn at mu_l where F has one
    (`_has_arm`), if at any angle; NaN at the others."""
    has = _has_arm(mech, F, X, M)
    if not has.any():
        return
    foot = np.where(has, _foot(X, F, M), np.nan)
    pts[M_name] = _over(M, mu_l.value)
    pts[f"{name}:foot"] = _over(foot, mu_l.value)
    segs.append(Segment(name, M_name, f"{name}:foot", _abs(foot - M), "m", "arm"))


def _link_drawing(mech: "Mechanism", res: "Analysis", k: int, pts: dict, segs: list, mu_l: Scale) -> None:
    """Link k at mu_l: its points, and a segment between every two of its joints."""
    joints = [p.point for p in mech.pairs if k in p.links and p.point in mech.links[k].points]
    joints += [p.guide for p in mech.pairs if p.links[0] == k and p.guide in mech.links[k].points]
    names = list(dict.fromkeys(joints)) or list(mech.links[k].points)[:1]
    for name in mech.links[k].points:
        pts[name] = _over(_world(res, k, name), mu_l.value)
    for a in range(len(names)):
        for b in range(a + 1, len(names)):
            A, B = names[a], names[b]
            segs.append(Segment(f"{A}{B}", A, B, _abs(pts[B] - pts[A]) * mu_l.value, "m", "link"))
    for p in mech.pairs:
        if p.kind == "P" and k in p.links:
            X = _over(_world(res, p.links[1], p.point), mu_l.value)
            d = _guide(res, p)
            name = f"guide P({link_number(mech, p.links[0])},{link_number(mech, p.links[1])})"     # the text's numbers
            pts[f"{name}:from"], pts[f"{name}:to"] = X - 40 * d, X + 40 * d
            segs.append(Segment(name, f"{name}:from", f"{name}:to", np.full(len(X), np.nan), "", "line"))


def _cycle(kind: str, titles, scale: Scale, res: "Analysis", pts: dict, segs, paths=None, notes=(),
           results=(), equation=(), steps=()) -> PlanCycle:
    """A PlanCycle at the angles of `res`; `titles` one string for every angle or N strings;
    `notes` the lines at every angle (a list) or per angle (N tuples)."""
    n = len(res.phi_deg)
    titles = (titles,) * n if isinstance(titles, str) else tuple(titles)
    if notes and isinstance(notes[0], str):
        notes = (tuple(notes),) * n
    return PlanCycle(kind, titles, scale, res.phi_deg, pts, tuple(segs), paths or {}, tuple(notes), results, equation,
                     steps=steps)


# -- the plans

def group_plans(mech: "Mechanism", res: "Analysis", mu_l, mu_F: dict[str, Scale] | None = None) -> list[PlanCycle]:
    """The plan of every Assur group at mu_l (seed 002 fig. 1.9, seed 000 figs. 6.1-6.3) at the N
    angles of `res`: the group's links, every load at its point (weights, inertia main vectors
    F_i at S with their moments M_i as arcs, and the single resultant F_i(h) at z = h/mu_l from
    S), the carried reactions, the unknown reactions (pins of RRR, RRP split into R..n along and
    R..t across the link; prismatic normal forces at their offset x, with the arm x_..), and the
    arms h_.. of the moment equations. Forces are drawn at a round force scale of their own:
    `mu_F[label]` (label "2,3" of group:2,3) where given, else chosen for the largest force over
    the angles."""
    _drawable(res)
    mu_l = _scale(mu_l, "mu_l", "m/mm")
    plans = []
    with np.errstate(invalid="ignore", divide="ignore"):
        for g in mech.structure.groups:
            if g.klass == 3:
                plans.append(_triad_group_plan(mech, res, g, mu_l, (mu_F or {}).get(_group_label(g))))
            else:
                plans.append(_dyad_group_plan(mech, res, g, mu_l, (mu_F or {}).get(_group_label(g))))
    return plans


def _dyad_group_plan(mech: "Mechanism", res: "Analysis", g, mu_l: Scale, mu_F: Scale | None) -> PlanCycle:
    """A dyad's plan (`group_plans`)."""
    j, k = g.links
    later = _later(mech, g)
    loads = {x: link_loads(mech, res, x) + _carried(mech, res, x, later) for x in (j, k)}
    outer = [_outer(mech, res, g, 0), _outer(mech, res, g, 1)]
    mu_g = mu_F or force_scale([ld.force for x in (j, k) for ld in loads[x]] + [o.whole.force for o in outer])
    pts: dict[str, np.ndarray] = {}
    segs: list[Segment] = []
    paths: dict[str, np.ndarray] = {}
    drawn_notes = _links_and_loads(mech, res, loads, pts, segs, paths, mu_l, mu_g)
    for o in outer:
        w = o.whole
        if o.normal is None:
            _arrow(segs, pts, w.name, w.point, w.force, mu_l, mu_g, role="result")
        else:
            _arrow(segs, pts, f"{w.name}n", w.point, o.normal, mu_l, mu_g, role="component")
            _arrow(segs, pts, f"{w.name}t", w.point, o.tangential, mu_l, mu_g, role="component")
    for p in (g.pairs[0], g.pairs[1], g.pairs[2]):
        if p.kind == "P":
            drawn_notes = [a + b for a, b in zip(drawn_notes, _offset(mech, res, p, pts, segs, mu_l))]
    for links, M_name in _moment_equations(g):
        M = _world(res, next(x for x in links[::-1] if M_name in mech.links[x].points), M_name)
        for x in links:
            for ld in loads[x]:
                _arm(mech, segs, pts, arm_name(ld.name), M, M_name, ld.point, ld.force, mu_l)
    _group_couples(mech, res, (j, k), pts, segs, paths, mu_l)
    notes = _friction_circles(mech, res, g.pairs, pts, segs, paths, mu_l)
    return _cycle(f"group:{_group_label(g)}", f"Group {_group_label(g)} ({g.kind}): loads and reactions"
                  + (" with friction" if res.friction is not None else "") + f"; forces drawn at {mu_g}",
                  mu_l, res, pts, segs, paths, [tuple(notes) + z for z in drawn_notes])


def _links_and_loads(mech: "Mechanism", res: "Analysis", loads: dict[int, list[Load]], pts: dict, segs: list,
                     paths: dict, mu_l: Scale, mu_F: Scale) -> list[tuple[str, ...]]:
    """The links of a group (the keys of `loads`) at mu_l, their loads at mu_F and the single
    inertia resultants; an inertia force not drawn where it is zero (`_zeros`). Returns each
    angle's notes: what is zero there (a couple too: `_group_couples` draws them), what F_i(h)
    replaces."""
    for x in loads:
        _link_drawing(mech, res, x, pts, segs, mu_l)
    zeros: dict[str, tuple[np.ndarray, str]] = {}
    replaces = []
    for x in loads:
        zeros.update(_zeros(mech, res, x))
        for ld in loads[x]:
            _load_arrow(segs, pts, ld, zeros, mu_l, mu_F)
        replaces.append(_resultant(mech, res, x, pts, segs, mu_l, mu_F))
    notes = zero_notes(zeros, len(res.phi_deg))
    return [z + tuple(r[i] for r in replaces if r[i]) for i, z in enumerate(notes)]


def _zeros(mech: "Mechanism", res: "Analysis", k: int) -> dict[str, tuple[np.ndarray, str]]:
    """Link k's inertia force and couples where zero (`zero`): name -> ((N,) bool, why: "" at
    the angle, "link k translates" where M_i<k> is zero by the link's motion)."""
    link, out = mech.links[k], {}
    if link.com is not None and link.mass:
        out[f"F_i{k}"] = (zero_inertia_force(mech, res, k) & ~res.singular, "")
    if link.I_S:
        out[f"M_i{k}"] = (zero_eps(mech, res, k) & ~res.singular, f"link {k} translates" if translates(mech, k) else "")
    for c in link_couples(mech, res, k):
        if c.name not in out:                     # an applied moment: against its largest over the angles
            big = np.nanmax(np.abs(c.moment)) if np.isfinite(c.moment).any() else 0.0
            out[c.name] = (zero_of(c.moment, big) & ~res.singular, "")
    return out


def _load_arrow(segs: list, pts: dict, ld: Load, zeros: dict[str, tuple[np.ndarray, str]], mu_l: Scale,
                mu_F: Scale) -> None:
    """Load `ld` as an arrow (`_arrow`), NaN where it is zero (`zeros`); one zero at every angle not
    drawn at all."""
    zero = zeros[ld.name][0] if ld.name in zeros else np.zeros(len(ld.force), dtype=bool)
    if not zero.all():
        _arrow(segs, pts, ld.name, ld.point, np.where(zero, np.nan, ld.force), mu_l, mu_F)


def _couple_centre(mech: "Mechanism", res: "Analysis", k: int) -> np.ndarray:
    """(N,) complex world m: where link k's couples are drawn, its centre of mass (its origin)."""
    link = mech.links[k]
    return _world(res, k, link.com) if link.com else res.kin.origin_z[:, k]


def _couples(mech: "Mechanism", res: "Analysis", k: int, at: np.ndarray, radius_mm: float,
             zeros: dict[str, tuple[np.ndarray, str]], paths: dict, mu_l: Scale, lines) -> None:
    """Link k's couples as arcs of `radius_mm` about `at` (world m), NaN where zero (`zeros`);
    one zero at every angle not drawn at all. Each arc `_couple_arc`, clear of `lines`."""
    for c in link_couples(mech, res, k):
        zero = zeros[c.name][0]
        if not zero.all():
            paths[c.name] = np.where(zero[:, None], np.nan, _couple_arc(_over(at, mu_l.value), c.moment, radius_mm, lines))


def _couple_arc(S: np.ndarray, moment: np.ndarray, radius_mm: float, lines) -> np.ndarray:
    """(N, 19): a 270-degree arc around S (mm) in the sense of the moment at each angle (ccw for
    positive), its ends either side of S's right, turned so that its arrowhead falls clear of
    the heavy `lines` (`arcs.arc`)."""
    sense = np.where(np.asarray(moment) >= 0, 1.0, -1.0)
    return arc(np.asarray(S), radius_mm, sense, -135.0 * sense, 270.0, lines)


def _group_couples(mech: "Mechanism", res: "Analysis", links, pts: dict, segs: list, paths: dict,
                   mu_l: Scale) -> None:
    """The couples of a group's `links`, drawn last, about each link's centre of mass (8 mm arcs),
    their arrowheads clear of every link and vector drawn on the plan."""
    lines = heavy_lines(pts, segs)
    for x in links:
        _couples(mech, res, x, _couple_centre(mech, res, x), 8.0, _zeros(mech, res, x), paths, mu_l, lines)


def _leash_parts(mech: "Mechanism", res: "Analysis", side) -> _Parts:
    """The reaction of the known link on a triad's leash: a two-pin leash's split along its axis
    (outer pin -> inner pin) and across it; a leash on an inner prismatic pair's along its axis
    (the guide's normal) and along the guide; a slider's normal force whole."""
    ell, outer, inner, known = side
    whole = _reaction_load(mech, res, known, ell)
    if outer.kind != "R":
        return _Parts(whole)
    if inner.kind == "P":
        return _split(whole, 1j * _guide(res, inner))
    u = _world(res, ell, inner.point) - _world(res, ell, outer.point)
    return _split(whole, _over(u, _abs(u)))


def _special_point(mech: "Mechanism", res: "Analysis", g) -> tuple[str, np.ndarray]:
    """The name on the plans and the world position (m, (N,)) of a triad's special point S."""
    from ..kinematics import special_point_z
    return ("S" if "S" not in mech.point_names else "S*"), np.asarray(special_point_z(mech, res.kin, g), dtype=complex)


def _orders(mech: "Mechanism", res: "Analysis", g) -> list[tuple[tuple, np.ndarray]]:
    """A triad's sides in the solver's order (`kinematics.special_sides`) and the angles (an (N,)
    mask) where it is that order, for each order the angles of `res` hold, in the order of their
    first angle."""
    from ..kinematics import special_index
    k = special_index(mech, res.kin, g)
    first = sorted(set(k.tolist()), key=lambda x: int(np.argmax(k == x)))
    return [(tuple(g.sides[(x + i) % 3] for i in (1, 2, 0)), k == x) for x in first]


def _masked(segs: list[Segment], where: np.ndarray) -> list[Segment]:
    """The segments with their values NaN off `where` (not drawn there)."""
    return [replace(s, value=np.where(where, s.value, np.nan)) for s in segs]


def _merged(parts: list[tuple[np.ndarray, dict, list[Segment]]]) -> tuple[dict, list[Segment]]:
    """One plan's points and segments from parts drawn each at its own angles (mask, points,
    segments with values NaN off the mask): a point at each angle from the part there (NaN where
    the part lacks it), the segments in an order that keeps each part's, one where two parts
    draw the same name between the same points."""
    n = len(parts[0][0])
    pts: dict[str, np.ndarray] = {}
    for where, p, _ in parts:
        for name, z in p.items():
            pts[name] = np.where(where, z, pts.get(name, np.full(n, np.nan + 0j)))
    out: list[Segment] = []
    for where, _, segs in parts:
        at = -1
        for s in segs:
            key = (s.name, s.start, s.end, s.unit, s.kind, s.scale)
            j = next((i for i in range(at + 1, len(out)) if (out[i].name, out[i].start, out[i].end, out[i].unit,
                                                             out[i].kind, out[i].scale) == key), None)
            if j is None:
                at += 1
                out.insert(at, s)
            else:
                at = j
                o = out[j]
                out[j] = replace(o, value=np.where(where, s.value, o.value))
    return pts, out


def _triad_group_plan(mech: "Mechanism", res: "Analysis", g, mu_l: Scale, mu_F: Scale | None = None) -> PlanCycle:
    """A triad's plan (Artobolevsky 1988): its four links with their loads and the carried
    reactions; each leash's outer reaction (a two-pin leash's split into R..n along its axis and
    R..t across it, a leash on an inner prismatic pair's likewise, R..t along the guide; a
    slider's normal force at its offset x); the axes of the two leashes through Assur's special
    point S drawn through it (at each angle the two the solver takes there); the arms of each
    two-pin leash's moment equation about its inner pin (R..t) and of the group's about S (R..n
    of the third leash, marked (S))."""
    later = _later(mech, g)
    loads = {x: link_loads(mech, res, x) + _carried(mech, res, x, later) for x in g.links}
    parts = [_leash_parts(mech, res, side) for side in g.sides]
    mu_F = mu_F or force_scale([ld.force for x in g.links for ld in loads[x]] + [o.whole.force for o in parts])
    pts: dict[str, np.ndarray] = {}
    segs: list[Segment] = []
    paths: dict[str, np.ndarray] = {}
    notes = _links_and_loads(mech, res, loads, pts, segs, paths, mu_l, mu_F)
    S_name, S = _special_point(mech, res, g)
    pts[S_name] = _over(S, mu_l.value)
    for (ell, outer, inner, _), o in zip(g.sides, parts):
        w = o.whole
        if o.normal is None:
            _arrow(segs, pts, w.name, w.point, w.force, mu_l, mu_F, role="result")
            notes = [a + b for a, b in zip(notes, _offset(mech, res, outer, pts, segs, mu_l))]
        else:
            _arrow(segs, pts, f"{w.name}n", w.point, o.normal, mu_l, mu_F, role="component")
            _arrow(segs, pts, f"{w.name}t", w.point, o.tangential, mu_l, mu_F, role="component")
            X = _world(res, ell, inner.point)
            for ld in loads[ell] if inner.kind == "R" else ():
                _arm(mech, segs, pts, arm_name(ld.name), X, inner.point, ld.point, ld.force, mu_l)
    axes = []
    for sides, where in _orders(mech, res, g):
        drawn = []
        for ell, outer, inner, _ in sides[:2]:
            on = outer.point if inner.kind == "P" else inner.point        # a point of the leash's axis
            drawn.append(Segment(f"axis {on}{S_name}", on, S_name, _abs(_world(res, ell, on) - S), "m", "line"))
        axes.append((where, {}, _masked(drawn, where)))
    segs += _merged(axes)[1]
    for x in g.links:
        for ld in loads[x]:
            _arm(mech, segs, pts, f"{arm_name(ld.name)}({S_name})", S, S_name, ld.point, ld.force, mu_l)
    _group_couples(mech, res, g.links, pts, segs, paths, mu_l)
    return _cycle(f"group:{_group_label(g)}", f"Group {g.label} (III3, Assur's point {S_name}): loads and reactions; "
                  f"forces drawn at {mu_F}", mu_l, res, pts, segs, paths, notes)


def _triad_polygon(mech: "Mechanism", res: "Analysis", g, sides) -> tuple[list[tuple[str, np.ndarray, str]], list, list]:
    """A triad's vector equation, its sides in the solver's order `sides`, in an order that keeps
    each leash's forces together, leashes 1 and 2 those through S and 3 the third
    (`kinematics.special_sides`): R..t of leash 2, its loads, the base's loads, R..n and R..t of
    leash 3 (R..n known from the group's moment about S), its loads, leash 1's loads, its R..t,
    and the unknowns R..n of leashes 1 and 2 closing the polygon. Also, per leash, the indices of
    its first and last forces (its inner reaction closes its own polygon from the one to the
    other) and of its two reaction parts."""
    later = _later(mech, g)
    parts = [_leash_parts(mech, res, side) for side in sides]
    loads = lambda x: [(ld.name, ld.force, "given") for ld in link_loads(mech, res, x) + _carried(mech, res, x, later)]
    t = lambda o: [] if o.normal is None else [(f"{o.whole.name}t", o.tangential, "component")]
    n = lambda o: [(o.whole.name, o.whole.force, "result")] if o.normal is None else [(f"{o.whole.name}n", o.normal, "component")]
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


def _resultant(mech: "Mechanism", res: "Analysis", k: int, pts: dict, segs: list, mu_l: Scale,
               mu_F: Scale) -> list[str]:
    """The single inertia resultant F_i<k>(h) of a link with both a main vector and a main
    moment (neither zero, `zero`), at z = h/mu_l from S on the side whose moment opposes eps
    (seed 000 sec. 4), and z; at the angles where it has both (NaN at the others), if at any.
    It replaces F_i<k> and M_i<k>, which are drawn too: it is drawn as an alternative (kind
    "alternative": dashed), and each angle's note (N strings, "" where not drawn) says so."""
    n = len(res.phi_deg)
    link = mech.links[k]
    if link.com is None or not link.mass or not link.I_S or translates(mech, k):
        return [""] * n
    il = res.inertia(k)
    F = _z(il.force)
    has = ~zero_inertia_force(mech, res, k) & ~zero_eps(mech, res, k) & ~res.singular
    if not has.any():
        return [""] * n
    S, K = _world(res, k, link.com), np.where(has, _z(il.point), np.nan)
    _arrow(segs, pts, f"F_i{k}(h)", K, np.where(has, F, np.nan), mu_l, mu_F, "alternative")
    pts[f"z_{k}:S"] = np.where(has, _over(S, mu_l.value), np.nan)
    segs.append(Segment(f"z_{k}", f"z_{k}:S", f"F_i{k}(h):from", np.where(has, il.h, np.nan), "m", "arm"))
    return [f"F_i{k}(h) (dashed) replaces F_i{k} and M_i{k}: one or the other acts, not both" if h else ""
            for h in has.tolist()]


def _offset(mech: "Mechanism", res: "Analysis", p, pts: dict, segs: list, mu_l: Scale) -> list[tuple[str, ...]]:
    """The offset x of prismatic pair p's normal force from its slider point, along the guide,
    where it is defined, if at any angle (NaN at the others). Where it falls outside the slider
    link (`_off_link`): the link's line drawn on to it (kind "extension", dashed), a
    ModelWarning naming the pair and the angles, and each angle's note (N tuples) saying so."""
    n = len(res.phi_deg)
    x = res.reaction_offset(*p.links)
    if np.isnan(x).all():
        return [()] * n
    X, d = _world(res, p.links[1], p.point), _guide(res, p)
    R = reaction_name(mech, *p.links)
    name = "x_" + R[1:]
    pts[f"{name}:from"] = np.where(np.isnan(x), np.nan, _over(X, mu_l.value))
    pts[f"{name}:to"] = (X + x * d) / mu_l.value   # rounded as before
    segs.append(Segment(name, f"{name}:from", f"{name}:to", _abs(x), "m", "arm"))
    lo, hi = _span(mech, res, p)
    off = _off_link(mech, x, lo, hi)
    if not off.any():
        return [()] * n
    q = link_number(mech, p.links[1])
    pts[f"{name}:edge"] = np.where(off, _over(X + np.clip(x, lo, hi) * d, mu_l.value), np.nan)
    segs.append(Segment(f"link {q} extended to {R}", f"{name}:edge", f"{name}:to", np.where(off, _abs(x - np.clip(x, lo, hi)), np.nan),
                        "m", "extension"))
    pair = f"P({link_number(mech, p.links[0])},{q})"
    warnings.warn(ModelWarning(
        f"pair {pair}: the normal force {R} acts {np.nanmax(np.abs(x[off])):.4g} m from {p.point} at most, outside link {q} "
        f"(its points span {np.nanmin(lo[off]):.4g} .. {np.nanmax(hi[off]):.4g} m along the guide) at phi = "
        f"{_angle_list(np.round(res.phi_deg[off], 9))}: "
        f"the link is shorter than the model's loads need, or its points do not reach its ends"), stacklevel=3)
    return [(f"{R} acts {abs(v):.4g} m from {p.point}, outside link {q} ({a:.4g} .. {b:.4g} m along the guide): "
             f"the link's line drawn on to it, dashed",) if o else ()
            for v, a, b, o in zip(x.tolist(), lo.tolist(), hi.tolist(), off.tolist())]


def _span(mech: "Mechanism", res: "Analysis", p) -> tuple[np.ndarray, np.ndarray]:
    """(N,) each, m: the least and the greatest of prismatic pair p's slider link's points along
    the guide, from its slider point."""
    k = p.links[1]
    X, d = _world(res, k, p.point), _guide(res, p)
    along = np.stack([_dot(_world(res, k, name) - X, d) for name in mech.links[k].points])
    return along.min(axis=0), along.max(axis=0)


def _off_link(mech: "Mechanism", x: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """(N,) bool: where offset x (m) lies outside [lo, hi] by more than ZERO_REL of the mechanism's
    size, on a link that has a length along the guide (a slider drawn as one point has none)."""
    tol = ZERO_REL * mech.size
    with np.errstate(invalid="ignore"):
        return (hi - lo > tol) & ((x < lo - tol) | (x > hi + tol))


def _polygon(mech: "Mechanism", res: "Analysis", g: "AssurGroup") -> tuple[list[tuple[str, np.ndarray, str]], int, int]:
    """The group's vector equation in the texts' order, as (name, force N (N,), role: a load
    given, a reaction's part a component, a whole reaction found a result): the known part of
    j's outer reaction (R..t) or the whole of it, j's loads, k's loads, then k's outer reaction
    (R..t known, R..n unknown; or the normal force) and j's R..n closing it. Also the index of
    the last of j's loads (the internal reaction closes j's polygon there) and the index at
    which j's whole outer reaction starts (the vertex after the closing side; 0 if unsplit)."""
    j, k = g.links
    later = _later(mech, g)
    oj, ok = _outer(mech, res, g, 0), _outer(mech, res, g, 1)
    seq: list[tuple[str, np.ndarray, str]] = []
    if oj.normal is None:
        seq.append((oj.whole.name, oj.whole.force, "result"))
    else:
        seq.append((f"{oj.whole.name}t", oj.tangential, "component"))
    seq += [(ld.name, ld.force, "given") for ld in link_loads(mech, res, j) + _carried(mech, res, j, later)]
    end_j = len(seq)
    seq += [(ld.name, ld.force, "given") for ld in link_loads(mech, res, k) + _carried(mech, res, k, later)]
    if ok.normal is None:
        seq.append((ok.whole.name, ok.whole.force, "result"))
    else:
        seq += [(f"{ok.whole.name}t", ok.tangential, "component"), (f"{ok.whole.name}n", ok.normal, "component")]
    if oj.normal is not None:
        seq.append((f"{oj.whole.name}n", oj.normal, "component"))
    return seq, end_j, 0 if oj.normal is None else len(seq) - 1


def _vertex(n: int) -> str:
    return string.ascii_lowercase[n] if n < 26 else f"v{n}"


def force_plans(mech: "Mechanism", res: "Analysis", mu_F) -> list[PlanCycle]:
    """The force plan of every Assur group at mu_F (seed 002 fig. 1.10, seed 000 sec. 6) at the N
    angles of `res`: the polygon of the group's vector equation in the texts' order, vertices
    lettered a, b, c, ... from the start of the first known force, closed by the unknowns; the
    whole outer reactions (R12 = R12n + R12t, ...) as chords; and the internal reaction (R32: of
    link k on link j) from the polygon of link j, the chord from the end of j's loads to the
    start of j's outer reaction. Each segment's value is the force's magnitude, N. A dyad closed by
    two unknowns of known direction (R12n, R43) shows their lines through the polygon's start and
    the last known force's end, and the intersection that fixes both (`core.construction`); its
    steps: the known forces, the lines, the intersection, the unknowns."""
    _drawable(res)
    mu_F = _scale(mu_F, "mu_F", "N/mm")
    plans = []
    with np.errstate(invalid="ignore", divide="ignore"):
        for g in mech.structure.groups:
            plans.append(_triad_force_plan(mech, res, g, mu_F) if g.klass == 3 else _dyad_force_plan(mech, res, g, mu_F))
    return plans


def _dyad_force_plan(mech: "Mechanism", res: "Analysis", g, mu_F: Scale) -> PlanCycle:
    """A dyad's force plan (`force_plans`)."""
    j, k = g.links
    seq, end_j, start_j = _polygon(mech, res, g)
    pts, segs = _closed_polygon(seq, mu_F)
    oj, ok = _outer(mech, res, g, 0), _outer(mech, res, g, 1)
    X = _vertex(start_j)
    if oj.normal is not None:     # whole pin reactions as chords: R = R^n + R^tau
        segs.append(Segment(oj.whole.name, X, _vertex(1), _abs(oj.whole.force), "N", role="result"))
    if ok.normal is not None:
        first = len(seq) - 3
        segs.append(Segment(ok.whole.name, _vertex(first), _vertex(first + 2), _abs(ok.whole.force), "N", role="result"))
    segs.append(Segment(reaction_name(mech, k, j), _vertex(end_j), X, _abs(_z(res.reaction(k, j))), "N", role="result"))
    equation = tuple(name for name, *_ in seq)
    steps = equation
    if oj.normal is not None:      # closed by two unknowns of known direction (seed 002 fig. 1.10)
        m = len(seq)
        lines = construction(_vertex(m - 1), [(equation[-1], _vertex(0)), (equation[-2], _vertex(m - 2))])
        segs += lines
        steps = equation[:-2] + tuple(s.name for s in lines) + equation[-2:]
    return _cycle(f"forces:{_group_label(g)}", f"Force plan of group {_group_label(g)} ({g.kind}): "
                  + " + ".join(equation) + " = 0", mu_F, res, pts, segs, equation=equation,
                  notes=["the reactions with friction in the reactions"] if res.friction is not None else (), steps=steps)


def _closed_polygon(seq: list[tuple[str, np.ndarray, str]], mu_F: Scale) -> tuple[dict, list]:
    """The polygon of `seq` (name, force, role) at mu_F: vertices a, b, c, ... from the start of
    the first force, the last force ending at the first vertex."""
    pts = {_vertex(0): np.zeros(len(seq[0][1]), dtype=complex)}
    segs = []
    for n, (name, F, role) in enumerate(seq):
        a, b = _vertex(n), _vertex((n + 1) % len(seq))
        if b not in pts:
            pts[b] = pts[a] + _over(F, mu_F.value)
        segs.append(Segment(name, a, b, _abs(F), "N", role=role))
    return pts, segs


def _triad_force_plan(mech: "Mechanism", res: "Analysis", g, mu_F: Scale) -> PlanCycle:
    """A triad's force plan: its polygon (`_triad_polygon`) closed by R..n of the leashes through S,
    the whole reaction of each two-pin leash as a chord over its two parts, and each leash's
    inner reaction (of the base on it) from its own polygon: the chord from the end of its
    forces back to their start. Each order of the sides the angles hold (`_orders`) drawn at its
    own angles: its equation and title there, and its construction (as a dyad's, `_dyad_force_plan`):
    the lines of the two unknowns R..n, along the axes of the leashes through S, through the
    polygon's start and the last known force's end, and the intersection that fixes both
    (`core.construction` in that order); its steps: the known forces, the lines, the
    intersection, the unknowns (N tuples where the order changes with the angle)."""
    orders = _orders(mech, res, g)
    parts, equations, steps = [], [], []
    for sides, where in orders:
        seq, spans, whole = _triad_polygon(mech, res, g, sides)
        pts, segs = _closed_polygon(seq, mu_F)
        m = len(seq)
        equation = tuple(name for name, *_ in seq)
        order = str(g.sides.index(sides[2]) + 1)          # the tag of the triad's order (kinematic's too)
        lines = construction(_vertex(m - 1), [(equation[-1], _vertex(0)), (equation[-2], _vertex(m - 2))], order)
        pts[alias(_vertex(m - 1), order)] = pts[_vertex(m - 1)]
        segs += lines
        steps.append(equation[:-2] + tuple(s.name for s in lines) + equation[-2:])
        for (ell, _, _, known), w in zip(sides, whole):
            if w is not None:
                segs.append(Segment(reaction_name(mech, known, ell), _vertex(w[0] % m), _vertex(w[1] % m),
                                    _abs(_z(res.reaction(known, ell))), "N", role="result"))
        for (ell, _, _, _), (a, b) in zip(sides, spans):
            segs.append(Segment(reaction_name(mech, g.links[0], ell), _vertex(b % m), _vertex(a % m),
                                _abs(_z(res.reaction(g.links[0], ell))), "N", role="result"))
        parts.append((where, pts, _masked(segs, where)))
        equations.append(equation)
    pts, segs = _merged(parts)
    which = np.argmax(np.stack([where for _, where in orders]), axis=0)      # each angle's order
    titles = [f"Force plan of group {g.label} (III3): " + " + ".join(equations[o]) + " = 0" for o in which.tolist()]
    equation = equations[0] if len(orders) == 1 else tuple(equations[o] for o in which.tolist())
    steps_at = steps[0] if len(orders) == 1 else tuple(steps[o] for o in which.tolist())
    return _cycle(f"forces:{_group_label(g)}", titles, mu_F, res, pts, segs, equation=equation, steps=steps_at)


#: The longest force on the plan of the initial link when it takes a force scale of its own, mm.
CRANK_FORCE_MM = 80.0


def crank_plan(mech: "Mechanism", res: "Analysis", mu_l, mu_F=None) -> PlanCycle:
    """The initial link at mu_l with its loads drawn at mu_F (seed 002 fig. 1.11, seed 000
    sec. 7) at the N angles of `res`: the reactions of the groups on it (R21 at A, ...), its own
    weight and inertia, the frame's reaction at the pivot (R01; R41 for seed 002's ICE), the arms
    h_.. of its moment equation about the pivot, and the balancing load: an engine's couple M_bal
    (an arc, its value M_bal = sum of the arms' moments); a working machine's gear mesh (pitch
    circles of wheel and pinion, pitch point P, line of action at alpha_w, F_bal at P and its arm
    r_b). mu_F None: a round force scale of its own, the largest reaction over the angles at most
    CRANK_FORCE_MM. Its title states M_bal (F_bal) at each angle."""
    _drawable(res)
    mu_l = _scale(mu_l, "mu_l", "m/mm")
    if mu_F is None:
        mu_F = force_scale([_all_reactions(res)], CRANK_FORCE_MM)
    mu_F = _scale(mu_F, "mu_F", "N/mm")
    with np.errstate(invalid="ignore", divide="ignore"):
        return _crank_plan(mech, res, mu_l, mu_F)


def _crank_plan(mech: "Mechanism", res: "Analysis", mu_l: Scale, mu_F: Scale) -> PlanCycle:
    dr, L = mech.drive, lettering(mech)
    pts: dict[str, np.ndarray] = {}
    segs: list[Segment] = []
    paths: dict[str, np.ndarray] = {}
    _link_drawing(mech, res, 1, pts, segs, mu_l)
    O = _world(res, 1, dr.pivot)
    on_crank = _carried(mech, res, 1, set(range(2, mech.n_links))) + link_loads(mech, res, 1)
    zeros = _zeros(mech, res, 1)
    for ld in on_crank:
        _load_arrow(segs, pts, ld, zeros, mu_l, mu_F)
    for ld in on_crank:
        _arm(mech, segs, pts, arm_name(ld.name), O, dr.pivot, ld.point, ld.force, mu_l)
    R01 = _reaction_load(mech, res, 0, 1)
    _arrow(segs, pts, R01.name, R01.point, R01.force, mu_l, mu_F, role="result")
    M_bal = np.asarray(res.balancing_moment, dtype=float)
    if dr.kind == "machine":
        gear = dr.gear
        e = complex(*gear.centre_direction)
        r_pinion = gear.r_w * gear.z_pinion / gear.z_wheel
        P = O + gear.r_w * e
        paths["pitch circle of the wheel"] = _circle(_over(O, mu_l.value), gear.r_w / mu_l.value)
        paths["pitch circle of the pinion"] = _circle(_over(O + (gear.r_w + r_pinion) * e, mu_l.value), r_pinion / mu_l.value)
        F_bal = _z(res.balancing_force)
        line = np.where(_abs(F_bal) > 0, _unit(F_bal), _line_of_action(gear, M_bal))
        pts["P"] = _over(P, mu_l.value)
        pts["line of action:from"], pts["line of action:to"] = pts["P"] - 40 * line, pts["P"] + 40 * line
        segs.append(Segment("line of action", "line of action:from", "line of action:to", np.full(len(P), np.nan),
                            "", "line"))
        _arrow(segs, pts, L.F_bal, P, F_bal, mu_l, mu_F, role="result")
        foot = _foot(P, line, O)
        pts["r_b:foot"] = _over(foot, mu_l.value)
        segs.append(Segment("r_b", dr.pivot, "r_b:foot", _abs(foot - O), "m", "arm"))
        titles = [f"Initial link: gear mesh alpha_w = {gear.alpha_w_deg:g} deg, {L.F_bal} = {f:.6g} N, "
                  f"r_b = {gear.r_b * 1e3:.6g} mm, {L.M_bal} = {L.F_bal} r_b = {m:.6g} N m"
                  for f, m in zip(_abs(F_bal).tolist(), M_bal.tolist())]
        results = (Result(L.F_bal, _abs(F_bal), "N"), Result("r_b", np.full(len(P), gear.r_b), "m"),
                   Result(L.M_bal, M_bal, "N m", "M = F r_b"))
    else:
        paths[L.M_bal] = _couple_arc(_over(O, mu_l.value), M_bal, 10.0, heavy_lines(pts, segs))
        titles = [f"Initial link: balancing couple {L.M_bal} = {m:.6g} N m" for m in M_bal.tolist()]
        results = (Result(L.M_bal, M_bal, "N m", "M = sum"),)
    _couples(mech, res, 1, O, 6.0, zeros, paths, mu_l, heavy_lines(pts, segs))
    notes = _friction_circles(mech, res, [p for p in mech.pairs if dr.link in p.links], pts, segs, paths, mu_l)
    return _cycle("crank", [f"{t}; forces drawn at {mu_F}" for t in titles], mu_l, res, pts, segs, paths,
                  notes=[tuple(notes) + z for z in zero_notes(zeros, len(res.phi_deg))], results=results)


def _line_of_action(gear, M: np.ndarray) -> np.ndarray:
    """(N,) complex: the gear mesh's line of action where F_bal = 0, by the sense of M (N,)."""
    e, alpha = complex(*gear.centre_direction), math.radians(gear.alpha_w_deg)
    return np.where(M >= 0, 1.0, -1.0) * math.cos(alpha) * 1j * e - math.sin(alpha) * e


def _circle(C: np.ndarray, r) -> np.ndarray:
    """(N, 73): circles of radius r about the centres C (N,), mm."""
    return np.asarray(C)[:, None] + np.asarray(r)[..., None] * np.exp(1j * np.linspace(0.0, 2 * np.pi, 73))
