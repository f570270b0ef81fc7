"""An asset's own mesh in the proof (--geometry), height as bump, the example asset."""

from __future__ import annotations

import hashlib
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from lookdev.pipeline.blend.result import BlendedMaterial
from lookdev.pipeline.proof.geometry import GeometryError, load_mesh, placed, proof_mesh
from lookdev.pipeline.proof.shaderball import CUP_CENTER

ROOT = Path(__file__).resolve().parents[3]
SCRIPT = ROOT / "scripts" / "make_example_asset.py"


@pytest.fixture(scope="module")
def asset(tmp_path_factory):
    folder = tmp_path_factory.mktemp("asset")
    subprocess.run([sys.executable, str(SCRIPT), str(folder)], check=True, capture_output=True)
    return folder


@pytest.mark.slow
def test_example_asset_is_small_deterministic_and_udim(asset, tmp_path):
    files = sorted(p.name for p in asset.iterdir())
    assert "pebble.obj" in files and "pebble.toml" in files
    tiles = {name.split(".")[1] for name in files if name.endswith(".png")}
    assert tiles == {"1001", "1002", "1011", "1012"}
    assert sum(p.stat().st_size for p in asset.iterdir()) < 400_000
    subprocess.run([sys.executable, str(SCRIPT), str(tmp_path)], check=True, capture_output=True)

    def digest(folder):
        return {p.name: hashlib.sha256(p.read_bytes()).hexdigest() for p in folder.iterdir()}

    assert digest(tmp_path) == digest(asset)
    text = (asset / "pebble.toml").read_text()
    assert 'textures = "pebble_<channel>.<UDIM>.png"' in text


@pytest.mark.slow
def test_obj_uvs_span_the_four_tiles_unflipped(asset):
    mesh = load_mesh(asset / "pebble.obj")
    assert mesh.uvs.min() >= 0.0 and 1.9 < mesh.uvs.max() < 2.0
    # the bottom ring (lowest y) has v = 0: OBJ's v is read as stored (v up)
    bottom = mesh.positions[:, 1] < mesh.positions[:, 1].min() + 1e-4
    assert np.allclose(mesh.uvs[bottom, 1], 0.0)


def test_placed_mesh_rests_on_the_ground_in_the_cups_slot(asset):
    mesh = placed(load_mesh(asset / "pebble.obj"))
    lo, hi = mesh.positions.min(axis=0), mesh.positions.max(axis=0)
    assert lo[1] == pytest.approx(0.0, abs=1e-6)
    assert float((hi - lo).max()) == pytest.approx(2.0, rel=1e-5)
    assert (lo[0] + hi[0]) / 2 == pytest.approx(CUP_CENTER[0], abs=1e-5)


def test_usd_mesh_with_face_varying_st_reads_like_the_obj(tmp_path):
    from pxr import Gf, Sdf, Usd, UsdGeom

    stage = Usd.Stage.CreateNew(str(tmp_path / "quad.usda"))
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.z)
    mesh = UsdGeom.Mesh.Define(stage, "/quad")
    mesh.GetPointsAttr().Set(
        [Gf.Vec3f(0, 0, 0), Gf.Vec3f(1, 0, 0), Gf.Vec3f(1, 1, 0), Gf.Vec3f(0, 1, 0)]
    )
    mesh.GetFaceVertexCountsAttr().Set([4])
    mesh.GetFaceVertexIndicesAttr().Set([0, 1, 2, 3])
    st = UsdGeom.PrimvarsAPI(mesh).CreatePrimvar(
        "st", Sdf.ValueTypeNames.TexCoord2fArray, UsdGeom.Tokens.faceVarying
    )
    st.Set([(0, 0), (2, 0), (2, 2), (0, 2)])
    stage.Save()
    m = load_mesh(tmp_path / "quad.usda")
    assert m.faces.shape == (2, 3)  # the quad fanned into two triangles
    assert m.uvs.max() == 2.0
    assert np.ptp(m.positions[:, 1]) == 0.0  # z up turned to y up: the quad lies flat
    assert np.ptp(m.positions[:, 2]) == 1.0


def test_bad_geometry_is_one_line(tmp_path, monkeypatch):
    monkeypatch.setenv("LOOKDEV_CACHE", str(tmp_path))
    with pytest.raises(GeometryError, match="does not exist"):
        proof_mesh(tmp_path / "none.obj")
    (tmp_path / "x.fbx").write_text("")
    with pytest.raises(GeometryError, match="unsupported geometry format"):
        proof_mesh(tmp_path / "x.fbx")
    (tmp_path / "noise.ply").write_bytes(b"not a ply")
    with pytest.raises(GeometryError) as err:
        proof_mesh(tmp_path / "noise.ply")
    assert "\n" not in str(err.value)


def test_height_map_wraps_the_bsdf_in_a_bumpmap_read_over_udim_tiles():
    import mitsuba as mi

    from lookdev.pipeline.export.mitsuba import bsdf_dict

    hub = BlendedMaterial("bumpy", "disney", (4, 4), {"roughness": 0.4})
    plain = bsdf_dict(hub)
    hub.height_map = np.zeros((8, 8), np.float32)
    hub.map_tiles = (2, 2)
    bump = bsdf_dict(hub)
    assert plain["type"] != "bumpmap"
    assert bump["type"] == "bumpmap" and bump["scale"] == 1.0
    assert bump["bsdf"]["type"] == plain["type"]
    to_uv = np.asarray(bump["height"]["to_uv"].matrix)
    assert to_uv[0, 0] == to_uv[1, 1] == 0.5  # UDIM u, v ∈ [0, 2) read into the map
    mi.load_dict(bump)  # Mitsuba takes it


@pytest.mark.slow
def test_proof_renders_an_asset_mesh_with_a_bump(tmp_path, monkeypatch, asset):
    monkeypatch.setenv("LOOKDEV_CACHE", str(tmp_path / "cache"))
    import lookdev

    (asset / "bumpy.toml").write_text(
        'name = "bumpy"\nmodel = "disney"\n'
        'height = { texture = "pebble_Height.<UDIM>.png", scale = 0.05 }\n'
        "[params]\nroughness = 0.3\n"
    )
    doc = lookdev.proof(
        [str(asset / "bumpy.toml")],
        ["studio"],
        tmp_path / "proofs",
        frames=1,
        light_frames=0,
        spp=4,
        resolution=(64, 32),
        ibl_width=64,
        geometry=asset / "pebble.obj",
    )
    (entry,) = doc["proofs"]
    assert entry["rendered"] == 1
    frame = tmp_path / "proofs" / "bumpy" / "studio" / "frame_000.exr"
    assert frame.is_file()
