"""Transport mode at a lookdev BSDF plugin: radiance, importance, and the path's IOR.

Our models describe radiance: f(light, viewer), a refraction into a medium of relative
index η carrying the 1/η² of the solid angle's compression (Veach 1997 §5.2, the
non-symmetric BSDF). Under ``TransportMode.Importance`` (a light tracer such as
``ptracer``) si.wi is where the light came from and wo leads to the sensor, and Mitsuba
asks for the adjoint f*(si.wi, wo) = f(light = si.wi, viewer = wo): the plugin evaluates
the model with the roles as they physically are, and a sampled direction (drawn by the
model's sampler with si.wi as the viewer, so the pdf is unchanged) is worth that
f·|cos θo|/pdf. For a radiance-form refraction this is f·η², η = η(wo side)/η(si.wi side),
exactly Mitsuba's convention (mitsuba3 ``roughdielectric.cpp``: ``scale = Radiance ?
sqr(inv_eta) : 1`` in ``eval``; ``dielectric.cpp``: ``factor = Radiance ? sqr(eta_ti) : 1``
in ``sample``), but it is also right for lobes that are not of that form: a Lambertian
``diff_trans`` beside the glass has no η², Smits' transmitted highlights
(:mod:`lookdev.materials.pixar`) are centred on the refracted view, so f(l, v) ≠ f(v, l) at
any IOR, and Conty–Kulla's terminator softening (:mod:`lookdev.materials.sheen`) acts on
the light side only (:attr:`~lookdev.materials.bsdf.Lobe.reciprocal`). A delta sample has
no f to evaluate, so the model supplies its adjoint itself when ``prepared.adjoint`` asks
(:class:`~lookdev.materials.bsdf.Model`): the Disney glass drops its 1/η², as
``dielectric`` does; Smits' refracted view sends light from l to the one viewer whose view
refracts to l, weight η² W (:mod:`lookdev.materials.pixar_scatter`). A reciprocal BSDF is
untouched in both modes (same kernel, bit-identical values). The components holding a
refraction or a non-reciprocal lobe are flagged ``NonSymmetric``
(:func:`.components.components_of`).

Measured (``tests/_transport_furnace.py``, which ``python tests/_transport_furnace.py``
prints; test ``test_mitsuba_transport.py``): white glass, η = 1.5, seen by a camera
*inside* it (the radiance in the glass, η² = 2.25 if lossless), ``path`` / ``ptracer``:
smooth 2.250 / 2.232 (``dielectric`` the same), rough 0.3 2.213 / 2.205
(``roughdielectric`` 2.213 / 2.206), thin 1.000 / 1.000; spec_trans 0.6 + diff_trans 0.3
1.415 / 1.406 (1.588 before, +12 %: the η² was applied to the Lambertian part too); the
Pixar glass (clear, back 1) 0.476 / 0.474 (1.265 before). Seen from outside, where
``ptracer`` connects by the Importance ``eval`` of the rough transmission: 0.497 / 0.503
(``roughdielectric`` 0.498 / 0.498). ``ptracer`` noise there ≈ 1.1 % (32768 spp, 8×8).
The preset ``pixar_clear_glass`` (delta lobes only), camera inside: 1.000 / 1.024
(8 more seeds: 1.001 ± 0.006; 5.3 before, the η² guessed for its delta). The sheen's
softening changes only grazing light: a white sheen ball agrees either way
(0.078 / 0.078), which is why its test is on ``eval`` (``test_mitsuba_models.py``).
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any

from lookdev.materials.bsdf import Model, Prepared

from .components import Components

__all__ = ["adjoint_prepared", "adjoint_weight", "eta_along", "f_for_mode", "is_adjoint"]


def is_adjoint(ctx: Any, comps: Components) -> bool:
    """Whether the context asks for the adjoint of a BSDF that differs from it: importance
    transport of a non-symmetric one (a reciprocal model is its own adjoint)."""
    import mitsuba as mi

    return ctx.mode == mi.TransportMode.Importance and any(comps.non_symmetric)


def f_for_mode(ctx, comps: Components, model: Model, xp, prepared, si_wi, wo) -> Any:
    """The model's f for Mitsuba's (si.wi, wo) in the context's transport mode.

    Ours is ``eval(light, viewer)``. Radiance: si.wi is the viewer, wo the light.
    Importance (a light tracer): si.wi is where the light came from and wo leads to the
    sensor, and Mitsuba asks for the adjoint f*(si.wi, wo) = f(light = si.wi, viewer = wo)
    — the model evaluated with the roles as they physically are. For a reciprocal model
    that is the same number, so only a non-symmetric BSDF pays.
    """
    if is_adjoint(ctx, comps):
        return model.eval(xp, prepared, si_wi, wo)
    return model.eval(xp, prepared, wo, si_wi)


def adjoint_prepared(prepared: Prepared) -> Prepared:
    """``prepared`` asking the model's sampler for its deltas' adjoint (``adjoint``)."""
    return replace(prepared, adjoint=True)


def adjoint_weight(ctx, comps, model, xp, prepared, si, bs, weight, delta) -> Any:
    """The sampled value f*(si.wi, wo)·|cos θo|/pdf of a light tracer.

    The direction is drawn by the model's own sampler with si.wi in the viewer's place, so
    the pdf of a sample with a density is unchanged, and its value is the adjoint f of
    :func:`f_for_mode` over that pdf (what ``eval``/``pdf`` say, so MIS stays consistent).
    A delta has no f to evaluate: the model, asked through ``prepared.adjoint``, returned
    its adjoint direction and weight itself.
    """
    import drjit as dr

    if delta is True:
        return weight
    f = xp.Array3(f_for_mode(ctx, comps, model, xp, prepared, si.wi, bs.wo))
    inv_pdf = dr.select(bs.pdf > 0, dr.rcp(bs.pdf), 0.0)
    dense = f * (dr.abs(bs.wo.z) * inv_pdf)
    if delta is False:
        return dense
    return dr.select(delta, xp.Array3(weight), dense)


def eta_along(comps: Components, params: Any, prepared: Any, cos_view, reflected) -> Any:
    """Relative IOR along a sampled path (Mitsuba's Russian roulette tracks it).

    Through a solid dielectric it is the model's ``prepared.eta`` going in and its
    inverse going out; reflections and thin sheets do not bend the path.
    """
    import drjit as dr
    import mitsuba as mi

    eta = prepared.eta
    solid = not getattr(params, "thin", False)
    bends = mi.BSDFFlags.GlossyTransmission | mi.BSDFFlags.DeltaTransmission
    if eta is None or not solid or not comps.transmits & bends:
        return mi.Float(1.0)
    crossing = dr.select(cos_view > 0, eta, 1.0 / eta)
    return dr.select(reflected, 1.0, crossing)
