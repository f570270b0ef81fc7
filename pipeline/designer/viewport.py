"""The Material Designer's viewport: one material in the proof scene, in two modes.

``designer`` (:cite:`Burley2012` §6.1) relights a g-buffer of the scene with the model's own
Dr.Jit evaluation and sampling against the IBL (:mod:`.designer_mode`, :mod:`.relight`):
fast, direct lighting only. ``truth`` path traces the proofs' scene with the proofs'
plugin, edited in place (:mod:`.truth`). Both refine progressively while nothing
changes and show their pixels through the proofs' OCIO view
(:func:`lookdev.pipeline.proof.tonemap.view`), after the viewport's exposure. The view
is applied again only to the pixels whose value changed since the last frame shown
(:class:`DisplayCache`): an edit or a refinement of the material leaves the ground, the
rig and the background as they were, and the view is per pixel, so the image is the same
as a full transform at a fraction of its cost (ACES 2.0's view was two thirds of an edit).

.. code-block:: python

    view = Viewport(lookdev.blend("gold"), width=480, height=270)
    frame = view.step()              # frame.display: (270, 480, 3) uint8
    view.update_material(lookdev.blend("plastic_glossy"))
    view.rotate_ibl(90.0)
    while not frame.converged:
        frame = view.step()

The viewport is not thread-safe: one render thread drives it.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from lookdev.materials.errors import LookdevError, check_range

__all__ = ["MODES", "DesignerError", "DisplayCache", "Frame", "Viewport"]

MODES = ("designer", "truth")
IBL_WIDTH = 512
"""Every IBL is brought to this width (× ½ high): one envmap size, one set of kernels."""
MIN_SIDE, MAX_SIDE = 8, 4096


class DesignerError(LookdevError):
    """The designer's viewport cannot do what was asked (mode, size, IBL, geometry)."""


@dataclass
class Frame:
    """One refinement of the viewport's image."""

    rgb: np.ndarray
    """(H, W, 3) float32, scene-linear working space, accumulated (denoised if so)."""
    display: np.ndarray
    """(H, W, 3) uint8 through lookdev's OCIO view (the proofs'), after the exposure."""
    spp: int
    """Samples per pixel accumulated so far."""
    mode: str
    denoised: bool
    converged: bool
    """Refinement has reached its stopping rule; :meth:`Viewport.step` is then cheap."""
    exposure: float = 0.0
    """The stops :attr:`display` was made at."""


class Viewport:
    """A live view of one blended material in the proof scene (module docstring).

    Parameters
    ----------
    material
        The blended material (what :func:`lookdev.blend` returns) or a model's parameters.
    mode
        ``"designer"`` or ``"truth"``.
    ibl
        A built-in IBL name or an ``.exr``/``.hdr`` path.
    geometry
        None for the proof scene's cup; else a mesh file (PLY, OBJ, USD) in its place,
        as ``lookdev proof --geometry`` takes.
    width, height
        The image size in pixels.
    seed
        Seeds every pass (a pass's seed also follows its index).
    shadows
        Designer mode traces a shadow ray per light sample (see :mod:`.relight`).
    rig
        The calibrated rig beside the material (``full``, ``balls``, ``none``).
    """

    def __init__(
        self,
        material: Any,
        *,
        mode: str = "designer",
        ibl: Any = "studio",
        geometry: Any = None,
        width: int = 480,
        height: int = 270,
        seed: int = 0,
        shadows: bool = True,
        rig: str = "full",
        noise_target: float | None = None,
        max_spp: int | None = None,
    ):
        from lookdev.pipeline.blend.result import as_hub
        from lookdev.pipeline.variant import use_mitsuba

        from .progressive import MAX_SPP, NOISE_TARGET

        use_mitsuba()
        self._check_mode(mode)
        self._check_size(width, height)
        self.hub = as_hub(material)
        self.mode = mode
        self.size = (int(width), int(height))
        self.seed, self.shadows, self.rig = int(seed), bool(shadows), rig
        self.noise_target = NOISE_TARGET if noise_target is None else float(noise_target)
        self.max_spp = MAX_SPP if max_spp is None else int(max_spp)
        self.geometry = None
        if geometry is not None:
            from lookdev.pipeline.proof.geometry import proof_mesh

            self.geometry = str(proof_mesh(geometry))
        self.exposure = 0.0
        self.ibl_angle = 0.0
        self.element_angle = 0.0
        self._environment = self._load_ibl(ibl)
        self.ibl = ibl
        self._engines: dict[str, Any] = {}
        self._seen: dict[str, dict[str, Any]] = {}
        self._last: Frame | None = None
        self._raw: Frame | None = None
        self._display = DisplayCache()

    # -- checks -----------------------------------------------------------------------------
    @staticmethod
    def _check_mode(mode: str) -> None:
        if mode not in MODES:
            raise DesignerError(f"unknown mode {mode!r}; use {' or '.join(MODES)}", field="mode")

    @staticmethod
    def _check_size(width: int, height: int) -> None:
        for name, side in (("width", width), ("height", height)):
            check_range(side, MIN_SIDE, MAX_SIDE, field=name, error=DesignerError)

    @staticmethod
    def _load_ibl(ibl: Any) -> np.ndarray:
        from lookdev.pipeline.proof import ibl as ibl_module

        try:
            return ibl_module.load(ibl, IBL_WIDTH).pixels
        except ibl_module.IblError as exc:
            raise DesignerError(exc.message, where=exc.where, field="ibl") from None

    # -- the engines, each brought up to date when it is used ---------------------------------
    def _state(self) -> dict[str, Any]:
        return {
            "hub": self.hub,
            "environment": id(self._environment),
            "ibl": self.ibl_angle,
            "element": self.element_angle,
            "size": self.size,
        }

    def _engine(self) -> Any:
        engine = self._engines.get(self.mode)
        if engine is None:
            engine = self._new_engine()
            self._engines[self.mode] = engine
            self._seen[self.mode] = self._state()
            self._pose(engine, {"ibl": 0.0, "element": 0.0})
            return engine
        seen, now = self._seen[self.mode], self._state()
        if seen["size"] != now["size"]:
            engine.resize(*now["size"])
        if seen["environment"] != now["environment"]:
            engine.set_environment(self._environment)
        self._pose(engine, seen)
        if seen["hub"] is not now["hub"]:
            engine.set_material(self.hub)
        self._seen[self.mode] = now
        return engine

    def _pose(self, engine: Any, seen: dict[str, Any]) -> None:
        if seen["element"] != self.element_angle:
            engine.rotate_element(self.element_angle)
        if seen["ibl"] != self.ibl_angle:
            engine.rotate_ibl(self.ibl_angle)

    def _new_engine(self) -> Any:
        common = {
            "rig": self.rig,
            "seed": self.seed,
            "noise_target": self.noise_target,
            "max_spp": self.max_spp,
        }
        if self.mode == "designer":
            from .designer_mode import DesignerMode

            return DesignerMode(
                self.hub,
                self._environment,
                self.size,
                self.geometry,
                shadows=self.shadows,
                **common,
            )
        from .truth import TruthMode

        return TruthMode(self.hub, self._environment, self.size, self.geometry, **common)

    # -- the interface ---------------------------------------------------------------------
    def update_material(self, material: Any) -> None:
        """Show a new blended material; accumulation restarts (truth mode: a traverse
        update, no recompile, unless a switch changed the kernels' structure)."""
        from lookdev.pipeline.blend.result import as_hub

        self.hub = as_hub(material)
        self._last = None

    def set_mode(self, mode: str) -> None:
        self._check_mode(mode)
        self.mode = mode
        self._last = None

    def set_ibl(self, ibl: Any) -> None:
        """A built-in IBL name or an ``.exr``/``.hdr`` path (brought to one size)."""
        self._environment = self._load_ibl(ibl)
        self.ibl = ibl
        self._last = None

    def rotate_ibl(self, degrees: float) -> None:
        """The lighting's absolute azimuth in degrees (the proofs' convention)."""
        self.ibl_angle = _angle(degrees, "ibl rotation")
        self._last = None

    def rotate_element(self, degrees: float) -> None:
        """The element's (ball and cup) absolute turn about +y, in degrees."""
        self.element_angle = _angle(degrees, "element rotation")
        self._last = None

    def set_exposure(self, stops: float) -> None:
        """Display only: the next frame shows the same pixels brighter or darker."""
        from lookdev.pipeline.proof.tonemap import EXPOSURE_MAX

        check_range(stops, -EXPOSURE_MAX, EXPOSURE_MAX, field="exposure", error=DesignerError)
        self.exposure = float(stops)

    def resize(self, width: int, height: int) -> None:
        self._check_size(width, height)
        self.size = (int(width), int(height))
        self._last = None

    def step(self) -> Frame:
        """One progressive refinement pass (cheap once converged); in truth mode the
        denoised image once it has been still for a moment (:meth:`raw` has the other)."""
        engine = self._engine()
        if self._last is None or not engine.converged or self._last.mode != self.mode:
            self._raw = self._frame(engine.step(), engine, denoised=False)
            self._last = self._raw
        if not self._last.denoised and hasattr(engine, "denoised_image"):
            denoised = engine.denoised_image()
            if denoised is not None:
                self._last = self._frame(denoised, engine, denoised=True)
        return self._shown(self._last)

    def raw(self) -> Frame:
        """The last frame without denoising (a step first if there is none)."""
        if self._raw is None:
            self.step()
        return self._shown(self._raw)

    def close(self) -> None:
        """Drop the scenes and their kernels' inputs."""
        self._engines.clear()
        self._seen.clear()
        self._last = self._raw = None
        self._display = DisplayCache()

    # -- frames ------------------------------------------------------------------------------
    def _frame(self, rgb: np.ndarray, engine: Any, *, denoised: bool) -> Frame:
        display = self._display(rgb, self.exposure)
        converged = engine.converged
        return Frame(rgb, display, engine.spp, self.mode, denoised, converged, self.exposure)

    def _shown(self, frame: Frame) -> Frame:
        """``frame`` with its display at the current exposure (redone only if it changed)."""
        if frame.exposure != self.exposure:
            frame.display = self._display(frame.rgb, self.exposure)
            frame.exposure = self.exposure
        return frame


def _display(rgb: np.ndarray, exposure: float) -> np.ndarray:
    """The proofs' view transform of scene-linear ``rgb``, as 8-bit display values."""
    from lookdev.pipeline.proof import tonemap

    return tonemap.to_8bit(tonemap.view(rgb, exposure))


class DisplayCache:
    """:func:`_display` of successive images, transforming only the pixels that changed.

    The OCIO view maps each pixel on its own, so the pixels equal to the last image's
    at the same exposure keep their display values; the rest are transformed. The
    arrays it returns are new ones (a frame already sent is never written to).
    """

    def __init__(self) -> None:
        self._rgb: np.ndarray | None = None
        self._out: np.ndarray | None = None
        self._exposure = 0.0

    def __call__(self, rgb: np.ndarray, exposure: float) -> np.ndarray:
        last = self._rgb
        if last is None or last.shape != rgb.shape or self._exposure != exposure:
            out = _display(rgb, exposure)
        else:
            changed = np.any(rgb != last, axis=-1)
            out = self._out.copy()
            if changed.any():
                out[changed] = _display(rgb[changed], exposure)
        self._rgb, self._out, self._exposure = rgb.copy(), out, exposure
        return out


def _angle(degrees: float, field: str) -> float:
    import math

    value = float(degrees)
    if not math.isfinite(value):
        raise DesignerError(f"{degrees!r} is not a finite angle", field=field)
    return value % 360.0
