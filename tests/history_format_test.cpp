// The resume history's records (render/history_format.h): every field of dev::PathHistory is
// checked as its entry in historyRecordFields says, so that no record a kernel would misread or
// sum into inf or negative pixels is loaded.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>

#include "render/history_format.h"

namespace pr {
namespace {

// A record that keeps a path and a direct light, every relational check in play.
dev::PathHistory validRecord() {
  dev::PathHistory h{};
  dev::PathReservoir& r = h.r;
  r.prim = 0;
  r.inst = 0;
  r.b1 = r.b2 = 0.25f;
  r.wz = 1.0f;
  r.g_src = r.rest_r = r.rest_g = r.rest_b = r.pdf_light = 1.0f;
  r.f_r = r.f_g = r.f_b = 1.0f;
  r.kind = PR_RS_NEE2 | PR_RS_JOINED;
  r.p_hat = r.w_sum = r.m = 1.0f;
  r.suffix = 2;
  for (float& x : r.sp) x = 0.5f;
  r.rn = r.rh = 1.0f;
  dev::DirectReservoir& d = h.d;
  d.light = 0;
  d.b1 = d.b2 = 0.25f;
  d.wy = 1.0f;
  d.f_r = d.f_g = d.f_b = d.p_hat = d.w_sum = d.m = 1.0f;
  h.prim = 0;
  h.inst = 0;
  h.b1 = h.b2 = 0.25f;
  h.wx = 1.0f;
  h.stamp = 3;
  return h;
}

bool accepted(const dev::PathHistory& record) {
  HistoryHeader header{};
  header.key = 7;
  header.frame = 11;
  header.chains = 1;
  header.first = 0;
  header.end = 1;
  std::string part = beginHistoryPart(header);
  std::memcpy(historyRecords(&part, 0), &record, sizeof record);
  sealHistoryPart(&part);
  HistoryLayout want;
  want.key = 7;
  want.frame = 11;
  want.chains = 1;
  want.first = 0;
  want.end = 1;
  HistoryScene scene;
  scene.lights = 1;
  scene.validSurface = [](uint32_t prim, uint32_t inst) { return prim == 0 && inst == 0; };
  HistoryHeader read{};
  return checkHistoryPart(part, want, scene, &read);
}

// A value that its check refuses, written over the field's first bytes.
void corrupt(char* at, RecordCheck check) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  auto put = [at](auto v) { std::memcpy(at, &v, sizeof v); };
  switch (check) {
    case RecordCheck::Any:
      put(0xdeadbeefu);
      break;
    case RecordCheck::Finite:
      put(nan);
      break;
    case RecordCheck::Bounded:
    case RecordCheck::Reservoir:
      put(-1.0f);
      break;
    case RecordCheck::Surface:
      put(uint32_t(0x7ffffff0u));
      break;
    case RecordCheck::Light:
      put(uint32_t(5));
      break;
    case RecordCheck::Bary:
      put(5.0f);
      break;
    case RecordCheck::Kind:
      put(uint32_t(7));
      break;
    case RecordCheck::Suffix:
      put(uint32_t(PR_RS_SUFFIX + 1));
      break;
  }
}

TEST(HistoryFormat, EveryFieldOfARecordIsChecked) {
  ASSERT_TRUE(accepted(validRecord()));
  size_t covered = 0;
  for (const RecordField& field : historyRecordFields()) {
    SCOPED_TRACE(field.name);
    covered += field.size;
    dev::PathHistory bad = validRecord();
    corrupt(reinterpret_cast<char*>(&bad) + field.offset, field.check);
    EXPECT_EQ(accepted(bad), field.check == RecordCheck::Any);
  }
  EXPECT_EQ(covered, sizeof(dev::PathHistory));
}

// The last of a field's floats counts as much as its first (sp holds 18).
TEST(HistoryFormat, EveryFloatOfAnArrayFieldIsChecked) {
  dev::PathHistory bad = validRecord();
  bad.r.sp[3 * PR_RS_SUFFIX - 1] = std::numeric_limits<float>::infinity();
  EXPECT_FALSE(accepted(bad));
}

// Kinds and their flags as the kernels make them pass; other bits do not.
TEST(HistoryFormat, KindsAreThoseTheKernelsMake) {
  for (uint32_t kind : {PR_RS_DEEP, PR_RS_NEE2, PR_RS_HIT2, PR_RS_HIT2 | PR_RS_JOINED | PR_RS_LAST2,
                        PR_RS_DEEP | PR_RS_JOINED | PR_RS_CAMERA,
                        PR_RS_DEEP | PR_RS_JOINED | PR_RS_CAMERA | PR_RS_NO_L}) {
    dev::PathHistory h = validRecord();
    h.r.kind = kind;
    EXPECT_TRUE(accepted(h)) << kind;
  }
  // 0x80: PR_RS_NO_L on a path that is not PR_RS_JOINED.
  for (uint32_t kind : {3u, 0x80u, 0x100u, PR_RS_NEE2 | 0x1000u}) {
    dev::PathHistory h = validRecord();
    h.r.kind = kind;
    EXPECT_FALSE(accepted(h)) << kind;
  }
}

}  // namespace
}  // namespace pr
