// One scene on one device with one rendering mode: everything needed to render its frames to
// images in memory. `pathreuse render` writes them to files; `pathreuse portability` compares
// them across devices.
#pragma once

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "cl/context.h"
#include "cl/device.h"
#include "io/image.h"
#include "render/film.h"
#include "render/gpu_scene.h"
#include "render/integrator.h"
#include "render/options.h"
#include "scene/scene.h"

namespace pr {

class PathTracer;
class AovRenderer;

// Checks what joins several options and what needs more than a range (each option's range is the
// option table's: app/render_cli.h); throws InputError naming the option.
void validateRenderOptions(const RenderOptions& o);

// Neither an emissive triangle nor a punctual light.
bool sceneHasNoLights(const Scene& scene);

// The environment the options ask for: a map, a colour, none, or (no option given, a scene
// with no lights) a uniform white one, as model viewers light such scenes. Throws InputError
// naming the map file where it cannot be read.
Environment resolveEnvironment(const RenderOptions& o, const Scene& scene);

class RenderSession {
 public:
  // `scene` must outlive the session. Picks the camera and image size, builds the device scene
  // and the integrator. Throws InputError for a camera that does not exist or is orthographic.
  RenderSession(const Scene& scene, const DeviceEntry& device, const RenderOptions& options);
  ~RenderSession();

  // Renders frame f (time f / fps). Frames must come in increasing order for reuse to apply;
  // any order gives correct images.
  Image renderFrame(int64_t frame, FrameStats* stats);
  // The same, writing only the rows setRows() chose into `image` (of the session's size).
  void renderRows(int64_t frame, Image* image, FrameStats* stats);
  // --aov, --denoise: whether the session makes auxiliary images, and adding frame f's to
  // `image` (the whole image, after the frame's colour), denoising it where asked
  // (render/aov.h). Returns the seconds of each.
  bool hasAovs() const { return aov_ != nullptr; }
  std::pair<double, double> renderAovs(int64_t frame, Image* image);
  // --aov samples: whether it was asked for, and each pixel's samples in the last frame from
  // this session's film (0 outside its rows; several devices' counts add up).
  bool samplesAov() const { return samplesAov_; }
  const std::vector<float>& sampleCounts() const { return counts_; }
  // Rows [rowBegin, rowEnd) of each frame are rendered (default: all). The light paths of
  // path reuse cover every slot whatever the rows (render/multi_device.h).
  void setRows(int rowBegin, int rowEnd) { film_->setRows(rowBegin, rowEnd); }
  // Sample passes [begin, end) of each frame are rendered (default: all; render/integrator.h),
  // and renderSums gives the film's sums (Film::readSums) for another device's to be added.
  void setPasses(int begin, int end) { integrator_->setPasses(begin, end); }
  std::vector<float> renderSums(int64_t frame, FrameStats* stats);

  // --resample's history between frames (render/path_tracer.h): whether the last frame left
  // one, its bytes, and checking then loading the one frame `frame` wrote (checking sets the
  // scene to that frame's time, so that the next frame finds what moved since, as it would have).
  const Scene& scene() const { return scene_; }
  std::string environmentDigest() const;
  bool hasHistory() const;
  std::string writeHistory(const std::string& key);
  bool checkHistory(const std::string& data, const std::string& key, int64_t frame);
  void applyHistory(const std::string& data);
  // The records of pass `pass`'s chain of that history, and writing them on the device the
  // pass moved to (render/multi_device.h); pass < the passes chained, this device's.
  int chains() const;
  std::string chain(int pass);
  void setChain(int pass, const std::string& records);

  int width() const { return width_; }
  int height() const { return height_; }
  Context& context() { return ctx_; }
  Integrator& integrator() { return *integrator_; }
  // The frames of the animation at the session's fps, and the range the options ask for.
  int frameCount() const { return frameCount_; }
  FrameRange frameRange() const;

 private:
  // Frame f into the film (its stats into *fs).
  void render(int64_t frame, FrameStats* fs);
  // From the film's sums just read: the samples channel (--aov samples) and, under
  // --noise-threshold, the stats' mean and maximum samples per pixel.
  void takeCounts(const std::vector<float>& sums, FrameStats* fs);

  const Scene& scene_;
  RenderOptions options_;
  int camera_ = 0;
  int width_ = 0, height_ = 0;
  int frameCount_ = 1;
  Context ctx_;
  std::unique_ptr<GpuScene> gpu_;
  std::unique_ptr<Film> film_;
  std::unique_ptr<Integrator> integrator_;
  std::unique_ptr<AovRenderer> aov_;  // --aov
  bool samplesAov_ = false;
  std::vector<float> counts_;  // sampleCounts()
};

}  // namespace pr
