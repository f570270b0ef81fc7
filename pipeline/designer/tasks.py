"""The work around the viewport, each through lookdev's own API on the material on screen:
the BRDF-explorer views (:func:`lookdev.plot`, numpy backend), the USD loss notes
(:func:`lookdev.pipeline.export.usd.loss_notes`), "Export USD" (:func:`lookdev.export_usd`)
and "Proof" (:func:`lookdev.proof`, the batch with its review page, run in the background).

Outputs go under the session's folder only, where the page reads them back through
:class:`~.guard.Roots`.
"""

from __future__ import annotations

import threading
import time
import uuid
from concurrent.futures import ThreadPoolExecutor
from typing import Any

__all__ = ["export_usd", "losses", "plot", "start_proof", "status"]

_proofs = ThreadPoolExecutor(max_workers=1, thread_name_prefix="designer-proof")
_lock = threading.Lock()


def plot(d: Any, view: str) -> bytes:
    """One BRDF-explorer view of the current material as PNG bytes (cached per edit)."""
    import lookdev

    path = d.folder / "plots" / f"{view}-{d.session.version}.png"
    if not path.is_file():
        lookdev.plot(d.session.hub(), path, view=view, library=d.library)
    return path.read_bytes()


def losses(d: Any) -> dict[str, str]:
    """``{context: note}`` for the current material ("" where nothing is lost)."""
    from lookdev.pipeline.export.usd import loss_notes

    return loss_notes(d.session.hub())


def export_usd(d: Any) -> dict[str, Any]:
    """Write the current material as USD into the session's exports folder."""
    import lookdev

    name = d.session.name
    out = d.folder / "exports" / f"{name}-{d.session.version}.usda"
    result = lookdev.export_usd(d.session.material(), out, library=d.library)
    where = d.roots.locate(result.output)
    return {
        "file": f"files/{where[0]}/{where[1]}" if where else None,
        "losses": result.losses.get(name, {}),
    }


def start_proof(d: Any) -> dict[str, Any]:
    """Queue a full proof of the current material; poll :func:`status` for its page."""
    import lookdev

    material = d.session.material()
    task_id = uuid.uuid4().hex[:12]
    out = d.folder / "proofs" / task_id
    with _lock:
        d.tasks[task_id] = {"id": task_id, "state": "queued", "name": material.name}

    def run() -> None:
        _update(d, task_id, state="running", started=time.time())
        try:
            lookdev.proof(
                [material],
                ibls=[d.ibl],
                out=out,
                report=True,
                library=d.library,
                geometry=d.geometry,
                **d.proof_settings,
            )
        except Exception as exc:  # reported on the page, in one line
            _update(d, task_id, state="failed", error=f"{type(exc).__name__}: {exc}")
            return
        where = d.roots.locate(out / "index.html")
        _update(d, task_id, state="done", page=f"files/{where[0]}/{where[1]}" if where else None)
        d.broadcast({"type": "task", **d.tasks[task_id]})

    _proofs.submit(run)
    return d.tasks[task_id]


def status(d: Any, task_id: str) -> dict[str, Any]:
    with _lock:
        return dict(d.tasks.get(task_id, {"id": task_id, "state": "unknown"}))


def _update(d: Any, task_id: str, **changes: Any) -> None:
    with _lock:
        d.tasks[task_id].update(changes)
