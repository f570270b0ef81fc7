"""The view transform's baked LUT (materials/colour_lut.py) against OCIO's exact processor.

Compared in 8-bit code values, which is how what the bake shows is stored (PNG frames,
contact sheets, the review page's thumbnails).
"""

from __future__ import annotations

import numpy as np
import PyOpenColorIO as ocio
import pytest

from lookdev.materials import colour, colour_lut

LEVELS = [0.0, 1e-6, 2.0**-12, 0.01, 0.18, 1.0, 16.0, 1e3, 1e4, 1e30]
HUES = [
    (1, 1, 1), (1, 0, 0), (0, 1, 0), (0, 0, 1), (1, 1, 0), (0, 1, 1), (1, 0, 1),
    (1, 0.5, 0), (1, 0.1, 0.05), (0.05, 0.1, 1),
]  # fmt: skip


def codes(pixels, exposure=0.0, exact=False):
    return np.rint(colour.to_display(pixels, exposure, exact=exact) * 255.0)


def difference(pixels, exposure=0.0):
    return np.abs(codes(pixels, exposure) - codes(pixels, exposure, exact=True))


def frame(seed=5):
    """A frame-like image: log-normal brightness, tinted towards a colour per pixel."""
    rng = np.random.default_rng(seed)
    tint = rng.uniform(0.2, 1.0, (120, 240, 3))
    return (rng.lognormal(-1.5, 1.5, (120, 240, 1)) * tint).astype(np.float32)


@pytest.mark.parametrize("view", ["ACES 2.0 - SDR 100 nits (Rec.709)", "Un-tone-mapped"])
def test_black_grey_white_and_saturated_hues_are_within_one_code_value(view):
    edges = np.array([[level * h for h in hue] for level in LEVELS for hue in HUES], np.float32)
    with colour.use(view=view):
        assert difference(edges).max() <= 1.0
        assert codes(np.zeros((1, 3)))[0].tolist() == [0.0, 0.0, 0.0]
        assert codes(np.full((1, 3), 1e30))[0].tolist() == [255.0, 255.0, 255.0]


def test_saturated_hues_stay_within_the_measured_bound():
    # the bake's worst place: pure blue near 1.85, at the display gamut's edge (7 codes)
    levels = np.geomspace(1e-6, 1e4, 400)
    hues = np.array([[k * h for h in hue] for k in levels for hue in HUES[1:]], np.float32)
    d = difference(hues).max(axis=-1)
    assert d.max() <= 8.0
    assert np.mean(d > 1.0) <= 0.01


@pytest.mark.parametrize("exposure", [0.0, 2.5, -3.0])
def test_a_frame_is_within_one_code_value_almost_everywhere(exposure):
    d = difference(frame(), exposure)
    assert d.mean() < 0.15
    assert np.mean(d.max(axis=-1) <= 1.0) >= 0.999
    assert d.max() <= 3.0


def test_the_exact_path_is_the_ocio_processor_itself():
    pixels = frame(7)
    expected = pixels.copy()
    key = (colour.settings().config_name, colour.working_space(), colour.display())
    colour._display_cpu(*key, colour.view(), colour.look()).applyRGB(expected.reshape(-1))
    assert np.array_equal(colour.to_display(pixels, exact=True), np.clip(expected, 0.0, 1.0))


def test_the_bake_is_made_once_per_view():
    def bake():
        key = (colour.settings().config_name, colour.working_space(), colour.display())
        return colour._display_lut(*key, colour.view(), colour.look())

    first = bake()
    assert first is not None and bake() is first
    with colour.use(view="Un-tone-mapped"):
        assert bake() is not first


def test_a_view_still_rising_above_the_cube_is_not_baked():
    assert colour_lut.saturates(lambda x: np.clip(x, 0.0, 1.0))
    rising = 2.0 ** (colour_lut.HI + 4)
    assert not colour_lut.saturates(lambda x: x / (x + np.float32(rising)))


def test_the_input_is_not_changed():
    pixels = frame(9)
    pixels[0, 0] = (np.nan, -1.0, np.inf)
    before = pixels.copy()
    shown = colour.to_display(pixels)
    assert np.array_equal(pixels, before, equal_nan=True)
    assert shown[0, 0].tolist() == [0.0, 0.0, 0.0]


def _range_then_half():
    """Clamp to [0, 1], then halve: a clamp that the op after it does not commute with."""
    matrix = ocio.MatrixTransform(matrix=[0.5, 0, 0, 0, 0, 0.5, 0, 0, 0, 0, 0.5, 0, 0, 0, 0, 1])
    clamp = ocio.RangeTransform(minInValue=0.0, maxInValue=1.0, minOutValue=0.0, maxOutValue=1.0)
    return ocio.Config.CreateRaw().getProcessor(ocio.GroupTransform([clamp, matrix]))


def test_a_clamp_that_does_not_commute_with_what_follows_is_baked_clamped():
    processor = _range_then_half()
    exact = processor.getDefaultCPUProcessor()
    baked = colour_lut.baked(processor, exact, colour._apply_in_parallel)
    pixels = np.array([[0.25, 0.5, 2.0], [4.0, 8.0, 1e4]], np.float32)
    expected = pixels.copy()
    exact.applyRGB(expected.reshape(-1))
    baked.applyRGB(pixels.reshape(-1))
    np.testing.assert_allclose(pixels, expected, atol=1 / 255)  # 2.0 → 0.5, not 1.0


def test_unclamped_drops_only_the_clamps_to_the_unit_range():
    wide = ocio.RangeTransform(minInValue=0.0, maxInValue=4.0, minOutValue=0.0, maxOutValue=4.0)
    cpu = colour_lut.unclamped(
        ocio.Config.CreateRaw().getProcessor(
            ocio.GroupTransform([_range_then_half().createGroupTransform(), wide])
        )
    )
    pixels = np.array([[2.0, 8.0, 16.0]], np.float32)
    cpu.applyRGB(pixels.reshape(-1))
    assert pixels.tolist() == [[1.0, 4.0, 4.0]]
