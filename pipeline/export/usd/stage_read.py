"""Reading a USD stage's materials as networks: every Material's render contexts, its
shaders, their values and connections, as :class:`~.network.MaterialSpec` (what
:mod:`.reader` turns into presets and :mod:`.validate` checks).

Values are followed through connections to the Material's own interface inputs (the
usdex, Houdini and Omniverse pattern: the shader input connects to ``inputs:X`` on the
Material, which holds the value).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from .network import CONTEXT_OUTPUT, Connection, Image, MaterialSpec, Network, Node

__all__ = ["DOC_KEY", "PRIM_KEY", "colour_spaces", "custom_of", "read_networks"]

PRIM_KEY = "prim_path"
"""Where :func:`read_networks` keeps a material's prim path in ``MaterialSpec.custom``."""
DOC_KEY = "material_doc"
"""Where :func:`read_networks` keeps the Material's ``doc`` (lookdev's loss lines)."""


def read_networks(stage) -> list[MaterialSpec]:
    """Every material's networks as :class:`~.network.MaterialSpec` (switch prims skipped);
    ``custom["meters_per_unit"]`` is the stage's."""
    from pxr import Usd, UsdGeom, UsdShade

    units = float(UsdGeom.GetStageMetersPerUnit(stage))
    specs = []
    for prim in stage.Traverse(Usd.TraverseInstanceProxies()):
        if not prim.IsA(UsdShade.Material) or custom_of(prim).get("switch"):
            continue
        material = UsdShade.Material(prim)
        networks = []
        for context, output_name in CONTEXT_OUTPUT.items():
            net = _network(material, context, output_name)
            if net is not None:
                networks.append(net)
        custom = {**custom_of(prim), "meters_per_unit": units, PRIM_KEY: str(prim.GetPath())}
        custom[DOC_KEY] = prim.GetDocumentation() or ""
        specs.append(MaterialSpec(custom.get("preset", prim.GetName()), networks, custom))
    return specs


def colour_spaces(stage) -> dict[str, str]:
    """Each material's colour space (UsdColorSpaceAPI, on it or an ancestor; "" if none),
    by the name :func:`read_networks` gives it."""
    from pxr import Usd, UsdShade

    return {
        custom_of(prim).get("preset", prim.GetName()): Usd.ColorSpaceAPI.ComputeColorSpaceName(
            prim, None
        )
        or ""
        for prim in stage.Traverse(Usd.TraverseInstanceProxies())
        if prim.IsA(UsdShade.Material)
    }


def custom_of(prim) -> dict[str, Any]:
    """lookdev's ``customData`` of ``prim`` (empty if none)."""
    return dict(prim.GetCustomDataByKey("lookdev") or {})


def _network(material, context: str, output_name: str) -> Network | None:
    output = material.GetOutput(output_name)
    if not output:
        return None
    terminal = _source(output)
    if terminal is None:
        return None
    nodes: dict[str, Node] = {}
    _collect(material.GetPrim().GetStage().GetPrimAtPath(terminal[0]), nodes)
    name = terminal[0].name
    return Network(context, Connection(name, terminal[1]), list(nodes.values()))


def _source(port):
    sources, _ = port.GetConnectedSources()
    if not sources:
        return None
    src = sources[0]
    return src.source.GetPrim().GetPath(), src.sourceName


def _collect(prim, nodes: dict[str, Node]) -> None:
    from pxr import UsdShade

    shader = UsdShade.Shader(prim)
    if not shader or prim.GetName() in nodes:
        return
    node = Node(prim.GetName(), str(shader.GetIdAttr().Get() or ""))
    nodes[node.name] = node
    for out in shader.GetOutputs():
        node.outputs[out.GetBaseName()] = str(out.GetTypeName())
    for inp in shader.GetInputs():
        kind = str(inp.GetTypeName())
        # Followed through the Material's interface inputs to a shader output or a value.
        for attr in inp.GetValueProducingAttributes(shaderOutputsOnly=False):
            base, where = UsdShade.Utils.GetBaseNameAndType(attr.GetName())
            if where == UsdShade.AttributeType.Output:
                node.inputs[inp.GetBaseName()] = (kind, Connection(attr.GetPrim().GetName(), base))
                _collect(attr.GetPrim(), nodes)
            elif attr.HasAuthoredValue():
                node.inputs[inp.GetBaseName()] = (kind, _plain(attr.Get()))
                if attr.HasColorSpace():
                    node.color_spaces[inp.GetBaseName()] = str(attr.GetColorSpace())
            break
    node.custom.update(custom_of(prim))


def _plain(value: Any) -> Any:
    from pxr import Sdf

    if isinstance(value, Sdf.AssetPath):
        return Image(Path(value.resolvedPath or value.path))
    if hasattr(value, "__len__") and not isinstance(value, str):
        return tuple(float(x) for x in value)
    return value
