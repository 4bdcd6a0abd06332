"""MuJoCo adapter of the cross-validation harness: the scene as MJCF, solved two ways.

Routes
------
`solve(scene)` (route "exact"): inverse dynamics at the exact state, from MuJoCo's own model
quantities. At every angle the joint coordinates, rates and accelerations of the scene are
written to qpos/qvel/qacc; the position and velocity stages (those of mj_fwdPosition and
mj_fwdVelocity that inverse dynamics needs: mj_kinematics, mj_comPos, mj_makeConstraint,
mj_comVel) evaluate the kinematics, `mj_rne(m, d, 1, .)` gives M qacc + bias (gravity
included), `mj_applyFT` the generalised applied loads (also written to `xfrc_applied`), and the
equality rows of `efc_J` the loop-closure Jacobian. The square system

    [S | J^T] [tau; lambda] = M qacc + bias - Q_applied

(S selects the crank's dof) gives the driving moment tau and the constraint forces lambda; they
are written into `efc_force` and `mj_rnePostConstraint` fills `cfrc_int[b]`, whose force part
is the force of the parent on body b's subtree through b's tree joint. `mj_inverse` is not
used: at exactly consistent kinematics it returns zero equality forces (guide/engines.md).

`simulate(scene)` (route "simulation"): MuJoCo's own constrained forward dynamics with soft
equality constraints, from the exact initial state, stepped by `mujoco.rollout` (MuJoCo's C++
multi-step rollout: no Python loop over the steps). The crank's motion is prescribed by a
"clock": a flywheel on its own hinge, far heavier than the mechanism, turning at the crank
speed, to which a joint equality ties the crank; that constraint's force is the driving
moment. The solver's torque is never fed in. The applied loads of every step are the
rollout's open-loop control (`xfrc_applied`). At the samples, the rollout's recorded states
are evaluated again by `mj_forward` (the constraint forces `efc_force`, as in that step) and
`mj_rnePostConstraint` (`cfrc_int`, the sites' accelerations); reactions are read from
`efc_force` (cut pairs) and `cfrc_int` (tree pairs).

Kinematics (both routes): a site at every point of `tracked_points` (each link's centre of
mass, each pair's point); positions `site_xpos`, velocities `mj_objectVelocity`, accelerations
`mj_objectAcceleration` (classical, gravity taken back out of cacc), at the state used.

MJCF (see `mjcf`)
-----------------
One body per moving link (named `link<k>`), nested as the scene's spanning tree; a hinge
(axis 0 0 1) or slide joint per tree pair, placed so that qpos = 0 is the scene's q = 0
(scene.py: child angle = parent angle + rel_angle [+ q]; the anchors coincide, a prismatic
child's anchor moved by q * axis). No geoms (no contacts). Loops:

- a cut revolute pair i-j: `<connect site1 site2>` with site1 on link j = pair.links[1] and
  site2 on link i at the pair's point. MuJoCo's connect row force is the force on site1's
  body, so the in-plane rows (x, y) are R = force of pair.links[0] on pair.links[1].
- a cut prismatic pair (guide g, slider s): MuJoCo has no in-plane slot equality, so a
  massless helper body `slot<n>` hangs on the guide body at the guide point, turned by the
  pair's alpha (its frame is the slider's frame), with a slide joint along the guide; a
  `<weld site1 site2>` joins the slider's point to the helper's origin. The weld's in-plane
  rows (x, y translation, z rotation) lock the slider's point to the moving helper and its
  angle to the guide's: exactly the two conditions of a prismatic pair, with the extra helper
  dof taking up the travel (its coordinate is the pair's slide travel, known exactly). The
  helper is massless (its mass is set to 0 after compiling, see below), so the force it passes
  on has no component along the guide; the weld's translational force on the slider is R.
  The weld's other three rows (z translation, x and y rotation) are identically zero in a
  planar model and are dropped; so is the connect's z row.

Masses: MuJoCo refuses moving bodies with zero mass or a zero principal inertia ("mass and
inertia of moving bodies must be larger than mjMINVAL"), and wants A + B >= C. The MJCF gives
each body its mass and I_S as the z inertia, x and y inertia entries equal to the z entry
(only z rotation exists in a planar model), and a placeholder floor where a value is zero:
massless links (a balanced crank, neglected blocks) and the helper bodies.

- exact route: the placeholders are EXACT_FLOOR (1e-12) of the scene's mass / inertia scales,
  and after compiling `body_mass` and `body_inertia` are overwritten with the exact values
  (zero where the link is massless). mj_rne, mj_comPos and mj_rnePostConstraint read them
  directly, so the placeholders have no effect at all (kept instead, they change the results
  by ~1e-12 of the peaks: tested). The inertia matrix is never factorised by this route, so
  a singular M (a massless leaf body) does no harm.
- simulation route: forward dynamics needs a positive definite M, so the floors stay, at
  SIM_FLOOR (1e-7) of the scales; 1e-7 and 1e-9 give results within 1e-6 of each other
  (tested). MuJoCo's constraint regularisation is scaled by each body's `body_invweight0`
  (inverse inertia at qpos0), which a floor body makes ~1/floor: its constraints would be
  that much softer (the shaper's slots came out 100 % wrong). Floor bodies therefore take
  their tree parent's invweight0 (see `_regularisation_weights`).

Conventions: SI, world x right, y up, gravity -y. R[:, pair.index] is the force of
pair.links[0] on pair.links[1] (world x, y); M_drive the moment the drive applies to the crank
about +z. For a working machine (drive.kind = "machine") the drive is the pinion's force on
the crank's gear at the pitch point, not a couple: its moment about the crank axis is the
torque found here, its line of action that of the model's gear pair, and the frame's reaction
on the crank is the joint force minus that mesh force (as kinetostat defines it).

May use: kinetostat (planar, gear_force), the scene, mujoco.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from kinetostat._text import xml_escape
from kinetostat.planar import rotate

from kinetostat.kinetostatics import gear_force

from .scene import EngineResult, Scene, tracked_points

__all__ = ["mjcf", "slot_motion", "solve", "simulate", "SIM_FLOOR", "SIM_STEPS_PER_REV"]

#: Exact route: the MJCF's placeholder mass / inertia of massless bodies, relative to the
#: scene's largest mass and largest m*size^2. Overwritten with exact zeros after compiling
#: (kept, they would change forces by about this fraction of the weights and inertia forces).
EXACT_FLOOR = 1e-12
#: Absolute lower bound of the placeholders: 100 x MuJoCo's mjMINVAL (1e-15), which the
#: compiler requires every moving body's mass and principal inertias to exceed.
ABS_FLOOR = 1e-13
#: Simulation route: floor on every body's mass and inertia, relative to the scene's scales;
#: it stays in the dynamics (a positive definite M is needed), so it must sit well below the
#: route's tolerance (it changes forces by about SIM_FLOOR times the largest inertia force).
SIM_FLOOR = 1e-7
#: The out-of-plane rows of the loop closures (connect z; weld z, rx, ry) must be identically
#: zero in a planar model; anything above round-off means a body or joint left the plane.
OFF_PLANE_TOL = 1e-12
#: Simulation route: default number of time steps per crank revolution.
SIM_STEPS_PER_REV = 7200
#: Simulation route: the drive's clock flywheel has this many times (a bound of the driving
#: moment) / omega^2 as its moment of inertia: its speed changes by at most 2 pi / CLOCK_INERTIA
#: (6e-9) in a revolution.
CLOCK_INERTIA = 1e9


# ----------------------------------------------------------------------------- MJCF

def _f(x: float) -> str:
    """A float as the shortest text that reads back to the same double."""
    return repr(float(x))


def _v(*xs: float) -> str:
    return " ".join(_f(x) for x in xs)


def _quat_z(angle: float) -> str:
    return _v(math.cos(angle / 2), 0.0, 0.0, math.sin(angle / 2))


def _scales(scene: Scene) -> tuple[float, float]:
    """Mass scale (kg) and inertia scale (kg m^2) of the scene, for the floors."""
    size = scene.mech.size
    m = max([b.mass for b in scene.bodies] + [0.0]) or 1.0
    I = max([b.I_S for b in scene.bodies] + [b.mass * size**2 for b in scene.bodies] + [0.0]) or m * size**2
    return m, I


def _slider_cuts(scene: Scene):
    return [p for p in scene.cuts if p.kind == "P"]


def mjcf(scene: Scene, floor: float = EXACT_FLOOR, timestep: float = 1e-4,
         solref: tuple[float, float] = (0.02, 1.0),
         solimp: tuple[float, ...] = (0.9, 0.95, 0.001, 0.5, 2.0), clock_inertia: float = 0.0) -> str:
    """The scene as an MJCF document (see the module docstring for the layout).

    `clock_inertia` > 0 (simulation): adds the drive's clock, a flywheel body `clock` on its own
    hinge with that moment of inertia (kg m^2), and a joint equality `drive` that ties the
    crank's joint to it (same solref and solimp as the loops).
    `floor`: placeholder mass / inertia, relative to the scene's scales, of bodies whose mass or
    I_S is zero (MuJoCo requires positive values). `timestep`, `solref`, `solimp`: options of
    the equality constraints for forward simulation (the exact route does not use them).
    """
    mech = scene.mech
    m_scale, I_scale = _scales(scene)
    m_min, I_min = max(floor * m_scale, ABS_FLOOR), max(floor * I_scale, ABS_FLOOR)
    children: dict[int, list[int]] = {}
    for n, j in enumerate(scene.joints):
        children.setdefault(j.parent, []).append(n)
    sites: dict[int, list[str]] = {}          # link -> site elements on it
    helpers: dict[int, list[str]] = {}        # guide link -> helper bodies hanging on it
    eqs: list[str] = []
    sr, si = _v(*solref), _v(*solimp)
    for i, (name, k) in enumerate(tracked_points(mech)):     # the gate's kinematics points
        x, y = mech.links[k].points[name]
        sites.setdefault(k, []).append(f'<site name="pt{i}" pos="{_v(x, y, 0)}"/>')
    for p in scene.cuts:
        a, b = p.links
        if p.kind == "R":
            for k, tag in ((b, "b"), (a, "a")):
                x, y = mech.links[k].points[p.point]
                sites.setdefault(k, []).append(f'<site name="cut{p.index}{tag}" pos="{_v(x, y, 0)}"/>')
            eqs.append(f'<connect name="cut{p.index}" site1="cut{p.index}b" site2="cut{p.index}a" '
                       f'solref="{sr}" solimp="{si}"/>')
        else:
            guide, slider = a, b
            gx, gy = mech.links[guide].points[p.guide]
            sx, sy = mech.links[slider].points[p.point]
            sites.setdefault(slider, []).append(f'<site name="cut{p.index}b" pos="{_v(sx, sy, 0)}"/>')
            helpers.setdefault(guide, []).append(
                f'<body name="slot{p.index}" pos="{_v(gx, gy, 0)}" quat="{_quat_z(p.alpha)}">'
                f'<joint name="slot{p.index}" type="slide" axis="1 0 0"/>'
                f'<inertial pos="0 0 0" mass="{_f(m_min)}" diaginertia="{_v(I_min, I_min, I_min)}"/>'
                f'<site name="cut{p.index}a"/></body>')
            eqs.append(f'<weld name="cut{p.index}" site1="cut{p.index}b" site2="cut{p.index}a" '
                       f'solref="{sr}" solimp="{si}"/>')

    def body(n: int, indent: str) -> list[str]:
        j, b = scene.joints[n], scene.bodies[n]
        assert b.link == j.child
        pos = j.anchor_parent - rotate(j.anchor_child, np.float64(j.rel_angle))
        out = [f'{indent}<body name="link{b.link}" pos="{_v(pos[0], pos[1], 0)}" quat="{_quat_z(j.rel_angle)}">']
        if j.kind == "R":
            out.append(f'{indent}  <joint name="pair{j.pair.index}" type="hinge" axis="0 0 1" '
                       f'pos="{_v(j.anchor_child[0], j.anchor_child[1], 0)}"/>')
        else:
            ax = rotate(j.axis, np.float64(-j.rel_angle))      # slide axis in the child's frame
            out.append(f'{indent}  <joint name="pair{j.pair.index}" type="slide" axis="{_v(ax[0], ax[1], 0)}" '
                       f'pos="{_v(j.anchor_child[0], j.anchor_child[1], 0)}"/>')
        mass, I = max(b.mass, m_min), max(b.I_S, I_min)
        out.append(f'{indent}  <inertial pos="{_v(b.com[0], b.com[1], 0)}" mass="{_f(mass)}" '
                   f'diaginertia="{_v(I, I, I)}"/>')
        out += [f'{indent}  {s}' for s in sites.get(b.link, [])]
        out += [f'{indent}  {h}' for h in helpers.get(b.link, [])]
        for c in children.get(b.link, []):
            out += body(c, indent + "  ")
        out.append(f'{indent}</body>')
        return out

    lines = [f'<mujoco model="{xml_escape(mech.name)}">',
             '  <compiler angle="radian" autolimits="true"/>',
             f'  <option timestep="{_f(timestep)}" gravity="0 {_f(-scene.g)} 0" jacobian="dense" '
             f'integrator="Euler" solver="Newton" iterations="50" tolerance="1e-14">',
             '    <flag contact="disable" frictionloss="disable" limit="disable"/>',
             '  </option>',
             '  <worldbody>']
    lines += [f'    {s}' for s in sites.get(0, [])]
    lines += [f'    {h}' for h in helpers.get(0, [])]
    for c in children.get(0, []):
        lines += body(c, "    ")
    if clock_inertia > 0:
        lines.append(f'    <body name="clock"><joint name="clock" type="hinge" axis="0 0 1"/>'
                     f'<inertial pos="0 0 0" mass="{_f(m_scale)}" diaginertia="{_v(*[clock_inertia] * 3)}"/></body>')
        crank = scene.joints[scene.crank_joint].pair.index
        eqs.append(f'<joint name="drive" joint1="pair{crank}" joint2="clock" polycoef="0 1 0 0 0" '
                   f'solref="{sr}" solimp="{si}"/>')
    lines += ['  </worldbody>', '  <equality>'] + [f'    {e}' for e in eqs] + ['  </equality>', '</mujoco>']
    return "\n".join(lines) + "\n"


# ----------------------------------------------------------------------------- the compiled model

@dataclass
class _Model:
    """A compiled scene and the index maps between it and the scene."""
    m: object                  # mujoco.MjModel
    d: object                  # mujoco.MjData
    body: dict                 # link -> MuJoCo body id (frame 0 -> 0)
    joint_dof: np.ndarray      # (n_joints,) dof of scene.joints[n]
    slot_dof: dict             # P cut pair index -> dof of its helper
    rows: dict                 # cut pair index -> efc rows (relative to the equality's first row)
    eq_id: dict                # cut pair index -> equality id
    crank_dof: int
    point_site: np.ndarray     # (n_points,) site of tracked_points(scene.mech)[i]
    point_body: np.ndarray     # (n_points,) its body
    point_root: np.ndarray     # (n_points,) the root of its body's tree (cvel, cacc are about its subtree_com)
    clock_dof: int = -1        # simulation: dof of the drive's clock (-1: none)
    drive_eq: int = -1         # simulation: id of the joint equality crank = clock


def _compile(scene: Scene, floor: float, exact_masses: bool, **options) -> _Model:
    import mujoco
    xml = mjcf(scene, floor=floor, **options)
    m = mujoco.MjModel.from_xml_string(xml)
    d = mujoco.MjData(m)
    name = lambda obj, s: mujoco.mj_name2id(m, obj, s)
    body = {0: 0}
    for b in scene.bodies:
        body[b.link] = name(mujoco.mjtObj.mjOBJ_BODY, f"link{b.link}")
    joint_dof = np.array([m.jnt_dofadr[name(mujoco.mjtObj.mjOBJ_JOINT, f"pair{j.pair.index}")]
                          for j in scene.joints])
    slot_dof = {p.index: int(m.jnt_dofadr[name(mujoco.mjtObj.mjOBJ_JOINT, f"slot{p.index}")])
                for p in _slider_cuts(scene)}
    rows = {p.index: (0, 1) if p.kind == "R" else (0, 1, 5) for p in scene.cuts}
    eq_id = {p.index: name(mujoco.mjtObj.mjOBJ_EQUALITY, f"cut{p.index}") for p in scene.cuts}
    if exact_masses:
        for b in scene.bodies:
            m.body_mass[body[b.link]] = b.mass
            m.body_inertia[body[b.link]] = b.I_S
        for p in _slider_cuts(scene):
            k = name(mujoco.mjtObj.mjOBJ_BODY, f"slot{p.index}")
            m.body_mass[k] = 0.0
            m.body_inertia[k] = 0.0
    sites = np.array([name(mujoco.mjtObj.mjOBJ_SITE, f"pt{i}") for i in range(len(tracked_points(scene.mech)))],
                     int)
    clock = name(mujoco.mjtObj.mjOBJ_JOINT, "clock")
    return _Model(m, d, body, joint_dof, slot_dof, rows, eq_id, int(joint_dof[scene.crank_joint]), sites,
                  m.site_bodyid[sites].copy(), m.body_rootid[m.site_bodyid[sites]].copy(),
                  int(m.jnt_dofadr[clock]) if clock >= 0 else -1, name(mujoco.mjtObj.mjOBJ_EQUALITY, "drive"))


def slot_motion(scene: Scene) -> dict:
    """Cut prismatic pair index -> travel (m), rate (m/s) and second derivative (m/s^2), each (N,),
    of its slider along the guide: the coordinate of its helper body's slide joint `slot<index>`."""
    kin, mech = scene.res.kin, scene.mech
    out = {}
    for p in _slider_cuts(scene):
        g, s = p.links
        th = kin.theta[:, g]
        G = kin.origin[:, g] + rotate(np.asarray(mech.links[g].points[p.guide], float), th)
        S = kin.origin[:, s] + rotate(np.asarray(mech.links[s].points[p.point], float), kin.theta[:, s])
        d = rotate(np.asarray(p.direction, float), th)
        out[p.index] = (np.sum((S - G) * d, axis=-1), kin.v_slide[:, p.index], kin.a_slide[:, p.index])
    return out


def _exact_state(scene: Scene, mm: _Model):
    """qpos, qvel, qacc (N, nv) of the scene's exact motion."""
    N, nv = len(scene.phi_deg), mm.m.nv
    qpos, qvel, qacc = (np.zeros((N, nv)) for _ in range(3))
    qpos[:, mm.joint_dof], qvel[:, mm.joint_dof], qacc[:, mm.joint_dof] = scene.q, scene.qd, scene.qdd
    for idx, (s, v, a) in slot_motion(scene).items():
        dof = mm.slot_dof[idx]
        qpos[:, dof], qvel[:, dof], qacc[:, dof] = s, v, a
    return qpos, qvel, qacc


def _mesh_force(scene: Scene, M: np.ndarray) -> np.ndarray:
    """(N, 2) the pinion's force on the crank's gear for driving moments M (machines; zeros
    for an engine): on the gear pair's line of action, with moment M about the crank axis."""
    dr = scene.mech.drive
    if dr.kind != "machine":
        return np.zeros((len(M), 2))
    return gear_force(dr.gear, M)


def _rows(mm: _Model, idx: int) -> np.ndarray:
    """efc rows of cut pair idx used (in-plane), absolute indices into the efc arrays."""
    d = mm.d
    first = int(np.flatnonzero(d.efc_id[:d.ne] == mm.eq_id[idx])[0])
    return first + np.asarray(mm.rows[idx])


def _applied(scene: Scene, mm: _Model, F: np.ndarray, M: np.ndarray) -> np.ndarray:
    """Generalised force of the applied loads F (L, 2) at the CoMs and M (L,) (one angle);
    also writes them to xfrc_applied (read by mj_rnePostConstraint)."""
    import mujoco
    m, d = mm.m, mm.d
    qfrc = np.zeros(m.nv)
    d.xfrc_applied[:] = 0.0
    for b in scene.bodies:
        k = mm.body[b.link]
        f = np.array([F[b.link, 0], F[b.link, 1], 0.0])
        t = np.array([0.0, 0.0, M[b.link]])
        if not (f.any() or t.any()):
            continue
        d.xfrc_applied[k, :3], d.xfrc_applied[k, 3:] = f, t
        mujoco.mj_applyFT(m, d, f, t, d.xipos[k].copy(), k, qfrc)
    return qfrc


def _reactions(scene: Scene, mm: _Model, M_drive: float) -> np.ndarray:
    """(n_pairs, 2) reactions from cfrc_int (tree pairs) and efc_force (cut pairs), after
    mj_rnePostConstraint."""
    d = mm.d
    R = np.full((len(scene.mech.pairs), 2), np.nan)
    for n, j in enumerate(scene.joints):
        F = d.cfrc_int[mm.body[j.child], 3:5].copy()     # parent on the child's subtree
        R[j.pair.index] = F if j.pair.links[0] == j.parent else -F
    for p in scene.cuts:
        R[p.index] = d.efc_force[_rows(mm, p.index)[:2]]
    crank = scene.joints[scene.crank_joint]
    Fb = _mesh_force(scene, np.array([M_drive]))[0]
    R[crank.pair.index] -= Fb if crank.pair.links[1] == 1 else -Fb
    return R


def _point_kinematics(mm: _Model) -> np.ndarray:
    """(3, n_points, 2) position, velocity and classical acceleration (world; m, m/s, m/s^2) of
    the tracked points' sites, from MuJoCo's site_xpos and its body motions cvel and cacc (what
    mj_objectVelocity and mj_objectAcceleration read: spatial vectors [angular; linear at the
    tree's subtree_com], shifted to the site, with w x v added for the classical acceleration).
    cacc comes from mj_rnePostConstraint, which must have run at this state, and starts from
    the world's acceleration -gravity, as an accelerometer: gravity is added back."""
    m, d = mm.m, mm.d
    b = mm.point_body
    p = d.site_xpos[mm.point_site, :2]
    r = p - d.subtree_com[mm.point_root, :2]
    zr = r[:, ::-1] * (-1.0, 1.0)                             # z x r (planar: w, alpha along z)
    w, al = d.cvel[b, 2:3], d.cacc[b, 2:3]
    v = d.cvel[b, 3:5] + w * zr
    a = d.cacc[b, 3:5] + al * zr + w * v[:, ::-1] * (-1.0, 1.0) + m.opt.gravity[:2]
    out = np.empty((3,) + p.shape)
    out[0], out[1], out[2] = p, v, a
    return out


# ----------------------------------------------------------------------------- exact route

def _kinematics(m, d) -> None:
    """The position and velocity stages that inverse dynamics needs: body poses, CoM-frame
    inertias and dofs (mj_kinematics, mj_comPos), the constraint rows efc_J (mj_makeConstraint),
    body velocities and cdof_dot (mj_comVel). This is mj_fwdPosition + mj_fwdVelocity without
    factorising the inertia matrix, which is singular when a leaf body is massless (the exact
    route keeps massless links massless) and is not needed here."""
    import mujoco
    mujoco.mj_kinematics(m, d)
    mujoco.mj_comPos(m, d)
    mujoco.mj_makeConstraint(m, d)
    mujoco.mj_comVel(m, d)


def solve(scene: Scene, keep_floors: bool = False) -> EngineResult:
    """Driving moment and reactions by MuJoCo's inverse dynamics at the exact state of every
    angle (route "exact"; see the module docstring). NaN at the solver's singular angles.

    `keep_floors=True` leaves the MJCF's placeholder masses of massless bodies in the model
    instead of writing the exact zeros back (only to show that they do not matter).
    Raises RuntimeError if a dropped (out-of-plane) constraint row is not identically zero.
    """
    import mujoco
    t0 = time.perf_counter()
    mm = _compile(scene, EXACT_FLOOR, exact_masses=not keep_floors)
    build = time.perf_counter() - t0

    t0 = time.perf_counter()
    m, d = mm.m, mm.d
    N, nv = len(scene.phi_deg), m.nv
    qpos, qvel, qacc = _exact_state(scene, mm)
    F_ext, M_ext = scene.external()
    M_drive = np.full(N, np.nan)
    R = np.full((N, len(scene.mech.pairs), 2), np.nan)
    kin = np.full((3, N, len(mm.point_site), 2), np.nan)
    rne = np.zeros(nv)
    S = np.zeros(nv)
    S[mm.crank_dof] = 1.0
    gap, off_plane = 0.0, 0.0
    _kinematics(m, d)                                   # every equality is always active: fixed rows
    rows = np.concatenate([_rows(mm, p.index) for p in scene.cuts] + [np.zeros(0, int)])
    dropped = np.setdiff1d(np.arange(d.ne), rows)
    for i in range(N):
        if scene.res.singular[i]:
            continue
        d.qpos[:], d.qvel[:], d.qacc[:] = qpos[i], qvel[i], qacc[i]
        _kinematics(m, d)
        mujoco.mj_rne(m, d, 1, rne)                     # M qacc + bias (Coriolis, centrifugal, gravity)
        Q = _applied(scene, mm, F_ext[i], M_ext[i])
        J = d.efc_J[:d.nefc * nv].reshape(d.nefc, nv)
        off_plane = max(off_plane, float(np.abs(J[dropped]).max(initial=0.0)))
        gap = max(gap, float(np.abs(d.efc_pos[:d.ne]).max(initial=0.0)))
        x = np.linalg.solve(np.column_stack([S, J[rows].T]), rne - Q)
        d.efc_force[:d.nefc] = 0.0
        d.efc_force[rows] = x[1:]
        mujoco.mj_rnePostConstraint(m, d)               # cfrc_int from qacc, efc_force, xfrc_applied
        M_drive[i] = x[0]
        R[i] = _reactions(scene, mm, x[0])
        kin[:, i] = _point_kinematics(mm)
    if off_plane > OFF_PLANE_TOL:
        raise RuntimeError(f"an out-of-plane constraint row is not zero (|J| up to {off_plane:.3g}): "
                           f"the MJCF is not planar")
    run = time.perf_counter() - t0
    masses = "placeholder floors kept" if keep_floors else "massless bodies exactly massless"
    return EngineResult("mujoco", "exact", scene.phi_deg.copy(), M_drive, R,
                        points=tracked_points(scene.mech), x=kin[0], v=kin[1], a=kin[2], build_seconds=build, run_seconds=run,
                        note=f"MuJoCo {mujoco.__version__}: [S | J^T][tau; lambda] = mj_rne - applied at the "
                             f"exact state, reactions from cfrc_int (tree) and efc_force (cuts); {masses}; "
                             f"largest loop-closure gap at the exact state {gap:.2g} (m or rad)")


# ----------------------------------------------------------------------------- simulation route

def simulate(scene: Scene, steps_per_rev: int = SIM_STEPS_PER_REV, run_in_deg: float = 30.0,
             timeconst_steps: float = 2.0, impedance: float = 0.9999,
             floor: float = SIM_FLOOR) -> EngineResult:
    """Driving moment, reactions and point kinematics from MuJoCo's forward dynamics (route
    "simulation"), stepped by MuJoCo's own multi-step rollout (`mujoco.rollout`, C++), without a
    Python loop over the steps.

    The mechanism starts `run_in_deg` before the first sample angle in the exact state there
    (joint coordinates and rates from the scene's motion) and is integrated by MuJoCo
    (semi-implicit Euler, `mj_step`) at `steps_per_rev` uniform steps per crank revolution.

    Drive (prescribed crank motion): a "clock", a flywheel on its own hinge with an inertia
    CLOCK_INERTIA times a bound of the driving moment over omega^2 (it loses at most
    2 pi / CLOCK_INERTIA of its speed in a revolution), turns at the crank speed, and a joint
    equality constraint ties the crank's angle to it (the crank's weight in the constraint's
    regularisation is the clock's, so the tie is stiff: it follows the Baumgarte reference of the
    loop constraints with no extra softness). The driving moment is that constraint's force:
    MuJoCo's own, at the simulated state. The solver's torque and reactions are never used.

    Loop closures are MuJoCo's soft equality constraints made as stiff as MuJoCo allows:
    solref time constant `timeconst_steps` time steps (MuJoCo's stability floor is 2 steps)
    with critical damping, constant impedance `impedance` (MuJoCo's maximum is 0.9999).
    The error falls as 1/steps_per_rev (first order: semi-implicit Euler with the Baumgarte
    stabilisation tied to the step).

    Applied loads (gas force tables, forces against the velocity, springs) are evaluated by
    kinetostat's load model at the exact state of each step's crank angle and passed to the
    rollout as its open-loop control (`xfrc_applied` at the centres of mass, per step).

    Samples: the rollout returns the state after every step. At each sample instant (the
    previous step's state, advanced by one partial step where the instant falls between
    steps) `mj_forward` recomputes what MuJoCo computed in that step: the constraint forces
    (`efc_force`), then `mj_rnePostConstraint` the joint forces `cfrc_int` and the sites'
    accelerations; the loads there are the solver's at that angle (a load against the velocity
    flips at a dead centre). A working machine's drive is the gear mesh force, as in `solve`.
    Needs a constant crank speed (drive.eps = 0): kinetostat's state at every angle has
    omega = drive.omega, and a crank that accelerates passes through no two of them.
    """
    import mujoco
    from mujoco import rollout
    mech = scene.mech
    if mech.drive.eps != 0.0:
        raise ValueError(f"simulate: the crank must turn at a constant speed (drive.eps = 0), got "
                         f"drive.eps = {mech.drive.eps} rad/s^2: kinetostat's states at different "
                         f"angles all have omega = drive.omega, which no accelerating motion passes through")
    if not (isinstance(steps_per_rev, (int, np.integer)) and steps_per_rev >= 4):
        raise ValueError(f"steps_per_rev: expected an integer >= 4, got {steps_per_rev!r}")
    t0 = time.perf_counter()
    omega = mech.drive.omega                                     # rad/s, > 0, in the drive's sense
    T = 2 * math.pi / omega
    dt = T / steps_per_rev
    tc = timeconst_steps * dt

    # uniform steps from the run-in start; the sample instants (between steps or on them)
    phi = scene.phi_deg
    N = len(phi)
    t_sample = run_in_deg / 360 * T + ((phi - phi[0]) % 360.0) / 360.0 * T
    n_steps = int(math.ceil(t_sample.max() / dt - 1e-9))
    t_grid = np.arange(n_steps + 1) * dt
    dense = _dense_scene(scene, phi[0] - run_in_deg + np.degrees(omega * t_grid))
    if dense.res.singular.any():
        bad = np.unique(np.round(dense.phi_deg[dense.res.singular] % 360.0, 3))
        raise ValueError(f"simulate: the motion passes through singular positions at phi = {bad.tolist()} deg; "
                         f"a simulation cannot follow it there (use the exact route)")
    F_ext, M_ext = dense.external()
    mm = _compile(scene, floor, exact_masses=False, timestep=dt, solref=(tc, 1.0),
                  solimp=(impedance, impedance, 0.001, 0.5, 2.0),
                  clock_inertia=CLOCK_INERTIA * _moment_bound(scene, F_ext, M_ext) / omega**2)
    m, d = mm.m, mm.d
    if timeconst_steps < 2.0:
        m.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_REFSAFE
    _regularisation_weights(scene, mm)
    m.dof_invweight0[mm.crank_dof] = m.dof_invweight0[mm.clock_dof]
    build = time.perf_counter() - t0

    t0 = time.perf_counter()
    qpos, qvel, _ = _exact_state(dense, mm)
    c, q_ref = mm.crank_dof, np.unwrap(dense.q[:, scene.crank_joint])
    d.qpos[:], d.qvel[:] = qpos[0], qvel[0]
    d.qpos[c] = d.qpos[mm.clock_dof] = q_ref[0]
    d.qvel[mm.clock_dof] = dense.qd[0, scene.crank_joint]
    d.time = 0.0
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    state0 = np.zeros(mujoco.mj_stateSize(m, spec))
    mujoco.mj_getState(m, d, state0, spec)
    xfrc = _xfrc(scene, mm, F_ext, M_ext)
    states, _ = rollout.rollout(m, d, state0[None], xfrc[None, :n_steps].reshape(1, n_steps, -1),
                                control_spec=mujoco.mjtState.mjSTATE_XFRC_APPLIED, nstep=n_steps)
    states = np.concatenate([state0[None], states[0]])          # state at every grid instant

    F_s, M_s = scene.external()          # at the samples: the very loads the solver had
    x_s = _xfrc(scene, mm, F_s, M_s)
    M_drive = np.full(N, np.nan)
    R = np.full((N, len(mech.pairs), 2), np.nan)
    kin = np.full((3, N, len(mm.point_site), 2), np.nan)
    drift = 0.0
    for k, t in enumerate(t_sample):
        n = int(math.floor(t / dt + 1e-9))
        mujoco.mj_setState(m, d, states[n], spec)
        if t - n * dt > 1e-9 * dt:                              # a partial step to the instant
            d.xfrc_applied[:] = xfrc[n]
            m.opt.timestep = t - n * dt
            mujoco.mj_step(m, d)
            m.opt.timestep = dt
        d.xfrc_applied[:] = x_s[k]
        mujoco.mj_forward(m, d)
        mujoco.mj_rnePostConstraint(m, d)
        M_drive[k] = d.efc_force[_drive_row(mm)]
        R[k] = _reactions(scene, mm, M_drive[k])
        kin[:, k] = _point_kinematics(mm)
        drift = max(drift, float(np.max(np.abs(d.efc_pos[:d.ne]))))
    run = time.perf_counter() - t0
    return EngineResult("mujoco", "simulation", phi.copy(), M_drive, R, points=tracked_points(mech),
                        x=kin[0], v=kin[1], a=kin[2], build_seconds=build, run_seconds=run,
                        note=f"MuJoCo {mujoco.__version__} forward dynamics by mujoco.rollout, semi-implicit "
                             f"Euler, {steps_per_rev} steps/rev (dt = {dt:.3g} s), run-in {run_in_deg} deg; "
                             f"crank tied to a clock flywheel (joint equality); equality solref ({tc:.3g} s, 1), "
                             f"impedance {impedance}; mass/inertia floor {floor} x scale; largest constraint "
                             f"violation at the samples {drift:.2g} (m or rad)")


def _moment_bound(scene: Scene, F_ext: np.ndarray, M_ext: np.ndarray) -> float:
    """A bound of the driving moment's size from the model alone, N m: inertia (the largest
    m size^2 or I_S, times omega^2), weights and applied loads times the mechanism's size."""
    _, I = _scales(scene)
    size, omega = scene.mech.size, scene.mech.drive.omega
    weight = sum(b.mass for b in scene.bodies) * scene.g
    loads = np.nanmax(np.linalg.norm(F_ext, axis=-1).sum(axis=-1), initial=0.0)
    return I * omega**2 + size * (weight + loads) + np.nanmax(np.abs(M_ext).sum(axis=-1), initial=0.0)


def _xfrc(scene: Scene, mm: _Model, F: np.ndarray, M: np.ndarray) -> np.ndarray:
    """(N, nbody, 6) xfrc_applied of the loads F (N, L, 2) at the centres of mass and moments
    M (N, L): force then torque, world frame."""
    out = np.zeros((len(F), mm.m.nbody, 6))
    for b in scene.bodies:
        k = mm.body[b.link]
        out[:, k, :2] = F[:, b.link]
        out[:, k, 5] = M[:, b.link]
    return out


def _drive_row(mm: _Model) -> int:
    """efc row of the clock's joint equality (its force is the torque on the crank)."""
    return int(np.flatnonzero(mm.d.efc_id[:mm.d.ne] == mm.drive_eq)[0])


def _regularisation_weights(scene: Scene, mm: _Model) -> None:
    """Give floor-mass bodies (massless links, slot helpers) their tree parent's invweight0.

    MuJoCo regularises a constraint row with R = (1 - d)/d times an estimate of the row's
    inverse inertia summed from `body_invweight0` of the two bodies (their inverse inertia at
    qpos0). A body that carries only a floor mass would make that estimate ~1/floor and the
    constraint ~1/floor times softer than intended (the shaper's slots came out 100 % wrong).
    Its motion is in fact set by its neighbours, so it borrows its parent's weights.
    """
    import mujoco
    m = mm.m
    light = [(mm.body[b.link], [b.mass == 0.0, b.I_S == 0.0]) for b in scene.bodies]
    light += [(mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, f"slot{p.index}"), [True, True])
              for p in _slider_cuts(scene)]
    for k, floored in sorted(light):              # parents (lower ids) first
        parent = m.body_parentid[k]
        for c in (0, 1):                          # translation, rotation
            if floored[c]:
                m.body_invweight0[k, c] = m.body_invweight0[parent, c]


def _dense_scene(scene: Scene, phi_deg: np.ndarray) -> Scene:
    """The scene's mechanism on another grid of angles (exact states and loads at each)."""
    from .scene import build_scene
    return build_scene(scene.mech, phi_deg=phi_deg)
