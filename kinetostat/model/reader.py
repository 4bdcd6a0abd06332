"""The model reader: the raw TOML structure, checked section by section against the schema, into
an immutable Mechanism; every problem collected and reported at once, each with its field path
and line, and what only follows from a problem already reported left out.

May use: the standard library, errors, limits, mechanism, schema, checks, read_*.
"""
from __future__ import annotations

import warnings
from types import MappingProxyType

from ..errors import ModelError, ModelWarning, StructureError
from .checks import doubts, missing_radii
from .limits import MAX_PROBLEMS, MIN_G
from .mechanism import Mechanism
from .read_drive import DriveReading
from .read_links import LinkReading
from .read_loads import LoadReading
from .read_parameters import ParameterReading
from .read_records import RecordReading
from .schema import MECHANISM, MODEL


class _Reader(ParameterReading, LinkReading, DriveReading, LoadReading, RecordReading):
    """Reads the raw TOML structure, collecting every problem instead of stopping at the first."""

    def mechanism(self) -> Mechanism:
        d = self.data
        self.unknown_keys(d, MODEL.keys(), "<top level>")
        head = (self.read(MODEL, d, "mechanism", "") if "mechanism" in d else {}) or {}   # missing: its fields say so
        self.unknown_keys(head, MECHANISM.keys(), "mechanism")
        self.read_parameters(head)
        name = self.read(MECHANISM, head, "name", "mechanism")
        source = self.read(MECHANISM, head, "source", "mechanism")
        assumptions = self.read(MECHANISM, head, "assumptions", "mechanism") or ()
        g = self.read(MECHANISM, head, "g", "mechanism")
        if g is not None and 0 < g < MIN_G:
            self.err(f"mechanism.g: {g:g} m/s^2 is below {MIN_G:g}: the weights g m would lose their digits or "
                     f"vanish; write 0 to switch gravity off, or g in m/s^2 (9.81)")
            g = None

        links = self.links(g)
        pairs = self.pairs(links)
        drive = self.drive(links, pairs)
        branches = self.groups(links)
        loads_ = self.loads(links, pairs)
        springs = self.springs(links)
        friction = self.friction()
        flywheel = self.flywheel()
        published = self.published(links, pairs, drive)
        study = self.study(pairs)
        lettering = self.lettering(links, loads_)
        for msg in missing_radii(friction, pairs):
            self.err(msg)
        if self.problems:
            more = [f"... and {self.unshown} more problems (the first {MAX_PROBLEMS} are shown)"] if self.unshown else []
            raise ModelError(self.problems + more, source=self.source, lines=self.lines + [None] * len(more))
        try:
            mech = Mechanism(name=name, source=source, assumptions=tuple(assumptions), g=g,
                             links=tuple(links), pairs=tuple(pairs),
                             branches=MappingProxyType(branches), loads=tuple(loads_),
                             springs=tuple(springs), drive=drive, friction=friction,
                             published=tuple(published), path=self.source,
                             parameters=MappingProxyType({n: v for n, v in self.values.items() if n != "g"}),
                             expressions=MappingProxyType(self.expressions), study=study, lettering=lettering,
                             flywheel=flywheel)
        except StructureError as exc:
            raise StructureError(f"{self.source}: {exc}") from None
        for path, msg in doubts(mech, self.group_tables, self.slider_axes, self.text):
            line = self.line_of(path)
            warnings.warn(f"{self.source}: {'' if line is None else f'line {line}: '}{path}: {msg}",
                          ModelWarning, stacklevel=4)
        return mech
