"""The command line the benchmark peers' scripts share (cycles_frames.py, luxcore_frames.py,
scene_export.py), each run by its own Python: standard library only."""

import argparse
import sys


def peer_args(prog, source, render=True, extra=None):
    """Parses SOURCE OUTDIR --frames A-B --width W --height H [--camera NAME] [--world R,G,B]
    and, with `render`, --spp N
    --max-depth D --seed S --threads T; `extra(ap)` adds a script's own. Sets a.first, a.last."""
    ap = argparse.ArgumentParser(prog=prog)
    ap.add_argument(source)
    ap.add_argument("outdir")
    ap.add_argument("--frames", required=True, help="A-B")
    ap.add_argument("--width", type=int, required=True)
    ap.add_argument("--height", type=int, required=True)
    if render:
        ap.add_argument("--spp", type=int, required=True)
        ap.add_argument("--max-depth", type=int, required=True)
        ap.add_argument("--seed", type=int, default=1)
        ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--camera", help="the camera's name (default: the file's first)")
    ap.add_argument("--world", help="R,G,B: a uniform world of this radiance (default: black)")
    if extra:
        extra(ap)
    a = ap.parse_args(sys.argv[1:])
    first, _, last = a.frames.partition("-")
    try:
        a.first, a.last = int(first), int(last or first)
    except ValueError:
        ap.error(f"--frames {a.frames!r}: not A-B")
    return a
