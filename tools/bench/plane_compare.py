"""One material on a wide plane seen at a chosen elevation under a uniform white sky, direct light
only: pathreuse's path tracer against Blender 5.2's Cycles, the mean over the image's middle
quarter. It isolates a BSDF's directional albedo at one view angle, which spheres (blender_compare)
spread over every angle: a dark dielectric at grazing views is where the dielectric layer's
Fresnel shows.

  /usr/bin/python3 -m tools.bench.plane_compare --cycles BPY/bin/python --binary build/pathreuse

Each case is roughness, base colour (grey) and the camera's elevation in degrees. Cycles is a
benchmark peer, not a dependency: --cycles names a Python 3.13 with PyPI's bpy 5.2.3.
"""

import argparse
import base64
import json
import math
import struct
import subprocess
import sys
from pathlib import Path

import numpy as np

from .blender_compare import LUMA, Images

HERE = Path(__file__).resolve().parent
REPO = HERE.parents[1]
CASES = "0.5:0:20,0.5:0:45,0.5:0:80,0.5:0.05:20,0.3:0.05:20,0.5:0.3:20,0.5:0.3:60"


def plane_gltf(path, roughness, base, elevation):
    """A 100 m square plane at y = 0 and a camera 10 m from its centre at `elevation` degrees."""
    s = 50.0
    pos = [(-s, 0, -s), (s, 0, -s), (s, 0, s), (-s, 0, s)]
    data = b"".join(struct.pack("<3f", *p) for p in pos)
    data += b"".join(struct.pack("<3f", 0, 1, 0) for _ in pos)
    data += b"".join(struct.pack("<H", i) for i in (0, 2, 1, 0, 3, 2))
    data += b"\0" * (-len(data) % 4)
    e = math.radians(elevation)
    doc = {
        "asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0, 1]}],
        "nodes": [{"mesh": 0},
                  {"camera": 0, "name": "front", "translation": [0, 10 * math.sin(e), 10 * math.cos(e)],
                   "rotation": [math.sin(-e / 2), 0, 0, math.cos(-e / 2)]}],
        "cameras": [{"type": "perspective",
                     "perspective": {"yfov": 0.3, "aspectRatio": 1.0, "znear": 0.01, "zfar": 1000}}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1}, "indices": 2,
                                    "material": 0}]}],
        "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [base, base, base, 1],
                                                "metallicFactor": 0.0,
                                                "roughnessFactor": roughness}}],
        "buffers": [{"byteLength": len(data),
                     "uri": "data:application/octet-stream;base64," + base64.b64encode(data).decode()}],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 48},
                        {"buffer": 0, "byteOffset": 48, "byteLength": 48},
                        {"buffer": 0, "byteOffset": 96, "byteLength": 12}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
                       "min": [-s, 0, -s], "max": [s, 0, s]},
                      {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC3"},
                      {"bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR"}],
    }
    path.write_text(json.dumps(doc))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--cycles", required=True, help="a Python with bpy 5.2.3")
    ap.add_argument("--binary", default=str(REPO / "build" / "pathreuse"))
    ap.add_argument("--cases", default=CASES, help="roughness:base:elevation, comma-separated")
    ap.add_argument("--spp", type=int, default=512)
    ap.add_argument("--size", type=int, default=64)
    ap.add_argument("--work", default="/tmp/pathreuse-plane-compare")
    a = ap.parse_args()
    images = Images(a.binary, lambda: a.cycles)
    size = ["--width", str(a.size), "--height", str(a.size)]
    q = a.size // 4
    print("| roughness | base | elevation | ours | Cycles | ours / Cycles |")
    print("| ---: | ---: | ---: | ---: | ---: | ---: |")
    for case in a.cases.split(","):
        roughness, base, elevation = (float(x) for x in case.split(":"))
        d = Path(a.work) / case.replace(":", "_")
        d.mkdir(parents=True, exist_ok=True)
        scene = d / "plane.gltf"
        plane_gltf(scene, roughness, base, elevation)
        subprocess.run([a.binary, "render", str(scene), "--camera", "0", "--mode", "pathtrace",
                        "--spp", str(a.spp), "--max-depth", "2", "--env-color", "1,1,1",
                        "--exr-float", "--frames", "0", "--out", str(d / "ours" / "f_%04d.exr"),
                        "-q", *size], check=True)
        subprocess.run([a.cycles, str(HERE / "cycles_frames.py"), str(scene), str(d / "cycles"),
                        "--frames", "0-0", "--spp", str(a.spp), "--max-depth", "2",
                        "--camera", "front", "--world", "1,1,1", *size], check=True,
                       stdout=subprocess.DEVNULL)
        mean = [float((images.read(d / k / "f_0000.exr") @ LUMA)[q:-q, q:-q].mean())
                for k in ("ours", "cycles")]
        print(f"| {roughness:g} | {base:g} | {elevation:g} | {mean[0]:.4f} | {mean[1]:.4f} | "
              f"{mean[0] / mean[1]:.4f} |", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
