"""Renders frames exported by tools/bench/scene_export.py with LuxCoreRender 2.11's BIDIRCPU, for
tools/bench/bench_temporal.py --luxcore (a benchmark peer, not a dependency of pathreuse). Run by
a Python that has PyPI's `pyluxcore` 2.11 (Python 3.12, in a virtual environment of its own), with
LD_PRELOAD naming the wheel's libtbbmalloc and libtbbmalloc_proxy (else PoCL aborts in it):

  VENV/bin/python tools/bench/luxcore_frames.py EXPORTDIR OUTDIR --frames A-B --spp N \\
      --width W --height H --max-depth D [--seed S] [--threads T]

Bidirectional path tracing on the CPU, Sobol samples, Russian roulette off (its default biases
the mean), eye and light paths of at most D - 1 segments (pathreuse's --max-depth D counts the
camera's hit and the light's vertex), a box pixel filter one pixel wide, the exported suns as
distant lights, a black world or the exported uniform one. Materials
from the exported Principled inputs, as near as LuxCore's own come: glass where transmission > 0.5,
metal (metal2 with the base colour's Fresnel) where metallic > 0.5, else matte where roughness is
at least 0.95, else glossy2 (diffuse base colour under a specular coat of reflectance 0.04), GGX
alpha = roughness^2; the emission makes an area light. Writes
OUTDIR/f_%04d.exr (linear float RGB) and prints one JSON line per frame: {"frame": f, "render_s":
seconds from the session's start (scene preprocessing included) to its halt at N spp}.
"""

import json
import math
import os
import sys
import time

import numpy as np
import pyluxcore

from peer_args import peer_args


def parse_args():
    return peer_args("luxcore_frames.py", "export", extra=lambda ap: ap.add_argument(
        "--verbose", action="store_true", help="LuxCore's log on stderr"))


def properties(lines):
    p = pyluxcore.Properties()
    p.SetFromString("\n".join(lines))
    return p


def vec(v):
    return " ".join(f"{x:.9g}" for x in v)


def material_props(k, m):
    name = f"scene.materials.m{k}"
    lines = []
    if m["transmission"] > 0.5:
        lines += [f"{name}.type = roughglass" if m["roughness"] > 0.0 else f"{name}.type = glass",
                  f"{name}.kt = {vec(m['base'])}", f"{name}.kr = 1 1 1",
                  f"{name}.interiorior = {m['ior']}", f"{name}.exteriorior = 1"]
        if m["roughness"] > 0.0:
            r = max(m["roughness"] ** 2, 1e-4)
            lines += [f"{name}.uroughness = {r}", f"{name}.vroughness = {r}"]
    elif m["metallic"] > 0.5:
        r = max(m["roughness"] ** 2, 1e-4)
        lines += [f"scene.textures.fc{k}.type = fresnelcolor",
                  f"scene.textures.fc{k}.kr = {vec(m['base'])}",
                  f"{name}.type = metal2", f"{name}.fresnel = fc{k}",
                  f"{name}.uroughness = {r}", f"{name}.vroughness = {r}"]
    elif m["roughness"] >= 0.95:
        lines += [f"{name}.type = matte", f"{name}.kd = {vec(m['base'])}"]
    else:  # a dielectric coat (F0 0.04) over a diffuse base
        r = max(m["roughness"] ** 2, 1e-4)
        lines += [f"{name}.type = glossy2", f"{name}.kd = {vec(m['base'])}",
                  f"{name}.ks = 0.04 0.04 0.04", f"{name}.uroughness = {r}",
                  f"{name}.vroughness = {r}"]
    if max(m["emission"]) > 0.0:
        lines += [f"{name}.emission = {vec(m['emission'])}", f"{name}.emission.gain = 1 1 1",
                  f"{name}.emission.power = 0", f"{name}.emission.efficency = 0",
                  f"{name}.emission.normalizebycolor = 0"]
    return lines


def long_fov(vfov_deg, a):
    """LuxCore's field of view spans the image's longer side."""
    if a.width <= a.height:
        return vfov_deg
    half = math.tan(math.radians(vfov_deg) / 2.0) * a.width / a.height
    return math.degrees(2.0 * math.atan(half))


def build_scene(info, frame, arrays, a):
    scene = pyluxcore.Scene()
    cam = info["frames"][str(frame)]
    props = [
        "scene.camera.type = perspective",
        f"scene.camera.lookat.orig = {vec(cam['eye'])}",
        f"scene.camera.lookat.target = {vec(cam['target'])}",
        f"scene.camera.up = {vec(cam['up'])}",
        f"scene.camera.fieldofview = {long_fov(cam['vfov_deg'], a)}",
    ]
    for k, sun in enumerate(info.get("suns", [])):
        props += [f"scene.lights.sun{k}.type = sharpdistant",
                  f"scene.lights.sun{k}.direction = {vec(sun['direction'])}",
                  f"scene.lights.sun{k}.color = {vec(sun['irradiance'])}",
                  f"scene.lights.sun{k}.gain = 1 1 1"]
    if info.get("world"):
        props += ["scene.lights.world.type = constantinfinite",
                  f"scene.lights.world.color = {vec(info['world'])}",
                  "scene.lights.world.gain = 1 1 1"]
    used = sorted({int(k[1:]) for k in arrays.files if k.startswith("p")})
    for k in used:
        props += material_props(k, info["materials"][k])
    scene.Parse(properties(props))
    for k in used:
        p = np.ascontiguousarray(arrays[f"p{k}"], dtype=np.float32)
        n = np.ascontiguousarray(arrays[f"n{k}"], dtype=np.float32)
        tris = np.arange(len(p), dtype=np.uint32).reshape(-1, 3)
        # pyluxcore takes lists of tuples.
        scene.DefineMesh(f"mesh{k}", list(map(tuple, p.tolist())), list(map(tuple, tris.tolist())),
                         list(map(tuple, n.tolist())), None, None, None)
        scene.Parse(properties([f"scene.objects.o{k}.shape = mesh{k}",
                                f"scene.objects.o{k}.material = m{k}"]))
    return scene


def render(scene, out, a):
    d = a.max_depth - 1
    cfg = properties([
        "renderengine.type = BIDIRCPU",
        "sampler.type = SOBOL",
        f"renderengine.seed = {a.seed}",
        f"path.maxdepth = {d}",
        f"light.maxdepth = {d}",
        "path.russianroulette.depth = 1000",
        "path.russianroulette.cap = 1",
        f"native.threads.count = {a.threads}",
        f"film.width = {a.width}",
        f"film.height = {a.height}",
        "film.filter.type = BOX",
        "film.filter.width = 0.5",
        "film.imagepipelines.0.0.type = NOP",
        "film.outputs.0.type = RGB",
        f"film.outputs.0.filename = {out}",
        f"batch.haltspp = {a.spp}",
    ])
    session = pyluxcore.RenderSession(pyluxcore.RenderConfig(cfg, scene))
    start = time.perf_counter()
    session.Start()
    # Halt conditions are checked as the stats are updated.
    while True:
        session.UpdateStats()
        if session.HasDone():
            break
        time.sleep(0.002)
    secs = time.perf_counter() - start
    session.GetFilm().SaveOutputs()
    session.Stop()
    return secs


def main():
    a = parse_args()
    pyluxcore.Init(lambda msg: print(msg, file=sys.stderr) if a.verbose else None)
    with open(f"{a.export}/scene.json", encoding="utf-8") as f:
        info = json.load(f)
    if info.get("textured"):
        print(f"luxcore_frames: {a.export}: the scene has image textures, which the export "
              "leaves out", file=sys.stderr)
        return 2
    for frame in range(a.first, a.last + 1):
        arrays = np.load(f"{a.export}/f_{frame:04d}.npz")
        scene = build_scene(info, frame, arrays, a)
        secs = render(scene, f"{a.outdir}/f_{frame:04d}.exr", a)
        print(json.dumps({"frame": frame, "render_s": secs}), flush=True)
    return 0


if __name__ == "__main__":
    code = main()
    sys.stdout.flush()
    # pyluxcore 2.11 crashes in its teardown at the interpreter's exit, after every frame is
    # written: leave without it.
    os._exit(code)
