"""The model file's rules against misreading (issue 13, items 6-9): contradictions and
ambiguities refused or warned with the number that looks wrong, read-only models and results,
and error messages that name the link by its id, the line of the file and the close name."""
from __future__ import annotations

import dataclasses
import math
import tomllib
import warnings
from types import MappingProxyType

import numpy as np
import pytest

import kinetostat
from kinetostat import ModelError
from kinetostat.errors import ModelWarning
from conftest import FOUR_BAR, four_bar

SLIDER = """
[mechanism]
name = "vertical crank-slider"
g = 9.81
[drive]
pivot = "O"
point = "A"
reference = [1.0, 0.0]
sense = "ccw"
rpm = 1500.0
[frame]
O = [0.0, 0.0]
[[link]]
id = 1
points = { O = [0.0, 0.0], A = [0.05, 0.0] }
[[link]]
id = 2
points = { A = [0.0, 0.0], B = [0.2, 0.0], S2 = [0.08, 0.0] }
mass = 1.0
I_S = 0.004
com = "S2"
[[link]]
id = 3
points = { B = [0.0, 0.0], S3 = [0.03, 0.02] }
mass = 2.0
I_S = 0.01
com = "S3"
[[pair]]
kind = "R"
links = [0, 1]
point = "O"
[[pair]]
kind = "R"
links = [1, 2]
point = "A"
[[pair]]
kind = "R"
links = [2, 3]
point = "B"
[[pair]]
kind = "P"
links = [0, 3]
guide = "O"
direction = [0.0, 1.0]
point = "B"
[[group]]
links = [2, 3]
branch = 1
"""


def _problems(text: str) -> ModelError:
    with pytest.raises(ModelError) as exc:
        kinetostat.loads(text)
    return exc.value


def _line(text: str, fragment: str) -> int:
    """1-based line of the first line of `text` that contains `fragment`."""
    return next(n for n, line in enumerate(text.splitlines(), 1) if fragment in line)


# ----------------------------------------------------------------------------- item 9: messages

@pytest.mark.parametrize("old, new, message, at", [
    ("mass = 1.5", "masss = 1.5", "link[id=2].masss: unknown field (did you mean 'mass'?)", "masss"),
    ('com = "S2"', 'com = "S22"', "link[id=2].com: unknown point 'S22' (did you mean 'S2'?)", 'com = "S22"'),
    ('links = [2, 3]\npoint = "B"', 'links = [2, 7]\npoint = "B"', "pair[2].links: unknown link 7", "links = [2, 7]"),
    ("rpm = 300.0", "rpm = -3.0", "drive.rpm: must be >= 0", "rpm = -3.0"),
    ('sense = "ccw"', 'sense = "cww"', "drive.sense: invalid value 'cww' (did you mean 'cw'?)", "cww"),
    ("branch = 1", "branch = 2", "group[0].branch: expected +1 or -1, got 2", "branch = 2"),
    ('link = 3\nvalue = -4.0', 'link = 3\nvalue = -4.0\ndirektion = [0.0, 1.0]',
     "load[0].direktion: unknown field (did you mean 'direction'?)", "direktion"),
])
def test_message_names_the_link_id_the_close_name_and_the_line(old, new, message, at):
    text = FOUR_BAR.replace(old, new, 1)
    exc = _problems(text)
    n = next(i for i, p in enumerate(exc.problems) if p.startswith(message))
    assert exc.lines[n] == _line(text, at), (exc.lines, exc.problems)
    assert f"line {_line(text, at)}: {message}" in str(exc)


def test_one_typo_is_one_problem():
    """A misspelt id or points key is the cause; the links, pairs and loads that refer to the
    link or its points are consequences, not reported (before: 8 problems for `idd`)."""
    for old, new, message in [("id = 2", "idd = 2", "[[link]] #2.idd: unknown field (did you mean 'id'?)"),
                              ("points = { A = [0.0, 0.0], B", "pointz = { A = [0.0, 0.0], B",
                               "link[id=2].pointz: unknown field (did you mean 'points'?)"),
                              ("B = [0.35, 0.0]", "B = [0.35]",
                               "link[id=2].points.B: expected [x, y] with two finite numbers, got [0.35]")]:
        exc = _problems(FOUR_BAR.replace(old, new, 1))
        assert exc.problems == [message + exc.problems[0][len(message):]] and exc.problems[0].startswith(message)


def test_missing_model_file_is_a_file_not_found_error(tmp_path):
    try:
        kinetostat.load(tmp_path / "absent.toml")
    except FileNotFoundError as exc:
        assert isinstance(exc, ModelError) and "absent.toml" in str(exc)
    else:
        pytest.fail("no FileNotFoundError")


# ----------------------------------------------------------------------------- item 5: engines

def test_a_body_of_infinite_mass_never_reaches_an_engine():
    """g = 5e-320 with a weight once gave mass = inf, and pymunk aborted the process. The loader
    refuses it (tests/hostile/tiny_g_*.toml); the harness refuses such a body too."""
    pytest.importorskip("kinetostat_validation")
    from kinetostat_validation.scene import build_scene
    mech = kinetostat.loads(FOUR_BAR)
    heavy = dataclasses.replace(mech, links=(mech.links[0], dataclasses.replace(mech.links[1], mass=math.inf),
                                             *mech.links[2:]))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with pytest.raises(ValueError, match=r"link 1: mass = inf is not a finite number"):
            build_scene(heavy, steps=4)


# ----------------------------------------------------------------------------- item 6: read-only

def _reachable(obj, path="", seen=None):
    """(path, value) of every array, mapping and list reachable from obj's public attributes and
    properties, through dataclasses, named tuples, tuples and mappings."""
    seen = set() if seen is None else seen
    if id(obj) in seen or isinstance(obj, (str, bytes, int, float, complex, type(None))):
        return
    seen.add(id(obj))
    if isinstance(obj, (np.ndarray, list, dict, MappingProxyType)):
        yield path, obj
    if isinstance(obj, np.ndarray):
        return
    if isinstance(obj, (tuple, list)):
        for i, x in enumerate(obj):
            yield from _reachable(x, f"{path}[{i}]", seen)
        return
    if isinstance(obj, (dict, MappingProxyType)):
        for k, x in obj.items():
            yield from _reachable(x, f"{path}[{k!r}]", seen)
        return
    if not (dataclasses.is_dataclass(obj) or hasattr(obj, "_fields")):
        return
    for name in dir(obj):
        if name.startswith("_") or callable(getattr(type(obj), name, None)) and not isinstance(
                getattr(type(obj), name, None), property):
            continue
        try:
            value = getattr(obj, name)
        except (TypeError, AttributeError):      # e.g. Pair.alpha of a revolute pair
            continue
        yield from _reachable(value, f"{path}.{name}", seen)


def _written(value) -> bool:
    """Try an in-place write; True if it took."""
    try:
        if isinstance(value, np.ndarray):
            if value.size:
                value.flat[0] = ~value.flat[0] if value.dtype == bool else value.flat[0] + 1
            return bool(value.size)
        if isinstance(value, list):
            value.append(None)
            return True
        value["__x__"] = 1
        return True
    except (ValueError, TypeError):
        return False


@pytest.mark.parametrize("name", kinetostat.examples.names())
def test_models_and_results_cannot_be_changed_in_place(name):
    mech = kinetostat.load(name)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = kinetostat.analyze(mech, steps=8)
    before = res.balancing_moment.copy()
    checked = 0
    for root, obj in (("mech", mech), ("res", res)):
        for path, value in list(_reachable(obj, root)):
            checked += 1
            if _written(value):      # a write may only land in a fresh copy: the source is unchanged
                again = eval(path, {"mech": mech, "res": res})      # noqa: S307 (a path built above)
                assert again is not value, f"{path} is writable and shared"
    m, I, c = mech.inertia_arrays
    for a in (m, I, c, mech.points_z):
        assert not _written(a)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        np.testing.assert_array_equal(kinetostat.analyze(mech, steps=8).balancing_moment, before)
    assert checked > 20


# ----------------------------------------------------------------------------- item 7: contradictions

def test_same_group_twice_with_one_branch_still_loads():
    mech = kinetostat.loads(FOUR_BAR + "[[group]]\nlinks = [3, 2]\nbranch = 1\n")
    assert dict(mech.branches) == {frozenset({2, 3}): 1}


def test_a_model_drawn_in_millimetres_is_warned_with_its_numbers():
    data = tomllib.loads(FOUR_BAR)
    for t in [data["frame"]] + [link["points"] for link in data["link"]]:
        for k, (x, y) in t.items():
            t[k] = [1000 * x, 1000 * y]
    with pytest.warns(ModelWarning) as rec:
        kinetostat.from_dict(data)
    text = str(rec[0].message)
    # the rod spans 350 m, the 100 m crank at 300 rpm moves its pin at 100 * 10 pi m/s
    assert "spans 350 m" in text and f"{100 * 10 * math.pi:.4g} m/s" in text and "millimetres" in text
    with warnings.catch_warnings():
        warnings.simplefilter("error", ModelWarning)
        for name in kinetostat.examples.names():           # the bundled models draw no warning
            kinetostat.load(name)


# ----------------------------------------------------------------------------- item 8: ambiguities

def test_rrr_branch_takes_j_as_the_lower_id_and_a_reversed_list_is_warned():
    with pytest.warns(ModelWarning, match=r"group\[0\]\.links: \[3, 2\]: in an RRR group j is the lower id, 2"):
        reversed_ = kinetostat.loads(FOUR_BAR.replace("links = [2, 3]\nbranch = 1", "links = [3, 2]\nbranch = 1"))
    base = kinetostat.loads(FOUR_BAR)
    res = kinetostat.analyze(base, phi_deg=[0.0, 77.0])
    np.testing.assert_array_equal(kinetostat.analyze(reversed_, phi_deg=[0.0, 77.0]).position("B"), res.position("B"))
    # the documented rule, by hand: P on link j = 2 (A), Q on link k = 3 (C), B the inner joint
    P, Q, B = res.position("A"), res.position("C"), res.position("B")
    cross = (Q[:, 0] - P[:, 0]) * (B[:, 1] - P[:, 1]) - (Q[:, 1] - P[:, 1]) * (B[:, 0] - P[:, 0])
    assert (np.sign(cross) == 1).all()


def test_slider_frame_is_warned_and_slider_axis_states_it():
    """The slider's points (S3 off the guide line) in the guide frame, and the same points drawn in
    the world frame with slider_axis = the guide direction there: the same forces. Without it
    the world-drawn points draw a warning (and are another mechanism)."""
    with pytest.warns(ModelWarning, match=r"pair\[3\]: slider link 3's points .* 'S3' lies 0.02 m off the guide"):
        guide_frame = kinetostat.loads(SLIDER)
    # guide frame (a, b) is world (-b, a) for a vertical guide: S3 = (0.03, 0.02) -> world (-0.02, 0.03)
    world = SLIDER.replace("S3 = [0.03, 0.02]", "S3 = [-0.02, 0.03]")
    with warnings.catch_warnings():
        warnings.simplefilter("error", ModelWarning)
        stated = kinetostat.loads(world.replace('point = "B"\n[[group]]', 'point = "B"\nslider_axis = [0.0, 1.0]\n[[group]]'))
    a = kinetostat.analyze(guide_frame, steps=24)
    b = kinetostat.analyze(stated, steps=24)
    np.testing.assert_allclose(b.forces.R, a.forces.R, rtol=0, atol=1e-12 * np.abs(a.forces.R).max())
    np.testing.assert_allclose(b.balancing_moment, a.balancing_moment, rtol=0, atol=1e-12 * np.abs(a.balancing_moment).max())
    with pytest.warns(ModelWarning):
        misread = kinetostat.analyze(kinetostat.loads(world), steps=24)
    # a translating block's centre of mass moves the line of the guide's reaction (its moment
    # about B), not M_bal
    m_true, m_misread = a.forces.m[:, 3], misread.forces.m[:, 3]
    assert np.abs(m_misread - m_true).max() > 0.1 * np.abs(m_true).max()


SLOTTED_LEVER = """
[mechanism]
name = "massless slotted lever, slot through its pivot"
g = 9.81
[drive]
pivot = "O"
point = "A"
reference = [1.0, 0.0]
sense = "ccw"
rpm = 60.0
[frame]
O = [0.0, 0.0]
C = [0.0, -0.2]
[[link]]
id = 1
points = { O = [0.0, 0.0], A = [0.1, 0.0] }
[[link]]
id = 2
points = { A = [0.0, 0.0] }
[[link]]
id = 3
points = { C = [0.0, 0.0], G = [0.0, 0.0] }
[[pair]]
kind = "R"
links = [0, 1]
point = "O"
[[pair]]
kind = "R"
links = [1, 2]
point = "A"
[[pair]]
kind = "P"
links = [3, 2]
guide = "G"
direction = [1.0, 0.0]
point = "A"
[[pair]]
kind = "R"
links = [0, 3]
point = "C"
[[group]]
links = [2, 3]
branch = 1
[[load]]
name = "resisting moment"
kind = "moment"
link = 3
value = -10.0
"""


def test_massless_lever_whose_slot_passes_its_pivot_is_no_zero_length_link():
    """Its points coincide, but its slot gives it a direction. Virtual work, all links massless:
    M_bal omega_1 + M_3 omega_3 = 0."""
    mech = kinetostat.loads(SLOTTED_LEVER)
    res = kinetostat.analyze(mech, steps=36)
    expected = 10.0 * res.omega(3) / res.omega(1)
    np.testing.assert_allclose(res.balancing_moment, expected, rtol=0, atol=1e-12 * np.abs(expected).max())
    # a lever that is in no prismatic pair is still refused
    exc = _problems(four_bar(("S3 = [0.12, -0.01] }", "S3 = [0.12, -0.01] }"),
                             ("C = [0.0, 0.0], B = [0.3, 0.0], S3 = [0.12, -0.01]", "C = [0.0, 0.0], B = [0.0, 0.0], S3 = [0.0, 0.0]")))
    assert any("all points coincide (zero-length link)" in p for p in exc.problems)


def test_a_tiny_g_with_weights_is_warned_with_its_number():
    """g = 1e-11 with a weight of 1 N gives a finite mass of 1e11 kg: loads, with a warning."""
    with pytest.warns(ModelWarning, match=r"line 4: mechanism\.g: 1e-11 m/s\^2 is far from the 9\.81"):
        mech = kinetostat.loads(four_bar(("g = 9.81", "g = 1e-11"), ("mass = 1.5", "weight = 1.0")))
    assert mech.links[2].mass == pytest.approx(1e11)


def test_line_is_found_past_strings_that_look_like_keys():
    text = FOUR_BAR.replace('g = 9.81', 'assumptions = [\n  "rpm = 300 as in the text",\n  """\nrpm = 1\n""",\n]\ng = 9.81', 1)
    exc = _problems(text.replace("rpm = 300.0", "rpm = -300.0"))
    assert exc.problems == ["drive.rpm: must be >= 0.0, got -300.0"]
    assert exc.lines == [_line(text, "rpm = 300.0")]


def test_line_is_found_past_rows_of_an_array_that_look_like_headers():
    text = FOUR_BAR.replace("[[link]]\nid = 2", 'extra = [\n  [0.0, 1.0],\n  [2.0, 3.0],\n]\n[[link]]\nid = 2', 1)
    exc = _problems(text.replace("mass = 1.5", "mass = -1.5"))
    n = exc.problems.index("link[id=2].mass: must be >= 0.0, got -1.5")
    assert exc.lines[n] == _line(text, "mass = 1.5")
