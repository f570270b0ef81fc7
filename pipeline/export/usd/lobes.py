"""Which lobes of a material carry weight, and its parameters with the dead ones reset.

"A lobe whose weight is zero everywhere is not … exported" (:doc:`/design`). Which of a
model's lobes live is the model's own rule (:func:`lookdev.materials.registry.live_lobes`);
this module adds the exporter's finer groups of inputs (the dielectric part of the
specular, Conty-Kulla sheen, the 2012 subsurface, flatness on thin sheets, the scatter
distance of a solid). A parameter of a dead lobe has no effect, so it is neither written
nor compared. Values are judged as USD stores them (float32).

>>> from lookdev.materials.params import DisneyParams
>>> on = active_lobes(canonical(DisneyParams(metallic=1.0, sheen=0.5)))
>>> on["sheen"], on["dielectric"]
(False, False)
"""

from __future__ import annotations

from typing import Any

import numpy as np

from lookdev.materials import registry
from lookdev.materials.params import DisneyParams
from lookdev.materials.pixar import PixarParams

__all__ = [
    "DEFAULTS",
    "FINER_GROUPS",
    "REGISTRY_MODEL",
    "active_lobes",
    "canonical",
    "effective",
    "parameter_groups",
]

FINER_GROUPS: dict[str, dict[str, str]] = {
    "disney": {
        "specular": "dielectric",
        "specular_tint": "dielectric",
        "ior": "dielectric",
        "sheen_roughness": "conty_kulla",
        "sheen_lambda": "conty_kulla",
        "subsurface": "subsurface",
        "flatness": "flatness",
        "scatter_distance": "scatter",
        "scatter_distance_scale": "scatter",
    },
}
"""model → parameter → the exporter's group (:func:`active_lobes`) that alone keeps it
live, where that is finer than the model's lobes (the registry's ``Lobe.params``)."""


def parameter_groups(model: str) -> dict[str, tuple[str, ...]]:
    """Parameter → the lobes and groups any one of which keeps it live; parameters not
    listed are always live. The model's own lobes come from the registry."""
    out: dict[str, tuple[str, ...]] = {}
    if model != "pixar_weights":  # blended weights: each is its own lobe's weight
        out.update(registry.parameter_lobes(registry.MODELS[REGISTRY_MODEL[model]]))
    out.update({k: (group,) for k, group in FINER_GROUPS.get(model, {}).items()})
    return out


DEFAULTS: dict[str, dict[str, Any]] = {
    "disney": {**DisneyParams().model_dump(), "ior": 1.5, "specular": 0.5},
    "pixar": {**PixarParams().model_dump(), "eta": PixarParams().eta},
    "pixar_weights": {
        **dict.fromkeys(("front", "behind", "specN", "specG", "reflN", "reflG"), (0.0,) * 3),
        **dict.fromkeys(("reflTN", "f0", "preview_base"), (0.0,) * 3),
        "preview_metallic": 0.0,
        **dict.fromkeys(("spec_roughness", "refl_roughness", "highlight_roughness"), 0.0),
        "eta": PixarParams().eta,
    },
}
"""model → our defaults (Disney: both spellings of the F0; Pixar: the IOR in use, ``eta``)."""


def canonical(params: Any) -> dict[str, Any]:
    """All parameters as plain values, with ``specular`` and ``ior`` both filled in.

    >>> c = canonical(DisneyParams(ior=1.5))
    >>> round(c["specular"], 6), c["ior"]
    (0.5, 1.5)
    """
    data = params.model_dump()
    if isinstance(params, DisneyParams):
        data["specular"] = params.effective_specular
        data["ior"] = params.effective_ior
    if isinstance(params, PixarParams):
        from .pixar import derived

        data["eta"] = params.eta  # the IOR in use: given, or from normal_fresnel
        data.update(derived(params))
    return data


REGISTRY_MODEL = {"disney": "disney", "pixar": "pixar", "pixar_weights": "pixar_layered"}
"""This exporter's model names → the registry's (a Pixar blend is Smits' lobe weights)."""


def active_lobes(
    values: dict[str, Any], model: str = "disney", live: tuple[str, ...] | None = None
) -> dict[str, bool]:
    """lobe → whether it carries any weight, for canonical ``values`` of ``model``.

    The model's own lobes are live as the registry says: ``live`` (a blend's answer, maps
    included), or :func:`lookdev.materials.registry.live_lobes` of ``values`` as USD
    stores them (float32: a weight of 1e-50 is written, and read, as 0). The rest are the
    exporter's finer groups of inputs, each switched by a live lobe and a value.
    """
    if live is None:
        live = _live(values, model)
    on = {lobe.name: lobe.name in live for lobe in registry.MODELS[REGISTRY_MODEL[model]].lobes}
    v = {k: _stored(x) for k, x in values.items()}
    if model in ("pixar", "pixar_weights"):
        on["highlights"] = on["specular"] or on["reflection"]
        on["transmission"] = on["specular_t"] or on["reflection_t"]
        on["dielectric"] = v.get("metallic", 0.0) < 1.0
        return on
    thin = bool(v["thin"])
    # Burley 2015: a solid's scatter distance fills its interior, entered by the diffuse
    # (diff_trans) and the glass (lookdev.materials.subsurface); the 2012 `subsurface`
    # blend is then off (disney_prepare: the whole diffuse enters the medium).
    scatter = (on["spec_trans"] or on["diff_trans"]) and not thin and v["scatter_distance"] > 0
    subsurface = on["diffuse"] and v["subsurface"] > 0.0 and not scatter
    return {
        **on,
        "dielectric": v["metallic"] < 1.0,
        "conty_kulla": on["sheen"] and v["sheen_model"] == "conty_kulla",
        "subsurface": subsurface,
        "flatness": on["diffuse"] and thin and v["flatness"] > 0.0,
        "scatter": scatter,
        # A DCC's subsurface (its weight and colour): the 2012 blend or the interior.
        "subsurface_any": subsurface or scatter,
        "thin": thin,
    }


def _live(values: dict[str, Any], model: str) -> tuple[str, ...]:
    """The registry's live lobes for canonical ``values`` (constants) as USD stores them."""
    target = registry.MODELS[REGISTRY_MODEL[model]]
    fields = target.params_type.model_fields
    given = {k: v for k, v in values.items() if k in fields and v is not None}
    if model == "disney" and "ior" in given and "specular" in given:
        del given["ior"]  # canonical values spell the F0 both ways; the model takes one
    return registry.live_lobes(target, target.params_type.parse(given))


def _stored(x: Any) -> Any:
    """A float as USD stores it (float32): a weight of 1e-50 is written, and read, as 0."""
    return float(np.float32(x)) if isinstance(x, float) else x


def effective(values: dict[str, Any], model: str = "disney", lobes: dict | None = None):
    """``values`` with every parameter of a dead lobe reset to its default.

    Two materials with equal effective values reflect light identically.
    """
    lobes = active_lobes(values, model) if lobes is None else lobes
    owners = parameter_groups(model)
    defaults = DEFAULTS[model]
    return {
        k: (v if k not in owners or any(lobes[g] for g in owners[k]) else defaults[k])
        for k, v in values.items()
    }
