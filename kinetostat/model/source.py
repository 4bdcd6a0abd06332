"""From a file, a text or a dict to a Mechanism: the file read safely (a regular file, bounded
size, UTF-8), the TOML parsed at a bounded cost (`parse_text`, once per text), then read by the
reader (`build`, once per set of parameters: a sweep's designs share one parsed text).

May use: the standard library, _io (`read_regular`), errors, expressions, examples, limits, lines, mechanism, reader.
"""
from __future__ import annotations

import tomllib
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Mapping

from .._io import FileTooLarge, NotRegularFile, read_regular
from ..errors import ModelError, ModelFileNotFound
from ..expressions import suggestion_budget
from .limits import _KEY_BYTES, _LEVEL_BYTES, MAX_FILE_BYTES, MAX_KEY, MAX_KEY_MEMORY
from .lines import _Lines
from .mechanism import Mechanism
from .reader import _Reader

def load(path: str | Path, parameters: Mapping[str, Any] | None = None) -> Mechanism:
    """Read and validate a model file (TOML), or a bundled model by name (`load("ice_crank_slider")`).
    `parameters`: values (numbers or expressions) that replace those of the file's `[parameters]`.

    Raises `ModelError` listing every problem (`ModelFileNotFound`, also a FileNotFoundError,
    where the file does not exist)."""
    from ..examples import resolve
    path = resolve(path)
    return loads(_read_text(path), source=str(path), parameters=parameters)


def _read_text(path: Path) -> str:
    """The text of a model file: a regular file (never a FIFO or a device, which would block or
    never end: `read_regular`) of at most MAX_FILE_BYTES, UTF-8."""
    try:
        raw = read_regular(path, MAX_FILE_BYTES)
    except FileNotFoundError:
        from ..examples import hint
        raise ModelFileNotFound(str(path), hint(path)) from None
    except NotRegularFile as exc:
        raise ModelError([f"cannot read file: {exc.kind}, not a regular file; a model is a regular TOML file"], source=str(path)) from None
    except FileTooLarge:
        raise ModelError([f"file is too large for a model (at most {MAX_FILE_BYTES} bytes, MAX_FILE_BYTES)"],
                         source=str(path)) from None
    except OSError as exc:
        raise ModelError([f"cannot read file: {exc.strerror}"], source=str(path)) from None
    try:
        return raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise ModelError([f"not UTF-8 text: byte 0x{exc.object[exc.start]:02x} at offset {exc.start}"],
                         source=str(path)) from None


def model_text(mech: Mechanism) -> str:
    """The text of `mech`'s model file as it is now (read as `load` reads it), "" where the model
    has no file or it can no longer be read."""
    try:
        return _read_text(Path(mech.path)) if mech.path else ""
    except ValueError:                  # ModelError: gone, not a regular file, too large, not UTF-8
        return ""


@dataclass(frozen=True)
class ParsedModel:
    """A model's text parsed once: its TOML structure and where its keys sit (for the messages'
    line numbers). `build` makes its Mechanism for any parameters without reading the text again;
    nothing here changes `data` (a design sweep's designs share it)."""
    text: str
    source: str
    data: Mapping[str, Any]
    lines: _Lines


def parse_text(text: str, source: str = "<string>") -> ParsedModel:
    """Parse a model's TOML text (at most MAX_FILE_BYTES characters, keys of bounded cost) once;
    ModelError for a text too large or not TOML."""
    if len(text) > MAX_FILE_BYTES:
        raise ModelError([f"a text of {len(text)} characters is too large for a model (at most {MAX_FILE_BYTES}, "
                          f"MAX_FILE_BYTES)"], source=source)
    _check_key_cost(text, source)
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ModelError([f"TOML syntax error: {exc}"], source=source) from None
    except RecursionError:
        raise ModelError(["TOML nested too deeply (arrays or tables within each other)"], source=source) from None
    return ParsedModel(text, source, data, _Lines(text))


def build(model: ParsedModel, parameters: Mapping[str, Any] | None = None) -> Mechanism:
    """The Mechanism of the parsed `model` with `parameters` (as for `load`): its expressions
    evaluated again, every field read and checked as `loads` does (it is `loads` without the parsing)."""
    with suggestion_budget():       # "did you mean" work bounded per model
        return _Reader(model.data, model.source, model.text, parameters, model.lines).mechanism()


def loads(text: str, source: str = "<string>", parameters: Mapping[str, Any] | None = None) -> Mechanism:
    """Parse a model from TOML text (at most MAX_FILE_BYTES characters); `parameters` as for `load`."""
    return build(parse_text(text, source), parameters)


def _check_key_cost(text: str, source: str) -> None:
    """Refuse keys whose parsing would take too much memory, before tomllib sees them: tomllib
    keeps the path of every level of every key, so memory grows with the number of keys and as
    the square of their depth (measured: 65 keys 3000 levels deep, 390 kB, took 2.3 GB)."""
    cost = 0
    for n, line in enumerate(text.splitlines(), 1):
        head = line.lstrip()
        key = head if head.startswith("[") else line.partition("=")[0]
        if len(key) > MAX_KEY:
            raise ModelError([f"line {n}: a key of {len(key)} characters (at most {MAX_KEY})"], source=source)
        if not head.startswith("#") and ("=" in line or head.startswith("[")):
            cost += _KEY_BYTES + _LEVEL_BYTES * (key.count(".") + 1) ** 2
            if cost > MAX_KEY_MEMORY:
                raise ModelError([f"line {n}: the keys up to here would take about {cost / 2**20:.0f} MiB to "
                                  f"parse (at most {MAX_KEY_MEMORY / 2**20:.0f} MiB): too many keys, or keys "
                                  f"nested too deeply (this one has {key.count('.') + 1} dotted parts)"],
                                 source=source)


def from_dict(data: Mapping[str, Any], source: str = "<dict>",
              parameters: Mapping[str, Any] | None = None) -> Mechanism:
    """Build a Mechanism from the parsed structure of a model file; `parameters` as for `load`."""
    with suggestion_budget():       # "did you mean" work bounded per model
        return _Reader(data, source, overrides=parameters).mechanism()
