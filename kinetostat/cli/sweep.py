"""`sweep`: every combination of some parameters' values analysed, one row of peaks per design.

May use: `.common`, the solver, `kinetostat.sweep`.
"""
from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

from .common import CLIError, EXIT_OK, _done, _lines, _load, _parquet_engine, _quiet, _save, _scheduler_installed, _writable_file


def _param(text: str) -> tuple[str, list[float]]:
    """`--param NAME=VALUES`: a range start:stop:step that includes its stop, a list a,b,c, or one value."""
    name, eq, spec = text.partition("=")
    name = name.strip()
    if not eq or not name or not spec.strip():
        raise argparse.ArgumentTypeError(f"invalid --param {text!r}: expected NAME=VALUES, e.g. --param r=0.05:0.11:0.015 "
                                         f"(start:stop:step, stop included), --param n_k=0,60,120 or --param c=0.54")
    try:
        if ":" in spec:
            return name, _range(*(float(x) for x in spec.split(":")))
        values = [float(x) for x in spec.split(",")]
    except (TypeError, ValueError) as exc:
        why = str(exc) if isinstance(exc, _RangeError) else "expected numbers"
        raise argparse.ArgumentTypeError(f"invalid --param {text!r}: {why} (a range start:stop:step includes its "
                                         f"stop; a list a,b,c)") from None
    if not all(map(math.isfinite, values)):
        raise argparse.ArgumentTypeError(f"invalid --param {text!r}: expected finite numbers")
    return name, values


class _RangeError(ValueError):
    pass


def _range(start: float, stop: float, step: float) -> list[float]:
    """start, start + step, ..., stop (included, as the texts' ranges are), each start + k step
    rounded to 12 digits of the range's scale; the step must divide stop - start."""
    if not all(map(math.isfinite, (start, stop, step))) or step == 0:
        raise _RangeError("the range's start, stop and step must be finite and the step non-zero")
    n = (stop - start) / step
    k = round(n)
    if n < -1e-9 or abs(n - k) > 1e-9 * max(1.0, abs(n)):
        raise _RangeError(f"the step {step:g} does not go from {start:g} to {stop:g} in whole steps")
    if k >= 100_000:
        raise _RangeError(f"{k + 1} values: at most 100000 per parameter")
    decimals = 12 - math.floor(math.log10(max(abs(start), abs(stop), abs(step))))
    return [round(start + i * step, decimals) for i in range(k)] + [stop]


def _table_writer(out: str):
    """How `--out` is written, by its suffix: (write(df, file), binary)."""
    from .. import tables
    suffix = Path(out).suffix.lower()
    if suffix == ".csv":
        return tables.write_csv, False
    if suffix == ".parquet":
        _parquet_engine(f"--out {out}", ".csv")
        return tables.write_parquet, True
    raise CLIError(f"--out {out}: unknown table format {suffix or '(no suffix)'!r}; use .parquet or .csv")


def cmd_sweep(args) -> int:
    from ..sweep import sweep
    write, binary = _table_writer(args.out)
    names = [n for n, _ in args.param]
    twice = sorted({n for n in names if names.count(n) > 1})
    if twice:
        raise CLIError(f"--param {twice[0]}: given more than once; give all its values in one --param")
    _scheduler_installed(args.scheduler)
    out = _writable_file(args.out, "--out")
    angles_out = out.with_name(f"{out.stem}.angles{out.suffix}") if args.full else None
    if angles_out is not None:
        _writable_file(str(angles_out), "--out")
    path = Path(args.model)
    mech = _load(path)
    t0 = time.perf_counter()
    try:
        sw = sweep(mech, dict(args.param), steps=args.steps, full=args.full, scheduler=args.scheduler,
                   friction=args.friction,
                   chunk=args.chunk, progress=not args.no_progress and not _quiet() and sys.stderr.isatty())
    except ValueError as exc:
        raise CLIError(f"--param: {str(exc).removeprefix('sweep: ')}") from None
    except ConnectionError as exc:       # no distributed scheduler at that address
        raise CLIError(f"--scheduler {args.scheduler}: {str(exc).partition(': ')[2]}") from None
    secs = time.perf_counter() - t0
    _save(out, "--out", lambda f: write(sw.table, f), binary)
    lines = [f"{mech.name}   [{path}]",
             f"{len(sw.table)} designs ({' x '.join(f'{n} {k}' for n, k in zip(names, sw.shape))}) x "
             f"{len(sw.phi_deg)} crank positions in {secs:.2f} s",
             f"table: {len(sw.table)} rows x {len(sw.table.columns)} columns -> {out}"]
    if angles_out is not None:
        _save(angles_out, "--out", lambda f: write(sw.angles, f), binary)
        lines.append(f"every angle: {len(sw.angles)} rows x {len(sw.angles.columns)} columns -> {angles_out}")
    failed = sw.table[sw.table["error"] != ""]
    if len(failed):
        lines.append(f"{len(failed)} design(s) failed (NaN peaks, the reason in the column 'error'), the first: "
                     f"{failed['error'].iloc[0]}")
    singular = int((sw.table["n_singular"].fillna(0) > 0).sum())
    if singular:
        lines.append(f"{singular} design(s) pass through singular positions (columns n_singular, singular_deg)")
    warned = sw.table["worst_digits"].dropna()
    if len(warned):
        from ..kinematics import DIGITS_WARN
        lines.append(f"{len(warned)} design(s) keep values with fewer than {DIGITS_WARN} significant digits near a "
                     f"singular position, down to {warned.min():.1f} (columns worst_digits, warned_deg)")
    _done(_lines(lines))
    return EXIT_OK
