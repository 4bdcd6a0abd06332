"""The command line's parser for the CLI reference page (sphinx-argparse reads it).

sphinx-argparse renders every help text as reStructuredText; the help texts are plain text
(`|R(i,j)|` a magnitude, `*.toml` a pattern), so their `|` and `*` are escaped here, on a parser
built for the page, and the terminal's `--help` stays as it is.

May use: kinetostat.cli.
"""
from __future__ import annotations

import argparse

from kinetostat.cli import build_parser


def _as_text(s: str | None) -> str | None:
    return None if s is None else s.replace("\\", "\\\\").replace("|", "\\|").replace("*", "\\*")


def _escape(parser: argparse.ArgumentParser) -> None:
    parser.description, parser.epilog = _as_text(parser.description), _as_text(parser.epilog)
    for action in parser._actions:
        if action.help not in (None, argparse.SUPPRESS):
            action.help = _as_text(action.help)
        if isinstance(action, argparse._SubParsersAction):
            for sub in dict.fromkeys(action.choices.values()):
                _escape(sub)
            for choice in action._choices_actions:
                choice.help = _as_text(choice.help)


def parser() -> argparse.ArgumentParser:
    """`kinetostat.cli.build_parser()` with its help texts escaped for reStructuredText."""
    p = build_parser()
    _escape(p)
    return p
