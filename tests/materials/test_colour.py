"""The one home of the colour constants and the sRGB curve (materials/colour.py), at its edges."""

from __future__ import annotations

import numpy as np
import pytest

from lookdev.materials.colour import (
    REC709_LUMINANCE,
    SRGB_DECODE_BREAK,
    SRGB_ENCODE_BREAK,
    luminance,
    srgb_decode,
    srgb_encode,
)
from lookdev.materials.disney_prepare import TINT_WEIGHTS


def test_luminance_of_black_is_zero_and_of_white_is_one():
    assert luminance((0.0, 0.0, 0.0)) == 0.0
    assert luminance(np.zeros((4, 5, 3), np.float32)).tolist() == np.zeros((4, 5)).tolist()
    assert luminance((1.0, 1.0, 1.0)) == pytest.approx(1.0, abs=1e-15)
    assert sum(REC709_LUMINANCE) == pytest.approx(1.0, abs=1e-15)


def test_luminance_is_per_pixel_and_a_float_for_a_triple():
    rgb = np.random.default_rng(1).random((6, 3))
    np.testing.assert_allclose(luminance(rgb), rgb @ np.array(REC709_LUMINANCE), rtol=0)
    assert isinstance(luminance([0.2, 0.3, 0.4]), float)


def test_burleys_tint_weights_are_not_rec709_luminance():
    assert TINT_WEIGHTS == (0.3, 0.6, 0.1) and TINT_WEIGHTS != REC709_LUMINANCE


@pytest.mark.parametrize("v", [0.0, 1.0])
def test_srgb_ends_are_fixed_points(v):
    assert srgb_decode(v) == v
    assert srgb_encode(v) == pytest.approx(v, abs=2e-16)  # 1.055 − 0.055 rounds to 1 − ulp


def test_srgb_decode_breakpoint_is_continuous():
    below = np.nextafter(SRGB_DECODE_BREAK, 0.0)
    above = np.nextafter(SRGB_DECODE_BREAK, 1.0)
    assert srgb_decode(SRGB_DECODE_BREAK) == SRGB_DECODE_BREAK / 12.92  # the line includes it
    assert srgb_decode(below) == pytest.approx(below / 12.92, rel=1e-15)
    assert srgb_decode(above) == pytest.approx(srgb_decode(SRGB_DECODE_BREAK), rel=1e-6)


def test_srgb_encode_breakpoint_is_continuous():
    above = np.nextafter(SRGB_ENCODE_BREAK, 1.0)
    assert srgb_encode(SRGB_ENCODE_BREAK) == 12.92 * SRGB_ENCODE_BREAK
    assert srgb_encode(above) == pytest.approx(srgb_encode(SRGB_ENCODE_BREAK), rel=1e-6)


def test_srgb_encode_of_decode_round_trips_on_8bit_codes_and_linear_values():
    codes = np.arange(256) / 255.0
    np.testing.assert_allclose(srgb_encode(srgb_decode(codes)), codes, atol=1e-12)
    lin = np.linspace(0.0, 1.0, 1001)
    np.testing.assert_allclose(srgb_decode(srgb_encode(lin)), lin, atol=1e-12)


def test_srgb_clips_to_its_domain_and_keeps_shapes_and_scalars():
    np.testing.assert_allclose(srgb_encode(np.array([-1.0, 2.0, np.inf])), [0, 1, 1], atol=2e-16)
    np.testing.assert_array_equal(srgb_decode(np.array([-1.0, 2.0])), [0.0, 1.0])
    assert srgb_encode(np.zeros((2, 3, 3))).shape == (2, 3, 3)
    assert isinstance(srgb_decode(0.5), float) and isinstance(srgb_encode(0.5), float)


def test_hex_colours_decode_through_the_one_curve():
    from lookdev.materials.params import parse_color

    assert parse_color("#808080") == (srgb_decode(128 / 255),) * 3
