"""Output files: atomic writes (a temporary file in the same folder, renamed into place; a device
or FIFO named by the user written as a stream), sets of files swapped in as a unit, the
leftovers of killed writes removed by the next write into their folder, folder names made from
model file names, and the check that a written path stays inside its folder. Input files and
earlier outputs: read whole only where regular and of bounded size (`read_regular`), so that a
FIFO never blocks and /dev/zero is never read.

May use: the standard library only.
"""
from __future__ import annotations

import hashlib
import os
import re
import secrets
import shutil
import signal
import socket
import stat
import threading
from contextlib import contextmanager
from pathlib import Path
from typing import IO, Iterator

__all__ = ["atomic", "write_text", "write_bytes", "remove_temporary", "remove_stale", "temporary_affixes",
           "safe_name", "unique_names", "inside", "is_stream", "unit", "read_regular", "NotRegularFile", "FileTooLarge",
           "open_append"]

#: The temporary files of the writes in progress in this process (`remove_temporary`).
_PENDING: set[str] = set()

#: The name of every temporary file or folder kinetostat writes: `.kinetostat-HOST-PID-RANDOM.tmp`,
#: HOST 8 hex digits of the machine's name, PID the writing process's id (`remove_stale`).
_TEMPORARY = re.compile(r"\.kinetostat-([0-9a-f]{8})-(\d{1,10})-\w+\.tmp")


def _host() -> str:
    """8 hex digits of this machine's name: a temporary name's HOST."""
    return hashlib.sha256(socket.gethostname().encode("utf-8", "surrogateescape")).hexdigest()[:8]


def temporary_affixes() -> tuple[str, str]:
    """The prefix and suffix of this process's temporary names (`_TEMPORARY`): for tempfile."""
    return f".kinetostat-{_host()}-{os.getpid()}-", ".tmp"


def _temporary_name(folder: Path) -> str:
    prefix, suffix = temporary_affixes()
    return str(folder / f"{prefix}{secrets.token_hex(6)}{suffix}")


def _running(pid: int) -> bool:
    """Whether process `pid` runs on this machine; True where that cannot be told (Windows,
    where signal 0 would end the process; a process of another user)."""
    if pid == os.getpid() or os.name == "nt":
        return True
    try:
        os.kill(pid, 0)
    except (ProcessLookupError, OverflowError):   # no such process; no process id is that large
        return False
    except OSError:
        return True
    return True


def remove_stale(folder: str | Path) -> None:
    """Remove the leftovers of killed writes from `folder` (SIGKILL, a power cut: no chance to
    clean up): the files and folders named as kinetostat names its temporary ones (`_TEMPORARY`)
    that were made on this machine by a process that no longer runs. A write running now in
    another process keeps its own; so does a leftover from another machine (a shared folder),
    and one whose process id another process has taken since (until that one ends)."""
    try:
        names = os.listdir(folder)
    except OSError:
        return
    host = _host()
    for name in names:
        m = _TEMPORARY.fullmatch(name)
        if m and m[1] == host and not _running(int(m[2])):
            _remove(os.path.join(folder, name))


class Interrupt:
    """Ctrl-C seen by the command line's handler (`kinetostat.cli.common`), also one whose
    KeyboardInterrupt was swallowed where it landed (a garbage-collection callback, a __del__):
    `checkpoint` raises it again, and a write calls it before it puts its file or set in place."""
    seen = False


def checkpoint() -> None:
    """Raise KeyboardInterrupt if Ctrl-C was pressed (`Interrupt`), also if its first raise was swallowed."""
    if Interrupt.seen:
        raise KeyboardInterrupt


def _file_mode(path: Path) -> int:
    """The mode of the file `path` replaces, or of a new file under the process's umask (a
    temporary file is created 0600)."""
    try:
        return path.stat().st_mode & 0o7777
    except FileNotFoundError:
        umask = os.umask(0)
        os.umask(umask)
        return 0o666 & ~umask


#: A name that stands for a process's open file: /proc/PID/fd/N, /dev/fd/N, /dev/stdin|stdout|stderr.
_STREAM_NAME = re.compile(r"/(proc/[^/]+/fd|dev/fd)/\d+|/dev/std(in|out|err)")


def _names_a_stream(path: str | Path) -> bool:
    """True where `path`, or a link on the way from it (at most 40 followed), is one of the
    _STREAM_NAME names: a process's own stdout or stderr even where that is a regular file."""
    p = os.path.abspath(path)
    for _ in range(40):
        p = os.path.join(os.path.realpath(os.path.dirname(p)), os.path.basename(p))   # its folder resolved
        if _STREAM_NAME.fullmatch(p):
            return True
        try:
            target = os.readlink(p)
        except (OSError, ValueError):                 # not a link, or not there
            return False
        p = os.path.join(os.path.dirname(p), target)
    return False


def _is_std_file(st: os.stat_result) -> bool:
    """True where `st` is the file this process's stdin, stdout or stderr is open on."""
    for fd in (0, 1, 2):
        try:
            s = os.fstat(fd)
        except OSError:
            continue
        if (s.st_dev, s.st_ino) == (st.st_dev, st.st_ino):
            return True
    return False


def is_stream(path: str | Path) -> bool:
    """True where `path` (links followed) exists and is not a regular file or folder: a device
    (/dev/null, /dev/stdout on a terminal or a pipe), a FIFO or a socket; or where it is, or links
    into, /proc/*/fd, /dev/fd or /dev/std* (e.g. /dev/stderr with stderr redirected to a file),
    or is the very file stdin, stdout or stderr is open on: never replaced by a new file."""
    try:
        st = os.stat(path)
    except (OSError, ValueError):
        return False
    return not (stat.S_ISREG(st.st_mode) or stat.S_ISDIR(st.st_mode)) or _names_a_stream(path) or _is_std_file(st)


_TEMPORARY_FLAGS = os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_CLOEXEC", 0)


@contextmanager
def atomic(path: str | Path, binary: bool = False, stream: bool = False) -> Iterator[IO]:
    """A file opened for writing that becomes `path` only when the block ends normally.

    The data go to a temporary file in `path`'s folder (a short name of its own, so that a
    `path` of 255 bytes still works; the leftovers of killed writes there are removed first,
    `remove_stale`), which is flushed, given the mode of the file it replaces
    and `os.replace`d onto `path`: a reader never sees half a file. An exception in the block,
    a full disk or an interrupt (KeyboardInterrupt) removes the temporary file and leaves the
    old `path` as it was, also a Ctrl-C whose KeyboardInterrupt was swallowed on the way
    (`checkpoint`). Text is UTF-8; a name the file system cannot hold raises OSError.

    Only a regular file (or a link, which is replaced, never followed) is replaced. A device,
    FIFO, socket or link to a process's own stream at `path` (`is_stream`) is written as a stream where `stream` (a path the
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
    remove_stale(path.parent)
    tmp = None
    try:
        for _ in range(100):     # named before it exists: an interrupt at any moment leaves no file behind
            tmp = _temporary_name(path.parent)
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
        checkpoint()
        os.replace(tmp, path)
    except BaseException:
        _remove(tmp)
        raise
    finally:
        _PENDING.discard(tmp)


def _remove(tmp: str | None) -> None:
    try:
        if tmp is not None and os.path.isdir(tmp) and not os.path.islink(tmp):
            shutil.rmtree(tmp)
        elif tmp is not None:
            os.unlink(tmp)
    except OSError:
        pass


@contextmanager
def _sigint_deferred() -> Iterator[None]:
    """Ctrl-C held back while the block runs (in the main thread; elsewhere nothing changes),
    then delivered to the handler that was in place."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    seen: list[int] = []
    old = signal.signal(signal.SIGINT, lambda signum, frame: seen.append(signum))
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, old)
        if seen:
            os.kill(os.getpid(), signal.SIGINT)


def _moves(tmp: Path, folder: Path, root: Path) -> list[tuple[Path, Path]]:
    """(file in `tmp`, its place in `folder`) for every file written into `tmp`; ValueError where
    a place would lie outside `folder` (a planted link to a folder elsewhere), OSError where it
    is neither a regular file nor a link (a device, a FIFO: never replaced). Places must resolve
    inside `root`."""
    moves = []
    for src in sorted(p for p in tmp.rglob("*") if not p.is_dir()):
        dst = folder / src.relative_to(tmp)
        inside(root, dst.parent)
        try:
            mode = os.lstat(dst).st_mode
        except FileNotFoundError:
            mode = None
        if mode is not None and (not (stat.S_ISREG(mode) or stat.S_ISLNK(mode)) or is_stream(dst)):
            raise OSError(22, "not a regular file (a device, FIFO, socket, folder or a stream's link); "
                          "left as it is", str(dst))
        if mode is not None and stat.S_ISREG(mode):
            os.chmod(src, mode & 0o7777)        # the mode of the file it replaces
        moves.append((src, dst))
    return moves


@contextmanager
def unit(folder: str | Path, root: str | Path | None = None) -> Iterator[Path]:
    """A set of files written as a unit into `folder` (created). The block writes them into a new
    hidden folder inside `folder` (the path yielded, same layout); when the block ends normally
    each file is renamed onto its place in `folder` (links in their way replaced, never
    followed; a place outside `folder` through a linked subfolder is ValueError, nothing moved),
    with Ctrl-C held back until the last rename: a reader sees the old set or the new one, never
    a mix. An exception, a full disk or an interrupt in the block (also one swallowed on the way,
    `checkpoint`) leaves `folder` as it was; the hidden folder is always removed (a killed
    write's, by the next write there, `remove_stale`). Files of `folder` the block did not write
    stay as they are.
    `root` (default `folder`): `folder` and every place written must resolve inside it (a
    `folder` that is a planted link to elsewhere: ValueError before anything is written)."""
    folder = Path(folder)
    root = folder if root is None else Path(root)
    if os.path.lexists(folder):
        inside(root, folder)
    folder.mkdir(parents=True, exist_ok=True)
    inside(root, folder)
    remove_stale(folder)
    tmp = None
    try:
        tmp = _temporary_name(folder)
        _PENDING.add(tmp)
        os.mkdir(tmp, 0o700)
        yield Path(tmp)
        moves = _moves(Path(tmp), folder, root)
        checkpoint()                    # a Ctrl-C swallowed while the set was written: the old set stays
        with _sigint_deferred():
            for src, dst in moves:
                dst.parent.mkdir(parents=True, exist_ok=True)
                os.replace(src, dst)
    finally:
        _remove(tmp)
        _PENDING.discard(tmp)


class NotRegularFile(OSError):
    """A file read as an input or an earlier output, or appended to, is not a regular file (a
    FIFO, a device, a socket or a directory, also through a link); `filename` names it, `kind`
    says what it is ("a FIFO")."""

    def __init__(self, path: str, mode: int):
        self.kind = ("a directory" if stat.S_ISDIR(mode) else "a FIFO" if stat.S_ISFIFO(mode) else
                     "a device" if stat.S_ISCHR(mode) or stat.S_ISBLK(mode) else
                     "a socket" if stat.S_ISSOCK(mode) else "not a regular file")
        super().__init__(22, f"{self.kind}, not a regular file; left as it is", path)


class FileTooLarge(OSError):
    """A file read as an input or an earlier output holds more bytes than its reader's limit;
    `filename` names it, `limit` is the limit in bytes."""

    def __init__(self, path: str, limit: int):
        super().__init__(27, f"larger than {limit} bytes, the most read", path)      # errno 27: EFBIG
        self.limit = limit


#: Opening flags of a file read or appended to: never waiting for a FIFO's other end.
_NO_WAIT = getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_CLOEXEC", 0)


def read_regular(path: str | Path, limit: int) -> bytes:
    """The bytes of the regular file `path` (links followed), at most `limit` of them.

    Opened without blocking (O_NONBLOCK: a FIFO with no writer does not hang the open) and
    checked on the opened descriptor (`fstat`, so that nothing can be swapped in between):
    `NotRegularFile` for a FIFO, device (/dev/zero, also through a link), socket or directory,
    `FileTooLarge` for more than `limit` bytes (also where the file grows while read). Other
    OSErrors (FileNotFoundError, PermissionError) as `os.open` raises them."""
    fd = os.open(path, os.O_RDONLY | _NO_WAIT)
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode):
            raise NotRegularFile(str(path), st.st_mode)
        if st.st_size > limit:
            raise FileTooLarge(str(path), limit)
    except BaseException:
        os.close(fd)
        raise
    with os.fdopen(fd, "rb") as f:
        data = f.read(limit + 1)
    if len(data) > limit:
        raise FileTooLarge(str(path), limit)
    return data


def open_append(path: str | Path) -> IO[str]:
    """`path` opened to append UTF-8 text, created where missing: a regular file only. Opened
    without blocking (a FIFO with no reader raises at once instead of waiting) and checked on
    the opened descriptor: `NotRegularFile` for a FIFO, device or socket."""
    fd = os.open(path, os.O_WRONLY | os.O_APPEND | os.O_CREAT | _NO_WAIT, 0o666)
    st = os.fstat(fd)
    if not stat.S_ISREG(st.st_mode):
        os.close(fd)
        raise NotRegularFile(str(path), st.st_mode)
    os.set_blocking(fd, True)
    return os.fdopen(fd, "a", encoding="utf-8")


def remove_temporary() -> None:
    """Remove the temporary files of the writes in progress: for a process about to end at once
    (`os._exit` in a signal handler), which leaves no `atomic` block to clean up after itself."""
    for tmp in list(_PENDING):
        _remove(tmp)


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
