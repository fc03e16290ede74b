"""Generates the committed material scenes of the tests (tests/data/materials/):

  zoo.gltf         a row of spheres of glTF metallic-roughness materials (rough and glossy
                   dielectrics and metals, KHR_materials_specular, a mirror and glass) on a
                   grey floor under an emissive quad and a point light: the scene of the
                   material-model conformance test, which renders it with `--material-model
                   gltf-reference` and compares with the frames the single-scattering model
                   rendered before the energy-conserving one became the default
                   (zoo_pathtrace_0000.exr, zoo_reuse_0000.exr)
  extensions.gltf  the same stage with KHR_materials_sheen, _clearcoat (with its own normal
                   map), _anisotropy (with a direction texture) and _specular, textured: every
                   lobe and texture of the BSDFs, for tools/ci/oclgrind-check.sh

  python3 -m tools.scenes.gen_material_zoo           # writes both
  python3 -m tools.scenes.gen_material_zoo --check   # exit 1 if a committed file is stale
"""

import argparse
import math
import os
import sys
import tempfile

from . import gltf_writer as gw

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
OUT_DIR = os.path.join(ROOT, "tests", "data", "materials")

# (name, base colour, metallic, roughness, extensions)
ZOO = [
    ("dielectric-r03", (0.8, 0.3, 0.2), 0.0, 0.3, None),
    ("white-r1", (0.9, 0.9, 0.9), 0.0, 1.0, None),
    ("gold-r05", (1.0, 0.77, 0.34), 1.0, 0.5, None),
    ("metal-r1", (0.9, 0.9, 0.9), 1.0, 1.0, None),
    ("specular", (0.2, 0.4, 0.7), 0.0, 0.4,
     {"KHR_materials_specular": {"specularFactor": 0.6,
                                 "specularColorFactor": [1.0, 0.5, 0.25]}}),
    ("half-metal", (0.6, 0.6, 0.3), 0.5, 0.6, None),
    ("mirror", (0.95, 0.95, 0.95), 1.0, 0.0, None),
    ("glass", (1.0, 1.0, 1.0), 0.0, 0.0, {"KHR_materials_transmission":
                                           {"transmissionFactor": 1.0}}),
]


def stripes(x, y):
    """A tangent-space normal map of ridges along v, as 8-bit RGB."""
    nx = 0.4 * math.sin(2.0 * math.pi * x / 8.0)
    n = (nx, 0.0, math.sqrt(1.0 - nx * nx))
    return tuple(int(round(255 * (0.5 * c + 0.5))) for c in n)


def swirl(x, y):
    """An anisotropy texture: direction turning with x (RG in [-1, 1]), strength in B."""
    a = 2.0 * math.pi * x / 16.0
    return (int(round(255 * (0.5 * math.cos(a) + 0.5))),
            int(round(255 * (0.5 * math.sin(a) + 0.5))), 200)


def extension_spheres(g):
    """The extensions scene's materials, with their textures."""
    coat_normal = g.png_texture("coat-normal", gw.png_rgb(8, 8, stripes))
    direction = g.png_texture("anisotropy-direction", gw.png_rgb(16, 4, swirl))
    sheen_colour = g.png_texture("sheen-colour", gw.png_rgb(
        4, 4, lambda x, y: (255, 128 + 32 * x, 255 - 40 * y)))
    return [
        ("sheen", (0.1, 0.1, 0.15), 0.0, 0.8,
         {"KHR_materials_sheen": {"sheenColorFactor": [1.0, 0.8, 0.6],
                                  "sheenRoughnessFactor": 0.4,
                                  "sheenColorTexture": {"index": sheen_colour}}}),
        ("sheen-smooth", (0.6, 0.2, 0.2), 0.0, 0.6,
         {"KHR_materials_sheen": {"sheenColorFactor": [0.8, 0.8, 1.0]}}),
        ("coat-normal", (0.7, 0.1, 0.1), 0.0, 0.6,
         {"KHR_materials_clearcoat": {"clearcoatFactor": 1.0, "clearcoatRoughnessFactor": 0.1,
                                      "clearcoatNormalTexture": {"index": coat_normal,
                                                                 "scale": 0.8}}}),
        ("coat-metal", (0.9, 0.6, 0.3), 1.0, 0.5,
         {"KHR_materials_clearcoat": {"clearcoatFactor": 0.7,
                                      "clearcoatRoughnessFactor": 0.3}}),
        ("anisotropic", (0.95, 0.95, 0.95), 1.0, 0.3,
         {"KHR_materials_anisotropy": {"anisotropyStrength": 0.8, "anisotropyRotation": 0.3}}),
        ("anisotropic-textured", (1.0, 0.77, 0.34), 1.0, 0.4,
         {"KHR_materials_anisotropy": {"anisotropyStrength": 1.0,
                                       "anisotropyTexture": {"index": direction}}}),
        ("specular-colour", (0.2, 0.4, 0.7), 0.0, 0.2,
         {"KHR_materials_specular": {"specularFactor": 0.8,
                                     "specularColorFactor": [1.0, 0.5, 0.25]}}),
        ("all", (0.3, 0.5, 0.3), 0.2, 0.5,
         {"KHR_materials_sheen": {"sheenColorFactor": [0.5, 0.5, 0.5],
                                  "sheenRoughnessFactor": 0.7},
          "KHR_materials_clearcoat": {"clearcoatFactor": 0.5},
          "KHR_materials_anisotropy": {"anisotropyStrength": 0.5}}),
    ]


def build(name):
    # asset.generator keeps the script's old path (before tools/ had folders): the committed
    # scenes and the caches keyed by a scene's bytes stay valid.
    g = gw.Gltf("pathreuse tools/gen_material_zoo.py")
    floor = g.material("floor", (0.5, 0.5, 0.5), 0.0, 1.0)
    light = g.material("light", (0.0, 0.0, 0.0), emissive=(1.0, 1.0, 1.0), strength=8.0,
                       double_sided=True)
    nodes = []
    plane = gw.quad((-5.0, 0.0, 3.0), (10.0, 0.0, 0.0), (0.0, 0.0, -8.0))
    nodes.append(g.node("floor", mesh=g.mesh("floor", [(plane, floor)])))
    lamp = gw.quad((-1.5, 4.0, -1.0), (0.0, 0.0, 2.0), (3.0, 0.0, 0.0))
    nodes.append(g.node("lamp", mesh=g.mesh("lamp", [(lamp, light)])))
    sphere = gw.uv_sphere(0.4, 24, 12)
    spheres = ZOO if name == "zoo" else extension_spheres(g)
    for i, (label, base, metallic, rough, ext) in enumerate(spheres):
        mat = g.material(label, base, metallic, rough)
        if ext:
            g.doc["materials"][mat]["extensions"] = ext
            g.extensions.update(ext.keys())
        x = (i - (len(spheres) - 1) / 2.0) * 0.9
        mesh = g.mesh(label, [(sphere, mat)])
        nodes.append(g.node(label, mesh=mesh, translation=(x, 0.4, 0.0)))
    cam = g.camera("camera", 0.5, 2.0, 0.05)
    nodes.append(g.node("camera", camera=cam, translation=(0.0, 1.6, 6.5),
                        rotation=gw.quat_axis_angle((1.0, 0.0, 0.0), -0.2)))
    lights = g.doc.setdefault("extensions", {}).setdefault("KHR_lights_punctual",
                                                           {"lights": []})
    lights["lights"].append({"name": "key", "type": "point", "color": [1.0, 0.9, 0.8],
                             "intensity": 20.0})
    g.extensions.add("KHR_lights_punctual")
    nodes.append(g.node("key", translation=(3.0, 3.0, 3.0),
                        extensions={"KHR_lights_punctual": {"light": 0}}))
    return g, nodes


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--check", action="store_true", help="exit 1 if a committed file is stale")
    args = ap.parse_args()
    stale = []
    for name in ("zoo", "extensions"):
        g, nodes = build(name)
        out = os.path.join(OUT_DIR, name + ".gltf")
        if args.check:
            with tempfile.TemporaryDirectory() as tmp:
                path = os.path.join(tmp, name + ".gltf")
                g.write(path, nodes, embedded=True)
                with open(path, "rb") as a, open(out, "rb") as b:
                    if a.read() != b.read():
                        stale.append(out)
            continue
        os.makedirs(OUT_DIR, exist_ok=True)
        g.write(out, nodes, embedded=True)
        gw.validate(out)
        print("gen_material_zoo: wrote " + out)
    if args.check:
        print("gen_material_zoo: " + ("stale: " + ", ".join(stale) if stale else "up to date"))
    return 1 if stale else 0


if __name__ == "__main__":
    sys.exit(main())
