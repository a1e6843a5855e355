// Owning images: moves leave an empty image behind, copies are deep, views see the pixels.
#include <gtest/gtest.h>

#include "core/image.h"

namespace studio {
namespace {

TEST(Image, MovedFromImageIsEmptyNotSizedWithoutPixels) {
  Mask a(4, 3, 7);
  Mask b(std::move(a));
  EXPECT_EQ(b.width(), 4);
  EXPECT_EQ(b.height(), 3);
  EXPECT_EQ(b(3, 2), 7);
  EXPECT_EQ(a.width(), 0);  // NOLINT(bugprone-use-after-move): the contract under test
  EXPECT_EQ(a.height(), 0);
  EXPECT_TRUE(a.pixels().empty());

  Mask c(2, 2);
  c = std::move(b);
  EXPECT_EQ(c.width(), 4);
  EXPECT_EQ(c.pixels().size(), 12u);
  EXPECT_EQ(b.width(), 0);  // NOLINT(bugprone-use-after-move)
  EXPECT_TRUE(b.pixels().empty());

  Mask& self = c;
  c = std::move(self);
  EXPECT_EQ(c.width(), 4);
  EXPECT_EQ(c.pixels().size(), 12u);
}

TEST(Image, CopiesAreDeep) {
  Image<Rgb8> a(2, 1, Rgb8{1, 2, 3});
  Image<Rgb8> b = a;
  b(0, 0).r = 9;
  EXPECT_EQ(a(0, 0).r, 1);
  EXPECT_EQ(b.view()(0, 0).r, 9);
}

}  // namespace
}  // namespace studio
