"""The reader's machinery: problems collected with their lines (each cause once, the rest counted),
expressions evaluated, and `ReaderCore.read`, which reads a field as its `schema.Field` says (type,
range, choices, length, order, shape, default; the message from the field's `rule` or its range)
through the typed getters (number, integer, string, strings, [i, j], series, vector, table, array
of tables, table of names), beside the getters the schema cannot say alone (points, a link's id
among the links, a point of a link, unknown keys with "did you mean", exactly one of a group).

May use: the standard library, expressions, limits, lines, parts, schema.
"""
from __future__ import annotations

import math
import re
import sys
from typing import Any, Mapping

from ..expressions import ExpressionError, parse as parse_expression, shown_number, suggest
from .limits import MAX_NAME, MAX_PROBLEMS, MAX_SHOWN, MAX_TABLE_POINTS, MAX_VALUE, _finite, _subnormal
from .lines import _Lines
from .parts import Link, Pair, Vec
from .schema import MODEL, REQUIRED, Field, Section


def _suggest(name: Any, valid) -> str:
    """" (did you mean 'mass'?)" when `name` is a near miss of one of `valid`, else "" (bounded
    work: `expressions.suggest`)."""
    return suggest(name, valid) if isinstance(name, str) else ""


#: What a missing required field of each type is, in its message ("missing (a number is required)").
_WANTED = {"number": "a number", "integer": "an integer", "link": "a link id", "string": "a string",
           "strings": "a list of strings", "links": "two link ids [i, j]", "series": "a list of numbers",
           "vector": "[x, y]", "direction": "a direction [x, y]", "map": "a table"}


#: Control characters (C0, DEL, C1), the line and paragraph separators (U+2028, U+2029) and the
#: bidirectional embeddings, overrides and isolates (U+202A-U+202E, U+2066-U+2069, which reorder
#: how a text reads: "Trojan source"), which no name holds: a name is one line of text.
_CONTROL = re.compile("[\x00-\x1f\x7f-\x9f\u2028\u2029\u202a-\u202e\u2066-\u2069]")


def _control(name: str) -> str:
    """The first control character of `name` as the reader names it ("U+001B at character 3"),
    or "" where it has none."""
    m = _CONTROL.search(name)
    return "" if m is None else f"U+{ord(m[0]):04X} at character {m.start() + 1}"


def _in_range(f: Field, x: Any) -> bool:
    """Is `x` (a number, or a string's length and characters) within the field's range and choices?"""
    if isinstance(x, str):
        return f.min_length <= len(x) <= (f.max_length or len(x)) and (x.isprintable() or not f.printable)
    return ((not f.choices or x in f.choices) and (f.minimum is None or x >= f.minimum)
            and (f.maximum is None or x <= f.maximum) and not (f.positive and x <= 0)
            and (f.exclusive_maximum is None or x < f.exclusive_maximum))


def _rule(f: Field, rule: str = "") -> str:
    """What a value outside the field's range or choices is told: `rule` or the field's own (its
    range filled in), else the range itself ("must be >= 0.0", "expected +1 or -1")."""
    if rule or f.rule:
        return (rule or f.rule).format_map(vars(f))
    if f.choices:
        signed = any(isinstance(c, int) and c < 0 for c in f.choices)
        return "expected " + " or ".join(f"{c:+d}" if signed else repr(c) for c in f.choices)
    if f.type in ("integer", "link"):
        lo, hi = f.minimum, f.maximum
        span = f"{lo}..{hi}" if hi is not None and lo is not None else f">= {lo}" if lo is not None else f"<= {hi}"
        return f"expected an integer {span} ({f.doc})"
    if f.positive:
        return "must be > 0"
    bounds = [f">= {f.minimum}"] * (f.minimum is not None) + [f"<= {f.maximum}"] * (f.maximum is not None) \
        + [f"< {f.exclusive_maximum}"] * (f.exclusive_maximum is not None)
    return ("values " if f.type == "series" else "") + "must be " + " and ".join(bounds)


class ReaderCore:
    """The base of every section of the reader (`read_*`): the problems collected (each once,
    with its line), the state of what was read, and the typed getters that check a field as the
    schema (`schema.Section`) describes it. Each getter returns None after recording a problem."""

    def __init__(self, data: Mapping[str, Any], source: str, text: str | None = None,
                 overrides: Mapping[str, Any] | None = None, lines: _Lines | None = None):
        self.data, self.source, self.problems, self.lines = data, source, [], []
        self.overrides = dict(overrides or {})
        self.values: dict[str, float] = {}        # parameters and g, as expressions read them
        self.failed: set[str] = set()             # parameters (or g) whose value is in error
        self.expressions: dict[str, tuple[str, float]] = {}   # field path -> (expression, value)
        self.text = text or ""                    # the file's text (its comments state parameters' units)
        self.where_lines = lines if lines is not None else _Lines(text) if text is not None else None   # text's
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

    # -- the typed getters: a field read as its table (schema.Section) describes it

    def scalar(self, x: Any, path: str) -> Any:
        """`x` itself, or the value of the expression `x` (a string) over the parameters; None
        after recording a problem (naming `path` and the parameter that fails)."""
        if path == "mechanism.g" and "g" in self.values:      # also a number that an override of g replaces
            return self.values["g"]
        if not isinstance(x, str):
            return x
        try:
            e = parse_expression(x)
            bad = sorted(n for n in e.names if n in self.failed)
            if bad:
                raise ExpressionError(f"reads {', '.join(map(repr, bad))}, which has an error (see "
                                      f"{', '.join('mechanism.g' if n == 'g' else f'parameters.{n}' for n in bad)})")
            value = e(self.values)
        except ExpressionError as exc:
            self.err(f'{path}: expression "{x:.{MAX_SHOWN}}": {exc}')
            return None
        self.expressions[path] = (x, value)
        return value


    def read(self, section: Section, tab: Mapping, key: str, where: str, **default: Any) -> Any:
        """Field `key` of the table `tab` (at `where`), checked as `section` describes it: its type,
        range, choices, length, shape and default (`default=...` gives a default that depends on
        the table, such as a link's name). None after recording a problem (or when an optional
        field without default is not given)."""
        f = section[key]
        d = default.get("default", f.default)
        path = f"{where}.{key}" if where else key
        if key not in tab:
            if d == REQUIRED and f.type == "table" and not where:
                self.err(f"{path}: missing table [{key}]")
            elif d == REQUIRED and f.type == "table":
                self.err(f"{path}: missing (a table {{ {', '.join(g.name for g in f.section.fields)} }} is required)")
            elif d == REQUIRED:
                self.err(f"{path}: missing ({_WANTED[f.type]} is required)")
            return None if d == REQUIRED else d
        x = tab[key]
        if f.type == "table":
            if not isinstance(x, dict):
                self.err(f"{path}: expected a table {{ {', '.join(g.name for g in f.section.fields)} }}")
                return None
            return x
        if f.type == "tables":
            if not (isinstance(x, list) and len(x) >= f.min_length and all(isinstance(t, dict) for t in x)):
                self.err(f"{path}: expected an array of tables ([[{f.section.name}]]) with "
                         f"{', '.join(g.name for g in f.section.fields)}")
                return None
            return x
        if f.type == "number":
            return self.number(f, x, path)
        if f.type in ("integer", "link"):
            return self.integer(f, x, path)
        if f.type == "string":
            return self.string(f, x, path)
        if f.type == "strings":
            return self.strings(f, x, path)
        if f.type == "links":
            return self.link_ids(f, x, path)
        if f.type == "series":
            return self.series(f, x, path)
        if f.type in ("vector", "direction"):
            return self.vec(x, path, unit=f.type == "direction")
        if f.type == "map" and f.items == "string":
            return self.names(f, x, path)
        raise TypeError(f"{section.name}.{key}: a {f.type} field has its own reader")

    def out_of_range(self, f: Field, path: str, shown: str) -> None:
        """Record that the value `shown` of field `f` at `path` is outside its range or choices
        (where the field's rule places it with "{value}", there; else after it)."""
        rule = f.rule.replace("{value}", shown) if "{value}" in f.rule else ""
        self.err(f"{path}: {_rule(f, rule)}" if rule else f"{path}: {_rule(f)}, got {shown}")

    def number(self, f: Field, x: Any, path: str) -> float | None:
        x0, x = x, self.scalar(x, path) if f.expression else x
        if isinstance(x, str):
            self.err(f"{path}: expected a number, got {x!r:.{MAX_SHOWN}}")
            return None
        if x is None:
            return None
        shown = shown_number(x) if not isinstance(x0, str) else f'{x!r} (= "{x0:.{MAX_SHOWN}}")'
        if not _finite(x):
            self.err(f"{path}: expected a finite number, got {shown}")
            return None
        if abs(x) > MAX_VALUE:
            self.err(f"{path}: {shown} is out of range (|value| <= {MAX_VALUE:g})")
            return None
        if (f.positive or f.divisor) and _subnormal(x):
            self.err(f"{path}: {shown} is subnormal (0 < |value| < {sys.float_info.min:.3g}): it loses its "
                     f"digits, and its products turn into 0, NaN or inf; write 0 or the value meant")
            return None
        if not _in_range(f, x):
            self.out_of_range(f, path, shown)
            return None
        return float(x)

    def integer(self, f: Field, x: Any, path: str) -> int | None:
        """An integer (or an expression giving a whole number) within the field's range or choices."""
        given, x = x, self.scalar(x, path) if f.expression else x
        if isinstance(x, float) and x.is_integer() and isinstance(given, str):
            x = int(x)
        if not isinstance(x, int) or isinstance(x, bool):
            if x is not None:
                one = f.choices or (f.minimum is not None and f.minimum == f.maximum)    # "+1 or -1", "link 1"
                want = _rule(f) if one else "expected an integer"
                self.err(f"{path}: {want}, got {x!r}" + (
                    "" if not (isinstance(x, float) and x.is_integer()) else
                    " (write it without a decimal point)" if want == "expected an integer"
                    else " (an integer: write it without a decimal point)"))
            return None
        if not _in_range(f, x):
            self.out_of_range(f, path, repr(x))
            return None
        return x

    def string(self, f: Field, x: Any, path: str) -> str | None:
        if not isinstance(x, str):
            self.err(f"{path}: expected a string, got {x!r}")
            return None
        if f.choices and x not in f.choices:
            self.err(f"{path}: invalid value {x!r}{_suggest(x, f.choices)}. Valid values: {list(f.choices)}")
            return None
        if f.max_length is not None and len(x) > f.max_length and not f.rule:
            self.err(f"{path}: {len(x)} characters, at most {f.max_length} (it labels plots and plans)")
            return None
        if f.one_line and _control(x):
            self.err(f"{path}: {x!r:.{MAX_SHOWN}} holds the control character {_control(x)}: a name is one "
                     f"line of text")
            return None
        if not _in_range(f, x):
            self.out_of_range(f, path, repr(x))
            return None
        return x

    def strings(self, f: Field, x: Any, path: str) -> tuple[str, ...] | None:
        if not (isinstance(x, list) and all(isinstance(a, str) for a in x)):
            self.err(f"{path}: expected a list of strings, got {x!r:.80}")
            return None
        return tuple(x)

    def link_ids(self, f: Field, x: Any, path: str) -> list[int] | None:
        """[i, j]: two different link ids (whether they are links, and joined, the caller asks)."""
        if not (isinstance(x, list) and len(x) == 2 and all(isinstance(i, int) and not isinstance(i, bool) for i in x)):
            self.err(f"{path}: expected two link ids [i, j], got {x!r:.80} ({f.doc})")
            return None
        if x[0] == x[1]:
            self.err(f"{path}: {f.rule or 'expected two different link ids [i, j]'}, got {x} ({f.doc})")
            return None
        return [x[0], x[1]]

    def names(self, f: Field, x: Any, path: str) -> dict[str, str] | None:
        """A table of strings by name (its keys among the field's choices, if it has any)."""
        if not (isinstance(x, dict) and all(isinstance(v, str) and (v.isprintable() or not f.printable)
                                            for v in x.values())):
            self.err(f"{path}: expected a table of {'printable ' if f.printable else ''}strings")
            return None
        bad = sorted(set(x) - set(f.choices)) if f.choices else []
        if bad:
            self.err(f"{path}.{bad[0]}: {_rule(f)}{_suggest(bad[0], f.choices)}. Valid: {sorted(f.choices)}")
            return None
        return dict(x)

    def series(self, f: Field, x: Any, path: str) -> tuple[float, ...] | None:
        """A list of at least two finite numbers (each may be an expression), each within the
        field's range, strictly increasing if the field says so; at most MAX_TABLE_POINTS."""
        if isinstance(x, list) and len(x) > MAX_TABLE_POINTS:
            self.err(f"{path}: {len(x)} values, at most {MAX_TABLE_POINTS} (MAX_TABLE_POINTS)")
            return None
        if isinstance(x, list):
            x = [self.scalar(v, f"{path}[{i}]") for i, v in enumerate(x)]
            if None in x:
                return None
        if not (isinstance(x, list) and len(x) >= 2 and all(_finite(v) and abs(v) <= MAX_VALUE for v in x)):
            self.err(f"{path}: expected a list of at least two finite numbers (|value| <= {MAX_VALUE:g})")
            return None
        bad = [v for v in x if not _in_range(f, v)]
        if bad:
            self.out_of_range(f, path, shown_number(bad[0]))
            return None
        down = [(a, b) for a, b in zip(x, x[1:]) if b <= a] if f.increasing else []
        if down:
            self.err(f"{path}: the values must increase strictly, got {shown_number(down[0][1])} after "
                     f"{shown_number(down[0][0])}")
            return None
        return tuple(float(v) for v in x)

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

    def table_list(self, key: str) -> list:
        """The array of tables `[[key]]` of the file (none: [])."""
        return self.read(MODEL, self.data, key, "", default=[]) or []

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

    def one_of(self, section: Section, tab: Mapping, where: str, **given: Any) -> bool:
        """Is exactly one field of each of the section's `one_of` groups given (of the groups whose
        condition holds, given the values of its discriminating fields)? Recorded if not."""
        ok = True
        for g in section.one_of:
            if g.when is not None and given.get(g.when[0], section[g.when[0]].default) not in g.when[1]:
                continue
            if sum(name in tab for name in g.fields) != 1:
                allowed = section.keys(**given)
                names = [name for name in g.fields if name in allowed]
                self.err(f"{where}: give exactly one of {', '.join(names[:-1])} or {names[-1]}"
                         + (f" ({g.hint})" if g.hint else ""))
                ok = False
        return ok

    def joined(self, pairs: list[Pair], lk: list[int], path: str) -> bool:
        """Do the links `lk` = [i, j] share a kinematic pair? (Recorded if not.)"""
        if any(set(p.links) == set(lk) for p in pairs):
            return True
        self.err(f"{path}: no kinematic pair joins links {lk}. Pairs: {[list(p.links) for p in pairs]}")
        return False

    def points(self, f: Field, raw: Any, where: str, lid: int | None = None) -> dict[str, Vec]:
        """A table of named points (at most the field's max_length); those that fail are recorded
        in points_unread for link `lid`."""
        if not isinstance(raw, dict) or not raw or len(raw) > f.max_length:
            self.err(f"{where}: {'missing: ' if raw is None else ''}expected a table of named points {{A = [x, y], ...}}"
                     + (f", at most {f.max_length} of them, got {len(raw)}" if raw and isinstance(raw, dict) else ""))
            self.points_unread.add((lid, None))
            return {}
        out = {}
        for name, xy in raw.items():
            if len(name) > MAX_NAME:
                self.err(f"{where}: a point name of {len(name)} characters ({name[:20]!r}...), at most {MAX_NAME} "
                         f"(it labels plots and plans)")
                self.points_unread.add((lid, name))
                continue
            if f.one_line and _control(name):
                self.err(f"{where}: the point name {name!r:.{MAX_SHOWN}} holds the control character "
                         f"{_control(name)}: a name is one line of text")
                self.points_unread.add((lid, name))
                continue
            v = self.vec(xy, f"{where}.{name}")
            if v is not None:
                out[name] = v
            else:
                self.points_unread.add((lid, name))
        return out
