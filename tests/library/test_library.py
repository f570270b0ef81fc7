"""Preset files and libraries: the built-ins, parsing, resolution, search path, saves."""

from __future__ import annotations

import doctest
import importlib
import json
import os
import re
import tomllib
from pathlib import Path

import jsonschema
import pytest

from lookdev.library import (
    Library,
    LibraryError,
    PresetError,
    PresetFile,
    PresetNotFoundError,
    builtin_folder,
    dump_preset,
    load_material,
    parse_preset,
)
from lookdev.library.index import INDEX_NAME, scan_folder
from lookdev.library.preset import check_params
from lookdev.library.schema import preset_schema
from lookdev.materials.colour import decode_hex
from lookdev.materials.errors import LookdevError, ParameterError
from lookdev.materials.layers import CombineMask, TextureMask, textures
from lookdev.materials.params import SPECULAR_F0_SCALE

BUILTIN = Library(use_env=False)
BUILTIN_NAMES = BUILTIN.names()


def write(folder: Path, name: str, text: str) -> Path:
    path = folder / f"{name}.toml"
    path.write_text(text, encoding="utf-8")
    return path


@pytest.fixture
def lib(tmp_path):
    """A user library in tmp_path, searched before the built-ins."""
    return Library([tmp_path], use_env=False)


@pytest.mark.parametrize("module", ["__init__", "errors", "preset", "material"])
def test_doctests(module):
    name = "lookdev.library" + ("" if module == "__init__" else f".{module}")
    result = doctest.testmod(importlib.import_module(name))
    assert result.attempted and not result.failed


# -- the built-in library ---------------------------------------------------------------


def test_builtin_library_is_big_enough_and_covers_the_issue():
    assert len(BUILTIN_NAMES) >= 40
    needed = {"gold", "silver", "copper", "aluminium", "iron", "chromium", "titanium", "brass"}
    needed |= {"plastic_glossy", "plastic_matte", "rubber", "ceramic_glazed", "marble"}
    needed |= {"glass_clear", "water", "car_paint_red", "velvet", "cotton", "satin", "leaf"}
    needed |= {"rusty_iron", "worn_paint_over_metal", "dust_over_plastic"}
    needed |= {"pixar_painted_metal", "pixar_rusty_metal", "pixar_translucent_plastic"}
    assert needed <= set(BUILTIN_NAMES)


@pytest.mark.parametrize("name", BUILTIN_NAMES)
def test_every_builtin_resolves_and_documents_itself(name):
    m = BUILTIN.load(name)
    assert m.description and m.tags
    # Every preset names its source, itself or through the preset it extends.
    chain = [tomllib.loads(p.read_text())["source"] for p in m.chain if "source" in p.read_text()]
    assert chain, f"{name} names no source"
    if m.model == "layered":
        assert m.params is None and m.layers
        assert len({layer.material.model for layer in m.layers}) == 1
    else:
        assert m.params is not None and not m.layers


def test_builtin_values_are_the_cited_measurements():
    # Hoffman 2015 / RTR4 Table 9.2 (linear F0); refractiveindex.info IORs.
    assert BUILTIN.load("gold").params.base_color == (1.0, 0.782, 0.344)
    assert BUILTIN.load("copper").params.base_color == (0.955, 0.638, 0.538)
    assert BUILTIN.load("water").params.ior == 1.333
    assert BUILTIN.load("glass_clear").params.effective_ior == 1.52
    assert BUILTIN.load("glass_frosted").params.ior == 1.52  # inherited


@pytest.mark.parametrize("name", BUILTIN_NAMES)
def test_source_notes_agree_with_the_values(name):
    """Every 'IOR x' and 'F0 f, so specular s' a preset cites is the value it uses."""
    m = BUILTIN.load(name)
    note = m.citation or ""
    if m.params is None or not note:
        return
    for ior in re.findall(r"IOR (\d+\.\d+)(?![\d-])", note):
        ior_used = m.params.ior if m.model == "pixar" else m.params.effective_ior
        assert ior_used == pytest.approx(float(ior), abs=0.01), note
    for f0, specular in re.findall(r"F0 (\d\.\d+), so specular (\d\.\d+)", note):
        assert m.params.specular == float(specular)
        assert float(specular) * SPECULAR_F0_SCALE == pytest.approx(float(f0), abs=0.002)


def test_issue_looks_use_the_features_they_name():
    velvet = BUILTIN.load("velvet").params
    assert velvet.sheen_model == "conty_kulla" and velvet.sheen > 0
    assert BUILTIN.load("satin").params.anisotropic > 0
    leaf = BUILTIN.load("leaf").params
    assert leaf.thin and leaf.diff_trans > 0
    assert BUILTIN.load("car_paint_red").params.clearcoat > 0
    assert BUILTIN.load("marble").params.scatter_distance > 0
    plastic = BUILTIN.load("pixar_translucent_plastic").params
    assert plastic.clear > 0 and plastic.back > 0
    for name in ("pixar_painted_metal", "pixar_rusty_metal"):
        assert {layer.material.model for layer in BUILTIN.load(name).layers} == {"pixar"}
    for name in ("rusty_iron", "worn_paint_over_metal", "dust_over_plastic"):
        for layer in BUILTIN.load(name).layers:
            assert not list(textures(layer.mask)), "built-in masks need no files"


def test_builtin_files_validate_against_the_generated_json_schema():
    schema = preset_schema()
    jsonschema.Draft202012Validator.check_schema(schema)
    validator = jsonschema.Draft202012Validator(schema)
    for h in BUILTIN.headers():
        validator.validate(tomllib.loads(h.path.read_text()))
    bad = {"name": "x", "model": "disney", "params": {"roughness": 2}}
    assert not validator.is_valid(bad)
    assert not validator.is_valid({"name": "x", "model": "disney", "colour": 1})
    assert validator.is_valid({"name": "x", "model": "disney", "params": {"base_color": "#aa8844"}})


# -- parsing: one file ------------------------------------------------------------------


@pytest.mark.parametrize(
    "text, field, allowed",
    [
        ('name = "a"\nmodel = "disney"\n[params\n', None, "line 3"),
        ('name = "a"\nmodel = "disney"\ncolour = 1\n', "colour", "allowed: name, model"),
        ('name = "a"\nmodel = "disney"\n[params]\nroughness = "x"\n', "params.roughness", "number"),
        ('name = "a"\nmodel = "disney"\n[params]\nroughness = 1.5\n', "params.roughness", "[0, 1]"),
        ('name = "a"\nmodel = "disney"\n[params]\nglossy = 1\n', "params.glossy", "unknown"),
        ('name = "a"\nmodel = "disney"\n[params]\nmetallic = true\n', "params.metallic", "number"),
        ('name = "a"\nmodel = "pixar"\n[params]\nclear = "0.5"\n', "params.clear", "number"),
        ('name = "a"\nmodel = "disney"\n[params]\nthin = 1\n', "params.thin", "boolean"),
        ('name = "a"\nmodel = "phong"\n', "model", "'disney', 'pixar', 'openpbr' or 'layered'"),
        ('name = "a"\n', None, "'model' is required"),
        ('name = "b"\nmodel = "disney"\n', "name", "differs from the file name"),
        ('name = "a"\nmodel = "disney"\ntags = "metal"\n', "tags", "list"),
        ('name = "a"\nmodel = "disney"\nextends = "../x"\n', "extends", "not a preset name"),
        ('name = "a"\nmodel = "layered"\n', None, "at least one [[layers]]"),
        ('name = "a"\nmodel = "layered"\n[[layers]]\nmask = 1\n', "layers[0]", "exactly one"),
        (
            'name = "a"\nmodel = "layered"\n[[layers]]\nmodel = "disney"\n'
            "params = {metallic = 2}\n",
            "layers[0].params.metallic",
            "[0, 1]",
        ),
        (
            'name = "a"\nmodel = "layered"\n[[layers]]\npreset = "gold"\nmask = 1.5\n',
            "layers[0].mask.constant.value",
            "1.5 is out of range; allowed [0, 1]",
        ),
    ],
)
def test_bad_files_fail_in_one_line_naming_file_and_field(text, field, allowed):
    with pytest.raises(LookdevError) as info:
        parse_preset(text.encode(), where="a.toml", stem="a")
    msg = str(info.value)
    assert msg.startswith("a.toml: ") and "\n" not in msg
    assert allowed in msg, msg
    if field:
        assert f": {field}: " in msg, msg


def test_not_utf8_and_too_big_are_clear_errors():
    with pytest.raises(PresetError, match="not UTF-8"):
        parse_preset(b"name = '\xff'", where="a.toml")
    with pytest.raises(PresetError, match="small text file"):
        parse_preset(b"#" * (2 << 20), where="a.toml")


def test_colours_are_linear_lists_or_srgb_hex_decoded_once():
    p = parse_preset(b'name="a"\nmodel="disney"\n[params]\nbase_color="#808080"', where="a")
    assert p.params["base_color"] == "#808080"  # kept as written for saving
    c = check_params(p.model, p.params, where=None).base_color
    assert c == decode_hex("#808080")


def test_dump_round_trips_and_keeps_colours_on_one_line():
    text = BUILTIN.find("dust_over_plastic").read_bytes()
    p = parse_preset(text, where="x")
    again = dump_preset(p)
    assert parse_preset(again.encode(), where="x") == p
    gold = dump_preset(BUILTIN.read("gold")[0])
    assert "base_color = [1.0, 0.782, 0.344]\n" in gold


# -- resolution -------------------------------------------------------------------------


def test_extends_chain_merges_child_over_parent(lib, tmp_path):
    write(tmp_path, "a", 'name="a"\nextends="gold"\n[params]\nroughness=0.6\n')
    write(tmp_path, "b", 'name="b"\nextends="a"\ndescription="B"\n[params]\nior=1.4\n')
    m = lib.load("b")
    assert (
        m.model == "disney" and m.description == "B" and m.tags == ["metal", "polished", "precious"]
    )
    assert m.params.roughness == 0.6 and m.params.metallic == 1.0
    # `ior` in the child replaces the parent's spelling `specular` instead of clashing.
    assert m.params.ior == 1.4 and "specular" not in m.params.model_fields_set
    assert [p.name for p in m.chain] == ["b.toml", "a.toml", "gold.toml"]


def test_cycles_and_missing_parents_name_the_chain(lib, tmp_path):
    write(tmp_path, "a", 'name="a"\nextends="b"\n')
    write(tmp_path, "b", 'name="b"\nextends="c"\n')
    write(tmp_path, "c", 'name="c"\nextends="a"\n')
    write(tmp_path, "d", 'name="d"\nextends="gld"\n')
    with pytest.raises(PresetError, match="cycle of presets: a → b → c → a"):
        lib.load("a")
    with pytest.raises(PresetNotFoundError) as info:
        lib.load("d")
    msg = str(info.value)
    assert "d.toml: extends: parent 'gld' not found" in msg and "did you mean 'gold'" in msg
    assert "chain d → gld" in msg


def test_model_mismatch_in_chain_is_an_error(lib, tmp_path):
    write(tmp_path, "a", 'name="a"\nmodel="layered"\nextends="gold"\n[[layers]]\npreset="iron"\n')
    with pytest.raises(PresetError, match="differs from its parent 'gold'"):
        lib.load("a")


def test_layers_resolve_references_inline_params_and_overrides(lib, tmp_path):
    write(
        tmp_path,
        "lay",
        'name="lay"\nmodel="layered"\n'
        '[[layers]]\npreset="gold"\n'
        '[[layers]]\npreset="gold"\nparams={roughness=0.9}\n'
        'mask={kind="texture", path="masks/m.exr"}\n'
        '[[layers]]\nmodel="disney"\nparams={base_color="#ffffff"}\nmask=0.25\n',
    )
    m = lib.load("lay")
    bottom, over, inline = m.layers
    assert bottom.material.params.roughness == 0.2 and over.material.params.roughness == 0.9
    assert isinstance(over.mask, TextureMask)
    assert over.mask.path == (tmp_path / "masks" / "m.exr").resolve()
    assert inline.material.params.base_color == (1.0, 1.0, 1.0) and inline.mask.value == 0.25


def test_layered_preset_as_a_layer_multiplies_masks(lib, tmp_path):
    write(tmp_path, "outer", 'name="outer"\nmodel="layered"\n[[layers]]\npreset="rusty_iron"\n'
          'mask=0.5\npresence=0.5\n')  # fmt: skip
    m = lib.load("outer")
    assert [layer.name for layer in m.layers] == ["rusty_iron/iron", "rusty_iron/rust"]
    assert m.layers[0].mask.value == 0.5  # constant 1 × 0.5 folds to 0.5
    assert isinstance(m.layers[1].mask, CombineMask) and m.layers[1].mask.kind == "multiply"
    assert [layer.presence for layer in m.layers] == [0.5, 0.5]


def test_layer_cycle_and_mixed_models_are_errors(lib, tmp_path):
    write(tmp_path, "x", 'name="x"\nmodel="layered"\n[[layers]]\npreset="y"\n')
    write(tmp_path, "y", 'name="y"\nmodel="layered"\n[[layers]]\npreset="x"\n')
    with pytest.raises(PresetError, match="cycle of presets: x → y → x"):
        lib.load("x")
    write(tmp_path, "z", 'name="z"\nmodel="layered"\n[[layers]]\npreset="nope"\n')
    with pytest.raises(PresetNotFoundError, match=r"z.toml: layers\[0\].preset: layer 'nope'"):
        lib.load("z")


# -- the search path --------------------------------------------------------------------


def test_search_order_user_libraries_first_then_env_then_builtin(tmp_path, monkeypatch):
    first, second = tmp_path / "first", tmp_path / "second"
    for folder, colour in ((first, "0.1"), (second, "0.2")):
        folder.mkdir()
        write(folder, "gold", f'name="gold"\nmodel="disney"\n[params]\nroughness={colour}\n')
    monkeypatch.setenv("LOOKDEV_LIBRARY_PATH", str(second))
    lib = Library([first])
    assert lib.folders == [first, second, builtin_folder()]
    assert lib.load("gold").params.roughness == 0.1
    assert lib.definitions("gold") == [
        first / "gold.toml",
        second / "gold.toml",
        *BUILTIN.definitions("gold"),
    ]
    assert Library().load("gold").params.roughness == 0.2


def test_builtin_folder_named_again_is_not_searched_twice():
    lib = Library([builtin_folder()], use_env=False)
    assert lib.folders == [builtin_folder()] and lib.definitions("gold") == BUILTIN.definitions(
        "gold"
    )


def test_unknown_name_suggests_close_ones(lib):
    with pytest.raises(PresetNotFoundError, match="did you mean 'copper'"):
        lib.load("coper")


def test_missing_library_folder_is_an_error(tmp_path):
    with pytest.raises(LibraryError, match="does not exist"):
        Library([tmp_path / "nope"], use_env=False).names()


def test_load_material_by_name_or_path(tmp_path):
    path = write(tmp_path, "mine", 'name="mine"\nextends="gold"\n')
    assert load_material(path).params.metallic == 1.0
    assert load_material(str(path)).name == "mine"
    assert load_material("gold").name == "gold"


def test_listing_index_is_used_and_notices_changes(tmp_path):
    write(tmp_path, "a", 'name="a"\nmodel="disney"\ndescription="one"\n')
    assert scan_folder(tmp_path)[0].description == "one"
    index = json.loads((tmp_path / INDEX_NAME).read_text())
    # Fresh files are 'racy' (changed within the timestamp granularity), not cached yet.
    assert index["entries"] == []
    old = 1_000_000_000
    os.utime(tmp_path / "a.toml", ns=(old, old))
    scan_folder(tmp_path)
    assert json.loads((tmp_path / INDEX_NAME).read_text())["entries"][0][0] == "a.toml"
    write(tmp_path, "a", 'name="a"\nmodel="disney"\ndescription="two"\n')
    assert scan_folder(tmp_path)[0].description == "two"
    stat = os.stat(tmp_path / "a.toml")
    key = f"{stat.st_mtime_ns}, {stat.st_size}, {stat.st_ino}"
    well_formed_but_wrong_types = (
        f'{{"version": 3, "entries": [["a.toml", {key}, "a", 5, [1], [2], null, null]]}}'
    )
    for junk in (
        "{not json",
        '{"version": 3, "entries": [["a.toml", "x"], 5]}',
        "[]",
        well_formed_but_wrong_types,
    ):
        (tmp_path / INDEX_NAME).write_text(junk)
        assert scan_folder(tmp_path)[0].description == "two"


def test_broken_files_are_listed_with_their_error_not_raised(tmp_path):
    write(tmp_path, "bad", "name = [")
    (h,) = scan_folder(tmp_path)
    assert h.error and "malformed TOML" in h.error and "\n" not in h.error


# -- saving -----------------------------------------------------------------------------


def test_save_refuses_overwrite_without_force_and_bad_names(lib, tmp_path):
    p = PresetFile(name="mine", extends="gold", params={"roughness": 0.3})
    path = lib.save(p)
    assert path == tmp_path / "mine.toml" and lib.load("mine").params.roughness == 0.3
    with pytest.raises(LibraryError, match="already exists.*--force"):
        lib.save(p)
    lib.save(p.model_copy(update={"params": {"roughness": 0.4}}), force=True)
    assert lib.load("mine").params.roughness == 0.4
    for bad in ("../evil", "/abs", "a/b", "a\\b", "..", "", "gold\n", "x" * 101):
        with pytest.raises(PresetError, match="not allowed"):
            lib.save(PresetFile.model_construct(name=bad, extends="gold", params={}))
    assert sorted(f.name for f in tmp_path.iterdir() if not f.name.startswith(".")) == ["mine.toml"]


def test_save_validates_before_writing(lib, tmp_path):
    with pytest.raises(PresetError, match="cycle"):
        lib.save(PresetFile(name="loop", extends="loop"))
    with pytest.raises(ParameterError):
        lib.save(PresetFile(name="x", model="disney", params={"roughness": 9}))
    assert not list(tmp_path.glob("*.toml"))


def test_builtin_is_read_only_and_unwritable_folders_fail_cleanly(tmp_path):
    lib = Library([tmp_path], use_env=False)
    with pytest.raises(LibraryError, match="built-in preset and read-only"):
        lib.update("gold", {"roughness": 0.1})
    with pytest.raises(LibraryError, match="built-in preset and read-only"):
        lib.remove("gold")
    with pytest.raises(LibraryError, match="no user library"):
        Library(use_env=False).save(PresetFile(name="x", extends="gold"))
    blocker = tmp_path / "file"
    blocker.write_text("")
    with pytest.raises(LibraryError, match="cannot write to this library"):
        lib.save(PresetFile(name="x", extends="gold"), folder=blocker / "lib")


def test_update_keeps_layers_and_their_masks(lib, tmp_path):
    text = builtin_folder().joinpath("layered", "dust_over_plastic.toml").read_bytes()
    lib.save(parse_preset(text, where="x").model_copy(update={"name": "dusty"}))
    lib.update("dusty", {"description": "Mine."})
    m = lib.load("dusty")
    assert m.description == "Mine." and m.layers == BUILTIN.load("dust_over_plastic").layers


def test_update_and_remove(lib, tmp_path):
    lib.save(PresetFile(name="mine", extends="gold"))
    lib.update("mine", {"roughness": 0.7, "tags": ["worn"]})
    m = lib.load("mine")
    assert m.params.roughness == 0.7 and m.tags == ["worn"]
    lib.update("mine", {"roughness": None})
    assert lib.load("mine").params.roughness == 0.2  # inherited again
    with pytest.raises(PresetError, match="'name' cannot be set"):
        lib.update("mine", {"name": "x"})
    lib.save(PresetFile(name="child", extends="mine"))
    with pytest.raises(LibraryError, match="child build on 'mine'"):
        lib.remove("mine")
    lib.remove("child")
    lib.remove("mine")
    assert "mine" not in lib.names()


def test_find_picks_the_file_a_listing_would_without_reading_any(tmp_path, monkeypatch):
    """A name resolves to the shallowest file, then the first by path, as ``presets list``
    shows it; hidden folders never win; no preset file is opened to find it."""
    import lookdev.library.index as index

    body = 'model = "disney"\n[params]\nroughness = 0.5\n'
    for rel in ("b/c/deep.toml", "z/deep.toml", "a/twice.toml", "b/twice.toml", ".hid/h.toml"):
        (tmp_path / rel).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / rel).write_text(body, encoding="utf-8")
    library = Library([tmp_path], use_env=False)
    listed = {n: library.definitions(n)[0] for n in ("deep", "twice")}
    assert listed == {"deep": tmp_path / "z/deep.toml", "twice": tmp_path / "a/twice.toml"}
    monkeypatch.setattr(index, "read_header", lambda *a, **k: pytest.fail("a header was read"))
    fresh = Library([tmp_path], use_env=False)
    assert {n: fresh.find(n) for n in listed} == listed
    assert fresh._find_in(tmp_path, "h") is None  # hidden: not a preset of the library


def test_every_builtin_name_finds_the_file_the_listing_shows():
    fresh = Library(use_env=False)  # found before any listing: from the folder names alone
    found = {n: fresh.find(n) for n in BUILTIN_NAMES}
    assert found == {n: BUILTIN.definitions(n)[0] for n in BUILTIN_NAMES}
