"""Shared code of the scene generators: triangle meshes, a glTF 2.0 writer and a
validator that re-reads what was written (see docs/design.md section 3 for the conventions).

Standard library only. Output is deterministic: every float that reaches the file goes
through float32 first, so the bytes do not depend on the last bit of the C library's
sin/cos.
"""

import base64
import json
import math
import os
import re
import struct
import zlib

FLOAT, UBYTE, USHORT, UINT = 5126, 5121, 5123, 5125
ARRAY_BUFFER, ELEMENT_ARRAY_BUFFER = 34962, 34963
COMPONENTS = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT4": 16}
CTYPE = {5120: ("b", 1), 5121: ("B", 1), 5122: ("h", 2), 5123: ("H", 2),
         5125: ("I", 4), 5126: ("f", 4)}


def f32(x):
    """The shortest decimal that reads back as the same float32 as x."""
    v = struct.unpack("<f", struct.pack("<f", x))[0]
    if v == 0.0:
        return 0.0
    for digits in range(1, 10):
        s = float("%.*g" % (digits, v))
        if struct.unpack("<f", struct.pack("<f", s))[0] == v:
            return s
    return v


def f32s(values):
    return [f32(v) for v in values]


# ---------------------------------------------------------------- vector helpers

def sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def normalize(v):
    n = math.sqrt(dot(v, v))
    return (v[0] / n, v[1] / n, v[2] / n)


def quat_axis_angle(axis, angle):
    ax = normalize(axis)
    s = math.sin(angle / 2)
    return (ax[0] * s, ax[1] * s, ax[2] * s, math.cos(angle / 2))


def quat_to_matrix(q):
    x, y, z, w = q
    return ((1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)),
            (2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)),
            (2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)))


def quat_look(direction):
    """Unit quaternion turning -Z (the camera's and the directional light's forward) to
    `direction`, keeping +Y as up as far as possible (yaw, then pitch)."""
    d = normalize(direction)
    yaw = math.atan2(-d[0], -d[2])
    pitch = math.asin(max(-1.0, min(1.0, d[1])))
    qy = quat_axis_angle((0, 1, 0), yaw)
    qx = quat_axis_angle((1, 0, 0), pitch)
    return quat_mul(qy, qx)


def quat_mul(a, b):
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return (aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
            aw * bw - ax * bx - ay * by - az * bz)


def mat_vec(m, v):
    return (dot(m[0], v), dot(m[1], v), dot(m[2], v))


# ---------------------------------------------------------------- meshes

class Mesh:
    """Indexed triangles with per-vertex normals (and uvs, where set), as flat lists."""

    def __init__(self):
        self.pos = []
        self.nrm = []
        self.idx = []
        self.uv = []  # empty, or 2 per vertex
        self.joints = []   # empty, or 4 joint indices per vertex (a skin's)
        self.weights = []  # with joints: 4 weights per vertex, adding to 1
        self.targets = []  # morph targets: per target a list of 3 position deltas per vertex
        self.target_weights = []  # the mesh's default morph weights

    @property
    def vertex_count(self):
        return len(self.pos) // 3

    @property
    def triangle_count(self):
        return len(self.idx) // 3

    def add(self, other, rotation=None, translation=(0.0, 0.0, 0.0)):
        """Appends `other`, optionally moved rigidly (rotation is a quaternion)."""
        base = self.vertex_count
        if other.uv or self.uv:
            if not self.uv:
                self.uv = [0.0] * (2 * base)
            self.uv += other.uv if other.uv else [0.0] * (2 * other.vertex_count)
        m = quat_to_matrix(rotation) if rotation else None
        tx, ty, tz = translation
        p, n = other.pos, other.nrm
        for i in range(0, len(p), 3):
            if m:
                q = mat_vec(m, (p[i], p[i + 1], p[i + 2]))
                r = mat_vec(m, (n[i], n[i + 1], n[i + 2]))
            else:
                q = (p[i], p[i + 1], p[i + 2])
                r = (n[i], n[i + 1], n[i + 2])
            self.pos += (q[0] + tx, q[1] + ty, q[2] + tz)
            self.nrm += r
        self.idx += [i + base for i in other.idx]
        return self


def grid(f, nu, nv, normal=None, flip=False, eps=1e-4):
    """Surface f(u, v) -> point over [0,1]^2 as nu x nv quads. Normals are `normal(u, v)`
    or the normalised cross(df/du, df/dv) by central differences; the winding follows the
    same cross product (reversed with flip). Zero-area triangles (at poles) are dropped."""
    m = Mesh()
    for j in range(nv + 1):
        v = j / nv
        for i in range(nu + 1):
            u = i / nu
            p = f(u, v)
            if normal:
                n = normalize(normal(u, v))
            else:
                du = sub(f(u + eps, v), f(u - eps, v))
                dv = sub(f(u, v + eps), f(u, v - eps))
                n = normalize(cross(du, dv))
            if flip:
                n = (-n[0], -n[1], -n[2])
            m.pos += p
            m.nrm += n
    row = nu + 1
    for j in range(nv):
        for i in range(nu):
            a, b = j * row + i, j * row + i + 1
            c, d = b + row, a + row
            for tri in ((a, b, c), (a, c, d)):
                if flip:
                    tri = (tri[0], tri[2], tri[1])
                if _area2(m.pos, tri) > 1e-14:
                    m.idx += tri
    return m


def _area2(pos, tri):
    p = [(pos[3 * k], pos[3 * k + 1], pos[3 * k + 2]) for k in tri]
    c = cross(sub(p[1], p[0]), sub(p[2], p[0]))
    return dot(c, c)


def quad(origin, eu, ev, nu=1, nv=1):
    """Parallelogram origin + u*eu + v*ev; faces along cross(eu, ev)."""
    return grid(lambda u, v: (origin[0] + u * eu[0] + v * ev[0],
                              origin[1] + u * eu[1] + v * ev[1],
                              origin[2] + u * eu[2] + v * ev[2]), nu, nv,
                normal=lambda u, v: cross(eu, ev))


def box(lo, hi):
    """Axis-aligned box with flat, outward normals (24 vertices, 12 triangles)."""
    x0, y0, z0 = lo
    x1, y1, z1 = hi
    dx, dy, dz = x1 - x0, y1 - y0, z1 - z0
    m = Mesh()
    m.add(quad((x1, y0, z1), (0, 0, -dz), (0, dy, 0)))   # +x
    m.add(quad((x0, y0, z0), (0, 0, dz), (0, dy, 0)))    # -x
    m.add(quad((x0, y1, z1), (dx, 0, 0), (0, 0, -dz)))   # +y
    m.add(quad((x0, y0, z0), (dx, 0, 0), (0, 0, dz)))    # -y
    m.add(quad((x0, y0, z1), (dx, 0, 0), (0, dy, 0)))    # +z
    m.add(quad((x1, y0, z0), (-dx, 0, 0), (0, dy, 0)))   # -z
    return m


def uv_sphere(radius, segments, rings, u0=0.0, u1=1.0):
    """Sphere (or the longitude band u0..u1 of one) with smooth normals."""
    def f(u, v):
        phi = 2 * math.pi * (u0 + (u1 - u0) * u)
        theta = math.pi * v
        return (radius * math.sin(theta) * math.cos(phi), radius * math.cos(theta),
                radius * math.sin(theta) * math.sin(phi))

    def n(u, v):
        p = f(u, v)
        return p if dot(p, p) > 0 else (0.0, 1.0 if v < 0.5 else -1.0, 0.0)
    return grid(f, segments, rings, normal=n)


def lathe(profile, segments, flutes=0, flute_depth=0.0):
    """Surface of revolution about +Y of profile [(y, r, flute_weight), ...] from bottom to
    top; flutes modulate the radius by flute_weight * flute_depth * cos(flutes * angle)."""
    m = Mesh()
    rows = len(profile)
    ring = []
    for j, (y, r, fw) in enumerate(profile):
        pts = []
        for i in range(segments + 1):
            a = 2 * math.pi * i / segments
            k = 1 + fw * flute_depth * math.cos(flutes * a)
            dk = -r * fw * flute_depth * flutes * math.sin(flutes * a)
            rr = r * k
            pts.append(((rr * math.cos(a), y, -rr * math.sin(a)),
                        (dk * math.cos(a) - rr * math.sin(a), 0.0,
                         -dk * math.sin(a) - rr * math.cos(a))))
        ring.append(pts)
    for j in range(rows):
        jm, jp = max(j - 1, 0), min(j + 1, rows - 1)
        for i in range(segments + 1):
            p, tu = ring[j][i]
            tv = sub(ring[jp][i][0], ring[jm][i][0])
            m.pos += p
            m.nrm += normalize(cross(tu, tv))
    row = segments + 1
    for j in range(rows - 1):
        for i in range(segments):
            a, b = j * row + i, j * row + i + 1
            c, d = b + row, a + row
            for tri in ((a, b, c), (a, c, d)):
                if _area2(m.pos, tri) > 1e-14:
                    m.idx += tri
    return m


# ---------------------------------------------------------------- writer

class Gltf:
    """Collects a glTF document and its one binary buffer."""

    def __init__(self, generator):
        self.doc = {"asset": {"version": "2.0", "generator": generator}}
        self.bin = bytearray()
        self.extensions = set()
        self._inputs = {}

    def _list(self, key):
        return self.doc.setdefault(key, [])

    def _append(self, key, item):
        lst = self._list(key)
        lst.append(item)
        return len(lst) - 1

    def accessor(self, values, ctype, atype, target=None, minmax=False):
        fmt = CTYPE[ctype][0]
        data = struct.pack("<%d%s" % (len(values), fmt), *values)
        while len(self.bin) % 4:
            self.bin.append(0)
        view = {"buffer": 0, "byteOffset": len(self.bin), "byteLength": len(data)}
        if target:
            view["target"] = target
        self.bin += data
        ncomp = COMPONENTS[atype]
        acc = {"bufferView": self._append("bufferViews", view), "componentType": ctype,
               "count": len(values) // ncomp, "type": atype}
        if minmax:
            stored = struct.unpack("<%d%s" % (len(values), fmt), data)
            cols = [stored[c::ncomp] for c in range(ncomp)]
            conv = f32 if ctype == FLOAT else int
            acc["min"] = [conv(min(c)) for c in cols]
            acc["max"] = [conv(max(c)) for c in cols]
        return self._append("accessors", acc)

    def png_texture(self, name, png):
        """A texture (repeating, linear filtering) of PNG bytes stored in the buffer."""
        while len(self.bin) % 4:
            self.bin.append(0)
        view = self._append("bufferViews", {"buffer": 0, "byteOffset": len(self.bin),
                                            "byteLength": len(png)})
        self.bin += png
        image = self._append("images", {"name": name, "bufferView": view,
                                        "mimeType": "image/png"})
        if "samplers" not in self.doc:
            self._append("samplers", {"magFilter": 9729, "minFilter": 9729})
        return self._append("textures", {"name": name, "sampler": 0, "source": image})

    def material(self, name, base, metallic=0.0, roughness=1.0, emissive=None,
                 strength=None, double_sided=False, normal_texture=None, extensions=None):
        """extensions: more KHR_materials_* objects by name (e.g. KHR_materials_specular)."""
        mat = {"name": name, "pbrMetallicRoughness": {
            "baseColorFactor": list(base) + [1.0] if len(base) == 3 else list(base),
            "metallicFactor": metallic, "roughnessFactor": roughness}}
        if emissive:
            mat["emissiveFactor"] = list(emissive)
        if strength is not None:
            mat["extensions"] = {"KHR_materials_emissive_strength":
                                 {"emissiveStrength": strength}}
            self.extensions.add("KHR_materials_emissive_strength")
        if double_sided:
            mat["doubleSided"] = True
        if normal_texture is not None:
            mat["normalTexture"] = {"index": normal_texture}
        for ext, value in (extensions or {}).items():
            mat.setdefault("extensions", {})[ext] = value
            self.extensions.add(ext)
        return self._append("materials", mat)

    def mesh(self, name, primitives):
        """primitives: [(Mesh, material index), ...]"""
        prims = []
        for m, mat in primitives:
            pos = self.accessor(m.pos, FLOAT, "VEC3", ARRAY_BUFFER, minmax=True)
            nrm = self.accessor(m.nrm, FLOAT, "VEC3", ARRAY_BUFFER)
            ctype = USHORT if m.vertex_count <= 65535 else UINT
            idx = self.accessor(m.idx, ctype, "SCALAR", ELEMENT_ARRAY_BUFFER)
            attrs = {"POSITION": pos, "NORMAL": nrm}
            if m.uv:
                attrs["TEXCOORD_0"] = self.accessor(m.uv, FLOAT, "VEC2", ARRAY_BUFFER)
            if m.joints:
                attrs["JOINTS_0"] = self.accessor(m.joints, UBYTE, "VEC4", ARRAY_BUFFER)
                attrs["WEIGHTS_0"] = self.accessor(m.weights, FLOAT, "VEC4", ARRAY_BUFFER)
            prim = {"attributes": attrs, "indices": idx, "material": mat, "mode": 4}
            if m.targets:
                prim["targets"] = [{"POSITION": self.accessor(d, FLOAT, "VEC3", ARRAY_BUFFER,
                                                              minmax=True)}
                                   for d in m.targets]
            prims.append(prim)
        mesh = {"name": name, "primitives": prims}
        weights = next((m.target_weights for m, _ in primitives if m.target_weights), None)
        if weights:
            mesh["weights"] = f32s(weights)
        return self._append("meshes", mesh)

    def skin(self, name, joints, inverse_binds):
        """joints: node indices; inverse_binds: a column-major 4x4 (16 floats) per joint."""
        ibm = self.accessor([f32(x) for m in inverse_binds for x in m], FLOAT, "MAT4")
        return self._append("skins", {"name": name, "joints": list(joints),
                                      "inverseBindMatrices": ibm})

    def node(self, name, mesh=None, camera=None, translation=None, rotation=None,
             children=None, extras=None, extensions=None, skin=None):
        n = {"name": name}
        if mesh is not None:
            n["mesh"] = mesh
        if skin is not None:
            n["skin"] = skin
        if camera is not None:
            n["camera"] = camera
        if children:
            n["children"] = list(children)
        if translation is not None:
            n["translation"] = f32s(translation)
        if rotation is not None:
            n["rotation"] = f32s(normalize4(rotation))
        if extensions:
            n["extensions"] = extensions
        if extras:
            n["extras"] = extras
        return self._append("nodes", n)

    def camera(self, name, yfov, aspect, znear, zfar=None):
        p = {"yfov": f32(yfov), "aspectRatio": f32(aspect), "znear": f32(znear)}
        if zfar:
            p["zfar"] = f32(zfar)
        return self._append("cameras", {"name": name, "type": "perspective",
                                        "perspective": p})

    def directional_light(self, name, color, intensity):
        self.extensions.add("KHR_lights_punctual")
        ext = self.doc.setdefault("extensions", {}).setdefault(
            "KHR_lights_punctual", {"lights": []})
        ext["lights"].append({"name": name, "type": "directional", "color": list(color),
                              "intensity": intensity})
        return len(ext["lights"]) - 1

    def animation(self, name, channels):
        """channels: [(node, path, times, values), ...], LINEAR; values are tuples (for
        "weights", one weight per morph target)."""
        samplers, chans = [], []
        for node, path, times, values in channels:
            key = tuple(times)
            if key not in self._inputs:
                self._inputs[key] = self.accessor(list(times), FLOAT, "SCALAR", minmax=True)
            if path == "rotation":
                values = [normalize4(q) for q in values]
            flat = [c for v in values for c in v]
            kind = {"rotation": "VEC4", "weights": "SCALAR"}.get(path, "VEC3")
            out = self.accessor(flat, FLOAT, kind)
            samplers.append({"input": self._inputs[key], "output": out,
                             "interpolation": "LINEAR"})
            chans.append({"sampler": len(samplers) - 1,
                          "target": {"node": node, "path": path}})
        return self._append("animations", {"name": name, "channels": chans,
                                           "samplers": samplers})

    def finish(self, scene_nodes, uri):
        while len(self.bin) % 4:
            self.bin.append(0)
        self.doc["scene"] = 0
        self.doc["scenes"] = [{"name": "Scene", "nodes": list(scene_nodes)}]
        self.doc["buffers"] = [{"byteLength": len(self.bin), "uri": uri}]
        if self.extensions:
            self.doc["extensionsUsed"] = sorted(self.extensions)
        order = ["asset", "extensionsUsed", "extensions", "scene", "scenes", "nodes",
                 "cameras", "meshes", "skins", "materials", "textures", "images", "samplers",
                 "animations", "accessors",
                 "bufferViews", "buffers"]
        return {k: self.doc[k] for k in order if k in self.doc}

    def write(self, path, scene_nodes, embedded):
        """Writes path (.gltf); the buffer goes into a data: URI or next to it as .bin."""
        if embedded:
            uri = "data:application/octet-stream;base64," + base64.b64encode(
                bytes(self.bin)).decode("ascii")
        else:
            uri = os.path.splitext(os.path.basename(path))[0] + ".bin"
        doc = self.finish(scene_nodes, uri)
        text = _SCALAR_LIST.sub(lambda m: "[" + ", ".join(
            t.rstrip(",") for t in m.group(1).split()) + "]",
                                json.dumps(doc, indent=1, ensure_ascii=True)) + "\n"
        with open(path, "w", encoding="ascii", newline="\n") as fh:
            fh.write(text)
        if not embedded:
            with open(os.path.join(os.path.dirname(path) or ".", uri), "wb") as fh:
                fh.write(self.bin)


def png_rgb(width, height, pixel):
    """PNG bytes of an 8-bit RGB image; pixel(x, y) gives (r, g, b), each 0-255."""
    raw = b"".join(b"\x00" + bytes(c for x in range(width) for c in pixel(x, y))
                   for y in range(height))

    def chunk(kind, data):
        return (struct.pack(">I", len(data)) + kind + data
                + struct.pack(">I", zlib.crc32(kind + data) & 0xffffffff))
    return (b"\x89PNG\r\n\x1a\n"
            + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0))
            + chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b""))


# a JSON list holding only numbers/literals, to be printed on one line
_SCALAR_LIST = re.compile(r"\[\s*([-+.\deEtrufalsn,\s]*?)\s*\]")


def _as32(x):
    return struct.unpack("<f", struct.pack("<f", x))[0]


def normalize4(q):
    n = math.sqrt(sum(c * c for c in q))
    return tuple(c / n for c in q)


# ---------------------------------------------------------------- validator

class Invalid(Exception):
    pass


def _check(cond, msg):
    if not cond:
        raise Invalid(msg)


def _walk_extensions(obj, found):
    if isinstance(obj, dict):
        for k, v in obj.items():
            if k == "extensions" and isinstance(v, dict):
                found.update(v.keys())
            _walk_extensions(v, found)
    elif isinstance(obj, list):
        for v in obj:
            _walk_extensions(v, found)


def validate(path):
    """Re-reads a .gltf written above and checks it. Returns a summary dict; raises
    Invalid naming the first problem."""
    with open(path, encoding="utf-8") as fh:
        doc = json.load(fh)
    _check(doc.get("asset", {}).get("version") == "2.0", "asset.version is not 2.0")

    buffers = []
    for b, buf in enumerate(doc.get("buffers", [])):
        uri = buf.get("uri", "")
        if uri.startswith("data:"):
            _check(uri.startswith("data:application/octet-stream;base64,"),
                   "buffers[%d]: unexpected data URI type" % b)
            data = base64.b64decode(uri.split(",", 1)[1], validate=True)
        else:
            with open(os.path.join(os.path.dirname(path), uri), "rb") as fh:
                data = fh.read()
        _check(len(data) == buf["byteLength"],
               "buffers[%d]: byteLength %d but %d bytes" % (b, buf["byteLength"], len(data)))
        buffers.append(data)

    views = doc.get("bufferViews", [])
    for v, view in enumerate(views):
        _check(0 <= view["buffer"] < len(buffers), "bufferViews[%d]: bad buffer" % v)
        _check(view.get("byteOffset", 0) + view["byteLength"] <= len(buffers[view["buffer"]]),
               "bufferViews[%d]: runs past its buffer" % v)
        _check("byteStride" not in view, "bufferViews[%d]: unexpected byteStride" % v)

    def read(a):
        acc = doc["accessors"][a]
        fmt, size = CTYPE[acc["componentType"]]
        ncomp = COMPONENTS[acc["type"]]
        view = views[acc["bufferView"]]
        start = view.get("byteOffset", 0) + acc.get("byteOffset", 0)
        need = acc["count"] * ncomp * size
        _check(acc.get("byteOffset", 0) + need <= view["byteLength"],
               "accessors[%d]: runs past bufferView %d" % (a, acc["bufferView"]))
        _check(start % size == 0, "accessors[%d]: misaligned" % a)
        vals = struct.unpack_from("<%d%s" % (acc["count"] * ncomp, fmt),
                                  buffers[view["buffer"]], start)
        if "min" in acc or "max" in acc:
            cols = [vals[c::ncomp] for c in range(ncomp)]
            _check([_as32(x) for x in acc.get("min", [])] == [min(c) for c in cols] and
                   [_as32(x) for x in acc.get("max", [])] == [max(c) for c in cols],
                   "accessors[%d]: min/max do not match the data" % a)
        return acc, vals

    cache = {}

    def get(a):
        _check(0 <= a < len(doc.get("accessors", [])), "accessor %d does not exist" % a)
        if a not in cache:
            cache[a] = read(a)
        return cache[a]

    for a in range(len(doc.get("accessors", []))):
        get(a)

    # mesh triangles: bounds, indices, normals, winding
    mesh_tris = []
    nmat = len(doc.get("materials", []))
    for mi, mesh in enumerate(doc.get("meshes", [])):
        tris = 0
        for pi, prim in enumerate(mesh["primitives"]):
            where = "meshes[%d].primitives[%d]" % (mi, pi)
            _check(prim.get("mode", 4) == 4, where + ": not TRIANGLES")
            _check(0 <= prim.get("material", 0) < max(nmat, 1), where + ": bad material")
            pacc, pos = get(prim["attributes"]["POSITION"])
            _check(pacc["type"] == "VEC3" and pacc["componentType"] == FLOAT,
                   where + ": POSITION is not float VEC3")
            _check("min" in pacc and "max" in pacc, where + ": POSITION lacks min/max")
            _check("NORMAL" in prim["attributes"], where + ": no NORMAL")
            nacc, nrm = get(prim["attributes"]["NORMAL"])
            _check(nacc["count"] == pacc["count"], where + ": NORMAL count != POSITION")
            for k in range(0, len(nrm), 3):
                ln = math.sqrt(nrm[k] ** 2 + nrm[k + 1] ** 2 + nrm[k + 2] ** 2)
                _check(abs(ln - 1) < 1e-4, where + ": normal %d is not unit" % (k // 3))
            iacc, idx = get(prim["indices"])
            _check(iacc["componentType"] in (5121, USHORT, UINT) and iacc["type"] == "SCALAR",
                   where + ": bad index type")
            _check(views[iacc["bufferView"]].get("target") == ELEMENT_ARRAY_BUFFER,
                   where + ": index bufferView lacks target 34963")
            _check(len(idx) % 3 == 0, where + ": index count not a multiple of 3")
            _check(max(idx) < pacc["count"], where + ": index out of range")
            for t in range(0, len(idx), 3):
                ia, ib, ic = idx[t], idx[t + 1], idx[t + 2]
                pa = pos[3 * ia:3 * ia + 3]
                g = cross(sub(pos[3 * ib:3 * ib + 3], pa), sub(pos[3 * ic:3 * ic + 3], pa))
                _check(dot(g, g) > 0, where + ": triangle %d is degenerate" % (t // 3))
                ns = [nrm[3 * ia + c] + nrm[3 * ib + c] + nrm[3 * ic + c] for c in range(3)]
                _check(dot(g, ns) > 0,
                       where + ": triangle %d winding disagrees with its normals" % (t // 3))
            tris += len(idx) // 3
        mesh_tris.append(tris)

    # nodes: tree, references, unit rotations
    nodes = doc.get("nodes", [])
    parent = {}
    for n, node in enumerate(nodes):
        _check("matrix" not in node or not any(k in node for k in
               ("translation", "rotation", "scale")), "nodes[%d]: matrix and TRS" % n)
        if "rotation" in node:
            q = node["rotation"]
            _check(abs(math.sqrt(sum(c * c for c in q)) - 1) < 1e-5,
                   "nodes[%d]: rotation not a unit quaternion" % n)
        if "mesh" in node:
            _check(0 <= node["mesh"] < len(mesh_tris), "nodes[%d]: bad mesh" % n)
        if "camera" in node:
            _check(0 <= node["camera"] < len(doc.get("cameras", [])),
                   "nodes[%d]: bad camera" % n)
        for c in node.get("children", []):
            _check(0 <= c < len(nodes) and c not in parent and c != n,
                   "nodes[%d]: bad or shared child %d" % (n, c))
            parent[c] = n
    roots = doc["scenes"][doc.get("scene", 0)]["nodes"]
    for r in roots:
        _check(r not in parent, "scene root %d is also a child" % r)
    seen = set()
    stack = list(roots)
    while stack:
        n = stack.pop()
        _check(n not in seen, "node %d reached twice (cycle)" % n)
        seen.add(n)
        stack += nodes[n].get("children", [])
    _check(seen == set(range(len(nodes))), "some nodes are not in the scene")

    # animations
    animated = set()
    duration = 0.0
    for ai, anim in enumerate(doc.get("animations", [])):
        for ci, ch in enumerate(anim["channels"]):
            where = "animations[%d].channels[%d]" % (ai, ci)
            smp = anim["samplers"][ch["sampler"]]
            target = ch["target"]
            _check(0 <= target["node"] < len(nodes), where + ": bad node")
            _check(target["path"] in ("translation", "rotation", "scale", "weights"),
                   where + ": unexpected path")
            animated.add(target["node"])
            iacc, t = get(smp["input"])
            _check("min" in iacc and "max" in iacc, where + ": input lacks min/max")
            _check(t[0] >= 0, where + ": negative time")
            _check(all(t[k] < t[k + 1] for k in range(len(t) - 1)),
                   where + ": input not strictly increasing")
            oacc, out = get(smp["output"])
            _check(smp.get("interpolation", "LINEAR") == "LINEAR",
                   where + ": only LINEAR is written")
            if target["path"] == "weights":
                mesh = doc["meshes"][nodes[target["node"]]["mesh"]]
                n = len(mesh["primitives"][0].get("targets", []))
                _check(n > 0 and oacc["count"] == n * iacc["count"],
                       where + ": weights output count != targets x input count")
                duration = max(duration, t[-1])
                continue
            _check(oacc["count"] == iacc["count"], where + ": output count != input count")
            if target["path"] == "rotation":
                _check(oacc["type"] == "VEC4", where + ": rotation output not VEC4")
                for k in range(0, len(out), 4):
                    ln = math.sqrt(sum(c * c for c in out[k:k + 4]))
                    _check(abs(ln - 1) < 1e-5, where + ": key %d not a unit quaternion" % (k // 4))
            else:
                _check(oacc["type"] == "VEC3", where + ": output not VEC3")
            duration = max(duration, t[-1])

    def dynamic(n):
        if "skin" in nodes[n]:
            return True  # placed by its joints
        while True:
            if n in animated or nodes[n].get("extras", {}).get("dynamic"):
                return True
            if n not in parent:
                return False
            n = parent[n]

    static_tris = dynamic_tris = 0
    for n, node in enumerate(nodes):
        if "mesh" in node:
            if dynamic(n):
                dynamic_tris += mesh_tris[node["mesh"]]
            else:
                static_tris += mesh_tris[node["mesh"]]

    # extensions and materials
    found = set()
    _walk_extensions(doc, found)
    used = set(doc.get("extensionsUsed", []))
    _check(found == used, "extensionsUsed %s but the file uses %s" % (sorted(used), sorted(found)))
    _check(set(doc.get("extensionsRequired", [])) <= used, "extensionsRequired not in Used")
    for mi, mat in enumerate(doc.get("materials", [])):
        pbr = mat.get("pbrMetallicRoughness", {})
        vals = pbr.get("baseColorFactor", []) + mat.get("emissiveFactor", []) + [
            pbr.get("metallicFactor", 1), pbr.get("roughnessFactor", 1)]
        _check(all(0 <= x <= 1 for x in vals), "materials[%d]: factor outside [0,1]" % mi)
    lights = doc.get("extensions", {}).get("KHR_lights_punctual", {}).get("lights", [])
    for n, node in enumerate(nodes):
        ext = node.get("extensions", {}).get("KHR_lights_punctual")
        if ext:
            _check(0 <= ext["light"] < len(lights), "nodes[%d]: bad light" % n)

    return {"triangles": static_tris + dynamic_tris, "static": static_tris,
            "dynamic": dynamic_tris, "duration": duration,
            "bytes": os.path.getsize(path) + sum(
                len(b) for b, buf in zip(buffers, doc["buffers"])
                if not buf.get("uri", "").startswith("data:"))}
