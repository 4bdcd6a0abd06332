"""The many designs of a sweep or a Monte Carlo tolerance study: the model's text parsed once
(`model.parse_text`) and each design built from it (`model.build`), the very Mechanism and analysis
that `loads` gives with the same parameters; the designs analysed a batch per kernel call
(`fast.analyses`), the very Analyses `analyze_fast` gives one by one; and a chunk whose designs
partly fail keeps the others' outputs."""
from __future__ import annotations

import dataclasses
import importlib
import warnings

import numpy as np
import pytest

import kinetostat
from kinetostat import fast
from kinetostat.analysis import crank_angles
from kinetostat.examples import resolve
from kinetostat.model import ModelError, build, loads, parse_text
from kinetostat.model.source import _read_text

tolmod = importlib.import_module("kinetostat.tolerance")      # the module (kinetostat.tolerance is the function)

#: Designs of models whose parameters are read by expressions (chain unit: l = sqrt(r**2 + c**2),
#: O1C1 = m_A r / m1_mA; ICE: l_AS2 = AS2_AB l_AB), each built in turn from one parsed text.
DESIGNS = {
    "chain_unit_four_bar": [{"r": 0.0801}, {"r": 0.05, "l": 0.6}, {"r": 0.11, "n_k": 300.0}, {}],
    "ice_crank_slider": [{"l_AB": 0.12}, {"AS2_AB": 0.4, "n1": 3000.0}, {"l_OA": 0.03, "l_AB": "3.5 * l_OA"}, {}],
}


def _text(name: str) -> tuple[str, str]:
    path = resolve(name)
    return _read_text(path), str(path)


@pytest.mark.parametrize("name", sorted(DESIGNS))
def test_each_design_built_from_one_parsed_text_is_the_mechanism_loads_gives(name):
    text, source = _text(name)
    model = parse_text(text, source)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", kinetostat.ModelWarning)
        for design in DESIGNS[name]:
            built, read = build(model, parameters=design), loads(text, source, parameters=design)
            for f in dataclasses.fields(read):
                assert getattr(built, f.name) == getattr(read, f.name), (design, f.name)
            assert dict(built.expressions) == dict(read.expressions)
            assert built.structure.formula == read.structure.formula
            a, b = kinetostat.analyze(built, steps=36), kinetostat.analyze(read, steps=36)
            np.testing.assert_array_equal(a.forces.R, b.forces.R)
            np.testing.assert_array_equal(a.balancing_moment, b.balancing_moment)


def test_the_parameters_of_a_design_do_not_leak_into_the_next():
    text, source = _text("chain_unit_four_bar")
    model = parse_text(text, source)
    assert build(model, parameters={"r": 0.1}).parameters["l"] == pytest.approx(np.hypot(0.1, 0.54), rel=1e-15)
    assert build(model).parameters["r"] == 0.080
    assert build(model).parameters["l"] == loads(text, source).parameters["l"]


def test_a_design_that_fails_names_its_field_and_line_as_loads_does():
    text, source = _text("chain_unit_four_bar")
    model = parse_text(text, source)
    with pytest.raises(ModelError) as built:
        build(model, parameters={"r": "sqrt(-1)"})
    with pytest.raises(ModelError) as read:
        loads(text, source, parameters={"r": "sqrt(-1)"})
    assert built.value.located == read.value.located
    assert any("parameters.r" in m and "line" in m for m in built.value.located), built.value.located


@pytest.mark.skipif(not fast.available(), reason="numba is not installed")
@pytest.mark.parametrize("name", [pytest.param(n, marks=() if n == "chain_unit_four_bar" else pytest.mark.slow)
                                  for n in sorted(DESIGNS)])
def test_designs_analysed_a_batch_per_kernel_call_are_those_analysed_one_by_one(name):
    """The four-bar by default (its kernels are compiled for tests/test_fast.py anyway); the ICE
    (its own two kernels to compile: about 40 s of CPU from a cold cache) with -m slow."""
    text, source = _text(name)
    model = parse_text(text, source)
    phi = crank_angles(None, 36)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", kinetostat.ModelWarning)
        mechs = [build(model, parameters=d) for d in DESIGNS[name]]
    together = fast.analyses(mechs, phi)
    for mech, a in zip(mechs, together):
        b = fast.analyze_fast(mech, phi, threads=1)
        for x, y in ((a.forces.R, b.forces.R), (a.balancing_moment, b.balancing_moment), (a.kin.a_z, b.kin.a_z),
                     (a.kin.error, b.kin.error), (a.singular, b.singular)):
            np.testing.assert_array_equal(x, y)


@pytest.mark.skipif(not fast.available(), reason="numba is not installed")
def test_a_chunk_whose_designs_partly_fail_keeps_the_others_outputs():
    """The coupler l within +-0.3 m of its 0.546 m: some four-bars do not assemble (2 of these 40);
    analysed together by the kernel, the same designs fail, for the same reason, as on the numpy
    path, and the rest agree with it."""
    text, source = _text("chain_unit_four_bar")
    model = parse_text(text, source)
    phi = crank_angles(None, 36)
    spec = lambda compiled: tolmod._Spec(["l"], np.array([build(model).parameters["l"]]), np.array([0.3]), "uniform",
                                         3, phi, compiled, np.zeros((36, 5)))
    together, failed, first = tolmod._outputs(model, spec(True), range(40))
    alone, failed_alone, first_alone = tolmod._outputs(model, spec(False), range(40))
    assert 0 < failed < 40 and (failed, first) == (failed_alone, first_alone)
    np.testing.assert_allclose(together, alone, rtol=1e-9, atol=1e-9)
