"""``lookdev check``: the stability report of every reflectance model (CI runs it)."""

from __future__ import annotations

from typing import Annotated

import typer
from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn

from lookdev.materials import registry
from lookdev.pipeline.analysis import stability

from .common import console, err_console, print_json, table

__all__ = ["COLUMNS", "check"]

COLUMNS = ["precision", "cases", "raised", "NaN", "inf", "negative", "energy gain"]


_MODEL_HELP = f"Only this model (repeatable): {', '.join(registry.MODELS)}."


def check(
    models: Annotated[
        list[str] | None,
        typer.Option("--model", "-m", metavar="NAME", help=_MODEL_HELP, show_default=False),
    ] = None,
    json_out: Annotated[
        bool, typer.Option("--json", help="Print one JSON object, for scripts.")
    ] = False,
) -> None:
    """Sweep every model over its stiff and extreme cases, in float32 and float64.

    Models: disney, sheen, pixar (one not built yet is skipped).
    Parameters: each at both ends of its range, and the named stiff combinations.
    Directions: normal, cos θ = 0.5, 1e-4, 1e-7, 0, below, wi = −wo, mirror.
    Uniforms: 0, ½ and 1 − 2⁻²⁴ in every sampling dimension, and random.

    Counts outputs (f, pdf, samples) with a NaN, an infinity or a negative
    value, and white-furnace albedos above 1 + the model's allowance
    (Disney adds energy by design: 0.79, measured; sheen 0.002; pixar 0).
    Furnace views: θo up to 89.99° at azimuths 0, 45, 90° (tangent to bitangent).

    Exit code 0 when nothing was found, 1 when anything was.
    """
    from lookdev.pipeline import api

    with Progress(
        TextColumn("[bold]{task.fields[model]}"),
        BarColumn(),
        MofNCompleteColumn(),
        TextColumn("{task.fields[case]}"),
        console=err_console,
        transient=True,
        disable=json_out or not err_console.is_terminal,
    ) as bar:
        task = bar.add_task("check", total=None, model="", case="")

        def advance(done: int, total: int, name: str, label: str) -> None:
            bar.update(task, completed=done, total=total, model=name, case=label)

        result = api.check(models, progress=advance)
    if json_out:
        print_json(result.to_json())
    else:
        _print(result.reports, result.seconds)
    if result.failed:
        raise typer.Exit(1)


def _print(reports: dict[str, stability.ModelReport], seconds: float):
    for name, r in reports.items():
        rows = [
            [dtype, r.cases_by_dtype[dtype], *(c[k] for k in stability.KINDS)]
            for dtype, c in r.by_dtype.items()
        ]
        rows.append(["total", r.cases, *(r.counts[k] for k in stability.KINDS)])
        status = "[red]FAILED[/red]" if r.failed else "[green]ok[/green]"
        t = table(f"{name}: {status} (energy allowance {r.allowance:g})", COLUMNS, rows)
        worst = r.worst
        if worst is not None:
            label = "worst" if r.failed else "highest albedo"
            value = f" = {worst.value:.4g}" if worst.value is not None else ""
            t.caption = f"{label}: {worst.kind}{value} at {worst.case}"
            if r.max_albedo_by_azimuth:
                per_phi = ", ".join(
                    f"φo {phi:g}° {f.value:.4g}"
                    for phi, f in sorted(r.max_albedo_by_azimuth.items())
                )
                t.caption += f"\nhighest albedo by azimuth: {per_phi}"
            t.caption_justify = "left"
        console.print(t)
    console.print(f"checked in {seconds:.1f} s", style="dim")
