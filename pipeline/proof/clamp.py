"""``--clamp``: a path tracer whose camera samples are limited to a radiance, for previews.

Clamping hides fireflies by biasing the image darker where light is concentrated (sun
caustics, small hot highlights), so proofs render unclamped unless asked (the
manifest reports each frame's ``firefly_share`` instead). Mitsuba 3's ``path``
integrator has no clamp, so this wraps it: a sample's radiance L is scaled by
``min(1, clamp / max(L))``, which keeps its hue. It is registered as a Mitsuba plugin and
traced like any integrator, so frozen renders replay it.
"""

from __future__ import annotations

import functools
from typing import Any

__all__ = ["PLUGIN", "integrator", "register"]

PLUGIN = "lookdev_clamped_path"


def integrator(
    max_depth: int, clamp: float | None, interior: dict[str, Any] | None = None
) -> dict[str, Any]:
    """The scene's integrator dict: Mitsuba's ``path`` (``volpath`` for a scene with an
    ``interior`` medium, :mod:`lookdev.pipeline.export.mitsuba.medium`), or it clamped."""
    from lookdev.pipeline.export.mitsuba.medium import integrator as plain

    inner = plain(max_depth, interior)
    if clamp is None:
        return inner
    register()
    out = {"type": PLUGIN, "max_depth": int(max_depth), "clamp": float(clamp)}
    return out if inner["type"] == "path" else out | {"inner": inner["type"]}


def register() -> None:
    """Register :data:`PLUGIN` for the current variant (once per variant)."""
    import mitsuba as mi

    _register(mi.variant())


@functools.cache
def _register(variant: str) -> None:
    import drjit as dr
    import mitsuba as mi

    class ClampedPath(mi.SamplingIntegrator):
        """Mitsuba's ``path`` with each sample's radiance limited to ``clamp``."""

        def __init__(self, props: mi.Properties):
            super().__init__(props)
            self.clamp = float(props.get("clamp"))
            depth = int(props.get("max_depth", 8))
            kind = str(props.get("inner", "path"))
            self.inner = mi.load_dict({"type": kind, "max_depth": depth})

        def sample(self, scene, sampler, ray, medium=None, active=True):  # noqa: ANN001
            radiance, valid, aovs = self.inner.sample(scene, sampler, ray, medium, active)
            peak = dr.max(radiance)
            scale = dr.select(peak > self.clamp, self.clamp / peak, 1.0)
            return radiance * scale, valid, aovs

        def aov_names(self) -> list[str]:
            return []

        def to_string(self) -> str:
            return f"ClampedPath[clamp={self.clamp}]"

    mi.register_integrator(PLUGIN, lambda props: ClampedPath(props))
