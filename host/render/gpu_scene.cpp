#include "render/gpu_scene.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <limits>
#include <map>

#include <glm/gtc/matrix_inverse.hpp>

#include "cl/kernel_binding.h"
#include "render/device_materials.h"
#include "render/kernel_programs.h"
#include "render/light_table.h"
#include "render/moved_tree.h"
#include "render/sweeps.h"
#include "scene/emission_power.h"
#include "util/check.h"
#include "util/error.h"
#include "util/hash.h"
#include "util/parallel.h"

namespace pr {

void toRows(const glm::mat4& m, float out[12]) {
  // glm is column-major: m[col][row].
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) out[r * 4 + c] = m[c][r];
}

dev::CameraParams toCameraParams(const CameraPose& pose, int width, int height) {
  dev::CameraParams c{};
  c.px = pose.position.x, c.py = pose.position.y, c.pz = pose.position.z;
  const glm::vec3 f = glm::normalize(pose.forward);
  const glm::vec3 r = glm::normalize(glm::cross(f, pose.up));
  const glm::vec3 u = glm::cross(r, f);
  c.fx = f.x, c.fy = f.y, c.fz = f.z;
  c.rx = r.x, c.ry = r.y, c.rz = r.z;
  c.ux = u.x, c.uy = u.y, c.uz = u.z;
  c.tan_half_fov = std::tan(0.5f * pose.yfov);
  c.znear = pose.znear;
  c.zfar = pose.zfar;
  c.aspect = float(width) / float(height);
  c.width = static_cast<uint32_t>(width);
  c.height = static_cast<uint32_t>(height);
  return c;
}

GpuScene::GpuScene(Context& ctx, const Scene& scene, const GpuSceneOptions& options)
    : ctx_(ctx),
      scene_(scene),
      options_(options),
      bvhWidth_(options.bvhWidth ? options.bvhWidth
                                 : defaultBvhWidth((ctx.device().type & CL_DEVICE_TYPE_GPU) != 0)),
      dsg_(bvhWidth_),
      deviceAccel_(bvhWidth_) {
  const TriangleMesh& sm = scene.staticMesh;
  staticTriangles_ = static_cast<uint32_t>(sm.triangleCount());
  accel::BuildOptions build;
  build.width = bvhWidth_;
  ssg_.build(sm.positions, sm.indices, build);
  // DSG prims are numbered after the static triangles, so a hit's prim is its shading triangle.
  uint32_t next = staticTriangles_;
  for (const TriangleMesh& m : scene.dynamicMeshes) {
    meshFirstTriangle_.push_back(next);
    dsg_.addMesh(m.positions, m.indices, next);
    next += static_cast<uint32_t>(m.triangleCount());
  }
  deviceAccel_.uploadStatic(ctx_, ssg_);
  deviceAccel_.uploadMeshes(ctx_, dsg_);
  for (const Material& m : scene.materials) {
    if (m.alphaMode != AlphaMode::Opaque) hasAlpha_ = true;
    // The BSDF's lobes the kernels compile (a --force-diffuse scene shades Lambert only).
    if (options.forceDiffuse) continue;
    if (m.sheenColor != glm::vec3(0.0f)) hasSheen_ = true;
    if (m.clearcoat > 0.0f) hasCoat_ = true;
    if (m.isAnisotropic()) hasAnisotropy_ = true;
  }

  // Static emitters, once; the light of each emissive triangle, for the pdf of a BSDF ray
  // that hits it.
  primLight_.assign(next, PR_INVALID_INDEX);
  const EmissionShares shares(scene);
  for (size_t i = 0; i < sm.triangleCount(); ++i) {
    const uint32_t mat = sm.materials[i];
    const glm::vec3 le = scene.materials[mat].emission();
    if (le == glm::vec3(0.0f)) continue;
    const glm::vec3 a = sm.positions[sm.indices[3 * i]], b = sm.positions[sm.indices[3 * i + 1]],
                    c = sm.positions[sm.indices[3 * i + 2]];
    dev::Light l = triangleLight(a, b, c, le, static_cast<uint32_t>(i), PR_INVALID_INDEX, mat);
    l.power *= shares.share(sm, i);  // 0: its texels are black, no light
    if (l.area > 0.0f && std::isfinite(l.power) && l.power > 0.0f) {
      primLight_[i] = static_cast<uint32_t>(staticEmitters_.size());
      staticEmitters_.push_back(l);
    }
  }
  // A dynamic mesh's emitters, with their shares: the same for each of its instances.
  std::vector<std::vector<std::pair<uint32_t, float>>> meshEmitters(scene.dynamicMeshes.size());
  for (size_t mi = 0; mi < scene.dynamicMeshes.size(); ++mi) {
    const TriangleMesh& m = scene.dynamicMeshes[mi];
    for (uint32_t k = 0; k < m.triangleCount(); ++k) {
      if (!scene.materials[m.materials[k]].isEmissive()) continue;
      const float share = shares.share(m, k);
      if (!(share > 0.0f)) continue;
      primLight_[meshFirstTriangle_[mi] + k] = static_cast<uint32_t>(meshEmitters[mi].size());
      meshEmitters[mi].push_back({k, share});
    }
  }
  for (uint32_t i = 0; i < scene.instances.size(); ++i) {
    instanceFirstLight_.push_back(
        static_cast<uint32_t>(staticEmitters_.size() + dynamicEmitters_.size()));
    const uint32_t mesh = scene.instances[i].mesh;
    for (const auto& [k, share] : meshEmitters[mesh]) {
      dynamicEmitters_.push_back({i, k, scene.dynamicMeshes[mesh].materials[k], share});
      lightsAnimated_ = true;
    }
  }
  primLightBuffer_ = upload("light of each emissive triangle", primLight_.data(),
                            primLight_.size() * sizeof(uint32_t), &shadingBytes_);
  size_t treeLights = staticEmitters_.size() + dynamicEmitters_.size();
  for (const auto& l : scene.lights) {
    if (l.dynamic) lightsAnimated_ = true;
    if (l.type != LightType::Directional) ++treeLights;
  }
  // Weighing each light from the shaded point pays with a few lights and costs too much with a
  // dozen; below the tree's threshold, power chose as well as the tree for less
  // (docs/experiments/exhaustive-light-sampler.md, light-bvh.md).
  lightChoice_ = options_.lightSampler;
  if (lightChoice_ == LightSampler::Auto)
    lightChoice_ = treeLights > kAutoLightBvhMin      ? LightSampler::Bvh
                   : treeLights <= kAutoExhaustiveMax ? LightSampler::Exhaustive
                                                      : LightSampler::Power;
  const Bounds b = scene.bounds;
  if (!b.empty()) {
    sceneRadius_ = std::max(1e-3f, 0.5f * glm::length(b.extent()));
    sceneCentre_ = b.centre();
  }
  uploadShading();
  deformed_.resize(scene.dynamicMeshes.size());
  lastPositions_.resize(scene.dynamicMeshes.size());
  stepPositions_.resize(scene.dynamicMeshes.size());
  sweepParts_.resize(scene.dynamicMeshes.size());
  lastNormals_.resize(scene.dynamicMeshes.size());
  for (size_t m = 0; m < scene.dynamicMeshes.size(); ++m)
    if (scene.meshDeforms(m)) deformed_[m] = scene.dynamicMeshes[m];
  // The environment's map and sampling tables (a placeholder float without one).
  std::vector<float> envData = {0.0f};
  if (options_.environment.present())
    envData = environmentTables(options_.environment, &envMeanLuminance_);
  if (options_.environment.present() && !options_.envChoiceByPower)
    envChoiceShare_ = std::max(
        1.0f - environmentUniformShare(options_.environment, envMeanLuminance_), kEnvChoiceFloor);
  envBuffer_ =
      upload("environment map", envData.data(), envData.size() * sizeof(float), &shadingBytes_);
  // The light-tracing selection table, at time 0 once and for all.
  const std::vector<dev::Light> atZero = lightsAt(0.0);
  traceTotal_ = runningSums(atZero, &traceCdf_);
  const size_t n = std::max<size_t>(traceCdf_.size(), 1);
  traceCdfBuffer_ = ctx_.allocate("light tracing power table", n * sizeof(float), CL_MEM_READ_ONLY);
  ctx_.zero(traceCdfBuffer_, n * sizeof(float));
  if (!traceCdf_.empty())
    CL_CHECK(ctx_.queue().enqueueWriteBuffer(traceCdfBuffer_, CL_TRUE, 0,
                                             traceCdf_.size() * sizeof(float), traceCdf_.data()));
  shadingBytes_ += n * sizeof(float);
  cameraStepBytes_ = sizeof(dev::CameraParams);  // placeholders until a shutter opens
  cameraSteps_ = ctx_.allocate("camera motion steps", cameraStepBytes_, CL_MEM_READ_ONLY);
  ctx_.zero(cameraSteps_, cameraStepBytes_);
  lightStepBytes_ = sizeof(dev::Light);
  lightSteps_ = ctx_.allocate("light motion steps", lightStepBytes_, CL_MEM_READ_ONLY);
  ctx_.zero(lightSteps_, lightStepBytes_);
  sweepBytes_ = kSweepRecordFloats * sizeof(float);
  sweeps_ = ctx_.allocate("shutter sweeps", sweepBytes_, CL_MEM_READ_ONLY);
  ctx_.zero(sweeps_, sweepBytes_);
  prevSweepBytes_ = sweepBytes_;
  prevSweeps_ = ctx_.allocate("shutter sweeps", prevSweepBytes_, CL_MEM_READ_ONLY);
  ctx_.zero(prevSweeps_, prevSweepBytes_);
  motionVertexBytes_ = sizeof(dev::ShadingVertex);
  motionVertices_ =
      ctx_.allocate("deforming mesh vertex motion steps", motionVertexBytes_, CL_MEM_READ_ONLY);
  ctx_.zero(motionVertices_, motionVertexBytes_);
  // Every dynamic mesh without motion steps (4 words each, the last 1).
  std::vector<uint32_t> still(std::max<size_t>(scene.dynamicMeshes.size(), 1) * 4, 1u);
  vertexMotionBytes_ = still.size() * sizeof(uint32_t);
  uint64_t unused = 0;
  vertexMotion_ =
      upload("dynamic mesh vertex motion table", still.data(), vertexMotionBytes_, &unused);
}

cl::Buffer GpuScene::upload(const char* name, const void* data, uint64_t bytes, uint64_t* counter) {
  cl::Buffer b = ctx_.allocate(name, bytes, CL_MEM_READ_ONLY);
  if (bytes > 0) {
    CL_CHECK(ctx_.queue().enqueueWriteBuffer(b, CL_TRUE, 0, bytes, data));
  } else {
    ctx_.zero(b, 16);
  }
  *counter += bytes ? bytes : 16;
  return b;
}

void GpuScene::uploadShading() {
  std::vector<dev::ShadingVertex> verts;
  std::vector<dev::ShadingTriangle> tris;
  auto addMesh = [&](const TriangleMesh& m) {
    const uint32_t base = static_cast<uint32_t>(verts.size());
    for (size_t v = 0; v < m.vertexCount(); ++v) verts.push_back(shadingVertex(m, v));
    for (size_t t = 0; t < m.triangleCount(); ++t)
      tris.push_back({base + m.indices[3 * t], base + m.indices[3 * t + 1],
                      base + m.indices[3 * t + 2], m.materials[t]});
  };
  addMesh(scene_.staticMesh);
  for (const TriangleMesh& m : scene_.dynamicMeshes) {
    meshFirstVertex_.push_back(static_cast<uint32_t>(verts.size()));
    addMesh(m);
  }

  std::vector<dev::Material> mats;
  for (const Material& m : scene_.materials)
    mats.push_back(toDeviceMaterial(m, {options_.forceDiffuse, options_.materialModel}));
  if (mats.empty()) mats.push_back(toDeviceMaterial(Material{}));

  const DeviceTextures packed = packTextures(scene_.textures);
  vertexCount_ = verts.size();
  vertices_ =
      upload("shading vertices", verts.data(), verts.size() * sizeof(verts[0]), &shadingBytes_);
  triangles_ =
      upload("shading triangles", tris.data(), tris.size() * sizeof(tris[0]), &shadingBytes_);
  materials_ = upload("materials", mats.data(), mats.size() * sizeof(mats[0]), &shadingBytes_);
  textures_ = upload("texture table", packed.infos.data(),
                     packed.infos.size() * sizeof(packed.infos[0]), &shadingBytes_);
  texels_ = upload("texels", packed.texels.data(), packed.texels.size() * 4, &shadingBytes_);
}

bool GpuScene::deformMeshes(double t, const std::vector<double>& times,
                            std::vector<bool>* changed) {
  const auto start = std::chrono::steady_clock::now();
  bool any = false;
  changed->assign(scene_.dynamicMeshes.size(), false);
  std::vector<dev::ShadingVertex> stepVertices;  // under a shutter (uploadVertexMotion)
  std::vector<uint32_t> table(scene_.dynamicMeshes.size() * 4, 0u);
  for (size_t m = 0; m < scene_.dynamicMeshes.size(); ++m) {
    uint32_t* vm = &table[m * 4];
    vm[0] = uint32_t(meshFirstVertex_[m]);
    vm[1] = uint32_t(scene_.dynamicMeshes[m].vertexCount());
    vm[2] = uint32_t(stepVertices.size());
    vm[3] = 1u;
    if (!scene_.meshDeforms(m)) continue;
    TriangleMesh& shape = deformed_[m];
    scene_.deformMesh(m, t, &shape);
    // Under a shutter the shapes over the interval change even where the frame's does not.
    const bool same = !firstFrame_ && times.empty() && shape.positions == lastPositions_[m] &&
                      shape.normals == lastNormals_[m];
    if (same) continue;
    lastPositions_[m] = shape.positions;
    lastNormals_[m] = shape.normals;
    (*changed)[m] = any = true;
    if (previousKnown_) copyToPrevious(meshFirstVertex_[m], shape.vertexCount(), false);
    // Each step's shape on its own core (deformMesh only reads the scene and writes positions,
    // normals and tangents), its shading vertices straight into their place in stepVertices.
    const size_t nv = shape.vertexCount(), first = stepVertices.size();
    std::vector<std::vector<glm::vec3>> steps(times.size());
    stepVertices.resize(first + times.size() * nv);
    parallelFor(int(times.size()), [&](int k) {
      // The middle step is the frame's time itself (an odd count): its shape is `shape`.
      TriangleMesh deformed;
      const TriangleMesh* s = &shape;
      if (times[size_t(k)] != t) {
        scene_.deformMesh(m, times[size_t(k)], &deformed);
        s = &deformed;
      }
      dev::ShadingVertex* out = stepVertices.data() + first + size_t(k) * nv;
      for (size_t v = 0; v < nv; ++v) out[v] = shadingVertex(scene_.dynamicMeshes[m], *s, v);
      if (s == &shape)
        steps[size_t(k)] = shape.positions;
      else
        steps[size_t(k)] = std::move(deformed.positions);
    });
    if (!times.empty()) vm[3] = uint32_t(times.size());
    accel::BuildOptions build;
    build.width = bvhWidth_;
    dsg_.replaceMesh(static_cast<uint32_t>(m), shape.positions, shape.indices, build,
                     times.empty() ? nullptr : &steps);
    stepPositions_[m] = std::move(steps);  // the sweeps' parts at each step (collectSweeps)
    std::vector<dev::ShadingVertex> verts(shape.vertexCount());
    for (size_t v = 0; v < verts.size(); ++v) verts[v] = shadingVertex(shape, v);
    CL_CHECK(ctx_.queue().enqueueWriteBuffer(
        vertices_, CL_TRUE, meshFirstVertex_[m] * sizeof(dev::ShadingVertex),
        verts.size() * sizeof(dev::ShadingVertex), verts.data()));
  }
  deformedAt_ = t;
  if (any) deviceAccel_.uploadMeshes(ctx_, dsg_, true);
  if (!times.empty()) uploadVertexMotion(stepVertices, table);
  deformSeconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return any;
}

void GpuScene::uploadVertexMotion(const std::vector<dev::ShadingVertex>& steps,
                                  const std::vector<uint32_t>& table) {
  auto write = [&](cl::Buffer* buffer, uint64_t* capacity, const char* name, const void* data,
                   uint64_t bytes) {
    if (bytes == 0) return;
    if (bytes > *capacity) {
      ctx_.release(name, *capacity);
      *buffer = ctx_.allocate(name, bytes, CL_MEM_READ_ONLY);
      *capacity = bytes;
    }
    CL_CHECK(ctx_.queue().enqueueWriteBuffer(*buffer, CL_TRUE, 0, bytes, data));
  };
  write(&motionVertices_, &motionVertexBytes_, "deforming mesh vertex motion steps", steps.data(),
        steps.size() * sizeof(dev::ShadingVertex));
  write(&vertexMotion_, &vertexMotionBytes_, "dynamic mesh vertex motion table", table.data(),
        table.size() * sizeof(uint32_t));
}

void GpuScene::keepPrevious() {
  if (keepPrevious_) return;
  keepPrevious_ = true;
  previousKnown_ = false;
  bool deforms = false;
  for (size_t m = 0; m < scene_.dynamicMeshes.size(); ++m)
    deforms = deforms || scene_.meshDeforms(m);
  if (deforms) {
    const uint64_t bytes = std::max<uint64_t>(vertexCount_, 1) * sizeof(dev::ShadingVertex);
    prevVertices_ = ctx_.allocate("previous shading vertices", bytes, CL_MEM_READ_ONLY);
    shadingBytes_ += bytes;
    ctx_.zero(prevVertices_, bytes);
  }
  const uint64_t bytes =
      std::max<uint64_t>(scene_.instances.size(), 1) * sizeof(dev::ShadingInstance);
  prevInstances_ = ctx_.allocate("previous DSG instance transforms", bytes, CL_MEM_READ_ONLY);
  instanceBytes_ += bytes;
  ctx_.zero(prevInstances_, bytes);
  copyToPrevious(0, vertexCount_, true);
}

void GpuScene::copyToPrevious(uint64_t firstVertex, uint64_t vertexCount, bool instances) {
  const uint64_t vs = sizeof(dev::ShadingVertex);
  if (prevVertices_() && vertexCount > 0)
    CL_CHECK(ctx_.queue().enqueueCopyBuffer(vertices_, prevVertices_, firstVertex * vs,
                                            firstVertex * vs, vertexCount * vs));
  // Before the first setTime there are no transforms yet: the previous ones stay zero, unread
  // while previousKnown() is false.
  if (instances && shadingInstances_() && !scene_.instances.empty())
    CL_CHECK(
        ctx_.queue().enqueueCopyBuffer(shadingInstances_, prevInstances_, 0, 0,
                                       scene_.instances.size() * sizeof(dev::ShadingInstance)));
}

void GpuScene::setTime(double t) {
  // What this call replaces becomes the previous shapes (copied before it is written over; the
  // queue runs in order).
  previousKnown_ = keepPrevious_ && !firstFrame_;
  if (previousKnown_) copyToPrevious(0, 0, true);
  const std::vector<double> times = shutter_ > 0.0 ? motionTimes(t) : std::vector<double>{};
  std::vector<bool> reshaped;
  deformMeshes(t, times, &reshaped);
  const size_t n = scene_.instances.size();
  std::vector<accel::InstanceInput> inputs(n);
  instances_.resize(n);
  anyMoved_ = firstFrame_;
  if (lastTransforms_.size() != n) lastTransforms_.assign(n, glm::mat4(0.0f));
  const std::vector<glm::mat4> was = lastTransforms_;
  std::vector<bool> reshapedInstance(n);
  std::vector<std::vector<glm::mat4>> motion;
  cameraMoves_ = false;
  if (!times.empty()) placeOverShutter(times, &motion);
  motionSteps_ = times.empty() ? 1u : uint32_t(times.size());
  for (size_t i = 0; i < n; ++i) {
    const glm::mat4 m = scene_.instanceTransform(i, t);
    inputs[i].mesh = scene_.instances[i].mesh;
    inputs[i].objectToWorld = m;
    dev::ShadingInstance& s = instances_[i];
    toRows(m, s.object_to_world);
    toRows(glm::inverse(m), s.world_to_object);
    s.first_triangle = meshFirstTriangle_[scene_.instances[i].mesh];
    s.mesh = scene_.instances[i].mesh;
    s.first_light = instanceFirstLight_[i];
    // A deformed mesh moves its instance: light paths on it or through where it is change.
    const bool moved = firstFrame_ || std::memcmp(&m, &lastTransforms_[i], sizeof m) != 0 ||
                       reshaped[scene_.instances[i].mesh];
    s.moved = moved ? 1u : 0u;
    reshapedInstance[i] = reshaped[scene_.instances[i].mesh];
    anyMoved_ = anyMoved_ || moved;
    lastTransforms_[i] = m;
  }
  // Under a shutter the boxes hold each instance over its interval, which moves with the frame.
  if (anyMoved_ || shutter_ > 0.0) {
    const std::vector<accel::Aabb> before = dsg_.instanceBounds();
    dsg_.setInstances(inputs, motion);
    deviceAccel_.uploadFrame(ctx_, dsg_);
    if (anyMoved_) collectMoved(before, was, reshapedInstance);
  }
  if (!anyMoved_) moved_.clear();
  if (shutter_ > 0.0 && sweepsWanted_) collectSweeps(times, motion);
  // The moved flags change even when no transform does (all back to 0), so always upload.
  const uint64_t bytes = std::max<size_t>(n, 1) * sizeof(dev::ShadingInstance);
  if (n > instanceCapacity_ || !shadingInstances_()) {
    if (shadingInstances_()) ctx_.release("DSG instance transforms", instanceBytes_);
    shadingInstances_ = ctx_.allocate("DSG instance transforms", bytes, CL_MEM_READ_ONLY);
    instanceBytes_ = bytes;
    instanceCapacity_ = std::max<size_t>(n, 1);
    ctx_.zero(shadingInstances_, bytes);
  }
  if (n > 0)
    CL_CHECK(ctx_.queue().enqueueWriteBuffer(shadingInstances_, CL_TRUE, 0,
                                             n * sizeof(dev::ShadingInstance), instances_.data()));
  if (firstFrame_ || lightsAnimated_) {
    buildLights(t);
  } else if (!lights_.empty() && lights_.front().moved) {
    // Nothing moves any more: clear the flags the first frame set.
    for (auto& l : lights_) l.moved = 0u;
    CL_CHECK(ctx_.queue().enqueueWriteBuffer(lightBuffer_, CL_TRUE, 0,
                                             lights_.size() * sizeof(dev::Light), lights_.data()));
  }
  // The first shapes kept: the previous ones start as these, so that what does not change
  // before the next setTime is known there too.
  if (keepPrevious_ && !previousKnown_) copyToPrevious(0, vertexCount_, true);
  firstFrame_ = false;
}

void GpuScene::collectMoved(const std::vector<accel::Aabb>& before,
                            const std::vector<glm::mat4>& was, const std::vector<bool>& reshaped) {
  moved_.clear();
  const std::vector<accel::Aabb>& after = dsg_.instanceBounds();
  // Enlarged by a little of the scene's size, so that rounding in the kernels' segment tests
  // cannot miss a surface on a box's face.
  const float pad = 1e-4f * sceneRadius_;
  auto box = [&](const std::vector<accel::Aabb>& bounds, size_t i, float* out) {
    if (i >= bounds.size() || bounds[i].empty()) {  // a box no point is in
      for (int a = 0; a < 3; ++a) out[a] = 1.0f, out[3 + a] = -1.0f;
      return;
    }
    const accel::Aabb& b = bounds[i];
    for (int a = 0; a < 3; ++a) out[a] = b.lo[a] - pad - 1e-4f * std::fabs(b.lo[a]);
    for (int a = 0; a < 3; ++a) out[3 + a] = b.hi[a] + pad + 1e-4f * std::fabs(b.hi[a]);
  };
  for (size_t i = 0; i < instances_.size(); ++i) {
    if (!instances_[i].moved) continue;
    dev::MovedInstance m{};
    box(before, i, m.box);
    box(after, i, m.box + 6);
    m.root = m.root_before = PR_INVALID_INDEX;
    const glm::mat4& now = lastTransforms_[i];
    const float d0 = glm::determinant(was[i]), d1 = glm::determinant(now);
    const uint32_t mesh = scene_.instances[i].mesh;
    // A deformed mesh's shape then is the BVH its replaceMesh of this frame kept.
    const uint32_t then = reshaped[i] ? dsg_.previousRoot(mesh) : dsg_.meshRoot(mesh);
    if (!firstFrame_ && then != PR_INVALID_INDEX && std::isfinite(d0) && std::isfinite(d1) &&
        d0 != 0.0f && d1 != 0.0f) {
      m.root = dsg_.meshRoot(mesh);
      m.root_before = then;
      toRows(glm::inverse(was[i]), m.before);
      std::memcpy(m.after, instances_[i].world_to_object, sizeof m.after);  // setTime's inverse
    }
    moved_.push_back(m);
  }
  moved_ = movedTree(std::move(moved_));
}

void GpuScene::collectSweeps(const std::vector<double>& times,
                             const std::vector<std::vector<glm::mat4>>& motion) {
  // This frame's records go where the frame before last's were (the queue runs in order).
  std::swap(sweeps_, prevSweeps_);
  std::swap(sweepBytes_, prevSweepBytes_);
  std::swap(sweepCount_, prevSweepCount_);
  std::vector<float> records;
  // Enlarged as moved_'s are, so that rounding in the kernels' tests cannot miss a face.
  const float pad = 1e-4f * sceneRadius_;
  for (size_t i = 0; i < scene_.instances.size() && i < motion.size(); ++i) {
    const uint32_t m = scene_.instances[i].mesh;
    const bool deforms = scene_.meshDeforms(m);
    bool moves = deforms;
    for (size_t k = 1; !moves && k < motion[i].size(); ++k) moves = motion[i][k] != motion[i][0];
    if (!moves) continue;
    const TriangleMesh& mesh = scene_.dynamicMeshes[m];
    if (sweepParts_[m].empty()) sweepParts_[m] = sweepParts(mesh.positions, mesh.indices);
    std::vector<const std::vector<glm::vec3>*> at;
    // A deforming mesh's shapes at the same steps, from deformMeshes of this frame.
    PR_CHECK(!deforms || stepPositions_[m].size() == motion[i].size());
    if (deforms)
      for (const std::vector<glm::vec3>& p : stepPositions_[m]) at.push_back(&p);
    else
      at.push_back(&mesh.positions);
    appendInstanceSweep(sweepParts_[m], motion[i], at, pad, &records);
  }
  for (size_t i = 0; i < scene_.lights.size(); ++i) {
    if (!scene_.lights[i].dynamic || times.empty()) continue;
    const PunctualLight first = scene_.lightAt(i, times.front());
    glm::vec3 lo = first.position, hi = first.position;
    bool moves = false;
    for (double at : times) {
      const PunctualLight l = scene_.lightAt(i, at);
      lo = glm::min(lo, l.position);
      hi = glm::max(hi, l.position);
      moves = moves || l.position != first.position || l.direction != first.direction;
    }
    if (!moves) continue;
    // A turning sun shines along other lines at other times: no light path holds.
    const float inf = std::numeric_limits<float>::infinity();
    if (first.type == LightType::Directional)
      appendBoxSweep(glm::vec3(-inf), glm::vec3(inf), pad, &records);
    else
      appendBoxSweep(lo, hi, pad, &records);
  }
  records = sweepTree(records);
  sweepCount_ = uint32_t(records.size() / kSweepRecordFloats);
  if (records.empty()) return;
  const uint64_t bytes = records.size() * sizeof(float);
  if (bytes > sweepBytes_) {
    ctx_.release("shutter sweeps", sweepBytes_);
    sweeps_ = ctx_.allocate("shutter sweeps", bytes, CL_MEM_READ_ONLY);
    sweepBytes_ = bytes;
  }
  CL_CHECK(ctx_.queue().enqueueWriteBuffer(sweeps_, CL_TRUE, 0, bytes, records.data()));
}

bool GpuScene::validSurface(uint32_t prim, uint32_t inst) const {
  if (inst == PR_INVALID_INDEX) return prim < staticTriangles_;
  if (inst >= scene_.instances.size()) return false;
  const uint32_t mesh = scene_.instances[inst].mesh;
  if (mesh >= scene_.dynamicMeshes.size()) return false;
  const uint32_t first = meshFirstTriangle_[mesh];
  return prim >= first && prim - first < scene_.dynamicMeshes[mesh].triangleCount();
}

bool GpuScene::anyLightMoved() const {
  return std::any_of(lights_.begin(), lights_.end(), [](const dev::Light& l) { return l.moved; });
}

std::vector<dev::Light> GpuScene::lightsAt(double t) const {
  std::vector<dev::Light> lights = staticEmitters_;
  std::vector<glm::mat4> xforms(scene_.instances.size());
  std::vector<bool> have(scene_.instances.size(), false);
  std::map<uint32_t, TriangleMesh> shapes;  // deforming meshes with emitters, at t
  for (const DynamicEmitter& e : dynamicEmitters_) {
    if (!have[e.instance])
      xforms[e.instance] = scene_.instanceTransform(e.instance, t), have[e.instance] = true;
    const glm::mat4& x = xforms[e.instance];
    const uint32_t mesh = scene_.instances[e.instance].mesh;
    const TriangleMesh* shape = &scene_.dynamicMeshes[mesh];
    if (scene_.meshDeforms(mesh) && deformedAt_ == t) {
      shape = &deformed_[mesh];  // setTime deformed it already
    } else if (scene_.meshDeforms(mesh)) {
      auto it = shapes.find(mesh);
      if (it == shapes.end()) {
        it = shapes.emplace(mesh, scene_.dynamicMeshes[mesh]).first;
        scene_.deformMesh(mesh, t, &it->second);
      }
      shape = &it->second;
    }
    const TriangleMesh& m = *shape;
    auto w = [&](uint32_t v) { return glm::vec3(x * glm::vec4(m.positions[v], 1.0f)); };
    dev::Light l = triangleLight(
        w(m.indices[3 * e.triangle]), w(m.indices[3 * e.triangle + 1]),
        w(m.indices[3 * e.triangle + 2]), scene_.materials[e.material].emission(),
        meshFirstTriangle_[scene_.instances[e.instance].mesh] + e.triangle, e.instance, e.material);
    l.power *= e.share;
    // A degenerate or non-finite placement keeps its slot in the table with no power.
    if (!(l.area > 0.0f) || !std::isfinite(l.power)) l.power = 0.0f, l.area = 0.0f;
    lights.push_back(l);
  }
  for (size_t i : punctualOrder())
    lights.push_back(punctualLight(scene_.lightAt(i, t), sceneRadius_));
  if (options_.environment.present())
    lights.push_back(pr::environmentLight(options_.environment, envMeanLuminance_, sceneRadius_));
  return lights;
}

std::vector<size_t> GpuScene::punctualOrder() const {
  // Directional lights and the environment last: the light BVH holds the lights before them.
  std::vector<size_t> order;
  for (int directional = 0; directional < 2; ++directional)
    for (size_t i = 0; i < scene_.lights.size(); ++i)
      if ((scene_.lights[i].type == LightType::Directional) == (directional == 1))
        order.push_back(i);
  return order;
}

uint32_t GpuScene::environmentLight() const {
  return options_.environment.present() ? static_cast<uint32_t>(lights_.size() - 1)
                                        : PR_INVALID_INDEX;
}

void GpuScene::buildLights(double t) {
  std::vector<dev::Light> next = lightsAt(t);
  if (options_.environment.present()) next.back().power *= envChoiceShare_;  // the last light
  const bool sameTable = lights_.size() == next.size();
  for (size_t i = 0; i < next.size(); ++i) {
    next[i].moved = (!sameTable || !sameGeometry(lights_[i], next[i])) ? 1u : 0u;
    if (sameTable) next[i].leaf = lights_[i].leaf;  // the tree keeps its leaves
  }
  lights_ = std::move(next);
  totalPower_ = runningSums(lights_, &cdf_);
  // The light BVH: built and uploaded once (an empty one where lights are chosen by power),
  // refitted and uploaded again only when a light moved. Its size never changes.
  if (!lightBvhBuilt_) {
    treeLights_ = 0;
    while (treeLights_ < lights_.size() && !dev::light_at_infinity(lights_[treeLights_].type))
      ++treeLights_;
    lightBvh_.build(&lights_, lightChoice_ == LightSampler::Bvh ? treeLights_ : 0u);
    lightBvhBuilt_ = true;
    lightNodeBytes_ = lightBvh_.nodes().size() * sizeof(dev::LightNode);
    lightNodeBuffer_ = ctx_.allocate("light BVH", lightNodeBytes_, CL_MEM_READ_ONLY);
    CL_CHECK(ctx_.queue().enqueueWriteBuffer(lightNodeBuffer_, CL_TRUE, 0, lightNodeBytes_,
                                             lightBvh_.nodes().data()));
  } else if (lightChoice_ == LightSampler::Bvh &&
             std::any_of(lights_.begin(), lights_.end(),
                         [](const dev::Light& l) { return l.moved != 0u; })) {
    lightBvh_.refit(&lights_);
    CL_CHECK(ctx_.queue().enqueueWriteBuffer(lightNodeBuffer_, CL_TRUE, 0, lightNodeBytes_,
                                             lightBvh_.nodes().data()));
  }

  const size_t count = std::max<size_t>(lights_.size(), 1);
  if (count > lightCapacity_) {
    if (lightCapacity_) {
      ctx_.release("light table", lightCapacity_ * sizeof(dev::Light));
      ctx_.release("light power table", lightCapacity_ * sizeof(float));
    }
    lightCapacity_ = count;
    lightBytes_ = count * (sizeof(dev::Light) + sizeof(float));
    lightBuffer_ = ctx_.allocate("light table", count * sizeof(dev::Light), CL_MEM_READ_ONLY);
    cdfBuffer_ = ctx_.allocate("light power table", count * sizeof(float), CL_MEM_READ_ONLY);
    ctx_.zero(lightBuffer_, count * sizeof(dev::Light));
    ctx_.zero(cdfBuffer_, count * sizeof(float));
  }
  if (!lights_.empty()) {
    CL_CHECK(ctx_.queue().enqueueWriteBuffer(lightBuffer_, CL_TRUE, 0,
                                             lights_.size() * sizeof(dev::Light), lights_.data()));
    CL_CHECK(ctx_.queue().enqueueWriteBuffer(cdfBuffer_, CL_TRUE, 0, cdf_.size() * sizeof(float),
                                             cdf_.data()));
  }
}

namespace {

// How far the blend of a and b lies from `mid` at the box's corners.
float blendError(const accel::Aabb& box, const glm::mat4& a, const glm::mat4& b,
                 const glm::mat4& mid) {
  float worst = 0.0f;
  for (int c = 0; c < 8; ++c) {
    const glm::vec4 corner(box.corner(c), 1.0f);
    const glm::vec3 exact(mid * corner);
    const glm::vec3 blend(0.5f * (a * corner + b * corner));
    worst = std::max(worst, glm::length(blend - exact));
  }
  return worst;
}

// The length one pixel spans at the point of a world box nearest the camera (at the middle of
// the shutter interval), never nearer than the near plane: what an error there looks like on
// the film. Shadows and reflections show an object's error at about its own size.
class PixelFootprint {
 public:
  PixelFootprint(const CameraPose& view, int height, float tiny)
      : position_(view.position),
        near_(std::max(view.znear, tiny)),
        angle_(2.0f * std::tan(0.5f * view.yfov) / float(std::max(height, 1))) {}
  float angle() const { return angle_; }
  float operator()(const accel::Aabb& box) const {
    const glm::vec3 nearest = glm::clamp(position_, box.lo, box.hi);
    return std::max(glm::length(nearest - position_), near_) * angle_;
  }

 private:
  glm::vec3 position_;
  float near_, angle_;
};

// What a deforming mesh's deformation is measured by (GpuScene::setShutter, once): each morph
// target's largest displacement, and each joint's box of the bind-pose vertices it moves.
void deformationReach(const Scene& scene, std::vector<std::vector<float>>* morphReach,
                      std::vector<std::vector<accel::Aabb>>* jointBoxes) {
  morphReach->assign(scene.dynamicMeshes.size(), {});
  jointBoxes->assign(scene.dynamicMeshes.size(), {});
  for (size_t m = 0; m < morphReach->size(); ++m) {
    if (!scene.meshDeforms(m)) continue;
    const TriangleMesh& base = scene.dynamicMeshes[m];
    for (const std::vector<glm::vec3>& target : base.morphPositions) {
      float reach = 0.0f;
      for (const glm::vec3& d : target) reach = std::max(reach, glm::length(d));
      (*morphReach)[m].push_back(reach);
    }
    const int skin = scene.deformers[m].skin;
    if (skin < 0 || base.influences <= 0) continue;
    std::vector<accel::Aabb>& boxes = (*jointBoxes)[m];
    boxes.resize(scene.skins[size_t(skin)].joints.size());
    const size_t k = size_t(base.influences);
    for (size_t v = 0; v < base.vertexCount(); ++v)
      for (size_t i = 0; i < k; ++i)
        if (base.jointWeights[v * k + i] != 0.0f && base.joints[v * k + i] < boxes.size())
          boxes[base.joints[v * k + i]].grow(base.positions[v]);
  }
}

// A deforming mesh's shape blended between two steps against its shape midway, in pixels (pixel):
// each joint's skinning matrix blended, at the box of the bind-pose vertices it moves (a skinned
// vertex is a weighted sum of them), and each morph weight blended, times its target's largest
// displacement.
class DeformationError {
 public:
  DeformationError(const Scene& scene, const std::vector<accel::Aabb>& meshBounds,
                   const std::vector<std::vector<float>>& morphReach,
                   const std::vector<std::vector<accel::Aabb>>& jointBoxes,
                   const PixelFootprint& pixel, float tiny)
      : scene_(scene),
        meshBounds_(meshBounds),
        morphReach_(morphReach),
        jointBoxes_(jointBoxes),
        pixel_(pixel),
        tiny_(tiny) {}

  float operator()(size_t m, double a, double b, double mid) const {
    const Deformer& d = scene_.deformers[m];
    const accel::Aabb& box = meshBounds_[m];
    if (box.empty()) return 0.0f;
    float worst = 0.0f;
    accel::Aabb placed;  // the mesh where it is midway
    if (!jointBoxes_[m].empty()) {
      const Skin& skin = scene_.skins[size_t(d.skin)];
      auto at = [&](size_t j, double u) {
        return scene_.nodeWorldTransform(skin.joints[j], u) * skin.inverseBind[j];
      };
      for (size_t j = 0; j < jointBoxes_[m].size(); ++j) {
        if (jointBoxes_[m][j].empty()) continue;
        const glm::mat4 jm = at(j, mid);
        const accel::Aabb world = jointBoxes_[m][j].transformed(jm);
        placed.grow(world);
        worst =
            std::max(worst, blendError(jointBoxes_[m][j], at(j, a), at(j, b), jm) / pixel_(world));
      }
    } else {
      placed = box.transformed(scene_.nodeWorldTransform(d.node, mid));
    }
    if (!morphReach_[m].empty() && !placed.empty()) {
      const TriangleMesh& base = scene_.dynamicMeshes[m];
      const std::vector<float> wa = scene_.morphWeightsAt(d.node, base, a),
                               wb = scene_.morphWeightsAt(d.node, base, b),
                               wm = scene_.morphWeightsAt(d.node, base, mid);
      float off = 0.0f;
      for (size_t k = 0; k < wm.size() && k < morphReach_[m].size(); ++k)
        off += std::abs(0.5f * (wa[k] + wb[k]) - wm[k]) * morphReach_[m][k];
      // The targets' displacements are the mesh's own units: scaled as its box is placed.
      const float scale =
          glm::length(placed.hi - placed.lo) / std::max(glm::length(box.hi - box.lo), tiny_);
      worst = std::max(worst, off * scale / pixel_(placed));
    }
    return worst;
  }

 private:
  const Scene& scene_;
  const std::vector<accel::Aabb>& meshBounds_;
  const std::vector<std::vector<float>>& morphReach_;
  const std::vector<std::vector<accel::Aabb>>& jointBoxes_;
  const PixelFootprint& pixel_;
  float tiny_;
};

}  // namespace

void GpuScene::setShutter(double seconds, int cameraIndex, int width, int height, bool sweeps,
                          double tolerancePixels) {
  shutter_ = seconds > 0.0 ? seconds : 0.0;
  motionPixels_ = static_cast<float>(tolerancePixels);
  sweepsWanted_ = sweeps;
  shutterCamera_ = cameraIndex;
  shutterWidth_ = width;
  shutterHeight_ = height;
  // A moving delta light must keep a chance wherever it may be during the interval; the tree's
  // and the exhaustive weights are of where it is at the frame's time, power's of no place.
  if (shutter_ > 0.0 && punctualMoves()) lightChoice_ = LightSampler::Power;
  meshBounds_.assign(scene_.dynamicMeshes.size(), accel::Aabb{});
  for (size_t m = 0; m < scene_.dynamicMeshes.size(); ++m)
    for (const glm::vec3& p : scene_.dynamicMeshes[m].positions) meshBounds_[m].grow(p);
  if (shutter_ > 0.0) deformationReach(scene_, &morphReach_, &jointBoxes_);
}

std::vector<double> GpuScene::motionTimes(double t) const {
  auto timesOf = [&](int steps) {
    std::vector<double> times(static_cast<size_t>(steps));
    for (int k = 0; k < steps; ++k)
      times[size_t(k)] = t + shutter_ * (double(k) / double(steps - 1) - 0.5);
    return times;
  };
  // Moving instances and deforming meshes: a blend of two steps within --motion-tolerance pixels
  // (half a pixel by default) of where the animation puts them midway, where the camera sees them
  // (PixelFootprint): fewer steps for a preview or a far object, more for a near one at a high
  // resolution. The camera's turn counts the same in pixels; its and the lights' moves, in the
  // scene's size. Two pixels moved the city's blocks 2% at 2 fps
  // (docs/experiments/motion-blur.md).
  const float pixels = motionPixels_;
  constexpr float kTolerance = 1e-3f;
  const PixelFootprint pixel(scene_.cameraAt(shutterCamera_, t), shutterHeight_,
                             1e-6f * sceneRadius_);
  auto instanceError = [&](const accel::Aabb& box, const glm::mat4& a, const glm::mat4& b,
                           const glm::mat4& mid) {
    return blendError(box, a, b, mid) / pixel(box.transformed(mid));
  };
  auto cameraFine = [&](const CameraPose& a, const CameraPose& b, const CameraPose& mid) {
    const float moved = glm::length(0.5f * (a.position + b.position) - mid.position) / sceneRadius_;
    const float turned =
        glm::length(glm::normalize(a.forward + b.forward) - glm::normalize(mid.forward)) +
        glm::length(glm::normalize(a.up + b.up) - glm::normalize(mid.up));
    return moved <= kTolerance && turned / pixel.angle() <= pixels;
  };
  auto lightError = [&](const PunctualLight& a, const PunctualLight& b, const PunctualLight& mid) {
    const float moved = glm::length(0.5f * (a.position + b.position) - mid.position) / sceneRadius_;
    const glm::vec3 axis = a.direction + b.direction;
    const float turned = glm::length(axis) > 0.0f
                             ? glm::length(glm::normalize(axis) - glm::normalize(mid.direction))
                             : 2.0f;
    return std::max(moved, turned);
  };
  const DeformationError deformError(scene_, meshBounds_, morphReach_, jointBoxes_, pixel,
                                     1e-6f * sceneRadius_);
  for (int steps = 3;; steps = 2 * steps - 1) {
    const std::vector<double> times = timesOf(steps);
    if (steps >= 33) return times;
    bool fine = true;
    for (size_t k = 0; fine && k + 1 < times.size(); ++k) {
      const double mid = 0.5 * (times[k] + times[k + 1]);
      // (A non-finite error, a degenerate placement, asks for more steps, up to the most.)
      fine = cameraFine(scene_.cameraAt(shutterCamera_, times[k]),
                        scene_.cameraAt(shutterCamera_, times[k + 1]),
                        scene_.cameraAt(shutterCamera_, mid));
      for (size_t i = 0; fine && i < scene_.lights.size(); ++i)
        fine = !scene_.lights[i].dynamic ||
               lightError(scene_.lightAt(i, times[k]), scene_.lightAt(i, times[k + 1]),
                          scene_.lightAt(i, mid)) <= kTolerance;
      for (size_t i = 0; fine && i < scene_.instances.size(); ++i) {
        const accel::Aabb& box = meshBounds_[scene_.instances[i].mesh];
        fine = box.empty() || instanceError(box, scene_.instanceTransform(i, times[k]),
                                            scene_.instanceTransform(i, times[k + 1]),
                                            scene_.instanceTransform(i, mid)) <= pixels;
      }
      for (size_t m = 0; fine && m < scene_.dynamicMeshes.size(); ++m)
        fine = !scene_.meshDeforms(m) || deformError(m, times[k], times[k + 1], mid) <= pixels;
    }
    if (fine) return times;
  }
}

void GpuScene::placeOverShutter(const std::vector<double>& times,
                                std::vector<std::vector<glm::mat4>>* motion) {
  motion->assign(scene_.instances.size(), {});
  for (size_t i = 0; i < motion->size(); ++i)
    for (double at : times) (*motion)[i].push_back(scene_.instanceTransform(i, at));
  lightMotionSteps_ = 1;
  if (punctualMoves()) {
    std::vector<dev::Light> steps;
    for (size_t i : punctualOrder())
      for (double at : times) steps.push_back(punctualLight(scene_.lightAt(i, at), sceneRadius_));
    const uint64_t bytes = steps.size() * sizeof(dev::Light);
    if (bytes > lightStepBytes_) {
      ctx_.release("light motion steps", lightStepBytes_);
      lightSteps_ = ctx_.allocate("light motion steps", bytes, CL_MEM_READ_ONLY);
      lightStepBytes_ = bytes;
    }
    CL_CHECK(ctx_.queue().enqueueWriteBuffer(lightSteps_, CL_TRUE, 0, bytes, steps.data()));
    lightMotionSteps_ = uint32_t(times.size());
  }
  std::vector<dev::CameraParams> cams;
  for (double at : times) cams.push_back(camera(shutterCamera_, at, shutterWidth_, shutterHeight_));
  cameraMoves_ = std::any_of(cams.begin(), cams.end(), [&](const dev::CameraParams& c) {
    return std::memcmp(&c, &cams.front(), sizeof c) != 0;
  });
  stillCamera_ = cams.front();
  const uint64_t bytes = cams.size() * sizeof(dev::CameraParams);
  if (bytes > cameraStepBytes_) {
    if (cameraStepBytes_) ctx_.release("camera motion steps", cameraStepBytes_);
    cameraSteps_ = ctx_.allocate("camera motion steps", bytes, CL_MEM_READ_ONLY);
    cameraStepBytes_ = bytes;
  }
  CL_CHECK(ctx_.queue().enqueueWriteBuffer(cameraSteps_, CL_TRUE, 0, bytes, cams.data()));
}

dev::CameraParams GpuScene::camera(int cameraIndex, double t, int width, int height) const {
  return toCameraParams(scene_.cameraAt(cameraIndex, t), width, height);
}

kargs::SceneArgs GpuScene::kernelArgs() {
  kargs::SceneArgs a;
  deviceAccel_.fillArgs(ctx_, &a);
  a.pr_sd_vertices = vertices_;
  a.pr_sd_triangles = triangles_;
  a.pr_sd_instances = shadingInstances_;
  a.pr_sd_materials = materials_;
  a.pr_sd_textures = textures_;
  a.pr_sd_texels = texels_;
  a.pr_sd_motion = a.pr_g_motion;
  a.pr_sd_motion_steps = a.pr_g_motion_steps;
  a.pr_sd_time = a.pr_g_time;
  a.pr_sd_motion_vertices = motionVertices_;
  a.pr_sd_vertex_motion = vertexMotion_;
  a.pr_l_lights = lightBuffer_;
  a.pr_l_cdf = cdfBuffer_;
  a.pr_l_nodes = lightNodeBuffer_;
  a.pr_l_prim_light = primLightBuffer_;
  a.pr_l_env = envBuffer_;
  a.pr_l_count = static_cast<cl_uint>(lights_.size());
  a.pr_l_tree_count = static_cast<cl_uint>(treeLights_);
  a.pr_l_total_power = totalPower_;
  a.pr_l_env_light = static_cast<cl_uint>(environmentLight());
  a.pr_l_motion = lightSteps_;
  a.pr_l_motion_first = static_cast<cl_uint>(staticEmitters_.size() + dynamicEmitters_.size());
  a.pr_l_motion_count = static_cast<cl_uint>(scene_.lights.size());
  a.pr_l_motion_steps = lightMotionSteps_;
  a.pr_l_sweeps = sweeps_;
  a.pr_l_sweep_count = sweepCount_;
  a.pr_l_camera_moves = cameraMoves_ ? 1u : 0u;
  return a;
}

std::string GpuScene::environmentDigest() const {
  const Environment& e = options_.environment;
  return Hash128()
      .add(&e.width, sizeof e.width)
      .add(&e.height, sizeof e.height)
      .add(e.rgb.data(), e.rgb.size() * sizeof(float))
      .hex();
}

std::string GpuScene::buildOptions() const {
  KernelFeatures f;
  f.bvhWidth = bvhWidth_;
  f.alpha = hasAlpha_;
  f.sheen = hasSheen_;
  f.coat = hasCoat_;
  f.anisotropy = hasAnisotropy_;
  f.terminatorOffset = options_.shadowTerminator;
  f.gltfModel = options_.materialModel == MaterialModel::Gltf;
  f.lightSampler = lightChoice_ == LightSampler::Power        ? PR_LIGHT_SAMPLER_POWER
                   : lightChoice_ == LightSampler::Exhaustive ? PR_LIGHT_SAMPLER_EXHAUSTIVE
                                                              : PR_LIGHT_SAMPLER_BVH;
  return kernelBuildOptions(f);
}

uint64_t GpuScene::deviceBytes() const {
  return deviceAccel_.staticBytes() + deviceAccel_.meshBytes() + deviceAccel_.frameBytes() +
         shadingBytes_ + instanceBytes_ + lightBytes_ + lightNodeBytes_ + cameraStepBytes_ +
         lightStepBytes_ + motionVertexBytes_ + vertexMotionBytes_;
}

}  // namespace pr
