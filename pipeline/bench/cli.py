"""The CPU time of the quick commands against the floor of ``import typer``.

Every command line is a fresh interpreter, so its start-up *is* its cost: the modules
it imports. Each command runs as a child process and is charged the user + system CPU
seconds the kernel accounts to that child (``os.wait4``), which, unlike wall time,
does not grow when other work shares the cores. Rounds interleave the floor and the
commands (one of each per round, in a rotating order), so a slow spell of the machine
falls on all of them alike; the median over rounds is reported, with each command's
ratio to the floor taken within its round.
"""

from __future__ import annotations

import os
import statistics
import subprocess
import sys
import tempfile
from collections.abc import Callable, Sequence
from typing import Any

__all__ = ["COMMANDS", "ENTRY", "FLOOR", "TARGET", "cpu_seconds", "run"]

FLOOR = ("-c", "import typer")
"""The baseline: an interpreter that imports Typer and does nothing with it."""
COMMANDS = {
    "--help": ("--help",),
    "--version": ("--version",),
    "presets list": ("presets", "list"),
    "presets show gold": ("presets", "show", "gold"),
}
"""The commands measured: what a newcomer types first."""
TARGET = 3.0
"""Each command within this many times the floor's CPU time."""
ENTRY = "import sys; from lookdev.pipeline.cli import main; main(sys.argv[1:])"
"""``python -c ENTRY ARGS…`` runs ``lookdev ARGS…`` in a fresh interpreter."""


def cpu_seconds(argv: Sequence[str], env: dict[str, str] | None = None) -> float:
    """User + system CPU seconds of one child process running ``argv`` (output dropped;
    on failure, the child's last line of stderr in the error).

    >>> cpu_seconds([sys.executable, "-c", "pass"]) > 0
    True
    """
    # stderr to a file, not a pipe: a child that writes more than a pipe holds would
    # block while we wait for it
    with tempfile.TemporaryFile() as err:
        child = subprocess.Popen(list(argv), stdout=subprocess.DEVNULL, stderr=err, env=env)
        _, status, usage = os.wait4(child.pid, 0)
        if os.waitstatus_to_exitcode(status) != 0:
            err.seek(0)
            last = err.read().decode(errors="replace").strip().splitlines()[-1:]
            code = os.waitstatus_to_exitcode(status)
            raise RuntimeError(f"{' '.join(argv)} exited {code}: {' '.join(last)}")
    return usage.ru_utime + usage.ru_stime


def run(rounds: int = 7, progress: Callable[[int], None] | None = None) -> dict[str, Any]:
    """Time :data:`COMMANDS` and :data:`FLOOR` in ``rounds`` interleaved rounds.

    Returns the floor's median CPU seconds, and per command its median CPU seconds, its
    median ratio to the floor (each ratio within one round), the range of those ratios,
    and whether the median meets :data:`TARGET`; with the load average before and after.
    """
    # One console width for every child: Rich lays the help out for it, and a terminal's
    # width would otherwise change what is measured.
    env = {**os.environ, "COLUMNS": "100", "PYTHONWARNINGS": "ignore"}
    python = sys.executable
    jobs = {"floor": [python, *FLOOR]}
    jobs |= {name: [python, "-c", ENTRY, *args] for name, args in COMMANDS.items()}
    # Warm the file cache and write the byte-code once, as any first run (or pip install)
    # does: PYTHONDONTWRITEBYTECODE (set in many containers) would otherwise have every
    # round compile lookdev's modules again, a cost no user's second start-up pays.
    warm = {k: v for k, v in env.items() if k != "PYTHONDONTWRITEBYTECODE"}
    for argv in jobs.values():
        cpu_seconds(argv, warm)
    load_before = os.getloadavg()
    times: dict[str, list[float]] = {name: [] for name in jobs}
    names = list(jobs)
    for r in range(rounds):
        order = names[r % len(names) :] + names[: r % len(names)]
        for name in order:
            times[name].append(cpu_seconds(jobs[name], env))
        if progress is not None:
            progress(r + 1)
    floor = times["floor"]
    result: dict[str, Any] = {
        "rounds": rounds,
        "python": sys.version.split()[0],
        "floor": "python -c 'import typer'",
        "floor_cpu_s": statistics.median(floor),
        "target_ratio": TARGET,
        "commands": {},
        "load_average": [round(load_before[0], 2), round(os.getloadavg()[0], 2)],
    }
    for name in COMMANDS:
        ratios = [t / f for t, f in zip(times[name], floor, strict=True)]
        result["commands"][f"lookdev {name}"] = {
            "cpu_s": statistics.median(times[name]),
            "ratio": statistics.median(ratios),
            "ratio_min": min(ratios),
            "ratio_max": max(ratios),
            "met": statistics.median(ratios) <= TARGET,
        }
    return result
