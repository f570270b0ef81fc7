"""The ``lookdev`` command line (Typer).

Commands are verbs; each group lives in its own module beside this one and is added in
:func:`_register`. Bad input anywhere ends in one line on stderr and exit code 2
(DESIGN.md, Errors): commands raise :class:`~lookdev.materials.errors.LookdevError` and
:func:`main` turns it into that line.
"""

from __future__ import annotations

import sys
from importlib import metadata

import typer

from lookdev.materials.errors import LookdevError

from .common import err_console

app = typer.Typer(
    name="lookdev",
    help="Author, blend, export and proof Disney and Pixar materials.",
    no_args_is_help=True,
    pretty_exceptions_enable=False,
    add_completion=False,
)


def _version(value: bool) -> None:
    if value:
        typer.echo(f"lookdev {metadata.version('lookdev')}")
        raise typer.Exit()


@app.callback()
def _root(
    version: bool = typer.Option(
        False, "--version", callback=_version, is_eager=True, help="Print the version and exit."
    ),
) -> None:
    """lookdev: material presets in, USD networks and Mitsuba proofs out."""


def _register() -> None:
    from . import bench, check, export, export_usd, plot, presets, proof
    from . import blend as blend_cli

    app.add_typer(bench.app, name="bench")
    app.command("check")(check.check)
    app.command("blend")(blend_cli.blend)
    app.add_typer(export.app, name="export")
    export.app.command("usd")(export_usd.export_usd)
    app.add_typer(export_usd.import_app, name="import")
    app.add_typer(export_usd.validate_app, name="validate")
    app.add_typer(presets.app, name="presets")
    app.command("plot")(plot.plot)
    app.command("proof")(proof.proof)
    _reflow_help(app)


def _reflow_help(typer_app: typer.Typer) -> None:
    # Rich mode keeps every docstring line break, so help wraps raggedly in narrow
    # terminals; markdown mode reflows paragraphs and keeps blank-line breaks.
    typer_app.rich_markup_mode = "markdown"
    for group in typer_app.registered_groups:
        _reflow_help(group.typer_instance)


_register()


def main(argv: list[str] | None = None) -> None:
    """Entry point of the ``lookdev`` script; ``argv`` defaults to ``sys.argv[1:]``."""
    try:
        app(args=argv, prog_name="lookdev")
    except LookdevError as exc:
        err_console.print(f"lookdev: error: {exc}", markup=False, highlight=False, soft_wrap=True)
        sys.exit(2)
    except KeyboardInterrupt:
        err_console.print("lookdev: interrupted", markup=False)
        sys.exit(130)
