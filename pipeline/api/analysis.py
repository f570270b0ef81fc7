"""The API's analyses: BRDF-explorer plots and the stability sweep (see
:mod:`lookdev.pipeline.api`)."""

from __future__ import annotations

import os
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from lookdev.materials.errors import argument, check_range

from .materials import PathLike, _materials, hub, library_for

__all__ = [
    "check",
    "Plot",
    "plot",
    "Stability",
]


PLOT_FORMATS = (".png", ".pdf", ".svg")
PLOT_VIEWS = ("slice", "albedo", "polar", "sphere")


@dataclass
class Plot:
    """What :func:`plot` wrote: the image, the view and the materials' labels."""

    output: Path
    view: str
    materials: list[str]

    def to_json(self) -> dict[str, Any]:
        return {"output": str(self.output), "view": self.view, "materials": self.materials}


def plot(
    materials: Any,
    path: PathLike,
    *,
    view: str = "slice",
    exposure: float = 0.0,
    ibl: str | None = None,
    resolution: int = 128,
    library: Any = None,
    vary: tuple[str, Sequence[float]] | None = None,
    uv: tuple[float, float] | None = None,
    overlay: bool = False,
) -> Plot:
    """Draw materials side by side as one BRDF-explorer view (Burley §3.2) to an image.

    ``uv``: draw a texture-driven material as it is at that UV (its parameters at the
    texel there, as :func:`lookdev.evaluate` takes them); by default the centre texel.

    ``view``: ``slice`` (f(θh, θd) at φd = 90°), ``albedo`` (directional albedo per
    channel), ``polar`` (f in the plane of incidence) or ``sphere`` (a lit sphere, also
    under ``ibl`` when given). ``path`` ends in ``.png``, ``.pdf`` or ``.svg``.
    ``vary`` = (parameter, values) draws each material once per value
    (``("specular_gamma", [1, 1.5, 2, 3])``). ``overlay``: the albedo and polar views draw
    every material on one axes (a measurement over its fit).
    """
    from lookdev.pipeline.analysis import plots

    output = Path(path)
    if output.suffix.lower() not in PLOT_FORMATS:
        raise plots.PlotError(
            f"cannot write {output.suffix or 'no extension'}; allowed {', '.join(PLOT_FORMATS)}",
            where=str(output),
        )
    if view not in PLOT_VIEWS:
        raise plots.PlotError(f"unknown view {view!r}; allowed {', '.join(PLOT_VIEWS)}")
    from lookdev.pipeline.proof.tonemap import EXPOSURE_MAX

    limit = EXPOSURE_MAX
    check_range(exposure, -limit, limit, field=argument("exposure"), error=plots.PlotError)
    check_range(resolution, 8, 1024, field=argument("resolution"), error=plots.PlotError)
    lib = library_for(library)
    if isinstance(materials, str | os.PathLike):
        materials = [materials]
    hubs = [hub(m, plots.MAP_RESOLUTION, lib) for m in _materials(materials, lib)]
    if uv is not None:
        hubs = [plots.at_uv(h, uv) for h in hubs]
    if vary is not None:  # after --uv, which makes a textured material uniform
        hubs = plots.varied(hubs, vary[0], [float(v) for v in vary[1]])
    environment = None
    if ibl is not None:
        if view != "sphere":
            raise plots.PlotError(
                f"{argument('ibl')} only applies to {argument('view')} sphere",
                field=argument("ibl"),
            )
        environment = plots.load_environment(ibl)
    fig = plots.figure(
        hubs,
        view,
        exposure=exposure,
        environment=environment,
        ibl_name=ibl or "",
        resolution=resolution,
        overlay=overlay,
    )
    plots.save_figure(fig, output)
    return Plot(output, view, [h.name for h in hubs])


@dataclass
class Stability:
    """The stability sweep's findings: a report per model of the registry."""

    reports: dict[str, Any]
    """``{model: lookdev.pipeline.analysis.stability.ModelReport}``."""
    seconds: float

    @property
    def failed(self) -> bool:
        """True when any model produced a NaN, an infinity, a negative value, an
        exception or an energy gain beyond its allowance."""
        return any(r.failed for r in self.reports.values())

    def to_json(self) -> dict[str, Any]:
        """The object ``lookdev check --json`` prints."""
        return {
            "models": {name: r.to_json() for name, r in self.reports.items()},
            "seconds": round(self.seconds, 3),
        }


def check(
    models: Iterable[str] | None = None,
    *,
    progress: Callable[[int, int, str, str], None] | None = None,
) -> Stability:
    """Sweep every reflectance model (or those named) over its stiff and extreme cases.

    Parameters at both ends of their ranges and the named stiff combinations, directions at
    and beyond grazing, ``wi = −wo``, uniforms at 0, ½ and 1 − 2⁻²⁴, in float32 and
    float64; white-furnace albedos against each model's energy allowance.
    ``progress(done, total, model, case)`` is called after each parameter set.

    >>> import lookdev
    >>> try:
    ...     lookdev.check(["no_such_model"])
    ... except lookdev.LookdevError as exc:
    ...     print(type(exc).__name__)
    CheckError
    """
    import time

    from lookdev.library.measured import builtin_measured, read_measured
    from lookdev.pipeline.analysis import stability

    names = list(models) if models else None
    measured = [read_measured(p) for p in builtin_measured()]  # the shipped measurements
    total = stability.case_count(names, measured) if progress is not None else 0
    done = 0

    def advance(name: str, label: str) -> None:
        nonlocal done
        done += 1
        if progress is not None:
            progress(done, total, name, label)

    started = time.perf_counter()
    reports = stability.run(names, advance, measured)
    return Stability(reports, time.perf_counter() - started)
