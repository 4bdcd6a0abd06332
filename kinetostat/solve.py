"""`analyze(mech, phi_deg)`: the whole kinetostatic analysis, by the path that suits the work: the
numpy path (`analysis.exact`) below `fast.threshold(mech)` angles (and for what the kernel
refuses), the compiled kernel (`fast`) from them on.

May use: model, analysis, fast.
"""
from __future__ import annotations

from . import fast
from .analysis import Analysis, crank_angles, exact, friction_method
from .model import Mechanism

__all__ = ["analyze"]


def analyze(mech: Mechanism, phi_deg=None, steps: int = 360, friction: str | None = None) -> Analysis:
    """Kinematic and kinetostatic analysis of `mech` at crank angles `phi_deg` (deg, array-like),
    or at `steps` equal steps over a full revolution when `phi_deg` is None.

    `friction` (a model with [friction] only; the default is the model's `friction.method`, else
    "first"): "first" is the first approximation of the TMM course text on friction (frictionless
    reactions and M_bal, the friction power from them); "reactions" solves the reactions with
    friction exactly (`kinetostat.friction`), group by group, on the numpy path at any number of angles.

    From `fast.threshold(mech)` angles on it runs the compiled kernel (`fast.analyze_fast`):
    fast.FAST_MIN (10,000) where this process holds the mechanism's kernel already, fast.FAST_COLD
    (500,000) where the call would load it; below them the numpy path (`exact`): the same results
    to rounding (tests/test_fast.py). A mechanism the kernel does not take (`fast.refusal`: a
    class-III group) and friction="reactions" (the kernel has no friction in the reactions) go
    the numpy path at any count."""
    if not isinstance(mech, Mechanism):
        raise TypeError(f"analyze: expected a Mechanism, got {type(mech).__name__}; "
                        f"read a model file with kinetostat.load(path)")
    phi_deg = crank_angles(phi_deg, steps)
    method = friction_method(mech, friction)
    if (method != "reactions" or mech.friction is None) and fast.pays(mech, len(phi_deg)):
        return fast.analyze_fast(mech, phi_deg)
    return exact(mech, phi_deg, method)
