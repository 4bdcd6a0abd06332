"""The reader's sections for the mechanism's body: the links (and their bodies), the pairs, the
groups' branches.

May use: the standard library, limits, parts, mechanism, schema, checks, core.
"""
from __future__ import annotations

from types import MappingProxyType
from typing import Mapping

from .checks import check_pairs, turned_slider
from .core import ReaderCore, _in_range, _suggest
from .limits import MAX_VALUE, MIN_LENGTH
from .mechanism import extent
from .parts import Body, Link, Pair, Vec, combine
from .schema import BODY, GROUP, LINK, MODEL, PAIR


class LinkReading(ReaderCore):
    """The reader's sections for links, their bodies, pairs, groups: a part of `reader._Reader`."""

    def links(self, g: float | None) -> list[Link]:
        frame = Link(0, "frame", MappingProxyType(self.points(MODEL["frame"], self.data.get("frame"), "frame", 0)))
        raw = self.table_list("link")
        by_id: dict[int, Link] = {}
        for n, t in enumerate(raw):
            lid = t.get("id")
            valid_id = isinstance(lid, int) and not isinstance(lid, bool) and _in_range(LINK["id"], lid)
            # named by its id, as the texts number links; by its table's place only without one
            where = f"link[id={lid}]" if valid_id and lid not in by_id else f"[[link]] #{n + 1}"
            if valid_id and lid not in by_id:
                self.link_table[lid] = n
            self.unknown_keys(t, LINK.keys(), where)
            if valid_id and lid in by_id:
                self.err(f"{where}.id: duplicate link id {lid} (link[id={lid}] is [[link]] "
                         f"#{self.link_table[lid] + 1})")
            elif not valid_id:
                self.read(LINK, t, "id", where)
            if not valid_id or lid in by_id:
                self.ids_unknown = True
                lid = None
            pts = self.points(LINK["points"], t.get("points"), f"{where}.points", lid)
            bodies: tuple[Body, ...] = ()
            if "body" in t:
                bodies = self.bodies(t, where, pts, g)
                if bodies:
                    m_total, S, I_total = combine(bodies)
                    com = t.get("com", f"S{lid if lid is not None else n + 1}")
                    if not isinstance(com, str) or com in pts:
                        self.err(f"{where}.com: with bodies, com names the new point of their combined centre "
                                 f"of mass; got {com!r}" + (", already a point of the link" if com in pts else ""))
                    elif lid is not None:
                        pts[com] = S
                        by_id[lid] = Link(lid, self.read(LINK, t, "name", where, default=f"link {lid}"),
                                          MappingProxyType(pts), m_total, I_total, com, bodies)
                continue
            if "mass" in t and "weight" in t:
                self.err(f"{where}: give mass or weight, not both")
            if "weight" in t:
                w = self.read(LINK, t, "weight", where)
                mass = None if (w is None or not g) else w / g
                if w is not None and g == 0:     # (a missing or invalid g is reported already)
                    self.err(f"{where}.weight: a weight needs mechanism.g > 0 to give a mass")
                elif mass is not None and not mass <= MAX_VALUE:
                    self.err(f"{where}.weight: {w:g} N / g = {w:g} / {g:g} m/s^2 gives a mass of {mass:g} kg, "
                             f"out of range (<= {MAX_VALUE:g} kg): is mechanism.g right?")
                    mass = None
            else:
                mass = self.read(LINK, t, "mass", where)
            I_S = self.read(LINK, t, "I_S", where)
            com = self.read(LINK, t, "com", where)
            if com is not None and pts and com not in pts:
                self.err(f"{where}.com: unknown point {com!r}{_suggest(com, pts)}. Valid names: {sorted(pts)}")
            if mass and com is None:
                self.err(f"{where}.com: missing (a link with mass needs its centre-of-mass point)")
            span = extent(pts.values()) if pts else None
            if span == 0 and len(pts) >= 2:
                self.coincident[lid if lid is not None else -n - 1] = where     # refused unless in a P pair
            elif span is not None and 0 < span < MIN_LENGTH:
                self.err(f"{where}.points: the link spans only {span:.3g} m: below {MIN_LENGTH:g} m the squares of "
                         f"its lengths underflow (accelerations and forces turn into 0 or NaN); is the unit right?")
            if lid is not None:
                by_id[lid] = Link(lid, self.read(LINK, t, "name", where, default=f"link {lid}"),
                                  MappingProxyType(pts), mass or 0.0, I_S or 0.0, com)
        ids = sorted(by_id)
        if ids != list(range(1, len(ids) + 1)) or self.ids_unknown:
            if not self.ids_unknown:        # a table without a valid id is the cause of any gap
                self.err(f"link: ids must be 1..n without gaps, got {ids}")
            self.ids_unknown = True
            return [frame]
        return [frame] + [by_id[i] for i in ids]

    def bodies(self, t: Mapping, where: str, pts: dict[str, Vec], g: float | None) -> tuple[Body, ...]:
        """[[link.body]]: each with mass (or weight), com (a point of the link or [x, y]) and
        I_S about its own centre (default 0, a point mass); () after recording a problem."""
        for key in ("mass", "weight", "I_S"):
            if key in t:
                self.err(f"{where}.{key}: a link given by bodies takes its {key} from them; remove it")
        raw = self.read(LINK, t, "body", where)
        if raw is None:
            return ()
        n0, out = len(self.problems), []
        for n, b in enumerate(raw):
            w = f"{where}.body[{n}]"
            self.unknown_keys(b, BODY.keys(), w)
            if not self.one_of(BODY, b, w):
                continue
            mass = self.read(BODY, b, "mass", w)
            if "weight" in b:
                wt = self.read(BODY, b, "weight", w)
                if wt is not None and not g:
                    self.err(f"{w}.weight: a weight needs mechanism.g > 0 to give a mass")
                mass = None if wt is None or not g else wt / g
            raw_com = b.get("com")
            if isinstance(raw_com, str):
                com = pts.get(raw_com)
                if com is None:
                    self.err(f"{w}.com: unknown point {raw_com!r}{_suggest(raw_com, pts)}. Valid names: {sorted(pts)}")
            else:
                com = self.vec(raw_com, f"{w}.com")
            I_S = self.read(BODY, b, "I_S", w)
            if None not in (mass, com, I_S):
                out.append(Body(self.read(BODY, b, "name", w, default=f"body {n + 1}"), mass, com, I_S))
        return tuple(out) if len(self.problems) == n0 else ()

    def pairs(self, links: list[Link]) -> list[Pair]:
        out = []
        for n, t in enumerate(self.table_list("pair")):
            where = f"pair[{n}]"
            kind = self.read(PAIR, t, "kind", where)
            self.unknown_keys(t, PAIR.keys(kind=kind), where)
            lk = self.read(PAIR, t, "links", where)
            if lk is None or not all(self.link_ok(links, x, f"{where}.links") for x in lk):
                continue
            radius = self.read(PAIR, t, "radius", where)
            if kind == "R":
                pt = t.get("point")
                if all(self.point_ok(links, x, pt, f"{where}.point") for x in lk):
                    out.append(Pair(len(out), "R", tuple(lk), pt, radius=radius))
            elif kind == "P":
                pt, gd = t.get("point"), t.get("guide")
                pts = lambda k: links[k].points
                if pt not in pts(lk[1]) and gd not in pts(lk[0]) and pt in pts(lk[0]) and gd in pts(lk[1]):
                    self.err(f"{where}.links: a prismatic pair lists [guide link, slider link], and {lk} reads "
                             f"reversed: point {pt!r} is on link {lk[0]} and guide {gd!r} on link {lk[1]}; "
                             f"write links = [{lk[1]}, {lk[0]}]")
                    continue
                order = " (links = [guide link, slider link]: the {} is on link {})"
                ok = self.point_ok(links, lk[1], pt, f"{where}.point", order.format("point", lk[1]))
                ok &= self.point_ok(links, lk[0], gd, f"{where}.guide", order.format("guide point", lk[0]))
                d = self.read(PAIR, t, "direction", where)
                axis = self.read(PAIR, t, "slider_axis", where) if "slider_axis" in t else None
                if ok and d is not None and ("slider_axis" not in t or axis is not None):
                    if axis is not None:
                        self.slider_axes.add(len(out))
                        links[lk[1]] = turned_slider(links[lk[1]], axis)
                    out.append(Pair(len(out), "P", tuple(lk), pt, gd, d, radius))
        for msg in check_pairs(links, out, self.coincident, self.slider_axes):
            self.err(msg)
        return out

    def groups(self, links: list[Link]) -> dict[frozenset, int]:
        out = {}
        for n, t in enumerate(self.table_list("group")):
            where = f"group[{n}]"
            self.unknown_keys(t, GROUP.keys(), where)
            lk = self.read(GROUP, t, "links", where)
            if lk is None or not all(self.link_ok(links, x, f"{where}.links") for x in lk):
                continue
            b = self.read(GROUP, t, "branch", where)
            if b is None:
                continue
            key = frozenset(lk)
            if key in out and out[key] != b:
                first = self.group_tables[key][0]
                self.err(f"{where}.branch: group {sorted(key)} is already given branch = {out[key]:+d} by "
                         f"group[{first}]; this entry says {b:+d}: keep one")
                continue
            out[key] = b
            self.group_tables.setdefault(key, (n, tuple(lk)))
        return out
