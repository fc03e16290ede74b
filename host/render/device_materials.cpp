#include "render/device_materials.h"

#include <algorithm>
#include <cmath>

namespace pr {

dev::Material toDeviceMaterial(const Material& m, const MaterialOptions& options) {
  dev::Material d{};
  d.base_r = m.baseColorFactor.r;
  d.base_g = m.baseColorFactor.g;
  d.base_b = m.baseColorFactor.b;
  d.base_a = m.baseColorFactor.a;
  const glm::vec3 e = m.emission();
  d.emit_r = e.r, d.emit_g = e.g, d.emit_b = e.b;
  d.metallic = m.metallicFactor;
  d.roughness = m.roughnessFactor;
  d.ior = m.ior > 0.0f ? m.ior : 1.5f;
  // KHR_materials_specular over KHR_materials_ior: F0 = min(((ior-1)/(ior+1))^2 colour, 1) x
  // factor, F90 = factor (0.04 and 1 by default).
  const double r = (double(d.ior) - 1.0) / (double(d.ior) + 1.0);
  for (int c = 0; c < 3; ++c) d.spec_f0[c] = float(r * r * double(m.specularColor[c]));
  d.spec_f90 = m.specular;
  d.coat = m.clearcoat;
  d.coat_roughness = m.clearcoatRoughness;
  // KHR_materials_volume: Beer-Lambert inside a transmissive object that is not thin-walled.
  const bool volume = m.transmission > 0.0f && m.thickness > 0.0f &&
                      std::isfinite(m.attenuationDistance) && m.attenuationDistance > 0.0f;
  for (int c = 0; c < 3; ++c)
    d.sigma_a[c] = volume ? float(-std::log(std::max(double(m.attenuationColor[c]), 1e-6)) /
                                  double(m.attenuationDistance))
                          : 0.0f;
  d.transmission = m.transmission;
  d.alpha_cutoff = m.alphaCutoff;
  d.base_texture = m.baseColorTexture.valid() ? m.baseColorTexture.texture : PR_NO_TEXTURE;
  d.mr_texture =
      m.metallicRoughnessTexture.valid() ? m.metallicRoughnessTexture.texture : PR_NO_TEXTURE;
  d.emission_texture = m.emissiveTexture.valid() ? m.emissiveTexture.texture : PR_NO_TEXTURE;
  d.normal_texture = m.normalTexture.valid() ? m.normalTexture.texture : PR_NO_TEXTURE;
  d.normal_scale = m.normalScale;
  d.uv_sets = (m.baseColorTexture.texCoord == 1 ? PR_UV_BASE : 0u) |
              (m.metallicRoughnessTexture.texCoord == 1 ? PR_UV_MR : 0u) |
              (m.emissiveTexture.texCoord == 1 ? PR_UV_EMISSION : 0u) |
              (m.normalTexture.texCoord == 1 ? PR_UV_NORMAL : 0u);
  uint32_t flags = 0;
  if (m.doubleSided) flags |= PR_MAT_DOUBLE_SIDED;
  if (m.alphaMode == AlphaMode::Mask) flags |= PR_MAT_ALPHA_MASK;
  if (m.alphaMode == AlphaMode::Blend) flags |= PR_MAT_ALPHA_BLEND;
  if (m.isEmissive()) flags |= PR_MAT_EMISSIVE;
  if (m.transmission > 0.0f) {
    flags |= PR_MAT_GLASS;
  } else if (m.metallicFactor >= 0.999f && m.roughnessFactor <= 0.02f &&
             !m.metallicRoughnessTexture.valid()) {
    flags |= PR_MAT_MIRROR;
  }
  if (options.forceDiffuse && !(flags & (PR_MAT_GLASS | PR_MAT_MIRROR))) flags |= PR_MAT_LAMBERT;
  if (options.model == MaterialModel::Gltf) flags |= PR_MAT_GLTF_MODEL;
  d.flags = flags;
  // KHR_texture_transform: uv' = T * R * S * uv with R = [[c, s], [-s, c]].
  auto transform = [](const TextureRef& t, float* out) {
    const float c = std::cos(t.rotation), s = std::sin(t.rotation);
    out[0] = c * t.scale.x, out[1] = s * t.scale.y, out[2] = t.offset.x;
    out[3] = -s * t.scale.x, out[4] = c * t.scale.y, out[5] = t.offset.y;
  };
  transform(m.baseColorTexture, d.base_uv);
  transform(m.metallicRoughnessTexture, d.mr_uv);
  transform(m.emissiveTexture, d.emission_uv);
  transform(m.normalTexture, d.normal_uv);
  auto texture = [](const TextureRef& t) { return t.valid() ? t.texture : PR_NO_TEXTURE; };
  d.spec_texture = texture(m.specularTexture);
  d.spec_color_texture = texture(m.specularColorTexture);
  d.coat_texture = texture(m.clearcoatTexture);
  d.coat_roughness_texture = texture(m.clearcoatRoughnessTexture);
  transform(m.specularTexture, d.spec_uv);
  transform(m.specularColorTexture, d.spec_color_uv);
  transform(m.clearcoatTexture, d.coat_uv);
  transform(m.clearcoatRoughnessTexture, d.coat_roughness_uv);
  d.uv_sets |= (m.specularTexture.texCoord == 1 ? PR_UV_SPEC : 0u) |
               (m.specularColorTexture.texCoord == 1 ? PR_UV_SPEC_COLOR : 0u) |
               (m.clearcoatTexture.texCoord == 1 ? PR_UV_COAT : 0u) |
               (m.clearcoatRoughnessTexture.texCoord == 1 ? PR_UV_COAT_ROUGHNESS : 0u);
  d.coat_normal_texture = texture(m.clearcoatNormalTexture);
  d.coat_normal_scale = m.clearcoatNormalScale;
  transform(m.clearcoatNormalTexture, d.coat_normal_uv);
  for (int c = 0; c < 3; ++c) d.sheen[c] = m.sheenColor[c];
  d.sheen_roughness = m.sheenRoughness;
  d.sheen_texture = texture(m.sheenColorTexture);
  d.sheen_roughness_texture = texture(m.sheenRoughnessTexture);
  transform(m.sheenColorTexture, d.sheen_uv);
  transform(m.sheenRoughnessTexture, d.sheen_roughness_uv);
  d.aniso_strength = m.anisotropyStrength;
  d.aniso_cos = std::cos(m.anisotropyRotation);
  d.aniso_sin = std::sin(m.anisotropyRotation);
  d.aniso_texture = texture(m.anisotropyTexture);
  transform(m.anisotropyTexture, d.aniso_uv);
  d.transmission_texture = texture(m.transmissionTexture);
  transform(m.transmissionTexture, d.transmission_uv);
  d.uv_sets |= (m.clearcoatNormalTexture.texCoord == 1 ? PR_UV_COAT_NORMAL : 0u) |
               (m.sheenColorTexture.texCoord == 1 ? PR_UV_SHEEN : 0u) |
               (m.sheenRoughnessTexture.texCoord == 1 ? PR_UV_SHEEN_ROUGHNESS : 0u) |
               (m.anisotropyTexture.texCoord == 1 ? PR_UV_ANISO : 0u) |
               (m.transmissionTexture.texCoord == 1 ? PR_UV_TRANSMISSION : 0u);
  return d;
}

DeviceTextures packTextures(const std::vector<Texture>& textures) {
  DeviceTextures out;
  for (const Texture& t : textures) {
    dev::TextureInfo info{};
    info.offset = static_cast<uint32_t>(out.texels.size());
    const bool ok = t.width > 0 && t.height > 0 && t.rgba8.size() == size_t(t.width) * t.height * 4;
    info.width = ok ? t.width : 1;
    info.height = ok ? t.height : 1;
    info.flags = (t.srgb ? PR_TEX_SRGB : 0u) | (t.nearest ? PR_TEX_NEAREST : 0u) |
                 (static_cast<uint32_t>(t.wrapS) << PR_TEX_WRAP_S_SHIFT) |
                 (static_cast<uint32_t>(t.wrapT) << PR_TEX_WRAP_T_SHIFT);
    if (ok) {
      for (size_t i = 0; i < size_t(t.width) * t.height; ++i) {
        const uint8_t* p = &t.rgba8[i * 4];
        out.texels.push_back(uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 |
                             uint32_t(p[3]) << 24);
      }
    } else {
      out.texels.push_back(0xffffffffu);  // a white texel stands in for an undecodable image
    }
    out.infos.push_back(info);
  }
  return out;
}

dev::ShadingVertex shadingVertex(const TriangleMesh& mesh, const TriangleMesh& s, size_t v) {
  dev::ShadingVertex sv{};
  sv.px = s.positions[v].x, sv.py = s.positions[v].y, sv.pz = s.positions[v].z;
  if (v < s.normals.size()) sv.nx = s.normals[v].x, sv.ny = s.normals[v].y, sv.nz = s.normals[v].z;
  if (v < mesh.uvs.size()) sv.u = mesh.uvs[v].x, sv.v = mesh.uvs[v].y;
  const glm::vec2 uv1 = v < mesh.uvs1.size() ? mesh.uvs1[v] : glm::vec2(sv.u, sv.v);
  sv.u1 = uv1.x, sv.v1 = uv1.y;
  const glm::vec4 t = v < s.tangents.size() ? s.tangents[v] : glm::vec4(1, 0, 0, 1);
  sv.tx = t.x, sv.ty = t.y, sv.tz = t.z, sv.tw = t.w;
  return sv;
}

dev::ShadingVertex shadingVertex(const TriangleMesh& m, size_t v) {
  return shadingVertex(m, m, v);
}

}  // namespace pr
