"""Proof jobs sampled per pixel (the default with a target): the manifest's fields, the
checked denoiser's files, resumption, and the real HDR as a standing IBL."""

from __future__ import annotations

import json

import numpy as np
import pytest

from lookdev.pipeline.proof import batch, contact, ibl, settings

pytestmark = pytest.mark.render


@pytest.fixture(autouse=True)
def _cache(tmp_path_factory, monkeypatch):
    monkeypatch.setenv("LOOKDEV_CACHE", str(tmp_path_factory.getbasetemp() / "cache"))


@pytest.fixture(scope="module")
def plastic():
    from lookdev.library import load_material
    from lookdev.pipeline.blend import blend

    return blend(load_material("plastic_glossy"), 16)


def test_per_pixel_sampling_to_a_display_target_is_opt_in():
    s = settings.Settings(adaptive=True)
    assert s.per_pixel() and s.noise == settings.DEFAULT_NOISE
    assert s.max_spp == settings.DEFAULT_PIXEL_MAX_SPP
    default = settings.Settings()
    assert not default.per_pixel()
    assert (default.noise, default.max_spp) == (settings.UNIFORM_NOISE, settings.DEFAULT_MAX_SPP)
    assert not settings.Settings(adaptive=True, pixel_filter="gaussian").per_pixel()


def test_a_per_pixel_proof_records_its_estimates_and_resumes(plastic, tmp_path):
    s = batch.Settings(
        element_frames=1,
        light_frames=1,
        resolution=(24, 12),
        noise=0.03,
        max_spp=64,
        rig="none",
        adaptive=True,
    )
    job = batch.make_jobs([plastic], [ibl.load(ibl.REAL_HDR, 64)], tmp_path, s)[0]
    doc = batch.run_job(job)
    assert job.ibl == "venice_sunset_1k" and doc["rendered"] == 2
    for f in doc["frames"]:
        assert f["sampling"] == "per_pixel" and f["noise_target"] == 0.03
        assert 0 <= f["converged"] <= 1 and f["stop"] in ("target", "max_spp")
        assert f["stop"] != "target" or f["converged"] >= 0.999
        assert 16 <= f["spp_mean"] <= f["spp_max"] <= 64
        assert f["noise"] <= f["noise_raw"] + 1e-9  # shown: the better of raw and denoised
        assert set(f["images"]) == {"raw", "png", "denoised", "denoised_png", "difference_png"}
        assert f["denoise"]["residual"] == pytest.approx(f["noise"], abs=1e-5)
        diff = contact.read_rgb(job.folder / f["images"]["difference_png"])
        assert diff.shape[:2] == (12, 24) and np.isfinite(diff).all()
    again = batch.run_job(job)
    assert (again["rendered"], again["skipped"]) == (0, 2)
    manifest = json.loads((job.folder / "manifest.json").read_text())
    assert manifest["settings"]["adaptive"] is True


def test_the_real_hdr_is_a_lat_long_sky_with_a_sun():
    env = ibl.load(ibl.REAL_HDR, 256)
    assert env.pixels.shape == (128, 256, 3) and float(env.pixels.max()) > 100.0


def test_a_square_ibl_is_refused_in_one_line(tmp_path):
    path = contact.write_exr(np.ones((16, 16, 3), np.float32), tmp_path / "square.exr")
    with pytest.raises(ibl.IblError, match="not a lat-long map") as err:
        ibl.load(path, 64)
    assert "\n" not in str(err.value)
