"""The proof scene: a sphere and a tilted cup on a ground plane, under an IBL.

The sphere shows the material over every normal direction at once. The cup, a thick bowl
revolved from a closed profile (convex outside and round rim, concave inside), shows how
the material looks in cavities, where light bounces on the material itself; it is tilted
towards the camera so that its inside is seen, and since its outside is a hemisphere
tilted about its own centre it rests on the ground at any tilt and any turntable angle.

The cup is a triangle mesh generated with numpy and written once as a binary PLY into
the cache (:func:`cup_ply`), so a scene dict, the naive benchmark script and an exported
XML scene all load the same file. World: y up, camera on +z looking at the pair; the
calibrated rig (:mod:`.rig`) stands right of the cup and the camera frames it too.
"""

from __future__ import annotations

import hashlib
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from lookdev.library import files

from . import rig as rig_module
from .ibl import cache_dir, envmap_to_world
from .rig import DEFAULT_RIG

__all__ = [
    "BALL_CENTER",
    "CUP_CENTER",
    "CUP_TILT_DEG",
    "CUP_WALL",
    "DISTANCE",
    "ELEVATION_DEG",
    "GROUND_ALBEDO",
    "MARGIN",
    "METERS_PER_UNIT",
    "MeshData",
    "PAIR_HALF_WIDTH",
    "PIXEL_FILTERS",
    "ball_to_world",
    "camera",
    "cup_mesh",
    "cup_ply",
    "cup_profile",
    "cup_to_world",
    "envmap",
    "eye",
    "framed",
    "lathe",
    "rotation_x",
    "scene_dict",
    "write_ply",
]

GROUND_ALBEDO = 0.18  # a photographer's mid-grey card
BALL_CENTER = (-1.2, 1.0, 0.0)
CUP_CENTER = (1.2, 1.0, 0.0)
CUP_TILT_DEG = 40.0  # towards the camera, so the inside shows
CUP_WALL = 0.18  # wall thickness, in units of the outer radius
METERS_PER_UNIT = 0.05
"""The proof's scale: the ball's radius (1 unit) is 5 cm, a 10 cm shader ball, so a
preset's scatter distances (metres) show as they would on a hand-sized object."""


@dataclass(frozen=True)
class MeshData:
    """Triangles with per-vertex normals and UVs, float32 / uint32."""

    positions: np.ndarray  # (N, 3)
    normals: np.ndarray  # (N, 3)
    uvs: np.ndarray  # (N, 2)
    faces: np.ndarray  # (F, 3)


def cup_profile(samples: int = 48) -> tuple[np.ndarray, np.ndarray]:
    """(r, y) along the cup's closed profile: outer pole → rim → inner pole.

    Outer hemisphere of radius 1, a semicircular rim of diameter ``CUP_WALL``, inner
    hemisphere of radius 1 − ``CUP_WALL``; the sphere centre is the origin.
    """
    w = CUP_WALL
    t = np.linspace(-math.pi / 2, 0.0, samples)
    outer = np.stack([np.cos(t), np.sin(t)], axis=1)
    s = np.linspace(0.0, math.pi, max(8, samples // 4))[1:]
    rim = np.stack([1 - w / 2 + (w / 2) * np.cos(s), (w / 2) * np.sin(s)], axis=1)
    inner = (1 - w) * np.stack([np.cos(-t[::-1]), np.sin(-t[::-1])], axis=1)[1:]
    inner[:, 1] *= -1  # back down into the bowl: y from 0 to −(1 − w)
    pts = np.concatenate([outer, rim, inner])
    pts[np.abs(pts[:, 0]) < 1e-9, 0] = 0.0
    return pts[:, 0], pts[:, 1]


def lathe(r: np.ndarray, y: np.ndarray, segments: int = 96) -> MeshData:
    """Revolve the profile (r, y) about the y axis; normals from the profile's tangent.

    The profile runs so that the solid is on its left when r is right and y up (outer
    surface bottom → top); the outward normal is the tangent turned clockwise. A seam
    column is duplicated so UVs wrap; zero-area triangles at the poles are dropped.
    """
    n_prof = len(r)
    tangent = np.gradient(np.stack([r, y], axis=1), axis=0)
    normal2 = np.stack([tangent[:, 1], -tangent[:, 0]], axis=1)
    normal2 /= np.linalg.norm(normal2, axis=1, keepdims=True)
    phi = np.linspace(0.0, 2.0 * math.pi, segments + 1)
    c, s = np.cos(phi)[None, :], np.sin(phi)[None, :]
    pos = np.stack(np.broadcast_arrays(r[:, None] * c, y[:, None], r[:, None] * s), -1)
    nrm = np.stack(np.broadcast_arrays(normal2[:, :1] * c, normal2[:, 1:], normal2[:, :1] * s), -1)
    arc = np.concatenate([[0.0], np.cumsum(np.hypot(np.diff(r), np.diff(y)))])
    uv = np.stack(np.broadcast_arrays(phi[None, :] / (2 * math.pi), (arc / arc[-1])[:, None]), -1)
    idx = np.arange(n_prof * (segments + 1)).reshape(n_prof, segments + 1)
    a, b = idx[:-1, :-1].ravel(), idx[:-1, 1:].ravel()
    cc, d = idx[1:, :-1].ravel(), idx[1:, 1:].ravel()
    faces = np.concatenate([np.stack([a, d, b], 1), np.stack([a, cc, d], 1)])
    flat = pos.reshape(-1, 3)
    area = np.linalg.norm(
        np.cross(flat[faces[:, 1]] - flat[faces[:, 0]], flat[faces[:, 2]] - flat[faces[:, 0]]),
        axis=1,
    )
    return MeshData(
        flat.astype(np.float32),
        nrm.reshape(-1, 3).astype(np.float32),
        uv.reshape(-1, 2).astype(np.float32),
        faces[area > 1e-12].astype(np.uint32),
    )


def rotation_x(degrees: float) -> np.ndarray:
    """3×3 rotation about +x (right-handed: +y turns towards +z)."""
    a = math.radians(degrees)
    return np.array([[1, 0, 0], [0, math.cos(a), -math.sin(a)], [0, math.sin(a), math.cos(a)]])


def cup_mesh(segments: int = 96, samples: int = 48) -> MeshData:
    """The cup in world space at turntable angle 0: tilted, then moved to its place."""
    m = lathe(*cup_profile(samples), segments)
    tilt = rotation_x(CUP_TILT_DEG)
    return MeshData(
        (m.positions @ tilt.T + np.asarray(CUP_CENTER)).astype(np.float32),
        (m.normals @ tilt.T).astype(np.float32),
        m.uvs,
        m.faces,
    )


def write_ply(mesh: MeshData, path: Path) -> Path:
    """Binary little-endian PLY (x y z nx ny nz u v; triangles), written atomically."""
    n, f = len(mesh.positions), len(mesh.faces)
    header = (
        "ply\nformat binary_little_endian 1.0\n"
        f"element vertex {n}\n"
        + "".join(f"property float {k}\n" for k in ("x", "y", "z", "nx", "ny", "nz", "u", "v"))
        + f"element face {f}\nproperty list uchar uint vertex_indices\nend_header\n"
    )
    vertices = np.concatenate([mesh.positions, mesh.normals, mesh.uvs], axis=1).astype("<f4")
    faces = np.zeros(f, dtype=[("n", "u1"), ("i", "<u4", 3)])
    faces["n"], faces["i"] = 3, mesh.faces
    files.make_folder(path.parent)
    return files.atomic_write(path, header.encode("ascii") + vertices.tobytes() + faces.tobytes())


def cup_ply() -> Path:
    """The cup's PLY in the cache, generated on first use (keyed by its parameters)."""
    key = hashlib.sha256(repr((CUP_CENTER, CUP_TILT_DEG, CUP_WALL, 96, 48)).encode())
    path = cache_dir().parent / "mesh" / f"cup-{key.hexdigest()[:12]}.ply"
    return path if path.is_file() else write_ply(cup_mesh(), path)


PAIR_HALF_WIDTH = 2.3
"""Half the width the ball and the cup take together (x from −2.3 to 2.3)."""
MARGIN = 0.6
"""Space left and right of what is framed, in world units."""
ELEVATION_DEG, DISTANCE = 14.0, 9.0


def framed(rig: str = DEFAULT_RIG) -> tuple[float, float]:
    """(left, right) world x the camera frames: the pair and the ``rig`` beside it."""
    left, right = -PAIR_HALF_WIDTH, PAIR_HALF_WIDTH
    if rig != "none":
        lo, hi = rig_module.extent(rig)
        left, right = min(left, lo), max(right, hi)
    return left, right


def eye(rig: str = DEFAULT_RIG) -> tuple[np.ndarray, np.ndarray]:
    """(camera origin, target) framing the pair and the ``rig`` beside it."""
    left, right = framed(rig)
    elevation = math.radians(ELEVATION_DEG)
    target = np.array([(left + right) / 2, 0.85, 0.0])
    origin = target + DISTANCE * np.array([0.0, math.sin(elevation), math.cos(elevation)])
    return origin, target


PIXEL_FILTERS = ("box", "gaussian")
"""Reconstruction filters a proof camera takes; ``box`` is the default (see :func:`camera`)."""


def camera(
    width: int, height: int, rig: str = DEFAULT_RIG, pixel_filter: str = "box"
) -> dict[str, Any]:
    """A perspective camera framing both shapes and the rig, slightly above them.

    The pixel filter is a box by default: each sample lands in one pixel, so pixel noise
    stays independent, which a denoiser relies on (a Gaussian spreads each sample over
    its neighbours, and OIDN then gains almost nothing), and it costs less.
    """
    import mitsuba as mi

    origin, target = eye(rig)
    left, right = framed(rig)
    # Horizontal field of view that fits what is framed with a margin; a tall film keeps
    # the same width and shows more ground and sky.
    fov = 2.0 * math.degrees(math.atan(((right - left) / 2 + MARGIN) / DISTANCE))
    return {
        "type": "perspective",
        "fov": fov,
        "fov_axis": "x",
        "to_world": mi.ScalarTransform4f().look_at(
            origin=origin.tolist(), target=target.tolist(), up=[0.0, 1.0, 0.0]
        ),
        "film": {
            "type": "hdrfilm",
            "width": int(width),
            "height": int(height),
            "pixel_format": "rgb",
            "rfilter": {"type": pixel_filter},
        },
        "sampler": {"type": "independent"},
    }


def ball_to_world(degrees: float) -> Any:
    """The ball's transform at turntable angle ``degrees``."""
    import mitsuba as mi

    return mi.ScalarTransform4f().translate(list(BALL_CENTER)).rotate([0, 1, 0], degrees)


def cup_to_world(degrees: float) -> Any:
    """The cup's transform at turntable angle ``degrees``: a turn about its own centre."""
    import mitsuba as mi

    pivot = list(CUP_CENTER)
    return (
        mi.ScalarTransform4f()
        .translate(pivot)
        .rotate([0, 1, 0], degrees)
        .translate([-c for c in pivot])
    )


_material = {"type": "ref", "id": "material"}


def _instance(group: str, to_world: Any) -> dict[str, Any]:
    return {"type": "instance", "shapegroup": {"type": "ref", "id": group}, "to_world": to_world}


def envmap(environment: np.ndarray) -> dict[str, Any]:
    """The scene's ``envmap`` emitter of a lat-long (H, W, 3) ``environment``, unturned."""
    import mitsuba as mi

    bitmap = mi.Bitmap(np.ascontiguousarray(environment, dtype=np.float32))
    return {"type": "envmap", "bitmap": bitmap, "to_world": envmap_to_world(0.0)}


def scene_dict(
    bsdf: dict[str, Any],
    environment: np.ndarray,
    resolution: tuple[int, int],
    max_depth: int,
    geometry: str | Path | None = None,
    *,
    rig: str = DEFAULT_RIG,
    pixel_filter: str = "box",
    clamp: float | None = None,
    interior: dict[str, Any] | None = None,
) -> dict[str, Any]:
    """The shader-ball scene; the same ``bsdf`` on the ball and the cup, the ``rig``
    (:mod:`.rig`: ``full``, ``balls`` or ``none``) beside them.

    ``geometry``: a PLY already placed in the cup's slot (:func:`.geometry.proof_mesh`)
    shown instead of the cup, turning about the same centre.

    ``environment`` is a lat-long (H, W, 3) float32 array, used as it is (exposure is
    already in its pixels, see :mod:`.ibl`) and oriented by :data:`.ibl.ORIENTATION`.
    ``clamp``: each camera sample's radiance is limited to that value (:mod:`.clamp`;
    biased, for previews); None renders unclamped.
    ``interior`` (:func:`lookdev.pipeline.export.mitsuba.medium.interior_dict` at
    :data:`METERS_PER_UNIT`) fills the ball and the cup of a solid subsurface material;
    only then does the scene take ``volpath``.
    """
    import mitsuba as mi

    from .clamp import integrator

    width, height = resolution
    inside = {} if interior is None else {"interior": interior}
    return {
        "type": "scene",
        "integrator": integrator(max_depth, clamp, interior),
        "sensor": camera(width, height, rig, pixel_filter),
        "environment": envmap(environment),
        "material": bsdf | {"id": "material"},
        # Each shape sits in a shapegroup placed by an instance: turning an instance
        # re-commits only the top-level acceleration structure (≈ 10 ms, not ≈ 80 ms
        # for moving the shapes themselves; measured in lookdev bench proof).
        "ball_shape": {
            "type": "shapegroup",
            "shape": {"type": "sphere", "bsdf": _material, **inside},
        },
        "cup_shape": {
            "type": "shapegroup",
            "shape": {
                "type": "ply",
                "filename": str(geometry or cup_ply()),
                "face_normals": False,
                "bsdf": _material,
                **inside,
            },
        },
        "ball": _instance("ball_shape", ball_to_world(0.0)),
        "cup": _instance("cup_shape", cup_to_world(0.0)),
        "ground": {
            "type": "rectangle",
            "to_world": mi.ScalarTransform4f().rotate([1, 0, 0], -90).scale([30, 30, 1]),
            "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": GROUND_ALBEDO}},
        },
        **rig_module.shapes(rig, tuple(eye(rig)[0])),
    }
