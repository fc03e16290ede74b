"""Path resampling across frames, measured on animations: per frame relMSE against path-traced
references, seconds per frame, flicker, and the equal-error speed-up over the path tracer, for
the path tracer, `--resample` within each frame (`--resample-history 0`), `--resample` with the
previous frames' paths (1 neighbour, the default, and 3), and `--mode reuse` without path
resampling (`--no-resample`), as it is by default (resampled, no neighbours) and with 1 neighbour.

  /usr/bin/python3 -m tools.bench.bench_temporal                     # ~10-15 min on 2 cores
  /usr/bin/python3 -m tools.bench.bench_temporal --scenes atrium --seeds 1
  /usr/bin/python3 -m tools.bench.bench_temporal --scenes atrium --scene-args "--env sky.exr"
  /usr/bin/python3 -m tools.bench.bench_temporal --cycles VENV/bin/python   # and Cycles 5.2
  /usr/bin/python3 -m tools.bench.bench_temporal --cycles VENV/bin/python --luxcore LUXVENV/bin/python

With --cycles (a Python that has PyPI's bpy 5.2, Python 3.13, in a virtual environment of its
own: a benchmark peer, not a dependency), Blender's Cycles renders the measured frames too
(tools/bench/cycles_frames.py: the materials as Blender imports them, CPU, 2 threads), at each
spp of the sweep, and is measured against its own reference frames at the reference spp (cached
like ours), so that each renderer's relMSE is its distance from what it converges to. It has no
history to warm up; its seconds are those of its renders, without Blender's start and import.

With --luxcore too (a Python that has PyPI's pyluxcore 2.11, Python 3.12, in a virtual environment
of its own), LuxCoreRender's BIDIRCPU renders the same frames (tools/bench/luxcore_frames.py, from
triangles that --cycles's bpy exports: tools/bench/scene_export.py), Russian roulette off, against
its own references at --luxcore-ref-spp (128: its frames take several times ours); its seconds
are from its session's start to its halt.

The first --warm frames of each run are rendered and not measured: temporal reuse needs a few
frames of history, as a user's sequence has after its start. Every figure is the median over
seeds (each seed one process per setting and spp, settings interleaved); relMSE is exr_compare's
and the equal-error time is interpolated in log-log over the spp sweep, as tools/bench/evaluate.py
does. Needs numpy, hence /usr/bin/python3.
"""

import argparse
import hashlib
import json
import math
import os
import subprocess
import sys
import tempfile
from pathlib import Path

from .benchlib import ATRIUM, REPO, median
from .evaluation.metrics import LOWEST, flicker, interp_time
from .evaluation.run import Runner, die, file_sha, load_scenes, references, warm_up

SETTINGS = {
    "pathtrace": ("pathtrace", ()),
    "resample, one frame": ("pathtrace", ("--resample", "--resample-history", "0")),
    "resample": ("pathtrace", ("--resample",)),
    "resample, 3 neighbours": ("pathtrace", ("--resample", "--resample-neighbors", "3")),
    "resample, no neighbours": ("pathtrace", ("--resample", "--resample-neighbors", "0")),
    "reuse, no resample": ("reuse", ("--no-resample",)),
    "reuse": ("reuse", ()),  # resampled, no neighbours: the default
    "reuse, 1 neighbour": ("reuse", ("--resample-neighbors", "1")),
    "reuse, connection history": ("reuse", ("--connection-history", "20")),
    "reuse, no light tracing": ("reuse", ("--no-light-tracing",)),
    # Light sampling weighing the environment by its whole power (before 2026-12-06's default).
    "pathtrace, env by power": ("pathtrace", ("--env-light-choice", "power")),
    "reuse, env by power": ("reuse", ("--env-light-choice", "power")),
    # The previous frame's confidence capped lower than the default 20.
    "reuse, history 1": ("reuse", ("--resample-history", "1")),
    "reuse, history 4": ("reuse", ("--resample-history", "4")),
    # Fewer light paths per camera sample (default 4).
    "reuse, 2 paths per pixel": ("reuse", ("--paths-per-pixel", "2")),
    "reuse, 1 path per pixel": ("reuse", ("--paths-per-pixel", "1")),
    # One shadow ray per eye vertex, to a candidate chosen by RIS (the CPU default: all).
    "reuse, 1 connection": ("reuse", ("--connections", "1")),
}


def add_run_args(ap, frames, sweep, seeds, settings):
    """The options of a run that bench_temporal and bench_animations share (defaults their own)."""
    ap.add_argument("--width", type=int, default=160)
    ap.add_argument("--frames", type=int, default=frames, help="frames per run, --warm included")
    ap.add_argument("--warm", type=int, default=4, help="first frames rendered, not measured")
    ap.add_argument("--spp", type=int, default=4,
                    help="the spp the settings are compared at (the path tracer's target error)")
    ap.add_argument("--sweep-spp", default=sweep)
    ap.add_argument("--seeds", default=seeds)
    ap.add_argument("--ref-spp", type=int, default=512)
    ap.add_argument("--max-depth", type=int, default=8)
    ap.add_argument("--build", default="build", help="folder holding pathreuse and exr_compare")
    ap.add_argument("--json", help="write the figures here too")
    ap.add_argument("--cycles", help="a Python with bpy 5.2: measure Cycles too")
    ap.add_argument("--luxcore", help="a Python with pyluxcore 2.11: measure LuxCore BIDIR too "
                    "(needs --cycles's Python to export the frames)")
    ap.add_argument("--luxcore-ref-spp", type=int, default=128,
                    help="LuxCore's reference spp (its 4-spp frame takes 7x ours)")
    ap.add_argument("--settings", default=settings,
                    help="the settings measured, by name, separated by ';'")
    ap.add_argument("--quiet", action="store_true")


def check_run_args(args):
    """add_run_args's options checked and parsed; the programs' paths in args.exe, args.cmp."""
    args.settings = [n.strip() for n in args.settings.split(";")]
    for n in args.settings:
        if n not in SETTINGS:
            die(f"--settings: no setting {n!r} (there are: {'; '.join(SETTINGS)})")
    if args.luxcore and not args.cycles:
        die("--luxcore: give --cycles too (its bpy exports the frames LuxCore renders)")
    if "pathtrace" not in args.settings:
        die("--settings: the gains are over 'pathtrace', which must be one of them")
    args.sweep_spp = sorted({int(s) for s in args.sweep_spp.split(",")} | {args.spp})
    args.seeds = [int(s) for s in args.seeds.split(",")]
    if args.frames - args.warm < 2 or args.warm < 0:
        die("--frames must exceed --warm by at least 2 (flicker needs frame pairs)")
    args.reuse_args = ""
    build = Path(args.build) if Path(args.build).is_absolute() else REPO / args.build
    args.exe, args.cmp = build / "pathreuse", build / "exr_compare"
    for f in (args.exe, args.cmp):
        if not f.is_file():
            die(f"{f} not found; build first (tools/setup/build.sh)")


def parse_args():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scenes", default="atrium,cornell-dynamic,cornell-skinned")
    add_run_args(ap, frames=12, sweep="1,2,4,8", seeds="1,2,3", settings=";".join(SETTINGS))
    ap.add_argument("--atrium-ref-spp", type=int, default=256)
    ap.add_argument("--atrium", default=str(ATRIUM), help="atrium glTF (generated if absent)")
    ap.add_argument("--cache", default=str(REPO / "out" / "bench-temporal-cache"),
                    help="reference frames, kept between runs")
    ap.add_argument("--scene-args", default="",
                    help="options every render of ours takes, references too (e.g. '--env FILE'; "
                    "part of the references' key); the peers do not see them")
    args = ap.parse_args()
    check_run_args(args)
    # What load_scenes and Runner read.
    args.atrium_frames = args.frames
    args.timing_frames = args.atrium_timing_frames = args.frames
    args.atrium_sweep_spp = args.sweep_spp
    return args


def measure(runner, sc, ref_exrs, refs, args):
    """{setting: {spp: (relMSE, s/frame, flicker)}}, medians over seeds of the measured frames'
    mean relMSE, median seconds and mean flicker."""
    runs = {name: {s: [] for s in args.sweep_spp} for name in args.settings}
    for seed in args.seeds:
        for spp in args.sweep_spp:
            for name in args.settings:
                mode, extra = SETTINGS[name]
                recs, imgs, _, diffs = runner.render(sc.path, mode, spp, seed, sc.frames[0],
                                                     sc.frames[-1], extra=extra, refs=ref_exrs)
                w = args.warm
                e = sum(d["relmse"] for d in diffs[w:]) / len(diffs[w:])
                t = median([r["wall_s"] for r in recs[w:]])
                fl = [flicker(imgs[k - 1], imgs[k], refs[k - 1], refs[k])
                      for k in range(w + 1, len(imgs))]
                runs[name][spp].append((e, t, sum(fl) / len(fl)))
    return {name: {s: tuple(median([r[i] for r in rs]) for i in range(3)) for s, rs in by.items()}
            for name, by in runs.items()}


CYCLES = "Cycles 5.2 (its own reference)"
LUXCORE = "LuxCore 2.11 BIDIR (its own reference)"
BENCH = REPO / "tools" / "bench"


def measured(args, sc):
    """The first and last measured frame of a scene: its frames after the --warm ones."""
    return sc.frames[args.warm], sc.frames[-1]


def peer_view(sc):
    """What a peer is told of the view: the camera by name, the world's colour."""
    out = []
    if getattr(sc, "camera_name", None):
        out += ["--camera", sc.camera_name]
    if getattr(sc, "world", None):
        out += ["--world", sc.world]
    return out


def peer_frames(args, cmd, name, sc, spp, seed):
    """Runs a peer's frame script; the render seconds of the measured frames."""
    env = None
    if name == "luxcore":
        libs = sorted(Path(os.path.abspath(args.luxcore)).parent.parent.glob(
            "lib/python3*/site-packages/pyluxcore.libs/libtbbmalloc*.so*"))
        if len(libs) < 2:
            die(f"--luxcore {args.luxcore}: no pyluxcore.libs/libtbbmalloc* beside it", 1)
        env = dict(os.environ, LD_PRELOAD=":".join(map(str, libs)))
    proc = subprocess.run(cmd, capture_output=True, text=True, env=env)
    if proc.returncode != 0:
        die(f"{name} failed ({proc.returncode}): {' '.join(cmd)}\n{proc.stderr.strip()[-2000:]}", 1)
    recs = [json.loads(line) for line in proc.stdout.splitlines() if line.startswith("{")]
    first, last = measured(args, sc)
    if len(recs) != last - first + 1:
        die(f"expected {last - first + 1} frames from: {' '.join(cmd)}", 1)
    if not args.quiet:
        print(f"  {sc.key:16s} {name:9s} spp {spp:3d} seed {seed}       frames "
              f"{first}-{last}: median {median([r['render_s'] for r in recs]):.3f} "
              "s/frame", flush=True)
    return [r["render_s"] for r in recs]


def frame_args(args, sc, spp, seed, size):
    first, last = measured(args, sc)
    return ["--frames", f"{first}-{last}", "--spp", str(spp), "--width",
            str(size[1]), "--height", str(size[0]), "--max-depth", str(args.max_depth), "--seed",
            str(seed)]


def cycles_render(args, sc, spp, seed, size, out):
    """Cycles' measured frames at spp into out/f_%04d.exr; their render seconds."""
    out.mkdir(parents=True, exist_ok=True)
    cmd = [args.cycles, str(BENCH / "cycles_frames.py"), str(sc.path), str(out)]
    return peer_frames(args, cmd + frame_args(args, sc, spp, seed, size) + peer_view(sc), "cycles",
                       sc, spp, seed)


def luxcore_export(args, sc, size, cache):
    """The measured frames as triangles (tools/bench/scene_export.py), kept in the cache."""
    first, last = measured(args, sc)
    key = hashlib.sha1(json.dumps([file_sha(sc.path), list(size), first, last, peer_view(sc),
                                   file_sha(BENCH / "scene_export.py")]).encode()).hexdigest()[:16]
    out = cache / f"{sc.key}_export_{key}"
    if not (out / "scene.json").is_file():
        out.mkdir(parents=True, exist_ok=True)
        cmd = [args.cycles, str(BENCH / "scene_export.py"), str(sc.path), str(out), "--frames",
               f"{first}-{last}", "--width", str(size[1]), "--height", str(size[0]),
               *peer_view(sc)]
        proc = subprocess.run(cmd, capture_output=True, text=True)
        if proc.returncode != 0 or not (out / "scene.json").is_file():
            die(f"export failed ({proc.returncode}): {' '.join(cmd)}\n{proc.stderr[-2000:]}", 1)
    return out


def luxcore_render(args, export, sc, spp, seed, size, out):
    """LuxCore's measured frames at spp into out/f_%04d.exr; their render seconds."""
    out.mkdir(parents=True, exist_ok=True)
    cmd = [args.luxcore, str(BENCH / "luxcore_frames.py"), str(export), str(out)]
    return peer_frames(args, cmd + frame_args(args, sc, spp, seed, size), "luxcore", sc, spp, seed)


def peer_measure(runner, sc, size, args, cache, tmp, name, ref_spp, render):
    """A peer's row, {spp: (relMSE, s/frame, flicker)}, against its own reference frames;
    render(spp, seed, out) renders the measured frames."""
    first, last = measured(args, sc)
    key = hashlib.sha1(json.dumps([file_sha(sc.path), list(size), ref_spp, args.max_depth, name,
                                   first, last, peer_view(sc)]).encode()).hexdigest()[:16]
    frames = range(first, last + 1)
    ref_dir = cache / f"{sc.key}_{name.split('-')[0]}_{key}"
    ref_exrs = [ref_dir / f"f_{f:04d}.exr" for f in frames]
    if not all(p.is_file() for p in ref_exrs):
        print(f"  {name} references for {sc.key}: {len(ref_exrs)} frame(s) at {ref_spp} spp",
              flush=True)
        render(ref_spp, 1000, ref_dir)
    refs = runner.read(ref_exrs)
    runs = {s: [] for s in args.sweep_spp}
    for seed in args.seeds:
        for spp in args.sweep_spp:
            out = tmp / f"{name}_{sc.key}_{spp}_{seed}"
            secs = render(spp, seed, out)
            exrs = [out / f"f_{f:04d}.exr" for f in frames]
            e = [runner.diff(x, r)["relmse"] for x, r in zip(exrs, ref_exrs)]
            imgs = runner.read(exrs)
            fl = [flicker(imgs[k - 1], imgs[k], refs[k - 1], refs[k]) for k in range(1, len(imgs))]
            runs[spp].append((sum(e) / len(e), median(secs), sum(fl) / len(fl)))
    return {s: tuple(median([r[i] for r in rs]) for i in range(3)) for s, rs in runs.items()}


def report(sc, fig, args):
    """Markdown lines: the sweep, then the equal-error speed-up and flicker against the path
    tracer at --spp."""
    pt = fig["pathtrace"][args.spp]
    target = pt[0]
    first, last = measured(args, sc)
    lines = [f"### {sc.key} ({args.width} px wide, frames {first}-{last} of "
             f"{sc.frames[0]}-{last} measured, seeds {','.join(map(str, args.seeds))})", "",
             "| setting | " + " | ".join(f"spp {s}: relMSE, s/frame" for s in args.sweep_spp)
             + f" | equal-error speed-up (target: path tracer at {args.spp} spp) "
             f"| relMSE x s at {args.spp} spp: the path tracer's over this "
             f"| flicker at {args.spp} spp, / path tracer's |",
             "|---|" + "---|" * (len(args.sweep_spp) + 3)]
    out = {}
    for name, by in fig.items():
        pts = [(by[s][1], by[s][0]) for s in args.sweep_spp]
        t, how = interp_time(pts, target)
        sp = pt[1] / t if t else None
        fl = by[args.spp][2] / pt[2] if pt[2] > 0 else math.nan
        cells = [f"{by[s][0]:.4f}, {by[s][1]:.3f}" for s in args.sweep_spp]
        sps = "not reached" if sp is None else f"{sp:.2f}x" + (" (at least)" if how == LOWEST else "")
        # The path tracer's error falls as 1 / spp at a time that grows as spp, so this is the
        # equal-error speed-up at this setting's error where the target is passed below 1 spp.
        work = by[args.spp][0] * by[args.spp][1]
        gain = pt[0] * pt[1] / work if work > 0 else math.nan
        lines.append(f"| {name} | " + " | ".join(cells) + f" | {sps} | {gain:.2f}x | {fl:.2f} |")
        out[name] = {"points": {str(s): dict(zip(("relmse", "s_per_frame", "flicker"), by[s]))
                                for s in args.sweep_spp},
                     "equal_error_speedup": sp, "speedup_lower_bound": how == LOWEST,
                     "relmse_seconds_gain": gain,
                     "flicker_ratio": fl}
    return lines + [""], out


def main():
    args = parse_args()
    scenes = load_scenes(args)
    for sc in scenes:
        if sc.key == "atrium":
            sc.ref_spp = args.atrium_ref_spp
    cache = Path(args.cache)
    lines, out = [], {}
    with tempfile.TemporaryDirectory(prefix="bench-temporal-") as tmp:
        tmp = Path(tmp)
        warm_up(args.exe, scenes, tmp)
        runner = Runner(args, tmp)
        for sc in scenes:
            ref_exrs, refs, _ = references(runner, sc, cache)
            fig = measure(runner, sc, ref_exrs, refs, args)
            size = refs[0].shape[:2]
            if args.cycles:
                fig[CYCLES] = peer_measure(
                    runner, sc, size, args, cache, tmp, "cycles-5.2", sc.ref_spp,
                    lambda spp, seed, out: cycles_render(args, sc, spp, seed, size, out))
            if args.luxcore:
                export = luxcore_export(args, sc, size, cache)
                fig[LUXCORE] = peer_measure(
                    runner, sc, size, args, cache, tmp, "luxcore-2.11-bidir", args.luxcore_ref_spp,
                    lambda spp, seed, out: luxcore_render(args, export, sc, spp, seed, size, out))
            l, o = report(sc, fig, args)
            lines += l
            out[sc.key] = o
            print("\n".join(l), flush=True)
    if args.json:
        Path(args.json).write_text(json.dumps(out, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
