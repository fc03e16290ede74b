"""Writes frames of a glTF animation as world-space triangles per material, for a benchmark peer
that has no glTF importer (tools/bench/luxcore_frames.py). Run by a Python that has `bpy` 5.2
(the one of bench_temporal --cycles):

  VENV/bin/python tools/bench/scene_export.py SCENE.gltf OUTDIR --frames A-B --width W --height H

The scene goes through Blender's glTF importer, as for Cycles (tools/bench/cycles_frames.py),
and frame f is evaluated at f / 24 s (skins, morph targets and transforms applied). Writes
OUTDIR/scene.json (each material's Principled BSDF inputs; the suns and the world colour of
--world; whether any image texture was imported; per frame the camera's eye, target, up and
vertical field of view for a W x H image) and OUTDIR/f_%04d.npz (per material
index k, triangle corners p<k> and their shading normals n<k>, float32, 3 rows per triangle).
Image textures are not exported: a scene that has them is marked "textured" and
luxcore_frames.py refuses it.
"""

import json
import math
import sys

import bpy
import numpy as np
from mathutils import Vector

from cycles_frames import first_camera
from peer_args import peer_args


def parse_args():
    return peer_args("scene_export.py", "scene", render=False)


def principled(mat):
    """The material's Principled BSDF inputs that the peer maps (defaults where absent)."""
    out = {"base": [0.8, 0.8, 0.8], "metallic": 0.0, "roughness": 0.5, "transmission": 0.0,
           "ior": 1.5, "emission": [0.0, 0.0, 0.0]}
    if mat is None or not mat.use_nodes:
        return out
    node = next((n for n in mat.node_tree.nodes if n.type == "BSDF_PRINCIPLED"), None)
    if node is None:
        return out
    i = node.inputs
    out["base"] = list(i["Base Color"].default_value)[:3]
    out["metallic"] = float(i["Metallic"].default_value)
    out["roughness"] = float(i["Roughness"].default_value)
    out["transmission"] = float(i["Transmission Weight"].default_value)
    out["ior"] = float(i["IOR"].default_value)
    strength = float(i["Emission Strength"].default_value)
    out["emission"] = [c * strength for c in list(i["Emission Color"].default_value)[:3]]
    return out


def suns(scene):
    """Each sun's direction of travel and irradiance (RGB)."""
    out = []
    for obj in scene.objects:
        if obj.type == "LIGHT" and obj.data.type == "SUN":
            d = (obj.matrix_world.to_3x3() @ Vector((0.0, 0.0, -1.0))).normalized()
            out.append({"direction": list(d),
                        "irradiance": [c * obj.data.energy for c in obj.data.color]})
    return out


def camera_at(cam, a):
    m = cam.matrix_world
    eye = m.translation
    forward = (m.to_3x3() @ Vector((0.0, 0.0, -1.0))).normalized()
    up = (m.to_3x3() @ Vector((0.0, 1.0, 0.0))).normalized()
    data = cam.data
    aspect = a.width / a.height
    fit = data.sensor_fit
    horizontal = fit == "HORIZONTAL" or (fit == "AUTO" and aspect >= 1.0)
    half = math.tan(data.angle / 2.0)
    vfov = 2.0 * math.atan(half / aspect) if horizontal else data.angle
    return {"eye": list(eye), "target": list(eye + forward), "up": list(up),
            "vfov_deg": math.degrees(vfov)}


def main():
    a = parse_args()
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.fps = 24
    scene.render.fps_base = 1.0
    bpy.ops.import_scene.gltf(filepath=a.scene, export_import_convert_lighting_mode="RAW")
    cam = first_camera(a.scene, scene, a.camera)
    mats = list(bpy.data.materials)
    index = {m.name: k for k, m in enumerate(mats)}
    info = {"materials": [principled(m) for m in mats] + [principled(None)], "frames": {},
            "world": [float(x) for x in a.world.split(",")] if a.world else None,
            "suns": suns(scene), "textured": any(i.source == "FILE" for i in bpy.data.images)}
    fallback = len(mats)
    for f in range(a.first, a.last + 1):
        scene.frame_set(f)
        deps = bpy.context.evaluated_depsgraph_get()
        soups = {}
        for obj in scene.objects:
            if obj.type != "MESH":
                continue
            ev = obj.evaluated_get(deps)
            mesh = ev.to_mesh()
            mesh.calc_loop_triangles()
            t = len(mesh.loop_triangles)
            verts = np.empty(t * 3, dtype=np.int64)
            loops = np.empty(t * 3, dtype=np.int64)
            mat_of = np.empty(t, dtype=np.int64)
            mesh.loop_triangles.foreach_get("vertices", verts)
            mesh.loop_triangles.foreach_get("loops", loops)
            mesh.loop_triangles.foreach_get("material_index", mat_of)
            co = np.empty(len(mesh.vertices) * 3, dtype=np.float64)
            mesh.vertices.foreach_get("co", co)
            cn = np.empty(len(mesh.corner_normals) * 3, dtype=np.float64)
            mesh.corner_normals.foreach_get("vector", cn)
            world = np.array(ev.matrix_world, dtype=np.float64)
            normal_m = np.linalg.inv(world[:3, :3]).T
            p = co.reshape(-1, 3)[verts] @ world[:3, :3].T + world[:3, 3]
            n = cn.reshape(-1, 3)[loops] @ normal_m.T
            n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-30)
            slots = [s.material for s in ev.material_slots]
            for slot in np.unique(mat_of):
                mat = slots[slot] if slot < len(slots) else None
                k = index.get(mat.name, fallback) if mat is not None else fallback
                sel = np.repeat(mat_of == slot, 3)
                soups.setdefault(k, []).append((p[sel], n[sel]))
            ev.to_mesh_clear()
        arrays = {}
        for k, parts in soups.items():
            arrays[f"p{k}"] = np.concatenate([q for q, _ in parts]).astype(np.float32)
            arrays[f"n{k}"] = np.concatenate([m for _, m in parts]).astype(np.float32)
        np.savez(f"{a.outdir}/f_{f:04d}.npz", **arrays)
        info["frames"][str(f)] = camera_at(cam, a)
    with open(f"{a.outdir}/scene.json", "w", encoding="utf-8") as out:
        json.dump(info, out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
