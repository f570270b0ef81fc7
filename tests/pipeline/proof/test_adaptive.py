"""Per-pixel adaptive sampling: the estimate, the stop rule, compaction, the checked denoiser.

The pass loop runs against a fake renderer whose pixels are a known picture plus seeded
Gaussian noise of σ/√n (n the pixel's samples), so every stop is deterministic and the
true error of every pixel is known.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from lookdev.pipeline.proof import adaptive, checked
from lookdev.pipeline.proof.tonemap import view

H, W = 24, 48
TRUTH = np.full((H, W, 3), 0.18)
TRUTH[:, W // 2 :] = 0.6


class FakeRenderer:
    """Pixels of ``TRUTH`` with noise σ per sample; ``loud`` columns have 8× the noise."""

    width, height = W, H

    def __init__(self, sigma: float = 0.1, loud: slice = slice(0, 6)):
        self.sigma = np.full((H, W), sigma)
        self.sigma[:, loud] *= 8
        self.asked: list[np.ndarray] = []

    def render(self, pixels, samples, seed):
        self.asked.append(np.asarray(pixels))
        rng = np.random.default_rng(seed)
        truth = TRUTH.reshape(-1, 3)[pixels]
        k = (samples // 2)[:, None].astype(float)
        sig = self.sigma.ravel()[pixels][:, None]
        half = [truth * k + rng.normal(0, 1, truth.shape) * sig * np.sqrt(k) for _ in range(2)]
        return half[0], half[1]


def _run(r, **kw):
    kw = {"target": 0.02, "max_spp": 4096, "seed": lambda i: 10 + i} | kw
    return adaptive.render_adaptive(r, **kw)


# -- the helpers ---------------------------------------------------------------------------
@settings(max_examples=25, deadline=None)
@given(st.integers(1, 9), st.integers(1, 9), st.integers(0, 3), st.integers(0, 2**32 - 1))
def test_box_mean_is_the_clipped_window_mean(h, w, radius, seed):
    x = np.random.default_rng(seed).random((h, w))
    want = np.array(
        [
            [x[max(0, i - radius) : i + radius + 1, max(0, j - radius) : j + radius + 1].mean()
             for j in range(w)]
            for i in range(h)
        ]
    )  # fmt: skip
    np.testing.assert_allclose(adaptive.box_mean(x, radius), want, rtol=1e-9, atol=1e-12)


def test_dilate_grows_a_pixel_to_its_neighbourhood_and_leaves_empty_empty():
    m = np.zeros((5, 5), bool)
    assert not adaptive.dilate(m, 1).any()
    m[0, 0] = True
    assert adaptive.dilate(m, 1).sum() == 4  # a corner: 2×2 of its 3×3 is inside
    m[0, 0], m[2, 2] = False, True
    assert adaptive.dilate(m, 1).sum() == 9


def test_pass_samples_are_even_within_the_cap_and_at_most_a_doubling():
    spp = np.array([16, 16, 100, 254, 256])
    out = adaptive.pass_samples(spp, np.array([0.021, 9.0, 9.0, 9.0, 9.0]), 0.02, 256)
    assert out.tolist() == [8, 16, 100, 2, 0]
    assert (out % 2 == 0).all() and (spp + out <= 256).all()


# -- the loop ------------------------------------------------------------------------------
def test_each_pass_renders_only_open_pixels_and_the_loud_ones_get_the_samples():
    r = FakeRenderer()
    f = _run(r)
    assert f.stop == "target" and f.converged >= adaptive.CONVERGED_SHARE
    assert len(r.asked[0]) == H * W and all(len(p) < H * W for p in r.asked[1:])
    quiet, loud = f.spp[:, 20:].mean(), f.spp[:, :6].mean()
    assert loud > 30 * quiet  # variance 64× higher: ≈ 64× the samples
    # open pixels keep their neighbours open: column 6 (next to the loud band) sampled more
    assert f.spp[:, 6].mean() > f.spp[:, 12].mean()


def test_the_estimate_is_within_2x_of_the_true_display_error_per_region():
    f = _run(FakeRenderer(), target=0.01)
    d = view(f.image) - view(TRUTH)
    true = np.mean(d * d, axis=-1)
    for cols in (slice(0, 6), slice(8, 22), slice(26, W)):
        est = math.sqrt(np.mean(np.square(f.raw_error[:, cols])))
        meas = math.sqrt(np.mean(true[:, cols]))
        assert 0.5 < est / meas < 2.0


def test_an_unreachable_target_stops_at_the_cap_and_records_the_share_met():
    f = _run(FakeRenderer(), target=1e-5, max_spp=64)
    assert f.stop == "max_spp" and f.spp.max() == 64 and f.converged < 0.5


def test_a_time_budget_stops_before_the_next_pass_would_overrun_it():
    ticks = iter(range(100))
    f = _run(FakeRenderer(), target=1e-5, time_budget=2.5, clock=lambda: float(next(ticks)))
    # passes take 1 tick: after the second, a third would end at 3 > 2.5
    assert (f.stop, f.passes, f.seconds) == ("time_budget", 2, 2.0)


def test_max_spp_below_the_first_pass_renders_one_pass_of_the_cap():
    f = _run(FakeRenderer(), max_spp=4)
    assert f.passes == 1 and (f.spp == 4).all()


# -- the checked denoiser --------------------------------------------------------------------
def test_an_identity_denoiser_has_no_bias_and_the_raw_noise_as_residual():
    rng = np.random.default_rng(3)
    a, b = (TRUTH + rng.normal(0, 0.05, TRUTH.shape) for _ in range(2))
    raw = adaptive.pixel_error(a, b)
    c = checked.check(a, b, raw, lambda im: im)
    assert float(c.bias.mean()) < 0.05 * float(np.mean(raw**2))
    assert c.noise == pytest.approx(math.sqrt(np.mean(raw**2)), rel=0.05)


def test_a_biased_denoiser_is_caught_and_the_raw_pixels_take_over():
    rng = np.random.default_rng(4)
    a, b = (TRUTH + rng.normal(0, 0.002, TRUTH.shape) for _ in range(2))
    raw = adaptive.pixel_error(a, b)
    c = checked.check(a, b, raw, lambda im: im * 0.7)  # darkens: no noise left, all bias
    truth_err = np.abs(view(TRUTH * 0.7) - view(TRUTH)).mean()
    assert math.sqrt(float(c.bias.mean())) == pytest.approx(truth_err, rel=0.2)
    assert c.raw_weight > 0.95  # the raw frame is far better: it is what is shown
    assert np.abs(view(c.image) - view(TRUTH)).mean() < 0.1 * truth_err


def test_a_denoiser_whose_halves_err_alike_is_caught_by_the_hold_out():
    """D_A = D_B (a fixed pattern whatever the input): their difference sees nothing; the
    raw other half does."""
    rng = np.random.default_rng(5)
    a, b = (TRUTH + rng.normal(0, 0.01, TRUTH.shape) for _ in range(2))
    pattern = TRUTH + rng.normal(0, 0.05, TRUTH.shape)
    c = checked.check(a, b, adaptive.pixel_error(a, b), lambda im: pattern)
    assert float(c.variance.max()) == 0.0
    d = view(pattern) - view(TRUTH)
    truth_err = math.sqrt(float(np.mean(d * d)))
    est = math.sqrt(float(np.mean(c.bias)))
    assert 0.5 * truth_err < est < 2.0 * truth_err


def test_an_isolated_loud_pixel_keeps_half_its_own_estimate():
    x = np.zeros((5, 5))
    x[2, 2] = 9.0
    out = adaptive.local_mean(x, 1)
    assert out[2, 2] == pytest.approx(adaptive.OWN * 9.0) and out[0, 0] == 0.0


def test_blend_edges_zero_errors():
    img, w = checked.blend(
        np.zeros((1, 1, 3)), np.ones((1, 1, 3)), np.zeros((1, 1)), np.zeros((1, 1))
    )
    assert w.tolist() == [[0.0]] and img.tolist() == [[[1.0, 1.0, 1.0]]]


# -- in Mitsuba ----------------------------------------------------------------------------
@pytest.fixture(scope="module")
def table():
    from lookdev.library import load_material
    from lookdev.pipeline.blend import blend
    from lookdev.pipeline.proof import ibl, turntable
    from lookdev.pipeline.variant import use_mitsuba

    use_mitsuba()
    hub = blend(load_material("plastic_glossy"), 16)
    bsdf, depth = turntable.material_bsdf(hub)
    t = turntable.Turntable(bsdf, ibl.load("studio", 64).pixels, (24, 12), depth, rig="none")
    t.set_frame(turntable.Frame(0, "element", 0.0))
    return t


@pytest.mark.render
def test_compacted_pixels_render_what_the_film_renders(table):
    """The compacted wavefront's frame has the mean of ``mi.render``'s, within noise;
    a pixel asked alone gets what it gets in a full pass with the same lanes' seed."""
    r = adaptive.PixelRenderer(table.scene, table.camera_index, freeze=False)
    n = r.width * r.height
    sa, sb = r.render(np.arange(n), np.full(n, 256), seed=5)
    mine = ((sa + sb) / 256).reshape(r.height, r.width, 3)
    film = table.render(256, seed=6)
    diff = float(mine.mean() - film.mean())
    noise = float(np.std(mine - film)) / math.sqrt(mine.size)
    assert abs(diff) < 5 * noise + 1e-4
    part_a, _ = r.render(np.array([7, 100]), np.array([8, 4]), seed=9)
    assert part_a.shape == (2, 3) and np.isfinite(part_a).all()


@pytest.mark.render
def test_a_gaussian_filter_is_refused_for_per_pixel_sampling():
    from lookdev.library import load_material
    from lookdev.pipeline.blend import blend
    from lookdev.pipeline.proof import ibl, turntable

    hub = blend(load_material("plastic_glossy"), 16)
    bsdf, depth = turntable.material_bsdf(hub)
    env = ibl.load("studio", 64).pixels
    t = turntable.Turntable(bsdf, env, (8, 8), depth, rig="none", pixel_filter="gaussian")
    with pytest.raises(ValueError, match="box pixel filter"):
        adaptive.PixelRenderer(t.scene, t.camera_index)


def test_negative_light_keeps_its_value_in_the_checked_frame():
    """A patch outside the working gamut (negative red), denoised as denoise.denoise does
    (each sign as light), keeps its value in the frame shown."""
    from lookdev.pipeline.proof.denoise import denoise

    a = np.full((32, 32, 3), 0.3)
    a[8:24, 8:24, 0] = -0.05
    b = a.copy()
    raw = adaptive.pixel_error(a, b) + 0.01
    c = checked.check(a, b, raw, denoise)
    assert np.allclose(c.image[12:20, 12:20, 0], -0.05, atol=0.005)
    assert np.all(np.isfinite(c.residual))


@pytest.mark.render
def test_the_bench_item_measures_all_three_methods_and_the_estimate_per_class():
    from lookdev.pipeline.bench import adaptive as bench
    from lookdev.pipeline.bench import error

    assert "adaptive" in error.ITEMS
    s = bench.AdaptiveSettings(cases=(("plastic_glossy", "studio"),), resolution=(24, 12),
                               reference_spp=32, max_spp=32)  # fmt: skip
    (case,) = bench.run(s)
    assert "skipped" not in case, case.get("skipped")
    for method in ("uniform", "adaptive", "adaptive_checked"):
        assert case[method]["relmse"] > 0 and case[method]["cpu_s"] > 0
    assert set(case["adaptive"]["estimate_check"]) == {"smooth", "edges", "hot"}
    assert case["uniform"]["cpu_to_target"] == "predicted"
