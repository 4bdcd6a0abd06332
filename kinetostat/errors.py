"""Errors and warnings of kinetostat: every message names the field path or the crank angles."""
from __future__ import annotations

from collections.abc import Sequence

import numpy as np

__all__ = ["ModelError", "AssemblyError", "StructureError", "SingularPositionWarning"]


class ModelError(ValueError):
    """A model file or a model object is invalid. `problems` lists every fault found."""

    def __init__(self, problems: Sequence[str], source: str = "model"):
        self.problems = list(problems)
        self.source = source
        lines = "\n".join(f"  - {p}" for p in self.problems)
        super().__init__(f"{source}: {len(self.problems)} problem(s):\n{lines}")


class StructureError(ValueError):
    """The linkage is not a mobility-1 chain of class-II Assur groups on a crank."""


def _angle_list(phi_deg: np.ndarray, limit: int = 12) -> str:
    shown = ", ".join(f"{a:.6g}" for a in phi_deg[:limit])
    more = f", ... ({len(phi_deg)} angles in all)" if len(phi_deg) > limit else ""
    return f"[{shown}{more}] deg"


class AssemblyError(ValueError):
    """The linkage cannot be assembled at some crank angles (`phi_deg` lists them)."""

    def __init__(self, group: str, phi_deg: np.ndarray, why: str):
        self.group = group
        self.phi_deg = np.round(np.asarray(phi_deg, dtype=float), 9)   # undo rad->deg rounding
        super().__init__(f"group {group} cannot be assembled ({why}) at phi = {_angle_list(self.phi_deg)}")


class SingularPositionWarning(UserWarning):
    """A group is near a singular (dead-centre / toggle) position at some crank angles, where the
    values keep fewer than DIGITS_WARN significant digits (estimated by a perturbed re-solve).

    Fields: `group` (its label), `phi_deg` (the angles, deg), `cond` (the group plan's condition
    number there), `digits` (the digits estimated left at each of those angles)."""

    def __init__(self, message: str, group: str = "", phi_deg=(), cond=(), digits=()):
        super().__init__(message)
        self.group = group
        self.phi_deg = np.round(np.asarray(phi_deg, dtype=float), 9)     # undo rad->deg rounding
        self.cond = np.asarray(cond, dtype=float)
        self.digits = np.asarray(digits, dtype=float)


def singular_message(group: str, phi_deg: np.ndarray, cond: np.ndarray, digits: np.ndarray,
                     digits_min: int) -> str:
    """The warning's text: the angles, the largest cond, the fewest digits left and what was done."""
    nan = digits < digits_min
    if nan.all():
        what = f"values set to NaN: fewer than {digits_min} digits left"
    elif nan.any():
        what = (f"values set to NaN at {_angle_list(np.round(phi_deg[nan], 9))}, where fewer than "
                f"{digits_min} digits are left; kept elsewhere")
    else:
        what = "values kept"
    return (f"group {group} is near a singular position at phi = {_angle_list(np.round(phi_deg, 9))}; "
            f"condition number up to {np.max(cond):.3g}; estimated significant digits left "
            f"{np.min(digits):.1f} to {np.max(digits):.1f} ({what})")
