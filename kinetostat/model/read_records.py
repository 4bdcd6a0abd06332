"""The reader's sections for what the model records beside the mechanism: the sources' published
values, a parameter study, the text's lettering.

May use: the standard library, limits, parts, schema, core.
"""
from __future__ import annotations

from types import MappingProxyType
from typing import Any, Mapping

from .core import ReaderCore, _rule, _suggest
from .limits import MAX_STUDY_VALUES, MAX_VALUE, _finite
from .parts import PUBLISHED_UNITS, Drive, Link, Load, Pair, Published, Study
from .schema import LETTERING, MODEL, PUBLISHED, REQUIRED, STUDY


class RecordReading(ReaderCore):
    """The reader's sections for published values, study, lettering: a part of `reader._Reader`."""

    def published(self, links: list[Link], pairs: list[Pair], drive: Drive | None) -> list[Published]:
        out: list[Published] = []
        first: dict[str, int] = {}
        for n, t in enumerate(self.table_list("published")):
            entry = self.published_entry(t, f"published[{n}]", links, pairs, drive)
            if entry is None:
                continue
            if entry.symbol in first:
                self.err(f"published[{n}].symbol: {entry.symbol!r} is already used by published[{first[entry.symbol]}]")
                continue
            first[entry.symbol] = n
            out.append(entry)
        return out

    def published_entry(self, t: Mapping, where: str, links: list[Link], pairs: list[Pair],
                        drive: Drive | None) -> Published | None:
        quantity = self.read(PUBLISHED, t, "quantity", where)
        allowed = PUBLISHED.keys(quantity=quantity)
        needs = allowed - PUBLISHED.keys()        # the quantity's own fields
        self.unknown_keys(t, allowed, where)
        n_problems = len(self.problems)
        symbol, source, meaning, accuracy, value = (
            self.read(PUBLISHED, t, key, where) for key in ("symbol", "source", "meaning", "accuracy", "value"))
        angles = self.published_angles(t.get("angle"), f"{where}.angle")
        reduce = self.read(PUBLISHED, t, "reduce", where)
        if isinstance(t.get("angle"), list) and reduce is None and "reduce" not in t:
            self.err(f"{where}.reduce: missing: a list of angles needs reduce = 'min', 'max' or 'angle_of_max'")
        elif reduce is not None and not isinstance(t.get("angle"), list):
            self.err(f"{where}.reduce: only with a list of angles (angle = [...])")
        by_angle = reduce == "angle_of_max"
        tol_key, other = ("tolerance_deg", "tolerance") if by_angle else ("tolerance", "tolerance_deg")
        if other in t:
            self.err(f"{where}.{other}: " + ("the angle of the maximum takes tolerance_deg (deg)" if by_angle
                                             else "only reduce = 'angle_of_max' takes tolerance_deg; "
                                                  "give tolerance (relative, e.g. 0.01 for 1 %)"))
        tolerance = self.read(PUBLISHED, t, tol_key, where, default=REQUIRED)
        unit = "deg" if by_angle else PUBLISHED_UNITS.get(quantity)
        if "unit" in t and unit is not None and t["unit"] != unit:
            self.err(f"{where}.unit: {quantity if not by_angle else 'angle_of_max'} is in {unit!r}, "
                     f"got {t['unit']!r}")
        point = relative_to = link = pair = None
        if "point" in needs:
            point = self.published_point(t, "point", where, links, required=True)
            relative_to = self.published_point(t, "relative_to", where, links, required=False)
        elif "link" in needs:
            link = self.read(PUBLISHED, t, "link", where)
            if link is not None:
                self.link_ok(links, link, f"{where}.link")
        elif "pair" in needs:
            pair = self.read(PUBLISHED, t, "pair", where)
            pair = tuple(pair) if pair is not None and self.joined(pairs, pair, f"{where}.pair") else None
        if quantity == "balancing_force" and drive is not None and drive.kind != "machine":
            self.err(f"{where}.quantity: a balancing force needs drive.kind = 'machine' (an engine has a moment)")
        if len(self.problems) > n_problems or None in (symbol, source, quantity, value, angles, tolerance):
            return None
        return Published(symbol, quantity, value, unit, angles, reduce, tolerance, source, meaning, accuracy,
                         point, relative_to, link, pair)

    def published_angles(self, x: Any, where: str) -> tuple[float, ...] | None:
        items = [self.scalar(a, f"{where}[{i}]") for i, a in enumerate(x)] if isinstance(x, list) \
            else [self.scalar(x, where)]
        if None in items and x is not None:
            return None
        most = PUBLISHED["angle"].max_length
        if x is None or not items or len(items) > most or not all(_finite(a) and abs(a) <= MAX_VALUE for a in items):
            self.err(f"{where}: " + ("missing (a crank angle in deg, or a list of them)" if x is None else
                                     f"expected a finite number of deg or a list of 1..{most} of them, got {x!r}"[:200]))
            return None
        return tuple(float(a) for a in items)

    def published_point(self, t: Mapping, key: str, where: str, links: list[Link], *, required: bool) -> str | None:
        name = t.get(key)
        if name is None and not required:
            return None
        if not isinstance(name, str) or not any(name in link.points for link in links):
            known = sorted({p for link in links for p in link.points})
            self.err(f"{where}.{key}: " + (f"missing (a point name is required). Valid names: {known}" if name is None
                                           else f"unknown point {name!r}. Valid names: {known}"))
            return None
        return name

    def study(self, pairs: list[Pair]) -> Study | None:
        """[study]: vary = { name = [values], ... } (one or two parameters), pair = [i, j], steps."""
        t = self.read(MODEL, self.data, "study", "")
        if t is None:
            return None
        self.unknown_keys(t, STUDY.keys(), "study")
        title = self.read(STUDY, t, "title", "study")
        vary, v, most = [], t.get("vary"), STUDY["vary"].max_length
        if not (isinstance(v, dict) and 1 <= len(v) <= most):
            self.err(f"study.vary: expected a table of 1..{most} parameters and their values, "
                     f"e.g. {{ r = [0.05, 0.08], n_k = [60, 120] }}, got {v!r:.80}")
        else:
            for name, xs in v.items():
                if name not in self.values or name == "g":
                    self.err(f"study.vary.{name}: not a parameter of the model{_suggest(name, self.values)}. "
                             f"Parameters: {sorted(n for n in self.values if n != 'g')}")
                elif not (isinstance(xs, list) and 1 <= len(xs) <= MAX_STUDY_VALUES and all(_finite(x) for x in xs)):
                    self.err(f"study.vary.{name}: expected a list of 1..{MAX_STUDY_VALUES} finite numbers")
                else:
                    vary.append((name, tuple(float(x) for x in xs)))
        pair = self.read(STUDY, t, "pair", "study")
        if pair is None or not self.joined(pairs, pair, "study.pair"):
            return None
        steps = self.read(STUDY, t, "steps", "study")
        if steps is None or not isinstance(v, dict) or len(vary) != len(v):
            return None
        return Study(title, tuple(vary), (pair[0], pair[1]), steps)

    def lettering(self, links: list[Link], loads: list[Load]) -> Mapping[str, Any]:
        """`[lettering]`: the text's names (models/FORMAT.md), checked; frozen."""
        t = self.read(MODEL, self.data, "lettering", "")
        if t is None:
            return MappingProxyType({})
        self.unknown_keys(t, LETTERING.keys(), "lettering")
        out: dict[str, Any] = {}
        k = self.read(LETTERING, t, "frame", "lettering", default=None)
        if k and k < len(links):
            self.err(f"lettering.frame: {_rule(LETTERING['frame'])}, not a moving link's (1..{len(links) - 1}), got {k!r}")
        elif k is not None:
            out["frame"] = k
        for key in ("M_bal", "F_bal", "language", "name", "loads"):
            x = self.read(LETTERING, t, key, "lettering", default=None)
            bad = sorted(set(x) - {ld.name for ld in loads}) if key == "loads" and x else ()
            if bad:
                self.err(f"lettering.loads.{bad[0]}: no such load{_suggest(bad[0], [ld.name for ld in loads])}. "
                         f"Valid: {sorted(ld.name for ld in loads)}")
            elif x:
                out[key] = MappingProxyType(x) if isinstance(x, dict) else x
        return MappingProxyType(out)
