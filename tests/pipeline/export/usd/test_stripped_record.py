"""lookdev's own networks read back without its customData (what a DCC leaves after a
re-save): every built-in preset comes back with the same model and values, or with the
difference named."""

from __future__ import annotations

from pathlib import Path

import pytest

pytest.importorskip("pxr")

from pxr import Usd  # noqa: E402

import lookdev  # noqa: E402
from lookdev.library import Library  # noqa: E402
from lookdev.materials.fresnel import specular_to_ior  # noqa: E402
from lookdev.pipeline.export.usd.lobes import DEFAULTS, effective  # noqa: E402
from lookdev.pipeline.export.usd.pixar import ior_to_normal_fresnel  # noqa: E402
from lookdev.pipeline.export.usd.reader import import_usd  # noqa: E402


def _canonical(model: str, params: dict) -> dict:
    """Effective values, the F0 in one spelling (Disney: ior; Pixar: normal_fresnel)."""
    v = dict(DEFAULTS[model])
    v.update({k: tuple(x) if isinstance(x, list) else x for k, x in params.items()})
    if model == "disney":
        if "specular" in params and "ior" not in params:
            v["ior"] = specular_to_ior(params["specular"])
        v.pop("specular", None)
    else:
        eta = params.get("eta", params.get("ior"))
        if eta is not None:
            v["normal_fresnel"] = ior_to_normal_fresnel(eta)
        v.pop("eta", None)
        v.pop("ior", None)
    return effective(v, model)


def _close(a, b) -> bool:
    if isinstance(a, tuple) or isinstance(b, tuple):
        a, b = (x if isinstance(x, tuple) else (x,) * 3 for x in (a, b))
        return all(map(_close, a, b))
    if isinstance(a, float) and isinstance(b, float):
        return a == pytest.approx(b, rel=1e-4, abs=1e-6)
    return a == b


def _strip(path: Path, out: Path) -> None:
    stage = Usd.Stage.Open(str(path))
    for prim in stage.Traverse():
        if prim.GetCustomDataByKey("lookdev") is not None:
            prim.ClearCustomDataByKey("lookdev")
    stage.GetRootLayer().Export(str(out))


@pytest.fixture(scope="module")
def stripped(tmp_path_factory):
    folder = tmp_path_factory.mktemp("strip")
    lookdev.export_usd([], folder / "all.usda", all_presets=True, map_resolution=8)
    _strip(folder / "all.usda", folder / "stripped.usda")
    text = (folder / "stripped.usda").read_text()
    assert "customData" not in text or "lookdev" not in text.split("customData", 1)[1][:40]
    skipped: list[str] = []
    found = import_usd(folder / "stripped.usda", skipped)
    return {m.name: m for m in found}, skipped


def test_every_builtin_preset_comes_back_exact_or_with_a_named_loss(stripped):
    found, skipped = stripped
    library = Library()
    counts = {"exact": 0, "named": 0}
    for name in library.names():
        material = lookdev.load(name)
        if material.layers or material.params is None:
            continue
        imported = found[name]
        assert imported.model == material.model, name  # Pixar stays Pixar
        source = _canonical(
            material.model, material.params.model_dump(exclude_unset=True, exclude_none=True)
        )
        got = _canonical(imported.model, imported.params)
        differ = [k for k in source if not _close(source[k], got[k])]
        losses = " ".join(imported.loss)
        assert all(k in losses for k in differ), (name, differ, imported.loss)
        counts["named" if differ else "exact"] += 1
    assert counts["exact"] > 0
    # the layered Pixar presets are skipped with their reason, never silently
    assert all("layered Pixar material" in line for line in skipped)


@pytest.mark.parametrize(
    "name, want",
    [
        ("felt", {"sheen_model": "conty_kulla", "sheen_roughness": 0.7}),
        ("velvet_silk", {"sheen_lambda": "exact", "sheen_roughness": 0.04}),
        ("car_paint_red", {"clearcoat": 1.0}),  # not 4.0: lookdev's coat, not OpenPBR's
    ],
)
def test_sheen_settings_and_coat_survive_the_strip(stripped, name, want):
    found, _ = stripped
    params = found[name].params
    for key, value in want.items():
        assert _close(params[key], value), (key, params.get(key))


def test_pixar_presets_stay_pixar(stripped):
    found, _ = stripped
    pixar = [n for n in Library().names() if lookdev.load(n).model == "pixar"]
    assert pixar and all(found[n].model == "pixar" for n in pixar)
