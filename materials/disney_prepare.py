"""Disney BSDF parameters → what its lobes need: colours, α, lobe weights, sampling odds.

The first half of :mod:`.disney` (which holds the lobes, ``eval``/``pdf``/``sample`` and
the published :data:`~.disney.MODEL`); see there for the lobes and the sources followed.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import Any

from . import energy
from . import fresnel as fr
from . import microfacet as mf
from .bsdf import Lobe, Prepared
from .fresnel import SPECULAR_F0_SCALE
from .params import DisneyParams

__all__ = [
    "CLEARCOAT_F0",
    "DISNEY_LOBES",
    "DisneyPrepared",
    "ETA_MIN",
    "INV_PI",
    "LOBES",
    "SCHLICK_MEAN",
    "SHEEN_ALBEDO_GUESS",
    "TINT_WEIGHTS",
    "lobe_odds",
    "luminance",
    "mix",
    "prepare",
    "tint_color",
    "with_odds",
]

INV_PI = 1.0 / math.pi
TINT_WEIGHTS = (0.3, 0.6, 0.1)
"""Burley's tint luminance, from the Disney BRDF Explorer's ``disney.brdf``:
``float Cdlum = .3*Cdlin[0] + .6*Cdlin[1] + .1*Cdlin[2]; // luminance approx.``
(Schutte's seed prints (0.3, 0.6, 1.0): a typo). Part of the model, a rough hue normaliser;
not luminance Y (:func:`lookdev.materials.colour.luminance`, the working space's XYZ row), which
measures pixels."""
CLEARCOAT_F0 = 0.04  # IOR 1.5 polyurethane (Burley §5.4)
SCHLICK_MEAN = 1.0 / 21.0  # ∫ (1 − μ)⁵ 2μ dμ: hemispherical mean of the Schlick weight
SHEEN_ALBEDO_GUESS = 0.1  # rough albedo of sheen 1, only used to weight sampling
ETA_MIN = 1.001  # as Mitsuba: at η = 1 the rough BTDF becomes a delta
DISNEY_LOBES = (
    Lobe("diffuse", "diffuse", params=("subsurface", "flatness")),
    # A solid's scatter distance turns this lobe on too: it is the entry into the medium.
    Lobe(
        "diff_trans",
        "diffuse",
        True,
        params=("diff_trans", "scatter_distance", "scatter_distance_scale"),
        switches=("diff_trans", "scatter_distance"),
    ),
    Lobe(
        "sheen",
        "glossy",
        params=("sheen", "sheen_tint", "sheen_model", "sheen_roughness", "sheen_lambda"),
        switches=("sheen",),
        reciprocal=False,  # with sheen_model = "conty_kulla": its terminator softening
    ),
    Lobe(
        "specular",
        "glossy",
        highlight=True,
        params=("specular_gamma", "energy_compensation"),
        reciprocal_unless=("energy_compensation",),  # Turquin's factor is read at the view
    ),
    Lobe(
        "clearcoat",
        "glossy",
        highlight=True,
        params=("clearcoat", "clearcoat_gloss"),
        switches=("clearcoat",),
    ),
    Lobe(
        "spec_trans",
        "glossy",
        transmits=True,
        highlight=True,
        params=("spec_trans",),
        switches=("spec_trans",),
    ),
)
"""Burley 2012 §5 and Schutte 2018 §3; weights in :func:`prepare` (``weights``)."""
LOBES = tuple(lobe.name for lobe in DISNEY_LOBES)


@dataclass(frozen=True, kw_only=True)
class DisneyPrepared(Prepared):
    """What the Disney lobes read (:func:`prepare`); colours channel-first. ``eta`` is
    the relative IOR of the interface (Burley 2015 §5.4), ``delta`` its smooth lobes."""

    thin: bool
    """A thin sheet (Burley 2015 §4.2): no interior, transmission leaves at once."""
    base: Any
    """``base_color``."""
    roughness: Any
    """Burley's perceptual roughness r (α = r²)."""
    ax: Any
    """Specular GGX αx (Burley 2012 App. B, with anisotropy)."""
    ay: Any
    """Specular GGX αy."""
    ax2: Any
    """αx²."""
    ay2: Any
    """αy²."""
    a2: Any
    """αx αy: the α² of the isotropic GTR used when γ ≠ 2 (App. B eq. 1)."""
    gamma: Any
    """The specular GTR exponent γ (2 is GGX)."""
    ggx: bool
    """γ is the constant 2: anisotropic GGX with visible-normal sampling."""
    tax: Any
    """Transmission αx (rougher for a thin sheet, Burley 2015 Fig. 15)."""
    tay: Any
    """Transmission αy."""
    tax2: Any
    """Transmission αx²."""
    tay2: Any
    """Transmission αy²."""
    spec_a: Any
    """Colour A of the front Fresnel A + (B − A)(1 − cos θd)⁵ + c·F (:func:`_fresnel_terms`)."""
    spec_b: Any
    """Scalar B of that blend (its value at grazing)."""
    spec_c: Any
    """Weight c of the exact dielectric Fresnel in it."""
    spec_lum_a: Any
    """Burley's tint luminance of A."""
    energy: bool
    """Turquin 2019 multiple-scattering compensation of the specular (:mod:`.energy`)."""
    energy_r: Any = None
    """The roughness the compensation's albedo table is read at; None without it."""
    energy_f0: Any = None
    """The specular's F0 seen from outside, for the compensation; None without it."""
    glass: Any
    """Specular transmission weight (1 − metallic)·spec_trans (Burley 2015 §3)."""
    diffuse: Any
    """Diffuse reflection weight."""
    diff_trans: Any
    """Diffuse transmission weight (Burley 2015 §4.2; a solid's entry into its medium)."""
    volume: bool
    """A solid with a scatter distance: an interior medium gives the colour (§4)."""
    trans_color: Any
    """Colour of the transmission: √base thin, white into a medium, else base."""
    sheen: Any
    """Sheen weight (1 − metallic)(1 − spec_trans)·sheen."""
    sheen_color: Any
    """mix(1, tint, sheen_tint) (Burley 2012 §5.3)."""
    sheen_model: str
    """``"burley"`` or ``"conty_kulla"`` (:mod:`.sheen`)."""
    sheen_r: Any
    """Conty–Kulla sheen roughness."""
    sheen_exact: bool
    """Conty–Kulla's Λ from the exact table, not the fit."""
    clearcoat: Any
    """Clearcoat weight 0.25·clearcoat (Burley 2012 §5.4)."""
    clearcoat_a2: Any
    """GTR1 α² of the coat, mix(0.1, 0.001, clearcoat_gloss)²."""
    subsurface: Any
    """Hanrahan–Krueger blend of the diffuse (0 with an interior medium)."""
    flatness: Any
    """A thin sheet's diffuse flattening (0 for a solid)."""
    odds: dict[str, Any] = field(default_factory=dict)
    """Probability of sampling each kept lobe, viewer outside (:func:`lobe_odds`)."""
    odds_inside: dict[str, Any] = field(default_factory=dict)
    """The same for a viewer inside a solid."""


# -- parameters --------------------------------------------------------------------------
def luminance(c: Any) -> Any:
    """Burley's tint luminance of a channel-first colour (:data:`TINT_WEIGHTS`)."""
    return TINT_WEIGHTS[0] * c[0] + TINT_WEIGHTS[1] * c[1] + TINT_WEIGHTS[2] * c[2]


def tint_color(xp: Any, base: Any) -> Any:
    """Base colour over its luminance (hue and saturation only); white for black."""
    lum = luminance(base)
    if isinstance(lum, float):
        return base / lum if lum > 0 else xp.color((1.0, 1.0, 1.0))
    return xp.select(lum > 0.0, base / xp.select(lum > 0.0, lum, 1.0), 1.0)


def mix(a: Any, b: Any, t: Any) -> Any:
    return a + (b - a) * t


def _eta(xp: Any, params: DisneyParams, maps: dict[str, Any]) -> Any:
    """Relative IOR: ``ior`` or the IOR whose F0 is 0.08·specular (Burley §5.4)."""
    if "ior" in maps:
        return xp.scalar(maps["ior"])
    if "specular" in maps and not params.uses_ior:
        return fr.specular_to_ior(xp.scalar(maps["specular"]), xp)
    return params.effective_ior


def _fresnel_terms(xp, p, base, tint, w_d, w_g, eta) -> tuple[Any, Any, Any]:
    """(A, B, c) with F_front(θd) = A + (B − A)(1 − cos θd)⁵ + c · F_dielectric(θd, η).

    Schlick is linear in F0, so the metal, the tinted dielectric and the glass reflection
    collapse into one colour A, one scalar B and one exact-Fresnel weight c:

    * ``specular`` given: the BRDF Explorer's Schlick with F0 = mix(0.08·specular·
      mix(1, tint, specular_tint), base, metallic) on the BRDF part (weight 1 − w_g);
    * ``ior`` given: the 2015 dielectric Fresnel, tinted like Mitsuba's ``principled``
      (Schutte's DisneyFresnel drops specular_tint unless metallic > 0);
    * the glass part w_g always reflects the exact dielectric Fresnel.
    """
    metallic, spec_tint = p["metallic"], p["specular_tint"]
    tinted = mix(1.0, tint, spec_tint)
    if p["uses_ior"]:
        a = metallic * base + w_d * spec_tint * fr.ior_to_f0(eta) * tint
        b = metallic + w_d * spec_tint
        return a, b, w_d * (1.0 - spec_tint) + w_g
    a = metallic * base + w_d * (SPECULAR_F0_SCALE * p["specular"]) * tinted
    return a, metallic + w_d, w_g


def prepare(xp: Any, params: DisneyParams, **maps: Any) -> DisneyPrepared:
    """Derived colours, α, lobe weights, which lobes exist, and their sampling odds."""
    names = (
        "subsurface metallic specular specular_tint roughness anisotropic sheen sheen_tint "
        "sheen_roughness clearcoat clearcoat_gloss spec_trans diff_trans flatness"
    ).split()
    p = {n: xp.scalar(maps.get(n, getattr(params, n))) for n in names}
    p["uses_ior"] = params.uses_ior
    thin = params.thin
    base = xp.color(maps.get("base_color", params.base_color))
    tint = tint_color(xp, base)
    eta = _eta(xp, params, maps)
    eta = max(eta, ETA_MIN) if isinstance(eta, float) else xp.maximum(eta, ETA_MIN)
    w_d = (1.0 - p["metallic"]) * (1.0 - p["spec_trans"])
    w_g = (1.0 - p["metallic"]) * p["spec_trans"]
    a, b, c = _fresnel_terms(xp, p, base, tint, w_d, w_g, eta)
    # Burley 2015: a solid with a scatter distance has an interior medium
    # (:mod:`.subsurface`) that gives the colour; its diffuse's Lambertian part and its
    # glass lead into it untinted, and only the retro-reflection stays on the surface.
    volume = not thin and params.scatter_distance > 0.0
    trans_color = xp.sqrt(base) if thin else (xp.color((1.0, 1.0, 1.0)) if volume else base)
    diffuse, diff_trans = w_d * (1.0 - p["diff_trans"]), w_d * p["diff_trans"]
    if volume:
        diffuse, diff_trans = (w_d if _rough(p["roughness"]) else 0.0), w_d
    ax, ay = mf.anisotropic_alphas(xp, p["roughness"], p["anisotropic"])
    # The GTR shape of the specular lobe: 2 keeps the anisotropic GGX and visible-normal
    # sampling; any other γ is the isotropic GTR of App. B (eq. 1) with α² = αx αy.
    # A per-element γ (a blend of layers with different γ) takes the GTR path throughout.
    gamma = maps.get("specular_gamma", params.specular_gamma)
    ggx = isinstance(gamma, int | float) and gamma == 2.0
    # Turquin 2019 multiple-scattering factor of the specular lobe (:mod:`.energy`).
    compensated = energy.compensated(params, ggx)
    r_t = p["roughness"]
    if thin:
        # Burley 2015 Fig. 15 via Schutte: a thin sheet's transmission looks rougher.
        r_t = (0.65 * eta - 0.35) * p["roughness"]
        r_t = min(r_t, 1.0) if isinstance(r_t, float) else xp.minimum(r_t, 1.0)
        tax, tay = mf.anisotropic_alphas(xp, r_t, p["anisotropic"])
    else:
        tax, tay = ax, ay
    # Lobes whose α is below ALPHA_MIN are deltas (microfacet.is_delta, disney_interface).
    delta = tuple(
        k
        for k, r in (("specular", p["roughness"]), ("spec_trans", r_t))
        if mf.is_delta(r, p["anisotropic"]) and (k != "specular" or ggx)
    )  # GTR's tails (γ < 2) carry visible energy at any α: γ ≠ 2 stays glossy, as the coat
    sheen, clearcoat = w_d * p["sheen"], 0.25 * p["clearcoat"]
    weights = {
        "diffuse": diffuse,
        "diff_trans": diff_trans,
        "sheen": sheen,
        "specular": 1.0,
        "clearcoat": clearcoat,
        "spec_trans": w_g,
    }
    pr = DisneyPrepared(
        lobes=tuple(k for k in LOBES if not xp.known_zero(weights[k])),
        delta=delta,
        eta=eta,
        thin=thin,
        base=base,
        roughness=p["roughness"],
        ax=ax,
        ay=ay,
        ax2=ax * ax,
        ay2=ay * ay,
        a2=ax * ay,
        gamma=float(gamma) if isinstance(gamma, int | float) else xp.scalar(gamma),
        ggx=ggx,
        tax=tax,
        tay=tay,
        tax2=tax * tax,
        tay2=tay * tay,
        spec_a=a,
        spec_b=b,
        spec_c=c,
        spec_lum_a=luminance(a),
        energy=compensated,
        energy_r=energy.table_roughness(xp, ax, ay) if compensated else None,
        energy_f0=energy.f0_of(xp, a, c, eta) if compensated else None,
        glass=w_g,
        diffuse=diffuse,
        diff_trans=diff_trans,
        volume=volume,
        trans_color=trans_color,
        sheen=sheen,
        sheen_color=mix(1.0, tint, p["sheen_tint"]),
        sheen_model=params.sheen_model,
        sheen_r=p["sheen_roughness"],
        sheen_exact=params.sheen_lambda == "exact",
        clearcoat=clearcoat,
        clearcoat_a2=_sq(mix(0.1, 0.001, p["clearcoat_gloss"])),  # Burley §5.4 / App. B
        subsurface=0.0 if volume else p["subsurface"],
        flatness=p["flatness"] if thin else 0.0,
    )
    return with_odds(xp, pr)


def with_odds(xp: Any, pr: DisneyPrepared, lobes: tuple[str, ...] | None = None):
    """``pr`` (restricted to ``lobes`` if given) with its sampling odds for its lobes."""
    if lobes is not None:
        pr = replace(pr, lobes=lobes)
    odds, odds_inside = lobe_odds(xp, pr)
    return replace(pr, odds=odds, odds_inside=odds_inside)


def _rough(roughness: Any) -> bool:
    """False where the retro-reflection is a known zero (roughness 0 exactly)."""
    return not (isinstance(roughness, float) and roughness == 0.0)


def _sq(x: Any) -> Any:
    return x * x


def lobe_odds(xp: Any, pr: DisneyPrepared) -> tuple[dict[str, Any], dict[str, Any]]:
    """Selection probabilities ∝ estimated albedo, for a viewer outside and (solid) inside.

    Estimates: diffuse ρ·lum(base), Schlick lobes F0 + (1 − F0)/21, glass 1 − F0 split
    by 1/η² inside. Sheen is sampled like the diffuse, by the cosine.
    """
    f0 = fr.ior_to_f0(pr.eta)
    lum_a = luminance(pr.spec_a)
    lum_t = luminance(pr.trans_color)
    est = {
        "diffuse": pr.diffuse * luminance(pr.base),
        "sheen": pr.sheen * luminance(pr.sheen_color) * SHEEN_ALBEDO_GUESS,
        "diff_trans": pr.diff_trans * lum_t,
        "specular": lum_a
        + (pr.spec_b - lum_a) * SCHLICK_MEAN
        + pr.spec_c * (f0 + (1.0 - f0) * SCHLICK_MEAN),
        "clearcoat": pr.clearcoat * (CLEARCOAT_F0 + (1.0 - CLEARCOAT_F0) * SCHLICK_MEAN),
        "spec_trans": pr.glass * lum_t * (1.0 - f0),
    }
    inside = {k: 0.0 for k in est}
    if not pr.thin:
        escape = (1.0 - f0) / (pr.eta * pr.eta)
        inside.update(
            diff_trans=est["diff_trans"],
            specular=pr.glass * (1.0 - escape),
            spec_trans=pr.glass * lum_t * escape,
        )
    return _normalise(xp, est, pr.lobes), _normalise(xp, inside, pr.lobes)


def _normalise(xp: Any, est: dict[str, Any], lobes: tuple[str, ...]) -> dict[str, Any]:
    keep = [k for k in lobes if k in est]
    total = sum(est[k] for k in keep)
    if isinstance(total, float):
        return {k: (est[k] / total if total > 0 else 0.0) for k in keep}
    safe = xp.select(total > 0.0, total, 1.0)
    return {k: est[k] / safe for k in keep}
