"""Generate lookdev's example asset: a small mesh with a UDIM texture set (no downloads).

    python scripts/make_example_asset.py OUT_DIR

writes into OUT_DIR

    pebble.obj                          a pebble (squashed, lumpy sphere), 48×24 quads,
                                        UVs over the 2×2 UDIM tiles 1001, 1002, 1011, 1012
                                        (longitude → u ∈ [0, 2), latitude → v ∈ [0, 2))
    pebble_BaseColor.<UDIM>.png         8-bit sRGB: one hue per tile, with painted bands
    pebble_Roughness.<UDIM>.png         8-bit data
    pebble_Metallic.<UDIM>.png          8-bit data: tile 1002 is metal
    pebble_Normal_OpenGL.<UDIM>.png     8-bit, +Y up: the height's slope
    pebble_Height.<UDIM>.png            16-bit data, 0..1
    pebble.toml                         the preset: textures = "pebble_<channel>.<UDIM>.png",
                                        height 1 = 1 cm (scale 0.01 scene units)

Everything is a function of the tile and texel: the same files every run (64² a tile,
about 100 kB in all). ``scripts/run.sh`` makes it and proofs it with ``--geometry``.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import OpenImageIO as oiio

from lookdev.materials import colour

NAME = "pebble"
TILES = {(0, 0): 1001, (1, 0): 1002, (0, 1): 1011, (1, 1): 1012}
SIZE = 64
HUES = {  # linear Rec.709 base colour of each tile
    1001: (0.60, 0.18, 0.08),
    1002: (0.90, 0.64, 0.30),  # the metal tile: a gold-ish F0
    1011: (0.10, 0.32, 0.12),
    1012: (0.08, 0.14, 0.45),
}
HEIGHT_SCALE = 0.01  # scene units for height 1


def tile_uv(u0: int, v0: int) -> tuple[np.ndarray, np.ndarray]:
    """UDIM-space (u, v) of each texel centre of tile (u0, v0), UV order (row 0: v low)."""
    t = (np.arange(SIZE) + 0.5) / SIZE
    return np.meshgrid(u0 + t, v0 + t)


def height(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """0..1: ripples around the pebble plus a finer weave, continuous across tiles."""
    ripples = 0.5 + 0.5 * np.sin(2 * math.pi * 6 * v / 2)
    weave = 0.5 + 0.5 * np.sin(2 * math.pi * 16 * u / 2) * np.sin(2 * math.pi * 8 * v / 2)
    return (0.7 * ripples + 0.3 * weave).astype(np.float32)


def normals(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Tangent-space normals of the height field (OpenGL, +Y up), (n + 1)/2 encoded.

    Slopes per unit UV times a nominal 0.02 of relief per UV unit: a visible, gentle bump.
    """
    e = 1e-3
    du = (height(u + e, v) - height(u - e, v)) / (2 * e)
    dv = (height(u, v + e) - height(u, v - e)) / (2 * e)
    n = np.stack([-0.02 * du, -0.02 * dv, np.ones_like(du)], axis=-1)
    n /= np.linalg.norm(n, axis=-1, keepdims=True)
    return 0.5 * n + 0.5


def write_png(path: Path, pixels: np.ndarray, fmt=oiio.UINT8) -> None:
    """``pixels`` in UV order (row 0 = v low) written top row first, as viewers show."""
    px = np.ascontiguousarray(np.clip(pixels[::-1], 0.0, 1.0), dtype=np.float32)
    channels = 1 if px.ndim == 2 else px.shape[2]
    out = oiio.ImageOutput.create(str(path))
    if out is None or not out.open(str(path), oiio.ImageSpec(SIZE, SIZE, channels, fmt)):
        raise SystemExit(f"cannot write {path}: {oiio.geterror()}")
    out.write_image(px)
    out.close()


def textures(folder: Path) -> None:
    for (u0, v0), tile in TILES.items():
        u, v = tile_uv(u0, v0)
        h = height(u, v)
        band = (np.sin(2 * math.pi * 3 * u) > 0.6)[..., None]
        base = np.where(band, 0.85, 1.0) * np.asarray(HUES[tile], dtype=np.float32)
        srgb = colour.convert(base, colour.working_space(), colour.SRGB_TEXTURE)
        write_png(folder / f"{NAME}_BaseColor.{tile}.png", srgb)
        write_png(folder / f"{NAME}_Roughness.{tile}.png", 0.25 + 0.5 * h)
        write_png(folder / f"{NAME}_Metallic.{tile}.png", np.full_like(h, tile == 1002))
        write_png(folder / f"{NAME}_Normal_OpenGL.{tile}.png", normals(u, v))
        write_png(folder / f"{NAME}_Height.{tile}.png", h, oiio.UINT16)


def mesh(folder: Path, segments: int = 48, rings: int = 24) -> None:
    """An OBJ pebble: longitude → u ∈ [0, 2), latitude → v ∈ [0, 2) (v up)."""
    lines = [f"# lookdev example asset: {NAME}, UVs over UDIM tiles 1001-1012"]
    verts = []
    for j in range(rings + 1):
        theta = math.pi * j / rings  # from the bottom pole up
        for i in range(segments + 1):
            phi = 2 * math.pi * i / segments
            lump = 1.0 + 0.06 * math.sin(3 * phi) * math.sin(theta) ** 2
            x = lump * math.sin(theta) * math.cos(phi)
            z = lump * math.sin(theta) * math.sin(phi)
            y = -0.7 * math.cos(theta)
            verts.append((x, y, z, 2.0 * i / segments, 2.0 * j / rings))
    for x, y, z, _, _ in verts:
        lines.append(f"v {x:.6f} {y:.6f} {z:.6f}")
    for *_, u, v in verts:
        lines.append(f"vt {min(u, 1.999999):.6f} {min(v, 1.999999):.6f}")
    row = segments + 1
    for j in range(rings):
        for i in range(segments):
            a, b = j * row + i + 1, j * row + i + 2
            c, d = a + row, b + row
            # counter-clockwise seen from outside (normals point out)
            lines.append(f"f {a}/{a} {c}/{c} {d}/{d}")
            lines.append(f"f {a}/{a} {d}/{d} {b}/{b}")
    (folder / f"{NAME}.obj").write_text("\n".join(lines) + "\n", encoding="ascii")


PRESET = f'''name = "{NAME}"
model = "disney"
description = "lookdev's example asset: a pebble painted over four UDIM tiles."
tags = ["example", "textured"]
textures = "{NAME}_<channel>.<UDIM>.png"
# The painted height is 0..1; a height of 1 is 1 cm (scene units are metres).
height = {{ texture = "{NAME}_Height.<UDIM>.png", scale = {HEIGHT_SCALE} }}

[params]
specular = 0.5
'''


def main(argv: list[str]) -> int:
    if len(argv) != 1:
        print(__doc__.strip().splitlines()[2], file=sys.stderr)
        return 2
    folder = Path(argv[0])
    folder.mkdir(parents=True, exist_ok=True)
    textures(folder)
    mesh(folder)
    (folder / f"{NAME}.toml").write_text(PRESET, encoding="utf-8")
    print(f"wrote {folder}/{NAME}.obj, .toml and {5 * len(TILES)} texture tiles")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
