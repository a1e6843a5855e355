// Owned samples and the sequence / bounded-string helpers; the QoS table.

#include "wire/sample.h"

#include <gtest/gtest.h>

#include "wire/entity.h"

namespace studio::wire {
namespace {

TEST(Sample, AssignViewResizeAndMove) {
  Owned<studio_ActorMesh> m;
  EXPECT_TRUE(view(m->vertices).empty());
  const std::vector<float> v{1, 2, 3, 4, 5, 6};
  assign(m->vertices, v);
  EXPECT_EQ(to_vector(m->vertices), v);
  resize(m->vertices, 4);
  EXPECT_EQ(to_vector(m->vertices), (std::vector<float>{1, 2, 3, 4}));
  resize(m->vertices, 6);
  EXPECT_EQ(to_vector(m->vertices), (std::vector<float>{1, 2, 3, 4, 0, 0}));
  Owned<studio_ActorMesh> moved(std::move(m));
  EXPECT_TRUE(view(m->vertices).empty());
  EXPECT_EQ(view(moved->vertices).size(), 6u);
  Owned<studio_ActorMesh> other;
  assign(other->triangles, std::vector<uint32_t>{0, 1, 2});
  other = std::move(moved);  // frees the old triangles (ASan checks)
  EXPECT_EQ(view(other->vertices).size(), 6u);
  EXPECT_TRUE(view(other->triangles).empty());
}

TEST(Sample, BoundedStrings) {
  Owned<studio_CameraCalibration> c;
  set(c->camera_id, "cam7");
  EXPECT_EQ(str(c->camera_id), "cam7");
  EXPECT_THROW(set(c->camera_id, std::string(64, 'x')), std::length_error);
  set(c->camera_id, std::string(63, 'y'));
  EXPECT_EQ(str(c->camera_id).size(), 63u);
}

TEST(Qos, RowsFollowTheDesignTable) {
  const auto& calib = topic_row(TopicId::camera_calibration);
  EXPECT_STREQ(calib.name, "studio/camera/calibration");
  EXPECT_TRUE(calib.reliable && calib.transient_local);
  EXPECT_EQ(calib.depth, 1);
  const auto& mask = topic_row(TopicId::camera_mask);
  EXPECT_FALSE(mask.reliable || mask.transient_local);
  const auto& node = topic_row(TopicId::scene_node);
  EXPECT_TRUE(node.reliable && node.transient_local);
  EXPECT_GT(topic_row(TopicId::service_status).liveliness_lease_s, 0);

  Qos q = qos_for(TopicId::scene_node);
  dds_reliability_kind_t rel;
  dds_duration_t block;
  ASSERT_TRUE(dds_qget_reliability(q.get(), &rel, &block));
  EXPECT_EQ(rel, DDS_RELIABILITY_RELIABLE);
  dds_durability_kind_t dur;
  ASSERT_TRUE(dds_qget_durability(q.get(), &dur));
  EXPECT_EQ(dur, DDS_DURABILITY_TRANSIENT_LOCAL);
  dds_history_kind_t hist;
  int32_t depth;
  ASSERT_TRUE(dds_qget_history(q.get(), &hist, &depth));
  EXPECT_EQ(hist, DDS_HISTORY_KEEP_LAST);
  EXPECT_EQ(depth, 1);
  Qos s = qos_for(TopicId::service_status);
  dds_liveliness_kind_t lk;
  dds_duration_t lease;
  ASSERT_TRUE(dds_qget_liveliness(s.get(), &lk, &lease));
  EXPECT_EQ(lk, DDS_LIVELINESS_AUTOMATIC);
  EXPECT_EQ(lease, DDS_MSECS(3000));
}

}  // namespace
}  // namespace studio::wire
