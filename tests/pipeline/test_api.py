"""The Python API (``import lookdev``): its contract, and the guide's example running."""

from __future__ import annotations

import json
import re
import subprocess
import sys
from collections.abc import Mapping
from pathlib import Path

import numpy as np
import pytest

import lookdev
from lookdev.materials.bsdf import Model
from lookdev.materials.pixar import LAYERED_MODEL

GUIDE = Path(__file__).resolve().parents[2] / "docs" / "guide" / "python.md"
RNG = np.random.default_rng(7)


def _unit(v):
    v = np.asarray(v, dtype=np.float64)
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def _hemisphere(shape):
    return _unit(RNG.normal(size=(*shape, 3)) * [1, 1, 0] + [0, 0, 1.5])


@pytest.fixture(autouse=True)
def _cache(tmp_path_factory, monkeypatch):
    monkeypatch.setenv("LOOKDEV_CACHE", str(tmp_path_factory.getbasetemp() / "cache"))


@pytest.fixture(scope="module")
def rust():
    return lookdev.blend("rusty_iron", 16)


@pytest.fixture(scope="module")
def pixar_rust():
    return lookdev.blend("pixar_rusty_metal", 16)


# -- the package ---------------------------------------------------------------------------
def test_import_lookdev_loads_nothing_heavy():
    code = (
        "import sys, lookdev; "
        "print(sorted(m for m in ('mitsuba', 'pxr', 'matplotlib', 'numpy', "
        "'lookdev.pipeline.api') if m in sys.modules))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"


def test_every_exported_name_resolves_from_the_api():
    from lookdev.pipeline import api

    assert set(lookdev.__all__) <= set(api.__all__)
    for name in lookdev.__all__:
        assert getattr(lookdev, name) is getattr(api, name)
    with pytest.raises(AttributeError):
        lookdev.no_such_thing  # noqa: B018


def test_models_is_a_mapping_of_models():
    assert isinstance(lookdev.models, Mapping)
    assert {"disney", "sheen", "pixar", "pixar_layered"} <= set(lookdev.models)
    assert all(isinstance(lookdev.models[n], Model) for n in lookdev.models)
    assert lookdev.models["pixar_layered"] is LAYERED_MODEL
    with pytest.raises(KeyError):
        lookdev.models["no_such_model"]


# -- load ----------------------------------------------------------------------------------
PRESET = 'name = "api_red"\nmodel = "disney"\n\n[params]\nbase_color = [0.8, 0.1, 0.1]\n'


def test_load_searches_library_folders_then_the_environment_then_builtins(tmp_path, monkeypatch):
    monkeypatch.delenv("LOOKDEV_LIBRARY_PATH", raising=False)
    (tmp_path / "api_red.toml").write_text(PRESET)
    assert lookdev.load("api_red", library=tmp_path).params.base_color == (0.8, 0.1, 0.1)
    assert lookdev.load("api_red", library=[str(tmp_path)]).name == "api_red"
    assert lookdev.load(tmp_path / "api_red.toml").name == "api_red"
    assert lookdev.load(str(tmp_path / "api_red.toml")).name == "api_red"
    with pytest.raises(lookdev.LookdevError):
        lookdev.load("api_red")
    monkeypatch.setenv("LOOKDEV_LIBRARY_PATH", str(tmp_path))
    assert lookdev.load("api_red").name == "api_red"
    assert lookdev.load("gold").params.metallic == 1.0  # the built-ins come last


def test_api_errors_are_the_lines_the_cli_prints(cli, tmp_path):
    with pytest.raises(lookdev.LookdevError) as caught:
        lookdev.load("no_such_preset_anywhere")
    r = cli("blend", "no_such_preset_anywhere", "-o", str(tmp_path))
    assert r.code == 2
    assert r.err.strip() == f"lookdev: error: {caught.value}"

    with pytest.raises(lookdev.LookdevError) as caught:
        lookdev.export_usd(["gold"], tmp_path / "gold.txt")
    r = cli("export", "usd", "gold", "-o", str(tmp_path / "gold.txt"))
    assert r.err.strip() == f"lookdev: error: {caught.value}"


# -- evaluate, sample, pdf -----------------------------------------------------------------
def test_shapes_broadcast_over_leading_axes():
    wi, wo = _hemisphere((4, 5)), _hemisphere((5,))
    f = lookdev.evaluate("gold", wi, wo)
    assert f.shape == (4, 5, 3) and f.dtype == np.float64
    assert lookdev.pdf("gold", wi, wo).shape == (4, 5)
    s_wi, weight, p = lookdev.sample("gold", wo, RNG.random((4, 5, 3)))
    assert s_wi.shape == weight.shape == (4, 5, 3) and p.shape == (4, 5)
    single = lookdev.evaluate("gold", wi[0, 0], wo[0])
    assert single.shape == (3,) and np.allclose(single, f[0, 0])
    f32 = lookdev.evaluate("gold", wi, wo, dtype=np.float32)
    assert f32.dtype == np.float32 and np.allclose(f32, f, rtol=1e-4)


def test_a_material_a_name_and_its_parameters_agree():
    wi, wo = _hemisphere((8,)), _hemisphere((8,))
    gold = lookdev.load("gold")
    f = lookdev.evaluate("gold", wi, wo)
    assert np.array_equal(lookdev.evaluate(gold, wi, wo), f)
    assert np.array_equal(lookdev.evaluate(gold.params, wi, wo), f)


def _texel_uv(blended, rows, cols):
    width, height = blended.resolution
    return np.stack([(cols + 0.5) / width, (rows + 0.5) / height], axis=-1)


@pytest.mark.parametrize("which", ["rust", "pixar_rust"])
def test_uv_reads_the_parameters_of_its_texel(which, request):
    blended = request.getfixturevalue(which)
    assert blended.maps
    width, height = blended.resolution
    rows, cols = RNG.integers(0, height, 6), RNG.integers(0, width, 6)
    uv = _texel_uv(blended, rows, cols)
    wi, wo, u = _hemisphere((6,)), _hemisphere((6,)), RNG.random((6, 3))
    f = lookdev.evaluate(blended, wi, wo, uv=uv)
    p = lookdev.pdf(blended, wi, wo, uv=uv)
    drawn = lookdev.sample(blended, wo, u, uv=uv)
    for k, (r, c) in enumerate(zip(rows, cols, strict=True)):
        params = blended.params_at(r, c)
        if blended.representation == "lobe_weights":
            fields = LAYERED_MODEL.params_type.model_fields
            params = LAYERED_MODEL.params_type.parse(
                {n: v for n, v in params.items() if n in fields}
            )
        np.testing.assert_allclose(f[k], lookdev.evaluate(params, wi[k], wo[k]), rtol=1e-6)
        np.testing.assert_allclose(p[k], lookdev.pdf(params, wi[k], wo[k]), rtol=1e-6)
        for got, want in zip(drawn, lookdev.sample(params, wo[k], u[k]), strict=True):
            np.testing.assert_allclose(got[k], want, rtol=1e-6, atol=1e-12)


def test_uv_repeats_and_broadcasts(rust):
    wi, wo = _hemisphere(()), _hemisphere(())
    corner = lookdev.evaluate(rust, wi, wo, uv=[0.0, 0.0])
    assert corner.shape == (3,)
    assert np.array_equal(lookdev.evaluate(rust, wi, wo, uv=[1.0, 2.0]), corner)
    grid = lookdev.evaluate(rust, wi, wo, uv=RNG.random((3, 4, 2)))
    assert grid.shape == (3, 4, 3)


def test_a_uniform_material_ignores_uv_but_takes_its_shape():
    wi, wo = _hemisphere(()), _hemisphere(())
    f = lookdev.evaluate("gold", wi, wo, uv=RNG.random((5, 2)))
    assert f.shape == (5, 3) and np.allclose(f, lookdev.evaluate("gold", wi, wo))


def test_bad_input_raises_lookdev_errors(rust):
    wi = _hemisphere(())
    with pytest.raises(lookdev.LookdevError, match="uv="):
        lookdev.evaluate(rust, wi, wi)
    with pytest.raises(lookdev.LookdevError, match=r"\(\.\.\., 3\)"):
        lookdev.evaluate("gold", wi[:2], wi)
    with pytest.raises(lookdev.LookdevError, match=r"\(\.\.\., 2\)"):
        lookdev.evaluate(rust, wi, wi, uv=[0.5])
    with pytest.raises(lookdev.LookdevError, match="NaN"):
        lookdev.evaluate(rust, wi, wi, uv=[np.nan, 0.5])
    with pytest.raises(lookdev.LookdevError, match="broadcast"):
        lookdev.evaluate("gold", _hemisphere((2,)), _hemisphere((3,)))
    with pytest.raises(lookdev.LookdevError):
        lookdev.evaluate(object(), wi, wi)


# -- USD -------------------------------------------------------------------------------------
def test_export_usd_lists_files_and_what_each_context_lost(tmp_path):
    from pxr import Usd, UsdShade

    result = lookdev.export_usd(["gold", "velvet", "gold"], tmp_path / "looks.usda")
    assert result.output == tmp_path / "looks.usda" and result.files[0] == result.output
    assert all(p.is_file() for p in result.files)
    assert result.materials == ["gold", "velvet"]
    assert result.contexts == ("universal", "mtlx", "ri")
    assert set(result.losses) == {"gold", "velvet"}
    assert all(set(v) == set(result.contexts) for v in result.losses.values())
    assert result.losses["gold"]["universal"] == ""
    assert "sheen" in result.losses["velvet"]["universal"]
    # the same notes the stage carries, in the surface shaders' customData
    stage = Usd.Stage.Open(str(result.output))
    material = UsdShade.Material(stage.GetPrimAtPath("/Materials/velvet"))
    surface = material.ComputeSurfaceSource()[0]
    assert (
        surface.GetPrim().GetCustomData()["lookdev"]["loss"]
        == (result.losses["velvet"]["universal"])
    )
    assert json.loads(json.dumps(result.to_json()))["materials"] == ["gold", "velvet"]


def test_export_usd_takes_the_cli_options(tmp_path):
    result = lookdev.export_usd(
        "gold", tmp_path / "gold.usda", contexts=["mtlx"], mtlx=tmp_path / "gold.mtlx"
    )
    assert result.contexts == ("mtlx",) and set(result.losses["gold"]) == {"mtlx"}
    assert (tmp_path / "gold.mtlx") in result.files
    with pytest.raises(lookdev.LookdevError, match="render context"):
        lookdev.export_usd(["gold"], tmp_path / "x.usda", contexts=["arnold"])
    with pytest.raises(lookdev.LookdevError, match="at least one preset"):
        lookdev.export_usd([], tmp_path / "x.usda")


# -- Mitsuba, check --------------------------------------------------------------------------
def test_export_mitsuba_writes_a_scene(tmp_path):
    result = lookdev.export_mitsuba("rusty_iron", tmp_path / "scene.xml", map_resolution=8)
    assert result.scene.is_file() and result.preset == "rusty_iron"
    assert result.plugins and result.max_depth >= 1
    assert result.textures and all(Path(t).is_file() for t in result.textures)
    with pytest.raises(lookdev.LookdevError, match="no such environment image"):
        lookdev.export_mitsuba("gold", tmp_path / "g.xml", ibl=tmp_path / "none.exr")


@pytest.mark.slow
def test_check_returns_the_findings():
    seen = []
    result = lookdev.check(["pixar"], progress=lambda *a: seen.append(a))
    assert list(result.reports) == ["pixar"] and not result.failed
    assert seen and seen[-1][0] == seen[-1][1]  # done == total at the end
    assert set(result.to_json()) == {"models", "seconds"}
    with pytest.raises(lookdev.LookdevError):
        lookdev.check(["no_such_model"])


# -- proofs and the guide's example ----------------------------------------------------------
def _guide_example() -> str:
    """The first example of the Python API guide page."""
    blocks = re.findall(r"```python\n(.*?)```", GUIDE.read_text(encoding="utf-8"), flags=re.S)
    return blocks[0]


@pytest.mark.slow
@pytest.mark.render
def test_the_guide_example_runs(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    exec(compile(_guide_example(), "python.md", "exec"), {"__name__": "readme"})
    assert (tmp_path / "looks.usda").is_file()
    manifest = json.loads((tmp_path / "proofs" / "manifest.json").read_text())
    assert [(p["material"], p["ibl"], p["frames"]) for p in manifest["proofs"]] == [
        ("gold", "studio", 2)
    ]
    assert "frames in" in capsys.readouterr().out


@pytest.mark.slow
@pytest.mark.render
def test_proof_returns_the_manifest_and_resumes(tmp_path):
    settings = dict(frames=1, light_frames=1, spp=4, resolution=(32, 16), ibl_width=64)
    events = []
    first = lookdev.proof("gold", "studio", tmp_path, progress=events.append, **settings)
    assert first == {**json.loads((tmp_path / "manifest.json").read_text())}
    (entry,) = first["proofs"]
    assert (entry["material"], entry["ibl"], entry["rendered"], entry["skipped"]) == (
        "gold",
        "studio",
        2,
        0,
    )
    assert (tmp_path / entry["contact_sheet"]).is_file()
    assert events[-1].frames_done == events[-1].frames_total == 2
    assert [e.finished["material"] for e in events if e.finished] == ["gold"]
    again = lookdev.proof(["gold"], ["studio"], tmp_path, **settings)
    assert (again["proofs"][0]["rendered"], again["proofs"][0]["skipped"]) == (0, 2)


def test_proof_rejects_bad_settings_before_rendering(tmp_path):
    # resolutions now have a documented maximum too, so the message names the range (issue 13)
    with pytest.raises(
        lookdev.LookdevError, match=r"^resolution: 4 is out of range; allowed \[8, 8192\]"
    ):
        lookdev.proof("gold", "studio", tmp_path, resolution=(4, 4), ibl_width=64)
    with pytest.raises(lookdev.LookdevError, match="^frames: "):
        lookdev.proof("gold", "studio", tmp_path, frames=0, ibl_width=64)
    assert not (tmp_path / "manifest.json").exists()
