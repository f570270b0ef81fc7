"""Turntables: the element rotating through N frames, then the lighting through M frames.

Burley 2012 §6.1: "all turntables include both element and lighting rotations". The scene
is loaded once; every frame only updates scene parameters through ``mi.traverse`` (the
``to_world`` of the ball's and the cup's instances and of the envmap),
so Mitsuba reuses the kernels it compiled for the first frame (DESIGN.md, Proofing).

Each frame is rendered as two independent half-sample images: their mean is the frame
and their difference estimates its noise (the variance of a mean of two independent
estimates is a quarter of their squared difference), at no extra cost.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np

from . import shaderball

REC709_Y = np.array([0.2126, 0.7152, 0.0722])


@dataclass(frozen=True)
class Frame:
    """One frame of a turntable: which rotation, and its angle in degrees."""

    index: int
    kind: Literal["element", "light"]
    angle: float

    @property
    def label(self) -> str:
        return f"{self.kind} {self.angle:.0f}°"


def frames(element: int, light: int) -> list[Frame]:
    """``element`` frames of one element turn, then ``light`` frames of one lighting turn.

    >>> [f.label for f in frames(2, 2)]
    ['element 0°', 'element 180°', 'light 0°', 'light 180°']
    """
    out = [Frame(i, "element", 360.0 * i / element) for i in range(element)]
    return out + [Frame(element + i, "light", 360.0 * i / light) for i in range(light)]


def material_bsdf(material: Any, *, force_all_lobes: bool = False) -> tuple[dict, int]:
    """The Mitsuba BSDF dict of a material (our plugins) and the path depth it needs.

    A layered material is blended once (:func:`~lookdev.pipeline.export.mitsuba.scene.flatten`)
    and both answers come from that.
    """
    from lookdev.pipeline.export.mitsuba import bsdf_dict, max_depth_for
    from lookdev.pipeline.export.mitsuba.scene import flatten

    flat = flatten(material)
    return bsdf_dict(flat, force_all_lobes=force_all_lobes), max_depth_for(flat)


class Turntable:
    """A loaded shader-ball scene whose rotations are set per frame, never reloaded."""

    def __init__(
        self,
        bsdf: dict[str, Any],
        environment: np.ndarray,
        resolution: tuple[int, int],
        max_depth: int,
    ):
        import mitsuba as mi

        self.scene = mi.load_dict(shaderball.scene_dict(bsdf, environment, resolution, max_depth))
        self.params = mi.traverse(self.scene)
        self._pose = (0.0, 0.0)  # (element, light) angles the scene is posed at

    def set_frame(self, frame: Frame) -> None:
        """Pose the element and the lighting for ``frame``, pushing only what changed.

        Turning the element re-commits the scene's top-level acceleration structure, so a
        lighting frame after the first touches the envmap's ``to_world`` alone.
        """
        import mitsuba as mi

        element = frame.angle if frame.kind == "element" else 0.0
        light = frame.angle if frame.kind == "light" else 0.0
        if element != self._pose[0]:
            self.params["ball.to_world"] = shaderball.ball_to_world(element)
            self.params["cup.to_world"] = shaderball.cup_to_world(element)
        if light != self._pose[1]:
            self.params["environment.to_world"] = mi.ScalarTransform4f().rotate([0, 1, 0], light)
        self._pose = (element, light)
        self.params.update()

    def render(self, spp: int, seed: int) -> np.ndarray:
        """One image (H, W, 3) float32 at the current pose."""
        import mitsuba as mi

        return np.array(mi.render(self.scene, spp=spp, seed=seed), dtype=np.float32)[..., :3]


@dataclass(frozen=True)
class RenderedFrame:
    """A frame's image and what the manifest records about it."""

    frame: Frame
    image: np.ndarray
    seconds: float
    noise_rmse: float
    noise_relative: float | None  # None for a black frame


def render_frame(table: Turntable, frame: Frame, spp: int, seed: int = 0) -> RenderedFrame:
    """Render ``frame`` as two half-sample images; their mean and a noise estimate.

    ``noise_rmse`` is the estimated RMS error of the mean image, √(mean((A − B)²)/4),
    taken on luminance; ``noise_relative`` divides it by the mean luminance (None when
    the frame is black: JSON has no infinity). An odd ``spp`` is rounded down to even.
    Seeds 2·seed and 2·seed + 1 keep every frame's samples distinct and reruns equal.
    """
    half = max(1, spp // 2)
    t0 = time.perf_counter()
    table.set_frame(frame)
    a = table.render(half, seed=2 * seed)
    b = table.render(half, seed=2 * seed + 1)
    seconds = time.perf_counter() - t0
    image = 0.5 * (a + b)
    diff = (a - b) @ REC709_Y
    rmse = math.sqrt(float(np.mean(diff.astype(np.float64) ** 2)) / 4.0)
    mean = float(np.mean(image @ REC709_Y))
    return RenderedFrame(frame, image, seconds, rmse, rmse / mean if mean > 0 else None)
