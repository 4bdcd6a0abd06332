"""A mechanism compiled to a program: the straight-line sequence of calls to the group equations
(`groups`) that solves its kinematics (groups in the order of attachment) and its kinetostatics
(from the last group to the first, then the initial link), and the executor that runs it on
arrays.

A program is built once per structure (`motion_program`, `statics_program`): its steps name
their inputs and outputs; the numbers of one design (points, directions, masses, the group
scales: `constants`) enter as the environment it runs in. The same program runs
- on numpy arrays over the angles (`run`): today's path;
- on the arrays of any Array API library (`run` with that namespace: `bind`);
- on scalars inside a compiled loop over designs and angles (`kinetostat.fast` generates it
  from `code`, over groups' source with its compiled primitives).

May use: numpy, groups, triad, sizes, errors (model and structure for type hints only).
"""
from __future__ import annotations

import types
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Callable, Mapping, NamedTuple

import numpy as np

from . import groups, triad
from .errors import AssemblyError
from .sizes import group_scales

if TYPE_CHECKING:
    from .model import Mechanism, Pair
    from .structure import AssurGroup, Triad

__all__ = ["Step", "Program", "motion_program", "statics_program", "constants", "run", "bind",
           "code", "free_names", "compiled", "Identifiers", "REACH_TOL"]

#: An assembly discriminant below -REACH_TOL x its scale: the group cannot be assembled there.
REACH_TOL = 1e-12


class Step(NamedTuple):
    """out = groups.<fn>(*args): args are names in the environment or literal numbers. fn
    "check" is the assembly test: args (discriminant, scale), `why` says what fails."""
    fn: str
    args: tuple
    out: tuple[str, ...]
    group: str = ""
    why: str = ""


@dataclass(frozen=True)
class Program:
    """Steps over an environment of named values; `inputs` the per-angle names it reads (phi,
    or the motion for the statics), `outputs` the names it leaves for the caller."""
    steps: tuple[Step, ...]
    inputs: tuple[str, ...]
    outputs: tuple[str, ...]
    stages: tuple[int, ...] = ()     # statics: the index of the first step of each group (in the
                                     # order solved) and of the initial link


# ----------------------------------------------------------------------------- the numbers of one design
def constants(mech: "Mechanism", points: tuple[Mapping[str, complex], ...] | None = None,
              scales: list[float] | None = None) -> dict[str, Any]:
    """The base constants the programs of `mech` read: every local point (x<k>_<name>, complex),
    every guide direction (d<p>, complex unit) and its angle (alpha<p>), the group scales
    (L<n>, m), the drive, the masses (mass<k>, I_S<k>, com<k> the local centre of mass), g,
    the gear, the design angle phi_design (rad) and each triad's track<n> (None here: a
    `triad.Track` that `kinematics.tracks` sets). `points`: the local points (default the
    model's; the accuracy check passes them perturbed); `scales`: the group scales."""
    pts = mech.points_z if points is None else points
    c: dict[str, Any] = {}
    for k, link_pts in enumerate(pts):
        for name, z in link_pts.items():
            c[_x(k, name)] = z
    for p in mech.pairs:
        if p.kind == "P":
            c[f"d{p.index}"], c[f"alpha{p.index}"] = complex(*p.direction), p.alpha
    for n, L in enumerate(group_scales(mech) if scales is None else scales):
        c[f"L{n}"] = L
    dr = mech.drive
    c["sense"] = float(dr.sense)
    c["ref_phase"] = float(np.arctan2(dr.reference[1], dr.reference[0]))
    mass, I_S, com = mech.inertia_arrays
    for k in range(1, mech.n_links):
        c[f"mass{k}"], c[f"I_S{k}"], c[f"com{k}"] = float(mass[k]), float(I_S[k]), complex(com[k])
    c["g"] = float(mech.g)
    c["phi_design"] = float(np.radians(dr.design_deg))
    for n, grp in enumerate(mech.structure.groups):
        if grp.klass == 3:
            c[f"track{n}"] = None        # a triad's poses at the stations (`kinematics` sets them)
    if dr.kind == "machine":
        g = dr.gear
        c["gear_e"], c["gear_alpha"], c["gear_rb"] = complex(*g.centre_direction), float(np.radians(g.alpha_w_deg)), g.r_b
    return c


def _x(k: int, name: str) -> str:
    return f"x{k}_{name}"


# ----------------------------------------------------------------------------- building
class _Build:
    """Accumulates steps; knows which link's motion is in which names. The frame's points are
    constants with no velocity or acceleration."""

    def __init__(self, mech: "Mechanism"):
        self.mech = mech
        self.steps: list[Step] = []
        self.n = 0

    def tmp(self, stem: str = "t") -> str:
        self.n += 1
        return f"{stem}_{self.n}"

    def call(self, fn: str, *args, out: int | tuple[str, ...] = 1) -> Any:
        names = tuple(self.tmp() for _ in range(out)) if isinstance(out, int) else out
        self.steps.append(Step(fn, args, names))
        return names[0] if len(names) == 1 else names

    def const(self, fn: str, *args) -> str:
        """A derived constant (memoised by its expression)."""
        key = f"c_{fn}_" + "_".join(str(a) for a in args)
        if key not in self._consts:
            self._consts.add(key)
            self.steps.append(Step(fn, args, (key,)))
        return key

    _consts: set

    def length(self, k: int, a: str, b: str) -> str:
        """|x_a - x_b| of link k."""
        return self.const("length", _x(k, a), _x(k, b))

    def offset(self, p: "Pair", k: int, name: str) -> str:
        """Signed distance c = (X - G) x d of point `name` of link k from pair p's guide line."""
        if k == p.links[0]:
            return self.const("guide_offset", _x(k, name), _x(k, p.guide), f"d{p.index}")
        return self.const("slider_offset", _x(k, name), _x(k, p.point))

    @staticmethod
    def anchor(p: "Pair", k: int) -> str:
        """A point of link k that lies on the guide line (c = 0)."""
        return p.guide if k == p.links[0] else p.point


class _Motion(_Build):
    """The kinematics program: link k's angle, e^{i theta}, origin motion in th<k>, rot<k>,
    O<k>, V<k>, A<k>, w<k>, e<k>; pair p's sliding in vs<p>, as<p>; group n's conditioning in
    cond<n>."""

    def __init__(self, mech: "Mechanism"):
        super().__init__(mech)
        self._consts = set()
        self.slides: set[int] = set()

    def motion(self, k: int) -> tuple[str, ...]:
        return tuple(f"{s}{k}" for s in ("O", "V", "A", "w", "e"))

    def point(self, k: int, name: str) -> tuple:
        if not k:
            return _x(0, name), 0.0, 0.0
        O, V, A, w, e = self.motion(k)
        return self.call("point_motion", O, V, A, w, e, f"rot{k}", _x(k, name), out=3)

    def position(self, k: int, name: str):
        return self.call("place", f"O{k}", f"rot{k}", _x(k, name)) if k else _x(0, name)

    def at(self, k: int, X: str) -> tuple:
        if not k:
            return 0.0, 0.0
        O, V, A, w, e = self.motion(k)
        return self.call("motion_at", O, V, A, w, e, X, out=2)

    def set_link(self, k: int, th, rot, X, x_local, w, V, e, A) -> None:
        """Fix link k from its angle th, rot, and the motion X, V, A of its local point x_local."""
        self.steps.append(Step("origin_motion", (X, V, A, w, e, rot, x_local), (f"O{k}", f"V{k}", f"A{k}")))
        for name, value in ((f"th{k}", th), (f"rot{k}", rot), (f"w{k}", w), (f"e{k}", e)):
            self.steps.append(Step("same", (value,), (name,)))

    def aligned(self, k: int, a: str, b: str, X: str) -> tuple[str, str]:
        """Angle and e^{i theta} of link k whose local vector x_b - x_a is the world vector X."""
        x = self.const("sub", _x(k, b), _x(k, a))
        return self.call("aligned", X, x, self.const("phase", x), out=2)

    def turned(self, p: "Pair", k: int, th, rot) -> tuple:
        """Angle and e^{i theta} of link k of P pair p from those of the pair's other link."""
        if not p.alpha:
            return th, rot
        fn = "turn" if k == p.links[1] else "unturn"
        return self.call(fn, th, rot, f"alpha{p.index}", f"d{p.index}", out=2)

    def guide(self, p: "Pair", k: int, rot_k) -> str:
        """World unit direction d of pair p's guide, given e^{i theta} of its link k."""
        return self.call("times", f"d{p.index}", rot_k) if k == p.links[0] else rot_k

    def check(self, g: "AssurGroup", disc: str, scale, why: str) -> None:
        self.steps.append(Step("check", (disc, scale), (), g.label, why))

    def slide(self, p: "Pair", mover: int, v, a) -> None:
        """Record the motion of `mover` relative to the pair's other link along d."""
        self.slides.add(p.index)
        sign = 1.0 if mover == p.links[1] else -1.0
        self.steps.append(Step("scaled", (v, sign), (f"vs{p.index}",)))
        self.steps.append(Step("scaled", (a, sign), (f"as{p.index}",)))

    def conditioning(self, n: int, frob, det) -> None:
        self.steps.append(Step("condition", (frob, det), (f"cond{n}",)))

    # -- the groups, exactly as the vector equations of the texts read
    def rrr(self, n: int, g: "AssurGroup") -> None:
        (pj, pin, pk), (j, k), (a, c) = g.pairs, g.links, g.known
        P, VP, AP = self.point(a, pj.point)
        Q, VQ, AQ = self.point(c, pk.point)
        lj, lk = self.length(j, pin.point, pj.point), self.length(k, pin.point, pk.point)
        disc, B, PB, QB, wj, wk, ej, ek, frob, det = self.call(
            "rrr_motion", P, VP, AP, Q, VQ, AQ, lj, lk, float(g.branch), f"L{n}", out=10)
        self.check(g, disc, self.const("square", lj), f"|{pj.point}{pk.point}| outside [|l{j} - l{k}|, l{j} + l{k}]")
        self.set_link(j, *self.aligned(j, pj.point, pin.point, PB), P, _x(j, pj.point), wj, VP, ej, AP)
        self.set_link(k, *self.aligned(k, pk.point, pin.point, QB), Q, _x(k, pk.point), wk, VQ, ek, AQ)
        self.conditioning(n, frob, det)

    def rrp(self, n: int, g: "AssurGroup") -> None:
        (pj, pin, pk), (j, k), (a, b) = g.pairs, g.links, g.known
        P, VP, AP = self.point(a, pj.point)
        th_k, rot_k = self.turned(pk, k, *self.frame_of(b))
        d = self.guide(pk, k, rot_k)
        K = self.position(b, self.anchor(pk, b))
        lj = self.length(j, pin.point, pj.point)
        Ob, Vb, Ab, wb, eb = self.motion(b) if b else (0.0,) * 5
        disc, B, PB, wj, VB, ej, AB, vr, ar, frob, det = self.call(
            "rrp_motion", P, VP, AP, K, d, self.offset(pk, k, pin.point), lj, float(g.branch),
            Ob, Vb, Ab, wb, eb, f"L{n}", out=11)
        self.check(g, disc, self.const("square", lj), f"the guide line is farther than l{j} from {pj.point}")
        self.set_link(j, *self.aligned(j, pj.point, pin.point, PB), P, _x(j, pj.point), wj, VP, ej, AP)
        self.set_link(k, th_k, rot_k, B, _x(k, pin.point), wb, VB, eb, AB)
        self.slide(pk, k, vr, ar)
        self.conditioning(n, frob, det)

    def rpr(self, n: int, g: "AssurGroup") -> None:
        (pj, pin, pk), (j, k), (a, c) = g.pairs, g.links, g.known   # j slides on k's guide
        P, VP, AP = self.point(a, pj.point)
        Q, VQ, AQ = self.point(c, pk.point)
        e = self.const("sub", self.offset(pin, j, pj.point), self.offset(pin, k, pk.point))
        disc, d, th_j, wk, ek, vr, ar, frob, det = self.call(
            "rpr_motion", P, VP, AP, Q, VQ, AQ, e, float(g.branch), f"L{n}", out=9)
        self.check(g, disc, self.const("square", f"L{n}"), f"{pj.point} comes closer than the guide offset to {pk.point}")
        self.set_link(k, *self.turned(pin, k, th_j, d), Q, _x(k, pk.point), wk, VQ, ek, AQ)
        self.set_link(j, th_j, d, P, _x(j, pj.point), wk, VP, ek, AP)
        self.slide(pin, j, vr, ar)
        self.conditioning(n, frob, det)

    def prp(self, n: int, g: "AssurGroup") -> None:
        (pj, pin, pk), (j, k), (a, c) = g.pairs, g.links, g.known
        th_j, rot_j = self.turned(pj, j, *self.frame_of(a))
        th_k, rot_k = self.turned(pk, k, *self.frame_of(c))
        da, dc = self.guide(pj, j, rot_j), self.guide(pk, k, rot_k)
        Ka = self.call("off_line", self.position(a, self.anchor(pj, a)), self.offset(pj, j, pin.point), da)
        Kc = self.call("off_line", self.position(c, self.anchor(pk, c)), self.offset(pk, k, pin.point), dc)
        B, VB, AB, v1, v2, a1, a2, frob, det = self.call(
            "prp_motion", Ka, da, Kc, dc, *self.motion_or_rest(a), *self.motion_or_rest(c), out=9)
        wa, ea = (f"w{a}", f"e{a}") if a else (0.0, 0.0)
        wc, ec = (f"w{c}", f"e{c}") if c else (0.0, 0.0)
        self.set_link(j, th_j, rot_j, B, _x(j, pin.point), wa, VB, ea, AB)
        self.set_link(k, th_k, rot_k, B, _x(k, pin.point), wc, VB, ec, AB)
        self.slide(pj, j, v1, a1)
        self.slide(pk, k, v2, a2)
        self.conditioning(n, frob, det)

    def rpp(self, n: int, g: "AssurGroup") -> None:
        (pj, pin, pk), (j, k), (a, c) = g.pairs, g.links, g.known
        P, VP, AP = self.point(a, pj.point)
        th_k, rot_k = self.turned(pk, k, *self.frame_of(c))
        th_j, rot_j = self.turned(pin, j, th_k, rot_k)
        d_in, dc = self.guide(pin, k, rot_k), self.guide(pk, k, rot_k)
        Oj = self.call("origin_motion", P, 0.0, 0.0, 0.0, 0.0, rot_j, _x(j, pj.point), out=3)[0]
        Kj = self.call("place", Oj, rot_j, _x(j, self.anchor(pin, j)))
        Kc = self.position(c, self.anchor(pk, c))
        rY = self.call("times", _x(k, self.anchor(pin, k)), rot_k)
        rX = self.call("times", _x(k, self.anchor(pk, k)), rot_k)
        Ok, VB, AB, v1, v2, a1, a2, frob, det = self.call(
            "rpp_motion", P, VP, AP, Kj, d_in, dc, Kc, rX, rY, *self.motion_or_rest(c), out=9)
        wc, ec = (f"w{c}", f"e{c}") if c else (0.0, 0.0)
        self.set_link(j, th_j, rot_j, P, _x(j, pj.point), wc, VP, ec, AP)
        self.set_link(k, th_k, rot_k, P, self.call("local_of", P, Ok, rot_k), wc, VB, ec, AB)
        self.slide(pin, j, v1, a1)
        self.slide(pk, k, v2, a2)
        self.conditioning(n, frob, det)

    def iii3(self, n: int, g: "Triad") -> None:
        """III3: the base link's pose by Newton with continuation (`triad.iii3_positions`), then
        the plans at Assur's special point S (the two leash axes meeting at the best angle) as
        2x2 solves. A leash (`triad.LEASH_KINDS`): (kind, x on the base, P, c as `triad.misses`
        reads them, then the outer pin's velocity and acceleration; a slider's: its guide's world
        direction)."""
        b = g.links[0]
        X, leash = [], []
        for i in range(3):
            po, pi, ell, a = g.pairs[2 * i], g.pairs[2 * i + 1], g.links[1 + i], g.known[i]
            if po.kind == "R" and pi.kind == "R":
                A, VA, AA = self.point(a, po.point)
                leash.append(("R", _x(b, pi.point), A, self.length(ell, pi.point, po.point), VA, AA))
            elif po.kind == "P":
                d = self.guide(po, a, self.frame_of(a)[1])
                K = self.call("off_line", self.position(a, self.anchor(po, a)), self.offset(po, ell, pi.point), d)
                leash.append(("P", _x(b, pi.point), K, self.call("times", d, 1j), d))
            else:                # the base's line through A, at A's offset from the guide (local to the base)
                A, VA, AA = self.point(a, po.point)
                d = f"d{pi.index}" if b == pi.links[0] else 1.0
                x = self.const("off_line", _x(b, self.anchor(pi, b)), self.offset(pi, ell, po.point), d)
                leash.append(("L", x, A, self.const("times", d, 1j), VA, AA))
        O, rot, closure, path, _, _ = self.call(
            "iii3_positions", "phi", "phi_design", *(float(triad.LEASH_KINDS.index(m[0])) for m in leash),
            *(m[1] for m in leash), *(m[2] for m in leash), *(m[3] for m in leash),
            f"L{n}", f"track{n}", out=(self.tmp(), self.tmp(), self.tmp(), self.tmp(), f"it{n}", f"res{n}"))
        self.steps.append(Step("check", (closure, 0.0), (), g.label, "the three leashes do not close in the mode "
                               "drawn at the design position: the crank cannot reach these angles from there"))
        self.steps.append(Step("check", (path, 0.0), (), g.label, "Newton left the mode's path: another assembly "
                               "mode is near"))
        u = []
        for i, m in enumerate(leash):
            K = self.call("place", O, rot, m[1])
            if m[0] == "L":           # the axis: the base's line's normal through the outer pin
                X.append(m[2])
                u.append(self.call("leash_slider", K, m[2], self.call("times", m[3], rot), out=2)[0])
            else:
                X.append(K)
                u.append(self.call("leash_rr" if m[0] == "R" else "leash_slider", K, m[2], m[3], out=2)[0])
        S, det, k = self.call("special_point", X[0], u[0], X[1], u[1], X[2], u[2], out=3)
        ref = [self.at(g.known[i], X[i])[0] if m[0] == "P" else m[4] for i, m in enumerate(leash)]
        vS, w, h = self.call("iii3_velocity", S, *X, *u, det, k, *ref, out=3)
        VX = [self.call("motion_at", S, vS, 0.0, w, 0.0, Xi, out=2)[0] for Xi in X]
        normal = [self.leash_motion(g, i, m, X[i], u[i], VX[i], 0.0, w)[2] for i, m in enumerate(leash)]
        acc = [self.at(g.known[i], X[i])[1] if m[0] == "P" else m[5] for i, m in enumerate(leash)]
        aS, e = self.call("iii3_acceleration", S, *X, *u, det, k, h, w, *acc, *normal, out=2)
        th = self.call("phase", rot)
        self.set_link(b, th, rot, S, self.call("local_of", S, O, rot), w, vS, e, aS)
        for i, m in enumerate(leash):
            po, pi, ell, a = g.pairs[2 * i], g.pairs[2 * i + 1], g.links[1 + i], g.known[i]
            AX = self.call("motion_at", S, vS, aS, w, e, X[i], out=2)[1]
            w_l, e_l, _ = self.leash_motion(g, i, m, X[i], u[i], VX[i], AX, w)
            if m[0] == "R":
                self.set_link(ell, *self.aligned(ell, po.point, pi.point, self.call("sub", X[i], m[2])), m[2],
                              _x(ell, po.point), w_l, m[4], e_l, m[5])
            elif m[0] == "P":
                wa, ea = (f"w{a}", f"e{a}") if a else (0.0, 0.0)
                self.set_link(ell, *self.turned(po, ell, *self.frame_of(a)), X[i], _x(ell, pi.point), wa, VX[i], ea, AX)
                self.slide(po, ell, w_l, e_l)
            else:                     # turns with the base; its pin A moves with the known link
                self.set_link(ell, *self.turned(pi, ell, th, rot), X[i], _x(ell, po.point), w, m[4], e, m[5])
                self.slide(pi, ell, w_l, e_l)
        self.steps.append(Step("iii3_condition", (*u, det, k, h, f"L{n}"), (f"cond{n}",)))

    def leash_motion(self, g: "Triad", i: int, m: tuple, X, u, VX, AX, w) -> tuple:
        """Leash i's (omega, eps, normal term) given the motion VX, AX of the base's point at X
        (its axis' point); a slider's (v_r, a_r, Coriolis term) on the known link's line; a
        leash on an inner prismatic pair the same of its outer pin A (at X) on the base's line
        (turning at w, the base's omega), the term taken to the base's side: -2 w v_r."""
        if m[0] == "R":
            return self.call("rr_leash_motion", X, m[2], VX, m[4], AX, m[5], out=3)
        if m[0] == "P":
            a = g.known[i]
            VXa, AXa = self.at(a, X)
            return self.call("slider_leash_motion", m[4], VX, VXa, AX, AXa, f"w{a}" if a else 0.0, out=3)
        vr, ar, cor = self.call("slider_leash_motion", self.call("times", u, -1j), m[4], VX, m[5], AX, w, out=3)
        return vr, ar, self.call("scaled", cor, -1.0)

    def frame_of(self, k: int) -> tuple:
        """Angle and e^{i theta} of link k (the frame's are constants)."""
        return (f"th{k}", f"rot{k}") if k else (0.0, 1.0 + 0j)

    def motion_or_rest(self, k: int) -> tuple:
        """O, V, A, w, e of link k; the frame's at rest."""
        return self.motion(k) if k else (0.0,) * 5


def _solver(g: "AssurGroup | Triad") -> str:
    """The builder's method for group g: its kind's name, iii3 for a triad."""
    return "iii3" if g.klass == 3 else g.kind.lower()


def motion_program(mech: "Mechanism") -> Program:
    """The kinematics of `mech` (memoised per mechanism): inputs phi (rad) and the crank's
    w_in, e_in in the drive's sense (rad/s, rad/s^2)."""
    def make() -> Program:
        b = _Motion(mech)
        dr = mech.drive
        arm = b.const("sub", _x(1, dr.point), _x(1, dr.pivot))
        offset = b.const("sub", "ref_phase", b.const("phase", arm))
        th1, rot1 = b.call("crank", "phi", "sense", offset, out=2)
        b.set_link(1, th1, rot1, _x(0, dr.pivot), _x(1, dr.pivot), b.call("scaled", "w_in", "sense"), 0.0,
                   b.call("scaled", "e_in", "sense"), 0.0)
        for n, g in enumerate(mech.structure.groups):
            getattr(b, _solver(g))(n, g)
        L, G = mech.n_links, len(mech.structure.groups)
        outputs = tuple(f"{s}{k}" for s in ("th", "rot", "O", "V", "A", "w", "e") for k in range(1, L)) + \
            tuple(f"{s}{p}" for s in ("vs", "as") for p in sorted(b.slides)) + tuple(f"cond{n}" for n in range(G)) + \
            tuple(f"{s}{n}" for n, g in enumerate(mech.structure.groups) if g.klass == 3 for s in ("it", "res"))
        return Program(tuple(b.steps), ("phi", "w_in", "e_in"), outputs)
    # keyed by the branches too: a Mechanism copied with other branches (dataclasses.replace) shares the memo
    return mech.memo(("motion_program", tuple(g.branch for g in mech.structure.groups)), make)


class _Statics(_Build):
    # its temporaries are s_<n>, the motion's t_<n>: a compiled kernel runs both in one scope
    """The kinetostatics program: known wrench of link k (force, moment about its origin) in
    F<k>, M<k>, updated as groups are solved; the reaction of pair p (force of p.links[0] on
    p.links[1]) in R<p>, its normal force and moment about the slider point in N<p>, m<p>."""

    def __init__(self, mech: "Mechanism"):
        super().__init__(mech)
        self._consts = set()
        self.prismatic_pairs: set[int] = set()

    def tmp(self, stem: str = "s") -> str:
        return super().tmp(stem)

    def at(self, k: int, name: str):
        return self.call("place", f"O{k}", f"rot{k}", _x(k, name)) if k else _x(0, name)

    def moment(self, k: int, X) -> str:
        return self.call("moment_about", f"M{k}", f"O{k}", f"F{k}", X)

    def carry(self, k: int, R, X, m=0.0) -> None:
        if k:
            self.steps.append(Step("carry", (f"F{k}", f"M{k}", f"O{k}", R, X, m), (f"F{k}", f"M{k}")))

    def normal(self, p: "Pair") -> str:
        """World unit normal n = i d of P pair p's guide."""
        return self.call("times", self.const("times", f"d{p.index}", 1j), f"rot{p.links[0]}") if p.links[0] \
            else self.const("times", f"d{p.index}", 1j)

    def revolute(self, p: "Pair", giver: int, R) -> None:
        self.steps.append(Step("revolute_pair", (R, 1.0 if giver == p.links[0] else -1.0), (f"R{p.index}",)))

    def prismatic(self, p: "Pair", giver: int, N, n, m, X0) -> str:
        self.prismatic_pairs.add(p.index)
        f = self.tmp()
        self.steps.append(Step("prismatic_pair", (N, n, m, X0, self.at(p.links[1], p.point),
                                                  1.0 if giver == p.links[0] else -1.0),
                               (f, f"R{p.index}", f"N{p.index}", f"m{p.index}")))
        return f

    def rrr(self, g: "AssurGroup") -> None:
        (pj, pin, pk), (j, k), (a, c) = g.pairs, g.links, g.known
        P, B, Q = self.at(j, pj.point), self.at(j, pin.point), self.at(k, pk.point)
        lj, lk = self.length(j, pin.point, pj.point), self.length(k, pin.point, pk.point)
        R_aj, R_jk, R_ck = self.call("rrr_polygon", P, B, Q, lj, lk, f"F{j}", f"F{k}",
                                     self.moment(j, B), self.moment(k, B), out=3)
        self.revolute(pj, a, R_aj)
        self.revolute(pin, j, R_jk)
        self.revolute(pk, c, R_ck)
        self.carry(a, R_aj, P)
        self.carry(c, R_ck, Q)

    def rrp(self, g: "AssurGroup") -> None:
        (pj, pin, pk), (j, k), (a, b) = g.pairs, g.links, g.known
        P, B = self.at(j, pj.point), self.at(j, pin.point)
        n = self.normal(pk)
        R_aj, R_jk, N, m_bk = self.call("rrp_polygon", P, B, self.length(j, pin.point, pj.point), n,
                                        f"F{j}", f"F{k}", self.moment(j, B), self.moment(k, B), out=4)
        self.revolute(pj, a, R_aj)
        self.revolute(pin, j, R_jk)
        f_bk = self.prismatic(pk, b, N, n, m_bk, B)
        self.carry(a, R_aj, P)
        self.carry(b, f_bk, B, m_bk)

    def rpr(self, g: "AssurGroup") -> None:
        (pj, pin, pk), (j, k), (a, c) = g.pairs, g.links, g.known   # j slides on k's guide
        P, Q, n = self.at(j, pj.point), self.at(k, pk.point), self.normal(pin)
        mP = self.moment(j, P)
        N = self.call("rpr_polygon", P, Q, n, mP, self.moment(k, Q))
        f_kj = self.prismatic(pin, k, N, n, self.call("scaled", mP, -1.0), P)
        R_aj = self.call("sub", self.call("scaled", f"F{j}", -1.0), f_kj)
        R_ck = self.call("sub", f_kj, f"F{k}")
        self.revolute(pj, a, R_aj)
        self.revolute(pk, c, R_ck)
        self.carry(a, R_aj, P)
        self.carry(c, R_ck, Q)

    def prp(self, g: "AssurGroup") -> None:
        (pj, pin, pk), (j, k), (a, c) = g.pairs, g.links, g.known
        B, na, nc = self.at(j, pin.point), self.normal(pj), self.normal(pk)
        Na, Nc = self.call("prp_polygon", na, nc, f"F{j}", f"F{k}", out=2)
        m_aj = self.call("scaled", self.moment(j, B), -1.0)
        m_ck = self.call("scaled", self.moment(k, B), -1.0)
        f_aj = self.prismatic(pj, a, Na, na, m_aj, B)
        self.revolute(pin, j, self.call("add", f"F{j}", f_aj))
        f_ck = self.prismatic(pk, c, Nc, nc, m_ck, B)
        self.carry(a, f_aj, B, m_aj)
        self.carry(c, f_ck, B, m_ck)

    def iii3(self, g: "Triad") -> None:
        """III3 in the texts' order: R^tau of each leash (a two-pin leash's from its moment about
        its inner pin; on an inner prismatic pair, from its force balance along the guide); R^n
        of the leash whose axis is off S from the group's moment about S; R^n of the two whose
        axes meet in S from the group's force polygon; the inner reactions from each leash's polygon (S: `triad.special_point`), a
        prismatic pair's acting where the leash's moment about its outer pin puts it."""
        b = g.links[0]
        X, u, T, P, m = [], [], [], [], []
        for i in range(3):
            po, pi, ell = g.pairs[2 * i], g.pairs[2 * i + 1], g.links[1 + i]
            if pi.kind == "P":                 # the axis: the guide's normal through the outer pin
                X.append(self.at(ell, po.point))
                P.append(X[i])
                u.append(self.normal(pi))
                T.append(self.call("line_tangential", u[i], f"F{ell}"))
                m.append(0.0)
                continue
            X.append(self.at(b, pi.point))
            if po.kind == "R":
                P.append(self.at(ell, po.point))
                length = self.length(ell, pi.point, po.point)
                u.append(self.call("leash_rr", X[i], P[i], length, out=2)[0])
                T.append(self.call("rr_tangential", u[i], self.moment(ell, X[i]), length))
                m.append(0.0)
            else:
                P.append(X[i])
                u.append(self.normal(po))
                T.append(0j)
                m.append(self.call("scaled", self.moment(ell, X[i]), -1.0))
        S, det, k = self.call("special_point", X[0], u[0], X[1], u[1], X[2], u[2], out=3)
        F, MS = f"F{b}", self.moment(b, S)
        for ell in g.links[1:]:
            F, MS = self.call("add", F, f"F{ell}"), self.call("add", MS, self.moment(ell, S))
        N = self.call("iii3_polygon", S, *X, *u, det, k, *T, *P, *m, F, MS, out=3)
        for i in range(3):
            po, pi, ell, a = g.pairs[2 * i], g.pairs[2 * i + 1], g.links[1 + i], g.known[i]
            if po.kind == "R":
                R = self.call("add", T[i], self.call("times", N[i], u[i]))
                self.revolute(po, a, R)
                self.carry(a, R, P[i])
            else:
                R = self.prismatic(po, a, N[i], u[i], m[i], X[i])
                self.carry(a, R, X[i], m[i])
            inner = self.call("add", f"F{ell}", R)         # the leash on the base
            if pi.kind == "R":
                self.revolute(pi, ell, inner)
            else:
                self.prismatic(pi, ell, self.call("dot", inner, u[i]), u[i], self.moment(ell, X[i]), X[i])

    def rpp(self, g: "AssurGroup") -> None:
        (pj, pin, pk), (j, k), (a, c) = g.pairs, g.links, g.known
        P, n_in, nc = self.at(j, pj.point), self.normal(pin), self.normal(pk)
        N1, Nc = self.call("rpp_polygon", n_in, nc, f"F{k}", out=2)
        mj = self.moment(j, P)
        m_ck = self.call("scaled", self.call("add", mj, self.moment(k, P)), -1.0)
        f_kj = self.prismatic(pin, k, N1, n_in, self.call("scaled", mj, -1.0), P)
        f_ck = self.prismatic(pk, c, Nc, nc, m_ck, P)
        R_aj = self.call("sub", self.call("scaled", f"F{j}", -1.0), f_kj)
        self.revolute(pj, a, R_aj)
        self.carry(a, R_aj, P)
        self.carry(c, f_ck, P, m_ck)


def statics_program(mech: "Mechanism") -> Program:
    """The kinetostatics of `mech` (memoised per mechanism): inputs the motion (rot<k>, O<k>)
    and the known wrenches F<k>, M<k> of every moving link (applied and inertia, about its local
    origin); outputs R<p> for every pair, N<p>, m<p> for the prismatic ones, M_bal and F_bal."""
    def make() -> Program:
        b = _Statics(mech)
        stages = []
        for g in reversed(mech.structure.groups):
            stages.append(len(b.steps))
            getattr(b, _solver(g))(g)
        stages.append(len(b.steps))
        dr = mech.drive
        b.steps.append(Step("scaled", (b.moment(1, b.at(1, dr.pivot)), -1.0), ("M_bal",)))
        if dr.kind == "machine":
            b.steps.append(Step("gear_force", ("M_bal", "gear_e", "gear_alpha", "gear_rb"), ("F_bal",)))
            b.revolute(mech.pair_between(0, 1), 0, b.call("scaled", b.call("add", "F1", "F_bal"), -1.0))
        else:
            b.steps.append(Step("same", (0j,), ("F_bal",)))
            b.revolute(mech.pair_between(0, 1), 0, b.call("scaled", "F1", -1.0))
        L = mech.n_links
        inputs = tuple(f"{s}{k}" for s in ("rot", "O", "F", "M") for k in range(1, L))
        outputs = tuple(f"R{p.index}" for p in mech.pairs) + \
            tuple(f"{s}{p}" for s in ("N", "m") for p in sorted(b.prismatic_pairs)) + ("M_bal", "F_bal")
        return Program(tuple(b.steps), inputs, outputs, tuple(stages))
    return mech.memo("statics_program", make)


# ----------------------------------------------------------------------------- running
_BOUND: dict[int, types.SimpleNamespace] = {}


def bind(xp: Any) -> types.SimpleNamespace:
    """The group equations with `xp` as their array namespace (numpy, an array-api-compat
    namespace): every function of `groups` rebuilt over a copy of its globals in which `xp` is
    the given namespace, so that they also call each other bound (memoised per namespace). The
    five primitives (`groups.magnitude` ...) stay the operators they are in `groups`: results
    are numpy's. (The compiled path, `kinetostat.fast`, compiles groups' source with its own.)"""
    key = id(xp)
    if key not in _BOUND:
        names = {**{n: groups for n in groups.__all__}, **{n: triad for n in triad.EQUATIONS}}
        if xp is np:
            _BOUND[key] = types.SimpleNamespace(**{n: getattr(m, n) for n, m in names.items()})
        else:
            env = dict(vars(groups), xp=xp)
            for n, m in names.items():
                f = getattr(m, n)
                env[n] = types.FunctionType(f.__code__, env, n, f.__defaults__, f.__closure__)
            _BOUND[key] = types.SimpleNamespace(**{n: env[n] for n in names})
    return _BOUND[key]


def code(program: Program, var: Callable[[str], str], check: Callable[[int, str, str], str]) -> list[str]:
    """The program as straight-line Python statements: each step one call of a group equation
    (by its name in `groups`), names turned into identifiers by `var`, literals written out;
    the assembly test written by `check(step index, discriminant, scale)`. A step that only
    names a value (`same`, or a product with 1) costs nothing: later steps read the value.
    Work linear in the number of steps: each alias is written out at most once, found through
    the name it stands for."""
    alias: dict[str, str] = {}                     # name -> the name whose value it reads
    readers: dict[str, dict[str, None]] = {}       # that name -> its aliases, in order given

    def name(a) -> str:
        return var(alias.get(a, a)) if isinstance(a, str) else repr(a)

    def forget(a: str) -> None:
        readers[alias.pop(a)].pop(a)

    lines = []
    for i, st in enumerate(program.steps):
        if st.fn == "check":
            lines.append(check(i, *map(name, st.args)))
        elif isinstance(st.args[0], str) and (st.fn == "same" or (
                st.fn in ("scaled", "revolute_pair") and st.args[1] == 1.0)):
            t = alias.get(st.args[0], st.args[0])
            if st.out[0] in alias:
                forget(st.out[0])
            alias[st.out[0]] = t
            readers.setdefault(t, {})[st.out[0]] = None
        else:
            for t in st.out:                        # a name read later keeps the value it was given
                for a in readers.pop(t, ()):
                    lines.append(f"{var(a)} = {var(t)}")
                    del alias[a]
            lines.append(f"{', '.join(var(o) for o in st.out)} = {st.fn}({', '.join(map(name, st.args))})")
            for o in st.out:
                if o in alias:
                    forget(o)
    lines.extend(f"{var(a)} = {name(a)}" for a in alias)      # every name given stays readable
    return lines


def free_names(program: Program) -> list[str]:
    """The names a program reads before it writes them (its constants and inputs), in order."""
    written: set[str] = set()
    free: dict[str, None] = {}
    for st in program.steps:
        for a in st.args:
            if isinstance(a, str) and a not in written:
                free[a] = None
        written.update(st.out)
    return list(free)


class Identifiers(dict):
    """Environment name -> a Python identifier v<n> (point names need not be identifiers)."""

    def __missing__(self, name: str) -> str:
        self[name] = f"v{len(self)}"
        return self[name]


def compiled(program: Program, xp: Any = np) -> Callable[[Mapping[str, Any]], dict[str, Any]]:
    """The program as one Python function env -> outputs over arrays of `xp` (memoised per
    program and namespace): the steps as straight-line code, no interpretation per step."""
    key = (id(program), id(xp))
    if key not in _COMPILED:
        ids = Identifiers()
        body = [f"{ids[n]} = env[{n!r}]" for n in free_names(program)]
        body += code(program, ids.__getitem__,
                     lambda i, d, s: f"if _any({d} < -{REACH_TOL!r} * {s}): _fail({i}, {d}, {s}, env)")
        body.append("return {" + ", ".join(f"{o!r}: {ids[o]}" for o in program.outputs) + "}")
        src = "def _run(env):\n    " + "\n    ".join(body) + "\n"
        scope = dict(vars(bind(xp)), _any=lambda b: bool(xp.any(b)), _fail=lambda i, d, s, env: _assembly_error(
            program.steps[i], d, s, env))
        exec(compile(src, f"<program {len(program.steps)} steps>", "exec"), scope)
        _COMPILED[key] = (program, scope["_run"])        # the program kept alive with its key
    return _COMPILED[key][1]


_COMPILED: dict[tuple[int, int], tuple[Program, Callable]] = {}


def _assembly_error(st: Step, disc, scale, env: Mapping[str, Any]) -> AssemblyError:
    """AssemblyError naming the crank angles where the group of step `st` cannot be assembled."""
    bad = np.asarray(disc < -REACH_TOL * scale)
    phi = np.broadcast_to(np.asarray(env["phi"]), bad.shape)
    raise AssemblyError(st.group, np.degrees(phi[bad]), st.why)


def run(program: Program, env: dict[str, Any], *, xp: Any = np) -> dict[str, Any]:
    """Run `program` over `env` (constants and inputs, arrays of `xp`); `env` updated with the
    program's outputs and returned. Raises AssemblyError naming the crank angles (env["phi"],
    rad) where a group cannot be assembled."""
    env.update(compiled(program, xp)(env))
    return env
