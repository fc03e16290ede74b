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
import sys
import tempfile
from pathlib import Path

import numpy as np

from .benchlib import ATRIUM, REPO, ensure_atrium, median
from .evaluation.metrics import flicker
from .evaluation.run import Runner, file_sha


def add_common_args(ap, last):
    """The options bench_denoise and bench_adaptive share: image, frames, references, binaries."""
    ap.add_argument("--width", type=int, default=160)
    ap.add_argument("--first", type=int, default=8)
    ap.add_argument("--last", type=int, default=last)
    ap.add_argument("--ref-spp", type=int, default=1024)
    ap.add_argument("--seeds", default="1,2")
    ap.add_argument("--exe", default=str(REPO / "build" / "pathreuse"))
    ap.add_argument("--cmp", default=str(REPO / "build" / "exr_compare"))
    ap.add_argument("--atrium", default=str(ATRIUM))
    ap.add_argument("--cache", default=str(REPO / "out" / "bench-denoise-cache"))


def finish_common_args(args):
    """What the evaluation's Runner expects beside them; returns the reference cache folder."""
    args.max_depth, args.reuse_args, args.quiet = 8, "", False
    args.seeds = [int(s) for s in args.seeds.split(",")]
    cache = Path(args.cache)
    cache.mkdir(parents=True, exist_ok=True)
    return cache


def scene_path(key, args):
    """The scene file of a scene key: the atrium (fetched once), else one of scenes/."""
    if key == "atrium":
        return ensure_atrium(args.atrium, python=sys.executable)
    return REPO / "scenes" / f"{key}.gltf"


def reference(runner, key, scene, extra, cache):
    """The reference frames of one setting of materials, cached as float EXRs."""
    a = runner.args
    h = hashlib.sha1(json.dumps([file_sha(scene), a.width, a.first, a.last, a.ref_spp, a.max_depth,
                                 extra]).encode()).hexdigest()[:12]
    exrs = [cache / f"{key}_{h}_f{f:04d}.exr" for f in range(a.first, a.last + 1)]
    if not all(e.is_file() for e in exrs):
        print(f"  {key} {' '.join(extra)}: references at {a.ref_spp} spp", flush=True)
        runner.render(scene, "reuse", a.ref_spp, 1000, a.first, a.last, keep=False, extra=extra,
                      save=exrs)
    return exrs


def measure(runner, key, scene, extra, cache):
    """Per setting of --settings: (spp, denoised, relMSE, flicker, s/frame), medians of seeds."""
    a = runner.args
    refs = reference(runner, key, scene, extra, cache)
    ref_imgs = runner.read(refs)
    rows = []
    for spp, denoise in a.settings:
        errs, fls, secs = [], [], []
        for seed in a.seeds:
            recs, imgs, _, diffs = runner.render(scene, "reuse", spp, seed, a.first, a.last,
                                                 extra=extra + (["--denoise"] if denoise else []),
                                                 refs=refs)
            errs.append(float(np.mean([d["relmse"] for d in diffs])))
            fls.append(float(np.mean([flicker(imgs[k - 1], imgs[k], ref_imgs[k - 1], ref_imgs[k])
                                      for k in range(1, len(imgs))])))
            secs.append(median([r["wall_s"] for r in recs[1:]] or [recs[0]["wall_s"]]))
        rows.append((spp, denoise, median(errs), median(fls), median(secs)))
    return rows


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scenes", default="cornell-dynamic,atrium")
    add_common_args(ap, last=11)
    ap.add_argument("--settings", default="256:raw,16:raw,16:denoise,4:denoise",
                    help="spp:raw or spp:denoise, comma-separated")
    ap.add_argument("--full-only", action="store_true", help="without the --force-diffuse runs")
    args = ap.parse_args()
    cache = finish_common_args(args)
    args.settings = [(int(s.split(":")[0]), s.split(":")[1] == "denoise")
                     for s in args.settings.split(",")]
    results = {}
    with tempfile.TemporaryDirectory() as t:
        runner = Runner(args, Path(t))
        for key in args.scenes.split(","):
            scene = scene_path(key, args)
            for extra in ([],) if args.full_only else ([], ["--force-diffuse"]):
                results[(key, " ".join(extra))] = measure(runner, key, scene, extra, cache)
    print("\n| scene | materials | setting | relMSE | flicker | s/frame | relMSE x s |\n"
          "|---|---|---|---|---|---|---|")
    for (key, extra), rows in results.items():
        for spp, denoise, e, fl, s in rows:
            print(f"| {key} | {'diffuse' if extra else 'full'} | {spp} spp "
                  f"{'denoised' if denoise else 'raw'} | {e:.5f} | {fl:.5f} | {s:.3f} | {e * s:.6f} |")
        raw256 = [e for spp, d, e, _, _ in rows if spp == 256 and not d]
        den16 = [e for spp, d, e, _, _ in rows if spp == 16 and d]
        if raw256 and den16:
            print(f"|  | goal: denoised 16 spp below raw 256 spp | "
                  f"{'met' if den16[0] < raw256[0] else 'not met'} | {den16[0] / raw256[0]:.2f}x | | | |")


if __name__ == "__main__":
    main()
