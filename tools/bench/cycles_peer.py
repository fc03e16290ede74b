"""Renders a glTF scene with Blender Cycles (Debian's `blender` package) under the light
transport of `pathreuse render --force-diffuse`: every material becomes a Lambert surface of its
base colour plus its emission, no world light, a box pixel filter one pixel wide, no clamping,
no denoising, no adaptive sampling, Cycles' max bounces = --max-depth - 2. For benchmarks only
(tools/bench/bench_sampling.py --cycles): Blender is not a dependency of pathreuse.

  blender -b --factory-startup --python tools/bench/cycles_peer.py -- SCENE.gltf OUT.exr \\
      --width W --height H --spp N --max-depth D [--seed S] [--threads T]

Prints one JSON line: {"render_s": ..., "width": ..., ...}. Debian 12's numpy lacks np.bool,
which the glTF importer of Blender 3.4 still uses; it is put back before the import.
"""

import argparse
import json
import sys
import time

import bpy
import numpy as np

if not hasattr(np, "bool"):
    np.bool = bool  # Blender 3.4's glTF importer on numpy >= 1.24


def args_after_dashes():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    ap = argparse.ArgumentParser(prog="cycles_peer.py")
    ap.add_argument("scene")
    ap.add_argument("out")
    ap.add_argument("--width", type=int, required=True)
    ap.add_argument("--height", type=int, required=True)
    ap.add_argument("--spp", type=int, required=True)
    ap.add_argument("--max-depth", type=int, required=True)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--threads", type=int, default=2)
    return ap.parse_args(argv)


def first_camera_name(path):
    with open(path, encoding="utf-8") as f:
        doc = json.load(f)
    cams = doc.get("cameras", [])
    return cams[0].get("name") if cams else None


def diffuse_only(mat):
    """Replaces the material's surface by Lambert(base colour) + its emission."""
    if not mat.use_nodes:
        return
    nt = mat.node_tree
    principled = next((n for n in nt.nodes if n.type == "BSDF_PRINCIPLED"), None)
    output = next((n for n in nt.nodes if n.type == "OUTPUT_MATERIAL"), None)
    if principled is None or output is None:
        return
    diffuse = nt.nodes.new("ShaderNodeBsdfDiffuse")
    base = principled.inputs["Base Color"]
    if base.is_linked:
        nt.links.new(base.links[0].from_socket, diffuse.inputs["Color"])
    else:
        diffuse.inputs["Color"].default_value = base.default_value
    surface = diffuse.outputs["BSDF"]
    emit_in = principled.inputs["Emission"]
    strength = principled.inputs["Emission Strength"].default_value
    emits = emit_in.is_linked or (max(emit_in.default_value[:3]) > 0.0 and strength > 0.0)
    if emits:
        emission = nt.nodes.new("ShaderNodeEmission")
        if emit_in.is_linked:
            nt.links.new(emit_in.links[0].from_socket, emission.inputs["Color"])
        else:
            emission.inputs["Color"].default_value = emit_in.default_value
        emission.inputs["Strength"].default_value = strength
        add = nt.nodes.new("ShaderNodeAddShader")
        nt.links.new(diffuse.outputs["BSDF"], add.inputs[0])
        nt.links.new(emission.outputs["Emission"], add.inputs[1])
        surface = add.outputs["Shader"]
    nt.links.new(surface, output.inputs["Surface"])


def main():
    a = args_after_dashes()
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.import_scene.gltf(filepath=a.scene)
    scene = bpy.context.scene
    for mat in bpy.data.materials:
        diffuse_only(mat)
    world = bpy.data.worlds.new("black")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.0
    scene.world = world
    want = first_camera_name(a.scene)
    cams = [o for o in scene.objects if o.type == "CAMERA"]
    if not cams:
        raise SystemExit("cycles_peer: the scene has no camera")
    scene.camera = next((o for o in cams if want and o.data.name == want), cams[0])
    scene.frame_set(0)

    scene.render.engine = "CYCLES"
    c = scene.cycles
    c.device = "CPU"
    c.samples = a.spp
    c.use_adaptive_sampling = False
    c.use_denoising = False
    c.seed = a.seed
    bounces = max(0, a.max_depth - 2)
    c.max_bounces = c.diffuse_bounces = c.glossy_bounces = c.transmission_bounces = bounces
    c.transparent_max_bounces = 0
    c.volume_bounces = 0
    c.sample_clamp_direct = 0.0
    c.sample_clamp_indirect = 0.0
    c.caustics_reflective = c.caustics_refractive = True
    c.blur_glossy = 0.0
    c.light_sampling_threshold = 0.0
    c.pixel_filter_type = "BOX"
    c.filter_width = 1.0
    scene.render.threads_mode = "FIXED"
    scene.render.threads = a.threads
    scene.render.resolution_x = a.width
    scene.render.resolution_y = a.height
    scene.render.resolution_percentage = 100
    scene.render.film_transparent = False
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    scene.view_settings.exposure = 0.0
    scene.view_settings.gamma = 1.0
    img = scene.render.image_settings
    img.file_format = "OPEN_EXR"
    img.color_depth = "32"
    img.exr_codec = "ZIP"
    scene.render.filepath = a.out
    start = time.perf_counter()
    bpy.ops.render.render(write_still=True)
    took = time.perf_counter() - start
    print(json.dumps({"render_s": took, "width": a.width, "height": a.height, "spp": a.spp,
                      "bounces": bounces, "camera": scene.camera.data.name}))


main()
