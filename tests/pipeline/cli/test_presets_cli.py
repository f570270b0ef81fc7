"""``lookdev presets …`` and ``lookdev bench library`` as a user runs them."""

from __future__ import annotations

import json
import tomllib

import pytest

from lookdev.library import Library
from lookdev.materials.params import DisneyParams

BUILTIN_NAMES = Library(use_env=False).names()


@pytest.fixture(autouse=True)
def _no_env_library(monkeypatch):
    monkeypatch.delenv("LOOKDEV_LIBRARY_PATH", raising=False)


def one_line_error(r, *needles: str) -> str:
    """The run failed the way bad input must: exit 2, one line on stderr, no traceback."""
    assert r.code == 2, (r.out, r.err)
    lines = r.err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("lookdev: error: "), r.err
    assert "Traceback" not in r.err + r.out
    for n in needles:
        assert n in lines[0], lines[0]
    return lines[0]


def test_list_lists_every_builtin(cli):
    r = cli("presets", "list", "--json")
    assert r.code == 0
    listed = json.loads(r.out)
    assert sorted(e["name"] for e in listed) == BUILTIN_NAMES
    assert all(e["library"] == "built-in" and e["description"] for e in listed)
    table = cli("presets", "list")
    assert table.code == 0 and f"{len(BUILTIN_NAMES)} presets" in table.out


def test_list_filters_by_tag_and_model(cli):
    metals = json.loads(cli("presets", "list", "--tag", "metal", "--json").out)
    assert {"gold", "iron", "brushed_steel"} <= {e["name"] for e in metals}
    assert all("metal" in e["tags"] for e in metals)
    both = json.loads(cli("presets", "list", "-t", "metal", "-t", "brushed", "--json").out)
    assert {e["name"] for e in both} == {"brushed_aluminium", "brushed_steel"}
    layered = json.loads(cli("presets", "list", "--model", "layered", "--json").out)
    assert layered and all(e["model"] == "layered" for e in layered)
    one_line_error(
        cli("presets", "list", "--model", "phong"), "--model", "disney, pixar, openpbr, layered"
    )


def test_list_warns_about_broken_files_and_lists_the_rest(cli, tmp_path):
    (tmp_path / "broken.toml").write_text("name = [\n")
    (tmp_path / "fine.toml").write_text('name = "fine"\nextends = "gold"\n')
    r = cli("presets", "list", "-L", str(tmp_path), "--json")
    assert r.code == 0
    names = {e["name"]: e for e in json.loads(r.out)}
    assert "broken" not in names and names["fine"]["model"] == "disney"  # inherited
    assert "broken.toml" in r.err and "end of document, line 2" in r.err


def test_show_says_which_file_won(cli, tmp_path, monkeypatch):
    (tmp_path / "gold.toml").write_text('name = "gold"\nmodel = "disney"\n# mine\n')
    monkeypatch.setenv("LOOKDEV_LIBRARY_PATH", str(tmp_path))
    r = cli("presets", "show", "gold")
    assert r.code == 0 and str(tmp_path / "gold.toml") in r.out and "shadows" in r.out
    assert "# mine" in r.out  # the file as written, comments included
    doc = json.loads(cli("presets", "show", "gold", "--json").out)
    assert doc["file"] == str(tmp_path / "gold.toml")
    assert doc["shadows"] == [str(p) for p in Library(use_env=False).definitions("gold")]


def test_show_resolved_gives_every_parameter_and_where_it_came_from(cli):
    r = cli("presets", "show", "brushed_steel", "--resolved")
    assert r.code == 0 and "brushed_steel.toml" in r.out and "iron.toml" in r.out
    assert "default" in r.out
    doc = json.loads(cli("presets", "show", "brushed_steel", "-r", "--json").out)["resolved"]
    assert doc["params"]["anisotropic"] == 0.7 and doc["params"]["metallic"] == 1.0
    assert len(doc["params"]) == len(DisneyParams.model_fields)  # every one, defaults too
    layered = json.loads(cli("presets", "show", "rusty_iron", "-r", "--json").out)["resolved"]
    assert [layer["name"] for layer in layered["layers"]] == ["iron", "rust"]
    assert cli("presets", "show", "rusty_iron", "-r").code == 0


def test_unknown_name_suggests(cli):
    one_line_error(cli("presets", "show", "coper"), "'coper' not found", "did you mean 'copper'")


def test_new_set_and_rm_round_trip(cli, tmp_path):
    lib = str(tmp_path / "looks")  # created on first save
    r = cli(
        "presets", "new", "worn_gold", "--from", "gold", "-L", lib,
        "--set", "roughness=0.45", "--set", 'base_color="#aa8844"',
        "--set", "sheen_model=conty_kulla", "--set", 'description="Worn."',
    )  # fmt: skip
    assert r.code == 0, r.err
    path = tmp_path / "looks" / "worn_gold.toml"
    doc = tomllib.loads(path.read_text())
    assert doc["extends"] == "gold" and doc["description"] == "Worn."
    assert doc["params"] == {
        "roughness": 0.45,
        "base_color": "#aa8844",
        "sheen_model": "conty_kulla",
    }
    assert cli("presets", "set", "worn_gold", "base_color=[0.9, 0.6, 0.2]", "-L", lib).code == 0
    assert tomllib.loads(path.read_text())["params"]["base_color"] == [0.9, 0.6, 0.2]
    assert cli("presets", "set", "worn_gold", "roughness=", "-L", lib).code == 0
    m = Library([lib], use_env=False).load("worn_gold")
    assert m.params.roughness == 0.2 and m.params.base_color == (0.9, 0.6, 0.2)
    one_line_error(cli("presets", "new", "worn_gold", "--from", "gold", "-L", lib), "--force")
    assert cli("presets", "new", "worn_gold", "--from", "silver", "-L", lib, "--force").code == 0
    assert cli("presets", "rm", "worn_gold", "-L", lib).code == 0
    assert not path.exists()


def test_new_from_a_model(cli, tmp_path):
    r = cli(
        "presets", "new", "teal", "--model", "pixar", "-s", "roughness=0.2", "-L", str(tmp_path)
    )
    assert r.code == 0 and Library([tmp_path], use_env=False).load("teal").model == "pixar"
    one_line_error(cli("presets", "new", "x", "-L", str(tmp_path)), "--from PARENT or --model")


@pytest.mark.parametrize(
    "args, needles",
    [
        (["new", "../x", "--from", "gold"], ["NAME", "not allowed", "'..'"]),
        (["new", "a/b", "--from", "gold"], ["not allowed"]),
        (["new", "x", "--from", "gld"], ["'gld' not found", "did you mean 'gold'"]),
        (["new", "x", "--from", "gold", "--set", "roughness=2"], ["params.roughness", "[0, 1]"]),
        (["new", "x", "--from", "gold", "--set", "rough=0.2"], ["params.rough", "unknown"]),
        (["new", "x", "--from", "gold", "--set", "roughness"], ["--set", "KEY=VALUE"]),
        (["new", "x", "--from", "gold", "--set", "name=y"], ["'name' cannot be set"]),
        (["new", "x", "--from", "gold", "--set", "tags=3"], ["tags", "list"]),
        (["set", "gold", "roughness=0.1"], ["built-in preset and read-only"]),
        (["rm", "gold"], ["built-in preset and read-only"]),
        (["set", "nope", "roughness=0.1"], ["'nope' not found"]),
    ],
)
def test_bad_edits_exit_2_in_one_line(cli, tmp_path, args, needles):
    one_line_error(cli("presets", *args, "-L", str(tmp_path)), *needles)
    assert not list(tmp_path.glob("*.toml"))


def test_writes_need_a_user_library_that_is_writable(cli, tmp_path):
    one_line_error(cli("presets", "new", "x", "--from", "gold"), "no user library", "--library")
    blocker = tmp_path / "file"
    blocker.write_text("")
    one_line_error(
        cli("presets", "new", "x", "--from", "gold", "-L", str(blocker / "lib")),
        "cannot write to this library",
    )


def test_library_must_be_a_folder(cli, tmp_path):
    one_line_error(cli("presets", "list", "-L", str(tmp_path / "nope")), "does not exist")
    (tmp_path / "f").write_text("")
    one_line_error(cli("presets", "list", "-L", str(tmp_path / "f")), "is a file, not a folder")


def test_rm_refuses_while_others_build_on_it(cli, tmp_path):
    lib = str(tmp_path)
    assert cli("presets", "new", "base", "--from", "gold", "-L", lib).code == 0
    assert cli("presets", "new", "child", "--from", "base", "-L", lib).code == 0
    one_line_error(cli("presets", "rm", "base", "-L", lib), "child build on 'base'", "--force")
    assert cli("presets", "rm", "base", "-L", lib, "--force").code == 0


def test_validate_everything_and_explicit_paths(cli, tmp_path):
    r = cli("presets", "validate")
    assert r.code == 0 and f"{len(BUILTIN_NAMES)} of {len(BUILTIN_NAMES)}" in r.out
    (tmp_path / "a.toml").write_text('name = "a"\nextends = "b"\n')
    (tmp_path / "b.toml").write_text('name = "b"\nextends = "a"\n')
    (tmp_path / "c.toml").write_text('name = "c"\nmodel = "disney"\n[params]\nmetallic = 7\n')
    (tmp_path / "d.toml").write_text('name = "d"\nextends = "gold"\n')
    r = cli("presets", "validate", str(tmp_path))
    assert r.code == 2 and "1 of 4 preset files valid" in r.out
    errors = r.err.strip().splitlines()
    assert len(errors) == 3 and "Traceback" not in r.err
    assert any("cycle of presets" in e for e in errors)
    assert any("c.toml: params.metallic: 7 is out of range; allowed [0, 1]" in e for e in errors)
    doc = json.loads(cli("presets", "validate", str(tmp_path / "d.toml"), "--json").out)
    assert doc == [{"file": str(tmp_path / "d.toml"), "ok": True, "error": None}]
    one_line_error(cli("presets", "validate", str(tmp_path / "nope.toml")), "no such file")


def test_validate_flags_a_name_defined_twice_in_one_library(cli, tmp_path):
    (tmp_path / "sub").mkdir()
    (tmp_path / "x.toml").write_text('name = "x"\nextends = "gold"\n')
    (tmp_path / "sub" / "x.toml").write_text('name = "x"\nextends = "silver"\n')
    assert Library([tmp_path], use_env=False).load("x").chain[0] == tmp_path / "x.toml"
    r = cli("presets", "validate", "-L", str(tmp_path))
    assert r.code == 2 and "sub/x.toml: 'x' is also defined by" in r.err


def test_malformed_toml_names_file_and_line(cli, tmp_path):
    (tmp_path / "bad.toml").write_text(
        'name = "bad"\nmodel = "disney"\n[params]\nroughness = 0.3.\n'
    )
    one_line_error(cli("presets", "show", "bad", "-L", str(tmp_path)), "bad.toml", "line 4")


def test_schema_is_json_schema_for_preset_files(cli, tmp_path):
    r = cli("presets", "schema")
    assert r.code == 0
    schema = json.loads(r.out)
    assert schema["$schema"].endswith("2020-12/schema") and "DisneyParams" in schema["$defs"]
    assert "PixarParams" in schema["$defs"]
    out = tmp_path / "preset.schema.json"
    assert cli("presets", "schema", "-o", str(out)).code == 0
    assert json.loads(out.read_text()) == schema


def test_bench_library_reports_the_ratio(cli):
    r = cli("bench", "library", "--n", "40", "--repeat", "1", "--json")
    assert r.code == 0, r.err
    doc = json.loads(r.out)
    assert doc["n"] == 40 and doc["target_ratio"] == 2.0
    for key in ("ratio_list_to_read", "ratio_list_json_to_read", "ratio_cold_to_read"):
        assert doc[key] > 0
    assert cli("bench", "library", "--n", "40", "--repeat", "1").code == 0
