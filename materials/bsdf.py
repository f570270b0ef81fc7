"""The BSDF contract every reflectance model implements, and its numpy front door.

A model module (``disney``, ``sheen``, ``pixar``) writes its maths once, as four
backend-generic *core* functions over the array shim (:mod:`.arrays`), and publishes them
as a :class:`Model`:

``prepare(xp, params, **maps) -> prepared``
    Everything that depends only on the parameters, computed once: derived colours, α,
    lobe weights and selection probabilities. ``params`` is the model's pydantic schema
    (constants, discrete switches such as ``thin``); ``maps`` override single fields with
    per-element values (texture lookups in Mitsuba, per-texel arrays in analysis). A lobe
    whose weight is ``xp.known_zero`` is recorded as absent here, and the other core
    functions then skip it entirely (:doc:`/design`: nothing is computed that is not needed).
``eval(xp, prepared, wi, wo) -> colour``
    f(wi, wo) *without* the cosine; ``wi`` towards the light, ``wo`` towards the viewer,
    both pointing away from the surface in the local frame (normal +z).
``pdf(xp, prepared, wi, wo) -> scalar``
    Solid-angle density with which ``sample`` produces ``wi`` given ``wo``.
``sample(xp, prepared, wo, u) -> (wi, weight, pdf, delta)``
    ``u`` is a vector of three uniforms (``u[0]`` picks the lobe, ``u[1], u[2]`` the
    direction); ``weight = f·|cos θi| / pdf``; a failed sample has pdf 0 and weight 0.
    ``delta`` (a mask, or ``False`` for a model without delta lobes) marks samples of a
    delta lobe (a smooth mirror or refraction, :mod:`.disney_interface`): ``eval`` and
    ``pdf`` leave such lobes out, and their sample's ``pdf`` is the probability with
    which the lobe was chosen (Mitsuba's convention), its weight the lobe's exact value.

Vectors and colours are channel-first inside core functions (see :mod:`.arrays`). The
functions below are the public numpy API: they take ``(..., 3)`` arrays, broadcast, and
return ``(..., 3)`` / ``(...)`` arrays.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from .arrays import NumpyOps, from_channel_first, to_channel_first

__all__ = ["Lobe", "Model", "Prepared", "density", "draw", "evaluate", "keep_lobes"]


@dataclass(frozen=True, kw_only=True)
class Prepared:
    """What every model's ``prepare`` returns: the members every consumer reads.

    Each model subclasses it with its own named members (``DisneyPrepared`` …), as pbrt's
    and Mitsuba's BSDFs name theirs; a member is either a Python value (a constant the
    kernel is traced with, so a known-zero lobe is pruned) or an array of the backend
    (numpy or Dr.Jit). Immutable: :func:`dataclasses.replace` makes a changed copy.
    """

    lobes: tuple[str, ...]
    """The lobes ``eval``/``pdf``/``sample`` visit (the live ones, or a restriction)."""
    delta: tuple[str, ...] = ()
    """The kept lobes sampled as Dirac deltas (a smooth mirror or refraction)."""
    eta: Any = None
    """Relative IOR inside/outside of a refracting solid; None where nothing refracts."""
    adjoint: bool = False
    """Sample the delta lobes' adjoint (a light tracer's Importance mode, :class:`Model`)."""


@dataclass(frozen=True)
class Lobe:
    """One lobe of a model: how it scatters, which normal shades it, what drives it.

    ``params`` are the parameters that act through this lobe alone (or only through lobes
    listed with them): where every lobe naming a parameter is dead, the parameter has no
    effect; ``switches`` are those of them that turn it on. Parameters no lobe names
    (``base_color``, ``roughness`` …) are always live.
    Whether the lobe is live is never decided here but by the model's own ``prepare``
    (:func:`lookdev.materials.registry.live_lobes`), the one rule every consumer asks.
    """

    name: str
    scattering: str
    """``"diffuse"`` or ``"glossy"`` (Mitsuba's BSDF flag families)."""
    transmits: bool = False
    highlight: bool = False
    """Shaded with the highlight (specular) normal where a material has two (Smits, Burley §6)."""
    family: str = ""
    """Smits' lobe type (diffuse, specular, reflection) shared by a lobe and its
    transmitted twin; the lobe's own name where it has no twin."""
    params: tuple[str, ...] = ()
    switches: tuple[str, ...] = ()
    """The parameters that switch the lobe on (its own weight); none for a base lobe that
    any material has unless others take its energy (the Disney diffuse and specular)."""
    reciprocal: bool = True
    """f(light, viewer) = f(viewer, light), apart from the (η_viewer/η_light)² of a
    refraction into a solid (Veach 1997 §5.2), which the model's ``prepared.eta``
    carries. False for a lobe that is not, for some of its parameters: Smits' transmitted
    highlights are centred on the *refracted view*, Conty–Kulla's terminator softening
    acts on the light side only. A light tracer evaluates such a lobe with the roles as
    they are, and Mitsuba flags it ``NonSymmetric``."""
    reciprocal_unless: tuple[str, ...] = ()
    """Switches that make a reciprocal lobe non-reciprocal when on (a parameter set
    true): Turquin's energy compensation of the Disney specular is read at the view
    only (:mod:`.energy`), so ``energy_compensation`` does."""

    def is_reciprocal(self, params: Any) -> bool:
        """Whether this lobe is reciprocal for these parameters (see ``reciprocal``)."""
        return self.reciprocal and not any(
            getattr(params, name, False) is True for name in self.reciprocal_unless
        )

    @property
    def mitsuba_flag(self) -> str:
        """The ``mi.BSDFFlags`` member of this lobe (``GlossyTransmission`` …)."""
        return self.scattering.title() + ("Transmission" if self.transmits else "Reflection")


def keep_lobes(xp: Any, prepared: Prepared, names: Any) -> Prepared:
    """``prepared`` with only its lobes named in ``names`` evaluated and sampled: the
    default :attr:`Model.restrict`, for models that choose among ``prepared.lobes``
    as they go (a model that stores sampling odds recomputes them in its own)."""
    return replace(prepared, lobes=tuple(k for k in prepared.lobes if k in names))


@dataclass(frozen=True)
class Model:
    """A reflectance model: its name, parameter schema and four core functions.

    ``restrict(xp, prepared, names)`` limits a prepared material to some of its lobes:
    a material whose lobe groups have their own shading normals renders as two
    restricted halves (:mod:`lookdev.pipeline.export.mitsuba.normals`).

    ``prepared.adjoint`` (set by a light tracer's adapter, Mitsuba's Importance mode)
    asks ``sample`` for the *adjoint* of its delta lobes: given where the light comes
    from (in the viewer's argument), the direction towards the viewer and the weight
    f(light, viewer)·|cos|/pdf (Veach 1997 §3.7). A delta has no f the adapter could
    evaluate, so only the model knows it; lobes with a density are unchanged (the
    adapter weights them by ``eval`` with the roles swapped).
    """

    name: str
    params_type: type
    prepare: Callable[..., Any]
    eval: Callable[..., Any]
    pdf: Callable[..., Any]
    sample: Callable[..., Any]
    restrict: Callable[..., Any] = keep_lobes
    lobes: tuple[Lobe, ...] = ()
    guide: Callable[..., Any] | None = None
    """``guide(xp, prepared, wo) -> colour``: what the model's *glossy* lobes add to a
    denoiser's albedo guide (:func:`lookdev.materials.guides.guide_albedo` adds the
    diffuse-like ones itself); None when they add nothing."""

    def lobe(self, name: str) -> Lobe:
        """The lobe called ``name``; a ``KeyError`` naming the known ones otherwise."""
        for lobe in self.lobes:
            if lobe.name == name:
                return lobe
        known = ", ".join(lobe.name for lobe in self.lobes)
        raise KeyError(f"model {self.name!r} has no lobe {name!r}; known: {known}")

    @property
    def lobe_names(self) -> tuple[str, ...]:
        return tuple(lobe.name for lobe in self.lobes)


def _flatten_maps(maps: dict[str, Any], lead: tuple[int, ...], dtype: Any) -> dict[str, Any]:
    """Per-element parameter maps, broadcast to the directions' leading shape, flattened."""
    flat = {}
    for name, value in maps.items():
        a = np.asarray(value, dtype=dtype)
        if a.ndim > 0 and a.shape[-1] == 3 and a.ndim == len(lead) + 1:
            flat[name] = np.broadcast_to(a, (*lead, 3)).reshape(-1, 3).T
        else:
            flat[name] = np.broadcast_to(a, lead).reshape(-1)
    return flat


def _directions(*vs: Any, dtype: Any) -> tuple[list[np.ndarray], tuple[int, ...]]:
    arrays = np.broadcast_arrays(*(np.asarray(v, dtype=dtype) for v in vs))
    out = []
    lead: tuple[int, ...] = ()
    for a in arrays:
        cf, lead = to_channel_first(a, dtype)
        out.append(cf)
    return out, lead


def _call(core: Callable[..., Any], model: Model, params: Any, a: Any, b: Any, dtype, maps):
    """Run one core function on user arrays: (its result, element count N, leading shape)."""
    xp = NumpyOps(dtype)
    (a_, b_), lead = _directions(a, b, dtype=dtype)
    with np.errstate(all="ignore"):
        prepared = model.prepare(xp, params, **_flatten_maps(maps, lead, dtype))
        return core(xp, prepared, a_, b_), a_.shape[1], lead


def _out(x: Any, n: int, lead: tuple[int, ...], colour: bool) -> np.ndarray:
    return from_channel_first(np.broadcast_to(x, (3, n) if colour else (n,)), lead)


def evaluate(
    model: Model, params: Any, wi: Any, wo: Any, *, dtype: Any = np.float64, **maps: Any
) -> np.ndarray:
    """f(wi, wo) without the cosine, shape (..., 3)."""
    f, n, lead = _call(model.eval, model, params, wi, wo, dtype, maps)
    return _out(f, n, lead, colour=True)


def density(
    model: Model, params: Any, wi: Any, wo: Any, *, dtype: Any = np.float64, **maps: Any
) -> np.ndarray:
    """pdf of sampling wi given wo (solid angle), shape (...)."""
    p, n, lead = _call(model.pdf, model, params, wi, wo, dtype, maps)
    return _out(p, n, lead, colour=False)


def draw(
    model: Model,
    params: Any,
    wo: Any,
    u: Any,
    *,
    dtype: Any = np.float64,
    delta: bool = False,
    **maps: Any,
) -> tuple[np.ndarray, ...]:
    """Sample wi given wo and uniforms u of shape (..., 3): (wi, weight, pdf).

    With ``delta=True`` a fourth boolean array (...) marks the samples of delta lobes,
    whose pdf is the probability of the lobe's choice rather than a density (MIS with
    another strategy must give them weight 1, a histogram must leave them out).
    """
    (wi, weight, pdf, is_delta), n, lead = _call(model.sample, model, params, wo, u, dtype, maps)
    out = _out(wi, n, lead, True), _out(weight, n, lead, True), _out(pdf, n, lead, False)
    if not delta:
        return out
    flags = np.broadcast_to(np.asarray(is_delta, dtype=bool), (n,))
    return (*out, from_channel_first(flags, lead))
