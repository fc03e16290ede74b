"""Renders random combinations of `pathreuse render`'s options on small frames and checks each:
an exit of 0, or 2 with a one-line error; every pixel finite and not negative; the same command
twice gives the same bytes; --mode reuse gives retrace's bytes; with --device2, the frames of
that device differ from the first's in a few single samples at most (round-off may move a
discrete choice; a fault moves many pixels).

  python3 tools/fuzz/option_sweep.py --build build --count 200 --seed 1
  OCL_ICD_VENDORS=$(bash tools/setup/intel-opencl.sh) \\
    python3 tools/fuzz/option_sweep.py --build build --device2 "intel(r) opencl"

Scenes: the project's demo scenes, and the third-party ones of ../shared/scenes where present.
One line per combination (ok, reject, or FAIL with what failed); exit 1 if any failed.
"""

import argparse
import array
import os
import random
import shlex
import struct
import subprocess
import sys
import tempfile
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
SHARED = ["CesiumMan/CesiumMan.gltf", "Fox/Fox.gltf", "BoxAnimated/BoxAnimated.gltf",
          "ToyCar/ToyCar.gltf", "StainedGlassLamp/StainedGlassLamp.gltf",
          "BrainStem/BrainStem.gltf", "DamagedHelmet/DamagedHelmet.gltf",
          "FlightHelmet/FlightHelmet.gltf"]

# (chance, choices): each option is added with its chance, with one of its values.
OPTIONS = [
    (0.4, [["--shutter", v] for v in ("0.25", "0.5", "1", "2")]),
    (0.3, [["--fps", v] for v in ("2", "8", "30")]),
    (0.3, [["--resample"], ["--no-resample"]]),
    (0.2, [["--resample-neighbors", v] for v in ("0", "1", "3")]),
    (0.15, [["--resample-history", v] for v in ("0", "1", "5")]),
    (0.2, [["--max-depth", v] for v in ("1", "2", "3", "12")]),
    (0.2, [["--paths-per-pixel", v] for v in ("1", "2", "7")]),
    (0.15, [["--connections", v] for v in ("1", "2", "all")]),
    (0.15, [["--no-eye-paths"], ["--no-light-tracing"]]),
    (0.1, [["--connection-history", "3"]]),
    (0.15, [["--light-sampler", v] for v in ("bvh", "exhaustive", "power")]),
    (0.15, [["--noise-threshold", "0.1"]]),
    (0.15, [["--aov", v] for v in ("albedo,normal", "depth,motion,object", "material")]),
    (0.1, [["--material-model", "gltf-reference"]]),
    (0.1, [["--shadow-terminator", "off"]]),
    (0.1, [["--force-diffuse"]]),
    (0.2, [["--env-color", "0.3,0.5,1"]]),
    (0.1, [["--env", "none"]]),
    (0.1, [["--bvh-width", v] for v in ("2", "4")]),
    (0.1, [["--light-paths", v] for v in ("1", "5", "100")]),
    (0.1, [["--motion-tolerance", v] for v in ("0.05", "8")]),
    (0.1, [["--fixed-noise"]]),
    (0.1, [["--warm-up", "2"]]),
]


def combination(rng, scenes):
    first = rng.randrange(20)
    args = [rng.choice(scenes), "--allow-outside-uris", "--width", str(rng.choice([7, 16, 33])),
            "--height", str(rng.choice([5, 12, 24])), "--spp", str(rng.choice([1, 2, 3, 6])),
            "--seed", str(rng.randrange(5)), "--mode", rng.choice(["reuse", "retrace", "pathtrace"]),
            "--frames", f"{first}-{first + rng.choice([0, 1, 2])}"]
    for chance, choices in OPTIONS:
        if rng.random() < chance:
            args += rng.choice(choices)
    return args


def pixels(build, exr, tmp):
    raw = os.path.join(tmp, "img.raw")
    subprocess.run([str(build / "exr_compare"), "--raw", exr, raw], check=True,
                   capture_output=True)
    data = Path(raw).read_bytes()
    values = array.array("f")
    values.frombytes(data[8:])
    return struct.unpack("<II", data[:8]), values


def render(build, args, out, env=None):
    for f in os.listdir(out):
        os.remove(os.path.join(out, f))
    cmd = [str(build / "pathreuse"), "render", *args, "--exr-float", "--quiet", "--out",
           os.path.join(out, "f_%04d.exr")]
    return subprocess.run(cmd, capture_output=True, text=True, timeout=900, env=env)


def frames(out):
    return sorted(f for f in os.listdir(out) if f.endswith(".exr"))


def same_bytes(a, b, names):
    return [n for n in names if not os.path.exists(os.path.join(b, n)) or
            Path(a, n).read_bytes() != Path(b, n).read_bytes()]


def check(args, build, device2, tmp):
    """What failed for one combination: [] where nothing did; None where it was refused."""
    a, b = os.path.join(tmp, "a"), os.path.join(tmp, "b")
    p = render(build, args, a)
    if p.returncode == 2:
        return None if len(p.stderr.strip().splitlines()) == 1 else ["error not one line: " +
                                                                     p.stderr.strip()]
    if p.returncode != 0:
        return [f"exit {p.returncode}: {p.stderr.strip()[-300:]}"]
    names, bad = frames(a), []
    for n in names:
        _, v = pixels(build, os.path.join(a, n), tmp)
        if any(not (0.0 <= x < float("inf")) for x in v):
            bad.append(f"{n}: NaN, infinite or negative pixels")
    render(build, args, b)
    bad += [f"{n}: not the same twice" for n in same_bytes(a, b, names)]
    if "reuse" in args:
        retrace = list(args)
        retrace[retrace.index("--mode") + 1] = "retrace"
        render(build, retrace, b)
        bad += [f"{n}: reuse differs from retrace" for n in same_bytes(a, b, names)]
    if device2:
        if render(build, args + ["--device", device2], b).returncode != 0:
            return bad + [f"fails on {device2}"]
        for n in names:
            (w, h), x = pixels(build, os.path.join(a, n), tmp)
            _, y = pixels(build, os.path.join(b, n), tmp)
            differ = sum(1 for i in range(w * h)
                         if any(abs(x[3 * i + c] - y[3 * i + c]) > 1e-3 * (1 + abs(x[3 * i + c]))
                                for c in range(3)))
            if differ > max(2, w * h // 50):
                bad.append(f"{n}: {differ} of {w * h} pixels differ on {device2}")
    return bad


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--build", default="build")
    ap.add_argument("--count", type=int, default=100, help="combinations to render")
    ap.add_argument("--seed", type=int, default=1, help="which combinations")
    ap.add_argument("--device2", help="a second device to compare with the default one")
    args = ap.parse_args()
    build = (REPO / args.build).resolve()
    scenes = [str(p) for p in sorted((REPO / "scenes").glob("*.gltf"))]
    shared = REPO.parent / "shared" / "scenes"
    scenes += [str(shared / s) for s in SHARED if (shared / s).is_file()]
    failed = 0
    with tempfile.TemporaryDirectory() as tmp:
        os.makedirs(os.path.join(tmp, "a"))
        os.makedirs(os.path.join(tmp, "b"))
        for k in range(args.count):
            combo = combination(random.Random(args.seed * 1000003 + k), scenes)
            line = " ".join(shlex.quote(x) for x in combo)
            try:
                bad = check(combo, build, args.device2, tmp)
            except subprocess.TimeoutExpired:
                bad = ["timed out (900 s)"]
            if bad:
                failed += 1
                print(f"FAIL {line}\n  " + "\n  ".join(bad), flush=True)
            else:
                print(("reject " if bad is None else "ok ") + line, flush=True)
    print(f"option_sweep: {failed} of {args.count} combinations failed")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
