"""Writes lit wrappers of real glTF assets for the benchmark on real animations
(tools/bench/bench_animations.py). A wrapper is a .gltf of its own (and a small .bin of what it
adds) whose buffers and images name the asset's files where they are, so nothing is copied; a
renderer reads it with pathreuse's --allow-outside-uris.

  python3 -m tools.scenes.gen_real_scenes vc ../shared/scenes/VC/VC.gltf --out /tmp/vc/vc-lit.gltf
  python3 -m tools.scenes.gen_real_scenes brainstem ../shared/scenes/BrainStem/BrainStem.gltf \\
      --out /tmp/brainstem/brainstem-stage.gltf

vc         The Virtual City under a sun, with its sky dome's walls emitting their own texture
           and the dome's roof taken away, so that the sky (a uniform environment the renderer
           adds) and the sun light the streets. Its sky is a closed dome of opaque textured
           walls meant to be drawn unlit; lit by nothing it renders black. Every camera is
           named camera<i> (as the renderers' --camera pick them) and one camera is added:
           "still6", camera 6 held where it is at --still-frame.
brainstem  The skinned BrainStem walking on a grey floor before a back wall, with two cameras:
           "front" held still, and "orbit" circling it (10 degrees a second) as it walks.
framed     Any asset as it is, with a camera "front" added that frames its bounding box (at
           time 0) from the front (+Z), a little above, square: for comparing one still image
           of it with a peer (tools/bench/asset_compare.py).
"""

import argparse
import base64
import json
import math
import os
import struct
import sys

from . import gltf_writer as gw

FPS = 24.0
COMPONENTS = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT4": 16}
FORMATS = {5126: "f", 5125: "I", 5123: "H", 5121: "B"}


class Asset:
    """A .gltf whose buffers are files or base64 data URIs: its JSON, and accessors read from
    its buffers."""

    def __init__(self, path):
        self.path = os.path.abspath(path)
        self.dir = os.path.dirname(self.path)
        with open(self.path, encoding="utf-8") as f:
            self.doc = json.load(f)
        self.buffers = []
        for b in self.doc["buffers"]:
            uri = b.get("uri", "")
            if uri.startswith("data:"):
                head, _, payload = uri.partition(",")
                if not head.endswith(";base64"):
                    raise gw.Invalid(f"{path}: a buffer's data URI is not base64")
                self.buffers.append(base64.b64decode(payload))
                continue
            if not uri:
                raise gw.Invalid(f"{path}: a buffer has no uri (a .glb's)")
            with open(os.path.join(self.dir, uri), "rb") as f:
                self.buffers.append(f.read())

    def read(self, index):
        """Accessor `index` as a list of tuples (or of numbers for SCALAR)."""
        a = self.doc["accessors"][index]
        view = self.doc["bufferViews"][a["bufferView"]]
        n, fmt = COMPONENTS[a["type"]], FORMATS[a["componentType"]]
        size = struct.calcsize("<" + fmt)
        stride = view.get("byteStride") or n * size
        base = view.get("byteOffset", 0) + a.get("byteOffset", 0)
        data = self.buffers[view["buffer"]]
        out = [struct.unpack_from("<" + fmt * n, data, base + k * stride) for k in range(a["count"])]
        return [v[0] for v in out] if n == 1 else out

    def rebase(self, out_dir):
        """Buffer and image URIs relative to out_dir, where the wrapper is written."""
        for b in self.doc["buffers"]:
            if not b["uri"].startswith("data:"):
                b["uri"] = os.path.relpath(os.path.join(self.dir, b["uri"]), out_dir)
        for im in self.doc.get("images", []):
            if "uri" in im and not im["uri"].startswith("data:"):
                im["uri"] = os.path.relpath(os.path.join(self.dir, im["uri"]), out_dir)


class Extra:
    """What a wrapper adds to its asset's buffers: one more buffer, written beside it."""

    def __init__(self, doc):
        self.doc, self.data = doc, bytearray()
        self.buffer = len(doc["buffers"])

    def accessor(self, values, component, kind, minmax=False, target=None):
        fmt = FORMATS[component]
        flat = [x for v in values for x in (v if isinstance(v, (tuple, list)) else (v,))]
        while len(self.data) % 4:
            self.data.append(0)
        view = {"buffer": self.buffer, "byteOffset": len(self.data),
                "byteLength": struct.calcsize("<" + fmt) * len(flat)}
        if target:
            view["target"] = target
        self.data += struct.pack("<%d%s" % (len(flat), fmt), *flat)
        self.doc["bufferViews"].append(view)
        acc = {"bufferView": len(self.doc["bufferViews"]) - 1, "componentType": component,
               "count": len(values), "type": kind}
        if minmax:
            n = COMPONENTS[kind]
            cols = [[v[c] if n > 1 else v for v in values] for c in range(n)]
            acc["min"], acc["max"] = [min(c) for c in cols], [max(c) for c in cols]
        self.doc["accessors"].append(acc)
        return len(self.doc["accessors"]) - 1

    def write(self, out):
        """The wrapper, and its .bin where it added data (glTF allows no empty buffer)."""
        while len(self.data) % 4:
            self.data.append(0)
        bin_path = os.path.splitext(out)[0] + ".bin"
        os.makedirs(os.path.dirname(os.path.abspath(out)), exist_ok=True)
        if self.data:
            self.doc["buffers"].append({"byteLength": len(self.data),
                                        "uri": os.path.basename(bin_path)})
            with open(bin_path + ".tmp", "wb") as f:
                f.write(self.data)
            os.replace(bin_path + ".tmp", bin_path)
        with open(out + ".tmp", "w", encoding="utf-8") as f:
            json.dump(self.doc, f, indent=1)
        os.replace(out + ".tmp", out)


# Column-major 4x4 matrices, as glTF stores them.
def mat_mul(a, b):
    return [sum(a[r + 4 * k] * b[k + 4 * c] for k in range(4)) for c in range(4) for r in range(4)]


def trs_matrix(t, q, s):
    r = gw.quat_to_matrix(q)
    m = [0.0] * 16
    for c in range(3):
        for row in range(3):
            m[row + 4 * c] = r[row][c] * s[c]
    m[12], m[13], m[14], m[15] = t[0], t[1], t[2], 1.0
    return m


def slerp(a, b, u):
    d = sum(x * y for x, y in zip(a, b))
    if d < 0.0:
        b, d = tuple(-x for x in b), -d
    if d > 0.9995:
        q = tuple(x + u * (y - x) for x, y in zip(a, b))
    else:
        th = math.acos(d)
        wa, wb = math.sin((1 - u) * th) / math.sin(th), math.sin(u * th) / math.sin(th)
        q = tuple(wa * x + wb * y for x, y in zip(a, b))
    n = math.sqrt(sum(x * x for x in q))
    return tuple(x / n for x in q)


def sample(asset, sampler, t):
    """An animation sampler's value at time t (LINEAR or STEP, clamped at its ends)."""
    times, values = asset.read(sampler["input"]), asset.read(sampler["output"])
    mode = sampler.get("interpolation", "LINEAR")
    if mode not in ("LINEAR", "STEP"):
        raise gw.Invalid(f"{mode} sampling is not supported here")
    if t <= times[0]:
        return values[0]
    if t >= times[-1]:
        return values[-1]
    k = next(i for i in range(1, len(times)) if times[i] >= t)
    if mode == "STEP":
        return values[k - 1]
    u = (t - times[k - 1]) / (times[k] - times[k - 1])
    a, b = values[k - 1], values[k]
    if len(a) == 4:
        return slerp(a, b, u)
    return tuple(x + u * (y - x) for x, y in zip(a, b))


def local_matrix(asset, node, t):
    n = asset.doc["nodes"][node]
    if "matrix" in n:
        return list(n["matrix"])
    trs = {"translation": tuple(n.get("translation", (0, 0, 0))),
           "rotation": tuple(n.get("rotation", (0, 0, 0, 1))),
           "scale": tuple(n.get("scale", (1, 1, 1)))}
    for anim in asset.doc.get("animations", []):
        for ch in anim["channels"]:
            if ch["target"].get("node") == node and ch["target"]["path"] in trs:
                trs[ch["target"]["path"]] = sample(asset, anim["samplers"][ch["sampler"]], t)
    return trs_matrix(trs["translation"], trs["rotation"], trs["scale"])


def world_matrix(asset, node, t):
    parent = {c: i for i, n in enumerate(asset.doc["nodes"]) for c in n.get("children", [])}
    m = local_matrix(asset, node, t)
    while node in parent:
        node = parent[node]
        m = mat_mul(local_matrix(asset, node, t), m)
    return m


def add_sun(doc, direction, color, irradiance):
    ext = doc.setdefault("extensions", {}).setdefault("KHR_lights_punctual", {"lights": []})
    ext["lights"].append({"name": "sun", "type": "directional", "color": list(color),
                          "intensity": irradiance})
    used = doc.setdefault("extensionsUsed", [])
    if "KHR_lights_punctual" not in used:
        used.append("KHR_lights_punctual")
    doc["nodes"].append({"name": "sun", "rotation": list(gw.quat_look(direction)),
                         "extensions": {"KHR_lights_punctual": {"light": len(ext["lights"]) - 1}}})
    return len(doc["nodes"]) - 1


def light_vc(asset, extra, args):
    doc = asset.doc
    sky_images = {i for i, im in enumerate(doc["images"])
                  if os.path.basename(im.get("uri", "")).startswith("s_0")}
    sky_textures = {i for i, t in enumerate(doc["textures"]) if t.get("source") in sky_images}
    sky = set()
    for i, m in enumerate(doc["materials"]):
        tex = m.get("pbrMetallicRoughness", {}).get("baseColorTexture", {}).get("index")
        if tex in sky_textures:
            sky.add(i)
            m["emissiveTexture"] = {"index": tex}
            m["emissiveFactor"] = [1.0, 1.0, 1.0]
            m.setdefault("extensions", {})["KHR_materials_emissive_strength"] = {
                "emissiveStrength": args.sky_strength}
            m["pbrMetallicRoughness"]["baseColorFactor"] = [0.0, 0.0, 0.0, 1.0]
            m.pop("occlusionTexture", None)
    if len(sky) != 8:
        raise gw.Invalid(f"expected the 8 sky dome materials, found {len(sky)}")
    used = doc.setdefault("extensionsUsed", [])
    used.append("KHR_materials_emissive_strength")
    cut = 0
    for mesh in doc["meshes"]:
        for prim in mesh["primitives"]:
            if prim.get("material") not in sky:
                continue
            pos, idx = asset.read(prim["attributes"]["POSITION"]), asset.read(prim["indices"])
            walls = []
            for k in range(0, len(idx), 3):
                a, b, c = (pos[i] for i in idx[k:k + 3])
                n = gw.cross(gw.sub(b, a), gw.sub(c, a))
                if abs(n[2]) < 0.5 * math.sqrt(gw.dot(n, n)):  # the dome's z is up: walls only
                    walls += idx[k:k + 3]
            cut += (len(idx) - len(walls)) // 3
            prim["indices"] = extra.accessor(walls, 5125, "SCALAR", target=34963)
    nodes, cams = doc["nodes"], doc["cameras"]
    for i, c in enumerate(cams):
        c["name"] = f"camera{i}"
    holder = {n["camera"]: i for i, n in enumerate(nodes) if "camera" in n}
    for c, i in holder.items():
        nodes[i]["name"] = f"camera{c}"
    still = dict(cams[6], name="still6")
    cams.append(still)
    nodes.append({"name": "still6", "camera": len(cams) - 1,
                  "matrix": world_matrix(asset, holder[6], args.still_frame / FPS)})
    root = doc["scenes"][doc.get("scene", 0)]["nodes"]
    root.append(len(nodes) - 1)
    root.append(add_sun(doc, (0.45, -0.8, 0.35), (1.0, 0.95, 0.85), args.sun))
    return f"8 sky materials emit, {cut} roof triangles cut, a sun, camera still6 added"


def light_brainstem(asset, extra, args):
    doc = asset.doc
    doc.setdefault("materials", []).append({
        "name": "stage", "pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1.0],
                                                  "metallicFactor": 0.0, "roughnessFactor": 0.8}})
    stage = len(doc["materials"]) - 1
    floor = gw.quad((-4.0, 0.0, -3.0), (0, 0, 7.0), (8.0, 0, 0))
    wall = gw.quad((-4.0, 0.0, -3.0), (8.0, 0, 0), (0, 4.0, 0))
    prims = []
    for q in (floor, wall):
        pos = [tuple(q.pos[k:k + 3]) for k in range(0, len(q.pos), 3)]
        nrm = [tuple(q.nrm[k:k + 3]) for k in range(0, len(q.nrm), 3)]
        attrs = {"POSITION": extra.accessor(pos, 5126, "VEC3", minmax=True, target=34962),
                 "NORMAL": extra.accessor(nrm, 5126, "VEC3", target=34962)}
        prims.append({"attributes": attrs, "material": stage,
                      "indices": extra.accessor(q.idx, 5125, "SCALAR", target=34963)})
    doc["meshes"].append({"name": "stage", "primitives": prims})
    nodes = doc["nodes"]
    nodes.append({"name": "stage", "mesh": len(doc["meshes"]) - 1})
    root = doc["scenes"][doc.get("scene", 0)]["nodes"]
    root.append(len(nodes) - 1)
    cams = doc.setdefault("cameras", [])
    for name in ("front", "orbit"):
        cams.append({"name": name, "type": "perspective",
                     "perspective": {"yfov": 0.7, "aspectRatio": 16.0 / 9.0, "znear": 0.05}})
    eye, at = (0.0, 1.2, 3.2), (0.0, 1.0, 0.0)
    look = gw.quat_look(gw.sub(at, eye))
    nodes.append({"name": "front", "camera": len(cams) - 2, "translation": list(eye),
                  "rotation": list(look)})
    root.append(len(nodes) - 1)
    nodes.append({"name": "orbit", "camera": len(cams) - 1, "translation": list(eye),
                  "rotation": list(look)})
    nodes.append({"name": "orbit_pivot", "children": [len(nodes) - 1]})
    pivot = len(nodes) - 1
    root.append(pivot)
    anim = doc["animations"][0]
    end = max(asset.read(s["input"])[-1] for s in anim["samplers"])
    times = [end * k / 140 for k in range(141)]
    quats = [gw.quat_axis_angle((0, 1, 0), math.radians(10.0) * t - math.radians(60.0))
             for t in times]
    anim["samplers"].append({"input": extra.accessor(times, 5126, "SCALAR", minmax=True),
                             "output": extra.accessor(quats, 5126, "VEC4"),
                             "interpolation": "LINEAR"})
    anim["channels"].append({"sampler": len(anim["samplers"]) - 1,
                             "target": {"node": pivot, "path": "rotation"}})
    return "a floor and a back wall, cameras front and orbit"


def bounds(asset):
    """The axis-aligned box of every mesh node's POSITION corners in world space at time 0."""
    lo, hi = [math.inf] * 3, [-math.inf] * 3
    for i, n in enumerate(asset.doc["nodes"]):
        if "mesh" not in n:
            continue
        m = world_matrix(asset, i, 0.0)
        for p in asset.doc["meshes"][n["mesh"]]["primitives"]:
            a = asset.doc["accessors"][p["attributes"]["POSITION"]]
            for c in range(8):
                v = [a["max"][k] if (c >> k) & 1 else a["min"][k] for k in range(3)]
                w = [sum(m[r + 4 * k] * v[k] for k in range(3)) + m[r + 12] for r in range(3)]
                lo = [min(x, y) for x, y in zip(lo, w)]
                hi = [max(x, y) for x, y in zip(hi, w)]
    if lo[0] > hi[0]:
        raise gw.Invalid("no mesh to frame")
    return lo, hi


def frame_front(asset, extra, args):
    doc = asset.doc
    lo, hi = bounds(asset)
    centre = [(a + b) / 2 for a, b in zip(lo, hi)]
    radius = 0.5 * math.sqrt(sum((b - a) ** 2 for a, b in zip(lo, hi)))
    yfov = 0.6
    dist = radius / math.sin(yfov / 2) * 1.05
    d = gw.normalize((0.0, 0.35, 1.0))
    eye = tuple(c + dist * x for c, x in zip(centre, d))
    cams = doc.setdefault("cameras", [])
    cams.append({"name": "front", "type": "perspective",
                 "perspective": {"yfov": yfov, "aspectRatio": 1.0, "znear": dist * 1e-3}})
    doc["nodes"].append({"name": "front", "camera": len(cams) - 1, "translation": list(eye),
                         "rotation": list(gw.quat_look(gw.sub(tuple(centre), eye)))})
    doc["scenes"][doc.get("scene", 0)]["nodes"].append(len(doc["nodes"]) - 1)
    return f"camera front at {', '.join('%.3g' % x for x in eye)}"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("asset", choices=("vc", "brainstem", "framed"))
    ap.add_argument("source", help="the asset's .gltf")
    ap.add_argument("--out", required=True, help="the wrapper's .gltf (its .bin beside it)")
    ap.add_argument("--sky-strength", type=float, default=1.0,
                    help="vc: emission strength of the sky dome's texture (default 1)")
    ap.add_argument("--sun", type=float, default=3.0, help="vc: the sun's irradiance (default 3)")
    ap.add_argument("--still-frame", type=float, default=200.0,
                    help="vc: the frame (at 24 fps) where camera still6 holds camera 6's pose")
    args = ap.parse_args()
    try:
        asset = Asset(args.source)
        asset.rebase(os.path.dirname(os.path.abspath(args.out)))
        extra = Extra(asset.doc)
        what = {"vc": light_vc, "brainstem": light_brainstem,
                "framed": frame_front}[args.asset](asset, extra, args)
        extra.write(args.out)
    except (gw.Invalid, OSError, KeyError, ValueError, struct.error) as e:
        print(f"gen_real_scenes: {args.source}: {e}", file=sys.stderr)
        return 2
    print(f"{args.out}: {what}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
