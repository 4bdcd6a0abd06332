"""The immutable Mechanism: a planar one-degree-of-freedom linkage built once from its parts,
with its structure (mobility, Assur groups) derived, and read-only arrays derived on demand.

May use: the standard library, numpy, planar, structure, parts.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any, Callable, Mapping

import numpy as np

from ..planar import diameter
from ..structure import Structure, analyse_structure
from .parts import Drive, Flywheel, Friction, Link, Load, Pair, Published, Spring, Study


@dataclass(frozen=True)
class Mechanism:
    """A planar one-degree-of-freedom linkage. Build with `kinetostat.load`; never mutated."""
    name: str
    source: str
    assumptions: tuple[str, ...]
    g: float
    links: tuple[Link, ...]           # index = link id, links[0] is the frame
    pairs: tuple[Pair, ...]
    branches: Mapping[frozenset, int]
    loads: tuple[Load, ...]
    springs: tuple[Spring, ...]
    drive: Drive
    friction: Friction | None
    published: tuple[Published, ...] = ()   # the sources' printed values for this model
    path: str | None = None
    #: `[parameters]`: name -> value, in the file's order (overrides applied)
    parameters: Mapping[str, float] = field(default_factory=lambda: MappingProxyType({}))
    #: every field and parameter given as an expression: field path -> (expression, value)
    expressions: Mapping[str, tuple[str, float]] = field(default_factory=lambda: MappingProxyType({}))
    study: Study | None = None
    #: `[flywheel]`: a flywheel on the crank shaft (J, or delta to size it for), None: none given
    flywheel: Flywheel | None = None
    #: `[lettering]`: the names the model's source text uses (frame, M_bal, F_bal, loads, name,
    #: language), as given; read through `kinetostat.model.lettering.lettering`
    lettering: Mapping[str, Any] = field(default_factory=lambda: MappingProxyType({}))
    #: Structural analysis (mobility, Assur groups, structure formula), derived from the pairs
    #: when the mechanism is built; raises StructureError for what kinetostat does not analyse.
    structure: Structure = field(init=False, repr=False, compare=False)
    # memo of quantities derived from the (immutable) data, e.g. the strokes of travel tables
    _derived: dict = field(default_factory=dict, repr=False, compare=False)

    def __post_init__(self):
        object.__setattr__(self, "structure", analyse_structure(self.n_links, self.pairs, self.branches))

    def __repr__(self) -> str:
        return (f"Mechanism(name={_abbreviate(self.name)!r}, links={self.n_links}, pairs={len(self.pairs)}, "
                f"structure={self.structure.formula!r}, drive={self.drive.kind} {self.drive.omega:.4g} rad/s)")

    @property
    def n_links(self) -> int:
        """Number of links including the frame."""
        return len(self.links)

    def point_owner(self, name: str) -> int:
        """Id of the first link that carries point `name`."""
        for link in self.links:
            if name in link.points:
                return link.id
        raise KeyError(f"unknown point {name!r}. Valid names: {sorted(self.point_names)}")

    @property
    def point_names(self) -> list[str]:
        seen: dict[str, None] = {}
        for link in self.links:
            seen.update(dict.fromkeys(link.points))
        return list(seen)

    def pair_between(self, i: int, j: int) -> Pair:
        for p in self.pairs:
            if set(p.links) == {i, j}:
                return p
        raise KeyError(f"no kinematic pair between links {i} and {j}. "
                       f"Pairs: {[p.label for p in self.pairs]}")

    def memo(self, key: Any, make: Callable[[], Any]) -> Any:
        """make(), computed once per key and kept; its arrays (alone or in a tuple) read-only, so
        that no caller can change what later analyses read."""
        if key not in self._derived:
            value = make()
            for a in value if isinstance(value, tuple) else (value,):
                if isinstance(a, np.ndarray):
                    a.flags.writeable = False
            self._derived[key] = value
        return self._derived[key]

    @property
    def inertia_arrays(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(mass (L,), I_S (L,), centre of mass in the local frame (L,) complex), read-only."""
        return self.memo("inertia", lambda: (
            np.array([link.mass for link in self.links]), np.array([link.I_S for link in self.links]),
            np.array([complex(*link.points[link.com]) if link.com else 0j for link in self.links])))

    @property
    def points_z(self) -> tuple[Mapping[str, complex], ...]:
        """Every link's points in its local frame as complex numbers x + iy, read-only."""
        return self.memo("points_z", lambda: tuple(
            MappingProxyType({n: complex(*xy) for n, xy in link.points.items()}) for link in self.links))

    @property
    def size(self) -> float:
        """Characteristic length: the largest distance between two points of one link, m."""
        return self.memo("size", self._largest_link)

    def _largest_link(self) -> float:
        return max((extent(link.points.values()) for link in self.links[1:]), default=0.0) or 1.0



def extent(points) -> float:
    """Largest distance between two of `points` ((x, y) pairs), m."""
    return diameter(complex(*xy) for xy in points)


def _abbreviate(text: str, limit: int = 90) -> str:
    """`text` cut to `limit` characters with an ellipsis: a name as a summary shows it."""
    return text if len(text) <= limit else text[:limit - 1] + "\u2026"
