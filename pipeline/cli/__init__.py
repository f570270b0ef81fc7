"""The ``lookdev`` command line (Typer).

Commands are verbs; each group lives in its own module beside this one and is added in
:func:`_register`. Bad input anywhere ends in one line on stderr and exit code 2
(DESIGN.md, Errors): commands raise :class:`~lookdev.materials.errors.LookdevError` and
:func:`main` turns it into that line.
"""

from __future__ import annotations

import os
import sys
from importlib import metadata

import typer

from lookdev.materials.errors import LookdevError

from .common import quiet_numerics

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


INTERRUPTED = "interrupted: run the same command again to resume"
"""What Ctrl-C prints (exit 130): frames, manifests and writes are resumable."""


def main(argv: list[str] | None = None) -> None:
    """Entry point of the ``lookdev`` script; ``argv`` defaults to ``sys.argv[1:]``.

    The one place errors become what a user sees (DESIGN.md, Errors): a
    :class:`LookdevError`, Click's own usage errors (bad option values, unknown commands
    and options, missing arguments) and an ``OSError`` end in one line on stderr and exit
    2; exit 1 stays "checked and found problems"; Ctrl-C ends in one line and exit 130.
    """
    click = _click_exceptions()
    if argv is None:  # the console script: spawned proof workers inherit the filter
        os.environ.setdefault("PYTHONWARNINGS", "ignore::RuntimeWarning")
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
        error(str(exc))
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
