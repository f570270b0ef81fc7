"""Measured isotropic BRDFs: a table of f over a grid of directions, interpolated.

A measurement is a :class:`MeasuredTable`: f(wi, wo) *without* the cosine, in 1/sr, per
RGB channel, on one of two grids (the readers in :mod:`lookdev.library.measured` fill it):

``"mbsdf"`` — NVIDIA's MBSDF :cite:`NVIDIA2025MDL` (Appendix B): the light's polar angle
    θi, the viewer's θo, both equi-spaced over [0, π/2] *endpoints included* (n steps),
    and the azimuth between them, φ = |φo − φi| folded into [0, π], equi-spaced with its
    endpoints too. (The neuraylib header documents θ over [0, π/2) and its CUDA example
    reads cell centres; the specification is followed here.)
``"merl"`` — Matusik et al.'s MERL format :cite:`Matusik2003`: Rusinkiewicz's half and
    difference angles :cite:`Rusinkiewicz1998`, θh on a square-root scale (index
    √(θh / (π/2))·90), θd linear over [0, π/2] (90), φd over [0, π) (180), periodic in
    π by reciprocity. Sample k sits at its cell's lower edge, where MERL's own look-up
    (``floor`` of the index) reads it.

Evaluation interpolates trilinearly between the samples (MERL's reference code reads the
nearest cell; interpolating is what makes a fit's gradient and a render smooth), clamps at
the grid's ends and clamps negative measurements (noise around zero) to zero. Sampling is
cosine-weighted: it needs nothing from the table, so a table of any shape samples the
same way; its variance on a sharp highlight is the price (a tabulated sampler would fix
that).

>>> import numpy as np
>>> table = MeasuredTable.constant(1 / np.pi)            # a white Lambertian, tabulated
>>> from lookdev.materials.bsdf import evaluate
>>> f = evaluate(MODEL, MeasuredParams(table=table), [0, 0.6, 0.8], [0.6, 0, 0.8])
>>> [round(float(v) * np.pi, 6) for v in f]
[1.0, 1.0, 1.0]
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Annotated, Any, Literal

import numpy as np
from pydantic import BeforeValidator, ConfigDict, Field, field_validator

from .bsdf import Lobe, Model, Prepared
from .params import Params
from .tables import gather

__all__ = [
    "GRIDS",
    "MODEL",
    "MeasuredPrepared",
    "MeasuredParams",
    "MeasuredTable",
    "grid_directions",
    "table_by_key",
    "table_coordinates",
]

GRIDS = ("mbsdf", "merl")
HALF_PI = 0.5 * math.pi
_COS_FLOOR = 1e-6  # below this a direction is tangent: no reflection


class MeasuredTable:
    """f on a grid: ``values`` of shape (n0, n1, n2, 3), float32, 1/sr.

    Axes: ``"mbsdf"`` (θi, θo, φ); ``"merl"`` (θh, θd, φd). ``source`` names the file.
    ``negative`` counts the samples below zero the reader found (clamped when evaluated).
    A plain class, not a dataclass, so that a schema dump keeps it whole.
    """

    __slots__ = ("grid", "values", "source", "negative")

    def __init__(
        self,
        grid: Literal["mbsdf", "merl"],
        values: np.ndarray,
        source: str = "",
        negative: int = 0,
    ):
        if grid not in GRIDS:
            raise ValueError(f"unknown grid {grid!r}; known: {', '.join(GRIDS)}")
        v = np.asarray(values, dtype=np.float32)
        if v.ndim != 4 or v.shape[-1] != 3 or min(v.shape[:3]) < 2:
            raise ValueError(f"a table has shape (n0, n1, n2, 3), n ≥ 2; got {v.shape}")
        self.grid, self.values, self.source, self.negative = grid, v, source, negative

    def __repr__(self) -> str:
        return f"MeasuredTable({self.grid!r}, shape={self.shape}, source={self.source!r})"

    @classmethod
    def constant(
        cls, f: float, shape: tuple[int, int, int] = (4, 4, 4), source: str = "constant"
    ) -> MeasuredTable:
        """A table of one value (a tabulated Lambertian of albedo π·f)."""
        return cls("mbsdf", np.full((*shape, 3), f, dtype=np.float32), source=source)

    @property
    def shape(self) -> tuple[int, int, int]:
        return tuple(int(n) for n in self.values.shape[:3])  # type: ignore[return-value]

    def flat(self) -> np.ndarray:
        """The values clamped at zero, (n0·n1·n2, 3), in the order the model reads them."""
        return np.maximum(self.values, 0).reshape(-1, 3)

    def key(self) -> str:
        """A name for this table in this process (:func:`table_by_key` finds it): what a
        scene description that holds only strings (a Mitsuba plugin's properties) passes."""
        name = f"measured:{self.source}:{id(self):x}"
        _TABLES[name] = self
        return name


_TABLES: dict[str, MeasuredTable] = {}


def table_by_key(value: Any) -> Any:
    """The table a :meth:`MeasuredTable.key` names; anything else as it is."""
    if isinstance(value, str):
        if value not in _TABLES:
            raise ValueError(f"no measured table {value!r} in this process")
        return _TABLES[value]
    return value


class MeasuredParams(Params):
    """A measured BRDF as a material: its table and a scale (1 reproduces the file)."""

    model_config = ConfigDict(
        extra="forbid",
        allow_inf_nan=False,
        frozen=True,
        validate_default=True,
        arbitrary_types_allowed=True,
    )
    table: Annotated[MeasuredTable, BeforeValidator(table_by_key)] = Field(
        default_factory=lambda: MeasuredTable.constant(0.18 / math.pi, source="grey"),
        description="the measurement; by default an 18 % grey Lambertian, tabulated",
    )
    scale: float = Field(1.0, ge=0.0, le=1e3, description="multiplies every value")

    @field_validator("table")
    @classmethod
    def _finite(cls, table: MeasuredTable) -> MeasuredTable:
        if not np.all(np.isfinite(table.values)):
            raise ValueError(f"{table.source or 'the table'} holds NaN or infinite values")
        return table


# -- coordinates -------------------------------------------------------------------------------
def _polar(xp: Any, v: Any) -> Any:
    return xp.acos(xp.clip(v[2], -1.0, 1.0))


def _relative_azimuth(xp: Any, wi: Any, wo: Any) -> Any:
    """|φo − φi| in [0, π] from the directions' projections (0 where one is normal)."""
    dot = wi[0] * wo[0] + wi[1] * wo[1]
    r = xp.safe_sqrt((wi[0] * wi[0] + wi[1] * wi[1]) * (wo[0] * wo[0] + wo[1] * wo[1]))
    return xp.acos(xp.select(r > 0, dot / xp.select(r > 0, r, 1.0), 1.0))


def _half_difference(xp: Any, wi: Any, wo: Any) -> tuple[Any, Any, Any]:
    """Rusinkiewicz's (θh, θd, φd mod π) :cite:`Rusinkiewicz1998`, without atan2."""
    h = xp.normalize(xp.vec3(wi[0] + wo[0], wi[1] + wo[1], wi[2] + wo[2]))
    theta_h = _polar(xp, h)
    rh = xp.safe_sqrt(h[0] * h[0] + h[1] * h[1])
    cos_ph = xp.select(rh > 0, h[0] / xp.select(rh > 0, rh, 1.0), 1.0)
    sin_ph = xp.select(rh > 0, h[1] / xp.select(rh > 0, rh, 1.0), 0.0)
    # d = R_y(−θh) R_z(−φh) wi: the light seen from the half vector's frame
    x = cos_ph * wi[0] + sin_ph * wi[1]
    y = -sin_ph * wi[0] + cos_ph * wi[1]
    ct, st = h[2], rh
    dx = ct * x - st * wi[2]
    dz = st * x + ct * wi[2]
    theta_d = xp.acos(xp.clip(dz, -1.0, 1.0))
    rd = xp.safe_sqrt(dx * dx + y * y)
    phi = xp.acos(xp.select(rd > 0, dx / xp.select(rd > 0, rd, 1.0), 1.0))
    phi_d = xp.select(y < 0, math.pi - phi, phi)  # φd and φd + π are one sample (reciprocity)
    return theta_h, theta_d, phi_d


def table_coordinates(xp: Any, grid: str, shape: tuple[int, int, int], wi: Any, wo: Any):
    """Continuous sample indices (x0, x1, x2) of the direction pair on ``grid``."""
    n0, n1, n2 = shape
    if grid == "mbsdf":
        return (
            _polar(xp, wi) * ((n0 - 1) / HALF_PI),
            _polar(xp, wo) * ((n1 - 1) / HALF_PI),
            _relative_azimuth(xp, wi, wo) * ((n2 - 1) / math.pi),
        )
    theta_h, theta_d, phi_d = _half_difference(xp, wi, wo)
    return (
        xp.sqrt(xp.clip(theta_h / HALF_PI, 0.0, 1.0)) * n0,
        theta_d * (n1 / HALF_PI),
        phi_d * (n2 / math.pi),
    )


def grid_directions(grid: str, shape: tuple[int, int, int]) -> tuple[np.ndarray, np.ndarray]:
    """(wi, wo), each (n0, n1, n2, 3), at every sample of ``grid``: where a writer
    evaluates a model so that :func:`table_coordinates` reads each value back at its
    own sample."""
    n0, n1, n2 = shape
    if grid == "mbsdf":
        ti = np.linspace(0, HALF_PI, n0)[:, None, None]
        to = np.linspace(0, HALF_PI, n1)[None, :, None]
        ph = np.linspace(0, math.pi, n2)[None, None, :]
        wi = np.stack(np.broadcast_arrays(np.sin(ti), 0 * ph, np.cos(ti)), -1)
        wo = np.stack(
            np.broadcast_arrays(np.sin(to) * np.cos(ph), np.sin(to) * np.sin(ph), np.cos(to)),
            -1,
        )
        return np.broadcast_to(wi, (*shape, 3)), np.broadcast_to(wo, (*shape, 3))
    th = (HALF_PI * (np.arange(n0) / n0) ** 2)[:, None, None]
    td = (HALF_PI * np.arange(n1) / n1)[None, :, None]
    pd = (math.pi * np.arange(n2) / n2)[None, None, :]
    d = np.stack(
        np.broadcast_arrays(np.sin(td) * np.cos(pd), np.sin(td) * np.sin(pd), np.cos(td)), -1
    )
    d = np.broadcast_to(d, (*shape, 3))
    th = np.broadcast_to(th, shape)
    # wi = R_y(θh) d (φh = 0), wo its mirror about h = (sin θh, 0, cos θh)
    wi = np.stack(
        [
            np.cos(th) * d[..., 0] + np.sin(th) * d[..., 2],
            d[..., 1],
            -np.sin(th) * d[..., 0] + np.cos(th) * d[..., 2],
        ],
        -1,
    )
    h = np.stack([np.sin(th), np.zeros_like(th), np.cos(th)], -1)
    wo = 2 * np.sum(wi * h, -1, keepdims=True) * h - wi
    return wi, wo


# -- interpolation -------------------------------------------------------------------------------
def _gather(xp: Any, channels: tuple[np.ndarray, ...], index: Any) -> Any:
    """The colour at integer-valued ``index`` of a table kept as three flat channels."""
    return xp.vec3(*(gather(xp, c, index) for c in channels))


def _interpolate(xp: Any, prepared: MeasuredPrepared, x0: Any, x1: Any, x2: Any) -> Any:
    """Trilinear interpolation; the third axis wraps where the grid is periodic."""
    n0, n1, n2 = prepared.shape
    periodic = prepared.grid == "merl"

    def split(x: Any, n: int, wrap: bool) -> tuple[Any, Any, Any]:
        if wrap:
            x = x - xp.floor(x / n) * n
            i = xp.minimum(xp.floor(x), n - 1)
            j = xp.select(i + 1 >= n, 0.0 * i, i + 1)
            return i, j, x - i
        x = xp.clip(x, 0.0, n - 1.0)
        i = xp.minimum(xp.floor(x), n - 2.0)
        return i, i + 1, x - i

    i0, j0, t0 = split(x0, n0, False)
    i1, j1, t1 = split(x1, n1, False)
    i2, j2, t2 = split(x2, n2, periodic)
    channels = prepared.channels
    out = 0.0
    for a, wa in ((i0, 1 - t0), (j0, t0)):
        for b, wb in ((i1, 1 - t1), (j1, t1)):
            for c, wc in ((i2, 1 - t2), (j2, t2)):
                out = out + _gather(xp, channels, (a * n1 + b) * n2 + c) * (wa * wb * wc)
    return out


# -- the core functions ------------------------------------------------------------------------
@dataclass(frozen=True, kw_only=True)
class MeasuredPrepared(Prepared):
    """What the interpolated table reads (no IOR, no delta)."""

    channels: tuple[Any, Any, Any]
    """The table's red, green and blue values, each flattened over its grid."""
    grid: Any
    """The table's parametrisation (:data:`GRIDS`)."""
    shape: tuple[int, ...]
    """Its node counts per coordinate."""
    scale: Any
    """A factor on f."""


def prepare(xp: Any, params: MeasuredParams, **maps: Any) -> MeasuredPrepared:
    """The table as the backend reads it (a flattened array), its grid and the scale."""
    table = params.table
    dtype = xp.dtype if xp.name == "numpy" else np.float32
    flat = table.flat().astype(dtype)
    return MeasuredPrepared(
        lobes=("measured",) if params.scale > 0 else (),
        channels=tuple(np.ascontiguousarray(flat[:, c]) for c in range(3)),
        grid=table.grid,
        shape=table.shape,
        scale=maps.get("scale", params.scale),
    )


def eval(xp: Any, prepared: MeasuredPrepared, wi: Any, wo: Any) -> Any:  # noqa: A001
    """f(wi, wo): the interpolated table times ``scale``; 0 below either side."""
    above = (wi[2] > _COS_FLOOR) & (wo[2] > _COS_FLOOR)
    if not prepared.lobes:
        return xp.zeros(wi[2]) * xp.color((0.0, 0.0, 0.0))
    x = table_coordinates(xp, prepared.grid, prepared.shape, wi, wo)
    f = _interpolate(xp, prepared, *x) * prepared.scale
    return xp.select(above, f, 0.0 * f)


def pdf(xp: Any, prepared: MeasuredPrepared, wi: Any, wo: Any) -> Any:
    """Cosine-weighted hemisphere density cos θi / π, on the viewer's side only."""
    ok = (wi[2] > 0) & (wo[2] > 0)
    return xp.select(ok, wi[2] * (1.0 / math.pi), 0.0 * wi[2])


def sample(xp: Any, prepared: MeasuredPrepared, wo: Any, u: Any):
    """A cosine-weighted direction (Malley's method); weight f·cos θi / pdf = π f."""
    r = xp.safe_sqrt(u[1])
    phi = 2.0 * math.pi * u[2]
    z = xp.safe_sqrt(1.0 - u[1])
    wi = xp.vec3(r * xp.cos(phi), r * xp.sin(phi), z)
    p = pdf(xp, prepared, wi, wo)
    f = eval(xp, prepared, wi, wo)
    weight = xp.select(p > 0, f * math.pi, 0.0 * f)
    return wi, weight, p, False


MODEL = Model(
    name="measured",
    params_type=MeasuredParams,
    prepare=prepare,
    eval=eval,
    pdf=pdf,
    sample=sample,
    lobes=(Lobe("measured", "glossy", params=("scale",), switches=("scale",)),),
)
