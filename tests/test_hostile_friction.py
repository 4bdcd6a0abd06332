"""Absurd friction figures (issue 35, class 4): a cycle efficiency of -1.2e14 where the loads do no
net work, a LinAlgError traceback from a singular friction solve, a journal radius of 1e6 m taken
silently, friction power in the billions of watts where no equilibrium exists. Each now gives NaN
with its reason, or a ModelWarning naming the field."""
from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

import kinetostat
from kinetostat import ModelWarning, SelfLockingWarning, SingularFrictionWarning, UndefinedFigureWarning
from conftest import ROOT


def _with_friction(name: str, f: float, radius: float, pair_radius: str = "") -> str:
    """The bundled model `name` (no [friction] of its own) with [friction] f, radius, method "reactions"."""
    text = (ROOT / "models" / f"{name}.toml").read_text()
    assert "[friction]" not in text
    if pair_radius:                       # the crank's pivot: its own journal radius
        text = text.replace('links = [0, 1]\npoint = "O1"\n', f'links = [0, 1]\npoint = "O1"\nradius = {pair_radius}\n', 1)
    return text + f'\n[friction]\nf = {f!r}\nradius = {radius!r}\nmethod = "reactions"\n'


def _load(text: str) -> kinetostat.Mechanism:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ModelWarning)
        return kinetostat.loads(text)


def _analyze(text: str, steps: int = 36) -> kinetostat.Analysis:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SelfLockingWarning)
        return kinetostat.analyze(_load(text), steps=steps)


# gravity and inertia only (chain unit), or a load that gives back what it takes (the triad's resisting
# force on the base): no net work over a steady cycle. Before: -1.25863e+14 and 2.12158e-15, exit 0.
NO_NET_WORK = {"chain_unit_four_bar": _with_friction("chain_unit_four_bar", 0.1, 0.01),
               "triad_slider": _with_friction("triad_slider", 0.1, 0.01)}


@pytest.mark.parametrize("name", list(NO_NET_WORK))
def test_cycle_efficiency_is_undefined_where_the_loads_do_no_net_work(name):
    res = _analyze(NO_NET_WORK[name])
    with pytest.warns(UndefinedFigureWarning, match=r"cycle_efficiency: undefined \(NaN\): the loads do no net work") as w:
        eta = res.cycle_efficiency()
    assert math.isnan(eta) and w[0].message.reason.startswith("the loads do no net work over the cycle")
    assert res.cycle_efficiency_reason() == w[0].message.reason
    # the power balance from the work of every load: the loads' net work is rounding of what they move,
    # while friction takes a real share of the drive's work (so eta would be W0 / Wf = rounding / that)
    W = res.work()
    loads = [v for k, v in W.items() if k != "balancing moment" and not k.startswith("friction")]
    lost = -sum(v for k, v in W.items() if k.startswith("friction"))
    assert abs(sum(loads)) <= 1e-13 * lost and lost > 1.0
    assert W["balancing moment"] == pytest.approx(lost, rel=1e-12)
    assert np.isfinite(res.friction_energy()).all()


def test_cycle_efficiency_of_a_machine_with_friction_is_unchanged():
    """The ICE (its own [friction]): the numbers before the change, and the power balance over the
    cycle (engine: shaft work out / gas work in), from work() and from the arrays by the trapezoid
    rule (first order across the friction's jumps: 3e-5 at 360 angles)."""
    ice = kinetostat.load("ice_crank_slider")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SelfLockingWarning)
        res = kinetostat.analyze(ice, steps=36, friction="reactions")
        fine = kinetostat.analyze(ice, steps=360, friction="reactions")
        first = kinetostat.analyze(ice, steps=36, friction="first")
    with warnings.catch_warnings():
        warnings.simplefilter("error", UndefinedFigureWarning)
        eta, eta_first = res.cycle_efficiency(), first.cycle_efficiency()
    assert eta == pytest.approx(0.5530360453469362, rel=1e-13) and res.cycle_efficiency_reason() == ""
    assert eta_first == pytest.approx(0.5519330355505162, rel=1e-13)
    W = res.work()
    assert eta == pytest.approx(-W["balancing moment"] / W["load gas force"], rel=1e-12)
    u = fine._unit_motion()
    W0, Wf = ((M * u.omega[:, 1]).mean() for M in (fine.balancing_moment_frictionless, fine.balancing_moment))
    assert abs(Wf / W0 - eta) <= 1e-4


CHAIN_F1 = _with_friction("chain_unit_four_bar", 1.0, 0.2)     # self-locking: no equilibrium at 140 .. 210 deg


def test_no_equilibrium_gives_nan_friction_power_and_undefined_cycle_figures():
    """Before: the last pass's friction loads stood there (up to 1e5 W on this model, 3.6e9 W on others),
    and the cycle efficiency was a bare NaN."""
    res = _analyze(CHAIN_F1)
    none = res.self_locking_reason == "no equilibrium"
    assert none.sum() == 8 and np.isnan(res.friction_power[none]).all() and np.isnan(res.friction.load[none]).all()
    assert np.isfinite(res.friction_power[~none]).all() and np.isnan(res.balancing_moment[none]).all()
    with pytest.warns(UndefinedFigureWarning, match=r"cycle_efficiency: undefined \(NaN\): no equilibrium with friction "
                                                   r"at some angles of the cycle \(\d+ of its \d+ integration angles, phi = 1[34]\d"):
        assert math.isnan(res.cycle_efficiency())
    with pytest.warns(UndefinedFigureWarning, match=r"friction_energy: undefined \(NaN\): no equilibrium"):
        assert np.isnan(res.friction_energy()).all()


YOKE_GUIDES = "R32 slider A on guide K and R03 slider Y on guide H"     # as the report names them


def test_singular_friction_jacobian_is_no_equilibrium_naming_the_angles_and_the_pairs():
    """The scotch yoke with f = 1: the two guides' friction loads enter the group only as their sum,
    Newton's Jacobian is singular (before: numpy.linalg.LinAlgError out of analyze and the CLI; then the
    angles only). One warning line names the angles and the pairs it cannot tell apart: the two guides,
    not the block's pin."""
    with pytest.warns(SelfLockingWarning) as w:
        res = kinetostat.analyze(_load(_with_friction("scotch_yoke", 1.0, 0.01)), steps=36)
    none = res.self_locking_reason == "no equilibrium"
    assert none.sum() >= 24 and "no equilibrium at phi = [" in str(w[0].message)
    assert set(res.phi_deg[none]) <= set(w[0].message.phi_deg)
    assert np.isnan(res.friction_power[none]).all() and np.isnan(res.balancing_moment[none]).all()
    tied = [x.message for x in w if x.category is SingularFrictionWarning]
    assert len(tied) == 1, [str(x.message) for x in w]
    text = str(tied[0])
    assert "\n" not in text and text.startswith(f"friction solve singular at {none.sum()} angle(s): the friction "
                                                f"loads of the pairs {YOKE_GUIDES} at phi = [10, 20, 30, ")
    assert list(tied[0].phi_deg) == list(res.phi_deg[none]) and set(tied[0].pairs) == {tuple(YOKE_GUIDES.split(" and "))}
    assert res.friction.dependent[none][:, 2:].all() and not res.friction.dependent[:, :2].any()
    assert not res.friction.dependent[~none].any()


@pytest.mark.parametrize("f, radius, pair_radius, field", [
    (0.1, 1e6, "", "friction.radius"),        # before: accepted silently, 1.5e13 W of friction power
    (0.1, 0.01, "1e6", "pair[0].radius"),     # the crank's own journal
    (5.0, 0.01, "", "friction.f"),            # a percentage?
])
def test_implausible_friction_figures_warn_naming_the_field(f, radius, pair_radius, field):
    text = _with_friction("chain_unit_four_bar", f, radius, pair_radius)
    with pytest.warns(ModelWarning) as w:
        kinetostat.loads(text)
    msgs = [str(x.message) for x in w if issubclass(x.category, ModelWarning)]
    assert len(msgs) == 1 and f": {field}: " in msgs[0], msgs


def test_plausible_friction_figures_do_not_warn():
    with warnings.catch_warnings():
        warnings.simplefilter("error", ModelWarning)
        kinetostat.load("ice_crank_slider")                                  # f 0.05, r 12 mm
        kinetostat.loads(_with_friction("chain_unit_four_bar", 1.0, 0.29))   # at the limits: f 1, r 0.5 x 0.585 m


def test_cli_says_why_the_cycle_efficiency_is_undefined(cli, tmp_path):
    path = tmp_path / "chain.toml"
    path.write_text(NO_NET_WORK["chain_unit_four_bar"])
    r = cli("analyze", path, "--steps", "36")
    assert r.returncode == 0 and "Traceback" not in r.stderr, r.stderr
    line = next(x for x in r.stdout.splitlines() if "cycle efficiency" in x)
    assert line.startswith("  cycle efficiency: undefined: the loads do no net work over the cycle"), line
    path.write_text(_with_friction("scotch_yoke", 1.0, 0.01))
    r = cli("analyze", path, "--steps", "36")
    assert r.returncode == 0 and "Traceback" not in r.stderr, r.stderr
    assert "cycle efficiency: undefined: no equilibrium with friction" in r.stdout
    tied = [x for x in r.stderr.splitlines() if "friction solve singular" in x]
    assert len(tied) == 1 and tied[0].startswith("kinetostat: warning: chain.toml: friction solve singular at 35 "
                                                 f"angle(s): the friction loads of the pairs {YOKE_GUIDES} at phi = [10, "), r.stderr


@pytest.mark.parametrize("model, at, why", [
    (_with_friction("scotch_yoke", 1.0, 0.01), 30.0, "no equilibrium with friction (self-locking)"),
    ("ice_crank_slider", 0.0, "near a dead centre (the frictionless balancing moment at most 0.1 of the moment friction takes)"),
])
def test_worksheet_says_why_eta_is_undefined(model, at, why):
    """Before: the eta row a bare NaN (a dash in the sheet, null in its JSON) with its formula as the note."""
    from kinetostat.plans.worksheet import worksheet
    mech = kinetostat.load(model) if "\n" not in model else _load(model)
    row = next(r for r in worksheet(mech, at=at).rows if r.key == "eta")
    assert math.isnan(row.value) and row.note == f"undefined: {why}"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SelfLockingWarning)
        assert kinetostat.analyze(mech, phi_deg=[at], friction="reactions").efficiency_reason[0] == why


def test_cli_values_table_says_why_eta_is_undefined(cli):
    r = cli("analyze", ROOT / "models" / "ice_crank_slider.toml", "--at", "0", "30", "180", "--friction", "reactions")
    assert r.returncode == 0 and "Traceback" not in r.stderr, r.stderr
    assert "  eta undefined at phi = 0, 180 deg: near a dead centre (the frictionless balancing moment at most 0.1 " \
           "of the moment friction takes)" in r.stdout.splitlines(), r.stdout


def test_sweep_says_once_why_eta_cycle_is_undefined(tmp_path):
    """Before: one UndefinedFigureWarning per design (a flood over a large sweep) and a bare NaN in the
    table. Now: each design's reason in eta_cycle_reason, one warning counting the designs by cause."""
    path = tmp_path / "chain.toml"
    path.write_text(NO_NET_WORK["chain_unit_four_bar"])
    with warnings.catch_warnings(record=True) as w:
        warnings.simplefilter("always")
        sw = kinetostat.sweep(path, {"r": [0.05, 0.08, 0.11]}, steps=36)
    msgs = [str(x.message) for x in w if issubclass(x.category, UndefinedFigureWarning)]
    assert msgs == ["sweep: eta_cycle undefined (NaN) for 3 of 3 design(s): 3 where the loads do no net work over "
                    "the cycle (each design's reason in eta_cycle_reason)"], msgs
    assert sw.table["eta_cycle"].isna().all() and sw.table.attrs["units"]["eta_cycle_reason"] == "text"
    assert sw.table["eta_cycle_reason"].str.startswith("the loads do no net work over the cycle (the frictionless").all()
    with warnings.catch_warnings():            # not a full cycle: no cycle efficiency asked for, no warning
        warnings.simplefilter("error", UndefinedFigureWarning)
        sw = kinetostat.sweep(path, {"r": [0.05, 0.08]}, phi_deg=[10.0, 20.0])
    assert (sw.table["eta_cycle_reason"] == "the angles are not a uniform full cycle (sweep with steps=N)").all()
