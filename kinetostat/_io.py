"""Output files: atomic writes (a temporary file in the same folder, renamed into place), folder
names made from model file names, and the check that a written path stays inside its folder.

May use: the standard library only.
"""
from __future__ import annotations

import os
import re
import tempfile
from contextlib import contextmanager
from pathlib import Path
from typing import IO, Iterator

__all__ = ["atomic", "write_text", "write_bytes", "remove_temporary", "safe_name", "unique_names", "inside"]

#: The temporary files of the writes in progress in this process (`remove_temporary`).
_PENDING: set[str] = set()


def _file_mode(path: Path) -> int:
    """The mode of the file `path` replaces, or of a new file under the process's umask (a
    temporary file is created 0600)."""
    try:
        return path.stat().st_mode & 0o7777
    except FileNotFoundError:
        umask = os.umask(0)
        os.umask(umask)
        return 0o666 & ~umask


@contextmanager
def atomic(path: str | Path, binary: bool = False) -> Iterator[IO]:
    """A file opened for writing that becomes `path` only when the block ends normally.

    The data go to a temporary file in `path`'s folder (a short name of its own, so that a
    `path` of 255 bytes still works), which is flushed, given the mode of the file it replaces
    and `os.replace`d onto `path`: a reader never sees half a file. An exception in the block,
    a full disk or an interrupt (KeyboardInterrupt) removes the temporary file and leaves the
    old `path` as it was. Text is UTF-8; a name the file system cannot hold raises OSError.
    """
    path = Path(path)
    if path.is_dir():
        raise IsADirectoryError(21, "it is a directory", str(path))
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=".kinetostat-", suffix=".tmp")
    _PENDING.add(tmp)
    try:
        with (os.fdopen(fd, "wb") if binary else os.fdopen(fd, "w", encoding="utf-8", newline="")) as f:
            yield f
        os.chmod(tmp, _file_mode(path))
        os.replace(tmp, path)
    except BaseException:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        raise
    finally:
        _PENDING.discard(tmp)


def remove_temporary() -> None:
    """Remove the temporary files of the writes in progress: for a process about to end at once
    (`os._exit` in a signal handler), which leaves no `atomic` block to clean up after itself."""
    for tmp in list(_PENDING):
        try:
            os.unlink(tmp)
        except OSError:
            pass


def write_text(path: str | Path, text: str) -> Path:
    """`text` as UTF-8 into `path`, atomically (see `atomic`)."""
    with atomic(path) as f:
        f.write(text)
    return Path(path)


def write_bytes(path: str | Path, data: bytes) -> Path:
    """`data` into `path`, atomically (see `atomic`)."""
    with atomic(path, binary=True) as f:
        f.write(data)
    return Path(path)


def safe_name(text: str, fallback: str = "model") -> str:
    """A folder or file name made of `text`'s ASCII letters, digits, '_' and '-' (every other run
    of characters one '_'), at most 100 characters; `fallback` where nothing is left. Never '.',
    '..', a hidden name or a path."""
    s = re.sub(r"[^A-Za-z0-9_-]+", "_", str(text)).strip("_-")[:100].strip("_-")
    return s or fallback


def unique_names(texts: list[str], fallback: str = "model") -> list[str]:
    """`safe_name` of each text, made unique in the list by "-2", "-3", ... (case-insensitively,
    for file systems that ignore case), in the order given."""
    seen: set[str] = set()
    out = []
    for t in texts:
        base = safe_name(t, fallback)
        name, n = base, 1
        while name.lower() in seen:
            n += 1
            name = f"{base}-{n}"
        seen.add(name.lower())
        out.append(name)
    return out


def inside(root: str | Path, path: str | Path) -> Path:
    """`path`, after checking that it resolves (links followed) to a place inside `root`;
    ValueError otherwise."""
    r, p = Path(root).resolve(), Path(path).resolve()
    if p != r and r not in p.parents:
        raise ValueError(f"{path} is outside {root}")
    return Path(path)
