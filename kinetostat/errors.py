"""Errors and warnings of kinetostat: every message names the field path or the crank angles.

May use: the standard library, numpy and `_text` (one-line problems).
"""
from __future__ import annotations

import errno
from collections.abc import Sequence

import numpy as np

from ._text import one_line

__all__ = ["ModelError", "ModelFileNotFound", "ModelWarning", "AssemblyError", "StructureError",
           "SingularPositionWarning", "SelfLockingWarning", "SingularFrictionWarning", "UndefinedFigureWarning"]


class ModelError(ValueError):
    """A model file or a model object is invalid. `problems` lists every fault found; `lines`
    (same length) the line of the TOML file where each sits, or None where none is known."""

    def __init__(self, problems: Sequence[str], source: str = "model",
                 lines: Sequence[int | None] | None = None):
        self.problems = [one_line(p) for p in problems]    # a newline in a name cannot forge a line
        self.source = source
        self.lines = list(lines) if lines is not None else [None] * len(self.problems)
        text = "\n".join(f"  - {p}" for p in self.located)
        super().__init__(f"{one_line(source)}: {len(self.problems)} problem(s):\n{text}")

    @property
    def located(self) -> list[str]:
        """The problems, each led by its line in the file ("line 12: ...") where it is known."""
        return [p if n is None else f"line {n}: {p}" for p, n in zip(self.problems, self.lines)]


class ModelFileNotFound(ModelError, FileNotFoundError):
    """The model file does not exist (`except FileNotFoundError` catches it too); `hint`: a line
    that names a bundled model of that name (`kinetostat.examples.hint`)."""

    def __init__(self, path: str, hint: str = ""):
        super().__init__(["cannot read file: no such file" + (f"; {hint}" if hint else "")], source=path)
        self.errno, self.strerror, self.filename = errno.ENOENT, "No such file or directory", path

    def __str__(self) -> str:
        return self.args[0]      # the ModelError text, not "[Errno 2] ..."


class ModelWarning(UserWarning):
    """A model loads, but a number or a rule it relies on looks like a mistake (the message
    gives the number and its likely cause)."""


class StructureError(ValueError):
    """The linkage is not a mobility-1 chain of class-II Assur groups and triads III3 on a crank."""


def _angle_list(phi_deg: np.ndarray, limit: int = 12) -> str:
    shown = ", ".join(f"{a:.6g}" for a in phi_deg[:limit])
    more = f", ... ({len(phi_deg)} angles in all)" if len(phi_deg) > limit else ""
    return f"[{shown}{more}] deg"


class AssemblyError(ValueError):
    """The linkage cannot be assembled at some crank angles (`phi_deg` lists them)."""

    def __init__(self, group: str, phi_deg: np.ndarray, why: str):
        self.group, self.why = group, why
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


class SelfLockingWarning(UserWarning):
    """With friction in the reactions, the self-locking crank angles, each with its reason
    (`Analysis.self_locking_reason`): "no equilibrium" (neither the friction passes nor Newton's
    method find one: M_bal, the forces and the friction power NaN), "wedged" (a pair's friction gain >= 1: an
    equilibrium exists but is not the only one; M_bal is the one reached from the frictionless
    solution, eta NaN) or "eta<=0" (the loads cannot drive the crank through friction: M_bal is
    the equilibrium value, the drive must help). `phi_deg` lists the angles, `reasons` the
    reason of each."""

    def __init__(self, message: str, phi_deg=(), reasons=()):
        super().__init__(message)
        self.phi_deg = np.round(np.asarray(phi_deg, dtype=float), 9)     # undo rad->deg rounding
        self.reasons = tuple(reasons)


#: What M_bal means at a self-locking angle of each reason (`SelfLockingWarning`).
SELF_LOCKING_MEANING = {
    "no equilibrium": "no finite drive moves the mechanism: M_bal, the reactions and the friction power NaN",
    "wedged": "a pair's friction gain >= 1, the equilibrium not unique: M_bal is the one reached from the "
              "frictionless solution, eta NaN",
    "eta<=0": "the loads cannot drive the crank through friction: M_bal is the equilibrium, the drive helps",
}


def self_locking_message(phi_deg: np.ndarray, reasons) -> str:
    """The warning's one-line text: the self-locking angles grouped by reason, each with what M_bal means there."""
    reasons = np.asarray(reasons, dtype=object)
    parts = [f"{key} at phi = {_angle_list(np.round(np.asarray(phi_deg)[reasons == key], 9))} ({why})"
             for key, why in SELF_LOCKING_MEANING.items() if (reasons == key).any()]
    return f"self-locking with friction in the reactions at {len(reasons)} angle(s): " + "; ".join(parts)


class SingularFrictionWarning(SelfLockingWarning):
    """With friction in the reactions, Newton's method stopped on a Jacobian singular to rounding:
    the friction loads of some pairs are not independent in their group (the yoke's two guides'
    enter it only as their sum), so no equilibrium, or no unique one, is found at those angles
    (self-locking, "no equilibrium"). `phi_deg` lists the angles, `pairs` the names of the pairs
    at each (a tuple of names per angle)."""

    def __init__(self, message: str, phi_deg=(), pairs=()):
        self.pairs = tuple(tuple(names) for names in pairs)
        super().__init__(message, phi_deg, ("no equilibrium",) * len(self.pairs))


def singular_friction_message(phi_deg: np.ndarray, pairs) -> str:
    """The warning's one-line text: the angles where Newton's Jacobian is singular, grouped by the
    pairs (their names, a tuple per angle) whose friction loads it found dependent."""
    phi = np.round(np.asarray(phi_deg, dtype=float), 9)
    parts = [f"{' and '.join(names)} at phi = {_angle_list(phi[[p == names for p in pairs]])}"
             for names in dict.fromkeys(pairs)]
    return (f"friction solve singular at {len(pairs)} angle(s): the friction loads of the pairs "
            + "; of ".join(parts) + " are not independent in their group (Newton's Jacobian singular to "
            "rounding): no equilibrium found there (M_bal, the reactions and the friction power NaN)")


class UndefinedFigureWarning(UserWarning):
    """A figure over the cycle with friction (`cycle_efficiency`, `friction_energy`, `work`) is
    undefined and returned as NaN; `reason` says why (the loads do no net work over the cycle, or
    no equilibrium with friction at some of its angles)."""

    def __init__(self, message: str, reason: str = ""):
        super().__init__(message)
        self.reason = reason
