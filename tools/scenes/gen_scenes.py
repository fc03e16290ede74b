"""Generates the committed demo scenes scenes/cornell-dynamic.gltf, scenes/cornell-orbit.gltf
and scenes/cornell-skinned.gltf (a skinned tentacle swaying and a morphing ball in the box),
validates them, and with --check tells whether the committed copies are stale.

  python3 -m tools.scenes.gen_scenes                 # writes scenes/*.gltf
  python3 -m tools.scenes.gen_scenes --check scenes/ # exit 1 if the committed files differ
  python3 -m tools.scenes.gen_scenes --skinned-only --tentacle 200x128 --out /tmp/big
                                              # the skinned scene alone, a 51k-triangle tentacle
"""

import argparse
import math
import os
import sys
import tempfile

from . import gltf_writer as gw

DURATION = 5.0
KEY_STEP = 0.25
CENTRE = (0.0, 1.0, 0.0)          # centre of the box's interior
EYE_DISTANCE = 3.9                 # camera distance from CENTRE, in front of the opening
ORBIT_DEG = 25.0                   # orbit half-angle about the vertical axis through CENTRE
WALL = 0.04                        # wall thickness: walls are slabs so they look solid
LIGHT_Y, LIGHT_W, LIGHT_D, LIGHT_STRENGTH = 1.98, 0.5, 0.4, 17.0
SPHERE_R, SPHERE_SEG, SPHERE_RINGS = 0.25, 32, 16
SHORT_BOX = dict(size=(0.6, 0.6, 0.6), at=(0.36, 0.0, 0.3), yaw=-17.0)
TALL_BOX = dict(size=(0.6, 1.2, 0.6), at=(-0.34, 0.0, -0.4), yaw=17.0)
# asset.generator keeps the script's old path (before tools/ had folders): the committed
# scenes and the caches keyed by a scene's bytes stay valid.
GENERATOR = "pathreuse tools/gen_scenes.py"
SCENES = ("cornell-dynamic.gltf", "cornell-orbit.gltf", "cornell-skinned.gltf")
# The skinned scene: a tentacle of JOINTS joints swaying from the floor, and a ball morphing
# between a squashed and a spiky shape on the short block.
TENTACLE_AT, TENTACLE_H, TENTACLE_R, JOINTS = (-0.42, 0.0, 0.35), 1.3, 0.1, 6
TENTACLE_RINGS, TENTACLE_SEG = 32, 16
BLOB_AT, BLOB_R = (0.36, 0.85, 0.3), 0.22


def key_times():
    n = int(round(DURATION / KEY_STEP))
    return [gw.f32(DURATION * k / n) for k in range(n + 1)]


def sphere_centre(t):
    """Figure-eight at mid-height in the front half of the box, through the light's
    beam, period DURATION (the path loops)."""
    w = 2 * math.pi * t / DURATION
    return (0.55 * math.sin(w), 1.0 + 0.12 * math.cos(w), 0.45 + 0.2 * math.sin(2 * w))


def sphere_rotation(t):
    return gw.quat_axis_angle((0.3, 1.0, 0.2), 2 * math.pi * t / DURATION)


def orbit_pose(t):
    a = math.radians(ORBIT_DEG) * math.sin(2 * math.pi * t / DURATION)
    pos = (CENTRE[0] + EYE_DISTANCE * math.sin(a), CENTRE[1],
           CENTRE[2] + EYE_DISTANCE * math.cos(a))
    return pos, gw.quat_axis_angle((0, 1, 0), a)


def box_distance(p, spec):
    """Distance from p to a (yawed) box given as in SHORT_BOX."""
    sx, sy, sz = spec["size"]
    ax, ay, az = spec["at"]
    a = -math.radians(spec["yaw"])
    dx, dz = p[0] - ax, p[2] - az
    lx = math.cos(a) * dx + math.sin(a) * dz     # rotate into the box frame
    lz = -math.sin(a) * dx + math.cos(a) * dz
    ly = p[1] - (ay + sy / 2)
    q = [max(abs(lx) - sx / 2, 0), max(abs(ly) - sy / 2, 0), max(abs(lz) - sz / 2, 0)]
    return math.sqrt(sum(c * c for c in q))


def check_clearance(times):
    """The keyed (linearly interpolated) sphere path stays inside the box and off the
    blocks and the light."""
    keys = [sphere_centre(t) for t in times]
    margin = 0.02
    for k in range(len(keys) - 1):
        for s in range(21):
            f = s / 20
            p = tuple(keys[k][c] + f * (keys[k + 1][c] - keys[k][c]) for c in range(3))
            r = SPHERE_R + margin
            ok = (abs(p[0]) < 1 - r and r < p[1] < LIGHT_Y - r and -1 + r < p[2] < 1 - SPHERE_R
                  and box_distance(p, SHORT_BOX) > r and box_distance(p, TALL_BOX) > r)
            if not ok:
                raise gw.Invalid("moving sphere path collides near t=%.3f" % times[k])


def cornell_box(g):
    """The box's materials, walls and light. Returns the white material and the walls' and
    light's nodes."""
    white = g.material("white", (0.73, 0.73, 0.73))
    red = g.material("red", (0.63, 0.065, 0.05))
    green = g.material("green", (0.14, 0.45, 0.091))
    light = g.material("light", (0.0, 0.0, 0.0), emissive=(1.0, 1.0, 1.0),
                       strength=LIGHT_STRENGTH)
    t = WALL

    # interior x in [-1,1], y in [0,2], z in [-1,1]; the front (+z) is open
    shell = gw.Mesh()
    shell.add(gw.box((-1 - t, -t, -1 - t), (1 + t, 0, 1)))      # floor
    shell.add(gw.box((-1 - t, 2, -1 - t), (1 + t, 2 + t, 1)))   # ceiling
    shell.add(gw.box((-1 - t, 0, -1 - t), (1 + t, 2, -1)))      # back wall
    left = gw.box((-1 - t, 0, -1), (-1, 2, 1))
    right = gw.box((1, 0, -1), (1 + t, 2, 1))
    walls = g.mesh("walls", [(shell, white), (left, red), (right, green)])

    lamp = gw.quad((-LIGHT_W / 2, LIGHT_Y, -LIGHT_D / 2), (LIGHT_W, 0, 0), (0, 0, LIGHT_D))
    if lamp.nrm[1::3] != [-1.0] * lamp.vertex_count:
        raise gw.Invalid("light quad does not face down")
    lamp_mesh = g.mesh("light", [(lamp, light)])
    return white, [g.node("walls", mesh=walls), g.node("light", mesh=lamp_mesh)]


def block(g, white, name, spec):
    """A white block as SHORT_BOX or TALL_BOX gives it, standing on the floor."""
    sx, sy, sz = spec["size"]
    m = g.mesh(name, [(gw.box((-sx / 2, 0, -sz / 2), (sx / 2, sy, sz / 2)), white)])
    return g.node(name, mesh=m, translation=spec["at"],
                  rotation=gw.quat_axis_angle((0, 1, 0), math.radians(spec["yaw"])))


def build(orbit):
    g = gw.Gltf(GENERATOR)
    white, roots = cornell_box(g)
    gold = g.material("sphere", (0.8, 0.7, 0.2), roughness=0.3)

    sphere = g.mesh("sphere", [(gw.uv_sphere(SPHERE_R, SPHERE_SEG, SPHERE_RINGS), gold)])
    times = key_times()
    check_clearance(times)

    roots += [block(g, white, "short_block", SHORT_BOX), block(g, white, "tall_block", TALL_BOX)]
    ball = g.node("moving_sphere", mesh=sphere, translation=sphere_centre(0.0),
                  rotation=sphere_rotation(0.0), extras={"dynamic": True})
    roots.append(ball)
    cam = g.camera("camera", 0.69, 4.0 / 3.0, 0.01, 100.0)
    channels = [(ball, "translation", times, [sphere_centre(x) for x in times]),
                (ball, "rotation", times, [sphere_rotation(x) for x in times])]
    if orbit:
        pos0, rot0 = orbit_pose(0.0)
        eye = g.node("camera", camera=cam, translation=pos0, rotation=rot0)
        poses = [orbit_pose(x) for x in times]
        channels += [(eye, "translation", times, [p for p, _ in poses]),
                     (eye, "rotation", times, [q for _, q in poses])]
    else:
        eye = g.node("camera", camera=cam,
                     translation=(CENTRE[0], CENTRE[1], CENTRE[2] + EYE_DISTANCE))
    roots.append(eye)
    g.animation("orbit" if orbit else "moving_sphere", channels)
    return g, roots


def tentacle_pose(k, t):
    """Joint k's rotation at t: a wave travelling up the chain, about z and x."""
    w = 2 * math.pi * t / DURATION
    a = math.radians(9.0) * math.sin(w - 0.6 * k)
    b = math.radians(5.0) * math.sin(2 * w - 0.9 * k)
    return gw.quat_mul(gw.quat_axis_angle((0, 0, 1), a), gw.quat_axis_angle((1, 0, 0), b))


def tentacle_mesh(rings, segments):
    """A closed tube of radius TENTACLE_R tapering to a tip, in bind pose, skinned to the
    chain: each vertex between the two joints nearest its height."""
    x0, y0, z0 = TENTACLE_AT

    def radius(v):
        return TENTACLE_R * (1.0 - v ** 6)

    def f(u, v):
        a = 2 * math.pi * u
        return (x0 + radius(v) * math.cos(a), y0 + TENTACLE_H * v, z0 - radius(v) * math.sin(a))

    def n(u, v):
        a = 2 * math.pi * u
        slope = 6 * TENTACLE_R * v ** 5 / TENTACLE_H  # the taper leans the normal up
        return (math.cos(a), slope, -math.sin(a))
    m = gw.grid(f, segments, rings, normal=n)
    step = TENTACLE_H / (JOINTS - 1)
    for k in range(m.vertex_count):
        s = min((m.pos[3 * k + 1] - y0) / step, JOINTS - 1 - 1e-6)
        j = int(s)
        frac = s - j
        m.joints += [j, min(j + 1, JOINTS - 1), 0, 0]
        m.weights += [gw.f32(1.0 - frac), gw.f32(frac), 0.0, 0.0]
    return m


def blob_mesh():
    """A sphere with two morph targets: squashed, and spiky."""
    m = gw.uv_sphere(BLOB_R, 24, 12)
    squash, spikes = [], []
    for k in range(m.vertex_count):
        x, y, z = m.pos[3 * k:3 * k + 3]
        squash += [gw.f32(0.35 * x), gw.f32(-0.45 * y), gw.f32(0.35 * z)]
        nx, ny, nz = m.nrm[3 * k:3 * k + 3]
        bump = max(0.0, math.cos(5 * math.atan2(z, x)) * math.sin(math.acos(max(-1, min(1, ny)))))
        spikes += [gw.f32(0.12 * bump * nx), gw.f32(0.12 * bump * ny), gw.f32(0.12 * bump * nz)]
    m.pos = [p + c for p, c in zip(m.pos, BLOB_AT * m.vertex_count)]
    m.targets = [squash, spikes]
    m.target_weights = [0.0, 0.0]
    return m


def build_skinned(rings=TENTACLE_RINGS, segments=TENTACLE_SEG):
    g = gw.Gltf(GENERATOR)
    white, roots = cornell_box(g)
    skin_mat = g.material("tentacle", (0.55, 0.25, 0.45), roughness=0.5)
    blob_mat = g.material("blob", (0.2, 0.45, 0.7), roughness=0.35)
    roots.append(block(g, white, "short_block", SHORT_BOX))
    # the joint chain: the root at the tentacle's foot, each next one `step` above
    times = key_times()
    step = TENTACLE_H / (JOINTS - 1)
    joints = []
    for k in reversed(range(JOINTS)):
        children = [joints[-1]] if joints else None
        at = TENTACLE_AT if k == 0 else (0.0, step, 0.0)
        joints.append(g.node("joint%d" % k, translation=at, rotation=tentacle_pose(k, 0.0),
                             children=children))
    joints.reverse()
    binds = []
    for k in range(JOINTS):
        x, y, z = TENTACLE_AT
        binds.append([1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, -x, -(y + k * step), -z, 1])
    skin = g.skin("tentacle", joints, binds)
    tentacle = g.node("tentacle", mesh=g.mesh("tentacle", [(tentacle_mesh(rings, segments),
                                                            skin_mat)]), skin=skin)
    blob = g.node("blob", mesh=g.mesh("blob", [(blob_mesh(), blob_mat)]))
    roots += [joints[0], tentacle, blob]
    cam = g.camera("camera", 0.69, 4.0 / 3.0, 0.01, 100.0)
    roots.append(g.node("camera", camera=cam,
                        translation=(CENTRE[0], CENTRE[1], CENTRE[2] + EYE_DISTANCE)))
    channels = [(joints[k], "rotation", times, [tentacle_pose(k, x) for x in times])
                for k in range(JOINTS)]

    def blob_weights(x):
        w = 2 * math.pi * x / DURATION
        return (gw.f32(0.5 + 0.5 * math.sin(w)), gw.f32(0.5 + 0.5 * math.sin(2 * w + 1.0)))
    channels.append((blob, "weights", times, [blob_weights(x) for x in times]))
    g.animation("sway_and_morph", channels)
    return g, roots


def generate(folder, names=SCENES, tentacle=(TENTACLE_RINGS, TENTACLE_SEG)):
    """Writes both scenes into folder, validates them; returns {name: summary}."""
    out = {}
    for name in names:
        if "skinned" in name:
            g, roots = build_skinned(*tentacle)
        else:
            g, roots = build(orbit="orbit" in name)
        path = os.path.join(folder, name)
        g.write(path, roots, embedded=True)
        s = gw.validate(path)
        if abs(s["duration"] - DURATION) > 1e-6:
            raise gw.Invalid("%s: animation lasts %g s, not %g" % (name, s["duration"], DURATION))
        if s["bytes"] >= 300 * 1024 and tentacle == (TENTACLE_RINGS, TENTACLE_SEG):
            raise gw.Invalid("%s: %d bytes, over the 300 KB budget" % (name, s["bytes"]))
        out[name] = s
    return out


def main():
    here = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", default=os.path.join(here, "scenes"),
                    help="folder to write into (default: the repository's scenes/)")
    ap.add_argument("--check", metavar="DIR",
                    help="regenerate into a temporary folder and compare with DIR")
    ap.add_argument("--skinned-only", action="store_true",
                    help="write only cornell-skinned.gltf (for benchmarks)")
    ap.add_argument("--tentacle", default="%dx%d" % (TENTACLE_RINGS, TENTACLE_SEG),
                    metavar="RINGSxSEGMENTS",
                    help="the tentacle's tessellation (2 x RINGS x SEGMENTS triangles)")
    args = ap.parse_args()
    try:
        rings, segments = (int(x) for x in args.tentacle.split("x"))
        if rings < 2 or segments < 3:
            raise ValueError
    except ValueError:
        ap.error("--tentacle must be RINGSxSEGMENTS, at least 2x3")
    try:
        if args.check:
            with tempfile.TemporaryDirectory() as tmp:
                generate(tmp)
                stale = []
                for name in SCENES:
                    committed = os.path.join(args.check, name)
                    with open(os.path.join(tmp, name), "rb") as fh:
                        fresh = fh.read()
                    if not os.path.exists(committed):
                        stale.append(name + " (missing)")
                        continue
                    with open(committed, "rb") as fh:
                        if fh.read() != fresh:
                            stale.append(name)
            if stale:
                print("gen_scenes: stale in %s: %s; run python3 -m tools.scenes.gen_scenes and commit"
                      % (args.check, ", ".join(stale)), file=sys.stderr)
                return 1
            print("gen_scenes: %s up to date" % ", ".join(SCENES))
            return 0
        os.makedirs(args.out, exist_ok=True)
        names = ("cornell-skinned.gltf",) if args.skinned_only else SCENES
        for name, s in generate(args.out, names, (rings, segments)).items():
            print("%s: %d triangles (%d static, %d dynamic), %.1f s, %d bytes"
                  % (name, s["triangles"], s["static"], s["dynamic"], s["duration"], s["bytes"]))
        return 0
    except (gw.Invalid, OSError, KeyError, ValueError) as e:
        print("gen_scenes: %s" % e, file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main())
