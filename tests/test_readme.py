"""The README's and the documentation pages' examples run as written, from an empty folder: each
page's Python blocks in a fresh interpreter that ran only `import kinetostat` (the slow pages with
-m slow); the commands of their bash blocks (a quick sample by default, the rest with -m slow;
tests/test_package.py runs them with the wheel installed); every page's
inline `kinetostat.` names and calls with literal arguments in one such interpreter, and every `kinetostat ...` shell command a page shows parses with the
command line's own parser, its model files exist, and every `python -m MODULE` it shows names a
module that exists. The pages: README.md and every docs/**/*.md (not the built site)."""
from __future__ import annotations

import ast
import importlib.util
import os
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


def page_python(page: Path) -> str:
    """The program of a page's Python: `import kinetostat`, its blocks in order, the checks of what
    they leave behind."""
    return "import kinetostat\n" + "\n".join(_blocks(_text(page), "python")) + "\n" + AFTER.get(_name(page), "")


def readme_python() -> list[str]:
    """The programs of every page's Python (`page_python`), one per page that has any."""
    return [page_python(p) for p in WITH_PYTHON]


def user_env() -> dict:
    """This environment less what could point a command at the checkout's models or code."""
    return {k: v for k, v in os.environ.items() if k not in ("KINETOSTAT_MODELS", "PYTHONPATH")}


@pytest.mark.parametrize("page", [pytest.param(p, id=_name(p), marks=[pytest.mark.slow] if _name(p) in SLOW else [])
                                  for p in WITH_PYTHON])
def test_the_pages_python_runs_in_a_fresh_interpreter_from_an_empty_folder(page, tmp_path):
    """One process per page: `import kinetostat` alone, then the page's Python blocks in order,
    in an empty folder, and the checks of what they leave behind."""
    r = subprocess.run([sys.executable, "-c", page_python(page)], cwd=tmp_path, env=user_env(), capture_output=True,
                       text=True, timeout=120)
    assert r.returncode == 0, f"{_name(page)}:\n{r.stderr[-3000:]}"


def _shell_commands(text: str, inline: bool = True) -> list[list[str]]:
    """Every command line of a page's bash blocks (and inline spans) that runs kinetostat or
    `python -m`: comments and output redirections (`> FILE`) dropped, `.venv/bin/` and `&&` chains split."""
    lines = [ln.split("  #")[0].split(" # ")[0] for b in _blocks(text, "bash") for ln in b.splitlines()]
    lines += [s for s in _inline(text) if s.startswith(("kinetostat ", "python -m "))] if inline else []
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


#: Commands of the bash blocks that make or test the checkout (a venv, an editable install, its
#: test suite, the docs' build, a rerun checked against its committed reports/), not examples of
#: use: not run from an empty folder.
CHECKOUT = {"python3 -m venv .venv", "python -m pip install -e '.[all]'", "python -m pytest -q",
            "python -m pytest -m slow", "python -m sphinx -W -b html docs docs/_build/html",
            "kinetostat report --out rerun --check reports"}
#: Examples not run even with -m slow: (command, why).
NOT_RUN = {"kinetostat variant 2 --all --out keys": "every code of task 2, about 1000 keys: hours"}
#: The example run by default (a process of its own, about a second); every other one is slow (the
#: commands themselves run in-process in their own tests: test_cli, test_package).
QUICK = {"kinetostat analyze ice_crank_slider --at 30"}
#: The slow examples' own time limit: the suite's 300 s (pyproject's pytest timeout) is shorter
#: than a report of every model with its pages, or the stability study, on 2 cores.
SLOW_RUN = [pytest.mark.slow, pytest.mark.timeout(3600)]


def readme_examples() -> list[str]:
    """The commands of every page's bash blocks a user runs (kinetostat, python -m), each once, less
    CHECKOUT and NOT_RUN."""
    lines = dict.fromkeys(shlex.join(w) for p in PAGES for w in _shell_commands(_text(p), inline=False))
    return [c for c in lines if c not in CHECKOUT and c not in NOT_RUN]


def test_the_commands_left_out_or_run_by_default_are_the_pages():
    shown = {shlex.join(w) for p in PAGES for w in _shell_commands(_text(p), inline=False)}
    assert CHECKOUT | set(NOT_RUN) <= shown
    assert QUICK <= set(readme_examples()) and len(readme_examples()) >= 18


def run_example(command: str, cwd: Path, bindir: Path = Path(sys.executable).parent) -> subprocess.CompletedProcess:
    """A page's command run as its reader would, in `cwd`, by the programs of `bindir` (this
    interpreter's, or a fresh venv's): `kinetostat` its entry point, `python` its interpreter."""
    argv = shlex.split(command)
    program = bindir / "kinetostat" if argv[0] == "kinetostat" else bindir / "python"
    return subprocess.run([str(program), *argv[1:]], cwd=cwd, env=user_env(), capture_output=True, text=True,
                          timeout=3600, stdin=subprocess.DEVNULL)


@pytest.mark.parametrize("command", [c if c in QUICK else pytest.param(c, marks=SLOW_RUN) for c in readme_examples()])
def test_a_pages_command_runs_from_an_empty_folder(command, tmp_path):
    r = run_example(command, tmp_path)
    assert r.returncode == 0 and "Traceback" not in r.stderr, (r.stdout[-2000:], r.stderr[-2000:])
