"""The commands on one model: `analyze` (summary, worksheet, full table), `structure`, `export`
(MJCF, URDF), `examples` (the bundled models listed or copied) and `schema` (the JSON Schema of
the model format).

May use: `.common`, the solver, `kinetostat.plans.worksheet`; the harness inside `cmd_export`.
"""
from __future__ import annotations

import math
import sys
from pathlib import Path

from .._text import one_line
from .common import CLIError, EXIT_OK, TABLE_SUFFIXES, _Out, _analyze, _done, _fmt, _law, _lines, _load, _model_error_lines, _parquet_engine, _save, _turn, _warn, _writable_file, bundled_models


def _summary(res, path: Path) -> list[str]:
    import numpy as np
    m = res.mech
    s = m.structure
    phi = res.phi_deg
    lines = [f"{m.name}   [{path}]",
             f"structure: {s.formula}   (W = 3*{s.n} - 2*{s.p5} - {s.p4} = {s.W})",
             f"{len(phi)} crank position(s), phi = {phi.min():g} .. {phi.max():g} deg; "
             f"omega1 = {m.drive.omega:.6g} rad/s ({m.drive.omega * 30 / math.pi:.6g} rpm, "
             f"{'ccw' if m.drive.sense > 0 else 'cw'})"]
    lines.append("peak reactions |R(i,j)| (force of link i on link j):")
    for p in m.pairs:
        mag = np.linalg.norm(res.forces.R[:, p.index], axis=-1)
        where = f"at {p.point}" if p.kind == "R" else f"guide {p.guide}"
        name = f"R({p.links[0]},{p.links[1]}) {where}"
        if np.any(np.isfinite(mag)):
            i = int(np.nanargmax(mag))
            lines.append(f"  {name:<22s} {_fmt(mag[i], 'N'):>14s}  at phi = {phi[i]:g} deg")
        else:
            lines.append(f"  {name:<22s} {'n/a':>14s}")
    M = res.balancing_moment
    if np.any(np.isfinite(M)):
        i, j = int(np.nanargmin(M)), int(np.nanargmax(M))
        lines.append(f"balancing moment M_bal: {_fmt(M[i], 'N m')} (phi = {phi[i]:g} deg) .. "
                     f"{_fmt(M[j], 'N m')} (phi = {phi[j]:g} deg)")
    if m.drive.kind == "machine":
        F = np.linalg.norm(res.balancing_force, axis=-1)
        if np.any(np.isfinite(F)):
            lines.append(f"balancing force |F_bal| on the gear mesh: {_fmt(np.nanmin(F), 'N')} .. {_fmt(np.nanmax(F), 'N')}")
    d = res.lever_discrepancy
    if np.any(np.isfinite(d)):
        k = int(np.nanargmax(np.abs(d)))
        lines.append(f"lever discrepancy max |M_lever - M_bal|: {abs(d[k]):.3g} N m (phi = {phi[k]:g} deg)")
    if m.friction is not None:
        lines += _friction_lines(res)
    triads = [n for n, g in enumerate(s.groups) if g.klass == 3]
    if triads and res.kin.residual is not None:
        r = res.kin.residual[:, triads].max(axis=1)
        k = int(np.argmax(r))
        lines.append(f"triads' closure (Newton) residual: largest leash miss {r[k]:.3g} m (phi = {phi[k]:g} deg; "
                     f"{r[k] / m.size:.2g} of the linkage's size)")
    n_sing = int(np.sum(res.singular))
    if n_sing:
        lines.append(f"singular positions: {n_sing} (their values are NaN)")
    if len(phi) <= 12:
        exact = res.friction is not None
        head = f"  {'phi, deg':>9s} {'M_bal, N m':>12s} " + (f"{'M_bal,0, N m':>12s} {'eta':>8s} {'passes':>6s} " if exact else "") \
            + " ".join(f"{'|R(%d,%d)|, N' % p.links:>13s}" for p in m.pairs)
        lines += ["values:", head]
        for n in range(len(phi)):
            extra = (f"{res.balancing_moment_frictionless[n]:12.6g} {res.efficiency[n]:8.4g} "
                     f"{int(res.friction.passes[n].max()):6d} ") if exact else ""
            lines.append(f"  {phi[n]:9.4g} {M[n]:12.6g} {extra}" + " ".join(
                f"{np.linalg.norm(res.forces.R[n, p.index]):13.6g}" for p in m.pairs))
        if exact:                      # a NaN eta with its reason
            why = res.efficiency_reason
            lines += [f"  eta undefined at phi = {', '.join(f'{a:g}' for a in phi[why == r])} deg: {r}"
                      for r in dict.fromkeys(why[why != ""])]
    return lines


def _friction_lines(res) -> list[str]:
    """The summary's friction lines: the method, the self-locking angles by reason (on a uniform
    full cycle the zones, edges to 1e-9 deg), eta elsewhere; with friction in the reactions the
    frictionless and frictional peak M_bal, the passes, the friction power per pair (where an
    equilibrium exists) and the cycle efficiency (on a uniform full cycle), or why it is undefined."""
    import warnings

    import numpy as np
    from ..errors import SelfLockingWarning
    m, phi = res.mech, res.phi_deg
    lock, why = res.self_locking, res.self_locking_reason
    eta = res.efficiency[~lock & np.isfinite(res.efficiency)]
    lines = [f"friction ({res.friction_method}): self-locking at {int(lock.sum())} of {len(phi)} positions"
             + (f", eta {eta.min():.4g} .. {eta.max():.4g} elsewhere" if len(eta) else "")]
    cycle = len(phi) > 1 and np.allclose(phi, phi[0] + np.arange(len(phi)) * 360.0 / len(phi), rtol=0, atol=1e-9)
    if cycle and lock.any():
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", SelfLockingWarning)
            zones = res.self_locking_zones()
        lines.append("  self-locking zones: " + "; ".join(f"{round(a, 9) + 0.0:.9f} .. {round(b, 9) + 0.0:.9f} deg" for a, b in zones))
    for key in dict.fromkeys(why[lock]):
        at = phi[why == key]
        lines.append(f"  {key}: {len(at)} position(s), phi = " + ", ".join(f"{x:g}" for x in at[:8])
                     + (", ..." if len(at) > 8 else ""))
    if res.friction is None:
        return lines
    M0, Mf = res.balancing_moment_frictionless, res.balancing_moment
    if np.isfinite(Mf).any():
        i, k = int(np.nanargmax(np.abs(M0))), int(np.nanargmax(np.abs(Mf)))
        lines.append(f"  peak |M_bal| frictionless {_fmt(abs(M0[i]), 'N m')} (phi = {phi[i]:g} deg), "
                     f"with friction {_fmt(abs(Mf[k]), 'N m')} (phi = {phi[k]:g} deg)")
    p = res.friction.passes
    lines.append(f"  passes per group: at most {int(p.max(initial=0))} (Newton's method at "
                 f"{int(res.friction.newton.sum())} position(s))")
    P = res.friction_power
    lines.append("  peak friction power: " + ", ".join(
        f"{q.label} {_fmt(float(np.nanmax(P[:, q.index])), 'W')}" for q in m.pairs if np.isfinite(P[:, q.index]).any()))
    if cycle:
        why = res.cycle_efficiency_reason()
        lines.append(f"  cycle efficiency: undefined: {why}" if why else f"  cycle efficiency: {res.cycle_efficiency():.6g}")
    return lines


def _worksheet_lines(mech, phi: float) -> list[str]:
    """The worksheet's kinematic and inertia values at one position, as a student compares them."""
    import warnings

    from ..plans.worksheet import worksheet
    with warnings.catch_warnings():          # the analysis above has warned already
        warnings.simplefilter("ignore")
        ws = worksheet(mech, at=phi)
    lines = [f"worksheet at phi = {phi:g} deg (kinematics, inertia and loads; mu_l = {ws.mu_l:g} m/mm):"]
    for r in ws.rows:
        if r.section in ("kinematics", "accelerations", "inertia"):
            sense = r.direction if r.direction in ("cw", "ccw") else ""
            lines.append(f"  {r.symbol:<14s} {_fmt(r.value, r.unit):>18s}  {sense}".rstrip())
    return lines


def cmd_analyze(args) -> int:
    out = args.out
    if out is not None and out != "-":
        suffix = Path(out).suffix.lower()
        if suffix not in TABLE_SUFFIXES:
            raise CLIError(f"--out {out}: unknown table format {suffix or '(no suffix)'!r}; "
                           f"use one of {', '.join(TABLE_SUFFIXES)} (or '-' for CSV on stdout)")
        if suffix == ".parquet":
            _parquet_engine(f"--out {out}", ".csv / .json")
        _writable_file(out, "--out")
    path = Path(args.model)
    mech = _load(path)
    law = None
    if args.delta is not None or args.flywheel is not None:
        law = _law(mech, path, delta=args.delta, flywheel=args.flywheel, steps=args.steps)
    res, _ = _analyze(mech, path, phi_deg=_turn(args.at, "--at"), steps=args.steps, friction=args.friction,
                      out=out, law=law)
    lines = _summary(res, path)
    if law is not None:
        lines.insert(3, f"at the true law of motion (--{'delta' if args.delta is not None else 'flywheel'}): "
                        f"omega_mean = {law.omega_mean:.6g} rad/s, delta = {law.delta:.6g}, "
                        f"J_flywheel = {law.J_flywheel:.6g} kg m^2 on the crank shaft (see 'kinetostat motion')")
    if len(res.phi_deg) == 1:
        lines += _worksheet_lines(mech, float(res.phi_deg[0]))
    if out is not None:
        from .. import tables
        df = res.to_frame()
        if out == "-":
            _Out.write(tables.csv_text(df).rstrip("\n"))
        else:
            suffix = Path(out).suffix.lower()
            write = {".csv": tables.write_csv, ".json": tables.write_json}.get(suffix, tables.write_parquet)
            _save(out, "--out", lambda f: write(df, f), binary=suffix == ".parquet")
            lines.append(f"table: {len(df)} rows x {len(df.columns)} columns -> {out}")
    else:
        lines.append("(the full table: --out FILE.csv | FILE.parquet | FILE.json)")
    _Out.write(_lines(lines), err=(out == "-"))
    return EXIT_OK


def cmd_structure(args) -> int:
    path = Path(args.model)
    m = _load(path)
    s = m.structure
    pairs = ", ".join(f"{p.label} at {p.point}" if p.kind == "R" else f"{p.label} guide {p.guide}" for p in m.pairs)
    crank = next(p for p in m.pairs if set(p.links) == {0, 1})
    lines = [f"{m.name}   [{path}]",
             f"moving links n = {s.n}: " + ", ".join(f"{k.id} {k.name}" for k in m.links[1:]),
             f"lower pairs p5 = {s.p5}: {pairs}",
             f"higher pairs p4 = {s.p4}",
             f"mobility (Chebyshev): W = 3n - 2p5 - p4 = 3*{s.n} - 2*{s.p5} - {s.p4} = {s.W}",
             f"initial mechanism I(0,1): crank 1 on the frame at {crank.point} ({crank.label})",
             "Assur groups, in order of attachment:"]
    lines += [f"  {g.describe()}" for g in s.groups]
    if not s.groups:
        lines.append("  none")
    lines.append(f"structure formula: {s.formula}")
    lines.append(f"class {s.mechanism_class}, order {s.order}")
    if args.modes:
        from ..errors import AssemblyError
        from ..kinematics import assembly_modes, triad_warnings
        try:
            found = assembly_modes(m)
            for text in triad_warnings(m):         # the analysis' own warnings: two modes close, ...
                _warn(f"{path.name}: {text}")
        except AssemblyError as exc:
            raise CLIError(f"{path}: {exc}") from None
        lines += ["assembly modes at the design position:"] + [x for am in found for x in am.lines()]
    if m.parameters:
        lines.append("parameters: " + ", ".join(f"{n} = {v:.10g}" for n, v in m.parameters.items()))
    if m.expressions:
        lines.append("numbers from expressions:")
        lines += [f"  {path} = {text} = {v:.10g}" for path, (text, v) in m.expressions.items()]
    _Out.write(_lines(lines))
    return EXIT_OK


def cmd_export(args) -> int:
    from ..errors import AssemblyError, ModelError
    path = Path(args.model)
    mech = _load(path)
    from kinetostat_validation.export import to_mjcf, to_urdf
    try:
        text = to_mjcf(mech) if args.format == "mjcf" else to_urdf(mech)
    except AssemblyError as exc:
        raise CLIError(f"{path}: {exc}") from None
    except ModelError as exc:       # faults that show only over the cycle (a travel diagram's stroke)
        raise CLIError(lines=_model_error_lines(exc)) from None
    if args.output is None or args.output == "-":
        _Out.write(text.rstrip("\n"))
        return EXIT_OK
    _save(args.output, "-o", lambda f: f.write(text))
    _done(one_line(f"{args.format.upper()} of {path.name} -> {args.output}"))
    return EXIT_OK


def cmd_schema(args) -> int:
    from ..model.describe import print_schema
    return print_schema(sys.stdout)


def cmd_examples(args) -> int:
    from .. import examples
    if args.force and args.copy is None:
        raise CLIError("--force only goes with --copy DIR (it replaces files already in DIR)")
    if args.copy is not None:
        try:
            written = examples.copy(args.copy, overwrite=args.force)
        except FileExistsError as exc:
            raise CLIError(f"--copy {args.copy}: {exc.filename} {exc.strerror}; nothing copied "
                           f"(--force replaces them)") from None
        except OSError as exc:
            raise CLIError(f"cannot write --copy {args.copy}: {exc.strerror or exc}") from None
        _done(one_line(f"{len(written)} files ({', '.join(p.name for p in written)}) -> {args.copy}"))
        return EXIT_OK
    lines = [f"bundled models in {examples.models_dir()} (by name: kinetostat.load(NAME); "
             f"copies: kinetostat examples --copy DIR):"]
    for path in bundled_models():
        m = _load(path)
        lines.append(f"  {path.stem:<24s} {m.structure.formula:<34s} {m.source or m.name}")
    _Out.write(_lines(lines))
    return EXIT_OK
