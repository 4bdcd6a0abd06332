"""The seeds' published values of a bundled model, set beside the exact ones.

May use: numpy, the solver (analysis, model). Never matplotlib, the harness or the engines.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable

import numpy as np

from ..analysis import Analysis, analyze
from ..model import Mechanism


@dataclass(frozen=True)
class PublishedValue:
    """One number a seed prints, and how to get the same quantity from an Analysis."""
    symbol: str                         # as the source names it
    meaning: str                        # what it is, in this project's terms
    value: float                        # the published number
    unit: str
    compute: Callable[[Analysis], float]
    tolerance: float                    # accepted |difference|: relative, or deg when unit == "deg"


@dataclass(frozen=True)
class PublishedSet:
    """A seed's published results for one bundled model, at the crank angles it used."""
    source: str
    phi_deg: tuple[float, ...]          # angles the source evaluated (deg, model's convention)
    accuracy: str                       # why the tolerance is what it is
    values: tuple[PublishedValue, ...]
    picture_deg: float = 30.0           # position of the mechanism picture in the report


def _n(a) -> float:
    return float(np.linalg.norm(np.asarray(a)[0]))


def _F_O1(res: Analysis) -> np.ndarray:
    return np.linalg.norm(res.reaction(0, 1), axis=-1)


_G = 0.005      # seed 002 reads its plans to 0.1 mm on ~80 mm vectors: 0.5 %
_P = 0.01       # seed 004 prints 0.1 N of its own sampling on a reconstructed geometry: 1 %

#: The seeds' published numbers, in ONE place, keyed by model stem.
PUBLISHED: dict[str, PublishedSet] = {
    "ice_crank_slider": PublishedSet(
        source="seed 002 (UkrDUZT course guide, part 1), sec. 1.2.2-1.2.3: the worked example "
               "at phi = 30 deg from top dead centre, velocity, acceleration and force plans drawn "
               "and measured, and Zhukovsky's lever",
        phi_deg=(30.0,),
        accuracy="values measured on drawn plans (lengths to 0.1 mm on ~80 mm vectors): 0.5 %",
        picture_deg=30.0,
        values=(
            PublishedValue("V_B", "|v_B|, piston velocity", 10.94, "m/s", lambda r: _n(r.velocity("B")), _G),
            PublishedValue("V_BA", "|v_B - v_A|, relative velocity", 14.92, "m/s",
                           lambda r: _n(r.velocity("B") - r.velocity("A")), _G),
            PublishedValue("V_S2", "|v_S2|, rod centre of mass", 12.2, "m/s", lambda r: _n(r.velocity("S2")), _G),
            PublishedValue("omega2", "|omega_2|, rod", 135.6, "rad/s", lambda r: abs(float(r.omega(2)[0])), _G),
            PublishedValue("a_B", "|a_B|, piston acceleration", 8311.0, "m/s^2",
                           lambda r: _n(r.acceleration("B")), _G),
            PublishedValue("a_S2", "|a_S2|, rod centre of mass", 7875.0, "m/s^2",
                           lambda r: _n(r.acceleration("S2")), _G),
            PublishedValue("eps2", "|eps_2|, rod", 33782.0, "rad/s^2", lambda r: abs(float(r.eps(2)[0])), _G),
            PublishedValue("F_i2", "|F_i2|, rod inertia force", 3937.5, "N", lambda r: _n(r.inertia(2).force), _G),
            PublishedValue("F_i3", "|F_i3|, piston inertia force", 3216.4, "N", lambda r: _n(r.inertia(3).force), _G),
            PublishedValue("M_i2", "|M_i2|, rod inertia moment", 57.43, "N m",
                           lambda r: abs(float(r.inertia(2).moment[0])), _G),
            PublishedValue("R12", "|R(1,2)|, crank on rod at A", 3172.0, "N", lambda r: _n(r.reaction(1, 2)), _G),
            PublishedValue("R43", "|R(0,3)|, cylinder (frame, the text's link 4) on piston", 780.5, "N",
                           lambda r: _n(r.reaction(0, 3)), _G),
            PublishedValue("R32", "|R(3,2)|, piston on rod at B", 6481.0, "N", lambda r: _n(r.reaction(3, 2)), _G),
            PublishedValue("M_bal (force plans)", "|M_bal|, group by group", 102.74, "N m",
                           lambda r: abs(float(r.balancing_moment[0])), _G),
            PublishedValue("M_bal (lever)", "|M_bal| by Zhukovsky's lever", 102.97, "N m",
                           lambda r: abs(float(r.lever_moment[0])), _G),
        )),
    "chain_unit_four_bar": PublishedSet(
        source="seed 004, V. A. Potapov (2024), force analysis of the chain-unit drive mechanism, "
               "line 389: the crank bearing O1 is the most loaded pair, F_O1 = 38.4 .. 286.9 N, "
               "largest near phi_k = 90 deg",
        phi_deg=tuple(float(a) for a in range(0, 360, 10)),
        accuracy="the paper's cycle sampled every 10 deg from phi_k = 0, values printed to 0.1 N, "
                 "geometry reconstructed from its formulas: 1 %; the angle of the maximum 'near 90 deg': 10 deg",
        picture_deg=90.0,
        values=(
            PublishedValue("F_O1 min", "min |R(0,1)| over the sampled cycle", 38.4, "N",
                           lambda r: float(np.nanmin(_F_O1(r))), _P),
            PublishedValue("F_O1 max", "max |R(0,1)| over the sampled cycle", 286.9, "N",
                           lambda r: float(np.nanmax(_F_O1(r))), _P),
            PublishedValue("phi_k at F_O1 max", "crank angle of the maximum (paper: 'near 90 deg')", 90.0, "deg",
                           lambda r: float(r.phi_deg[np.nanargmax(_F_O1(r))]), 10.0),
        )),
}


def published_rows(mech: Mechanism, stem: str) -> list[dict[str, Any]] | None:
    """Exact values of this model next to the seed's published ones (None if none published)."""
    pub = PUBLISHED.get(stem)
    if pub is None:
        return None
    res = analyze(mech, phi_deg=list(pub.phi_deg))
    out = []
    for v in pub.values:
        got = v.compute(res)
        if v.unit == "deg":
            diff, ok = got - v.value, abs(got - v.value) <= v.tolerance
        else:
            diff = 100.0 * (got - v.value) / v.value
            ok = abs(diff) <= 100.0 * v.tolerance
        out.append(dict(symbol=v.symbol, meaning=v.meaning, published=v.value, exact=got, unit=v.unit,
                        diff=diff, diff_unit="deg" if v.unit == "deg" else "%", tolerance=v.tolerance, ok=ok))
    return out
