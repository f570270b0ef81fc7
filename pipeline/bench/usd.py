"""``lookdev bench usd``: authoring 1,000 materials into one stage, fast path vs naive.

Both paths author the *same* networks (:class:`~lookdev.pipeline.export.usd.network.MaterialSpec`,
all three render contexts) into an in-memory stage:

- fast: Sdf-level, the exporter's own :func:`~lookdev.pipeline.export.usd.authoring.author`
  (``Sdf.ChangeBlock``, ``Sdf.PrimSpec``, ``Sdf.AttributeSpec``);
- naive: prim by prim through the high-level ``Usd``/``UsdShade`` API
  (``UsdShade.Material.Define``, ``Shader.CreateInput(...).Set``, ``ConnectToSource``),
  no change block, so every edit notifies and recomposes.

Reported: materials per second of each, ``ratio_fast_to_naive`` (target ≥ 5), the time
to build the networks (shared by both, not in either figure), whether the two layers are
the same ``.usda`` text byte for byte (``same_layers``), and the whole export as a user
runs it (networks, authoring, the .usda written): ``end_to_end_materials_per_s``.

Stability: on a shared machine one timing of each path gave ratios from 1.6× to 3.8×. So
the paths are timed in *interleaved rounds* (each round: fast, naive, floor, end to end,
one after another, after a garbage collection), every ratio is taken within its round,
and the figures are the median over rounds with their spread (min and max), so load
that changes between rounds moves both sides of a ratio together.

Also a floor: the same prim and attribute specs created *empty* (no values, types or
connections set beyond the attribute's type) with usd-core's cheapest calls,
``Sdf.JustCreatePrimInLayer`` / ``Sdf.JustCreatePrimAttributeInLayer``, a change block
per material as the writer has, paths built outside the clock. No authoring from Python
can beat it, so ``ratio_bound = naive_s / floor_s`` is the most any such path could
reach over the naive reference.

And a second floor, ``floor_set_s``: every value, connection and metadata field the fast
path writes, read back from its layer outside the clock and written again with the same
usd-core calls in the same change blocks (:func:`author_recorded`), nothing computed in
between: what the writer's own calls cost, so ``ratio_bound_set = naive_s /
floor_set_s`` is the most any writer making them could reach, and ``fast_s /
floor_set_s`` what lookdev's Python adds.

Wall and CPU seconds: the ratios above are of wall time (``perf_counter``), as a user
waits. The naive path's recompositions run on usd-core's worker threads, so its CPU
seconds (``time.process_time``, every thread of the process) exceed its wall seconds on
an idle machine and approach them on a loaded one; ``ratio_fast_to_naive_cpu`` is the
ratio of CPU seconds. ``naive_one_thread_s`` is the naive path with usd-core limited to
one worker thread (``Work.SetConcurrencyLimit(1)``), the fast path's condition (it uses
none): ``ratio_fast_to_naive_one_thread``.
"""

from __future__ import annotations

import gc
import statistics
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

from lookdev.materials import colour
from lookdev.materials.params import DisneyParams
from lookdev.pipeline.export.usd.authoring import (
    COLOUR_SPACE_API,
    COLOUR_SPACE_ATTR,
    DCC_LOSS,
    MTLX_CONFIG_API,
    author,
    dcc_loss_note,
    loss_doc,
    new_layer,
    usd_value,
    value_types,
)
from lookdev.pipeline.export.usd.mtlx import mtlx_version
from lookdev.pipeline.export.usd.network import (
    CONTEXT_OUTPUT,
    CONTEXTS,
    DISPLACEMENT_OUTPUT,
    Connection,
    Interface,
    MaterialSpec,
    Source,
    prim_name,
    source_from_params,
)
from lookdev.pipeline.export.usd.writer import export_usd, material_spec

__all__ = [
    "author_fast",
    "author_floor",
    "author_naive",
    "author_recorded",
    "bench_sources",
    "bench_specs",
    "end_to_end",
    "per_material",
    "recorded",
    "run",
    "spec_paths",
]


def _timed(fn) -> tuple[float, float]:
    """Wall and CPU (every thread of the process) seconds of ``fn()``."""
    gc.collect()
    t0, c0 = time.perf_counter(), time.process_time()
    fn()
    return time.perf_counter() - t0, time.process_time() - c0


def _one_thread(fn):
    """``fn`` run with usd-core's work dispatcher limited to one thread."""
    from pxr import Work

    def run():
        before = Work.GetConcurrencyLimit()
        Work.SetConcurrencyLimit(1)
        try:
            return fn()
        finally:
            Work.SetConcurrencyLimit(before)

    return run


def _spread(values: list[float]) -> dict[str, float]:
    return {
        "median": float(statistics.median(values)),
        "min": float(min(values)),
        "max": float(max(values)),
    }


def run(count: int, *, repeat: int = 5) -> dict[str, Any]:
    """Every figure of the benchmark (see module doc); ``repeat`` interleaved rounds."""
    t0 = time.perf_counter()
    specs = bench_specs(count)
    build_s = time.perf_counter() - t0
    base = Path.cwd()
    groups = per_material(*spec_paths(specs))
    recording = recorded(author_fast(specs, base))
    names = ("fast", "naive", "naive_one_thread", "floor", "floor_set", "end_to_end")
    rounds: dict[str, list[float]] = {k: [] for k in names}
    cpu: dict[str, list[float]] = {k: [] for k in names}
    with tempfile.TemporaryDirectory(prefix="lookdev-bench-usd-") as tmp:
        jobs = {
            "fast": lambda: author_fast(specs, base),
            "naive": lambda: author_naive(specs, base),
            "naive_one_thread": _one_thread(lambda: author_naive(specs, base)),
            "floor": lambda: author_floor(groups),
            "floor_set": lambda: author_recorded(recording),
            "end_to_end": lambda: end_to_end(count, Path(tmp)),
        }
        for job in jobs.values():  # warm-up: imports, caches, first-touch allocations
            job()
        for _ in range(max(1, repeat)):
            for name, job in jobs.items():
                wall, seconds = _timed(job)
                rounds[name].append(wall)
                cpu[name].append(seconds)
    fast = rounds["fast"]
    ratios = [n / f for n, f in zip(rounds["naive"], fast, strict=True)]
    bounds = [n / f for n, f in zip(rounds["naive"], rounds["floor"], strict=True)]
    set_bounds = [n / f for n, f in zip(rounds["naive"], rounds["floor_set"], strict=True)]
    rates = [count / t for t in rounds["end_to_end"]]
    fast_s = statistics.median(fast)
    naive_s = statistics.median(rounds["naive"])
    floor_s = statistics.median(rounds["floor"])
    end_to_end_s = statistics.median(rounds["end_to_end"])
    naive_stage = author_naive(specs, base)  # keeps its root layer alive
    same = _text(author_fast(specs, base)) == _text(naive_stage.GetRootLayer())
    cpu_ratios = [n / f for n, f in zip(cpu["naive"], cpu["fast"], strict=True)]
    one_ratios = [n / f for n, f in zip(rounds["naive_one_thread"], fast, strict=True)]
    ratio = _spread(ratios)
    rate = _spread(rates)
    return {
        "rounds": max(1, repeat),
        "materials": count,
        "contexts": len(CONTEXTS),
        "shaders": sum(len(n.nodes) for s in specs for n in s.networks),
        "build_networks_s": build_s,
        "fast_s": fast_s,
        "naive_s": naive_s,
        "fast_materials_per_s": count / fast_s,
        "naive_materials_per_s": count / naive_s,
        "ratio_fast_to_naive": ratio["median"],
        "ratio_fast_to_naive_min": ratio["min"],
        "ratio_fast_to_naive_max": ratio["max"],
        "fast_cpu_s": statistics.median(cpu["fast"]),
        "naive_cpu_s": statistics.median(cpu["naive"]),
        "ratio_fast_to_naive_cpu": _spread(cpu_ratios)["median"],
        "naive_one_thread_s": statistics.median(rounds["naive_one_thread"]),
        "ratio_fast_to_naive_one_thread": _spread(one_ratios)["median"],
        "floor_empty_specs_s": floor_s,
        "ratio_bound": _spread(bounds)["median"],
        "floor_set_s": statistics.median(rounds["floor_set"]),
        "ratio_bound_set": _spread(set_bounds)["median"],
        "floor_set_same_layers": _text(author_recorded(recording))
        == _text(author_fast(specs, base)),
        "same_layers": same,
        "end_to_end_s": end_to_end_s,
        "end_to_end_materials_per_s": rate["median"],
        "end_to_end_materials_per_s_min": rate["min"],
        "end_to_end_materials_per_s_max": rate["max"],
    }


def bench_sources(count: int, seed: int = 7) -> list[Source]:
    """``count`` varied Disney materials (metals, coats, sheen, glass …)."""
    rng = np.random.default_rng(seed)
    sources = []
    for i in range(count):
        r = rng.random(8)
        params = DisneyParams(
            base_color=tuple(float(x) for x in rng.random(3)),
            metallic=float(r[0] > 0.7),
            roughness=float(r[1]),
            clearcoat=float(r[2] > 0.6) * float(r[3]),
            sheen=float(r[4] > 0.7) * float(r[5]),
            spec_trans=float(r[6] > 0.85),
            specular=float(0.2 + 0.6 * r[7]),
        )
        sources.append(source_from_params(f"m{i:05d}", "disney", params))
    return sources


def bench_specs(count: int) -> list[MaterialSpec]:
    """The networks of :func:`bench_sources`, all three contexts."""
    return [material_spec(s, CONTEXTS) for s in bench_sources(count)]


def end_to_end(count: int, folder: Path) -> None:
    """What ``lookdev export usd`` does for ``count`` constant materials: networks, Sdf
    authoring, the .usda written (atomically) into ``folder``."""
    export_usd(bench_sources(count), folder / "bench.usda")


def author_fast(specs: list[MaterialSpec], base: Path):
    """The exporter's Sdf-level authoring into a new anonymous layer."""
    layer = new_layer()
    author(layer, specs, base)
    return layer


def spec_paths(specs: list[MaterialSpec]) -> tuple[list[Any], list[tuple[Any, Any, Any]]]:
    """Every prim path and every (attribute path, type, variability) that :func:`author`
    writes for ``specs``, parents before children."""
    from pxr import Sdf

    types = value_types()
    scope = Sdf.Path("/Materials")
    prims, attributes = [scope], []
    for spec in specs:
        path = scope.AppendChild(prim_name(spec.name))
        prims.append(path)
        space = path.AppendProperty(COLOUR_SPACE_ATTR)
        attributes.append((space, types["token"], Sdf.VariabilityUniform))
        if any(net.context == "mtlx" for net in spec.networks):
            version = path.AppendProperty("config:mtlx:version")
            attributes.append((version, types["string"], Sdf.VariabilityUniform))
        if dcc_loss_note(spec) is not None:
            attributes.append(
                (path.AppendProperty(DCC_LOSS), types["string"], Sdf.VariabilityVarying)
            )
        for name, (kind, _) in spec.interface().items():
            attr = path.AppendProperty(f"inputs:{name}")
            attributes.append((attr, types[kind], Sdf.VariabilityVarying))
        for net in spec.networks:
            output = path.AppendProperty(f"outputs:{CONTEXT_OUTPUT[net.context]}")
            attributes.append((output, types["token"], Sdf.VariabilityVarying))
            if net.displacement is not None:
                output = path.AppendProperty(f"outputs:{DISPLACEMENT_OUTPUT[net.context]}")
                attributes.append((output, types["token"], Sdf.VariabilityVarying))
            for node in net.nodes:
                shader = path.AppendChild(node.name)
                prims.append(shader)
                ident = shader.AppendProperty("info:id")
                attributes.append((ident, types["token"], Sdf.VariabilityUniform))
                for name, (kind, _) in node.inputs.items():
                    attr = shader.AppendProperty(f"inputs:{name}")
                    attributes.append((attr, types[kind], Sdf.VariabilityVarying))
                for name, kind in node.outputs.items():
                    attr = shader.AppendProperty(f"outputs:{name}")
                    attributes.append((attr, types[kind], Sdf.VariabilityVarying))
    return prims, attributes


def per_material(prims: list[Any], attributes: list[tuple[Any, ...]]) -> list[tuple[list, list]]:
    """``prims`` and ``attributes`` (paths, or rows with the path first, as
    :func:`spec_paths` and :func:`recorded` give them) grouped by the material they belong to, in
    order; the first group is the scope's."""
    groups: dict[Any, tuple[list, list]] = {}
    for rows, at in ((prims, 0), (attributes, 1)):
        for row in rows:
            path = row[0] if isinstance(row, tuple) else row
            prefixes = path.GetPrefixes()
            key = prefixes[1] if len(prefixes) > 1 else prefixes[0]
            groups.setdefault(key, ([], []))[at].append(row)
    return list(groups.values())


def author_floor(groups: list[tuple[list[Any], list[tuple[Any, Any, Any]]]]):
    """The specs of ``groups`` (:func:`per_material` of :func:`spec_paths`) created empty,
    a change block a material: the floor (module doc)."""
    from pxr import Sdf

    layer = Sdf.Layer.CreateAnonymous(".usda")
    for prims, attributes in groups:
        with Sdf.ChangeBlock():
            for path in prims:
                Sdf.JustCreatePrimInLayer(layer, path)
            for path, type_name, variability in attributes:
                Sdf.JustCreatePrimAttributeInLayer(layer, path, type_name, variability)
    return layer


PRIM_FIELDS = ("customData", "documentation", "apiSchemas")
"""The prim metadata the writer sets beyond specifier and type."""


def recorded(layer) -> list[tuple[list[tuple], list[tuple]]]:
    """What :func:`author` wrote into ``layer``, spec by spec, parents first, grouped by
    material (:func:`per_material`): prims as (path, type, {field: value}), attributes as
    (path, type, variability, custom, default or None, connections or None, colour
    space or None)."""
    from pxr import Sdf

    prims, attributes = [], []

    def visit(path) -> None:
        if path.IsPrimPath():
            spec = layer.GetPrimAtPath(path)
            info = {k: spec.GetInfo(k) for k in PRIM_FIELDS if spec.HasInfo(k)}
            prims.append((path, spec.typeName, info))
        elif path.IsPrimPropertyPath():
            spec = layer.GetAttributeAtPath(path)
            links = list(spec.connectionPathList.explicitItems)
            space = spec.GetInfo("colorSpace") if spec.HasInfo("colorSpace") else None
            default = spec.default if spec.HasDefaultValue() else None
            attributes.append(
                (path, spec.typeName, spec.variability, spec.custom, default, links or None, space)
            )

    layer.Traverse(Sdf.Path("/Materials"), visit)
    prims.sort(key=lambda p: p[0].pathElementCount)
    return per_material(prims, attributes)


def author_recorded(recording: list[tuple[list[tuple], list[tuple]]]):
    """The recorded specs written again with the writer's calls, a change block a
    material (the second floor, module doc)."""
    from pxr import Sdf

    layer = new_layer()  # as author_fast's, so the layers are byte for byte the same
    made = {}
    just, create = Sdf.JustCreatePrimAttributeInLayer, Sdf.CreatePrimAttributeInLayer
    for prims, attributes in recording:
        with Sdf.ChangeBlock():
            for path, type_name, info in prims:
                parent = made.get(path.GetParentPath())
                if parent is None:
                    spec = Sdf.CreatePrimInLayer(layer, path)
                    spec.specifier, spec.typeName = Sdf.SpecifierDef, type_name
                else:
                    spec = Sdf.PrimSpec(parent, path.name, Sdf.SpecifierDef, type_name)
                for key, value in info.items():
                    spec.SetInfo(key, value)
                made[path] = spec
            for path, type_name, variability, custom, default, links, space in attributes:
                if default is None and links is None and space is None:
                    just(layer, path, type_name, variability, custom)
                    continue
                attr = create(layer, path, type_name, variability, custom)
                if links is not None:
                    attr.connectionPathList.explicitItems = links
                if default is not None:
                    attr.default = default
                if space is not None:
                    attr.SetInfo("colorSpace", space)
    return layer


def author_naive(specs: list[MaterialSpec], base: Path):
    """The same networks through ``UsdShade``, prim by prim, without a change block.

    Returns the in-memory stage (its root layer lives as long as the stage).
    """
    from pxr import Sdf, Usd, UsdGeom, UsdShade

    stage = Usd.Stage.Open(new_layer())  # the layer metadata the writer's layer starts with
    stage.SetDefaultPrim(UsdGeom.Scope.Define(stage, "/Materials").GetPrim())
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.y)
    UsdGeom.SetStageMetersPerUnit(stage, 1.0)
    types = value_types()
    for spec in specs:
        path = Sdf.Path("/Materials").AppendChild(prim_name(spec.name))
        material = UsdShade.Material.Define(stage, path)
        material.GetPrim().SetCustomData({"lookdev": dict(spec.custom)})
        material.GetPrim().SetDocumentation(loss_doc(spec))
        schemas = [COLOUR_SPACE_API]
        material.GetPrim().CreateAttribute(
            COLOUR_SPACE_ATTR, types["token"], False, Sdf.VariabilityUniform
        ).Set(colour.interop_id())
        mtlx = any(net.context == "mtlx" for net in spec.networks)
        schemas += [MTLX_CONFIG_API] if mtlx else []
        material.GetPrim().SetMetadata("apiSchemas", Sdf.TokenListOp.Create(prependedItems=schemas))
        if mtlx:
            material.GetPrim().CreateAttribute(
                "config:mtlx:version", types["string"], False, Sdf.VariabilityUniform
            ).Set(mtlx_version())
        note = dcc_loss_note(spec)
        if note is not None:
            material.GetPrim().CreateAttribute(DCC_LOSS, types["string"], True).Set(note)
        interface = {
            name: material.CreateInput(name, types[kind])
            for name, (kind, _) in spec.interface().items()
        }
        for name, (kind, value) in spec.interface().items():
            interface[name].Set(usd_value(kind, value, base))
        for net in spec.networks:
            shaders = {}
            for node in net.nodes:
                shader = UsdShade.Shader.Define(stage, path.AppendChild(node.name))
                shader.CreateIdAttr(node.id)
                if any(node.custom.values()):
                    custom = {k: v for k, v in node.custom.items() if v}
                    shader.GetPrim().SetCustomData({"lookdev": custom})
                for name, kind in node.outputs.items():
                    shader.CreateOutput(name, types[kind])
                shaders[node.name] = shader
            for node in net.nodes:
                for name, (kind, value) in node.inputs.items():
                    inp = shaders[node.name].CreateInput(name, types[kind])
                    if isinstance(value, Connection):
                        inp.ConnectToSource(shaders[value.node].GetOutput(value.output))
                    elif isinstance(value, Interface):
                        inp.ConnectToSource(interface[value.name])
                        inp.Set(usd_value(kind, value.value, base))
                    else:
                        inp.Set(usd_value(kind, value, base))
                    if name in node.color_spaces:
                        inp.GetAttr().SetColorSpace(node.color_spaces[name])
            terminal = shaders[net.terminal.node].GetOutput(net.terminal.output)
            output = material.CreateOutput(CONTEXT_OUTPUT[net.context], types["token"])
            output.ConnectToSource(terminal)
            if net.displacement is not None:
                disp = shaders[net.displacement.node].GetOutput(net.displacement.output)
                name = DISPLACEMENT_OUTPUT[net.context]
                material.CreateOutput(name, types["token"]).ConnectToSource(disp)
    return stage


def _text(layer) -> str:
    """The layer as ``.usda`` text: two layers are the same when these are, byte for byte."""
    return layer.ExportToString()
