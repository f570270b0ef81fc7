"""Every command that writes a file makes its folder (``mkdir -p``), by one rule
(:func:`lookdev.library.files.make_folder`), and a command that fails leaves no folder."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("pxr")
oiio = pytest.importorskip("OpenImageIO")


def _png(path: Path, pixels: np.ndarray) -> None:
    spec = oiio.ImageSpec(pixels.shape[1], pixels.shape[0], pixels.shape[2], oiio.UINT8)
    out = oiio.ImageOutput.create(str(path))
    out.open(str(path), spec)
    out.write_image((pixels * 255).astype(np.uint8))
    out.close()


@pytest.fixture
def fresh(tmp_path, monkeypatch):
    """A fresh folder holding hero.toml (a textured preset), as the working directory."""
    _png(tmp_path / "hero_base.png", np.random.default_rng(0).random((4, 4, 3)))
    (tmp_path / "hero.toml").write_text(
        'name = "hero"\nmodel = "disney"\n\n[params]\nroughness = 0.4\n\n'
        '[params.base_color]\ntexture = "hero_base.png"\ncolorspace = "sRGB - Texture"\n'
    )
    monkeypatch.chdir(tmp_path)
    return tmp_path


def test_export_usd_collect_preview_geometry_into_a_new_folder(cli, fresh):
    args = ("export", "usd", "hero.toml", "-o", "pub/hero.usda")
    result = cli(*args, "--collect", "--preview-geometry")
    assert result.code == 0, result.err
    assert (fresh / "pub/hero.usda").is_file()
    assert (fresh / "pub/hero_textures/hero_base.png").is_file()


def test_import_usd_into_a_new_folder_with_rename(cli, fresh):
    assert cli("export", "usd", "hero.toml", "gold", "-o", "looks.usda").code == 0
    result = cli("import", "usd", "looks.usda", "-o", "imported/", "--rename")
    assert result.code == 0, result.err
    assert sorted(p.name for p in (fresh / "imported").iterdir()) == ["gold.toml", "hero.toml"]


@pytest.mark.parametrize(
    "args, written",
    [
        (
            ("export", "usd", "gold", "-o", "a/b/gold.usda", "--mtlx", "c/gold.mtlx"),
            ["a/b/gold.usda", "c/gold.mtlx"],
        ),
        (
            ("export", "usd", "gold", "velvet", "-o", "lib/all.usda", "--split", "lib/parts"),
            ["lib/all.usda", "lib/parts/gold.usda"],
        ),
        (("export", "mitsuba", "gold", "-o", "m/n/gold.xml"), ["m/n/gold.xml"]),
        (("blend", "gold", "-o", "maps/gold", "-r", "4"), ["maps/gold/gold.json"]),
    ],
)
def test_every_writing_command_makes_its_folder(cli, fresh, args, written):
    result = cli(*args)
    assert result.code == 0, result.err
    for path in written:
        assert (fresh / path).is_file(), path


def test_a_failed_write_leaves_no_new_folder(cli, fresh):
    before = sorted(p.name for p in fresh.iterdir())
    assert cli("export", "usd", "no_such_preset", "-o", "new/x.usda").code == 2
    blocked = cli("export", "usd", "gold", "-o", "hero.toml/x.usda")
    assert blocked.code == 2 and "is a file" in blocked.err and len(blocked.err.splitlines()) == 1
    assert cli("import", "usd", "missing.usda", "-o", "new2/").code == 2
    assert sorted(p.name for p in fresh.iterdir()) == before
