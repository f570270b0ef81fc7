"""Masks too large for the sampler's budget stay in their files: streamed rows, same values."""

from __future__ import annotations

import json
import math

import numpy as np
import OpenImageIO as oiio
import pytest
from _blend_helpers import disney, layer, layered, write_image

from lookdev.library import images
from lookdev.materials.layers import TextureMask
from lookdev.pipeline.blend import MaskSampler, TextureError, blend, resample
from lookdev.pipeline.blend.masks import BoxReduced
from lookdev.pipeline.blend.resample import TextureFile, read_channels

FORMATS = [(oiio.FLOAT, "exr"), (oiio.HALF, "exr"), (oiio.UINT8, "png"), (oiio.UINT16, "tif")]


def _whole(resolution):
    return MaskSampler(resolution, images={})  # a caller's cache: always decoded whole


def _streamed(resolution):
    return MaskSampler(resolution, output_channels=1e-9)  # no budget: always streamed


@pytest.mark.parametrize("fmt, suffix", FORMATS)
@pytest.mark.parametrize("channels", [1, 3])
def test_rows_read_from_the_file_equal_the_whole_image(tmp_path, fmt, suffix, channels):
    rng = np.random.default_rng(4)
    pixels = rng.random((37, 23, channels), dtype=np.float32)  # sizes that divide nothing
    tex = TextureMask(path=write_image(tmp_path / f"m.{suffix}", pixels, fmt=fmt))
    whole = read_channels(tex, channels)
    source = TextureFile(tex, channels)
    assert source.shape == whole.shape and source.dtype == whole.dtype
    for rows in ([0], [36], [36, 0, 36], [5, 6, 7, 20, 21], list(range(37))[::-1], []):
        np.testing.assert_array_equal(source[np.array(rows, dtype=int)], whole[rows])


@pytest.mark.parametrize("fmt, suffix", FORMATS)
@pytest.mark.parametrize("channel, count", [("R", 1), ("G", 1), ("R", 3)])
def test_rows_read_in_chunks_equal_openimageio_whole_image(
    tmp_path, monkeypatch, fmt, suffix, channel, count
):
    """Chunks of 32 rows (the smallest) across runs of every length: each chunk lands
    flipped in its place, as stored; the reference is ImageBuf's whole decode."""
    monkeypatch.setattr(images, "_CHUNK_BYTES", 1)
    rng = np.random.default_rng(11)
    pixels = rng.random((101, 19, 3), dtype=np.float32)
    pixels[:7] = 0.0  # exactly 0 and 1 survive every format
    pixels[-5:] = 1.0
    path = write_image(tmp_path / f"m.{suffix}", pixels, fmt=fmt)
    first = "RGB".index(channel)
    buf = oiio.ImageBuf(str(path))
    whole = buf.get_pixels(fmt, oiio.ROI(0, 19, 0, 101, 0, 1, first, first + count))
    expected = np.asarray(whole).reshape(101, 19, count)[::-1]  # UV order: row 0 at v = 0
    source = TextureFile(TextureMask(path=path, channel=channel), count)
    for rows in (range(101), range(31, 97), range(32, 64), [100, 0, 33, 34, 35, 64, 65]):
        np.testing.assert_array_equal(source[np.array(list(rows))], expected[list(rows)])
    exact = resample.as_float(expected)
    assert (exact[-7:] == 0).all() and (exact[:5] == 1).all()


@pytest.mark.parametrize("wrap", ["periodic", "clamp", "black", "mirror"])
@pytest.mark.parametrize(
    "size, out, scale",
    [(64, 64, 1.0), (48, 160, 1.0), (256, 40, 1.0), (96, 24, 3.0), (60, 16, 0.5)],
)
def test_a_streamed_mask_evaluates_exactly_as_a_decoded_one(tmp_path, wrap, size, out, scale):
    """Magnified, 1:1, minified (box-reduced rows computed per tile), repeated, cropped."""
    rng = np.random.default_rng(size)
    path = write_image(tmp_path / "m.exr", rng.random((size, size + 7), dtype=np.float32))
    tex = TextureMask(path=path, wrap=wrap, uv_scale=(scale, scale), uv_offset=(0.1, 0.3))
    whole, streamed = _whole((out, out + 3)), _streamed((out, out + 3))
    np.testing.assert_array_equal(streamed.evaluate(tex), whole.evaluate(tex))
    assert isinstance(streamed.image(tex), TextureFile)
    assert isinstance(whole.image(tex), np.ndarray)
    assert streamed.bounds(tex) == whole.bounds(tex)


@pytest.mark.parametrize("value", [0.0, 1.0])
def test_streamed_masks_of_exactly_zero_and_one_prune_like_decoded_ones(tmp_path, value):
    path = write_image(tmp_path / "flat.exr", np.full((32, 32), value, dtype=np.float32))
    tex = TextureMask(path=path)
    assert _streamed((8, 8)).bounds(tex) == (value, value) == _whole((8, 8)).bounds(tex)


def test_box_reduction_by_rows_equals_the_whole_reduction(tmp_path):
    rng = np.random.default_rng(9)
    path = write_image(tmp_path / "m.exr", rng.random((64, 32, 3), dtype=np.float32))
    source = TextureFile(TextureMask(path=path), 3)
    lazy = BoxReduced(source, 4, 2)
    whole = lazy[np.arange(16)]
    assert whole.shape == (16, 16, 3)
    expected = read_channels(TextureMask(path=path), 3).reshape(16, 4, 16, 2, 3).mean(axis=(1, 3))
    np.testing.assert_allclose(whole, expected, rtol=1e-6)
    np.testing.assert_array_equal(lazy[np.array([15, 0, 7, 7])], whole[[15, 0, 7, 7]])


def test_a_nan_in_a_streamed_mask_is_one_clear_error(tmp_path):
    pixels = np.zeros((300, 8), dtype=np.float32)
    pixels[2, 3] = np.nan  # a file row near the top: the last UV rows, read last
    tex = TextureMask(path=write_image(tmp_path / "bad.exr", pixels))
    with pytest.raises(TextureError, match="non-finite") as err:
        _streamed((8, 8)).bounds(tex, where="layer 'rust'")
    assert "\n" not in str(err.value) and "bad.exr" in str(err.value)


def test_blend_streams_masks_larger_than_half_its_output(tmp_path):
    """Two 64² float masks varying one 32² map: half the output is 2 KiB, so both stream;
    the blend equals the one made with the masks decoded whole."""
    rng = np.random.default_rng(5)
    masks = [
        TextureMask(path=write_image(tmp_path / f"m{i}.exr", rng.random((64, 64), np.float32)))
        for i in range(2)
    ]
    material = layered(
        layer(disney("base", roughness=0.2)),
        layer(disney("a", roughness=0.5), masks[0]),
        layer(disney("b", roughness=0.8), masks[1]),
    )
    streamed = blend(material, 32)
    decoded = blend(material, 32, images={})
    assert set(streamed.maps) == {"roughness"}
    np.testing.assert_array_equal(streamed.maps["roughness"], decoded.maps["roughness"])


@pytest.mark.slow
def test_bench_blend_reports_resident_peaks_of_both_cases(cli):
    r = cli("bench", "blend", "--resolution", "16", "--repeat", "1", "--json")
    assert r.code == 0, r.err
    doc = json.loads(r.out)
    for case in ("stack", "large_masks", "large_masks_decoded", "udim"):
        assert doc[f"peak_rss_mb_{case}"] >= 0 and math.isfinite(doc[f"peak_rss_to_output_{case}"])
    for case in ("stack", "large_masks", "udim"):
        assert doc["targets_met"][f"peak_rss_to_output_{case}"] in (True, False)
    assert doc["output_mb_large_masks"] == 16 * 16 * 4 / 1e6  # one float32 map: roughness
    assert doc["output_mb_udim"] == 32 * 32 * 4 / 1e6  # roughness over the 2 x 2 tiles
    assert "peak_to_output" in doc  # tracemalloc's figure stays beside the resident one


@pytest.mark.slow
def test_bench_blend_table_says_met_or_missed(cli):
    r = cli("bench", "blend", "--resolution", "16", "--repeat", "1")
    assert r.code == 0, r.err
    assert "peak_rss_to_output_large_masks" in r.out
    assert "< 2: met" in r.out or "< 2: missed" in r.out
