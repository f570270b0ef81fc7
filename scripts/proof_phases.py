# ruff: noqa: E402  (imports are timed: they come after the clock starts)
"""Where a proof batch's time goes: each phase's own (self) wall and CPU seconds.

    python scripts/proof_phases.py OUT [PRESET ...] -- IBL ...

Runs ``lookdev.proof(..., report=True)`` in this one process (an inline executor, so
the worker's phases can be timed: the process pool's start is not included) with every
phase's function wrapped by a timer; a phase called inside another is subtracted from
it. Work on another thread is listed as ``[thread]``: its CPU seconds are the process's
while it ran, so they overlap the main thread's. ``PHASE_KW`` (JSON) adds keyword
arguments (``{"frames": 1}``). Used for docs/measurements/proof-cost.md.
"""

import json
import os
import sys
import threading
import time
from collections import defaultdict

__all__ = []

T0, C0 = time.perf_counter(), time.process_time()

acc = defaultdict(lambda: [0.0, 0.0, 0])
local = threading.local()
lock = threading.Lock()


def _stack():
    s = getattr(local, "stack", None)
    if s is None:
        s = local.stack = []
    return s


def timed(phase_of, fn):
    def w(*a, **k):
        phase = phase_of(a, k) if callable(phase_of) else phase_of
        st = _stack()
        st.append([0.0, 0.0])
        t, c = time.perf_counter(), time.process_time()
        try:
            return fn(*a, **k)
        finally:
            dt, dc = time.perf_counter() - t, time.process_time() - c
            child = st.pop()
            if st:
                st[-1][0] += dt
                st[-1][1] += dc
            tag = (
                phase
                if threading.current_thread() is threading.main_thread()
                else phase + " [thread]"
            )
            with lock:
                e = acc[tag]
                e[0] += dt - child[0]
                e[1] += dc - child[1]
                e[2] += 1

    w.__wrapped__ = fn
    return w


def patch(mod, name, phase):
    setattr(mod, name, timed(phase, getattr(mod, name)))


t = time.perf_counter()
c = time.process_time()

import lookdev.pipeline.api as api
from lookdev.pipeline.analysis import report
from lookdev.pipeline.proof import (
    batch,
    contact,
    denoise,
    material_info,
    passes,
    tonemap,
    turntable,
)
from lookdev.pipeline.variant import use_mitsuba

use_mitsuba()

acc["imports + variant"] = [time.perf_counter() - t, time.process_time() - c, 1]

first = {"v": True}
orig_init = turntable.Turntable.__init__


def init(self, *a, **k):
    first["v"] = True
    return orig_init(self, *a, **k)


turntable.Turntable.__init__ = timed("scene load (Turntable)", init)
patch(turntable, "material_bsdf", "scene load (bsdf dict)")
patch(turntable, "material_interior", "scene load (bsdf dict)")


def rphase(a, k):
    if first["v"]:
        first["v"] = False
        return "render (first frame of a job)"
    return "render (other frames)"


patch(passes, "render_frame", rphase)
patch(denoise, "guide_renderer", "guides (renderer setup)")
denoise.GuideRenderer.render = timed("guides (aov render)", denoise.GuideRenderer.render)
patch(denoise, "denoise", "OIDN")
patch(contact, "write_exr", "EXR writes")
patch(contact, "write_png", "PNG writes")
patch(tonemap, "view", "view transform")
patch(contact, "file_entry", "hashing (file_entry)")
batch.file_entry = contact.file_entry  # noqa
patch(batch, "write_json", "manifest writes")
orig_rm = batch.read_manifest


def rm(*a, **k):
    first["v"] = True
    return orig_rm(*a, **k)


batch.read_manifest = timed("manifest reads", rm)
patch(batch, "_sheet", "contact sheets")
patch(contact, "read_rgb", "PNG reads (sheets, overview)")
patch(contact, "draw_text", "sheet text")
patch(batch, "overview", "overview.png")
patch(batch, "_remove_strays", "manifest writes")
patch(material_info, "write_material_info", "material.json")
patch(report, "write_report", "review page")
patch(report, "material_plots", "review page (plots)")
import lookdev.pipeline.api.proofs as api_proofs

patch(api_proofs, "hub", "load + blend materials")
from lookdev.pipeline.proof import ibl as iblmod

patch(iblmod, "load", "load IBLs")

from concurrent.futures import Executor, Future


class Inline(Executor):
    def submit(self, fn, *a, **k):
        f = Future()
        try:
            f.set_result(fn(*a, **k))
        except BaseException as e:
            f.set_exception(e)
        return f


argv = sys.argv[1:]
out = argv[0]
i = argv.index("--")
presets, ibls = argv[1:i], argv[i + 1 :]
t1, c1 = time.perf_counter(), time.process_time()
extra = json.loads(os.environ.get("PHASE_KW", "{}"))
doc = api.proof(presets, ibls, out, executor=Inline(), report=True, **extra)
wall, cpu = time.perf_counter() - T0, time.process_time() - C0
import glob

render = sum(
    f["time_s"] for m in glob.glob(out + "/*/*/manifest.json") for f in json.load(open(m))["frames"]
)
total_self = sum(v[0] for v in acc.values())
rows = sorted(acc.items(), key=lambda kv: -kv[1][0])
print(f"{'phase':40s} {'wall s':>8s} {'cpu s':>8s} {'calls':>6s} {'share':>6s}")
for k, (w_, c_, n) in rows:
    print(f"{k:40s} {w_:8.2f} {c_:8.2f} {n:6d} {100 * w_ / wall:5.1f}%")
print(f"{'(unattributed)':40s} {wall - total_self:8.2f}")
print(
    f"total wall {wall:.2f} s, cpu {cpu:.2f} s; batch wall_seconds {doc['wall_seconds']}; "
    f"rendering (time_s) {render:.2f} s = {100 * render / doc['wall_seconds']:.1f}% of batch wall, "
    f"{100 * render / wall:.1f}% of the process"
)
json.dump(
    {k: v for k, v in acc.items()}
    | {"_wall": wall, "_cpu": cpu, "_batch": doc["wall_seconds"], "_render": render},
    open(out + ".phases.json", "w"),
    indent=1,
)
