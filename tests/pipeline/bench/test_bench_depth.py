"""``lookdev bench depth`` (pipeline/bench/depth.py), at tiny settings."""

from __future__ import annotations

import json

import numpy as np
import pytest

from lookdev.pipeline.bench import depth as bench_depth

pytestmark = pytest.mark.render


def test_loss_is_zero_for_equal_images_and_counts_darker_pixels():
    ref = np.ones((4, 25, 3), np.float32)
    assert bench_depth.loss(ref, ref) == {"mean_loss": 0.0, "p99_pixel_loss": 0.0}
    darker = ref * 0.9
    result = bench_depth.loss(darker, ref)
    assert result["mean_loss"] == pytest.approx(0.1, rel=1e-5)
    assert result["p99_pixel_loss"] == pytest.approx(0.1, rel=1e-5)


def test_measure_renders_both_depths_with_shared_seeds():
    s = bench_depth.Settings(
        presets=("gold",), spp=4, resolution=(24, 12), reference_depth=12, repeat=1, ibl_width=32
    )
    row = bench_depth.measure("gold", s)
    assert row["depth"] == 6 and row["reference_depth"] == 12
    assert row["seconds"] > 0 and row["reference_seconds"] > 0
    # A metal loses light in the cup when its paths are cut, never gains any.
    assert -1e-3 <= row["mean_loss"] < 0.05
    assert row["p99_pixel_loss"] >= row["mean_loss"] - 1e-3


def test_cli_json_and_bad_reference_depth(cli):
    result = cli(
        "bench",
        "depth",
        "plastic_matte",
        "--spp",
        "2",
        "--resolution",
        "16",
        "8",
        "--repeat",
        "1",
        "--reference-depth",
        "8",
        "--json",
    )
    assert result.code == 0, result.err
    data = json.loads(result.out)
    assert [r["preset"] for r in data["presets"]] == ["plastic_matte"]
    assert data["presets"][0]["depth"] == 4
    bad = cli("bench", "depth", "glass_clear", "--reference-depth", "8", "--json")
    assert bad.code == 2 and "must exceed the depth 16" in bad.err
