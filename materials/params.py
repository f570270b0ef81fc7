"""Material parameter schemas (pydantic), shared machinery for every model.

Ranges follow Burley's principles (§5.1): parameters are 0..1 over their plausible range,
may be pushed beyond it where that makes sense, and are rejected where meaningless
(NaN, infinity, negative roughness …) with a one-line :class:`ParameterError` naming the
field and the allowed range. Colours are scene-linear Rec.709; a ``"#rrggbb"`` string is
taken as sRGB-encoded and decoded once, here.

>>> DisneyParams(base_color="#ffffff", metallic=1.0).base_color
(1.0, 1.0, 1.0)
>>> round(DisneyParams().effective_ior, 6)
1.5
"""

from __future__ import annotations

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

from .colour import srgb_decode
from .errors import ParameterError
from .fresnel import SPECULAR_F0_SCALE, ior_to_specular, specular_to_ior

_HEX = re.compile(r"^#?([0-9a-fA-F]{6})$")


def parse_color(value: Any) -> Any:
    """``"#rrggbb"`` (sRGB) → linear triple; ``[r, g, b]`` and a grey scalar pass through."""
    if isinstance(value, str):
        m = _HEX.match(value.strip())
        if not m:
            raise ValueError(f"colour {value!r} is neither '#rrggbb' nor [r, g, b]")
        h = m.group(1)
        return tuple(srgb_decode(int(h[i : i + 2], 16) / 255.0) for i in (0, 2, 4))
    if isinstance(value, int | float) and not isinstance(value, bool):
        return (float(value),) * 3
    return value


def _unit(default: float, description: str, *, le: float | None = 1.0, ge: float = 0.0):
    return Field(default, ge=ge, le=le, description=description)


Channel = Annotated[float, Field(ge=0.0, le=1.0)]
Color = Annotated[tuple[Channel, Channel, Channel], BeforeValidator(parse_color)]


class Params(BaseModel):
    """Base of every parameter schema: strict about unknown names, NaN and infinity."""

    model_config = ConfigDict(extra="forbid", allow_inf_nan=False, frozen=True)

    @classmethod
    def parse(cls, data: dict[str, Any], *, where: str | None = None):
        """Validate ``data``; any problem becomes one :class:`ParameterError` line."""
        try:
            return cls.model_validate(data)
        except ValidationError as exc:
            raise parameter_error(exc, where=where) from None

    def replace(self, **changes: Any):
        """A validated copy with some parameters changed."""
        data = self.model_dump(exclude_unset=True)
        data.update(changes)
        return type(self).parse(data)


def parameter_error(exc: ValidationError, *, where: str | None = None) -> ParameterError:
    """The first pydantic error as one line: field, value, what is allowed."""
    err = exc.errors(include_url=False)[0]
    loc = ".".join(str(p) for p in err["loc"] if not isinstance(p, int)) or None
    ctx = err.get("ctx") or {}
    kind = err["type"]
    given = err.get("input")
    if kind in ("greater_than_equal", "less_than_equal", "greater_than", "less_than"):
        msg = f"{given!r} is out of range; allowed {_range_text(exc, err)}"
    elif kind == "extra_forbidden":
        msg = "unknown parameter"
    elif kind == "finite_number":
        msg = f"{given!r} is not a finite number"
    elif kind == "value_error":
        msg = str(ctx.get("error", err["msg"]))
    else:
        msg = f"{err['msg']} (got {given!r})"
    return ParameterError(msg, where=where, field=loc)


def _range_text(exc: ValidationError, err: dict[str, Any]) -> str:
    """``[lo, hi]`` of the offending field, or the violated bound alone when the field's
    schema is not known here (a nested model that did not call :func:`register_schema`)."""
    ctx = err.get("ctx") or {}
    loc = err["loc"]
    if loc and isinstance(loc[-1], int):
        lo, hi = 0.0, 1.0  # a colour channel
    else:
        field = next((p for p in reversed(loc) if isinstance(p, str)), None)
        lo, hi = _bounds(exc.title, field)
    if lo is None and hi is None:
        bound = next((f"{op} {ctx[k]:g}" for k, op in _OPS if k in ctx), "")
        return bound or "a smaller or larger value"
    lo_text = "-∞" if lo is None else f"{float(lo):g}"
    hi_text = "∞" if hi is None else f"{float(hi):g}"
    return f"[{lo_text}, {hi_text}]"


_OPS = (("ge", "≥"), ("gt", ">"), ("le", "≤"), ("lt", "<"))


def _bounds(model_name: str, field: str | None) -> tuple[float | None, float | None]:
    """The (ge, le) bounds declared on ``field`` of the schema ``model_name``, else of the
    first registered schema that declares that field; (None, None) when none does."""
    named = _SCHEMAS.get(model_name)
    for cls in [named] * (named is not None) + list(_SCHEMAS.values()):
        if field not in cls.model_fields:
            continue
        lo = hi = None
        for m in cls.model_fields[field].metadata:
            lo = getattr(m, "ge", None) if getattr(m, "ge", None) is not None else lo
            hi = getattr(m, "le", None) if getattr(m, "le", None) is not None else hi
        if lo is not None or hi is not None:
            return lo, hi
    return None, None


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
    sheen: float = _unit(0.0, "Additional grazing lobe for cloth; may exceed 1.", le=None)
    sheen_tint: float = _unit(0.5, "Tints the sheen towards the base colour.")
    sheen_model: Literal["disney", "conty_kulla"] = Field(
        "disney", description="Burley's Fresnel-shaped sheen or the Conty-Kulla microfacet sheen."
    )
    sheen_roughness: float = _unit(0.3, "Conty-Kulla sheen roughness r (sheen_model only).")
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
        0.0, ge=0.0, description="Mean free path inside solid transmissive materials (scene units)."
    )
    thin: bool = Field(False, description="Thin-walled surface (leaves, paper): no interior.")

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


_SCHEMAS: dict[str, type[Params]] = {"DisneyParams": DisneyParams}


def register_schema(cls: type[Params]) -> type[Params]:
    """Make a parameter schema's ranges known to the one-line error messages."""
    _SCHEMAS[cls.__name__] = cls
    return cls
