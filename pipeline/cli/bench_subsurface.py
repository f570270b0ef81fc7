"""``lookdev bench subsurface`` (registered in :mod:`.bench`; the measuring is
:mod:`lookdev.pipeline.bench.subsurface`)."""

from __future__ import annotations

from typing import Annotated

import typer

from lookdev.pipeline.bench import subsurface

from .common import JsonOut, console, print_json, table

__all__ = ["subsurface_"]


def subsurface_(
    spp: Annotated[int, typer.Option("--spp", "-s", min=4, help="Samples per pixel.")] = 64,
    as_json: JsonOut = False,
) -> None:
    """Path-traced subsurface: thick-slab reflectance against the base colour (three
    colours), the white furnace, the cup rim's glow under back light, and the proof's
    cost against the same preset without a scatter distance (equal spp, equal noise)."""
    with console.status("rendering slabs, furnace, rims and proofs", spinner="dots"):
        r = subsurface.run(spp=spp)
    if as_json:
        print_json(r)
        return
    rows = [[k, *v["base"], *v["error"], max(v["standard_error"])] for k, v in r["slab"].items()]
    cols = ["slab", "R", "G", "B", "ΔR", "ΔG", "ΔB", "± (1σ)"]
    console.print(table(f"thick slab ({r['mapping']})", cols, rows))
    f = r["furnace"]
    console.print(f"white furnace, roughness 0: {f['mean']:.4f} ± {f['standard_error']:.4f} (≤ 1)")
    f = r["furnace_rough"]
    console.print(
        f"white furnace, roughness 0.5: {f['with']:.4f}, without a distance {f['without']:.4f}"
        " (Burley's retro-reflection adds energy by design)"
    )
    rows = [[k, v["with"], v["without"], v["ratio"]] for k, v in r["rim"].items()]
    console.print(table("cup rim under back light", ["preset", "with", "without", "×"], rows))
    rows = [[k, v["time_ratio"], v["equal_noise_ratio"]] for k, v in r["cost"].items()]
    cols = ["preset", "× time, equal spp", "× time, equal noise"]
    console.print(table("proof cost against no distance", cols, rows))
