"""The arrangement of the universal network: its constants on the surface (what
Blender reads), the Material's interface driving the MaterialX and RenderMan networks
(what Houdini, Katana and usdview edit), checked with usd-core's own resolution."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("pxr")

from pxr import Sdf, Usd, UsdShade  # noqa: E402

from lookdev.pipeline import api  # noqa: E402
from lookdev.pipeline.export.usd.geometry import uv_sphere  # noqa: E402


def _producer(stage, shader: str, name: str):
    inp = UsdShade.Shader(stage.GetPrimAtPath(shader)).GetInput(name)
    (attr,) = inp.GetValueProducingAttributes()
    return attr


def test_surface_constants_are_unconnected_and_the_interface_drives_the_others(tmp_path):
    out = tmp_path / "gold.usda"
    api.export_usd(["gold"], out)
    stage = Usd.Stage.Open(str(out))
    preview = UsdShade.Shader(stage.GetPrimAtPath("/Materials/gold/preview_surface"))
    for name in ("diffuseColor", "metallic", "roughness"):
        assert not preview.GetInput(name).HasConnectedSource(), name
    assert _producer(stage, "/Materials/gold/preview_surface", "roughness").Get() == (
        pytest.approx(0.2)
    )
    # A DCC's override of the interface reaches MaterialX and RenderMan.
    UsdShade.Material(stage.GetPrimAtPath("/Materials/gold")).GetInput("roughness").Set(0.35)
    # (OpenPBR, the default mtlx surface, names it specular_roughness)
    for shader, name in (
        ("/Materials/gold/mtlx_surface", "specular_roughness"),
        ("/Materials/gold/ri_surface", "roughness"),
    ):
        attr = _producer(stage, shader, name)
        assert attr.GetPath() == Sdf.Path("/Materials/gold.inputs:roughness")
        assert attr.Get() == pytest.approx(0.35)


def test_a_universal_only_file_has_no_interface_nothing_reads(tmp_path):
    out = tmp_path / "gold.usda"
    api.export_usd(["gold"], out, ("universal",))
    stage = Usd.Stage.Open(str(out))
    material = UsdShade.Material(stage.GetPrimAtPath("/Materials/gold"))
    assert material.GetInputs() == []


def test_preview_geometry_is_meshes_bound_to_their_materials(tmp_path):
    out = tmp_path / "lib.usda"
    api.export_usd(["gold", "velvet"], out, ("universal",), preview_geometry=True)
    stage = Usd.Stage.Open(str(out))
    for name in ("gold", "velvet"):
        prim = stage.GetPrimAtPath(f"/Materials/Geometry/{name}_sphere")
        assert prim.GetTypeName() == "Mesh"
        bound = UsdShade.MaterialBindingAPI(prim).ComputeBoundMaterial()[0]
        assert bound.GetPath() == f"/Materials/{name}"
        assert len(prim.GetAttribute("points").Get()) == len(uv_sphere().points)


@pytest.mark.parametrize(("rings", "segments"), [(2, 3), (5, 7), (32, 64)])
def test_sphere_faces_point_outwards_and_st_covers_the_square(rings, segments):
    m = uv_sphere(rings, segments)
    start = np.concatenate([[0], np.cumsum(m.counts)[:-1]])
    for s, n in zip(start, m.counts, strict=True):
        a, b, c = m.points[m.indices[s : s + 3]]
        centre = m.points[m.indices[s : s + n]].mean(axis=0)
        assert np.dot(np.cross(b - a, c - b), centre) > 0.0
    assert m.st.min() == 0.0 and m.st.max() == 1.0
    assert np.allclose(np.linalg.norm(m.normals, axis=1), 1.0)


@pytest.mark.parametrize(("rings", "segments"), [(1, 8), (4, 2)])
def test_a_sphere_too_coarse_is_refused(rings, segments):
    with pytest.raises(ValueError, match="rings"):
        uv_sphere(rings, segments)
