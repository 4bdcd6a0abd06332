"""A rerun's report folder against an earlier one (the committed `reports/`): every number within
its tolerance, every other text equal, each difference named.

What a rerun may change: the last digits of an error at rounding level (they differ from machine
to machine), the libraries' versions, the figures' drawing. What it may not: anything else. So,
per model folder of the rerun (one holding a summary.json):

- the same file names;
- summary.json: equal, but each route's `worst` error within the route's stated `tolerance` (two
  errors both below ROUNDING, at rounding level, agree) and `published.worst_percent` within one
  unit of its last printed digit;
- cycle.csv.gz (`writer.CYCLE_FILE`, read decompressed): the same columns, units and rows; each
  value within TOLERANCES["reference"] (the solver's stated accuracy, 1e-11) of its unit's scale
  (the largest |value| of that unit, as the table is rounded: `kinetostat.tables.rounded`); an
  angle as the shortest turn, a reaction's angle weighed by the reaction (|R| times the turn in
  rad, against the force's tolerance); text and flags equal;
- the figures (.svg, .png) and page.html: present, not compared (drawn from the numbers above);
- every other text file (Markdown, HTML, segments.csv, worksheet.csv) and the folder's own
  index.md/index.html (but for its Studies section, listed where the studies' files are in the
  folder; line numbers of the rerun): equal line by line but for the versions after "made
  with", the numbers in e-notation (the error figures, checked in summary.json) and a relative
  1e-9 in other numbers (12 printed digits).

May use: numpy, zlib, `_io` (bounded reads of regular files), `kinetostat.tables` (reading the CSV),
the writer's CYCLE_FILE, the document's ROUNDING and the harness's tolerances (imported inside
`compare_reports`).
"""
from __future__ import annotations

import io
import json
import math
import re
import zlib
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Iterator

import numpy as np

from .._io import read_regular
from .document import ROUNDING
from .writer import CYCLE_FILE

#: Relative difference allowed in a number of a text file that is not in e-notation (12 digits printed).
TEXT_RTOL = 1e-9
#: Files of a folder whose content is not compared (figures).
FIGURES = (".svg", ".png")
#: Units compared as the shortest turn, and the turn in rad.
_TURN = {"deg": 360.0, "rad": 2 * math.pi}
_NUMBER = re.compile(r"(?<![\w.])[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?(?![\w.])")
_VERSIONS = re.compile(r"kinetostat \d\S*?(?:, [A-Za-z][\w-]* \d[^,\s]*?)*(?=\.?(?:\s|$|<))")
#: At most this many differences named per text file (the rest counted).
TEXT_LIMIT = 10
#: The most bytes of one report file that are read (an earlier output: a regular file only, `read_regular`).
MAX_REPORT_BYTES = 256 * 2**20


@dataclass(frozen=True)
class Difference:
    """One thing of a rerun that differs from the earlier report beyond its tolerance."""
    model: str          # the model's folder; "" for the folder's own index
    file: str           # the file's name; "" for the model's folder itself
    what: str           # the quantity, column (with its unit), key or "text"
    where: str          # the crank angle, line or route; "" where none
    fresh: str          # the rerun's value
    committed: str      # the earlier report's value
    tolerance: str      # what was allowed; "equal" where nothing is

    def __str__(self) -> str:
        at = "/".join(p for p in (self.model, self.file) if p) or "."
        where = f" at {self.where}" if self.where else ""
        return (f"{at}: {self.what}{where}: rerun {self.fresh}, committed {self.committed} "
                f"(tolerance: {self.tolerance})")


def _digit(x: float) -> float:
    """One unit in the third (last printed, ERROR_DIGITS) significant digit of `x`."""
    return 10.0 ** (math.floor(math.log10(abs(x))) - 2) if x else 0.0


def errors_agree(a: float | None, b: float | None, tolerance: float | None) -> bool:
    """Two error figures of the same check agree: equal, both below ROUNDING (at rounding level),
    or within max(`tolerance`, one unit in their last printed digit)."""
    if a is None or b is None:
        return a is b
    if a == b or (abs(a) < ROUNDING and abs(b) < ROUNDING):
        return True
    return abs(a - b) <= max(tolerance or 0.0, _digit(max(abs(a), abs(b))))


def _json(model: str, fresh: Any, old: Any, path: str = "") -> Iterator[Difference]:
    """The differences of two summary.json trees (`path`: the keys down to here, dotted)."""
    if isinstance(fresh, dict) and isinstance(old, dict):
        for k in dict.fromkeys([*old, *fresh]):
            key = f"{path}.{k}" if path else str(k)
            if k not in fresh or k not in old:
                yield Difference(model, "summary.json", key, "", "absent" if k not in fresh else json.dumps(fresh[k]),
                                 "absent" if k not in old else json.dumps(old[k]), "equal")
            elif k == "worst" and path.startswith("routes."):
                tol = fresh.get("tolerance") if fresh.get("tolerance") == old.get("tolerance") else None
                if fresh[k] != old[k] and (not _numbers(fresh[k], old[k]) or not errors_agree(fresh[k], old[k], tol)):
                    yield Difference(model, "summary.json", key, "", json.dumps(fresh[k]), json.dumps(old[k]),
                                     f"the route's {tol:g}, or both below {ROUNDING:.1e}" if tol else "equal")
            elif k == "worst_percent" and path == "published":
                if fresh[k] != old[k] and (not _numbers(fresh[k], old[k]) or not errors_agree(fresh[k], old[k], None)):
                    yield Difference(model, "summary.json", key, "", json.dumps(fresh[k]), json.dumps(old[k]),
                                     "one unit in the last printed digit")
            else:
                yield from _json(model, fresh[k], old[k], key)
    elif fresh != old or type(fresh) is not type(old):
        yield Difference(model, "summary.json", path, "", json.dumps(fresh), json.dumps(old), "equal")


def _numbers(*xs: Any) -> bool:
    return all(x is None or (isinstance(x, (int, float)) and not isinstance(x, bool)) for x in xs)


def _scales(df) -> dict[str, float]:
    """Each unit's scale in the table `df`: its largest finite |value| over the columns of that unit."""
    out: dict[str, float] = {}
    for name, col in df.items():
        if col.dtype.kind == "f":
            v = np.abs(col.to_numpy(dtype=float))
            v = v[np.isfinite(v)]
            unit = df.attrs["units"][name]
            out[unit] = max(out.get(unit, 0.0), float(v.max()) if v.size else 0.0)
    return out


def _cycle(model: str, fresh_path: Path, old_path: Path) -> Iterator[Difference]:
    """The differences of two cycle tables (CYCLE_FILE) (the rules of the module's docstring)."""
    from kinetostat.tables import read_csv
    from kinetostat_validation.compare import TOLERANCES

    rtol = TOLERANCES["reference"].peak_relative
    new, old = (read_csv(io.StringIO(_read_gzip(p))) for p in (fresh_path, old_path))
    head = [f"{c} [{new.attrs['units'][c]}]" for c in new.columns]
    was = [f"{c} [{old.attrs['units'][c]}]" for c in old.columns]
    if head != was or len(new) != len(old):
        yield Difference(model, CYCLE_FILE, "columns and rows", "", f"{len(head)} columns x {len(new)} rows",
                         f"{len(was)} columns x {len(old)} rows" + ("" if head == was else
                         f"; first differing column: {next((b for a, b in zip(head + [''], was + ['']) if a != b), '')!r}"),
                         "equal")
        return
    units, scale = old.attrs["units"], _scales(old)
    phi = old["phi_deg"].to_numpy(dtype=float)
    for c in old.columns:
        a, b = new[c], old[c]
        if b.dtype.kind != "f" or a.dtype.kind != "f":
            bad = np.flatnonzero(a.astype(str).to_numpy() != b.astype(str).to_numpy())
            if bad.size:
                k = int(bad[0])
                yield Difference(model, CYCLE_FILE, c, f"φ = {phi[k]:g}°", str(a.iloc[k]), str(b.iloc[k]), "equal")
            continue
        x, y = a.to_numpy(dtype=float), b.to_numpy(dtype=float)
        unit = units[c]
        with np.errstate(invalid="ignore"):        # inf - inf: an infinite value on both sides is equal
            d = np.where(x == y, 0.0, x - y)
        if unit in _TURN:
            d = (d + _TURN[unit] / 2) % _TURN[unit] - _TURN[unit] / 2
        tol, said = rtol * scale[unit], f"{rtol:g} of the {unit} scale {scale[unit]:.6g} {unit}"
        reaction = c[len("angle_"):] if c.startswith("angle_R_") else None
        if reaction in old.columns and unit in _TURN:      # the angle of a reaction: |R| times the turn
            force = units[reaction]
            d = np.abs(old[reaction].to_numpy(dtype=float)) * d * (2 * math.pi / _TURN[unit])
            tol, said = rtol * scale[force], f"|{reaction}| x turn within {rtol:g} of the {force} scale {scale[force]:.6g} {force}"
        d = np.where((np.isnan(x) & np.isnan(y)) | (x == y), 0.0, np.abs(d))
        d = np.where(np.isnan(d), np.inf, d)
        if d.size and float(d.max()) > tol:
            k = int(np.argmax(d))
            yield Difference(model, CYCLE_FILE, f"{c} [{unit}]", f"φ = {phi[k]:g}°", f"{x[k]:.12g}", f"{y[k]:.12g}", said)


def _normal(line: str) -> str:
    return _VERSIONS.sub("<versions>", line)


def _line(model: str, name: str, n: int, new: str, old: str) -> Difference | None:
    """The first difference of line `n` of two text files, or None where the two agree."""
    new, old = _normal(new), _normal(old)
    if new == old:
        return None
    a, b = _NUMBER.split(new), _NUMBER.split(old)
    xs, ys = _NUMBER.findall(new), _NUMBER.findall(old)
    if a != b or len(xs) != len(ys):
        return Difference(model, name, "text", f"line {n}", _excerpt(new, old), _excerpt(old, new), "equal")
    for x, y in zip(xs, ys):
        if "e" in x.lower() or "e" in y.lower():
            continue                                  # an error figure (or a tiny or huge value)
        u, v = float(x), float(y)
        if abs(u - v) > TEXT_RTOL * max(abs(u), abs(v)):
            return Difference(model, name, "number", f"line {n}", x, y, f"relative {TEXT_RTOL:g}")
    return None


def _excerpt(s: str, other: str, width: int = 60) -> str:
    """`s` around its first character that differs from `other`, quoted."""
    k = next((i for i, (p, q) in enumerate(zip(s, other)) if p != q), min(len(s), len(other)))
    lo = max(0, k - width // 2)
    return repr(("…" if lo else "") + s[lo:lo + width] + ("…" if lo + width < len(s) else ""))


#: The first line of the folder index's Studies section (Markdown, HTML) and of the section after it.
_STUDIES, _SECTION = re.compile(r'^(## Studies|<h2 id="studies">)'), re.compile(r"^(## |<h2[ >])")


def _without_studies(lines: list[str]) -> list[tuple[int, str]]:
    """(line number, line) of an index but for its Studies section: the studies are runs of their
    own, listed where their files are in the folder, not part of what `report` reruns."""
    out, inside = [], False
    for n, line in enumerate(lines, 1):
        inside = bool(_STUDIES.match(line)) or (inside and not _SECTION.match(line))
        if not inside:
            out.append((n, line))
    return out


def _text(model: str, name: str, fresh_path: Path, old_path: Path) -> Iterator[Difference]:
    new, old = (list(enumerate(_read(p).splitlines(), 1)) for p in (fresh_path, old_path))
    if not model:                                  # the folder's own index
        new, old = _without_studies([t for _, t in new]), _without_studies([t for _, t in old])
    found = [d for (n, a), (_, b) in zip(new, old) if (d := _line(model, name, n, a, b)) is not None]
    yield from found[:TEXT_LIMIT]
    if len(found) > TEXT_LIMIT:
        yield Difference(model, name, "text", "", f"{len(found) - TEXT_LIMIT} more lines differ", "", "equal")
    if len(new) != len(old):
        yield Difference(model, name, "lines", "", str(len(new)), str(len(old)), "equal")


def _read(path: Path) -> str:
    """The text of the report file `path`: a regular file of at most MAX_REPORT_BYTES (OSError else)."""
    return read_regular(path, MAX_REPORT_BYTES).decode("utf-8", "replace")


def _read_gzip(path: Path) -> str:
    """The text of the gzip-compressed report file `path`, at most MAX_REPORT_BYTES both as read
    and as decompressed (OSError else: a file cut short, not gzip, or a bomb)."""
    inflate = zlib.decompressobj(wbits=16 + zlib.MAX_WBITS)
    try:
        data = inflate.decompress(read_regular(path, MAX_REPORT_BYTES), MAX_REPORT_BYTES)
    except zlib.error as exc:
        raise OSError(0, f"not gzip ({exc})", str(path)) from None
    if inflate.unconsumed_tail:
        raise OSError(0, f"more than {MAX_REPORT_BYTES} bytes decompressed", str(path))
    if not inflate.eof:
        raise OSError(0, "cut short", str(path))
    return data.decode("utf-8", "replace")


def _file(model: str, name: str, fresh: Path, old: Path) -> Iterator[Difference]:
    try:
        yield from _compared(model, name, fresh, old)
    except OSError as exc:           # a FIFO, a device, too large: named, not waited on
        yield Difference(model, name, "file", "", "", f"not read ({exc.strerror or exc}): {exc.filename}",
                         "a regular file")


def _compared(model: str, name: str, fresh: Path, old: Path) -> Iterator[Difference]:
    if name == "summary.json":
        yield from _json(model, json.loads(_read(fresh)), json.loads(_read(old)))
    elif name == CYCLE_FILE:
        yield from _cycle(model, fresh, old)
    elif not name.endswith(FIGURES) and name != "page.html":
        yield from _text(model, name, fresh, old)


def compare_reports(fresh: str | Path, committed: str | Path) -> list[Difference]:
    """The differences of the report folder `fresh` (a rerun of `kinetostat report`) from
    `committed` (an earlier one: the repository's reports/), by the rules of the module's
    docstring, over the models of `fresh` (its subfolders holding a summary.json) and its
    index.md/index.html; empty when the rerun reproduces `committed`."""
    fresh, committed = Path(fresh), Path(committed)
    out: list[Difference] = []
    for name in ("index.md", "index.html"):
        if (fresh / name).is_file():
            if (committed / name).is_file():
                out += _text("", name, fresh / name, committed / name)
            else:
                out.append(Difference("", name, "file", "", "present", "absent", "equal"))
    for d in sorted(p for p in fresh.iterdir() if (p / "summary.json").is_file()):
        old = committed / d.name
        if not old.is_dir():
            out.append(Difference(d.name, "", "folder", "", "present", "absent", "equal"))
            continue
        names = {p.name for p in d.iterdir() if p.is_file()}
        before = {p.name for p in old.iterdir() if p.is_file()}
        out += [Difference(d.name, n, "file", "", "present" if n in names else "absent",
                           "present" if n in before else "absent", "equal") for n in sorted(names ^ before)]
        for n in sorted(names & before):
            try:
                out += list(_file(d.name, n, d / n, old / n))
            except (OSError, ValueError, KeyError) as exc:      # a cut-short JSON, a CSV without phi_deg
                out.append(Difference(d.name, n, f"file not readable ({type(exc).__name__}: {exc})", "", "", "",
                                      "equal"))
    return out
