"""Material parameter schemas (pydantic), shared machinery for every model.

Ranges follow Burley's principles (§5.1): parameters are 0..1 over their plausible range,
may be pushed beyond it where that makes sense, and are rejected where meaningless
(NaN, infinity, negative roughness …) with a one-line :class:`ParameterError` naming the
field and the allowed range. Colours are scene-linear in the working space
(:mod:`.colour`), converted once, here, from the space a preset writes them in: a
``"#rrggbb"`` string is sRGB-encoded (``sRGB - Texture``), a ``[r, g, b]`` triple or a grey
scalar is linear Rec.709 (:data:`~.colour.PRESET_LINEAR`).

>>> DisneyParams(base_color="#ffffff", metallic=1.0).base_color
(1.0, 1.0, 1.0)
>>> round(DisneyParams().effective_ior, 6)
1.5
"""

from __future__ import annotations

import math
import re
from typing import Annotated, Any, Literal

from pydantic import (
    BaseModel,
    BeforeValidator,
    ConfigDict,
    Field,
    ValidationError,
    model_validator,
)

from .colour_state import PRESET_LINEAR, settings
from .errors import ParameterError as ParameterError  # re-exported
from .errors import one_line, register_schema
from .fresnel import SPECULAR_F0_SCALE, ior_to_specular, specular_to_ior

__all__ = [
    "Channel",
    "Color",
    "DisneyParams",
    "Params",
    "SCATTER_DISTANCE_MAX",
    "SCATTER_DISTANCE_MIN",
    "SHEEN_MAX",
    "SPECULAR_GAMMA_MAX",
    "SheenLambda",
    "parse_color",
]

_HEX = re.compile(r"^#?([0-9a-fA-F]{6})$")


def parse_color(value: Any) -> Any:
    """``"#rrggbb"`` (sRGB) or linear Rec.709 ``[r, g, b]`` / grey → the working space."""
    if isinstance(value, str):
        m = _HEX.match(value.strip())
        if not m:
            raise ValueError(f"colour {value!r} is neither '#rrggbb' nor [r, g, b]")
        from .colour import decode_hex  # OCIO decodes it: imported by the presets that need it

        return decode_hex(m.group(1))
    if isinstance(value, int | float) and not isinstance(value, bool):
        value = (float(value),) * 3
    return _from_preset_linear(value)


def _from_preset_linear(value: Any) -> Any:
    """A finite numeric triple converted into the working space; anything else as given,
    for the schema to reject with its own message (NaN, a pair, a string in a list)."""
    try:
        rgb = tuple(float(v) for v in value)
    except (TypeError, ValueError):
        return value
    if len(rgb) != 3 or not all(math.isfinite(v) for v in rgb):
        return value
    ws = settings().working_space  # the default: no look-up (this runs for every colour)
    if ws in ("lin_rec709", PRESET_LINEAR):
        return value  # as written: no float32 round trip
    import numpy as np  # a conversion's float32 pixels: only for another working space

    from .colour import canonical, convert, working_space

    if canonical(PRESET_LINEAR) == working_space():
        return value
    out = convert(rgb, PRESET_LINEAR).astype(np.float64)
    # a colour on a range edge stays on it: OCIO's float32 matrix may land an ulp outside
    edge = np.clip(out, 0.0, 1.0)
    return tuple(float(v) for v in np.where(np.abs(out - edge) < 1e-6, edge, out))


def _unit(default: float, description: str, *, le: float | None = 1.0, ge: float = 0.0):
    return Field(default, ge=ge, le=le, description=description)


SheenLambda = Literal["fit", "exact"]
"""Conty-Kulla's Smith Λ: Table 1's fit (r ≥ 0.08) or the integrated one (r ≥ 0.01),
:mod:`lookdev.materials.sheen`."""
SHEEN_MAX = 10.0
"""Ceiling of Disney ``sheen`` (:doc:`/design`, Ranges: every parameter has a ceiling)."""
SPECULAR_GAMMA_MAX = 10.0
"""Ceiling of Disney ``specular_gamma``. At γ = 10 the GTR lobe is already ≈ 2.3 times narrower
than GGX at the same roughness, and every float32 value of the lobe is finite up to it
(``lookdev check`` sweeps it at roughness 0, where D's peak is 2.9·10⁶)."""
SCATTER_DISTANCE_MIN = 1e-6
SCATTER_DISTANCE_MAX = 1e6
"""Bounds of a non-zero ``scatter_distance``: σt = 1/(s·d) stays a finite float32."""

Channel = Annotated[float, Field(ge=0.0, le=1.0)]
Color = Annotated[tuple[Channel, Channel, Channel], BeforeValidator(parse_color)]


class Params(BaseModel):
    """Base of every parameter schema: strict about unknown names, NaN and infinity."""

    # defaults are validated too: a default colour is linear Rec.709 like a written one,
    # and must reach an ACEScg working space converted
    model_config = ConfigDict(
        extra="forbid", allow_inf_nan=False, frozen=True, validate_default=True
    )

    @classmethod
    def parse(cls, data: dict[str, Any], *, where: str | None = None):
        """Validate ``data``; any problem becomes one :class:`ParameterError` line."""
        try:
            return cls.model_validate(data)
        except ValidationError as exc:
            raise one_line(exc, where=where) from None

    def replace(self, **changes: Any):
        """A validated copy with some parameters changed."""
        data = self.model_dump(exclude_unset=True)
        data.update(changes)
        return type(self).parse(data)


@register_schema
class DisneyParams(Params):
    """Burley 2012 (+ 2014 addenda) principled BRDF and the 2015 BSDF extension.

    Defaults are Burley's: a grey dielectric with ``specular`` 0.5 (IOR 1.5).
    ``specular`` and ``ior`` spell one thing two ways: give one, not both. With
    ``specular`` the model is the 2012 BRDF (Schlick Fresnel); with ``ior`` the 2015
    dielectric Fresnel (Schutte seed).
    """

    base_color: Color = Field((0.82, 0.67, 0.16), description="Surface colour, linear RGB.")
    subsurface: float = _unit(0.0, "Blend of the diffuse towards the Hanrahan-Krueger shape.")
    metallic: float = _unit(0.0, "0 dielectric, 1 metal; linear blend between.")
    specular: float = _unit(
        0.5,
        "Incident specular amount: 0..1 ↦ F0 0..0.08 (IOR 1.0..1.8); up to 12.5 (F0 = 1).",
        le=1.0 / SPECULAR_F0_SCALE,
    )
    specular_tint: float = _unit(0.0, "Tints the incident specular towards the base colour.")
    roughness: float = _unit(0.5, "Perceptual roughness; α = roughness².")
    anisotropic: float = _unit(0.0, "Aspect ratio of the specular highlight.")
    specular_gamma: float = Field(
        2.0,
        gt=0.0,
        le=SPECULAR_GAMMA_MAX,
        description="Expert: GTR shape γ of the primary specular lobe (Burley 2012 App. B); 2 is "
        "Burley's GGX, lower gives a longer tail, higher a tighter one. Isotropic when not 2.",
        json_schema_extra={"texturable": False},  # it picks the lobe's sampling technique
    )
    energy_compensation: bool = Field(
        False,
        description="Scale the primary specular lobe by Turquin 2019's multiple-scattering "
        "factor 1 + F0 (1 − E)/E (lookdev.materials.energy), so a white rough metal reflects "
        "all the light; off keeps Burley's single-scattering look. GGX only: no effect where "
        "specular_gamma is not 2; the glass's transmission and the clearcoat stay uncompensated.",
    )
    sheen: float = _unit(
        0.0,
        "Additional grazing lobe for cloth; may exceed 1 (Burley), up to 10: ten times the "
        "plausible range already outshines the base at grazing, and the ceiling keeps every "
        "float32 value of the model and of its albedo integrals finite (lookdev check sweeps it).",
        le=SHEEN_MAX,
    )
    sheen_tint: float = _unit(0.5, "Tints the sheen towards the base colour.")
    sheen_model: Literal["disney", "conty_kulla"] = Field(
        "disney", description="Burley's Fresnel-shaped sheen or the Conty-Kulla microfacet sheen."
    )
    sheen_roughness: float = _unit(
        0.3,
        "Conty-Kulla sheen roughness r (sheen_model only); clamped to 0.08 with the fitted "
        "Λ, to 0.01 with sheen_lambda 'exact'.",
    )
    sheen_lambda: SheenLambda = Field(
        "fit",
        description="Conty-Kulla Smith Λ: 'fit' is the paper's Table 1 (what MaterialX's "
        "sheen_bsdf renders), 'exact' the integrated Λ, tabulated (sheen_model only).",
    )
    clearcoat: float = _unit(
        0.0, "Second specular lobe; 0..1 ↦ weight 0..0.25, up to 4 (weight 1).", le=4.0
    )
    clearcoat_gloss: float = _unit(1.0, "0 'satin' (α = 0.1) .. 1 'gloss' (α = 0.001).")
    spec_trans: float = _unit(0.0, "Specular transmission (glass, water).")
    diff_trans: float = _unit(0.0, "Fraction of the diffuse that is transmitted.")
    flatness: float = _unit(0.0, "Thin surfaces: blend of Lambert towards Hanrahan-Krueger.")
    ior: float | None = Field(
        None, ge=1.0, le=10.0, description="Index of refraction; the 2015 spelling of specular."
    )
    scatter_distance: float = Field(
        0.0,
        ge=0.0,
        le=SCATTER_DISTANCE_MAX,
        description="Solid (not thin) materials: how far light scatters under the surface, a "
        "length in scene units (metres at metersPerUnit = 1; Burley 2015's scatter distance "
        "d, the medium's σt = 1/(s·d), :mod:`lookdev.materials.subsurface`). 0: no interior "
        f"medium (the 2012 ``subsurface`` blend applies), else {SCATTER_DISTANCE_MIN:g} .. "
        f"{SCATTER_DISTANCE_MAX:g}, so σt, s in 1.04 .. 4.14, stays a finite float32.",
    )
    scatter_distance_scale: Color = Field(
        (1.0, 1.0, 1.0),
        description="Per-channel scale of ``scatter_distance`` (OpenPBR's "
        "subsurface_radius_scale): 'red scatters further' for skin is (1, 0.4, 0.2).",
    )
    thin: bool = Field(False, description="Thin-walled surface (leaves, paper): no interior.")

    @model_validator(mode="after")
    def _scatter_distance_not_tiny(self) -> DisneyParams:
        smallest = self.scatter_distance * min(self.scatter_distance_scale)
        if self.scatter_distance > 0.0 and not smallest >= SCATTER_DISTANCE_MIN:
            raise ValueError(
                f"scatter_distance {self.scatter_distance:g} × scatter_distance_scale "
                f"{min(self.scatter_distance_scale):g} is out of range; allowed 0 or "
                f"[{SCATTER_DISTANCE_MIN:g}, {SCATTER_DISTANCE_MAX:g}] in every channel"
            )
        return self

    @model_validator(mode="after")
    def _gtr_gamma_is_isotropic(self) -> DisneyParams:
        # Burley's App. B closes the anisotropic stretch only for γ = 2 (GGX, eq. 13).
        if self.specular_gamma != 2.0 and self.anisotropic > 0.0:
            raise ValueError(
                "specular_gamma other than 2 is isotropic: set anisotropic 0 or specular_gamma 2"
            )
        return self

    @model_validator(mode="after")
    def _one_spelling_of_specular(self) -> DisneyParams:
        if "ior" in self.model_fields_set and "specular" in self.model_fields_set:
            raise ValueError("give either 'specular' or 'ior', not both: they are one parameter")
        return self

    @property
    def uses_ior(self) -> bool:
        """True when the 2015 dielectric Fresnel applies (``ior`` was given)."""
        return self.ior is not None

    @property
    def effective_ior(self) -> float:
        """IOR whose normal-incidence reflectance is ``0.08 · specular`` (Burley §5.4)."""
        if self.ior is not None:
            return self.ior
        return specular_to_ior(self.specular)

    @property
    def effective_specular(self) -> float:
        """``specular`` whose F0 equals the Fresnel reflectance of ``ior`` at normal incidence."""
        if self.ior is None:
            return self.specular
        return ior_to_specular(self.ior)
