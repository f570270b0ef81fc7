"""``lookdev bench eval`` (registered in :mod:`.bench`; the measuring is
:mod:`lookdev.pipeline.bench.eval`)."""

from __future__ import annotations

from typing import Annotated

import typer
from rich.progress import Progress

from lookdev.pipeline.bench import eval as eval_bench

from .common import JsonOut, console, err_console, print_json, table

__all__ = ["eval_"]


def eval_(
    n: Annotated[
        int, typer.Option("--n", "-n", min=1000, max=50_000_000, help="Direction pairs.")
    ] = 1_000_000,
    repeat: Annotated[
        int, typer.Option(min=1, max=20, help="Interleaved timing rounds; the best counts.")
    ] = 5,
    as_json: JsonOut = False,
) -> None:
    """Evaluate the Disney BSDF on N direction pairs: numpy, Dr.Jit and Mitsuba's principled.

    Eight materials share the pairs, so every lobe runs; all three are timed in one run.
    The figures are throughput ratios to Mitsuba's C++ plugin in CPU seconds: Dr.Jit ≥ 0.5
    (frozen, as renders replay it: ≥ 1.5), numpy ≥ 0.1; --json adds each material's.
    First-call (tracing + compile) times are shown apart and excluded from the rates.
    """
    with Progress(console=err_console, transient=True, disable=as_json) as bar:
        task = bar.add_task("compiling and timing", total=repeat)

        def step(round_: int) -> None:
            bar.update(task, completed=round_, description=f"timing round {round_ + 1}")

        result = eval_bench.run(n, repeat=repeat, progress=step)
    if as_json:
        print_json(result)
        return
    rows = [
        ["numpy float32", result["evals_per_s_numpy_float32"], "", ""],
        ["numpy float64", result["evals_per_s_numpy_float64"], "", ""],
        ["numpy float32, no lobe pruned", result["evals_per_s_numpy_every_lobe"], "", ""],
        ["Dr.Jit (ours)", result["evals_per_s_drjit"], result["drjit_first_call_s"], ""],
        ["Dr.Jit, prepare in every call", result["evals_per_s_drjit_prepare_each_call"], "", ""],
        [
            "Dr.Jit, frozen",
            result["evals_per_s_drjit_frozen"],
            result["drjit_frozen_first_call_s"],
            "",
        ],
        ["Mitsuba principled", result["evals_per_s_mitsuba"], result["mitsuba_first_call_s"], ""],
        [
            "Mitsuba principled, frozen",
            result["evals_per_s_mitsuba_frozen"],
            result["mitsuba_frozen_first_call_s"],
            "",
        ],
        ["ratio Dr.Jit / Mitsuba", result["ratio_drjit_to_mitsuba"], "", "≥ 0.5"],
        ["ratio Dr.Jit frozen / Mitsuba", result["ratio_drjit_frozen_to_mitsuba"], "", "≥ 1.5"],
        [
            "ratio Dr.Jit frozen / Mitsuba frozen",
            result["ratio_drjit_frozen_to_mitsuba_frozen"],
            "",
            "",
        ],
        [
            f"ratio numpy ({result['numpy_dtype']}) / Mitsuba",
            result["ratio_numpy_to_mitsuba"],
            "",
            "≥ 0.1",
        ],
        ["ratio pruned / no lobe pruned (numpy)", result["ratio_pruned_to_every_lobe"], "", ""],
    ]
    console.print(
        table(
            f"bench eval: {n:,} pairs, {len(eval_bench.PARAM_SETS)} materials, {result['variant']}",
            ["backend", "evals/s", "first call s", "target"],
            rows,
        )
    )
