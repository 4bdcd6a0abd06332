"""The reader's sections for what acts on the mechanism: loads (forces, moments, dampers, their
diagrams and characteristics), springs, friction.

May use: the standard library, numpy, core, limits, parts, schema.
"""
from __future__ import annotations

from typing import Any, Mapping

import numpy as np

from .core import ReaderCore
from .limits import MAX_SHOWN
from .parts import Characteristic, Friction, Link, Load, Pair, Spring, Table
from .schema import CHARACTERISTIC, FRICTION, LOAD, LOAD_TABLE, MODEL, SPRING, SPRING_END


class LoadReading(ReaderCore):
    """The reader's sections for loads, springs, friction: a part of `reader._Reader`."""

    def loads(self, links: list[Link], pairs: list[Pair]) -> list[Load]:
        out = []
        for n, t in enumerate(self.table_list("load")):
            where = f"load[{n}]"
            kind = self.read(LOAD, t, "kind", where)
            name = self.read(LOAD, t, "name", where, default=f"load {n}")
            if kind == "damper":
                self.unknown_keys(t, LOAD.keys(kind=kind), where)
                damper = self.damper(t, where, name, links, pairs)
                if damper is not None:
                    out.append(damper)
                continue
            self.unknown_keys(t, LOAD.keys(kind=kind or "force"), where)
            lid = self.read(LOAD, t, "link", where)
            if lid is None or not self.link_ok(links, lid, f"{where}.link"):
                continue
            point, direction = None, None
            if kind == "force":
                if not self.point_ok(links, lid, t.get("point"), f"{where}.point"):
                    continue
                point = t["point"]
                raw = t.get("direction")
                direction = ("against_velocity" if raw == "against_velocity"
                             else self.vec(raw, f"{where}.direction", unit=True))
            else:
                raw = t.get("direction")
                if raw not in (None, "against_omega"):
                    self.err(f"{where}.direction: a moment takes no direction or 'against_omega', got {raw!r}")
                direction = raw
            if not self.one_of(LOAD, t, where, kind=kind or "force"):
                continue
            value = self.read(LOAD, t, "value", where)
            table = self.table(self.read(LOAD, t, "table", where), f"{where}.table") if "table" in t else None
            if "characteristic" in t:
                if direction is not None:
                    self.err(f"{where}.direction: a characteristic M(omega) gives its own sign")
                    continue
                characteristic = self.characteristic(t["characteristic"], f"{where}.characteristic")
                if characteristic is not None:
                    out.append(Load(name, kind, lid, None, None, None, None, characteristic))
                continue
            if table is not None and table.argument == "travel":
                if kind == "moment":
                    self.err(f"{where}.table.travel: a moment acts on a link, not at a point, so it has no "
                             f"travel to follow; use phi_deg (the crank angle), or make it a force at a point")
                    continue
                if table.axis is None and direction == "against_velocity":
                    self.err(f"{where}.table.axis: missing: the travel is measured along axis, and a force "
                             f"directed 'against_velocity' has no fixed direction to take it from (give the "
                             f"world direction of the stroke, e.g. axis = [0.0, 1.0])")
                    continue
            if kind == "force" and direction is None:
                continue
            if value is not None or table is not None:
                out.append(Load(name, kind, lid, point, direction, value, table))
        return out

    def characteristic(self, t: Any, where: str) -> Characteristic | None:
        """A motor's M(omega): { omega = [...], M = [...] } or an expression of omega."""
        if isinstance(t, str):
            c = Characteristic(expression=t, parameters=tuple(self.values.items()))
            try:
                value = c(np.array([0.0, 1.0]))
            except ValueError as exc:
                self.err(f'{where}: "{t:.{MAX_SHOWN}}": {exc}')
                return None
            if not np.isfinite(value).all():
                self.err(f'{where}: "{t:.{MAX_SHOWN}}" is not finite at omega = 0 or 1 rad/s')
                return None
            return c
        if not isinstance(t, dict):
            self.err(f"{where}: expected {{ omega = [...], M = [...] }} (rad/s, N m) or an expression of omega")
            return None
        self.unknown_keys(t, CHARACTERISTIC.keys(), where)
        ws, ms = self.read(CHARACTERISTIC, t, "omega", where), self.read(CHARACTERISTIC, t, "M", where)
        if ws is None or ms is None:
            return None
        if len(ws) != len(ms):
            self.err(f"{where}.M: {len(ms)} values for {len(ws)} speeds")
            return None
        return Characteristic(ws, ms)

    def damper(self, t: Mapping, where: str, name: str, links: list[Link], pairs: list[Pair]) -> Load | None:
        """A viscous damper on the pair `pair` = [i, j]: coefficient c >= 0."""
        lk = self.read(LOAD, t, "pair", where)
        c = self.read(LOAD, t, "c", where)
        if lk is None or not all(self.link_ok(links, x, f"{where}.pair") for x in lk) \
                or not self.joined(pairs, lk, f"{where}.pair"):
            return None
        if c is None:
            return None
        return Load(name, "damper", lk[1], None, None, c, None, None, (lk[0], lk[1]))

    def table(self, t: dict | None, where: str) -> Table | None:
        """A load diagram [load.table] (None: reported)."""
        if t is None:
            return None
        self.unknown_keys(t, LOAD_TABLE.keys(), where)
        if not self.one_of(LOAD_TABLE, t, where):
            return None
        arg = "phi" if "phi_deg" in t else "travel"
        xs = self.read(LOAD_TABLE, t, "phi_deg" if arg == "phi" else "travel", where)
        vs = self.read(LOAD_TABLE, t, "value", where)
        vr = self.read(LOAD_TABLE, t, "value_return", where)
        scale = self.read(LOAD_TABLE, t, "scale", where)
        if xs is None or vs is None or scale is None:
            return None
        for nm, v in (("value", vs), ("value_return", vr)):
            if v is not None and len(v) != len(xs):
                self.err(f"{where}.{nm}: {len(v)} values for {len(xs)} arguments")
        if arg == "phi" and xs[0] == 0 and xs[-1] == 360 and len(vs) == len(xs) and vs[0] != vs[-1]:
            self.err(f"{where}: a crank-angle diagram is periodic, but its value at 0 deg ({vs[0]:g}) "
                     f"and at 360 deg ({vs[-1]:g}) differ")
        if arg == "phi" and ("value_return" in t or "axis" in t or "origin" in t):
            self.err(f"{where}: value_return, axis and origin belong to a travel table")
        axis = self.read(LOAD_TABLE, t, "axis", where)
        origin = self.read(LOAD_TABLE, t, "origin", where)
        return Table(arg, xs, vs, vr, scale, axis, origin)

    def springs(self, links: list[Link]) -> list[Spring]:
        out = []
        for n, t in enumerate(self.table_list("spring")):
            where = f"spring[{n}]"
            self.unknown_keys(t, SPRING.keys(), where)
            ends = []
            for e in ("a", "b"):
                end = self.read(SPRING, t, e, where)
                if end is None:
                    continue
                self.unknown_keys(end, SPRING_END.keys(), f"{where}.{e}")
                lid = self.read(SPRING_END, end, "link", f"{where}.{e}")
                if lid is not None and self.link_ok(links, lid, f"{where}.{e}.link") and \
                        self.point_ok(links, lid, end.get("point"), f"{where}.{e}.point"):
                    ends.append((lid, end["point"]))
            if len(ends) == 2 and ends[0][1] == ends[1][1]:
                self.err(f"{where}: both ends are the point {ends[0][1]!r}: the spring has no length or direction")
                ends = []
            k = self.read(SPRING, t, "stiffness", where)
            l0 = self.read(SPRING, t, "free_length", where)
            if len(ends) == 2 and k is not None and l0 is not None:
                out.append(Spring(self.read(SPRING, t, "name", where, default=f"spring {n}"), ends[0], ends[1], k, l0))
        return out

    def friction(self) -> Friction | None:
        t = self.read(MODEL, self.data, "friction", "")
        if t is None:
            return None
        self.unknown_keys(t, FRICTION.keys(), "friction")
        f = self.read(FRICTION, t, "f", "friction")
        r = self.read(FRICTION, t, "radius", "friction")
        method = self.read(FRICTION, t, "method", "friction")
        return None if f is None else Friction(f, r, method)
