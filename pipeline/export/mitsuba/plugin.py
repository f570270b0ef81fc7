"""One Mitsuba BSDF plugin class that renders any :class:`~lookdev.materials.bsdf.Model`.

The class adapts the model's four core functions, run on the Dr.Jit backend of the array
shim (:meth:`DrJitOps.for_mitsuba`), to Mitsuba's BSDF interface, so a proof shows the very
maths the numpy plots and tests describe (:doc:`/design`, One implementation of each model).

Conventions at the boundary, and only here (:doc:`/design`, Conventions):

* Mitsuba's ``si.wi`` is the viewer side and its ``wo`` the light side; our core
  ``eval(xp, prepared, wi=light, wo=viewer)`` is the other way round, so the names swap.
* Mitsuba's ``eval`` returns f·|cos θ| of the light side; ours returns f: multiply here.
* Mitsuba's ``sample`` draws the light side from ``sample1`` (lobe choice) and ``sample2``
  (direction): ``u = (sample1, sample2.x, sample2.y)``, and our sample weight
  ``f·|cos θi|/pdf`` is exactly Mitsuba's sample value.
* Transport mode. Our models describe radiance: f(light, viewer), a refraction into a
  medium of relative index η carrying the 1/η² of the solid angle's compression (Veach 1997
  §5.2, the non-symmetric BSDF). Under ``TransportMode.Importance`` (a light tracer such
  as ``ptracer``) si.wi is where the light came from and wo leads to the sensor, and
  Mitsuba asks for the adjoint f*(si.wi, wo) = f(light = si.wi, viewer = wo): the plugin
  evaluates the model with the roles as they physically are, and a sampled direction
  (drawn by the model's sampler with si.wi as the viewer, so the pdf is unchanged) is
  worth that f·|cos θo|/pdf. For a radiance-form refraction this is f·η², η = η(wo
  side)/η(si.wi side), exactly Mitsuba's convention (mitsuba3 ``roughdielectric.cpp``:
  ``scale = Radiance ? sqr(inv_eta) : 1`` in ``eval``; ``dielectric.cpp``: ``factor =
  Radiance ? sqr(eta_ti) : 1`` in ``sample``), but it is also right for lobes that are not
  of that form: a Lambertian ``diff_trans`` beside the glass has no η², Smits'
  transmitted highlights (:mod:`lookdev.materials.pixar`) are centred on the refracted
  view, so f(l, v) ≠ f(v, l) at any IOR, and Conty–Kulla's terminator softening
  (:mod:`lookdev.materials.sheen`) acts on the light side only
  (:attr:`~lookdev.materials.bsdf.Lobe.reciprocal`).
  A delta sample has no f to evaluate, so the model supplies its adjoint itself when
  ``prepared[ADJOINT]`` asks (:class:`~lookdev.materials.bsdf.Model`): the Disney glass
  drops its 1/η², as ``dielectric`` does; Smits' refracted view sends light from l to
  the one viewer whose view refracts to l, weight η² W (:mod:`lookdev.materials.pixar_scatter`).
  A reciprocal BSDF is untouched in both modes
  (same kernel, bit-identical values). The components holding a refraction or a
  non-reciprocal lobe are flagged ``NonSymmetric``.

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

Delta lobes. A model may sample some lobes as Dirac deltas (smooth glass, mirrors:
``prepared["delta"]``, :mod:`lookdev.materials.disney_interface`). They form their own
components, flagged ``DeltaReflection`` / ``DeltaTransmission`` (a BSDF with no other
lobe has no ``Smooth`` flag, so the path tracer samples no light at its vertices);
``eval`` and ``pdf`` leave them out, as the model does, and a sample of one reports that
type and component (the model's ``delta`` mask), its pdf the probability of its choice.
A context that asks for the smooth components only gets such samples with weight 0.

Parameters arrive as Mitsuba properties, one per schema field: a constant (float, bool,
string, ``rgb``) or a texture (``bitmap`` …). Constants are handed to ``prepare`` as Python
values, so a lobe whose weight is a constant zero is pruned while the kernel is traced;
textures are evaluated at ``si`` and handed to ``prepare`` as ``maps``. With the boolean
property ``force_all_lobes`` every numeric parameter is handed over as an opaque Dr.Jit
value instead: no weight is then a *known* zero and every lobe is traced (the benchmark
baseline). With ``live`` (the Material Designer's truth mode) those opaque values are the
traversed parameters themselves, defaults included: ``mi.traverse`` edits of any of them
change memory the kernel reads, never the kernel; only a switch (``thin``, a model name)
needs a new BSDF.
"""

from __future__ import annotations

import functools
from collections.abc import Iterable
from typing import Any

import numpy as np

from lookdev.materials.arrays import DrJitOps
from lookdev.materials.bsdf import ADJOINT, Model
from lookdev.materials.errors import LookdevError
from lookdev.materials.guides import guide_albedo
from lookdev.materials.registry import is_color_field

__all__ = [
    "FORCE_ALL_LOBES",
    "LIVE",
    "MitsubaExportError",
    "ONLY_LOBES",
    "PLUGIN_PREFIX",
    "WEIGHT_SCALE",
    "delta_lobes",
    "lobe_kinds",
    "lobes_of",
    "opaque_inputs",
    "plugin_name",
    "register_model",
]

PLUGIN_PREFIX = "lookdev_"
FORCE_ALL_LOBES = "force_all_lobes"
LIVE = "live"
"""Boolean property: every continuous parameter is a traversed, opaque Dr.Jit value read
by the kernel from memory, so an edit through ``mi.traverse`` needs no new kernel (the
designer's truth mode); every lobe a value can switch on is traced."""
ONLY_LOBES = "only_lobes"
"""Comma-separated lobe names: the plugin evaluates and samples only these (Model.restrict)."""
WEIGHT_SCALE = "weight_scale"
"""A factor on f and on sampled weights, not on pdfs: halves of a split material carry 2."""


class MitsubaExportError(LookdevError):
    """A material cannot become a Mitsuba BSDF or scene as asked."""


def lobes_of(prepared: Any) -> tuple[str, ...]:
    """The lobe names a prepared material kept (``prepared["lobes"]`` or ``.lobes``)."""
    lobes = (
        prepared.get("lobes") if isinstance(prepared, dict) else getattr(prepared, "lobes", None)
    )
    if lobes is None:
        raise MitsubaExportError("the model's prepare() does not record its 'lobes'")
    return tuple(lobes)


def lobe_kinds(lobes: Iterable[str], model: Model, delta: Iterable[str] = ()) -> set[str]:
    """Mitsuba flag names (``GlossyReflection`` …) of the given lobes of ``model``,
    as the registry describes them (:class:`lookdev.materials.bsdf.Lobe`); the lobes in
    ``delta`` (a prepared material's smooth lobes) are ``DeltaReflection`` /
    ``DeltaTransmission`` instead."""
    delta = set(delta)
    try:
        return {_kind(model.lobe(name), name in delta) for name in lobes}
    except KeyError as exc:
        raise MitsubaExportError(exc.args[0]) from None


def _kind(lobe: Any, delta: bool) -> str:
    if not delta:
        return lobe.mitsuba_flag
    return "Delta" + ("Transmission" if lobe.transmits else "Reflection")


def delta_lobes(prepared: Any) -> tuple[str, ...]:
    """The kept lobes a prepared material samples as deltas (``prepared["delta"]``)."""
    delta = prepared.get("delta", ()) if isinstance(prepared, dict) else ()
    return tuple(k for k in lobes_of(prepared) if k in delta)


def plugin_name(model: Model) -> str:
    """The Mitsuba plugin name of a model: ``lookdev_<model.name>``."""
    return PLUGIN_PREFIX + model.name


def register_model(model: Model) -> str:
    """Register ``model`` as a Mitsuba BSDF plugin for the current variant; its name."""
    import mitsuba as mi

    name = plugin_name(model)
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

    flag = mi.BSDFFlags

    class ModelBSDF(mi.BSDF):
        """A lookdev Model as a Mitsuba BSDF (see the module docstring)."""

        def __init__(self, props: mi.Properties, model: Model):
            mi.BSDF.__init__(self, props)
            self.model = model
            self.xp = DrJitOps.for_mitsuba()
            fields = model.params_type.model_fields
            self.force_all_lobes = False
            self.live = False
            self.only_lobes: tuple[str, ...] | None = None
            self.weight_scale = 1.0
            self.constants: dict[str, Any] = {}
            self.textures: dict[str, mi.Texture] = {}
            for key in props.keys():
                value = props[key]
                if key == FORCE_ALL_LOBES:
                    self.force_all_lobes = bool(value)
                elif key == LIVE:
                    self.live = bool(value)
                elif key == ONLY_LOBES:
                    self.only_lobes = tuple(n.strip() for n in str(value).split(",") if n.strip())
                elif key == WEIGHT_SCALE:
                    self.weight_scale = float(value)
                elif key not in fields:
                    raise MitsubaExportError(
                        f"unknown parameter; allowed: {', '.join(fields)}",
                        where=plugin_name(model),
                        field=key,
                    )
                elif isinstance(value, mi.Texture):
                    self.textures[key] = value
                else:
                    self.constants[key] = _python_value(value)
            # Numbers and colours can change after load; switches (``thin``, a model name)
            # shape the traced kernel, so a new BSDF is the way to change them.
            self.traversed = {
                k: _drjit_value(v)
                for k, v in self.constants.items()
                if isinstance(v, float | tuple)
            }
            if self.live:
                params = self.model.params_type.parse(self.constants, where=plugin_name(model))
                self.traversed = opaque_inputs(self.model, params, skip=self.textures)
            self._configure()

        # -- parameters ----------------------------------------------------------------
        def _configure(self) -> None:
            """Validate the constants and derive flags from the lobes ``prepare`` keeps."""
            self.params = self.model.params_type.parse(
                self.constants, where=plugin_name(self.model)
            )
            placeholders = {k: self._placeholder(k) for k in self.textures}
            prepared = self._restricted(
                self.model.prepare(self.xp, self.params, **self._forced(), **placeholders)
            )
            self.lobes = lobes_of(prepared)
            """The lobes this instance traces (the model's live lobes, or ``only_lobes``)."""
            # A constant material's prepare is the same at every hit and in every call:
            # computed here once, not traced again by each eval/pdf/sample of each render
            # (it was most of the model's tracing time, lookdev bench eval).
            constant = not (self.textures or self.force_all_lobes or self.live)
            self._constant_prepared = prepared if constant else None
            kinds = sorted(lobe_kinds(self.lobes, self.model, delta_lobes(prepared)))
            # Components: reflection and transmission with a density, then the deltas.
            groups = [
                [k for k in kinds if side in k and ("Delta" in k) == delta]
                for delta in (False, True)
                for side in ("Reflection", "Transmission")
            ]
            self.components = [_union([getattr(flag, k) for k in g], flag) for g in groups]
            # Mitsuba numbers only the components that exist, in this order.
            present = [i for i, c in enumerate(self.components) if c]
            self.component_index = tuple(
                present.index(i) if c else 0 for i, c in enumerate(self.components)
            )
            transmit = self.components[1] or self.components[3]
            extra = flag.FrontSide | (flag.BackSide if transmit else flag.Empty)
            if self.textures:
                extra |= flag.SpatiallyVarying
            if getattr(self.params, "anisotropic", 0) or "anisotropic" in self.textures:
                extra |= flag.Anisotropic
            self.refracts = self._refracts(prepared)
            """Transmission bends the path (η ≠ 1 through a solid): non-symmetric."""
            self.non_symmetric = self._non_symmetric(delta_lobes(prepared))
            """Per component (0–3 as ``components``): f(l, v) ≠ f(v, l) somewhere in it."""
            self.m_components = [
                c | extra | (flag.NonSymmetric if ns else flag.Empty)
                for c, ns in zip(self.components, self.non_symmetric, strict=True)
                if c != flag.Empty
            ]
            self.m_flags = functools.reduce(lambda a, b: a | b, self.m_components, flag.Empty)

        def _non_symmetric(self, delta: tuple[str, ...]) -> list[bool]:
            """Which of the four components is not reciprocal: the transmission of a
            refracting solid (its η²) and any component holding a lobe the registry
            declares non-reciprocal (:attr:`~lookdev.materials.bsdf.Lobe.reciprocal`)."""
            out = [False, self.refracts, False, self.refracts]
            for name in self.lobes:
                lobe = self.model.lobe(name)
                if not lobe.is_reciprocal(self.params):
                    out[int(lobe.transmits) + 2 * (name in delta)] = True
            return out

        def _placeholder(self, field: str) -> Any:
            # A texture may be non-zero somewhere: an opaque value keeps its lobe alive.
            if is_color_field(self.model.params_type, field):
                return self.xp.Array3(dr.opaque(mi.Float, 0.5))
            return dr.opaque(mi.Float, 0.5)

        def _forced(self) -> dict[str, Any]:
            """Every numeric parameter as an opaque Dr.Jit value, when all lobes must be
            traced (:func:`opaque_inputs`); in ``live`` mode the traversed values."""
            if self.live:
                return dict(self.traversed)
            if not self.force_all_lobes:
                return {}
            return opaque_inputs(self.model, self.params, skip=self.textures)

        def _prepare(self, si: mi.SurfaceInteraction3f, active: mi.Bool) -> Any:
            if self._constant_prepared is not None:
                return self._constant_prepared
            maps = self._forced()
            for key, tex in self.textures.items():
                if is_color_field(self.model.params_type, key):
                    maps[key] = self.xp.Array3(tex.eval(si, active))
                else:
                    maps[key] = tex.eval_1(si, active)
            return self._restricted(self.model.prepare(self.xp, self.params, **maps))

        def _scaled(self, value: Any) -> Any:
            return value if self.weight_scale == 1.0 else value * self.weight_scale

        def _restricted(self, prepared: Any) -> Any:
            if self.only_lobes is None:
                return prepared
            return self.model.restrict(self.xp, prepared, self.only_lobes)

        def traverse(self, callback: Any) -> None:
            for key, value in self.traversed.items():
                callback.put(key, value, mi.ParamFlags.NonDifferentiable)
            for key, tex in self.textures.items():
                callback.put(key, tex, mi.ParamFlags.NonDifferentiable)

        def parameters_changed(self, keys: list[str]) -> None:
            changed = [k for k in keys if k in self.traversed]
            if self.live:
                # In memory, not literals: the kernel reads them (no new kernel), and the
                # lobes and flags depend on switches only.
                for key in changed:
                    dr.make_opaque(self.traversed[key])
                return
            for key in changed:
                self.constants[key] = _from_drjit(self.traversed[key], self.constants[key])
            if changed:
                self._configure()

        # -- the BSDF interface --------------------------------------------------------
        def _hemisphere_mask(
            self, ctx: mi.BSDFContext, cos_view: mi.Float, cos_light: mi.Float
        ) -> mi.Bool:
            """Directions in a hemisphere whose component the context asks for."""
            same_side = cos_view * cos_light > 0
            want_r = _is_enabled(ctx, self.components[0], self.component_index[0])
            want_t = _is_enabled(ctx, self.components[1], self.component_index[1])
            # select, not ~: on scalar variants the mask is a Python bool, and ~True is -2.
            return dr.select(same_side, want_r, want_t)

        def _f(self, ctx: mi.BSDFContext, prepared: Any, si_wi: Any, wo: Any) -> Any:
            """The model's f for Mitsuba's (si.wi, wo) in the context's transport mode.

            Ours is ``eval(light, viewer)``. Radiance: si.wi is the viewer, wo the light.
            Importance (a light tracer): si.wi is where the light came from and wo leads to
            the sensor, and Mitsuba asks for the adjoint f*(si.wi, wo) = f(light = si.wi,
            viewer = wo) — the model evaluated with the roles as they physically are. For a
            reciprocal model that is the same number, so only a non-symmetric BSDF pays.
            """
            if ctx.mode == mi.TransportMode.Importance and any(self.non_symmetric):
                return self.model.eval(self.xp, prepared, si_wi, wo)
            return self.model.eval(self.xp, prepared, wo, si_wi)

        def eval(self, ctx, si, wo, active=True):
            prepared = self._prepare(si, active)
            f = self._f(ctx, prepared, si.wi, wo)
            ok = active & self._hemisphere_mask(ctx, si.wi.z, wo.z)
            return dr.select(ok, self._scaled(mi.Spectrum(f) * dr.abs(wo.z)), 0.0)

        def pdf(self, ctx, si, wo, active=True):
            prepared = self._prepare(si, active)
            pdf = self.model.pdf(self.xp, prepared, wo, si.wi)
            ok = active & self._hemisphere_mask(ctx, si.wi.z, wo.z)
            return dr.select(ok, mi.Float(pdf), 0.0)

        def eval_pdf(self, ctx, si, wo, active=True):
            prepared = self._prepare(si, active)
            f = self._f(ctx, prepared, si.wi, wo)
            pdf = self.model.pdf(self.xp, prepared, wo, si.wi)
            ok = active & self._hemisphere_mask(ctx, si.wi.z, wo.z)
            return (
                dr.select(ok, self._scaled(mi.Spectrum(f) * dr.abs(wo.z)), 0.0),
                dr.select(ok, mi.Float(pdf), 0.0),
            )

        def sample(self, ctx, si, sample1, sample2, active=True):
            prepared = self._prepare(si, active)
            adjoint = ctx.mode == mi.TransportMode.Importance and any(self.non_symmetric)
            if adjoint and isinstance(prepared, dict):
                prepared = {**prepared, ADJOINT: True}  # the model's deltas, adjoint
            u = self.xp.vec3(sample1, sample2.x, sample2.y)
            wi, weight, pdf, delta = self.model.sample(self.xp, prepared, si.wi, u)
            bs = dr.zeros(mi.BSDFSample3f)
            bs.wo = mi.Vector3f(wi)
            bs.pdf = mi.Float(pdf)
            reflected = si.wi.z * bs.wo.z > 0
            bs.eta = self._eta(prepared, si.wi.z, reflected)
            delta = mi.Bool(delta) if not isinstance(delta, bool) else delta
            # Component i: 0/1 reflection/transmission with a density, 2/3 the deltas.
            pick = [(reflected, 0, 1), (reflected, 2, 3)]
            index, kind, enabled = [], [], []
            for cond, r, t in pick:
                index.append(dr.select(cond, self.component_index[r], self.component_index[t]))
                kind.append(
                    dr.select(
                        cond,
                        _leading(self.components[r], flag),
                        _leading(self.components[t], flag),
                    )
                )
                enabled.append(
                    dr.select(
                        cond,
                        _is_enabled(ctx, self.components[r], self.component_index[r]),
                        _is_enabled(ctx, self.components[t], self.component_index[t]),
                    )
                )
            bs.sampled_component = mi.UInt32(dr.select(delta, index[1], index[0]))
            bs.sampled_type = mi.UInt32(dr.select(delta, kind[1], kind[0]))
            ok = active & (bs.pdf > 0) & dr.select(delta, enabled[1], enabled[0])
            if adjoint:
                weight = self._adjoint_weight(ctx, prepared, si, bs, weight, delta)
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

        def _refracts(self, prepared: Any) -> bool:
            """Whether a transmitted path changes medium (see :meth:`_eta`)."""
            eta = prepared.get("eta") if isinstance(prepared, dict) else None
            solid = not getattr(self.params, "thin", False)
            bends = flag.GlossyTransmission | flag.DeltaTransmission
            glossy_t = bool((self.components[1] | self.components[3]) & bends)
            if eta is None or not solid or not glossy_t:
                return False
            try:
                return float(eta) != 1.0  # a constant η = 1 does not bend the path
            except (TypeError, RuntimeError):
                return True  # a texture or an opaque value: it may

        def _adjoint_weight(self, ctx, prepared, si, bs, weight, delta) -> Any:
            """The sampled value f*(si.wi, wo)·|cos θo|/pdf of a light tracer.

            The direction is drawn by the model's own sampler with si.wi in the viewer's
            place, so the pdf of a sample with a density is unchanged, and its value is
            the adjoint f of :meth:`_f` over that pdf (what ``eval``/``pdf`` say, so MIS
            stays consistent). A delta has no f to evaluate: the model, asked through
            ``prepared[ADJOINT]``, returned its adjoint direction and weight itself.
            """
            if delta is True:
                return weight
            f = self.xp.Array3(self._f(ctx, prepared, si.wi, bs.wo))
            inv_pdf = dr.select(bs.pdf > 0, dr.rcp(bs.pdf), 0.0)
            dense = f * (dr.abs(bs.wo.z) * inv_pdf)
            if delta is False:
                return dense
            return dr.select(delta, self.xp.Array3(weight), dense)

        def _eta(self, prepared: Any, cos_view: mi.Float, reflected: mi.Bool) -> mi.Float:
            """Relative IOR along a sampled path (Mitsuba's Russian roulette tracks it).

            Through a solid dielectric it is the model's ``prepared["eta"]`` going in and
            its inverse going out; reflections and thin sheets do not bend the path.
            """
            eta = prepared.get("eta") if isinstance(prepared, dict) else None
            solid = not getattr(self.params, "thin", False)
            bends = flag.GlossyTransmission | flag.DeltaTransmission
            if eta is None or not solid or not (self.components[1] | self.components[3]) & bends:
                return mi.Float(1.0)
            crossing = dr.select(cos_view > 0, eta, 1.0 / eta)
            return dr.select(reflected, 1.0, crossing)

        def to_string(self) -> str:
            return f"ModelBSDF[model={self.model.name!r}, lobes={self.m_flags!r}]"

    return ModelBSDF


def opaque_inputs(model: Model, params: Any, skip: Iterable[str] = ()) -> dict[str, Any]:
    """Every continuous parameter of ``params`` (the schema's texturable fields that hold
    a value, defaults included) as an opaque Dr.Jit value, for ``model.prepare``'s maps.

    ``known_zero`` cannot see through an opaque value, so no lobe weight derived from one
    (``spec_trans``, or ``1 − metallic`` of a metal) is pruned, and a kernel traced with
    these inputs reads them from memory: new values need no new kernel. Fields in ``skip``
    (textures) are left out.
    """
    import drjit as dr
    import mitsuba as mi

    from lookdev.materials.textures import texturable

    weights = texturable(model.params_type)  # not choices such as specular_gamma
    skip = set(skip)
    out: dict[str, Any] = {}
    for key, value in params.model_dump().items():
        if key in skip or isinstance(value, bool) or key not in weights:
            continue
        if isinstance(value, int | float):
            out[key] = dr.opaque(mi.Float, float(value))
        elif isinstance(value, tuple):
            out[key] = mi.Vector3f(*(dr.opaque(mi.Float, float(c)) for c in value))
    return out


def _union(flags: list[Any], flag: Any) -> int:
    return int(functools.reduce(lambda a, b: a | b, flags, flag.Empty))


def _is_enabled(ctx: Any, component: int, index: int) -> bool:
    """Mitsuba's ``BSDFContext::is_enabled`` for a union of flags (the binding takes one)."""
    every_component = 0xFFFFFFFF
    wanted = (ctx.type_mask & component) == component
    return bool(component) and wanted and ctx.component in (every_component, index)


def _leading(component: Any, flag: Any) -> int:
    """The sampled type reported for a component: glossy if it has a glossy lobe."""
    for kind in (flag.DeltaReflection, flag.DeltaTransmission):
        if component & kind:
            return int(kind)
    for kind in (flag.GlossyReflection, flag.GlossyTransmission):
        if component & kind:
            return int(kind)
    for kind in (flag.DiffuseReflection, flag.DiffuseTransmission):
        if component & kind:
            return int(kind)
    return 0


def _python_value(value: Any) -> Any:
    """A Mitsuba property as a plain value for the pydantic schema; numbers as the
    float32 the kernel computes in (so a lobe is pruned exactly where its stored weight is
    0, as :func:`lookdev.materials.registry.live_lobes` judges)."""
    if isinstance(value, bool | str):
        return value
    if isinstance(value, int | float):
        return float(np.float32(value))
    try:
        return tuple(float(c) for c in value)  # ScalarColor3f / ScalarColor3d
    except TypeError:
        return value


def _drjit_value(value: float | tuple[float, ...]) -> Any:
    """A numeric constant as the Dr.Jit value ``mi.traverse`` exposes."""
    import mitsuba as mi

    return mi.Color3f(*value) if isinstance(value, tuple) else mi.Float(value)


def _from_drjit(value: Any, old: float | tuple[float, ...]) -> float | tuple[float, ...]:
    """The updated traversed value back as the constant's Python type."""
    if isinstance(old, tuple):
        return tuple(float(value[i][0]) for i in range(3))
    return float(value[0])
