"""The one colour module (materials/colour.py): OCIO conversions checked against colour-science.

colour-science is an independent implementation of the same standards (IEC 61966-2-1's
sRGB curve, ITU-R BT.709 and ACES AP1 primaries), so agreement here is agreement with the
standards, not with ourselves.
"""

from __future__ import annotations

import colour as colour_science
import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from lookdev.materials import colour
from lookdev.materials.disney_prepare import TINT_WEIGHTS


def srgb_decode(v):
    return colour_science.models.eotf_sRGB(np.asarray(v, dtype=np.float64))


def test_luminance_of_black_is_zero_and_of_white_is_one():
    assert colour.luminance((0.0, 0.0, 0.0)) == 0.0
    assert colour.luminance(np.zeros((4, 5, 3), np.float32)).tolist() == np.zeros((4, 5)).tolist()
    assert colour.luminance((1.0, 1.0, 1.0)) == pytest.approx(1.0, abs=1e-12)


@pytest.mark.parametrize(("space", "reference"), [("lin_rec709", "sRGB"), ("acescg", "ACEScg")])
def test_luminance_weights_are_the_xyz_matrix_y_row(space, reference):
    y_row = colour_science.RGB_COLOURSPACES[reference].matrix_RGB_to_XYZ[1]
    with colour.use(working_space=space):
        # OCIO adapts AP1's ACES white to D65 (Bradford); colour-science's row is unadapted
        np.testing.assert_allclose(colour.luminance_weights(), y_row / y_row.sum(), atol=6e-3)
    if space == "lin_rec709":
        # IEC 61966-2-1 prints the matrix to 4 digits
        np.testing.assert_allclose(colour.luminance_weights(), y_row, atol=5e-5)


def test_luminance_is_per_pixel_and_a_float_for_a_triple():
    rgb = np.random.default_rng(1).random((6, 3))
    np.testing.assert_allclose(colour.luminance(rgb), rgb @ colour.luminance_weights(), rtol=0)
    assert isinstance(colour.luminance([0.2, 0.3, 0.4]), float)


def test_burleys_tint_weights_are_not_luminance():
    assert TINT_WEIGHTS == (0.3, 0.6, 0.1)
    assert not np.allclose(TINT_WEIGHTS, colour.luminance_weights(), atol=1e-2)


def test_srgb_texture_decodes_every_8bit_code_as_iec_61966_2_1():
    codes = np.repeat((np.arange(256) / 255.0)[:, None], 3, axis=1)
    ours = colour.convert(codes, "sRGB - Texture")
    np.testing.assert_allclose(ours, srgb_decode(codes), atol=1e-6)
    assert ours[0].tolist() == [0.0, 0.0, 0.0] and ours[-1] == pytest.approx(1.0, abs=1e-7)


def test_acescg_working_space_matches_colour_science_primaries():
    rgb = np.random.default_rng(2).random((32, 3))
    with colour.use(working_space="acescg"):
        ours = colour.convert(rgb, "lin_rec709")
    reference = colour_science.RGB_to_RGB(
        rgb, "sRGB", "ACEScg", chromatic_adaptation_transform="Bradford"
    )
    np.testing.assert_allclose(ours, reference, atol=2e-3)  # CAT rounding differs by < 0.2 %


def test_data_spaces_pass_through_untouched_and_input_is_not_changed():
    rgb = np.array([[0.25, 2.0, -1.0]], np.float32)
    out = colour.convert(rgb, "Raw", "ACEScg")
    assert out.tolist() == rgb.tolist() and out is not rgb
    assert colour.is_data("Raw") and not colour.is_data("ACEScg")


def test_aliases_resolve_and_unknown_spaces_fail_in_one_line():
    assert colour.canonical("srgb_tx") == colour.canonical("sRGB - Texture")
    with pytest.raises(colour.ColourError, match="unknown colour space 'sRGB-ish'") as e:
        colour.convert([0.5, 0.5, 0.5], "sRGB-ish")
    assert "\n" not in str(e.value)


def test_an_unreadable_config_fails_in_one_line(tmp_path):
    with pytest.raises(colour.ColourError, match="cannot read the OCIO config") as e:
        with colour.use(config=str(tmp_path / "missing.ocio")):
            pass
    assert "\n" not in str(e.value)
    assert colour.working_space() == "Linear Rec.709 (sRGB)"  # nothing left in force


def test_ocio_environment_variable_names_the_config(monkeypatch):
    monkeypatch.setenv("OCIO", "ocio://cg-config-v4.0.0_aces-v2.0_ocio-v2.5")
    assert colour.config().getName().startswith("cg-config")
    monkeypatch.delenv("OCIO")
    assert colour.config().getName().startswith("studio-config")


@given(st.integers(0, 0xFFFFFF))
def test_hex_colours_decode_as_srgb_texture(code):
    text = f"#{code:06x}"
    expected = srgb_decode([int(text[i : i + 2], 16) / 255.0 for i in (1, 3, 5)])
    np.testing.assert_allclose(colour.decode_hex(text), expected, atol=1e-6)


@pytest.mark.parametrize("working", ["lin_rec709", "acescg"])
@pytest.mark.parametrize("dtype", [np.uint8, np.uint16])
@pytest.mark.parametrize("space", ["sRGB - Texture", "ACEScct", "Raw"])
def test_integer_codes_convert_as_their_normalised_values(working, dtype, space):
    c = colour
    top = np.iinfo(dtype).max
    codes = np.random.default_rng(2).integers(0, top + 1, (64, 32, 3)).astype(dtype)
    codes[0, :3] = [[0, 0, 0], [top, top, top], [top, 0, 0]]
    with c.use(working_space=working):
        exact = c.convert(codes.astype(np.float64) / top, space)
        np.testing.assert_allclose(c.convert_codes(codes, space), exact, rtol=0, atol=1e-6)


def test_a_user_config_s_file_rules_name_a_colour_map_s_space(tmp_path):
    import PyOpenColorIO as ocio

    cfg = ocio.Config.CreateFromFile(colour.DEFAULT_CONFIG)
    rules = cfg.getFileRules()
    rules.insertRule(0, "acescg_maps", "ACEScg", "*_acescg*", "exr")
    cfg.setFileRules(rules)
    path = tmp_path / "studio.ocio"
    cfg.serialize(str(path))
    with colour.use(config=str(path)):
        assert colour.texture_space(False, True, None, "/a/wall_acescg.1001.exr") == "ACEScg"
        # no rule of its own matches: the bit-depth rule; data is never colour-converted
        assert colour.texture_space(True, True, None, "/a/wall.png") == colour.canonical(
            colour.SRGB_TEXTURE
        )
        assert colour.texture_space(False, False, None, "/a/r_acescg.exr") == "Raw"
    # lookdev's own default config: its plate rules (EXR → ACES2065-1) are not consulted
    assert colour.texture_space(False, True, None, "/a/wall.exr") == colour.working_space()


def test_a_large_frame_goes_through_the_view_in_blocks_with_the_same_codes():
    frame = np.random.default_rng(3).lognormal(-1.5, 1.5, (300, 480, 3)).astype(np.float32)
    rows = colour.PARALLEL_PIXELS // 480 // 2  # each slice below the threshold: one block
    serial = np.concatenate(
        [colour.to_display(frame[k : k + rows]) for k in range(0, 300, rows)], axis=0
    )
    assert np.array_equal(colour.to_display(frame), serial)
