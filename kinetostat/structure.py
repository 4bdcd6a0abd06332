"""Structural analysis (seed 000 sec. 5, seed 002 sec. 1.2.1): mobility by Chebyshev and the
decomposition into the initial mechanism I(0,1), class-II Assur groups (dyads) and the
simplest class-III group III3 (a triad: a ternary base link and three leashes; Artobolevsky).

Works on the model's data only (the number of links, the pairs, the assembly branches): it
imports nothing of `model`, which calls `analyse_structure` when it builds a Mechanism. May
use: `errors`.

May use: errors only (never the model: the dependency runs model -> structure).
"""
from __future__ import annotations

import heapq
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Protocol

from .errors import StructureError

__all__ = ["AssurGroup", "Triad", "Structure", "analyse_structure", "GROUP_KINDS", "KinematicPair"]

# The five kinds of class-II groups, numbered as the texts number them ("вид").
GROUP_KINDS = {"RRR": 1, "RRP": 2, "RPR": 3, "PRP": 4, "RPP": 5}


class KinematicPair(Protocol):
    """What the structural analysis reads of a pair (`kinetostat.model.Pair` is one)."""

    @property
    def kind(self) -> str:
        """"R" (revolute) or "P" (prismatic)."""

    @property
    def links(self) -> tuple[int, int]:
        """The two links it joins; P: (guide link, slider link)."""


@dataclass(frozen=True)
class AssurGroup:
    """A class-II, order-2 Assur group (dyad) of links j, k.

    `pairs` = (outer pair of j, inner pair j-k, outer pair of k); `kind` reads their kinds in
    that order. For RPR, j is the slider of the inner prismatic pair and k carries the guide.
    `known` = (link that j's outer pair joins, link that k's outer pair joins).
    """
    kind: str
    links: tuple[int, int]
    pairs: tuple[KinematicPair, KinematicPair, KinematicPair]   # the model's Pair objects
    known: tuple[int, int]
    branch: int
    klass = 2     # the group's class (Assur-Artobolevsky)

    @property
    def vid(self) -> str:
        """The kind's number as the texts give it ("вид")."""
        return f"kind {GROUP_KINDS[self.kind]}"

    @property
    def sides(self) -> tuple[tuple[int, KinematicPair, KinematicPair, int], ...]:
        """(link, its outer pair, the inner pair, the known link) of j and of k."""
        return ((self.links[0], self.pairs[0], self.pairs[1], self.known[0]),
                (self.links[1], self.pairs[2], self.pairs[1], self.known[1]))

    @property
    def label(self) -> str:
        return f"II({self.links[0]},{self.links[1]})" if self.links[0] < self.links[1] \
            else f"II({self.links[1]},{self.links[0]})"

    def describe(self) -> str:
        """One line for the structure listing: links, outer and inner pairs, branch."""
        outer_j, inner, outer_k = self.pairs
        return (f"{self.label}  {self.kind} ({self.vid})  links {self.links[0]}, {self.links[1]}; "
                f"outer pairs {outer_j.label}, {outer_k.label} (to links {self.known[0]}, {self.known[1]}), "
                f"inner {inner.label}; branch {self.branch:+d}")

    def __repr__(self) -> str:
        pairs = ", ".join(f"{p.kind}({p.links[0]},{p.links[1]})" for p in self.pairs)
        return f"AssurGroup({self.label} {self.kind}, pairs=[{pairs}], known={self.known}, branch={self.branch:+d})"


@dataclass(frozen=True)
class Triad:
    """The class-III, order-3 Assur group III3 of the base link `links[0]` and the leashes
    `links[1:]`: leash i joins the base at its inner pair `pairs[2i + 1]` and the link
    `known[i]`, already attached, at its outer pair `pairs[2i]`. A leash's pairs: both revolute
    (a two-pin leash); an outer prismatic pair, the guide on either link, and an inner revolute
    (a slider: the inner pin runs on a line carried by the known link); or an outer revolute and
    an inner prismatic, the guide on either link (the leash turns with the base: a line carried
    by the base runs through the outer pin). `kind` reads the outer pairs, e.g. "RRR" or "RRP",
    `inner` the inner pairs.
    Assur's special point S is where two leash axes meet: per angle the two that meet at the
    best angle (`triad.special_point`), any two may define it.
    The assembly mode is the one the model's points draw at the design position (no branch)."""
    kind: str
    links: tuple[int, int, int, int]
    pairs: tuple[KinematicPair, ...]
    known: tuple[int, int, int]
    branch: int = 0
    klass = 3

    @property
    def inner(self) -> str:
        """The inner pairs' kinds, leash by leash, e.g. "RRR" or "RRP"."""
        return "".join(self.pairs[2 * i + 1].kind for i in range(3))

    @property
    def vid(self) -> str:
        return f"III3 {self.kind}" + ("" if self.inner == "RRR" else f", inner {self.inner}")

    @property
    def sides(self) -> tuple[tuple[int, KinematicPair, KinematicPair, int], ...]:
        """(leash, its outer pair, its inner pair on the base, the known link) of each leash."""
        return tuple((self.links[1 + i], self.pairs[2 * i], self.pairs[2 * i + 1], self.known[i]) for i in range(3))

    @property
    def label(self) -> str:
        return "III(" + ",".join(map(str, sorted(self.links))) + ")"

    def describe(self) -> str:
        """One line for the structure listing: base, leashes with their outer and inner pairs."""
        leashes = "; ".join(f"leash {i + 1} link {self.links[1 + i]}: outer {self.pairs[2 * i].label} (to link "
                            f"{self.known[i]}), inner {self.pairs[2 * i + 1].label}" for i in range(3))
        inner = "" if self.inner == "RRR" else f", inner pairs {self.inner}"
        return (f"{self.label}  class III, order 3 (III3, outer pairs {self.kind}{inner})  base link {self.links[0]}; "
                f"{leashes}; mode: as drawn at the design position")

    def __repr__(self) -> str:
        pairs = ", ".join(f"{p.kind}({p.links[0]},{p.links[1]})" for p in self.pairs)
        return f"Triad({self.label} base {self.links[0]}, pairs=[{pairs}], known={self.known})"


@dataclass(frozen=True)
class Structure:
    """Mobility W = 3n - 2 p5 - p4 and the order in which groups are attached."""
    n: int
    p5: int
    p4: int
    groups: tuple[AssurGroup | Triad, ...]

    @property
    def W(self) -> int:
        return 3 * self.n - 2 * self.p5 - self.p4

    @property
    def formula(self) -> str:
        """The structure formula as the texts write it, e.g. I(0,1) <- II(2,3) <- II(4,5)."""
        return " <- ".join(["I(0,1)"] + [g.label for g in self.groups])

    @property
    def mechanism_class(self) -> int:
        """The highest class of its groups (1: the initial mechanism alone)."""
        return max((g.klass for g in self.groups), default=1)

    @property
    def order(self) -> int:
        """The highest order of its groups (a dyad 2, a triad III3 3)."""
        return max((g.klass for g in self.groups), default=1)

    def __repr__(self) -> str:
        return f"Structure(W={self.W}, formula={self.formula!r}, kinds={[g.kind for g in self.groups]})"

    def __str__(self) -> str:
        kinds = ", ".join(f"{g.label} {g.kind} ({g.vid})" for g in self.groups)
        return (f"W = 3*{self.n} - 2*{self.p5} - {self.p4} = {self.W}; {self.formula}; "
                f"class {self.mechanism_class}, order {self.order}; groups: {kinds or 'none'}")


def analyse_structure(n_links: int, pairs: Sequence[KinematicPair],
                      branches: Mapping[frozenset, int]) -> Structure:
    """Mobility and Assur-group decomposition of `n_links` links (frame included) joined by
    `pairs`: dyads, each of kinds RRR, RRP, RPR on its assembly branch `branches[{j, k}]` (+1 or
    -1), and triads III3. Raises StructureError for what is unsupported (class IV and higher)."""
    n = n_links - 1
    s = Structure(n, len(pairs), 0, ())
    if s.W != 1:
        raise StructureError(f"mobility W = 3*{n} - 2*{s.p5} - 0 = {s.W}; kinetostat analyses "
                             f"mechanisms with one degree of freedom (W = 1) driven at the crank")
    crank_frame = [p for p in pairs if set(p.links) == {0, 1}]
    if len(crank_frame) != 1 or crank_frame[0].kind != "R":
        raise StructureError("the crank (link 1) must be joined to the frame by exactly one revolute pair")

    groups = _groups(n_links, pairs, branches)
    remaining = set(range(2, n_links)).difference(*(g.links for g in groups))
    if remaining:
        raise StructureError(_unsupported(remaining, pairs))
    unused = set(branches) - {frozenset(g.links) for g in groups}
    if unused:
        raise StructureError(f"group: branch given for {[sorted(u) for u in unused]}, "
                             f"which is not an Assur group of this mechanism "
                             f"(groups: {[g.label for g in groups]})")
    return Structure(n, len(pairs), 0, tuple(groups))


#: The most paths the search for the most complex closed contour of a refused group walks.
CONTOUR_WALKS = 100_000


def _unsupported(remaining: set[int], pairs: Sequence[KinematicPair]) -> str:
    """The refusal of the links that split into no dyad or triad III3: per set of them joined by
    inner pairs (pairs between two of them), its links and its class by Artobolevsky's rule, the
    number of pairs of its most complex closed contour of inner pairs, a link with k inner pairs
    counting as a contour of k (`_contour`)."""
    adj: dict[int, list[int]] = {x: [] for x in remaining}
    for p in pairs:
        if set(p.links) <= remaining:
            adj[p.links[0]].append(p.links[1])
            adj[p.links[1]].append(p.links[0])
    parts, left = [], set(remaining)
    while left:
        part, todo = set(), [min(left)]
        while todo:
            x = todo.pop()
            if x not in part:
                part.add(x)
                todo += adj[x]
        left -= part
        cycle, whole = _contour(sorted(part), adj)
        hub = max(sorted(part), key=lambda x: len(adj[x]))
        klass = max(len(cycle), len(adj[hub]), 2)
        why = (f"its most complex closed contour of inner pairs, {'-'.join(map(str, cycle))}, has {len(cycle)} pairs"
               + ("" if whole else f" (or more: the search stopped after {CONTOUR_WALKS:,} paths)")
               if len(cycle) >= len(adj[hub]) else f"its link {hub} has {len(adj[hub])} inner pairs")
        parts.append(f"({','.join(map(str, sorted(part)))}) of class {_roman(klass)}{'+' if not whole else ''}: {why}")
    return (f"links {sorted(remaining)} do not split into class-II Assur groups (dyads) and class-III triads III3: "
            f"they form the group{'s' if len(parts) > 1 else ''} {'; '.join(parts)}; kinetostat solves dyads and "
            f"triads III3 only")


def _contour(nodes: list[int], adj: Mapping[int, list[int]]) -> tuple[tuple[int, ...], bool]:
    """The longest closed contour (links in order, at least 3) of the graph `adj` over `nodes`,
    by a depth-first walk of the simple paths from each link through higher ones (at most
    CONTOUR_WALKS paths), and whether the walk was whole."""
    best: tuple[int, ...] = ()
    walks = 0
    stack = [(s,) for s in reversed(nodes)]
    while stack and walks < CONTOUR_WALKS:
        path = stack.pop()
        walks += 1
        for y in sorted(adj[path[-1]], reverse=True):      # the lowest link walked first
            if y == path[0] and len(path) >= max(3, len(best) + 1):
                best = path
            elif y > path[0] and y not in path:
                stack.append(path + (y,))
    return best, not stack


def _roman(n: int) -> str:
    """n in Roman numerals, as the texts write a group's class."""
    out = ""
    for value, sign in ((1000, "M"), (900, "CM"), (500, "D"), (400, "CD"), (100, "C"), (90, "XC"), (50, "L"),
                        (40, "XL"), (10, "X"), (9, "IX"), (5, "V"), (4, "IV"), (1, "I")):
        count, n = divmod(n, value)
        out += sign * count
    return out


def _groups(n_links: int, pairs: Sequence[KinematicPair],
            branches: Mapping[frozenset, int]) -> list[AssurGroup | Triad]:
    """The groups in the order of attachment: each time, of the links not yet attached, the
    first dyad (j, k), j < k, joined to each other by one pair and each to the attached links by one
    pair; where no dyad is left, the first triad (`_triad`). Stops where neither is left. Work O(pairs x log links): per link its pairs to the
    attached links, kept as links attach; a heap of the dyads that may be next."""
    at: list[list[KinematicPair]] = [[] for _ in range(n_links)]
    between: dict[frozenset, int] = {}
    for p in pairs:
        for x in p.links:
            at[x].append(p)
        between[frozenset(p.links)] = between.get(frozenset(p.links), 0) + 1
    known: set[int] = set()
    out: list[list[KinematicPair]] = [[] for _ in range(n_links)]    # pairs to attached links
    heap: list[tuple[int, int]] = []
    other = lambda p, x: p.links[1] if p.links[0] == x else p.links[0]

    def attach(*links: int) -> None:
        known.update(links)
        for x in links:
            for p in at[x]:
                y = other(p, x)
                if y in known:
                    continue
                out[y].append(p)
                if len(out[y]) == 1:                 # y may now close a dyad with a neighbour
                    for q in at[y]:
                        z = other(q, y)
                        if z not in known and len(out[z]) == 1 and between[frozenset((y, z))] == 1:
                            heapq.heappush(heap, (min(y, z), max(y, z)))

    attach(0, 1)
    groups: list[AssurGroup | Triad] = []
    while True:
        while heap:
            j, k = heapq.heappop(heap)
            if j in known or k in known or len(out[j]) != 1 or len(out[k]) != 1:
                continue                             # attached since, or joined twice
            inner = next(p for p in at[j] if other(p, j) == k)
            groups.append(_orient(branches, j, k, out[j][0], inner, out[k][0]))
            attach(j, k)
        triad = _triad(n_links, at, known, out)
        if triad is None:
            return groups
        groups.append(triad)
        attach(*triad.links)


def _triad(n_links: int, at: Sequence[Sequence[KinematicPair]], known: set[int],
           out: Sequence[Sequence[KinematicPair]]) -> Triad | None:
    """The first triad III3 among the links not attached: a base link with exactly three pairs,
    none to an attached link, each to a leash that has exactly two pairs, one of them to an
    attached link. Raises StructureError, naming the group, the leash and its pairs, for a leash
    with two prismatic pairs (it only locks the base's angle to the known link's: no axis)."""
    for b in range(2, n_links):
        if b in known or out[b] or len(at[b]) != 3:
            continue
        leashes = [(set(p.links) - {b}).pop() for p in at[b]]
        if len(set(leashes)) != 3 or any(x in known or len(at[x]) != 2 or len(out[x]) != 1 for x in leashes):
            continue
        order = sorted(range(3), key=lambda i: leashes[i])
        pairs: list[KinematicPair] = []
        for i in order:
            x, inner, outer = leashes[i], at[b][i], out[leashes[i]][0]
            if inner.kind == "P" and outer.kind == "P":
                label = "III(" + ",".join(map(str, sorted([b, *leashes]))) + ")"
                raise StructureError(
                    f"triad {label}: leash {x} joins the base {b} by the prismatic pair {inner.label} and link "
                    f"{(set(outer.links) - {x}).pop()} by the prismatic pair {outer.label}; kinetostat takes a leash "
                    f"with at most one prismatic pair (two lock the base's angle to the known link's, a group "
                    f"the special point S does not solve)")
            pairs += [outer, inner]
        ls = tuple(leashes[i] for i in order)
        return Triad("".join(pairs[2 * i].kind for i in range(3)), (b, *ls), tuple(pairs),
                     tuple((set(pairs[2 * i].links) - {ls[i]}).pop() for i in range(3)))
    return None


def _orient(branches: Mapping[frozenset, int], j: int, k: int, pj: KinematicPair, pin: KinematicPair,
            pk: KinematicPair) -> AssurGroup:
    kind = pj.kind + pin.kind + pk.kind
    if kind not in GROUP_KINDS or (kind == "RPR" and pin.links[1] != j):
        j, k, pj, pk = k, j, pk, pj
        kind = kind[::-1]
    if kind not in GROUP_KINDS:
        raise StructureError(f"group II({min(j, k)},{max(j, k)}) of kind {kind} is not supported "
                             f"(kinds: {list(GROUP_KINDS)})")
    other = lambda p, x: (set(p.links) - {x}).pop()
    key = frozenset((j, k))
    if kind in ("RRR", "RRP", "RPR"):
        if key not in branches:
            raise StructureError(f"group II({min(j, k)},{max(j, k)}) ({kind}): assembly branch missing; "
                                 f"add [[group]] links = [{min(j, k)}, {max(j, k)}], branch = 1 or -1")
        branch = branches[key]
    else:
        branch = 1
    return AssurGroup(kind, (j, k), (pj, pin, pk), (other(pj, j), other(pk, k)), branch)
