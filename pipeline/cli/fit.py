"""``lookdev fit``: a preset fitted to a measured BRDF (MBSDF or MERL)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from .common import console, print_json

__all__ = ["fit"]


def fit(
    measured: Annotated[
        Path, typer.Argument(help="The measurement: an .mbsdf or a MERL .binary file.")
    ],
    output: Annotated[
        Path,
        typer.Option("--output", "-o", help="The preset file to write (its stem is its name)."),
    ],
    model: Annotated[
        str, typer.Option("--model", "-m", help="The model to fit: disney or pixar.")
    ] = "disney",
    start: Annotated[
        str | None,
        typer.Option("--from", help="A preset (name or file) to start from.", show_default=False),
    ] = None,
    fix: Annotated[
        list[str] | None,
        typer.Option(
            "--fix", metavar="NAME=VALUE", help="Hold a parameter (repeatable), e.g. metallic=0."
        ),
    ] = None,
    starts: Annotated[int, typer.Option(min=1, max=64, help="Starting points.")] = 4,
    seed: Annotated[int, typer.Option(help="Seed of the random starts and samples.")] = 0,
    force: Annotated[bool, typer.Option("--force", help="Replace an existing file.")] = False,
    json_out: Annotated[bool, typer.Option("--json", help="Print one JSON object.")] = False,
) -> None:
    """Fit a Disney or Pixar preset to a measured BRDF and write it.

    The error is the cosine-weighted log error (Löw et al. 2012) over the
    measurement's own samples: RMS of log(1 + f cos θi) model − measurement,
    reported in all and per viewer band (normal < 30°, 45°, grazing ≥ 60°).
    The same seed gives the same fit. The written preset's `source` names the
    measurement and the error.

    Example: `lookdev fit carpaint_red.mbsdf --model disney --fix metallic=0 -o red.toml`
    """
    from lookdev.library import PresetFile, dump_preset
    from lookdev.library.files import atomic_write
    from lookdev.library.measured import read_measured, resolve_measured
    from lookdev.materials.colour import PRESET_LINEAR, convert, working_space
    from lookdev.materials.errors import LookdevError
    from lookdev.materials.registry import dead_parameters, live_lobes, model_named
    from lookdev.pipeline import api
    from lookdev.pipeline.analysis.fit import FitError
    from lookdev.pipeline.analysis.fit import fit as run_fit

    from .presets import parse_assignments

    if output.exists() and not force:
        raise FitError(f"{output} exists; pass --force to replace it", field="--output")
    table = read_measured(resolve_measured(measured))
    try:
        fixed = parse_assignments(fix or [])
    except LookdevError as exc:
        raise FitError(exc.message, field="--fix") from None
    first = None
    if start is not None:
        source = api.load(start)
        if source.model != model:
            raise FitError(f"{start} is a {source.model} preset, not {model}", field="--from")
        first = source.params
    result = run_fit(table, model, start=first, fixed=fixed, starts=starts, seed=seed)

    dead = dead_parameters(model_named(model), live_lobes(model_named(model), result.params))
    params = {}
    for name in type(result.params).model_fields:
        if name in dead:
            continue
        value = getattr(result.params, name)
        if name in result.params.model_fields_set or name in fixed:
            if isinstance(value, tuple):  # colours back from the working space to a preset's
                value = [round(float(v), 4) for v in convert(value, working_space(), PRESET_LINEAR)]
            elif isinstance(value, float):
                value = round(value, 4)
            params[name] = value
    preset = PresetFile(
        name=output.stem,
        model=model,
        description=f"{model} fitted to the measurement {table.source}",
        tags=["measured", "fitted"],
        source=f"fitted to {table.source} by lookdev fit (seed {seed}, {starts} starts): "
        f"cosine-weighted log RMS {result.error:.4f}",
        params=params,
    )
    output.parent.mkdir(parents=True, exist_ok=True)
    atomic_write(output, dump_preset(preset))
    summary = {
        "file": str(output),
        "measurement": table.source,
        "model": model,
        "params": params,
        "error": result.error,
        "bands": result.bands,
        "starts": result.starts,
        "evaluations": result.evaluations,
    }
    if json_out:
        print_json(summary)
        return
    bands = ", ".join(f"{k} {v:.4f}" for k, v in result.bands.items())
    console.print(f"fitted {output.stem}: log RMS {result.error:.4f} ({bands}) → {output}")
