"""Glass furnaces for Mitsuba's two transport modes: ``path`` (radiance) against ``ptracer``
(a particle tracer: importance), our plugin against Mitsuba's own dielectrics.

Two layouts under a constant white sky, emitters hidden (the particle tracer's direct
view of an environment is noisy and tests nothing here), box-filtered 8×8 film:

* ``inside``: the camera sits *inside* a glass ball (radius 2) and looks at a white
  Lambertian ball (radius 1) that fills the frame. Light enters the glass once and is seen
  from inside, so the image is the radiance in the glass: η² for a lossless solid
  (Veach 1997 §5.2, radiance/η² is invariant), 1 for a thin sheet. A BSDF whose
  Importance mode got the η² wrong (or any other non-reciprocity) is off by that factor
  in ``ptracer``. The glass is only *sampled* here (a shadow ray cannot pass it).
* ``outside``: the camera outside a ball of the material. ``ptracer`` connects the
  camera to the ball's surface by ``eval`` in Importance mode (light from inside,
  refracting towards the camera); the path tracer by sampling. Delta-only BSDFs cannot
  be connected (``ptracer`` renders them black), so smooth and thin glass use ``inside``.

``python tests/_transport_furnace.py`` prints the table quoted in the README and in
:mod:`lookdev.pipeline.export.mitsuba.transport`.
"""

from __future__ import annotations

from typing import Any

import numpy as np

RESOLUTION = 8
PATH_SPP = 1024
PTRACER_SPP = 32768
"""Measured spread of one 4096-spp ``ptracer`` render of rough glass ``inside``: 3.1 %
of the mean (16 seeds; the caustics give it a heavy tail, so 4 seeds underestimated it
threefold). At 32768 spp that is 1.1 %, and ``path`` at 1024 spp is below 0.1 %."""
TOLERANCE = 0.05
"""Relative agreement asked of two renders: ≈ 4.5 σ of the ``ptracer`` side."""


def cases() -> dict[str, tuple[Any, str]]:
    """name → (material params, layout)."""
    from lookdev.materials.params import DisneyParams
    from lookdev.materials.registry import model_named

    glass = DisneyParams(base_color=(1.0, 1.0, 1.0), spec_trans=1.0, roughness=0.0, ior=1.5)
    pixar = model_named("pixar").params_type.parse(
        {"clear": 1.0, "back": 1.0, "roughness": 0.6, "ior": 1.5}
    )
    pixar_clear = model_named("pixar").params_type.parse(
        {"surface_color": (1.0, 1.0, 1.0), "roughness": 0.0, "clear": 1.0, "ior": 1.52}
    )  # the preset pixar_clear_glass: a delta transmitted lobe
    mixed = glass.replace(spec_trans=0.6, diff_trans=0.3, roughness=0.3)
    return {
        "smooth": (glass, "inside"),
        "rough": (glass.replace(roughness=0.3), "inside"),
        "rough-outside": (glass.replace(roughness=0.3), "outside"),
        "thin": (glass.replace(thin=True), "inside"),
        "mixed": (mixed, "inside"),
        "mixed-outside": (mixed, "outside"),
        "pixar": (pixar, "inside"),
        "pixar-outside": (pixar, "outside"),
        "pixar-clear": (pixar_clear, "inside"),
    }


def has_builtin(params: Any) -> bool:
    """Whether Mitsuba has a twin of ``params`` (a Disney glass: spec_trans 1, metallic 0)."""
    return getattr(params, "spec_trans", 0.0) == 1.0 and getattr(params, "diff_trans", 0) == 0


def bsdfs(params: Any) -> dict[str, dict[str, Any]]:
    """``ours`` (the plugin, never ``principled``) and, where one exists, ``builtin``."""
    from lookdev.pipeline.bench.glass import builtin_dict
    from lookdev.pipeline.export.mitsuba.scene import bsdf_dict

    out = {"ours": bsdf_dict(params, allow_principled=False)}
    if has_builtin(params):
        out["builtin"] = builtin_dict(params)
    return out


def scene(mi: Any, bsdf: dict[str, Any], integrator: str, layout: str, spp: int) -> dict:
    T = mi.ScalarTransform4f
    white = {"type": "diffuse", "reflectance": {"type": "rgb", "value": [1.0, 1.0, 1.0]}}
    if layout == "inside":
        origin, fov = [0.0, 0.0, 1.8], 40.0  # the white ball (33.7° half-angle) fills it
        shapes = {
            "shell": {"type": "sphere", "radius": 2.0, "bsdf": bsdf},
            "ball": {"type": "sphere", "radius": 1.0, "bsdf": white},
        }
    else:
        origin, fov = [0.0, 0.0, 4.0], 35.0
        shapes = {"ball": {"type": "sphere", "radius": 1.0, "bsdf": bsdf}}
    film = {"type": "hdrfilm", "width": RESOLUTION, "height": RESOLUTION}
    return {
        "type": "scene",
        "integrator": {"type": integrator, "max_depth": 64, "hide_emitters": True},
        "sensor": {
            "type": "perspective",
            "fov": fov,
            "to_world": T().look_at(origin=origin, target=[0, 0, 0], up=[0, 1, 0]),
            "film": film | {"pixel_format": "rgb", "rfilter": {"type": "box"}},
            "sampler": {"type": "independent", "sample_count": spp},
        },
        "sky": {"type": "constant", "radiance": {"type": "rgb", "value": [1.0, 1.0, 1.0]}},
        **shapes,
    }


def furnace(mi: Any, bsdf: dict[str, Any], integrator: str, layout: str, seed: int = 0) -> float:
    """The image's mean (a white material: every channel alike) for one render."""
    spp = PTRACER_SPP if integrator == "ptracer" else PATH_SPP
    image = mi.render(mi.load_dict(scene(mi, bsdf, integrator, layout, spp)), seed=seed)
    return float(np.mean(np.array(image, dtype=np.float64)))


def table(mi: Any) -> list[tuple[str, str, str, float]]:
    """(case, bsdf, integrator, furnace value) for every case, renderer and mode."""
    rows = []
    for name, (params, layout) in cases().items():
        for label, bsdf in bsdfs(params).items():
            for integrator in ("path", "ptracer"):
                rows.append((name, label, integrator, furnace(mi, bsdf, integrator, layout)))
    return rows


if __name__ == "__main__":
    from lookdev.pipeline.variant import use_mitsuba

    use_mitsuba()
    import mitsuba

    for row in table(mitsuba):
        print(f"{row[0]:14s} {row[1]:8s} {row[2]:8s} {row[3]:.4f}", flush=True)
