"""Denoising against more samples (issue 34): per scene, with full materials and with
--force-diffuse, the relMSE of raw frames at a few spp and of --denoise frames at fewer, against
high-spp references of the same frames, and the flicker of each sequence (noise that changes
between frames, the evaluation's measure). The goal it reports: denoised 16 spp closer to the
reference than raw 256 spp.

  /usr/bin/python3 -m tools.bench.bench_denoise --scenes cornell-dynamic,atrium

References are cached in --cache between runs (keyed by scene file, size, frames, spp and
options). Every render uses the default --mode reuse."""

import argparse
import hashlib
import json
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

from .benchlib import ATRIUM, REPO, ensure_atrium, median
from .evaluation.metrics import flicker
from .evaluation.run import load_raw


def render(args, scene, spp, seed, out, extra):
    cmd = [str(args.exe), "render", str(scene), "--frames", f"{args.first}-{args.last}",
           "--width", str(args.width), "--spp", str(spp), "--seed", str(seed), "--quiet",
           "--exr-float", "--out", str(out / "f_%04d.exr"), "--stats", str(out / "stats.jsonl"),
           *extra]
    out.mkdir(parents=True, exist_ok=True)
    subprocess.run(cmd, check=True, capture_output=True)
    recs = [json.loads(x) for x in (out / "stats.jsonl").read_text().splitlines() if x.strip()]
    return [out / f"f_{f:04d}.exr" for f in range(args.first, args.last + 1)], recs


def read(args, exrs, tmp):
    imgs = []
    for i, e in enumerate(exrs):
        raw = tmp / f"r{i}.raw"
        subprocess.run([str(args.cmp), "--raw", str(e), str(raw)], check=True)
        imgs.append(load_raw(raw))
    return imgs


def relmse(args, exr, ref):
    out = subprocess.run([str(args.cmp), str(exr), str(ref)], check=True, capture_output=True,
                         text=True).stdout
    return json.loads(out)["relmse"]


def reference(args, key, scene, extra, cache):
    h = hashlib.sha1(json.dumps([Path(scene).read_bytes().hex()[:4096], args.width, args.first,
                                 args.last, args.ref_spp, extra]).encode()).hexdigest()[:12]
    d = cache / f"{key}_{h}"
    exrs = [d / f"f_{f:04d}.exr" for f in range(args.first, args.last + 1)]
    if not all(e.is_file() for e in exrs):
        print(f"  {key}{' ' + ' '.join(extra) if extra else ''}: reference at {args.ref_spp} spp",
              flush=True)
        render(args, scene, args.ref_spp, 1000, d, extra)
    return exrs


def measure(args, key, scene, extra, cache, tmp):
    refs = reference(args, key, scene, extra, cache)
    ref_imgs = read(args, refs, tmp)
    rows = []
    for spp, denoise in args.settings:
        errs, fls, secs = [], [], []
        for seed in args.seeds:
            out = tmp / f"{key}_{spp}_{denoise}_{seed}"
            exrs, recs = render(args, scene, spp, seed, out, extra + (["--denoise"] if denoise else []))
            errs.append(float(np.mean([relmse(args, e, r) for e, r in zip(exrs, refs)])))
            imgs = read(args, exrs, tmp)
            fls.append(float(np.mean([flicker(imgs[k - 1], imgs[k], ref_imgs[k - 1], ref_imgs[k])
                                      for k in range(1, len(imgs))])))
            secs.append(median([r["wall_s"] for r in recs[1:]] or [recs[0]["wall_s"]]))
        rows.append((spp, denoise, median(errs), median(fls), median(secs)))
        print(f"  {key:16s} {' '.join(extra):15s} {spp:4d} spp {'denoised' if denoise else 'raw':8s}"
              f" relMSE {rows[-1][2]:.5f}  flicker {rows[-1][3]:.5f}  {rows[-1][4]:.3f} s/frame",
              flush=True)
    return rows


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scenes", default="cornell-dynamic,atrium")
    ap.add_argument("--width", type=int, default=160)
    ap.add_argument("--first", type=int, default=8)
    ap.add_argument("--last", type=int, default=11)
    ap.add_argument("--ref-spp", type=int, default=1024)
    ap.add_argument("--seeds", default="1,2")
    ap.add_argument("--settings", default="256:raw,16:raw,16:denoise,4:denoise",
                    help="spp:raw or spp:denoise, comma-separated")
    ap.add_argument("--exe", default=str(REPO / "build" / "pathreuse"))
    ap.add_argument("--cmp", default=str(REPO / "build" / "exr_compare"))
    ap.add_argument("--atrium", default=str(ATRIUM))
    ap.add_argument("--cache", default=str(REPO / "out" / "bench-denoise-cache"))
    args = ap.parse_args()
    args.seeds = [int(s) for s in args.seeds.split(",")]
    args.settings = [(int(s.split(":")[0]), s.split(":")[1] == "denoise")
                     for s in args.settings.split(",")]
    cache = Path(args.cache)
    cache.mkdir(parents=True, exist_ok=True)
    results = {}
    with tempfile.TemporaryDirectory() as t:
        tmp = Path(t)
        for key in args.scenes.split(","):
            if key == "atrium":
                scene = ensure_atrium(args.atrium, python=sys.executable)
            else:
                scene = REPO / "scenes" / f"{key}.gltf"
            for extra in ([], ["--force-diffuse"]):
                results[(key, " ".join(extra))] = measure(args, key, scene, extra, cache, tmp)
    print("\n| scene | materials | setting | relMSE | flicker | s/frame |\n|---|---|---|---|---|---|")
    for (key, extra), rows in results.items():
        for spp, denoise, e, fl, s in rows:
            print(f"| {key} | {'diffuse' if extra else 'full'} | {spp} spp "
                  f"{'denoised' if denoise else 'raw'} | {e:.5f} | {fl:.5f} | {s:.3f} |")
        raw256 = [e for spp, d, e, _, _ in rows if spp == 256 and not d]
        den16 = [e for spp, d, e, _, _ in rows if spp == 16 and d]
        if raw256 and den16:
            print(f"|  | goal: denoised 16 spp below raw 256 spp | "
                  f"{'met' if den16[0] < raw256[0] else 'not met'} | {den16[0] / raw256[0]:.2f}x | | |")


if __name__ == "__main__":
    main()
