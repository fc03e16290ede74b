"""Crops of one frame of an animation at equal spp, for the eye: the path tracer, reuse without
and with path resampling, and resampling with spatial neighbours, beside a reference; under each
crop its relMSE over the whole frame and the correlation of its error between pixels k apart
(spatial reuse shares paths between pixels, so their errors move together: blotches rather than
grain). Writes a PNG and prints a Markdown table.

  /usr/bin/python3 -m tools.bench.reuse_crops [--scene atrium] [--frame 12] [--spp 4]
      [--crop X,Y,W,H] [--out docs/reuse_crops_atrium.png]
"""

import argparse
import json
import subprocess
import tempfile
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from .benchlib import ATRIUM, REPO, ensure_atrium  # noqa: E402
from .evaluation.plots import tonemap  # noqa: E402
from .evaluation.run import load_raw  # noqa: E402

SETTINGS = [
    ("path tracer", "--mode pathtrace"),
    ("reuse --no-resample", "--mode reuse --no-resample"),
    ("reuse (default: resampled, 0 neighbours)", "--mode reuse"),
    ("reuse, 3 neighbours", "--mode reuse --resample-neighbors 3"),
    ("reuse, 8 neighbours within 3 px", "--mode reuse --resample-neighbors 8 --resample-radius 3"),
    ("path tracer resampled, 8 neighbours within 3 px",
     "--mode pathtrace --resample --resample-neighbors 8 --resample-radius 3"),
]


def parse_args():
    ap = argparse.ArgumentParser(prog="reuse_crops")
    ap.add_argument("--scene", default="atrium", help="atrium or a glTF path")
    ap.add_argument("--frame", type=int, default=12, help="rendered after frames 0 .. frame - 1")
    ap.add_argument("--spp", type=int, default=4)
    ap.add_argument("--ref-spp", type=int, default=512)
    ap.add_argument("--width", type=int, default=160)
    ap.add_argument("--seed", type=int, default=3)
    ap.add_argument("--crop", default="", help="X,Y,W,H in pixels (default: the middle half)")
    ap.add_argument("--exposure", type=float, default=0.0, help="EV for display")
    ap.add_argument("--lags", default="1,2,4,8", help="pixel distances of the error correlation")
    ap.add_argument("--out", default=str(REPO / "out" / "reuse_crops.png"))
    ap.add_argument("--build", default=str(REPO / "build"))
    return ap.parse_args()


def render(args, scene, extra, spp, seed, out, first=0):
    """Frames first .. frame at spp into out; the last frame's image."""
    exe = Path(args.build) / "pathreuse"
    cmd = [str(exe), "render", str(scene), "--frames", f"{first}-{args.frame}", "--width",
           str(args.width), "--spp", str(spp), "--seed", str(seed), "--quiet", "--out",
           str(out / "f_%04d.exr")] + extra.split()
    subprocess.run(cmd, check=True)
    raw = out / "last.raw"
    subprocess.run([str(Path(args.build) / "exr_compare"), "--raw",
                    str(out / f"f_{args.frame:04d}.exr"), str(raw)], check=True)
    return load_raw(raw)


def error_correlation(img, ref, lag):
    """Correlation of the luminance error between pixels `lag` apart, across and down, with
    the errors clipped to their 1st and 99th percentiles so that a few fireflies do not decide
    it."""
    e = (img - ref).mean(axis=2)
    e = np.clip(e, *np.percentile(e, [1, 99]))
    pairs = [(e[:, :-lag], e[:, lag:]), (e[:-lag, :], e[lag:, :])]
    a = np.concatenate([p[0].ravel() for p in pairs])
    b = np.concatenate([p[1].ravel() for p in pairs])
    a, b = a - a.mean(), b - b.mean()
    return float((a * b).sum() / np.sqrt((a * a).sum() * (b * b).sum()))


def main():
    args = parse_args()
    scene = ensure_atrium(ATRIUM) if args.scene == "atrium" else Path(args.scene)
    lags = [int(x) for x in args.lags.split(",")]
    with tempfile.TemporaryDirectory(prefix="reuse-crops-") as tmp:
        tmp = Path(tmp)
        (tmp / "ref").mkdir()
        # The reference: the path tracer's frame alone (it keeps nothing between frames).
        ref = render(args, scene, "--mode pathtrace", args.ref_spp, 1000, tmp / "ref",
                     first=args.frame)
        rows = []
        for i, (name, extra) in enumerate(SETTINGS):
            (tmp / str(i)).mkdir()
            img = render(args, scene, extra, args.spp, args.seed, tmp / str(i))
            relmse = float((((img - ref) ** 2) / (ref ** 2 + 0.01)).mean())
            rows.append((name, extra, img, relmse, [error_correlation(img, ref, k) for k in lags]))
    h, w, _ = ref.shape
    if args.crop:
        x, y, cw, ch = (int(v) for v in args.crop.split(","))
    else:
        x, y, cw, ch = w // 4, h // 4, w // 2, h // 2
    tiles = [(f"{n}\nrelMSE {e:.4f}, corr. 1 px {c[0]:.2f}", img) for n, _, img, e, c in rows]
    tiles.append((f"reference ({args.ref_spp} spp)", ref))
    ncol = 4
    nrow = (len(tiles) + ncol - 1) // ncol
    fig, axes = plt.subplots(nrow, ncol, squeeze=False,
                             figsize=(ncol * cw / 24 + 0.4, nrow * (ch / 24 + 0.6) + 0.3))
    for ax in axes.ravel()[len(tiles):]:
        ax.axis("off")
    for ax, (title, img) in zip(axes.ravel(), tiles):
        ax.imshow(tonemap(img[y:y + ch, x:x + cw], args.exposure), interpolation="nearest")
        ax.set_title(title, fontsize=9)
        ax.set_xticks([])
        ax.set_yticks([])
    fig.suptitle(f"{Path(scene).stem}, frame {args.frame} after frames 0-{args.frame - 1}, "
                 f"{args.spp} spp, seed {args.seed}; crop {cw}x{ch} at ({x}, {y})", fontsize=10)
    fig.tight_layout(pad=0.3)
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(args.out, dpi=80, pil_kwargs={"optimize": True})
    plt.close(fig)
    print(f"| setting | relMSE at {args.spp} spp | "
          + " | ".join(f"error correlation at {k} px" for k in lags) + " |")
    print("|---|---|" + "---|" * len(lags))
    for name, extra, _, e, c in rows:
        print(f"| {name} (`{extra}`) | {e:.4f} | " + " | ".join(f"{v:.2f}" for v in c) + " |")
    print(json.dumps({"out": args.out, "crop": [x, y, cw, ch]}))


if __name__ == "__main__":
    main()
