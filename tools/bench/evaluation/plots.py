"""Plots of the evaluation (matplotlib, Agg): time per frame, error against time, equal time,
per-frame error and flicker, a contact sheet per scene, and an MP4 per scene when ffmpeg is
installed."""

import shutil
import subprocess
from dataclasses import dataclass, field

import matplotlib
import numpy as np

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from .results import MODES  # noqa: E402

MODE_STYLE = {"reuse": ("tab:blue", "-"), "retrace": ("tab:orange", "--"),
              "pathtrace": ("tab:green", "-"), "pathtrace fixed": ("tab:red", ":")}


@dataclass
class PlotFiles:
    """File names of the PNGs, relative to the output folder."""
    time: str = "eval_time_per_frame.png"
    error: str = "eval_error_vs_time.png"
    equal: str = "eval_equal_time.png"
    perframe: str = "eval_per_frame.png"
    sheets: dict = field(default_factory=dict)   # scene key -> contact sheet

    @classmethod
    def for_scenes(cls, scenes):
        return cls(sheets={sc.key: f"eval_contact_{sc.key}.png" for sc in scenes})

    def all(self):
        return [self.time, self.error, self.equal, self.perframe, *self.sheets.values()]


def finish_figure(fig, title, path):
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def scene_axes(results, rows, height):
    """A figure with a column of `rows` axes per scene."""
    return plt.subplots(rows, len(results), figsize=(4.2 * len(results), height), squeeze=False)


def equal_time_rows(et):
    """(style name, quality row) of the equal-time comparison."""
    return [("reuse", et.reuse), ("pathtrace", et.pathtrace_fresh),
            ("pathtrace fixed", et.pathtrace_fixed)]


def plot_time_per_frame(results, path):
    fig, axes = scene_axes(results, 1, 3.2)
    for ax, r in zip(axes[0], results):
        sc = r.scene
        tfirst, tlast = sc.timing_frames
        x = np.arange(tfirst, tlast + 1)
        for m in MODES:
            w = np.array(r.timing[m].per_frame_wall)
            c, ls = MODE_STYLE[m]
            ax.plot(x, np.median(w, axis=0), color=c, ls=ls, lw=1.2, label=m)
            ax.fill_between(x, w.min(axis=0), w.max(axis=0), color=c, alpha=0.15, lw=0)
        ax.set_title(f"{sc.key} ({sc.camera} camera)", fontsize=9)
        ax.set_xlabel("frame")
        ax.set_ylabel("wall time per frame [s]")
        ax.set_ylim(bottom=0)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
    finish_figure(fig, "Time per frame (median of runs; band: min-max)", path)


def plot_equal_error(results, spp, path):
    fig, axes = scene_axes(results, 1, 3.4)
    for ax, r in zip(axes[0], results):
        for m in ("reuse", "pathtrace"):
            pts = getattr(r.equal_error, m).points
            c, ls = MODE_STYLE[m]
            ax.loglog([p.time_s for p in pts], [p.relmse for p in pts], marker="o", ms=3,
                      color=c, ls=ls, label=m)
            for p in pts:
                ax.annotate(str(p.spp), (p.time_s, p.relmse), fontsize=6,
                            xytext=(2, 2), textcoords="offset points")
        fx = r.setting("pathtrace", spp, True).summary()
        ax.loglog([fx.time_s_per_frame.median], [fx.relmse], marker="x",
                  color=MODE_STYLE["pathtrace fixed"][0], ls="", label=f"pathtrace fixed, spp {spp}")
        ax.axhline(r.equal_error.target_relmse, color="gray", lw=0.8, ls="--",
                   label=f"{r.equal_error.target_from} relMSE")
        ax.set_title(f"{r.scene.key}", fontsize=9)
        ax.set_xlabel("time per frame [s]")
        ax.set_ylabel("relMSE")
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=6)
    finish_figure(fig, "Error against time (labels: spp; mean over frames and seeds)", path)


def plot_equal_time(results, path):
    fig, axes = scene_axes(results, 2, 5.4)
    for j, r in enumerate(results):
        et = r.equal_time
        rows = equal_time_rows(et)
        names = [f"{n}\nspp {s.spp}" for n, s in rows]
        cols = [MODE_STYLE[n][0] for n, _ in rows]
        for i, key in enumerate(("relmse", "flicker")):
            ax = axes[i][j]
            vals = [getattr(s, key) for _, s in rows]
            runs = [getattr(s, key + "_runs") for _, s in rows]
            lo = [v - min(x) for v, x in zip(vals, runs)]
            hi = [max(x) - v for v, x in zip(vals, runs)]
            ax.bar(names, vals, color=cols, yerr=[lo, hi], capsize=3)
            ax.set_ylabel("relMSE" if key == "relmse" else "flicker F")
            ax.tick_params(axis="x", labelsize=7)
            ax.grid(alpha=0.3, axis="y")
            if i == 0:
                ax.set_title(f"{r.scene.key}: time pathtrace/reuse = "
                             f"{et.time_ratio_pathtrace_over_reuse:.2f}", fontsize=8)
    finish_figure(fig, "Equal time: error and flicker (mean over seeds; bars: min-max)", path)


def plot_per_frame_error(results, path):
    fig, axes = scene_axes(results, 2, 5.0)
    for j, r in enumerate(results):
        fr = r.scene.frames
        for name, s in equal_time_rows(r.equal_time):
            c, ls = MODE_STYLE[name]
            lab = f"{name} spp {s.spp}"
            axes[0][j].semilogy(fr, s.relmse_per_frame, color=c, ls=ls, label=lab)
            axes[1][j].semilogy(fr[1:], s.flicker_per_pair, color=c, ls=ls, label=lab)
        axes[0][j].set_title(r.scene.key, fontsize=9)
        axes[0][j].set_ylabel("relMSE")
        axes[1][j].set_ylabel("F (pair t-1, t)")
        axes[1][j].set_xlabel("frame t")
        for ax in axes[:, j]:
            ax.grid(alpha=0.3, which="both")
            ax.legend(fontsize=6)
    finish_figure(fig, "Equal time, per frame (mean over seeds)", path)


def tonemap(img, ev):
    x = np.clip(img * 2.0 ** ev, 0.0, 1.0)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1 / 2.4) - 0.055)


def sheet_rows(r, args):
    """(name, images of the first seed) at equal time, and the reference."""
    k = r.equal_time.pathtrace_spp
    s0 = args.seeds[0]
    return [(f"reuse spp {args.spp}", r.setting("reuse", args.spp).imgs[s0]),
            (f"pathtrace spp {k}", r.setting("pathtrace", k).imgs[s0]),
            (f"pathtrace fixed spp {k}", r.setting("pathtrace", k, True).imgs[s0]),
            (f"reference spp {r.scene.ref_spp}", r.refs)]


def contact_sheet(r, args, path):
    """Rows: modes at equal time and the reference; columns: two consecutive frames and the
    change between them (what flickers). Two frames keep the PNG under 500 KB: noise does
    not compress."""
    sc = r.scene
    rows = sheet_rows(r, args)
    nf = len(sc.frames)
    c0 = max(0, nf // 2 - 1)
    cols = [c for c in (c0, c0 + 1) if c < nf]
    h, w, _ = rows[0][1][0].shape
    fig, axes = plt.subplots(len(rows), len(cols) + 1, squeeze=False,
                             figsize=((len(cols) + 1) * w / 80 + 0.9, len(rows) * h / 80 + 0.5))
    for i, (name, imgs) in enumerate(rows):
        for j, c in enumerate(cols):
            axes[i][j].imshow(tonemap(imgs[c], args.exposure), interpolation="nearest")
            if i == 0:
                axes[i][j].set_title(f"frame {sc.frames[c]}", fontsize=7)
        if len(cols) > 1:
            d = np.abs(imgs[cols[1]] - imgs[cols[0]]).mean(axis=2)
            axes[i][-1].imshow(np.clip(d * 4 * 2.0 ** args.exposure, 0, 1), cmap="magma",
                               vmin=0, vmax=1, interpolation="nearest")
        if i == 0:
            axes[i][-1].set_title(f"|frame {sc.frames[cols[min(1, len(cols) - 1)]]} - "
                                  f"{sc.frames[cols[0]]}| x4", fontsize=7)
        axes[i][0].set_ylabel(name, fontsize=7)
        for ax in axes[i]:
            ax.set_xticks([])
            ax.set_yticks([])
    fig.suptitle(f"{sc.key}: equal time, seed {args.seeds[0]}, exposure {args.exposure:+g} EV",
                 fontsize=8)
    fig.tight_layout(pad=0.3)
    fig.savefig(path, dpi=80, pil_kwargs={"optimize": True})
    plt.close(fig)


def write_mp4(r, args, path, tmp):
    """Side-by-side video of the equal-time rows when ffmpeg is installed."""
    ff = shutil.which("ffmpeg")
    if not ff:
        return False
    rows = sheet_rows(r, args)
    d = tmp / f"mp4_{r.scene.key}"
    d.mkdir()
    for t in range(len(r.scene.frames)):
        strip = np.concatenate([tonemap(imgs[t], args.exposure) for _, imgs in rows], axis=1)
        plt.imsave(d / f"f_{t:04d}.png", strip)
    proc = subprocess.run([ff, "-y", "-loglevel", "error", "-framerate", "8", "-i", str(d / "f_%04d.png"),
                           "-vf", "scale=trunc(iw/2)*2:trunc(ih/2)*2:flags=neighbor",
                           "-pix_fmt", "yuv420p", str(path)], capture_output=True, text=True)
    return proc.returncode == 0


def write_all(results, args, out_dir, tmp):
    """Every PNG, and the MP4s ffmpeg can write; returns (PlotFiles, MP4 names)."""
    names = PlotFiles.for_scenes([r.scene for r in results])
    plot_time_per_frame(results, out_dir / names.time)
    plot_equal_error(results, args.spp, out_dir / names.error)
    plot_equal_time(results, out_dir / names.equal)
    plot_per_frame_error(results, out_dir / names.perframe)
    mp4s = []
    for r in results:
        contact_sheet(r, args, out_dir / names.sheets[r.scene.key])
        mp4 = out_dir / f"eval_{r.scene.key}.mp4"
        if write_mp4(r, args, mp4, tmp):
            mp4s.append(mp4.name)
    return names, mp4s
