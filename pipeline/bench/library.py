"""``lookdev bench library``: listing a big preset library against reading its bytes.

Target (issue 4): ``lookdev presets list`` over a library of 10,000 presets answers within
2x the time it takes merely to read those files' bytes. Both are timed in this process
over the same freshly generated library, best of a few runs each, page cache warm:

============  =======================================================================
read          open and read every preset file (paths known in advance: the floor)
list          ``presets list`` end to end, output to /dev/null (the target's ratio)
list --json   the same with ``--json``
entries       ``Library.entries()`` alone: the search-path walk and the headers
cold          ``Library.entries()`` with no index yet (the first listing of a library)
============  =======================================================================

The generated files are dated an hour back, as in a library nobody is editing right
now: files changed in the last seconds are re-read on purpose (see ``library.index``).
"""

from __future__ import annotations

import contextlib
import os
import tempfile
import time
from pathlib import Path
from typing import Annotated, Any

import typer

from lookdev.library import Library
from lookdev.library.index import INDEX_NAME

TARGET_RATIO = 2.0
MODELS = ("disney", "disney", "disney", "layered")


def preset_text(i: int) -> str:
    """Preset number ``i`` of the generated library: varied models, tags, extends chains."""
    name = f"bench_{i:06d}"
    tags = f'["bench", "group_{i % 13}", "{("metal", "paint", "cloth")[i % 3]}"]'
    head = f'name = "{name}"\ndescription = "Generated preset {i} for the library benchmark."\n'
    head += f"tags = {tags}\nsource = 'lookdev bench library'\n"
    if i % 5 == 4:  # one in five extends its predecessor
        return head + f'extends = "bench_{i - 1:06d}"\n\n[params]\nroughness = {i % 10 / 10}\n'
    if MODELS[i % 4] == "layered":
        return head + (
            'model = "layered"\n\n[[layers]]\npreset = "gold"\n\n[[layers]]\npreset = "rust"\n'
            f'mask = {{ kind = "noise", scale = {4 + i % 8}, seed = {i % 97} }}\n'
        )
    return head + (
        f'model = "disney"\n\n[params]\nbase_color = [{i % 7 / 7:.3f}, 0.5, 0.25]\n'
        f"roughness = {i % 10 / 10}\nmetallic = {i % 2}.0\nclearcoat = 0.5\n"
    )


def build_library(folder: Path, n: int, progress=None) -> list[Path]:
    """Write ``n`` preset files into ``folder`` (100 per sub-folder), dated an hour back."""
    past = time.time() - 3600
    paths = []
    for i in range(n):
        sub = folder / f"group_{i // 100:04d}"
        if i % 100 == 0:
            sub.mkdir(parents=True, exist_ok=True)
        path = sub / f"bench_{i:06d}.toml"
        path.write_text(preset_text(i), encoding="utf-8")
        os.utime(path, (past, past))
        paths.append(path)
        if progress is not None:
            progress()
    return paths


def measure(folder: Path, paths: list[Path], *, repeat: int = 3) -> dict[str, float]:
    """Seconds (best of ``repeat``) of reading, listing and the list command over ``folder``.

    The candidates and the baseline take turns within each round, so a burst of load
    from other processes slows all of them rather than skewing one ratio.
    """
    from lookdev.pipeline.cli.presets import list_

    def read() -> None:
        for p in paths:
            with open(p, "rb") as f:
                f.read()

    def entries() -> None:
        Library([folder], use_env=False).entries()

    def command(as_json: bool) -> None:
        with open(os.devnull, "w") as null, contextlib.redirect_stdout(null):
            list_(tag=None, model=None, library=[folder], as_json=as_json)

    def cold() -> None:
        (folder / INDEX_NAME).unlink(missing_ok=True)
        entries()

    cases = {
        "read_s": read,
        "list_s": lambda: command(False),
        "list_json_s": lambda: command(True),
        "entries_s": entries,
        "cold_s": cold,
    }
    best = dict.fromkeys(cases, float("inf"))
    for fn in cases.values():  # warm-up: page cache, imports, and the index itself
        fn()
    for _ in range(repeat):
        for key, fn in cases.items():
            t0 = time.perf_counter()
            fn()
            best[key] = min(best[key], time.perf_counter() - t0)
    return best


def report(n: int, times: dict[str, float]) -> dict[str, Any]:
    """Times plus ratios to the read baseline; ``ratio_list_to_read`` is the target's."""
    read = times["read_s"]
    ratios = {
        "ratio_list_to_read": times["list_s"] / read,
        "ratio_list_json_to_read": times["list_json_s"] / read,
        "ratio_entries_to_read": times["entries_s"] / read,
        "ratio_cold_to_read": times["cold_s"] / read,
    }
    return {
        "n": n,
        **times,
        **ratios,
        "target_ratio": TARGET_RATIO,
        "meets_target": ratios["ratio_list_to_read"] <= TARGET_RATIO,
    }


def command(
    n: Annotated[int, typer.Option("--n", min=1, help="Presets in the generated library.")] = 10000,
    repeat: Annotated[int, typer.Option("--repeat", min=1, help="Runs per timing (best).")] = 5,
    as_json: Annotated[bool, typer.Option("--json", help="Print one JSON object.")] = False,
) -> None:
    """Time `presets list` over N generated presets against reading their bytes (target ≤ 2x).

    Example: lookdev bench library --n 10000
    """
    from rich.progress import Progress

    from lookdev.pipeline.cli.common import console, print_json, table

    with tempfile.TemporaryDirectory(prefix="lookdev-bench-library-") as tmp:
        folder = Path(tmp)
        with Progress(console=console, transient=True, disable=as_json) as bar:
            task = bar.add_task(f"writing {n} presets", total=n)
            paths = build_library(folder, n, progress=lambda: bar.advance(task))
            bar.update(task, description="timing", completed=n)
            result = report(n, measure(folder, paths, repeat=repeat))
    if as_json:
        print_json(result)
        return
    rows = [
        ["read bytes (baseline)", result["read_s"], 1.0],
        ["presets list", result["list_s"], result["ratio_list_to_read"]],
        ["presets list --json", result["list_json_s"], result["ratio_list_json_to_read"]],
        ["Library.entries()", result["entries_s"], result["ratio_entries_to_read"]],
        ["first listing (no index)", result["cold_s"], result["ratio_cold_to_read"]],
    ]
    console.print(table(f"library of {n} presets", ["what", "seconds", "× read"], rows))
    verdict = "meets" if result["meets_target"] else "MISSES"
    console.print(f"presets list {verdict} the target of ≤ {TARGET_RATIO:g}× reading the bytes")
