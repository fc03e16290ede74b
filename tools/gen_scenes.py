#!/usr/bin/env python3
"""Generates the committed demo scenes scenes/cornell-dynamic.gltf and
scenes/cornell-orbit.gltf, validates them, and with --check tells whether the committed
copies are stale.

  python3 tools/gen_scenes.py                 # writes scenes/*.gltf
  python3 tools/gen_scenes.py --check scenes/ # exit 1 if the committed files differ
"""

import argparse
import math
import os
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import gltf_writer as gw  # noqa: E402

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
SCENES = ("cornell-dynamic.gltf", "cornell-orbit.gltf")


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


def build(orbit):
    g = gw.Gltf("pathreuse tools/gen_scenes.py")
    white = g.material("white", (0.73, 0.73, 0.73))
    red = g.material("red", (0.63, 0.065, 0.05))
    green = g.material("green", (0.14, 0.45, 0.091))
    light = g.material("light", (0.0, 0.0, 0.0), emissive=(1.0, 1.0, 1.0),
                       strength=LIGHT_STRENGTH)
    gold = g.material("sphere", (0.8, 0.7, 0.2), roughness=0.3)
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

    def block(name, spec):
        sx, sy, sz = spec["size"]
        m = g.mesh(name, [(gw.box((-sx / 2, 0, -sz / 2), (sx / 2, sy, sz / 2)), white)])
        return g.node(name, mesh=m, translation=spec["at"],
                      rotation=gw.quat_axis_angle((0, 1, 0), math.radians(spec["yaw"])))

    sphere = g.mesh("sphere", [(gw.uv_sphere(SPHERE_R, SPHERE_SEG, SPHERE_RINGS), gold)])
    times = key_times()
    check_clearance(times)

    roots = [g.node("walls", mesh=walls), g.node("light", mesh=lamp_mesh),
             block("short_block", SHORT_BOX), block("tall_block", TALL_BOX)]
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


def generate(folder):
    """Writes both scenes into folder, validates them; returns {name: summary}."""
    out = {}
    for name in SCENES:
        g, roots = build(orbit="orbit" in name)
        path = os.path.join(folder, name)
        g.write(path, roots, embedded=True)
        s = gw.validate(path)
        if abs(s["duration"] - DURATION) > 1e-6:
            raise gw.Invalid("%s: animation lasts %g s, not %g" % (name, s["duration"], DURATION))
        if s["bytes"] >= 300 * 1024:
            raise gw.Invalid("%s: %d bytes, over the 300 KB budget" % (name, s["bytes"]))
        out[name] = s
    return out


def main():
    here = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", default=os.path.join(here, "scenes"),
                    help="folder to write into (default: the repository's scenes/)")
    ap.add_argument("--check", metavar="DIR",
                    help="regenerate into a temporary folder and compare with DIR")
    args = ap.parse_args()
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
                print("gen_scenes: stale in %s: %s; run python3 tools/gen_scenes.py and commit"
                      % (args.check, ", ".join(stale)), file=sys.stderr)
                return 1
            print("gen_scenes: %s up to date" % ", ".join(SCENES))
            return 0
        os.makedirs(args.out, exist_ok=True)
        for name, s in generate(args.out).items():
            print("%s: %d triangles (%d static, %d dynamic), %.1f s, %d bytes"
                  % (name, s["triangles"], s["static"], s["dynamic"], s["duration"], s["bytes"]))
        return 0
    except (gw.Invalid, OSError, KeyError, ValueError) as e:
        print("gen_scenes: %s" % e, file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main())
