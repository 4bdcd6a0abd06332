"""Hostile kernel cache (issue 35, class 1): a module or a numba pickle planted in the kernels'
cache folder never runs, also beside the right module (a cache restored from elsewhere: not signed
by this user's key); a folder others can write is bypassed with one warning; a corrupt entry
is rebuilt; the private fallback folder is removed on exit.

The generated module here is a one-line numba function with the kernel's name and disk cache
(`kernel_cache.load` takes any such text), so that each test compiles in a fraction of a second
instead of the seconds a mechanism's kernel takes; `test_a_mechanism_kernel_...` runs the real one.
"""
from __future__ import annotations

import hashlib
import importlib.util
import os
import pickle
import subprocess
import sys
import warnings
from pathlib import Path

import pytest

from kinetostat import kernel_cache
from kinetostat.kernel_cache import KernelCacheWarning

POSIX = pytest.mark.skipif(os.name != "posix", reason="owners and modes are POSIX")
TEXT = "import numba\ndef kernel(x):\n    return x + 1\nkernel = numba.njit(cache=True)(kernel)\n"
NAME = "k" + hashlib.sha256(TEXT.encode()).hexdigest()[:20]


class _Planted:
    """A pickle that creates the file `marker` when it is loaded (what an attacker plants)."""

    def __init__(self, marker: Path):
        self.marker = str(marker)

    def __reduce__(self):
        return (open, (self.marker, "w"))


@pytest.fixture
def cache(tmp_path, monkeypatch) -> Path:
    """An empty cache folder of this test (private: its parents are pytest's 0700 folder)."""
    folder = tmp_path / "cache"
    monkeypatch.setenv(kernel_cache.CACHE_ENV, str(folder))
    monkeypatch.delenv("NUMBA_CACHE_DIR", raising=False)
    monkeypatch.setattr(kernel_cache, "_SCRATCH", [])        # this test's own fallback folder, if any
    monkeypatch.setenv("XDG_CONFIG_HOME", str(tmp_path / "config"))    # and its own key
    monkeypatch.setattr(kernel_cache, "_KEY", [])
    return folder


def _plant_index(folder: Path, marker: Path) -> Path:
    """A numba cache index of NAME's kernel (numba's very file name) that runs code when read."""
    tag = f"py{sys.version_info.major}{sys.version_info.minor}"
    index = folder / "__pycache__" / f"{NAME}.kernel-2.{tag}.nbi"
    index.parent.mkdir(parents=True, exist_ok=True)
    index.write_bytes(pickle.dumps(_Planted(marker)))
    return index


def _load_and_call(expect_warning: bool = False):
    with warnings.catch_warnings(record=True) as seen:
        warnings.simplefilter("always")
        module = kernel_cache.load(TEXT)
        assert module.kernel(41) == 42
    ours = [w for w in seen if issubclass(w.category, KernelCacheWarning)]
    assert len(ours) == (1 if expect_warning else 0), [str(w.message) for w in ours]
    return module, (str(ours[0].message) if ours else "")


@POSIX
def test_a_foreign_module_is_rewritten_and_never_run(cache, tmp_path):
    marker = tmp_path / "ran"
    cache.mkdir(mode=0o700)
    (cache / f"{NAME}.py").write_text(f"open({str(marker)!r}, 'w')\nkernel = lambda x: x + 1\n")
    module, _ = _load_and_call()
    assert not marker.exists()
    assert (cache / f"{NAME}.py").read_text() == TEXT
    assert module.__file__ == str(cache / f"{NAME}.py")


@POSIX
def test_a_planted_bytecode_file_beside_the_right_module_is_never_run(cache, tmp_path):
    """Python's import would run a .pyc whose header matches the module's mtime and size."""
    marker = tmp_path / "ran"
    cache.mkdir(mode=0o700)
    source = cache / f"{NAME}.py"
    source.write_text(TEXT)
    st = source.stat()
    code = compile(f"open({str(marker)!r}, 'w')\nkernel = lambda x: x + 1\n", str(source), "exec")
    pyc = Path(importlib.util.cache_from_source(str(source)))
    pyc.parent.mkdir()
    pyc.write_bytes(importlib._bootstrap_external._code_to_timestamp_pyc(code, st.st_mtime, st.st_size))
    _load_and_call()
    assert not marker.exists()


@POSIX
def test_a_planted_numba_pickle_beside_a_foreign_module_is_removed_unread(cache, tmp_path):
    marker = tmp_path / "ran"
    cache.mkdir(mode=0o700)
    (cache / f"{NAME}.py").write_text(TEXT + "# foreign\n")
    index = _plant_index(cache, marker)
    module, _ = _load_and_call()
    assert module.kernel._cache._cache_file._index_path == str(index)      # the file numba reads
    assert not marker.exists()


@POSIX
@pytest.mark.parametrize("where", ["folder", "pycache"])
def test_a_folder_others_can_write_is_bypassed_with_one_warning(cache, tmp_path, where):
    """A world-writable cache folder (or numba's __pycache__ in it): the planted pickle stays
    unread, and the kernel is compiled in the private folder or in memory."""
    marker = tmp_path / "ran"
    cache.mkdir()
    (cache / f"{NAME}.py").write_text(TEXT)
    index = _plant_index(cache, marker)
    os.chmod(cache if where == "folder" else index.parent, 0o777)
    module, message = _load_and_call(expect_warning=True)
    assert "can be written by other users" in message and "\n" not in message
    assert not marker.exists()
    if where == "folder":
        assert Path(module.__file__).parent == kernel_cache._SCRATCH[0]
    else:
        assert "compiled in memory" in message


@POSIX
@pytest.mark.skipif(not hasattr(os, "geteuid") or os.geteuid() != 0, reason="chown needs root")
def test_a_folder_owned_by_another_user_is_bypassed(cache, tmp_path):
    marker = tmp_path / "ran"
    cache.mkdir(mode=0o700)
    (cache / f"{NAME}.py").write_text(f"open({str(marker)!r}, 'w')\n")
    os.chown(cache, 65534, 65534)
    _, message = _load_and_call(expect_warning=True)
    assert "owned by another user (uid 65534)" in message and not marker.exists()


@POSIX
def test_the_folder_is_made_private(cache):
    _load_and_call()
    assert cache.stat().st_mode & 0o777 == 0o700


@pytest.mark.parametrize("entry", ["empty", "cut short", "a folder", "a FIFO"])
def test_a_corrupt_entry_is_rebuilt(cache, entry):
    cache.mkdir(mode=0o700)
    path = cache / f"{NAME}.py"
    if entry == "empty":
        path.write_text("")
    elif entry == "cut short":
        path.write_text(TEXT[:30])
    elif entry == "a folder":
        path.mkdir()
    elif hasattr(os, "mkfifo"):
        os.mkfifo(path)
    else:
        pytest.skip("no FIFOs here")
    _load_and_call()
    assert path.is_file() and path.read_text() == TEXT


@POSIX
def test_the_private_fallback_folder_is_removed_on_exit(tmp_path):
    """A cache path that cannot be a folder: one warning line, and no kinetostat-* folder left."""
    blocker = tmp_path / "not-a-folder"
    blocker.write_text("")
    scratch = tmp_path / "tmp"
    scratch.mkdir()
    env = dict(os.environ, KINETOSTAT_CACHE=str(blocker), TMPDIR=str(scratch))
    script = ("from kinetostat import kernel_cache; m = kernel_cache.load(" + repr(TEXT) + "); "
              "assert m.kernel(1) == 2; import os; print(os.listdir(" + repr(str(scratch)) + "))")
    p = subprocess.run([sys.executable, "-c", script], env=env, capture_output=True, text=True, timeout=120)
    assert p.returncode == 0, p.stderr
    assert "kinetostat-kernels-" in p.stdout                      # it was used while the process ran
    assert list(scratch.iterdir()) == []                          # and is gone after it
    lines = [ln for ln in p.stderr.splitlines() if "KernelCacheWarning" in ln]
    assert len(lines) == 1 and "cannot be made" in lines[0], p.stderr


@POSIX
def test_a_mechanism_kernel_comes_from_a_planted_folder_unharmed(cache, tmp_path, monkeypatch):
    """The real path: `fast.kernel` of a bundled model with its module planted (a foreign file
    under its very name): the planted code never runs and the kernel's module is the generated one."""
    import kinetostat
    from kinetostat import fast
    monkeypatch.setattr(fast, "_KERNELS", {})
    m = kinetostat.load("chain_unit_four_bar")
    text = fast._module(fast._source(m, fast._layout(m), "full"))
    name = "k" + hashlib.sha256(text.encode()).hexdigest()[:20]
    marker = tmp_path / "ran"
    cache.mkdir(mode=0o700)
    (cache / f"{name}.py").write_text(f"open({str(marker)!r}, 'w')\nkernel = None\n")
    fn, _ = fast.kernel(m, "full")
    assert fn is not None and not marker.exists()
    assert (cache / f"{name}.py").read_text() == text


@pytest.mark.parametrize("index", [b"", b"\x80\x04garbage"])
def test_a_corrupt_numba_index_beside_the_right_module_is_rebuilt(cache, index):
    """Before: numba's EOFError (an empty index) or UnpicklingError on every call, never rebuilt."""
    cache.mkdir(mode=0o700)
    (cache / f"{NAME}.py").write_text(TEXT)
    tag = f"py{sys.version_info.major}{sys.version_info.minor}"
    path = cache / "__pycache__" / f"{NAME}.kernel-2.{tag}.nbi"
    path.parent.mkdir()
    path.write_bytes(index)
    module, _ = _load_and_call()
    assert module.kernel._cache._cache_file._index_path == str(path)      # the file numba reads
    assert path.stat().st_size > len(index)                                 # written anew by numba


@POSIX
def test_a_planted_pickle_beside_the_right_module_is_removed_unread_and_the_new_one_signed(cache, tmp_path):
    """A restored cache: the module is the generated one, its numba index planted. Not signed by
    this user's key, it is removed unread; what numba then saves is signed, and read back."""
    marker = tmp_path / "ran"
    cache.mkdir(mode=0o700)
    (cache / f"{NAME}.py").write_text(TEXT)
    index = _plant_index(cache, marker)
    module, _ = _load_and_call()
    assert not marker.exists()
    assert (cache / "__pycache__" / f"{NAME}.sig").stat().st_size == 32
    assert kernel_cache.key_path().stat().st_mode & 0o777 == 0o600
    again = kernel_cache.load(TEXT)                 # a kernel of its own: numba reads the signed pickles
    assert again.kernel(1) == 2 and sum(again.kernel.stats.cache_hits.values()) == 1
    index.write_bytes(index.read_bytes() + b"x")    # one byte more: the signature no longer holds
    third = kernel_cache.load(TEXT)
    assert third.kernel(1) == 2 and sum(third.kernel.stats.cache_misses.values()) == 1


@POSIX
def test_a_key_others_can_read_is_not_used(cache, tmp_path):
    key = kernel_cache.key_path()
    key.parent.mkdir(parents=True)
    key.write_bytes(b"k" * 32)
    os.chmod(key, 0o644)
    _, message = _load_and_call(expect_warning=True)
    assert "is not a file only you can read" in message and "not reused" in message


@POSIX
@pytest.mark.skipif(not hasattr(os, "geteuid") or os.geteuid() != 0, reason="lchown to another user needs root")
def test_a_link_owned_by_another_user_on_the_way_is_not_trusted(tmp_path):
    private = tmp_path / "private"
    private.mkdir(mode=0o700)
    link = tmp_path / "link"
    link.symlink_to(private)
    os.lchown(link, 65534, 65534)
    assert "through the link" in kernel_cache.untrusted(link)
    assert kernel_cache.untrusted(private) is None


@POSIX
def test_two_processes_asking_for_the_same_cold_kernel_compile_it_once(cache, tmp_path):
    """Before: two test workers asking for the same kernel at once both compiled it (about 20 s of
    CPU each for a four-bar's). The first compile holds a lock: the other process waits, then loads
    the pickles the first saved. This process and another start their call together (when the
    file `go` appears)."""
    go = tmp_path / "go"
    script = ("import os, time\nfrom kinetostat import kernel_cache\n"
              f"m = kernel_cache.load({TEXT!r})\n"
              "print('ready', flush=True)\n"
              f"while not os.path.exists({str(go)!r}): time.sleep(0.002)\n"
              "assert m.kernel(1) == 2\n"
              "s = m.kernel.stats\nprint(sum(s.cache_misses.values()), sum(s.cache_hits.values()))\n")
    other = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    here = kernel_cache.load(TEXT)          # the same folder and key: the cache fixture's, in the environment
    assert other.stdout.readline() == "ready\n", other.communicate()[1]
    go.write_text("")
    assert here.kernel(1) == 2
    out, err = other.communicate(timeout=120)
    assert other.returncode == 0, err
    stats = here.kernel.stats
    results = [out.split(), [str(sum(stats.cache_misses.values())), str(sum(stats.cache_hits.values()))]]
    assert sorted(results) == [["0", "1"], ["1", "0"]]        # one compiled (a miss), the other loaded (a hit)
