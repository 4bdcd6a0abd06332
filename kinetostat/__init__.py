"""kinetostat: kinetostatic analysis of planar linkages by the graphical-analytic method.

    >>> import kinetostat
    >>> mech = kinetostat.load("models/ice_crank_slider.toml")
    >>> res = kinetostat.analyze(mech, phi_deg=[30.0])
    >>> mech.structure.formula
    'I(0,1) <- II(2,3)'
    >>> res
    Analysis(mechanism='ICE crank-slider (worked example of Logvinenko, Nadtoka 2021)', positions=1, phi_deg=30, singular=0)

The plans of the graphical method: `kinetostat.plans.build(mech, at=30)`. The submodules `examples`,
`plans` and `variants` are imported when first used (`kinetostat.plans`), not by `import kinetostat`.

Progress and diagnostics that are not warnings go to the logger `logging.getLogger("kinetostat")`
(each module's logger under it); the package gives it a NullHandler only, so an application
configures logging itself (the command line: one stderr handler, -q and -v).

The solver's public names. May use: the solver modules only (never the harness
`kinetostat_validation`, the engines, matplotlib or `kinetostat.report`).
"""
import logging as _logging
import os as _os
import sys as _sys
from typing import TYPE_CHECKING as _TYPE_CHECKING

_logging.getLogger(__name__).addHandler(_logging.NullHandler())


def _interrupted_while_starting(signum, frame) -> None:
    """Ctrl-C while the command line imports the package: one line and exit 130, no traceback."""
    _os.write(2, b"kinetostat: error: interrupted\n")
    _os._exit(130)


if _sys.argv[:1] == ["-m"] or _os.path.basename(_sys.argv[0] if _sys.argv else "") in ("kinetostat", "kinetostat.exe"):
    import signal as _signal      # the command line starts (`python -m kinetostat`, or its script): cli.main takes over
    _signal.signal(_signal.SIGINT, _interrupted_while_starting)

from .analysis import Analysis, InertiaLoad     # after the handler: these imports take most of the start
from .solve import analyze
from .errors import (AssemblyError, ModelError, ModelFileNotFound, ModelWarning, SelfLockingWarning,
                     SingularFrictionWarning, SingularPositionWarning, StructureError, UndefinedFigureWarning)
from .kinematics import COND_CHECK, COND_MAX, DIGITS_MIN, DIGITS_WARN
from .model import Flywheel, Mechanism, from_dict, load, loads
from .motion import Motion, law_of_motion
from .sensitivity import Sensitivity, sensitivity
from .structure import AssurGroup, Structure
from .sweep import Sweep, sweep
from .tolerance import Tolerance, tolerance
from .virtual_work import VirtualWork, virtual_work

if _TYPE_CHECKING:
    from . import examples, plans, variants

#: The submodules imported on first use (`__getattr__`): the plans alone took half of the start.
_LAZY = ("examples", "plans", "variants")


def __getattr__(name: str):
    """`kinetostat.plans` (and `examples`, `variants`) imported when first asked for (PEP 562)."""
    if name in _LAZY:
        import importlib
        return importlib.import_module(f"{__name__}.{name}")
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_LAZY))

__all__ = ["load", "loads", "from_dict", "analyze", "virtual_work", "VirtualWork", "Mechanism", "Analysis", "InertiaLoad",
           "AssurGroup", "Structure", "ModelError", "ModelFileNotFound", "ModelWarning", "StructureError",
           "AssemblyError", "SingularPositionWarning", "SelfLockingWarning", "SingularFrictionWarning", "UndefinedFigureWarning", "COND_CHECK", "COND_MAX", "DIGITS_WARN", "DIGITS_MIN",
           "examples", "plans", "variants", "sweep", "Sweep", "tolerance", "Tolerance", "law_of_motion", "Motion", "Flywheel", "sensitivity", "Sensitivity"]
__version__ = "0.2.0"
