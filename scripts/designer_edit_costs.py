"""What one layer edit costs the designer's session in blending (CPU ms, medians).

For each case, interleaved: a fresh ``lookdev.blend`` of the edited material (what a
designer without a session would do), the session's blend with its shared texture cache,
and an undo (the blend cached by content). Run: ``python scripts/designer_edit_costs.py``.
"""

from __future__ import annotations

import os
import statistics
import tempfile
import time
from pathlib import Path

import numpy as np
from PIL import Image

import lookdev
from lookdev.library import Library
from lookdev.pipeline.designer.session import BLEND_RESOLUTION, Session

TEXTURED = """name = "tex_layers"
model = "layered"
[[layers]]
preset = "plastic_glossy"
[[layers]]
preset = "rust"
[layers.mask]
kind = "texture"
path = "mask.png"
"""


def _cpu(fn) -> float:
    start = time.process_time()
    fn()
    return time.process_time() - start


def measure(session: Session, rounds: int = 8) -> tuple[float, float, float]:
    session.hub()
    fresh, shared, undo = [], [], []
    for i in range(rounds):
        session.edit({"op": "set", "target": 1, "field": "roughness", "value": 0.3 + 0.05 * i})
        m = session.material()
        pair = [
            (fresh, lambda m=m: lookdev.blend(m, BLEND_RESOLUTION)),
            (shared, lambda m=m: session.hub(m)),
        ]
        for out, fn in pair if i % 2 else pair[::-1]:
            out.append(_cpu(fn))
        session.undo()
        undo.append(_cpu(session.hub))
        session.redo()
    return tuple(statistics.median(x) * 1000 for x in (fresh, shared, undo))


def main() -> None:
    folder = Path(tempfile.mkdtemp(prefix="designer-costs-"))
    noise = np.random.default_rng(1).random((2048, 2048))
    Image.fromarray((noise * 255).astype(np.uint8)).save(folder / "mask.png")
    (folder / "tex_layers.toml").write_text(TEXTURED)
    library = Library([folder], use_env=False)
    for name in ("dust_over_plastic", "rusty_iron", "tex_layers"):
        fresh, shared, undo = measure(Session(library, name))
        print(
            f"{name:18s} blend {BLEND_RESOLUTION}²: fresh {fresh:6.1f} ms, session "
            f"{shared:6.1f} ms, undo {undo:5.2f} ms (CPU)"
        )
    print("load average:", " ".join(f"{x:.2f}" for x in os.getloadavg()))


if __name__ == "__main__":
    main()
