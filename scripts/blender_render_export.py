# Renders an `sft export` folder's model.obj with Blender Cycles (headless) from the views of an
# sft dataset under the dataset's point lights, so that the picture can be compared with sft's
# render of the same export (tests/apps/blender_render_test.cc; docs/export.md, "Rendering the
# export in Blender"):
#   blender -b --factory-startup --python scripts/blender_render_export.py -- \
#       EXPORT_DIR DATASET_DIR OUT_DIR [--views 0,2] [--spp 32] [--bounces 1] [--seed 0]
#       [--threads 0] [--shader principled|sft] [--specular mtl|f0]
# Writes OUT_DIR/NNN.exr per view (NNN = the view's index in scene.json): linear radiance, RGBA
# float32, alpha = pixel coverage (transparent film, black background), and OUT_DIR/render.json
# (the material Blender built, the settings, the time per view).
#
# The scene follows sft's conventions (docs/dataset.md, docs/design-notes.md "Blender Cycles
# 3.4"), so that nothing but the material can differ:
# - cameras: PINHOLE or SIMPLE_PINHOLE (square pixels); pixel (x, y) covers [x, x+1] x [y, y+1],
#   a box filter one pixel wide, as sft's film. Distortion models are refused.
# - point lights of radiant intensity I (W/sr) become Blender point lights of radius 0 and power
#   4*pi*I watts; a camera-frame light is placed at C + R^T p for each view. Environment lights
#   are refused (not needed for the comparison; a point light makes no light-sampling noise).
# - --bounces counts path segments as sft's --bounces does (1 = direct light only), i.e. Cycles'
#   max_bounces = bounces - 1.
# - the "Standard" view transform and no look, dither or compositing: the EXR holds the render
#   as Cycles computed it (linear, unit exposure); no denoising, no adaptive sampling, no clamping,
#   no light threshold.
# - the mesh is shaded flat (sft uses the geometric normal) with Cycles' shadow-terminator offsets
#   at 0.
# The material: the OBJ importer's Principled BSDF, with one fix: Blender 3.4 tags map_Pr (the
# roughness texture, linear) sRGB, so it is retagged Non-Color. --specular f0 sets the Principled
# Specular input to Ks/0.08 so that its F0 = 0.08 * Specular equals sft's specular weight (what
# the glTF export says through KHR_materials_specular); the default keeps the importer's
# Specular = Ks. --shader sft replaces the Principled BSDF by sft's own BSDF in Cycles nodes
# (Diffuse BSDF of roughness 0, i.e. Lambert, plus a Glossy BSDF, GGX, of colour Ks and the same
# roughness texture: no Fresnel, separable Smith masking, alpha = roughness^2), fed by the same
# image texture nodes: what is left of a difference then is the textures' and the sampling's.
import argparse
import json
import math
import os
import sys
import time

import bpy
import mathutils


def parse_args():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    parser = argparse.ArgumentParser(prog="blender_render_export.py")
    parser.add_argument("export_dir")
    parser.add_argument("dataset_dir")
    parser.add_argument("out_dir")
    parser.add_argument("--views", default="", help="comma-separated view indices (default all)")
    parser.add_argument("--spp", type=int, default=32)
    parser.add_argument("--bounces", type=int, default=1, help="path segments, as sft's --bounces")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--threads", type=int, default=0, help="0 = all cores")
    parser.add_argument("--shader", choices=("principled", "sft"), default="principled")
    parser.add_argument("--specular", choices=("mtl", "f0"), default="mtl")
    return parser.parse_args(argv)


def quaternion_matrix(q):
    """Rotation matrix (rows) of the unit quaternion [w, x, y, z]."""
    n = math.sqrt(sum(c * c for c in q))
    w, x, y, z = (c / n for c in q)
    return [[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]]


def camera_centre(rotation, translation):
    """C = -R^T t."""
    return [-sum(rotation[r][c] * translation[r] for r in range(3)) for c in range(3)]


def setup_render(args):
    scene = bpy.context.scene
    scene.render.engine = "CYCLES"
    cycles = scene.cycles
    cycles.device = "CPU"
    cycles.samples = args.spp
    cycles.use_adaptive_sampling = False
    cycles.use_denoising = False
    cycles.seed = args.seed
    cycles.use_animated_seed = False
    bounces = max(args.bounces - 1, 0)
    cycles.max_bounces = bounces
    cycles.diffuse_bounces = bounces
    cycles.glossy_bounces = bounces
    cycles.transmission_bounces = bounces
    cycles.volume_bounces = 0
    cycles.transparent_max_bounces = 0
    cycles.sample_clamp_direct = 0.0
    cycles.sample_clamp_indirect = 0.0
    cycles.light_sampling_threshold = 0.0
    cycles.blur_glossy = 0.0
    cycles.caustics_reflective = True
    cycles.caustics_refractive = True
    cycles.pixel_filter_type = "BOX"
    cycles.filter_width = 1.0
    cycles.film_exposure = 1.0
    scene.render.film_transparent = True
    scene.render.threads_mode = "FIXED" if args.threads > 0 else "AUTO"
    if args.threads > 0:
        scene.render.threads = args.threads
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    scene.view_settings.exposure = 0.0
    scene.view_settings.gamma = 1.0
    scene.view_settings.use_curve_mapping = False
    scene.render.dither_intensity = 0.0
    scene.render.use_compositing = False
    scene.render.use_sequencer = False
    settings = scene.render.image_settings
    settings.file_format = "OPEN_EXR"
    settings.color_mode = "RGBA"
    settings.color_depth = "32"
    settings.exr_codec = "ZIP"
    world = bpy.data.worlds.new("black")
    world.use_nodes = True
    background = world.node_tree.nodes["Background"]
    background.inputs["Color"].default_value = (0.0, 0.0, 0.0, 1.0)
    background.inputs["Strength"].default_value = 0.0
    scene.world = world


def image_node_of(socket):
    """The image texture node feeding `socket` directly or through one other node, or None."""
    if not socket.is_linked:
        return None
    node = socket.links[0].from_node
    if node.type == "TEX_IMAGE":
        return node
    for other in node.inputs:
        if other.is_linked and other.links[0].from_node.type == "TEX_IMAGE":
            return other.links[0].from_node
    return None


def read_ks(export_dir):
    """The MTL's Ks (its first component): sft's specular weight."""
    with open(os.path.join(export_dir, "model.mtl")) as f:
        for line in f:
            parts = line.split()
            if parts and parts[0] == "Ks":
                return float(parts[1])
    return 0.0


def prepare_material(material, args, ks):
    """Applies the fixes described at the top to one imported material; returns what was done."""
    tree = material.node_tree
    bsdf = next(n for n in tree.nodes if n.type == "BSDF_PRINCIPLED")
    albedo = image_node_of(bsdf.inputs["Base Color"])
    roughness = image_node_of(bsdf.inputs["Roughness"])
    info = {"name": material.name, "distribution": bsdf.distribution}
    if roughness is not None:
        info["roughness_colorspace_imported"] = roughness.image.colorspace_settings.name
        roughness.image.colorspace_settings.name = "Non-Color"
    if args.specular == "f0":
        bsdf.inputs["Specular"].default_value = ks / 0.08
    for name in ("Specular", "Metallic", "Sheen", "Clearcoat", "Subsurface", "Transmission"):
        info[name.lower()] = bsdf.inputs[name].default_value
    if args.shader == "principled":
        info["shader"] = "Principled BSDF"
        return info
    output = next(n for n in tree.nodes if n.type == "OUTPUT_MATERIAL")
    diffuse = tree.nodes.new("ShaderNodeBsdfDiffuse")
    diffuse.inputs["Roughness"].default_value = 0.0
    if albedo is not None:
        tree.links.new(albedo.outputs["Color"], diffuse.inputs["Color"])
    else:
        diffuse.inputs["Color"].default_value = bsdf.inputs["Base Color"].default_value
    shader = diffuse.outputs["BSDF"]
    if ks > 0.0:
        glossy = tree.nodes.new("ShaderNodeBsdfGlossy")
        glossy.distribution = "GGX"
        glossy.inputs["Color"].default_value = (ks, ks, ks, 1.0)
        if roughness is not None:
            tree.links.new(roughness.outputs["Color"], glossy.inputs["Roughness"])
        else:
            glossy.inputs["Roughness"].default_value = bsdf.inputs["Roughness"].default_value
        add = tree.nodes.new("ShaderNodeAddShader")
        tree.links.new(shader, add.inputs[0])
        tree.links.new(glossy.outputs["BSDF"], add.inputs[1])
        shader = add.outputs["Shader"]
    tree.links.new(shader, output.inputs["Surface"])
    info["shader"] = "Diffuse BSDF + Glossy BSDF (GGX)" if ks > 0.0 else "Diffuse BSDF"
    return info


def import_model(export_dir, args):
    bpy.ops.wm.obj_import(filepath=os.path.join(export_dir, "model.obj"), forward_axis="Y",
                          up_axis="Z")
    meshes = [o for o in bpy.context.scene.objects if o.type == "MESH"]
    if len(meshes) != 1:
        raise SystemExit("expected one mesh in model.obj, Blender imported %d" % len(meshes))
    obj = meshes[0]
    mesh = obj.data
    for polygon in mesh.polygons:
        polygon.use_smooth = False
    if mesh.has_custom_normals:
        mesh.free_normals_split()
    obj.cycles.shadow_terminator_offset = 0.0
    obj.cycles.shadow_terminator_geometry_offset = 0.0
    ks = read_ks(export_dir)
    materials = [prepare_material(m, args, ks) for m in mesh.materials if m is not None]
    return obj, {"faces": len(mesh.polygons), "ks": ks, "materials": materials}


def make_camera(scene):
    data = bpy.data.cameras.new("camera")
    data.type = "PERSP"
    data.sensor_fit = "HORIZONTAL"
    data.sensor_width = 36.0
    data.clip_start = 1e-4
    data.clip_end = 1e5
    camera = bpy.data.objects.new("camera", data)
    scene.collection.objects.link(camera)
    scene.camera = camera
    return camera


def place_camera(camera, spec, rotation, centre):
    """Blender's camera from a PINHOLE/SIMPLE_PINHOLE camera and the view's pose."""
    model, params = spec["model"], spec["params"]
    if model == "SIMPLE_PINHOLE":
        fx, fy, cx, cy = params[0], params[0], params[1], params[2]
    elif model == "PINHOLE":
        fx, fy, cx, cy = params
    else:
        raise SystemExit("camera %s: model %s is not supported (PINHOLE, SIMPLE_PINHOLE)" %
                         (spec["id"], model))
    if abs(fx - fy) > 1e-6 * fx:
        raise SystemExit("camera %s: fx != fy is not supported" % spec["id"])
    width, height = spec["width"], spec["height"]
    render = bpy.context.scene.render
    render.resolution_x, render.resolution_y, render.resolution_percentage = width, height, 100
    render.pixel_aspect_x = render.pixel_aspect_y = 1.0
    data = camera.data
    data.lens = fx * data.sensor_width / width
    # With a horizontal sensor fit both shifts are fractions of the image width; Blender's y is up.
    data.shift_x = (0.5 * width - cx) / width
    data.shift_y = (cy - 0.5 * height) / width
    # Blender's camera looks along its -z with +y up; sft's (OpenCV) along +z with +y down.
    world_from_camera = mathutils.Matrix.Identity(4)
    for r in range(3):
        for c in range(3):
            flip = 1.0 if c == 0 else -1.0
            world_from_camera[r][c] = rotation[c][r] * flip
        world_from_camera[r][3] = centre[r]
    camera.matrix_world = world_from_camera


def make_point_light(scene, spec):
    intensity = spec["intensity"]
    if not isinstance(intensity, list):
        intensity = [intensity] * 3
    peak = max(intensity)
    data = bpy.data.lights.new(spec["id"], "POINT")
    data.energy = 4.0 * math.pi * peak
    data.color = [i / peak for i in intensity] if peak > 0 else [0.0, 0.0, 0.0]
    data.shadow_soft_size = 0.0
    data.cycles.cast_shadow = True
    data.cycles.max_bounces = 1024
    light = bpy.data.objects.new(spec["id"], data)
    scene.collection.objects.link(light)
    return light


def main():
    args = parse_args()
    start = time.perf_counter()
    with open(os.path.join(args.dataset_dir, "scene.json")) as f:
        dataset = json.load(f)
    cameras = {c["id"]: c for c in dataset["cameras"]}
    light_specs = {l["id"]: l for l in dataset.get("lights", [])}
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    setup_render(args)
    obj, model = import_model(args.export_dir, args)
    camera = make_camera(scene)
    lights = {}
    for light_id, spec in light_specs.items():
        if spec.get("type", "point") != "point":
            raise SystemExit("light %s: only point lights are supported" % light_id)
        lights[light_id] = make_point_light(scene, spec)
    os.makedirs(args.out_dir, exist_ok=True)
    indices = ([int(v) for v in args.views.split(",")] if args.views
               else list(range(len(dataset["views"]))))
    report = {"blender": bpy.app.version_string, "spp": args.spp, "bounces": args.bounces,
              "seed": args.seed, "shader": args.shader, "specular": args.specular,
              "model": model, "views": []}
    for index in indices:
        view = dataset["views"][index]
        rotation = quaternion_matrix(view["cam_from_world"]["rotation"])
        centre = camera_centre(rotation, view["cam_from_world"]["translation"])
        place_camera(camera, cameras[view["camera"]], rotation, centre)
        for light_id, light in lights.items():
            on = light_id in view.get("lights", [])
            light.hide_render = not on
            spec = light_specs[light_id]
            p = spec["position"]
            if spec.get("frame", "world") == "camera":
                p = [centre[c] + sum(rotation[r][c] * p[r] for r in range(3)) for c in range(3)]
            light.location = p
        scene.render.filepath = os.path.join(args.out_dir, "%03d.exr" % index)
        view_start = time.perf_counter()
        bpy.ops.render.render(write_still=True)
        report["views"].append({"view": index, "image": "%03d.exr" % index,
                                "seconds": time.perf_counter() - view_start})
    report["seconds"] = time.perf_counter() - start
    path = os.path.join(args.out_dir, "render.json")
    with open(path + ".tmp", "w") as f:
        json.dump(report, f, indent=1)
    os.replace(path + ".tmp", path)


main()
