"""The designer's edit session: schema-checked edits, undo/redo, inherited vs overridden,
save as a child preset (only the changes) or over the file, through the library."""

from __future__ import annotations

import os
import stat
import threading
import tomllib

import pytest

from lookdev.library import Library, LibraryError
from lookdev.pipeline.designer.session import EditRefused, Session


def _session(folder, preset="gold"):
    return Session(Library([folder], use_env=False), preset)


def _set(s, field, value, target=None):
    s.edit({"op": "set", "target": target, "field": field, "value": value})


@pytest.mark.parametrize(
    ("field", "value", "message"),
    [
        ("roughness", 1.5, "params.roughness: 1.5 is out of range; allowed [0, 1]"),
        ("roughness", -0.0001, "out of range"),
        ("roughness", "0.5", "params.roughness"),
        ("sheen_model", "velvet", "params.sheen_model"),
        ("base_color", [1.0, 2.0, 0.5], "params.base_color"),
        ("no_such", 1.0, "no_such"),
        ("specular_gamma", 0.0, "params.specular_gamma"),
    ],
)
def test_an_invalid_edit_is_refused_with_the_schema_message(user_library, field, value, message):
    s = _session(user_library)
    before, version = dict(s.doc["params"]), s.version
    with pytest.raises(EditRefused, match=message.replace("[", r"\[").replace("]", r"\]")):
        _set(s, field, value)
    assert s.doc["params"] == before and s.version == version and not s.dirty


def test_edges_of_the_range_are_accepted(user_library):
    s = _session(user_library)
    for v in (0.0, 1.0):
        _set(s, "roughness", v)
        assert s.material().params.roughness == v


def test_undo_redo(user_library):
    s = _session(user_library)
    _set(s, "roughness", 0.6)
    _set(s, "metallic", 0.5)
    s.undo()
    assert s.doc["params"]["metallic"] == 1.0 and s.doc["params"]["roughness"] == 0.6
    s.undo()
    assert not s.dirty
    s.redo()
    s.redo()
    assert s.material().params.metallic == 0.5
    s.undo()
    _set(s, "roughness", 0.1)  # a new edit forgets the redo
    assert not s.redo_stack


def test_inherited_and_overridden(user_library):
    (user_library / "warm_gold.toml").write_text(
        'name = "warm_gold"\nextends = "gold"\n[params]\nroughness = 0.4\n'
    )
    s = _session(user_library, "warm_gold")
    top = s.state()["targets"][0]
    assert top["overridden"] == ["roughness"] and top["values"]["roughness"] == 0.4
    assert top["base"]["roughness"] == 0.2 and top["values"]["metallic"] == 1.0
    s.edit({"op": "reset", "target": None, "field": "roughness"})
    assert s.material().params.roughness == 0.2  # the parent's again


def test_save_as_new_writes_only_the_changes(user_library):
    s = _session(user_library)
    _set(s, "roughness", 0.35)
    path = s.save_new("my_gold")
    doc = tomllib.loads(path.read_text())
    assert doc == {"name": "my_gold", "extends": "gold", "params": {"roughness": 0.35}}
    assert not s.dirty and s.name == "my_gold"
    assert stat.S_IMODE(path.stat().st_mode) == 0o666 & ~_umask()
    loaded = Library([user_library], use_env=False).load("my_gold")
    assert loaded.params.roughness == 0.35 and loaded.params.metallic == 1.0
    assert [p.name for p in loaded.chain] == ["my_gold.toml", "gold.toml"]


def test_a_reset_override_is_written_as_the_parents_value(user_library):
    (user_library / "warm_gold.toml").write_text(
        'name = "warm_gold"\nextends = "gold"\n[params]\nroughness = 0.4\n'
    )
    s = _session(user_library, "warm_gold")
    s.edit({"op": "reset", "target": None, "field": "roughness"})
    doc = tomllib.loads(s.save_new("cool_gold").read_text())
    assert doc["extends"] == "warm_gold" and doc["params"] == {"roughness": 0.2}


def test_save_as_new_refuses_an_existing_name(user_library):
    s = _session(user_library)
    s.save_new("mine")
    _set(s, "roughness", 0.5)
    with pytest.raises(LibraryError, match="already exists"):
        s.save_new("mine")


def test_save_over_its_own_file(user_library):
    s = _session(user_library)
    s.save_new("mine")
    _set(s, "roughness", 0.7)
    path = s.save_over()
    assert tomllib.loads(path.read_text())["params"] == {"roughness": 0.7}


def test_save_over_refuses_a_file_changed_on_disk(user_library):
    s = _session(user_library)
    path = s.save_new("mine")
    path.write_text(path.read_text() + "# someone else\n")
    _set(s, "roughness", 0.7)
    with pytest.raises(LibraryError, match="changed on disk"):
        s.save_over()
    assert "someone else" in path.read_text()


def test_save_over_a_builtin_is_refused(user_library):
    s = _session(user_library)
    _set(s, "roughness", 0.7)
    with pytest.raises(LibraryError, match="built-in preset and read-only"):
        s.save_over()


def test_a_read_only_library_is_refused_clearly(user_library, monkeypatch):
    s = _session(user_library)
    user_library.chmod(0o555)
    if os.geteuid() == 0:  # root may write anyway: the library asks os.access
        real = os.access
        monkeypatch.setattr(os, "access", lambda p, m: False if p == user_library else real(p, m))
    try:
        with pytest.raises(LibraryError, match="read-only"):
            s.save_new("mine")
    finally:
        user_library.chmod(0o755)
    assert list(user_library.iterdir()) == []


def test_a_new_layered_preset(user_library):
    s = _session(user_library)
    _set(s, "roughness", 0.3)
    s.replace(
        {
            "name": "untitled",
            "model": "layered",
            "layers": [{"preset": "gold", "params": {"roughness": 0.3}}],
        }
    )
    s.edit({"op": "layer_add", "preset": "rust", "mask": {"kind": "noise", "scale": 6}})
    with pytest.raises(EditRefused, match="scale"):
        s.edit({"op": "layer_mask", "index": 1, "mask": {"kind": "noise", "scale": -1}})
    s.edit({"op": "layer_move", "index": 1, "to": 0})
    s.edit({"op": "layer_move", "index": 0, "to": 1})
    path = s.save_new("rusty_gold")
    doc = tomllib.loads(path.read_text())
    assert "extends" not in doc and doc["model"] == "layered"
    assert doc["layers"][1] == {
        "name": "rust",
        "preset": "rust",
        "mask": {"kind": "noise", "scale": 6.0},
    }
    assert s.state()["targets"][1]["model"] == "disney"


def test_hidden_layers_leave_the_blend_not_the_preset(user_library):
    s = _session(user_library, "dust_over_plastic")
    s.set_hidden(1, True)
    assert len(s.material().layers) == 1 and len(s.doc["layers"]) == 2
    s.set_hidden(0, True)
    assert s.material().layers[0].mask.value == 0.0


def test_blends_are_cached_and_undo_costs_nothing(user_library):
    s = _session(user_library, "dust_over_plastic")
    first = s.hub()
    _set(s, "roughness", 0.8, target=1)
    second = s.hub()
    s.undo()
    assert s.hub() is first and second is not first
    assert [k for k, _ in s.blend_log] == ["blended", "blended", "cached"]


def test_two_tabs_editing_at_once(user_library):
    s = _session(user_library)
    errors = []

    def tab(values):
        for v in values:
            try:
                _set(s, "roughness", v)
            except Exception as exc:  # noqa: BLE001
                errors.append(exc)

    threads = [
        threading.Thread(target=tab, args=([i / 40 for i in range(k, 40, 2)],)) for k in (0, 1)
    ]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not errors and len(s.undo_stack) == 40
    assert s.material().params.roughness == s.doc["params"]["roughness"]


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def _grey_png(path, value=128):
    import numpy as np
    from PIL import Image

    ramp = np.tile(np.linspace(0, 255, 8, dtype=np.uint8), (8, 1))
    Image.fromarray(ramp if value is None else np.full((8, 8), value, np.uint8)).save(path)


def test_a_parameter_driven_by_a_map_can_be_swapped_and_made_constant(user_library):
    from lookdev.pipeline.designer.guard import Roots

    _grey_png(user_library / "rough.png")
    _grey_png(user_library / "ramp.png", None)
    s = Session(
        Library([user_library], use_env=False), "gold", roots=Roots({"library0": user_library})
    )
    s.save_new("mapped")  # in the user library: texture paths are relative to it
    ref = {"root": "library0", "path": "rough.png"}
    _set(s, "roughness", {"texture": ref, "channel": "r", "colorspace": "Raw"})
    assert s.doc["params"]["roughness"]["texture"] == "rough.png"
    assert "roughness" in s.material().textures
    shown = s.state()["targets"][0]["values"]["roughness"]
    assert shown["texture"] == "rough.png" and shown["channel"] == "r"
    with pytest.raises(EditRefused, match="channel"):
        _set(s, "roughness", {"texture": ref, "channel": "q"})
    _set(s, "roughness", {"texture": {"root": "library0", "path": "ramp.png"}, "channel": "r"})
    assert s.hub().maps["roughness"].std() > 0.1  # the ramp varies across u
    _set(s, "roughness", 0.4)  # replaced by a constant
    assert s.material().textures == {} and s.material().params.roughness == 0.4


def test_a_layer_mask_from_a_texture(user_library):
    from lookdev.pipeline.designer.guard import Roots

    _grey_png(user_library / "mask.png", None)
    s = Session(
        Library([user_library], use_env=False), "gold", roots=Roots({"library0": user_library})
    )
    s.replace({"name": "untitled", "model": "layered", "layers": [{"preset": "gold"}]})
    mask = {"kind": "texture", "path": {"root": "library0", "path": "mask.png"}, "channel": 0}
    s.edit({"op": "layer_add", "preset": "rust", "mask": mask})
    path = s.save_new("masked")
    doc = tomllib.loads(path.read_text())
    assert doc["layers"][1]["mask"] == {"kind": "texture", "path": "mask.png"}
    assert Library([user_library], use_env=False).load("masked").layers[1].material.name == "rust"


def test_a_mask_preview_is_the_blends_own_evaluation(user_library):
    import io

    import numpy as np
    from PIL import Image

    from lookdev.pipeline.designer.guard import Roots
    from lookdev.pipeline.designer.previews import PREVIEW_PX, mask_of, preview_png

    _grey_png(user_library / "mask.png", None)  # a ramp along u, 0 .. 255
    s = Session(
        Library([user_library], use_env=False), "gold", roots=Roots({"library0": user_library})
    )
    s.save_new("base")
    s.replace({"name": "untitled", "model": "layered", "layers": [{"preset": "gold"}]})
    ref = {"root": "library0", "path": "mask.png"}
    mask = {"kind": "texture", "path": ref, "wrap": "clamp"}
    s.edit({"op": "layer_add", "preset": "rust", "mask": mask})
    grey = np.asarray(Image.open(io.BytesIO(preview_png(mask_of(s, 1, "mask")))))
    assert grey.shape == (PREVIEW_PX, PREVIEW_PX)
    assert grey[:, 0].max() < 40 and grey[:, -1].min() > 215  # dark at u = 0, light at u = 1
    s.edit({"op": "layer_mask", "index": 1, "mask": {**s.doc["layers"][1]["mask"], "invert": True}})
    inverted = np.asarray(Image.open(io.BytesIO(preview_png(mask_of(s, 1, "mask")))))
    assert np.abs(inverted.astype(int) + grey - 255).max() <= 1
    ramp = {"kind": "ramp", "axis": "v"}  # v runs up the image: the top row is v ≈ 1
    s.edit({"op": "layer_mask", "index": 1, "mask": ramp})
    up = np.asarray(Image.open(io.BytesIO(preview_png(mask_of(s, 1, "mask")))))
    assert up[0].mean() > 215 and up[-1].mean() < 40


def test_a_colour_shows_its_hex(user_library):
    s = Session(Library([user_library], use_env=False), "gold")
    _set(s, "base_color", "#808080")
    shown = s.state()["targets"][0]
    assert shown["hex"]["base_color"] == "#808080"
    assert shown["values"]["base_color"][0] == pytest.approx(0.2158605, abs=1e-5)
