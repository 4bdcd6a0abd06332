"""The README's examples run as written: its Python blocks (and its inline `kinetostat.` names
and calls with literal arguments) in a fresh interpreter that ran only `import kinetostat`, and
every `kinetostat ...` shell command it shows parses with the command line's own parser, its
model files exist, and every `python -m MODULE` it shows names a module that exists."""
from __future__ import annotations

import ast
import importlib.util
import re
import shlex
import subprocess
import sys

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


def test_the_readmes_python_runs_in_a_fresh_interpreter():
    """One process: `import kinetostat` alone, then the inline names and literal calls (e.g.
    kinetostat.variants.WORKED_EXAMPLE), then each Python block in order, from the checkout."""
    spans = [s for s in _inline() if _literal_call_or_name(s)]
    assert "kinetostat.variants.WORKED_EXAMPLE" in spans and len(_blocks("python")) >= 2
    lines = [s if "(" in s else f"resolve({s!r})" for s in spans]
    code = RESOLVE + "\n".join(lines) + "\n" + "\n".join(_blocks("python"))
    # what the blocks leave behind is checked too: the API block's result and the sweep's shape
    code += "\nassert res.phi_deg.shape == (360,) and df.attrs['units']['R_1_2'] == 'N'\n" \
            "assert sw.peak('R_0_1').shape == (5, 5)\n"
    r = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr[-3000:]


def _shell_commands() -> list[list[str]]:
    """Every command line of the README's bash blocks and inline spans that runs kinetostat or
    `python -m`: comments and output redirections (`> FILE`) dropped, `.venv/bin/` and `&&` chains split."""
    lines = [ln.split("  #")[0].split(" # ")[0] for b in _blocks("bash") for ln in b.splitlines()]
    lines += [s for s in _inline() if s.startswith(("kinetostat ", "python -m "))]
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
