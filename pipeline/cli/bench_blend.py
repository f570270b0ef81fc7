"""``lookdev bench blend`` (registered in :mod:`.bench`; the measuring is
:mod:`lookdev.pipeline.bench.blend`)."""

from __future__ import annotations

from typing import Annotated

import typer

from lookdev.pipeline.bench import blend

from .common import JsonOut, Repeat, console, print_json, table

__all__ = ["blend_"]


def blend_(
    resolution: Annotated[
        int, typer.Option("--resolution", "-r", min=16, max=8192, help="Texels per side.")
    ] = 2048,
    repeat: Repeat = 3,
    as_json: JsonOut = False,
) -> None:
    """Blend 4 texture-masked Disney layers into all parameter maps vs a numpy copy.

    Reports the time against the memory-bandwidth bound measured in the same run
    (target ≤ 4×), peak memory against the output size (target < 2×: numpy's traced peak,
    and the resident peak of a child process, OpenImageIO's buffers included, for this
    stack and for large float EXR masks driving one map), and what pruning saved on a
    preset where it applies. The target column says met or missed.
    """
    result = blend.run(resolution, repeat=repeat)
    if as_json:
        print_json(result)
        return
    rows = [[k, v, blend.verdict(k, v)] for k, v in result.items() if not isinstance(v, dict)]
    for name, saving in result["pruning"].items():
        rows += [[f"pruning {name}: {k}", v, ""] for k, v in saving.items()]
    console.print(table(f"bench blend ({resolution}²)", ["measure", "value", "target"], rows))
