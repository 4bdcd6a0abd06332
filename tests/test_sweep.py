"""Design sweeps (`kinetostat.sweep`, `kinetostat sweep`): seed 004's study r x n_k as a sweep equals a
loop of `analyze` over the same designs; Dask (local schedulers, a local cluster of 2 workers) gives
the same table as the sweep in this process; a design that fails keeps its row."""
from __future__ import annotations

import itertools
import shutil
import subprocess
import sys

import numpy as np
import pandas as pd
import pytest

import kinetostat
from kinetostat.cli import _param, _range, _RangeError
from kinetostat.tables import read_csv

from conftest import ROOT

CHAIN = ROOT / "models" / "chain_unit_four_bar.toml"
#: Seed 004's experimental range (line 368): r = 50 ... 110 mm in steps of 15 mm, n_k = 0 ... 487 rpm.
STUDY = {"r": [0.05, 0.065, 0.08, 0.095, 0.11], "n_k": [0.0, 60.0, 120.0, 240.0, 487.0]}
PEAKS = ["peak_R_0_1", "peak_R_1_2", "peak_R_2_3", "peak_R_0_3", "peak_M_bal"]


def _loop_peaks(params: dict, steps: int) -> dict[str, np.ndarray]:
    """The peaks by a plain loop of analyze(load(path, parameters=design)), shaped as the design axes."""
    out = {c: [] for c in PEAKS}
    for values in itertools.product(*params.values()):
        res = kinetostat.analyze(kinetostat.load(CHAIN, parameters=dict(zip(params, values))), steps=steps)
        for i, j in ((0, 1), (1, 2), (2, 3), (0, 3)):
            out[f"peak_R_{i}_{j}"].append(np.nanmax(np.linalg.norm(res.reaction(i, j), axis=-1)))
        out["peak_M_bal"].append(np.nanmax(np.abs(res.balancing_moment)))
    return {c: np.reshape(v, [len(x) for x in params.values()]) for c, v in out.items()}


def test_seed_004_study_as_a_sweep_equals_a_loop_of_analyze():
    """The acceptance test: r x n_k, 360 angles each, every peak to 1e-13 of the loop's."""
    sw = kinetostat.sweep(CHAIN, STUDY, steps=360)
    assert sw.shape == (5, 5) and len(sw.table) == 25 and len(sw.phi_deg) == 360
    expected = _loop_peaks(STUDY, 360)
    for col in PEAKS:
        np.testing.assert_allclose(sw.peak(col), expected[col], rtol=1e-13, atol=0)
    # the first parameter is the slowest: row 7 is r = 0.065 (index 1), n_k = 120 (index 2)
    assert sw.table.loc[7, ["r", "n_k"]].tolist() == [0.065, 120.0]
    # the paper's case r = 80 mm, n_k = 120 rpm: the continuous maximum of F_O1, 288.3 N (model header)
    assert sw.peak("R_0_1")[2, 2] == pytest.approx(288.3, abs=0.05)
    assert (sw.table["n_singular"] == 0).all() and (sw.table["error"] == "").all()
    assert sw.table.attrs["units"]["peak_M_bal"] == "N m" and sw.table.attrs["units"]["peak_R_0_1"] == "N"


def test_import_kinetostat_leaves_pandas_and_dask_unloaded():
    """The sweep is exported by the package, yet a one-shot command does not pay for pandas or Dask."""
    code = "import sys, kinetostat; print(sorted({'pandas', 'dask', 'distributed'} & set(sys.modules)))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "[]"


def test_unknown_parameters_and_bad_values_are_named():
    with pytest.raises(ValueError, match=r"'rr' is not a parameter of the model \(did you mean 'r'\?\)\. "
                                         r"Parameters: r, n_k, c, h"):
        kinetostat.sweep(CHAIN, {"rr": [0.05]})
    with pytest.raises(ValueError, match="n_k: expected a non-empty list of finite numbers"):
        kinetostat.sweep(CHAIN, {"n_k": []})
    with pytest.raises(ValueError, match="chunk"):
        kinetostat.sweep(CHAIN, {"n_k": [0]}, chunk=0)
    with pytest.raises(KeyError, match=r"no peak of 'R_0_2'.*Peaks: \['R_0_1'"):
        kinetostat.sweep(CHAIN, {"n_k": [0]}, steps=4).peak("R_0_2")


def test_a_mechanism_with_overrides_is_refused_as_a_model():
    with pytest.raises(ValueError, match="parameters differ from those of its file"):
        kinetostat.sweep(kinetostat.load(CHAIN, parameters={"c": 0.6}), {"r": [0.05]})


def test_a_design_that_does_not_assemble_keeps_its_row():
    """r = 0.9 m: the crank is longer than the coupler and rocker can reach (Grashof fails)."""
    sw = kinetostat.sweep(CHAIN, {"r": [0.05, 0.9], "n_k": [120.0]}, steps=36)
    ok, bad = sw.table.iloc[0], sw.table.iloc[1]
    assert ok["error"] == "" and np.isfinite(ok[PEAKS].astype(float)).all()
    assert bad["error"].startswith("AssemblyError: group II(2,3) cannot be assembled")
    assert bad[PEAKS].isna().all() and pd.isna(bad["n_singular"])
    assert np.isnan(sw.peak("R_0_1")[1, 0])


def test_a_design_the_model_refuses_keeps_its_row():
    sw = kinetostat.sweep(CHAIN, {"m2": [7.791, -1.0]}, steps=4)
    assert sw.table["error"].iloc[0] == ""
    line = 1 + next(n for n, text in enumerate(CHAIN.read_text(encoding="utf-8").splitlines())
                    if text.startswith("mass = ") and "m2" in text)       # the line of link 2's mass
    assert sw.table["error"].iloc[1] == f'ModelError: line {line}: link[id=2].mass: must be >= 0.0, got -1.0 (= "m2")'


def test_a_parameter_named_as_a_column_of_the_angles_table_is_refused(tmp_path, cli):
    """With full=True the parameters lead the cycle table's columns: a parameter named phi_deg
    would write a second phi_deg (the CSV's header one field longer than its rows); refused."""
    text = (ROOT / "models" / "chain_unit_four_bar.toml").read_text(encoding="utf-8").replace("n_k", "phi_deg")
    path = tmp_path / "clash.toml"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(ValueError, match="parameter 'phi_deg' has the name of a column"):
        kinetostat.sweep(path, {"phi_deg": [60.0, 120.0]}, steps=12, full=True)
    assert kinetostat.sweep(path, {"phi_deg": [60.0, 120.0]}, steps=12).table.shape[0] == 2    # without full: no clash
    p = cli("sweep", path, "--param", "phi_deg=60,120", "--steps", "12", "--full", "--out", tmp_path / "s.csv")
    assert p.returncode == 2 and "phi_deg" in p.stderr and not (tmp_path / "s.csv").exists()


def test_full_keeps_every_angle_with_the_design_first():
    sw = kinetostat.sweep(CHAIN, {"r": [0.05, 0.08]}, steps=12, full=True)
    a = sw.angles
    assert len(a) == 24 and list(a.columns[:2]) == ["r", "phi_deg"]
    res = kinetostat.analyze(kinetostat.load(CHAIN, parameters={"r": 0.08}), steps=12)
    np.testing.assert_array_equal(a.loc[a["r"] == 0.08, "R_0_1"], np.linalg.norm(res.reaction(0, 1), axis=-1))
    assert a.attrs["units"]["R_0_1"] == "N" and a.attrs["units"]["r"] == "m"
    assert sw.table.attrs["units"]["r"] == "m"          # the model file's comment: "# crank length O1A, m"


class _Bar:
    """A progress bar that counts the chunks it is told of."""
    def __init__(self, total: int, enabled: bool):
        self.total, self.done, self.closed = total, 0, False

    def update(self, n: int = 1) -> None:
        self.done += n

    def close(self) -> None:
        self.closed = True


@pytest.fixture
def bars(monkeypatch) -> list[_Bar]:
    """The progress bars the sweeps of a test make."""
    made: list[_Bar] = []
    monkeypatch.setattr(sys.modules["kinetostat.sweep"], "_bar", lambda *a: made.append(_Bar(*a)) or made[-1])
    return made


@pytest.mark.parametrize("scheduler", ["threads", "processes"])
def test_dask_local_schedulers_give_the_same_table(scheduler, bars):
    params = {"r": [0.05, 0.08, 0.9], "n_k": [0.0, 487.0]}
    here = kinetostat.sweep(CHAIN, params, steps=36, full=True)
    there = kinetostat.sweep(CHAIN, params, steps=36, full=True, scheduler=scheduler, chunk=2, progress=True)
    pd.testing.assert_frame_equal(here.table, there.table, check_exact=True)
    pd.testing.assert_frame_equal(here.angles, there.angles, check_exact=True)
    assert [(b.total, b.done, b.closed) for b in bars] == [(1, 1, True), (3, 3, True)]   # 6 designs, 2 a chunk


def test_a_local_cluster_of_two_workers_gives_the_same_table(bars):
    """A distributed scheduler over TCP, by its Client and by its address; its two workers are
    threads of this process (processes=False: the tasks still travel pickled over TCP), which
    saves starting two interpreters (the processes scheduler above runs tasks in other processes)."""
    distributed = pytest.importorskip("distributed")
    here = kinetostat.sweep(CHAIN, STUDY, steps=360)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=False, protocol="tcp://",
                                 dashboard_address=None, scheduler_kwargs={"dashboard_address": ":0"}) as lc, \
            distributed.Client(lc) as client:
        by_client = kinetostat.sweep(CHAIN, STUDY, steps=360, scheduler=client, chunk=4, progress=True)
        by_address = kinetostat.sweep(CHAIN, STUDY, steps=360, scheduler=lc.scheduler_address, chunk=7)
    pd.testing.assert_frame_equal(here.table, by_client.table, check_exact=True)
    pd.testing.assert_frame_equal(here.table, by_address.table, check_exact=True)
    assert [(b.total, b.done) for b in bars] == [(1, 1), (7, 7), (4, 4)]      # 25 designs: 7 chunks of 4, 4 of 7


# ----------------------------------------------------------------------------- the command line

def test_ranges_include_their_stop():
    assert _range(0.05, 0.11, 0.015) == [0.05, 0.065, 0.08, 0.095, 0.11]       # r = 50 ... 110 mm: five designs
    assert _range(0.0, 487.0, 487.0) == [0.0, 487.0]
    assert _range(3.0, 1.0, -1.0) == [3.0, 2.0, 1.0]
    assert _param("n_k=0,60,120,240,487") == ("n_k", [0.0, 60.0, 120.0, 240.0, 487.0])
    assert _param("c=0.54") == ("c", [0.54])
    with pytest.raises(_RangeError, match="does not go from 0.05 to 0.11 in whole steps"):
        _range(0.05, 0.11, 0.016)
    with pytest.raises(_RangeError, match="non-zero"):
        _range(0.05, 0.11, 0.0)
    with pytest.raises(_RangeError, match="whole steps"):
        _range(0.11, 0.05, 0.015)


def test_cli_sweep_writes_the_study_as_parquet_and_csv(cli, tmp_path):
    args = ["sweep", "chain_unit_four_bar", "--param", "r=0.05:0.11:0.015", "--param", "n_k=0,60,120,240,487",
            "--steps", "36", "--no-progress"]
    r = cli(*args, "--out", tmp_path / "sweep.parquet")
    assert r.returncode == 0, r.stderr
    assert "25 designs (r 5 x n_k 5) x 36 crank positions" in r.stdout
    df = pd.read_parquet(tmp_path / "sweep.parquet")
    assert len(df) == 25
    assert list(df.columns) == ["r", "n_k", *PEAKS, "n_singular", "singular_deg", "worst_digits", "warned_deg", "error"]
    sw = kinetostat.sweep(CHAIN, STUDY, steps=36)
    pd.testing.assert_frame_equal(df, sw.table, check_exact=True, check_dtype=False)
    r = cli(*args, "--out", tmp_path / "sweep.csv")
    assert r.returncode == 0, r.stderr
    csv = read_csv(tmp_path / "sweep.csv")
    assert csv.attrs["units"]["peak_R_0_1"] == "N" and csv.attrs["units"]["peak_M_bal"] == "N m"
    for c in PEAKS:                     # CSV: 12 significant digits of the column's largest value
        peak = sw.table[c].abs().max()
        np.testing.assert_allclose(csv[c].to_numpy(), sw.table[c].to_numpy(), rtol=0, atol=6e-12 * peak)
    assert not (tmp_path / "sweep.angles.csv").exists()


def test_cli_sweep_full_writes_the_angles_beside_out(cli, tmp_path):
    r = cli("sweep", "chain_unit_four_bar", "--param", "r=0.05,0.08", "--steps", "12", "--full",
            "--scheduler", "threads", "--out", tmp_path / "s.csv")
    assert r.returncode == 0, r.stderr
    angles = read_csv(tmp_path / "s.angles.csv")
    assert len(angles) == 24 and list(angles.columns[:2]) == ["r", "phi_deg"] and "s.angles.csv" in r.stdout


@pytest.mark.parametrize("args, message", [
    (["--param", "r=0.05:0.11:0.016"], "invalid --param 'r=0.05:0.11:0.016': the step 0.016 does not go"),
    (["--param", "rr=0.05"], "--param: 'rr' is not a parameter of the model (did you mean 'r'?)"),
    (["--param", "r"], "invalid --param 'r': expected NAME=VALUES"),
    (["--param", "r=a,b"], "invalid --param 'r=a,b': expected numbers"),
    (["--param", "r=0.05", "--param", "r=0.06"], "--param r: given more than once"),
    (["--param", "r=0.05", "--out", "sweep.txt"], "--out sweep.txt: unknown table format '.txt'"),
    (["--param", "r=0.05", "--scheduler", "nowhere"], "--scheduler nowhere: no distributed scheduler there"),
])
def test_cli_sweep_bad_options_are_named(cli, tmp_path, args, message):
    if "--out" not in args:
        args = [*args, "--out", str(tmp_path / "s.csv")]
    r = cli("sweep", "chain_unit_four_bar", *args, cwd=tmp_path)
    assert r.returncode == 2 and message in r.stderr and "Traceback" not in r.stderr
    assert not list(tmp_path.iterdir())


def test_the_reports_study_is_the_sweep_its_command_line_writes(cli, tmp_path):
    """The chain-unit report's r x n_k table: study_table equals the table `kinetostat sweep` writes
    from the command line the report prints."""
    from kinetostat.report.writer import study_command, study_table
    mech = kinetostat.load(CHAIN)
    command = study_command(mech)
    assert command == ("kinetostat sweep chain_unit_four_bar.toml --param r=0.05,0.065,0.08,0.095,0.11 "
                       "--param n_k=0,60,120,240,487 --steps 36 --out study.csv")
    shutil.copy(CHAIN, tmp_path)
    r = cli(*command.split()[1:], "--no-progress", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    written = read_csv(tmp_path / "study.csv")
    table = study_table(mech)
    np.testing.assert_allclose(written["peak_R_0_1"].to_numpy().reshape(5, 5), table, rtol=0,
                               atol=6e-12 * np.nanmax(table))


def test_a_large_sweep_runs_the_compiled_kernel_and_equals_the_loop_of_analyze():
    """25 designs x 2400 angles (over fast.FAST_MIN, the peaks kernel loaded): the chunk's peaks
    come from one kernel call; they equal analyze design by design to 1e-13."""
    from kinetostat import fast
    fast.kernel(kinetostat.load(CHAIN), "peaks")
    sw = kinetostat.sweep(CHAIN, {"r": [0.05, 0.065, 0.08, 0.095, 0.11], "n_k": [0.0, 60.0, 120.0, 240.0, 487.0]},
                          steps=2400, chunk=25)
    for _, row in sw.table.iterrows():
        res = kinetostat.analyze(kinetostat.load(CHAIN, parameters={"r": row["r"], "n_k": row["n_k"]}), steps=2400)
        R = np.linalg.norm(res.forces.R, axis=-1).max(axis=0)
        got = row[[f"peak_R_{p.links[0]}_{p.links[1]}" for p in res.mech.pairs]].astype(float).to_numpy()
        np.testing.assert_allclose(got, R, rtol=1e-13, atol=0)
        assert abs(row["peak_M_bal"] - np.abs(res.balancing_moment).max()) <= 1e-13 * max(np.abs(res.balancing_moment).max(), 1.0)



@pytest.mark.parametrize("designs", [[0.6], [0.6, 0.9]])
def test_failing_designs_keep_their_rows_on_the_compiled_path(monkeypatch, designs):
    """The compiled path (fast.FAST_MIN and FAST_COLD lowered to 0) with designs that cannot be assembled: each
    keeps its row with the reason, and each is tried once alone after its chunk failed (once a
    RecursionError: a failing design was retried by itself, forever). The kernel's stand-in
    raises what the kernel raises, the AssemblyError of the first design that fails (the real
    kernel: the slow test below)."""
    from kinetostat import fast
    monkeypatch.setattr(fast, "FAST_MIN", 0)
    monkeypatch.setattr(fast, "FAST_COLD", 0)
    calls = []

    def peaks(mechs, phi_deg):
        calls.append(len(mechs))
        with monkeypatch.context() as numpy_path:       # analyze itself on its numpy path
            numpy_path.setattr(fast, "FAST_MIN", 10**9)
            for m in mechs:
                kinetostat.analyze(m, phi_deg=phi_deg)
        raise AssertionError("every design here fails")
    monkeypatch.setattr(fast, "peaks", peaks)
    sw = kinetostat.sweep(CHAIN, {"r": designs}, steps=36)
    assert calls == ([1] if len(designs) == 1 else [2, 1, 1])     # the chunk, then each design once
    for _, bad in sw.table.iterrows():
        assert bad["error"].startswith("AssemblyError: group II(2,3) cannot be assembled")
        assert bad[PEAKS].isna().all()


@pytest.mark.slow
def test_a_failing_design_beside_a_good_one_in_the_compiled_kernel(monkeypatch):
    """The issue's reproducer in small: the real kernel, r = 0.08 m (assembles) and 0.6 m (does not)."""
    from kinetostat import fast
    monkeypatch.setattr(fast, "FAST_MIN", 0)
    monkeypatch.setattr(fast, "FAST_COLD", 0)
    sw = kinetostat.sweep(CHAIN, {"r": [0.08, 0.6]}, steps=36)
    ok, bad = sw.table.iloc[0], sw.table.iloc[1]
    assert bad["error"].startswith("AssemblyError: group II(2,3) cannot be assembled") and bad[PEAKS].isna().all()
    ref = _loop_peaks({"r": [0.08]}, 36)
    assert ok["error"] == ""
    np.testing.assert_allclose(ok[PEAKS].astype(float).to_numpy(), [ref[c][0] for c in PEAKS], rtol=1e-13)
