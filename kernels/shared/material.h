// Materials as the kernels see them: glTF metallic-roughness with emission, transmission
// (a dielectric interface, smooth or GGX-rough), alpha cut-out/coverage, textures with their
// transforms and uv sets, normal maps, and the KHR_materials extensions (specular, clearcoat,
// sheen, anisotropy, volume).
#pragma once

#include "shared/common.h"

PR_NAMESPACE_BEGIN

#define PR_MAT_DOUBLE_SIDED 1u
#define PR_MAT_ALPHA_MASK 2u   // cut-out at alpha_cutoff
#define PR_MAT_ALPHA_BLEND 4u  // stochastic coverage: pass through with probability 1 - alpha
#define PR_MAT_MIRROR 8u       // delta reflection (metallic 1, roughness ~0)
#define PR_MAT_GLASS 16u       // transmissive (KHR_materials_transmission): shading_frame
#define PR_MAT_EMISSIVE 32u
#define PR_MAT_LAMBERT 64u      // shaded as pure Lambert with the base colour (--force-diffuse)
#define PR_MAT_GLTF_MODEL 128u  // the glTF specification's BSDF (--material-model gltf-reference)

#define PR_NO_TEXTURE (-1)

// 496 bytes.
typedef struct {
  float base_r, base_g, base_b, base_a;  // linear baseColorFactor
  float emit_r, emit_g, emit_b;          // emissiveFactor * emissive_strength (radiance)
  u32 flags;
  float metallic, roughness, ior, transmission;
  float alpha_cutoff;
  i32 base_texture;  // index into the texture table, or PR_NO_TEXTURE
  i32 mr_texture;    // metallicRoughness (G = roughness, B = metallic)
  i32 emission_texture;
  // KHR_texture_transform of each texture as a 2x3 matrix, rows first: uv' = M * (u, v, 1).
  float base_uv[6];
  float mr_uv[6];
  float emission_uv[6];
  i32 normal_texture;  // tangent-space normal map (linear), or PR_NO_TEXTURE
  float normal_scale;  // scales the map's x and y
  float normal_uv[6];
  u32 uv_sets;           // bit PR_UV_*: that texture reads TEXCOORD_1, else TEXCOORD_0
  float spec_f90;        // KHR_materials_specular: F90 of the dielectric layer (1)
  float spec_f0[3];      // ((ior-1)/(ior+1))^2 x colour: F0 = min(this x texture, 1) x F90
  float coat;            // KHR_materials_clearcoat factor (0: none)
  float coat_roughness;  // its roughness
  // KHR_materials_volume inside a transmissive object: attenuation per unit length per channel
  // (-ln(attenuationColor) / attenuationDistance); 0: none (thin-walled or clear).
  float sigma_a[3];
  // The extensions' textures (PR_NO_TEXTURE: none), each with its transform: specular (A
  // scales the factor), specular colour (RGB, sRGB), clearcoat (R), clearcoat roughness (G).
  i32 spec_texture, spec_color_texture, coat_texture, coat_roughness_texture;
  float spec_uv[6];
  float spec_color_uv[6];
  float coat_uv[6];
  float coat_roughness_uv[6];
  // KHR_materials_clearcoat's own normal map (PR_NO_TEXTURE: the coat takes the interpolated
  // normal), with its scale and transform.
  i32 coat_normal_texture;
  float coat_normal_scale;
  float coat_normal_uv[6];
  // KHR_materials_sheen: colour (0: none) and roughness, their textures (RGB sRGB; A).
  float sheen[3];
  float sheen_roughness;
  i32 sheen_texture, sheen_roughness_texture;
  float sheen_uv[6];
  float sheen_roughness_uv[6];
  // KHR_materials_anisotropy: strength (0: isotropic), rotation from the tangent (cos, sin), the
  // texture (RG direction in the tangent frame, B strength).
  float aniso_strength;
  float aniso_cos, aniso_sin;
  i32 aniso_texture;
  float aniso_uv[6];
  // KHR_materials_transmission's texture (R scales the factor), its transform.
  i32 transmission_texture;
  float transmission_uv[6];
  float pad;
} Material;

#define PR_UV_BASE 1u
#define PR_UV_MR 2u
#define PR_UV_EMISSION 4u
#define PR_UV_NORMAL 8u
#define PR_UV_SPEC 16u
#define PR_UV_SPEC_COLOR 32u
#define PR_UV_COAT 64u
#define PR_UV_COAT_ROUGHNESS 128u
#define PR_UV_COAT_NORMAL 256u
#define PR_UV_SHEEN 512u
#define PR_UV_SHEEN_ROUGHNESS 1024u
#define PR_UV_ANISO 2048u
#define PR_UV_TRANSMISSION 4096u

// One texture in the shared texel buffer (RGBA8 packed in u32, row-major). 16 bytes.
typedef struct {
  u32 offset;  // first texel
  u32 width, height;
  u32 flags;  // PR_TEX_SRGB
} TextureInfo;

#define PR_TEX_SRGB 1u
#define PR_TEX_NEAREST 2u
// Wrap modes in bits 2-3 (S) and 4-5 (T): 0 repeat, 1 clamp to edge, 2 mirrored repeat.
#define PR_TEX_WRAP_S_SHIFT 2u
#define PR_TEX_WRAP_T_SHIFT 4u

PR_NAMESPACE_END

PR_STATIC_ASSERT(sizeof(pr::dev::Material) == 496, "Material layout");
PR_STATIC_ASSERT(offsetof(pr::dev::Material, flags) == 28, "Material layout");
PR_STATIC_ASSERT(offsetof(pr::dev::Material, alpha_cutoff) == 48, "Material layout");
PR_STATIC_ASSERT(offsetof(pr::dev::Material, base_uv) == 64, "Material layout");
PR_STATIC_ASSERT(offsetof(pr::dev::Material, emission_uv) == 112, "Material layout");
PR_STATIC_ASSERT(offsetof(pr::dev::Material, normal_uv) == 144, "Material layout");
PR_STATIC_ASSERT(offsetof(pr::dev::Material, spec_f0) == 176, "Material layout");
PR_STATIC_ASSERT(offsetof(pr::dev::Material, coat_normal_texture) == 320, "Material layout");
PR_STATIC_ASSERT(offsetof(pr::dev::Material, sheen) == 352, "Material layout");
PR_STATIC_ASSERT(offsetof(pr::dev::Material, aniso_strength) == 424, "Material layout");
PR_STATIC_ASSERT(offsetof(pr::dev::Material, transmission_uv) == 468, "Material layout");
PR_STATIC_ASSERT(sizeof(pr::dev::TextureInfo) == 16, "TextureInfo layout");
