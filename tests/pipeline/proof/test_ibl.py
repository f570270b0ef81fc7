"""Built-in and user IBLs: generation, caching, Mitsuba's lat-long convention, bad files."""

from __future__ import annotations

import math
import shutil

import numpy as np
import pytest

from lookdev.pipeline.proof import ibl


@pytest.fixture(autouse=True)
def _cache(tmp_path, monkeypatch):
    monkeypatch.setenv("LOOKDEV_CACHE", str(tmp_path / "cache"))


def _write(pixels, path):
    import OpenImageIO as oiio

    assert oiio.ImageBuf(np.ascontiguousarray(pixels, dtype=np.float32)).write(str(path))
    return path


def test_every_builtin_generates_a_finite_lat_long_image():
    assert set(ibl.builtin_names()) >= {"studio", "sky", "overcast", "sunset"}
    for name in ibl.builtin_names():
        env = ibl.load(name, 64)
        assert env.pixels.shape == (32, 64, 3) and env.pixels.dtype == np.float32
        assert np.isfinite(env.pixels).all() and env.pixels.min() >= 0.0
        assert env.pixels.max() > 1.0, f"{name} has no light brighter than its backdrop"


def test_generated_once_then_read_from_the_cache():
    first = ibl.resolve("studio", 64)
    stamp = first.stat().st_mtime_ns
    assert ibl.resolve("studio", 64) == first and first.stat().st_mtime_ns == stamp


def test_editing_a_definition_regenerates_it(tmp_path, monkeypatch):
    folder = tmp_path / "defs"
    shutil.copytree(ibl.definitions_folder(), folder)
    monkeypatch.setattr(ibl, "definitions_folder", lambda: folder)
    before = ibl.resolve("overcast", 64)
    text = (folder / "overcast.toml").read_text().replace("exposure = 0.0", "exposure = 1.0")
    (folder / "overcast.toml").write_text(text)
    after = ibl.resolve("overcast", 64)
    assert after != before
    assert np.allclose(ibl.read_image(after), 2.0 * ibl.read_image(before), rtol=1e-6)


def test_directions_follow_mitsubas_envmap():
    """A single bright pixel is seen by Mitsuba exactly along ``directions``' vector."""
    from lookdev.pipeline.variant import use_mitsuba

    use_mitsuba()
    import drjit as dr
    import mitsuba as mi

    width = 32
    d, _ = ibl.directions(width)
    pixels = np.zeros((16, 32, 3), np.float32)
    pixels[4, 9] = 100.0
    emitter = mi.load_dict({"type": "envmap", "bitmap": mi.Bitmap(pixels)})
    si = dr.zeros(mi.SurfaceInteraction3f, 3)
    looks = np.stack([d[4, 9], d[4, 20], d[12, 9]])
    si.wi = mi.Vector3f(-looks.T)  # wi points from the emitter back towards the scene
    red = np.array(emitter.eval(si))[0]  # pixel centres: bilinear weights are 1 and 0
    assert red == pytest.approx([100.0, 0.0, 0.0], abs=1e-3)


def test_the_sun_lands_where_it_is_defined_with_its_irradiance():
    sun = ibl.Sun(azimuth=30.0, elevation=40.0, irradiance=(3.0, 2.0, 1.0))
    defn = ibl.IblDefinition(name="sun_only", sun=sun)
    width = 256
    pixels = ibl.generate(defn, width).astype(np.float64)
    d, omega = ibl.directions(width)
    axis = ibl.direction(30.0, 40.0)
    brightest = d.reshape(-1, 3)[np.argmax(pixels[..., 0])]
    assert math.degrees(math.acos(min(1.0, brightest @ axis))) < 360.0 / width * 2
    irradiance = (pixels * (np.clip(d @ axis, 0, None) * omega)[..., None]).sum(axis=(0, 1))
    assert irradiance == pytest.approx([3.0, 2.0, 1.0], rel=1e-5)


def test_cie_overcast_horizon_is_a_third_of_the_zenith():
    """CIE type 1 reproduces Moon & Spencer's overcast sky: L(horizon) ≈ L(zenith)/3."""
    sky = ibl.definition("overcast").sky
    d = np.array([[0.0, 1.0, 0.0], [1.0, 1e-3, 0.0]])
    zenith, horizon = ibl.cie_sky(sky, d, np.array([0.0, 1.0, 0.0]))[:, 1]
    assert horizon / zenith == pytest.approx(1.0 / 3.0, abs=0.01)


def test_the_ground_reflects_the_sky_as_a_diffuse_surface():
    defn = ibl.IblDefinition(
        name="furnace_over_grey",
        background=ibl.Gradient(zenith=(1, 1, 1), horizon=(1, 1, 1), ground=(0, 0, 0)),
        ground=ibl.Ground(albedo=(0.5, 0.5, 0.5)),
    )
    pixels = ibl.generate(defn, 128)
    # Uniform sky of radiance 1 gives E = π, so the ground shows ρ E / π = ρ.
    assert pixels[-1, 0] == pytest.approx([0.5, 0.5, 0.5], rel=2e-3)


def test_user_files_are_resampled_with_exposure_folded_in(tmp_path):
    rng = np.random.default_rng(1)
    pixels = rng.uniform(0.0, 2.0, (64, 128, 3)).astype(np.float32)
    exr = _write(pixels, tmp_path / "room.exr")
    env = ibl.load(exr, 32, exposure=1.0)
    assert env.name == "room" and env.pixels.shape == (16, 32, 3)
    assert env.pixels.mean() == pytest.approx(2.0 * pixels.mean(), rel=0.02)


def test_hdr_files_work_and_alpha_is_dropped(tmp_path):
    hdr = _write(np.full((8, 16, 3), 0.5, np.float32), tmp_path / "flat.hdr")
    assert ibl.load(hdr, 16).pixels == pytest.approx(0.5, rel=0.02)
    rgba = _write(np.ones((8, 16, 4), np.float32), tmp_path / "rgba.exr")
    assert ibl.load(rgba, 16).pixels.shape == (8, 16, 3)


def test_nan_and_negative_pixels_become_black(tmp_path):
    pixels = np.ones((8, 16, 3), np.float32)
    pixels[0, 0] = np.nan
    pixels[1, 1] = -5.0
    env = ibl.load(_write(pixels, tmp_path / "bad.exr"), 16)
    assert np.isfinite(env.pixels).all() and env.pixels.min() == 0.0


@pytest.mark.parametrize(
    ("given", "message"),
    [
        ("nowhere.exr", "no such IBL file"),
        ("studoi", "built-ins: overcast, sky, studio, sunset"),
    ],
)
def test_bad_names_are_one_line_errors(given, message):
    with pytest.raises(ibl.IblError, match=message) as info:
        ibl.load(given)
    assert "\n" not in str(info.value)


def test_undecodable_files_are_one_line_errors(tmp_path):
    junk = tmp_path / "junk.exr"
    junk.write_bytes(b"not an image at all")
    with pytest.raises(ibl.IblError, match="cannot decode") as info:
        ibl.load(junk)
    assert str(junk) in str(info.value) and "\n" not in str(info.value)


def test_a_broken_definition_names_its_file_and_field(tmp_path, monkeypatch):
    (tmp_path / "bad.toml").write_text('name = "bad"\n[sun]\nazimuth = 0\nelevation = 120\n')
    monkeypatch.setattr(ibl, "definitions_folder", lambda: tmp_path)
    with pytest.raises(ibl.IblError, match=r"bad\.toml: sun\.elevation"):
        ibl.resolve("bad")
