"""``lookdev bench error`` (registered in :mod:`.bench`; the measuring is
:mod:`lookdev.pipeline.bench.error`)."""

from __future__ import annotations

import dataclasses
import time
from pathlib import Path
from typing import Annotated

import typer
from rich.progress import Progress

from lookdev.pipeline.bench import error, quality

from .common import JsonOut, console, print_json, table

__all__ = ["error_"]


ERROR_COLUMNS = ["case", "method", "setting", "error", "ms/call", "ns/eval", "× faster", "against"]


def _error_row(r: error.Row) -> list[str]:
    return [
        r.case,
        r.method,
        r.setting,
        f"{r.error:.3g}",
        f"{r.seconds * 1e3:.3g}",
        f"{r.seconds_per_evaluation * 1e9:.3g}",
        f"{r.speedup:.3g}" if r.reference_seconds else "",
        r.reference,
    ]


def error_(
    out_dir: Annotated[
        Path,
        typer.Option(
            "--output", "-o", help="Folder for error_bench.json and .png.", file_okay=False
        ),
    ] = Path("error_bench"),
    item: Annotated[
        list[str] | None,
        typer.Option("--item", "-i", help=f"Measure only these items: {', '.join(error.ITEMS)}."),
    ] = None,
    quick: Annotated[bool, typer.Option("--quick", help="Short ladders (CI, tests).")] = False,
    denoise_cases: Annotated[
        list[str] | None,
        typer.Option(
            "--denoise-case",
            metavar="PRESET:IBL",
            help="Item denoise: measure these cases (repeatable) instead of "
            "plastic_glossy:sky and glass_clear:sky.",
        ),
    ] = None,
    denoise_resolution: Annotated[
        tuple[int, int] | None,
        typer.Option(
            "--resolution",
            metavar="W H",
            help="Item denoise: the frame's size (default 192 96; a 4096-spp reference "
            "at 480 240 costs 6.25× as much).",
        ),
    ] = None,
    guide_spp: Annotated[
        int | None,
        typer.Option(
            "--guide-spp",
            min=1,
            help="Item denoise: samples of the albedo/normal guides, at most the frame's "
            "(default: the proofs' GUIDE_SPP).",
        ),
    ] = None,
    denoise_rig: Annotated[
        str | None,
        typer.Option(
            "--rig",
            help="Item denoise: the rig beside the material, full|balls|none (default: "
            "the proofs' full rig).",
        ),
    ] = None,
    as_json: JsonOut = False,
) -> None:
    """Error against run time of every approximation lookdev makes, measured now.

    Proof renders (relMSE vs spp and time), directional albedo (quadrature, Monte Carlo,
    table), the Conty-Kulla Λ fit vs numerical integration, float32 vs float64
    evaluation of every model, and the white furnace of a rough metal with
    energy_compensation off and on. Writes a table, error_bench.json and a log-log plot.
    """
    items = tuple(item or error.ITEMS)
    unknown = [i for i in items if i not in error.ITEMS]
    if unknown:
        raise error.BenchError(
            f"unknown item {unknown[0]!r}; allowed {', '.join(error.ITEMS)}", field="--item"
        )
    settings = error.Settings.quick() if quick else error.Settings()
    if denoise_cases:
        cases = tuple(tuple(c.split(":", 1)) for c in denoise_cases)
        if any(len(c) != 2 or not all(c) for c in cases):
            raise error.BenchError("expected PRESET:IBL", field="--denoise-case")
        settings = dataclasses.replace(
            settings, denoise=dataclasses.replace(settings.denoise, cases=cases)
        )
    if denoise_resolution is not None:
        if min(denoise_resolution) < 8:
            raise error.BenchError(
                f"{denoise_resolution[0]} {denoise_resolution[1]}: at least 8",
                field="--resolution",
            )
        settings = dataclasses.replace(
            settings,
            denoise=dataclasses.replace(settings.denoise, resolution=tuple(denoise_resolution)),
        )
    if denoise_rig is not None:
        from lookdev.pipeline.proof.rig import RIGS

        if denoise_rig not in RIGS:
            raise error.BenchError(
                f"unknown rig {denoise_rig!r}; allowed {', '.join(RIGS)}", field="--rig"
            )
        settings = dataclasses.replace(
            settings, denoise=dataclasses.replace(settings.denoise, rig=denoise_rig)
        )
    if guide_spp is not None:
        settings = dataclasses.replace(
            settings, denoise=dataclasses.replace(settings.denoise, guide_spp=guide_spp)
        )
    start = time.perf_counter()
    with Progress(console=console, transient=True, disable=as_json) as bar:
        task = bar.add_task("measuring", total=None)
        report = error.run(
            settings,
            items,
            progress=lambda name, done, total: bar.update(
                task, description=name, completed=done, total=total
            ),
        )
    paths = error.write_outputs(report, settings, out_dir)
    if as_json:
        print_json({**report.to_json(settings), "outputs": {k: str(v) for k, v in paths.items()}})
        return
    for item in error.ITEMS:
        rows = [r for r in report.rows if r.item == item]
        if rows:
            console.print(
                table(
                    f"{item}: {error.ERROR_NAMES[item]} against time",
                    ERROR_COLUMNS,
                    [_error_row(r) for r in rows],
                )
            )
    if report.denoise:
        from lookdev.pipeline.bench import denoise as denoise_bench

        console.print(
            table(
                "denoise: equal wall time (guides and denoiser included); † = extrapolated "
                "along relMSE ∝ 1/spp",
                denoise_bench.EQUAL_TIME_COLUMNS,
                denoise_bench.equal_time_rows(report.denoise),
            )
        )
        for case in report.denoise:
            verdict = "met" if case.summary["claim_met"] else "NOT met"
            console.print(
                f"{case.preset} × {case.ibl}: {case.summary['claim']}: {verdict}; "
                f"reference {case.reference_spp} spp, its own relMSE {case.reference_floor:.2g}; "
                f"{case.resolution[0]}×{case.resolution[1]}, rig {case.rig}, "
                f"guides ≤ {case.guide_spp} spp, "
                f"load average {case.load_average[0]:g} → {case.load_average[1]:g}",
                highlight=False,
            )
    if report.mainjob:
        console.print(
            table(
                "mainjob: old (192×96, 32 spp) and new default frames against converged "
                "references; noise estimate vs measured: relative RMS of the raw frame",
                quality.TABLE_COLUMNS,
                quality.table_rows(report.mainjob),
            )
        )
    for what, why in report.skipped.items():
        console.print(f"[yellow]skipped[/] {what}: {why}")
    console.print(
        f"wrote {paths['json']} and {paths['plot']} in {time.perf_counter() - start:.1f} s"
    )
