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
    """A group is near a singular (dead-centre / toggle) position at some crank angles."""


def singular_message(group: str, phi_deg: np.ndarray, cond: np.ndarray, marked: bool) -> str:
    what = "values set to NaN" if marked else "values kept, accuracy reduced"
    return (f"group {group} is near a singular position at phi = {_angle_list(phi_deg)}; "
            f"condition number up to {np.max(cond):.3g} ({what})")
