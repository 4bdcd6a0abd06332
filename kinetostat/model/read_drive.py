"""The reader's sections for the drive: the crank, its speed or law of motion, the gear mesh of
a working machine, the flywheel on its shaft.

May use: the standard library, numpy, core, limits, laws, parts, mechanism, schema.
"""
from __future__ import annotations

import math

import numpy as np

from .core import ReaderCore
from .laws import mentions_phi, pole
from .limits import MAX_SHOWN, MAX_VALUE, MIN_GEAR
from .mechanism import extent
from .parts import Drive, Flywheel, Gear, Link, Pair, SpeedLaw
from .schema import DRIVE, FLYWHEEL, GEAR, MODEL, OMEGA_TABLE


class DriveReading(ReaderCore):
    """The reader's sections for the drive: a part of `reader._Reader`."""

    def drive(self, links: list[Link], pairs: list[Pair]) -> Drive | None:
        t = self.read(MODEL, self.data, "drive", "")
        if t is None:
            return None
        w = "drive"
        self.unknown_keys(t, DRIVE.keys(kind="machine"), w)     # gear with another kind: its own message below
        self.read(DRIVE, t, "link", w)
        pivot, point = t.get("pivot"), t.get("point")
        if len(links) > 1:
            if self.point_ok(links, 1, pivot, "drive.pivot") & self.point_ok(links, 1, point, "drive.point") \
                    and links[1].points[pivot] == links[1].points[point]:
                self.err(f"drive.point: {point!r} coincides with the pivot {pivot!r} "
                         f"(zero crank length: the crank angle has no direction)")
            if not any(p.kind == "R" and set(p.links) == {0, 1} and p.point == pivot for p in pairs):
                self.err(f"drive.pivot: the crank needs a revolute pair with the frame at {pivot!r}")
        ref = self.read(DRIVE, t, "reference", w)
        sense = self.read(DRIVE, t, "sense", w)
        law = None
        if not self.one_of(DRIVE, t, w):
            omega = None
        elif "omega_table" in t:
            law = self.speed_table(self.read(DRIVE, t, "omega_table", w), "drive.omega_table")
        elif isinstance(t.get("omega"), str) and mentions_phi(t["omega"]):
            law = self.speed_expression(t["omega"], "drive.omega")
        elif "rpm" in t:
            rpm = self.read(DRIVE, t, "rpm", w)
            omega = None if rpm is None else rpm * math.pi / 30
        else:
            omega = self.read(DRIVE, t, "omega", w)
        if law is not None and "eps" in t:
            self.err("drive.eps: a law of motion gives eps = omega d omega / d phi itself; remove eps")
        eps = self.read(DRIVE, t, "eps", w)
        if "omega_table" in t or isinstance(t.get("omega"), str) and mentions_phi(t["omega"]):
            omega, eps = (None, None) if law is None else self.law_scales(law)
        design = self.read(DRIVE, t, "design_deg", w)
        kind = self.read(DRIVE, t, "kind", w)
        gear = None
        if kind == "machine":
            gear = self.gear(t, max((extent(k.points.values()) for k in links[1:]), default=0.0))
        elif "gear" in t:
            self.err("drive.gear: only a working machine (drive.kind = 'machine') has a gear mesh")
        if None in (ref, sense, omega, eps, design) or (kind == "machine" and gear is None):
            return None
        return Drive(1, pivot, point, ref, 1 if sense == "ccw" else -1, omega, eps, kind, gear, design, law,
                     self.source)

    def flywheel(self) -> Flywheel | None:
        """[flywheel]: J (kg m^2) or delta, exactly one (None: absent, or reported)."""
        t = self.read(MODEL, self.data, "flywheel", "")
        if t is None:
            return None
        self.unknown_keys(t, FLYWHEEL.keys(), "flywheel")
        if not self.one_of(FLYWHEEL, t, "flywheel"):
            return None
        J, delta = self.read(FLYWHEEL, t, "J", "flywheel"), self.read(FLYWHEEL, t, "delta", "flywheel")
        return None if J is None and delta is None else Flywheel(J, delta)

    def speed_table(self, t: dict | None, where: str) -> SpeedLaw | None:
        """[drive.omega_table] (None: reported): phi_deg and omega (rad/s) or rpm over one revolution."""
        if t is None:
            return None
        self.unknown_keys(t, OMEGA_TABLE.keys(), where)
        if not self.one_of(OMEGA_TABLE, t, where):
            return None
        xs = self.read(OMEGA_TABLE, t, "phi_deg", where)
        key = "omega" if "omega" in t else "rpm"
        vs = self.read(OMEGA_TABLE, t, key, where)
        if xs is None or vs is None:
            return None
        n = len(self.problems)
        if len(vs) != len(xs):
            self.err(f"{where}.{key}: {len(vs)} values for {len(xs)} angles")
        if len(xs) < 3:
            self.err(f"{where}.phi_deg: a periodic spline needs at least 3 angles, got {len(xs)}")
        if not xs[-1] - xs[0] <= 360:
            self.err(f"{where}.phi_deg: the angles must lie within one revolution (last - first <= 360)")
        elif xs[-1] - xs[0] == 360 and len(vs) == len(xs) and vs[0] != vs[-1]:
            self.err(f"{where}.{key}: the law is periodic, but its values at {xs[0]:g} and {xs[-1]:g} deg "
                     f"({vs[0]:g}, {vs[-1]:g}) differ")
        if len(self.problems) > n:
            return None
        scale = 1.0 if key == "omega" else math.pi / 30
        return SpeedLaw(xs, tuple(v * scale for v in vs))

    def speed_expression(self, text: str, where: str) -> SpeedLaw | None:
        """drive.omega as an expression of phi (rad), periodic over a revolution."""
        law = SpeedLaw(expression=text, parameters=tuple(self.values.items()))
        try:
            law(np.zeros(1))
        except ValueError as exc:
            self.err(f'{where}: "{text:.{MAX_SHOWN}}": {exc}')
            return None
        return law

    def law_scales(self, law: SpeedLaw) -> tuple[float | None, float | None]:
        """The largest omega and |eps| of `law` over a revolution, after checking that omega is
        finite, >= 0 and periodic; (None, None) after recording a problem."""
        where = "drive.omega_table" if law.expression is None else "drive.omega"
        phi = np.linspace(0.0, 2 * np.pi, 721)
        w, dw = law(phi)
        if not (np.isfinite(w).all() and np.isfinite(dw).all()):
            at = np.degrees(phi[~(np.isfinite(w) & np.isfinite(dw))])
            self.err(f"{where}: omega(phi) is not finite (or not real) over the whole revolution: so at phi = "
                     f"{at[0]:.4g} deg" + (f" ({len(at)} of 721 angles checked, up to {at[-1]:.4g} deg)"
                                           if len(at) > 1 else ""))
        elif law.expression is not None and (p := pole(law, phi, w, dw)) is not None:
            a, b, at, value = p
            self.err(f"{where}: omega(phi) " + (
                f"is not finite (or not real) at phi = {at:.8g} deg, between the angles checked {a:.4g} and "
                f"{b:.4g} deg" if math.isnan(value) else
                f"has a pole between phi = {a:.4g} and {b:.4g} deg (checked every 0.5 deg): it reaches "
                f"{value:.4g} rad/s at phi = {at:.8g} deg, against at most {np.abs(w).max():.4g} rad/s at "
                f"the angles checked"))
        elif (w < 0).any():
            self.err(f"{where}: omega(phi) must be >= 0 (in the drive's sense); it is "
                     f"{w.min():.4g} rad/s at phi = {np.degrees(phi[np.argmin(w)]):.4g} deg")
        elif np.abs(w.max()) > MAX_VALUE:
            self.err(f"{where}: omega(phi) reaches {w.max():.4g} rad/s (at most {MAX_VALUE:g})")
        elif law.expression is not None and not (
                abs(w[-1] - w[0]) <= 1e-9 * max(abs(w).max(), 1.0) and abs(dw[-1] - dw[0]) <= 1e-9 * max(abs(dw).max(), 1.0)):
            self.err(f"{where}: omega(phi) must be periodic over a revolution (value and slope at 0 and 2 pi): "
                     f"omega = {w[0]:.6g}, {w[-1]:.6g}; d omega/d phi = {dw[0]:.6g}, {dw[-1]:.6g}")
        else:
            return float(w.max()), float(np.abs(w * dw).max())
        return None, None

    def gear(self, drive: dict, size: float) -> Gear | None:
        """[drive.gear] of the table [drive]; `size`: the largest link, m (the wheel must not be
        vanishingly small beside it)."""
        w = "drive.gear"
        if "gear" not in drive:
            self.err(f"{w}: a working machine needs the table [drive.gear] (module, z_pinion, z_wheel, ...)")
            return None
        t = self.read(DRIVE, drive, "gear", "drive")
        if t is None:
            return None
        self.unknown_keys(t, GEAR.keys(), w)
        module = self.read(GEAR, t, "module", w)
        z1, z2 = self.read(GEAR, t, "z_pinion", w), self.read(GEAR, t, "z_wheel", w)
        corr = self.read(GEAR, t, "correction", w)
        if corr == "unequal" and "alpha_w_deg" not in t:
            self.err(f"{w}.alpha_w_deg: required for an unequal correction (25-26 deg typically)")
        alpha = self.read(GEAR, t, "alpha_w_deg", w)
        y = self.read(GEAR, t, "y", w)
        cd = self.read(GEAR, t, "centre_direction", w)
        if None in (module, z1, z2, corr, alpha, y, cd):
            return None
        gear = Gear(module, z1, z2, corr, alpha, y, cd)
        if gear.r_w <= 0:
            self.err(f"{w}.y: the wheel's pitch radius r_w = r (1 + 2y/(z1 + z2)) = {gear.r_w:g} m must be > 0")
            return None
        if gear.r_b < MIN_GEAR * size:
            self.err(f"{w}.module: the wheel's base radius r_b = {gear.r_b:.3g} m is below {MIN_GEAR:g} of the "
                     f"largest link ({size:.3g} m): the balancing force M_bal / r_b would be out of range; "
                     f"is the module in metres (0.010 for 10 mm)?")
            return None
        return gear
