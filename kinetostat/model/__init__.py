"""The mechanism model: a model file (TOML), described once by `schema`, read and checked by
`reader` into the immutable `Mechanism` of `mechanism`.

Rooms: parts (the frozen parts a Mechanism is made of), mechanism (the Mechanism), laws
(splines, parsed expressions of laws), limits (sizes, ranges, thresholds), schema (every table
and field of the format), describe (the schema as JSON Schema and as the field tables of
models/FORMAT.md), source (file -> text -> data), lines (where keys sit), core (the reader's
machinery), read_* (its sections), checks (the cross-field checks and plausibility warnings),
reader (the sections put together). It also re-exports what the single module `kinetostat.model`
offered before it became this package (the errors, Structure, the limits, Vec), so that
`from kinetostat.model import ModelError, MIN_LENGTH, Vec` keeps working.

May use: its rooms, errors, structure.
"""
from __future__ import annotations

from ..errors import ModelError, ModelFileNotFound, ModelWarning, StructureError
from ..structure import Structure, analyse_structure
from .core import _suggest
from .laws import _periodic_spline, _spline_at
from .limits import (FASTEST_PIN, LAW_VARIABLES, MAX_FILE_BYTES, MAX_KEY, MAX_KEY_MEMORY, MAX_NAME, MAX_PARAMETERS,
                     MAX_POINTS, MAX_PROBLEMS, MAX_PUBLISHED_ANGLES, MAX_SHOWN, MAX_TABLE_POINTS, MAX_VALUE, MIN_GEAR, MIN_LENGTH)
from .lines import _Lines
from .mechanism import Mechanism, _abbreviate
from .parts import (PUBLISHED_UNITS, Body, Characteristic, Drive, Flywheel, Friction, Gear, Link, Load, Pair, Published, SpeedLaw,
                    Spring, Study, Table, Vec, combine)
from .source import ParsedModel, _read_text, build, from_dict, load, loads, model_text, parse_text

__all__ = ["Link", "Body", "Pair", "Table", "Load", "Characteristic", "SpeedLaw", "combine", "Spring", "Gear", "Drive",
           "Flywheel", "Friction", "Published", "Study", "Mechanism", "PUBLISHED_UNITS", "load", "loads", "from_dict", "model_text"]
