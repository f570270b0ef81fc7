"""The denoiser's two known failures, as figures: ``lookdev bench error --item detail``.

* **glass against spp** — glass_clear under ``sky`` (the sun's caustic and glint), the
  turntable's first pose: relative MSE (:func:`.measure.relative_mse`) against a converged
  reference of the raw frame, OIDN's output alone and the checked frame
  (:mod:`lookdev.pipeline.proof.checked`), for a ladder of uniform sample counts; each
  with its CPU time. The claim it tests: more samples never make the shown frame worse.
* **pebble detail** — the example asset (``scripts/make_example_asset.py``: a mesh over
  four UDIM tiles with painted height) on its own mesh under ``studio``, no rig beside it
  (so the frame holds only the pebble and the floor): the *high-pass energy* — the mean
  square of display luminance minus its 3×3 mean — of each frame against the
  reference's. A denoiser that smooths the relief away lowers it; noise raises it.

Both references are rendered in two independent halves; their own relMSE is reported
(``relmse_floor``). The figures (``detail_glass.png``, ``detail_pebble.png``) are written
beside ``error_bench.json``.
"""

from __future__ import annotations

import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from .measure import relative_mse

__all__ = ["DetailSettings", "glass_curve", "high_pass_energy", "pebble_detail", "plot", "tasks"]

ASSET_SCRIPT = Path(__file__).resolve().parents[2] / "scripts" / "make_example_asset.py"


@dataclass(frozen=True)
class DetailSettings:
    ladder: tuple[int, ...] = (4, 8, 16, 32, 64, 128, 256)
    glass_resolution: tuple[int, int] = (120, 60)
    pebble_resolution: tuple[int, int] = (240, 120)
    pebble_spp: tuple[int, ...] = (16, 64)
    reference_spp: int = 2048
    ibl_width: int = 512

    @classmethod
    def quick(cls) -> DetailSettings:
        return cls((4, 8), (24, 12), (32, 16), (4,), 32, 64)


def high_pass_energy(image: np.ndarray) -> float:
    """Mean square of the display luminance minus its 3×3 mean: the frame's fine detail.

    >>> round(high_pass_energy(np.full((4, 4, 3), 0.5)), 6)
    0.0
    """
    from lookdev.pipeline.proof.adaptive import box_mean
    from lookdev.pipeline.proof.tonemap import view

    lum = view(np.asarray(image, np.float32), exact=True).mean(axis=-1)
    return float(np.mean(np.square(lum - box_mean(lum, 1))))


def _frames(table: Any, spps: tuple[int, ...], reference_spp: int) -> dict[str, Any]:
    """Reference halves and, per count, the raw, OIDN-alone and checked frames, CPU s."""
    from lookdev.pipeline.proof import adaptive, checked, denoise
    from lookdev.pipeline.proof.turntable import Frame

    from .adaptive import uniform_halves

    table.set_frame(Frame(0, "element", 0.0))
    r = adaptive.PixelRenderer(table.scene, table.camera_index, freeze=False)
    ra, rb, ref_cpu = uniform_halves(r, reference_spp, 7_000_000)
    guides = denoise.guide_renderer(table).render(seed=0)
    out = {"ref": 0.5 * (ra + rb), "floor": relative_mse(ra, rb) / 4.0, "ref_cpu": ref_cpu}
    steps = []
    for spp in spps:
        a, b, cpu = uniform_halves(r, spp, 100 + spp)
        c0 = time.process_time()
        c = checked.check(a, b, adaptive.pixel_error(a, b), lambda im: denoise.denoise(im, guides))
        steps.append({"spp": spp, "raw": 0.5 * (a + b), "oidn": c.denoised, "checked": c.image,
                      "residual": c.noise, "cpu_s": cpu,
                      "check_cpu_s": time.process_time() - c0 + guides.cpu_seconds})  # fmt: skip
    out["steps"] = steps
    return out


def glass_curve(s: DetailSettings) -> dict[str, Any]:
    """Glass × sky: relMSE of raw, OIDN alone and checked against spp (module docstring)."""
    from .adaptive import environment
    from .quality import blended, proof_table

    table = proof_table(
        blended("glass_clear"), environment("sky", s.ibl_width), s.glass_resolution, "box"
    )
    f = _frames(table, s.ladder, s.reference_spp)
    rows = [
        {"spp": st["spp"], "cpu_s": round(st["cpu_s"], 3),
         "check_cpu_s": round(st["check_cpu_s"], 3), "residual": st["residual"],
         **{k: relative_mse(st[k], f["ref"]) for k in ("raw", "oidn", "checked")}}
        for st in f["steps"]
    ]  # fmt: skip
    return {"case": "glass_clear × sky", "resolution": list(s.glass_resolution),
            "reference_spp": s.reference_spp, "relmse_floor": f["floor"],
            "ladder": rows}  # fmt: skip


def pebble_detail(s: DetailSettings) -> dict[str, Any]:
    """The example pebble's high-pass energy, raw, OIDN alone and checked, against the
    reference's (module docstring); the images kept for :func:`plot`."""
    from lookdev.library import load_material
    from lookdev.pipeline.blend import blend
    from lookdev.pipeline.proof import batch, geometry, ibl, turntable

    with tempfile.TemporaryDirectory() as tmp:
        subprocess.run([sys.executable, str(ASSET_SCRIPT), tmp], check=True, capture_output=True)
        hub = blend(load_material(Path(tmp) / "pebble.toml"), batch.MAP_RESOLUTION)
        mesh = geometry.proof_mesh(Path(tmp) / "pebble.obj")
        bsdf, depth = turntable.material_bsdf(hub)
        env = ibl.load("studio", s.ibl_width).pixels
        table = turntable.Turntable(bsdf, env, s.pebble_resolution, depth, str(mesh), rig="none",
                                    interior=turntable.material_interior(hub))  # fmt: skip
        f = _frames(table, s.pebble_spp, s.reference_spp)
    ref_hp = high_pass_energy(f["ref"])
    rows = []
    for st in f["steps"]:
        row = {"spp": st["spp"], "cpu_s": round(st["cpu_s"], 3)}
        for k in ("raw", "oidn", "checked"):
            hp = high_pass_energy(st[k])
            err = relative_mse(st[k], f["ref"])
            row[k] = {"high_pass": hp, "ratio": hp / ref_hp, "relmse": err}
        rows.append(row)
    return {"case": "pebble × studio", "resolution": list(s.pebble_resolution),
            "reference_spp": s.reference_spp, "relmse_floor": f["floor"],
            "reference_high_pass": ref_hp, "ladder": rows,
            "images": {"reference": f["ref"], **{f"{k} {st['spp']} spp": st[k]
                       for st in f["steps"] for k in ("raw", "oidn", "checked")}}}  # fmt: skip


def plot(results: dict[str, Any], out_dir: Path) -> dict[str, Path]:
    """``detail_glass.png`` (relMSE against spp) and ``detail_pebble.png`` (the frames and
    their high-pass images) from what :func:`tasks` measured."""
    from lookdev.pipeline.analysis.plots import plt, save_figure
    from lookdev.pipeline.proof.adaptive import box_mean
    from lookdev.pipeline.proof.tonemap import view

    paths = {}
    if "glass" in results:
        g = results["glass"]
        fig, ax = plt.subplots(figsize=(6, 4.5), layout="constrained")
        spp = [r["spp"] for r in g["ladder"]]
        for k, m in (("raw", "o"), ("oidn", "s"), ("checked", "*")):
            label = {"oidn": "OIDN alone", "checked": "checked (shown)"}.get(k, k)
            ax.loglog(spp, [r[k] for r in g["ladder"]], "-", marker=m, label=label)
        ax.axhline(g["relmse_floor"], color="grey", ls=":", label="reference's own")
        ax.set(xlabel="samples per pixel", ylabel="relative MSE", title=g["case"])
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize="small")
        paths["glass"] = save_figure(fig, out_dir / "detail_glass.png")
    if "pebble" in results:
        images = results["pebble"]["images"]
        fig, axes = plt.subplots(2, len(images), figsize=(2.6 * len(images), 3.2),
                                 layout="constrained", squeeze=False)  # fmt: skip
        for i, (name, im) in enumerate(images.items()):
            v = np.clip(view(np.asarray(im, np.float32)), 0, 1)
            lum = v.mean(axis=-1)
            axes[0, i].imshow(v)
            axes[1, i].imshow(lum - box_mean(lum, 1), cmap="RdBu", vmin=-0.05, vmax=0.05)
            axes[0, i].set_title(name, fontsize="small")
            for ax in axes[:, i]:
                ax.set_axis_off()
        paths["pebble"] = save_figure(fig, out_dir / "detail_pebble.png")
    return paths


def tasks(s: DetailSettings, report: Any) -> list[tuple[str, Any]]:
    """Two tasks for :func:`.error.run`, each storing its result in ``report.detail`` and
    returning rows (relMSE against CPU seconds)."""
    from .measure import Row

    def rows(name: str, data: dict[str, Any]) -> list[Row]:
        out = []
        for r in data["ladder"]:
            for k in ("raw", "oidn", "checked"):
                err = r[k]["relmse"] if isinstance(r[k], dict) else r[k]
                cpu = r["cpu_s"] + (r.get("check_cpu_s", 0.0) if k != "raw" else 0.0)
                out.append(Row("detail", data["case"], k, f"{r['spp']} spp", err, cpu,
                               reference=f"{data['reference_spp']} spp"))  # fmt: skip
        return out

    def glass() -> list[Row]:
        report.detail["glass"] = glass_curve(s)
        return rows("glass", report.detail["glass"])

    def pebble() -> list[Row]:
        report.detail["pebble"] = pebble_detail(s)
        return rows("pebble", report.detail["pebble"])

    return [("detail glass", glass), ("detail pebble", pebble)]
