# Opens an `sft export` folder in Blender (headless) and writes what Blender read, as JSON, for
# tests/apps/blender_round_trip_test.cc (the "long" Blender round trip) and for users checking an
# export by hand:
#   blender -b --factory-startup --python scripts/blender_check_export.py -- EXPORT_DIR OUT.json
# For model.obj (bpy.ops.wm.obj_import, axes kept as written: up Z, forward Y) and model.glb
# (bpy.ops.import_scene.gltf, needs python3-numpy; glTF is Y-up and Blender turns it back to Z-up)
# it records the mesh (vertex positions, faces as vertex indices with their UVs, in Blender's
# order), the material (what feeds the Principled BSDF's Base Color, Roughness, Metallic and
# Specular: an image texture's file, colour space and size, or a value) and the texels of the
# albedo and roughness images at every face's UV centroid (nearest texel, Blender's raw pixel
# values: 8-bit PNG bytes / 255, no colour management).
import json
import os
import sys

import bpy


def texture_of(socket):
    """The image texture node feeding `socket`, through at most two other nodes, or None."""
    if not socket.is_linked:
        return None
    node = socket.links[0].from_node
    for _ in range(3):
        if node.type == "TEX_IMAGE":
            return node
        linked = [i for i in node.inputs if i.is_linked]
        if not linked:
            return None
        node = linked[0].links[0].from_node
    return None


def socket_info(bsdf, name):
    socket = bsdf.inputs[name]
    node = texture_of(socket)
    if node is not None and node.image is not None:
        image = node.image
        return {
            "image": os.path.basename(image.filepath or image.name),
            "colorspace": image.colorspace_settings.name,
            "size": [image.size[0], image.size[1]],
            "via": socket.links[0].from_node.type,
            "from_socket": socket.links[0].from_socket.name,
        }
    if socket.is_linked:
        return {"node": socket.links[0].from_node.type}
    value = socket.default_value
    return {"value": list(value) if hasattr(value, "__len__") else value}


def texel(image, pixels, u, v):
    w, h = image.size
    x = min(max(int(u * w), 0), w - 1)
    y = min(max(int(v * h), 0), h - 1)  # Blender's row 0 is the bottom row, v up.
    i = (y * w + x) * image.channels
    return pixels[i:i + image.channels]


def object_info(obj):
    mesh = obj.data
    uv = mesh.uv_layers.active
    faces = []
    for poly in mesh.polygons:
        faces.append({
            "v": [mesh.loops[i].vertex_index for i in poly.loop_indices],
            "uv": [list(uv.data[i].uv) for i in poly.loop_indices] if uv else [],
        })
    world = obj.matrix_world
    info = {
        "name": obj.name,
        "vertices": [list(world @ v.co) for v in mesh.vertices],
        "faces": faces,
        "uv_layers": len(mesh.uv_layers),
        "materials": [],
    }
    for material in mesh.materials:
        if material is None or not material.use_nodes:
            continue
        bsdf = next((n for n in material.node_tree.nodes if n.type == "BSDF_PRINCIPLED"), None)
        if bsdf is None:
            continue
        entry = {"name": material.name}
        for key, name in (("base_color", "Base Color"), ("roughness", "Roughness"),
                          ("metallic", "Metallic"), ("specular", "Specular")):
            entry[key] = socket_info(bsdf, name)
        samples = {}
        for key, name in (("base_color", "Base Color"), ("roughness", "Roughness")):
            node = texture_of(bsdf.inputs[name])
            if node is None or node.image is None or not uv:
                continue
            pixels = list(node.image.pixels)
            values = []
            for face in faces:
                u = sum(c[0] for c in face["uv"]) / len(face["uv"])
                v = sum(c[1] for c in face["uv"]) / len(face["uv"])
                values.append([u, v] + list(texel(node.image, pixels, u, v)))
            samples[key] = values
        entry["samples"] = samples
        info["materials"].append(entry)
    return info


def numpy_bool_shim():
    """Debian's Blender 3.4.1 glTF importer uses np.bool, which Debian's numpy 1.24 removed
    (AttributeError in set_poly_smoothing); the alias it meant is the builtin bool."""
    try:
        import numpy
    except ImportError:
        return
    if "bool" not in numpy.__dict__:
        numpy.bool = bool


def import_and_read(importer):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    importer()
    meshes = [o for o in bpy.context.scene.objects if o.type == "MESH"]
    return [object_info(o) for o in meshes]


def main():
    argv = sys.argv[sys.argv.index("--") + 1:]
    export_dir, out_path = argv[0], argv[1]
    report = {"blender": bpy.app.version_string}
    obj = os.path.join(export_dir, "model.obj")
    if os.path.exists(obj):
        report["obj"] = import_and_read(lambda: bpy.ops.wm.obj_import(
            filepath=obj, forward_axis="Y", up_axis="Z"))
    glb = os.path.join(export_dir, "model.glb")
    if os.path.exists(glb):
        numpy_bool_shim()
        try:
            report["glb"] = import_and_read(lambda: bpy.ops.import_scene.gltf(filepath=glb))
        except Exception as e:  # the add-on missing or numpy absent: reported, not fatal.
            report["glb_error"] = str(e).splitlines()[0] if str(e) else type(e).__name__
    with open(out_path + ".tmp", "w") as f:
        json.dump(report, f)
    os.replace(out_path + ".tmp", out_path)


main()
