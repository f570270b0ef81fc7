"""Command groups whose sub-commands are imported only when they run.

A group built by :func:`lazy_group` knows its sub-commands from a table of
:class:`Lazy` entries: the module and attribute that hold each one, and the line its
parent's ``--help`` lists it with. ``lookdev --help`` (or ``lookdev bench --help``)
shows the table without importing a single command module; ``lookdev presets list``
imports ``presets.py`` and nothing of the benchmarks, Mitsuba or USD. A command module is
imported when the group resolves that command's name: to run it, or to show its own
``--help``.

Typer (0.29) coerces option values with pydantic, building a ``TypeAdapter`` for each
parameter before looking at its value; an option left unset needs none, so every command
here builds its adapters on the first value given (:func:`defer_coercion`): ``lookdev
presets list`` imports no pydantic.

An entry's attribute is either a :class:`typer.Typer` (a sub-group, e.g. ``presets``) or
a plain function (a command, e.g. ``proof``), exactly what ``app.add_typer`` or
``app.command`` would have been given.
"""

from __future__ import annotations

import functools
import importlib
import inspect
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import typer
from typer.core import TyperCommand, TyperGroup

__all__ = ["Lazy", "LazyGroup", "defer_coercion", "lazy_group"]

PACKAGE = __name__.rpartition(".")[0]
"""Relative module names of the tables resolve against the CLI package."""


@dataclass(frozen=True)
class Lazy:
    """Where a sub-command lives, and how its parent lists it.

    ``target`` is ``"module:attribute"``; a module starting with ``.`` is relative to
    :mod:`lookdev.pipeline.cli` (``".bench_blend:blend_"``). ``help`` is the one line of
    the parent's listing (Click's ``short_help``): the command's own ``--help`` shows its
    docstring in full.
    """

    target: str
    help: str
    panel: str | None = None

    def load(self, name: str, markup: Any) -> Any:
        """The Click command of this entry, built from the imported module."""
        module, _, attribute = self.target.partition(":")
        obj = getattr(importlib.import_module(module, PACKAGE), attribute)
        if isinstance(obj, typer.Typer):
            _markup(obj, markup)
            command = _group_building_on_use(obj)
            command.name = name
        else:
            command = _built(typer.models.CommandInfo(name=name, callback=obj), markup)
        command.short_help = self.help
        if self.panel is not None:
            command.rich_help_panel = self.panel
        return command


def _built(info: Any, markup: Any) -> Any:
    """The Click command of one Typer ``CommandInfo``, its coercion deferred."""
    command = typer.main.get_command_from_info(
        info, pretty_exceptions_short=True, rich_markup_mode=markup
    )
    defer_coercion(command)
    return command


def _group_building_on_use(app: typer.Typer) -> Any:
    """The group of ``app`` with each of its own commands built when resolved: Typer reads
    every command's signature and type hints when it builds a group (≈ 0.5 ms a command),
    and a run resolves one."""
    if isinstance(app.info.cls, typer.models.DefaultPlaceholder):
        app.info.cls = LazyGroup
    infos, app.registered_commands = app.registered_commands, []
    try:
        group = typer.main.get_group(app)
    finally:
        app.registered_commands = infos
    others, group.commands = group.commands, {}  # Typer lists commands before groups
    for info in infos:
        name = info.name or typer.main.get_command_name(info.callback.__name__)
        group.commands[name] = _Placeholder(
            name,
            functools.partial(_built, info),
            help=info.help or inspect.getdoc(info.callback),
            short_help=info.short_help,
            panel=info.rich_help_panel,
            hidden=info.hidden,
            deprecated=info.deprecated,
        )
    group.commands.update(others)
    defer_coercion(group)
    return group


def _markup(app: typer.Typer, markup: Any) -> None:
    # The parent's help style (markdown: paragraphs reflow) holds for nested groups too.
    app.rich_markup_mode = markup
    for group in app.registered_groups:
        _markup(group.typer_instance, markup)


class LazyGroup(TyperGroup):
    """A Typer group completed from :attr:`table` (set by :func:`lazy_group`).

    Until a name is resolved its entry is a placeholder carrying only the listing's line,
    so help, typo suggestions and shell completion work without importing it.
    """

    table: Mapping[str, Lazy] = {}

    def __init__(self, **attrs: Any) -> None:
        super().__init__(**attrs)
        defer_coercion(self)
        for name, entry in self.table.items():
            self.commands.setdefault(
                name,
                _Placeholder(
                    name,
                    functools.partial(entry.load, name),
                    help=entry.help,
                    short_help=entry.help,
                    panel=entry.panel,
                ),
            )

    def resolve_command(self, ctx: Any, args: list[str]) -> Any:
        placeholder = self.commands.get(args[0]) if args else None
        if isinstance(placeholder, _Placeholder):
            self.commands[args[0]] = placeholder.build(self.rich_markup_mode)
        return super().resolve_command(ctx, args)


class _Placeholder(TyperCommand):
    """A command not yet imported or built: what its parent's listing shows, and
    ``build(markup)``, which makes the command itself."""

    def __init__(
        self,
        name: str,
        build: Any,
        *,
        help: str | None,
        short_help: str | None = None,
        panel: str | None = None,
        hidden: bool = False,
        deprecated: bool = False,
    ) -> None:
        super().__init__(
            name=name, help=help, short_help=short_help, hidden=hidden, deprecated=deprecated
        )
        self.build = build
        if panel is not None:
            self.rich_help_panel = panel


def defer_coercion(command: Any) -> None:
    """Let each parameter of ``command`` (and of its sub-commands) build Typer's coercion
    when it first gets a value: one left unset (``None``) is returned as Typer returns it,
    without a pydantic ``TypeAdapter``. A Typer without that machinery is left as it is."""
    on_first_value = _on_first_value_class()
    if on_first_value is None:  # pragma: no cover - another Typer
        return

    def defer(param: Any) -> Any:
        if getattr(param, "_runtime_param", False) is None and hasattr(param, "type_descriptor"):
            d = param.type_descriptor
            param._runtime_param = on_first_value(d.parameter_info, d.annotation)
        return param

    for param in getattr(command, "params", ()):
        defer(param)
    help_option = command.get_help_option  # made on first use: `--help` is a parameter too
    command.get_help_option = lambda ctx: defer(help_option(ctx))
    for sub in getattr(command, "commands", {}).values():
        if not isinstance(sub, _Placeholder):
            defer_coercion(sub)


@functools.cache
def _on_first_value_class() -> type | None:
    """Typer's runtime parameter that builds its coercion on the first value (made once:
    a dataclass costs ≈ 0.3 ms to create, and every command and group asks for it)."""
    try:
        from typer._coercion import PassThroughRuntimeParam, RuntimeParam, build_runtime_param
    except ImportError:  # pragma: no cover - another Typer
        return None

    @dataclass(frozen=True)
    class OnFirstValue(RuntimeParam):
        def _coerce_value(self, value: Any, param: Any, ctx: Any) -> Any:
            d = param.type_descriptor
            if _already_plain(d, value):
                # Typer's adapter would return a plain `str` or `bool` unchanged; building
                # it imports Typer's pydantic layer (≈ 0.07 CPU s, `presets show`'s NAME)
                param._runtime_param = PassThroughRuntimeParam(d.parameter_info, d.annotation)
                return value
            param._runtime_param = build_runtime_param(d)
            return param._runtime_param._coerce_value(value, param=param, ctx=ctx)

    return OnFirstValue


def _already_plain(descriptor: Any, value: Any) -> bool:
    """True when ``value`` is already what a plain ``str`` or ``bool`` parameter takes, with
    no parser, Click type or file handling that Typer's coercion would apply."""
    info = descriptor.parameter_info
    return (
        descriptor.annotation in (str, bool)
        and type(value) is descriptor.annotation
        and descriptor.file_annotation is None
        and getattr(info, "parser", None) is None
        and getattr(info, "click_type", None) is None
    )


def lazy_group(table: Mapping[str, Lazy]) -> type[LazyGroup]:
    """A :class:`LazyGroup` class for ``typer.Typer(cls=...)`` that holds ``table``."""
    return type("LazyGroup", (LazyGroup,), {"table": dict(table)})
