"""``lookdev.designer(...)``: the Material Designer from Python (and from a notebook).

The interactive loop of :cite:`Burley2012` §6.1: a local web page whose viewport relights the
material as every parameter and layer is edited, saving presets into the library.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

__all__ = ["DesignerHandle", "designer"]


class DesignerHandle:
    """A designer running on a background thread (``block=False``): its ``url``, and
    :meth:`stop`. In a notebook the handle shows as a link to the page."""

    def __init__(self, app: Any, stop: Any):
        self.designer = app
        self._stop = stop

    @property
    def url(self) -> str:
        return self.designer.url

    def stop(self) -> None:
        """Stop the server and its renderer."""
        self._stop()

    def _repr_html_(self) -> str:
        return f'<a href="{self.url}" target="_blank">lookdev designer: {self.url}</a>'

    def __repr__(self) -> str:
        return f"DesignerHandle({self.url!r})"


def designer(
    presets: Any = None,
    *,
    library: Any = None,
    ibl: str = "studio",
    geometry: str | Path | None = None,
    port: int | None = None,
    open_browser: bool = False,
    block: bool = True,
    size: tuple[int, int] = (480, 270),
) -> DesignerHandle | None:
    """Start the Material Designer on 127.0.0.1 and print its URL (with its token).

    Parameters
    ----------
    presets
        A preset name or ``.toml`` file, or several: the first is opened.
    library
        Extra preset folders searched (and saved into) before the built-ins.
    ibl
        A built-in IBL name or an ``.exr``/``.hdr`` file lighting the viewport.
    geometry
        A mesh in the proof scene's place (as ``proof --geometry`` takes).
    port
        The port; default a free one.
    open_browser
        Open the page in the default browser.
    block
        True: serve until Ctrl-C. False: serve on a background thread and return a
        :class:`DesignerHandle` (a notebook goes on running cells).
    size
        Viewport pixels (width, height).
    """
    from lookdev.pipeline.designer.server import Designer
    from lookdev.pipeline.proof import ibl as ibls

    from .materials import library_for

    ibls.load(ibl, 64)  # an unknown IBL is one line now, not an error in the page later
    if geometry is not None and not Path(geometry).is_file():
        from lookdev.materials.errors import LookdevError

        raise LookdevError("no such mesh file", where=str(geometry), field="--geometry")
    if isinstance(presets, str | Path):
        presets = [presets]
    app = Designer(
        [str(p) for p in presets or []],
        library=library_for(library),
        ibl=ibl,
        geometry=None if geometry is None else str(geometry),
        port=port,
        size=size,
    )
    print(f"lookdev designer: {app.url}", flush=True)
    if open_browser:
        import webbrowser

        webbrowser.open(app.url)
    if block:
        app.serve()
        return None
    return DesignerHandle(app, app.serve_in_background())
