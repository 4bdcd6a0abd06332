"""The house's imports against its map: no module of the package or of the harness imports,
directly or through others, a module that imports it back (module-level and function-level
imports alike, relative and absolute, type-checking ones too, and the `__init__` of every package
above an imported module, which the import runs), and no room imports a room of a higher layer
or one its line in the documentation's "How it works" (docs/explanation/how-it-works.md) does not
name, nor does its line name a room it does not import. The layers and the rooms are read from
that page (one source of truth), so the map stays true."""
from __future__ import annotations

import ast
import functools
import re
from pathlib import Path

import pytest

from conftest import ROOT

PACKAGES = {"kinetostat": ROOT / "kinetostat", "kinetostat_validation": ROOT / "validation"}
HOW_IT_WORKS = (ROOT / "docs" / "explanation" / "how-it-works.md").read_text(encoding="utf-8")
HARNESS_USERS = {"report", "cli"}        # the only rooms that may import the harness (How it works)


def _modules() -> dict[str, tuple[Path, bool]]:
    """Every module of the package and of the harness: dotted name -> (file, is a package)."""
    mods = {}
    for top, folder in PACKAGES.items():
        for path in sorted(folder.rglob("*.py")):
            parts = [top, *path.relative_to(folder).with_suffix("").parts]
            package = parts[-1] == "__init__"
            mods[".".join(parts[:-1] if package else parts)] = (path, package)
    return mods


MODULES = _modules()


@functools.lru_cache(maxsize=None)
def _tree(path: Path) -> ast.Module:
    """The parsed source of `path`, parsed once for all the tests here."""
    return ast.parse(path.read_text(encoding="utf-8"))


def _target(name: str) -> str | None:
    """The module that an imported dotted name lives in (a name imported from a module: that module)."""
    while name and name not in MODULES:
        name = name.rpartition(".")[0]
    return name or None


def _imports(module: str) -> dict[str, int]:
    """The modules `module` imports anywhere in its source (-> the line of the first import)."""
    path, package = MODULES[module]
    here = module if package else module.rpartition(".")[0]
    out: dict[str, int] = {}
    for node in ast.walk(_tree(path)):
        if isinstance(node, ast.Import):
            names = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = here.split(".")[: len(here.split(".")) - node.level + 1]
                origin = ".".join(base + ([node.module] if node.module else []))
            else:
                origin = node.module or ""
            names = [f"{origin}.{a.name}" if f"{origin}.{a.name}" in MODULES else origin for a in node.names]
        else:
            continue
        for name in names:
            target = _target(name)
            if target and target != module:
                out.setdefault(target, node.lineno)
    return out


def _with_parents(module: str, imports: dict[str, int]) -> dict[str, int]:
    """`imports` and the packages above each imported module, whose `__init__` the import runs
    first (importing kinetostat.model.limits runs kinetostat/model/__init__.py), except the
    packages `module` itself stands in, which are already being imported when it runs."""
    out = dict(imports)
    for target, line in imports.items():
        parts = target.split(".")
        for n in range(1, len(parts)):
            parent = ".".join(parts[:n])
            if parent in MODULES and MODULES[parent][1] and not module.startswith(parent + ".") and parent != module:
                out.setdefault(parent, line)
    return out


#: Each module's imports (`_imports`, `_with_parents`), filled by `_graph` when this file's first
#: test runs (not at collection, which every test worker does).
GRAPH: dict[str, dict[str, int]] = {}


@pytest.fixture(scope="module", autouse=True)
def _graph() -> None:
    GRAPH.update({m: _with_parents(m, _imports(m)) for m in MODULES})


def _cycle() -> list[str] | None:
    """One import circle of GRAPH (its modules in order, the first repeated at the end), or None."""
    state: dict[str, int] = {}            # 1 on the current path, 2 done
    path: list[str] = []

    def visit(m: str) -> list[str] | None:
        state[m] = 1
        path.append(m)
        for t in sorted(GRAPH[m]):
            if state.get(t) == 1:
                return path[path.index(t):] + [t]
            if t not in state and (found := visit(t)):
                return found
        path.pop()
        state[m] = 2
        return None
    for m in sorted(GRAPH):
        if m not in state and (found := visit(m)):
            return found
    return None


def _room(module: str) -> str:
    """How it works' name of the room a package module belongs to: `plans` for kinetostat.plans.draw,
    `__init__` for the package itself."""
    parts = module.split(".")
    return "__init__" if len(parts) == 1 else parts[1]


def _layers() -> dict[str, int]:
    """room -> its layer (0 the lowest), from How it works' picture of the layers."""
    block = re.search(r"<!-- layers:.*?-->\n```text\n(.*?)\n```", HOW_IT_WORKS, flags=re.S)
    assert block, "How it works: the picture of the layers (<!-- layers: ... --> and a text block) is missing"
    rows = block.group(1).splitlines()[::-1]
    layer = {}
    for n, row in enumerate(rows):
        rooms = re.split(r"\s{2,}", row.strip())[1]
        for room in rooms.split(", "):
            assert room not in layer, f"How it works: room {room} stands in two layers"
            layer[room] = n
    return layer


def _uses() -> dict[str, set[str]]:
    """room -> the rooms its line in How it works' list says it uses."""
    out = {}
    for name, text in re.findall(r"^- `([\w]+)/?` — (.*?)(?=^- `|^\n)", HOW_IT_WORKS, flags=re.S | re.M):
        said = re.search(r"Uses: (.*?)\.\s*$", " ".join(text.split()))
        if said:
            out[name] = set() if said.group(1) == "none" else set(said.group(1).split(", "))
    return out


LAYERS = _layers()
USES = _uses()
PACKAGE_MODULES = sorted(m for m in MODULES if m.split(".")[0] == "kinetostat")


def test_no_import_circles():
    cycle = _cycle()
    assert cycle is None, "import circle: " + " -> ".join(
        f"{a} (line {GRAPH[a][b]})" for a, b in zip(cycle, cycle[1:])) + f" -> {cycle[-1]}"


def test_the_walk_sees_relative_absolute_and_deferred_imports():
    # the circles this test was written against, each kind of import once: they must be seen
    assert "kinetostat.program" in GRAPH["kinetostat.kinematics"]              # from .program import
    assert "kinetostat.solve" in GRAPH["kinetostat.plans.solution"]            # inside a function, ..solve
    assert "kinetostat.plans.worksheet" in GRAPH["kinetostat.cli.analyze"]     # deferred, ..plans.worksheet
    assert "kinetostat.units" in GRAPH["kinetostat.report.writer"]             # from .. import units
    assert "kinetostat.analysis" in GRAPH["kinetostat_validation.stability"]   # absolute
    GRAPH["kinetostat.analysis"]["kinetostat.solve"] = 0                       # a circle, made up
    try:
        cycle = _cycle()
        assert cycle[0] == cycle[-1] and set(cycle) == {"kinetostat.analysis", "kinetostat.solve"}
    finally:
        del GRAPH["kinetostat.analysis"]["kinetostat.solve"]


def test_the_walk_sees_a_circle_through_a_package_init():
    """structure -> model/__init__ -> mechanism -> structure: importing any module of `model`
    from structure runs model/__init__, which imports mechanism, which imports structure."""
    planted = _with_parents("kinetostat.structure", {"kinetostat.model.limits": 0})
    assert set(planted) == {"kinetostat.model.limits", "kinetostat.model"}
    assert "kinetostat.model" not in _with_parents("kinetostat.model.core", {"kinetostat.model.limits": 0})
    saved = GRAPH["kinetostat.structure"]
    GRAPH["kinetostat.structure"] = {**saved, **planted}
    try:
        cycle = _cycle()
        assert cycle is not None and {"kinetostat.structure", "kinetostat.model",
                                      "kinetostat.model.mechanism"} <= set(cycle), cycle
    finally:
        GRAPH["kinetostat.structure"] = saved


def _used() -> dict[str, set[str]]:
    """room -> the other rooms of the package its modules import."""
    out: dict[str, set[str]] = {_room(m): set() for m in PACKAGE_MODULES}
    for m in PACKAGE_MODULES:
        out[_room(m)] |= {_room(t) for t in GRAPH[m] if t.split(".")[0] == "kinetostat"} - {_room(m)}
    return out


def test_a_rooms_line_names_only_rooms_it_uses():
    """The other direction of the map: a room its line in How it works names under "Uses:" is imported."""
    used = _used()
    stale = {room: sorted(said - used[room]) for room, said in USES.items() if said - used[room]}
    assert not stale, f"How it works' 'Uses:' names rooms the code does not import: {stale}"
    USES["tables"] = USES["tables"] | {"plans"}       # a stale entry, made up: it must be seen
    try:
        assert {room for room, said in USES.items() if said - used[room]} == {"tables"}
    finally:
        USES["tables"] = USES["tables"] - {"plans"}


@pytest.mark.parametrize("module", PACKAGE_MODULES)
def test_a_room_uses_only_its_layer_and_those_below_and_what_its_line_names(module):
    room = _room(module)
    assert room in LAYERS, f"{module}: room {room} is on no layer of the picture in How it works"
    assert room in USES, f"{module}: room {room} has no line with 'Uses: ...' in the list of How it works"
    for target, line in GRAPH[module].items():
        if target.split(".")[0] != "kinetostat":
            assert room in HARNESS_USERS, f"{module}, line {line}: imports the harness {target}"
            continue
        other = _room(target)
        if other == room:
            continue
        assert LAYERS[other] <= LAYERS[room], (f"{module}, line {line}: imports {target}, of the layer above "
                                               f"(How it works: {other} stands above {room})")
        assert other in USES[room], f"{module}, line {line}: imports {target}; the line of {room} in How it works does not name {other}"


def test_the_map_names_only_rooms_that_exist():
    rooms = {_room(m) for m in PACKAGE_MODULES}
    assert set(LAYERS) == rooms, (set(LAYERS) - rooms, rooms - set(LAYERS))
    assert set(USES) == rooms, (set(USES) - rooms, rooms - set(USES))
    assert all(used <= rooms for used in USES.values())


def test_the_model_package_keeps_the_names_of_the_module_it_replaced():
    """`kinetostat.model` was one module (to c9e783d); the names users and tests imported from it
    import from the package, the same objects as where they live now."""
    import kinetostat
    import kinetostat.model as model
    from kinetostat.model import limits, parts
    from kinetostat.structure import Structure
    assert (model.ModelError, model.ModelWarning, model.ModelFileNotFound, model.StructureError) == (
        kinetostat.ModelError, kinetostat.ModelWarning, kinetostat.errors.ModelFileNotFound, kinetostat.StructureError)
    assert model.Structure is Structure and model.Vec is parts.Vec
    for name in ("MAX_KEY", "MAX_KEY_MEMORY", "MAX_FILE_BYTES", "MAX_VALUE", "MAX_POINTS", "MIN_LENGTH", "MIN_GEAR",
                 "MAX_PUBLISHED_ANGLES", "MAX_SHOWN", "MAX_NAME", "MAX_PROBLEMS", "MAX_PARAMETERS", "LAW_VARIABLES"):
        assert getattr(model, name) is getattr(limits, name), name


def test_no_module_defines_a_name_twice():
    """A module's top-level function or class defined twice keeps the last one alone: two merged
    branches each added `cli.common._probe` (the memory guard's probe of a model, then a
    writability probe of a folder), and the guard called the folder's with a model, caught the
    TypeError and checked nothing."""
    twice = {}
    for name, (path, _) in _modules().items():
        seen: set[str] = set()
        for node in _tree(path).body:
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
                if node.name in seen:
                    twice.setdefault(name, []).append(node.name)
                seen.add(node.name)
    assert not twice, twice
