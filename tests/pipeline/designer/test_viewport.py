"""The designer's viewport: both modes on tiny frames (designer: relit g-buffer; truth:
the proofs' path tracer edited in place)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from lookdev.materials.params import DisneyParams
from lookdev.pipeline.blend.result import BlendedMaterial

pytestmark = pytest.mark.render

W, H = 48, 27


def hub(**params) -> BlendedMaterial:
    return BlendedMaterial.of_params(DisneyParams(**params))


@pytest.fixture(scope="module")
def viewport():
    from lookdev.pipeline.designer.viewport import Viewport

    view = Viewport(hub(base_color=(0.8, 0.2, 0.1), roughness=0.4), width=W, height=H, rig="balls")
    yield view
    view.close()


def _material(view) -> np.ndarray:
    return view._engines["designer"].gbuffer.material_mask()


def test_designer_frame_refines_and_edits_change_only_the_material(viewport):
    viewport.set_mode("designer")
    first = viewport.step()
    assert first.rgb.shape == (H, W, 3) and first.rgb.dtype == np.float32
    assert first.display.shape == (H, W, 3) and first.display.dtype == np.uint8
    assert first.mode == "designer" and not first.denoised and first.spp == 1
    for _ in range(5):
        frame = viewport.step()
    assert frame.spp > first.spp and np.all(np.isfinite(frame.rgb))
    before = frame.rgb.copy()
    parts = viewport._engines["designer"].parts
    other_spp = parts["other"].spp
    viewport.update_material(hub(base_color=(0.1, 0.3, 0.9), roughness=0.4))
    after = viewport.step()
    inside = _material(viewport)
    assert inside.any() and (~inside).any()
    # Blue where the material is, from one sample again; the ground, rig and sky keep
    # what they had reached (their part is not restarted).
    assert after.rgb[inside][:, 2].mean() > before[inside][:, 2].mean()
    assert parts["material"].spp == 1 and parts["other"].spp == other_spp


def test_ibl_rotation_relights_and_exposure_is_display_only(viewport):
    viewport.set_mode("designer")
    viewport.rotate_ibl(0.0)
    for _ in range(4):
        frame = viewport.step()
    viewport.rotate_ibl(180.0)
    turned = viewport.step()
    assert np.abs(turned.rgb - frame.rgb).mean() > 1e-3
    rgb = turned.rgb.copy()
    bright = turned.display.mean()
    viewport.set_exposure(-3.0)
    shown = viewport.raw()
    np.testing.assert_array_equal(shown.rgb, rgb)
    assert shown.display.mean() < bright
    viewport.set_exposure(0.0)


def test_frozen_passes_equal_traced_ones():
    """The recorded (frozen) pass replays exactly what tracing the model computes, at
    every sub-pixel position (each its own hit count under one padded width)."""
    import mitsuba as mi

    from lookdev.pipeline.designer import gbuffer
    from lookdev.pipeline.designer.relight import Relighter
    from lookdev.pipeline.proof import ibl, shaderball
    from lookdev.pipeline.variant import use_mitsuba

    use_mitsuba()
    env = ibl.load("studio", 64).pixels
    scene = mi.load_dict(shaderball.scene_dict({"type": "diffuse"}, env, (W, H), 2, rig="none"))
    g = gbuffer.render(scene, W, H)
    material = hub(base_color=(0.5, 0.5, 0.2), clearcoat=0.5)
    outs = []
    for freeze in (True, False):
        r = Relighter(scene, freeze=freeze)
        r.set_material(material, g)
        outs.append(
            [r.shade(g, part, k, 7 + k) for k in range(4) for part in ("material", "other")]
        )
    assert len({h.width for h in g.material}) == 1
    assert len({h.count for h in g.material}) > 1  # the positions see different pixels
    for (p1, v1), (p2, v2) in zip(*outs, strict=True):
        np.testing.assert_array_equal(p1, p2)
        np.testing.assert_allclose(v1, v2, rtol=1e-5, atol=1e-6)


def test_a_pass_continues_each_pixels_sequence():
    """A pass of 4 samples from sample 0 is the mean of four 1-sample passes numbered 0 … 3
    (the same per-pixel shift, the sequence continued), and another seed differs."""
    import mitsuba as mi

    from lookdev.pipeline.designer import gbuffer
    from lookdev.pipeline.designer.relight import Relighter
    from lookdev.pipeline.proof import ibl, shaderball
    from lookdev.pipeline.variant import use_mitsuba

    use_mitsuba()
    env = ibl.load("studio", 64).pixels
    scene = mi.load_dict(shaderball.scene_dict({"type": "diffuse"}, env, (W, H), 2, rig="none"))
    g = gbuffer.render(scene, W, H)
    r = Relighter(scene, freeze=False)
    r.set_material(hub(base_color=(0.5, 0.5, 0.2), roughness=0.3), g)
    for part in ("material", "other"):
        pixels, four = r.shade(g, part, 0, 5, spp=4, base=0)
        ones = [r.shade(g, part, 0, 5, spp=1, base=k)[1] for k in range(4)]
        np.testing.assert_allclose(four, np.mean(ones, axis=0), rtol=1e-4, atol=1e-6)
        assert not np.allclose(r.shade(g, part, 0, 6, spp=4, base=0)[1], four)


@pytest.mark.parametrize("dims", [1, 2, 5])
def test_the_kronecker_steps_are_distinct_fractions(dims):
    from lookdev.pipeline.designer.relight import kronecker

    alphas = kronecker(dims)
    assert len(set(alphas)) == dims and all(0 < a < 2**32 for a in alphas)


def test_the_display_cache_transforms_only_what_changed_and_matches_a_full_view():
    from lookdev.pipeline.designer.viewport import DisplayCache, _display

    rng = np.random.default_rng(4)
    first = rng.random((H, W, 3)).astype(np.float32) * 4.0
    cache = DisplayCache()
    shown = cache(first, 0.0)
    second = first.copy()
    second[: H // 2, : W // 3] *= 0.25
    again = cache(second, 0.0)
    assert again is not shown  # a frame already sent is never written to
    full = _display(second, 0.0)
    assert np.abs(again.astype(int) - full.astype(int)).max() <= 1
    np.testing.assert_array_equal(again[H // 2 :], shown[H // 2 :])
    darker = cache(second, -2.0)  # a new exposure transforms everything
    assert darker.mean() < again.mean()


def test_truth_mode_edits_in_place_with_no_kernel_compiles(viewport):
    """Random edits of every continuous parameter, lobe switches included (clearcoat,
    sheen, spec_trans from 0), after the first frame: no new kernel, no new scene."""
    import drjit as dr

    viewport.set_mode("truth")
    viewport.update_material(hub(base_color=(0.8, 0.2, 0.1), roughness=0.4))
    first = viewport.step()
    assert first.mode == "truth" and first.spp == 1
    engine = viewport._engines["truth"]
    rebuilds = engine.rebuilds
    rng = np.random.default_rng(3)
    dr.set_flag(dr.JitFlag.KernelHistory, True)
    dr.kernel_history()  # clears it
    means = []
    for i in range(4):
        edit = {
            "base_color": tuple(float(c) for c in rng.random(3)),
            "roughness": float(rng.random()),
            "clearcoat": float(i % 2),
            "sheen": float(rng.random()) * (i % 2),
            "spec_trans": 0.5 * (i % 2),
            "metallic": float(rng.random()) * 0.5,
        }
        viewport.update_material(hub(**edit))
        means.append(viewport.step().rgb.mean())
    history = dr.kernel_history()
    dr.set_flag(dr.JitFlag.KernelHistory, False)
    compiled = [k for k in history if k.get("cache_hit") is not None and not k["cache_hit"]]
    assert compiled == []
    assert engine.rebuilds == rebuilds
    assert len(set(np.round(means, 6))) == len(means)  # every edit shows


def test_truth_mode_denoises_when_still_and_keeps_the_raw_frame(viewport, monkeypatch):
    from lookdev.pipeline.designer import truth

    monkeypatch.setattr(truth, "STILL_SECONDS", 0.0)
    viewport.set_mode("truth")
    frame = viewport.step()
    raw = viewport.raw()
    assert frame.denoised and not raw.denoised
    assert frame.spp == raw.spp
    assert not np.array_equal(frame.rgb, raw.rgb)


def test_a_switch_rebuilds_the_truth_scene_once(viewport):
    viewport.set_mode("truth")
    viewport.step()
    engine = viewport._engines["truth"]
    rebuilds = engine.rebuilds
    viewport.update_material(hub(thin=True, spec_trans=0.5))
    assert np.all(np.isfinite(viewport.step().rgb))
    assert engine.rebuilds == rebuilds + 1


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (lambda v: v.set_mode("preview"), "unknown mode"),
        (lambda v: v.resize(4, 27), "width"),
        (lambda v: v.set_exposure(math.nan), "exposure"),
        (lambda v: v.rotate_ibl(math.inf), "finite"),
        (lambda v: v.set_ibl("no-such-ibl"), "ibl"),
    ],
)
def test_bad_input_is_one_designer_error(viewport, call, message):
    from lookdev.pipeline.designer.viewport import DesignerError

    with pytest.raises(DesignerError, match=message):
        call(viewport)


def test_resize_keeps_the_framing_in_both_modes():
    from lookdev.pipeline.designer.viewport import Viewport

    view = Viewport(hub(roughness=0.4), width=W, height=H, rig="none")
    view.step()
    share = _material(view).mean()
    view.resize(2 * W, 2 * H)
    frame = view.step()
    assert frame.rgb.shape == (2 * H, 2 * W, 3)
    assert abs(_material(view).mean() - share) < 0.02  # the same picture, more pixels
    view.set_mode("truth")
    assert view.step().rgb.shape == (2 * H, 2 * W, 3)
    view.close()


def test_a_table_reading_sheen_renders_in_designer_mode():
    """The Conty-Kulla sheen reads look-up tables; its pass renders (frozen, or traced
    each pass where the recording cannot see a variable it reads)."""
    from lookdev.pipeline.designer.viewport import Viewport

    view = Viewport(hub(sheen=1.0, sheen_model="conty_kulla"), width=W, height=H, rig="none")
    for _ in range(3):
        frame = view.step()
    inside = _material(view)
    assert np.all(np.isfinite(frame.rgb)) and frame.rgb[inside].mean() > 0
    view.close()
