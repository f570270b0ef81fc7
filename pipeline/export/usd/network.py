"""A small, USD-free description of shading networks, and what feeds them.

Every render context (:mod:`.preview`, :mod:`.mtlx`, :mod:`.ri`) turns a :class:`Source`
into a :class:`Network` of :class:`Node` s; :mod:`.writer` authors those into USD layers
(and :mod:`.mtlx` into standalone ``.mtlx`` documents). Keeping the description apart
from the authoring lets the fast Sdf writer, the naive Usd-API reference of the
benchmark and the MaterialX writer share one set of networks.
"""

from __future__ import annotations

import re
import struct
from collections.abc import Callable
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import numpy as np

from lookdev.materials import registry
from lookdev.materials.errors import LookdevError

from .lobes import DEFAULTS, REGISTRY_MODEL, active_lobes, canonical, effective
from .names import SUBSURFACE_WEIGHT, Slot
from .sheen_lambda import exact_sheen

__all__ = [
    "CONTEXTS",
    "CONTEXT_OUTPUT",
    "Connection",
    "DEFAULT_SPELLING",
    "DISPLACEMENT_OUTPUT",
    "ExportError",
    "F0_KEYS",
    "Image",
    "Interface",
    "LOCAL",
    "LOCAL_SUBSURFACE_M",
    "MaterialSpec",
    "Network",
    "Node",
    "ST_PRIMVAR",
    "Source",
    "TextureFactory",
    "UNIT",
    "WEIGHTS",
    "gtr_as_ggx",
    "lobe_coverage",
    "local_subsurface",
    "loss_note",
    "noted_values",
    "plain_value",
    "prim_name",
    "same",
    "same_or_eq",
    "source_from_params",
    "subsurface_radius",
    "surface_inputs",
    "untargeted",
]

CONTEXT_OUTPUT = {"universal": "surface", "mtlx": "mtlx:surface", "ri": "ri:surface"}
"""render context → the Material's terminal output name (UsdShade convention)."""

CONTEXTS = tuple(CONTEXT_OUTPUT)
DISPLACEMENT_OUTPUT = {
    "universal": "displacement",
    "mtlx": "mtlx:displacement",
    "ri": "ri:displacement",
}
"""render context → the Material's displacement output name (UsdShade convention)."""

F0_KEYS = frozenset(("specular", "ior", "eta"))
"""One quantity in several spellings (Burley's specular, an IOR): mapped when any is."""

DEFAULT_SPELLING = {"disney": "specular", "pixar": "normal_fresnel"}
"""How a preset gives its normal-incidence reflectance unless it gives ``ior``."""

WEIGHTS = frozenset(
    ("sheen", "clearcoat", "spec_trans", "diff_trans", "subsurface", "flatness", "scatter_distance")
)
"""Parameters that switch their own lobe on: written whenever the lobe is live, default
or not, so that a reader can tell a pruned lobe (input absent) from a live one."""


class ExportError(LookdevError):
    """A material cannot be exported as asked (missing texture, unwritable path …)."""


@dataclass(frozen=True)
class Connection:
    """The output ``output`` of node ``node`` in the same material."""

    node: str
    output: str


@dataclass
class Node:
    """One shader: its id, inputs (``name → (type, value or Connection)``) and outputs."""

    name: str
    id: str
    inputs: dict[str, tuple[str, Any]] = field(default_factory=dict)
    outputs: dict[str, str] = field(default_factory=dict)
    custom: dict[str, str] = field(default_factory=dict)
    color_spaces: dict[str, str] = field(default_factory=dict)
    """Input name → colour space of the file it names (USD ``colorSpace`` metadata,
    MaterialX ``colorspace``)."""


@dataclass
class Network:
    """The nodes of one render context and the connection its terminal reads."""

    context: str
    terminal: Connection
    nodes: list[Node]
    displacement: Connection | None = None
    """What the Material's displacement output of this context reads, if anything."""


@dataclass(frozen=True)
class Interface:
    """A Material interface input (``inputs:NAME`` on the Material, holding ``value``)
    that a shader input reads: one override there drives every render context."""

    name: str
    value: Any = None


ST_PRIMVAR = Interface("frame:stPrimvarName", "st")
"""The texture-coordinate primvar every texture reads, on the Material's interface
(the UsdPreviewSurface spec's convention: an override there retargets every reader)."""


@dataclass
class MaterialSpec:
    """Everything written for one material: its networks and its metadata."""

    name: str
    networks: list[Network]
    custom: dict[str, Any]
    size: Any = None
    """The universal context measured against the material (a :class:`.fidelity.Fidelity`),
    when the export measured it: its figures go into the loss note a DCC shows."""

    def interface(self) -> dict[str, tuple[str, Any]]:
        """The Material's interface inputs the networks read: name → (type, value)."""
        out: dict[str, tuple[str, Any]] = {}
        for net in self.networks:
            for node in net.nodes:
                for kind, value in node.inputs.values():
                    if isinstance(value, Interface):
                        out.setdefault(value.name, (kind, value.value))
        return out


def plain_value(value: Any) -> Any:
    """An input's value with an interface reference replaced by the interface's value
    (for writers without interfaces: a standalone ``.mtlx``)."""
    return value.value if isinstance(value, Interface) else value


@dataclass(frozen=True)
class Image:
    """A texture a network reads: a file, and optionally its pixels (for conversions).

    ``write`` marks an image the exporter must write itself (a converted map, a baked
    procedural mask) before the stage that references it. A *referenced* image (the
    preset's own file, :attr:`reference`) is read as it is: ``colorspace`` names its
    encoding (OCIO), ``channel`` the texture output that carries the parameter, and
    ``scale``/``bias`` the affine map from the file's decoded value to the parameter
    (:class:`~lookdev.materials.textures.TextureInput`'s scale, offset and range);
    ``fallback`` is the parameter's mean, read where the file is missing.
    """

    path: Path
    pixels: np.ndarray | None = None
    write: bool = False
    origin: Path | None = None  # a file written elsewhere (a bake) to copy to ``path``
    colorspace: str | None = None
    """OCIO colour space of the file; None: written by lookdev (working space, or data)."""
    channel: str = ""
    """Output read: ``r``, ``g``, ``b``, ``a`` or ``rgb``; "" picks by the input's type."""
    scale: float = 1.0
    bias: float = 0.0
    fallback: Any = None
    wrap: str = "periodic"
    flip_y: bool = False  # a DirectX normal map (green down)
    derived_dir: Path | None = None  # where converted copies of a referenced file go
    reference: bool = False
    """The preset's own file, not a bake: the exporter points at it (or copies it with
    ``--collect``) and converts nothing."""

    @property
    def udim(self) -> bool:
        """True when ``path`` is a ``<UDIM>`` tile pattern."""
        return "<UDIM>" in self.path.name


@dataclass
class Source:
    """What a network needs of a material: values, maps, normal map, lobes.

    ``values`` are canonical (:func:`.lobes.canonical`); ``maps`` maps a parameter to the
    image that varies it (baked blends); ``spelling`` records whether the preset wrote
    ``specular`` or ``ior`` so an import gives back the same spelling.
    """

    name: str
    model: str
    values: dict[str, Any]
    maps: dict[str, Image] = field(default_factory=dict)
    normal_map: Image | None = None
    spelling: str = "specular"
    description: str = ""
    layers: list[Any] = field(default_factory=list)  # live.LiveLayer, bottom first
    notes: list[str] = field(default_factory=list)  # losses every context shares
    live: tuple[str, ...] | None = None
    """The model's live lobes (the blend's, maps included); None: judged from ``values``."""
    record: str = ""
    """The preset it came from, as JSON (:mod:`.record`), carried for an exact import."""
    height: Image | None = None
    """Heights in scene units (value · scale + bias of the image), for displacement."""
    custom: dict[str, Any] = field(default_factory=dict)
    """Values no target expresses, kept in the Material's ``customData`` (``lookdev``) for
    the import (the GTR ``specular_gamma`` and the roughness it was authored with)."""
    size: Any = None
    """The universal context measured against the material (:attr:`MaterialSpec.size`)."""

    @cached_property
    def lobes(self) -> dict[str, bool]:
        """The model's live lobes and the exporter's groups of inputs (:mod:`.lobes`)."""
        mapped = self.maps or self.model == "pixar_weights"  # values are not all it has
        return active_lobes(self.values, self.model, self.live if mapped else None)

    @cached_property
    def live_values(self) -> dict[str, Any]:
        """The values with every parameter of a dead lobe reset to its default."""
        return effective(self.values, self.model, self.lobes)


def source_from_params(name: str, model: str, params: Any, description: str = "") -> Source:
    """A constant material's :class:`Source` (no maps)."""
    spelling = "ior" if getattr(params, "ior", None) is not None else DEFAULT_SPELLING[model]
    source = Source(name, model, canonical(params), spelling=spelling, description=description)
    return untargeted(source)


def untargeted(source: Source) -> Source:
    """``source`` with the values no DCC target has carried in ``customData`` for the
    import: the GTR γ (:func:`gtr_as_ggx`), the exact-Λ sheen (:func:`.sheen_lambda.exact_sheen`)
    and ``energy_compensation``.

    No target has a switch for the specular's multiple scattering: UsdPreviewSurface and
    PxrDisneyBsdf have none, and MaterialX's ``ND_disney_principled`` (its
    ``generalized_schlick_bsdf`` and ``dielectric_bsdf``, pbrlib_defs.mtlx) neither; its
    GLSL reference always applies Turquin's factor (``mx_ggx_energy_compensation``), its
    OSL leaves it to the renderer's closures. So the switch is a named loss
    (:func:`loss_note`) in every context, and kept here so the import gives it back.
    """
    if source.model == "disney" and source.values.get("energy_compensation", False):
        source.custom["energy_compensation"] = True
    return exact_sheen(gtr_as_ggx(source))


def gtr_as_ggx(source: Source) -> Source:
    """A Disney ``specular_gamma`` ≠ 2 (no DCC target has GTR's γ) written as the GGX
    roughness whose highlight is as wide (half maximum of the measured slice,
    :func:`lookdev.materials.highlight.ggx_roughness_like`), with the loss named and
    γ and the authored roughness kept in ``customData`` for the import.
    """
    gamma = source.values.get("specular_gamma", 2.0) if source.model == "disney" else 2.0
    if gamma == 2.0:
        return source
    rough = source.values["roughness"]
    source.custom["specular_gamma"] = float(gamma)
    if "roughness" in source.maps:
        source.notes.append(
            "its roughness map is written as it is, for GGX (γ is kept in customData)"
        )
        return source
    from lookdev.materials.highlight import ggx_roughness_like
    from lookdev.materials.params import DisneyParams

    # The other parameters matter to the measured width only through F and G: the
    # roughness and γ alone, with the Fresnel of a white metal, define the highlight.
    lobe = DisneyParams(metallic=1.0, base_color=(1.0, 1.0, 1.0), roughness=float(rough))
    matched = ggx_roughness_like(lobe.replace(specular_gamma=float(gamma)))
    source.custom["roughness"] = float(rough)
    source.values["roughness"] = matched
    source.notes.append(
        f"its roughness {rough:.4g} is written as the GGX roughness {matched:.4g}, whose "
        "highlight has the same half-maximum width (γ is kept in customData)"
    )
    return source


TextureFactory = Callable[[list[Node], Slot, Image], tuple[str, Any]]
"""Adds the nodes reading one map for ``slot`` and returns the (type, Connection)."""


def surface_inputs(
    source: Source,
    table: tuple[Slot, ...],
    defaults: dict[str, Any] | None,
    nodes: list[Node],
    texture: TextureFactory,
) -> dict[str, tuple[str, Any]]:
    """Inputs of a surface from a name table: only live lobes, only non-default values.

    ``defaults`` are the target's own input defaults (``None``: unknown, author all).
    """
    lobes = source.lobes
    values = source.live_values
    inputs: dict[str, tuple[str, Any]] = {}
    for slot in table:
        if slot.lobe is not None and not lobes[slot.lobe]:
            continue
        if slot.param in source.maps:
            inputs[slot.input] = texture(nodes, slot, source.maps[slot.param])
            continue
        value = slot.to_target(values[slot.param])
        at_default = defaults is not None and same_or_eq(value, defaults.get(slot.input))
        if at_default and slot.param not in WEIGHTS:
            continue
        inputs[slot.input] = (slot.type, _interface(slot, value))
    return inputs


LOCAL_SUBSURFACE_M = 1e-3
"""The radius (metres) written for Burley 2012's subsurface when a preset gives no
``scatter_distance``: his subsurface is a local flattening of the diffuse (§5.3), light
does not travel, so a renderer's diffusion radius must be small against the shading
(1 mm; skin's mean free paths are of that order). MaterialX's default, one scene unit
(1 m at metersPerUnit 1), made skin and marble glow through."""

LOCAL = "local"
"""Shader ``customData`` ``subsurface_radius`` value marking :data:`LOCAL_SUBSURFACE_M`
(so an import reads it back as no distance)."""

UNIT = "m"
"""lookdev's length unit: ``scatter_distance`` is in metres (the proof scene's unit); an
export divides lengths by the stage's ``metersPerUnit``."""


def local_subsurface(source: Source) -> bool:
    """True when only Burley 2012's distance-less subsurface is live (no distance given)."""
    lobes = source.lobes
    return (
        bool(lobes.get("subsurface"))
        and not lobes.get("scatter")
        and ("scatter_distance" not in source.maps)
    )


def subsurface_radius(
    source: Source, inputs: dict[str, tuple[str, Any]], name: str, meters_per_unit: float
) -> str:
    """Write a Disney target's subsurface: the radius input ``name`` in the stage's units
    and, for a solid's interior, the weight; the sentence naming what that loses, or ``""``.

    A solid with a scatter distance (Burley 2015, :mod:`lookdev.materials.subsurface`)
    sends its whole diffuse into its interior medium, as ND_disney_principled and
    PxrDisneyBsdf do at ``subsurface`` 1 (they mix diffuse and subsurface by it), so the
    weight is written 1 whatever the preset's 2012 ``subsurface`` (which the model then
    ignores); the radius is ``scatter_distance · scatter_distance_scale`` per channel
    (metres, :data:`UNIT`) ÷ ``metersPerUnit``. Where only the 2012 subsurface is live
    (no distance given), :data:`LOCAL_SUBSURFACE_M` instead.
    """
    from lookdev.materials.subsurface import scatter_distances

    lobes = source.lobes
    lost = []
    if lobes.get("scatter"):
        inputs[SUBSURFACE_WEIGHT] = ("float", 1.0)
        if lobes.get("spec_trans"):
            lost.append(
                f"the glass (spec_trans) enters no medium there: {name} scatters the diffuse only"
            )
    if "scatter_distance" in source.maps:
        if meters_per_unit != 1.0:
            lost.append(
                f"{name} is the scatter_distance map in metres, not scaled to "
                f"metersPerUnit {meters_per_unit:g}"
            )
        scale = source.live_values["scatter_distance_scale"]
        if "scatter_distance_scale" in source.maps or len(set(scale)) > 1:
            lost.append(f"{name} is the scatter_distance map, grey: no scatter_distance_scale")
        return "; ".join(lost)
    if lobes.get("scatter"):
        values = source.live_values
        if "scatter_distance_scale" in source.maps:
            lost.append(f"{name} takes the mean of the scatter_distance_scale map")
        params = SimpleNamespace(
            scatter_distance=values["scatter_distance"],
            scatter_distance_scale=values["scatter_distance_scale"],
        )
        radius = scatter_distances(params) / meters_per_unit
        inputs[name] = ("color3f", tuple(float(x) for x in radius))
        return "; ".join(lost)
    if local_subsurface(source):
        d = LOCAL_SUBSURFACE_M / meters_per_unit
        inputs[name] = ("color3f", (d, d, d))
        return (
            f"Burley 2012's subsurface has no distance (a local flattening of the diffuse); "
            f"{name} is written as {LOCAL_SUBSURFACE_M * 1e3:g} mm ({d:g} scene units at "
            f"metersPerUnit {meters_per_unit:g}), so light travels little"
        )
    return ""


def _interface(slot: Slot, value: Any) -> Any:
    """A value taken as it is (no conversion) sits on the Material's interface under the
    parameter's name, so one override drives every context; converted values stay on
    the shader (the contexts would disagree on one interface value)."""
    from .names import _same

    if slot.to_target is _same and not isinstance(value, str):
        return Interface(slot.param, value)
    return value


def same(a: Any, b: Any) -> bool:
    """Equal as USD would store them (float32), for values and colour triples.

    >>> same(0.1, 0.1 + 1e-12), same((1.0, 0.5, 0.0), (1.0, 0.5, 1e-3))
    (True, False)
    """
    if isinstance(a, tuple) or isinstance(b, tuple):
        return (
            isinstance(a, tuple)
            and isinstance(b, tuple)
            and len(a) == len(b)
            and all(map(same, a, b))
        )
    return _f32(a) == _f32(b)


def _f32(x: Any) -> float:
    try:
        return _FLOAT32.unpack(_FLOAT32.pack(x))[0]
    except OverflowError:  # beyond float32: stored as infinity
        return float(np.float32(x))


_FLOAT32 = struct.Struct("f")


def loss_note(source: Source, context: str, mapped: set[str], extra: str = "") -> str:
    """One sentence naming the live parameters ``context`` cannot express, or ``""``."""
    values = source.live_values
    defaults = DEFAULTS[source.model]
    lost = sorted(
        k
        for k in defaults
        if k not in mapped and k not in F0_KEYS and not same_or_eq(values[k], defaults[k])
    )
    parts = []
    if lost:
        shown = ", ".join(f"{k}={_short(values[k])}" for k in lost)
        parts.append(f"{context} cannot express {shown}")
    if extra:
        parts.append(extra)
    return "; ".join(parts + source.notes)


_NOTED = re.compile(r"\b([a-z_]+)=([A-Za-z_]+|[-+]?[0-9][0-9.eE+-]*)(?=[,;\s]|$)")


def noted_values(doc: str, keys: tuple[str, ...]) -> dict[str, Any]:
    """The scalar values of ``keys`` that :func:`loss_note` named (``key=value``) in a
    Material's ``doc``: what a DCC keeps of a value no network carries when it drops
    lookdev's ``customData``. Words stay strings; ``True``/``False`` become bools.

    >>> noted_values("mtlx: X cannot express sheen_model=conty_kulla, sheen_roughness=0.7",
    ...              ("sheen_model", "sheen_roughness"))
    {'sheen_model': 'conty_kulla', 'sheen_roughness': 0.7}
    """
    out: dict[str, Any] = {}
    for key, text in _NOTED.findall(doc or ""):
        if key not in keys or key in out:
            continue
        if text in ("True", "False"):
            out[key] = text == "True"
        elif text[0].isalpha() or text[0] == "_":
            out[key] = text
        else:
            try:
                out[key] = float(text)
            except ValueError:
                continue
    return out


def lobe_coverage(source: Source, context: str, preview_opacity: str = "keep") -> dict[str, str]:
    """Each of the model's lobes in ``context``: ``"dead"`` (no weight: nothing written),
    ``"written"`` (live, and the context carries it: a base lobe, or one of the
    parameters that switch it on is mapped), or ``"lost"`` (live, and no switch of it is
    expressible: :func:`loss_note` names them). No lobe is live and silently missing.
    ``preview_opacity`` as for the universal context's build (transmission is lost
    there unless ``"transmission"`` asks for the spec's opacity reading).
    """
    from .names import mapped_params

    model = registry.MODELS[REGISTRY_MODEL[source.model]]
    mapped = mapped_params(context, source.model, preview_opacity)
    out = {}
    for lobe in model.lobes:
        if not source.lobes[lobe.name]:
            out[lobe.name] = "dead"
        elif not lobe.switches or mapped & set(lobe.switches):
            out[lobe.name] = "written"
        else:
            out[lobe.name] = "lost"
    return out


def same_or_eq(a: Any, b: Any) -> bool:
    if isinstance(a, str | bool) or isinstance(b, str | bool) or a is None or b is None:
        return a == b
    return same(a, b)


def _short(v: Any) -> str:
    if isinstance(v, float):
        return f"{v:g}"
    if isinstance(v, tuple):
        return "(" + ", ".join(f"{x:g}" for x in v) + ")"
    return str(v)


def prim_name(name: str) -> str:
    """A USD prim name for a preset name (``-`` and a leading digit are not allowed).

    >>> prim_name("car-paint"), prim_name("3m_tape")
    ('car_paint', '_3m_tape')
    """
    safe = re.sub(r"[^A-Za-z0-9_]", "_", name)
    return f"_{safe}" if safe[:1].isdigit() else safe
