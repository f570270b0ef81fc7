"""Proof pieces: the view transform, contact sheets, the shader ball and the turntable."""

from __future__ import annotations

import doctest
import importlib

import colour as colour_science
import numpy as np
import pytest

from lookdev.materials import colour
from lookdev.pipeline.proof import contact, shaderball, tonemap

MODULES = ["ibl", "tonemap", "contact", "shaderball", "turntable", "batch"]


@pytest.mark.parametrize("name", MODULES)
def test_doctests(name, tmp_path, monkeypatch):
    monkeypatch.setenv("LOOKDEV_CACHE", str(tmp_path))
    module = importlib.import_module(f"lookdev.pipeline.proof.{name}")
    assert doctest.testmod(module).failed == 0


# -- view transform ------------------------------------------------------------------------
# The view is OCIO's DisplayViewTransform of the one config (materials/colour.py). These
# tests read its output back with colour-science, an independent implementation of the
# sRGB curve and of Oklab, to check what the view promises.
ACES_SDR = "ACES 2.0 - SDR 100 nits (Rec.709)"
UNTONED = "Un-tone-mapped"


def _oklab_hue(display: np.ndarray) -> float:
    """Oklab hue angle (degrees) of an sRGB display code value."""
    linear = colour_science.models.eotf_sRGB(np.clip(display, 0.0, 1.0))
    lab = colour_science.XYZ_to_Oklab(colour_science.RGB_to_XYZ(linear, "sRGB"))
    return float(np.degrees(np.arctan2(lab[..., 2], lab[..., 1])))


def test_the_default_view_is_the_configs_aces_2_sdr_view():
    assert (colour.display(), colour.view()) == ("sRGB - Display", ACES_SDR)


@pytest.mark.parametrize("k", [2.0, 4.0, 8.0, 16.0, 64.0])
def test_a_hot_saturated_highlight_keeps_its_hue_through_the_default_view(k):
    """Burley §6.2: clipping shifts hue and "forces the core to always go to white". The
    ACES 2.0 view promises hue preservation through its roll-off: measured within 4.4° of
    Oklab hue from 0.1× to 64× this red; Un-tone-mapped clips it towards yellow."""
    red = np.array([1.0, 0.1, 0.01])
    dim = _oklab_hue(tonemap.view(0.1 * red))
    hot = tonemap.view(k * red)
    assert hot.max() <= 1.0 and hot[0] >= hot[1] >= hot[2]
    assert abs(_oklab_hue(hot) - dim) < 5.0
    if k >= 4.0:
        with colour.use(view=UNTONED):
            assert abs(_oklab_hue(tonemap.view(k * red)) - dim) > 25.0  # what it replaces


def test_un_tone_mapped_is_the_srgb_curve_of_the_clipped_values():
    grey = np.linspace(0.0, 2.0, 41)[:, None].repeat(3, axis=1)
    with colour.use(view=UNTONED):
        out = tonemap.view(grey, exact=True)
        baked = tonemap.view(grey)
    reference = colour_science.models.eotf_inverse_sRGB(np.clip(grey, 0.0, 1.0))
    np.testing.assert_allclose(out, reference, atol=2e-6)
    np.testing.assert_allclose(baked, reference, atol=0.5 / 255.0)  # the LUT: within ½ code


@pytest.mark.parametrize("view", [ACES_SDR, UNTONED])
def test_view_is_monotone_in_grey_and_exposure_is_a_scale(view):
    grey = np.geomspace(1e-4, 1e4, 200)[:, None].repeat(3, axis=1)
    with colour.use(view=view):
        out = tonemap.view(grey, exact=True)[:, 0]
        assert np.all(np.diff(out) >= 0.0) and out[0] >= 0.0 and out[-1] <= 1.0
        baked = tonemap.view(grey)[:, 0]  # the LUT: monotone but for float32 rounding at white
        assert np.all(np.diff(baked) >= -1e-7) and baked[0] >= 0.0 and baked[-1] <= 1.0
        np.testing.assert_allclose(tonemap.view(grey, 1.0), tonemap.view(2.0 * grey), atol=1e-6)


@pytest.mark.parametrize(
    ("grey", "shown"),
    [
        (0.0, 0.0),  # black stays black
        (1e30, 1.0),  # huge: white, never above it
        (-3.0, 0.0),  # negative: black
        (float("nan"), 0.0),  # NaN: black, not NaN
        (float("inf"), 0.0),  # infinite: black (a renderer's bug, not light)
    ],
)
def test_view_at_its_edges(grey, shown):
    out = tonemap.view(np.full((1, 3), grey), exposure=tonemap.EXPOSURE_MAX)
    assert np.isfinite(out).all()
    np.testing.assert_allclose(out, np.full((1, 3), shown), atol=2e-3)


def test_view_survives_nan_inf_and_negative_pixels():
    out = tonemap.view(np.array([[np.nan, 1.0, 0.5], [np.inf, -1.0, 0.0], [0.0, 0.0, 0.0]]))
    assert np.isfinite(out).all() and out.min() >= 0.0 and out.max() <= 1.0
    assert out[2].tolist() == [0.0, 0.0, 0.0]


def test_a_grey_looks_the_same_in_either_working_space():
    grey = np.linspace(0.0, 4.0, 33)[:, None].repeat(3, axis=1)
    shown = {}
    for space in colour.WORKING_SPACES:
        with colour.use(working_space=space):
            shown[space] = tonemap.to_8bit(tonemap.view(colour.convert(grey, "lin_rec709")))
    assert np.abs(shown["lin_rec709"].astype(int) - shown["acescg"]).max() <= 1


def test_unknown_display_view_or_look_is_one_line():
    for kwargs in ({"view": "Filmic"}, {"display": "CRT"}, {"look": "bleach"}):
        with pytest.raises(colour.ColourError, match="lookdev colour views") as e:
            with colour.use(**kwargs):
                pass
        assert "\n" not in str(e.value)


# -- contact sheets ------------------------------------------------------------------------
def _frames(n, h=24, w=32):
    return [np.full((h, w, 3), (i + 1) / (n + 1)) for i in range(n)]


def test_contact_sheet_grid_holds_every_frame_and_labels_it():
    images = _frames(5)
    sheet = contact.contact_sheet(images, [f"frame {i}" for i in range(5)], "gold × studio", 3)
    title_h, label_h = max(16, 24 // 5), max(12, 24 // 8)
    assert sheet.shape[1] == 3 * (32 + contact.GAP) + contact.GAP
    assert sheet.shape[0] == title_h + 2 * (24 + label_h + contact.GAP) + contact.GAP
    x0, y0 = contact.GAP, title_h
    assert sheet[y0 + 5, x0 + 5] == pytest.approx(images[0][0, 0])
    label = sheet[y0 + 24 : y0 + 24 + label_h, x0 : x0 + 32]
    assert (label > 0.5).any(), "no text under the first frame"


@pytest.mark.parametrize(("x", "y"), [(4, 40), (150, 12), (-3, 78)])
def test_a_label_drawn_in_its_box_is_the_label_drawn_on_the_whole_canvas(x, y):
    import OpenImageIO as oiio

    canvas = np.random.default_rng(2).uniform(0.0, 1.0, (80, 200, 3))
    whole = oiio.ImageBuf(canvas.astype(np.float32))
    if not oiio.ImageBufAlgo.render_text(
        whole, x, y, "element 45°  gy", 20, "DroidSans", contact.TEXT
    ):
        pytest.skip("no font: the bitmap font draws labels")
    contact.draw_text(canvas, x, y, "element 45°  gy", 20)  # edges: clipped alike
    assert np.array_equal(canvas.astype(np.float32), whole.get_pixels(oiio.FLOAT))


def test_without_fonts_the_bitmap_font_still_labels(monkeypatch):
    import OpenImageIO as oiio

    monkeypatch.setattr(oiio.ImageBufAlgo, "render_text", lambda *a, **k: False)
    sheet = contact.contact_sheet(_frames(2), ["element 0°", "light 90°"], "fallback", 2)
    title = sheet[: max(16, 24 // 5)]
    assert (title > 0.5).any()
    assert contact.bitmap_text("°", 2).shape == (10, 8)


def test_contact_sheet_needs_a_label_per_frame():
    with pytest.raises(contact.ProofImageError, match="one label per frame"):
        contact.contact_sheet(_frames(2), ["only one"], "t", 2)


def test_images_are_written_whole_or_not_at_all(tmp_path):
    path = contact.write_png(np.full((4, 4, 3), 0.5), tmp_path / "a.png")
    assert path.is_file() and [p.name for p in tmp_path.iterdir()] == ["a.png"]
    with pytest.raises(contact.ProofImageError, match="cannot (write|create folder)"):
        contact.write_exr(np.zeros((4, 4, 3)), tmp_path / "a.png" / "b.exr")
    assert [p.name for p in tmp_path.iterdir()] == ["a.png"]  # nothing half-written


def test_proof_images_keep_their_pixels_whatever_the_compression(tmp_path):
    """PNG and EXR compression change bytes, never pixels: both read back as written."""
    import OpenImageIO as oiio

    rng = np.random.default_rng(3)
    display = rng.random((12, 20, 3))
    png = oiio.ImageBuf(str(contact.write_png(display, tmp_path / "a.png")))
    assert np.array_equal(png.get_pixels(oiio.UINT8), tonemap.to_8bit(display))
    linear = (rng.random((12, 20, 3)) * 50.0).astype(np.float32)
    exr = oiio.ImageBuf(str(contact.write_exr(linear, tmp_path / "a.exr")))
    assert np.array_equal(exr.get_pixels(oiio.FLOAT), linear)
    assert exr.spec().get_string_attribute("compression") == "zip"


# -- shader ball ---------------------------------------------------------------------------
def test_cup_mesh_is_oriented_unit_normalled_and_rests_on_the_ground():
    m = shaderball.cup_mesh(segments=32, samples=16)
    p = m.positions.astype(np.float64)
    f = m.faces
    face_n = np.cross(p[f[:, 1]] - p[f[:, 0]], p[f[:, 2]] - p[f[:, 0]])
    vertex_n = m.normals[f].mean(axis=1)
    assert np.all(np.einsum("ij,ij->i", face_n, vertex_n) > 0), "winding disagrees with normals"
    assert np.linalg.norm(m.normals, axis=1) == pytest.approx(1.0, abs=1e-6)
    assert p[:, 1].min() == pytest.approx(0.0, abs=1e-3)
    assert m.uvs.min() >= 0.0 and m.uvs.max() <= 1.0


def test_cup_has_convex_and_concave_regions():
    """Outside, normals point away from the sphere centre; inside the bowl, towards it."""
    r, y = shaderball.cup_profile(32)
    m = shaderball.lathe(r, y, 16)
    outward = np.einsum("ij,ij->i", m.normals, m.positions)
    radius = np.linalg.norm(m.positions, axis=1)
    outer, inner = radius > 0.999, radius < 1.0 - shaderball.CUP_WALL + 1e-3
    assert outer.sum() > 100 and inner.sum() > 100
    assert np.all(outward[outer] > 0) and np.all(outward[inner] < 0)


def test_ply_round_trips_through_mitsuba(tmp_path):
    from lookdev.pipeline.variant import use_mitsuba

    use_mitsuba()
    import mitsuba as mi

    m = shaderball.cup_mesh(segments=16, samples=8)
    path = shaderball.write_ply(m, tmp_path / "cup.ply")
    params = mi.traverse(mi.load_dict({"type": "ply", "filename": str(path)}))
    loaded = np.array(params["vertex_positions"]).reshape(-1, 3)
    assert loaded.shape == m.positions.shape and np.allclose(loaded, m.positions, atol=1e-6)
    assert np.array(params["faces"]).size == m.faces.size


def test_a_sheet_title_fits_a_one_frame_sheet_and_draws_no_missing_glyph():
    # "≤" has no glyph in the sheets' font: the sampling label says it in words
    from lookdev.pipeline.proof.batch import _sampling_label
    from lookdev.pipeline.proof.settings import Settings

    label = _sampling_label(Settings())
    assert label == "target noise 0.05, up to 4 spp" and "≤" not in label
    title = f"glass_clear × sky  ({label})  denoised"
    size = contact.fitting_size(title, 42, 480 - 2 * contact.GAP - 2)
    assert 10 <= size < 42  # shrunk to fit 480 px, not cut off
    assert contact.fitting_size("gold", 42, 480) == 42  # a short title keeps its size
