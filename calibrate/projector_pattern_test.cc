// The projected pattern's geometry (calibrate/projector_pattern.h): the ChArUco corners detected in
// the drawn projector frame itself lie at ProjectedPattern::projector_pixel (pixel-centre
// convention), and a bad placement is refused in one line.
#include "calibrate/projector_pattern.h"

#include <gtest/gtest.h>

#include "calibrate/detect.h"

namespace studio::calibrate {
namespace {

ProjectedPattern pattern() {
  ProjectedPattern p;
  p.board = parse_target_spec("charuco:16x9:110:80:DICT_4X4_100").value();
  p.x0 = 77;
  p.y0 = 41;
  p.margin_px = 36;
  return p;
}

TEST(ProjectedPattern, DetectedCornersLieAtTheirProjectorPixels) {
  const ProjectedPattern p = pattern();
  auto frame = draw_pattern(p, 1920, 1080);
  ASSERT_TRUE(frame) << frame.error().message;
  // Outside the board and its margin the frame is black.
  EXPECT_EQ(frame->at<uint8_t>(0, 0), 0);
  EXPECT_EQ(frame->at<uint8_t>(p.y0 - p.margin_px, p.x0 - p.margin_px), 255);
  EXPECT_EQ(frame->at<uint8_t>(p.y0, p.x0), 0);  // square (0, 0) is black
  auto points = detect_target(*frame, p.board);
  ASSERT_TRUE(points) << points.error().message;
  ASSERT_EQ(int(points->size()), p.board.point_count());
  double worst = 0;
  for (const PointObservation& o : *points)
    worst = std::max(worst, (o.pixel - p.projector_pixel(o.id)).norm());
  EXPECT_LT(worst, 0.1);
}

TEST(ProjectedPattern, RefusesAPatternThatDoesNotFit) {
  ProjectedPattern p = pattern();
  p.x0 = 300;
  auto frame = draw_pattern(p, 1920, 1080);
  ASSERT_FALSE(frame);
  EXPECT_NE(frame.error().message.find("does not fit"), std::string::npos);
  p = pattern();
  p.board = parse_target_spec("chessboard:9x6:0.1").value();
  EXPECT_FALSE(p.validate(1920, 1080));
}

}  // namespace
}  // namespace studio::calibrate
