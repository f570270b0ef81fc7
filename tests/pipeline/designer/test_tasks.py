"""Around the viewport: BRDF views, USD loss notes, Export USD and Proof, each on the
material as edited, written into the session's folder and read back through the server."""

from __future__ import annotations

import time

import pytest


def _edit(client, designer, **op):
    r = client.post(f"/{designer.token}/api/edit", json={"op": "set", "target": None, **op})
    assert r.status_code == 200 and "refused" not in r.json(), r.text
    return r.json()


@pytest.mark.parametrize("view", ["slice", "polar", "albedo"])
def test_brdf_views_of_the_current_parameters(client, designer, view):
    t = designer.token
    before = client.get(f"/{t}/api/plot/{view}.png").content
    _edit(client, designer, field="roughness", value=0.9)
    after = client.get(f"/{t}/api/plot/{view}.png")
    assert after.status_code == 200 and after.content[:8] == b"\x89PNG\r\n\x1a\n"
    assert after.content != before


def test_an_unknown_view_is_one_line(client, designer):
    r = client.get(f"/{designer.token}/api/plot/sphere.png")
    assert r.status_code == 422 and "unknown view" in r.json()["error"]


def test_loss_notes_follow_the_edit(client, designer):
    t = designer.token
    assert set(client.get(f"/{t}/api/losses").json()) == {"universal", "mtlx", "ri"}
    _edit(client, designer, field="sheen", value=1.0)
    assert "sheen" not in client.get(f"/{t}/api/losses").json()["universal"]  # a metal's: dead
    _edit(client, designer, field="metallic", value=0.0)
    _edit(client, designer, field="sheen_model", value="conty_kulla")
    notes = client.get(f"/{t}/api/losses").json()
    assert "sheen=1" in notes["universal"] and "sheen_model=conty_kulla" in notes["ri"]


def test_export_usd_of_the_edited_material(client, designer):
    _edit(client, designer, field="roughness", value=0.45)
    r = client.post(f"/{designer.token}/api/export_usd", json={})
    assert r.status_code == 200, r.text
    usda = client.get(f"/{designer.token}/{r.json()['file']}")
    assert usda.status_code == 200 and b"0.45" in usda.content


@pytest.mark.render
def test_proof_queues_a_batch_and_links_its_review_page(client, designer):
    designer.proof_settings = dict(
        frames=1, light_frames=1, spp=2, resolution=(32, 16), rig="none", denoise=False
    )
    t = designer.token
    task = client.post(f"/{t}/api/proof", json={}).json()
    assert task["state"] in ("queued", "running")
    deadline = time.monotonic() + 600
    while (s := client.get(f"/{t}/api/task/{task['id']}").json())["state"] not in (
        "done",
        "failed",
    ):
        assert time.monotonic() < deadline
        time.sleep(1)
    assert s["state"] == "done", s
    page = client.get(f"/{t}/{s['page']}")
    assert page.status_code == 200 and b"gold" in page.content
