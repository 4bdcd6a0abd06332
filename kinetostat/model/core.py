"""The reader's machinery: problems collected with their lines (each cause once, the rest counted),
and the typed getters each field of the schema is read with (number, vector, string, integer,
points, series, a link's id, a point of a link, unknown keys with "did you mean").

May use: the standard library, expressions, limits, lines, parts, schema.
"""
from __future__ import annotations

import math
import re
import sys
from typing import Any, Mapping

from ..expressions import shown_number, suggest
from .limits import MAX_NAME, MAX_POINTS, MAX_PROBLEMS, MAX_SHOWN, MAX_VALUE, _finite, _subnormal
from .lines import _Lines
from .parts import Link, Vec
from .schema import REQUIRED, Section


def _suggest(name: Any, valid) -> str:
    """" (did you mean 'mass'?)" when `name` is a near miss of one of `valid`, else "" (bounded
    work: `expressions.suggest`)."""
    return suggest(name, valid) if isinstance(name, str) else ""



class ReaderCore:
    """What every section of the reader uses: the problems collected (each once, with its line),
    the state of what was read, and the typed getters that check a field as the schema
    (`schema.Section`) describes it. Each getter returns None after recording a problem."""

    def __init__(self, data: Mapping[str, Any], source: str, text: str | None = None,
                 overrides: Mapping[str, Any] | None = None):
        self.data, self.source, self.problems, self.lines = data, source, [], []
        self.overrides = dict(overrides or {})
        self.values: dict[str, float] = {}        # parameters and g, as expressions read them
        self.failed: set[str] = set()             # parameters (or g) whose value is in error
        self.expressions: dict[str, tuple[str, float]] = {}   # field path -> (expression, value)
        self.where_lines = _Lines(text) if text is not None else None
        self.link_table: dict[int, int] = {}      # link id -> index of its [[link]] table
        # causes already reported, whose consequences are not reported again:
        self.ids_unknown = False                  # some [[link]] has no valid id: "unknown link" follows
        self.points_unread: set[tuple[int, str | None]] = set()   # (link, point) that failed (None: all)
        self.misspelled: set[str] = set()         # field paths given under a near-miss name
        self.unshown = 0                          # problems beyond MAX_PROBLEMS, counted only
        self.group_tables: dict[frozenset, tuple[int, tuple]] = {}   # group -> (its [[group]], links as listed)
        self.coincident: dict[int, str] = {}      # links whose points all coincide -> their field path
        self.slider_axes: set[int] = set()        # P pairs (index) whose slider frame the file states

    def err(self, msg: str) -> None:
        path = msg.partition(": ")[0]
        if path in self.misspelled and msg[len(path):].startswith(": missing"):
            return          # "mass: missing" after "masss: unknown field (did you mean 'mass'?)"
        if len(self.problems) >= MAX_PROBLEMS:
            self.unshown += 1
            return
        self.problems.append(msg)
        self.lines.append(self.line_of(path))

    _STEP = re.compile(r"(\[\[(\w+)\]\] #(\d+)|[^.\[]+)(?:\[(id=)?(\d+)\])?")

    def line_of(self, path: str) -> int | None:
        """Line of the file where the field `path` of a message (e.g. `link[id=2].mass`) sits."""
        if self.where_lines is None or " " in path.replace("<top level>", "").replace("[[link]] #", ""):
            return None
        steps: tuple = ()
        for part in path.split("."):
            m = self._STEP.fullmatch(part)
            if m is None:
                return None
            if m[2]:                                  # [[link]] #3: the third table
                steps += (m[2], int(m[3]) - 1)
                continue
            steps += () if m[1] == "<top level>" else (m[1],)
            if m[5] is not None:
                steps += (self.link_table.get(int(m[5]), -1) if m[4] else int(m[5]),)
        return self.where_lines.line(steps) if steps else None

    # -- parameters and expressions

    def read(self, section: Section, tab: Mapping, key: str, where: str, **default: Any) -> Any:
        """Field `key` of the table `tab` (at `where`), checked as `section` describes it: its type,
        range, choices and default (`default=...` gives a default that depends on the table,
        such as a link's name)."""
        f = section[key]
        d = default.get("default", f.default)
        if f.type == "number":
            return self.number(tab, key, where, default=d, minimum=f.minimum, positive=f.positive, divisor=f.divisor)
        if f.type == "string":
            return self.string(tab, key, where, choices=f.choices or None, default=d, max_length=f.max_length)
        if f.type == "integer":
            return self.integer(tab, key, where)
        raise TypeError(f"{section.name}.{key}: a {f.type} field has its own reader")

    def number(self, tab: Mapping, key: str, where: str, *, default: Any = REQUIRED,
               minimum: float | None = None, positive: bool = False, divisor: bool = False) -> float | None:
        if key not in tab:
            if default == REQUIRED:
                self.err(f"{where}.{key}: missing (a number is required)")
                return None
            return default
        x = self.scalar(tab[key], f"{where}.{key}")
        if x is None:
            return None
        shown = shown_number(x) if not isinstance(tab[key], str) else f'{x!r} (= "{tab[key]:.{MAX_SHOWN}}")'
        if not _finite(x):
            self.err(f"{where}.{key}: expected a finite number, got {shown}")
            return None
        if abs(x) > MAX_VALUE:
            self.err(f"{where}.{key}: {shown} is out of range (|value| <= {MAX_VALUE:g})")
            return None
        if (positive or divisor) and _subnormal(x):
            self.err(f"{where}.{key}: {shown} is subnormal (0 < |value| < {sys.float_info.min:.3g}): it loses its "
                     f"digits, and its products turn into 0, NaN or inf; write 0 or the value meant")
            return None
        if positive and x <= 0:
            self.err(f"{where}.{key}: must be > 0, got {shown}")
            return None
        if minimum is not None and x < minimum:
            self.err(f"{where}.{key}: must be >= {minimum}, got {shown}")
            return None
        return float(x)

    def vec(self, x: Any, where: str, *, unit: bool = False) -> Vec | None:
        if isinstance(x, list) and len(x) == 2:
            x = [self.scalar(c, f"{where}[{i}]") for i, c in enumerate(x)]
            if None in x:
                return None
        if not (isinstance(x, list) and len(x) == 2 and all(_finite(c) for c in x)):
            self.err(f"{where}: expected [x, y] with two finite numbers, got {x!r}")
            return None
        if max(abs(x[0]), abs(x[1])) > MAX_VALUE:
            self.err(f"{where}: {x!r} is out of range (|coordinate| <= {MAX_VALUE:g})")
            return None
        if unit:
            n = math.hypot(*x)
            if n == 0:
                self.err(f"{where}: direction must not be zero")
                return None
            return (x[0] / n, x[1] / n)
        return (float(x[0]), float(x[1]))

    def string(self, tab: Mapping, key: str, where: str, *, choices: tuple[str, ...] | None = None,
               default: Any = REQUIRED, max_length: int | None = None) -> str | None:
        if key not in tab:
            if default == REQUIRED:
                self.err(f"{where}.{key}: missing (a string is required)")
                return None
            return default
        x = tab[key]
        if not isinstance(x, str):
            self.err(f"{where}.{key}: expected a string, got {x!r}")
            return None
        if choices and x not in choices:
            self.err(f"{where}.{key}: invalid value {x!r}{_suggest(x, choices)}. Valid values: {list(choices)}")
            return None
        if max_length is not None and len(x) > max_length:
            self.err(f"{where}.{key}: {len(x)} characters, at most {max_length} (it labels plots and plans)")
            return None
        return x

    def integer(self, tab: Mapping, key: str, where: str) -> int | None:
        x = self.scalar(tab.get(key), f"{where}.{key}")     # an expression must give a whole number
        if isinstance(x, float) and x.is_integer() and isinstance(tab.get(key), str):
            x = int(x)
        if not isinstance(x, int) or isinstance(x, bool):
            self.err(f"{where}.{key}: expected an integer, got {x!r}" if key in tab
                     else f"{where}.{key}: missing (an integer is required)")
            return None
        return x

    def table_list(self, key: str) -> list:
        x = self.data.get(key, [])
        if not isinstance(x, list) or not all(isinstance(t, dict) for t in x):
            self.err(f"{key}: expected an array of tables ([[{key}]])")
            return []
        return x

    def unknown_keys(self, tab: Mapping, allowed: set[str], where: str) -> None:
        unused = sorted(allowed.difference(tab))
        for k in tab:
            if k not in allowed and len(self.problems) >= MAX_PROBLEMS:
                self.unshown += 1
            elif k not in allowed:
                hint = _suggest(k, unused)
                if hint:
                    self.misspelled.add(f"{where}.{hint.split(chr(39))[1]}")
                self.err(f"{where}.{k}: unknown field{hint}. Valid fields: {sorted(allowed)}")

    # -- sections

    def link_ok(self, links: list[Link], lid: Any, where: str, *, first: int = 0) -> bool:
        """Is `lid` the id of a link (>= `first`)? Unknown ids are not reported while some
        [[link]] table has no valid id: that table's problem is the cause."""
        if not isinstance(lid, int) or isinstance(lid, bool) or not first <= lid < len(links):
            if not self.ids_unknown:
                moving = " moving" if first else ""
                self.err(f"{where}: unknown{moving} link {lid!r}. Valid links: {list(range(first, len(links)))}")
            return False
        return True

    def point_ok(self, links: list[Link], lid: int, name: Any, where: str, why: str = "") -> bool:
        if not isinstance(name, str) or name not in links[lid].points:
            if name is None:            # (after a misspelt key, err leaves this out)
                self.err(f"{where}: missing (a point of link {lid} is required){why}. "
                         f"Valid names: {sorted(links[lid].points)}")
            elif (lid, None) not in self.points_unread and (lid, name) not in self.points_unread:
                self.err(f"{where}: link {lid} has no point {name!r}{_suggest(name, links[lid].points)}{why}. "
                         f"Valid names: {sorted(links[lid].points)}")
            return False
        return True

    def points(self, raw: Any, where: str, lid: int | None = None) -> dict[str, Vec]:
        """A table of named points; those that fail are recorded in points_unread for link `lid`."""
        if not isinstance(raw, dict) or not raw or len(raw) > MAX_POINTS:
            self.err(f"{where}: {'missing: ' if raw is None else ''}expected a table of named points {{A = [x, y], ...}}"
                     + (f", at most {MAX_POINTS} of them, got {len(raw)}" if raw and isinstance(raw, dict) else ""))
            self.points_unread.add((lid, None))
            return {}
        out = {}
        for name, xy in raw.items():
            if len(name) > MAX_NAME:
                self.err(f"{where}: a point name of {len(name)} characters ({name[:20]!r}...), at most {MAX_NAME} "
                         f"(it labels plots and plans)")
                self.points_unread.add((lid, name))
                continue
            v = self.vec(xy, f"{where}.{name}")
            if v is not None:
                out[name] = v
            else:
                self.points_unread.add((lid, name))
        return out

    def series(self, x: Any, where: str) -> tuple[float, ...] | None:
        if isinstance(x, list):
            x = [self.scalar(v, f"{where}[{i}]") for i, v in enumerate(x)]
            if None in x:
                return None
        if not (isinstance(x, list) and len(x) >= 2 and all(_finite(v) and abs(v) <= MAX_VALUE for v in x)):
            self.err(f"{where}: expected a list of at least two finite numbers (|value| <= {MAX_VALUE:g})")
            return None
        return tuple(float(v) for v in x)