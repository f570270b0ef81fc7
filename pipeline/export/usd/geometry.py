"""The preview sphere as a polygon mesh: what DCC importers bind a material to.

A ``UsdGeomSphere`` gprim is a renderer's shape, not a DCC's: Blender's importer turns
it into a mesh of its own and drops its material binding. A ``UsdGeomMesh`` with
vertex normals (shaded smooth, no subdivision) and an ``st`` primvar (longitude → u,
latitude → v, so maps show) arrives bound in Blender's default import.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["SphereMesh", "uv_sphere"]


@dataclass(frozen=True)
class SphereMesh:
    """A unit sphere's mesh arrays, as ``UsdGeomMesh`` stores them (y up)."""

    points: np.ndarray
    """(V, 3) positions on the unit sphere."""
    normals: np.ndarray
    """(V, 3) outward unit normals (equal to the points)."""
    st: np.ndarray
    """(V, 2) texture coordinates: u = longitude / 2π, v = 1 at the north pole."""
    counts: np.ndarray
    """(F,) vertices per face: triangles at the poles, quads between."""
    indices: np.ndarray
    """(Σ counts,) vertex indices, counter-clockwise seen from outside (right-handed)."""


def uv_sphere(rings: int = 32, segments: int = 64) -> SphereMesh:
    """A latitude–longitude sphere of ``rings`` bands and ``segments`` slices.

    Vertices form a (rings + 1) × (segments + 1) grid: the seam column is doubled so
    ``st`` does not wrap, and each pole row keeps one vertex per slice (a triangle
    fan whose ``u`` follows its slice).

    >>> m = uv_sphere(4, 8)
    >>> m.points.shape, len(m.counts), int(m.counts.sum()) == len(m.indices)
    ((45, 3), 32, True)
    >>> bool(np.allclose(np.linalg.norm(m.points, axis=1), 1.0))
    True
    """
    if rings < 2 or segments < 3:
        raise ValueError(f"a sphere needs rings ≥ 2 and segments ≥ 3, not {rings}, {segments}")
    i = np.arange(rings + 1)[:, None]
    j = np.arange(segments + 1)[None, :]
    theta = np.pi * i / rings  # from the north pole (+y)
    phi = 2.0 * np.pi * j / segments
    points = np.stack(
        np.broadcast_arrays(
            np.sin(theta) * np.sin(phi), np.cos(theta), np.sin(theta) * np.cos(phi)
        ),
        axis=-1,
    ).reshape(-1, 3)
    st = np.stack(np.broadcast_arrays(j / segments, 1.0 - i / rings), axis=-1).reshape(-1, 2)

    def vertex(r: int, s: int) -> int:
        return r * (segments + 1) + s

    counts: list[int] = []
    indices: list[int] = []
    for r in range(rings):
        for s in range(segments):
            # Counter-clockwise seen from outside: down the meridian, then east.
            a, b = vertex(r, s), vertex(r + 1, s)
            c, d = vertex(r + 1, s + 1), vertex(r, s + 1)
            if r == 0:
                face = [a, b, c]
            elif r == rings - 1:
                face = [a, b, d]
            else:
                face = [a, b, c, d]
            counts.append(len(face))
            indices += face
    return SphereMesh(
        points=points,
        normals=points.copy(),
        st=st,
        counts=np.asarray(counts, np.int32),
        indices=np.asarray(indices, np.int32),
    )
