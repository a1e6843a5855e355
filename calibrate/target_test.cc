#include <gtest/gtest.h>

#include <cstdio>

#include <opencv2/aruco/charuco.hpp>
#include <opencv2/imgproc.hpp>

#include "calibrate/detect.h"
#include "calibrate/target.h"

namespace studio::calibrate {
namespace {

TEST(TargetSpec, ParsesTheDesignSpecs) {
  auto c = parse_target_spec("chessboard:9x6:0.025");
  ASSERT_TRUE(c) << c.error().message;
  EXPECT_EQ(c->kind, TargetSpec::Kind::chessboard);
  EXPECT_EQ(c->point_count(), 54);
  EXPECT_DOUBLE_EQ(c->points()[10].x(), 0.025);  // row 1, col 1
  EXPECT_DOUBLE_EQ(c->points()[10].y(), 0.025);
  auto h = parse_target_spec("charuco:11x11:0.09:0.07:DICT_5X5_100");
  ASSERT_TRUE(h) << h.error().message;
  EXPECT_EQ(h->point_count(), 100);
  EXPECT_EQ(parse_target_spec(h->to_string())->point_count(), 100);
  for (const char* bad : {"", "chessboard", "chessboard:9:0.1", "chessboard:9x6:-1", "chessboard:9x6:abc",
                          "charuco:5x5:0.1:0.2:DICT_4X4_50", "charuco:5x5:0.1:0.05:NOPE", "disc:3x3:1",
                          "chessboard:1x6:0.1", "charuco:40x40:0.1:0.05:4X4_50"}) {
    auto r = parse_target_spec(bad);
    EXPECT_FALSE(r) << bad;
    if (!r) {
      EXPECT_EQ(r.error().message.find('\n'), std::string::npos);
    }
  }
}

TEST(TargetSpec, CharucoPointsAreOpenCvsCorners) {
  const TargetSpec t = *parse_target_spec("charuco:7x5:0.04:0.03:DICT_4X4_50");
  auto board = cv::aruco::CharucoBoard::create(7, 5, 0.04f, 0.03f,
                                               cv::aruco::getPredefinedDictionary(t.dictionary));
  const auto pts = t.points();
  ASSERT_EQ(pts.size(), board->chessboardCorners.size());
  for (size_t i = 0; i < pts.size(); ++i) {
    EXPECT_NEAR(pts[i].x(), board->chessboardCorners[i].x, 1e-6);
    EXPECT_NEAR(pts[i].y(), board->chessboardCorners[i].y, 1e-6);
  }
}

// A board drawn at 'ppm' pixels per metre with a margin, warped by a homography.
cv::Mat warp(const cv::Mat& board, const cv::Matx33d& h, cv::Size size) {
  cv::Mat out;
  cv::warpPerspective(board, out, h, size, cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar(255));
  return out;
}

TEST(Detect, CharucoCornersLandWhereTheBoardPutsThem) {
  const TargetSpec t = *parse_target_spec("charuco:7x5:0.04:0.03:DICT_4X4_50");
  auto board = cv::aruco::CharucoBoard::create(7, 5, 0.04f, 0.03f,
                                               cv::aruco::getPredefinedDictionary(t.dictionary));
  const double ppm = 2500;  // 100 px squares
  cv::Mat drawn;
  board->draw(cv::Size(700, 500), drawn, 0, 1);
  const cv::Matx33d h(0.9, 0.1, 60, -0.05, 0.85, 80, 0.0001, 0.00005, 1);
  const cv::Mat image = warp(drawn, h, cv::Size(900, 700));
  auto found = detect_target(image, t);
  ASSERT_TRUE(found) << found.error().message;
  ASSERT_EQ(found->size(), 24u);
  const auto pts = t.points();
  double worst = 0;
  for (const auto& p : *found) {
    // Board pixel of the corner: y down from the top-left like the target frame. draw() puts
    // the square edges on pixel borders (pixels 0..99 are the first square), so in the
    // pixel-centre convention of core/camera.h and warpPerspective a corner lies at 100k - 0.5.
    const cv::Vec3d b(pts[p.id].x() * ppm - 0.5, pts[p.id].y() * ppm - 0.5, 1);
    const cv::Vec3d q = h * b;
    worst = std::max(worst, std::hypot(q[0] / q[2] - p.pixel.x(), q[1] / q[2] - p.pixel.y()));
  }
  std::printf("worst ChArUco corner error on the warped board: %.3f px\n", worst);
  EXPECT_LT(worst, 0.3);

  // Partial view: the right part of the board cut away still gives the corners that are seen.
  cv::Mat cut = image.clone();
  cut.colRange(520, cut.cols).setTo(255);
  auto partial = detect_target(cut, t);
  ASSERT_TRUE(partial);
  EXPECT_GT(partial->size(), 6u);
  EXPECT_LT(partial->size(), 24u);
}

TEST(Detect, ChessboardInOpenCvOrder) {
  const TargetSpec t = *parse_target_spec("chessboard:6x4:0.05");
  cv::Mat board(5 * 60 + 120, 7 * 60 + 120, CV_8U, cv::Scalar(255));
  for (int r = 0; r < 5; ++r)
    for (int c = 0; c < 7; ++c)
      if ((r + c) % 2 == 0) board(cv::Rect(60 + c * 60, 60 + r * 60, 60, 60)).setTo(0);
  auto found = detect_target(board, t);
  ASSERT_TRUE(found) << found.error().message;
  ASSERT_EQ(found->size(), 24u);
  // Consecutive ids step along a row by one square.
  EXPECT_NEAR(std::abs((*found)[1].pixel.x() - (*found)[0].pixel.x()), 60, 0.5);
  EXPECT_NEAR((*found)[1].pixel.y(), (*found)[0].pixel.y(), 0.5);
  EXPECT_TRUE(detect_target(cv::Mat(100, 100, CV_8U, cv::Scalar(128)), t)->empty());
  EXPECT_FALSE(detect_target(cv::Mat(), t));
}

}  // namespace
}  // namespace studio::calibrate
