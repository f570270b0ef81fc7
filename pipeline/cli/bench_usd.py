"""``lookdev bench usd`` (registered in :mod:`.bench`; the measuring is
:mod:`lookdev.pipeline.bench.usd`)."""

from __future__ import annotations

from typing import Annotated

import typer

from lookdev.pipeline.bench import usd

from .common import JsonOut, console, print_json, table

__all__ = ["usd_"]


def usd_(
    materials: Annotated[
        int, typer.Option("--materials", "-n", min=1, max=100_000, help="Materials per stage.")
    ] = 1000,
    repeat: Annotated[
        int, typer.Option("--repeat", min=1, help="Interleaved rounds (median and spread).")
    ] = 5,
    as_json: JsonOut = False,
) -> None:
    """Export N materials into one stage: Sdf-level authoring vs the naive Usd API.

    Both author identical networks (UsdPreviewSurface, MaterialX and RenderMan contexts)
    in the same run, in interleaved rounds (fast, naive, the two floors, end to end); each ratio
    is taken within its round and reported as the median over rounds with its min-max
    spread, as is the end-to-end materials per second (target ≥ 5×).
    """
    result = usd.run(materials, repeat=repeat)
    if as_json:
        print_json(result)
        return
    rows = [[k, v] for k, v in result.items()]
    console.print(table(f"bench usd ({materials} materials)", ["measure", "value"], rows))
    ratio, bound = result["ratio_fast_to_naive"], result["ratio_bound"]
    above_floor = result["fast_s"] / result["floor_empty_specs_s"]
    lo, hi = result["ratio_fast_to_naive_min"], result["ratio_fast_to_naive_max"]
    rate = result["end_to_end_materials_per_s"]
    rate_lo, rate_hi = (
        result["end_to_end_materials_per_s_min"],
        result["end_to_end_materials_per_s_max"],
    )
    console.print(
        f"median of {result['rounds']} interleaved rounds: ratio {ratio:.2f}× "
        f"[{lo:.2f}–{hi:.2f}], end to end {rate:,.0f} materials/s [{rate_lo:,.0f}–{rate_hi:,.0f}]"
    )
    console.print(
        f"fast path {ratio:.2f}× the naive reference (target ≥ 5×: "
        f"{'met' if ratio >= 5 else 'missed'}); creating the same specs empty, which no "
        f"Python authoring can beat, is {bound:.2f}× it; the fast path takes "
        f"{above_floor:.1f}× that floor to also set values, connections and metadata"
    )
    console.print(
        f"the writer's own usd-core calls replayed with nothing computed are "
        f"{result['ratio_bound_set']:.2f}× the naive reference: the most any writer making "
        f"them could reach; the fast path takes "
        f"{result['fast_s'] / result['floor_set_s']:.2f}× their time"
    )
    console.print(
        f"in CPU seconds (the naive path's usd-core worker threads counted) "
        f"{result['ratio_fast_to_naive_cpu']:.2f}×; against the naive path limited to one "
        f"worker thread {result['ratio_fast_to_naive_one_thread']:.2f}×"
    )
