"""Metrics of the evaluation: relMSE (plain and without the worst 1% of pixels, as exr_compare
measures them), flicker, the runs of one setting and their quality row, the equal-time spp
search, the equal-error times and the summary of timing runs. Images are float32 arrays
(H, W, 3)."""

import math
from dataclasses import dataclass, field

import numpy as np

from ..benchlib import frame_breakdown, kernel_s, median

from .results import (EqualError, EqualTime, EqualTimeRound, ErrorPoint, QualityRow, Stats,
                      TimeToTarget, TimingSummary, TrimmedEqualError)

EPS = 0.01               # the +0.01 in F, as in relMSE
LOWEST = "at or below the lowest spp"


def flicker(prev, cur, rprev, rcur):
    """Noise that changes between frames: the frame difference minus the reference's."""
    d = (cur - prev) - (rcur - rprev)
    m = 0.5 * (rcur + rprev)
    return float(np.mean(d ** 2 / (m ** 2 + EPS)))


def quality(diffs, imgs, refs):
    """Per-frame relMSE, per-frame trimmed relMSE, per-pair flicker. diffs: exr_compare's
    measures of each frame against its reference (run.Runner.diff): relMSE is computed in one
    place, host/portability/compare.cpp, for the renderer, its tests and these tools."""
    e = [d["relmse"] for d in diffs]
    et = [d["relmse_trimmed"] for d in diffs]
    fl = [flicker(imgs[t - 1], imgs[t], refs[t - 1], refs[t]) for t in range(1, len(imgs))]
    return e, et, fl


def body_time(recs):
    """Median wall seconds per frame, leaving out a run's first frame (reuse traces every
    slot there)."""
    return median([r["wall_s"] for r in recs[1:]] or [recs[0]["wall_s"]])


@dataclass
class SettingRuns:
    """Runs of one (mode, spp, fixed noise) on the quality frames, one per seed."""
    mode: str
    spp: int
    fixed: bool
    times: list = field(default_factory=list)  # per run: s/frame
    err: list = field(default_factory=list)    # per run: per-frame relMSE
    errt: list = field(default_factory=list)   # per run: per-frame trimmed relMSE
    flk: list = field(default_factory=list)    # per run: per-pair flicker
    imgs: dict = field(default_factory=dict)   # seed -> images (first seed only)

    def add(self, seed, recs, diffs, imgs, refs, keep_imgs):
        self.times.append(body_time(recs))
        e, et, f = quality(diffs, imgs, refs)
        self.err.append(e)
        self.errt.append(et)
        self.flk.append(f)
        if keep_imgs:
            self.imgs[seed] = imgs

    def summary(self):
        e = [float(np.mean(x)) for x in self.err]
        f = [float(np.mean(x)) for x in self.flk]
        et = [float(np.mean(x)) for x in self.errt]
        return QualityRow(
            mode=self.mode, spp=self.spp, fixed_noise=self.fixed,
            time_s_per_frame=Stats.of(self.times),
            relmse=float(np.mean(e)), relmse_runs=e,
            relmse_trim=float(np.mean(et)), relmse_trim_runs=et,
            relmse_median_frame=float(np.median(self.err)),
            flicker=float(np.mean(f)), flicker_runs=f,
            relmse_per_frame=[float(v) for v in np.mean(self.err, axis=0)],
            flicker_per_pair=[float(v) for v in np.mean(self.flk, axis=0)])


def setting(settings, mode, spp, fixed=False):
    """The runs of (mode, spp, fixed) in settings, added empty when absent."""
    return settings.setdefault((mode, spp, fixed), SettingRuns(mode, spp, fixed))


# ---------------------------------------------------------------- equal time

def equal_time_first_spp(pt, t_reuse, default):
    """pt: (spp, s/frame) of pathtrace. The spp whose time matches t_reuse on a least-squares
    line through them; default when time does not grow with spp."""
    n = len(pt)
    ms, mt = sum(s for s, _ in pt) / n, sum(t for _, t in pt) / n
    slope = sum((s - ms) * (t - mt) for s, t in pt) / max(1e-12, sum((s - ms) ** 2 for s, _ in pt))
    icpt = mt - slope * ms
    return max(1, round((t_reuse - icpt) / slope)) if slope > 0 else default


def equal_time_round(k, reuse_times, pathtrace_times):
    """One round of interleaved runs: reuse against pathtrace at spp k, s/frame per seed."""
    return EqualTimeRound(pathtrace_spp=k, reuse_s=Stats.of(reuse_times),
                          pathtrace_s=Stats.of(pathtrace_times),
                          ratio=median(pathtrace_times) / median(reuse_times),
                          ratios_per_seed=[p / r for p, r in zip(pathtrace_times, reuse_times)])


def equal_time_next_spp(k, ratio, tried):
    """The pathtrace spp of the next round, or None when k is within 5% or no new spp is left."""
    if abs(ratio - 1) <= 0.05:
        return None
    nk = max(1, round(k / ratio))
    if nk == k:
        nk = k + (1 if ratio < 1 else -1)
    return None if nk in tried or nk < 1 else nk


def equal_time(settings, rounds, spp):
    """The round whose time ratio is nearest 1 and the quality rows at its spp."""
    best = min(rounds, key=lambda r: abs(r.ratio - 1))
    k = best.pathtrace_spp
    return EqualTime(reuse_spp=spp, pathtrace_spp=k, rounds=rounds,
                     time_ratio_pathtrace_over_reuse=best.ratio,
                     within_5_percent=abs(best.ratio - 1) <= 0.05,
                     reuse=setting(settings, "reuse", spp).summary(),
                     pathtrace_fresh=setting(settings, "pathtrace", k).summary(),
                     pathtrace_fixed=setting(settings, "pathtrace", k, True).summary())


# ---------------------------------------------------------------- equal error

def interp_time(points, target):
    """points: (time, relMSE) by increasing spp. The time at which relMSE reaches target,
    interpolated in log-log between the two bracketing points; None when not reached."""
    if points[0][1] <= target:
        return points[0][0], LOWEST
    for (t0, e0), (t1, e1) in zip(points, points[1:]):
        if e0 >= target >= e1 and e0 > e1:
            s = (math.log(target) - math.log(e0)) / (math.log(e1) - math.log(e0))
            return math.exp(math.log(t0) + s * (math.log(t1) - math.log(t0))), "interpolated"
    return None, "not reached"


def time_points(settings, mode, sweep, measure):
    """(median s/frame, measure of the quality row) over the sweep's spp."""
    out = []
    for s in sweep:
        runs = setting(settings, mode, s)
        out.append((median(runs.times), getattr(runs.summary(), measure)))
    return out


def time_to_target(settings, mode, sweep, target):
    pts = time_points(settings, mode, sweep, "relmse")
    t, how = interp_time(pts, target)
    # Slope of log relMSE over log spp between the last two sweep points: -1 for pure
    # variance, near 0 at a bias floor or where correlated light paths stop helping.
    tail = (math.log(pts[-1][1] / pts[-2][1]) / math.log(sweep[-1] / sweep[-2])
            if len(pts) > 1 else float("nan"))
    return TimeToTarget(time_s=t, how=how, tail_slope=tail,
                        points=[ErrorPoint(spp=s, time_s=p[0], relmse=p[1]) for s, p in zip(sweep, pts)])


def speedup(t_reuse, t_pathtrace):
    return t_pathtrace / t_reuse if t_reuse and t_pathtrace else None


def equal_error(settings, sweep, spp):
    """The time reuse and pathtrace need to reach pathtrace's relMSE at spp. Where reuse's lowest
    spp already beats that, pathtrace's relMSE at the next larger spp of the sweep that reuse's
    sweep brackets is the target instead (so that both times are measured, not bounded); only
    where none is bracketed is the speed-up a lower bound."""
    def bracketed(s):
        relmse = setting(settings, "pathtrace", s).summary().relmse
        return time_to_target(settings, "reuse", sweep, relmse).how != LOWEST

    spp = next((s for s in sweep if s >= spp and bracketed(s)), spp)
    target = setting(settings, "pathtrace", spp).summary()
    reuse = time_to_target(settings, "reuse", sweep, target.relmse)
    pathtrace = time_to_target(settings, "pathtrace", sweep, target.relmse)
    # The same on relMSE without the worst 1% of pixels (a diagnosis of how much rare, large
    # errors decide the plain one).
    tr, tp = (interp_time(time_points(settings, m, sweep, "relmse_trim"), target.relmse_trim)[0]
              for m in ("reuse", "pathtrace"))
    return EqualError(
        target_relmse=target.relmse, target_from=f"pathtrace spp {spp}",
        reuse=reuse, pathtrace=pathtrace, speedup=speedup(reuse.time_s, pathtrace.time_s),
        # Reuse already at or below the target at its lowest spp: its time there bounds the
        # time it needs from above, so the speed-up is a lower bound.
        speedup_lower_bound=reuse.how == LOWEST,
        trimmed=TrimmedEqualError(target_relmse_trim=target.relmse_trim, reuse=tr, pathtrace=tp,
                                  speedup=speedup(tr, tp)))


# ---------------------------------------------------------------- timing runs

def summarize_timing(runs):
    """runs: (stats records, process seconds) of one mode's timing runs."""
    per_run = []
    for recs, wall in runs:
        body = recs[1:]
        per_run.append({"wall": median([r["wall_s"] for r in body]),
                        "kernel": median([kernel_s(r) for r in body]),
                        "total": sum(r["wall_s"] for r in recs),
                        "frame0": recs[0]["wall_s"], "process": wall})
    frames = [r for recs, _ in runs for r in recs[1:]]
    _, share, stage_med, rays = frame_breakdown(frames)
    reused = [r["counters"]["slots_reused"] / r["counters"]["slots"] for r in frames
              if "counters" in r and r["counters"].get("slots")]
    return TimingSummary(
        wall_s_per_frame=Stats.of([p["wall"] for p in per_run]),
        kernel_s_per_frame=Stats.of([p["kernel"] for p in per_run]),
        total_s=Stats.of([p["total"] for p in per_run]),
        frame0_s=median([p["frame0"] for p in per_run]),
        process_s=Stats.of([p["process"] for p in per_run]),
        per_run_wall=[p["wall"] for p in per_run],
        stage_share_percent=share,
        stage_s_per_frame=stage_med,
        rays_per_frame=rays,
        slots_reused_fraction=median(reused) if reused else None,
        per_frame_wall=[[r["wall_s"] for r in recs] for recs, _ in runs])
