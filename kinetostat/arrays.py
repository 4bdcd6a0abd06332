"""The solver on the arrays of any library that follows the Python Array API standard (CuPy,
JAX, PyTorch; array-api-strict in the tests), through array-api-compat: the mechanism's
programs (`kinetostat.program`) run with the group equations bound to the arrays' namespace,
so the work stays on the arrays' device. The model's constants move there once (memoised per
mechanism, namespace and device).

Covered: the kinematics, gravity and inertia, the reactions of every pair, M_bal and F_bal. Not
covered: loads besides gravity and inertia (their tables and characteristics are numpy code),
laws of motion, and the accuracy guard (no perturbed re-solve): `solve` refuses the first two
by name and returns `cond` so the caller can see ill-conditioned angles.

May use: array-api-compat, program, groups.
"""
from __future__ import annotations

from typing import TYPE_CHECKING, Any, Mapping


from .program import bind, constants, motion_program, run, statics_program

if TYPE_CHECKING:
    from .model import Mechanism

__all__ = ["solve"]


def solve(mech: "Mechanism", phi: Any) -> Mapping[str, Any]:
    """Kinematics and kinetostatics of `mech` at crank angles `phi` (rad, an (N,) array of an
    Array API library), on that library and device. Returns arrays of it, leading with the
    angle axis: theta, omega, eps (N, L) rad, rad/s, rad/s^2; rot, origin, v, a (N, L) complex
    (x + iy, m, m/s, m/s^2, world frame); R (N, n_pairs) complex, force of pair.links[0] on
    pair.links[1], N; M_bal (N,) N m about +z; F_bal (N,) complex, N; cond (N, n_groups)."""
    from array_api_compat import array_namespace, device
    xp = array_namespace(phi)
    if mech.loads or mech.springs:
        raise NotImplementedError(f"kinetostat.arrays.solve: {mech.name!r} has loads besides gravity and inertia "
                                  f"({', '.join(ld.name for ld in mech.loads) or 'springs'}); use kinetostat.analyze")
    if mech.drive.law is not None:
        raise NotImplementedError("kinetostat.arrays.solve: a law of motion (drive omega(phi)); use kinetostat.analyze")
    triads = [g.label for g in mech.structure.groups if g.klass == 3]
    if triads:
        raise NotImplementedError(f"kinetostat.arrays.solve: a class-III group ({', '.join(triads)}): its positions "
                                  f"are a continuation over the angle axis in numpy; use kinetostat.analyze")
    dev = device(phi)
    env = dict(mech.memo(("xp constants", id(xp), str(dev)), lambda: {
        n: xp.asarray(v, dtype=xp.complex128 if isinstance(v, complex) else xp.float64, device=dev)
        for n, v in {**constants(mech), "w_in": float(mech.drive.omega), "e_in": float(mech.drive.eps)}.items()}))
    env["phi"] = phi
    run(motion_program(mech), env, xp=xp)
    g = bind(xp)
    L = mech.n_links
    for k in range(1, L):
        r, F_i, M_i = g.inertia(env[f"A{k}"], env[f"w{k}"], env[f"e{k}"], env[f"rot{k}"], env[f"com{k}"],
                                env[f"mass{k}"], env[f"I_S{k}"])
        env[f"F{k}"], env[f"M{k}"] = g.wrench(*g.weight(r, env[f"mass{k}"], env["g"]), F_i, M_i, r)
    run(statics_program(mech), env, xp=xp)
    N = phi.shape[0]

    def stack(stem: str, count: int, rest: complex, dtype, start: int = 1):
        return xp.stack([xp.broadcast_to(xp.asarray(env[f"{stem}{k}"] if k >= start and f"{stem}{k}" in env else rest,
                                                    dtype=dtype, device=dev), (N,)) for k in range(count)], axis=-1)

    f, c = xp.float64, xp.complex128
    return {"theta": stack("th", L, 0.0, f), "omega": stack("w", L, 0.0, f), "eps": stack("e", L, 0.0, f),
            "rot": stack("rot", L, 1.0, c), "origin": stack("O", L, 0.0, c), "v": stack("V", L, 0.0, c),
            "a": stack("A", L, 0.0, c), "R": stack("R", len(mech.pairs), 0.0, c, 0),
            "cond": stack("cond", len(mech.structure.groups), 0.0, f, 0),
            "M_bal": xp.broadcast_to(xp.asarray(env["M_bal"], dtype=f, device=dev), (N,)),
            "F_bal": xp.broadcast_to(xp.asarray(env["F_bal"], dtype=c, device=dev), (N,))}
