"""The units of a model's fields and [parameters], as a model file states them (SI throughout,
models/FORMAT.md), in the ASCII spelling of the tables' units ("kg m^2", "rad/s^2").

May use: the standard library only; a Mechanism and its model file's text are passed in (its
`parameters`, `expressions`).
"""
from __future__ import annotations

import re
from typing import Any, Iterable

__all__ = ["field_unit", "parameter_units", "NOT_STATED", "PRESSURES"]

#: A parameter's unit where neither a field nor the model file's comment gives one.
NOT_STATED = "not stated"
#: Unit of a model field by its last name (models/FORMAT.md: SI throughout); points are in m.
_FIELD_UNITS = {"mass": "kg", "I_S": "kg m^2", "rpm": "rpm", "omega": "rad/s", "eps": "rad/s^2", "module": "m",
                "z_wheel": "1", "z_pinion": "1", "scale": "N", "stiffness": "N/m", "free_length": "m", "radius": "m",
                "f": "1", "value": "N or N m"}
#: Units a model file's comment may state for a parameter ("r = 0.080  # crank length, m").
#: The units of pressure a comment may state, each with the pascals it holds (SI: Pa; the others
#: are not the file's units).
PRESSURES = {"Pa": "1", "kPa": "1e3", "MPa": "1e6", "bar": "1e5"}
_STATED_UNITS = {"m", "mm", "rpm", "kg", "kg m^2", "kg/m", "kg/m^3", "N", "N m", "N/m", *PRESSURES, "m^2", "rad/s",
                 "rad/s^2", "deg", "m/s^2", "s", "1"}


def field_unit(path: str) -> str | None:
    """The unit of a model field given by its path ("link[id=2].mass"), None where unknown."""
    if ".points." in path or path.startswith("frame."):
        return "m"
    return _FIELD_UNITS.get(re.sub(r"\[[^\]]*\]$", "", path).rsplit(".", 1)[-1])


def parameter_units(m: Any, text: str, names: Iterable[str] | None = None) -> dict[str, str]:
    """The unit of each of the Mechanism `m`'s [parameters] (or of those `names`): that of a
    field given as the parameter's name alone, else the one the model file's comment on the
    parameter states ("# crank length, m"; a ratio "l_AB / l_OA" is 1), else `NOT_STATED`.
    `text`: the model file's text ("" where there is none; `kinetostat.model.model_text`)."""
    out = {}
    for name in m.parameters if names is None else names:
        unit = next((u for path, (expr, _) in m.expressions.items()
                     if not path.startswith("parameters.") and expr.strip() == name
                     and (u := field_unit(path)) is not None), None)
        said = re.search(rf"^[ \t]*{re.escape(name)}[ \t]*=[^#\n]*#([^\n]*)", text, re.M)
        if unit is None and said:
            comment = re.sub(r"\([^)]*\)", "", said[1])
            unit = next((t.strip() for t in re.split(r"[,:;]", comment) if t.strip() in _STATED_UNITS), None)
            if unit is None and re.match(r"\s*\w+ / \w+", comment):
                unit = "1"
        out[name] = unit or NOT_STATED
    return out
