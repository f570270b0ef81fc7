"""BRDF-explorer views of materials (Burley 2012 §3.2), computed with the numpy backend.

Each view is a pair: a pure function that computes its numbers (tested against
independent computations) and a ``draw_*`` function that puts them on a matplotlib axis.
:func:`figure` lays several blended materials side by side, one column each, labelled;
a material that varies across its surface is wrapped onto the sphere and shown by its
centre texel in the other views.

* ``slice``  — f(θh, θd) at φd = 90° (Burley Fig. 3): θh to the right (left edge = the
  specular peak), θd up (top edge = the Fresnel peak, bottom edge = retro-reflection),
  shown with an exposure control through the proofs' view transform
  (:func:`lookdev.pipeline.proof.tonemap.view`).
* ``albedo`` — directional albedo against incidence angle per channel (Fig. 11/12).
* ``polar``  — f in the plane of incidence for several incidence angles; the light comes
  from the left, the mirror direction is on the right.
* ``sphere`` — a lit sphere under a point light, and under an IBL when one is given.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import matplotlib

__all__ = [
    "ALBEDO_SAMPLES",
    "CHANNEL_COLOURS",
    "MAP_RESOLUTION",
    "OVERLAY_STYLES",
    "POLAR_DECADES",
    "PlotError",
    "VIEWS",
    "albedo_curves",
    "at_uv",
    "brdf_slice",
    "draw_albedo",
    "draw_albedo_overlay",
    "draw_polar",
    "draw_polar_overlay",
    "draw_slice",
    "draw_sphere",
    "figure",
    "incidence_on_slice",
    "load_environment",
    "polar_curves",
    "save_figure",
    "slice_directions",
    "total_curve",
    "varied",
]

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from lookdev.library import files  # noqa: E402
from lookdev.materials.bsdf import Model, evaluate  # noqa: E402
from lookdev.materials.colour import luminance  # noqa: E402
from lookdev.materials.errors import LookdevError, argument  # noqa: E402
from lookdev.pipeline.blend.result import BlendedMaterial  # noqa: E402
from lookdev.pipeline.proof import tonemap  # noqa: E402

from .albedo import albedo_monte_carlo, albedo_tabulated  # noqa: E402
from .sphere import ibl_sphere, point_light_sphere  # noqa: E402

VIEWS = ("slice", "albedo", "polar", "sphere")
CHANNEL_COLOURS = ("#d62728", "#2ca02c", "#1f77b4")


MAP_RESOLUTION = 256
"""Texels a side of a layered material's maps when it is blended for plots."""


class PlotError(LookdevError):
    """A view cannot be made as asked (unknown model, unreadable environment …)."""


def load_environment(name_or_path: str, width: int = 256) -> np.ndarray:
    """A lat-long environment (H, W, 3): a built-in IBL name or an .exr/.hdr file, read
    and resampled by the proof module so the sphere sees what the proofs see."""
    from lookdev.pipeline.proof import ibl

    return ibl.load(name_or_path, width).pixels.astype(np.float64)


# -- slice ---------------------------------------------------------------------------
def slice_directions(
    theta_h: np.ndarray, theta_d: np.ndarray, phi_d: float = math.pi / 2
) -> tuple[np.ndarray, np.ndarray]:
    """(wi, wo) for every (θd, θh) pair, shape (len(θd), len(θh), 3).

    Rusinkiewicz's half/difference parametrisation: the half vector at θh in the x-z
    plane; the difference vector at (θd, φd) in the half vector's frame; wi and wo are
    the difference vector and its mirror image about h, rotated by θh about y.

    >>> wi, wo = slice_directions(np.array([0.0]), np.array([math.pi / 4]))
    >>> (wi[0, 0].round(6) + 0.0).tolist(), (wo[0, 0].round(6) + 0.0).tolist()
    ([0.0, 0.707107, 0.707107], [0.0, -0.707107, 0.707107])
    """
    th, td = np.meshgrid(theta_h, theta_d)
    d = np.stack([np.sin(td) * math.cos(phi_d), np.sin(td) * math.sin(phi_d), np.cos(td)], -1)
    mirrored = d * np.array([-1.0, -1.0, 1.0])

    def rotate_y(v: np.ndarray) -> np.ndarray:
        c, s = np.cos(th), np.sin(th)
        return np.stack(
            [c * v[..., 0] + s * v[..., 2], v[..., 1], -s * v[..., 0] + c * v[..., 2]], -1
        )

    return rotate_y(d), rotate_y(mirrored)


def brdf_slice(model: Model, params: Any, n: int = 128, phi_d: float = math.pi / 2):
    """(θh, θd, f) with f of shape (n, n, 3): row i is θd[i], column j is θh[j] (radians)."""
    theta = (np.arange(n) + 0.5) / n * (math.pi / 2)
    wi, wo = slice_directions(theta, theta, phi_d)
    f = evaluate(model, params, wi, wo)
    below = (wi[..., 2] <= 0) | (wo[..., 2] <= 0)
    return theta, theta, np.where(below[..., None], 0.0, np.nan_to_num(f))


def incidence_on_slice(theta_h: np.ndarray, theta_d: np.ndarray) -> np.ndarray:
    """θl (= θv) in degrees over the φd = 90° slice: cos θl = cos θh cos θd.

    Burley Fig. 3 draws these isolines; diffuse effects tend to follow them.

    >>> float(incidence_on_slice(np.radians(60.0), np.radians(60.0)).round(4))
    75.5225
    """
    return np.degrees(np.arccos(np.cos(theta_h) * np.cos(theta_d)))


def draw_slice(ax: Any, hub: BlendedMaterial, *, exposure: float = 0.0, n: int = 128) -> None:
    th, td, f = brdf_slice(hub.bsdf_model, hub.centre_params, n)
    ax.imshow(tonemap.view(f, exposure), origin="lower", extent=(0, 90, 0, 90))
    deg_h, deg_d = np.meshgrid(np.degrees(th), np.degrees(td))
    lines = ax.contour(
        deg_h,
        deg_d,
        incidence_on_slice(*np.meshgrid(th, td)),
        [30, 60, 80],
        colors="w",
        linewidths=0.6,
        linestyles=":",
        alpha=0.7,
    )
    ax.clabel(lines, fmt="θl %g°", fontsize="xx-small")
    ax.set_xlabel("θh (°)")
    ax.set_ylabel("θd (°)")
    ax.set_xticks([0, 30, 60, 90])
    ax.set_yticks([0, 30, 60, 90])


# -- albedo --------------------------------------------------------------------------
ALBEDO_SAMPLES = 2048


def albedo_curves(hub: BlendedMaterial, n_theta: int = 46) -> list:
    """The albedo curve(s) drawn, 0..89.5°: Monte Carlo, and the shipped table if any.

    The curve is the model's own importance-sampled estimate: unbiased at any roughness,
    where a fixed quadrature grid misses the narrow peaks of glossy lobes (``lookdev
    bench error`` measures by how much).
    """
    theta = np.radians(np.linspace(0.0, 89.5, n_theta))
    mc = albedo_monte_carlo(hub.bsdf_model, hub.centre_params, theta, n_samples=ALBEDO_SAMPLES)
    table = albedo_tabulated(hub.bsdf_model, hub.centre_params, theta)
    return [mc] + ([table] if table is not None else [])


def total_curve(hub: BlendedMaterial, n_theta: int = 46):
    """Reflected plus transmitted albedo, or None for a model that transmits nothing.

    Same seed and samples as the reflected curve, so the two differ exactly by what
    went through the surface. Transmitted radiance is compressed by 1/η² entering a
    denser medium, so clear glass totals 0.04 + 0.96/1.52² ≈ 0.46 here, not 1.
    """
    theta = np.radians(np.linspace(0.0, 89.5, n_theta))
    both = albedo_monte_carlo(
        hub.bsdf_model, hub.centre_params, theta, n_samples=ALBEDO_SAMPLES, hemisphere="both"
    )
    reflect = albedo_monte_carlo(hub.bsdf_model, hub.centre_params, theta, n_samples=ALBEDO_SAMPLES)
    return both if np.any(both.albedo > reflect.albedo) else None


def draw_albedo(ax: Any, hub: BlendedMaterial) -> None:
    mc, *table = albedo_curves(hub)
    total = total_curve(hub)
    deg = np.degrees(mc.theta)
    for c, colour in enumerate(CHANNEL_COLOURS):
        if total is not None:
            ax.plot(
                deg,
                total.albedo[:, c],
                "-.",
                color=colour,
                lw=1,
                label="reflected + transmitted" if c == 0 else None,
            )
        ax.plot(deg, mc.albedo[:, c], color=colour, lw=1.6, label="RGB"[c])
        lo, hi = mc.albedo[:, c] - 2 * mc.stderr[:, c], mc.albedo[:, c] + 2 * mc.stderr[:, c]
        ax.fill_between(deg, lo, hi, color=colour, alpha=0.2, lw=0, label="±2σ" if c == 0 else None)
        if table:
            ax.plot(
                np.degrees(table[0].theta),
                table[0].albedo[:, c],
                "--",
                color=colour,
                lw=1,
                label="table" if c == 0 else None,
            )
    ax.axhline(1.0, color="0.4", ls=":", lw=1)  # above it the material creates energy
    ax.set_xlim(0, 90)
    top = mc.albedo.max() if total is None else max(mc.albedo.max(), total.albedo.max())
    ax.set_ylim(0, max(1.05, float(top) * 1.1))
    ax.set_xlabel("incidence angle θ (°)")
    ax.set_ylabel(f"directional albedo (MC, {ALBEDO_SAMPLES} spp)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize="small", loc="best")


# -- polar ---------------------------------------------------------------------------
def polar_curves(
    model: Model, params: Any, incidence_deg: Sequence[float] = (0, 30, 60, 80), n: int = 361
) -> tuple[np.ndarray, np.ndarray]:
    """θo in (−90°, 90°) and the luminance (working space) of f for each incidence angle, (A, n).

    The light is at −θi in the x-z plane, so the mirror direction is θo = +θi.
    """
    theta_o = np.radians(np.linspace(-89.75, 89.75, n))
    wo = np.stack([np.sin(theta_o), np.zeros_like(theta_o), np.cos(theta_o)], -1)
    rows = []
    for ti in np.radians(np.asarray(incidence_deg, dtype=np.float64)):
        wi = np.array([-math.sin(ti), 0.0, math.cos(ti)])
        rows.append(luminance(np.nan_to_num(evaluate(model, params, wi, wo))))
    return theta_o, np.array(rows)


POLAR_DECADES = 4


def _log_polar_axes(ax: Any, floor: float, *, label_every: int) -> None:
    """The upper half-plane of a polar view, its radius :data:`POLAR_DECADES` decades of f
    above 10^``floor``, every ``label_every``-th decade labelled."""
    ax.set_theta_zero_location("N")
    ax.set_theta_direction(-1)
    ax.set_thetamin(-90)
    ax.set_thetamax(90)
    ax.set_rmax(POLAR_DECADES * 1.02)
    ticks = np.arange(1, POLAR_DECADES + 1)
    ax.set_rticks(ticks)
    labels = [f"{10.0 ** (floor + t):.1g}" if t % label_every == 0 else "" for t in ticks]
    ax.set_yticklabels(labels, fontsize="x-small")


def draw_polar(
    ax: Any, hub: BlendedMaterial, incidence_deg: Sequence[float] = (0, 30, 60, 80)
) -> None:
    """Luminance of f on a logarithmic radius spanning :data:`POLAR_DECADES` decades.

    A glossy peak is thousands of times its surroundings; on a linear radius it would
    flatten every other curve and every diffuse material to a dot.
    """
    theta_o, lum = polar_curves(hub.bsdf_model, hub.centre_params, incidence_deg)
    top = math.log10(max(float(lum.max()), 1e-12))
    floor = top - POLAR_DECADES
    for ti, row in zip(incidence_deg, lum, strict=True):
        r = np.log10(np.maximum(row, 10.0**floor)) - floor
        ax.plot(theta_o, r, lw=1.4, label=f"θi = {ti:g}°")
    _log_polar_axes(ax, floor, label_every=2)
    ax.text(
        0.5,
        -0.02,
        "f, luminance (log radius)",
        transform=ax.transAxes,
        ha="center",
        va="top",
        fontsize="x-small",
    )
    ax.legend(fontsize="x-small", loc="upper left", bbox_to_anchor=(-0.12, 1.12))


# -- overlays: several materials on one axes (a measurement beside its fit) --------------
OVERLAY_STYLES = ("-", "--", ":", "-.")


def draw_albedo_overlay(ax: Any, hubs: Sequence[BlendedMaterial]) -> None:
    """Each material's albedo per channel on one axes, a line style per material."""
    for hub, style in zip(hubs, itertools.cycle(OVERLAY_STYLES), strict=False):
        mc = albedo_curves(hub)[0]
        for c, colour in enumerate(CHANNEL_COLOURS):
            label = hub.name if c == 0 else None
            ax.plot(np.degrees(mc.theta), mc.albedo[:, c], style, color=colour, lw=1.4, label=label)
    ax.axhline(1.0, color="0.4", ls=":", lw=1)
    ax.set_xlim(0, 90)
    ax.set_ylim(0, 1.05)
    ax.set_xlabel("incidence angle θ (°)")
    ax.set_ylabel(f"directional albedo R, G, B (MC, {ALBEDO_SAMPLES} spp)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize="small", loc="best")


def draw_polar_overlay(
    ax: Any, hubs: Sequence[BlendedMaterial], incidence_deg: Sequence[float] = (0, 30, 60)
) -> None:
    """Each material's polar curves on one log radius, a colour per incidence angle and a
    line style per material."""
    curves = [polar_curves(h.bsdf_model, h.centre_params, incidence_deg) for h in hubs]
    top = math.log10(max(max(float(lum.max()) for _, lum in curves), 1e-12))
    floor = top - POLAR_DECADES
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for hub, (theta_o, lum), style in zip(
        hubs, curves, itertools.cycle(OVERLAY_STYLES), strict=False
    ):
        for k, (ti, row) in enumerate(zip(incidence_deg, lum, strict=True)):
            r = np.log10(np.maximum(row, 10.0**floor)) - floor
            ax.plot(theta_o, r, style, color=colours[k], lw=1.3, label=f"{hub.name}, θi = {ti:g}°")
    _log_polar_axes(ax, floor, label_every=1)
    ax.legend(fontsize="xx-small", loc="upper left", bbox_to_anchor=(-0.25, 1.15))


# -- sphere --------------------------------------------------------------------------
def draw_sphere(ax: Any, image: np.ndarray, exposure: float, title: str) -> None:
    ax.imshow(tonemap.view(image, exposure))
    ax.set_axis_off()
    ax.set_title(title, fontsize="small")


# -- one parameter varied -------------------------------------------------------------
def varied(hubs: Sequence[BlendedMaterial], field: str, values: Sequence[float]) -> list:
    """Each uniform material once per value of one parameter, side by side (the columns
    of ``lookdev plot --vary specular_gamma=1,1.5,2,3``): how one knob reshapes a lobe.
    A switch takes 0 and 1 (``--vary energy_compensation=off,on``)."""
    out = []
    for hub in hubs:
        if hub.maps or hub.normal_map is not None:
            raise PlotError(
                f"{hub.name} varies across its surface; {argument('vary')} takes uniform presets"
            )
        if field not in type(hub.params).model_fields:
            known = ", ".join(type(hub.params).model_fields)
            raise PlotError(
                f"{hub.name} has no parameter {field!r}; known: {known}", field=argument("vary")
            )
        switch = type(hub.params).model_fields[field].annotation is bool
        for value in values:
            # a switch (``energy_compensation``) takes 0/1 and is labelled off/on
            v = bool(value) if switch else value
            label = ("on" if v else "off") if switch else f"{value:g}"
            try:
                params = hub.params.replace(**{field: v})
            except LookdevError as exc:
                raise PlotError(str(exc), where=hub.name, field=argument("vary")) from None
            out.append(BlendedMaterial.of_params(params, name=f"{hub.name} {field}={label}"))
    return out


# -- figure --------------------------------------------------------------------------
def at_uv(hub: BlendedMaterial, uv: tuple[float, float]) -> BlendedMaterial:
    """``hub`` as the uniform material it is at ``uv`` (every plot then shows that texel);
    a layered Pixar hub (lobe weights, not parameters) keeps its maps."""
    if not hub.maps or hub.representation != "params":
        return hub
    u, v = uv
    return BlendedMaterial.of_params(hub.params_at_uv(u, v), name=f"{hub.name} @ uv ({u:g}, {v:g})")


def figure(
    hubs: Sequence[BlendedMaterial],
    view: str,
    *,
    exposure: float = 0.0,
    environment: np.ndarray | None = None,
    ibl_name: str = "IBL",
    resolution: int = 128,
    overlay: bool = False,
):
    """A matplotlib figure of one view for several materials side by side, or (albedo and
    polar with ``overlay``) drawn over each other on one axes."""
    if view not in VIEWS:
        raise ValueError(f"view must be one of {', '.join(VIEWS)}")
    if overlay and view in ("albedo", "polar"):
        fig = plt.figure(figsize=(6.4, 4.6), layout="constrained")
        ax = fig.add_subplot(1, 1, 1, projection="polar" if view == "polar" else None)
        (draw_polar_overlay if view == "polar" else draw_albedo_overlay)(ax, hubs)
        fig.suptitle(f"{view}: " + " vs ".join(h.name for h in hubs), fontsize="medium")
        return fig
    cols = len(hubs)
    rows = 2 if view == "sphere" and environment is not None else 1
    polar = view == "polar"
    fig = plt.figure(figsize=(3.6 * cols, 3.4 * rows + 0.6), layout="constrained")
    for i, hub in enumerate(hubs):
        if view == "sphere":
            img = point_light_sphere(
                hub.bsdf_model, hub.centre_params, resolution=resolution, maps=(hub.maps or None)
            )
            ax = fig.add_subplot(rows, cols, i + 1)
            draw_sphere(ax, img, exposure, f"{hub.name}\npoint light")
            if environment is not None:
                img = ibl_sphere(
                    hub.bsdf_model,
                    hub.centre_params,
                    environment,
                    resolution=min(resolution, 96),
                    maps=(hub.maps or None),
                )
                ax = fig.add_subplot(rows, cols, cols + i + 1)
                draw_sphere(ax, img, exposure, f"{hub.name}\n{ibl_name}")
            continue
        ax = fig.add_subplot(1, cols, i + 1, projection="polar" if polar else None)
        if view == "slice":
            draw_slice(ax, hub, exposure=exposure, n=resolution)
        elif view == "albedo":
            draw_albedo(ax, hub)
        else:
            draw_polar(ax, hub)
        ax.set_title(hub.name + ("\n(centre texel)" if (hub.maps or None) else ""))
    suffix = f", exposure {exposure:+g}" if view in ("slice", "sphere") else ""
    fig.suptitle(f"{view}{suffix}", fontsize="medium")
    return fig


def save_figure(fig: Any, path: str | Path) -> Path:
    """Write the figure atomically (temporary file, then rename) and close it."""
    path = Path(path)
    files.make_folder(path.parent)
    try:
        with files.atomic_path(path) as tmp:
            fig.savefig(tmp, dpi=110)
    finally:
        plt.close(fig)
    return path
