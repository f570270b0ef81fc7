"""The designer's HTTP routes (all behind :class:`~.server.GuardMiddleware`).

JSON in and out; a :class:`~lookdev.materials.errors.LookdevError` becomes ``422`` with
its one-line message (the page shows it beside the control that caused it), so nothing
the page sends can end in a traceback. Files are read only through :class:`~.guard.Roots`.
"""

from __future__ import annotations

import asyncio
import json
import math
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Any

from starlette.requests import Request
from starlette.responses import FileResponse, HTMLResponse, JSONResponse, Response
from starlette.routing import Route

from lookdev.materials.errors import LookdevError

from . import library_panel, previews, tasks
from .controls import mask_kinds, texture_fields
from .session import EditRefused

__all__ = ["IMAGE_SUFFIXES", "PLOT_VIEWS", "STATIC", "routes", "view_changes"]

STATIC = Path(__file__).with_name("static")
IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg", ".exr", ".tif", ".tiff", ".hdr", ".tx")
PLOT_VIEWS = ("slice", "polar", "albedo")
MAX_BODY = 1 << 20
THUMBNAILS = ThreadPoolExecutor(max_workers=1, thread_name_prefix="designer-thumbnails")
MODES = ("designer", "truth")
SIZE_MAX = 1920


def routes(d: Any) -> list[Route]:
    """The routes of designer ``d`` (a :class:`~.server.Designer`)."""

    async def index(request: Request) -> Response:
        return HTMLResponse((STATIC / "index.html").read_text(encoding="utf-8"))

    async def state(request: Request) -> Response:
        out = d.session.state()
        out["roots"] = d.roots.names()
        out["writable"] = [str(f) for f in d.library.user_folders]
        return JSONResponse(out)

    async def meta(request: Request) -> Response:
        return JSONResponse(
            {
                "masks": mask_kinds(),
                "texture_fields": texture_fields(),
                "plot_views": list(PLOT_VIEWS),
                "modes": list(MODES),
            }
        )

    async def library(request: Request) -> Response:
        return JSONResponse(await asyncio.to_thread(library_panel.entries, d.library))

    async def thumbnail(request: Request) -> Response:
        name = request.path_params["name"]
        # its own thread: seventy thumbnails queued must not starve the edits' threads
        path = await asyncio.get_running_loop().run_in_executor(
            THUMBNAILS, library_panel.thumbnail, d.library, name, d.folder / "thumbnails"
        )
        return FileResponse(path, media_type="image/png")

    async def browse(request: Request) -> Response:
        q = request.query_params
        root = q.get("root") or d.roots.names()[0]
        listing = await asyncio.to_thread(d.roots.listing, root, q.get("path", ""), IMAGE_SUFFIXES)
        return JSONResponse(listing | {"roots": d.roots.names()})

    async def preview(request: Request) -> Response:
        q = request.query_params
        target = None if q.get("target", "") in ("", "null") else int(q["target"])
        mask = await asyncio.to_thread(previews.mask_of, d.session, target, q.get("field", ""))
        data = await asyncio.to_thread(previews.preview_png, mask)
        return Response(data, media_type="image/png", headers={"Cache-Control": "no-store"})

    async def files(request: Request) -> Response:
        path = d.roots.resolve(request.path_params["root"], request.path_params["path"])
        if not path.is_file():
            return JSONResponse({"error": "no such file"}, status_code=404)
        return FileResponse(path)

    async def edit(request: Request) -> Response:
        op = await _body(request)
        await asyncio.to_thread(d.session.edit, op)
        return await _changed(d)

    async def undo(request: Request) -> Response:
        await asyncio.to_thread(d.session.undo)
        return await _changed(d)

    async def redo(request: Request) -> Response:
        await asyncio.to_thread(d.session.redo)
        return await _changed(d)

    async def open_(request: Request) -> Response:
        body = await _body(request)
        await asyncio.to_thread(d.session.open, _name(body.get("name")))
        return await _changed(d)

    async def new_layered(request: Request) -> Response:
        body = await _body(request)
        await asyncio.to_thread(d.session.replace, _layered_doc(d.session, body))
        return await _changed(d)

    async def hide(request: Request) -> Response:
        body = await _body(request)
        d.session.set_hidden(int(body.get("index", -1)), bool(body.get("hidden")))
        return await _changed(d)

    async def save(request: Request) -> Response:
        body = await _body(request)
        over = body.get("mode") == "over"
        name = None if over else _name(body.get("name"))

        def run() -> tuple[Any, list[str]]:
            with d.session.lock:  # this save's messages, not a later one's
                path = d.session.save_over() if over else d.session.save_new(name)
                return path, list(d.session.save_messages)

        path, copied = await asyncio.to_thread(run)
        d.broadcast({"type": "state", "version": d.session.version})
        return JSONResponse({"saved": str(path), "name": d.session.name, "copied": copied})

    async def plot(request: Request) -> Response:
        view = request.path_params["view"]
        if view not in PLOT_VIEWS:
            raise LookdevError(f"unknown view {view!r}; allowed {', '.join(PLOT_VIEWS)}")
        data = await asyncio.to_thread(tasks.plot, d, view)
        return Response(data, media_type="image/png", headers={"Cache-Control": "no-store"})

    async def losses(request: Request) -> Response:
        return JSONResponse(await asyncio.to_thread(tasks.losses, d))

    async def proof(request: Request) -> Response:
        return JSONResponse(tasks.start_proof(d))

    async def task(request: Request) -> Response:
        return JSONResponse(tasks.status(d, request.path_params["id"]))

    async def export_usd(request: Request) -> Response:
        return JSONResponse(await asyncio.to_thread(tasks.export_usd, d))

    table = [
        ("/", index, ["GET"]),
        ("/api/state", state, ["GET"]),
        ("/api/meta", meta, ["GET"]),
        ("/api/library", library, ["GET"]),
        ("/api/thumbnail/{name}.png", thumbnail, ["GET"]),
        ("/api/browse", browse, ["GET"]),
        ("/api/preview.png", preview, ["GET"]),
        ("/files/{root}/{path:path}", files, ["GET"]),
        ("/api/edit", edit, ["POST"]),
        ("/api/undo", undo, ["POST"]),
        ("/api/redo", redo, ["POST"]),
        ("/api/open", open_, ["POST"]),
        ("/api/new_layered", new_layered, ["POST"]),
        ("/api/hide", hide, ["POST"]),
        ("/api/save", save, ["POST"]),
        ("/api/plot/{view}.png", plot, ["GET"]),
        ("/api/losses", losses, ["GET"]),
        ("/api/proof", proof, ["POST"]),
        ("/api/task/{id}", task, ["GET"]),
        ("/api/export_usd", export_usd, ["POST"]),
    ]
    return [Route(path, _answering(fn), methods=methods) for path, fn, methods in table]


def _answering(fn):
    """``fn`` with the library's errors as 422 and one line, never a traceback; an edit
    the schema refuses is a normal answer (``{"refused": message}``), not an HTTP error."""

    async def wrapped(request: Request) -> Response:
        try:
            return await fn(request)
        except EditRefused as exc:  # an answer, not a failure: the page shows it in place
            return JSONResponse({"refused": str(exc)})
        except LookdevError as exc:
            return JSONResponse({"error": str(exc)}, status_code=422)
        except (ValueError, TypeError) as exc:
            return JSONResponse({"error": f"bad request: {exc}"}, status_code=400)

    return wrapped


async def _body(request: Request) -> dict[str, Any]:
    data = await request.body()
    if len(data) > MAX_BODY:
        raise ValueError("request too large")
    body = json.loads(data or b"{}")
    if not isinstance(body, dict):
        raise ValueError("expected a JSON object")
    return body


async def _changed(d: Any) -> Response:
    await asyncio.to_thread(d.material_changed)
    return JSONResponse(d.session.state())


def _name(value: Any) -> str:
    from lookdev.library.preset import check_name

    return check_name(value, field=None)


def _layered_doc(session: Any, body: dict[str, Any]) -> dict[str, Any]:
    """A new layered preset whose first layer is the material on screen: the preset
    opened, with this session's changes as the layer's overrides."""
    base = session.parent_name or session.name
    layer: dict[str, Any] = {"name": base, "preset": base}
    params = {
        k: v
        for k, v in session.doc.get("params", {}).items()
        if session.original.get("params", {}).get(k) != v
    }
    if session.doc.get("layers"):
        raise LookdevError("this preset is layered already: add layers to it")
    if params:
        layer["params"] = params
    return {"name": _name(body.get("name") or "untitled"), "model": "layered", "layers": [layer]}


def view_changes(message: dict[str, Any]) -> dict[str, Any]:
    """The viewport changes a websocket message asks for, checked (bad ones dropped)."""
    out: dict[str, Any] = {}
    for key in ("rotate_ibl", "rotate_element", "exposure"):
        value = message.get(key)
        if isinstance(value, int | float) and math.isfinite(value):
            out[key] = float(value) if key != "exposure" else max(-16.0, min(16.0, value))
    if message.get("mode") in MODES:
        out["mode"] = message["mode"]
    if message.get("ab_against") in ("opened", "parent"):
        out["ab_against"] = message["ab_against"]
    for key in ("raw", "ab"):
        if isinstance(message.get(key), bool):
            out[key] = message[key]
    size = message.get("size")
    if isinstance(size, list) and len(size) == 2 and all(isinstance(v, int) for v in size):
        out["size"] = (max(16, min(SIZE_MAX, size[0])), max(16, min(SIZE_MAX, size[1])))
    return out
