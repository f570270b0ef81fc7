"""Designer mode (:cite:`Burley2012` §6.1): a g-buffer of the proof scene relit per edit.

The scene is the proofs' (:func:`lookdev.pipeline.proof.shaderball.scene_dict`) with a
stand-in BSDF on the material's shapes: it is only intersected, never path traced, so
it is loaded once per geometry and environment size. The g-buffer (:mod:`.gbuffer`) is
rendered again when the element turns or the film changes size; the lighting turns by the
envmap's ``to_world`` alone (:mod:`.relight`); a new material changes the shading
inputs and restarts the accumulation (:mod:`.progressive`).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from lookdev.pipeline.proof import shaderball
from lookdev.pipeline.proof.ibl import envmap_to_world

from . import gbuffer as gbuffer_module
from .progressive import MAX_SPP, NOISE_TARGET, Part
from .relight import Relighter

__all__ = ["STAND_IN", "DesignerMode"]

STAND_IN = {"type": "diffuse"}
"""The BSDF the g-buffer's scene puts on the material's shapes (never shaded)."""
FIRST_SPP, LATER_SPP = 1, 4
"""Samples per pixel of the first pass after a change (the quickest answer) and of the
passes that refine it (fewer launches per sample)."""


class DesignerMode:
    """The designer-mode renderer of one viewport (see the module docstring)."""

    def __init__(
        self,
        hub: Any,
        environment: np.ndarray,
        size: tuple[int, int],
        geometry: str | None = None,
        *,
        rig: str = "full",
        shadows: bool = True,
        seed: int = 0,
        noise_target: float = NOISE_TARGET,
        max_spp: int = MAX_SPP,
    ):
        import mitsuba as mi

        self.size = (int(size[0]), int(size[1]))
        self.geometry, self.rig, self.seed = geometry, rig, int(seed)
        self.scene = mi.load_dict(
            shaderball.scene_dict(STAND_IN, environment, self.size, 2, geometry, rig=rig)
        )
        self.params = mi.traverse(self.scene)
        self.relighter = Relighter(self.scene, shadows=shadows)
        self.element = 0.0
        self.hub = hub
        self.noise_target, self.max_spp = noise_target, max_spp
        self.passes = 0
        self._render_gbuffer()

    # -- state changes ------------------------------------------------------------------
    def _render_gbuffer(self) -> None:
        width, height = self.size
        self.gbuffer = gbuffer_module.render(self.scene, width, height)
        self.relighter.set_material(self.hub, self.gbuffer)
        layers = len(self.gbuffer.material)
        self.parts = {
            name: Part(width * height, layers, self.noise_target, self.max_spp)
            for name in ("material", "other")
        }
        self.passes = {"material": 0, "other": 0}

    def restart(self, parts: tuple[str, ...] = ("material", "other")) -> None:
        for name in parts:
            self.parts[name].reset()
            self.passes[name] = 0

    def set_material(self, hub: Any) -> None:
        """A new material: only its own pixels start again (the lighting is the same)."""
        self.hub = hub
        self.relighter.set_material(hub, self.gbuffer)
        self.restart(("material",))

    def set_environment(self, pixels: np.ndarray) -> None:
        """New environment pixels, of the size the scene was loaded with (the viewport
        brings every IBL to one size: a new size would be a new kernel)."""
        from .truth import envmap_data

        data = envmap_data(pixels)
        self.params["environment.data"] = data
        self.params.update()
        self.restart()

    def rotate_ibl(self, degrees: float) -> None:
        self.params["environment.to_world"] = envmap_to_world(degrees)
        self.params.update()
        self.restart()

    def rotate_element(self, degrees: float) -> None:
        self.element = float(degrees)
        self.params["ball.to_world"] = shaderball.ball_to_world(self.element)
        self.params["cup.to_world"] = shaderball.cup_to_world(self.element)
        self.params.update()
        self._render_gbuffer()

    def resize(self, width: int, height: int) -> None:
        self.size = (int(width), int(height))
        self.params["sensor.film.size"] = mi_vector(self.size)
        self.params.update()
        self._render_gbuffer()

    # -- rendering ------------------------------------------------------------------------
    @property
    def converged(self) -> bool:
        return all(p.converged for p in self.parts.values())

    @property
    def spp(self) -> int:
        """Samples per pixel of the material's pixels (the rest of the frame refines
        after them, see :meth:`step`); of the rest when no material is in view."""
        material = self.parts["material"]
        return material.spp if material.mask.any() else self.parts["other"].spp

    def step(self) -> np.ndarray:
        """One pass; the image (H, W, 3) float32.

        A part with no samples (after an edit, the material; after an IBL turn, both) is
        shaded first; then the material refines until it converges, then the rest.
        """
        empty = [name for name, part in self.parts.items() if part.spp == 0]
        waiting = [name for name, part in self.parts.items() if not part.converged]
        for name in empty or waiting[:1]:
            self._pass(name)
        return self.image()

    def _pass(self, name: str) -> None:
        part, n = self.parts[name], self.passes[name]
        layers = len(self.gbuffer.material)
        spp = FIRST_SPP if n == 0 else max(1, min(LATER_SPP, part.max_spp - part.spp))
        layer = n % layers
        # One sequence per part and position (relight._samples), continued pass by pass.
        seed = (self.seed << 24) ^ (layer << 1) ^ (name == "other")
        base = int(part.counts[layer].sum())
        shaded = self.relighter.shade(self.gbuffer, name, layer, seed, spp, base)
        if shaded is not None:
            pixels, rgb = shaded
            part.add(rgb, layer, spp, pixels)
        else:
            part.spp += spp  # nothing of this part at that position
        self.passes[name] = n + 1

    def image(self) -> np.ndarray:
        """The accumulated image (H, W, 3) float32: each part over the sub-pixel
        positions the material has reached (all of the other part's otherwise)."""
        material, other = self.parts["material"], self.parts["other"]
        layers = material.done() if material.done().size else other.done()
        width, height = self.size
        rgb = material.mean(layers) + other.mean(layers)
        return rgb.astype(np.float32).reshape(height, width, 3)


def mi_vector(size: tuple[int, int]) -> Any:
    import mitsuba as mi

    return mi.ScalarVector2u(*size)
