"""Compares one still image of each real glTF asset, rendered by pathreuse's path tracer and by
Blender 5.2's Cycles, under a uniform white sky of radiance 1 and nothing else.

Each asset (a folder of ../shared/scenes, or --scenes) gets a wrapper with a camera that frames
it from the front (tools/scenes/gen_real_scenes.py framed); both renderers render frame 0 of it
at the same size, spp and depth (Cycles through tools/bench/cycles_frames.py: Blender's importer,
colour textures sRGB, CPU, box filter, no denoising or clamping). Over the pixels where either
image differs from the sky by more than 2% (the asset), the tool gives the ratio ours / Cycles of
the mean luminance and of each channel, and the 95th percentile over the 16x16 blocks wholly on
the asset of |ours / Cycles - 1| (block means): the parts that differ show there; and the mean
over the asset's pixels (two pixels in from its outline) of |ours / Cycles - 1| of 3x3 means:
what a normal map's orientation or a texture's lookup changes, which block means average away.
Its parts are its materials: ours renders with `--aov material`, and for each material with at
least --part-pixels pixels two in from the outline, the ratio of the mean luminance; the line
gives the part furthest from Cycles ("parts worst"), --json every part.

  /usr/bin/python3 -m tools.bench.asset_compare --cycles ~/.cache/pathreuse/bpy-5.2.3/bin/python \\
      --binary build/pathreuse --assets StainedGlassLamp,ToyCar --spp 256 --width 256

`coarse-sphere` is no asset of ../shared/scenes but one the tool writes: a Lambertian sphere of
albedo 0.5 (specularFactor 0) of 12 x 6 flat facets with a smooth sphere's vertex normals. Under the
white sky its exact radiance is 0.5 at every point, so its line also gives each renderer against
that (what smooth normals on coarse facets lose or gain: Cycles darkens the facets' edges).

--ours-args passes more options to our renderer, e.g. --ours-args='--shadow-terminator off' (how
much of a difference is the smooth normals' handling).

Cycles is a benchmark peer, not a dependency: --cycles names a Python 3.13 with PyPI's bpy 5.2.3.
Writes WORK/NAME/{ours,cycles}/f_0000.exr, the ratio map WORK/NAME/ratio.png, and with --json the
figures.
"""

import argparse
import json
import os
import shlex
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

from tools.scenes import gltf_writer as gw

from .benchlib import run_tool
from .blender_compare import LUMA, Images, compare, ratio_png

HERE = Path(__file__).resolve().parent
REPO = HERE.parents[1]


COARSE = "coarse-sphere"
COARSE_ALBEDO = 0.5


def coarse_sphere(path):
    """The coarse-sphere asset (the module's docstring) at path."""
    g = gw.Gltf("asset_compare coarse-sphere")
    mat = g.material("lambert-0.5", [COARSE_ALBEDO] * 3, extensions={
        "KHR_materials_specular": {"specularFactor": 0.0}})
    mesh = g.mesh("sphere", [(gw.uv_sphere(1.0, 12, 6), mat)])
    path.parent.mkdir(parents=True, exist_ok=True)
    g.write(str(path), [g.node("sphere", mesh=mesh)], embedded=True)


def wrapper(name, scenes, work):
    """The framed wrapper of asset `name` and its camera's index."""
    src = Path(scenes) / name / f"{name}.gltf"
    if name == COARSE:
        src = Path(work) / name / "source" / f"{name}.gltf"
        coarse_sphere(src)
    if not src.is_file():
        sys.exit(f"asset_compare: {src}: no such asset")
    out = Path(work) / name / f"{name}-framed.gltf"
    run_tool("tools.scenes.gen_real_scenes", ["framed", src, "--out", out], check=True,
             stdout=subprocess.DEVNULL)
    cameras = json.loads(out.read_text())["cameras"]
    return out, len(cameras) - 1


def box3(a):
    """The 3x3 mean of each pixel (edges repeated)."""
    p = np.pad(a, 1, mode="edge")
    return sum(p[y:y + a.shape[0], x:x + a.shape[1]] for y in range(3) for x in range(3)) / 9


def shrink(mask, pixels=2):
    """The mask less its pixels within `pixels` steps (4-neighbour) of its outline."""
    inner = mask.copy()
    for _ in range(pixels):
        p = np.pad(inner, 1, constant_values=False)
        inner = inner & p[:-2, 1:-1] & p[2:, 1:-1] & p[1:-1, :-2] & p[1:-1, 2:]
    return inner


def pixel_deviation(ours, cyc, mask):
    """Mean |ours / Cycles - 1| of the 3x3 means of luminance over mask shrunk by two pixels."""
    inner = shrink(mask)
    a, b = box3(ours @ LUMA), box3(cyc @ LUMA)
    sel = inner & (b > 0)
    return float(np.abs(a[sel] / b[sel] - 1).mean()) if sel.any() else float("nan")


def read_channel(binary, exr, name):
    """One channel of an EXR (e.g. material.ID) as a float array, through exr_compare."""
    with tempfile.TemporaryDirectory() as tmp:
        raw = Path(tmp) / "channel.raw"
        subprocess.run([str(Path(binary).parent / "exr_compare"), "--raw-channel", name, str(exr),
                        str(raw)], check=True)
        with open(raw, "rb") as f:
            w, h = np.fromfile(f, "<u4", 2)
            return np.fromfile(f, "<f4").reshape(int(h), int(w))


def material_names(scene):
    """The wrapper's glTF material names by index."""
    doc = json.loads(Path(scene).read_text())
    return [m.get("name", f"material {i}") for i, m in enumerate(doc.get("materials", []))]


def parts(ours, cyc, mask, ids, names, min_pixels):
    """Per material with at least min_pixels pixels two in from the asset's outline: its name,
    pixel count and ratio ours / Cycles of the mean luminance, furthest from 1 first."""
    inner = shrink(mask)
    yo, yc = ours @ LUMA, cyc @ LUMA
    rows = []
    for k in np.unique(ids[inner]):
        sel = inner & (ids == k)
        n = int(sel.sum())
        if n < min_pixels or not (yc[sel].mean() > 0):
            continue
        i = int(k)
        name = names[i] if 0 <= i < len(names) else f"id {i}"
        rows.append({"material": name, "pixels": n, "ratio": float(yo[sel].mean() / yc[sel].mean())})
    return sorted(rows, key=lambda r: -abs(r["ratio"] - 1))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--assets", default="StainedGlassLamp,ToyCar,DamagedHelmet,FlightHelmet,"
                    "CesiumMan,Fox,BrainStem," + COARSE)
    ap.add_argument("--scenes", default=str(REPO.parent / "shared" / "scenes"))
    ap.add_argument("--binary", default=str(REPO / "build" / "pathreuse"))
    ap.add_argument("--cycles", required=True, help="a Python with bpy 5.2.3")
    ap.add_argument("--spp", type=int, default=256)
    ap.add_argument("--width", type=int, default=256, help="and height (default 256)")
    ap.add_argument("--max-depth", type=int, default=16)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--block", type=int, default=16)
    ap.add_argument("--work", default="/tmp/pathreuse-asset-compare")
    ap.add_argument("--ours-args", default="",
                    help="more options for ours, written with '=' since they start with --: "
                    "--ours-args='--shadow-terminator off'")
    ap.add_argument("--part-pixels", type=int, default=200,
                    help="pixels a material needs to count as a part (default 200)")
    ap.add_argument("--json", help="write the figures here")
    a = ap.parse_args()
    images = Images(a.binary, lambda: a.cycles)
    rows = []
    for name in a.assets.split(","):
        scene, camera = wrapper(name, a.scenes, a.work)
        d = Path(a.work) / name
        size = ["--width", str(a.width), "--height", str(a.width)]
        subprocess.run([a.binary, "render", str(scene), "--allow-outside-uris", "--camera",
                        str(camera), "--mode", "pathtrace", "--spp", str(a.spp), "--max-depth",
                        str(a.max_depth), "--env-color", "1,1,1", "--exr-float", "--frames", "0",
                        "--out", str(d / "ours" / "f_%04d.exr"), "-q", "--aov", "material",
                        *size, *shlex.split(a.ours_args)], check=True,
                       env=dict(os.environ, POCL_MAX_PTHREAD_COUNT=str(a.threads)))
        subprocess.run([a.cycles, str(HERE / "cycles_frames.py"), str(scene), str(d / "cycles"),
                        "--frames", "0-0", "--spp", str(a.spp), "--max-depth", str(a.max_depth),
                        "--threads", str(a.threads), "--camera", "front", "--world", "1,1,1",
                        *size], check=True, stdout=subprocess.DEVNULL)
        ours = images.read(d / "ours" / "f_0000.exr")
        cyc = images.read(d / "cycles" / "f_0000.exr")
        mask = (np.abs(ours - 1).max(axis=2) > 0.02) | (np.abs(cyc - 1).max(axis=2) > 0.02)
        ids = read_channel(a.binary, d / "ours" / "f_0000.exr", "material.ID")
        row = {"asset": name, **compare(ours, cyc, mask, a.block),
               "pixel_deviation": pixel_deviation(ours, cyc, mask),
               "parts": parts(ours, cyc, mask, ids, material_names(scene), a.part_pixels)}
        worst = row["parts"][0] if row["parts"] else {"material": "none", "ratio": float("nan")}
        ratio_png(d / "ratio.png", ours, cyc, mask)
        if name == COARSE:
            inner = shrink(mask)
            row["exact"] = COARSE_ALBEDO
            row["ours_exact"] = float((ours[inner] @ LUMA).mean() / COARSE_ALBEDO)
            row["cycles_exact"] = float((cyc[inner] @ LUMA).mean() / COARSE_ALBEDO)
        rows.append(row)
        print(f"{name:18s} luminance {row['mean_ratio']:.3f}  rgb "
              + " ".join(f"{x:.3f}" for x in row["rgb_ratio"])
              + f"  blocks p95 {row['p95_block']:.3f} max {row['max_block']:.3f}"
              + f"  pixels {row['pixel_deviation']:.4f}"
              + f" ({row['blocks']} blocks, {row['pixels']} px)"
              + f"  parts worst {worst['ratio']:.3f} ({worst['material']}) of {len(row['parts'])}"
              + (f"  exact {row['exact']}: ours {row['ours_exact']:.4f} Cycles "
                 f"{row['cycles_exact']:.4f}" if "exact" in row else ""),
              flush=True)
    if a.json:
        Path(a.json).write_text(json.dumps(rows, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
