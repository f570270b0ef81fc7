"""``lookdev presets …``: browse, inspect, create, edit, validate and remove presets."""

from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import Annotated, Any

import typer

from lookdev.library import PresetError
from lookdev.library.library import Library, apply_changes, read_preset
from lookdev.library.toml_file import check_name
from lookdev.materials.model_names import PRESET_MODELS

from .common import console, err_console, print_json

__all__ = [
    "JsonOpt",
    "LibraryOpt",
    "TABLE_MAX_ROWS",
    "app",
    "list_",
    "new",
    "parse_assignments",
    "rm",
    "schema",
    "set_",
    "show",
    "validate",
]

# `presets list` reads headers only: the schemas (pydantic and the models, through
# lookdev.library.preset), Rich's syntax highlighting and the resolved views are imported
# by the commands that show or change a preset.

app = typer.Typer(
    help="Browse and edit material presets. Presets are TOML files found, in order, in each "
    "--library folder, then in LOOKDEV_LIBRARY_PATH (os.pathsep-separated), then in the "
    "built-in library; the first definition of a name wins. Writes go to the first user "
    "library; the built-in one is read-only.\n\n"
    'A preset with `extends = "parent"` takes the parent\'s parameters and overrides some '
    "(giving `ior` drops an inherited `specular` and vice versa); description, tags, source "
    "and layers are inherited unless given. A layer naming a layered preset brings its layers, "
    'masks multiplied. Colours are linear Rec.709 \\[r, g, b] or sRGB "#rrggbb", converted '
    "to the working space (`lookdev --working-space`).",
    no_args_is_help=True,
)

LibraryOpt = Annotated[
    list[Path] | None,
    typer.Option(
        "--library",
        "-L",
        help="Preset folder searched before LOOKDEV_LIBRARY_PATH and the built-ins; repeatable. "
        "The first one receives writes.",
    ),
]
TABLE_MAX_ROWS = 500
"""Longer listings print plain aligned columns: Rich takes seconds to lay out 10^4 rows."""

JsonOpt = Annotated[bool, typer.Option("--json", help="Print one JSON document for scripts.")]


@app.command("list")
def list_(
    tag: Annotated[
        list[str] | None,
        typer.Option(
            "--tag", "-t", help="Only presets with this tag; repeatable (all must match)."
        ),
    ] = None,
    model: Annotated[
        str | None, typer.Option("--model", "-m", help="Only this model: disney, pixar or layered.")
    ] = None,
    library: LibraryOpt = None,
    as_json: JsonOpt = False,
) -> None:
    """List the presets each name resolves to (files that fail to parse are warned about).

    Reads each file's header only, cached per library in .lookdev-index.json; run
    `presets validate` to check parameters and references too.

    Examples:

      lookdev presets list --tag metal

      lookdev presets list -L ~/looks --model layered --json
    """
    allowed = (*PRESET_MODELS, "layered")
    if model is not None and model not in allowed:
        raise PresetError(
            f"unknown model {model!r}; allowed: {', '.join(allowed)}", field="--model"
        )
    from lookdev.library import listing

    from .presets_view import text_table

    lib = Library(library)
    entries = lib.entries()
    broken = [h for h in entries if h.error]
    shown = listing.matching(entries, tag or [], model)
    for h in broken:
        err_console.print(
            f"lookdev: warning: {h.error}", markup=False, highlight=False, soft_wrap=True
        )
    if as_json:
        sys.stdout.write(listing.listing_json(shown, lib))
    elif len(shown) <= TABLE_MAX_ROWS:
        rows = [listing.row(h, lib) for h in shown]
        console.print(text_table(f"{len(rows)} presets", listing.COLUMNS, rows))
    else:
        sys.stdout.write(listing.listing_text(shown, lib))


@app.command()
def show(
    name: Annotated[str, typer.Argument(help="Preset name (or a path to a .toml file).")],
    resolved: Annotated[
        bool,
        typer.Option(
            "--resolved",
            "-r",
            help="Show every parameter after extends and defaults, with the file that set it.",
        ),
    ] = False,
    library: LibraryOpt = None,
    as_json: JsonOpt = False,
) -> None:
    """Show a preset as written, or --resolved; says which file won when several define NAME.

    Examples:

      lookdev presets show gold

      lookdev presets show brushed_steel --resolved
    """
    from lookdev.library.preset import preset_document

    from .presets_view import material_json, print_resolved

    lib = Library(library)
    path = Path(name) if name.endswith(".toml") else lib.find(name)
    preset = read_preset(path)
    explicit = name.endswith(".toml")
    others = [] if explicit else [p for p in lib.definitions(preset.name) if p != path]
    material = lib.load_file(path) if resolved else _textures_checked(lib, preset, path)
    links = lib.read_through(path)
    if as_json:
        doc: dict[str, Any] = {
            "name": preset.name,
            "file": str(path),
            "shadows": [str(p) for p in others],
            "read_through_links": {str(k): str(v) for k, v in links},
        }
        doc["preset"] = preset_document(preset)
        if material is not None:
            doc["resolved"] = material_json(material)
        print_json(doc)
        return
    if material is None and not sys.stdout.isatty():
        # Piped or redirected (`presets show gold > mine.toml`): the file as plain TOML, the
        # provenance as comments, no Rich wrapping, so the output parses and round-trips.
        text = path.read_text(encoding="utf-8-sig")
        provenance = [f"# {preset.name} from {path}", *(f"# shadows {p}" for p in others)]
        provenance += [f"# read through the symlink {link} -> {dest}" for link, dest in links]
        sys.stdout.write(
            "\n".join(provenance) + "\n" + text + ("" if text.endswith("\n") else "\n")
        )
        return
    console.print(f"[bold]{preset.name}[/] from {path}", highlight=False)
    for p in others:
        console.print(f"  shadows {p}", style="dim", highlight=False)
    for link, dest in links:
        console.print(f"  read through the symlink {link} -> {dest}", style="dim", highlight=False)
    if material is None:
        from rich.syntax import Syntax

        text = path.read_text(encoding="utf-8-sig")
        console.print(Syntax(text, "toml", theme="ansi_dark", word_wrap=True))
    else:
        print_resolved(material)


def _textures_checked(lib: Library, preset: Any, path: Path) -> None:
    """Check the textures a preset drives parameters with (files, tiles, channels, colour
    spaces, ranges) even when it is shown as written: a bad map is one line and exit 2
    here as in `proof` and `export`. Other problems of resolving (a missing parent) are
    left to --resolved, so a preset can still be shown as written. A preset that names
    neither a texture nor another preset has none to check, and is not resolved."""
    from lookdev.library.errors import TextureError
    from lookdev.library.preset import references_files
    from lookdev.materials.errors import LookdevError

    if not references_files(preset):
        return
    try:
        lib.load_file(path)
    except TextureError:
        raise
    except LookdevError:
        pass


@app.command()
def new(
    name: Annotated[str, typer.Argument(help="Name of the new preset (letters, digits, _ and -).")],
    parent: Annotated[
        str | None, typer.Option("--from", "-f", help="Preset to extend; its values are inherited.")
    ] = None,
    model: Annotated[
        str | None, typer.Option("--model", "-m", help="Model when not extending: disney or pixar.")
    ] = None,
    assignments: Annotated[
        list[str] | None,
        typer.Option(
            "--set",
            "-s",
            help='KEY=VALUE, VALUE in TOML (0.3, "#aa8844", [0.9, 0.6, 0.2]); repeatable.',
        ),
    ] = None,
    textures: Annotated[
        list[str] | None,
        typer.Option(
            "--textures",
            "-t",
            help="A texture set: 'maps/asset_*.png' (quoted; or the files) named "
            "asset_<channel>[.<UDIM>].ext with Substance Painter / Mari channel names; "
            "the preset gets textures = 'asset_<channel>.<UDIM>.png' (model disney).",
        ),
    ] = None,
    library: LibraryOpt = None,
    force: Annotated[
        bool, typer.Option("--force", help="Replace a preset of that name in the target library.")
    ] = False,
    as_json: JsonOpt = False,
) -> None:
    """Create preset NAME in the first --library folder, extending --from PARENT.

    With --textures, from a folder of painted maps: each file's channel name
    (BaseColor, Roughness, Metallic, Normal_OpenGL, Height, …) says which parameter it
    drives (lookdev.library.texture_sets), UDIM tiles are grouped into one <UDIM> set,
    and channels no parameter takes (Emissive, AO) are named.

    Examples:

      lookdev presets new worn_gold --from gold --set roughness=0.45 -L ~/looks

      lookdev presets new teal_plastic --model disney --set base_color='"#2a8c8c"' -L ~/looks

      lookdev presets new hero --textures 'maps/hero_*.png' -L ~/looks
    """
    check_name(name, field="NAME")
    if textures and parent is None and model is None:
        model = "disney"
    if (parent is None) == (model is None):
        raise PresetError(
            "give exactly one of --from PARENT or --model disney|pixar", field="--from"
        )
    lib = Library(library)
    if parent is not None:
        lib.find(parent)
    where = str(lib.target() / f"{name}.toml")
    from lookdev.library.preset import PresetFile

    fields = {"name": name, "model": model, "extends": parent, "params": {}}
    notes: list[str] = []
    if textures:
        fields["textures"], notes = _texture_set(textures, lib.target(), where)
    base = PresetFile.model_construct(**fields)
    preset = apply_changes(base, parse_assignments(assignments or []), where=where)
    path = lib.save(preset, force=force)
    _report("created", preset.name, path, as_json)
    for note in notes:
        err_console.print(f"note: {note}", highlight=False, markup=False)


def _texture_set(given: list[str], target: Path, where: str) -> tuple[str, list[str]]:
    """The ``textures =`` pattern (relative to the preset's folder) of the files
    ``given`` (globs expanded), and what the set leaves out."""
    import glob
    import os

    from lookdev.library.texture_sets import expand, from_files

    paths: list[Path] = []
    for item in given:
        item = os.path.expanduser(item)
        matched = sorted(glob.glob(item)) if any(c in item for c in "*?[") else [item]
        if not matched:
            raise PresetError(f"--textures {item!r} matches no files", field="--textures")
        paths += [Path(p) for p in matched]
    missing = [p for p in paths if not p.is_file()]
    if missing:
        raise PresetError(f"texture {missing[0]} does not exist", field="--textures")
    pattern, folder = from_files(paths)
    found = expand(pattern, folder, where=where)
    rel = os.path.relpath(folder.resolve(), target.resolve())
    if rel == ".." or rel.startswith(".." + os.sep):
        # maps kept outside the library: a relative path would leave it (lookdev.library.
        # containment), so the preset names them absolutely and stays valid when copied
        return Path(folder.resolve(), pattern).as_posix(), found.notes
    return Path(rel, pattern).as_posix(), found.notes


@app.command("set")
def set_(
    name: Annotated[str, typer.Argument(help="Preset to change, in a user library.")],
    assignments: Annotated[
        list[str],
        typer.Argument(
            metavar="KEY=VALUE…",
            help="Parameter or description/tags/source/extends; VALUE is TOML; an empty VALUE "
            "removes the key so it is inherited again.",
        ),
    ],
    library: LibraryOpt = None,
    as_json: JsonOpt = False,
) -> None:
    """Change values of preset NAME in place (atomically, under the library's lock).

    Examples:

      lookdev presets set worn_gold roughness=0.5 'tags=["metal", "worn"]' -L ~/looks

      lookdev presets set worn_gold roughness= -L ~/looks
    """
    path = Library(library).update(name, parse_assignments(assignments))
    _report("updated", name, path, as_json)


@app.command()
def validate(
    paths: Annotated[
        list[Path] | None,
        typer.Argument(
            metavar="[PATH…]", help="Preset files or folders; default: every library on the path."
        ),
    ] = None,
    library: LibraryOpt = None,
    as_json: JsonOpt = False,
) -> None:
    """Check preset files parse and resolve; exit 2 if any does not.

    Examples:

      lookdev presets validate

      lookdev presets validate ~/looks/worn_gold.toml
    """
    # Folders named here join the search path, so their presets' parents are found.
    lib = Library([*[p if p.is_dir() else p.parent for p in paths or []], *(library or [])])
    results = lib.validate(lib.files_under(paths) if paths else None)
    bad = [(f, e) for f, e in results if e]
    if as_json:
        print_json([{"file": str(f), "ok": e is None, "error": e} for f, e in results])
    else:
        for _, e in bad:
            err_console.print(f"lookdev: error: {e}", markup=False, highlight=False, soft_wrap=True)
        console.print(
            f"{len(results) - len(bad)} of {len(results)} preset files valid", highlight=False
        )
    if bad:
        raise typer.Exit(2)


@app.command()
def rm(
    name: Annotated[str, typer.Argument(help="Preset to delete from its user library.")],
    library: LibraryOpt = None,
    force: Annotated[
        bool, typer.Option("--force", help="Delete even if other presets build on it.")
    ] = False,
    as_json: JsonOpt = False,
) -> None:
    """Delete preset NAME (never a built-in one; refuses while others extend or layer it)."""
    path = Library(library).remove(name, force=force)
    _report("removed", name, path, as_json)


@app.command()
def schema(
    output: Annotated[
        Path | None,
        typer.Option(
            "--output", "-o", help="Write to this file instead of stdout.", dir_okay=False
        ),
    ] = None,
) -> None:
    """Print the JSON Schema of preset files, for editor validation and completion.

    Example (Taplo / Even Better TOML): lookdev presets schema -o preset.schema.json, then
    start a preset with the line  #:schema ./preset.schema.json
    """
    from lookdev.library.schema import preset_schema

    text = json.dumps(preset_schema(), indent=2) + "\n"
    if output is None:
        typer.echo(text, nl=False)
        return
    from lookdev.library import store

    store.atomic_write(output, text.encode("utf-8"))
    console.print(f"wrote {output}", highlight=False)


def parse_assignments(items: list[str]) -> dict[str, Any]:
    """``["roughness=0.3", "sheen_model=conty_kulla"]`` → a dict; ``"k="`` maps k to None."""
    from lookdev.library.preset import parse_value

    out: dict[str, Any] = {}
    for item in items:
        key, sep, value = item.partition("=")
        key = key.strip()
        if not sep or not key:
            raise PresetError(f"{item!r} is not KEY=VALUE (e.g. roughness=0.3)", field="--set")
        out[key] = parse_value(value.strip()) if value.strip() else None
    return out


def _report(verb: str, name: str, path: Path, as_json: bool) -> None:
    if as_json:
        print_json({verb: name, "file": str(path)})
    else:
        console.print(f"{verb} {name}: {path}", highlight=False)
