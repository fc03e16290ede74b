"""Compares pathreuse's glTF materials with Blender 5.2's Cycles, material by material.

For every material of a catalogue (dielectrics, metals, KHR_materials_specular, _clearcoat,
_sheen, _anisotropy, glass; see --list) it writes a scene with one smooth sphere of it
(128x64 segments, NORMALs; TEXCOORD_0 and TANGENTs where anisotropic) and a camera, under
two lightings:

  furnace  a uniform environment of radiance 1 and nothing else (ours `--env-color 1,1,1`,
           Cycles' world colour 1, strength 1): the sphere's radiance is its directional
           albedo, so energy that a BSDF loses or gains shows directly
  area     an emissive quad (KHR_materials_emissive_strength, double sided) above and to
           the side, a large Lambertian grey floor (KHR_materials_specular specularFactor 0:
           the same Lambert surface in both renderers), black world, ours `--env none`

and renders it with `pathreuse render --mode pathtrace --max-depth 64 --exr-float` and with
Cycles (CPU, through Blender's own glTF importer, the Principled BSDF as imported: box
filter 1 px wide, 62 bounces, no clamping, denoising, adaptive sampling or path guiding,
glossy filter 0, light tree on, fixed seed, Standard view transform, linear float EXR). Then
over the pixels that lie wholly on the sphere (computed from the camera and the sphere, and
checked against a ray cast through Blender's imported camera and mesh) it gives the ratio
ours / Cycles of the mean luminance and of each channel's mean, and the 95th percentile over
the 16x16 blocks wholly on the sphere of |ours / Cycles - 1| (block means); a row passes when
both are within --tolerance (2%). In the furnace, it adds the mean radiance (= albedo) of
each renderer per band of 0.1 of n.v (the cosine between the normal and the view direction).

--case column instead renders the atrium (tools/scenes/gen_atrium.py --size S, its first camera)
with direct light only (ours --max-depth 2, Cycles 0 bounces) and compares the region of the
fluted foreground column: the pixels whose camera ray (cast through Blender's imported scene)
hits the shaft of the column that covers most of the image, less a one-pixel border, plus a
profile across the column (per image column x, the ratio over its pixels): the flutes run
vertically, so stripes show as the profile's extremes.

Blender is a benchmark peer, not a dependency: the tool makes its own virtual environment of a
Python 3.13 interpreter (--python, else python3.13 on PATH, else pyenv's) with PyPI's
bpy==5.2.3 and numpy (tools/bench/requirements-blender.txt) under ~/.cache/pathreuse/bpy-5.2.3/ the
first time (about 1 GB). Renders are cached under --cache keyed by scene contents and settings
(ours also by the renderer binary's and PATHREUSE_KERNEL_DIR's contents), so after a change
to the renderer only ours renders again; --rerender-ours forces it. Blender renders one scene
at a time with --threads threads; ours gets POCL_MAX_PTHREAD_COUNT=--threads.

  python3 -m tools.bench.blender_compare --binary build/pathreuse                 # everything, 200 px, 1024 spp
  python3 -m tools.bench.blender_compare --materials 'metal-*,lambert-grey' --lighting furnace --spp 256
  python3 -m tools.bench.blender_compare --materials 'lambert-*' --ours-args=--force-diffuse  # set-up check
  python3 -m tools.bench.blender_compare --ours-args="--material-model gltf-reference" --json old.json
  python3 -m tools.bench.blender_compare --case column --atrium-size 1 --spp 1024
  python3 -m tools.bench.blender_compare --list

(--ours-args takes its value after '=', since the value starts with --.) --noise renders ours
again with --seed + 1 and gives the same figures between our two seeds: the floor below which
a difference is noise (that render is also the cache entry of a later --seed S+1 run).
Ratio maps (ours / Cycles, red brighter, blue darker, saturating at 10%) go to WORK/maps/.

Cost on the project's 2-core machine, shared (load 4 to 8), per sphere on average: Cycles 23 s
in the furnace at 160x160 and 256 spp, 26 s under the area light at 128x128 and 128 spp (the
render call); ours 19 s (furnace, 64 spp) and 38 s (area, 128 spp). The whole set (60
materials, both lightings) at those settings took 1 h 50 min of renders; the defaults (200 px,
1024 spp) cost 6 to 13 times that, so use --spp, --ours-spp, --width/--height and
--materials. The atrium column at 320x180, 1024 spp: Cycles 884 s, ours 422 s.

The driver needs numpy: it runs under any Python >= 3.11 that has it (Debian's python3), and
otherwise re-runs itself under the Blender environment's interpreter. EXRs are read with
exr_compare --raw from the renderer's build folder (else through bpy). Exit status 0, or 1
with --strict when a row fails.
"""

import argparse
import fnmatch
import hashlib
import json
import math
import os
import shlex
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
REPO = HERE.parents[1]

BPY_VERSION = "5.2.3"
VENV = Path.home() / ".cache" / "pathreuse" / f"bpy-{BPY_VERSION}"
REQUIREMENTS = HERE / "requirements-blender.txt"
# Bumped when the Cycles set-up below changes, so that cached Cycles renders are redone.
CYCLES_SETUP = "cycles-setup-1"


# ---------------------------------------------------------------- Blender's environment

def python_313(explicit):
    """A Python 3.13 interpreter: --python, python3.13 on PATH (a pyenv shim may be there
    without being runnable), pyenv's own versions, /usr/bin/python3.13."""
    cands = [explicit] if explicit else []
    cands.append(shutil.which("python3.13"))
    root = Path(os.environ.get("PYENV_ROOT", Path.home() / ".pyenv"))
    cands += [str(p) for p in sorted(root.glob("versions/3.13*/bin/python3.13"), reverse=True)]
    cands.append("/usr/bin/python3.13")
    for c in cands:
        if not c:
            continue
        try:
            out = subprocess.run([c, "-c", "import sys; print(sys.version_info[:2] == (3, 13))"],
                                 capture_output=True, text=True, timeout=60)
        except (OSError, subprocess.TimeoutExpired):
            out = None
        if out and out.returncode == 0 and out.stdout.strip() == "True":
            return c
        if explicit and c == explicit:
            sys.exit(f"blender_compare: --python {c} is not a runnable Python 3.13")
    sys.exit("blender_compare: no Python 3.13 found (bpy 5.2 needs it): give --python PATH")


def ensure_venv(explicit_python):
    """The virtual environment's python, made (venv + pip install) when absent. A marker
    written after a successful install tells a complete environment from an interrupted one."""
    py = VENV / "bin" / "python"
    marker = VENV / ".installed"
    reqs = REQUIREMENTS.read_text() if REQUIREMENTS.is_file() else f"bpy=={BPY_VERSION}\nnumpy\n"
    if py.is_file() and marker.is_file() and marker.read_text() == reqs:
        return str(py)
    base = python_313(explicit_python)
    print(f"blender_compare: installing bpy {BPY_VERSION} into {VENV} (about 1 GB, once) ...",
          flush=True)
    if not py.is_file():
        VENV.parent.mkdir(parents=True, exist_ok=True)
        subprocess.run([base, "-m", "venv", str(VENV)], check=True)
    with tempfile.NamedTemporaryFile("w", suffix=".txt", delete=False) as f:
        f.write(reqs)
    try:
        subprocess.run([str(py), "-m", "pip", "install", "--disable-pip-version-check", "-r",
                        f.name], check=True)
    finally:
        os.unlink(f.name)
    ver = subprocess.run([str(py), "-c", "import bpy; print(bpy.app.version_string)"],
                         capture_output=True, text=True)
    if ver.returncode or not ver.stdout.strip().startswith(BPY_VERSION):
        sys.exit(f"blender_compare: bpy in {VENV} does not import: {ver.stderr.strip()[-400:]}")
    marker.write_text(reqs)
    return str(py)


try:
    import numpy as np
except ImportError:  # e.g. a pyenv python3 without numpy: the Blender environment has it
    if os.environ.get("BLENDER_COMPARE_REEXEC"):
        sys.exit("blender_compare: numpy is missing")
    _py = ensure_venv(next((sys.argv[i + 1] for i, a in enumerate(sys.argv[:-1])
                            if a == "--python"), None))
    os.environ["BLENDER_COMPARE_REEXEC"] = "1"
    # The same module under that interpreter, the repository root on its import path.
    os.environ["PYTHONPATH"] = os.pathsep.join(
        [str(REPO)] + [p for p in [os.environ.get("PYTHONPATH")] if p])
    os.execv(_py, [_py, "-m", "tools.bench.blender_compare"] + sys.argv[1:])

from ..scenes import gltf_writer as gw  # noqa: E402
from .benchlib import run_tool  # noqa: E402


# ---------------------------------------------------------------- materials

ROUGH = (0.0, 0.25, 0.5, 0.75, 1.0)
GOLD = (1.0, 0.77, 0.34)


def _catalogue():
    """{name: (class, glTF material dict without name, needs tangents)}."""
    cat = {}

    def add(name, cls, base, metallic, rough, ext=None, tangents=False):
        mat = {"pbrMetallicRoughness": {"baseColorFactor": list(base) + [1.0],
                                        "metallicFactor": metallic, "roughnessFactor": rough}}
        if ext:
            mat["extensions"] = ext
        cat[name] = (cls, mat, tangents)

    def r(x):
        return "r%03d" % round(100 * x)
    # Pure Lambert in both renderers (F0 = F90 = 0; Cycles' Specular IOR Level 0): the set-up
    # check, and what --force-diffuse shades
    no_spec = {"KHR_materials_specular": {"specularFactor": 0.0}}
    add("lambert-grey", "lambert", (0.8,) * 3, 0.0, 1.0, no_spec)
    add("lambert-white", "lambert", (1.0,) * 3, 0.0, 1.0, no_spec)
    # a dark base shows the specular layer's own albedo, which a white one hides
    for tone, base in (("dark", (0.1,) * 3), ("grey", (0.8,) * 3), ("white", (1.0,) * 3)):
        for x in ROUGH:
            add(f"dielectric-{tone}-{r(x)}", "dielectric", base, 0.0, x)
    for tone, base in (("white", (1.0,) * 3), ("gold", GOLD)):
        for x in ROUGH:
            add(f"metal-{tone}-{r(x)}", "metal", base, 1.0, x)
    for variant, spec in (("f05", {"specularFactor": 0.5}),
                          ("colour", {"specularColorFactor": [1.0, 0.5, 0.25]})):
        for x in ROUGH:
            add(f"specular-{variant}-{r(x)}", "specular", (0.5,) * 3, 0.0, x,
                {"KHR_materials_specular": dict(spec)})
    for x in ROUGH:  # the coat's roughness varies; under it a white diffuse-ish base
        add(f"clearcoat-{r(x)}", "clearcoat", (1.0,) * 3, 0.0, 1.0,
            {"KHR_materials_clearcoat": {"clearcoatFactor": 1.0, "clearcoatRoughnessFactor": x}})
    for tone, base in (("dark", (0.1,) * 3), ("white", (1.0,) * 3)):
        for x in ROUGH:  # the sheen's roughness varies
            add(f"sheen-{tone}-{r(x)}", "sheen", base, 0.0, 1.0,
                {"KHR_materials_sheen": {"sheenColorFactor": [1.0, 1.0, 1.0],
                                         "sheenRoughnessFactor": x}})
    for s in (0.5, 1.0):
        for x in ROUGH:
            add(f"aniso-s{round(10 * s):02d}-{r(x)}", "anisotropy", (1.0,) * 3, 1.0, x,
                {"KHR_materials_anisotropy": {"anisotropyStrength": s,
                                              "anisotropyRotation": 0.5}}, tangents=True)
    add("glass", "glass", (1.0,) * 3, 0.0, 0.0,
        {"KHR_materials_transmission": {"transmissionFactor": 1.0}})
    # rough glass (GGX refraction), glass tinted as ToyCar's, glass at half its points
    for tone, base in (("white", (1.0,) * 3), ("green", (0.3, 0.8, 0.3))):
        for x in ((0.25, 0.5, 0.75) if tone == "white" else (0.0, 0.5)):
            add(f"glass-{tone}-{r(x)}", "glass", base, 0.0, x,
                {"KHR_materials_transmission": {"transmissionFactor": 1.0}})
    add("glass-half-r050", "glass", (1.0,) * 3, 0.0, 0.5,
        {"KHR_materials_transmission": {"transmissionFactor": 0.5}})
    add("glass-coat-r050", "glass", (1.0,) * 3, 0.0, 0.5,
        {"KHR_materials_transmission": {"transmissionFactor": 1.0},
         "KHR_materials_clearcoat": {"clearcoatFactor": 1.0, "clearcoatRoughnessFactor": 0.1}})
    # the roughnesses of the figures (metal 0.7, white dielectric 0.3)
    add("issue-metal-white-r070", "issue", (1.0,) * 3, 1.0, 0.7)
    add("issue-dielectric-white-r030", "issue", (1.0,) * 3, 0.0, 0.3)
    return cat


MATERIALS = _catalogue()


def expected_principled(mat):
    """What Blender's importer should set on the Principled BSDF for a catalogue material
    (its own mappings: Specular IOR Level = 0.5 x specularFactor, rotation / 2 pi, ...)."""
    pbr, ext = mat["pbrMetallicRoughness"], mat.get("extensions", {})
    spec = ext.get("KHR_materials_specular", {})
    coat = ext.get("KHR_materials_clearcoat")
    sheen = ext.get("KHR_materials_sheen")
    aniso = ext.get("KHR_materials_anisotropy", {})
    exp = {"Base Color": pbr["baseColorFactor"], "Metallic": pbr["metallicFactor"],
           "Roughness": pbr["roughnessFactor"], "IOR": 1.5,
           "Specular IOR Level": 0.5 * spec.get("specularFactor", 1.0),
           "Specular Tint": spec.get("specularColorFactor", [1.0] * 3) + [1.0],
           "Coat Weight": coat["clearcoatFactor"] if coat else 0.0,
           "Sheen Weight": 1.0 if sheen else 0.0,
           "Anisotropic": aniso.get("anisotropyStrength", 0.0),
           "Anisotropic Rotation": aniso.get("anisotropyRotation", 0.0) / (2 * math.pi),
           "Transmission Weight": ext.get("KHR_materials_transmission", {}).get(
               "transmissionFactor", 0.0)}
    if coat:
        exp["Coat Roughness"] = coat.get("clearcoatRoughnessFactor", 0.0)
    if sheen:
        exp["Sheen Tint"] = sheen["sheenColorFactor"] + [1.0]
        exp["Sheen Roughness"] = sheen["sheenRoughnessFactor"]
    return exp


def importer_mismatches(name, logged):
    """Inputs where the imported Principled node differs from expected_principled."""
    if not logged:
        return ["no Principled BSDF imported"]
    got, bad = logged["inputs"], []
    for k, want in expected_principled(MATERIALS[name][1]).items():
        have = got.get(k)
        w = want if isinstance(want, list) else [want]
        h = have if isinstance(have, list) else [have]
        if have is None or isinstance(have, str) or len(w) != len(h) or any(
                abs(a - b) > 1e-4 for a, b in zip(w, h)):
            bad.append(f"{k}: {have} (expected {want})")
    return bad


def select_materials(spec):
    names = []
    for pat in [p.strip() for p in spec.split(",") if p.strip()]:
        hit = [n for n in MATERIALS if fnmatch.fnmatchcase(n, pat) or MATERIALS[n][0] == pat]
        if not hit:
            sys.exit(f"blender_compare: no material matches {pat!r} (see --list)")
        names += [n for n in hit if n not in names]
    return names


# ---------------------------------------------------------------- sphere scenes

RADIUS, CAM_DIST, YFOV = 1.0, 4.0, 0.56  # the sphere fills about 90% of the image height
SEGMENTS, RINGS = 128, 64
LAMP_CENTRE, LAMP_SIZE, LAMP_STRENGTH = (1.6, 2.8, 2.2), 2.0, 8.0
FLOOR_Y, FLOOR_GREY = -RADIUS, 0.5


def sphere_mesh():
    """The UV sphere with TEXCOORD_0 (u round +Y, v from the top) and, apart, its TANGENTs:
    d/du, w = +1, i.e. MikkTSpace's frame on these uvs. Cycles, whose importer ignores
    TANGENT without an anisotropy texture, takes the radial tangent round the object's Z
    (glTF +Y): the same axis, with the same bitangent N x T up to the sign of both."""
    m = gw.uv_sphere(RADIUS, SEGMENTS, RINGS)
    tangents = []
    for j in range(RINGS + 1):
        for i in range(SEGMENTS + 1):
            u, v = i / SEGMENTS, j / RINGS
            m.uv += (u, v)
            phi = 2 * math.pi * u
            tangents += (-math.sin(phi), 0.0, math.cos(phi), 1.0)
    assert len(tangents) == 4 * m.vertex_count
    return m, tangents


def write_sphere_scene(path, name, lighting, width, height, mesh):
    cls, mat, needs_tangents = MATERIALS[name]
    sphere, tangents = mesh
    # The old path (before tools/ had folders), kept: the render cache is keyed by scene bytes.
    g = gw.Gltf("pathreuse tools/blender_compare.py")
    mi = g._append("materials", dict(name=name, **json.loads(json.dumps(mat))))
    for ext in mat.get("extensions", {}):
        g.extensions.add(ext)
    if not needs_tangents:
        bare = gw.Mesh()
        bare.pos, bare.nrm, bare.idx = sphere.pos, sphere.nrm, sphere.idx
        sphere = bare
    mesh_i = g.mesh("sphere", [(sphere, mi)])
    if needs_tangents:
        g.doc["meshes"][mesh_i]["primitives"][0]["attributes"]["TANGENT"] = g.accessor(
            [gw.f32(t) for t in tangents], gw.FLOAT, "VEC4", gw.ARRAY_BUFFER)
    nodes = [g.node("sphere", mesh=mesh_i)]
    cam = g.camera("camera", YFOV, width / height, 0.05, 100.0)
    nodes.append(g.node("camera", camera=cam, translation=(0.0, 0.0, CAM_DIST)))  # looks at -Z
    if lighting == "area":
        lambert = {"KHR_materials_specular": {"specularFactor": 0.0}}
        floor_m = g.material("floor", (FLOOR_GREY,) * 3, 0.0, 1.0)
        g.doc["materials"][floor_m]["extensions"] = dict(lambert)
        lamp_m = g.material("lamp", (0.0, 0.0, 0.0), 0.0, 1.0, emissive=(1.0, 1.0, 1.0),
                            strength=LAMP_STRENGTH, double_sided=True)
        g.doc["materials"][lamp_m]["extensions"]["KHR_materials_specular"] = {"specularFactor": 0.0}
        g.extensions.add("KHR_materials_specular")
        floor = gw.quad((-15.0, FLOOR_Y, 15.0), (30.0, 0.0, 0.0), (0.0, 0.0, -30.0))
        nodes.append(g.node("floor", mesh=g.mesh("floor", [(floor, floor_m)])))
        n = gw.normalize(tuple(-c for c in LAMP_CENTRE))  # faces the sphere
        eu = gw.normalize(gw.cross((0.0, 1.0, 0.0), n))
        ev = gw.cross(n, eu)
        h = LAMP_SIZE / 2
        origin = tuple(LAMP_CENTRE[k] - h * (eu[k] + ev[k]) for k in range(3))
        lamp = gw.quad(origin, tuple(LAMP_SIZE * c for c in eu), tuple(LAMP_SIZE * c for c in ev))
        nodes.append(g.node("lamp", mesh=g.mesh("lamp", [(lamp, lamp_m)])))
    write_if_changed(g, nodes, path)


def write_if_changed(g, nodes, path):
    """Writes the scene (.gltf and .bin) only where its bytes changed, validating it then: an
    unchanged scene keeps its files (and so its cached renders) and costs no validation."""
    with tempfile.TemporaryDirectory(dir=path.parent) as tmp:
        new = Path(tmp) / path.name
        g.write(str(new), nodes, embedded=False)
        pairs = [(new, path), (new.with_suffix(".bin"), path.with_suffix(".bin"))]
        if all(b.is_file() and a.read_bytes() == b.read_bytes() for a, b in pairs):
            return
        gw.validate(str(new))
        for a, b in pairs[::-1]:  # the .gltf last: it names the .bin
            os.replace(a, b)


def sphere_geometry(width, height):
    """From the camera and the analytic sphere: the mask of pixels whose whole square lies on
    the sphere (all four corners hit a sphere shrunk by 0.1%: the tessellation lies within
    0.03% of the radius), the pixel-centre hit mask, and n.v at the pixel centres."""
    t = math.tan(YFOV / 2)
    aspect = width / height

    def hits(xs, ys, radius):
        px, py = np.meshgrid(xs, ys)
        d = np.stack([(2 * px / width - 1) * t * aspect, (1 - 2 * py / height) * t,
                      -np.ones_like(px)], axis=-1)
        d /= np.linalg.norm(d, axis=-1, keepdims=True)
        b = CAM_DIST * d[..., 2]  # o.d with o = (0, 0, CAM_DIST)
        disc = b * b - (CAM_DIST ** 2 - radius ** 2)
        return d, b, disc
    _, _, disc = hits(np.arange(width + 1.0), np.arange(height + 1.0), RADIUS * 0.999)
    c = disc > 0
    full = c[:-1, :-1] & c[1:, :-1] & c[:-1, 1:] & c[1:, 1:]
    d, b, disc = hits(np.arange(width) + 0.5, np.arange(height) + 0.5, RADIUS)
    centre = disc > 0
    tt = -b - np.sqrt(np.maximum(disc, 0.0))
    p = np.array([0.0, 0.0, CAM_DIST]) + tt[..., None] * d
    nv = np.where(centre, np.sum(-d * p / RADIUS, axis=-1), 0.0)
    return full, centre, np.clip(nv, 0.0, 1.0)


# ---------------------------------------------------------------- the Blender side

# Runs in the venv's Python with bpy: renders each job of a JSON list with Cycles, writes
# the EXR, a ray-cast hit map through the imported camera and the job's metadata (the
# importer's Principled inputs per material, the settings as Blender read them back).
BLENDER_SCRIPT = r'''
import json, os, sys, time
import bpy
import numpy as np


def value(v):
    if isinstance(v, (bool, int, str)):
        return v
    try:
        return [round(float(x), 6) for x in v]
    except TypeError:
        return round(float(v), 6)


def principled_log():
    out = {}
    for mat in bpy.data.materials:
        if mat.node_tree is None:
            continue
        for node in mat.node_tree.nodes:
            if node.type != "BSDF_PRINCIPLED":
                continue
            ins = {}
            for s in node.inputs:
                if not s.enabled:  # e.g. the hidden closure "Weight"
                    continue
                if s.is_linked:
                    ln = s.links[0]
                    ins[s.name] = "linked from %s.%s" % (ln.from_node.bl_idname, ln.from_socket.name)
                elif hasattr(s, "default_value"):
                    ins[s.name] = value(s.default_value)
            out[mat.name] = {"distribution": node.distribution,
                             "subsurface_method": node.subsurface_method, "inputs": ins,
                             "nodes": sorted(n.bl_idname for n in mat.node_tree.nodes)}
    return out


def raycast(scene, w, h, path):
    """Per pixel centre: the glTF-space hit point (Blender z-up -> glTF y-up) and the hit
    object's number (0: none), float32 [h, w, 4], rows from the top."""
    cam = scene.camera
    dg = bpy.context.evaluated_depsgraph_get()
    tr, br, bl, tl = cam.data.view_frame(scene=scene)
    rot = cam.matrix_world.to_3x3()
    org = cam.matrix_world.translation
    out = np.zeros((h, w, 4), np.float32)
    names = {}
    for j in range(h):
        for i in range(w):
            p = tl + (tr - tl) * ((i + 0.5) / w) + (bl - tl) * ((j + 0.5) / h)
            hit, loc, _, _, ob, _ = scene.ray_cast(dg, org, (rot @ p).normalized())
            if hit:
                k = names.setdefault(ob.name, len(names) + 1)
                out[j, i] = (loc.x, loc.z, -loc.y, k)
    out.tofile(path)
    return {str(k): n for n, k in names.items()}


def render(job):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.import_scene.gltf(filepath=job["scene"])
    scene = bpy.context.scene
    world = bpy.data.worlds.new("blender_compare")
    if world.node_tree is None:
        world.use_nodes = True
    bg = next(n for n in world.node_tree.nodes if n.type == "BACKGROUND")
    bg.inputs["Color"].default_value = list(job["world"]) + [1.0]
    bg.inputs["Strength"].default_value = 1.0 if max(job["world"]) > 0 else 0.0
    scene.world = world
    with open(job["scene"], encoding="utf-8") as f:
        cams = json.load(f).get("cameras", [])
    want = cams[0].get("name") if cams else None
    objs = [o for o in scene.objects if o.type == "CAMERA"]
    scene.camera = next((o for o in objs if o.data.name == want), objs[0])
    scene.frame_set(0)  # the importer keys glTF time t at frame t * fps

    r = scene.render
    r.engine = "CYCLES"
    c = scene.cycles
    c.device = "CPU"
    c.samples = job["spp"]
    c.use_adaptive_sampling = False
    c.use_denoising = False
    c.use_guiding = False
    c.seed = job["seed"]
    c.use_animated_seed = False
    b = job["bounces"]
    c.max_bounces = c.diffuse_bounces = c.glossy_bounces = c.transmission_bounces = b
    c.transparent_max_bounces = b
    c.volume_bounces = 0
    c.min_light_bounces = c.min_transparent_bounces = 0
    c.sample_clamp_direct = c.sample_clamp_indirect = 0.0
    c.caustics_reflective = c.caustics_refractive = True
    c.blur_glossy = 0.0
    c.use_light_tree = True
    c.light_sampling_threshold = 0.0
    c.pixel_filter_type = "BOX"
    c.filter_width = 1.0
    r.threads_mode = "FIXED"
    r.threads = job["threads"]
    r.resolution_x, r.resolution_y = job["width"], job["height"]
    r.resolution_percentage = 100
    r.film_transparent = False
    v = scene.view_settings
    v.view_transform = "Standard"
    v.look = "None"
    v.exposure = 0.0
    v.gamma = 1.0
    img = r.image_settings
    img.file_format = "OPEN_EXR"
    img.color_mode = "RGB"
    img.color_depth = "32"
    img.exr_codec = "ZIP"
    r.filepath = job["out"]
    meta = {"blender": bpy.app.version_string, "principled": principled_log(),
            "camera": {"name": scene.camera.data.name, "angle_y": scene.camera.data.angle_y,
                       "sensor_fit": scene.camera.data.sensor_fit},
            "cycles": {k: value(getattr(c, k)) for k in (
                "samples", "max_bounces", "diffuse_bounces", "glossy_bounces",
                "transmission_bounces", "use_light_tree", "light_sampling_threshold",
                "pixel_filter_type", "filter_width", "blur_glossy", "seed",
                "sample_clamp_direct", "sample_clamp_indirect", "use_adaptive_sampling",
                "use_denoising", "use_guiding", "direct_light_sampling_type")},
            "view_transform": v.view_transform,
            "world": {"color": value(bg.inputs["Color"].default_value),
                      "strength": value(bg.inputs["Strength"].default_value)}}
    t0 = time.perf_counter()
    bpy.ops.render.render(write_still=True)
    meta["render_s"] = time.perf_counter() - t0
    if job.get("hits"):
        t1 = time.perf_counter()
        meta["hit_objects"] = raycast(scene, job["width"], job["height"], job["hits"])
        meta["raycast_s"] = time.perf_counter() - t1
    tmp = job["meta"] + ".tmp"
    with open(tmp, "w") as f:
        json.dump(meta, f, indent=1)
    os.replace(tmp, job["meta"])  # the cache entry counts once this exists
    return meta


jobs = json.load(open(sys.argv[1]))
for n, job in enumerate(jobs):
    meta = render(job)
    print("[cycles] %d/%d %s: %.1f s" % (n + 1, len(jobs), job["label"], meta["render_s"]),
          flush=True)
'''

EXR_TO_RAW = r'''
import sys
import bpy
import numpy as np
for src, dst in zip(sys.argv[1::2], sys.argv[2::2]):
    im = bpy.data.images.load(src)
    w, h = im.size
    px = np.empty(w * h * 4, np.float32)
    im.pixels.foreach_get(px)
    rgb = px.reshape(h, w, 4)[::-1, :, :3]  # Blender's rows run from the bottom
    with open(dst, "wb") as f:
        np.array([w, h], "<u4").tofile(f)
        np.ascontiguousarray(rgb, "<f4").tofile(f)
    bpy.data.images.remove(im)
'''


# ---------------------------------------------------------------- renders and caching

def digest(*parts):
    h = hashlib.sha256()
    for p in parts:
        h.update(p if isinstance(p, bytes) else json.dumps(p, sort_keys=True).encode())
        h.update(b"\0")
    return h.hexdigest()[:20]


def scene_bytes(path):
    """A .gltf and the files its buffers and images name."""
    path = Path(path)
    data = [path.read_bytes()]
    doc = json.loads(data[0])
    for item in doc.get("buffers", []) + doc.get("images", []):
        uri = item.get("uri", "")
        if uri and not uri.startswith("data:"):
            data.append((path.parent / uri).read_bytes())
    return b"".join(hashlib.sha256(d).digest() for d in data)


def code_fingerprint(binary):
    """The renderer as it renders: its binary (kernels are built into it) and any kernel
    folder that PATHREUSE_KERNEL_DIR substitutes."""
    h = hashlib.sha256(Path(binary).read_bytes())
    kdir = os.environ.get("PATHREUSE_KERNEL_DIR")
    if kdir:
        for p in sorted(Path(kdir).rglob("*")):
            if p.is_file():
                h.update(str(p.relative_to(kdir)).encode() + p.read_bytes())
    return h.hexdigest()[:16]


class Job:
    """One comparison: a scene, rendered by both, and what to compare."""

    def __init__(self, label, scene, material, lighting, width, height):
        self.label, self.scene, self.material, self.lighting = label, Path(scene), material, lighting
        self.width, self.height = width, height


def read_raw(path):
    with open(path, "rb") as f:
        w, h = np.fromfile(f, "<u4", 2)
        return np.fromfile(f, "<f4").reshape(int(h), int(w), 3).astype(np.float64)


class Images:
    """Reads EXRs to float arrays: exr_compare --raw beside the binary, else bpy."""

    def __init__(self, binary, venv_python):
        self.tool = Path(binary).parent / "exr_compare"
        self.venv_python = venv_python

    def read(self, exr):
        with tempfile.TemporaryDirectory() as tmp:
            raw = Path(tmp) / "img.raw"
            if self.tool.is_file():
                subprocess.run([str(self.tool), "--raw", str(exr), str(raw)], check=True)
            else:
                script = Path(tmp) / "exr_to_raw.py"
                script.write_text(EXR_TO_RAW)
                subprocess.run([self.venv_python(), str(script), str(exr), str(raw)], check=True,
                               capture_output=True)
            return read_raw(raw)


def run_cycles(jobs, args, cache, venv_python, log):
    """Renders every job not in the cache, in one Blender process, one at a time. Returns
    {label: (exr, meta)}."""
    out, todo = {}, []
    for j in jobs:
        # threads are left out of the key: Cycles' image does not depend on them
        key = digest(CYCLES_SETUP, BPY_VERSION, scene_bytes(j.scene), j.cycles_settings)
        exr, meta, hits = (cache / "cycles" / f"{key}{s}" for s in (".exr", ".json", ".hits"))
        out[j.label] = (exr, meta, hits)
        if not (exr.is_file() and meta.is_file() and hits.is_file()):
            todo.append(dict(j.cycles_settings, label=j.label, scene=str(j.scene), out=str(exr),
                             meta=str(meta), hits=str(hits), threads=args.threads))
    if todo:
        (cache / "cycles").mkdir(parents=True, exist_ok=True)
        py = venv_python()
        print(f"blender_compare: Cycles renders {len(todo)} scene(s) ({len(jobs) - len(todo)} "
              f"cached), {args.threads} threads ...", flush=True)
        with tempfile.TemporaryDirectory() as tmp:
            script, jobs_file = Path(tmp) / "cycles_side.py", Path(tmp) / "jobs.json"
            script.write_text(BLENDER_SCRIPT)
            jobs_file.write_text(json.dumps(todo))
            with open(log, "a") as lf:
                p = subprocess.Popen([py, str(script), str(jobs_file)], stdout=subprocess.PIPE,
                                     stderr=subprocess.STDOUT, text=True)
                for line in p.stdout:
                    lf.write(line)
                    if line.startswith("[cycles]"):
                        print(line.rstrip(), flush=True)
                rc = p.wait()
        missing = [t["label"] for t in todo if not Path(t["meta"]).is_file()]
        if rc or missing:
            sys.exit(f"blender_compare: Blender failed (exit {rc}; {len(missing)} render(s) "
                     f"missing); see {log}")
    return {k: (exr, json.loads(meta.read_text()), hits) for k, (exr, meta, hits) in out.items()}


def run_ours(jobs, args, cache, fingerprint, seed_offset=0):
    """Renders each job with pathreuse, unless cached (and not --rerender-ours). Returns
    {label: (exr, wall seconds of the render or None when cached)}."""
    out = {}
    ours_args = shlex.split(args.ours_args)
    (cache / "ours").mkdir(parents=True, exist_ok=True)
    done = 0
    for j in jobs:
        settings = dict(j.ours_settings, seed=args.seed + seed_offset, extra=ours_args)
        key = digest("ours", scene_bytes(j.scene), settings, fingerprint)
        exr = cache / "ours" / f"{key}.exr"
        if exr.is_file() and not args.rerender_ours:
            out[j.label] = (exr, None)
            continue
        with tempfile.TemporaryDirectory(dir=cache / "ours") as tmp:
            cmd = ([str(args.binary), "render", str(j.scene), "--mode", "pathtrace",
                    "--frames", "0", "--exr-float", "--quiet",
                    "--width", str(j.width), "--height", str(j.height),
                    "--spp", str(settings["spp"]), "--seed", str(settings["seed"]),
                    "--max-depth", str(settings["max_depth"]),
                    "--out", str(Path(tmp) / "frame_%04d.exr")] + settings["env"] + ours_args)
            env = dict(os.environ, POCL_MAX_PTHREAD_COUNT=str(args.threads))
            t0 = time.perf_counter()
            run = subprocess.run(cmd, env=env, capture_output=True, text=True)
            took = time.perf_counter() - t0
            if run.returncode:
                sys.exit(f"blender_compare: pathreuse failed on {j.label}: "
                         f"{run.stderr.strip()[-600:]}\n  {shlex.join(cmd)}")
            os.replace(Path(tmp) / "frame_0000.exr", exr)
        done += 1
        print(f"[ours] {done} {j.label}{' (seed +%d)' % seed_offset if seed_offset else ''}: "
              f"{took:.1f} s", flush=True)
        out[j.label] = (exr, took)
    return out


# ---------------------------------------------------------------- comparison

LUMA = np.array([0.2126, 0.7152, 0.0722])


def ratio(a, b):
    return float(a / b) if b > 0 else float("nan")


def compare(ours, cyc, mask, block):
    """Mean luminance and channel ratios over the mask; |ratio - 1| over the blocks wholly
    inside it (ratio of block means of luminance): its 95th percentile and maximum."""
    yo, yc = ours @ LUMA, cyc @ LUMA
    h, w = mask.shape
    hb, wb = h // block, w // block

    def blocks(a):
        return a[:hb * block, :wb * block].reshape(hb, block, wb, block).sum(axis=(1, 3))
    inside = blocks(mask.astype(np.float64)) == block * block
    bo, bc = blocks(yo)[inside], blocks(yc)[inside]
    dev = np.abs(bo / np.where(bc > 0, bc, np.nan) - 1)
    dev = dev[np.isfinite(dev)]
    so, sc = ours[mask].sum(axis=0), cyc[mask].sum(axis=0)
    return {"pixels": int(mask.sum()), "mean_ours": float(yo[mask].mean()),
            "mean_cycles": float(yc[mask].mean()), "mean_ratio": ratio(yo[mask].sum(), yc[mask].sum()),
            "rgb_ratio": [ratio(so[c], sc[c]) for c in range(3)], "blocks": int(dev.size),
            "p95_block": float(np.percentile(dev, 95)) if dev.size else float("nan"),
            "max_block": float(dev.max()) if dev.size else float("nan")}


BANDS = [(k / 10, (k + 1) / 10) for k in range(10)]


def bands(ours, cyc, mask, nv):
    yo, yc = ours @ LUMA, cyc @ LUMA
    out = []
    for lo, hi in BANDS:
        sel = mask & (nv >= lo) & (nv < hi if hi < 1 else nv <= hi)
        n = int(sel.sum())
        out.append({"nv": [lo, hi], "pixels": n,
                    "ours": float(yo[sel].mean()) if n else None,
                    "cycles": float(yc[sel].mean()) if n else None})
    return out


def ratio_png(path, ours, cyc, mask, span=0.1, outline=None):
    """ours / Cycles luminance: grey at 1, blue darker, red brighter, saturating at +-span;
    outside the mask dim grey; outline (a mask) drawn green."""
    yo, yc = ours @ LUMA, cyc @ LUMA
    r = np.where(yc > 0, yo / np.where(yc > 0, yc, 1), 1.0) - 1
    s = np.clip(r / span, -1, 1)
    rgb = np.empty(mask.shape + (3,))
    rgb[..., 0] = 0.5 + 0.5 * s
    rgb[..., 1] = 0.5 - 0.5 * np.abs(s)
    rgb[..., 2] = 0.5 - 0.5 * s
    rgb[~mask] = 0.15
    if outline is not None:
        edge = outline & ~(np.roll(outline, 1, 0) & np.roll(outline, -1, 0)
                           & np.roll(outline, 1, 1) & np.roll(outline, -1, 1))
        rgb[edge] = (0.1, 0.9, 0.1)
    px = (np.clip(rgb, 0, 1) * 255 + 0.5).astype(np.uint8)
    path.write_bytes(gw.png_rgb(px.shape[1], px.shape[0], lambda x, y: px[y, x].tolist()))


def srgb_png(path, img, scale):
    """The image times scale, sRGB-encoded, for looking at."""
    x = np.clip(img * scale, 0, 1)
    x = np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1 / 2.4) - 0.055)
    px = (x * 255 + 0.5).astype(np.uint8)
    path.write_bytes(gw.png_rgb(px.shape[1], px.shape[0], lambda c, r: px[r, c].tolist()))


# ---------------------------------------------------------------- the two cases

def sphere_jobs(args, work):
    names = select_materials(args.materials)
    lightings = [s.strip() for s in args.lighting.split(",") if s.strip()]
    for lt in lightings:
        if lt not in ("furnace", "area"):
            sys.exit(f"blender_compare: unknown lighting {lt!r} (furnace, area)")
    mesh = sphere_mesh()
    w, h = args.width or 200, args.height or 200
    jobs = []
    for lt in lightings:
        (work / "scenes" / lt).mkdir(parents=True, exist_ok=True)
        for name in names:
            path = work / "scenes" / lt / f"{name}.gltf"
            write_sphere_scene(path, name, lt, w, h, mesh)
            j = Job(f"{name} / {lt}", path, name, lt, w, h)
            world = [1.0, 1.0, 1.0] if lt == "furnace" else [0.0, 0.0, 0.0]
            j.cycles_settings = {"width": w, "height": h, "spp": args.spp, "seed": args.seed,
                                 "bounces": 62, "world": world}
            j.ours_settings = {"width": w, "height": h, "spp": args.ours_spp or args.spp,
                               "max_depth": 64,
                               "env": ["--env-color", "1,1,1"] if lt == "furnace" else ["--env", "none"]}
            jobs.append(j)
    return jobs


def column_jobs(args, work):
    size = args.atrium_size
    path = Path(args.atrium) if args.atrium else work / f"atrium-size{size:g}" / "atrium.gltf"
    if not path.is_file():
        print(f"blender_compare: generating {path} ...", flush=True)
        run_tool("tools.scenes.gen_atrium", ["--size", f"{size:g}", "--out", path], check=True)
    cams = json.loads(path.read_text()).get("cameras", [])
    aspect = cams[0]["perspective"].get("aspectRatio", 16 / 9) if cams else 16 / 9
    h = args.height or 180
    w = args.width or int(round(h * aspect))
    j = Job("atrium column / direct", path, "atrium", "direct", w, h)
    j.cycles_settings = {"width": w, "height": h, "spp": args.spp, "seed": args.seed,
                         "bounces": 0, "world": [0.0, 0.0, 0.0]}
    j.ours_settings = {"width": w, "height": h, "spp": args.ours_spp or args.spp, "max_depth": 2,
                       "env": ["--env", "none"]}
    return [j]


def column_region(hits, names):
    """The shaft (its base and capital left out) of the column covering most pixels, from
    the ray-cast hit points, less a one-pixel border (pixels straddling its silhouette)."""
    from ..scenes import gen_atrium as ga
    atrium = [int(k) for k, n in names.items() if n.split(".")[0] == "atrium"]
    on = np.isin(hits[..., 3], atrium)
    x, y, z = hits[..., 0], hits[..., 1], hits[..., 2]
    best = None
    for level, (floor_y, col_top, _) in enumerate(ga.STOREYS):
        for cx, cz in ga.column_positions():
            sel = (on & (np.hypot(x - cx, z - cz) < ga.COL_R * 1.35)
                   & (y > floor_y + ga.PLINTH_H + 0.25) & (y < col_top - 0.35))
            if best is None or sel.sum() > best[0].sum():
                best = (sel, {"storey": level, "x": cx, "z": cz})
    sel, where = best
    core = sel.copy()
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            core &= np.roll(np.roll(sel, dy, 0), dx, 1)
    core[0, :] = core[-1, :] = core[:, 0] = core[:, -1] = False
    return core, where


def profile(ours, cyc, region, min_pixels=8):
    """Per image column x: ratio of the luminance summed over the region's pixels there."""
    yo, yc = (ours @ LUMA) * region, (cyc @ LUMA) * region
    n = region.sum(axis=0)
    xs = [x for x in range(region.shape[1]) if n[x] >= min_pixels and yc[:, x].sum() > 0]
    return [(x, int(n[x]), float(yo[:, x].sum() / yc[:, x].sum())) for x in xs]


# ---------------------------------------------------------------- report

def finite(o):
    """NaN (no blocks, a black channel) as null, so that the JSON is strict."""
    if isinstance(o, float):
        return o if math.isfinite(o) else None
    if isinstance(o, dict):
        return {k: finite(v) for k, v in o.items()}
    if isinstance(o, (list, tuple)):
        return [finite(v) for v in o]
    return o


def fmt(x, f="{:.3f}"):
    return "n/a" if x is None or (isinstance(x, float) and math.isnan(x)) else f.format(x)


def main():
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--case", choices=("spheres", "column"), default="spheres")
    ap.add_argument("--materials", default="*", help="names, globs or classes, comma-separated "
                    "(default every one; --list shows them)")
    ap.add_argument("--lighting", default="furnace,area", help="furnace, area or both")
    ap.add_argument("--list", action="store_true", help="list the materials and exit")
    ap.add_argument("--spp", type=int, default=1024, help="samples per pixel (default 1024)")
    ap.add_argument("--ours-spp", type=int, help="ours only, if fewer suffice (default --spp)")
    ap.add_argument("--width", type=int, help="default 200 (spheres) or the camera's aspect at "
                    "--height (column)")
    ap.add_argument("--height", type=int, help="default 200 (spheres) or 180 (column)")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--threads", type=int, default=2, help="for Cycles and PoCL (default 2)")
    ap.add_argument("--binary", default=str(REPO / "build" / "pathreuse"))
    ap.add_argument("--ours-args", default="", help="more options for ours, written with '=' "
                    "since they start with --: --ours-args='--material-model gltf-reference', "
                    "--ours-args=--force-diffuse")
    ap.add_argument("--rerender-ours", action="store_true",
                    help="render ours again even when cached")
    ap.add_argument("--noise", action="store_true", help="also render ours with --seed + 1 "
                    "and give the same figures between the two seeds (the noise floor)")
    ap.add_argument("--tolerance", type=float, default=0.02, help="pass threshold (default 0.02)")
    ap.add_argument("--block", type=int, default=16, help="block size in pixels (default 16)")
    ap.add_argument("--atrium-size", type=float, default=1.0, help="gen_atrium.py --size")
    ap.add_argument("--atrium", help="an atrium .gltf to use (made by gen_atrium.py at "
                    "--atrium-size when absent; default one in --work)")
    ap.add_argument("--python", help="Python 3.13 for Blender's environment")
    ap.add_argument("--work", default="/tmp/pathreuse-blender-compare",
                    help="scenes, logs and ratio maps (default %(default)s)")
    ap.add_argument("--cache", default=str(Path.home() / ".cache" / "pathreuse" / "blender-compare"),
                    help="renders (default %(default)s)")
    ap.add_argument("--json", help="write the results here")
    ap.add_argument("--strict", action="store_true", help="exit 1 when a row fails")
    args = ap.parse_args()

    if args.list:
        for n, (cls, mat, _) in MATERIALS.items():
            print(f"{n:30s} {cls:10s} {json.dumps(mat, separators=(',', ':'))}")
        return 0
    args.binary = Path(args.binary).resolve()
    if not args.binary.is_file():
        sys.exit(f"blender_compare: no renderer at {args.binary} (--binary)")
    work, cache = Path(args.work), Path(args.cache)
    (work / "maps").mkdir(parents=True, exist_ok=True)
    log = work / "blender.log"
    venv = {}

    def venv_python():
        if "py" not in venv:
            venv["py"] = ensure_venv(args.python)
        return venv["py"]

    start = time.perf_counter()
    jobs = sphere_jobs(args, work) if args.case == "spheres" else column_jobs(args, work)
    cycles = run_cycles(jobs, args, cache, venv_python, log)
    fingerprint = code_fingerprint(args.binary)
    ours = run_ours(jobs, args, cache, fingerprint)
    ours2 = run_ours(jobs, args, cache, fingerprint, seed_offset=1) if args.noise else {}
    images = Images(args.binary, venv_python)

    rows = []
    geo = {}
    for j in jobs:
        c_exr, meta, hits_path = cycles[j.label]
        cyc = images.read(c_exr)
        our = images.read(ours[j.label][0])
        hits = np.fromfile(hits_path, np.float32).reshape(j.height, j.width, 4)
        row = {"material": j.material, "lighting": j.lighting, "ours_s": ours[j.label][1],
               "cycles_s": meta["render_s"], "principled": meta["principled"].get(j.material),
               "cycles_settings": meta["cycles"], "blender": meta["blender"]}
        slug = j.label.replace(" / ", "-").replace(" ", "_")
        if args.case == "spheres":
            if (j.width, j.height) not in geo:
                geo[(j.width, j.height)] = sphere_geometry(j.width, j.height)
            mask, centre, nv = geo[(j.width, j.height)]
            sphere_ids = [int(k) for k, n in meta["hit_objects"].items() if n.split(".")[0] == "sphere"]
            blender_centre = np.isin(hits[..., 3], sphere_ids)
            row["mask_mismatch"] = int((blender_centre != centre).sum())  # silhouette pixels only
            row["importer_mismatch"] = importer_mismatches(j.material, row["principled"])
            row.update(compare(our, cyc, mask, args.block))
            if j.lighting == "furnace":
                row["bands"] = bands(our, cyc, mask, nv)
            ratio_png(work / "maps" / f"{slug}.png", our, cyc, mask)
        else:
            region, where = column_region(hits, meta["hit_objects"])
            row["column"] = where
            row.update(compare(our, cyc, region, args.block))
            prof = profile(our, cyc, region)
            row["profile"] = prof
            lit = (cyc @ LUMA) > 0
            row["image_mean_ratio"] = ratio((our @ LUMA)[lit].sum(), (cyc @ LUMA)[lit].sum())
            ratio_png(work / "maps" / f"{slug}.png", our, cyc, lit, outline=region)
            scale = 0.5 / max(float(np.percentile(cyc @ LUMA, 90)), 1e-6)
            srgb_png(work / "maps" / f"{slug}-ours.png", our, scale)
            srgb_png(work / "maps" / f"{slug}-cycles.png", cyc, scale)
        if args.noise:
            o2 = images.read(ours2[j.label][0])
            m = mask if args.case == "spheres" else region
            n = compare(our, o2, m, args.block)
            row["noise"] = {"mean_ratio": n["mean_ratio"], "p95_block": n["p95_block"]}
        tol = args.tolerance
        row["pass"] = bool(abs(row["mean_ratio"] - 1) <= tol and row["p95_block"] <= tol)
        rows.append(row)

    # ---- tables
    settings = {"case": args.case, "spp_cycles": args.spp, "spp_ours": args.ours_spp or args.spp,
                "width": jobs[0].width, "height": jobs[0].height, "seed": args.seed,
                "threads": args.threads, "binary": str(args.binary), "ours_args": args.ours_args,
                "fingerprint": fingerprint, "tolerance": args.tolerance, "block": args.block,
                "blender": rows[0]["blender"] if rows else None}
    print()
    print(f"ours ({args.binary.name} {args.ours_args}".rstrip() + f") vs Cycles {settings['blender']}: "
          f"{settings['width']}x{settings['height']}, {settings['spp_ours']} / {args.spp} spp, "
          f"ratio = ours / Cycles of mean luminance, p95 = 95th percentile over {args.block}x"
          f"{args.block} blocks of |ratio - 1|")
    print()
    noise_h = " noise mean | noise p95 |" if args.noise else ""
    print(f"| material | lighting | ratio | R | G | B | p95 | blocks | ours | Cycles |{noise_h} pass |")
    print("| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |"
          + (" ---: | ---: |" if args.noise else "") + " --- |")
    for r in rows:
        noise = (f" {fmt(r['noise']['mean_ratio'], '{:.4f}')} | {fmt(r['noise']['p95_block'], '{:.4f}')} |"
                 if args.noise else "")
        print(f"| {r['material']} | {r['lighting']} | {fmt(r['mean_ratio'], '{:.4f}')} | "
              + " | ".join(fmt(x) for x in r["rgb_ratio"])
              + f" | {fmt(r['p95_block'], '{:.4f}')} | {r['blocks']} | {fmt(r['mean_ours'])} | "
              f"{fmt(r['mean_cycles'])} |{noise} {'yes' if r['pass'] else 'NO'} |")
    banded = [r for r in rows if r.get("bands")]
    if banded:
        print()
        print("Furnace, mean radiance (= directional albedo) per band of n.v, ours / Cycles:")
        print()
        print("| material | " + " | ".join(f"{lo:.1f}-{hi:.1f}" for lo, hi in BANDS) + " |")
        print("| --- |" + " ---: |" * len(BANDS))
        for r in banded:
            print(f"| {r['material']} | " + " | ".join(
                f"{fmt(b['ours'])}/{fmt(b['cycles'])}" if b["pixels"] else "-" for b in r["bands"]) + " |")
    for r in rows:
        if "profile" in r:
            p = r["profile"]
            lo = min(p, key=lambda t: t[2]) if p else None
            hi = max(p, key=lambda t: t[2]) if p else None
            print()
            print(f"column: storey {r['column']['storey']} at x={r['column']['x']:g}, "
                  f"z={r['column']['z']:g}; {r['pixels']} pixels; across it (per image column "
                  f"of >= 8 region pixels) the ratio runs from {fmt(lo and lo[2])} (x={lo and lo[0]}) "
                  f"to {fmt(hi and hi[2])} (x={hi and hi[0]}); whole lit image "
                  f"{fmt(r['image_mean_ratio'], '{:.4f}')}")
            print("profile x:ratio " + " ".join(f"{x}:{q:.3f}" for x, _, q in p))
    odd = {r["material"]: r["importer_mismatch"] for r in rows if r.get("importer_mismatch")}
    if odd:
        print()
        print("Blender's importer set other Principled inputs than expected:")
        for name, bad in odd.items():
            print(f"  {name}: " + "; ".join(bad))
    mism = [r["mask_mismatch"] for r in rows if "mask_mismatch" in r]
    passed = sum(r["pass"] for r in rows)
    took = time.perf_counter() - start
    ours_s = [r["ours_s"] for r in rows if r["ours_s"] is not None]
    print()
    print(f"{passed} of {len(rows)} within {args.tolerance:.0%}; renders: ours {len(ours_s)} new "
          f"({sum(ours_s):.0f} s), Cycles {sum(r['cycles_s'] for r in rows):.0f} s in all (cached "
          f"or new); {took:.0f} s this run"
          + (f"; mask vs Blender's ray cast: at most {max(mism)} pixel centres differ" if mism else "")
          + f"; ratio maps in {work / 'maps'}")
    if args.json:
        Path(args.json).write_text(json.dumps(finite({"settings": settings, "rows": rows}),
                                              indent=1, allow_nan=False))
    return 1 if args.strict and passed < len(rows) else 0


if __name__ == "__main__":
    sys.exit(main())
