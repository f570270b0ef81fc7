"""``lookdev bench …``: performance targets measured as ratios within one run.

Each benchmark times the candidate and its baseline in the same process, prints a table
for people, and with ``--json`` one object for scripts. Benchmarks live in their feature
modules and register here with :func:`benchmark`.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Any

import typer

app = typer.Typer(
    help="Measure performance targets as ratios against a baseline run in the same process.",
    no_args_is_help=True,
)


def best_time(fn: Callable[[], Any], *, repeat: int = 3, min_time: float = 0.0) -> float:
    """Best wall time of ``repeat`` calls (after one warm-up call), in seconds."""
    fn()
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
        if min_time and sum(times) > min_time and len(times) >= 2:
            break
    return min(times)


def _register() -> None:
    from lookdev.pipeline.bench import blend, depth, error, library, proof, usd
    from lookdev.pipeline.bench import eval as eval_

    app.command("blend")(blend.command)
    app.command("depth")(depth.command)
    app.command("error")(error.command)
    app.command("eval")(eval_.command)
    app.command("library")(library.command)
    app.command("proof")(proof.command)
    app.command("usd")(usd.command)


_register()
