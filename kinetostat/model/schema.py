"""The model format, written once: every table of a model file and every field in it, with its
type, unit, range, default, whether it takes an expression, and a one-line description.

The reader takes its per-field checks from here (types, ranges, defaults, choices, the fields a
table may hold); `describe` makes the field tables of models/FORMAT.md and the JSON Schema of
editors from it. What is not one field's business (structure, contradictions, plausibility)
lives in the reader's sections and in `checks`.

A small table of our own rather than pydantic or msgspec: the reader keeps its own reporting
(field paths such as `link[id=2].mass`, the file's line, "did you mean", every problem at once,
no follow-on errors), which those libraries would have to be bent to give; the table is data.

May use: the standard library, limits, parts (PUBLISHED_UNITS).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Mapping

from .limits import MAX_NAME, MAX_PARAMETERS, MAX_POINTS, MAX_PUBLISHED_ANGLES
from .parts import PUBLISHED_UNITS

#: The default of a field that must be given.
REQUIRED = "required"


@dataclass(frozen=True)
class Field:
    """One field of a table. `type`: number, integer, string, strings (a list of them), vector
    ([x, y]), direction (a nonzero [x, y]), series (a list of 2..MAX_TABLE_POINTS numbers), points (named
    [x, y]), point (a point's name), link (a link's id), links ([i, j]), angles (a number or a
    list), com (a point's name or [x, y]), load_direction, characteristic, map (a table of named
    `items`), table or tables (`section`, a nested table or array of tables)."""
    name: str
    type: str
    doc: str
    unit: str = ""
    default: Any = None               # REQUIRED, None (optional, no default) or the value taken
    minimum: float | None = None      # value >= minimum (numbers, integers, links, a series' items)
    positive: bool = False            # value > 0 (also refused subnormal)
    divisor: bool = False             # refused subnormal (0 < |x| < 2.2e-308): it divides or is squared
    choices: tuple = ()               # strings, integers: the values allowed; map: the keys allowed
    expression: bool = False          # a string is an expression over [parameters]
    max_length: int | None = None     # strings: most characters; lists and tables: most items
    maximum: float | None = None      # value <= maximum (as minimum)
    exclusive_maximum: float | None = None   # value < exclusive_maximum (as minimum)
    min_length: int = 0               # strings: fewest characters; tables: fewest tables
    printable: bool = False           # strings (a map's too): printable characters only
    one_line: bool = False            # strings, the names of points: a name, no control character (C0, DEL, C1)
    increasing: bool = False          # series: strictly increasing
    rule: str = ""                    # the message when out of range or choices (links: the same id twice), "{minimum}"
                                      # etc. filled in from the field, "{value}" the value (else ", got" it follows);
                                      # default: the range, "must be >= 0.0"
    when: tuple[str, tuple] | None = None   # (field, values): allowed only when that field has one of them
    required_when: tuple[str, tuple] | None = None   # (field, values): required when that field has one of them
    section: "Section | None" = None  # table, tables, characteristic: its table
    items: str = ""                   # map: "number", "numbers" (a list) or "string"


@dataclass(frozen=True)
class OneOf:
    """Exactly one of `fields` is given (only when the field `when[0]` has one of the values
    `when[1]`, if `when`); `hint`: what the reader's message adds."""
    fields: tuple[str, ...]
    when: tuple[str, tuple] | None = None
    hint: str = ""


@dataclass(frozen=True)
class Section:
    """A table (`array`: an array of tables `[[name]]`) of the model file; `one_of`: the groups of
    its fields of which exactly one is given."""
    name: str
    doc: str
    fields: tuple[Field, ...]
    array: bool = False
    one_of: tuple[OneOf, ...] = ()

    def __post_init__(self):
        object.__setattr__(self, "_by_name", {f.name: f for f in self.fields})

    def __getitem__(self, key: str) -> Field:
        return self._by_name[key]

    def keys(self, **given: Any) -> set[str]:
        """Names of the fields this table may hold, given the values of its discriminating fields
        (`PAIR.keys(kind="P")`): those without `when`, and those whose condition holds."""
        return {f.name for f in self.fields if f.when is None or given.get(f.when[0]) in f.when[1]}


def _num(name: str, doc: str, unit: str = "", **kw) -> Field:
    """A number field: a TOML number or an expression over [parameters]."""
    return Field(name, "number", doc, unit, expression=True, **kw)


_TEETH = "a gear needs at least {minimum} teeth"
_SPEEDS = "the crank turns in the drive's sense: speeds must be >= {minimum:g}"
_SYMBOL = dict(min_length=1, max_length=16, printable=True,
               rule="expected a symbol of {min_length}..{max_length} printable characters")
#: The languages of the outputs.
LANGUAGES = ("en", "uk", "ru")


def _name(doc: str, default: str) -> Field:
    return Field("name", "string", doc, default=default, max_length=MAX_NAME, one_line=True)


GEAR = Section("drive.gear", "The last gear pair of a working machine (drive.kind = \"machine\"; Kiriienko 2019, sec. 7.1).", (
    _num("module", "module of the gear pair", "m", default=REQUIRED, positive=True),
    Field("z_pinion", "integer", "teeth of the driving pinion", default=REQUIRED, minimum=5, expression=True,
          rule=_TEETH),
    Field("z_wheel", "integer", "teeth of the wheel on the crank shaft", default=REQUIRED, minimum=5, expression=True,
          rule=_TEETH),
    Field("correction", "string", "profile correction; \"unequal\" needs alpha_w_deg and y", default="none",
          choices=("none", "equal", "unequal")),
    _num("alpha_w_deg", "pressure angle of the mesh", "deg", default=20.0, positive=True, exclusive_maximum=45.0,
         rule="pressure angle must be below {exclusive_maximum:g} deg"),
    _num("y", "pitch-line shift coefficient (unequal correction only)", default=0.0),
    Field("centre_direction", "direction", "world direction from the crank axis to the pinion axis", default=REQUIRED,
          expression=True),
))

OMEGA_TABLE = Section("drive.omega_table", "A law of motion omega(phi) as a table over one revolution (periodic cubic spline).", (
    Field("phi_deg", "series", "crank angles, within 360 deg", "deg", default=REQUIRED, expression=True, increasing=True),
    Field("omega", "series", "crank speeds (or rpm)", "rad/s", expression=True, minimum=0.0, rule=_SPEEDS),
    Field("rpm", "series", "crank speeds (or omega)", "rpm", expression=True, minimum=0.0, rule=_SPEEDS),
), one_of=(OneOf(("omega", "rpm"), hint="omega in rad/s"),))

DRIVE = Section("drive", "The initial link I(0,1): the crank, its angle's reference and sense, its speed.", (
    Field("link", "link", "the crank: always 1", default=1, minimum=1, maximum=1, rule="the crank must be link {minimum}"),
    Field("pivot", "point", "the crank's revolute pair with the frame", default=REQUIRED),
    Field("point", "point", "crank angle = direction of pivot -> point", default=REQUIRED),
    Field("reference", "direction", "world direction of phi = 0", default=REQUIRED, expression=True),
    Field("sense", "string", "positive sense of phi and of omega", default=REQUIRED, choices=("ccw", "cw")),
    _num("rpm", "crank speed, >= 0 in sense (0: statics); one of rpm, omega, omega_table", "rpm", minimum=0.0, divisor=True),
    _num("omega", "crank speed, >= 0 in sense; or a law of motion, an expression of phi (rad)", "rad/s",
         minimum=0.0, divisor=True),
    Field("omega_table", "table", "a law of motion omega(phi) as a table", section=OMEGA_TABLE),
    _num("eps", "crank angular acceleration in sense (not with a law of motion)", "rad/s^2", default=0.0),
    Field("kind", "string", "\"engine\": balancing moment through a coupling; \"machine\": balancing force on a gear mesh",
          default="engine", choices=("engine", "machine")),
    Field("gear", "table", "the gear mesh of a machine", default=REQUIRED, section=GEAR, when=("kind", ("machine",))),
    _num("design_deg", "the design position: crank angle of the mechanism's picture", "deg", default=30.0),
), one_of=(OneOf(("rpm", "omega", "omega_table"), hint="omega: a number, or an expression of phi"),))

MECHANISM = Section("mechanism", "What the model is and where its data come from.", (
    _name("free text, labels plots and plans", "unnamed"),
    Field("source", "string", "where the data come from", default=""),
    Field("assumptions", "strings", "every number not in the source, and why", default=()),
    _num("g", "gravity along -y (0 switches it off); expressions read it as g", "m/s^2", default=REQUIRED,
         minimum=0.0, divisor=True),
))

BODY = Section("link.body", "One of the bodies a link is made of; the link's mass, centre and I_S are theirs combined.", (
    _name("the body's name", "body <n>"),
    _num("mass", "mass (or weight)", "kg", minimum=0.0),
    _num("weight", "weight, converted with g (or mass)", "N", minimum=0.0),
    Field("com", "com", "its centre of mass: a point of the link, or local [x, y]", "m", default=REQUIRED, expression=True),
    _num("I_S", "moment of inertia about its own centre (0: a point mass)", "kg m^2", default=0.0, minimum=0.0),
), array=True, one_of=(OneOf(("mass", "weight")),))

LINK = Section("link", "A moving link, one table each, numbered as in the text (1 = the crank).", (
    Field("id", "integer", "the link's number: 1..n without gaps", default=REQUIRED, minimum=1,
          rule="moving links are numbered from {minimum} (0 is the frame)"),
    _name("the link's name", "link <id>"),
    Field("points", "points", "named points in the link's local frame", "m", default=REQUIRED, expression=True,
          max_length=MAX_POINTS, one_line=True),
    _num("mass", "mass (or weight)", "kg", default=0.0, minimum=0.0),
    _num("weight", "weight, converted with g (or mass)", "N", minimum=0.0),
    _num("I_S", "moment of inertia about the centre of mass", "kg m^2", default=0.0, minimum=0.0),
    Field("com", "string", "the point that is the centre of mass (needed if mass > 0; with bodies: a new point)"),
    Field("body", "tables", "the bodies the link is made of, instead of mass, weight and I_S", section=BODY,
          min_length=1),
), array=True)

PAIR = Section("pair", "A lower kinematic pair: revolute R or prismatic P.", (
    Field("kind", "string", "revolute or prismatic", default=REQUIRED, choices=("R", "P")),
    Field("links", "links", "R: the two links; P: [guide link, slider link]", default=REQUIRED,
          rule="a pair joins two different links"),
    Field("point", "point", "R: a point of both links; P: a point of the slider on the guide line", default=REQUIRED),
    _num("radius", "journal radius, for friction losses", "m", positive=True),
    Field("guide", "point", "a point of the guide link on the guide line", default=REQUIRED, when=("kind", ("P",))),
    Field("direction", "direction", "guide direction in the guide link's local frame", default=REQUIRED,
          expression=True, when=("kind", ("P",))),
    Field("slider_axis", "direction", "the guide direction in the frame the slider's points are given in",
          default=(1.0, 0.0), expression=True, when=("kind", ("P",))),
), array=True)

GROUP = Section("group", "The assembly branch of an Assur group (RRR, RRP, RPR).", (
    Field("links", "links", "the group's two links (RRR: the lower id is j)", default=REQUIRED),
    Field("branch", "integer", "+1 or -1 (see Branches)", default=REQUIRED, choices=(1, -1)),
), array=True)

LOAD_TABLE = Section("load.table", "A piecewise-linear load diagram; the load is scale * value.", (
    Field("phi_deg", "series", "argument: crank angle (or travel)", "deg", expression=True, minimum=0.0, maximum=360.0,
          increasing=True, rule="angles must lie in [{minimum:g}, {maximum:g}]"),
    Field("travel", "series", "argument: fraction of the stroke (or phi_deg)", expression=True, minimum=0.0,
          maximum=1.0, increasing=True, rule="fractions of stroke must lie in [{minimum:g}, {maximum:g}]"),
    Field("value", "series", "the diagram's values (forward stroke for travel)", expression=True, default=REQUIRED),
    Field("value_return", "series", "travel only: values on the return stroke (default: value)", expression=True),
    _num("scale", "load per table unit", "N or N m", default=1.0),
    Field("axis", "direction", "travel only: world axis of the stroke (default: the load's direction)", expression=True),
    Field("origin", "string", "travel only: the extreme the travel is measured from", default="max", choices=("max", "min")),
), one_of=(OneOf(("phi_deg", "travel")),))

CHARACTERISTIC = Section("load.characteristic", "A motor's M(omega), in the drive's sense: a table (or an expression of omega).", (
    Field("omega", "series", "speeds", "rad/s", default=REQUIRED, expression=True, increasing=True),
    Field("M", "series", "moments at those speeds", "N m", default=REQUIRED, expression=True),
))

_APPLIED = ("force", "moment")
LOAD = Section("load", "An external force at a point, a moment on a link, or a viscous damper on a pair.", (
    _name("the load's name", "load <n>"),
    Field("kind", "string", "what the load is", default="force", choices=("force", "moment", "damper")),
    Field("link", "link", "the loaded link (not the frame)", default=REQUIRED, minimum=1, when=("kind", _APPLIED),
          rule="loads on the frame do not enter the analysis"),
    Field("point", "point", "force: its point of application", when=("kind", _APPLIED),
          required_when=("kind", ("force",))),
    Field("direction", "load_direction", "force: world direction or \"against_velocity\"; moment: \"against_omega\"",
          expression=True, when=("kind", _APPLIED), required_when=("kind", ("force",))),
    _num("value", "constant value: N, or N m about +z (or table, characteristic)", "N or N m", when=("kind", _APPLIED)),
    Field("table", "table", "a load diagram (or value)", section=LOAD_TABLE, when=("kind", _APPLIED)),
    Field("characteristic", "characteristic", "moment: M(omega) of the link, a table or an expression of omega",
          section=CHARACTERISTIC, when=("kind", ("moment",))),
    Field("pair", "links", "damper: the links of a pair (either order)", default=REQUIRED, when=("kind", ("damper",))),
    _num("c", "damper coefficient: N m s/rad (R) or N s/m (P)", "N m s/rad or N s/m", default=REQUIRED, minimum=0.0,
         when=("kind", ("damper",))),
), array=True, one_of=(OneOf(("value", "table", "characteristic"), when=("kind", _APPLIED)),))

SPRING_END = Section("spring.a", "An end of a spring: a point of a link.", (
    Field("link", "link", "the link", default=REQUIRED),
    Field("point", "point", "its point", default=REQUIRED),
))

SPRING = Section("spring", "A linear spring between two points; force = stiffness * (length - free_length).", (
    _name("the spring's name", "spring <n>"),
    Field("a", "table", "one end", default=REQUIRED, section=SPRING_END),
    Field("b", "table", "the other end", default=REQUIRED, section=SPRING_END),
    _num("stiffness", "stiffness", "N/m", default=REQUIRED, minimum=0.0),
    _num("free_length", "free length", "m", default=REQUIRED, minimum=0.0),
), array=True)

FRICTION = Section("friction", "Friction in the pairs (TMM course text on friction).", (
    _num("f", "reduced friction coefficient", default=REQUIRED, minimum=0.0),
    _num("radius", "default journal radius of revolute pairs", "m", positive=True),
    Field("method", "string", "analyze's default: 'first' (the first approximation: frictionless reactions) or "
          "'reactions' (friction in the reactions, solved exactly)", default="first", choices=("first", "reactions")),
))

FLYWHEEL = Section("flywheel", "A flywheel on the crank shaft, its centre on the crank's axis (kinetostat.law_of_motion).", (
    _num("J", "its moment of inertia", "kg m^2", minimum=0.0),
    _num("delta", "the coefficient of fluctuation (omega_max - omega_min) / omega_mean to size the smallest flywheel for",
         positive=True, exclusive_maximum=2.0, rule="must be > 0 and < 2 (omega_min = omega_mean (1 - delta/2) > 0)"),
), one_of=(OneOf(("J", "delta"), hint="a flywheel J in kg m^2, or delta to size it for"),))

_AT_POINT, _OF_LINK = ("velocity", "acceleration"), ("omega", "eps", "inertia_force", "inertia_moment")
PUBLISHED = Section("published", "A value the source prints for this model, checked by `kinetostat validate`.", (
    Field("symbol", "string", "as the source names it (unique in the file)", default=REQUIRED, one_line=True),
    Field("meaning", "string", "what it is, in this project's terms", default=""),
    Field("quantity", "string", "what it measures (a magnitude)", default=REQUIRED, choices=tuple(PUBLISHED_UNITS)),
    Field("point", "point", "velocity, acceleration: the point", default=REQUIRED, when=("quantity", _AT_POINT)),
    Field("relative_to", "point", "velocity, acceleration: minus this point's", when=("quantity", _AT_POINT)),
    Field("link", "link", "omega, eps, inertia_force, inertia_moment: the moving link", default=REQUIRED, minimum=1,
          when=("quantity", _OF_LINK), rule="unknown moving link {value}: expected a link >= {minimum}"),
    Field("pair", "links", "reaction: R(i, j), force of link i on link j", default=REQUIRED,
          when=("quantity", ("reaction",))),
    Field("angle", "angles", "crank angle, or a list of them with reduce", "deg", default=REQUIRED, expression=True,
          max_length=MAX_PUBLISHED_ANGLES),
    Field("reduce", "string", "over a list of angles: min, max, or the angle of the max", choices=("min", "max", "angle_of_max")),
    _num("value", "the published number, in unit", default=REQUIRED),
    Field("unit", "string", "if given, the quantity's unit (deg for angle_of_max)"),
    _num("tolerance", "accepted |exact - value| / |value| (not with angle_of_max)", positive=True),
    _num("tolerance_deg", "angle_of_max: accepted |difference|", "deg", positive=True),
    Field("source", "string", "where the number is printed", default=REQUIRED),
    Field("accuracy", "string", "why the tolerance is what it is", default=""),
), array=True)

STUDY = Section("study", "A parameter study: the largest |R(i,j)| over the cycle for every combination of values.", (
    Field("title", "string", "the study's title", default="parameter study", one_line=True),
    Field("vary", "map", "one or two parameters and their values (first: rows, second: columns)", default=REQUIRED,
          items="numbers", max_length=2),
    Field("pair", "links", "R(i, j) tabulated: force of link i on link j", default=REQUIRED),
    Field("steps", "integer", "crank angles per cycle, equally spaced from 0", default=36, minimum=1, maximum=3600),
))

LETTERING = Section("lettering", "The names the model's source text uses, on every output.", (
    Field("language", "string", "the text's language: outputs are written in it by default", choices=LANGUAGES),
    Field("frame", "integer", "the frame's number in the text (no moving link's)", default=0, minimum=0, maximum=99,
          rule="expected the frame's number {minimum}..{maximum}"),
    Field("M_bal", "string", "the balancing moment's symbol", default="M_bal", **_SYMBOL),
    Field("F_bal", "string", "the balancing force's symbol", default="F_bal", **_SYMBOL),
    Field("loads", "map", "a load's symbol by its [[load]] name", items="string", printable=True),
    Field("name", "map", "the mechanism's name by language", items="string", printable=True, choices=LANGUAGES,
          rule="no such language"),
))

MODEL = Section("<top level>", "A kinetostat mechanism model: one planar linkage with one degree of freedom, SI units.", (
    Field("mechanism", "table", MECHANISM.doc, default=REQUIRED, section=MECHANISM),
    Field("parameters", "map", "named numbers and expressions that any numeric field may read",
          items="number", max_length=MAX_PARAMETERS),
    Field("drive", "table", DRIVE.doc, default=REQUIRED, section=DRIVE),
    Field("frame", "points", "link 0: its points in world coordinates", "m", default=REQUIRED, expression=True,
          max_length=MAX_POINTS, one_line=True),
    Field("link", "tables", LINK.doc, default=REQUIRED, section=LINK),
    Field("pair", "tables", PAIR.doc, section=PAIR),
    Field("group", "tables", GROUP.doc, section=GROUP),
    Field("load", "tables", LOAD.doc, section=LOAD),
    Field("spring", "tables", SPRING.doc, section=SPRING),
    Field("friction", "table", FRICTION.doc, section=FRICTION),
    Field("flywheel", "table", FLYWHEEL.doc, section=FLYWHEEL),
    Field("published", "tables", PUBLISHED.doc, section=PUBLISHED),
    Field("study", "table", STUDY.doc, section=STUDY),
    Field("lettering", "table", LETTERING.doc, section=LETTERING),
))


def sections(root: Section = MODEL) -> list[Section]:
    """`root` and every table nested in it, in the order of the file format (each once)."""
    out: list[Section] = [root]
    for f in root.fields:
        if f.section is not None and f.section not in out:
            out += [s for s in sections(f.section) if s not in out]
    return out


#: Every table by its name (`SECTIONS["drive.gear"]`).
SECTIONS: Mapping[str, Section] = {s.name: s for s in sections()}
