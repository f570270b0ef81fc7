"""Denoising proof frames (pipeline/proof/denoise.py) and ``lookdev proof --denoise``."""

from __future__ import annotations

import json
import sys
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest

from lookdev.pipeline.proof import batch, denoise, ibl

pytestmark = pytest.mark.render


@pytest.fixture(autouse=True)
def _cache(tmp_path_factory, monkeypatch):
    monkeypatch.setenv("LOOKDEV_CACHE", str(tmp_path_factory.getbasetemp() / "cache"))


@pytest.fixture(scope="module")
def mi():
    from lookdev.pipeline.variant import use_mitsuba

    use_mitsuba()
    import mitsuba

    return mitsuba


def _sun_sky(width=64):
    """A dim sky with a small, bright sun: a diffuse plane under it is noisy at low spp."""
    h = width // 2
    env = np.full((h, width, 3), 0.2, np.float32)
    env[h // 4 - 1 : h // 4 + 1, width // 3 : width // 3 + 2] = 400.0
    return env


@pytest.fixture(scope="module")
def flat(mi):
    """A 24×24 box-filtered view straight down at a large two-coloured diffuse plane
    (our Disney plugin) under the sun sky, and its 256-spp reference."""
    from lookdev.materials.params import DisneyParams
    from lookdev.pipeline.export.mitsuba.scene import bsdf_dict

    def plane(colour, x):
        params = DisneyParams(base_color=colour, roughness=0.5)
        return {
            "type": "rectangle",
            "to_world": mi.ScalarTransform4f().translate([x, 0, 0]).scale([10, 20, 1]),
            "bsdf": bsdf_dict(params, allow_principled=False),
        }

    scene = mi.load_dict(
        {
            "type": "scene",
            "integrator": {"type": "path", "max_depth": 3},
            "sensor": {
                "type": "perspective",
                "fov": 4.0,  # from far away: every pixel sees the plane within 2° of normal
                "to_world": mi.ScalarTransform4f().look_at([0, 0, 50], [0, 0, 0], [0, 1, 0]),
                "film": {
                    "type": "hdrfilm",
                    "width": 24,
                    "height": 24,
                    "rfilter": {"type": "box"},
                    "pixel_format": "rgb",
                },
                "sampler": {"type": "independent"},
            },
            "left": plane((0.8, 0.3, 0.1), -10),
            "right": plane((0.1, 0.4, 0.8), 10),
            "sky": {"type": "envmap", "bitmap": mi.Bitmap(_sun_sky())},
        }
    )
    reference = np.array(mi.render(scene, spp=256, seed=99), np.float64)[..., :3]
    return scene, reference


def _rel_mse(x, ref):
    return float(np.mean((x - ref) ** 2 / (ref**2 + 1e-2)))


def test_guides_have_the_frames_shape_and_are_finite(mi, flat):
    scene, _ = flat
    guides = denoise.GuideRenderer(scene, 0, 4).render(seed=1)
    for image, lo in ((guides.albedo, 0.0), (guides.normal, -1.0)):
        assert image.shape == (24, 24, 3) and image.dtype == np.float32
        assert np.all(np.isfinite(image)) and image.min() >= lo and image.max() <= 1.0
    # Facing the camera, each half's albedo is its base colour (Burley's diffuse at
    # normal view is Lambert); the normal is the plane's +z everywhere.
    np.testing.assert_allclose(guides.albedo[12, 3], (0.8, 0.3, 0.1), rtol=1e-4)
    np.testing.assert_allclose(guides.albedo[12, 20], (0.1, 0.4, 0.8), rtol=1e-4)
    np.testing.assert_allclose(guides.normal, np.broadcast_to([0, 0, 1], (24, 24, 3)), atol=1e-5)
    assert guides.seconds > 0 and guides.spp == 4


def test_guides_take_the_frames_samples_up_to_the_cap(mi, flat):
    scene, _ = flat
    renderer = denoise.GuideRenderer(scene, 0, 4, freeze=False)
    assert [renderer.render(seed=1, spp=n).spp for n in (1, 2, 8, None)] == [1, 2, 4, 4]
    # One guide sample per pixel: the same first hits, only less anti-aliased.
    one = renderer.render(seed=1, spp=1)
    np.testing.assert_allclose(one.albedo[12, 3], (0.8, 0.3, 0.1), rtol=1e-4)


def test_denoised_frame_is_closer_to_the_reference_than_raw(mi, flat):
    scene, reference = flat
    renderer = denoise.GuideRenderer(scene, 0, 4)
    for seed in (1, 2):  # deterministic seeds
        raw = np.array(mi.render(scene, spp=4, seed=seed), np.float32)[..., :3]
        d = renderer.denoise(raw, seed=seed)
        assert d.image.shape == raw.shape and np.all(np.isfinite(d.image))
        raw_err, den_err = _rel_mse(raw, reference), _rel_mse(d.image, reference)
        assert raw_err > 0.02  # the frame is noisy: the comparison means something
        assert den_err < 0.5 * raw_err
        assert d.aov_seconds > 0 and d.denoise_seconds > 0
        assert d.timings() | {"aov_s": 0, "denoise_s": 0} == {
            "aov_s": 0,
            "denoise_s": 0,
            "guide_spp": 4,
        }


def test_denoise_without_guides_and_with_bad_pixels_stays_finite():
    rng = np.random.default_rng(3)
    image = rng.exponential(0.5, size=(16, 16, 3)).astype(np.float32)
    image[0, 0] = np.nan
    image[1, 1] = -3.0
    out = denoise.denoise(image)
    assert out.shape == image.shape and np.all(np.isfinite(out))


def test_light_below_zero_is_denoised_not_clamped():
    """A chart patch outside the working gamut (the ColorChecker's cyan has negative red
    in Rec.709) keeps its value: OIDN's HDR input is [0, inf), so it is denoised apart."""
    rng = np.random.default_rng(5)
    truth = np.full((64, 96, 3), 0.3, np.float32)
    truth[20:40, 30:60] = (-0.066, 0.2, 0.35)  # the cyan patch, red below zero
    noisy = truth * rng.exponential(1.0, truth.shape).astype(np.float32)
    out = denoise.denoise(noisy)
    patch = out[24:36, 34:56]
    assert abs(float(patch[..., 0].mean()) + 0.066) < 0.01  # was clamped to 0
    assert abs(float(patch[..., 2].mean()) - 0.35) < 0.03
    assert abs(float(out[:10, :10, 0].mean()) - 0.3) < 0.03  # the positive light as before


@pytest.mark.slow
def test_a_denoised_job_writes_both_exrs_and_records_timings(mi, tmp_path):
    from lookdev.library import load_material
    from lookdev.pipeline.blend import blend

    settings = batch.Settings(element_frames=1, light_frames=1, spp=4, resolution=(32, 16))
    settings = batch.Settings(**{**settings.__dict__, "denoise": True})
    job = batch.make_jobs(
        [blend(load_material("plaster"), 16)], [ibl.load("studio", 64)], tmp_path, settings
    )[0]
    doc = batch.run_job(job)
    folder = tmp_path / "plaster" / "studio"
    manifest = json.loads((folder / "manifest.json").read_text())
    assert manifest["settings"]["denoise"] is True
    for f in manifest["frames"]:
        raw = folder / f["images"]["raw"]
        den = folder / f["images"]["denoised"]
        assert raw.is_file() and den.is_file() and raw != den
        assert (folder / f["images"]["denoised_png"]).is_file()
        assert f["files"]["denoised"]["size"] == den.stat().st_size
        assert f["denoise"]["aov_s"] > 0 and f["denoise"]["denoise_s"] > 0
        assert f["denoise"]["guide_spp"] == 4  # the frame's own count (under GUIDE_SPP)
    assert (folder / "contact_denoised.png").is_file()
    again = batch.run_job(job)  # the denoised files are vouched for like the raw ones
    assert again["rendered"] == 0 and again["skipped"] == doc["rendered"]
    (folder / "frame_000_denoised.exr").unlink()
    assert batch.run_job(job)["rendered"] == 1


@pytest.mark.slow
def test_api_proof_passes_denoise_through(mi, tmp_path):
    from lookdev.pipeline import api

    with ThreadPoolExecutor(1) as pool:
        doc = api.proof(
            "plaster",
            "studio",
            tmp_path,
            frames=1,
            light_frames=0,
            spp=2,
            resolution=(16, 8),
            ibl_width=32,
            executor=pool,
            denoise=True,
        )
    assert (tmp_path / "plaster" / "studio" / "frame_000_denoised.exr").is_file()
    (entry,) = doc["proofs"]
    assert (tmp_path / entry["contact_sheet_denoised"]).is_file()


def test_missing_pyoidn_is_one_line_exit_2(cli, tmp_path, monkeypatch):
    monkeypatch.setitem(sys.modules, "pyoidn", None)  # import pyoidn → ImportError
    r = cli("proof", "plaster", "--ibl", "studio", "-n", "1", "-m", "0", "-s", "2",
            "-r", "16", "8", "--denoise", "-o", str(tmp_path / "out"))  # fmt: skip
    assert r.code == 2 and "pip install pyoidn" in r.err
    assert len(r.err.strip().splitlines()) == 1 and "Traceback" not in r.err
    assert not list(tmp_path.rglob("frame_*"))
    with pytest.raises(denoise.DenoiseError):
        denoise.denoise(np.zeros((4, 4, 3), np.float32))
