"""Hostile model text in what CI reads (issue 35, class 2): a published value whose source holds
newlines, `::error::`, `::add-mask::`, `%`, HTML and `|` forges no workflow command on stdout,
no markup in $GITHUB_STEP_SUMMARY, and leaves the JUnit XML well-formed, in the pytest plugin
and in `kinetostat validate`; each channel's one escaping function holds the text as text."""
from __future__ import annotations

import os
import re
import xml.etree.ElementTree as ET

import pytest

from conftest import four_bar
from kinetostat._text import markdown_text, one_line, workflow_command_text

pytest_plugins = ["pytester"]

#: A published value's source as a TOML basic string: forged commands after newlines (LF, CR LF),
#: a tag, a percent sign, a table cell's bar, a control character.
SOURCE = (r"\u0001x\n::error::forged\n::add-mask::secret <img src=x onerror=alert(1)> 100 % | cell"
          r"\r\n::warning title=t::two")
SYMBOL = "w2 <b>|%::,"          # printable: a symbol may hold it
HOSTILE = four_bar(append=f"""
[[published]]
symbol = "{SYMBOL}"
quantity = "omega"
link = 2
angle = 30.0
value = 1.0
tolerance = 0.01
source = "{SOURCE}"
""")
LEGIT = re.compile(r"::error file=[^:\n]*,line=\d+,title=[^:\n]*::.*")


def _commands(stdout: str) -> list[str]:
    """The lines of stdout that the Actions runner reads as workflow commands."""
    return [ln for ln in stdout.splitlines() if ln.lstrip().startswith(("::", "##["))]


def _assert_summary_is_text(summary: str) -> None:
    assert "<img" not in summary and "&lt;img src=x onerror=alert(1)>" in summary
    for row in (ln for ln in summary.splitlines() if ln.startswith("| ")):
        assert len(re.findall(r"(?<!\\)\|", row)) == 9, row        # 8 cells: no bar of the source splits one
    assert "x\\\\n::error::forged" in summary                       # the newline shown, not taken


@pytest.mark.parametrize("text, data, prop", [
    ("a\nb", "a%0Ab", "a%0Ab"),
    ("a\r\n::error::x", "a%0D%0A::error::x", "a%0D%0A%3A%3Aerror%3A%3Ax"),
    ("100 %0A", "100 %250A", "100 %250A"),                         # a % that spells an escape stays text
    ("f(a, b): <b>", "f(a, b): <b>", "f(a%2C b)%3A <b>"),
    ("\x1b[2J", "\\x1b[2J", "\\x1b[2J"),
])
def test_workflow_command_text(text, data, prop):
    assert workflow_command_text(text) == data and workflow_command_text(text, prop=True) == prop
    assert "\n" not in data + prop and "\r" not in data + prop


@pytest.mark.parametrize("text, cell", [
    ("a\n::error::x", "a\\\\n::error::x"),
    ("<img src=x onerror=alert(1)>", "&lt;img src=x onerror=alert(1)>"),
    ("a | b", "a \\| b"),
    ("50 % & [x](javascript:y)", "50 % &amp; \\[x\\](javascript:y)"),
])
def test_markdown_cell(text, cell):
    assert markdown_text(text) == cell


def test_terminal_text_is_one_line():
    assert one_line("x\n::error::forged\r\n::add-mask::s") == "x\\n::error::forged\\r\\n::add-mask::s"


def test_plugin_forges_no_command_and_no_markup(pytester, monkeypatch):
    """Before: the failure's text printed the source's lines raw ('::error::forged' and
    '::add-mask::secret' lines on stdout) and the summary carried its <img> tag."""
    (pytester.path / "m.toml").write_text(HOSTILE, encoding="utf-8")
    summary = pytester.path / "summary.md"
    monkeypatch.setenv("GITHUB_ACTIONS", "true")
    monkeypatch.setenv("GITHUB_WORKSPACE", str(pytester.path))
    monkeypatch.setenv("GITHUB_STEP_SUMMARY", str(summary))
    r = pytester.runpytest_inprocess("--kinetostat", "m.toml", "--kinetostat-steps", "12", "-k", "published",
                                     "--junitxml=j.xml", "-p", "no:cacheprovider", "-p", "no:hypothesispytest")
    r.assert_outcomes(failed=1)
    out = r.stdout.str()
    (command,) = _commands(out)                                      # the one annotation, escaped
    assert LEGIT.fullmatch(command), command
    assert "(published value: \\x01x%0A::error::forged%0A::add-mask::secret <img" in command
    assert "100 %25 | cell%0D%0A::warning title=t::two)" in command
    assert "source: \\x01x\\n::error::forged\\n::add-mask::secret" in out    # the failure's text, one line
    _assert_summary_is_text(summary.read_text(encoding="utf-8"))
    (trust,) = [p.get("value") for p in ET.parse(pytester.path / "j.xml").iter("property") if p.get("name") == "trust"]
    assert trust.endswith("x\n::error::forged\n::add-mask::secret <img src=x onerror=alert(1)> 100 % | cell"
                          "\r\n::warning title=t::two")                 # XML held the text as it is


def test_validate_forges_no_command_and_no_markup(cli, tmp_path):
    (tmp_path / "m.toml").write_text(HOSTILE, encoding="utf-8")
    summary = tmp_path / "summary.md"
    r = cli("validate", "m.toml", "--engines", "none", "--steps", "12", "--no-progress", "--junit", "v.xml",
            env={"GITHUB_ACTIONS": "true", "GITHUB_STEP_SUMMARY": str(summary), "GITHUB_WORKSPACE": str(tmp_path)},
            cwd=tmp_path)
    assert r.returncode == 1, r.stderr
    (command,) = _commands(r.stdout)
    assert LEGIT.fullmatch(command) and "%0A::error::forged%0A::add-mask::secret" in command
    assert not _commands(r.stderr)
    _assert_summary_is_text(summary.read_text(encoding="utf-8"))
    root = ET.parse(tmp_path / "v.xml").getroot()                    # well-formed, U+0001 written as \x01
    (failure,) = root.iter("failure")
    assert "source: \\x01x\n::error::forged\n::add-mask::secret <img" in failure.text


@pytest.mark.skipif(os.name != "posix", reason="a newline in a file name")
def test_a_model_file_name_forges_no_command(pytester, monkeypatch):
    """Before: a collected model file named 'evil\\n::error::forged.toml' that fails to load put
    '::error::forged...' lines on stdout (its path in the failure's text and in pytest's own
    headers). Now it is not collected, one escaped line names it, and the gate fails."""
    (pytester.path / "evil\n::error::forged.toml").write_text("[mechanism]\n", encoding="utf-8")
    monkeypatch.setenv("GITHUB_ACTIONS", "true")
    r = pytester.runpytest_inprocess("--kinetostat", ".", "--kinetostat-steps", "12", "-p", "no:cacheprovider",
                                     "-p", "no:hypothesispytest")
    out = r.stdout.str()
    assert not _commands(out), out
    assert "kinetostat: not collected: " in out and "evil\\n::error::forged.toml" in out
    assert r.ret == pytest.ExitCode.TESTS_FAILED
