"""``lookdev import usd``: UsdShade networks back into presets.

Reading inverts the name tables of :mod:`.names`: an input that is authored gives its
value through ``Slot.from_target``; one that is not authored takes the target's default
(which is what a renderer would use), except in the RenderMan context, whose defaults
usd-core does not know and where lookdev writes every live input. An input connected to
a texture node gives that texture's file as the parameter's map.

Contexts are read in the order universal, RenderMan, MaterialX, each overriding the
parameters it expresses more faithfully: a foreign ``UsdPreviewSurface`` gives what that
surface can say, an OpenPBR or Standard Surface network what :mod:`.foreign` maps. A
lookdev export gives back its preset exactly, from the record it carries (:mod:`.record`).

The networks come from :func:`.stage_read.read_networks`. A texture feeding an input is
kept as a :class:`~lookdev.materials.textures.TextureInput` (file, channel, colour space,
scale and bias as ``scale``/``offset``, wrap). What a preset cannot hold (alpha and
cut-outs, the normal, emission, occlusion, displacement, an unreadable map) is named as a
loss.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from lookdev.materials.errors import LookdevError
from lookdev.materials.fresnel import ior_to_specular, specular_to_ior
from lookdev.materials.subsurface import split_distances
from lookdev.materials.textures import TextureInput

from .foreign import FOREIGN_SURFACES, preview_extras, read_foreign, specular_workflow
from .lobes import DEFAULTS, active_lobes, effective
from .mtlx_openpbr import mapped_from_disney
from .names import DERIVED_FROM, SURFACE_IDS, table_for
from .network import (
    F0_KEYS,
    LOCAL,
    Connection,
    ExportError,
    MaterialSpec,
    Network,
    Node,
    plain_value,
    same_or_eq,
)
from .pixar import ior_to_normal_fresnel
from .preview import preview_defaults
from .read_maps import image_input, round32, settle_maps, texture_file, texture_input
from .record import network_digest, read_record
from .stage_read import DOC_KEY, PRIM_KEY, colour_spaces, read_networks

__all__ = [
    "F0_SPELLING",
    "Imported",
    "MTLX_PREVIEW",
    "NO_SURFACE",
    "READABLE",
    "READ_ORDER",
    "SKIPPED_WHY",
    "UNTARGETED",
    "import_usd",
    "model_of",
    "refusal",
]

UNTARGETED = ("sheen_model", "sheen_roughness", "sheen_lambda", "specular_gamma")
"""Disney values no network carries (kept in ``customData``); without it, the ones the
Material's ``doc`` names (:func:`.network.noted_values`) are read from there."""
READ_ORDER = ("universal", "ri", "mtlx")
READABLE = {
    "disney": READ_ORDER,
    # PxrSurface and OpenPBR get Smits' derived weights, which do not invert to his
    # parameters: a Pixar material is read from its UsdPreviewSurface, and of OpenPBR
    # only the inputs that take one of his parameters as it is (`clear`, which the
    # preview surface keeps out of `opacity` by default, among them).
    "pixar": ("universal", "mtlx"),
    # A blend of Pixar layers is lobe weights, not parameters: nothing to read back.
    "pixar_weights": (),
}


@dataclass
class Imported:
    """One material read from USD: preset fields, maps, and what was not readable."""

    name: str
    model: str
    params: dict[str, Any]
    maps: dict[str, TextureInput] = field(default_factory=dict)
    contexts: list[str] = field(default_factory=list)
    loss: list[str] = field(default_factory=list)
    document: dict[str, Any] | None = None
    """The whole preset, when the file carried lookdev's record (an exact round trip)."""
    prim: str = ""
    """The Material's prim path in the file (what a refusal names)."""


def _to_preset_space(values: dict[str, Any], space: str, result: Imported) -> None:
    """Colours read in the stage's colour space → linear Rec.709, the space a preset's
    ``[r, g, b]`` is written in (:data:`~lookdev.materials.colour.PRESET_LINEAR`)."""
    from lookdev.materials import colour

    if not space:
        return
    try:
        source = colour.canonical(space)
    except colour.ColourError:
        result.loss.append(f"colour space {space!r} is unknown to the OCIO config: kept as is")
        return
    if colour.canonical(colour.PRESET_LINEAR) == source:
        return
    for key, value in values.items():
        if not (isinstance(value, tuple) and len(value) == 3):
            continue
        converted = np.asarray(colour.convert(value, source, colour.PRESET_LINEAR), float)
        if key == "scatter_distance_scale":  # per channel over the largest, as split_distances
            top = float(converted.max())
            if top > 0.0:
                values["scatter_distance"] = values.get("scatter_distance", 0.0) * top
                converted = converted / top
        clipped = np.clip(converted, 0.0, 1.0)
        if np.max(np.abs(clipped - converted)) > 1e-6:
            shown = ", ".join(f"{c:.4g}" for c in converted)
            result.loss.append(
                f"{key} ({shown}) in linear Rec.709 is outside a preset's [0, 1]: clipped"
            )
        values[key] = tuple(float(v) for v in clipped)


SKIPPED_WHY = {
    "pixar_weights": "a layered Pixar material: composited lobe weights have no preset "
    "parameters; import its layers' presets instead",
}
"""Why a material of a given ``model`` (customData) cannot be imported."""
NO_SURFACE = (
    "no UsdPreviewSurface, ND_disney_principled, PxrDisneyBsdf, OpenPBR, Standard Surface "
    "or glTF PBR surface"
)


def import_usd(
    path: Path, skipped: list[str] | None = None, refused: list[str] | None = None
) -> list[Imported]:
    """Read every material of the USD file ``path`` into presets, as far as it can.

    A material that cannot become a preset (a layered Pixar material, a surface lookdev
    does not read) is never dropped silently: its name and the reason are appended to
    ``skipped``. A value a preset would reject (out of range, NaN, infinity) refuses its
    material, never the file: one line naming the prim, the field and the value is
    appended to ``refused``; an import never clamps silently. When nothing is readable
    the error names every skipped and refused material.
    """
    from pxr import Tf, Usd

    path = Path(path)
    if not path.is_file():
        what = "is a folder, not a USD file" if path.is_dir() else "file does not exist"
        raise ExportError(what, where=str(path))
    try:
        stage = Usd.Stage.Open(str(path))
    except Tf.ErrorException:
        raise ExportError("USD cannot open it", where=str(path)) from None
    found, left, bad = [], [], []
    spaces = colour_spaces(stage)
    for spec in read_networks(stage):
        prim = spec.custom.get(PRIM_KEY, spec.name)
        try:
            imported = _imported(spec, spaces.get(spec.name, ""))
        except LookdevError as exc:
            bad.append(refusal(prim, exc))
            continue
        if imported is None:
            why = SKIPPED_WHY.get(spec.custom.get("model") or model_of(spec.networks), NO_SURFACE)
            left.append(f"{spec.name!r} ({why})")
        else:
            imported.prim = prim
            found.append(imported)
    if skipped is not None:
        skipped.extend(left)
    if refused is not None:
        refused.extend(bad)
    if not found:
        detail = f"; skipped {', '.join(left)}" if left else ""
        detail += f"; refused {'; '.join(bad)}" if bad else ""
        raise ExportError(
            f"no material to import: none has a {NO_SURFACE[3:]}{detail}",
            where=str(path),
        )
    return found


def refusal(prim: str, exc: LookdevError) -> str:
    """The one line naming a refused material's prim, the field and the value."""
    return ": ".join(p for p in (prim, exc.field, exc.message) if p)


def _imported(spec: MaterialSpec, space: str = "") -> Imported | None:
    document = read_record(spec.custom)
    edited = document is not None and spec.custom.get("networks") != network_digest(spec.networks)
    if document is not None and not edited:  # lookdev's own export, as exported
        result = Imported(spec.name, document.get("model", "layered"), {}, document=document)
        result.params = dict(document.get("params", {}))
        result.contexts.append("record")
        return result
    model = spec.custom.get("model") or model_of(spec.networks)
    values = dict(DEFAULTS[model])
    result = Imported(spec.name, model, {})
    if edited:
        result.loss.append(
            "the networks were edited after lookdev exported them: read from the networks, "
            "not from the preset record the file carries"
        )
    by_context = {net.context: net for net in spec.networks}
    spelling = spec.custom.get("spelling") or "ior"
    translated = None  # a foreign surface read into Burley's parameters
    for context in READABLE[model]:
        net = by_context.get(context)
        foreign = _foreign(net) if model == "disney" else None
        exact = mapped_from_disney(foreign) if foreign is not None else False
        if foreign is not None and result.contexts and (exact or "ri" in result.contexts):
            # lookdev's own Disney → OpenPBR mapping, or any OpenPBR beside a PxrDisneyBsdf
            # already read (its record stripped, a file is known by that): the contexts
            # read hold Burley's parameters as they are; the mapping's inverse loses some
            if foreign.custom.get("loss"):
                result.loss.append(f"{context}: {foreign.custom['loss']}")
            result.contexts.append(context)
            continue
        if foreign is not None:
            translated = foreign
            units = spec.custom.get("meters_per_unit", 1.0)
            if _read_foreign(foreign, net, units, values, result):
                spelling = "specular"
            result.contexts.append(context)
            continue
        surface, read_as = _surface(net, context, model), context
        if surface is None and context == "mtlx" and model == "disney":
            surface, read_as = _mtlx_preview(net), "universal"
        if surface is None:
            continue
        units = spec.custom.get("meters_per_unit", 1.0)
        _read_surface(net, surface, read_as, model, values, result, units)
        if read_as == "universal":
            nodes = {n.name: n for n in net.nodes}
            result.loss.extend(preview_extras(surface, nodes, texture_file))
            if model == "disney" and _specular_workflow(surface, values, result):
                spelling = "specular"
        result.contexts.append(context)
        if surface.custom.get("loss"):
            result.loss.append(f"{context}: {surface.custom['loss']}")
    if not result.contexts:
        return None
    if model == "pixar" and document is None and "ri" in by_context:
        result.loss.append(_pixar_unread(model))
    if model == "disney" and document is None:
        _untargeted_from_doc(spec, values, result)
    if model == "disney" and "specular_gamma" in spec.custom:
        # No target has GTR's γ: the writer kept it, and the roughness it was authored
        # with (the surfaces carry the GGX roughness matched to it), in customData.
        values["specular_gamma"] = float(spec.custom["specular_gamma"])
        if "roughness" in spec.custom:
            values["roughness"] = float(spec.custom["roughness"])
    if model == "disney" and spec.custom.get("energy_compensation"):
        values["energy_compensation"] = True  # no target has the switch (network.untargeted)
    if model == "disney" and "sheen_lambda" in spec.custom:
        # The exact-Λ sheen: no target has it; the writer kept it (sheen_lambda module).
        from .sheen_lambda import CARRIED

        values.update({k: spec.custom[k] for k in CARRIED if k in spec.custom})
    _to_preset_space(values, space, result)
    result.params = _preset_params(values, model, spelling)
    if translated is not None:
        _translation_loss(translated, space, result)
    settle_maps(result)
    return result


def model_of(networks: list[Network]) -> str:
    """The model of a Material without lookdev's ``customData`` (a DCC re-saved it), from
    its networks: RenderMan's ``PxrSurface`` at lookdev's ri surface prim is lookdev's
    Pixar model (its layered form when the MaterialX surface is marked a blend);
    anything else is read as Disney (``PxrDisneyBsdf``, ``ND_disney_principled``, and a
    foreign OpenPBR or Standard Surface). Without a ri network an OpenPBR surface does not
    tell lookdev's Pixar export from a Disney one or another tool's, and reads as Disney."""
    from . import ri
    from .mtlx import BLEND_KEY

    surfaces = {
        net.context: next((n for n in net.nodes if n.name == net.terminal.node), None)
        for net in networks
    }
    ids = {context: node.id if node else "" for context, node in surfaces.items()}
    names = {net.context: net.terminal.node for net in networks}
    if ids.get("ri") == SURFACE_IDS[("ri", "pixar")] and names.get("ri") == ri.SURFACE:
        mtlx = surfaces.get("mtlx")
        layered = mtlx is not None and mtlx.custom.get(BLEND_KEY) == "pixar_weights"
        return "pixar_weights" if layered else "pixar"
    return "disney"


def _pixar_unread(model: str) -> str:
    """The loss line of a Pixar material read without its record: the parameters only
    PxrSurface carries, as Smits' derived lobe weights, which do not invert."""
    readable = {
        slot.param
        for context in READABLE[model]
        for slot in table_for(context, model)
        if context == "universal" or slot.param not in DERIVED_FROM
    }
    spelled = F0_KEYS | {F0_SPELLING[model][1]}  # the F0 is read, in any spelling
    unread = sorted(k for k in DEFAULTS[model] if k not in readable | spelled)
    return (
        "ri: without lookdev's record, " + ", ".join(unread) + " are read at their defaults "
        "(PxrSurface carries them only as Smits' derived lobe weights, which do not invert)"
    )


def _untargeted_from_doc(spec: MaterialSpec, values: dict[str, Any], result: Imported) -> None:
    """Without the record: the Disney values no network carries, from the ``doc``'s loss
    lines when they name them; a live sheen whose model nothing names is a named loss."""
    from .network import noted_values

    missing = tuple(k for k in UNTARGETED if k not in spec.custom)
    noted = noted_values(spec.custom.get(DOC_KEY, ""), missing)
    if "sheen_lambda" in noted:
        spec.custom.update(
            {k: noted[k] for k in ("sheen_lambda", "sheen_model", "sheen_roughness") if k in noted}
        )
        noted = {k: v for k, v in noted.items() if k not in spec.custom}
    if "specular_gamma" in noted:
        spec.custom["specular_gamma"] = noted.pop("specular_gamma")
        result.loss.append(
            "specular_gamma read from the Material's doc: the roughness is the GGX one the "
            "networks carry (the authored GTR roughness was in customData)"
        )
    values.update(noted)
    named = "sheen_model" in noted or "sheen_model" in spec.custom
    if values.get("sheen", 0.0) > 0.0 and values.get("sheen_model") == "disney" and not named:
        result.loss.append(
            "no record and no doc name the sheen model: read as Burley's sheen "
            "(sheen_model disney); MaterialX renders ND_disney_principled's sheen as "
            "Conty-Kulla at roughness 0.3"
        )


def _foreign(net: Network | None) -> Node | None:
    """The OpenPBR or Standard Surface shader a network ends in, if it does."""
    if net is None:
        return None
    node = next((n for n in net.nodes if n.name == net.terminal.node), None)
    return node if node is not None and node.id in FOREIGN_SURFACES else None


def _translation_loss(surface: Node, space: str, result: Imported) -> None:
    """The measured albedo loss of an OpenPBR surface, or a Standard Surface as MaterialX's
    translation makes it one (:func:`.openpbr_import.openpbr_values`), read as Burley's
    ``result.params`` (:func:`.fidelity.translation_loss`), in the surface's own colour
    space: the preset's colours are taken back into it (out of Rec.709's gamut an ACEScg
    colour is clipped in the preset, a loss the figure then includes). A surface with
    connected inputs is not measured: the per-texel look is not one material."""
    from lookdev.materials import colour
    from lookdev.materials.params import DisneyParams

    from .fidelity import translation_loss
    from .openpbr_import import AS_OPENPBR_IDS, OPENPBR_IDS, openpbr_values, params_from_values

    if surface.id not in AS_OPENPBR_IDS:
        return  # glTF: lookdev has no model of it to measure
    if any(isinstance(plain_value(v), Connection) for _, v in surface.inputs.values()):
        return
    values, _ = openpbr_values(surface)
    try:
        openpbr, _ = params_from_values(values)
    except LookdevError:  # out of the specification's range: named where it is read
        return
    disney = DisneyParams.parse(result.params).model_dump()
    try:
        source = colour.canonical(space) if space else None
    except colour.ColourError:  # kept as is by the import (named there)
        source = None
    if source is not None and source != colour.canonical(colour.PRESET_LINEAR):
        for key, value in disney.items():
            if isinstance(value, tuple) and len(value) == 3:  # linear: a scale's split too
                back = colour.convert(value, colour.PRESET_LINEAR, source)
                disney[key] = tuple(float(x) for x in back)
    named = "OpenPBR" if surface.id in OPENPBR_IDS else STANDARD_AS_OPENPBR
    line = translation_loss(openpbr, DisneyParams.model_construct(**disney), named)
    if line:
        result.loss.append(f"mtlx: {line}")


STANDARD_AS_OPENPBR = "Standard Surface (as OpenPBR by MaterialX's translation)"
"""How a measured loss names a Standard Surface source (:func:`_translation_loss`)."""


def _read_foreign(surface: Node, net: Network, units: float, values, result: Imported) -> bool:
    """An OpenPBR, Standard Surface or glTF surface into ``values`` and ``result.maps``
    (:func:`.foreign.read_foreign`); True when its F0 is spelled as ``specular`` (a
    specular weight of 0)."""
    from .mtlx import node_defaults

    read, maps, losses = read_foreign(surface, node_defaults(surface.id), units)
    values.update(read)
    if "ior" in read:
        values["specular"] = ior_to_specular(read["ior"])
    nodes = {n.name: n for n in net.nodes}
    for param, (name, conn, scale) in maps.items():
        texture = image_input(nodes, conn, scale) if scale else None
        if texture is None:
            result.loss.append(f"mtlx: {surface.id} {name} is a connected network (not imported)")
        else:
            result.maps[param] = texture
    result.loss.extend(f"mtlx: {line}" for line in losses)
    if read.get("specular") == 0.0 and "ior" not in read:
        values["ior"] = specular_to_ior(0.0)  # F0 0: spelled as Burley's specular 0
        return True
    return False


def _specular_workflow(surface: Node, values: dict[str, Any], result: Imported) -> bool:
    """A foreign UsdPreviewSurface in its specular workflow (:func:`.foreign.specular_workflow`):
    True when it was one."""
    flag = surface.inputs.get("useSpecularWorkflow")
    if flag is None or not flag[1]:
        return False
    colour = surface.inputs.get("specularColor", ("color3f", (0.0, 0.0, 0.0)))[1]
    if isinstance(colour, Connection):
        result.loss.append("universal: specularColor is a texture; its mean is unknown")
        return True
    diffuse = values["base_color"]
    if not isinstance(diffuse, tuple):
        diffuse = (float(diffuse),) * 3
    read, losses = specular_workflow(tuple(diffuse), tuple(colour))
    values.update(read)
    values["ior"] = specular_to_ior(values["specular"])
    result.loss.extend(losses)
    return True


MTLX_PREVIEW = "ND_UsdPreviewSurface_surfaceshader"
"""MaterialX's UsdPreviewSurface: the same inputs as the universal surface, read alike."""


def _mtlx_preview(net: Network | None) -> Node | None:
    if net is None:
        return None
    node = next((n for n in net.nodes if n.name == net.terminal.node), None)
    return node if node is not None and node.id == MTLX_PREVIEW else None


def _surface(net: Network | None, context: str, model: str) -> Node | None:
    if net is None:
        return None
    node = next((n for n in net.nodes if n.name == net.terminal.node), None)
    if node is None or node.id != SURFACE_IDS.get((context, model)):
        return None
    return node


def _read_surface(net, surface, context, model, values, result, units: float = 1.0) -> None:
    """Values of one surface into ``values`` (our names), maps into ``result.maps``.

    Unwritten inputs of a lobe take the target's default only once the written ones
    show the lobe live: lookdev prunes a dead lobe's inputs, and their target defaults
    (MaterialX's ``subsurfaceDistance`` = 1) must not bring it back to life. Lengths
    come back in metres (× the stage's ``units``, metersPerUnit); a radius lookdev wrote
    for Burley 2012's distance-less subsurface (marked on the shader) is no distance.
    """
    defaults = _defaults(context, surface.id)
    nodes = {n.name: n for n in net.nodes}
    table = table_for(context, model)
    has_specular = any(s.param == "specular" for s in table)
    pending = []
    if model == "pixar" and context != "universal":
        table = tuple(s for s in table if s.param not in DERIVED_FROM)
    local = surface.custom.get("subsurface_radius") == LOCAL
    for slot in table:
        if slot.param == "ior" and has_specular:
            continue  # there `ior` only refracts and equals the specular's IOR by construction
        if slot.param == "scatter_distance" and local:
            continue
        given = surface.inputs.get(slot.input)
        if given is not None and isinstance(given[1], Connection):
            texture = texture_input(nodes, given[1], slot)  # None for a live mix chain
            if texture is not None and slot.texture_linear is None:
                result.loss.append(
                    f"{context}: {slot.input} reads the map {texture.texture} through a "
                    f"conversion {slot.param} has no texture form for (not imported)"
                )
            elif texture is not None:
                result.maps.setdefault(slot.param, texture)
        elif given is not None and slot.param == "scatter_distance":
            # RGB in scene units → metres, largest channel and each channel over it.
            radius = np.broadcast_to(np.asarray(given[1], dtype=np.float64), (3,)) * units
            d, values["scatter_distance_scale"] = split_distances(radius)
            values[slot.param] = d
        elif given is not None:
            values[slot.param] = slot.from_target(given[1])
        elif defaults is not None and slot.input in defaults:
            pending.append(slot)
    lobes = active_lobes(values, model)
    for slot in pending:
        if slot.lobe is None or lobes[slot.lobe]:
            values[slot.param] = slot.from_target(defaults[slot.input])
    if lobes.get("scatter") and values.get("subsurface") == 1.0:
        # The weight a solid's interior is written with (:func:`.network.subsurface_radius`),
        # not Burley 2012's blend, which the model ignores there.
        values["subsurface"] = DEFAULTS[model]["subsurface"]
    if has_specular:
        values["ior"] = specular_to_ior(values["specular"])


def _defaults(context: str, node_id: str) -> dict[str, Any] | None:
    """The target's input defaults; None for RenderMan, whose usd-core has none."""
    if context == "universal":
        return preview_defaults()
    if context == "mtlx":
        from .mtlx import node_defaults

        return node_defaults(node_id)
    return None


F0_SPELLING = {
    "disney": ("ior", "specular", ior_to_specular),
    "pixar": ("eta", "normal_fresnel", ior_to_normal_fresnel),
}
"""model → (the IOR value read, the other spelling, the conversion to it)."""


def _preset_params(values: dict[str, Any], model: str, spelling: str) -> dict:
    """Non-default live parameters, the F0 in the preset's own spelling (ior or the other)."""
    live = effective(values, model)
    defaults = DEFAULTS[model]
    read, other, convert = F0_SPELLING[model]
    params = {
        k: round32(v)
        for k, v in live.items()
        if k in defaults and k not in F0_KEYS | {other} and not same_or_eq(v, defaults[k])
    }
    ior = live[read]
    key, value = ("ior", ior) if spelling == "ior" else (other, convert(ior))
    reference = defaults[read] if key == "ior" else defaults[other]
    if not same_or_eq(value, reference):
        params[key] = round32(value)
    return params


def import_as_openpbr(path: Path, refused: list[str] | None = None) -> dict[str, Any]:
    """Material name → :class:`~.reader.Imported` of model ``openpbr`` for every material
    of the USD file ``path`` whose ``mtlx`` surface is an OpenPBR Surface lookdev did not
    map from a Disney material (those keep their record or their Disney reading), or a
    Standard Surface, read as OpenPBR by MaterialX's translation
    (:func:`.openpbr_import.openpbr_values`). A material whose values OpenPBR's ranges
    reject is left out; its refusal line (:func:`refusal`) is appended to ``refused``."""
    from pxr import Usd

    from .openpbr_import import AS_OPENPBR_IDS, openpbr_values, params_from_values

    stage = Usd.Stage.Open(str(path))
    out = {}
    for spec in read_networks(stage):
        net = next((n for n in spec.networks if n.context == "mtlx"), None)
        if net is None:
            continue
        surface = next((n for n in net.nodes if n.name == net.terminal.node), None)
        if surface is None or surface.id not in AS_OPENPBR_IDS or mapped_from_disney(surface):
            continue
        values, notes = openpbr_values(surface)
        try:
            params, more = params_from_values(values, f"{path}: material {spec.name!r}")
        except LookdevError as exc:
            if refused is not None:
                refused.append(refusal(spec.custom.get(PRIM_KEY, spec.name), exc))
            continue
        data = params.model_dump(exclude_defaults=True)
        out[spec.name] = Imported(spec.name, "openpbr", data, contexts=["mtlx"], loss=notes + more)
    return out
