"""The README's examples run as written, from an empty folder: its Python blocks (and its inline
`kinetostat.` names and calls with literal arguments) in a fresh interpreter that ran only
`import kinetostat`; the commands of its bash blocks run (a quick sample by default, the rest
with -m slow; tests/test_package.py runs them with the wheel installed); and every `kinetostat
...` shell command it shows parses with the command line's own parser, its model files exist,
and every `python -m MODULE` it shows names a module that exists."""
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

README = (ROOT / "README.md").read_text(encoding="utf-8")
FENCE = re.compile(r"^```(\w+)\n(.*?)^```", re.M | re.S)


def _blocks(lang: str) -> list[str]:
    return [body for kind, body in FENCE.findall(README) if kind == lang]


def _inline() -> list[str]:
    """Inline code spans outside the fenced blocks (a span may wrap a line), each once."""
    text = re.sub(r"\s*\n\s*", " ", FENCE.sub("", README))
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
#: must resolve after `import kinetostat` alone; another (kinetostat.fast.peaks) and a package's
#: submodule (kinetostat.plans.drawing_error) are modules' paths.
RESOLVE = """
import importlib
import kinetostat

def resolve(path):
    parts = path.split(".")
    head = parts[1]
    obj = getattr(kinetostat, head) if head in kinetostat.__all__ else importlib.import_module(f"kinetostat.{head}")
    for name in parts[2:]:             # a package's submodule (kinetostat.plans.drawing_error) by its path
        obj = getattr(obj, name) if hasattr(obj, name) else importlib.import_module(f"{obj.__name__}.{name}")
    return obj
"""


def readme_python() -> str:
    """The program of the README's Python: `resolve` the inline names, the literal calls, then each
    Python block in order, then checks of what the blocks leave behind."""
    spans = [s for s in _inline() if _literal_call_or_name(s)]
    assert "kinetostat.variants.WORKED_EXAMPLE" in spans and len(_blocks("python")) >= 2
    lines = [s if "(" in s else f"resolve({s!r})" for s in spans]
    code = RESOLVE + "\n".join(lines) + "\n" + "\n".join(_blocks("python"))
    # what the blocks leave behind is checked too: the API block's result and the sweep's shape
    return code + "\nassert res.phi_deg.shape == (360,) and df.attrs['units']['R_1_2'] == 'N'\n" \
                  "assert sw.peak('R_0_1').shape == (5, 5)\n"


def test_the_readmes_python_runs_in_a_fresh_interpreter_from_an_empty_folder(tmp_path):
    """One process: `import kinetostat` alone, then the inline names and literal calls (e.g.
    kinetostat.variants.WORKED_EXAMPLE), then each Python block in order, in an empty folder."""
    r = subprocess.run([sys.executable, "-c", readme_python()], cwd=tmp_path, env=user_env(), capture_output=True,
                       text=True, timeout=120)
    assert r.returncode == 0, r.stderr[-3000:]


def _shell_commands(inline: bool = True) -> list[list[str]]:
    """Every command line of the README's bash blocks (and inline spans) that runs kinetostat or
    `python -m`: comments and output redirections (`> FILE`) dropped, `.venv/bin/` and `&&` chains split."""
    lines = [ln.split("  #")[0].split(" # ")[0] for b in _blocks("bash") for ln in b.splitlines()]
    lines += [s for s in _inline() if s.startswith(("kinetostat ", "python -m "))] if inline else []
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


def test_the_readmes_shell_commands_parse():
    commands = _shell_commands()
    runs = [w[1:] for w in commands if w[0] == "kinetostat"]
    modules = {w[2] for w in commands if w[0].startswith("python") and w[1] == "-m"}
    assert len(runs) >= 15 and {"kinetostat_validation.benchmark", "pytest"} <= modules
    parser = build_parser()
    subcommands = next(a for a in parser._actions if a.choices and "analyze" in a.choices).choices
    for argv in runs:
        assert argv[0] in subcommands, argv
        if _synopsis(argv):
            continue
        args = parser.parse_args(argv)               # CLIError (a failing test) if an option is wrong
        for word in argv:
            if word.endswith(".toml"):
                assert (ROOT / word).is_file(), (argv, word)
        assert callable(args.func), argv
    for module in modules - {"venv"}:
        assert importlib.util.find_spec(module) is not None, module



#: Commands of the bash blocks that make or test the checkout (a venv, an editable install, its
#: test suite), not examples of use: not run from an empty folder.
CHECKOUT = {"python3 -m venv .venv", "python -m pip install -e '.[all]'", "python -m pytest -q", "python -m pytest -m slow"}
#: Examples not run even with -m slow: (command, why).
NOT_RUN = {"kinetostat variant 2 --all --out keys": "every code of task 2, about 1000 keys: hours"}
#: Examples run by default (a second each); every other one is slow.
QUICK = {"kinetostat analyze ice_crank_slider --at 30", "kinetostat structure slotted_link_shaper",
         "kinetostat examples --copy my_models"}


def readme_examples() -> list[str]:
    """The README's bash-block commands a user runs (kinetostat, python -m), each once, less CHECKOUT and NOT_RUN."""
    lines = dict.fromkeys(shlex.join(w) for w in _shell_commands(inline=False))
    return [c for c in lines if c not in CHECKOUT and c not in NOT_RUN]


def test_the_commands_left_out_or_run_by_default_are_the_readmes():
    assert CHECKOUT | set(NOT_RUN) <= {shlex.join(w) for w in _shell_commands(inline=False)}
    assert QUICK <= set(readme_examples()) and len(readme_examples()) >= 18


def user_env() -> dict:
    """This environment less what could point a command at the checkout's models or code."""
    return {k: v for k, v in os.environ.items() if k not in ("KINETOSTAT_MODELS", "PYTHONPATH")}


def run_example(command: str, cwd: Path, bindir: Path = Path(sys.executable).parent) -> subprocess.CompletedProcess:
    """A README command run as its reader would, in `cwd`, by the programs of `bindir` (this
    interpreter's, or a fresh venv's): `kinetostat` its entry point, `python` its interpreter."""
    argv = shlex.split(command)
    program = bindir / "kinetostat" if argv[0] == "kinetostat" else bindir / "python"
    return subprocess.run([str(program), *argv[1:]], cwd=cwd, env=user_env(), capture_output=True, text=True,
                          timeout=3600, stdin=subprocess.DEVNULL)


#: The slow examples' own time limit: the suite's 300 s (pyproject's pytest timeout) is shorter
#: than a report of every model with its pages, or the stability study, on 2 cores.
SLOW = [pytest.mark.slow, pytest.mark.timeout(3600)]


@pytest.mark.parametrize("command", [c if c in QUICK else pytest.param(c, marks=SLOW) for c in readme_examples()])
def test_a_readme_command_runs_from_an_empty_folder(command, tmp_path):
    r = run_example(command, tmp_path)
    assert r.returncode == 0 and "Traceback" not in r.stderr, (r.stdout[-2000:], r.stderr[-2000:])
