"""Textured parameters through the blend, the API and the Mitsuba plugin: a texel of a
texture-driven material equals the constant material with that texel's values."""

from __future__ import annotations

import numpy as np
import OpenImageIO as oiio
import pytest
from _blend_helpers import disney, layer, layered, write_image
from hypothesis import given, settings
from hypothesis import strategies as st

import lookdev
from lookdev.library import Material
from lookdev.materials.layers import NoiseMask
from lookdev.materials.params import DisneyParams
from lookdev.materials.textures import TextureInput
from lookdev.pipeline.blend import blend

WI, WO = np.array([0.3, 0.1, 0.95]), np.array([-0.2, 0.4, 0.89])


def textured(name: str, **textures: TextureInput) -> Material:
    return Material(name=name, model="disney", params=DisneyParams(metallic=0.3), textures=textures)


def test_a_texel_of_a_textured_preset_evaluates_as_the_constant_preset(tmp_path):
    rough = np.linspace(0.1, 0.9, 16, dtype=np.float32).reshape(4, 4)
    write_image(tmp_path / "r.exr", rough)
    hub = blend(textured("t", roughness=TextureInput(texture=str(tmp_path / "r.exr"))), 4)
    assert hub.textures["roughness"].texture == str(tmp_path / "r.exr")  # passed through
    for row, col in [(0, 0), (1, 3), (3, 2)]:
        value = float(rough[::-1][row, col])  # UV row 0 is the file's bottom row
        assert hub.maps["roughness"][row, col] == pytest.approx(value, abs=1e-6)
        uv = ((col + 0.5) / 4, (row + 0.5) / 4)
        constant = DisneyParams(metallic=0.3, roughness=value)
        expected = lookdev.evaluate(constant, WI, WO)
        # maps are float32, so the model runs in float32 there: float32 tolerance
        np.testing.assert_allclose(lookdev.evaluate(hub, WI, WO, uv=uv), expected, rtol=1e-3)


def test_srgb_8bit_map_and_its_linear_float_twin_agree_to_8_bits(tmp_path):
    codes = np.arange(0, 256, 5, dtype=np.float32)[:48].reshape(4, 4, 3) / 255.0
    write_image(tmp_path / "c.png", codes, fmt=oiio.UINT8)
    linear = lookdev_linear(codes)
    write_image(tmp_path / "c.exr", linear)
    srgb = blend(textured("a", base_color=TextureInput(texture=str(tmp_path / "c.png"))), 4)
    flat = blend(textured("b", base_color=TextureInput(texture=str(tmp_path / "c.exr"))), 4)
    np.testing.assert_allclose(srgb.maps["base_color"], flat.maps["base_color"], atol=1 / 255)


def lookdev_linear(encoded: np.ndarray) -> np.ndarray:
    from lookdev.materials import colour

    return colour.convert(encoded, "sRGB - Texture")


def test_a_textured_layer_blends_per_texel_as_a_constant_would(tmp_path):
    rough = np.linspace(0.2, 0.8, 64, dtype=np.float32).reshape(8, 8)
    write_image(tmp_path / "r.exr", rough)
    tex = TextureInput(texture=str(tmp_path / "r.exr"))
    mask = NoiseMask(scale=2)
    top = disney("top", roughness=0.9, metallic=0.3)
    hub = blend(layered(layer(textured("base", roughness=tex)), layer(top, mask)), 8)
    assert "roughness" not in hub.textures  # blending changed it: no file to reference
    from lookdev.pipeline.blend.masks import MaskSampler

    m = MaskSampler((8, 8)).evaluate(mask)
    expected = (1 - m) * rough[::-1] + m * 0.9
    np.testing.assert_allclose(hub.maps["roughness"], expected, atol=1e-6)


@settings(max_examples=10, deadline=None)
@given(st.floats(0.0, 1.0, width=32))
def test_texture_of_a_constant_image_is_the_constant(tmp_path_factory, value):
    folder = tmp_path_factory.mktemp("const")
    write_image(folder / "r.exr", np.full((4, 4), value, dtype=np.float32))
    hub = blend(textured("c", roughness=TextureInput(texture=str(folder / "r.exr"))), 4)
    assert not hub.maps and hub.constants["roughness"] == pytest.approx(value)


def test_udim_tiles_land_on_their_uv_squares(tmp_path):
    colours = {1001: (1, 0, 0), 1002: (0, 1, 0), 1011: (0, 0, 1), 1012: (1, 1, 0)}
    for tile, rgb in colours.items():
        write_image(tmp_path / f"c.{tile}.exr", np.broadcast_to(np.float32(rgb), (4, 4, 3)))
    tex = TextureInput(texture=str(tmp_path / "c.<UDIM>.exr"))
    hub = blend(textured("u", base_color=tex), 4)
    assert hub.uv_extent == (0, 0, 2, 2) and hub.tiles == (1001, 1002, 1011, 1012)
    assert hub.resolution == (8, 8) and hub.textures["base_color"].texture.endswith("<UDIM>.exr")
    for tile, rgb in colours.items():
        u, v = (tile - 1001) % 10 + 0.5, (tile - 1001) // 10 + 0.5
        assert hub.params_at_uv(u, v).base_color == pytest.approx(rgb)


@pytest.mark.slow
def test_udim_quadrants_render_in_mitsuba(tmp_path):
    """The Dr.Jit plugin reads each tile's colour at that tile's UVs (to_uv onto the extent)."""
    from _mitsuba_helpers import interaction, mitsuba_module

    mi = mitsuba_module()
    colours = {
        1001: (0.9, 0.1, 0.1),
        1002: (0.1, 0.9, 0.1),
        1011: (0.1, 0.1, 0.9),
        1012: (0.9, 0.9, 0.1),
    }
    for tile, rgb in colours.items():
        write_image(tmp_path / f"c.{tile}.exr", np.broadcast_to(np.float32(rgb), (4, 4, 3)))
    tex = TextureInput(texture=str(tmp_path / "c.<UDIM>.exr"))
    hub = blend(textured("u", base_color=tex), 4)
    from lookdev.pipeline.export.mitsuba import bsdf_dict

    bsdf = mi.load_dict(bsdf_dict(hub, allow_principled=False))
    ctx = mi.BSDFContext()
    for tile in colours:
        uv = ((tile - 1001) % 10 + 0.5, (tile - 1001) // 10 + 0.5)
        si = interaction(mi, [WO], uv=uv)
        got = np.array(bsdf.eval(ctx, si, mi.Vector3f(WI)), dtype=np.float64).ravel()
        expected = lookdev.evaluate(hub, WI, WO, uv=uv) * WI[2]  # Mitsuba's f·cos
        np.testing.assert_allclose(got, expected, rtol=2e-3, atol=1e-5)


def test_a_textured_pixar_layer_composites_per_texel_as_its_constant_twin(tmp_path):
    from lookdev.library import Layer
    from lookdev.materials.pixar import PixarParams

    rough = np.linspace(0.1, 0.9, 16, dtype=np.float32).reshape(4, 4)
    col = np.random.default_rng(1).random((4, 4, 3)).astype(np.float32)
    write_image(tmp_path / "r.exr", rough)
    write_image(tmp_path / "c.exr", col)
    textures = {
        "roughness": TextureInput(texture=str(tmp_path / "r.exr")),
        "surface_color": TextureInput(texture=str(tmp_path / "c.exr")),
    }
    base = Material(name="b", model="pixar", params=PixarParams(metallic=0.2), textures=textures)
    stack = Material(name="s", model="layered", layers=[Layer(material=base, name="base")])
    plain, layered_hub = blend(base, 4), blend(stack, 4)
    assert set(plain.textures) == set(textures) and layered_hub.representation == "lobe_weights"
    for row, col_ in [(0, 0), (2, 3), (3, 1)]:
        texel = PixarParams(
            metallic=0.2,
            roughness=float(rough[::-1][row, col_]),
            surface_color=tuple(float(x) for x in col[::-1][row, col_]),
        )
        uv = ((col_ + 0.5) / 4, (row + 0.5) / 4)
        expected = lookdev.evaluate(texel, WI, WO)
        for hub in (plain, layered_hub):
            np.testing.assert_allclose(lookdev.evaluate(hub, WI, WO, uv=uv), expected, rtol=1e-5)


def test_a_textured_sheen_votes_on_the_sheen_model(tmp_path):
    from lookdev.pipeline.blend import BlendError

    write_image(tmp_path / "s.exr", np.linspace(0.0, 1.0, 16, dtype=np.float32).reshape(4, 4))
    sheen = TextureInput(texture=str(tmp_path / "s.exr"))
    cloth = Material(
        name="cloth",
        model="disney",
        params=DisneyParams(sheen_model="conty_kulla"),
        textures={"sheen": sheen},
    )
    velvet = disney("velvet", sheen=1.0, sheen_model="disney")
    with pytest.raises(BlendError, match="sheen_model"):
        blend(layered(layer(cloth), layer(velvet, NoiseMask())), 4)


def test_a_plot_at_a_uv_draws_the_constant_material_of_that_texel(tmp_path):
    """`lookdev plot --uv U V`: the slice drawn is the constant preset's slice at that texel."""
    from lookdev.pipeline.analysis import plots

    rough = np.linspace(0.1, 0.9, 16, dtype=np.float32).reshape(4, 4)
    write_image(tmp_path / "r.exr", rough)
    hub = blend(textured("t", roughness=TextureInput(texture=str(tmp_path / "r.exr"))), 4)
    for row, col in [(0, 0), (2, 1), (3, 3)]:
        uv = ((col + 0.5) / 4, (row + 0.5) / 4)
        at = plots.at_uv(hub, uv)
        assert not at.maps and at.params.roughness == pytest.approx(rough[::-1][row, col])
        constant = DisneyParams(metallic=0.3, roughness=float(rough[::-1][row, col]))
        _, _, f_uv = plots.brdf_slice(at.bsdf_model, at.centre_params, 16)
        _, _, f_const = plots.brdf_slice(at.bsdf_model, constant, 16)
        np.testing.assert_allclose(f_uv, f_const, rtol=1e-5, atol=1e-7)
    out = lookdev.plot(
        textured("t", roughness=TextureInput(texture=str(tmp_path / "r.exr"))),
        tmp_path / "p.png",
        uv=(0.9, 0.9),
        resolution=16,
    )
    assert out.materials == ["t @ uv (0.9, 0.9)"] and (tmp_path / "p.png").stat().st_size > 0
