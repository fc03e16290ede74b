"""The evaluation's report: the goals and their verdicts, results.md (findings, plots, and per
scene the timing, quality, equal-time and equal-error tables) and results.json."""

import datetime
import json
import os
from dataclasses import asdict, dataclass
from pathlib import Path

from ..benchlib import machine_lines, median

from .results import MODES, REF_SEED, Goal, Stats

GOAL_TIME_RATIO = 0.5    # reuse / retrace per-frame time
GOAL_F_RATIO = 1 / 3     # reuse F / pathtrace F at equal time
GOAL_SPEEDUP = 2.0       # equal-error speed-up over pathtrace
PAPER_RATIO = 0.7        # the paper's "about 30% less computation"


@dataclass
class Evaluation:
    """All that results.md and results.json report."""
    args: object                 # evaluate.py's parsed options (sweeps as lists)
    argv: list
    results: list                # SceneResult, in --scenes order
    plots: object                # plots.PlotFiles
    mp4s: list
    elapsed: float               # seconds of the runs
    loads: list                  # 1-min load average before each run

    def command(self):
        return "/usr/bin/python3 -m tools.bench.evaluate" + "".join(f" {a}" for a in self.argv)


def fmt_e(x):
    return f"{x:.4g}"


def goals(results):
    """The goals' verdicts: time per frame on every scene, equal time and equal error on the
    still-camera ones."""
    rows = []
    for r in results:
        ratio = r.time_ratio()
        same = max(r.identical) == 0.0
        rows.append(Goal("reuse <= 0.5 x retrace time per frame, identical output", r.scene.key,
                         f"{ratio:.3f} ({'bit-identical' if same else 'NOT identical'})",
                         ratio <= GOAL_TIME_RATIO and same))
    for r in results:
        if r.scene.camera != "still":
            continue
        a, b = r.equal_time.reuse, r.equal_time.pathtrace_fresh
        rows.append(Goal("equal time: reuse relMSE < pathtrace relMSE", r.scene.key,
                         f"{a.relmse:.4g} vs {b.relmse:.4g}", a.relmse < b.relmse))
        fr = a.flicker / b.flicker if b.flicker > 0 else float("inf")
        rows.append(Goal("equal time: reuse F <= 1/3 of pathtrace F (fresh seeds)", r.scene.key,
                         f"{a.flicker:.4g} vs {b.flicker:.4g} (ratio {fr:.3f})", fr <= GOAL_F_RATIO))
        ee = r.equal_error
        sp, bound = ee.speedup, ee.speedup_lower_bound
        ok = bool(sp and sp >= GOAL_SPEEDUP)
        rows.append(Goal("equal-error speed-up over pathtrace >= 2x", r.scene.key,
                         (f"at least {sp:.2f}x (reuse beats the target at its lowest spp)" if bound
                          else f"{sp:.2f}x") if sp else "not reached",
                         None if bound and not ok else ok))
    return rows


# ---------------------------------------------------------------- results.md

def kernel_table(t):
    stages = sorted({k for m in MODES for k in t[m].stage_share_percent})
    L = ["| stage | " + " | ".join(MODES) + " |", "|---|" + "---:|" * len(MODES)]
    for st in stages:
        cells = [f"{t[m].stage_share_percent[st]:.1f}% ({t[m].stage_s_per_frame[st]:.4f} s)"
                 if st in t[m].stage_share_percent else "-" for m in MODES]
        L.append(f"| {st} | " + " | ".join(cells) + " |")
    return L


def timing_section(r, args):
    sc, t = r.scene, r.timing
    tf, tl = sc.timing_frames
    L = ["### Time per frame (the paper's Figure 9)", "",
         f"Frames {tf}-{tl}, spp {args.spp}, seed {args.seeds[0]}, {args.repeats} runs per mode, "
         "interleaved. s/frame: median over a run's frames after its first (reuse traces every "
         "slot in its first frame), then median [min-max] over runs. total: the sum of all "
         "frames' wall time of a run, median [min-max] over runs.", "",
         "| mode | wall s/frame | kernel s/frame | first frame s | total s | process s |",
         "|---|---:|---:|---:|---:|---:|"]
    for m in MODES:
        s = t[m]
        L.append(f"| {m} | {s.wall_s_per_frame.fmt()} | {s.kernel_s_per_frame.fmt()} | "
                 f"{s.frame0_s:.3f} | {s.total_s.fmt('{:.2f}')} | {s.process_s.fmt('{:.1f}')} |")
    rr = [a / b for a, b in zip(t["reuse"].per_run_wall, t["retrace"].per_run_wall)]
    rp = [a / b for a, b in zip(t["reuse"].per_run_wall, t["pathtrace"].per_run_wall)]
    diff = max(r.identical)
    L += ["", "Per-run ratios of s/frame (runs made back to back), median [min-max]: "
          f"reuse/retrace {Stats.of(rr).fmt()}; reuse/pathtrace at the same spp (not equal "
          f"noise) {Stats.of(rp).fmt()}.",
          f"Slots reused per frame (reuse): {100 * (t['reuse'].slots_reused_fraction or 0):.2f}% (median). "
          f"reuse and retrace images, same seed and spp, over {len(r.identical)} seed(s) x "
          f"{len(sc.frames)} frames: largest |difference| {diff:.3g}"
          f" ({'bit-identical' if diff == 0 else 'not identical'}).", "",
          "Rays by kind per frame (median):", "",
          "| rays | " + " | ".join(MODES) + " |", "|---|" + "---:|" * len(MODES)]
    kinds = sorted({k for m in MODES for k in t[m].rays_per_frame})
    for k in kinds:
        L.append(f"| {k} | " + " | ".join(f"{t[m].rays_per_frame[k]:,.0f}" if k in t[m].rays_per_frame
                                         else "-" for m in MODES) + " |")
    L += ["", "Share of kernel time per stage (percent of summed `stages_s`; median s per frame):", "",
          *kernel_table(t), ""]
    return L


def quality_section(r):
    sc = r.scene
    L = ["### Error and flicker against the reference", "",
         f"Frames {sc.frames[0]}-{sc.frames[-1]} ({len(sc.frames)} frames, "
         f"{len(sc.frames) - 1} pairs); reference: pathtrace at {sc.ref_spp} spp, seed "
         f"{REF_SEED}. relMSE: mean over frames, then over seeds; F: mean over pairs, then over "
         f"seeds; [min-max] over seeds. s/frame: median [min-max] over the seeds' runs.", "",
         "relMSE (trim 1%): the same sum without each frame's worst 1% of pixels, divided by all "
         "pixels (as `pathreuse portability`'s relMSE*); median frame: the "
         "median of the per-frame relMSE over frames and seeds (both show how much a few "
         "fireflies decide the mean).", "",
         "| mode | spp | s/frame | relMSE | relMSE (trim 1%) | median frame relMSE | F | F / relMSE |",
         "|---|---:|---:|---:|---:|---:|---:|---:|"]
    for s in r.sorted_settings():
        q = s.summary()
        er, fl = q.relmse_runs, q.flicker_runs
        L.append(f"| {s.mode}{' (fixed noise)' if s.fixed else ''} | {s.spp} | "
                 f"{q.time_s_per_frame.fmt()} | {fmt_e(q.relmse)} [{fmt_e(min(er))}-{fmt_e(max(er))}] | "
                 f"{fmt_e(q.relmse_trim)} | {fmt_e(q.relmse_median_frame)} | "
                 f"{fmt_e(q.flicker)} [{fmt_e(min(fl))}-{fmt_e(max(fl))}] | "
                 f"{q.flicker / q.relmse:.2f} |")
    return L


def equal_time_section(et):
    L = ["", "### Equal time", "",
         f"reuse at spp {et.reuse_spp} against pathtrace at the spp whose time per frame "
         "matches, measured in interleaved runs (reuse, pathtrace per seed):", "",
         "| round | pathtrace spp | reuse s/frame | pathtrace s/frame | pathtrace / reuse (per seed) |",
         "|---:|---:|---:|---:|---:|"]
    for i, rd in enumerate(et.rounds):
        L.append(f"| {i + 1} | {rd.pathtrace_spp} | {rd.reuse_s.fmt()} | {rd.pathtrace_s.fmt()} | "
                 f"{rd.ratio:.3f} ({', '.join(f'{x:.3f}' for x in rd.ratios_per_seed)}) |")
    fresh = et.pathtrace_fresh
    L += ["", f"Chosen: pathtrace spp {et.pathtrace_spp}, time ratio "
          f"{et.time_ratio_pathtrace_over_reuse:.3f} "
          f"({'within' if et.within_5_percent else 'NOT within'} 5%).", "",
          "| mode | spp | relMSE | relMSE (trim 1%) | F | relMSE / pathtrace's | F / pathtrace's |",
          "|---|---:|---:|---:|---:|---:|---:|"]
    for name, s in (("reuse", et.reuse), ("pathtrace, fresh seed per frame", et.pathtrace_fresh),
                    ("pathtrace, fixed seed per frame", et.pathtrace_fixed)):
        L.append(f"| {name} | {s.spp} | {fmt_e(s.relmse)} | {fmt_e(s.relmse_trim)} | {fmt_e(s.flicker)} | "
                 f"{s.relmse / fresh.relmse:.3f} | {s.flicker / fresh.flicker:.3f} |")
    return L


def equal_error_section(ee, spp):
    L = ["", "### Equal error", "",
         f"Target: the relMSE of {ee.target_from} (fresh seeds), {fmt_e(ee.target_relmse)}"
         + (f" (reuse's lowest spp already beats pathtrace's at spp {spp}, so the target is "
            "the first larger spp of the sweep that reuse's sweep brackets)"
            if ee.target_from != f"pathtrace spp {spp}" else "") + ". "
         "Time to reach it: log-log interpolation between the two sweep points around it; "
         "no extrapolation. Tail slope: d log relMSE / d log spp between the last two sweep "
         "points (-1 when error is variance only; near 0 at a floor).", "",
         "| mode | time to target s/frame | how | tail slope |", "|---|---:|---|---:|"]
    for m, e in (("reuse", ee.reuse), ("pathtrace", ee.pathtrace)):
        L.append(f"| {m} | {e.time_s:.4f} | {e.how} | {e.tail_slope:.2f} |" if e.time_s
                 else f"| {m} | not reached | {e.how} (lowest relMSE "
                      f"{fmt_e(min(p.relmse for p in e.points))}) | {e.tail_slope:.2f} |")
    L += ["", "Speed-up (pathtrace time / reuse time at the target): "
          + (f"{ee.speedup:.2f}x" if ee.speedup else "not reached") + ". On relMSE without "
          "each frame's worst 1% of pixels (a diagnosis, not the goal's measure): "
          + (f"{ee.trimmed.speedup:.2f}x" if ee.trimmed.speedup else "not reached") + ".", ""]
    return L


def scene_section(r, args, names):
    sc = r.scene
    return [f"## {sc.key} ({sc.camera} camera)", "",
            f"`{sc.path}`" + (f", {sc.triangles}" if sc.triangles else "") + ".", "",
            *timing_section(r, args), *quality_section(r), *equal_time_section(r.equal_time),
            *equal_error_section(r.equal_error, args.spp),
            f"![contact sheet]({names.sheets[sc.key]})", ""]


def findings(results, args):
    F = []
    for r in results:
        key = r.scene.key
        ratio = r.time_ratio()
        re, rt = r.timing["reuse"], r.timing["retrace"]
        lt = rt.stage_share_percent.get("light_trace", 0.0)
        top = max(re.stage_share_percent, key=re.stage_share_percent.get)
        F.append(f"- **{key}, time**: reuse/retrace = {ratio:.3f} per frame (goal <= "
                 f"{GOAL_TIME_RATIO}: {'met' if ratio <= GOAL_TIME_RATIO else 'NOT met'}; the "
                 f"paper's {PAPER_RATIO}: {'at or below' if ratio <= PAPER_RATIO else 'above'}). "
                 f"`light_trace` is {lt:.1f}% of retrace's kernel time, so skipping every light "
                 f"path could at best give {1 - lt / 100:.2f}; `{top}` holds "
                 f"{re.stage_share_percent[top]:.1f}% of reuse's kernel time "
                 f"({re.stage_s_per_frame[top]:.4f} of {re.kernel_s_per_frame.median:.4f} s per frame).")
        et = r.equal_time
        a, b, c = et.reuse, et.pathtrace_fresh, et.pathtrace_fixed
        F.append(f"- **{key}, equal time** (reuse spp {a.spp}, pathtrace spp {b.spp}, time "
                 f"ratio {et.time_ratio_pathtrace_over_reuse:.3f}): relMSE {fmt_e(a.relmse)} vs "
                 f"{fmt_e(b.relmse)} (ratio {a.relmse / b.relmse:.3f}); F {fmt_e(a.flicker)} vs "
                 f"{fmt_e(b.flicker)} (ratio {a.flicker / b.flicker:.3f}). Pathtrace with a "
                 f"fixed seed: relMSE {fmt_e(c.relmse)}, F {fmt_e(c.flicker)} (ratio "
                 f"{c.flicker / b.flicker:.3f} to fresh seeds): freezing the noise lowers F "
                 f"without lowering the error.")
        ee = r.equal_error
        if ee.speedup:
            F.append(f"- **{key}, equal error**: reuse reaches the relMSE of {ee.target_from} "
                     f"in {ee.reuse.time_s:.4f} s per frame against "
                     f"{ee.pathtrace.time_s:.4f} s: speed-up "
                     + (f"at least {ee.speedup:.2f}x (reuse's lowest spp already beats the "
                        "target, so its time there bounds what it needs from above)."
                        if ee.speedup_lower_bound else f"{ee.speedup:.2f}x."))
        else:
            lo = min(p.relmse for p in ee.reuse.points)
            F.append(f"- **{key}, equal error**: reuse does not reach pathtrace's "
                     f"spp-{args.spp} relMSE ({fmt_e(ee.target_relmse)}) within the sweep "
                     f"(spp up to {ee.reuse.points[-1].spp}; lowest {fmt_e(lo)}, tail slope "
                     f"{ee.reuse.tail_slope:.2f}): not reached.")
        q = r.setting("reuse", args.spp).summary()
        p = r.setting("pathtrace", args.spp).summary()
        ts = ee.trimmed.speedup
        F.append(f"- **{key}, error tails** (spp {args.spp}): reuse's relMSE per seed "
                 f"{', '.join(fmt_e(x) for x in q.relmse_runs)} (pathtrace: "
                 f"{', '.join(fmt_e(x) for x in p.relmse_runs)}); median frame {fmt_e(q.relmse_median_frame)} "
                 f"vs {fmt_e(p.relmse_median_frame)}; without each frame's worst 1% of pixels "
                 f"{fmt_e(q.relmse_trim)} vs {fmt_e(p.relmse_trim)}, equal-error speed-up on "
                 f"that measure " + (f"{ts:.2f}x" if ts else "not reached") + ". Where the "
                 "two measures disagree, large, rare errors decide the mean; reuse's light paths "
                 "persist across frames, so an error that comes from one persists too (which "
                 "connections cause them is not isolated here).")
    return F


def write_markdown(path, ev, gl):
    args, loads, names = ev.args, ev.loads, ev.plots
    now = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    L = ["# Evaluation: reuse, retrace and pathtrace against the paper's claims", "",
         "Written by `tools/bench/evaluate.py`. The paper claims (a) about 30% less "
         "computation than path tracing over an animation (its Figure 9) and (b) less temporal "
         "flicker at the same computing time (its Figures 6-8). This page measures both on our "
         "scenes.", "",
         f"- date: {now}", *machine_lines(args.exe),
         f"- command: `{ev.command()}`" + (" (QUICK smoke form: the figures mean nothing)" if args.quick else ""),
         f"- settings: width {args.width} (height from each camera's aspect), default spp "
         f"{args.spp}, max depth {args.max_depth}, renderer defaults for C (4 light paths per "
         f"sample) and N_L (one slot per pixel); seeds {args.seeds} (the seeds are the repeats); "
         f"sweep spp {args.sweep_spp}; timing runs: {args.repeats} per mode",
         f"- load: 1-min load average before each run, median {median(loads):.2f} "
         f"[{min(loads):.2f}-{max(loads):.2f}] on {os.cpu_count()} CPUs (shared cores)",
         f"- total evaluation time: {ev.elapsed:.0f} s", "",
         "Definitions. relMSE = mean over pixels and RGB channels of (I - R)^2 / (R^2 + 0.01), "
         "measured by `exr_compare` (the renderer's own comparison, host/portability/compare.cpp). "
         "Flicker F = mean over consecutive pairs (t-1, t), pixels and channels of "
         "((I_t - I_{t-1}) - (R_t - R_{t-1}))^2 / (((R_t + R_{t-1}) / 2)^2 + 0.01): real "
         "lighting change cancels, only noise that changes between frames counts. A frozen "
         "noise pattern lowers F but not relMSE, so F is always shown next to relMSE. "
         "Pathtrace runs both with a fresh seed per frame (the frame number is part of the "
         "random-number key: the usual practice) and with `--fixed-noise` (the key ignores the "
         "frame: the same noise pattern every frame). Reuse's light paths are keyed by slot and "
         "stay the same across frames unless moving objects disturb them; its camera samples "
         "change every frame. The reference has noise of its own: its relMSE is about "
         "spp/ref_spp of a run's (under 1% at spp 4), so it is left in.", "",
         "## Goals", "", "| goal | scene | measured | verdict |", "|---|---|---|---|"]
    for g in gl:
        verdict = "undetermined (a lower bound below the goal)" if g.met is None else (
            "met" if g.met else "**NOT met**")
        L.append(f"| {g.goal} | {g.scene} | {g.measured} | {verdict} |")
    L += ["", f"Goals checked on the still-camera scenes: "
          f"{', '.join(r.scene.key for r in ev.results if r.scene.camera == 'still')}. Where a goal is "
          "missed, the kernel that holds the time is named under Findings and tabled per scene.", "",
          "## Findings", "", *findings(ev.results, args), "",
          "## Plots", "",
          f"![time per frame]({names.time})", "",
          f"![error against time]({names.error})", "",
          f"![equal time]({names.equal})", "",
          f"![per-frame error and flicker]({names.perframe})", ""]
    if ev.mp4s:
        L += ["Videos (ffmpeg): " + ", ".join(f"`{m}`" for m in ev.mp4s), ""]
    else:
        L += ["No MP4: ffmpeg is not installed on this machine (the script writes one per scene "
              "when it is).", ""]
    for r in ev.results:
        L += scene_section(r, args, names)
    Path(path).write_text("\n".join(L) + "\n")


# ---------------------------------------------------------------- results.json

def scene_json(r):
    sc = r.scene
    return {
        "scene": str(sc.path), "camera": sc.camera, "triangles": sc.triangles,
        "quality_frames": [sc.frames[0], sc.frames[-1]],
        "timing_frames": list(sc.timing_frames), "reference_spp": sc.ref_spp,
        "reference_cache_key": r.ref_key,
        "reuse_equals_retrace_max_abs_diff": max(r.identical),
        "timing": {m: r.timing[m].to_json() for m in MODES},
        "sweep": [asdict(s.summary()) for s in r.sorted_settings()],
        "equal_time": asdict(r.equal_time),
        "equal_error": asdict(r.equal_error),
    }


def write_json(path, ev, gl):
    """results.json; returns the document."""
    args = ev.args
    doc = {"date": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
           "command": ev.command(),
           "quick": args.quick,
           "settings": {"width": args.width, "spp": args.spp, "max_depth": args.max_depth,
                        "seeds": args.seeds, "repeats": args.repeats, "sweep_spp": args.sweep_spp,
                        "atrium_sweep_spp": args.atrium_sweep_spp, "reference_seed": REF_SEED},
           "elapsed_s": ev.elapsed, "load_avg": asdict(Stats.of(ev.loads)),
           "scenes": {r.scene.key: scene_json(r) for r in ev.results},
           "goals": [g.to_json() for g in gl],
           "plots": ev.plots.all(), "videos": ev.mp4s}
    Path(path).write_text(json.dumps(doc, indent=1, allow_nan=False) + "\n")
    return doc


def write(out_dir, ev):
    """results.json and results.md; returns the JSON document."""
    gl = goals(ev.results)
    doc = write_json(out_dir / "results.json", ev, gl)
    write_markdown(out_dir / "results.md", ev, gl)
    return doc
