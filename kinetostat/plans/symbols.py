"""How a symbol is lettered: its base, subscript and superscript as runs of text at three levels,
one rule that every writer follows (the SVG sheets and the page: `labels.label_markup`, the notes
of `draw`; the PDFs: `pdf.Canvas.text`; the HTML worksheet and pack: `html`).

    >>> runs("R12t"), runs("a^n_BA"), runs("μ_l"), runs("pi-a")
    ((('R', 0), ('12', -1), ('t', 1)), (('a', 0), ('n', 1), ('BA', -1)), (('μ', 0), ('l', -1)), (('πa', 0),))

A symbol as the project writes it: letters, then a subscript (digits, R12; or after "_", F_i2,
μ_l), a superscript (after "^", a^n; a reaction's component letter after its digits, R12t), in
any order; primes after the letters (M'_зр); a pair's indices "(4,3)" belong to the script before
them (V_rel(4,3)); "*" (drawn out of scale) and anything after the symbol (F_i2(h), M_i2/l (a))
are set as they are, its own symbols with "_" or "^" as such (l_AB/l_OA). "pi" is π; a segment "pi-a" is its two points' symbols (πa).

In a text, a symbol is a name marked by `mark` (\\x01name\\x02) or any word with "_" or "^" in it
(μ_l = 0.001 m/mm, δ = (M'_зр - M_зр) / M'_зр): `text_runs` splits a text so.

May use: the standard library.
"""
from __future__ import annotations

import re
from functools import lru_cache
from html import escape

__all__ = ["runs", "text_runs", "mark", "plain", "html", "SCRIPT", "SUB_DROP", "SUP_RISE", "SUB", "SUP"]

#: Levels of a run: on the baseline 0, subscript SUB, superscript SUP.
SUB, SUP = -1, 1
#: A script's font size, of the symbol's size (GOST 2.304: indices a size smaller).
SCRIPT = 0.75
#: How far a subscript's baseline drops, and a superscript's rises, em of the symbol's size.
SUB_DROP, SUP_RISE = 0.22, 0.33

_OPEN, _CLOSE = "\x01", "\x02"
_SEGMENT = re.compile(r"[^-\s]+-[^-\s]+")
#: Letters (and primes), then scripts: "_x" a subscript, "^x" a superscript (x: word characters,
#: several joined by commas as the lever letters coincident arms, h_G3,Fi3; a pair's "(i,j)" after
#: them), or digits (a subscript, "2_3" as "2,3") and a component letter n, t (a superscript); the
#: rest as it is.
_HEAD = re.compile(r"([^\W\d_]+)('*)")
_SCRIPT = re.compile(r"([_^])([^\W_]+(?:,[^\W_]+)*(?:\(\d+,\d+\))?)")
_DIGITS = re.compile(r"(\d+(?:[_,]\d+)*)([nt](?![\w(]))?")
#: A word of a text that is a symbol: word characters with "_" or "^" in it (μ_l, a^n_BA, V_rel(4,3)).
_WORD = re.compile(r"(?<![\w'])[^\W_]['\w^]*[_^][\w^']*(?:\(\d+,\d+\))?")


@lru_cache(maxsize=4096)
def runs(name: str) -> tuple[tuple[str, int], ...]:
    """A symbol as (text, level) runs, level 0 on the baseline, SUB or SUP (the module's rule)."""
    if name == "pi":
        return (("π", 0),)
    if _SEGMENT.fullmatch(name) and not ("_" in name or "^" in name):
        a, b = name.split("-")
        return _merge(runs(a) + runs(b))
    star = name.endswith("*") and len(name) > 1
    body = name[:-1] if star else name
    m = _HEAD.match(body)
    if not m:
        return ((name, 0),)
    out = [(m.group(1), 0)] + ([("′" * len(m.group(2)), 0)] if m.group(2) else [])
    pos = m.end()
    d = _DIGITS.match(body, pos)
    if d:
        out.append((d.group(1).replace("_", ","), SUB))
        if d.group(2):
            out.append((d.group(2), SUP))
        pos = d.end()
    while (s := _SCRIPT.match(body, pos)):
        out.append((s.group(2), SUB if s.group(1) == "_" else SUP))
        pos = s.end()
    if body[pos:pos + 1].isalnum():                # letters after its digits (B3B4): a name, as it is
        return ((name, 0),)
    rest = body[pos:] + ("*" if star else "")
    return _merge(tuple(out) + text_runs(rest))                  # l_AB/l_OA: the rest may hold symbols too


def _merge(rs: tuple[tuple[str, int], ...]) -> tuple[tuple[str, int], ...]:
    """Runs with neighbours of one level joined."""
    out: list[tuple[str, int]] = []
    for t, level in rs:
        if out and out[-1][1] == level:
            out[-1] = (out[-1][0] + t, level)
        elif t:
            out.append((t, level))
    return tuple(out)


def mark(name: str) -> str:
    """`name` marked as a symbol in a text (`text_runs` letters it by `runs`)."""
    return f"{_OPEN}{name}{_CLOSE}"


@lru_cache(maxsize=16384)
def text_runs(s: str) -> tuple[tuple[str, int], ...]:
    """A text as (text, level) runs: its marked names and its words with "_" or "^" by `runs`, the
    rest on the baseline."""
    out: list[tuple[str, int]] = []
    for k, piece in enumerate(re.split(f"{_OPEN}([^{_CLOSE}]*){_CLOSE}", s)):
        if k % 2:
            out += runs(piece)
            continue
        at = 0
        for w in _WORD.finditer(piece):
            out += [(piece[at:w.start()], 0), *runs(w.group())]
            at = w.end()
        out.append((piece[at:], 0))
    return _merge(tuple(out))


def plain(s: str) -> str:
    """A text as read, its symbols' scripts inline (for a width or a search)."""
    return "".join(t for t, _ in text_runs(s))


def html(s: str, escaped: bool = False) -> str:
    """A text as HTML, escaped (`escaped`: `s` is HTML text already), its symbols' scripts in <sub> and <sup>."""
    esc = str if escaped else escape
    return "".join(esc(t) if not level else f"<{'sub' if level == SUB else 'sup'}>{esc(t)}</{'sub' if level == SUB else 'sup'}>"
                   for t, level in text_runs(s))
