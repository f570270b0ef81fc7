"""Blender as a consumer: its ``bpy`` wheel, run in its own interpreter.

Blender's Python module (PyPI ``bpy``) pins its own Python and numpy, so it lives in a
virtual environment of its own (``scripts/setup.sh`` makes ``.venv-blender``) and lookdev
talks to it through a subprocess: :func:`run` starts :mod:`.blender_side` there with a
JSON request and reads a JSON answer. Nothing of lookdev is imported on Blender's side.

The interpreter is ``$LOOKDEV_BLENDER_PYTHON`` if set, else ``.venv-blender/bin/python``
beside the checkout (:func:`interpreter`). :func:`interpreters` lists every Blender
installed beside the checkout (``.venv-blender``: bpy 4.5; ``.venv-blender5``: the newest
bpy, 5.x), so the tests run against each.
"""

from __future__ import annotations

import json
import os
import subprocess
import tempfile
from pathlib import Path
from typing import Any

from lookdev.materials.errors import LookdevError

__all__ = ["VENVS", "BlenderError", "interpreter", "interpreters", "run", "version"]

ENV = "LOOKDEV_BLENDER_PYTHON"
SIDE = Path(__file__).with_name("blender_side.py")
VENVS = (".venv-blender", ".venv-blender5")
"""The virtual environments ``scripts/setup.sh`` installs Blender into, the default first."""


class BlenderError(LookdevError):
    """Blender is not installed, or a Blender run failed."""


def interpreter() -> Path | None:
    """The Python that imports ``bpy``, or None when none is installed."""
    found = interpreters()
    return found[0] if found else None


def interpreters() -> list[Path]:
    """Every Python that imports ``bpy``: ``$LOOKDEV_BLENDER_PYTHON`` alone if set, else
    those of :data:`VENVS` that exist."""
    given = os.environ.get(ENV)
    if given:
        return [Path(given)]
    root = Path(__file__).resolve().parents[2]
    return [p for v in VENVS if (p := root / v / "bin" / "python").exists()]


def run(
    request: dict[str, Any], timeout: float = 1800.0, python: Path | None = None
) -> dict[str, Any]:
    """Run one request (``{"op": …}``, see :mod:`.blender_side`) in Blender (``python``,
    by default :func:`interpreter`); its answer."""
    python = python or interpreter()
    if python is None:
        raise BlenderError(
            f"no Blender Python: run scripts/setup.sh (it makes .venv-blender) or set {ENV}"
        )
    with tempfile.TemporaryDirectory(prefix="lookdev-blender-") as tmp:
        ask, answer = Path(tmp) / "request.json", Path(tmp) / "answer.json"
        ask.write_text(json.dumps(request))
        try:
            done = subprocess.run(
                [str(python), str(SIDE), str(ask), str(answer)],
                capture_output=True,
                text=True,
                timeout=timeout,
                check=False,
            )
        except (OSError, subprocess.TimeoutExpired) as exc:
            raise BlenderError(f"Blender did not run ({exc})") from None
        if done.returncode != 0 or not answer.exists():
            tail = (done.stderr or done.stdout).strip().splitlines()[-1:] or ["no output"]
            raise BlenderError(f"Blender failed (exit {done.returncode}): {tail[0]}")
        return json.loads(answer.read_text())


def version(python: Path | None = None) -> str:
    """The Blender version the interpreter's ``bpy`` is, e.g. ``"4.5.15"``."""
    return str(run({"op": "version"}, python=python)["version"])
