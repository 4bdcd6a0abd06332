"""Output files: atomic writes (a temporary file in the same folder, renamed into place; a device
or FIFO named by the user written as a stream), sets of files swapped in as a unit, folder names
made from model file names, and the check that a written path stays inside its folder.

May use: the standard library only.
"""
from __future__ import annotations

import os
import re
import secrets
import stat
from contextlib import contextmanager
from pathlib import Path
from typing import IO, Iterator

__all__ = ["atomic", "write_text", "write_bytes", "remove_temporary", "safe_name", "unique_names", "inside",
           "is_stream"]

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


def is_stream(path: str | Path) -> bool:
    """True where `path` (links followed) exists and is not a regular file or folder: a device
    (/dev/null, /dev/stdout on a terminal or a pipe), a FIFO or a socket."""
    try:
        mode = os.stat(path).st_mode
    except (OSError, ValueError):
        return False
    return not (stat.S_ISREG(mode) or stat.S_ISDIR(mode))


_TEMPORARY_FLAGS = os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_CLOEXEC", 0)


@contextmanager
def atomic(path: str | Path, binary: bool = False, stream: bool = False) -> Iterator[IO]:
    """A file opened for writing that becomes `path` only when the block ends normally.

    The data go to a temporary file in `path`'s folder (a short name of its own, so that a
    `path` of 255 bytes still works), which is flushed, given the mode of the file it replaces
    and `os.replace`d onto `path`: a reader never sees half a file. An exception in the block,
    a full disk or an interrupt (KeyboardInterrupt) removes the temporary file and leaves the
    old `path` as it was. Text is UTF-8; a name the file system cannot hold raises OSError.

    Only a regular file (or a link, which is replaced, never followed) is replaced. A device,
    FIFO or socket at `path` (links followed) is written as a stream where `stream` (a path the
    user named, e.g. `-o /dev/null`), else refused (OSError) and left as it was.
    """
    path = Path(path)
    if path.is_dir():
        raise IsADirectoryError(21, "it is a directory", str(path))
    if is_stream(path):
        if not stream:
            raise OSError(22, "not a regular file (a device, FIFO or socket); left as it is", str(path))
        with open(path, "ab" if binary else "a", **({} if binary else {"encoding": "utf-8", "newline": ""})) as f:
            yield f
        return
    tmp = None
    try:
        for _ in range(100):     # named before it exists: an interrupt at any moment leaves no file behind
            tmp = str(path.parent / f".kinetostat-{secrets.token_hex(6)}.tmp")
            _PENDING.add(tmp)
            try:
                fd = os.open(tmp, _TEMPORARY_FLAGS, 0o600)
                break
            except FileExistsError:          # another file's name: not ours to remove
                _PENDING.discard(tmp)
                tmp = None
        else:
            raise FileExistsError(17, "no free temporary name", str(path.parent))
        with (os.fdopen(fd, "wb") if binary else os.fdopen(fd, "w", encoding="utf-8", newline="")) as f:
            yield f
        os.chmod(tmp, _file_mode(path))
        os.replace(tmp, path)
    except BaseException:
        _remove(tmp)
        raise
    finally:
        _PENDING.discard(tmp)


def _remove(tmp: str | None) -> None:
    try:
        if tmp is not None:
            os.unlink(tmp)
    except OSError:
        pass


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
