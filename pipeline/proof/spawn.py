"""Worker processes that do not re-run the caller's script.

A spawned process starts a fresh interpreter, and Python's ``multiprocessing`` then
imports the parent's main script in it (so that functions defined there can be
unpickled): a plain script calling :func:`lookdev.proof` without an
``if __name__ == "__main__":`` guard would load, blend and export everything again in
each worker before a frame is rendered. Proof workers unpickle only lookdev's own jobs,
so they are started without the main script (:data:`CONTEXT`).
"""

from __future__ import annotations

import sys
import types
from multiprocessing.context import SpawnContext, SpawnProcess

__all__ = ["CONTEXT"]


class _Process(SpawnProcess):
    """A spawned process whose start-up data names no main script to re-run."""

    def start(self) -> None:
        # Python reads sys.modules["__main__"] while starting the child (its
        # "preparation data"): for that moment it sees a main module with no file.
        main = sys.modules["__main__"]
        stand_in = types.ModuleType("__main__")
        stand_in.__spec__ = None
        sys.modules["__main__"] = stand_in
        try:
            super().start()
        finally:
            sys.modules["__main__"] = main


class _Context(SpawnContext):
    Process = _Process


CONTEXT = _Context()
"""The ``mp_context`` of the proofs' local process pool."""
