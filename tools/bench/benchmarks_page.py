"""Regenerates docs/benchmarks.md: runs each benchmark section's command and writes its tables
into the page, dated and marked with the commit it ran at.

  python3 -m tools.bench.benchmarks_page --build build --cycles PY --luxcore PY  # all: hours
  python3 -m tools.bench.benchmarks_page --only sampling,multidevice            # some sections
  python3 -m tools.bench.benchmarks_page --list       # ids, needs, durations, what runs here
  python3 -m tools.bench.benchmarks_page --dry-run    # the commands, nothing run
  python3 -m tools.bench.benchmarks_page --check      # the page has exactly the sections' blocks

SECTIONS below is the one list of sections: an id, a title, the command (argv; {build},
{cycles} and {luxcore} stand for --build, --cycles and --luxcore), what it needs and a rough
duration. Each section owns a block of the page, the lines between

  <!-- bench:ID begin -->
  <!-- bench:ID end -->

For each section the script runs its command from the repository root (stdout captured and
echoed to stderr as it comes, stderr passed through), keeps the Markdown table lines of its
stdout (lines starting with '|') with their captions (a heading or a line ending in ':' just
before a table, and the lines a section names), and replaces the block with

  _Measured DATE at commit SHA on CPU (N cores), T s:_ `COMMAND`

  | the tables |

A section that writes a page of its own (evaluate.py, bench_reuse.py, bench_rays.sh) gets one
such line naming the page it rewrote. The commit is `git rev-parse --short HEAD`, with
"+changes" when `git status --porcelain` lists anything but the generated pages themselves.

A section whose needs are missing is skipped with one line on stderr, its block (and its old
date) left as it was. A command that fails leaves its block as it was; the others still run,
and the script exits 1 at the end. The page is rewritten (a temporary file, then os.replace)
after each section, so an interrupted run keeps the sections it finished. Standard library
only.
"""

import argparse
import ctypes.util
import fnmatch
import json
import os
import re
import shlex
import shutil
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from datetime import datetime, timezone
from pathlib import Path

from .benchlib import cpu_model

REPO = Path(__file__).resolve().parents[2]
PAGE = REPO / "docs" / "benchmarks.md"
SHARED_SCENES = REPO.parent / "shared" / "scenes"  # where the bench tools read them
PY = "python3"
DEBIAN_PY = "/usr/bin/python3"  # the tools that need numpy and matplotlib


@dataclass(frozen=True)
class Section:
    id: str
    title: str
    argv: tuple  # {build}, {cycles}, {luxcore} are filled in
    needs: tuple
    minutes: int  # rough duration on the project's 2-core machine (or a GPU's, for gpu)
    writes: tuple = ()  # pages the tool writes itself (repository paths; globs for the rest)
    caption: str = ""  # regex: a line just before a table that is its caption
    keep: str = ""  # regex: more lines of stdout to keep, wherever they are
    convert: object = None  # stdout -> Markdown, for a tool that prints no table


def asset_table(text):
    """asset_compare.py prints one line per asset, not a table: its figures as one."""
    pat = re.compile(r"^(\S+)\s+luminance (\S+)\s+rgb (\S+) (\S+) (\S+)\s+blocks p95 (\S+) "
                     r"max (\S+)\s+pixels (\S+) \((\d+) blocks, (\d+) px\)"
                     r"(?:\s+parts worst (\S+) \((.*)\) of (\d+))?"
                     r"(?:\s+exact \S+: ours (\S+) Cycles (\S+))?")
    rows = [m.groups() for m in map(pat.match, text.splitlines()) if m]
    if not rows:
        return ""
    head = ["Ours / Cycles per asset (asset_compare's lines as a table):", "",
            "| asset | luminance | R G B | p95 block | max block | pixels | blocks | px "
            "| worst part (of the materials) | ours, Cycles / exact |",
            "|---|---:|---|---:|---:|---:|---:|---:|---|---|"]

    def worst(r):
        return f"{r[10]} {r[11]} (of {r[12]})" if r[10] else ""

    return "\n".join(head + [f"| {r[0]} | {r[1]} | {r[2]} {r[3]} {r[4]} | {r[5]} | {r[6]} | "
                             f"{r[7]} | {r[8]} | {r[9]} | {worst(r)} | "
                             f"{f'{r[13]}, {r[14]}' if r[13] else ''} |" for r in rows]) + "\n"


MATERIALS = (PY, "-m", "tools.bench.blender_compare", "--binary", "{build}/pathreuse",
             "--python", "{cycles}")
MATERIALS_KEEP = r"^\d+ of \d+ within|^column: storey"

SECTIONS = [
    Section("rays", "Ray traversal against Embree 3",
            ("bash", "tools/bench/bench_rays.sh", "--build", "{build}"),
            ("embree", "cmake", "shared-scenes"), 10, writes=("docs/ray-benchmark.md",)),
    Section("sampling", "Light choice per case",
            (PY, "-m", "tools.bench.bench_sampling", "--build", "{build}"),
            ("build", "shared-scenes"), 25, caption=r"^- spp ", keep=r"^- .*: relMSE \S+ / \S+ = "),
    Section("sampling-cycles", "The path tracer against Blender's Cycles",
            (PY, "-m", "tools.bench.bench_sampling", "--build", "{build}", "--cases", "1,2,3",
             "--cycles"),
            ("build", "blender", "shared-scenes"), 15, caption=r"^- spp ",
            keep=r"^- .*: relMSE \S+ / \S+ = "),
    Section("materials-furnace", "Materials in a white furnace",
            MATERIALS + ("--lighting", "furnace", "--width", "160", "--height", "160", "--spp",
                         "256", "--ours-spp", "64"),
            ("build", "cycles"), 45, caption=r"^ours \(", keep=MATERIALS_KEEP),
    Section("materials-area", "Materials under an area light",
            MATERIALS + ("--lighting", "area", "--width", "128", "--height", "128", "--spp",
                         "128"),
            ("build", "cycles"), 65, caption=r"^ours \(", keep=MATERIALS_KEEP),
    Section("materials-column", "The atrium's fluted column",
            MATERIALS + ("--case", "column", "--atrium-size", "1", "--spp", "1024"),
            ("build", "cycles"), 25, caption=r"^ours \(", keep=MATERIALS_KEEP),
    Section("assets", "Real assets",
            (DEBIAN_PY, "-m", "tools.bench.asset_compare", "--cycles", "{cycles}", "--binary",
             "{build}/pathreuse", "--spp", "256", "--width", "256"),
            ("build", "numpy", "cycles", "shared-scenes"), 20, convert=asset_table),
    Section("plane", "One material on a plane at chosen view angles",
            (DEBIAN_PY, "-m", "tools.bench.plane_compare", "--cycles", "{cycles}", "--binary",
             "{build}/pathreuse"),
            ("build", "numpy", "cycles"), 3),
    Section("animations", "Real animations, still and moving cameras",
            (DEBIAN_PY, "-m", "tools.bench.bench_animations", "--build", "{build}", "--cycles",
             "{cycles}", "--luxcore", "{luxcore}"),
            ("build", "numpy", "cycles", "luxcore", "shared-scenes"), 45,
            keep=r"^LuxCore not run on "),
    Section("temporal", "Generated animations against Cycles and LuxCore",
            (DEBIAN_PY, "-m", "tools.bench.bench_temporal", "--build", "{build}", "--settings",
             "pathtrace;reuse", "--frames", "16", "--warm", "8", "--cycles", "{cycles}",
             "--luxcore", "{luxcore}"),
            ("build", "numpy", "cycles", "luxcore"), 45),
    Section("sampling-reuse", "One frame against our path tracer and Cycles",
            (PY, "-m", "tools.bench.bench_sampling", "--build", "{build}", "--cases", "2,3",
             "--reuse", "--cycles"),
            ("build", "blender", "shared-scenes"), 20, caption=r"^- spp ",
            keep=r"^- .*: relMSE \S+ / \S+ = "),
    Section("connections", "Connection strategies on a CPU",
            (PY, "-m", "tools.bench.bench_connections", "--build", "{build}"),
            ("build",), 20),
    Section("connections-gpu", "Connection strategies on a GPU",
            (PY, "-m", "tools.bench.bench_connections", "--build", "{build}", "--width", "640",
             "--device", "gpu"),
            ("build", "gpu"), 20),
    Section("reuse", "Reuse against retrace and pathtrace",
            (PY, "-m", "tools.bench.bench_reuse", "--build", "{build}"),
            ("build",), 15, writes=("docs/reuse-benchmark.md",)),
    Section("evaluate", "The paper's claims",
            (DEBIAN_PY, "-m", "tools.bench.evaluate", "--build", "{build}"),
            ("build", "numpy"), 45,
            writes=("docs/results.md", "docs/results.json", "docs/eval_*")),
    Section("denoise", "Denoising against more samples",
            (DEBIAN_PY, "-m", "tools.bench.bench_denoise", "--exe", "{build}/pathreuse", "--cmp",
             "{build}/exr_compare", "--scenes", "cornell-dynamic,atrium", "--first", "8",
             "--last", "10", "--seeds", "1,2"),
            ("build", "numpy", "oidn"), 30),
    Section("adaptive", "Adaptive sampling against uniform sampling",
            (DEBIAN_PY, "-m", "tools.bench.bench_adaptive", "--exe", "{build}/pathreuse", "--cmp",
             "{build}/exr_compare", "--scenes", "atrium,cornell-dynamic", "--seeds", "1,2",
             "--oracle-seeds", "8", "--settings",
             "u:32,u:64,u:128,a:128:0.06,a:128:0.045,a:128:0.035,a:256:0.045,a:256:0.035,"
             "a:256:0.025"),
            ("build", "numpy"), 30, caption=r"^--mode "),
    Section("multidevice", "Two PoCL drivers on one CPU",
            (PY, "-m", "tools.bench.bench_multidevice", "--exe", "{build}/pathreuse",
             "--repeats", "5"),
            ("build", "pocl-drivers"), 10,
            keep=r"^Rows per device frame by frame|^Replicated light paths"),
]

NEEDS = {
    "build": "the renderer built in --build DIR (pathreuse, exr_compare)",
    "numpy": "/usr/bin/python3 with numpy and matplotlib (python3-numpy python3-matplotlib)",
    "cycles": "--cycles PY: a Python 3.13 with PyPI's bpy 5.2",
    "luxcore": "--luxcore PY: a Python 3.12 with PyPI's pyluxcore 2.11",
    "blender": "Debian's Blender (Cycles 3.4) as `blender` on PATH",
    "shared-scenes": "../shared/scenes beside the repository (the bench tools read it there)",
    "embree": "Embree 3 found by cmake for ray_bench (apt-get install libembree-dev)",
    "cmake": "cmake on PATH (bench_rays.sh builds ray_bench)",
    "gpu": "an OpenCL GPU device that the renderer lists",
    "oidn": "Open Image Denoise 2 (tools/setup/oidn.sh, or PATHREUSE_OIDN)",
    "pocl-drivers": "PoCL's pthread and basic drivers (POCL_DEVICES='pthread basic')",
}


class BlockError(Exception):
    pass


# ------------------------------------------------------------------ the page's blocks

MARK = re.compile(r"^<!-- bench:([A-Za-z0-9_.-]+) (begin|end) -->[ \t\r]*$", re.M)


def block_ids(text):
    """The ids of the page's blocks in order; BlockError where markers do not pair up."""
    ids, open_id = [], None
    for m in MARK.finditer(text):
        sid, kind = m.group(1), m.group(2)
        if kind == "begin":
            if open_id is not None:
                raise BlockError(f"block {open_id!r}: no end marker before the begin of {sid!r}")
            if sid in ids:
                raise BlockError(f"block {sid!r}: appears twice")
            open_id = sid
        else:
            if open_id != sid:
                raise BlockError(f"block {sid!r}: end marker without its begin marker")
            ids.append(sid)
            open_id = None
    if open_id is not None:
        raise BlockError(f"block {open_id!r}: no end marker")
    return ids


def replace_block(text, sid, body):
    """The page with block `sid`'s lines replaced by `body`; all else byte for byte as it was.
    BlockError (naming the id) where the block is missing or its markers are not one pair."""
    begins = [m for m in MARK.finditer(text) if m.group(1) == sid and m.group(2) == "begin"]
    ends = [m for m in MARK.finditer(text) if m.group(1) == sid and m.group(2) == "end"]
    if not begins and not ends:
        raise BlockError(f"block {sid!r}: not in the page (add <!-- bench:{sid} begin --> and "
                         f"<!-- bench:{sid} end --> lines)")
    if len(begins) != 1 or len(ends) != 1 or ends[0].start() < begins[0].end():
        raise BlockError(f"block {sid!r}: needs exactly one begin and, after it, one end marker")
    start = text.index("\n", begins[0].end()) + 1 if "\n" in text[begins[0].end():] else None
    if start is None or start > ends[0].start():
        raise BlockError(f"block {sid!r}: begin and end markers on one line")
    if body and not body.endswith("\n"):
        body += "\n"
    return text[:start] + body + text[ends[0].start():]


def check_page(text, sections):
    """Problems (strings) with the page's blocks against the sections: every section id has a
    block and every block a section."""
    try:
        ids = block_ids(text)
    except BlockError as e:
        return [str(e)]
    known = [s.id for s in sections]
    errs = [f"section {i!r} has no block in the page" for i in known if i not in ids]
    errs += [f"block {i!r} belongs to no section" for i in ids if i not in known]
    return errs


def read_page(path):
    """The page's text, line endings as they are."""
    with open(path, encoding="utf-8", newline="") as f:
        return f.read()


def write_atomic(path, text):
    path = Path(path)
    mode = path.stat().st_mode & 0o777 if path.exists() else 0o644
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        with os.fdopen(fd, "w", encoding="utf-8", newline="") as f:
            f.write(text)
            f.flush()
            os.fsync(f.fileno())
        os.chmod(tmp, mode)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


# ------------------------------------------------------------------ a command's tables

HEADING = re.compile(r"^#{1,6}\s+(.*?)\s*#*\s*$")


def extract(stdout, caption="", keep=""):
    """The Markdown table lines of a tool's stdout (lines starting with '|'), each table's
    caption (the non-blank line just before it: a heading, made bold, a line ending in ':', or
    one matching `caption`) and the lines matching `keep`; blank lines between groups."""
    lines = [l.rstrip() for l in stdout.splitlines()]
    is_table = [l.startswith("|") for l in lines]

    def next_nonblank(i):
        for j in range(i + 1, len(lines)):
            if lines[j].strip():
                return j
        return None

    items = []  # (line number, text, is table)
    for i, l in enumerate(lines):
        if is_table[i]:
            items.append((i, l, True))
            continue
        if not l.strip():
            continue
        h = HEADING.match(l)
        text = f"**{h.group(1)}**" if h else l
        if keep and re.search(keep, l):
            items.append((i, text, False))
            continue
        j = next_nonblank(i)
        if j is not None and is_table[j] and (h or l.endswith(":")
                                              or (caption and re.search(caption, l))):
            items.append((i, text, False))
    out = []
    for k, (i, text, tab) in enumerate(items):
        if k:
            pi, _, ptab = items[k - 1]
            out.append("\n" if pi + 1 == i and ptab == tab else "\n\n")
        out.append(text)
    return "".join(out) + "\n" if out else ""


# ------------------------------------------------------------------ where it runs

class Context:
    """--build, --cycles, --luxcore and what the needs' checks found (each checked once)."""

    def __init__(self, build="build", cycles=None, luxcore=None):
        self.build_arg = build
        self.build = Path(build) if Path(build).is_absolute() else REPO / build
        self.cycles, self.luxcore = cycles, luxcore
        self._missing = {}
        self._devices = None

    def fill(self, argv):
        """argv with {build}, {cycles}, {luxcore} filled in (placeholders where not given)."""
        vals = {"build": self.build_arg, "cycles": self.cycles or "CYCLES_PY",
                "luxcore": self.luxcore or "LUXCORE_PY"}
        return [a.format(**vals) for a in argv]

    def devices(self):
        if self._devices is None:
            self._devices = []
            exe = self.build / "pathreuse"
            if exe.is_file():
                try:
                    out = subprocess.run([str(exe), "devices", "--json"], capture_output=True,
                                         text=True, timeout=120)
                    self._devices = json.loads(out.stdout)["devices"] if out.returncode == 0 else []
                except (OSError, ValueError, KeyError, subprocess.TimeoutExpired):
                    self._devices = []
        return self._devices

    def missing(self, need):
        """Why `need` is not met here, or None where it is."""
        if need not in self._missing:
            self._missing[need] = CHECKS[need](self)
        return self._missing[need]


def _has_module(python, module):
    try:
        out = subprocess.run([python, "-c", "import importlib.util, sys; sys.exit("
                              f"importlib.util.find_spec({module!r}) is None)"],
                             capture_output=True, timeout=120)
    except (OSError, subprocess.TimeoutExpired):
        return False
    return out.returncode == 0


def _check_build(ctx):
    absent = [n for n in ("pathreuse", "exr_compare") if not (ctx.build / n).is_file()]
    return f"{ctx.build_arg}/{' and '.join(absent)} not built" if absent else None


def _check_numpy(ctx):
    if not Path(DEBIAN_PY).is_file():
        return f"{DEBIAN_PY} not found"
    absent = [m for m in ("numpy", "matplotlib") if not _has_module(DEBIAN_PY, m)]
    return f"{DEBIAN_PY} lacks {' and '.join(absent)}" if absent else None


def _check_python(ctx, attr, module, flag):
    py = getattr(ctx, attr)
    if not py:
        return f"{flag} PY not given"
    if not (shutil.which(py) or Path(py).is_file()):
        return f"{flag} {py}: not found"
    return None if _has_module(py, module) else f"{flag} {py}: no module {module}"


def _check_embree(ctx):
    cache = ctx.build / "CMakeCache.txt"
    if cache.is_file():
        m = re.search(r"^embree_DIR:PATH=(.*)$", cache.read_text(errors="replace"), re.M)
        if m and not m.group(1).endswith("NOTFOUND"):
            return None
        return (f"{ctx.build_arg} was configured without Embree 3 (apt-get install "
                "libembree-dev, then cmake again)")
    found = [p for pat in ("/usr/lib/*/cmake/embree-3*", "/usr/lib/cmake/embree-3*",
                           "/usr/local/lib/cmake/embree-3*") for p in Path("/").glob(pat[1:])]
    return None if found else "no Embree 3 (apt-get install libembree-dev)"


def _check_gpu(ctx):
    if _check_build(ctx):
        return _check_build(ctx) + " (it lists the devices)"
    gpus = [d for d in ctx.devices() if d.get("type") == "GPU"]
    return None if gpus else f"no OpenCL GPU among {ctx.build_arg}/pathreuse's devices"


def _check_oidn(ctx):
    lib = os.environ.get("PATHREUSE_OIDN")
    if lib:
        return None if Path(lib).is_file() else f"PATHREUSE_OIDN={lib}: not found"
    root = os.environ.get("PATHREUSE_OPENCL_HOME")
    if not root:
        x = os.environ.get("XDG_CACHE_HOME")
        root = f"{x}/pathreuse" if x else str(Path.home() / ".cache" / "pathreuse")
    if Path(root, "oidn", "libOpenImageDenoise.so.2").exists():
        return None
    if ctypes.util.find_library("OpenImageDenoise"):
        return None
    return "no Open Image Denoise 2 (tools/setup/oidn.sh installs it)"


def _check_pocl_drivers(ctx):
    exe = ctx.build / "pathreuse"
    if not exe.is_file():
        return f"{ctx.build_arg}/pathreuse not built (it lists the devices)"
    try:
        out = subprocess.run([str(exe), "devices", "--json"], capture_output=True, text=True,
                             timeout=120, env=dict(os.environ, POCL_DEVICES="pthread basic"))
        devs = [d for d in json.loads(out.stdout)["devices"]
                if d.get("platform_vendor") == "The pocl project"]
    except (OSError, ValueError, KeyError, subprocess.TimeoutExpired):
        devs = []
    return None if len(devs) == 2 else "PoCL's pthread and basic drivers are not both there"


def _check_shared(ctx):
    if SHARED_SCENES.is_dir():
        return None
    if os.environ.get("PATHREUSE_SCENES"):
        return (f"{SHARED_SCENES} not found (PATHREUSE_SCENES is set, but the bench tools read "
                "../shared/scenes: link it there)")
    return f"{SHARED_SCENES} not found"


CHECKS = {
    "build": _check_build,
    "numpy": _check_numpy,
    "cycles": lambda ctx: _check_python(ctx, "cycles", "bpy", "--cycles"),
    "luxcore": lambda ctx: _check_python(ctx, "luxcore", "pyluxcore", "--luxcore"),
    "blender": lambda ctx: None if shutil.which("blender") else "no `blender` on PATH",
    "shared-scenes": _check_shared,
    "embree": _check_embree,
    "cmake": lambda ctx: None if shutil.which("cmake") else "no `cmake` on PATH",
    "gpu": _check_gpu,
    "oidn": _check_oidn,
    "pocl-drivers": _check_pocl_drivers,
}
assert set(CHECKS) == set(NEEDS)


def missing_needs(section, ctx):
    """[(need, why)] of the section's needs that are not met."""
    return [(n, why) for n in section.needs for why in [ctx.missing(n)] if why]


def machine(section, ctx):
    """'CPU model (N cores)', and the GPU's name for a section that needs one."""
    m = f"{cpu_model()} ({os.cpu_count()} cores)"
    if "gpu" in section.needs:
        gpus = sorted({d["name"] for d in ctx.devices() if d.get("type") == "GPU"})
        if gpus:
            m += " with " + ", ".join(gpus)
    return m


def commit(excluded):
    """The short commit, '+changes' when `git status --porcelain` lists anything but the paths
    matching `excluded` (the generated pages, which this run rewrites)."""
    try:
        sha = subprocess.run(["git", "-C", str(REPO), "rev-parse", "--short", "HEAD"],
                             capture_output=True, text=True).stdout.strip()
        st = subprocess.run(["git", "-C", str(REPO), "status", "--porcelain"],
                            capture_output=True, text=True).stdout
    except OSError:
        return "unknown"
    changed = []
    for line in st.splitlines():
        path = line[3:].split(" -> ")[-1].strip('"')
        if not any(fnmatch.fnmatch(path, pat) for pat in excluded):
            changed.append(path)
    return (sha or "unknown") + ("+changes" if changed else "")


def command_text(argv):
    home = str(Path.home()) + "/"
    return shlex.join(argv).replace(home, "~/")


def duration_text(minutes):
    return f"~{minutes} min" if minutes < 90 else f"~{minutes / 60:.1f} h".replace(".0 h", " h")


def block_body(section, argv, date, sha, mach, seconds, stdout, page):
    """The block's new lines; None (with the reason) where the output has no table."""
    head = f"_Measured {date} at commit {sha} on {mach}, {seconds:.0f} s"
    if section.writes:
        target = REPO / section.writes[0]
        link = os.path.relpath(target, Path(page).resolve().parent)
        return head + f"; rewrote [{target.name}]({link}):_ `{command_text(argv)}`\n", None
    text = section.convert(stdout) if section.convert else stdout
    tables = extract(text, section.caption, section.keep)
    if not any(l.startswith("|") for l in tables.splitlines()):
        return None, "its output has no Markdown table"
    return f"{head}:_ `{command_text(argv)}`\n\n{tables}\n", None


def run_command(argv, echo=sys.stderr):
    """Runs argv from the repository root: stdout captured (and echoed to `echo` as it comes),
    stderr passed through. (exit status, stdout, seconds)."""
    start = time.monotonic()
    out = []
    with subprocess.Popen(argv, cwd=REPO, stdout=subprocess.PIPE, text=True, bufsize=1,
                          errors="replace") as proc:
        for line in proc.stdout:
            out.append(line)
            echo.write(line)
            echo.flush()
    rc = proc.returncode
    return rc, "".join(out), time.monotonic() - start


def regenerate(sections, ctx, page, extra_args=(), log=sys.stderr, runner=run_command):
    """Runs the sections into the page; the number of failed sections."""
    page = Path(page)
    text = read_page(page)
    for s in sections:  # before hours of work: every block is there
        replace_block(text, s.id, "")
    excluded = {str(page.resolve().relative_to(REPO)) if page.resolve().is_relative_to(REPO)
                else ""} | {w for s in SECTIONS for w in s.writes}
    sha = commit(excluded)
    failed, done, skipped = [], [], []
    for s in sections:
        miss = missing_needs(s, ctx)
        if miss:
            print(f"benchmarks_page: {s.id}: skipped, missing "
                  + "; ".join(f"{n} ({why})" for n, why in miss), file=log, flush=True)
            skipped.append(s.id)
            continue
        argv = ctx.fill(s.argv) + list(extra_args)
        print(f"benchmarks_page: {s.id}: {command_text(argv)}", file=log, flush=True)
        before = {w: _mtime(REPO / w) for w in s.writes[:1]}
        try:
            rc, stdout, secs = runner(argv, log)
        except OSError as e:
            rc, stdout, secs = None, "", 0.0
            why = str(e)
        else:
            why = f"exit status {rc}" if rc else None
        if not why and s.writes and _mtime(REPO / s.writes[0]) == before[s.writes[0]]:
            why = f"{s.writes[0]} was not rewritten"
        body = None
        if not why:
            date = datetime.now(timezone.utc).strftime("%Y-%m-%d")
            body, why = block_body(s, argv, date, sha, machine(s, ctx), secs, stdout, page)
        if why:
            print(f"benchmarks_page: {s.id}: FAILED ({why}); its block is left as it was",
                  file=log, flush=True)
            failed.append(s.id)
            continue
        text = replace_block(read_page(page), s.id, body)
        write_atomic(page, text)
        done.append(s.id)
        print(f"benchmarks_page: {s.id}: written to {page} ({secs:.0f} s)", file=log, flush=True)
    print(f"benchmarks_page: {len(done)} written, {len(skipped)} skipped, {len(failed)} failed"
          + (f": {', '.join(failed)}" if failed else ""), file=log, flush=True)
    return len(failed)


def _mtime(path):
    try:
        return path.stat().st_mtime_ns
    except OSError:
        return None


def list_sections(sections, ctx, out=sys.stdout):
    """One line per section (id, duration, needs, title) and one saying whether it runs here."""
    runs = 0
    wid = max(len(s.id) for s in sections)
    for s in sections:
        miss = missing_needs(s, ctx)
        runs += 0 if miss else s.minutes
        print(f"{s.id:{wid}s}  {duration_text(s.minutes):>8s}  {s.title}; needs "
              f"{', '.join(s.needs)}", file=out)
        here = ("runs here" if not miss else
                "skipped here: " + "; ".join(f"{n}: {why}" for n, why in miss))
        print(f"{'':{wid}s}  {'':8s}  {here}", file=out)
    print(f"\n{len(sections)} sections, {duration_text(sum(s.minutes for s in sections))} in "
          f"all; those that run here {duration_text(runs)}.\nNeeds:", file=out)
    for n, d in NEEDS.items():
        print(f"  {n:14s} {d}", file=out)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", default="build", help="the renderer's build folder (default build)")
    ap.add_argument("--cycles", metavar="PY", help="a Python 3.13 with PyPI's bpy 5.2")
    ap.add_argument("--luxcore", metavar="PY", help="a Python 3.12 with PyPI's pyluxcore 2.11")
    ap.add_argument("--only", metavar="ID[,ID...]", help="these sections only")
    ap.add_argument("--list", action="store_true", help="the sections, their needs and durations, "
                    "and which would run here")
    ap.add_argument("--dry-run", action="store_true", help="print the commands, run nothing")
    ap.add_argument("--check", action="store_true",
                    help="check that the page has exactly the sections' blocks, run nothing")
    ap.add_argument("--page", default=str(PAGE), help="the page (default docs/benchmarks.md); "
                    "the pages that tools write themselves stay in docs/")
    # For testing on a copy of the page: more arguments for the one section of --only (written
    # with '=' since they start with --), e.g. --extra-args='--cases 4 --spp 4 --seeds 1'.
    ap.add_argument("--extra-args", default="", help=argparse.SUPPRESS)
    a = ap.parse_args(argv)
    ctx = Context(a.build, a.cycles, a.luxcore)
    sections = SECTIONS
    if a.only:
        ids = [i.strip() for i in a.only.split(",") if i.strip()]
        unknown = [i for i in ids if i not in {s.id for s in SECTIONS}]
        if unknown:
            ap.error(f"--only: no section {', '.join(unknown)} (there are: "
                     f"{', '.join(s.id for s in SECTIONS)})")
        sections = [s for s in SECTIONS if s.id in ids]
    extra = shlex.split(a.extra_args)
    if extra and len(sections) != 1:
        ap.error("--extra-args: with --only of one section")
    if a.list:
        list_sections(sections, ctx)
        return 0
    if a.dry_run:
        for s in sections:
            miss = missing_needs(s, ctx)
            note = ("  # skipped here, missing " + ", ".join(n for n, _ in miss)) if miss else ""
            print(f"{s.id}: {command_text(ctx.fill(s.argv) + extra)}{note}")
        return 0
    page = Path(a.page)
    try:
        text = read_page(page)
    except OSError as e:
        sys.exit(f"benchmarks_page: {e}")
    if a.check:
        errs = check_page(text, SECTIONS)
        for e in errs:
            print(f"benchmarks_page: {page}: {e}", file=sys.stderr)
        return 1 if errs else 0
    try:
        return 1 if regenerate(sections, ctx, page, extra) else 0
    except BlockError as e:
        sys.exit(f"benchmarks_page: {page}: {e}")
    except KeyboardInterrupt:
        print("benchmarks_page: interrupted; the page keeps the sections written so far",
              file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
