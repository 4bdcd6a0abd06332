"""Sphinx configuration of kinetostat's documentation site.

Build (offline, warnings as errors): python -m sphinx -W --keep-going -b html docs docs/_build/html

The pages are Markdown (myst-parser), moved from the README as they were; the API reference is
autodoc of the docstrings (plain prose with units: no Google or NumPy sections, so no napoleon);
the command-line reference is generated from `kinetostat.cli.build_parser()` (sphinx-argparse);
the model format includes models/FORMAT.md, whose field tables are generated from the schema.
Nothing is fetched: no intersphinx, no remote images or fonts.
"""
from __future__ import annotations

import re
import sys
from pathlib import Path

import kinetostat

sys.path.insert(0, str(Path(__file__).parent / "_ext"))   # cli_reference: the parser for the CLI page

project = "kinetostat"
author = "kinetostat contributors"
copyright = "kinetostat contributors, MIT licence (the bundled DejaVu Sans: Bitstream Vera licence)"
release = version = kinetostat.__version__

extensions = ["myst_parser", "sphinx.ext.autodoc", "sphinxarg.ext"]
source_suffix = {".md": "markdown", ".rst": "restructuredtext"}
exclude_patterns = ["_build"]

myst_enable_extensions = ["colon_fence"]
myst_heading_anchors = 3            # "#the-interactive-page" anchors for the moved README sections

#: `name` in a docstring is code (the docstrings' convention), not rST's default italic title.
default_role = "literal"

autodoc_member_order = "bysource"
autodoc_typehints = "description"   # hints beside the prose, not in long signatures
autodoc_default_options = {"members": True, "show-inheritance": True}

html_theme = "furo"
html_title = f"kinetostat {release}"
html_static_path: list[str] = []

#: An override without a docstring of its own (the pytest plugin's `runtest`, `repr_failure`)
#: would show its base class's docstring, written for that library's site (pytest's labels).
autodoc_inherit_docstrings = False

#: `|x|` is a magnitude in the docstrings (plain text with `code` spans), never an rST
#: substitution: escaped outside the code spans before docutils reads them.
_BAR = re.compile(r"(`+[^`]*`+)|\|")


def _bars_as_text(app, what, name, obj, options, lines: list[str]) -> None:
    lines[:] = [_BAR.sub(lambda m: m.group(1) or "\\|", line) for line in lines]


def setup(app) -> None:
    app.connect("autodoc-process-docstring", _bars_as_text)

# Option names such as --out stay as typed: no "--" turned into an en dash.
smartquotes = False
