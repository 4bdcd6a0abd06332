"""The command line of the studies that write files (`python -m kinetostat_validation.drawing_error`,
`.stability`, `.benchmark`): `--out`, by default `./reports` of the working directory (never a
folder inside the installed package), and one line naming the extra to install where the plots'
matplotlib is missing.

May use: the standard library.
"""
from __future__ import annotations

import argparse
import importlib.util
from pathlib import Path

__all__ = ["OUT", "parser", "require_plots"]

#: The studies' default output folder, relative to the working directory.
OUT = Path("reports")


def parser(module: str, doc: str) -> argparse.ArgumentParser:
    """The parser of `python -m kinetostat_validation.<module>`: its docstring's first paragraph and `--out`."""
    ap = argparse.ArgumentParser(prog=f"python -m kinetostat_validation.{module}", description=" ".join(doc.split("\n\n")[0].split()))
    ap.add_argument("--out", type=Path, default=OUT, metavar="DIR",
                    help="folder for the study's files, made if missing (default: ./reports)")
    return ap


def require_plots(ap: argparse.ArgumentParser) -> None:
    """Exit 2 with one line, before any work, where matplotlib (extra `reports`) is not installed."""
    if importlib.util.find_spec("matplotlib") is None:
        ap.exit(2, f"{ap.prog}: error: its plots need matplotlib: pip install 'kinetostat[reports]'\n")
