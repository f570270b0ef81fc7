"""The render thread: the one owner of the session's viewports.

A :class:`~lookdev.pipeline.designer.viewport.Viewport` is not thread-safe, so one
thread holds it (and a second one for the A/B split's reference). The server posts
what changed (a new blended material, a rotation, the exposure, the mode …); the thread
takes the latest value of each, applies them, and steps the viewport while its image is
still refining and someone is watching. Each frame goes out as a JPEG (Pillow) to every
connected page through ``publish``; a page that cannot keep up gets the newest frame,
not a queue of old ones (see :mod:`.server`).

Nothing here knows a formula: the pixels are the viewport's.
"""

from __future__ import annotations

import io
import threading
import time
from collections.abc import Callable
from typing import Any

__all__ = ["JPEG_QUALITY", "Renderer", "encode"]

JPEG_QUALITY = 90
IDLE_WAIT_S = 0.25
VIEW_KEYS = ("mode", "ibl", "rotate_ibl", "rotate_element", "exposure", "size")
# Dr.Jit's recording and replay of frozen passes (dr.freeze) is process state, not a
# thread's: two designers in one process (two notebook cells) render one pass at a time.
_PASS_LOCK = threading.Lock()


def encode(display: Any, fmt: str = "JPEG") -> bytes:
    """An (H, W, 3) uint8 display image as JPEG (or PNG) bytes."""
    from PIL import Image

    buf = io.BytesIO()
    image = Image.fromarray(display, "RGB")
    image.save(buf, fmt, **({"quality": JPEG_QUALITY} if fmt == "JPEG" else {}))
    return buf.getvalue()


class Renderer:
    """Runs the viewport(s) on one thread; :meth:`post` is safe from any thread."""

    def __init__(
        self,
        factory: Callable[..., Any],
        publish: Callable[[str, bytes, dict[str, Any]], None],
        *,
        watching: Callable[[], bool] = lambda: True,
    ):
        self._factory = factory
        self._publish = publish
        self._watching = watching
        self._pending: dict[str, Any] = {}
        self._wake = threading.Condition()
        self._stop = False
        self.error: str | None = None
        self.view: dict[str, Any] = {"raw": False, "ab": False, "exposure": 0.0}
        self.version = 0
        """The session's version of the material on screen: every frame carries it, so a
        page (or a benchmark) knows which edit a frame shows."""
        self._thread = threading.Thread(target=self._run, name="designer-render", daemon=True)
        self._thread.start()

    def post(self, **changes: Any) -> None:
        """Ask for changes: ``material=``, ``reference=``, ``mode=``, ``ibl=``,
        ``rotate_ibl=``, ``rotate_element=``, ``exposure=``, ``size=(w, h)``, ``raw=``,
        ``ab=``; the newest value of each wins."""
        with self._wake:
            self._pending.update(changes)
            self._wake.notify()

    def close(self, timeout: float = 10.0) -> None:
        """Stop the thread and close the viewports (called on shutdown)."""
        with self._wake:
            self._stop = True
            self._wake.notify()
        self._thread.join(timeout)

    # -- the thread ------------------------------------------------------------------------
    def _run(self) -> None:
        views: dict[str, Any] = {}
        state = {"A": {"converged": True, "fresh": False}, "B": {"converged": True, "fresh": False}}
        try:
            while True:
                with self._wake:
                    busy = not all(s["converged"] for s in self._live(state))
                    if not self._pending and (not busy or not self._watching()):
                        self._wake.wait(IDLE_WAIT_S)
                    if self._stop:
                        return
                    pending, self._pending = self._pending, {}
                self._apply(pending, views, state)
                for key, vp in list(views.items()):
                    if key == "B" and not self.view["ab"]:
                        continue
                    s = state[key]
                    if (not s["converged"] or s["fresh"]) and self._watching():
                        self._step(key, vp, s)
                        break  # one pass, then look at the queue again
        except Exception as exc:  # shown on the page; the server keeps serving
            self.error = f"{type(exc).__name__}: {exc}"
            self._publish("error", b"", {"error": self.error})
        finally:
            for vp in views.values():
                vp.close()

    def _live(self, state: dict[str, Any]) -> list[dict[str, Any]]:
        return [state["A"]] + ([state["B"]] if self.view["ab"] else [])

    def _apply(self, pending: dict[str, Any], views: dict[str, Any], state: dict) -> None:
        self.version = pending.get("version", self.version)
        for key, name in (("material", "A"), ("reference", "B")):
            if key in pending:
                if name not in views:
                    views[name] = self._factory(pending[key], **self._view_kwargs())
                    self._replay(views[name])
                else:
                    views[name].update_material(pending[key])
                state[name].update(converged=False, fresh=True)
        for key in ("raw", "ab"):
            if key in pending:
                self.view[key] = bool(pending[key])
                state["A"]["fresh"] = True
        for key in VIEW_KEYS:
            if key in pending:
                self.view[key] = pending[key]
                for name, vp in views.items():
                    _set_view(vp, key, pending[key])
                    state[name].update(
                        fresh=True, converged=key == "exposure" and state[name]["converged"]
                    )

    def _view_kwargs(self) -> dict[str, Any]:
        out = {k: self.view[k] for k in ("mode", "ibl") if k in self.view}
        if "size" in self.view:
            out["width"], out["height"] = self.view["size"]
        return out

    def _replay(self, vp: Any) -> None:
        for key in ("rotate_ibl", "rotate_element", "exposure"):
            if key in self.view:
                _set_view(vp, key, self.view[key])

    def _step(self, key: str, vp: Any, s: dict[str, Any]) -> None:
        start = time.perf_counter()
        with _PASS_LOCK:
            frame = vp.step()
        shown = vp.raw() if self.view["raw"] and frame.denoised else frame
        s.update(converged=bool(frame.converged), fresh=False)
        meta = {
            "view": key,
            "version": self.version,
            "spp": int(frame.spp),
            "mode": frame.mode,
            "denoised": bool(shown.denoised),
            "converged": bool(frame.converged),
            "ms": round((time.perf_counter() - start) * 1000.0, 1),
            "width": int(frame.display.shape[1]),
            "height": int(frame.display.shape[0]),
        }
        self._publish(key, encode(shown.display), meta)


def _set_view(vp: Any, key: str, value: Any) -> None:
    if key == "mode":
        vp.set_mode(value)
    elif key == "ibl":
        vp.set_ibl(value)
    elif key == "rotate_ibl":
        vp.rotate_ibl(float(value))
    elif key == "rotate_element":
        vp.rotate_element(float(value))
    elif key == "exposure":
        vp.set_exposure(float(value))
    elif key == "size":
        vp.resize(int(value[0]), int(value[1]))
