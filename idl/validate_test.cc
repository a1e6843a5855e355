// Validators: every valid sample passes, and each class of malformed sample is rejected with
// its reason (lengths, ranges, run sums and ordering, finite floats, ids).

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "core/mask_codec.h"
#include "harness/wire_samples.h"
#include "wire/types.h"

namespace studio::wire {
namespace {

using testing::make;
const double kNaN = std::nan("");

// Writes an out-of-range value into an enum field, as a malicious or buggy peer could.
template <class E>
void poke(E& field, uint32_t value) {
  static_assert(sizeof(E) == sizeof value);
  std::memcpy(&field, &value, sizeof value);
}

TEST(Validate, GeneratedSamplesOfEveryTypeAreValid) {
  for (int seed = 0; seed < 6; ++seed) {
    EXPECT_FALSE(validate(*make<studio_CameraCalibration>(seed)));
    EXPECT_FALSE(validate(*make<studio_AlphaMask>(seed)));
    EXPECT_FALSE(validate(*make<studio_CameraImage>(seed)));
    EXPECT_FALSE(validate(*make<studio_CameraState>(seed)));
    EXPECT_FALSE(validate(*make<studio_CameraControl>(seed)));
    EXPECT_FALSE(validate(*make<studio_CaptureCommand>(seed)));
    EXPECT_FALSE(validate(*make<studio_SegmentSet>(seed)));
    EXPECT_FALSE(validate(*make<studio_ActorMesh>(seed)));
    EXPECT_FALSE(validate(*make<studio_HeadPose>(seed)));
    EXPECT_FALSE(validate(*make<studio_SceneNode>(seed)));
    EXPECT_FALSE(validate(*make<studio_SceneCommand>(seed)));
    EXPECT_FALSE(validate(*make<studio_ProjectorCalibration>(seed)));
    EXPECT_FALSE(validate(*make<studio_ServiceStatus>(seed)));
    EXPECT_FALSE(validate(*make<studio_ProjectorMask>(seed)));
    EXPECT_FALSE(validate(*make<studio_ProjectorFrame>(seed)));
  }
}

TEST(Validate, TableRowsValidateTheirOwnType) {
  auto mask = make<studio_AlphaMask>(0);
  EXPECT_FALSE(topic_row(TopicId::camera_mask).validate(mask.get()));
  view(mask->runs)[1] = 1000;
  EXPECT_EQ(topic_row(TopicId::camera_mask).validate(mask.get()), Reject::bad_runs);
  EXPECT_EQ(topic_table().size(), kTopicCount);
}

TEST(Validate, ProjectorFrameChecksItsMaskRunsThumbnailAndNumbers) {
  auto f = make<studio_ProjectorFrame>(2);
  view(f->mask_runs)[1] = f->width + 1;  // leaves the row
  EXPECT_EQ(validate(*f), Reject::bad_runs);
  f = make<studio_ProjectorFrame>(2);
  f->height += 1;  // row_start no longer height + 1 entries
  EXPECT_EQ(validate(*f), Reject::bad_size);
  f = make<studio_ProjectorFrame>(2);
  f->thumb_width += 1;  // thumbnail bytes != w * h * 3
  EXPECT_EQ(validate(*f), Reject::bad_size);
  f = make<studio_ProjectorFrame>(2);
  f->margin_m = kNaN;
  EXPECT_EQ(validate(*f), Reject::non_finite);
  f = make<studio_ProjectorFrame>(2);
  f->latency_ms = -1;
  EXPECT_EQ(validate(*f), Reject::out_of_range);
  f = make<studio_ProjectorFrame>(2);
  set(f->projector_id, "");
  EXPECT_EQ(validate(*f), Reject::bad_id);
}

TEST(Validate, CalibrationRejectsNonFiniteAndNonRotations) {
  auto c = make<studio_CameraCalibration>(1);
  c->rd3 = kNaN;
  EXPECT_EQ(validate(*c), Reject::non_finite);
  c = make<studio_CameraCalibration>(1);
  c->R[0] = 2;  // not orthonormal
  EXPECT_EQ(validate(*c), Reject::out_of_range);
  c = make<studio_CameraCalibration>(1);
  c->K[0] = -1;
  EXPECT_EQ(validate(*c), Reject::out_of_range);
  c = make<studio_CameraCalibration>(1);
  c->width = 0;
  EXPECT_EQ(validate(*c), Reject::bad_size);
  c = make<studio_CameraCalibration>(1);
  set(c->camera_id, "");
  EXPECT_EQ(validate(*c), Reject::bad_id);
  c = make<studio_CameraCalibration>(1);
  std::memset(c->camera_id, 'x', sizeof c->camera_id);  // unterminated
  EXPECT_EQ(validate(*c), Reject::bad_id);
}

TEST(Validate, MaskRunsMustBeSortedInsideTheImageAndSumAtMostWH) {
  auto m = make<studio_AlphaMask>(0);
  auto runs = view(m->runs);
  runs[1] = m->width + 1;  // leaves the row
  EXPECT_EQ(validate(*m), Reject::bad_runs);
  m = make<studio_AlphaMask>(0);
  std::swap(view(m->runs)[0], view(m->runs)[1]);  // begin > end
  EXPECT_EQ(validate(*m), Reject::bad_runs);
  m = make<studio_AlphaMask>(0);
  auto rs = view(m->row_start);
  rs[rs.size() - 1] += 1;  // claims more runs than sent
  EXPECT_EQ(validate(*m), Reject::bad_size);
  m = make<studio_AlphaMask>(0);
  m->height += 1;  // row_start no longer height+1
  EXPECT_EQ(validate(*m), Reject::bad_size);
  m = make<studio_AlphaMask>(0);
  poke(m->encoding, 7);
  EXPECT_EQ(validate(*m), Reject::out_of_range);
  // Overlapping runs in one row (a second run starting inside the first).
  m = make<studio_AlphaMask>(0);
  std::vector<uint32_t> start(m->height + 1, 0), bad{2, 10, 5, 12};
  for (uint32_t y = 1; y <= m->height; ++y) start[y] = 2;
  assign(m->row_start, start);
  assign(m->runs, bad);
  EXPECT_EQ(validate(*m), Reject::bad_runs);
}

TEST(Validate, CodecMasksAreDecodedAndMustMatchTheHeader) {
  RunMask rm(64, 48);
  rm.push_run(3, 10, 20);
  rm.push_run(4, 11, 22);
  rm.finish();
  Owned<studio_AlphaMask> m;
  set(m->camera_id, "cam0");
  m->width = 64;
  m->height = 48;
  m->encoding = studio_MASK_CODEC;
  assign(m->data, encode_mask(rm));
  EXPECT_FALSE(validate(*m));
  m->width = 65;
  EXPECT_EQ(validate(*m), Reject::bad_size);
  m->width = 64;
  auto bytes = encode_mask(rm);
  bytes.push_back(0);  // trailing garbage
  assign(m->data, bytes);
  EXPECT_EQ(validate(*m), Reject::bad_runs);
  assign(m->data, std::vector<uint8_t>{});
  EXPECT_EQ(validate(*m), Reject::bad_runs);
}

TEST(Validate, ImagesSegmentsMeshesAndTheRest) {
  auto img = make<studio_CameraImage>(0);
  img->height += 1;
  EXPECT_EQ(validate(*img), Reject::bad_size);
  img = make<studio_CameraImage>(0);
  img->format = studio_IMAGE_JPEG;  // RGB bytes are no JPEG (no SOI marker)
  EXPECT_EQ(validate(*img), Reject::out_of_range);

  auto seg = make<studio_SegmentSet>(0);
  view(seg->intervals)[0] = std::nanf("");
  EXPECT_EQ(validate(*seg), Reject::non_finite);
  seg = make<studio_SegmentSet>(0);
  seg->nu += 1;
  EXPECT_EQ(validate(*seg), Reject::bad_size);
  seg = make<studio_SegmentSet>(0);
  view(seg->intervals)[1] = 99.f;  // past box_max on the axis
  EXPECT_EQ(validate(*seg), Reject::bad_runs);
  seg = make<studio_SegmentSet>(0);
  seg->axis = 3;
  EXPECT_EQ(validate(*seg), Reject::out_of_range);

  auto mesh = make<studio_ActorMesh>(0);
  view(mesh->triangles)[0] = 20;  // 20 vertices: index 20 is out of range
  EXPECT_EQ(validate(*mesh), Reject::out_of_range);
  mesh = make<studio_ActorMesh>(0);
  resize(mesh->vertices, 7);
  EXPECT_EQ(validate(*mesh), Reject::bad_size);

  auto head = make<studio_HeadPose>(0);
  head->confidence = 1.5;
  EXPECT_EQ(validate(*head), Reject::out_of_range);
  head = make<studio_HeadPose>(0);
  head->velocity[2] = INFINITY;
  EXPECT_EQ(validate(*head), Reject::non_finite);

  auto node = make<studio_SceneNode>(1);
  set(node->parent, "node1");  // its own parent
  EXPECT_EQ(validate(*node), Reject::out_of_range);
  node = make<studio_SceneNode>(1);
  node->parent_from_node[15] = 0;
  EXPECT_EQ(validate(*node), Reject::out_of_range);

  auto cmd = make<studio_SceneCommand>(0);
  set(cmd->target, "");
  EXPECT_EQ(validate(*cmd), Reject::bad_id);
  cmd = make<studio_SceneCommand>(0);
  poke(cmd->verb, 42);
  EXPECT_EQ(validate(*cmd), Reject::out_of_range);

  auto state = make<studio_CameraState>(0);
  view(state->features)[1].min = 1e9;  // min > max
  EXPECT_EQ(validate(*state), Reject::out_of_range);
  auto status = make<studio_ServiceStatus>(0);
  view(status->counters)[0].value = kNaN;
  EXPECT_EQ(validate(*status), Reject::non_finite);
  auto control = make<studio_CameraControl>(0);
  set(control->feature, "");
  EXPECT_EQ(validate(*control), Reject::bad_id);
  auto capture = make<studio_CaptureCommand>(0);
  poke(capture->action, 9);
  EXPECT_EQ(validate(*capture), Reject::out_of_range);
  auto proj = make<studio_ProjectorCalibration>(0);
  proj->homography[4] = kNaN;
  EXPECT_EQ(validate(*proj), Reject::non_finite);
}

}  // namespace
}  // namespace studio::wire
