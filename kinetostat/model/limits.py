"""The limits of a model file: sizes, ranges and the thresholds of the plausibility warnings.

May use: the standard library, expressions.
"""
from __future__ import annotations

import sys
from typing import Any

from ..expressions import _finite_number

#: The variables of laws of motion (phi, rad) and of motor characteristics (omega, rad/s): no parameter's name.
LAW_VARIABLES = ("phi", "omega")

#: Longest key (or table header) of a model file, characters.
MAX_KEY = 10_000
#: Largest model file read (or text parsed), bytes (a model is a few kB, the largest bundled one
#: 16 kB; 4000 links take 0.8 MB).
MAX_FILE_BYTES = 32 * 2**20
#: Memory tomllib may take for the keys of one file, estimated as _KEY_BYTES per key plus
#: _LEVEL_BYTES per square of its depth (fitted to measurements: 266k two-level keys of a
#: 4 MB file took 220 MB, 29k keys of 64 levels 1.1 GB).
MAX_KEY_MEMORY = 256 * 2**20
_KEY_BYTES, _LEVEL_BYTES = 800, 9
#: Largest magnitude of any number in a model file (m, kg, N, ...): beyond it squares overflow.
MAX_VALUE = 1e12
#: Most points of one link.
MAX_POINTS = 10_000
#: Most values of one table's list (a law of motion's omega_table, a load diagram, a motor
#: characteristic): a measured diagram has a few hundred; 200,000 load in about 7 s, 10^6 took
#: over a minute.
MAX_TABLE_POINTS = 200_000
#: Shortest nonzero span of a link, m: sqrt of the smallest normal double, so that squares of
#: lengths stay normal numbers.
MIN_LENGTH = 1e-150
#: Smallest nonzero g, m/s^2: below it the weights g m and their moments g m x turn subnormal or
#: zero (3e-308 is a normal double, but 0.8 kg times it is not).
MIN_G = 1e-150
#: Smallest base radius of the drive's gear wheel, relative to the largest link.
MIN_GEAR = 1e-6
#: A ModelWarning asks whether a model was drawn in millimetres above these: the largest link,
#: m, and the crank pin's speed, m/s (machines of the texts: links below 2 m, pins below 30 m/s).
LARGEST_LINK, FASTEST_PIN = 20.0, 340.0
#: Warned: a link whose radius of gyration exceeds this many times its span (I_S in g mm^2 makes it
#: 30000 times too long; a flywheel on a crank, a few spans), and a
#: force diagram whose largest force is below this fraction of the mechanism's weights and
#: inertia forces (a pressure in MPa times an area in m^2?).
GYRATION_SPANS, FORCE_SCALE = 100.0, 1e-4
#: Warned: a reduced friction coefficient above FRICTION_F (a friction angle above 45 deg: dry metal
#: pairs take 0.1 .. 0.3, lubricated ones 0.01 .. 0.1; a percentage or an angle typed as f exceeds
#: it), and a journal radius above JOURNAL_SPANS of the largest link (a journal wider than the
#: linkage: a radius in millimetres, or a diameter of the wrong unit).
FRICTION_F, JOURNAL_SPANS = 1.0, 0.5

#: Most parameters of one file, and most values one parameter takes in a study.
MAX_PARAMETERS, MAX_STUDY_VALUES = 1000, 50
#: Most crank angles one `[[published]]` entry may list.
MAX_PUBLISHED_ANGLES = 3600


#: Characters of an expression quoted in a message.
MAX_SHOWN = 120
#: Longest name of the mechanism, a point, link, body, load or spring (each labels plots and plans:
#: 10,000 characters took a report two minutes, a mechanism's name of 100,000 characters 24 s).
MAX_NAME = 200
#: Most problems listed for one file (the rest are counted): 300,000 unknown keys stay one short list.
MAX_PROBLEMS = 100


def _finite(x: Any) -> bool:
    """A finite number, also as a float (an integer of 400 digits is not)."""
    return isinstance(x, (int, float)) and not isinstance(x, bool) and _finite_number(x)


def _subnormal(x: float) -> bool:
    """Nonzero but below the smallest normal double: no model number is meant so."""
    return 0 < abs(x) < sys.float_info.min
