"""A small document model written as Markdown, and that same Markdown rendered to an HTML page
by markdown-it-py; number formats of the reports.

The HTML is markdown-it's CommonMark rendering (tables enabled, raw HTML off, so any HTML or
`javascript:` link in a model's strings comes out escaped or as text) with: heading ids by
GitHub's rule (the table of contents links work in both), links to a report's `index.md` turned
into its `index.html` (other `.md` files, the studies, stay Markdown), images (PNG, SVG) linked
as the files beside the page that they are (`<img src="reactions.svg">`, as in the Markdown),
tables wrapped in a horizontally scrolling box.

May use: the standard library, `kinetostat._io` (atomic writes) and markdown-it-py (imported where a
document is parsed, `_markdown_it` and its rule `_inline`).
"""
from __future__ import annotations

import html
import math
import re
import sys
import unicodedata
from pathlib import Path
from typing import Any, Sequence

from .._io import write_text

#: An error smaller than this fraction of the cycle's peak is at rounding level (1000 units in the
#: last place of the peak): printed with its digits and ROUNDING_MARK beside them.
ROUNDING = 1000 * sys.float_info.epsilon
#: Beside an error at rounding level (`_rel`, `_err`); ROUNDING_NOTE says what it means.
ROUNDING_MARK = "†"
#: The footnote of every table or list that prints ROUNDING_MARK.
ROUNDING_NOTE = (f"{ROUNDING_MARK}: below {ROUNDING:.1e} of the cycle's peak (1000 units in its last place), "
                 "at rounding level: the two routes agree to machine precision, and these digits differ from "
                 "machine to machine")


def _fmt(x: float | None, digits: int = 4) -> str:
    if x is None or (isinstance(x, float) and math.isnan(x)):
        return "n/a"
    if x == 0:
        return "0"
    a = abs(x)
    if 1e-3 <= a < 1e6:
        return f"{x:.{digits}g}"
    return f"{x:.{max(digits - 2, 1)}e}"


def _fe(x: float | None) -> str:
    if x is None or (isinstance(x, float) and math.isnan(x)):
        return "n/a"
    return "0" if x == 0 else f"{x:.2e}"


def _rel(x: float | None) -> str:
    """A peak-relative error to three significant digits, ROUNDING_MARK beside it below ROUNDING (not 0)."""
    return _fe(x) + (f" {ROUNDING_MARK}" if x and _is_rounding(x) else "")


def _is_rounding(x: float | None) -> bool:
    return x is not None and math.isfinite(x) and abs(x) < ROUNDING


def _err(x: float | None, peak: float, unit: str) -> str:
    """An absolute error in `unit` (`_fmt`), ROUNDING_MARK beside it where it is below ROUNDING × peak (not 0)."""
    if x is None or not math.isfinite(x):
        return "n/a"
    return f"{_fmt(x)} {unit}" + (f" {ROUNDING_MARK}" if 0 < abs(x) < ROUNDING * abs(peak) else "")


#: Markup characters that act anywhere in a line: code, emphasis, links and images, autolinks and
#: raw HTML, entities (`&lt;`, `&#106;`), GitHub's strikethrough, a heading's closing '#', an
#: underscore at a word's edge; '|' is escaped by the table cells.
_MD_SPECIAL = re.compile(r"([\\`*\[\]<>&~#]|(?<![A-Za-z0-9])_|_(?![A-Za-z0-9]))")
#: Markup that acts at the start of a block (list, thematic break, setext underline).
_MD_START = re.compile(r"^(\s*)([+=-]|\d+(?=[.)]))")


def esc(text: Any) -> str:
    """Text from a model file (or a file name) as literal Markdown on one line: its markup
    characters backslash-escaped, line breaks as spaces, characters that UTF-8 cannot hold (a
    non-UTF-8 file name's bytes) as backslash escapes. Every string of a model goes through it."""
    s = str(text).encode("utf-8", "backslashreplace").decode("utf-8")
    s = _MD_SPECIAL.sub(r"\\\1", " ".join(s.splitlines()))
    return _MD_START.sub(lambda m: m[1] + (m[2] + "\\" if m[2][0].isdigit() else "\\" + m[2]), s)


def slug(text: str, seen: dict[str, int] | None = None) -> str:
    """GitHub's heading id: lower case, only letters, digits, '_', '-' and spaces (as '-');
    a repeated id gets -1, -2, ... (pass the same `seen` for one document)."""
    s = "".join(c for c in text.lower() if c in " -_" or unicodedata.category(c)[0] in "LN")
    s = s.replace(" ", "-")
    if seen is not None:
        n = seen.get(s, 0)
        seen[s] = n + 1
        if n:
            s = f"{s}-{n}"
    return s


def _markdown_it():
    """markdown-it: CommonMark, tables enabled, raw HTML off; its core rule "inline" is `_inline`."""
    from markdown_it import MarkdownIt
    md = MarkdownIt("commonmark", {"html": False}).enable("table")
    md.core.ruler.at("inline", _inline)
    return md


#: The characters at which one of markdown-it's inline rules (CommonMark, raw HTML off) can start:
#: backslash escape, code, emphasis, link (and image, `![`), autolink, entity, line break.
_INLINE_MARKUP = re.compile(r"[\\`*_\[<&\n]")


def _inline(state) -> None:
    """markdown-it's core rule "inline" (each inline token's children parsed), the same tokens made
    at once for a text without `_INLINE_MARKUP` (one text token, none for an empty text): 84 % of a
    report's inline texts, most of them table cells; a sixth of its HTML's CPU."""
    from markdown_it.token import Token
    for token in state.tokens:
        if token.type != "inline":
            continue
        if _INLINE_MARKUP.search(token.content):
            token.children = []
            state.md.inline.parse(token.content, state.md, state.env, token.children)
        else:
            token.children = [Token("text", "", 0, content=token.content)] if token.content else []


def _plain(inline) -> str:
    """The text of an inline token as GitHub sees it for a heading id (markup dropped)."""
    return "".join(t.content for t in (inline.children or []) if t.type in ("text", "code_inline"))


class Doc:
    """Blocks of a report, written as Markdown (`markdown()`) and rendered from it (`html()`)."""

    def __init__(self, title: str):
        self.title = title
        self.blocks: list[tuple] = []

    def h(self, level: int, text: str):
        self.blocks.append(("h", level, text))

    def p(self, text: str):
        self.blocks.append(("p", text))

    def ul(self, items: Sequence[str]):
        if items:
            self.blocks.append(("ul", list(items)))

    def table(self, header: Sequence[str], rows: Sequence[Sequence[Any]], align: str | None = None):
        """align: one letter per column, 'l' or 'r' (default: all left)."""
        self.blocks.append(("table", list(header), [[str(c) for c in r] for r in rows],
                            align or "l" * len(header)))

    def img(self, path: Path, caption: str, link: bool = False):
        """A PNG or SVG image with its caption; `link`: the image links to its file (a sheet to
        open at full size)."""
        self.blocks.append(("img", Path(path), caption, link))

    def pre(self, text: str):
        self.blocks.append(("pre", text))

    def toc(self):
        """A list of links to every level-2 heading of the document (written where it is called)."""
        self.blocks.append(("toc",))

    # -- Markdown
    def _block(self, b: tuple) -> str:
        kind = b[0]
        if kind == "h":
            return "#" * b[1] + " " + b[2]
        if kind == "p":
            return b[1]
        if kind == "ul":
            return "\n".join(f"- {i}" for i in b[1])
        if kind == "table":
            _, header, rows, align = b
            cell = lambda s: str(s).replace("|", "\\|").replace("\n", " ")
            lines = ["| " + " | ".join(cell(h) for h in header) + " |",
                     "|" + "|".join("---:" if a == "r" else "---" for a in align) + "|"]
            lines += ["| " + " | ".join(cell(c) for c in r) + " |" for r in rows]
            return "\n".join(lines)
        if kind == "img":
            image = f"![{b[2]}]({b[1].name})"
            return (f"[{image}]({b[1].name})" if b[3] else image) + f"\n\n*{b[2]}*"
        if kind == "pre":
            return "```\n" + b[1].rstrip("\n") + "\n```"
        raise ValueError(f"unknown block {kind!r}")

    def markdown(self) -> str:
        parts = ["" if b[0] == "toc" else self._block(b) for b in self.blocks]
        if any(b[0] == "toc" for b in self.blocks):
            # the headings alone parse as they do in the whole document (each is one line)
            heads = _headings("\n\n".join(s for b, s in zip(self.blocks, parts) if b[0] == "h"))
            toc = "\n".join(f"- [{text}](#{sid})" for lvl, text, sid in heads if lvl == 2)
            parts = [toc if b[0] == "toc" else s for b, s in zip(self.blocks, parts)]
        return "\n\n".join(s for s in parts if s) + "\n"

    def write(self, folder: Path, name: str = "index") -> Path:
        """`folder/name.md` and `folder/name.html` (the HTML rendered from that Markdown); the .md path."""
        text = self.markdown()
        write_text(Path(folder) / f"{name}.md", text)
        write_text(Path(folder) / f"{name}.html", self.html(text))
        return Path(folder) / f"{name}.md"

    # -- HTML
    def html(self, markdown: str | None = None) -> str:
        """The page rendered from `markdown()` (or the given `markdown`, the same text already
        written); images stay links to their files, beside the page as beside the Markdown."""
        md = _markdown_it()
        tokens = md.parse(self.markdown() if markdown is None else markdown)
        seen: dict[str, int] = {}
        for n, t in enumerate(tokens):
            if t.type == "heading_open":
                t.attrSet("id", slug(_plain(tokens[n + 1]), seen))
            elif t.type == "td_open" and tokens[n + 1].content.startswith(("**FAIL", "**ERROR", "**PASS")):
                t.attrSet("class", "pass" if tokens[n + 1].content.startswith("**PASS") else "fail")
            for c in t.children or []:
                if c.type == "link_open":
                    href = str(c.attrGet("href") or "")
                    path, hash_, frag = href.partition("#")
                    if not re.match(r"^[a-z][a-z0-9+.-]*:", href) and (path == "index.md" or path.endswith("/index.md")):
                        c.attrSet("href", path[:-3] + ".html" + hash_ + frag)
        md.add_render_rule("table_open", lambda *a: '<div class="scroll"><table>\n')
        md.add_render_rule("table_close", lambda *a: "</table></div>\n")
        body = md.renderer.render(tokens, md.options, {})
        return _HTML.format(title=html.escape(self.title), body=body)


def _headings(markdown: str) -> list[tuple[int, str, str]]:
    """(level, Markdown text, id) of every heading, ids as `Doc.html` and GitHub give them."""
    tokens = _markdown_it().parse(markdown)
    seen: dict[str, int] = {}
    return [(int(t.tag[1]), tokens[n + 1].content, slug(_plain(tokens[n + 1]), seen))
            for n, t in enumerate(tokens) if t.type == "heading_open"]


_HTML = """<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>{title}</title>
<meta name="viewport" content="width=device-width, initial-scale=1">
<style>
body {{ font-family: system-ui, -apple-system, "Segoe UI", sans-serif; max-width: 60em; margin: 1.5em auto;
       padding: 0 1em; color: #222; line-height: 1.45; overflow-wrap: break-word; }}
.scroll {{ overflow-x: auto; max-width: 100%; margin: 0.8em 0; }}
table {{ border-collapse: collapse; font-size: 0.9em; }}
th, td {{ border: 1px solid #ccc; padding: 0.25em 0.6em; vertical-align: top; }}
th {{ background: #f2f2f2; }}
td {{ font-variant-numeric: tabular-nums; }}
td.pass {{ background: #e6f4e6; }} td.fail {{ background: #fbe3e3; }}
img {{ max-width: 100%; height: auto; }}
code, pre {{ background: #f6f6f6; }} pre {{ padding: 0.6em; overflow-x: auto; }}
</style></head>
<body>
{body}</body></html>
"""
