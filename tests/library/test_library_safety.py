"""Saves survive SIGKILL mid-write, and two processes writing one library lose nothing."""

from __future__ import annotations

import os
import signal
import subprocess
import textwrap
import time

import pytest
from _processes import spawn
from _processes import wait_for as wait

from lookdev.library import Library, PresetFile
from lookdev.library.store import PAUSE_ENV

pytestmark = pytest.mark.skipif(os.name != "posix", reason="SIGKILL and fork semantics")

CLI = "import sys; from lookdev.pipeline.cli import main; main(sys.argv[1:])"


def start(code: str, *args: str, pause: float | None = None) -> subprocess.Popen:
    return spawn(code, *args, env_extra=None if pause is None else {PAUSE_ENV: str(pause)})


def wait_for(predicate, proc: subprocess.Popen, timeout: float = 60.0) -> None:
    wait(predicate, proc, timeout)


@pytest.mark.slow
def test_sigkill_in_the_middle_of_a_save_leaves_the_old_file(tmp_path):
    lib = Library([tmp_path], use_env=False)
    target = lib.save(PresetFile(name="mine", extends="gold", params={"roughness": 0.3}))
    old = target.read_bytes()
    # `presets set` pauses after writing and fsyncing the temporary file, before the rename.
    proc = start(CLI, "presets", "set", "mine", "roughness=0.9", "-L", str(tmp_path), pause=60)

    def new_bytes_are_on_disk() -> bool:
        tmps = list(tmp_path.glob(".mine.toml.*.tmp.toml"))
        return bool(tmps) and b"roughness = 0.9" in tmps[0].read_bytes()

    wait_for(new_bytes_are_on_disk, proc)
    proc.send_signal(signal.SIGKILL)
    proc.wait(timeout=30)
    assert proc.returncode == -signal.SIGKILL
    assert target.read_bytes() == old
    assert lib.load("mine").params.roughness == 0.3
    # The stale temporary is invisible, and the dead process's lock does not block.
    assert lib.names().count("mine") == 1 and "mine" in lib.names()
    assert list(tmp_path.glob(".mine.toml.*.tmp.toml"))
    lib.update("mine", {"roughness": 0.5})
    assert lib.load("mine").params.roughness == 0.5
    assert not list(tmp_path.glob(".mine.toml.*.tmp.toml"))  # the next locked write cleans up


KEYS = {
    "a": ["roughness", "metallic", "specular_tint", "anisotropic", "sheen", "sheen_tint"],
    "b": ["subsurface", "spec_trans", "diff_trans", "flatness", "clearcoat", "sheen_roughness"],
}
WRITER = f"KEYS = {KEYS!r}\n" + textwrap.dedent(
    """
    import sys, time
    from pathlib import Path
    from lookdev.library import Library, LibraryError, PresetFile

    folder, tag, go = Path(sys.argv[1]), sys.argv[2], Path(sys.argv[3])
    lib = Library([folder], use_env=False)
    while not go.exists():
        time.sleep(0.005)
    keys = KEYS[tag]
    for i, key in enumerate(keys):
        lib.save(PresetFile(name=f"{tag}{i}", extends="gold", params={"roughness": i / 10}))
        # Read-modify-write of one shared preset: each round sets one more key.
        lib.update("shared", {key: 0.5})
    try:
        lib.save(PresetFile(name="dup", extends="gold", params={"roughness": 0.1}))
        print("saved dup")
    except LibraryError as exc:
        print("refused dup:", exc)
    """
)


@pytest.mark.slow
def test_two_processes_saving_into_one_library_lose_nothing(tmp_path):
    lib = Library([tmp_path], use_env=False)
    lib.save(PresetFile(name="shared", extends="gold"))
    go = tmp_path.parent / f"{tmp_path.name}.go"
    # A short pause inside each write widens the window a missing lock would lose data in.
    procs = [start(WRITER, str(tmp_path), tag, str(go), pause=0.02) for tag in "ab"]
    time.sleep(0.5)
    go.touch()
    outs = [p.communicate(timeout=120) for p in procs]
    assert all(p.returncode == 0 for p in procs), outs
    names = set(lib.names())
    assert {f"{t}{i}" for t, keys in KEYS.items() for i in range(len(keys))} <= names
    shared = lib.load("shared").params
    assert all(getattr(shared, k) == 0.5 for k in KEYS["a"] + KEYS["b"])  # no edit lost
    # The same new name from both: exactly one wins, the other is refused, never clobbered.
    verdicts = sorted(out.strip().split(":")[0] for out, _ in outs)
    assert verdicts == ["refused dup", "saved dup"], outs
    assert not list(tmp_path.glob(".*.tmp*"))


FLIPPER = textwrap.dedent(
    """
    import sys
    from lookdev.library import Library

    lib = Library([sys.argv[1]], use_env=False)
    for i in range(40):
        lib.update("mine", {"roughness": (0.1, 0.9)[i % 2], "description": "x" * (i * 50)})
    """
)


@pytest.mark.slow
def test_readers_never_see_a_half_written_preset(tmp_path):
    lib = Library([tmp_path], use_env=False)
    lib.save(PresetFile(name="mine", extends="gold", params={"roughness": 0.5}))
    proc = start(FLIPPER, str(tmp_path))
    seen = set()
    while proc.poll() is None:
        seen.add(lib.load("mine").params.roughness)  # raises on a torn file
    assert proc.returncode == 0, proc.communicate()
    assert seen <= {0.1, 0.5, 0.9} and len(seen) >= 2
