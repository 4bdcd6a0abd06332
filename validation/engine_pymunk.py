"""pymunk adapter of the cross-validation harness: the simulation route.

Every moving link becomes a pymunk dynamic body (mass and I_S at its centre of mass; no shapes,
so nothing collides), every kinematic pair a constraint, and a `SimpleMotor` holds the crank at
the model's constant speed. One revolution is simulated, starting from the exact state a little
before the scene's first angle; each step's constraint impulse divided by the step is a
reaction, and the step values are interpolated in crank angle to the scene's angles.

How the model maps onto pymunk (Chipmunk's cpPivotJoint.c, cpGrooveJoint.c, cpGearJoint.c,
cpSimpleMotor.c, cpSpaceStep.c):

- Revolute pair: `PivotJoint` at the pair's point; impulse / dt = |R|.
- Prismatic pair: `GrooveJoint` on the guide link parallel to the guide direction, longer than
  the stroke, plus `GearJoint(ratio=1)` that locks the relative rotation. Inside the groove
  Chipmunk projects the accumulated impulse on the groove normal, so the groove's impulse / dt
  is the normal force alone (frictionless, no along-guide part): the solver's R of the pair. The
  gear joint's impulse is the pair's reaction couple, which the solver states as the offset x of
  the normal force instead; it is not reported.
  With the relative rotation locked, "the slider point stays on the guide line" is the same
  constraint as "a point of the slider stays on a line parallel to the guide". The groove runs
  through the guide's centre of mass and its anchor is the slider point straight across from
  the slider's centre of mass (on the frame: the slider's centre of mass itself). The normal
  force is the same; but Chipmunk solves the groove as a point constraint and projects the
  impulse afterwards, which is exact only when the 2x2 effective mass does not couple the normal
  and the sliding direction, i.e. when both lever arms lie along or across the guide. Anchors at
  the slider points left O(dt) errors on the scotch yoke at 1440 steps: 1.3 % of the peak for the
  yoke on its frame guide (slider point 0.18 m from the yoke's centre of mass) and 0.02 % for the
  block in the moving yoke; this placement none.
- Magnitudes only: `Constraint.impulse` is |jAcc|; the sign is not public API. R is returned as
  `[|R_i|, 0]` per pair with `magnitudes_only=True`: only `norm(R, axis=-1)` means anything.
- Driving moment, signed: a constant bias torque K (twice the solver's peak |M_drive| over the
  cycle) on the crank keeps the motor's torque M_drive - K negative, so M_drive = K -
  impulse / dt. A pure couple changes no reaction. If the motor torque ever comes near zero, K
  is raised and the cycle rerun.
- Working machine (`drive.kind = "machine"`): the solver's crank-bearing reaction contains the
  pinion's force on the wheel (pitch point, line of action). pymunk has no gear mesh, so the
  cycle runs twice: the first run gives the signed driving moment at every step, the second
  applies the mesh force of that moment to the crank at the pitch point as an external force
  (open loop: feeding back the current run's own moment oscillates and grows) while the motor
  supplies the small remainder.
- Time step: Chipmunk moves positions with the old velocities, then solves the velocities at
  the new positions (semi-implicit Euler). The bodies start with the exact velocities half a step
  ahead; loads are applied, and reactions sampled, at the angle the positions reach in the step.
  pymunk runs with one step as its unit of time (see `_simulate`), so that `error_bias` can
  correct a set fraction POSITION_CORRECTION of the positional error per step.
  Measured: the error falls as dt^2 (RICHARDSON_ORDER) once the impulse solver has converged.
- Iterations: Gauss-Seidel over the constraints, warm-started from the previous step. Heavy
  and light links together (25-30 kg rams and sliders behind 0.8 kg blocks) converge slowly: the
  residual is an error that does not fall with dt, and with too few iterations the two slotted-
  link shapers go unstable (a velocity oscillation of period two steps that grows). Each run is
  checked (below); an unstable run is repeated with twice the iterations, up to
  MAX_DOUBLINGS times, and `note` says so.
- Checks against the exact motion at every step: a link angle off by more than
  BRANCH_ANGLE_TOL or a centre of mass by more than BRANCH_POSITION_TOL (branch jump or drift,
  which pymunk does silently near singular positions), or velocities that jitter from step to
  step enough to move the forces by JITTER_TOL (instability). After the last rerun, values
  within BRANCH_BAND_DEG of such a step are NaN and `note` names the angles, so a harness sees
  a failure instead of a large "error".
- Iterations in use: at 1440 steps the light linkages stay at 50; the furnace loader needs 200,
  the rotating slotted link 200, the slotted-link shaper 400, and are then limited by the
  impulse solver (1e-4 to 2e-3 of the peak); `iterations=1000` brings them to 2e-5 to 2e-4.
- Massless links and I_S = 0: a pymunk dynamic body needs m > 0 and I > 0. Such links get a
  surrogate mass (the heaviest link's) or moment of inertia (the largest I_S), whose weight and
  inertia are cancelled by an applied force m'(a_S - g) and torque I' eps along the exact
  motion. A massless crank's surrogate centre of mass is its pivot, where a_S = 0 exactly.
- External loads (everything but gravity, which is pymunk's) come from `Scene.external()` of the
  same mechanism on the step grid: force at the centre of mass and moment about it, at the exact
  state of each step's angle.
- Point kinematics: positions and velocities of the tracked points (`scene.tracked_points`)
  from the bodies' own positions, angles and velocities (the velocity at a step's positions is
  the mean of the half-step velocities either side). No accelerations: pymunk's state has none
  (its solver works on velocities), and differences of the velocities carry the impulse
  solver's iteration residual and every load jump (measured up to 1.3e-2 of the peak on the
  slotted-link shaper at 1440 steps, 5.7e-3 at the scotch yoke's load flip), so they would
  compare the difference quotient, not pymunk.
- `drive.eps` != 0: the solver's state (constant omega with a nonzero eps at every angle) is not
  a motion a simulation can follow; all values are NaN with a note.

May use: kinetostat (analysis, planar), the scene, pymunk.
"""
from __future__ import annotations

import math
import time
import warnings
from dataclasses import dataclass

import numpy as np

from kinetostat import SingularPositionWarning, analyze
from kinetostat.planar import as_xy, rotate

from .scene import EngineResult, Scene, build_scene, tracked_points

__all__ = ["simulate", "richardson_extrapolate", "RICHARDSON_ORDER", "POSITION_CORRECTION", "MAX_DOUBLINGS",
           "BRANCH_ANGLE_TOL", "BRANCH_POSITION_TOL", "JITTER_TOL", "BRANCH_BAND_DEG", "LEAD_DEG"]

#: Order p of the step-size error f(dt) = f + c dt^p; Richardson: (2^p f(dt/2) - f(dt)) / (2^p - 1).
#: Measured 2 on every model once the impulse solver has converged (errors fall 4x per halving).
RICHARDSON_ORDER = 2
#: Fraction of a constraint's positional error corrected per step. 1 (all of it) is ~2x more
#: accurate on the simple linkages but went unstable on the rotating slotted link at 2880 steps
#: and 200 iterations; 0.5 was stable wherever 1 was, and on that case too.
POSITION_CORRECTION = 0.5
#: How often an unstable run is repeated with twice the iterations (50 -> 400 at most).
MAX_DOUBLINGS = 3
#: A step has left the exact motion when some link's angle is off by more than this (rad; the
#: normal O(dt^2) pose error is below 1e-4 rad) ...
BRANCH_ANGLE_TOL = 0.05
#: ... or some centre of mass by more than this fraction of the mechanism's size ...
BRANCH_POSITION_TOL = 0.02
#: ... or the velocities jitter: J, the largest second difference over steps of (simulated -
#: exact) velocity in units of omega_crank * size (angular: omega_crank), is a period-two
#: oscillation of amplitude J/4 whose forces are ~J n / (4 pi) of the inertia forces (n steps per
#: revolution). Flagged above this force fraction. Measured: converged runs 1e-8 to 6e-3 (ringing
#: after load kinks and jumps); the furnace loader's ringing at 50 iterations 3e-2 (rerun with
#: more iterations, rightly: its errors then fall 30x); the unstable shapers at 50 iterations
#: 1.5 to 7e4.
JITTER_TOL = 1e-2
#: Half-width of the NaN band around a step that failed a check, deg.
BRANCH_BAND_DEG = 5.0
#: Crank angle simulated before the first sample, deg: the warm start of the impulse solver
#: needs a few steps (the first step's impulses start from zero).
LEAD_DEG = 10.0


def simulate(scene: Scene, steps_per_rev: int = 720, iterations: int = 50,
             richardson: bool = True) -> EngineResult:
    """Simulate one crank revolution of `scene` in pymunk: the reactions' magnitudes and the
    signed driving moment at the scene's angles (see the module docstring).

    steps_per_rev: time steps per crank revolution; iterations: pymunk `Space.iterations` to
    start with (doubled on instability); richardson: also run at 2 * steps_per_rev and
    extrapolate with RICHARDSON_ORDER (both levels with the same iterations). The default,
    Richardson over 720 and 1440 steps, costs ~1.5-2.5x one run at 1440 and is 15-300x more
    accurate on five of the eight bundled models, 8x on the rotating slotted link, equal on the
    scotch yoke (a load jump sets its error) and 2.6x less accurate on the furnace loader (its
    two levels end at different iteration counts); measured in the benchmark and the table of
    tests/test_engine_pymunk.py.
    """
    if not isinstance(steps_per_rev, (int, np.integer)) or steps_per_rev < 36:
        raise ValueError(f"steps_per_rev: expected an integer >= 36, got {steps_per_rev!r}")
    if not isinstance(iterations, (int, np.integer)) or iterations < 1:
        raise ValueError(f"iterations: expected a positive integer, got {iterations!r}")
    mech = scene.mech
    N, n_pairs = len(scene.phi_deg), len(mech.pairs)
    if mech.drive.eps != 0:
        nan = np.full((N, len(tracked_points(mech)), 2), np.nan)
        return EngineResult("pymunk", "simulation", np.array(scene.phi_deg, float), np.full(N, np.nan),
                            np.full((N, n_pairs, 2), np.nan), magnitudes_only=True,
                            points=tracked_points(mech), x=nan, v=nan,
                            note="drive.eps != 0: the solver's state (constant omega, nonzero eps at "
                                 "every angle) is not a motion a simulation can follow; all values NaN")
    n = int(steps_per_rev)
    t0 = time.perf_counter()
    preps = [_Prep(scene, m) for m in ([n, 2 * n] if richardson else [n])]
    build = time.perf_counter() - t0
    notes: list[str] = []
    its = int(iterations)
    run = 0.0
    for attempt in range(MAX_DOUBLINGS + 1):
        cycles = []
        for p in preps:          # the coarse level first: where it fails, the fine one is not run
            cycles.append(_cycle(p, its))
            if cycles[-1].bad.any() and attempt < MAX_DOUBLINGS:
                break
        build += sum(c.build_seconds for c in cycles)
        run += sum(c.run_seconds for c in cycles)
        failed = [c for c in cycles if c.bad.any()]
        if not failed or attempt == MAX_DOUBLINGS:
            break
        notes.append(f"{its} iterations: " + "; ".join(c.failure for c in failed)
                     + f"; rerun with {2 * its}")
        its *= 2
    outs = []
    for c in cycles:
        if c.warning:
            notes.append(c.warning)
        M, R, kin = c.M.copy(), c.R.copy(), c.kin.copy()
        if c.bad.any():
            notes.append(c.failure + f"; values within {BRANCH_BAND_DEG:g} deg are NaN")
            band = _widen(c.bad, max(1, int(round(BRANCH_BAND_DEG / c.prep.dphi))))
            M[band], R[band], kin[band] = np.nan, np.nan, np.nan
        outs.append([_sample(c.prep, v) for v in (M, R, kin)])
    if richardson:
        M_out, R_out, kin = (richardson_extrapolate(c, f) for c, f in zip(*outs))
        head = f"Richardson (order {RICHARDSON_ORDER}) over {n} and {2 * n} steps/rev"
    else:
        (M_out, R_out, kin), = outs
        head = f"{n} steps/rev"
    notes.insert(0, f"{head}, {its} iterations; R[:, i] = [|R_i|, 0] (pymunk impulses are "
                    f"magnitudes); M_drive signed (bias torque); point positions and velocities from "
                    f"the bodies' states (no accelerations: see the module docstring)")
    for p in preps:
        notes += p.notes
    R = np.zeros(R_out.shape + (2,))
    R[..., 0] = R_out
    return EngineResult("pymunk", "simulation", np.array(scene.phi_deg, float), M_out, R,
                        magnitudes_only=True, points=preps[0].points, x=kin[:, 0], v=kin[:, 1],
                        build_seconds=build, run_seconds=run, note="; ".join(dict.fromkeys(notes)))


def richardson_extrapolate(coarse: np.ndarray, fine: np.ndarray, order: int = RICHARDSON_ORDER) -> np.ndarray:
    """Richardson extrapolation of values at steps h (`coarse`) and h/2 (`fine`) whose error is
    c h^order: (2^order fine - coarse) / (2^order - 1)."""
    w = 2.0 ** order
    return (w * fine - coarse) / (w - 1)


class _Prep:
    """What one cycle at n steps needs apart from pymunk: the exact motion and the loads on a
    half-step grid, the bodies' centres of mass and (surrogate) inertias, the mesh geometry.

    Grid index i is the crank angle phi0 + (i/2 - lead) dphi; step k starts at index 2k and its
    positions reach index 2(k + 1). Steps lead .. lead + n - 1 are sampled: they reach the angles
    phi0 + dphi .. phi0 + 360 deg.
    """

    def __init__(self, scene: Scene, n: int):
        mech = self.mech = scene.mech
        dr = mech.drive
        self.scene, self.n = scene, n
        self.phi0 = float(scene.phi_deg[0])
        self.dphi = 360.0 / n
        self.lead = int(math.ceil(LEAD_DEG / self.dphi))
        self.steps = n + self.lead
        offs = (0.5 * np.arange(2 * self.steps + 2) - self.lead) * self.dphi
        # the sample at 360 deg is taken at phi0 itself, so that a load that jumps there
        # (against_velocity at a reversal) is evaluated exactly as the solver evaluates it
        offs[2 * self.steps] = 0.0
        grid = self.phi0 + offs
        with warnings.catch_warnings():      # the scene's own analysis has warned already
            warnings.simplefilter("ignore", SingularPositionWarning)
            dense = build_scene(mech, phi_deg=grid, res=analyze(mech, phi_deg=grid))
        self.kin = dense.res.kin
        M_cycle = np.abs(dense.res.balancing_moment)
        M_cycle = M_cycle[np.isfinite(M_cycle)]
        self.M_peak = float(M_cycle.max()) if M_cycle.size else 0.0    # scale of the bias torque
        self.F_ext, self.M_ext = (_fill_nan(a) for a in dense.external())
        self.omega1 = float(self.kin.omega[self.lead * 2, dr.link])
        self.dt = 2 * math.pi / abs(self.omega1) / n
        self.machine = dr.kind == "machine"
        self.links = [b.link for b in scene.bodies]
        self.points = tracked_points(mech)
        masses = [b.mass for b in scene.bodies if b.mass > 0]
        m_ref = max(masses) if masses else 1.0
        I_ref = max([b.I_S for b in scene.bodies if b.I_S > 0] or [m_ref * (mech.size / 4) ** 2])
        self.notes: list[str] = []
        self.mass, self.moment, self.com = {}, {}, {0: np.zeros(2)}
        self.comp_F, self.comp_T = {}, {}      # cancel surrogate inertias, per grid index
        g_vec = np.array([0.0, -scene.g])
        for b in scene.bodies:
            k = b.link
            m, I, c = b.mass, b.I_S, np.asarray(b.com, float)
            if m <= 0:
                pts = mech.links[k].points
                c = (np.asarray(pts[dr.pivot], float) if k == dr.link
                     else np.mean([np.asarray(p, float) for p in pts.values()], axis=0))
                m = m_ref
                self.comp_F[k] = m * (self.kin.point(k, c)[2] - g_vec)
                self.notes.append(f"link {k} massless: surrogate {m:.4g} kg cancelled by m'(a_S - g)")
            if I <= 0:
                I = I_ref
                self.comp_T[k] = I * self.kin.eps[:, k]
            self.mass[k], self.moment[k], self.com[k] = m, I, c
        # exact centre-of-mass velocity and angular velocity per grid index, for the checks
        self.V = {k: self.kin.point(k, self.com[k])[1] for k in self.links}
        if self.machine:
            gear = dr.gear
            e = np.asarray(gear.centre_direction, float)
            t = np.array([-e[1], e[0]])
            a = math.radians(gear.alpha_w_deg)
            self.pitch = np.asarray(mech.links[0].points[dr.pivot], float) + gear.r_w * e
            self.r_b = gear.r_b
            self.line_pos = math.cos(a) * t - math.sin(a) * e     # unit force direction, M > 0
            self.line_neg = -math.cos(a) * t - math.sin(a) * e    # M < 0 (the other flank)

    def mesh_force(self, M: float) -> np.ndarray:
        """The pinion's force on the wheel for a driving moment M (as the solver's F_bal)."""
        if not math.isfinite(M):
            return np.zeros(2)
        return abs(M) / self.r_b * (self.line_pos if M >= 0 else self.line_neg)

    def pose(self, k: int, i) -> tuple[np.ndarray, np.ndarray]:
        """Exact centre of mass (m) and angle (rad) of link k at grid index i: (2,) and a
        scalar, or for an index array (n, 2) and (n,)."""
        th = self.kin.theta[i, k]
        return as_xy(self.kin.origin_z[i, k]) + rotate(self.com[k], th), th


@dataclass
class _Run:
    """Raw values of one simulated revolution, per sampled step."""
    M: np.ndarray            # (n,) signed driving moment, N m
    R: np.ndarray            # (n, n_pairs) reaction magnitudes, N
    pose: np.ndarray         # (n,) worst pose deviation / its tolerance
    jitter: np.ndarray       # (n,) worst velocity jitter / JITTER_TOL
    tau_min: float           # smallest motor torque magnitude, N m
    M_all: np.ndarray        # (lead + n,) signed driving moment at every step, lead-in included
    kin: np.ndarray          # (n, 2, n_points, 2) position and velocity of the tracked points
    build_seconds: float
    run_seconds: float


@dataclass
class _Cyc:
    """One accepted cycle at n steps: the sampled steps' values and what failed where."""
    prep: _Prep
    M: np.ndarray
    R: np.ndarray
    kin: np.ndarray
    bad: np.ndarray          # (n,) step failed a check
    failure: str = ""        # which checks failed where
    warning: str = ""        # anything else the reader must know
    build_seconds: float = 0.0
    run_seconds: float = 0.0


def _cycle(prep: _Prep, iterations: int) -> _Cyc:
    K = 2.0 * prep.M_peak if prep.M_peak > 0 else 1.0
    for _ in range(3):
        runs = [_simulate(prep, iterations, K, None)]
        if prep.machine:
            runs.append(_simulate(prep, iterations, K, runs[0].M_all))
        if (min(r.tau_min for r in runs) > 0.05 * K
                or any((r.pose > 1).any() or (r.jitter > 1).any() for r in runs)):
            break         # bias large enough, or a failed run (rerun with more iterations)
        K *= 4.0          # the motor torque came near zero: the bias did not cover M_drive
    last = runs[-1]
    pose_bad = np.zeros(prep.n, bool)
    jit_bad = np.zeros(prep.n, bool)
    for r in runs:
        pose_bad |= r.pose > 1.0
        jit_bad |= r.jitter > 1.0
    x = prep.phi0 + (np.arange(prep.n) + 1.0) * prep.dphi
    fails = []
    if pose_bad.any():
        fails.append(f"{prep.n} steps: poses left the exact ones (branch jump or drift) at "
                     f"{_ranges(x[pose_bad] % 360.0)} deg")
    if jit_bad.any():
        fails.append(f"{prep.n} steps: velocities oscillate (unstable) at {_ranges(x[jit_bad] % 360.0)} deg")
    warn = ""
    if min(r.tau_min for r in runs) <= 0.05 * K:
        warn = f"{prep.n} steps: the bias torque did not cover the driving moment: sign of M_drive uncertain"
    return _Cyc(prep, last.M, last.R, last.kin, pose_bad | jit_bad, "; ".join(fails), warn,
                sum(r.build_seconds for r in runs), sum(r.run_seconds for r in runs))


def _sample(prep: _Prep, values: np.ndarray) -> np.ndarray:
    """Step values (n, ...) at phi0 + (k+1) dphi, interpolated in crank angle to the scene's angles."""
    x = (np.arange(prep.n) + 1.0) * prep.dphi
    rel = (np.asarray(prep.scene.phi_deg, float) - prep.phi0) % 360.0
    flat = values.reshape(prep.n, -1)
    out = np.stack([np.interp(rel, x, flat[:, i], period=360.0) for i in range(flat.shape[1])], axis=-1)
    return out.reshape((len(rel),) + values.shape[1:])


def _simulate(prep: _Prep, iterations: int, K: float, M_first: np.ndarray | None) -> _Run:
    """One revolution (after the lead-in) in a fresh pymunk space. M_first: a machine's driving
    moment at every step from a first run, whose mesh force is applied to the crank.

    pymunk runs with one step as its unit of time (lengths in m, masses in kg): velocities are
    v dt, forces and torques F dt^2, an impulse over the unit step is F dt^2. Chipmunk's
    algorithm is the same in any time unit; in this one `error_bias` (the fraction of a positional
    error left after one time unit) is directly the fraction left after one step, which
    (1 - beta) ** (1 / dt) in seconds cannot express once it underflows (dt ~ 1e-5 s).
    """
    import pymunk

    t0 = time.perf_counter()
    mech, kin, dt = prep.mech, prep.kin, prep.dt
    v_u, f_u = dt, dt * dt             # SI -> pymunk units: velocity, force and torque
    dr = mech.drive
    space = pymunk.Space()
    space.iterations = iterations
    space.gravity = (0.0, -prep.scene.g * f_u)
    bodies = {0: space.static_body}
    for k in prep.links:
        body = pymunk.Body(prep.mass[k], prep.moment[k])
        S, th = prep.pose(k, 0)
        body.position = (float(S[0]), float(S[1]))       # body origin = centre of mass
        body.angle = float(th)
        V = prep.V[k][1]                                  # exact velocity half a step ahead
        body.velocity = (float(V[0]) * v_u, float(V[1]) * v_u)
        body.angular_velocity = float(kin.omega[1, k]) * v_u
        space.add(body)
        bodies[k] = body

    def local(k: int, p) -> tuple[float, float]:
        q = np.asarray(p, float) - prep.com[k]
        return float(q[0]), float(q[1])

    pair_c, locks = [], []
    for p in mech.pairs:
        a, b = p.links
        if p.kind == "R":
            c = pymunk.PivotJoint(bodies[a], bodies[b], local(a, mech.links[a].points[p.point]),
                                  local(b, mech.links[b].points[p.point]))
        else:
            c = _groove(prep, p, bodies)
            locks.append(pymunk.GearJoint(bodies[a], bodies[b],
                                          float(kin.theta[0, b] - kin.theta[0, a]), 1.0))
        pair_c.append(c)
    # SimpleMotor drives b.w - a.w = -rate
    motor = pymunk.SimpleMotor(space.static_body, bodies[dr.link], -prep.omega1 * v_u)
    for c in pair_c + locks + [motor]:
        c.error_bias = 1.0 - POSITION_CORRECTION
        space.add(c)

    steps, lead, n_pairs, L = prep.steps, prep.lead, len(mech.pairs), len(prep.links)
    imp = np.zeros((steps, n_pairs))
    tau = np.zeros(steps)
    M_mesh = np.zeros(steps)
    state = np.zeros((steps, L, 6))                   # x, y, angle, vx, vy, w (SI)
    build = time.perf_counter() - t0
    t0 = time.perf_counter()
    crank = dr.link
    jj = 2 * (np.arange(steps) + 1)                   # the angle the positions reach in each step
    F_all, T_all = np.zeros((steps, L, 2)), np.zeros((steps, L))
    for i, lk in enumerate(prep.links):               # the loads of every step, before the steps
        F, T = prep.F_ext[jj, lk], prep.M_ext[jj, lk]
        if lk in prep.comp_F:
            F = F + prep.comp_F[lk][jj]
        if lk in prep.comp_T:
            T = T + prep.comp_T[lk][jj]
        if lk == crank:
            T = T + K
            if M_first is not None:
                f = np.array([prep.mesh_force(float(M)) for M in M_first[:steps]])
                r = prep.pitch - prep.pose(lk, jj)[0]
                M_mesh[:] = r[:, 0] * f[:, 1] - r[:, 1] * f[:, 0]
                F = F + f
                T = T + M_mesh
        F_all[:, i], T_all[:, i] = F, T
    forces, torques = (F_all * f_u).tolist(), (T_all * f_u).tolist()
    order = [bodies[lk] for lk in prep.links]
    for k in range(steps):
        for body, F, T in zip(order, forces[k], torques[k]):
            body.force = (F[0], F[1])
            body.torque = T
        space.step(1.0)
        for i, c in enumerate(pair_c):
            imp[k, i] = c.impulse
        tau[k] = motor.impulse
        for i, lk in enumerate(prep.links):
            body = bodies[lk]
            p, v = body.position, body.velocity
            state[k, i] = (p[0], p[1], body.angle, v[0] / v_u, v[1] / v_u, body.angular_velocity / v_u)
    run = time.perf_counter() - t0

    # checks against the exact motion: poses at index 2(k+1), velocities half a step later
    jp = 2 * (np.arange(steps) + 1)
    pose = np.zeros(steps)
    dv = np.zeros((steps, L, 3))
    w_s, v_s = abs(prep.omega1), abs(prep.omega1) * mech.size
    for i, lk in enumerate(prep.links):
        th = kin.theta[jp, lk]
        S = kin.origin[jp, lk] + rotate(prep.com[lk], th)
        d_th = np.abs((state[:, i, 2] - th + math.pi) % (2 * math.pi) - math.pi) / BRANCH_ANGLE_TOL
        d_x = np.hypot(state[:, i, 0] - S[:, 0], state[:, i, 1] - S[:, 1]) / (BRANCH_POSITION_TOL * mech.size)
        pose = np.maximum(pose, np.maximum(d_th, d_x))
        V, W = prep.V[lk][jp + 1], kin.omega[jp + 1, lk]
        dv[:, i] = np.stack([(state[:, i, 3] - V[:, 0]) / v_s, (state[:, i, 4] - V[:, 1]) / v_s,
                             (state[:, i, 5] - W) / w_s], axis=-1)
    jitter = np.zeros(steps)
    jitter[1:-1] = (np.abs(dv[2:] - 2 * dv[1:-1] + dv[:-2]).max(axis=(1, 2))
                    * prep.n / (4 * math.pi) / JITTER_TOL)
    jitter[-1] = jitter[-2]
    jitter[:lead] = 0.0                               # the lead-in settles the warm start
    pose = np.where(np.isnan(pose), np.inf, pose)
    jitter = np.where(np.isnan(jitter), np.inf, jitter)
    # the motor's torque on the crank is M - K - M_mesh < 0, of magnitude tau / dt
    M_all = K + M_mesh - tau / f_u
    s = slice(lead, steps)
    return _Run(M_all[s], imp[s] / f_u, pose[s], jitter[s], float(np.min(tau[s])) / f_u, M_all,
                _point_kinematics(prep, state)[s], build, run)


def _point_kinematics(prep: _Prep, state: np.ndarray) -> np.ndarray:
    """(steps, 2, n_points, 2) position and velocity (world; m, m/s) of the tracked points from
    the bodies' states, at the angle each step's positions reach. The velocities in `state` are
    half a step ahead of the positions: the velocity there is the mean of the step's and the
    previous step's (second order; the first step has no previous one and is NaN)."""
    steps = len(state)
    out = np.full((steps, 2, len(prep.points), 2), np.nan)
    for n, (name, k) in enumerate(prep.points):
        i = prep.links.index(k)
        S, th, V, w = state[:, i, :2], state[:, i, 2], state[:, i, 3:5], state[:, i, 5]
        r = rotate(np.asarray(prep.mech.links[k].points[name], float) - prep.com[k], th)
        rp = np.stack([-r[:, 1], r[:, 0]], axis=-1)              # z x r
        V_mid, w_mid = 0.5 * (V[1:] + V[:-1]), 0.5 * (w[1:] + w[:-1])
        out[:, 0, n] = S + r
        out[1:, 1, n] = V_mid + w_mid[:, None] * rp[1:]
    return out


def _groove(prep: _Prep, p, bodies):
    """GrooveJoint of prismatic pair p (relative rotation locked by a GearJoint).

    The groove lies on the guide link along the guide direction through the guide's centre of
    mass; where the guide is on a triad's leash, on the other link instead (the rotation locked,
    a point of either link on a line of the other is one constraint; measured: the groove on a
    3 kg rocking block oscillated, 1.7e-2 of the peak reaction, on the base 2.4e-7; on the frame
    as the slider no cycle closed). Its anchor is the slider's point on that line straight
    across (normal to the guide) from the slider's centre of mass. Both lever arms then lie along or across the guide, so
    Chipmunk's 2x2 groove mass does not couple the normal and the sliding direction. On the frame
    (infinite mass) the anchor is the slider's centre of mass. The groove covers the stroke with
    a margin of a stroke plus the mechanism's size at each end.
    """
    import pymunk

    kin = prep.kin
    a, b = p.links
    d = np.asarray(p.direction, float)
    if any(g.klass == 3 and a in g.links[1:] for g in prep.mech.structure.groups):
        a, b = b, a                                                 # the guide's direction in b's frame
        d = rotate(d, float(kin.theta[0, b] - kin.theta[0, a]))
    Sa = kin.origin[:, a] + rotate(prep.com[a], kin.theta[:, a])
    Sb = kin.origin[:, b] + rotate(prep.com[b], kin.theta[:, b])
    dw = rotate(d, kin.theta[:, a])
    nw = np.stack([-dw[:, 1], dw[:, 0]], axis=-1)
    if a == 0:
        Q = rotate(Sb[0] - Sa[0], -float(kin.theta[0, a]))          # groove through S_b
        anchor = np.zeros(2)
        s = np.sum((Sb - Sa - rotate(Q, kin.theta[:, a])) * dw, axis=-1)
    else:
        Q = np.zeros(2)                                             # groove through S_a
        h = float(np.dot(Sb[0] - Sa[0], nw[0]))                     # constant: rotation locked
        anchor = rotate(-h * nw[0], -float(kin.theta[0, b]))        # slider point across from S_b
        s = np.sum((Sb - Sa) * dw, axis=-1)
    lo, hi = float(np.nanmin(s)), float(np.nanmax(s))
    margin = (hi - lo) + prep.mech.size
    g0, g1 = Q + (lo - margin) * d, Q + (hi + margin) * d
    return pymunk.GrooveJoint(bodies[a], bodies[b], (float(g0[0]), float(g0[1])),
                              (float(g1[0]), float(g1[1])), (float(anchor[0]), float(anchor[1])))


def _widen(bad: np.ndarray, w: int) -> np.ndarray:
    """Steps within w of a bad step, periodic over the cycle."""
    padded = np.r_[bad[-w:], bad, bad[:w]].astype(float)
    return np.convolve(padded, np.ones(2 * w + 1), mode="same")[w:-w] > 0


def _fill_nan(a: np.ndarray) -> np.ndarray:
    """Loads at singular angles (NaN in the exact solution) filled from their neighbours."""
    if not np.any(np.isnan(a)):
        return a
    a = a.copy()
    flat = a.reshape(len(a), -1)
    idx = np.arange(len(a))
    for col in range(flat.shape[1]):
        good = np.isfinite(flat[:, col])
        if good.any() and not good.all():
            flat[~good, col] = np.interp(idx[~good], idx[good], flat[good, col])
    return a


def _ranges(angles: np.ndarray) -> str:
    """Compact text of a set of angles, deg: '12.0-15.5, 200.0'."""
    if len(angles) == 0:
        return ""
    a = np.sort(angles)
    parts, start, prev = [], a[0], a[0]
    for x in a[1:]:
        if x - prev > 1.0:
            parts.append(f"{start:.1f}" if start == prev else f"{start:.1f}-{prev:.1f}")
            start = x
        prev = x
    parts.append(f"{start:.1f}" if start == prev else f"{start:.1f}-{prev:.1f}")
    return ", ".join(parts)
