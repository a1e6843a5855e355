// The preview's pure bookkeeping beside its node (issue 16): the frame-exact image books
// (preview/frame_images.h), the scene mirror's assembly (preview/scene_mirror.h) and the
// actor's bounds centre (preview/camera_select.h).
#include "preview/frame_images.h"

#include <gtest/gtest.h>

#include "preview/camera_select.h"
#include "preview/scene_mirror.h"

namespace studio::preview {
namespace {

FrameImage image(uint64_t frame, uint8_t value = 7) { return {1, 1, frame, {value, value, value}}; }

TEST(FrameImageStoreTest, AsksEachImageOnceAndNotForWhatIsHere) {
  FrameImageStore s;
  EXPECT_EQ(s.to_request(5, {"cam0", "cam1"}), (std::vector<std::string>{"cam0", "cam1"}));
  EXPECT_TRUE(s.to_request(5, {"cam0", "cam1"}).empty());  // asked already
  s.add("cam2", image(6));
  EXPECT_EQ(s.to_request(6, {"cam2", "cam3"}), (std::vector<std::string>{"cam3"}));
}

TEST(FrameImageStoreTest, GivesAFramesImagesOnlyWhenAllOfExactlyThatFrameAreHere) {
  FrameImageStore s;
  s.add("cam0", image(5, 1));
  s.add("cam1", image(4, 2));  // another frame: never stands in for frame 5
  EXPECT_FALSE(s.settled(5, {"cam0", "cam1"}));
  ASSERT_FALSE(s.find(5, {"cam0", "cam1"}).has_value());
  EXPECT_EQ(s.find(5, {"cam0", "cam1"}).error(), FrameImageStore::Missing::late);
  s.add("cam1", image(5, 3));
  EXPECT_TRUE(s.settled(5, {"cam0", "cam1"}));
  const auto got = s.find(5, {"cam1", "cam0"});
  ASSERT_TRUE(got.has_value());
  ASSERT_EQ(got->size(), 2u);
  EXPECT_EQ((*got)[0].rgb[0], 3);  // in the order asked
  EXPECT_EQ((*got)[1].rgb[0], 1);
  EXPECT_EQ((*got)[0].frame, 5u);
}

TEST(FrameImageStoreTest, ARefusalSettlesTheFrameAsRefused) {
  FrameImageStore s;
  s.add("cam0", image(9));
  s.refuse("cam1", 9);
  EXPECT_TRUE(s.settled(9, {"cam0", "cam1"}));
  ASSERT_FALSE(s.find(9, {"cam0", "cam1"}).has_value());
  EXPECT_EQ(s.find(9, {"cam0", "cam1"}).error(), FrameImageStore::Missing::refused);
  EXPECT_TRUE(s.find(9, {"cam0"}).has_value());  // positive control: cam0's is here
}

TEST(FrameImageStoreTest, ARigWideRequestTakesWhicheverImagesCame) {
  FrameImageStore s;
  const std::vector<std::string> rig{"cam0", "cam1", "cam2", "cam3"};
  s.add("cam0", image(7, 1));
  s.add("cam2", image(7, 3));
  s.add("cam1", image(6, 9));  // another frame: not cam1's image of frame 7
  EXPECT_FALSE(s.answered(7, rig));
  s.refuse("cam3", 7);
  EXPECT_FALSE(s.answered(7, rig));  // cam1 has not answered frame 7
  s.refuse("cam1", 7);
  EXPECT_TRUE(s.answered(7, rig));
  const auto here = s.here(7, rig);
  ASSERT_EQ(here.size(), 2u);
  EXPECT_EQ(here[0].first, "cam0");
  EXPECT_EQ(here[0].second.rgb[0], 1);
  EXPECT_EQ(here[1].first, "cam2");
  EXPECT_EQ(here[1].second.frame, 7u);
  EXPECT_TRUE(s.here(8, rig).empty());
}

TEST(FrameImageStoreTest, KeepsTheNewestFrames) {
  FrameImageStore s(3);
  for (uint64_t f = 1; f <= 5; ++f) s.add("cam0", image(f));
  EXPECT_EQ(s.images(), 3u);
  EXPECT_FALSE(s.find(2, {"cam0"}).has_value());
  EXPECT_TRUE(s.find(3, {"cam0"}).has_value());
  EXPECT_TRUE(s.find(5, {"cam0"}).has_value());
}

scene::Node node(const std::string& id, const std::string& parent) {
  scene::Node n;
  n.id = id;
  n.parent = parent;
  return n;
}

TEST(SceneMirrorTest, ParentsBeforeChildrenWhateverTheKeysOrder) {
  // "a_child" sorts before its parent "b_parent".
  const std::map<std::string, scene::Node> nodes{{"a_child", node("a_child", "b_parent")},
                                                 {"b_parent", node("b_parent", "")},
                                                 {"c_leaf", node("c_leaf", "a_child")}};
  const scene::Scene s = assemble_scene(nodes);
  EXPECT_EQ(s.nodes().size(), 3u);
  ASSERT_NE(s.find("c_leaf"), nullptr);
  EXPECT_EQ(s.find("c_leaf")->parent, "a_child");
}

TEST(SceneMirrorTest, AnOrphanWaitsWithItsSubtree) {
  const std::map<std::string, scene::Node> nodes{{"root", node("root", "")},
                                                 {"orphan", node("orphan", "missing")},
                                                 {"grandchild", node("grandchild", "orphan")}};
  const scene::Scene s = assemble_scene(nodes);
  EXPECT_NE(s.find("root"), nullptr);
  EXPECT_EQ(s.find("orphan"), nullptr);
  EXPECT_EQ(s.find("grandchild"), nullptr);
}

TEST(BoundsCentreTest, IsTheMiddleOfTheBox) {
  EXPECT_TRUE(bounds_centre({}).isZero());
  const Eigen::Vector3d c = bounds_centre({{0, 0, 0}, {2, 4, -6}, {1, 1, 1}});
  EXPECT_TRUE(c.isApprox(Eigen::Vector3d(1, 2, -2.5))) << c.transpose();
}

}  // namespace
}  // namespace studio::preview
