"""Texture paths a designer save writes: relative to the NEW file, resolving to the image
picked, and never into a folder that goes away (a picked file outside the library is
copied beside the preset)."""

from __future__ import annotations

import os
import tomllib
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from lookdev.library import Library, LibraryError


def _png(path: Path, value: int) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    Image.fromarray(np.full((8, 8), value, np.uint8)).save(path)
    return path


def _roughness_map(root: str, path: str) -> dict:
    """The edit that drives roughness with the image ``path`` under the picker's ``root``."""
    return {"op": "set", "target": None, "field": "roughness", "value": _map(root, path)}


def _map(root: str, path: str) -> dict:
    return {"texture": {"root": root, "path": path}, "channel": "r", "colorspace": "Raw"}


def _lands(preset: Path, written: str) -> Path:
    return Path(os.path.realpath(preset.parent / written))


def _check_resolves(cli, user_library: Path, name: str, image: Path) -> None:
    material = Library([user_library], use_env=False).load(name)
    assert "roughness" in material.textures
    r = cli("presets", "show", name, "--resolved", "--library", str(user_library))
    assert r.code == 0, r.err
    assert image.name in r.out


def test_a_map_picked_on_a_builtin_is_saved_relative_to_the_new_file(designer, user_library, cli):
    image = _png(user_library / "maps" / "rough.png", 90)
    s = designer.session
    assert s.path.parent != user_library  # gold is the built-in preset
    s.edit(_roughness_map("library0", "maps/rough.png"))
    path = s.save_new("my_gold")
    written = tomllib.loads(path.read_text())["params"]["roughness"]["texture"]
    assert written == "maps/rough.png"
    assert _lands(path, written) == Path(os.path.realpath(image))
    _check_resolves(cli, user_library, "my_gold", image)
    assert s.save_messages == []  # nothing needed copying


def test_save_as_new_into_a_subfolder_rebases_the_path(designer, user_library, cli):
    image = _png(user_library / "rough.png", 90)
    s = designer.session
    s.edit(_roughness_map("library0", "rough.png"))
    path = s.save_new("deep_gold", user_library / "metals" / "warm")
    written = tomllib.loads(path.read_text())["params"]["roughness"]["texture"]
    assert written == "../../rough.png"
    assert _lands(path, written) == Path(os.path.realpath(image))
    _check_resolves(cli, user_library, "deep_gold", image)


def test_a_map_in_the_session_folder_is_copied_beside_the_preset(designer, user_library, cli):
    picked = _png(designer.folder / "exports" / "rough.png", 120)
    s = designer.session
    s.edit(_roughness_map("session", "exports/rough.png"))
    path = s.save_new("copied_gold")
    written = tomllib.loads(path.read_text())["params"]["roughness"]["texture"]
    copy = _lands(path, written)
    assert copy.parent == Path(os.path.realpath(user_library))
    assert copy.read_bytes() == picked.read_bytes()
    assert s.save_messages == [f"copied {picked.name} into the library as {written}"]
    designer.close()
    picked.unlink()  # the session folder goes when the designer stops
    _check_resolves(cli, user_library, "copied_gold", copy)


def test_a_copy_never_replaces_another_image(designer, user_library):
    _png(user_library / "rough.png", 10)  # the library's own, different image
    _png(designer.folder / "rough.png", 200)
    s = designer.session
    s.edit(_roughness_map("session", "rough.png"))
    path = s.save_new("second")
    written = tomllib.loads(path.read_text())["params"]["roughness"]["texture"]
    assert written != "rough.png"
    assert np.asarray(Image.open(user_library / "rough.png")).max() == 10
    assert np.asarray(Image.open(_lands(path, written))).min() == 200
    s.save_over()  # the same picked image again: the copy is reused, not made twice
    assert sorted(p.name for p in user_library.glob("*.png")) == sorted(["rough.png", written])


def test_a_mask_from_the_session_folder_survives_the_session(designer, user_library):
    picked = _png(designer.folder / "mask.png", 255)
    s = designer.session
    s.replace({"name": "untitled", "model": "layered", "layers": [{"preset": "gold"}]})
    mask = {"kind": "texture", "path": {"root": "session", "path": "mask.png"}, "channel": 0}
    s.edit({"op": "layer_add", "preset": "rust", "mask": mask})
    path = s.save_new("masked", user_library / "layered")
    written = tomllib.loads(path.read_text())["layers"][1]["mask"]["path"]
    assert written == "mask.png"
    assert _lands(path, written).read_bytes() == picked.read_bytes()
    picked.unlink()
    assert Library([user_library], use_env=False).load("masked").layers[1].material.name == "rust"


def test_save_over_a_user_preset_in_a_subfolder(designer, user_library, cli):
    image = _png(user_library / "rough.png", 90)
    session_image = _png(designer.folder / "spots.png", 30)
    s = designer.session
    path = s.save_new("mine", user_library / "sub")
    s.edit(_roughness_map("library0", "rough.png"))
    assert s.save_over() == path
    written = tomllib.loads(path.read_text())["params"]["roughness"]["texture"]
    assert written == "../rough.png" and _lands(path, written) == Path(os.path.realpath(image))
    _check_resolves(cli, user_library, "mine", image)
    s.edit(_roughness_map("session", "spots.png"))
    s.save_over()
    written = tomllib.loads(path.read_text())["params"]["roughness"]["texture"]
    assert written == "spots.png"
    assert _lands(path, written).read_bytes() == session_image.read_bytes()
    assert s.doc["params"]["roughness"]["texture"] == written  # the session follows the copy
    assert not s.dirty


def test_a_refused_save_leaves_no_copy(designer, user_library):
    _png(designer.folder / "rough.png", 120)
    s = designer.session
    s.save_new("taken")
    s.open("gold")
    s.edit(_roughness_map("session", "rough.png"))
    with pytest.raises(LibraryError, match="already exists"):
        s.save_new("taken")
    assert list(user_library.glob("*.png")) == []


def test_the_save_response_says_what_was_copied(client, designer):
    _png(designer.folder / "rough.png", 120)
    t = designer.token
    op = _roughness_map("session", "rough.png")
    r = client.post(f"/{t}/api/edit", json=op)
    assert r.status_code == 200, r.text
    r = client.post(f"/{t}/api/save", json={"mode": "new", "name": "from_page"})
    assert r.status_code == 200, r.text
    assert r.json()["copied"] == ["copied rough.png into the library as rough.png"]


def test_an_image_of_another_library_is_copied_into_the_one_saved_to(user_library, tmp_path):
    from lookdev.pipeline.designer.guard import Roots
    from lookdev.pipeline.designer.session import Session

    other = tmp_path / "shared"
    image = _png(other / "rough.png", 70)
    library = Library([user_library, other], use_env=False)
    s = Session(library, "gold", roots=Roots({"library0": user_library, "library1": other}))
    s.edit(_roughness_map("library1", "rough.png"))
    path = s.save_new("borrowed")
    assert path.parent == user_library
    written = tomllib.loads(path.read_text())["params"]["roughness"]["texture"]
    assert written == "rough.png" and (user_library / written).read_bytes() == image.read_bytes()
    assert Library([user_library], use_env=False).load("borrowed").textures


def test_save_over_from_the_page_says_what_was_copied(client, designer, user_library):
    _png(designer.folder / "spots.png", 30)
    t = designer.token
    assert (
        client.post(f"/{t}/api/save", json={"mode": "new", "name": "mine"}).json()["copied"] == []
    )
    op = _roughness_map("session", "spots.png")
    assert client.post(f"/{t}/api/edit", json=op).status_code == 200
    r = client.post(f"/{t}/api/save", json={"mode": "over"})
    assert r.status_code == 200, r.text
    assert r.json()["copied"] == ["copied spots.png into the library as spots.png"]
    assert (user_library / "spots.png").is_file()
