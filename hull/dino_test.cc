// Real data: the Middlebury dinoSparseRing (../shared/data/middlebury_dino, see its README).
// Silhouettes by thresholding the black background with Middlebury's recipe (0.19 of full scale,
// dilate 10 px, erode 7 px); the views listed in dinoSR_good_silhouette_images.txt. The segment
// hull's mesh, re-projected into every used view, must match the silhouette with IoU >= 0.9.
#include <gtest/gtest.h>

#include <filesystem>
#include <opencv2/imgproc.hpp>

#include "hull/segment_mesh.h"
#include "hull/silhouette_cut.h"
#include "support/middlebury_dino.h"

namespace fs = std::filesystem;

namespace studio::hull {
namespace {

TEST(MiddleburyDino, ReprojectedMeshMatchesSilhouettes) {
  const fs::path dir = fs::path(STUDIO_SHARED_DATA) / "middlebury_dino";
  if (!fs::exists(dir / "dinoSR_par.txt")) GTEST_SKIP() << "no " << dir << " (shared test data)";
  auto dino = studio::testing::load_middlebury_dino(dir.string());
  ASSERT_TRUE(dino) << dino.error().message;
  const std::vector<Camera>& cams = dino->cameras;
  const std::vector<cv::Mat>& sil = dino->silhouettes;
  const std::vector<RunMask>& masks = dino->masks;
  std::vector<View> views;
  for (std::size_t k = 0; k < cams.size(); ++k) views.push_back({&cams[k], &masks[k]});
  GridSpec g;
  g.box_min = studio::testing::DinoViews::box_min(0.005);
  g.box_max = studio::testing::DinoViews::box_max(0.005);
  g.cells_u = g.cells_v = 200;
  CutOptions o;
  o.threads = 2;
  auto hull = visual_hull(g, views, o);
  ASSERT_TRUE(hull) << hull.error().message;
  // The README's carved reference: about 1.05e-4 m^3.
  EXPECT_NEAR(hull->volume(), 1.05e-4, 0.25e-4);
  const Mesh mesh = segment_marching_cubes(*hull);
  EXPECT_TRUE(check_topology(mesh).watertight());
  for (std::size_t k = 0; k < cams.size(); ++k) {
    cv::Mat proj(sil[k].size(), CV_8U, cv::Scalar(0));
    std::vector<cv::Point> pts(3);
    for (const auto& t : mesh.triangles) {
      bool ok = true;
      for (int q = 0; q < 3; ++q) {
        Eigen::Vector2d p;
        ok = ok && cams[k].project(mesh.vertices[t[q]].cast<double>(), &p);
        pts[q] = cv::Point(int(std::lround(p.x() * 16)), int(std::lround(p.y() * 16)));
      }
      if (ok) cv::fillConvexPoly(proj, pts, cv::Scalar(255), cv::LINE_8, 4);
    }
    const double inter = cv::countNonZero(proj & sil[k]), uni = cv::countNonZero(proj | sil[k]);
    EXPECT_GE(inter / uni, 0.9) << cams[k].id;
    std::printf("%s IoU %.4f\n", cams[k].id.c_str(), inter / uni);
  }
}

}  // namespace
}  // namespace studio::hull
