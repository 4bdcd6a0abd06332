"""The command `motion`: a machine's law of motion (`kinetostat.law_of_motion`) as a table
(motion.csv), one sheet of diagrams (motion.svg, motion.pdf: `kinetostat.plans.motion_sheet`) and a
summary (summary.txt, also printed), written into DIR as one set.

May use: `.common`, the solver (`kinetostat.motion`, `kinetostat.tables`), `kinetostat.plans.motion_sheet`.
"""
from __future__ import annotations

import math
from pathlib import Path

from .._io import unit
from .._text import one_line
from .common import CLIError, EXIT_OK, _Out, _done, _law, _lines, _load, _os_reason, _writable_dir

#: motion.csv's columns: the Motion's (N,) arrays, in its order, with their units.
COLUMNS = {"phi_deg": "deg", "J_red": "kg m^2", "dJ_red": "kg m^2/rad", "M_red": "N m", "M_drive": "N m",
           "work": "J", "T": "J", "omega": "rad/s", "eps": "rad/s^2"}


def frame(motion):
    """The Motion's arrays as a DataFrame, units in attrs["units"] (`tables.write_csv`'s header)."""
    import pandas as pd
    df = pd.DataFrame({k: getattr(motion, k) for k in COLUMNS})
    df.attrs["units"] = dict(COLUMNS)
    return df


def _where(motion, delta, flywheel) -> str:
    """Where the flywheel came from: the option, the model's [flywheel], or none."""
    if delta is not None:
        return f"sized for delta = {delta:g} (--delta)"
    if flywheel is not None:
        return "given (--flywheel)"
    fw = motion.mech.flywheel
    if fw is None:
        return "none (no --delta, --flywheel or [flywheel] in the model)"
    return f"sized for the model's [flywheel] delta = {fw.delta:g}" if fw.J is None else "the model's [flywheel] J"


def summary_lines(motion, path: Path, delta=None, flywheel=None) -> list[str]:
    """The summary: speeds, delta, the flywheel exact and by each approximate method with its
    difference from the exact, the drive's moment."""
    import numpy as np
    m = motion.mech
    J = motion.J_flywheel
    M = np.asarray(motion.M_drive)
    lines = [f"{m.name}   [{path}]",
             f"law of motion over {len(motion.phi_deg)} positions, drive: {motion.drive}",
             f"omega_mean = {motion.omega_mean:.6g} rad/s ({motion.omega_mean * 30 / math.pi:.6g} rpm); "
             f"omega_max = {motion.omega_max:.6g}, omega_min = {motion.omega_min:.6g} rad/s",
             f"delta = {motion.delta:.6g}" + ("" if motion.delta_target is None else f" (asked {motion.delta_target:g})"),
             f"J_flywheel = {J:.6g} kg m^2 (exact; {_where(motion, delta, flywheel)})"]
    for method, value in motion.approximate.items():
        diff = f"{(value - J) / J * 100:+.3g} % from the exact" if J > 0 else f"{value - J:+.3g} kg m^2 from the exact"
        lines.append(f"  {method}: J_flywheel = {value:.6g} kg m^2 ({diff})")
    if np.ptp(M) <= 1e-12 * max(np.max(np.abs(M)), 1e-300):
        lines.append(f"M_drive = {M[0]:.6g} N m (constant)")
    else:
        lines.append(f"M_drive = {M.min():.6g} .. {M.max():.6g} N m (mean {M.mean():.6g}; the characteristic M(omega))")
    lines.append(f"J_red = {np.min(motion.J_red):.6g} .. {np.max(motion.J_red):.6g} kg m^2; "
                 f"M_red = {np.min(motion.M_red):.6g} .. {np.max(motion.M_red):.6g} N m")
    return lines


def cmd_motion(args) -> int:
    from .. import tables
    from ..model.lettering import lettering
    from ..plans.motion_sheet import motion_sheet, no_drive
    path = Path(args.model)
    mech = _load(path)
    motion = _law(mech, path, delta=args.delta, flywheel=args.flywheel, steps=args.steps)
    out = _writable_dir(args.out, "--out")     # after the law: a refused model leaves no folder behind
    lang = args.lang or lettering(mech).language or "en"
    lines = summary_lines(motion, path, args.delta, args.flywheel)
    why = no_drive(motion.M_red)
    if why:                                    # gravity only: the machine runs free, its speed still swings
        lines.append(f"{why}: M_drive = 0, the machine runs free")
    sheet = motion_sheet(motion, lang)
    names = ("motion.csv", "motion.svg", "motion.pdf", "summary.txt")
    try:
        with unit(out) as tmp:              # one set: never a new table beside an old sheet
            with open(tmp / names[0], "w", encoding="utf-8", newline="") as f:
                tables.write_csv(frame(motion), f)
            (tmp / names[1]).write_text(sheet.svg(), encoding="utf-8")
            (tmp / names[2]).write_bytes(sheet.pdf())
            (tmp / names[3]).write_text("\n".join(map(one_line, lines)) + "\n", encoding="utf-8")
    except (OSError, ValueError) as exc:
        raise CLIError(f"cannot write --out {out}: {_os_reason(exc, out) if isinstance(exc, OSError) else exc}") from None
    _Out.write(_lines(lines))
    _done(one_line(f"{path.name}: {', '.join(names)} -> {out}"))
    return EXIT_OK
