"""The memory guard (issue 35, class 6): `--steps` is weighed with what a position really costs on
its output path (the analysis measured by a probe, the --out table by measured constants) against
the memory the process may take (MemAvailable, RLIMIT_AS, the cgroup's limit); a MemoryError is one
line; the CSV and JSON tables are written a chunk at a time, byte for byte as before."""
from __future__ import annotations

import csv
import io
import json
import os
import subprocess
import sys

import pytest

import kinetostat
from conftest import ROOT
from kinetostat import tables
from kinetostat.cli import common

ICE = ROOT / "models" / "ice_crank_slider.toml"


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="RLIMIT_AS and /proc/self/status: Linux")
def test_out_csv_beyond_the_address_space_limit_is_refused_in_one_line(tmp_path):
    """The audit's reproducer: under a 4 GiB RLIMIT_AS, 2.5 million positions into a CSV (9.7 kB a
    position then) ended in a MemoryError traceback."""
    import resource

    def four_gib() -> None:
        resource.setrlimit(resource.RLIMIT_AS, (4 * 2**30, resource.getrlimit(resource.RLIMIT_AS)[1]))
    env = {k: v for k, v in os.environ.items() if k != "KINETOSTAT_MODELS"}
    r = subprocess.run([sys.executable, "-m", "kinetostat", "analyze", str(ICE), "--steps", "2500000",
                        "--out", "big.csv"], cwd=tmp_path, env=env, preexec_fn=four_gib,
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 2, r.stderr
    assert r.stderr.count("\n") == 1 and "Traceback" not in r.stderr, r.stderr
    assert r.stderr.startswith("kinetostat: error: --steps 2500000: the analysis and its table (--out big.csv) "
                               "would need about "), r.stderr
    assert "available to this process" in r.stderr
    assert list(tmp_path.iterdir()) == []                      # no big.csv, no temporary file


def test_the_available_memory_is_the_least_of_meminfo_rlimit_and_cgroup(monkeypatch):
    import resource
    meminfo = {"MemAvailable": 64 * 2**30, "VmSize": 1 * 2**30}
    monkeypatch.setattr(common, "_status_bytes", meminfo.get)
    cgroup = {"/sys/fs/cgroup/memory.max": 8 * 2**30, "/sys/fs/cgroup/memory.current": 3 * 2**30}
    monkeypatch.setattr(common, "_read_number", cgroup.get)
    monkeypatch.setattr(resource, "getrlimit", lambda what: (resource.RLIM_INFINITY, resource.RLIM_INFINITY))
    assert common._available_memory() == 5 * 2**30                       # the cgroup: 8 - 3 GiB
    monkeypatch.setattr(resource, "getrlimit", lambda what: (4 * 2**30, resource.RLIM_INFINITY))
    assert common._available_memory() == 3 * 2**30                       # RLIMIT_AS 4 GiB - VmSize 1 GiB
    cgroup.clear()
    cgroup.update({"/sys/fs/cgroup/memory/memory.limit_in_bytes": 2**31, "/sys/fs/cgroup/memory/memory.usage_in_bytes": 2**30})
    assert common._available_memory() == 2**30                           # cgroup v1: 2 - 1 GiB


def test_the_guard_weighs_the_output_path(monkeypatch):
    """Per position: the analysis as the probe measures it, doubled; with --out, the table's
    cells (81 columns for this model) at TABLE_CELL_BYTES each."""
    mech = kinetostat.load(ICE)
    per_angle, res = common._probe(mech)
    assert 1000 < per_angle < 4000, per_angle                   # ~1.2 kB measured, not the arrays' 841 bytes
    cols = len(res.to_frame().columns)
    monkeypatch.setattr(common, "_probe", lambda m: (per_angle, res))
    monkeypatch.setattr(common, "_available_memory", lambda: 10**9)
    fits = 10**9 / (common.ANALYSIS_HEADROOM * per_angle + common.TABLE_CELL_BYTES[".csv"] * cols)
    common._check_memory(mech, int(fits * 0.99), "t.csv")
    with pytest.raises(common.CLIError, match=r"and its table \(--out t.csv\)"):
        common._check_memory(mech, int(fits * 1.01), "t.csv")
    common._check_memory(mech, int(fits * 1.01))                # without --out: the analysis alone fits
    with pytest.raises(common.CLIError, match=r"--steps \d+: the analysis would need about "):
        common._check_memory(mech, int(10**9 / (common.ANALYSIS_HEADROOM * per_angle) * 1.01))


def test_a_memory_error_anywhere_is_one_line(cli, monkeypatch, tmp_path):
    from kinetostat import tables as tables_module

    def no_memory(df, f):
        f.write("phi_deg [deg]\n")
        raise MemoryError
    monkeypatch.setattr(tables_module, "write_csv", no_memory)
    r = cli("analyze", ICE, "--steps", "12", "--out", tmp_path / "t.csv")
    assert r.returncode == 2 and r.stderr == "kinetostat: error: out of memory (MemoryError); use fewer --steps, or give " \
                                    "the process more memory\n", r.stderr
    assert list(tmp_path.iterdir()) == []                      # the half-written table removed


# ============================================================================ the tables, chunk by chunk

def _old_write_csv(df, f) -> None:
    """The CSV writer before the chunks (every row's text at once), as the reference."""
    def cells(col) -> list[str]:
        text = (lambda v: tables.FLOAT_FORMAT % v) if col.dtype.kind == "f" else str
        return ["" if na else text(v) for v, na in zip(col.tolist(), col.isna().tolist())]
    w = csv.writer(f, lineterminator="\n")
    w.writerow(tables.header(df))
    w.writerows(zip(*(cells(col) for _, col in tables.rounded(df).items())))


@pytest.mark.parametrize("rows", [0, 1, 17])
def test_the_tables_written_by_chunks_are_byte_identical(rows, monkeypatch):
    """Against the writers of one piece (CSV: the old writer; JSON: `json.dump` of the document),
    chunks of 5 rows, a text column with a comma, a quote, a newline, None and a non-ASCII letter."""
    import pandas as pd
    monkeypatch.setattr(tables, "CSV_CHUNK", 5)
    df = kinetostat.analyze(kinetostat.load(ICE), steps=max(rows, 1)).to_frame().iloc[:rows]
    df = df.assign(note=pd.Series(["a, \"b\"\nc", None, "é"] * (rows // 3 + 1), dtype=object)[:rows].to_numpy())
    df.attrs["units"] = {**df.attrs["units"], "note": "text"}
    new, old = io.StringIO(), io.StringIO()
    tables.write_csv(df, new)
    _old_write_csv(df, old)
    assert new.getvalue() == old.getvalue()
    new = io.StringIO()
    tables.write_json(df, new)
    assert new.getvalue() == json.dumps(tables.json_document(df), indent=1, allow_nan=False, ensure_ascii=False) + "\n"
