"""``lookdev bench mainjob`` (registered in :mod:`.bench`; the measuring is
:mod:`lookdev.pipeline.bench.knobs`)."""

from __future__ import annotations

import dataclasses
from typing import Annotated

import typer

from lookdev.pipeline.bench import knobs, noise

from .common import JsonOut, console, print_json, table

__all__ = ["mainjob_"]


def mainjob_(
    presets: Annotated[
        list[str] | None,
        typer.Argument(help="Presets (default: the main job's seven)."),
    ] = None,
    ibl: Annotated[str, typer.Option("--ibl", "-i", help="IBL to time jobs under.")] = "sky",
    quick: Annotated[bool, typer.Option("--quick", help="Tiny frames (CI, tests).")] = False,
    as_json: JsonOut = False,
) -> None:
    """What each knob of the main job costs: frames, sample cap, denoising.

    Each preset's proof job is replayed under --ibl (scene load, a 4 + 4 turntable at
    480×240 rendered to the default noise target under each cap, frames written and
    denoised, every step timed); from these, every candidate default's cost over the
    whole main job (× 4 IBLs) as a ratio to the previous default's (16 frames, cap 8, raw).
    """
    s = knobs.CostSettings.quick() if quick else knobs.CostSettings()
    s = dataclasses.replace(s, presets=tuple(presets or s.presets), ibl=ibl)
    with console.status("replaying proof jobs", spinner="dots"):
        rows = knobs.cost(s)
    report = {
        "settings": dataclasses.asdict(s),
        "load_average": list(noise._load()),
        "jobs": rows,
        "candidates": knobs.project(rows, s),
    }
    if as_json:
        print_json(report)
        return
    cols = ["preset", "max spp", "set-up CPU s", "first frame CPU s", "steady frame CPU s",
            "denoise CPU s/frame"]  # fmt: skip
    console.print(table("a proof job, step by step", cols, knobs.job_rows(rows)))
    cols = ["frames", "max spp", "denoise", "wall s", "CPU s", "× previous wall", "× previous CPU"]
    rows_ = [
        [c["frames"], c["max_spp"], "on" if c["denoise"] else "off", c["wall_s"], c["cpu_s"],
         c["over_today_wall"], c["over_today_cpu"]]
        for c in report["candidates"]
    ]  # fmt: skip
    console.print(table("the main job's proofs, per candidate default", cols, rows_))
    console.print(f"load average {report['load_average']}", highlight=False)
