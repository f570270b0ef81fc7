"""A preset's height and texture-set normal map on the hub (pipeline/blend/surface_maps.py)."""

from __future__ import annotations

import numpy as np
import OpenImageIO as oiio
import pytest
from _blend_helpers import write_image

import lookdev
from lookdev.pipeline.blend.errors import TextureError
from lookdev.pipeline.blend.surface_maps import udim_tiles


def test_height_is_scaled_to_scene_units_over_the_udim_box(tmp_path):
    # tile 1002 (u = 1) is white, 1011 (v = 1) grey; 1012 is missing: the set's mean
    write_image(tmp_path / "h.1001.png", np.zeros((4, 4)), oiio.UINT16)
    write_image(tmp_path / "h.1002.png", np.ones((4, 4)), oiio.UINT16)
    write_image(tmp_path / "h.1011.png", np.full((4, 4), 0.5), oiio.UINT16)
    (tmp_path / "p.toml").write_text(
        'name = "p"\nmodel = "disney"\n'
        'height = { texture = "h.<UDIM>.png", scale = 0.02, offset = 0.001 }\n'
    )
    hub = lookdev.blend(str(tmp_path / "p.toml"), 4)
    assert hub.map_tiles == (2, 2)
    assert hub.height_map.shape == (8, 8) and hub.height_map.dtype == np.float32
    h = hub.height_map
    assert h[:4, :4] == pytest.approx(0.001)  # tile 1001, UV rows from v = 0
    assert h[:4, 4:] == pytest.approx(0.021)  # 1002: u in [1, 2)
    assert h[4:, :4] == pytest.approx(0.011, abs=1e-6)  # 1011: v in [1, 2)
    assert h[4:, 4:] == pytest.approx(0.02 * 0.5 + 0.001, abs=1e-6)  # missing: the mean
    assert hub.textures["height"].scale == 0.02
    assert "height_map" in hub.arrays  # baked and digested with the other maps


def test_a_directx_normal_map_is_flipped_to_opengl(tmp_path):
    encoded = np.broadcast_to(np.array([0.5, 0.75, 0.9]), (4, 4, 3))
    write_image(tmp_path / "a_Normal_DirectX.png", encoded, oiio.UINT8)
    (tmp_path / "p.toml").write_text('name = "p"\nmodel = "disney"\ntextures = "a_<channel>.png"\n')
    hub = lookdev.blend(str(tmp_path / "p.toml"), 4)
    assert hub.normal_map.shape == (4, 4, 3)
    assert hub.normal_map[0, 0, 1] < 0  # green up in the file (DirectX: y down) → −y
    assert np.linalg.norm(hub.normal_map, axis=-1) == pytest.approx(1.0)


def test_no_tiles_is_a_texture_error(tmp_path):
    with pytest.raises(TextureError, match="no UDIM tiles"):
        udim_tiles(tmp_path / "x.<UDIM>.png")
