"""Running the renderer for the evaluation: the scenes and their checks, one render process
(stats read, EXRs read through `exr_compare --raw` and measured against their references by
`exr_compare`), references cached on disk, and one scene's runs: the spp sweep, the equal-time
rounds and the timing runs, interleaved across modes."""

import hashlib
import json
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

from ..benchlib import REPO, ensure_atrium, median

from . import metrics
from .metrics import setting
from .results import MODES, REF_SEED, Scene, SceneResult


def die(msg, code=2):
    print(f"evaluate: {msg}", file=sys.stderr)
    sys.exit(code)


def load_raw(path):
    w, h = np.fromfile(path, dtype="<u4", count=2)
    return np.fromfile(path, dtype="<f4", offset=8).reshape(int(h), int(w), 3)


def load_scenes(args):
    """The scenes of --scenes, checked against their animations' frame counts."""
    scenes = []
    for key in args.scenes.split(","):
        if key in ("cornell-dynamic", "cornell-orbit", "cornell-skinned"):
            scenes.append(Scene(key=key, path=REPO / "scenes" / f"{key}.gltf",
                                camera="moving" if key == "cornell-orbit" else "still",
                                frames=list(range(args.frames)), ref_spp=args.ref_spp,
                                timing_frames=(0, args.timing_frames - 1), sweep=args.sweep_spp))
        elif key == "atrium":
            scenes.append(Scene(key=key, path=ensure_atrium(args.atrium, python=sys.executable),
                                camera="still", frames=list(range(args.atrium_frames)),
                                ref_spp=args.atrium_ref_spp, sweep=args.atrium_sweep_spp,
                                timing_frames=(0, args.atrium_timing_frames - 1)))
        else:
            die(f"--scenes: unknown scene {key}")
    for sc in scenes:
        info = json.loads(subprocess.run([str(args.exe), "info", str(sc.path), "--json"], check=True,
                                         capture_output=True, text=True).stdout)
        n = info["animation"]["frames"]
        if max(sc.frames[-1], sc.timing_frames[1]) > n - 1:
            die(f"{sc.path} has frames 0-{n - 1}; fewer frames, please")
        s, d = info["triangles"]["static"], info["triangles"]["dynamic"]
        sc.triangles = f"{s + d:,} triangles ({d:,} dynamic, {100 * d / max(1, s + d):.1f}%)"
    return scenes


def warm_up(exe, scenes, tmp):
    """Untimed: fills the kernel binary cache."""
    for sc in scenes:
        for m in ("reuse", "pathtrace"):
            subprocess.run([str(exe), "render", str(sc.path), "--frames", "0", "--width", "8",
                            "--spp", "1", "--mode", m, "--out", str(tmp / "warm_%04d.exr"), "--quiet"],
                           check=True, capture_output=True)


class Runner:
    def __init__(self, args, tmp):
        self.args, self.tmp = args, tmp
        self.exe, self.cmp = args.exe, args.cmp
        self.n = 0
        self.loads = []   # 1-min load average before each run

    def render(self, scene, mode, spp, seed, first, last, fixed=False, keep=True, extra=(),
               refs=None, save=None):
        """One process rendering frames first..last; returns (stats records, images or None,
        process seconds, diffs or None). keep: read the images. refs: the reference EXRs of
        frames first..last; diffs then holds each frame's exr_compare measures against its
        reference (self.diff). save: paths to copy the frames' EXRs to."""
        self.n += 1
        out = self.tmp / f"run{self.n}"
        out.mkdir()
        stats = out / "stats.jsonl"
        cmd = [str(self.exe), "render", str(scene), "--frames", f"{first}-{last}",
               "--width", str(self.args.width), "--spp", str(spp),
               "--max-depth", str(self.args.max_depth), "--seed", str(seed), "--mode", mode,
               "--out", str(out / "f_%04d.exr"), "--stats", str(stats), "--quiet", "--exr-float",
               *extra]  # float EXRs in every run, so that runs pay the same for writing
        cmd += getattr(self.args, "scene_args", "").split()  # every render, references too
        if mode != "pathtrace":
            cmd += self.args.reuse_args.split()
        if fixed:
            cmd.append("--fixed-noise")
        self.loads.append(os.getloadavg()[0])
        t0 = time.perf_counter()
        proc = subprocess.run(cmd, capture_output=True, text=True)
        wall = time.perf_counter() - t0
        if proc.returncode != 0:
            die(f"render failed ({proc.returncode}): {' '.join(cmd)}\n{proc.stderr.strip()}", 1)
        recs = [json.loads(x) for x in stats.read_text().splitlines() if x.strip()]
        if len(recs) != last - first + 1:
            die(f"expected {last - first + 1} stats lines from: {' '.join(cmd)}", 1)
        exrs = [out / f"f_{f:04d}.exr" for f in range(first, last + 1)]
        diffs = [self.diff(e, r) for e, r in zip(exrs, refs)] if refs is not None else None
        for e, dest in zip(exrs, save or []):
            tmp = Path(f"{dest}.tmp")
            shutil.copyfile(e, tmp)
            os.replace(tmp, dest)  # no half-written cache entry
        imgs = self.read(exrs) if keep else None
        shutil.rmtree(out)
        if not self.args.quiet:
            body = [r["wall_s"] for r in recs[1:]] or [recs[0]["wall_s"]]
            print(f"  {Path(scene).stem:16s} {mode:9s} spp {spp:3d} seed {seed}"
                  f"{' fixed' if fixed else '':6s} frames {first}-{last}: "
                  f"median {median(body):.3f} s/frame, process {wall:.1f} s", flush=True)
        return recs, imgs, wall, diffs

    def read(self, exrs):
        """The images of EXR files, through exr_compare --raw."""
        self.n += 1
        raws = [self.tmp / f"read{self.n}_{i}.raw" for i in range(len(exrs))]
        subprocess.run([str(self.cmp), "--raw", *[str(p) for pair in zip(exrs, raws) for p in pair]],
                       check=True)
        imgs = [load_raw(r) for r in raws]
        for r in raws:
            r.unlink()
        return imgs

    def diff(self, exr, ref):
        """exr_compare's measures of an EXR against its reference EXR (its JSON: relmse,
        relmse_trimmed, mad, ...), the one relMSE that the renderer and its tests use too."""
        proc = subprocess.run([str(self.cmp), str(exr), str(ref)], capture_output=True, text=True)
        if proc.returncode != 0:
            die(f"exr_compare {exr} {ref} failed ({proc.returncode}): {proc.stderr.strip()}", 1)
        d = json.loads(proc.stdout)
        if d["non_finite"]:
            die(f"{exr} against {ref}: {d['non_finite']} non-finite values", 1)
        return d


def file_sha(path):
    h = hashlib.sha1()
    h.update(Path(path).read_bytes())
    for side in Path(path).parent.glob(Path(path).stem + "*.bin"):
        h.update(side.read_bytes())
    return h.hexdigest()


def consecutive_groups(frames):
    """Sorted frame numbers as (first, last) runs of consecutive ones."""
    groups, start = [], frames[0]
    for prev, f in zip(frames, frames[1:] + [None]):
        if f != prev + 1:
            groups.append((start, prev))
            start = f
    return groups


def references(runner, sc, cache):
    """Reference frames of a scene: pathtrace at ref spp, seed REF_SEED, cached per frame as
    float EXRs (what exr_compare measures against). Returns (their paths, their images, key)."""
    a = runner.args
    scene_args = getattr(a, "scene_args", "")
    key = hashlib.sha1(json.dumps([file_sha(sc.path), a.width, sc.ref_spp, a.max_depth,
                                   REF_SEED, "pathtrace"] + ([scene_args] if scene_args else []))
                       .encode()).hexdigest()[:16]
    path = {f: cache / f"{sc.key}_{key}_f{f:04d}.exr" for f in sc.frames}
    missing = [f for f in sc.frames if not path[f].is_file()]
    if missing:
        print(f"  references for {sc.key}: {len(missing)} frame(s) at {sc.ref_spp} spp",
              flush=True)
        cache.mkdir(parents=True, exist_ok=True)
        # Consecutive runs of missing frames render in one process each.
        for first, last in consecutive_groups(missing):
            runner.render(sc.path, "pathtrace", sc.ref_spp, REF_SEED, first, last, keep=False,
                          save=[path[f] for f in range(first, last + 1)])
    paths = [path[f] for f in sc.frames]
    return paths, runner.read(paths), key


class SceneRuns:
    """The quality runs of one scene, gathered per setting."""

    def __init__(self, runner, sc, ref_exrs, refs, seeds):
        self.runner, self.sc, self.seeds = runner, sc, seeds
        self.ref_exrs, self.refs = ref_exrs, refs  # the references' EXR files and images
        self.settings = {}

    def setting(self, mode, spp, fixed=False):
        return setting(self.settings, mode, spp, fixed)

    def render(self, mode, spp, seed, fixed=False, keep=True):
        """keep: read the images and measure them against the references."""
        return self.runner.render(self.sc.path, mode, spp, seed, self.sc.frames[0], self.sc.frames[-1],
                                  fixed, keep, refs=self.ref_exrs if keep else None)

    def add(self, mode, spp, seed, recs, imgs, diffs, fixed=False):
        self.setting(mode, spp, fixed).add(seed, recs, diffs, imgs, self.refs, seed == self.seeds[0])

    def run(self, mode, spp, seed, fixed=False):
        recs, imgs, _, diffs = self.render(mode, spp, seed, fixed)
        self.add(mode, spp, seed, recs, imgs, diffs, fixed)
        return imgs

    def sweep(self, spp, sweep):
        """Seeds are the repeats; modes interleaved within each seed. Returns, per seed, the
        largest |difference| of reuse and retrace at spp (same seed)."""
        identical = []
        for seed in self.seeds:
            for s in sweep:
                a = self.run("reuse", s, seed)
                self.run("pathtrace", s, seed)
                if s == spp:
                    b = self.run("retrace", s, seed)
                    identical.append(max(float(np.max(np.abs(x - y))) for x, y in zip(a, b)))
                    self.run("pathtrace", s, seed, fixed=True)
        return identical

    def equal_time_rounds(self, spp, sweep, n_rounds):
        """Reuse at spp against pathtrace at the spp that takes as long, measured side by side
        in fresh interleaved runs; up to n_rounds tries of that spp."""
        pt = [(s, median(self.setting("pathtrace", s).times)) for s in sweep]
        k = metrics.equal_time_first_spp(pt, median(self.setting("reuse", spp).times), spp)
        rounds, tried = [], set()
        for _ in range(n_rounds):
            tried.add(k)
            rt, pt_t = [], []
            have = len(self.setting("pathtrace", k).err) >= len(self.seeds)  # images already measured
            for seed in self.seeds:
                recs, _, _, _ = self.render("reuse", spp, seed, keep=False)
                rt.append(metrics.body_time(recs))
                recs, imgs, _, diffs = self.render("pathtrace", k, seed, keep=not have)
                pt_t.append(metrics.body_time(recs))
                if not have:
                    self.add("pathtrace", k, seed, recs, imgs, diffs)
                if len(self.setting("pathtrace", k, True).err) < len(self.seeds):
                    self.run("pathtrace", k, seed, fixed=True)
            rounds.append(metrics.equal_time_round(k, rt, pt_t))
            k = metrics.equal_time_next_spp(k, rounds[-1].ratio, tried)
            if k is None:
                break
        return rounds


def timing_runs(runner, sc, args):
    """The paper's Figure 9: default settings over the timing frames, images not read;
    modes interleaved within each repeat."""
    tfirst, tlast = sc.timing_frames
    runs = {m: [] for m in MODES}
    for _ in range(args.repeats):
        for m in MODES:
            recs, _, wall, _ = runner.render(sc.path, m, args.spp, args.seeds[0], tfirst, tlast,
                                             keep=False)
            runs[m].append((recs, wall))
    return {m: metrics.summarize_timing(runs[m]) for m in MODES}


def evaluate_scene(runner, sc, cache, args):
    print(f"{sc.key}: frames {sc.frames[0]}-{sc.frames[-1]}", flush=True)
    ref_exrs, refs, ref_key = references(runner, sc, cache)
    q = SceneRuns(runner, sc, ref_exrs, refs, args.seeds)
    identical = q.sweep(args.spp, sc.sweep)
    rounds = q.equal_time_rounds(args.spp, sc.sweep, args.equal_time_rounds)
    equal_time = metrics.equal_time(q.settings, rounds, args.spp)
    equal_error = metrics.equal_error(q.settings, sc.sweep, args.spp)
    return SceneResult(scene=sc, refs=refs, ref_key=ref_key, settings=q.settings,
                       identical=identical, equal_time=equal_time, equal_error=equal_error,
                       timing=timing_runs(runner, sc, args))
