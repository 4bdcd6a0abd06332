"""`analyze(mech, phi_deg)`: the whole kinetostatic analysis, by the path that suits the work: the
numpy path (`analysis.exact`) below `fast.threshold(mech)` angles (and for what the kernel
refuses), the compiled kernel (`fast`) from them on.

May use: model, analysis, fast, motion.
"""
from __future__ import annotations

from . import fast
from .analysis import Analysis, crank_angles, exact, friction_method
from .model import Mechanism
from .motion import Motion, at_motion

__all__ = ["analyze"]


def analyze(mech: Mechanism, phi_deg=None, steps: int = 360, friction: str | None = None,
            law: Motion | None = None) -> Analysis:
    """Kinematic and kinetostatic analysis of `mech` at crank angles `phi_deg` (deg, array-like),
    or at `steps` equal steps over a full revolution when `phi_deg` is None.

    `law` (a `kinetostat.law_of_motion(mech)` result): at that true motion instead of the model's
    drive speed, with its flywheel (J_flywheel on the crank about its axis: no force, the moment
    -J_flywheel eps); at law.phi_deg (the default angles then) exactly its omega and eps, between
    them the periodic cubic Hermite through its omega and d omega/d phi = eps/omega. The balancing
    moment about +z is then drive.sense x law.M_drive (with [friction]: balancing_moment_with_friction
    is, the first approximation's losses being part of law.M_red).

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
    if law is not None:
        if not isinstance(law, Motion):
            raise TypeError(f"analyze: law: expected a Motion (kinetostat.law_of_motion(mech)), got {type(law).__name__}")
        if law.mech != mech:
            raise ValueError(f"analyze: law: the Motion of another mechanism ({law.mech.name!r}), not of {mech.name!r}")
        phi_deg = law.phi_deg if phi_deg is None else phi_deg
        mech = at_motion(mech, law.phi_deg, law.omega, law.eps / law.omega, law.J_flywheel)
    phi_deg = crank_angles(phi_deg, steps)
    method = friction_method(mech, friction)
    if (method != "reactions" or mech.friction is None) and fast.pays(mech, len(phi_deg)):
        return fast.analyze_fast(mech, phi_deg)
    return exact(mech, phi_deg, method)
