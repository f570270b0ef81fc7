"""The calibrated look-dev rig beside the material: a chrome ball, an 18 % grey ball and a
ColorChecker chart (:doc:`/design`, Proofing).

A look-dev lead reads a proof against references that do not change from material to
material: the chrome ball shows where the light comes from and how sharp it is, the grey
ball shows its level and colour on a known diffuse albedo (0.18, a photographer's mid-grey
card), and the chart shows 24 known reflectances under the same light. ``--rig`` chooses:

* ``full`` (the default: what a look-dev lead expects in a proof frame): both balls and
  the chart;
* ``balls``: the two balls only (the chart's place stays empty, so framing is the same
  as ``full`` and the two can be compared frame for frame);
* ``none``: the material alone, framed as tightly as before the rig existed.

The rig stands in a column right of the cup and does not turn with the element; it turns
with the lighting like everything else. Its values are not invented here: the chart's 24
patches are colour-science's ``ColorChecker24 - After November 2014`` (X-Rite's published
CIE xyY under ICC D50), taken to CIE XYZ, adapted to the working space's white with the
Bradford transform (the ICC's) and expressed in the working space's linear RGB
(:func:`patch_values`); they are used as diffuse albedos. The chart's surround is its own
``black 2`` patch value. The chrome ball is Mitsuba's ``conductor`` with its measured
chromium (``Cr``) index of refraction.
"""

from __future__ import annotations

import functools
from typing import Any, Literal

import numpy as np

__all__ = [
    "CHART",
    "CHART_NAME",
    "DEFAULT_RIG",
    "GREY_ALBEDO",
    "RIGS",
    "Rig",
    "chart_size",
    "chart_texture",
    "extent",
    "manifest_entry",
    "patch_values",
    "shapes",
]

Rig = Literal["full", "balls", "none"]
RIGS: tuple[str, ...] = ("full", "balls", "none")
DEFAULT_RIG: Rig = "full"

CHART_NAME = "ColorChecker24 - After November 2014"
"""The colour-science data set the chart's patches come from."""
CAT = "Bradford"
"""Chromatic adaptation from the data's D50 to the working space's white (the ICC's)."""
GREY_ALBEDO = 0.18
CHROME = "Cr"
"""Mitsuba's measured conductor for the chrome ball."""

# Geometry (world units: the material's ball has radius 1, y up, camera on +z).
COLUMN_X = 3.0
"""Centre of the rig's column, right of the cup (which reaches x ≈ 2.2)."""
BALL_RADIUS = 0.3
CHROME_CENTER = (COLUMN_X - 0.34, 1.45, 0.0)
GREY_CENTER = (COLUMN_X + 0.34, 1.45, 0.0)
CHART = {"columns": 6, "rows": 4, "width": 1.25, "centre": (COLUMN_X, 0.5, 0.35)}
"""The chart: 6 × 4 patches standing on the ground in front of the balls, facing the camera."""
PATCH_TEXELS, GAP_TEXELS = 8, 2  # per patch and between patches, in the chart's bitmap


@functools.cache
def _patches(space: str) -> tuple[tuple[str, tuple[float, float, float]], ...]:
    import colour

    from lookdev.materials import colour as lcolour

    data = colour.CCS_COLOURCHECKERS[CHART_NAME]
    names = list(data.data)
    xyz = colour.xyY_to_XYZ(np.array([data.data[n] for n in names], dtype=np.float64))
    # colour-science knows the studio config's linear spaces by the same names; any other
    # working space is reached from linear Rec.709 by the one OCIO config.
    known = space if space in colour.RGB_COLOURSPACES else "Linear Rec.709 (sRGB)"
    rgb = colour.XYZ_to_RGB(
        xyz,
        colour.RGB_COLOURSPACES[known],
        illuminant=data.illuminant,
        chromatic_adaptation_transform=CAT,
        apply_cctf_encoding=False,
    )
    if known != space:
        rgb = lcolour.convert(rgb, known, space).astype(np.float64)
    return tuple((n, tuple(float(c) for c in row)) for n, row in zip(names, rgb, strict=True))


def patch_values(space: str | None = None) -> dict[str, tuple[float, float, float]]:
    """The chart's 24 patches as linear RGB in ``space`` (default: the working space),
    in reading order (``dark skin`` … ``black 2 (1.5 D)``), float64.

    >>> v = patch_values("Linear Rec.709 (sRGB)")
    >>> len(v), [round(c, 4) for c in v["neutral 5 (.70 D)"]]
    (24, [0.1901, 0.1908, 0.1898])
    """
    from lookdev.materials import colour as lcolour

    return dict(_patches(lcolour.working_space() if space is None else lcolour.canonical(space)))


def chart_texture(space: str | None = None) -> np.ndarray:
    """The chart's albedo as a float32 (H, W, 3) bitmap, row 0 at the chart's bottom edge
    (Mitsuba's bitmap puts row 0 at v = 0, the rectangle's bottom): the neutral row at
    the bottom, ``dark skin`` at the top left, as the chart is held."""
    values = list(patch_values(space).values())
    cols, rows = CHART["columns"], CHART["rows"]
    pitch = PATCH_TEXELS + GAP_TEXELS
    image = np.empty((rows * pitch + GAP_TEXELS, cols * pitch + GAP_TEXELS, 3), np.float32)
    image[:] = values[-1]  # the surround: the chart's own black
    for i, rgb in enumerate(values):
        r, c = divmod(i, cols)
        top = GAP_TEXELS + r * pitch
        left = GAP_TEXELS + c * pitch
        image[top : top + PATCH_TEXELS, left : left + PATCH_TEXELS] = rgb
    return np.ascontiguousarray(image[::-1])


def chart_size() -> tuple[float, float]:
    """(width, height) of the chart in world units, from its bitmap's aspect."""
    cols, rows = CHART["columns"], CHART["rows"]
    pitch = PATCH_TEXELS + GAP_TEXELS
    aspect = (rows * pitch + GAP_TEXELS) / (cols * pitch + GAP_TEXELS)
    return CHART["width"], CHART["width"] * aspect


def _facing(centre: np.ndarray, eye: np.ndarray, half: tuple[float, float]) -> Any:
    """A rectangle's ``to_world``: centred at ``centre``, normal towards ``eye``, its +x
    to the camera's right and +y up (so a bitmap reads the right way round)."""
    import mitsuba as mi

    n = eye - centre
    n /= np.linalg.norm(n)
    right = np.cross([0.0, 1.0, 0.0], n)
    right /= np.linalg.norm(right)
    up = np.cross(n, right)
    m = np.eye(4)
    m[:3, 0], m[:3, 1], m[:3, 2], m[:3, 3] = right * half[0], up * half[1], n, centre
    return mi.ScalarTransform4f(m.tolist())


def shapes(rig: str, eye: tuple[float, float, float]) -> dict[str, Any]:
    """The rig's Mitsuba shapes for ``rig`` (``full``, ``balls``, ``none``), by scene key.

    ``eye`` is the camera position (the chart faces it).
    """
    import mitsuba as mi

    if rig not in RIGS:
        raise ValueError(f"unknown rig {rig!r}; one of {', '.join(RIGS)}")
    out: dict[str, Any] = {}
    if rig == "none":
        return out
    out["rig_chrome"] = {
        "type": "sphere",
        "center": list(CHROME_CENTER),
        "radius": BALL_RADIUS,
        "bsdf": {"type": "conductor", "material": CHROME},
    }
    out["rig_grey"] = {
        "type": "sphere",
        "center": list(GREY_CENTER),
        "radius": BALL_RADIUS,
        "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": GREY_ALBEDO}},
    }
    if rig == "full":
        width, height = chart_size()
        centre = np.asarray(CHART["centre"], dtype=np.float64)
        centre[1] = max(centre[1], height / 2 + 0.02)  # stands just above the ground
        out["rig_chart"] = {
            "type": "rectangle",
            "to_world": _facing(centre, np.asarray(eye, np.float64), (width / 2, height / 2)),
            "bsdf": {
                "type": "diffuse",
                "reflectance": {
                    "type": "bitmap",
                    "data": mi.TensorXf(chart_texture()),
                    "raw": True,  # linear working-space albedo already
                    "filter_type": "nearest",
                },
            },
        }
    return out


def extent(rig: str) -> tuple[float, float]:
    """(left, right) world x the rig reaches (0, 0 for ``none``): for the camera's framing."""
    if rig == "none":
        return (0.0, 0.0)
    left = CHROME_CENTER[0] - BALL_RADIUS
    right = GREY_CENTER[0] + BALL_RADIUS
    if rig == "full":
        half = chart_size()[0] / 2
        left, right = min(left, CHART["centre"][0] - half), max(right, CHART["centre"][0] + half)
    return (left, right)


def manifest_entry(rig: str) -> dict[str, Any]:
    """What a proof's manifest records about its rig."""
    from lookdev.materials import colour as lcolour

    entry: dict[str, Any] = {"rig": rig}
    if rig != "none":
        entry["grey_albedo"] = GREY_ALBEDO
        entry["chrome"] = f"Mitsuba conductor, material {CHROME}"
    if rig == "full":
        entry["chart"] = CHART_NAME
        entry["chart_space"] = lcolour.working_space()
        entry["chart_adaptation"] = CAT
    return entry
