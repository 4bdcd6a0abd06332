"""What a user meets first: the angles of a result, short reprs, the units of the table, and
an import of the solver that pulls in nothing of the harness, the engines or the reports."""
from __future__ import annotations

import ast
import subprocess
import sys
from fractions import Fraction

import numpy as np
import pytest

import kinetostat
from conftest import FOUR_BAR, MODELS, ROOT

ICE = ROOT / "models" / "ice_crank_slider.toml"


# ----------------------------------------------------------------------------- angles

@pytest.mark.parametrize("N", [360, 720, 7, 36])
def test_steps_give_k_360_over_n_correctly_rounded(N):
    phi = kinetostat.analyze(kinetostat.load(ICE), steps=N).phi_deg
    exact = [float(Fraction(360 * k, N)) for k in range(N)]     # the rational 360 k / N, rounded once
    assert phi.tolist() == exact


def test_phi_deg_30_is_30_and_a_frame_filter_finds_it():
    res = kinetostat.analyze(kinetostat.load(ICE), steps=360)
    assert res.phi_deg[30] == 30.0
    df = res.to_frame()
    assert len(df[df.phi_deg == 30]) == 1
    assert df.phi_deg.tolist() == list(map(float, range(360)))


def test_given_angles_come_back_as_given_and_read_only():
    asked = [0.1, 29.999999999999996, 1e-300, -720.5, 359.9999999999999]
    res = kinetostat.analyze(kinetostat.load(ICE), phi_deg=asked)
    assert res.phi_deg.tolist() == asked
    with pytest.raises(ValueError):
        res.phi_deg[0] = 5.0
    mine = np.array(asked)
    res = kinetostat.analyze(kinetostat.load(ICE), phi_deg=mine)
    mine[0] = 99.0                                # the result keeps its own copy
    assert res.phi_deg[0] == 0.1


# ----------------------------------------------------------------------------- repr

def _public_objects(mech, res):
    yield mech
    yield res
    yield res.kin
    yield res.forces
    yield mech.structure
    yield from mech.structure.groups
    yield from mech.links
    yield from mech.pairs
    yield from mech.loads
    yield from mech.springs
    yield mech.drive
    yield mech.friction
    for k in range(1, mech.n_links):
        yield res.inertia(k)


@pytest.mark.parametrize("path", MODELS, ids=[p.stem for p in MODELS])
def test_every_repr_of_a_bundled_model_is_a_short_summary(path):
    mech = kinetostat.load(path)
    res = kinetostat.analyze(mech, steps=36)
    for obj in _public_objects(mech, res):
        assert len(repr(obj)) <= 500, (type(obj).__name__, len(repr(obj)))
    assert mech.structure.formula in repr(mech)
    assert repr(res).endswith(f"positions=36, phi_deg=0..350, singular={int(res.singular.sum())})")


def test_repr_of_the_ice_model_and_its_result():
    mech = kinetostat.load(ICE)
    assert repr(mech) == ("Mechanism(name='ICE crank-slider (worked example of Logvinenko, Nadtoka 2021)', links=4, pairs=4, "
                          "structure='I(0,1) <- II(2,3)', drive=engine 471.2 rad/s)")
    assert repr(kinetostat.analyze(mech, phi_deg=[30.0])) == (
        "Analysis(mechanism='ICE crank-slider (worked example of Logvinenko, Nadtoka 2021)', positions=1, phi_deg=30, singular=0)")
    assert repr(mech.structure) == "Structure(W=1, formula='I(0,1) <- II(2,3)', kinds=['RRP'])"


def test_a_long_name_is_cut_in_the_repr():
    mech = kinetostat.loads(FOUR_BAR.replace('name = "test four-bar"', f'name = "{"x" * 200}"'))   # MAX_NAME
    assert len(mech.name) == 200
    assert len(repr(mech)) < 250 and "\u2026" in repr(mech)
    assert len(repr(kinetostat.analyze(mech, steps=4))) < 200


# ----------------------------------------------------------------------------- table units

UNIT_OF_PREFIX = {   # column family -> unit, written out here independently of to_frame
    "phi_deg": "deg", "x": "m", "y": "m", "vx": "m/s", "vy": "m/s", "ax": "m/s^2", "ay": "m/s^2",
    "theta": "rad", "omega": "rad/s", "eps": "rad/s^2", "Fix": "N", "Fiy": "N", "Mi": "N m", "h": "m",
    "Rx": "N", "Ry": "N", "R": "N", "m": "N m", "vs": "m/s", "as": "m/s^2", "M_bal": "N m",
    "M_lever": "N m", "F_balx": "N", "F_baly": "N", "F_bal": "N", "Pfr": "W", "Pfr_total": "W",
    "cond": "1", "singular": "bool", "xK": "m", "yK": "m", "lSK": "m", "angle": "deg", "Fax": "N",
    "eta": "1", "self_locking": "bool", "M_bal_0": "N m",
}


def _family(column: str) -> str:
    if column in UNIT_OF_PREFIX:
        return column
    return column.split("_", 1)[0]


@pytest.mark.parametrize("path", MODELS, ids=[p.stem for p in MODELS])
def test_every_column_has_its_unit(path):
    df = kinetostat.analyze(kinetostat.load(path), steps=12).to_frame()
    units = df.attrs["units"]
    assert list(units) == list(df.columns)
    for col in df.columns:
        assert units[col] == UNIT_OF_PREFIX[_family(col)], col
    assert "link i on link j" in df.attrs["frame"] and "gravity along -y" in df.attrs["frame"]
    assert df.attrs["mechanism"] == kinetostat.load(path).name


def test_machine_and_friction_columns_have_units():
    machine = kinetostat.analyze(kinetostat.load(ROOT / "models" / "compressor.toml"), steps=12).to_frame()
    units = machine.attrs["units"]
    assert units["F_bal"] == units["F_balx"] == "N"
    assert units["x_0_3"] == "m" and units["m_0_3"] == "N m" and units["cond_II(2,3)"] == "1"
    friction = kinetostat.analyze(kinetostat.load(ICE), steps=12).to_frame()     # the ICE model has friction
    assert friction.attrs["units"]["Pfr_total"] == friction.attrs["units"]["Pfr_0_1"] == "W"


# ----------------------------------------------------------------------------- imports

def test_the_solver_imports_nothing_of_the_harness_engines_or_reports():
    code = ("import sys, kinetostat\n"
            f"kinetostat.analyze(kinetostat.load({str(ICE)!r}), steps=36)\n"
            "bad = ['kinetostat_validation', 'validation', 'pinocchio', 'mujoco', 'pymunk', 'matplotlib',"
            " 'kinetostat.report']\n"
            "print(sorted(m for m in sys.modules if m.split('.')[0] in bad or m.startswith('kinetostat.report')))\n")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT / "tests", timeout=120)
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip() == "[]"


def test_the_plans_and_variants_are_imported_when_first_used():
    code = ("import sys, kinetostat\n"
            f"kinetostat.analyze(kinetostat.load({str(ICE)!r}), steps=36)\n"
            "print(sorted(m for m in sys.modules if m.startswith(('kinetostat.plans', 'kinetostat.variants',"
            " 'urllib.request', 'pandas'))))\n"
            "print(kinetostat.plans.build.__module__, kinetostat.examples.__name__, kinetostat.variants.__name__)\n"
            "print(sorted(set(kinetostat.__all__) - set(dir(kinetostat))))\n"
            "from kinetostat import *\n"
            "print(plans.__name__)\n")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT / "tests", timeout=120)
    assert r.returncode == 0, r.stderr
    assert r.stdout.splitlines() == ["[]", "kinetostat.plans kinetostat.examples kinetostat.variants", "[]",
                                     "kinetostat.plans"]
    with pytest.raises(AttributeError, match="no attribute 'plan'"):
        kinetostat.plan


def test_the_plans_command_imports_no_pandas_markdown_it_or_matplotlib(tmp_path):
    """`kinetostat plans` writes its sheets, segments.csv and the worksheet (CSV, HTML) without
    pandas (0.6 s to import) or markdown-it-py: the budget of a plan (issue 34 (b))."""
    code = ("import sys\nfrom kinetostat.cli import main\n"
            f"assert main(['-q', 'plans', {str(ICE)!r}, '--at', '30', '--out', {str(tmp_path / 'p')!r}]) == 0\n"
            "print(sorted({m.split('.')[0] for m in sys.modules} & {'pandas', 'markdown_it', 'matplotlib'}))\n")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT / "tests", timeout=120)
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip() == "[]"
    assert {"segments.csv", "worksheet.csv", "worksheet.html"} <= {p.name for p in (tmp_path / "p").iterdir()}


def test_the_variant_command_imports_no_pandas(tmp_path):
    """`kinetostat variant` writes its cycle.csv without pandas (`Analysis.columns`, `tables.columns_csv`):
    0.6 s of the budget of a variant (issue 34 (d))."""
    code = ("import sys\nfrom kinetostat.cli import main\n"
            f"assert main(['variant', '1', '479', '-q', '--no-pack', '--out', {str(tmp_path / 'v')!r}]) == 0\n"
            "print(sorted({m.split('.')[0] for m in sys.modules} & {'pandas', 'matplotlib'}))\n")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT / "tests", timeout=120)
    assert r.returncode == 0, r.stderr
    assert r.stdout.splitlines()[-1] == "[]"            # after the variant's summary
    assert (tmp_path / "v" / "cycle.csv").read_text(encoding="utf-8").startswith("phi_deg [deg],x_O [m]")


def _imports(module: str) -> set[str]:
    tree = ast.parse((ROOT / "kinetostat" / f"{module}.py").read_text(encoding="utf-8"))
    out = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            out.add("." * node.level + (node.module or ""))
        elif isinstance(node, ast.Import):
            out.update(a.name for a in node.names)
    return out


def test_structure_and_model_depend_one_way():
    assert not {".model", "kinetostat.model"} & _imports("structure")      # not even for type checking
    assert "..structure" in _imports("model/mechanism")
    mech = kinetostat.load(ICE)
    assert mech.structure is mech.structure and mech.structure.formula == "I(0,1) <- II(2,3)"
    with pytest.raises(AttributeError):
        mech.structure = None
