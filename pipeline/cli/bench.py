"""``lookdev bench …``: performance targets measured as ratios within one run.

Each benchmark times the candidate and its baseline in the same process and returns its
figures (:mod:`lookdev.pipeline.bench`); its command, in its own module
``bench_<name>.py`` beside this one, prints them as a table for people, and with
``--json`` as one object for scripts.

A benchmark command is one row of :data:`COMMANDS`: its name, the ``module:function``
that holds it and the line ``lookdev bench --help`` lists it with. Nothing is imported
until that command runs (:mod:`.lazy`), so no other command pays for the benchmarks.
"""

from __future__ import annotations

import typer

from .lazy import Lazy, lazy_group

__all__ = ["COMMANDS", "app"]

COMMANDS = {
    "blend": Lazy(
        ".bench_blend:blend_", "Blend 4 texture-masked Disney layers into all maps vs a numpy copy."
    ),
    "cli": Lazy(".bench_cli:cli_", "CPU time of the quick commands vs `import typer`."),
    "dcc": Lazy(
        ".bench_dcc:dcc_", "Blender Cycles renders of the exported USD beside lookdev's proofs."
    ),
    "depth": Lazy(
        ".bench_depth:depth_", "The proof scene at each material's path depth vs a deep reference."
    ),
    "designer": Lazy(
        ".bench_designer:designer_", "The designer's viewport: edit, rotation and convergence."
    ),
    "error": Lazy(
        ".bench_error:error_", "Error against run time of every approximation lookdev makes."
    ),
    "eval": Lazy(
        ".bench_eval:eval_", "The Disney BSDF on N pairs: numpy, Dr.Jit and Mitsuba's principled."
    ),
    "fit": Lazy(".bench_fit:fit_", "A fit of the Disney model to a measured BRDF, twice."),
    "glass": Lazy(
        ".bench_glass:glass_", "Our glass at equal noise against Mitsuba's (rough)dielectric."
    ),
    "library": Lazy(
        ".bench_library:library_",
        "`presets list` over N generated presets against reading their bytes.",
    ),
    "mainjob": Lazy(
        ".bench_mainjob:mainjob_",
        "What each knob of the main job costs: frames, sample cap, denoising.",
    ),
    "noise": Lazy(
        ".bench_noise:noise_", "Rendering to a noise target: pixel-filter cost, noise per pass."
    ),
    "proof": Lazy(
        ".bench_proof:proof_", "Proof turntable vs a scene-rebuilding script and bare mi.render."
    ),
    "subsurface": Lazy(
        ".bench_subsurface:subsurface_", "Path-traced subsurface: thick slabs, furnace, rims, cost."
    ),
    "targets": Lazy(
        ".bench_targets:targets_", "The main job's noise target against its CPU and frames met."
    ),
    "usd": Lazy(
        ".bench_usd:usd_", "N materials into one stage: Sdf-level authoring vs the Usd API."
    ),
}
"""``lookdev bench NAME``: where each command lives; add a benchmark with one row."""

app = typer.Typer(
    cls=lazy_group(COMMANDS),
    help="Measure performance targets as ratios against a baseline run in the same process.",
    no_args_is_help=True,
)
