"""Proof pieces: the view transform, contact sheets, the shader ball and the turntable."""

from __future__ import annotations

import doctest
import importlib

import colour as colour_science
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from lookdev.pipeline.proof import contact, shaderball, tonemap

MODULES = ["ibl", "tonemap", "contact", "shaderball", "turntable", "batch"]


@pytest.mark.parametrize("name", MODULES)
def test_doctests(name, tmp_path, monkeypatch):
    monkeypatch.setenv("LOOKDEV_CACHE", str(tmp_path))
    module = importlib.import_module(f"lookdev.pipeline.proof.{name}")
    assert doctest.testmod(module).failed == 0


# -- view transform ------------------------------------------------------------------------
def _decode(srgb: np.ndarray) -> np.ndarray:
    """Inverse sRGB OETF, to read the view transform's linear output back."""
    return np.where(srgb <= 0.04045, srgb / 12.92, ((srgb + 0.055) / 1.055) ** 2.4)


channel = st.floats(0.0, 1e4, allow_nan=False)


@pytest.mark.slow
@settings(max_examples=200, deadline=None)
@given(st.tuples(channel, channel, channel), st.floats(-4.0, 4.0))
def test_view_keeps_hue_and_never_clips(rgb, exposure):
    rgb = np.array(rgb)
    out = _decode(tonemap.view(rgb, exposure))
    assert out.max() <= 1.0 + 1e-12
    m = rgb.max()
    if m > 1e-6:  # the channel ratios (hue, saturation) survive exactly
        assert out / out.max() == pytest.approx(rgb / m, abs=1e-9)


def test_view_is_the_identity_below_the_knee_and_rolls_off_above():
    x = np.array([0.0, 0.1, tonemap.DEFAULT_KNEE])
    assert tonemap.shoulder(x) == pytest.approx(x)
    h = 1e-6  # C¹ at the knee: the shoulder leaves with slope 1
    slope = (tonemap.shoulder(tonemap.DEFAULT_KNEE + h) - tonemap.DEFAULT_KNEE) / h
    assert slope == pytest.approx(1.0, rel=1e-4)
    big = tonemap.shoulder(np.array([1.0, 10.0, 1e3, 1e30]))
    assert np.all(np.diff(big) >= 0) and big.max() <= 1.0 and big[-1] == pytest.approx(1.0)


def srgb_encode(v):
    """IEC 61966-2-1 encoding, from colour-science (an independent implementation)."""
    return colour_science.models.eotf_inverse_sRGB(np.clip(np.asarray(v, np.float64), 0, 1))


def test_a_hot_saturated_highlight_stays_saturated():
    """Burley §6.2: clipping "forces the core to always go to white"; this must not."""
    hot_red = np.array([200.0, 20.0, 2.0])
    clipped = srgb_encode(np.clip(hot_red, 0, 1))
    viewed = tonemap.view(hot_red)
    assert clipped.min() == pytest.approx(1.0)  # clipping: white
    assert viewed[0] > 0.99 and viewed[2] < 0.5  # ours: still red


@pytest.mark.parametrize(
    ("grey", "shown"),
    [
        (0.0, 0.0),  # black stays black
        (0.5, srgb_encode(0.5)),  # below the knee: the sRGB encoding alone
        (1.0, srgb_encode(float(tonemap.shoulder(1.0)))),  # 1 rolls off: no clipping
        (1e30, srgb_encode(1.0)),  # huge: tends to white, never above it
        (-3.0, 0.0),  # negative: black
        (float("nan"), 0.0),  # NaN: black, not NaN
    ],
)
def test_view_at_its_edges(grey, shown):
    out = tonemap.view(np.full((1, 3), grey))
    assert np.isfinite(out).all()
    np.testing.assert_allclose(out, np.full((1, 3), shown), atol=2e-7)  # OCIO: float32


def test_view_survives_nan_inf_and_negative_pixels():
    out = tonemap.view(np.array([[np.nan, 1.0, 0.5], [np.inf, -1.0, 0.0], [0.0, 0.0, 0.0]]))
    assert np.isfinite(out).all() and out.min() >= 0.0 and out.max() <= 1.0


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
    with pytest.raises(contact.ProofImageError, match="cannot write"):
        contact.write_exr(np.zeros((4, 4, 3)), tmp_path / "a.png" / "b.exr")


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
