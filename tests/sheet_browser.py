"""Sheets in a real browser: Debian's headless Chromium driven by Playwright measures every text's
arrowhead's and point's box (getBBox, in the SVG's millimetres) and reports the overlaps a reader would
see. Used by tests/test_sheet_layout.py; as a script (`python tests/sheet_browser.py OUT file.svg
...`) it writes PNG screenshots of sheets.

May use: playwright, pytest (in `chromium`), the standard library.
"""
from __future__ import annotations

import shutil
import sys
from contextlib import contextmanager
from pathlib import Path

ARGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
        "--disable-component-update", "--no-first-run"]

#: Boxes of every text, arrowhead and point (a dot of the plan), in SVG user units (mm: the sheets
#: use no transforms), with their text.
_MEASURE = """() => {
  const out = [];
  for (const el of document.querySelectorAll('text, path.arrowhead, #plan circle')) {
    const b = el.getBBox(), tag = {text: 'text', circle: 'point'}[el.tagName] || 'arrow';
    out.push({tag, text: el.textContent, box: [b.x, b.y, b.x + b.width, b.y + b.height]});
  }
  return out;
}"""


def launch(playwright):
    """Debian's chromium, headless (None where it is not installed)."""
    exe = shutil.which("chromium") or shutil.which("chromium-browser")
    if exe is None:
        return None
    return playwright.chromium.launch(executable_path=exe, args=ARGS)


@contextmanager
def chromium():
    """A headless Chromium for a test fixture: Playwright's, on Debian's chromium with a fresh
    profile; the test skipped, with the reason, where either is missing or does not start."""
    import pytest
    sync = pytest.importorskip("playwright.sync_api", reason="Playwright is not installed (pip install playwright)")
    with sync.sync_playwright() as p:
        try:
            browser = launch(p)
        except Exception as exc:                    # noqa: BLE001 - any launch failure: no browser here
            pytest.skip(f"Chromium does not start: {exc}")
        if browser is None:
            pytest.skip("no chromium on PATH (apt-get install chromium)")
        yield browser
        browser.close()


def measure(page, svg_text: str) -> list[dict]:
    """Boxes (x0, y0, x1, y1, mm) of every text, arrowhead and point of an SVG sheet, set at its
    own size (A3, 1 mm = 3.78 px): the drawing's, not a screen's zoom (a sheet shrunk to a column
    sets its 3.5 mm letters at 4 px, where the browser's hinting widens them)."""
    page.set_content(svg_text.split("?>", 1)[-1])
    return page.evaluate(_MEASURE)


def overlap(a, b, tol: float) -> bool:
    return a[0] < b[2] - tol and b[0] < a[2] - tol and a[1] < b[3] - tol and b[1] < a[3] - tol


def overlaps(items: list[dict], tol: float = 0.05) -> list[str]:
    """Pairs of texts that overlap, and texts over an arrowhead or a point (by more than `tol` mm)."""
    texts = [i for i in items if i["tag"] == "text" and i["text"].strip()]
    marks = [i for i in items if i["tag"] in ("arrow", "point")]
    bad = []
    for n, a in enumerate(texts):
        for b in texts[n + 1:]:
            if overlap(a["box"], b["box"], tol):
                bad.append(f"text {a['text']!r} over text {b['text']!r}")
        for b in marks:
            if overlap(a["box"], b["box"], tol):
                what = "an arrowhead" if b["tag"] == "arrow" else "a point"
                bad.append(f"text {a['text']!r} over {what} at {[round(v, 1) for v in b['box']]}")
    return bad


def screenshots(out: Path, files: list[Path]) -> None:
    from playwright.sync_api import sync_playwright
    out.mkdir(parents=True, exist_ok=True)
    with sync_playwright() as p:
        browser = launch(p)
        page = browser.new_page(viewport={"width": 1590, "height": 1125}, device_scale_factor=1.5)
        for f in files:
            page.goto(f.resolve().as_uri())
            page.screenshot(path=str(out / f"{f.parent.name}__{f.stem}.png"), timeout=20000)
        browser.close()


if __name__ == "__main__":
    screenshots(Path(sys.argv[1]), [Path(f) for f in sys.argv[2:]])
