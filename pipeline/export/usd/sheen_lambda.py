"""The exact-Λ Conty-Kulla sheen (``sheen_lambda = "exact"``) in an export.

No target has it: MaterialX's ``sheen_bsdf`` in mode ``conty_kulla`` (the sheen of
``ND_disney_principled``) is the paper's model, the fitted Λ of Table 1 with its floor
r ≥ 0.08, and RenderMan's and UsdPreviewSurface's sheens are not Conty-Kulla's at all.
An export therefore writes the sheen as each target has it, names the loss with its
measured size (the difference of the lobe's directional albedo between the two Λ, read
from the shipped tables at the material's roughness), and keeps the mode, the sheen model
and the roughness in the Material's ``customData`` so that the import gives them back.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from lookdev.materials import sheen

__all__ = ["CARRIED", "albedo_difference", "exact_sheen"]

CARRIED = ("sheen_lambda", "sheen_model", "sheen_roughness")
"""What ``customData`` keeps of an exact-Λ sheen for the import."""

VIEW_MAX = 85.0
"""Views compared, up to 85° from the normal (the fidelity report's last angle). Beyond
it the two differ most, but over a sliver of a sphere: the fit's albedo dips there
(E(cos θ = 10⁻⁴) = 0.63 against 0.96 exact, r = 0.3) because its Λ stays finite where
the true one grows like 1/cos θ."""
_MU = np.linspace(np.cos(np.radians(VIEW_MAX)), 1.0, 200)


def albedo_difference(r: float | None = None) -> tuple[float, float, float]:
    """(largest |E_fit − E_exact|, its cos θ, its r) of the softened lobe (F = 1) over
    views up to :data:`VIEW_MAX`, at roughness ``r`` or, for None (a roughness map),
    over r ∈ [0.01, 1]."""
    rs = np.geomspace(sheen.R_MIN_EXACT, 1.0, 41) if r is None else np.array([float(r)])
    d = np.abs(
        sheen.albedo(_MU[None, :], rs[:, None], True, "fit")
        - sheen.albedo(_MU[None, :], rs[:, None], True, "exact")
    )
    j, i = np.unravel_index(np.argmax(d), d.shape)
    return float(d[j, i]), float(_MU[i]), float(rs[j])


def exact_sheen(source: Any) -> Any:
    """Name the loss of a live exact-Λ sheen and carry its mode for the import.

    ``source`` is a :class:`.network.Source` (not imported: network calls this)."""
    if source.model != "disney" or not source.lobes.get("conty_kulla"):
        return source
    values = source.live_values
    if values.get("sheen_lambda", "fit") != "exact":
        return source
    mapped = "sheen_roughness" in source.maps
    diff, mu, r = albedo_difference(None if mapped else values["sheen_roughness"])
    for key in CARRIED:
        source.custom[key] = values[key] if isinstance(values[key], str) else float(values[key])
    where = "over its roughness map" if mapped else f"at r = {r:.3g}"
    source.notes.append(
        "its Conty-Kulla sheen uses the exact Λ (sheen_lambda=exact); MaterialX's sheen_bsdf "
        "(conty_kulla) has the fitted Λ of Table 1, r ≥ 0.08: the sheen's directional albedo "
        f"differs by up to {diff:.3g} {where} (θ = {np.degrees(np.arccos(mu)):.0f}°; "
        "sheen_lambda is kept in customData)"
    )
    return source
