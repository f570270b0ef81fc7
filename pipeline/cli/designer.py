"""``lookdev designer``: the Material Designer, a local web page (:cite:`Burley2012` §6.1)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

__all__ = ["designer"]


def designer(
    presets: Annotated[
        list[str] | None,
        typer.Argument(
            metavar="[PRESET|FILE]…",
            help="Preset names or .toml files; the first is opened (default plastic_glossy).",
        ),
    ] = None,
    library: Annotated[
        list[Path] | None,
        typer.Option(
            "--library",
            "-L",
            help="Preset folders searched before the built-ins; the first is where "
            "'Save as new' writes.",
        ),
    ] = None,
    ibl: Annotated[
        str, typer.Option("--ibl", help="A built-in IBL name or an .exr/.hdr file.")
    ] = "studio",
    geometry: Annotated[
        Path | None,
        typer.Option(
            "--geometry", help="A mesh (PLY, OBJ, USD) in the proof scene's place.", dir_okay=False
        ),
    ] = None,
    port: Annotated[
        int | None,
        typer.Option(
            "--port", min=1024, max=65535, help="Port on 127.0.0.1 (default: a free one)."
        ),
    ] = None,
    open_browser: Annotated[
        bool, typer.Option("--open", help="Open the page in the default browser.")
    ] = False,
) -> None:
    """Develop a look interactively: sliders, layers and the library around a live viewport.

    Starts a web server on 127.0.0.1 only and prints its URL, which carries a per-session
    token: keep it to yourself (anyone with it can edit your library). The page works
    offline. Ctrl-C stops it.

    Example:

      lookdev designer gold -L ~/looks --open
    """
    import lookdev

    lookdev.designer(
        presets or None,
        library=library,
        ibl=ibl,
        geometry=geometry,
        port=port,
        open_browser=open_browser,
    )
