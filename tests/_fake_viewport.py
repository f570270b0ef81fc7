"""TEMPORARY stand-in for the render helper's Viewport until it lands (then removed)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass
class Frame:
    rgb: np.ndarray
    display: np.ndarray
    spp: int
    mode: str
    denoised: bool
    converged: bool


class Viewport:
    def __init__(
        self,
        material,
        *,
        mode="designer",
        ibl="studio",
        geometry=None,
        width=480,
        height=270,
        seed=0,
    ):
        self.material, self.mode, self.w, self.h = material, mode, width, height
        self.azimuth = 0.0
        self.exposure = 0.0
        self.spp = 0

    def update_material(self, material):
        self.material, self.spp = material, 0

    def set_mode(self, mode):
        self.mode, self.spp = mode, 0

    def set_ibl(self, ibl):
        self.spp = 0

    def rotate_ibl(self, degrees):
        self.azimuth, self.spp = degrees, 0

    def rotate_element(self, degrees):
        self.spp = 0

    def set_exposure(self, stops):
        self.exposure = stops

    def resize(self, width, height):
        self.w, self.h, self.spp = width, height, 0

    def step(self):
        from lookdev.pipeline.designer.library_panel import _render

        img = _render(self.material)
        shift = int(self.azimuth) % img.shape[1]
        img = np.roll(img, shift, axis=1)
        out = np.zeros((self.h, self.w, 3), np.uint8)
        s = min(self.h, self.w, img.shape[0])
        out[:s, :s] = img[:s, :s]
        out = np.clip(out.astype(np.float32) * 2.0**self.exposure, 0, 255).astype(np.uint8)
        self.spp += 1
        self.last = Frame(
            out.astype(np.float32) / 255, out, self.spp, self.mode, False, self.spp >= 2
        )
        return self.last

    def raw(self):
        return self.last

    def close(self):
        pass
