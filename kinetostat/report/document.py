"""A small document model rendered to Markdown and to self-contained HTML, and number formats.

May use: the standard library only.
"""
from __future__ import annotations

import base64
import html
import math
import re
from pathlib import Path
from typing import Any, Sequence


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


class Doc:
    """A small document model rendered both to Markdown and to self-contained HTML.

    Inline text uses Markdown's `code`, **bold** and [text](href); everything else is literal.
    """

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

    def img(self, path: Path, caption: str):
        self.blocks.append(("img", Path(path), caption))

    def pre(self, text: str):
        self.blocks.append(("pre", text))

    # -- Markdown
    def markdown(self) -> str:
        out = []
        for b in self.blocks:
            kind = b[0]
            if kind == "h":
                out.append("#" * b[1] + " " + b[2])
            elif kind == "p":
                out.append(b[1])
            elif kind == "ul":
                out.append("\n".join(f"- {i}" for i in b[1]))
            elif kind == "table":
                _, header, rows, align = b
                cell = lambda s: str(s).replace("|", "\\|").replace("\n", " ")
                lines = ["| " + " | ".join(cell(h) for h in header) + " |",
                         "|" + "|".join("---:" if a == "r" else "---" for a in align) + "|"]
                lines += ["| " + " | ".join(cell(c) for c in r) + " |" for r in rows]
                out.append("\n".join(lines))
            elif kind == "img":
                out.append(f"![{b[2]}]({b[1].name})\n\n*{b[2]}*")
            elif kind == "pre":
                out.append("```\n" + b[1].rstrip("\n") + "\n```")
        return "\n\n".join(out) + "\n"

    # -- HTML
    @staticmethod
    def inline(text: str) -> str:
        s = html.escape(str(text), quote=False)
        s = re.sub(r"`([^`]+)`", r"<code>\1</code>", s)
        s = re.sub(r"\*\*([^*]+)\*\*", r"<b>\1</b>", s)
        s = re.sub(r"\[([^\]]+)\]\(([^)\s]+)\)", lambda m: f'<a href="{html.escape(m[2])}">{m[1]}</a>', s)
        return s

    def html(self) -> str:
        body = []
        for b in self.blocks:
            kind = b[0]
            if kind == "h":
                body.append(f"<h{b[1]}>{self.inline(b[2])}</h{b[1]}>")
            elif kind == "p":
                body.append(f"<p>{self.inline(b[1])}</p>")
            elif kind == "ul":
                body.append("<ul>" + "".join(f"<li>{self.inline(i)}</li>" for i in b[1]) + "</ul>")
            elif kind == "table":
                _, header, rows, align = b
                cls = lambda a: ' class="r"' if a == "r" else ""
                head = "".join(f"<th{cls(a)}>{self.inline(h)}</th>" for h, a in zip(header, align))
                trs = []
                for r in rows:
                    tds = []
                    for c, a in zip(r, align):
                        mark = ' class="fail"' if c.startswith(("**FAIL", "**ERROR")) else \
                            ' class="pass"' if c.startswith("**PASS") else ""
                        tds.append(f"<td{cls(a) if not mark else mark}>{self.inline(c)}</td>")
                    trs.append("<tr>" + "".join(tds) + "</tr>")
                body.append(f"<table><thead><tr>{head}</tr></thead><tbody>{''.join(trs)}</tbody></table>")
            elif kind == "img":
                data = base64.b64encode(b[1].read_bytes()).decode("ascii")
                body.append(f'<figure><img src="data:image/png;base64,{data}" alt="{html.escape(b[2])}">'
                            f"<figcaption>{self.inline(b[2])}</figcaption></figure>")
            elif kind == "pre":
                body.append(f"<pre>{html.escape(b[1])}</pre>")
        return _HTML.format(title=html.escape(self.title), body="\n".join(body))


_HTML = """<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>{title}</title>
<meta name="viewport" content="width=device-width, initial-scale=1">
<style>
body {{ font-family: system-ui, -apple-system, "Segoe UI", sans-serif; max-width: 1100px; margin: 2em auto;
       padding: 0 1em; color: #222; line-height: 1.45; }}
table {{ border-collapse: collapse; margin: 0.8em 0; font-size: 0.92em; }}
th, td {{ border: 1px solid #ccc; padding: 0.25em 0.6em; text-align: left; vertical-align: top; }}
th {{ background: #f2f2f2; }}
td.r, th.r {{ text-align: right; font-variant-numeric: tabular-nums; }}
td.pass {{ background: #e6f4e6; }} td.fail {{ background: #fbe3e3; }}
figure {{ margin: 1em 0; }} img {{ max-width: 100%; }}
figcaption {{ font-style: italic; color: #555; }}
code, pre {{ background: #f6f6f6; }} pre {{ padding: 0.6em; overflow-x: auto; }}
</style></head>
<body>
{body}
</body></html>
"""
