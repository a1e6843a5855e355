#include "core/log.h"

#include <gtest/gtest.h>

namespace studio::log {
namespace {

TEST(Log, PerCategoryLevels) {
  ASSERT_TRUE(configure("warn,hull=debug"));
  EXPECT_TRUE(enabled("hull", Level::debug));
  EXPECT_FALSE(enabled("hull", Level::trace));
  EXPECT_FALSE(enabled("keyer", Level::info));
  EXPECT_TRUE(enabled("keyer", Level::error));
  set_level("keyer", Level::trace);
  EXPECT_TRUE(enabled("keyer", Level::trace));
  EXPECT_FALSE(enabled("keyer", Level::off));
}

TEST(Log, RejectsMalformedSpecWithoutChangingAnything) {
  ASSERT_TRUE(configure("info"));
  EXPECT_FALSE(configure("info,hull=loud"));
  EXPECT_FALSE(configure("=debug"));
  EXPECT_FALSE(configure("verbose"));
  // "scene" has no level of its own (PerCategoryLevels gave "hull" one, which configure keeps).
  EXPECT_TRUE(enabled("scene", Level::info));
  EXPECT_FALSE(enabled("scene", Level::debug));
}

TEST(Log, DisabledLineDoesNotEvaluateItsStream) {
  ASSERT_TRUE(configure("error"));
  int evaluated = 0;
  auto side_effect = [&] { return ++evaluated; };
  STUDIO_LOG(info, "test") << side_effect();
  EXPECT_EQ(evaluated, 0);
  testing::internal::CaptureStderr();
  STUDIO_LOG(error, "test") << "value " << side_effect();
  const std::string out = testing::internal::GetCapturedStderr();
  EXPECT_EQ(evaluated, 1);
  EXPECT_NE(out.find("ERROR [test] value 1\n"), std::string::npos) << out;
}

}  // namespace
}  // namespace studio::log
