"""Screenshots of the Material Designer in headless Chromium (Debian's, via playwright).

Usage: ``python scripts/designer_screenshots.py OUT_DIR [PRESET]`` writes ``page.png``
(the whole page) and crops of the viewport, the parameters, the layer stack (its top
layer's mask editor unfolded) and the library into OUT_DIR;
``docs/gallery/designer.png`` is ``page.png`` of ``rusty_iron`` and
``docs/gallery/designer_layers.png`` its ``layers.png``.
"""

from __future__ import annotations

import sys
import tempfile
import time
from pathlib import Path

from playwright.sync_api import sync_playwright

from lookdev.library import Library
from lookdev.pipeline.designer.server import Designer

FLAGS = ["--no-sandbox", "--disable-gpu", "--disable-background-networking"]
FLAGS += ["--disable-component-update", "--disable-quic", "--disable-sync", "--no-first-run"]
PARTS = {"viewport": "#centre", "controls": "#controls", "layers": "#layers-panel"}
PARTS |= {"library": "#library"}
SPP = 64


def main(out: Path, preset: str = "rusty_iron") -> None:
    out.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as scratch:
        d = Designer([preset], library=Library([scratch], use_env=False), size=(480, 270))
        stop = d.serve_in_background()
        try:
            with sync_playwright() as p:
                browser = p.chromium.launch(executable_path="/usr/bin/chromium", args=FLAGS)
                page = browser.new_page(viewport={"width": 1500, "height": 980})
                page.goto(d.url)
                page.wait_for_function(
                    "Number(document.getElementById('viewport').dataset.frames || 0) > 0",
                    timeout=300_000,
                )
                page.wait_for_function(  # converged, or enough samples to look at
                    "(n) => { const t = document.getElementById('frame-info').textContent;"
                    " const m = t.match(/(\\d+) spp/);"
                    " return t.includes('converged') || (m && Number(m[1]) >= n); }",
                    arg=SPP,
                    timeout=600_000,
                )
                # the top layer's mask editor unfolded, as an artist edits it
                page.click("#layers li:first-child details.mask summary")
                time.sleep(20)  # the plot, the thumbnails and the mask preview
                page.screenshot(path=str(out / "page.png"))
                for name, selector in PARTS.items():
                    if page.locator(selector).is_visible():
                        page.locator(selector).screenshot(path=str(out / f"{name}.png"))
                browser.close()
        finally:
            stop()


if __name__ == "__main__":
    main(Path(sys.argv[1]), *sys.argv[2:3])
