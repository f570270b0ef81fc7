"""The designer's server refuses what is not its own page: no token, a foreign Origin or
Host, paths out of its folders; and writes nothing when it refuses."""

from __future__ import annotations

import os

import pytest
from _designer import snapshot
from starlette.websockets import WebSocketDisconnect

from lookdev.pipeline.designer.guard import Guard, PathRefused, Roots

SAVE = {"mode": "new", "name": "stolen"}


def test_binds_to_loopback_only(designer):
    assert designer.url.startswith(f"http://127.0.0.1:{designer.port}/{designer.token}/")
    from lookdev.pipeline.designer import server

    assert server.HOST == "127.0.0.1"


def test_the_token_is_fresh_and_long(designer, user_library):
    from lookdev.library import Library
    from lookdev.pipeline.designer.server import Designer

    other = Designer(library=Library([user_library], use_env=False))
    try:
        assert other.token != designer.token and len(designer.token) >= 20
    finally:
        other.close()


@pytest.mark.parametrize(
    "path", ["/", "/api/state", "/api/library", "/files/session/x", "/static/designer.js"]
)
def test_no_token_no_page(client, path):
    r = client.get(path)
    assert r.status_code == 403 and "token" in r.text


def test_a_wrong_token_is_refused(client, designer, user_library, tmp_path):
    before = snapshot(user_library, tmp_path / "session")
    wrong = designer.token[:-1] + ("A" if designer.token[-1] != "A" else "B")
    assert client.get(f"/{wrong}/api/state").status_code == 403
    assert client.post(f"/{wrong}/api/save", json=SAVE).status_code == 403
    assert (
        client.post("/api/save", json=SAVE, headers={"x-lookdev-token": wrong}).status_code == 403
    )
    assert snapshot(user_library, tmp_path / "session") == before


def test_the_token_opens_the_page(client, designer):
    assert client.get(f"/{designer.token}/").status_code == 200
    assert client.get(f"/{designer.token}/static/designer.js").status_code == 200
    r = client.get("/api/state", headers={"x-lookdev-token": designer.token})
    assert r.status_code == 200 and r.json()["name"] == "gold"


def test_a_foreign_origin_cannot_write(client, designer, user_library, tmp_path):
    before = snapshot(user_library, tmp_path / "session")
    t = designer.token
    for origin in ("http://evil.example", f"http://127.0.0.1:{designer.port + 1}", "null"):
        h = {"origin": origin}
        assert client.post(f"/{t}/api/save", json=SAVE, headers=h).status_code == 403
        op = {"op": "set", "target": None, "field": "roughness", "value": 0.9}
        assert client.post(f"/{t}/api/edit", json=op, headers=h).status_code == 403
    assert snapshot(user_library, tmp_path / "session") == before
    assert designer.session.doc["params"]["roughness"] == 0.2  # gold's, untouched
    own = {"origin": f"http://127.0.0.1:{designer.port}"}
    assert client.get(f"/{t}/api/state", headers=own).status_code == 200


@pytest.mark.parametrize(
    "host", ["evil.example:{port}", "127.0.0.1:{other}", "localhost.evil.example:{port}", ""]
)
def test_a_foreign_host_is_refused(client, designer, user_library, host):
    """DNS rebinding: the attacker's name resolves to 127.0.0.1, its Host header stays."""
    h = {"host": host.format(port=designer.port, other=designer.port + 1)}
    before = snapshot(user_library)
    assert client.get(f"/{designer.token}/api/state", headers=h).status_code == 403
    assert client.post(f"/{designer.token}/api/save", json=SAVE, headers=h).status_code == 403
    assert snapshot(user_library) == before


def test_the_websocket_needs_the_token_and_the_origin(client, designer):
    with pytest.raises(WebSocketDisconnect):
        with client.websocket_connect(f"ws://127.0.0.1:{designer.port}/ws"):
            pass
    with pytest.raises(WebSocketDisconnect):
        with client.websocket_connect(
            f"ws://127.0.0.1:{designer.port}/{designer.token}/ws",
            headers={"origin": "http://evil.example"},
        ):
            pass


TRAVERSALS = [
    "../../../../etc/passwd",
    "..%2F..%2F..%2Fetc%2Fpasswd",
    "%2e%2e/%2e%2e/%2e%2e/etc/passwd",
    "..%252F..%252Fetc%252Fpasswd",
    "/etc/passwd",
    "%2Fetc%2Fpasswd",
    "..\\..\\etc\\passwd",
    "out/passwd",  # a symlink inside the session folder that leads out
]


@pytest.mark.parametrize("path", TRAVERSALS)
def test_files_stay_inside_their_folders(client, designer, path):
    os.symlink("/etc", designer.folder / "out")
    r = client.get(f"/{designer.token}/files/session/{path}")
    assert r.status_code in (403, 422)  # 403: a client normalised the dots away
    assert "root:" not in r.text


@pytest.mark.parametrize("path", ["../../x.png", "/etc/passwd", "a%2F..%2F..%2Fb", "out/hosts"])
def test_a_texture_edit_cannot_point_outside(client, designer, path):
    os.symlink("/etc", designer.folder / "out")
    op = {
        "op": "set",
        "target": None,
        "field": "roughness",
        "value": {"texture": {"root": "session", "path": path}},
    }
    r = client.post(f"/{designer.token}/api/edit", json=op)
    assert r.status_code == 422 and "refused" not in r.json()
    assert designer.session.doc["params"]["roughness"] == 0.2


@pytest.mark.parametrize("name", ["../evil", "/tmp/evil", "a/b", "..", "x%2Fy", ""])
def test_a_save_name_is_a_name(client, designer, user_library, tmp_path, name):
    before = snapshot(user_library, tmp_path)
    r = client.post(f"/{designer.token}/api/save", json={"mode": "new", "name": name})
    assert r.status_code == 422 and "not allowed" in r.json()["error"]
    assert snapshot(user_library, tmp_path) == before


def test_an_unknown_root_is_refused(tmp_path):
    roots = Roots({"session": tmp_path})
    with pytest.raises(PathRefused, match="unknown folder"):
        roots.resolve("library9", "x")
    assert roots.resolve("session", "a/./b") == tmp_path.resolve() / "a" / "b"


def test_guard_compares_the_whole_token():
    g = Guard("abcdef", port=1)
    assert not g.token_ok("abcde") and not g.token_ok("abcdefg") and not g.token_ok(None)
    assert g.check({"host": "127.0.0.1:1"}, "abcdef") is None


@pytest.mark.parametrize("path", TRAVERSALS)
def test_the_file_picker_stays_inside_its_folders(client, designer, path):
    os.symlink("/etc", designer.folder / "out")
    r = client.get(f"/{designer.token}/api/browse", params={"root": "session", "path": path})
    assert r.status_code == 422 and set(r.json()) == {"error"}  # no listing of anything


def test_the_file_picker_lists_only_what_it_may_open(client, designer):
    os.symlink("/etc", designer.folder / "out")
    os.symlink("/etc/hosts", designer.folder / "hosts.png")
    (designer.folder / "exports" / "mask.png").write_bytes(b"")
    r = client.get(f"/{designer.token}/api/browse", params={"root": "session"})
    assert r.status_code == 200
    listing = r.json()
    assert "out" not in listing["dirs"] and "hosts.png" not in listing["files"]
    assert "exports" in listing["dirs"] and listing["up"] is None
    where = {"root": "session", "path": "exports"}
    inner = client.get(f"/{designer.token}/api/browse", params=where)
    assert inner.json()["files"] == ["exports/mask.png"] and inner.json()["up"] == ""
    other = client.get(f"/{designer.token}/api/browse", params={"root": "nowhere"})
    assert other.status_code == 422 and "unknown folder" in other.json()["error"]


@pytest.mark.parametrize("path", ["/etc/passwd", "../../../../etc/passwd", "out/hosts"])
def test_a_typed_path_cannot_point_outside(client, designer, user_library, path):
    """A mask or map path sent as plain text reaches no further than a picked one (a new
    preset's relative paths start from the library it will be saved in)."""
    os.symlink("/etc", user_library / "out")
    t = designer.token
    assert client.post(f"/{t}/api/new_layered", json={"name": "typed"}).status_code == 200
    op = {"op": "layer_add", "preset": "rust", "mask": {"kind": "texture", "path": path}}
    r = client.post(f"/{t}/api/edit", json=op)
    assert r.status_code == 422, r.text
    assert len(designer.session.doc["layers"]) == 1
    op = {"op": "set", "target": 0, "field": "roughness", "value": {"texture": path}}
    r = client.post(f"/{t}/api/edit", json=op)
    assert r.status_code == 422 and "outside" in r.json()["error"], r.text  # no file opened
    assert "roughness" not in designer.session.doc["layers"][0].get("params", {})


def test_a_preview_reads_only_the_document(client, designer):
    t = designer.token
    r = client.get(f"/{t}/api/preview.png", params={"target": "", "field": "roughness"})
    assert r.status_code == 422 and "not driven by a map" in r.json()["error"]
    assert client.post(f"/{t}/api/new_layered", json={"name": "p"}).status_code == 200
    op = {"op": "layer_add", "preset": "rust", "mask": {"kind": "ramp", "axis": "v"}}
    assert client.post(f"/{t}/api/edit", json=op).status_code == 200
    r = client.get(f"/{t}/api/preview.png", params={"target": 1, "field": "mask"})
    assert r.status_code == 200 and r.headers["content-type"] == "image/png"
    r = client.get(f"/{t}/api/preview.png", params={"target": 7, "field": "mask"})
    assert r.status_code == 422
