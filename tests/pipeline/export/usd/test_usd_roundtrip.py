"""Export → import recovers every parameter the written surfaces can express."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

pytest.importorskip("pxr")
from pxr import Sdf, Usd, UsdShade  # noqa: E402

from lookdev.library import Library, load_material  # noqa: E402
from lookdev.materials.params import DisneyParams  # noqa: E402
from lookdev.pipeline.blend import blend  # noqa: E402
from lookdev.pipeline.export.usd.lobes import DEFAULTS, canonical, effective  # noqa: E402
from lookdev.pipeline.export.usd.names import PREVIEW_DISNEY  # noqa: E402
from lookdev.pipeline.export.usd.network import source_from_params  # noqa: E402
from lookdev.pipeline.export.usd.reader import import_usd  # noqa: E402
from lookdev.pipeline.export.usd.sources import source_for  # noqa: E402
from lookdev.pipeline.export.usd.writer import export_usd  # noqa: E402

PREVIEW_PARAMS = {s.param for s in PREVIEW_DISNEY} | {"specular"}
"""What UsdPreviewSurface expresses: its table, with both spellings of the F0."""
UNEXPRESSIBLE = {"sheen_model", "sheen_roughness", "flatness"}

PIXAR_PREVIEW = {"surface_color", "metallic", "roughness", "clear", "normal_fresnel", "ior"}
"""What a Pixar material is read back from: UsdPreviewSurface (the F0 as the surface's
IOR) and the OpenPBR inputs that take one of Smits' parameters as it is (``clear``, which
the preview surface keeps out of ``opacity`` by default)."""
PIXAR_OPENPBR = {"surface_color", "metallic", "specular_tint", "clear", "transmission_tint"}

"""What no context reads back: the sheen model and roughness (MaterialX's Disney sheen is
Conty-Kulla's with a fixed roughness, RenderMan's is Burley's), and ``flatness``, which
neither ND_disney_principled nor PxrDisneyBsdf has (lookdev wrote RenderMan a
``flatness`` input RenderMan does not define: it was never read by a renderer)."""

unit = st.floats(0.0, 1.0)
edge_unit = st.sampled_from([0.0, 1.0]) | unit  # the edges themselves, often
disney = st.fixed_dictionaries(
    {
        "base_color": st.tuples(unit, unit, unit),
        "metallic": edge_unit,
        "roughness": edge_unit,
        "subsurface": edge_unit,
        "specular_tint": edge_unit,
        "anisotropic": edge_unit,
        "sheen": edge_unit,
        "sheen_tint": edge_unit,
        "clearcoat": st.sampled_from([0.0, 4.0]) | st.floats(0.0, 4.0),
        "clearcoat_gloss": edge_unit,
        "spec_trans": edge_unit,
        "diff_trans": edge_unit,
        "flatness": edge_unit,
        # 0 (no medium) or at least 1e-6: a tinier one made σt infinite (issue 13)
        "scatter_distance": st.sampled_from([0.0]) | st.floats(1e-4, 10.0),
        # per channel, as the RGB radius of ND_disney_principled / PxrDisneyBsdf
        "scatter_distance_scale": st.tuples(*[st.sampled_from([1.0]) | st.floats(0.01, 1.0)] * 3),
        "thin": st.booleans(),
    },
    optional={"ior": st.floats(1.0, 3.0), "specular": st.floats(0.0, 2.0)},
).filter(lambda d: not ("ior" in d and "specular" in d))


def _round_trip(tmp: Path, params: DisneyParams, contexts) -> dict:
    out = tmp / "rt.usda"
    export_usd([source_from_params("m", "disney", params)], out, contexts=contexts)
    (found,) = import_usd(out)
    assert found.model == "disney"
    return found.params


def _assert_same(got: dict, want: DisneyParams, keys: set[str]) -> None:
    """Effective values equal to float32 precision on ``keys`` (F0 compared as IOR)."""
    a = effective(canonical(DisneyParams.parse(got)))
    b = effective(canonical(want))
    for k in sorted(keys):
        if k == "specular":
            continue  # one parameter with `ior`; compared there
        if isinstance(b[k], str | bool):
            assert a[k] == b[k], k
        else:
            np.testing.assert_allclose(a[k], b[k], rtol=2e-6, atol=2e-6, err_msg=k)


@pytest.mark.slow
@settings(
    max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(data=disney)
def test_universal_round_trip_recovers_what_it_expresses(tmp_path, data):
    params = DisneyParams(**data)
    got = _round_trip(tmp_path, params, ("universal",))
    keys = PREVIEW_PARAMS
    if 0.0 < np.float32(params.metallic) < 1.0:
        # A fractional metallic is refitted for the surface's own interpolation (F0
        # towards white): base colour and metallic change, named in the loss note.
        keys = keys - {"metallic", "base_color"}
    _assert_same(got, params, keys)
    unexpressed = set(got) - PREVIEW_PARAMS
    assert not unexpressed, f"read parameters the surface cannot hold: {unexpressed}"


@pytest.mark.slow
@settings(
    max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(data=disney)
def test_all_contexts_round_trip_recovers_every_parameter(tmp_path, data):
    params = DisneyParams(**data)
    got = _round_trip(tmp_path, params, ("universal", "mtlx", "ri"))
    _assert_same(got, params, set(DEFAULTS["disney"]) - UNEXPRESSIBLE)


def test_spelling_of_the_specular_comes_back(tmp_path):
    assert _round_trip(tmp_path, DisneyParams(ior=1.33), ("universal",)) == {"ior": 1.33}
    assert _round_trip(tmp_path, DisneyParams(specular=0.3), ("universal",)) == {
        "specular": pytest.approx(0.3, rel=1e-6)
    }


@pytest.mark.parametrize("name", Library(use_env=False).names())
def test_every_builtin_preset_round_trips(tmp_path, name):
    material = load_material(name, Library(use_env=False))
    if material.model == "layered":
        pytest.skip("layered presets round-trip as maps (test_baked_maps_come_back_as_paths)")
    out = tmp_path / "rt.usda"
    export_usd([source_from_params(name, material.model, material.params)], out)
    (found,) = import_usd(out)
    assert found.model == material.model
    params_type = type(material.params)
    got = effective(canonical(params_type.parse(found.params)), material.model)
    want = effective(canonical(material.params), material.model)
    if material.model == "disney":  # every context is read back: everything expressible
        keys = set(DEFAULTS["disney"]) - UNEXPRESSIBLE - {"specular"}
    else:  # Pixar is read from its UsdPreviewSurface (PxrSurface weights do not invert)
        keys = (PIXAR_PREVIEW - {"ior", "normal_fresnel"}) | {"eta"}
    for k in sorted(keys):
        if isinstance(want[k], str | bool) or want[k] is None:
            assert got[k] == want[k], k
        else:
            np.testing.assert_allclose(got[k], want[k], rtol=2e-6, atol=2e-6, err_msg=k)


def test_baked_maps_come_back_as_paths(tmp_path):
    material = load_material("rusty_iron", Library(use_env=False))
    scratch = tmp_path / "scratch"
    scratch.mkdir()
    source = source_for(blend(material, 16), tmp_path / "tex", scratch=scratch, bake=True)
    export_usd([source], tmp_path / "r.usda", contexts=("universal",))
    (found,) = import_usd(tmp_path / "r.usda")
    assert set(found.maps) == set(source.maps) - {"specular"}  # universal reads F0 as ior
    for name, texture in found.maps.items():
        assert (
            Path(texture.texture).resolve()
            == (tmp_path / "tex" / source.maps[name].path.name).resolve()
        )


def test_foreign_preview_surface_imports(tmp_path):
    """A UsdPreviewSurface written by another tool, with a texture on its roughness."""
    path = tmp_path / "foreign.usda"
    stage = Usd.Stage.CreateNew(str(path))
    material = UsdShade.Material.Define(stage, "/Looks/Ceramic")
    surface = UsdShade.Shader.Define(stage, "/Looks/Ceramic/Surface")
    surface.CreateIdAttr("UsdPreviewSurface")
    surface.CreateInput("diffuseColor", Sdf.ValueTypeNames.Color3f).Set((0.9, 0.85, 0.8))
    surface.CreateInput("ior", Sdf.ValueTypeNames.Float).Set(1.6)
    tex = UsdShade.Shader.Define(stage, "/Looks/Ceramic/Rough")
    tex.CreateIdAttr("UsdUVTexture")
    import OpenImageIO as oiio

    grey = oiio.ImageOutput.create(str(tmp_path / "rough.png"))  # one channel
    grey.open(str(tmp_path / "rough.png"), oiio.ImageSpec(2, 2, 1, oiio.UINT8))
    grey.write_image(np.full((2, 2, 1), 100, np.uint8))
    grey.close()
    tex.CreateInput("file", Sdf.ValueTypeNames.Asset).Set("./rough.png")
    out = tex.CreateOutput("r", Sdf.ValueTypeNames.Float)
    surface.CreateInput("roughness", Sdf.ValueTypeNames.Float).ConnectToSource(out)
    material.CreateSurfaceOutput().ConnectToSource(surface.ConnectableAPI(), "surface")
    stage.Save()
    (found,) = import_usd(path)
    assert found.name == "Ceramic"
    assert found.params["base_color"] == (0.9, 0.85, 0.8)
    assert found.params["ior"] == pytest.approx(1.6)  # a foreign file spells the F0 as IOR
    assert Path(found.maps["roughness"].texture).name == "rough.png"
    assert found.maps["roughness"].channel == 0  # `r` of a one-channel file: its channel


scale = st.sampled_from([0.0, 1.0]) | st.floats(0.0, 2.0)
pixar = st.fixed_dictionaries(
    {
        "surface_color": st.tuples(unit, unit, unit),
        "metallic": edge_unit,
        "roughness": edge_unit,
        "clear": edge_unit,
        "back": edge_unit,
        "grazing_fresnel": edge_unit,
        "specular_scale": scale,
        "reflection_t_scale": scale,
    },
    optional={"ior": st.floats(1.0, 3.0), "normal_fresnel": st.floats(0.0, 19.0)},
).filter(lambda d: not ("ior" in d and "normal_fresnel" in d))


@pytest.mark.slow
@settings(
    max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(data=pixar)
def test_pixar_universal_round_trip(tmp_path, data):
    from lookdev.materials.pixar import PixarParams

    params = PixarParams(**data)
    out = tmp_path / "px.usda"
    source = source_from_params("px", "pixar", params)
    result = export_usd([source], out)
    (found,) = import_usd(out)
    assert found.model == "pixar" and found.contexts == ["universal", "mtlx"]
    got = effective(canonical(PixarParams.parse(found.params)), "pixar")
    want = effective(canonical(params), "pixar")
    keys = PIXAR_PREVIEW - {"ior"}
    if not source.lobes["transmission"]:
        # `clear` travels as OpenPBR's transmission_weight, written only while a
        # transmitted lobe lives (the preview surface keeps opacity 1); otherwise its
        # darkening of the diffuse is a loss the universal note names.
        keys = keys - {"clear"}
        if np.float32(params.clear) > 0:  # what the model sees (a float32 of 1e-235 is 0)
            assert "clear=" in result.losses["px"]["universal"]
    for k in keys:
        np.testing.assert_allclose(got[k], want[k], rtol=2e-6, atol=2e-6, err_msg=k)
    np.testing.assert_allclose(got["eta"], want["eta"], rtol=2e-6, err_msg="eta")
    assert set(found.params) <= PIXAR_PREVIEW | PIXAR_OPENPBR


def test_pixar_ri_surface_carries_smits_weights(tmp_path):
    """PxrSurface face/edge colours are Smits' normal/grazing weights; dead lobes are off."""
    from lookdev.materials.pixar import PixarParams, lobe_weights

    def surface_of(params: PixarParams):
        out = tmp_path / f"px{params.metallic}.usda"  # a layer stays open while its stage lives
        export_usd([source_from_params("px", "pixar", params)], out, contexts=("ri",))
        stage = Usd.Stage.Open(str(out))
        return stage, stage.GetPrimAtPath("/Materials/px/ri_surface")

    params = PixarParams(surface_color=(0.9, 0.6, 0.3), roughness=0.3, clear=0.5)
    stage, surface = surface_of(params)
    w = lobe_weights(params)
    pairs = (
        ("specularFaceColor", "reflN"),
        ("specularEdgeColor", "reflG"),
        ("roughSpecularFaceColor", "specN"),
        ("roughSpecularEdgeColor", "specG"),
        ("refractionColor", "reflTN"),
    )
    for name, key in pairs:
        np.testing.assert_allclose(surface.GetAttribute(f"inputs:{name}").Get(), w[key], rtol=1e-6)
    assert surface.GetAttribute("inputs:refractionGain").Get() == 1.0
    # A mirror metal (Smits: roughness 0 puts all the highlight in the reflection lobe,
    # and the diffuse's Mix[…, 1, rough] leaves it nothing).
    stage, surface = surface_of(PixarParams(surface_color=0.9, metallic=1.0, roughness=0.0))
    assert surface.GetAttribute("inputs:diffuseGain").Get() == 0.0
    assert not surface.GetAttribute("inputs:roughSpecularFaceColor").IsAuthored()
    assert not surface.GetAttribute("inputs:refractionGain").IsAuthored()


def test_foreign_specular_workflow_reads_f0_as_specular(tmp_path):
    """Burley §5.4: F0 = 0.08 × specular; a grey specularColor 0.04 is specular 0.5."""
    path = tmp_path / "spec.usda"
    stage = Usd.Stage.CreateNew(str(path))
    material = UsdShade.Material.Define(stage, "/Looks/Tile")
    surface = UsdShade.Shader.Define(stage, "/Looks/Tile/Surface")
    surface.CreateIdAttr("UsdPreviewSurface")
    surface.CreateInput("useSpecularWorkflow", Sdf.ValueTypeNames.Int).Set(1)
    surface.CreateInput("specularColor", Sdf.ValueTypeNames.Color3f).Set((0.04, 0.04, 0.04))
    surface.CreateInput("metallic", Sdf.ValueTypeNames.Float).Set(1.0)  # ignored by the workflow
    material.CreateSurfaceOutput().ConnectToSource(surface.ConnectableAPI(), "surface")
    stage.Save()
    (found,) = import_usd(path)
    assert "metallic" not in found.params
    got = DisneyParams.parse(found.params)
    assert got.effective_specular == pytest.approx(0.5, rel=1e-6)


def test_specular_gamma_round_trips_through_custom_data(tmp_path):
    # No target has GTR's γ: each surface gets the GGX roughness of the same highlight
    # width, the loss is named, and the import gives back γ and the authored roughness.
    params = DisneyParams(metallic=1.0, roughness=0.4, specular_gamma=3.0)
    out = tmp_path / "gamma.usda"
    export_usd([source_from_params("m", "disney", params)], out)
    (found,) = import_usd(out)
    assert found.params == {"metallic": 1.0, "roughness": 0.4, "specular_gamma": 3.0}
    assert all("specular_gamma=3" in line and "GGX roughness" in line for line in found.loss)
    stage = Usd.Stage.Open(str(out))
    for node, name in (
        ("preview_surface", "roughness"),
        ("mtlx_surface", "specular_roughness"),  # OpenPBR Surface
        ("ri_surface", "roughness"),
    ):
        written = stage.GetPrimAtPath(f"/Materials/m/{node}").GetAttribute(f"inputs:{name}")
        assert written.Get() == pytest.approx(0.35677, abs=1e-4)  # lookdev.materials.highlight


def test_exact_sheen_lambda_names_its_loss_and_round_trips(tmp_path):
    # MaterialX's sheen_bsdf (conty_kulla) has the fitted Λ: the exact mode is a named,
    # measured loss in every context, and customData carries it back with its sheen.
    values = {
        "sheen": 1.0,
        "sheen_model": "conty_kulla",
        "sheen_roughness": 0.03,
        "sheen_lambda": "exact",
    }
    out = tmp_path / "exact.usda"
    export_usd([source_from_params("m", "disney", DisneyParams(**values))], out)
    (found,) = import_usd(out)
    assert {k: found.params[k] for k in values} == pytest.approx(values)
    for line in found.loss:
        assert "sheen_lambda=exact" in line and "directional albedo differs by up to" in line
    # The fit mode exports as before: nothing carried, no sheen_lambda in the notes.
    fit = tmp_path / "fit.usda"
    export_usd(
        [source_from_params("m", "disney", DisneyParams(**{**values, "sheen_lambda": "fit"}))], fit
    )
    (found,) = import_usd(fit)
    assert "sheen_lambda" not in found.params
    assert not any("sheen_lambda" in line for line in found.loss)


def test_energy_compensation_is_a_named_loss_carried_through_custom_data(tmp_path):
    # No target has the switch (MaterialX's pbrlib has energy_compensation on the
    # Oren-Nayar diffuse only): every context names the loss, customData carries it back.
    params = DisneyParams(metallic=1.0, roughness=0.6, energy_compensation=True)
    out = tmp_path / "ms.usda"
    export_usd([source_from_params("m", "disney", params)], out, mtlx_surface="disney")
    (found,) = import_usd(out)
    assert found.params == {"metallic": 1.0, "roughness": 0.6, "energy_compensation": True}
    assert len(found.loss) == 3
    assert all("energy_compensation=True" in line for line in found.loss)
    off = tmp_path / "off.usda"
    plain_params = params.replace(energy_compensation=False)
    export_usd([source_from_params("m", "disney", plain_params)], off, mtlx_surface="disney")
    (plain,) = import_usd(off)
    assert "energy_compensation" not in plain.params and not plain.loss
    # OpenPBR's lobes always keep the multiple-scattering energy: the switch on is what
    # it expresses, the switch off is its named loss
    export_usd([source_from_params("m", "disney", params)], out)
    (found,) = import_usd(out)
    assert [line.split(":")[0] for line in found.loss] == ["universal", "ri"]
    export_usd([source_from_params("m", "disney", plain_params)], off)
    (plain,) = import_usd(off)
    assert len(plain.loss) == 1 and "multiple_scattering" not in plain.loss[0]
    assert plain.loss[0].startswith("mtlx:") and "single-scattering" in plain.loss[0]
