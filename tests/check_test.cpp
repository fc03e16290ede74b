// Internal checks: PR_CHECK on the host, PR_DCHECK where PATHREUSE_DCHECKS is defined, and the
// shared code's PR_KCHECK in the host's CPU reference.
#include <gtest/gtest.h>

#include <string>

#include "shared/common.h"
#include "util/check.h"
#include "util/error.h"

namespace pr {
namespace {

TEST(Check, FailedCheckThrowsNamingTheCondition) {
  EXPECT_NO_THROW(PR_CHECK(1 + 1 == 2));
  try {
    PR_CHECK(1 + 1 == 3);
    FAIL() << "PR_CHECK did not throw";
  } catch (const RuntimeError& e) {
    EXPECT_NE(std::string(e.what()).find("internal check failed: 1 + 1 == 3"), std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("check_test.cpp"), std::string::npos) << e.what();
  }
}

TEST(Check, DebugChecksWhereEnabled) {
#ifdef PATHREUSE_DCHECKS
  EXPECT_THROW(PR_DCHECK(false), RuntimeError);
#else
  EXPECT_NO_THROW(PR_DCHECK(false));
#endif
}

// The shared code's checks abort the host's CPU reference (kernels compile them out).
TEST(CheckDeathTest, SharedCodeChecksAbortTheCpuReference) {
  EXPECT_DEATH(PR_KCHECK(1 + 1 == 3), "check failed: 1 \\+ 1 == 3");
  PR_KCHECK(1 + 1 == 2);
}

}  // namespace
}  // namespace pr
