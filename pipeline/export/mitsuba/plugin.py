"""One Mitsuba BSDF plugin class that renders any :class:`~lookdev.materials.bsdf.Model`.

The class adapts the model's four core functions, run on the Dr.Jit backend of the array
shim (:meth:`DrJitOps.for_mitsuba`), to Mitsuba's BSDF interface, so a proof shows the very
maths the numpy plots and tests describe (:doc:`/design`, One implementation of each model).
It only ties together the parts that each do one thing, as Mitsuba's own plugins do:

* :mod:`.inputs`: the properties it reads (constants, textures, its switches), what it
  exposes to ``mi.traverse`` and what ``prepare`` is handed;
* :mod:`.components`: the kept lobes as Mitsuba components and flags, and which
  component a direction or a sample belongs to;
* :mod:`.transport`: radiance against importance transport (the adjoint) and the IOR
  along a sampled path.

Conventions at the boundary, and only here (:doc:`/design`, Conventions):

* Mitsuba's ``si.wi`` is the viewer side and its ``wo`` the light side; our core
  ``eval(xp, prepared, wi=light, wo=viewer)`` is the other way round, so the names swap.
* Mitsuba's ``eval`` returns f·|cos θ| of the light side; ours returns f: multiply here.
* Mitsuba's ``sample`` draws the light side from ``sample1`` (lobe choice) and ``sample2``
  (direction): ``u = (sample1, sample2.x, sample2.y)``, and our sample weight
  ``f·|cos θi|/pdf`` is exactly Mitsuba's sample value.
* Transport mode: :mod:`.transport`.
"""

from __future__ import annotations

import functools
from typing import Any

from lookdev.materials.arrays import DrJitOps
from lookdev.materials.bsdf import Model
from lookdev.materials.guides import guide_albedo

from . import components as cm
from . import inputs as ins
from . import transport as tr

__all__ = ["register_model"]


def register_model(model: Model) -> str:
    """Register ``model`` as a Mitsuba BSDF plugin for the current variant; its name."""
    import mitsuba as mi

    name = ins.plugin_name(model)
    key = (mi.variant(), name, id(model))
    if key not in _REGISTERED:
        cls = _plugin_class(mi.variant())
        mi.register_bsdf(name, lambda props: cls(props, model))
        _REGISTERED.add(key)
    return name


_REGISTERED: set[tuple[str, str, int]] = set()


@functools.cache
def _plugin_class(variant: str) -> type:
    """The adapter class for one Mitsuba variant (``mi.BSDF`` differs per variant)."""
    import drjit as dr
    import mitsuba as mi

    class ModelBSDF(mi.BSDF):
        """A lookdev Model as a Mitsuba BSDF (see the module docstring)."""

        def __init__(self, props: mi.Properties, model: Model):
            mi.BSDF.__init__(self, props)
            self.model = model
            self.xp = DrJitOps.for_mitsuba()
            self.inputs = ins.read_properties(props, model)
            self.traversed = ins.traversed_values(model, self.inputs)
            self._configure()

        # -- parameters ----------------------------------------------------------------
        def _configure(self) -> None:
            """Validate the constants and derive the components from the lobes kept."""
            model, inputs = self.model, self.inputs
            self.params = model.params_type.parse(inputs.constants, where=ins.plugin_name(model))
            placeholders = ins.texture_placeholders(self.xp, model, inputs.textures)
            prepared = self._restricted(
                model.prepare(self.xp, self.params, **self._forced(), **placeholders)
            )
            # A constant material's prepare is the same at every hit and in every call:
            # computed here once, not traced again by each eval/pdf/sample of each render
            # (it was most of the model's tracing time, lookdev bench eval).
            constant = not (inputs.textures or inputs.force_all_lobes or inputs.live)
            self._constant_prepared = prepared if constant else None
            self.comps = cm.components_of(model, self.params, prepared, inputs.textures)
            self.lobes = self.comps.lobes  # what a test or a user asks of a loaded BSDF
            self.m_components = list(self.comps.m_components)
            self.m_flags = self.comps.m_flags

        def _forced(self) -> dict[str, Any]:
            """Every numeric parameter as an opaque Dr.Jit value, when all lobes must be
            traced (:func:`.inputs.opaque_inputs`); in ``live`` mode the traversed values."""
            if self.inputs.live:
                return dict(self.traversed)
            if not self.inputs.force_all_lobes:
                return {}
            return ins.opaque_inputs(self.model, self.params, skip=self.inputs.textures)

        def _prepare(self, si: mi.SurfaceInteraction3f, active: mi.Bool) -> Any:
            if self._constant_prepared is not None:
                return self._constant_prepared
            maps = self._forced()
            maps.update(ins.texture_maps(self.xp, self.model, self.inputs.textures, si, active))
            return self._restricted(self.model.prepare(self.xp, self.params, **maps))

        def _restricted(self, prepared: Any) -> Any:
            if self.inputs.only_lobes is None:
                return prepared
            return self.model.restrict(self.xp, prepared, self.inputs.only_lobes)

        def _scaled(self, value: Any) -> Any:
            scale = self.inputs.weight_scale
            return value if scale == 1.0 else value * scale

        def traverse(self, callback: Any) -> None:
            for key, value in self.traversed.items():
                callback.put(key, value, mi.ParamFlags.NonDifferentiable)
            for key, tex in self.inputs.textures.items():
                callback.put(key, tex, mi.ParamFlags.NonDifferentiable)

        def parameters_changed(self, keys: list[str]) -> None:
            if self.inputs.live:
                # In memory, not literals: the kernel reads them (no new kernel), and the
                # lobes and flags depend on switches only.
                for key in keys:
                    if key in self.traversed:
                        dr.make_opaque(self.traversed[key])
                return
            if ins.updated_constants(self.inputs, self.traversed, keys):
                self._configure()

        # -- the BSDF interface --------------------------------------------------------
        def _f(self, ctx: mi.BSDFContext, prepared: Any, si_wi: Any, wo: Any) -> Any:
            return tr.f_for_mode(ctx, self.comps, self.model, self.xp, prepared, si_wi, wo)

        def _masked_f(self, ctx, si, wo, prepared, ok) -> Any:
            f = self._f(ctx, prepared, si.wi, wo)
            return dr.select(ok, self._scaled(mi.Spectrum(f) * dr.abs(wo.z)), 0.0)

        def _masked_pdf(self, si, wo, prepared, ok) -> Any:
            return dr.select(ok, mi.Float(self.model.pdf(self.xp, prepared, wo, si.wi)), 0.0)

        def eval(self, ctx, si, wo, active=True):
            prepared = self._prepare(si, active)
            ok = active & cm.hemisphere_mask(ctx, self.comps, si.wi.z, wo.z)
            return self._masked_f(ctx, si, wo, prepared, ok)

        def pdf(self, ctx, si, wo, active=True):
            prepared = self._prepare(si, active)
            ok = active & cm.hemisphere_mask(ctx, self.comps, si.wi.z, wo.z)
            return self._masked_pdf(si, wo, prepared, ok)

        def eval_pdf(self, ctx, si, wo, active=True):
            prepared = self._prepare(si, active)
            ok = active & cm.hemisphere_mask(ctx, self.comps, si.wi.z, wo.z)
            return self._masked_f(ctx, si, wo, prepared, ok), self._masked_pdf(si, wo, prepared, ok)

        def sample(self, ctx, si, sample1, sample2, active=True):
            prepared = self._prepare(si, active)
            adjoint = tr.is_adjoint(ctx, self.comps)
            if adjoint:
                prepared = tr.adjoint_prepared(prepared)  # the model's deltas, adjoint
            u = self.xp.vec3(sample1, sample2.x, sample2.y)
            wi, weight, pdf, delta = self.model.sample(self.xp, prepared, si.wi, u)
            bs = dr.zeros(mi.BSDFSample3f)
            bs.wo = mi.Vector3f(wi)
            bs.pdf = mi.Float(pdf)
            reflected = si.wi.z * bs.wo.z > 0
            bs.eta = tr.eta_along(self.comps, self.params, prepared, si.wi.z, reflected)
            delta = mi.Bool(delta) if not isinstance(delta, bool) else delta
            bs.sampled_component, bs.sampled_type, enabled = cm.sampled_component(
                ctx, self.comps, reflected, delta
            )
            ok = active & (bs.pdf > 0) & enabled
            if adjoint:
                weight = tr.adjoint_weight(
                    ctx, self.comps, self.model, self.xp, prepared, si, bs, weight, delta
                )
            value = dr.select(ok, self._scaled(mi.Spectrum(weight)), 0.0)
            bs.pdf = dr.select(ok, bs.pdf, 0.0)
            return bs, value

        def eval_diffuse_reflectance(self, si, active=True):
            """The albedo guide of Mitsuba's ``aov`` integrator (and so of the denoiser):
            the model's diffuse-like lobes plus OIDN's rules for its glossy ones
            (:func:`lookdev.materials.guides.guide_albedo`), not Mitsuba's default
            π·f(wi = n), which bakes the highlight in and leaves glass black."""
            prepared = self._prepare(si, active)
            albedo = guide_albedo(self.xp, self.model, prepared, si.wi)  # si.wi: the viewer
            return dr.select(active, self._scaled(mi.Spectrum(albedo)), 0.0)

        def to_string(self) -> str:
            return f"ModelBSDF[model={self.model.name!r}, lobes={self.m_flags!r}]"

    return ModelBSDF
