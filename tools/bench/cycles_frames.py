"""Renders frames of a glTF animation with Blender 5.2's Cycles, for tools/bench/bench_temporal.py
--cycles (a benchmark peer, not a dependency of pathreuse). Run by a Python that has `bpy` 5.2
(PyPI's wheel, Python 3.13, in a virtual environment of its own):

  VENV/bin/python tools/bench/cycles_frames.py SCENE.gltf OUTDIR --frames A-B --spp N \\
      --width W --height H --max-depth D [--seed S] [--threads T] [--camera NAME] [--world R,G,B]
      [--shutter S] [--fps F]

The scene goes through Blender's own glTF importer with its materials as imported (Principled
BSDF; colour textures read as sRGB), lights unconverted (a sun's intensity is its irradiance, as
pathreuse reads it), a black world or one of --world R,G,B, the first camera or the one --camera
names, frame f at time f / 24 s (pathreuse's default --fps; --fps changes it).
Cycles on the CPU: a box pixel filter one pixel wide, no adaptive sampling, denoising, clamping or
path guiding, light tree on, max bounces = D - 2 (pathreuse counts the camera's hit and the light's
vertex in --max-depth), a fixed seed per run (Cycles' seed is not animated: each frame's noise
pattern is the same, as Blender's default). --shutter S turns motion blur on: the shutter open S
frames centred on the frame (Blender's default position), every object's transform and deformation
blurred with 4 motion steps. Writes OUTDIR/f_%04d.exr (linear float) and prints
one JSON line per frame: {"frame": f, "render_s": seconds of bpy.ops.render.render}.
"""

import json
import sys
import time

import bpy

from peer_args import peer_args


def extra_args(ap):
    ap.add_argument("--shutter", type=float, default=0.0, help="motion blur: frames it is open")
    ap.add_argument("--fps", type=int, default=24, help="frame f is at time f / fps")


def parse_args():
    return peer_args("cycles_frames.py", "scene", extra=extra_args)


def first_camera(path, scene, name=None):
    """The camera named `name` (its glTF node's or camera's name), else the file's first."""
    with open(path, encoding="utf-8") as f:
        doc = json.load(f)
    want = name or (doc.get("cameras", [{}])[0].get("name") if doc.get("cameras") else None)
    cams = [o for o in scene.objects if o.type == "CAMERA"]
    if not cams:
        raise SystemExit("cycles_frames: the scene has no camera")
    found = next((o for o in cams if want and want in (o.name, o.data.name)), None)
    if name and found is None:
        raise SystemExit(f"cycles_frames: no camera named {name}")
    return found or cams[0]


def colour_textures_srgb():
    """Blender's importer reads a texture that is both base colour and occlusion as Non-Color;
    as colour (base or emission) glTF says it is sRGB."""
    for mat in bpy.data.materials:
        if not mat.use_nodes:
            continue
        for node in mat.node_tree.nodes:
            if node.type != "BSDF_PRINCIPLED":
                continue
            todo = [node.inputs[n] for n in ("Base Color", "Emission Color")]
            while todo:
                for link in todo.pop().links:
                    up = link.from_node
                    if up.type == "TEX_IMAGE" and up.image is not None:
                        up.image.colorspace_settings.name = "sRGB"
                    todo += [i for i in up.inputs if i.is_linked]


def world(scene, rgb):
    """A uniform world of radiance rgb ("R,G,B"), or black."""
    w = bpy.data.worlds.new("world")
    w.use_nodes = True
    bg = w.node_tree.nodes["Background"]
    if rgb:
        bg.inputs["Color"].default_value = [float(x) for x in rgb.split(",")] + [1.0]
        bg.inputs["Strength"].default_value = 1.0
    else:
        bg.inputs["Strength"].default_value = 0.0
    scene.world = w


def motion_blur(scene, shutter):
    scene.render.use_motion_blur = shutter > 0.0
    if shutter <= 0.0:
        return
    scene.render.motion_blur_shutter = shutter
    scene.render.motion_blur_position = "CENTER"
    for ob in scene.objects:
        ob.cycles.use_motion_blur = True
        ob.cycles.use_deform_motion = True
        ob.cycles.motion_steps = 4


def setup(a):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.fps = a.fps
    scene.render.fps_base = 1.0
    # RAW: a sun's intensity is its irradiance, as pathreuse reads it
    bpy.ops.import_scene.gltf(filepath=a.scene, export_import_convert_lighting_mode="RAW")
    colour_textures_srgb()
    for light in bpy.data.lights:
        if light.type == "SUN":
            light.angle = 0.0  # glTF's directional light is a delta light
    world(scene, a.world)
    scene.camera = first_camera(a.scene, scene, a.camera)
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
    motion_blur(scene, a.shutter)
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
