"""Zhukovsky's rigid lever drawn (seed 000 sec. 8, seed 002 sec. 1.2.3, fig. 1.12): the velocity
plan turned by 90 deg with every load at its like point, the arms about the pole and the
balancing force F'_bal at the crank pin's image; and the check of M_bal by both routes.

The plan is turned by 90 deg counter-clockwise (each image is i v / mu_v) and the forces keep
their true directions. Seed 002 keeps the plan and turns the forces by 90 deg clockwise instead:
the same figure turned as a whole, with the same arms and moments. The moment about the pole of
a force F at the image of a point of velocity v is then -(F . v) / mu_v, minus its power over
mu_v, so that sum(moments) mu_v / omega_1 = M_bal (the balancing moment on the crank).

An inertia main moment M_i (and an applied moment) is replaced, as seed 002 does, by a couple of
forces M_i / l_AB at the ends a, b of the link's image, across the link AB on the mechanism.

May use: numpy, `core`, `forces` (the loads and their lettering). Never matplotlib.
"""
from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from .core import Plan, Result, Scale, Segment
from .forces import _scale, _single, arm_name, force_scale, link_couples, link_loads
from ..model.lettering import lettering

if TYPE_CHECKING:
    from ..analysis import Analysis
    from ..model import Mechanism

__all__ = ["lever_plan", "lever_check", "pole_moment", "NATURAL", "TOLERANCE_PCT"]

#: The arms on the lever are measured on the drawing and kept in mm (seed 002: h_Fi2 = 37.67 mm).
NATURAL = Scale("natural", 1.0, "mm/mm")
#: The texts' rule: the two balancing moments may differ by 5 % (seed 002, line 468).
TOLERANCE_PCT = 5.0


def _couple_ends(mech: "Mechanism", k: int) -> list[tuple[str, tuple[float, float]]]:
    """The two joints of link k (else its two farthest points) where a couple becomes two forces,
    as (name, local point). A link of one point (a block turning with its slot) gets a second
    point at the mechanism's size along its local x, named with a prime (A')."""
    link = mech.links[k]
    joints = list(dict.fromkeys(p.point for p in mech.pairs if k in p.links and p.point in link.points))
    names = joints if len(joints) >= 2 else list(link.points)
    if len(names) < 2:
        x, y = link.points[names[0]]
        return [(names[0], (x, y)), (f"{names[0]}'", (x + mech.size, y))]
    pairs = [(a, b) for a in names for b in names if a < b]
    a, b = max(pairs, key=lambda ab: np.hypot(*np.subtract(link.points[ab[0]], link.points[ab[1]])))
    return [(a, link.points[a]), (b, link.points[b])]


def _image(mech: "Mechanism", res: "Analysis", k: int, name: str, mu_v: Scale, pts: dict,
           local: tuple[float, float] | None = None) -> str:
    """Name of the like point of point `name` of link k (at `local`, default the link's point of
    that name) on the turned plan: lower case, with the link's number where another link's point
    of that name moves otherwise. Added to pts."""
    v = complex(res.kin.velocity_z(k, mech.links[k].points[name] if local is None else local)[0])
    z = 1j * v / mu_v.value
    key = name.lower()
    if key in pts and abs(pts[key] - z) > 1e-9 * max(1.0, abs(z)):
        key = f"{key}{k}"
    pts[key] = z
    return key


def lever_plan(mech: "Mechanism", res: "Analysis", mu_v, mu_F: Scale | None = None) -> Plan:
    """Zhukovsky's lever at mu_v: pole p, the image of every point of the moving links (turned by
    90 deg counter-clockwise), the vectors p-x and the links' images (a-b, values in m/s), every
    force at its like point (its value in N, drawn at a round force scale of its own; couples as
    two forces "M_i2/l (a)", "M_i2/l (b)"), the arms h_.. about the pole (value: the arm's
    drawn length in mm, as the texts keep it: `NATURAL`), and the balancing force F'_bal (the model's
    lettering: F'_зр) at the crank pin's image, across p-a, whose moment about the pole cancels
    the loads'. Its results: F'_bal, M'_bal, M_bal by the force plans and their difference δ
    against the texts' 5 % (TOLERANCE_PCT). `mu_F`: the forces' scale (default: chosen at this angle)."""
    _single(res)
    mu_v = _scale(mu_v, "mu_v", "m/(s mm)")
    pts: dict[str, complex] = {"p": 0j}
    segs: list[Segment] = []
    forces: list[tuple[str, str, complex]] = []     # (name, image point, force N)
    for k in range(1, mech.n_links):
        link = mech.links[k]
        images = [_image(mech, res, k, name, mu_v, pts) for name in link.points]
        for name, img in zip(link.points, images):
            if abs(pts[img]) > 0 and f"p-{img}" not in {s.name for s in segs}:
                segs.append(Segment(f"p-{img}", "p", img, abs(pts[img]) * mu_v.value, "m/s"))
        joints = list(dict.fromkeys(p.point for p in mech.pairs if k in p.links and p.point in link.points))
        for n, a in enumerate(joints):
            for b in joints[n + 1:]:
                ia, ib = images[list(link.points).index(a)], images[list(link.points).index(b)]
                if abs(pts[ia]) and abs(pts[ib]):      # a link pivoted on the frame: its image is p-x
                    segs.append(Segment(f"{ia}-{ib}", ia, ib, abs(pts[ib] - pts[ia]) * mu_v.value, "m/s", "link"))
        for ld in link_loads(mech, res, k):
            forces.append((ld.name, images[list(link.points).index(ld.at)], ld.force))
        for c in link_couples(mech, res, k):
            if c.moment == 0:
                continue
            (a, la), (b, lb) = _couple_ends(mech, k)
            A, B = (complex(res.kin.position_z(k, q)[0]) for q in (la, lb))
            F = c.moment / abs(A - B) ** 2 * 1j * (A - B)       # F at A, -F at B: (A - B) x F = M
            for name, local, f in ((a, la, F), (b, lb, -F)):
                forces.append((f"{c.name}/l ({name.lower()})", _image(mech, res, k, name, mu_v, pts, local), f))
    total = sum(_moment(pts[at], F) for _, at, F in forces)
    crank_pin = _image(mech, res, mech.drive.link, mech.drive.point, mu_v, pts)
    pa = pts[crank_pin]
    F_bal = _across(pa, -total)
    L = lettering(mech)
    F_name = L.lever(L.F_bal)
    forces.append((F_name, crank_pin, F_bal))
    mu_F = mu_F or force_scale([F for _, _, F in forces])
    for name, at, F in forces:
        start = f"{name}:from"
        pts[start], pts[f"{name}:to"] = pts[at], pts[at] + F / mu_F.value
        segs.append(Segment(name, start, f"{name}:to", abs(F), "N", "vector", mu_F))
        if name != F_name and abs(F) > 0 and abs(pts[at]) > 0:
            u = F / abs(F)
            foot = pts[at] - (pts[at] * u.conjugate()).real * u
            pts[f"{arm_name(name)}:foot"] = foot
            segs.append(Segment(arm_name(name), "p", f"{arm_name(name)}:foot", abs(foot) * NATURAL.value, "mm", "arm",
                                NATURAL))
    omega1 = float(res.omega(mech.drive.link)[0])
    M_lever = float(total) * mu_v.value / omega1
    M_forces = float(res.balancing_moment[0])
    delta = (M_lever - M_forces) / M_lever * 100 if M_lever else 0.0
    results = (Result(F_name, abs(F_bal), "N", "by lever"), Result(L.lever(L.M_bal), M_lever, "N m", "by lever"),
               Result(L.M_bal, M_forces, "N m", "by force plans"),
               Result("δ", delta, "%", "within 5" if abs(delta) <= TOLERANCE_PCT else "beyond 5"))
    return Plan("lever", f"Zhukovsky's lever (velocity plan turned by 90 deg ccw): {F_name} = {abs(F_bal):.6g} N "
                f"at {crank_pin}, {L.lever(L.M_bal)} = {M_lever:.6g} N m; forces drawn at {mu_F}",
                mu_v, float(res.phi_deg[0]), pts, tuple(segs), results=results)


def _moment(r: complex, F: complex) -> float:
    """z-moment of force F at r about the origin (N mm for r in mm)."""
    return (r.conjugate() * F).imag


def _across(pa: complex, moment: float) -> complex:
    """The force across pa at the end of pa whose moment about the pole is `moment`."""
    if pa == 0:
        return 0j
    return moment / abs(pa) * 1j * pa / abs(pa)


def pole_moment(plan: Plan, without: tuple[str, ...] | None = None) -> float:
    """Sum of the moments about the pole p of the lever's forces (segments in N), N mm, read off
    the plan's own points: each force along its drawn segment, at its start; `without` the
    forces left out (default: the balancing force, the last one drawn)."""
    if without is None:
        without = tuple(s.name for s in plan.segments if s.unit == "N")[-1:]
    total = 0.0
    for s in plan.segments:
        if s.unit == "N" and s.name not in without:
            d = plan.points[s.end] - plan.points[s.start]
            if abs(d):
                total += _moment(plan.points[s.start] - plan.points["p"], d / abs(d) * s.value)
    return total


def lever_check(mech: "Mechanism", res: "Analysis", mu_v=0.2) -> dict:
    """M_bal by both routes (seed 002: 102.74 N m by the force plans, 102.97 by the lever, 0.22 %):
    `M_bal_forces` from the group-by-group solution, `M_bal_lever` = the lever's moment about the
    pole x mu_v / omega_1, `F_bal_lever` = F'_bal (N) at the crank pin, with |M_bal_lever| =
    F'_bal l_OA, and `difference_pct` = (M_lever - M_forces) / M_lever x 100 as seed 002 writes it.
    mu_v only sets the drawing; the results do not depend on it."""
    plan = lever_plan(mech, res, mu_v)
    mu = plan.scale.value
    omega1 = float(res.omega(mech.drive.link)[0])
    M_lever = float(pole_moment(plan)) * mu / omega1
    M_forces = float(res.balancing_moment[0])
    link = mech.links[mech.drive.link]
    l_OA = float(np.hypot(*np.subtract(link.points[mech.drive.point], link.points[mech.drive.pivot])))
    return {"phi_deg": float(res.phi_deg[0]), "M_bal_forces": M_forces, "M_bal_lever": M_lever,
            "F_bal_lever": float([s for s in plan.segments if s.unit == "N"][-1].value), "l_OA": l_OA,
            "difference_pct": (M_lever - M_forces) / M_lever * 100 if M_lever else 0.0}
