"""The ``mtlx`` context as OpenPBR Surface (pipeline/export/usd/mtlx_openpbr.py): every
built-in preset, layered ones included, validates against MaterialX's own libraries and
generates shader code with every generator the installed MaterialX package has (GLSL,
ESSL, OSL, MDL, MSL, Slang); ``--mtlx-surface disney`` keeps ND_disney_principled; the
mapping's edges and its named losses."""

from __future__ import annotations

import pytest

pytest.importorskip("MaterialX")
import MaterialX as mx  # noqa: E402
from MaterialX import PyMaterialXGenShader as gen  # noqa: E402

from lookdev.materials.params import DisneyParams  # noqa: E402
from lookdev.pipeline import api  # noqa: E402
from lookdev.pipeline.export.usd.lobes import active_lobes, canonical  # noqa: E402
from lookdev.pipeline.export.usd.openpbr_map import (  # noqa: E402
    LOSSES,
    anisotropic_roughness,
    coat_roughness,
    losses_of,
    openpbr_values,
)


def _generators():
    out = {}
    for module, names in (
        ("PyMaterialXGenGlsl", ("GlslShaderGenerator", "EsslShaderGenerator")),
        ("PyMaterialXGenOsl", ("OslShaderGenerator",)),
        ("PyMaterialXGenMdl", ("MdlShaderGenerator",)),
        ("PyMaterialXGenMsl", ("MslShaderGenerator",)),
        ("PyMaterialXGenSlang", ("SlangShaderGenerator",)),
    ):
        try:
            mod = __import__(f"MaterialX.{module}", fromlist=["x"])
        except ImportError:
            continue
        for name in names:
            if hasattr(mod, name):
                out[name] = getattr(mod, name)
    return out


GENERATORS = _generators()


def test_every_preset_is_openpbr_and_validates(exported):
    result, doc = exported
    valid, message = doc.validate()
    assert valid, message
    categories = {
        shader.getCategory()
        for material in doc.getMaterialNodes()
        for shader in mx.getShaderNodes(material)
    }
    # every material's surface, layered Pixar included
    assert categories == {"open_pbr_surface"}
    # layered presets are written as live mix chains feeding the surface
    assert any(n.getCategory() == "mix" for n in doc.getNodes())


def test_generators_present():
    assert {"GlslShaderGenerator", "OslShaderGenerator"} <= set(GENERATORS)


@pytest.mark.slow
@pytest.mark.parametrize("generator", sorted(GENERATORS))
def test_every_exported_material_generates_code(exported, generator):
    _, doc = exported
    shader_gen = GENERATORS[generator].create()
    context = gen.GenContext(shader_gen)
    context.registerSourceCodeSearchPath(mx.getDefaultDataSearchPath())
    failed, done = [], 0
    for material in doc.getMaterialNodes():
        for shader in mx.getShaderNodes(material):
            try:
                code = shader_gen.generate(shader.getName(), shader, context)
                assert code.getSourceCode(gen.PIXEL_STAGE)
                done += 1
            except Exception as exc:  # MaterialX raises its own types; name the material
                failed.append(f"{material.getName()}: {str(exc).splitlines()[0]}")
    assert not failed, failed
    assert done > 60


def test_disney_surface_kept_when_asked(tmp_path):
    api.export_usd("gold", tmp_path / "g.usda", mtlx=tmp_path / "g.mtlx", mtlx_surface="disney")
    assert "<disney_principled" in (tmp_path / "g.mtlx").read_text()


def test_unknown_surface_is_one_clear_error(tmp_path):
    from lookdev.materials.errors import LookdevError

    with pytest.raises(LookdevError, match="mtlx surface 'arnold'"):
        api.export_usd("gold", tmp_path / "g.usda", mtlx_surface="arnold")
    assert not (tmp_path / "g.usda").exists()


def _values(**kw):
    values = canonical(DisneyParams(**kw))
    return values, active_lobes(values)


def test_mapping_edges():
    v, lobes = _values(metallic=1.0, roughness=0.0)
    out = openpbr_values(v, lobes)
    assert out["base_metalness"] == 1.0 and out["specular_roughness"] == 0.0
    assert out["specular_color"] == (1.0, 1.0, 1.0)
    v, lobes = _values(clearcoat=1.0, clearcoat_gloss=1.0)
    out = openpbr_values(v, lobes)
    assert out["coat_weight"] == pytest.approx(0.25) and out["coat_darkening"] == 0.0
    v, lobes = _values(sheen=10.0)
    assert openpbr_values(v, lobes)["fuzz_weight"] == 1.0
    # black base: Burley's tint is white, not NaN
    v, lobes = _values(base_color=(0.0, 0.0, 0.0), specular_tint=1.0)
    assert openpbr_values(v, lobes)["specular_color"] == (1.0, 1.0, 1.0)


def test_coat_roughness_is_monotone_and_anisotropic_roughness_capped():
    assert coat_roughness(1.0) < coat_roughness(0.5) < coat_roughness(0.0) <= 1.0
    assert anisotropic_roughness(0.5, 0.0) == pytest.approx(0.5)
    assert anisotropic_roughness(0.5, 1.0) > 0.5
    assert anisotropic_roughness(1.0, 1.0) == 1.0


def test_each_named_loss_applies_where_its_term_is_live():
    names = {loss.name for loss in LOSSES}
    issue = "specular specular_tint metallic anisotropic clearcoat sheen spec_trans diff_trans"
    assert set(issue.split()) | {"scatter_distance", "flatness", "subsurface"} <= names
    v, lobes = _values(clearcoat=0.5, sheen=0.5, anisotropic=0.5)
    got = {loss.name for loss in losses_of(v, lobes)}
    assert {"clearcoat", "sheen", "anisotropic"} <= got
    v, lobes = _values(metallic=1.0)
    assert "diffuse" not in {loss.name for loss in losses_of(v, lobes)}


def test_term_losses_measure_every_case():
    from lookdev.pipeline.analysis.openpbr_losses import CASES, term_losses

    rows = {r["case"]: r for r in term_losses(samples=2048)}
    assert set(rows) == set(CASES)
    assert rows["spec_trans"]["rms"] < 0.02  # glass carries over
    assert rows["metallic, roughness 0.1"]["rms"] < 0.02  # F82 with a white tint is Schlick
    assert rows["subsurface (2012)"]["rms"] > rows["diffuse+specular (base)"]["rms"]
