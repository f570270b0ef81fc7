"""``lookdev bench noise`` (registered in :mod:`.bench`; the measuring is
:mod:`lookdev.pipeline.bench.noise`)."""

from __future__ import annotations

from typing import Annotated

import typer

from lookdev.pipeline.bench import noise

from .common import JsonOut, console, print_json, table

__all__ = ["noise_"]


def noise_(
    presets: Annotated[
        list[str] | None,
        typer.Argument(help="Presets (default: gold, plastic_glossy, glass_clear)."),
    ] = None,
    ibls: Annotated[
        list[str] | None,
        typer.Option("--ibl", "-i", help="IBLs, repeatable (default: sky, sunset)."),
    ] = None,
    quick: Annotated[bool, typer.Option("--quick", help="Tiny frames (CI, tests).")] = False,
    as_json: JsonOut = False,
) -> None:
    """Rendering to a noise target: pixel-filter cost, noise per pass, defaults new/old.

    For each PRESET under each --ibl: a proof frame at 480×240 rendered in passes of 4
    spp up to 16, with its estimated relative noise, firefly share and time after each
    pass; for each candidate (target, cap), where frames stop and the main job's time
    against the old default (192×96, 32 spp, Gaussian filter), loaded and rendered
    interleaved in the same run. Also a Gaussian pixel filter's cost over a box.
    """
    given = {k: tuple(v) for k, v in (("presets", presets), ("ibls", ibls)) if v}
    s = noise.Settings.quick(**given) if quick else noise.Settings(**given)
    with console.status("rendering to noise targets", spinner="dots"):
        report = noise.run(s)
    if as_json:
        print_json(report)
        return
    rows = [
        [f"{r['preset']} × {r['ibl']}", r["gaussian_over_box_wall"], r["gaussian_over_box_cpu"]]
        for r in report["filter"]
    ]
    console.print(table("Gaussian pixel filter / box", ["frame", "wall", "CPU"], rows))
    pc = report["pass_cost"]
    console.print(
        f"{pc['spp'] // pc['pass_spp']} passes of {pc['pass_spp']} spp / one of {pc['spp']}: "
        f"wall {pc['passes_over_one_wall']:.3g}, CPU {pc['passes_over_one_cpu']:.3g}",
        highlight=False,
    )
    rows = [
        [f"{r['preset']} × {r['ibl']}", p["spp"], p["noise"], p["firefly_share"], p["cpu_s"]]
        for r in report["traces"]
        for p in r["trace"]
    ]
    columns = ["frame", "spp", "noise", "firefly share", "CPU s"]
    console.print(table(f"passes at {s.resolution[0]}×{s.resolution[1]}", columns, rows))
    rows = [
        [c["target"], c["max_spp"], f"{c['met']}/{c['jobs']}", c["mean_spp"],
         c["new_over_old_wall"], c["new_over_old_cpu"]]
        for c in report["candidates"]
    ]  # fmt: skip
    columns = ["target", "max spp", "met", "mean spp", "main job new/old wall", "CPU"]
    console.print(table("candidate defaults", columns, rows))
    console.print(f"load average {report['load_average']}", highlight=False)
