"""The schema of the model format (`schema`) told to people and to editors: the JSON Schema
(draft-07, which Even Better TOML / taplo reads) shipped as `model.schema.json`, and the field
tables of models/FORMAT.md. Both are generated from the one table; tests fail when they are stale.

    python -m kinetostat.model.describe              # print the JSON Schema
    python -m kinetostat.model.describe --write      # rewrite model.schema.json and FORMAT.md's tables

May use: the standard library, limits, schema.
"""
from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import Any, TextIO

from .limits import MAX_STUDY_VALUES, MAX_TABLE_POINTS, MAX_VALUE
from .schema import MODEL, REQUIRED, Field, Section, sections

#: The JSON Schema shipped in the wheel (package data), as `json_schema()` writes it.
SCHEMA_FILE = Path(__file__).with_name("model.schema.json")
#: The file format's reference, whose field tables sit between these markers.
FORMAT_MD = Path(__file__).resolve().parents[2] / "models" / "FORMAT.md"
#: What an unknown key of a table must match: nothing. A schema, not `additionalProperties: false`,
#: so that a validator fails at the key's own path, not at the table's: taplo (Even Better TOML)
#: marks every key and value of a table for an error at the table (one misspelt key of a [[link]]
#: gave 19 errors; tamasfe/taplo#515), and the key's path alone for an error at the key.
UNKNOWN_KEY: dict[str, Any] = {"not": {}}
BEGIN, END = "<!-- fields: begin (generated from kinetostat/model/schema.py; do not edit) -->", "<!-- fields: end -->"

def json_schema() -> dict:
    """The JSON Schema (draft-07) of a model file read as TOML: every table and field, with its
    title and description (what editors show), type, range, default and allowed keys."""
    out = {"$schema": "http://json-schema.org/draft-07/schema#", "$id": "urn:kinetostat:model-format",
           "title": "kinetostat model", **_section(MODEL)}
    out["definitions"] = {s.name: _section(s) for s in sections()[1:]}
    return out


def _section(s: Section) -> dict:
    out: dict[str, Any] = {"type": "object", "description": _doc(s),
                           "properties": {f.name: _field(f) for f in s.fields}, "additionalProperties": UNKNOWN_KEY}
    required = [f.name for f in s.fields if f.default == REQUIRED and f.when is None]
    if required:
        out["required"] = required
    conditions = []
    for f in s.fields:
        if f.when is not None:
            conditions.append({"if": _holds(s, f.when), "else": {"properties": {f.name: False}},
                               **({"then": {"required": [f.name]}} if f.default == REQUIRED else {})})
        if f.required_when is not None:
            conditions.append({"if": _holds(s, f.required_when), "then": {"required": [f.name]}})
    for group in s.one_of:
        one = {"oneOf": [{"required": [name]} for name in group.fields]}
        conditions.append(one if group.when is None else {"if": _holds(s, group.when), "then": one})
    if conditions:
        out["allOf"] = conditions
    return out


def _holds(s: Section, when: tuple[str, tuple]) -> dict:
    """A JSON Schema that holds when the field `when[0]` of `s` has one of the values `when[1]`
    (its default counts when it is not given)."""
    key, values = when
    test: dict[str, Any] = {"properties": {key: {"enum": list(values)}}}
    if s[key].default not in values:
        test["required"] = [key]
    return test


def _doc(s: Section) -> str:
    """The table's line, with the groups of its fields of which exactly one is given."""
    return s.doc + "".join(f" Exactly one of {', '.join(g.fields)}" + (
        f" (with {g.when[0]} = {' or '.join(g.when[1])})" if g.when else "") + "." for g in s.one_of)


def _number(f: Field, integer: bool = False) -> dict:
    """A number (an integer) within the field's range, or an expression if the field takes one:
    {"type": ["number", "string"], "minimum": ...} (minimum and maximum apply to numbers only),
    so that an editor names the bound a number breaks."""
    kind = "integer" if integer else "number"
    out: dict[str, Any] = {"type": [kind, "string"] if f.expression else kind}
    if f.choices:
        out["enum"] = list(f.choices)
    if f.positive:
        out["exclusiveMinimum"] = 0
    out["minimum"] = f.minimum if f.minimum is not None else -MAX_VALUE
    out["maximum"] = f.maximum if f.maximum is not None else MAX_VALUE
    if f.exclusive_maximum is not None:
        out["exclusiveMaximum"] = f.exclusive_maximum
    return out


def _field(f: Field) -> dict:
    number = {"type": ["number", "string"], "minimum": -MAX_VALUE, "maximum": MAX_VALUE}
    vector = {"type": "array", "items": number, "minItems": 2, "maxItems": 2}
    link = {"type": "integer", "minimum": f.minimum or 0}
    if f.maximum is not None:
        link["maximum"] = f.maximum
    kinds: dict[str, Any] = {
        "number": lambda: _number(f), "integer": lambda: _number(f, integer=True),
        "string": lambda: {"type": "string", **({"enum": list(f.choices)} if f.choices else {}),
                           **({"minLength": f.min_length} if f.min_length else {}),
                           **({"maxLength": f.max_length} if f.max_length else {})},
        "strings": lambda: {"type": "array", "items": {"type": "string"}},
        "vector": lambda: vector, "direction": lambda: vector,
        "series": lambda: {"type": "array", "items": _number(f), "minItems": 2, "maxItems": MAX_TABLE_POINTS},
        "points": lambda: {"type": "object", "additionalProperties": vector, "minProperties": 1,
                           "maxProperties": f.max_length},
        "point": lambda: {"type": "string"},
        "link": lambda: link,
        "links": lambda: {"type": "array", "items": {"type": "integer", "minimum": 0}, "minItems": 2, "maxItems": 2,
                          "uniqueItems": True},
        # one schema of several types rather than anyOf: each keyword applies to its own type
        # (minimum to numbers, items to arrays, pattern to strings), and an editor names it
        "angles": lambda: {**number, "type": ["number", "string", "array"], "items": number, "minItems": 1,
                           "maxItems": f.max_length},
        "com": lambda: {**vector, "type": ["string", "array"]},
        "load_direction": lambda: {**vector, "type": ["array", "string"],
                                   "pattern": "^(against_velocity|against_omega)$"},
        "characteristic": lambda: {"anyOf": [_ref(f.section), {"type": "string", "description":
                                                                "an expression of omega (rad/s)"}]},
        "map": lambda: _map(f),
        "table": lambda: _ref(f.section),
        "tables": lambda: {"type": "array", "items": {"$ref": f"#/definitions/{f.section.name}"},
                           **({"minItems": f.min_length} if f.min_length else {})},
    }
    out = {"title": f.name + (f" ({f.unit})" if f.unit else ""), "description": _describe(f), **kinds[f.type]()}
    if f.default not in (None, REQUIRED) and not (isinstance(f.default, str) and "<" in f.default):
        out["default"] = list(f.default) if isinstance(f.default, tuple) else f.default
    return out


def _map(f: Field) -> dict:
    items = {"number": {"type": ["number", "string"]},
             "numbers": {"type": "array", "items": {"type": "number"}, "minItems": 1, "maxItems": MAX_STUDY_VALUES},
             "string": {"type": "string"}}[f.items]
    out: dict[str, Any] = {"type": "object", "additionalProperties": items}
    if f.choices:
        out["propertyNames"] = {"enum": list(f.choices)}
    if f.max_length:
        out["maxProperties"] = f.max_length
    if f.default == REQUIRED:
        out["minProperties"] = 1
    return out


def _ref(s: Section | None) -> dict:
    """The section's definition, referred to (inside allOf: a $ref's siblings, the field's title
    and description, would be ignored in draft-07)."""
    assert s is not None
    return {"allOf": [{"$ref": f"#/definitions/{s.name}"}]}


def _describe(f: Field, unit: bool = True) -> str:
    """The field's description as an editor shows it: its line, its unit, when it is allowed."""
    out = f.doc[0].upper() + f.doc[1:].removesuffix(".")
    if f.unit and unit:
        out += f"; {f.unit}"
    if f.when is not None:
        out += f" (only with {f.when[0]} = {' or '.join(map(str, f.when[1]))})"
    if f.default == REQUIRED:
        out += ". Required"
    if f.required_when is not None:
        out += f". Required with {f.required_when[0]} = {' or '.join(map(str, f.required_when[1]))}"
    return out + "."


# ----------------------------------------------------------------------------- models/FORMAT.md

_TYPES = {"number": "number", "integer": "integer", "string": "string", "strings": "list of strings",
          "vector": "[x, y]", "direction": "[x, y], nonzero", "series": f"list of 2..{MAX_TABLE_POINTS} numbers",
          "points": "table of name = [x, y]", "point": "point name", "link": "link id", "links": "[i, j]",
          "angles": "number or list", "com": "point name or [x, y]",
          "load_direction": "[x, y] or string", "characteristic": "table or expression", "map": "table of names",
          "table": "table", "tables": "array of tables"}


def field_tables() -> str:
    """The field tables of models/FORMAT.md (Markdown), one per table of the format."""
    out = []
    for s in sections():
        head = "Top level" if s is MODEL else (f"`[[{s.name}]]`" if s.array else f"`[{s.name}]`")
        out += [f"### {head}", "", _doc(s).replace("|", "\\|"), "", "| field | type | unit | range | default | expression | description |",
                "|---|---|---|---|---|---|---|"]
        for f in s.fields:
            kind = _TYPES[f.type] + (": " + ", ".join(f"`{json.dumps(c)}`" for c in f.choices) if f.choices else "")
            default = "required" if f.default == REQUIRED else "" if f.default is None else (
                f"`{list(f.default)}`" if isinstance(f.default, tuple) else f"`{json.dumps(f.default, ensure_ascii=False)}`")
            doc = _describe(f, unit=False).removesuffix(". Required.").removesuffix(".")
            cells = (f"`{f.name}`", kind, f.unit, _range(f), default, "yes" if f.expression else "", doc)
            out.append("| " + " | ".join(c.replace("|", "\\|") for c in cells) + " |")
        out.append("")
    return "\n".join(out).rstrip() + "\n"


def _range(f: Field) -> str:
    """The field's range as FORMAT.md shows it ("> 0, < 45", "0..360, increasing", "1..16 printable characters")."""
    bounds = _bounds(f)
    return f"{bounds}, increasing" if f.increasing and bounds else "increasing" if f.increasing else bounds


def _bounds(f: Field) -> str:
    if f.type == "map" and f.printable:
        return "printable strings"
    if f.type == "tables" and f.min_length:
        return f"at least {f.min_length}"
    if f.min_length or f.printable:
        return f"{f.min_length}..{f.max_length} printable characters"
    low = "> 0" if f.positive else None if f.minimum is None else f">= {f.minimum:g}"
    high = None if f.exclusive_maximum is None else f"< {f.exclusive_maximum:g}"
    if f.minimum is not None and f.maximum is not None:
        return f"{f.minimum:g}" + (f"..{f.maximum:g}" if f.maximum != f.minimum else "")
    if f.maximum is not None:
        high = f"<= {f.maximum:g}"
    if low or high:
        return ", ".join(b for b in (low, high) if b)
    if f.max_length is not None:
        return f"at most {f.max_length}" + (" characters" if f.type == "string" else "") + (
            "" if not f.one_line else ", no control characters" if f.type == "string" else
            ", names without control characters")
    return "no control characters" if f.one_line else ""


def format_md(text: str) -> str:
    """`text` (models/FORMAT.md) with its field tables replaced by those of the schema."""
    head, _, rest = text.partition(BEGIN)
    _, _, tail = rest.partition(END)
    if not rest or not tail:
        raise ValueError(f"models/FORMAT.md has no markers {BEGIN} ... {END}")
    return f"{head}{BEGIN}\n{field_tables()}{END}{tail}"


def schema_text() -> str:
    """The JSON Schema as the shipped file holds it."""
    return json.dumps(json_schema(), indent=2, ensure_ascii=False) + "\n"


def print_schema(out: TextIO) -> int:
    """Write the JSON Schema of the model format to `out`; the exit code (0)."""
    out.write(schema_text())
    return 0


def main(argv: list[str] | None = None) -> int:
    args = sys.argv[1:] if argv is None else argv
    if args == ["--write"]:
        SCHEMA_FILE.write_text(schema_text(), encoding="utf-8")
        FORMAT_MD.write_text(format_md(FORMAT_MD.read_text(encoding="utf-8")), encoding="utf-8")
        return 0
    if args:
        print(__doc__.split("\n\n")[1], file=sys.stderr)
        return 2
    return print_schema(sys.stdout)


if __name__ == "__main__":
    sys.exit(main())
