"""The half of :mod:`.blender` that runs inside Blender's own Python (``bpy``).

Run as ``python blender_side.py REQUEST.json ANSWER.json`` by :func:`.blender.run`; it
imports nothing of lookdev (Blender's interpreter does not have it). Requests:

- ``{"op": "version"}``: the Blender version.
- ``{"op": "read", "usd": PATH, "options": {…}}``: import ``PATH`` with Blender's USD
  importer (its defaults, updated by ``options``) and describe what arrived: every
  material's Principled BSDF inputs (a value, or the chain of nodes feeding it down to an
  image's file and colour space), its custom properties, and every mesh's materials.
- ``{"op": "render", …}``: see :func:`render` (the DCC-vs-proof bench).
"""

from __future__ import annotations

import json
import math
import sys
from typing import Any

__all__ = ["PRINCIPLED_INPUTS", "main"]

PRINCIPLED_INPUTS = (
    "Base Color",
    "Metallic",
    "Roughness",
    "IOR",
    "Alpha",
    "Specular IOR Level",
    "Specular Tint",
    "Anisotropic",
    "Coat Weight",
    "Coat Roughness",
    "Emission Color",
    "Emission Strength",
    "Sheen Weight",
    "Subsurface Weight",
    "Transmission Weight",
    "Normal",
)
"""The Principled BSDF inputs :func:`read` reports (Blender 4.x names)."""


def _plain(value: Any) -> Any:
    try:
        return [float(x) for x in value]
    except TypeError:
        return float(value)


def _feed(socket: Any) -> dict[str, Any]:
    """What drives an input socket: its value, or the nodes upstream to an image."""
    if not socket.is_linked:
        return {"value": _plain(socket.default_value)} if hasattr(socket, "default_value") else {}
    chain, image = [], None
    link = socket.links[0]
    while link is not None:
        node = link.from_node
        chain.append({"node": node.bl_idname, "output": link.from_socket.name})
        if node.bl_idname == "ShaderNodeTexImage":
            img = node.image
            image = None
            if img is not None:
                image = {
                    "name": img.name,
                    "file": img.filepath,
                    "source_path": img.get("usd_source_path", ""),
                    "packed": img.packed_file is not None,
                    "colorspace": img.colorspace_settings.name,
                    "tiled": img.source == "TILED",
                }
            break
        upstream = [s for s in node.inputs if s.is_linked]
        link = upstream[0].links[0] if upstream else None
    return {"chain": chain, "image": image}


def _custom(idblock: Any) -> dict[str, Any]:
    out = {}
    for key in idblock.keys():
        value = idblock[key]
        out[key] = value if isinstance(value, str | int | float) else str(value)
    return out


def _import(bpy: Any, path: str, options: dict[str, Any]) -> None:
    bpy.ops.wm.read_factory_settings(use_empty=True)
    result = bpy.ops.wm.usd_import(filepath=path, **options)
    if "FINISHED" not in result:
        raise RuntimeError(f"Blender's USD import of {path} returned {sorted(result)}")


def read(bpy: Any, request: dict[str, Any]) -> dict[str, Any]:
    """Import a USD file and describe its materials and meshes (module docstring)."""
    _import(bpy, request["usd"], request.get("options", {}))
    materials = {}
    for mat in bpy.data.materials:
        if mat.node_tree is None:
            continue
        principled = [n for n in mat.node_tree.nodes if n.bl_idname == "ShaderNodeBsdfPrincipled"]
        inputs = {}
        if principled:
            node = principled[0]
            inputs = {name: _feed(node.inputs[name]) for name in PRINCIPLED_INPUTS}
        materials[mat.name] = {
            "principled": bool(principled),
            "inputs": inputs,
            "custom": _custom(mat),
            "blend": getattr(mat, "surface_render_method", ""),
        }
    meshes = {
        obj.name: [slot.material.name for slot in obj.material_slots if slot.material]
        for obj in bpy.data.objects
        if obj.type == "MESH"
    }
    return {"version": bpy.app.version_string, "materials": materials, "meshes": meshes}


def render(bpy: Any, request: dict[str, Any]) -> dict[str, Any]:
    """Render materials of a USD file in Cycles, one EXR each (scene-linear).

    ``request``: ``usd``; ``materials`` (names); ``out`` (folder); ``environment`` (a
    lat-long EXR already in Blender's convention: u from +x towards +y … and v = 1 at
    the zenith); ``camera`` {``origin``, ``target``, ``fov_x_deg``} and ``objects``
    [{``kind``: ``sphere`` | ``ply`` | ``plane``, ``matrix`` (4×4 row-major, Blender's
    z-up world), ``file`` (ply), ``albedo`` (a grey diffuse instead of the material)}],
    ``resolution`` [w, h], ``spp``, ``max_bounces``, ``seed``, ``threads``.
    """
    from mathutils import Matrix, Vector

    _import(bpy, request["usd"], {"import_all_materials": True})
    for obj in list(bpy.data.objects):
        bpy.data.objects.remove(obj, do_unlink=True)
    scene = bpy.context.scene
    scene.render.engine = "CYCLES"
    cycles = scene.cycles
    cycles.device = "CPU"
    cycles.samples = int(request["spp"])
    cycles.use_adaptive_sampling = False
    cycles.use_denoising = False
    cycles.seed = int(request.get("seed", 0))
    cycles.max_bounces = cycles.diffuse_bounces = cycles.glossy_bounces = int(
        request["max_bounces"]
    )
    cycles.transmission_bounces = cycles.transparent_max_bounces = int(request["max_bounces"])
    cycles.volume_bounces = 0
    # What Mitsuba's path tracer does: no clamping, no glossy filter, caustics kept.
    cycles.sample_clamp_direct = cycles.sample_clamp_indirect = 0.0
    cycles.blur_glossy = 0.0
    cycles.caustics_reflective = cycles.caustics_refractive = True
    cycles.pixel_filter_type = "BOX"
    scene.render.filter_size = 1.0
    scene.render.threads_mode = "FIXED"
    scene.render.threads = int(request.get("threads", 1))
    width, height = request["resolution"]
    scene.render.resolution_x, scene.render.resolution_y = int(width), int(height)
    scene.render.resolution_percentage = 100
    scene.render.film_transparent = False
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    scene.view_settings.exposure = 0.0
    scene.view_settings.gamma = 1.0
    settings = scene.render.image_settings
    settings.file_format = "OPEN_EXR"
    settings.color_depth = "32"
    settings.color_mode = "RGB"
    settings.exr_codec = "ZIP"

    world = bpy.data.worlds.new("lookdev_environment")
    scene.world = world
    world.use_nodes = True
    nodes = world.node_tree.nodes
    env = nodes.new("ShaderNodeTexEnvironment")
    env.image = bpy.data.images.load(request["environment"])
    env.image.colorspace_settings.name = "Linear Rec.709"
    env.interpolation = "Linear"
    background = nodes["Background"]
    world.node_tree.links.new(env.outputs["Color"], background.inputs["Color"])
    background.inputs["Strength"].default_value = 1.0

    cam_data = bpy.data.cameras.new("camera")
    cam_data.sensor_fit = "HORIZONTAL"
    cam_data.angle_x = math.radians(request["camera"]["fov_x_deg"])
    cam_data.clip_start, cam_data.clip_end = 0.01, 1000.0
    cam = bpy.data.objects.new("camera", cam_data)
    scene.collection.objects.link(cam)
    origin = Vector(request["camera"]["origin"])
    cam.location = origin
    direction = Vector(request["camera"]["target"]) - origin
    cam.rotation_euler = direction.to_track_quat("-Z", "Y").to_euler()
    scene.camera = cam

    shaded = []
    for i, spec in enumerate(request["objects"]):
        if spec["kind"] == "sphere":
            bpy.ops.mesh.primitive_uv_sphere_add(segments=256, ring_count=128, radius=1.0)
            obj = bpy.context.active_object
            bpy.ops.object.shade_smooth()
        elif spec["kind"] == "plane":
            bpy.ops.mesh.primitive_plane_add(size=2.0)
            obj = bpy.context.active_object
        else:
            bpy.ops.wm.ply_import(filepath=spec["file"], forward_axis="Y", up_axis="Z")
            obj = bpy.context.active_object
            bpy.ops.object.shade_smooth()
        obj.name = f"object_{i}"
        if obj.type == "MESH" and obj.data.uv_layers:
            # The USD importer names a mesh's UV map after its primvar, and lookdev's
            # texture readers ask for "st".
            obj.data.uv_layers[0].name = "st"
        if "uv_frame" in spec:
            _mitsuba_sphere_uv(obj, Matrix(spec["uv_frame"]))
        obj.matrix_world = Matrix(spec["matrix"])
        if "albedo" in spec:
            grey = bpy.data.materials.new(f"grey_{i}")
            grey.use_nodes = True
            bsdf = grey.node_tree.nodes["Principled BSDF"]
            bsdf.inputs["Base Color"].default_value = (*[spec["albedo"]] * 3, 1.0)
            bsdf.inputs["Roughness"].default_value = 1.0
            bsdf.inputs["Specular IOR Level"].default_value = 0.0
            obj.data.materials.append(grey)
        else:
            shaded.append(obj)

    frames = {}
    for name in request["materials"]:
        material = bpy.data.materials.get(name)
        if material is None:
            raise RuntimeError(f"the USD import has no material {name}")
        for obj in shaded:
            obj.data.materials.clear()
            obj.data.materials.append(material)
        path = f"{request['out']}/{name}.exr"
        scene.render.filepath = path
        bpy.ops.render.render(write_still=True)
        frames[name] = path
    return {"version": bpy.app.version_string, "frames": frames}


def _mitsuba_sphere_uv(obj: Any, frame: Any) -> None:
    """Mitsuba's sphere parametrisation (its ``sphere`` shape: u = atan2(y, x) / 2π,
    v = θ / π with θ from +z, in the sphere's own frame) as the mesh's st. ``frame`` takes
    Blender's object coordinates to that frame. Mitsuba's bitmap puts a map's row 0 at
    v = 0 and lookdev's maps are row 0 at st t = 0 (bottom-up), so t = v (not 1 − v).

    The mesh is first turned so that its poles lie on the frame's z axis: its rings are
    then Mitsuba's rings, and only the faces at the seam (kept on one side) and at the
    poles (u of the pole vertex taken from the face's others) need care."""
    mesh = obj.data
    mesh.transform(frame.inverted().to_4x4())
    layer = mesh.uv_layers["st"]
    for poly in mesh.polygons:
        uvs, poles = [], []
        for k, loop in enumerate(poly.loop_indices):
            p = frame @ mesh.vertices[mesh.loops[loop].vertex_index].co
            u = (math.atan2(p.y, p.x) / (2 * math.pi)) % 1.0
            theta = math.acos(max(-1.0, min(1.0, p.z / max(p.length, 1e-12))))
            if math.hypot(p.x, p.y) < 1e-6:
                poles.append(k)
            uvs.append([u, theta / math.pi])
        others = [uv[0] for k, uv in enumerate(uvs) if k not in poles]
        if others and max(others) - min(others) > 0.5:
            for uv in uvs:  # a face across the seam: keep it on one side
                uv[0] += 1.0 if uv[0] < 0.5 else 0.0
            others = [uv[0] for k, uv in enumerate(uvs) if k not in poles]
        for k in poles:
            uvs[k][0] = sum(others) / len(others) if others else 0.0
        for loop, uv in zip(poly.loop_indices, uvs, strict=True):
            layer.data[loop].uv = uv


def main(argv: list[str]) -> int:
    """Answer the request file ``argv[1]`` into ``argv[2]``."""
    import bpy

    with open(argv[1]) as f:
        request = json.load(f)
    op = request["op"]
    if op == "version":
        answer: dict[str, Any] = {"version": bpy.app.version_string}
    elif op == "read":
        answer = read(bpy, request)
    elif op == "render":
        answer = render(bpy, request)
    else:
        raise SystemExit(f"unknown op {op!r}")
    with open(argv[2], "w") as f:
        json.dump(answer, f)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
