"""The library panel: every preset on the path, thumbnails cached and refreshed when the
preset (or its parent) changes."""

from __future__ import annotations

import numpy as np
from PIL import Image

from lookdev.library import Library
from lookdev.pipeline.designer import library_panel


def test_every_preset_is_listed_with_model_and_tags(user_library):
    (user_library / "warm_gold.toml").write_text('name = "warm_gold"\nextends = "gold"\n')
    lib = Library([user_library], use_env=False)
    entries = {e["name"]: e for e in library_panel.entries(lib)}
    assert set(entries) == set(lib.names())
    assert entries["warm_gold"]["model"] == "disney" and not entries["warm_gold"]["builtin"]
    assert entries["gold"]["builtin"] and "metal" in entries["gold"]["tags"]


def test_thumbnails_are_cached_and_follow_the_chain(user_library, tmp_path):
    child = user_library / "warm_gold.toml"
    child.write_text('name = "warm_gold"\nextends = "gold"\n[params]\nroughness = 0.1\n')
    lib = Library([user_library], use_env=False)
    cache = tmp_path / "thumbs"
    first = library_panel.thumbnail(lib, "warm_gold", cache)
    stamp = first.stat().st_mtime_ns
    assert library_panel.thumbnail(lib, "warm_gold", cache) == first
    assert first.stat().st_mtime_ns == stamp  # not rendered again
    image = np.asarray(Image.open(first))
    assert image.shape[:2] == (library_panel.THUMB_PX, library_panel.THUMB_PX)
    assert image.max() > 50  # lit, not black
    child.write_text('name = "warm_gold"\nextends = "gold"\n[params]\nroughness = 0.9\n')
    second = library_panel.thumbnail(lib, "warm_gold", cache)
    assert second != first and not first.exists()
    assert np.abs(np.asarray(Image.open(second), float) - image).mean() > 1.0
