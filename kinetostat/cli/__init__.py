"""The command line, `kinetostat COMMAND`: analyze, structure, plans, validate, report, export, examples,
variant, sweep, schema (also `python -m kinetostat`).

Exit codes: 0 success; 1 `validate` found a check beyond tolerance or a route that raised, or
`report` could not make a model's report; 2 bad input or options (model file, structure,
assembly, angles, engine names, output path, stdout that cannot be written, `--steps` beyond the
memory the process may take: MemoryError, or refused before by the memory guard); 3 `validate`: no
failure, but a model that nothing checked (every route skipped, no published values), or a
route named with --engines whose engine is not installed; 130 interrupted (Ctrl-C). `sweep`
exits 0 once its table is written, also where designs failed (each keeps its row with the
reason in `error`). Expected problems print one `kinetostat: error: ...` line (a model file's
problem list prints one line per problem) and never a traceback; warnings print one line each. Every output file is written atomically (`kinetostat._io.atomic`): an interrupt or a full
disk leaves the previous file as it was; a device, FIFO, or the process's own stdout or stderr
(also through a link, e.g. /dev/stderr) named as an output is written as a stream, never replaced; the files of `plans`, `variant` and each model's `report` are
swapped in as a set (`kinetostat._io.unit`). Text from a model is printed with its control
characters visible, and every error, warning and summary line stays one line (a newline as \\n).
-q (errors only) and -v (also progress lines), before or after the command, set the level of the
package logger `kinetostat`, to which `main` gives one stderr handler while a command runs.

The rooms: `common` (what every command shares: exit codes, errors, output, interrupts, atomic
saving, progress, loading), one module per command or group of related commands (`analyze`:
analyze, structure, export, examples, schema; `validate`; `report`; `plans`: plans, variant;
`sweep`), `parser` (the options of every command), and `main` here.

May use: every room of the package, and the harness inside the commands that need it
(imported there, so that `import kinetostat.cli` loads no engine).
"""
from __future__ import annotations

import sys
import warnings
from typing import Sequence

from .common import (EXIT_FAIL, EXIT_INTERRUPTED, EXIT_NOT_CHECKED, EXIT_OK, EXIT_USAGE, CLIError, _checkpoint,
                     _error, _interrupts, _logging, _quiet_stdout, _readable_streams, _showwarning, bundled_models)
from .parser import build_parser
from .sweep import _param, _range, _RangeError
from .validate import exit_code, validation_table

__all__ = ["main", "build_parser", "exit_code", "bundled_models", "CLIError", "validation_table", "EXIT_OK",
           "EXIT_FAIL", "EXIT_USAGE", "EXIT_NOT_CHECKED", "EXIT_INTERRUPTED", "_param", "_range", "_RangeError"]


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the `kinetostat` console script; returns the exit code."""
    warnings.showwarning = _showwarning
    _readable_streams()
    with _interrupts():
        try:
            parser = build_parser()
            args = parser.parse_args(argv)
            with _logging(args.verbosity):
                code = args.func(args)
                _checkpoint()
            sys.stdout.flush()           # stdout on a full disk fails here, not at the interpreter's exit
            return code
        except CLIError as exc:
            _error(exc)
            return exc.code
        except KeyboardInterrupt:
            _error("interrupted")
            return EXIT_INTERRUPTED
        except MemoryError:              # what the memory guard (`--steps`) could not foresee
            _error("out of memory (MemoryError); use fewer --steps, or give the process more memory")
            return EXIT_USAGE
        except BrokenPipeError:          # `kinetostat ... | head`: the reader has what it wanted
            _quiet_stdout()
            return EXIT_OK
        except OSError as exc:           # stdout on a full disk, a name the file system cannot hold
            _quiet_stdout()
            where = f"{exc.filename}: " if exc.filename else "cannot write to stdout: "
            _error(f"{where}{exc.strerror or exc}")
            return EXIT_USAGE
