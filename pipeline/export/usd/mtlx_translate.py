"""Standard Surface read as OpenPBR Surface by MaterialX's own translation.

MaterialX 1.39's data library ships the translation graph
``NG_standard_surface_to_open_pbr_surface`` (node definition
``ND_standard_surface_to_open_pbr_surface``, among its BxDF translations). lookdev does
not restate its mapping: MaterialX's ``ShaderTranslator`` puts the translation node in
front of an ``open_pbr_surface`` exactly as it does for a renderer, and the graph behind
the translation node's outputs is then evaluated on the material's constants, node by
node, by the semantics of MaterialX's standard library nodes (:data:`OPS`; MaterialX
Specification, "Standard Nodes"). A node the evaluator does not know is an error naming
it, never a guess: a MaterialX release that changes the graph is read as it is or
refused.

Two departures, both named where they apply:

- Unauthored inputs are given Standard Surface's own defaults before the translation. The
  translation node's defaults differ (``base`` 0.8 × ``base_color`` 1 against Standard
  Surface's ``base`` 1 × ``base_color`` 0.8): a material authoring ``base_color`` alone
  (MaterialX's grey sphere, 0.18) would otherwise translate to ``base_weight`` 0.8, a
  base 20 % darker than the material it came from.
- A connected input (a texture, a procedural) has no constant: every OpenPBR input whose
  graph reads it is returned as connected, for the caller to name.
"""

from __future__ import annotations

from functools import cache
from typing import Any

import numpy as np

from .network import ExportError

__all__ = [
    "CONNECTED",
    "OPS",
    "TRANSLATION",
    "standard_surface_to_openpbr",
]

TRANSLATION = "ND_standard_surface_to_open_pbr_surface"
"""MaterialX's node definition of the Standard Surface → OpenPBR Surface translation."""
STANDARD = "ND_standard_surface_surfaceshader"
GEOMETRY = ("normal", "coat_normal", "tangent")
"""Standard Surface inputs that are geometry, not a value the translation carries."""


class _Connected:
    """A value fed by a network: no constant (:data:`CONNECTED`)."""

    def __repr__(self) -> str:
        return "CONNECTED"


CONNECTED = _Connected()
"""The value of a connected input, and of everything the translation computes from it."""


def _if(test):
    return lambda i: i["in1"] if test(float(i["value1"]), float(i["value2"])) else i["in2"]


OPS = {
    "dot": lambda i: i["in"],
    "convert": lambda i: i["in"],
    "mix": lambda i: i["bg"] * (1.0 - i["mix"]) + i["fg"] * i["mix"],
    "multiply": lambda i: i["in1"] * i["in2"],
    "divide": lambda i: i["in1"] / i["in2"],
    "add": lambda i: i["in1"] + i["in2"],
    "subtract": lambda i: i["in1"] - i["in2"],
    "power": lambda i: i["in1"] ** i["in2"],
    "max": lambda i: np.maximum(i["in1"], i["in2"]),
    "min": lambda i: np.minimum(i["in1"], i["in2"]),
    "clamp": lambda i: np.clip(i["in"], i["low"], i["high"]),
    "dotproduct": lambda i: np.dot(i["in1"], i["in2"]),
    "extract": lambda i: i["in"][int(i["index"])],
    "ifgreater": _if(lambda a, b: a > b),
    "ifgreatereq": _if(lambda a, b: a >= b),
    "ifequal": _if(lambda a, b: a == b),
}
"""MaterialX standard node (category) → its result from its inputs' values (MaterialX
Specification, "Standard Nodes": ``mix`` is bg·(1 − mix) + fg·mix, ``ifgreater`` gives
``in1`` when value1 > value2, ``convert`` between color3 and vector3 keeps the channels)."""


@cache
def _library():
    from .mtlx import _library as library

    return library()


def _value(value: Any) -> Any:
    """A MaterialX value as numpy (vectors and colours) or a plain scalar."""
    if hasattr(value, "asTuple"):
        return np.asarray(value.asTuple(), dtype=np.float64)
    return value


def _plain(value: Any) -> Any:
    if isinstance(value, np.ndarray):
        return value.item() if value.ndim == 0 else tuple(float(v) for v in value)
    if isinstance(value, bool):
        return value
    return float(value) if isinstance(value, int | float | np.floating) else value


def _evaluate(graph, node_name: str, interface, memo: dict) -> Any:
    """The value of node ``node_name`` of the translation graph ``graph``."""
    if node_name in memo:
        return memo[node_name]
    node = graph.getNode(node_name)
    op = OPS.get(node.getCategory())
    if op is None:
        raise ExportError(
            f"MaterialX's {TRANSLATION} uses a {node.getCategory()!r} node ({node_name}), "
            "which lookdev's evaluator of its graph does not know"
        )
    nodedef = node.getNodeDef()
    inputs = {}
    for spec in nodedef.getActiveInputs():
        inp = node.getInput(spec.getName())
        if inp is None:
            value = _value(spec.getValue())
        elif inp.getInterfaceName():
            value = interface(inp.getInterfaceName())
        elif inp.getNodeName():
            value = _evaluate(graph, inp.getNodeName(), interface, memo)
        else:
            value = _value(inp.getValue())
        inputs[spec.getName()] = value
    if any(v is CONNECTED for v in inputs.values()):
        memo[node_name] = CONNECTED
    else:
        memo[node_name] = op(inputs)
    return memo[node_name]


def _mx_value(mx, mx_type: str, value: Any) -> Any:
    if mx_type == "color3":
        return mx.Color3(*(float(v) for v in np.broadcast_to(value, (3,))))
    if mx_type == "boolean":
        return bool(value)
    if mx_type == "integer":
        return int(value)
    return float(value)


def standard_surface_to_openpbr(values: dict[str, Any]) -> tuple[dict[str, Any], list[str]]:
    """OpenPBR Surface inputs of a Standard Surface whose inputs are ``values`` (authored
    constants, or :data:`CONNECTED`), by MaterialX's translation graph; and the notes on
    what it does not carry (an input the translation has no input for, at a value other
    than Standard Surface's default). An OpenPBR input computed from a connected input is
    :data:`CONNECTED`."""
    import MaterialX as mx
    from MaterialX import PyMaterialXGenShader as mx_gen

    from .mtlx import node_defaults

    library = _library()
    doc = mx.createDocument()
    doc.setDataLibrary(library)
    shader = doc.addNode("standard_surface", "standard_surface", "surfaceshader")
    doc.addMaterialNode("material", shader)
    std = library.getNodeDef(STANDARD)
    translated = {i.getName() for i in library.getNodeDef(TRANSLATION).getActiveInputs()}
    defaults = node_defaults(STANDARD)
    connected, notes = set(), []
    for spec in std.getActiveInputs():
        name = spec.getName()
        if name in GEOMETRY or spec.getType() not in ("float", "color3", "boolean", "integer"):
            continue
        value = values.get(name, defaults.get(name))
        if name not in translated:
            if name in values and not _same(values[name], defaults.get(name)):
                notes.append(
                    f"{name} has no input in MaterialX's {TRANSLATION} (not read as OpenPBR)"
                )
            continue
        if value is CONNECTED:
            connected.add(name)
            value = defaults.get(name)
        if value is not None:
            shader.setInputValue(name, _mx_value(mx, spec.getType(), value), spec.getType())
    mx_gen.ShaderTranslator.create().translateShader(shader, "open_pbr_surface")
    surface = next(n for n in doc.getNodes() if n.getCategory() == "open_pbr_surface")
    out, memo = {}, {}
    for inp in surface.getInputs():
        graph_out = doc.getNodeGraph(inp.getNodeGraphString()).getOutput(inp.getOutputString())
        node = graph_out.getConnectedNode()  # the translation node of the ShaderTranslator
        impl = node.getNodeDef().getImplementation()

        def interface(name, node=node):
            if name in connected:
                return CONNECTED
            given = node.getInput(name)
            return _value((given or node.getNodeDef().getInput(name)).getValue())

        value = _evaluate(
            impl, impl.getOutput(graph_out.getOutputString()).getNodeName(), interface, memo
        )
        out[inp.getName()] = value if value is CONNECTED else _plain(value)
    return out, notes


def _same(a: Any, b: Any) -> bool:
    if a is CONNECTED or b is None:
        return False
    return bool(np.allclose(np.asarray(a, dtype=float), np.asarray(b, dtype=float)))
