"""Friction in the reactions (the standard continuation of seed 003's first approximation):
the reactions with friction solved exactly, group by group, and what follows from them (the
instantaneous and cycle efficiency, the self-locking angles and the edges of their zones).

The laws, per pair, with the reduced coefficient f of `[friction]` and the journal radius r of
the pair (or the model's default):
- revolute: a friction moment of magnitude f r |R| on pair.links[1], opposing its rotation
  relative to pair.links[0] (the reaction is tangent to the friction circle rho = f r); the
  opposite moment on links[0];
- prismatic: a friction force of magnitude f |N| along the guide on the slider (links[1]),
  opposing its sliding relative to the guide, through the slider point on the guide line (the
  total reaction leans by arctg f from the normal); the opposite force on the guide.

The friction loads are loads like any other: each group's own statics steps (the group's steps
of `program.statics_program`, marked by its `stages`) run again with the friction loads of the
group's pairs added to its links' known wrenches, the loads recomputed from the new reactions,
until the reactions stop changing (fixed-point passes from the frictionless solution, the
texts' successive approximation carried to rounding). Where MAX_PASSES passes do not converge,
Newton's method on the stage's friction loads looks for the equilibrium (from the frictionless
loads). Where a stage's friction gain (`_gain`: reactions with no other load, in equilibrium
with their own friction, grow by this factor per pass) is 1 or more, a pair wedges: the angle
is self-locking, and an equilibrium found there need not be the only one. Groups go in the order of the frictionless
solution (last attached first), then the initial link; each stage's passes converge before the
next stage starts. Vectorised over the angles.

Zero relative motion (a dead centre, a slider at rest): the friction takes the direction of the
relative motion just before, the limit from the side the motion comes from in time: where
|relative velocity| <= RATE_TOL x the crank's (x size for a slider), its sign is -sign(relative
acceleration); where that is 0 too, or the crank stands still, no friction (the friction of
rest is static, indeterminate within its bound).

May use: numpy, program, kinetostatics, planar (model and kinematics for type hints only).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from .kinetostatics import Forces, packed, statics_environment
from .planar import as_xy, cross_z
from .program import Program, run, statics_program

if TYPE_CHECKING:
    from .kinematics import Kinematics
    from .model import Mechanism

__all__ = ["FrictionSolution", "solve", "power", "relative_rate", "motion_sense", "efficiency", "cycle_efficiency",
           "METHODS", "RATE_TOL", "MAX_PASSES", "DEAD_CENTRE", "NO_NET_WORK", "NULL_SHARE"]

#: analyze(friction=...): seed 003's first approximation, or friction in the reactions.
METHODS = ("first", "reactions")
#: A relative velocity below this fraction of the crank's (angular; x size for a slider) is zero.
RATE_TOL = 1e-12
#: Most fixed-point passes per stage; an angle not converged by then goes to Newton's method.
MAX_PASSES = 60
#: Most Newton steps on a stage's friction loads; an angle not converged by then has no equilibrium found.
NEWTON_STEPS = 40
#: eta is undefined (NaN) near a dead centre: where |M0| <= DEAD_CENTRE x |Mf - M0| (`Analysis.efficiency`).
DEAD_CENTRE = 0.1
#: The cycle efficiency is undefined (NaN) where the frictionless drive's work over the cycle is at
#: rounding level: |W0| <= NO_NET_WORK x the integral of |M0 omega_1| over the cycle (`cycle_efficiency`).
#: The loads then do no net work (gravity and inertia only, over a steady cycle): W0 is the rounding
#: left of terms that cancel, found at 2e-17 .. 6e-16 of that integral (a few eps) on the bundled
#: four-bar and triads; 1e-12 leaves room for the digits a solve near a toggle loses, and the
#: smallest real net work of a bundled machine is 0.19 of it (the ICE).
NO_NET_WORK = 1e-12
#: Where Newton's Jacobian is singular to rounding, a pair takes part in it (`FrictionSolution.dependent`)
#: where its share of the null vector is at least this x the largest share (the yoke at f = 1: its two
#: guides 0.71 each, the block's pin 0.01).
NULL_SHARE = 0.1
#: Power-iteration steps for a stage's friction gain (`_gain`).
GAIN_STEPS = 40
#: Converged: the largest change of a stage's reactions in one pass below this x its largest reaction.
PASS_TOL = 1e-14
#: ... or the change stopped decreasing below this x the largest reaction (the rounding floor).
FLOOR_TOL = 1e-10


@dataclass(frozen=True)
class FrictionSolution:
    """The friction loads of the exact solution (`analyze(mech, friction="reactions")`)."""
    M_bal_frictionless: np.ndarray   # (N,) balancing moment without friction, N m about +z
    load: np.ndarray      # (N, n_pairs) revolute: friction moment on pair.links[1], N m about +z;
                          #   prismatic: friction force on the slider along the guide's direction d, N;
                          #   the opposite on pair.links[0]
    F: np.ndarray         # (N, L) complex: all friction forces on each link, N, world
    M: np.ndarray         # (N, L) their moment about each link's local origin, N m
    passes: np.ndarray    # (N, n_groups + 1) int: fixed-point passes of each stage (groups in the
                          #   order solved, then the initial link); above MAX_PASSES: MAX_PASSES +
                          #   the Newton steps that found the equilibrium; 0 where singular or unsolved
    solved: np.ndarray    # (N,) bool: an equilibrium found at every stage (False: NaN forces, friction
                          #   loads and so friction power)
    wedged: np.ndarray    # (N,) bool: at some stage a pair wedges: with no other load, the friction
                          #   loads call for reactions whose friction is at least as large (`_gain`
                          #   >= 1): self-locking; the equilibrium found there need not be the only one
    dependent: np.ndarray  # (N, n_pairs) bool: the pairs whose friction loads Newton's Jacobian found
                          #   dependent (singular to rounding, the pairs of its null vector, NULL_SHARE),
                          #   where Newton stopped: no equilibrium found there (False elsewhere)

    def __repr__(self) -> str:
        return f"FrictionSolution(positions={len(self.solved)}, passes<={int(self.passes.max(initial=0))})"

    @property
    def newton(self) -> np.ndarray:
        """(N,) bool: Newton's method found the equilibrium at some stage (the passes did not converge)."""
        return (self.passes > MAX_PASSES).any(axis=1)

    def take(self, idx) -> "FrictionSolution":
        """The solution at the angles `idx` only."""
        return FrictionSolution(*(getattr(self, f)[idx] for f in self.__dataclass_fields__))


def _coefficients(mech: "Mechanism") -> np.ndarray:
    """(n_pairs,) f r of each revolute pair (m), f of each prismatic one."""
    fr = mech.friction
    return np.array([fr.f * ((p.radius if p.radius is not None else fr.radius) if p.kind == "R" else 1.0)
                     for p in mech.pairs])


def relative_rate(mech: "Mechanism", kin: "Kinematics") -> tuple[np.ndarray, np.ndarray]:
    """(N, n_pairs) each: the motion of pair.links[1] relative to links[0] (omega_j - omega_i,
    rad/s, for a revolute pair; the sliding velocity, m/s, for a prismatic one) and its rate
    (rad/s^2; m/s^2)."""
    i, j = np.array([p.links for p in mech.pairs]).T
    revolute = np.array([p.kind == "R" for p in mech.pairs])
    return (np.where(revolute, kin.omega[:, j] - kin.omega[:, i], kin.v_slide),
            np.where(revolute, kin.eps[:, j] - kin.eps[:, i], kin.a_slide))


def power(mech: "Mechanism", kin: "Kinematics", load: np.ndarray) -> np.ndarray:
    """(N, n_pairs) power lost in each pair, W: -(friction load (`FrictionSolution.load`) x the
    relative motion) at the motion `kin`, signed: >= 0 wherever the friction opposes the motion
    (a load along the motion would show as a negative loss); where the relative motion is below
    RATE_TOL (at rest, `motion_sense`) |load x rate|, a rounding-sized loss, never negative."""
    rate = relative_rate(mech, kin)[0]
    revolute = np.array([p.kind == "R" for p in mech.pairs])
    still = np.abs(rate) <= RATE_TOL * np.abs(kin.omega[:, 1:2]) * np.where(revolute, 1.0, mech.size)
    return np.where(still, np.abs(load * rate), -load * rate)


def motion_sense(mech: "Mechanism", kin: "Kinematics") -> np.ndarray:
    """(N, n_pairs) sign of the motion of pair.links[1] relative to links[0] (`relative_rate`),
    with the module's convention where it is zero."""
    revolute = np.array([p.kind == "R" for p in mech.pairs])
    rate, accel = relative_rate(mech, kin)
    crank = np.abs(kin.omega[:, 1:2])
    still = np.abs(rate) <= RATE_TOL * crank * np.where(revolute, 1.0, mech.size)
    return np.where(still, np.where(crank > 0, -np.sign(accel), 0.0), np.sign(rate))


def _wrench(env: dict, p, q: np.ndarray, d: np.ndarray, S: np.ndarray, F: np.ndarray, M: np.ndarray) -> None:
    """Add the friction load q (N,) of pair p to the wrenches F, M (N, L) of its moving links:
    a couple (revolute), or q d through S (prismatic); the opposite on links[0]."""
    i, j = p.links
    for k, s in ((j, 1.0), (i, -1.0)):
        if not k:
            continue
        if p.kind == "R":
            M[:, k] += s * q
        else:
            F[:, k] += s * q * d
            M[:, k] += s * cross_z(S - env[f"O{k}"], q * d)


def solve(mech: "Mechanism", kin: "Kinematics", F: np.ndarray, M: np.ndarray, M_bal_frictionless: np.ndarray
          ) -> tuple[Forces, FrictionSolution]:
    """Reactions and balancing load with friction in the reactions, from the known wrenches F
    (complex), M (N, L) about each link's origin (applied and inertia), as `kinetostatics.forces`
    takes them. Call under np.errstate(all="ignore"), as `analyze` does."""
    prog = statics_program(mech)
    env = statics_environment(mech, kin, F, M)
    N, L, n = len(kin.phi), mech.n_links, len(mech.pairs)
    sense, coef = motion_sense(mech, kin), _coefficients(mech)
    d = {p.index: complex(*p.direction) * (kin.rot[:, p.links[0]] if p.links[0] else 1.0)
         for p in mech.pairs if p.kind == "P"}
    S = {p.index: kin.position_z(p.links[1], mech.links[p.links[1]].points[p.point])
         for p in mech.pairs if p.kind == "P"}
    load = np.zeros((N, n))
    F_fr, M_fr = np.zeros((N, L), complex), np.zeros((N, L))
    bounds = prog.stages + (len(prog.steps),)
    passes = np.zeros((N, len(prog.stages)), int)
    solved, wedged, dependent = np.ones(N, bool), np.zeros(N, bool), np.zeros((N, n), bool)
    names = [f"{s}{k}" for s in "FM" for k in range(1, L)]
    for st in range(len(prog.stages)):
        segment = mech.memo(("friction_stage", st), lambda: _segment(prog, bounds[st], bounds[st + 1]))
        pairs = [p for p in mech.pairs if any(f"R{p.index}" in s.out for s in segment.steps)]
        keep = {k: env[k] for k in names}

        def reactions() -> np.ndarray:
            return np.stack([env[f"R{p.index}"] if p.kind == "R" else env[f"N{p.index}"] for p in pairs], -1) \
                * np.ones((N, 1))

        def friction(R: np.ndarray) -> np.ndarray:
            return -coef[[p.index for p in pairs]] * np.abs(R) * sense[:, [p.index for p in pairs]]

        def apply(q: np.ndarray, base: dict = keep) -> np.ndarray:
            """Run the stage with the friction loads q (N, n) on its links, added to the known
            wrenches `base`; its reactions."""
            env.update(base)
            dF, dM = np.zeros((N, L), complex), np.zeros((N, L))
            for c, p in enumerate(pairs):
                _wrench(env, p, q[:, c], d.get(p.index), S.get(p.index), dF, dM)
            for k in range(1, L):
                env[f"F{k}"], env[f"M{k}"] = base[f"F{k}"] + dF[:, k], base[f"M{k}"] + dM[:, k]
            run(segment, env)
            wrench[:] = dF, dM
            return reactions()

        wrench: list = [None, None]
        run(segment, env)
        R = reactions()
        done = ~np.isfinite(R).all(axis=1) | ~solved       # singular there, or an earlier stage unsolved
        q0 = q = friction(R)
        wedged |= ~done & (_gain(lambda q: friction(apply(q, {k: 0.0 * keep[k] for k in names})),
                                 -sense[:, [p.index for p in pairs]]) >= 1.0)
        last = np.full(N, np.inf)
        for count in range(1, MAX_PASSES + 1):
            R_new = apply(q)
            change = np.abs(R_new - R).max(axis=1)
            scale = np.abs(R_new).max(axis=1)
            now = ~done & ((change <= PASS_TOL * scale) | ((change >= last) & (change <= FLOOR_TOL * scale)))
            passes[now, st] = count
            done |= now
            applied, R, last = q, R_new, change
            if done.all():
                break
            q = friction(R)
        if not done.all():                 # the passes do not converge there: Newton on the friction loads
            applied, R, newton, tied = _newton(apply, friction, np.where(done[:, None], applied, q0), ~done)
            dependent[:, [p.index for p in pairs]] |= tied
            passes[newton > 0, st] = MAX_PASSES + newton[newton > 0]
            done |= newton > 0
        dF, dM = wrench
        failed = ~done
        for c, p in enumerate(pairs):
            load[:, p.index] = applied[:, c]
        F_fr += dF
        M_fr += dM
        if failed.any():
            solved &= ~failed
            for k in names:
                env[k] = np.where(failed, np.nan, env[k])
    load[~solved] = np.nan                   # no equilibrium: no friction load (not the last pass's)
    F_fr[~solved], M_fr[~solved] = np.nan, np.nan
    frc = packed(mech, env, N)
    for p in mech.pairs:                     # a guide's reaction leans: its friction force joins the normal one
        if p.kind == "P":
            frc.R[:, p.index] += as_xy(load[:, p.index] * d[p.index])
    if not solved.all():
        frc = Forces(*(np.where(solved.reshape((N,) + (1,) * (a.ndim - 1)), a, np.nan)
                       for a in (frc.R, frc.normal, frc.m, frc.M_bal, frc.F_bal)))
    return frc, FrictionSolution(np.asarray(M_bal_frictionless, float), load, F_fr, M_fr, passes, solved, wedged,
                                 dependent)


def _gain(T, q: np.ndarray) -> np.ndarray:
    """(N,) the growth factor of the friction loads through a stage with no other load: the
    friction loads T(q) that the reactions to the loads q (N, n) call for, |T^k q|^(1/k) for
    large k, by power iteration (T is positively homogeneous of degree 1). At least 1: a pair
    wedges (reactions with no load in equilibrium with their own friction: self-locking)."""
    gain = np.zeros(len(q))
    size = np.abs(q).max(axis=1)
    for _ in range(GAIN_STEPS):
        q = np.where(size[:, None] > 0, q / np.where(size > 0, size, 1.0)[:, None], 0.0)
        q = T(q)
        size = np.abs(q).max(axis=1)
        gain, last = np.nan_to_num(size, nan=np.inf), gain
        if np.all(np.abs(gain - last) <= 1e-9 * np.maximum(gain, 1.0)):     # settled (inf - inf: not)
            break
    return gain


def _newton(apply, friction, q: np.ndarray, todo: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Newton's method on a stage's friction loads q (N, n) at the angles `todo`: the root of
    H(q) = friction(apply(q)) - q, its Jacobian by forward differences (n + 1 stage runs a step,
    over all angles at once; the other angles keep their q). Returns the loads, the reactions
    apply gives with them, the steps each angle took (0: no root found: H not below PASS_TOL of
    the loads within NEWTON_STEPS, or the Jacobian singular to rounding, as where two pairs'
    friction loads enter the stage only as their sum: no root, or no unique one) and (N, n) bool
    the pairs of the null vector where Newton stopped on a singular Jacobian (share >= NULL_SHARE)."""
    N, n = q.shape
    steps = np.zeros(N, int)
    dependent = np.zeros((N, n), bool)
    for k in range(1, NEWTON_STEPS + 1):
        R = apply(q)
        H = friction(R) - q
        size = np.abs(q).max(axis=1) + np.abs(friction(R)).max(axis=1)
        ok = todo & (np.abs(H).max(axis=1) <= PASS_TOL * size) & np.isfinite(H).all(axis=1)
        steps[ok] = k
        todo = todo & ~ok
        if not todo.any():
            break
        J = np.empty((N, n, n))
        for c in range(n):
            h = 1e-7 * (np.abs(q[:, c]) + 1e-3 * size) + 1e-300
            dq = q.copy()
            dq[:, c] += h
            J[:, :, c] = (friction(apply(dq)) - dq - H) / h[:, None]
        finite = np.isfinite(J).all(axis=(1, 2))
        _, s, vt = np.linalg.svd(np.where((todo & finite)[:, None, None], J, np.eye(n)))
        singular = todo & finite & (s[:, -1] <= s[:, 0] * n * np.finfo(float).eps)   # numpy's matrix_rank rule
        null = np.abs(vt[:, -1, :])
        dependent |= singular[:, None] & (null >= NULL_SHARE * null.max(axis=1, keepdims=True))
        todo = todo & ~singular
        with np.errstate(all="ignore"):
            step = np.linalg.solve(np.where(todo[:, None, None], J, np.eye(n)), np.where(todo[:, None], -H, 0.0)[..., None])
        q = np.where(todo[:, None], q + step[..., 0], q)
    R = apply(q)
    return q, R, steps, dependent


def _segment(prog: Program, start: int, stop: int) -> Program:
    """The steps [start, stop) of `prog` as a program that leaves every name it writes."""
    steps = prog.steps[start:stop]
    return Program(steps, (), tuple(dict.fromkeys(o for s in steps for o in s.out)))


def efficiency(M0: np.ndarray, Mf: np.ndarray, turn: np.ndarray, tol: np.ndarray) -> np.ndarray:
    """(N,) instantaneous efficiency from the balancing moments without (M0) and with (Mf)
    friction, N m; `turn` the sign of the crank's rotation (+-1): M0/Mf where the drive works
    against the loads (M0 turn >= 0), Mf/M0 where the loads drive the crank (M0 turn < 0); NaN
    where both moments are below `tol` (a dead centre: undefined); M0 below `tol` alone counts as
    0 (eta = 0: the drive works against friction only)."""
    M0 = np.where(np.abs(M0) <= tol, 0.0, M0)
    with np.errstate(divide="ignore", invalid="ignore"):
        eta = np.where(M0 * turn >= 0, M0 / Mf, Mf / M0) + 0.0      # + 0.0: no -0
    return np.where((np.abs(M0) <= tol) & (np.abs(Mf) <= tol), np.nan, eta)


def cycle_efficiency(W0: float, Wf: float, scale: float) -> float:
    """Efficiency over one revolution, 1, from the works of the balancing moment without (W0)
    and with (Wf) friction, J, by the rule of `efficiency`: W0 / Wf where W0 > 0, Wf / W0 where
    the loads drive the crank. NaN where |W0| <= NO_NET_WORK x `scale` (the integral of |M0
    omega_1| over the cycle, J): the loads do no net work, W0 is rounding."""
    if not abs(W0) > NO_NET_WORK * scale:
        return float("nan")
    return float(W0 / Wf if W0 > 0 else Wf / W0)
