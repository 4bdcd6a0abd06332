"""Zhukovsky's rigid lever drawn (seed 002 sec. 1.2.3, fig. 1.12; seed 000 sec. 8): the velocity
plan as it is, every load turned by 90 deg clockwise at its like point (TURN), the arms about the
pole and the balancing force F'_bal at the crank pin's image, across p-a, as a `PlanCycle` at the
N angles of an analysis at once (as `forces` builds its plans); and the check of M_bal by both
routes.

Seed 002 keeps the plan and turns the forces by 90 deg clockwise, as drawn here; seed 000 turns the
plan by 90 deg and keeps the forces: the same figure turned as a whole, with the same arms and
moments. The moment about the pole of a force F turned at the image of a point of velocity v is
-(F . v) / mu_v, minus its power over mu_v, so that sum(moments) mu_v / omega_1 = M_bal (the
balancing moment on the crank).

An inertia main moment M_i (and an applied moment) is replaced, as seed 002 does, by a couple of
forces M_i / l_AB at the ends a, b of the link's image, across the link AB on the mechanism.

May use: numpy, `core`, `forces` (the loads and their lettering). Never matplotlib.
"""
from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from .core import Plan, PlanCycle, Result, Scale, Segment
from .forces import _abs, _cycle, _dot, _drawable, _over, _scale, _unit, arm_name, force_scale, link_couples, link_loads
from ..model.lettering import lettering

if TYPE_CHECKING:
    from ..analysis import Analysis
    from ..model import Mechanism

__all__ = ["lever_plan", "lever_check", "pole_moment", "NATURAL", "TOLERANCE_PCT", "TURN"]

#: The arms on the lever are measured on the drawing and kept in mm (seed 002: h_Fi2 = 37.67 mm).
NATURAL = Scale("natural", 1.0, "mm/mm")
#: The texts' rule: the two balancing moments may differ by 5 % (seed 002, line 468).
TOLERANCE_PCT = 5.0
#: How a load is turned onto the lever: by 90 deg clockwise (F -> -i F), as seed 002 turns them.
TURN = -1j


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
    that name) on the velocity plan: lower case, with the link's number where another link's point
    of that name moves otherwise at any of the angles. Added to pts ((N,) complex, mm)."""
    v = np.asarray(res.kin.velocity_z(k, mech.links[k].points[name] if local is None else local), dtype=complex)
    z = _over(v, mu_v.value)
    key = name.lower()
    if key in pts and (_abs(pts[key] - z) > 1e-9 * np.maximum(1.0, _abs(z))).any():
        key = f"{key}{k}"
    pts[key] = z
    return key


def lever_plan(mech: "Mechanism", res: "Analysis", mu_v, mu_F: Scale | None = None) -> PlanCycle:
    """Zhukovsky's lever at mu_v at the N angles of `res`: pole p, the image of every point of the
    moving links (the velocity plan, not turned), the vectors p-x and the links' images (a-b,
    values in m/s), every force turned by 90 deg clockwise (`TURN`) at its like point (its value
    in N, drawn at a round force scale of its own; couples as two forces "M_i2/l (a)",
    "M_i2/l (b)"), the arms h_.. about the pole to the turned force's line where not zero (value:
    the arm's drawn length in mm, as the texts keep it: `NATURAL`), and the balancing force
    F'_bal (the model's lettering: F'_зр) at the crank pin's image, across p-a, whose moment
    about the pole cancels the loads'. Its results: F'_bal, M'_bal, M_bal by the force plans and
    their difference δ against the texts' 5 % (TOLERANCE_PCT). `mu_F`: the forces' scale
    (default: chosen for the largest force over the angles). An element that exists at some
    angles only (an image off the pole, a couple, an arm) is NaN at the others."""
    _drawable(res)
    mu_v = _scale(mu_v, "mu_v", "m/(s mm)")
    with np.errstate(invalid="ignore", divide="ignore"):
        return _lever_plan(mech, res, mu_v, mu_F)


def _lever_plan(mech: "Mechanism", res: "Analysis", mu_v: Scale, mu_F: Scale | None) -> PlanCycle:
    n = len(res.phi_deg)
    pts: dict[str, np.ndarray] = {"p": np.zeros(n, dtype=complex)}
    segs: list[Segment] = []
    forces: list[tuple[str, str, np.ndarray]] = []     # (name, image point, force turned N (N,))
    for k in range(1, mech.n_links):
        link = mech.links[k]
        images = [_image(mech, res, k, name, mu_v, pts) for name in link.points]
        for name, img in zip(link.points, images):
            off = _abs(pts[img]) > 0
            if off.any() and f"p-{img}" not in {s.name for s in segs}:
                segs.append(Segment(f"p-{img}", "p", img, np.where(off, _abs(pts[img]) * mu_v.value, np.nan), "m/s",
                                    role="link"))       # the lever: a rigid body
        joints = list(dict.fromkeys(p.point for p in mech.pairs if k in p.links and p.point in link.points))
        for m, a in enumerate(joints):
            for b in joints[m + 1:]:
                ia, ib = images[list(link.points).index(a)], images[list(link.points).index(b)]
                off = (_abs(pts[ia]) > 0) & (_abs(pts[ib]) > 0)    # a link pivoted on the frame: its image is p-x
                if off.any():
                    segs.append(Segment(f"{ia}-{ib}", ia, ib, np.where(off, _abs(pts[ib] - pts[ia]) * mu_v.value, np.nan),
                                        "m/s", "link"))
        for ld in link_loads(mech, res, k):
            forces.append((ld.name, images[list(link.points).index(ld.at)], TURN * ld.force))
        for c in link_couples(mech, res, k):
            acts = c.moment != 0
            if not acts.any():
                continue
            (a, la), (b, lb) = _couple_ends(mech, k)
            A, B = (np.asarray(res.kin.position_z(k, q), dtype=complex) for q in (la, lb))
            F = np.where(acts, c.moment / _abs(A - B) ** 2 * 1j * (A - B), np.nan)   # F at A, -F at B: (A - B) x F = M
            for name, local, f in ((a, la, F), (b, lb, -F)):
                forces.append((f"{c.name}/l ({name.lower()})", _image(mech, res, k, name, mu_v, pts, local), TURN * f))
    total = sum(np.where(np.isnan(F), 0.0, _moment(pts[at], F)) for _, at, F in forces)   # a couple acts where not NaN
    crank_pin = _image(mech, res, mech.drive.link, mech.drive.point, mu_v, pts)
    F_bal = _across(pts[crank_pin], -total)
    L = lettering(mech)
    F_name = L.lever(L.F_bal)
    forces.append((F_name, crank_pin, F_bal))
    mu_F = mu_F or force_scale([F for _, _, F in forces])
    for name, at, F in forces:
        start = f"{name}:from"
        pts[start] = np.where(np.isnan(F), np.nan, pts[at])               # a couple's force NaN where it acts not
        pts[f"{name}:to"] = pts[start] + _over(F, mu_F.value)
        segs.append(Segment(name, start, f"{name}:to", _abs(F), "N", "vector", mu_F, "result" if name == F_name else "given"))
        u = _unit(F)
        foot = pts[at] - _dot(pts[at], u) * u
        has = (_abs(F) > 0) & (_abs(foot) > 1e-9 * _abs(pts[at]))      # a line through the pole has no arm
        if name != F_name and has.any():
            foot = np.where(has, foot, np.nan)
            pts[f"{arm_name(name)}:foot"] = foot
            segs.append(Segment(arm_name(name), "p", f"{arm_name(name)}:foot", _abs(foot) * NATURAL.value, "mm", "arm",
                                NATURAL))
    omega1 = np.asarray(res.omega(mech.drive.link), dtype=float)
    M_lever = total * mu_v.value / omega1
    M_forces = np.asarray(res.balancing_moment, dtype=float)
    delta = np.where(M_lever != 0, (M_lever - M_forces) / np.where(M_lever != 0, M_lever, 1.0) * 100, 0.0)
    within = tuple("within 5" if abs(d) <= TOLERANCE_PCT else "beyond 5" for d in delta.tolist())
    results = (Result(F_name, _abs(F_bal), "N", "by lever"), Result(L.lever(L.M_bal), M_lever, "N m", "by lever"),
               Result(L.M_bal, M_forces, "N m", "by force plans"),
               Result("δ", delta, "%", within[0] if len(set(within)) == 1 else within))
    titles = [f"Zhukovsky's lever (forces turned by 90 deg cw): {F_name} = {f:.6g} N "
              f"at {crank_pin}, {L.lever(L.M_bal)} = {m:.6g} N m; forces drawn at {mu_F}"
              for f, m in zip(_abs(F_bal).tolist(), M_lever.tolist())]
    return _cycle("lever", titles, mu_v, res, pts, segs, results=results)


def _moment(r, F):
    """z-moment of force F at r about the origin (N mm for r in mm); scalars or arrays."""
    return np.real(r) * np.imag(F) - np.imag(r) * np.real(F)


def _across(pa: np.ndarray, moment: np.ndarray) -> np.ndarray:
    """The force across pa at the end of pa whose moment about the pole is `moment` (0 where pa = 0)."""
    a = _abs(pa)
    return np.where(a > 0, _over(moment / np.where(a > 0, a, 1.0) * 1j * pa, np.where(a > 0, a, 1.0)), 0j)


def pole_moment(plan: Plan | PlanCycle, without: tuple[str, ...] | None = None):
    """Sum of the moments about the pole p of the lever's forces (segments in N), N mm, read off
    the plan's own points: each force along its drawn segment, at its start; `without` the
    forces left out (default: the balancing force, the last one drawn). A float for a Plan, (N,)
    for a PlanCycle (a force not drawn at an angle counts nothing there)."""
    if without is None:
        without = tuple(s.name for s in plan.segments if s.unit == "N")[-1:]
    total = 0.0
    for s in plan.segments:
        if s.unit == "N" and s.name not in without:
            d = np.asarray(plan.points[s.end] - plan.points[s.start])
            a = _abs(d)
            with np.errstate(invalid="ignore", divide="ignore"):
                term = np.where(a > 0, _moment(plan.points[s.start] - plan.points["p"], _over(d, np.where(a > 0, a, 1.0)) * s.value), 0.0)
            total = total + np.nan_to_num(term)
    return float(total) if isinstance(plan, Plan) else np.broadcast_to(total, (plan.n,)).copy()


def lever_check(mech: "Mechanism", res: "Analysis", mu_v=0.2) -> dict:
    """M_bal by both routes at the one angle of `res` (seed 002: 102.74 N m by the force plans,
    102.97 by the lever, 0.22 %): `M_bal_forces` from the group-by-group solution, `M_bal_lever`
    = the lever's moment about the pole x mu_v / omega_1, `F_bal_lever` = F'_bal (N) at the crank
    pin, with |M_bal_lever| = F'_bal l_OA, and `difference_pct` = (M_lever - M_forces) / M_lever x
    100 as seed 002 writes it. mu_v only sets the drawing; the results do not depend on it."""
    if len(res.phi_deg) != 1:
        raise ValueError(f"lever_check: analyse at one crank angle, e.g. analyze(mech, phi_deg=[30]); "
                         f"got {len(res.phi_deg)} angles")
    plan = lever_plan(mech, res, mu_v).at(0)
    mu = plan.scale.value
    omega1 = float(res.omega(mech.drive.link)[0])
    M_lever = float(pole_moment(plan)) * mu / omega1
    M_forces = float(res.balancing_moment[0])
    link = mech.links[mech.drive.link]
    l_OA = float(np.hypot(*np.subtract(link.points[mech.drive.point], link.points[mech.drive.pivot])))
    return {"phi_deg": float(res.phi_deg[0]), "M_bal_forces": M_forces, "M_bal_lever": M_lever,
            "F_bal_lever": float([s for s in plan.segments if s.unit == "N"][-1].value), "l_OA": l_OA,
            "difference_pct": (M_lever - M_forces) / M_lever * 100 if M_lever else 0.0}
