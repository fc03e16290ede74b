// The scene on the device: both BVHs (SSG once, DSG top level per frame), shading geometry,
// materials, textures, the light table (rebuilt when lights move) and the camera.
#pragma once

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "accel/device_accel.h"
#include "accel/scene_accel.h"
#include "cl/context.h"
#include "render/device_materials.h"
#include "render/light_bvh_builder.h"
#include "render/options.h"
#include "scene/environment_map.h"
#include "scene/scene.h"
#include "shared/camera.h"
#include "shared/geometry.h"
#include "shared/lights.h"
#include "shared/material.h"

namespace pr {

struct GpuSceneOptions {
  // Every non-delta material becomes pure Lambert with its base colour (pbrt's --force-diffuse):
  // a diagnostic with exactly known albedo, used by the furnace tests.
  bool forceDiffuse = false;
  MaterialModel materialModel = MaterialModel::Energy;  // the BSDF model
  bool shadowTerminator = true;  // smooth-shaded facets' terminator offset (shared/transport.h)
  LightSampler lightSampler = LightSampler::Auto;
  int bvhWidth = 0;         // children per BVH node; 0: defaultBvhWidth of the device
  Environment environment;  // the environment light; none where !present()
  // Light sampling weighs the environment by its whole power (--env-light-choice power), not
  // by the part above its uniform floor (GpuScene::envChoiceShare_).
  bool envChoiceByPower = false;
};

// A transform as the kernels keep it: its top three rows, row-major (ShadingInstance).
void toRows(const glm::mat4& m, float out[12]);
// The camera as the kernels see it, exposed for tests (materials: render/device_materials.h).
dev::CameraParams toCameraParams(const CameraPose& pose, int width, int height);

class GpuScene {
 public:
  GpuScene(Context& ctx, const Scene& scene, const GpuSceneOptions& options = {});

  // Evaluates the animation at time t: instance transforms, the DSG's top level, moving
  // lights. Uploads only what changed. Instances whose transform differs from the previous
  // call are flagged `moved` (all of them on the first call).
  void setTime(double t);

  // The camera at time t for an image of width x height.
  dev::CameraParams camera(int cameraIndex, double t, int width, int height) const;
  // Motion blur: from now on each setTime(t) also places the instances and camera `cameraIndex`
  // (for width x height) at motionSteps() times over [t - seconds / 2, t + seconds / 2]
  // (kernels/shared/motion.h), and the punctual lights (then chosen by power) and deforming
  // meshes; 0 seconds: none. sweeps: also what moves while it is open (LightData.sweeps), which
  // path reuse and resampling test their paths against and the path tracer alone never reads.
  void setShutter(double seconds, int cameraIndex, int width, int height, bool sweeps = true,
                  double tolerancePixels = kDefaultMotionTolerance);
  // The last setTime's motion steps (1: none) and the camera at each (a placeholder at 1).
  uint32_t motionSteps() const { return motionSteps_; }
  const cl::Buffer& cameraSteps() const { return cameraSteps_; }
  // The camera's motion steps where it moves over the shutter interval; else 1, and the one
  // camera every step holds is stillCamera() (camera_at_time gives it bit for bit).
  uint32_t cameraMotionSteps() const { return cameraMoves_ ? motionSteps_ : 1u; }
  const dev::CameraParams& stillCamera() const { return stillCamera_; }

  // The scene's kernel arguments (PR_ARGS_SCENE) as they are now; copy them into a kernel's
  // argument struct with kargs::setScene after each setTime.
  kargs::SceneArgs kernelArgs();
  // A hash of the environment's texels (its map's content) and size; computed when asked.
  std::string environmentDigest() const;
  // Build options every kernel that takes the scene is compiled with.
  std::string buildOptions() const;
  // The light-tracing selection table: running sums of every light's power at time 0, fixed for
  // the whole animation so that a light path depends only on its key and the scene at its frame.
  const cl::Buffer& traceCdf() const { return traceCdfBuffer_; }
  float traceTotalPower() const { return traceTotal_; }
  // Radius and centre of the scene's bounding sphere (directional lights emit from its disk).
  float sceneRadius() const { return sceneRadius_; }
  // The environment light's index in the light table, or PR_INVALID_INDEX.
  uint32_t environmentLight() const;
  glm::vec3 sceneCentre() const { return sceneCentre_; }

  // Whether (prim, inst) names a triangle of this scene as hits do (inst PR_INVALID_INDEX: the
  // SSG's; else one of that instance's mesh).
  bool validSurface(uint32_t prim, uint32_t inst) const;
  const Scene& scene() const { return scene_; }
  const std::vector<dev::Light>& lights() const { return lights_; }
  const std::vector<dev::ShadingInstance>& instances() const { return instances_; }
  bool anyInstanceMoved() const { return anyMoved_; }
  // Whether the last setTime changed a light (the light table, and so every light pdf).
  bool anyLightMoved() const;
  // Every instance the last setTime moved or reshaped: its bounds before and now, a little
  // enlarged, its mesh's BVH roots (the previous shape's where it deformed) and both
  // world-to-object transforms: where this frame's scene may differ from the previous one's
  // (path resampling's temporal reuse).
  const std::vector<dev::MovedInstance>& movedInstances() const { return moved_; }
  // From now on keep the previous setTime's shapes beside the current ones: its instance
  // transforms and, where a mesh deforms, its shading vertices (path resampling rebuilds the
  // previous frame's x_1 on them). Until the next setTime they are the current ones.
  void keepPrevious();
  // Whether previousVertices and previousInstances hold the previous setTime's shapes (a
  // setTime after keepPrevious that followed another).
  bool previousKnown() const { return previousKnown_; }
  // The previous shapes (the current buffers where nothing keeps them: never deformed, or not
  // asked for).
  const cl::Buffer& previousVertices() const { return prevVertices_() ? prevVertices_ : vertices_; }
  const cl::Buffer& previousInstances() const {
    return prevInstances_() ? prevInstances_ : shadingInstances_;
  }
  // Under a shutter, the previous setTime's sweeps (pt_resample's temporal tests) and their count
  // of records.
  const cl::Buffer& previousSweeps() const { return prevSweeps_; }
  uint32_t previousSweepCount() const { return prevSweepCount_; }
  // Host seconds the last setTime spent deforming meshes and rebuilding their BVHs.
  double lastDeformSeconds() const { return deformSeconds_; }
  bool hasAlphaMaterials() const { return hasAlpha_; }
  uint64_t deviceBytes() const;
  int bvhWidth() const { return bvhWidth_; }
  const accel::StaticAccel& staticAccel() const { return ssg_; }
  const accel::DynamicAccel& dynamicAccel() const { return dsg_; }
  accel::DeviceAccel& deviceAccel() { return deviceAccel_; }

 private:
  void uploadShading();
  // Deforming meshes at t: their BVHs built again and shading vertices uploaded where their
  // shape changed (*changed, per dynamic mesh); under a shutter, also their shapes at `times`
  // (motion steps). Returns whether any changed.
  bool deformMeshes(double t, const std::vector<double>& times, std::vector<bool>* changed);
  // Under a shutter: the deforming meshes' vertices at the motion steps and the table of where
  // each dynamic mesh's are (ShadingData.motion_vertices, vertex_motion).
  void uploadVertexMotion(const std::vector<dev::ShadingVertex>& steps,
                          const std::vector<uint32_t>& table);
  // Copies the current shapes to the previous ones: vertex range [first, first + count) and,
  // with `instances`, the instance transforms.
  void copyToPrevious(uint64_t firstVertex, uint64_t vertexCount, bool instances);
  void buildLights(double t);
  // The fewest motion steps (3, 5, 9, 17, 33) at which a blend of two steps places every moving
  // instance's box and deforming mesh within half a pixel of where the animation puts them
  // midway, as the camera sees them, and the camera and lights within a thousandth of the scene;
  // the times of those steps around t.
  std::vector<double> motionTimes(double t) const;
  // Under a shutter: each instance's transforms at `times` (*motion) and the camera's, uploaded
  // to cameraSteps_.
  void placeOverShutter(const std::vector<double>& times,
                        std::vector<std::vector<glm::mat4>>* motion);
  // moved_ from the instances' bounds and transforms before this frame's setInstances and after
  // (reshaped: per instance, its mesh deformed this frame).
  void collectMoved(const std::vector<accel::Aabb>& before, const std::vector<glm::mat4>& was,
                    const std::vector<bool>& reshaped);
  // Under a shutter: the boxes of what moves while it is open (LightData.sweeps), from the
  // instances' transforms at the motion steps `times` (*motion as placeOverShutter gave them),
  // the deforming meshes and the punctual lights.
  void collectSweeps(const std::vector<double>& times,
                     const std::vector<std::vector<glm::mat4>>& motion);
  std::vector<dev::Light> lightsAt(double t) const;
  // The scene's punctual lights in light-table order (directional ones last).
  std::vector<size_t> punctualOrder() const;
  bool punctualMoves() const {
    for (const auto& l : scene_.lights)
      if (l.dynamic) return true;
    return false;
  }
  cl::Buffer upload(const char* name, const void* data, uint64_t bytes, uint64_t* counter);

  Context& ctx_;
  const Scene& scene_;
  GpuSceneOptions options_;
  int bvhWidth_;  // (before the accels: they are built that wide)
  accel::StaticAccel ssg_;
  accel::DynamicAccel dsg_;
  accel::DeviceAccel deviceAccel_;

  uint32_t staticTriangles_ = 0;
  std::vector<uint32_t> meshFirstTriangle_;  // per dynamic mesh, in the shading triangle array
  std::vector<uint32_t> meshFirstVertex_;    // per dynamic mesh, in the shading vertex array
  std::vector<TriangleMesh> deformed_;       // per dynamic mesh: its shape this frame
  std::vector<std::vector<glm::vec3>> lastPositions_, lastNormals_;
  double deformSeconds_ = 0.0;
  double deformedAt_ = std::nan("");  // the time deformed_ holds (NaN: none yet)
  std::vector<dev::ShadingInstance> instances_;
  std::vector<glm::mat4> lastTransforms_;
  std::vector<dev::MovedInstance> moved_;
  bool firstFrame_ = true;
  bool anyMoved_ = true;
  bool hasAlpha_ = false;
  bool hasSheen_ = false, hasCoat_ = false, hasAnisotropy_ = false;  // of any material

  // The light table keeps one order for the whole animation: static emitters, then the
  // emissive triangles of each instance, then punctual lights.
  struct DynamicEmitter {
    uint32_t instance, triangle, material;
    float share;  // of its power, from its emission texture (scene/emission_power.h)
  };
  std::vector<dev::Light> staticEmitters_;
  std::vector<DynamicEmitter> dynamicEmitters_;
  std::vector<uint32_t> instanceFirstLight_;  // light of each instance's first emitter
  std::vector<uint32_t> primLight_;           // per shading triangle, see LightData.prim_light
  LightBvh lightBvh_;
  bool lightBvhBuilt_ = false;
  LightSampler lightChoice_ = LightSampler::Bvh;  // never Auto
  // Lights in the tree: all but the directional ones and the environment, which are last.
  uint32_t treeLights_ = 0;
  std::vector<dev::Light> lights_;
  std::vector<float> cdf_;
  float totalPower_ = 0.0f;
  std::vector<float> traceCdf_;
  float traceTotal_ = 0.0f;
  cl::Buffer traceCdfBuffer_;
  float sceneRadius_ = 1.0f;
  glm::vec3 sceneCentre_{0.0f};
  bool lightsAnimated_ = false;
  double shutter_ = 0.0;  // seconds (setShutter)
  bool sweepsWanted_ = true;
  int shutterCamera_ = 0, shutterWidth_ = 1, shutterHeight_ = 1;
  // What a motion step's blend may stray, in pixels (setShutter).
  float motionPixels_ = float(kDefaultMotionTolerance);
  std::vector<accel::Aabb> meshBounds_;  // per dynamic mesh, object space (motionTimes)
  // Per deforming mesh, what motionTimes measures its deformation by (setShutter): each morph
  // target's largest displacement, each joint's box of the bind-pose vertices it moves.
  std::vector<std::vector<float>> morphReach_;
  std::vector<std::vector<accel::Aabb>> jointBoxes_;
  uint32_t motionSteps_ = 1;
  cl::Buffer cameraSteps_;
  uint64_t cameraStepBytes_ = 0;
  cl::Buffer motionVertices_, vertexMotion_;  // ShadingData.motion_vertices, vertex_motion
  uint64_t motionVertexBytes_ = 0, vertexMotionBytes_ = 0;
  cl::Buffer lightSteps_;  // each punctual light at the motion steps (LightData.motion)
  uint64_t lightStepBytes_ = 0;
  uint32_t lightMotionSteps_ = 1;
  cl::Buffer sweeps_;  // LightData.sweeps (collectSweeps; render/sweeps.h)
  // Per dynamic mesh: its triangles' groups (sweepParts), and under a shutter a deforming mesh's
  // positions at each motion step.
  std::vector<std::vector<std::vector<uint32_t>>> sweepParts_;
  std::vector<std::vector<std::vector<glm::vec3>>> stepPositions_;
  uint64_t sweepBytes_ = 0;
  uint32_t sweepCount_ = 0;
  bool cameraMoves_ = false;         // at the motion steps of the shutter interval
  dev::CameraParams stillCamera_{};  // the first step's camera (setShutter)
  cl::Buffer prevSweeps_;            // the previous setTime's sweeps_, swapped with it
  uint64_t prevSweepBytes_ = 0;
  uint32_t prevSweepCount_ = 0;

  cl::Buffer vertices_, triangles_, shadingInstances_, materials_, textures_, texels_;
  cl::Buffer prevVertices_, prevInstances_;  // keepPrevious
  bool keepPrevious_ = false, previousKnown_ = false;
  uint64_t vertexCount_ = 0;
  cl::Buffer lightBuffer_, cdfBuffer_, lightNodeBuffer_, primLightBuffer_, envBuffer_;
  float envMeanLuminance_ = 0.0f;
  // The share of the environment's power by which light sampling chooses it (buildLights): the
  // part above its floor, which BSDF sampling draws as well as light sampling does (a uniform
  // environment's radiance is the same in every direction: the BSDF's own distribution is as
  // good as any), at least kEnvChoiceFloor. The light tracer keeps its whole power.
  float envChoiceShare_ = 1.0f;
  uint64_t lightNodeBytes_ = 0;
  uint64_t shadingBytes_ = 0, instanceBytes_ = 0, lightBytes_ = 0;
  size_t lightCapacity_ = 0, instanceCapacity_ = 0;
};

}  // namespace pr
