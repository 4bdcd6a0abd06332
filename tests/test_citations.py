"""What a user reads cites the texts by author and year (issue 21): no bundled model file, no
FORMAT.md, no generated variant model, worksheet, key, index or CLI line says "seed 00x" or points
to a line of the seed files (which a reader does not have). A model file's own line numbers in
error messages ("line 27: link[id=2].mass ...") are the reader's file and are allowed."""
from __future__ import annotations

import re
import warnings
from pathlib import Path

import pytest

from kinetostat import variants
from kinetostat.report.sources import WORKS

MODELS = Path(__file__).resolve().parents[1] / "models"
# "seed 002", "seeds/000_...", "line 360", "lines 120-130", "(l.131)", and the uk/ru "джерело 002",
# "источник 002"; not "line 27:" (an error message)
SEED_REF = re.compile(r"\bseeds?[ /_]?0\d\d|\blines? \d+(?![\d:])|\bl\.\s?\d+|(джерел|источник)\w* 0\d\d",
                      re.IGNORECASE)


def seed_refs(text: str) -> list[str]:
    return [text[max(m.start() - 30, 0):m.end() + 10] for m in SEED_REF.finditer(text)]


def test_the_pattern_finds_what_it_must_and_passes_error_messages():
    assert len(seed_refs("seed 002 (lines 116-150); Seed 000 line 947; (l.131); seeds/004_6.txt")) == 6
    assert len(seed_refs("(приклад джерела 002, розд. 1.2); (источник 000, разд. 6.3)")) == 2
    assert seed_refs("`line 27: link[id=2].mass: must be >= 0.0`; Logvinenko, Nadtoka 2021, sec. 1.2.3") == []


@pytest.mark.parametrize("path", sorted(MODELS.glob("*.toml")) + [MODELS / "FORMAT.md"], ids=lambda p: p.name)
def test_bundled_files_cite_by_author_and_year(path):
    text = path.read_text(encoding="utf-8")
    assert seed_refs(text) == []
    if path.suffix == ".toml" and path.stem != "scotch_yoke":      # scotch_yoke follows no one text
        assert any(w.key in text for w in WORKS), path.name


@pytest.mark.parametrize("lang", [pytest.param("en", marks=pytest.mark.slow), "uk", pytest.param("ru", marks=pytest.mark.slow)])
def test_a_variant_model_its_key_and_its_cli_lines_cite_by_author_and_year(lang, tmp_path):
    v = variants.variant(2, "479")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        k = variants.write_key(v, tmp_path, lang=lang, cycle_csv=False, teacher_pack=False)
    files = [p for p in tmp_path.rglob("*") if p.suffix in {".toml", ".md", ".html", ".csv", ".json", ".svg"}]
    assert {p.suffix for p in files} >= {".toml", ".md", ".html", ".svg"}
    for p in files:
        assert seed_refs(p.read_text(encoding="utf-8")) == [], p.name
    printed = "\n".join(variants.summary(v, k, tmp_path, lang) + [variants.index_markdown([k], lang)])
    assert seed_refs(printed) == []
    assert "Logvinenko, Nadtoka 2021" in v.toml() and "2021" in printed
