"""A command imports only what it runs: the module sets of the quick commands, the lazy
tables of ``lookdev`` and ``lookdev bench``, and the CPU benchmark's figures.

The module sets are read from a fresh interpreter (what a user's shell starts), not
timed: which packages load is deterministic, how long they take on a shared machine is
not (``lookdev bench cli`` measures that).
"""

from __future__ import annotations

import importlib
import json
import subprocess
import sys

import pytest
import typer

from lookdev.pipeline import cli as cli_package
from lookdev.pipeline.cli import bench as bench_cli
from lookdev.pipeline.cli.lazy import LazyGroup

HEAVY = ("mitsuba", "drjit", "pxr", "numpy", "OpenImageIO", "PyOpenColorIO", "matplotlib")
"""Packages no quick command needs."""
OURS_HEAVY = ("lookdev.pipeline.bench", "lookdev.materials.registry", "lookdev.library.preset")

CHILD = """
import atexit, json, sys
atexit.register(lambda: print(json.dumps(sorted(sys.modules)), file=sys.__stderr__))
from lookdev.pipeline.cli import main
main(sys.argv[1:])
"""


def loaded(*args: str) -> set[str]:
    """The modules a fresh ``lookdev ARGS`` has imported when it exits."""
    r = subprocess.run(
        [sys.executable, "-c", CHILD, *args], capture_output=True, text=True, timeout=120
    )
    assert r.returncode == 0, r.stderr
    return set(json.loads(r.stderr.strip().splitlines()[-1]))


def heavy(modules: set[str], names: tuple[str, ...]) -> list[str]:
    return sorted(m for m in modules if any(m == n or m.startswith(n + ".") for n in names))


@pytest.mark.parametrize("args", [("--help",), ("--version",), ("bench", "--help")])
def test_help_and_version_import_no_command_and_no_heavy_package(args):
    modules = loaded(*args)
    # Typer 0.29 coerces option values through pydantic; options left unset need none
    # (lazy.defer_coercion), so no quick command imports it for Typer's sake
    assert heavy(modules, HEAVY + OURS_HEAVY + ("pydantic",)) == []
    commands = {m for m in modules if m.startswith("lookdev.pipeline.cli.")}
    assert commands <= {"lookdev.pipeline.cli.lazy", "lookdev.pipeline.cli.bench"}


MODEL_MODULES = tuple(
    f"lookdev.materials.{m}" for m in ("disney", "disney_prepare", "sheen", "openpbr", "measured")
)
"""Evaluation modules of the models: validating a Disney preset needs none of them."""


def test_presets_list_reads_headers_without_the_models_or_pydantic():
    modules = loaded("presets", "list")
    assert heavy(modules, HEAVY + OURS_HEAVY + MODEL_MODULES + ("pydantic",)) == []
    assert "lookdev.pipeline.cli.presets" in modules


def test_presets_show_validates_without_the_models_the_image_reader_or_a_renderer():
    modules = loaded("presets", "show", "gold")
    # a preset's check is its schemas: array code, colour conversion and the models'
    # evaluation come in only for a colour to convert or a map to read
    unwanted = HEAVY + MODEL_MODULES + ("lookdev.materials.pixar", "lookdev.materials.registry")
    assert heavy(modules, unwanted + ("lookdev.pipeline.bench", "lookdev.materials.colour")) == []
    assert "lookdev.materials.params" in modules  # it was validated
    assert heavy(modules, ("rich",)) == []  # piped: the file as plain TOML, no Rich
    # NAME is a plain str: Typer's pydantic coercion of it would be a no-op (lazy.py)
    assert "typer._adapters" not in modules


def test_presets_show_of_a_textured_preset_still_reads_its_maps():
    modules = loaded("presets", "show", "rusty_iron")
    assert "lookdev.library.material" in modules  # resolved, so its maps were checked


def test_presets_show_loads_no_renderer_no_usd_and_no_benchmark():
    modules = loaded("presets", "show", "gold", "--resolved")
    assert heavy(modules, ("mitsuba", "drjit", "pxr", "matplotlib", "lookdev.pipeline.bench")) == []


def _entries(group: type[LazyGroup]):
    return list(group.table.items())


@pytest.mark.parametrize(
    ("app", "name"),
    [(cli_package.app, n) for n in cli_package.COMMANDS]
    + [(bench_cli.app, n) for n in bench_cli.COMMANDS],
)
def test_every_table_entry_loads_as_what_it_says(app, name):
    table = app.info.cls.table
    command = table[name].load(name, "markdown")
    assert command.name == name and command.short_help == table[name].help
    assert command.callback is not None or getattr(command, "commands", None)


def test_each_entry_is_listed_by_its_line_and_runs_its_own_help(cli):
    r = cli("bench", "--help")
    assert r.code == 0
    for name, entry in bench_cli.COMMANDS.items():
        assert name in r.out and entry.help.split()[-1].strip(".`") in r.out
    r = cli("bench", "cli", "--help")
    assert r.code == 0 and "--rounds" in r.out


def test_a_typo_still_gets_a_suggestion(cli):
    r = cli("presest", "list")
    assert r.code == 2 and "Did you mean 'presets'" in r.err


def test_an_option_given_is_still_coerced_and_range_checked(cli):
    r = cli("bench", "cli", "--rounds", "0")
    assert r.code == 2 and r.err.count("\n") == 1 and "--rounds: 0 is out of range" in r.err
    r = cli("presets", "list", "--json", "--model", "disney")
    assert r.code == 0 and all(p["model"] == "disney" for p in json.loads(r.out))


def test_lazy_group_is_a_typer_group():
    assert issubclass(cli_package.app.info.cls, LazyGroup)
    assert issubclass(cli_package.app.info.cls, typer.core.TyperGroup)


def test_bench_cli_measures_every_command_against_the_floor(monkeypatch):
    from lookdev.pipeline.bench import cli as bench

    calls = []

    def fake(argv, env=None):  # the child's CPU time: the floor 0.1 s, commands 0.2 s
        calls.append(argv)
        return 0.1 if argv[1:] == list(bench.FLOOR) else 0.2

    monkeypatch.setattr(bench, "cpu_seconds", fake)
    result = bench.run(rounds=3)
    assert result["floor_cpu_s"] == pytest.approx(0.1)
    assert set(result["commands"]) == {f"lookdev {c}" for c in bench.COMMANDS}
    for r in result["commands"].values():
        assert r["ratio"] == pytest.approx(2.0) and r["met"]
    # a warm-up of each, then every round runs every one of them
    assert len(calls) == (1 + 3) * (1 + len(bench.COMMANDS))


def test_cpu_seconds_of_a_failing_child_is_an_error():
    from lookdev.pipeline.bench import cli as bench

    with pytest.raises(RuntimeError, match="exited 3"):
        bench.cpu_seconds([sys.executable, "-c", "raise SystemExit(3)"])


@pytest.mark.slow
def test_bench_cli_json_runs_for_real(cli):
    r = cli("bench", "cli", "--rounds", "1", "--json")
    assert r.code == 0, r.err
    doc = json.loads(r.out)
    assert doc["floor_cpu_s"] > 0 and len(doc["commands"]) == 4
    assert all(c["cpu_s"] > 0 for c in doc["commands"].values())


def test_a_failing_timed_child_names_its_last_error_line_and_never_blocks_on_stderr():
    from lookdev.pipeline.bench.cli import cpu_seconds

    chatty = "import sys; sys.stderr.write('x' * 200000 + '\\nthe reason\\n'); sys.exit(3)"
    with pytest.raises(RuntimeError, match="exited 3: the reason"):
        cpu_seconds([sys.executable, "-c", chatty])


@pytest.mark.parametrize("name", ["presets", "export", "import", "validate", "colour"])
def test_a_sub_group_lists_what_typer_lists_and_builds_only_the_command_run(name):
    entry = cli_package.COMMANDS[name]
    lazy = entry.load(name, "markdown")
    module, _, attribute = entry.target.partition(":")
    app = getattr(importlib.import_module(module, "lookdev.pipeline.cli"), attribute)
    eager = typer.main.get_group(app)

    def listing(group):
        return [
            (n, c.get_short_help_str(80), c.hidden, c.deprecated, c.rich_help_panel)
            for n, c in group.commands.items()
        ]

    assert listing(lazy) == listing(eager)
    first = next(n for n, c in eager.commands.items() if not isinstance(c, typer.core.TyperGroup))
    assert type(lazy.commands[first]).__name__ == "_Placeholder"
    ctx = lazy.make_context(name, [first, "--help"], resilient_parsing=True)
    lazy.resolve_command(ctx, [first])
    built = lazy.commands[first]
    assert built.callback is not None and [p.name for p in built.params] == [
        p.name for p in eager.commands[first].params
    ]
    others = [n for n in lazy.commands if n != first]
    assert all(
        type(lazy.commands[n]).__name__ == "_Placeholder"
        or isinstance(lazy.commands[n], typer.core.TyperGroup)
        for n in others
    )


def test_bench_cli_writes_the_byte_code_once_even_where_the_environment_forbids_it(
    monkeypatch,
):
    """A container's PYTHONDONTWRITEBYTECODE would have every round compile lookdev again:
    the warm-up writes the byte-code (as a first run does), the rounds keep the setting."""
    from lookdev.pipeline.bench import cli as bench

    envs = []
    monkeypatch.setenv("PYTHONDONTWRITEBYTECODE", "1")
    monkeypatch.setattr(bench, "cpu_seconds", lambda argv, env=None: envs.append(env) or 0.1)
    bench.run(rounds=2)
    warm, rounds = envs[: 1 + len(bench.COMMANDS)], envs[1 + len(bench.COMMANDS) :]
    assert all("PYTHONDONTWRITEBYTECODE" not in e for e in warm)
    assert all(e["PYTHONDONTWRITEBYTECODE"] == "1" for e in rounds)
