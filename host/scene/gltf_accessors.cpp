#include "scene/gltf_accessors.h"

#include <algorithm>
#include <cstring>

namespace pr::gltf {

size_t componentSize(int componentType) {
  switch (componentType) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
      return 1;
    case TINYGLTF_COMPONENT_TYPE_SHORT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
      return 2;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
    case TINYGLTF_COMPONENT_TYPE_FLOAT:
      return 4;
    default:
      return 0;
  }
}

size_t componentCount(int type) {
  switch (type) {
    case TINYGLTF_TYPE_SCALAR:
      return 1;
    case TINYGLTF_TYPE_VEC2:
      return 2;
    case TINYGLTF_TYPE_VEC3:
      return 3;
    case TINYGLTF_TYPE_VEC4:
      return 4;
    case TINYGLTF_TYPE_MAT2:
      return 4;
    case TINYGLTF_TYPE_MAT3:
      return 9;
    case TINYGLTF_TYPE_MAT4:
      return 16;
    default:
      return 0;
  }
}

const char* typeName(int type) {
  switch (type) {
    case TINYGLTF_TYPE_SCALAR:
      return "SCALAR";
    case TINYGLTF_TYPE_VEC2:
      return "VEC2";
    case TINYGLTF_TYPE_VEC3:
      return "VEC3";
    case TINYGLTF_TYPE_VEC4:
      return "VEC4";
    case TINYGLTF_TYPE_MAT2:
      return "MAT2";
    case TINYGLTF_TYPE_MAT3:
      return "MAT3";
    case TINYGLTF_TYPE_MAT4:
      return "MAT4";
    default:
      return "unknown type";
  }
}

const char* componentName(int componentType) {
  switch (componentType) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
      return "BYTE";
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
      return "UNSIGNED_BYTE";
    case TINYGLTF_COMPONENT_TYPE_SHORT:
      return "SHORT";
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
      return "UNSIGNED_SHORT";
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
      return "UNSIGNED_INT";
    case TINYGLTF_COMPONENT_TYPE_FLOAT:
      return "FLOAT";
    default:
      return "unknown component type";
  }
}

double readComponent(const uint8_t* p, int componentType, bool normalized) {
  switch (componentType) {
    case TINYGLTF_COMPONENT_TYPE_FLOAT: {
      float f;
      std::memcpy(&f, p, 4);
      return f;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
      uint32_t v;
      std::memcpy(&v, p, 4);
      return v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
      uint16_t v;
      std::memcpy(&v, p, 2);
      return normalized ? v / 65535.0 : v;
    }
    case TINYGLTF_COMPONENT_TYPE_SHORT: {
      int16_t v;
      std::memcpy(&v, p, 2);
      return normalized ? std::max(v / 32767.0, -1.0) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
      return normalized ? *p / 255.0 : *p;
    case TINYGLTF_COMPONENT_TYPE_BYTE: {
      const int8_t v = static_cast<int8_t>(*p);
      return normalized ? std::max(v / 127.0, -1.0) : v;
    }
    default:
      return 0.0;
  }
}

bool fits(uint64_t a, uint64_t b, uint64_t c, uint64_t limit) {
  uint64_t bc = 0, sum = 0;
  if (__builtin_mul_overflow(b, c, &bc) || __builtin_add_overflow(a, bc, &sum)) return false;
  return sum <= limit;
}

std::vector<double> readAccessor(const tinygltf::Model& model, int index) {
  const auto& a = model.accessors[size_t(index)];
  const size_t cs = componentSize(a.componentType), nc = componentCount(a.type), elem = cs * nc;
  std::vector<double> out(a.count * nc, 0.0);
  if (a.bufferView >= 0) {
    const auto& v = model.bufferViews[size_t(a.bufferView)];
    const size_t stride = v.byteStride ? v.byteStride : elem;
    const uint8_t* base = model.buffers[size_t(v.buffer)].data.data() + v.byteOffset + a.byteOffset;
    for (size_t i = 0; i < a.count; ++i)
      for (size_t c = 0; c < nc; ++c)
        out[i * nc + c] = readComponent(base + i * stride + c * cs, a.componentType, a.normalized);
  }
  if (a.sparse.isSparse) {
    const auto& sp = a.sparse;
    const auto& iv = model.bufferViews[size_t(sp.indices.bufferView)];
    const auto& vv = model.bufferViews[size_t(sp.values.bufferView)];
    const uint8_t* ip = model.buffers[size_t(iv.buffer)].data.data() + iv.byteOffset +
                        size_t(sp.indices.byteOffset);
    const uint8_t* vp =
        model.buffers[size_t(vv.buffer)].data.data() + vv.byteOffset + size_t(sp.values.byteOffset);
    const size_t is = componentSize(sp.indices.componentType);
    for (int i = 0; i < sp.count; ++i) {
      const size_t k = size_t(readComponent(ip + size_t(i) * is, sp.indices.componentType, false));
      for (size_t c = 0; c < nc; ++c)
        out[k * nc + c] =
            readComponent(vp + size_t(i) * elem + c * cs, a.componentType, a.normalized);
    }
  }
  return out;
}

}  // namespace pr::gltf
