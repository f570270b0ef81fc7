"""Resolved materials: ``extends`` chains followed, layer references loaded, all validated.

A :class:`Material` is what the rest of the pipeline consumes (blending, export, proofs):
a disney or pixar material with validated parameters, or a layered one whose layers are
resolved non-layered materials under masks (Burley §5.7: "a material can be picked from
the library and added … as an additional layer and then blended in with a mask").

Resolution rules (documented for preset authors in ``lookdev presets --help``):

- ``extends``: the parent's parameters, then the child's over them. ``specular`` and
  ``ior`` spell one parameter two ways, so a child giving one drops the parent's other.
  ``description``, ``tags`` and ``source`` are inherited unless the child gives its own;
  ``layers`` likewise (a child's list replaces the parent's whole).
- A layer naming a layered preset contributes that preset's layers, each under the
  product of its own mask and the referencing layer's mask (presence multiplies too).
- All layers of one material share one model: Disney layers blend parameters, Pixar
  layers composite lobe weights, and the two do not mix.
"""

from __future__ import annotations

from collections.abc import Callable
from functools import partial
from pathlib import Path
from typing import Any, Literal

from pydantic import BaseModel, ConfigDict, Field, model_validator

from lookdev.materials.layers import CombineMask, ConstantMask, Mask, TextureMask, map_textures
from lookdev.materials.openpbr_params import OpenPBRParams
from lookdev.materials.params import DisneyParams
from lookdev.materials.pixar_params import PixarParams
from lookdev.materials.textures import UDIM_TOKEN, TextureInput, is_texture_input

from .errors import PresetError, PresetNotFoundError, TextureError
from .index import held_warnings
from .preset import MODELS, PresetFile, split_params

__all__ = [
    "Layer",
    "Lookup",
    "Material",
    "absolute_textures",
    "merge_params",
    "multiply_masks",
    "resolve",
]

Lookup = Callable[[str], tuple[PresetFile, Path]]
"""Finds a preset by name: its parsed file and where it lives."""


class Material(BaseModel):
    """A resolved preset, ready for blending, export and proofing."""

    model_config = ConfigDict(frozen=True)

    name: str
    model: Literal["disney", "pixar", "openpbr", "layered"]
    description: str = ""
    tags: list[str] = Field(default_factory=list)
    params: DisneyParams | PixarParams | OpenPBRParams | None = Field(
        None, description="None when layered."
    )
    textures: dict[str, TextureInput] = Field(
        default_factory=dict,
        description="Parameters driven by textures (paths absolute), checked at load; "
        "``params`` holds the schema default for them.",
    )
    layers: list[Layer] = Field(default_factory=list)
    source: Path | None = None
    citation: str | None = Field(None, description="The preset's `source` note (measurements).")
    chain: list[Path] = Field(default_factory=list, description="Files merged, child first.")
    height: TextureInput | None = Field(
        None, description="Height map (path absolute), in scene units after scale/offset."
    )
    normal_map: TextureMask | None = Field(
        None, description="Tangent-space normal map of a texture set (path absolute)."
    )
    notes: list[str] = Field(
        default_factory=list, description="What the preset's texture set left out, and why."
    )

    def __repr__(self) -> str:
        from .display import material_repr

        return material_repr(self)

    def _repr_html_(self) -> str:
        """The notebook view: parameters, the file of the chain that set each, a swatch."""
        from .display import material_html

        return material_html(self)

    @model_validator(mode="after")
    def _params_fit_the_model(self) -> Material:
        expected = MODELS.get(self.model)
        if (self.params is None) != (expected is None) or (
            expected is not None and not isinstance(self.params, expected)
        ):
            raise ValueError(f"a {self.model} material needs {getattr(expected, '__name__', None)}")
        return self


class Layer(BaseModel):
    """One layer of a layered material: a resolved material under a mask."""

    model_config = ConfigDict(frozen=True)

    material: Material
    mask: Mask = Field(default_factory=ConstantMask)
    presence: float = 1.0
    normal_map: TextureMask | None = None
    specular_normal_map: TextureMask | None = None
    name: str | None = None


Material.model_rebuild()


def resolve(name: str, lookup: Lookup) -> Material:
    """The material ``name`` with its ``extends`` chain and layer references resolved.

    Warnings about its maps are printed once it has resolved: a material that fails
    prints its error alone (:func:`.index.held_warnings`).
    """
    with held_warnings():
        return _resolve(name, lookup, ())


def _resolve(name: str, lookup: Lookup, seen: tuple[str, ...]) -> Material:
    preset, paths = _merge_chain(name, lookup, seen)
    where = str(paths[0])
    common = {
        "name": name,
        "model": preset.model,
        "description": preset.description,
        "tags": list(preset.tags),
        "source": paths[0],
        "citation": preset.source,
        "chain": paths,
    }
    common |= _surface_maps(preset, paths[0])
    if preset.model in MODELS:
        params, textures = _checked(preset.model, _with_set(preset, paths[0]), where=where)
        return _tiles_agree(Material(params=params, textures=textures, **common))
    material = Material(layers=_layers(preset, paths[0], lookup, (*seen, name)), **common)
    return _tiles_agree(material)


def _checked(model: str, params: dict[str, Any], *, where: str, prefix: str = "params"):
    """(constants, textures) of ``params``, every texture opened and its values checked
    (:mod:`.textures`: files, tiles, channels, colour space, range)."""
    constants, textures = split_params(model, params, where=where, prefix=prefix)
    for key, tex in textures.items():
        # the image reader (OpenImageIO) is imported only for a preset that has textures
        from .textures import ParamTexture

        label = f"{prefix}.{key}"
        ParamTexture(tex, key, MODELS[model], where=where, label=label).check()
    return constants, textures


def _tiles_agree(material: Material) -> Material:
    """Every UDIM texture of a material covers the same tiles: a tile one map lacks is a
    hole in the asset (a missing file), not a region another map may cover alone."""
    owners: dict[int, str] = {}
    sets = []
    for label, mat in [(None, material)] + [
        (layer.name, layer.material) for layer in material.layers
    ]:
        for key, tex in mat.textures.items():
            if tex.udim:
                from .textures import ParamTexture

                field = f"{label}: {key}" if label else key
                tiles = set(ParamTexture(tex, key, MODELS[mat.model], where=None).tiles)
                sets.append((field, tex, tiles))
                for t in tiles:
                    owners.setdefault(t, field)
    every = set(owners)
    for field, tex, tiles in sets:
        missing = sorted(every - tiles)
        if missing:
            name = tex.texture.replace(UDIM_TOKEN, str(missing[0]))
            raise TextureError(
                f"missing UDIM tile {missing[0]} ({name} does not exist) of {tex.texture}; "
                f"{owners[missing[0]]} has that tile, and every map of a material covers the "
                "same tiles",
                where=str(material.source) if material.source else None,
                field=field,
            )
    return material


def _merge_chain(name: str, lookup: Lookup, seen: tuple[str, ...]) -> tuple[PresetFile, list[Path]]:
    """Follow ``extends`` from ``name`` to its root and merge child over parent."""
    chain: list[tuple[PresetFile, Path]] = []
    current: str | None = name
    while current is not None:
        names = [*seen, *(p.name for p, _ in chain)]
        if current in names:
            start = names.index(current)
            cycle = " → ".join([*names[start:], current])
            where = str(chain[-1][1]) if chain else None
            # A cycle that starts among the enclosing materials passes through a layer.
            field = "layers" if start < len(seen) else "extends"
            raise PresetError(f"cycle of presets: {cycle}", where=where, field=field)
        found, path = _find_parent(current, lookup, chain)
        if found.params:  # texture paths are relative to the file that writes them
            params = absolute_textures(found.params, Path(path).parent)
            found = found.model_copy(update={"params": params})
        chain.append((found, path))
        current = chain[-1][0].extends
    preset = chain[-1][0]
    for child, path in reversed(chain[:-1]):
        preset = _override(preset, child, where=str(path))
    return preset, [p for _, p in chain]


def _find_parent(name: str, lookup: Lookup, chain: list[tuple[PresetFile, Path]]):
    try:
        return lookup(name)
    except PresetNotFoundError as exc:
        if not chain:
            raise
        names = " → ".join([*(p.name for p, _ in chain), name])
        raise PresetNotFoundError(
            f"parent {exc.message} (chain {names})", where=str(chain[-1][1]), field="extends"
        ) from None


def _override(parent: PresetFile, child: PresetFile, *, where: str) -> PresetFile:
    """``child`` over ``parent``: parameters merged, other given fields replaced."""
    if child.model is not None and child.model != parent.model:
        raise PresetError(
            f"model {child.model!r} differs from its parent {parent.name!r} ({parent.model}); "
            "a preset extends one of its own model",
            where=where,
            field="model",
        )
    given = child.model_fields_set
    inherited = ("description", "tags", "source", "layers", "textures", "height")
    update: dict[str, Any] = {k: getattr(child, k) for k in inherited if k in given}
    update["params"] = merge_params(parent.params, child.params)
    if parent.model in MODELS:
        split_params(parent.model, update["params"], where=where)
    return parent.model_copy(update={**update, "name": child.name, "extends": None})


def merge_params(base: dict[str, Any], over: dict[str, Any]) -> dict[str, Any]:
    """``over`` on top of ``base``; giving ``specular`` or ``ior`` drops the other.

    >>> merge_params({"specular": 0.5, "roughness": 0.2}, {"ior": 1.33})
    {'roughness': 0.2, 'ior': 1.33}
    """
    spellings = {"specular": "ior", "ior": "specular"}
    dropped = {spellings[k] for k in over if k in spellings}
    return {**{k: v for k, v in base.items() if k not in dropped}, **over}


def _layers(preset: PresetFile, path: Path, lookup: Lookup, seen: tuple[str, ...]) -> list[Layer]:
    """The resolved layers of a layered preset, bottom to top, texture paths made absolute."""
    where = str(path)
    out: list[Layer] = []
    for i, spec in enumerate(preset.layers):
        field = f"layers[{i}]"
        absolute = partial(_absolute_texture, folder=path.parent)
        common = {
            "mask": map_textures(spec.mask, absolute),
            "presence": spec.presence,
            "normal_map": spec.normal_map and absolute(spec.normal_map),
            "specular_normal_map": spec.specular_normal_map and absolute(spec.specular_normal_map),
        }
        given = absolute_textures(spec.params, path.parent)
        if spec.preset is None:
            params, textures = _checked(spec.model, given, where=where, prefix=f"{field}.params")
            name = spec.name or f"{preset.name}.{field}"
            material = Material(
                name=name, model=spec.model, params=params, textures=textures, source=path
            )
            out.append(Layer(material=material, name=name, **common))
            continue
        inner = _resolve_layer(spec.preset, lookup, seen, where=where, field=f"{field}.preset")
        if inner.model == "layered":
            if spec.params:
                raise PresetError(
                    f"{spec.preset!r} is layered; params overrides apply to disney or pixar "
                    "layers only",
                    where=where,
                    field=f"{field}.params",
                )
            out += [_nest(sub, spec.name or spec.preset, common) for sub in inner.layers]
            continue
        if spec.params:
            below = {**inner.params.model_dump(exclude_unset=True), **inner.textures}
            merged = merge_params(below, given)
            params, textures = _checked(inner.model, merged, where=where, prefix=f"{field}.params")
            inner = inner.model_copy(update={"params": params, "textures": textures})
        out.append(Layer(material=inner, name=spec.name or spec.preset, **common))
    models = sorted({layer.material.model for layer in out})
    if len(models) > 1:
        raise PresetError(
            f"layers mix the models {' and '.join(models)}; all layers of a preset share one "
            "(disney layers blend parameters, pixar layers composite lobes)",
            where=where,
            field="layers",
        )
    return out


def _resolve_layer(name: str, lookup: Lookup, seen, *, where: str, field: str) -> Material:
    try:
        return _resolve(name, lookup, seen)
    except PresetNotFoundError as exc:
        if exc.where is not None:
            raise
        raise PresetNotFoundError(f"layer {exc.message}", where=where, field=field) from None


def _nest(sub: Layer, outer_name: str, outer: dict[str, Any]) -> Layer:
    """A layer of a layered preset used as one layer: masks and presences multiply."""
    return Layer(
        material=sub.material,
        mask=multiply_masks(outer["mask"], sub.mask),
        presence=outer["presence"] * sub.presence,
        normal_map=sub.normal_map or outer["normal_map"],
        specular_normal_map=sub.specular_normal_map or outer["specular_normal_map"],
        name=f"{outer_name}/{sub.name}",
    )


def multiply_masks(a: Mask, b: Mask) -> Mask:
    """The product of two masks, leaving out a factor that is constant 1.

    >>> multiply_masks(ConstantMask(value=1.0), ConstantMask(value=0.5)).value
    0.5
    """
    if isinstance(a, ConstantMask) and a.value == 1.0:
        return b
    if isinstance(b, ConstantMask) and b.value == 1.0:
        return a
    return CombineMask(kind="multiply", inputs=[a, b])


def _absolute_texture(texture: TextureMask, *, folder: Path) -> TextureMask:
    """Texture paths in a preset are relative to its file; consumers get absolute ones."""
    return texture.model_copy(update={"path": (folder / texture.path.expanduser()).resolve()})


def absolute_textures(params: dict[str, Any], folder: Path) -> dict[str, Any]:
    """``params`` with each texture's path made absolute against ``folder`` (the preset
    file's), as mask textures are; ``<UDIM>`` is kept."""
    out = dict(params)
    for key, value in params.items():
        if (
            isinstance(value, dict)
            and is_texture_input(value)
            and isinstance(value["texture"], str)
        ):
            texture = str((folder / Path(value["texture"]).expanduser()).resolve())
            out[key] = {**value, "texture": texture}
        elif isinstance(value, TextureInput):
            texture = str((folder / Path(value.texture).expanduser()).resolve())
            out[key] = value.model_copy(update={"texture": texture})
    return out


def _with_set(preset: PresetFile, path: Path) -> dict[str, Any]:
    """The preset's parameters over its texture set's inputs (:mod:`.texture_sets`)."""
    if preset.textures is None:
        return preset.params
    from .texture_sets import expand

    found = expand(preset.textures, path.parent, where=str(path))
    return {**found.inputs, **preset.params}


def _surface_maps(preset: PresetFile, path: Path) -> dict[str, Any]:
    """Height, normal map and notes of a preset: its own ``height`` (path made absolute)
    over its texture set's."""
    out: dict[str, Any] = {}
    height = preset.height
    if preset.textures is not None:
        from .texture_sets import expand

        found = expand(preset.textures, path.parent, where=str(path))
        out["notes"] = found.notes
        if found.normal_map is not None:
            out["normal_map"] = TextureMask(path=Path(found.normal_map["path"]))
            if found.normal_map["flip_y"]:
                out["notes"].append(
                    "normal map is DirectX (+Y down): its green channel is flipped on read"
                )
        if height is None and found.height is not None:
            height = TextureInput.parse(found.height)
    if height is not None:
        texture = Path(height.texture).expanduser()
        absolute = texture if texture.is_absolute() else path.parent / texture
        out["height"] = height.model_copy(update={"texture": str(absolute)})
    return out
