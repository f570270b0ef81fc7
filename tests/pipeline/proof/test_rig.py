"""The calibrated rig: ColorChecker values from colour-science, an 18 % grey ball that
renders 0.18 under a white sky, ``--rig none`` without it, and the IBL orientation
convention held by proofs and exported scenes alike."""

from __future__ import annotations

import math

import colour
import numpy as np
import pytest

from lookdev.materials import colour as lcolour
from lookdev.pipeline.proof import ibl, rig, shaderball

DATA = colour.CCS_COLOURCHECKERS[rig.CHART_NAME]


@pytest.fixture(scope="module")
def mi():
    from lookdev.pipeline.variant import use_mitsuba

    use_mitsuba()
    import mitsuba

    return mitsuba


def _expected(space: str) -> np.ndarray:
    """xyY → XYZ → Bradford D50 → the space's white → its linear RGB, written out step by
    step with colour-science's own pieces (not the module's one call)."""
    xyz = colour.xyY_to_XYZ(np.array(list(DATA.data.values())))
    cs = colour.RGB_COLOURSPACES[space]
    adapted = colour.chromatic_adaptation(
        xyz,
        colour.xy_to_XYZ(DATA.illuminant),
        colour.xy_to_XYZ(cs.whitepoint),
        method="Von Kries",
        transform="Bradford",
    )
    return adapted @ cs.matrix_XYZ_to_RGB.T


@pytest.mark.parametrize("space", ["lin_rec709", "acescg"])
def test_patch_values_are_colour_sciences_colorchecker_to_float_precision(space):
    with lcolour.use(working_space=space):
        values = rig.patch_values()
        name = lcolour.working_space()
    assert list(values) == list(DATA.data)  # all 24, in the chart's reading order
    got = np.array(list(values.values()))
    np.testing.assert_allclose(got, _expected(name), rtol=0, atol=1e-12)
    # the neutral row keeps the data's Y as its luminance (adaptation moves only colours)
    with lcolour.use(working_space=space):
        y = lcolour.luminance(got[-6:])
    np.testing.assert_allclose(y, [v[2] for v in list(DATA.data.values())[-6:]], atol=1e-3)


def test_acescg_patches_agree_with_the_ocio_configs_conversion():
    """The same chart through OCIO's Rec.709 → ACEScg: the CATs differ a little."""
    with lcolour.use(working_space="acescg"):
        direct = np.array(list(rig.patch_values().values()))
    via_ocio = lcolour.convert(
        np.array(list(rig.patch_values("lin_rec709").values())), "lin_rec709", "ACEScg"
    )
    np.testing.assert_allclose(direct, via_ocio, atol=2e-3)


def test_chart_bitmap_holds_the_patches_the_right_way_up():
    values = list(rig.patch_values().values())
    tex = rig.chart_texture()
    pitch = rig.PATCH_TEXELS + rig.GAP_TEXELS
    top = tex[::-1]  # row 0 of the bitmap is the chart's bottom edge
    for i, rgb in enumerate(values):
        r, c = divmod(i, 6)
        y = rig.GAP_TEXELS + r * pitch + rig.PATCH_TEXELS // 2
        x = rig.GAP_TEXELS + c * pitch + rig.PATCH_TEXELS // 2
        np.testing.assert_array_equal(top[y, x], np.float32(rgb))
    assert tex.dtype == np.float32


def test_rig_objects_are_in_the_scene_only_when_asked(mi):
    env = np.ones((8, 16, 3), np.float32)
    keys = {
        r: {k for k in shaderball.scene_dict({"type": "diffuse"}, env, (16, 8), 2, rig=r)}
        for r in rig.RIGS
    }
    assert {k for k in keys["full"] if k.startswith("rig_")} == {
        "rig_chrome",
        "rig_grey",
        "rig_chart",
    }
    assert {k for k in keys["balls"] if k.startswith("rig_")} == {"rig_chrome", "rig_grey"}
    assert not {k for k in keys["none"] if k.startswith("rig_")}
    # without the rig the camera frames the pair as tightly as before
    assert shaderball.framed("none") == (-2.3, 2.3)
    assert shaderball.framed("full")[1] > 3.0
    scene = mi.load_dict(shaderball.scene_dict({"type": "diffuse"}, env, (16, 8), 2, rig="none"))
    assert len(scene.shapes()) == 3  # the ground and the ball's and the cup's instances


@pytest.mark.render
def test_grey_ball_renders_0_18_under_a_white_sky(mi):
    """A diffuse albedo ρ under constant radiance 1 reflects ρ (no other object in view)."""
    grey = rig.shapes("balls", (0.0, 0.0, 10.0))["rig_grey"]
    centre = np.array(rig.GREY_CENTER)
    scene = mi.load_dict(
        {
            "type": "scene",
            "integrator": {"type": "path", "max_depth": 3},
            "emitter": {"type": "constant", "radiance": {"type": "rgb", "value": 1.0}},
            "sensor": {
                "type": "perspective",
                "fov": 2 * math.degrees(math.atan(0.5 * rig.BALL_RADIUS / 4.0)),
                "to_world": mi.ScalarTransform4f().look_at(
                    origin=(centre + [0, 0, 4.0]).tolist(), target=centre.tolist(), up=[0, 1, 0]
                ),
                "film": {
                    "type": "hdrfilm",
                    "width": 8,
                    "height": 8,
                    "pixel_format": "rgb",
                    "rfilter": {"type": "box"},  # independent pixels: the noise is theirs
                },
                "sampler": {"type": "independent", "sample_count": 256},
            },
            "grey": grey,
        }
    )
    image = np.array(mi.render(scene), dtype=np.float64)[..., 0]  # grey: R = G = B
    noise = image.std() / math.sqrt(image.size)
    assert abs(image.mean() - rig.GREY_ALBEDO) <= 4 * noise + 1e-4, (image.mean(), noise)


def _spot_ibl(tmp_path, u: float) -> str:
    """A black lat-long with one bright patch on the horizon at ``u``."""
    from lookdev.pipeline.proof.contact import write_exr

    width = 64
    pixels = np.zeros((width // 2, width, 3), np.float32)
    col = int(u * width)
    pixels[12:20, col - 3 : col + 3] = 50.0
    return str(write_exr(pixels, tmp_path / f"spot_{u}.exr"))


@pytest.mark.render
def test_the_orientation_convention_holds_in_exported_scenes(mi, tmp_path):
    """u = ½ lights the sphere from the camera's side at rotation 0; at +90° that light
    comes from the camera's right (ibl.ORIENTATION)."""
    from lookdev.materials.params import DisneyParams
    from lookdev.pipeline.export.mitsuba.scene import scene_dict

    matte = DisneyParams(base_color=(0.8, 0.8, 0.8), roughness=1.0, specular=0.0)
    front = _spot_ibl(tmp_path, 0.5)

    def render(rotation):
        tree = scene_dict(
            matte, resolution=(16, 16), spp=32, environment=front, ibl_rotation=rotation
        )
        return np.array(mi.render(mi.load_dict(tree)), dtype=np.float64)[..., :3].mean(-1)

    at0, at90 = render(0.0), render(90.0)
    left, right = at90[:, :8].sum(), at90[:, 8:].sum()
    assert right > 5 * left  # lit from the camera's right
    assert at0[6:10, 6:10].mean() > 2 * at90[6:10, 6:10].mean()  # front-lit at 0
    # the proof rotates its environment by the same transform
    assert str(ibl.envmap_to_world(90.0)) == str(
        scene_dict(matte, environment=front, ibl_rotation=90.0)["environment"]["to_world"]
    )


def test_exported_xml_states_the_orientation(tmp_path):
    from lookdev.materials.params import DisneyParams
    from lookdev.pipeline.export.mitsuba.xml import export_scene

    path = tmp_path / "s.xml"
    export_scene(DisneyParams(), path, environment=_spot_ibl(tmp_path, 0.5))
    text = path.read_text()
    assert "lookdev IBL orientation: up: +y" in text
    assert 'name="to_world"' in text.split("<emitter")[1].split("</emitter>")[0]
