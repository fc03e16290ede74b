// Tangents as MikkTSpace builds them, without its vertex splitting: each triangle's dP/du and
// dP/dv from its uvs, projected onto the plane of each corner's normal, summed at the vertex
// weighted by the corner's angle; the handedness from the summed dP/dv, turned around: glTF's v
// runs down the image, and a normal map's +Y is up it (so b = w cross(n, t) is along -dP/dv, as
// in MikkTSpace run on 1 - v, which authored tangents follow). Vertices that glTF
// exporters share across a uv seam or a mirrored uv island are already split (their uvs
// differ), so the one remaining difference is a vertex whose triangles disagree in handedness.
#include "scene/tangents.h"

#include <cmath>

#include <glm/glm.hpp>

namespace pr {
namespace {

glm::vec3 anyPerpendicular(const glm::vec3& n) {
  const glm::vec3 a = std::fabs(n.x) < 0.9f ? glm::vec3(1, 0, 0) : glm::vec3(0, 1, 0);
  return glm::normalize(glm::cross(a, n));
}

bool usable(const glm::vec3& v) {
  const float l = glm::length(v);
  return l > 1e-20f && std::isfinite(l);
}

}  // namespace

void generateTangents(TriangleMesh& mesh, const std::vector<uint8_t>& uvSet) {
  const size_t nv = mesh.vertexCount();
  // A vertex of a flat primitive has a zero normal: its faces' area-weighted normal stands in
  // (the device projects the tangent onto each face's plane where it shades).
  std::vector<glm::vec3> normals(nv, glm::vec3(0.0f));
  for (size_t v = 0; v < nv && v < mesh.normals.size(); ++v) normals[v] = mesh.normals[v];
  std::vector<glm::vec3> faceSum(nv, glm::vec3(0.0f));
  for (size_t t = 0; t < mesh.triangleCount(); ++t) {
    const uint32_t i[3] = {mesh.indices[3 * t], mesh.indices[3 * t + 1], mesh.indices[3 * t + 2]};
    const glm::vec3 n = glm::cross(mesh.positions[i[1]] - mesh.positions[i[0]],
                                   mesh.positions[i[2]] - mesh.positions[i[0]]);
    if (!std::isfinite(n.x + n.y + n.z)) continue;
    for (uint32_t v : i) faceSum[v] += n;
  }
  for (size_t v = 0; v < nv; ++v)
    if (!usable(normals[v]))
      normals[v] = usable(faceSum[v]) ? glm::normalize(faceSum[v]) : glm::vec3(0.0f, 0.0f, 1.0f);
  std::vector<glm::vec3> sumT(nv, glm::vec3(0.0f)), sumB(nv, glm::vec3(0.0f));
  for (size_t t = 0; t < mesh.triangleCount(); ++t) {
    const std::vector<glm::vec2>& uvs =
        (t < uvSet.size() && uvSet[t] && !mesh.uvs1.empty()) ? mesh.uvs1 : mesh.uvs;
    if (uvs.size() < nv) continue;
    const uint32_t i[3] = {mesh.indices[3 * t], mesh.indices[3 * t + 1], mesh.indices[3 * t + 2]};
    const glm::vec3 e1 = mesh.positions[i[1]] - mesh.positions[i[0]];
    const glm::vec3 e2 = mesh.positions[i[2]] - mesh.positions[i[0]];
    const glm::vec2 d1 = uvs[i[1]] - uvs[i[0]], d2 = uvs[i[2]] - uvs[i[0]];
    const float det = d1.x * d2.y - d2.x * d1.y;
    if (!(std::fabs(det) > 0.0f) || !std::isfinite(det)) continue;  // no uv gradient
    const glm::vec3 dpdu = (e1 * d2.y - e2 * d1.y) / det;
    const glm::vec3 dpdv = (e2 * d1.x - e1 * d2.x) / det;
    if (!usable(dpdu) || !usable(dpdv)) continue;
    for (int k = 0; k < 3; ++k) {
      const glm::vec3& p = mesh.positions[i[k]];
      const glm::vec3 a = mesh.positions[i[(k + 1) % 3]] - p,
                      b = mesh.positions[i[(k + 2) % 3]] - p;
      if (!usable(a) || !usable(b)) continue;
      const float angle =
          std::acos(glm::clamp(glm::dot(glm::normalize(a), glm::normalize(b)), -1.0f, 1.0f));
      const glm::vec3& n = normals[i[k]];
      const glm::vec3 tu = dpdu - n * glm::dot(n, dpdu), tv = dpdv - n * glm::dot(n, dpdv);
      if (usable(tu)) sumT[i[k]] += glm::normalize(tu) * angle;
      if (usable(tv)) sumB[i[k]] += glm::normalize(tv) * angle;
    }
  }
  mesh.tangents.resize(nv);
  for (size_t v = 0; v < nv; ++v) {
    const glm::vec3& n = normals[v];
    glm::vec3 t = sumT[v] - n * glm::dot(n, sumT[v]);
    t = usable(t) ? glm::normalize(t) : anyPerpendicular(n);
    const float w = glm::dot(glm::cross(n, t), sumB[v]) > 0.0f ? -1.0f : 1.0f;
    mesh.tangents[v] = glm::vec4(t, w);
  }
}

}  // namespace pr
