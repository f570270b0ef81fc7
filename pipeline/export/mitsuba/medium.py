"""The interior medium of a solid subsurface material, and the integrator it needs.

A solid Disney material with a scatter distance (:func:`lookdev.materials.subsurface.
has_interior`) is a boundary BSDF (our plugin: surface lobes, the diffuse entry and the
glass) around a Mitsuba ``homogeneous`` medium, isotropic, whose σt and albedo come from
:func:`lookdev.materials.subsurface.interior` (our slab's albedo table). Only scenes
holding such a medium need the volumetric path tracer; every other scene keeps ``path``
and its speed (:func:`integrator`).
"""

from __future__ import annotations

from typing import Any

from lookdev.materials.subsurface import has_interior, interior
from lookdev.pipeline.blend.result import as_hub

__all__ = ["integrator", "interior_dict"]


def interior_dict(material: Any, meters_per_unit: float = 1.0) -> dict[str, Any] | None:
    """The Mitsuba ``homogeneous`` medium inside ``material``, or None (no interior).

    ``meters_per_unit``: metres per unit of the scene it goes into (presets' distances
    are metres at metersPerUnit = 1). A textured scatter distance or colour is represented
    by its mean: a homogeneous medium has one σt and one albedo.
    """
    hub = as_hub(material)
    if hub.bsdf_model.name != "disney":
        return None
    params = hub.params
    changes = {}
    for name in ("base_color", "scatter_distance"):
        if name in hub.maps:
            changes[name] = hub.mean(name)
    if changes:
        params = params.model_copy(update=changes)
    if not has_interior(params):
        return None
    sigma_t, albedo = interior(params, meters_per_unit)
    # Mitsuba reads an RGB σt as a reflectance (each channel ≤ 1): the largest channel
    # goes into ``scale``.
    top = float(sigma_t.max())
    return {
        "type": "homogeneous",
        "sigma_t": {"type": "rgb", "value": [float(v) / top for v in sigma_t]},
        "scale": top,
        "albedo": {"type": "rgb", "value": [float(v) for v in albedo]},
        "phase": {"type": "isotropic"},
        # No emitter sampling from inside: the boundary is our (non-null) BSDF, so every
        # shadow ray from a medium event ends on it. Measured on the skin proof (160×80,
        # 16 spp): 12 % faster, mean radiance unchanged within noise (0.195 vs 0.196).
        "sample_emitters": False,
    }


def integrator(max_depth: int, interior: dict[str, Any] | None = None) -> dict[str, Any]:
    """``volpath`` where the scene holds an interior medium, else ``path`` (its speed)."""
    kind = "path" if interior is None else "volpath"
    return {"type": kind, "max_depth": int(max_depth)}
