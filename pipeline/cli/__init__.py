"""The ``lookdev`` command line (Typer).

Commands are verbs; each group lives in its own module beside this one, listed in
:data:`COMMANDS` and imported only when it runs (:mod:`.lazy`). Bad input anywhere ends
in one line on stderr and exit code 2 (:doc:`/design`, Errors): commands raise
:class:`~lookdev.materials.errors.LookdevError` and :func:`main` turns it into that line.
"""

from __future__ import annotations

import os
import sys
import warnings
from collections.abc import Iterator
from contextlib import contextmanager

import typer

from lookdev.materials.errors import LookdevError

from .lazy import Lazy, lazy_group

__all__ = [
    "COLOUR_PANEL",
    "COMMANDS",
    "GLOBAL_OPTIONS",
    "INTERRUPTED",
    "app",
    "error",
    "main",
    "os_error_line",
    "quiet_numerics",
]

COMMANDS = {
    "presets": Lazy(".presets:app", "Browse, show, create, edit and validate presets."),
    "plot": Lazy(".plot:plot", "Draw presets as one BRDF-explorer view, to an image."),
    "fit": Lazy(".fit:fit", "Fit a Disney or Pixar preset to a measured BRDF (MBSDF, MERL)."),
    "blend": Lazy(".blend:blend", "Blend a preset's layers into EXR maps and JSON."),
    "export": Lazy(".export:app", "Write presets for other tools: Mitsuba scenes, USD."),
    "import": Lazy(".import_usd:import_app", "Read materials written by other tools back."),
    "validate": Lazy(".validate_usd:validate_app", "Check exported files as their readers will."),
    "proof": Lazy(".proof:proof", "Render turntable proofs: every preset under every IBL."),
    "designer": Lazy(".designer:designer", "Develop a look interactively in a local web page."),
    "check": Lazy(".check:check", "Sweep every model over its stiff and extreme cases."),
    "colour": Lazy(".colour:app", "List the OCIO config's colour spaces, views and looks."),
    "bench": Lazy(".bench:app", "Measure performance targets against baselines run alongside."),
}
"""The commands of ``lookdev``: each module is imported only when its command runs."""

app = typer.Typer(
    name="lookdev",
    cls=lazy_group(COMMANDS),
    # markdown: help paragraphs reflow to the terminal (rich mode keeps every line break)
    rich_markup_mode="markdown",
    help="Author, blend, export and proof Disney and Pixar materials.\n\n"
    "Colour is managed by OpenColorIO. Colour options go before the command and hold for "
    "all of it: `lookdev --working-space acescg --view Un-tone-mapped proof gold`. "
    "`lookdev colour spaces` and `lookdev colour views` list the names the config knows.",
    no_args_is_help=True,
    pretty_exceptions_enable=False,
    add_completion=False,
)


def _version(value: bool) -> None:
    if value:
        from importlib import metadata

        typer.echo(f"lookdev {metadata.version('lookdev')}")
        raise typer.Exit()


COLOUR_PANEL = "Colour (global: before the command, for every command)"
GLOBAL_OPTIONS = ("--config", "--working-space", "--display", "--view", "--look")
"""Options of :func:`_root`: a user who types one after the command is told where it goes."""


@app.callback()
def _root(
    ctx: typer.Context,
    version: bool = typer.Option(
        False, "--version", callback=_version, is_eager=True, help="Print the version and exit."
    ),
    config: str | None = typer.Option(
        None,
        "--config",
        metavar="FILE|ocio://NAME",
        help="OpenColorIO config: a .ocio file or a built-in ocio:// name. Default: $OCIO, "
        "else OCIO's built-in ACES 2.0 studio config.",
        rich_help_panel=COLOUR_PANEL,
        show_default=False,
    ),
    working_space: str | None = typer.Option(
        None,
        "--working-space",
        metavar="lin_rec709|acescg",
        help="Scene-linear space every colour is held, rendered, exported and written in "
        "(or any colour space of the config). Default lin_rec709.",
        rich_help_panel=COLOUR_PANEL,
        show_default=False,
    ),
    display: str | None = typer.Option(
        None,
        "--display",
        help="OCIO display of the view transform for PNGs, contact sheets, plots and the "
        "review page. Default: the config's (sRGB - Display).",
        rich_help_panel=COLOUR_PANEL,
        show_default=False,
    ),
    view: str | None = typer.Option(
        None,
        "--view",
        help="OCIO view of that display. Default: the config's (ACES 2.0 - SDR 100 nits "
        "(Rec.709): highlights roll off, hue kept); Un-tone-mapped: the sRGB curve alone.",
        rich_help_panel=COLOUR_PANEL,
        show_default=False,
    ),
    look: str | None = typer.Option(
        None,
        "--look",
        help="OCIO look(s) applied before the view, comma-separated.",
        rich_help_panel=COLOUR_PANEL,
        show_default=False,
    ),
) -> None:
    """lookdev: material presets in, USD networks and Mitsuba proofs out.

    Colour is managed by OpenColorIO: colour options go before the command and hold for
    all of it, e.g. `lookdev --working-space acescg --view Un-tone-mapped proof gold`.
    `lookdev colour spaces` and `lookdev colour views` list the names the config knows.
    """
    given = {
        "config": config,
        "working_space": working_space,
        "display": display,
        "view": view,
        "look": look,
    }
    if any(v is not None for v in given.values()):
        from lookdev.materials import colour

        ctx.with_resource(colour.use(**given))


@contextmanager
def quiet_numerics() -> Iterator[None]:
    """numpy's ``RuntimeWarning`` (overflow, invalid value, divide by zero) stays off stderr.

    Parameters are range-checked at load so that no derived quantity overflows; the
    stability sweep (``lookdev check``) reports non-finite values as findings. A warning
    on stderr in between would only break the one-line rule.
    """
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        yield


INTERRUPTED = "interrupted: run the same command again to resume"
"""What Ctrl-C prints (exit 130): frames, manifests and writes are resumable."""


def main(argv: list[str] | None = None) -> None:
    """Entry point of the ``lookdev`` script; ``argv`` defaults to ``sys.argv[1:]``.

    The one place errors become what a user sees (:doc:`/design`, Errors): a
    :class:`LookdevError`, Click's own usage errors (bad option values, unknown commands
    and options, missing arguments) and an ``OSError`` end in one line on stderr and exit
    2; exit 1 stays "checked and found problems"; Ctrl-C ends in one line and exit 130.
    """
    click = _click_exceptions()
    if argv is None:  # the console script: spawned proof workers inherit the filter
        os.environ.setdefault("PYTHONWARNINGS", "ignore::RuntimeWarning")
    # lookdev uses no pydantic plugin, and looking for one reads the entry points of every
    # installed distribution on the first schema (≈ 5 ms of `presets show`'s 150);
    # PYDANTIC_DISABLE_PLUGINS= (empty) in the environment turns the search back on
    os.environ.setdefault("PYDANTIC_DISABLE_PLUGINS", "__all__")
    code: object = 0
    try:
        with quiet_numerics():
            code = app(args=argv, prog_name="lookdev", standalone_mode=False)
    except click.NoArgsIsHelpError:  # bare `lookdev presets`: Typer printed the help
        code = 2
    except click.UsageError as exc:
        error(_usage_line(exc))
        code = 2
    except click.ClickException as exc:  # FileError and the like
        error(exc.format_message())
        code = 2
    except LookdevError as exc:
        error(exc.one_line(_options(exc)))
        code = 2
    except typer.Abort:  # a prompt interrupted (Ctrl-C / EOF)
        code = 130
    except KeyboardInterrupt:
        code = 130
    except OSError as exc:
        error(os_error_line(exc))
        code = 2
    if code == 130:
        _line(INTERRUPTED)
    if isinstance(code, int) and code:
        sys.exit(code)


def _options(exc: BaseException) -> dict[str, str]:
    """Argument name → the option (or ``ARGUMENT``) of the command that raised ``exc``,
    its groups' too: how :meth:`LookdevError.one_line` names a Python argument here.

    The command is read from the traceback (the innermost frame holding a Click context),
    so no command registers anything: the API names ``noise``, the user reads ``--noise``.
    """
    context_type = type.mro(typer.Context)[1]  # Click's Context, which Typer's derives
    ctx, tb = None, exc.__traceback__
    while tb is not None:
        found = tb.tb_frame.f_locals.get("ctx")
        ctx = found if isinstance(found, context_type) else ctx
        tb = tb.tb_next
    names: dict[str, str] = {}
    while ctx is not None:
        for param in ctx.command.params:
            if param.name and param.opts:
                opts = [o for o in param.opts if o.startswith("--")] or param.opts
                is_option = opts[0].startswith("-")
                label = max(opts, key=len) if is_option else (param.metavar or param.name.upper())
                names.setdefault(param.name, label)
        ctx = ctx.parent
    return names


def _click_exceptions():
    """The module of the Click exceptions Typer raises (Typer ≥ 0.29 vendors Click)."""
    return sys.modules[typer.BadParameter.__module__]


_RANGE_ERRORS = ("greater_than_equal", "less_than_equal", "greater_than", "less_than")


def _usage_line(exc) -> str:
    """Click's usage error as one line, pointing at the command's ``--help``.

    An option value outside the option's ``min``/``max`` reads like a preset's range
    error: "--spp: 0 is out of range; allowed [2, 65536]".
    """
    ctx = exc.ctx
    where = ctx.command_path if ctx is not None else "lookdev"
    param = getattr(exc, "param", None)
    low, high = getattr(param, "min", None), getattr(param, "max", None)
    cause = exc.__cause__
    if param is not None and (low is not None or high is not None) and cause is not None:
        first = next(iter(getattr(cause, "errors", lambda: [{}])()), {})
        given = first.get("input", "")
        name = max(param.opts, key=len) if param.opts else param.name
        allowed = f"[{'-∞' if low is None else f'{low:g}'}, {'∞' if high is None else f'{high:g}'}]"
        if str(given).strip().lower().lstrip("+-") in ("nan", "inf", "infinity"):
            message = f"{name}: {given} is not a finite number; allowed {allowed}"
        elif first.get("type") in _RANGE_ERRORS:
            message = f"{name}: {given} is out of range; allowed {allowed}"
        else:
            message = f"{name}: {given!r} is not a number in {allowed}"
    elif getattr(exc, "option_name", None) in GLOBAL_OPTIONS and ctx is not None:
        name = exc.option_name
        command = ctx.command_path.removeprefix("lookdev").strip()
        return (
            f"{name} is a global colour option: put it before the command, "
            f"as in 'lookdev {name} VALUE {command} …' (see 'lookdev --help')"
        )
    else:
        message = exc.format_message().replace("Value error, ", "").rstrip(".")
        message = message[:1].lower() + message[1:]
    return f"{message} (see '{where} --help')"


def os_error_line(exc: OSError) -> str:
    """``OSError`` as "file: reason", without Python's ``[Errno n]`` prefix."""
    reason = exc.strerror or str(exc)
    names = [str(n) for n in (exc.filename, exc.filename2) if n]
    return ": ".join([" -> ".join(names), reason] if names else [reason])


def error(message: str) -> None:
    """``lookdev: error: MESSAGE`` as exactly one line on stderr."""
    _line(f"lookdev: error: {message}")


def _line(text: str) -> None:
    sys.stderr.write(" ".join(text.split()) + "\n")
    sys.stderr.flush()
