"""The kinematic plans of the graphical method (seed 002 sec. 1.2.2, seed 000 secs. 6-8), drawn
from the exact solution: the plan of positions, the velocity plan and the acceleration plan.

Lettering (as the texts letter them): the poles are `p` (velocities) and `pi` (accelerations,
the texts' π); a point of the plans is the model's point name in lower case (`a`, `b`, `s2`).
Where a block slides on a moving link, the two coincident points are told apart by the link
number, as seed 000 does (`a1` the crank pin and block, `a3` the point of slotted link 3 under
it). Points of the frame coincide with the pole and are not named.
Acceleration components: `<r>-n<k>` the normal part a^n = ω_k² l of link k's point relative to
its reference point r (seed 002: `a-n2` for a^n_BA), `n<k>-<q>` the tangential part a^τ = |ε_k| l
(seed 002: `n2-b`); seed 000 numbers the points n1, n2, n3 in the order drawn, seed 002 by the
link, which is followed here. A block sliding on a moving guide: `<from>-k` the Coriolis part
2|ω v_rel| and `k-<to>` the relative (sliding) part, drawn from the point already known (the
crank pin `a1` in a slotted-link group, the guide's point `b3` when the guide is known); `k1`,
`k2`, ... when a plan has several. The plan of positions names each position's points with the
position number (`A3`, `S2_3` where the name ends in a digit) and the design position's plain.

Every plan is built for the N angles of one analysis at once (`core.PlanCycle`); an element that
exists at some angles only is NaN (not drawn) at the others.

May use: numpy, `kinetostat.kinematics` (Assur's special point), `.solution` (the one analysis the
plans are drawn from; positions alone where a search needs new angles: the starting position's
refinement, its 12 positions, the other assembly branch at the angles drawn), `.core`, `.zero`
(a plan's side that collapses).
"""
from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, replace
from types import MappingProxyType
from typing import NamedTuple

import numpy as np

from .core import PlanCycle, Scale, Segment, alias, construction
from .solution import CYCLE_STEPS, Positions, Solution, grid, positions, solve
from .zero import by_pattern, translates, zero_of

__all__ = ["positions_plan", "fixed_positions", "other_branches", "assembled", "FixedPositions", "velocity_plan", "acceleration_plan", "starting_position", "plan_point_names",
           "N_POSITIONS", "PATH_STEPS"]

#: Positions of the plan of positions: every 30 deg.
N_POSITIONS = 12
#: Crank angles sampled for the path of a centre of mass.
PATH_STEPS = 180
#: Angles a round of the search for the starting position solves at once.
SECTIONS = 63


def _titles(text: str, res) -> tuple[str, ...]:
    """`text` with `{at:g}` filled at each angle of `res`: the N titles of a cycle."""
    return tuple(text.format(at=float(a)) for a in res.phi_deg)


def _ok(res) -> np.ndarray:
    """(N,) True at the angles where the plans are drawn (not at a singular position)."""
    return ~np.asarray(res.singular, bool)


def _where(on: np.ndarray | None, value: np.ndarray) -> np.ndarray:
    """A segment's value at the angles `on` (N,) bool (None: all), NaN at the others: the segment
    is not drawn there (`PlanCycle.drawn`)."""
    return value if on is None else np.where(on, value, np.nan)


def _any(values, res) -> bool:
    """Whether an element whose existence `values` (N,) decide is drawn at some angle of `res`
    (`values` != 0 at a non-singular angle): such an element is in the plan at every angle."""
    return bool(np.any((np.asarray(values) != 0) & _ok(res)))


# ----------------------------------------------------------------------------- points of the plans

class _Point(NamedTuple):
    link: int
    local: complex | np.ndarray     # local coordinates on `link`, m; (N,) where it moves on the link


@dataclass(frozen=True)
class _Sliding:
    """A prismatic pair between two moving links, drawn from the point already known (`start`)
    to the other (`end`); `from_guide`: the known point is the guide's."""
    pair: object
    guide_name: str
    slider_name: str
    from_guide: bool

    @property
    def start(self) -> str:
        return self.guide_name if self.from_guide else self.slider_name

    @property
    def end(self) -> str:
        return self.slider_name if self.from_guide else self.guide_name


def _moving_p_pairs(mech):
    return [p for p in mech.pairs if p.kind == "P" and 0 not in p.links]


def plan_point_names(mech, res=None) -> dict[str, _Point]:
    """The points of the velocity and acceleration plans: plan name -> (link, local coordinates),
    in the order the texts draw them (crank, then group by group). Needs `res` (one angle) for
    the coincident points of a guide, which move along it: their local coordinates (N,) over
    the angles of `res`)."""
    frame = mech.links[0].points
    split = {p.point for p in _moving_p_pairs(mech)}
    out: dict[str, _Point] = {}
    seen = set()
    for link in mech.links[1:]:
        for name, xy in link.points.items():
            if name in frame or name in seen:
                continue
            seen.add(name)
            owner = mech.point_owner(name)
            key = f"{name.lower()}{owner}" if name in split else name.lower()
            out[key] = _Point(owner, complex(*mech.links[owner].points[name]))
    if res is not None:
        for p in _moving_p_pairs(mech):
            g = p.links[0]
            out[f"{p.point.lower()}{g}"] = _Point(g, (_z(res, p.point) - res.kin.origin_z[:, g]) / res.kin.rot[:, g])
    return out


def _name_of(mech, point: str) -> str:
    """Plan name of the model point `point` (frame points: the pole, None)."""
    if point in mech.links[0].points:
        return ""
    split = {p.point for p in _moving_p_pairs(mech)}
    return f"{point.lower()}{mech.point_owner(point)}" if point in split else point.lower()


def _slidings(mech, pole: str) -> list[_Sliding]:
    """Prismatic pairs between moving links, in the order drawn, each from its known side (a
    triad's inner pair: from the guide); a slider's point on a frame pin (a rocking block) is
    the plan's `pole`."""
    out = []
    for g in mech.structure.groups:
        for idx, p in enumerate(g.pairs):
            if p.kind != "P" or 0 in p.links:
                continue
            guide, slider = p.links
            known = g.links[0] if idx == 1 else next((i for i in p.links if i not in g.links), p.links[0])
            out.append(_Sliding(p, f"{p.point.lower()}{guide}", _name_of(mech, p.point) or pole, known == guide))
    return out


def _point_motion(kin, k: int, local) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Position, velocity, acceleration (each (N,) complex) of the point of link k at `local`
    (complex, or (N,) complex where it moves on the link): `Kinematics.point_z`'s formula."""
    r = local * kin.rot[:, k]
    w, e = kin.omega[:, k], kin.eps[:, k]
    return kin.origin_z[:, k] + r, kin.v_z[:, k] + 1j * w * r, kin.a_z[:, k] + (1j * e - w**2) * r


def _motion(res, pts: dict[str, _Point]):
    """name -> (position, velocity, acceleration), each (N,) complex over the angles of `res`."""
    return {n: _point_motion(res.kin, p.link, p.local) for n, p in pts.items()}


def _floating_joints(mech, names: dict[str, _Point]) -> list[tuple[int, list[str]]]:
    """Links not pivoted to the frame and the plan names of their joints (pins, coincident points)."""
    out = []
    for link in mech.links[1:]:
        k = link.id
        pairs = [p for p in mech.pairs if k in p.links]
        if any(p.kind == "R" and 0 in p.links for p in pairs):
            continue
        joints = []
        for p in pairs:
            n = _name_of(mech, p.point) if (p.kind == "R" or p.links[1] == k) else f"{p.point.lower()}{k}"
            if n and n in names and n not in joints:
                joints.append(n)
        if len(joints) > 1:
            out.append((k, joints))
    return out


def _rel(a: str, b: str, value, unit: str) -> Segment:
    """A relative vector a-b: a component of its plan's vector sums."""
    return Segment(f"{a}-{b}", a, b, np.asarray(value, dtype=float), unit, role="component")


def _absolute(mech, pts: dict[str, _Point], n: str, pole: str, value, unit: str) -> Segment:
    """The absolute vector pole-n of point n: given on the driving link (known from its motion),
    else a result the plan is drawn to find."""
    role = "given" if pts[n].link == mech.drive.link else "result"
    return Segment(f"{pole}-{n}", pole, n, np.asarray(value, dtype=float), unit, role=role)


def velocity_plan(mech, res, scales: dict[str, Scale]) -> PlanCycle:
    """The velocity plan (seed 002 fig. 1.7) at every angle of `res`: pole p, p-x for every
    point, the relative velocities of each floating link's joints (a-b), the sliding velocities
    of blocks on moving guides (a1-a3), like points by similarity (s2 on ab), and a triad's
    special point s (v_S from the outer pins of the two leashes through S, e.g. a-s, e-s): all at
    mu_v; the construction of each dyad's point (`_constructions`) and of a triad's through s
    (`_triad_lines`)."""
    mu = scales["mu_v"]
    pts = plan_point_names(mech, res)
    mo = _motion(res, pts)
    points = {"p": np.zeros(len(res.phi_deg), complex), **{n: m[1] / mu.value for n, m in mo.items()}}
    segs = [_absolute(mech, pts, n, "p", np.abs(m[1]), "m/s") for n, m in mo.items()]
    for _, joints in _floating_joints(mech, pts):
        segs += [_rel(a, b, np.abs(mo[b][1] - mo[a][1]), "m/s") for i, a in enumerate(joints) for b in joints[i + 1:]]
    for s in _slidings(mech, "p"):
        segs.append(_rel(s.start, s.end, np.abs(res.kin.v_slide[:, s.pair.index]), "m/s"))
    special = _special(mech, res, pts)
    for name, b, local, refs in special:        # v_S = v_1 + v_S1 = v_2 + v_S2
        vS = _point_motion(res.kin, b, local)[1]
        points[name] = vS / mu.value
        segs += [Segment(f"{r or 'p'}-{name}", r or "p", name, _where(on, np.abs(vS - (mo[r][1] if r else 0j))), "m/s",
                         role="component" if r else "result") for r, on in refs]
    triads = _triad_lines(mech, res, "p", special)
    _aliases(points, triads)
    lines, steps = _constructions(mech, segs, "p", triads)
    return PlanCycle("velocity", _titles("Velocity plan at phi = {at:g} deg", res), mu, res.phi_deg, points,
                     tuple(segs + lines), notes=_collapsed(mech, pts, segs, len(res.phi_deg)), steps=steps)


def _found(mech, g) -> str:
    """The plan name of the point a dyad's plan fixes: its inner joint (a block on a moving guide:
    the guide's point under it, seed 000's a3)."""
    p = g.pairs[1]
    return _name_of(mech, p.point) if p.kind == "R" else f"{p.point.lower()}{p.links[0]}"


def _component(name: str) -> bool:
    """Whether a plan point is the end of a component (n2, k: not a point of a link)."""
    return name[:1] in "nk" and name[1:].isdigit() or name == "k"


def _constructions(mech, segs: list[Segment], pole: str, triads=()) -> tuple[list[Segment], tuple]:
    """The construction of a velocity or an acceleration plan (seed 002 sec. 1.2.2) and its steps
    in the texts' order. Per dyad, the point q it fixes (`_found`) lies on two lines of known
    direction: those of the vectors drawn to q from known points (v_BA from a and v_B from p; a^t_BA
    from n2 and a_B from pi), less a whole relative vector split into components (a-b where
    a-n2-b is drawn) and, where three remain, the one from the pole; each line through its known
    point (`core.construction`), the one reached through more vectors first. The steps: per line
    the vectors that reach its known point from the pole or a point fixed already (components
    first: pi-a, a-n2), then the line; then the intersection.
    `triads`: per triad, its construction in each order of its sides (`_triad_lines`): (angles
    (N,) bool, order, [(point, [(line, known point), (line, known point)]), ...]), each drawn at
    its angles (`core.construction`'s order); the steps then change with the angle (N tuples).
    A dyad whose q is not fixed so has no construction drawn."""
    vectors = [s for s in segs if s.kind == "vector"]
    out: list[Segment] = []
    steps: list[str] = []

    def chain(x: str, fixed: set[str], pool: list[Segment]) -> list[str]:
        """The vectors of `pool` from the pole or a point fixed already to x, in the order drawn
        (components first: pi-a, a-n2)."""
        into = [s for s in pool if s.end == x and s.start != x]
        if x in fixed or not into:
            return []
        s = next((s for s in into if _component(s.start)), into[0])
        return [*chain(s.start, fixed, pool), s.name]

    def made(q: str, lines: list[tuple[str, str]], fixed: set[str], order: str = "", pool=vectors) -> list[str]:
        """The construction of q (`core.construction`), through the known link first, added to
        `out`; its steps (the vectors of `pool`: those drawn in its order); q and the known
        points added to `fixed`."""
        lines = sorted(lines, key=lambda x: (-len(chain(x[1], fixed, pool)), x[1] == pole))
        drawn = construction(q, lines, order)
        out.extend(drawn)
        own: list[str] = []
        for (_, known), line in zip(lines, drawn):
            path = chain(known, fixed, pool)
            own += [n for n in path if n not in own] + [line.name]
            fixed |= {x for v in pool if v.name in path for x in (v.start, v.end)}
        fixed |= {q, *(known for _, known in lines)}
        return own + [drawn[-1].name]

    fixed = {pole}
    for g in mech.structure.groups:
        if g.klass == 3:
            continue
        q = _found(mech, g)
        into = [s for s in vectors if s.end == q and s.start != q]
        starts = {s.start for s in into}
        into = [s for s in into if not any(t.start == s.start and t.end in starts and _component(t.end) for t in vectors)]
        if len(into) > 2:
            into = [s for s in into if s.start != pole]
        if len(into) != 2:
            continue
        steps += [n for n in made(q, [(s.name, s.start) for s in into], fixed) if n not in steps]
    if not triads:
        return out, tuple(steps)
    n = len(triads[0][0][0])
    at = [list(steps) for _ in range(n)]
    for orders in triads:
        for where, order, points in orders:
            own: list[str] = []
            known = set(fixed)
            pool = [v for v in vectors if np.isfinite(np.broadcast_to(np.asarray(v.value, float), where.shape)[where]).any()]
            for q, lines in points:
                own += made(q, lines, known, order, pool)
            for i in np.flatnonzero(where):
                at[i] += own
    return out, tuple(tuple(x) for x in at) if len({tuple(x) for x in at}) > 1 else tuple(at[0])


def _triad_lines(mech, res, pole: str, special: list) -> list:
    """Per triad (Artobolevsky 1988, the class-III group: "the special point S of Assur, where the
    axes of two leashes meet, taken as a point of the base link"), its velocity plan's
    construction in each order of its sides over the angles of `res` (`kinematics.special_index`
    k: S on the axes of sides k+1 and k+2): (angles (N,) bool, the order's tag, [(point fixed,
    [(line, known point), (line, known point)]) in the order drawn]): s on the lines of v_S - v_O
    through the outer pins o of the two leashes through S (square to a two-pin leash's axis, along
    a slider's guide or a rocking block's arm: the vectors o-s); the third leash's inner point q3
    on the line of v_Q3 - v_S through s (square to S Q3) and of the leash's own vector o-q3; the
    other two inner points each on the line of its velocity relative to q3 (square to Q3 Q) and of
    its leash's vector (a line through s would run parallel to it). A triad whose leash's outer
    prismatic pair is on a moving link, or whose inner one has its guide on the leash, is left
    out (the lines above are not then of known direction through a point on the plan)."""
    from ..kinematics import special_index
    triads = [g for g in mech.structure.groups if g.klass == 3]
    out = []
    for g, (s_name, _, _, _) in zip(triads, special):
        ends = []
        for ell, o, i, _ in g.sides:
            if (o.kind == "P" and 0 not in o.links) or (i.kind == "P" and i.links[0] != g.links[0]):
                break
            outer = (_name_of(mech, o.point) if o.kind == "R" else "") or pole
            inner = _name_of(mech, i.point) if i.kind == "R" else f"{i.point.lower()}{i.links[0]}"
            ends.append((outer, inner))
        else:
            k = special_index(mech, res.kin, g)
            orders = []
            for x in sorted(set(k[_ok(res)].tolist())):
                (o1, q1), (o2, q2), (o3, q3) = (ends[(x + j) % 3] for j in (1, 2, 0))
                orders.append((_ok(res) & (k == x), str(x + 1), [
                    (s_name, [(f"{o1}-{s_name}", o1), (f"{o2}-{s_name}", o2)]),
                    (q3, [(f"{s_name}-{q3}", s_name), (f"{o3}-{q3}", o3)]),
                    (q1, [(f"{q3}-{q1}", q3), (f"{o1}-{q1}", o1)]),
                    (q2, [(f"{q3}-{q2}", q3), (f"{o2}-{q2}", o2)])]))
            out.append(orders)
    return out


def _aliases(points: dict, triads: list) -> None:
    """Each triad construction's points in its order (`core.alias`): the point at its angles, NaN
    at the others."""
    for orders in triads:
        for where, order, fixed in orders:
            for q, _ in fixed:
                points[alias(q, order)] = np.where(where, points[q], np.nan)


def _collapsed(mech, pts: dict[str, _Point], segs: list[Segment], n: int) -> tuple[tuple[str, ...], ...]:
    """Each of n angles' notes naming the special position where a side of a velocity or an
    acceleration plan collapses to a point (its value zero, `zero.zero_of`, against the plan's
    largest there): 'special position: p-b = 0, the plan collapses there' (b on the pole). A
    side between two points of a link that translates (`zero.translates`) is zero at every
    angle: no special position."""
    still = {n for n, q in pts.items() if translates(mech, q.link)}
    segs = [s for s in segs if not (s.start in still and s.end in still)]
    if not segs:
        return ((),) * n
    vals = np.stack([np.broadcast_to(np.asarray(s.value, dtype=float), (n,)) for s in segs])
    with np.errstate(invalid="ignore"):
        ref = np.max(np.where(np.isfinite(vals), vals, 0.0), axis=0)
        zero = zero_of(vals, ref) & (ref > 0)
    return tuple(by_pattern(zero, lambda row: tuple(f"special position: {s.name} = 0, the plan collapses there"
                                                     for s, z in zip(segs, row) if z)))


def _special(mech, res, pts: dict) -> list[tuple[str, int, np.ndarray, list[tuple[str, np.ndarray | None]]]]:
    """Per triad: the plan name of Assur's special point S (a point of the base link), the base,
    S's local coordinates on it (N,), and the references of the leashes through S: (the plan name
    of the leash's outer pin, "" for a point of the frame at the pole; the angles (N,) bool where
    its axis passes through S, None: at every angle; its segment NaN, not drawn, at the others).
    S lies on two of the three leashes' axes
    (`kinematics.special_sides`), which two may change over the cycle; the references are in the
    solver's order at the first angle."""
    from ..kinematics import special_index, special_point_z
    out = []
    for n, g in enumerate(g for g in mech.structure.groups if g.klass == 3):
        name = "s" if n == 0 else f"s{n + 1}'"
        name = name if name not in pts else f"{name}'"
        b = g.links[0]
        S, k = special_point_z(mech, res.kin, g), special_index(mech, res.kin, g)
        local = (S - res.kin.origin_z[:, b]) / res.kin.rot[:, b]
        first = int(k[0]) % 3
        refs = []
        for j in ((first + 1) % 3, (first + 2) % 3, first):        # the sides in the solver's order
            on = (k != j) | ~_ok(res)
            if j == first and not np.any(on & _ok(res)):
                continue
            _, o, _, _ = g.sides[j]
            refs.append((_name_of(mech, o.point) if o.kind == "R" else "", None if on.all() else on))
        out.append((name, b, local, refs))
    return out


def _normals(mech, g):
    """(link, reference point, point) whose relative acceleration the group's plan splits into
    normal and tangential parts, by the group's kind (a triad: each two-pin leash)."""
    if g.klass == 3:
        return [(ell, o.point, i.point) for ell, o, i, _ in g.sides if o.kind == i.kind == "R"]
    p0, p1, p2 = g.pairs
    j, k = g.links
    if g.kind == "RRR":
        return [(j, p0.point, p1.point), (k, p2.point, p1.point)]
    if g.kind == "RRP":
        return [(j, p0.point, p1.point)]
    if g.kind == "RPR":      # the guide link k turns about its outer pin: its point under the block
        guide = p1.links[0]
        return [(guide, p2.point if guide == k else p0.point, f"{p1.point.lower()}{guide}")]
    return []                # PRP, RPP: no link of the group turns about a pin of its own


def acceleration_plan(mech, res, scales: dict[str, Scale]) -> PlanCycle:
    """The acceleration plan (seed 002 fig. 1.8, seed 000 sec. 6.3) at every angle of `res`: pole
    pi; the crank pin (normal and tangential parts at the angles where the crank accelerates); per
    group the normal `r-n<k>` and tangential `n<k>-q` parts of each turning link, the Coriolis
    `-k` and relative `k-` parts of a block on a moving guide at the angles where the guide turns
    (where it stands still: the relative part alone, NaN, not drawn, elsewhere); pi-x for every
    point, the relative accelerations of each floating link's joints (a-b), like points by
    similarity, and a triad's special point s from the outer pins of the two leashes through S
    (e.g. a-s): all at mu_a; the construction of each dyad's point (`_constructions`) and of a
    triad's through s, with the base link's normal parts it needs (`_triad_normals`)."""
    mu = scales["mu_a"]
    pts = plan_point_names(mech, res)
    mo = _motion(res, pts)
    points = {"pi": np.zeros(len(res.phi_deg), complex), **{n: m[2] / mu.value for n, m in mo.items()}}
    segs: list[Segment] = []
    unit = "m/s^2"

    def split(k: int, ref_point: str, q: str, where: np.ndarray | None = None) -> None:
        """The normal and tangential parts of q relative to the reference point (at the angles
        `where` only: NaN, not drawn, at the others)."""
        ref = _name_of(mech, ref_point) if ref_point in mech.point_names else ref_point
        start = ref or "pi"
        r_ref, a_ref = (mo[ref][0], mo[ref][2]) if ref else (complex(*mech.links[0].points[ref_point]), 0j)
        w, e = res.kin.omega[:, k], res.kin.eps[:, k]
        l = np.abs(mo[q][0] - r_ref)
        n = f"n{k}"
        points[n] = (a_ref - w * w * (mo[q][0] - r_ref)) / mu.value
        if where is not None:
            points[n] = np.where(where, points[n], np.nan)
        segs.extend([_rel(start, n, w * w * l, unit), _rel(n, q, np.abs(e) * l, unit)])

    d = mech.drive
    eps = res.kin.eps[:, d.link]
    if _any(eps, res):                  # the crank pin's parts where the crank accelerates
        split(d.link, d.pivot, _name_of(mech, d.point), eps != 0)
    for g in mech.structure.groups:
        for k, ref_point, q in _normals(mech, g):
            split(k, ref_point, q if q in pts else _name_of(mech, q))
    slidings = _slidings(mech, "pi")
    turning = [s for s in slidings if _any(res.kin.omega[:, s.pair.links[0]], res)]
    for s in slidings:
        p = s.pair
        guide = p.links[0]
        w = res.kin.omega[:, guide]
        v_r, a_r = res.kin.v_slide[:, p.index], res.kin.a_slide[:, p.index]
        if s in turning:                 # where the guide stands still: no Coriolis part, k not drawn
            dw = complex(*p.direction) * res.kin.rot[:, guide]
            cor = 2j * w * v_r * dw                      # slider's acceleration = guide point's + cor + a_r d
            kname = "k" if len(turning) == 1 else f"k{turning.index(s) + 1}"
            points[kname] = np.where(w != 0, points[s.start] + (cor if s.from_guide else -cor) / mu.value, np.nan)
            segs += [_rel(s.start, kname, 2 * np.abs(w * v_r), unit), _rel(kname, s.end, np.abs(a_r), unit)]
            if not np.all(w != 0):
                segs.append(_rel(s.start, s.end, _where(w == 0, np.abs(a_r)), unit))
        else:
            segs.append(_rel(s.start, s.end, np.abs(a_r), unit))
    segs += [_absolute(mech, pts, n, "pi", np.abs(m[2]), unit) for n, m in mo.items()]
    special = _special(mech, res, pts)
    for name, b, local, refs in special:        # a_S = a_1 + a_S1 = a_2 + a_S2
        aS = _point_motion(res.kin, b, local)[2]
        points[name] = aS / mu.value
        segs.append(Segment(f"pi-{name}", "pi", name, np.abs(aS), unit, role="result"))
        segs += [_rel(r, name, _where(on, np.abs(aS - mo[r][2])), unit) for r, on in refs if r]
    for _, joints in _floating_joints(mech, pts):
        segs += [_rel(a, b, np.abs(mo[b][2] - mo[a][2]), unit) for i, a in enumerate(joints) for b in joints[i + 1:]]
    notes = _collapsed(mech, pts, segs, len(res.phi_deg))
    triads = _triad_normals(mech, res, mo, special, points, segs, mu.value)
    _aliases(points, triads)
    lines, steps = _constructions(mech, segs, "pi", triads)
    return PlanCycle("acceleration", _titles("Acceleration plan at phi = {at:g} deg", res), mu, res.phi_deg,
                     points, tuple(segs + lines), notes=notes, steps=steps)


def _triad_normals(mech, res, mo: dict, special: list, points: dict, segs: list[Segment], mu: float) -> list:
    """Per triad whose leashes each turn about two pins or slide in a guide of the frame, its
    acceleration plan's construction in each order of its sides (as `_triad_lines`; Artobolevsky
    1988, the class-III group): S, a point of the base link b on the axis of leash l (outer pin O,
    inner Q), has a_S = a_O + a^n_QO + a^n_SQ + a^t, the tangential parts a^t_QO and a^t_SQ both
    square to the axis (a slider's: a_S = a^n_SQ + a part along its guide); so s lies on the line
    of that direction through the end of the normal parts drawn from the outer pin's point (a-n2,
    then n2-n31: omega_b^2 QS, along S -> Q), for each of the two leashes through S. The third
    leash's inner point Q3 on the line square to S Q3 through the end of its normal part relative
    to s and on its leash's (through n5 square to F D; a slider's: through pi along the guide);
    the other two inner points each on the line square to Q3 Q through the end of its normal part
    relative to Q3 and on its leash's. The base link's normal parts n<b>1, n<b>2, ... (in the
    order drawn) are added to `points` and `segs` at the angles of their order (NaN, not drawn,
    at the others). A triad with a leash on an inner prismatic pair (a rocking block: its point
    under the block is known only through the Coriolis part, drawn from the guide), or on a
    prismatic pair to a moving link, is left out."""
    from ..kinematics import special_index
    triads = [g for g in mech.structure.groups if g.klass == 3]
    out = []
    for g, (s_name, base, local, _) in zip(triads, special):
        if any(i.kind == "P" or (o.kind == "P" and 0 not in o.links) for _, o, i, _ in g.sides):
            continue
        w2 = res.kin.omega[:, base] ** 2
        world = {s_name: _point_motion(res.kin, base, local)[0]}
        leash = []
        for ell, o, i, _ in g.sides:               # (inner point, the end of its leash's known parts)
            q = _name_of(mech, i.point)
            world[q] = mo[q][0]
            leash.append((q, f"n{ell}" if o.kind == "R" else "pi"))
        k = special_index(mech, res.kin, g)
        orders = []
        for x in sorted(set(k[_ok(res)].tolist())):
            where = _ok(res) & (k == x)
            made: list[str] = []

            def normal(start: str, rel: str, to: str) -> str:
                """The base link's normal part of `to` relative to `rel` drawn from `start`: its end."""
                name = f"n{base}{len(made) + 1}"
                made.append(name)
                an = -w2 * (world[to] - world[rel])
                points[name] = np.where(where, points[start] + an / mu, points.get(name, np.full(len(where), np.nan + 0j)))
                segs.append(_rel(start, name, _where(where, np.abs(an)), "m/s^2"))
                return name

            (q1, k1), (q2, k2), (q3, k3) = (leash[(x + j) % 3] for j in (1, 2, 0))
            m1, m2 = normal(k1, q1, s_name), normal(k2, q2, s_name)
            m3 = normal(s_name, s_name, q3)
            fixed = [(s_name, [(f"{m1}-{s_name}", m1), (f"{m2}-{s_name}", m2)]),
                     (q3, [(f"{m3}-{q3}", m3), (f"{k3}-{q3}", k3)])]
            for q, kq in ((q1, k1), (q2, k2)):
                m = normal(q3, q3, q)
                fixed.append((q, [(f"{m}-{q}", m), (f"{kq}-{q}", kq)]))
            orders.append((where, str(x + 1), fixed))
        out.append(orders)
    return out


# ----------------------------------------------------------------------------- plan of positions

def _dead_centre_functions(mech):
    """For each group whose driving link turns about a frame pin: f(res) -> (N,) whose roots
    are the group's dead centres, and a mask of the roots that count. Crank and rod (the link
    jointed at the pin) in line, extended (seed 002's starting position); a block on the pin
    sliding in a slotted link: the crank square to the slot (the slotted link's extreme)."""
    frame_pins = {p.links[1] if p.links[0] == 0 else p.links[0]: p.point
                  for p in mech.pairs if p.kind == "R" and 0 in p.links}
    out = []
    for g in mech.structure.groups:
        if g.klass == 3:            # a triad's leash: no dead centre of the texts' starting position
            continue
        drv = g.known[0]
        p0, p1, _ = g.pairs
        if drv not in frame_pins or p0.kind != "R":
            continue
        pivot = frame_pins[drv]

        def crank(res, pivot=pivot, j=p0.point):
            return _z(res, j) - _z(res, pivot)

        if p1.kind == "R":
            def f(res, crank=crank, j=p0.point, x=p1.point):
                c, r = crank(res), _z(res, x) - _z(res, j)
                return (c.conjugate() * r).imag, (c.conjugate() * r).real > 0
        else:
            def f(res, crank=crank, p=p1):
                d = complex(*p.direction) * res.kin.rot[:, p.links[0]]
                return (crank(res).conjugate() * d).real, np.ones(len(res.phi_deg), bool)
        out.append(f)
    return out


def _z(res, name: str) -> np.ndarray:
    xy = res.position(name)
    return xy[:, 0] + 1j * xy[:, 1]


def starting_position(mech, solution: Solution | None = None) -> float:
    """The texts' starting position (seed 002: crank and rod stretched in one line), crank angle
    in deg in [0, 360): the first dead centre of the first group driven by a link turning about
    a frame pin that has one (module docstring of `_dead_centre_functions`), found by a scan of
    the CYCLE_STEPS angles of the cycle grid of `solution` (`solution.solve`; default: solved
    here), then its bracket cut in SECTIONS + 1 parts by one solve of the positions a round
    (`solution.positions`), to the resolution of a float (~1e-14 deg). 0 (the model's reference)
    when there is none."""
    steps = CYCLE_STEPS
    phi = grid(steps)
    cyc = (solution or solve(mech, other=False)).on(phi)
    for f in _dead_centre_functions(mech):
        val, ok = f(cyc)
        nxt = np.roll(val, -1)
        hits = np.flatnonzero(ok & np.isfinite(val) & ((val == 0) | (np.sign(val) * np.sign(nxt) < 0)))
        if not len(hits):
            continue
        i = hits[0]
        if val[i] == 0:
            return float(phi[i])
        lo, hi, flo = phi[i], phi[i] + 360.0 / steps, val[i]
        for _ in range(16):                 # each round: SECTIONS angles in one analysis
            inner = np.unique(lo + (hi - lo) * np.arange(1, SECTIONS + 1) / (SECTIONS + 1))
            inner = inner[(inner > lo) & (inner < hi)]
            if not len(inner):
                break
            fm = f(positions(mech, inner))[0]
            if np.any(fm == 0):
                return float(inner[np.argmax(fm == 0)] % 360.0)
            changed = np.flatnonzero(np.sign(fm) != np.sign(flo))
            j = int(changed[0]) if len(changed) else len(inner)
            lo, flo = (inner[j - 1], fm[j - 1]) if j else (lo, flo)
            hi = inner[j] if j < len(inner) else hi
        return float(0.5 * (lo + hi) % 360.0)
    return 0.0


def _position_names(mech) -> tuple[dict[str, int], callable]:
    """Moving points (name -> owner) and the rule naming them at position i."""
    frame = mech.links[0].points
    moving = {}
    for link in mech.links[1:]:
        for n in link.points:
            if n not in frame and n not in moving:
                moving[n] = link.id
    plain = {f"{n}{i}" for n in moving if not n[-1].isdigit() for i in range(N_POSITIONS)}
    sep_all = bool(plain & set(mech.point_names))

    def name(n: str, i: int | None) -> str:
        if i is None or n in frame:
            return n
        return f"{n}_{i}" if (sep_all or n[-1].isdigit()) else f"{n}{i}"
    return moving, name


def _outline(mech, k: int) -> list[str]:
    """The model points a link is drawn through: its pins, and for a guide the slot up to the
    block (the guide point and the block's point); a link with one pin through its other points."""
    pts: list[str] = []
    for p in mech.pairs:
        if k not in p.links:
            continue
        for n in ([p.point] if p.kind == "R" else ([p.guide, p.point] if p.links[0] == k else [p.point])):
            if n not in pts:
                pts.append(n)
    if len(pts) == 1:           # a block or a ram: drawn through its other points (tool, centre of mass)
        pts += [n for n in mech.links[k].points if n not in pts]
    return pts


def _draw_position(mech, res, idx, label: int | None, mu: float, points: dict, segs: list) -> None:
    """Points and links of the mechanism at res's angle number idx (an int; a slice: the (N,)
    angles it takes), named for position `label`."""
    moving, name = _position_names(mech)
    for n, xy in mech.links[0].points.items():
        points[n] = complex(*xy) / mu
    for n in moving:
        points[name(n, label)] = _z(res, n)[idx] / mu
    for link in mech.links[1:]:
        outline = _outline(mech, link.id)
        for i, a in enumerate(outline):
            for b in outline[i + 1:]:
                za, zb = points[name(a, label)], points[name(b, label)]
                segs.append(Segment(f"{name(a, label)}-{name(b, label)}", name(a, label), name(b, label),
                                    np.abs(zb - za) * mu, "m", "link" if label is None else "position"))


def assembled(mech, phi_deg) -> tuple[Positions | None, np.ndarray]:
    """(the positions of `mech` at the angles `phi_deg` where it assembles (`solution.positions`),
    those angles (N,) bool): one solve, and one more without the angles an AssemblyError named;
    (None, all False) where it does not assemble at the rest either (or the model is refused: a ValueError)."""
    from ..errors import AssemblyError
    phi = np.asarray(phi_deg, float)
    where = np.ones(len(phi), bool)
    for _ in range(2):
        try:
            return positions(mech, phi[where]), where
        except AssemblyError as exc:
            where = where & ~np.isin(np.round(phi, 9), exc.phi_deg)
            if not where.any():
                break
        except (ValueError, KeyError):
            break
    return None, np.zeros(len(phi), bool)


def other_branches(mech, res) -> dict:
    """Per group with two assembly branches (`mech.branches`): (the analysis of the mechanism with
    that group's other branch at the angles of `res` where it assembles, those angles (N,) bool),
    positions only, one solve for all of them (`assembled`); left out where it assembles at none."""
    out = {}
    for key, b in mech.branches.items():
        alt, where = assembled(replace(mech, branches={**mech.branches, key: -b}), res.phi_deg)
        if alt is not None:
            out[key] = (alt, where)
    return out


def _branch_marks(mech, res, mu: float, points: dict, segs: list, dashed=True) -> list[list[str]]:
    """Mark each group's assembly branch at every angle of `res`: a note per angle, and the other
    branch's inner joint drawn dashed (primed name) where it lies elsewhere (NaN at the angles
    where it does not; with `dashed` False, (N,) bool False at an angle, only noted there: it runs
    off the sheet). The other branch is analysed once for all angles (`other_branches`)."""
    from ..kinematics import assembly_modes
    n_at = len(res.phi_deg)
    dashed = np.broadcast_to(np.asarray(dashed, bool), (n_at,))
    notes: list[list[str]] = [[] for _ in range(n_at)]
    alts = other_branches(mech, res) if mech.branches else {}
    for g in mech.structure.groups:
        key = frozenset(g.links)
        if g.klass == 3:
            count = next(len(am.O) for am in assembly_modes(mech) if am.group == g.label)
            for lines in notes:
                lines.append(f"{g.label} III3: the mode the model draws at the design position ({count} modes there)")
            continue
        if key not in mech.branches:
            for lines in notes:
                lines.append(f"{g.label} {g.kind}: one assembly")
            continue
        b = mech.branches[key]
        q = g.pairs[1].point
        text = f"{g.label} {g.kind}: branch {b:+d} drawn"
        zq = np.full(n_at, np.nan + 0j)
        assembles = np.zeros(n_at, bool)
        if key in alts:
            alt, assembles = alts[key]
            zq[assembles] = _z(alt, q)
        here = _z(res, q)
        same = ~(np.isfinite(zq) & (np.abs(zq - here) > 1e-9 * mech.size))
        drawn = assembles & ~same & dashed
        qp = f"{q}'"
        for i, lines in enumerate(notes):
            lines.append(text + (" (the other branch does not assemble here)" if not assembles[i] else
                                 " (the other branch looks the same here)" if same[i] else
                                 f" (the other branch {qp} off the sheet at this scale)" if not dashed[i] else
                                 f"; dashed to {qp}: the other branch"))
        if not drawn.any():
            continue
        points[qp] = np.where(drawn, zq / mu, np.nan)
        for p in (g.pairs[0], g.pairs[2]):
            n = p.point if p.kind == "R" else None
            if n is not None:
                segs.append(Segment(f"{n}-{qp}", n, qp, np.full(n_at, np.nan), "", "line"))
    return notes


@dataclass(frozen=True)
class FixedPositions:
    """The part of `mech`'s plan of positions at scale `mu` that no design position moves
    (`fixed_positions`): the 12 positions from `start` (deg), their points (plan units, mm) and
    segments, and the path of every centre of mass."""
    mech: object
    mu: Scale
    start: float
    points: Mapping[str, complex]
    segments: tuple[Segment, ...]
    paths: Mapping[str, tuple[complex, ...]]


def fixed_positions(mech, mu: Scale, starting_deg: float | None = None,
                    solution: Solution | None = None) -> FixedPositions:
    """The 12 positions every 30 deg in the drive's sense from the starting position (found by
    `starting_position` unless given; their positions alone, `solution.positions`) and the paths
    of the centres of mass (PATH_STEPS angles of the cycle grid of `solution`, `solution.solve`;
    default: solved here), at `mu`: made once for the plans of many angles (`positions_plan`'s `fixed`)."""
    if starting_deg is not None and not math.isfinite(float(starting_deg)):
        raise ValueError(f"starting position: expected a finite angle in degrees, got {starting_deg!r}")
    solution = solution or solve(mech, other=False)
    start = starting_position(mech, solution) if starting_deg is None else float(starting_deg)
    twelve = positions(mech, start + 30.0 * np.arange(N_POSITIONS))
    points: dict[str, complex] = {}
    segs: list[Segment] = []
    for i in range(N_POSITIONS):
        _draw_position(mech, twelve, i, i, mu.value, points, segs)
    cycle = solution.on(np.arange(PATH_STEPS + 1) * 360.0 / PATH_STEPS)
    paths = {link.com: tuple(_z(cycle, link.com) / mu.value) for link in mech.links[1:]
             if link.com and link.com not in mech.links[0].points}
    return FixedPositions(mech, mu, start, MappingProxyType(points), tuple(segs), MappingProxyType(paths))


def positions_plan(mech, res, scales: dict[str, Scale], starting_deg: float | None = None,
                   other_branch: bool | np.ndarray = True, fixed: FixedPositions | None = None,
                   solution: Solution | None = None) -> PlanCycle:
    """The plan of positions (seed 002 fig. 1.5) at every angle of `res`: 12 positions every 30 deg
    in the drive's sense from the starting position (found by `starting_position` unless given),
    the design position at each angle of `res` (plain names), the paths of every centre of mass
    and the assembly branch of each group (notes; the other branch dashed, except where
    `other_branch` (a bool, or (N,) bool per angle) is False): all at mu_l. Link segments' values
    are the exact distances between their points, m. `fixed`: the 12 positions and the paths made
    already (`fixed_positions` of this `mech` at mu_l, from `starting_deg` where it is given; else
    made from `solution`)."""
    mu = scales["mu_l"]
    if fixed is None:
        fixed = fixed_positions(mech, mu, starting_deg, solution)
    elif fixed.mech is not mech or fixed.mu != mu:
        raise ValueError(f"fixed: the positions of {fixed.mech.name} at {fixed.mu}, not of {mech.name} at {mu}")
    elif starting_deg is not None and float(starting_deg) != fixed.start:
        raise ValueError(f"fixed: positions from {fixed.start:g} deg, not from starting_deg = {starting_deg:g} deg")
    points = dict(fixed.points)
    segs = list(fixed.segments)
    _draw_position(mech, res, slice(None), None, mu.value, points, segs)
    marks = _branch_marks(mech, res, mu.value, points, segs, other_branch)
    notes = [(f"position 0 at phi = {fixed.start:.6g} deg (crank and rod in line), then every 30 deg; "
              f"design position phi = {float(at):g} deg drawn with plain letters", *m) for at, m in zip(res.phi_deg, marks)]
    return PlanCycle("positions", _titles("Plan of positions, design position phi = {at:g} deg", res), mu,
                     res.phi_deg, points, tuple(segs), fixed.paths, tuple(notes))
