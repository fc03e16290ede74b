// --fixed-noise: the camera samples' random numbers ignore the frame, so an unchanged view gives
// the same image every frame, while the scene still moves with the frame number. The
// evaluation (tools/bench/evaluate.py) uses it to show what freezing the noise does to flicker.
#include <gtest/gtest.h>

#include <string>

#include "io/image.h"
#include "support/gltf_builder.h"
#include "support/render_helpers.h"
#include "support/test_env.h"

namespace pr {
namespace {

// A closed room with a point light; the only moving object stays outside it, so every frame
// shows the same scene.
std::string stillRoom() {
  test::GltfBuilder b;
  const int white = b.addMaterial({glm::vec4(0.7f, 0.7f, 0.7f, 1), 0, 1});
  b.addNode(b.addBox(glm::vec3(-1, 0, -1), glm::vec3(1, 2, 1), white, true));
  b.addNode(b.addBox(glm::vec3(-0.3f, 0, -0.3f), glm::vec3(0.3f, 0.6f, 0.3f), white));
  b.addPointLight(glm::vec3(0, 1.8f, 0), glm::vec3(1), 5.0f);
  const int outside = b.addNode(b.addBox(glm::vec3(-0.1f), glm::vec3(0.1f), white));
  b.animateTranslation(outside, {0.0f, 1.0f}, {{5.0f, 1.0f, 5.0f}, {6.0f, 1.0f, 5.0f}});
  b.addCamera(glm::vec3(0.5f, 1.2f, 0.8f), glm::vec3(-0.5f, 0.5f, -1.0f), 1.2f, 4.0f / 3.0f);
  return b.write(test::tempDir("fixed-noise-room"), "room");
}

// Without path resampling, which carries each frame's paths into the next (so that frames
// differ however the noise is keyed).
TEST(FixedNoise, SameNoiseEveryFrameOnlyWhenAsked) {
  const std::string scene = stillRoom();
  for (const char* mode : {"pathtrace", "reuse", "retrace"}) {
    const std::string args =
        std::string("--fps 10 --width 24 --height 18 --spp 2 --no-resample --mode ") + mode;
    const std::string fixed = test::renderFrames(scene, "0-2", args + " --fixed-noise", "fixed");
    const std::string fresh = test::renderFrames(scene, "0-2", args, "fresh");
    EXPECT_EQ(test::frameImage(fixed, 0).rgba, test::frameImage(fixed, 2).rgba) << mode;
    // Frame 0's key is the same either way.
    EXPECT_EQ(test::frameImage(fixed, 0).rgba, test::frameImage(fresh, 0).rgba) << mode;
    EXPECT_NE(test::frameImage(fresh, 0).rgba, test::frameImage(fresh, 2).rgba) << mode;
  }
}

TEST(FixedNoise, TheSceneStillAnimates) {
  // The demo's sphere moves: with the noise fixed, frame 10 alone equals frame 10 of a range
  // (the time follows the frame) and differs from frame 0.
  const std::string scene = test::sourcePath("scenes/cornell-dynamic.gltf");
  const std::string args = "--width 32 --height 24 --spp 1 --mode pathtrace --fixed-noise";
  const std::string one = test::renderFrames(scene, "10", args, "fixed-one");
  const std::string range = test::renderFrames(scene, "0-10", args, "fixed-range");
  EXPECT_EQ(test::frameImage(one, 10).rgba, test::frameImage(range, 10).rgba);
  EXPECT_NE(test::frameImage(range, 0).rgba, test::frameImage(range, 10).rgba);
}

}  // namespace
}  // namespace pr
