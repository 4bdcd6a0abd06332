"""Hostile inputs that gave tracebacks or unbounded work (issue 22, points 6, 7): each now gives one
error line (exit 2 from the command line, 130 for Ctrl-C) and bounded work, shown by counting."""
from __future__ import annotations

import csv
import io
import os
import signal
import socket
import subprocess
import sys
import tracemalloc
import warnings

import numpy as np
import pytest

import kinetostat
from kinetostat import ModelError
from conftest import FOUR_BAR, ROOT

BIG = "1" + "0" * 400          # a 401-digit integer: no float holds it


def _one_line_exit_2(p) -> None:
    assert p.returncode == 2 and "Traceback" not in p.stderr, p.stderr
    assert p.stderr.startswith("kinetostat: error:") and p.stderr.count("\n") == 1, p.stderr


# ============================================================================ 6. one line instead of a traceback

HUGE = {
    "parameter": (FOUR_BAR.replace("[drive]", f"[parameters]\nx = {BIG}\n[drive]"),
                  "parameters.x: an integer of 401 digits is too large"),
    "mass": (FOUR_BAR.replace("mass = 1.5", f"mass = {BIG}"), "mass: expected a finite number, got an integer of 401 digits"),
    "law": (FOUR_BAR.replace("rpm = 300.0\n", f'omega = "{BIG} + 0*phi"\n').replace("eps = 0.0\n", ""),
            "drive.omega: \"1000"),
    "characteristic": (FOUR_BAR + f'\n[[load]]\nname = "m"\nkind = "moment"\nlink = 1\ncharacteristic = "{BIG}*omega"\n',
                       "an integer of 401 digits is too large (overflow)"),
}


@pytest.mark.parametrize("where", HUGE)
def test_a_401_digit_integer_is_one_error_line(where, tmp_path, cli):
    text, message = HUGE[where]
    with pytest.raises(ModelError, match="401 digits"):
        kinetostat.loads(text)
    model = tmp_path / "m.toml"
    model.write_text(text, encoding="utf-8")
    p = cli("analyze", model, "--steps", "4")
    _one_line_exit_2(p)
    assert message in p.stderr and BIG not in p.stderr


def test_a_chain_of_1000_parameters_resolves_without_recursion():
    """p0 reads p1, ..., p998 reads p999 (the most parameters a file may have): RecursionError
    before; now each is its successor + 1, at the default recursion limit."""
    from kinetostat.model import MAX_PARAMETERS
    assert MAX_PARAMETERS == 1000 and sys.getrecursionlimit() <= 1000
    chain = "".join(f'p{i} = "p{i + 1} + 1"\n' for i in range(999)) + "p999 = 1.0\n"
    mech = kinetostat.loads(FOUR_BAR.replace("[drive]", "[parameters]\n" + chain + "[drive]"))
    assert mech.parameters["p0"] == 1000.0 and mech.parameters["p500"] == 500.0
    cycle = "".join(f'p{i} = "p{(i + 1) % 1000} + 1"\n' for i in range(1000))
    with pytest.raises(ModelError, match=r"cycle p0 -> p1 -> p2 .* -> p999 -> p0"):
        kinetostat.loads(FOUR_BAR.replace("[drive]", "[parameters]\n" + cycle + "[drive]"))


def test_a_sweep_of_ten_billion_designs_is_refused_before_any_is_made(tmp_path, cli, monkeypatch):
    sweep_module = sys.modules["kinetostat.sweep"]
    made = []
    monkeypatch.setattr(sweep_module, "_run", lambda parts, *a, **k: made.append(parts))
    model = tmp_path / "m.toml"
    model.write_text(FOUR_BAR.replace("[drive]", "[parameters]\na = 1.0\nb = 2.0\n[drive]"), encoding="utf-8")
    p = cli("sweep", model, "--param", "a=0:99999:1", "--param", "b=0:99999:1", "--out", tmp_path / "s.csv")
    _one_line_exit_2(p)
    assert "1e+10 designs, at most 1000000" in p.stderr and made == []
    assert not (tmp_path / "s.csv").exists()


@pytest.mark.parametrize("scheme", ["tls", "ucx"])
def test_a_tls_or_ucx_scheduler_is_one_error_line(scheme, tmp_path, cli):
    pytest.importorskip("distributed")
    p = cli("sweep", "ice_crank_slider", "--param", "g=9.8", "--steps", "4", "--out", tmp_path / "s.csv",
            "--scheduler", f"{scheme}://127.0.0.1:1")
    _one_line_exit_2(p)
    assert f"--scheduler {scheme}://127.0.0.1:1" in p.stderr and "distributed.Client" in p.stderr


def test_a_scheduler_with_no_worker_stops_with_a_message(monkeypatch):
    """A scheduler that answers but has no worker: the sweep stopped forever; now it waits
    CONNECT_TIMEOUT (shortened here) for a worker and says why it stops."""
    distributed = pytest.importorskip("distributed")
    sweep_module = sys.modules["kinetostat.sweep"]
    monkeypatch.setattr(sweep_module, "CONNECT_TIMEOUT", 0.5)
    busy = socket.socket()              # the dashboard's default port taken (by this test, or already by another)
    try:
        busy.bind(("", 8787))
    except OSError:
        pass
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            # no dashboard; the scheduler's HTTP routes on a free port, not 8787 ("Port 8787 is already in use")
            with distributed.LocalCluster(n_workers=0, processes=False, dashboard_address=None,
                                          scheduler_kwargs={"dashboard_address": ":0"}) as cluster:
                with pytest.raises(ConnectionError, match="no worker joined it within 0.5 s"):
                    kinetostat.sweep("ice_crank_slider", {"g": [9.8]}, steps=4, scheduler=cluster.scheduler_address)
    finally:
        busy.close()
    assert not [str(w.message) for w in caught if "already in use" in str(w.message)]


SITE = '''
import os, signal, sys
class Interrupt:
    """Ctrl-C at the moment `import kinetostat` imports numpy (deterministic, no timing)."""
    def find_spec(self, name, path=None, target=None):
        if name == "numpy" and "kinetostat" in sys.modules:
            sys.meta_path.remove(self)
            os.kill(os.getpid(), signal.SIGINT)
        return None
sys.meta_path.insert(0, Interrupt())
'''


def test_ctrl_c_while_the_package_imports_exits_130_with_one_line(tmp_path):
    (tmp_path / "sitecustomize.py").write_text(SITE)
    env = {k: v for k, v in os.environ.items() if k != "KINETOSTAT_MODELS"}
    env["PYTHONPATH"] = os.pathsep.join([str(tmp_path), env.get("PYTHONPATH", "")])
    r = subprocess.run([sys.executable, "-m", "kinetostat", "examples"], capture_output=True, text=True,
                       cwd=ROOT, env=env, timeout=120)
    assert r.returncode == 130, (r.returncode, r.stderr)
    assert r.stderr == "kinetostat: error: interrupted\n" and r.stdout == ""


def test_dask_process_workers_ignore_ctrl_c(monkeypatch):
    """The workers of the 'processes' scheduler start with SIGINT ignored: Ctrl-C reaches the main
    process alone, and no worker prints a KeyboardInterrupt traceback."""
    import dask
    real, seen = dask.compute, {}

    def compute(*tasks, **kw):
        seen.update(kw)
        probe = dask.delayed(lambda: signal.getsignal(signal.SIGINT) is signal.SIG_IGN)()
        *out, ignored = real(*tasks, probe, **kw)
        seen["ignored"] = ignored
        return tuple(out)
    monkeypatch.setattr(dask, "compute", compute)
    sw = kinetostat.sweep("ice_crank_slider", {"g": [9.8]}, steps=4, scheduler="processes")
    assert len(sw.table) == 1 and seen["scheduler"] == "processes" and seen["ignored"] is True


# ============================================================================ 7. bounded work

def test_the_periodic_spline_of_a_large_table_takes_linear_memory():
    """12,000 knots took 46 s and 2.3 GB (a dense n x n solve); 10^6 were a 7 TiB allocation.
    The cyclic tridiagonal solve keeps memory linear: 8,000 knots within 5 MB (dense: 512 MB)."""
    from kinetostat.model import _periodic_spline, _spline_at
    n = 8_000
    x = tuple(np.linspace(0.0, 360.0, n, endpoint=False))
    y = tuple(2.0 + np.sin(np.radians(x)))
    _periodic_spline.cache_clear()
    tracemalloc.start()
    xs, ys, m = _periodic_spline(x, y)
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    assert peak < 5e6, peak
    phi = np.radians([10.0, 123.4567, 359.99])                  # the spline of sin: value and slope
    w, dw = _spline_at(xs, ys, m, phi)
    np.testing.assert_allclose(w, 2.0 + np.sin(phi), atol=1e-12)
    np.testing.assert_allclose(dw, np.cos(phi), atol=1e-9)


# ============================================================================ 12. plausibility and scales

def test_an_inertia_in_g_mm2_is_warned():
    """The coupler's I_S written in g mm^2 (0.016 kg m^2 = 1.6e7 g mm^2): its radius of gyration
    would be 3266 m on a 0.35 m link (0.10 m in kg m^2)."""
    with pytest.warns(kinetostat.ModelWarning, match=r"link\[id=2\]\.I_S: 1\.6e\+07 kg m\^2 gives a radius of "
                                                     r"gyration of 3266 m.*g mm\^2 is 1e-9 kg m\^2"):
        kinetostat.loads(FOUR_BAR.replace("I_S = 0.016", "I_S = 1.6e7"))


def test_a_pressure_in_mpa_is_warned():
    """The ICE's indicator diagram with p_max in MPa (2.4 instead of 2.4e6 Pa): its largest force
    0.0121 N instead of 12063.7 N (pi/4 0.08^2 2.4e6)."""
    text = (ROOT / "models" / "ice_crank_slider.toml").read_text(encoding="utf-8")
    assert "p_max = 2.4e6" in text
    with pytest.warns(kinetostat.ModelWarning, match=r"table\.scale: the diagram's largest force is 0\.01206 N.*MPa"):
        kinetostat.loads(text.replace("p_max = 2.4e6", "p_max = 2.4"))


@pytest.mark.parametrize("scale, message", [
    ("mu_F=5e-324", "mu_F must be a positive number in N/mm (at least 2.23e-308)"),
    ("mu_F=1e-307", "--scale mu_F=1e-307 N/mm would draw the forces plan beyond 1e308 mm across"),
    # a ZeroDivisionError (the frame's hatching at 1e19 mm), a 383 GiB and a 1.2 GiB allocation (the
    # labels' samples along a link), a 181 GiB one, "Maximum allowed size exceeded": the ICE's
    # positions span 0.182 m, the crank pin's velocity 17 m/s
    ("mu_l=1e-20", "--scale mu_l=1e-20 m/mm would draw the mechanism plan 1.82e+19 mm across (at most 100000 mm)"),
    ("mu_l=1e-12", "--scale mu_l=1e-12 m/mm would draw the mechanism plan 1.82e+11 mm across"),
    ("mu_l=1e-9", "--scale mu_l=1e-09 m/mm would draw the mechanism plan 1.82e+08 mm across"),
    ("mu_v=1e-9", "--scale mu_v=1e-09 m/(s mm) would draw the velocity plan 1.7e+10 mm across"),
    ("mu_v=1e-300", "--scale mu_v=1e-300 m/(s mm) would draw the velocity plan 1.7e+301 mm across"),
])
def test_a_scale_that_draws_beyond_a_sheet_is_refused(scale, message, tmp_path, cli):
    out = tmp_path / "plans"
    p = cli("plans", ROOT / "models" / "ice_crank_slider.toml", "--scale", scale, "--out", out)
    _one_line_exit_2(p)
    assert message in p.stderr
    assert not out.exists() or not list(out.iterdir())


def test_the_drawings_loops_are_bounded_by_a_sheet():
    """What a plan near MAX_EXTENT_MM draws: the frame's hatching (its ends (N,) over the angles)
    is capped at 50 strokes, as many at every angle as the stretch's length at the first gives,
    whatever the length handed to it; a zero-length stretch is no error; the labels' placer clips a
    line to each candidate box (no samples along it), so a line 1e12 mm long costs what a short
    one does."""
    import numpy as np
    from kinetostat.plans.labels import Placer
    from kinetostat.plans.mechanism import _hatch
    paths: dict = {}
    _hatch(np.array([0j, 0j]), np.array([1e12 + 0j, 3.0 + 0j]), 1j, "h", paths)
    assert len(paths) == 1 + 50                         # the line and its strokes every 2 mm over 100 mm
    assert all(v.shape == (2, 2) for v in paths.values())      # each at both angles
    paths.clear()
    _hatch(np.array([1e19 + 0j]), np.array([1e19 + 0j]), 1j, "h", paths)       # both ends one float at 1e19 mm
    assert len(paths) == 1
    placer = Placer(1, (0.0, 0.0, 420.0, 297.0))
    placer.line([0.0, 100.0, 1e12, 100.0])
    placer.line([50.0, 100.0, 50.0, 100.0])
    box = placer.place(("A",), np.zeros(1, dtype=int), 3.5, np.array([[50.0, 100.0]])).box[0]
    assert box[3] <= 100.0 or box[1] >= 100.0          # beside the line, not over it


# ============================================================================ 8. accuracy near singular positions

TOGGLE = ROOT / "tests" / "hostile" / "singular_toggle.toml"      # stretched at 180 deg: 8.0 digits left at 179


@pytest.mark.parametrize("path", ["numpy", "compiled"])
def test_the_sweep_table_gives_the_warned_band_and_its_worst_digits(path):
    """sweep silenced the warning and had no column for the warned band (8 digits left,
    n_singular = 0 where no angle was NaN). Both paths now give the band and the fewest digits,
    equal to what analyze estimates at those angles."""
    from kinetostat import fast
    phi = np.arange(360.0)
    with pytest.warns(kinetostat.SingularPositionWarning):
        res = kinetostat.analyze(kinetostat.load(TOGGLE), phi_deg=phi)
    band = ~res.singular & (res.digits < kinetostat.DIGITS_WARN)
    assert list(res.phi_deg[band]) == [176, 177, 178, 179, 181, 182, 183, 184]
    if path == "numpy":
        sw = kinetostat.sweep(TOGGLE, {"g": [9.81]}, phi_deg=phi)
        assert sw.table["warned_deg"][0] == "176 177 178 179 181 182 183 184"
        assert sw.table["worst_digits"][0] == round(float(res.digits[band].min()), 1) and sw.table["n_singular"][0] == 1
    else:
        with pytest.warns(kinetostat.SingularPositionWarning):
            pk = fast.peaks([kinetostat.load(TOGGLE)], phi)
        assert list(pk.warned_deg[0]) == list(res.phi_deg[band])
        assert pk.worst_digits[0] == pytest.approx(res.digits[band].min(), abs=1e-9)


def test_plans_and_worksheet_at_a_warned_angle_state_the_accuracy(tmp_path, cli):
    out = tmp_path / "plans"
    p = cli("plans", TOGGLE, "--at", "179", "--out", out)
    assert p.returncode == 0, p.stderr
    assert "kinetostat: warning:" in p.stderr and "phi = [179] deg" in p.stderr and "8.0 to 8.0" in p.stderr
    assert "about 8.0 significant digits left at this angle" in (out / "worksheet.md").read_text(encoding="utf-8")
    assert '"digits": 8.0' in (out / "worksheet.json").read_text(encoding="utf-8")
    line = "Accuracy: near a singular position: about 8.0 significant digits left at this angle (fewer than 10)"
    sheets = sorted(out.glob("*.svg"))
    assert len(sheets) == 8 and all(line in q.read_text(encoding="utf-8") for q in sheets)     # every sheet says it
    rows = list(csv.DictReader(io.StringIO((out / "worksheet.csv").read_text(encoding="utf-8"))))
    assert (rows[0]["section"], rows[0]["key"], float(rows[0]["value"])) == ("Accuracy", "digits", 8.0)
    assert rows[0]["note"].startswith("near a singular position: about 8.0 significant digits left")
    calm = tmp_path / "calm"
    assert cli("plans", TOGGLE, "--at", "90", "--out", calm).returncode == 0
    assert not any("Accuracy" in q.read_text(encoding="utf-8") for q in [*calm.glob("*.svg"), *calm.glob("worksheet.*")])
    uk = tmp_path / "uk"
    assert cli("plans", TOGGLE, "--at", "179", "--lang", "uk", "--only", "velocity", "--out", uk).returncode == 0
    assert "Точність: поблизу особливого положення: лишилося близько 8,0 значущих цифр" in (
        uk / "velocity.svg").read_text(encoding="utf-8")


def test_did_you_mean_work_is_bounded(monkeypatch):
    """480 parameters of 20 characters and 500 expressions each reading an unknown look-alike:
    each unknown was compared with every parameter (240,000 difflib ratios; the audit's 15
    minutes with longer names). Now at most SUGGESTIONS suggestions of SUGGEST_CANDIDATES
    candidates each are made per model, and at most MAX_PROBLEMS problems are listed."""
    import difflib
    from kinetostat.expressions import SUGGEST_CANDIDATES, SUGGESTIONS
    from kinetostat.model import MAX_PROBLEMS
    calls = []
    real = difflib.SequenceMatcher.ratio
    monkeypatch.setattr(difflib.SequenceMatcher, "ratio", lambda self: calls.append(1) or real(self))
    params = "".join(f"{'p' * 17}{i:03d} = 1.0\n" for i in range(480))
    reads = "".join(f'u{i} = "{"p" * 16}x{i:03d}"\n' for i in range(500))
    with pytest.raises(ModelError) as exc:
        kinetostat.loads(FOUR_BAR.replace("[drive]", "[parameters]\n" + params + reads + "[drive]"))
    assert 0 < len(calls) <= 2 * SUGGESTIONS * SUGGEST_CANDIDATES            # get_close_matches: 2 per match
    problems = exc.value.problems
    assert len(problems) == MAX_PROBLEMS + 1 and problems[-1] == "... and 400 more problems (the first 100 are shown)"
    assert "(did you mean 'p" in problems[0]                                   # the first ones still suggest


@pytest.mark.parametrize("edit, message", [
    (("S3 = [0.12, -0.01] }", "S3 = [0.12, -0.01], " + "N" * 10_000 + " = [0.2, 0.0] }"),
     "link[id=3].points: a point name of 10000 characters ('NNNNNNNNNNNNNNNNNNNN'...), at most 200"),
    (('name = "resisting moment"', 'name = "' + "N" * 10_000 + '"'), "load[0].name: 10000 characters, at most 200"),
    # the mechanism's own name (it titles every sheet and page): 100,000 characters took `report` 24.5 s
    (('name = "test four-bar"', 'name = "' + "N" * 100_000 + '"'), "mechanism.name: 100000 characters, at most 200"),
])
def test_a_name_of_10000_characters_is_refused_before_any_plot(edit, message, tmp_path, cli):
    """A point named with 10,000 characters made a report take two minutes (its labels); names
    that label plots and plans are refused at load beyond MAX_NAME characters."""
    from kinetostat.model import MAX_NAME
    assert MAX_NAME == 200
    model = tmp_path / "m.toml"
    model.write_text(FOUR_BAR.replace(*edit), encoding="utf-8")
    p = cli("plans", model, "--out", tmp_path / "plans")
    _one_line_exit_2(p)
    assert message in p.stderr and not (tmp_path / "plans").exists()
