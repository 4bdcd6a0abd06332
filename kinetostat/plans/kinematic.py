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

May use: numpy, `kinetostat.solve` (the exact results: never re-solved here), `.core`.
"""
from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, replace
from types import MappingProxyType
from typing import NamedTuple

import numpy as np

from .core import Plan, Scale, Segment

__all__ = ["positions_plan", "fixed_positions", "FixedPositions", "velocity_plan", "acceleration_plan", "starting_position", "plan_point_names",
           "N_POSITIONS", "PATH_STEPS"]

#: Positions of the plan of positions: every 30 deg.
N_POSITIONS = 12
#: Crank angles sampled for the path of a centre of mass.
PATH_STEPS = 180


def _at(res) -> float:
    if len(res.phi_deg) != 1:
        raise ValueError(f"a plan is drawn at one crank angle; the analysis holds {len(res.phi_deg)}")
    if res.singular[0]:
        raise ValueError(f"the mechanism is at a singular position at {res.phi_deg[0]:g} deg "
                         f"(velocities and accelerations undefined); draw the plans at another angle")
    return float(res.phi_deg[0])


# ----------------------------------------------------------------------------- points of the plans

class _Point(NamedTuple):
    link: int
    local: complex      # local coordinates on `link`, m


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
    the coincident points of a guide, which move along it."""
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
            X = complex(*res.position(p.point)[0])
            out[f"{p.point.lower()}{g}"] = _Point(g, (X - res.kin.origin_z[0, g]) / res.kin.rot[0, g])
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


def _motion(res, pts: dict[str, _Point]):
    """name -> (position, velocity, acceleration) complex at the analysis's one angle."""
    return {n: tuple(complex(z[0]) for z in res.kin.point_z(p.link, (p.local.real, p.local.imag)))
            for n, p in pts.items()}


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


def _rel(a: str, b: str, value: float, unit: str) -> Segment:
    return Segment(f"{a}-{b}", a, b, float(value), unit)


def velocity_plan(mech, res, scales: dict[str, Scale]) -> Plan:
    """The velocity plan (seed 002 fig. 1.7): pole p, p-x for every point, the relative
    velocities of each floating link's joints (a-b), the sliding velocities of blocks on moving
    guides (a1-a3), like points by similarity (s2 on ab), and a triad's special point s (v_S
    from the outer pins of the two leashes through S, e.g. a-s, e-s): all at mu_v."""
    at = _at(res)
    mu = scales["mu_v"]
    pts = plan_point_names(mech, res)
    mo = _motion(res, pts)
    points = {"p": 0j, **{n: m[1] / mu.value for n, m in mo.items()}}
    segs = [Segment(f"p-{n}", "p", n, abs(m[1]), "m/s") for n, m in mo.items()]
    for _, joints in _floating_joints(mech, pts):
        segs += [_rel(a, b, abs(mo[b][1] - mo[a][1]), "m/s") for i, a in enumerate(joints) for b in joints[i + 1:]]
    for s in _slidings(mech, "p"):
        segs.append(_rel(s.start, s.end, abs(res.kin.v_slide[0, s.pair.index]), "m/s"))
    for name, b, local, refs in _special(mech, res, pts):        # v_S = v_1 + v_S1 = v_2 + v_S2
        vS = complex(res.kin.point_z(b, (local.real, local.imag))[1][0])
        points[name] = vS / mu.value
        segs += [Segment(f"{r or 'p'}-{name}", r or "p", name, abs(vS - (mo[r][1] if r else 0j)), "m/s") for r in refs]
    return Plan("velocity", f"Velocity plan at phi = {at:g} deg", mu, at, points, tuple(segs))


def _special(mech, res, pts: dict) -> list[tuple[str, int, complex, list[str]]]:
    """Per triad: the plan name of Assur's special point S (a point of the base link), the base,
    S's local coordinates on it, and the plan names of the references of the two leashes through
    S (their outer pins; "" for a point of the frame, at the pole)."""
    from ..kinematics import special_point_z, special_sides
    out = []
    for n, g in enumerate(g for g in mech.structure.groups if g.klass == 3):
        name = "s" if n == 0 else f"s{n + 1}'"
        name = name if name not in pts else f"{name}'"
        b = g.links[0]
        S = complex(special_point_z(mech, res.kin, g)[0])
        local = (S - res.kin.origin_z[0, b]) / res.kin.rot[0, b]
        refs = [_name_of(mech, o.point) if o.kind == "R" else "" for _, o, _, _ in special_sides(mech, res.kin, g)[:2]]
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


def acceleration_plan(mech, res, scales: dict[str, Scale]) -> Plan:
    """The acceleration plan (seed 002 fig. 1.8, seed 000 sec. 6.3): pole pi; the crank pin
    (normal and tangential parts when the crank accelerates); per group the normal `r-n<k>` and
    tangential `n<k>-q` parts of each turning link, the Coriolis `-k` and relative `k-` parts of
    a block on a moving guide; pi-x for every point, the relative accelerations of each floating
    link's joints (a-b), like points by similarity, and a triad's special point s with its
    construction from the outer pins of the two leashes through S (e.g. a-s): all at mu_a."""
    at = _at(res)
    mu = scales["mu_a"]
    pts = plan_point_names(mech, res)
    mo = _motion(res, pts)
    points = {"pi": 0j, **{n: m[2] / mu.value for n, m in mo.items()}}
    segs: list[Segment] = []
    unit = "m/s^2"

    def split(k: int, ref_point: str, q: str) -> None:
        ref = _name_of(mech, ref_point) if ref_point in mech.point_names else ref_point
        start = ref or "pi"
        r_ref, a_ref = (mo[ref][0], mo[ref][2]) if ref else (complex(*mech.links[0].points[ref_point]), 0j)
        w, e = res.kin.omega[0, k], res.kin.eps[0, k]
        l = abs(mo[q][0] - r_ref)
        n = f"n{k}"
        points[n] = (a_ref - w * w * (mo[q][0] - r_ref)) / mu.value
        segs.extend([Segment(f"{start}-{n}", start, n, float(w * w * l), unit), Segment(f"{n}-{q}", n, q, float(abs(e) * l), unit)])

    d = mech.drive
    if res.kin.eps[0, d.link] != 0:
        split(d.link, d.pivot, _name_of(mech, d.point))
    for g in mech.structure.groups:
        for k, ref_point, q in _normals(mech, g):
            split(k, ref_point, q if q in pts else _name_of(mech, q))
    slidings = _slidings(mech, "pi")
    turning = [s for s in slidings if res.kin.omega[0, s.pair.links[0]] != 0]
    for s in slidings:
        p = s.pair
        guide = p.links[0]
        w = res.kin.omega[0, guide]
        v_r, a_r = res.kin.v_slide[0, p.index], res.kin.a_slide[0, p.index]
        if s in turning:
            dw = complex(*p.direction) * res.kin.rot[0, guide]
            cor = 2j * w * v_r * dw                      # slider's acceleration = guide point's + cor + a_r d
            kname = "k" if len(turning) == 1 else f"k{turning.index(s) + 1}"
            points[kname] = points[s.start] + (cor if s.from_guide else -cor) / mu.value
            segs += [Segment(f"{s.start}-{kname}", s.start, kname, float(2 * abs(w * v_r)), unit),
                     Segment(f"{kname}-{s.end}", kname, s.end, float(abs(a_r)), unit)]
        else:
            segs.append(_rel(s.start, s.end, abs(a_r), unit))
    segs += [Segment(f"pi-{n}", "pi", n, abs(m[2]), unit) for n, m in mo.items()]
    for name, b, local, refs in _special(mech, res, pts):        # a_S = a_1 + a_S1 = a_2 + a_S2
        aS = complex(res.kin.point_z(b, (local.real, local.imag))[2][0])
        points[name] = aS / mu.value
        segs.append(Segment(f"pi-{name}", "pi", name, abs(aS), unit))
        segs += [Segment(f"{r}-{name}", r, name, abs(aS - mo[r][2]), unit) for r in refs if r]
    for _, joints in _floating_joints(mech, pts):
        segs += [_rel(a, b, abs(mo[b][2] - mo[a][2]), unit) for i, a in enumerate(joints) for b in joints[i + 1:]]
    return Plan("acceleration", f"Acceleration plan at phi = {at:g} deg", mu, at, points, tuple(segs))


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


def starting_position(mech, steps: int = 720) -> float:
    """The texts' starting position (seed 002: crank and rod stretched in one line), crank angle
    in deg in [0, 360): the first dead centre of the first group driven by a link turning about
    a frame pin that has one (module docstring of `_dead_centre_functions`), found by a scan of
    `steps` angles and bisection to ~1e-13 deg. 0 (the model's reference) when there is none."""
    from ..solve import analyze
    phi = np.arange(steps) * 360.0 / steps
    cyc = analyze(mech, phi_deg=phi)
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
        for _ in range(60):
            mid = 0.5 * (lo + hi)
            fm = f(analyze(mech, phi_deg=[mid]))[0][0]
            if fm == 0 or mid in (lo, hi):
                break
            if np.sign(fm) == np.sign(flo):
                lo, flo = mid, fm
            else:
                hi = mid
        return float(mid % 360.0)
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


def _draw_position(mech, res, idx: int, label: int | None, mu: float, points: dict, segs: list) -> None:
    """Points and links of the mechanism at res's angle number idx, named for position `label`."""
    moving, name = _position_names(mech)
    for n, xy in mech.links[0].points.items():
        points[n] = complex(*xy) / mu
    for n in moving:
        points[name(n, label)] = complex(*res.position(n)[idx]) / mu
    for link in mech.links[1:]:
        outline = _outline(mech, link.id)
        for i, a in enumerate(outline):
            for b in outline[i + 1:]:
                za, zb = points[name(a, label)], points[name(b, label)]
                segs.append(Segment(f"{name(a, label)}-{name(b, label)}", name(a, label), name(b, label),
                                    abs(zb - za) * mu, "m", "link" if label is None else "position"))


def _branch_marks(mech, at: float, res, mu: float, points: dict, segs: list, dashed: bool = True) -> list[str]:
    """Mark each group's assembly branch: a note, and the other branch's inner joint drawn dashed
    (primed name) where it lies elsewhere (with `dashed` False only noted: it runs off the sheet)."""
    from ..solve import analyze
    from ..errors import AssemblyError
    notes = []
    for g in mech.structure.groups:
        key = frozenset(g.links)
        if g.klass == 3:
            from ..kinematics import assembly_modes
            count = next(len(am.O) for am in assembly_modes(mech) if am.group == g.label)
            notes.append(f"{g.label} III3: the mode the model draws at the design position ({count} modes there)")
            continue
        if key not in mech.branches:
            notes.append(f"{g.label} {g.kind}: one assembly")
            continue
        b = mech.branches[key]
        q = g.pairs[1].point
        text = f"{g.label} {g.kind}: branch {b:+d} drawn"
        try:
            alt = analyze(replace(mech, branches={**mech.branches, key: -b}), phi_deg=[at])
            zq = complex(*alt.position(q)[0])
        except (AssemblyError, ValueError, KeyError):
            notes.append(text + " (the other branch does not assemble here)")
            continue
        if not np.isfinite(zq) or abs(zq - complex(*res.position(q)[0])) <= 1e-9 * mech.size:
            notes.append(text + " (the other branch looks the same here)")
            continue
        qp = f"{q}'"
        if not dashed:
            notes.append(text + f" (the other branch {qp} off the sheet at this scale)")
            continue
        points[qp] = zq / mu
        for p in (g.pairs[0], g.pairs[2]):
            n = p.point if p.kind == "R" else None
            if n is not None:
                segs.append(Segment(f"{n}-{qp}", n, qp, float("nan"), "", "line"))
        notes.append(text + f"; dashed to {qp}: the other branch")
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


def fixed_positions(mech, mu: Scale, starting_deg: float | None = None) -> FixedPositions:
    """The 12 positions every 30 deg in the drive's sense from the starting position (found by
    `starting_position` unless given) and the paths of the centres of mass (PATH_STEPS angles), at
    `mu`: made once for the plans of many angles (`positions_plan`'s `fixed`)."""
    from ..solve import analyze
    start = starting_position(mech) if starting_deg is None else float(starting_deg)
    if not math.isfinite(start):
        raise ValueError(f"starting position: expected a finite angle in degrees, got {starting_deg!r}")
    twelve = analyze(mech, phi_deg=start + 30.0 * np.arange(N_POSITIONS))
    points: dict[str, complex] = {}
    segs: list[Segment] = []
    for i in range(N_POSITIONS):
        _draw_position(mech, twelve, i, i, mu.value, points, segs)
    cycle = analyze(mech, phi_deg=np.arange(PATH_STEPS + 1) * 360.0 / PATH_STEPS)
    paths = {link.com: tuple(_z(cycle, link.com) / mu.value) for link in mech.links[1:]
             if link.com and link.com not in mech.links[0].points}
    return FixedPositions(mech, mu, start, MappingProxyType(points), tuple(segs), MappingProxyType(paths))


def positions_plan(mech, res, scales: dict[str, Scale], starting_deg: float | None = None,
                   other_branch: bool = True, fixed: FixedPositions | None = None) -> Plan:
    """The plan of positions (seed 002 fig. 1.5): 12 positions every 30 deg in the drive's sense
    from the starting position (found by `starting_position` unless given), the design position
    of `res` (plain names), the paths of every centre of mass and the assembly branch of each
    group (notes; the other branch dashed, unless `other_branch` is False): all at mu_l. Link segments' values are the exact
    distances between their points, m. `fixed`: the 12 positions and the paths made already
    (`fixed_positions` of this `mech` at mu_l, from `starting_deg` where it is given)."""
    at = float(res.phi_deg[0])
    mu = scales["mu_l"]
    if fixed is None:
        fixed = fixed_positions(mech, mu, starting_deg)
    elif fixed.mech is not mech or fixed.mu != mu:
        raise ValueError(f"fixed: the positions of {fixed.mech.name} at {fixed.mu}, not of {mech.name} at {mu}")
    elif starting_deg is not None and float(starting_deg) != fixed.start:
        raise ValueError(f"fixed: positions from {fixed.start:g} deg, not from starting_deg = {starting_deg:g} deg")
    points = dict(fixed.points)
    segs = list(fixed.segments)
    _draw_position(mech, res, 0, None, mu.value, points, segs)
    notes = [f"position 0 at phi = {fixed.start:.6g} deg (crank and rod in line), then every 30 deg; "
             f"design position phi = {at:g} deg drawn with plain letters"]
    notes += _branch_marks(mech, at, res, mu.value, points, segs, other_branch)
    return Plan("positions", f"Plan of positions, design position phi = {at:g} deg", mu, at, points,
                tuple(segs), fixed.paths, tuple(notes))
