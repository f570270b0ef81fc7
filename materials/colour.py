"""Colour management: the one OpenColorIO config, the working space, and every conversion.

lookdev is scene-linear in a *named* working space (:doc:`/design`, Colour). Every conversion
between colour spaces is an OpenColorIO processor built from one config, so no transfer
curve or primaries matrix is written by hand anywhere in the program:

* the config is ``$OCIO`` when set, else OCIO's built-in ACES studio config
  (:data:`DEFAULT_CONFIG`, pinned so that outputs do not drift with the OCIO release);
  :func:`use` names another one (the CLI's ``--config``) and the working space;
* the working space is linear Rec.709 by default (:data:`WORKING_SPACES`: ``lin_rec709``
  or ``acescg``), named by the config's own colour-space names;
* :func:`convert` moves pixels between any two of the config's spaces, by name or alias
  (``"sRGB - Texture"``, ``"ACEScg"``, ``"Raw"``); :func:`to_working` into the working space;
* :func:`texture_space` names the colour space a texture is read in (the file rule);
* :func:`decode_hex` reads a preset's ``"#rrggbb"`` as sRGB-encoded (``"sRGB - Texture"``);
* :func:`luminance` weighs linear working-space RGB by the Y row of its RGB → CIE XYZ
  matrix, asked of the config (Rec.709: ITU-R BT.709-6 item 3.3);
* :func:`to_display` is the one view transform (an OCIO ``DisplayViewTransform`` from the
  working space to a display and view of the config, looks optional): proofs, contact
  sheets, plots and the review page all show pixels through it, by default through its
  bake into a 3D LUT (:mod:`.colour_lut`);
* :func:`chromaticities` and :func:`interop_id` name a space the way EXR headers and USD
  (``colorSpace:name``) spell it (MaterialX's names are the exporter's:
  :func:`lookdev.pipeline.export.usd.mtlx.mtlx_color_space`).

The default view is the config's own (the studio config: ``sRGB - Display`` /
``ACES 2.0 - SDR 100 nits (Rec.709)``): proofs judge materials under IBLs with a sun, and
their speculars and glass caustics run to hundreds of times diffuse white. Through
``Un-tone-mapped`` (the sRGB curve alone) every such highlight clips, and clipping one
channel before the others turns a hot red into orange and then white (Burley 2012 §6.2);
the ACES 2.0 view rolls highlights off with their hue kept and reaches white only at the
very top. It costs mid-tone brightness (18 % grey shows at code 0.35, not 0.46): a look
judged against albedo values uses ``--view Un-tone-mapped`` or ``--exposure``.

Burley's tint weights ``(0.3, 0.6, 0.1)`` (:data:`lookdev.materials.disney_prepare.
TINT_WEIGHTS`) are not luminance: they are a hue normaliser inside the Disney BRDF, part of
the model.

OCIO reads its own config (a file named by ``$OCIO``, or one compiled into the library);
this module opens no file itself, so ``materials`` stays free of I/O.

>>> luminance((1.0, 1.0, 1.0))
1.0
>>> [round(v, 5) for v in decode_hex("#808080")]
[0.21586, 0.21586, 0.21586]
"""

from __future__ import annotations

import contextlib
import functools
import os
from collections.abc import Iterator
from concurrent.futures import ThreadPoolExecutor
from typing import Any

import numpy as np
import PyOpenColorIO as ocio

from . import colour_lut
from .colour_state import (
    DEFAULT_CONFIG,
    PRESET_LINEAR,
    RAW,
    SRGB_TEXTURE,
    WORKING_SPACES,
    ColourError,
    Settings,
    _current,
    settings,
)
from .errors import argument

__all__ = [
    "DEFAULT_CONFIG",
    "WORKING_SPACES",
    "ColourError",
    "Settings",
    "settings",
    "pinned",
    "use",
    "config",
    "canonical",
    "working_space",
    "convert",
    "convert_codes",
    "to_working",
    "decode_hex",
    "encode_hex",
    "luminance",
    "luminance_weights",
    "is_data",
    "spaces",
    "displays",
    "views",
    "looks",
    "display",
    "view",
    "look",
    "to_display",
    "chromaticities",
    "interop_id",
    "PRESET_LINEAR",
    "texture_space",
]


def pinned() -> Settings:
    """The settings in force with every default spelled out (the config's name, the
    working space, display, view and look as the config names them), for another
    process, whose ``$OCIO`` may differ: ``use(**dataclasses.asdict(pinned()))``."""
    disp, v, names = _view_names()
    return Settings(settings().config_name, working_space(), disp, v, ", ".join(names))


@contextlib.contextmanager
def use(
    config: str | None = None,
    working_space: str | None = None,
    *,
    display: str | None = None,
    view: str | None = None,
    look: str | None = None,
) -> Iterator[Settings]:
    """Use another OCIO config, working space and/or view inside a ``with`` block.

    ``None`` keeps what is in force; every name is checked here, so a typo fails at once
    with one line. Another config resets the display, view and look to its defaults
    unless they are given too.

    >>> with use(working_space="acescg"):
    ...     working_space()
    'ACEScg'
    >>> working_space()
    'Linear Rec.709 (sRGB)'
    """
    old = settings()
    same = config is None or config == old.config
    new = Settings(
        old.config if config is None else config,
        working_space or old.working_space,
        _pick(display, old.display, same),
        _pick(view, old.view, same),
        _pick(look, old.look, same),
    )
    _load(new.config_name)  # fail here, with the name, not at the first conversion
    _current.append(new)
    try:
        _scene_linear(canonical(WORKING_SPACES.get(new.working_space, new.working_space)))
        _view_names()
        yield new
    finally:
        _current.pop()


def _scene_linear(name: str) -> str:
    """``name`` if it can be a working space: scene-referred, linear, not data.

    Parameters are blended, rendered and exported as light, so a display space
    (``sRGB - Display``), an encoded one (``sRGB Encoded Rec.709``, ACEScct) or ``Raw``
    would make every sum wrong. A config that declares no encoding is trusted.
    """
    cs = config().getColorSpace(name)
    display = cs.getReferenceSpaceType() == ocio.REFERENCE_SPACE_DISPLAY
    encoding = cs.getEncoding()
    if display or cs.isData() or encoding not in ("", "scene-linear"):
        kind = "display-referred" if display else "data" if cs.isData() else f"{encoding}-encoded"
        raise ColourError(
            f"{name!r} is {kind}, not a scene-linear working space (e.g. lin_rec709, acescg; "
            "`lookdev colour spaces` lists them)",
            field=argument("working_space"),
        )
    return name


def _pick(given: str | None, old: str, same_config: bool) -> str:
    if given is not None:
        return given
    return old if same_config else ""


@functools.cache
def _load(name: str) -> ocio.Config:
    try:
        return ocio.Config.CreateFromFile(name)
    except Exception as exc:  # OCIO raises its own Exception type for every failure
        first = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        raise ColourError(f"cannot read the OCIO config {name!r}: {first}") from None


def config() -> ocio.Config:
    """The OCIO config in force (see :class:`Settings`)."""
    return _load(settings().config_name)


def canonical(space: str) -> str:
    """The config's name for ``space`` (a name or an alias); a :class:`ColourError` if none.

    >>> canonical("srgb_tx"), canonical("lin_ap1")
    ('sRGB Encoded Rec.709 (sRGB)', 'ACEScg')
    """
    found = _lookup(settings().config_name, space)
    if found is None:
        known = ", ".join(sorted(config().getColorSpaceNames())[:6])
        raise ColourError(
            f"unknown colour space {space!r} in the OCIO config {settings().config_name!r} "
            f"(e.g. {known}, …; `lookdev colour spaces` lists them)"
        )
    return found[0]


@functools.cache
def _lookup(config_name: str, space: str) -> tuple[str, bool] | None:
    # OCIO's look-up by name or alias costs ≈ 0.1 ms (it scans the config); a preset's
    # colours ask it several times each, so the answer (name, is data) is kept
    cs = _load(config_name).getColorSpace(space)
    return None if cs is None else (cs.getName(), bool(cs.isData()))


def working_space() -> str:
    """The config's name of the working space (scene-linear; every parameter lives in it)."""
    ws = settings().working_space
    return canonical(WORKING_SPACES.get(ws, ws))


def is_data(space: str) -> bool:
    """True for a data space (``Raw``): values pass through every conversion unchanged."""
    found = _lookup(settings().config_name, space)
    return bool(found is not None and found[1])


@functools.cache
def _cpu(config_name: str, src: str, dst: str) -> Any:
    # OCIO's default optimisation approximates pow() (sRGB white decodes to 1.000024, out
    # of a colour's range); lossless keeps every 8-bit code within 8e-7 of IEC 61966-2-1.
    processor = _load(config_name).getProcessor(src, dst)
    return processor.getOptimizedCPUProcessor(ocio.OPTIMIZATION_LOSSLESS)


def convert(pixels: Any, src: str, dst: str | None = None) -> np.ndarray:
    """``pixels`` (…, 3) from colour space ``src`` to ``dst`` (default: the working space).

    Float32 out, the input untouched. Data spaces on either side mean no conversion.

    >>> [round(float(v), 5) for v in convert(np.array([0.5, 0.5, 0.5]), "sRGB - Texture")]
    [0.21404, 0.21404, 0.21404]
    """
    src = canonical(src)
    dst = working_space() if dst is None else canonical(dst)
    out = np.array(pixels, dtype=np.float32, copy=True, order="C")
    if src == dst or is_data(src) or is_data(dst):
        return out
    if out.shape[-1:] != (3,):
        raise ColourError(f"colour conversion needs (…, 3) RGB, not shape {out.shape}")
    _cpu(settings().config_name, src, dst).applyRGB(out.reshape(-1))
    return out


def convert_codes(codes: np.ndarray, src: str, dst: str | None = None) -> np.ndarray:
    """Integer-coded RGB ``codes`` (…, 3; uint8 or uint16, code/max is the encoded value)
    from ``src`` to ``dst`` (default: the working space), float32: :func:`convert` of
    ``codes / max``, to within 1e-6.

    A texture of integers has at most 2⁸ or 2¹⁶ values per channel, so where the OCIO
    transform is a per-channel curve followed by a matrix (every display-encoded texture
    space into a scene-linear one: sRGB, gamma, Rec.709 curves; checked, not assumed)
    the conversion is a table lookup per channel then a 3 × 3 matrix, both taken from
    OCIO once per space pair; OCIO's lossless CPU path costs ~0.4 µs a pixel, which a 4K
    UDIM set pays per tile. Where the check fails, it is :func:`convert`.
    """
    codes = np.asarray(codes)
    src = canonical(src)
    dst = working_space() if dst is None else canonical(dst)
    split = _curves_and_matrix(settings().config_name, src, dst, np.iinfo(codes.dtype).max)
    if split is None:
        return convert(codes.astype(np.float32) / np.float32(np.iinfo(codes.dtype).max), src, dst)
    curves, matrix = split
    if curves[0] is curves[1] is curves[2]:  # one curve for all channels (sRGB, gamma)
        out = curves[0][codes]
    else:
        out = np.empty(codes.shape, dtype=np.float32)
        for k in range(3):
            out[..., k] = curves[k][codes[..., k]]
    if matrix is None:
        return out
    flat = out.reshape(-1, 3)
    return (flat @ matrix.T).reshape(out.shape)


@functools.cache
def _curves_and_matrix(config_name: str, src: str, dst: str, top: int) -> tuple | None:
    """(three per-channel curves over the codes 0..top, then a 3 × 3 matrix or None for the
    identity) with ``convert(c / top) = M · (f_r(c_r), f_g(c_g), f_b(c_b))``; None when the
    transform is not of that form (black must stay black, each channel's ramp must move
    along one direction, and a random sample of codes must agree within 1e-6)."""
    if np.abs(convert(np.zeros(3), src, dst)).max() > 0:
        return None
    levels = np.arange(top + 1, dtype=np.float64) / top
    columns, curves = [], []
    for k in range(3):
        ramp = np.zeros((top + 1, 3), dtype=np.float32)
        ramp[:, k] = levels
        out = convert(ramp, src, dst).astype(np.float64)
        column = out[-1]  # the curve is 1 at the top code
        curve = out @ column / (column @ column)
        if np.abs(np.outer(curve, column) - out).max() > 1e-6:
            return None
        columns.append(column)
        curves.append(curve.astype(np.float32))
    matrix = np.array(columns, dtype=np.float64).T
    sample = np.random.default_rng(0).integers(0, top + 1, (4096, 3))
    exact = convert(sample / top, src, dst)
    linear = np.stack([curves[k][sample[:, k]] for k in range(3)], axis=-1)
    if np.abs(linear @ matrix.T - exact).max() > 1e-6:
        return None
    identity = np.allclose(matrix, np.eye(3), rtol=0, atol=1e-7)
    if all(np.array_equal(curves[0], c) for c in curves[1:]):
        curves = [curves[0]] * 3
    return tuple(curves), (None if identity else matrix.astype(np.float32))


def to_working(pixels: Any, space: str) -> np.ndarray:
    """``pixels`` (…, 3) in ``space`` → the working space (float32)."""
    return convert(pixels, space)


def decode_hex(value: str, space: str = SRGB_TEXTURE) -> tuple[float, float, float]:
    """``"#rrggbb"`` (8 bits per channel, encoded in ``space``) → working-space linear RGB."""
    h = value.strip().lstrip("#")
    rgb = [int(h[i : i + 2], 16) / 255.0 for i in (0, 2, 4)]
    return tuple(float(x) for x in convert(rgb, space))


def encode_hex(rgb: Any, space: str = SRGB_TEXTURE) -> str:
    """Working-space linear RGB → ``"#rrggbb"`` encoded in ``space``: :func:`decode_hex`'s
    inverse to 8 bits (a colour outside the encoding's 0..1 is clipped to its edge).

    >>> encode_hex(decode_hex("#808080"))
    '#808080'
    """
    encoded = np.clip(convert(np.asarray(rgb, np.float32), working_space(), space), 0.0, 1.0)
    return "#" + "".join(f"{round(float(v) * 255.0):02x}" for v in encoded)


@functools.cache
def _weights(config_name: str, space: str) -> np.ndarray:
    xyz = _load(config_name).getColorSpace("CIE XYZ-D65 - Display-referred") or None
    target = xyz.getName() if xyz is not None else None
    if target is None:  # a config without an XYZ space: fall back to its luminance coefficients
        return np.array(_load(config_name).getDefaultLumaCoefs(), dtype=np.float64)
    basis = np.eye(3, dtype=np.float32)
    _cpu(config_name, space, target).applyRGB(basis.reshape(-1))
    y = basis[:, 1].astype(np.float64)
    return y / y.sum()


def luminance_weights() -> np.ndarray:
    """The Y weights of linear working-space R, G, B (sum 1): the XYZ matrix's Y row."""
    return _weights(settings().config_name, working_space())


def luminance(rgb: Any) -> Any:
    """Luminance Y of linear working-space RGB over the last axis; 0 for black.

    Summed in float64 (float32 images too); a plain triple gives a float.

    >>> luminance((0.0, 0.0, 0.0)), round(luminance((0.0, 1.0, 0.0)), 4)
    (0.0, 0.7152)
    """
    out = np.asarray(rgb) @ luminance_weights()
    return float(out) if np.ndim(out) == 0 and not isinstance(rgb, np.ndarray) else out


# -- what the config offers ------------------------------------------------------------------
def spaces() -> list[str]:
    """Every colour-space name of the config, in its order."""
    return list(config().getColorSpaceNames())


def displays() -> list[str]:
    """The config's displays, its default first."""
    return list(config().getDisplays())


def views(display_name: str | None = None) -> list[str]:
    """The views of ``display_name`` (default: the display in force), its default first."""
    return list(config().getViews(display_name or display()))


def looks() -> list[str]:
    """The config's look names."""
    return list(config().getLookNames())


def _one_of(kind: str, name: str, known: list[str], command: str, of: str = "") -> str:
    if name in known:
        return name
    folded = {k.casefold(): k for k in known}
    if name.casefold() in folded:  # "un-tone-mapped" is what a user types
        return folded[name.casefold()]
    shown = "; ".join(known[:5]) + ("; …" if len(known) > 5 else "")
    raise ColourError(
        f"unknown {kind} {name!r}{of} in the OCIO config {settings().config_name!r} "
        f"(known: {shown}; `lookdev colour {command}` lists them)"
    )


def _view_names() -> tuple[str, str, tuple[str, ...]]:
    s = settings()
    disp = _one_of("display", s.display, displays(), "views") if s.display else displays()[0]
    known = list(config().getViews(disp))
    v = _one_of("view", s.view, known, "views", f" of {disp!r}") if s.view else known[0]
    names = tuple(n.strip() for n in s.look.split(",")) if s.look.strip() else ()
    if "" in names:
        raise ColourError(
            f"look {s.look!r} has an empty name; give look names separated by commas "
            "(`lookdev colour views` lists them)",
            field=argument("look"),
        )
    return disp, v, tuple(_one_of("look", n, looks(), "views") for n in names)


def display() -> str:
    """The display of the view transform in force (the config's name)."""
    return _view_names()[0]


def view() -> str:
    """The view in force (the config's name)."""
    return _view_names()[1]


def look() -> str:
    """The looks in force, comma-separated (empty: none)."""
    return ", ".join(_view_names()[2])


@functools.cache
def _display_processor(config_name: str, src: str, disp: str, v: str, look_names: str) -> Any:
    cfg = _load(config_name)
    transform = ocio.GroupTransform()
    if look_names:  # looks grade scene-linear pixels, in the look's process space and back
        transform.appendTransform(ocio.LookTransform(src=src, dst=src, looks=look_names))
    transform.appendTransform(ocio.DisplayViewTransform(src=src, display=disp, view=v))
    return cfg.getProcessor(transform)


@functools.cache
def _display_cpu(*key: str) -> Any:
    return _display_processor(*key).getOptimizedCPUProcessor(ocio.OPTIMIZATION_LOSSLESS)


@functools.cache
def _display_lut(*key: str) -> Any:
    """The bake of the view transform ``key`` names (:func:`.colour_lut.baked`), made once;
    None when the view cannot be baked (then it is always exact)."""
    return colour_lut.baked(_display_processor(*key), _display_cpu(*key), _apply_in_parallel)


def to_display(pixels: Any, exposure: float = 0.0, *, exact: bool = False) -> np.ndarray:
    """Scene-linear working-space ``pixels`` (…, 3) → display code values in [0, 1].

    The one view transform: ``2**exposure`` (stops) scales the scene-linear values, then
    the config's ``DisplayViewTransform`` (with the looks in force) to :func:`display` /
    :func:`view` encodes them for the display. NaN, infinite and negative channels show
    black (a renderer's bug, not light); the output is clipped to the display range.

    By default the transform runs through its bake into a 3D LUT (:mod:`.colour_lut`,
    made once per config, working space, display, view and looks): ≈ 10× less CPU, and
    within 1 8-bit code value of the exact processor on 99.996 % of proof pixels, 2 at
    most (mean 0.11); saturated colours at the display gamut's edge can be up to 8 off.
    What is shown as 8-bit pixels takes it; ``exact=True`` runs OCIO's processor itself,
    for display values measured rather than shown (noise estimates). A view the bake
    cannot hold (:func:`.colour_lut.saturates`) is always exact.

    >>> grey = np.array([[0.0], [0.18], [1e30]]).repeat(3, axis=1)
    >>> [round(float(v), 4) for v in to_display(grey, exact=True)[:, 0]]
    [0.0, 0.3492, 1.0]
    >>> bool(np.abs(to_display(grey) - to_display(grey, exact=True)).max() < 1 / 255)
    True
    """
    rgb = np.asarray(pixels, dtype=np.float32)[..., :3]
    if rgb.shape[-1:] != (3,):
        raise ColourError(f"a view transform needs (…, 3) RGB, not shape {rgb.shape}")
    out = _scaled(rgb, exposure)
    disp, v, names = _view_names()
    key = (settings().config_name, working_space(), disp, v, ", ".join(names))
    cpu = None if exact else _display_lut(*key)
    _apply_in_parallel(cpu if cpu is not None else _display_cpu(*key), out.reshape(-1, 3))
    return np.clip(out, 0.0, 1.0, out=out)


def _scaled(rgb: np.ndarray, exposure: float) -> np.ndarray:
    # a new C-ordered float32 array: non-finite and negative channels 0, × 2**exposure
    out = np.ascontiguousarray(np.nan_to_num(rgb, nan=0.0, posinf=0.0, neginf=0.0))
    np.maximum(out, 0.0, out=out)
    if exposure == 0.0:  # in place, in float32: the float64 path below costs ≈ 5 ms a frame
        return out
    scaled = out * np.float64(2.0**exposure)  # float64: no float32 overflow
    return np.minimum(scaled, np.finfo(np.float32).max).astype(np.float32, order="C")


PARALLEL_PIXELS = 1 << 15
"""From this many pixels up, a view transform runs in row blocks on every core."""


@functools.cache
def _pool() -> ThreadPoolExecutor:
    return ThreadPoolExecutor(max_workers=os.cpu_count() or 1, thread_name_prefix="ocio")


def _apply_in_parallel(cpu: Any, pixels: np.ndarray) -> None:
    # ACES 2.0's view costs ≈ 0.6 µs a pixel on one core, a third of a proof frame's
    # display time; PyOpenColorIO releases the GIL, so blocks run on every core
    # (measured 1.9× on 2 cores for a 480×240 frame, bit-identical output)
    blocks = min(os.cpu_count() or 1, max(1, len(pixels) // PARALLEL_PIXELS))
    if blocks == 1:
        cpu.applyRGB(pixels.reshape(-1))
        return
    parts = np.array_split(pixels, blocks)  # views of contiguous rows: converted in place
    list(_pool().map(lambda part: cpu.applyRGB(part.reshape(-1)), parts))


# -- naming a space in files ------------------------------------------------------------------
def interop_id(space: str | None = None) -> str:
    """USD's canonical name of ``space`` (default: the working space), e.g.
    ``lin_rec709_scene``: OCIO 2.5's interop ID, else an alias of that form.

    >>> interop_id(), interop_id("ACEScg"), interop_id(RAW)
    ('lin_rec709_scene', 'lin_ap1_scene', 'data')
    """
    cs = config().getColorSpace(canonical(space) if space else working_space())
    if cs.isData():
        return "data"
    found = cs.getInteropID() if hasattr(cs, "getInteropID") else ""
    if found:
        return found
    canon = [a for a in cs.getAliases() if a.endswith("_scene")]  # USD's canonical form
    return canon[0] if canon else cs.getName()


@functools.cache
def _chromaticities(config_name: str, space: str, interop: str) -> tuple[float, ...]:
    import colour as colour_science  # a maintained table of primaries and white points

    known = colour_science.RGB_COLOURSPACES
    named = known.get(space) or known.get(interop)
    if named is not None:
        xy = np.vstack([named.primaries, named.whitepoint])
    else:  # a space colour-science does not know: its primaries as the config maps them
        basis = np.vstack([np.eye(3), np.ones((1, 3))]).astype(np.float32)
        _cpu(config_name, space, "CIE XYZ-D65 - Display-referred").applyRGB(basis.reshape(-1))
        xy = basis[:, :2] / basis.sum(axis=1, keepdims=True)
    return tuple(round(float(v), 6) for v in xy.reshape(-1))


def chromaticities(space: str | None = None) -> tuple[float, ...]:
    """The EXR ``chromaticities`` of ``space`` (default: the working space): red, green,
    blue and white (x, y), from colour-science's table of the space (the config's own
    mapping to CIE XYZ for a space it does not know).

    >>> chromaticities("ACEScg")
    (0.713, 0.293, 0.165, 0.83, 0.128, 0.044, 0.32168, 0.33767)
    """
    name = canonical(space) if space else working_space()
    if is_data(name):
        raise ColourError(f"{name!r} is data: it has no chromaticities")
    return _chromaticities(settings().config_name, name, interop_id(name))


def texture_space(
    bits_are_integer: bool, drives_colour: bool, declared: str | None, path: str | None = None
) -> str:
    """The colour space a texture file is read in, by the config's name.

    The rule, first match wins:

    1. ``declared`` (the texture's ``colorspace``) when given;
    2. a data map (anything but a colour: roughness, metallic, masks, normals, heights)
       is ``Raw``: it is never colour-converted by default;
    3. the config's own file rules, when the config in force is not lookdev's default
       (``$OCIO`` or ``--config`` named one) and ``path`` matches one of its rules other
       than ``Default``: a studio that wrote rules for its texture names gets them. The
       built-in studio config's rules are for plates (EXR → ACES2065-1), not textures,
       so they are not consulted;
    4. an integer colour map (8 or 16 bits) is ``sRGB - Texture`` (painted maps are
       display-encoded), a float colour map (half, float EXR) is the working space
       (scene-linear maps are written linear, in the space the look is built in).

    >>> texture_space(True, True, None), texture_space(False, True, None)
    ('sRGB Encoded Rec.709 (sRGB)', 'Linear Rec.709 (sRGB)')
    >>> texture_space(True, False, None), texture_space(True, False, "ACEScg")
    ('Raw', 'ACEScg')
    """
    if declared is not None:
        return canonical(declared)
    if not drives_colour:
        return canonical(RAW)
    if path is not None and settings().config_name != DEFAULT_CONFIG:
        cfg = config()
        if not cfg.filepathOnlyMatchesDefaultRule(path):
            found = cfg.getColorSpaceFromFilepath(path)  # (name, rule index) in PyOpenColorIO
            return canonical(found[0] if isinstance(found, tuple) else found)
    return canonical(SRGB_TEXTURE) if bits_are_integer else working_space()
