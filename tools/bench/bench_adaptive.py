"""Adaptive sampling against uniform sampling (issue 34): per scene, the relMSE and seconds per
frame of uniform renders at a few spp and of --noise-threshold renders at a few thresholds (spp
as their cap), against high-spp references of the same frames. For each uniform setting it
reports the time adaptive sampling needs to reach the same relMSE (log-log interpolation between
the thresholds that bracket it) and its ratio to the uniform render's time; the goal on the
atrium is at most 2/3.

  /usr/bin/python3 -m tools.bench.bench_adaptive --scenes atrium,cornell-dynamic

References are shared with bench_denoise (same cache and keys). Every render uses the default
--mode reuse unless --mode says otherwise."""

import argparse
import math
import sys
import tempfile
from pathlib import Path

import numpy as np

from .bench_denoise import add_common_args, finish_common_args, reference, scene_path
from .benchlib import median
from .evaluation.run import Runner


def measure(runner, key, scene, extra, cache):
    """Per setting: (label, relMSE, s/frame, mean spp), medians over the seeds."""
    a = runner.args
    refs = reference(runner, key, scene, extra, cache)
    rows = []
    for label, spp, threshold in a.settings:
        errs, secs, spps = [], [], []
        for seed in a.seeds:
            flags = ["--noise-threshold", str(threshold)] if threshold else []
            if threshold and a.min_spp:
                flags += ["--adaptive-min-spp", str(a.min_spp)]
            recs, _, _, diffs = runner.render(scene, a.mode, spp, seed, a.first, a.last, keep=False,
                                              extra=extra + flags, refs=refs)
            errs.append(float(np.mean([d["relmse"] for d in diffs])))
            body = recs[1:] or recs
            secs.append(median([r["wall_s"] for r in body]))
            spps.append(float(np.mean([r["spp"]["mean"] for r in recs])))
        rows.append((label, threshold, median(errs), median(secs), median(spps)))
    return rows


def oracle_gain(runner, key, scene, extra, cache, spp, seeds):
    """What any allocation of samples to pixels could gain in mean relMSE at an equal total:
    mean(r) / mean(sqrt(r))^2, r a pixel's relative squared error per sample, measured from
    uniform renders of frame --first at `spp` against its reference over `seeds` seeds. Noise
    in r spreads it, so this overstates the gain (an upper bound in practice)."""
    a = runner.args
    ref = runner.read(reference(runner, key, scene, extra, cache)[:1])[0]
    errs = []
    for seed in seeds:
        _, imgs, _, _ = runner.render(scene, a.mode, spp, seed, a.first, a.first, extra=extra)
        errs.append((imgs[0] - ref) ** 2 / (ref ** 2 + 0.01))
    r = np.mean(errs, axis=0).mean(axis=2) * spp
    return float(r.mean() / np.sqrt(r).mean() ** 2)


def time_to_reach(target, adaptive):
    """Seconds at which the adaptive points (relMSE, s) reach relMSE `target` (log-log), or None
    where no two points bracket it."""
    pts = sorted(adaptive, key=lambda p: p[1])
    for (e0, s0), (e1, s1) in zip(pts, pts[1:]):
        if (e0 - target) * (e1 - target) <= 0 and e0 != e1:
            t = (math.log(target) - math.log(e0)) / (math.log(e1) - math.log(e0))
            return math.exp(math.log(s0) + t * (math.log(s1) - math.log(s0)))
    return None


def parse_settings(text):
    """u:SPP (uniform) or a:SPP:THRESHOLD (adaptive, SPP the cap), comma-separated."""
    out = []
    for item in text.split(","):
        parts = item.split(":")
        if parts[0] == "u" and len(parts) == 2:
            out.append((f"uniform {parts[1]} spp", int(parts[1]), 0.0))
        elif parts[0] == "a" and len(parts) == 3:
            out.append((f"threshold {parts[2]}, cap {parts[1]}", int(parts[1]), float(parts[2])))
        else:
            sys.exit(f"bench_adaptive: --settings: bad item {item}")
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scenes", default="atrium,cornell-dynamic")
    ap.add_argument("--diffuse", action="store_true", help="also with --force-diffuse")
    ap.add_argument("--mode", default="reuse")
    add_common_args(ap, last=10)
    ap.add_argument("--settings",
                    default="u:16,u:32,u:64,a:256:0.2,a:256:0.14,a:256:0.1,a:256:0.07,a:256:0.05")
    ap.add_argument("--min-spp", type=int, default=0, help="--adaptive-min-spp (0: default)")
    ap.add_argument("--oracle-seeds", type=int, default=0,
                    help="also the gain bound of any allocation, from this many uniform renders")
    args = ap.parse_args()
    cache = finish_common_args(args)
    args.settings = parse_settings(args.settings)
    results, oracles = {}, {}
    with tempfile.TemporaryDirectory() as t:
        runner = Runner(args, Path(t))
        for key in args.scenes.split(","):
            scene = scene_path(key, args)
            for extra in ([], ["--force-diffuse"]) if args.diffuse else ([],):
                results[(key, " ".join(extra))] = measure(runner, key, scene, extra, cache)
                if args.oracle_seeds:
                    spp = min(s for _, s, th in args.settings if not th)
                    oracles[(key, " ".join(extra))] = oracle_gain(
                        runner, key, scene, extra, cache, spp, range(101, 101 + args.oracle_seeds))
    print(f"\n--mode {args.mode}, {args.width} px, frames {args.first}-{args.last}, seeds "
          f"{args.seeds}, references {args.ref_spp} spp\n\n"
          "| scene | materials | setting | mean spp | relMSE | s/frame | relMSE x s |\n"
          "|---|---|---|---|---|---|---|")
    for (key, extra), rows in results.items():
        mat = "diffuse" if extra else "full"
        for label, _, e, s, spp in rows:
            print(f"| {key} | {mat} | {label} | {spp:.1f} | {e:.5f} | {s:.3f} | {e * s:.6f} |")
        adaptive = [(e, s) for _, th, e, s, _ in rows if th]
        for label, th, e, s, _ in rows:
            if th:
                continue
            t = time_to_reach(e, adaptive)
            ratio = f"{t / s:.2f}x ({t:.3f} s)" if t else "not bracketed"
            print(f"|  | {mat} | adaptive to reach {label}'s relMSE | | | {ratio} | |")
        if (key, extra) in oracles:
            print(f"|  | {mat} | bound on any allocation's gain at equal samples | | "
                  f"{oracles[(key, extra)]:.2f}x | | |")


if __name__ == "__main__":
    main()
