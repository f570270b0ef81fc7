"""The designer's web server: Starlette on uvicorn, bound to loopback, one session.

Every URL lives under ``/<token>/`` (so the page's relative links, its images and its
websocket carry the token without a cookie); :class:`GuardMiddleware` refuses anything
else, a foreign ``Host`` (DNS rebinding) and a foreign ``Origin`` before any route runs.
HTTP routes are in :mod:`.routes`; the websocket here streams the viewport's frames and
takes the view controls (rotation, exposure, mode, raw/denoised, A/B). Edits go through
HTTP so each gets its own answer (accepted, or refused with the schema's message); every
tab of the session is told of each change over its websocket, so two tabs stay in step.
"""

from __future__ import annotations

import asyncio
import contextlib
import json
import socket
import tempfile
import threading
from pathlib import Path
from typing import Any

from starlette.applications import Starlette
from starlette.responses import PlainTextResponse
from starlette.routing import Mount, WebSocketRoute
from starlette.staticfiles import StaticFiles
from starlette.websockets import WebSocket, WebSocketDisconnect

from lookdev.library import Library

from .guard import Guard, Roots, new_token
from .routes import STATIC
from .session import Session

__all__ = ["DEFAULT_SIZE", "Designer", "GuardMiddleware", "free_port"]

HOST = "127.0.0.1"
DEFAULT_SIZE = (480, 270)
CLIENT_QUEUE = 2
"""Frames a page may have waiting; past that a new frame is dropped (the one after it is
newer still). News (a state version, a task) is never dropped: a tab that missed a state
message would wait for it forever once the frames stop."""


def free_port() -> int:
    """A port the OS says is free on loopback now."""
    with socket.socket() as s:
        s.bind((HOST, 0))
        return s.getsockname()[1]


class GuardMiddleware:
    """ASGI middleware: token as the first path segment (or header), Host and Origin."""

    def __init__(self, app: Any, guard: Guard):
        self.app = app
        self.guard = guard

    async def __call__(self, scope, receive, send):
        if scope["type"] not in ("http", "websocket"):
            return await self.app(scope, receive, send)
        headers = {k.decode("latin-1"): v.decode("latin-1") for k, v in scope["headers"]}
        path = scope["path"]
        first, _, rest = path.lstrip("/").partition("/")
        reason = self.guard.check(headers, first)
        if reason is None and not self.guard.token_ok(first):
            rest = path.lstrip("/")  # token in the header: the whole path is the route
        if reason is not None:
            if scope["type"] == "websocket":
                await send({"type": "websocket.close", "code": 1008, "reason": reason})
                return None
            response = PlainTextResponse(f"refused: {reason}\n", status_code=403)
            return await response(scope, receive, send)
        scope = dict(scope, path="/" + rest, root_path="")
        return await self.app(scope, receive, send)


class Designer:
    """One designer: its library, session, token, folders, render thread and app."""

    def __init__(
        self,
        presets: list[str] | None = None,
        *,
        library: Library,
        ibl: str = "studio",
        geometry: str | None = None,
        port: int | None = None,
        folder: Path | None = None,
        size: tuple[int, int] = DEFAULT_SIZE,
        viewport_factory: Any = None,
    ):
        self.library = library
        self.port = port or free_port()
        self.token = new_token()
        self.guard = Guard(self.token, port=self.port)
        self._scratch = None
        if folder is None:
            self._scratch = tempfile.TemporaryDirectory(prefix="lookdev-designer-")
            folder = Path(self._scratch.name)
        self.folder = Path(folder)
        for sub in ("thumbnails", "exports", "proofs", "plots"):
            (self.folder / sub).mkdir(parents=True, exist_ok=True)
        roots = {f"library{i}": p for i, p in enumerate(library.user_folders) if p.is_dir()}
        if library.builtin is not None:
            roots["builtin"] = library.builtin
        roots["session"] = self.folder
        self.roots = Roots(roots)
        self.presets = list(presets or [])
        self.session = Session(library, self.presets[0] if self.presets else None, roots=self.roots)
        self.ibl, self.geometry, self.size = ibl, geometry, size
        self._factory = viewport_factory
        self.clients: set[asyncio.Queue] = set()
        self.loop: asyncio.AbstractEventLoop | None = None
        self.renderer = None
        # Two tabs connecting at once both ask for the renderer from worker threads; one
        # must be made, not two (two render threads replaying Dr.Jit recordings at once
        # deadlocked: one held the GIL waiting on Dr.Jit, the other the reverse).
        self._renderer_lock = threading.Lock()
        self.tasks: dict[str, dict[str, Any]] = {}
        self.ab_against = "opened"
        self.proof_settings: dict[str, Any] = {}
        """Keyword arguments of :func:`lookdev.proof` for *Proof* (default: the main job's)."""
        self.app = self._build()
        _import_heavy_modules()

    @property
    def url(self) -> str:
        return f"http://{HOST}:{self.port}/{self.token}/"

    # -- app -------------------------------------------------------------------------------
    def _build(self):
        from . import routes

        app = Starlette(
            routes=[
                *routes.routes(self),
                WebSocketRoute("/ws", self._websocket),
                Mount("/static", StaticFiles(directory=STATIC), name="static"),
            ],
            lifespan=self._lifespan,
        )
        return GuardMiddleware(app, self.guard)

    @contextlib.asynccontextmanager
    async def _lifespan(self, app):
        self.loop = asyncio.get_running_loop()
        yield
        self.close()

    def close(self) -> None:
        """Stop the render thread (closing the viewports) and remove the scratch folder."""
        if self.renderer is not None:
            self.renderer.close()
            self.renderer = None
        if self._scratch is not None:
            self._scratch.cleanup()
            self._scratch = None

    # -- rendering -------------------------------------------------------------------------
    def _viewport(self, material, **kw):
        factory = self._factory
        if factory is None:
            from .viewport import Viewport as factory
        kw.setdefault("mode", "designer")
        kw.setdefault("ibl", self.ibl)
        kw.setdefault("width", self.size[0])
        kw.setdefault("height", self.size[1])
        return factory(material, geometry=self.geometry, **kw)

    def ensure_renderer(self) -> None:
        with self._renderer_lock:
            if self.renderer is None:
                from .render import Renderer

                self.renderer = Renderer(
                    self._viewport, self._publish, watching=lambda: bool(self.clients)
                )
                self.renderer.post(
                    material=self.session.hub(), ibl=self.ibl, version=self.session.version
                )

    def material_changed(self) -> None:
        """After an edit: the new blend to the viewport, the news to every tab."""
        if self.renderer is not None:
            with self.session.lock:  # the version of this blend, not of a later edit
                hub, version = self.session.hub(), self.session.version
            self.renderer.post(material=hub, version=version)
            if self.renderer.view.get("ab"):
                self.renderer.post(reference=self._reference())
        self.broadcast({"type": "state", "version": self.session.version})

    def _publish(self, kind: str, data: bytes, meta: dict[str, Any]) -> None:
        """From the render thread: hand a frame to the event loop for every client."""
        if self.loop is None:
            return
        message = {"type": "frame" if kind in ("A", "B") else kind, **meta}
        with contextlib.suppress(RuntimeError):  # loop closed while shutting down
            self.loop.call_soon_threadsafe(self._fan_out, message, data)

    def broadcast(self, message: dict[str, Any]) -> None:
        if self.loop is None:
            return
        with contextlib.suppress(RuntimeError):
            self.loop.call_soon_threadsafe(self._fan_out, message, b"")

    def _fan_out(self, message: dict[str, Any], data: bytes) -> None:
        frame = message["type"] == "frame"
        for queue in list(self.clients):
            if frame and queue.qsize() >= CLIENT_QUEUE:
                continue  # a slow page: no backlog of frames (see CLIENT_QUEUE)
            queue.put_nowait((message, data))

    async def _websocket(self, ws: WebSocket) -> None:
        await ws.accept()
        queue: asyncio.Queue = asyncio.Queue()  # bounded for frames only (_fan_out)
        self.clients.add(queue)
        await asyncio.to_thread(self.ensure_renderer)
        self.renderer.post(rotate_ibl=self.renderer.view.get("rotate_ibl", 0.0))
        sender = asyncio.create_task(_send_loop(ws, queue))
        try:
            while True:
                message = json.loads(await ws.receive_text())
                await asyncio.to_thread(self._view_message, message)
        except (WebSocketDisconnect, json.JSONDecodeError, RuntimeError):
            pass
        finally:
            self.clients.discard(queue)
            sender.cancel()

    def _view_message(self, message: dict[str, Any]) -> None:
        from .routes import view_changes

        changes = view_changes(message)
        if "ab_against" in changes:
            self.ab_against = changes.pop("ab_against")
            changes.setdefault("ab", bool(self.renderer.view.get("ab")))
        if changes.get("ab"):
            changes["reference"] = self._reference()
        if changes:
            self.renderer.post(**changes)

    def _reference(self):
        return self.session.hub(self.session.reference(self.ab_against))

    # -- running ---------------------------------------------------------------------------
    def _server(self):
        import uvicorn

        config = uvicorn.Config(
            self.app, host=HOST, port=self.port, log_level="warning", ws="websockets-sansio"
        )
        return uvicorn.Server(config)

    def serve(self) -> None:
        """Run until Ctrl-C: uvicorn closes the connections, the render thread closes the
        viewports, the scratch folder goes; then return (a stop, not a failure)."""
        try:
            self._server().run()
        except KeyboardInterrupt:  # uvicorn re-raises the SIGINT it shut down for
            pass
        finally:
            self.close()

    def serve_in_background(self, timeout: float = 30.0):
        """Serve on a daemon thread; returns ``stop()``, which ends it and the renderer."""
        import threading
        import time

        server = self._server()
        server.install_signal_handlers = lambda: None  # only the main thread may
        thread = threading.Thread(target=server.run, name="lookdev-designer", daemon=True)
        thread.start()
        deadline = time.monotonic() + timeout
        while not server.started and thread.is_alive() and time.monotonic() < deadline:
            time.sleep(0.02)

        def stop() -> None:
            server.should_exit = True
            thread.join(timeout)
            self.close()

        return stop


def _import_heavy_modules() -> None:
    """Import, on this thread, what the routes' worker threads will use: extension
    modules imported for the first time from several threads at once can deadlock on the
    import lock (seen here: usd-core's ``pxr`` in one thread, Pillow in another)."""
    import PIL.Image  # noqa: F401

    import lookdev.pipeline.analysis.plots  # noqa: F401
    import lookdev.pipeline.analysis.sphere  # noqa: F401
    import lookdev.pipeline.export.usd.writer  # noqa: F401
    import lookdev.pipeline.proof.tonemap  # noqa: F401


async def _send_loop(ws: WebSocket, queue: asyncio.Queue) -> None:
    with contextlib.suppress(Exception):  # the page went away mid-frame: stop quietly
        while True:
            message, data = await queue.get()
            await ws.send_text(json.dumps(message))
            if data:
                await ws.send_bytes(data)
