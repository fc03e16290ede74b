"""Motion blur (--shutter) against Blender 5.2's Cycles with motion blur on, and what it costs.

  /usr/bin/python3 -m tools.bench.bench_motion_blur --build build --cycles BPY/bin/python

The scenes: the Virtual City's camera 6 at frame 204 (45 moving cars and a moving camera;
tools/scenes/gen_real_scenes.py vc, as bench_animations makes it), the same at 2 fps,
CesiumMan walking and the Fox looking round (skinned; gen_real_scenes framed) and BrainStem on its
stage under the orbiting camera, at 2 fps. Both
renderers path trace the frame at --spp with the shutter open each of --shutters frames, centred
(Blender's default). Per shutter: our mean over Cycles', and
over 16x16 blocks the share within 2% of Cycles' and the median and 95th-percentile deviation, for
the blurred pair and, as the control that shows the blur is measured at all, our sharp frame
against Cycles' blurred one; then the cost of the shutter over a sharp frame at 4 spp (median
seconds per frame of frames after the first). With --cost-runs N the sharp and blurred runs
alternate N times and the cost is the median of the pairs' ratios (the machine's drift cancels in
a pair); --cost-only measures that alone, without Cycles. Needs numpy, hence /usr/bin/python3.

  /usr/bin/python3 -m tools.bench.bench_motion_blur --build build --cost-only --cost-runs 5 \
      --shutters 0.5 --scenes cesiumman-2fps,fox-2fps
"""

import argparse
import json
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

from .benchlib import REPO, median

SHARED = REPO.parent / "shared" / "scenes"
BENCH = REPO / "tools" / "bench"

# key: (wrapper kind, source, our camera index, its name for Cycles, frame, fps, world, size)
SCENES = {
    "vc-cam6": ("vc", "VC/VC.gltf", 6, "camera6", 204, 24, "0.5,0.6,0.8", (160, 96)),
    # The same moment at 2 fps: a shutter of half a frame is a quarter second, metres of motion.
    "vc-cam6-2fps": ("vc", "VC/VC.gltf", 6, "camera6", 17, 2, "0.5,0.6,0.8", (160, 96)),
    # Deformation blur: CesiumMan walking (a skin), framed from the front, a quarter second open.
    "cesiumman-2fps": ("framed", "CesiumMan/CesiumMan.gltf", 0, "front", 1, 2, "1,1,1",
                       (128, 128)),
    # The Fox looking round (its first animation, "Survey"; skinned), a second in.
    "fox-2fps": ("framed", "Fox/Fox.gltf", 0, "front", 2, 2, "1,1,1", (128, 128)),
    # BrainStem (61,666 skinned triangles) on its stage, the orbiting camera, two seconds in.
    "brainstem-2fps": ("brainstem", "BrainStem/BrainStem.gltf", 1, "orbit", 4, 2, "0.8,0.85,1.0",
                       (160, 120)),
}


def parse_args():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--build", default="build", help="the folder with pathreuse and exr_compare")
    ap.add_argument("--cycles", help="a Python with bpy 5.2 (Blender's Cycles)")
    ap.add_argument("--cost-runs", type=int, default=1,
                    help="paired sharp / blurred runs for the cost (the median of their ratios)")
    ap.add_argument("--cost-only", action="store_true",
                    help="the cost of the shutter alone (no images, no Cycles)")
    ap.add_argument("--fps", type=int, help="this frame rate instead of each scene's own")
    ap.add_argument("--spp", type=int, default=512, help="samples per pixel of the compared frames")
    ap.add_argument("--shutters", default="0.5,2", help="frames the shutter is open, A,B,...")
    ap.add_argument("--work", default="out/bench-motion-blur")
    ap.add_argument("--scenes", default=",".join(SCENES))
    args = ap.parse_args()
    if not args.cost_only and not args.cycles:
        ap.error("--cycles is needed unless --cost-only")
    return args


def wrapper(kind, source, work):
    src = SHARED / source
    if not src.is_file():
        sys.exit(f"bench_motion_blur: {src} not found: put ../shared/scenes beside the project")
    out = work / kind / f"{src.stem}-{kind}.gltf"
    if not out.is_file():
        subprocess.run([sys.executable, "-m", "tools.scenes.gen_real_scenes", kind, str(src),
                        "--out", str(out)], cwd=REPO, check=True)
    return out


def read(build, exr):
    with tempfile.TemporaryDirectory() as tmp:
        raw = Path(tmp) / "img.raw"
        subprocess.run([str(build / "exr_compare"), "--raw", str(exr), str(raw)], check=True)
        with open(raw, "rb") as f:
            w, h = np.fromfile(f, "<u4", 2)
            return np.fromfile(f, "<f4").reshape(int(h), int(w), 3).astype(np.float64)


def ours(args, sc, spp, shutter, out, stats=None, frames=None):
    scene, cam, frame, fps, world, size = sc
    cmd = [str(args.build / "pathreuse"), "render", str(scene), "--allow-outside-uris", "--fps",
           str(fps),
           "--camera", str(cam), "--env-color", world, "--mode", "pathtrace", "--spp", str(spp),
           "--width", str(size[0]), "--height", str(size[1]), "--frames", frames or str(frame),
           "--shutter", str(shutter), "--exr-float", "--quiet", "--out", str(out / "f_%04d.exr")]
    if stats:
        cmd += ["--stats", str(stats)]
    subprocess.run(cmd, check=True)
    return out / f"f_{frame:04d}.exr"


def cycles(args, sc, name, shutter, out):
    scene, _, frame, fps, world, size = sc
    exr = out / f"f_{frame:04d}.exr"
    if not exr.is_file():
        subprocess.run([args.cycles, str(BENCH / "cycles_frames.py"), str(scene), str(out),
                        "--frames", str(frame), "--spp", str(args.spp), "--width", str(size[0]),
                        "--height", str(size[1]), "--max-depth", "8", "--camera", name, "--world",
                        world, "--shutter", str(shutter), "--fps", str(fps)], check=True,
                       capture_output=True)
    return exr


def blocks(a, b, n=16):
    """Per 16x16 block (luminance): a's mean over b's less 1, where b's is not black."""
    lum = np.array([0.2126, 0.7152, 0.0722])
    la, lb = a @ lum, b @ lum
    devs = []
    for y in range(0, a.shape[0] - n + 1, n):
        for x in range(0, a.shape[1] - n + 1, n):
            mb = lb[y:y + n, x:x + n].mean()
            if mb > 1e-3:
                devs.append(la[y:y + n, x:x + n].mean() / mb - 1.0)
    d = np.abs(np.array(devs))
    return {"mean": float(la.mean() / lb.mean()), "within_2pct": float((d <= 0.02).mean()),
            "median_dev": float(np.median(d)), "p95_dev": float(np.percentile(d, 95)),
            "blocks": len(devs)}


def cost(args, sc, shutter_open, work):
    """Median seconds per frame at 4 spp, sharp and with the shutter open (frames 1..5 of 6), over
    --cost-runs alternating runs, and the median of the runs' ratios."""
    walls, ratios = {0.0: [], shutter_open: []}, []
    for _ in range(args.cost_runs):
        for shutter in (0.0, shutter_open):
            stats = work / f"cost-{shutter}.jsonl"
            stats.unlink(missing_ok=True)
            first = max(0, sc[2] - 3)
            ours(args, sc, 4, shutter, work / "cost", stats, f"{first}-{first + 5}")
            lines = [json.loads(x) for x in stats.read_text().splitlines()]
            walls[shutter].append(median([x["wall_s"] for x in lines[1:]]))
        ratios.append(walls[shutter_open][-1] / walls[0.0][-1])
    return median(walls[0.0]), median(walls[shutter_open]), median(ratios)


def main():
    args = parse_args()
    args.build = (REPO / args.build).resolve()
    work = (REPO / args.work).resolve()
    rows = {}
    for key in args.scenes.split(","):
        kind, source, cam, name, frame, fps, world, size = SCENES[key]
        if args.fps:  # the same moment at another frame rate
            frame, fps = round(frame * args.fps / fps), args.fps
        sc = (wrapper(kind, source, work), cam, frame, fps, world, size)
        d = work / key
        if args.cost_only:
            for shutter in (float(x) for x in args.shutters.split(",")):
                sharp_s, blur_s, ratio = cost(args, sc, shutter, d)
                print(json.dumps({"scene": key, "fps": fps, "shutter": shutter, "sharp_s": sharp_s,
                                  "shutter_s": blur_s, "cost": ratio}), flush=True)
            continue
        sharp = read(args.build, ours(args, sc, args.spp, 0.0, d / "ours-sharp"))
        for shutter in (float(x) for x in args.shutters.split(",")):
            blur = read(args.build, ours(args, sc, args.spp, shutter, d / f"ours-{shutter}"))
            peer = read(args.build, cycles(args, sc, name, shutter,
                                           d / f"cycles-{args.spp}-{shutter}"))
            sharp_s, blur_s, ratio = cost(args, sc, shutter, d)
            row = {"blurred": blocks(blur, peer), "sharp_vs_blurred": blocks(sharp, peer),
                   "sharp_s": sharp_s, "shutter_s": blur_s, "cost": ratio}
            rows[(key, shutter)] = row
            print(json.dumps({"scene": key, "shutter": shutter, **row}), flush=True)
    if args.cost_only:
        return 0
    print("| scene | shutter | mean vs Cycles | 16x16 blocks within 2% | median / p95 deviation "
          "| our sharp frame: within 2%, p95 | cost of the shutter |")
    print("|---|---:|---:|---:|---:|---:|---:|")
    for (key, shutter), r in rows.items():
        b, s = r["blurred"], r["sharp_vs_blurred"]
        print(f"| {key} | {shutter:g} | {b['mean']:.4f} | {b['within_2pct']:.0%} of {b['blocks']} "
              f"| {b['median_dev']:.2%} / {b['p95_dev']:.2%} | {s['within_2pct']:.0%}, "
              f"{s['p95_dev']:.2%} | {r['cost']:.2f}x ({r['shutter_s'] * 1e3:.0f} ms / "
              f"{r['sharp_s'] * 1e3:.0f} ms) |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
