"""A UDIM set of four tiles rendered on a 2 × 2 UV quad: each tile's colour lands on its
own quadrant (the hub's maps span the tiles, the bitmap's to_uv brings the mesh's UVs onto
them). A tiny render; which UV each pixel sees is asked of Mitsuba (a ray per pixel), not
assumed from the camera's conventions."""

from __future__ import annotations

import numpy as np
import pytest
from _blend_helpers import write_image

from lookdev.library import Material
from lookdev.materials.params import DisneyParams
from lookdev.materials.textures import TextureInput
from lookdev.pipeline.blend import blend

COLOURS = {1001: (0.8, 0.05, 0.05), 1002: (0.05, 0.8, 0.05), 1011: (0.05, 0.05, 0.8)}
COLOURS[1012] = (0.5, 0.5, 0.5)
SIZE = 24

# UVs 0..2 across the quad; written as 1 − v because Mitsuba's OBJ reader flips v.
QUAD_OBJ = """v -1 -1 0
v 1 -1 0
v 1 1 0
v -1 1 0
vt 0 1
vt 2 1
vt 2 -1
vt 0 -1
vn 0 0 1
f 1/1/1 2/2/1 3/3/1
f 1/1/1 3/3/1 4/4/1
"""


@pytest.mark.slow
def test_each_udim_tile_renders_on_its_quadrant(tmp_path):
    from _mitsuba_helpers import mitsuba_module

    from lookdev.pipeline.export.mitsuba import bsdf_dict

    mi = mitsuba_module()
    for tile, rgb in COLOURS.items():
        write_image(tmp_path / f"c.{tile}.exr", np.broadcast_to(np.float32(rgb), (8, 8, 3)))
    params = DisneyParams(roughness=1.0, specular=0.0)
    tex = TextureInput(texture=str(tmp_path / "c.<UDIM>.exr"))
    hub = blend(
        Material(name="udim", model="disney", params=params, textures={"base_color": tex}), 8
    )
    assert hub.uv_extent == (0, 0, 2, 2)
    (tmp_path / "quad.obj").write_text(QUAD_OBJ)
    scene = mi.load_dict(
        {
            "type": "scene",
            "integrator": {"type": "direct"},
            "emitter": {"type": "constant"},
            "quad": {
                "type": "obj",
                "filename": str(tmp_path / "quad.obj"),
                "bsdf": bsdf_dict(hub, allow_principled=False),
            },
            "sensor": {
                "type": "orthographic",
                "to_world": mi.ScalarTransform4f().look_at(
                    origin=[0, 0, 3], target=[0, 0, 0], up=[0, 1, 0]
                ),
                "film": {"type": "hdrfilm", "width": SIZE, "height": SIZE, "pixel_format": "rgb"},
                "sampler": {"type": "independent", "sample_count": 16},
            },
        }
    )
    image = np.array(mi.render(scene, seed=1), dtype=np.float64)
    # One ray per pixel centre, all at once: which UV each pixel sees.
    jj, ii = np.meshgrid((np.arange(SIZE) + 0.5) / SIZE, (np.arange(SIZE) + 0.5) / SIZE)
    film = mi.Point2f(jj.ravel().astype(np.float32), ii.ravel().astype(np.float32))
    ray, _ = scene.sensors()[0].sample_ray(0.0, 0.5, film, mi.Point2f(0.5, 0.5))
    si = scene.ray_intersect(ray)
    u = np.array(si.uv.x).reshape(SIZE, SIZE)
    v = np.array(si.uv.y).reshape(SIZE, SIZE)
    hit = np.array(si.is_valid()).reshape(SIZE, SIZE)
    inside = hit & (np.abs(u - 1) > 0.15) & (np.abs(v - 1) > 0.15)  # off the seams
    assert inside.sum() > SIZE * SIZE // 2
    names = np.array(list(COLOURS))
    directions = np.array([np.array(c) / np.linalg.norm(c) for c in COLOURS.values()])
    seen = names[
        np.argmax((image / np.linalg.norm(image, axis=-1, keepdims=True)) @ directions.T, axis=-1)
    ]
    expected = 1001 + np.floor(u).astype(int) + 10 * np.floor(v).astype(int)
    np.testing.assert_array_equal(seen[inside], expected[inside])
    assert set(expected[inside]) == set(COLOURS)  # every quadrant seen
