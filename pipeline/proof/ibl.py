"""Environment lights (IBLs) for proofs: built-ins generated procedurally, or user files.

A built-in IBL is a small TOML definition in ``presets/ibl/`` (a background gradient or a
CIE sky, a sun, soft boxes, a ground) rendered once into a lat-long EXR with OpenImageIO
and cached under ``$LOOKDEV_CACHE`` (default ``~/.cache/lookdev``) by a hash of the
definition, so editing a definition regenerates it. Any ``.exr`` or ``.hdr`` a user names
is used the same way.

Every IBL of a batch is brought to one resolution and its exposure is folded into the
pixels (:func:`load`): in Mitsuba 3.9 a new envmap resolution or ``scale`` compiles a new
kernel, while new pixel values of the same size do not (:doc:`/design`, Proofing).

Colour: the proof renders in the working space. Built-ins are generated in linear Rec.709
(:data:`IBL_SPACE`); a file is in the space its header names (``colorSpace``,
``oiio:ColorSpace``), else linear Rec.709. :func:`load` converts each into the working
space through OCIO (for ACEScg, Rec.709 → AP1 with the config's chromatic adaptation),
so one IBL lights a material identically in either working space.

Lat-long convention (Mitsuba's ``envmap``): (u, v) looks along
``(sin φ sin θ, cos θ, −cos φ sin θ)`` with φ = 2πu, θ = πv; row 0 is the zenith (+y)
(see :func:`directions` for where exactly each pixel sits).
Light directions in the definitions are (azimuth, elevation) in degrees with azimuth 0
towards the camera (+z: a front light), 90 from the camera's right (+x), 180 behind the
subject (a rim light).

Orientation convention (:data:`ORIENTATION`; written to every proof manifest and as a
comment into exported Mitsuba scenes, which use the same :func:`envmap_to_world`):
**up is +y**; at **rotation 0** the lat-long's centre column (u = ½) lies towards the
camera (+z) and u = ¼ towards the camera's right (+x), row 0 is the zenith; a **positive
rotation** turns the environment about +y right-handedly, counter-clockwise seen from
above: a light in front of the subject moves to the camera's right at +90°.
"""

from __future__ import annotations

import hashlib
import json
import logging
import math
import os
import tomllib
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, ValidationError

from lookdev.materials import colour
from lookdev.materials.errors import LookdevError, one_line

from .contact import ProofImageError, write_exr

__all__ = [
    "CieSky",
    "DEFAULT_WIDTH",
    "Environment",
    "GENERATOR_VERSION",
    "Gradient",
    "Ground",
    "IBL_SPACE",
    "IblDefinition",
    "IblError",
    "ORIENTATION",
    "REAL_HDR",
    "Rgb",
    "SUFFIXES",
    "SoftBox",
    "Sun",
    "builtin_names",
    "cache_dir",
    "check_latlong",
    "cie_sky",
    "definition",
    "definitions_folder",
    "direction",
    "directions",
    "envmap_to_world",
    "file_space",
    "generate",
    "gradient",
    "load",
    "read_image",
    "resample",
    "resolve",
    "soft_box",
    "sun_disc",
]

ORIENTATION = {
    "up": "+y",
    "camera": "on +z looking towards -z, +x to its right",
    "zero_rotation": "lat-long centre column (u = 0.5) towards the camera (+z), "
    "u = 0.25 towards the camera's right (+x), row 0 the zenith (+y)",
    "positive_rotation": "right-handed about +y (counter-clockwise seen from above): "
    "a light in front (+z) moves to the camera's right (+x) at +90 degrees",
    "convention": "Mitsuba 3 envmap, to_world = rotate(+y, degrees)",
}
"""The IBL orientation every proof and exported scene uses (module docstring)."""
GENERATOR_VERSION = 1  # bump when the generator's maths changes: invalidates the cache
DEFAULT_WIDTH = 512
REAL_HDR = Path(__file__).resolve().parents[2] / "tests" / "data" / "venice_sunset_1k.hdr"
"""A real sky (Poly Haven's Venice Sunset, CC0; source beside it in ``tests/data``): the
standing real-light IBL of the proof tests and of ``lookdev bench error``. Present in a
source checkout, not in an installed wheel."""
SUFFIXES = (".exr", ".hdr")

Rgb = tuple[float, float, float]


class IblError(LookdevError):
    """An IBL name, definition or file cannot be used."""


# -- definitions ---------------------------------------------------------------------------
class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class Gradient(_Strict):
    """Background radiance blending horizon → zenith above and horizon → ground below."""

    zenith: Rgb
    horizon: Rgb
    ground: Rgb
    sharpness: float = Field(1.0, gt=0, description="Exponent on |y|: > 1 hugs the horizon.")


class CieSky(_Strict):
    """CIE S 011/E:2003 standard general sky: relative luminance from five coefficients.

    L(Z, χ)/L_z = f(χ) φ(Z) / (f(Z_s) φ(0)) with φ(Z) = 1 + a·exp(b / cos Z) and
    f(χ) = 1 + c·(exp(dχ) − exp(dπ/2)) + e·cos²χ (Z: zenith angle, χ: angle to the sun).
    Type 12 (clear, low turbidity) is a=−1, b=−0.32, c=10, d=−3, e=0.45; type 1 (overcast,
    steep gradation towards the zenith) is a=4, b=−0.7, c=0, d=−1, e=0.
    """

    a: float
    b: float
    c: float
    d: float
    e: float
    zenith: Rgb = Field(description="Radiance at the zenith.")
    horizon_tint: Rgb = Field((1.0, 1.0, 1.0), description="Colour multiplier at the horizon.")


class Sun(_Strict):
    """A disc of given irradiance (at normal incidence), spread over ≥ 2 pixels."""

    azimuth: float
    elevation: float = Field(ge=-90, le=90)
    irradiance: Rgb
    angular_diameter: float = Field(0.53, gt=0, le=30, description="Degrees.")


class SoftBox(_Strict):
    """A rectangular area light seen from the subject, with smooth edges."""

    name: str = ""
    azimuth: float
    elevation: float = Field(ge=-90, le=90)
    width: float = Field(gt=0, lt=180, description="Angular width, degrees.")
    height: float = Field(gt=0, lt=180, description="Angular height, degrees.")
    radiance: Rgb
    softness: float = Field(0.15, ge=0, le=1, description="Edge falloff, fraction of size.")


class Ground(_Strict):
    """A diffuse ground below the horizon lit by everything above (radiance = ρ·E/π)."""

    albedo: Rgb


class IblDefinition(_Strict):
    """One built-in IBL: the sum of its parts, scaled by 2^exposure."""

    name: str
    description: str = ""
    exposure: float = 0.0
    background: Gradient | None = None
    sky: CieSky | None = None
    sun: Sun | None = None
    ground: Ground | None = None
    lights: list[SoftBox] = Field(default_factory=list)


def definitions_folder() -> Path:
    """``presets/ibl`` of this checkout or installation."""
    import lookdev.presets

    return Path(next(iter(lookdev.presets.__path__))) / "ibl"


def builtin_names() -> list[str]:
    """Names of the built-in IBLs, sorted."""
    return sorted(p.stem for p in definitions_folder().glob("*.toml"))


def definition(name: str) -> IblDefinition:
    """The parsed definition of built-in IBL ``name``; one-line errors."""
    path = definitions_folder() / f"{name}.toml"
    if not path.is_file():
        raise IblError(
            f"not a built-in IBL nor an existing .exr/.hdr file; built-ins: "
            f"{', '.join(builtin_names())}",
            where=name,
        )
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
        return IblDefinition.model_validate(data)
    except tomllib.TOMLDecodeError as exc:
        raise IblError(f"not valid TOML ({exc})", where=str(path)) from None
    except ValidationError as exc:
        raise one_line(exc, IblError, where=str(path)) from None


# -- generation ----------------------------------------------------------------------------
def directions(width: int) -> tuple[np.ndarray, np.ndarray]:
    """Unit directions (H, W, 3) where Mitsuba's envmap shows each pixel; solid angles (H, W).

    Mitsuba 3.9's envmap puts column i at u = (i + ½)/W but row j at v = j/(H − 1): the
    first row is the zenith itself and the last the nadir (measured in
    tests/pipeline/proof/test_ibl.py). Solid angles are the trapezoid rule's weights on that grid.

    >>> d, omega = directions(64)
    >>> bool(abs(omega.sum() - 4 * math.pi) < 0.05), d[0, 0].round(6).tolist()
    (True, [0.0, 1.0, -0.0])
    """
    height = width // 2
    phi = (np.arange(width) + 0.5) / width * 2.0 * math.pi
    theta = np.arange(height) / (height - 1) * math.pi
    st, ct = np.sin(theta)[:, None], np.cos(theta)[:, None]
    d = np.stack(np.broadcast_arrays(np.sin(phi) * st, ct, -np.cos(phi) * st), axis=-1)
    omega = (
        (2.0 * math.pi / width) * (math.pi / (height - 1)) * np.broadcast_to(st, (height, width))
    )
    return d, omega


def direction(azimuth: float, elevation: float) -> np.ndarray:
    """Unit vector towards (azimuth, elevation) in degrees (module docstring convention)."""
    az, el = math.radians(azimuth), math.radians(elevation)
    return np.array([math.sin(az) * math.cos(el), math.sin(el), math.cos(az) * math.cos(el)])


def envmap_to_world(degrees: float = 0.0) -> Any:
    """The envmap's ``to_world`` at lighting rotation ``degrees`` (:data:`ORIENTATION`)."""
    import mitsuba as mi

    return mi.ScalarTransform4f().rotate([0.0, 1.0, 0.0], float(degrees))


def _smooth_step(x: np.ndarray) -> np.ndarray:
    x = np.clip(x, 0.0, 1.0)
    return x * x * (3.0 - 2.0 * x)


def gradient(g: Gradient, d: np.ndarray) -> np.ndarray:
    y = d[..., 1:2]
    t = np.abs(y) ** g.sharpness
    far = np.where(y >= 0, np.asarray(g.zenith), np.asarray(g.ground))
    return (1.0 - t) * np.asarray(g.horizon) + t * far


def cie_sky(s: CieSky, d: np.ndarray, sun_dir: np.ndarray) -> np.ndarray:
    """Upper-hemisphere radiance of the CIE general sky (zero below the horizon)."""
    cos_z = np.clip(d[..., 1], 1e-3, 1.0)
    z = np.arccos(cos_z)
    chi = np.arccos(np.clip(d @ sun_dir, -1.0, 1.0))
    zs = math.acos(float(np.clip(sun_dir[1], -1.0, 1.0)))

    def gradation(cz: np.ndarray | float) -> np.ndarray:
        return 1.0 + s.a * np.exp(s.b / cz)

    def indicatrix(x: np.ndarray | float) -> np.ndarray:
        return 1.0 + s.c * (np.exp(s.d * x) - math.exp(s.d * math.pi / 2)) + s.e * np.cos(x) ** 2

    rel = indicatrix(chi) * gradation(cos_z) / (indicatrix(zs) * gradation(1.0))
    tint = 1.0 + (np.asarray(s.horizon_tint) - 1.0) * (z / (math.pi / 2))[..., None]
    radiance = np.clip(rel, 0.0, None)[..., None] * np.asarray(s.zenith) * tint
    return np.where(d[..., 1:2] > 0, radiance, 0.0)


def sun_disc(sun: Sun, d: np.ndarray, omega: np.ndarray, width: int) -> np.ndarray:
    """The sun as a disc whose pixels integrate exactly to its irradiance."""
    axis = direction(sun.azimuth, sun.elevation)
    radius = max(math.radians(sun.angular_diameter) / 2, 2.0 * 2.0 * math.pi / width)
    angle = np.arccos(np.clip(d @ axis, -1.0, 1.0))
    weight = _smooth_step((radius - angle) / (0.25 * radius) + 0.5)
    cosine = np.clip(d @ axis, 0.0, None)
    norm = float((weight * cosine * omega).sum())
    if norm <= 0.0:
        return np.zeros((*weight.shape, 3))
    return weight[..., None] * (np.asarray(sun.irradiance) / norm)


def soft_box(box: SoftBox, d: np.ndarray) -> np.ndarray:
    """Radiance of one soft box: a rectangle in the box's own angular coordinates."""
    c = direction(box.azimuth, box.elevation)
    right = np.cross([0.0, 1.0, 0.0], c)
    right = right / np.linalg.norm(right) if np.linalg.norm(right) > 1e-6 else np.array([1.0, 0, 0])
    up = np.cross(c, right)
    front = d @ c
    u = np.degrees(np.arctan2(d @ right, front))
    v = np.degrees(np.arctan2(d @ up, front))
    soft = max(box.softness, 1e-3)

    def edge(x: np.ndarray, size: float) -> np.ndarray:
        return _smooth_step((size / 2 - np.abs(x)) / (soft * size) + 0.5)

    mask = edge(u, box.width) * edge(v, box.height) * (front > 0)
    return mask[..., None] * np.asarray(box.radiance)


def generate(defn: IblDefinition, width: int = DEFAULT_WIDTH) -> np.ndarray:
    """The lat-long image (H, W, 3) float32 of a definition, exposure folded in."""
    d, omega = directions(width)
    rgb = np.zeros((*omega.shape, 3))
    if defn.background is not None:
        rgb += gradient(defn.background, d)
    sun_dir = direction(defn.sun.azimuth, defn.sun.elevation) if defn.sun else np.array([0, 1, 0])
    if defn.sky is not None:
        rgb += cie_sky(defn.sky, d, sun_dir)
    if defn.sun is not None:
        rgb += sun_disc(defn.sun, d, omega, width)
    for box in defn.lights:
        rgb += soft_box(box, d)
    if defn.ground is not None:
        above = d[..., 1] > 0
        irradiance = (rgb * (d[..., 1] * omega * above)[..., None]).sum(axis=(0, 1))
        rgb = np.where(above[..., None], rgb, np.asarray(defn.ground.albedo) * irradiance / math.pi)
    return (rgb * 2.0**defn.exposure).astype(np.float32)


# -- files ---------------------------------------------------------------------------------
def cache_dir() -> Path:
    """Where generated IBLs live: ``$LOOKDEV_CACHE/ibl`` or ``~/.cache/lookdev/ibl``."""
    root = os.environ.get("LOOKDEV_CACHE") or Path.home() / ".cache" / "lookdev"
    return Path(root) / "ibl"


IBL_SPACE = colour.WORKING_SPACES["lin_rec709"]
"""Built-in IBLs are generated (and cached) in linear Rec.709; :func:`load` converts every
IBL into the working space."""


def _key(defn: IblDefinition, width: int) -> str:
    text = json.dumps([GENERATOR_VERSION, width, defn.model_dump(mode="json")], sort_keys=True)
    return hashlib.sha256(text.encode()).hexdigest()[:12]


def resolve(name_or_path: str | Path, width: int = DEFAULT_WIDTH) -> Path:
    """The lat-long file of an IBL: a user's .exr/.hdr as given, a built-in generated once.

    >>> resolve("studio").suffix
    '.exr'
    """
    path = Path(name_or_path).expanduser()
    if path.suffix.lower() in SUFFIXES:
        if not path.is_file():
            raise IblError("no such IBL file", where=str(path))
        return path
    defn = definition(str(name_or_path))
    out = cache_dir() / f"{defn.name}-{width}-{_key(defn, width)}.exr"
    if not out.is_file():
        try:
            write_exr(generate(defn, width), out, IBL_SPACE)
        except ProofImageError as exc:
            raise IblError(f"cannot cache the IBL ({exc.message})", where=str(out)) from None
    return out


def file_space(path: Path) -> str:
    """The colour space an IBL file declares (its ``colorSpace`` or OpenImageIO's
    ``oiio:ColorSpace``, when the OCIO config knows the name), else :data:`IBL_SPACE`.

    Radiance .hdr files and EXRs without such attributes are taken as linear Rec.709, as
    HDRI sites publish them."""
    import OpenImageIO as oiio

    from lookdev.library.files import quiet_c_stderr

    with quiet_c_stderr():
        inp = oiio.ImageInput.open(str(path))
        if inp is None:
            oiio.geterror()
            return IBL_SPACE
        spec = inp.spec()
        named = [spec.get_string_attribute(a) for a in ("colorSpace", "oiio:ColorSpace")]
        inp.close()
    for name in named:
        if name and colour.config().getColorSpace(name) is not None:
            return colour.canonical(name)
    return IBL_SPACE


def _cached(path: Path) -> bool:
    """True for a generated IBL in the cache (which lookdev may delete and regenerate)."""
    return path.parent == cache_dir() and path.suffix == ".exr"


@dataclass(frozen=True)
class Environment:
    """An IBL ready to render: its name, file and pixels (H, W, 3) float32."""

    name: str
    source: Path
    pixels: np.ndarray


def read_image(path: Path) -> np.ndarray:
    """An .exr/.hdr as (H, W, 3) float32 RGB; NaN and negative pixels become 0."""
    from .contact import ProofImageError, read_rgb

    try:
        pixels = read_rgb(path)
    except ProofImageError as exc:
        raise IblError(exc.message, where=str(path)) from None
    return np.clip(np.nan_to_num(pixels, nan=0.0, posinf=0.0), 0.0, None).astype(np.float32)


def check_latlong(pixels: np.ndarray, path: Path | str) -> None:
    """Refuse, in one line, an image that is not a 2:1 lat-long map (a square EXR, a
    cube-map cross, a photo): resampled to 2:1 it would be stretched without a word."""
    h, w = pixels.shape[:2]
    if w != 2 * h:
        raise IblError(
            f"{w}×{h} is not a lat-long map (width must be twice the height)", where=str(path)
        )


def resample(pixels: np.ndarray, width: int) -> np.ndarray:
    """Lat-long pixels at ``width`` × ``width/2`` (OpenImageIO's filtered resize)."""
    import OpenImageIO as oiio

    height = width // 2
    if pixels.shape[:2] == (height, width):
        return pixels
    src = oiio.ImageBuf(np.ascontiguousarray(pixels))
    dst = oiio.ImageBufAlgo.resize(src, roi=oiio.ROI(0, width, 0, height, 0, 1, 0, 3))
    return np.clip(dst.get_pixels(oiio.FLOAT), 0.0, None).astype(np.float32)


def load(
    name_or_path: str | Path, width: int = DEFAULT_WIDTH, exposure: float = 0.0
) -> Environment:
    """An IBL at ``width`` × ``width/2`` pixels with ``exposure`` stops folded in."""
    if width < 8 or width % 2:
        raise IblError(f"width {width} must be even and at least 8", field="width")
    path = resolve(name_or_path, width)
    try:
        image = read_image(path)
        if _cached(path) and image.shape[:2] != (width // 2, width):
            raise IblError(f"{image.shape[1]}×{image.shape[0]}, not {width}×{width // 2}")
    except IblError as exc:
        if not _cached(path):
            raise
        # A cached IBL that does not decode or has the wrong size (a killed write, a
        # copied cache): regenerate it instead of failing every proof under it.
        logging.getLogger("lookdev").warning(
            "lookdev: note: cached IBL %s was unusable (%s); regenerated", path, exc.message
        )
        path.unlink(missing_ok=True)
        path = resolve(name_or_path, width)
        image = read_image(path)
    check_latlong(image, path)
    # the proof renders in the working space: an ACEScg one gets the IBL converted (OCIO)
    pixels = colour.to_working(resample(image, width), file_space(path))
    pixels = np.clip(pixels, 0.0, None) * np.float32(2.0**exposure)
    name = path.stem if Path(str(name_or_path)).suffix.lower() in SUFFIXES else str(name_or_path)
    return Environment(name, path, pixels)
