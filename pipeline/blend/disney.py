"""Disney layers: parameter blending (Burley 2012 §5.7 and §6.1).

A stack is blended bottom to top like a Photoshop layer stack: each layer's parameters
replace those below in proportion to its mask, ``p ← lerp(p, pᵢ, mᵢ)``, for every
parameter, colours included, in the space the parameters are written in. That space is
Burley's perceptually linear one (roughness, not α = roughness²; ``specular``, not F0),
the one in which "materials generally interpolate in a very intuitive way" (§5.7).

Unrolled, the chain is a weighted sum (:func:`stack_weights`)::

    p = Σᵢ wᵢ pᵢ,   wᵢ = mᵢ · Πⱼ>ᵢ (1 − mⱼ),   w₀ = Πⱼ>₀ (1 − mⱼ)

which is exact at masks 0 and 1 (a full-coverage layer gives weight exactly 1 to itself and
exactly 0 below), and lets one matrix product produce every parameter map of a tile.

Parameters that cannot be interpolated (``thin``, ``sheen_model``, ``energy_compensation``)
must agree across the layers that show; ``ior`` is blended as the ``specular`` it spells
(Burley's parameter, linear in F0) and spelled back as ``ior`` only when every layer wrote
``ior``.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from lookdev.materials.fresnel import specular_to_ior
from lookdev.materials.params import DisneyParams

from .errors import BlendError

__all__ = [
    "COLOR",
    "DISCRETE",
    "SCALARS",
    "VOTERS",
    "assemble",
    "check_discrete",
    "layer_values",
    "spell_specular",
    "stack_weights",
]

COLOR = "base_color"
SCALARS = tuple(
    name
    for name, info in DisneyParams.model_fields.items()
    if info.annotation in (float, "float") and name != COLOR
)
"""Continuous scalar parameters, blended linearly (``ior`` travels as ``specular``)."""
DISCRETE = ("thin", "sheen_model", "sheen_lambda", "scatter_distance_scale", "energy_compensation")
"""Parameters with no in-between: every layer that shows must agree (the per-channel
scale of the scatter distance shapes one homogeneous interior medium, so it is one value)."""
VOTERS = {
    "sheen_model": "sheen",
    "sheen_lambda": "sheen",
    "scatter_distance_scale": "scatter_distance",
}
"""A layer votes on these only where the parameter they refine is non-zero."""


def layer_values(params: DisneyParams) -> dict[str, Any]:
    """The continuous parameters of one layer in blending space (``ior`` as ``specular``)."""
    values: dict[str, Any] = {COLOR: tuple(params.base_color)}
    values.update({name: float(getattr(params, name)) for name in SCALARS})
    values["specular"] = float(params.effective_specular)
    return values


def stack_weights(masks: Sequence[Any], out: np.ndarray | None = None) -> Any:
    """Weights of the layers of a stack whose masks above the base are ``masks``.

    Returns ``[w₀, w₁, …]`` (base first), broadcastable like the masks, summing to 1.
    With ``out`` (shape (L, …)) the weights are written there, in place, and it is
    returned. Top down, ``wᵢ = mᵢ · r`` then ``r ← r − wᵢ`` (= r (1 − mᵢ)), so mᵢ = 1
    leaves exactly 0 for every layer below.

    >>> [float(w) for w in stack_weights([0.5, 1.0])]  # a full-coverage top hides all below
    [0.0, 0.0, 1.0]
    >>> [float(w) for w in stack_weights([0.5, 0.5])]
    [0.25, 0.25, 0.5]
    """
    weights: Any = [None] * (len(masks) + 1) if out is None else out
    remaining: Any = 1.0
    if out is not None:
        remaining = out[0]
        remaining.fill(1.0)
    for i in range(len(masks), 0, -1):
        if out is None:
            weights[i] = masks[i - 1] * remaining
            remaining = remaining - weights[i]
        else:
            np.multiply(masks[i - 1], remaining, out=out[i])
            remaining -= out[i]
    if out is None:
        weights[0] = remaining
    return weights


def check_discrete(stack: Sequence[tuple[str, DisneyParams]]) -> dict[str, Any]:
    """The one value of each discrete parameter, or a :class:`BlendError` naming the layer.

    A layer without sheen does not vote on ``sheen_model``, nor one without a scatter
    distance on its scale (:data:`VOTERS`: the choice changes nothing there). ``stack``
    is ``(label, params)`` bottom to top, of the layers that show.
    """
    out: dict[str, Any] = {}
    for name in DISCRETE:
        voters = [
            (label, p) for label, p in stack if name not in VOTERS or getattr(p, VOTERS[name]) > 0
        ]
        voters = voters or list(stack[-1:])
        first_label, first = voters[0]
        for label, p in voters[1:]:
            if getattr(p, name) != getattr(first, name):
                raise BlendError(
                    f"{name} = {getattr(p, name)!r} differs from layer {first_label!r} "
                    f"({getattr(first, name)!r}); it cannot be blended, so the layers that "
                    "show must agree",
                    where=f"layer {label!r}",
                    field=name,
                )
        out[name] = getattr(first, name)
    return out


def spell_specular(stack: Sequence[DisneyParams], specular: Any) -> dict[str, Any]:
    """``specular`` (constant or map) in the spelling the layers used.

    ``ior`` when every layer wrote ``ior`` (one shared value passes through exactly), else
    ``specular``: a stack mixing the two spellings takes the 2012 one.
    """
    iors = {p.ior for p in stack}
    if None in iors:
        return {"specular": specular}
    if len(iors) == 1:
        return {"ior": iors.pop()}
    ior = specular_to_ior(np.asarray(specular))
    return {"ior": ior.astype(np.float32) if np.ndim(ior) else float(ior)}


def assemble(
    constants: dict[str, Any], discrete: dict[str, Any], stack: Sequence[DisneyParams]
) -> dict[str, Any]:
    """The constants of a blended Disney material: one spelling of specular, plain values."""
    out = {k: v for k, v in constants.items() if k != "specular"}
    if "specular" in constants:
        out.update(spell_specular(stack, constants["specular"]))
    out.update(discrete)
    return out
