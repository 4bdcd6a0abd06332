"""The reader's section for `[parameters]`: each parameter evaluated (overrides applied, in any
order) into the values that the fields' expressions read (`core.ReaderCore.scalar`), its
problems named by parameter.

May use: the standard library, expressions, core, limits, schema.
"""
from __future__ import annotations

import keyword
import unicodedata
from typing import Mapping

from ..expressions import CONSTANTS, FUNCTIONS
from ..expressions import resolve as resolve_parameters
from .core import ReaderCore, _suggest
from .limits import LAW_VARIABLES
from .schema import MODEL


def _code_points(name: str) -> str:
    """A name with the code points that are not ASCII named: 'µ' -> "'µ' (U+00B5 MICRO SIGN)"."""
    odd = [f"U+{ord(c):04X} {unicodedata.name(c, '?')}" for c in dict.fromkeys(name) if ord(c) > 127]
    return f"{name!r}" + (f" ({', '.join(odd[:4])}{', ...' if len(odd) > 4 else ''})" if odd else "")


class ParameterReading(ReaderCore):
    """The reader's section for parameters: a part of `reader._Reader`."""

    def read_parameters(self, head: Mapping) -> None:
        """Evaluate `[parameters]` (with the overrides) and g (mechanism.g, which expressions read
        as `g`), in any order, into self.values; problems are recorded against each parameter."""
        t = self.data.get("parameters", {})
        if not isinstance(t, dict):
            self.err("parameters: expected a table of named numbers and expressions")
            t = {}
        most = MODEL["parameters"].max_length
        if len(t) > most:
            self.err(f"parameters: {len(t)} parameters, at most {most}")
            t = {}
        raw = dict(t)
        for name in raw:
            if name == "g":
                self.err("parameters.g: g is mechanism.g (m/s^2), which expressions read as g: give it there")
            elif name in FUNCTIONS or name in CONSTANTS:
                self.err(f"parameters.{name}: {name!r} is the name of a function or constant of expressions")
            elif name in LAW_VARIABLES:
                self.err(f"parameters.{name}: {name!r} is the variable of a law of motion omega(phi) or of a "
                         f"characteristic M(omega), which would hide this parameter there; choose another name")
            elif unicodedata.normalize("NFKC", name) != name:
                self.err(f"parameters.{name}: {_code_points(name)} reads as {_code_points(unicodedata.normalize('NFKC', name))} "
                         f"in expressions (Unicode NFKC, as Python folds names); write it so")
            elif keyword.iskeyword(name):
                self.err(f"parameters.{name}: {name!r} is a Python keyword, which an expression reads as itself, "
                         f"never as this parameter; choose another name")
            elif not name.isidentifier() or name.startswith("__"):
                self.err(f"parameters.{name}: a parameter's name is a Python-style identifier (letters, digits, _)")
        for name, x in self.overrides.items():
            if name != "g" and name not in raw:
                self.err(f"parameters: cannot override {name!r}: the model has no such parameter"
                         f"{_suggest(name, [*raw, 'g'])}. Parameters: {sorted(raw)}")
            elif name != "g":
                raw[name] = x
        raw = {n: x for n, x in raw.items() if n != "g"}
        if "g" in head or "g" in self.overrides:
            raw["g"] = self.overrides.get("g", head.get("g"))
        values, problems = resolve_parameters(raw)
        for name, msg in problems.items():
            if name != "g":             # mechanism.g reports its own problem when read
                self.err(f"parameters.{name}: {msg}")
        self.values, self.failed = values, set(problems)
        for name, x in raw.items():
            if isinstance(x, str) and name in values:
                self.expressions["mechanism.g" if name == "g" else f"parameters.{name}"] = (x, values[name])
