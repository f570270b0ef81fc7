"""Turntables: the element rotating through N frames, then the lighting through M frames.

Burley 2012 §6.1: "all turntables include both element and lighting rotations". The scene
is loaded once; every frame only updates scene parameters through ``mi.traverse`` (the
``to_world`` of the ball's and the cup's instances and of the envmap),
so Mitsuba reuses the kernels it compiled for the first frame (:doc:`/design`, Proofing).
Renders are also frozen (``dr.freeze``): after the first frames are recorded, a frame
replays the recorded kernel launches instead of tracing the integrator and our Python
BSDF plugins again, which is most of a small frame's fixed cost.

Each render is a pair of independent half-sample images side by side
(:meth:`Turntable.render_halves`): their mean is the frame and their difference estimates
its noise at no extra cost; :mod:`.passes` adds such pairs until a noise target is met.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Literal

import numpy as np

from . import shaderball
from .ibl import envmap_to_world
from .rig import DEFAULT_RIG

__all__ = ["Frame", "Turntable", "frames", "material_bsdf", "material_interior"]


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


def material_bsdf(hub: Any, *, force_all_lobes: bool = False) -> tuple[dict, int]:
    """The Mitsuba BSDF dict of a blended material (our plugins) and the path depth it needs."""
    from lookdev.pipeline.export.mitsuba import bsdf_dict, max_depth_for

    return bsdf_dict(hub, force_all_lobes=force_all_lobes), max_depth_for(hub)


def material_interior(hub: Any) -> dict[str, Any] | None:
    """The interior medium of a solid subsurface material at the proof's scale, or None."""
    from lookdev.pipeline.export.mitsuba.medium import interior_dict

    return interior_dict(hub, shaderball.METERS_PER_UNIT)


class Turntable:
    """A loaded shader-ball scene whose rotations are set per frame, never reloaded.

    ``rig`` places the calibrated rig beside the material (:mod:`.rig`); it stays put
    while the element turns and turns with the lighting.
    """

    def __init__(
        self,
        bsdf: dict[str, Any],
        environment: np.ndarray,
        resolution: tuple[int, int],
        max_depth: int,
        geometry: str | None = None,
        *,
        rig: str = DEFAULT_RIG,
        pixel_filter: str = "box",
        clamp: float | None = None,
        interior: dict[str, Any] | None = None,
    ):
        import mitsuba as mi

        scene = shaderball.scene_dict(
            bsdf,
            environment,
            resolution,
            max_depth,
            geometry,
            rig=rig,
            pixel_filter=pixel_filter,
            clamp=clamp,
            interior=interior,
        )
        scene["sensor_pair"] = _sensor_pair(scene["sensor"])
        self.scene = mi.load_dict(scene)
        self.width = int(resolution[0])
        # The plain camera renders single images; the pair renders a frame's two
        # independent half-sample images in one launch (see render_halves).
        widths = [s.film().size()[0] for s in self.scene.sensors()]
        self.pair_index = widths.index(2 * self.width)
        self.camera_index = widths.index(self.width)
        self.params = mi.traverse(self.scene)
        self.environment_shape = tuple(np.shape(environment))
        self._pose = (0.0, 0.0)  # (element, light) angles the scene is posed at
        self._launch = _frozen(_render_call)

    def set_frame(self, frame: Frame) -> None:
        """Pose the element and the lighting for ``frame``, pushing only what changed.

        Turning the element re-commits the scene's top-level acceleration structure, so a
        lighting frame after the first touches the envmap's ``to_world`` alone.
        """
        element = frame.angle if frame.kind == "element" else 0.0
        light = frame.angle if frame.kind == "light" else 0.0
        if element != self._pose[0]:
            self.params["ball.to_world"] = shaderball.ball_to_world(element)
            self.params["cup.to_world"] = shaderball.cup_to_world(element)
        if light != self._pose[1]:
            self.params["environment.to_world"] = envmap_to_world(light)
        self._pose = (element, light)
        self.params.update()

    def set_environment(self, environment: np.ndarray) -> None:
        """Light the loaded scene with another lat-long ``environment`` of the same shape.

        The envmap's pixels are replaced through ``mi.traverse`` by those a fresh load of
        ``environment`` holds (Mitsuba's ``envmap`` rebuilds its sampling distribution from
        them), so the frames equal a scene loaded with it, bit for bit, and the scene's
        plugins and compiled kernels are kept.
        """
        import mitsuba as mi

        shape = tuple(np.shape(environment))
        if shape != self.environment_shape:
            raise ValueError(f"an environment of shape {shape}, not {self.environment_shape}")
        fresh = mi.load_dict(shaderball.envmap(environment))
        self.params["environment.data"] = mi.traverse(fresh)["data"]
        self.params.update()

    @property
    def recordings(self) -> int:
        """How many times the frozen launch was traced and recorded (0 when not frozen)."""
        return getattr(self._launch, "n_recordings", 0)

    def render(self, spp: int, seed: int) -> np.ndarray:
        """One image (H, W, 3) float32 at the current pose."""
        return self._image(self.camera_index, spp, seed)

    def render_halves(self, spp: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
        """Two independent images of ``spp`` samples each at the current pose, rendered
        side by side by one ``mi.render`` call (a second call cost ~10 % per frame)."""
        pair = self._image(self.pair_index, spp, seed)
        return pair[:, : self.width], pair[:, self.width :]

    def _image(self, sensor: int, spp: int, seed: int) -> np.ndarray:
        import mitsuba as mi

        # The seed goes in as a JIT value: a Python int would be part of the recording's
        # key and every frame (each its own seed) would record anew.
        image = self._launch(self.scene, sensor, spp, mi.UInt32(seed))
        return np.array(image, dtype=np.float32)[..., :3]


def _render_call(scene: Any, sensor: int, spp: int, seed: Any) -> Any:
    import mitsuba as mi

    return mi.render(scene, sensor=sensor, spp=spp, seed=seed)


def _frozen(fn: Any) -> Any:
    """``fn`` frozen with ``dr.freeze`` on a JIT variant; as it is on a scalar one."""
    import drjit as dr
    import mitsuba as mi

    return dr.freeze(fn) if dr.is_jit_v(mi.Float) else fn


def _sensor_pair(camera: dict[str, Any]) -> dict[str, Any]:
    """Mitsuba's ``batch`` sensor holding the same camera twice over a double-width film.

    Each half gets its own samples, so the halves are independent renders of the frame;
    checked: no filter bleed between them at the shared edge.
    """
    view = {k: v for k, v in camera.items() if k not in ("film", "sampler")}
    film = {**camera["film"], "width": 2 * camera["film"]["width"]}
    return {"type": "batch", "a": view, "b": dict(view), "film": film, "sampler": camera["sampler"]}
