"""Generates a large atrium test scene (not committed): a courtyard surrounded by two
storeys of columns and arches, galleries, outer walls, curtains, an opening in the roof
lit by an emissive sky quad (or a directional sun, or at night by several hundred small
lanterns), three moving objects, two still cameras and one walking through the courtyard.

  python3 -m tools.scenes.gen_atrium --size 1 --out /tmp/atrium/atrium.gltf   # ~300k triangles
  python3 -m tools.scenes.gen_atrium --size 0.1 --out /tmp/atrium-small.gltf  # quick test scene
  python3 -m tools.scenes.gen_atrium --light lanterns --out /tmp/atrium-lanterns/atrium.gltf
  python3 -m tools.scenes.gen_atrium --normal-maps --out /tmp/atrium-tiles/atrium.gltf  # bevelled tiles

--size scales the tessellation (triangles grow about linearly with it); the layout, the
cameras and the lanterns do not change. --light picks the lighting:

  sky       an emissive quad over the opening in the roof (the default)
  sun       a KHR_lights_punctual directional light through the opening
  lanterns  night, a many-lights scene: 460 small emissive lantern bodies (boxes and
            low-poly spheres, 4 to 35 cm; 6936 emissive triangles) in every bay of both
            storeys (under each arch, hanging from the gallery ceilings, sconces on the
            outer walls and on the arcades' courtyard faces, candles on the gallery
            floors), on the courtyard floor and on six strings of bulbs across the
            courtyard; warm white, amber, red, green, blue, cool white and pink, emission
            strengths spread over two orders of magnitude (a fixed pseudo-random sequence,
            so the file is the same every time); 6 point lights and a spot light, and the
            swinging lantern's glass glows (an emitter on a moving instance). No sky.

Writes PATH.gltf and PATH.bin, validates them, prints one line.
"""

import argparse
import math
import os
import random
import sys
import time

from . import gltf_writer as gw

# Layout in metres. Column centre lines run round the courtyard rectangle
# x in [-COL_X, COL_X], z in [-COL_Z, COL_Z]; bays are BAY wide.
COL_X, COL_Z, BAY = 8.0, 4.0, 2.0
ARCADE_D = 0.6                                  # arcade wall thickness
IN_X, IN_Z = COL_X - ARCADE_D / 2, COL_Z - ARCADE_D / 2   # inner face of the arcades
OUT_X, OUT_Z, WALL_T = 11.0, 7.0, 0.5           # inside of the outer walls, their thickness
COL_R, ARCH_R, ABACUS = 0.22, 0.7, 0.6          # column radius, arch radius, capital width
PLINTH_H, ABACUS_H = 0.12, 0.2
# per storey: floor level, column top (lathe), arcade top; the slab above starts there
STOREYS = ((0.0, 4.0, 5.4), (5.7, 9.1, 10.4))
SLAB_T = 0.3
ROOF_TOP = STOREYS[1][2] + SLAB_T
DURATION, KEY_STEP = 10.0, 0.25
SKY_STRENGTH = 2.0


def counts(size):
    """Tessellation for a size: each 2D count scales with sqrt(size)."""
    k = math.sqrt(size)

    def n(base, lo):
        return max(lo, int(round(base * k)))
    return dict(col_seg=n(40, 12), col_rows=n(40, 10), arch_seg=n(40, 8),
                arch_rows=n(5, 1), arch_depth=n(4, 1), cloth_u=n(36, 8), cloth_v=n(72, 12),
                tiles=n(2, 1), ball_band=n(8, 2), ball_rings=n(32, 8), lantern_seg=n(24, 8))


# ---------------------------------------------------------------- static parts

def column(height, c):
    """Fluted column from y=0 (top of the plinth) to `height`: torus base, shaft with
    entasis, flared capital."""
    rows = c["col_rows"]
    nb, ns = max(3, rows // 4), max(2, rows * 2 // 5)
    nc = max(3, rows - nb - ns - 1)
    base_h, cap_h = 0.25, 0.35
    shaft = height - base_h - cap_h
    prof = []
    for k in range(nb + 1):
        s = k / nb
        prof.append((base_h * s, COL_R * (1.12 + 0.18 * math.sin(math.pi * s)), 0.0))
    for k in range(ns + 1):
        s = k / ns
        prof.append((base_h + shaft * s, COL_R * (1 - 0.1 * s * s), 1.0))
    top = COL_R * 0.9
    for k in range(1, nc + 1):
        s = k / nc
        prof.append((height - cap_h + cap_h * s, top + (1.3 * COL_R - top) * s * s, 0.0))
    return gw.lathe(prof, c["col_seg"], flutes=max(6, c["col_seg"] // 3), flute_depth=0.04)


def arcade_bay(spring, top, c):
    """One bay of an arcade wall in a local frame: x in [-BAY/2, BAY/2] along the wall,
    z in [-ARCADE_D/2, ARCADE_D/2] across, a semicircular arch of ARCH_R springing at
    y = spring, solid up to y = top."""
    n, rows, depth = c["arch_seg"], c["arch_rows"], c["arch_depth"]
    half, d = BAY / 2, ARCADE_D / 2
    m = gw.Mesh()

    def face(z, flip):
        def spandrel(u, v):
            a = math.pi * (1 - u)
            x = ARCH_R * math.cos(a)
            y0 = spring + ARCH_R * math.sin(a)
            return (x, y0 + (top - y0) * v, z)
        m.add(gw.grid(spandrel, n, rows, normal=lambda u, v: (0, 0, 1), flip=flip))
        for x0 in (-half, ARCH_R):
            w = half - ARCH_R
            m.add(gw.grid(lambda u, v: (x0 + w * u, spring + (top - spring) * v, z), 1, rows,
                          normal=lambda u, v: (0, 0, 1), flip=flip))
    face(d, False)
    face(-d, True)

    def intrados(u, w):
        a = math.pi * (1 - u)
        return (ARCH_R * math.cos(a), spring + ARCH_R * math.sin(a), -d + 2 * d * w)
    m.add(gw.grid(intrados, n, depth,
                  normal=lambda u, w: (-math.cos(math.pi * (1 - u)),
                                       -math.sin(math.pi * (1 - u)), 0)))
    return m


def curtain(width, y_bottom, y_top, phase, c):
    """Hanging cloth in a local frame, facing +z: folds whose depth grows downwards."""
    folds = 4

    def f(u, v):
        amp = 0.05 + 0.05 * (1 - v)
        z = amp * math.sin(2 * math.pi * folds * u + phase) + 0.02 * math.sin(math.pi * u)
        return (-width / 2 + width * u, y_bottom + (y_top - y_bottom) * v, z)
    return gw.grid(f, c["cloth_u"], c["cloth_v"])


def ring_boxes(y0, y1, inner_x, inner_z):
    """Four boxes covering the outer rectangle minus the inner one (slabs, floors)."""
    m = gw.Mesh()
    m.add(gw.box((-OUT_X, y0, inner_z), (OUT_X, y1, OUT_Z)))
    m.add(gw.box((-OUT_X, y0, -OUT_Z), (OUT_X, y1, -inner_z)))
    m.add(gw.box((inner_x, y0, -inner_z), (OUT_X, y1, inner_z)))
    m.add(gw.box((-OUT_X, y0, -inner_z), (-inner_x, y1, inner_z)))
    return m


def column_positions():
    pts = []
    nx, nz = int(round(2 * COL_X / BAY)), int(round(2 * COL_Z / BAY))
    for i in range(nx + 1):
        x = -COL_X + BAY * i
        pts += [(x, -COL_Z), (x, COL_Z)]
    for j in range(1, nz):
        z = -COL_Z + BAY * j
        pts += [(-COL_X, z), (COL_X, z)]
    return pts


def bays():
    """(centre x, centre z, yaw) of every arcade bay; yaw turns local x along the wall."""
    out = []
    nx, nz = int(round(2 * COL_X / BAY)), int(round(2 * COL_Z / BAY))
    for i in range(nx):
        x = -COL_X + BAY * (i + 0.5)
        out += [(x, -COL_Z, 0.0), (x, COL_Z, math.pi)]
    for j in range(nz):
        z = -COL_Z + BAY * (j + 0.5)
        out += [(-COL_X, z, math.pi / 2), (COL_X, z, -math.pi / 2)]
    return out


def tile_normal_map(size=64, bevel=0.06, depth=0.03):
    """PNG of a tangent-space normal map: one square tile per uv unit, its edges bevelled
    (slope depth / bevel) down to a groove."""
    def height(x, y):
        d = min(x, 1.0 - x, y, 1.0 - y)
        return depth * min(1.0, d / bevel)

    def pixel(i, j):
        x, y, e = (i + 0.5) / size, (j + 0.5) / size, 0.5 / size
        dx = (height(x + e, y) - height(x - e, y)) / (2 * e)
        dy = (height(x, y + e) - height(x, y - e)) / (2 * e)
        n = gw.normalize((-dx, -dy, 1.0))
        return tuple(int(round((c * 0.5 + 0.5) * 255)) for c in n)
    return gw.png_rgb(size, size, pixel)


def build_static(c, normal_maps=False):
    """Returns {material name: Mesh} of everything that does not move. With normal_maps the
    courtyard tiles are meshes of their own, with uvs of one unit per tile."""
    stone, dark, plaster = gw.Mesh(), gw.Mesh(), gw.Mesh()
    tiles = (gw.Mesh(), gw.Mesh()) if normal_maps else (stone, dark)
    cloths = [gw.Mesh(), gw.Mesh(), gw.Mesh()]
    for level, (floor_y, col_top, arcade_top) in enumerate(STOREYS):
        shaft = column(col_top - floor_y - PLINTH_H, c)
        spring = col_top + ABACUS_H
        bay = arcade_bay(spring, arcade_top, c)
        h, a = ABACUS / 2, ABACUS / 2
        for x, z in column_positions():
            stone.add(shaft, translation=(x, floor_y + PLINTH_H, z))
            dark.add(gw.box((x - h, floor_y, z - h), (x + h, floor_y + PLINTH_H, z + h)))
            dark.add(gw.box((x - a, col_top, z - a), (x + a, spring, z + a)))
        for x, z, yaw in bays():
            stone.add(bay, rotation=gw.quat_axis_angle((0, 1, 0), yaw), translation=(x, 0, z))
        for sx in (-1, 1):                     # corner piers close the arcade corners
            for sz in (-1, 1):
                x, z, d = sx * COL_X, sz * COL_Z, ARCADE_D / 2
                stone.add(gw.box((x - d, spring, z - d), (x + d, arcade_top, z + d)))
        # slab above this storey: gallery floor, then the roof; open over the courtyard
        stone.add(ring_boxes(arcade_top, arcade_top + SLAB_T, IN_X, IN_Z))

    # ground floor: gallery ring plus a checkerboard of courtyard tiles
    dark.add(ring_boxes(-0.2, 0.0, IN_X, IN_Z))
    tx, tz = 16 * c["tiles"] // 2, 8 * c["tiles"] // 2
    wx, wz = 2 * IN_X / tx, 2 * IN_Z / tz
    for i in range(tx):
        for j in range(tz):
            tile = gw.quad((-IN_X + wx * i, 0.0, -IN_Z + wz * (j + 1)), (wx, 0, 0), (0, 0, -wz))
            if normal_maps:
                p = tile.pos
                tile.uv = [f for k in range(0, len(p), 3)
                           for f in ((p[k] + IN_X) / wx - i, (p[k + 2] + IN_Z) / wz - j)]
            tiles[0 if (i + j) % 2 else 1].add(tile)

    # outer walls, closing the building up to the roof
    y0, y1, t = -0.2, ROOF_TOP, WALL_T
    plaster.add(gw.box((-OUT_X - t, y0, -OUT_Z - t), (OUT_X + t, y1, -OUT_Z)))
    plaster.add(gw.box((-OUT_X - t, y0, OUT_Z), (OUT_X + t, y1, OUT_Z + t)))
    plaster.add(gw.box((-OUT_X - t, y0, -OUT_Z), (-OUT_X, y1, OUT_Z)))
    plaster.add(gw.box((OUT_X, y0, -OUT_Z), (OUT_X + t, y1, OUT_Z)))

    # curtains in the ground-floor bays of the long sides, just behind the arcade
    floor_y, col_top, arcade_top = STOREYS[0]
    k = 0
    for x, z, yaw in bays():
        if yaw not in (0.0, math.pi):
            continue
        offset = ARCADE_D / 2 + 0.2
        zz = z - offset if z < 0 else z + offset
        cl = curtain(BAY - 0.4, 1.0, arcade_top - 0.05, 0.7 * k, c)
        # local +z faces the courtyard
        cloths[k % 3].add(cl, rotation=gw.quat_axis_angle((0, 1, 0), yaw), translation=(x, 0, zz))
        k += 1
    out = {"stone": stone, "dark_stone": dark, "plaster": plaster, "cloth_red": cloths[0],
           "cloth_green": cloths[1], "cloth_blue": cloths[2]}
    if normal_maps:
        out["stone_tiles"], out["dark_tiles"] = tiles
    return out


# ---------------------------------------------------------------- moving parts

def walkthrough(t):
    """The moving camera at time t: it walks from the courtyard camera's place towards the
    far corner of the courtyard, rising a little, and pans 60 degrees to its left over the
    animation: about 1.1 m and 6 degrees a second, a handheld walk."""
    u = t / DURATION
    eye = (COURTYARD_EYE[0] - 10.0 * u, COURTYARD_EYE[1] + 0.8 * u, COURTYARD_EYE[2] - 4.0 * u)
    yaw = math.radians(-100.0 + 60.0 * u)
    look = (math.cos(yaw), -0.12, math.sin(yaw))
    return eye, gw.quat_look(look)


def key_times():
    n = int(round(DURATION / KEY_STEP))
    return [gw.f32(DURATION * k / n) for k in range(n + 1)]


BALL_R, BALL_Z = 0.6, 1.0


def ball_pose(t):
    """Rolls along x across the courtyard and back; rotation matches the rolling."""
    x = -6.0 * math.cos(2 * math.pi * t / DURATION)
    return (x, BALL_R, BALL_Z), gw.quat_axis_angle((0, 0, 1), -x / BALL_R)


COURTYARD_EYE = (7.0, 1.7, 2.8)                 # the courtyard camera
LANTERN_PIVOT, LANTERN_ROD = (0.0, STOREYS[0][2], COL_Z + 1.6), 1.8


def lantern_swing(t):
    """Pendulum about x, two swings in the animation, amplitude 20 degrees."""
    a = math.radians(20) * math.sin(4 * math.pi * t / DURATION)
    return gw.quat_axis_angle((1, 0, 0), a)


CRATE = 0.8


def crate_position(t):
    """Slides along the -z upper gallery and back."""
    return (5.0 * math.sin(2 * math.pi * t / DURATION), STOREYS[1][0] + CRATE / 2,
            -(COL_Z + 1.5))


def ball_meshes(c):
    bands = 6
    a, b = gw.Mesh(), gw.Mesh()
    for k in range(bands):
        band = gw.uv_sphere(BALL_R, c["ball_band"], c["ball_rings"], k / bands, (k + 1) / bands)
        (a if k % 2 else b).add(band)
    return a, b


def lantern_meshes(c):
    """Rod and body hanging down from the pivot (local origin)."""
    seg = c["lantern_seg"]
    rod = gw.lathe([(-LANTERN_ROD, 0.015, 0), (0.0, 0.015, 0)], 8)
    metal = gw.Mesh().add(rod)
    body_top = -LANTERN_ROD
    cap = [(body_top - 0.08, 0.2, 0), (body_top - 0.04, 0.12, 0), (body_top, 0.03, 0)]
    metal.add(gw.lathe(cap, seg))
    rows = max(4, seg // 2)
    glass_prof = []
    for k in range(rows + 1):
        s = k / rows
        glass_prof.append((body_top - 0.5 + 0.42 * s, 0.05 + 0.13 * math.sin(math.pi * (0.15 + 0.85 * s)), 0))
    glass = gw.lathe(glass_prof, seg)
    return metal, glass


# ---------------------------------------------------------------- night: many lanterns

# emission colours (factor in [0, 1]) and how often each is drawn
LANTERN_COLOURS = (("warm", (1.0, 0.78, 0.5), 5), ("amber", (1.0, 0.55, 0.15), 4),
                   ("red", (1.0, 0.14, 0.08), 2), ("green", (0.25, 1.0, 0.3), 2),
                   ("blue", (0.2, 0.4, 1.0), 2), ("cool", (0.8, 0.9, 1.0), 1),
                   ("pink", (1.0, 0.35, 0.75), 1))
# emission strength levels: STRENGTH_LO x 10^(k / 4), k = 0..8, i.e. a factor of 100
STRENGTH_LO, STRENGTH_LEVELS = 0.5, 9
LANTERN_GLASS_STRENGTH = 4.0    # the swinging lantern's glass in the lanterns variant


def scaled(mesh, sx, sy, sz):
    """A copy of mesh scaled along the axes (normals by the inverse transpose)."""
    m = gw.Mesh()
    m.idx = list(mesh.idx)
    for i in range(0, len(mesh.pos), 3):
        m.pos += (mesh.pos[i] * sx, mesh.pos[i + 1] * sy, mesh.pos[i + 2] * sz)
        m.nrm += gw.normalize((mesh.nrm[i] / sx, mesh.nrm[i + 1] / sy, mesh.nrm[i + 2] / sz))
    return m


def rod(a, b, r):
    """Thin square rod (a 4-sided open prism) from point a to point b."""
    d = gw.sub(b, a)
    n = math.sqrt(gw.dot(d, d))
    prism = gw.lathe([(0.0, r, 0), (n, r, 0)], 4)
    axis = gw.cross((0.0, 1.0, 0.0), d)
    s = math.sqrt(gw.dot(axis, axis))
    if s < 1e-9:
        rot = None if d[1] > 0 else gw.quat_axis_angle((1, 0, 0), math.pi)
    else:
        rot = gw.quat_axis_angle(axis, math.atan2(s, d[1]))
    return gw.Mesh().add(prism, rotation=rot, translation=a)


class Lanterns:
    """Collects the emitters (one Mesh per colour and strength level) and the iron that
    holds them; every emitter draws its colour and level from one fixed sequence."""

    def __init__(self):
        self.rng = random.Random(1)
        self.emitters = {}          # (colour index, level) -> Mesh
        self.iron = gw.Mesh()
        self.count = 0
        self._bag = [i for i, (_, _, w) in enumerate(LANTERN_COLOURS) for _ in range(w)]

    def add(self, mesh, centre, lo=0, hi=STRENGTH_LEVELS - 1, rotation=None):
        key = (self.rng.choice(self._bag), self.rng.randint(lo, hi))
        self.emitters.setdefault(key, gw.Mesh()).add(mesh, rotation=rotation,
                                                     translation=centre)
        self.count += 1

    def hanging(self, x, top, z, drop, body):
        """A body hanging `drop` below (x, top, z) on a rod, with a small iron cap."""
        half = body_half_height(body)
        cy = top - drop - half
        self.iron.add(rod((x, cy + half, z), (x, top, z), 0.008))
        self.iron.add(gw.box((x - 0.04, cy + half, z - 0.04),
                             (x + 0.04, cy + half + 0.02, z + 0.04)))
        return (x, cy, z)


def span_box(a, b, pad):
    """Axis-aligned box spanning points a and b, widened by pad in x and z."""
    return gw.box((min(a[0], b[0]) - pad, min(a[1], b[1]), min(a[2], b[2]) - pad),
                  (max(a[0], b[0]) + pad, max(a[1], b[1]), max(a[2], b[2]) + pad))


def body_half_height(m):
    ys = m.pos[1::3]
    return (max(ys) - min(ys)) / 2


def sphere_body(r, stretch=1.0):
    return scaled(gw.uv_sphere(1.0, 6, 3), r, r * stretch, r)


def box_body(w, h):
    return gw.box((-w / 2, -h / 2, -w / 2), (w / 2, h / 2, w / 2))


def near_pendulum(x, z, level):
    """Whether (x, z) on that storey is in the swinging lantern's way."""
    return level == 0 and abs(x) < 0.7 and abs(z - LANTERN_PIVOT[2]) < 1.2


def build_lanterns():
    """Returns the Lanterns of the night variant: every bay of both storeys, the columns'
    courtyard faces, the courtyard floor and strings of bulbs across the courtyard."""
    L = Lanterns()
    rng = L.rng
    gallery = OUT_Z - COL_Z                    # depth of the galleries (3 m on every side)

    def world(bx, bz, yaw, lx, ly, lz):
        c, s = math.cos(yaw), math.sin(yaw)
        return (bx + lx * c + lz * s, ly, bz - lx * s + lz * c)

    for level, (floor_y, col_top, arcade_top) in enumerate(STOREYS):
        crown = col_top + ABACUS_H + ARCH_R
        for bx, bz, yaw in bays():
            # under the crown of the arch
            body = sphere_body(rng.uniform(0.07, 0.11), rng.choice((1.0, 1.4)))
            x, _, z = world(bx, bz, yaw, 0.0, 0.0, 0.0)
            L.add(body, L.hanging(x, crown, z, rng.uniform(0.15, 0.35), body), lo=3)
            # two hanging from the gallery ceiling
            for lx in (-0.5, 0.5):
                x, _, z = world(bx, bz, yaw, lx, 0.0, -gallery / 2)
                if near_pendulum(x, z, level):
                    continue
                if rng.random() < 0.5:
                    body = sphere_body(rng.uniform(0.06, 0.12), rng.choice((1.0, 1.5)))
                else:
                    body = box_body(rng.uniform(0.1, 0.2), rng.uniform(0.15, 0.3))
                L.add(body, L.hanging(x, arcade_top, z, rng.uniform(0.3, 1.0), body), lo=2)
            # sconce on the outer wall facing the bay
            w, h = rng.uniform(0.08, 0.14), rng.uniform(0.12, 0.2)
            x, y, z = world(bx, bz, yaw, 0.0, floor_y + 2.3, -gallery + 0.04 + w / 2)
            L.add(box_body(w, h), (x, y, z), lo=2, hi=6)
            ax, _, az = world(bx, bz, yaw, 0.0, 0.0, -gallery)
            L.iron.add(span_box((ax, y - h / 2 - 0.03, az), (x, y - h / 2, z), 0.02))
            # candles on the gallery floor against the outer wall
            for lx in (-0.6, 0.6):
                w, h = rng.uniform(0.04, 0.08), rng.uniform(0.06, 0.2)
                x, _, z = world(bx, bz, yaw, lx + rng.uniform(-0.2, 0.2), 0.0, -gallery + 0.25)
                L.add(box_body(w, h), (x, floor_y + h / 2, z), hi=5)
        # sconces on the arcade's courtyard face above every column
        for cx, cz in column_positions():
            if abs(cz) == COL_Z:
                nx, nz = 0.0, -math.copysign(1.0, cz)
            else:
                nx, nz = -math.copysign(1.0, cx), 0.0
            if abs(cx) == COL_X and abs(cz) == COL_Z:   # corner pier: on its diagonal
                nx, nz = -math.copysign(1.0, cx), -math.copysign(1.0, cz)
            y = col_top + ABACUS_H + 0.45
            face, d = ARCADE_D / 2, ARCADE_D / 2 + 0.08
            body = sphere_body(rng.uniform(0.05, 0.08), 1.3)
            L.add(body, (cx + nx * d, y, cz + nz * d), lo=1, hi=7)
            L.iron.add(span_box((cx + nx * face, y - 0.1, cz + nz * face),
                                (cx + nx * d, y - 0.08, cz + nz * d), 0.015))

    # strings of bulbs across the courtyard below the upper arcades, sagging 1.2 m
    top_y, sag, bulbs = STOREYS[1][2] - 0.3, 1.2, 13
    bulb = scaled(gw.uv_sphere(1.0, 4, 2), 0.035, 0.035, 0.035)   # an octahedron
    for k in range(6):
        x = -IN_X + 2 * IN_X * (k + 0.5) / 6
        pts = []
        for i in range(bulbs + 2):
            t = i / (bulbs + 1)
            pts.append((x, top_y - sag * 4 * t * (1 - t), -IN_Z + 2 * IN_Z * t))
        for a, b in zip(pts, pts[1:]):
            L.iron.add(rod(a, b, 0.004))
        for p in pts[1:-1]:
            L.add(bulb, (p[0], p[1] - 0.039, p[2]), lo=0, hi=6)

    # the courtyard floor: lanterns round its edge and a cluster of candles, clear of the
    # rolling ball's track and of the courtyard camera
    edge = []
    for i in range(15):
        x = -IN_X + 0.4 + (2 * IN_X - 0.8) * i / 14
        edge += [(x, -IN_Z + 0.4), (x, IN_Z - 0.4)]
    for j in range(6):
        z = -IN_Z + 0.9 + (2 * IN_Z - 1.8) * j / 5
        edge += [(-IN_X + 0.4, z), (IN_X - 0.4, z)]
    cam = COURTYARD_EYE
    for x, z in edge:
        if math.hypot(x - cam[0], z - cam[2]) < 0.9:
            continue
        w, h = rng.uniform(0.12, 0.2), rng.uniform(0.2, 0.32)
        L.add(box_body(w, h), (x, h / 2, z), lo=1, hi=7)
    for i in range(9):
        a = 2 * math.pi * i / 9
        r = 0.5 + 0.15 * (i % 2)
        w, h = rng.uniform(0.04, 0.07), rng.uniform(0.06, 0.25)
        L.add(box_body(w, h), (r * math.cos(a), h / 2, -1.9 + r * math.sin(a)), hi=4)
    return L


def add_lanterns(g, roots):
    """The night lighting: the lanterns (one static node), point lights and a spot."""
    L = build_lanterns()
    prims = [(L.iron, g.material("lantern_iron", (0.06, 0.06, 0.06), metallic=1.0,
                                 roughness=0.5))]
    for (ci, lv) in sorted(L.emitters):
        name, col, _ = LANTERN_COLOURS[ci]
        strength = STRENGTH_LO * 10 ** (lv / 4)
        mat = g.material("lantern_%s_%d" % (name, lv), tuple(0.5 * c for c in col),
                         roughness=0.6, emissive=col, strength=gw.f32(strength))
        prims.append((L.emitters[(ci, lv)], mat))
    roots.append(g.node("lanterns", mesh=g.mesh("lanterns", prims)))

    # warm point lights in the corners of the galleries, a spot from the upper gallery
    # onto the courtyard
    for i, (pos, col, cd) in enumerate((
            ((-9.5, 4.6, -5.5), (1.0, 0.75, 0.45), 3.0), ((9.5, 4.6, -5.5), (1.0, 0.75, 0.45), 3.0),
            ((-9.5, 4.6, 5.5), (1.0, 0.6, 0.3), 3.0), ((9.5, 4.6, 5.5), (1.0, 0.6, 0.3), 3.0),
            ((-9.5, 9.6, 0.0), (0.7, 0.8, 1.0), 4.0), ((9.5, 9.6, 0.0), (0.7, 0.8, 1.0), 4.0))):
        light = punctual_light(g, "lamp_%d" % i, "point", col, cd)
        roots.append(g.node("lamp_%d" % i, translation=pos,
                            extensions={"KHR_lights_punctual": {"light": light}}))
    spot_pos, spot_at = (0.0, STOREYS[1][2] - 0.2, -IN_Z + 0.15), (0.0, 0.0, 0.8)
    spot = punctual_light(g, "spot", "spot", (1.0, 0.95, 0.85), 40.0, cone=(0.25, 0.35))
    roots.append(g.node("spot", translation=spot_pos,
                        rotation=gw.quat_look(gw.sub(spot_at, spot_pos)),
                        extensions={"KHR_lights_punctual": {"light": spot}}))
    return L.count


def punctual_light(g, name, kind, color, intensity, cone=None):
    """A KHR_lights_punctual point or spot light (intensity in candela); returns its index.
    cone: (inner, outer) angles in radians of a spot."""
    g.extensions.add("KHR_lights_punctual")
    ext = g.doc.setdefault("extensions", {}).setdefault("KHR_lights_punctual", {"lights": []})
    light = {"name": name, "type": kind, "color": list(color), "intensity": intensity}
    if kind == "spot":
        light["spot"] = {"innerConeAngle": cone[0], "outerConeAngle": cone[1]}
    ext["lights"].append(light)
    return len(ext["lights"]) - 1


def build(size, light, normal_maps=False):
    c = counts(size)
    # asset.generator keeps the script's old path (before tools/ had folders): the committed
    # scenes and the caches keyed by a scene's bytes stay valid.
    g = gw.Gltf("pathreuse tools/gen_atrium.py --size %g" % size
                + (" --light lanterns" if light == "lanterns" else "")
                + (" --normal-maps" if normal_maps else ""))
    mats = {
        "stone": g.material("stone", (0.62, 0.58, 0.5), roughness=0.9),
        "dark_stone": g.material("dark_stone", (0.32, 0.3, 0.27), roughness=0.8),
        "plaster": g.material("plaster", (0.7, 0.66, 0.58)),
        "cloth_red": g.material("cloth_red", (0.6, 0.08, 0.07), double_sided=True),
        "cloth_green": g.material("cloth_green", (0.1, 0.35, 0.12), double_sided=True),
        "cloth_blue": g.material("cloth_blue", (0.1, 0.15, 0.45), double_sided=True),
    }
    if normal_maps:
        bumps = g.png_texture("tile_normals", tile_normal_map())
        mats["stone_tiles"] = g.material("stone_tiles", (0.62, 0.58, 0.5), roughness=0.9,
                                         normal_texture=bumps)
        mats["dark_tiles"] = g.material("dark_tiles", (0.32, 0.3, 0.27), roughness=0.8,
                                        normal_texture=bumps)
        # polished dark tiles: a clear coat and a tinted specular layer
        g.doc["materials"][mats["dark_tiles"]]["extensions"] = {
            # the coat thinner on the bevels (the normal map's red channel)
            "KHR_materials_clearcoat": {"clearcoatFactor": 0.8, "clearcoatRoughnessFactor": 0.15,
                                        "clearcoatTexture": {"index": bumps}},
            "KHR_materials_specular": {"specularColorFactor": [1.0, 0.9, 0.8]}}
        g.extensions.update(("KHR_materials_clearcoat", "KHR_materials_specular"))
    emitters = 0
    static = build_static(c, normal_maps)
    roots = [g.node("atrium", mesh=g.mesh("atrium", [(static[k], mats[k]) for k in mats]))]

    if light == "sky":
        sky = g.material("sky", (0.0, 0.0, 0.0), emissive=(0.85, 0.92, 1.0),
                         strength=SKY_STRENGTH)
        quad = gw.quad((-IN_X, ROOF_TOP, -IN_Z), (2 * IN_X, 0, 0), (0, 0, 2 * IN_Z))
        if quad.nrm[1::3] != [-1.0] * quad.vertex_count:
            raise gw.Invalid("sky quad does not face down")
        roots.append(g.node("sky", mesh=g.mesh("sky", [(quad, sky)])))
    elif light == "lanterns":
        emitters = add_lanterns(g, roots)
    else:
        sun = g.directional_light("sun", (1.0, 0.95, 0.85), 5.0)
        roots.append(g.node("sun", rotation=gw.quat_look((0.35, -1.0, 0.25)),
                            extensions={"KHR_lights_punctual": {"light": sun}}))

    times = key_times()
    white = g.material("ball_white", (0.8, 0.8, 0.78), roughness=0.4)
    red = g.material("ball_red", (0.7, 0.1, 0.08), roughness=0.4)
    wa, wb = ball_meshes(c)
    ball = g.node("rolling_ball", mesh=g.mesh("ball", [(wa, white), (wb, red)]),
                  translation=ball_pose(0)[0], rotation=ball_pose(0)[1],
                  extras={"dynamic": True})
    metal = g.material("lantern_metal", (0.2, 0.2, 0.2), metallic=1.0, roughness=0.4)
    if light == "lanterns":                    # the swinging lantern is lit too
        glass = g.material("lantern_glass", (0.9, 0.8, 0.5), roughness=0.5,
                           emissive=(1.0, 0.75, 0.4), strength=LANTERN_GLASS_STRENGTH)
    else:
        glass = g.material("lantern_glass", (0.9, 0.8, 0.5), roughness=0.5)
        if normal_maps:  # with the polished tiles: the lantern in tinted, absorbing glass
            g.doc["materials"][glass]["extensions"] = {
                "KHR_materials_transmission": {"transmissionFactor": 1.0},
                "KHR_materials_volume": {"thicknessFactor": 0.05, "attenuationDistance": 0.1,
                                         "attenuationColor": [0.9, 0.7, 0.4]}}
            g.extensions.update(("KHR_materials_transmission", "KHR_materials_volume"))
    lm, lg = lantern_meshes(c)
    lantern = g.node("lantern", mesh=g.mesh("lantern", [(lm, metal), (lg, glass)]),
                     extras={"dynamic": True})
    pivot = g.node("lantern_pivot", children=[lantern], translation=LANTERN_PIVOT,
                   rotation=lantern_swing(0), extras={"dynamic": True})
    wood = g.material("crate_wood", (0.45, 0.3, 0.18), roughness=0.7)
    h = CRATE / 2
    crate = g.node("sliding_crate", mesh=g.mesh("crate", [(gw.box((-h, -h, -h), (h, h, h)), wood)]),
                   translation=crate_position(0), extras={"dynamic": True})
    roots += [ball, pivot, crate]
    motion = g.animation("motion", [
        (ball, "translation", times, [ball_pose(t)[0] for t in times]),
        (ball, "rotation", times, [ball_pose(t)[1] for t in times]),
        (pivot, "rotation", times, [lantern_swing(t) for t in times]),
        (crate, "translation", times, [crate_position(t) for t in times])])

    # cameras: in the corner arch of the upper gallery looking across the courtyard, and
    # one standing in the courtyard
    cams = [("gallery_corner", (-COL_X + BAY / 2, STOREYS[1][0] + 1.7, COL_Z), (4.0, 2.0, -3.0)),
            ("courtyard", COURTYARD_EYE, (-8.0, 4.0, -2.0))]
    for name, eye, at in cams:
        cam = g.camera(name, 0.9, 16.0 / 9.0, 0.05, 200.0)
        roots.append(g.node(name, camera=cam, translation=eye,
                            rotation=gw.quat_look(gw.sub(at, eye))))
    # The third camera walks; made last, so that the other nodes, cameras and accessors keep
    # their indices (and the first camera, the default, its view).
    walk = g.node("walkthrough", camera=g.camera("walkthrough", 0.9, 16.0 / 9.0, 0.05, 200.0),
                  translation=walkthrough(0)[0], rotation=walkthrough(0)[1])
    roots.append(walk)
    moves = g.doc["animations"].pop(g.animation("walk", [
        (walk, "translation", times, [walkthrough(t)[0] for t in times]),
        (walk, "rotation", times, [walkthrough(t)[1] for t in times])]))
    one = g.doc["animations"][motion]
    for ch in moves["channels"]:
        ch["sampler"] += len(one["samplers"])
    one["samplers"] += moves["samplers"]
    one["channels"] += moves["channels"]
    return g, roots, emitters


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--size", type=float, default=1.0,
                    help="tessellation scale; 1 gives about 300k triangles (default 1)")
    ap.add_argument("--out", required=True, help="output .gltf (a .bin is written beside it)")
    ap.add_argument("--light", choices=("sky", "sun", "lanterns"), default="sky",
                    help="emissive sky quad over the opening (default), a KHR_lights_punctual "
                    "sun, or night lit by several hundred small emissive lanterns")
    ap.add_argument("--normal-maps", action="store_true",
                    help="bevelled courtyard tiles: a normal map (and uvs) on the floor tiles, "
                    "the dark ones clear-coated; the lantern in tinted, absorbing glass")
    args = ap.parse_args()
    if not args.size > 0:
        ap.error("--size must be positive")
    start = time.time()
    try:
        g, roots, emitters = build(args.size, args.light, args.normal_maps)
        os.makedirs(os.path.dirname(os.path.abspath(args.out)), exist_ok=True)
        g.write(args.out, roots, embedded=False)
        s = gw.validate(args.out)
        frac = s["dynamic"] / s["triangles"]
        if frac > 0.05:
            raise gw.Invalid("dynamic triangles are %.1f%% of all, over 5%%" % (100 * frac))
        if abs(s["duration"] - DURATION) > 1e-6:
            raise gw.Invalid("animation lasts %g s, not %g" % (s["duration"], DURATION))
    except (gw.Invalid, OSError, KeyError, ValueError) as e:
        print("gen_atrium: %s" % e, file=sys.stderr)
        return 1
    lit = ", %d lanterns" % emitters if emitters else ""
    print("%s: %d triangles (%d static, %d dynamic = %.2f%%)%s, %d bytes, %.1f s"
          % (args.out, s["triangles"], s["static"], s["dynamic"], 100 * frac, lit, s["bytes"],
             time.time() - start))
    return 0


if __name__ == "__main__":
    sys.exit(main())
