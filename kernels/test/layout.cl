// Test kernel: writes the device compiler's sizeof of each shared struct, then the offset of
// each listed field, in the order of shared/layout.h. Reads nothing.
#include "shared/types.h"
#include "shared/layout.h"

PR_KERNEL void struct_layout(__global uint* out) {
  if (get_global_id(0) != 0) return;
  uint i = 0;
#define PR_WRITE_SIZE(T) out[i++] = (uint)sizeof(T);
  PR_SHARED_STRUCTS(PR_WRITE_SIZE)
#define PR_WRITE_OFFSET(T, m)                                               \
  {                                                                         \
    T probe;                                                                \
    out[i++] = (uint)((__private char*)&probe.m - (__private char*)&probe); \
  }
  PR_SHARED_FIELDS(PR_WRITE_OFFSET)
}
