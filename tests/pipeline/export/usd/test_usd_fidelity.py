"""UsdPreviewSurface measured (issue 15 §3) and the mappings it decided: the spec's BRDF,
the --report table, OpenPBR's roughness for Pixar presets, the metallic workflow of
layered Pixar presets, subsurface units, frosted glass and the tangent-space normal."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("pxr")
from pxr import Usd  # noqa: E402

import lookdev  # noqa: E402
from lookdev.materials.arrays import NumpyOps  # noqa: E402
from lookdev.materials.bsdf import evaluate  # noqa: E402
from lookdev.materials.fresnel import ior_to_f0  # noqa: E402
from lookdev.materials.params import DisneyParams  # noqa: E402
from lookdev.materials.preview_surface import MODEL, PreviewParams  # noqa: E402
from lookdev.pipeline import api  # noqa: E402
from lookdev.pipeline.analysis.albedo import albedo_monte_carlo  # noqa: E402
from lookdev.pipeline.blend import BlendedMaterial  # noqa: E402
from lookdev.pipeline.export.usd.authoring import DCC_LOSS, FULLY, dcc_loss_note  # noqa: E402
from lookdev.pipeline.export.usd.fidelity import Fidelity  # noqa: E402
from lookdev.pipeline.export.usd.network import Connection, MaterialSpec, Network  # noqa: E402
from lookdev.pipeline.export.usd.pixar import metallic_workflow  # noqa: E402


def _prepare(xp, params):
    """The prepared values as plain RGB (channel-first colours are (3, 1))."""
    pr = MODEL.prepare(xp, params)
    arrays = {f.name: getattr(pr, f.name) for f in dataclasses.fields(pr)}
    return dataclasses.replace(
        pr, **{k: np.ravel(v) for k, v in arrays.items() if isinstance(v, np.ndarray)}
    )


def test_preview_brdf_follows_the_spec_at_its_edges():
    """Spec 2.5: metallic 1 → F0 = F90 = albedo, no diffuse; metallic 0 → F0 from ior,
    F90 white; a white furnace keeps a white rough dielectric near 1 at normal view."""
    gold = PreviewParams(diffuse_color=(1.0, 0.78, 0.34), metallic=1.0, roughness=0.5)
    p = _prepare(NumpyOps(), gold)
    np.testing.assert_allclose(p.f0, [1.0, 0.78, 0.34])
    np.testing.assert_allclose(p.f90, [1.0, 0.78, 0.34])
    np.testing.assert_allclose(p.diffuse, 0.0)
    plastic = PreviewParams(diffuse_color=(0.5, 0.5, 0.5), metallic=0.0, ior=1.5)
    p = _prepare(NumpyOps(), plastic)
    np.testing.assert_allclose(p.f0, ior_to_f0(1.5))
    np.testing.assert_allclose(p.f90, 1.0)
    white = PreviewParams(diffuse_color=(1.0, 1.0, 1.0), roughness=0.5)
    a = albedo_monte_carlo(MODEL, white, [0.0], n_samples=20000)
    assert a.albedo[0, 0] == pytest.approx(1.0, abs=0.02)
    # Below the horizon nothing; reciprocal in wi and wo.
    wi, wo = np.array([0.3, 0.1, 0.9]), np.array([-0.5, 0.2, 0.8])
    wi, wo = wi / np.linalg.norm(wi), wo / np.linalg.norm(wo)
    np.testing.assert_allclose(evaluate(MODEL, white, wi, wo), evaluate(MODEL, white, wo, wi))
    assert not evaluate(MODEL, white, -wi, wo).any()


def test_preview_sampler_agrees_with_its_density():
    """E(θ) by the sampler equals E(θ) by quadrature of eval for a rough lobe (the
    sampler's weight f·cos/pdf is consistent with pdf)."""
    from lookdev.pipeline.analysis.albedo import albedo_quadrature

    p = PreviewParams(
        diffuse_color=(0.8, 0.2, 0.1), roughness=0.6, clearcoat=0.5, clearcoat_roughness=0.4
    )
    th = np.radians([0.0, 45.0, 70.0])
    mc = albedo_monte_carlo(MODEL, p, th, n_samples=40000)
    quad = albedo_quadrature(MODEL, p, th, n_mu=96, n_phi=96)
    np.testing.assert_allclose(mc.albedo, quad.albedo, atol=5 * mc.stderr.max() + 2e-3)


def test_export_report_prints_and_carries_the_fidelity(cli, tmp_path):
    out = tmp_path / "r.usda"
    result = cli(
        "export", "usd", "gold", "plastic_glossy", "glass_clear", "-o", str(out), "--report"
    )
    assert result.code == 0, result.err
    assert "Each context vs the material" in result.out
    summary = json.loads(
        cli("export", "usd", "gold", "glass_clear", "-o", str(out), "--report", "--json").out
    )
    rows = {r["material"]: r for r in summary["fidelity"]}
    assert len(rows["gold"]["albedo_source"]) == len(rows["gold"]["angles_deg"]) == 6
    # Gold's metallic preview is close to Burley's metal at normal view; glass, kept
    # opaque in the preview, is far (its transmission is the named loss).
    assert abs(rows["gold"]["albedo_preview"][0][0] - rows["gold"]["albedo_source"][0][0]) < 0.05
    assert rows["glass_clear"]["rms"] > 3 * rows["gold"]["rms"]
    # The size the loss note in the file states is the report's own.
    stage = Usd.Stage.Open(str(out))
    note = stage.GetPrimAtPath("/Materials/glass_clear").GetAttribute(DCC_LOSS).Get()
    assert note.endswith(f"measured against the material: {rows['glass_clear']['size']}")
    assert rows["glass_clear"]["albedo_change"] > 0.5 and not rows["glass_clear"]["fully"]


def _fidelity(albedo_change: float, highlight_ratio: float) -> Fidelity:
    flat = [[0.5] * 3] * 6
    return Fidelity("m", flat, flat, 0.0, 0.0, "0° R", highlight_ratio, albedo_change=albedo_change)


@pytest.mark.parametrize(
    ("change", "ratio", "fully"),
    [(0.0, 1.0, True), (-0.009, 1.049, True), (0.011, 1.0, False), (0.0, 0.94, False)],
)
def test_fully_means_within_what_the_measurement_resolves(change, ratio, fully):
    assert _fidelity(change, ratio).fully is fully


def test_the_size_in_words_signs_each_change_with_a_minus_sign():
    assert _fidelity(-0.746, 1.09).size() == "albedo \u221274.6 %, highlight +9 %, albedo RMS 0.00"
    assert _fidelity(0.0, 1.0).size() == "albedo 0.0 %, highlight 0 %, albedo RMS 0.00"


def test_a_note_says_fully_only_when_nothing_is_named_and_the_figures_are_small():
    def note(size):
        return dcc_loss_note(
            MaterialSpec("m", [Network("universal", Connection("s", "surface"), [])], {}, size)
        )

    assert note(None) == FULLY
    assert note(_fidelity(0.002, 1.01)).startswith(f"{FULLY} (measured against the material:")
    assert note(_fidelity(-0.05, 0.98)).startswith(
        "UsdPreviewSurface's BRDF is not the material's;"
    )


def test_openpbr_takes_the_energy_weighted_highlight_roughness(tmp_path):
    out = tmp_path / "p.usda"
    api.export_usd(["pixar_gold", "pixar_clear_glass"], out, ("mtlx",))
    stage = Usd.Stage.Open(str(out))

    def rough(name):
        return stage.GetAttributeAtPath(
            f"/Materials/{name}/mtlx_surface.inputs:specular_roughness"
        ).Get()

    assert rough("pixar_clear_glass") == 0.0  # was 1.0: fully frosted
    # pixar_gold (Smits roughness 0.15): broad lobe 0.63, sharp 0.156; two thirds of its
    # highlight energy is in the broad lobe, so the weighted roughness is 0.47 (was 0.63).
    assert rough("pixar_gold") == pytest.approx(0.4676, abs=1e-3)


def test_layered_pixar_metal_keeps_its_reflectance_in_the_metallic_workflow():
    """Before: specularColor = F0, which DCC importers read as a tint on their own F0
    0.04 (a 25x loss on a metal); now the preview's own F0 equals Smits' F0."""
    f0 = np.array([0.9, 0.7, 0.3])
    base, m = metallic_workflow(np.zeros(3), f0, 1.5)
    prepared = _prepare(
        NumpyOps(),
        PreviewParams(diffuse_color=tuple(base), metallic=float(m), ior=1.5),
    )
    seen_after = np.asarray(prepared.f0)
    seen_before = 0.04 * f0  # specular tint on a DCC's dielectric F0
    np.testing.assert_allclose(seen_after, f0, rtol=1e-6)
    assert (seen_after / seen_before).min() == pytest.approx(25.0)
    # A dielectric region stays a dielectric with its diffuse.
    base, m = metallic_workflow(np.array([0.5, 0.1, 0.1]), np.full(3, 0.04), 1.5)
    assert float(m) == 0.0 and base[0] * (1 - 0.04) == pytest.approx(0.5)


def test_subsurface_radius_is_in_scene_units(tmp_path):
    out = tmp_path / "s.usda"
    # Burley 2012's blend: no distance
    blend_2012 = BlendedMaterial.of_params(DisneyParams(subsurface=0.5), name="blend_2012")
    result = api.export_usd(
        ["marble", blend_2012], out, ("mtlx",), meters_per_unit=0.01, mtlx_surface="disney"
    )
    stage = Usd.Stage.Open(str(out))
    assert stage.GetMetadata("metersPerUnit") == 0.01

    def radius(name):
        path = f"/Materials/{name}/mtlx_surface.inputs:subsurfaceDistance"
        return tuple(stage.GetAttributeAtPath(path).Get())

    # marble's distance (Jensen 2001, ≈ 0.42 mm) in centimetres, per channel (× its scale)
    assert radius("marble") == pytest.approx(_radius_cm("marble"), rel=1e-6)
    assert radius("blend_2012") == pytest.approx((0.1,) * 3)  # 1 mm, named as a loss
    assert "1 mm" in result.losses["blend_2012"]["mtlx"]
    assert "1 mm" not in result.losses["marble"].get("mtlx", "")


def test_frosted_glass_is_a_named_loss_in_materialx(tmp_path):
    result = api.export_usd(
        ["glass_frosted", "glass_clear"], tmp_path / "g.usda", ("mtlx",), mtlx_surface="disney"
    )
    assert "renders clear" in result.losses["glass_frosted"]["mtlx"]
    # OpenPBR refracts with specular_roughness: nothing to lose there
    openpbr = api.export_usd(["glass_frosted"], tmp_path / "o.usda", ("mtlx",))
    assert "renders clear" not in openpbr.losses["glass_frosted"]["mtlx"]
    assert "renders clear" not in result.losses["glass_clear"].get("mtlx", "")


def test_layered_pixar_mtlx_is_openpbr_with_a_world_space_normal():
    from lookdev.pipeline.export.usd import mtlx
    from lookdev.pipeline.export.usd.lobes import DEFAULTS
    from lookdev.pipeline.export.usd.network import Connection, Image, Network, Node, Source
    from lookdev.pipeline.export.usd.reader import model_of

    values = {**DEFAULTS["pixar_weights"], "preview_base": (0.5, 0.2, 0.1)}
    source = Source("s", "pixar_weights", values, normal_map=Image(Path("n.exr")))
    net = mtlx.build(source)
    assert net.nodes[0].id == "ND_open_pbr_surface_surfaceshader"
    assert net.nodes[0].custom[mtlx.BLEND_KEY] == "pixar_weights"
    kind, conn = net.nodes[0].inputs["geometry_normal"]
    ids = {n.name: n.id for n in net.nodes}
    assert ids[conn.node] == "ND_normalmap_float"  # OpenPBR takes the normal in world space
    assert "composited" in net.nodes[0].custom["loss"]
    ri = Network("ri", Connection("ri_surface", "out"), [Node("ri_surface", "PxrSurface", {})])
    assert model_of([net, ri]) == "pixar_weights"
    net.nodes[0].custom.pop(mtlx.BLEND_KEY)
    assert model_of([net, ri]) == "pixar"


def test_the_universal_proof_renders_the_preview_surface_s_own_brdf():
    from lookdev.library import Library, load_material
    from lookdev.pipeline.blend import blend
    from lookdev.pipeline.export.usd.fidelity import preview_hub

    lib = Library(use_env=False)
    velvet = preview_hub(blend(load_material("velvet", lib), 8))
    assert velvet.name == "velvet-universal"
    assert velvet.bsdf_model.name == "usd_preview_surface"  # not Burley's with sheen off
    rust = preview_hub(blend(load_material("rusty_iron", lib), 16))
    assert set(rust.maps) == {"diffuse_color", "metallic", "roughness"}
    assert rust.maps["diffuse_color"].shape == (16, 16, 3)
    gold = preview_hub(blend(load_material("pixar_gold", lib), 8))
    assert (gold.params.metallic, gold.params.roughness) == (1.0, 0.15)
    assert gold.live_lobes == ("specular",)  # a pure metal: no diffuse traced


@pytest.mark.slow
def test_proof_context_universal_renders_both(cli, tmp_path):
    args = ("proof", "gold", "--context", "universal", "--ibl", "studio", "--frames", "1")
    result = cli(*args, "--light-frames", "0", "--spp", "2", "--resolution", "16", "8",
                 "-o", str(tmp_path), "--json")  # fmt: skip
    assert result.code == 0, result.err
    names = {p["material"] for p in json.loads(result.out)["proofs"]}
    assert names == {"gold", "gold-universal"}


def _radius_cm(name: str) -> list[float]:
    params = lookdev.load(name).params
    return [100.0 * params.scatter_distance * s for s in params.scatter_distance_scale]


def _inputs(stage, name, shader):
    prim = stage.GetPrimAtPath(f"/Materials/{name}/{shader}")
    return {a.GetName().split(":", 1)[1]: a.Get() for a in prim.GetAttributes()
            if a.GetName().startswith("inputs:")}  # fmt: skip


def test_a_solid_with_a_distance_exports_a_scattering_subsurface(tmp_path):
    """skin has subsurface 0 and a distance: the model sends its whole diffuse into the
    interior, so each Disney target gets weight 1, the per-channel radius in scene
    units, and (RenderMan) the base colour as its subsurface colour."""
    out = tmp_path / "s.usda"
    result = api.export_usd(
        ["skin"], out, ("universal", "mtlx", "ri"), meters_per_unit=0.01, mtlx_surface="disney"
    )
    stage = Usd.Stage.Open(str(out))
    radius = _radius_cm("skin")  # ≈ 0.86 mm × (1, 0.49, 0.27), in centimetres
    mtlx = _inputs(stage, "skin", "mtlx_surface")
    assert mtlx["subsurface"] == 1.0
    assert tuple(mtlx["subsurfaceDistance"]) == pytest.approx(radius, rel=1e-6)
    ri = _inputs(stage, "skin", "ri_surface")
    assert ri["subsurface"] == 1.0
    assert tuple(ri["scatterDistances"]) == pytest.approx(radius, rel=1e-6)
    skin = lookdev.load("skin").params
    assert tuple(ri["subsurfaceColor"]) == pytest.approx(skin.base_color, rel=1e-6)
    # The per-channel distance is expressed: no loss names it, but the preview has none.
    for context in ("mtlx", "ri"):
        assert "scatter_distance" not in result.losses["skin"].get(context, "")
    assert "has no subsurface" in result.losses["skin"]["universal"]
    assert "subsurface" not in _inputs(stage, "skin", "preview_surface")


@pytest.mark.parametrize("contexts", [("mtlx",), ("ri",), ("universal", "mtlx", "ri")])
def test_the_per_channel_distance_comes_back(tmp_path, contexts):
    from lookdev.pipeline.export.usd.network import source_from_params
    from lookdev.pipeline.export.usd.reader import import_usd
    from lookdev.pipeline.export.usd.writer import export_usd

    params = DisneyParams(
        base_color=(0.6, 0.4, 0.2),
        subsurface=0.3,  # ignored by a solid with a distance: not read back
        scatter_distance=0.002,
        scatter_distance_scale=(0.5, 1.0, 0.25),
    )
    out = tmp_path / "rt.usda"
    export_usd(
        [source_from_params("m", "disney", params)], out, contexts=contexts, meters_per_unit=0.01
    )
    (found,) = import_usd(out)
    assert found.params["scatter_distance"] == pytest.approx(0.002, rel=1e-6)
    assert found.params["scatter_distance_scale"] == pytest.approx((0.5, 1.0, 0.25), rel=1e-6)
    assert "subsurface" not in found.params


def test_thin_and_distance_free_subsurface_keep_the_2012_weight(tmp_path):
    out = tmp_path / "s.usda"
    thin = BlendedMaterial.of_params(
        DisneyParams(subsurface=0.4, thin=True, scatter_distance=0.01), name="thin"
    )
    api.export_usd([thin], out, ("mtlx", "ri"), mtlx_surface="disney")
    stage = Usd.Stage.Open(str(out))
    assert _inputs(stage, "thin", "mtlx_surface")["subsurface"] == pytest.approx(0.4)
    assert _inputs(stage, "thin", "ri_surface")["subsurface"] == pytest.approx(0.4)
