"""Scene generators: the demo scenes (gen_scenes.py), the material zoo (gen_material_zoo.py),
the large atrium (gen_atrium.py), and the glTF writer they share (gltf_writer.py)."""
