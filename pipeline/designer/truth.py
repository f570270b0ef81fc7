"""Truth mode: the proofs' path tracer, scene and plugin, edited in place and refined.

The scene is the proofs' shader ball (:class:`lookdev.pipeline.proof.turntable.Turntable`:
the same scene dict, camera, rig, frozen ``mi.render``) with the material's plugin in its
``live`` form (:data:`lookdev.pipeline.export.mitsuba.inputs.LIVE`): every continuous
parameter is a traversed value the kernels read from memory and every lobe a value can
switch on is traced, so an edit is a ``mi.traverse`` update and the next pass replays
the recorded kernels (no scene reload, no new kernel). Passes of ``pass_spp`` samples
accumulate into two halves (:mod:`.progressive`); once the image has been still for
:data:`STILL_SECONDS` it is also denoised as the proofs denoise
(:mod:`lookdev.pipeline.proof.denoise`: OIDN guided by albedo and normals), the raw
image one :meth:`TruthMode.raw_image` away.

What rebuilds the scene instead (a new kernel, once; Dr.Jit caches it on disk): a switch
(``thin``, ``sheen_model``, ``specular_gamma``, ``energy_compensation``, ``ior`` given or
not), a parameter turning from a constant into a map or a map changing size, normal,
bump or subsurface-medium changes (the medium's coefficients come from the parameters)
and a new film size. The path depth is :data:`TRUTH_DEPTH` whatever the lobes, so
switching the glass on needs no new integrator.
"""

from __future__ import annotations

import hashlib
import time
from typing import Any

import numpy as np

from lookdev.pipeline.export.mitsuba.depth import DEPTH_SOLID_GLOSSY, max_depth_for
from lookdev.pipeline.proof import shaderball
from lookdev.pipeline.proof.ibl import envmap_to_world

from .progressive import MAX_SPP, NOISE_TARGET, Part

__all__ = ["PASS_SPP", "STILL_SECONDS", "TRUTH_DEPTH", "TruthMode", "envmap_data"]

TRUTH_DEPTH = DEPTH_SOLID_GLOSSY
"""Path depth of every surface material (the deepest a surface needs, solid glass: Mitsuba's
Russian roulette ends most paths long before it)."""
PASS_SPP = 1
"""Samples per pixel of a pass: the first frame after an edit comes soonest."""
STILL_SECONDS = 0.5
"""An image unchanged this long is denoised."""


def envmap_data(pixels: np.ndarray) -> Any:
    """Lat-long pixels as Mitsuba's ``envmap`` holds them (its ``data`` parameter)."""
    import mitsuba as mi

    emitter = mi.load_dict({"type": "envmap", "bitmap": mi.Bitmap(np.ascontiguousarray(pixels))})
    return mi.traverse(emitter)["data"]


def _digest(array: Any) -> str:
    if array is None:
        return "-"
    a = np.ascontiguousarray(array, dtype=np.float32)
    return f"{a.shape}:{hashlib.sha256(a.tobytes()).hexdigest()[:16]}"


def structure(hub: Any) -> str:
    """Everything about ``hub`` that shapes the truth scene's kernels (module docstring)."""
    from lookdev.pipeline.export.mitsuba.inputs import opaque_inputs
    from lookdev.pipeline.export.mitsuba.medium import interior_dict
    from lookdev.pipeline.export.mitsuba.scene import plugin_inputs

    from .relight import structure_key

    model = hub.bsdf_model
    constants, maps = plugin_inputs(hub)
    params = model.params_type.parse(constants, where=hub.name)
    key = structure_key(model, params, opaque_inputs(model, params))
    shapes = sorted((k, np.shape(v)) for k, v in maps.items())
    normals = [
        _digest(getattr(hub, n)) for n in ("normal_map", "specular_normal_map", "height_map")
    ]
    medium = interior_dict(hub, shaderball.METERS_PER_UNIT)
    return repr((key, shapes, normals, repr(medium), tuple(hub.uv_extent)))


class TruthMode:
    """The truth-mode renderer of one viewport (see the module docstring)."""

    def __init__(
        self,
        hub: Any,
        environment: np.ndarray,
        size: tuple[int, int],
        geometry: str | None = None,
        *,
        rig: str = "full",
        seed: int = 0,
        noise_target: float = NOISE_TARGET,
        max_spp: int = MAX_SPP,
        pass_spp: int = PASS_SPP,
    ):
        self.size = (int(size[0]), int(size[1]))
        self.environment = environment
        self.geometry, self.rig, self.seed = geometry, rig, int(seed)
        self.noise_target, self.max_spp, self.pass_spp = noise_target, max_spp, pass_spp
        self.ibl, self.element = 0.0, 0.0
        self.rebuilds = 0
        self._build(hub)

    # -- the scene ------------------------------------------------------------------------
    def _build(self, hub: Any) -> None:
        from lookdev.pipeline.export.mitsuba import bsdf_dict
        from lookdev.pipeline.export.mitsuba.medium import interior_dict
        from lookdev.pipeline.proof.turntable import Turntable

        self.hub, self.key = hub, structure(hub)
        interior = interior_dict(hub, shaderball.METERS_PER_UNIT)
        depth = TRUTH_DEPTH if interior is None else max_depth_for(hub)
        self.table = Turntable(
            bsdf_dict(hub, live=True),
            self.environment,
            self.size,
            depth,
            self.geometry,
            rig=self.rig,
            interior=interior,
        )
        self.params = self.table.params
        self.rebuilds += 1
        self._guides = None
        self._pose(self.element, self.ibl)
        self.part = Part(self.size[0] * self.size[1], 1, self.noise_target, self.max_spp)
        self._changed()

    def _pose(self, element: float, ibl: float) -> None:
        self.params["ball.to_world"] = shaderball.ball_to_world(element)
        self.params["cup.to_world"] = shaderball.cup_to_world(element)
        self.params["environment.to_world"] = envmap_to_world(ibl)
        self.params.update()

    def _changed(self) -> None:
        self.part.reset()
        self.passes = 0
        self.changed_at = time.monotonic()
        self._still = False
        self.denoised: np.ndarray | None = None
        self.denoised_spp = 0

    def _plugin_keys(self) -> dict[str, list[str]]:
        """Traversed parameter → its scene keys, over every live plugin in the scene."""
        out: dict[str, list[str]] = {}
        for key in self.params.keys():
            node = self.params.properties[key][2]
            inputs = getattr(node, "inputs", None)  # a lookdev plugin's (mitsuba.inputs)
            if getattr(inputs, "live", False) and hasattr(node, "traversed"):
                field = key.rsplit(".", 1)[-1]
                if field in node.traversed:
                    out.setdefault(field, []).append(key)
                elif key.endswith(".data") and key.rsplit(".", 2)[-2] in inputs.textures:
                    out.setdefault(key.rsplit(".", 2)[-2] + ".data", []).append(key)
        return out

    def set_material(self, hub: Any) -> None:
        """A new material: its values pushed in place, or a rebuild when its structure
        changed (module docstring)."""
        import mitsuba as mi

        from lookdev.pipeline.export.mitsuba.scene import plugin_inputs

        if structure(hub) != self.key:
            self._build(hub)
            return
        model = hub.bsdf_model
        constants, maps = plugin_inputs(hub)
        params = model.params_type.parse(constants, where=hub.name)
        for field, keys in self._plugin_keys().items():
            if field.endswith(".data"):
                data = np.asarray(maps[field.removesuffix(".data")], np.float32)
                value = mi.TensorXf(data if data.ndim == 3 else data[..., None])
            else:
                v = getattr(params, field)
                value = mi.Vector3f(*map(float, v)) if isinstance(v, tuple) else mi.Float(float(v))
            for key in keys:
                self.params[key] = value
        self.params.update()
        self.hub = hub
        self._guides = None
        self._changed()

    def set_environment(self, pixels: np.ndarray) -> None:
        """New environment pixels, of the size the scene was loaded with."""
        self.environment = pixels
        self.params["environment.data"] = envmap_data(pixels)
        self.params.update()
        self._changed()

    def rotate_ibl(self, degrees: float) -> None:
        self.ibl = float(degrees)
        self.params["environment.to_world"] = envmap_to_world(self.ibl)
        self.params.update()
        self._guides = None
        self._changed()

    def rotate_element(self, degrees: float) -> None:
        self.element = float(degrees)
        self._pose(self.element, self.ibl)
        self._guides = None
        self._changed()

    def resize(self, width: int, height: int) -> None:
        self.size = (int(width), int(height))
        self._build(self.hub)

    # -- rendering ------------------------------------------------------------------------
    @property
    def converged(self) -> bool:
        return self.part.converged

    @property
    def spp(self) -> int:
        return self.part.spp

    def step(self) -> np.ndarray:
        """One pass (unless converged); the accumulated raw image (H, W, 3) float32."""
        # Still as the step began: a slow pass must not make the first frame after an
        # edit look still and pay for a denoise.
        self._still = self.still
        if not self.part.converged:
            spp = max(1, min(self.pass_spp, self.max_spp - self.part.spp))
            seed = ((self.seed & 0xFFF) << 20) | (self.passes & 0xFFFFF)
            image = self.table.render(spp, seed)
            self.part.add(image.reshape(-1, 3), 0, spp)
            self.passes += 1
        return self.raw_image()

    def raw_image(self) -> np.ndarray:
        width, height = self.size
        return self.part.mean().astype(np.float32).reshape(height, width, 3)

    @property
    def still(self) -> bool:
        return time.monotonic() - self.changed_at >= STILL_SECONDS

    def denoised_image(self) -> np.ndarray | None:
        """The accumulated image denoised, once still: redone when the samples have
        doubled since the last one (or refinement stopped); None before."""
        from lookdev.pipeline.proof import denoise

        if not (self._still or self.converged) or not self.part.spp:
            return None
        stale = self.denoised is None or self.part.spp >= 2 * self.denoised_spp
        if stale or (self.converged and self.denoised_spp != self.part.spp):
            if self._guides is None:
                renderer = denoise.GuideRenderer(
                    self.table.scene, self.table.camera_index, denoise.GUIDE_SPP, freeze=False
                )
                self._guides = renderer.render(seed=self.seed)
            self.denoised = denoise.denoise(self.raw_image(), self._guides)
            self.denoised_spp = self.part.spp
        return self.denoised
