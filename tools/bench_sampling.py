#!/usr/bin/env python3
"""Sampling quality of the path tracer: relMSE per sample and relMSE x seconds against a
high-spp reference, on the scenes where emitter sampling and stratification matter.

  python3 tools/bench_sampling.py                       # the table, this build's kernels
  python3 tools/bench_sampling.py --baseline-kernels DIR  # and side by side with other kernels

For each case the reference is rendered once (cached in --cache, keyed by its settings and
the kernels it was rendered with) at --ref-factor x the spp; each configuration then renders
--seeds seeds, interleaved, and the table gives the median relMSE (eps 0.01, as exr_compare),
the median kernel seconds per frame, and their product. --baseline-kernels points
PATHREUSE_KERNEL_DIR at another kernels/ folder (e.g. `git archive` of an older commit), so
both run in the same binary on the same machine in the same run. Standard library only.
"""

import argparse
import hashlib
import json
import os
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import benchlib  # noqa: E402

REPO = benchlib.REPO

# (name, scene, width, height, render options)
CASES = [
    ("atrium direct (--max-depth 2)", "atrium", 320, 180, ["--force-diffuse", "--max-depth", "2"]),
    ("atrium full (--max-depth 64)", "atrium", 320, 180, ["--force-diffuse", "--max-depth", "64"]),
    ("cornell-nvpro (--max-depth 64)", "cornell-nvpro", 320, 240, ["--force-diffuse", "--max-depth", "64"]),
    ("cornell-dynamic (default depth)", "cornell-dynamic", 320, 240, []),
]


def scene_path(name, python):
    if name == "atrium":
        return benchlib.ensure_atrium(benchlib.ATRIUM, python)
    if name == "cornell-nvpro":
        return REPO.parent / "shared" / "scenes" / "cornell-nvpro" / "cornellBox.gltf"
    return REPO / "scenes" / f"{name}.gltf"


def render(exe, scene, w, h, spp, seed, opts, out_exr, stats, kernels=None):
    env = dict(os.environ)
    if kernels:
        env["PATHREUSE_KERNEL_DIR"] = str(kernels)
    cmd = [str(exe), "render", str(scene), "--mode", "pathtrace", "--frames", "0", "--width", str(w),
           "--height", str(h), "--spp", str(spp), "--seed", str(seed), "--quiet", "--exr-float",
           "--out", str(out_exr).replace("0000", "%04d"), "--stats", str(stats)] + opts
    subprocess.run(cmd, check=True, env=env)
    rec = json.loads(Path(stats).read_text().splitlines()[-1])
    return benchlib.kernel_s(rec)


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
    ap.add_argument("--cases", help="comma-separated case numbers (1-based) to run")
    ap.add_argument("--cache", default="/tmp/pathreuse-bench-sampling")
    ap.add_argument("--python", default="/usr/bin/python3", help="python for gen_atrium.py")
    args = ap.parse_args()
    exe = Path(args.build) / "pathreuse"
    compare = Path(args.build) / "exr_compare"
    cache = Path(args.cache)
    cache.mkdir(parents=True, exist_ok=True)
    configs = [("this build", None)]
    if args.baseline_kernels:
        configs.insert(0, ("baseline", Path(args.baseline_kernels).resolve()))
    chosen = [int(c) - 1 for c in args.cases.split(",")] if args.cases else range(len(CASES))
    print("\n".join(benchlib.machine_lines(exe)))
    print(f"- spp {args.spp}, reference {args.spp * args.ref_factor} spp, {args.seeds} seeds, "
          f"relMSE eps 0.01, kernel seconds per frame\n")
    print("| case | kernels | relMSE | kernel s | relMSE x s |\n| --- | --- | ---: | ---: | ---: |")
    tmp = Path(tempfile.mkdtemp(prefix="bench-sampling-"))
    for ci in chosen:
        name, scene, w, h, opts = CASES[ci]
        sp = scene_path(scene, args.python)
        if not Path(sp).is_file():
            print(f"| {name} | skipped: {sp} not found | | | |")
            continue
        ref_spp = args.spp * args.ref_factor
        key = hashlib.sha1(json.dumps([str(sp), w, h, ref_spp, opts, kernels_key(REPO / "kernels")]).encode()).hexdigest()[:16]
        ref = cache / f"ref_{key}_0000.exr"
        if not ref.is_file():
            print(f"rendering the reference of {name} ({ref_spp} spp) ...", file=sys.stderr, flush=True)
            render(exe, sp, w, h, ref_spp, 1000, opts, ref, tmp / "ref.jsonl")
        results = {label: ([], []) for label, _ in configs}
        for seed in range(1, args.seeds + 1):
            for label, kd in configs:
                img = tmp / f"img_0000.exr"
                ks = render(exe, sp, w, h, args.spp, seed, opts, img, tmp / "s.jsonl", kd)
                results[label][0].append(relmse(compare, img, ref))
                results[label][1].append(ks)
        for label, _ in configs:
            e, t = results[label]
            me, mt = statistics.median(e), statistics.median(t)
            print(f"| {name} | {label} | {me:.5f} | {mt:.3f} | {me * mt:.5f} |", flush=True)


if __name__ == "__main__":
    main()
