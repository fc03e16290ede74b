"""Connection strategies against the path tracer: relMSE and relMSE x kernel seconds of one
frame against a path-traced reference, for `reuse` with every connection traced
(`--connections all`) and with K resampled ones, with and without a connection history, on the
demo scenes and the atrium.

  python3 -m tools.bench.bench_connections                   # 160-wide frames, 16 spp, PoCL or the default device
  python3 -m tools.bench.bench_connections --width 640 --device gpu   # a GPU wants larger frames
  python3 -m tools.bench.bench_connections --frames 12     # frame 11 of 0-11: histories warmed up

Each scene's reference is pathtrace at --ref-spp (seed 999); each configuration renders frames 0 to
--frames - 1 and is measured on the last, with --seeds seeds, interleaved; the table gives
medians over the seeds: relMSE (eps 0.01, as exr_compare), kernel seconds (the sum of the
frame's stages), their product (lower is better: the error reached per unit of time), and
shadow rays per camera sample (connection and next-event). --baseline-kernels DIR adds the reuse rows rendered with another kernels/ folder
(PATHREUSE_KERNEL_DIR; e.g. `git archive` of an older commit), side by side in the same run.
Standard library only, so that a GPU machine's Python runs it too.
"""

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

from . import benchlib

# The connections alone (--no-eye-paths), as the paper makes them.
CONN = ["--mode", "reuse", "--no-eye-paths"]
CONFIGS = [("pathtrace", ["--mode", "pathtrace"]),
           ("reuse all", CONN + ["--connections", "all"]),
           ("reuse K=1", CONN + ["--connections", "1"]),
           ("reuse K=2", CONN + ["--connections", "2"])]
# The connection history (reservoirs carried over frames; measure it with --frames 8 or more),
# and the candidates it stands for drawn in one frame instead.
CONFIGS += [("reuse K=1 H20", CONN + ["--connections", "1", "--connection-history", "20"]),
            ("reuse K=1 H20 P4", CONN + ["--connections", "1", "--connection-history", "20",
                                         "--connection-history-period", "4"]),
            ("reuse all H20", CONN + ["--connections", "all", "--connection-history", "20"]),
            ("reuse K=1 C16", CONN + ["--connections", "1", "--paths-per-pixel", "16"])]
# Eye paths (the default): the path tracer's eye paths with the connections, MIS over whole paths.
EYE = ["--mode", "reuse", "--eye-paths"]
CONFIGS += [("eye all", EYE + ["--connections", "all"]),
            ("eye K=1", EYE + ["--connections", "1"]),
            ("eye K=2", EYE + ["--connections", "2"]),
            ("eye all C1", EYE + ["--connections", "all", "--paths-per-pixel", "1"]),
            ("eye all C2", EYE + ["--connections", "all", "--paths-per-pixel", "2"]),
            ("eye K=1 C1", EYE + ["--connections", "1", "--paths-per-pixel", "1"]),
            ("eye K=1 H20", EYE + ["--connections", "1", "--connection-history", "20"]),
            ("eye K=1 C8", EYE + ["--connections", "1", "--paths-per-pixel", "8"]),
            ("eye K=1 C16", EYE + ["--connections", "1", "--paths-per-pixel", "16"])]
ASPECT = {"cornell-dynamic": 0.75, "cornell-skinned": 0.75, "atrium": 0.5625}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", default=str(benchlib.REPO / "build"))
    ap.add_argument("--scenes", default="cornell-dynamic,cornell-skinned,atrium")
    ap.add_argument("--atrium", default=str(benchlib.ATRIUM), help="atrium glTF (generated if absent)")
    ap.add_argument("--width", type=int, default=160, help="height from the scene's aspect")
    ap.add_argument("--spp", type=int, default=16)
    ap.add_argument("--ref-spp", type=int, default=1024)
    ap.add_argument("--seeds", type=int, default=3)
    ap.add_argument("--frames", type=int, default=1,
                    help="render frames 0 to N-1 and measure the last (a connection history's warm-up)")
    ap.add_argument("--device", help="--device of every render (default: the renderer's)")
    ap.add_argument("--baseline-kernels", help="another kernels/ folder for the reuse rows")
    ap.add_argument("--configs", help="comma-separated labels of the rows to run (default: all)")
    a = ap.parse_args()
    configs = [(label, opts, None) for label, opts in CONFIGS]
    if a.baseline_kernels:
        configs += [(label + " (baseline)", opts, a.baseline_kernels) for label, opts in CONFIGS
                    if label != "pathtrace"]
    if a.configs:
        configs = [c for c in configs if c[0] in a.configs.split(",")]
    exe, compare = Path(a.build) / "pathreuse", Path(a.build) / "exr_compare"
    device = ["--device", a.device] if a.device else []
    work = Path(tempfile.mkdtemp(prefix="pathreuse-connections-"))

    last = a.frames - 1

    def render(scene, w, h, spp, seed, opts, tag, kernels=None, first=0):
        out = work / f"{tag}_%04d.exr"
        stats = work / f"{tag}.jsonl"
        subprocess.run([str(exe), "render", str(scene), "--frames", f"{first}-{last}", "--width", str(w), "--height",
                        str(h), "--spp", str(spp), "--seed", str(seed), "--quiet", "--exr-float", "--out",
                        str(out), "--stats", str(stats)] + device + opts, check=True,
                       env=dict(os.environ, PATHREUSE_KERNEL_DIR=kernels) if kernels else None)
        rec = json.loads(stats.read_text().splitlines()[-1])
        return work / f"{tag}_{last:04d}.exr", rec

    print("# Connection strategies against the path tracer\n")
    print("\n".join(benchlib.machine_lines(exe)))
    print(f"- command: `{' '.join(sys.argv)}`\n", flush=True)
    for name in a.scenes.split(","):
        scene = benchlib.ensure_atrium(a.atrium) if name == "atrium" else benchlib.REPO / "scenes" / f"{name}.gltf"
        w = a.width
        h = max(1, round(w * ASPECT.get(name, 0.75)))
        ref, _ = render(scene, w, h, a.ref_spp, 999, ["--mode", "pathtrace"], f"{name}_ref",
                        first=last)
        rows = {}
        for seed in range(1, a.seeds + 1):
            for label, opts, kernels in configs:
                img, rec = render(scene, w, h, a.spp, seed, opts, f"{name}_{seed}", kernels)
                out = subprocess.run([str(compare), str(ref), str(img)], capture_output=True, text=True,
                                     check=True).stdout
                rel = json.loads(out.strip().splitlines()[-1])["relmse"]
                rays, cam = rec["rays"], max(1, rec["rays"]["camera"])
                rows.setdefault(label, []).append(
                    (rel, benchlib.kernel_s(rec), rays.get("connection", 0) / cam, rays.get("shadow", 0) / cam))
        print(f"## {name}, {w}x{h}, {a.spp} spp, frame {last} (of 0-{last}), medians of {a.seeds} seeds; "
              f"reference: pathtrace {a.ref_spp} spp\n")
        print("| config | relMSE | kernel s | relMSE x s | connection rays / sample | NEE rays / sample |")
        print("|---|---:|---:|---:|---:|---:|")
        for label, v in rows.items():
            med = [statistics.median(x[i] for x in v) for i in range(4)]
            print(f"| {label} | {med[0]:.4f} | {med[1]:.4f} | {med[0] * med[1]:.3g} | {med[2]:.2f} | {med[3]:.2f} |")
        print(flush=True)


if __name__ == "__main__":
    main()
