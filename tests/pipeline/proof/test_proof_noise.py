"""Proofs rendered to a noise target, in Mitsuba: the manifest's fields, resumption,
``--clamp``, the command's bad values, and the estimate against a converged reference."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from lookdev.materials.colour import luminance
from lookdev.pipeline.proof import batch, ibl, passes, turntable

pytestmark = pytest.mark.render

NOISY = batch.Settings(
    element_frames=1, light_frames=1, resolution=(16, 8), noise=1e-4, max_spp=4, denoise=False
)  # unreachable: every frame stops at max_spp


@pytest.fixture(autouse=True)
def _cache(tmp_path_factory, monkeypatch):
    monkeypatch.setenv("LOOKDEV_CACHE", str(tmp_path_factory.getbasetemp() / "cache"))


@pytest.fixture(scope="module")
def gold():
    from lookdev.library import load_material
    from lookdev.pipeline.blend import blend

    return blend(load_material("gold"), 16)


def _job(material, out, settings, name="sky"):
    return batch.make_jobs([material], [ibl.load(name, 64)], out, settings)[0]


FIELDS = {
    "spp": int,
    "passes": int,
    "noise": float,
    "noise_rmse": float,
    "noise_target": float,
    "time_s": float,
    "stop": str,
    "firefly_share": float,
}


def test_manifest_records_sampling_per_frame_and_resumes(gold, tmp_path):
    job = _job(gold, tmp_path, NOISY)
    doc = batch.run_job(job)
    manifest = json.loads((job.folder / "manifest.json").read_text())
    assert manifest["filter"] == "box" and manifest["clamp"] is None
    assert manifest["settings"]["noise"] == 1e-4 and manifest["settings"]["max_spp"] == 4
    for f in manifest["frames"]:
        for name, kind in FIELDS.items():
            assert isinstance(f[name], kind), name
        assert f["clamp"] is None and f["noise_target"] == 1e-4
        assert (f["stop"], f["spp"], f["passes"]) == ("max_spp", 4, 1)
        assert 0 < f["firefly_share"] <= 1
        assert f["images"] == {"raw": f["files"]["raw"]["file"], "png": f["files"]["png"]["file"]}
        assert f["images"]["raw"].endswith(".exr") and f["images"]["png"].endswith(".png")
        assert all((job.folder / name).is_file() for name in f["images"].values())
    again = batch.run_job(job)
    assert (doc["rendered"], again["rendered"], again["skipped"]) == (2, 0, 2)
    entry = batch.summary(tmp_path, [job], [again], 1.0)["proofs"][0]
    assert entry["stops"] == {"max_spp": 2} and entry["filter"] == "box"
    assert entry["mean_spp"] == 4.0 and entry["max_firefly_share"] > 0


def test_a_fixed_spp_records_no_target(gold, tmp_path):
    fixed = batch.Settings(element_frames=1, light_frames=0, resolution=(16, 8), spp=6)
    batch.run_job(job := _job(gold, tmp_path, fixed))
    (f,) = json.loads((job.folder / "manifest.json").read_text())["frames"]
    assert (f["stop"], f["spp"], f["noise_target"]) == ("spp", 6, None)


def test_clamp_limits_every_sample_and_is_recorded(gold, tmp_path):
    clamped = batch.Settings(
        element_frames=1, light_frames=0, resolution=(16, 8), spp=8, clamp=0.25
    )
    batch.run_job(job := _job(gold, tmp_path, clamped))
    manifest = json.loads((job.folder / "manifest.json").read_text())
    (f,) = manifest["frames"]
    assert manifest["clamp"] == 0.25 and f["clamp"] == 0.25
    from lookdev.pipeline.proof.contact import read_rgb

    raw = read_rgb(job.folder / f["images"]["raw"])
    assert raw.max() <= 0.25 * (1 + 1e-5)  # a pixel is a mean of clamped samples


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--noise", "0"], "--noise: 0 is out of range"),
        (["--noise", "-0.5"], "--noise: -0.5 is out of range"),
        (["--noise", "nan"], "--noise: nan is not a finite number"),
        (["--max-spp", "0"], "--max-spp: 0 is out of range"),
        (["--time-budget", "-1"], "--time-budget: -1 is out of range"),
        (["--clamp", "0"], "--clamp: 0 is out of range"),
        (["--spp", "8", "--noise", "0.1"], "--spp is a fixed count"),
        (["--spp", "1"], "--spp: 1 is out of range"),
        (["--pixel-filter", "tent"], "--pixel-filter"),
    ],
)
def test_bad_sampling_options_are_one_line_exit_2(cli, tmp_path, args, message):
    r = cli("proof", "gold", "--ibl", "studio", "-o", str(tmp_path / "out"), *args)
    assert r.code == 2 and message in r.err, r.err
    assert len(r.err.strip().splitlines()) == 1 and "Traceback" not in r.err
    assert not list(tmp_path.rglob("frame_*"))


@pytest.mark.slow
@pytest.mark.parametrize(("preset", "name"), [("plastic_glossy", "sky"), ("gold", "sunset")])
def test_the_estimate_is_within_2x_of_the_error_against_a_converged_reference(preset, name):
    """A frame rendered to a target by passes; its error measured against a reference of
    8192 spp (the reference's own remaining noise, estimated from its halves, taken out
    in quadrature) is within a factor of 2 of the frame's estimate."""
    from lookdev.library import load_material
    from lookdev.pipeline.blend import blend
    from lookdev.pipeline.variant import use_mitsuba

    use_mitsuba()
    bsdf, depth = turntable.material_bsdf(blend(load_material(preset), 64))
    table = turntable.Turntable(bsdf, ibl.load(name, 128).pixels, (32, 16), depth)
    frame = turntable.Frame(0, "element", 0.0)
    r = passes.render_frame(table, frame, noise=0.15, max_spp=256)
    table.set_frame(frame)
    halves = [table.render_halves(1024, seed=50_000 + k) for k in range(4)]
    ref_a = np.mean([a for a, _ in halves], axis=0)
    ref_b = np.mean([b for _, b in halves], axis=0)
    ref_noise = passes.estimate(ref_a, ref_b).rmse
    reference = luminance(0.5 * (ref_a + ref_b).astype(np.float64))
    measured2 = float(np.mean((luminance(r.image.astype(np.float64)) - reference) ** 2))
    measured = math.sqrt(max(measured2 - ref_noise**2, 0.0))
    assert ref_noise < 0.5 * measured, "reference not converged enough to judge"
    assert 0.5 < r.noise_rmse / measured < 2.0, (r.noise_rmse, measured, r.spp, r.stop)
