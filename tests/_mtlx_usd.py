"""MaterialX documents wrapped in one USD stage, encoded as usd-core's ``usdMtlx`` file
format plugin encodes them (the PyPI wheel of usd-core has no such plugin).

The encoding follows the flattened stages of the USD working group's
``test_assets/MaterialXTest`` (``basicTextured_flatten.usda``): each ``surfacematerial``
becomes a ``Material`` whose ``outputs:mtlx:surface`` reads a ``Shader`` with
``info:id`` = the node definition's name; the surface shader's authored values live on
the Material's interface inputs (``inputs:base_color``) that the shader's inputs connect
to; a ``nodegraph`` becomes a ``NodeGraph`` under the Material whose outputs connect to
its nodes' ``Shader`` prims; a ``filename`` input is an ``asset`` with the file's
``colorSpace`` metadata; the document's ``colorspace`` (``lin_rec709``, ``acescg``)
is the Material's ``UsdColorSpaceAPI`` colour space (by USD's name, ``lin_ap1_scene``).

Used by the foreign-import tests and by ``python tests/_mtlx_usd.py OUT.usda FILE…``.
"""

from __future__ import annotations

import re
import sys
from pathlib import Path

__all__ = ["wrap"]

SDF_TYPE = {
    "float": "Float",
    "integer": "Int",
    "boolean": "Bool",
    "string": "String",
    "filename": "Asset",
    "color3": "Color3f",
    "color4": "Color4f",
    "vector2": "Float2",
    "vector3": "Float3",
    "vector4": "Float4",
    "matrix33": "Matrix3d",
    "matrix44": "Matrix4d",
}
"""MaterialX type → ``Sdf.ValueTypeNames`` attribute (anything else, a closure, is a token)."""


def _slug(name: str) -> str:
    return re.sub(r"[^A-Za-z0-9_]", "_", name) or "_"


def _sdf_type(mx_type: str):
    from pxr import Sdf

    return getattr(Sdf.ValueTypeNames, SDF_TYPE.get(mx_type, "Token"))


def _value(inp, folder: Path, base: Path):
    from pxr import Sdf

    if inp.getType() == "filename":
        path = Path(inp.getResolvedValueString())
        path = path if path.is_absolute() else folder / path
        try:
            return Sdf.AssetPath(str(path.resolve().relative_to(base.resolve())))
        except ValueError:
            return Sdf.AssetPath(str(path.resolve()))
    value = inp.getValue()
    if hasattr(value, "asTuple"):
        return tuple(value.asTuple())
    return value


class _Writer:
    def __init__(self, stage, folder: Path, base: Path) -> None:
        self.stage, self.folder, self.base = stage, folder, base

    def node(self, node, parent, done: dict) -> object:
        """The Shader prim of MaterialX ``node`` under ``parent`` (made once)."""
        from pxr import UsdShade

        key = (str(parent), node.getName())
        if key in done:
            return done[key]
        nodedef = node.getNodeDef()
        shader = UsdShade.Shader.Define(self.stage, parent.AppendChild(_slug(node.getName())))
        done[key] = shader
        shader.SetShaderId(nodedef.getName() if nodedef else node.getCategory())
        outputs = nodedef.getActiveOutputs() if nodedef else []
        for out in outputs or [node]:
            shader.CreateOutput(out.getName() if nodedef else "out", _sdf_type(out.getType()))
        for inp in node.getInputs():
            self.input(shader, inp, parent, done, interface=None)
        return shader

    def input(self, shader, inp, parent, done: dict, interface) -> None:
        """``inp`` on ``shader``: a value (on ``interface`` when given, connected to it),
        or a connection to the node or node graph output it names."""
        import MaterialX as mx

        port = shader.CreateInput(inp.getName(), _sdf_type(inp.getType()))
        graph = inp.getParent().getParent()
        if inp.getInterfaceName() and isinstance(graph, mx.NodeGraph):
            outer = graph.getInput(inp.getInterfaceName())
            if outer is not None and outer.hasValueString():
                port.Set(_value(outer, self.folder, self.base))
            return
        if inp.getNodeGraphString():
            source = self.graph_output(inp, parent, done)
            if source is not None:
                port.ConnectToSource(source)
            return
        upstream = inp.getConnectedNode()
        if upstream is not None:
            out = self.node(upstream, parent, done)
            name = inp.getOutputString() or out.GetOutputs()[0].GetBaseName()
            port.ConnectToSource(out.GetOutput(name))
            return
        if not inp.hasValueString():
            return
        value = _value(inp, self.folder, self.base)
        if interface is not None:
            outer = interface.CreateInput(inp.getName(), _sdf_type(inp.getType()))
            outer.Set(value)
            port.ConnectToSource(outer)
            port = outer
        else:
            port.Set(value)
        space = inp.getActiveColorSpace() if inp.getType() == "filename" else ""
        if space:
            port.GetAttr().SetColorSpace(space)

    def node_with_interface(self, node, material, done: dict):
        """The surface shader: its values on the Material's interface inputs (as usdMtlx)."""
        from pxr import UsdShade

        nodedef = node.getNodeDef()
        shader = UsdShade.Shader.Define(
            self.stage, material.GetPath().AppendChild(_slug(nodedef.getName()))
        )
        shader.SetShaderId(nodedef.getName())
        shader.CreateOutput("surface", _sdf_type("surfaceshader"))
        for inp in node.getInputs():
            self.input(shader, inp, material.GetPath(), done, interface=material)
        return shader

    def graph_output(self, inp, parent, done: dict):
        """The ``NodeGraph`` output an input reads (its graph written under ``parent``)."""
        from pxr import UsdShade

        doc = inp.getDocument()
        graph = doc.getNodeGraph(inp.getNodeGraphString())
        if graph is None:
            return None
        out_name = inp.getOutputString() or graph.getOutputs()[0].getName()
        output = graph.getOutput(out_name)
        prim = UsdShade.NodeGraph.Define(self.stage, parent.AppendChild(_slug(graph.getName())))
        port = prim.CreateOutput(out_name, _sdf_type(output.getType()))
        upstream = output.getConnectedNode()
        if upstream is None:
            return port
        shader = self.node(upstream, prim.GetPath(), done)
        name = output.getOutputString() or shader.GetOutputs()[0].GetBaseName()
        port.ConnectToSource(shader.GetOutput(name))
        return port


def wrap(mtlx_files: list[Path], out: Path) -> list[str]:
    """Write every ``surfacematerial`` of ``mtlx_files`` into the USD file ``out``, one
    ``Scope`` per file under ``/MaterialX``; the Material prim paths, in order."""
    import MaterialX as mx
    from pxr import Usd, UsdGeom, UsdShade

    from lookdev.materials import colour

    library = mx.createDocument()
    mx.loadLibraries(mx.getDefaultDataLibraryFolders(), mx.getDefaultDataSearchPath(), library)
    stage = Usd.Stage.CreateInMemory()
    UsdGeom.SetStageMetersPerUnit(stage, 0.01)  # centimetres, as the usd-wg MaterialXTest stages
    written = []
    for file in mtlx_files:
        file = Path(file)
        doc = mx.createDocument()
        mx.readFromXmlFile(doc, str(file))
        doc.setDataLibrary(library)
        scope = stage.DefinePrim(f"/MaterialX/{_slug(file.stem)}", "Scope").GetPath()
        writer = _Writer(stage, file.parent, out.parent)
        for material_node in doc.getMaterialNodes():
            material = UsdShade.Material.Define(
                stage, scope.AppendChild(_slug(material_node.getName()))
            )
            if doc.getColorSpace():  # the document's colour space names its colour values
                space = Usd.ColorSpaceAPI.Apply(material.GetPrim())
                space.CreateColorSpaceNameAttr(colour.interop_id(doc.getColorSpace()))
            surface_in = material_node.getInput("surfaceshader")
            surface = surface_in.getConnectedNode() if surface_in is not None else None
            if surface is None:
                continue
            done: dict = {}
            shader = writer.node_with_interface(surface, material, done)
            material.CreateSurfaceOutput("mtlx").ConnectToSource(shader.GetOutput("surface"))
            written.append(str(material.GetPath()))
    stage.GetRootLayer().Export(str(out))
    return written


if __name__ == "__main__":
    paths = wrap([Path(p) for p in sys.argv[2:]], Path(sys.argv[1]))
    print(f"{len(paths)} materials in {sys.argv[1]}")
