"""Helpers shared by the benchmark scripts (bench_reuse.py, bench_sampling.py, evaluate.py and
its evaluation/ package): statistics of the renderer's per-frame stats, the machine description
for a report, and the large atrium (its sky-lit default and its night, many-lights variant).
Standard library only, so that any Python 3 can import it."""

import os
import platform
import shutil
import statistics
import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
ATRIUM = Path("/tmp/pathreuse-atrium/atrium.gltf")
# the night variant lit by ~460 small emissive lanterns (tools/scenes/gen_atrium.py --light lanterns)
ATRIUM_LANTERNS = Path("/tmp/pathreuse-atrium-lanterns/atrium.gltf")


def median(xs):
    return statistics.median(xs) if xs else float("nan")


def kernel_s(rec):
    """Kernel seconds of one frame: the sum of its stages."""
    return sum(rec["stages_s"].values())


def frame_breakdown(frames):
    """Over a list of per-frame stats records: kernel seconds summed per stage, each stage's
    percent of all kernel time, each stage's median seconds per frame, and each ray kind's
    median count per frame (stages and kinds sorted by name)."""
    totals = {}
    for r in frames:
        for k, v in r["stages_s"].items():
            totals[k] = totals.get(k, 0.0) + v
    totals = dict(sorted(totals.items()))
    ktot = sum(totals.values())
    share = {k: 100.0 * v / ktot for k, v in totals.items()} if ktot else {}
    stage_med = {k: median([r["stages_s"].get(k, 0.0) for r in frames]) for k in totals}
    kinds = sorted({k for r in frames for k in r["rays"]})
    rays = {k: median([r["rays"].get(k, 0) for r in frames]) for k in kinds}
    return totals, share, stage_med, rays


def fmt_rng(xs, f="{:.3f}"):
    """'median [min-max]'."""
    return f"{f.format(median(xs))} [{f.format(min(xs))}-{f.format(max(xs))}]"


def ensure_atrium(path, python=None, light="sky"):
    """Generates the atrium (size 1, ~300k triangles) at `path` when it is absent; `light` is
    gen_atrium.py's --light (sky, sun or lanterns). Give each variant its own path (ATRIUM,
    ATRIUM_LANTERNS): a file already there is used as it is."""
    path = Path(path)
    if not path.is_file():
        print(f"generating {path} ...", flush=True)
        path.parent.mkdir(parents=True, exist_ok=True)
        run_tool("tools.scenes.gen_atrium", ["--size", "1", "--out", str(path)]
                 + (["--light", light] if light != "sky" else []), python=python, check=True)
    return path


def run_tool(module, args, python=None, **kwargs):
    """Runs one of the tools package's modules (e.g. tools.scenes.gen_atrium) as `python -m`,
    with the repository root on PYTHONPATH so that it imports from any working directory;
    kwargs go to subprocess.run."""
    env = dict(kwargs.pop("env", None) or os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(REPO)] + [p for p in [env.get("PYTHONPATH")] if p])
    return subprocess.run([python or sys.executable, "-m", module, *map(str, args)], env=env,
                          **kwargs)


def cpu_model():
    """The CPU's model name from /proc/cpuinfo ('unknown' where there is none)."""
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return "unknown"


def machine_lines(exe):
    """Markdown list items: machine, OpenCL devices, PoCL package, commit."""
    cpu = cpu_model()
    dev = subprocess.run([str(exe), "devices"], capture_output=True, text=True).stdout.strip()
    commit = subprocess.run(["git", "-C", str(REPO), "rev-parse", "--short", "HEAD"],
                            capture_output=True, text=True).stdout.strip() or "unknown"
    dirty = subprocess.run(["git", "-C", str(REPO), "status", "--porcelain", "--untracked-files=no"],
                           capture_output=True, text=True).stdout.strip()
    pocl = subprocess.run(["dpkg-query", "-W", "-f", "${Version}", "pocl-opencl-icd"],
                          capture_output=True, text=True).stdout.strip() if shutil.which("dpkg-query") else ""
    return [f"- machine: {os.cpu_count()} logical CPUs (nproc), {cpu}, {platform.system()} "
            f"{platform.release()}",
            "- device: " + "; ".join(f"`{d}`" for d in dev.splitlines()),
            f"- PoCL package: {pocl or 'n/a'}; POCL_MAX_PTHREAD_COUNT="
            f"{os.environ.get('POCL_MAX_PTHREAD_COUNT', 'unset')}",
            f"- commit: {commit}{' (tracked files modified)' if dirty else ''}"]
