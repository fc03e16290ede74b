"""Benchmark of several devices in one render: PoCL's two drivers (POCL_DEVICES="pthread
basic") together against each alone, in reuse and pathtrace modes, on the demo animation.
Prints a markdown report: per-frame wall time, the overhead of two devices against the faster
one alone, the rows each device got (load balance) and what the replicated light paths cost.

  python3 -m tools.bench.bench_multidevice              # defaults, ~5 min on 2 cores
  python3 -m tools.bench.bench_multidevice --quick      # smoke run

Runs are interleaved per repeat (basic, pthread, both, basic, ...) so that load from other
users of the machine hits every configuration alike. Frame 0 (a warm-up: reuse traces every
slot there, and the split is even) is left out of the per-frame figures. Standard library only.
"""

import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from .benchlib import REPO, machine_lines, median

DEMO = REPO / "scenes" / "cornell-dynamic.gltf"
LIGHT_STAGES = ("invalidate", "light_trace")


def die(msg):
    print(f"bench_multidevice: {msg}", file=sys.stderr)
    sys.exit(2)


def pocl_devices(exe, env):
    out = subprocess.run([str(exe), "devices", "--json"], capture_output=True, text=True, env=env)
    if out.returncode != 0:
        die(f"pathreuse devices failed: {out.stderr.strip()}")
    devs = [d for d in json.loads(out.stdout)["devices"] if d["platform_vendor"] == "The pocl project"]
    if len(devs) != 2:
        die(f"expected PoCL's two drivers under POCL_DEVICES='pthread basic', found {len(devs)}")
    basic = next((d for d in devs if "basic" in d["name"]), None)
    other = next((d for d in devs if d is not basic), None)
    if basic is None:
        die("no PoCL 'basic' device listed")
    return {"basic": basic, "pthread": other}


def render(exe, env, args, mode, devices, tmp, n):
    out = tmp / f"run{n}"
    out.mkdir()
    stats = out / "stats.jsonl"
    cmd = [str(exe), "render", str(args.scene), "--frames", f"0-{args.frames}", "--width",
           str(args.width), "--height", str(args.height), "--spp", str(args.spp), "--mode", mode,
           "--out", str(out / "f_%04d.exr"), "--stats", str(stats), "--quiet"]
    for d in devices:
        cmd += ["--device", str(d)]
    t0 = time.perf_counter()
    proc = subprocess.run(cmd, capture_output=True, text=True, env=env)
    wall = time.perf_counter() - t0
    if proc.returncode != 0:
        die(f"render failed ({proc.returncode}): {' '.join(cmd)}\n{proc.stderr.strip()}")
    recs = [json.loads(line) for line in stats.read_text().splitlines() if line.strip()]
    shutil.rmtree(out)
    return recs, wall


def light_s(stages):
    return sum(stages.get(k, 0.0) for k in LIGHT_STAGES)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--exe", default=str(REPO / "build" / "pathreuse"))
    ap.add_argument("--scene", default=str(DEMO))
    ap.add_argument("--frames", type=int, default=8, help="frames 0..N (frame 0 is a warm-up)")
    ap.add_argument("--width", type=int, default=320)
    ap.add_argument("--height", type=int, default=240)
    ap.add_argument("--spp", type=int, default=4)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--modes", default="reuse,pathtrace")
    ap.add_argument("--quick", action="store_true", help="160x120, 4 frames, 1 repeat")
    args = ap.parse_args()
    if args.quick:
        args.width, args.height, args.frames, args.repeats = 160, 120, 4, 1
    exe = Path(args.exe)
    if not exe.is_file():
        die(f"{exe}: not built (cmake --build build)")
    os.environ["POCL_DEVICES"] = "pthread basic"  # machine_lines lists the devices too
    os.environ.pop("PATHREUSE_DEVICE", None)
    env = dict(os.environ)
    devs = pocl_devices(exe, env)
    configs = {"basic": [devs["basic"]["index"]], "pthread": [devs["pthread"]["index"]],
               "both": [devs["basic"]["index"], devs["pthread"]["index"]]}
    tmp = Path(tempfile.mkdtemp(prefix="bench-multidevice-"))
    n = 0
    results = {}
    try:
        for mode in args.modes.split(","):
            runs = {c: [] for c in configs}
            for rep in range(args.repeats):
                for c, d in configs.items():
                    n += 1
                    recs, wall = render(exe, env, args, mode, d, tmp, n)
                    runs[c].append((recs, wall))
                    body = [r for r in recs if r["frame"] > 0]
                    print(f"  {mode:9s} {c:8s} repeat {rep}: median frame "
                          f"{median([r['wall_s'] for r in body]):.3f} s, process {wall:.1f} s",
                          file=sys.stderr, flush=True)
            results[mode] = runs
    finally:
        shutil.rmtree(tmp, ignore_errors=True)

    L = ["# Several devices: PoCL's two drivers against each alone", ""]
    L += machine_lines(exe) + [
        f"- scene `{Path(args.scene).name}`, {args.width}x{args.height}, {args.spp} spp, frames "
        f"0-{args.frames} (frame 0 left out), {args.repeats} runs per configuration, interleaved;"
        " wall = the renderer's per-frame wall time; 'vs' = median over repeats of the ratio of "
        "per-run medians (runs of one repeat ran back to back)",
        f"- command: `python3 -m tools.bench.bench_multidevice"
        f"{' --quick' if args.quick else ''}`", ""]
    for mode, runs in results.items():
        body = {c: [r for recs, _ in rs for r in recs if r["frame"] > 0] for c, rs in runs.items()}
        wall = {c: median([r["wall_s"] for r in b]) for c, b in body.items()}
        run_meds = {c: [median([r["wall_s"] for r in recs if r["frame"] > 0]) for recs, _ in rs]
                    for c, rs in runs.items()}
        proc = {c: median([w for _, w in rs]) for c, rs in runs.items()}
        best = min(("basic", "pthread"), key=lambda c: wall[c])
        L += [f"## {mode}", "",
              "| devices | wall s/frame (median) | per-run medians | process s | vs " + best + " alone |",
              "|---|---|---|---|---|"]
        for c in configs:
            paired = median([x / y for x, y in zip(run_meds[c], run_meds[best])])
            L.append(f"| {c} | {wall[c]:.4f} | {' '.join(f'{x:.4f}' for x in run_meds[c])} | "
                     f"{proc[c]:.2f} | {paired:.2f}x |")
        both = body["both"]
        L += ["", "Two devices, per device (median over frames >= 1):", "",
              "| device | rows (share) | wall s of its part | kernel s | light paths s "
              "(invalidate + light_trace) | light % of its kernel s |", "|---|---|---|---|---|---|"]
        for i in range(2):
            parts = [r["devices"][i] for r in both]
            ker = [sum(p["stages_s"].values()) for p in parts]
            lig = [light_s(p["stages_s"]) for p in parts]
            rows = median([p["rows"] for p in parts])
            L.append(f"| {parts[0]['name']} | {rows:.0f} ({rows / args.height:.0%}) | "
                     f"{median([p['wall_s'] for p in parts]):.4f} | {median(ker):.4f} | "
                     f"{median(lig):.4f} | "
                     f"{100 * median([l / k for l, k in zip(lig, ker) if k > 0]):.1f} |")
        L += ["", "Rows per device frame by frame (last run): " +
              ", ".join("/".join(str(d["rows"]) for d in r["devices"])
                        for r in runs["both"][-1][0]), ""]
        if mode != "pathtrace":
            single = {c: median([light_s(r["stages_s"]) for r in body[c]]) for c in ("basic", "pthread")}
            total_two = median([light_s(r["stages_s"]) for r in both])
            L += [f"Replicated light paths: invalidate + light_trace summed over both devices "
                  f"{total_two:.4f} s/frame, against {single['basic']:.4f} s (basic alone) and "
                  f"{single['pthread']:.4f} s (pthread alone).", ""]
    L += [f"Load average (1 min) at the end: {os.getloadavg()[0]:.2f} on {os.cpu_count()} CPUs.", ""]
    print("\n".join(L))


if __name__ == "__main__":
    main()
