#include "accel/device_accel.h"

#include "cl/kernel_binding.h"

#include <algorithm>
#include <string>
#include <vector>

#include "cl/cl_check.h"
#include "util/error.h"

namespace pr::accel {

void DeviceAccel::upload(Context& ctx, Slot& slot, const char* name, const void* data,
                         uint64_t bytes, bool grow) {
  if (slot.bytes < std::max<uint64_t>(bytes, 64)) {
    if (slot.bytes > 0) ctx.release(name, slot.bytes);
    // Per-frame buffers get headroom so a slowly growing instance count does not reallocate.
    const uint64_t want = std::max<uint64_t>(grow ? bytes + bytes / 2 : bytes, 64);
    slot.buffer = ctx.allocate(name, want, CL_MEM_READ_ONLY);
    slot.bytes = want;
    ctx.zero(slot.buffer, want);
  }
  if (bytes > 0 && data)
    CL_CHECK(ctx.queue().enqueueWriteBuffer(slot.buffer, CL_TRUE, 0, bytes, data));
}

template <class T>
static uint64_t byteSize(const std::vector<T>& v) {
  return uint64_t(v.size()) * sizeof(T);
}

void DeviceAccel::uploadStatic(Context& ctx, const StaticAccel& ssg) {
  if (ssg.wide().width != width_)
    throw RuntimeError("DeviceAccel: static BVH is " + std::to_string(ssg.wide().width) +
                       " wide, the kernels take " + std::to_string(width_));
  upload(ctx, staticNodes_, "static BVH nodes", ssg.wide().words.data(), ssg.wide().bytes(), false);
  upload(ctx, staticTris_, "static BVH triangles", ssg.packets().data(), byteSize(ssg.packets()),
         false);
}

void DeviceAccel::uploadMeshes(Context& ctx, const DynamicAccel& dsg, bool grow) {
  if (dsg.width() != width_)
    throw RuntimeError("DeviceAccel: dynamic BVHs are " + std::to_string(dsg.width()) +
                       " wide, the kernels take " + std::to_string(width_));
  upload(ctx, meshNodes_, "dynamic mesh BVH nodes", dsg.meshNodes().data(),
         byteSize(dsg.meshNodes()), grow);
  upload(ctx, meshTris_, "dynamic mesh triangles", dsg.meshPackets().data(),
         byteSize(dsg.meshPackets()), grow);
  upload(ctx, meshMotion_, "dynamic mesh motion table", dsg.meshMotion().data(),
         byteSize(dsg.meshMotion()), grow);
  if (dsg.motionPacketCount() > 0) {
    const uint64_t packet = sizeof(dev::BvhTriPacket);
    upload(ctx, motionTris_, "deforming mesh motion steps", nullptr,
           dsg.motionPacketCount() * packet, grow);
    uint64_t at = 0;
    for (const DynamicAccel::PacketRun& run : dsg.motionPacketRuns()) {
      CL_CHECK(ctx.queue().enqueueWriteBuffer(motionTris_.buffer, CL_TRUE, at * packet,
                                              run.count * packet, run.data));
      at += run.count;
    }
    upload(ctx, motionBounds_, "deforming mesh node boxes at the motion steps",
           dsg.motionBounds().data(), byteSize(dsg.motionBounds()), grow);
  }
}

void DeviceAccel::uploadFrame(Context& ctx, const DynamicAccel& dsg) {
  if (byteSize(dsg.meshNodes()) > meshNodes_.bytes && !dsg.instances().empty())
    throw RuntimeError("DeviceAccel: uploadMeshes must follow the last addMesh");
  upload(ctx, tlasNodes_, "top-level BVH nodes", dsg.tlas().words.data(), dsg.tlas().bytes(), true);
  upload(ctx, instances_, "dynamic instances", dsg.instances().data(), byteSize(dsg.instances()),
         true);
  instanceCount_ = uint32_t(dsg.instances().size());
  motionSteps_ = dsg.motionSteps();
  if (motionSteps_ > 1)
    upload(ctx, motion_, "instance motion steps", dsg.motion().data(), byteSize(dsg.motion()),
           true);
}

void DeviceAccel::fillArgs(Context& ctx, kargs::SceneArgs* a) {
  if (staticNodes_.bytes == 0) throw RuntimeError("DeviceAccel: static geometry not uploaded");
  for (Slot* s : {&tlasNodes_, &instances_, &meshNodes_, &meshTris_, &motion_, &motionTris_,
                  &meshMotion_, &motionBounds_})
    if (s->bytes == 0) upload(ctx, *s, "dynamic geometry placeholder", nullptr, 0, false);
  a->pr_g_static_nodes = staticNodes_.buffer;
  a->pr_g_static_tris = staticTris_.buffer;
  a->pr_g_tlas_nodes = tlasNodes_.buffer;
  a->pr_g_instances = instances_.buffer;
  a->pr_g_mesh_nodes = meshNodes_.buffer;
  a->pr_g_mesh_tris = meshTris_.buffer;
  a->pr_g_instance_count = instanceCount_;
  a->pr_g_motion = motion_.buffer;
  a->pr_g_motion_steps = motionSteps_;
  a->pr_g_time = 0.5f;  // the frame's own time; kernels set each path's (scene_at_sample)
  a->pr_g_motion_tris = motionTris_.buffer;
  a->pr_g_mesh_motion = meshMotion_.buffer;
  a->pr_g_motion_bounds = motionBounds_.buffer;
}

cl_uint DeviceAccel::setKernelArgs(Context& ctx, cl::Kernel& kernel, cl_uint first) {
  kargs::SceneArgs a;
  fillArgs(ctx, &a);
  // Every geometry entry of the table, in its order.
  cl_uint index = first;
#define PR_SET_GEOM_(role, kind, type, name) \
  CL_CHECK(kernel.setArg(index++, a.PR_ARG_NAME(role, name)));
  PR_ARGS_SCENE_GEOM(PR_SET_GEOM_, PR_SET_GEOM_)
#undef PR_SET_GEOM_
  return index;
}

}  // namespace pr::accel
