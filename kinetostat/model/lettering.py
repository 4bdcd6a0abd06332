"""A model's lettering: the names its source text gives (the model file's `[lettering]` table,
models/FORMAT.md), with the project's defaults where the model gives none. Every output that
names the frame, the balancing moment or force, or a load (sheets, worksheet, answer key,
cycle.csv aliases) asks here, so that all of them say what the text says.

    >>> import kinetostat
    >>> L = lettering(kinetostat.load("ice_crank_slider"))
    >>> L.frame, L.M_bal, L.F_bal, L.load("gas force"), L.language
    (4, 'M_зр', 'F_зр', 'F_p', 'uk')
    >>> in_lang(L.M_bal, "ru"), in_lang(L.lever(L.F_bal), "en")
    ('M_ур', "F'_bal")

May use: the model (`kinetostat.model`), the standard library.
"""
from __future__ import annotations

import re
from dataclasses import dataclass, field, replace
from types import MappingProxyType
from typing import TYPE_CHECKING, Any, Iterable, Mapping

if TYPE_CHECKING:
    from .mechanism import Mechanism

__all__ = ["Lettering", "lettering", "link_number", "reaction_name", "pair_name", "aliases", "with_alias_columns",
           "with_aliases", "in_lang", "DEFAULT", "SUBSCRIPTS"]


@dataclass(frozen=True)
class Lettering:
    """The names a model's text uses: `frame` the frame's number (seed 002's ICE: 4, so R43,
    R41), `M_bal`, `F_bal` the balancing moment's and force's symbols (M_зр, F_зр), `loads` load
    name -> symbol (gas force -> F_p), `names` language -> the mechanism's name in it, `language`
    the text's language ("" where the model does not state it)."""
    frame: int = 0
    M_bal: str = "M_bal"
    F_bal: str = "F_bal"
    loads: Mapping[str, str] = field(default_factory=lambda: MappingProxyType({}))
    names: Mapping[str, str] = field(default_factory=lambda: MappingProxyType({}))
    language: str = ""

    def load(self, name: str, default: str | None = None) -> str:
        """The symbol of the model's load `name` (`default`, else the name, where none is given)."""
        return self.loads.get(name, name if default is None else default)

    def lever(self, symbol: str) -> str:
        """The lever's symbol of a balancing quantity: a prime after its letter (M'_зр, F'_bal)."""
        head, sep, tail = symbol.partition("_")
        return f"{head}'{sep}{tail}"

    def name(self, lang: str, default: str) -> str:
        """The mechanism's name in `lang` (its own name where the model gives none in `lang`)."""
        return self.names.get(lang, default)

    def in_lang(self, lang: str) -> "Lettering":
        """This lettering as `lang`'s texts write its balancing symbols and loads (`in_lang`):
        for the texts of an output in `lang`; a plan's own names stay the model's."""
        return replace(self, M_bal=in_lang(self.M_bal, lang), F_bal=in_lang(self.F_bal, lang),
                       loads=MappingProxyType({k: in_lang(v, lang) for k, v in self.loads.items()}))


DEFAULT = Lettering()

#: A subscript as each language's texts write it, language -> {as a model may letter it: as that
#: language writes it}: the balancing quantity's зр (Ukrainian, зрівноважувальний), ур (Russian,
#: уравновешивающий), bal (English, balancing); КО (корисний опір) in English ur, useful resistance.
SUBSCRIPTS = MappingProxyType({"en": MappingProxyType({"зр": "bal", "ур": "bal", "КО": "ur"}),
                               "uk": MappingProxyType({"bal": "зр", "ур": "зр"}),
                               "ru": MappingProxyType({"bal": "ур", "зр": "ур"})})
_SUBSCRIPT = re.compile(r"(?<=_)[^\W\d_]+")


def in_lang(symbol: str, lang: str) -> str:
    """A symbol (or a text of symbols) as `lang`'s texts write it: each subscript after "_" that
    SUBSCRIPTS[lang] names, in that language (M_зр -> M_bal in English, M_ур in Russian; M'_зр +
    P_f/ω1 -> M'_ур + P_f/ω1); the model's other letters as it gives them."""
    table = SUBSCRIPTS.get(lang, {})
    return _SUBSCRIPT.sub(lambda m: table.get(m.group(), m.group()), symbol)


def _published_frame(mech: "Mechanism") -> int:
    """The frame's number a published reaction letters (R43 for the pair (0, 3): 4), else 0."""
    for p in mech.published:
        if p.quantity == "reaction" and p.pair is not None and 0 in p.pair:
            m = re.fullmatch(r"R_?(\d)(\d)", p.symbol)
            if m:
                digits = tuple(int(d) for d in m.groups())
                side = p.pair.index(0)
                if digits[1 - side] == p.pair[1 - side]:
                    return digits[side]
    return 0


def lettering(mech: "Mechanism") -> Lettering:
    """The lettering of `mech`: its `[lettering]` table, the frame's number from a published
    reaction where the table gives none, the defaults otherwise."""
    given = dict(getattr(mech, "lettering", None) or {})
    return Lettering(frame=int(given.get("frame", _published_frame(mech))),
                     M_bal=str(given.get("M_bal", DEFAULT.M_bal)), F_bal=str(given.get("F_bal", DEFAULT.F_bal)),
                     loads=MappingProxyType(dict(given.get("loads", {}))),
                     names=MappingProxyType(dict(given.get("name", {}))),
                     language=str(given.get("language", "")))


def link_number(mech: "Mechanism", k: int) -> int:
    """Link k's number as the text letters it: the frame's (`Lettering.frame`) for k = 0, else k."""
    return lettering(mech).frame if k == 0 else k


def reaction_name(mech: "Mechanism", i: int, j: int, part: str = "") -> str:
    """R<i><j> (force of link i on link j) as the texts letter it; part "n" or "t" for a component."""
    a, b = link_number(mech, i), link_number(mech, j)
    return f"R{a}{b}{part}" if a < 10 and b < 10 else f"R{a},{b}{part}"


def pair_name(mech: "Mechanism", p) -> str:
    """A pair as the outputs name it: its reaction and where it acts (R43 at B; R32 slider A on guide K)."""
    where = f"at {p.point}" if p.kind == "R" else f"slider {p.point} on guide {p.guide}"
    return f"{reaction_name(mech, *p.links)} {where}"


def aliases(columns: Iterable[str], mech: "Mechanism") -> dict[str, str]:
    """The text's names of the analysis table's `columns` (`Analysis.columns`), alias -> column:
    R_4_3 for R_0_3 where the frame is lettered 4 (and Rx_, Ry_, angle_R_, x_ likewise), M_зр for
    M_bal, M'_зр for M_lever, F_зр for F_bal."""
    L = lettering(mech)
    columns = list(columns)
    alias: dict[str, str] = {}
    if L.frame:
        for col in columns:
            m = re.fullmatch(r"(Rx|Ry|R|angle_R|x|m|vs|as)_(\d+)_(\d+)", col)
            if m and "0" in m.group(2, 3):
                i, j = (L.frame if g == "0" else g for g in m.group(2, 3))
                alias[f"{m.group(1)}_{i}_{j}"] = col
    for symbol, col in ((L.M_bal, "M_bal"), (L.lever(L.M_bal), "M_lever"), (L.F_bal, "F_bal")):
        if symbol != col and col in columns and symbol not in columns:
            alias[symbol] = col
    return alias


def with_alias_columns(cols: Mapping[str, Any], units: Mapping[str, str], mech: "Mechanism"
                       ) -> tuple[dict[str, Any], dict[str, str]]:
    """The analysis table's columns (`Analysis.columns`: name -> array, name -> unit) with the
    text's names (`aliases`) added as copies of their columns, after them: as `with_aliases` a frame."""
    alias = aliases(cols, mech)
    return ({**cols, **{a: cols[c] for a, c in alias.items()}},
            {**units, **{a: units.get(c, "") for a, c in alias.items()}})


def with_aliases(df, mech: "Mechanism"):
    """The analysis frame `df` (`Analysis.to_frame`) with the text's names (`aliases`) added as
    copies of their columns, after them. Units carried."""
    units = dict(df.attrs.get("units", {}))
    alias = aliases(df.columns, mech)
    out = df.assign(**{a: df[c] for a, c in alias.items()})
    out.attrs.update(df.attrs, units=units | {a: units.get(c, "") for a, c in alias.items()})
    return out
