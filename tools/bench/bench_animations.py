"""Path reuse on real animations, each watched by a still and by a moving camera: the Virtual
City under a sun and a sky (its cameras 6 and 4, and camera 6 held still), the skinned BrainStem
under an environment (an orbiting and a still camera), and the generated atrium in the sun (a
camera walking through the courtyard, and the courtyard's still one). Per scene: relMSE against
our path tracer's reference, seconds per frame, relMSE x s, flicker, for our path tracer and
`--mode reuse` (and Cycles 5.2 and LuxCore 2.11 BIDIR with --cycles and --luxcore, each against
its own reference), the images of one frame, and a summary of reuse's gains.

  /usr/bin/python3 -m tools.bench.bench_animations                       # ours: ~40 min, 2 cores
  /usr/bin/python3 -m tools.bench.bench_animations --scenes vc-still,vc-cam6 --seeds 1
  /usr/bin/python3 -m tools.bench.bench_animations --cycles BPY/bin/python --luxcore LUX/bin/python

The scenes are made on first use under --work: the city and BrainStem as wrappers of the files
in ../shared/scenes (tools/scenes/gen_real_scenes.py; without that folder those scenes are
refused, saying so), the atrium by tools/scenes/gen_atrium.py (--size 0.5, --light sun). Peers
see the same glTF files (the environment as a uniform world); LuxCore renders the exported
triangles without textures, so it is not run on the city. Needs numpy and matplotlib, hence
/usr/bin/python3. How each figure is made: tools/bench/bench_temporal.py.
"""

import argparse
import json
import subprocess
import sys
import tempfile
from pathlib import Path

from . import bench_temporal as bt
from .benchlib import REPO
from .evaluation.results import Scene
from .evaluation.run import Runner, die, references

SHARED = REPO.parent / "shared" / "scenes"
SKY = "0.5,0.6,0.8"
STAGE_SKY = "0.8,0.85,1.0"

# key: (made by, our camera index, its name for the peers, camera, first frame, environment)
SCENES = {
    "vc-still": ("vc", 14, "still6", "still", 200, SKY),
    "vc-cam6": ("vc", 6, "camera6", "moving", 200, SKY),
    "vc-cam4": ("vc", 4, "camera4", "moving", 200, SKY),
    "brainstem-still": ("brainstem", 0, "front", "still", 96, STAGE_SKY),
    "brainstem-orbit": ("brainstem", 1, "orbit", "moving", 96, STAGE_SKY),
    "atrium-still": ("atrium", 1, "courtyard", "still", 0, SKY),
    "atrium-walk": ("atrium", 2, "walkthrough", "moving", 0, SKY),
}
LUXCORE_SKIPS = {"vc": "its textures are not exported to LuxCore"}


def parse_args():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scenes", default=",".join(SCENES))
    bt.add_run_args(ap, frames=10, sweep="2,4,8", seeds="1,2", settings="pathtrace;reuse")
    ap.add_argument("--work", default=str(REPO / "out" / "bench-animations"),
                    help="the generated scenes, the references and the images")
    args = ap.parse_args()
    keys = [k.strip() for k in args.scenes.split(",")]
    for k in keys:
        if k not in SCENES:
            die(f"--scenes: no scene {k!r} (there are: {', '.join(SCENES)})")
    args.scenes = keys
    bt.check_run_args(args)
    args.scene_args = ""  # set per scene before its renders
    return args


def make_scene(kind, work):
    """The glTF of a scene kind, generated under work when absent."""
    if kind == "atrium":
        path = work / "atrium-sun" / "atrium.gltf"
        cmd = ["-m", "tools.scenes.gen_atrium", "--size", "0.5", "--light", "sun"]
    else:
        src = SHARED / {"vc": "VC/VC.gltf", "brainstem": "BrainStem/BrainStem.gltf"}[kind]
        if not src.is_file():
            die(f"{src} not found: the {kind} scenes need ../shared/scenes beside the project")
        path = work / kind / f"{kind}-lit.gltf"
        cmd = ["-m", "tools.scenes.gen_real_scenes", kind, str(src)]
    if not path.is_file():
        subprocess.run([sys.executable, *cmd, "--out", str(path)], cwd=REPO, check=True)
    return path


def load(args, work):
    scenes = []
    for key in args.scenes:
        kind, cam, name, camera, first, env = SCENES[key]
        sc = Scene(key=key, path=make_scene(kind, work), camera=camera,
                   frames=list(range(first, first + args.frames)), ref_spp=args.ref_spp,
                   timing_frames=(first, first + args.frames - 1), sweep=args.sweep_spp)
        sc.kind, sc.camera_name, sc.world = kind, name, env
        sc.args = f"--camera {cam} --env-color {env}" + (
            " --allow-outside-uris" if kind != "atrium" else "")
        scenes.append(sc)
    return scenes


def save_images(runner, sc, args, ref_exr, out):
    """The last measured frame at --spp, seed 1, of each of our settings, and its reference, as
    PNGs (sRGB, exposure 0) in out."""
    from .evaluation.plots import plt, tonemap

    def png(img, name):
        plt.imsave(out / f"{sc.key}_{name}.png", tonemap(img, 0.0))

    out.mkdir(parents=True, exist_ok=True)
    last = sc.frames[-1]
    png(runner.read([ref_exr])[0], "reference")
    for name in args.settings:
        mode, extra = bt.SETTINGS[name]
        _, imgs, _, _ = runner.render(sc.path, mode, args.spp, 1, last - args.warm, last,
                                      extra=extra)
        png(imgs[-1], name.replace(" ", "-").replace(",", ""))


def work_at(fig, name, spp):
    e, t, _ = fig[name][spp]
    return e * t


def summary(rows, args):
    head = ["| scene | camera | reuse over the path tracer (relMSE x s) |"]
    peers = [p for p, on in ((bt.CYCLES, args.cycles), (bt.LUXCORE, args.luxcore)) if on]
    head[0] += "".join(f" reuse over {p.split(' (')[0]} |" for p in peers)
    lines = ["## Summary (at %d spp)" % args.spp, "", head[0],
             "|---|---|---|" + "---|" * len(peers)]
    for sc, fig in rows:
        if "reuse" not in fig:
            continue
        r = work_at(fig, "reuse", args.spp)
        cells = [f"{work_at(fig, 'pathtrace', args.spp) / r:.2f}x"]
        for p in peers:
            cells.append(f"{work_at(fig, p, args.spp) / r:.2f}x" if p in fig else "not run")
        lines.append(f"| {sc.key} | {sc.camera} | " + " | ".join(cells) + " |")
    return lines + [""]


def main():
    args = parse_args()
    work = Path(args.work)
    scenes = load(args, work)
    cache = work / "cache"
    lines, out, rows = [], {}, []
    with tempfile.TemporaryDirectory(prefix="bench-animations-") as tmp:
        tmp = Path(tmp)
        runner = Runner(args, tmp)
        for sc in scenes:
            args.scene_args = sc.args  # every render of this scene, references too
            for mode in ("reuse", "pathtrace"):  # untimed: fills the kernel cache
                runner.render(sc.path, mode, 1, 1, sc.frames[0], sc.frames[0], keep=False)
            ref_exrs, refs, _ = references(runner, sc, cache)
            fig = bt.measure(runner, sc, ref_exrs, refs, args)
            size = refs[0].shape[:2]
            if args.cycles:
                fig[bt.CYCLES] = bt.peer_measure(
                    runner, sc, size, args, cache, tmp, "cycles-5.2", sc.ref_spp,
                    lambda spp, seed, o: bt.cycles_render(args, sc, spp, seed, size, o))
            if args.luxcore and sc.kind not in LUXCORE_SKIPS:
                export = bt.luxcore_export(args, sc, size, cache)
                fig[bt.LUXCORE] = bt.peer_measure(
                    runner, sc, size, args, cache, tmp, "luxcore-2.11-bidir",
                    args.luxcore_ref_spp,
                    lambda spp, seed, o: bt.luxcore_render(args, export, sc, spp, seed, size, o))
            save_images(runner, sc, args, ref_exrs[-1], work / "images")
            l, o = bt.report(sc, fig, args)
            if args.luxcore and sc.kind in LUXCORE_SKIPS:
                l.insert(-1, f"LuxCore not run on {sc.key}: {LUXCORE_SKIPS[sc.kind]}.")
            lines += l
            out[sc.key] = dict(o, camera=sc.camera)
            rows.append((sc, fig))
            print("\n".join(l), flush=True)
    s = summary(rows, args)
    print("\n".join(s), flush=True)
    print(f"images: {work / 'images'}")
    if args.json:
        Path(args.json).write_text(json.dumps(out, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
