// The light BVH (host/render/light_bvh_builder.h, kernels/shared/light_bvh.h) on the CPU reference:
// the choice it makes follows the pmf it reports (chi-square), the pmfs of all lights add to
// at most one, no light that can reach a point (above its normal) is given probability 0, the cones
// and boxes of every node hold their children's after build and after refit, and a point next to
// one of many lights chooses that one far more often than power alone would. The exhaustive
// choice for few lights (light_exhaustive_sample) is held to the same pmf tests, and its
// weights to the irradiance they estimate.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "render/light_bvh_builder.h"
#include "shared/lights.h"
#include "shared/rng.h"
#include "support/chi_square.h"

namespace pr {
namespace {

using dev::float3;
using dev::make_float3;

dev::Light triangle(float3 v0, float3 e1, float3 e2, float power) {
  dev::Light l{};
  l.type = PR_LIGHT_TRIANGLE;
  l.p0x = v0.x, l.p0y = v0.y, l.p0z = v0.z;
  l.e1x = e1.x, l.e1y = e1.y, l.e1z = e1.z;
  l.e2x = e2.x, l.e2y = e2.y, l.e2z = e2.z;
  l.area = 0.5f * dev::length(dev::cross(e1, e2));
  l.power = power;
  l.le_r = l.le_g = l.le_b = power / (PR_PI * std::max(l.area, 1e-12f));
  l.inst = l.prim = PR_INVALID_INDEX;
  return l;
}

dev::Light punctual(uint32_t type, float3 p, float3 axis, float cosOuter, float power) {
  dev::Light l{};
  l.type = type;
  l.p0x = p.x, l.p0y = p.y, l.p0z = p.z;
  l.e1x = axis.x, l.e1y = axis.y, l.e1z = axis.z;
  l.cos_inner = std::min(1.0f, cosOuter + 0.05f);
  l.cos_outer = cosOuter;
  l.power = power;
  l.le_r = l.le_g = l.le_b = power / (4.0f * PR_PI);
  l.inst = l.prim = PR_INVALID_INDEX;
  return l;
}

float3 randomUnit(std::mt19937& g) {
  std::normal_distribution<float> n;
  for (;;) {
    const float3 v = make_float3(n(g), n(g), n(g));
    if (dev::dot(v, v) > 1e-4f) return dev::normalize(v);
  }
}

// Small triangles of random orientation and power spread over a 10 m box, some point lights
// and some spot lights, as a scene with many lamps has.
std::vector<dev::Light> randomLights(uint32_t seed, int triangles) {
  std::mt19937 g(seed);
  std::uniform_real_distribution<float> pos(-5.0f, 5.0f), size(0.02f, 0.3f), power(0.1f, 10.0f);
  std::vector<dev::Light> lights;
  for (int i = 0; i < triangles; ++i) {
    const float3 v0 = make_float3(pos(g), pos(g), pos(g));
    lights.push_back(triangle(v0, randomUnit(g) * size(g), randomUnit(g) * size(g), power(g)));
  }
  for (int i = 0; i < 6; ++i)
    lights.push_back(punctual(PR_LIGHT_POINT, make_float3(pos(g), pos(g), pos(g)),
                              make_float3(0, 0, 1), -1.0f, power(g)));
  for (int i = 0; i < 6; ++i)
    lights.push_back(punctual(PR_LIGHT_SPOT, make_float3(pos(g), pos(g), pos(g)), randomUnit(g),
                              std::cos(0.2f + 0.2f * i), power(g)));
  return lights;
}

struct Receiver {
  float3 p, n;
};

std::vector<Receiver> randomReceivers(uint32_t seed, int count) {
  std::mt19937 g(seed);
  std::uniform_real_distribution<float> pos(-6.0f, 6.0f);
  std::vector<Receiver> r;
  for (int i = 0; i < count; ++i)
    r.push_back(
        {make_float3(pos(g), pos(g), pos(g)), i % 4 == 3 ? make_float3(0, 0, 0) : randomUnit(g)});
  return r;
}

// Whether the point of light l at barycentrics (b1, b2) (triangles; punctual lights: the light)
// sends r anything, with margin eps on each cosine. Only light above the receiver's normal
// counts (every non-delta BSDF reflects).
bool reachesFrom(const dev::Light& l, const Receiver& r, float b1, float b2, float eps) {
  float3 q = make_float3(l.p0x, l.p0y, l.p0z);
  if (l.type == PR_LIGHT_TRIANGLE)
    q = q + make_float3(l.e1x, l.e1y, l.e1z) * b1 + make_float3(l.e2x, l.e2y, l.e2z) * b2;
  const float3 wi = dev::normalize(q - r.p);
  if ((r.n.x != 0 || r.n.y != 0 || r.n.z != 0) && !(dev::dot(wi, r.n) > eps)) return false;
  if (l.type == PR_LIGHT_SPOT)
    return -dev::dot(wi, make_float3(l.e1x, l.e1y, l.e1z)) > l.cos_outer + eps;
  if (l.type == PR_LIGHT_TRIANGLE) {
    const float3 nl = dev::normalize(
        dev::cross(make_float3(l.e1x, l.e1y, l.e1z), make_float3(l.e2x, l.e2y, l.e2z)));
    return std::fabs(dev::dot(wi, nl)) > eps;
  }
  return true;
}

// Chi-square tail probability of n choices from (p, normal) against light_bvh_pmf.
double choicePValue(const LightBvh& bvh, const std::vector<dev::Light>& lights, const Receiver& r,
                    int n, uint32_t seed, int* mismatches) {
  const auto& nodes = bvh.nodes();
  std::vector<double> expected(lights.size());
  for (size_t i = 0; i < lights.size(); ++i)
    expected[i] = dev::light_bvh_pmf(nodes.data(), lights[i].leaf, r.p, r.n) * double(n);
  std::vector<double> count(lights.size(), 0.0);
  dev::Rng rng = dev::rng_make(seed, PR_RNG_TEST, 0u, 0u, 0u);
  for (int s = 0; s < n; ++s) {
    float pmf;
    const uint32_t l = dev::light_bvh_sample(nodes.data(), r.p, r.n, dev::rng_next(&rng), &pmf);
    if (l == PR_INVALID_INDEX) continue;
    count[l] += 1.0;
    const float expect = dev::light_bvh_pmf(nodes.data(), lights[l].leaf, r.p, r.n);
    if (!(std::fabs(pmf - expect) <= 1e-4f * expect)) ++*mismatches;
  }
  return test::chiSquarePValue(count, expected);
}

TEST(LightBvh, ChoicesFollowTheReportedPmf) {
  std::vector<dev::Light> lights = randomLights(1u, 300);
  LightBvh bvh;
  bvh.build(&lights, uint32_t(lights.size()));
  ASSERT_EQ(bvh.nodes().size(), 2 * lights.size() - 1);
  int mismatches = 0;
  const std::vector<Receiver> receivers = randomReceivers(2u, 6);
  for (size_t k = 0; k < receivers.size(); ++k)
    EXPECT_GT(choicePValue(bvh, lights, receivers[k], 200000, uint32_t(k), &mismatches), 1e-4)
        << "receiver " << k;
  EXPECT_EQ(mismatches, 0) << "the pmf light_bvh_sample returns is not light_bvh_pmf's";
}

TEST(LightBvh, PmfsAddToOneAndNoReachableLightIsImpossible) {
  std::vector<dev::Light> lights = randomLights(3u, 200);
  LightBvh bvh;
  bvh.build(&lights, uint32_t(lights.size()));
  const auto& nodes = bvh.nodes();
  for (const Receiver& r : randomReceivers(4u, 200)) {
    double sum = 0.0;
    bool anyReaches = false;
    for (const dev::Light& l : lights) {
      const float pmf = dev::light_bvh_pmf(nodes.data(), l.leaf, r.p, r.n);
      ASSERT_GE(pmf, 0.0f);
      sum += pmf;
      // Can this light send anything to r? Its vertex 0 (a punctual light's position).
      const bool reaches = reachesFrom(l, r, 0.0f, 0.0f, 1e-3f);
      anyReaches = anyReaches || reaches;
      if (reaches) {
        EXPECT_GT(pmf, 0.0f) << "a light that reaches the point is never chosen";
      }
    }
    // Below 1 where a node's bound admits the point but none of its lights does: the choice
    // then fails, which costs a sample but no bias.
    EXPECT_LE(sum, 1.0 + 1e-4);
    if (anyReaches) {
      EXPECT_GT(sum, 0.0);
    }
  }
}

// Angle between two unit vectors, well conditioned near 0 and pi.
double angleBetween(const glm::dvec3& a, const glm::dvec3& b) {
  return std::atan2(glm::length(glm::cross(a, b)), glm::dot(a, b));
}

// Every node's box and cone hold those of its children (nodes with power).
void expectNested(const LightBvh& bvh) {
  const auto& nodes = bvh.nodes();
  for (size_t i = 0; i < nodes.size(); ++i) {
    const dev::LightNode& n = nodes[i];
    if (n.flags & PR_LIGHT_NODE_LEAF) continue;
    for (uint32_t c : {uint32_t(i + 1), n.index}) {
      const dev::LightNode& k = nodes[c];
      ASSERT_EQ(k.parent, i);
      if (!(k.power > 0.0f)) continue;
      const LightBounds &bn = bvh.bounds(i), &bk = bvh.bounds(c);
      for (int a = 0; a < 3; ++a) {
        EXPECT_LE(bn.lo[a], bk.lo[a]);
        EXPECT_GE(bn.hi[a], bk.hi[a]);
      }
      // The device's sphere is the box's.
      const glm::vec3 half = 0.5f * (bk.hi - bk.lo);
      EXPECT_FLOAT_EQ(k.r2, glm::dot(half, half));
      EXPECT_FLOAT_EQ(k.cx, 0.5f * (bk.lo.x + bk.hi.x));
      const double angle = angleBetween(glm::dvec3(n.axis_x, n.axis_y, n.axis_z),
                                        glm::dvec3(k.axis_x, k.axis_y, k.axis_z));
      const double thetaN = std::acos(std::clamp(double(n.cos_o), -1.0, 1.0));
      const double thetaK = std::acos(std::clamp(double(k.cos_o), -1.0, 1.0));
      if (thetaN < 3.14159) {
        EXPECT_LE(angle + thetaK, thetaN + 1e-4) << "node " << i;
      }
      EXPECT_LE(n.cos_e, k.cos_e + 1e-6f);
    }
  }
}

TEST(LightBvh, NodesHoldTheirChildrenAfterBuildAndRefit) {
  std::vector<dev::Light> lights = randomLights(5u, 150);
  LightBvh bvh;
  bvh.build(&lights, uint32_t(lights.size()));
  expectNested(bvh);
  // Move half of the lights far away and turn them; switch one off.
  std::mt19937 g(6u);
  for (size_t i = 0; i < lights.size(); i += 2) {
    lights[i].p0x += 20.0f;
    if (lights[i].type == PR_LIGHT_TRIANGLE) {
      const float3 e = randomUnit(g) * 0.2f;
      lights[i].e1x = e.x, lights[i].e1y = e.y, lights[i].e1z = e.z;
    }
  }
  lights[3].power = 0.0f;
  for (auto& l : lights) l.leaf = 12345u;
  bvh.refit(&lights);
  expectNested(bvh);
  int mismatches = 0;
  for (const Receiver& r : randomReceivers(7u, 3)) {
    EXPECT_EQ(dev::light_bvh_pmf(bvh.nodes().data(), lights[3].leaf, r.p, r.n), 0.0f);
    EXPECT_GT(choicePValue(bvh, lights, r, 100000, 9u, &mismatches), 1e-4);
  }
  EXPECT_EQ(mismatches, 0);
}

TEST(LightBvh, ConeUnionHoldsBothCones) {
  std::mt19937 g(8u);
  std::uniform_real_distribution<float> angle(0.0f, 1.6f);
  for (int k = 0; k < 2000; ++k) {
    LightBounds a, b;
    a.power = b.power = 1.0f;
    const float3 wa = randomUnit(g), wb = randomUnit(g);
    a.axis = glm::vec3(wa.x, wa.y, wa.z), b.axis = glm::vec3(wb.x, wb.y, wb.z);
    a.thetaO = k % 5 == 0 ? 0.0f : angle(g), b.thetaO = angle(g);
    const LightBounds u = unionOf(a, b);
    for (const LightBounds* c : {&a, &b}) {
      const double d = angleBetween(glm::dvec3(u.axis), glm::dvec3(c->axis));
      EXPECT_LE(d + c->thetaO, double(u.thetaO) + 1e-5) << "case " << k;
    }
    EXPECT_LE(u.thetaO, 3.1416f);
  }
}

// The reason for the tree: next to one lamp among hundreds, that lamp is chosen far more often
// than its share of the power (51 times here; by power alone, 1 time).
TEST(LightBvh, ANearLightIsChosenMoreThanItsPowerShare) {
  std::vector<dev::Light> lights = randomLights(10u, 400);
  double total = 0.0;
  for (const auto& l : lights) total += l.power;
  LightBvh bvh;
  bvh.build(&lights, uint32_t(lights.size()));
  const dev::Light& near = lights[17];
  const float3 c =
      make_float3(near.p0x, near.p0y, near.p0z) +
      make_float3(near.e1x + near.e2x, near.e1y + near.e2y, near.e1z + near.e2z) / 3.0f;
  const float3 nl = dev::normalize(dev::cross(make_float3(near.e1x, near.e1y, near.e1z),
                                              make_float3(near.e2x, near.e2y, near.e2z)));
  const float3 p = c + nl * 0.05f;
  const float pmf = dev::light_bvh_pmf(bvh.nodes().data(), near.leaf, p, -nl);
  EXPECT_GT(pmf, 20.0 * near.power / total);
}

// The exhaustive choice (few lights: every one weighed from the receiver) over the same kinds of
// lights: the choice follows light_exhaustive_pmf, the pmfs add to one where any light reaches
// the point, and no light that reaches the point has probability 0.
double exhaustivePValue(const std::vector<dev::Light>& lights, const Receiver& r, int n,
                        uint32_t seed, int* mismatches) {
  const uint32_t count = uint32_t(lights.size());
  std::vector<double> expected(count), observed(count, 0.0);
  for (uint32_t i = 0; i < count; ++i)
    expected[i] = dev::light_exhaustive_pmf(lights.data(), count, i, r.p, r.n) * double(n);
  dev::Rng rng = dev::rng_make(seed, PR_RNG_TEST, 0u, 0u, 0u);
  for (int s = 0; s < n; ++s) {
    float pmf;
    const uint32_t l =
        dev::light_exhaustive_sample(lights.data(), count, r.p, r.n, dev::rng_next(&rng), &pmf);
    if (l == PR_INVALID_INDEX) continue;
    observed[l] += 1.0;
    const float expect = dev::light_exhaustive_pmf(lights.data(), count, l, r.p, r.n);
    if (!(std::fabs(pmf - expect) <= 1e-5f * expect)) ++*mismatches;
  }
  return test::chiSquarePValue(observed, expected);
}

TEST(LightExhaustive, ChoicesFollowTheReportedPmf) {
  const std::vector<dev::Light> lights = randomLights(11u, 4);  // 4 triangles, 12 punctual
  int mismatches = 0;
  const std::vector<Receiver> receivers = randomReceivers(12u, 8);
  for (size_t k = 0; k < receivers.size(); ++k)
    EXPECT_GT(exhaustivePValue(lights, receivers[k], 200000, uint32_t(k), &mismatches), 1e-4)
        << "receiver " << k;
  EXPECT_EQ(mismatches, 0) << "the pmf light_exhaustive_sample returns is not the one it reports";
}

TEST(LightExhaustive, PmfsAddToOneAndNoReachableLightIsImpossible) {
  const std::vector<dev::Light> lights = randomLights(13u, 12);
  const uint32_t count = uint32_t(lights.size());
  std::mt19937 g(14u);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (const Receiver& r : randomReceivers(15u, 300)) {
    double sum = 0.0;
    bool anyReaches = false;
    for (uint32_t i = 0; i < count; ++i) {
      const float pmf = dev::light_exhaustive_pmf(lights.data(), count, i, r.p, r.n);
      ASSERT_GE(pmf, 0.0f);
      sum += pmf;
      // A few points of the light (its corners' neighbourhood included).
      bool reaches = false;
      for (int k = 0; k < 16 && !reaches; ++k) {
        float b1 = u(g), b2 = u(g);
        if (b1 + b2 > 1.0f) b1 = 1.0f - b1, b2 = 1.0f - b2;
        reaches = reachesFrom(lights[i], r, b1, b2, 1e-4f);
      }
      anyReaches = anyReaches || reaches;
      if (reaches) {
        EXPECT_GT(pmf, 0.0f) << "a light that reaches the point is never chosen: light " << i;
      }
    }
    // One where any light gets a share (16 points may miss a corner that reaches the point).
    if (anyReaches || sum > 0.0) {
      EXPECT_NEAR(sum, 1.0, 1e-5);
    }
  }
}

// The importance is the luminance of the unshadowed irradiance: exact for point and spot lights,
// within 25% for a triangle wholly above the receiver (numerical integration over its area).
TEST(LightExhaustive, ImportanceIsTheIrradiance) {
  std::mt19937 g(16u);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  const std::vector<dev::Light> lights = randomLights(17u, 40);
  int triangles = 0;
  for (const Receiver& r : randomReceivers(18u, 60)) {
    if (r.n.x == 0 && r.n.y == 0 && r.n.z == 0) continue;
    for (const dev::Light& l : lights) {
      const float lum = dev::luminance(make_float3(l.le_r, l.le_g, l.le_b));
      const float importance = dev::light_receiver_importance(&l, r.p, r.n);
      const float3 q = make_float3(l.p0x, l.p0y, l.p0z);
      if (l.type != PR_LIGHT_TRIANGLE) {
        const float3 d = q - r.p;
        const float3 wi = dev::normalize(d);
        float e = lum * std::max(0.0f, dev::dot(wi, r.n)) / dev::dot(d, d);
        if (l.type == PR_LIGHT_SPOT)
          e *= dev::spot_attenuation(-dev::dot(wi, make_float3(l.e1x, l.e1y, l.e1z)), l.cos_inner,
                                     l.cos_outer);
        EXPECT_NEAR(importance, e, 1e-4f * e + 1e-12f);
        continue;
      }
      const float3 e1 = make_float3(l.e1x, l.e1y, l.e1z), e2 = make_float3(l.e2x, l.e2y, l.e2z);
      const float3 cr = dev::cross(e1, e2);
      const float3 nl = dev::normalize(cr);
      bool above = true;
      for (const float3& v : {q, q + e1, q + e2}) above = above && dev::dot(v - r.p, r.n) > 0.0f;
      if (!above) continue;
      double e = 0.0;
      const int n = 20000;
      for (int k = 0; k < n; ++k) {
        float b1 = u(g), b2 = u(g);
        if (b1 + b2 > 1.0f) b1 = 1.0f - b1, b2 = 1.0f - b2;
        const float3 d = q + e1 * b1 + e2 * b2 - r.p;
        const float d2 = dev::dot(d, d);
        const float3 wi = d / std::sqrt(d2);
        e += double(dev::dot(wi, r.n)) * std::fabs(dev::dot(wi, nl)) / d2;
      }
      e *= double(lum) * 0.5 * dev::length(cr) / n;
      ++triangles;
      EXPECT_NEAR(importance / e, 1.0, 0.25) << "triangle importance " << importance << " vs " << e;
    }
  }
  EXPECT_GT(triangles, 50);
}

// The resampled choice through the tree: for every light that can reach the point, the mean of
// 1{chosen = l} / weight over many draws is 1 (what makes next-event estimation with it
// unbiased), and the tree pmf it reports for MIS is light_bvh_pmf's.
TEST(LightBvh, ResampledChoiceIsUnbiasedForEveryLight) {
  std::vector<dev::Light> lights = randomLights(19u, 60);
  LightBvh bvh;
  bvh.build(&lights, uint32_t(lights.size()));
  const auto& nodes = bvh.nodes();
  int mismatches = 0, checked = 0;
  for (const Receiver& r : randomReceivers(20u, 4)) {
    std::vector<double> sum(lights.size(), 0.0), sum2(lights.size(), 0.0);
    dev::Rng rng = dev::rng_make(21u, PR_RNG_TEST, 0u, 0u, 0u);
    const int n = 400000;
    for (int s = 0; s < n; ++s) {
      const float ut = dev::rng_next(&rng), ur = dev::rng_next(&rng);
      float weight, treePmf;
      const uint32_t l = dev::light_tree_resample(nodes.data(), lights.data(), r.p, r.n, ut, ur,
                                                  &weight, &treePmf);
      if (l == PR_INVALID_INDEX) continue;
      ASSERT_GT(weight, 0.0f);
      const double v = 1.0 / weight;
      sum[l] += v;
      sum2[l] += v * v;
      const float expect = dev::light_bvh_pmf(nodes.data(), lights[l].leaf, r.p, r.n);
      if (!(std::fabs(treePmf - expect) <= 1e-4f * expect)) ++mismatches;
    }
    for (size_t i = 0; i < lights.size(); ++i) {
      if (!(dev::light_receiver_importance(&lights[i], r.p, r.n) > 0.0f) ||
          !(dev::light_bvh_pmf(nodes.data(), lights[i].leaf, r.p, r.n) > 0.0f))
        continue;
      const double mean = sum[i] / n, var = std::max(0.0, sum2[i] / n - mean * mean);
      // Five standard errors; lights chosen too rarely to judge are left out.
      if (sum[i] == 0.0 || var / n > 0.04) continue;
      ++checked;
      EXPECT_NEAR(mean, 1.0, 5.0 * std::sqrt(var / n) + 1e-3) << "light " << i;
    }
  }
  EXPECT_GT(checked, 60);
  EXPECT_EQ(mismatches, 0) << "the tree pmf light_tree_resample reports is not light_bvh_pmf's";
}

TEST(LightBvh, NoLightsGiveOneLeafThatIsNeverChosen) {
  std::vector<dev::Light> lights;
  LightBvh bvh;
  bvh.build(&lights, 0);
  ASSERT_EQ(bvh.nodes().size(), 1u);
  float pmf = 1.0f;
  EXPECT_EQ(dev::light_bvh_sample(bvh.nodes().data(), make_float3(0, 0, 0), make_float3(0, 0, 1),
                                  0.5f, &pmf),
            PR_INVALID_INDEX);
  EXPECT_EQ(pmf, 0.0f);
}

}  // namespace
}  // namespace pr
