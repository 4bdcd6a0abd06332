"""The bundled mechanisms (the seeds' worked cases): where they are, by name, and a copy of them.

    >>> import kinetostat
    >>> kinetostat.examples.names()[:2]
    ['chain_unit_four_bar', 'compressor']
    >>> mech = kinetostat.load("ice_crank_slider")          # a bundled model by name
    >>> kinetostat.examples.copy("my_models")               # doctest: +SKIP

The wheel carries the repository's `models/` folder as the package data `kinetostat/models/`; a
checkout (editable install) reads `models/` beside the package. `$KINETOSTAT_MODELS` overrides both.
May use: the standard library and `_io` (the model reader calls it to resolve a bare name).
"""
from __future__ import annotations

import errno
import os
import shutil
from pathlib import Path

__all__ = ["models_dir", "names", "path", "resolve", "hint", "copy"]


def models_dir() -> Path:
    """Folder of the bundled model files (`*.toml`, with `FORMAT.md`)."""
    env = os.environ.get("KINETOSTAT_MODELS")
    if env:
        return Path(env).expanduser()
    here = Path(__file__).resolve().parent
    for d in (here / "models", here.parent / "models"):     # wheel, then checkout
        if (d / "FORMAT.md").is_file():
            return d
    return here / "models"


def names() -> list[str]:
    """Names of the bundled models (file stems), sorted."""
    d = models_dir()
    return sorted(p.stem for p in d.glob("*.toml")) if d.is_dir() else []


def path(name: str) -> Path:
    """File of the bundled model `name` (stem, with or without `.toml`); FileNotFoundError if none."""
    stem = name[:-5] if name.endswith(".toml") else name
    if stem in names():
        return models_dir() / f"{stem}.toml"
    raise FileNotFoundError(f"no bundled model named {name!r}; bundled: {', '.join(names()) or 'none'}")


def resolve(model: str | Path) -> Path:
    """The file a user means by `model`: the path as given, or, where no such file exists and
    `model` is a bare name (`ice_crank_slider`, `ice_crank_slider.toml`), that bundled model."""
    p = Path(model)
    if not p.exists() and p.parent == Path(".") and p.suffix in ("", ".toml") and p.stem in names():
        return path(p.stem)
    return p


def hint(model: str | Path) -> str:
    """One line for a model file that does not exist but is named as a bundled model is
    (`models/ice_crank_slider.toml` run from a folder without it): that model's name and how to
    read it from any folder or copy it there; "" for any other path."""
    p = Path(model)
    if p.exists() or p.suffix not in ("", ".toml") or p.stem not in names():
        return ""
    return (f"{p.stem} is a bundled model: kinetostat.load({p.stem!r}) and `kinetostat report {p.stem}` read it "
            f"from any folder, `kinetostat examples --copy {p.parent}` copies the bundled models there")


def copy(dest: str | Path, overwrite: bool = False) -> list[Path]:
    """Copy every bundled model and FORMAT.md into the folder `dest` (created); returns the written files.

    Nothing is written if a file of that name (or a link, also a dangling one) is already there,
    unless `overwrite`: FileExistsError, its `filename` the first such file. NotADirectoryError if
    `dest` is a file. The files are copied as a set (`kinetostat._io.unit`): all or none; a link
    in the way is replaced, never followed."""
    from ._io import unit
    dest = Path(dest)
    if dest.exists() and not dest.is_dir():
        raise NotADirectoryError(f"{dest} is not a directory")
    src = [models_dir() / f"{n}.toml" for n in names()] + [models_dir() / "FORMAT.md"]
    clash = [dest / p.name for p in src if os.path.lexists(dest / p.name)]
    if clash and not overwrite:
        more = f" (and {len(clash) - 1} more of the {len(src)} files)" if len(clash) > 1 else ""
        raise FileExistsError(errno.EEXIST, f"already exists{more}", str(clash[0]))
    with unit(dest) as tmp:
        for p in src:
            shutil.copyfile(p, tmp / p.name)
    return [dest / p.name for p in src]
