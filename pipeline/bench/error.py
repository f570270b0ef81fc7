"""``lookdev bench error``: every approximation's error against its run time, in one run.

Items (see :mod:`.measure` for how each is measured):

========== ==============================================================================
render     proof renders of a diffuse, glossy metal, clearcoat, sheen and glass preset:
           relative MSE against a high-sample reference, for a ladder of spp
albedo     directional albedo by quadrature, Monte Carlo and the shipped table
lambda     the Conty-Kulla Λ fit against numerical integration
precision  float32 against float64 evaluation of every model
denoise    equal-time curves of raw and OIDN-denoised proof frames (plastic, glass
           under sky, box filter) against a converged reference (:mod:`.denoise`)
sheen_     both modes of the Conty-Kulla ``sheen_lambda`` (Table 1's fit, the exact
lambda     table) against numerical integration, r from 0.01 to 1
energy     a white rough metal's furnace |1 − E| with ``energy_compensation`` off and on,
           by roughness, against the eval time the table look-up costs (:mod:`.energy`)
mainjob    the main job's old and new default frame against converged references, and
           each frame's noise estimate against its measured error (:mod:`.quality`)
adaptive   uniform, per-pixel adaptive and adaptive + checked denoising at equal CPU
           time, and the estimate per pixel class (:mod:`.adaptive`)
detail     glass × sky raw, OIDN alone and checked against spp, and the example pebble's
           high-pass energy against its reference's, as figures (:mod:`.detail`)
========== ==============================================================================

Outputs: a Rich table, ``error_bench.json`` (every row, the settings and the machine)
and ``error_bench.png`` (log-log error against time, one panel per item) in ``-o DIR``.
An item that cannot run here (a model or preset missing) is listed with the reason, never
silently dropped.
"""

from __future__ import annotations

import json
import platform
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from lookdev.library import files
from lookdev.materials.bsdf import Model
from lookdev.materials.errors import LookdevError

from . import adaptive as adaptive_bench
from . import denoise as denoise_bench
from . import detail as detail_bench
from . import measure, quality
from .measure import Row

__all__ = [
    "BenchError",
    "EDGE_CASES",
    "ERROR_NAMES",
    "ITEMS",
    "LOBE_CASES",
    "MARKERS",
    "RENDER_IBL",
    "RENDER_PRESETS",
    "Report",
    "Settings",
    "lambda_fit",
    "model_cases",
    "plot_error_vs_time",
    "render_cases",
    "run",
    "write_outputs",
]

ITEMS = (
    "render", "albedo", "lambda", "precision", "denoise", "sheen_lambda", "energy", "mainjob",
    "adaptive", "detail",
)  # fmt: skip

RENDER_IBL = "studio"
# Proof-render cases: label → built-in preset name.
RENDER_PRESETS: dict[str, str] = {
    "diffuse": "plaster",
    "glossy metal": "gold",
    "clearcoat": "car_paint_red",
    "sheen": "velvet",
    "glass": "glass_clear",
}


@dataclass(frozen=True)
class Settings:
    """How far each ladder goes; ``quick()`` is for tests and CI."""

    render_ladder: tuple[int, ...] = (1, 4, 16, 64)
    render_reference_spp: int = 1024
    render_resolution: int = 32
    quadrature: tuple[int, ...] = (8, 16, 32, 64, 128)
    samples: tuple[int, ...] = (64, 256, 1024, 4096)
    albedo_reference_nodes: int = 512
    albedo_reference_samples: int = 65536
    lambda_nodes: tuple[int, ...] = (8, 16, 32, 64, 128)
    lambda_reference_nodes: int = 2048
    precision_pairs: int = 20000
    energy_samples: int = 16384
    denoise: denoise_bench.DenoiseSettings = field(default_factory=denoise_bench.DenoiseSettings)
    mainjob: quality.ErrorSettings = field(default_factory=quality.ErrorSettings)
    adaptive: adaptive_bench.AdaptiveSettings = field(
        default_factory=adaptive_bench.AdaptiveSettings
    )
    detail: detail_bench.DetailSettings = field(default_factory=detail_bench.DetailSettings)

    @classmethod
    def quick(cls) -> Settings:
        return cls(
            render_ladder=(1, 4, 16),
            render_reference_spp=128,
            render_resolution=16,
            quadrature=(8, 16, 32),
            samples=(64, 256),
            albedo_reference_nodes=128,
            albedo_reference_samples=8192,
            lambda_nodes=(4, 16),
            lambda_reference_nodes=512,
            precision_pairs=2000,
            energy_samples=2048,
            denoise=denoise_bench.DenoiseSettings.quick(),
            mainjob=quality.ErrorSettings.quick(),
            adaptive=adaptive_bench.AdaptiveSettings.quick(),
            detail=detail_bench.DetailSettings.quick(),
        )


@dataclass
class Report:
    rows: list[Row] = field(default_factory=list)
    skipped: dict[str, str] = field(default_factory=dict)  # "item: case" → reason
    denoise: list[denoise_bench.Case] = field(default_factory=list)
    mainjob: list[dict[str, Any]] = field(default_factory=list)  # quality.error_case each
    adaptive: list[dict[str, Any]] = field(default_factory=list)  # adaptive.bench_case each
    detail: dict[str, Any] = field(default_factory=dict)  # "glass", "pebble": detail's results

    def to_json(self, settings: Settings) -> dict[str, Any]:
        return {
            "settings": asdict(settings),
            "machine": {"python": platform.python_version(), "platform": platform.platform()},
            "rows": [
                {
                    **asdict(r),
                    "seconds_per_evaluation": r.seconds_per_evaluation,
                    "speedup_vs_reference": r.speedup,
                }
                for r in self.rows
            ],
            "skipped": self.skipped,
            "denoise": [case.as_json() for case in self.denoise],
            "mainjob": self.mainjob,
            "adaptive": self.adaptive,
            "detail": {
                k: {key: v for key, v in d.items() if key != "images"}
                for k, d in self.detail.items()
            },
        }


class BenchError(LookdevError):
    """The error bench cannot run as asked."""


# -- what there is to measure --------------------------------------------------------
EDGE_CASES = {"roughness": (0.0, 1.0)}
LOBE_CASES = ("clearcoat", "sheen", "spec_trans")  # switched fully on, one at a time


def model_cases(models: dict[str, Model]) -> list[tuple[str, Model, Any]]:
    """(label, model, params): each model's defaults, its roughness at 0 and 1 (the
    edges themselves) and each optional lobe switched on, where the model has them."""
    cases = []
    for name, model in models.items():
        default = model.params_type()
        fields = type(default).model_fields
        cases.append((f"{name} default", model, default))
        for param, values in EDGE_CASES.items():
            if param in fields:
                cases += [
                    (f"{name} {param} {v:g}", model, default.replace(**{param: v})) for v in values
                ]
        cases += [
            (f"{name} {lobe} 1", model, default.replace(**{lobe: 1.0}))
            for lobe in LOBE_CASES
            if lobe in fields
        ]
    return cases


def lambda_fit() -> Callable[[np.ndarray, float], np.ndarray] | None:
    """The shipped Conty-Kulla Λ fit as ``fit(cos_theta, r)``, or None."""
    try:
        from lookdev.materials import sheen
    except ImportError:
        return None
    return getattr(sheen, "lambda_fit", None)


def render_cases(library: Any = None) -> tuple[list[tuple[str, dict, int]], dict[str, str]]:
    """(label, Mitsuba BSDF dict, max depth) per render case, as the proofs build them,
    and the reasons for any gaps."""
    try:
        from lookdev.library import load_material
        from lookdev.pipeline.blend import blend
        from lookdev.pipeline.export.mitsuba import register_plugins
        from lookdev.pipeline.proof.batch import MAP_RESOLUTION
        from lookdev.pipeline.proof.turntable import material_bsdf
    except ImportError as exc:
        return [], {f"render: {label}": f"not available: {exc}" for label in RENDER_PRESETS}
    register_plugins()
    cases, missing = [], {}
    for label, preset in RENDER_PRESETS.items():
        try:
            bsdf, depth = material_bsdf(blend(load_material(preset, library), MAP_RESOLUTION))
            cases.append((f"{label} ({preset})", bsdf, depth))
        except LookdevError as exc:
            missing[f"render: {label}"] = str(exc)
    return cases, missing


# -- running -------------------------------------------------------------------------
def run(
    settings: Settings,
    items: tuple[str, ...] = ITEMS,
    *,
    render: list[tuple[str, dict, int]] | None = None,
    models: dict[str, Model] | None = None,
    environment: np.ndarray | None = None,
    progress: Callable[[str, int, int], None] = lambda task, done, total: None,
) -> Report:
    """Measure every asked item now. ``render``/``models`` override what is discovered."""
    report = Report()
    if models is None:
        from lookdev.materials.registry import MODELS as models
    tasks: list[tuple[str, Callable[[], list[Row]]]] = []
    if "render" in items:
        from lookdev.pipeline.variant import use_mitsuba

        use_mitsuba()
        if render is None:
            render, gaps = render_cases()
            report.skipped.update(gaps)
        if environment is None:
            from lookdev.pipeline.proof import ibl

            environment = ibl.load(RENDER_IBL, 64).pixels
        env = environment
        for label, bsdf, depth in render:
            tasks.append(
                (
                    f"render {label}",
                    lambda b=bsdf, d=depth, lab=label: measure.bench_render(
                        lab,
                        b,
                        env,
                        max_depth=d,
                        ladder=settings.render_ladder,
                        reference_spp=settings.render_reference_spp,
                        resolution=settings.render_resolution,
                    ),
                )
            )
    if "albedo" in items:
        for label, model, params in model_cases(models):
            tasks.append(
                (
                    f"albedo {label}",
                    lambda m=model, p=params, lab=label: measure.bench_albedo(
                        lab,
                        m,
                        p,
                        quadrature=settings.quadrature,
                        samples=settings.samples,
                        reference_nodes=settings.albedo_reference_nodes,
                        reference_samples=settings.albedo_reference_samples,
                    ),
                )
            )
    if "lambda" in items:
        fit = lambda_fit()
        if fit is None:
            report.skipped["lambda: fit"] = "lookdev.materials.sheen.lambda_fit is not installed"
        tasks.append(
            (
                "lambda",
                lambda: measure.bench_lambda(
                    fit,
                    nodes=settings.lambda_nodes,
                    reference_nodes=settings.lambda_reference_nodes,
                ),
            )
        )
    if "sheen_lambda" in items:
        tasks.append(
            (
                "sheen_lambda",
                lambda: measure.bench_sheen_lambda(reference_nodes=settings.lambda_reference_nodes),
            )
        )
    if "precision" in items:
        for label, model, params in model_cases(models):
            tasks.append(
                (
                    f"precision {label}",
                    lambda m=model, p=params, lab=label: measure.bench_precision(
                        lab, m, p, n=settings.precision_pairs
                    ),
                )
            )
    if "denoise" in items:
        tasks += _denoise_tasks(settings.denoise, report)
    if "energy" in items:
        from . import energy

        n = settings.energy_samples
        tasks.append(("energy", lambda: energy.bench_energy(samples=n)))
    if "mainjob" in items:
        tasks += quality.tasks(settings.mainjob, report)
    if "adaptive" in items:
        tasks += adaptive_bench.tasks(settings.adaptive, report)
    if "detail" in items:
        tasks += detail_bench.tasks(settings.detail, report)
    for done, (name, task) in enumerate(tasks):
        progress(name, done, len(tasks))
        try:
            report.rows.extend(task())
        except Exception as exc:  # noqa: BLE001 - one broken case must not hide the rest
            first = (str(exc).splitlines() or [""])[0]
            report.skipped[name] = f"failed: {type(exc).__name__}: {first}"
    return report


def _denoise_tasks(
    settings: denoise_bench.DenoiseSettings, report: Report
) -> list[tuple[str, Callable[[], list[Row]]]]:
    """One task per (preset, IBL) of ``settings.cases``; each adds its Case."""
    from lookdev.library import load_material
    from lookdev.pipeline.blend import blend
    from lookdev.pipeline.export.mitsuba import register_plugins
    from lookdev.pipeline.proof import ibl
    from lookdev.pipeline.proof.batch import MAP_RESOLUTION
    from lookdev.pipeline.proof.turntable import material_bsdf

    register_plugins()

    def task(preset: str, ibl_name: str) -> list[Row]:
        bsdf, depth = material_bsdf(blend(load_material(preset), MAP_RESOLUTION))
        env = ibl.load(ibl_name, settings.ibl_width).pixels
        case = denoise_bench.bench_case(preset, ibl_name, bsdf, env, depth, settings)
        report.denoise.append(case)
        return case.rows()

    return [
        (f"denoise {preset} × {name}", lambda p=preset, n=name: task(p, n))
        for preset, name in settings.cases
    ]


# -- output ----------------------------------------------------------------------------
MARKERS = {
    "quadrature": "o",
    "monte carlo": "s",
    "table": "*",
    "fit (eq. 3)": "^",
    "integral": "D",
    "path tracer": "o",
    "float32": "v",
    "raw": "o",
    "denoised": "*",
    "old default": "s",
    "new default": "*",
    "uniform": "s",
    "adaptive": "o",
    "adaptive + checked": "*",
    "oidn": "s",
    "checked": "*",
}


def plot_error_vs_time(report: Report, path: Path) -> Path:
    """Log-log error against seconds per call: a panel per item, a colour per case, a
    marker per method, each legend beside its panel."""
    from matplotlib.lines import Line2D

    from lookdev.pipeline.analysis.plots import plt, save_figure

    items = [i for i in ITEMS if any(r.item == i and r.error > 0 for r in report.rows)]
    rows_n = max(1, (len(items) + 1) // 2)
    fig, axes = plt.subplots(
        rows_n, 2, figsize=(15, 5 * rows_n), layout="constrained", squeeze=False
    )
    for ax in axes.flat[len(items) :]:
        ax.set_axis_off()
    for ax, item in zip(axes.flat, items, strict=False):
        rows = [r for r in report.rows if r.item == item and r.error > 0]
        cases = list(dict.fromkeys(r.case for r in rows))
        colours = plt.get_cmap("tab20")(np.linspace(0, 1, max(len(cases), 2)))
        for case, method in dict.fromkeys((r.case, r.method) for r in rows):
            pts = [r for r in rows if (r.case, r.method) == (case, method)]
            ax.loglog(
                [r.seconds for r in pts],
                [r.error for r in pts],
                "-",
                marker=MARKERS.get(method, "o"),
                ms=4,
                lw=1,
                color=colours[cases.index(case)],
            )
        handles = [Line2D([], [], color=colours[i], lw=2, label=c) for i, c in enumerate(cases)]
        methods = dict.fromkeys(r.method for r in rows)
        handles += [
            Line2D([], [], color="k", ls="", marker=MARKERS.get(m, "o"), label=m) for m in methods
        ]
        ax.legend(
            handles=handles,
            fontsize="x-small",
            loc="upper left",
            bbox_to_anchor=(1.01, 1.0),
            borderaxespad=0,
        )
        ax.set_title(f"{item}: {ERROR_NAMES[item]}")
        ax.set_xlabel("seconds per call")
        ax.set_ylabel(ERROR_NAMES[item])
        ax.grid(alpha=0.3, which="both")
    return save_figure(fig, path)


def write_outputs(report: Report, settings: Settings, out_dir: Path) -> dict[str, Path]:
    """``error_bench.json`` and ``error_bench.png`` in ``out_dir``, each written whole."""
    files.make_folder(out_dir)
    js = out_dir / "error_bench.json"
    files.atomic_write(js, json.dumps(report.to_json(settings), indent=2) + "\n")
    out = {"json": js, "plot": plot_error_vs_time(report, out_dir / "error_bench.png")}
    return out | detail_bench.plot(report.detail, out_dir)


ERROR_NAMES = {
    "render": "relative MSE",
    "albedo": "relative RMS error",
    "lambda": "relative RMS error",
    "precision": "max relative error of float32",
    "denoise": "relative MSE (mean over seeds)",
    "sheen_lambda": "relative RMS error of Λ",
    "energy": "white furnace max |1 − E|",
    "mainjob": "relative MSE of the frame as shown",
    "adaptive": "relative MSE at equal CPU time",
    "detail": "relative MSE (glass ladder, pebble)",
}
