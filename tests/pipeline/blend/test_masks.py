"""lookdev.pipeline.blend.masks: evaluating masks at any resolution."""

from __future__ import annotations

import numpy as np
import OpenImageIO as oiio
import pytest
from _blend_helpers import write_image
from hypothesis import given, settings
from hypothesis import strategies as st

from lookdev.materials.layers import (
    CombineMask,
    ConstantMask,
    InvertMask,
    LevelsMask,
    NoiseMask,
    RampMask,
    TextureMask,
)
from lookdev.pipeline.blend import MaskSampler, TextureError
from lookdev.pipeline.blend.masks import fractal_noise


def evaluate(mask, height, width=None):
    return MaskSampler((height, width or height)).evaluate(mask, where="layer 'x'")


@pytest.fixture
def ramp_file(tmp_path):
    """A 4×4 image whose file rows (top first) are 0.0, 0.25, 0.5, 0.75 in R; G = 1 − R."""
    rows = np.repeat(np.array([0.0, 0.25, 0.5, 0.75])[:, None], 4, axis=1)
    return write_image(tmp_path / "rows.exr", np.stack([rows, 1 - rows], axis=-1))


# -- textures ------------------------------------------------------------------------------
def test_one_to_one_is_an_exact_copy_with_v_up(ramp_file):
    m = evaluate(TextureMask(path=ramp_file), 4)
    # UV row 0 is v ≈ 0: the bottom of the image, the file's last row.
    assert m[:, 0].tolist() == [0.75, 0.5, 0.25, 0.0]
    assert m.dtype == np.float32 and m.shape == (4, 4)


@pytest.mark.parametrize("channel", [1, "G", "g"])
def test_channel_by_index_name_or_letter(ramp_file, channel):
    m = evaluate(TextureMask(path=ramp_file, channel=channel), 4)
    assert m[:, 0].tolist() == [0.25, 0.5, 0.75, 1.0]


def test_invert(ramp_file):
    m = evaluate(TextureMask(path=ramp_file, invert=True), 4)
    assert m[:, 0].tolist() == [0.25, 0.5, 0.75, 1.0]


def test_eight_bit_images_are_data_not_colour(tmp_path):
    path = write_image(tmp_path / "m.png", np.full((2, 2), 128 / 255), fmt=oiio.UINT8)
    m = evaluate(TextureMask(path=path), 2)
    assert np.allclose(m, 128 / 255, atol=1e-6)  # no sRGB decoding (that would give 0.216)


def test_magnification_is_bilinear(tmp_path):
    path = write_image(tmp_path / "two.exr", np.array([[0.0, 1.0]]))
    m = evaluate(TextureMask(path=path, wrap="clamp"), 1, 4)
    # Output texel centres at u = 1/8 … 7/8 fall at source x = −0.25, 0.25, 0.75, 1.25.
    assert m[0].tolist() == [0.0, 0.25, 0.75, 1.0]


def test_minification_filters_instead_of_point_sampling(tmp_path):
    checker = (np.indices((256, 256)).sum(axis=0) % 2).astype(np.float32)
    m = evaluate(TextureMask(path=write_image(tmp_path / "c.exr", checker)), 16)
    # Point samples of a one-texel checker alias to all 0 or all 1; a filter gives ½.
    assert np.allclose(m, 0.5, atol=1e-6)


def test_minified_mean_is_the_source_mean(tmp_path):
    rng = np.random.default_rng(3)
    src = rng.random((64, 96)).astype(np.float32)
    m = evaluate(TextureMask(path=write_image(tmp_path / "n.exr", src)), 8, 12)
    assert m.mean() == pytest.approx(src.mean(), abs=1e-5)
    assert m.std() < src.std() / 4  # averaged, so much smoother


def test_minification_by_uv_scale_counts_too(tmp_path):
    stripes = np.tile(np.array([0.0, 1.0], dtype=np.float32), (4, 8))
    m = evaluate(TextureMask(path=write_image(tmp_path / "s.exr", stripes), uv_scale=(8, 1)), 4)
    assert np.allclose(m, 0.5, atol=1e-6)


@pytest.mark.parametrize(
    ("wrap", "expected"),
    [
        ("periodic", [0.5, 0.75, 0.0, 0.25]),
        ("clamp", [0.5, 0.75, 0.75, 0.75]),
        ("mirror", [0.5, 0.75, 0.75, 0.5]),
        ("black", [0.5, 0.75, 0.0, 0.0]),
    ],
)
def test_wrap_modes(tmp_path, wrap, expected):
    row = np.array([[0.0, 0.25, 0.5, 0.75]], dtype=np.float32)
    path = write_image(tmp_path / "row.exr", row)
    m = evaluate(TextureMask(path=path, wrap=wrap, uv_offset=(0.5, 0.0)), 1, 4)
    assert m[0].tolist() == expected


def test_values_outside_0_1_are_clamped_after_filtering(tmp_path):
    src = np.array([[-0.5, 1.5], [2.0, 0.0]], dtype=np.float32)
    sampler = MaskSampler((2, 2))
    tex = TextureMask(path=write_image(tmp_path / "hdr.exr", src))
    assert sampler.evaluate(tex)[::-1].tolist() == [[0.0, 1.0], [1.0, 0.0]]
    one = MaskSampler((1, 1)).evaluate(tex)  # the filtered average is 0.75: inside, kept
    assert one.tolist() == [[0.75]]
    assert sampler.bounds(tex) == (0.0, 1.0)


def test_texture_bounds_come_from_the_texels(tmp_path):
    src = np.array([[0.2, 0.7]], dtype=np.float32)
    tex = TextureMask(path=write_image(tmp_path / "b.exr", src))
    sampler = MaskSampler((8, 8))
    assert sampler.bounds(tex) == pytest.approx((0.2, 0.7))
    assert sampler.bounds(tex.model_copy(update={"invert": True})) == pytest.approx((0.3, 0.8))
    black = tex.model_copy(update={"wrap": "black", "uv_offset": (0.5, 0.0)})
    assert sampler.bounds(black)[0] == 0.0  # reads past the edge: zero is possible
    m = sampler.evaluate(tex)
    assert 0.2 - 1e-6 <= m.min() and m.max() <= 0.7 + 1e-6


def test_tiles_concatenate_to_the_whole(tmp_path):
    rng = np.random.default_rng(0)
    tex = TextureMask(path=write_image(tmp_path / "r.exr", rng.random((37, 53))), uv_scale=(2, 3))
    mask = CombineMask(kind="screen", inputs=[tex, NoiseMask(seed=4, octaves=6)])
    sampler = MaskSampler((29, 31))
    whole = sampler.evaluate(mask)
    parts = [sampler.evaluate(mask, slice(a, min(29, a + 5))) for a in range(0, 29, 5)]
    assert np.array_equal(np.concatenate(parts), whole)


# -- bad input -----------------------------------------------------------------------------
def test_missing_file_names_the_layer_and_the_file(tmp_path):
    with pytest.raises(TextureError) as info:
        evaluate(TextureMask(path=tmp_path / "nope.exr"), 4)
    assert str(info.value).startswith("layer 'x': ") and "nope.exr does not exist" in str(
        info.value
    )


def test_undecodable_file(tmp_path):
    path = tmp_path / "broken.png"
    path.write_bytes(b"\x89PNG\r\n\x1a\n this is not a png")
    with pytest.raises(TextureError, match=r"layer 'x': cannot decode .*broken\.png"):
        evaluate(TextureMask(path=path), 4)


def test_missing_channel_lists_what_the_file_has(ramp_file):
    with pytest.raises(TextureError) as info:
        evaluate(TextureMask(path=ramp_file, channel="A"), 4)
    assert "rows.exr has no channel 'A'; it has R, G" in str(info.value)
    with pytest.raises(TextureError, match="no channel 5"):
        evaluate(TextureMask(path=ramp_file, channel=5), 4)


def test_non_finite_pixels(tmp_path):
    path = write_image(tmp_path / "nan.exr", np.array([[0.5, np.nan]]))
    with pytest.raises(TextureError, match=r"nan\.exr has non-finite pixels"):
        evaluate(TextureMask(path=path), 4)


# -- procedural ----------------------------------------------------------------------------
def test_noise_is_deterministic_in_range_and_seeded():
    a = evaluate(NoiseMask(scale=5, octaves=4, seed=9), 64)
    assert np.array_equal(a, evaluate(NoiseMask(scale=5, octaves=4, seed=9), 64))
    assert not np.allclose(a, evaluate(NoiseMask(scale=5, octaves=4, seed=10), 64))
    assert 0.0 <= a.min() and a.max() <= 1.0 and 0.05 < a.std()


def test_noise_tiles_with_period_one():
    mask = NoiseMask(scale=3.3, octaves=5, seed=2, lacunarity=2.5)
    u = np.linspace(0, 1, 50)[None, :]
    v = np.linspace(0, 1, 40)[:, None]
    here = fractal_noise(mask, u, v, 512, 512)
    assert np.allclose(here, fractal_noise(mask, u + 1.0, v - 2.0, 512, 512), atol=1e-6)


def test_noise_drops_octaves_it_cannot_resolve():
    # Every octave of a 64-cell lattice is finer than 8 texels can show: only the mean stays.
    assert np.all(evaluate(NoiseMask(scale=64, octaves=3), 8) == 0.5)


def test_ramps():
    assert evaluate(RampMask(axis="v"), 4, 1)[:, 0].tolist() == [0.125, 0.375, 0.625, 0.875]
    smooth = evaluate(RampMask(axis="u", start=0.25, end=0.75, interpolation="smooth"), 1, 4)
    assert smooth[0].tolist() == [0.0, 0.15625, 0.84375, 1.0]
    radial = evaluate(RampMask(axis="radial", start=0.0, end=0.5), 3)
    assert radial[1, 1] == 0.0 and radial[0, 0] == pytest.approx(np.hypot(1 / 3, 1 / 3) / 0.5)
    assert MaskSampler((3, 3)).bounds(RampMask(axis="radial", end=0.5))[0] == 0.0


def test_ramp_bounds_are_exact():
    sampler = MaskSampler((4, 8))
    assert sampler.bounds(RampMask(axis="u")) == (1 / 16, 15 / 16)
    assert sampler.bounds(RampMask(axis="u", start=-2, end=-1)) == (1.0, 1.0)  # uniform


# -- combinations --------------------------------------------------------------------------
@pytest.mark.parametrize(
    ("mask", "value"),
    [
        (CombineMask(kind="multiply", inputs=[0.5, 0.4]), 0.2),
        (CombineMask(kind="screen", inputs=[0.5, 0.4]), 0.7),
        (CombineMask(kind="max", inputs=[0.5, 0.4, 0.9]), 0.9),
        (CombineMask(kind="min", inputs=[0.5, 0.4, 0.9]), 0.4),
        (InvertMask(input=0.25), 0.75),
        (LevelsMask(input=0.5, low=0.25, high=0.75), 0.5),
        (LevelsMask(input=0.25, gamma=2.0), 0.5),
        (LevelsMask(input=0.6, contrast=3.0), 0.8),
        (LevelsMask(input=0.5, out_low=0.2, out_high=0.4), 0.3),
        (LevelsMask(input=0.1, low=0.25, high=0.75), 0.0),
    ],
)
def test_combinations_by_hand(mask, value):
    m = evaluate(mask, 2)
    assert np.allclose(m, value, atol=1e-6)
    assert MaskSampler((2, 2)).bounds(mask) == pytest.approx((value, value))


def test_exact_zero_and_one_survive_every_combination():
    for mask in (
        CombineMask(kind="multiply", inputs=[1.0, 1.0]),
        CombineMask(kind="screen", inputs=[0.0, 1.0]),
        InvertMask(input=0.0),
        LevelsMask(input=1.0, gamma=3.0, contrast=2.0),
    ):
        assert np.all(evaluate(mask, 3) == 1.0)
    assert np.all(evaluate(CombineMask(kind="multiply", inputs=[0.0, 0.7]), 3) == 0.0)


def _masks():
    leaf = st.one_of(
        st.floats(0, 1).map(lambda v: ConstantMask(value=v)),
        st.builds(RampMask, axis=st.sampled_from(["u", "v", "radial"])),
        st.builds(NoiseMask, scale=st.floats(0.5, 20), octaves=st.integers(1, 5)),
    )
    return st.recursive(
        leaf,
        lambda inner: st.one_of(
            st.builds(InvertMask, input=inner),
            st.builds(LevelsMask, input=inner, gamma=st.floats(0.2, 5), contrast=st.floats(0, 4)),
            st.builds(
                CombineMask,
                kind=st.sampled_from(["multiply", "screen", "max", "min"]),
                inputs=st.lists(inner, min_size=1, max_size=3),
            ),
        ),
        max_leaves=6,
    )


@settings(max_examples=60, deadline=None)
@given(_masks())
def test_any_mask_stays_in_0_1_and_within_its_bounds(mask):
    sampler = MaskSampler((9, 7))
    m = sampler.evaluate(mask)
    lo, hi = sampler.bounds(mask)
    assert m.dtype == np.float32 and np.isfinite(m).all()
    assert 0.0 <= m.min() and m.max() <= 1.0
    assert lo - 1e-6 <= m.min() and m.max() <= hi + 1e-6


def test_a_channel_beside_alpha_is_not_premultiplied(tmp_path):
    rgba = np.zeros((2, 2, 4), dtype=np.float32)
    rgba[..., 0], rgba[..., 3] = 0.8, 0.5  # PNG alpha is unassociated: R stays 0.8
    path = write_image(tmp_path / "rgba.png", rgba, fmt=oiio.UINT8)
    m = evaluate(TextureMask(path=path, channel="R"), 2)
    assert np.allclose(m, round(0.8 * 255) / 255, atol=1e-6)
    assert np.allclose(evaluate(TextureMask(path=path, channel="A"), 2), 128 / 255, atol=1e-6)


@pytest.mark.parametrize(
    ("fmt", "suffix", "dtype", "step"),
    [
        (oiio.UINT8, "png", np.uint8, 1 / 255),
        (oiio.UINT16, "png", np.uint16, 1 / 65535),
        (oiio.HALF, "exr", np.float16, 1 / 1024),
    ],
)
def test_decoded_masks_stay_in_the_files_pixel_format(tmp_path, fmt, suffix, dtype, step):
    values = np.linspace(0, 1, 16, dtype=np.float32).reshape(4, 4)
    tex = TextureMask(path=write_image(tmp_path / f"m.{suffix}", values, fmt=fmt))
    sampler = MaskSampler((4, 4))
    assert sampler.image(tex).dtype == dtype  # 1 or 2 bytes a texel, not 4
    assert np.allclose(sampler.evaluate(tex)[::-1], values, atol=step)


def test_many_repeats_are_box_reduced_first_and_stay_filtered(tmp_path):
    rng = np.random.default_rng(1)
    src = rng.random((512, 512)).astype(np.float32)
    tex = TextureMask(path=write_image(tmp_path / "grain.exr", src), uv_scale=(64, 64))
    sampler = MaskSampler((128, 128))
    m = sampler.evaluate(tex)  # footprint 256 texels: reduced by 128, then a tent
    assert sampler._mips and next(iter(sampler._mips.values())).shape == (4, 4, 1)
    assert abs(float(m.mean()) - float(src.mean())) < 0.01 and m.std() < 0.05


def test_box_reduction_agrees_with_the_full_tent(tmp_path):
    y, x = np.mgrid[0:256, 0:256] / 256.0
    smooth = (0.5 + 0.4 * np.sin(2 * np.pi * x) * np.cos(2 * np.pi * y)).astype(np.float32)
    tex = TextureMask(path=write_image(tmp_path / "smooth.exr", smooth))
    reduced = MaskSampler((16, 16)).evaluate(tex)  # footprint 16: reduced by 8
    assert np.allclose(reduced, _full_tent(tex, 16), atol=0.01)


def _full_tent(tex, n):
    """The tent filter on the full-resolution source (no box reduction)."""
    from lookdev.pipeline.blend.resample import resample, taps

    sampler = MaskSampler((n, n))
    src = sampler.image(tex)
    h, w = src.shape[:2]
    out = resample(src, taps(n, h, 1.0, 0.0, "periodic"), taps(n, w, 1.0, 0.0, "periodic"))
    return np.clip(out[..., 0], 0.0, 1.0)
