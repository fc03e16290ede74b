// Scene materials, textures and vertices as the kernels see them (kernels/shared/material.h,
// geometry.h): the conversions GpuScene uploads, exposed for tests.
#pragma once

#include <cstdint>
#include <vector>

#include "render/options.h"
#include "scene/scene.h"
#include "shared/geometry.h"
#include "shared/material.h"

namespace pr {

// How the device materials shade: forceDiffuse makes every non-delta material pure Lambert;
// model picks the BSDF (kernels/shared/bsdf.h).
struct MaterialOptions {
  bool forceDiffuse = false;
  MaterialModel model = MaterialModel::Energy;
};

// The device material: factors, texture slots with their transforms and uv sets, the
// extensions' parameters.
dev::Material toDeviceMaterial(const Material& m, const MaterialOptions& options = {});

// All textures in one texel buffer (RGBA8 packed in u32) with a table of where each starts.
struct DeviceTextures {
  std::vector<dev::TextureInfo> infos;
  std::vector<uint32_t> texels;
};
DeviceTextures packTextures(const std::vector<Texture>& textures);

// Vertex v of a mesh: position, normal, both uv sets (TEXCOORD_0 standing in for a missing
// TEXCOORD_1) and tangent.
dev::ShadingVertex shadingVertex(const TriangleMesh& m, size_t v);
// The same for a deformed shape of `mesh` (Scene::deformMesh): its positions, normals and
// tangents from `shape`, the rest from `mesh`.
dev::ShadingVertex shadingVertex(const TriangleMesh& mesh, const TriangleMesh& shape, size_t v);

}  // namespace pr
