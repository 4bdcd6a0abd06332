"""The teaching commands: `plans` (the SVG sheets of the graphical method), `page` (the interactive
page of a mechanism) and `variant` (the task variants of Logvinenko, Nadtoka 2021 and their answer
keys).

May use: `.common`, `kinetostat._forecast` (the estimated time of --all), the solver, `kinetostat.plans`, `kinetostat.variants`.
"""
from __future__ import annotations

import argparse
import logging
import math
import sys
import time
import warnings
from pathlib import Path

from .._forecast import Forecast
from .._io import unit
from .._text import one_line
from .common import (CLIError, EXIT_OK, _Out, _checkpoint, _close, _done, _law, _lines, _load, _os_reason, _progress, _size,
                     _turn, _warn, _writable_dir, _writable_file)

log = logging.getLogger(__name__)


def _scale_item(text: str) -> tuple[str, float]:
    from ..plans.scales import SCALE_UNITS
    key, eq, value = text.partition("=")
    if not eq or key not in SCALE_UNITS:
        raise argparse.ArgumentTypeError(f"invalid --scale {text!r}: expected KEY=VALUE with KEY one of "
                                         f"{', '.join(SCALE_UNITS)}, e.g. --scale mu_l=0.001 mu_v=0.2")
    try:
        x = float(value)
    except ValueError:
        x = math.nan
    if not (math.isfinite(x) and x >= sys.float_info.min):      # a subnormal scale divides to inf
        raise argparse.ArgumentTypeError(f"invalid --scale {text!r}: {key} must be a positive number "
                                         f"in {SCALE_UNITS[key]} (at least {sys.float_info.min:.3g})")
    return key, x


def _plan_names(text: str) -> list[str]:
    from ..plans import BUILDERS
    names = [n.strip() for n in text.split(",") if n.strip()]
    valid = [n for n, _ in BUILDERS]
    bad = [n for n in names if n not in valid]
    if bad or not names:
        raise argparse.ArgumentTypeError(f"invalid --only {text!r}: expected plan names from {', '.join(valid)}, "
                                         f"comma-separated")
    return names


def cmd_plans(args) -> int:
    import numpy as np
    from ..errors import ModelWarning, SelfLockingWarning, SingularPositionWarning, singular_message
    from ..kinematics import DIGITS_MIN
    from ..plans import build, cycle_scales, solve
    from ..plans.worksheet import worksheet
    from ..model.lettering import lettering
    from ..plans.scales import ScaleError
    path = Path(args.model)
    mech = _load(path)
    law = _law(mech, path, delta=args.delta, flywheel=args.flywheel) \
        if args.delta is not None or args.flywheel is not None else None
    args.lang = args.lang or lettering(mech).language or "en"
    out = _writable_dir(args.out, "--out")
    only = [n for group in (args.only or []) for n in group] or None
    args.at, args.starting = _turn(args.at, "--at"), _turn(args.starting, "--starting")
    try:
        with warnings.catch_warnings(record=True) as caught:     # the accuracy at this angle: said below
            warnings.simplefilter("always")
            at = mech.drive.design_deg if args.at is None else args.at
            solution = solve(mech, [at], args.friction or "first", law)          # every sheet below from it
            fixed = cycle_scales(mech, solution=solution) if args.cycle_scales else None          # the page's scales
            plans = build(mech, at=at, scales=dict(args.scale or []), starting_deg=args.starting, only=only,
                          fixed=fixed, friction=args.friction or "first", law=law, solution=solution)
            sheet = None if only else worksheet(mech, plans.at, mu_l=plans.scales["mu_l"].value, lang=args.lang,
                                                friction=args.friction or "first", law=law, solution=solution)
    except ScaleError as exc:             # a plan beyond a sheet's size, before any of it is drawn
        raise CLIError(f"--scale {exc}") from None
    except ValueError as exc:
        raise CLIError(f"--at {args.at if args.at is not None else 'design position'}: {exc}") from None
    try:
        with unit(out) as tmp:                # swapped in as a set: never new sheets beside an old worksheet
            written = plans.write(tmp, lang=args.lang) + (sheet.write(tmp) if sheet is not None else [])
    except (OSError, ValueError) as exc:
        raise CLIError(f"cannot write --out {out}: {getattr(exc, 'strerror', None) or exc}") from None
    at_plan = []
    for w in caught:                      # of the cycle's angles, the plans' alone; the model's: any angle
        if issubclass(w.category, SingularPositionWarning):
            here = np.isclose(w.message.phi_deg, plans.at)
            if here.any():
                m = w.message
                at_plan.append(singular_message(m.group, m.phi_deg[here], m.cond[here], m.digits[here], DIGITS_MIN))
        elif issubclass(w.category, (SelfLockingWarning, ModelWarning)):
            at_plan.append(str(w.message))
    for text in dict.fromkeys(t.splitlines()[0] for t in at_plan):
        _warn(f"{path.name}: {text}")
    _done(one_line(plans.summary(path.name, len(written), out, args.lang)))
    return EXIT_OK


def cmd_page(args) -> int:
    from ..model.lettering import lettering
    from ..plans.page import write_page
    mech = _load(Path(args.model))
    out = _writable_file(args.out, "--out")
    try:
        path = write_page(mech, out, lang=args.lang or lettering(mech).language or "en", student=args.student,
                          at=_turn(args.at, "--at"))
    except ValueError as exc:
        raise CLIError(f"--at {args.at if args.at is not None else 'design position'}: {exc}") from None
    _done(one_line(f"{Path(args.model).name}: page -> {path} ({_size(path.stat().st_size)})"))
    return EXIT_OK


def cmd_variant(args) -> int:
    from .. import variants
    from ..errors import AssemblyError, ModelError
    try:
        tasks = list(variants.TASKS) if args.task is None else [variants.check_task(args.task, "TASK")]
        if args.all and args.code is not None:
            raise CLIError(f"CODE {args.code!r}: not with --all (--all writes every code of the task)")
        if not args.all:
            if args.task is None or args.code is None:
                raise CLIError("TASK and CODE are required (e.g. 'kinetostat variant 1 479'), or --all")
            jobs = [variants.variant(tasks[0], variants.check_code(args.code, tasks[0], "CODE"))]
        else:
            jobs = [(t, c) for t in tasks for c in variants.codes()]
    except ValueError as exc:
        raise CLIError(f"{exc} (see 'kinetostat variant --help')") from None
    args.lang = args.lang or "uk"                   # seed 002's language (its models' [lettering])
    teacher_pack = not args.no_pack
    default = "task_variants" if args.all else jobs[0].name
    out = _writable_dir(args.out or default, "--out")
    if args.all:                                    # the first line of a long job, before its first key
        pack = "with the teacher's pack" if teacher_pack else "no pack"
        log.info(one_line(f"variant --all: {len(jobs)} code(s) of task(s) {', '.join(map(str, tasks))} into {out}, "
                          f"{pack}{', pages' if args.page else ''}"))
    t0 = time.perf_counter()
    keys = []
    eta = Forecast(log, len(jobs), "variant(s)", faster=(["--no-pack"] if teacher_pack else [])
                   + (["no --page"] if args.page else []) + (["one TASK"] if args.task is None else []))
    bar = _progress(len(jobs), "variants", args.all and not args.no_progress)
    try:
        for job in jobs:
            _checkpoint()
            v = job if not args.all else variants.variant(*job)
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                try:
                    keys.append(variants.write_key(v, out / v.name if args.all else out, lang=args.lang,
                                                   cycle_csv=not args.all, root=out, teacher_pack=teacher_pack,
                                                   page=args.page))
                except (AssemblyError, ModelError, ValueError) as exc:   # also a folder linked outside --out
                    raise CLIError(f"task {v.task} variant {v.code}: {exc}") from None
                except OSError as exc:
                    raise CLIError(f"cannot write --out {out}: {_os_reason(exc, out)}") from None
            log.debug("task %d variant %s: the key, %d files", v.task, v.code, len(keys[-1].files))
            bar.update()
            eta.done()
        if args.all:
            try:
                index = variants.write_index(out, keys, args.lang)
            except OSError as exc:
                raise CLIError(f"cannot write the index into {out}: {_os_reason(exc, out)}") from None
    finally:
        _close(bar)
    if args.all:
        from ..plans.i18n import num, text
        _done(one_line(text("cli.all", args.lang, keys=len(keys), tasks=", ".join(map(str, tasks)), out=out,
                                 index=index, s=num(time.perf_counter() - t0, args.lang, decimals=1))))
        return EXIT_OK
    lines = variants.summary(jobs[0], keys[0], out, args.lang)
    _Out.write(_lines(lines))
    return EXIT_OK
