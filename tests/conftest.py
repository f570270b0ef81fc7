"""Shared fixtures: run the CLI in-process and capture its exit code and output."""

from __future__ import annotations

import os
import sys
import warnings
from dataclasses import dataclass
from pathlib import Path

# Rich sizes its consoles when lookdev.pipeline.cli.common is first imported; a wide one
# keeps long temporary paths on one line so tests can find them in the output.
os.environ["COLUMNS"] = "240"

import pytest
from hypothesis import HealthCheck, settings

# The tree under tests/ mirrors the code (tests/materials, tests/pipeline/blend …); the
# helper modules shared by several of them (_lambert, _mitsuba_tiny …) live here.
TESTS = Path(__file__).resolve().parent
sys.path.insert(0, str(TESTS))

# Property tests draw the same examples on every run (CI must not be red one run in ten);
# HYPOTHESIS_PROFILE=explore searches afresh, and keeps what fails, when hunting bugs.
# Timing is not deterministic either: no per-example deadline and no "too slow" health
# check, which a loaded machine trips (seen once at load 18 on a test that passed alone).
settings.register_profile(
    "deterministic",
    derandomize=True,
    database=None,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow],
)
settings.register_profile("explore", max_examples=500)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "deterministic"))


DEFAULT_IGNORED = (DeprecationWarning, PendingDeprecationWarning, ImportWarning, ResourceWarning)
"""What Python's default warning filters hide from a user's terminal."""
SHOW_WARNING = warnings.showwarning
"""The interpreter's printer of warnings (to stderr), before pytest records them."""


@dataclass
class CliResult:
    code: int
    out: str
    err: str


@pytest.fixture
def cli(capfd):
    """``cli("presets", "list")`` → CliResult(code, out, err), as a user would see it.

    Captured at the file descriptors, so a C library's own line (libpng, OpenColorIO)
    counts; Python warnings print as the interpreter's default filters print them (pytest
    would otherwise record them out of sight): every "one line on stderr" test sees what
    a terminal shows.
    """
    from lookdev.pipeline.cli import main

    def run(*args: str) -> CliResult:
        capfd.readouterr()
        with warnings.catch_warnings():
            warnings.resetwarnings()
            for category in DEFAULT_IGNORED:
                warnings.simplefilter("ignore", category)
            warnings.showwarning = SHOW_WARNING
            try:
                main(list(args))
                code = 0
            except SystemExit as exc:
                code = exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 1)
        captured = capfd.readouterr()
        return CliResult(code, captured.out, captured.err)

    return run
