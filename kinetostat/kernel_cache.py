"""The folder of the compiled kernels, and what of it is trusted.

`fast` generates each kernel as a Python module and compiles it with numba's disk cache, so
that a later process loads the machine code instead of compiling it again. Two kinds of file
in that folder would run as code if they were planted: the module itself, and numba's cache of
it (`__pycache__/*.nbi`, `*.nbc`: pickles, unpickled when the kernel is first called). So:

- `folder()` is the cache folder (`cache_dir`) only where this user alone can write it and every
  folder above it (`untrusted`: owned by this user or root, writable by nobody else unless
  sticky, as OpenSSH checks a key's path); a folder it creates is made 0700. Anywhere else,
  one warning (`KernelCacheWarning`) and a private temporary folder of this process instead,
  removed when the process exits.
- `load(text)` never imports the file: it runs `text` itself, the source generated now, so
  Python's bytecode cache (`__pycache__/*.pyc`) is never read. The file on disk, which numba
  stamps its cache with, is compared byte for byte with `text` and rewritten where it differs
  (missing, empty, cut short, foreign, not a regular file); numba's pickles of that module are
  removed whenever it is.
- numba's pickles are signed: once numba has saved them, an HMAC-SHA256 of every pickle of the
  module (`k<hash>.sig` beside them) under this user's key (`key_path()`: 32 random bytes,
  0600, kept outside the cache folder). Before numba reads them, the signature is checked, and
  pickles it does not hold (planted, restored from another machine or user, cut short, written
  by an earlier version) are removed unread, so that numba compiles afresh. The pickles are read
  only from a trusted folder: where numba would keep them elsewhere (NUMBA_CACHE_DIR) and that
  folder is not trusted, the kernel compiles in memory, with one warning.
- a kernel's first compile holds a lock (`k<hash>.lock` beside numba's pickles, `flock`): of
  processes asking for the same kernel at once (test workers), one compiles it and the others,
  waiting, load what it saved. No lock on Windows.

What is trusted, then: the key file, and pickles it signed in a folder only this user can write.
A kernel cache restored from elsewhere (a CI cache of an untrusted branch) is not: its pickles
are removed and compiled again. Where the key cannot be kept (no writable home), one warning,
and a key of this process: kernels are then compiled once per process. On Windows the folders'
owners and permissions are not checked.

May use: the standard library, numba (its cache object), and `_io` (atomic writes, bounded reads).
"""
from __future__ import annotations

import atexit
import hashlib
import hmac
import os
import secrets
import shutil
import stat
import sys
import tempfile
import threading
import types
import warnings
from pathlib import Path

try:
    import fcntl
except ImportError:                       # Windows: no lock of the first compile
    fcntl = None

from ._io import read_regular, write_bytes

__all__ = ["CACHE_ENV", "KernelCacheWarning", "cache_dir", "key_path", "folder", "untrusted", "load"]

#: The environment variable naming the kernels' cache folder.
CACHE_ENV = "KINETOSTAT_CACHE"
#: The most bytes of numba's pickles of one kernel that are read to check their signature (a
#: kernel's are about 0.5 MB).
MAX_PICKLES = 256 * 2**20


class KernelCacheWarning(UserWarning):
    """The kernels' cache folder (or numba's cache of them) cannot be trusted or used: the kernels
    are compiled in a private temporary folder, or in memory, instead."""


def cache_dir() -> Path:
    """The folder of the generated kernel modules and numba's cache of them: $KINETOSTAT_CACHE,
    else $XDG_CACHE_HOME/kinetostat, else ~/.cache/kinetostat."""
    if os.environ.get(CACHE_ENV):
        return Path(os.environ[CACHE_ENV])
    base = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(base) / "kinetostat"


def untrusted(path: str | Path) -> str | None:
    """Why the folder `path` cannot be trusted with code (its words, to follow the path in a
    message), or None where only this user (and root) can write it and every folder above it.
    A folder above may be writable by others where it is sticky (/tmp). None on Windows."""
    if os.name != "posix":
        return None
    uid = os.geteuid()
    given = Path(os.path.abspath(path))
    for part in [given, *given.parents]:          # a link on the way another user could turn elsewhere
        try:
            st = os.lstat(part)
        except OSError:
            continue
        if stat.S_ISLNK(st.st_mode) and st.st_uid not in (0, uid):
            return f"is reached through the link {part}, owned by another user (uid {st.st_uid})"
    real = Path(os.path.realpath(path))
    try:
        st = os.stat(real)
    except OSError as exc:
        return f"cannot be read ({exc.strerror})"
    if not stat.S_ISDIR(st.st_mode):
        return "is not a folder"
    if st.st_uid != uid:
        return f"is owned by another user (uid {st.st_uid})"
    if st.st_mode & 0o022:
        return f"can be written by other users (mode {stat.filemode(st.st_mode)})"
    for above in real.parents:
        st = os.stat(above)
        if st.st_uid not in (0, uid):
            return f"lies in {above}, owned by another user (uid {st.st_uid})"
        if st.st_mode & 0o022 and not st.st_mode & stat.S_ISVTX:
            return f"lies in {above}, which other users can write (mode {stat.filemode(st.st_mode)})"
    return None


def key_path() -> Path:
    """The file of this user's key that signs numba's pickles of the kernels: outside the cache
    folder, in $XDG_CONFIG_HOME/kinetostat (else ~/.config/kinetostat)."""
    base = os.environ.get("XDG_CONFIG_HOME") or Path.home() / ".config"
    return Path(base) / "kinetostat" / "kernel-cache.key"


_LOCK = threading.Lock()
_SCRATCH: list[Path] = []        # this process's private temporary folder, once made
_KEY: list[bytes] = []           # the key, once read or made


def _read_key(path: Path) -> bytes:
    """The key at `path`, made first where missing (32 random bytes, 0600, linked into place
    whole); OSError or ValueError saying why it cannot be trusted."""
    path.parent.mkdir(mode=0o700, parents=True, exist_ok=True)
    if not os.path.lexists(path):
        tmp = path.with_name(f".{path.name}.{os.getpid()}.{secrets.token_hex(4)}")
        fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
        with os.fdopen(fd, "wb") as f:
            f.write(secrets.token_bytes(32))
        try:
            os.link(tmp, path)                 # whole or not at all; another process's key wins a race
        except FileExistsError:
            pass
        finally:
            tmp.unlink()
    why = untrusted(path.parent)
    st = os.lstat(path)
    if why is None and os.name == "posix" and (not stat.S_ISREG(st.st_mode) or st.st_uid != os.geteuid()
                                                or st.st_mode & 0o077):
        why = f"is not a file only you can read (mode {stat.filemode(st.st_mode)}, uid {st.st_uid})"
    key = b"" if why else read_regular(path, 64)
    if why is None and len(key) != 32:
        why = "is not a key kinetostat made"
    if why:
        raise ValueError(why)
    return key


def _key() -> bytes:
    """This user's key (`key_path`); where it cannot be kept or trusted, one warning and a key of
    this process (no kernel compiled by another process is then reused)."""
    with _LOCK:
        if not _KEY:
            path = key_path()
            try:
                _KEY.append(_read_key(path))
            except (OSError, ValueError) as exc:
                _warn(f"the kernel cache's key {path} {getattr(exc, 'strerror', None) or exc}: kernels compiled by "
                      f"other processes are not reused")
                _KEY.append(secrets.token_bytes(32))
        return _KEY[0]


def _scratch() -> Path:
    """This process's private temporary folder (0700, made once), removed when it exits."""
    if not _SCRATCH:
        _SCRATCH.append(Path(tempfile.mkdtemp(prefix="kinetostat-kernels-")))
        atexit.register(shutil.rmtree, _SCRATCH[0], True)
    return _SCRATCH[0]


def _warn(message: str) -> None:
    warnings.warn(message, KernelCacheWarning, stacklevel=4)


def folder() -> Path:
    """The folder the kernel modules are written to: `cache_dir()` (made 0700 where it is new)
    where it can be made and is trusted (`untrusted`), else this process's private temporary
    folder, with one `KernelCacheWarning` saying why."""
    wanted = cache_dir()
    try:
        wanted.parent.mkdir(parents=True, exist_ok=True)
        wanted.mkdir(mode=0o700, exist_ok=True)
        why = untrusted(wanted)
    except OSError as exc:
        why = f"cannot be made ({exc.strerror or exc})"
    if why is None:
        return wanted
    with _LOCK:
        fresh = not _SCRATCH
        scratch = _scratch()
    if fresh:
        _warn(f"the kernel cache {wanted} {why}: kernels are compiled in a private temporary folder for this "
              f"process ({scratch}); set {CACHE_ENV} to a folder only you can write to keep them")
    return scratch


def _rewrite(path: Path, data: bytes) -> bool:
    """Make the file `path` hold exactly `data` (a link, FIFO, device or folder there replaced, never
    followed or waited on); True where it had to be written."""
    try:
        if not path.is_symlink() and read_regular(path, len(data)) == data:
            return False
    except OSError:                       # not there, not a regular file, or longer than `data`
        pass
    if path.is_dir() and not path.is_symlink():
        shutil.rmtree(path)
    elif os.path.lexists(path) and not stat.S_ISREG(os.lstat(path).st_mode):
        path.unlink()
    write_bytes(path, data)
    return True


def _pickles(where: Path, stem: str) -> list[Path]:
    """numba's cache files of the module `stem` in its cache folder `where`."""
    return [p for p in where.glob(f"{stem}.*") if p.suffix in (".nbi", ".nbc")]


def _signature(where: Path, stem: str) -> bytes:
    """The HMAC-SHA256, under this user's key, of numba's pickles of the module `stem` in `where`
    (their names, sizes and bytes, in the order of their names)."""
    mac = hmac.new(_key(), digestmod="sha256")
    for p in sorted(_pickles(where, stem)):
        data = read_regular(p, MAX_PICKLES)
        mac.update(p.name.encode() + b"\0" + len(data).to_bytes(8, "little") + data)
    return mac.digest()


def _signed(where: Path, stem: str) -> bool:
    """Whether the pickles of `stem` in `where` are those this user's key signed."""
    try:
        return hmac.compare_digest(read_regular(where / f"{stem}.sig", 64), _signature(where, stem))
    except OSError:
        return False


def _unsign(where: Path, stem: str) -> None:
    """Remove the pickles of `stem` in `where` and their signature."""
    for p in [*_pickles(where, stem), where / f"{stem}.sig"]:
        p.unlink(missing_ok=True)


def _sign_cache(cache, where: Path, stem: str) -> None:
    """numba's disk cache `cache` of the kernel `stem` made to read only pickles this user's key
    signed (others removed unread first) and to sign what it saves."""
    load_overload, save_overload = cache.load_overload, cache.save_overload

    def load_signed(sig, target_context):
        if not _signed(where, stem):
            _unsign(where, stem)
        return load_overload(sig, target_context)

    def save_signed(sig, data):
        save_overload(sig, data)
        try:
            write_bytes(where / f"{stem}.sig", _signature(where, stem))
        except OSError:                   # unsigned: compiled again by the next process
            pass

    cache.load_overload, cache.save_overload = load_signed, save_signed


def _compile_locked(kernel, lock: Path) -> None:
    """numba's dispatcher `kernel` made to compile each new signature (or load it from its disk
    cache) holding an exclusive `flock` of the file `lock`, so that a process waiting on another's
    compile then loads its saved pickles. Unlocked where the file cannot be opened, or on Windows."""
    compile_ = kernel.compile

    def compile(sig):
        try:
            fd = os.open(lock, os.O_RDWR | os.O_CREAT | getattr(os, "O_NOFOLLOW", 0), 0o600)
        except OSError:
            return compile_(sig)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX)
            return compile_(sig)
        finally:
            os.close(fd)                  # releases the lock

    if fcntl is not None:
        kernel.compile = compile


def load(text: str) -> types.ModuleType:
    """The generated module `text`, run from the file k<hash of text>.py of `folder()`, which is
    made to hold `text` first; its `kernel`'s disk cache is numba's, reading only pickles this
    user's key signed, where that folder is trusted (the pickles removed where the file was
    rewritten) and compiling under a lock of other processes (`_compile_locked`), where that
    folder is trusted, else none."""
    from numba.core.caching import NullCache

    name = "k" + hashlib.sha256(text.encode()).hexdigest()[:20]
    home = folder()
    path = home / f"{name}.py"
    data = text.encode("utf-8")
    try:
        rewritten = _rewrite(path, data)
    except OSError as exc:                 # a folder that refuses the write: the private one
        home = _scratch()
        _warn(f"cannot write the kernel {path} ({exc.strerror or exc}): compiled in {home}")
        path = home / f"{name}.py"
        rewritten = _rewrite(path, data)
    module = types.ModuleType(f"kinetostat_kernel_{name}")
    module.__file__ = str(path)
    sys.modules[module.__name__] = module          # numba's cache finds the kernel's environment by module name
    exec(compile(text, str(path), "exec"), module.__dict__)
    kernel = module.kernel
    where = Path(kernel._cache.cache_path)         # where numba keeps (and would unpickle) the compiled code
    why = untrusted(where)
    if why is not None:
        _warn(f"numba's cache folder {where} {why}: the kernel {name} is compiled in memory, not cached")
        kernel._cache = NullCache()
    else:
        if rewritten:
            _unsign(where, name)
        _sign_cache(kernel._cache, where, name)
        _compile_locked(kernel, where / f"{name}.lock")
    return module
