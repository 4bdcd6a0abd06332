"""Pinocchio adapter: constrained inverse dynamics of the scene's tree at the exact state.

The scene's spanning tree becomes one `pin.Model` embedded in 3-D (the plane z = 0): a
revolute pair is a `JointModelRZ` (q is the angle, nq = 1), a prismatic pair a
`JointModelPrismaticUnaligned` along the in-plane guide direction. Every joint frame is its
child link's local frame shifted to the child's anchor (`anchor_child`), so a link-local point
p sits at p - anchor_child in its joint frame (link 0, the frame, is the world itself).

Loop closures (the scene's cut pairs):

- cut R pair: a `RigidConstraintModel(CONTACT_3D)` between the two links at the pin, in
  LOCAL_WORLD_ALIGNED axes; its z row is identically zero in a planar model and is dropped.
  Measured on pin 4.1.0: the constraint's velocity is v(c1 on body 1) - v(c2 on body 2), so
  lambda is the world force applied to the FIRST body (pair.links[0]); the force of links[0]
  on links[1] is -lambda.
- cut P pair: two rows built here from Pinocchio's joint Jacobians (LOCAL_WORLD_ALIGNED):
  n . (v_X(guide) - v_X(slider)) and omega_guide - omega_slider, X the slider point (on the
  guide line), n the guide's world normal. These are exactly the derivatives of the pair's two
  holonomic constraints (slider point on the guide line, relative rotation locked) at an
  assembled state, and their drift (J-dot v) is written out below, so the forward round trip is
  exact too. A CONTACT_6D model (LOCAL, frame 1 on the guide with x along the guide, frame 2
  at the slider point) restricted to its normal (1) and rotation (5) rows spans the same rows
  (checked to 7e-16 on the three slotted-link models), which is enough for inverse dynamics;
  but Pinocchio has no sliding rigid constraint, its 6-D drift is for two frames held together
  and calc() does not fill it anyway, so the own rows give one definition for both Jacobian
  and drift (Jc qdd_exact = gamma to rounding).

Inverse dynamics at each angle: b = rnea(q, v, a, fext) with the applied non-gravity loads as
fext; [S | Jc^T] [tau; lambda] = b (square: nv = 1 + 2 n_cuts for a one-DOF planar linkage).
The constraint forces are then fed back as fext and rnea is called again: data.f[i] is the
wrench of the parent link on joint i's subtree in joint i's frame; its force part is the pair
force of parent on child (rotated to world). The residual of that second rnea against S tau
checks the fext mapping and is reported in `note`.

Working machines (drive.kind = "machine"): the drive is the pinion's force F_bal on the
crank's gear, not a pure couple. The driving moment is the same (the crank turns about its
pivot), but the frame's reaction on the crank differs by F_bal; it is computed from this
engine's own tau with the solver's gear convention (`gear_force`, see `Scene` docstring) and
applied to the crank as an external force in the second rnea.

May use: kinetostat (planar, gear_force), the scene, pinocchio.
"""
from __future__ import annotations

import math
import time

import numpy as np
import pinocchio as pin

from kinetostat.kinetostatics import gear_force
from kinetostat.planar import rotate

from .scene import EngineResult, Scene, tracked_points

__all__ = ["solve", "forward_round_trip", "PinocchioScene"]

def _v3(p) -> np.ndarray:
    return np.array([float(p[0]), float(p[1]), 0.0])


def _rz(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def _rot90(a: np.ndarray) -> np.ndarray:
    return np.array([-a[1], a[0], 0.0])


class PinocchioScene:
    """The pin.Model, its data and the loop closures of one scene, built once."""

    def __init__(self, scene: Scene):
        self.scene = scene
        model = pin.Model()
        model.gravity = pin.Motion(np.array([0.0, -scene.g, 0.0]) if scene.g else np.zeros(3), np.zeros(3))
        # link -> (joint id, offset of the link frame's points in the joint frame)
        self.jid = {0: 0}
        self.off = {0: np.zeros(2)}
        for n in self._depth_first(scene):
            j, b = scene.joints[n], scene.bodies[n]
            assert j.child == b.link, "scene bodies and joints must be in the same tree order"
            placement = pin.SE3(_rz(j.rel_angle), _v3(np.asarray(j.anchor_parent) - self.off[j.parent]))
            if j.kind == "R":
                jm = pin.JointModelRZ()
            else:
                jm = pin.JointModelPrismaticUnaligned(_rz(j.rel_angle).T @ _v3(j.axis))
            jid = model.addJoint(self.jid[j.parent], jm, placement, f"pair{j.pair.index}_link{j.child}")
            self.jid[j.child] = jid
            self.off[j.child] = np.asarray(j.anchor_child, float)
            if b.mass > 0 or b.I_S > 0:          # a massless link carries no inertia at all
                lever = _v3(np.asarray(b.com) - self.off[b.link])
                # out-of-plane inertias never enter planar motion (omega is along z): zero
                model.appendBodyToJoint(jid, pin.Inertia(b.mass, lever, np.diag([0.0, 0.0, b.I_S])), pin.SE3.Identity())
        self.model = model
        self.data = model.createData()
        self.nv = model.nv
        self.crank_v = model.joints[self.jid[scene.joints[scene.crank_joint].child]].idx_v
        self.q_idx = [model.joints[self.jid[j.child]].idx_q for j in scene.joints]
        self.v_idx = [model.joints[self.jid[j.child]].idx_v for j in scene.joints]

        # loop closures
        self.r_cuts, self.p_cuts = [], []
        self.cmodels = pin.StdVec_RigidConstraintModel()
        for pair in scene.cuts:
            a, c = pair.links
            if pair.kind == "R":
                m1 = pin.SE3(np.eye(3), _v3(self._local(a, pair.point)))
                m2 = pin.SE3(np.eye(3), _v3(self._local(c, pair.point)))
                cm = pin.RigidConstraintModel(pin.ContactType.CONTACT_3D, model, self.jid[a], m1,
                                              self.jid[c], m2, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)
                self.cmodels.append(cm)
                self.r_cuts.append(pair)
            else:
                # slider point (slider link) and the guide direction (guide link's joint frame)
                self.p_cuts.append((pair, _v3(self._local(c, pair.point)), _v3(pair.direction)))
        self.cdatas = pin.StdVec_RigidConstraintData()
        for cm in self.cmodels:
            self.cdatas.append(cm.createData())

        # applied loads: body com in its joint frame
        self.com_local = {b.link: _v3(np.asarray(b.com) - self.off[b.link]) for b in scene.bodies}
        F, M = scene.external()
        self.F_ext, self.M_ext = F, M
        self.has_ext = bool(np.any(F[:, 1:] != 0) or np.any(M[:, 1:] != 0))
        # working machine: the drive is a gear force on the crank
        dr = scene.mech.drive
        self.gear = dr.gear if dr.kind == "machine" else None
        # the P cuts' guide angle minus slider angle at the scene's first state: constraint_gap's zero
        pin.forwardKinematics(model, self.data, self.state(0)[0])
        self.p_angles = [self._angle(p.links[0]) - self._angle(p.links[1]) for p, _, _ in self.p_cuts]

    @staticmethod
    def _depth_first(scene: Scene) -> list[int]:
        """Scene joint indices in depth-first pre-order. Pinocchio's crba (and every algorithm
        that works on a joint's subtree as one contiguous block of velocity indices) needs
        each subtree's joints to be added consecutively; the scene's breadth-first order
        breaks that as soon as the frame has two children (rnea and the Jacobians still come
        out right, the mass matrix does not)."""
        order: list[int] = []

        def visit(link: int) -> None:
            for n, j in enumerate(scene.joints):
                if j.parent == link:
                    order.append(n)
                    visit(j.child)

        visit(0)
        return order

    # -- geometry helpers
    def _angle(self, link: int) -> float:
        """The world angle of `link`'s joint frame (needs data.oMi), rad."""
        R = self.data.oMi[self.jid[link]].rotation
        return math.atan2(R[1, 0], R[0, 0])

    def _local(self, link: int, name: str) -> np.ndarray:
        return np.asarray(self.scene.mech.links[link].points[name], float) - self.off[link]

    def state(self, n: int):
        sc, nq = self.scene, self.model.nq
        q, v, a = np.zeros(nq), np.zeros(self.nv), np.zeros(self.nv)
        q[self.q_idx], v[self.v_idx], a[self.v_idx] = sc.q[n], sc.qd[n], sc.qdd[n]
        return q, v, a

    def _world_force(self, link: int, f: np.ndarray, point: np.ndarray, moment: float = 0.0) -> pin.Force:
        """In-plane force f (3,) at world point (3,) plus moment about z, as the joint-local
        spatial force of `link`'s joint (Pinocchio's fext convention). Needs data.oMi."""
        mz = point[0] * f[1] - point[1] * f[0] + moment          # moment about the world origin
        return self.data.oMi[self.jid[link]].actInv(pin.Force(f, np.array([0.0, 0.0, mz])))

    def applied_fext(self, n: int) -> pin.StdVec_Force:
        """The scene's applied loads at angle n as Pinocchio's fext (needs data.oMi)."""
        return self.fext(self.F_ext[n], self.M_ext[n]) if self.has_ext else self.fext()

    def fext(self, F: np.ndarray | None = None, M: np.ndarray | None = None) -> pin.StdVec_Force:
        """Loads F (L, 2), N, at the centres of mass and M (L,), N m, about them (world) as
        Pinocchio's fext, one joint-local spatial force per joint (needs data.oMi); none: zeros."""
        fext = pin.StdVec_Force()
        for _ in range(self.model.njoints):
            fext.append(pin.Force.Zero())
        if F is None:
            return fext
        for b in self.scene.bodies:
            k = b.link
            if F[k, 0] == 0 and F[k, 1] == 0 and M[k] == 0:
                continue
            S = self.data.oMi[self.jid[k]].act(self.com_local[k])
            fext[self.jid[k]] += self._world_force(k, _v3(F[k]), S, float(M[k]))
        return fext

    def _point_motion(self, link: int, X: np.ndarray):
        """World velocity and classical acceleration (from data.v, data.a) of the material
        point of `link` at world position X, its linear Jacobian (3, nv) and angular z row
        (nv,), world axes. Planar: every angular velocity is along z."""
        jid = self.jid[link]
        if jid == 0:
            return np.zeros(3), np.zeros(3), np.zeros((3, self.nv)), np.zeros(self.nv)
        oMi = self.data.oMi[jid]
        r = X - oMi.translation                       # world lever from the joint origin
        J = pin.getJointJacobian(self.model, self.data, jid, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)
        Jw = J[5]
        Jp = J[:3].copy()                             # v_X = v_o + w_z rot90(r)
        Jp[0] -= r[1] * Jw
        Jp[1] += r[0] * Jw
        R = oMi.rotation
        v, a = self.data.v[jid], self.data.a[jid]
        w, al = v.angular[2], a.angular[2]
        vl = v.linear
        vo = R @ vl                                   # velocity of the joint origin, world
        ao = R @ (a.linear + w * np.array([-vl[1], vl[0], 0.0]))   # its classical acceleration
        rr = np.array([-r[1], r[0], 0.0])
        vX = vo + w * rr
        aX = ao + al * rr - w * w * r
        return vX, aX, Jp, Jw

    def frame_motion(self, q, v, a) -> np.ndarray:
        """(L, 9) per link (row 0, the frame: zeros) the motion of its joint frame by Pinocchio's
        forwardKinematics(q, v, a), world axes: origin x, y (m), angle (rad), origin velocity
        x, y (m/s), angular velocity (rad/s), classical origin acceleration x, y (m/s^2),
        angular acceleration (rad/s^2)."""
        pin.forwardKinematics(self.model, self.data, q, v, a)
        out = np.zeros((self.scene.mech.n_links, 9))
        for k, jid in self.jid.items():
            if not jid:
                continue
            oMi, vj, aj = self.data.oMi[jid], self.data.v[jid], self.data.a[jid]
            R, vl, w = oMi.rotation, vj.linear, vj.angular[2]
            ao = R @ (aj.linear + w * np.array([-vl[1], vl[0], 0.0]))    # classical, joint origin
            out[k] = (*oMi.translation[:2], math.atan2(R[1, 0], R[0, 0]), *(R @ vl)[:2], w, *ao[:2],
                      aj.angular[2])
        return out

    def point_kinematics(self, points, frames: np.ndarray) -> np.ndarray:
        """(3, N, n_points, 2) position, velocity and classical acceleration (world; m, m/s,
        m/s^2) of the (point name, link) `points` from `frame_motion` at N states (N, L, 9)."""
        out = np.zeros((3, len(frames), len(points), 2))
        for i, (name, k) in enumerate(points):
            f = frames[:, k]
            r = rotate(self._local(k, name), f[:, 2])
            rp = np.stack([-r[:, 1], r[:, 0]], axis=-1)          # z x r
            w, al = f[:, 5:6], f[:, 8:9]
            out[0, :, i] = f[:, :2] + r
            out[1, :, i] = f[:, 3:5] + w * rp
            out[2, :, i] = f[:, 6:8] + al * rp - w**2 * r
        return out

    def p_rows(self, with_drift: bool):
        """Rows (2 per P cut) of the P cuts' constraint Jacobian, their drift J-dot v
        (needs data.v, data.a with a = 0), and (X, n) per cut for the forces."""
        rows, drift, geo = [], [], []
        for pair, x_slider, d_guide in self.p_cuts:
            g, s = pair.links
            X = self.data.oMi[self.jid[s]].act(x_slider)
            Rg = self.data.oMi[self.jid[g]].rotation if self.jid[g] else np.eye(3)
            n = Rg @ _rot90(d_guide)
            vg, ag, Jg, Wg = self._point_motion(g, X)
            vs, as_, Js, Ws = self._point_motion(s, X)
            rows += [n @ (Jg - Js), Wg - Ws]
            if with_drift:
                # c = (X_s - X_g) . n(theta_g) = 0, X_g the guide's material point at X (the
                # rows above are -dc/dq); c'' = n . (a_s - a_g) + 2 w_g rot90(n) . (v_s - v_g)
                # + (X_s - X_g) . n'' (zero here), so rows @ qdd = n . (a0_s - a0_g) + 2 w_g ...
                # with a0 the classical accelerations at qdd = 0
                wg = Rg @ self.data.v[self.jid[g]].angular if self.jid[g] else np.zeros(3)
                drift += [n @ (as_ - ag) + 2 * wg[2] * (_rot90(n) @ (vs - vg)), 0.0]
            geo.append((X, n))
        return np.array(rows).reshape(-1, self.nv), np.array(drift), geo

    def constraint_gap(self, q) -> np.ndarray:
        """The loop closures' position errors at q, in the rows of `constraint_jacobian` (whose
        rows times v are their rates): R cuts the pin on the first link minus on the second
        (x, y, m); P cuts the guide line's offset from the slider point along the guide's normal
        (m) and the guide's angle minus the slider's less their angle at the scene's first state
        (rad). Sets data.oMi."""
        model, data = self.model, self.data
        pin.forwardKinematics(model, data, q)
        gap = []
        for cm, cd, pair in zip(self.cmodels, self.cdatas, self.r_cuts):
            cm.calc(model, data, cd)
            gap += list((cd.oMc1.translation - cd.oMc2.translation)[:2])
        for (pair, x_slider, d_guide), a0 in zip(self.p_cuts, self.p_angles):
            g, s = pair.links
            X = data.oMi[self.jid[s]].act(x_slider)
            G = data.oMi[self.jid[g]].act(_v3(self._local(g, pair.guide)))      # oMi[0]: the world itself
            n = data.oMi[self.jid[g]].rotation @ _rot90(d_guide)
            gap += [(G - X) @ n, (self._angle(g) - self._angle(s) - a0 + math.pi) % (2 * math.pi) - math.pi]
        return np.array(gap)

    def constraint_jacobian(self, q, with_drift=False, v=None):
        """Stacked in-plane constraint rows (n_con, nv): R cuts (x, y world) then P cuts."""
        model, data = self.model, self.data
        pin.computeJointJacobians(model, data, q)
        if with_drift:
            pin.forwardKinematics(model, data, q, v, np.zeros(self.nv))   # data.v, data.a at qdd = 0
        for cm, cd in zip(self.cmodels, self.cdatas):
            cm.calc(model, data, cd)                  # BEFORE getConstraintsJacobian (stale otherwise)
        blocks, drifts = [], []
        if len(self.cmodels):
            Jr = pin.getConstraintsJacobian(model, data, self.cmodels, self.cdatas)
            keep = np.ravel([[3 * i, 3 * i + 1] for i in range(len(self.cmodels))])
            blocks.append(Jr[keep])
            if with_drift:
                # J-dot v of a LWA point constraint: the relative classical acceleration
                # c1 - c2 at qdd = 0 (what constraintDynamics stores in
                # contact1_acceleration_drift; calc() alone does not fill it)
                for pair, cd in zip(self.r_cuts, self.cdatas):
                    a1 = self._point_motion(pair.links[0], cd.oMc1.translation)[1]
                    a2 = self._point_motion(pair.links[1], cd.oMc2.translation)[1]
                    drifts.append(-(a1 - a2)[:2])
        Jp, dp, geo = self.p_rows(with_drift)
        blocks.append(Jp)
        if with_drift:
            drifts.append(dp)
        Jc = np.vstack(blocks) if blocks else np.zeros((0, self.nv))
        gamma = np.concatenate(drifts) if with_drift and drifts else np.zeros(0)
        return Jc, gamma, geo


def _machine_force(gear, tau: float) -> tuple[np.ndarray, np.ndarray]:
    """The pinion's force on the crank's gear (world, (3,)) for driving moment tau (the solver's
    convention, `kinetostat.kinetostatics.gear_force`), and the pitch point relative to the pivot."""
    F = gear_force(gear, np.array([tau]))[0]
    return _v3(F), _v3(gear.r_w * np.asarray(gear.centre_direction, float))


def solve(scene: Scene) -> EngineResult:
    """Driving moment and every pair's reaction by Pinocchio at the scene's exact states."""
    t0 = time.perf_counter()
    ps = PinocchioScene(scene)
    build = time.perf_counter() - t0
    t0 = time.perf_counter()
    model, data = ps.model, ps.data
    N, n_pairs = scene.q.shape[0], len(scene.mech.pairs)
    M_drive = np.full(N, np.nan)
    R = np.full((N, n_pairs, 2), np.nan)
    points = tracked_points(scene.mech)
    frames = np.full((N, scene.mech.n_links, 9), np.nan)
    S = np.zeros(ps.nv)
    S[ps.crank_v] = 1.0
    crank_link = scene.joints[scene.crank_joint].child
    pivot = None
    worst = 0.0
    for n in range(N):
        if not (np.isfinite(scene.q[n]).all() and np.isfinite(scene.qd[n]).all() and np.isfinite(scene.qdd[n]).all()):
            continue                                   # singular position: the solver's NaN too
        q, v, a = ps.state(n)
        Jc, _, geo = ps.constraint_jacobian(q)         # also sets data.oMi for the loads
        fext = ps.applied_fext(n)
        b = pin.rnea(model, data, q, v, a, fext).copy()
        A = np.column_stack([S, Jc.T])
        try:
            x = np.linalg.solve(A, b)
        except np.linalg.LinAlgError:                  # exactly singular position
            continue
        tau, lam = x[0], x[1:]
        M_drive[n] = tau
        # feed the constraint forces back as external loads on both bodies of each cut
        k = 0
        for cd, pair in zip(ps.cdatas, ps.r_cuts):
            f = np.array([lam[k], lam[k + 1], 0.0])    # world force on the first body
            X = cd.oMc1.translation
            i, j = pair.links
            if ps.jid[i]:
                fext[ps.jid[i]] += ps._world_force(i, f, X)
            if ps.jid[j]:
                fext[ps.jid[j]] += ps._world_force(j, -f, cd.oMc2.translation)
            R[n, pair.index] = -f[:2]
            k += 2
        for (pair, _, _), (X, nrm) in zip(ps.p_cuts, geo):
            f, m = lam[k] * nrm, lam[k + 1]            # on the guide (first body)
            g, s = pair.links
            if ps.jid[g]:
                fext[ps.jid[g]] += ps._world_force(g, f, X, m)
            if ps.jid[s]:
                fext[ps.jid[s]] += ps._world_force(s, -f, X, -m)
            R[n, pair.index] = -f[:2]
            k += 2
        if ps.gear is not None:
            F_bal, r_pitch = _machine_force(ps.gear, tau)
            if pivot is None:
                pivot = data.oMi[ps.jid[crank_link]].translation.copy()   # fixed pivot of the crank
            fext[ps.jid[crank_link]] += ps._world_force(crank_link, F_bal, pivot + r_pitch)
        tau2 = pin.rnea(model, data, q, v, a, fext)
        res = tau2.copy()
        res[ps.crank_v] -= 0.0 if ps.gear is not None else tau   # the gear force carries tau
        worst = max(worst, float(np.max(np.abs(res))))
        for j in scene.joints:
            jid = ps.jid[j.child]
            fw = data.oMi[jid].rotation @ data.f[jid].linear   # parent on child, world
            R[n, j.pair.index] = fw[:2] if j.pair.links[0] == j.parent else -fw[:2]
        frames[n] = ps.frame_motion(q, v, a)
    xp, vp, ap = ps.point_kinematics(points, frames)
    run = time.perf_counter() - t0
    scale = np.nanmax(np.abs(M_drive)) if np.isfinite(M_drive).any() else 1.0
    note = (f"pin {pin.__version__}; {model.nv} joints, {len(ps.r_cuts)} CONTACT_3D + {len(ps.p_cuts)} "
            f"P-row loop closures; constraint forces fed back as fext reproduce S tau to "
            f"{worst / (scale or 1.0):.1e} of max|tau|")
    return EngineResult("pinocchio", "exact", scene.phi_deg.copy(), M_drive, R, points=points, x=xp, v=vp, a=ap,
                        build_seconds=build, run_seconds=run, note=note)


def forward_round_trip(scene: Scene, tau: np.ndarray, method: str = "auto") -> np.ndarray:
    """Constrained forward dynamics driven by the crank moment `tau` (N,) at the scene's exact
    q, qdot: returns the crank acceleration minus the prescribed one, (N,), rad/s^2 (NaN at
    singular positions). The applied non-gravity loads enter as generalised forces.

    method "kkt": the KKT system of Pinocchio's mass matrix (crba), rnea(q, v, 0, fext),
      constraint Jacobian and drift (J-dot v): [M -Jc^T; Jc 0] [qdd; lambda] = [S tau - b; gamma].

    method "constraintDynamics": Pinocchio's own `pin.constraintDynamics` (proximal Cholesky);
      its rigid constraints cannot slide, so it needs a scene whose cut pairs are all revolute.

    "auto": constraintDynamics when every cut is revolute, the KKT otherwise.
    """
    ps = PinocchioScene(scene)
    if method == "auto":
        method = "constraintDynamics" if not ps.p_cuts else "kkt"
    if method not in ("kkt", "constraintDynamics"):
        raise ValueError(f"method: expected 'auto', 'kkt' or 'constraintDynamics', got {method!r}")
    if method == "constraintDynamics" and ps.p_cuts:
        raise ValueError("constraintDynamics has no sliding constraint: the scene cuts a prismatic pair "
                         f"({', '.join(p.label for p, _, _ in ps.p_cuts)}); use method='kkt'")
    model, data = ps.model, ps.data
    tau = np.asarray(tau, float)
    N = scene.q.shape[0]
    err = np.full(N, np.nan)
    S = np.zeros(ps.nv)
    S[ps.crank_v] = 1.0
    zero = np.zeros(ps.nv)
    if method == "constraintDynamics":
        pin.initConstraintDynamics(model, data, ps.cmodels, ps.cdatas)
        # the z rows of CONTACT_3D are identically zero: the proximal iterations absorb that
        # rank deficiency (mu small against the Delassus matrix, converges in 3-4 iterations)
        prox = pin.ProximalSettings(1e-14, 1e-10, 50)
    for n in range(N):
        if not (np.isfinite(scene.q[n]).all() and np.isfinite(scene.qd[n]).all() and np.isfinite(tau[n])):
            continue
        q, v, a_exact = ps.state(n)
        if method == "kkt":
            Jc, gamma, _ = ps.constraint_jacobian(q, with_drift=True, v=v)
            b = pin.rnea(model, data, q, v, zero, ps.applied_fext(n)).copy()   # nle - gen. loads
            M = pin.crba(model, data, q)
            M = np.triu(M) + np.triu(M, 1).T                             # crba fills the upper part
            m = Jc.shape[0]
            K = np.block([[M, -Jc.T], [Jc, np.zeros((m, m))]])
            try:
                qdd = np.linalg.solve(K, np.concatenate([S * tau[n] - b, gamma]))
            except np.linalg.LinAlgError:
                continue
        else:
            pin.computeJointJacobians(model, data, q)                    # oMi for the loads
            fext = ps.applied_fext(n)
            # generalised loads (rnea returns data.tau itself: copy before the second call)
            Q = pin.rnea(model, data, q, v, zero).copy() - pin.rnea(model, data, q, v, zero, fext)
            qdd = pin.constraintDynamics(model, data, q, v, S * tau[n] + Q, ps.cmodels, ps.cdatas, prox)
        err[n] = qdd[ps.crank_v] - a_exact[ps.crank_v]
    return err
