"""``lookdev colour``: what the OpenColorIO config in force offers, by the names it uses.

The names listed here are what ``--working-space``, a texture's ``colorspace``, and the
global ``--display``/``--view``/``--look`` options accept (aliases too, and display,
view and look names without regard to case).
"""

from __future__ import annotations

from typing import Annotated, Any

import typer

from .common import console, print_json, table

__all__ = ["app", "spaces", "views"]

app = typer.Typer(
    help="List the colour spaces, displays, views and looks of the OCIO config in force "
    "(--config, $OCIO, or the built-in ACES 2.0 studio config).",
    no_args_is_help=True,
)

JsonOption = Annotated[bool, typer.Option("--json", help="Print one JSON object for scripts.")]


def _header() -> dict[str, Any]:
    from lookdev.materials import colour

    return {"config": colour.settings().config_name, "working_space": colour.working_space()}


@app.command("spaces")
def spaces(as_json: JsonOption = False) -> None:
    """The config's colour spaces: name, family, data or colour, aliases.

    The working space is marked; `lookdev --working-space NAME …` picks another.
    """
    from lookdev.materials import colour

    cfg = colour.config()
    rows = []
    for name in colour.spaces():
        cs = cfg.getColorSpace(name)
        rows.append(
            {
                "name": name,
                "family": cs.getFamily(),
                "data": bool(cs.isData()),
                "working": name == colour.working_space(),
                "aliases": list(cs.getAliases()),
            }
        )
    if as_json:
        print_json(_header() | {"spaces": rows})
        return
    shown = [
        [
            ("* " if r["working"] else "  ") + r["name"],
            r["family"],
            "data" if r["data"] else "",
            ", ".join(r["aliases"][:3]),
        ]
        for r in rows
    ]
    head = _header()
    title = f"{head['config']} (* working space: {head['working_space']})"
    console.print(table(title, ["colour space", "family", "", "aliases"], shown))


@app.command("views")
def views(
    display: Annotated[
        str | None, typer.Option("--display", help="Only this display's views.")
    ] = None,
    as_json: JsonOption = False,
) -> None:
    """The config's displays and their views, and its looks; the ones in force marked.

    `lookdev --display D --view V --look L COMMAND …` shows PNGs, contact sheets, plots
    and the review page through them.
    """
    from lookdev.materials import colour

    with colour.use(display=display):
        current = (colour.display(), colour.view(), colour.look())
        shown = [colour.display()] if display else colour.displays()
        rows = [
            {"display": d, "views": colour.views(d), "default_view": colour.views(d)[0]}
            for d in shown
        ]
    in_force = {"display": current[0], "view": current[1], "look": current[2]}
    if as_json:
        print_json(_header() | {"in_force": in_force, "displays": rows, "looks": colour.looks()})
        return
    lines = [
        [
            ("* " if r["display"] == current[0] else "  ") + r["display"],
            "; ".join(
                ("*" if r["display"] == current[0] and v == current[1] else "") + v
                for v in r["views"]
            ),
        ]
        for r in rows
    ]
    console.print(table(f"{_header()['config']} (* in force)", ["display", "views"], lines))
    console.print(f"looks: {', '.join(colour.looks()) or 'none'}", highlight=False)
