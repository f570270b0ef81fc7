"""``lookdev bench glass`` (registered in :mod:`.bench`; the measuring is
:mod:`lookdev.pipeline.bench.glass`)."""

from __future__ import annotations

from typing import Annotated

import typer

from lookdev.pipeline.bench import glass

from .common import JsonOut, console, print_json, table
from .render_options import Ibl, Resolution, Spp, check_resolution, rendered

__all__ = ["glass_"]


def glass_(
    presets: Annotated[
        list[str] | None,
        typer.Argument(help="Glass presets to measure (default: every built-in glass)."),
    ] = None,
    ibl: Ibl = "sky",
    spp: Spp = 16,
    reference_spp: Annotated[
        int,
        typer.Option(
            "--reference-spp", min=4, help="Samples of each reference (relMSE denominator)."
        ),
    ] = 256,
    resolution: Resolution = (128, 64),
    repeat: Annotated[
        int, typer.Option("--repeat", min=1, help="Seeds (interleaved rounds).")
    ] = 24,
    as_json: JsonOut = False,
) -> None:
    """Cost of our glass at equal noise against Mitsuba's dielectric / roughdielectric.

    Per preset: the relMSE of a SPP frame (variance over REPEAT seeds), times its CPU
    time, ours over the built-in's (target ≤ 1.5), in interleaved rounds; the noise
    ratio's 90 % bootstrap interval and the difference of the mean luminances (± its
    standard error) beside it.

    Example:

      lookdev bench glass glass_clear glass_frosted --spp 16 --json
    """
    check_resolution(resolution, glass.BenchGlassError)
    settings = glass.Settings(
        presets=tuple(presets or glass.DEFAULT_PRESETS),
        ibl=ibl,
        spp=spp,
        reference_spp=reference_spp,
        resolution=resolution,
        repeat=repeat,
    )
    result = rendered(glass.run, settings, as_json)
    if as_json:
        print_json(result)
        return
    columns = ["preset", "built-in", "relMSE ours", "relMSE built-in", "noise ratio (90 %)"]
    columns += ["CPU s ours", "CPU s built-in", "time ratio", "cost ratio", "Δ mean", "target"]

    def interval(r: dict) -> str:
        ci = r["noise_ratio_interval"]
        return f"{r['noise_ratio']:.2f}" + (f" ({ci[0]:.2f}–{ci[1]:.2f})" if ci else "")

    rows = [
        [
            r["preset"],
            r["builtin"],
            f"{r['ours_relmse']:.3g}",
            f"{r['builtin_relmse']:.3g}",
            interval(r),
            f"{r['ours_seconds']:.3g}",
            f"{r['builtin_seconds']:.3g}",
            f"{r['time_ratio']:.2f}",
            f"{r['ratio']:.2f}",
            f"{100 * r['reference_difference']:+.1f} ± {100 * r['reference_difference_se']:.1f} %",
            "met" if r["met"] else "missed",
        ]
        for r in result["presets"]
    ]
    title = f"glass cost at equal noise ({spp} spp, {ibl}, ≤ {glass.TARGET:g}×)"
    console.print(table(title, columns, rows))
