"""The README's and the documentation pages' examples run as written: each page's Python blocks in
a fresh interpreter that ran only `import kinetostat` (the slow pages with -m slow), every page's
inline `kinetostat.` names and calls with literal arguments in one such interpreter, and every `kinetostat ...` shell command a page shows parses with the
command line's own parser, its model files exist, and every `python -m MODULE` it shows names a
module that exists. The pages: README.md and every docs/**/*.md (not the built site)."""
from __future__ import annotations

import ast
import importlib.util
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

from conftest import ROOT
from kinetostat.cli import build_parser

DOCS = ROOT / "docs"
PAGES = [ROOT / "README.md", *sorted(p for p in DOCS.rglob("*.md") if "_build" not in p.relative_to(DOCS).parts)]
FENCE = re.compile(r"^```(\w*)\n(.*?)^```", re.M | re.S)     # a block without a language too


def _name(page: Path) -> str:
    return page.relative_to(ROOT).as_posix()


def _text(page: Path) -> str:
    return page.read_text(encoding="utf-8")


def _blocks(text: str, lang: str) -> list[str]:
    return [body for kind, body in FENCE.findall(text) if kind == lang]


def _inline(text: str) -> list[str]:
    """Inline code spans outside the fenced blocks (a span may wrap a line), each once."""
    text = re.sub(r"\s*\n\s*", " ", FENCE.sub("", text))
    return list(dict.fromkeys(re.findall(r"`([^`]+)`", text)))


def _literal_call_or_name(span: str) -> bool:
    """`kinetostat.a.b` or `kinetostat.f("x", 1)`: names under kinetostat, literal arguments only."""
    if not span.startswith("kinetostat."):
        return False
    try:
        tree = ast.parse(span, mode="eval")
    except SyntaxError:
        return False
    return all(n.id == "kinetostat" for n in ast.walk(tree) if isinstance(n, ast.Name))


#: Run before the inline spans: a public name (in kinetostat.__all__, e.g. kinetostat.variants)
#: must resolve after `import kinetostat` alone; another (kinetostat.fast.peaks), a package's
#: submodule (kinetostat.plans.drawing_error) and a name of the module behind a public function
#: (kinetostat.sweep.CONNECT_TIMEOUT) are modules' paths.
RESOLVE = """
import importlib
import kinetostat

def resolve(path):
    parts = path.split(".")
    obj = kinetostat
    for n, name in enumerate(parts[1:], 1):
        if hasattr(obj, name) and (obj is not kinetostat or name in kinetostat.__all__):
            obj = getattr(obj, name)
            continue
        module = ".".join(parts[:n])
        try:
            obj = importlib.import_module(f"{module}.{name}")
        except ModuleNotFoundError:
            obj = getattr(importlib.import_module(module), name)
    return obj
"""

#: What a page's blocks leave behind is checked too: the API block's result, the sweep's shape.
AFTER = {
    "README.md": "assert res.phi_deg.shape == (360,) and mech.structure.formula == 'I(0,1) <- II(2,3)'\n",
    "docs/tutorial/python-api.md": "assert res.phi_deg.shape == (360,) and df.attrs['units']['R_1_2'] == 'N'\n",
    "docs/how-to/sweep.md": "assert sw.peak('R_0_1').shape == (5, 5)\n",
}

#: The pages whose Python blocks take seconds (the API tour's cycles with friction, a 5 x 5 sweep):
#: run with -m slow. By default the README's first example, the other pages' blocks and every
#: page's inline names run.
SLOW = {"docs/tutorial/python-api.md", "docs/how-to/sweep.md"}

WITH_PYTHON = [p for p in PAGES if _blocks(_text(p), "python")]


def _spans(page: Path) -> list[str]:
    return [s for s in _inline(_text(page)) if _literal_call_or_name(s)]


def test_the_pages_hold_the_examples():
    """The checks below see the pages: the README's first example, the API tour, the sweep, and the
    inline name kinetostat.variants.WORKED_EXAMPLE (the teacher's pack) are among them."""
    assert {_name(p) for p in WITH_PYTHON} >= set(AFTER) | SLOW
    assert "kinetostat.variants.WORKED_EXAMPLE" in _spans(DOCS / "how-to" / "teachers-pack.md")


def test_the_pages_inline_names_resolve_in_a_fresh_interpreter():
    """One process: `import kinetostat` alone, then every page's inline names and literal calls
    (e.g. kinetostat.variants.WORKED_EXAMPLE); a failure names the page and the span."""
    lines = []
    for page in PAGES:
        for span in _spans(page):
            expr = span if "(" in span else f"resolve({span!r})"
            lines += ["try:", f"    {expr}", "except Exception as e:",
                      f"    raise SystemExit({f'{_name(page)}: {span}: '!r} + repr(e))"]
    assert len(lines) >= 4 * 10
    r = subprocess.run([sys.executable, "-c", RESOLVE + "\n".join(lines)], cwd=ROOT, capture_output=True, text=True,
                       timeout=120)
    assert r.returncode == 0, r.stderr[-3000:]


@pytest.mark.parametrize("page", [pytest.param(p, id=_name(p), marks=[pytest.mark.slow] if _name(p) in SLOW else [])
                                  for p in WITH_PYTHON])
def test_the_pages_python_runs_in_a_fresh_interpreter(page):
    """One process per page: `import kinetostat` alone, then the page's Python blocks in order,
    from the checkout, and the checks of what they leave behind."""
    code = "import kinetostat\n" + "\n".join(_blocks(_text(page), "python")) + "\n" + AFTER.get(_name(page), "")
    r = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, f"{_name(page)}:\n{r.stderr[-3000:]}"


def _shell_commands(text: str) -> list[list[str]]:
    """Every command line of a page's bash blocks and inline spans that runs kinetostat or
    `python -m`: comments and output redirections (`> FILE`) dropped, `.venv/bin/` and `&&` chains split."""
    lines = [ln.split("  #")[0].split(" # ")[0] for b in _blocks(text, "bash") for ln in b.splitlines()]
    lines += [s for s in _inline(text) if s.startswith(("kinetostat ", "python -m "))]
    out = []
    for line in lines:
        for part in line.split("&&"):
            words = shlex.split(part.replace(".venv/bin/", "").split(" > ")[0])
            if words and words[0] in ("kinetostat", "python", "python3"):
                out.append(words)
    return out


def _synopsis(argv: list[str]) -> bool:
    """`kinetostat plans` or `kinetostat analyze MODEL --at DEG`: a command named, not an example."""
    return len(argv) == 1 or any(w.isupper() or "|" in w or w.startswith("[") for w in argv)


def test_the_pages_show_the_commands():
    """Over all pages: the commands of the tutorial's list, the benchmark and the slow tests are shown."""
    commands = [w for p in PAGES for w in _shell_commands(_text(p))]
    runs = [w for w in commands if w[0] == "kinetostat"]
    modules = {w[2] for w in commands if w[0].startswith("python") and w[1] == "-m"}
    assert len(runs) >= 15 and {"kinetostat_validation.benchmark", "pytest", "sphinx"} <= modules


@pytest.mark.parametrize("page", PAGES, ids=_name)
def test_the_pages_shell_commands_parse(page):
    commands = _shell_commands(_text(page))
    parser = build_parser()
    subcommands = next(a for a in parser._actions if a.choices and "analyze" in a.choices).choices
    for argv in (w[1:] for w in commands if w[0] == "kinetostat"):
        assert argv[0] in subcommands, (_name(page), argv)
        if _synopsis(argv):
            continue
        args = parser.parse_args(argv)               # CLIError (a failing test) if an option is wrong
        for word in argv:
            if word.endswith(".toml"):
                assert (ROOT / word).is_file(), (_name(page), argv, word)
        assert callable(args.func), (_name(page), argv)
    for module in {w[2] for w in commands if w[0].startswith("python") and w[1] == "-m"} - {"venv"}:
        assert importlib.util.find_spec(module) is not None, (_name(page), module)
