"""``lookdev bench dcc`` in small: Blender Cycles renders two exported presets beside the
proofs, and each loss note agrees with what Cycles shows.

One preset the note says the universal context expresses fully (a white, near-mirror
metal: UsdPreviewSurface's metal is the material's within the measurement), one with a
named loss (velvet: its sheen is lost, the note says by how much).
"""

from __future__ import annotations

import pytest

pytest.importorskip("pxr")

from lookdev.pipeline.bench import blender, dcc  # noqa: E402

pytestmark = [
    pytest.mark.dcc,
    pytest.mark.slow,
    pytest.mark.skipif(blender.interpreter() is None, reason="no Blender (bpy) installed"),
]

MIRROR = """\
name = "white_mirror"
model = "disney"
description = "A white near-mirror metal: what UsdPreviewSurface expresses fully."

[params]
base_color = [0.95, 0.95, 0.95]
metallic = 1.0
roughness = 0.05
"""


@pytest.fixture(
    scope="module",
    params=[pytest.param(p, id=p.parent.parent.name) for p in blender.interpreters()],
)
def bench(request, tmp_path_factory):
    lib = tmp_path_factory.mktemp("lib")
    (lib / "white_mirror.toml").write_text(MIRROR)
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("LOOKDEV_LIBRARY_PATH", str(lib))
        out = dcc.run(
            tmp_path_factory.mktemp("bench"),
            ("white_mirror", "velvet"),
            resolution=(80, 40),
            spp=16,
            python=request.param,
        )
    return {r["preset"]: r for r in out["rows"]}


def test_a_fully_expressed_preset_says_so_and_cycles_matches_it_within_noise(bench):
    row = bench["white_mirror"]
    assert row["fully"] and row["loss"].startswith("UsdPreviewSurface expresses this material")
    assert row["agree"], row


def test_a_named_loss_says_by_how_much_and_cycles_shows_that_much(bench):
    row = bench["velvet"]
    assert not row["fully"]
    assert "sheen" in row["loss"] and "measured against the material: albedo −" in row["loss"]
    assert row["stated"] < -0.5  # the note: most of velvet's light is its lost sheen
    assert row["mean_diff"]["cycles-proof"] < -0.3  # and Cycles shows it darker
    assert row["agree"], row
