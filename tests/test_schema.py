"""The model format's one schema (kinetostat/model/schema.py) and what is generated from it: the
JSON Schema shipped for editors and the field tables of models/FORMAT.md, both current; the
JSON Schema, run by an independent validator (fastjsonschema), accepts every bundled model and
refuses hostile files at the field the reader names."""
from __future__ import annotations

import io
import json
import re
import tomllib
from pathlib import Path

import pytest

import kinetostat
from kinetostat import ModelError
from kinetostat.model import describe, schema
from conftest import MODELS, ROOT, four_bar

fastjsonschema = pytest.importorskip("fastjsonschema")
HOSTILE = ROOT / "tests" / "hostile"


@pytest.fixture(scope="module")
def validate():
    return fastjsonschema.compile(describe.json_schema())


def test_shipped_schema_is_current():
    """model.schema.json is what the schema gives (regenerate: python -m kinetostat.model.describe --write)."""
    assert describe.SCHEMA_FILE.read_text(encoding="utf-8") == describe.schema_text()
    out = io.StringIO()
    assert describe.print_schema(out) == 0 and json.loads(out.getvalue()) == describe.json_schema()


def test_format_md_field_tables_are_current():
    """The field tables of models/FORMAT.md are the schema's (regenerate as above)."""
    text = (ROOT / "models" / "FORMAT.md").read_text(encoding="utf-8")
    assert describe.format_md(text) == text
    for s in schema.sections():          # every table and field is in the reference
        assert all(f"| `{f.name}` |" in describe.field_tables() for f in s.fields)


def test_reader_takes_its_keys_and_ranges_from_the_schema():
    """An unknown field's message lists the schema's fields; a range is the schema's."""
    with pytest.raises(ModelError) as e:
        kinetostat.loads(four_bar(("[[pair]]", "[[pair]]\ncolour = 1")))
    listed = re.search(r"pair\[0\]\.colour: unknown field\. Valid fields: (\[.*?\])", str(e.value))
    assert listed and eval(listed[1]) == sorted(schema.PAIR.keys(kind="R"))
    assert schema.PAIR.keys(kind="P") - schema.PAIR.keys(kind="R") == {"guide", "direction", "slider_axis"}
    assert schema.LINK["mass"].minimum == 0.0 and schema.GEAR["module"].positive


@pytest.mark.parametrize("path", MODELS, ids=lambda p: p.stem)
def test_json_schema_accepts_every_bundled_model(path: Path, validate):
    validate(tomllib.loads(path.read_text(encoding="utf-8")))


#: Hostile files the JSON Schema refuses alone (no cross-field check needed).
REFUSED = ["drive_link_not_crank", "empty_file", "extra_drive_field", "extra_link_field", "extra_pair_guide_on_R",
           "extra_top_level", "gear_too_few_teeth", "huge_mass", "inf_rpm", "load_on_frame", "missing_drive",
           "missing_g", "missing_pair_kind", "negative_g", "negative_inertia", "negative_mass", "negative_spring",
           "rpm_negative", "type_branch_bool", "type_link_not_array", "type_links_string", "type_point_string",
           "type_point_three_coords", "type_points_array", "type_sense_invalid", "typo_link_field", "typo_value"]


@pytest.mark.parametrize("name", REFUSED)
def test_json_schema_refuses_hostile_files_where_the_reader_does(name: str, validate):
    """The JSON Schema's first error names a field the reader's message names (link tables by id)."""
    path = HOSTILE / f"{name}.toml"
    data = tomllib.loads(path.read_text(encoding="utf-8"))
    with pytest.raises(fastjsonschema.JsonSchemaValueException) as e:
        validate(data)
    where = _reader_path(data, e.value)
    with pytest.raises(ModelError) as reader:
        kinetostat.load(path)
    paths = [m.partition(": ")[0] for m in reader.value.problems]
    assert any(p == where or p.startswith(where + ".") or p.startswith(where + "[") for p in paths), (where, paths)


def _reader_path(data: dict, exc) -> str:
    """The field path of a fastjsonschema error as the reader writes it: `link[id=2].mass`."""
    steps, node, out = exc.path[1:], data, ""
    for i, step in enumerate(steps):
        if isinstance(node, list):
            n = int(step)
            link_id = node[n].get("id") if steps[i - 1] == "link" and isinstance(node[n], dict) else None
            out += f"[id={link_id}]" if isinstance(link_id, int) else f"[{n}]"
            node = node[n]
        else:
            out += ("." if out else "") + step
            node = node[step]
    named = re.search(r"must (?:not )?contain [\[{]'(\w+)'", exc.message)   # the missing or unknown field
    if named:       # the reader names an unknown key of the file's top level so
        out += "." + named[1] if out else ("<top level>." if "not" in exc.message else "") + named[1]
    return out.replace(".[", "[")


def test_cli_schema_prints_the_shipped_schema(cli):
    r = cli("schema")
    assert r.returncode == 0 and r.stderr == "" and r.stdout == describe.SCHEMA_FILE.read_text(encoding="utf-8")
    assert "model file format" in cli("schema", "--help").stdout


def test_a_spring_end_refuses_an_unknown_key(validate):
    """A spring's end { link, point } is a table of the schema like any other: a near miss is
    named, by the reader and by the JSON Schema (before, the reader ignored it)."""
    text = four_bar(append='\n[[spring]]\na = { link = 0, point = "O" }\nb = { link = 2, ponit = "B" }\n'
                           'stiffness = 500.0\nfree_length = 0.1\n')
    with pytest.raises(ModelError) as e:
        kinetostat.loads(text)
    assert e.value.problems == ["spring[0].b.ponit: unknown field (did you mean 'point'?). Valid fields: ['link', 'point']"]
    with pytest.raises(fastjsonschema.JsonSchemaValueException) as j:
        validate(tomllib.loads(text))
    assert _reader_path(tomllib.loads(text), j.value) in ("spring[0].b.ponit", "spring[0].b.point")


def test_a_missing_point_name_is_missing_and_not_reported_after_its_misspelling():
    """A point name not given reads "missing", and not at all after the misspelt key it follows
    from (before: "link 1 has no point None" beside the unknown field)."""
    with pytest.raises(ModelError) as e:
        kinetostat.loads(four_bar(('point = "A"', 'pont = "A"')))
    assert [p.partition(":")[0] for p in e.value.problems] == ["drive.pont"]
    with pytest.raises(ModelError) as e:
        kinetostat.loads(four_bar(('point = "A"\n', '')))
    assert "drive.point: missing (a point of link 1 is required). Valid names: ['A', 'O', 'S1']" in e.value.problems
