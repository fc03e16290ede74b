"""Sampling quality of the path tracer: relMSE per sample and relMSE x seconds against a
high-spp reference, on the scenes where emitter sampling and stratification matter.

  python3 -m tools.bench.bench_sampling                       # the table, this build's kernels
  python3 -m tools.bench.bench_sampling --baseline-kernels DIR  # and side by side with other kernels
  python3 -m tools.bench.bench_sampling --baseline-build DIR    # ... or with another build's binary

For each case the reference is rendered once (cached in --cache, keyed by the scene's name
and file contents, its settings and the kernels it was rendered with) at --ref-factor x the
spp; each configuration then renders --seeds seeds, interleaved, and the table gives the
median relMSE (eps 0.01, as exr_compare), the median kernel seconds per frame, and their
product. A case may render in several variants against the one reference (the many-lights
atrium, tools/scenes/gen_atrium.py --light lanterns: --light-sampler bvh and power, one row each,
the reference with the default sampler); a line below the table gives the ratio of their
relMSE. A render that fails (e.g. an option this build lacks) gives a row saying so.
--baseline-kernels points
PATHREUSE_KERNEL_DIR at another kernels/ folder (e.g. `git archive` of an older commit), so
both run in the same binary on the same machine in the same run; --baseline-build runs another
build's pathreuse instead (e.g. of an older commit whose device structs differ). Standard
library only.

--resample adds a row rendered with --mode pathtrace --resample and its defaults (paths
resampled with neighbouring pixels'). --reuse adds a row rendered with --mode reuse and its
defaults (eye paths and connections), a single frame, so its light paths are all traced in that
frame's time.

--cycles adds, for the cases whose light transport Blender can match (--force-diffuse scenes
without punctual lights: cases 1-3), a row rendered by Blender Cycles (Debian's `blender`,
tools/bench/cycles_peer.py: Lambert + emission, box filter, bounces = --max-depth - 2, 2 threads)
with the same spp and seeds against the same reference. Its time column is the wall time of
Blender's render call (scene sync and Embree BVH build included), ours the kernel seconds;
the "wall s" column gives our wall time per frame for a like-for-like view.
"""

import argparse
import hashlib
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

from . import benchlib

REPO = benchlib.REPO
CYCLES_PEER = Path(__file__).resolve().parent / "cycles_peer.py"  # run inside Blender

# (name, scene, width, height, render options[, variants]); variants: [(short name, more
# render options), ...], each a row of the table (labelled by its options) rendered against
# the one reference (rendered with the case's options alone); a line after the table gives
# the relMSE of the second variant over the first
SAMPLERS = [("bvh", ["--light-sampler", "bvh"]), ("power", ["--light-sampler", "power"])]
FEW = [("exhaustive", ["--light-sampler", "exhaustive"]), ("power", ["--light-sampler", "power"])]
CYCLES_CASES = {0, 1, 2}  # --force-diffuse, no punctual lights: the same transport in Cycles
CASES = [
    ("atrium direct (--max-depth 2)", "atrium", 320, 180, ["--force-diffuse", "--max-depth", "2"],
     FEW),
    ("atrium full (--max-depth 64)", "atrium", 320, 180, ["--force-diffuse", "--max-depth", "64"],
     FEW),
    ("cornell-nvpro (--max-depth 64)", "cornell-nvpro", 320, 240,
     ["--force-diffuse", "--max-depth", "64"], FEW),
    ("cornell-dynamic (default depth)", "cornell-dynamic", 320, 240, [], FEW),
    ("atrium lanterns direct (--max-depth 2)", "atrium-lanterns", 320, 180,
     ["--force-diffuse", "--max-depth", "2"], SAMPLERS),
]


def scene_path(name, python):
    if name == "atrium":
        return benchlib.ensure_atrium(benchlib.ATRIUM, python)
    if name == "atrium-lanterns":
        return benchlib.ensure_atrium(benchlib.ATRIUM_LANTERNS, python, light="lanterns")
    if name == "cornell-nvpro":
        return REPO.parent / "shared" / "scenes" / "cornell-nvpro" / "cornellBox.gltf"
    return REPO / "scenes" / f"{name}.gltf"


def render(exe, scene, w, h, spp, seed, opts, out_exr, stats, kernels=None):
    env = dict(os.environ)
    if kernels:
        env["PATHREUSE_KERNEL_DIR"] = str(kernels)
    mode = [] if "--mode" in opts else ["--mode", "pathtrace"]
    cmd = [str(exe), "render", str(scene)] + mode + ["--frames", "0", "--width", str(w),
           "--height", str(h), "--spp", str(spp), "--seed", str(seed), "--quiet", "--exr-float",
           "--out", str(out_exr).replace("0000", "%04d"), "--stats", str(stats)] + opts
    run = subprocess.run(cmd, env=env, stderr=subprocess.PIPE, text=True)
    if run.returncode:
        sys.stderr.write(run.stderr)
        lines = run.stderr.strip().splitlines()
        raise RenderFailed(lines[-1] if lines else f"exit status {run.returncode}")
    rec = json.loads(Path(stats).read_text().splitlines()[-1])
    return benchlib.kernel_s(rec), float(rec.get("wall_s", 0.0))


def render_cycles(scene, w, h, spp, seed, opts, out_exr):
    """Blender Cycles through tools/bench/cycles_peer.py; returns the render call's seconds."""
    depth = int(opts[opts.index("--max-depth") + 1]) if "--max-depth" in opts else 8
    cmd = ["blender", "-b", "--factory-startup", "--python", str(CYCLES_PEER),
           "--", str(scene), str(out_exr), "--width", str(w), "--height", str(h), "--spp", str(spp),
           "--max-depth", str(depth), "--seed", str(seed)]
    # Debian's Blender takes its Python home from the first python3 on PATH: put Debian's first,
    # so that a pyenv or virtualenv interpreter running this tool leaves Blender its numpy.
    env = dict(os.environ, PATH="/usr/bin:" + os.environ.get("PATH", ""))
    run = subprocess.run(cmd, capture_output=True, text=True, env=env)
    lines = [l for l in run.stdout.splitlines() if l.startswith('{"render_s"')]
    if run.returncode or not lines or not Path(out_exr).is_file():
        raise RenderFailed((run.stderr.strip().splitlines() or ["blender failed"])[-1])
    return json.loads(lines[-1])["render_s"]


class RenderFailed(Exception):
    pass


def scene_digest(scene):
    """SHA-1 of a glTF and the files it refers to (buffers, images), so that a regenerated
    scene gets new references."""
    scene = Path(scene)
    h = hashlib.sha1(scene.read_bytes())
    if scene.suffix.lower() == ".gltf":
        doc = json.loads(scene.read_text(encoding="utf-8"))
        for item in doc.get("buffers", []) + doc.get("images", []):
            uri = item.get("uri", "")
            if uri and not uri.startswith("data:"):
                f = scene.parent / uri
                h.update(uri.encode())
                h.update(f.read_bytes() if f.is_file() else b"missing")
    return h.hexdigest()[:16]


def relmse(compare, a, ref):
    out = subprocess.run([str(compare), str(a), str(ref)], check=True, capture_output=True, text=True)
    return json.loads(out.stdout)["relmse"]


def kernels_key(kdir):
    h = hashlib.sha1()
    for p in sorted(Path(kdir).rglob("*")):
        if p.is_file():
            h.update(p.name.encode())
            h.update(p.read_bytes())
    return h.hexdigest()[:12]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", default=str(REPO / "build"))
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--ref-factor", type=int, default=16)
    ap.add_argument("--seeds", type=int, default=3)
    ap.add_argument("--baseline-kernels", help="another kernels/ folder to compare with")
    ap.add_argument("--baseline-build", help="another build folder whose pathreuse to compare with")
    ap.add_argument("--cases", help="comma-separated case numbers (1-based) to run")
    ap.add_argument("--cache", default="/tmp/pathreuse-bench-sampling")
    ap.add_argument("--python", default="/usr/bin/python3", help="python for gen_atrium.py")
    ap.add_argument("--cycles", action="store_true", help="add Blender Cycles rows (cases 1-3)")
    ap.add_argument("--resample", action="store_true",
                    help="add a row of --mode pathtrace --resample with its defaults")
    ap.add_argument("--reuse", action="store_true",
                    help="add a row of --mode reuse with its defaults (one frame: every light path traced)")
    args = ap.parse_args()
    exe = Path(args.build) / "pathreuse"
    compare = Path(args.build) / "exr_compare"
    cache = Path(args.cache)
    cache.mkdir(parents=True, exist_ok=True)
    configs = [("this build", None)]
    if args.baseline_kernels:
        configs.insert(0, ("baseline", Path(args.baseline_kernels).resolve()))
    if args.baseline_build:
        configs.insert(0, ("baseline build", Path(args.baseline_build).resolve() / "pathreuse"))
    chosen = [int(c) - 1 for c in args.cases.split(",")] if args.cases else range(len(CASES))
    # generated scenes first, so that the generator's lines do not land inside the table
    scenes = {CASES[ci][1]: scene_path(CASES[ci][1], args.python) for ci in chosen}
    print("\n".join(benchlib.machine_lines(exe)))
    print(f"- spp {args.spp}, reference {args.spp * args.ref_factor} spp, {args.seeds} seeds, "
          f"relMSE eps 0.01, kernel seconds per frame\n")
    print("| case | kernels | relMSE | kernel s | relMSE x s | wall s |\n"
          "| --- | --- | ---: | ---: | ---: | ---: |")
    tmp = Path(tempfile.mkdtemp(prefix="bench-sampling-"))
    notes = []
    for ci in chosen:
        name, scene, w, h, opts = CASES[ci][:5]
        variants = CASES[ci][5] if len(CASES[ci]) > 5 else [(None, [])]
        sp = scenes[scene]
        if not Path(sp).is_file():
            print(f"| {name} | skipped: {sp} not found | | | | |")
            continue
        ref_spp = args.spp * args.ref_factor
        key = hashlib.sha1(json.dumps([scene, str(sp), scene_digest(sp), w, h, ref_spp, opts,
                                       kernels_key(REPO / "kernels")]).encode()).hexdigest()[:16]
        ref = cache / f"ref_{key}_0000.exr"
        if not ref.is_file():
            print(f"rendering the reference of {name} ({ref_spp} spp) ...", file=sys.stderr, flush=True)
            try:
                render(exe, sp, w, h, ref_spp, 1000, opts, tmp / "ref_0000.exr", tmp / "ref.jsonl")
            except RenderFailed as e:
                print(f"| {name} | reference failed: {e} | | | | |", flush=True)
                continue
            shutil.move(str(tmp / "ref_0000.exr"), str(ref))   # only a finished one is cached
        rows = [(label, vlabel, kd, vopts) for vlabel, vopts in variants for label, kd in configs]
        if args.resample:
            rows.append(("pathtrace --resample (its defaults)", None, None, ["--resample"]))
        if args.reuse:
            rows.append(("reuse (its defaults)", None, None, ["--mode", "reuse"]))
        if args.cycles and ci in CYCLES_CASES:
            rows.append(("Blender Cycles 3.4 (CPU, 2 threads; time: render call)", None, "cycles", []))
        results = {(label, vlabel): ([], [], [], []) for label, vlabel, _, _ in rows}
        for seed in range(1, args.seeds + 1):
            for label, vlabel, kd, vopts in rows:
                e, t, failed, walls = results[(label, vlabel)]
                if failed:
                    continue
                img = tmp / f"img_0000.exr"
                try:
                    if kd == "cycles":
                        ks, wall = render_cycles(sp, w, h, args.spp, seed, opts, img), None
                    else:
                        # kd: another kernels/ folder, or another build's binary
                        other = kd is not None and kd.name == "pathreuse"
                        ks, wall = render(kd if other else exe, sp, w, h, args.spp, seed,
                                          opts + vopts, img, tmp / "s.jsonl",
                                          None if other else kd)
                except RenderFailed as err:
                    failed.append(str(err))
                    continue
                e.append(relmse(compare, img, ref))
                t.append(ks)
                if wall is not None:
                    walls.append(wall)
        med = {}
        for label, vlabel, _, _ in rows:
            e, t, failed, walls = results[(label, vlabel)]
            row = label if vlabel is None else f"{label}, {' '.join(dict(variants)[vlabel])}"
            if failed:
                print(f"| {name} | {row} | failed: {failed[0]} | | | |", flush=True)
                continue
            me, mt = statistics.median(e), statistics.median(t)
            mw = f"{statistics.median(walls):.3f}" if walls else ""
            med[(label, vlabel)] = me
            print(f"| {name} | {row} | {me:.5f} | {mt:.3f} | {me * mt:.5f} | {mw} |", flush=True)
        if len(variants) > 1:
            (a, _), (b, _) = variants[:2]
            for label, _ in configs:
                if (label, a) in med and (label, b) in med and med[(label, a)] > 0:
                    r = f"{med[(label, b)] / med[(label, a)]:.3f}"
                else:
                    r = "n/a (a render failed)"
                notes.append(f"- {name}, {label}: relMSE {b} / {a} = {r}")
    if notes:
        print("\n" + "\n".join(notes), flush=True)


if __name__ == "__main__":
    main()
