"""``lookdev bench glass`` (pipeline/bench/glass.py), at tiny settings."""

from __future__ import annotations

import json

import numpy as np
import pytest

from lookdev.materials.params import DisneyParams
from lookdev.pipeline.bench import glass

pytestmark = pytest.mark.render


def test_the_nearest_builtin_of_each_kind_of_glass():
    smooth = DisneyParams(base_color=(0.5, 0.8, 0.5), spec_trans=1.0, roughness=0.0, ior=1.52)
    d = glass.builtin_dict(smooth)
    assert d["type"] == "dielectric" and d["int_ior"] == 1.52 and d["ext_ior"] == 1.0
    assert d["specular_transmittance"]["value"] == [0.5, 0.8, 0.5]
    rough = glass.builtin_dict(smooth.replace(roughness=0.3))
    assert rough["type"] == "roughdielectric" and rough["alpha"] == pytest.approx(0.09)
    thin = glass.builtin_dict(smooth.replace(thin=True, base_color=(0.25, 0.25, 0.25)))
    assert thin["type"] == "thindielectric" and thin["specular_transmittance"]["value"][0] == 0.5
    with pytest.raises(glass.BenchGlassError):
        glass.builtin_dict(DisneyParams(spec_trans=0.5))


@pytest.mark.slow
def test_smooth_glass_costs_what_dielectric_costs(cli):
    result = cli(
        "bench", "glass", "glass_clear", "--spp", "2", "--reference-spp", "16",
        "--resolution", "24", "12", "--repeat", "3", "--json",
    )  # fmt: skip
    assert result.code == 0, result.err
    row = json.loads(result.out)["presets"][0]
    assert row["builtin"] == "dielectric" and row["depth"] == 16
    # Same choices with the same random numbers: the same image, the same noise.
    assert row["noise_ratio"] == pytest.approx(1.0, rel=1e-3)
    assert row["noise_ratio_interval"] == pytest.approx([1.0, 1.0], rel=1e-3)
    assert abs(row["reference_difference"]) < 1e-3
    assert row["ours_seconds"] > 0 and row["builtin_seconds"] > 0
    assert row["ours_wall_seconds"] > 0 and len(row["time_ratio_quartiles"]) == 2


def test_reference_must_outnumber_the_frames(cli):
    result = cli("bench", "glass", "water", "--spp", "16", "--reference-spp", "32")
    assert result.code == 2 and "--reference-spp" in result.err


def test_noise_is_the_variance_over_frames_not_the_error_against_one_reference():
    rng = np.random.default_rng(0)
    truth = np.full((4, 4, 3), 2.0)
    frames = truth + rng.normal(0.0, 0.5, (4000, 4, 4, 3))
    den = truth**2 + glass.RELMSE_EPS
    # E[relMSE] of one frame = σ² / (ref² + ε), with no reference in the numerator.
    assert glass.noise(frames, den) == pytest.approx(0.25 / den.mean(), rel=0.03)
    # A shifted reference would add its error; the variance does not see it.
    assert glass.noise(frames + 1.0, den) == pytest.approx(glass.noise(frames, den))
