"""``lookdev proof``: turntables of presets under IBLs, batched (Burley 2012 §6.1)."""

from __future__ import annotations

from contextlib import ExitStack
from enum import StrEnum
from pathlib import Path
from typing import Annotated

import typer
from rich.progress import (
    BarColumn,
    MofNCompleteColumn,
    Progress,
    TextColumn,
    TimeElapsedColumn,
    TimeRemainingColumn,
)

from lookdev.pipeline.proof.settings import (
    DEFAULT_ADAPTIVE,
    DEFAULT_DENOISE,
    DEFAULT_FRAMES,
    DEFAULT_LIGHT_FRAMES,
    DEFAULT_MAX_SPP,
    DEFAULT_NOISE,
    DEFAULT_PIXEL_MAX_SPP,
    DEFAULT_RESOLUTION,
    UNIFORM_NOISE,
)

from .common import console, err_console, print_json, table

__all__ = ["ProofContext", "Rig", "proof"]


class ProofContext(StrEnum):
    universal = "universal"
    mtlx = "mtlx"


class Rig(StrEnum):
    """``--rig``: the values of :data:`lookdev.pipeline.proof.rig.RIGS`."""

    full = "full"
    balls = "balls"
    none = "none"


def proof(
    presets: Annotated[
        list[str] | None,
        typer.Argument(
            metavar="[PRESET]…",
            help="Preset names or .toml files. None: a representative set of built-ins.",
            show_default=False,
        ),
    ] = None,
    ibls: Annotated[
        list[str] | None,
        typer.Option(
            "--ibl",
            "-i",
            help="A built-in IBL (studio, sky, overcast, sunset) or an .exr/.hdr lat-long "
            "file; repeat for several. None: every built-in.",
            show_default=False,
        ),
    ] = None,
    frames: Annotated[
        int, typer.Option("--frames", "-n", min=1, max=360, help="Element-rotation frames.")
    ] = DEFAULT_FRAMES,
    light_frames: Annotated[
        int, typer.Option("--light-frames", "-m", min=0, max=360, help="Lighting-rotation frames.")
    ] = DEFAULT_LIGHT_FRAMES,
    spp: Annotated[
        int | None,
        typer.Option(
            "--spp",
            "-s",
            help="A fixed count of samples per pixel for every frame (2 .. 65536), instead "
            "of a noise target.",
            show_default=False,
        ),
    ] = None,
    noise: Annotated[
        float | None,
        typer.Option(
            "--noise",
            help="Render each frame until its relative RMS noise on luminance is at most "
            f"this [default: {UNIFORM_NOISE:g}]. With --adaptive: until every pixel's "
            "estimated RMS error on the image shown (display code values 0-1, after the "
            "view; the checked denoised frame when denoising) is at most this "
            f"[default: {DEFAULT_NOISE:g}].",
            show_default=False,
        ),
    ] = None,
    max_spp: Annotated[
        int | None,
        typer.Option(
            "--max-spp",
            help="The most samples a frame may take to reach --noise [default: "
            f"{DEFAULT_MAX_SPP}; a pixel's {DEFAULT_PIXEL_MAX_SPP} with --adaptive].",
            show_default=False,
        ),
    ] = None,
    time_budget: Annotated[
        float | None,
        typer.Option(
            "--time-budget",
            metavar="SECONDS",
            help="The most rendering seconds a frame may take to reach --noise (no new "
            "pass starts that would end past it) [default: none].",
            show_default=False,
        ),
    ] = None,
    clamp: Annotated[
        float | None,
        typer.Option(
            "--clamp",
            metavar="VALUE",
            help="Limit each camera sample's radiance to VALUE: hides fireflies but darkens "
            "what they belong to; for quick previews (recorded in the manifests). "
            "[default: none, unclamped]",
            show_default=False,
        ),
    ] = None,
    pixel_filter: Annotated[
        str,
        typer.Option(
            "--pixel-filter",
            help="Reconstruction filter: box (pixel noise stays independent, as a "
            "denoiser needs) or gaussian.",
        ),
    ] = "box",
    resolution: Annotated[
        tuple[int, int],
        typer.Option(
            "--resolution",
            "-r",
            metavar="W H",
            help="Frame size in pixels, each 8 .. 8192.",
        ),
    ] = DEFAULT_RESOLUTION,
    output: Annotated[
        Path, typer.Option("--output", "-o", help="Folder for frames, sheets and manifests.")
    ] = Path("proofs"),
    exposure: Annotated[
        float,
        typer.Option(
            "--exposure",
            "-e",
            min=-32.0,
            max=32.0,
            help="Stops applied by the PNG view transform (-32 .. 32).",
        ),
    ] = 0.0,
    ibl_width: Annotated[
        int,
        typer.Option(
            "--ibl-width", min=8, max=8192, help="Every IBL is resampled to this width (×½ high)."
        ),
    ] = 512,
    rig: Annotated[
        Rig,
        typer.Option(
            "--rig",
            help="The calibrated rig beside the material: full (chrome ball, 18 % grey "
            "ball, ColorChecker chart), balls, or none.",
        ),
    ] = Rig.full,
    scheduler: Annotated[
        str | None,
        typer.Option(
            "--scheduler",
            help="Dask scheduler address (tcp://host:8786): run jobs on that cluster. The "
            "output folder must be shared with its workers.",
        ),
    ] = None,
    jobs: Annotated[
        int | None,
        typer.Option(
            "--workers",
            "-j",
            min=1,
            max=1024,
            help="Local worker processes (default 1: each renders on every core).",
        ),
    ] = None,
    library: Annotated[
        list[Path] | None,
        typer.Option("--library", "-L", help="Extra preset folders searched before the built-ins."),
    ] = None,
    as_json: Annotated[
        bool, typer.Option("--json", help="Print the batch manifest as one JSON object.")
    ] = False,
    geometry: Annotated[
        Path | None,
        typer.Option(
            "--geometry",
            "-g",
            help="A mesh (PLY, OBJ, or USD geometry) shown in the cup's place beside the "
            "ball, with its own UVs (UDIM tiles included).",
        ),
    ] = None,
    denoise: Annotated[
        bool,
        typer.Option(
            "--denoise/--no-denoise",
            help="Also write each frame denoised by Intel Open Image Denoise (CPU, guided by "
            "albedo and normal images rendered with it): frame_NNN_denoised.exr/.png beside "
            "the raw frame, which is kept. --no-denoise: raw frames only.",
        ),
    ] = DEFAULT_DENOISE,
    adaptive: Annotated[
        bool,
        typer.Option(
            "--adaptive/--no-adaptive",
            help="Sample per pixel: each pass renders only the pixels whose A/B estimate "
            "is above --noise (box filter), and the denoised frame is checked. Off by "
            "default: whole-frame passes (docs/measurements/adaptive.md says why).",
        ),
    ] = DEFAULT_ADAPTIVE,
    report: Annotated[
        bool,
        typer.Option(
            "--report",
            help="Also write OUTPUT/index.html, the review page: turntable players, a "
            "synchronised comparison across materials or IBLs, raw/denoised, each "
            "material's parameters, source, USD losses and BRDF plots, every frame's "
            "spp/noise/time; static, opens from disk, offline.",
        ),
    ] = False,
    context: Annotated[
        ProofContext | None,
        typer.Option(
            "--context",
            help="'universal': also proof, beside each preset, its USD universal context "
            "as PRESET-universal: the UsdPreviewSurface values rendered by that surface's "
            "own BRDF, what a DCC preview shows; 'mtlx': also PRESET-mtlx, its OpenPBR "
            "Surface rendered by the OpenPBR model, what an OpenPBR renderer shows "
            "(export usd --report measures both differences).",
        ),
    ] = None,
) -> None:
    """Render turntable proofs: every PRESET under every --ibl.

    Each proof turns the element through --frames frames, then the lighting through
    --light-frames frames, and writes under OUTPUT/PRESET/IBL/: EXR frames, tone-mapped PNG
    frames, a labelled contact.png and a manifest.json. Each frame is rendered in passes
    per pixel until its pixels' estimated error on the image shown is at most --noise
    (each pass renders only the pixels still above it), or --max-spp or --time-budget is
    reached (or at a fixed --spp); its manifest entry records the mean and largest spp,
    the noise reached (raw, and the checked denoised residual), the share of pixels that
    met the target, why it stopped, its time and the share of its error in fireflies.
    Re-running skips frames the manifests vouch for, so an interrupted batch resumes
    where it stopped.

    Examples:

      lookdev proof                                   # built-in set × built-in IBLs

      lookdev proof gold velvet --ibl studio --ibl ~/hdri/loft.exr -o proofs

      lookdev proof copper --noise 0.02 --max-spp 4096 --resolution 960 480

      lookdev proof gold --ibl sky --spp 16 --clamp 20 -r 240 120   # preview

      lookdev proof copper --spp 256 --resolution 640 320 --scheduler tcp://farm:8786

      lookdev proof hero.toml --geometry hero.usd --ibl studio

      lookdev --working-space acescg --view Un-tone-mapped proof gold   # colour: global options

    Frames render in the working space (EXRs carry its chromaticities); PNGs and contact
    sheets show them through the OCIO view (`lookdev --help`, Colour).
    """
    from lookdev.pipeline import api
    from lookdev.pipeline.proof import batch

    with ExitStack() as stack:
        bar, task = None, None

        def show(p: batch.Progress) -> None:
            nonlocal bar, task
            if bar is None:  # once the batch runs: loading errors stay one line
                bar = stack.enter_context(_progress())
                task = bar.add_task("proofs", total=p.frames_total)
            if p.finished is not None:
                bar.console.print(
                    f"  {p.finished['material']} × {p.finished['ibl']}: "
                    f"{p.finished['rendered']} rendered, {p.finished['skipped']} already done",
                    highlight=False,
                )
            bar.update(task, completed=p.frames_done, total=p.frames_total)

        doc = api.proof(
            presets,
            ibls,
            output,
            frames=frames,
            light_frames=light_frames,
            spp=spp,
            noise=noise,
            max_spp=max_spp,
            time_budget=time_budget,
            clamp=clamp,
            pixel_filter=pixel_filter,
            resolution=resolution,
            exposure=exposure,
            ibl_width=ibl_width,
            rig=rig.value,
            jobs=jobs,
            scheduler=scheduler,
            report=report,
            library=library,
            progress=show,
            context=None if context is None else context.value,
            geometry=geometry,
            denoise=denoise,
            adaptive=adaptive,
        )
    if as_json:
        print_json(doc)
        return
    rows = [
        [
            e["material"],
            e["ibl"],
            f"{e['rendered']} + {e['skipped']}",
            e["render_seconds"],
            e.get("mean_spp"),  # .get: a kept entry may come from an older batch
            e.get("mean_noise_relative"),
            ", ".join(f"{k} {v}" for k, v in sorted((e.get("stops") or {}).items())),
            e.get("max_firefly_share"),
        ]
        for e in doc["proofs"]
    ]
    columns = ["material", "ibl", "new + kept", "render s", "spp", "noise", "stop", "fireflies"]
    console.print(table(f"proofs in {output}", columns, rows))
    console.print(
        f"{doc['wall_seconds']:.1f} s. Contact sheets: {output}/MATERIAL/IBL/contact.png; "
        f"all proofs: {output / 'overview.png'}; manifest: {output / batch.MANIFEST}"
        + (f"; review page: {doc['report']}" if report else ""),
        highlight=False,
    )


def _progress() -> Progress:
    return Progress(
        TextColumn("[bold]{task.description}"),
        BarColumn(),
        MofNCompleteColumn(),
        TextColumn("frames"),
        TimeElapsedColumn(),
        TextColumn("ETA"),
        TimeRemainingColumn(),
        console=err_console,
        transient=False,
        # A bar is for a person at a terminal: in a log or a pipe it would only add lines
        # (and an error must stay the one line on stderr).
        disable=not err_console.is_terminal,
    )
