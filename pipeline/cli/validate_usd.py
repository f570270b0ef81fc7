"""``lookdev validate usd``: exported files checked the way the tools that read them will."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from .common import console, print_json, table

__all__ = ["validate_app", "validate_usd"]

validate_app = typer.Typer(
    help="Check exported files the way the tools that read them will.", no_args_is_help=True
)


@validate_app.command("usd")
def validate_usd(
    file: Annotated[Path, typer.Argument(help="USD file to check.")],
    as_json: Annotated[bool, typer.Option("--json", help="Print one JSON object.")] = False,
) -> None:
    """Run every validator usd-core registers, and MaterialX's own check on mtlx networks.

    usd-core cannot know MaterialX (ND_*) or RenderMan (Pxr*) shader ids, so their
    MissingShaderIdInRegistry errors are expected and listed apart; every other error
    fails. Every authored shader input is also checked against its node's definition
    (renderers ignore an unknown input silently): Pxr* against RenderMan's input names
    kept with lookdev, ND_* against MaterialX's node definitions, UsdPreviewSurface and
    UsdUVTexture against usd-core's Sdr registry. Exit code 0 when valid, 1 when not.
    """
    from lookdev.pipeline.export.usd.validate import validate_usd as check

    report = check(file.expanduser())
    if as_json:
        print_json(
            {
                "file": report.path,
                "ok": report.ok,
                "validators": report.validators,
                "errors": report.errors,
                "warnings": report.warnings,
                "allowed": report.allowed,
                "mtlx_networks": report.mtlx_networks,
                "inputs_checked": report.inputs_checked,
            }
        )
    else:
        rows = [
            ["errors", len(report.errors)],
            ["warnings", len(report.warnings)],
            ["expected (MaterialX/RenderMan ids)", len(report.allowed)],
            ["MaterialX networks checked", report.mtlx_networks],
            ["shader inputs checked against their node's definition", report.inputs_checked],
        ]
        console.print(table(f"{file} — {report.validators} validators", ["check", "count"], rows))
        for line in report.errors + report.warnings:
            console.print(f"  {line}", markup=False, highlight=False)
        console.print("[green]valid[/]" if report.ok else "[red]not valid[/]")
    if not report.ok:
        raise typer.Exit(1)
