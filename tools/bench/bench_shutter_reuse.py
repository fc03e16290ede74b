"""Path reuse's gain over the path tracer with the shutter open, against its gain without it.

  /usr/bin/python3 -m tools.bench.bench_shutter_reuse --build build

Per scene and shutter (0, and each of --shutters frames): a reference frame path traced at
--ref-spp with that shutter; then the path tracer and --mode reuse at --spp over the frames before
it (reuse keeps its light paths over them), each run with --seeds seeds. Per run: the frame's
relMSE against the reference, and the median wall seconds per frame of the run's frames after the
first (the stats line; exr_compare's relMSE). The gain is the path tracer's relMSE x s over reuse's (medians over the
seeds). Reuse runs twice: as by default (which resamples without a shutter and not under one)
and with the other choice (--no-resample without a shutter, --resample under one). The
scenes: the demo, the Virtual City's camera 6 at frame 204 (45 moving cars, a moving camera) and
BrainStem on its stage under the orbiting camera (skinned). bench_motion_blur, whose wrappers it
shares, needs numpy: hence /usr/bin/python3.
"""

import argparse
import json
import subprocess
import sys
from pathlib import Path

from .bench_motion_blur import wrapper
from .benchlib import REPO, median

# key: (wrapper kind or None, source, camera, frame, fps, world, size)
SCENES = {
    "cornell-dynamic": (None, "scenes/cornell-dynamic.gltf", 0, 30, 24, None, (160, 120)),
    "vc-cam6": ("vc", "VC/VC.gltf", 6, 204, 24, "0.5,0.6,0.8", (160, 96)),
    "brainstem": ("brainstem", "BrainStem/BrainStem.gltf", 1, 96, 24, "0.8,0.85,1.0", (160, 120)),
}


def parse_args():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--build", default="build", help="the folder with pathreuse and exr_compare")
    ap.add_argument("--scenes", default=",".join(SCENES))
    ap.add_argument("--shutters", default="0.5", help="frames the shutter is open, A,B,...")
    ap.add_argument("--spp", type=int, default=4)
    ap.add_argument("--ref-spp", type=int, default=1024)
    ap.add_argument("--history", type=int, default=6, help="frames rendered before the measured one")
    ap.add_argument("--seeds", default="1,2,3")
    ap.add_argument("--work", default="out/bench-shutter-reuse")
    return ap.parse_args()


def render(args, sc, out, mode, spp, shutter, seed, first, extra=()):
    """Frames first..frame of scene sc into out; returns (the frame's EXR, wall s per frame)."""
    scene, cam, frame, fps, world, size = sc
    stats = out / "stats.jsonl"
    stats.unlink(missing_ok=True)
    cmd = [str(args.build / "pathreuse"), "render", str(scene), "--allow-outside-uris",
           "--fps", str(fps), "--camera", str(cam), "--mode", mode, "--spp", str(spp),
           "--width", str(size[0]), "--height", str(size[1]), "--frames", f"{first}-{frame}",
           "--shutter", str(shutter), "--seed", str(seed), "--exr-float", "--quiet",
           "--stats", str(stats), "--out", str(out / "f_%04d.exr"), *extra]
    cmd += ["--env-color", world] if world else ["--env", "none"]
    subprocess.run(cmd, check=True)
    walls = [json.loads(x)["wall_s"] for x in stats.read_text().splitlines()]
    return out / f"f_{frame:04d}.exr", median(walls[1:] if len(walls) > 1 else walls)


def relmse(args, exr, ref):
    """exr_compare's relMSE of exr against ref."""
    out = subprocess.run([str(args.build / "exr_compare"), str(exr), str(ref)], check=True,
                         capture_output=True, text=True).stdout
    return float(json.loads(out)["relmse"])


def main():
    args = parse_args()
    args.build = (REPO / args.build).resolve()
    work = (REPO / args.work).resolve()
    seeds = [int(s) for s in args.seeds.split(",")]
    shutters = [0.0] + [float(x) for x in args.shutters.split(",")]
    rows = []
    for key in args.scenes.split(","):
        kind, source, cam, frame, fps, world, size = SCENES[key]
        scene = wrapper(kind, source, work) if kind else REPO / source
        sc = (scene, cam, frame, fps, world, size)
        first = frame - args.history
        for shutter in shutters:
            d = work / key / f"s{shutter:g}"
            ref_exr = d / "ref" / f"f_{frame:04d}.exr"
            if not ref_exr.is_file():
                (d / "ref").mkdir(parents=True, exist_ok=True)
                render(args, sc, d / "ref", "pathtrace", args.ref_spp, shutter, 99, frame)
            # Under a shutter the default does not resample: the other row asks for it.
            other = ("reuse --resample", ("--resample",)) if shutter > 0 else \
                ("reuse --no-resample", ("--no-resample",))
            runs = [("pathtrace", ()), ("reuse", ()), other]
            res = {}
            for name, extra in runs:
                errs, walls = [], []
                for seed in seeds:
                    out = d / name.replace(" ", "") / str(seed)
                    out.mkdir(parents=True, exist_ok=True)
                    exr, wall = render(args, sc, out, name.split()[0], args.spp, shutter, seed,
                                       first, extra)
                    errs.append(relmse(args, exr, ref_exr))
                    walls.append(wall)
                res[name] = (median(errs), median(walls))
            pt_e, pt_s = res["pathtrace"]
            for name, (e, s) in res.items():
                row = {"scene": key, "shutter": shutter, "run": name, "relmse": e, "s": s,
                       "relmse_s": e * s, "gain": (pt_e * pt_s) / (e * s)}
                rows.append(row)
                print(json.dumps(row), flush=True)
    print("| scene | shutter | run | relMSE | s/frame | relMSE x s | gain over the path tracer |")
    print("|---|---:|---|---:|---:|---:|---:|")
    for r in rows:
        print(f"| {r['scene']} | {r['shutter']:g} | {r['run']} | {r['relmse']:.4f} | {r['s']:.3f} "
              f"| {r['relmse_s']:.5f} | {r['gain']:.2f}x |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
