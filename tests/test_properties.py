"""Property-based tests: random valid mechanisms of every group kind, checked by identities that
hold to rounding for an exact solver, and a sample of them against two independent routes.

Strategies build model dicts (`kinetostat.from_dict`) of six families, one per group kind:

- ``RRR``  four-bar crank-rocker: Grashof with a margin, |b - c| < d - a and b + c > d + a;
- ``RRP``  crank-slider with an offset and inclined guide (rod > crank + |offset| with a margin);
           the slider's guide point may be off the pin's line (point K of the slider);
- ``RPR``  slotted link, rotating (pivot distance < crank) or swinging (pivot distance > crank),
           with a slot offset smaller than the block's least distance from the pivot;
- ``PRP``  shaper: a swinging slotted link (RPR) carrying a second slot in which a block slides,
           pinned to a ram in a frame guide (the PRP group never meets a parallel guide);
- ``RPP``  Scotch yoke with the slot at 30..150 deg to the yoke's guide;
- ``RRR+RRP`` six-bar: a four-bar whose rocker drives a slider through a rod.

Every link's local frame is a random rigid placement (sliders: a random shift, x along the
guide), revolute pairs list their links in random order (R is the force of links[0] on
links[1]), masses log-uniform, some links massless, centres of mass anywhere near the link,
constant forces in random directions at random points (some against the velocity), moments,
a spring, random g, speed, crank acceleration, sense, reference direction, and engine or
machine drive. A drawn mechanism is kept only if the solver assembles it over a whole cycle
without a SingularPositionWarning (`hypothesis.assume`).

Number of examples per property and kind: `QUICK` by default, `EXAMPLES` with -m slow (hypothesis
runs exactly that many valid examples unless it finds a failure); `RAN` counts them in a session.
"""
from __future__ import annotations

import math
import warnings
from collections import Counter

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

import kinetostat
from conftest import EVERY_GROUP, MODELS, four_bar, kinetic_energy, sampled
from kinetostat import AssemblyError, SingularPositionWarning
from kinetostat.model import FASTEST_PIN
from kinetostat.planar import cross, rotate

KINDS = ["RRR", "RRP", "RPR", "PRP", "RPP", "RRR+RRP"]

#: The drawn models are plausible (metres, g near 9.81, RRR groups listed j < k, slider frames
#: confirmed): a ModelWarning is a fault of the strategies.
pytestmark = pytest.mark.filterwarnings("error::kinetostat.ModelWarning")

#: Valid examples per property and per kind (6 kinds) with -m slow: 6 x (150 + 150 + 50 + 15 + 4) =
#: 2214 checks on 6 x (150 + 50 + 15 + 4) = 1314 drawn mechanisms (equilibrium and lever share
#: theirs). The 40-digit reference is slow (~0.15 s a mechanism): few random ones, plus the
#: hand-made hard cases of HARD (near a toggle, extreme ratios) and every bundled model.
EXAMPLES = {"equilibrium": 150, "lever": 150, "power": 50, "pinocchio": 15, "mpmath": 4}
#: The sample of the default suite: 6 x (20 + 20 + 8 + 3 + 1) checks on 6 x 32 mechanisms.
QUICK = {"equilibrium": 20, "lever": 20, "power": 8, "pinocchio": 3, "mpmath": 1}
SIZES = {"quick": QUICK, "full": EXAMPLES}
SIZE = pytest.mark.parametrize("size", ["quick", pytest.param("full", marks=pytest.mark.slow)])
#: Identities that hold to rounding, relative to the cycle's peak force / moment.
ROUNDING = 1e-9
#: Power balance with dT/dphi by 9-point central differences at h = 5e-4 rad: truncation
#: ~h^8 T^(9), rounding ~1e-16 T / h ~ 1e-12 (a 5-point stencil at 1e-3 rad left 1e-8 of
#: truncation on a shaper whose PRP group has cond ~ 50).
POWER = 1e-8
STENCIL = {1: 4 / 5, 2: -1 / 5, 3: 4 / 105, 4: -1 / 280}
#: Pinocchio's constrained inverse dynamics at the solver's exact state (rounding only).
PINOCCHIO = 1e-9
#: The mpmath reference (40 digits) of validation/reference.py.
MPMATH = 1e-10

RAN: Counter = Counter()

_SETTINGS = dict(deadline=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much])


# ----------------------------------------------------------------------------- drawing helpers

def _u(draw, lo, hi):
    return draw(st.floats(lo, hi, allow_nan=False, allow_infinity=False))


def _log(draw, lo, hi):
    return 10.0 ** _u(draw, math.log10(lo), math.log10(hi))


def _dir(angle):
    return [math.cos(angle), math.sin(angle)]


def _rigid(draw, pts: dict, scale: float, turn: bool = True) -> dict:
    """A random rigid placement of a link's local frame (turn=False: shift only, for sliders)."""
    g = _u(draw, -math.pi, math.pi) if turn else 0.0
    t = np.array([_u(draw, -1, 1), _u(draw, -1, 1)]) * scale
    c, s = math.cos(g), math.sin(g)
    R = np.array([[c, -s], [s, c]])
    return {k: list(map(float, R @ np.asarray(v, float) + t)) for k, v in pts.items()}, (R if turn else np.eye(2))


class _Builder:
    """Collects the tables of one model dict."""

    def __init__(self, draw, scale: float):
        self.draw, self.s = draw, scale
        self.frame: dict = {}
        self.links: dict[int, dict] = {}
        self.pairs: list[dict] = []
        self.groups: list[dict] = []
        self.extra: dict[int, list[str]] = {}

    def link(self, lid: int, pts: dict, length: float, *, slider: bool = False, dirs: dict | None = None):
        """Add link `lid` from canonical points; extra points (centre of mass, load points) are
        drawn near the segment [0, length] of the canonical x axis. Returns the rotation used
        (to carry canonical directions into the local frame)."""
        draw = self.draw
        pts = dict(pts)
        for n in range(2):
            pts[f"F{lid}{n}"] = [_u(draw, -0.3, 1.3) * length, _u(draw, -0.4, 0.4) * length]
        pts[f"S{lid}"] = [_u(draw, -0.3, 1.3) * length, _u(draw, -0.3, 0.3) * length]
        local, R = _rigid(draw, pts, self.s, turn=not slider)
        massless = draw(st.integers(0, 6)) == 0
        mass = 0.0 if massless else _log(draw, 0.01, 20.0)
        table = {"id": lid, "points": local, "mass": mass,
                 "I_S": mass * (_u(draw, 0.0, 0.6) * length) ** 2 + (_log(draw, 1e-6, 1e-2) if massless and draw(st.booleans()) else 0.0)}
        if mass:
            table["com"] = f"S{lid}"
        self.links[lid] = table
        self.extra[lid] = [f"F{lid}0", f"F{lid}1", f"S{lid}"]
        return R

    def R(self, i, j, point):
        ij = [i, j] if self.draw(st.booleans()) else [j, i]
        self.pairs.append({"kind": "R", "links": ij, "point": point})

    def P(self, guide, slider, guide_point, direction, point):
        self.pairs.append({"kind": "P", "links": [guide, slider], "guide": guide_point,
                           "direction": [float(x) for x in direction], "point": point,
                           "slider_axis": [1.0, 0.0]})     # confirmed: points in the guide's frame

    def group(self, j, k):
        self.groups.append({"links": sorted([j, k]), "branch": self.draw(st.sampled_from([1, -1]))})

    def model(self) -> dict:
        draw, s = self.draw, self.s
        n_links = len(self.links)
        loads = []
        for n in range(draw(st.integers(0, 3))):
            lid = draw(st.integers(1, n_links))
            against = draw(st.integers(0, 4)) == 0
            loads.append({"name": f"force {n}", "link": lid, "point": draw(st.sampled_from(self.extra[lid])),
                          "direction": "against_velocity" if against else _dir(_u(draw, -math.pi, math.pi)),
                          "value": _log(draw, 0.1, 1000.0) * (1 if against else draw(st.sampled_from([1, -1])))})
        for n in range(draw(st.integers(0, 2))):
            lid = draw(st.integers(1, n_links))
            loads.append({"name": f"moment {n}", "kind": "moment", "link": lid,
                          "value": _log(draw, 0.01, 100.0) * s * draw(st.sampled_from([1, -1]))})
        springs = []
        if draw(st.booleans()):
            lid = draw(st.integers(1, n_links))
            self.frame["E0"] = [_u(draw, -2, 2) * s, _u(draw, -2, 2) * s]
            springs.append({"name": "spring", "a": {"link": 0, "point": "E0"},
                            "b": {"link": lid, "point": draw(st.sampled_from(self.extra[lid]))},
                            "stiffness": _log(draw, 1.0, 1e4), "free_length": _u(draw, 0.0, 2.0) * s})
        arm = np.subtract(self.links[1]["points"]["A"], self.links[1]["points"]["O"])
        drive = {"link": 1, "pivot": "O", "point": "A",
                 "reference": [x * _log(draw, 0.5, 2.0) for x in _dir(_u(draw, -math.pi, math.pi))],
                 "sense": draw(st.sampled_from(["ccw", "cw"])),
                 "rpm": _log(draw, 1.0, min(3000.0, 0.9 * FASTEST_PIN / np.linalg.norm(arm) * 30 / math.pi))}
        w = drive["rpm"] * math.pi / 30
        drive["eps"] = _u(draw, -1.0, 1.0) * w**2 if draw(st.booleans()) else 0.0
        if draw(st.integers(0, 3)) == 0:
            drive["kind"] = "machine"
            corr = draw(st.sampled_from(["none", "equal", "unequal"]))
            drive["gear"] = {"module": _u(draw, 0.002, 0.01), "z_pinion": draw(st.integers(12, 20)),
                             "z_wheel": draw(st.integers(30, 80)), "correction": corr,
                             "alpha_w_deg": _u(draw, 18.0, 27.0),
                             "y": _u(draw, -0.5, 0.5) if corr == "unequal" else 0.0,
                             "centre_direction": _dir(_u(draw, -math.pi, math.pi))}
        assert np.linalg.norm(arm) > 0
        return {"mechanism": {"name": "hypothesis", "g": draw(st.sampled_from([0.0, 9.81, 10.0])) },
                "drive": drive, "frame": self.frame,
                "link": [self.links[k] for k in sorted(self.links)],
                "pair": self.pairs, "group": self.groups, "load": loads, "spring": springs}


def _crank(b: _Builder, r: float) -> None:
    b.frame["O"] = [0.0, 0.0]
    b.link(1, {"O": [0.0, 0.0], "A": [r, 0.0]}, r)
    b.R(0, 1, "O")


def _four_bar(draw, b: _Builder):
    """Crank a = s; frame d, coupler, rocker with a Grashof crank-rocker margin."""
    s = b.s
    a = s
    d = _u(draw, 1.6, 5.0) * s
    c = _u(draw, 1.4, 5.0) * s
    m = 0.25 * s
    lo = max(d + a - c, c - (d - a)) + m
    hi = c + (d - a) - m
    assume(hi > lo and hi > 1.3 * s)
    cb = _u(draw, max(lo, 1.3 * s), hi)
    beta = _u(draw, -math.pi, math.pi)
    b.frame["C"] = [d * math.cos(beta), d * math.sin(beta)]
    _crank(b, a)
    b.link(2, {"A": [0.0, 0.0], "B": [cb, 0.0]}, cb)
    b.link(3, {"C": [0.0, 0.0], "B": [c, 0.0]}, c)
    b.R(1, 2, "A")
    b.R(2, 3, "B")
    b.R(0, 3, "C")
    b.group(2, 3)
    return c


def _rrp(draw, b: _Builder, *, P: str = "A", known: int = 1, j: int = 2, k: int = 3,
         reach: float | None = None, centre=(0.0, 0.0)):
    """A rod j from point P of link `known` to slider k in a frame guide. The point P stays within
    `reach` of `centre`; the line of the slider's pin B passes at offset e from `centre`."""
    s = b.s
    reach = s if reach is None else reach
    e = _u(draw, -1.5, 1.5) * s
    l = reach + abs(e) + _u(draw, 0.3, 3.0) * s
    beta = _u(draw, -math.pi, math.pi)
    dvec, nvec = np.array(_dir(beta)), np.array(_dir(beta + math.pi / 2))
    with_k = draw(st.booleans())
    kx, ky = (_u(draw, -0.5, 0.5) * s, _u(draw, -0.5, 0.5) * s) if with_k else (0.0, 0.0)
    G = np.asarray(centre) + (e + ky) * nvec + _u(draw, -2, 2) * s * dvec
    b.frame[f"G{k}"] = [float(x) for x in G]
    pin = f"B{k}"
    b.link(j, {P: [0.0, 0.0], pin: [l, 0.0]}, l)
    pts = {pin: [0.0, 0.0]}
    if with_k:
        pts[f"K{k}"] = [kx, ky]
    b.link(k, pts, s, slider=True)
    b.R(known, j, P)
    b.R(j, k, pin)
    b.P(0, k, f"G{k}", dvec, f"K{k}" if with_k else pin)
    b.group(j, k)


def _slotted(draw, b: _Builder, swinging: bool):
    """Crank r = s; slotted link 3 about frame point C; block 2 on the crank pin in the slot."""
    s = b.s
    rho = _u(draw, 1.5, 4.0) if swinging else _u(draw, 0.1, 0.7)
    dist = rho * s
    beta = _u(draw, -math.pi, math.pi)
    C = np.array(_dir(beta)) * dist
    b.frame["C"] = [float(x) for x in C]
    e = _u(draw, -0.8, 0.8) * (abs(s - dist) - 0.1 * s)
    span = s + dist
    _crank(b, s)
    R3 = b.link(3, {"C": [0.0, 0.0], "K3": [_u(draw, -0.5, 1.0) * span, e]}, span)
    d_slot = R3 @ np.array([1.0, 0.0])
    b.link(2, {"A": [0.0, 0.0]}, 0.2 * s, slider=True)
    b.R(1, 2, "A")
    b.P(3, 2, "K3", d_slot, "A")
    b.R(0, 3, "C")
    b.group(2, 3)
    return C, dist, R3, span


def mechanism_dict(kind: str):
    @st.composite
    def build(draw):
        s = _log(draw, 0.02, 2.0)
        b = _Builder(draw, s)
        if kind == "RRR":
            _four_bar(draw, b)
        elif kind == "RRP":
            _crank(b, s)
            _rrp(draw, b)
        elif kind == "RPR":
            _slotted(draw, b, swinging=draw(st.booleans()))
        elif kind == "PRP":
            C, dist, R3, span = _slotted(draw, b, swinging=True)
            delta = _u(draw, -0.3, 0.3)
            K4 = [_u(draw, -0.5, 1.0) * span, _u(draw, -0.3, 0.3) * s]
            pts3 = b.links[3]["points"]
            # second slot of link 3: local point and direction (canonical frame turned by R3)
            t3 = np.asarray(pts3["C"], float)            # C is the canonical origin
            pts3["K4"] = [float(x) for x in R3 @ np.asarray(K4) + t3]
            d2_local = R3 @ np.array(_dir(delta))
            u_co = -C / dist                              # from C towards the crank centre
            mean_slot = math.atan2(u_co[1], u_co[0]) + delta
            psi = _u(draw, -math.pi / 6, math.pi / 6)
            d5 = np.array(_dir(mean_slot + math.pi / 2 + psi))
            h = _u(draw, 0.5, 2.0) * dist * draw(st.sampled_from([1, -1]))
            b.frame["D"] = [float(x) for x in C + h * u_co + _u(draw, -1, 1) * s * d5]
            b.link(4, {"B": [0.0, 0.0]}, 0.2 * s, slider=True)
            b.link(5, {"B": [0.0, 0.0]}, s, slider=True)
            b.P(3, 4, "K4", d2_local, "B")
            b.R(4, 5, "B")
            b.P(0, 5, "D", d5, "B")
        elif kind == "RPP":
            _crank(b, s)
            psi = _u(draw, math.radians(30), math.radians(150)) * draw(st.sampled_from([1, -1]))
            dc = np.array(_dir(_u(draw, -math.pi, math.pi)))
            b.frame["H"] = [_u(draw, -2, 2) * s, _u(draw, -2, 2) * s]
            b.link(2, {"A": [0.0, 0.0]}, 0.2 * s, slider=True)
            b.link(3, {"Y": [0.0, 0.0], "K3": [_u(draw, -1, 1) * s, _u(draw, -1, 1) * s]}, 2 * s, slider=True)
            b.R(1, 2, "A")
            b.P(3, 2, "K3", _dir(psi), "A")
            b.P(0, 3, "H", dc, "Y")
        else:   # RRR+RRP: the rocker's point E drives a slider through rod 4
            c = _four_bar(draw, b)
            pts3 = b.links[3]["points"]
            E_can = np.array([_u(draw, 0.2, 1.5) * c, _u(draw, -0.5, 0.5) * c])
            # canonical -> local of link 3: C is the canonical origin, B is at (c, 0)
            Cl, Bl = np.asarray(pts3["C"], float), np.asarray(pts3["B"], float)
            ex = (Bl - Cl) / c
            R3 = np.column_stack([ex, [-ex[1], ex[0]]])
            pts3["E"] = [float(x) for x in Cl + R3 @ E_can]
            _rrp(draw, b, P="E", known=3, j=4, k=5, reach=float(np.linalg.norm(E_can)),
                 centre=tuple(b.frame["C"]))
        return b.model()
    return build()


class Case(tuple):
    """(mech, res) of one drawn model; shows the model dict when hypothesis reports it."""

    def __new__(cls, data, mech, res):
        obj = super().__new__(cls, (mech, res))
        obj.data = data
        return obj

    def __repr__(self) -> str:
        return f"Case(kinetostat.from_dict({self.data!r}))"


def _assembled(data: dict, steps: int = 120):
    """The mechanism and its analysis over a cycle, or None if it does not assemble cleanly."""
    try:
        mech = kinetostat.from_dict(data)
    except kinetostat.ModelWarning as exc:
        # a drawn two-group chain may just pass the 20 m plausibility bound of a single linkage
        # (the warning "drawn in millimetres?"), or a link drawn under a millimetre keep its drawn
        # moment of inertia (the warning on a radius of gyration over 100 spans: "is it in kg m^2?"):
        # not mechanisms the strategies mean to draw
        if "the largest link spans" in str(exc) or "radius of gyration" in str(exc):
            return None
        raise
    except kinetostat.ModelError as exc:
        # the drawn extra points of a small slider may all fall on its pin, or within 1e-150 m of
        # it (hypothesis likes 0 and the tiniest floats): a degenerate link, refused as such
        if all("all points coincide" in p or "the link spans only" in p for p in exc.problems):
            return None
        raise
    with warnings.catch_warnings():
        warnings.simplefilter("error", SingularPositionWarning)
        try:
            res = kinetostat.analyze(mech, steps=steps)
        except (AssemblyError, SingularPositionWarning):
            return None
    for sp in mech.springs:
        # a spring through zero length has no direction there: kinetostat gives NaN silently
        # (reported, test_hostile.py::test_spring_through_zero_length); not drawn here
        A = res.kin.point(sp.a[0], mech.links[sp.a[0]].points[sp.a[1]])[0]
        B = res.kin.point(sp.b[0], mech.links[sp.b[0]].points[sp.b[1]])[0]
        if np.min(np.linalg.norm(B - A, axis=-1)) < 1e-3 * mech.size:
            return None
    return Case(data, mech, res)


def valid(kind: str):
    return mechanism_dict(kind).map(_assembled).filter(lambda x: x is not None)


# ----------------------------------------------------------------------------- independent checks

def residuals(res) -> tuple[np.ndarray, np.ndarray, float, float]:
    """Force (N, L-1, 2) and moment (N', L-1) residual of every moving link: applied + inertia +
    every pair's reaction + the drive, moments about each link's local origin; and the scales
    (peak reaction, peak reaction x reach of the points). Applied loads are recomputed here from
    the model. Left out: the angles where a prismatic pair's normal force is exactly zero (the
    Analysis then records no line of action, x = NaN, and a couple carried by the pair is lost:
    see test_prismatic_pure_couple_is_recorded), and those where a load against the velocity
    has no direction (`_dead_centre`)."""
    m, kin = res.mech, res.kin
    N, L = kin.theta.shape
    F = np.zeros((N, L, 2))
    M = np.zeros((N, L))

    def add(k, f, X, couple=0.0):
        if k:
            F[:, k] += f
            M[:, k] += cross(X - kin.origin[:, k], f) + couple

    def at(k, name):
        return kin.point(k, m.links[k].points[name])

    G = np.array([0.0, -m.g])
    lost, dead = np.zeros(N, bool), np.zeros(N, bool)
    for link in m.links[1:]:
        if link.mass:
            S, _, aS = at(link.id, link.com)
            add(link.id, link.mass * (G - aS), S)
        M[:, link.id] -= link.I_S * kin.eps[:, link.id]
    for ld in m.loads:
        k = ld.link
        if ld.kind == "moment":
            M[:, k] += ld.value
            continue
        X, V, _ = at(k, ld.point)
        if ld.direction == "against_velocity":
            sp = np.linalg.norm(V, axis=-1, keepdims=True)
            e = -V / np.where(sp > 0, sp, 1.0)
            dead |= _dead_centre(m, V)
        else:
            e = np.broadcast_to(np.asarray(ld.direction), (N, 2))
        add(k, ld.value * e, X)
    for sp in m.springs:
        A, B = at(*sp.a)[0], at(*sp.b)[0]
        ln = np.linalg.norm(B - A, axis=-1, keepdims=True)
        f = -sp.stiffness * (ln - sp.free_length) * (B - A) / ln
        add(sp.b[0], f, B)
        add(sp.a[0], -f, A)
    for p in m.pairs:
        R = res.forces.R[:, p.index]
        i, j = p.links
        if p.kind == "R":
            X = at(j, p.point)[0]
        else:
            d = rotate(np.asarray(p.direction), kin.theta[:, i])
            x = res.forces.x[:, p.index]
            lost |= np.isnan(x)          # N = 0 exactly: a couple in the pair is not recorded
            X = at(j, p.point)[0] + np.nan_to_num(x)[:, None] * d
        add(j, R, X)
        add(i, -R, X)
    dr = m.drive
    if dr.kind == "engine":
        M[:, 1] += res.balancing_moment
    else:
        O = at(1, dr.pivot)[0]
        add(1, res.balancing_force, O + dr.gear.r_w * np.asarray(dr.gear.centre_direction))
    peak = float(np.max(np.linalg.norm(res.forces.R, axis=-1)))
    reach = max(float(np.max(np.linalg.norm(at(k, n)[0] - kin.origin[:, k], axis=-1)))
                for k in range(1, L) for n in m.links[k].points)
    return F[~dead, 1:], M[~(dead | lost), 1:], peak, peak * reach


def _dead_centre(mech, V) -> np.ndarray:
    """Angles where a load `against_velocity` has (nearly) no direction: its point's speed is
    below 1e-6 of size x omega (kinetostat drops the force below 1e-9 of that; in between, and
    at the threshold itself, the two conventions would differ by the whole load)."""
    return np.linalg.norm(V, axis=-1) < 1e-6 * mech.size * mech.drive.omega


def dead_centres(res) -> np.ndarray:
    m = res.mech
    out = np.zeros(len(res.phi_deg), bool)
    for ld in m.loads:
        if ld.kind == "force" and ld.direction == "against_velocity":
            out |= _dead_centre(m, res.kin.point(ld.link, m.links[ld.link].points[ld.point])[1])
    return out


# ----------------------------------------------------------------------------- properties

def every_link_is_in_equilibrium(mech, res, kind, size) -> None:
    F, M, peak, mscale = residuals(res)
    F0, L0 = load_scale(res)
    assume(F0 > 0)                   # everything massless and unloaded: nothing to check
    peak, mscale = max(peak, 1e-6 * F0), max(mscale, 1e-6 * F0 * L0)
    assert np.isfinite(res.forces.R).all() and np.isfinite(res.balancing_moment).all()
    assert np.max(np.abs(F), initial=0.0) <= ROUNDING * peak, (np.max(np.abs(F)) / peak)
    assert np.max(np.abs(M), initial=0.0) <= ROUNDING * mscale, (np.max(np.abs(M)) / mscale)
    RAN["equilibrium", kind, size] += 1


def lever_equals_group_by_group(mech, res, kind, size) -> None:
    # peak |M_bal|; where M_bal is a cancellation of much larger powers (e.g. a mass on the
    # crank pin, whose inertia force passes through the pivot) rounding follows those
    power = np.sum(np.abs((res.F_applied + res.F_i) * res.kin.v_origin), axis=-1) \
        + np.abs((res.M_applied + res.M_i) * res.kin.omega)
    gross = np.max(power.sum(axis=1) / np.abs(res.omega(1)))
    F0, L0 = load_scale(res)
    peak = max(np.max(np.abs(res.balancing_moment)), 1e-6 * gross, 1e-6 * F0 * L0)
    assert np.max(np.abs(res.lever_discrepancy)) <= ROUNDING * peak
    if mech.drive.kind == "machine":
        # the pinion's force has the balancing moment about the crank pivot
        e = np.asarray(mech.drive.gear.centre_direction)
        np.testing.assert_allclose(cross(mech.drive.gear.r_w * e, res.balancing_force),
                                   res.balancing_moment, rtol=0, atol=ROUNDING * peak)
    RAN["lever", kind, size] += 1


@SIZE
@pytest.mark.parametrize("kind", KINDS)
def test_equilibrium_and_lever(kind, size):
    examples = SIZES[size]
    """Every link in equilibrium, and Zhukovsky's lever equal to the group-by-group balancing
    moment, on the same drawn mechanisms (drawing, not checking, is most of the time)."""
    @settings(max_examples=max(examples["equilibrium"], examples["lever"]), **_SETTINGS)
    @given(valid(kind))
    def check(mr):
        mech, res = mr
        lever_equals_group_by_group(mech, res, kind, size)
        every_link_is_in_equilibrium(mech, res, kind, size)    # its assume() comes last
    check()


@SIZE
@pytest.mark.parametrize("kind", KINDS)
def test_power_balance(kind, size):
    examples = SIZES[size]
    """M_bal omega_1 + power of the applied loads = dT/dt, T by 9-point differences along the
    cycle (dT/dt = dT/dphi omega + 2 T eps / omega for a crank accelerating at eps)."""
    @settings(max_examples=examples["power"], **_SETTINGS)
    @given(valid(kind), st.floats(0.0, 5.0))
    def check(mr, offset):
        mech, _ = mr
        phi = np.arange(0.0, 360.0, 7.5) + offset
        res = kinetostat.analyze(mech, phi_deg=phi)
        h = np.degrees(5e-4)
        T = {s: kinetic_energy(mech, phi + s * h) for s in range(-4, 5)}
        dT = np.degrees(sum(c * (T[s] - T[-s]) for s, c in STENCIL.items()) / h)   # per rad
        dr = mech.drive
        dT_dt = dT * dr.omega + 2 * T[0] * dr.eps / dr.omega
        P_loads = np.sum(res.F_applied * res.kin.v_origin, axis=-1) + res.M_applied * res.kin.omega
        P_drive = res.balancing_moment * res.omega(1)
        residual = P_drive + P_loads[:, 1:].sum(axis=1) - dT_dt
        # ... and T omega: the rate scale of the kinetic energy (T constant: dT/dt is 0 + noise)
        # ... and a rounding floor: T and its differences carry ~1e-16 of the kinetic energy the
        # masses would have at the speed of the largest coordinate (a centre of mass 1e-12 from
        # the pivot written as 1.000000000001 has an arm known to 1e-4 only)
        reach = max(np.max(np.abs(res.kin.origin[:, k])) + max(np.abs(p).max() for p in mech.links[k].points.values())
                    for k in range(1, mech.n_links))
        T_coord = sum(0.5 * (l.mass * reach**2 + l.I_S) * (2 * dr.omega) ** 2 for l in mech.links[1:])
        # ... and the power the reactions would carry at the crank's speed and the linkage's reach
        # (loads that do no work, e.g. a spring of constant length, leave every power at rounding)
        P_R = np.max(np.linalg.norm(res.forces.R, axis=-1)) * reach * dr.omega
        scale = max(np.max(np.abs(P_drive)), np.max(np.abs(dT_dt)), np.max(np.abs(P_loads)),
                    dr.omega * np.max(T[0]), 1e-4 * dr.omega * T_coord, P_R)
        assert np.max(np.abs(residual)) <= POWER * scale, np.max(np.abs(residual)) / scale
        RAN["power", kind, size] += 1
    check()


def load_scale(res) -> tuple[float, float]:
    """A force (N) and a length (m) scale of the loads the mechanism could carry: applied loads
    plus m (omega^2 + |eps|) size and g per link. Peak-relative errors are taken against at
    least 1e-6 of it: where every reaction vanishes (a mass at a fixed pivot, g = 0) the solver
    and an engine each return rounding noise (~1e-18 N) that no relative measure can compare."""
    m, size = res.mech, res.mech.size
    w2 = m.drive.omega**2 + abs(m.drive.eps)
    F = np.linalg.norm(res.F_applied[:, 1:], axis=-1).sum(axis=1) + np.abs(res.M_applied[:, 1:]).sum(axis=1) / size
    F = float(np.max(F)) + sum(l.mass * (w2 * size + m.g) + l.I_S * w2 / size for l in m.links[1:])
    return F, size


def _peak_errors(M_ref, R_ref, M, R, scale=(0.0, 0.0)):
    """Peak-relative errors: M_bal against its peak, every reaction against the peak reaction
    (peaks at least 1e-6 of `scale` = load_scale(res))."""
    ok = np.isfinite(M_ref) & np.isfinite(M)
    assert ok.any()
    F0, L0 = scale
    rel = lambda err, peak: err / peak if peak > 0 else err     # all zero (nothing loaded): absolute
    eM = rel(np.max(np.abs(M[ok] - M_ref[ok])), max(np.max(np.abs(M_ref[ok])), 1e-6 * F0 * L0))
    eR = rel(np.max(np.linalg.norm(R[ok] - R_ref[ok], axis=-1)),
             max(np.max(np.linalg.norm(R_ref[ok], axis=-1)), 1e-6 * F0))
    return eM, eR


@SIZE
@pytest.mark.parametrize("kind", KINDS)
def test_agrees_with_pinocchio(kind, size):
    examples = SIZES[size]
    try:
        from kinetostat_validation.engine_pinocchio import solve
        from kinetostat_validation.scene import build_scene
    except ImportError as exc:          # the adapter is not there (or pinocchio is not installed)
        pytest.skip(f"Pinocchio adapter not importable: {exc}")

    @settings(max_examples=examples["pinocchio"], **_SETTINGS)
    @given(valid(kind))
    def check(mr):
        mech, _ = mr
        scene = build_scene(mech, steps=36)
        er = solve(scene)
        eM, eR = _peak_errors(scene.res.balancing_moment, scene.res.forces.R, er.M_drive, er.R,
                              load_scale(scene.res))
        assert eM <= PINOCCHIO and eR <= PINOCCHIO, (eM, eR)
        RAN["pinocchio", kind, size] += 1
    check()


@SIZE
@pytest.mark.parametrize("kind", KINDS)
def test_agrees_with_mpmath_reference(kind, size):
    examples = SIZES[size]
    from kinetostat_validation.reference import reference

    @settings(max_examples=examples["mpmath"], **_SETTINGS)
    @given(valid(kind), st.floats(0.0, 30.0))
    def check(mr, offset):
        mech, _ = mr
        phi = np.arange(0.0, 360.0, 30.0) + offset
        res = kinetostat.analyze(mech, phi_deg=phi)
        M_ref, R_ref = reference(mech, phi, res=res)
        M_ref[dead_centres(res)] = np.nan        # the force against a zero velocity: convention
        assume(np.isfinite(M_ref).any())
        eM, eR = _peak_errors(M_ref, R_ref, res.balancing_moment, res.forces.R, load_scale(res))
        assert eM <= MPMATH and eR <= MPMATH, (eM, eR)
        RAN["mpmath", kind, size] += 1
    check()


def test_example_counts():
    """Every property that ran in this session ran its full number of valid examples."""
    for (prop, kind, size), n in RAN.items():
        assert n >= SIZES[size][prop], (prop, kind, size, n)


# A massless crank-slider (g = 0) whose slider carries a pure moment: the frame's guide must
# answer with a pure couple, normal force exactly 0.
PURE_COUPLE = """
[mechanism]
g = 0.0
[drive]
pivot = "O"
point = "A"
reference = [1.0, 0.0]
sense = "ccw"
rpm = 60.0
[frame]
O = [0.0, 0.0]
G = [0.0, 0.0]
[[link]]
id = 1
points = { O = [0.0, 0.0], A = [0.1, 0.0] }
[[link]]
id = 2
points = { A = [0.0, 0.0], B = [0.3, 0.0] }
[[link]]
id = 3
points = { B = [0.0, 0.0], K = [0.05, 0.0] }
[[pair]]
kind = "R"
links = [0, 1]
point = "O"
[[pair]]
kind = "R"
links = [1, 2]
point = "A"
[[pair]]
kind = "R"
links = [2, 3]
point = "B"
[[pair]]
kind = "P"
links = [0, 3]
guide = "G"
direction = [1.0, 0.0]
point = "B"
[[group]]
links = [2, 3]
branch = 1
[[load]]
name = "a couple on the slider"
kind = "moment"
link = 3
value = 5.0
"""


def test_prismatic_pure_couple_is_recorded():
    res = kinetostat.analyze(kinetostat.loads(PURE_COUPLE), phi_deg=[30.0, 120.0])
    assert np.all(res.forces.R == 0.0)              # nothing else is loaded: true
    m = res.mech
    p = m.pair_between(0, 3)
    # the slider's moment balance about B: applied 5 N m + the guide's couple = 0; the couple is
    # the reaction's moment about the slider point, its normal force is 0, so its line is nowhere
    np.testing.assert_allclose(res.forces.m[:, p.index], -5.0)
    assert np.isnan(res.forces.x[:, p.index]).all()


# PURE_COUPLE loaded: a crank 0.1 m, rod 0.1001 m (rod/crank 1.001: the rod stands almost square to
# the guide at phi = 90 deg, cond ~ 45), rod and slider with mass, g, a 300 N m moment.
LONG_CRANK = (PURE_COUPLE.replace("g = 0.0", "g = 9.81")
              .replace("B = [0.3, 0.0] }", 'B = [0.1001, 0.0], S2 = [0.04, 0.005] }\nmass = 2.0\nI_S = 0.01\ncom = "S2"')
              .replace("K = [0.05, 0.0] }", 'K = [0.05, 0.0] }\nmass = 5.0\ncom = "B"')
              .replace("value = 5.0", "value = -300.0"))


# Hard cases for the reference, which random drawing (kept away from singular positions) rarely meets.
# The four-bar (crank 0.1, frame 0.3) with coupler 0.25 and rocker 0.15 + 1e-5 m is 1e-5 m short
# of a stretched dyad at phi = 180 deg (|AC| = 0.4): cond ~ 155 there, reactions ~ 1/sin of the
# transmission angle. (Measured: the error grows as cond^2, ~1e-11 here, ~7e-11 at cond 490.)
NEAR_TOGGLE = four_bar(("A = [0.0, 0.0], B = [0.35, 0.0]", "A = [0.0, 0.0], B = [0.25, 0.0]"),
                       ("C = [0.0, 0.0], B = [0.3, 0.0]", "C = [0.0, 0.0], B = [0.15001, 0.0]"))
# Masses 1e-4 .. 1e4 kg, 30 000 rpm decelerating at 5000 rad/s^2, a 4 MN m load: inertia, gravity
# and loads of wildly different size in one sum.
EXTREME_RATIOS = four_bar(("mass = 0.8", "mass = 1e-4"), ("mass = 1.5", "mass = 1e4"), ("I_S = 0.016", "I_S = 100.0"),
                          ("rpm = 300.0", "rpm = 30000.0"), ("eps = 0.0", "eps = -5e3"), ("value = -4.0", "value = -4e6"))
#: text, critical angles (deg) added to the cycle, the least peak condition number they reach
HARD = {
    "four-bar 1e-5 m from toggle": (NEAR_TOGGLE, [179.0, 179.9, 180.0, 180.1, 181.0], 100.0),
    "four-bar masses 1e-4..1e4 kg at 30000 rpm": (EXTREME_RATIOS, [], 1.0),
    "crank-slider rod 1.001 x crank": (LONG_CRANK, [89.0, 90.0, 91.0, 269.5], 30.0),
}


@pytest.mark.parametrize("case", list(HARD))
def test_hard_cases_agree_with_mpmath_reference(case):
    """The cycle at 12 angles plus the case's critical angles, against the 40-digit reference."""
    from kinetostat_validation.reference import reference
    text, extra, cond = HARD[case]
    mech = kinetostat.loads(text)
    phi = np.concatenate([np.arange(0.0, 360.0, 30.0) + 7.0, extra])
    with warnings.catch_warnings():
        warnings.simplefilter("error", SingularPositionWarning)       # hard, yet regular
        res = kinetostat.analyze(mech, phi_deg=phi)
    assert np.max(res.cond) >= cond                                  # the case is as hard as said
    M_ref, R_ref = reference(mech, phi, res=res)
    eM, eR = _peak_errors(M_ref, R_ref, res.balancing_moment, res.forces.R, load_scale(res))
    assert eM <= MPMATH and eR <= MPMATH, (eM, eR)


@pytest.mark.parametrize("path", sampled(MODELS, EVERY_GROUP))
def test_bundled_models_agree_with_mpmath_reference(path):
    """The bundled models (engines and machines, all five group kinds and a triad by default;
    every one with -m slow) at 12 angles."""
    from kinetostat_validation.reference import reference
    mech = kinetostat.load(path)
    phi = np.arange(0.0, 360.0, 30.0) + 7.0
    res = kinetostat.analyze(mech, phi_deg=phi)
    M_ref, R_ref = reference(mech, phi, res=res)
    eM, eR = _peak_errors(M_ref, R_ref, res.balancing_moment, res.forces.R, load_scale(res))
    assert eM <= MPMATH and eR <= MPMATH, (eM, eR)
