// The device buffers of the SSG and DSG (kernels/shared/bvh.h's SceneGeom): the static BVH and
// the meshes' BVHs are uploaded once, the TLAS and instance records every frame.
#pragma once

#include <cstdint>

#include "accel/scene_accel.h"
#include "cl/context.h"
#include "cl/kernel_binding.h"

namespace pr::accel {

class DeviceAccel {
 public:
  // For kernels compiled with -DPR_BVH_WIDTH=width: uploads refuse BVHs of another width.
  explicit DeviceAccel(int width = PR_BVH_WIDTH) : width_(width) {}
  int width() const { return width_; }

  void uploadStatic(Context& ctx, const StaticAccel& ssg);
  // The meshes' BVHs (after the last addMesh, and again after replaceMesh: grow leaves room
  // for a deforming mesh's BVH to grow).
  void uploadMeshes(Context& ctx, const DynamicAccel& dsg, bool grow = false);
  // This frame's TLAS, instance records and motion steps; buffers grow as needed and are reused.
  void uploadFrame(Context& ctx, const DynamicAccel& dsg);

  // The geometry's kernel arguments (PR_ARGS_SCENE_GEOM) into `args`. Needs uploadStatic;
  // missing DSG parts are bound as small placeholder buffers with instance count 0.
  void fillArgs(Context& ctx, kargs::SceneArgs* args);
  // The same arguments set from index `first` on, for the test and benchmark kernels, which
  // take them after their own; returns the index after them.
  cl_uint setKernelArgs(Context& ctx, cl::Kernel& kernel, cl_uint first);

  uint32_t instanceCount() const { return instanceCount_; }
  // Device bytes held: static part, meshes, per-frame part.
  uint64_t staticBytes() const { return staticNodes_.bytes + staticTris_.bytes; }
  uint64_t meshBytes() const {
    return meshNodes_.bytes + meshTris_.bytes + motionTris_.bytes + meshMotion_.bytes +
           motionBounds_.bytes;
  }
  uint64_t frameBytes() const { return tlasNodes_.bytes + instances_.bytes + motion_.bytes; }

 private:
  struct Slot {
    cl::Buffer buffer;
    uint64_t bytes = 0;  // allocated
  };
  // Writes `bytes` into the slot, (re)allocating when too small (never less than 64 bytes:
  // OpenCL has no empty buffers).
  static void upload(Context& ctx, Slot& slot, const char* name, const void* data, uint64_t bytes,
                     bool grow);

  int width_;
  Slot staticNodes_, staticTris_, meshNodes_, meshTris_, tlasNodes_, instances_, motion_,
      motionTris_, meshMotion_, motionBounds_;
  uint32_t instanceCount_ = 0;
  uint32_t motionSteps_ = 1;
};

}  // namespace pr::accel
