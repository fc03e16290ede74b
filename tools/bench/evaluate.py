"""Evaluation of pathreuse against the paper's claims: time per frame of reuse,
retrace and pathtrace (the paper's Figure 9), error against a high-sample reference, temporal
flicker, equal-time and equal-error comparisons. Writes results.md, results.json and PNG plots.

  /usr/bin/python3 -m tools.bench.evaluate              # full run into docs/, ~30-45 min on 2 cores
  /usr/bin/python3 -m tools.bench.evaluate --quick --out-dir /tmp/eval   # smoke form, < 1 min

Needs numpy and matplotlib (Debian: python3-numpy python3-matplotlib, installed by
tools/setup/install-deps.sh), hence /usr/bin/python3. Reads EXRs through `exr_compare --raw`
and measures relMSE with `exr_compare` (the renderer's own comparison).

Runs are interleaved across modes (reuse, pathtrace, ... per seed) so that load from other
users of the machine hits all modes alike; every time is the median of >= 3 runs (seeds double
as repeats) with min and max. References are pathtrace renders at high spp with their own
seed, cached on disk keyed by scene content and settings.

This file reads the options and runs the steps; the work is in tools/bench/evaluation/: run.py
(renders, references), metrics.py, plots.py, report.py (results.md, results.json) and
results.py (the dataclasses that carry the results between them).
"""

import argparse
import shutil
import sys
import tempfile
import time
from pathlib import Path

from .benchlib import ATRIUM, REPO

try:
    import numpy  # noqa: F401
    import matplotlib  # noqa: F401
except ImportError as e:  # the smoke test must fail, not skip, without them
    print(f"evaluate: {e}; install python3-numpy python3-matplotlib (bash tools/setup/install-deps.sh) "
          "and run with /usr/bin/python3", file=sys.stderr)
    sys.exit(1)

from .evaluation import plots, report  # noqa: E402
from .evaluation.run import Runner, die, evaluate_scene, load_scenes, warm_up  # noqa: E402


def parse_args():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out-dir", default=str(REPO / "docs"), help="results.md, results.json, PNGs")
    ap.add_argument("--quick", action="store_true", help="smoke form: tiny, < 1 min")
    ap.add_argument("--width", type=int, default=160)
    ap.add_argument("--frames", type=int, default=21,
                    help="consecutive quality frames of the cornell scenes (>= 17 for 16 pairs)")
    ap.add_argument("--atrium-frames", type=int, default=17)
    ap.add_argument("--timing-frames", type=int, default=121,
                    help="frames of the timing runs (cornell scenes; default: the whole animation)")
    ap.add_argument("--atrium-timing-frames", type=int, default=49)
    ap.add_argument("--spp", type=int, default=4, help="default spp (equal-error target)")
    ap.add_argument("--sweep-spp", default="1,2,4,8,16")
    ap.add_argument("--atrium-sweep-spp", default="1,2,4,8")
    ap.add_argument("--seeds", default="1,2,3")
    ap.add_argument("--repeats", type=int, default=3, help="timing runs per mode")
    ap.add_argument("--ref-spp", type=int, default=512)
    ap.add_argument("--atrium-ref-spp", type=int, default=256)
    ap.add_argument("--max-depth", type=int, default=8)
    ap.add_argument("--exposure", type=float, default=0.0, help="EV for the contact sheets")
    ap.add_argument("--equal-time-rounds", type=int, default=2)
    ap.add_argument("--scenes", default="cornell-dynamic,cornell-orbit,cornell-skinned,atrium")
    ap.add_argument("--atrium", default=str(ATRIUM), help="atrium glTF (generated if absent)")
    ap.add_argument("--build", default="build", help="folder holding pathreuse and exr_compare")
    ap.add_argument("--cache", default=None, help="reference cache (default out/evaluate-cache)")
    ap.add_argument("--quiet", action="store_true")
    ap.add_argument("--reuse-args", default="",
                    help="extra options of every reuse and retrace render, e.g. "
                         "\"--connections 1 --connection-history 20\"")
    args = ap.parse_args()
    if args.quick:
        args.width, args.frames, args.atrium_frames = 32, 5, 5
        args.timing_frames = args.atrium_timing_frames = 5
        args.sweep_spp = args.atrium_sweep_spp = "1,4"
        args.seeds, args.repeats, args.ref_spp, args.atrium_ref_spp = "1", 1, 16, 16
        args.equal_time_rounds = 1
    args.seeds = [int(s) for s in args.seeds.split(",")]
    args.sweep_spp = sorted({int(s) for s in args.sweep_spp.split(",")} | {args.spp})
    args.atrium_sweep_spp = sorted({int(s) for s in args.atrium_sweep_spp.split(",")} | {args.spp})
    if min(args.width, args.frames, args.atrium_frames, args.spp, args.repeats, min(args.sweep_spp)) < 1:
        die("sizes, frames, spp and repeats must be >= 1")
    if min(args.frames, args.atrium_frames, args.timing_frames, args.atrium_timing_frames) < 2:
        die("at least 2 frames are needed for flicker")
    build = Path(args.build) if Path(args.build).is_absolute() else REPO / args.build
    args.exe, args.cmp = build / "pathreuse", build / "exr_compare"
    for f in (args.exe, args.cmp):
        if not f.is_file():
            die(f"{f} not found; build first: cmake -S . -B build -DCMAKE_BUILD_TYPE=RelWithDebInfo "
                "&& cmake --build build -j2")
    return args


def main():
    args = parse_args()
    argv = sys.argv[1:]
    out_dir = Path(args.out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    cache = Path(args.cache) if args.cache else (out_dir / ".cache" if args.quick
                                                 else REPO / "out" / "evaluate-cache")
    scenes = load_scenes(args)

    t_start = time.perf_counter()
    tmp = Path(tempfile.mkdtemp(prefix="evaluate_"))
    try:
        runner = Runner(args, tmp)
        warm_up(args.exe, scenes, tmp)
        results = [evaluate_scene(runner, sc, cache, args) for sc in scenes]
        elapsed = time.perf_counter() - t_start
        names, mp4s = plots.write_all(results, args, out_dir, tmp)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)

    ev = report.Evaluation(args=args, argv=argv, results=results, plots=names, mp4s=mp4s,
                           elapsed=elapsed, loads=runner.loads)
    doc = report.write(out_dir, ev)
    print(f"wrote {out_dir / 'results.md'}, results.json and {len(doc['plots'])} PNGs ({elapsed:.0f} s)")


if __name__ == "__main__":
    main()
