"""``lookdev import usd``: UsdShade materials written by other tools, read back as presets."""

from __future__ import annotations

from enum import StrEnum
from pathlib import Path
from typing import Annotated

import typer

from .common import console, print_json

__all__ = ["PARTLY_IMPORTED", "ImportOpenPBR", "import_app", "import_usd"]

import_app = typer.Typer(
    help="Read materials written by other tools back into presets.", no_args_is_help=True
)


class ImportOpenPBR(StrEnum):
    disney = "disney"
    itself = "itself"


@import_app.command("usd")
def import_usd(
    file: Annotated[Path, typer.Argument(help="USD file with UsdShade materials.")],
    output: Annotated[
        Path | None,
        typer.Option(
            "--output",
            "-o",
            help="Preset .toml to write (a folder when the file holds several materials; "
            "made if missing); default: print the TOML.",
        ),
    ] = None,
    force: Annotated[
        bool, typer.Option("--force", help="Replace preset files of the same name in -o.")
    ] = False,
    rename: Annotated[
        bool,
        typer.Option(
            "--rename",
            help="Import a material whose name another material of the file, a preset in "
            "-o, or (when -o is a library folder) a library preset has as NAME_imported "
            "(default: refuse; --force replaces a preset in -o instead).",
        ),
    ] = False,
    openpbr: Annotated[
        ImportOpenPBR,
        typer.Option(
            "--openpbr",
            help="OpenPBR Surface materials from other tools: 'disney' (translated to "
            "Burley's parameters, losses named) or 'itself' (an openpbr preset holding "
            "its inputs as they are, proofed by lookdev's OpenPBR model; a Standard "
            "Surface becomes one by MaterialX's own translation to OpenPBR).",
        ),
    ] = ImportOpenPBR.disney,
    as_json: Annotated[bool, typer.Option("--json", help="Print one JSON object.")] = False,
) -> None:
    """Read materials from a USD file back into presets.

    Reads UsdPreviewSurface, OpenPBR, Standard Surface and glTF PBR networks from any tool
    (values followed through the Material's interface inputs), and gives a lookdev
    export back exactly (its preset travels in the Material's customData). A parameter
    fed by a texture becomes the preset's texture table for it (file, channel, colour
    space, scale/offset, wrap; under "maps" with --json); what a preset cannot hold (alpha and
    cut-outs, normal, emission, occlusion, a specular-workflow conversion) is printed
    and listed as "# loss:" lines. A name another material of the file has, or (when
    -o is a folder of the library) a library preset elsewhere has, is refused unless
    --rename.

    Examples:

      lookdev import usd gold.usda

      lookdev import usd library.usda -o imported/

    Foreign files import as far as they can: a material that cannot become a preset (a
    layered Pixar material, a surface lookdev does not read) is skipped and a value a
    preset would reject (out of range, NaN, infinity; never clamped) refuses its
    material, each in one line on stderr naming the prim, the field and the value, and
    the others are written. An input on a lobe whose weight is 0 is not read. An existing
    preset file is replaced only with --force.

    Exit status: 0 every material imported; 3 partly imported (some written, some
    skipped or refused: the lines say which); 2 bad input (nothing importable, a file
    that is not USD, a name clash, an unwritable -o).
    """
    from lookdev.pipeline.export.usd.presets import import_names, screen, write_presets
    from lookdev.pipeline.export.usd.reader import import_usd as read

    skipped: list[str] = []
    refused: list[str] = []
    found = read(file.expanduser(), skipped, refused)
    if openpbr is ImportOpenPBR.itself:
        from lookdev.pipeline.export.usd.reader import import_as_openpbr

        not_openpbr: list[str] = []
        itself = import_as_openpbr(file.expanduser(), not_openpbr)
        for m in found:  # OpenPBR's ranges refuse it: it stays Burley's, and says why
            why = [line for line in not_openpbr if line.startswith(f"{m.prim}:")]
            if m.name not in itself and why:
                m.loss.append(f"mtlx: read as Burley's, not as OpenPBR ({why[0]})")
        found = [itself.get(m.name, m) for m in found]
    found = screen(found, refused)
    if not found:
        from lookdev.pipeline.export.usd.network import ExportError

        raise ExportError("no material to import: refused " + "; ".join(refused), where=str(file))
    names = import_names(found, _taken_names(output, rename), rename=rename)
    written = write_presets(found, output, force=force, names=names)
    if as_json:
        print_json(
            {
                "file": str(file),
                "materials": [
                    {
                        "name": m.name,
                        "prim": m.prim,
                        "preset": name,
                        "model": m.model,
                        "params": m.params,
                        "maps": {
                            k: v.model_dump(mode="json", exclude_defaults=True)
                            | {"texture": v.texture}
                            for k, v in m.maps.items()
                        },
                        "contexts": m.contexts,
                        "loss": m.loss,
                    }
                    for m, name in zip(found, names, strict=True)
                ],
                "written": [str(p) for p in written],
                "skipped": skipped,
                "refused": refused,
            }
        )
    elif output is None:
        from lookdev.pipeline.export.usd.presets import preset_toml

        for m, name in zip(found, names, strict=True):
            typer.echo(preset_toml(m, name))
    else:
        for path, m in zip(written, found, strict=True):
            console.print(f"wrote [bold]{path}[/]")
            for line in m.loss:
                console.print(f"  loss: {line}", markup=False, highlight=False)
    if skipped or refused:
        for line in skipped:  # one line each, never wrapped
            typer.echo(f"lookdev: skipped {line}", err=True)
        for line in refused:
            typer.echo(f"lookdev: refused {line}", err=True)
        total = len(found) + len(skipped) + len(refused)
        typer.echo(f"lookdev: partly imported: {len(found)} of {total} materials", err=True)
        raise typer.Exit(PARTLY_IMPORTED)


PARTLY_IMPORTED = 3
"""``lookdev import usd``'s exit status when some materials were written and some not."""


def _taken_names(output: Path | None, rename: bool) -> set[str]:
    """Preset names an import into ``output`` must not take.

    When ``output`` is a folder of the library's search path, a preset of the same name
    elsewhere in the library would shadow it or be shadowed: refused (or renamed). With
    ``rename``, the presets already in ``output`` are avoided too (without it, replacing
    one is ``--force``'s business).
    """
    if output is None:
        return set()
    from lookdev.library import Library

    target = output.expanduser()
    folder = (target.parent if target.suffix == ".toml" else target).resolve()
    taken: set[str] = set()
    if rename and folder.is_dir():
        taken |= {p.stem for p in folder.glob("*.toml")}
    library = Library()
    if any(folder == f.resolve() for f in library.folders if f.is_dir()):
        for name in library.names():
            if library.find(name).resolve().parent != folder:
                taken.add(name)
    return taken
