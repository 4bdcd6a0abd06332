"""The model format's one schema (kinetostat/model/schema.py) and what is generated from it: the
JSON Schema shipped for editors and the field tables of models/FORMAT.md, both current; the
JSON Schema, run by an independent validator (fastjsonschema), accepts every bundled model and
refuses hostile files at the field the reader names."""
from __future__ import annotations

import dataclasses
import io
import json
import re
import shutil
import os
import subprocess
import sys
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


def test_reader_takes_its_keys_from_the_schema():
    """An unknown field's message lists the schema's fields (those its kind allows)."""
    with pytest.raises(ModelError) as e:
        kinetostat.loads(four_bar(("[[pair]]", "[[pair]]\ncolour = 1")))
    listed = re.search(r"pair\[0\]\.colour: unknown field\. Valid fields: (\[.*?\])", str(e.value))
    assert listed and eval(listed[1]) == sorted(schema.PAIR.keys(kind="R"))
    assert schema.PAIR.keys(kind="P") - schema.PAIR.keys(kind="R") == {"guide", "direction", "slider_axis"}


def _patch(monkeypatch, section: schema.Section, name: str, **change) -> None:
    """Edit one field of the table for this test (the reader and describe read the same Section)."""
    new = dataclasses.replace(section[name], **change)
    monkeypatch.setitem(section.__dict__, "fields", tuple(new if f.name == name else f for f in section.fields))
    monkeypatch.setitem(section.__dict__, "_by_name", {**section.__dict__["_by_name"], name: new})


LETTERING = "\n[lettering]\n"


@pytest.mark.parametrize("section, name, change, edit, message", [
    (schema.LINK, "mass", dict(minimum=1.0), {}, "link[id=1].mass: must be >= 1.0, got 0.8"),
    (schema.LINK, "I_S", dict(maximum=0.01), {}, "link[id=2].I_S: must be >= 0.0 and <= 0.01, got 0.016"),
    (schema.GROUP, "branch", dict(choices=(-1,)), {}, "group[0].branch: expected -1, got 1"),
    (schema.DRIVE, "link", dict(minimum=2, maximum=2), dict(edits=[("rpm = 300.0", "rpm = 300.0\nlink = 1")]),
     "drive.link: the crank must be link 2, got 1"),
    (schema.LINK, "id", dict(minimum=2), {}, "[[link]] #1.id: moving links are numbered from 2 (0 is the frame), got 1"),
    (schema.LOAD, "link", dict(maximum=2), {}, "load[0].link: loads on the frame do not enter the analysis, got 3"),
    (schema.LOAD_TABLE, "phi_deg", dict(maximum=180.0),
     dict(edits=[("value = -4.0", "table = { phi_deg = [0.0, 270.0], value = [1.0, 1.0] }")]),
     "load[0].table.phi_deg: angles must lie in [0, 180], got 270.0"),
    (schema.LETTERING, "M_bal", dict(max_length=4), dict(append=LETTERING + 'M_bal = "M_b12"'),
     "lettering.M_bal: expected a symbol of 1..4 printable characters, got 'M_b12'"),
    (schema.LETTERING, "name", dict(choices=("uk",)), dict(append=LETTERING + 'name = { en = "x" }'),
     "lettering.name.en: no such language. Valid: ['uk']"),
    (schema.LETTERING, "frame", dict(maximum=9), dict(append=LETTERING + "frame = 12"),
     "lettering.frame: expected the frame's number 0..9, got 12"),
    (schema.MECHANISM, "g", dict(maximum=9.8), {}, "mechanism.g: must be >= 0.0 and <= 9.8, got 9.81"),
])
def test_reader_takes_its_ranges_and_choices_from_the_schema(monkeypatch, validate, section, name, change, edit,
                                                            message):
    """Edit a field's range or choices in the table and the reader's verdict on the same model
    changes with it, and so does the JSON Schema's (the unedited one compiled once for the module)."""
    text = four_bar(*edit.get("edits", []), append=edit.get("append", ""))
    kinetostat.loads(text)
    validate(tomllib.loads(text))
    _patch(monkeypatch, section, name, **change)
    with pytest.raises(ModelError) as e:
        kinetostat.loads(text)
    assert e.value.problems == [message]
    with pytest.raises(fastjsonschema.JsonSchemaValueException):
        fastjsonschema.compile(describe.json_schema())(tomllib.loads(text))


def test_reader_takes_its_orders_and_groups_from_the_schema(monkeypatch):
    """A series the table calls increasing, and a group of which the table wants exactly one,
    are checked as the table says (the group by the JSON Schema too)."""
    text = four_bar(("value = -4.0", "table = { phi_deg = [0.0, 360.0], value = [2.0, 2.0] }"))
    kinetostat.loads(text)
    _patch(monkeypatch, schema.LOAD_TABLE, "value", increasing=True)
    with pytest.raises(ModelError) as e:
        kinetostat.loads(text)
    assert e.value.problems == ["load[0].table.value: the values must increase strictly, got 2.0 after 2.0"]
    monkeypatch.setitem(schema.DRIVE.__dict__, "one_of", (schema.OneOf(("rpm", "eps"), hint="a test"),))
    with pytest.raises(ModelError) as e:
        kinetostat.loads(four_bar())
    assert e.value.problems == ["drive: give exactly one of rpm or eps (a test)"]
    with pytest.raises(fastjsonschema.JsonSchemaValueException) as j:
        fastjsonschema.compile(describe.json_schema())(tomllib.loads(four_bar()))
    assert _reader_path(tomllib.loads(four_bar()), j.value) == "drive"


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
    named = re.search(r"must contain \['(\w+)'", exc.message)   # the missing field
    if named:
        out += "." + named[1] if out else named[1]
    if len(steps) == 1 and exc.rule == "not":    # the reader names an unknown key of the file's top level so
        out = "<top level>." + out
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


_SLIDER = ('kind = "R"\nlinks = [0, 3]\npoint = "C"', 'kind = "P"\nlinks = [0, 3]\npoint = "C"\nguide = "C"\ndirection = [1.0, 0.0]')
_FORCE = ('kind = "moment"\nlink = 3\nvalue = -4.0', 'kind = "force"\nlink = 3\npoint = "B"\ndirection = [0.0, -1.0]\nvalue = 10.0')
_PUBLISHED = '\n[[published]]\nsymbol = "x"\nangle = 30.0\nvalue = 1.0\ntolerance = 0.1\nsource = "s"\n'
_GEAR = ('kind = "engine"', 'kind = "machine"\n[drive.gear]\nmodule = 0.005\nz_pinion = 20\nz_wheel = 60\n'
                            'centre_direction = [1.0, 0.0]')


@pytest.mark.parametrize("edits, append, where", [
    ([_SLIDER, ('guide = "C"\n', "")], "", "pair[3].guide"),
    ([_SLIDER, ("direction = [1.0, 0.0]\n", "")], "", "pair[3].direction"),
    ([_FORCE, ('link = 3\npoint = "B"\n', "link = 3\n")], "", "load[0].point"),
    ([_FORCE, ("direction = [0.0, -1.0]\n", "")], "", "load[0].direction"),
    ([_FORCE, ("value = 10.0", "")], "", "load[0]"),
    ([], _PUBLISHED + 'quantity = "velocity"\n', "published[0].point"),
    ([], _PUBLISHED + 'quantity = "omega"\n', "published[0].link"),
    ([], _PUBLISHED + 'quantity = "reaction"\n', "published[0].pair"),
    ([("rpm = 300.0", "")], "", "drive"),
    ([("rpm = 300.0", "rpm = 300.0\nomega = 31.4")], "", "drive"),
    ([("rpm = 300.0\neps = 0.0", 'omega_table = { phi_deg = [0.0, 120.0, 240.0] }')], "", "drive.omega_table"),
    ([_GEAR, ("[drive.gear]", "[gear]")], "", "drive.gear"),
    ([("kind = \"engine\"", _GEAR[1].replace("machine", "engine"))], "", "drive.gear"),
], ids=["P-guide", "P-direction", "force-point", "force-direction", "force-value", "velocity-point",
        "omega-link", "reaction-pair", "no-speed", "two-speeds", "omega-table-no-speed", "machine-gear",
        "engine-gear"])
def test_json_schema_requires_what_the_reader_requires_by_kind(edits, append, where, validate):
    """A field required only for some kinds (or one of a group) is required by the JSON Schema
    too: a hand-made file that lacks it is refused by both, at the field (or table) the reader names."""
    good = four_bar(*[e for e in edits if e in (_SLIDER, _FORCE, _GEAR)])
    validate(tomllib.loads(good))
    text = four_bar(*edits, append=append)
    data = tomllib.loads(text)
    with pytest.raises(fastjsonschema.JsonSchemaValueException) as e:
        validate(data)
    assert _reader_path(data, e.value) == where, e.value.message
    with pytest.raises(ModelError) as reader:
        kinetostat.loads(text)
    assert any(m.startswith(where + ":") or m.startswith(where + ".") for m in reader.value.problems), reader.value.problems


def _numbers(node, path=""):
    """(path, schema) of every schema in `node` that admits a number."""
    if isinstance(node, dict):
        kind = node.get("type")
        if kind in ("number", "integer") or isinstance(kind, list) and {"number", "integer"} & set(kind):
            yield path, node
        for k, v in node.items():
            yield from _numbers(v, f"{path}/{k}")
    elif isinstance(node, list):
        for n, v in enumerate(node):
            yield from _numbers(v, f"{path}/{n}")


def test_an_out_of_range_number_is_told_its_bound(validate):
    """A number that may be an expression is {"type": ["number", "string"], "minimum": ...}, not an
    anyOf of the two (which editors report as "not valid under any of the schemas listed in the
    'anyOf' keyword"): the validator names the bound the number breaks."""
    numbers = dict(_numbers(describe.json_schema()))
    assert numbers and not [p for p, n in numbers.items() if "anyOf" in n]
    g = describe.json_schema()["definitions"]["mechanism"]["properties"]["g"]
    assert g["type"] == ["number", "string"] and g["minimum"] == 0.0
    with pytest.raises(fastjsonschema.JsonSchemaValueException) as e:
        validate(tomllib.loads(four_bar(("g = 9.81", "g = -9.81"))))
    assert e.value.message == "data.mechanism.g must be bigger than or equal to 0.0"
    validate(tomllib.loads(four_bar(("g = 9.81", 'g = "9.81 * 1"'))))       # an expression is a string


@pytest.mark.parametrize("edit, where", [(("branch = 1", "branch = 1.5"), "group[0].branch"),
                                         (("id = 3", "id = 3.5"), "link[2].id"),
                                         (("branch = 1", "branch = 1.0"), None), (("id = 3", "id = 3.0"), None)])
def test_an_integer_field_is_an_integer(edit, where, validate):
    """Where the reader requires an integer the JSON Schema says "type": "integer" and refuses
    1.5. It cannot refuse 1.0: JSON Schema draft-07 (and fastjsonschema with it) counts a number
    with a zero fraction as an integer, and a TOML reader hands both as the same JSON number; the
    reader refuses it ("write it without a decimal point")."""
    props = describe.json_schema()["definitions"]
    assert props["group"]["properties"]["branch"]["type"] == props["link"]["properties"]["id"]["type"] == "integer"
    text = four_bar(edit)
    if where is None:
        validate(tomllib.loads(text))
    else:
        with pytest.raises(fastjsonschema.JsonSchemaValueException) as e:
            validate(tomllib.loads(text))
        assert e.value.message == f"data.{where} must be integer"
    with pytest.raises(ModelError, match="expected"):
        kinetostat.loads(text)


#: One misspelt key per table: (text edit of the four-bar, the key's path as fastjsonschema writes it).
MISSPELT = [
    (('[[link]]\nid = 1', '[[link]]\nid = 1\nmasss = 1.0'), "data.link[0].masss"),
    (('[drive]', '[drive]\nrmp = 60.0'), "data.drive.rmp"),
    (('[mechanism]', '[linkk]\nid = 9\n\n[mechanism]'), "data.linkk"),
]


@pytest.mark.parametrize("edit, where", MISSPELT, ids=["link", "drive", "top_level"])
def test_an_unknown_key_fails_at_the_key_not_at_its_table(edit, where, validate):
    """An editor marks where the validator's error sits: at the key, not at the whole table (taplo
    marked every key and value of the [[link]] table, 19 errors for one key, for an error at the table)."""
    with pytest.raises(fastjsonschema.JsonSchemaValueException) as e:
        validate(tomllib.loads(four_bar(edit)))
    assert e.value.name == where and e.value.rule == "not"


def test_no_table_of_the_json_schema_refuses_unknown_keys_as_a_whole():
    """No `additionalProperties: false` anywhere: every table's unknown keys fail one by one, at their own path."""
    def objects(node):
        if isinstance(node, dict):
            yield node
            for v in node.values():
                yield from objects(v)
        elif isinstance(node, list):
            for v in node:
                yield from objects(v)
    tables = [o for o in objects(describe.json_schema()) if "properties" in o and o.get("type") == "object"]
    assert len(tables) >= 10 and all(o["additionalProperties"] == describe.UNKNOWN_KEY for o in tables)
    assert not any(o.get("additionalProperties") is False for o in objects(describe.json_schema()))


#: taplo (the TOML editors' validator; the test extra installs it beside this interpreter), or None.
TAPLO = shutil.which("taplo", path=os.pathsep.join([str(Path(sys.executable).parent), os.environ.get("PATH", "")]))


@pytest.mark.skipif(TAPLO is None, reason="taplo (pip install taplo) not beside this Python nor on PATH")
def test_taplo_reports_one_misspelt_key_once(tmp_path):
    """The editors' validator itself: one error, on the key's line."""
    model = tmp_path / "m.toml"
    model.write_text(four_bar(MISSPELT[0][0]), encoding="utf-8")
    r = subprocess.run([TAPLO, "check", "--schema", describe.SCHEMA_FILE.as_uri(), str(model)],
                       capture_output=True, text=True, timeout=60)
    errors = [line for line in (r.stdout + r.stderr).splitlines() if line.startswith("error")]
    assert r.returncode != 0 and len(errors) == 1, r.stdout + r.stderr
    line = four_bar(MISSPELT[0][0]).splitlines().index("masss = 1.0") + 1
    assert f"m.toml:{line}:" in r.stdout + r.stderr
