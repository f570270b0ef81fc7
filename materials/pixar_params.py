"""Smits' parameters and lobe weights as schemas ("Reflection Model Design for Wall-E and
Up"): :class:`PixarParams`, what a preset writes, and :data:`PixarLobeWeights`, the twelve
weights a layered stack composites to. The model that evaluates them is :mod:`.pixar`;
they live apart from it so that a preset is checked without the model's array code, as
:mod:`.params` and :mod:`.openpbr_params` are for the other models.
"""

from __future__ import annotations

from typing import Annotated, Any

from pydantic import BeforeValidator, Field, create_model

from .fresnel import f0_to_ior
from .params import Color, Params, parse_color, register_schema
from .pixar_lobes import LN_10

__all__ = [
    "CONE_LOBES",
    "DIELECTRIC_REFL",
    "FALLOFF_LOBES",
    "GRAZING",
    "LOBE_SCALE_MAX",
    "PixarLobeWeights",
    "PixarParams",
    "WEIGHT_NAMES",
    "Weight",
]

DIELECTRIC_REFL = 0.05  # Smits' default normal reflectance of a dielectric

WEIGHT_NAMES = (
    "diffN diffG specN specG reflN reflG diffTN diffTG specTN specTG reflTN reflTG".split()
)


LOBE_SCALE_MAX = 10.0
"""Ceiling of the lobe ``*_scale`` parameters: above 1 a lobe adds energy on purpose (Smits'
"Additional Parameters"); 10 bounds every lobe weight at 10 (surface colour and Fresnel
terms are ≤ 1), so weights, values and albedos stay finite float32 (lookdev check)."""


def _scale(description: str, le: float = LOBE_SCALE_MAX) -> Any:
    if le == LOBE_SCALE_MAX:
        description += f" Up to {LOBE_SCALE_MAX:g}: adds energy above 1, weights stay ≤ 10."
    return Field(1.0, ge=0.0, le=le, description=description)


@register_schema
class PixarParams(Params):
    """Smits' parameters; 0..1 is the plausible range unless a field says otherwise."""

    surface_color: Color = Field((0.5, 0.5, 0.5), description="surfColor, linear RGB.")
    metallic: float = Field(0.0, ge=0.0, le=1.0, description="0 dielectric, 1 metal.")
    roughness: float = Field(0.5, ge=0.0, le=1.0, description="0 mirror-like, 1 all diffuse.")
    clear: float = Field(
        0.0, ge=0.0, le=1.0, description="Share of entering light that passes straight through."
    )
    back: float = Field(
        0.0, ge=0.0, le=1.0, description="Share of scattered light leaving on the far side."
    )
    normal_fresnel: float = _scale(
        "Scales nRefl (0.05 dielectric, surface colour metal); 20 reaches 1.", le=20.0
    )
    grazing_fresnel: float = _scale("Scales gRefl (1): tames hot grazing highlights.", le=1.0)
    specular_tint: Color = Field((1.0, 1.0, 1.0), description="Tint of specular and reflection.")
    transmission_tint: Color = Field(
        (1.0, 1.0, 1.0), description="Tint of transmitted specular and refraction."
    )
    diffuse_scale: float = _scale("Scale of the diffuse lobe (above 1 may add energy).")
    specular_scale: float = _scale("Scale of the specular lobe.")
    reflection_scale: float = _scale("Scale of the reflection lobe.")
    diffuse_t_scale: float = _scale("Scale of the transmitted diffuse lobe.")
    specular_t_scale: float = _scale("Scale of the transmitted specular lobe.")
    reflection_t_scale: float = _scale("Scale of the refraction lobe.")
    specular_cone_scale: float = _scale("Scales the specular cone, (30 r + 5)°.", le=2.5)
    reflection_cone_scale: float = _scale("Scales the reflection cone, 10 r°.", le=2.5)
    ior: float | None = Field(
        None,
        ge=1.0,
        le=10.0,
        description="Refraction of the transmitted lobes; default from 0.05 × normal_fresnel.",
    )

    @property
    def eta(self) -> float:
        """The IOR: given, or the one whose normal reflectance is the dielectric nRefl."""
        if self.ior is not None:
            return self.ior
        return f0_to_ior(DIELECTRIC_REFL * self.normal_fresnel)


GRAZING = "_grazing"
"""Suffix of a weight's value for the view at grazing incidence (s = 1)."""
CONE_LOBES = ("specular", "reflection", "specular_t", "reflection_t")
FALLOFF_LOBES = ("specular", "specular_t")
_Weight = Annotated[float, Field(ge=0.0)]
Weight = Annotated[tuple[_Weight, _Weight, _Weight], BeforeValidator(parse_color)]
"""A lobe weight per channel: ≥ 0, above 1 only where a lobe scale pushed it."""


def _weight_fields() -> dict[str, Any]:
    out = {}
    for name in WEIGHT_NAMES:
        side = "normal" if name.endswith("N") else "grazing"
        out[name] = (
            Weight,
            Field(
                (0.0, 0.0, 0.0), description=f"{name}: weight at {side} incidence, view head-on."
            ),
        )
        out[name + GRAZING] = (
            Weight | None,
            Field(
                None, description=f"{name} for the grazing view; unset: {name} (no view change)."
            ),
        )
    for lobe in CONE_LOBES:
        out[f"{lobe}_cone"] = (
            float,
            Field(20.0, ge=0.0, le=90.0, description=f"Cone of the {lobe} lobe (degrees)."),
        )
    for lobe in FALLOFF_LOBES:
        out[f"{lobe}_falloff"] = (
            float,
            Field(
                LN_10 / 2,
                ge=0.0,
                description=f"−ln of the {lobe} lobe's value at its cone, relative to its "
                "peak (Smits' powerS: r ln 10).",
            ),
        )
    out["ior"] = (
        float,
        Field(PixarParams().eta, ge=1.0, description="IOR of the transmitted lobes' view."),
    )  # unbounded above: PixarParams.eta derives it from nRefl, which may reach 1
    return out


PixarLobeWeights = register_schema(
    create_model(
        "PixarLobeWeights",
        __base__=Params,
        __doc__="Smits' lobe weights as a material's inputs: what compositing a layered "
        "stack produces (lookdev.pipeline.blend.pixar), and what any Pixar material is.",
        **_weight_fields(),
    )
)
