"""An asset's own mesh in the proof (``lookdev proof --geometry FILE``).

The mesh takes the cup's place beside the shader ball, so a textured asset is judged on
the UVs it was painted on. PLY and OBJ are read by Mitsuba's own loaders; USD geometry
(every ``UsdGeom.Mesh`` of the stage, in world space, ``primvars:st`` vertex,
faceVarying or uniform, polygons fanned into triangles) by usd-core. The mesh is moved
and scaled into the cup's slot (centred on its axis, resting on the ground, at most
2 units tall and 2 wide, up axis y: a Z-up stage is turned) and written once as a PLY
into the cache, keyed by the file's bytes, so every worker of a batch loads the same
file and the turntable turns it about its own centre like the cup
(:func:`lookdev.pipeline.proof.shaderball.cup_to_world`). UVs are the mesh's own, in
lookdev's convention (v up, UDIM tiles at u, v ≥ 1); OBJ's v is not flipped.
"""

from __future__ import annotations

import hashlib
from pathlib import Path

import numpy as np

from lookdev.materials.errors import LookdevError

from .ibl import cache_dir
from .shaderball import CUP_CENTER, MeshData, write_ply

__all__ = ["GeometryError", "SUFFIXES", "load_mesh", "proof_mesh"]

SUFFIXES = (".ply", ".obj", ".usd", ".usda", ".usdc", ".usdz")
FIT = 1.0  # half the largest extent after scaling, in scene units (the cup's radius)


class GeometryError(LookdevError):
    """A mesh for the proof cannot be used (missing, unreadable, no triangles, no UVs)."""


def proof_mesh(path: str | Path) -> Path:
    """The PLY in the cache that puts ``path``'s mesh in the cup's slot (made once)."""
    path = Path(path).expanduser()
    if not path.is_file():
        raise GeometryError("geometry file does not exist", where=str(path))
    if path.suffix.lower() not in SUFFIXES:
        raise GeometryError(
            f"unsupported geometry format {path.suffix!r}; use {', '.join(SUFFIXES)}",
            where=str(path),
        )
    key = hashlib.sha256(path.read_bytes() + repr((CUP_CENTER, FIT)).encode()).hexdigest()
    out = cache_dir().parent / "mesh" / f"asset-{key[:16]}.ply"
    if not out.is_file():
        write_ply(placed(load_mesh(path)), out)
    return out


def load_mesh(path: Path) -> MeshData:
    """Triangles, normals and UVs of a PLY, OBJ or USD file (see module doc)."""
    suffix = path.suffix.lower()
    mesh = _usd_mesh(path) if suffix.startswith(".usd") else _mitsuba_mesh(path)
    if len(mesh.faces) == 0:
        raise GeometryError("the file holds no triangles", where=str(path))
    return mesh


def placed(mesh: MeshData) -> MeshData:
    """``mesh`` scaled and moved into the cup's slot, resting on the ground (y = 0)."""
    lo, hi = mesh.positions.min(axis=0), mesh.positions.max(axis=0)
    scale = FIT / max(float((hi - lo).max()) / 2.0, 1e-12)
    centre = np.array([(lo[0] + hi[0]) / 2, lo[1], (lo[2] + hi[2]) / 2])
    target = np.array([CUP_CENTER[0], 0.0, CUP_CENTER[2]])
    positions = (mesh.positions - centre) * scale + target
    return MeshData(positions.astype(np.float32), mesh.normals, mesh.uvs, mesh.faces)


def _mitsuba_mesh(path: Path) -> MeshData:
    import mitsuba as mi

    from lookdev.pipeline.variant import use_mitsuba

    if mi.variant() is None:
        use_mitsuba()
    kind = path.suffix.lower()[1:]
    props = {"type": kind, "filename": str(path), "face_normals": False}
    if kind == "obj":
        props["flip_tex_coords"] = False  # lookdev's UVs are v-up, as the file stores them
    try:
        shape = mi.load_dict(props)
    except Exception as exc:  # Mitsuba raises RuntimeError with a multi-line message
        first = str(exc).strip().splitlines()[-1] if str(exc).strip() else type(exc).__name__
        raise GeometryError(
            f"Mitsuba cannot read the mesh: {first[:200]}", where=str(path)
        ) from None
    params = mi.traverse(shape)
    positions = np.asarray(params["vertex_positions"], dtype=np.float32).reshape(-1, 3)
    faces = np.asarray(params["faces"], dtype=np.uint32).reshape(-1, 3)
    if "vertex_texcoords" not in params or len(params["vertex_texcoords"]) == 0:
        raise GeometryError("the mesh has no UVs (texture coordinates)", where=str(path))
    uvs = np.asarray(params["vertex_texcoords"], dtype=np.float32).reshape(-1, 2)
    normals = (
        np.asarray(params["vertex_normals"], dtype=np.float32).reshape(-1, 3)
        if "vertex_normals" in params and len(params["vertex_normals"])
        else _vertex_normals(positions, faces)
    )
    return MeshData(positions, normals, uvs, faces)


def _usd_mesh(path: Path) -> MeshData:
    """Every mesh of a USD stage, world space, y up, as one unwelded triangle list."""
    from pxr import Usd, UsdGeom

    stage = Usd.Stage.Open(str(path))
    if stage is None:
        raise GeometryError("usd-core cannot open the file", where=str(path))
    z_up = UsdGeom.GetStageUpAxis(stage) == UsdGeom.Tokens.z
    cache = UsdGeom.XformCache()
    parts: list[tuple[np.ndarray, np.ndarray]] = []
    for prim in stage.Traverse():
        if not prim.IsA(UsdGeom.Mesh):
            continue
        mesh = UsdGeom.Mesh(prim)
        points = np.asarray(mesh.GetPointsAttr().Get() or [], dtype=np.float64)
        counts = np.asarray(mesh.GetFaceVertexCountsAttr().Get() or [], dtype=np.int64)
        indices = np.asarray(mesh.GetFaceVertexIndicesAttr().Get() or [], dtype=np.int64)
        if len(points) == 0 or len(counts) == 0:
            continue
        st = _st_per_corner(prim, counts, indices)
        if st is None:
            continue
        m = np.asarray(cache.GetLocalToWorldTransform(prim), dtype=np.float64)
        world = points @ m[:3, :3] + m[3, :3]
        corners = _fan(counts)  # (T, 3) indices into the face-vertex list
        parts.append((world[indices][corners].reshape(-1, 3), st[corners].reshape(-1, 2)))
    if not parts:
        raise GeometryError("no UsdGeom.Mesh with primvars:st in the stage", where=str(path))
    positions = np.concatenate([p for p, _ in parts]).astype(np.float32)
    if z_up:  # lookdev's scenes are y up
        positions = positions[:, [0, 2, 1]] * np.array([1, 1, -1], dtype=np.float32)
    uvs = np.concatenate([t for _, t in parts]).astype(np.float32)
    faces = np.arange(len(positions), dtype=np.uint32).reshape(-1, 3)
    return MeshData(positions, _smooth_normals(positions, faces), uvs, faces)


def _st_per_corner(prim, counts: np.ndarray, indices: np.ndarray) -> np.ndarray | None:
    """``primvars:st`` (or ``st``) expanded to one UV per face-vertex, or None."""
    from pxr import UsdGeom

    api = UsdGeom.PrimvarsAPI(prim)
    primvar = api.GetPrimvar("st") if api.HasPrimvar("st") else None
    if primvar is None:
        return None
    values = np.asarray(primvar.ComputeFlattened() or [], dtype=np.float64)
    if values.size == 0:
        return None
    interpolation = primvar.GetInterpolation()
    if interpolation == UsdGeom.Tokens.faceVarying:
        return values
    if interpolation in (UsdGeom.Tokens.vertex, UsdGeom.Tokens.varying):
        return values[indices]
    if interpolation == UsdGeom.Tokens.uniform:
        return np.repeat(values, counts, axis=0)
    return np.repeat(values[:1], len(indices), axis=0)  # constant


def _fan(counts: np.ndarray) -> np.ndarray:
    """Triangles (face-vertex indices) fanning each polygon from its first corner."""
    starts = np.concatenate([[0], np.cumsum(counts)[:-1]])
    tris = [
        (s, s + k, s + k + 1) for s, n in zip(starts, counts, strict=True) for k in range(1, n - 1)
    ]
    return np.asarray(tris, dtype=np.int64).reshape(-1, 3)


def _vertex_normals(positions: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Area-weighted vertex normals (a mesh without its own)."""
    p = positions.astype(np.float64)
    n = np.cross(p[faces[:, 1]] - p[faces[:, 0]], p[faces[:, 2]] - p[faces[:, 0]])
    out = np.zeros_like(p)
    for k in range(3):
        np.add.at(out, faces[:, k], n)
    out /= np.maximum(np.linalg.norm(out, axis=1, keepdims=True), 1e-12)
    return out.astype(np.float32)


def _smooth_normals(positions: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Vertex normals of an unwelded list, shared between corners at one position."""
    _, weld = np.unique(np.round(positions, 6), axis=0, return_inverse=True)
    weld = weld.reshape(-1)
    welded = np.zeros((weld.max() + 1, 3))
    welded[weld] = positions
    return _vertex_normals(welded.astype(np.float32), weld[faces].astype(np.uint32))[weld]
