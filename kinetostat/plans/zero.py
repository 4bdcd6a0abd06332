"""What is zero on a sheet, and so not drawn: a link's ω and ε, its inertia force and couple, a
side of a plan (seed 000 sec. 4: a translating link has no M_i; seed 002 fig. 1.6 draws the
senses of what turns), decided by one rule, never by `== 0.0` on floats:

- exactly zero by the link's kind of motion: a link joined to the frame by a prismatic pair, or
  by one to such a link, translates (`translates`): ω, ε, M_i are zero at every angle;
- else zero at an angle where its magnitude is at most ZERO_REL of the same kind of quantity of
  the crank there (`rates`): ω_k against |ω_1|, ε_k against ω_1² + |ε_1|, a centre of mass's
  acceleration against (ω_1² + |ε_1|) times the mechanism's size. The solver's rounding noise
  (ω2 = 8e-15 rad/s of a crank at 524 rad/s) is 1e-17 of it; a value the solver keeps has at
  least DIGITS_MIN = 6 digits, far above.

May use: numpy and the solver's public results (`Analysis`, `Mechanism`).
"""
from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from ..analysis import Analysis
    from ..model import Mechanism

__all__ = ["ZERO_REL", "translates", "rates", "zero_omega", "zero_eps", "zero_inertia_force", "zero_of", "zero_notes",
           "by_pattern"]

#: A quantity at most this fraction of its reference (`rates`) is zero: not drawn.
ZERO_REL = 1e-9


def translates(mech: "Mechanism", k: int) -> bool:
    """Whether link k translates by its pairs: joined by a prismatic pair to the frame or to a
    link that translates (a piston, a ram)."""
    still, grew = {0}, True
    while grew:
        grew = False
        for p in mech.pairs:
            if p.kind == "P" and (p.links[0] in still) != (p.links[1] in still):
                still |= set(p.links)
                grew = True
    return k != 0 and k in still


def rates(res: "Analysis") -> tuple[np.ndarray, np.ndarray]:
    """(N,) each: the references of an angular velocity (|ω_1|, rad/s) and of an angular
    acceleration (ω_1² + |ε_1|, rad/s²) at each angle, of the crank."""
    d = res.mech.drive.link
    w, e = np.abs(res.kin.omega[:, d]), np.abs(res.kin.eps[:, d])
    return w, w * w + e


def zero_of(values, reference) -> np.ndarray:
    """(N,) bool: where |values| <= ZERO_REL reference (NaN: not zero, not known)."""
    return np.abs(np.asarray(values, dtype=float)) <= ZERO_REL * np.asarray(reference, dtype=float)


def zero_omega(mech: "Mechanism", res: "Analysis", k: int) -> np.ndarray:
    """(N,) bool: where ω_k is zero (`translates`, or ZERO_REL of |ω_1|)."""
    return np.full(len(res.phi_deg), translates(mech, k)) | zero_of(res.kin.omega[:, k], rates(res)[0])


def zero_eps(mech: "Mechanism", res: "Analysis", k: int) -> np.ndarray:
    """(N,) bool: where ε_k, and so M_i<k> = -I_S ε_k, is zero (`translates`, or ZERO_REL of
    ω_1² + |ε_1|)."""
    return np.full(len(res.phi_deg), translates(mech, k)) | zero_of(res.kin.eps[:, k], rates(res)[1])


def zero_inertia_force(mech: "Mechanism", res: "Analysis", k: int) -> np.ndarray:
    """(N,) bool: where F_i<k> = -m a_S is zero (a_S at most ZERO_REL of (ω_1² + |ε_1|) times the
    mechanism's size)."""
    F = res.F_i[:, k]
    return zero_of(np.hypot(F[:, 0], F[:, 1]), mech.links[k].mass * rates(res)[1] * mech.size)


def by_pattern(where: np.ndarray, make) -> list:
    """`make(row)` of each angle's column of `where` (Q, N) bool, made once for each distinct
    column: a per-angle note from which quantities are zero there, without a loop over the angles."""
    patterns, inverse = np.unique(np.asarray(where, dtype=bool).T, axis=0, return_inverse=True)
    made = [make(p) for p in patterns]
    return [made[i] for i in inverse.reshape(-1)]


def zero_notes(zeros: dict[str, tuple[np.ndarray, str]], n: int) -> list[tuple[str, ...]]:
    """The notes of each of n angles on the quantities not drawn there: name -> ((N,) bool where
    zero, why: "" for "at this angle", else e.g. "link 5 translates"); one line per reason."""
    if not zeros:
        return [()] * n
    items = list(zeros.items())

    def notes(row: np.ndarray) -> tuple[str, ...]:
        by_why: dict[str, list[str]] = {}
        for (name, (_, why)), z in zip(items, row):
            if z:
                by_why.setdefault(why, []).append(f"{name} = 0")
        return tuple(f"{', '.join(names)} ({why or 'at this angle'}): not drawn" for why, names in by_why.items())
    return by_pattern(np.stack([np.broadcast_to(where, (n,)) for where, _ in zeros.values()]), notes)
