"""Textures an imported material reads: the file a texture node names, its channel by
USD's rule, its colour space, scale, offset and wrap, as a preset's
:class:`~lookdev.materials.textures.TextureInput`; maps a preset could not load are
left out and named.

UsdUVTexture (USD's UsdPreviewSurface specification) and MaterialX image nodes
(``ND_image_*``, ``ND_tiledimage_*``) are read; a ``PxrTexture`` gives its file.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from lookdev.materials.textures import TextureInput

from .network import Connection, Image, Node

__all__ = [
    "COLOUR_SPACE",
    "MTLX_IMAGES",
    "WRAP",
    "image_input",
    "round32",
    "settle_maps",
    "texture_file",
    "texture_input",
    "usd_channel",
]


TEXTURE_FILE_INPUT = {"UsdUVTexture": "file", "PxrTexture": "filename"}


MTLX_IMAGES = ("ND_image_", "ND_tiledimage_", "ND_UsdUVTexture")
"""MaterialX image nodes (by id prefix): their ``file`` is the texture an input reads."""


DATA_IMAGES = ("_float", "_vector2", "_vector3", "_vector4")
"""MaterialX image node id endings whose values are data (no colour transform)."""


def settle_maps(result: Any) -> None:
    """Keep only the maps of ``result`` (an imported material, :class:`.reader.Imported`)
    a preset can load: the file (a UDIM tile) exists and OpenImageIO
    reads it; a UsdUVTexture output names the file's channel by USD's rule (one channel:
    r, g, b and rgb repeat it, a is 1; two: r, g, b and rgb repeat the first, a is the
    second; three: a is 1). What is dropped is named."""
    import OpenImageIO as oiio

    for param, tex in list(result.maps.items()):
        path = Path(tex.texture)
        tiles = sorted(path.parent.glob(path.name.replace("<UDIM>", "[0-9]" * 4)))
        first = tiles[0] if "<UDIM>" in path.name and tiles else path
        image = oiio.ImageInput.open(str(first)) if first.is_file() else None
        if image is None:
            what = "does not exist" if not first.is_file() else "cannot be read"
            result.loss.append(f"the map {tex.texture} of {param} {what} (not imported)")
            del result.maps[param]
            continue
        channels = image.spec().nchannels
        image.close()
        index = usd_channel(tex.channel, channels)
        if index == "one":  # alpha of a file without alpha: 1, through scale and offset
            result.params[param] = round32(tex.scale + tex.offset)
            result.loss.append(
                f"{param} reads the alpha of {tex.texture}, which has {channels} channel(s): "
                f"1 by USD's rule, imported as the constant {result.params[param]:g}"
            )
            del result.maps[param]
        elif index != tex.channel:
            result.maps[param] = tex.model_copy(update={"channel": index})


def usd_channel(output: str | int | None, channels: int) -> str | int | None:
    """The file channel a UsdUVTexture output reads in a file of ``channels`` channels
    (USD's rule, see :func:`settle_maps`): a channel, None for the default (the first
    three or a grey one), ``"one"`` for the constant 1; ``output`` unchanged when the
    file has it, or when it is not a UsdUVTexture output.

    >>> [usd_channel(c, 1) for c in ("r", "g", "a", "rgb")]
    [0, 0, 'one', None]
    >>> [usd_channel(c, 2) for c in ("b", "a", "rgb")], usd_channel("a", 3), usd_channel("g", 4)
    ([0, 1, 0], 'one', 'g')
    """
    if output not in ("r", "g", "b", "a", "rgb"):
        return output
    if output == "a":
        return output if channels >= 4 else 1 if channels == 2 else "one"
    if output == "rgb":
        return 0 if channels == 2 else None
    return output if channels >= 3 else 0


def image_input(nodes: dict[str, Node], conn: Connection, scale: float) -> TextureInput | None:
    """The texture of a MaterialX image node feeding an input (its file and the file's
    colour space; ``scale`` the weight and conversion of the input), or None."""
    node = nodes.get(conn.node)
    if node is None or not node.id.startswith(MTLX_IMAGES):
        return None
    path = texture_file(nodes, conn)
    if path is None:
        return None
    fields: dict[str, Any] = {"texture": str(path)}
    space = node.color_spaces.get("file")
    if node.id.endswith(DATA_IMAGES):
        fields["colorspace"] = "Raw"  # MaterialX converts colour images only
    elif space:
        fields["colorspace"] = space
    if scale != 1.0:
        fields["scale"] = scale
    return TextureInput.parse(fields)


WRAP = {"repeat": "periodic", "clamp": "clamp", "black": "black", "mirror": "mirror"}
"""UsdUVTexture ``wrapS`` → :class:`TextureInput` ``wrap``."""


COLOUR_SPACE = {"raw": "Raw", "sRGB": "sRGB - Texture"}
"""UsdUVTexture ``sourceColorSpace`` → the OCIO config's name (``auto``: by file rule)."""


def texture_input(nodes: dict[str, Node], conn: Connection, slot) -> TextureInput | None:
    """The :class:`TextureInput` of the texture node feeding ``slot``: its file, output
    channel, colour space, UsdUVTexture scale/bias as scale/offset and wrap. The slot's
    own conversion is not applied (it is named by the input it feeds)."""
    path = texture_file(nodes, conn)
    if path is None:
        return None
    node = nodes[conn.node]
    fields: dict[str, Any] = {"texture": str(path)}
    if conn.output in ("r", "g", "b", "a", "rgb"):
        fields["channel"] = conn.output
    space = node.inputs.get("sourceColorSpace", (None, None))[1]
    if space in COLOUR_SPACE:
        fields["colorspace"] = COLOUR_SPACE[space]
    channel = {"r": 0, "g": 1, "b": 2, "a": 3}.get(conn.output, 0)
    scale = node.inputs.get("scale", (None, None))[1]
    bias = node.inputs.get("bias", (None, None))[1]
    s = float(scale[channel]) if isinstance(scale, tuple) else 1.0
    o = float(bias[channel]) if isinstance(bias, tuple) else 0.0
    # The input is a·param + b (the slot's affine map): param = (texel·s + o − b)/a.
    a, b = slot.texture_linear or (1.0, 0.0)
    s, o = s / a, (o - b) / a
    if s != 1.0:
        fields["scale"] = s
    if o != 0.0:
        fields["offset"] = o
    wrap = node.inputs.get("wrapS", (None, None))[1]
    if wrap in WRAP:
        fields["wrap"] = WRAP[wrap]
    return TextureInput.parse(fields)


def texture_file(nodes: dict[str, Node], conn: Connection) -> Path | None:
    node = nodes.get(conn.node)
    if node is None:
        return None
    key = TEXTURE_FILE_INPUT.get(node.id, "file")
    value = node.inputs.get(key, (None, None))[1]
    return value.path if isinstance(value, Image) else None


def round32(v: Any) -> Any:
    """float32-stored values as the shortest decimal that reads back the same float32."""
    import numpy as np

    if isinstance(v, float):
        return float(np.format_float_positional(np.float32(v), unique=True))
    if isinstance(v, tuple):
        return tuple(round32(x) for x in v)
    return v
