"""The model's checks that are not one field's: how pairs, points and links fit together (a
contradiction is an error), and what loads but looks like a mistake (a ModelWarning). Each is
a function yielding its messages; the reader records them.

May use: the standard library, expressions, limits, parts, mechanism, units.
"""
from __future__ import annotations

import math
from types import MappingProxyType
from typing import Iterator, Mapping

from ..expressions import parse as parse_expression
from ..units import PRESSURES, parameter_units
from .limits import FASTEST_PIN, FORCE_SCALE, FRICTION_F, GYRATION_SPANS, JOURNAL_SPANS, LARGEST_LINK
from .mechanism import Mechanism, extent
from .parts import Friction, Link, Pair, Vec


def check_pairs(links: list[Link], pairs: list[Pair], coincident: Mapping[int, str],
                slider_axes: set[int]) -> Iterator[str]:
    """What the pairs read say against each other and the links: a pair given twice, a link of
    coincident points outside a prismatic pair, a slider_axis of a link in two prismatic pairs,
    a point whose table columns would be a pair's, a point name on two links not joined there."""
    seen: dict[frozenset, int] = {}
    for p in pairs:
        key = frozenset(p.links)
        if key in seen:
            yield f"pair[{p.index}]: links {sorted(key)} are already joined by pair[{seen[key]}]"
        seen[key] = p.index
    in_p = {k for p in pairs if p.kind == "P" for k in p.links}
    for lid, where in coincident.items():
        if lid not in in_p:     # a guide or a slider takes its direction from its pair
            yield f"{where}.points: all points coincide (zero-length link)"
    sliders = [p.links[1] for p in pairs if p.kind == "P"]
    for n in slider_axes:
        if sliders.count(pairs[n].links[1]) > 1:
            yield (f"pair[{n}].slider_axis: link {pairs[n].links[1]} slides in more than one prismatic pair; "
                   f"give its points in the frame of its guides instead")
    # the CSV columns of a point (x_P, vx_P, ...) must not be those of a prismatic pair (x_i_j)
    for p in pairs:
        name = f"{p.links[0]}_{p.links[1]}"
        for link in links if p.kind == "P" else ():
            if name in link.points:
                yield (f"{'frame' if link.id == 0 else f'link[id={link.id}].points'}.{name}: the point's "
                       f"table column x_{name} would be that of prismatic pair {p.label} (x_{name}, the "
                       f"line of its normal force): rename the point")
    # a point name on two links must be the revolute pair that joins them (or a chain of
    # revolute pairs at that point: several links on one pin)
    owners: dict[str, list[int]] = {}
    for link in links:
        for name in link.points:
            owners.setdefault(name, []).append(link.id)
    pins: dict[str, list[tuple[int, int]]] = {}
    for p in pairs:
        if p.kind == "R":
            pins.setdefault(p.point, []).append(p.links)
    for name, ids in owners.items():
        if len(ids) > 1:
            comp = _components(pins.get(name, []))
            for a, b in zip(ids, ids[1:]):
                if comp.get(a, -a - 1) != comp.get(b, -b - 1):
                    yield (f"point {name!r} is on links {a} and {b}, which share no revolute pair "
                           f"at {name!r}: rename one of them")


def missing_radii(friction: Friction | None, pairs: list[Pair]) -> Iterator[str]:
    """Friction losses need the journal radius of every revolute pair, or a default one."""
    if friction is not None and friction.radius is None:
        for p in pairs:
            if p.kind == "R" and p.radius is None:
                yield (f"pair[{p.index}].radius: missing; friction losses need the journal radius "
                       f"of every revolute pair (or a default friction.radius)")


def doubts(mech: Mechanism, group_tables: Mapping[frozenset, tuple[int, tuple]],
           slider_axes: set[int], text: str = "") -> Iterator[tuple[str, str]]:
    """(field path, message) for what loads but looks like a mistake: a number far out of
    the usual, or a rule the file relies on that is easily misread. `text`: the model file's
    (its comments state the parameters' units)."""
    crank = mech.links[1].points
    r = math.dist(crank[mech.drive.pivot], crank[mech.drive.point])
    if mech.size > LARGEST_LINK or r * mech.drive.omega > FASTEST_PIN:
        yield "link", (f"the largest link spans {mech.size:.4g} m and the crank pin moves at "
                       f"{r * mech.drive.omega:.4g} m/s: lengths are read in metres; was the model drawn "
                       f"in millimetres? (warned above {LARGEST_LINK:g} m or {FASTEST_PIN:g} m/s)")
    if mech.g and not 1.0 <= mech.g <= 100.0:
        yield "mechanism.g", (f"{mech.g:g} m/s^2 is far from the 9.81 of the texts (warned outside 1..100): "
                              f"is it in m/s^2? (0 switches gravity off)")
    for link in mech.links[1:]:
        span = extent(link.points.values())
        if link.mass > 0 and span > 0 and math.sqrt(link.I_S / link.mass) > GYRATION_SPANS * span:
            yield f"link[id={link.id}].I_S", (
                f"{link.I_S:.4g} kg m^2 gives a radius of gyration of {math.sqrt(link.I_S / link.mass):.4g} m, "
                f"more than {GYRATION_SPANS:g} times the link's span {span:.4g} m: is it in kg m^2? "
                f"(g mm^2 is 1e-9 kg m^2, kg mm^2 1e-6)")
    scale = FORCE_SCALE * max([mech.g * link.mass for link in mech.links]
                              + [link.mass * extent(link.points.values()) * mech.drive.omega**2 for link in mech.links])
    for n, ld in enumerate(mech.loads):
        if ld.kind == "force" and ld.table is not None and 0 < max(map(abs, ld.table.value)) * abs(ld.table.scale) < scale:
            peak = max(map(abs, ld.table.value)) * abs(ld.table.scale)
            yield f"load[{n}].table.scale", (
                f"the diagram's largest force is {peak:.4g} N, below {FORCE_SCALE:g} of the mechanism's weights "
                f"and inertia forces ({scale / FORCE_SCALE:.4g} N): is a pressure in MPa multiplied by an area "
                f"in m^2? (scale in N per table unit: 1 MPa = 1e6 Pa)")
    yield from friction_doubts(mech)
    yield from _pressure_doubts(mech, text)
    for g in mech.structure.groups:
        n, listed = group_tables.get(frozenset(g.links), (None, ()))
        if g.kind == "RRR" and n is not None and listed[0] > listed[1]:
            yield f"group[{n}].links", (
                f"{list(listed)}: in an RRR group j is the lower id, {listed[1]} (P on link {listed[1]}), "
                f"whatever the order listed; if branch was computed with j = {listed[0]}, flip its sign; "
                f"list the links as {sorted(listed)} to silence this warning")
    for p in mech.pairs:
        slider = mech.links[p.links[1]]
        if p.kind != "P" or abs(p.alpha) <= 1e-9 or p.index in slider_axes:
            continue                  # a guide along x (to rounding): both readings are the same
        y0 = slider.points[p.point][1]
        off = [n for n, xy in slider.points.items() if abs(xy[1] - y0) > 1e-9 * mech.size]
        if off:
            yield f"pair[{p.index}]", (
                f"slider link {slider.id}'s points are read in a frame whose x axis runs along the guide "
                f"(direction {list(p.direction)} in link {p.links[0]}'s frame), and {off[0]!r} lies "
                f"{abs(slider.points[off[0]][1] - y0):.4g} m off the guide line in it; if the points were "
                f"drawn in another frame (e.g. the world's), give slider_axis = the guide direction in "
                f"that frame (slider_axis = [1.0, 0.0] confirms the default)")


def friction_doubts(mech: Mechanism) -> Iterator[tuple[str, str]]:
    """(field path, message) for friction figures far out of the usual: f above FRICTION_F, a
    journal radius in use (a revolute pair's own, or the default) above JOURNAL_SPANS x the
    largest link."""
    fr = mech.friction
    if fr is None:
        return
    if fr.f > FRICTION_F:
        yield "friction.f", (f"{fr.f:g} is a friction angle of {math.degrees(math.atan(fr.f)):.3g} deg (warned above "
                             f"{FRICTION_F:g}; metal pairs take 0.01 .. 0.3): is it a percentage or an angle?")
    limit = JOURNAL_SPANS * mech.size
    used = {("friction.radius" if p.radius is None else f"pair[{p.index}].radius"): (fr.radius if p.radius is None else p.radius)
            for p in mech.pairs if p.kind == "R"}
    for path, r in used.items():
        if r is not None and r > limit:
            yield path, (f"a journal radius of {r:.4g} m is more than {JOURNAL_SPANS:g} of the largest link "
                         f"({mech.size:.4g} m): is it in metres? (f r = {fr.f * r:.4g} m is the friction circle)")


def _pressure_doubts(mech: Mechanism, text: str) -> Iterator[tuple[str, str]]:
    """A force diagram's scale (N per table unit) that reads a pressure parameter (its unit as
    the model file `text` states it): stated in another unit than Pa (the file's SI), or
    combined with values beyond 1, which are then not the fractions of that pressure (p/p_max)
    that such a scale (area x p_max) multiplies."""
    for n, ld in enumerate(mech.loads):
        path = f"load[{n}].table.scale"
        if ld.kind != "force" or ld.table is None or path not in mech.expressions:
            continue
        read = parse_expression(mech.expressions[path][0]).names & set(mech.parameters)   # it parsed when read
        units = parameter_units(mech, text, sorted(read))
        for name in sorted(p for p in read if units[p] in PRESSURES):
            if units[name] != "Pa":
                yield path, (f"reads parameters.{name}, stated in {units[name]}; the scale is in N per table unit "
                             f"and the file's units are SI: give {name} in Pa (1 {units[name]} = "
                             f"{PRESSURES[units[name]]} Pa)")
            elif max(map(abs, ld.table.value)) > 1:
                yield f"load[{n}].table.value", (
                    f"the diagram's values reach {max(map(abs, ld.table.value)):.4g}, but its scale "
                    f"(\"{mech.expressions[path][0]:.60}\" = {ld.table.scale:.6g} N) already holds the pressure "
                    f"parameters.{name}: the values are then fractions of it (at most 1); are they pressures "
                    f"(MPa)? Give them as p/{name}, or a scale of the area alone (m^2, values in Pa)")


def turned_slider(link: Link, axis: Vec) -> Link:
    """The slider `link` with its points turned from the author's frame, in which the guide runs
    along `axis`, into the documented one, whose x axis runs along the guide."""
    turn = complex(*axis).conjugate()
    pts = {n: ((z := complex(*xy) * turn).real, z.imag) for n, xy in link.points.items()}
    return Link(link.id, link.name, MappingProxyType(pts), link.mass, link.I_S, link.com, link.bodies)


def _components(edges: list[tuple[int, int]]) -> dict[int, int]:
    """Connected components of the links joined by `edges`: link -> representative."""
    parent: dict[int, int] = {}

    def root(x: int) -> int:
        parent.setdefault(x, x)
        while parent[x] != x:
            parent[x] = parent[parent[x]]
            x = parent[x]
        return x

    for i, j in edges:
        parent[root(i)] = root(j)
    return {x: root(x) for x in parent}
