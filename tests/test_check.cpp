// RVR_CHECK and RVR_DCHECK (rvr/core/check.h): a broken invariant aborts with a message naming
// the condition, the caller's message and file:line; a kept one costs nothing visible.
#include <gtest/gtest.h>

#include <memory>

#include "rvr/core/check.h"

namespace {

int g_evaluations = 0;

bool counted(bool value) {
  ++g_evaluations;
  return value;
}

void leaf_count_check(int count) {
  RVR_CHECK(count <= 65535, "leaf of ", count, " triangles does not fit uint16_t");
}

void stack_depth_dcheck(int depth) {
  RVR_DCHECK(depth < 64, "traversal stack at depth ", depth);
}

TEST(CheckDeathTest, BrokenCheckAbortsNamingConditionMessageAndPlace) {
  EXPECT_DEATH(leaf_count_check(70000),
               "rvr: invariant broken: count <= 65535 \\(leaf of 70000 triangles does not fit "
               "uint16_t\\) at .*test_check\\.cpp:[0-9]+");
}

TEST(CheckDeathTest, CheckWithoutMessageNamesTheCondition) {
  EXPECT_DEATH(RVR_CHECK(1 + 1 == 3), "rvr: invariant broken: 1 \\+ 1 == 3 at .*test_check");
}

TEST(Check, KeptCheckEvaluatesItsConditionOnceAndContinues) {
  g_evaluations = 0;
  leaf_count_check(65535);
  RVR_CHECK(counted(true), "never printed");
  EXPECT_EQ(g_evaluations, 1);
}

#if RVR_DCHECK_IS_ON
TEST(CheckDeathTest, BrokenDcheckAbortsWhereDchecksAreOn) {
  EXPECT_DEATH(stack_depth_dcheck(64),
               "rvr: invariant broken: depth < 64 \\(traversal stack at depth 64\\)");
}

TEST(Check, KeptDcheckEvaluatesItsConditionOnce) {
  g_evaluations = 0;
  stack_depth_dcheck(63);
  RVR_DCHECK(counted(true));
  EXPECT_EQ(g_evaluations, 1);
}
#else
TEST(Check, DcheckIsNotEvaluatedWhereDchecksAreOff) {
  g_evaluations = 0;
  stack_depth_dcheck(64);  // would abort if it were on
  RVR_DCHECK(counted(false), "never evaluated");
  EXPECT_EQ(g_evaluations, 0);
}
#endif

}  // namespace
