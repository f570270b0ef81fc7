"""The designer as a process and a server: it prints its URL, stops cleanly on Ctrl-C,
and keeps serving when a page goes away in the middle of a frame."""

from __future__ import annotations

import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

pytestmark = pytest.mark.slow


def test_ctrl_c_stops_it_cleanly(user_library):
    p = subprocess.Popen(
        [
            str(Path(sys.executable).with_name("lookdev")),
            "designer",
            "gold",
            "-L",
            str(user_library),
        ],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        line = p.stdout.readline()
        assert line.startswith("lookdev designer: http://127.0.0.1:"), line
        time.sleep(0.5)
        p.send_signal(signal.SIGINT)
        _, err = p.communicate(timeout=60)
    finally:
        if p.poll() is None:
            p.kill()
    assert p.returncode == 0, err
    assert "Traceback" not in err
    assert list(user_library.iterdir()) == []


def _frame(ws) -> dict:
    """The next frame's metadata (its JPEG follows), skipping other news."""
    while True:
        message = ws.receive_json()
        if message["type"] == "frame":
            data = ws.receive_bytes()
            assert data[:2] == b"\xff\xd8"  # a JPEG
            return message


def test_a_page_leaving_mid_render_does_not_stop_the_server(client, designer):
    t = designer.token
    with client.websocket_connect(f"ws://127.0.0.1:{designer.port}/{t}/ws") as ws:
        first = _frame(ws)
        assert first["view"] == "A" and first["spp"] >= 1
        ws.send_json({"rotate_ibl": 45.0})
    # gone mid-refinement; an edit arrives with nobody watching
    op = {"op": "set", "target": None, "field": "roughness", "value": 0.5}
    assert client.post(f"/{t}/api/edit", json=op).status_code == 200
    with client.websocket_connect(f"ws://127.0.0.1:{designer.port}/{t}/ws") as ws:
        assert _frame(ws)["view"] == "A"
    assert designer.renderer.error is None


def test_two_tabs_hear_of_each_others_edits(client, designer):
    t = designer.token
    with (
        client.websocket_connect(f"ws://127.0.0.1:{designer.port}/{t}/ws") as a,
        client.websocket_connect(f"ws://127.0.0.1:{designer.port}/{t}/ws") as b,
    ):
        _frame(a), _frame(b)
        op = {"op": "set", "target": None, "field": "metallic", "value": 0.5}
        version = client.post(f"/{t}/api/edit", json=op).json()["version"]
        for ws in (a, b):
            while (m := ws.receive_json())["type"] != "state":
                if m["type"] == "frame":
                    ws.receive_bytes()
            assert m["version"] == version


def test_bad_view_messages_are_dropped():
    from lookdev.pipeline.designer.routes import view_changes

    assert view_changes({"rotate_ibl": float("nan"), "mode": "evil", "size": [1, 99999]}) == {
        "size": (16, 1920)
    }
    assert view_changes({"exposure": 99, "ab": True, "raw": "yes"}) == {
        "exposure": 16.0,
        "ab": True,
    }


def test_ab_split_renders_the_reference_beside(client, designer):
    t = designer.token
    with client.websocket_connect(f"ws://127.0.0.1:{designer.port}/{t}/ws") as ws:
        _frame(ws)
        ws.send_json({"ab": True, "ab_against": "parent"})
        views = set()
        while views != {"A", "B"}:
            views.add(_frame(ws)["view"])
    assert designer.ab_against == "parent" and designer.renderer.view["ab"]


def test_from_python_without_blocking(user_library, capsys):
    import httpx

    import lookdev

    handle = lookdev.designer("gold", library=user_library, block=False, size=(32, 18))
    try:
        assert capsys.readouterr().out.strip() == f"lookdev designer: {handle.url}"
        assert handle.url in handle._repr_html_()
        assert httpx.get(handle.url + "api/state").json()["name"] == "gold"
        assert httpx.get(handle.url.rsplit("/", 2)[0] + "/api/state").status_code == 403
    finally:
        handle.stop()
    with pytest.raises(httpx.ConnectError):
        httpx.get(handle.url + "api/state", timeout=2)


@pytest.mark.render
def test_the_mode_switch_and_the_raw_toggle(client, designer):
    t = designer.token
    with client.websocket_connect(f"ws://127.0.0.1:{designer.port}/{t}/ws") as ws:
        assert _frame(ws)["mode"] == "designer"
        ws.send_json({"mode": "truth", "raw": True})
        while (m := _frame(ws))["mode"] != "truth":
            pass
        assert not m["denoised"]  # raw: the frame before denoising, whatever the engine did
    assert designer.renderer.view["mode"] == "truth" and designer.renderer.view["raw"]


def test_two_tabs_connecting_at_once_start_one_renderer(designer):
    import threading

    before = {t for t in threading.enumerate() if t.name == "designer-render"}
    start = threading.Barrier(4)

    def connect() -> None:
        start.wait()
        designer.ensure_renderer()

    tabs = [threading.Thread(target=connect) for _ in range(4)]
    for t in tabs:
        t.start()
    for t in tabs:
        t.join()
    started = {t for t in threading.enumerate() if t.name == "designer-render"} - before
    assert len(started) == 1


def test_frames_say_which_edit_they_show(client, designer):
    t = designer.token
    with client.websocket_connect(f"ws://127.0.0.1:{designer.port}/{t}/ws") as ws:
        assert _frame(ws)["version"] == designer.session.version
        op = {"op": "set", "target": None, "field": "roughness", "value": 0.7}
        version = client.post(f"/{t}/api/edit", json=op).json()["version"]
        while (seen := _frame(ws)["version"]) < version:
            assert seen < version
        assert seen == version
