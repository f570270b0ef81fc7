"""Designer-mode shading: the g-buffer relit by the environment with the model's own maths.

Each pass shades every pixel of the g-buffer (:mod:`.gbuffer`) once per sample with two
strategies combined by the power heuristic (:cite:`Veach1997` §9.2): a direction drawn from the
environment by Mitsuba's importance sampling of the ``envmap`` (the scene's own emitter,
so rotating its ``to_world`` rotates the lighting and nothing else), and a direction drawn
by the model's ``sample``. The material's pixels are shaded by the model's core functions
(``prepare``, ``eval``, ``pdf``, ``sample``) on the Dr.Jit backend of the array shim, the
very code the Mitsuba plugin and the numpy plots run; there is no other copy of any
formula. Every continuous parameter enters as an opaque Dr.Jit value
(:func:`lookdev.pipeline.export.mitsuba.inputs.opaque_inputs`), or as a per-pixel array
read from the blended maps at the g-buffer's UVs, so every lobe a control can switch on
is traced and an edit changes data, not the kernel.

The pass is frozen (``dr.freeze``): after its first recording an update replays the
recorded kernel launches instead of tracing the model in Python again. A recording
depends on what ``prepare`` decided in Python (the switches ``thin``, ``sheen_model``,
``specular_gamma``, ``energy_compensation``, a scatter distance's medium, which fields
are maps): :func:`structure_key` spells that out, and a new key records anew.

What designer mode leaves out, against truth mode (the path tracer, :mod:`.truth`):

* inter-reflection: light reaches a point only from the environment, so the cup's inside
  misses the light its walls bounce and the ground's bounce light is absent;
* occlusion is optional (``shadows``): with it, a shadow ray per sample blocks
  environment light the scene occludes (the ball's contact shadow, the cup's inside);
  without it every direction above the surface sees the environment;
* transmission sees the environment straight along the direction the surface refracts
  into (no second interface, no medium): glass and ``diff_trans`` are indicative only;
  a subsurface medium (``scatter_distance``) shows its surface lobes alone;
* normal, bump and specular-normal maps are not applied (the mesh's shading normals);
  parameter maps are read at the nearest texel (the proofs' bitmaps filter bilinearly);
* the rig and the ground are shaded by what their own BSDFs gave the g-buffer: their
  diffuse reflectance, and the chrome ball's mirror direction and Fresnel weight.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any

import numpy as np

from lookdev.materials.arrays import DrJitOps
from lookdev.materials.bsdf import Prepared
from lookdev.materials.tables import device_tables

from .gbuffer import GBuffer, Hits

__all__ = ["Relighter", "kronecker", "material_values", "structure_key"]

INV_PI = 1.0 / math.pi


def material_values(hub: Any, hits: Hits) -> tuple[Any, dict[str, Any], tuple[str, ...]]:
    """(params, values, mapped) for shading ``hits`` with ``hub``'s model.

    ``params``: the model's parameters (switches and defaults, as the plugin parses
    them); ``values``: every continuous field as an opaque Dr.Jit scalar, and each mapped
    field as a Dr.Jit array over the hits (the map's nearest texel at the hit's UV);
    ``mapped``: the names of the latter, sorted.
    """
    import mitsuba as mi

    from lookdev.materials.registry import is_color_field
    from lookdev.pipeline.export.mitsuba.inputs import opaque_inputs
    from lookdev.pipeline.export.mitsuba.scene import plugin_inputs

    model = hub.bsdf_model
    constants, maps = plugin_inputs(hub)
    params = model.params_type.parse(constants, where=hub.name)
    values = opaque_inputs(model, params, skip=maps)
    if maps and hits.count:
        rows, cols = hub.texel(hits.uv)
    for key, array in maps.items():
        if not hits.count:
            continue
        texels = np.ascontiguousarray(array[rows, cols], dtype=np.float32)
        pad = np.repeat(texels[-1:], hits.width - hits.count, axis=0)
        texels = np.concatenate([texels, pad]) if len(pad) else texels
        if is_color_field(model.params_type, key):
            values[key] = mi.Vector3f(
                *(mi.Float(np.ascontiguousarray(texels[:, c])) for c in range(3))
            )
        else:
            values[key] = mi.Float(texels)
    return params, values, tuple(sorted(maps))


def structure_key(model: Any, params: Any, values: dict[str, Any]) -> str:
    """What a traced pass depends on beyond its Dr.Jit inputs: every value ``prepare``
    computed in Python (switches, lobe and delta lists, constants), by name."""
    import drjit as dr

    xp = DrJitOps.for_mitsuba()
    prepared = model.prepare(xp, params, **values)

    def plain(value: Any) -> Any:
        if isinstance(value, Prepared):  # by member, as a dict: Dr.Jit values by type
            return {f.name: plain(getattr(value, f.name)) for f in dataclasses.fields(value)}
        if isinstance(value, dict):
            return {k: plain(v) for k, v in sorted(value.items())}
        if isinstance(value, list | tuple):
            return [plain(v) for v in value]
        if dr.is_array_v(value):
            return type(value).__name__
        return repr(value)

    return f"{model.name}:{plain(prepared)}"


def _gathered(arrays: dict[str, Any], index: Any, width: int) -> dict[str, Any]:
    """Each array (one value per hit) repeated for ``spp`` samples: gathered at ``index``."""
    import drjit as dr

    out = {}
    for key, value in arrays.items():
        out[key] = dr.gather(type(value), value, index) if dr.width(value) == width else value
    return out


def kronecker(dims: int) -> tuple[int, ...]:
    """The additive recurrence of :cite:`Roberts2018` in ``dims`` dimensions: frac(1/φᵏ),
    k = 1..dims, with φ the positive root of x^(dims+1) = x + 1, as 32-bit fractions.

    >>> [round(a / 2**32, 6) for a in kronecker(1)]  # the golden ratio's sequence
    [0.618034]
    """
    phi = 2.0
    for _ in range(64):  # Newton's method converges from 2 in a few steps
        phi -= (phi ** (dims + 1) - phi - 1.0) / ((dims + 1) * phi**dims - 1.0)
    return tuple(int((phi**-k % 1.0) * 2**32) for k in range(1, dims + 1))


def _samples(seed: Any, base: Any, n: int, spp: int, dims: int) -> list[Any]:
    """``dims`` uniform numbers for each of the ``spp`` samples of ``n`` pixels.

    Sample ``base + s`` of a pixel is that point of the Kronecker sequence
    (:func:`kronecker`), shifted modulo 1 by an offset random per pixel and fixed for the
    accumulation (:cite:`Cranley1976`): each pixel's samples over the passes are one
    low-discrepancy set, so its error falls faster than independent samples' while the
    estimate stays unbiased (the shift is uniform). Integer arithmetic modulo 2³² keeps
    every index exact.
    """
    import drjit as dr
    import mitsuba as mi

    i = dr.arange(mi.UInt32, n * spp)
    index = base + i % spp
    # ``seed`` and not the constructor: it would add each lane's index to the state.
    rng = mi.PCG32()
    rng.seed(mi.UInt64(seed) * 0x9E3779B97F4A7C15, mi.UInt64(i // spp))
    out = []
    for alpha in kronecker(dims):
        bits = rng.next_uint32() + index * alpha  # wraps modulo 2^32: frac(shift + k·α)
        out.append(mi.Float(bits >> 8) * (1.0 / (1 << 24)))
    return out


def _env(emitter: Any, d: Any) -> Any:
    """The environment's radiance arriving from direction ``d`` (world space)."""
    import drjit as dr
    import mitsuba as mi

    si = dr.zeros(mi.SurfaceInteraction3f)
    si.wi = -d
    return emitter.eval(si)


def _env_pdf(emitter: Any, it: Any, d: Any) -> Any:
    import drjit as dr
    import mitsuba as mi

    ds = dr.zeros(mi.DirectionSample3f)
    ds.d = d
    return emitter.pdf_direction(it, ds)


def _power(a: Any, b: Any) -> Any:
    """The power heuristic's weight of strategy a against b (pdfs)."""
    import drjit as dr

    a2, b2 = a * a, b * b
    return dr.select(a2 > 0, a2 / (a2 + b2), 0.0)


def _visible(scene: Any, it: Any, d: Any, shadows: bool, active: Any) -> Any:

    if not shadows:
        return active
    return active & ~scene.ray_test(it.spawn_ray(d), active)


def _material_pass(model: Any, params: Any, shadows: bool) -> Any:
    """The material's pass for one structure (see the module docstring), to be frozen."""
    xp = DrJitOps.for_mitsuba()

    def shade(scene, emitter, g: dict, values: dict, seed, base, spp: int, n: int, tables):
        import drjit as dr
        import mitsuba as mi

        index = dr.arange(mi.UInt32, n * spp) // spp
        g = _gathered(g, index, n)
        values = _gathered(values, index, n)
        u = _samples(seed, base, n, spp, 5)
        frame = mi.Frame3f(g["s"], dr.cross(g["n"], g["s"]), g["n"])
        wo = frame.to_local(g["wo"])
        it = dr.zeros(mi.Interaction3f, n * spp)
        it.p, it.n = g["p"], g["n"]
        pr = model.prepare(xp, params, **values)
        # The environment's strategy.
        ds, radiance = emitter.sample_direction(it, mi.Point2f(u[0], u[1]))
        wi = frame.to_local(ds.d)
        f = mi.Vector3f(model.eval(xp, pr, wi, wo))
        p_bsdf = mi.Float(model.pdf(xp, pr, wi, wo))
        light = f * dr.abs(wi.z) * _power(ds.pdf, p_bsdf) * mi.Vector3f(radiance)
        # The model's strategy.
        wi2, value, pdf2, delta = model.sample(xp, pr, wo, mi.Vector3f(u[2], u[3], u[4]))
        wi2 = mi.Vector3f(wi2)
        d2 = frame.to_world(wi2)
        mis = dr.select(mi.Bool(delta), 1.0, _power(mi.Float(pdf2), _env_pdf(emitter, it, d2)))
        reflected = mi.Vector3f(value) * mi.Vector3f(_env(emitter, d2)) * mis
        ok1, ok2 = ds.pdf > 0, mi.Float(pdf2) > 0
        # Both strategies' values in one kernel before the shadow rays (a ray test splits
        # the kernel, and anything left unevaluated would be computed again after it).
        dr.schedule(light, reflected, ds.d, d2, wi.z, wi2.z, ok1, ok2)
        # Transmission sees the environment straight through (no shadow ray).
        seen1 = _visible(scene, it, ds.d, shadows, ok1 & (wi.z > 0)) | (ok1 & (wi.z <= 0))
        seen2 = _visible(scene, it, d2, shadows, ok2 & (wi2.z > 0)) | (ok2 & (wi2.z <= 0))
        total = dr.select(seen1, light, 0.0) + dr.select(seen2, reflected, 0.0)
        out = dr.block_sum(total, spp) / spp if spp > 1 else total
        return out

    return shade


def _other_pass(shadows: bool) -> Any:
    """The pass of everything but the material: diffuse objects, mirrors, background."""

    def shade(scene, emitter, g: dict, seed, base, spp: int, n: int, tables) -> Any:
        import drjit as dr
        import mitsuba as mi

        index = dr.arange(mi.UInt32, n * spp) // spp
        g = _gathered(g, index, n)
        u = _samples(seed, base, n, spp, 4)
        hit = g["hit"]
        it = dr.zeros(mi.Interaction3f, n * spp)
        it.p, it.n = g["p"], g["n"]
        frame = mi.Frame3f(g["n"])
        albedo = mi.Vector3f(g["albedo"])
        diffuse = hit & (dr.max(albedo) > 0)
        # Lambertian reflection of the environment, as the objects' own BSDFs gave it.
        ds, radiance = emitter.sample_direction(it, mi.Point2f(u[0], u[1]), diffuse)
        cos = dr.dot(ds.d, g["n"])
        ok1 = diffuse & (cos > 0) & (ds.pdf > 0)
        light = albedo * INV_PI * cos * _power(ds.pdf, cos * INV_PI) * mi.Vector3f(radiance)
        local = mi.warp.square_to_cosine_hemisphere(mi.Point2f(u[2], u[3]))
        d = frame.to_world(local)
        ok2 = diffuse & (local.z > 0)
        reflected = albedo * _power(local.z * INV_PI, _env_pdf(emitter, it, d))
        reflected *= mi.Vector3f(_env(emitter, d))
        dr.schedule(light, reflected, ds.d, d, ok1, ok2)  # before the rays (see above)
        total = dr.select(_visible(scene, it, ds.d, shadows, ok1), light, 0.0)
        total += dr.select(_visible(scene, it, d, shadows, ok2), reflected, 0.0)
        # Mirrors (the chrome ball) see the environment along their reflected direction.
        total += mi.Vector3f(g["mirror_w"]) * mi.Vector3f(_env(emitter, g["mirror_d"]))
        total = dr.select(hit, total, mi.Vector3f(_env(emitter, -g["view"])))
        out = dr.block_sum(total, spp) / spp if spp > 1 else total
        return out

    return shade


class Relighter:
    """Shades a g-buffer pass by pass (see the module docstring). Not thread-safe."""

    def __init__(self, scene: Any, *, shadows: bool = True, freeze: bool = True):
        import drjit as dr
        import mitsuba as mi

        self.scene = scene
        self.emitter = scene.environment()
        self.shadows = shadows
        self._freeze = freeze and dr.is_jit_v(mi.Float)
        self._material_passes: dict[str, Any] = {}
        self._other = self._frozen(_other_pass(shadows))
        self.values: list[dict[str, Any]] = []
        self.key = ""
        self.model = None
        self.params = None

    def _unfrozen(self, part: str) -> Any:
        if part == "material":
            return _material_pass(self.model, self.params, self.shadows)
        return _other_pass(self.shadows)

    def _frozen(self, fn: Any) -> Any:
        import drjit as dr

        return dr.freeze(fn) if self._freeze else fn

    @property
    def recordings(self) -> int:
        """How many times the frozen passes were traced and recorded, in all."""
        passes = [self._other, *self._material_passes.values()]
        return sum(getattr(p, "n_recordings", 0) for p in passes)

    def set_material(self, hub: Any, gbuffer: GBuffer) -> None:
        """Shade ``hub`` from now on: its values per sub-pixel position of ``gbuffer``."""
        per_layer = [material_values(hub, hits) for hits in gbuffer.material]
        self.model = hub.bsdf_model
        self.params = per_layer[0][0]
        self.values = [v for _, v, _ in per_layer]
        self.key = structure_key(self.model, self.params, self.values[0])
        if self.key not in self._material_passes:
            self._material_passes[self.key] = self._frozen(
                _material_pass(self.model, self.params, self.shadows)
            )

    def shade(
        self, gbuffer: GBuffer, part: str, layer: int, seed: int, spp: int = 1, base: int = 0
    ):
        """One pass of ``spp`` samples per pixel of ``part`` (``"material"`` or
        ``"other"``) at sub-pixel position ``layer``: (flat pixel indices, (N, 3)
        radiance float32), or None when the part has no pixel there. The samples are
        numbers ``base`` … ``base + spp - 1`` of each pixel's sequence for ``seed``
        (:func:`_samples`): one seed per accumulation, ``base`` the samples it has."""
        import drjit as dr
        import mitsuba as mi

        hits = (gbuffer.material if part == "material" else gbuffer.other)[layer]
        if not hits.count:
            return None
        seed_ = dr.opaque(mi.UInt32, seed & 0xFFFFFFFF)
        base_ = dr.opaque(mi.UInt32, base & 0xFFFFFFFF)
        # ``hits.width`` (padded) is a Python int: each width is its own recording.
        if part == "material":
            fn = self._material_passes[self.key]
            args = (hits.arrays, self.values[layer], seed_, base_, spp, hits.width)
        else:
            fn = self._other
            args = (hits.arrays, seed_, base_, spp, hits.width)
        # The models' look-up tables are inputs too (tables.device_tables).
        try:
            value = fn(self.scene, self.emitter, *args, device_tables())
        except RuntimeError:
            if not hasattr(fn, "n_recordings"):
                raise
            # A model whose kernel reads a variable the recording cannot see (measured:
            # the Conty-Kulla sheen of velvet) is traced on every pass instead.
            fn = getattr(fn, "__wrapped__", None) or self._unfrozen(part)
            if part == "material":
                self._material_passes[self.key] = fn
            else:
                self._other = fn
            value = fn(self.scene, self.emitter, *args, device_tables())
        dr.eval(value)
        rgb = np.stack([value[c].numpy() for c in range(3)], axis=1)
        return hits.pixel, rgb[: hits.count]
