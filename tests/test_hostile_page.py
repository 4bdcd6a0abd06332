"""Hostile names in the interactive page (issue 35, class 5): a lettering symbol `<!--<script>`
or a point `</script>` leaves the page's data block whole (before, `<!--<script>` made it swallow
the page's script: the sheets never drew, and no error showed); control characters in a name
are refused by the reader, naming the field."""
from __future__ import annotations

import json
import re
import zlib
from html.parser import HTMLParser

import pytest

import kinetostat
import kinetostat.plans as P
from conftest import four_bar
from kinetostat.plans.page import ILLEGAL7, page

M_BAL, POINT = "<!--<script>", "</script>"
#: Point B of the four-bar named POINT (a pair's point: its velocity and acceleration rows name it).
HOSTILE = four_bar(("B = [0.35, 0.0]", f'"{POINT}" = [0.35, 0.0]'), ("B = [0.3, 0.0]", f'"{POINT}" = [0.3, 0.0]'),
                   ('point = "B"', f'point = "{POINT}"'), append=f'[lettering]\nM_bal = "{M_BAL}"\n')


class _Scripts(HTMLParser):
    """The page's <script> elements: (id, raw text) each, as an HTML parser ends them."""

    def __init__(self):
        super().__init__()
        self.scripts: list[list] = []

    def handle_starttag(self, tag, attrs):
        if tag == "script":
            self.scripts.append([dict(attrs).get("id"), ""])

    def handle_data(self, data):
        if self.scripts and self.lasttag == "script":
            self.scripts[-1][1] += data


@pytest.fixture(scope="module")
def hostile_page(tmp_path_factory):
    """The key page of the hostile four-bar, at one angle and the design position (cycle scales
    sampled every 120 deg: about a second), written to a file."""
    mech = kinetostat.loads(HOSTILE)
    path = tmp_path_factory.mktemp("page") / "key.html"
    path.write_text(page(mech, angles=[0.0], fixed=P.cycle_scales(mech, step_deg=120.0)), encoding="utf-8")
    return path


def test_a_name_cannot_end_or_extend_the_data_block(hostile_page):
    html = hostile_page.read_text(encoding="utf-8")
    parser = _Scripts()
    parser.feed(html)
    ids = [i for i, _ in parser.scripts]
    assert ids[-2:] == ["page-data", None] and all(i.startswith("blob-") for i in ids[:-2])
    assert html.count("<script") == len(ids)                   # no other element
    (data,) = [text for i, text in parser.scripts if i == "page-data"]
    # what would end the element early, or (after "<!--") make its "</script>" not end it (HTML, script data)
    assert not re.search(r"<!--|</?script", data, re.IGNORECASE), data[:200]
    (meta,) = [text for i, text in parser.scripts if i == "blob-meta"]
    symbols = [r["symbol"] for r in json.loads(_unpacked(meta))["rows"]]
    assert M_BAL in symbols and f"V_{POINT}" in symbols        # the names, as they were, in the page's blob


def _unpacked(blob: str) -> bytes:
    """A blob of the page (page.py `_packed`) back as its bytes: 7 bits a character (a character of
    U+0100 and up: a group of ILLEGAL7 and, but for the last, the group after it), inflated."""
    groups = []
    for c in map(ord, blob):
        if c < 256:
            groups.append(c)
            continue
        k = (c - 256) >> 7
        groups += [ILLEGAL7[k % 3]] + ([(c - 256) & 127] if k < 3 else [])
    bits = "".join(format(g, "07b") for g in groups)
    data = bytes(int(bits[i:i + 8], 2) for i in range(0, len(bits) // 8 * 8, 8))
    return zlib.decompress(data, -15)


def test_the_page_gets_ready_in_a_browser(hostile_page, chromium):
    """Before: the data block swallowed the page's script; body[data-ready] was never set."""
    pg = chromium.new_page()
    errors = []
    pg.on("pageerror", lambda e: errors.append(str(e)))
    pg.goto(hostile_page.as_uri())
    pg.wait_for_selector("body[data-ready]", state="attached", timeout=10000)
    assert not errors, errors
    assert M_BAL in pg.inner_text("#value-table")              # shown as text
    pg.close()


@pytest.mark.parametrize("edit, field", [
    (('name = "test four-bar"', 'name = "four\\u0000bar"'), "mechanism.name: 'four\\x00bar'"),
    (('name = "test four-bar"', 'name = "four\\u001b[2Jbar"'), "mechanism.name: 'four\\x1b[2Jbar'"),
    (('name = "test four-bar"', 'name = "four\\u0085bar"'), "mechanism.name: 'four\\x85bar'"),
    (('id = 2\n', 'id = 2\nname = "rod\\nx"\n'), "link[id=2].name: 'rod\\nx'"),
    (('O = [0.0, 0.0]\nC', '"Q\\u009f" = [0.0, 0.0]\nO = [0.0, 0.0]\nC'), "frame: the point name 'Q\\x9f'"),
    (('name = "resisting moment"', 'name = "M\\tc"'), "load[0].name: 'M\\tc'"),
    (('name = "test four-bar"', 'name = "four\\u202ebar"'), "mechanism.name: 'four\\u202ebar' holds the control character U+202E"),
    (('id = 2\n', 'id = 2\nname = "rod\\u2028x"\n'), "link[id=2].name: 'rod\\u2028x' holds the control character U+2028"),
])
def test_a_control_character_in_a_name_is_refused(edit, field):
    with pytest.raises(kinetostat.ModelError) as exc:
        kinetostat.loads(four_bar(edit))
    (problem,) = exc.value.problems
    assert problem.startswith(field) and "holds the control character U+" in problem, problem


def test_a_control_character_in_a_published_symbol_is_refused():
    text = four_bar(append='[[published]]\nsymbol = "w2\\r\\n::error::x"\nquantity = "omega"\nlink = 2\n'
                           'angle = 30.0\nvalue = 11.6\ntolerance = 0.01\nsource = "test"\n')
    with pytest.raises(kinetostat.ModelError, match=r"published\[0\]\.symbol: .* U\+000D at character 3"):
        kinetostat.loads(text)
