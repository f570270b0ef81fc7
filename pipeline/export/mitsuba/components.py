"""A plugin's lobes as Mitsuba components and flags.

The kept lobes of a prepared material fall into four components, in this order:
reflection and transmission with a density, then the deltas (Mitsuba numbers only the
components that exist). A model may sample some lobes as Dirac deltas (smooth glass,
mirrors: ``prepared.delta``, :mod:`lookdev.materials.disney_interface`). They form their
own components, flagged ``DeltaReflection`` / ``DeltaTransmission`` (a BSDF with no other
lobe has no ``Smooth`` flag, so the path tracer samples no light at its vertices);
``eval`` and ``pdf`` leave them out, as the model does, and a sample of one reports that
type and component (the model's ``delta`` mask), its pdf the probability of its choice.
A context that asks for the smooth components only gets such samples with weight 0.
"""

from __future__ import annotations

import functools
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any

from lookdev.materials.bsdf import Model, Prepared

from .inputs import MitsubaExportError

__all__ = [
    "Components",
    "components_of",
    "delta_lobes",
    "hemisphere_mask",
    "lobe_kinds",
    "lobes_of",
    "sampled_component",
]


def lobes_of(prepared: Prepared) -> tuple[str, ...]:
    """The lobe names a prepared material kept (``prepared.lobes``)."""
    if not isinstance(prepared, Prepared):
        raise MitsubaExportError("the model's prepare() does not return a Prepared")
    return tuple(prepared.lobes)


def delta_lobes(prepared: Prepared) -> tuple[str, ...]:
    """The kept lobes a prepared material samples as deltas (``prepared.delta``)."""
    return tuple(k for k in lobes_of(prepared) if k in prepared.delta)


def lobe_kinds(lobes: Iterable[str], model: Model, delta: Iterable[str] = ()) -> set[str]:
    """Mitsuba flag names (``GlossyReflection`` …) of the given lobes of ``model``,
    as the registry describes them (:class:`lookdev.materials.bsdf.Lobe`); the lobes in
    ``delta`` (a prepared material's smooth lobes) are ``DeltaReflection`` /
    ``DeltaTransmission`` instead."""
    delta = set(delta)
    try:
        return {_kind(model.lobe(name), name in delta) for name in lobes}
    except KeyError as exc:
        raise MitsubaExportError(exc.args[0]) from None


def _kind(lobe: Any, delta: bool) -> str:
    if not delta:
        return lobe.mitsuba_flag
    return "Delta" + ("Transmission" if lobe.transmits else "Reflection")


@dataclass(frozen=True)
class Components:
    """The four components of a plugin and the flags Mitsuba reads."""

    lobes: tuple[str, ...]
    """The lobes this instance traces (the model's live lobes, or ``only_lobes``)."""
    flags: tuple[int, int, int, int]
    """Per component, the union of its lobes' flags (0: the component is absent)."""
    index: tuple[int, int, int, int]
    """Per component, Mitsuba's number for it (0 for an absent one)."""
    refracts: bool
    """Transmission bends the path (η ≠ 1 through a solid): non-symmetric."""
    non_symmetric: tuple[bool, bool, bool, bool]
    """Per component: f(l, v) ≠ f(v, l) somewhere in it."""
    m_components: tuple[Any, ...]
    """The ``mi.BSDFFlags`` of each present component, as ``mi.BSDF.m_components``."""
    m_flags: Any
    """Their union, as ``mi.BSDF.m_flags``."""

    @property
    def transmits(self) -> int:
        """The transmitted components' flags (with a density or delta)."""
        return self.flags[1] | self.flags[3]


def components_of(model: Model, params: Any, prepared: Any, textured: Iterable[str]):
    """The :class:`Components` of a prepared material (its kept lobes, their kinds, the
    sides and symmetry); ``textured`` names the fields a texture drives."""
    import mitsuba as mi

    flag = mi.BSDFFlags
    textured = set(textured)
    lobes = lobes_of(prepared)
    delta = delta_lobes(prepared)
    kinds = sorted(lobe_kinds(lobes, model, delta))
    groups = [
        [k for k in kinds if side in k and ("Delta" in k) == is_delta]
        for is_delta in (False, True)
        for side in ("Reflection", "Transmission")
    ]
    flags = tuple(_union([getattr(flag, k) for k in g], flag) for g in groups)
    present = [i for i, c in enumerate(flags) if c]
    index = tuple(present.index(i) if c else 0 for i, c in enumerate(flags))
    extra = flag.FrontSide | (flag.BackSide if flags[1] or flags[3] else flag.Empty)
    if textured:
        extra |= flag.SpatiallyVarying
    if getattr(params, "anisotropic", 0) or "anisotropic" in textured:
        extra |= flag.Anisotropic
    refracts = _refracts(params, prepared, flags[1] | flags[3])
    non_symmetric = _non_symmetric(model, params, lobes, delta, refracts)
    m_components = tuple(
        c | extra | (flag.NonSymmetric if ns else flag.Empty)
        for c, ns in zip(flags, non_symmetric, strict=True)
        if c != flag.Empty
    )
    m_flags = functools.reduce(lambda a, b: a | b, m_components, flag.Empty)
    return Components(lobes, flags, index, refracts, non_symmetric, m_components, m_flags)


def _refracts(params: Any, prepared: Any, transmits: int) -> bool:
    """Whether a transmitted path changes medium (see :func:`.transport.eta_along`)."""
    import mitsuba as mi

    eta = prepared.eta
    solid = not getattr(params, "thin", False)
    bends = mi.BSDFFlags.GlossyTransmission | mi.BSDFFlags.DeltaTransmission
    if eta is None or not solid or not bool(transmits & bends):
        return False
    try:
        return float(eta) != 1.0  # a constant η = 1 does not bend the path
    except (TypeError, RuntimeError):
        return True  # a texture or an opaque value: it may


def _non_symmetric(model, params, lobes, delta, refracts) -> tuple[bool, bool, bool, bool]:
    """Which of the four components is not reciprocal: the transmission of a refracting
    solid (its η²) and any component holding a lobe the registry declares non-reciprocal
    (:attr:`~lookdev.materials.bsdf.Lobe.reciprocal`)."""
    out = [False, refracts, False, refracts]
    for name in lobes:
        lobe = model.lobe(name)
        if not lobe.is_reciprocal(params):
            out[int(lobe.transmits) + 2 * (name in delta)] = True
    return tuple(out)


def hemisphere_mask(ctx: Any, comps: Components, cos_view: Any, cos_light: Any) -> Any:
    """Directions in a hemisphere whose component the context asks for."""
    import drjit as dr

    same_side = cos_view * cos_light > 0
    want_r = _is_enabled(ctx, comps.flags[0], comps.index[0])
    want_t = _is_enabled(ctx, comps.flags[1], comps.index[1])
    # select, not ~: on scalar variants the mask is a Python bool, and ~True is -2.
    return dr.select(same_side, want_r, want_t)


def sampled_component(ctx: Any, comps: Components, reflected: Any, delta: Any):
    """A sample's component number, its reported type and whether the context wants it.

    Component i: 0/1 reflection/transmission with a density, 2/3 the deltas; the side is
    ``reflected``, the density or delta ``delta`` (masks, or Python bools).
    """
    import drjit as dr
    import mitsuba as mi

    flag = mi.BSDFFlags
    index, kind, enabled = [], [], []
    for r, t in ((0, 1), (2, 3)):
        index.append(dr.select(reflected, comps.index[r], comps.index[t]))
        kind.append(
            dr.select(reflected, _leading(comps.flags[r], flag), _leading(comps.flags[t], flag))
        )
        enabled.append(
            dr.select(
                reflected,
                _is_enabled(ctx, comps.flags[r], comps.index[r]),
                _is_enabled(ctx, comps.flags[t], comps.index[t]),
            )
        )
    return (
        mi.UInt32(dr.select(delta, index[1], index[0])),
        mi.UInt32(dr.select(delta, kind[1], kind[0])),
        dr.select(delta, enabled[1], enabled[0]),
    )


def _union(flags: list[Any], flag: Any) -> int:
    return int(functools.reduce(lambda a, b: a | b, flags, flag.Empty))


def _is_enabled(ctx: Any, component: int, index: int) -> bool:
    """Mitsuba's ``BSDFContext::is_enabled`` for a union of flags (the binding takes one)."""
    every_component = 0xFFFFFFFF
    wanted = (ctx.type_mask & component) == component
    return bool(component) and wanted and ctx.component in (every_component, index)


def _leading(component: Any, flag: Any) -> int:
    """The sampled type reported for a component: glossy if it has a glossy lobe."""
    for kind in (flag.DeltaReflection, flag.DeltaTransmission):
        if component & kind:
            return int(kind)
    for kind in (flag.GlossyReflection, flag.GlossyTransmission):
        if component & kind:
            return int(kind)
    for kind in (flag.DiffuseReflection, flag.DiffuseTransmission):
        if component & kind:
            return int(kind)
    return 0
