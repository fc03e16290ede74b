// glTF accessors: sizes and names of their component and element types, and reading the
// values of one whose ranges validation has checked.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include <tiny_gltf.h>

namespace pr::gltf {

// Bytes per component; 0 for an invalid componentType.
size_t componentSize(int componentType);
// Components per element (SCALAR 1 ... MAT4 16); 0 for an invalid type.
size_t componentCount(int type);
const char* typeName(int type);
const char* componentName(int componentType);

// One component as a number, normalised integers mapped to [0,1] or [-1,1].
double readComponent(const uint8_t* p, int componentType, bool normalized);

// a + b * c <= limit, without overflow.
bool fits(uint64_t a, uint64_t b, uint64_t c, uint64_t limit);

// Every element of a checked accessor, components flattened (count * components values).
std::vector<double> readAccessor(const tinygltf::Model& model, int index);

}  // namespace pr::gltf
