"""The review page people use: players, comparison, raw/denoised, driven in headless Chromium.

The batch is synthetic (manifests as :mod:`lookdev.pipeline.proof.batch` writes them, with
the per-frame fields of issue 16) and every frame a flat colour of its own, so a
screenshot of a player says exactly which frame it shows: cheap and deterministic.
"""

from __future__ import annotations

import json
import os
import time
from pathlib import Path

import numpy as np
import OpenImageIO as oiio
import pytest
from _chromium import PROBLEMS, Page, needs_chromium

from lookdev.pipeline.analysis import report as R
from lookdev.pipeline.analysis import review

HOSTILE = 'chalk <img src=x onerror="console.error(1)"> & "co"'
MATERIALS = ("gold", HOSTILE)
IBLS = ("studio", "sunset")
KINDS = [("element", 0.0), ("element", 180.0), ("light", 0.0), ("light", 180.0)]


def colour(material: int, ibl: int, index: int, denoised: bool) -> tuple[int, int, int]:
    """The flat 8-bit colour of one frame: every frame of the batch differs."""
    return (40 + 50 * index, 60 + 100 * ibl + 30 * denoised, 50 + 120 * material + 40 * denoised)


def _png(path: Path, rgb: tuple[int, int, int]) -> str:
    pixels = np.empty((48, 96, 3), np.uint8)
    pixels[:] = rgb
    buf = oiio.ImageBuf(oiio.ImageSpec(96, 48, 3, oiio.UINT8))
    buf.set_pixels(oiio.ROI(), pixels)
    assert buf.write(str(path)), buf.geterror()
    return path.name


@pytest.fixture
def batch(tmp_path: Path) -> Path:
    """2 materials × 2 IBLs × 4 frames; gold has denoised frames, the other does not."""
    root = tmp_path / "batch"
    for m, material in enumerate(MATERIALS):
        for i, ibl in enumerate(IBLS):
            folder = root / R._slug(material) / ibl
            folder.mkdir(parents=True)
            frames = []
            for k, (kind, angle) in enumerate(KINDS):
                images = {"png": _png(folder / f"frame_{k:03d}.png", colour(m, i, k, False))}
                if material == "gold":
                    images["denoised_png"] = _png(
                        folder / f"frame_{k:03d}_denoised.png", colour(m, i, k, True)
                    )
                frames.append(
                    {
                        "index": k,
                        "kind": kind,
                        "angle": angle,
                        "images": images,
                        "spp": 64 * (k + 1),
                        "noise": 0.02 - 0.001 * k,
                        "noise_target": 0.02,
                        "time_s": 1.5 + k,
                        "stop": "target" if k else "max_spp",
                        "firefly_share": 0.3,
                        "clamp": None,
                    }
                )
            manifest = {"material": material, "ibl": ibl, "filter": "box", "frames": frames}
            (folder / "manifest.json").write_text(json.dumps(manifest))
    info = {
        "material": "gold",
        "model": "disney",
        "parameters": {"metallic": 1.0, "base_color": [1.0, 0.78, 0.34]},
        "source": {"file": "/presets/gold.toml", "extends": [], "citation": "measured"},
        "usd_losses": {"universal": "", "mtlx": "", "ri": "cannot express </script>"},
    }
    (root / "gold" / "material.json").write_text(json.dumps(info))
    return root


def test_page_data_carries_every_frame_field_and_degrades_without_them(batch, tmp_path):
    entries = R.read_manifests(batch)
    data = review.page_data(batch, entries, lambda p: p, {})
    gold = next(p for p in data["proofs"] if p["id"] == "gold/studio")
    assert gold["filter"] == "box" and len(gold["frames"]) == 4
    f = gold["frames"][1]
    assert {k: f[k] for k in review.FRAME_FIELDS} == {
        "spp": 128,
        "noise": 0.019,
        "noise_target": 0.02,
        "time_s": 2.5,
        "stop": "target",
        "firefly_share": 0.3,
        "clamp": None,
    }
    assert f["denoised"].endswith("frame_001_denoised.png")
    assert data["materials"][HOSTILE] is None  # not recorded: the page says so
    # an old manifest (format 1 names, no new fields): values found, the rest null
    old = tmp_path / "old" / "m" / "sky"
    old.mkdir(parents=True)
    _png(old / "frame_000.png", (1, 2, 3))
    doc = {
        "material": "m",
        "ibl": "sky",
        "settings": {"spp": 32},
        "frames": [
            {"index": 0, "png": {"file": "frame_000.png"}, "seconds": 0.7, "noise_relative": 0.5}
        ],
    }
    (old / "manifest.json").write_text(json.dumps(doc))
    (frame,) = review.page_data(
        old.parent.parent, R.read_manifests(old.parent.parent), lambda p: p, {}
    )["proofs"][0]["frames"]
    assert (frame["spp"], frame["noise"], frame["time_s"]) == (32, 0.5, 0.7)
    assert frame["stop"] is None and frame["denoised"] is None


def test_names_cannot_break_out_of_the_pages_json():
    text = review.data_script({"name": "</script><script>alert(1)</script> & \u2028"})
    assert text.count("</script>") == 1 and "<script>alert" not in text
    inner = text.split(">", 1)[1].rsplit("</script>", 1)[0]
    assert json.loads(inner)["name"].startswith("</script>")


def _wait(page: Page, expression: str, timeout: float = 10.0) -> None:
    deadline = time.monotonic() + timeout
    while not page.js(expression):
        if time.monotonic() > deadline:
            raise AssertionError(f"timed out waiting for {expression}")
        time.sleep(0.05)


def _shown(page: Page, selector: str) -> tuple[int, int, int]:
    """The colour at the centre of the image ``selector`` as Chromium paints it."""
    _wait(
        page,
        "(i => i.getAttribute('src') === i.dataset.want && i.complete && i.naturalWidth > 0)"
        f"(document.querySelector({selector!r}))",
    )
    shot = page.screenshot(selector)
    path = Path(os.environ.get("TMPDIR", "/tmp")) / f"lookdev-shot-{os.getpid()}.png"
    path.write_bytes(shot)
    buf = oiio.ImageBuf(str(path))
    pixels = buf.get_pixels(oiio.UINT8)
    path.unlink()
    h, w = pixels.shape[:2]
    return tuple(int(c) for c in pixels[h // 2, w // 2, :3])


def _close(a, b, tol=3) -> bool:
    return all(abs(x - y) <= tol for x, y in zip(a, b, strict=True))


PLAYER = '.player[data-proof="gold/studio"]'
OTHER = f".player[data-proof={json.dumps(HOSTILE + '/studio')}]"


@pytest.mark.slow
@needs_chromium
def test_review_page_plays_scrubs_toggles_and_compares(batch, tmp_path):
    index = R.write_report(batch, plots=False)
    shots = Path(os.environ.get("LOOKDEV_SCREENSHOTS", tmp_path / "shots"))
    shots.mkdir(parents=True, exist_ok=True)
    with Page(index.as_uri(), tmp_path / "profile") as page:
        assert page.js("document.querySelectorAll('.player').length") == 4
        assert page.js("document.querySelectorAll('#compare-grid figure').length") == 2
        # names are text, never markup
        assert page.js("document.querySelectorAll('img[src=\"x\"]').length") == 0
        headings = page.js("[...document.querySelectorAll('.material h2')].map(h => h.textContent)")
        assert headings == sorted(MATERIALS)  # the batch order: by name
        img = f"{PLAYER} img.frame"
        page.js(f"document.querySelector('{PLAYER}').scrollIntoView()")  # players load when seen
        # a denoised batch opens on its denoised frames; the rest starts from the raw ones
        assert page.js("document.querySelector('#denoised').checked") is True
        assert _close(_shown(page, img), colour(0, 0, 0, True))
        page.js("document.querySelector('#denoised').click()")
        assert _close(_shown(page, img), colour(0, 0, 0, False))
        (shots / "player.png").write_bytes(page.screenshot(PLAYER))

        # scrub to the light turn's first frame
        page.js(
            f"(s => {{ s.value = 2; s.dispatchEvent(new Event('input')); }})"
            f"(document.querySelector('{PLAYER} .scrub'))"
        )
        assert _close(_shown(page, img), colour(0, 0, 2, False))
        label = page.js(f"document.querySelector('{PLAYER} .label').textContent")
        assert label.startswith("light 0°")
        stats = page.js(f"document.querySelector('{PLAYER} .stats').textContent")
        assert stats == "Converged: noise 1.8 % (target 2 %), 192 samples per pixel, 3.5 s."

        # play: the frame advances; pause: it stays
        page.js(f"document.querySelector('{PLAYER} .play').click()")
        _wait(page, f"document.querySelector('{PLAYER} .scrub').value != '2'")
        page.js(f"document.querySelector('{PLAYER} .play').click()")
        held = page.js(f"document.querySelector('{PLAYER} .scrub').value")
        time.sleep(0.5)
        assert page.js(f"document.querySelector('{PLAYER} .scrub').value") == held
        # the light turn alone
        page.js(
            f"(s => {{ s.value = 'light'; s.dispatchEvent(new Event('change')); }})"
            f"(document.querySelector('{PLAYER} .segment'))"
        )
        assert page.js(f"document.querySelector('{PLAYER} .scrub').value") == "2"

        # raw → denoised where the proof has it; the other material stays raw, and says so
        page.js("document.querySelector('#denoised').click()")
        assert _close(_shown(page, img), colour(0, 0, 2, True))
        assert page.js(f"document.querySelector('{PLAYER} .which').textContent") == "denoised"
        assert page.js(f"document.querySelector({OTHER!r} + ' .which').textContent") == "raw"
        page.js("document.querySelector('#denoised').click()")
        assert _close(_shown(page, img), colour(0, 0, 2, False))

        # comparison: one material under every IBL, synchronised
        page.js(
            "(s => { s.value = 'material'; s.dispatchEvent(new Event('change')); })"
            "(document.querySelector('#compare-mode'))"
        )
        page.js(
            "(s => { s.value = 'gold'; s.dispatchEvent(new Event('change')); })"
            "(document.querySelector('#compare-pick'))"
        )
        captions = page.js(
            "[...document.querySelectorAll('#compare-grid figcaption')].map(c => c.textContent)"
        )
        assert captions == list(IBLS)
        page.js(
            "(s => { s.value = 3; s.dispatchEvent(new Event('input')); })"
            "(document.querySelector('#compare-scrub'))"
        )
        for i, ibl in enumerate(IBLS):
            cell = f'#compare-grid figure[data-proof="gold/{ibl}"] img'
            assert _close(_shown(page, cell), colour(0, i, 3, False))
        page.js("document.querySelector('#compare-play').click()")
        _wait(page, "document.querySelector('#compare-scrub').value != '3'")
        page.js("document.querySelector('#compare-play').click()")
        (shots / "comparison.png").write_bytes(page.screenshot("#compare"))
        # all materials under one IBL again
        page.js(
            "(s => { s.value = 'ibl'; s.dispatchEvent(new Event('change')); })"
            "(document.querySelector('#compare-mode'))"
        )
        captions = page.js(
            "[...document.querySelectorAll('#compare-grid figcaption')].map(c => c.textContent)"
        )
        assert captions == sorted(MATERIALS)
        info = page.js("document.querySelector('.material .losses').textContent")
        assert "ri: cannot express </script>" in info
        none = page.js("document.querySelectorAll('.material')[0].textContent")
        assert "not recorded by this batch" in none
        (shots / "page.png").write_bytes(page.screenshot())
        seen = page.problems()
    for problem in PROBLEMS:
        assert not seen[problem], (problem, seen[problem])


@needs_chromium
def test_review_page_speaks_plainly_filters_and_loads_players_when_seen(batch, tmp_path):
    index = R.write_report(batch, plots=False)
    header = index.read_text().split("<p>", 1)[1].split("</p>", 1)[0]
    assert header.startswith("2 materials, each under 2 IBLs (4 proofs). Materials: ")
    assert header.endswith("IBLs: studio, sunset.")
    with Page(index.as_uri(), tmp_path / "profile") as page:
        # the first frame did not converge: it says so, and why
        first = page.js(f"document.querySelector('{PLAYER} .stats').textContent")
        assert first == (
            "Not converged: noise 2 % (target 2 %) at the sample cap, 64 samples per pixel, 1.5 s."
        )
        detail = page.js(f"document.querySelector('{PLAYER} details.more').open")
        assert detail is False  # the numbers behind it wait behind "details"
        text = page.js(f"document.querySelector('{PLAYER} .detail').textContent")
        assert "0.1 % of pixels hold 30 %" in text and "not clamped" in text
        what = page.js(f"document.querySelector('{PLAYER} .what').textContent")
        assert what == "Turntable: 2 frames turning the object, 2 turning the light"
        # players below the fold have fetched nothing yet; scrolled to, they load
        tops = page.js(
            "[...document.querySelectorAll('.player')].map(p => "
            "[p.getBoundingClientRect().top > innerHeight + 200, "
            "p.querySelector('img.frame').getAttribute('src') !== null])"
        )
        assert tops[-1][0], "the test batch must reach below the fold"
        assert all(below != loaded for below, loaded in tops), tops
        last = "document.querySelectorAll('.player')[3]"
        assert page.js(f"{last}.querySelector('img.frame').getAttribute('src')") is None
        page.js(f"{last}.scrollIntoView()")
        _wait(page, f"{last}.querySelector('img.frame').getAttribute('src') !== null")
        # the table of contents links every material; the filter hides the others
        links = page.js("[...document.querySelectorAll('#toc a')].map(a => a.textContent)")
        assert links == sorted(MATERIALS)
        page.js(
            "(f => { f.value = 'GOL'; f.dispatchEvent(new Event('input')); })"
            "(document.querySelector('#filter'))"
        )
        visible = page.js(
            "[...document.querySelectorAll('.material')].filter(s => !s.hidden)"
            ".map(s => s.dataset.material)"
        )
        assert visible == ["gold"]
        assert page.js("document.querySelector('#filter-count').textContent") == (
            "1 of 2 materials"
        )
        page.js(
            "(f => { f.value = ''; f.dispatchEvent(new Event('input')); })"
            "(document.querySelector('#filter'))"
        )
        assert (
            page.js("[...document.querySelectorAll('.material')].filter(s => s.hidden).length") == 0
        )
        seen = page.problems()
    for problem in PROBLEMS:
        assert not seen[problem], (problem, seen[problem])
