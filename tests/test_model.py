"""Model files: loading, immutability, and one clear error per fault (asserted by message)."""
from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import kinetostat
from kinetostat import AssemblyError, ModelError, StructureError

from conftest import FOUR_BAR


def test_every_bundled_model_loads_and_runs(mech):
    res = kinetostat.analyze(mech, steps=72)
    assert res.to_frame().shape[0] == 72
    assert np.isfinite(res.balancing_moment).all()


def test_mechanism_is_immutable():
    mech = kinetostat.loads(FOUR_BAR)
    with pytest.raises(dataclasses.FrozenInstanceError):
        mech.g = 10.0
    with pytest.raises(TypeError):
        mech.links[2].points["A"] = (1.0, 1.0)


def _problems(text: str) -> list[str]:
    with pytest.raises(ModelError) as exc:
        kinetostat.loads(text, source="bad.toml")
    assert str(exc.value).startswith("bad.toml:")
    return exc.value.problems


@pytest.mark.parametrize("old, new, message", [
    ('links = [2, 3]\npoint = "B"', 'links = [2, 7]\npoint = "B"',
     "pair[2].links: unknown link 7. Valid links: [0, 1, 2, 3]"),
    ("mass = 1.5", "mass = -1.5", "link[id=2].mass: must be >= 0.0, got -1.5"),
    ('points = { C = [0.0, 0.0], B = [0.3, 0.0], S3 = [0.12, -0.01] }',
     'points = { C = [0.0, 0.0], B = [0.0, 0.0], S3 = [0.0, 0.0] }',
     "link[id=3].points: all points coincide (zero-length link)"),
    ("I_S = 0.016", 'I_S = "heavy"', "link[id=2].I_S: expression \"heavy\": unknown name 'heavy'"),
    ('sense = "ccw"', 'sense = "left"', "drive.sense: invalid value 'left'. Valid values: ['ccw', 'cw']"),
    ("rpm = 300.0", "rpm = nan", "drive.rpm: expected a finite number, got nan"),
    ('com = "S2"', 'com = "S9"', "link[id=2].com: unknown point 'S9'. Valid names: ['A', 'B', 'S2']"),
    ('link = 3\nvalue = -4.0', 'link = 5\nvalue = -4.0', "load[0].link: unknown link 5. Valid links: [0, 1, 2, 3]"),
    ("branch = 1", "branch = 2", "group[0].branch: expected +1 or -1, got 2"),
    ("[[group]]", "colour = 'red'\n[[group]]", "pair[3].colour: unknown field. Valid fields: ['kind', 'links', 'point', 'radius']"),
])
def test_each_fault_is_named(old, new, message):
    assert old in FOUR_BAR
    problems = _problems(FOUR_BAR.replace(old, new, 1))
    assert any(p.startswith(message) for p in problems), problems


def test_all_problems_are_reported_at_once():
    text = FOUR_BAR.replace("mass = 1.5", "mass = -1.5").replace("I_S = 0.009", "I_S = -1.0")
    problems = _problems(text.replace('sense = "ccw"', 'sense = "up"'))
    assert len(problems) == 3, problems


def test_pair_on_missing_point():
    problems = _problems(FOUR_BAR.replace('links = [0, 3]\npoint = "C"', 'links = [0, 3]\npoint = "D"'))
    assert "pair[3].point: link 0 has no point 'D'. Valid names: ['C', 'O']" in problems


def test_toml_syntax_error():
    problems = _problems(FOUR_BAR.replace("g = 9.81", "g = = 9.81"))
    assert problems[0].startswith("TOML syntax error: ")
    assert "line" in problems[0]


def test_missing_file(tmp_path):
    with pytest.raises(ModelError, match="cannot read file"):
        kinetostat.load(tmp_path / "none.toml")


def test_linkage_that_cannot_be_assembled_names_the_angles():
    # coupler 0.35 - rocker 0.12 = 0.23 > |AC| = sqrt((0.3 - 0.1 cos)^2 + (0.1 sin)^2) near phi = 0
    mech = kinetostat.loads(FOUR_BAR.replace("B = [0.3, 0.0], S3", "B = [0.12, 0.0], S3"))
    with pytest.raises(AssemblyError) as exc:
        kinetostat.analyze(mech, phi_deg=[0.0, 30.0, 60.0, 180.0, 330.0])
    assert exc.value.group == "II(2,3)"
    assert list(exc.value.phi_deg) == [0.0, 30.0, 330.0]
    assert str(exc.value) == ("group II(2,3) cannot be assembled (|AC| outside [|l2 - l3|, l2 + l3]) "
                              "at phi = [0, 30, 330] deg")


def _linkage(links: dict[int, str], pins: list[tuple[int, int, str]]) -> str:
    """A crank-driven model: frame O, F, G, the links' points (id -> TOML inline table), revolute pairs."""
    head = """
[mechanism]
g = 9.81
[drive]
pivot = "O"
point = "A"
reference = [1.0, 0.0]
sense = "ccw"
rpm = 60.0
[frame]
O = [0.0, 0.0]
F = [0.5, 0.3]
G = [0.5, -0.3]
"""
    return head + "".join(f"[[link]]\nid = {k}\npoints = {pts}\n" for k, pts in links.items()) + "".join(
        f'[[pair]]\nkind = "R"\nlinks = [{i}, {j}]\npoint = "{p}"\n' for i, j, p in pins)


def test_class_three_group_is_recognised_and_class_four_refused(tmp_path, cli):
    # W = 1, links 2..5 form the class-III group III3: ternary link 3 (B, D, E) with three leashes
    crank = "{ O = [0.0, 0.0], A = [0.1, 0.0] }"
    three = _linkage({1: crank, 2: "{ A = [0.0, 0.0], B = [0.3, 0.0] }",
                      3: "{ B = [0.0, 0.0], D = [0.1, 0.1], E = [0.1, -0.1] }",
                      4: "{ D = [0.0, 0.0], F = [0.2, 0.0] }", 5: "{ E = [0.0, 0.0], G = [0.2, 0.0] }"},
                     [(0, 1, "O"), (1, 2, "A"), (2, 3, "B"), (3, 4, "D"), (4, 0, "F"), (3, 5, "E"), (5, 0, "G")])
    s = kinetostat.loads(three).structure
    assert (s.formula, s.mechanism_class, s.order) == ("I(0,1) <- III(2,3,4,5)", 3, 3)
    assert s.groups[0].links == (3, 2, 4, 5) and s.groups[0].known == (1, 0, 0)
    # the class-IV group of four links: the closed contour 2-3-4-5 with outer pairs on 2 and 4
    four = _linkage({1: crank, 2: "{ A = [0.0, 0.0], B = [0.3, 0.0], D = [0.1, -0.1] }",
                     3: "{ B = [0.0, 0.0], C = [0.2, 0.0] }", 4: "{ C = [0.0, 0.0], F = [0.2, 0.0], H = [0.1, -0.1] }",
                     5: "{ D = [0.0, 0.0], H = [0.2, 0.0] }"},
                    [(0, 1, "O"), (1, 2, "A"), (2, 3, "B"), (3, 4, "C"), (4, 0, "F"), (4, 5, "H"), (5, 2, "D")])
    with pytest.raises(StructureError, match=r"links \[2, 3, 4, 5\] do not split into class-II Assur groups"
                                             r" \(dyads\) and class-III triads III3: they form the group \(2,3,4,5\) of "
                                             r"class IV: its most complex closed contour of inner pairs, 2-3-4-5, has 4 pairs"):
        kinetostat.loads(four)
    (tmp_path / "four.toml").write_text(four)
    out = cli("structure", tmp_path / "four.toml")
    assert out.returncode == 2 and len(out.stderr.strip().splitlines()) == 1
    assert "group (2,3,4,5) of class IV" in out.stderr


def test_wrong_mobility_is_refused():
    text = FOUR_BAR.replace('[[pair]]\nkind = "R"\nlinks = [0, 3]\npoint = "C"\n', "")
    text = text.replace("C = [0.3, 0.0]", "C0 = [0.3, 0.0]")
    with pytest.raises(StructureError, match=r"mobility W = 3\*3 - 2\*3 - 0 = 3"):
        kinetostat.loads(text)
