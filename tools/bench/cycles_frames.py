"""Renders frames of a glTF animation with Blender 5.2's Cycles, for tools/bench/bench_temporal.py
--cycles (a benchmark peer, not a dependency of pathreuse). Run by a Python that has `bpy` 5.2
(PyPI's wheel, Python 3.13, in a virtual environment of its own):

  VENV/bin/python tools/bench/cycles_frames.py SCENE.gltf OUTDIR --frames A-B --spp N \\
      --width W --height H --max-depth D [--seed S] [--threads T]

The scene goes through Blender's own glTF importer with its materials as imported (Principled
BSDF), a black world, the first camera, frame f at time f / 24 s (pathreuse's default --fps).
Cycles on the CPU: a box pixel filter one pixel wide, no adaptive sampling, denoising, clamping or
path guiding, light tree on, max bounces = D - 2 (pathreuse counts the camera's hit and the light's
vertex in --max-depth), a fixed seed per run (Cycles' seed is not animated: each frame's noise
pattern is the same, as Blender's default). Writes OUTDIR/f_%04d.exr (linear float) and prints
one JSON line per frame: {"frame": f, "render_s": seconds of bpy.ops.render.render}.
"""

import json
import sys
import time

import bpy

from peer_args import peer_args


def parse_args():
    return peer_args("cycles_frames.py", "scene")


def first_camera(path, scene):
    with open(path, encoding="utf-8") as f:
        doc = json.load(f)
    want = doc.get("cameras", [{}])[0].get("name") if doc.get("cameras") else None
    cams = [o for o in scene.objects if o.type == "CAMERA"]
    if not cams:
        raise SystemExit("cycles_frames: the scene has no camera")
    return next((o for o in cams if want and o.data.name == want), cams[0])


def setup(a):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.fps = 24
    scene.render.fps_base = 1.0
    bpy.ops.import_scene.gltf(filepath=a.scene)
    world = bpy.data.worlds.new("black")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.0
    scene.world = world
    scene.camera = first_camera(a.scene, scene)
    scene.render.engine = "CYCLES"
    c = scene.cycles
    c.device = "CPU"
    c.samples = a.spp
    c.use_adaptive_sampling = False
    c.use_denoising = False
    c.use_guiding = False
    c.use_light_tree = True
    c.seed = a.seed
    c.use_animated_seed = False
    bounces = max(0, a.max_depth - 2)
    c.max_bounces = c.diffuse_bounces = c.glossy_bounces = c.transmission_bounces = bounces
    c.transparent_max_bounces = 8
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
    return scene


def main():
    a = parse_args()
    scene = setup(a)
    for f in range(a.first, a.last + 1):
        scene.frame_set(f)
        scene.render.filepath = f"{a.outdir}/f_{f:04d}.exr"
        start = time.perf_counter()
        bpy.ops.render.render(write_still=True)
        print(json.dumps({"frame": f, "render_s": time.perf_counter() - start}), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
