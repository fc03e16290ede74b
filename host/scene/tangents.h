// Per-vertex tangents for normal maps where a glTF mesh gives none (the glTF spec asks for
// MikkTSpace's): see tangents.cpp for how close this comes.
#pragma once

#include <cstdint>
#include <vector>

#include "scene/scene.h"

namespace pr {

// Fills mesh.tangents (one per vertex: xyz unit and orthogonal to the vertex normal, w = +1 or
// -1 the bitangent's handedness, b = w cross(n, t), along -dP/dv: up the image, as glTF's
// normal maps read +Y) from each triangle's uv gradient. uvSet[t]
// (0 or 1) says which of mesh.uvs / mesh.uvs1 triangle t's normal map reads. A zero vertex
// normal (a flat primitive) stands for the area-weighted normal of the vertex's triangles.
void generateTangents(TriangleMesh& mesh, const std::vector<uint8_t>& uvSet);

}  // namespace pr
