"""The machine's law of motion by forward dynamics: MuJoCo and Pinocchio integrate the machine
with a free crank, and their omega(phi) is compared with kinetostat's (`kinetostat.law_of_motion`).

The machine: the model's mechanism (one `Scene` for both engines) with the flywheel's J_flywheel
added to the crank's moment of inertia about its axis (Pinocchio: `with_flywheel`; MuJoCo: after
compiling, so that its placeholder floors keep the linkage's scale), the drive's constant moment
M_drive on the crank (a characteristic M(omega) is one of the model's loads), and its applied loads evaluated by kinetostat's load model
(`kinetostat.applied.applied_wrenches`) at the engine's own crank angle and speed at every stage
of every step (they depend on the state, so this is a Python loop over the steps; the runs of one
call, `forwards`, step together and have their loads evaluated in one pass a stage, `_lockstep`). Gravity is the
engines' own. Friction is not modelled by the engines: a mechanism with [friction] is refused.

Integration: the classical Runge-Kutta method (RK4, order 4) at the step
dt = 2 pi / (omega_mean * steps_per_rev), shortened where a step would pass a crank angle at
which a load table's value has a kink (np.interp: its slope jumps there, an O(dt^2) error in the
step that holds it; the angles law_of_motion cuts its work integral at) to end there (predicted
by phi + omega h + eps h^2 / 2: within O(h^3)), from the exact state at phi_0 (kinetostat's positions,
velocities at omega(phi_0)), over `cycles` revolutions; both engines give only the accelerations:

- MuJoCo: `mj_forward` (its soft equality constraints as the harness builds them,
  `engine_mujoco._compile`, made as stiff as it allows: impedance 0.9999, time constant
  TIMECONST_STEPS steps); MuJoCo's own RK4 (`integrator="RK4"`) is not used because it holds
  xfrc_applied over a step, which makes a state-dependent load first order.
- Pinocchio: `pin.constraintDynamics` with its Baumgarte corrector where every loop-closing pair
  is revolute, else the KKT system of `engine_pinocchio` with the same Baumgarte terms
  (Pinocchio has no sliding rigid constraint), as `engine_pinocchio.forward_round_trip`.

The engine's omega at kinetostat's angles of the last cycle is the cubic Hermite interpolation
of its steps (phi(t) with omega, omega(t) with eps: O(dt^4), the integrator's order). The energy
balance T + V - W = const (T kinetic energy, flywheel included, V gravity's potential, W the work
of M_drive and the loads, integrated by the same RK4, and in MuJoCo that of its soft constraints,
efc_force . efc_vel: on the shaper 0.5 J a cycle, all of its T + V - W drift) is measured over
the whole run.

May use: kinetostat (model, kinematics, applied, planar, motion: law_of_motion and its cuts), the scene, the MuJoCo and
Pinocchio adapters (imported when used), numpy.
"""
from __future__ import annotations

import importlib.util
import math
import time
from dataclasses import dataclass, replace
from typing import Generator, Protocol

import numpy as np

from kinetostat import Mechanism, law_of_motion
from kinetostat.applied import applied_wrenches, com_motion
from kinetostat.kinematics import kinematics
from kinetostat.motion import _Cycle
from kinetostat.planar import as_xy

from .scene import Scene, build_scene, loads_at_centres

__all__ = ["ENGINES", "STEPS_PER_REV", "Trajectory", "Forward", "Agreement", "MotionCheck", "integrate", "forward", "forwards",
           "convergence", "observed_order", "check_law_of_motion", "with_flywheel", "at_angles"]

ENGINES = ("mujoco", "pinocchio")
#: The convergence study's steps per revolution (each twice the last).
STEPS_PER_REV = (90, 180, 360)
#: MuJoCo: the equality constraints' time constant in steps (critical damping, |lambda dt| = 1/4
#: against RK4's 2.78): of 1, 2, 4, 8 and 16 steps, 4 gave the ICE's smallest error (RK4's error
#: on the stiff constraint mode grows below it, the constraints' softness above).
TIMECONST_STEPS = 4.0
#: MuJoCo's largest constraint impedance (solimp): the softness 1 - 0.9999 left.
IMPEDANCE = 0.9999
#: Pinocchio: the Baumgarte corrector's natural frequency per crank speed (Kp = w^2, Kd = 2 w,
#: w = BAUMGARTE * omega_mean): the loop-closure drift decays by e in 1/(4 pi) of a revolution;
#: 20 made the ICE's error at 90 steps/rev 30 times larger (the mode's |lambda dt| = 1.4).
BAUMGARTE = 2.0
#: A landing angle closer than this to the crank's (rad) counts as reached.
LANDING = 1e-9


@dataclass(frozen=True)
class Trajectory:
    """One engine's run, sampled at every step (K samples)."""
    engine: str
    steps_per_rev: int
    dt: float                  # s
    t: np.ndarray              # (K,) s
    phi: np.ndarray            # (K,) rad, crank angle in the drive's sense, unwrapped (phi_0 at t = 0)
    omega: np.ndarray          # (K,) rad/s, in the drive's sense
    eps: np.ndarray            # (K,) rad/s^2
    energy: np.ndarray         # (K,) J: T + V - W, constant but for the integrator's error
    work_swing: float          # J: max - min over the run of W, the work of the drive, the loads (and
                               #   MuJoCo's soft constraints)
    seconds: float             # wall time of the run: its own steps and its share of the load passes it
                               #   shared with the runs integrated together (`_lockstep`)
    note: str

    @property
    def energy_error(self) -> float:
        """max |T + V - W - its start value| over the work's swing, 1."""
        return float(np.max(np.abs(self.energy - self.energy[0])) / (self.work_swing or 1.0))


@dataclass(frozen=True)
class Forward:
    """An engine's omega(phi) over the last cycle at kinetostat's angles, beside kinetostat's."""
    engine: str
    steps_per_rev: int
    phi_deg: np.ndarray        # (N,) deg, motion.phi_deg
    omega: np.ndarray          # (N,) rad/s, the engine's
    omega_law: np.ndarray      # (N,) rad/s, kinetostat's motion.omega
    omega_mean: float          # rad/s
    trajectory: Trajectory

    @property
    def error(self) -> float:
        """max |omega_engine - omega_kinetostat| / omega_mean, 1."""
        return float(np.max(np.abs(self.omega - self.omega_law)) / self.omega_mean)


@dataclass(frozen=True)
class Agreement:
    """One row of a convergence study."""
    engine: str
    steps_per_rev: int
    error: float               # max |omega_engine - omega_kinetostat| / omega_mean, 1
    order: float | None        # observed order against the previous row of the engine (None: first)
    energy_error: float        # the run's energy balance, relative to the work's swing
    seconds: float             # wall time of the run: its own steps and its share of the load passes it
                               #   shared with the runs integrated together (`_lockstep`)


class _Engine(Protocol):
    """An engine's forward dynamics of the scene, for `integrate`."""
    crank: int                 # the crank's index in q and v
    note: str                  # the engine's version and settings

    def start(self, qd_scale: float) -> tuple[np.ndarray, np.ndarray]: ...
    def derivative(self, q: np.ndarray, v: np.ndarray, F: np.ndarray, M: np.ndarray,
                   drive: float) -> tuple[np.ndarray, float, float]: ...


# ----------------------------------------------------------------------------- loads

def _loads(mech: Mechanism, scene: Scene, phi: np.ndarray, omega: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """kinetostat's applied loads (gravity out) at the crank angles phi (rad, (n,)), each at its own
    speed omega (rad/s, (n,)), as the engines take them: force at each centre of mass (n, L, 2), N,
    moment about it (n, L), N m. One pass of the kinematics over all n angles at unit crank speed,
    scaled to each angle's speed (velocities by omega, accelerations by omega^2: eps = 0)."""
    unit = kinematics(mech, phi, unit_speed=True)
    w = omega[:, None]
    kin = replace(unit, v_z=unit.v_z * w, a_z=unit.a_z * w**2, omega=unit.omega * w, eps=unit.eps * w**2,
                  v_slide=unit.v_slide * w, a_slide=unit.a_slide * w**2)
    F, M = applied_wrenches(mech, kin, com_motion(mech, kin)[0])
    return loads_at_centres(scene.bodies, scene.g, kin, as_xy(F), M)


# ----------------------------------------------------------------------------- engines

class _MuJoCo:
    """MuJoCo's forward dynamics of the scene: accelerations by mj_forward."""

    def __init__(self, scene: Scene, J_flywheel: float, dt: float):
        import mujoco
        from .engine_mujoco import SIM_FLOOR, _compile, _regularisation_weights
        self.scene = scene
        tc = TIMECONST_STEPS * dt
        self.mm = _compile(scene, SIM_FLOOR, exact_masses=False, timestep=dt, solref=(tc, 1.0),
                           solimp=(IMPEDANCE, IMPEDANCE, 0.001, 0.5, 2.0))
        # the flywheel after compiling: in the MJCF it would set the scale of the placeholder
        # floors (SIM_FLOOR of the largest inertia: 5e-5 kg m^2 on the shaper's slot helper, 1e-4
        # of its rocker's I_S); mj_setConst then derives the constants from the new inertia
        m, d = self.mm.m, self.mm.d
        m.body_inertia[self.mm.body[scene.mech.drive.link]] += J_flywheel
        mujoco.mj_setConst(m, d)
        _regularisation_weights(scene, self.mm)
        self.mm.m.opt.enableflags |= mujoco.mjtEnableBit.mjENBL_ENERGY
        self.mm.m.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_REFSAFE
        self.crank = self.mm.crank_dof
        self.note = (f"MuJoCo {mujoco.__version__}: mj_forward, soft equality constraints solref ({tc:.3g} s, 1), "
                     f"impedance {IMPEDANCE}")

    def start(self, qd_scale: float) -> tuple[np.ndarray, np.ndarray]:
        from .engine_mujoco import _exact_state
        qpos, qvel, _ = _exact_state(self.scene, self.mm)
        return qpos[0], qvel[0] * qd_scale

    def derivative(self, q, v, F, M, drive):
        """qacc at (q, v) under the loads F (L, 2), M (L,) and the crank moment `drive` (N m
        about +z); the power of the loads and the soft constraints, W; T + V, J."""
        import mujoco
        from .engine_mujoco import _applied
        m, d = self.mm.m, self.mm.d
        d.qpos[:], d.qvel[:] = q, v
        mujoco.mj_kinematics(m, d)                  # xipos for the loads' generalised force
        mujoco.mj_comPos(m, d)
        Q = _applied(self.scene, self.mm, F, M)     # also sets xfrc_applied
        d.qfrc_applied[:] = 0.0
        d.qfrc_applied[self.crank] = drive
        mujoco.mj_forward(m, d)
        soft = float(d.efc_force[:d.nefc] @ d.efc_vel[:d.nefc])    # the soft constraints' power
        return d.qacc.copy(), float(Q @ v) + soft, float(d.energy.sum())


class _Pinocchio:
    """Pinocchio's constrained forward dynamics of the scene with Baumgarte stabilisation."""

    def __init__(self, scene: Scene, omega_mean: float):
        import pinocchio as pin
        from .engine_pinocchio import PinocchioScene
        self.pin = pin
        self.ps = ps = PinocchioScene(scene)
        self.crank = ps.crank_v
        self.scene = scene
        w = BAUMGARTE * omega_mean
        self.kp, self.kd = w * w, 2.0 * w
        self.zero = np.zeros(ps.nv)
        self.method = "kkt" if ps.p_cuts else "constraintDynamics"
        if self.method == "constraintDynamics":
            for cm in ps.cmodels:
                bp = cm.m_baumgarte_parameters
                bp.Kp, bp.Kd = self.kp, self.kd
                cm.m_baumgarte_parameters = bp
            pin.initConstraintDynamics(ps.model, ps.data, ps.cmodels, ps.cdatas)
            self.prox = pin.ProximalSettings(1e-14, 1e-10, 50)
        self.note = (f"pin {pin.__version__}: {self.method}, Baumgarte Kp = {self.kp:.3g} 1/s^2, "
                     f"Kd = {self.kd:.3g} 1/s")

    def start(self, qd_scale: float) -> tuple[np.ndarray, np.ndarray]:
        q, v, _ = self.ps.state(0)
        return q, v * qd_scale

    def derivative(self, q, v, F, M, drive):
        """qdd at (q, v) under the loads F (L, 2), M (L,) and the crank moment `drive` (N m about
        +z); the loads' power, W; T + V, J."""
        pin, ps = self.pin, self.ps
        model, data = ps.model, ps.data
        pin.computeJointJacobians(model, data, q)                      # oMi for the loads
        fext = ps.fext(F, M)
        Q = pin.rnea(model, data, q, v, self.zero).copy() - pin.rnea(model, data, q, v, self.zero, fext)
        tau = Q.copy()
        tau[self.crank] += drive
        if self.method == "constraintDynamics":
            qdd = pin.constraintDynamics(model, data, q, v, tau, ps.cmodels, ps.cdatas, self.prox).copy()
        else:
            Jc, gamma, _ = ps.constraint_jacobian(q, with_drift=True, v=v)
            gap = ps.constraint_gap(q)
            b = pin.rnea(model, data, q, v, self.zero).copy()
            Mq = pin.crba(model, data, q)
            Mq = np.triu(Mq) + np.triu(Mq, 1).T
            m = Jc.shape[0]
            K = np.block([[Mq, -Jc.T], [Jc, np.zeros((m, m))]])
            rhs = np.concatenate([tau - b, gamma - self.kd * (Jc @ v) - self.kp * gap])
            qdd = np.linalg.solve(K, rhs)[:ps.nv]
        energy = pin.computeKineticEnergy(model, data, q, v) + pin.computePotentialEnergy(model, data, q)
        return qdd, float(Q @ v), float(energy)


# ----------------------------------------------------------------------------- integration

#: What a run yields: the crank angle (rad) and speed (rad/s) it needs the loads at; it is sent
#: the loads there, force (L, 2), N, and moment (L,), N m, at each centre of mass (`_loads`).
Run = Generator[tuple[float, float], tuple[np.ndarray, np.ndarray], Trajectory]


def integrate(mech: Mechanism, J_flywheel: float, M_drive: float, phi0_deg: float, omega0: float,
              omega_mean: float, engine: str = "mujoco", steps_per_rev: int = 360,
              cycles: float = 3) -> Trajectory:
    """The machine integrated forward by `engine` (see the module docstring) from the crank angle
    phi0_deg (deg) at speed omega0 (rad/s, drive's sense) until phi_0 + 360 cycles deg; flywheel
    J_flywheel (kg m^2) on the crank, drive moment M_drive (N m, drive's sense) constant.
    Raises ValueError for a mechanism with friction, an unknown engine, a bad step count, or a
    crank that stops or turns back (no steady motion to follow)."""
    scene = build_scene(mech, phi_deg=[phi0_deg])
    run = _run(mech, scene, J_flywheel, M_drive, phi0_deg, omega0, omega_mean, engine, steps_per_rev, cycles)
    return _lockstep(mech, scene, [run])[0]


def _run(mech: Mechanism, scene: Scene, J_flywheel: float, M_drive: float, phi0_deg: float, omega0: float,
         omega_mean: float, engine: str, steps_per_rev: int, cycles: float) -> Run:
    """`integrate`'s run (its arguments checked and its engine built now) as a generator that asks
    for the loads at each stage of each step (`Run`); `_lockstep` drives it."""
    if mech.friction is not None:
        raise ValueError("integrate: the engines model no friction; give the mechanism without it "
                         "(dataclasses.replace(mech, friction=None)) to kinetostat and the engines alike")
    if engine not in ENGINES:
        raise ValueError(f"engine: expected one of {ENGINES}, got {engine!r}")
    if not (isinstance(steps_per_rev, (int, np.integer)) and steps_per_rev >= 4):
        raise ValueError(f"steps_per_rev: expected an integer >= 4, got {steps_per_rev!r}")
    if not (omega0 > 0 and omega_mean > 0 and J_flywheel >= 0 and cycles > 0):
        raise ValueError(f"integrate: needs omega0 > 0, omega_mean > 0, J_flywheel >= 0 and cycles > 0, got "
                         f"{omega0}, {omega_mean}, {J_flywheel}, {cycles}")
    dt = 2 * math.pi / (omega_mean * steps_per_rev)
    eng: _Engine = (_MuJoCo(scene, J_flywheel, dt) if engine == "mujoco"
                    else _Pinocchio(with_flywheel(scene, J_flywheel), omega_mean))
    return _steps(mech, engine, eng, M_drive, math.radians(phi0_deg), omega0, dt, steps_per_rev, cycles)


def _steps(mech: Mechanism, engine: str, eng: _Engine, M_drive: float, phi0: float, omega0: float, dt: float,
           steps_per_rev: int, cycles: float) -> Run:
    """RK4 steps of `eng` from phi0 (rad) at omega0 (rad/s) to phi0 + 2 pi cycles, landing on the
    load tables' kinks (`integrate`); the Trajectory is the generator's return value."""
    sense, c = mech.drive.sense, eng.crank
    q, v = eng.start(omega0 / mech.drive.omega)
    qc0 = q[c]

    def f(q, v):
        phi, w = phi0 + sense * (q[c] - qc0), sense * v[c]
        F, M = yield phi, w
        a, power, energy = eng.derivative(q, v, F, M, sense * M_drive)
        return a, power + M_drive * w, energy, phi, w

    def step(q, v, W, a1, p1, h):
        """One RK4 step of length h (a1, p1: the derivatives at its start)."""
        v2 = v + h / 2 * a1
        a2, p2, *_ = yield from f(q + h / 2 * v, v2)
        v3 = v + h / 2 * a2
        a3, p3, *_ = yield from f(q + h / 2 * v2, v3)
        v4 = v + h * a3
        a4, p4, *_ = yield from f(q + h * v3, v4)
        return (q + h / 6 * (v + 2 * v2 + 2 * v3 + v4), v + h / 6 * (a1 + 2 * a2 + 2 * a3 + a4),
                W + h / 6 * (p1 + 2 * p2 + 2 * p3 + p4))

    end, limit = phi0 + 2 * math.pi * cycles, int(3 * steps_per_rev * cycles) + 10
    knots, k = _landings(mech, phi0, end), 0
    W, t, rows = 0.0, 0.0, []
    while True:
        a1, p1, E, phi, w = yield from f(q, v)
        eps = sense * a1[c]
        rows.append((t, phi, w, eps, E - W, W))
        k += int(np.searchsorted(knots[k:], phi + LANDING))           # landings reached
        if k == len(knots):
            break
        if w <= 0 or len(rows) > limit:
            raise ValueError(f"integrate ({engine}): the crank stopped or turned back near phi = "
                             f"{math.degrees(phi) % 360:.1f} deg (omega = {w:.4g} rad/s): no steady motion")
        h, gap = dt, knots[k] - phi
        if gap < w * dt + eps * dt * dt / 2 and w * w + 2 * eps * gap > 0:
            # the next landing within this step: shortened to reach it by phi + w h + eps h^2 / 2 (it
            # lands within O(h^3), so a kink there costs O(h^6)), and counted as reached
            h = 2 * gap / (w + math.sqrt(w * w + 2 * eps * gap))
            k += 1
        q, v, W = yield from step(q, v, W, a1, p1, h)
        t += h
    t, phi, w, eps, energy, work = np.array(rows).T
    return Trajectory(engine, int(steps_per_rev), dt, t, phi, w, eps, energy, float(np.ptp(work)), 0.0,
                      f"{eng.note}; RK4, {steps_per_rev} steps/rev (dt = {dt:.3g} s), {cycles} cycles, "
                      f"{len(knots)} landings on load table knots and the run's end")


def _lockstep(mech: Mechanism, scene: Scene, runs: list[Run]) -> list[Trajectory]:
    """The runs driven together: at each round the loads every unfinished run asks for are
    evaluated in one `_loads` call (the kinematics of all their angles in one pass, the largest
    cost of a run). Each Trajectory's `seconds`: its own steps' wall time and its share of the
    rounds' loads."""
    seconds = [0.0] * len(runs)
    asked: dict[int, tuple[float, float]] = {}
    done: dict[int, Trajectory] = {}

    def advance(i: int, loads: tuple[np.ndarray, np.ndarray] | None) -> None:
        t0 = time.perf_counter()
        try:
            asked[i] = next(runs[i]) if loads is None else runs[i].send(loads)
        except StopIteration as stop:
            asked.pop(i, None)
            done[i] = stop.value
        seconds[i] += time.perf_counter() - t0

    for i in range(len(runs)):
        advance(i, None)
    while asked:
        t0 = time.perf_counter()
        order = list(asked)
        F, M = _loads(mech, scene, np.array([asked[i][0] for i in order]), np.array([asked[i][1] for i in order]))
        share = (time.perf_counter() - t0) / len(order)
        for n, i in enumerate(order):
            seconds[i] += share
            advance(i, (F[n], M[n]))
    return [replace(done[i], seconds=seconds[i]) for i in range(len(runs))]


def _landings(mech: Mechanism, phi0: float, end: float) -> np.ndarray:
    """The crank angles (rad, unwrapped, in (phi0, end], ascending) a step ends on: over the run,
    the angles where a load table's value has a kink, as law_of_motion cuts its work integral
    there (its `_Cycle.knots`: a crank-angle table's knots, where a travel table's point passes its
    knots or turns), and the run's end."""
    knots = np.radians(_Cycle.of(mech, np.zeros(1)).knots)
    turns = np.arange(math.floor(phi0 / (2 * math.pi)), math.ceil(end / (2 * math.pi)) + 1)
    every = (knots[:, None] + 2 * math.pi * turns).ravel()
    return np.unique(np.append(every[(every > phi0 + LANDING) & (every < end - LANDING)], end))


def with_flywheel(scene: Scene, J_flywheel: float) -> Scene:
    """The scene with J_flywheel (kg m^2) added to the crank's moment of inertia (the flywheel's
    centre on the crank's axis: about the crank's centre of mass and its axis alike)."""
    crank = scene.mech.drive.link
    return replace(scene, bodies=tuple(replace(b, I_S=b.I_S + J_flywheel) if b.link == crank else b
                                       for b in scene.bodies))


def _hermite(y0, y1, d0, d1, h, s):
    """The cubic Hermite interpolant over a step of length h (values y, derivatives d) at s in [0, 1]."""
    return y0 * (1 + 2 * s) * (1 - s) ** 2 + h * d0 * s * (1 - s) ** 2 + y1 * s * s * (3 - 2 * s) - h * d1 * s * s * (1 - s)


def _crossing(p0, p1, w0, w1, h, phi):
    """s in [0, 1] where the Hermite phi(t) of a step (angles p, speeds w, length h) reaches phi:
    Newton from the linear guess (phi(t) rises monotonically: omega > 0)."""
    s = (phi - p0) / (p1 - p0)
    for _ in range(8):
        slope = h * (w0 * (1 - s) * (1 - 3 * s) + w1 * s * (3 * s - 2)) + 6 * (p1 - p0) * s * (1 - s)
        s = s - (_hermite(p0, p1, w0, w1, h, s) - phi) / slope
    return s


def at_angles(tr: Trajectory, phi: np.ndarray) -> np.ndarray:
    """The trajectory's omega at crank angles phi (rad, unwrapped, within the run): cubic
    Hermite interpolation of its steps, phi(t) with omega and omega(t) with eps (O(dt^4))."""
    phi = np.asarray(phi, float)
    k = np.clip(np.searchsorted(tr.phi, phi, side="right") - 1, 0, len(tr.phi) - 2)
    h = tr.t[k + 1] - tr.t[k]
    w0, w1 = tr.omega[k], tr.omega[k + 1]
    s = _crossing(tr.phi[k], tr.phi[k + 1], w0, w1, h, phi)
    return _hermite(w0, w1, tr.eps[k], tr.eps[k + 1], h, s)


def forward(mech: Mechanism, motion, engine: str = "mujoco", steps_per_rev: int = 360,
            cycles: int = 3) -> Forward:
    """The machine of `motion` (a `kinetostat.Motion` of `mech`, without friction) integrated by
    `engine` from motion's omega(phi_0) at phi_0 over `cycles` revolutions, with motion's flywheel
    and drive (a constant moment; a characteristic M(omega) is one of the model's loads, so the
    load model gives it at the engine's speed); its omega at motion.phi_deg in the last cycle
    beside motion.omega."""
    return forwards(mech, motion, ((engine, steps_per_rev),), cycles)[0]


def forwards(mech: Mechanism, motion, runs: tuple[tuple[str, int], ...], cycles: int = 3) -> list[Forward]:
    """`forward` of every (engine, steps_per_rev) of `runs`, integrated together (`_lockstep`)."""
    drive = 0.0 if motion.drive == "characteristic" else float(motion.M_drive[0])
    phi_deg = np.asarray(motion.phi_deg, float)
    scene = build_scene(mech, phi_deg=[float(phi_deg[0])])
    trs = _lockstep(mech, scene, [_run(mech, scene, motion.J_flywheel, drive, float(phi_deg[0]), float(motion.omega[0]),
                                       motion.omega_mean, engine, n, cycles) for engine, n in runs])
    last = np.radians(phi_deg[0] + (phi_deg - phi_deg[0]) % 360.0 + 360.0 * (cycles - 1))
    return [Forward(engine, int(n), phi_deg, at_angles(tr, last), np.asarray(motion.omega, float),
                    float(motion.omega_mean), tr) for (engine, n), tr in zip(runs, trs)]


def observed_order(errors: list[float], steps: list[int]) -> list[float | None]:
    """log(e_{i-1} / e_i) / log(n_i / n_{i-1}) for successive step counts n (None for the first)."""
    return [None] + [math.log(errors[i - 1] / errors[i]) / math.log(steps[i] / steps[i - 1])
                     if errors[i] > 0 and errors[i - 1] > 0 else None for i in range(1, len(errors))]


def convergence(mech: Mechanism, motion, engines: tuple[str, ...] = ENGINES,
                steps_per_rev: tuple[int, ...] = STEPS_PER_REV, cycles: int = 3) -> tuple[Agreement, ...]:
    """Every engine at every step count: its error against kinetostat's omega(phi), the observed
    order, the energy balance and the wall time (see `forward`)."""
    rows = []
    done = forwards(mech, motion, tuple((engine, n) for engine in engines for n in steps_per_rev), cycles)
    for engine in engines:
        runs = [r for r in done if r.engine == engine]
        orders = observed_order([r.error for r in runs], list(steps_per_rev))
        rows += [Agreement(engine, r.steps_per_rev, r.error, o, r.trajectory.energy_error, r.trajectory.seconds)
                 for r, o in zip(runs, orders)]
    return tuple(rows)


@dataclass(frozen=True)
class MotionCheck:
    """The "law of motion" check of one model: kinetostat's motion and the engines' agreement."""
    model: str
    omega_mean: float          # rad/s
    delta: float               # 1
    J_flywheel: float          # kg m^2
    M_drive: float             # N m, the drive's moment at phi_0 (drive's sense; constant but for a characteristic)
    energy_error: float        # kinetostat's side: max |T - T(phi_0) - A(phi)| over the swing of A, 1
    rows: tuple[Agreement, ...]
    skipped: tuple[str, ...]   # engines not installed (never counted as agreeing)
    note: str


def check_law_of_motion(mech: Mechanism, delta: float | None = None, flywheel: float | None = None,
                        engines: tuple[str, ...] = ENGINES, steps_per_rev: tuple[int, ...] = STEPS_PER_REV,
                        cycles: int = 3) -> MotionCheck:
    """kinetostat's law of motion of `mech` without its friction (the engines model none), with
    the flywheel `kinetostat.law_of_motion` sizes for `delta` or is given, checked by the engines
    installed among `engines` at every step count (`convergence`)."""
    plain = replace(mech, friction=None)
    motion = law_of_motion(plain, delta=delta, flywheel=flywheel)
    have = tuple(e for e in engines if importlib.util.find_spec(e))       # the engines' modules are named so
    swing = float(np.ptp(motion.work)) or 1.0
    energy = float(np.max(np.abs(motion.T - motion.T[0] - motion.work)) / swing)
    note = "friction left out (the engines model none)" if mech.friction is not None else ""
    return MotionCheck(mech.name, motion.omega_mean, motion.delta, motion.J_flywheel, float(motion.M_drive[0]),
                       energy, convergence(plain, motion, have, steps_per_rev, cycles),
                       tuple(e for e in engines if e not in have), note)
