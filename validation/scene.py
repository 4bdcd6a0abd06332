"""One engine-neutral scene derived from a Mechanism: what every engine adapter builds from.

A spanning tree of the links rooted at the frame (breadth first over the pairs), the
loop-closing pairs cut, inertias at the centres of mass, and the exact joint trajectories of
the solver for the prescribed crank motion.

Joint coordinates (q = 0 is the placement below, not an assembled configuration):

- revolute joint: child angle = parent angle + rel_angle + q, q wrapped to [-pi, pi) and 0 at
  phi = 0 in every scene of the mechanism (so scenes at different angles share one engine
  model); the anchor points
  `anchor_parent` (parent frame) and `anchor_child` (child frame) coincide.
- prismatic joint: child angle = parent angle + rel_angle; the child's anchor sits at the
  parent's anchor + q * axis (axis in the parent frame). q is the slider point's travel
  along the guide direction from the guide point, whichever of the two links is the parent.

Child frame origin in the parent frame: a_p + q*axis - R(rel_angle [+ q]) a_c.

The drive: an engine's crank is driven by a pure moment about its pivot. A working machine's
crank (`mech.drive.kind == "machine"`) is driven by the pinion's force on its gear at the pitch
point, `kinetostat.kinetostatics.gear_force(mech.drive.gear, M)`: same driving moment M, but the
frame's reaction on the crank carries that force too, so adapters must apply it to compare R(0,1).

May use: kinetostat (model, analysis, kinematics, planar), numpy.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from kinetostat import Analysis, Mechanism, analyze
from kinetostat.kinematics import Kinematics
from kinetostat.model import MAX_VALUE, Pair
from kinetostat.planar import cross, rotate

__all__ = ["Joint", "Body", "Scene", "EngineResult", "build_scene", "loads_at_centres", "tracked_points"]


@dataclass(frozen=True)
class Joint:
    """A tree joint: the pair that joins `child` to `parent`."""
    pair: Pair
    parent: int
    child: int
    kind: str                  # "R" or "P"
    anchor_parent: np.ndarray  # (2,) parent local frame, m
    anchor_child: np.ndarray   # (2,) child local frame, m
    rel_angle: float           # rad
    axis: np.ndarray           # (2,) unit slide direction in the parent frame (P); zeros for R


@dataclass(frozen=True)
class Body:
    """A moving link as a rigid body: inertia at the centre of mass."""
    link: int
    mass: float                # kg
    I_S: float                 # kg m^2 about the centre of mass
    com: np.ndarray            # (2,) centre of mass, link local frame, m


@dataclass(frozen=True)
class Scene:
    """Engine-neutral description of one mechanism and its exact motion over N angles."""
    mech: Mechanism
    bodies: tuple[Body, ...]       # in tree order (parent before child); body n is link bodies[n].link
    joints: tuple[Joint, ...]      # joints[n] joins bodies[n] to its parent
    cuts: tuple[Pair, ...]         # loop-closing pairs (constraints)
    crank_joint: int               # index of the crank's joint (the actuated one)
    g: float                       # m/s^2, gravity along -y
    res: Analysis                  # the solver's answer at the same angles (reference)
    q: np.ndarray                  # (N, n_joints) joint coordinates, rad or m
    qd: np.ndarray                 # (N, n_joints) their rates
    qdd: np.ndarray                # (N, n_joints) their second derivatives

    @property
    def phi_deg(self) -> np.ndarray:
        return self.res.phi_deg

    def body_of(self, link: int) -> int:
        return next(n for n, b in enumerate(self.bodies) if b.link == link)

    def external(self) -> tuple[np.ndarray, np.ndarray]:
        """Applied loads other than gravity on each link: force at the centre of mass
        (N, L, 2) and moment about the centre of mass (N, L), world frame, N and N m."""
        return loads_at_centres(self.bodies, self.g, self.res.kin, self.res.F_applied, self.res.M_applied)

    def reaction(self, pair: Pair) -> np.ndarray:
        """The solver's reaction of pair.links[0] on pair.links[1], (N, 2), N."""
        return self.res.forces.R[:, pair.index]

    @property
    def M_drive(self) -> np.ndarray:
        """The solver's driving moment on the crank about +z, (N,), N m."""
        return self.res.balancing_moment


def loads_at_centres(bodies: tuple[Body, ...], g: float, kin: Kinematics, F_applied: np.ndarray,
                     M_applied: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The applied loads F_applied (N, L, 2), N, and M_applied (N, L), N m about each link's local
    origin, as the engines take them: gravity taken out (the engines have their own), the force at
    the body's centre of mass and the moment about it."""
    F, M = F_applied.copy(), M_applied.copy()
    links = np.array([b.link for b in bodies], dtype=int)          # each moving link once
    weight = np.array([b.mass for b in bodies])[:, None] * np.array([0.0, -g])
    O = kin.origin[:, links]
    S = O + rotate(np.array([b.com for b in bodies]).reshape(-1, 2), kin.theta[:, links])
    F[:, links] -= weight
    M[:, links] -= cross(S - O, np.broadcast_to(weight, S.shape))
    M[:, links] += cross(O - S, F[:, links])
    return F, M


def tracked_points(mech: Mechanism) -> tuple[tuple[str, int], ...]:
    """The points whose kinematics the gate compares, as (point name, link): every moving link's
    centre of mass and every pair's point (R: the joint, on its moving link; P: the slider
    point, on the slider), each name once. Points of the frame (fixed) are left out."""
    out: dict[str, int] = {}
    for k, link in enumerate(mech.links):
        if k and link.com is not None:
            out.setdefault(link.com, k)
    for p in mech.pairs:
        k = p.links[1] if p.kind == "P" or p.links[1] != 0 else p.links[0]
        if k != 0:
            out.setdefault(p.point, k)
    return tuple(out.items())


def build_scene(mech: Mechanism, phi_deg=None, steps: int = 360, res: Analysis | None = None) -> Scene:
    """The scene of `mech` with its exact motion at `phi_deg` (or `steps` angles over a cycle)."""
    res = res if res is not None else analyze(mech, phi_deg=phi_deg, steps=steps, friction="first")
    ref = analyze(mech, phi_deg=[0.0], friction="first")   # revolute joints' zero: the assembly at phi = 0, for every scene
    parent = {0: None}
    order, joints, used = [], [], set()
    frontier = [0]
    while frontier:
        nxt = []
        for p_link in frontier:
            for pair in mech.pairs:
                if p_link not in pair.links or pair.index in used:
                    continue
                child = pair.links[1] if pair.links[0] == p_link else pair.links[0]
                if child in parent:
                    continue
                parent[child] = p_link
                used.add(pair.index)
                order.append(child)
                joints.append(_joint(mech, ref, pair, p_link, child))
                nxt.append(child)
        frontier = nxt
    cuts = tuple(p for p in mech.pairs if p.index not in used)
    bodies = tuple(_body(mech, k) for k in order)
    q, qd, qdd = _joint_motion(res, joints)
    crank = next(n for n, j in enumerate(joints) if {j.parent, j.child} == {0, 1})
    return Scene(mech, bodies, tuple(joints), cuts, crank, mech.g, res, q, qd, qdd)


def _body(mech: Mechanism, k: int) -> Body:
    """Link k as a body; refused here, before any engine sees it, where its mass or inertia is
    not a finite number in the model's range: pymunk aborts the process on an infinite mass
    (measured: SIGABRT in cpBodySetMass with mass = inf from weight / g, g = 5e-320)."""
    link = mech.links[k]
    for what, x in (("mass", link.mass), ("I_S", link.I_S)):
        if not (math.isfinite(x) and 0 <= x <= MAX_VALUE):
            raise ValueError(f"link {k}: {what} = {x!r} is not a finite number in [0, {MAX_VALUE:g}]: "
                             f"no engine is given it")
    com = np.asarray(link.points[link.com], float) if link.com else np.zeros(2)
    return Body(k, link.mass, link.I_S, com)


def _joint(mech: Mechanism, ref: Analysis, pair: Pair, parent: int, child: int) -> Joint:
    pts = lambda k, n: np.asarray(mech.links[k].points[n], float)
    if pair.kind == "R":
        rel = float(ref.kin.theta[0, child] - ref.kin.theta[0, parent])
        return Joint(pair, parent, child, "R", pts(parent, pair.point), pts(child, pair.point), rel, np.zeros(2))
    guide, slider = pair.links
    if parent == guide:
        return Joint(pair, parent, child, "P", pts(guide, pair.guide), pts(slider, pair.point),
                     pair.alpha, np.asarray(pair.direction))
    # parent is the slider: the guide point sits at -q along the slider's own x axis
    return Joint(pair, parent, child, "P", pts(slider, pair.point), pts(guide, pair.guide),
                 -pair.alpha, np.array([-1.0, 0.0]))


def _joint_motion(res: Analysis, joints: list[Joint]):
    kin = res.kin
    N = len(kin.phi)
    q, qd, qdd = (np.zeros((N, len(joints))) for _ in range(3))
    for n, j in enumerate(joints):
        if j.kind == "R":
            q[:, n] = _wrap(kin.theta[:, j.child] - kin.theta[:, j.parent] - j.rel_angle)
            qd[:, n] = kin.omega[:, j.child] - kin.omega[:, j.parent]
            qdd[:, n] = kin.eps[:, j.child] - kin.eps[:, j.parent]
        else:
            th_p = kin.theta[:, j.parent]
            Ap = kin.origin[:, j.parent] + rotate(j.anchor_parent, th_p)
            Ac = kin.origin[:, j.child] + rotate(j.anchor_child, kin.theta[:, j.child])
            q[:, n] = np.sum((Ac - Ap) * rotate(j.axis, th_p), axis=-1)
            qd[:, n] = kin.v_slide[:, j.pair.index]
            qdd[:, n] = kin.a_slide[:, j.pair.index]
    return q, qd, qdd


def _wrap(a: np.ndarray) -> np.ndarray:
    return (a + math.pi) % (2 * math.pi) - math.pi


@dataclass(frozen=True)
class EngineResult:
    """What one engine route returns over the scene's angles; compared with the solver."""
    engine: str                 # "pinocchio", "mujoco", "pymunk"
    route: str                  # "exact" (inverse dynamics at the exact state) or "simulation"
    phi_deg: np.ndarray         # (N,) the angles the values belong to
    M_drive: np.ndarray         # (N,) driving moment on the crank about +z, N m
    R: np.ndarray               # (N, n_pairs, 2) force of pair.links[0] on pair.links[1], N, world
    magnitudes_only: bool = False   # True: only |M_drive| and |R| are meaningful (pymunk)
    points: tuple[tuple[str, int], ...] = ()   # (point name, link) of the kinematics below
    x: np.ndarray | None = None  # (N, n_points, 2) positions of `points`, world, m (engine's own)
    v: np.ndarray | None = None  # (N, n_points, 2) their velocities, m/s
    a: np.ndarray | None = None  # (N, n_points, 2) their accelerations, m/s^2
    build_seconds: float = 0.0  # wall time to build the engine model
    run_seconds: float = 0.0    # wall time of the cycle
    note: str = ""              # anything the reader must know (step size, iterations, ...)
