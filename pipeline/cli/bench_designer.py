"""``lookdev bench designer``: the Material Designer viewport's figures against its targets."""

from __future__ import annotations

from contextlib import nullcontext
from typing import Annotated

import typer

from .common import console, err_console, print_json, table

__all__ = ["ITEMS", "designer_"]

ITEMS = ("designer", "client", "rotation", "converge", "truth", "compare")


def designer_(
    presets: Annotated[
        list[str] | None,
        typer.Argument(help="Presets to compare the two modes on (default: the main job's)."),
    ] = None,
    item: Annotated[
        list[str] | None,
        typer.Option("--item", help=f"Measure only these: {', '.join(ITEMS)} (repeatable)."),
    ] = None,
    edits: Annotated[int, typer.Option(min=3, max=1000, help="Timed edits per mode.")] = 20,
    compare_spp: Annotated[
        int, typer.Option(min=4, max=4096, help="Samples per pixel of each compared image.")
    ] = 256,
    as_json: Annotated[bool, typer.Option("--json", help="Print one JSON object.")] = False,
) -> None:
    """Time the designer's viewport at 480×270: an edit → its first frame in designer mode
    (target ≤ 0.15 s) and truth mode (≤ 0.4 s), IBL rotations per second at 240×135
    (≥ 10), seconds to converge to relMSE ≤ 0.01 against a 1024-spp reference (≤ 2 s),
    kernels compiled over 100 random truth-mode edits (0), and the relMSE of designer
    against truth per preset with what explains it. Wall and CPU seconds and the load
    average are reported beside every figure (the machine may be shared).
    """
    from lookdev.materials.errors import LookdevError
    from lookdev.pipeline.bench import designer

    chosen = tuple(item or ITEMS)
    unknown = sorted(set(chosen) - set(ITEMS))
    if unknown:
        err_console.print(f"error: --item {unknown[0]!r}: use one of {', '.join(ITEMS)}")
        raise typer.Exit(2)
    status_ = console.status("measuring", spinner="dots") if not as_json else nullcontext()
    with status_ as status:

        def progress(what: str) -> None:
            if status is not None:
                status.update(what)

        try:
            result = designer.run(
                presets=tuple(presets) if presets else None,
                edits=edits,
                compare_spp=compare_spp,
                items=chosen,
                progress=progress,
            )
        except LookdevError as exc:
            err_console.print(f"error: {exc}")
            raise typer.Exit(2) from None
    if as_json:
        print_json(result)
        return
    rows = []
    if "designer_edit" in result:
        r = result["designer_edit"]
        rows.append(["designer edit → frame, median s", r["median_s"], r["median_cpu_s"], "≤ 0.15"])
    if "client_edit" in result:
        r = result["client_edit"]
        rows.append(
            ["edit via the server → page, median s", r["median_s"], r["median_cpu_s"], "≤ 0.15"]
        )
    if "ibl_rotation" in result:
        r = result["ibl_rotation"]
        rows.append(
            ["IBL rotations / s (240×135)", r["updates_per_s"], r["cpu_s_per_update"], "≥ 10"]
        )
    if "designer_converge" in result:
        r = result["designer_converge"]
        rows.append(["designer converge s (relMSE ≤ 0.01)", r["seconds"], r["cpu_s"], "≤ 2"])
    if "truth_edit" in result:
        r = result["truth_edit"]
        rows.append(["truth edit → frame, median s", r["median_s"], r["median_cpu_s"], "≤ 0.4"])
    if "truth_compiles" in result:
        r = result["truth_compiles"]
        rows.append(["kernels compiled, 100 truth edits", r["kernels_compiled"], "", "0"])
    console.print(table("bench designer", ["figure", "value", "CPU s", "target"], rows))
    if "designer_vs_truth" in result:
        cmp_ = result["designer_vs_truth"]
        rows = [
            [
                name,
                r["designer_vs_truth"]["material"],
                r["designer_vs_truth_direct"]["material"],
                r["truth_direct_vs_truth"]["material"],
                r["designer_no_shadows_vs_truth"]["material"],
            ]
            for name, r in cmp_["presets"].items()
        ]
        cols = ["preset", "designer/truth", "designer/direct", "direct/truth", "no shadows/truth"]
        title = f"relMSE on the material's pixels, {cmp_['size'][0]}×{cmp_['size'][1]}"
        console.print(table(title, cols, rows))
