"""Which lobes of a material carry weight, and its parameters with the dead ones reset.

"A lobe whose weight is zero everywhere is not … exported" (DESIGN.md). A Disney
material's lobe weights follow Burley 2012 §5 and Schutte 2018 §3: the dielectric part
is weighted ``1 - metallic``; sheen and subsurface sit on the diffuse, which is further
weighted ``1 - spec_trans``; ``diff_trans`` and ``flatness`` exist only on thin surfaces.
Smits' six lobes (Pixar) live where his weights are not zero (:mod:`.pixar`). A parameter
of a dead lobe has no effect, so it is neither written nor compared. Weights are judged as
USD stores them (float32).

>>> from lookdev.materials.params import DisneyParams
>>> on = active_lobes(canonical(DisneyParams(metallic=1.0, sheen=0.5)))
>>> on["sheen"], on["dielectric"]
(False, False)
"""

from __future__ import annotations

from typing import Any

import numpy as np

from lookdev.materials.params import DisneyParams
from lookdev.materials.pixar import PixarParams

PARAM_LOBE: dict[str, dict[str, str]] = {
    "disney": {
        "specular": "dielectric",
        "specular_tint": "dielectric",
        "ior": "dielectric",
        "sheen": "sheen",
        "sheen_tint": "sheen",
        "sheen_model": "sheen",
        "sheen_roughness": "conty_kulla",
        "clearcoat": "clearcoat",
        "clearcoat_gloss": "clearcoat",
        "spec_trans": "spec_trans",
        "diff_trans": "diff_trans",
        "subsurface": "subsurface",
        "flatness": "flatness",
        "scatter_distance": "scatter",
    },
    "pixar": {
        "back": "diffuse_t",
        "diffuse_t_scale": "diffuse_t",
        "diffuse_scale": "diffuse",
        "specular_scale": "specular",
        "specular_cone_scale": "specular",
        "reflection_scale": "reflection",
        "reflection_cone_scale": "reflection",
        "specular_t_scale": "specular_t",
        "reflection_t_scale": "reflection_t",
        "specular_tint": "highlights",
        "transmission_tint": "transmission",
        "ior": "transmission",
    },
    "pixar_weights": {},  # blended lobe weights: each is its own lobe's weight
}
"""model → parameter → the lobe it belongs to (parameters not listed are always live)."""

DEFAULTS: dict[str, dict[str, Any]] = {
    "disney": {**DisneyParams().model_dump(), "ior": 1.5, "specular": 0.5},
    "pixar": {**PixarParams().model_dump(), "eta": PixarParams().eta},
    "pixar_weights": {
        **dict.fromkeys(("front", "behind", "specN", "specG", "reflN", "reflG"), (0.0,) * 3),
        **dict.fromkeys(("reflTN", "f0"), (0.0,) * 3),
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


def active_lobes(values: dict[str, Any], model: str = "disney") -> dict[str, bool]:
    """lobe → whether it carries any weight, for canonical ``values`` of ``model``."""
    if model == "pixar" and "amp_diffuse" not in values:  # bare parameters: derive weights
        fields = {k: values[k] for k in PixarParams.model_fields if k in values}
        values = {**values, **canonical(PixarParams.parse(fields))}
    v = {k: _stored(x) for k, x in values.items()}
    if model in ("pixar", "pixar_weights"):
        return _pixar_lobes(v)
    dielectric = v["metallic"] < 1.0
    diffuse = dielectric and v["spec_trans"] < 1.0
    spec_trans = dielectric and v["spec_trans"] > 0.0
    subsurface = diffuse and v["subsurface"] > 0.0
    sheen = dielectric and v["sheen"] > 0.0
    return {
        "specular": True,
        "dielectric": dielectric,
        "diffuse": diffuse,
        "sheen": sheen,
        "conty_kulla": sheen and v["sheen_model"] == "conty_kulla",
        "clearcoat": v["clearcoat"] > 0.0,
        "spec_trans": spec_trans,
        "subsurface": subsurface,
        "diff_trans": diffuse and v["thin"] and v["diff_trans"] > 0.0,
        "flatness": diffuse and v["thin"] and v["flatness"] > 0.0,
        "scatter": (spec_trans or subsurface) and not v["thin"] and v["scatter_distance"] > 0,
        "thin": bool(v["thin"]),
    }


def _pixar_lobes(v: dict[str, Any]) -> dict[str, bool]:
    """Smits' six lobes live where their weight amplitude (:mod:`.pixar`) is not zero."""
    on = {lobe: v[f"amp_{lobe}"] > 0.0 for lobe in LOBES_PIXAR}
    on["highlights"] = on["specular"] or on["reflection"]
    on["transmission"] = on["specular_t"] or on["reflection_t"]
    on["dielectric"] = v.get("metallic", 0.0) < 1.0
    return on


LOBES_PIXAR = ("diffuse", "diffuse_t", "specular", "reflection", "specular_t", "reflection_t")


def _stored(x: Any) -> Any:
    """A float as USD stores it (float32): a weight of 1e-50 is written, and read, as 0."""
    return float(np.float32(x)) if isinstance(x, float) else x


def effective(values: dict[str, Any], model: str = "disney", lobes: dict | None = None):
    """``values`` with every parameter of a dead lobe reset to its default.

    Two materials with equal effective values reflect light identically.
    """
    lobes = active_lobes(values, model) if lobes is None else lobes
    owner = PARAM_LOBE[model]
    defaults = DEFAULTS[model]
    return {k: (v if k not in owner or lobes[owner[k]] else defaults[k]) for k, v in values.items()}
