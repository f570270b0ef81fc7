"""Pixar layers: lobe-weight compositing (Smits, "Reflection Model Design for Wall-E and Up",
section "Layering").

Each layer is Smits' six lobes with normal and grazing weights (:func:`layer_lobes`), the
cone angles of its highlight lobes, a diffuse and a highlight normal, and a layer weight
α = mask × presence. Two ways to combine a stack, top first:

**Simple layering** (``"simple"``): "the weights can be computed with standard A over B
compositing and then applied directly to the lobe weights": layer k gets
``cₖ = αₖ Πⱼ₍above₎ (1 − αⱼ)``, every lobe weight is ``Σ cₖ Wₖ``.

**Full layering** (``"full"``, the default): light that layer A transmits (refraction,
transmitted specular, transmitted diffuse) meets the six lobes of the layer B below.
Blur orders the lobe types, reflection/refraction < specular < diffuse; a B lobe that
blurs less keeps the incoming type and cone, one that blurs the same keeps the type and
takes the max cone, one that blurs more replaces the type (and brings its own cone).
That gives Smits' table for the light reflected back out of B::

    A \\ B              reflection B   specular B   diffuse B
    refraction A       reflection     specular     diffuse
    transmitted spec   specular       specular     diffuse
    transmitted diff   diffuse        diffuse      diffuse

and the same nine interactions with B's transmitted lobes accumulate the transmission
that the next layer down receives. Incident light enters as a unit refraction packet of
cone 0, so a lone layer reproduces its own lobes exactly. Where α < 1 the uncovered share
passes to the next layer unchanged; under the bottom layer there is nothing, so light
that gets through every layer leaves as the composite's transmitted lobes. Weights
multiply per channel and separately at normal and grazing incidence; every interaction
moves at most the energy it receives, so no stack returns more than 1 per channel.
Smits' one-pass scheme does not attenuate light reflected by B on its way back up
through A ("account for all interactions in some plausible manner").

Cones and normals are blended by energy, "the product of the lobe and layer weights":
an interaction's energy is the channel mean of its (N + G)/2 weight. Two normals are kept,
one for the diffuse lobes and one for the highlights (Smits: "two, one for all diffuse,
one for all highlights").

The diffuse weights depend on the view through FrnBlend(…, V·n), which is affine in
s = (1 − V·n)⁵. A stack is therefore composited twice, for the view at normal incidence
(s = 0) and at grazing (s = 1); simple layering is linear, so its result is exact at
every view by interpolating in s, full layering is exact at both ends.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from lookdev.materials.pixar import PixarParams, lobe_weights
from lookdev.materials.pixar_lobes import CONE_MIN_DEG, LN_10, reflection_cone, specular_cone
from lookdev.materials.pixar_scatter import LOBES, PIXAR_LOBES, PREFIX

from .errors import BlendError

__all__ = [
    "BLUR",
    "FLAT",
    "GROUP",
    "Lobes",
    "Part",
    "REFLECTED",
    "TRANSMITTED",
    "TYPE_OF",
    "composite",
    "energy_sum",
    "layer_lobes",
    "unit",
]

BLUR = {"reflection": 0, "specular": 1, "diffuse": 2}
"""Smits' order of blurring: reflection/refraction < specular < diffuse."""
# Smits' lobe types, their reflected and transmitted lobes and the normal each is shaded
# with, as the model's registry declares them (lookdev.materials.pixar_scatter.PIXAR_LOBES).
TYPE_OF = {lobe.name: lobe.family for lobe in PIXAR_LOBES}
REFLECTED = {lobe.family: lobe.name for lobe in PIXAR_LOBES if not lobe.transmits}
TRANSMITTED = {lobe.family: lobe.name for lobe in PIXAR_LOBES if lobe.transmits}
GROUP = {lobe.name: "highlight" if lobe.highlight else "diffuse" for lobe in PIXAR_LOBES}
FLAT = np.array([0.0, 0.0, 1.0])
"""The geometric normal in the shading frame."""


@dataclass
class Part:
    """Light of one lobe type: normal/grazing weights (…, 3), cone (…), normal (…, 3)."""

    n: Any
    g: Any
    cone: Any = 0.0
    normal: Any = None
    """None: the geometric normal (0, 0, 1); no normal arithmetic is done for it."""
    falloff: Any = LN_10
    """−ln of the lobe's value at its cone relative to its peak: Smits' powerS falls to
    0.1^r there (r ln 10), powerR to 0.1 (ln 10). It travels with the cone, so the
    composite's exponent is falloff / sin²(cone) and a lone layer keeps its own."""

    @property
    def energy(self) -> Any:
        """Channel mean of (N + G)/2: the weight for energy-weighted blending."""
        total = self.n + self.g  # channels summed by hand: a mean over a last axis of 3 is slow
        return (total[..., 0] + total[..., 1] + total[..., 2]) * (1.0 / 6.0)


Lobes = dict[str, Part]
"""Lobe name (:data:`LOBES`) → its light."""


def layer_lobes(
    params: PixarParams, cos_view: float, normals: dict | None = None, maps: dict | None = None
) -> Lobes:
    """One layer's six lobes (Smits' weights, cones in degrees) for a view at ``cos_view``.

    Cones: specular (30 r + 5)°, reflection 10 r° (at least the model's floor), each times
    its cone scale; transmitted lobes share their front twin's cone. ``maps`` give
    parameters per texel (a textured layer): weights (..., 3) and cones (...) per texel.
    """
    maps = maps or {}
    w = lobe_weights(params, cos_view, maps)
    r = maps.get("roughness", params.roughness)
    spec = specular_cone(r, maps.get("specular_cone_scale", params.specular_cone_scale))
    refl_scale = maps.get("reflection_cone_scale", params.reflection_cone_scale)
    refl = np.maximum(reflection_cone(r, refl_scale), CONE_MIN_DEG)
    refl = refl if np.ndim(refl) else float(refl)
    cone = {"diffuse": 0.0, "specular": spec, "reflection": refl}
    falloff = {"diffuse": LN_10, "specular": r * LN_10, "reflection": LN_10}
    normals = normals or {}
    return {
        lobe: Part(
            np.asarray(w[PREFIX[lobe] + "N"], dtype=np.float64),
            np.asarray(w[PREFIX[lobe] + "G"], dtype=np.float64),
            cone[TYPE_OF[lobe]],
            normals.get(GROUP[lobe]),
            falloff[TYPE_OF[lobe]],
        )
        for lobe in LOBES
    }


class _Sum:
    """Accumulates parts per lobe: weights add, cones and normals average by energy."""

    def __init__(self) -> None:
        self.parts: dict[str, list[Part]] = {lobe: [] for lobe in LOBES}

    def add(self, lobe: str, part: Part) -> None:
        self.parts[lobe].append(part)

    def total(self, lobe: str) -> Part:
        """The lobe's summed weights, mean cone and falloff, energy-weighted normal *sum*.

        Means are taken about the first part's value, so parts that share a cone (or a
        lone part) give that cone exactly. The normal stays None when every part has the
        geometric normal (no normal maps: the common case costs no vector arithmetic).
        """
        parts = self.parts[lobe] or [_zero()]
        energies = [p.energy for p in parts]
        n = sum(p.n for p in parts[1:]) + parts[0].n
        g = sum(p.g for p in parts[1:]) + parts[0].g
        e_sum = sum(energies)
        e_sum = np.where(e_sum > 0, e_sum, 1.0)

        def mean(attr: str) -> Any:
            ref = getattr(parts[0], attr)
            spread = sum(e * (getattr(p, attr) - ref) for e, p in zip(energies, parts, strict=True))
            return ref + spread / e_sum

        cone, falloff = mean("cone"), mean("falloff")
        normal = None
        if any(p.normal is not None for p in parts):
            normal = sum(
                np.asarray(e)[..., None] * (FLAT if p.normal is None else p.normal)
                for e, p in zip(energies, parts, strict=True)
            )
        return Part(n, g, cone, normal, falloff)


def composite(
    layers: Sequence[tuple[Lobes, Any]], mode: str = "full"
) -> tuple[Lobes, dict[str, np.ndarray]]:
    """Combine ``(lobes, α)`` pairs, **top first**, into one set of lobes and two normals.

    Returns the composite's lobes (cones energy-weighted; their ``normal`` is None) and
    the ``{"diffuse", "highlight"}`` unit normals that replace per-lobe normals
    (energy-weighted, the geometric normal where there is no energy).
    """
    if mode not in ("full", "simple"):
        raise BlendError(f"unknown Pixar layering {mode!r}; allowed: full, simple")
    acc = _Sum()
    if mode == "simple":
        _simple(layers, acc)
    else:
        _full(layers, acc)
    lobes = {lobe: acc.total(lobe) for lobe in LOBES}
    normals = {}
    for group in ("diffuse", "highlight"):
        members = [lobes[lobe] for lobe in LOBES if GROUP[lobe] == group]
        if all(p.normal is None for p in members):
            normals[group] = FLAT
            continue
        weighted = [
            p.normal if p.normal is not None else p.energy[..., None] * FLAT for p in members
        ]
        normals[group] = unit(sum(weighted))
    for part in lobes.values():
        part.normal = None
    return lobes, normals


def _simple(layers: Sequence[tuple[Lobes, Any]], acc: _Sum) -> None:
    """A over B: layer k contributes cₖ = αₖ Π(1 − αⱼ above) of each of its lobes."""
    remaining: Any = 1.0
    for lobes, alpha in layers:
        c = alpha * remaining
        if not _known(c, 0.0):
            for lobe, part in lobes.items():
                acc.add(lobe, _scaled(part, c))
        remaining = remaining * (1.0 - alpha)


def _full(layers: Sequence[tuple[Lobes, Any]], acc: _Sum) -> None:
    """Packets of transmitted light meet each layer's lobes by Smits' table (module doc)."""
    one = np.ones(3)
    packets = {"reflection": Part(one, one, 0.0)}  # the incident light, unblurred
    for lobes, alpha in layers:
        onward = _Sum()
        for kind, packet in packets.items():
            for lobe, part in () if _known(alpha, 0.0) else lobes.items():
                out_type, cone, falloff = _interact(kind, packet, TYPE_OF[lobe], part)
                hit = Part(packet.n * part.n, packet.g * part.g, cone, part.normal, falloff)
                hit = _scaled(hit, alpha)
                if lobe.endswith("_t"):
                    onward.add(TRANSMITTED[out_type], hit)
                else:
                    acc.add(REFLECTED[out_type], hit)
            if not _known(alpha, 1.0):
                onward.add(TRANSMITTED[kind], _scaled(packet, 1.0 - alpha))  # through holes
        packets = {
            TYPE_OF[lobe]: _normalised(onward.total(lobe)) for lobe in LOBES if lobe.endswith("_t")
        }
    for kind, packet in packets.items():
        acc.add(TRANSMITTED[kind], packet)


def _known(alpha: Any, value: float) -> bool:
    """True when every α equals ``value`` (its parts would be exactly zero: skip them)."""
    return bool(np.all(np.asarray(alpha) == value))


def _interact(incoming: str, packet: Part, lobe: str, part: Part) -> tuple[str, Any, Any]:
    """Smits' rule: less blur keeps type and cone, same blur takes the max cone, more
    blur replaces the type and "keeps any cone angle the same", read as: the lobe keeps
    its own cone (a refracted ray meeting a 20° specular lobe leaves in that lobe).
    The falloff goes with the cone it belongs to (the blurrier one on a tie)."""
    if BLUR[lobe] < BLUR[incoming]:
        return incoming, packet.cone, packet.falloff
    if BLUR[lobe] == BLUR[incoming]:
        wider = packet.cone > part.cone
        tie = packet.cone == part.cone
        falloff = np.where(
            tie,
            np.minimum(packet.falloff, part.falloff),
            np.where(wider, packet.falloff, part.falloff),
        )
        return incoming, np.maximum(packet.cone, part.cone), falloff
    return lobe, part.cone, part.falloff


def _scaled(part: Part, c: Any) -> Part:
    c = np.asarray(c)
    return Part(part.n * c[..., None], part.g * c[..., None], part.cone, part.normal, part.falloff)


def _normalised(part: Part) -> Part:
    """A part whose normal sum (energy-weighted, from :class:`_Sum`) is made unit."""
    normal = None if part.normal is None else unit(part.normal)
    return Part(part.n, part.g, part.cone, normal, part.falloff)


def unit(v: np.ndarray) -> np.ndarray:
    v = np.asarray(v, dtype=np.float64)
    length = np.linalg.norm(v, axis=-1, keepdims=True)
    flat = np.broadcast_to(FLAT, v.shape)
    return np.where(length > 1e-12, v / np.where(length > 1e-12, length, 1.0), flat)


def _zero() -> Part:
    """No light: what a lobe nothing reached totals to."""
    z = np.zeros(3)
    return Part(z, z, 0.0)


def energy_sum(lobes: Lobes) -> tuple[np.ndarray, np.ndarray]:
    """Σ over the six lobes of the normal and of the grazing weights, per channel."""
    return sum(p.n for p in lobes.values()), sum(p.g for p in lobes.values())
