"""``lookdev bench library``: listing a big preset library against reading its bytes.

Target: ``lookdev presets list`` over a library of 10,000 presets answers within
2x the time it takes merely to read those files' bytes. Both are timed in this process
over the same freshly generated library, best of a few runs each, page cache warm:

============  =======================================================================
read          open and read every preset file (paths known in advance: the floor)
list          what ``presets list`` does, through the library API: ``Library.entries()``
              and a text row per preset, written to /dev/null (the target's ratio)
list --json   the same with a JSON document per preset
entries       ``Library.entries()`` alone: the search-path walk and the headers
cold          ``Library.entries()`` with no index yet (the first listing of a library)
============  =======================================================================

The generated files are dated an hour back, as in a library nobody is editing right
now: files changed in the last seconds are re-read on purpose (see ``library.index``).
"""

from __future__ import annotations

import os
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

from lookdev.library import Library
from lookdev.library import listing as listing_of
from lookdev.library.index import INDEX_NAME

__all__ = [
    "MODELS",
    "TARGET_RATIO",
    "build_library",
    "listing",
    "measure",
    "preset_text",
    "report",
    "run",
]

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

    def read() -> None:
        for p in paths:
            with open(p, "rb") as f:
                f.read()

    def entries() -> None:
        Library([folder], use_env=False).entries()

    def command(as_json: bool) -> None:
        with open(os.devnull, "w") as null:
            null.write(listing(Library([folder]), as_json=as_json))

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


def listing(lib: Library, *, as_json: bool = False) -> str:
    """What ``presets list`` writes for ``lib`` (plain text, as when piped, or JSON): the
    command's own functions (:mod:`lookdev.library.listing`), timed without the CLI."""
    shown = listing_of.matching(lib.entries(), [], None)
    return listing_of.listing_json(shown, lib) if as_json else listing_of.listing_text(shown, lib)


def run(
    n: int, *, repeat: int = 5, progress: Callable[[str, int], None] | None = None
) -> dict[str, Any]:
    """Every figure of the benchmark (module doc) over a library of ``n`` generated presets,
    written into a temporary folder; ``progress(what, presets_done)`` follows the writing."""
    with tempfile.TemporaryDirectory(prefix="lookdev-bench-library-") as tmp:
        folder = Path(tmp)
        done = 0

        def step() -> None:
            nonlocal done
            done += 1
            if progress is not None:
                progress(f"writing {n} presets", done)

        paths = build_library(folder, n, progress=step)
        if progress is not None:
            progress("timing", n)
        return report(n, measure(folder, paths, repeat=repeat))
