"""``lookdev bench eval``: the Disney BSDF on numpy, on Dr.Jit, and Mitsuba's ``principled``.

One run evaluates f(wi, wo) of the full Disney BSDF on N random direction pairs (viewer
above the surface, light anywhere on the sphere, so transmission is exercised), split
over :data:`PARAM_SETS` (eight materials that between them switch on every lobe):

- ``numpy``: :data:`lookdev.materials.disney.MODEL` on the numpy backend, float32 and
  float64, channel-first arrays prepared beforehand (the layout change of the public
  wrappers is not evaluation);
- ``drjit``: the same Python model traced by Dr.Jit (LLVM), forced with ``dr.eval`` and
  waited for, as the plugin evaluates a constant material: its ``prepare`` once, ``eval``
  traced in every call; the first call (tracing + kernel compilation, or a hit in Dr.Jit's
  on-disk kernel cache after an earlier run) is reported on its own and excluded from the
  throughput. Beside it, in the same rounds: ``drjit_prepare_each_call`` (``prepare``
  traced again in every call, as the plugin did before it kept a constant material's
  prepare: most of the tracing time, which at 125 000 evaluations a material is about half
  of a call) and ``drjit_frozen`` (the call recorded once by ``dr.freeze`` and replayed,
  as the proofs' turntable and the designer's passes run the model: the kernel alone,
  whose pruned constant-parameter form is smaller than ``principled``'s general one;
  target ``ratio_drjit_frozen_to_mitsuba`` ≥ 1.5);
- ``mitsuba``: the C++ ``principled`` plugin with the nearest parameters (see
  :func:`principled_dict`; the two models differ where :doc:`/design` says), same pairs,
  traced by its C++ in every call; and ``mitsuba_frozen``, the same call frozen, so that
  ``ratio_drjit_frozen_to_mitsuba_frozen`` compares replayed kernel with replayed kernel
  (``frozen_max_rel_diff``: the replays against the traced calls).

Reported: evaluations per second of each, per material too (``by_material``: each form's
rate and its ratio to ``principled`` on that material), and the throughput ratios
``ratio_drjit_to_mitsuba`` (target ≥ 0.5) and ``ratio_numpy_to_mitsuba`` (target ≥ 0.1,
with the faster numpy dtype, named in ``numpy_dtype``). What pruning buys is measured
too: numpy float32 with every lobe kept at weight zero (``ratio_pruned_to_every_lobe``,
with ``every_lobe_max_abs_diff`` showing that the values are the same).

The helpers :func:`principled_dict` and :func:`mitsuba_eval` are also what the tests
use to compare the two models where they coincide.
"""

from __future__ import annotations

import math
import time
from typing import Any

import numpy as np

from lookdev.materials import disney
from lookdev.materials.arrays import NumpyOps
from lookdev.materials.params import DisneyParams

__all__ = [
    "AGREEMENT_CASES",
    "DRJIT_MODES",
    "PARAM_SETS",
    "TARGET_FROZEN",
    "agreement",
    "direction_pairs",
    "mitsuba_eval",
    "principled_dict",
    "relative_difference",
    "run",
]

PARAM_SETS: dict[str, DisneyParams] = {
    "plastic": DisneyParams(base_color=(0.6, 0.2, 0.1), roughness=0.4),
    "gold": DisneyParams(base_color=(1.0, 0.77, 0.34), metallic=1.0, roughness=0.25),
    "brushed": DisneyParams(base_color=(0.9, 0.9, 0.9), metallic=1.0, anisotropic=0.8),
    "car_paint": DisneyParams(base_color=(0.1, 0.2, 0.6), roughness=0.5, clearcoat=1.0),
    "velvet": DisneyParams(base_color=(0.5, 0.1, 0.3), roughness=0.9, sheen=1.0, sheen_tint=0.0),
    "skin": DisneyParams(base_color=(0.8, 0.5, 0.4), roughness=0.6, subsurface=0.7),
    "glass": DisneyParams(base_color=(1.0, 1.0, 1.0), roughness=0.1, spec_trans=1.0, ior=1.5),
    "mixed": DisneyParams(
        base_color=(0.3, 0.6, 0.3), metallic=0.3, roughness=0.7, spec_trans=0.4, sheen=0.5
    ),
}


# -- Mitsuba's principled, for comparison ------------------------------------------------
def principled_dict(p: DisneyParams) -> dict[str, Any]:
    """Mitsuba ``principled`` parameters nearest to ``p``.

    Mitsuba's names: ``spec_tint`` for specular_tint, ``eta`` for ior, and ``flatness``
    for what is Burley 2012's ``subsurface`` blend (Mitsuba's formula is the BRDF
    Explorer's subsurface; it has no thin mode). Parameters Mitsuba lacks
    (diff_trans, thin, our thin ``flatness``) cannot be passed.
    """
    out: dict[str, Any] = {
        "type": "principled",
        "base_color": {"type": "rgb", "value": list(p.base_color)},
    }
    for ours, theirs in [
        ("roughness", "roughness"),
        ("anisotropic", "anisotropic"),
        ("metallic", "metallic"),
        ("specular_tint", "spec_tint"),
        ("sheen", "sheen"),
        ("sheen_tint", "sheen_tint"),
        ("clearcoat", "clearcoat"),
        ("clearcoat_gloss", "clearcoat_gloss"),
        ("spec_trans", "spec_trans"),
        ("subsurface", "flatness"),
    ]:
        value = float(getattr(p, ours))
        if value != 0.0 or ours in ("roughness", "clearcoat_gloss"):
            out[theirs] = value
    if p.uses_ior:
        out["eta"] = float(p.ior)
    else:
        out["specular"] = float(p.specular)
    return out


def _vectors(mi: Any, a: np.ndarray) -> Any:
    """(N, 3) numpy → mi.Vector3f."""
    a = np.asarray(a, dtype=np.float32)
    return mi.Vector3f(*(mi.Float(np.ascontiguousarray(a[:, k])) for k in range(3)))


def mitsuba_eval(bsdf: Any, wi: np.ndarray, wo: np.ndarray) -> np.ndarray:
    """f(wi, wo) of a Mitsuba BSDF without the cosine, our naming, shape (N, 3).

    Mitsuba's ``si.wi`` is our viewer ``wo`` and its ``wo`` our light ``wi``; its
    ``eval`` returns f times |cos| of that light direction, divided out here.
    """
    import drjit as dr
    import mitsuba as mi

    si = dr.zeros(mi.SurfaceInteraction3f, len(wi))
    si.wi = _vectors(mi, wo)
    value = bsdf.eval(mi.BSDFContext(), si, _vectors(mi, wi))
    f = np.array(value).reshape(3, -1).T.astype(np.float64)
    cos = np.abs(np.asarray(wi, dtype=np.float32)[:, 2]).astype(np.float64)
    return np.where(cos[:, None] > 0, f / np.maximum(cos[:, None], 1e-30), 0.0)


# Where the two models coincide (docs/design.md, Traps): model restricted to some lobes (None:
# all of ours), our parameters; Mitsuba gets principled_dict(params). With specular = 0
# Mitsuba's exact Fresnel is 0 everywhere, so its total is its diffuse (+ sheen) alone.
AGREEMENT_CASES: dict[str, tuple[tuple[str, ...] | None, DisneyParams]] = {
    "metal_r0.3_aniso0.5": (
        None,
        DisneyParams(base_color=(0.9, 0.6, 0.3), metallic=1.0, roughness=0.3, anisotropic=0.5),
    ),
    # Roughness 0 is a delta (no eval); 0.04 stretched by anisotropic 1 puts α_y at the
    # glossy minimum α (10⁻³) that both models clamp to.
    "metal_r0.04_aniso1": (
        None,
        DisneyParams(base_color=(0.9, 0.6, 0.3), metallic=1.0, roughness=0.04, anisotropic=1.0),
    ),
    "metal_r1_aniso1": (
        None,
        DisneyParams(base_color=(0.9, 0.6, 0.3), metallic=1.0, roughness=1.0, anisotropic=1.0),
    ),
    "diffuse_retro_r0.8": (("diffuse",), DisneyParams(specular=0.0, roughness=0.8)),
    "subsurface_is_flatness": (
        ("diffuse",),
        DisneyParams(specular=0.0, roughness=0.5, subsurface=0.6),
    ),
    "sheen_untinted": (
        ("diffuse", "sheen"),
        DisneyParams(specular=0.0, roughness=0.3, sheen=1.0, sheen_tint=0.0),
    ),
    "dielectric_ior1.5": (None, DisneyParams(ior=1.5, roughness=0.4)),
}


def relative_difference(ours: np.ndarray, theirs: np.ndarray) -> float:
    """max |ours − theirs| / max(|theirs|, 10⁻³ · max |theirs|): relative where it means
    something, absolute (scaled) where Mitsuba's value is near 0."""
    floor = 1e-3 * float(np.max(np.abs(theirs)))
    return float(np.max(np.abs(ours - theirs) / np.maximum(np.abs(theirs), floor)))


def agreement(n: int = 4096, seed: int = 1) -> dict[str, float]:
    """Max relative difference to ``principled`` per case of :data:`AGREEMENT_CASES`."""
    import mitsuba as mi

    from lookdev.materials.bsdf import evaluate
    from lookdev.pipeline.variant import use_mitsuba

    use_mitsuba()
    wi, wo = direction_pairs(n, seed)
    wi[:, 2] = np.abs(wi[:, 2])  # reflection only: where the cases coincide
    out = {}
    for name, (lobes, params) in AGREEMENT_CASES.items():
        model = disney.MODEL if lobes is None else disney.lobe_model(*lobes)
        ours = evaluate(model, params, wi, wo)
        theirs = mitsuba_eval(mi.load_dict(principled_dict(params)), wi, wo)
        out[name] = relative_difference(ours, theirs)
    return out


# -- the benchmark ---------------------------------------------------------------------------
def direction_pairs(n: int, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """(wi, wo), each (n, 3): wo uniform on the upper hemisphere, wi on the whole sphere."""
    rng = np.random.default_rng(seed)
    wi = rng.normal(size=(n, 3))
    wo = rng.normal(size=(n, 3))
    wo[:, 2] = np.abs(wo[:, 2])
    return (
        wi / np.linalg.norm(wi, axis=1, keepdims=True),
        wo / np.linalg.norm(wo, axis=1, keepdims=True),
    )


def _split(n: int) -> list[slice]:
    edges = np.linspace(0, n, len(PARAM_SETS) + 1).astype(int)
    return [slice(a, b) for a, b in zip(edges[:-1], edges[1:], strict=True)]


def _every_lobe(xp: Any, params: DisneyParams) -> dict[str, Any]:
    return disney.keep_every_lobe(xp, disney.prepare(xp, params))


def _numpy_runner(wi: np.ndarray, wo: np.ndarray, dtype: Any, prune: bool = True):
    xp = NumpyOps(dtype)
    parts = [(xp.asarray(wi[s].T), xp.asarray(wo[s].T)) for s in _split(len(wi))]
    prepare = disney.prepare if prune else _every_lobe

    def run() -> list[Any]:
        with np.errstate(all="ignore"):  # masked branches may overflow, as in bsdf.evaluate
            return [
                disney.MODEL.eval(xp, prepare(xp, p), a, b)
                for p, (a, b) in zip(PARAM_SETS.values(), parts, strict=True)
            ]

    return run


def _drjit_runner(wi: np.ndarray, wo: np.ndarray, mode: str = "prepared"):
    """Per-material callables of the Python model traced by Dr.Jit.

    ``mode``: ``"prepared"`` as the plugin evaluates a constant material (``prepare`` run
    once, ``eval`` traced per call); ``"prepare_each_call"`` with ``prepare`` traced
    again in every call (the plugin before it kept a constant material's prepare);
    ``"frozen"``: the call recorded once by ``dr.freeze`` and replayed, as the proofs'
    turntable and the designer's passes run it.
    """
    import drjit as dr
    import mitsuba as mi

    from lookdev.materials.arrays import DrJitOps

    xp = DrJitOps.for_mitsuba()
    model = disney.MODEL
    parts = [(_vectors(mi, wi[s]), _vectors(mi, wo[s])) for s in _split(len(wi))]
    dr.eval(parts)
    each_call = mode == "prepare_each_call"
    runners = []
    for params, (a, b) in zip(PARAM_SETS.values(), parts, strict=True):
        prepared = model.prepare(xp, params)

        # Everything the call needs is bound here, none of it in a closure: dr.freeze keys
        # every replay on its function's closure, and a Model there is walked field by
        # field down to its lobe table (six records of nine strings, tuples and flags:
        # ≈ 50 µs a call, measured), Python work of how the harness holds the model, not
        # of evaluating it; functions and prepared constants bound as defaults cost none.
        def call(
            a: Any,
            b: Any,
            params: Any = params,
            prepared: Any = prepared,
            prepare: Any = model.prepare,
            evaluate: Any = model.eval,
            xp: Any = xp,
            each_call: bool = each_call,
        ) -> Any:
            pr = prepare(xp, params) if each_call else prepared
            return evaluate(xp, pr, a, b)

        fn = dr.freeze(call) if mode == "frozen" else call

        def run(fn: Any = fn, a: Any = a, b: Any = b) -> Any:
            out = fn(a, b)
            dr.eval(out)
            dr.sync_thread()
            return out

        runners.append(run)
    return runners


def _mitsuba_runner(wi: np.ndarray, wo: np.ndarray, frozen: bool = False):
    """Per-material callables of ``principled``'s ``eval``, traced by its C++ in every
    call as a plugin's user calls it, or (``frozen``) recorded once by ``dr.freeze`` and
    replayed like ``drjit_frozen``: the same kernel without the tracing, so that the two
    frozen forms compare kernel with kernel. The BSDF is the frozen call's argument (its
    parameters are variables ``dr.freeze`` must see), one frozen function per material
    (which lobes ``principled`` evaluates is decided when it is loaded, outside what
    ``dr.freeze`` keys on); the interaction is made inside the call, zeros but for ``wi``.
    """
    import drjit as dr
    import mitsuba as mi

    ctx = mi.BSDFContext()

    def call(bsdf: Any, v: Any, w: Any) -> Any:
        si = dr.zeros(mi.SurfaceInteraction3f, dr.width(v))
        si.wi = v
        return bsdf.eval(ctx, si, w)

    runners = []
    for p, s in zip(PARAM_SETS.values(), _split(len(wi)), strict=True):
        bsdf = mi.load_dict(principled_dict(p))
        v, w = _vectors(mi, wo[s]), _vectors(mi, wi[s])
        dr.eval(v, w)
        fn = dr.freeze(call) if frozen else call

        def run(fn: Any = fn, bsdf: Any = bsdf, v: Any = v, w: Any = w) -> Any:
            out = fn(bsdf, v, w)
            dr.eval(out)
            dr.sync_thread()
            return out

        runners.append(run)
    return runners


def _all(runners: list[Any]) -> Any:
    return lambda: [r() for r in runners]


def _timed(fn: Any) -> float:
    """CPU seconds of the process (every thread) for ``fn()``: on a shared machine, wall
    time measures the other users' load as much as the code."""
    t0 = time.process_time()
    fn()
    return time.process_time() - t0


DRJIT_MODES = ("prepared", "prepare_each_call", "frozen")
TARGET_FROZEN = 1.5


def run(n: int = 1_000_000, *, repeat: int = 5, progress: Any = None) -> dict[str, Any]:
    """Every figure of the benchmark (see the module docstring).

    The backends are timed in CPU seconds in interleaved rounds (each once per round,
    best of ``repeat`` rounds kept, the Dr.Jit and Mitsuba forms in an order that rotates
    from round to round), so a change in machine load between them skews no ratio;
    the Dr.Jit forms and Mitsuba are timed material by material, so every material's
    ratio is measured too (the totals are the sums of the materials' best times).
    """
    from lookdev.pipeline.variant import use_mitsuba

    variant = use_mitsuba()
    wi, wo = direction_pairs(n)
    runners = {
        "numpy_float32": _numpy_runner(wi, wo, np.float32),
        "numpy_float64": _numpy_runner(wi, wo, np.float64),
        "numpy_every_lobe": _numpy_runner(wi, wo, np.float32, prune=False),
    }
    split = {f"drjit_{m}": _drjit_runner(wi, wo, m) for m in DRJIT_MODES}
    split["mitsuba"] = _mitsuba_runner(wi, wo)
    split["mitsuba_frozen"] = _mitsuba_runner(wi, wo, frozen=True)
    first = {name: _timed(fn) for name, fn in runners.items()}
    first |= {name: _timed(_all(fns)) for name, fns in split.items()}
    for fns in split.values():  # a second call: a frozen function records its replay
        _all(fns)()
    best = dict.fromkeys(runners, math.inf)
    per = {name: [math.inf] * len(PARAM_SETS) for name in split}
    for round_ in range(repeat):
        if progress is not None:
            progress(round_)
        for name, fn in runners.items():
            best[name] = min(best[name], _timed(fn))
        # The forms' order rotates from round to round: the first call after the numpy
        # backends pays ≈ 0.13 ms more, whoever makes it (measured), and no form may
        # always be the one.
        names = list(split)
        names = names[round_ % len(names) :] + names[: round_ % len(names)]
        for k in range(len(PARAM_SETS)):
            for name in names:
                per[name][k] = min(per[name][k], _timed(split[name][k]))
    for name, times in per.items():
        best[name] = sum(times)
    rate = {k: n / v for k, v in best.items()}
    sizes = [s.stop - s.start for s in _split(n)]
    by_material = {
        material: {name: sizes[k] / per[name][k] for name in split}
        | {
            f"ratio_{name}_to_mitsuba": per["mitsuba"][k] / per[name][k]
            for name in split
            if name != "mitsuba"
        }
        | {
            "ratio_drjit_frozen_to_mitsuba_frozen": per["mitsuba_frozen"][k]
            / per["drjit_frozen"][k]
        }
        for k, material in enumerate(PARAM_SETS)
    }
    numpy_dtype = max(("float32", "float64"), key=lambda d: rate[f"numpy_{d}"])
    return {
        "n": n,
        "materials": list(PARAM_SETS),
        "variant": variant,
        "evals_per_s_numpy_float32": rate["numpy_float32"],
        "evals_per_s_numpy_float64": rate["numpy_float64"],
        "evals_per_s_drjit": rate["drjit_prepared"],
        "evals_per_s_drjit_prepare_each_call": rate["drjit_prepare_each_call"],
        "evals_per_s_drjit_frozen": rate["drjit_frozen"],
        "evals_per_s_mitsuba": rate["mitsuba"],
        "evals_per_s_mitsuba_frozen": rate["mitsuba_frozen"],
        "drjit_first_call_s": first["drjit_prepared"],
        "drjit_frozen_first_call_s": first["drjit_frozen"],
        "mitsuba_first_call_s": first["mitsuba"],
        "mitsuba_frozen_first_call_s": first["mitsuba_frozen"],
        "numpy_dtype": numpy_dtype,
        "ratio_drjit_to_mitsuba": rate["drjit_prepared"] / rate["mitsuba"],
        "ratio_drjit_prepare_each_call_to_mitsuba": rate["drjit_prepare_each_call"]
        / rate["mitsuba"],
        "ratio_drjit_frozen_to_mitsuba": rate["drjit_frozen"] / rate["mitsuba"],
        "ratio_drjit_frozen_to_mitsuba_frozen": rate["drjit_frozen"] / rate["mitsuba_frozen"],
        "frozen_max_rel_diff": max(
            _max_rel_diff(_all(split[f"{side}_frozen"]), _all(split[unfrozen]))
            for side, unfrozen in (("drjit", "drjit_prepared"), ("mitsuba", "mitsuba"))
        ),
        "ratio_numpy_to_mitsuba": rate[f"numpy_{numpy_dtype}"] / rate["mitsuba"],
        "evals_per_s_numpy_every_lobe": rate["numpy_every_lobe"],
        "ratio_pruned_to_every_lobe": rate["numpy_float32"] / rate["numpy_every_lobe"],
        "every_lobe_max_abs_diff": _max_diff(runners["numpy_float32"], runners["numpy_every_lobe"]),
        "by_material": by_material,
        "target_drjit": 0.5,
        "target_drjit_frozen": TARGET_FROZEN,
        "target_numpy": 0.1,
    }


def _max_diff(a: Any, b: Any) -> float:
    return float(max(np.max(np.abs(x - y)) for x, y in zip(a(), b(), strict=True)))


def _max_rel_diff(a: Any, b: Any) -> float:
    """:func:`relative_difference` of two Dr.Jit runners' outputs, the largest over the
    materials: a frozen replay must give what the traced call gives."""
    return max(relative_difference(np.array(x), np.array(y)) for x, y in zip(a(), b(), strict=True))
