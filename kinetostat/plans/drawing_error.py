"""The error of drawing (issue 12, item 4): how far a careful hand-drawn solution of the
graphical-analytic method lands from the exact one, by Monte Carlo over the constructions.

Every act of the drawing carries an error: a vector laid off at a scale has its length wrong by
up to ±`length_mm` and its direction by up to ±`angle_deg`; a line drawn in a known direction
(⟂ AB, ∥ the guide) has its direction wrong by up to ±`angle_deg`; a length or an arm read off
the sheet is wrong by up to ±`length_mm` (each error uniform in its interval, independent).
The constructions are those of Logvinenko, Nadtoka 2021 (sec. 1.2) and Kiriienko 2019 (secs. 6-8), all reduced to one
operation: a point found as the intersection of two lines through known points with known
directions (`_Drafter.meet`), evaluated for all samples at once (numpy arrays of shape (n,)).

What is drawn, in order: the velocity plan (pa, then per group the two lines whose
intersection is the inner joint's point, like points by similarity), the acceleration plan (the
normal components from the read angular velocities, the tangential lines, the intersection),
the inertia loads from the read accelerations, then per group from the last attached to the
first its plan (arms read for the moment equation of R^τ) and force polygon closed by two lines,
a reaction on a link of an earlier group read and laid off there as a load, the crank (the arms
of the reactions on it) and Zhukovsky's lever (the velocity plan again, arms of the turned loads
about the pole).

Kinematics and inertia loads: groups RRR, RRP with its guide on the frame, and RPR (anything
else raises NotImplementedError naming it). Force plans, crank and lever: mechanisms whose groups
are all RRR or RRP with its guide on the frame (Logvinenko and Nadtoka's ICE and opposed twin,
the compressor, the chain-unit four-bar, the furnace loader); for the others `simulate` draws the
kinematics and the inertia loads only.

May use: the solver's results (`analysis`, `applied`; analysed in `plans.solution`), `plans.worksheet`, numpy. Never matplotlib.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Mapping

import numpy as np

from ..analysis import Analysis
from ..model import Mechanism
from .scales import solution_scales
from .solution import Solution, solve

__all__ = ["Scales", "DrawnSolution", "default_scales", "draws_forces", "simulate", "SUPPORTED"]

#: What `simulate` draws completely (forces included).
SUPPORTED = "Assur groups RRR, and RRP with its guide on the frame, any number"


@dataclass(frozen=True)
class Scales:
    """The drawing scales: μ_l m/mm, μ_v m/(s mm), μ_a m/(s^2 mm), μ_F N/mm."""
    mu_l: float
    mu_v: float
    mu_a: float
    mu_F: float


def default_scales(mech: Mechanism, at: float | None = None) -> Scales:
    """The scales the plans are drawn at (`scales.choose_scales`: as Logvinenko, Nadtoka 2021 choose them)."""
    return _scales(mech, solve(mech, [mech.drive.design_deg if at is None else at], other=False))


def _scales(mech: Mechanism, solution: Solution) -> Scales:
    """The texts' scales of the plans of `solution.res` (one angle; drawn: frictionless)."""
    sc = solution_scales(mech, solution)
    return Scales(sc["mu_l"].value, sc["mu_v"].value, sc["mu_a"].value, sc["mu_F"].value)


@dataclass(frozen=True)
class DrawnSolution:
    """Samples of every value a drawn solution reads, keyed as the worksheet keys them
    (`V_BA`, `eps_2`, `R_1_2`, `M_bal`, ...), and the exact values."""
    mechanism: str
    phi_deg: float
    scales: Scales
    length_mm: float
    angle_deg: float
    forces_drawn: bool      # False: only the kinematics and the inertia loads (see `draws_forces`)
    samples: Mapping[str, np.ndarray]
    exact: Mapping[str, float]
    units: Mapping[str, str] = field(default_factory=dict)

    def __post_init__(self) -> None:
        for name in ("samples", "exact", "units"):
            object.__setattr__(self, name, MappingProxyType(dict(getattr(self, name))))

    def __repr__(self) -> str:
        n = len(next(iter(self.samples.values()))) if self.samples else 0
        return (f"DrawnSolution({self.mechanism!r}, phi_deg={self.phi_deg:g}, ±{self.length_mm:g} mm, "
                f"±{self.angle_deg:g} deg, samples={n}, values={len(self.samples)})")

    def spread(self, key: str) -> dict:
        """Exact value, mean, σ, the 2.5 and 97.5 % points of a drawn value's samples."""
        s = self.samples[key]
        lo, hi = np.percentile(s, [2.5, 97.5])
        return {"key": key, "exact": self.exact[key], "mean": float(s.mean()), "sd": float(s.std()),
                "p2_5": float(lo), "p97_5": float(hi), "unit": self.units.get(key, "")}

    def percentile_of(self, key: str, value: float) -> float:
        """Where `value` falls among the samples of `key`, % (0-100)."""
        s = self.samples[key]
        return float(100.0 * (np.sum(s < value) + 0.5 * np.sum(s == value)) / len(s))


class _Drafter:
    """The acts of drawing, each with its error, for n samples at once (complex numbers, mm)."""

    def __init__(self, n: int, length_mm: float, angle_deg: float, seed: int):
        self.n, self.dl, self.da = n, length_mm, math.radians(angle_deg)
        self.rng = np.random.default_rng(seed)

    def _err(self, bound: float) -> np.ndarray:
        return self.rng.uniform(-bound, bound, self.n) if bound else np.zeros(self.n)

    def turn(self, u) -> np.ndarray:
        """A direction drawn (parallel or perpendicular to something drawn): u turned by its error."""
        return u * np.exp(1j * self._err(self.da))

    def draw(self, v) -> np.ndarray:
        """A vector laid off at its scale (v in mm): length and direction each with its error."""
        v = np.asarray(v, complex)
        mag = np.abs(v)
        return np.where(mag > 0, (mag + self._err(self.dl)) * self.turn(_unit(v)), 0.0)

    def read(self, z) -> np.ndarray:
        """A length read off the sheet, mm: never below 0 (a length is no less than none)."""
        return np.maximum(np.abs(z) + self._err(self.dl), 0.0)

    def arm(self, r, u) -> np.ndarray:
        """Signed arm (mm) about a point of a line through r (mm from the point) along unit u
        (counter-clockwise positive for a force along u), read off the sheet."""
        return (r.real * u.imag - r.imag * u.real) + self._err(self.dl)

    def like(self, x, along) -> np.ndarray:
        """A like point found by similarity: its distance along `along` measured with error."""
        return x + self._err(self.dl) * _unit(along)

    @staticmethod
    def meet(P1, u1, P2, u2) -> np.ndarray:
        """Intersection of the line through P1 along u1 with the line through P2 along u2."""
        d = P2 - P1
        s = (d.real * u2.imag - d.imag * u2.real) / (u1.real * u2.imag - u1.imag * u2.real)
        return P1 + s * u1


def _z(v: np.ndarray) -> complex:
    return complex(v[0], v[1])


class _Plans:
    """The drawn plans of one position: for each link, a known plan point x of its world point X
    and the factor f of similarity (plan point of Z = x + f (Z - X))."""

    def __init__(self, res: Analysis, sc: Scales, dr: _Drafter):
        self.res, self.m, self.sc, self.dr = res, res.mech, sc, dr
        self.world = {name: _z(res.position(name)[0]) for name in self.m.point_names}
        self.out: dict[str, np.ndarray] = {}
        self.units: dict[str, str] = {}

    def put(self, key: str, value: np.ndarray, unit: str) -> None:
        self.out[key], self.units[key] = value, unit

    def at(self, reg, k: int, Z: complex) -> np.ndarray:
        X, x, f = reg[k]
        return x + f * (Z - X)

    def like(self, reg, k: int, name: str) -> np.ndarray:
        X, x, f = reg[k]
        return self.dr.like(x + f * (self.world[name] - X), f * (self.world[name] - X))

    # ---- velocity and acceleration plans
    def kinematics(self) -> None:
        res, m, sc, dr, W = self.res, self.m, self.sc, self.dr, self.world
        d = m.drive
        O, A = W[d.pivot], W[d.point]
        zero = np.zeros(dr.n, complex)
        a_v = dr.draw(_z(res.velocity(d.point)[0]) / sc.mu_v)
        a_a = dr.draw(_z(res.acceleration(d.point)[0]) / sc.mu_a)
        self.v = {0: (0j, zero, 0.0), d.link: (O, zero, a_v / (A - O))}
        self.a = {0: (0j, zero, 0.0), d.link: (O, zero, a_a / (A - O))}
        self.omega = {d.link: zero + res.omega(d.link)[0]}     # signed, as read off the plans
        self.eps = {d.link: zero + res.eps(d.link)[0]}
        self.pa = a_v
        for g in m.structure.groups:
            {"RRR": self._rrr, "RRP": self._rrp, "RPR": self._rpr}.get(g.kind if g.klass == 2 else "",
                                                                        self._unsupported)(g)
        for k in range(1, m.n_links):
            com = m.links[k].com
            if com and f"V_{com}" not in self.out:
                self.put(f"V_{com}", dr.read(self.like(self.v, k, com)) * sc.mu_v, "m/s")
            if com and f"a_{com}" not in self.out:
                self.put(f"a_{com}", dr.read(self.like(self.a, k, com)) * sc.mu_a, "m/s^2")
        for name in m.links[d.link].points:      # the crank's other points (C of a twin): by similarity
            if name not in (d.pivot, d.point) and f"V_{name}" not in self.out:
                self.put(f"V_{name}", dr.read(self.like(self.v, d.link, name)) * sc.mu_v, "m/s")
                self.put(f"a_{name}", dr.read(self.like(self.a, d.link, name)) * sc.mu_a, "m/s^2")

    @staticmethod
    def _unsupported(g) -> None:
        raise NotImplementedError(f"drawing error: group {g.label} of kind {g.kind} ({g.vid}) is not drawn "
                                  f"(kinematics: the dyads RRR, RRP with its guide on the frame, RPR)")

    def _link_plan(self, P: str, B: str, pP, b, scale: float, key: str, unit: str):
        """Link PB: the relative value (V_BP or a^τ_BP) read off the plan, and it over l_PB (ω or ε)."""
        rel = self.dr.read(b - pP) * scale
        self.put(f"{key}_{B}{P}", rel, unit)
        return rel / abs(self.world[B] - self.world[P])

    def _normal(self, reg, a: int, k: int, P: str, B: str):
        """n_k: the end of a^n_BP (link k, ω_k as read) laid off from the plan point of P (on link a);
        a^n_BP = ω_k² l_PB as computed from the read ω_k."""
        W = self.world
        self.put(f"an_{B}{P}", np.abs(self.omega[k]) ** 2 * abs(W[B] - W[P]), "m/s^2")
        return self.at(reg, a, W[P]) + self.dr.draw(-self.omega[k] ** 2 * (W[B] - W[P]) / self.sc.mu_a)

    def _rrr(self, g) -> None:
        (pj, pin, pk), (j, k), (a, c) = g.pairs, g.links, g.known
        P, B, Q = pj.point, pin.point, pk.point
        dr, sc, W, res = self.dr, self.sc, self.world, self.res
        pP, pQ = self.at(self.v, a, W[P]), self.at(self.v, c, W[Q])
        b = dr.meet(pP, dr.turn(1j * (W[B] - W[P])), pQ, dr.turn(1j * (W[B] - W[Q])))
        self.put(f"V_{B}", dr.read(b) * sc.mu_v, "m/s")
        for link, X, pX in ((j, P, pP), (k, Q, pQ)):
            w = np.sign(res.omega(link)[0]) * self._link_plan(X, B, pX, b, sc.mu_v, "V", "m/s")
            self.omega[link] = w
            self.put(f"omega_{link}", np.abs(w), "rad/s")
        nP, nQ = self._normal(self.a, a, j, P, B), self._normal(self.a, c, k, Q, B)
        ab = dr.meet(nP, dr.turn(1j * (W[B] - W[P])), nQ, dr.turn(1j * (W[B] - W[Q])))
        self.put(f"a_{B}", dr.read(ab) * sc.mu_a, "m/s^2")
        for link, X, nX in ((j, P, nP), (k, Q, nQ)):
            e = self._link_plan(X, B, nX, ab, sc.mu_a, "at", "m/s^2")
            self.put(f"eps_{link}", e, "rad/s^2")
            self.eps[link] = np.sign(res.eps(link)[0]) * e
        self.v[j] = (W[P], pP, (b - pP) / (W[B] - W[P]))
        self.v[k] = (W[Q], pQ, (b - pQ) / (W[B] - W[Q]))
        aP, aQ = self.at(self.a, a, W[P]), self.at(self.a, c, W[Q])
        self.a[j] = (W[P], aP, (ab - aP) / (W[B] - W[P]))
        self.a[k] = (W[Q], aQ, (ab - aQ) / (W[B] - W[Q]))

    def _rrp(self, g) -> None:
        (pj, pin, pk), (j, k), (a, b_) = g.pairs, g.links, g.known
        if b_ != 0:
            raise NotImplementedError(f"drawing error: group {g.label} RRP with its guide on moving link {b_} "
                                      f"is not drawn (only guides on the frame)")
        P, B = pj.point, pin.point
        dr, sc, W, res = self.dr, self.sc, self.world, self.res
        guide = complex(*pk.direction)
        pP = self.at(self.v, a, W[P])
        zero = np.zeros(dr.n, complex)
        b = dr.meet(pP, dr.turn(1j * (W[B] - W[P])), zero, dr.turn(guide))
        self.put(f"V_{B}", dr.read(b) * sc.mu_v, "m/s")
        self.put(f"V_rel({pk.links[0]},{pk.links[1]})", self.out[f"V_{B}"], "m/s")    # on a guide of the frame: V_B
        w = np.sign(res.omega(j)[0]) * self._link_plan(P, B, pP, b, sc.mu_v, "V", "m/s")
        self.omega[j] = w
        self.put(f"omega_{j}", np.abs(w), "rad/s")
        aP = self.at(self.a, a, W[P])
        nP = self._normal(self.a, a, j, P, B)
        ab = dr.meet(nP, dr.turn(1j * (W[B] - W[P])), zero, dr.turn(guide))
        self.put(f"a_{B}", dr.read(ab) * sc.mu_a, "m/s^2")
        self.put(f"ar_{pk.links[0]}_{pk.links[1]}", self.out[f"a_{B}"], "m/s^2")        # a^r = a_B likewise
        e = self._link_plan(P, B, nP, ab, sc.mu_a, "at", "m/s^2")
        self.put(f"eps_{j}", e, "rad/s^2")
        self.eps[j], self.eps[k] = np.sign(res.eps(j)[0]) * e, zero
        self.v[j] = (W[P], pP, (b - pP) / (W[B] - W[P]))
        self.a[j] = (W[P], aP, (ab - aP) / (W[B] - W[P]))
        self.v[k], self.a[k] = (W[B], b, 0.0), (W[B], ab, 0.0)
        self.omega[k] = zero

    def _rpr(self, g) -> None:
        (pj, pin, pk), (j, k), (a, c) = g.pairs, g.links, g.known
        P, Q = pj.point, pk.point
        dr, sc, W, res = self.dr, self.sc, self.world, self.res
        guide = _z(res.velocity(P)[0]) - _z(_velocity_of(res, k, W[P]))     # v_r d, world
        dvec = guide / abs(guide) if abs(guide) else complex(*res.kin.rot[0, k]) * complex(*pin.direction)
        pP, pQ = self.at(self.v, a, W[P]), self.at(self.v, c, W[Q])
        pk_ = dr.meet(pQ, dr.turn(1j * (W[P] - W[Q])), pP, dr.turn(dvec))
        l = abs(W[P] - W[Q])
        w = np.sign(res.omega(k)[0]) * dr.read(pk_ - pQ) * sc.mu_v / l
        vr = dr.read(pP - pk_) * sc.mu_v
        self.omega[j] = self.omega[k] = w
        self.put(f"omega_{k}", np.abs(w), "rad/s")
        self.put(f"V_rel({pin.links[0]},{pin.links[1]})", vr, "m/s")
        aP, aQ = self.at(self.a, a, W[P]), self.at(self.a, c, W[Q])
        nQ = aQ + dr.draw(-w ** 2 * (W[P] - W[Q]) / sc.mu_a)
        sign_vr = np.sign((guide * np.conj(dvec)).real) if abs(guide) else 1.0
        cor = dr.draw(2j * w * sign_vr * vr * dvec / sc.mu_a)
        ak = dr.meet(nQ, dr.turn(1j * (W[P] - W[Q])), aP - cor, dr.turn(dvec))
        e = dr.read(ak - nQ) * sc.mu_a / l
        self.put(f"eps_{k}", e, "rad/s^2")
        self.eps[j] = self.eps[k] = np.sign(res.eps(k)[0]) * e
        f_v, f_a = (pk_ - pQ) / (W[P] - W[Q]), (ak - aQ) / (W[P] - W[Q])
        self.v[k], self.a[k] = (W[Q], pQ, f_v), (W[Q], aQ, f_a)
        self.v[j], self.a[j] = (W[P], pP, f_v), (W[P], aP, f_a)
        self.put(f"ar_{pin.links[0]}_{pin.links[1]}", dr.read(aP - cor - ak) * sc.mu_a, "m/s^2")   # a^r: its side

    # ---- loads, group plan, force polygon, crank, lever
    def loads(self):
        """Per moving link: [(force N (n,) complex drawn direction, world point)], couple N m (n,)."""
        res, m, sc, dr, W = self.res, self.m, self.sc, self.dr, self.world
        forces, couples = {}, {}
        mass, I_S, _ = m.inertia_arrays
        for link in m.links[1:]:
            k = link.id
            S = W[link.com] if link.com else _z(res.kin.origin[0, k])
            fl = []
            G = -1j * m.g * mass[k]
            if G:
                fl.append((G * np.ones(dr.n), S))
            if mass[k]:
                aS = self.at(self.a, k, S) if not link.com else self.like(self.a, k, link.com)
                Fi = mass[k] * dr.read(aS) * sc.mu_a
                self.put(f"F_i{k}", Fi, "N")
                fl.append((-Fi * dr.turn(_unit(aS)), S))
            Mi = -I_S[k] * self.eps[k]
            if I_S[k]:
                self.put(f"M_i{k}", np.abs(Mi), "N m")
                il = res.inertia(k)
                if il.moment[0] and np.isfinite(il.h[0]):   # the arm of the shifted inertia force, computed
                    self.put(f"h_{k}", np.abs(Mi) / Fi, "m")
                    self.put(f"z_{k}", np.abs(Mi) / Fi / sc.mu_l, "mm")
            ext = _z(res.F_applied[0, k]) - G
            Mext = res.M_applied[0, k] - _cross(S - _z(res.kin.origin[0, k]), G)
            if abs(ext) > 1e-12 * max(1.0, abs(_z(res.F_applied[0, k]))):
                X = _z(res.kin.origin[0, k]) + (-Mext / abs(ext) ** 2) * 1j * ext
                fl.append((ext * np.ones(dr.n), X))
                Mext = 0.0
            forces[k], couples[k] = fl, Mi + Mext
        return forces, couples

    def group_forces(self, g, loads, couples) -> list[tuple[int, int, np.ndarray, complex]]:
        """Group g's plan and force polygon under `loads` (link -> [(force N (n,) complex, world
        point)]) and `couples` (link -> N m (n,)); the reactions it takes from its known links:
        [(known link, group link, R_known_link drawn (n,) complex mm, world point)]."""
        sc, dr, W = self.sc, self.dr, self.world
        (pj, pin, pk), (j, k), (a, c) = g.pairs, g.links, g.known
        B = W[pin.point]

        def tangential(link, X):           # Σ M_B = 0 of the link: R^τ along i (B - X)/|BX|
            l = abs(B - X)
            tot = couples[link] / sc.mu_l
            for F, Y in loads[link]:
                tot = tot + np.abs(F) * dr.arm((Y - B) / sc.mu_l, _unit(F))
            return tot / (l / sc.mu_l), 1j * (B - X) / l

        Rt_j, t_j = tangential(j, W[pj.point])
        self.put(f"Rt_{a}_{j}", np.abs(Rt_j), "N")
        pts = [np.zeros(dr.n, complex)]
        pts.append(pts[-1] + dr.draw(Rt_j * t_j / sc.mu_F))
        for F, _ in loads[j]:
            pts.append(pts[-1] + dr.draw(F / sc.mu_F))
        end_j = pts[-1]
        for F, _ in loads[k]:
            pts.append(pts[-1] + dr.draw(F / sc.mu_F))
        end_k = pts[-1]
        if g.kind == "RRR":
            Rt_k, t_k = tangential(k, W[pk.point])
            self.put(f"Rt_{c}_{k}", np.abs(Rt_k), "N")
            pts.append(pts[-1] + dr.draw(Rt_k * t_k / sc.mu_F))
            last = (W[pk.point] - B) / abs(W[pk.point] - B)
        else:
            last = 1j * complex(*pk.direction)
        K = dr.meet(pts[0], dr.turn((B - W[pj.point]) / abs(B - W[pj.point])), pts[-1], dr.turn(last))
        R_aj, R_ck = pts[1] - K, K - end_k
        self.put(f"R_{a}_{j}", dr.read(R_aj) * sc.mu_F, "N")
        self.put(f"R_{c}_{k}", dr.read(R_ck) * sc.mu_F, "N")
        self.put(f"R_{k}_{j}", dr.read(K - end_j) * sc.mu_F, "N")
        self.put(f"Rn_{a}_{j}", dr.read(pts[0] - K) * sc.mu_F, "N")        # the polygon's closing sides
        if g.kind == "RRR":
            self.put(f"Rn_{c}_{k}", dr.read(K - pts[-1]) * sc.mu_F, "N")
        elif all(abs(Y - B) <= 1e-9 * abs(B - W[pj.point]) for _, Y in loads[k]) and not np.any(couples[k]):
            # Σ M_B = 0 of the slider with every load through B: its frame reaction's offset x is 0,
            # with no arm to read (other sliders: not drawn here)
            self.put(f"x_{pk.links[0]}_{pk.links[1]}", np.zeros(dr.n), "m")
        return [(a, j, R_aj, W[pj.point]), (c, k, R_ck, W[pk.point])]

    def forces_of_groups(self, forces, couples) -> list[tuple[int, np.ndarray, complex]]:
        """The groups' plans from the last attached to the first (Kiriienko 2019, sec. 7): each
        reaction a group takes from a moving link other than the crank is read, carried over with
        its drawn direction and laid off as a load of that link in the earlier group. Returns the
        reactions on the crank: [(group link, R_crank_link drawn (n,) complex mm, world point)]."""
        d, dr, sc = self.m.drive, self.dr, self.sc
        carried: dict[int, list] = {}
        on_crank = []
        for g in reversed(self.m.structure.groups):
            loads = {k: forces[k] + carried.get(k, []) for k in g.links}
            for known, link, R, X in self.group_forces(g, loads, couples):
                if known == d.link:
                    on_crank.append((link, R, X))
                elif known != 0:
                    F = self.out[f"R_{known}_{link}"] * dr.turn(-_unit(R))
                    carried.setdefault(known, []).append((F, X))
        return on_crank

    def crank(self, on_crank, forces, couples) -> np.ndarray:
        m, sc, dr, W = self.m, self.sc, self.dr, self.world
        d = m.drive
        O = W[d.pivot]
        M = couples[d.link]
        polygon = []                               # the crank's force polygon, closed by R01
        for other, R, X in on_crank:               # R_{other, crank} = -R_{crank, other}: its arm about O
            u = dr.turn(-_unit(R))
            h = dr.arm((X - O) / sc.mu_l, u)
            self.put(f"h_R{other}{d.link}", np.abs(h), "mm")
            R_read = self.out[f"R_{d.link}_{other}"]
            self.put(f"R_{other}_{d.link}", R_read, "N")
            M = M + R_read * h * sc.mu_l
            polygon.append(R_read * u)
        for F, Y in forces[d.link]:
            M = M + np.abs(F) * dr.arm((Y - O) / sc.mu_l, _unit(F)) * sc.mu_l
            polygon.append(F)
        self.put("M_bal", -M, "N m")
        if d.kind == "machine":
            self.put("F_bal", np.abs(M) / (dr.read(d.gear.r_b / sc.mu_l) * sc.mu_l), "N")
            M_exact, F_exact = self.res.balancing_moment[0], _z(self.res.balancing_force[0])
            if M_exact:                            # F_bal on its line of action, in proportion to M_bal
                polygon.append(-M / M_exact * abs(F_exact) * dr.turn(F_exact / abs(F_exact)))
        end = np.zeros(dr.n, complex)
        for F in polygon:
            end = end + dr.draw(F / sc.mu_F)
        self.put(f"R_0_{d.link}", dr.read(end) * sc.mu_F, "N")
        return -M

    def lever(self, forces, couples) -> np.ndarray:
        m, dr, W, res = self.m, self.dr, self.world, self.res
        d = m.drive
        total = np.zeros(dr.n)
        for k in range(1, m.n_links):
            for F, Y in forces[k]:
                x = self.at(self.v, k, Y)
                x = dr.like(x, x - self.v[k][1])      # by similarity from the link's known plan point
                u = dr.turn(_unit(F))
                total = total + np.abs(F) * ((x * np.conj(u)).real + dr._err(dr.dl))
            if np.any(couples[k] != 0):
                X, x, f = self.v[k]
                # the couple's moment on the lever: M_k omega_k / mu_v, omega_k from a link of the plan
                ref = max((n for n in m.links[k].points), key=lambda n: abs(W[n] - X))
                l = abs(W[ref] - X)
                total = total + couples[k] * np.sign(res.omega(k)[0]) * dr.read(f * (W[ref] - X)) / l
        pa = dr.read(self.pa)
        l1 = abs(W[d.point] - W[d.pivot])
        M = -total * l1 / (np.sign(res.omega(d.link)[0]) * pa)
        self.put("F_bal_lever", np.abs(M) / l1, "N")
        self.put("M_bal_lever", M, "N m")
        return M


def _unit(z) -> np.ndarray:
    """z / |z|, and 0 where z is 0 (a load that vanishes has no direction to draw)."""
    mag = np.abs(z)
    return np.where(mag > 0, z / np.where(mag > 0, mag, 1.0), 0.0)


def _cross(a: complex, b: complex) -> float:
    return a.real * b.imag - a.imag * b.real


def _velocity_of(res: Analysis, k: int, X: complex) -> np.ndarray:
    """Velocity (2,) of the point of link k at world position X."""
    r = X - _z(res.kin.origin[0, k])
    w = res.omega(k)[0]
    return res.kin.v_origin[0, k] + w * np.array([-r.imag, r.real])


def draws_forces(mech: Mechanism) -> bool:
    """Whether `simulate` draws the force plans, the crank and the lever of `mech` (SUPPORTED)."""
    return all(g.klass == 2 and (g.kind == "RRR" or (g.kind == "RRP" and g.known[1] == 0))
               for g in mech.structure.groups)


def simulate(mech: Mechanism, at: float | None = None, *, n: int = 20000, length_mm: float = 0.25,
             angle_deg: float = 0.25, scales: Scales | None = None, seed: int = 0,
             res: Analysis | None = None) -> DrawnSolution:
    """`n` drawn solutions of `mech` at crank angle `at` (deg; default its design position),
    each act of drawing wrong by up to ±length_mm (lengths, arms, readings) and ±angle_deg
    (directions), at `scales` (default: the texts' choice). `res`: the caller's frictionless
    analysis of `mech` at the one angle `at` (`analyze(mech, phi_deg=[at])`; default: made here,
    once: `solution.solve`, and for the default scales of a given `res`). Reproducible for a given seed."""
    from .worksheet import worksheet_cycle
    if not (isinstance(n, (int, np.integer)) and n >= 1):
        raise ValueError(f"n: expected a positive number of samples, got {n!r}")
    for name, v in (("length_mm", length_mm), ("angle_deg", angle_deg)):
        if not (isinstance(v, (int, float)) and math.isfinite(v) and v >= 0):
            raise ValueError(f"{name}: expected a finite precision >= 0, got {v!r}")
    solution = None
    if res is None:
        solution = solve(mech, [mech.drive.design_deg if at is None else float(at)], other=False)
        res = solution.res
    elif len(res.phi_deg) != 1 or res.friction is not None or (at is not None and float(at) != res.phi_deg[0]):
        raise ValueError(f"res: expected the frictionless analysis of {mech.name!r} at the one angle "
                         f"{'at' if at is None else f'{float(at):g} deg'} (analyze(mech, phi_deg=[at])), got {res}")
    at = float(res.phi_deg[0])
    sc = scales or _scales(mech, solution or solve(mech, res.phi_deg, other=False))
    dr = _Drafter(int(n), float(length_mm), float(angle_deg), seed)
    pl = _Plans(res, sc, dr)
    pl.kinematics()
    forces, couples = pl.loads()
    drawn = draws_forces(mech)
    if drawn:
        M = pl.crank(pl.forces_of_groups(forces, couples), forces, couples)
        ML = pl.lever(forces, couples)
        pl.put("delta_pct", (ML - M) / ML * 100.0, "%")
    ws = worksheet_cycle(mech, res, sc.mu_l).at(0)
    exact = {}
    for key in pl.out:
        try:
            exact[key] = ws.value(key)
        except KeyError:
            continue
    samples = {k: v.real if np.iscomplexobj(v) else v for k, v in pl.out.items() if k in exact}
    return DrawnSolution(mech.name, at, sc, float(length_mm), float(angle_deg), drawn, samples, exact,
                         {k: pl.units[k] for k in samples})
