"""Text from a model file (names, notes, expressions) made safe for each place it is written, one
function per place: XML (MJCF, URDF, SVG, JUnit), CSV cells opened by spreadsheets, Markdown (also
GitHub's step summary) and the HTML a CommonMark renderer makes of it, GitHub Actions' workflow
commands, JSON inside an HTML <script> element, and the terminal.

May use: the standard library only.
"""
from __future__ import annotations

import re
import json
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    import xml.etree.ElementTree as ET

__all__ = ["xml_safe", "xml_escape", "xml_clean_tree", "csv_cell", "markdown_text", "html_text",
           "workflow_command_text", "script_json", "visible", "one_line"]

#: Characters XML 1.0 cannot hold, even as a character reference.
_NOT_XML = re.compile("[\x00-\x08\x0b\x0c\x0e-\x1f\ufffe\uffff]")
#: Control characters a terminal acts on (C0 but newline and tab, DEL, C1: ESC [2J, OSC 52, ...).
_CONTROL = re.compile("[\x00-\x08\x0b-\x1f\x7f-\x9f]")
#: The first characters that make a spreadsheet read a cell as a formula (OWASP, CSV injection).
_FORMULA_START = ("=", "+", "-", "@", "\t", "\r", "\n")
#: Characters that make emphasis, code, links, table cells or strike-through in Markdown anywhere in a line;
#: `_` where it can open or close emphasis (CommonMark: not between two letters or digits, as in V_BA).
_MARKDOWN = re.compile(r"([\\`*\[\]|~]|(?<![^\W_])_|_(?![^\W_]))")


def _escaped(m: re.Match) -> str:
    return m[0].encode("unicode_escape").decode("ascii")


def xml_safe(s: str) -> str:
    """`s` with what XML cannot hold (control characters, a non-UTF-8 file name's bytes) as "\\x.."."""
    s = s.encode("utf-8", "backslashreplace").decode("utf-8")
    return _NOT_XML.sub(_escaped, s)


#: A text `xml_escape` leaves as it is: no & < > ", no control character, surrogate or non-character.
_XML_PLAIN = re.compile("[^&<>\"\x00-\x1f\ud800-\udfff\ufffe\uffff]*")
#: `xml_escape`'s entities and character references (`xml.sax.saxutils` imports urllib.request, http, email, ssl).
_XML_ENTITIES = str.maketrans({"&": "&amp;", "<": "&lt;", ">": "&gt;", '"': "&quot;", "\n": "&#10;", "\r": "&#13;",
                               "\t": "&#9;"})


def xml_escape(s: str) -> str:
    """`s` as XML character data or a quoted attribute's value, on one line: & < > " escaped,
    newline, return and tab as character references (an attribute keeps them), other controls
    as "\\x.."."""
    if _XML_PLAIN.fullmatch(s):                    # most names and labels: nothing to do
        return s
    return xml_safe(s).translate(_XML_ENTITIES)


def xml_clean_tree(root: ET.Element) -> ET.Element:
    """Every text, tail, comment and attribute of the tree made writable as XML; returns `root`."""
    for el in root.iter():
        el.attrib.update({k: xml_safe(v) for k, v in el.attrib.items()})
        if el.text:
            el.text = xml_safe(el.text)
        if el.tail:
            el.tail = xml_safe(el.tail)
    return root


def csv_cell(x: Any) -> Any:
    """A text cell a spreadsheet would read as a formula ('=1+2', '-2+3+cmd|...', '@SUM(..)')
    led by a single quote, as OWASP advises; numbers and other text as they are."""
    if isinstance(x, str) and x.startswith(_FORMULA_START):
        return "'" + x
    return x


def markdown_text(s: str) -> str:
    """`s` as literal text inside a Markdown line (a table cell, a heading): \\ ` * [ ] | ~ and
    a `_` not inside a word backslash-escaped, & < as entities (no tag, link, emphasis or extra cell from a name),
    controls visible, one line."""
    s = _MARKDOWN.sub(r"\\\1", one_line(s))
    return s.replace("&", "&amp;").replace("<", "&lt;")


#: The whitespace CommonMark trims from the edges of a heading, a paragraph or a table cell (Unicode
#: Zs, U+2028, U+2029; the controls `one_line` writes visibly).
_MARKDOWN_TRIM = " \u00a0\u1680" + "".join(map(chr, range(0x2000, 0x200b))) + "\u2028\u2029\u202f\u205f\u3000"
#: The characters a CommonMark renderer writes as entities in HTML text (not ').
_HTML_ENTITIES = str.maketrans({"&": "&amp;", "<": "&lt;", ">": "&gt;", '"': "&quot;"})


def html_text(s: str) -> str:
    """`s` as the text of an HTML heading, paragraph or table cell, as a CommonMark renderer
    writes `markdown_text(s)` standing alone there: controls visible, one line, the edges'
    whitespace trimmed, & < > " as entities."""
    return one_line(s).strip(_MARKDOWN_TRIM).translate(_HTML_ENTITIES)


def workflow_command_text(s: str, prop: bool = False) -> str:
    """`s` as the message (or, `prop`, a property's value: file, title) of a GitHub Actions
    workflow command `::error file=...,title=...::message`, by the runner's rules: % CR LF as
    %25 %0D %0A, and in a property : and , as %3A %2C; other controls visible ("\\x1b"). No
    newline is left to start a line of its own, which the runner would read as a command."""
    s = visible(s.replace("%", "%25").replace("\r", "%0D").replace("\n", "%0A"))
    return s.replace(":", "%3A").replace(",", "%2C") if prop else s


#: What JSON may hold that ends or changes an HTML <script> element (`</script>`, `<!--`, `]]>`)
#: or a JavaScript line (U+2028, U+2029), each written as its \\u escape.
_SCRIPT_UNSAFE = {"<": "\\u003c", ">": "\\u003e", "&": "\\u0026", "\u2028": "\\u2028", "\u2029": "\\u2029"}


def script_json(x: Any) -> str:
    """`x` as JSON that an HTML <script> element (a page's data block) holds whole: < > & and
    U+2028/U+2029 as \\u escapes, so that no text in it (`</script>`, `<!--<script>`) ends the
    element or swallows the next one; JSON.parse gives back the same text."""
    s = json.dumps(x, ensure_ascii=False)
    return s.translate(str.maketrans(_SCRIPT_UNSAFE))


def visible(s: str) -> str:
    """`s` with the control characters a terminal would act on written as "\\x1b" etc.; newlines
    and tabs kept."""
    return _CONTROL.sub(_escaped, s)


def one_line(s: str) -> str:
    """`s` on one line: every control character, newlines too, written as "\\n" etc."""
    return _CONTROL.sub(_escaped, s).replace("\n", "\\n").replace("\t", "\\t")
