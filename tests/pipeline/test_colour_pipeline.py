"""Colour management end to end (issue 14 item 3, issue 16 item 4): the working space from
preset to EXR, USD, MaterialX and proof; the EXR writer; the global CLI options.

Reference values come from colour-science (an independent implementation of the primaries
and transfer curves) and files are read back with OpenImageIO and usd-core, not with our
own readers.
"""

from __future__ import annotations

import json
from pathlib import Path

import colour as colour_science
import numpy as np
import OpenImageIO as oiio
import pytest

import lookdev
from lookdev.library import files
from lookdev.materials import colour
from lookdev.pipeline.exr import write_exr

ACES_SDR = "ACES 2.0 - SDR 100 nits (Rec.709)"
AP1 = colour_science.RGB_COLOURSPACES["ACEScg"]
REC709 = colour_science.RGB_COLOURSPACES["sRGB"]


@pytest.fixture(autouse=True)
def _cache(tmp_path_factory, monkeypatch):
    monkeypatch.setenv("LOOKDEV_CACHE", str(tmp_path_factory.getbasetemp() / "cache"))


def _header(path: Path) -> dict:
    inp = oiio.ImageInput.open(str(path))
    assert inp is not None, oiio.geterror()
    try:
        return {a.name: a.value for a in inp.spec().extra_attribs}
    finally:
        inp.close()


def _chromaticities(space) -> list[float]:
    return [*np.asarray(space.primaries).reshape(-1), *space.whitepoint]


# -- the EXR writer ------------------------------------------------------------------------
@pytest.mark.parametrize(("working", "reference"), [("lin_rec709", REC709), ("acescg", AP1)])
def test_a_colour_exr_carries_the_working_spaces_chromaticities_and_name(
    tmp_path, working, reference
):
    with colour.use(working_space=working):
        write_exr(tmp_path / "c.exr", np.full((4, 6, 3), 0.25, np.float32))
        name = colour.working_space()
    head = _header(tmp_path / "c.exr")
    np.testing.assert_allclose(head["chromaticities"], _chromaticities(reference), atol=1e-6)
    assert head["colorSpace"] == name and head["compression"] == "zip"
    assert oiio.ImageBuf(str(tmp_path / "c.exr")).get_pixels(oiio.FLOAT).shape == (4, 6, 3)


def test_a_data_exr_is_raw_without_primaries(tmp_path):
    write_exr(tmp_path / "r.exr", np.zeros((4, 6), np.float32), colour.RAW)
    head = _header(tmp_path / "r.exr")
    assert "chromaticities" not in head and head["colorSpace"] == "Raw"


def test_an_exr_that_cannot_be_written_is_one_line(tmp_path):
    with pytest.raises(files.WriteError, match="cannot write") as e:
        write_exr(tmp_path / "missing" / "x.exr", np.zeros((2, 2, 3)), shown="x.exr")
    assert "\n" not in str(e.value)


# -- ACEScg end to end -----------------------------------------------------------------------
def test_a_presets_hex_colour_lands_in_acescg_as_colour_science_converts_it():
    with lookdev.colour_settings(working_space="acescg"):
        material = lookdev.load("gold")
        hexed = colour.decode_hex("#d4af37")
    srgb = colour_science.models.eotf_sRGB(np.array([0xD4, 0xAF, 0x37]) / 255.0)
    reference = colour_science.RGB_to_RGB(
        srgb, REC709, AP1, chromatic_adaptation_transform="Bradford"
    )
    np.testing.assert_allclose(hexed, reference, atol=2e-3)  # CAT matrices round differently
    linear709 = lookdev.load("gold").params.base_color  # the preset's own linear Rec.709
    expected = colour_science.RGB_to_RGB(linear709, REC709, AP1, "Bradford")
    np.testing.assert_allclose(material.params.base_color, expected, atol=2e-3)


@pytest.mark.slow
def test_acescg_exports_name_their_colour_space(tmp_path):
    from pxr import Usd

    with lookdev.colour_settings(working_space="acescg"):
        lookdev.export_usd(["gold"], tmp_path / "gold.usda", mtlx=tmp_path / "gold.mtlx")
        lookdev.bake(lookdev.blend("rusty_car_paint", resolution=16), tmp_path / "baked")
    import MaterialX as mx

    doc = mx.createDocument()
    mx.readFromXmlFile(doc, str(tmp_path / "gold.mtlx"))
    assert doc.getColorSpace() == "acescg"
    stage = Usd.Stage.Open(str(tmp_path / "gold.usda"))
    prim = stage.GetPrimAtPath("/Materials/gold")
    assert prim.HasAPI(Usd.ColorSpaceAPI)
    assert Usd.ColorSpaceAPI.ComputeColorSpaceName(prim, None) == "lin_ap1_scene"
    assert stage.GetColorManagementSystem() == "OpenColorIO"
    colour_maps = [p for p in (tmp_path / "baked").glob("*.exr") if "color" in p.name]
    assert colour_maps, "the layered preset has a varying base colour"
    for path in colour_maps:
        np.testing.assert_allclose(_header(path)["chromaticities"], _chromaticities(AP1), atol=1e-6)


GREY = """name = "grey18"
model = "disney"

[params]
base_color = 0.18
roughness = 1.0
specular = 0.0
"""


@pytest.mark.slow
def test_a_grey_proof_frame_looks_the_same_in_either_working_space(tmp_path):
    """Grey albedo under a neutral sky: the render is the same light in two spaces, so the
    view (from each working space) must show the same code values (±1 of 255)."""
    from lookdev.library import load_material
    from lookdev.pipeline.blend import blend
    from lookdev.pipeline.proof import batch, ibl
    from lookdev.pipeline.variant import use_mitsuba

    use_mitsuba()
    (tmp_path / "grey18.toml").write_text(GREY)
    shown, heads = {}, {}
    for space in colour.WORKING_SPACES:
        with colour.use(working_space=space):
            material = blend(load_material(tmp_path / "grey18.toml"), 8)
            # the grey alone: the rig's chart and chrome ball are colours, rendered in two bases
            settings = batch.Settings(1, 0, 16, (48, 24), rig="none")
            job = batch.make_jobs(
                [material], [ibl.load("overcast", 64)], tmp_path / space, settings
            )[0]
        batch.run_job(job)  # the worker enters the job's colour settings itself
        folder = tmp_path / space / "grey18" / "overcast"
        shown[space] = oiio.ImageBuf(str(folder / "frame_000.png")).get_pixels(oiio.UINT8)
        heads[space] = _header(folder / "frame_000.exr")
        doc = json.loads((folder / "manifest.json").read_text())
        assert doc["settings"]["colour"]["working_space"] == colour.canonical(space)
    diff = np.abs(shown["lin_rec709"].astype(int) - shown["acescg"].astype(int))
    assert diff.max() <= 1, diff.max()
    np.testing.assert_allclose(heads["acescg"]["chromaticities"], _chromaticities(AP1), atol=1e-6)
    np.testing.assert_allclose(
        heads["lin_rec709"]["chromaticities"], _chromaticities(REC709), atol=1e-6
    )


# -- the CLI -------------------------------------------------------------------------------
def one_line(r) -> str:
    assert r.code == 2, (r.code, r.out, r.err)
    lines = r.err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("lookdev: error: "), r.err
    return lines[0]


def test_colour_lists_name_the_configs_spaces_and_views(cli):
    r = cli("colour", "spaces", "--json")
    assert r.code == 0, r.err
    doc = json.loads(r.out)
    names = [s["name"] for s in doc["spaces"]]
    assert "ACEScg" in names and doc["working_space"] == "Linear Rec.709 (sRGB)"
    r = cli("--working-space", "acescg", "--view", "un-tone-mapped", "colour", "views", "--json")
    doc = json.loads(r.out)
    assert doc["working_space"] == "ACEScg"
    assert doc["in_force"] == {"display": "sRGB - Display", "view": "Un-tone-mapped", "look": ""}


@pytest.mark.parametrize(
    ("args", "needle"),
    [
        (["--view", "Filmic", "colour", "views"], "unknown view 'Filmic'"),
        (["--display", "CRT", "colour", "views"], "unknown display 'CRT'"),
        (["--look", "bleach", "colour", "views"], "unknown look 'bleach'"),
        (["--working-space", "lin_p3", "colour", "spaces"], "unknown colour space 'lin_p3'"),
        (["--config", "/nowhere/config.ocio", "colour", "spaces"], "cannot read the OCIO config"),
        (["colour", "spaces", "--working-space", "acescg"], "is a global colour option"),
    ],
)
def test_unknown_colour_names_are_one_line_exit_2(cli, args, needle):
    assert needle in one_line(cli(*args))


def test_ocio_environment_names_another_builtin_config(cli, monkeypatch):
    other = "ocio://cg-config-v4.0.0_aces-v2.0_ocio-v2.5"
    monkeypatch.setenv("OCIO", other)
    r = cli("colour", "views", "--json")
    assert r.code == 0, r.err
    assert json.loads(r.out)["config"] == other
    assert colour.settings().config_name == other and colour.config().getName().startswith("cg")
    r = cli("--config", colour.DEFAULT_CONFIG, "colour", "views", "--json")
    assert json.loads(r.out)["config"] == colour.DEFAULT_CONFIG  # --config wins over $OCIO


@pytest.mark.slow
def test_view_changes_the_proof_png(cli, tmp_path):
    common = ["gold", "--ibl", "sky", "-n", "1", "-m", "0", "-s", "4", "-r", "32", "16"]
    pngs, exrs = {}, {}
    for view in (None, "Un-tone-mapped"):
        out = tmp_path / (view or "default")
        r = cli(*(["--view", view] if view else []), "proof", *common, "-o", str(out))
        assert r.code == 0, r.err
        pngs[view] = oiio.ImageBuf(str(out / "gold" / "sky" / "frame_000.png")).get_pixels()
        exrs[view] = oiio.ImageBuf(str(out / "gold" / "sky" / "frame_000.exr")).get_pixels()
        manifest = json.loads((out / "gold" / "sky" / "manifest.json").read_text())
        assert manifest["settings"]["colour"]["view"] == (view or ACES_SDR)
    assert np.abs(pngs[None] - pngs["Un-tone-mapped"]).max() > 0.05
    # the scene-linear frames do not depend on the view: only their display does
    np.testing.assert_array_equal(exrs[None], exrs["Un-tone-mapped"])


def test_an_acescg_stage_imports_back_into_the_presets_linear_rec709(tmp_path):
    from lookdev.pipeline.export.usd.reader import import_usd

    with lookdev.colour_settings(working_space="acescg"):
        lookdev.export_usd(["plastic_glossy"], tmp_path / "p.usda", contexts=["universal"])
    (imported,) = import_usd(tmp_path / "p.usda")
    written = lookdev.load("plastic_glossy").params.base_color  # linear Rec.709
    np.testing.assert_allclose(imported.params["base_color"], written, atol=1e-4)
